"""The one home of the figures' look: rc parameters, colours, markers, labels, saving.

Every figure module draws inside ``matplotlib.rc_context(STYLE)`` and saves with
:func:`save_figure`, so that fonts, sizes and file metadata are the same in every figure
and two rebuilds give identical bytes. Figures are built without pyplot (no global
state, no display backend). Editing this module redraws every figure, and nothing else.
"""

from __future__ import annotations

import functools
import os
import sys
import traceback
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import matplotlib as mpl
from matplotlib.figure import Figure

from chain.atomic import atomic_output

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
    # Titles at the top of their axes. The default (None) moves a title above whatever
    # sits on top of the axes (top ticks, an offset text), which no figure here has, and
    # costs a third of the layout time; same bytes.
    "axes.titley": 1.0,
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

#: Colours of the waves in the trace figures (and the setup's wave arrows).
LSTW_COLOR = "#1f4e9c"
RSTW_COLOR = "#c0392b"
REFERENCE_COLOR = "black"
#: Colour of the secondary solitary wave's marker.
SSW_COLOR = "#2a7f3f"

#: Seconds to microseconds, for time axes.
MICRO = 1e6


# ---- saving ---------------------------------------------------------------------


def save_figure(fig: Figure, path: str | os.PathLike, *, processes: int = 1) -> list[Path]:
    """Write ``fig`` as ``<path>.pdf`` and ``<path>.png`` with fixed metadata; returns
    their paths.

    Each file is written to a temporary name beside its destination and renamed, so
    an interrupted write never leaves a partial figure. No creation date or software
    version goes into the files: two rebuilds of the same figure give the same bytes.

    Parameters
    ----------
    fig : Figure
        The figure.
    path : path
        Destination without extension; parent folders are created.
    processes : int
        Processes that may draw at once (a job's cores): with 2 or more (and
        ``os.fork``), the PNG is drawn in a forked process while this one draws the PDF,
        the same bytes as one after the other (``tests/test_figures.py``).
    """
    stem = Path(path)
    if stem.suffix in (".pdf", ".png"):
        stem = stem.with_suffix("")
    stem.parent.mkdir(parents=True, exist_ok=True)
    pdf, png = (stem.with_name(f"{stem.name}.{extension}") for extension in ("pdf", "png"))
    with mpl.rc_context(STYLE), _rasterize_only_when_drawing():
        if processes > 1 and hasattr(os, "fork"):
            _save_side_by_side(fig, pdf, png)
        else:
            _save_pdf(fig, pdf)
            _save_png(fig, png)
    return [pdf, png]


def _save_pdf(fig: Figure, target: Path) -> None:
    with atomic_output(target) as temporary:
        fig.savefig(temporary, format="pdf", metadata=PDF_METADATA)


def _save_png(fig: Figure, target: Path) -> None:
    with atomic_output(target) as temporary:
        fig.savefig(temporary, format="png", metadata=PNG_METADATA, dpi=PNG_DPI)


def _save_side_by_side(fig: Figure, pdf: Path, png: Path) -> None:
    """The PDF drawn here and the PNG in a forked child, at the same time.

    Saved one after the other, the PNG is drawn from the layout the PDF's save left
    (constrained layout starts from the positions it finds): the child first lays the
    figure out as the PDF's save does, drawing nothing, so that its PNG has the bytes
    of the sequential save.
    """
    for stream in (sys.stdout, sys.stderr):
        stream.flush()  # nothing buffered is written twice
    child = os.fork()
    if child == 0:
        status = 1
        try:
            _lay_out_as_the_pdf_save_does(fig)
            _save_png(fig, png)
            status = 0
        except BaseException:  # an interruption too: the atomic writer has cleaned up
            traceback.print_exc()
        finally:
            sys.stderr.flush()
            os._exit(status)
    try:
        _save_pdf(fig, pdf)
    finally:
        _, status = os.waitpid(child, 0)
    if status != 0:
        raise RuntimeError(f"writing {png} failed in its process (traceback above)")


def _lay_out_as_the_pdf_save_does(fig: Figure) -> None:
    """What ``savefig(format="pdf")`` does to a figure with a layout engine before it
    draws: one draw with a PDF renderer, drawing switched off (matplotlib 3.11,
    ``FigureCanvasBase.print_figure``)."""
    from matplotlib.backend_bases import _get_renderer
    from matplotlib.backends.backend_pdf import FigureCanvasPdf

    if fig.get_layout_engine() is None:
        return
    canvas = FigureCanvasPdf(fig)
    renderer = _get_renderer(fig, functools.partial(canvas.print_pdf, metadata=PDF_METADATA))
    with renderer._draw_disabled():
        fig.draw(renderer)


