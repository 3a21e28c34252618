"""chain.pipeline.run.snakemake_patches: Snakemake's scheduler keeps one pending wake-up,
not one more per pass, and a SIGTERM that finds its main thread holding the scheduler's
lock stops the run instead of hanging it; both apply to the locked Snakemake, and a
run on another release says so. No clock: a pending timer here would fire in an hour,
the signal is sent while the lock is held, and the tests wait for what they check."""

from __future__ import annotations

import inspect
import os
import re
import signal
import threading
from pathlib import Path

import pytest
from snakemake.scheduling.job_scheduler import JobScheduler

from chain.pipeline.run.snakemake_patches import (
    SIGTERM_METHOD,
    WAKEUP_METHOD,
    WRITTEN_FOR,
    coalesce_wakeups,
    patch_snakemake,
    stop_gracefully_off_the_main_thread,
)

ROOT = Path(__file__).resolve().parents[1]


class FakeWakeupScheduler:
    """What the patch relies on in Snakemake's JobScheduler: a semaphore that wakes the
    loop, and the method that starts a timer releasing it."""

    def __init__(self):
        self._open_jobs = threading.Semaphore(0)
        self.started = []

    def _schedule_reevalutation(self, delay):
        timer = threading.Timer(delay, self._open_jobs.release)
        self.started.append(timer)
        timer.start()


def _ours(scheduler) -> list[threading.Timer]:
    return [t for t in threading.enumerate() if t is getattr(scheduler, "_pending_wakeup", 0)]


def test_many_passes_leave_one_pending_wakeup_that_is_a_daemon():
    """Fifty passes that each ask for a wake-up in an hour start one timer, a daemon
    (the process does not wait for it), and none of Snakemake's own."""

    class Scheduler(FakeWakeupScheduler):
        pass

    assert coalesce_wakeups(Scheduler)
    scheduler = Scheduler()
    for _ in range(50):
        getattr(scheduler, WAKEUP_METHOD)(3600.0)
    try:
        pending = _ours(scheduler)
        assert len(pending) == 1 and pending[0].daemon
        assert scheduler.started == []
    finally:
        scheduler._pending_wakeup.cancel()


def test_a_wakeup_that_fired_lets_the_pass_it_woke_start_the_next():
    """The timer releases the loop's semaphore once, and is no longer pending by then:
    the pass it wakes starts a new one (a scheduler whose jobs wait is woken again)."""

    class Scheduler(FakeWakeupScheduler):
        pass

    coalesce_wakeups(Scheduler)
    scheduler = Scheduler()
    getattr(scheduler, WAKEUP_METHOD)(0.0)
    assert scheduler._open_jobs.acquire(timeout=600)  # the wake-up came
    assert scheduler._pending_wakeup is None
    getattr(scheduler, WAKEUP_METHOD)(3600.0)
    try:
        assert len(_ours(scheduler)) == 1
        assert not scheduler._open_jobs.acquire(blocking=False)  # released once only
    finally:
        scheduler._pending_wakeup.cancel()


def test_a_scheduler_without_the_wakeup_method_is_left_alone():
    class Other:
        pass

    assert not coalesce_wakeups(Other)
    assert not hasattr(Other, WAKEUP_METHOD)


class FakeSigtermScheduler:
    """What the patch relies on in Snakemake's JobScheduler: a non-reentrant lock that
    the main thread holds while it selects jobs, and a SIGTERM handler that takes it to
    note the stop and then wakes the scheduling loop."""

    def __init__(self):
        self._lock = threading.Lock()
        self._open_jobs = threading.Semaphore(0)
        self._user_kill = None

    def exit_gracefully(self, *args):
        with self._lock:
            self._user_kill = "graceful"
        self._open_jobs.release()


@pytest.fixture
def sigterm_to(request):
    """Install ``scheduler.exit_gracefully`` as this process's SIGTERM handler, as
    Snakemake's scheduler does when it starts; restore the previous one afterwards."""
    previous = signal.getsignal(signal.SIGTERM)
    request.addfinalizer(lambda: signal.signal(signal.SIGTERM, previous))

    def install(scheduler):
        signal.signal(signal.SIGTERM, scheduler.exit_gracefully)

    return install


