"""Lazy re-exports for package ``__init__`` files (PEP 562).

``import chain.physics.theory`` (as the Snakefile does when it checks the config)
must not import numba, scipy.signal or pandas through the package's ``__init__``;
each public name is imported from its module on first use instead.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping


def lazy_exports(package: str, modules: Mapping[str, str]) -> tuple[Callable, Callable, list]:
    """``__getattr__``, ``__dir__`` and ``__all__`` of a package that re-exports names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    modules : mapping of str to str
        Module (absolute, ``chain.physics.model``) -> the public names it defines that
        the package exports, separated by spaces.
    """
    exports = {name: module for module, names in modules.items() for name in names.split()}

    def __getattr__(name: str):
        try:
            module = exports[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        return getattr(importlib.import_module(module), name)

    def __dir__() -> list[str]:
        return sorted(exports)

    return __getattr__, __dir__, sorted(exports)
