"""Bounds of the virtual experiment that depend on other keys: the digitiser against the
narrowest and the smallest pulse, the sensor spring against a given time step, the launch
delay against the sensors, the selection tolerance against the shots' speed mismatch.

Pulses are estimated as in :mod:`.bounds_run`, from the launch's V_m / V0
(:func:`chain.pipeline.config.launch_ratios`), each check taking the estimate that refuses only what
cannot work: the widest possible pulse for a sampling bound, the largest for detection.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from chain.analysis.pulses import DEFAULT_MIN_SNR
from chain.physics.materials import get_material, sphere_mass
from chain.physics.theory import LAUNCH_VELOCITY_RATIO
from chain.physics.time_step import STEPS_PER_SPRING_PERIOD
from chain.pipeline.config import check_passing, fail, launch_ratios, slowest_passing
from chain.pipeline.config.bounds_run import (
    DURATION_MARGIN,
    MIN_SENSOR_DISTANCE,
    check_resolution,
    pulse_force,
    pulse_speed,
    sensor_room,
)
from chain.pipeline.config.virtual import virtual_experiment

#: Standard deviations of the random launch jitter a delay bound covers (99.7 % of shots).
JITTER_SIGMAS = 3.0

#: Collision shots the selection must keep in a chain: each gives 2 points (LSTW and
#: RSTW), and the free exponent of |Delta| = A F_m^p needs 3 (chain.analysis.delays).
MIN_KEPT_SHOTS = 2

#: F_m grows as V_m^(6/5) (Eq. 5): the selection's |F_L - F_R| / mean from the speeds.
FORCE_SPEED_EXPONENT = 1.2


def _check_detection(config: Mapping, virtual: Mapping, speeds, ratios) -> None:
    """The smallest pulse, damped by the track drag on its way to the far sensor, stands
    above the detection threshold: DEFAULT_MIN_SNR x the noise and x the ADC step."""
    base = ["experiment", "virtual"]
    slowest = float(min(speeds))
    largest_of_smallest = pulse_force(config, ratios[1] * slowest)
    # Drag -m gamma v on every bead takes momentum as exp(-gamma t); F_m ~ V_m^(6/5).
    passing = slowest_passing(config, ratios[1] * slowest / LAUNCH_VELOCITY_RATIO)
    damping = math.exp(-FORCE_SPEED_EXPONENT * virtual["drag_rate_per_s"] * passing["time_s"])
    smallest = largest_of_smallest * damping
    where = f"<= {smallest:.3g} N at {slowest:g} m/s" + (
        f", {damping:.2g} of it left by drag_rate_per_s at S2" if damping < 1 else ""
    )
    noise = virtual["noise_N"]
    threshold = noise * DEFAULT_MIN_SNR
    if threshold >= largest_of_smallest:
        fail(
            [*base, "noise_N"],
            f"{noise:g} N hides the smallest pulse ({where}) below the detection threshold "
            f"of {DEFAULT_MIN_SNR:g} x noise_N; allowed: < "
            f"{largest_of_smallest / DEFAULT_MIN_SNR:.3g} N (or faster strikers)",
        )
    if threshold >= smallest:
        most = math.log(largest_of_smallest / threshold) / (
            FORCE_SPEED_EXPONENT * passing["time_s"]
        )
        fail(
            [*base, "drag_rate_per_s"],
            f"{virtual['drag_rate_per_s']:g} 1/s damps the smallest pulse ({where}) below "
            f"the detection threshold of {DEFAULT_MIN_SNR:g} x noise_N = {threshold:.3g} N; "
            f"allowed: < {most:.3g} 1/s",
        )
    bits = virtual["adc_bits"]
    if bits is None:
        return
    step_N = 2.0 * virtual["adc_range_V"] / 2**bits / (virtual["sensitivity_mV_per_N"] / 1e3)
    if step_N * DEFAULT_MIN_SNR >= smallest:
        most = smallest / DEFAULT_MIN_SNR * virtual["sensitivity_mV_per_N"] / 1e3 * 2**bits / 2
        fail(
            [*base, "adc_range_V"],
            f"{virtual['adc_range_V']:g} V: one ADC step of {bits} bits is {step_N:.3g} N, "
            f"and the smallest pulse ({where}) spans fewer than {DEFAULT_MIN_SNR:g} steps; "
            f"allowed: <= {most:.3g} V (or more adc_bits, or adc_bits: null)",
        )


def _check_sensor_spring(config: Mapping, virtual: Mapping) -> None:
    """With a given time step, the split sensor bead's spring (halves of m / 2) keeps
    STEPS_PER_SPRING_PERIOD / TIME_STEP_COARSENING steps per period: the coarsening the
    virtual experiment's own default step allows (energy drift ~1e-6)."""
    from chain.apparatus.virtual_settings import TIME_STEP_COARSENING

    step = virtual["time_step_s"]
    if step is None or virtual["readout"] != "sensor":
        return
    reduced = sphere_mass(get_material(config["material"]), config["radius_m"]) / 4.0
    steps = STEPS_PER_SPRING_PERIOD / TIME_STEP_COARSENING
    stiffest = reduced * (2.0 * math.pi / (steps * step)) ** 2
    stiffness = virtual["sensor_stiffness_N_per_m"]
    if stiffness > stiffest:
        fail(
            ["experiment", "virtual", "sensor_stiffness_N_per_m"],
            f"{stiffness:g} N/m oscillates in the split sensor bead with a period of "
            f"{2 * math.pi * math.sqrt(reduced / stiffness):.3g} s, fewer than {steps:g} "
            f"time_step_s = {step:g} s (RK4 drifts); allowed: <= {stiffest:.3g} N/m, or a "
            "smaller time_step_s (null: chosen for the spring)",
        )


