"""Reading helpers shared by the scripts (no analysis here)."""

import pandas as pd


def selection(snakemake):
    """The shot-selection table (chain.analysis.selection.select_shots), or None (keep all)."""
    paths = list(snakemake.input.get("selection", []))
    if not paths:
        return None
    return pd.concat([pd.read_csv(path) for path in paths], ignore_index=True)
