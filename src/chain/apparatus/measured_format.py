"""Vocabulary of the measured-trace format (``data/README.md``): names, tolerances and
the error type shared by the metadata reader, the shot-file reader and the dataset check."""

from __future__ import annotations

from collections.abc import Sequence

# How evenly a shot file's time must step (against sampling_interval_s): the trace
# table's own rule, re-exported for the readers here.
from chain.sampling import TIME_STEP_TOLERANCE as TIME_STEP_TOLERANCE

#: Name of the metadata file of a dataset.
METADATA_FILE = "metadata.yaml"

#: Value of the optional ``format`` key (bumped if the format ever changes).
FORMAT_NAME = "hertzchain-measured-traces/1"

#: Name of the time column of a shot file (seconds).
TIME_COLUMN = "t_s"

#: Standard gravity used to turn a drop height into an impact speed, m/s^2.
STANDARD_GRAVITY = 9.80665


#: At most this many problems are listed for one dataset (the rest are counted).
MAX_PROBLEMS = 20


class MeasuredDataError(ValueError):
    """A measured dataset does not follow the format.

    The message holds one line per problem, each naming the file and, where one
    applies, the line (CSV header = line 1; YAML line of the offending key).
    """


def voltage_column(bead: int) -> str:
    """Header of the voltage column of the sensor in bead ``bead`` (1..N), V."""
    return f"bead{int(bead)}_V"


def problem_list(problems: Sequence[str], limit: int = MAX_PROBLEMS) -> str:
    """``problems`` one per line, at most ``limit`` of them, then how many were left out.

    Parameters
    ----------
    problems : sequence of str
        One message per problem.
    limit : int
        Largest number of problems listed.
    """
    shown = list(problems[:limit])
    if len(problems) > limit:
        shown.append(f"... and more problems (the first {limit} are listed)")
    return "\n".join(shown)
