"""The studies: simulate and analyse in-process, one table each, beside the paper run.

Ablation of the virtual experiment (:mod:`.ablation`, :mod:`.ablation_table`), C against
our choices (:mod:`.c_sensitivity`), the sweep table (:mod:`.sweep`) and the mechanism
study (its settings, the LAMMPS cross-check, the LAMMPS sweep, what it measures of a
series, its table). They read schema-valid config values (defaults filled in by
validation) and know neither Snakemake nor ``results/``; the pipeline glue calls them.
"""
