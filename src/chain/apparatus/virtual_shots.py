"""The simulation of the virtual experiment's shots: the apparatus model integrated
batch by batch, read at the sensors (a MODEL; see :mod:`chain.apparatus.virtual`)."""

from __future__ import annotations

import itertools
import math
from dataclasses import asdict

import numpy as np
import pandas as pd

from chain.apparatus.virtual_settings import (
    CHAIN_STREAM,
    TIME_STEP_COARSENING,
    VirtualExperiment,
    check_switches,
)
from chain.physics.builders import build_chain, uniform_chain
from chain.physics.materials import contact_stiffness, sphere_mass
from chain.physics.model import ChainModel, Striker
from chain.physics.simulation import default_time_step, felt_contacts, simulate

#: Simulated samples per digitiser interval; the digitiser interpolates between them.
RECORD_OVERSAMPLING = 4

#: Launches per integrator call: bounds memory (a few MB per launch).
MAX_BATCH = 16

#: Fields of VirtualExperiment that a launch's integration does not read, or reads
#: through what they make (the shots' speeds and delays, the chain's radii and gaps, the
#: time step): a launch is known by the others (:func:`simulate_virtual_shots`).
_NOT_INTEGRATED = set(
    "seed impact_speeds_m_s drop_heights_m collision_shots reference_shots speed_mismatch "
    "reference_speed_mismatch timing_jitter_s right_speed_offset right_delay_s noise_N adc_bits "
    "adc_range_V sensitivity_mV_per_N time_step_s radius_dispersion gap_mean_m gap_spread_m".split()
)


def _launcher(model, side: int) -> slice:
    """Particles a launch sets moving: the striker, else every particle of the end bead."""
    striker = model.left_striker if side == 0 else model.right_striker
    if striker >= 0:
        return slice(striker, striker + 1)
    bead = 0 if side == 0 else model.n_beads - 1
    return slice(model.bead_first[bead], model.bead_last[bead] + 1)


def _initial_displacement(model, plan: pd.DataFrame) -> np.ndarray:
    """Gaps that delay one launch: u = +gap on the right launcher (striker, or bead N
    with ``launch="bead"``: it starts further right), u = -gap on the left one,
    gap = speed x |delay|."""
    displacement = np.zeros((len(plan), model.n_particles))
    delay = plan["delay_s"].to_numpy()
    late_right = np.flatnonzero(delay > 0)
    gap = plan["v_right_m_s"].to_numpy()[late_right] * delay[late_right]
    displacement[late_right, _launcher(model, 1)] = gap[:, None]
    late_left = np.flatnonzero(delay < 0)
    gap = plan["v_left_m_s"].to_numpy()[late_left] * delay[late_left]
    displacement[late_left, _launcher(model, 0)] = gap[:, None]
    return displacement


def chain_draws(settings: VirtualExperiment) -> tuple[np.ndarray, np.ndarray]:
    """The chain's own imperfections, drawn once per chain: (bead radii (N,) m, gaps at
    rest between neighbours (N-1,) m), from ``default_rng((seed, CHAIN_STREAM))``.

    Both are always drawn, in this order, so that each is the same whatever the other's
    setting; with zero dispersion and gaps they are R and 0 exactly.
    """
    rng = np.random.default_rng((settings.seed, CHAIN_STREAM))
    n_beads = settings.n_beads
    radii = settings.radius * (1.0 + settings.radius_dispersion * rng.standard_normal(n_beads))
    gaps = settings.gap_mean_m + settings.gap_spread_m * rng.standard_normal(n_beads - 1)
    return radii, np.maximum(gaps, 0.0)


def apparatus_chain(settings: VirtualExperiment, strikers: str, radii) -> ChainModel:
    """The apparatus model with strikers at ``strikers`` ("both" or "left"): equal beads
    (:func:`uniform_chain`) unless ``radii`` (N,) m differ, then each bead with its own
    mass and each contact with its own Hertz stiffness."""
    material = settings.material_object
    common = dict(
        eta=settings.eta_s,
        sensor_beads=settings.sensor_beads if settings.readout == "sensor" else (),
        sensor_stiffness=settings.sensor_stiffness_N_per_m,
        drag_rate=settings.drag_rate_per_s,
    )
    with_strikers = settings.launch == "striker"
    if np.all(radii == settings.radius):
        return uniform_chain(
            settings.n_beads,
            material=material,
            radius=settings.radius,
            striker_radius=settings.striker_radius if with_strikers else None,
            strikers=strikers,
            **common,
        )

    def striker(bead_radius):
        return Striker.sphere(settings.striker_radius, material, bead_radius, material)

    return build_chain(
        [sphere_mass(material, r) for r in radii],
        [contact_stiffness(material, a, material, b) for a, b in itertools.pairwise(radii)],
        left_striker=striker(radii[0]) if with_strikers else None,
        right_striker=striker(radii[-1]) if with_strikers and strikers == "both" else None,
        **common,
    )


