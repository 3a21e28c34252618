"""Bounds of config values that depend on other keys (issue 32, item 3).

The JSON schema (``workflow/schemas/config.schema.yaml``) holds every bound of a key on
its own (``minimum``, ``maxItems``, ...). The bounds here need a second key: a record
interval against the time step and the narrowest pulse, a duration against the
slowest wave, a detection threshold against the smallest pulse, names that must stay
apart after rounding. :func:`check_bounds` runs them (from
:func:`chain.pipeline.config.check_config`, before any job) and raises
:class:`ConfigError` naming the key, as every config check does.

:data:`RULES` states, per key, what bounds it besides the schema, and why: the table
``docs/config_bounds.md`` is generated from the schema and :data:`RULES` by
:func:`bounds_table` (``python -m chain.pipeline.config_bounds SCHEMA``), and a test
checks that the committed table is that output.

Pulse estimates
---------------
A pulse of incident amplitude F_m has the half width tau = R sqrt(10) / v (Eq. 4, v of
Eq. 5). F_m is estimated from the launch as in the duration check
(:mod:`chain.pipeline.config`): V_m = LAUNCH_VELOCITY_RATIO x (m_s / m) x V0, the lower
estimate for a striker (its momentum m_s V0), 2 m_s V0 the upper one (a striker that
bounces back). Each check takes the estimate that refuses only what cannot work: the
widest possible pulse for a sampling bound, the largest possible pulse for a detection
bound.

This module reads no file and knows no Snakemake.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping

from chain.analysis.pulses import DEFAULT_MIN_SNR, MIN_FIT_SAMPLES
from chain.errors import ConfigError, key_label
from chain.physics.materials import get_material
from chain.physics.theory import (
    LAUNCH_VELOCITY_RATIO,
    force_from_bead_velocity,
    pulse_half_width,
    pulse_passing_time,
)
from chain.pipeline.virtual_config import virtual_experiment
from chain.studies.mechanism_settings import (
    setting_name,
    sweep_settings,
    viscous_name,
)

#: A duration of LAMMPS or of a long chain must be this many times the passing time of
#: the slowest pulse. 1, not chain.pipeline.config.DURATION_MARGIN (1.2, which also
#: covers a striker's launch, estimated 12 % slow): a launched bead's estimate errs on
#: the slow side already (ratio 0.45 against 0.47 measured), and whatif/brass.yaml's
#: LAMMPS record (2.6 ms against 2.31 ms) passes its slowest wave.
DURATION_MARGIN = 1.0

#: Smallest max_energy_drift with the default RK4 step: that step is chosen for a
#: relative drift of about 1e-9 (measured 3.1e-10 at 1 m/s on the N = 26 chain).
DEFAULT_STEP_DRIFT = 1e-9

#: Relative tolerance of "a whole number of time steps".
MULTIPLE_TOLERANCE = 1e-9

#: Key (dotted, ``[]`` for every list item) -> what bounds it besides the schema. The
#: table docs/config_bounds.md shows these beside the schema's own bounds.
RULES = {
    "seed": "no upper bound: numpy.random.default_rng takes any integer >= 0 (tried 2^70)",
    "chains[].sensors": "each bead in 1..N, S1 < S2 (chain.pipeline.config)",
    "long_chains.N": "no N of `chains` (their files would clash)",
    "long_chains.duration_s": (
        ">= the time the slowest launch (v0_min_m_s) needs to reach the middle bead "
        "(Eq. 4/5): the waves must collide in the record"
    ),
    "models[].name": "each name once",
    "launch.v0_min_m_s": "<= v0_max_m_s, < v0_max_m_s with count > 1",
    "launch.count": "3: the free exponent of Delta = A F_m^p needs 3 amplitudes",
    "simulation.duration_s": (
        ">= 10 record intervals and >= 1.2 x the time the slowest wave (v0_min_m_s) "
        "needs to pass the far sensor (Eq. 4/5; chain.pipeline.config)"
    ),
    "simulation.time_step_s": "<= record_interval_s",
    "simulation.record_interval_s": (
        "a whole number of time_step_s (when given); <= tau / "
        f"{MIN_FIT_SAMPLES} of the narrowest pulse (v0_max_m_s, Eq. 4): a cos^6 fit "
        f"needs {MIN_FIT_SAMPLES} samples on its rising edge"
    ),
    "simulation.max_energy_drift": (
        f">= {DEFAULT_STEP_DRIFT:g} with time_step_s null (the default step's drift); "
        "<= 0.01: beyond 1 % the energy books are not a check"
    ),
    "analysis.main_estimator": "one of analysis.estimators",
    "figures.traces_model": "a name of models",
    "figures.traces_N": "values of N of chains",
    "figures.representative_force_N": "no upper bound: the nearest amplitude is shown",
    "figures.representative_index": "<= launch.count - 1",
    "figures.experiment_force_N": "no upper bound: the nearest amplitude is shown",
    "experiment.datasets": "non-empty exactly with source: measured",
    "experiment.virtual.impact_speeds_m_s": (
        "3 distinct amplitudes (the free exponent); not with drop_heights_m; the fastest "
        "must not saturate the ADC (adc_range_V)"
    ),
    "experiment.virtual.drop_heights_m": "as impact_speeds_m_s",
    "experiment.virtual.noise_N": (
        f"< 1/{DEFAULT_MIN_SNR:g} of the largest possible incident F_m of the slowest "
        "striker (2 m_s V0): a pulse must stand above the detection threshold"
    ),
    "experiment.virtual.sampling_interval_s": (
        f"<= duration_s / 10; <= tau / {MIN_FIT_SAMPLES} of the widest possible "
        "pulse of the fastest striker (m_s V0, Eq. 4)"
    ),
    "experiment.virtual.adc_range_V": (
        "> the reading of the largest possible pulse (2 m_s V0) when adc_bits is set"
    ),
    "experiment.virtual.duration_s": (
        ">= 10 samples and >= 1.2 x the time the slowest striker's wave needs to pass "
        "the far sensor (Eq. 4/5; chain.pipeline.config)"
    ),
    "experiment.virtual.time_step_s": "<= sampling_interval_s",
    "lammps.record_interval_s": (
        "a whole number of lammps.time_step_s (LAMMPS rounds it, the cross-check "
        f"compares sample by sample); <= tau / {MIN_FIT_SAMPLES} of the narrowest "
        "pulse (fastest of check_speeds_m_s and sweep.launch_speeds_m_s)"
    ),
    "lammps.duration_s": (
        "with mechanism_study: >= 10 record intervals and >= the time the slowest of "
        "check_speeds_m_s and sweep.launch_speeds_m_s needs to pass the far sensor "
        "(Eq. 4/5)"
    ),
    "lammps.sweep.track_friction": (
        "values apart by >= 0.005 (file names keep 2 decimals: mut030); > 0 means >= 0.005"
    ),
    "lammps.sweep.bead_friction": "as track_friction",
    "lammps.sweep.default_settings": "as track_friction",
    "lammps.sweep.default_viscous_N_s_per_m": "distinct in 6 significant digits (file names)",
    "lammps.sweep.viscous_N_s_per_m": "as default_viscous_N_s_per_m",
    "ablation.variants[].name": "each name once",
    "ablation.variants[].set": (
        "with default_run and source virtual: every bound of experiment.virtual, "
        "setup.striker_radius_m and experiment.tolerance, on the variant's own settings"
    ),
}


def _fail(path, message: str):
    raise ConfigError(f"config key {key_label(path)!r}: {message}")


def _tau(config: Mapping, bead_speed_m_s: float) -> float:
    """Half width tau of the pulse a bead speed V_m gives (Eq. 4/5), s."""
    beads = get_material(config["material"])
    force = force_from_bead_velocity(bead_speed_m_s, beads, config["radius_m"])
    return float(pulse_half_width(force, beads, config["radius_m"]))


def _check_resolution(config: Mapping, path, interval: float, bead_speed_m_s: float, what):
    tau = _tau(config, bead_speed_m_s)
    if interval * MIN_FIT_SAMPLES > tau:
        _fail(
            path,
            f"{interval:g} s does not resolve the narrowest pulse ({what}: tau ~ "
            f"{tau * 1e6:.3g} us, Eq. 4); a cos^6 fit needs {MIN_FIT_SAMPLES} samples on its "
            f"rising edge; allowed: <= {tau / MIN_FIT_SAMPLES:.3g} s",
        )


def _check_multiple(path, interval: float, step: float, step_key: str) -> None:
    ratio = interval / step
    if ratio < 1 - MULTIPLE_TOLERANCE or abs(ratio - round(ratio)) > MULTIPLE_TOLERANCE * ratio:
        _fail(
            path,
            f"{interval:g} s is not a whole number of {step_key} = {step:g} s (the samples "
            f"would fall every {max(1, round(ratio)) * step:g} s); allowed: k x {step:g} s, "
            "k = 1, 2, ...",
        )


def _check_passing(config: Mapping, path, duration: float, v0: float, what, sensors=None):
    """``duration`` >= DURATION_MARGIN x the slowest pulse's passing time (every chain)."""
    worst = max(
        (
            pulse_passing_time(
                config["material"],
                config["radius_m"],
                entry["N"],
                sensors(entry) if sensors else entry["sensors"],
                v0,
            )
            | {"N": entry["N"]}
            for entry in config["chains"]
        ),
        key=lambda passing: passing["time_s"],
    )
    needed = DURATION_MARGIN * worst["time_s"]
    if duration < needed:
        _fail(
            path,
            f"{duration:g} s is too short: the slowest wave ({what} at V0 = {v0:g} m/s, Eq. 5 "
            f"speed {worst['speed_m_s']:.0f} m/s) passes bead {worst['bead']} of the "
            f"N = {worst['N']} chain at ~{worst['time_s'] * 1e3:.3g} ms; allowed: >= "
            f"{needed:.3g} s",
        )


