"""Building a :class:`~chain.physics.model.ChainModel`: any beads (:func:`build_chain`)
or the paper's N equal beads (:func:`uniform_chain`), with sensor beads, strikers, walls."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from chain.errors import (
    ParameterError,
    check_bead_numbers,
    require_int,
    require_nonnegative,
    require_positive,
)
from chain.physics.materials import STEEL_100C6, Material, contact_stiffness, sphere_mass
from chain.physics.model import (
    HERTZ,
    PAPER_BEAD_RADIUS,
    PCB_200B02_STIFFNESS,
    SPRING,
    ChainModel,
    Striker,
)


def build_chain(
    bead_masses: Sequence[float],
    contact_stiffnesses: Sequence[float],
    *,
    eta: float | Sequence[float] = 0.0,
    left_wall_stiffness: float = 0.0,
    right_wall_stiffness: float = 0.0,
    sensor_beads: Sequence[int] = (),
    sensor_stiffness: float = PCB_200B02_STIFFNESS,
    left_striker: Striker | None = None,
    right_striker: Striker | None = None,
    drag_rate: float = 0.0,
) -> ChainModel:
    """A chain of N beads with any masses and contact stiffnesses.

    Parameters
    ----------
    bead_masses : sequence of N floats
        Mass of beads 1..N, kg (N >= 2).
    contact_stiffnesses : sequence of N-1 floats
        kappa of contact k between beads k and k+1, N/m^(3/2).
    eta : float or sequence of N-1 floats
        Kuwabara-Kono relaxation time per contact, s (0: elastic). Walls and strikers
        use the first value.
    left_wall_stiffness, right_wall_stiffness : float
        kappa of a rigid wall touching bead 1 / bead N, N/m^(3/2); 0 for a free end.
    sensor_beads : sequence of int
        Beads (1..N) cut in two halves of mass m/2 joined by a linear spring.
    sensor_stiffness : float
        Stiffness k_s of the sensor spring, N/m (PCB 200B02: 1.9e9).
    left_striker, right_striker : Striker or None
        An extra particle touching bead 1 (left) or bead N (right).
    drag_rate : float
        Linear track friction rate gamma, 1/s: every particle feels -m gamma v.
    """
    masses, stiffness, etas, sensors = _check_chain_inputs(
        bead_masses,
        contact_stiffnesses,
        eta,
        sensor_beads,
        sensor_stiffness,
        walls=(left_wall_stiffness, right_wall_stiffness),
        strikers=(left_striker, right_striker),
        drag_rate=drag_rate,
    )
    parts = _Particles()
    left_index = -1
    if left_striker is not None:
        left_index = parts.add_particle(left_striker.mass)
        parts.add_link(HERTZ, left_striker.contact_stiffness, etas[0])
    for number in range(1, len(masses) + 1):
        if number > 1:
            parts.contact_link.append(
                parts.add_link(HERTZ, stiffness[number - 2], etas[number - 2])
            )
        parts.add_bead(masses[number - 1], sensor_stiffness if number in sensors else None)
    right_index = -1
    if right_striker is not None:
        parts.add_link(HERTZ, right_striker.contact_stiffness, etas[-1])
        right_index = parts.add_particle(right_striker.mass)
    n_particles = len(parts.mass)
    return ChainModel(
        masses=np.array(parts.mass),
        link_kind=np.array(parts.link_kind, dtype=np.int64),
        link_stiffness=np.array(parts.link_stiffness),
        link_eta=np.array(parts.link_eta),
        wall_stiffness=np.array([left_wall_stiffness, right_wall_stiffness], dtype=float),
        wall_eta=np.array([etas[0], etas[-1]], dtype=float),
        drag_rate=np.full(n_particles, float(drag_rate)),
        bead_first=np.array(parts.bead_first, dtype=np.int64),
        bead_last=np.array(parts.bead_last, dtype=np.int64),
        contact_link=np.array(parts.contact_link, dtype=np.int64),
        sensor_beads=tuple(sorted(sensors)),
        sensor_link=np.array([parts.sensor_link[b] for b in sorted(sensors)], dtype=np.int64),
        left_striker=left_index,
        right_striker=right_index,
    )


def _check_chain_inputs(
    bead_masses,
    contact_stiffnesses,
    eta,
    sensor_beads,
    sensor_stiffness,
    *,
    walls: tuple[float, float],
    strikers: tuple[Striker | None, Striker | None],
    drag_rate: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, ...]]:
    """The inputs of :func:`build_chain` checked, as (masses kg, contact stiffnesses
    N/m^(3/2), eta per contact s, sensor beads); raises :class:`ParameterError` naming
    the first bad one."""
    masses = np.asarray(bead_masses, dtype=float)
    if masses.ndim != 1 or len(masses) < 2:
        raise ParameterError(f"bead_masses must list N >= 2 masses, got {len(masses)}")
    n_beads = len(masses)
    for number, mass in enumerate(masses, start=1):
        require_positive(f"bead_masses[bead {number}]", mass)
    stiffness = np.asarray(contact_stiffnesses, dtype=float)
    if stiffness.shape != (n_beads - 1,):
        raise ParameterError(
            f"contact_stiffnesses must have N-1 = {n_beads - 1} values, got {stiffness.size}"
        )
    for number, kappa in enumerate(stiffness, start=1):
        require_positive(f"contact_stiffnesses[contact {number}]", kappa)
    etas = np.broadcast_to(np.asarray(eta, dtype=float), (n_beads - 1,)).copy()
    for number, value in enumerate(etas, start=1):
        require_nonnegative(f"eta[contact {number}]", value)
    for side, wall, striker in zip(("left", "right"), walls, strikers):
        require_nonnegative(f"{side}_wall_stiffness", wall)
        if striker is not None and wall > 0:
            raise ParameterError(f"{side}_striker: cannot combine a striker with a {side} wall")
    require_nonnegative("drag_rate", drag_rate)
    # Sensor beads may come in any order here (the model sorts them); S1-first order is
    # a property of a recording, checked where sensors are read.
    sensors = tuple(sensor_beads)
    if sensors:
        sensors = check_bead_numbers("sensor_beads", sensors, n_beads, increasing=False)
        require_positive("sensor_stiffness", sensor_stiffness)
    return masses, stiffness, etas, sensors


class _Particles:
    """The particle and link lists of a chain as :func:`build_chain` lays them out,
    left to right."""

    def __init__(self) -> None:
        self.mass: list[float] = []
        self.link_kind: list[int] = []
        self.link_stiffness: list[float] = []
        self.link_eta: list[float] = []
        self.bead_first: list[int] = []
        self.bead_last: list[int] = []
        self.contact_link: list[int] = []
        self.sensor_link: dict[int, int] = {}

    def add_particle(self, mass: float) -> int:
        """Append a particle of ``mass`` (kg); its index."""
        self.mass.append(mass)
        return len(self.mass) - 1

    def add_link(self, kind: int, value: float, relaxation: float) -> int:
        """Append a link (HERTZ or SPRING, stiffness, eta s) to the right; its index."""
        self.link_kind.append(kind)
        self.link_stiffness.append(value)
        self.link_eta.append(relaxation)
        return len(self.link_kind) - 1

    def add_bead(self, mass: float, sensor_stiffness: float | None) -> None:
        """Append the next bead: one particle, or two halves joined by a spring of
        ``sensor_stiffness`` (N/m) for a sensor bead."""
        number = len(self.bead_first) + 1
        self.bead_first.append(len(self.mass))
        if sensor_stiffness is None:
            self.add_particle(mass)
        else:
            self.add_particle(mass / 2.0)
            self.add_particle(mass / 2.0)
            self.sensor_link[number] = self.add_link(SPRING, float(sensor_stiffness), 0.0)
        self.bead_last.append(len(self.mass) - 1)


def uniform_chain(
    n_beads: int,
    material: Material = STEEL_100C6,
    radius: float = PAPER_BEAD_RADIUS,
    eta: float = 0.0,
    *,
    left_wall: bool = False,
    right_wall: bool = False,
    sensor_beads: Sequence[int] = (),
    sensor_stiffness: float = PCB_200B02_STIFFNESS,
    striker_radius: float | None = None,
    strikers: str = "both",
    drag_rate: float = 0.0,
) -> ChainModel:
    """N equal beads, as in the paper; free ends unless walls are asked for.

    Parameters
    ----------
    n_beads : int
        Number of beads N >= 2.
    material : Material
        Bead material (default: the paper's 100C6 steel).
    radius : float
        Bead radius, m (default 13 mm).
    eta : float
        Kuwabara-Kono relaxation time, s (paper: 0.58e-6; 0 for Eq. 1).
    left_wall, right_wall : bool
        Put a rigid flat wall of the same material against bead 1 / bead N.
    sensor_beads : sequence of int
        Beads (1..N) modelled as split sensor beads.
    sensor_stiffness : float
        Sensor spring stiffness, N/m.
    striker_radius : float or None
        Radius of spherical strikers of the same material, m (paper: 4e-3); None for none.
    strikers : {"both", "left", "right"}
        Which ends get a striker when ``striker_radius`` is given.
    drag_rate : float
        Linear track friction rate, 1/s.
    """
    require_int("n_beads", n_beads, 2)
    radius = require_positive("radius", radius)
    if strikers not in ("both", "left", "right"):
        raise ParameterError(f"strikers must be 'both', 'left' or 'right', got {strikers!r}")
    mass = sphere_mass(material, radius)
    kappa = contact_stiffness(material, radius, material, radius)
    wall_kappa = contact_stiffness(material, radius, material, math.inf)
    left_striker = right_striker = None
    if striker_radius is not None:
        # Named here: Striker.sphere's own check would call it "radius", the beads' name.
        striker_radius = require_positive("striker_radius", striker_radius)
        striker = Striker.sphere(striker_radius, material, radius, material)
        left_striker = striker if strikers in ("both", "left") else None
        right_striker = striker if strikers in ("both", "right") else None
    return build_chain(
        np.full(n_beads, mass),
        np.full(n_beads - 1, kappa),
        eta=eta,
        left_wall_stiffness=wall_kappa if left_wall else 0.0,
        right_wall_stiffness=wall_kappa if right_wall else 0.0,
        sensor_beads=sensor_beads,
        sensor_stiffness=sensor_stiffness,
        left_striker=left_striker,
        right_striker=right_striker,
        drag_rate=drag_rate,
    )


__all__ = ["build_chain", "uniform_chain"]
