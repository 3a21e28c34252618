"""Checks on a pipeline configuration that a JSON schema cannot express.

The pipeline validates its config against ``workflow/schemas/config.schema.yaml``
first (types, ranges, defaults; snakemake.utils.validate names the key as
``On instance['chains'][1]['N']``), then calls :func:`check_config` for the relations
between keys (sensor beads inside their chain, the Fig. 3 model among the models...).
Every message of :func:`check_config` starts with the dotted name of the offending
key, e.g. ``config key 'chains[1].sensors': ...``, so that a bad config stops before
any job runs and says where.

The module takes plain dicts; it reads no file and knows nothing of Snakemake.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from chain.materials import MATERIALS


class ConfigError(ValueError):
    """A configuration value is inconsistent; the message names the key."""


def key_name(path: Iterable) -> str:
    """Dotted name of a config key from its path, e.g. ``chains[0].N``.

    Parameters
    ----------
    path : iterable of str and int
        Keys (str) and list indices (int) from the top of the config.
    """
    name = ""
    for part in path:
        if isinstance(part, int):
            name += f"[{part}]"
        else:
            name += f".{part}" if name else str(part)
    return name or "<top level>"


def _fail(path, message: str):
    raise ConfigError(f"config key {key_name(path)!r}: {message}")


def check_config(config: Mapping) -> None:
    """Check the relations between keys of a schema-valid config.

    Parameters
    ----------
    config : mapping
        The config after schema validation (defaults filled in).

    Raises
    ------
    ConfigError
        Naming the first offending key.
    """
    if config["material"] not in MATERIALS:
        known = ", ".join(sorted(MATERIALS))
        _fail(["material"], f"unknown material {config['material']!r}; known: {known}")

    seen_n: dict[int, int] = {}
    for i, entry in enumerate(config["chains"]):
        n = entry["N"]
        if n in seen_n:
            _fail(["chains", i, "N"], f"N = {n} is listed twice (also chains[{seen_n[n]}])")
        seen_n[n] = i
        s1, s2 = entry["sensors"]
        for j, bead in enumerate((s1, s2)):
            if not 1 <= bead <= n:
                _fail(["chains", i, "sensors", j], f"bead {bead} is outside the chain 1..{n}")
        if not s1 < s2:
            _fail(["chains", i, "sensors"], f"S1 must be left of S2 (S1 < S2), got {[s1, s2]}")

    names = [m["name"] for m in config["models"]]
    for i, name in enumerate(names):
        if name in names[:i]:
            _fail(["models", i, "name"], f"model name {name!r} is listed twice")

    launch = config["launch"]
    if launch["v0_min_m_s"] > launch["v0_max_m_s"]:
        _fail(
            ["launch", "v0_min_m_s"],
            f"{launch['v0_min_m_s']} m/s is above v0_max_m_s = {launch['v0_max_m_s']} m/s",
        )
    if launch["count"] > 1 and launch["v0_min_m_s"] == launch["v0_max_m_s"]:
        _fail(["launch", "count"], "several launch speeds need v0_min_m_s < v0_max_m_s")

    simulation = config.get("simulation", {})
    step = simulation.get("time_step_s")
    record = simulation.get("record_interval_s")
    if step is not None and record is not None and step > record:
        _fail(
            ["simulation", "time_step_s"],
            f"{step} s is longer than record_interval_s = {record} s",
        )
    duration = simulation.get("duration_s")
    if duration is not None and record is not None and duration < 10 * record:
        _fail(["simulation", "duration_s"], f"{duration} s holds fewer than 10 samples")

    analysis = config.get("analysis", {})
    if analysis.get("main_estimator") not in analysis.get("estimators", [None]):
        _fail(
            ["analysis", "main_estimator"],
            f"{analysis.get('main_estimator')!r} is not among analysis.estimators "
            f"{analysis.get('estimators')}",
        )

    figures = config.get("figures", {})
    if figures.get("traces_model") not in names:
        _fail(
            ["figures", "traces_model"],
            f"{figures.get('traces_model')!r} is not a configured model; models: {names}",
        )
    for j, n in enumerate(figures.get("traces_N") or []):
        if n not in seen_n:
            _fail(["figures", "traces_N", j], f"N = {n} is not a configured chain")
    index = figures.get("representative_index")
    if index is not None and index >= launch["count"]:
        _fail(
            ["figures", "representative_index"],
            f"{index} is not an amplitude index 0..{launch['count'] - 1}",
        )