def _check_delay(config: Mapping, virtual: Mapping, speeds, ratios) -> None:
    """A right launch delta late moves the collision point right by v delta / 2 (v the
    fastest pulse's speed); it must stay MIN_SENSOR_DISTANCE beads from S1 and S2."""
    speed = pulse_speed(config, ratios[1] * float(max(speeds)))
    bead = 2.0 * config["radius_m"]
    delay, jitter = virtual["right_delay_s"], virtual["timing_jitter_s"]
    for entry in config["chains"]:
        left, right = (room - MIN_SENSOR_DISTANCE for room in sensor_room(entry))
        # Beads the collision point moves right (+) and left (-) in the extreme shots.
        most = speed * (delay + JITTER_SIGMAS * jitter) / 2.0 / bead
        least = speed * (delay - JITTER_SIGMAS * jitter) / 2.0 / bead
        if most <= right and -least <= left:
            continue
        key = "right_delay_s" if delay / 2.0 * speed / bead > right else "timing_jitter_s"
        s1, s2 = (room + MIN_SENSOR_DISTANCE for room in (left, right))
        fail(
            ["experiment", "virtual", key],
            f"{virtual[key]:g} s: a launch delay of right_delay_s +- {JITTER_SIGMAS:g} "
            f"timing_jitter_s moves the collision point of the N = {entry['N']} chain by up "
            f"to {max(most, -least):.3g} beads (the fastest wave, ~{speed:.0f} m/s, Eq. 5); "
            f"S1 and S2 are {s1:g} and {s2:g} beads from it and must stay "
            f"{MIN_SENSOR_DISTANCE:g}: the waves must cross between the sensors; allowed: "
            f"right_delay_s + {JITTER_SIGMAS:g} x timing_jitter_s <= "
            f"{2.0 * right * bead / speed:.3g} s and {JITTER_SIGMAS:g} x timing_jitter_s - "
            f"right_delay_s <= {2.0 * left * bead / speed:.3g} s",
        )


def _check_tolerance(config: Mapping, settings) -> None:
    """The selection keeps MIN_KEPT_SHOTS collision shots of a chain, judged by the
    planned speeds of the shots (seeded, so known before any job)."""
    # The speeds alone: building each variant's whole plan (a DataFrame) costs ~0.15 s.
    from chain.apparatus.virtual_plan import collision_speeds

    tolerance = config["experiment"].get("tolerance")
    if tolerance is None:
        return
    left, right = (v.ravel() ** FORCE_SPEED_EXPONENT for v in collision_speeds(settings))
    mismatch = np.sort(np.abs(left - right) / ((left + right) / 2.0))
    if mismatch.size >= MIN_KEPT_SHOTS and mismatch[MIN_KEPT_SHOTS - 1] > tolerance:
        fail(
            ["experiment", "tolerance"],
            f"{tolerance:g} keeps {int(np.sum(mismatch <= tolerance))} of the {mismatch.size} "
            f"collision shots of the N = {settings.n_beads} chain (their launch speeds "
            f"alone give |F_L - F_R| / mean >= {mismatch[0]:.3g}, seed {settings.seed}); "
            f"the free exponent needs {MIN_KEPT_SHOTS} shots (3 points, 2 per shot); "
            f"allowed: >= {mismatch[MIN_KEPT_SHOTS - 1]:.3g} (or null: no selection)",
        )


def check_experiment_bounds(config: Mapping) -> None:
    """The virtual experiment's bounds that need two keys (module docstring) in
    ``config``, a schema-valid config with ``experiment.source: virtual`` that passed the
    checks before the bounds; :class:`~chain.errors.ConfigError` naming the first
    offending key."""
    virtual = config["experiment"]["virtual"]
    ratios = launch_ratios(config, virtual)
    for entry in config["chains"]:
        settings = virtual_experiment(config, entry["N"], entry["sensors"])
        _check_tolerance(config, settings)
    speeds, base = settings.nominal_speeds, ["experiment", "virtual"]
    fastest, slowest = float(max(speeds)), float(min(speeds))
    sampling, duration = virtual["sampling_interval_s"], virtual["duration_s"]
    what = f"{virtual['launch']} at {fastest:g} m/s"
    check_resolution(config, [*base, "sampling_interval_s"], sampling, ratios[0] * fastest, what)
    # Duration: the slowest launch's wave at the most it can be passes the far sensors.
    v0 = ratios[1] * slowest / LAUNCH_VELOCITY_RATIO
    what = f"{virtual['launch']} at {slowest:g} m/s, as bead 1 launched"
    check_passing(config, [*base, "duration_s"], duration, v0, what, DURATION_MARGIN)
    _check_detection(config, virtual, speeds, ratios)
    _check_sensor_spring(config, virtual)
    _check_delay(config, virtual, speeds, ratios)
