"""Figure ssw_spacetime: the secondary solitary wave (SSW) seen along the chain.

One panel per chain (the paper's chains on top, the long chains of config
``long_chains`` below, where the SSW has room to run as its own line): the contact force
of one collision over time (x, in the panel's resolution: each column the largest force
of its time bin, :func:`chain.analysis.ssw_track.pooled_field`) and contact index (y),
divided by the incident amplitude F_m, on a logarithmic colour scale from the tracking
floor (0.1 % of F_m, white below) so that a 1 % wave shows. Over it, the two
main waves (incident dashed, crossed solid: peak times at each contact) and the tracked
SSW (crosses, where it is separated). Top right: the SSW amplitude over F_m against the
distance from the collision point, every shot of every model and chain; a series that
is never separated says so in the legend. Everything drawn comes from
``ssw_track.csv`` and the fields the simulations recorded; nothing is computed here.
"""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from chain.analysis.ssw_track import TRACK_FLOOR, Field
from chain.report.figures.style import (
    LSTW_COLOR,
    RSTW_COLOR,
    STYLE,
    chain_marker,
    model_colors,
    new_figure,
)

#: Upper end of the colour scale, in F_m (the collision peak is ~1.75 F_m).
COLOR_MAX = 2.0
#: Colours of the waves, as in Fig. 2/3 (dark, to show on the bright pulses).
WAVE_COLORS = {"LSTW": LSTW_COLOR, "RSTW": RSTW_COLOR}
TRACK_COLOR = "#00e676"


