# hertzchain: Santibanez et al., "Experimental evidence of solitary wave interaction
# in Hertzian chains", reproduced. `snakemake --cores 2` rebuilds results/<run_name>/;
# what-if runs: `snakemake --cores 2 --configfile whatif/<name>.yaml`;
# report: `snakemake --report results/<run_name>/report.html` (or the `report` rule).

from snakemake.utils import min_version, validate

from chain.pipeline.config.files import check_config_files
from chain.pipeline.run.run_end import freeze_at_exit

min_version("9.0")
# Snakemake's ~1500 modules cost 0.3-0.45 s of garbage collection at the exit of every
# command, a dry run's or a failed check's too (chain.pipeline.run.run_end).
freeze_at_exit()
# Snakemake names neither the file nor the line of a YAML mistake, and keeps the last of
# two equal keys: check the main config before it is read, the overlays (read already)
# again.
check_config_files(["config.yaml", *workflow.overwrite_configfiles])


configfile: "config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"


rule all:
    default_target: True
    input:
        target_inputs("all"),


include: "workflow/rules/targets.smk"
include: "workflow/rules/steps.smk"
