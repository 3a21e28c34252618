"""The mechanism study (issue 24): why are the measured SSW larger than the model's?

Two parts, both on the LAMMPS engine (:mod:`chain.physics.lammps_engine`, optional):

* **the cross-check** (:func:`lammps_check_table`): in the frictionless 1D limit (no
  track, no gravity, mu = 0) LAMMPS and our kernel (:func:`chain.physics.simulation.simulate`)
  run the same shots; their sensor traces and their C must agree
  (``tables/lammps_check.csv``);
* **the friction/rotation sweep** (:func:`sweep_settings`, :func:`mechanism_rows`):
  beads on a floor track under gravity with track friction mu_t and bead-bead friction
  mu_b (rotation, rolling and twisting resistance), analysed as every other series:
  C from the delays, SSW/F_m at S2 from :func:`chain.analysis.ssw.ssw_fit_table`,
  each against the frictionless setting (``tables/ssw_mechanisms.csv``).

This module maps config keys (``lammps``) and knows no Snakemake.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from chain.analysis.delays import delay_fit_table, delay_table
from chain.analysis.pulse_rows import pulse_table
from chain.analysis.rows import flag_unusable
from chain.analysis.ssw import ssw_fit_table, ssw_table
from chain.physics.lammps_engine import GranularChain
from chain.physics.materials import get_material

#: Columns of ``tables/ssw_mechanisms.csv`` (the results contract).
MECHANISM_COLUMNS = (
    "mechanism",
    "setting",
    "N",
    "ssw_over_Fm",
    "ssw_over_Fm_err",
    "ratio_to_frictionless",
    "C",
    "C_stderr",
)

#: Mechanism name of the LAMMPS friction/rotation rows.
FRICTION_MECHANISM = "rotation + friction (LAMMPS)"

#: Mechanism name of the LAMMPS rows with a viscous inter-bead force instead of
#: Kuwabara-Kono (on the frictionless track).
VISCOUS_MECHANISM = "viscous inter-bead term (LAMMPS)"

#: Columns of ``tables/lammps_check.csv``.
CHECK_COLUMNS = (
    "N",
    "model",
    "eta_s",
    "n_speeds",
    "C_kernel",
    "C_kernel_stderr",
    "C_lammps",
    "rel_diff_C",
    "max_trace_diff_over_Fm",
    "max_trace_diff_N",
    "dt_kernel_s",
    "dt_lammps_s",
    "within_tolerance",
)

#: The cross-check's targets: C within this relative difference, and every sensor
#: sample within this fraction of the shot's F_m.
C_TOLERANCE = 1e-4
TRACE_TOLERANCE = 1e-4

#: Defaults of the ``lammps`` config section (as in the schema).
DEFAULTS = {
    "time_step_s": 2.5e-8,
    "record_interval_s": 1e-6,
    "duration_s": 2.6e-3,
    "check_speeds_m_s": [0.021, 0.0459, 0.1, 0.215],
}
SWEEP_DEFAULTS = {
    "launch_speeds_m_s": [0.021, 0.053, 0.13],
    "eta_s": 0.58e-6,
    "gravity_m_s2": 9.81,
    "track_friction": [0.0, 0.1, 0.3, 0.5],
    "bead_friction": [0.0, 0.1, 0.3],
    "default_settings": [[0.0, 0.0], [0.3, 0.0], [0.3, 0.3], [0.5, 0.3]],
    "viscous_N_s_per_m": [2.0, 10.0, 30.0],
    "default_viscous_N_s_per_m": [10.0],
}


def lammps_options(config: Mapping) -> dict:
    """The ``lammps`` section of a schema-valid config with its defaults filled in;
    ``sweep`` likewise."""
    section = dict(config.get("lammps") or {})
    options = {key: section.get(key, value) for key, value in DEFAULTS.items()}
    sweep = dict(section.get("sweep") or {})
    options["sweep"] = {key: sweep.get(key, value) for key, value in SWEEP_DEFAULTS.items()}
    return options


def setting_name(track_friction: float, bead_friction: float) -> str:
    """File-safe name of a (mu_t, mu_b) setting, e.g. ``mut030-mub010``."""
    return f"mut{round(100 * track_friction):03d}-mub{round(100 * bead_friction):03d}"


def setting_label(track_friction: float, bead_friction: float) -> str:
    """Human label of a (mu_t, mu_b) setting."""
    return f"mu_t={track_friction:g}, mu_b={bead_friction:g}"


def sweep_settings(config: Mapping, full: bool) -> dict[str, tuple[float, float]]:
    """Name -> (mu_t, mu_b) of the sweep: the default run's pairs (``full`` False), or
    those and the whole grid; the frictionless (0, 0) first, always."""
    sweep = lammps_options(config)["sweep"]
    pairs = [(t, b) for t, b in sweep["default_settings"]]
    if full:
        pairs += [(t, b) for t in sweep["track_friction"] for b in sweep["bead_friction"]]
    pairs = [(0.0, 0.0)] + [(float(t), float(b)) for t, b in pairs if (t, b) != (0, 0)]
    return {setting_name(t, b): (t, b) for t, b in dict.fromkeys(pairs)}


def viscous_name(gamma: float) -> str:
    """File-safe name of a viscous setting of gamma N s/m, e.g. ``visc2p0``."""
    return "visc" + f"{gamma:g}".replace(".", "p")


def viscous_settings(config: Mapping, full: bool) -> dict[str, float]:
    """Name -> gamma (N s/m) of the viscous inter-bead settings: the default run's or,
    with ``full``, those and the full list."""
    sweep = lammps_options(config)["sweep"]
    values = list(sweep["default_viscous_N_s_per_m"])
    if full:
        values += list(sweep["viscous_N_s_per_m"])
    return {viscous_name(float(g)): float(g) for g in dict.fromkeys(values)}


def granular_chain(
    config: Mapping,
    n_beads: int,
    *,
    eta: float,
    track_friction: float = 0.0,
    bead_friction: float = 0.0,
    track: bool = False,
    viscous_damping: float = 0.0,
) -> GranularChain:
    """The configured beads (material, radius) as a LAMMPS chain.

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    n_beads : int
        N.
    eta : float
        Kuwabara-Kono relaxation time, s.
    track_friction, bead_friction : float
        mu_t and mu_b.
    track : bool
        Floor and gravity (``lammps.sweep.gravity_m_s2``); False for the 1D limit.
    viscous_damping : float
        gamma of a viscous inter-bead force instead of Kuwabara-Kono, N s/m.
    """
    material = get_material(config["material"])
    return GranularChain(
        n_beads=int(n_beads),
        radius=float(config["radius_m"]),
        youngs_modulus=material.youngs_modulus,
        poisson_ratio=material.poisson_ratio,
        density=material.density,
        eta=float(eta),
        bead_friction=float(bead_friction),
        track_friction=float(track_friction),
        track=bool(track),
        gravity=float(lammps_options(config)["sweep"]["gravity_m_s2"]),
        viscous_damping=float(viscous_damping),
    )


def analyse_traces(traces: pd.DataFrame, estimator: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    """C and the SSW slope at S2 of one trace table, as the pipeline analyses any series.

    Parameters
    ----------
    traces : DataFrame
        A trace table (collision and reference shots per amplitude).
    estimator : str
        Pulse estimator (:data:`chain.analysis.pulses.ESTIMATORS`).

    Returns
    -------
    delay_fits : DataFrame
        :func:`chain.analysis.delays.delay_fit_table` rows (per N and pooled).
    ssw_fits : DataFrame
        :func:`chain.analysis.ssw.ssw_fit_table` rows of the S2 readings (SSW behind LSTW).
    """
    pulses = pulse_table(traces, estimators=(estimator,))
    delays = delay_table(pulses)
    fits = delay_fit_table(flag_unusable(delays, ["F_m_N", "delay_us"], "delay rows"))
    ssw = ssw_table(traces, pulses, estimator=estimator)
    return fits, ssw_fit_table(ssw[ssw["sensor"] == "S2"])


def trace_difference(first: pd.DataFrame, second: pd.DataFrame) -> tuple[float, float]:
    """Largest |difference| of two trace tables of the same shots, sample by sample:
    (over the shot's F_m, in N). F_m of a shot is its largest sensor force in ``first``.

    Parameters
    ----------
    first, second : DataFrame
        Trace tables with the same shots, sensors and sample times.
    """
    columns = [c for c in first.columns if c.startswith("force_bead")]
    worst_ratio, worst = 0.0, 0.0
    for shot, group in first.groupby("shot", sort=True):
        other = second[second["shot"] == shot]
        samples = min(len(group), len(other))
        a = group[columns].to_numpy(float)[:samples]
        b = other[columns].to_numpy(float)[:samples]
        diff = float(np.max(np.abs(a - b)))
        worst = max(worst, diff)
        worst_ratio = max(worst_ratio, diff / float(np.max(np.abs(a))))
    return worst_ratio, worst


def check_row(
    kernel: pd.DataFrame, lammps: pd.DataFrame, *, estimator: str, model: str, eta: float
) -> dict:
    """One row of ``lammps_check.csv`` from the kernel's and LAMMPS' traces of the same
    shots (one chain, one model); ``dt_*`` columns are left to the caller."""
    c_kernel = _c_of(analyse_traces(kernel, estimator)[0])
    c_lammps = _c_of(analyse_traces(lammps, estimator)[0])
    ratio, worst = trace_difference(kernel, lammps)
    rel = abs(c_lammps[0] - c_kernel[0]) / c_kernel[0]
    return {
        "N": int(kernel["N"].iloc[0]),
        "model": model,
        "eta_s": eta,
        "n_speeds": int(kernel["amplitude"].nunique()),
        "C_kernel": c_kernel[0],
        "C_kernel_stderr": c_kernel[1],
        "C_lammps": c_lammps[0],
        "rel_diff_C": rel,
        "max_trace_diff_over_Fm": ratio,
        "max_trace_diff_N": worst,
        "within_tolerance": bool(rel <= C_TOLERANCE and ratio <= TRACE_TOLERANCE),
    }


def _c_of(fits: pd.DataFrame) -> tuple[float, float]:
    """(C, its standard error) of the single chain in ``fits``, us N^(1/6)."""
    row = fits[fits["N"].astype(str) != "pooled"].iloc[0]
    return float(row["C_us_N16"]), float(row["C_stderr_us_N16"])


def mechanism_rows(
    mechanism: str,
    settings: Mapping[str, str],
    delay_fits: Sequence[pd.DataFrame],
    ssw_fits: Sequence[pd.DataFrame],
    reference: str,
) -> pd.DataFrame:
    """Rows of ``ssw_mechanisms.csv`` for one mechanism.

    Parameters
    ----------
    mechanism : str
        The ``mechanism`` column.
    settings : mapping
        Series name (the ``model`` column of the fits) -> setting label.
    delay_fits, ssw_fits : sequence of DataFrame
        :func:`analyse_traces` outputs of every series and chain.
    reference : str
        The series name of the frictionless (or ingredient-off) reference: its SSW/F_m
        per N is the denominator of ``ratio_to_frictionless``.

    Returns
    -------
    DataFrame
        Columns :data:`MECHANISM_COLUMNS`, one row per (setting, N), the reference's
        rows first (if it is one of ``settings``); SSW/F_m is the
        proportional slope of SSW against F_m at S2 (N/N) and its standard error, C in
        us N^(1/6).
    """
    delays = pd.concat(delay_fits, ignore_index=True)
    delays = delays[delays["N"].astype(str) != "pooled"].astype({"N": int})
    ssw = pd.concat(ssw_fits, ignore_index=True).astype({"N": int})
    base = ssw[ssw["model"] == reference].set_index("N")["slope"]
    rows = []
    ssw = ssw.assign(_first=ssw["model"] != reference).sort_values("_first", kind="stable")
    for (model, n_beads), group in ssw.groupby(["model", "N"], sort=False):
        if model not in settings:
            continue
        fit = group.iloc[0]
        delay = delays[(delays["model"] == model) & (delays["N"] == n_beads)]
        c_row = delay.iloc[0] if len(delay) else None
        rows.append(
            {
                "mechanism": mechanism,
                "setting": settings[model],
                "N": int(n_beads),
                "ssw_over_Fm": float(fit["slope"]),
                "ssw_over_Fm_err": float(fit["slope_stderr"]),
                "ratio_to_frictionless": float(fit["slope"]) / float(base.get(n_beads, np.nan)),
                "C": np.nan if c_row is None else float(c_row["C_us_N16"]),
                "C_stderr": np.nan if c_row is None else float(c_row["C_stderr_us_N16"]),
            }
        )
    return pd.DataFrame(rows, columns=MECHANISM_COLUMNS)


def run_lammps_check(config: Mapping, estimator: str) -> pd.DataFrame:
    """The cross-check of every configured chain and model (``lammps_check.csv``).

    For each chain (N, sensors) and model (eta): the same collision and reference shots
    at ``lammps.check_speeds_m_s`` by our kernel (its default step) and by LAMMPS
    without track, gravity or friction; rows as :func:`check_row`.

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    estimator : str
        Pulse estimator of the C fits.
    """
    from chain.apparatus.lammps_shots import lammps_shots
    from chain.apparatus.shots import shot_time_step, simulate_shots
    from chain.physics.model import uniform_chain

    options = lammps_options(config)
    speeds = options["check_speeds_m_s"]
    material = get_material(config["material"])
    rows = []
    for entry in config["chains"]:
        n_beads, sensors = int(entry["N"]), entry["sensors"]
        for model in config["models"]:
            eta = float(model["eta_s"])
            chain = uniform_chain(n_beads, material, config["radius_m"], eta)
            kernel, _ = simulate_shots(
                chain,
                speeds,
                sensors,
                model_name=model["name"],
                duration=options["duration_s"],
                record_interval=options["record_interval_s"],
            )
            lammps, _ = lammps_shots(
                granular_chain(config, n_beads, eta=eta),
                speeds,
                sensors,
                model_name=model["name"],
                duration=options["duration_s"],
                dt=options["time_step_s"],
                record_interval=options["record_interval_s"],
            )
            row = check_row(kernel, lammps, estimator=estimator, model=model["name"], eta=eta)
            row["dt_kernel_s"] = shot_time_step(chain, speeds, None, options["record_interval_s"])
            row["dt_lammps_s"] = options["time_step_s"]
            rows.append(row)
    return pd.DataFrame(rows, columns=CHECK_COLUMNS)


def run_sweep_setting(
    config: Mapping, n_beads: int, sensors: Sequence[int], name: str, estimator: str
) -> dict[str, pd.DataFrame]:
    """One setting of the friction/rotation sweep on one chain, run and analysed.

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    n_beads : int
        N.
    sensors : sequence of int
        [S1, S2].
    name : str
        A name of :func:`sweep_settings` or :func:`viscous_settings` (full lists); it is
        the traces' ``model``. Viscous settings run on the frictionless track with the
        viscous force instead of Kuwabara-Kono.
    estimator : str
        Pulse estimator.

    Returns
    -------
    dict
        ``traces``, ``runs`` (:func:`chain.apparatus.lammps_shots.lammps_shots`),
        ``delay_fits`` and ``ssw_fits`` (:func:`analyse_traces`).
    """
    from chain.apparatus.lammps_shots import lammps_shots

    options = lammps_options(config)
    viscous = viscous_settings(config, full=True)
    if name in viscous:
        chain = granular_chain(config, n_beads, eta=0.0, track=True, viscous_damping=viscous[name])
    else:
        track_friction, bead_friction = sweep_settings(config, full=True)[name]
        chain = granular_chain(
            config,
            n_beads,
            eta=options["sweep"]["eta_s"],
            track_friction=track_friction,
            bead_friction=bead_friction,
            track=True,
        )
    traces, runs = lammps_shots(
        chain,
        options["sweep"]["launch_speeds_m_s"],
        sensors,
        model_name=name,
        duration=options["duration_s"],
        dt=options["time_step_s"],
        record_interval=options["record_interval_s"],
    )
    delay_fits, ssw_fits = analyse_traces(traces, estimator)
    return {"traces": traces, "runs": runs, "delay_fits": delay_fits, "ssw_fits": ssw_fits}


#: Mechanism name of the candidates' reference row.
REFERENCE_MECHANISM = "reference (virtual experiment as configured)"


def candidate_rows(
    candidates: Mapping[str, tuple[str, str]],
    delay_fits: Mapping[str, pd.DataFrame],
    ssw_fits: Mapping[str, pd.DataFrame],
    reference: str,
) -> pd.DataFrame:
    """Rows of ``ssw_mechanisms.csv`` for the virtual-experiment candidates (ablation
    variants with a ``mechanism``), each against the ``reference`` variant.

    Parameters
    ----------
    candidates : mapping
        Variant name -> (mechanism, setting label); the reference may be absent.
    delay_fits, ssw_fits : mapping
        Variant name -> its ``_fits.csv`` and ``_ssw_fits.csv`` (replicate 0 is used).
    reference : str
        Name of the reference variant (the run's virtual experiment).

    Returns
    -------
    DataFrame
        Columns :data:`MECHANISM_COLUMNS`: the reference first (ratio 1), then every
        candidate in order.
    """

    def first(table: pd.DataFrame, name: str) -> pd.DataFrame:
        if "replicate" in table:
            table = table[table["replicate"] == 0]
        return table.assign(model=name)

    groups = {REFERENCE_MECHANISM: {reference: "as configured"}}
    for name, (mechanism, label) in candidates.items():
        if name != reference:
            groups.setdefault(mechanism, {})[name] = label
    names = [reference, *(n for n in candidates if n != reference)]
    delays = [first(delay_fits[n], n) for n in names]
    ssw = [first(ssw_fits[n], n) for n in names]
    tables = [
        mechanism_rows(mechanism, settings, delays, ssw, reference)
        for mechanism, settings in groups.items()
    ]
    return pd.concat(tables, ignore_index=True)


#: The ablation variant the candidates are compared with (config ``ablation.variants``).
CANDIDATE_REFERENCE = "mechanism_reference"


def candidate_variants(variants: Sequence[Mapping], full: bool) -> dict[str, tuple[str, str]]:
    """Variant name -> (mechanism, setting label) of the candidates of the mechanism
    study: the ablation variants with a ``mechanism`` (those of the default run, or all
    with ``full``), and :data:`CANDIDATE_REFERENCE` first; empty without it.

    Parameters
    ----------
    variants : sequence of mapping
        :func:`chain.pipeline.ablation.ablation_variants`.
    full : bool
        All candidates (target ``mechanisms``) rather than the default run's.
    """
    names = {v["name"] for v in variants}
    if CANDIDATE_REFERENCE not in names:
        return {}
    chosen = {CANDIDATE_REFERENCE: ("", "as configured")}
    for v in variants:
        if v["mechanism"] and (full or v["default_run"]):
            label = "; ".join(f"{k}={x}" for k, x in v["set"].items()) or "none"
            chosen[v["name"]] = (v["mechanism"], label)
    return chosen


def variant_ssw_fits(
    traces: Sequence[pd.DataFrame],
    pulses: pd.DataFrame,
    selection: pd.DataFrame | None,
    estimator: str,
) -> pd.DataFrame:
    """SSW = slope x F_m at S2 (behind LSTW) of an ablation variant's shots
    (:func:`chain.pipeline.ablation.run_variant_shots`), the same shot selection.

    Parameters
    ----------
    traces : sequence of DataFrame
        The trace table of each chain.
    pulses : DataFrame
        Their pulse rows.
    selection : DataFrame or None
        The shot selection; None keeps every shot.
    estimator : str
        Pulse estimator.
    """
    ssw = pd.concat(
        [
            ssw_table(t, pulses[pulses["N"] == t["N"].iloc[0]], selection, estimator=estimator)
            for t in traces
        ],
        ignore_index=True,
    )
    return ssw_fit_table(ssw[ssw["sensor"] == "S2"])
