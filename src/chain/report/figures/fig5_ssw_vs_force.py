"""Fig. 5: the secondary solitary wave (SSW). (a) Its amplitude against the incident
amplitude F_m at the paper's sensors, every series, with error bars; (b) SSW / F_m
against the distance from the collision point, where it has separated.

Panel (a) draws every measurable row of ``ssw.csv`` (method ``residual``): a colour per
series (simulation models; the experiment, real or a MODEL of the apparatus, black), a
marker per chain. Filled: resolved as a separate wave (the strict rule). Open with an
error bar: measured above its error but not resolved. Open with a downward arrow: an
upper limit, drawn at value + error. Thin lines: the proportional fits of
``ssw_fits.csv`` (slope ± statistical ± systematic error in the legend, with the number
of resolved points). Panel (b) draws the separated rows of ``ssw_track.csv`` (LSTW; RSTW
is its mirror), every shot, the paper's sensor positions (grey) and where each chain's
SSW first separates (dotted, ``ssw_speed.csv``). Nothing is computed here.
"""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from chain.analysis.rows import usable_rows
from chain.report.figures import picks
from chain.report.figures.style import STYLE, chain_marker, model_colors, new_figure, plain_numbers
from chain.report.naming import series_name
from chain.report.printed import plus_minus_stat_sys

#: Length of an upper-limit arrow, as a fraction of the drawn value (log axis).
ARROW_FRACTION = 0.35

#: Legend note of a series with no measurable SSW row.
NOTHING_MEASURED = "no measurable SSW"

#: Colour of the paper's sensor positions in panel (b).
SENSOR_COLOR = "0.6"


def fig5_ssw_vs_force(
    ssw: pd.DataFrame,
    fits: pd.DataFrame | None = None,
    track: pd.DataFrame | None = None,
    speed: pd.DataFrame | None = None,
    *,
    sensor_distances: dict[int, float] | None = None,
    experiment_label: str = "experiment",
) -> Figure:
    """Fig. 5, both panels (panel (b) only with ``track``).

    Parameters
    ----------
    ssw, fits : DataFrame
        ``ssw.csv`` and ``ssw_fits.csv``.
    track, speed : DataFrame, optional
        ``ssw_track.csv`` and ``ssw_speed.csv``.
    sensor_distances : dict, optional
        N -> distance of the paper's sensors from the collision point, beads.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    """
    panels = 1 if track is None else 2
    fig = new_figure(5.6 * panels, 5.4)
    with mpl.rc_context(STYLE):
        axes = np.atleast_1d(fig.subplots(1, panels))
        draw_ssw_vs_force(axes[0], ssw, fits, experiment_label=experiment_label)
        axes[0].set_title("(a) at the paper's sensors", loc="left")
        if track is not None:
            draw_ssw_vs_distance(axes[1], track, speed, sensor_distances or {})
            axes[1].set_title("(b) along the chain, where separated", loc="left")
    return fig


def draw_ssw_vs_force(ax, ssw: pd.DataFrame, fits=None, *, experiment_label="experiment"):
    """Panel (a) on ``ax``: SSW amplitude against F_m (log-log), every series, errors
    and upper limits, proportional fits; legend below the axes."""
    every = picks.main_method(ssw)
    rows = usable_rows(every, ["F_m_N", "ssw_N", "ssw_err_N"], "Fig. 5 SSW rows")
    colors = model_colors(picks.simulated_models(every))
    all_n = sorted({int(n) for n in every["N"]})
    fitted = _fit_rows(fits)
    keys = ["source", "model", "N"]
    for (source, model, n), shots in every.groupby(keys, sort=True):
        group = rows[(rows["source"] == source) & (rows["model"] == model) & (rows["N"] == n)]
        style, label = _series_style(source, model, int(n), colors, all_n, experiment_label)
        if group.empty:
            ax.plot([], [], ls="none", marker=style["marker"], color=style["color"],
                    label=f"{label}: {NOTHING_MEASURED} (0 of {len(shots)})")  # fmt: skip
            continue
        fit = fitted.get((source, model, int(n)))
        label += _fit_label(fit, group)
        if fit is not None and np.isfinite(fit["slope"]):
            grid = np.geomspace(group["F_m_N"].min(), group["F_m_N"].max(), 20)
            ax.plot(grid, fit["slope"] * grid, color=style["color"], lw=0.7, alpha=0.7)
        _draw_points(ax, group, style, label)
    if rows.empty:
        ax.text(0.5, 0.5, f"{NOTHING_MEASURED} in any series", transform=ax.transAxes,
                ha="center", va="center", fontsize=8, color="0.35")  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_numbers(ax.xaxis)
    plain_numbers(ax.yaxis)
    ax.set_xlabel("incident amplitude F$_m$ (N)")
    ax.set_ylabel("SSW amplitude (N)")
    handles, labels = ax.get_legend_handles_labels()
    handles += _key_handles()
    labels += [h.get_label() for h in _key_handles()]
    ax.legend(
        handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=5.5,
        frameon=False, ncol=1,
    )  # fmt: skip


