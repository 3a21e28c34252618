"""What a simulate job asks a batch scheduler for (chain.pipeline.plan.resources): the memory
request covers the measured peak of a real simulation, and grows with N and duration."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from chain.errors import ParameterError
from chain.physics.builders import uniform_chain
from chain.physics.materials import get_material
from chain.pipeline.plan.resources import (
    BASE_MB,
    BYTES_PER_BEAD_SAMPLE,
    MAX_THREADS,
    MIN_RUNTIME_MIN,
    SNAKEMAKE_MB,
    simulation_needs,
    simulation_threads,
)

STEEL = get_material("steel_100C6")
RADIUS = 0.013


def needs(n, launches=12, duration=2.6e-3, **kw):
    return simulation_needs(
        uniform_chain(n, STEEL, RADIUS, 0.58e-6), launches, 1.0, duration, 1e-6, **kw
    )


def test_memory_grows_with_chain_speeds_and_duration():
    paper = needs(26)
    assert needs(100).mem_mb > paper.mem_mb
    assert needs(26, launches=48).mem_mb > paper.mem_mb
    assert needs(26, duration=20e-3).mem_mb > paper.mem_mb
    # Linear in N x launches x samples: 4x the beads adds about 4x the trace memory.
    big = needs(400, launches=24, duration=10e-3)
    held_mb = BYTES_PER_BEAD_SAMPLE * 400 * 24 * 10_000 / 1e6
    assert big.mem_mb >= 1.5 * (BASE_MB + SNAKEMAKE_MB + held_mb)
    assert big.mem_mb % 100 == 0


def test_runtime_grows_with_work_and_never_under_the_minimum():
    assert needs(16, launches=4, duration=1.5e-3).runtime == MIN_RUNTIME_MIN
    long = needs(2000, launches=48, duration=50e-3)
    assert long.runtime > MIN_RUNTIME_MIN
    # Threads share the launches: more cores, less time (down to one launch each).
    assert needs(2000, launches=48, duration=50e-3, threads=8).runtime < long.runtime


def test_bad_arguments_are_named():
    with pytest.raises(ParameterError, match="n_launches"):
        needs(26, launches=0)
    with pytest.raises(ParameterError, match="duration"):
        needs(26, duration=-1.0)


# A fresh interpreter runs the simulate rule's work (simulate_shots, then the trace file)
# and reports its peak resident memory; the request must cover it without the Snakemake
# share (the job's Snakemake process is another process).
_MEASURE = textwrap.dedent(
    """
    import resource, sys
    import numpy as np
    from chain.apparatus.shots import simulate_shots
    from chain.physics.materials import get_material
    from chain.physics.builders import uniform_chain
    from chain.traces import write_traces
    n, launches, duration = 40, 8, 3.0e-3
    speeds = np.geomspace(0.05, 1.0, launches)
    model = uniform_chain(n, get_material("steel_100C6"), 0.013, 0.58e-6)
    traces, runs = simulate_shots(model, speeds, [10, 31], model_name="m", duration=duration)
    write_traces(traces, sys.argv[1])
    print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
    """
)


@pytest.mark.slow
def test_request_covers_the_measured_peak(tmp_path):
    out = subprocess.run(
        [sys.executable, "-c", _MEASURE, str(tmp_path / "traces.csv")],
        capture_output=True,
        text=True,
        check=True,
    )
    peak_mb = float(out.stdout.split()[-1])
    request = needs(40, launches=8, duration=3.0e-3).mem_mb
    assert peak_mb < request - SNAKEMAKE_MB, (peak_mb, request)


def test_threads_follow_the_integration_work():
    """Small jobs take one core (two of them then run at once); long sweeps take more,
    never more than their launches or MAX_THREADS."""

    def threads(n_beads, launches, duration):
        chain = uniform_chain(n_beads, STEEL, RADIUS, 0.58e-6)
        return simulation_threads(chain, launches, 1.0, duration)

    assert threads(26, 12, 2.6e-3) == 1  # the paper's jobs
    assert threads(100, 24, 5.2e-3) > 1
    assert threads(100, 24, 5.2e-3) <= threads(400, 24, 5.2e-3) <= MAX_THREADS
    # Collision and reference shots share one pool: one launch per thread at most.
    assert threads(5000, 3, 50e-3) == 6
