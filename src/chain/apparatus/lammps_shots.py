"""Shots run by LAMMPS (:mod:`chain.physics.lammps_engine`) as trace tables.

The same protocol as :func:`chain.apparatus.shots.simulate_shots`, read out as the
force felt at the sensor beads in the trace format with source ``lammps``, so that the
analysis of every other series (pulses, delays, C, SSW) runs on them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from chain.errors import ParameterError
from chain.physics.lammps_engine import GranularChain, run_granular_chain
from chain.traces import META_COLUMNS, sensor_column

#: Value of the ``source`` column of LAMMPS traces.
LAMMPS_SOURCE = "lammps"


def lammps_shots(
    chain: GranularChain,
    launch_speeds,
    sensor_beads,
    *,
    model_name: str,
    duration: float = 2.6e-3,
    dt: float = 2.5e-8,
    record_interval: float = 1e-6,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Collision and reference shots of ``chain`` for each launch speed, with LAMMPS.

    Parameters
    ----------
    chain : GranularChain
        The chain and its contact model (friction, track, dissipation).
    launch_speeds : sequence of float
        V0 per amplitude, m/s.
    sensor_beads : sequence of int
        Beads read, S1 first (1..N).
    model_name : str
        Value of the ``model`` column (the setting's name).
    duration, dt, record_interval : float
        Recorded time after the launch, Verlet step and sample interval, s
        (:func:`chain.physics.lammps_engine.run_granular_chain`).

    Returns
    -------
    traces : DataFrame
        Trace table, collision shots 0..A-1 then reference shots A..2A-1.
    runs : DataFrame
        One row per shot: shot, kind, amplitude, v0 values, dt_s, max_spin_rad_s (the
        largest final bead spin about the transverse axis).
    """
    speeds = np.asarray(launch_speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size == 0 or np.any(~(speeds > 0)):
        raise ParameterError(f"launch_speeds must be positive m/s values, got {launch_speeds!r}")
    beads = [int(b) for b in sensor_beads]
    tables, runs = [], []
    for offset, kind in enumerate(("collision", "reference")):
        for amplitude, speed in enumerate(speeds):
            shot = offset * len(speeds) + amplitude
            right = speed if kind == "collision" else 0.0
            run = run_granular_chain(
                chain, speed, right, duration=duration, dt=dt, record_interval=record_interval
            )
            samples = len(run.time)
            tables.append(
                pd.DataFrame(
                    {
                        "source": LAMMPS_SOURCE,
                        "model": model_name,
                        "N": chain.n_beads,
                        "shot": shot,
                        "kind": kind,
                        "amplitude": amplitude,
                        "v0_left_m_s": np.full(samples, speed),
                        "v0_right_m_s": np.full(samples, right),
                        "t_s": run.time,
                        **{sensor_column(b): run.force_felt(b) for b in beads},
                    }
                )[[*META_COLUMNS, *map(sensor_column, beads)]]
            )
            runs.append(
                {
                    "model": model_name,
                    "N": chain.n_beads,
                    "shot": shot,
                    "kind": kind,
                    "amplitude": amplitude,
                    "v0_left_m_s": speed,
                    "v0_right_m_s": right,
                    "dt_s": run.dt,
                    "max_spin_rad_s": float(np.max(np.abs(run.spin))),
                }
            )
    return pd.concat(tables, ignore_index=True), pd.DataFrame(runs)
