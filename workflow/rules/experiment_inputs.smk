# Input functions of the experiment's rules (experiment.smk) and of Fig. 2, from the
# plan's experiment parts.

from chain.pipeline.plan.datasets import bad_channel_policy


def raw_dataset(n):
    """Folder of the virtual experiment's dataset of the chain of n beads."""
    return PLAN.raw_dataset(n)


def experiment_datasets():
    """Each experiment dataset: series name, N and folder; None for the virtual
    experiment's, which the rules take as their `virtual` input, in order (a path
    holding the run name in a param would make every run's result its own)."""
    return [
        {"folder": part.folder, "name": part.name, "N": part.n_beads}
        for part in PLAN.experiment
    ]


def virtual_dataset_folders():
    """The virtual experiment's dataset folders (experiment/raw/N<N>), in order."""
    return [
        raw_dataset(part.n_beads) for part in PLAN.experiment if part.folder is None
    ]


def measured_dataset_files():
    """What loading the measured datasets depends on: each metadata.yaml and shot
    file (editing one reloads them)."""
    return [
        path
        for part in PLAN.experiment
        if part.folder is not None
        for path in part.files
    ]


def virtual_settings(wildcards):
    """The VirtualExperiment fields of one chain (plain values: a changed one reruns
    the job; RunPlan.virtual_settings)."""
    return PLAN.virtual_settings(int(wildcards.N))


def fig2_trace_files(wildcards):
    """Experiment chains shown in Fig. 2: those in figures.traces_N when it is set
    (all of them if it names none), else all."""
    chosen = config["figures"]["traces_N"]
    shown = [part for part in EXPERIMENT_PARTS if not chosen or part[2] in chosen]
    return [trace_file(*part) for part in shown or EXPERIMENT_PARTS]


BAD_CHANNELS = bad_channel_policy(config)


def experiment_trace_files(wildcards=None):
    return [trace_file(*part) for part in EXPERIMENT_PARTS]
