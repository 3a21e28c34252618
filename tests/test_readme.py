"""The README's library example runs as printed."""

from __future__ import annotations

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_example_runs():
    """Every ```python block of the README executes, and the fitted pulse is physical."""
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "the README has no python example"
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), namespace)
    fit = namespace["fit"]
    assert fit.ok
    # V0 = 0.3 m/s launches a wave of about 1 kN * 0.3^(6/5) ~ 235 N (less with dissipation).
    assert 150 < fit.peak_force < 260
