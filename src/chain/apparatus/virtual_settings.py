"""Settings of the virtual experiment and their checks (a MODEL of the apparatus;
see :mod:`chain.apparatus.virtual`)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np
import yaml

from chain.apparatus.acquisition import PCB_200B02_SENSITIVITY_MV_PER_N, check_adc_bits
from chain.apparatus.measured_format import METADATA_FILE
from chain.apparatus.metadata import impact_speed_from_drop_height, read_metadata
from chain.errors import (
    ParameterError,
    check_bead_numbers,
    require_int,
    require_nonnegative,
    require_positive,
)
from chain.labels import VIRTUAL_LABEL
from chain.physics.materials import Material, get_material
from chain.physics.model import PAPER_BEAD_RADIUS, PAPER_STRIKER_RADIUS, PCB_200B02_STIFFNESS

#: Stream number of the per-chain draws (bead radii, gaps): default_rng((seed, this)),
#: independent of the shot draws of default_rng(seed).
CHAIN_STREAM = 24

#: Fields drawn once per chain (non-negative).
_CHAIN_FIELDS = ("radius_dispersion", "gap_mean_m", "gap_spread_m")

#: Field names of older datasets -> the config's names, for
#: :meth:`VirtualExperiment.from_dataset`.
_LEGACY_FIELDS = {
    "eta": "eta_s",
    "drag_rate": "drag_rate_per_s",
    "sensor_stiffness": "sensor_stiffness_N_per_m",
}

#: The virtual experiment integrates with this many times the conservative default step
#: of :func:`chain.physics.time_step.default_time_step` (which aims at a 1e-9 energy drift).
#: At 8x the sensor forces change by ~1e-6 relative (checked against 1x), far below
#: the sensor noise and the ADC step, and a paper-sized run takes seconds.
TIME_STEP_COARSENING = 8

#: Default nominal impact speeds, m/s: incident amplitudes of about 9-90 N at the first
#: sensor of the paper's chains (drop heights 8 mm to 32 cm).
DEFAULT_IMPACT_SPEEDS_M_S = (0.4, 0.6, 0.8, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5)


@dataclass(frozen=True)
class VirtualExperiment:
    """Settings of the virtual experiment (a model of the paper's apparatus).

    The fields a pipeline config sets carry the names of its ``experiment.virtual``
    keys (units in the name), so a config section is passed on as it is.

    Attributes
    ----------
    n_beads : int
        Number of beads N (paper: 25 or 26).
    sensor_beads : tuple of int
        Split sensor beads, S1 first (paper: (9, 17) for N = 25, (10, 17) for N = 26).
    material : str or Material
        Bead and striker material (name from :data:`chain.physics.materials.MATERIALS`).
    radius : float
        Bead radius, m (paper: 13e-3).
    striker_radius : float
        Striker radius, m (paper: 4e-3).
    eta_s : float
        Kuwabara-Kono relaxation time, s (paper: 0.58e-6).
    drag_rate_per_s : float
        Track friction rate gamma, 1/s: every particle feels -m gamma v (0: none).
    sensor_stiffness_N_per_m : float
        Stiffness of the sensor between the halves of a split bead, N/m
        (PCB 200B02: 1.9e9).
    sensitivity_mV_per_N : float or tuple of float
        Sensor sensitivity, mV/N, one for all or one per sensor (PCB 200B02: 11.24).
    impact_speeds_m_s : tuple of float or None
        Nominal striker impact speeds, m/s, one per amplitude.
    drop_heights_m : tuple of float or None
        Nominal drop heights, m, one per amplitude (speed sqrt(2 g h)); give this or
        ``impact_speeds_m_s`` (neither: :data:`DEFAULT_IMPACT_SPEEDS_M_S`).
    collision_shots : int
        Shots with both strikers per amplitude (>= 1).
    reference_shots : int
        Shots with the left striker alone per amplitude (>= 0).
    speed_mismatch : float
        Relative standard deviation of each striker's impact speed (dimensionless).
    timing_jitter_s : float
        Standard deviation of the right striker's launch delay after the left, s.
    noise_N : float
        Standard deviation of the additive sensor noise, referred to force, N.
    sampling_interval_s : float
        Digitiser sampling interval, s.
    adc_bits : int or None
        ADC resolution, bits; None: no quantisation.
    adc_range_V : float
        ADC half span, V: the ADC reads [-adc_range_V, +adc_range_V).
    duration_s : float
        Recorded time per shot, s, from the first impact.
    time_step_s : float or None
        RK4 step, s; None: :data:`TIME_STEP_COARSENING` times the conservative default.
    seed : int
        Seed of ``numpy.random.default_rng``; the same seed gives the same bytes.
    readout : {"sensor", "felt"}
        ``sensor``: split sensor beads read as the sensor spring force (the apparatus);
        ``felt``: a point readout, the sensor beads are plain beads read as
        (F_{n-1,n} + F_{n,n+1}) / 2 (the paper's simulation, Fig. 3).
    launch : {"striker", "bead"}
        ``striker``: strikers of ``striker_radius`` hit beads 1 and N at the impact speed
        (the apparatus); ``bead``: no strikers, bead 1 (and bead N) start at the impact
        speed (the paper's simulation launch).
    reference_speed_mismatch : float or None
        Relative standard deviation of the reference shots' striker speed; None: the
        same as ``speed_mismatch``. The random draws are the same whatever the value.
    radius_dispersion : float
        Relative standard deviation s of the bead radii (0: equal beads): each radius
        is R (1 + s e), e standard normal, drawn once per chain (one set of beads for
        every shot) from ``default_rng((seed, CHAIN_STREAM))``, apart from the shots'.
    gap_mean_m, gap_spread_m : float
        Mean and standard deviation of the gap between neighbouring beads at rest, m
        (0: barely touching); gap k = max(0, mean + spread e), once per chain as above.
    right_speed_offset : float
        Systematic relative excess of the right striker's speed over the left one's
        (dimensionless; an amplitude mismatch that moves the collision point).
    right_delay_s : float
        Systematic delay of the right launch after the left one, s (added to the jitter).
    """

    n_beads: int = 25
    sensor_beads: tuple[int, ...] = (9, 17)
    material: str | Material = "steel_100C6"
    radius: float = PAPER_BEAD_RADIUS
    striker_radius: float = PAPER_STRIKER_RADIUS
    eta_s: float = 0.58e-6
    drag_rate_per_s: float = 0.0
    sensor_stiffness_N_per_m: float = PCB_200B02_STIFFNESS
    sensitivity_mV_per_N: float | tuple[float, ...] = PCB_200B02_SENSITIVITY_MV_PER_N
    impact_speeds_m_s: tuple[float, ...] | None = None
    drop_heights_m: tuple[float, ...] | None = None
    collision_shots: int = 5
    reference_shots: int = 3
    speed_mismatch: float = 0.02
    timing_jitter_s: float = 10e-6
    noise_N: float = 0.1
    sampling_interval_s: float = 1e-6
    adc_bits: int | None = 12
    adc_range_V: float = 2.0
    duration_s: float = 2.6e-3
    time_step_s: float | None = None
    seed: int = 0
    readout: str = "sensor"
    launch: str = "striker"
    reference_speed_mismatch: float | None = None
    radius_dispersion: float = 0.0
    gap_mean_m: float = 0.0
    gap_spread_m: float = 0.0
    right_speed_offset: float = 0.0
    right_delay_s: float = 0.0

    def __post_init__(self) -> None:
        # Checked in field order; lists from a config become tuples.
        require_int("n_beads", self.n_beads, 2)
        beads = check_bead_numbers("sensor_beads", self.sensor_beads, self.n_beads)
        object.__setattr__(self, "sensor_beads", beads)
        if not isinstance(self.material, Material):
            get_material(self.material)
        for name in ("radius", "striker_radius", "sensor_stiffness_N_per_m", "sampling_interval_s"):
            require_positive(name, getattr(self, name))
        for name in ("eta_s", "drag_rate_per_s", "timing_jitter_s", "noise_N", *_CHAIN_FIELDS):
            require_nonnegative(name, getattr(self, name))
        if self.radius_dispersion >= 0.1:
            raise ParameterError(
                f"radius_dispersion is a relative std < 0.1, got {self.radius_dispersion}"
            )
        if not -0.5 < self.right_speed_offset < 0.5:
            raise ParameterError(
                f"right_speed_offset is a relative excess in (-0.5, 0.5), "
                f"got {self.right_speed_offset}"
            )
        require_nonnegative("right_delay_s", self.right_delay_s)
        sensitivity = _checked_sensitivity(self.sensitivity_mV_per_N, len(beads))
        object.__setattr__(self, "sensitivity_mV_per_N", sensitivity)
        for name, values in _checked_amplitudes(self.impact_speeds_m_s, self.drop_heights_m):
            object.__setattr__(self, name, values)
        require_int("collision_shots", self.collision_shots, 1)
        require_int("reference_shots", self.reference_shots, 0)
        mismatch = require_nonnegative("speed_mismatch", self.speed_mismatch)
        if mismatch >= 0.5:
            raise ParameterError(f"speed_mismatch is a relative std < 0.5, got {mismatch}")
        if self.adc_bits is not None:
            check_adc_bits(self.adc_bits)
        require_positive("adc_range_V", self.adc_range_V)
        duration = require_positive("duration_s", self.duration_s)
        if duration < 3 * self.sampling_interval_s:
            raise ParameterError("duration_s must cover at least 3 sampling intervals")
        if self.time_step_s is not None:
            require_positive("time_step_s", self.time_step_s)
        require_int("seed", self.seed, 0)

    @classmethod
    def from_dict(cls, mapping: Mapping) -> VirtualExperiment:
        """Settings from a plain ``mapping`` of field names to values (a config section;
        lists are accepted for tuples); unknown keys are errors."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(mapping) - known)
        if unknown:
            raise ParameterError(
                f"virtual experiment: unknown settings {unknown}; known: {sorted(known)}"
            )
        return cls(**dict(mapping))

    @classmethod
    def from_dataset(cls, folder: str | os.PathLike) -> VirtualExperiment:
        """The settings that wrote the virtual dataset in ``folder`` (written by
        :func:`run_virtual_experiment`), read back from its ``metadata.yaml`` (to
        regenerate it, or to simulate it without noise)."""
        path = Path(folder) / METADATA_FILE
        read_metadata(folder)  # checks the format, names the file on error
        mapping = yaml.safe_load(path.read_text(encoding="utf-8"))
        apparatus = dict(mapping.get("apparatus") or {})
        if apparatus.get("model") != VIRTUAL_LABEL:
            raise ParameterError(f"{path}: not written by the virtual experiment")
        for key in ("model", "generator"):
            apparatus.pop(key, None)
        for old, new in _LEGACY_FIELDS.items():
            if old in apparatus:
                apparatus[new] = apparatus.pop(old)
        if isinstance(apparatus.get("material"), Mapping):
            apparatus["material"] = Material(**apparatus["material"])
        return cls.from_dict(
            {
                **apparatus,
                "n_beads": mapping["N"],
                "sensor_beads": mapping["sensor_beads"],
                "sensitivity_mV_per_N": mapping["sensitivity_mV_per_N"],
                "sampling_interval_s": float(mapping["sampling_interval_s"]),
            }
        )

    @property
    def material_object(self) -> Material:
        """The bead and striker :class:`~chain.physics.materials.Material`."""
        return self.material if isinstance(self.material, Material) else get_material(self.material)

    @property
    def sensitivities(self) -> tuple[float, ...]:
        """Sensitivity of each sensor, mV/N, S1 first."""
        s = self.sensitivity_mV_per_N
        return tuple(s) if isinstance(s, tuple) else (float(s),) * len(self.sensor_beads)

    @property
    def nominal_speeds(self) -> np.ndarray:
        """Nominal impact speed of each amplitude, m/s."""
        if self.drop_heights_m is not None:
            return impact_speed_from_drop_height(self.drop_heights_m)
        speeds = self.impact_speeds_m_s
        return np.array(DEFAULT_IMPACT_SPEEDS_M_S if speeds is None else speeds, dtype=float)


def _checked_sensitivity(sensitivity, n_sensors: int) -> float | tuple[float, ...]:
    """``sensitivity_mV_per_N`` checked: one positive value (mV/N) for all sensors, or
    a tuple of one per sensor."""
    if isinstance(sensitivity, Sequence) and not isinstance(sensitivity, str):
        sensitivity = tuple(require_positive("sensitivity_mV_per_N", s) for s in sensitivity)
        if len(sensitivity) != n_sensors:
            raise ParameterError(
                f"sensitivity_mV_per_N needs one value per sensor ({n_sensors}), "
                f"got {len(sensitivity)}"
            )
        return sensitivity
    return require_positive("sensitivity_mV_per_N", sensitivity)


def _checked_amplitudes(impact_speeds_m_s, drop_heights_m) -> list[tuple[str, tuple]]:
    """(field, tuple of positive values) of whichever of ``impact_speeds_m_s`` (m/s) and
    ``drop_heights_m`` (m) is given; giving both is an error."""
    if impact_speeds_m_s is not None and drop_heights_m is not None:
        raise ParameterError("give impact_speeds_m_s or drop_heights_m, not both")
    checked = []
    for name, values in (
        ("impact_speeds_m_s", impact_speeds_m_s),
        ("drop_heights_m", drop_heights_m),
    ):
        if values is not None:
            values = tuple(require_positive(name, v) for v in np.atleast_1d(values))
            if not values:
                raise ParameterError(f"{name} must list at least one value")
            checked.append((name, values))
    return checked


#: Values of the ablation switches of :class:`VirtualExperiment`.
READOUTS = ("sensor", "felt")
LAUNCHES = ("striker", "bead")


def check_switches(settings: VirtualExperiment) -> None:
    """Check the readout and launch switches and ``reference_speed_mismatch``; a
    :class:`ParameterError` names the field and what is allowed."""
    if settings.readout not in READOUTS:
        raise ParameterError(f"readout must be one of {READOUTS}, got {settings.readout!r}")
    if settings.launch not in LAUNCHES:
        raise ParameterError(f"launch must be one of {LAUNCHES}, got {settings.launch!r}")
    if settings.reference_speed_mismatch is not None:
        value = require_nonnegative("reference_speed_mismatch", settings.reference_speed_mismatch)
        if value >= 0.5:
            raise ParameterError(f"reference_speed_mismatch is a relative std < 0.5, got {value}")
