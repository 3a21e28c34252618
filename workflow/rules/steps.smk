# One rule per step of the plan (chain.pipeline.plan.steps.Step): its named inputs and
# parameters from the plan's job of the wildcards, its outputs, log and resources as the
# step says, each wildcard constrained to the plan's values. What a rule reads and
# writes, and why: the step's part of the plan (chain.pipeline.plan.<part>).


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
        conda:
            ENV
        threads: step.threads
        resources:
            **step.resources,
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
