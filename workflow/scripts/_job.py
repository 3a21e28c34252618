"""First import of every script: the job takes its result from the store if one is
stored, else runs its script here and stores what it computed; then the process exits
with the job's status (chain.pipeline.run.reuse.run_job). Not a code input of the rules
(chain.pipeline.plan.code.TRANSPORT): it says how a job runs, not what it computes.

The process skips the final garbage collections when it exits
(chain.pipeline.run.run_end.freeze_at_exit: 0.4-0.5 s less for a job's libraries).
"""

import __main__
from chain.pipeline.run.job_script import run_script
from chain.pipeline.run.reuse import Job, run_job
from chain.pipeline.run.run_end import freeze_at_exit

# Run again by run_script, the script finds this module imported: the job runs once.
if hasattr(__main__, "snakemake"):
    freeze_at_exit()
    sm, script = __main__.snakemake, __main__.__real_file__
    job = Job.of(sm.rule, sm.wildcards, sm.params, sm.input, sm.output, sm.log)
    folder = f"results/{sm.config['run_name']}"
    reuse = sm.config.get("reuse", True)
    raise SystemExit(run_job(job, reuse, folder, lambda: run_script(script)))
