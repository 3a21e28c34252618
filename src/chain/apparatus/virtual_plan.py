"""The shot plan of the virtual experiment: which shots, and their random imperfections
(a MODEL of a lab's shots; see :mod:`chain.apparatus.virtual`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from chain.apparatus.virtual_settings import VirtualExperiment, check_switches


def plan_shots(settings: VirtualExperiment) -> pd.DataFrame:
    """The shots of a virtual experiment and their random imperfections (no simulation).

    Shots are numbered amplitude by amplitude, collisions first, then references, as a
    lab would take them. This is the plan :func:`run_virtual_experiment` uses: its
    draws come first from ``default_rng(seed)``, in a fixed order, and the sensor noise
    is drawn after them from the same generator.

    Parameters
    ----------
    settings : VirtualExperiment
        The apparatus and the shot plan.

    Returns
    -------
    DataFrame
        shot, file, kind, amplitude, nominal_speed_m_s, drop_height_m (NaN if speeds
        were given), v_left_m_s, v_right_m_s (true impact speeds; 0 for the absent right
        striker of a reference), delay_s (right launch minus left launch; 0 for a
        reference), sampling_phase_s.
    """
    return _plan(settings, np.random.default_rng(settings.seed))


def collision_speeds(settings: VirtualExperiment) -> tuple[np.ndarray, np.ndarray]:
    """True impact speeds of the left and right strikers of the collision shots of
    ``settings``, m/s, shape (amplitudes, collision shots): the plan's (:func:`plan_shots`),
    drawn alone (they are its first draws), for a check that needs no more of it."""
    shape = (settings.nominal_speeds.size, settings.collision_shots, 3)
    return _collision_speeds(settings, np.random.default_rng(settings.seed).standard_normal(shape))


def _collision_speeds(settings: VirtualExperiment, draws: np.ndarray):
    """(left, right) speeds, m/s, from the collision draws (amplitude, shot, 3)."""
    nominal = settings.nominal_speeds[:, None]
    left = _speed(nominal, draws[..., 0], settings.speed_mismatch)
    right = _speed(nominal, draws[..., 1], settings.speed_mismatch)
    return left, right * (1.0 + settings.right_speed_offset)


def _speed(nominal, draw, spread):
    """A striker's true speed, m/s: a few-percent mismatch never makes it negative;
    the floor is a guard only."""
    return nominal * np.maximum(1.0 + spread * draw, 0.05)


def _plan(settings: VirtualExperiment, rng: np.random.Generator) -> pd.DataFrame:
    speeds = settings.nominal_speeds
    heights = (
        np.full(speeds.size, np.nan)
        if settings.drop_heights_m is None
        else np.asarray(settings.drop_heights_m, dtype=float)
    )
    check_switches(settings)
    n_amp, n_col, n_ref = speeds.size, settings.collision_shots, settings.reference_shots
    sigma = settings.speed_mismatch
    sigma_ref = settings.reference_speed_mismatch
    sigma_ref = sigma if sigma_ref is None else sigma_ref
    collision_draws = rng.standard_normal((n_amp, n_col, 3))
    collision_phase = rng.uniform(size=(n_amp, n_col))
    reference_draws = rng.standard_normal((n_amp, n_ref))
    reference_phase = rng.uniform(size=(n_amp, n_ref))

    left, right = _collision_speeds(settings, collision_draws)
    rows = []
    for a in range(n_amp):
        for c in range(n_col):
            delay = settings.right_delay_s + settings.timing_jitter_s * collision_draws[a, c, 2]
            rows.append(("collision", a, left[a, c], right[a, c], delay, collision_phase[a, c]))
        for r in range(n_ref):
            speed = _speed(speeds[a], reference_draws[a, r], sigma_ref)
            rows.append(("reference", a, speed, 0.0, 0.0, reference_phase[a, r]))
    plan = pd.DataFrame(
        rows, columns=["kind", "amplitude", "v_left_m_s", "v_right_m_s", "delay_s", "phase"]
    )
    plan.insert(0, "shot", np.arange(len(plan)))
    plan.insert(1, "file", [f"shot_{s:04d}.csv" for s in plan["shot"]])
    plan.insert(4, "nominal_speed_m_s", speeds[plan["amplitude"]])
    plan.insert(5, "drop_height_m", heights[plan["amplitude"]])
    plan["sampling_phase_s"] = plan.pop("phase") * settings.sampling_interval_s
    return plan
