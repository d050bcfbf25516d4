"""Assumed-modes (Rayleigh-Ritz) discretisation of a station (Eqs. 2.1-2.8, Appendices A-B).

The engine is general: a set of generalized coordinates, each with an admissible function
defined on the whole station tree, gives the generalized mass matrix (Eq. 2.5: point masses,
distributed beam mass by Gauss-Legendre quadrature, rotary inertias through the rotation
field psi') and stiffness matrix (Eq. 2.6 by quadrature, plus the gravity-gradient
stiffness of Appendix B-2 on the rigid rotation).

Kinematics.  Every coordinate q_i defines, for each component of the tree (bodies and
beams), the translation ``t_i`` and small rotation ``theta_i`` of the component's root.  A
point ``p`` of a component moves as a rigid extension of its root,
``u_i(p) = t_i + theta_i x (p - root)``, plus, on the beam the coordinate bends, the bending
field ``d psi(s/L)`` with rotation ``(a x d) psi'(s/L)/L`` (a the beam axis, d the bending
direction).  Children inherit the motion of their attachment point.  The seed report's four
functions (Eq. 2.21) are one choice of these coordinates (see :mod:`microg.seed.ioc`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Legendre, Polynomial

from microg.errors import InputError
from microg.models.station import Beam, RigidBody, Station
from microg.structure.fem import check_stiffness_contrast, torsion_is_rigid
from microg.structure.structure import PointMap, Structure

__all__ = [
    "Coordinate",
    "cantilever_functions",
    "report_cantilever_function",
    "planar_coordinates",
    "assemble",
    "build_ritz",
    "spatial_coordinates",
    "clamped_linear_functions",
    "point_maps",
    "sample_points",
    "gravity_gradient_stiffness",
    "PLANES",
    "MAX_FUNCTIONS",
    "MAX_RITZ_BEAMS",
]

#: most admissible functions per beam (polynomials up to degree 17 stay well conditioned)
MAX_FUNCTIONS = 16
#: most beams of an assumed-modes model.  The method is the report's, for a station of a few
#: cantilevered members; its assembly visits every component for every coordinate (measured:
#: 1.1 s at 25 beams, 4.2 s at 50, 228 s at 300), so larger trees go to the frame elements
MAX_RITZ_BEAMS = 40

#: planar analyses of the report: lateral direction, rotation axis (so that a rotation
#: q moves a point at height z by +z q laterally), normal of the plane
PLANES: dict[str, dict[str, np.ndarray]] = {
    "xz": {"lateral": np.array([1.0, 0, 0]), "axis": np.array([0, 1.0, 0])},
    "yz": {"lateral": np.array([0, 1.0, 0]), "axis": np.array([-1.0, 0, 0])},
}


@dataclass(frozen=True)
class Coordinate:
    """One generalized coordinate and its admissible function.

    Attributes
    ----------
    label : str
    kind : str
        ``"translation"`` (unit rigid translation along ``vector``), ``"rotation"`` (rigid
        rotation about ``vector`` through the origin, coordinate = angle x ``scale``), or
        ``"bending"`` (beam ``beam`` bends along ``vector`` with shape ``shape``).
    vector : ndarray (3,)
        Direction (unit).
    beam : str or None
    shape : Polynomial, Legendre or None
        psi(xi), xi = s/L in [0, 1]; psi(0) = psi'(0) = 0 for a cantilever.
    scale : float
        Length scale of a rotation coordinate (the report's l_k: psi_2 = z/l_k), m.
    """

    label: str
    kind: str
    vector: np.ndarray
    beam: str | None = None
    shape: Polynomial | Legendre | None = None
    scale: float = 1.0


def _shape(coord: Coordinate) -> Polynomial | Legendre:
    """The shape function of a beam-deformation coordinate (bending, torsion, axial)."""
    assert coord.shape is not None, f"coordinate {coord.label!r} has no shape function"
    return coord.shape


def report_cantilever_function() -> Polynomial:
    """The report's cantilever function psi = xi^2 - xi^3/3 (Eq. 2.21c-d)."""
    return Polynomial([0.0, 0.0, 1.0, -1.0 / 3.0])


def cantilever_functions(n: int) -> list[Polynomial | Legendre]:
    """``n`` admissible cantilever functions on xi in [0, 1]; the first is the report's.

    Functions 2..n are the twice-integrated shifted Legendre polynomials
    ``psi_k'' = sqrt(2k + 1) P_k(2 xi - 1)`` (k = 1..n-1) with ``psi_k(0) = psi_k'(0) = 0``:
    with the first they span the polynomials xi^2..xi^(n+1) (the same Ritz space as any
    other basis of that span), their curvatures are orthonormal, and the mass matrix stays
    well conditioned (condition ~1e4 at 16 functions, where xi^3 P_k gave 1e15 after
    scaling).  They are evaluated as Legendre series on [0, 1] (Clenshaw), not as
    monomials whose coefficients grow like 4^k.
    """
    funcs: list[Polynomial | Legendre] = [report_cantilever_function()]
    for k in range(1, n):
        leg = Legendre.basis(k, domain=[0.0, 1.0]) * np.sqrt(2.0 * k + 1.0)
        funcs.append(leg.integ(2, lbnd=0.0))
    return funcs


def clamped_linear_functions(n: int) -> list[Polynomial | Legendre]:
    """``n`` admissible functions with f(0) = 0 for torsion and axial motion (xi in [0, 1]).

    ``f_k' = sqrt(2k + 1) P_k(2 xi - 1)``, ``f_k(0) = 0`` (k = 0..n-1): the first is xi
    (uniform twist or stretch: exact for a tip torque or tip force on a uniform member), and
    they span xi..xi^n with orthonormal gradients (well-conditioned mass, diagonal uniform
    stiffness).
    """
    funcs: list[Polynomial | Legendre] = [Polynomial([0.0, 1.0])]
    for k in range(1, n):
        leg = Legendre.basis(k, domain=[0.0, 1.0]) * np.sqrt(2.0 * k + 1.0)
        funcs.append(leg.integ(1, lbnd=0.0))
    return funcs


def spatial_coordinates(
    station: Station, n_functions: int = 1, *, rotation_scale: float | None = None
) -> list[Coordinate]:
    """Three-dimensional assumed-modes coordinates of ``station``.

    Six rigid-body coordinates (translations along x, y, z; rotations about x, y, z through
    the origin, scaled by ``rotation_scale``), and for every beam ``n_functions`` bending
    functions along its local y and z axes, ``n_functions`` torsion functions (unless the
    beam is torsionally rigid: ``gj = 0``, or numerically zero by the rule of
    :data:`~microg.structure.fem.GJ_ZERO_FRACTION`) and ``n_functions`` axial functions
    (only when it has an axial stiffness ``ea``).

    Parameters
    ----------
    station : Station
    n_functions : int
        Functions per beam and per deformation kind (1 to ``MAX_FUNCTIONS``).
    rotation_scale : float, optional
        Length scale of the rotation coordinates, m (default ``station.reference_length``).
    """
    _check_functions(n_functions)
    scale = station.reference_length if rotation_scale is None else rotation_scale
    eye = np.eye(3)
    coords = [Coordinate(f"translation:{a}", "translation", eye[i]) for i, a in enumerate("xyz")]
    coords += [
        Coordinate(f"rotation:{a}", "rotation", eye[i], scale=scale) for i, a in enumerate("xyz")
    ]
    bend = cantilever_functions(n_functions)
    lin = clamped_linear_functions(n_functions)
    for beam in station.beams:
        for tag, d in (("y", beam.orientation), ("z", beam.local_z)):
            for k, f in enumerate(bend):
                coords.append(Coordinate(f"{beam.name}:{tag}{k + 1}", "bending", d, beam.name, f))
        if not torsion_is_rigid(beam):
            for k, f in enumerate(lin):
                coords.append(
                    Coordinate(f"{beam.name}:t{k + 1}", "torsion", beam.direction, beam.name, f)
                )
        if beam.ea is not None:
            for k, f in enumerate(lin):
                coords.append(
                    Coordinate(f"{beam.name}:a{k + 1}", "axial", beam.direction, beam.name, f)
                )
    return coords


def _check_functions(n_functions: int) -> None:
    if not (isinstance(n_functions, int | np.integer) and 1 <= n_functions <= MAX_FUNCTIONS):
        raise InputError(
            f"assumed functions per beam must be an integer from 1 to {MAX_FUNCTIONS}, "
            f"got {n_functions!r}",
            where="n",
            fix="use the finite-element method for finer models",
        )


def _bending_direction(beam: Beam, plane: str) -> np.ndarray:
    """The in-plane direction perpendicular to the beam axis (lateral if the axis is normal)."""
    lateral = PLANES[plane]["lateral"]
    axis = PLANES[plane]["axis"]
    d = np.cross(axis, beam.direction)
    if np.linalg.norm(d) < 1e-9:
        return lateral.copy()
    return d / np.linalg.norm(d)


def planar_coordinates(
    station: Station, plane: str, n_functions: int = 1, *, rotation_scale: float | None = None
) -> list[Coordinate]:
    """Coordinates of the report's planar analysis: translation, rotation, beam bending.

    Parameters
    ----------
    station : Station
    plane : {"xz", "yz"}
    n_functions : int
        Admissible functions per beam (1 reproduces the report).
    rotation_scale : float, optional
        Length scale of the rotation coordinate, m (default ``station.reference_length``).
    """
    _check_functions(n_functions)
    spec = PLANES[plane]
    scale = station.reference_length if rotation_scale is None else rotation_scale
    coords = [
        Coordinate("translation", "translation", spec["lateral"]),
        Coordinate("rotation", "rotation", spec["axis"], scale=scale),
    ]
    funcs = cantilever_functions(n_functions)
    for beam in station.beams:
        d = _bending_direction(beam, plane)
        for k, f in enumerate(funcs):
            coords.append(Coordinate(f"{beam.name}:{k + 1}", "bending", d, beam.name, f))
    return coords


def _children(station: Station) -> dict[str, list[Beam | RigidBody]]:
    components: tuple[Beam | RigidBody, ...] = (*station.bodies, *station.beams)
    kids: dict[str, list[Beam | RigidBody]] = {c.name: [] for c in components}
    for beam in station.beams:
        kids[beam.parent].append(beam)
    for body in station.bodies[1:]:
        if body.parent is not None:
            kids[body.parent].append(body)
    return kids


def _root_point(comp: Beam | RigidBody) -> np.ndarray:
    if isinstance(comp, Beam):
        return comp.root
    return comp.attach if comp.attach is not None else np.zeros(3)


def _root_motion(
    station: Station, coord: Coordinate
) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """For each component: (root point, root translation, root rotation) per unit q."""
    root = station.bodies[0]
    if coord.kind == "translation":
        t0, th0 = coord.vector.astype(float), np.zeros(3)
    elif coord.kind == "rotation":
        t0, th0 = np.zeros(3), coord.vector / coord.scale
    else:
        t0, th0 = np.zeros(3), np.zeros(3)
    origin = np.zeros(3)
    out: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    kids = _children(station)

    def visit(comp: Beam | RigidBody, point: np.ndarray, t: np.ndarray, th: np.ndarray) -> None:
        rp = _root_point(comp)
        t_root = t + np.cross(th, rp - point)
        out[comp.name] = (rp, t_root, th)
        for child in kids[comp.name]:
            cp = _root_point(child)
            t_c = t_root + np.cross(th, cp - rp)
            th_c = th.copy()
            if isinstance(comp, Beam) and coord.beam == comp.name:
                s = np.array([comp.arc_length(cp)])
                dt, dr = _own_motion(comp, coord, s, (cp - comp.station_position(s))[None, :])
                t_c = t_c + dt[0]
                th_c = th_c + dr[0]
            visit(child, cp, t_c, th_c)

    visit(root, origin, t0, th0)
    return out


def _own_motion(
    beam: Beam, coord: Coordinate, s: np.ndarray, offset: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Translation and rotation (p, 3) from the beam's own deformation coordinate.

    Bending along ``d``: ``w = d psi(s/L)``, rotation ``(a x d) psi'(s/L)/L``; torsion:
    rotation ``a phi(s/L)``; axial: ``a chi(s/L)``.  ``offset`` (p, 3) is each point's
    distance from the axis point at ``s`` (zero for points on the axis): the cross-section
    moves rigidly.
    """
    xi = np.asarray(s, float) / beam.length
    a = beam.direction
    p = xi.size
    t = np.zeros((p, 3))
    r = np.zeros((p, 3))
    if coord.kind == "bending":
        shape = _shape(coord)
        t = np.multiply.outer(shape(xi), coord.vector)
        slope = shape.deriv()(xi) / beam.length
        r = np.multiply.outer(slope, np.cross(a, coord.vector))
    elif coord.kind == "torsion":
        r = np.multiply.outer(_shape(coord)(xi), a)
    elif coord.kind == "axial":
        t = np.multiply.outer(_shape(coord)(xi), a)
    return t + np.cross(r, offset), r


def _field(
    station: Station,
    coords: Sequence[Coordinate],
    comp_name: str,
    positions: np.ndarray,
    motions: list[dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]],
) -> tuple[np.ndarray, np.ndarray]:
    """Translation and rotation maps (p, 3, n) of points of one component."""
    comp = station.component(comp_name)
    p = positions.shape[0]
    n = len(coords)
    tr = np.zeros((p, 3, n))
    rot = np.zeros((p, 3, n))
    for i, c in enumerate(coords):
        rp, t, th = motions[i][comp_name]
        tr[:, :, i] = t + np.cross(th, positions - rp)
        rot[:, :, i] = th
        if c.beam == comp_name and isinstance(comp, Beam):
            s = (positions - comp.root) @ comp.direction
            dt, dr = _own_motion(comp, c, s, positions - comp.station_position(s))
            tr[:, :, i] += dt
            rot[:, :, i] += dr
    return tr, rot


def gravity_gradient_stiffness(omega0: float, inertia_cm: np.ndarray, axis: np.ndarray) -> float:
    """Gravity-gradient restoring stiffness of a rigid rotation (Appendix B-2), N m / rad.

    Pitch about y: ``3 w0^2 (I_x - I_z)`` (Eq. 2.28); roll about x: ``3 w0^2 (I_y - I_z)``
    (Eq. 2.27, the report's form); yaw about z: 0.

    Parameters
    ----------
    omega0 : float
        Orbital rate, rad/s.
    inertia_cm : ndarray (3, 3)
        Station inertia about its centre of mass, kg m^2.
    axis : ndarray (3,)
        Rotation axis (a station axis, either sign).
    """
    ix, iy, iz = np.diag(inertia_cm)
    a = np.abs(np.asarray(axis, float))
    return float(3.0 * omega0**2 * (a[1] * (ix - iz) + a[0] * (iy - iz)))


def assemble(
    station: Station,
    coords: Sequence[Coordinate],
    *,
    gravity_gradient: bool = True,
    quadrature_points: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Generalized mass (Eq. 2.5) and stiffness (Eq. 2.6 + Appendix B-2) matrices, SI.

    Parameters
    ----------
    station : Station
    coords : sequence of Coordinate
    gravity_gradient : bool
        Add ``k = 3 w0^2 (I_a - I_b) / scale^2`` on each rotation coordinate (Appendix B-2
        with the 1/l_k^2 factor the coordinate q = theta l_k needs).
    quadrature_points : int, optional
        Gauss-Legendre points per beam (exact for polynomials of degree < 2 x this); by
        default enough for the products of the highest-degree functions, exactly.

    Returns
    -------
    mass, stiffness : ndarray (n, n)
    """
    n = len(coords)
    motions = [_root_motion(station, c) for c in coords]
    mass = np.zeros((n, n))
    stiff = np.zeros((n, n))
    if quadrature_points is None:
        degree = max((c.shape.degree() for c in coords if c.shape is not None), default=3)
        quadrature_points = max(8, degree + 2)  # 2 x points - 1 >= 2 x degree: exact
    xg, wg = np.polynomial.legendre.leggauss(quadrature_points)
    xg = 0.5 * (xg + 1.0)
    wg = 0.5 * wg
    comps: list[tuple[str, tuple]] = [(b.name, b.masses) for b in station.bodies]
    comps += [(b.name, b.masses) for b in station.beams]
    for name, masses in comps:
        if not masses:
            continue
        pos = np.array([m.position for m in masses])
        mvec = np.array([m.mass for m in masses])
        inertia = np.array([m.inertia for m in masses])
        tr, rot = _field(station, coords, name, pos, motions)
        mass += np.einsum("p,pai,paj->ij", mvec, tr, tr)
        mass += np.einsum("pai,pab,pbj->ij", rot, inertia, rot)
    for beam in station.beams:
        s = xg * beam.length
        pos = beam.station_position(s)
        if beam.mass_per_length > 0:
            tr, rot = _field(station, coords, beam.name, pos, motions)
            w = wg * beam.length * beam.mass_per_length
            mass += np.einsum("p,pai,paj->ij", w, tr, tr)
            # torsional inertia of the cross-sections (rho J about the beam axis)
            twist = np.einsum("pai,a->pi", rot, beam.direction)
            wj = wg * beam.length * beam.polar_mass_per_length
            mass += np.einsum("p,pi,pj->ij", wj, twist, twist)
        # bending strain energy: curvature of each coordinate on this beam
        idx = [i for i, c in enumerate(coords) if c.kind == "bending" and c.beam == beam.name]
        if idx:
            ey, ez = beam.orientation, beam.local_z
            curv = np.array([_shape(coords[i]).deriv(2)(xg) / beam.length**2 for i in idx])
            dirs = np.array([coords[i].vector for i in idx])
            # bending along local y is resisted by EI_z, along local z by EI_y
            eimat = (dirs @ ey)[:, None] * (dirs @ ey)[None, :] * beam.ei_z + (dirs @ ez)[
                :, None
            ] * (dirs @ ez)[None, :] * beam.ei_y
            kk = eimat * np.einsum("p,ip,jp->ij", wg * beam.length, curv, curv)
            stiff[np.ix_(idx, idx)] += kk
        for kind, rigidity in (("torsion", beam.gj), ("axial", beam.ea or 0.0)):
            idx = [i for i, c in enumerate(coords) if c.kind == kind and c.beam == beam.name]
            if idx:
                grad = np.array([_shape(coords[i]).deriv()(xg) / beam.length for i in idx])
                stiff[np.ix_(idx, idx)] += rigidity * np.einsum(
                    "p,ip,jp->ij", wg * beam.length, grad, grad
                )
    if gravity_gradient:
        _, _, inertia_cm = station.mass_properties()
        for i, c in enumerate(coords):
            if c.kind == "rotation":
                stiff[i, i] += (
                    gravity_gradient_stiffness(station.orbit.omega0, inertia_cm, c.vector)
                    / c.scale**2
                )
    return 0.5 * (mass + mass.T), 0.5 * (stiff + stiff.T)


def point_maps(station: Station, coords: Sequence[Coordinate]) -> dict[str, PointMap]:
    """Maps (3, n) from coordinates to the translation and rotation of every named point."""
    motions = [_root_motion(station, c) for c in coords]
    out = {}
    for pt in station.points:
        tr, rot = _field(station, coords, pt.on, pt.position[None, :], motions)
        out[pt.name] = PointMap(pt.name, pt.position, tr[0], rot[0])
    return out


@dataclass(frozen=True)
class RitzSamples:
    """Points sampled along the structure with their maps (for location maps and plots).

    Attributes
    ----------
    position : ndarray (p, 3)
        m.
    translation : ndarray (p, 3, n)
    rotation : ndarray (p, 3, n)
    component : ndarray (p,) of str
        Carrier of each sample.
    """

    position: np.ndarray
    translation: np.ndarray
    rotation: np.ndarray
    component: np.ndarray


def sample_points(
    station: Station, coords: Sequence[Coordinate], per_beam: int = 41
) -> RitzSamples:
    """Sample every beam at ``per_beam`` points and every body at its masses' positions."""
    motions = [_root_motion(station, c) for c in coords]
    pos_all, tr_all, rot_all, comp_all = [], [], [], []
    for body in station.bodies:
        if not body.masses:
            continue
        z = np.array([m.position for m in body.masses])
        # a line through the body's mass positions along the keel axis, for plots
        pos = np.unique(z, axis=0)
        tr, rot = _field(station, coords, body.name, pos, motions)
        pos_all.append(pos)
        tr_all.append(tr)
        rot_all.append(rot)
        comp_all += [body.name] * len(pos)
    for beam in station.beams:
        s = np.linspace(0.0, beam.length, per_beam)
        pos = beam.station_position(s)
        tr, rot = _field(station, coords, beam.name, pos, motions)
        pos_all.append(pos)
        tr_all.append(tr)
        rot_all.append(rot)
        comp_all += [beam.name] * len(pos)
    return RitzSamples(
        np.concatenate(pos_all),
        np.concatenate(tr_all),
        np.concatenate(rot_all),
        np.array(comp_all),
    )


def _rigid_vectors(coords: Sequence[Coordinate], center: np.ndarray) -> dict[str, np.ndarray]:
    """Unit rigid translations, and unit rotations about ``center`` (the centre of mass).

    A rotation coordinate turns the station about the origin; the rotation about the centre
    of mass adds the translation ``-(a x c)`` (projected on the model's translation
    coordinates: a planar model has only its lateral one).  Exact combinations of
    coordinates, independent of where the model sits in its frame.
    """
    n = len(coords)
    rigid: dict[str, np.ndarray] = {}
    trans = [(i, c.vector) for i, c in enumerate(coords) if c.kind == "translation"]
    for i, vec in trans:
        v = np.zeros(n)
        v[i] = 1.0
        rigid["xyz"[int(np.argmax(np.abs(vec)))]] = v * np.sign(vec.sum())
    for i, c in enumerate(coords):
        if c.kind == "rotation":
            axis = int(np.argmax(np.abs(c.vector)))
            sign = np.sign(c.vector[axis])
            v = np.zeros(n)
            v[i] = c.scale * sign
            shift = -np.cross(c.vector * sign, np.asarray(center, float))
            for j, t in trans:
                v[j] = float(shift @ t)
            rigid["r" + "xyz"[axis]] = v
    return rigid


def build_ritz(
    station: Station,
    plane: str | None = "xz",
    n_functions: int = 1,
    *,
    gravity_gradient: bool = True,
    coords: Sequence[Coordinate] | None = None,
) -> Structure:
    """Assumed-modes structure of ``station`` in a plane of the report.

    Parameters
    ----------
    station : Station
    plane : {"xz", "yz"} or None
        The report's planar analysis, or None for the three-dimensional model
        (:func:`spatial_coordinates`: bending both ways, torsion, axial where elastic).
    n_functions : int
        Admissible functions per beam (and per deformation kind in 3-D).
    gravity_gradient : bool
        Include the gravity-gradient stiffness on the rotation coordinates.
    coords : sequence of Coordinate, optional
        Custom coordinates (overrides ``plane``/``n_functions``).
    """
    if len(station.beams) > MAX_RITZ_BEAMS:
        raise InputError(
            f"the assumed-modes model takes at most {MAX_RITZ_BEAMS} beams, this station has "
            f"{len(station.beams)}",
            where="method",
            fix="use the frame finite elements (method fem)",
        )
    check_stiffness_contrast(station)
    if coords is not None:
        coords = list(coords)
    elif plane is None:
        coords = spatial_coordinates(station, n_functions)
    else:
        coords = planar_coordinates(station, plane, n_functions)
    mass, stiff = assemble(station, coords, gravity_gradient=gravity_gradient)
    total, cm, inertia = station.mass_properties()
    rigid = _rigid_vectors(coords, cm)
    return Structure(
        mass=mass,
        stiffness=stiff,
        dof_labels=tuple(c.label for c in coords),
        points=point_maps(station, coords),
        rigid_body=rigid,
        method="ritz",
        plane=plane,
        total_mass=total,
        center_of_mass=cm,
        inertia_cm=inertia,
        samples=sample_points(station, coords),
        meta={"model": station.name, "n_functions": n_functions, "coordinates": coords},
    )