def _check_simulation(config: Mapping) -> None:
    simulation = config["simulation"]
    launch = config["launch"]
    record, step = simulation["record_interval_s"], simulation.get("time_step_s")
    path = ["simulation", "record_interval_s"]
    if step is not None:
        _check_multiple(path, record, step, "simulation.time_step_s")
    fastest = LAUNCH_VELOCITY_RATIO * launch["v0_max_m_s"]
    _check_resolution(config, path, record, fastest, f"bead 1 at {launch['v0_max_m_s']:g} m/s")
    drift = simulation["max_energy_drift"]
    if step is None and drift < DEFAULT_STEP_DRIFT:
        _fail(
            ["simulation", "max_energy_drift"],
            f"{drift:g} is below the drift of the default time step (~{DEFAULT_STEP_DRIFT:g}); "
            f"allowed: >= {DEFAULT_STEP_DRIFT:g}, or a smaller simulation.time_step_s",
        )


def _check_long_chains(config: Mapping) -> None:
    duration = config.get("long_chains", {}).get("duration_s")
    if duration is None:
        return
    for n in config["long_chains"].get("N", []):
        middle = (n + 1) // 2
        long_chain = {**config, "chains": [{"N": n, "sensors": [middle, middle]}]}
        _check_passing(
            long_chain,
            ["long_chains", "duration_s"],
            duration,
            config["launch"]["v0_min_m_s"],
            "bead 1 launched, to the middle bead",
        )