def _draw_points(ax, group: pd.DataFrame, style: dict, label: str) -> None:
    """Resolved filled, measured open with error bars, upper limits open with arrows."""
    limit = group["upper_limit"].astype(bool)
    resolved = group["resolved"].astype(bool) & ~limit
    measured = ~limit & ~resolved
    for mask, face in ((resolved, style["color"]), (measured, "white")):
        part = group[mask]
        ax.errorbar(
            part["F_m_N"], part["ssw_N"], yerr=part["ssw_err_N"], ls="none", ms=4.5,
            marker=style["marker"], color=style["color"], mfc=face, mew=0.9, elinewidth=0.6,
            capsize=1.5,
        )  # fmt: skip
    top = group[limit]
    top = top[(top["ssw_N"] + top["ssw_err_N"]) > 0]
    level = (top["ssw_N"] + top["ssw_err_N"]).to_numpy(float)
    ax.errorbar(
        top["F_m_N"], level, yerr=ARROW_FRACTION * level, uplims=True, ls="none",
        ms=4.5, marker=style["marker"], color=style["color"], mfc="white", mew=0.9,
        elinewidth=0.6, capsize=1.5,
    )  # fmt: skip
    # One legend entry per series (the markers above carry none).
    ax.plot([], [], ls="-", lw=0.7, marker=style["marker"], color=style["color"],
            mfc=style["color"], ms=4.5, label=label)  # fmt: skip


def _key_handles() -> list:
    """Legend entries explaining the marker fills."""
    line = mpl.lines.Line2D
    return [
        line([], [], ls="none", marker="o", color="0.3", label="filled: resolved (separate wave)"),
        line([], [], ls="none", marker="o", color="0.3", mfc="white", label="open + bar: measured"),
        line([], [], ls="none", marker="$\\downarrow$", color="0.3",
             label="arrow: upper limit at value + error"),
    ]  # fmt: skip


def _fit_rows(fits) -> dict:
    """``{(source, model, N): fit row}`` of the drawn method's per-chain fits."""
    if fits is None or not len(fits):
        return {}
    rows = picks.main_method(fits)
    rows = rows[rows["N"].astype(str) != "pooled"]
    return {(r["source"], r["model"], int(r["N"])): r for _, r in rows.iterrows()}


def _fit_label(fit, group: pd.DataFrame) -> str:
    """', SSW/F_m = (3.4 ± < 0.1 (stat) ± 2.1 (sys)) %, 0 of 24 resolved'."""
    resolved = int(group["resolved"].astype(bool).sum())
    count = f"{resolved} of {len(group)} resolved"
    if fit is None or not np.isfinite(fit["slope"]):
        return f": {count}"
    scaled = (100 * fit["slope"], 100 * fit["slope_stat"], 100 * fit["slope_sys"])
    return f": SSW/F$_m$ = ({plus_minus_stat_sys(*scaled)}) %, {count}"


def _series_style(source, model, n, colors, all_n, experiment_label) -> tuple[dict, str]:
    """Marker style and legend label of one series."""
    marker = chain_marker(n, all_n)
    if marker == "x":
        marker = "s"  # a cross cannot be filled
    color = colors.get(model, "black") if source == "simulation" else "black"
    label = series_name(source, model, experiment_label, n)
    return {"marker": marker, "color": color}, label


def draw_ssw_vs_distance(ax, track: pd.DataFrame, speed=None, sensor_distances=None) -> None:
    """Panel (b) on ``ax``: SSW / F_m of the separated rows against the distance from
    the collision point, a colour per model and a marker per chain; the paper's sensor
    positions (grey bands) and the first separated distance of each chain (dotted)."""
    rows = track[track["wave"] == "LSTW"]
    colors = model_colors(list(dict.fromkeys(rows["model"])))
    chains = sorted({int(n) for n in rows["N"]})
    sensor_chains = set(sensor_distances or {})
    for (model, n), group in rows.groupby(["model", "N"], sort=True):
        separated = group[group["separated"].astype(bool)]
        marker = chain_marker(int(n), chains)
        marker = "D" if marker == "x" else marker  # "s" may be a long chain's
        label = f"{model}, N = {n}" + ("" if len(separated) else ": never separated")
        ax.plot(
            separated["distance_beads"], separated["force_N"] / separated["F_m_N"],
            ls="none", marker=marker, ms=3 if n in sensor_chains else 2, color=colors[model],
            alpha=0.6, mew=0.6,
            mfc="white" if n % 2 else colors[model], label=label,
        )  # fmt: skip
    for distance in sorted(set((sensor_distances or {}).values())):
        ax.axvline(distance, color=SENSOR_COLOR, lw=2.5, alpha=0.5, zorder=0)
    if sensor_distances:
        chains = ", ".join(f"{d:g} (N = {n})" for n, d in sorted(sensor_distances.items()))
        ax.plot([], [], color=SENSOR_COLOR, lw=2.5, alpha=0.5, label=f"paper's sensors: {chains}")
    _draw_separation(ax, speed, colors)
    ax.set_yscale("log")
    if not rows["separated"].astype(bool).any():  # an empty log axis needs its own limits
        ax.set_ylim(1e-3, 1e-1)
        ax.text(0.5, 0.5, "no separated SSW on any chain of this run", transform=ax.transAxes,
                ha="center", va="center", fontsize=7, color="0.3")  # fmt: skip
    ax.set_xlabel("distance from the collision point (beads)")
    ax.set_ylabel("SSW amplitude / F$_m$ (separated)")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=5.5, frameon=False,
              ncol=2)  # fmt: skip


def _draw_separation(ax, speed, colors) -> None:
    """Dotted line where each chain's SSW first separates (``ssw_speed.csv``, LSTW)."""
    if speed is None or not len(speed):
        return
    rows = speed[(speed["wave"] == "LSTW") & speed["distance_beads"].notna()]
    for row in rows.itertuples():
        ax.axvline(row.distance_beads, color=colors.get(row.model, "0.3"), ls=":", lw=0.8)
    ax.plot([], [], color="0.3", ls=":", lw=0.8, label="first separated (per chain)")
