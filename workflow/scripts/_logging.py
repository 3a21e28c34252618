"""Send a script's logging and stderr to the rule's log file (imported by the scripts)."""

import logging
import signal
import sys


def start(snakemake) -> logging.Logger:
    """Redirect stderr and the root logger to ``snakemake.log[0]``; return a logger.

    Also turn SIGTERM into ``SystemExit``, so that a job terminated mid-write (a batch
    system's or a container's stop, ``kill -TERM`` of the process group) leaves no
    temporary file: the atomic writers delete theirs on the way out. SIGINT already
    arrives as ``KeyboardInterrupt``.
    """
    signal.signal(signal.SIGTERM, _terminate)
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
    logger = logging.getLogger(f"rule {snakemake.rule}")
    logger.info("inputs: %s", list(snakemake.input))
    logger.info("outputs: %s", list(snakemake.output))
    return logger


def _terminate(signum, frame):
    raise SystemExit(128 + signum)
