# One rule per step of the plan (chain.pipeline.plan.steps.Step): its named inputs and
# parameters from the plan's job of the wildcards, its outputs, log and resources as the
# step says, each wildcard constrained to the plan's values. What a rule reads and
# writes, and why: the step's part of the plan (chain.pipeline.plan.<part>).


def caption(name):
    """A report caption: workflow/report/<name>, or the generic figure caption."""
    own = Path(workflow.basedir, "workflow", "report", name)
    return f"../report/{name if own.exists() else 'figure.rst'}"


def step_outputs(step):
    """(positional, named) outputs of a step, flagged for the report or as folders."""
    flagged = {}
    for name, path in step.outputs.items():
        if name in step.folders:
            path = directory(path)
        if name in step.report:
            file, category = step.report[name]
            path = report(path, caption=caption(file), category=category)
        flagged[name] = path
    positional = [p for n, p in flagged.items() if not n.isidentifier()]
    return positional, {n: p for n, p in flagged.items() if n.isidentifier()}


def step_params(step):
    """Parameter name -> function of the wildcards, for each parameter of the step; and
    the script's name, which names the script file when the job runs (Snakemake reads
    the script directive again then, long after this loop has moved on)."""
    names = PLAN.jobs.of(step.name, step.jobs[0]).params
    params = {
        name: lambda wildcards, n=name, s=step.name: PLAN.jobs.of(s, wildcards).params[n]
        for name in names
    }
    return {**params, "script": step.script_name}


def step_benchmark(step):
    """Snakemake's record of the job's time and memory, beside its log's place."""
    log = os.path.relpath(step.log, f"{OUT}/logs")
    return f"{OUT}/benchmarks/{os.path.splitext(log)[0]}.tsv"




for step in [s for s in PLAN.steps if s.script_name]:
    positional, named = step_outputs(step)

    rule:
        name:
            step.name
        input:
            unpack(job_inputs(step.name)),
        output:
            *positional,
            **named,
        log:
            step.log,
        benchmark:
            step_benchmark(step)
        wildcard_constraints:
            **step.constraints(),
        priority: step.priority
        threads: step.threads
        resources:
            **step.resources,
        conda:
            ENV
        params:
            **step_params(step),
        script:
            "../scripts/{params.script}.py"


for step in [s for s in PLAN.steps if not s.script_name]:
    positional, named = step_outputs(step)

    rule:
        name:
            step.name
        input:
            unpack(job_inputs(step.name)),
        output:
            *positional,
            **named,
        log:
            step.log,
        wildcard_constraints:
            **step.constraints(),
        conda:
            ENV
        shell:
            step.shell
