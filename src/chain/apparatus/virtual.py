"""The virtual experiment: a model of the paper's apparatus that writes "measured" files.

This is a MODEL, not data. It stands in for the lab of Sec. III so that the pipeline
can run its measured-trace path end to end, and so that the analysis can be tested on
data whose truth is known:

* a free chain of N beads (Hertz contacts with Kuwabara-Kono dissipation, relaxation
  time ``eta``) on a track;
* two small spherical strikers (radius ``striker_radius``, the bead material) touching
  beads 1 and N, launched towards the chain at the impact speed (or sqrt(2 g h) for a
  drop height h);
* split sensor beads (two halves joined by the sensor stiffness) read as the sensor
  spring force (``readout="sensor"`` of :mod:`chain.physics.simulation`);
* optional track friction, a linear drag F = -m gamma v on every particle (gamma =
  ``drag_rate``, 1/s; 0 by default). It is the simplest momentum-losing term and is
  configurable; the paper estimates track friction to be of the order of the viscous
  losses (Sec. V) but gives no law for it;
* shot-to-shot imperfections, all drawn from ``numpy.random.default_rng(seed)``:
  each striker's speed is the nominal one times (1 + speed_mismatch x normal); the
  right striker is launched ``delay`` = timing_jitter_s x normal later than the left
  one (an initial gap speed x delay between striker and end bead; a negative delay puts
  the gap on the left striker instead); the digitiser's sampling phase is uniform in
  one interval;
* acquisition (:mod:`chain.apparatus.acquisition`): additive Gaussian noise, sampling every
  ``sampling_interval_s``, volts through the sensitivity, ADC quantisation.

Switches for ablation studies (:mod:`chain.pipeline.ablation`) turn single ingredients
into the paper's simulation: ``readout="felt"`` reads plain beads instead of split
sensor beads, ``launch="bead"`` launches the end beads instead of strikers, and
``reference_speed_mismatch`` sets the reference shots' speed spread apart.

Each nominal amplitude gets ``collision_shots`` shots with both strikers and
``reference_shots`` with the left striker alone (the right striker absent). The shots
are written in the measured-trace format (:mod:`chain.apparatus.measured`), so
:func:`chain.apparatus.measured.load_dataset` reads them like a lab's files; a
``virtual_truth.csv`` beside them records what each shot really was.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from chain.apparatus.acquisition import (
    PCB_200B02_SENSITIVITY_MV_PER_N,
    add_noise,
    check_adc_bits,
    newtons_to_volts,
    quantise,
    resample,
)
from chain.apparatus.measured import (
    FORMAT_NAME,
    METADATA_FILE,
    impact_speed_from_drop_height,
    read_metadata,
    write_metadata,
    write_shot_csv,
)
from chain.atomic import ordinary_mode, replace_folder, write_text_atomic
from chain.errors import (
    ParameterError,
    check_bead_numbers,
    require_int,
    require_nonnegative,
    require_positive,
)
from chain.labels import VIRTUAL_LABEL
from chain.physics.materials import Material, get_material
from chain.physics.model import (
    PAPER_BEAD_RADIUS,
    PAPER_STRIKER_RADIUS,
    PCB_200B02_STIFFNESS,
    uniform_chain,
)
from chain.physics.simulation import default_time_step, felt_contacts, simulate

#: File beside the shots recording the true launch of each shot (ignored by the loader).
TRUTH_FILE = "virtual_truth.csv"

#: Default nominal impact speeds, m/s: incident amplitudes of about 9-90 N at the first
#: sensor of the paper's chains (drop heights 8 mm to 32 cm).
DEFAULT_IMPACT_SPEEDS_M_S = (0.4, 0.6, 0.8, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5)

#: The virtual experiment integrates with this many times the conservative default step
#: of :func:`chain.physics.simulation.default_time_step` (which aims at a 1e-9 energy drift).
#: At 8x the sensor forces change by ~1e-6 relative (checked against 1x), far below
#: the sensor noise and the ADC step, and a paper-sized run takes seconds.
TIME_STEP_COARSENING = 8

#: Simulated samples per digitiser interval; the digitiser interpolates between them.
RECORD_OVERSAMPLING = 4

#: Launches per integrator call: bounds memory (a few MB per launch).
MAX_BATCH = 16


@dataclass(frozen=True)
class VirtualExperiment:
    """Settings of the virtual experiment (a model of the paper's apparatus).

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
    eta : float
        Kuwabara-Kono relaxation time, s (paper: 0.58e-6).
    drag_rate : float
        Track friction rate gamma, 1/s: every particle feels -m gamma v (0: none).
    sensor_stiffness : float
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
    """

    n_beads: int = 25
    sensor_beads: tuple[int, ...] = (9, 17)
    material: str | Material = "steel_100C6"
    radius: float = PAPER_BEAD_RADIUS
    striker_radius: float = PAPER_STRIKER_RADIUS
    eta: float = 0.58e-6
    drag_rate: float = 0.0
    sensor_stiffness: float = PCB_200B02_STIFFNESS
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

    def __post_init__(self) -> None:
        # Checked in field order; lists from a config become tuples (the dataclass is
        # frozen, hence object.__setattr__).
        require_int("n_beads", self.n_beads, 2)
        beads = check_bead_numbers("sensor_beads", self.sensor_beads, self.n_beads)
        object.__setattr__(self, "sensor_beads", beads)
        if not isinstance(self.material, Material):
            get_material(self.material)
        for name in ("radius", "striker_radius", "sensor_stiffness", "sampling_interval_s"):
            require_positive(name, getattr(self, name))
        for name in ("eta", "drag_rate", "timing_jitter_s", "noise_N"):
            require_nonnegative(name, getattr(self, name))
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
        """Settings from a plain mapping (a config section); unknown keys are errors.

        Parameters
        ----------
        mapping : dict
            Field names to values (lists are accepted for tuples).
        """
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(mapping) - known)
        if unknown:
            raise ParameterError(
                f"virtual experiment: unknown settings {unknown}; known: {sorted(known)}"
            )
        return cls(**dict(mapping))

    @classmethod
    def from_dataset(cls, folder: str | os.PathLike) -> VirtualExperiment:
        """The settings that wrote a virtual dataset, read back from its
        ``metadata.yaml`` (to regenerate it, or to simulate it without noise).

        Parameters
        ----------
        folder : path
            A dataset folder written by :func:`run_virtual_experiment`.
        """
        path = Path(folder) / METADATA_FILE
        read_metadata(folder)  # checks the format, names the file on error
        mapping = yaml.safe_load(path.read_text(encoding="utf-8"))
        apparatus = dict(mapping.get("apparatus") or {})
        if apparatus.get("model") != VIRTUAL_LABEL:
            raise ParameterError(f"{path}: not written by the virtual experiment")
        for key in ("model", "generator"):
            apparatus.pop(key, None)
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

    def speed(nominal, draw, spread=sigma):
        # A few-percent mismatch never makes a speed negative; the floor is a guard only.
        return nominal * max(1.0 + spread * draw, 0.05)

    rows = []
    for a in range(n_amp):
        for c in range(n_col):
            left_draw, right_draw, delay_draw = collision_draws[a, c]
            rows.append(
                (
                    "collision",
                    a,
                    speed(speeds[a], left_draw),
                    speed(speeds[a], right_draw),
                    settings.timing_jitter_s * delay_draw,
                    collision_phase[a, c],
                )
            )
        for r in range(n_ref):
            rows.append(
                (
                    "reference",
                    a,
                    speed(speeds[a], reference_draws[a, r], sigma_ref),
                    0.0,
                    0.0,
                    reference_phase[a, r],
                )
            )
    plan = pd.DataFrame(
        rows,
        columns=["kind", "amplitude", "v_left_m_s", "v_right_m_s", "delay_s", "phase"],
    )
    plan.insert(0, "shot", np.arange(len(plan)))
    plan.insert(1, "file", [f"shot_{s:04d}.csv" for s in plan["shot"]])
    plan.insert(4, "nominal_speed_m_s", speeds[plan["amplitude"]])
    plan.insert(5, "drop_height_m", heights[plan["amplitude"]])
    plan["sampling_phase_s"] = plan.pop("phase") * settings.sampling_interval_s
    return plan


#: Values of the ablation switches of :class:`VirtualExperiment`.
READOUTS = ("sensor", "felt")
LAUNCHES = ("striker", "bead")


def check_switches(settings: VirtualExperiment) -> None:
    """Check the readout and launch switches and ``reference_speed_mismatch``.

    Raises
    ------
    ParameterError
        Naming the field and what is allowed.
    """
    if settings.readout not in READOUTS:
        raise ParameterError(f"readout must be one of {READOUTS}, got {settings.readout!r}")
    if settings.launch not in LAUNCHES:
        raise ParameterError(f"launch must be one of {LAUNCHES}, got {settings.launch!r}")
    if settings.reference_speed_mismatch is not None:
        value = require_nonnegative("reference_speed_mismatch", settings.reference_speed_mismatch)
        if value >= 0.5:
            raise ParameterError(f"reference_speed_mismatch is a relative std < 0.5, got {value}")


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


def _sensor_forces(settings, model, plan, dt, record_interval):
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
            initial_displacement=_initial_displacement(model, part),
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
    settings: VirtualExperiment, plan: pd.DataFrame
) -> tuple[np.ndarray, np.ndarray]:
    """Integrate the shots of ``plan`` (from :func:`plan_shots`) with the apparatus model.

    Collision shots use a chain with both strikers, reference shots one with the left
    striker only, both with the same time step; each kind is batched. With
    ``launch="bead"`` there are no strikers (the end beads are launched) and with
    ``readout="felt"`` no split sensor beads.

    Returns
    -------
    time : (S,) s
        Simulated (fine) time, from the first impact.
    forces : (B, n_sensors, S) N
        Sensor readings of every shot of ``plan``, in plan order.
    """
    check_switches(settings)
    material = settings.material_object
    common = dict(
        material=material,
        radius=settings.radius,
        eta=settings.eta,
        sensor_beads=settings.sensor_beads if settings.readout == "sensor" else (),
        sensor_stiffness=settings.sensor_stiffness,
        striker_radius=settings.striker_radius if settings.launch == "striker" else None,
        drag_rate=settings.drag_rate,
    )
    both = uniform_chain(settings.n_beads, strikers="both", **common)
    left = uniform_chain(settings.n_beads, strikers="left", **common)
    record_interval = settings.sampling_interval_s / RECORD_OVERSAMPLING
    fastest = float(plan[["v_left_m_s", "v_right_m_s"]].to_numpy().max())
    dt = settings.time_step_s or TIME_STEP_COARSENING * default_time_step(both, fastest)
    # A whole number of steps per recorded sample keeps the record grid exact.
    dt = record_interval / math.ceil(record_interval / dt - 1e-9)
    forces = np.empty((len(plan), len(settings.sensor_beads), 0))
    time = None
    for kind, model in (("collision", both), ("reference", left)):
        rows = np.flatnonzero(plan["kind"].to_numpy() == kind)
        if rows.size == 0:
            continue
        time, kind_forces = _sensor_forces(settings, model, plan.iloc[rows], dt, record_interval)
        if forces.shape[2] == 0:
            forces = np.empty((len(plan), len(settings.sensor_beads), time.size))
        forces[rows] = kind_forces
    return time, forces


def run_virtual_experiment(
    settings: VirtualExperiment, out_folder: str | os.PathLike, dataset_name: str
) -> Path:
    """Run the virtual experiment and write its shots as a measured dataset.

    Writes, in ``out_folder``: one ``shot_XXXX.csv`` per shot, ``metadata.yaml`` (the
    measured-trace format of ``data/README.md``; nominal impact speeds or drop heights,
    description "virtual experiment (model)") and ``virtual_truth.csv`` (what each shot
    really was: true speeds, delay, sampling phase, whether the ADC saturated). The
    folder appears complete or not at all: everything is written to a temporary folder
    that then replaces ``out_folder`` (which may exist only if empty or a dataset).

    Parameters
    ----------
    settings : VirtualExperiment
        The apparatus and the shot plan.
    out_folder : path
        Dataset folder to create (e.g. ``results/<run>/experiment/raw/N25``).
    dataset_name : str
        Dataset name written in the metadata (the ``model`` column after loading);
        use the same name for the chains of one experiment so their fits pool.

    Returns
    -------
    Path
        ``out_folder``.
    """
    if not isinstance(dataset_name, str) or not dataset_name.strip():
        raise ParameterError(f"dataset_name must be a non-empty string, got {dataset_name!r}")
    out = Path(out_folder)
    if out.exists() and (
        not out.is_dir() or (any(out.iterdir()) and not (out / METADATA_FILE).exists())
    ):
        raise ParameterError(f"{out}: exists and is not a dataset folder; refusing to replace it")
    rng = np.random.default_rng(settings.seed)
    plan = _plan(settings, rng)
    time, forces = simulate_virtual_shots(settings, plan)

    out.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        os.chmod(staging, ordinary_mode(directory=True))
        saturated = _write_shots(settings, plan, time, forces, rng, staging)
        if saturated.any():
            # A lab would re-range the digitiser; a clipped top biases the amplitude fit.
            warnings.warn(
                f"virtual experiment: the ADC saturated (|V| >= {settings.adc_range_V} V) in "
                f"shots {plan['shot'][saturated].tolist()}; raise adc_range_V",
                stacklevel=2,
            )
        truth = plan.assign(adc_saturated=saturated)
        text = truth.to_csv(index=False, float_format="%.10g", lineterminator="\n")
        write_text_atomic(text, staging / TRUTH_FILE)
        write_metadata(staging, _metadata(settings, plan, dataset_name))
        replace_folder(staging, out)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return out


def _write_shots(settings, plan, time, forces, rng, folder: Path) -> np.ndarray:
    saturated = np.zeros(len(plan), dtype=bool)
    sensitivities = np.array(settings.sensitivities)
    for i, shot in enumerate(plan.itertuples(index=False)):
        instants, sampled = resample(
            time, forces[i], settings.sampling_interval_s, shot.sampling_phase_s
        )
        noisy = add_noise(sampled, settings.noise_N, rng)
        volts = newtons_to_volts(noisy, 1.0) * sensitivities[:, None]
        if settings.adc_bits is not None:
            saturated[i] = bool(np.any(np.abs(volts) >= settings.adc_range_V))
            volts = quantise(volts, settings.adc_bits, settings.adc_range_V)
        write_shot_csv(folder / shot.file, instants, volts, settings.sensor_beads)
    return saturated


def _metadata(settings: VirtualExperiment, plan: pd.DataFrame, dataset_name: str) -> dict:
    apparatus = {
        key: _plain(value)
        for key, value in asdict(settings).items()
        if key not in ("n_beads", "sensor_beads", "sensitivity_mV_per_N", "sampling_interval_s")
    }
    if isinstance(settings.material, Material):
        apparatus["material"] = _plain(asdict(settings.material))
    apparatus = {
        "model": VIRTUAL_LABEL,
        "generator": "chain.apparatus.virtual.run_virtual_experiment",
        **apparatus,
    }
    sensitivities = settings.sensitivities
    shots = []
    for shot in plan.itertuples(index=False):
        entry = {"file": shot.file, "kind": shot.kind, "amplitude": int(shot.amplitude)}
        if settings.drop_heights_m is not None:
            entry["drop_height_m"] = float(shot.drop_height_m)
        else:
            entry["impact_speed_m_s"] = float(shot.nominal_speed_m_s)
        shots.append(entry)
    return {
        "format": FORMAT_NAME,
        "name": dataset_name,
        "description": (
            f"{VIRTUAL_LABEL}: simulated shots of a model of the apparatus of Santibanez "
            "et al. (strikers, split sensor beads, digitiser); not measured data. True "
            f"launches in {TRUTH_FILE}."
        ),
        "apparatus": apparatus,
        "N": settings.n_beads,
        "sensor_beads": list(settings.sensor_beads),
        "sensitivity_mV_per_N": (
            sensitivities[0] if len(set(sensitivities)) == 1 else list(sensitivities)
        ),
        "sampling_interval_s": settings.sampling_interval_s,
        "shots": shots,
    }


def _plain(value):
    """``value`` with tuples, numpy scalars and arrays turned into plain YAML types."""
    if isinstance(value, dict):
        return {key: _plain(item) for key, item in value.items()}
    if isinstance(value, tuple | list | np.ndarray):
        return [_plain(item) for item in value]
    if isinstance(value, np.generic):
        return value.item()
    return value
