# Input functions and settings of the ablation rules (ablation.smk), from the plan.

from chain.studies.ablation_table import overrides_text


wildcard_constraints:
    variant="|".join(PLAN.ablation) or "no-variant",


def ablation_settings(wildcards):
    """Per replicate, the VirtualExperiment fields of every chain of one variant."""
    return PLAN.ablation_settings(wildcards.variant)


def ablation_reads_run(wildcards):
    """Per replicate, whether it reads the run's virtual experiment (the `datasets`
    input) instead of simulating the same shots again (RunPlan.ablation_datasets): a
    flag, not the folders, whose path names the run (the result would be the run's own,
    not reusable by another)."""
    return [bool(folders) for folders in PLAN.ablation_datasets(wildcards.variant)]


def ablation_dataset_files(wildcards):
    """The run's virtual-experiment folders, one per chain in order, when a replicate
    reads them; else none."""
    replicates = PLAN.ablation_datasets(wildcards.variant)
    return next((folders for folders in replicates if folders), [])


# Variants with the settings and tolerance of one listed before them (e.g.
# sensor_bead_off = point_readout): their outputs are that variant's, copied.
ABLATION_TWINS = PLAN.ablation_twins


def twin_outputs(wildcards):
    twin = ABLATION_TWINS[wildcards.variant]
    return {
        "fits": f"{OUT}/ablation/{twin}_fits.csv",
        "ssw_fits": f"{OUT}/ablation/{twin}_ssw_fits.csv",
    }


def ablation_tolerance(wildcards):
    return PLAN.ablation_tolerance(wildcards.variant)


def ablation_names(which):
    """Variants of tables/ablation_exponent<which>.csv: "" the default run's, "_all" all."""
    return PLAN.ablation_names(full=which == "_all")


def ablation_fit_files(which):
    return [f"{OUT}/ablation/{name}_fits.csv" for name in ablation_names(which)]
