"""One setting of the mechanism study's friction/rotation (or viscous) sweep on one
chain, run by LAMMPS (:mod:`chain.physics.lammps_engine`, optional) and analysed as
every other series. This module maps config keys and knows no Snakemake."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd

from chain.apparatus.lammps_shots import lammps_shots
from chain.studies.mechanism_fits import analyse_per_estimator
from chain.studies.mechanism_settings import granular_chain, sweep_settings, viscous_settings


def run_sweep_setting(
    config: Mapping, n_beads: int, sensors: Sequence[int], name: str, estimators: Sequence[str]
) -> dict[str, pd.DataFrame]:
    """One setting of the friction/rotation sweep on one chain, run and analysed.

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    n_beads : int
        N.
    sensors : sequence of int
        [S1, S2].
    name : str
        A name of :func:`sweep_settings` or :func:`viscous_settings` (full lists); it is
        the traces' ``model``. Viscous settings run on the frictionless track with the
        viscous force instead of Kuwabara-Kono.
    estimators : sequence of str
        Pulse estimators: the fits of each, tagged (reporting tables pick the main one).

    Returns
    -------
    dict
        ``traces``, ``runs`` (:func:`chain.apparatus.lammps_shots.lammps_shots`),
        ``delay_fits`` and ``ssw_fits`` (:func:`analyse_per_estimator`).
    """
    options = config["lammps"]
    viscous = viscous_settings(config, full=True)
    if name in viscous:
        chain = granular_chain(config, n_beads, eta=0.0, track=True, viscous_damping=viscous[name])
    else:
        track_friction, bead_friction = sweep_settings(config, full=True)[name]
        chain = granular_chain(
            config,
            n_beads,
            eta=options["sweep"]["eta_s"],
            track_friction=track_friction,
            bead_friction=bead_friction,
            track=True,
        )
    traces, runs = lammps_shots(
        chain,
        options["sweep"]["launch_speeds_m_s"],
        sensors,
        model_name=name,
        duration=options["duration_s"],
        dt=options["time_step_s"],
        record_interval=options["record_interval_s"],
    )
    delay_fits, ssw_fits = analyse_per_estimator(traces, estimators)
    return {"traces": traces, "runs": runs, "delay_fits": delay_fits, "ssw_fits": ssw_fits}
