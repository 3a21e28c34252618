"""Simulated launches as the project's trace tables (:mod:`chain.traces`), and every
bead's felt force of a simulation's launches in a file (its readings), read back at any
beads: apart from the integrator, so a job that only reads them imports no numba.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from chain.atomic import atomic_output
from chain.traces import META_COLUMNS, sensor_column

if TYPE_CHECKING:  # the integrator's result type; importing it would load numba
    from chain.physics.simulation import SimulationResult


def launch_table(launches, forces, n_beads: int, kind: str, model_name: str, first_shot: int):
    """A trace table (source ``simulation``) of B launches: ``launches`` = (time (S,) s,
    left and right launch speeds (B,) m/s), ``forces`` = bead -> (B, S) force, N; the
    other arguments as :func:`trace_table`'s."""
    time, v_left, v_right = launches
    batch, samples = len(v_left), len(time)
    columns = {sensor_column(b): np.asarray(values).reshape(-1) for b, values in forces.items()}
    table = pd.DataFrame(
        {
            "source": "simulation",
            "model": model_name,
            "N": n_beads,
            "shot": np.repeat(np.arange(first_shot, first_shot + batch), samples),
            "kind": kind,
            "amplitude": np.repeat(np.arange(batch), samples),
            "v0_left_m_s": np.repeat(v_left, samples),
            "v0_right_m_s": np.repeat(v_right, samples),
            "t_s": np.tile(time, batch),
            **columns,
        }
    )
    return table[list(META_COLUMNS) + list(columns)]


def save_readings(launches: Sequence[SimulationResult], path) -> None:
    """Every bead's felt force of :func:`chain.apparatus.shots.simulate_launches`'
    launches (their contacts all recorded), ``.npz`` without pickles: ``time_s`` (S,),
    ``v0_left_m_s`` and ``v0_right_m_s`` (2A,), ``force_N`` (2A, N, S), collision shots
    then reference shots, as :func:`chain.apparatus.shots.shot_tables` numbers them.
    Written atomically.

    Parameters
    ----------
    launches : sequence of SimulationResult
        The collision and the reference batch.
    path : path
        The ``.npz`` file.
    """
    beads = range(1, launches[0].model.n_beads + 1)
    force = np.concatenate([np.stack([r.force_felt(b) for b in beads], axis=1) for r in launches])
    with atomic_output(path) as temporary, open(temporary, "wb") as stream:
        np.savez(
            stream,
            time_s=launches[0].time,
            v0_left_m_s=np.concatenate([r.v_left for r in launches]),
            v0_right_m_s=np.concatenate([r.v_right for r in launches]),
            force_N=force,
        )


def readings_table(path, beads, *, model_name: str) -> pd.DataFrame:
    """The trace table at ``beads`` of the launches :func:`save_readings` wrote: the
    table :func:`chain.apparatus.shots.simulate_shots` would give for those beads (same
    values, bit for bit).

    Parameters
    ----------
    path : path
        The ``.npz`` file.
    beads : sequence of int
        Beads read, S1 first.
    model_name : str
        Name written in the ``model`` column.
    """
    with np.load(path, allow_pickle=False) as saved:
        time, v_left, v_right, force = (saved[k] for k in ("time_s", "v0_left_m_s",
                                                          "v0_right_m_s", "force_N"))  # fmt: skip
    count, tables = len(v_left) // 2, []
    for offset, kind in enumerate(("collision", "reference")):
        shots = slice(offset * count, (offset + 1) * count)
        forces = {b: force[shots, b - 1] for b in beads}
        launches = (time, v_left[shots], v_right[shots])
        tables.append(launch_table(launches, forces, force.shape[1], kind, model_name, shots.start))
    return pd.concat(tables, ignore_index=True)
