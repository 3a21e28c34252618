"""How a series is named wherever a person reads it: summary.md, the article, the
figures' legends. One function, :func:`series_name`; ``summary.json`` keeps the names
it gave (``series_names``), and the text reads them back with :func:`named`.

A series is a table's (``source``, ``model``): ``simulation`` and a model name, or
``experiment`` and a dataset name. The experiment's rows carry the run's experiment
label, which says whether they are data ("measured (lab2011)") or a model of the
apparatus (:data:`chain.labels.VIRTUAL_LABEL`).
"""

from __future__ import annotations

from collections.abc import Mapping

from chain.labels import VIRTUAL_LABEL, VIRTUAL_SERIES


def is_virtual(experiment_label: str) -> bool:
    """Whether the experiment series is the virtual experiment (a model of the
    apparatus, not data), read off its label."""
    return str(experiment_label).startswith(VIRTUAL_LABEL)


def _label_names(experiment_label: str, model: str) -> bool:
    """Whether the label names this series alone ("virtual experiment (model)" the
    virtual one, "measured (lab2011)" or "...: lab2011" one dataset), so that adding
    the model would repeat it; a label of several datasets names none alone."""
    label, model = str(experiment_label), str(model)
    if label == VIRTUAL_LABEL:
        return model == VIRTUAL_SERIES
    return label.endswith((f"({model})", f": {model}"))


def series_name(source: str, model: str, experiment_label: str = "experiment", n=None) -> str:
    """The name of a series: "simulation, elastic", "virtual experiment (model)",
    "measured (a, b), a"; with ``n``, the chain after it: ", N = 25" or ", all N
    pooled".

    Parameters
    ----------
    source : str
        ``simulation`` or ``experiment``.
    model : str
        The model or dataset name (the tables' ``model`` column).
    experiment_label : str
        The run's name of its experiment rows (``summary.json`` ``experiment_label``).
    n : int, str or None
        Number of beads, ``"pooled"``, or None for the series alone.
    """
    if source == "experiment":
        name = (
            str(experiment_label)
            if _label_names(experiment_label, model)
            else f"{experiment_label}, {model}"
        )
    else:
        name = f"{source}, {model}"
    return _with_chain(name, n)


def _with_chain(name: str, n) -> str:
    """``name``, then ", N = 25" or ", all N pooled" (nothing for ``n`` None)."""
    if n is None:
        return name
    return f"{name}, " + ("all N pooled" if n == "pooled" else f"N = {n}")


def series_names(series, experiment_label: str) -> dict:
    """``{source: {model: name}}`` of ``series`` (pairs of source, model): the
    ``series_names`` of ``summary.json``."""
    names: dict = {}
    for source, model in series:
        names.setdefault(str(source), {})[str(model)] = series_name(source, model, experiment_label)
    return names


def named(summary: Mapping, source: str, model: str, n=None) -> str:
    """The name ``summary.json`` gave a series (``series_names``), with the chain as
    :func:`series_name` writes it; a summary without the name (an older run, a series
    the summary does not list) gets :func:`series_name`'s."""
    name = (summary.get("series_names") or {}).get(str(source), {}).get(str(model))
    if name is None:
        return series_name(source, model, summary.get("experiment_label", "experiment"), n)
    return _with_chain(name, n)
