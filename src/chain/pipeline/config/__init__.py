"""Config checks: the schema's relations between keys, every key's usable bounds, the
config files' YAML, and what the ablation and virtual-experiment sections mean.

Here, what the checks of :mod:`.check` and :mod:`.bounds_run`, :mod:`.bounds_experiment`
share: the message naming a key, a record's samples, the slowest wave, the launch.
"""

from collections.abc import Mapping

from chain.errors import ConfigError, key_label
from chain.physics.theory import LAUNCH_VELOCITY_RATIO, pulse_passing_time


def fail(path, message: str):
    """Raise :class:`ConfigError` naming the key ``path`` (keys and list indices)."""
    raise ConfigError(f"config key {key_label(path)!r}: {message}")


def check_samples(path, duration: float, interval: float, interval_key: str) -> None:
    """``duration`` (s) holds at least 10 samples of ``interval`` (s), the key named."""
    if duration < 10 * interval:
        fail(
            path,
            f"{duration:g} s holds fewer than 10 samples of {interval_key} = {interval:g} s; "
            f"allowed: >= {10 * interval:g} s",
        )


def slowest_passing(config: Mapping, v0: float) -> dict:
    """:func:`chain.physics.theory.pulse_passing_time` and ``N`` of the chain of
    ``config`` whose far sensor the wave of bead 1 launched at ``v0`` (m/s) passes last."""

    def passing(entry: Mapping) -> dict:
        args = config["material"], config["radius_m"], entry["N"], entry["sensors"], v0
        return pulse_passing_time(*args) | {"N": entry["N"]}

    return max(map(passing, config["chains"]), key=lambda found: found["time_s"])


def check_passing(config: Mapping, path, duration: float, v0: float, what: str, margin: float):
    """``duration`` (s) >= ``margin`` x the time the wave of bead 1 launched at ``v0``
    (m/s) takes to pass the far sensor of the chain it passes last
    (:func:`slowest_passing`); ``what`` names the launch, ``path`` the key."""
    worst = slowest_passing(config, v0)
    needed = margin * worst["time_s"]
    if duration < needed:
        fail(
            path,
            f"{duration:g} s is too short: the slowest wave ({what} at V0 = {v0:g} m/s: "
            f"F_m ~ {worst['force_N']:.3g} N, Eq. 5 speed {worst['speed_m_s']:.0f} m/s) has "
            f"passed bead {worst['bead']} of the N = {worst['N']} chain, "
            f"{worst['distance_m']:.3g} m from its launching end, at "
            f"~{worst['time_s'] * 1e3:.3g} ms; allowed: >= {margin:g} x that = {needed:.3g} s "
            "(or faster launches)",
        )


def launch_ratios(config: Mapping, virtual: Mapping) -> tuple[float, float]:
    """(least, most) V_m / V0 of the launch of ``virtual`` (``experiment.virtual`` of the
    schema-valid ``config``): a striker of mass m_s stops or bounces back elastically,
    handing the chain between m_s V0 and 2 m_s m / (m_s + m) V0; a launched bead
    (``launch: bead``) gives V_m = LAUNCH_VELOCITY_RATIO x V0."""
    if virtual.get("launch", "striker") == "bead":
        return LAUNCH_VELOCITY_RATIO, LAUNCH_VELOCITY_RATIO
    mass_ratio = (config["setup"]["striker_radius_m"] / config["radius_m"]) ** 3
    most = LAUNCH_VELOCITY_RATIO * 2.0 * mass_ratio / (1.0 + mass_ratio)
    return LAUNCH_VELOCITY_RATIO * mass_ratio, most
