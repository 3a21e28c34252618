"""The mechanism study's settings: which friction/rotation and viscous
settings the LAMMPS sweep runs, their names, the LAMMPS chain of a setting, and which
ablation variants of the virtual experiment are its candidates.

The sweep puts the beads on a floor track under gravity with track friction mu_t and
bead-bead friction mu_b (rotation, rolling and twisting resistance), or replaces
Kuwabara-Kono by a viscous inter-bead force; the frictionless (0, 0) setting is the
reference. This module maps the config's ``lammps`` section (schema-valid, defaults
filled in) and knows no Snakemake; it runs nothing (the chain is built, not run).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from chain.physics.lammps_engine import GranularChain
from chain.physics.materials import get_material
from chain.studies.ablation_table import overrides_text


def setting_name(track_friction: float, bead_friction: float) -> str:
    """File-safe name of a (mu_t, mu_b) setting, e.g. ``mut030-mub010``."""
    return f"mut{round(100 * track_friction):03d}-mub{round(100 * bead_friction):03d}"


def setting_label(track_friction: float, bead_friction: float) -> str:
    """Human label of a (mu_t, mu_b) setting."""
    return f"mu_t={track_friction:g}, mu_b={bead_friction:g}"


def sweep_settings(config: Mapping, full: bool) -> dict[str, tuple[float, float]]:
    """Name -> (mu_t, mu_b) of the sweep: the default run's pairs (``full`` False), or
    those and the whole grid; the frictionless (0, 0) first, always.

    Parameters
    ----------
    config : mapping
        A schema-valid config (``lammps.sweep`` is read).
    full : bool
        The whole mu_t x mu_b grid too (target ``mechanisms``).
    """
    sweep = config["lammps"]["sweep"]
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
    with ``full``, those and the full list.

    Parameters
    ----------
    config : mapping
        A schema-valid config (``lammps.sweep`` is read).
    full : bool
        The full list too (target ``mechanisms``).
    """
    sweep = config["lammps"]["sweep"]
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
        gravity=float(config["lammps"]["sweep"]["gravity_m_s2"]),
        viscous_damping=float(viscous_damping),
    )


#: The ablation variant the candidates are compared with (config ``ablation.variants``).
CANDIDATE_REFERENCE = "mechanism_reference"


def candidate_variants(variants: Sequence[Mapping], full: bool) -> dict[str, tuple[str, str]]:
    """Variant name -> (mechanism, setting label) of the candidates of the mechanism
    study: the ablation variants with a ``mechanism`` (those of the default run, or all
    with ``full``), and :data:`CANDIDATE_REFERENCE` first; empty without it.

    Parameters
    ----------
    variants : sequence of mapping
        :func:`chain.pipeline.config.ablation.ablation_variants`.
    full : bool
        All candidates (target ``mechanisms``) rather than the default run's.
    """
    names = {v["name"] for v in variants}
    if CANDIDATE_REFERENCE not in names:
        return {}
    chosen = {CANDIDATE_REFERENCE: ("", "as configured")}
    for v in variants:
        if v["mechanism"] and (full or v["default_run"]):
            chosen[v["name"]] = (v["mechanism"], overrides_text(v))
    return chosen
