"""Config checks: the schema's relations between keys, every key's usable bounds, the
config files' YAML, and what the ablation and virtual-experiment sections mean."""

from chain.errors import ConfigError, key_label


def fail(path, message: str):
    """Raise :class:`ConfigError` naming the key ``path`` (keys and list indices)."""
    raise ConfigError(f"config key {key_label(path)!r}: {message}")
