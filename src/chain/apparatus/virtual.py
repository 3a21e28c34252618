"""The virtual experiment: a model of the paper's apparatus that writes "measured" files.

This is a MODEL, not data. It stands in for the lab of Sec. III so that the pipeline
can run its measured-trace path end to end, and so that the analysis can be tested on
data whose truth is known: a free chain with Kuwabara-Kono dissipation on a track
(optionally with track friction, a linear drag: the paper estimates it to be of the
order of the viscous losses, Sec. V, but gives no law for it); two small spherical
strikers launched at beads 1 and N; split sensor beads read as the sensor spring force;
shot-to-shot imperfections (striker speed mismatch, launch jitter, which leaves an
initial gap between a striker and its end bead, the digitiser's sampling phase), all
drawn from ``numpy.random.default_rng(seed)``; and the acquisition of
:mod:`chain.apparatus.acquisition` (noise, sampling, sensitivity, ADC). Each setting is
described in :class:`~chain.apparatus.virtual_settings.VirtualExperiment`; its switches
(``readout``, ``launch``, ``reference_speed_mismatch``) turn single ingredients into
the paper's simulation for the ablation study (:mod:`chain.studies.ablation`).

Each nominal amplitude gets ``collision_shots`` shots with both strikers and
``reference_shots`` with the left striker alone (the right striker absent). The shots
are written in the measured-trace format (:mod:`chain.apparatus.measured`), so
:func:`chain.apparatus.measured.load_dataset` reads them like a lab's files; a
``virtual_truth.csv`` beside them records what each shot really was.

The settings and their checks live in :mod:`chain.apparatus.virtual_settings`, the shot
plan in :mod:`chain.apparatus.virtual_plan`, the simulation of the shots in
:mod:`chain.apparatus.virtual_shots` and the writing of the dataset in
:mod:`chain.apparatus.virtual_dataset`; this module gathers their public names.
"""

from chain.apparatus.virtual_dataset import TRUTH_FILE, run_virtual_experiment
from chain.apparatus.virtual_plan import plan_shots
from chain.apparatus.virtual_settings import (
    DEFAULT_IMPACT_SPEEDS_M_S,
    LAUNCHES,
    READOUTS,
    TIME_STEP_COARSENING,
    VirtualExperiment,
    check_switches,
)
from chain.apparatus.virtual_shots import MAX_BATCH, RECORD_OVERSAMPLING, simulate_virtual_shots
from chain.labels import VIRTUAL_LABEL

__all__ = [
    "DEFAULT_IMPACT_SPEEDS_M_S",
    "LAUNCHES",
    "MAX_BATCH",
    "READOUTS",
    "RECORD_OVERSAMPLING",
    "TIME_STEP_COARSENING",
    "TRUTH_FILE",
    "VIRTUAL_LABEL",
    "VirtualExperiment",
    "check_switches",
    "plan_shots",
    "run_virtual_experiment",
    "simulate_virtual_shots",
]
