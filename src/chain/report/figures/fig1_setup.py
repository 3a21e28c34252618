"""Fig. 1: the setup, drawn to scale from the configured chains.

Lengths are drawn in mm: N beads on the track, the two strikers, the split sensor beads
S1 and S2 wired to the acquisition, and the directions of the left- and right-launched
waves (LSTW, RSTW).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import matplotlib as mpl
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle, FancyArrowPatch, FancyBboxPatch, Rectangle

from chain.report.figures.style import LSTW_COLOR, RSTW_COLOR, STYLE, new_figure

#: Colours of the drawing.
TRACK_COLOR, TRACK_TEXT_COLOR = "#cfe3ef", "#4a6f86"
BEAD_COLOR, SENSOR_BEAD_COLOR, SENSOR_COLOR = "#d9d9d9", "#f3d9a4", "#7a4b00"
BOX_FACE, BOX_EDGE = "#eef3e8", "#4d6b35"


def fig1_setup(
    chains: Sequence[Mapping],
    *,
    bead_radius_m: float = 0.013,
    striker_radius_m: float = 0.004,
    material: str = "steel_100C6",
    max_rows: int = 6,
) -> Figure:
    """Fig. 1: the setup (see the module docstring), one chain per row.

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
    shown = _shown_chains(chains, max_rows)
    radius = bead_radius_m * 1e3  # drawn in mm
    striker = striker_radius_m * 1e3
    span = 2 * radius * max(int(c["N"]) for c in shown)
    fig = new_figure(7.0, 0.95 * len(shown) + 0.45)
    with mpl.rc_context(STYLE):
        axes = fig.subplots(len(shown), 1, squeeze=False)[:, 0]
        for ax, entry in zip(axes, shown):
            draw_chain(ax, int(entry["N"]), list(entry["sensors"]), radius, striker, span)
        title = (
            f"Setup: free chains of {material} beads, R = {radius:g} mm; strikers "
            f"R$_s$ = {striker:g} mm at both ends;\nsplit sensor beads S1, S2 "
            "(beads numbered 1..N from the left)"
        )
        if len(shown) < len(chains):
            title += f"; {len(shown)} of {len(chains)} chains shown"
        fig.suptitle(title, fontsize=8)
    return fig


def _shown_chains(chains: list, max_rows: int) -> list:
    """All chains, or ``max_rows`` of them evenly spaced."""
    if len(chains) <= max_rows:
        return chains
    picks = sorted(set(np.linspace(0, len(chains) - 1, max_rows).round().astype(int)))
    return [chains[i] for i in picks]


@dataclass(frozen=True)
class _Layout:
    """Where things go in one row, mm: bead centres and the row's landmarks."""

    n: int
    sensors: list
    radius: float
    striker: float
    span: float

    @property
    def centers(self) -> np.ndarray:
        return self.radius * (2 * np.arange(1, self.n + 1) - 1)

    @property
    def gap(self) -> float:
        return 2.5 * self.radius

    @property
    def length(self) -> float:
        return 2 * self.radius * self.n

    @property
    def left(self) -> float:
        return -self.gap - 2 * self.striker

    @property
    def right(self) -> float:
        # Common to all rows: the same scale in every row.
        return self.span + self.gap + 2 * self.striker

    @property
    def end(self) -> float:
        # This chain's right striker.
        return self.length + self.gap + 2 * self.striker

    @property
    def arrow_y(self) -> float:
        return self.radius + 19

    @property
    def box_y(self) -> float:
        return -self.radius - 30

    @property
    def box_size(self) -> tuple[float, float]:
        return min(170.0, 0.4 * self.span), 13.0


def draw_chain(ax, n: int, sensors: list[int], radius: float, striker: float, span: float):
    """One row of Fig. 1 on ``ax``: the chain of ``n`` beads with its ``sensors`` (bead
    numbers S1, S2), bead and striker radii and the longest chain's length ``span``, mm."""
    row = _Layout(n, sensors, radius, striker, span)
    _draw_beads(ax, row)
    _draw_strikers(ax, row)
    _draw_waves(ax, row)
    _draw_acquisition(ax, row)
    ax.text(row.end, -radius - 6, f"N = {n}", ha="right", va="top", fontsize=8, fontweight="bold")
    ax.set_xlim(row.left - striker, row.right + striker)
    ax.set_ylim(row.box_y - 4, row.arrow_y + 10)
    ax.set_aspect("equal")
    ax.axis("off")


def _draw_beads(ax, row: _Layout) -> None:
    """The track (Plexiglas) and the beads on it, sensor beads split."""
    radius, striker, left = row.radius, row.striker, row.left
    ax.add_patch(
        Rectangle(
            (left + striker, -radius - 4), row.end - left - 2 * striker, 4, color=TRACK_COLOR, lw=0
        )
    )
    ax.text(
        left + striker,
        -radius - 6,
        "track",
        ha="left",
        va="top",
        fontsize=6,
        color=TRACK_TEXT_COLOR,
    )
    for number, x in enumerate(row.centers, start=1):
        is_sensor = number in row.sensors
        face = SENSOR_BEAD_COLOR if is_sensor else BEAD_COLOR
        ax.add_patch(Circle((x, 0), radius, facecolor=face, edgecolor="#404040", lw=0.6))
        if is_sensor:
            ax.add_patch(Rectangle((x - 1.2, -radius), 2.4, 2 * radius, color=SENSOR_COLOR, lw=0))
        elif number in (1, row.n) or number % 5 == 0:
            ax.text(x, 0, str(number), ha="center", va="center", fontsize=5.5, color="#303030")


def _draw_strikers(ax, row: _Layout) -> None:
    """The two strikers, moving towards the chain."""
    gap, striker = row.gap, row.striker
    for side, x0, direction in ((0, -gap - striker, 1), (1, row.length + gap + striker, -1)):
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


def _draw_waves(ax, row: _Layout) -> None:
    """Arrows of the left- and right-launched waves above the chain."""
    centers, n, arrow_y = row.centers, row.n, row.arrow_y
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


def _draw_acquisition(ax, row: _Layout) -> None:
    """The acquisition box under the chain and the wires from the sensor beads."""
    centers, radius = row.centers, row.radius
    middle = 0.5 * (centers[0] + centers[-1])
    box_y = row.box_y
    box_w, box_h = row.box_size
    ax.add_patch(
        FancyBboxPatch(
            (middle - box_w / 2, box_y),
            box_w,
            box_h,
            boxstyle="round,pad=1.5",
            facecolor=BOX_FACE,
            edgecolor=BOX_EDGE,
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
    for label, bead in zip(("S1", "S2"), row.sensors):
        x = centers[bead - 1]
        ax.text(
            x,
            radius + 1.5,
            f"{label} (n = {bead})",
            ha="center",
            va="bottom",
            fontsize=6.5,
            color=SENSOR_COLOR,
            fontweight="bold",
        )
        x_box = middle - box_w / 2 + 8 if label == "S1" else middle + box_w / 2 - 8
        ax.plot(
            [x, x, x_box, x_box],
            [-radius, box_y + box_h + 8, box_y + box_h + 8, box_y + box_h + 1.5],
            color=SENSOR_COLOR,
            lw=0.7,
        )