def test_sigterm_while_the_main_thread_selects_jobs_stops_the_run(sigterm_to):
    """The signal arrives while the main thread holds the lock (the ILP solve): the
    handler returns at once, and once the pass releases the lock the stop is noted
    and the loop is woken, as Snakemake's handler means it to be."""

    class Scheduler(FakeSigtermScheduler):
        pass

    assert stop_gracefully_off_the_main_thread(Scheduler)
    scheduler = Scheduler()
    sigterm_to(scheduler)
    with scheduler._lock:  # the main thread selecting jobs
        os.kill(os.getpid(), signal.SIGTERM)  # the handler runs here, in this thread
        assert scheduler._user_kill is None  # not noted yet: the lock is held
    assert scheduler._open_jobs.acquire(timeout=600)  # the loop is woken
    assert scheduler._user_kill == "graceful"


def test_sigterm_at_any_other_time_stops_the_run_as_before(sigterm_to):
    class Scheduler(FakeSigtermScheduler):
        pass

    stop_gracefully_off_the_main_thread(Scheduler)
    scheduler = Scheduler()
    sigterm_to(scheduler)
    os.kill(os.getpid(), signal.SIGTERM)
    assert scheduler._open_jobs.acquire(timeout=600)
    assert scheduler._user_kill == "graceful"


def test_patching_twice_wraps_once():
    class Scheduler(FakeSigtermScheduler):
        pass

    assert stop_gracefully_off_the_main_thread(Scheduler)
    patched = getattr(Scheduler, SIGTERM_METHOD)
    assert stop_gracefully_off_the_main_thread(Scheduler)
    assert getattr(Scheduler, SIGTERM_METHOD) is patched


def test_a_scheduler_without_the_sigterm_handler_is_left_alone():
    class Other:
        pass

    assert not stop_gracefully_off_the_main_thread(Other)
    assert not hasattr(Other, SIGTERM_METHOD)


# ---- against the locked Snakemake: fails when a patch no longer applies --------------


def _snakemakes_own(method: str):
    handler = getattr(JobScheduler, method)
    return getattr(handler, "__wrapped__", handler)  # a Snakefile read here patched it


def test_the_locks_pin_the_snakemake_the_patches_were_written_for():
    """Every lock installs WRITTEN_FOR, and so does this environment: a new pin must
    come with a look at the patches (then this and the tests below say what changed)."""
    import snakemake

    for lock in sorted((ROOT / "requirements").glob("py3*.lock")):
        assert re.search(rf"^snakemake=={re.escape(WRITTEN_FOR)} ", lock.read_text(), re.M), lock
    assert snakemake.__version__ == WRITTEN_FOR


def test_snakemakes_wakeup_is_a_timer_that_releases_the_loop():
    """What coalesce_wakeups replaces: a method that starts a threading.Timer releasing
    ``_open_jobs``, called from the scheduling loop at every pass with ready jobs."""
    own = inspect.getsource(_snakemakes_own(WAKEUP_METHOD))
    assert "threading.Timer" in own and "self._open_jobs.release()" in own
    assert f"self.{WAKEUP_METHOD}(" in inspect.getsource(JobScheduler)


def test_snakemakes_sigterm_handler_takes_the_lock_its_main_thread_holds():
    """What stop_gracefully_off_the_main_thread works around: the handler takes
    ``self._lock``, which the job selection holds, and is SIGTERM's handler."""
    assert "with self._lock:" in inspect.getsource(_snakemakes_own(SIGTERM_METHOD))
    assert "with self._lock:" in inspect.getsource(JobScheduler.job_selector)
    assert f"signal.SIGTERM, self.{SIGTERM_METHOD}" in inspect.getsource(JobScheduler)


def test_both_patches_apply_to_the_locked_snakemake_without_a_word():
    class Scheduler(JobScheduler):
        pass

    assert patch_snakemake(Scheduler, WRITTEN_FOR) == []
    assert "snakemake_patches" in getattr(Scheduler, WAKEUP_METHOD).__code__.co_filename
    assert getattr(Scheduler, SIGTERM_METHOD)._off_the_main_thread