def field_image(field: Field, shot: int, f_m_N: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (us), contact numbers and force / F_m (contacts x bins) of one shot of a
    pooled field, NaN below the tracking floor (drawn white)."""
    ratio = field.force_N[shot].astype(float) / f_m_N
    contacts = np.arange(1, ratio.shape[0] + 1)
    return field.time_us, contacts, np.where(ratio >= TRACK_FLOOR, ratio, np.nan)


def draw_field(ax, time_us, contacts, ratio):
    """Contact force / F_m over time and contact index, log colours. Returns the mesh."""
    norm = LogNorm(vmin=TRACK_FLOOR, vmax=COLOR_MAX)
    mesh = ax.pcolormesh(
        time_us, contacts, ratio, norm=norm, cmap="magma", shading="nearest", rasterized=True
    )
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("contact k (beads k, k+1)")
    return mesh


def draw_waves(ax, track: pd.DataFrame) -> None:
    """Main waves (incident dashed, crossed solid) and the separated SSW of one shot.

    A wave's rows hold its crossed pulse downstream of the collision point and, at the
    same contacts, the incident pulse of the other wave (``other_time_us``)."""
    other = {"LSTW": "RSTW", "RSTW": "LSTW"}
    for wave, rows in track.groupby("wave", sort=True):
        incident = WAVE_COLORS.get(other.get(wave), "white")
        ax.plot(rows["other_time_us"], rows["contact"], color=incident, ls="--", lw=0.7)
        ax.plot(rows["main_time_us"], rows["contact"], color=WAVE_COLORS.get(wave), lw=0.7)
        separated = rows[rows["separated"].astype(bool)]
        ax.plot(
            separated["time_us"],
            separated["contact"],
            ls="none",
            marker="+",
            ms=4,
            mew=0.8,
            color=TRACK_COLOR,
            # About 8 markers per track, so that the wave under them stays visible.
            markevery=max(1, len(separated) // 8),
        )


def _draw_separated_ssw(ax, series: list[dict]) -> None:
    """SSW / F_m against distance from the collision point, one entry per series
    (``label``, ``distance``, ``ratio``, ``marker``, ``color``, ``filled``); a series
    without points gets a legend entry only."""
    for item in series:
        ax.plot(
            item["distance"],
            item["ratio"],
            ls="none",
            marker=item["marker"],
            ms=2.5,
            alpha=0.6,
            color=item["color"],
            mfc=item["color"] if item["filled"] else "none",
            mew=0.6,
            label=item["label"],
        )
    ax.set_xlabel("distance from the collision point (beads)")
    ax.set_ylabel("SSW amplitude / F$_m$")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), fontsize=6, frameon=False)


def ssw_series(track: pd.DataFrame) -> list[dict]:
    """The right panel's series: one per model and chain (LSTW; RSTW is its mirror)."""
    rows = track[track["wave"] == "LSTW"]
    colors = model_colors(list(dict.fromkeys(rows["model"])))
    chains = sorted({int(n) for n in rows["N"]})
    series = []
    for (model, n), group in rows.groupby(["model", "N"], sort=True):
        separated = group[group["separated"].astype(bool)]
        marker = chain_marker(int(n), chains)
        label = f"{model}, N = {n}"
        if separated.empty:
            label += ": never separated"
        series.append(
            {
                "label": label,
                "distance": separated["distance_beads"].to_numpy(float),
                "ratio": (separated["force_N"] / separated["F_m_N"]).to_numpy(float),
                "marker": "s" if marker == "x" else marker,
                "color": colors[model],
                "filled": marker != "x",
            }
        )
    return series


def fig_ssw_spacetime(
    fields: dict[int, tuple[Field, int]],
    track: pd.DataFrame,
    model: str,
    long_fields: dict[int, tuple[Field, int]] | None = None,
) -> Figure:
    """The space-time figure: field of one collision per chain of ``model`` (the paper's
    chains on top, the long chains below), and SSW amplitude against distance for every
    model and chain.

    Parameters
    ----------
    fields : dict
        N -> (pooled field of the chain's collisions, shot shown), the paper's chains.
    track : DataFrame
        ``ssw_track.csv``.
    model : str
        Model of the fields.
    long_fields : dict, optional
        The same for the long chains (config ``long_chains``).
    """
    long_fields = long_fields or {}
    columns = max(len(fields), len(long_fields), 1)
    rows = 2 if long_fields else 1
    fig = new_figure(3.4 * columns + 3.4, 3.3 * rows + 0.6)
    with mpl.rc_context(STYLE):
        grid = fig.add_gridspec(rows, columns + 1, width_ratios=[1.0] * columns + [1.0])
        mesh = None
        for row, chains in enumerate((fields, long_fields)[:rows]):
            for column, (n, field) in enumerate(sorted(chains.items())):
                ax = fig.add_subplot(grid[row, column])
                mesh = _field_panel(ax, n, field, track, model)
        side = fig.add_subplot(grid[0, columns])
        _draw_separated_ssw(side, ssw_series(track))
        side.set_title("SSW where separated (all shots)", loc="left")
        if mesh is not None:
            fig.colorbar(mesh, ax=fig.axes[:-1], label="contact force / F$_m$", shrink=0.8)
        fig.legend(handles=_wave_handles(), loc="outside lower left", ncol=5, fontsize=6,
                   frameon=False)  # fmt: skip
    return fig


def _field_panel(ax, n: int, field: tuple[Field, int], track: pd.DataFrame, model: str):
    """One chain's field of the shot shown, with its waves and tracked SSW; the mesh."""
    pooled, shot = field
    rows = track[(track["model"] == model) & (track["N"] == n) & (track["shot"] == shot)]
    f_m = float(rows["F_m_N"].iloc[0])
    mesh = draw_field(ax, *field_image(pooled, shot, f_m))
    draw_waves(ax, rows)
    ax.set_title(f"{model}, N = {n}, F$_m$ = {f_m:.0f} N", loc="left")
    return mesh


def _wave_handles() -> list:
    line = mpl.lines.Line2D
    return [
        line([], [], color=WAVE_COLORS["LSTW"], label="LSTW"),
        line([], [], color=WAVE_COLORS["RSTW"], label="RSTW"),
        line([], [], color="0.4", ls="--", label="incident (before crossing)"),
        line([], [], color="0.4", ls="-", label="crossed (after)"),
        line([], [], color=TRACK_COLOR, ls="none", marker="+", label="SSW tracked (separated)"),
    ]
