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

from dataclasses import dataclass, field

import numpy as np

from chain.errors import ParameterError, check_bead_numbers, require_positive
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
    :func:`~chain.physics.builders.build_chain` or
    :func:`~chain.physics.builders.uniform_chain` rather than directly.

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
