"""The virtual experiment's settings from a config (config keys -> VirtualExperiment
fields, chain.apparatus.virtual_settings), and the error a bad config raises.

Its own module so that both :mod:`chain.pipeline.config` (the checks) and
:mod:`chain.pipeline.ablation` (the variants) use it without importing each other.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence


class ConfigError(ValueError):
    """A configuration value is inconsistent; the message names the key."""


#: Config key of experiment.virtual -> field of chain.apparatus.virtual.VirtualExperiment.
VIRTUAL_FIELDS = {
    "eta_s": "eta",
    "drag_rate_per_s": "drag_rate",
    "sensor_stiffness_N_per_m": "sensor_stiffness",
    "sensitivity_mV_per_N": "sensitivity_mV_per_N",
    "impact_speeds_m_s": "impact_speeds_m_s",
    "drop_heights_m": "drop_heights_m",
    "collision_shots": "collision_shots",
    "reference_shots": "reference_shots",
    "speed_mismatch": "speed_mismatch",
    "timing_jitter_s": "timing_jitter_s",
    "noise_N": "noise_N",
    "sampling_interval_s": "sampling_interval_s",
    "adc_bits": "adc_bits",
    "adc_range_V": "adc_range_V",
    "duration_s": "duration_s",
    "time_step_s": "time_step_s",
    "readout": "readout",
    "launch": "launch",
    "reference_speed_mismatch": "reference_speed_mismatch",
    "radius_dispersion": "radius_dispersion",
    "gap_mean_m": "gap_mean_m",
    "gap_spread_m": "gap_spread_m",
    "right_speed_offset": "right_speed_offset",
    "right_delay_s": "right_delay_s",
}


def virtual_experiment_settings(config: Mapping, n_beads: int, sensors: Sequence[int]) -> dict:
    """The :class:`chain.apparatus.virtual.VirtualExperiment` fields for one chain of a config.

    Material and radius are the run's, the striker radius ``setup.striker_radius_m``,
    the seed the top-level seed + N (so that the chains' shots differ), the rest
    ``experiment.virtual`` renamed by :data:`VIRTUAL_FIELDS`.

    Parameters
    ----------
    config : mapping
        A schema-valid config (defaults filled in).
    n_beads : int
        N.
    sensors : sequence of int
        Sensor beads [S1, S2].

    Returns
    -------
    dict
        Plain values (lists for tuples), ready for ``VirtualExperiment.from_dict``.
    """
    virtual = config.get("experiment", {}).get("virtual", {})
    settings = {VIRTUAL_FIELDS[key]: value for key, value in virtual.items()}
    settings.update(
        n_beads=int(n_beads),
        sensor_beads=[int(b) for b in sensors],
        material=config["material"],
        radius=config["radius_m"],
        striker_radius=config.get("setup", {}).get("striker_radius_m", 0.004),
        seed=int(config.get("seed", 0)) + int(n_beads),
    )
    return settings