def _striker_ratio(config: Mapping, virtual: Mapping) -> float:
    """m_s / m: 1 for a bead launch."""
    if virtual.get("launch", "striker") == "bead":
        return 1.0
    return (config["setup"]["striker_radius_m"] / config["radius_m"]) ** 3


def _check_virtual(config: Mapping) -> None:
    virtual = config["experiment"]["virtual"]
    base = ["experiment", "virtual"]
    entry = config["chains"][0]
    speeds = virtual_experiment(config, entry["N"], entry["sensors"]).nominal_speeds
    ratio = LAUNCH_VELOCITY_RATIO * _striker_ratio(config, virtual)
    _check_resolution(
        config,
        [*base, "sampling_interval_s"],
        virtual["sampling_interval_s"],
        ratio * float(max(speeds)),
        f"striker at {float(max(speeds)):g} m/s",
    )
    beads = get_material(config["material"])
    largest_of_smallest = force_from_bead_velocity(
        2.0 * ratio * float(min(speeds)), beads, config["radius_m"]
    )
    noise = virtual["noise_N"]
    if noise * DEFAULT_MIN_SNR >= largest_of_smallest:
        _fail(
            [*base, "noise_N"],
            f"{noise:g} N hides the smallest pulse (<= {largest_of_smallest:.3g} N at "
            f"{float(min(speeds)):g} m/s) below the detection threshold of "
            f"{DEFAULT_MIN_SNR:g} x noise_N; allowed: < "
            f"{largest_of_smallest / DEFAULT_MIN_SNR:.3g} N",
        )