def test_another_release_is_left_as_it_is_and_said_so_in_one_line():
    class Other(JobScheduler):
        pass

    own = (getattr(Other, WAKEUP_METHOD), getattr(Other, SIGTERM_METHOD))
    lines = patch_snakemake(Other, "10.0.0")
    assert (getattr(Other, WAKEUP_METHOD), getattr(Other, SIGTERM_METHOD)) == own
    assert len(lines) == 1 and lines[0].startswith("hertzchain: Snakemake 10.0.0: the ")
    assert "stay off" in lines[0] and "wake-up timers multiply" in lines[0]
    assert "SIGTERM" in lines[0] and "docs/upstream/README.md" in lines[0]
    assert (ROOT / "docs" / "upstream" / "README.md").is_file()


#: The public names of Snakemake's workflow object that the Snakefile and common.smk
#: read while Snakemake reads them (the workflow, and rules.<name> of a rule).
WORKFLOW_NAMES = (
    "dryrun", "touch", "is_main_process", "current_basedir", "overwrite_configfiles",
    "output_settings",
)  # fmt: skip

#: A workflow that prints what common.smk reads, while Snakemake reads the Snakefile.
PROBE = """\
import json, sys

rule a:
    input:
        named=lambda w: "in.txt",
    output:
        out="out.txt",
    params:
        p=lambda w: 1,
    script:
        "s.py"

proxy = rules.a
print("PROBE " + json.dumps({
    "dryrun": workflow.dryrun,
    "touch": workflow.touch,
    "is_main_process": workflow.is_main_process,
    "current_basedir": str(workflow.current_basedir),
    "overwrite_configfiles": [str(p) for p in workflow.overwrite_configfiles],
    "output_dryrun": workflow.output_settings.dryrun,
    "input": sorted(proxy.input.keys()),
    "params": sorted(proxy.params.keys()),
    "output": [str(proxy.output["out"]), [str(p) for p in proxy.output]],
    "script": proxy.rule.script,
}), file=sys.stderr)
"""


@pytest.mark.parametrize("dry", [False, True], ids=["run", "dry-run"])
def test_the_workflow_names_common_reads_are_public_on_the_locked_snakemake(tmp_path, dry):
    """The names the workflow reads of Snakemake while it reads the Snakefile are public
    attributes of the locked release (no ``_``), and say what common.smk takes them for:
    a dry run is told by its output settings there (``workflow.dryrun`` is set only
    once the Snakefile is read), rules.<name> gives a rule's named inputs, params and
    outputs and its script."""
    import json
    import subprocess
    import sys

    import snakemake.api  # noqa: F401 (snakemake.workflow imports itself through it)
    from snakemake.rules import Rule, RuleProxy
    from snakemake.settings.types import OutputSettings
    from snakemake.workflow import Workflow

    assert all(hasattr(Workflow, name) for name in WORKFLOW_NAMES)
    assert "output_settings" in Workflow.__dataclass_fields__
    assert "dryrun" in OutputSettings.__dataclass_fields__
    assert {"input", "output", "params"} <= set(vars(RuleProxy))
    assert "self.rule = rule" in inspect.getsource(RuleProxy.__init__)
    assert "self.script" in inspect.getsource(Rule.__init__)

    (tmp_path / "Snakefile").write_text(PROBE)
    config = tmp_path / "extra.yaml"
    config.write_text("x: 1\n")
    args = ["--cores", "1", "--configfile", str(config), *(["-n"] if dry else [])]
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", *args],
        cwd=tmp_path, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL,
    )  # fmt: skip
    (line,) = [line for line in result.stderr.splitlines() if line.startswith("PROBE ")]
    seen = json.loads(line.removeprefix("PROBE "))
    assert seen["output_dryrun"] is dry
    assert seen["dryrun"] is False and seen["touch"] is False  # not set yet while parsing
    assert seen["is_main_process"] is True
    assert Path(seen["current_basedir"]) == tmp_path
    assert [Path(p).name for p in seen["overwrite_configfiles"]] == ["extra.yaml"]
    assert seen["input"] == ["named"] and seen["params"] == ["p"]
    assert seen["output"] == ["out.txt", ["out.txt"]]
    assert seen["script"] == "s.py"
