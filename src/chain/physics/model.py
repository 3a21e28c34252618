"""The chain model of Eq. 1: particles on a line joined by contacts.

A :class:`ChainModel` is a flat list of particles (beads, half-beads of sensor beads,
strikers) with one link between each neighbouring pair:

* a **Hertz contact**, F = kappa delta^(3/2) + (3/2) eta kappa delta^(1/2) d(delta)/dt
  while delta > 0 (Kuwabara-Kono dissipation, relaxation time eta). The total force is
  clipped at zero: a contact never pulls, so when the viscous term would make the force
  tensile during unloading the beads simply separate. With eta = 0 this is Eq. 1.
* a **bonded linear spring**, F = k delta, which joins the two halves of a sensor bead
  (a bead cut in two with a piezo stack between, read as k times its compression).

Optional rigid walls add a Hertz contact between an end particle and a fixed flat.
Beads are numbered 1..N as in the paper; contact k joins beads k and k+1.
Displacements u are positive to the right and the overlap of a link is
delta = u_left - u_right (positive in compression).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from chain.errors import (
    ParameterError,
    check_bead_numbers,
    require_int,
    require_nonnegative,
    require_positive,
)
from chain.physics.materials import STEEL_100C6, Material, contact_stiffness, sphere_mass

#: Link kinds.
HERTZ = 0
SPRING = 1

#: Stiffness of the PCB 200B02 force sensor embedded in a split bead, N/m (1.9 kN/um).
PCB_200B02_STIFFNESS = 1.9e9

#: Radius of the paper's strikers, m.
PAPER_STRIKER_RADIUS = 4e-3

#: Radius of the paper's beads, m.
PAPER_BEAD_RADIUS = 13e-3


@dataclass(frozen=True)
class Striker:
    """An extra particle touching an end bead at t = 0 (the paper's small dropped sphere).

    Parameters
    ----------
    mass : float
        Striker mass, kg.
    contact_stiffness : float
        Hertz stiffness of the striker-bead contact, N/m^(3/2).
    """

    mass: float
    contact_stiffness: float

    def __post_init__(self) -> None:
        require_positive("striker mass", self.mass)
        require_positive("striker contact_stiffness", self.contact_stiffness)

    @classmethod
    def sphere(
        cls,
        radius: float = PAPER_STRIKER_RADIUS,
        material: Material = STEEL_100C6,
        bead_radius: float = PAPER_BEAD_RADIUS,
        bead_material: Material = STEEL_100C6,
    ) -> Striker:
        """A spherical striker of ``radius`` (m) against a bead of ``bead_radius`` (m)."""
        return cls(
            mass=sphere_mass(material, radius),
            contact_stiffness=contact_stiffness(material, radius, bead_material, bead_radius),
        )


@dataclass(frozen=True, eq=False)
class ChainModel:
    """Particles and links of a chain, ready for the integrator. Build with
    :func:`build_chain` or :func:`uniform_chain` rather than directly.

    Attributes (arrays indexed by particle p = 0..P-1 or link j = 0..P-2, link j
    joining particles j and j+1)
    ----------
    masses : (P,) kg
    link_kind : (P-1,) HERTZ or SPRING
    link_stiffness : (P-1,) N/m^(3/2) for Hertz links, N/m for springs
    link_eta : (P-1,) s, Kuwabara-Kono relaxation time (Hertz links only)
    wall_stiffness : (2,) N/m^(3/2), left and right wall contacts; 0 means a free end
    wall_eta : (2,) s
    drag_rate : (P,) 1/s, linear track friction F = -m * drag_rate * v
    bead_first, bead_last : (N,) first and last particle of bead n (index n-1)
    contact_link : (N-1,) link index of contact k (index k-1)
    sensor_beads : bead numbers (1-based) that are split sensor beads
    sensor_link : (n_sensors,) link index of each sensor spring
    left_striker, right_striker : particle index of each striker, or -1
    """

    masses: np.ndarray
    link_kind: np.ndarray
    link_stiffness: np.ndarray
    link_eta: np.ndarray
    wall_stiffness: np.ndarray
    wall_eta: np.ndarray
    drag_rate: np.ndarray
    bead_first: np.ndarray
    bead_last: np.ndarray
    contact_link: np.ndarray
    sensor_beads: tuple[int, ...] = ()
    sensor_link: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    left_striker: int = -1
    right_striker: int = -1

    @property
    def n_beads(self) -> int:
        """Number of beads N (a split sensor bead counts once)."""
        return len(self.bead_first)

    @property
    def n_particles(self) -> int:
        """Number of integrated particles (beads, sensor halves, strikers)."""
        return len(self.masses)

    @property
    def bead_masses(self) -> np.ndarray:
        """Mass of each bead 1..N, kg (both halves of a sensor bead)."""
        return np.array(
            [self.masses[a : b + 1].sum() for a, b in zip(self.bead_first, self.bead_last)]
        )

    @property
    def is_conservative(self) -> bool:
        """True when no dissipation acts (eta = 0 everywhere, no drag)."""
        return not (np.any(self.link_eta > 0) or np.any(self.wall_eta > 0)) and not np.any(
            self.drag_rate > 0
        )

    def bead_index(self, bead: int) -> int:
        """Zero-based array index of ``bead`` (1..N); raises naming the bead otherwise."""
        (number,) = check_bead_numbers("bead", [bead], self.n_beads)
        return number - 1


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


def launch_velocities(model: ChainModel, v_left, v_right=0.0) -> np.ndarray:
    """Initial particle velocities for a batch of launches, m/s, shape (B, P).

    The left launcher (striker if present, else bead 1) moves right at ``v_left``;
    the right launcher (striker, else bead N) moves left at ``v_right``. The paper's
    simulation uses +V0 on bead 1 and -V0 on bead N (a collision) or V0 on bead 1 alone
    (the reference wave).

    Parameters
    ----------
    model : ChainModel
        The chain.
    v_left, v_right : float or array of B floats
        Launch speeds, m/s (non-negative; broadcast against each other).
    """
    left, right = np.broadcast_arrays(
        np.atleast_1d(np.asarray(v_left, dtype=float)),
        np.atleast_1d(np.asarray(v_right, dtype=float)),
    )
    if not np.isfinite(left).all() or (left < 0).any():
        raise ParameterError(f"v_left must be finite and >= 0 m/s, got {v_left!r}")
    if not np.isfinite(right).all() or (right < 0).any():
        raise ParameterError(f"v_right must be finite and >= 0 m/s, got {v_right!r}")
    velocities = np.zeros((len(left), model.n_particles))
    if model.left_striker >= 0:
        velocities[:, model.left_striker] = left
    else:
        velocities[:, model.bead_first[0] : model.bead_last[0] + 1] = left[:, None]
    if model.right_striker >= 0:
        velocities[:, model.right_striker] = -right
    else:
        velocities[:, model.bead_first[-1] : model.bead_last[-1] + 1] = -right[:, None]
    return velocities
