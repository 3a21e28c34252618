"""The library's error type and the checks of input values that raise it.

Every public function checks its inputs with these and raises
:class:`ParameterError` with a message that names the parameter, never a numpy
traceback from deep inside a kernel.
"""

from __future__ import annotations

import math


class ParameterError(ValueError):
    """An input value is outside its physical range; the message names the parameter."""


def require_positive(name: str, value: float) -> float:
    """Return ``value`` as a float, or raise :class:`ParameterError` naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number) or number <= 0.0:
        raise ParameterError(f"{name} must be a positive finite number, got {value!r}")
    return number


def require_nonnegative(name: str, value: float) -> float:
    """Return ``value`` as a float, or raise :class:`ParameterError` naming ``name``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number) or number < 0.0:
        raise ParameterError(f"{name} must be a non-negative finite number, got {value!r}")
    return number
