# hertzchain: Santibanez et al., "Experimental evidence of solitary wave interaction
# in Hertzian chains", reproduced. `snakemake --cores 2` rebuilds results/<run_name>/;
# what-if runs: `snakemake --cores 2 --configfile whatif/<name>.yaml`;
# report: `snakemake --report results/<run_name>/report.html`. The rules, one file per
# part of the workflow, are listed with their scripts in docs/rules.md.

from pathlib import Path

from snakemake.utils import min_version, validate

from chain.pipeline.config.files import check_config_files
from chain.pipeline.run.run_end import freeze_at_exit

min_version("9.0")
# Snakemake's ~1500 modules cost 0.3-0.45 s of garbage collection at the exit of every
# command, a dry run's or a failed check's too (chain.pipeline.run.run_end).
freeze_at_exit()
# Snakemake names neither the file nor the line of a YAML mistake, and keeps the last of
# two equal keys: check the config files before they are read (a module's config is
# given as a mapping, and its working directory has no config.yaml of ours).
check_config_files(
    [p for p in ["config.yaml", *workflow.overwrite_configfiles] if Path(p).exists()]
)


configfile: "config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"


# A stored job's folder ends in the key of its recipe (common.smk: stored()).
wildcard_constraints:
    key="[0-9a-f]{32}",
    N=r"\d+",


include: "workflow/rules/simulation.smk"
include: "workflow/rules/experiment.smk"
include: "workflow/rules/analysis.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/ablation.smk"
include: "workflow/rules/c_sensitivity.smk"
include: "workflow/rules/mechanisms.smk"
include: "workflow/rules/sweep.smk"
include: "workflow/rules/report.smk"


rule all:
    default_target: True
    input:
        run_folder_files(),
