"""Simulated shots as trace tables: the paper's simulation protocol.

For each launch speed, a collision shot (both ends launched) and a reference shot
(left end alone), integrated by :func:`chain.physics.simulation.simulate` and read
out at the sensor beads into the project's one trace format (:mod:`chain.traces`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

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
from chain.traces import META_COLUMNS, sensor_column


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
    columns = {sensor_column(b): read(b) for b in beads}
    batch, samples = result.contact_force.shape[:2]
    table = pd.DataFrame(
        {
            "source": "simulation",
            "model": model_name,
            "N": result.model.n_beads,
            "shot": np.repeat(np.arange(first_shot, first_shot + batch), samples),
            "kind": kind,
            "amplitude": np.repeat(np.arange(batch), samples),
            "v0_left_m_s": np.repeat(result.v_left, samples),
            "v0_right_m_s": np.repeat(result.v_right, samples),
            "t_s": np.tile(result.time, batch),
            **{name: values.reshape(-1) for name, values in columns.items()},
        }
    )
    return table[list(META_COLUMNS) + list(columns)]


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


def simulate_shots(
    model: ChainModel,
    launch_speeds,
    sensor_beads,
    *,
    model_name: str,
    duration: float = 2.6e-3,
    dt: float | None = None,
    record_interval: float = DEFAULT_RECORD_INTERVAL,
    readout: str = "felt",
    max_energy_drift: float = DEFAULT_MAX_ENERGY_DRIFT,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The paper's simulation protocol for a sweep of launch speeds.

    For each speed V0: a collision shot (+V0 on bead 1, -V0 on bead N) and a reference
    shot (+V0 on bead 1 alone), all in two batched integrator calls with one time step.

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
    duration, dt, record_interval, max_energy_drift
        As in :func:`simulate`.
    readout : {"felt", "sensor"}
        As in :func:`trace_table`.

    Returns
    -------
    traces : DataFrame
        Trace table, collision shots 0..A-1 then reference shots A..2A-1.
    runs : DataFrame
        One row per shot: shot, kind, amplitude, v0 values, energy_drift, dt_s,
        final_energy_J, dissipated_energy_J.
    """
    speeds = np.asarray(launch_speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size == 0 or np.any(~np.isfinite(speeds)) or np.any(speeds <= 0):
        raise ParameterError(f"launch_speeds must be positive m/s values, got {launch_speeds!r}")
    dt = shot_time_step(model, speeds, dt, record_interval)
    tables = []
    runs = []
    kinds = ("collision", "reference")
    # Both batches in one thread pool: every core busy until the last launch.
    results = simulate_many(
        [{"v_right": speeds}, {"v_right": 0.0 * speeds}],
        model=model,
        v_left=speeds,
        duration=duration,
        dt=dt,
        record_interval=record_interval,
        max_energy_drift=max_energy_drift,
        # Record only what the readout reads (sensor springs are always kept).
        contacts=felt_contacts(model, sensor_beads) if readout == "felt" else (),
        beads=(),
    )
    for offset, (kind, result) in enumerate(zip(kinds, results, strict=True)):
        first = offset * len(speeds)
        tables.append(
            trace_table(
                result,
                sensor_beads,
                kind=kind,
                model_name=model_name,
                readout=readout,
                first_shot=first,
            )
        )
        runs.append(
            pd.DataFrame(
                {
                    "model": model_name,
                    "N": model.n_beads,
                    "shot": np.arange(first, first + len(speeds)),
                    "kind": kind,
                    "amplitude": np.arange(len(speeds)),
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
