# Input functions and settings of the ablation rules (ablation.smk), from the plan.

from chain.studies.ablation_table import overrides_text


wildcard_constraints:
    variant="|".join(PLAN.ablation) or "no-variant",


def ablation_settings(wildcards):
    """Per replicate, the VirtualExperiment fields of every chain of one variant."""
    return PLAN.ablation_settings(wildcards.variant)


def ablation_tolerance(wildcards):
    return PLAN.ablation_tolerance(wildcards.variant)


def ablation_names(which):
    """Variants of tables/ablation_exponent<which>.csv: "" the default run's, "_all" all."""
    return PLAN.ablation_names(full=which == "_all")


def ablation_fit_files(which):
    return [f"{OUT}/ablation/{name}_fits.csv" for name in ablation_names(which)]
