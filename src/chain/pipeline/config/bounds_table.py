"""The table docs/config_bounds.md: every key of the config schema, its unit, smallest
and largest usable value, and what else bounds it and why.

The schema's own bounds fill the value columns; :data:`RULES` adds the bounds that need
other keys, or why a key has no upper bound. ``python -m chain.pipeline.config.bounds_table
SCHEMA`` prints the table; a test keeps the committed one equal to it.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping

import yaml

from chain.analysis.pulses import DEFAULT_MIN_SNR, MIN_FIT_SAMPLES
from chain.pipeline.config.bounds_experiment import JITTER_SIGMAS, MIN_KEPT_SHOTS
from chain.pipeline.config.bounds_run import DEFAULT_STEP_DRIFT, MIN_SENSOR_DISTANCE

_NAME = "<= 100 characters: part of file names (at most 255 bytes)"
_NEAREST = "no upper bound: the nearest amplitude is shown"

#: Key (dotted, ``[]`` for every list item) -> what bounds it besides the schema, and
#: why; for a key with no largest value in the schema, why it needs none.
RULES = {
    "run_name": "a folder name: results/<run_name>/",
    "seed": (
        "numpy.random.default_rng takes any integer >= 0; the run seeds it with seed + N "
        "+ 1000 k (< seed + 10^5), and 2^62 keeps that a 64-bit integer for whatever "
        "reads metadata.yaml or the ablation tables"
    ),
    "chains[].N": (
        f"each sensor {MIN_SENSOR_DISTANCE:g} beads from the collision point needs N >= 5"
    ),
    "chains[].sensors": (
        "each bead in 1..N, S1 < S2 (chain.pipeline.config.check); S1 <= (N + 1)/2 - "
        f"{MIN_SENSOR_DISTANCE:g} and S2 >= (N + 1)/2 + {MIN_SENSOR_DISTANCE:g}: each "
        "sensor reads the incident pulse, then the crossed one, as two pulses "
        "(chain.analysis.pulse_rows; measured: one pulse from 1.5 beads in)"
    ),
    "long_chains.N": "no N of `chains` (their files would clash)",
    "long_chains.duration_s": (
        ">= the time the slowest launch (v0_min_m_s) needs to reach the middle bead "
        "(Eq. 4/5): the waves must collide in the record; <= 1 as simulation.duration_s"
    ),
    "models[].name": f"each name once; {_NAME}",
    "launch.v0_min_m_s": "< v0_max_m_s (count >= 3 distinct speeds)",
    "launch.count": "3: the free exponent of Delta = A F_m^p needs 3 amplitudes",
    "simulation.duration_s": (
        ">= 10 record intervals and >= 1.2 x the time the slowest wave (v0_min_m_s) "
        "needs to pass the far sensor (Eq. 4/5; chain.pipeline.config.check)"
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
    "setup.striker_radius_m": (
        "no fixed upper bound: the sampling, detection and ADC bounds of "
        "experiment.virtual cap the pulses a striker gives"
    ),
    "analysis.main_estimator": "one of analysis.estimators",
    "figures.traces_model": "a name of models",
    "figures.traces_N": "values of N of chains",
    "figures.representative_force_N": _NEAREST,
    "figures.representative_index": "<= launch.count - 1",
    "figures.experiment_force_N": _NEAREST,
    "experiment.datasets": (
        "non-empty exactly with source: measured; no upper count: one analysis per dataset"
    ),
    "experiment.name": _NAME,
    "experiment.tolerance": (
        "> 0: F_L and F_R are two noisy fits, never equal; with the virtual experiment, "
        f"the planned shots' speeds (F_m ~ V^(6/5)) keep >= {MIN_KEPT_SHOTS} collision "
        "shots of every chain (3 points for the free exponent)"
    ),
    "experiment.virtual.drag_rate_per_s": (
        "the smallest pulse, damped as exp(-1.2 gamma t) until it passes the far sensor "
        "(momentum decays as exp(-gamma t)), stays above the detection threshold of "
        "noise_N"
    ),
    "experiment.virtual.sensor_stiffness_N_per_m": (
        "with time_step_s given and readout sensor: the split bead's period >= 50 "
        "time_step_s (the virtual experiment's own step coarsening); null: no upper "
        "bound, the step follows the spring"
    ),
    "experiment.virtual.sensitivity_mV_per_N": (
        "no fixed upper bound: adc_range_V must hold the largest pulse's reading"
    ),
    "experiment.virtual.impact_speeds_m_s": (
        "3 distinct amplitudes (the free exponent); not with drop_heights_m; the fastest "
        "must not saturate the ADC (adc_range_V)"
    ),
    "experiment.virtual.drop_heights_m": "as impact_speeds_m_s",
    "experiment.virtual.timing_jitter_s": (
        f"right_delay_s +- {JITTER_SIGMAS:g} x timing_jitter_s moves the collision point "
        f"(v delta / 2, the fastest wave) no nearer than {MIN_SENSOR_DISTANCE:g} beads to "
        "S1 or S2: the waves must cross between the sensors"
    ),
    "experiment.virtual.noise_N": (
        f"< 1/{DEFAULT_MIN_SNR:g} of the largest possible incident F_m of the slowest "
        "launch (2 m_s V0): a pulse must stand above the detection threshold"
    ),
    "experiment.virtual.sampling_interval_s": (
        f"<= duration_s / 10; <= tau / {MIN_FIT_SAMPLES} of the widest possible "
        "pulse of the fastest launch (m_s V0, Eq. 4)"
    ),
    "experiment.virtual.adc_range_V": (
        "with adc_bits: > the reading of the largest possible pulse (no saturation), and "
        f"<= the reading of {DEFAULT_MIN_SNR:g} ADC steps under the smallest one"
    ),
    "experiment.virtual.duration_s": (
        ">= 10 samples and >= 1.2 x the time the slowest launch's wave needs to pass "
        "the far sensor (Eq. 4/5; strikers or launch: bead; chain.pipeline.config.check)"
    ),
    "experiment.virtual.time_step_s": "<= sampling_interval_s",
    "experiment.virtual.gap_mean_m": (
        "no fixed upper bound, not checked: a gap only delays the wave (closed at the "
        "bead's speed, ~2 (m_s/m) V0); the amplitudes whose wave misses the record drop "
        "out of the fits"
    ),
    "experiment.virtual.gap_spread_m": "as gap_mean_m",
    "experiment.virtual.right_delay_s": "as timing_jitter_s",
    "lammps.time_step_s": "<= record_interval_s (a whole number of steps)",
    "lammps.record_interval_s": (
        "a whole number of lammps.time_step_s (LAMMPS rounds it, the cross-check "
        f"compares sample by sample); <= tau / {MIN_FIT_SAMPLES} of the narrowest "
        "pulse (fastest of check_speeds_m_s and sweep.launch_speeds_m_s)"
    ),
    "lammps.duration_s": (
        "with studies.mechanisms: >= 10 record intervals and >= the time the slowest of "
        "check_speeds_m_s and sweep.launch_speeds_m_s needs to pass the far sensor "
        "(Eq. 4/5); <= 1 as simulation.duration_s"
    ),
    "lammps.check_speeds_m_s": "<= 100 as launch.v0_max_m_s",
    "lammps.sweep.launch_speeds_m_s": "<= 100 as launch.v0_max_m_s",
    "lammps.sweep.eta_s": "<= 0.001 as models[].eta_s",
    "lammps.sweep.gravity_m_s2": (
        "no upper bound in the code: it only presses the beads on the track (the beads "
        "settle under it, damped, before the launch; friction mu_t m g)"
    ),
    "lammps.sweep.track_friction": (
        "values apart by >= 0.005 (file names keep 2 decimals: mut030); > 0 means >= 0.005"
    ),
    "lammps.sweep.bead_friction": "as track_friction",
    "lammps.sweep.default_settings": "as track_friction",
    "lammps.sweep.default_viscous_N_s_per_m": (
        "distinct in 6 significant digits (file names); no fixed upper bound: a larger "
        "gamma only damps the wave more (the detection of the LAMMPS traces decides)"
    ),
    "lammps.sweep.viscous_N_s_per_m": "as default_viscous_N_s_per_m",
    "ablation.variants[].name": f"each name once; {_NAME}",
    "ablation.variants[].description": "free text (the tables' overrides column)",
    "ablation.variants[].mechanism": "free text (tables/ssw_mechanisms.csv)",
    "ablation.variants[].set": (
        "every bound of experiment.virtual, setup.striker_radius_m and "
        "experiment.tolerance, on the variant's own settings (every variant: "
        "`studies.ablation: full` runs them all)"
    ),
}

#: Schema keywords of a key's smallest and largest value, as the table writes them.
_LOWER = {"minimum": ">= {}", "exclusiveMinimum": "> {}", "minItems": "{} items"}
_UPPER = {"maximum": "<= {}", "exclusiveMaximum": "< {}", "maxItems": "{} items"}
_LOWER["minLength"] = _UPPER["maxLength"] = "{} characters"

#: Written in the "largest" column of a choice (an enum or a boolean).
CHOICE = "(a choice)"


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


def _unit(key: str, kind: str) -> str:
    if kind == "boolean":
        return ""
    units = {"_m_s2": "m/s^2", "_m_s": "m/s", "_N_s_per_m": "N s/m", "_N_per_m": "N/m"}
    units |= {"_mV_per_N": "mV/N", "_per_s": "1/s", "_s": "s", "_m": "m", "_N": "N", "_V": "V"}
    name = key.rsplit(".", 1)[-1].removesuffix("[]")
    return next((unit for suffix, unit in units.items() if name.endswith(suffix)), "")


def table_rows(schema: Mapping) -> list[tuple[str, str, str, str, str, str]]:
    """(key, unit, type, smallest, largest, rule) of every leaf key of ``schema``, the
    parsed ``workflow/schemas/config.schema.yaml``."""
    rows = []
    for key, sub in _leaves(schema):
        kind = sub.get("type", "as experiment.virtual" if "$ref" in sub else "")
        kind = " or ".join(kind) if isinstance(kind, list) else kind
        enum = sub.get("enum") or (sub.get("items") or {}).get("enum")
        if kind == "boolean":
            enum = [False, True]
        lower = _side(sub, _LOWER)
        if enum:
            values = ", ".join(str(v).lower() if isinstance(v, bool) else str(v) for v in enum)
            lower = "; ".join(filter(None, [lower, f"one of {values}"]))
        upper = _side(sub, _UPPER) or (CHOICE if enum else "")
        rule = RULES.get(key, "").replace("|", "/")
        rows.append((key, _unit(key, kind), kind, lower, upper, rule))
    return rows


def bounds_table(schema: Mapping) -> str:
    """docs/config_bounds.md, from ``schema`` (the parsed config schema) and
    :data:`RULES` (:func:`table_rows`)."""
    lines = [
        "# Config bounds",
        "",
        "Generated by `python -m chain.pipeline.config.bounds_table "
        "workflow/schemas/config.schema.yaml > docs/config_bounds.md` from the schema (its "
        "bounds) and `chain.pipeline.config.bounds_table.RULES` (the bounds that need "
        "other keys, and why a key has no upper bound); `tests/test_config_bounds.py` "
        "fails when this file differs. A value outside them stops the run before any "
        "job, naming the key (for an ablation variant, the key and the variant).",
        "",
        "| key | unit | type | smallest | largest | also bounded by, why |",
        "|---|---|---|---|---|---|",
    ]
    for key, unit, kind, lower, upper, rule in table_rows(schema):
        lines.append(f"| `{key}` | {unit} | {kind} | {lower} | {upper} | {rule} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``python -m chain.pipeline.config.bounds_table SCHEMA``: print :func:`bounds_table`."""
    path = (sys.argv[1:] if argv is None else argv)[0]
    with open(path, encoding="utf-8") as handle:
        sys.stdout.write(bounds_table(yaml.safe_load(handle)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
