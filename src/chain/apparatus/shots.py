"""Simulated shots as trace tables: the paper's simulation protocol.

For each launch speed, a collision shot (both ends launched) and a reference shot
(left end alone), integrated by :func:`chain.physics.simulation.simulate` and read
out at the sensor beads into the project's one trace format (:mod:`chain.traces`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from chain.apparatus.readings import launch_table
from chain.errors import ParameterError
from chain.physics.integrator import DEFAULT_MAX_ENERGY_DRIFT
from chain.physics.model import ChainModel
from chain.physics.simulation import (
    DEFAULT_RECORD_INTERVAL,
    SimulationResult,
    default_time_step,
    felt_contacts,
    simulate_many,
)


def trace_table(
    result: SimulationResult,
    beads,
    *,
    kind: str,
    model_name: str,
    readout: str = "felt",
    first_shot: int = 0,
) -> pd.DataFrame:
    """The forces at ``beads`` of every launch of ``result`` as a trace table
    (:mod:`chain.traces`, source ``simulation``), one shot per launch, amplitude index
    0..B-1.

    Parameters
    ----------
    result : SimulationResult
        A batch of launches.
    beads : sequence of int
        Beads to read (1..N), S1 first.
    kind : {"collision", "reference"}
        Shot kind written in the table.
    model_name : str
        Value of the ``model`` column.
    readout : {"felt", "sensor"}
        ``felt``: (F_{n-1,n} + F_{n,n+1}) / 2 (sensors not modelled); ``sensor``: the
        split-bead sensor reading (the beads must be sensor beads of the model).
    first_shot : int
        Shot id of the first launch; launches get consecutive ids.
    """
    if readout not in ("felt", "sensor"):
        raise ParameterError(f"readout must be 'felt' or 'sensor', got {readout!r}")
    read = result.force_felt if readout == "felt" else result.sensor
    forces = {b: read(b) for b in beads}
    launches = (result.time, result.v_left, result.v_right)
    return launch_table(launches, forces, result.model.n_beads, kind, model_name, first_shot)


def shot_time_step(model: ChainModel, launch_speeds, dt: float | None, record_interval: float):
    """The RK4 step of :func:`simulate_shots` (and of a re-simulation of its shots), s.

    ``dt`` itself when given; else :func:`chain.physics.simulation.default_time_step` at
    the fastest launch, shortened so that ``record_interval`` is a whole number of steps.

    Parameters
    ----------
    model : ChainModel
        The chain.
    launch_speeds : sequence of float
        V0 per amplitude, m/s.
    dt : float or None
        An explicit step, s, or None.
    record_interval : float
        Time between recorded samples, s.
    """
    if dt is not None:
        return dt
    dt = default_time_step(model, float(np.max(launch_speeds)))
    return record_interval / math.ceil(record_interval / dt)


def simulate_launches(
    model: ChainModel,
    launch_speeds,
    *,
    duration: float = 2.6e-3,
    dt: float | None = None,
    record_interval: float = DEFAULT_RECORD_INTERVAL,
    max_energy_drift: float = DEFAULT_MAX_ENERGY_DRIFT,
    contacts="all",
) -> list[SimulationResult]:
    """The paper's launches for a sweep of speeds, integrated once: for each speed V0 a
    collision (+V0 on bead 1, -V0 on bead N) and a reference (+V0 on bead 1 alone), in
    two batches of one thread pool with one time step (:func:`shot_time_step`).

    Parameters
    ----------
    model : ChainModel
        The chain.
    launch_speeds : sequence of float
        V0 per amplitude, m/s.
    duration, dt, record_interval, max_energy_drift
        As in :func:`chain.physics.simulation.simulate` (s).
    contacts : "all" or sequence of int
        Contacts recorded (sensor springs and end forces are always kept).

    Returns
    -------
    list of SimulationResult
        The collision batch, then the reference batch.
    """
    speeds = np.asarray(launch_speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size == 0 or np.any(~np.isfinite(speeds)) or np.any(speeds <= 0):
        raise ParameterError(f"launch_speeds must be positive m/s values, got {launch_speeds!r}")
    # Both batches in one thread pool: every core busy until the last launch.
    return simulate_many(
        [{"v_right": speeds}, {"v_right": 0.0 * speeds}],
        model=model,
        v_left=speeds,
        duration=duration,
        dt=shot_time_step(model, speeds, dt, record_interval),
        record_interval=record_interval,
        max_energy_drift=max_energy_drift,
        contacts=contacts,
        beads=(),
    )


def shot_tables(
    launches: Sequence[SimulationResult], sensor_beads, *, model_name: str, readout: str = "felt"
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The trace table and the runs of :func:`simulate_launches`' launches: collision
    shots 0..A-1 then reference shots A..2A-1, read at ``sensor_beads``.

    Parameters
    ----------
    launches : sequence of SimulationResult
        The collision and the reference batch.
    sensor_beads : sequence of int
        Beads read, S1 first.
    model_name : str
        Name written in the ``model`` column.
    readout : {"felt", "sensor"}
        As in :func:`trace_table`.
    """
    tables, runs = [], []
    for offset, (kind, result) in enumerate(zip(("collision", "reference"), launches, strict=True)):
        first, count = offset * len(result.v_left), len(result.v_left)
        tables.append(trace_table(result, sensor_beads, kind=kind, model_name=model_name,
                                  readout=readout, first_shot=first))  # fmt: skip
        runs.append(
            pd.DataFrame(
                {
                    "model": model_name,
                    "N": result.model.n_beads,
                    "shot": np.arange(first, first + count),
                    "kind": kind,
                    "amplitude": np.arange(count),
                    "v0_left_m_s": result.v_left,
                    "v0_right_m_s": result.v_right,
                    "energy_drift": result.energy_drift,
                    "dt_s": result.dt,
                    "initial_energy_J": result.total_energy[:, 0],
                    "dissipated_energy_J": result.dissipated_energy[:, -1],
                }
            )
        )
    return pd.concat(tables, ignore_index=True), pd.concat(runs, ignore_index=True)


def simulate_shots(
    model: ChainModel,
    launch_speeds,
    sensor_beads,
    *,
    model_name: str,
    readout: str = "felt",
    **simulation,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The paper's simulation protocol for a sweep of launch speeds, read at the sensor
    beads: :func:`simulate_launches` recording only what the readout reads, then
    :func:`shot_tables`.

    Parameters
    ----------
    model : ChainModel
        The chain.
    launch_speeds : sequence of float
        V0 per amplitude, m/s.
    sensor_beads : sequence of int
        Beads to record, S1 first (paper: 9, 17 for N = 25; 10, 17 for N = 26).
    model_name : str
        Name written in the ``model`` column.
    readout : {"felt", "sensor"}
        As in :func:`trace_table`.
    **simulation
        ``duration``, ``dt``, ``record_interval``, ``max_energy_drift`` (s), as
        :func:`simulate_launches`'.

    Returns
    -------
    traces : DataFrame
        Trace table, collision shots 0..A-1 then reference shots A..2A-1.
    runs : DataFrame
        One row per shot: shot, kind, amplitude, v0 values, energy_drift, dt_s,
        final_energy_J, dissipated_energy_J.
    """
    contacts = felt_contacts(model, sensor_beads) if readout == "felt" else ()
    launches = simulate_launches(model, launch_speeds, contacts=contacts, **simulation)
    return shot_tables(launches, sensor_beads, model_name=model_name, readout=readout)
