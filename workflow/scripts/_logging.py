"""Send a script's logging and stderr to the rule's log file (imported by the scripts)."""

import logging
import sys


def start(snakemake) -> logging.Logger:
    """Redirect stderr and the root logger to ``snakemake.log[0]``; return a logger."""
    stream = open(snakemake.log[0], "w", buffering=1)  # lives as long as the job
    sys.stderr = stream
    logging.basicConfig(
        stream=stream,
        level=logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
        force=True,
    )
    logging.captureWarnings(True)
    logger = logging.getLogger(f"rule {snakemake.rule}")
    logger.info("inputs: %s", list(snakemake.input))
    logger.info("outputs: %s", list(snakemake.output))
    return logger
