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

Switches for ablation studies (:mod:`chain.studies.ablation`) turn single ingredients
into the paper's simulation: ``readout="felt"`` reads plain beads instead of split
sensor beads, ``launch="bead"`` launches the end beads instead of strikers, and
``reference_speed_mismatch`` sets the reference shots' speed spread apart.

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
from chain.apparatus.virtual_shots import (
    MAX_BATCH,
    RECORD_OVERSAMPLING,
    simulate_virtual_shots,
)
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