def rest_displacement(model: ChainModel, gaps) -> np.ndarray:
    """Particle displacements (P,) m that open ``gaps`` (N-1,) m between the beads at
    rest: every bead shifted right by the gaps to its left; strikers touch their bead."""
    offset = np.concatenate([[0.0], np.cumsum(gaps)])
    displacement = np.zeros(model.n_particles)
    for bead, (first, last) in enumerate(zip(model.bead_first, model.bead_last)):
        displacement[first : last + 1] = offset[bead]
    if model.right_striker >= 0:
        displacement[model.right_striker] = offset[-1]
    return displacement


def _sensor_forces(settings, model, plan, dt, record_interval, rest):
    """Simulated sensor forces of the shots in ``plan``: (time (S,), forces (B, n, S))."""
    time = None
    chunks = []
    for start in range(0, len(plan), MAX_BATCH):
        part = plan.iloc[start : start + MAX_BATCH]
        result = simulate(
            model,
            part["v_left_m_s"].to_numpy(),
            part["v_right_m_s"].to_numpy(),
            duration=settings.duration_s,
            dt=dt,
            record_interval=record_interval,
            initial_displacement=_initial_displacement(model, part) + rest,
            # Record only what the readout reads (sensor springs are always kept).
            contacts=(
                felt_contacts(model, settings.sensor_beads) if settings.readout == "felt" else ()
            ),
            beads=(),
        )
        time = result.time
        read = result.sensor if settings.readout == "sensor" else result.force_felt
        chunks.append(np.stack([read(b) for b in settings.sensor_beads], axis=1))
    return time, np.concatenate(chunks, axis=0)


def simulate_virtual_shots(
    settings: VirtualExperiment,
    plan: pd.DataFrame,
    known: dict | None = None,
    wanted: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the shots of ``plan`` (from :func:`plan_shots`), or the ``wanted`` ones
    (bool (len(plan),)), with the apparatus model: (simulated fine time (S,) s from the
    first impact, their sensor readings (B, n_sensors, S) N, in plan order).

    Collision shots use a chain with both strikers, reference shots one with the left
    striker only, both with the same time step (from the fastest shot of ``plan``); each
    kind is batched. With ``launch="bead"`` there are no strikers (the end beads are
    launched) and with ``readout="felt"`` no split sensor beads. Each distinct launch
    (chain, time step, kind, speeds, delay) is integrated once: a repeat, in ``plan`` or
    in ``known`` (launch -> (time, readings), filled here; one dict for calls that may
    share launches), takes its readings, the same to the bit (each launch is integrated
    on its own; the integrator's log names each launch it integrates).
    """
    check_switches(settings)
    radii, gaps = chain_draws(settings)
    both = apparatus_chain(settings, "both", radii)
    record_interval = settings.sampling_interval_s / RECORD_OVERSAMPLING
    fastest = float(plan[["v_left_m_s", "v_right_m_s"]].to_numpy().max())
    dt = settings.time_step_s or TIME_STEP_COARSENING * default_time_step(both, fastest)
    # A whole number of steps per recorded sample keeps the record grid exact.
    dt = record_interval / math.ceil(record_interval / dt - 1e-9)
    chain = (*((k, repr(v)) for k, v in asdict(settings).items() if k not in _NOT_INTEGRATED),
             dt, radii.tobytes(), gaps.tobytes())  # fmt: skip
    columns = ["kind", "v_left_m_s", "v_right_m_s", "delay_s"]
    launches = [(chain, *row) for row in plan[columns].itertuples(index=False, name=None)]
    if wanted is not None:
        plan, launches = plan[wanted], [k for k, w in zip(launches, wanted) if w]
    known = {} if known is None else known
    for kind, strikers in (("collision", "both"), ("reference", "left")):
        new: dict = {}  # launch -> its first shot
        for i, k in enumerate(launches):
            if k[1] == kind and k not in known:
                new.setdefault(k, i)
        if not new:
            continue
        model = both if strikers == "both" else apparatus_chain(settings, "left", radii)
        time, readings = _sensor_forces(
            settings, model, plan.iloc[list(new.values())], dt, record_interval,
            rest_displacement(model, gaps),
        )  # fmt: skip
        known.update((k, (time, r)) for k, r in zip(new, readings))
    return known[launches[0]][0], np.stack([known[k][1] for k in launches])
