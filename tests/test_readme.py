"""The library example of the documentation runs as printed: every ```python block of
README.md and of docs/*.md executes (each file in its own namespace), and the example
of docs/library.md fits a physical pulse."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
LIBRARY = ROOT / "docs" / "library.md"


def _blocks(page: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)


def _run(page: Path) -> dict:
    namespace: dict = {}
    for block in _blocks(page):
        exec(compile(block, str(page), "exec"), namespace)
    return namespace


def test_the_library_example_runs_and_fits_a_physical_pulse():
    assert _blocks(LIBRARY), "docs/library.md has no python example"
    fit = _run(LIBRARY)["fit"]
    assert fit.ok
    # V0 = 0.3 m/s launches a wave of about 1 kN * 0.3^(6/5) ~ 235 N (less with dissipation).
    assert 150 < fit.peak_force < 260


def test_every_other_python_example_runs():
    for page in PAGES:
        if page != LIBRARY:
            _run(page)


def test_the_readme_links_the_library_page():
    assert "docs/library.md" in (ROOT / "README.md").read_text(encoding="utf-8")
