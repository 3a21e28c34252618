"""A kernel version is compiled by one process at a time (chain.physics.compile_once):
a second process that needs it waits, then loads the first one's from numba's cache.
Shown on a small kernel (a step loop would cost ~15 s per compile)."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import textwrap

from chain.physics import compile_once

KERNEL = """\
import numba


@numba.njit(cache=True)
def twice(x):
    return 2.0 * x
"""

#: The second process: say it is about to call, call, report numba's cache counts.
SECOND = """\
import toy_kernel as toy
from chain.physics import compile_once
print("calling", flush=True)
result = compile_once.shared(toy.twice)(1.5)
stats = toy.twice.stats
print(result, sum(stats.cache_hits.values()), sum(stats.cache_misses.values()), flush=True)
"""


def test_a_second_process_loads_the_version_the_first_compiled(tmp_path, monkeypatch):
    """This process holds the version's lock while the second one starts its call,
    compiles the version only then, and releases it: the second one waited and loaded
    that version from the cache (one hit, no miss) instead of compiling it as well.
    (Without the lock it would have compiled at once: a miss.) No clock: each side
    waits for a line or a lock."""
    (tmp_path / "toy_kernel.py").write_text(KERNEL)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "toy_kernel", raising=False)
    toy = importlib.import_module("toy_kernel")
    signature = (toy.twice.typeof_pyval(1.5),)
    script = tmp_path / "second.py"
    script.write_text(textwrap.dedent(SECOND))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    with compile_once._version_lock(toy.twice, signature):
        second = subprocess.Popen(
            [sys.executable, str(script)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        assert second.stdout.readline().strip() == "calling", second.stderr.read()
        toy.twice.compile(signature)  # saved to the cache while the second one waits
    out, err = second.communicate(timeout=600)
    assert second.returncode == 0, err
    assert out.split() == ["3.0", "1", "0"], out


def test_a_kernel_without_cache_is_called_without_a_lock():
    """A kernel numba does not cache has no folder to lock in: the call just runs."""
    import numba

    @numba.njit
    def add(a, b):
        return a + b

    assert compile_once.shared(add)(2, 3) == 5
    assert len(add.overloads) == 1


def test_jobs_on_a_node_with_an_empty_cache_compile_the_kernel_once(cold_step_loop_jobs):
    """Three jobs start together on a node whose numba cache (NUMBA_CACHE_DIR, empty)
    lacks the kernel: one compiles it, the two others wait for it and load it from
    the cache, and all three get the same bits. No clock: every job has imported the
    library before any of them is let go, and each waits on the lock, not a delay.
    (Without chain.physics.compile_once all three compiled: three misses.) The jobs
    are conftest.py's :func:`cold_step_loop_jobs`, run once for this test and one of
    tests/test_kernels.py."""
    reports, cache = cold_step_loop_jobs
    assert sorted(report["misses"] for report in reports) == [0, 0, 1], reports
    assert sorted(report["hits"] for report in reports) == [0, 1, 1], reports
    assert len({report["digest"] for report in reports}) == 1
    assert list(cache.rglob("*_integrate_part*.nbi"))  # the cache is there
