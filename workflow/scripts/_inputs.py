"""Reading helpers shared by the scripts (no analysis here)."""

import pandas as pd


def selection(snakemake):
    """The shot-selection table (chain.analysis.selection.select_shots), or None (keep all)."""
    paths = list(snakemake.input.get("selection", []))
    return pd.concat([pd.read_csv(path) for path in paths], ignore_index=True) if paths else None


def dataset_folders(snakemake):
    """Each experiment dataset's folder, in the order of ``params.datasets``: a measured
    one's from its entry, the virtual experiment's from the ``virtual`` input."""
    virtual = iter(snakemake.input.virtual)
    return [dataset["folder"] or next(virtual) for dataset in snakemake.params.datasets]
