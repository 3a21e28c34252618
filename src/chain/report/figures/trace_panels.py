"""The panels shared by Fig. 2 (experiment) and Fig. 3 (simulation): forces at S1 and S2.

One column per chain, S1 on top and S2 below. In the collision shot the left-launched
wave (LSTW) is drawn solid and the right-launched one (RSTW) dashed: at S1 the first
pulse is the incident LSTW and the second the crossed RSTW, at S2 the other way round;
the trace is split at the minimum between the two pulses. The reference shot (LSTW
alone) is dotted. An inset zooms on what follows the crossed pulse, where the secondary
solitary wave (SSW) arrives. Which shots and rows are drawn is chosen in
:mod:`chain.report.figures.picks`.
"""

from __future__ import annotations

import math

import matplotlib as mpl
import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from chain.report.figures import picks
from chain.report.figures.style import (
    LSTW_COLOR,
    MICRO,
    REFERENCE_COLOR,
    RSTW_COLOR,
    SSW_COLOR,
    STYLE,
    new_figure,
)
from chain.traces import sensor_beads, sensor_column

#: Inset of the trace figures, axes fraction: width, height, and bottom edge.
INSET_WIDTH, INSET_HEIGHT, INSET_BOTTOM = 0.42, 0.52, 0.38

#: Line styles (colour, dash) of the two waves in a collision shot.
LSTW_STYLE, RSTW_STYLE = (LSTW_COLOR, "-"), (RSTW_COLOR, "--")


def trace_figure(
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
    """Fig. 2 or Fig. 3: the forces at S1 and S2 of one shot per chain.

    Parameters as in :func:`chain.report.figures.fig3_simulation_traces.fig3_simulation_traces`,
    and ``source`` (the rows drawn), ``title`` (the figure's title without the model)
    and ``selection`` (the acceptance protocol's table, or None).
    """
    chains = picks.split_by_chain(traces, source, model)
    # One column per chain; a single chain gets the width its legend and title need.
    fig = new_figure(max(3.4 * len(chains) + 0.4, 6.4), 5.0)
    letters = iter("ABCDEFGHIJKLMNOPQRSTUVWXYZ")
    with mpl.rc_context(STYLE):
        axes = fig.subplots(2, len(chains), squeeze=False, sharex="col")
        for column, (n, table) in enumerate(chains.items()):
            collision, reference = picks.representative_shots(
                table,
                pulses,
                selection,
                source=source,
                n=n,
                estimator=estimator,
                force=representative_force_N,
                index=representative_index,
            )
            beads = sensor_beads(table)
            panels = (("S1", beads[0]), ("S2", beads[-1]))
            for row, (sensor, bead) in enumerate(panels):
                ax = axes[row, column]
                times = draw_sensor(
                    ax, collision, reference, sensor, bead, beads[-1], pulses, ssw, estimator, inset
                )
                heading = f"({next(letters)}) N = {n}, {sensor} at n = {bead}"
                if row == 0:
                    heading += _shot_detail(collision, times)
                ax.set_title(heading, loc="left")
                ax.set_ylabel("force (N)")
                if row == 1:
                    ax.set_xlabel(
                        "time since launch (µs)" if source == "simulation" else "time (µs)"
                    )
        # The SSW marker's legend entry only where an inset marks one.
        marked = any(
            line.get_marker() == "v"
            for ax in fig.axes
            for box in ax.child_axes
            for line in box.get_lines()
        )
        fig.legend(
            handles=_legend_handles(inset and marked),
            loc="outside lower center",
            ncol=2,
            frameon=False,
        )
        fig.suptitle(_suptitle(title, source, next(iter(chains.values()))["model"].iloc[0]))
    return fig


def _shot_detail(collision, times) -> str:
    """Second line of a top panel's title: the launch speed and incident F_m."""
    f_m = times.get("incident", (None, None, None))[2]
    v0 = collision["v0_left_m_s"].iloc[0] if collision is not None else math.nan
    detail = []
    if np.isfinite(v0):
        detail.append(f"V$_0$ = {v0:.3g} m/s")
    if f_m is not None:
        detail.append(f"F$_m$ = {f_m:.0f} N")
    return "\n" + ", ".join(detail) if detail else ""


def _legend_handles(inset: bool) -> list[Line2D]:
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
                color=SSW_COLOR,
                marker="v",
                ls="none",
                label="secondary solitary wave (SSW): time and amplitude",
            )
        )
    return handles


def _suptitle(title: str, source: str, model_name) -> str:
    if source == "simulation":
        return f"{title}, {model_name} model"
    return title if str(model_name) in title else f"{title} (series {model_name})"


