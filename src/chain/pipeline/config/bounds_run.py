"""Bounds of the simulated run that depend on other keys: sensor beads against the
collision point, record intervals against time steps and the narrowest pulse,
durations against the slowest wave, LAMMPS file names.

Also the pulse estimates :mod:`.bounds_experiment` shares: a pulse of incident amplitude
F_m = F(V_m) (Eq. 5) has the half width tau = R sqrt(10) / v (Eq. 4).
"""

from __future__ import annotations

from collections.abc import Mapping

from chain.analysis.pulses import MIN_FIT_SAMPLES
from chain.analysis.ssw_track import collision_point
from chain.physics.materials import get_material
from chain.physics.theory import (
    LAUNCH_VELOCITY_RATIO,
    force_from_bead_velocity,
    nesterenko_speed_from_force,
    pulse_half_width,
)
from chain.pipeline.config import check_passing, check_samples, fail
from chain.studies.mechanism_settings import setting_name, sweep_settings, viscous_name

#: A duration of LAMMPS or of a long chain must be this many times the passing time of
#: the slowest pulse: 1, not check.DURATION_MARGIN (1.2, which also covers a striker's
#: launch): a launched bead's estimate errs on the slow side already (ratio 0.45 against
#: 0.47 measured), and whatif/brass.yaml's LAMMPS record (2.6 ms against 2.31 ms) passes.
DURATION_MARGIN = 1.0

#: Smallest max_energy_drift with the default RK4 step, chosen for a relative drift of
#: about 1e-9 (measured 3.1e-10 at 1 m/s on the N = 26 chain).
DEFAULT_STEP_DRIFT = 1e-9

#: Relative tolerance of "a whole number of time steps".
MULTIPLE_TOLERANCE = 1e-9

#: Least distance of a sensor bead from the collision point, beads: the sensor must read
#: the incident and the crossed pulse as two peaks (chain.analysis.pulses.find_pulses).
#: Measured (N = 16..26, V0 = 0.1 and 1 m/s): two fitted pulses from 2 beads, one below.
MIN_SENSOR_DISTANCE = 2.0


def pulse_force(config: Mapping, bead_speed_m_s: float) -> float:
    """Incident amplitude F_m of the pulse a bead speed V_m (m/s) gives (Eq. 5), N."""
    beads = get_material(config["material"])
    return float(force_from_bead_velocity(bead_speed_m_s, beads, config["radius_m"]))


def pulse_tau(config: Mapping, bead_speed_m_s: float) -> float:
    """Half width tau of the pulse a bead speed V_m (m/s) gives (Eq. 4/5), s."""
    force = pulse_force(config, bead_speed_m_s)
    return float(pulse_half_width(force, get_material(config["material"]), config["radius_m"]))


def pulse_speed(config: Mapping, bead_speed_m_s: float) -> float:
    """Speed of the pulse a bead speed V_m (m/s) gives (Eq. 5), m/s."""
    force = pulse_force(config, bead_speed_m_s)
    beads = get_material(config["material"])
    return float(nesterenko_speed_from_force(force, beads, config["radius_m"]))


def check_resolution(config: Mapping, path, interval: float, bead_speed_m_s: float, what):
    """``interval`` (s) samples the pulse of bead speed V_m with MIN_FIT_SAMPLES per tau."""
    tau = pulse_tau(config, bead_speed_m_s)
    if interval * MIN_FIT_SAMPLES > tau:
        fail(
            path,
            f"{interval:g} s does not resolve the narrowest pulse ({what}: tau ~ "
            f"{tau * 1e6:.3g} us, Eq. 4); a cos^6 fit needs {MIN_FIT_SAMPLES} samples on its "
            f"rising edge; allowed: <= {tau / MIN_FIT_SAMPLES:.3g} s",
        )


def check_multiple(path, interval: float, step: float, step_key: str) -> None:
    """``interval`` is a whole number (>= 1) of ``step``, both s."""
    ratio = interval / step
    if ratio < 1 - MULTIPLE_TOLERANCE or abs(ratio - round(ratio)) > MULTIPLE_TOLERANCE * ratio:
        fail(
            path,
            f"{interval:g} s is not a whole number of {step_key} = {step:g} s (the samples "
            f"would fall every {max(1, round(ratio)) * step:g} s); allowed: k x {step:g} s, "
            "k = 1, 2, ...",
        )


def sensor_room(entry: Mapping) -> tuple[float, float]:
    """How far S1 and S2 of a chain sit from its collision point, (N + 1) / 2, beads
    (S1 left of it, S2 right of it; negative when on the wrong side)."""
    middle = collision_point(entry["N"])
    return middle - entry["sensors"][0], entry["sensors"][-1] - middle


