"""numba's cache kept in step with the files a kernel inlines (chain.physics.kernel_cache).

numba keys a cached kernel on its own file only: a kernel that inlines a function of
another file ran that function's old code from the cache after the file was edited
(the lean kernel and slopes.py, 27 Nov 2026). Tested on a two-file package small enough
to compile in a fraction of a second, in fresh interpreters (numba's cache is read and
written per process).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from chain.physics.kernel_cache import SOURCES, forget_if_sources_changed, sources_digest

PHYSICS = Path(__file__).resolve().parents[1] / "src" / "chain" / "physics"

HELPER = """
import numba

@numba.njit(inline="always")
def scaled(x):
    return {factor} * x
"""

KERNEL = """
import numba

from chain.physics.kernel_cache import forget_if_sources_changed
from helper import scaled


@numba.njit(cache=True)
def kernel(x):
    return scaled(x)


forget_if_sources_changed(__name__, globals(), sources=[{helper!r}, __file__])
"""


def run_kernel(folder: Path) -> float:
    """kernel(1.0) in a fresh interpreter that imports the package in ``folder``."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(folder), *sys.path])}
    env.pop("NUMBA_CACHE_DIR", None)  # the cache beside the sources, as in a checkout
    done = subprocess.run(
        [sys.executable, "-c", "import kern; print(kern.kernel(1.0))"],
        capture_output=True, text=True, env=env, cwd=folder, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    return float(done.stdout.split()[-1])


def test_an_edited_helper_is_compiled_again(tmp_path):
    helper = tmp_path / "helper.py"
    helper.write_text(HELPER.format(factor=2.0))
    (tmp_path / "kern.py").write_text(KERNEL.format(helper=str(helper)))
    assert run_kernel(tmp_path) == 2.0
    assert (tmp_path / "__pycache__" / "kern.sources.sha256").is_file()
    assert run_kernel(tmp_path) == 2.0  # from the cache, same sources
    helper.write_text(HELPER.format(factor=3.0))  # the kernel's own file untouched
    assert run_kernel(tmp_path) == 3.0


def test_the_digest_covers_each_source_and_its_name(tmp_path):
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("x = 1\n")
    b.write_text("y = 2\n")
    first = sources_digest([a, b])
    assert sources_digest([a, b]) == first
    b.write_text("y = 3\n")
    assert sources_digest([a, b]) != first
    c = tmp_path / "c.py"
    c.write_text("y = 3\n")
    assert sources_digest([a, c]) != sources_digest([a, b])


def test_the_physics_kernels_name_every_file_they_are_compiled_from():
    """The lean kernel inlines slopes.py; the reference kernel reads kernels.py's
    constants: every chain.physics module that imports numba and defines or inlines a
    kernel is a source of the digest, and the kernels' modules check it."""
    compiled = {p.name for p in PHYSICS.glob("*.py") if "numba.njit" in p.read_text()}
    assert compiled - {"compile_once.py"} <= set(SOURCES)
    for name in ("kernels.py", "reference_kernel.py"):
        assert (
            "kernel_cache.forget_if_sources_changed(__name__, globals())"
            in (PHYSICS / name).read_text()
        )


def test_kernels_without_a_cache_are_left_alone(tmp_path):
    """A kernel compiled without numba's cache has no folder: no digest, nothing removed."""
    import numba

    @numba.njit
    def uncached(x):
        return x

    helper = tmp_path / "helper.py"
    helper.write_text("x = 1\n")
    assert not forget_if_sources_changed(__name__, {"uncached": uncached}, sources=[helper])
    assert not list(tmp_path.glob("**/*.sha256"))


def test_unreadable_sources_leave_the_cache_as_numba_keeps_it(tmp_path):
    """Sources that are not files (a zipped install): the kernels import, nothing is
    removed and no digest is written."""
    import numba

    @numba.njit(cache=True)
    def cached(x):
        return x

    missing = tmp_path / "no_such_source.py"
    assert not forget_if_sources_changed(__name__, {"cached": cached}, sources=[missing])
