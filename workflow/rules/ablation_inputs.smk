# Input functions and settings of the ablation rules (ablation.smk), from the plan.

from chain.studies.ablation_table import overrides_text


wildcard_constraints:
    variant="|".join(PLAN.ablation) or "no-variant",


def ablation_settings(wildcards):
    """Per replicate, the VirtualExperiment fields of every chain of one variant."""
    return PLAN.ablation_settings(wildcards.variant)


def ablation_datasets(wildcards):
    """Per replicate, the run's virtual-experiment datasets it reads instead of
    simulating the same shots again, or [] (RunPlan.ablation_datasets)."""
    return PLAN.ablation_datasets(wildcards.variant)


def ablation_dataset_files(wildcards):
    return sorted(
        {folder for folders in ablation_datasets(wildcards) for folder in folders}
    )


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
