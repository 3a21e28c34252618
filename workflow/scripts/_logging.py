"""A job's start and end (imported by the scripts): the inputs another job stored
checked against their digests, logging and stderr sent to the rule's log file, and the
job's folder of the store sealed at the end (chain.pipeline.run.entries)."""

import logging
import signal
import sys

from chain.pipeline.run.entries import DamagedEntry, seal, verify_inputs
from chain.pipeline.run.run_end import freeze_at_exit

#: Exit status of a job stopped by a signal: the shell's convention, 128 + signal.
SIGNAL_BASE = 128
#: Input file -> SHA-256 of the stored inputs this job checked (listed as it is sealed).
CHECKED = {}


def start(snakemake, check_inputs: bool = True) -> logging.Logger:
    """Check the job's stored inputs (a damaged one is named on the console, its entry
    discarded, and the job stops), then redirect stderr and the root logger to
    ``snakemake.log[0]``; return a logger. Also turn SIGTERM into ``SystemExit`` (a job
    stopped mid-write leaves no temporary file: the atomic writers delete theirs on the
    way out), and skip the garbage collections of the job's exit (0.25-0.5 s:
    chain.pipeline.run.run_end)."""
    signal.signal(signal.SIGTERM, stop_once)
    freeze_at_exit()
    try:
        CHECKED.update(verify_inputs(snakemake.input) if check_inputs else {})
    except DamagedEntry as error:
        print(f"hertzchain: rule {snakemake.rule}: {error}", file=sys.stderr)
        raise SystemExit(1) from None
    stream = open(snakemake.log[0], "w", buffering=1)  # lives as long as the job
    sys.stderr = stream
    logging.basicConfig(
        stream=stream,
        level=logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        force=True,
    )
    logging.captureWarnings(True)
    # fontTools reports every font it subsets for a PDF at INFO (a hundred lines of glyph
    # lists per figure): not about the run, and formatting them costs time.
    logging.getLogger("fontTools").setLevel(logging.WARNING)
    # numba's parallel loops on the job's threads, not on every core of the node (numba's
    # default); scripts that use no numba do not import it here. Results do not depend on it.
    numba, threads = sys.modules.get("numba"), getattr(snakemake, "threads", None)
    if numba is not None and threads:
        numba.set_num_threads(max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS)))
    logger = logging.getLogger(f"rule {snakemake.rule}")
    logger.info("inputs: %s", list(snakemake.input))
    logger.info("outputs: %s", list(snakemake.output))
    return logger


def done(snakemake) -> None:
    """Seal the job's folder of the store: its SHA256SUMS (output ``sums``) lists its
    outputs and the stored inputs it read, and the outputs become read-only."""
    sums = snakemake.output.sums
    seal([path for path in snakemake.output if path != sums], sums, CHECKED)
    logging.getLogger(f"rule {snakemake.rule}").info("done: %s sealed", sums)


def stop_once(signum: int, frame) -> None:
    """Signal handler: end the job as SIGINT (KeyboardInterrupt) or SIGTERM (SystemExit
    with status 128 + signal) do, once, then ignore both: a signal that arrives twice (to
    a process group, and passed on by a parent) cannot cut the writers' clean-up short."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(SIGNAL_BASE + signum)
