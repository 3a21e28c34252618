"""Config checks: the schema's relations between keys, every key's usable bounds, the
config files' YAML, and what the ablation and virtual-experiment sections mean."""
