"""Checks on a pipeline configuration that a JSON schema cannot express.

After the schema (types, ranges, defaults), :func:`check_config` checks that every number
is finite, the relations between keys, then the bounds that need a second key
(:mod:`chain.pipeline.config.bounds`). Every message starts with the dotted key (``config
key 'chains[1].sensors': ...``) and says what is allowed, so that a bad config stops before
any job runs and says where. A plain dict in; no file read, no Snakemake.

Duration: a record must last :data:`DURATION_MARGIN` times the time the slowest wave
(bead 1 launched at ``launch.v0_min_m_s``) needs to pass the sensor farthest from its
launching end (:func:`chain.physics.theory.pulse_passing_time`). The paper run passes with
2.6 ms against 1.9 ms; the SSW search is cut at the end of a shorter record.
"""

from __future__ import annotations

from collections.abc import Mapping

from chain.errors import ConfigError, ParameterError, key_label, nonfinite_paths
from chain.physics.materials import MATERIALS, get_material
from chain.physics.theory import force_from_bead_velocity
from chain.pipeline.config import check_passing, check_samples, fail, launch_ratios
from chain.pipeline.config.ablation import check_ablation
from chain.pipeline.config.virtual import virtual_experiment

#: The duration over the time the slowest pulse needs to pass the far sensor, at least.
DURATION_MARGIN = 1.2


def _check_step(path, step, interval: float, interval_key: str) -> None:
    if step is not None and step > interval:
        what = interval_key.removesuffix("_s").replace("_", " ")
        fail(
            path,
            f"{step:g} s is longer than {interval_key} = {interval:g} s; allowed: <= the {what}, "
            "or null",
        )


def _check_sources(experiment: Mapping) -> None:
    source = experiment.get("source", "none")
    datasets = experiment.get("datasets", [])
    if source == "measured" and not datasets:
        fail(
            ["experiment", "datasets"],
            "source: measured needs at least one dataset folder (data/README.md format), "
            "e.g. [data/lab2011_N25, data/lab2011_N26]",
        )
    if source != "measured" and datasets:
        fail(
            ["experiment", "datasets"],
            f"dataset folders are read only with source: measured (source is {source!r}); "
            "empty the list or set experiment.source: measured",
        )


def _check_virtual(config: Mapping) -> None:
    virtual = config.get("experiment", {}).get("virtual", {})
    base = ["experiment", "virtual"]
    if virtual.get("impact_speeds_m_s") is not None and virtual.get("drop_heights_m") is not None:
        fail(
            [*base, "drop_heights_m"],
            "give impact_speeds_m_s or drop_heights_m, not both (set the other to null)",
        )
    sampling = virtual.get("sampling_interval_s", 1.0)
    key = "sampling_interval_s"
    check_samples([*base, "duration_s"], virtual.get("duration_s", 0.0), sampling, key)
    _check_step([*base, "time_step_s"], virtual.get("time_step_s"), sampling, key)
    for entry in config["chains"]:
        try:
            settings = virtual_experiment(config, entry["N"], entry["sensors"])
        except ParameterError as error:
            fail(base, f"{error} (chain N = {entry['N']})")
    # The largest pulse: that of the fastest launch, handed on whole.
    fastest = float(max(settings.nominal_speeds))
    v_m = launch_ratios(config, virtual)[1] * fastest
    largest = force_from_bead_velocity(v_m, get_material(config["material"]), config["radius_m"])
    volts = largest * max(settings.sensitivities) / 1000.0
    if settings.adc_bits is not None and volts >= settings.adc_range_V:
        fail(
            [*base, "adc_range_V"],
            f"{settings.adc_range_V:g} V: the largest pulse (~{largest:.3g} N at "
            f"{fastest:g} m/s) reads ~{volts:.3g} V and would saturate the ADC; allowed: "
            f"> {volts:.3g} V (or slower strikers, or adc_bits: null)",
        )


def check_finite(config: Mapping) -> None:
    """Every number of ``config`` (a mapping, validated or not) is finite, else
    :class:`ConfigError` naming each key: the schema's minimum/maximum let NaN through,
    and YAML spells NaN and infinity ``.nan`` and ``.inf``."""
    bad = [
        f"config key {key_label(path)!r}: {number!r} is not a finite number; allowed: a "
        "finite number in the key's range (workflow/schemas/config.schema.yaml)"
        for path, number in nonfinite_paths(dict(config))
    ]
    if bad:
        raise ConfigError("\n".join(bad))


