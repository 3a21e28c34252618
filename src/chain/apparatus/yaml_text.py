"""YAML text as the metadata is read: ``1e-6`` a number, a syntax error with its line,
and the line of every node (for messages that name the line)."""

from __future__ import annotations

import re

import yaml

from chain.apparatus.measured_format import MeasuredDataError


class _Loader(yaml.SafeLoader):
    """SafeLoader that reads ``1e-6`` as a number (YAML 1.2), not as text (YAML 1.1)."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*\.?[0-9_]*|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."),
)


def load_yaml(text: str, where: str):
    """Parse YAML text; a syntax error becomes :class:`MeasuredDataError` with the line.

    Parameters
    ----------
    text : str
        The document.
    where : str
        File name used in messages.
    """
    try:
        return yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        at = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or str(error)
        raise MeasuredDataError(f"{where}{at}: not valid YAML ({problem})") from None


def yaml_lines(text: str) -> dict[tuple, int]:
    """1-based line of every node of a YAML document, keyed by its path (keys, indices)."""
    lines: dict[tuple, int] = {}

    def walk(node, path):
        lines[path] = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                lines[(*path, key.value)] = key.start_mark.line + 1
                walk(value, (*path, key.value))
        elif isinstance(node, yaml.SequenceNode):
            for index, item in enumerate(node.value):
                walk(item, (*path, index))

    try:
        root = yaml.compose(text, Loader=_Loader)
    except yaml.YAMLError:
        return lines
    if root is not None:
        walk(root, ())
    return lines


__all__ = ["load_yaml", "yaml_lines"]
