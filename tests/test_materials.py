"""Materials and geometry: the paper's compliance theta, Hertz stiffness kappa, bead mass."""

from __future__ import annotations

import math

import pytest

from chain import (
    MATERIALS,
    STEEL_100C6,
    Material,
    ParameterError,
    contact_stiffness,
    get_material,
    sphere_mass,
)
from chain.physics.materials import BRASS


def test_theta_is_the_papers_compliance(steel, tol):
    """theta = 3 (1 - nu^2) / (4 Y) (paper, Sec. II)."""
    expected = 3.0 * (1.0 - 0.3**2) / (4.0 * 203e9)
    assert steel.theta == pytest.approx(expected, rel=tol.roundoff)


def test_paper_material_values(steel):
    """100C6 steel as in Sec. III: rho = 7780 kg/m^3, Y = 203 GPa, nu = 0.3."""
    assert (steel.density, steel.youngs_modulus, steel.poisson_ratio) == (7780.0, 203e9, 0.3)


def test_contact_stiffness_two_equal_spheres(steel, radius, kappa, tol):
    """kappa^-1 = (theta + theta') (1/R + 1/R')^(1/2) gives 1 / (2 theta sqrt(2/R))."""
    expected = 1.0 / (2.0 * steel.theta * math.sqrt(2.0 / radius))
    assert kappa == pytest.approx(expected, rel=tol.roundoff)
    assert kappa == pytest.approx(1.2e10, rel=0.01)  # order of magnitude, N/m^(3/2)


def test_contact_stiffness_is_symmetric_and_general(steel, tol):
    """kappa of two different spheres is the paper's formula and symmetric in the pair."""
    forward = contact_stiffness(steel, 13e-3, BRASS, 4e-3)
    backward = contact_stiffness(BRASS, 4e-3, steel, 13e-3)
    expected = 1.0 / ((steel.theta + BRASS.theta) * math.sqrt(1 / 13e-3 + 1 / 4e-3))
    assert forward == pytest.approx(expected, rel=tol.roundoff)
    assert backward == pytest.approx(forward, rel=tol.roundoff)


def test_flat_wall_is_stiffer_by_sqrt2(steel, radius, kappa, wall_kappa, tol):
    """A flat (R' = inf) halves the curvature sum, so kappa_wall = sqrt(2) kappa_sphere."""
    assert wall_kappa / kappa == pytest.approx(math.sqrt(2.0), rel=tol.roundoff)


def test_sphere_mass(steel, radius, bead_mass, tol):
    """m = (4/3) pi R^3 rho (about 71.6 g for the paper's beads)."""
    assert bead_mass == pytest.approx(4 / 3 * math.pi * radius**3 * 7780.0, rel=tol.roundoff)
    assert bead_mass == pytest.approx(0.0716, rel=1e-3)


def test_get_material_by_name():
    """Every registered material is found under its own name."""
    for name, material in MATERIALS.items():
        assert get_material(name) is material
    assert get_material("steel_100C6") is STEEL_100C6


def test_get_material_unknown_lists_known_names():
    """An unknown name raises and the message lists the known materials."""
    with pytest.raises(ParameterError, match="material: unknown material 'unobtainium'") as info:
        get_material("unobtainium")
    for name in MATERIALS:
        assert name in str(info.value)


@pytest.mark.parametrize(
    ("kwargs", "parameter"),
    [
        ({"density": 0.0}, "density"),
        ({"density": -7780.0}, "density"),
        ({"density": math.nan}, "density"),
        ({"youngs_modulus": 0.0}, "youngs_modulus"),
        ({"youngs_modulus": -1e9}, "youngs_modulus"),
        ({"poisson_ratio": 0.5}, "poisson_ratio"),
        ({"poisson_ratio": 0.7}, "poisson_ratio"),
        ({"poisson_ratio": -1.0}, "poisson_ratio"),
        ({"poisson_ratio": -1.5}, "poisson_ratio"),
    ],
)
def test_material_rejects_unphysical_values(kwargs, parameter):
    """Density and Young's modulus must be > 0, nu in (-1, 0.5); the error names which."""
    values = {"name": "test", "density": 7780.0, "youngs_modulus": 203e9, "poisson_ratio": 0.3}
    values.update(kwargs)
    with pytest.raises(ParameterError, match=parameter):
        Material(**values)


@pytest.mark.parametrize("bad", [0.0, -13e-3, math.inf, math.nan])
def test_contact_stiffness_rejects_bad_radius(steel, bad):
    """A non-positive (or non-finite) first radius is rejected by name."""
    with pytest.raises(ParameterError, match="radius_a"):
        contact_stiffness(steel, bad, steel, 13e-3)


@pytest.mark.parametrize("bad", [0.0, -13e-3])
def test_contact_stiffness_rejects_bad_second_radius(steel, bad):
    """A non-positive second radius is rejected by name (math.inf means a flat wall)."""
    with pytest.raises(ParameterError, match="radius_b"):
        contact_stiffness(steel, 13e-3, steel, bad)


@pytest.mark.parametrize("bad", [0.0, -1e-3])
def test_sphere_mass_rejects_bad_radius(steel, bad):
    """A non-positive radius is rejected by name."""
    with pytest.raises(ParameterError, match="radius"):
        sphere_mass(steel, bad)