def _check_chains(config: Mapping) -> dict[int, int]:
    seen_n: dict[int, int] = {}
    for i, entry in enumerate(config["chains"]):
        n = entry["N"]
        if n in seen_n:
            fail(
                ["chains", i, "N"],
                f"N = {n} is listed twice (also chains[{seen_n[n]}]); allowed: each N once",
            )
        seen_n[n] = i
        s1, s2 = entry["sensors"]
        for j, bead in enumerate((s1, s2)):
            if not 1 <= bead <= n:
                fail(
                    ["chains", i, "sensors", j],
                    f"bead {bead} is outside the chain; allowed: beads 1..{n}",
                )
        if not s1 < s2:
            fail(
                ["chains", i, "sensors"],
                f"got {[s1, s2]}; allowed: S1 left of S2 (S1 < S2; S1 is met first by the LSTW)",
            )
    for i, n in enumerate(config.get("long_chains", {}).get("N", [])):
        if n in seen_n:
            fail(
                ["long_chains", "N", i],
                f"N = {n} is also chains[{seen_n[n]}] (their files would clash); allowed: "
                "an N not in chains",
            )
    return seen_n


def _check_models_and_launch(config: Mapping) -> list[str]:
    names = [m["name"] for m in config["models"]]
    for i, name in enumerate(names):
        if name in names[:i]:
            fail(
                ["models", i, "name"],
                f"model name {name!r} is listed twice; allowed: each name once (file names)",
            )
    launch = config["launch"]
    if launch["v0_min_m_s"] > launch["v0_max_m_s"]:
        fail(
            ["launch", "v0_min_m_s"],
            f"{launch['v0_min_m_s']} m/s is above v0_max_m_s = {launch['v0_max_m_s']} m/s; "
            "allowed: v0_min_m_s <= v0_max_m_s",
        )
    if launch["count"] > 1 and launch["v0_min_m_s"] == launch["v0_max_m_s"]:
        fail(
            ["launch", "count"],
            f"{launch['count']} launch speeds need v0_min_m_s < v0_max_m_s; allowed: a "
            "smaller v0_min_m_s (count is at least 3: the free exponent needs 3 speeds)",
        )
    return names


def _check_simulation(config: Mapping) -> None:
    simulation = config.get("simulation", {})
    record, duration = simulation.get("record_interval_s"), simulation.get("duration_s")
    path = ["simulation", "duration_s"]
    if record is not None:
        step = simulation.get("time_step_s")
        _check_step(["simulation", "time_step_s"], step, record, "record_interval_s")
        if duration is not None:
            check_samples(path, duration, record, "record_interval_s")
    if duration is None:
        return
    v0 = config["launch"]["v0_min_m_s"]
    check_passing(config, path, duration, v0, "bead 1 launched", DURATION_MARGIN)


def _check_analysis_and_figures(config: Mapping, names: list[str], seen_n) -> None:
    analysis = config.get("analysis", {})
    if analysis.get("main_estimator") not in analysis.get("estimators", [None]):
        fail(
            ["analysis", "main_estimator"],
            f"{analysis.get('main_estimator')!r} is not among analysis.estimators; allowed: "
            f"{analysis.get('estimators')}",
        )
    figures = config.get("figures", {})
    if figures.get("traces_model") not in names:
        fail(
            ["figures", "traces_model"],
            f"{figures.get('traces_model')!r} is not a configured model; allowed: {names}",
        )
    for j, n in enumerate(figures.get("traces_N") or []):
        if n not in seen_n:
            fail(
                ["figures", "traces_N", j],
                f"N = {n} is not a configured chain; allowed: {sorted(seen_n)}",
            )
    index = figures.get("representative_index")
    count = config["launch"]["count"]
    if index is not None and index >= count:
        fail(
            ["figures", "representative_index"],
            f"{index} is not an amplitude index; allowed: 0..{count - 1} (launch.count speeds)",
        )


def check_config(config: Mapping) -> None:
    """Check ``config``, validated by the schema (defaults filled in): every number
    finite, then the relations between keys; :class:`ConfigError` naming every
    non-finite key, else the first offending key."""
    check_finite(config)
    if config["material"] not in MATERIALS:
        known = ", ".join(sorted(MATERIALS))
        fail(["material"], f"unknown material {config['material']!r}; known: {known}")
    seen_n = _check_chains(config)
    names = _check_models_and_launch(config)
    _check_simulation(config)
    _check_analysis_and_figures(config, names, seen_n)
    experiment = config.get("experiment", {})
    _check_sources(experiment)
    if experiment.get("source", "none") == "virtual":
        _check_virtual(config)
    check_ablation(config)
    from chain.pipeline.config.bounds import check_bounds  # imports pandas: only here

    check_bounds(config, check_config)
