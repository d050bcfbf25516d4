"""The station model in memory: frozen dataclasses in SI units.

A station is a tree: a root rigid body, beams cantilevered from a body or from another
beam, and bodies that may ride on a beam.  :mod:`microg.models.toml` builds it from a TOML
file (validating units, signs and the tree); :mod:`microg.structure.ritz` and
:mod:`microg.structure.fem`
discretise it into a :class:`~microg.structure.Structure`.

Frame: x along the flight direction, y along the solar boom (orbit normal, pitch axis),
z along the keel (the report's convention; z = 0 at the keel joint, the main body at z < 0).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "PointMass",
    "RigidBody",
    "Beam",
    "NamedPoint",
    "Orbit",
    "Station",
    "POLAR_GYRATION_FRACTION",
]

#: radius of gyration of a beam's cross-section, as a fraction of its length, when the model
#: gives no axial stiffness to derive it from (torsional inertia only; see Beam.polar_mass)
POLAR_GYRATION_FRACTION = 0.02


@dataclass(frozen=True)
class PointMass:
    """A lumped mass with its rotary inertia.

    Attributes
    ----------
    name : str
    mass : float
        kg.
    position : ndarray (3,)
        Station-frame position of its centre, m.  For masses on a beam it lies on the beam.
    inertia : ndarray (3, 3)
        Rotary inertia about its own centre, station axes, kg m^2.
    source : str
        Where the value comes from (``"Table 3"``, ``"fitted to Appendix C-1/C-3"``...).
    fitted : bool
        True when the value was fitted rather than read from a source.
    movable : tuple of (lo, hi) or None
        For the layout optimiser: the range of the coordinate along its carrier (m).
    """

    name: str
    mass: float
    position: np.ndarray
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    source: str = ""
    fitted: bool = False
    movable: tuple[float, float] | None = None


@dataclass(frozen=True)
class RigidBody:
    """A rigid body carrying point masses.

    Attributes
    ----------
    name : str
    masses : tuple of PointMass
    parent : str or None
        None for the root body; otherwise the beam it rides on.
    attach : ndarray (3,) or None
        Station-frame point where it joins its parent beam, m.
    """

    name: str
    masses: tuple[PointMass, ...]
    parent: str | None = None
    attach: np.ndarray | None = None


@dataclass(frozen=True)
class Beam:
    """A straight Euler-Bernoulli beam cantilevered from its parent.

    Attributes
    ----------
    name : str
    parent : str
        Name of the body or beam it is attached to.
    root : ndarray (3,)
        Station-frame position of its root (the attachment point), m.
    direction : ndarray (3,)
        Unit vector from root to tip.
    length : float
        m.
    orientation : ndarray (3,)
        Unit vector of the local y axis, perpendicular to ``direction``; local z = x cross y.
    ei_y, ei_z : float
        Bending stiffness about local y and z, N m^2.
    gj : float
        Torsional stiffness, N m^2.
    ea : float or None
        Axial stiffness, N (None: axially rigid).
    mass_per_length : float
        kg/m, uniform.
    masses : tuple of PointMass
        Point masses on the beam (positions on its axis).
    """

    name: str
    parent: str
    root: np.ndarray
    direction: np.ndarray
    length: float
    orientation: np.ndarray
    ei_y: float
    ei_z: float
    gj: float
    ea: float | None
    mass_per_length: float
    masses: tuple[PointMass, ...] = ()

    @property
    def polar_mass_per_length(self) -> float:
        """Polar mass moment per length rho J of the cross-section, kg m (torsional inertia).

        ``m' (EI_y + EI_z) / EA`` (rho J = m'/A (I_y + I_z) for one material) when ``ea`` is
        given; otherwise a radius of gyration of ``POLAR_GYRATION_FRACTION`` of the length.
        Only torsional frequencies depend on it.
        """
        if self.ea is not None and self.ea > 0:
            return float(self.mass_per_length * (self.ei_y + self.ei_z) / self.ea)
        return float(self.mass_per_length * (POLAR_GYRATION_FRACTION * self.length) ** 2)

    @property
    def local_z(self) -> np.ndarray:
        """Unit vector of the local z axis."""
        return np.cross(self.direction, self.orientation)

    def station_position(self, s: float | np.ndarray) -> np.ndarray:
        """Station-frame position of arc length ``s`` (m) from the root."""
        s = np.asarray(s, float)
        return self.root + s[..., None] * self.direction

    def arc_length(self, position: np.ndarray) -> float:
        """Arc length of the projection of ``position`` on the beam axis, m."""
        return float(np.dot(np.asarray(position, float) - self.root, self.direction))


@dataclass(frozen=True)
class NamedPoint:
    """A point of interest (crew work site, experiment site) on a body or beam.

    Attributes
    ----------
    name : str
    on : str
        Body or beam carrying the point.
    position : ndarray (3,)
        Station-frame position, m.
    kind : str
        ``"crew"``, ``"experiment"`` or ``"point"``.
    description : str
    """

    name: str
    on: str
    position: np.ndarray
    kind: str = "point"
    description: str = ""


@dataclass(frozen=True)
class Orbit:
    """A circular orbit.

    Attributes
    ----------
    radius : float
        Orbit radius from the Earth's centre, m.
    mu : float
        Gravitational parameter, m^3/s^2.
    """

    radius: float
    mu: float = 3.986004418e14

    @property
    def omega0(self) -> float:
        """Orbital rate sqrt(mu/R^3), rad/s (Eq. 2.29)."""
        return float(np.sqrt(self.mu / self.radius**3))


@dataclass(frozen=True)
class Station:
    """A whole station model.

    Attributes
    ----------
    name : str
    bodies : tuple of RigidBody
        The first is the root (reference) body.
    beams : tuple of Beam
        In tree order: every beam's parent precedes it.
    points : tuple of NamedPoint
    orbit : Orbit
    reference_length : float
        Length scale of the rigid-rotation coordinate (the report's keel length l_k), m.
    description : str
    source : str
        File it was read from, if any.
    unit_system : {"SI", "US"} or None
        The file's declared unit system (``units`` in ``[station]``): the unit of a bare
        number given to the API or the CLI for this model (None: SI).
    """

    name: str
    bodies: tuple[RigidBody, ...]
    beams: tuple[Beam, ...]
    points: tuple[NamedPoint, ...]
    orbit: Orbit
    reference_length: float = 1.0
    description: str = ""
    source: str = ""
    unit_system: str | None = None

    def all_masses(self) -> list[PointMass]:
        """Every point mass on bodies and beams."""
        out: list[PointMass] = []
        for b in self.bodies:
            out.extend(b.masses)
        for bm in self.beams:
            out.extend(bm.masses)
        return out

    def component(self, name: str) -> RigidBody | Beam:
        """The body or beam called ``name`` (KeyError if none)."""
        components: tuple[RigidBody | Beam, ...] = (*self.bodies, *self.beams)
        for c in components:
            if c.name == name:
                return c
        raise KeyError(name)

    def point(self, name: str) -> NamedPoint:
        """The named point (KeyError if none)."""
        for p in self.points:
            if p.name == name:
                return p
        raise KeyError(name)

    def mass_properties(self) -> tuple[float, np.ndarray, np.ndarray]:
        """Total mass (kg), centre of mass (m) and inertia tensor about it (kg m^2).

        Beams contribute their distributed mass as slender rods along their axes.
        """
        total = 0.0
        first = np.zeros(3)
        second = np.zeros((3, 3))  # sum m (p p^T)
        local = np.zeros((3, 3))
        for pm in self.all_masses():
            total += pm.mass
            first += pm.mass * pm.position
            second += pm.mass * np.outer(pm.position, pm.position)
            local += pm.inertia
        for bm in self.beams:
            mb = bm.mass_per_length * bm.length
            c = bm.root + 0.5 * bm.length * bm.direction
            total += mb
            first += mb * c
            # slender rod: int rho (r0 + s d)(r0 + s d)^T ds
            second += mb * np.outer(c, c) + mb * bm.length**2 / 12.0 * np.outer(
                bm.direction, bm.direction
            )
        cm = first / total
        second_cm = second - total * np.outer(cm, cm)
        inertia = np.trace(second_cm) * np.eye(3) - second_cm + local
        return total, cm, inertia