@contextmanager
def _rasterize_only_when_drawing() -> Iterator[None]:
    """Skip the rasterizing of the PDF's layout pass, which draws nothing.

    ``savefig`` of a figure with a layout engine first draws it once with the
    renderer's drawing switched off, to lay it out, then draws it for real. In a PDF
    (matplotlib 3.11) the switch reaches the vector renderer only: the artists drawn
    ``rasterized=True`` are still rendered to pixels in that pass and the pixels thrown
    away (2.7 s of the space-time figure's 10). Within this context the mixed-mode
    renderer rasterizes only when its vector renderer draws; the written bytes are the
    same (``tests/test_figures.py``).
    """
    from matplotlib.backends.backend_mixed import MixedModeRenderer

    start, stop = MixedModeRenderer.start_rasterizing, MixedModeRenderer.stop_rasterizing

    def drawing(renderer) -> bool:
        # RendererBase._draw_disabled shadows the draw_* methods on the instance.
        return "draw_image" not in vars(renderer._vector_renderer)

    def start_if_drawing(renderer):
        if drawing(renderer):
            start(renderer)

    def stop_if_drawing(renderer):
        if drawing(renderer):
            stop(renderer)

    MixedModeRenderer.start_rasterizing = start_if_drawing
    MixedModeRenderer.stop_rasterizing = stop_if_drawing
    try:
        yield
    finally:
        MixedModeRenderer.start_rasterizing = start
        MixedModeRenderer.stop_rasterizing = stop


# ---- figures and axes -------------------------------------------------------------


def new_figure(width: float, height: float) -> Figure:
    """A figure of ``width`` x ``height`` inches with constrained layout, in the style."""
    with mpl.rc_context(STYLE):
        return Figure(figsize=(width, height), layout="constrained")


def axes_or_new(ax, width: float = 4.8, height: float = 3.6):
    """``(figure, axes)``: the given axes and their figure, or new axes on a new figure
    of ``width`` x ``height`` inches."""
    if ax is not None:
        return ax.figure, ax
    fig = new_figure(width, height)
    with mpl.rc_context(STYLE):
        return fig, fig.add_subplot()


def add_legend(fig, ax, own: bool, loc: str) -> None:
    """Below the axes on a figure of our own (never over the data); inside otherwise,
    at ``loc``."""
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


def plain_log_ticks(axis) -> None:
    """Ticks 1, 1.5, 2, 3, 5, 7 x 10^k written as plain numbers on a short log axis."""
    axis.set_major_locator(mpl.ticker.LogLocator(base=10, subs=(1.0, 1.5, 2.0, 3.0, 5.0, 7.0)))
    axis.set_major_formatter(mpl.ticker.StrMethodFormatter("{x:g}"))
    axis.set_minor_formatter(mpl.ticker.NullFormatter())


def plain_numbers(axis) -> None:
    """Major tick labels of ``axis`` written as plain numbers (``{x:g}``)."""
    axis.set_major_formatter(mpl.ticker.StrMethodFormatter("{x:g}"))


# ---- colours, markers, labels ------------------------------------------------------


def model_colors(models: Sequence[str]) -> dict[str, str]:
    """A colour per model name: fixed for elastic/viscoelastic, the cycle otherwise."""
    colors = {}
    extra = iter(_EXTRA_COLORS * 4)
    for name in models:
        colors[name] = MODEL_COLORS.get(name) or next(extra)
    return colors


def chain_marker(n: int, order: Sequence[int] = ()) -> str:
    """Marker of the chain of ``n`` beads: circle for 25, cross for 26 as in the paper;
    other chains take the next markers in the order of ``order``."""
    if n in N_MARKERS:
        return N_MARKERS[n]
    others = [m for m in order if m not in N_MARKERS]
    index = others.index(n) if n in others else 0
    return _EXTRA_MARKERS[index % len(_EXTRA_MARKERS)]


def us_n16(value: float) -> str:
    """A constant C in µs N^(1/6), for legends."""
    return f"{value:.2f} µs N$^{{1/6}}$"


def draw_even_odd(ax, n_beads, values, stderr, color: str, label: str) -> None:
    """A quantity against N with its error bars, even chains as filled circles and odd
    chains as open diamonds (the parity and sweep figures), joined by a faint line.

    Parameters
    ----------
    ax : Axes
        Where to draw.
    n_beads : Series of int
        Number of beads N of each point, sorted.
    values, stderr : Series of float
        The quantity and its standard error, in the axis' unit.
    color : str
        Colour of the series.
    label : str
        Legend label; ", even N" / ", odd N" is appended.
    """
    ax.plot(n_beads, values, color=color, lw=0.6, alpha=0.5)
    even = (n_beads.to_numpy() % 2) == 0
    for parity, part, filled in (("even", even, True), ("odd", ~even, False)):
        if not part.any():
            continue
        ax.errorbar(
            n_beads[part],
            values[part],
            yerr=stderr[part],
            ls="none",
            marker="o" if filled else "D",
            ms=5,
            color=color,
            mfc=color if filled else "white",
            mec=color,
            capsize=2,
            label=f"{label}, {parity} N",
        )