def _check_lammps(config: Mapping) -> None:
    options = config["lammps"]
    step, record = options["time_step_s"], options["record_interval_s"]
    _check_multiple(["lammps", "record_interval_s"], record, step, "lammps.time_step_s")
    speeds = [*options["check_speeds_m_s"], *options["sweep"]["launch_speeds_m_s"]]
    fastest = LAUNCH_VELOCITY_RATIO * max(speeds)
    _check_resolution(
        config, ["lammps", "record_interval_s"], record, fastest, f"bead 1 at {max(speeds):g} m/s"
    )
    duration = options["duration_s"]
    if duration < 10 * record:
        _fail(
            ["lammps", "duration_s"],
            f"{duration:g} s holds fewer than 10 samples of lammps.record_interval_s = "
            f"{record:g} s; allowed: >= {10 * record:g} s",
        )
    _check_passing(config, ["lammps", "duration_s"], duration, min(speeds), "bead 1 launched")


def _check_setting_names(config: Mapping) -> None:
    sweep = config["lammps"]["sweep"]
    base = ["lammps", "sweep"]
    for key in ("track_friction", "bead_friction", "default_settings"):
        names: dict[str, object] = {}
        for i, value in enumerate(sweep[key]):
            pair = tuple(value) if key == "default_settings" else (value, value)
            name = setting_name(*pair)
            if pair != (0, 0) and name == setting_name(0.0, 0.0):
                _fail(
                    [*base, key, i],
                    f"{value} is named as the frictionless setting ({name}: file names keep "
                    "2 decimals); allowed: 0 or >= 0.005",
                )
            if name in names and names[name] != pair:
                _fail(
                    [*base, key, i],
                    f"{value} and {names[name]} share the file name {name} (2 decimals); "
                    "allowed: values at least 0.005 apart",
                )
            names[name] = pair
    sweep_settings(config, full=True)
    for key in ("default_viscous_N_s_per_m", "viscous_N_s_per_m"):
        seen: dict[str, float] = {}
        for i, gamma in enumerate(sweep[key]):
            name = viscous_name(float(gamma))
            if name in seen and seen[name] != gamma:
                _fail(
                    [*base, key, i],
                    f"{gamma} and {seen[name]} share the file name {name} (6 digits); "
                    "allowed: values apart in 6 significant digits",
                )
            seen[name] = gamma


def variant_config(config: Mapping, overrides: Mapping) -> dict:
    """The config an ablation variant runs: ``experiment.virtual`` with the variant's
    overrides (``striker_radius_m`` into ``setup``, ``tolerance`` into ``experiment``),
    the virtual experiment as the source, and no variants of its own.

    Parameters
    ----------
    config : mapping
        A schema-valid config (defaults filled in).
    overrides : mapping
        The variant's ``set``.
    """
    derived = copy.deepcopy(dict(config))
    experiment = derived["experiment"]
    experiment.update(source="virtual", datasets=[])
    for key, value in overrides.items():
        if key == "striker_radius_m":
            derived["setup"]["striker_radius_m"] = value
        elif key == "tolerance":
            # null (no selection) has nothing to check; a number is the run's tolerance.
            if value is not None:
                experiment["tolerance"] = value
        else:
            experiment["virtual"][key] = value
    derived["ablation"] = {"variants": []}
    return derived


def _check_variants(config: Mapping, check: Callable[[Mapping], None]) -> None:
    # The default run's variants, with the virtual experiment only (as the workflow
    # runs them); those of `snakemake ablation` alone are left to their jobs.
    for i, variant in enumerate(config.get("ablation", {}).get("variants", [])):
        if not variant.get("default_run", False):
            continue
        overrides = variant.get("set") or {}
        try:
            check(variant_config(config, overrides))
        except ConfigError as error:
            raise ConfigError(
                f"config key {key_label(['ablation', 'variants', i, 'set'])!r} (variant "
                f"{variant['name']!r}): with its settings, {error}"
            ) from None


