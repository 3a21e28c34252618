"""Steps and jobs: what the workflow's rules are made of, written down by the plan.

A :class:`Step` is one rule: its outputs (path patterns with ``{wildcard}`` fields),
the wildcard values of every job the plan may ask of it, and for each job its named
inputs and its parameters. ``workflow/rules/steps.smk`` defines one Snakemake rule per
step, and the plan knows every job of the run before Snakemake builds its DAG: the
result store can then decide which jobs take a stored result before any job starts
(:mod:`chain.pipeline.run.reuse`).

A :class:`Job` is one job of a step, with every path filled in: inputs and outputs
relative to the working directory, as the rules name them.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

#: A job's cores or priority: a number, or a function of its wildcards.
Needs = Callable[[Mapping[str, str]], int] | int


@dataclass(frozen=True)
class Job:
    """One job: a step's rule with its wildcards, and every path filled in.

    Attributes
    ----------
    rule : str
        The step's (rule's) name.
    wildcards : dict of str to str
        Wildcard values (empty for a step of one job).
    inputs : dict of str to (str or list of str)
        Named inputs: a path, or a list of paths; ``lib`` holds the code the job runs.
    outputs : dict of str to str
        Named outputs (paths, a folder for a step's ``folders``).
    params : dict
        The job's parameters (plain values).
    log : str
        The job's log file.
    """

    rule: str
    wildcards: dict
    inputs: dict
    outputs: dict
    params: dict
    log: str

    def __str__(self) -> str:
        values = ", ".join(f"{k}={v}" for k, v in self.wildcards.items())
        return f"{self.rule} ({values})" if values else self.rule

    @property
    def input_paths(self) -> list[str]:
        """Every input path, in order."""
        return [path for paths in self.inputs.values() for path in as_list(paths)]


@dataclass(frozen=True)
class Step:
    """One rule of the workflow, as the plan defines it.

    Attributes
    ----------
    name : str
        Rule name (and, unless ``script`` says otherwise, its script's:
        ``workflow/scripts/<name>.py``).
    outputs : dict of str to str
        Output name -> path pattern (``{wildcard}`` fields). Names that are not Python
        identifiers (``"0"``) are positional outputs.
    jobs : sequence of dict
        The wildcard values of each job the plan may ask for (one ``{}`` for a step
        of one job; none for a step the run does not make).
    inputs : callable
        Wildcards -> named inputs (a path or a list of paths each), code excluded.
    params : callable
        Wildcards -> parameters.
    log : str
        Log file pattern.
    script : str
        Script name, ``workflow/scripts/<script>.py``; "" for a step run by ``shell``.
    shell : str
        The shell command of a step without a script.
    folders : tuple of str
        Outputs that are folders.
    report : dict
        Output name -> (caption file name in ``workflow/report/``, report category).
    threads, priority : int or callable
        Cores and Snakemake priority of a job (callables take the wildcards).
    resources : dict
        Resource name -> value, or callable (wildcards, threads).
    """

    name: str
    outputs: dict
    jobs: Sequence[dict] = ({},)
    inputs: Callable[[Mapping], dict] = lambda wildcards: {}
    params: Callable[[Mapping], dict] = lambda wildcards: {}
    log: str = ""
    script: str | None = None
    shell: str = ""
    folders: tuple[str, ...] = ()
    report: dict = field(default_factory=dict)
    threads: Needs = 1
    priority: Needs = 0
    resources: dict = field(default_factory=dict)

    @property
    def script_name(self) -> str:
        """The script the step runs ("" for a shell step)."""
        return "" if self.shell else (self.script or self.name)

    @cached_property
    def wildcard_names(self) -> tuple[str, ...]:
        """The wildcards of the output patterns, in order of appearance."""
        found = re.findall(r"{(\w+)}", " ".join(self.outputs.values()))
        return tuple(dict.fromkeys(found))

    def constraints(self) -> dict[str, str]:
        """Wildcard -> regular expression matching exactly the values of :attr:`jobs`
        (one that matches nothing when there is no job), so that Snakemake's rule
        for this step makes just the plan's jobs."""
        values = {name: dict.fromkeys(str(job[name]) for job in self.jobs)
                  for name in self.wildcard_names}  # fmt: skip
        return {name: "|".join(map(re.escape, v)) or "(?!)" for name, v in values.items()}

    def job(self, wildcards: Mapping, code: Callable[[str], list[str]]) -> Job:
        """The job of these wildcard values.

        Parameters
        ----------
        wildcards : mapping
            Wildcard values (strings or numbers).
        code : callable
            Script name -> the source files it runs (the job's ``lib`` input).
        """
        values = {name: str(wildcards[name]) for name in self.wildcard_names}
        inputs = {
            name: paths if isinstance(paths, str) else list(paths)
            for name, paths in self.inputs(values).items()
        }
        if self.script_name:
            inputs["lib"] = code(self.script_name)
        return Job(
            rule=self.name,
            wildcards=values,
            inputs=inputs,
            outputs={name: fill(path, values) for name, path in self.outputs.items()},
            params=self.params(values),
            log=fill(self.log, values),
        )


def as_list(paths: str | list[str]) -> list[str]:
    """A named input as a list of paths."""
    return [paths] if isinstance(paths, str) else paths


def fill(pattern: str, wildcards: Mapping[str, str]) -> str:
    """``pattern`` with each ``{name}`` replaced by its wildcard value."""
    return re.sub(r"{(\w+)}", lambda m: str(wildcards[m.group(1)]), pattern)


class Jobs:
    """Every job of a run's steps, and which of them a set of targets needs.

    Parameters
    ----------
    steps : iterable of Step
    code : callable
        Script name -> the source files it runs.
    """

    def __init__(self, steps: Iterable[Step], code: Callable[[str], list[str]]):
        self.steps = {step.name: step for step in steps}
        self.all = [step.job(w, code) for step in self.steps.values() for w in step.jobs]
        self._by_output = {path: job for job in self.all for path in job.outputs.values()}
        self._by_rule = {(job.rule, tuple(job.wildcards.items())): job for job in self.all}

    def of(self, rule: str, wildcards: Mapping) -> Job:
        """The job of ``rule`` with these wildcard values."""
        step = self.steps[rule]
        key = tuple((name, str(wildcards[name])) for name in step.wildcard_names)
        return self._by_rule[(rule, key)]

    def producer(self, path: str) -> Job | None:
        """The job that writes ``path``, or None (a file no job writes: a source)."""
        return self._by_output.get(path)

    def needed(self, targets: Iterable[str]) -> list[Job]:
        """The jobs that the files ``targets`` need, each after the jobs it reads
        from (a topological order)."""
        order: list[Job] = []
        done: set[int] = set()
        stack = [(job, False) for t in targets if (job := self.producer(t))]
        while stack:
            job, expanded = stack.pop()
            if id(job) in done:
                continue
            if expanded:
                done.add(id(job))
                order.append(job)
                continue
            stack.append((job, True))
            stack += [(up, False) for p in job.input_paths if (up := self.producer(p))]
        return order


class Part:
    """A part of the run plan: its facts, its steps and its files of the default run;
    none of each unless the part says otherwise.

    Parameters
    ----------
    plan : RunPlan
        The run's plan, whose shared facts the part reads.
    """

    def __init__(self, plan):
        self.plan = plan

    def steps(self) -> list[Step]:
        """The part's steps (the rules of its jobs)."""
        return []

    def targets(self) -> list[str]:
        """The part's files of the default run (its jobs' files the run asks for)."""
        return []

    def notes(self) -> list[str]:
        """What the console says of the part before any job."""
        return []
