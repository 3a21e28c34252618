"""Provenance: what made a run (commit, config, versions) and the headline check."""