def _check_sensors(config: Mapping) -> None:
    # check.py checks 1 <= S1 < S2 <= N; each sensor must also read two pulses apart.
    for i, entry in enumerate(config["chains"]):
        middle = collision_point(entry["N"])
        for j, room in enumerate(sensor_room(entry)):
            if room < MIN_SENSOR_DISTANCE:
                side = ("left", "right")[j]
                limit = middle - MIN_SENSOR_DISTANCE if j == 0 else middle + MIN_SENSOR_DISTANCE
                allowed = f"S1 <= {limit:g}" if j == 0 else f"S2 >= {limit:g}"
                fail(
                    ["chains", i, "sensors", j],
                    f"bead {entry['sensors'][j]} is {room:g} beads {side} of the collision "
                    f"point of the N = {entry['N']} chain (bead {middle:g}); the sensor reads "
                    f"the incident and the crossed pulse apart only from "
                    f"{MIN_SENSOR_DISTANCE:g} beads away; allowed: {allowed}",
                )


def _check_simulation(config: Mapping) -> None:
    simulation, launch = config["simulation"], config["launch"]
    record, step = simulation["record_interval_s"], simulation.get("time_step_s")
    path = ["simulation", "record_interval_s"]
    if step is not None:
        check_multiple(path, record, step, "simulation.time_step_s")
    fastest = LAUNCH_VELOCITY_RATIO * launch["v0_max_m_s"]
    check_resolution(config, path, record, fastest, f"bead 1 at {launch['v0_max_m_s']:g} m/s")
    drift = simulation["max_energy_drift"]
    if step is None and drift < DEFAULT_STEP_DRIFT:
        fail(
            ["simulation", "max_energy_drift"],
            f"{drift:g} is below the drift of the default time step (~{DEFAULT_STEP_DRIFT:g}); "
            f"allowed: >= {DEFAULT_STEP_DRIFT:g}, or a smaller simulation.time_step_s",
        )


def _check_long_chains(config: Mapping) -> None:
    duration = config.get("long_chains", {}).get("duration_s")
    if duration is None:
        return
    v0, what = config["launch"]["v0_min_m_s"], "bead 1 launched, to the middle bead"
    for n in config["long_chains"].get("N", []):
        middle = (n + 1) // 2
        long_chain = {**config, "chains": [{"N": n, "sensors": [middle, middle]}]}
        check_passing(
            long_chain, ["long_chains", "duration_s"], duration, v0, what, DURATION_MARGIN
        )


def _check_lammps(config: Mapping) -> None:
    options = config["lammps"]
    step, record = options["time_step_s"], options["record_interval_s"]
    path = ["lammps", "record_interval_s"]
    check_multiple(path, record, step, "lammps.time_step_s")
    speeds = [*options["check_speeds_m_s"], *options["sweep"]["launch_speeds_m_s"]]
    fastest = LAUNCH_VELOCITY_RATIO * max(speeds)
    check_resolution(config, path, record, fastest, f"bead 1 at {max(speeds):g} m/s")
    duration = options["duration_s"]
    check_samples(["lammps", "duration_s"], duration, record, "lammps.record_interval_s")
    check_passing(
        config, ["lammps", "duration_s"], duration, min(speeds), "bead 1 launched", DURATION_MARGIN
    )


def _check_setting_names(config: Mapping) -> None:
    # Settings that file names (2 decimals; gamma 6 digits) would confuse.
    sweep, base = config["lammps"]["sweep"], ["lammps", "sweep"]
    frictionless = setting_name(0.0, 0.0)
    for key in ("track_friction", "bead_friction", "default_settings"):
        names: dict[str, object] = {}
        for i, value in enumerate(sweep[key]):
            pair = tuple(value) if key == "default_settings" else (value, value)
            name = setting_name(*pair)
            if pair != (0, 0) and name == frictionless:
                fail(
                    [*base, key, i],
                    f"{value} is named as the frictionless setting ({name}: file names keep "
                    "2 decimals); allowed: 0 or >= 0.005",
                )
            if names.setdefault(name, pair) != pair:
                fail(
                    [*base, key, i],
                    f"{value} and {names[name]} share the file name {name} (2 decimals); "
                    "allowed: values at least 0.005 apart",
                )
    sweep_settings(config, full=True)
    for key in ("default_viscous_N_s_per_m", "viscous_N_s_per_m"):
        seen: dict[str, float] = {}
        for i, gamma in enumerate(sweep[key]):
            name = viscous_name(float(gamma))
            if seen.setdefault(name, gamma) != gamma:
                fail(
                    [*base, key, i],
                    f"{gamma} and {seen[name]} share the file name {name} (6 digits); "
                    "allowed: values apart in 6 significant digits",
                )


def check_run_bounds(config: Mapping) -> None:
    """The bounds of the simulated run that need two keys (module docstring) in
    ``config``, a schema-valid config that passed the checks before the bounds;
    :class:`~chain.errors.ConfigError` naming the first offending key."""
    _check_sensors(config)
    _check_simulation(config)
    _check_long_chains(config)
    if config["studies"]["mechanisms"]:
        _check_lammps(config)
        _check_setting_names(config)