def check_bounds(config: Mapping, check: Callable[[Mapping], None] | None = None) -> None:
    """Check the bounds of a schema-valid config that depend on other keys.

    Parameters
    ----------
    config : mapping
        The config after schema validation (defaults filled in) and the checks of
        :func:`chain.pipeline.config.check_config` up to the ablation.
    check : callable, optional
        The whole config check (:func:`chain.pipeline.config.check_config`), run again
        on each ablation variant's config (:func:`variant_config`); None skips the
        variants.

    Raises
    ------
    ConfigError
        Naming the first offending key.
    """
    _check_simulation(config)
    _check_long_chains(config)
    if config["experiment"]["source"] == "virtual":
        _check_virtual(config)
    if config.get("mechanism_study", True):
        _check_lammps(config)
        _check_setting_names(config)
    if check is not None and config["experiment"]["source"] == "virtual":
        _check_variants(config, check)


# ---- the table ------------------------------------------------------------------------

_LOWER = {"minimum": ">= {}", "exclusiveMinimum": "> {}", "minItems": "{} items"}
_UPPER = {"maximum": "<= {}", "exclusiveMaximum": "< {}", "maxItems": "{} items"}


def _leaves(schema: Mapping, path: str = ""):
    """(dotted key, schema of the key) of every leaf key, ``[]`` for list items."""
    properties = schema.get("properties")
    if properties and path.rsplit(".", 1)[-1] != "set":
        for name, sub in properties.items():
            yield from _leaves(sub, f"{path}.{name}" if path else name)
        return
    items = schema.get("items")
    if isinstance(items, Mapping) and items.get("properties"):
        yield from _leaves(items, f"{path}[]")
        return
    yield path, schema


def _side(schema: Mapping, words: Mapping) -> str:
    found = [form.format(_number(schema[k])) for k, form in words.items() if k in schema]
    items = schema.get("items")
    if isinstance(items, Mapping):
        found += [
            f"each {form.format(_number(items[k]))}" for k, form in words.items() if k in items
        ]
    return "; ".join(found)


def _number(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def _unit(key: str) -> str:
    units = {"_m_s2": "m/s^2", "_m_s": "m/s", "_N_s_per_m": "N s/m", "_N_per_m": "N/m"}
    units |= {"_mV_per_N": "mV/N", "_per_s": "1/s", "_s": "s", "_m": "m", "_N": "N", "_V": "V"}
    name = key.rsplit(".", 1)[-1].removesuffix("[]")
    return next((unit for suffix, unit in units.items() if name.endswith(suffix)), "")


def bounds_table(schema: Mapping) -> str:
    """docs/config_bounds.md: every key of the config schema, its unit, smallest and
    largest value (the schema's bounds) and the bounds :func:`check_bounds` and
    chain.pipeline.config add (:data:`RULES`).

    Parameters
    ----------
    schema : mapping
        The parsed ``workflow/schemas/config.schema.yaml``.
    """
    lines = [
        "# Config bounds",
        "",
        "Generated by `python -m chain.pipeline.config_bounds "
        "workflow/schemas/config.schema.yaml > docs/config_bounds.md` from the schema (its "
        "bounds) and `chain.pipeline.config_bounds.RULES` (the bounds that need other "
        "keys); `tests/test_config_bounds.py` fails when this file differs. A value "
        "outside them stops the run before any job, naming the key.",
        "",
        "| key | unit | type | smallest | largest | also bounded by, why |",
        "|---|---|---|---|---|---|",
    ]
    for key, sub in _leaves(schema):
        kind = sub.get("type", "as experiment.virtual" if "$ref" in sub else "")
        kind = " or ".join(kind) if isinstance(kind, list) else kind
        enum = sub.get("enum") or (sub.get("items") or {}).get("enum")
        lower = _side(sub, _LOWER) or (", ".join(map(str, enum)) if enum else "")
        rule = RULES.get(key, "").replace("|", "/")
        lines.append(
            f"| `{key}` | {_unit(key)} | {kind} | {lower} | {_side(sub, _UPPER)} | {rule} |"
        )
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``python -m chain.pipeline.config_bounds SCHEMA``: print :func:`bounds_table`."""
    import sys

    import yaml

    path = (sys.argv[1:] if argv is None else argv)[0]
    with open(path, encoding="utf-8") as handle:
        sys.stdout.write(bounds_table(yaml.safe_load(handle)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
