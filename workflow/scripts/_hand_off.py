"""First import of every script: the job takes its result from the store if one is
stored, else computes it (in the workflow's job server if one is up and shares the
job's environment, else here) and stores it; then the process exits with the job's
status (chain.pipeline.reuse.run_job, chain.pipeline.job_server.run).

The process skips the final garbage collections when it exits
(chain.pipeline.run_end.freeze_at_exit: 0.4-0.5 s less for a job's libraries). In the
server's child that runs a job, or where no Snakemake job runs, this does nothing.
"""

import __main__
from chain.pipeline import job_server
from chain.pipeline.reuse import Job, run_job
from chain.pipeline.run_end import freeze_at_exit

if hasattr(__main__, "snakemake") and not job_server.in_server():
    freeze_at_exit()
    sm, script = __main__.snakemake, __main__.__real_file__
    job = Job.of(sm.rule, sm.wildcards, sm.params, sm.input, sm.output, sm.log)
    folder = f"results/{sm.config['run_name']}"
    reuse = sm.config.get("reuse", True)
    raise SystemExit(run_job(job, reuse, folder, lambda: job_server.run(script)))
