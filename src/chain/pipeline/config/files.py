"""The pipeline's config files as text: YAML mistakes named by file and line.

Snakemake reports a config file it cannot parse without file or line, and a key given
twice silently keeps the last value. An overlay that is not YAML at all stops Snakemake
before the Snakefile runs; ``python -m chain.pipeline.config.files whatif/x.yaml`` names
file and line.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable
from pathlib import Path

import yaml

from chain.errors import ConfigError


class _StrictLoader(yaml.SafeLoader):
    """SafeLoader that refuses a key given twice in one mapping."""

    def construct_mapping(self, node, deep=False):
        seen: dict = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            line = key_node.start_mark.line + 1
            if key in seen:
                problem = (
                    f"key {key!r} is given twice (lines {seen[key]} and {line}); YAML would "
                    "keep only the last"
                )
                raise yaml.constructor.ConstructorError(None, None, problem, key_node.start_mark)
            seen[key] = line
        return super().construct_mapping(node, deep=deep)


def check_config_file(path: str | os.PathLike) -> None:
    """Parse the config file ``path`` (YAML or JSON, the main one or an overlay); raise
    :class:`ConfigError` naming the file and line of a mistake."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such config file") from None
    except (UnicodeDecodeError, OSError) as error:
        raise ConfigError(f"{path}: cannot be read as UTF-8 text ({error})") from None
    try:
        document = yaml.load(text, Loader=_StrictLoader)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        at = f" line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or str(error)
        raise ConfigError(f"{path}{at}: not valid YAML: {problem}") from None
    if document is not None and not isinstance(document, dict):
        raise ConfigError(
            f"{path}: must be a mapping of config keys, got {type(document).__name__}"
        )


def check_config_files(paths: Iterable[str | os.PathLike]) -> None:
    """:func:`check_config_file` on each of ``paths`` (config files)."""
    for path in paths:
        check_config_file(path)


def main(argv: list[str] | None = None) -> int:
    """``python -m chain.pipeline.config.files FILE...``: name the file and line of each
    YAML mistake in the config files ``argv`` (default the command line's); 1 if any."""
    status = 0
    for path in sys.argv[1:] if argv is None else argv:
        try:
            check_config_file(path)
        except ConfigError as error:
            print(error, file=sys.stderr)
            status = 1
        else:
            print(f"{path}: valid YAML, no repeated keys")
    return status


if __name__ == "__main__":
    raise SystemExit(main())