def draw_sensor(ax, collision, reference, sensor, bead, s2, pulses, ssw, estimator, inset):
    """One panel: the reference shot (dotted) and the collision shot split into its two
    waves at sensor ``sensor`` (bead ``bead``; ``s2`` is the S2 bead, whose reference
    pulse is the inset's template); returns the collision's pulse times at the sensor
    (:func:`chain.report.figures.picks.pulse_times`)."""
    column = sensor_column(bead)
    if reference is not None:
        ax.plot(reference["t_s"] * MICRO, reference[column], color=REFERENCE_COLOR, ls=":", lw=1.4)
    if collision is None:
        return {}
    meta = collision.iloc[0]
    time = collision["t_s"].to_numpy()
    force = collision[column].to_numpy()
    times = picks.pulse_times(pulses, meta, sensor, estimator)
    split = picks.split_index(time, force, times)
    # S1 meets the incident LSTW first, then the crossed RSTW; S2 the other way round.
    first, second = (LSTW_STYLE, RSTW_STYLE) if sensor == "S1" else (RSTW_STYLE, LSTW_STYLE)
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
            ref_times = picks.pulse_times(pulses, reference.iloc[0], "S2", estimator)
            template = (
                reference["t_s"].to_numpy(),
                reference[sensor_column(s2)].to_numpy(),
                ref_times.get("reference"),
            )
        marker = picks.ssw_marker(ssw, meta, sensor)
        draw_ssw_inset(ax, time, force, split, times, marker, second, template)
    return times


def inset_bounds(ax) -> list[float]:
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


def _crossed_peak(time, force, split, times) -> tuple[float, float, float]:
    """(time s, force N, duration tau s) of the crossed pulse; tau from the pulse table,
    else the full width at half maximum (about tau for a cos^6 pulse)."""
    crossed_time, crossed_force = time[split:], force[split:]
    i_peak = int(np.argmax(crossed_force))
    t_cross, f_cross = crossed_time[i_peak], float(crossed_force[i_peak])
    tau = times["crossed"][1] if "crossed" in times else math.nan
    if not np.isfinite(tau) or tau <= 0:
        half = crossed_time[crossed_force > 0.5 * f_cross]
        tau = max(float(half[-1] - half[0]), 1e-12)
    return t_cross, f_cross, tau


def draw_ssw_inset(ax, time, force, split, times, marker, style, template):
    """Zoom on the crossed pulse's trailing edge, where the secondary solitary wave (SSW)
    follows it: the crossed pulse (``style``: colour, dash), the reference pulse
    ``template`` (time s, force N, fitted (T, tau, F_m) or None) shifted and scaled onto
    it (peak on peak), and the SSW ``marker`` (time µs, amplitude N) of
    :mod:`chain.analysis.ssw`: a triangle just above the signal at the SSW's maximum (a
    bump behind the crossed pulse's trailing minimum), or, where the analysis found none
    resolved (``marker`` None), the words "SSW not resolved at this sensor"."""
    t_cross, f_cross, tau = _crossed_peak(time, force, split, times)
    start, stop = t_cross - 0.6 * tau, t_cross + 3.5 * tau
    if marker:
        stop = max(stop, marker[0] / MICRO + tau)
    top = min(f_cross, max(0.12 * f_cross, 2.5 * marker[1] if marker else 0.0))
    box = ax.inset_axes(inset_bounds(ax))
    window = (time >= start) & (time <= stop)
    if template is not None:
        _draw_template(box, template, times, t_cross, f_cross, start, stop)
    box.plot(time[window] * MICRO, force[window], color=style[0], ls=style[1], lw=1.0)
    if marker:
        _draw_ssw_marker(box, time, force, marker, top, tau)
    else:
        box.text(
            0.97,
            0.9,
            "SSW not resolved\nat this sensor",
            transform=box.transAxes,
            ha="right",
            va="top",
            fontsize=5.5,
            color=SSW_COLOR,
        )
    box.set_xlim(start * MICRO, stop * MICRO)
    box.set_ylim(-0.05 * top, top)
    box.tick_params(labelsize=5)
    box.set_title("crossed pulse, trailing edge", fontsize=5.5, pad=1.5)
    box.spines[["top", "right"]].set_visible(True)


def _draw_ssw_marker(box, time, force, marker, top, tau) -> None:
    """A triangle pointing down at the signal where the SSW peaks, and its amplitude."""
    level = float(np.interp(marker[0] / MICRO, time, force)) + 0.08 * top
    box.plot(marker[0], level, marker="v", color=SSW_COLOR, ms=4, ls="none")
    box.text(
        marker[0] + 0.25 * tau * MICRO,
        level,
        f"SSW {marker[1]:.2g} N",
        ha="left",
        va="center",
        fontsize=5.5,
        color=SSW_COLOR,
    )


def _draw_template(box, template, times, t_cross, f_cross, start, stop) -> None:
    """The reference pulse moved onto the crossed one: by the fitted times and
    amplitudes when both are known, else peak on peak."""
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
