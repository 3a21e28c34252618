"""The virtual experiment's dataset: the shots simulated, digitised and written in the
measured-trace format, with the truth beside them (a MODEL; see
:mod:`chain.apparatus.virtual`)."""

from __future__ import annotations

import os
import warnings
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd

from chain.apparatus.acquisition import add_noise, newtons_to_volts, quantise, resample
from chain.apparatus.measured import (
    FORMAT_NAME,
    METADATA_FILE,
    MeasuredDataError,
    _shot_table,
    write_metadata,
    write_shot_csv,
)
from chain.apparatus.metadata import parse_metadata
from chain.apparatus.shot_files import channel_faults, read_shot_csv
from chain.apparatus.virtual_plan import _plan, plan_shots
from chain.apparatus.virtual_settings import VirtualExperiment
from chain.apparatus.virtual_shots import simulate_virtual_shots
from chain.atomic import ordinary_mode, replace_folder, temporary_beside, write_text_atomic
from chain.errors import ParameterError
from chain.labels import VIRTUAL_LABEL
from chain.physics.materials import Material
from chain.traces import META_COLUMNS, sensor_column, validate_traces

#: File beside the shots recording the true launch of each shot (ignored by the loader).
TRUTH_FILE = "virtual_truth.csv"


def run_virtual_experiment(
    settings: VirtualExperiment, out_folder: str | os.PathLike, dataset_name: str
) -> Path:
    """Run the virtual experiment and write its shots as a measured dataset; returns
    ``out_folder``.

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
    with temporary_beside(out, directory=True) as staging:
        os.chmod(staging, ordinary_mode(directory=True))
        saturated = np.zeros(len(plan), dtype=bool)
        for i, shot in enumerate(plan.itertuples(index=False)):
            instants, volts, saturated[i] = _digitise(settings, shot, time, forces[i], rng)
            write_shot_csv(staging / shot.file, instants, volts, settings.sensor_beads)
        _warn_saturated(settings, plan, saturated)
        truth = plan.assign(adc_saturated=saturated)
        text = truth.to_csv(index=False, float_format="%.10g", lineterminator="\n")
        write_text_atomic(text, staging / TRUTH_FILE)
        write_metadata(staging, _metadata(settings, plan, dataset_name))
        replace_folder(staging, out)
    return out


def _digitise(settings: VirtualExperiment, shot, time, forces, rng):
    """One shot as the digitiser records it: (instants (K,) s, volts (n_sensors, K) V,
    whether the ADC saturated), its noise drawn from ``rng``."""
    instants, sampled = resample(time, forces, settings.sampling_interval_s, shot.sampling_phase_s)
    noisy = add_noise(sampled, settings.noise_N, rng)
    volts = newtons_to_volts(noisy, 1.0) * np.array(settings.sensitivities)[:, None]
    if settings.adc_bits is None:
        return instants, volts, False
    saturated = bool(np.any(np.abs(volts) >= settings.adc_range_V))
    return instants, quantise(volts, settings.adc_bits, settings.adc_range_V), saturated


def _warn_saturated(settings: VirtualExperiment, plan: pd.DataFrame, saturated) -> None:
    if np.any(saturated):  # a lab would re-range: a clipped top biases the amplitude fit
        warnings.warn(
            f"virtual experiment: the ADC saturated (|V| >= {settings.adc_range_V} V) in "
            f"shots {plan['shot'][saturated].tolist()}; raise adc_range_V",
            stacklevel=3,
        )


#: The settings that move the speeds or the delay of some shots and nothing else: the
#: same random draws, chain, time grid (with a set time step) and digitiser.
_LAUNCH_DRAWS = {"speed_mismatch", "reference_speed_mismatch", "timing_jitter_s"}
_LAUNCH_DRAWS |= {"right_speed_offset", "right_delay_s"}


def _shots_of(settings: VirtualExperiment, plan: pd.DataFrame, other) -> np.ndarray:
    """Which shots of ``plan`` (of ``settings``) are the shots of the virtual experiment
    ``other`` (or None) to the bit: the settings, with a set time step, differ at most in
    :data:`_LAUNCH_DRAWS`, and the shot's launch and sampling phase are its."""
    mine, theirs = asdict(settings), asdict(other) if other else {}
    differ = {key for key in mine if key not in _LAUNCH_DRAWS and mine[key] != theirs.get(key)}
    if differ or settings.time_step_s is None:
        return np.zeros(len(plan), dtype=bool)
    columns = ["kind", "v_left_m_s", "v_right_m_s", "delay_s", "sampling_phase_s"]
    return (plan[columns] == plan_shots(other)[columns]).all(axis=1).to_numpy()


def virtual_traces(
    settings: VirtualExperiment,
    dataset_name: str,
    known: dict | None = None,
    run: tuple[VirtualExperiment, str | os.PathLike] | None = None,
) -> pd.DataFrame:
    """The trace table that :func:`chain.apparatus.measured.load_dataset` reads from
    the dataset :func:`run_virtual_experiment` writes with these settings, to the bit
    (the files' 10 significant digits of time and 7 of volts included), made in memory.

    Parameters
    ----------
    settings : VirtualExperiment
        The apparatus and the shot plan.
    dataset_name : str
        The ``model`` column.
    known : dict, optional
        Launches integrated already (:func:`simulate_virtual_shots`), filled here.
    run : (VirtualExperiment, path), optional
        Another virtual experiment and its dataset folder: its shots read from its files.
    """
    rng = np.random.default_rng(settings.seed)
    plan = _plan(settings, rng)
    read = _shots_of(settings, plan, run and run[0])
    shots = simulate_virtual_shots(settings, plan, known, ~read) if (~read).any() else (None, [])
    time, integrated = shots[0], iter(shots[1])
    meta = parse_metadata(_metadata(settings, plan, dataset_name))
    tables, saturated = [], np.zeros(len(plan), dtype=bool)
    for i, shot in enumerate(plan.itertuples(index=False)):
        if read[i]:
            instants, volts = read_shot_csv(Path(run[1]) / shot.file, settings.sensor_beads)
            add_noise(np.zeros(volts.shape), settings.noise_N, rng)  # the draws it took
        else:
            digitised = _digitise(settings, shot, time, next(integrated), rng)
            (instants, volts), saturated[i] = _as_written(*digitised[:2]), digitised[2]
        faults = channel_faults(shot.file, volts, settings.sensor_beads)
        if faults:
            raise MeasuredDataError("\n".join(faults))
        tables.append(_shot_table(meta, dataset_name, i, instants, volts))
    _warn_saturated(settings, plan, saturated)
    columns = list(META_COLUMNS) + [sensor_column(b) for b in settings.sensor_beads]
    table = pd.concat(tables, ignore_index=True)[columns]
    return validate_traces(table, where=f"virtual experiment {dataset_name}")


def _as_written(instants: np.ndarray, volts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A shot's samples as its file holds them: (times (K,) s, volts (n_sensors, K) V)
    as :func:`chain.apparatus.measured.write_shot_csv` writes them (times with 10
    significant digits, volts with 7) and :func:`~chain.apparatus.measured.read_shot_csv`
    parses them (Python's correctly rounded conversions both ways: one result per value,
    so a digitiser's few distinct values are converted once each)."""
    distinct, where = np.unique(volts + 0.0, return_inverse=True)  # -0 written as 0
    return _rounded(instants, "%.10g"), _rounded(distinct, "%.7g")[where].reshape(volts.shape)


def _rounded(values: np.ndarray, form: str) -> np.ndarray:
    return np.array((f"{form} " * values.size % tuple(values.tolist())).split(), dtype=float)


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
