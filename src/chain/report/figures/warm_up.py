"""The figures' warm-up: what a process does once so that the processes it forks save
their figures without the costs of a first save.

A figure job's first save imported matplotlib's PDF backend and fontTools, built the
mathtext parser and loaded the fonts (~0.4 s a job). The job server
(:mod:`chain.pipeline.job_server`) runs these steps before it forks the jobs. Apart
from :mod:`chain.report.figures.style`, whose settings it uses, so that no figure's
rule depends on it: editing it redraws no figure.
"""

from __future__ import annotations

import io
from collections.abc import Callable

import matplotlib as mpl
from matplotlib.figure import Figure

from chain.report.figures import style


def warm_up_steps() -> list[Callable[[], None]]:
    """A small figure built, saved as PDF and as PNG into memory: three steps of
    0.2-0.8 s, to be run in this order, between which the caller may fork. A process
    forked after all three finds matplotlib's PDF backend and fontTools imported, the
    mathtext parser built and the fonts loaded; the bytes it saves are those of a cold
    process (tests/test_figures.py). Each step applies :data:`style.STYLE` only while
    it runs: a process forked in between has matplotlib's defaults, as a fresh one.
    Nothing is written."""
    figures: list[Figure] = []

    def build() -> None:
        import fontTools.subset  # noqa: F401 (the PDF's font subsets)
        import matplotlib.backends.backend_pdf  # noqa: F401

        with mpl.rc_context(style.STYLE):
            fig = Figure(figsize=(2.0, 1.5), layout="constrained")
            ax = fig.add_subplot()
            ax.loglog([1.0, 100.0], [1.0, 2.0], label=r"$\Delta = C\,F_m^{-1/6}$")
            ax.set(xlabel=r"$F_m$ (N)", ylabel=r"$|\Delta|$ ($\mu$s)", title="warm-up")
            ax.legend()
        figures.append(fig)

    def save(format: str, **options) -> None:
        with mpl.rc_context(style.STYLE):
            figures[0].savefig(io.BytesIO(), format=format, **options)

    def save_pdf() -> None:
        save("pdf", metadata=style.PDF_METADATA)

    def save_png() -> None:
        save("png", metadata=style.PNG_METADATA, dpi=style.PNG_DPI)

    return [build, save_pdf, save_png]
