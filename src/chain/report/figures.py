"""The paper's figures, one function per figure, drawn from tables and traces.

Every function takes the tables of the results contract (``pulses.csv``,
``delays.csv``, ``delay_fits.csv``, ``ssw.csv``, ``ssw_fits.csv``) and/or trace tables
(:mod:`chain.traces`), computes nothing heavier than a group mean, and returns a
:class:`matplotlib.figure.Figure` (built without pyplot, so no global state and no
display backend). :func:`save_figure` writes PDF and PNG with fixed metadata, so two
rebuilds give identical bytes.

==========================  ==========================================================
function                    paper figure
==========================  ==========================================================
:func:`fig1_setup`          Fig. 1, the setup drawn from the configured chains
:func:`fig2_experiment_traces`  Fig. 2, experiment forces at the two sensors
:func:`fig3_simulation_traces`  Fig. 3, simulated forces, same layout
:func:`fig4_delay_vs_force` Fig. 4, crossing delay |Delta| against F_m
:func:`fig5_ssw_vs_force`   Fig. 5, SSW amplitude against incident amplitude
:func:`fig_parity_ssw_vs_N` what-if: SSW slope against N, odd and even chains
==========================  ==========================================================

Tables may hold ``source == "experiment"`` rows (virtual or measured); they are drawn
as open markers under the label given by ``experiment_label`` (the pipeline passes
``"virtual experiment (model)"`` for the model of the apparatus).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, FancyArrowPatch, FancyBboxPatch, Rectangle

from chain.analysis.rows import is_ok, usable_rows
from chain.atomic import atomic_output
from chain.report.paper import PAPER
from chain.traces import sensor_beads, sensor_column

#: Resolution of the PNG files, dots per inch.
PNG_DPI = 200

#: rcParams applied while drawing and saving: fixed fonts and sizes, and the settings
#: that make the written bytes depend on nothing but the figure.
STYLE = {
    "font.family": "DejaVu Sans",
    "font.size": 8,
    "axes.titlesize": 8,
    "axes.labelsize": 8,
    "legend.fontsize": 7,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "lines.linewidth": 1.2,
    "pdf.fonttype": 42,
    "svg.hashsalt": "hertzchain",
    "svg.fonttype": "none",
    "path.simplify": False,
}

#: Metadata written in the files: no dates, no software version.
PDF_METADATA = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}
PNG_METADATA = {"Software": None}

#: Colours of the contact models (others take the next colours of the cycle).
MODEL_COLORS = {"elastic": "#1f77b4", "viscoelastic": "#d95f02"}
_EXTRA_COLORS = ("#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f")

#: Markers of the chains in Fig. 4/5 (paper: N = 25 circles, N = 26 crosses).
N_MARKERS = {25: "o", 26: "x"}
_EXTRA_MARKERS = ("s", "^", "D", "v", "P", "<", ">", "*")

#: Colours of the waves in the trace figures.
LSTW_COLOR = "#1f4e9c"
RSTW_COLOR = "#c0392b"
REFERENCE_COLOR = "black"

MICRO = 1e6

#: SSW measurement drawn in Fig. 3 and Fig. 5 (chain.analysis.ssw: ``residual`` or ``peak``).
SSW_METHOD = "residual"


# ---- saving ---------------------------------------------------------------------


def save_figure(fig: Figure, path: str | os.PathLike) -> list[Path]:
    """Write ``fig`` as ``<path>.pdf`` and ``<path>.png`` with fixed metadata.

    Each file is written to a temporary name beside its destination and renamed, so
    an interrupted write never leaves a partial figure. No creation date or software
    version goes into the files: two rebuilds of the same figure give the same bytes.

    Parameters
    ----------
    fig : Figure
        The figure.
    path : path
        Destination without extension; parent folders are created.

    Returns
    -------
    list of Path
        The PDF and PNG paths.
    """
    stem = Path(path)
    if stem.suffix in (".pdf", ".png"):
        stem = stem.with_suffix("")
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = []
    with mpl.rc_context(STYLE):
        for extension, options in (
            ("pdf", {"metadata": PDF_METADATA}),
            ("png", {"metadata": PNG_METADATA, "dpi": PNG_DPI}),
        ):
            target = stem.with_name(f"{stem.name}.{extension}")
            with atomic_output(target) as temporary:
                fig.savefig(temporary, format=extension, **options)
            written.append(target)
    return written


def _new_figure(width: float, height: float) -> Figure:
    with mpl.rc_context(STYLE):
        return Figure(figsize=(width, height), layout="constrained")


def _axes(ax, width=4.8, height=3.6):
    """The given axes, or new axes on a new figure."""
    if ax is not None:
        return ax.figure, ax
    fig = _new_figure(width, height)
    with mpl.rc_context(STYLE):
        return fig, fig.add_subplot()


def _legend(fig, ax, own: bool, loc: str) -> None:
    """Below the axes on a figure of our own (never over the data); inside otherwise."""
    if own:
        fig.legend(
            *ax.get_legend_handles_labels(),
            loc="outside lower center",
            ncol=2,
            fontsize=6,
            frameon=False,
        )
    else:
        ax.legend(loc=loc, fontsize=6, frameon=False)


def model_colors(models: Sequence[str]) -> dict[str, str]:
    """A colour per model name: fixed for elastic/viscoelastic, the cycle otherwise."""
    colors = {}
    extra = iter(_EXTRA_COLORS * 4)
    for name in models:
        colors[name] = MODEL_COLORS.get(name) or next(extra)
    return colors


def chain_marker(n: int, order: Sequence[int] = ()) -> str:
    """Marker of the chain of ``n`` beads: circle for 25, cross for 26 as in the paper."""
    if n in N_MARKERS:
        return N_MARKERS[n]
    others = [m for m in order if m not in N_MARKERS]
    index = others.index(n) if n in others else 0
    return _EXTRA_MARKERS[index % len(_EXTRA_MARKERS)]


def _label_source(source: str, experiment_label: str) -> str:
    return experiment_label if source == "experiment" else "simulation"


def _is_pooled(column: pd.Series) -> pd.Series:
    return column.astype(str) == "pooled"


def _plain_log_ticks(axis) -> None:
    """Ticks 1, 1.5, 2, 3, 5, 7 x 10^k written as plain numbers on a short log axis."""
    axis.set_major_locator(mpl.ticker.LogLocator(base=10, subs=(1.0, 1.5, 2.0, 3.0, 5.0, 7.0)))
    axis.set_major_formatter(mpl.ticker.StrMethodFormatter("{x:g}"))
    axis.set_minor_formatter(mpl.ticker.NullFormatter())


def _main_method(table: pd.DataFrame) -> pd.DataFrame:
    """Rows of the SSW measurement drawn (``residual``), if the table has several."""
    if "method" in table.columns and (table["method"] == SSW_METHOD).any():
        return table[table["method"] == SSW_METHOD]
    return table


def _us_n16(value: float) -> str:
    return f"{value:.2f} µs N$^{{1/6}}$"


# ---- Fig. 1 ---------------------------------------------------------------------


def fig1_setup(
    chains: Sequence[Mapping],
    *,
    bead_radius_m: float = 0.013,
    striker_radius_m: float = 0.004,
    material: str = "steel_100C6",
    max_rows: int = 6,
) -> Figure:
    """Fig. 1: the setup, one chain per row, drawn to scale from the configuration.

    N beads on the track, the two strikers, the split sensor beads S1 and S2 wired to
    the acquisition, and the directions of the left- and right-launched waves (LSTW,
    RSTW).

    Parameters
    ----------
    chains : sequence of mappings
        ``{"N": int, "sensors": [S1, S2]}`` per chain (the config's ``chains``).
    bead_radius_m, striker_radius_m : float
        Radii, m.
    material : str
        Bead material name, for the title.
    max_rows : int
        With more chains than this, an evenly spaced subset is drawn (and said so).
    """
    chains = list(chains)
    if not chains:
        raise ValueError("fig1_setup needs at least one chain")
    shown = chains
    if len(chains) > max_rows:
        picks = sorted(set(np.linspace(0, len(chains) - 1, max_rows).round().astype(int)))
        shown = [chains[i] for i in picks]
    radius = bead_radius_m * 1e3  # drawn in mm
    striker = striker_radius_m * 1e3
    longest = max(int(c["N"]) for c in shown)
    span = 2 * radius * longest
    fig = _new_figure(7.0, 0.95 * len(shown) + 0.45)
    with mpl.rc_context(STYLE):
        axes = fig.subplots(len(shown), 1, squeeze=False)[:, 0]
        for ax, entry in zip(axes, shown):
            _draw_chain(ax, int(entry["N"]), list(entry["sensors"]), radius, striker, span)
        title = (
            f"Setup: free chains of {material} beads, R = {radius:g} mm; strikers "
            f"R$_s$ = {striker:g} mm at both ends;\nsplit sensor beads S1, S2 "
            "(beads numbered 1..N from the left)"
        )
        if len(shown) < len(chains):
            title += f"; {len(shown)} of {len(chains)} chains shown"
        fig.suptitle(title, fontsize=8)
    return fig


def _draw_chain(ax, n: int, sensors: list[int], radius: float, striker: float, span: float):
    centers = radius * (2 * np.arange(1, n + 1) - 1)
    gap = 2.5 * radius
    length = 2 * radius * n
    left = -gap - 2 * striker
    right = span + gap + 2 * striker  # common to all rows: the same scale in every row
    end = length + gap + 2 * striker  # this chain's right striker
    # Track (Plexiglas) under the beads.
    ax.add_patch(
        Rectangle((left + striker, -radius - 4), end - left - 2 * striker, 4, color="#cfe3ef", lw=0)
    )
    ax.text(left + striker, -radius - 6, "track", ha="left", va="top", fontsize=6, color="#4a6f86")
    for number, x in enumerate(centers, start=1):
        is_sensor = number in sensors
        ax.add_patch(
            Circle(
                (x, 0),
                radius,
                facecolor="#f3d9a4" if is_sensor else "#d9d9d9",
                edgecolor="#404040",
                lw=0.6,
            )
        )
        if is_sensor:
            ax.add_patch(Rectangle((x - 1.2, -radius), 2.4, 2 * radius, color="#7a4b00", lw=0))
        elif number in (1, n) or number % 5 == 0:
            ax.text(x, 0, str(number), ha="center", va="center", fontsize=5.5, color="#303030")
    # Strikers, moving towards the chain.
    for side, x0, direction in ((0, -gap - striker, 1), (1, length + gap + striker, -1)):
        ax.add_patch(Circle((x0, 0), striker, facecolor="#808080", edgecolor="black", lw=0.6))
        ax.add_patch(
            FancyArrowPatch(
                (x0 + direction * (striker + 2), 0),
                (x0 + direction * (gap - 4), 0),
                arrowstyle="-|>",
                mutation_scale=7,
                lw=0.8,
                color="black",
            )
        )
        label = "+V$_0$" if side == 0 else "−V$_0$"
        ax.text(x0, striker + 3, f"striker\n{label}", ha="center", va="bottom", fontsize=6)
    # Waves.
    arrow_y = radius + 19
    for name, start, stop, color in (
        ("LSTW", centers[1], centers[min(5, n - 1)], LSTW_COLOR),
        ("RSTW", centers[-2], centers[max(n - 6, 0)], RSTW_COLOR),
    ):
        ax.add_patch(
            FancyArrowPatch(
                (start, arrow_y),
                (stop, arrow_y),
                arrowstyle="-|>",
                mutation_scale=9,
                lw=1.4,
                color=color,
            )
        )
        ax.text(
            0.5 * (start + stop),
            arrow_y + 2,
            name,
            ha="center",
            va="bottom",
            color=color,
            fontsize=7,
            fontweight="bold",
        )
    # Acquisition box and wires.
    middle = 0.5 * (centers[0] + centers[-1])
    box_y = -radius - 30
    box_w, box_h = min(170.0, 0.4 * span), 13.0
    ax.add_patch(
        FancyBboxPatch(
            (middle - box_w / 2, box_y),
            box_w,
            box_h,
            boxstyle="round,pad=1.5",
            facecolor="#eef3e8",
            edgecolor="#4d6b35",
            lw=0.8,
        )
    )
    ax.text(
        middle,
        box_y + box_h / 2,
        "acquisition: charge amplifier + oscilloscope",
        ha="center",
        va="center",
        fontsize=6,
    )
    for label, bead in zip(("S1", "S2"), sensors):
        x = centers[bead - 1]
        ax.text(
            x,
            radius + 1.5,
            f"{label} (n = {bead})",
            ha="center",
            va="bottom",
            fontsize=6.5,
            color="#7a4b00",
            fontweight="bold",
        )
        x_box = middle - box_w / 2 + 8 if label == "S1" else middle + box_w / 2 - 8
        ax.plot(
            [x, x, x_box, x_box],
            [-radius, box_y + box_h + 8, box_y + box_h + 8, box_y + box_h + 1.5],
            color="#7a4b00",
            lw=0.7,
        )
    ax.text(
        end,
        -radius - 6,
        f"N = {n}",
        ha="right",
        va="top",
        fontsize=8,
        fontweight="bold",
    )
    ax.set_xlim(left - striker, right + striker)
    ax.set_ylim(box_y - 4, arrow_y + 10)
    ax.set_aspect("equal")
    ax.axis("off")


# ---- Fig. 2 / Fig. 3 ------------------------------------------------------------


def fig2_experiment_traces(
    traces,
    pulses: pd.DataFrame | None = None,
    ssw: pd.DataFrame | None = None,
    *,
    model: str | None = None,
    representative_force_N: float = 300.0,
    representative_index: int | None = None,
    estimator: str = "fit_full",
    label: str = "experiment",
    inset: bool = True,
    selection: pd.DataFrame | None = None,
) -> Figure:
    """Fig. 2: experiment forces at S1 and S2, (A, B) N = 25, (C, D) N = 26.

    Same layout and notation as :func:`fig3_simulation_traces`; ``traces`` are
    experiment trace tables (``source == "experiment"``, virtual or measured), and
    ``label`` names them (``"virtual experiment (model)"`` for the model of the
    apparatus). Parameters as in :func:`fig3_simulation_traces`, and:

    Parameters
    ----------
    selection : DataFrame, optional
        ``experiment/selection.csv`` (:func:`chain.analysis.selection.select_shots`): the
        collision shot drawn is the first one the acceptance protocol kept, from the
        amplitudes that have one. None: the first collision shot.
    """
    return _trace_figure(
        traces,
        pulses,
        ssw,
        source="experiment",
        model=model,
        representative_force_N=representative_force_N,
        representative_index=representative_index,
        estimator=estimator,
        title=f"{label}: forces at the sensor beads",
        inset=inset,
        selection=selection,
    )


def fig3_simulation_traces(
    traces,
    pulses: pd.DataFrame | None = None,
    ssw: pd.DataFrame | None = None,
    *,
    model: str | None = "viscoelastic",
    representative_force_N: float = 300.0,
    representative_index: int | None = None,
    estimator: str = "fit_full",
    label: str = "simulation",
    inset: bool = True,
) -> Figure:
    """Fig. 3: simulated forces felt by the sensor beads (sensors not modelled).

    One column per chain (paper: (A, B) N = 25 at n = 9, 17; (C, D) N = 26 at
    n = 10, 17), S1 on top and S2 below. In the collision shot the left-launched wave
    (LSTW) is drawn solid and the right-launched one (RSTW) dashed: at S1 the first
    pulse is the incident LSTW and the second the crossed RSTW, at S2 the other way
    round; the trace is split at the minimum between the two pulses (their times from
    ``pulses``). The reference shot (LSTW alone) is dotted. An inset zooms on what
    follows the crossed pulse, where the secondary solitary wave (SSW) arrives; its
    amplitude from ``ssw`` is marked.

    Parameters
    ----------
    traces : DataFrame or sequence of DataFrames
        Trace tables (one chain each, or several chains in one table).
    pulses : DataFrame, optional
        ``pulses.csv``: pulse times for the split and the incident F_m used to pick the
        representative amplitude (without it: the peak of the S1 trace).
    ssw : DataFrame, optional
        ``ssw.csv``: the SSW marked in the insets.
    model : str or None
        Model to show (None: the first in the table).
    representative_force_N : float
        Show the amplitude whose incident F_m at S1 is closest to this, N.
    representative_index : int, optional
        Show this amplitude index instead.
    estimator : str
        Estimator whose pulse times and amplitudes are used.
    label : str
        Name of the data in the title.
    inset : bool
        Draw the SSW zoom.
    """
    return _trace_figure(
        traces,
        pulses,
        ssw,
        source="simulation",
        model=model,
        representative_force_N=representative_force_N,
        representative_index=representative_index,
        estimator=estimator,
        title=f"{label}: forces felt by the sensor beads (sensors not modelled)",
        inset=inset,
    )


def _split_by_chain(traces, source: str, model: str | None) -> dict[int, pd.DataFrame]:
    tables = [traces] if isinstance(traces, pd.DataFrame) else list(traces)
    chains: dict[int, pd.DataFrame] = {}
    for table in tables:
        table = table[table["source"] == source]
        if model is None and len(table):
            model = str(table["model"].iloc[0])
        table = table[table["model"] == model]
        for n, group in table.groupby("N", sort=True):
            group = group.dropna(axis=1, how="all")
            chains[int(n)] = group
    if not chains:
        raise ValueError(f"no {source} traces of model {model!r} to draw")
    return dict(sorted(chains.items()))


def _pick_amplitude(table, pulses, source, n, estimator, target_force, index, kept=None):
    """Amplitude index to draw: ``index``, else the one whose mean incident F_m at S1 is
    nearest ``target_force`` on a log scale (the largest or smallest if the target is
    out of range), among the amplitudes in ``kept`` when given."""
    if index is not None:
        return int(index)
    first = sensor_column(sensor_beads(table)[0])
    forces = None
    if pulses is not None and len(pulses):
        model = table["model"].iloc[0]
        rows = pulses[
            (pulses["source"] == source)
            & (pulses["model"] == model)
            & (pulses["N"].astype(str) == str(n))
            & (pulses["kind"] == "collision")
            & (pulses["sensor"] == "S1")
            & (pulses["role"] == "incident")
            & (pulses["estimator"] == estimator)
            & is_ok(pulses)
        ]
        if len(rows):
            forces = rows.groupby("amplitude")["F_m_N"].mean()
    if forces is None:
        collision = table[table["kind"] == "collision"]
        forces = collision.groupby("amplitude")[first].max()
    forces = forces[np.isfinite(forces) & (forces > 0)]
    if kept is not None and forces.index.isin(kept).any():
        forces = forces[forces.index.isin(kept)]
    if forces.empty:
        raise ValueError(f"N = {n}: no {source} amplitude with a positive incident F_m")
    return int((np.log(forces / target_force)).abs().idxmin())


def _pulse_times(pulses, shot_meta, sensor, estimator):
    if pulses is None or not len(pulses):
        return {}
    rows = pulses[
        (pulses["source"] == shot_meta["source"])
        & (pulses["model"] == shot_meta["model"])
        & (pulses["N"].astype(str) == str(shot_meta["N"]))
        & (pulses["shot"] == shot_meta["shot"])
        & (pulses["sensor"] == sensor)
        & (pulses["estimator"] == estimator)
        & is_ok(pulses)
    ]
    return {row.role: (row.T_s, row.tau_s, row.F_m_N) for row in rows.itertuples()}


def _split_index(time, force, times) -> int | None:
    """Index of the minimum between the incident and the crossed pulse, or None."""
    if "incident" in times and "crossed" in times:
        lo, hi = np.searchsorted(time, [times["incident"][0], times["crossed"][0]])
    else:
        from scipy.signal import find_peaks

        peaks, _ = find_peaks(force, prominence=0.3 * np.max(force))
        if len(peaks) < 2:
            return None
        lo, hi = peaks[0], peaks[1]
    if hi <= lo + 1:
        return None
    return int(lo + np.argmin(force[lo:hi]))


def _trace_figure(
    traces,
    pulses,
    ssw,
    *,
    source,
    model,
    representative_force_N,
    representative_index,
    estimator,
    title,
    inset,
    selection=None,
) -> Figure:
    chains = _split_by_chain(traces, source, model)
    # One column per chain; a single chain gets the width its legend and title need.
    fig = _new_figure(max(3.4 * len(chains) + 0.4, 6.4), 5.0)
    letters = iter("ABCDEFGHIJKLMNOPQRSTUVWXYZ")
    with mpl.rc_context(STYLE):
        axes = fig.subplots(2, len(chains), squeeze=False, sharex="col")
        for column, (n, table) in enumerate(chains.items()):
            kept = _kept_shots(selection, table)
            amplitude = _pick_amplitude(
                table,
                pulses,
                source,
                n,
                estimator,
                representative_force_N,
                representative_index,
                None if kept is None else _kept_amplitudes(table, kept),
            )
            beads = sensor_beads(table)
            s1, s2 = beads[0], beads[-1]
            shots = table[table["amplitude"] == amplitude]
            if shots.empty:
                raise ValueError(f"N = {n}: no shot of amplitude index {amplitude}")
            collision = _first_shot(shots, "collision", kept)
            reference = _first_shot(shots, "reference", kept)
            for row, (sensor, bead) in enumerate((("S1", s1), ("S2", s2))):
                ax = axes[row, column]
                times = _draw_sensor(
                    ax, collision, reference, sensor, bead, s2, pulses, ssw, estimator, inset
                )
                f_m = times.get("incident", (None, None, None))[2]
                heading = f"({next(letters)}) N = {n}, {sensor} at n = {bead}"
                if row == 0:
                    v0 = collision["v0_left_m_s"].iloc[0] if collision is not None else math.nan
                    detail = []
                    if np.isfinite(v0):
                        detail.append(f"V$_0$ = {v0:.3g} m/s")
                    if f_m is not None:
                        detail.append(f"F$_m$ = {f_m:.0f} N")
                    if detail:
                        heading += "\n" + ", ".join(detail)
                ax.set_title(heading, loc="left")
                ax.set_ylabel("force (N)")
                if row == 1:
                    ax.set_xlabel(
                        "time since launch (µs)" if source == "simulation" else "time (µs)"
                    )
        handles = [
            Line2D([], [], color=LSTW_COLOR, ls="-", label="LSTW (collision shot)"),
            Line2D([], [], color=RSTW_COLOR, ls="--", label="RSTW (collision shot)"),
            Line2D(
                [],
                [],
                color=REFERENCE_COLOR,
                ls=":",
                lw=1.4,
                label="reference (LSTW alone; inset: S2 reference moved onto the crossed pulse)",
            ),
        ]
        if inset:
            handles.append(
                Line2D(
                    [],
                    [],
                    color="#2a7f3f",
                    marker="v",
                    ls="none",
                    label="secondary solitary wave (SSW): time and amplitude",
                )
            )
        fig.legend(handles=handles, loc="outside lower center", ncol=2, frameon=False)
        model_name = next(iter(chains.values()))["model"].iloc[0]
        if source == "simulation":
            fig.suptitle(f"{title}, {model_name} model")
        else:
            named = str(model_name) in title
            fig.suptitle(title if named else f"{title} (series {model_name})")
    return fig


def _kept_shots(selection, table) -> set | None:
    """Shots (collision and reference) of ``table``'s chain that the acceptance protocol
    kept; None without a selection."""
    if selection is None or not len(selection):
        return None
    meta = table.iloc[0]
    rows = selection[
        (selection["model"] == meta["model"])
        & (selection["N"].astype(str) == str(meta["N"]))
        & is_ok(selection, "kept")
    ]
    if "source" in selection.columns:
        rows = rows[rows["source"] == meta["source"]]
    return set(rows["shot"])


def _kept_amplitudes(table, kept) -> set:
    """Amplitude indices with at least one kept collision shot."""
    collisions = table[(table["kind"] == "collision") & table["shot"].isin(kept)]
    return set(collisions["amplitude"])


def _first_shot(shots, kind, kept=None):
    rows = shots[shots["kind"] == kind]
    if kept is not None and rows["shot"].isin(kept).any():
        rows = rows[rows["shot"].isin(kept)]
    if rows.empty:
        return None
    return rows[rows["shot"] == rows["shot"].min()]


def _draw_sensor(ax, collision, reference, sensor, bead, s2, pulses, ssw, estimator, inset):
    column = sensor_column(bead)
    times = {}
    if reference is not None:
        ax.plot(
            reference["t_s"] * MICRO,
            reference[column],
            color=REFERENCE_COLOR,
            ls=":",
            lw=1.4,
        )
    if collision is None:
        return times
    meta = collision.iloc[0]
    time = collision["t_s"].to_numpy()
    force = collision[column].to_numpy()
    times = _pulse_times(pulses, meta, sensor, estimator)
    split = _split_index(time, force, times)
    lstw, rstw = (LSTW_COLOR, "-"), (RSTW_COLOR, "--")
    # S1 meets the incident LSTW first, then the crossed RSTW; S2 the other way round.
    first, second = (lstw, rstw) if sensor == "S1" else (rstw, lstw)
    if split is None:
        ax.plot(time * MICRO, force, color=first[0], ls=first[1])
    else:
        ax.plot(time[: split + 1] * MICRO, force[: split + 1], color=first[0], ls=first[1])
        ax.plot(time[split:] * MICRO, force[split:], color=second[0], ls=second[1])
    ax.set_ylim(bottom=min(0.0, float(force.min())) - 0.03 * float(force.max()))
    if inset and split is not None:
        template = None
        if reference is not None:
            # The reference wave at S2 has travelled as far from its launching end as the
            # crossed wave at either sensor (sensors symmetric about the middle).
            ref_time = reference["t_s"].to_numpy()
            ref_force = reference[sensor_column(s2)].to_numpy()
            ref_times = _pulse_times(pulses, reference.iloc[0], "S2", estimator)
            template = (ref_time, ref_force, ref_times.get("reference"))
        _draw_ssw_inset(ax, time, force, split, times, meta, sensor, ssw, second, template)
    return times


#: Inset of the trace figures, axes fraction: width, height, and bottom edge.
INSET_WIDTH, INSET_HEIGHT, INSET_BOTTOM = 0.42, 0.52, 0.38


def _inset_bounds(ax) -> list[float]:
    """Where the SSW inset goes: upper right, else upper left, whichever the traces
    drawn so far stay below; if neither, the y axis is raised so that they stay below
    the inset on the right (short records, where the two pulses fill the width)."""
    x_lo, x_hi = ax.get_xlim()
    y_lo, y_hi = ax.get_ylim()
    lines = [
        (np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float))
        for line in ax.get_lines()
    ]
    # Leave a small gap between the traces and the inset's lower edge.
    clear = INSET_BOTTOM - 0.04
    for left in (1.0 - INSET_WIDTH - 0.02, 0.02):
        start = x_lo + left * (x_hi - x_lo)
        stop = start + INSET_WIDTH * (x_hi - x_lo)
        highest = max(
            (
                float(np.max(y[(x >= start) & (x <= stop)]))
                for x, y in lines
                if np.any((x >= start) & (x <= stop))
            ),
            default=-np.inf,
        )
        if highest <= y_lo + clear * (y_hi - y_lo):
            return [left, INSET_BOTTOM, INSET_WIDTH, INSET_HEIGHT]
    highest = max((float(np.max(y)) for _, y in lines if len(y)), default=y_hi)
    ax.set_ylim(y_lo, y_lo + (highest - y_lo) / clear)
    left = 1.0 - INSET_WIDTH - 0.02
    return [left, INSET_BOTTOM, INSET_WIDTH, INSET_HEIGHT]


def _draw_ssw_inset(ax, time, force, split, times, meta, sensor, ssw, style, template):
    """Zoom on the crossed pulse's trailing edge, where the secondary solitary wave (SSW)
    rides at the paper's sensor positions: the crossed pulse, the reference pulse
    shifted and scaled onto it (peak on peak), and the SSW of :mod:`chain.analysis.ssw` marked
    at its time with its amplitude."""
    crossed_time, crossed_force = time[split:], force[split:]
    i_peak = int(np.argmax(crossed_force))
    t_cross, f_cross = crossed_time[i_peak], float(crossed_force[i_peak])
    tau = times["crossed"][1] if "crossed" in times else math.nan
    if not np.isfinite(tau) or tau <= 0:
        half = crossed_time[crossed_force > 0.5 * f_cross]
        tau = max(float(half[-1] - half[0]), 1e-12)  # FWHM is about tau for cos^6
    marker = None
    if ssw is not None and len(ssw):
        ssw = _main_method(ssw)
        rows = ssw[
            (ssw["source"] == meta["source"])
            & (ssw["model"] == meta["model"])
            & (ssw["N"].astype(str) == str(meta["N"]))
            & (ssw["shot"] == meta["shot"])
            & (ssw["sensor"] == sensor)
            & is_ok(ssw)
        ]
        if len(rows) and np.isfinite(rows["ssw_time_us"].iloc[0]):
            marker = (float(rows["ssw_time_us"].iloc[0]), float(rows["ssw_N"].iloc[0]))
    start, stop = t_cross - 0.6 * tau, t_cross + 3.5 * tau
    top = min(f_cross, max(0.12 * f_cross, 2.5 * marker[1] if marker else 0.0))
    box = ax.inset_axes(_inset_bounds(ax))
    window = (time >= start) & (time <= stop)
    if template is not None:
        ref_time, ref_force, fitted = template
        i_ref = int(np.argmax(ref_force))
        t_ref, f_ref = ref_time[i_ref], float(ref_force[i_ref])
        if fitted is not None and "crossed" in times:
            t_ref, f_ref, t_cross_fit = fitted[0], fitted[2], times["crossed"][0]
            shift, scale = t_cross_fit - t_ref, times["crossed"][2] / f_ref
        else:
            shift, scale = t_cross - t_ref, f_cross / f_ref
        shown = (ref_time + shift >= start) & (ref_time + shift <= stop)
        box.plot(
            (ref_time[shown] + shift) * MICRO,
            ref_force[shown] * scale,
            color=REFERENCE_COLOR,
            ls=":",
            lw=1.1,
        )
    box.plot(time[window] * MICRO, force[window], color=style[0], ls=style[1], lw=1.0)
    if marker:
        box.plot(marker[0], 0.93 * top, marker="v", color="#2a7f3f", ms=4, ls="none")
        box.text(
            marker[0] + 0.25 * tau * MICRO,
            0.93 * top,
            f"SSW {marker[1]:.2g} N",
            ha="left",
            va="center",
            fontsize=5.5,
            color="#2a7f3f",
        )
    box.set_xlim(start * MICRO, stop * MICRO)
    box.set_ylim(-0.05 * top, top)
    box.tick_params(labelsize=5)
    box.set_title("crossed pulse, trailing edge", fontsize=5.5, pad=1.5)
    box.spines[["top", "right"]].set_visible(True)


# ---- Fig. 4 ---------------------------------------------------------------------


def fig4_delay_vs_force(
    delays: pd.DataFrame,
    fits: pd.DataFrame | None = None,
    *,
    constants: Mapping | None = None,
    estimator: str = "fit_full",
    experiment_label: str = "experiment",
    paper: Mapping = PAPER,
    ax=None,
) -> Figure:
    """Fig. 4: crossing delay |Delta| against the incident amplitude F_m (log-log).

    Simulation: a solid line per model and chain (mean of LSTW and RSTW per launch)
    and the fitted Delta = C F_m^(-1/6) of each model (chains pooled), dashed, with C
    in the legend. Experiment rows (if any): N = 25 open circles, N = 26 crosses, and
    their own pooled fit. For comparison, the ballistic predictions (Eq. 6 as printed,
    and with the exact Hertz contact time) and the paper's C_exp.

    Parameters
    ----------
    delays : DataFrame
        ``delays.csv``.
    fits : DataFrame, optional
        ``delay_fits.csv``.
    constants : mapping, optional
        ``C_bal_paper_us_N16`` and ``C_bal_exact_us_N16`` of this run's beads
        (:func:`chain.physics.theory.ballistic_constants`).
    estimator : str
        Estimator drawn.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    paper : mapping
        The paper's numbers (``C_exp_us_N16``, ``C_exp_err_us_N16``, ``C_bal_us_N16``).
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = _axes(ax, 6.4, 5.4)
    rows = delays[delays["estimator"] == estimator].copy()
    rows["abs_delay_us"] = pd.to_numeric(rows["delay_us"], errors="coerce").abs()
    rows = usable_rows(rows, ["F_m_N", "abs_delay_us"], f"Fig. 4 ({estimator})", positive=True)
    per_chain = {}
    if fits is not None and len(fits):
        for fit in fits[(fits["estimator"] == estimator) & ~_is_pooled(fits["N"])].itertuples():
            if fit.source == "experiment" and np.isfinite(fit.C_us_N16):
                per_chain[(fit.model, int(fit.N))] = (fit.C_us_N16, fit.C_stderr_us_N16)
    models = list(dict.fromkeys(rows.loc[rows["source"] == "simulation", "model"]))
    colors = model_colors(models)
    all_n = sorted({int(n) for n in rows["N"]})
    force_range = [np.inf, -np.inf]
    with mpl.rc_context(STYLE):
        simulation = rows[rows["source"] == "simulation"]
        for (model, n), group in simulation.groupby(["model", "N"], sort=False):
            mean = group.groupby("amplitude")[["F_m_N", "abs_delay_us"]].mean().sort_values("F_m_N")
            ax.plot(
                mean["F_m_N"],
                mean["abs_delay_us"],
                color=colors[model],
                ls="-",
                lw=1.0 if int(n) % 2 else 1.6,
                marker="o" if int(n) % 2 else "s",
                ms=2.5,
                alpha=0.9,
                label=f"simulation, {model}, N = {int(n)}",
            )
            force_range = [
                min(force_range[0], mean["F_m_N"].min()),
                max(force_range[1], mean["F_m_N"].max()),
            ]
        experiment = rows[rows["source"] == "experiment"]
        several = experiment["model"].nunique() > 1
        for (model, n), group in experiment.groupby(["model", "N"], sort=True):
            marker = chain_marker(int(n), all_n)
            label = f"{experiment_label}, {model}" if several else experiment_label
            label += f", N = {int(n)}"
            if (model, int(n)) in per_chain:
                c, err = per_chain[(model, int(n))]
                label += f" (own fit C = {c:.1f} ± {err:.1f})"
            ax.plot(
                group["F_m_N"],
                group["abs_delay_us"],
                ls="none",
                marker=marker,
                mfc="none",
                mec="black",
                color="black",
                ms=5,
                mew=0.9,
                label=label,
            )
            force_range = [
                min(force_range[0], group["F_m_N"].min()),
                max(force_range[1], group["F_m_N"].max()),
            ]
        if not np.all(np.isfinite(force_range)):
            force_range = [10.0, 1000.0]
        grid = np.geomspace(force_range[0], force_range[1], 50)
        if fits is not None and len(fits):
            chosen = fits[(fits["estimator"] == estimator) & _is_pooled(fits["N"])]
            for fit in chosen.itertuples():
                if not np.isfinite(fit.C_us_N16):
                    continue
                who = (
                    f"fit to {experiment_label}, N pooled"
                    if fit.source == "experiment"
                    else f"fit to simulation, {fit.model}"
                )
                color = "black" if fit.source == "experiment" else colors.get(fit.model, "grey")
                ax.plot(
                    grid,
                    fit.C_us_N16 * grid ** (-1 / 6),
                    color=color,
                    ls="--",
                    lw=1.0,
                    label=f"{who}: C = {fit.C_us_N16:.1f} ± {fit.C_stderr_us_N16:.1f}"
                    " µs N$^{1/6}$",
                )
        references = []
        if constants is not None:
            references += [
                (
                    constants["C_bal_paper_us_N16"],
                    "#555555",
                    (0, (6, 2, 1, 2)),
                    "ballistic, Eq. 6 as printed: C$_{bal}$ = "
                    + _us_n16(constants["C_bal_paper_us_N16"]),
                ),
                (
                    constants["C_bal_exact_us_N16"],
                    "#999999",
                    (0, (3, 1.5)),
                    "ballistic, exact Hertz contact time: "
                    + _us_n16(constants["C_bal_exact_us_N16"]),
                ),
            ]
        references.append(
            (
                paper["C_exp_us_N16"],
                "#6a3d9a",
                (0, (1, 1.5)),
                f"paper's experimental fit: C$_{{exp}}$ = {paper['C_exp_us_N16']:.1f} ± "
                f"{paper['C_exp_err_us_N16']:.1f} µs N$^{{1/6}}$",
            )
        )
        for value, color, style, label in references:
            ax.plot(grid, value * grid ** (-1 / 6), color=color, ls=style, lw=1.0, label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        _plain_log_ticks(ax.yaxis)
        ax.xaxis.set_major_formatter(mpl.ticker.StrMethodFormatter("{x:g}"))
        ax.set_xlabel("incident amplitude F$_m$ at the first sensor (N)")
        ax.set_ylabel("|Δ| = |TOF(crossed) − TOF(reference)| (µs)")
        ax.set_title(f"Crossing delay against amplitude ({estimator} estimator)", loc="left")
        _legend(fig, ax, own, "lower left")
    return fig


# ---- Fig. 5 ---------------------------------------------------------------------


def fig5_ssw_vs_force(
    ssw: pd.DataFrame,
    fits: pd.DataFrame | None = None,
    *,
    experiment_label: str = "experiment",
    ax=None,
) -> Figure:
    """Fig. 5: amplitude of the secondary solitary wave (SSW) against the incident
    amplitude F_m (log-log): simulation filled markers, experiment open markers, one
    marker per chain (circle N = 25, cross/square N = 26), a colour per model, and the
    proportional fits SSW = slope x F_m (thin lines, slope in the legend).

    Parameters
    ----------
    ssw : DataFrame
        ``ssw.csv``.
    fits : DataFrame, optional
        ``ssw_fits.csv``.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = _axes(ax, 6.4, 5.0)
    rows = usable_rows(_main_method(ssw), ["F_m_N", "ssw_N"], "Fig. 5 SSW rows", positive=True)
    models = list(dict.fromkeys(rows.loc[rows["source"] == "simulation", "model"]))
    colors = model_colors(models)
    all_n = sorted({int(n) for n in rows["N"]})
    slopes = {}
    if fits is not None and len(fits):
        for fit in _main_method(fits).itertuples():
            if str(fit.N) != "pooled":
                slopes[(fit.source, fit.model, int(fit.N))] = (fit.slope, fit.slope_stderr)
    with mpl.rc_context(STYLE):
        for (source, model, n), group in rows.groupby(["source", "model", "N"], sort=False):
            n = int(n)
            marker = chain_marker(n, all_n)
            if marker == "x" and source == "simulation":
                marker = "s"  # a cross cannot be filled
            color = colors.get(model, "black") if source == "simulation" else "black"
            filled = source == "simulation"
            name = _label_source(source, experiment_label)
            label = f"{name}, {model}, N = {n}" if filled else f"{name}, N = {n}"
            slope = slopes.get((source, model, n))
            if slope is not None and np.isfinite(slope[0]):
                label += f" (slope {slope[0]:.2e} ± {slope[1]:.1e})"
                grid = np.geomspace(group["F_m_N"].min(), group["F_m_N"].max(), 20)
                ax.plot(grid, slope[0] * grid, color=color, lw=0.7, ls="-", alpha=0.7)
            ax.plot(
                group["F_m_N"],
                group["ssw_N"],
                ls="none",
                marker=marker,
                ms=4.5,
                color=color,
                mfc=color if filled else "none",
                mec=color,
                mew=0.9,
                label=label,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_major_formatter(mpl.ticker.StrMethodFormatter("{x:g}"))
        ax.yaxis.set_major_formatter(mpl.ticker.StrMethodFormatter("{x:g}"))
        ax.set_xlabel("incident amplitude F$_m$ (N)")
        ax.set_ylabel("SSW amplitude (N)")
        ax.set_title(
            "Secondary solitary waves: simulation filled, experiment open markers", loc="left"
        )
        _legend(fig, ax, own, "upper left")
    return fig


# ---- what-if: parity ---------------------------------------------------------------


def fig_parity_ssw_vs_N(
    ssw_fits: pd.DataFrame,
    *,
    experiment_label: str = "experiment",
    ax=None,
) -> Figure:
    """SSW slope (SSW amplitude / F_m) against the number of beads N, even chains
    (waves meet at a contact) filled, odd chains (waves meet at a bead) open; a colour
    per model, error bars one standard error.

    Parameters
    ----------
    ssw_fits : DataFrame
        ``ssw_fits.csv``.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = _axes(ax, 6.0, 4.4)
    ssw_fits = _main_method(ssw_fits)
    rows = ssw_fits[~_is_pooled(ssw_fits["N"])].assign(ok=True)
    rows = usable_rows(rows, ["slope", "slope_stderr"], "parity figure: SSW fits").copy()
    rows["N"] = rows["N"].astype(int)
    models = list(dict.fromkeys(rows.loc[rows["source"] == "simulation", "model"]))
    colors = model_colors(models)
    with mpl.rc_context(STYLE):
        for (source, model), group in rows.groupby(["source", "model"], sort=False):
            group = group.sort_values("N")
            color = colors.get(model, "black") if source == "simulation" else "black"
            name = f"{_label_source(source, experiment_label)}, {model}"
            ax.plot(group["N"], group["slope"], color=color, lw=0.6, alpha=0.5)
            for parity, filled in (("even", True), ("odd", False)):
                part = group[(group["N"] % 2 == 0) == (parity == "even")]
                if part.empty:
                    continue
                ax.errorbar(
                    part["N"],
                    part["slope"],
                    yerr=part["slope_stderr"],
                    ls="none",
                    marker="o" if filled else "D",
                    ms=5,
                    color=color,
                    mfc=color if filled else "white",
                    mec=color,
                    capsize=2,
                    label=f"{name}, {parity} N",
                )
        ax.set_xlabel("number of beads N")
        ax.set_ylabel("SSW amplitude / incident amplitude")
        ax.set_title(
            "Parity: even chains (waves meet at a contact) against odd (at a bead)", loc="left"
        )
        ax.xaxis.set_major_locator(mpl.ticker.MaxNLocator(integer=True))
        _legend(fig, ax, own, "best")
    return fig
