"""Bead materials, sphere geometry and the Hertz contact stiffness.

All quantities are SI: density in kg/m^3, Young's modulus in Pa, radius in m,
contact stiffness kappa in N/m^(3/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from chain.errors import ParameterError, require_positive


@dataclass(frozen=True)
class Material:
    """An isotropic elastic bead material.

    Parameters
    ----------
    name : str
        Label used in configs, tables and figure legends.
    density : float
        Mass density rho, kg/m^3.
    youngs_modulus : float
        Young's modulus Y, Pa.
    poisson_ratio : float
        Poisson ratio nu, dimensionless, in (-1, 0.5).
    source : str
        Where the values come from (datasheet, paper).
    """

    name: str
    density: float
    youngs_modulus: float
    poisson_ratio: float
    source: str = ""

    def __post_init__(self) -> None:
        require_positive(f"{self.name}: density", self.density)
        require_positive(f"{self.name}: youngs_modulus", self.youngs_modulus)
        nu = self.poisson_ratio
        if not (isinstance(nu, int | float) and -1.0 < nu < 0.5):
            raise ParameterError(f"{self.name}: poisson_ratio must lie in (-1, 0.5), got {nu!r}")

    @property
    def theta(self) -> float:
        """Elastic compliance theta = 3 (1 - nu^2) / (4 Y), in 1/Pa (paper, Sec. II)."""
        return 3.0 * (1.0 - self.poisson_ratio**2) / (4.0 * self.youngs_modulus)


#: The paper's beads: 100C6 bearing steel (Sec. III).
STEEL_100C6 = Material(
    name="steel_100C6",
    density=7780.0,
    youngs_modulus=203e9,
    poisson_ratio=0.3,
    source="Santibanez et al., Sec. III (100C6 roll-bearing steel)",
)

#: Free-cutting brass CW614N (CuZn39Pb3), for what-if runs.
BRASS = Material(
    name="brass",
    density=8470.0,
    youngs_modulus=97e9,
    poisson_ratio=0.31,
    source="CW614N (CuZn39Pb3) datasheet values: rho 8.47 g/cm^3, E 97 GPa, nu 0.31",
)

#: Stainless steel 316, for what-if runs.
STAINLESS_316 = Material(
    name="stainless_316",
    density=8000.0,
    youngs_modulus=193e9,
    poisson_ratio=0.29,
    source="AISI 316 datasheet values: rho 8.00 g/cm^3, E 193 GPa, nu 0.29",
)

#: Materials selectable by name in configs.
MATERIALS: dict[str, Material] = {m.name: m for m in (STEEL_100C6, BRASS, STAINLESS_316)}


def get_material(name: str) -> Material:
    """Look up a material by name; the error lists the known names."""
    try:
        return MATERIALS[name]
    except KeyError:
        known = ", ".join(sorted(MATERIALS))
        raise ParameterError(f"material: unknown material {name!r}; known: {known}") from None


def sphere_mass(material: Material, radius: float) -> float:
    """Mass of a solid sphere, kg.

    Parameters
    ----------
    material : Material
        Bead material (density in kg/m^3).
    radius : float
        Sphere radius, m.
    """
    radius = require_positive("radius", radius)
    return 4.0 / 3.0 * math.pi * radius**3 * material.density


def contact_stiffness(
    material_a: Material, radius_a: float, material_b: Material, radius_b: float = math.inf
) -> float:
    """Hertz contact stiffness kappa between two spheres (or a sphere and a flat), N/m^(3/2).

    The paper's form: kappa^-1 = (theta + theta') (1/R + 1/R')^(1/2), so that the
    contact force is F = kappa delta^(3/2) for an overlap delta.

    Parameters
    ----------
    material_a, material_b : Material
        Materials of the two bodies.
    radius_a : float
        Radius of curvature of the first body at the contact, m.
    radius_b : float
        Radius of curvature of the second body, m; ``math.inf`` for a flat wall.
    """
    radius_a = require_positive("radius_a", radius_a)
    if radius_b != math.inf:
        radius_b = require_positive("radius_b", radius_b)
    curvature = 1.0 / radius_a + (0.0 if radius_b == math.inf else 1.0 / radius_b)
    return 1.0 / ((material_a.theta + material_b.theta) * math.sqrt(curvature))
