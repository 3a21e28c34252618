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
from chain.apparatus.measured import FORMAT_NAME, METADATA_FILE, write_metadata, write_shot_csv
from chain.apparatus.virtual_plan import _plan
from chain.apparatus.virtual_settings import VirtualExperiment
from chain.apparatus.virtual_shots import simulate_virtual_shots
from chain.atomic import ordinary_mode, replace_folder, temporary_beside, write_text_atomic
from chain.errors import ParameterError
from chain.labels import VIRTUAL_LABEL
from chain.physics.materials import Material

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
