"""The library's error types and the checks of input values that raise them.

Every public function checks its inputs with these and raises
:class:`ParameterError` with a message that names the parameter, never a numpy
traceback from deep inside a kernel. The pipeline raises :class:`ConfigError` for a
bad config, its message naming the key (:func:`key_label`).
"""

from __future__ import annotations

import itertools
import math

import numpy as np


class ParameterError(ValueError):
    """An input value is outside its physical range; the message names the parameter."""


class ConfigError(ValueError):
    """A configuration value is inconsistent; the message names the key."""


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as a float > 0, or raise :class:`ParameterError` naming ``name``."""
    return _finite_number(name, value, zero_allowed=False)


def require_nonnegative(name: str, value: float) -> float:
    """Return ``value`` as a float >= 0, or raise :class:`ParameterError` naming ``name``."""
    return _finite_number(name, value, zero_allowed=True)


def _finite_number(name: str, value, zero_allowed: bool) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number) or number < 0.0 or (number == 0.0 and not zero_allowed):
        kind = "non-negative" if zero_allowed else "positive"
        raise ParameterError(f"{name} must be a {kind} finite number, got {value!r}")
    return number


def require_int(name: str, value, minimum: int) -> int:
    """Return ``value`` as an int >= ``minimum``, or raise :class:`ParameterError`
    naming ``name`` (a bool or a float such as 3.0 is not an integer here)."""
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < minimum:
        raise ParameterError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def bead_number_problem(beads, n_beads: int, *, increasing: bool = True) -> str | None:
    """What is wrong with a list of bead numbers of a chain of ``n_beads``, or None.

    The one rule for sensor beads wherever they come from (config, dataset metadata,
    trace columns, the chain model): integers in 1..N, distinct, and, where S1 must
    come first, strictly increasing. Callers raise their own error type with the
    message, naming their key, file or column.

    Parameters
    ----------
    beads : sequence of int
        Bead numbers, 1..N as in the paper.
    n_beads : int
        Number of beads N of the chain.
    increasing : bool
        Require strictly increasing numbers (S1 first); else only distinct ones.
    """
    try:
        numbers = list(beads)
    except TypeError:
        return f"must be a list of bead numbers, got {beads!r}"
    if not numbers:
        return "must name at least one bead"
    wrong = [b for b in numbers if isinstance(b, bool) or not isinstance(b, int | np.integer)]
    if wrong:
        return f"bead numbers must be integers, got {wrong}"
    outside = [int(b) for b in numbers if not 1 <= b <= n_beads]
    if outside:
        return f"bead {outside[0]} is outside the chain 1..{n_beads}"
    if increasing and any(a >= b for a, b in itertools.pairwise(numbers)):
        return f"must be strictly increasing (S1 first), got {[int(b) for b in numbers]}"
    if len(set(numbers)) != len(numbers):
        return f"duplicate bead in {[int(b) for b in numbers]}"
    return None


def check_bead_numbers(name: str, beads, n_beads: int, *, increasing: bool = True):
    """``beads`` as a tuple of ints, or :class:`ParameterError` naming ``name``
    (rules: :func:`bead_number_problem`)."""
    problem = bead_number_problem(beads, n_beads, increasing=increasing)
    if problem:
        raise ParameterError(f"{name}: {problem}")
    return tuple(int(b) for b in beads)


def key_label(path) -> str:
    """Dotted name of a key from its path in a YAML mapping, e.g. ``chains[0].N``.

    Parameters
    ----------
    path : iterable of str and int
        Keys (str) and list indices (int) from the top of the mapping.
    """
    name = ""
    for part in path:
        if isinstance(part, int):
            name += f"[{part}]"
        else:
            name += f".{part}" if name else str(part)
    return name or "<top level>"


def nonfinite_paths(value, path: tuple = ()):
    """Yield ``(path, number)`` for every NaN or infinite float inside nested mappings
    and lists (a parsed YAML document), ``path`` as keys and indices from the top.

    JSON schema's ``minimum``/``maximum`` let NaN through (every comparison with NaN is
    false), so a schema-valid document still needs this one general walk.

    Parameters
    ----------
    value : mapping, list or scalar
        The document (or part of it) to walk.
    path : tuple
        Path of ``value`` itself.
    """
    if isinstance(value, dict):
        for key, item in value.items():
            yield from nonfinite_paths(item, (*path, key))
    elif isinstance(value, list | tuple):
        for index, item in enumerate(value):
            yield from nonfinite_paths(item, (*path, index))
    elif isinstance(value, float | np.floating) and not math.isfinite(value):
        yield path, float(value)
