"""Frame element kernels: local stiffness and mass matrices, rotations, rigid links.

Pure functions of SI arrays, vectorised over elements.  Local DOF order per node
``(u, v, w, theta_x, theta_y, theta_z)``, node a then node b (:data:`DOF_NAMES`); the
assembly (:mod:`microg.structure.assembly`) rotates them to the basic frame.

* **Beams** (NASTRAN CBAR/CBEAM).  Timoshenko stiffness: the cubic element with the shear
  parameter ``phi = 12 EI / (k G A L^2)`` per plane (Przemieniecki, *Theory of Matrix
  Structural Analysis*, Eq. 5.115 with shear, sec. 5.6), exact for a uniform beam under end
  loads; ``phi = 0`` (no shear stiffness given) is the Euler-Bernoulli element.  Mass:

  - ``"lumped"`` (NASTRAN's default): half of ``m' L`` on each end's three translations;
    a ``"beam"`` (CBEAM) also lumps half of the polar moment ``rho J L`` on each end's axial
    rotation, a ``"bar"`` (CBAR) does not.  No rotational inertia otherwise (so the bending
    rotations carry no mass; see condensation below).  This reproduces Simcenter Nastran's
    grid-point weight table and eigenvalues of the ``beam_modes`` fixture to its printed
    digits (``tests/validation/test_nastran_beam_modes.py``).
  - ``"consistent"`` (microg's own, the default of graph and station models): the consistent
    mass of the shear-deformable element, translational and rotary inertia (Przemieniecki
    Eq. 11.41; Friedman & Kosmatka, *Computers & Structures* 47 (1993) 473, interdependent
    interpolation), torsion ``rho J L / 6 [[2, 1], [1, 2]]``.  At ``phi = 0`` without rotary
    inertia it is :func:`frame_mass_local`.
  - ``"coupled"`` and ``"coupled-nx9"`` (NASTRAN ``PARAM,COUPMASS`` > 0, CBAR only;
    :func:`bar_mass_coupled_local`): the translational part of the consistent mass and **no**
    torsional inertia; ``"coupled"`` (Simcenter Nastran 2020.2) also leaves out the coupling
    ``-3 m' L^3 / 420`` between the two ends' bending rotations, ``"coupled-nx9"`` (NX Nastran
    9.1, 2014) keeps it.  Both were identified from the runs' own output on the same bulk data
    (their weight checks and fixed-boundary eigenvalues agree with these forms to their printed
    digits, ``tests/validation/test_nastran_bar_mass.py``); no vendor document describing either
    was found.  A CBEAM under COUPMASS keeps ``"consistent"`` (no NASTRAN run to check it).

  Offsets (CBAR WA/WB) are rigid links from the node to the beam end; pin flags release end
  components by static condensation of the element (its mass by the same transformation).
  A section with ``I12 != 0`` is bent about its principal axes.
* **Rods** (CROD/CONROD): axial ``EA/L`` and torsion ``GJ/L``; mass lumped (``m' L/2`` on each
  end's translations) or consistent (linear in all three translations, NASTRAN's coupled
  rod mass).
* **Springs** (CBUSH): a 6x6 stiffness and viscous damping in the spring axes at the spring's
  point, each node carried there rigidly: the element is then free of rigid-body forces
  wherever the point is.  **Scalar springs** (CELAS): ``k (e_b - e_a)(e_b - e_a)^T`` on the
  two components along the nodes' axes.
* **Concentrated masses** (CONM2): :func:`point_mass_matrix` (offset and
  full inertia tensor).
* **Interpolation** (RBE3) kernel: :func:`interpolation_matrix`, the weighted least-squares
  rigid-body fit of the independent components (eliminated by :mod:`microg.structure.links`).
"""

from __future__ import annotations

import numpy as np

from microg.errors import InputError

__all__ = [
    "BAR_COUPLED_FORMS",
    "DOF_NAMES",
    "INTERPOLATION_COND_MAX",
    "bar_mass_coupled_local",
    "beam_mass_consistent_local",
    "beam_mass_lumped_local",
    "beam_stiffness_local",
    "bush_matrix",
    "frame_mass_local",
    "frame_rotation",
    "frame_stiffness_local",
    "interpolation_matrix",
    "point_mass_matrix",
    "release_ends",
    "rigid_link",
    "rod_mass_local",
    "rod_stiffness_local",
    "shear_parameter",
    "skew",
]

#: NASTRAN's coupled CBAR mass (PARAM,COUPMASS > 0) as each release forms it, by the name of
#: the mass formulation: whether the two ends' bending rotations are coupled
BAR_COUPLED_FORMS = {"coupled": False, "coupled-nx9": True}
#: coordinate names of a node, in order
DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")
#: an RBE3 whose normal matrix has a condition number above this is singular
INTERPOLATION_COND_MAX = 1e12


def frame_stiffness_local(
    length: np.ndarray, ea: np.ndarray, ei_y: np.ndarray, ei_z: np.ndarray, gj: np.ndarray
) -> np.ndarray:
    """Stiffness matrices of 3-D Euler-Bernoulli frame elements in local axes.

    Local DOF order per node ``(u, v, w, theta_x, theta_y, theta_z)``, node a then node b;
    ``theta_z = dv/dx`` and ``theta_y = -dw/dx`` (Przemieniecki, *Theory of Matrix
    Structural Analysis*, Eq. 5.115).

    Parameters
    ----------
    length : ndarray (ne,)
        Element lengths, m.
    ea : ndarray (ne,)
        Axial stiffness, N.
    ei_y, ei_z : ndarray (ne,)
        Bending stiffness about local y (deflection w) and local z (deflection v), N m^2.
    gj : ndarray (ne,)
        Torsional stiffness, N m^2.

    Returns
    -------
    ndarray (ne, 12, 12)
        N/m, N, N m per unit DOF.
    """
    L = np.asarray(length, float)
    k = np.zeros((L.size, 12, 12))
    _put2(k, (0, 6), np.asarray(ea, float) / L)
    _put2(k, (3, 9), np.asarray(gj, float) / L)
    _put4(k, (1, 5, 7, 11), np.asarray(ei_z, float) / L**3, _bend_k(L, +1.0))
    _put4(k, (2, 4, 8, 10), np.asarray(ei_y, float) / L**3, _bend_k(L, -1.0))
    return k


def frame_mass_local(
    length: np.ndarray, mass_per_length: np.ndarray, polar_mass_per_length: np.ndarray
) -> np.ndarray:
    """Consistent mass matrices of 3-D frame elements in local axes.

    Translational mass from the same cubic (bending) and linear (axial) shape functions as
    :func:`frame_stiffness_local`; torsional mass ``rho J L / 6 [[2, 1], [1, 2]]``.

    Parameters
    ----------
    length : ndarray (ne,)
        Element lengths, m.
    mass_per_length : ndarray (ne,)
        ``rho A``, kg/m.
    polar_mass_per_length : ndarray (ne,)
        ``rho J``, polar mass moment per length about the axis, kg m.

    Returns
    -------
    ndarray (ne, 12, 12)
        kg, kg m, kg m^2 per unit DOF.
    """
    L = np.asarray(length, float)
    m = np.zeros((L.size, 12, 12))
    mL = np.asarray(mass_per_length, float) * L
    _put2(m, (0, 6), mL / 6.0, mass=True)
    _put2(m, (3, 9), np.asarray(polar_mass_per_length, float) * L / 6.0, mass=True)
    _put4(m, (1, 5, 7, 11), mL / 420.0, _bend_m(L, +1.0))
    _put4(m, (2, 4, 8, 10), mL / 420.0, _bend_m(L, -1.0))
    return m


def frame_rotation(direction: np.ndarray, orientation: np.ndarray) -> np.ndarray:
    """Rotation matrices from station to element axes (rows: local x, y, z).

    Parameters
    ----------
    direction : ndarray (ne, 3)
        Unit vectors along the elements (local x).
    orientation : ndarray (ne, 3)
        Local y axes (made exactly perpendicular to ``direction`` here).

    Returns
    -------
    ndarray (ne, 3, 3)
        ``R`` with ``v_local = R @ v_station``.
    """
    ex = np.asarray(direction, float)
    ex = ex / np.linalg.norm(ex, axis=-1, keepdims=True)
    ey = np.asarray(orientation, float)
    ey = ey - np.sum(ey * ex, axis=-1, keepdims=True) * ex
    ey = ey / np.linalg.norm(ey, axis=-1, keepdims=True)
    ez = np.cross(ex, ey)
    return np.stack([ex, ey, ez], axis=-2)


def rigid_link(offset: np.ndarray) -> np.ndarray:
    """Rigid-link matrices: slave-node DOFs from master-node DOFs.

    ``u_s = u_m + theta_m x d`` and ``theta_s = theta_m`` with ``d = x_s - x_m``.

    Parameters
    ----------
    offset : ndarray (..., 3)
        Slave position minus master position, m.

    Returns
    -------
    ndarray (..., 6, 6)
    """
    d = np.asarray(offset, float)
    t = np.zeros((*d.shape[:-1], 6, 6))
    t[..., range(6), range(6)] = 1.0
    t[..., :3, 3:] = -skew(d)
    return t


def point_mass_matrix(mass: np.ndarray, inertia: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """6x6 mass matrices of point masses rigidly attached to a node.

    Parameters
    ----------
    mass : ndarray (p,)
        kg.
    inertia : ndarray (p, 3, 3)
        Rotary inertia about each mass's own centre, station axes, kg m^2.
    offset : ndarray (p, 3)
        Mass centre minus node position, m.

    Returns
    -------
    ndarray (p, 6, 6)
        ``T^T diag(m I, J) T`` with ``T`` the rigid link (mass, m [d]x coupling and the
        parallel-axis inertia ``J + m (|d|^2 I - d d^T)``).
    """
    m = np.asarray(mass, float)
    local = np.zeros((m.size, 6, 6))
    local[:, range(3), range(3)] = m[:, None]
    local[:, 3:, 3:] = np.asarray(inertia, float)
    t = rigid_link(offset)
    return np.swapaxes(t, -1, -2) @ local @ t


def skew(d: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[d]x`` with ``[d]x v = d x v``.

    Parameters
    ----------
    d : ndarray (..., 3)
        Vectors (any unit).
    """
    d = np.asarray(d, float)
    s = np.zeros((*d.shape[:-1], 3, 3))
    s[..., 0, 1], s[..., 0, 2] = -d[..., 2], d[..., 1]
    s[..., 1, 0], s[..., 1, 2] = d[..., 2], -d[..., 0]
    s[..., 2, 0], s[..., 2, 1] = -d[..., 1], d[..., 0]
    return s


def _put2(a: np.ndarray, idx: tuple[int, int], c: np.ndarray, *, mass: bool = False) -> None:
    i, j = idx
    diag, off = (2.0, 1.0) if mass else (1.0, -1.0)
    a[:, i, i] += diag * c
    a[:, j, j] += diag * c
    a[:, i, j] += off * c
    a[:, j, i] += off * c


def _put4(a: np.ndarray, idx: tuple[int, ...], c: np.ndarray, block: np.ndarray) -> None:
    ix = np.asarray(idx)
    a[:, ix[:, None], ix[None, :]] += c[:, None, None] * block


def _bend_k(L: np.ndarray, sign: float) -> np.ndarray:
    """Hermite bending stiffness pattern (times EI/L^3); sign -1 for the x-z plane."""
    s = sign
    one = np.ones_like(L)
    return np.stack(
        [
            np.stack([12 * one, 6 * s * L, -12 * one, 6 * s * L], -1),
            np.stack([6 * s * L, 4 * L**2, -6 * s * L, 2 * L**2], -1),
            np.stack([-12 * one, -6 * s * L, 12 * one, -6 * s * L], -1),
            np.stack([6 * s * L, 2 * L**2, -6 * s * L, 4 * L**2], -1),
        ],
        -2,
    )


def _bend_m(L: np.ndarray, sign: float) -> np.ndarray:
    """Hermite consistent-mass pattern (times rho A L / 420); sign -1 for the x-z plane."""
    s = sign
    one = np.ones_like(L)
    return np.stack(
        [
            np.stack([156 * one, 22 * s * L, 54 * one, -13 * s * L], -1),
            np.stack([22 * s * L, 4 * L**2, 13 * s * L, -3 * L**2], -1),
            np.stack([54 * one, 13 * s * L, 156 * one, -22 * s * L], -1),
            np.stack([-13 * s * L, -3 * L**2, -22 * s * L, 4 * L**2], -1),
        ],
        -2,
    )


def shear_parameter(length: np.ndarray, ei: np.ndarray, shear: np.ndarray | None) -> np.ndarray:
    """Timoshenko shear parameter ``phi = 12 EI / (k G A L^2)`` (0 without shear flexibility).

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    ei : ndarray (ne,)
        Bending stiffness of the plane, N m^2.
    shear : ndarray (ne,) or None
        Shear stiffness ``k G A`` of the same plane, N; ``inf`` or None: rigid in shear.
    """
    L = np.asarray(length, float)
    if shear is None:
        return np.zeros_like(L)
    ks = np.asarray(shear, float)
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(ks), 12.0 * np.asarray(ei, float) / (ks * L**2), 0.0)


def beam_stiffness_local(
    length: np.ndarray,
    ea: np.ndarray,
    ei_y: np.ndarray,
    ei_z: np.ndarray,
    gj: np.ndarray,
    phi_v: np.ndarray | None = None,
    phi_w: np.ndarray | None = None,
) -> np.ndarray:
    """Stiffness of shear-deformable (Timoshenko) 3-D beam elements in local axes.

    DOF order and signs of :func:`frame_stiffness_local`.  Per bending
    plane, with ``phi`` the shear parameter (:func:`shear_parameter`),
    ``EI/((1+phi) L^3) [[12, 6L, -12, 6L], [6L, (4+phi)L^2, -6L, (2-phi)L^2], ...]``
    (Przemieniecki sec. 5.6): the Euler-Bernoulli element with ``EI/(1+phi)`` plus
    ``EI phi/((1+phi) L) [[1, -1], [-1, 1]]`` on the two rotations.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    ea, gj : ndarray (ne,)
        N, N m^2.
    ei_y, ei_z : ndarray (ne,)
        About local y (deflection w) and local z (deflection v), N m^2.
    phi_v, phi_w : ndarray (ne,), optional
        Shear parameters of the v (x-y) and w (x-z) planes; 0 (Euler-Bernoulli) by default.

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    pv = np.zeros_like(L) if phi_v is None else np.asarray(phi_v, float)
    pw = np.zeros_like(L) if phi_w is None else np.asarray(phi_w, float)
    eiy = np.asarray(ei_y, float)
    eiz = np.asarray(ei_z, float)
    k = frame_stiffness_local(L, ea, eiy / (1.0 + pw), eiz / (1.0 + pv), gj)
    for (i, j), c in (
        ((5, 11), eiz * pv / (L * (1.0 + pv))),
        ((4, 10), eiy * pw / (L * (1.0 + pw))),
    ):
        k[:, i, i] += c
        k[:, j, j] += c
        k[:, i, j] -= c
        k[:, j, i] -= c
    return k


def _plane_mass(
    L: np.ndarray, m: np.ndarray, r: np.ndarray, phi: np.ndarray, s: float
) -> np.ndarray:
    """4x4 consistent mass (v, theta, v, theta) of one bending plane; s = -1 for x-z."""
    p = phi
    d = (1.0 + p) ** 2
    t11 = 13 / 35 + 7 * p / 10 + p**2 / 3
    t12 = (11 / 210 + 11 * p / 120 + p**2 / 24) * L
    t13 = 9 / 70 + 3 * p / 10 + p**2 / 6
    t14 = -(13 / 420 + 3 * p / 40 + p**2 / 24) * L
    t22 = (1 / 105 + p / 60 + p**2 / 120) * L**2
    t24 = -(1 / 140 + p / 60 + p**2 / 120) * L**2
    r11 = np.full_like(L, 6 / 5)
    r12 = (1 / 10 - p / 2) * L
    r22 = (2 / 15 + p / 6 + p**2 / 3) * L**2
    r24 = (-1 / 30 - p / 6 + p**2 / 6) * L**2
    trans = np.stack(
        [
            np.stack([t11, t12, t13, t14], -1),
            np.stack([t12, t22, -t14, t24], -1),
            np.stack([t13, -t14, t11, -t12], -1),
            np.stack([t14, t24, -t12, t22], -1),
        ],
        -2,
    )
    rot = np.stack(
        [
            np.stack([r11, r12, -r11, r12], -1),
            np.stack([r12, r22, -r12, r24], -1),
            np.stack([-r11, -r12, r11, -r12], -1),
            np.stack([r12, r24, -r12, r22], -1),
        ],
        -2,
    )
    out = (m * L / d)[:, None, None] * trans + (r / (L * d))[:, None, None] * rot
    sign = np.array([1.0, s, 1.0, s])
    return out * sign[:, None] * sign[None, :]


def beam_mass_consistent_local(
    length: np.ndarray,
    mass_per_length: np.ndarray,
    polar_mass: np.ndarray,
    phi_v: np.ndarray | None = None,
    phi_w: np.ndarray | None = None,
    rotary_y: np.ndarray | None = None,
    rotary_z: np.ndarray | None = None,
) -> np.ndarray:
    """Consistent mass of shear-deformable 3-D beam elements in local axes.

    Per bending plane, the shape functions of the Timoshenko element with shear parameter
    ``phi`` (Friedman & Kosmatka 1993): translational inertia ``m' L/(1+phi)^2 [...]`` and
    rotary inertia ``rho I/((1+phi)^2 L) [...]`` (Przemieniecki Eq. 11.41).  Axial
    ``m' L/6 [[2, 1], [1, 2]]``, torsion ``rho J L/6 [[2, 1], [1, 2]]``.  With ``phi = 0`` and
    no rotary inertia this is :func:`frame_mass_local`.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        ``m' = rho A``, kg/m.
    polar_mass : ndarray (ne,)
        ``rho J`` per length, kg m.
    phi_v, phi_w : ndarray (ne,), optional
        Shear parameters of the v (x-y) and w (x-z) planes.
    rotary_y, rotary_z : ndarray (ne,), optional
        Rotary inertia per length of rotation about local y (w plane) and z (v plane), kg m.

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    zero = np.zeros_like(L)
    m = np.asarray(mass_per_length, float) * np.ones_like(L)
    out = frame_mass_local(L, m, polar_mass)
    pv = zero if phi_v is None else np.asarray(phi_v, float)
    pw = zero if phi_w is None else np.asarray(phi_w, float)
    ry = zero if rotary_y is None else np.asarray(rotary_y, float)
    rz = zero if rotary_z is None else np.asarray(rotary_z, float)
    for idx, phi, rot, s in (((1, 5, 7, 11), pv, rz, 1.0), ((2, 4, 8, 10), pw, ry, -1.0)):
        ix = np.asarray(idx)
        e = np.flatnonzero((phi != 0) | (rot != 0))  # the others are the fem kernel's exactly
        if e.size:
            out[e[:, None, None], ix[None, :, None], ix[None, None, :]] = _plane_mass(
                L[e], m[e], rot[e], phi[e], s
            )
    return out


def bar_mass_coupled_local(
    length: np.ndarray,
    mass_per_length: np.ndarray,
    phi_v: np.ndarray | None = None,
    phi_w: np.ndarray | None = None,
    *,
    end_rotation_coupling: bool = False,
) -> np.ndarray:
    """NASTRAN's coupled (``PARAM,COUPMASS``) mass of CBAR elements in local axes.

    The translational inertia of :func:`beam_mass_consistent_local` (axial
    ``m' L/6 [[2, 1], [1, 2]]``; per bending plane the cubic element's, with ``phi`` its
    Timoshenko form) and no torsional or rotary inertia.  Without ``end_rotation_coupling``
    (Simcenter Nastran 2020.2) the terms between the two ends' bending rotations,
    ``-3 m' L^3 / 420`` at ``phi = 0``, are zero: the element's rigid-body inertia about its
    centre is then ``m' L^3 / 12 + m' L^3 / 70`` across the axis (the weight check of that
    release) instead of the exact ``m' L^3 / 12`` (NX Nastran 9.1, ``end_rotation_coupling``).
    Both forms are fitted to the runs' printed output (weight check and eigenvalues to 7
    digits); the shear terms (``phi != 0``) have no NASTRAN run behind them.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        ``m'``, kg/m.
    phi_v, phi_w : ndarray (ne,), optional
        Shear parameters of the v (x-y) and w (x-z) planes (:func:`shear_parameter`).
    end_rotation_coupling : bool
        Keep the coupling of the two ends' bending rotations (NX Nastran 9.1).

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    out = beam_mass_consistent_local(L, mass_per_length, np.zeros_like(L), phi_v, phi_w)
    if not end_rotation_coupling:
        for a, b in ((5, 11), (4, 10)):
            out[:, a, b] = out[:, b, a] = 0.0
    return out


def beam_mass_lumped_local(
    length: np.ndarray, mass_per_length: np.ndarray, polar_mass: np.ndarray, torsion: np.ndarray
) -> np.ndarray:
    """Lumped (diagonal) mass of 3-D beam elements, NASTRAN's default.

    Half the element's mass ``m' L`` on each end's three translations; where ``torsion`` is
    true (CBEAM), half its polar moment ``rho J L`` on each end's axial rotation too.  No
    rotational inertia otherwise.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        kg/m.
    polar_mass : ndarray (ne,)
        kg m.
    torsion : ndarray (ne,) of bool
        Lump the polar moment (CBEAM) or not (CBAR).

    Returns
    -------
    ndarray (ne, 12, 12)
    """
    L = np.asarray(length, float)
    half = 0.5 * np.asarray(mass_per_length, float) * L
    m = np.zeros((L.size, 12, 12))
    for i in (0, 1, 2, 6, 7, 8):
        m[:, i, i] = half
    tor = np.where(np.asarray(torsion, bool), 0.5 * np.asarray(polar_mass, float) * L, 0.0)
    m[:, 3, 3] = tor
    m[:, 9, 9] = tor
    return m


def rod_stiffness_local(length: np.ndarray, ea: np.ndarray, gj: np.ndarray) -> np.ndarray:
    """Rod elements (CROD): ``EA/L`` axially and ``GJ/L`` in torsion, local axes (ne, 12, 12)."""
    L = np.asarray(length, float)
    zero = np.zeros_like(L)
    return frame_stiffness_local(L, ea, zero, zero, gj)


def rod_mass_local(length: np.ndarray, mass_per_length: np.ndarray, lumped: bool) -> np.ndarray:
    """Rod mass: lumped ``m' L/2`` per end translation, or consistent (linear) in x, y and z.

    Parameters
    ----------
    length : ndarray (ne,)
        m.
    mass_per_length : ndarray (ne,)
        kg/m.
    lumped : bool

    Returns
    -------
    ndarray (ne, 12, 12)
        The consistent form is ``m' L/6 [[2, 1], [1, 2]]`` on each translation pair.
    """
    L = np.asarray(length, float)
    mL = np.asarray(mass_per_length, float) * L
    m = np.zeros((L.size, 12, 12))
    for i in range(3):
        if lumped:
            m[:, i, i] = m[:, i + 6, i + 6] = mL / 2.0
        else:
            m[:, i, i] = m[:, i + 6, i + 6] = mL / 3.0
            m[:, i, i + 6] = m[:, i + 6, i] = mL / 6.0
    return m


def release_ends(
    stiffness: np.ndarray, mass: np.ndarray, released: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Release element DOFs (pin flags) by static condensation of each element.

    ``u_r = -K_rr^+ K_rk u_k`` (pseudo-inverse: a component released at both ends leaves
    no stiffness there); ``K' = T^T K T`` and ``M' = T^T M T`` with ``T`` that map, and the
    released rows and columns zero.

    Parameters
    ----------
    stiffness, mass : ndarray (ne, 12, 12)
        Local matrices.
    released : ndarray (ne, 12) of bool

    Returns
    -------
    stiffness, mass : ndarray (ne, 12, 12)
    """
    k = np.array(stiffness, float)
    m = np.array(mass, float)
    rel = np.asarray(released, bool)
    for e in np.flatnonzero(rel.any(axis=1)):
        r = np.flatnonzero(rel[e])
        keep = np.flatnonzero(~rel[e])
        t = np.zeros((12, keep.size))
        t[keep, np.arange(keep.size)] = 1.0
        t[r] = -np.linalg.pinv(k[e][np.ix_(r, r)]) @ k[e][np.ix_(r, keep)]
        kk = t.T @ k[e] @ t
        mm = t.T @ m[e] @ t
        k[e] = 0.0
        m[e] = 0.0
        k[e][np.ix_(keep, keep)] = 0.5 * (kk + kk.T)
        m[e][np.ix_(keep, keep)] = 0.5 * (mm + mm.T)
    return k, m


def bush_matrix(
    matrix6: np.ndarray,
    axes: np.ndarray,
    node_a: np.ndarray,
    node_b: np.ndarray | None,
    location: np.ndarray,
) -> np.ndarray:
    """12x12 (6x6 grounded) basic-frame matrix of a CBUSH-like spring at ``location``.

    The relative motion at the spring point is ``d = L_b u_b - L_a u_a`` with ``L`` the
    rigid links from each node to the point (:func:`rigid_link`);
    ``K_e = G^T R6^T k R6 G`` with ``G = [-L_a, L_b]`` and ``R6 = diag(R, R)`` the spring axes.

    Parameters
    ----------
    matrix6 : ndarray (6, 6)
        Stiffness (or damping) in the spring axes.
    axes : ndarray (3, 3)
        Rows: spring x, y, z in the basic frame.
    node_a, node_b : ndarray (3,)
        Node positions, m (node_b None: grounded).
    location : ndarray (3,)
        Spring point, m.
    """
    r6 = np.zeros((6, 6))
    r6[:3, :3] = r6[3:, 3:] = np.asarray(axes, float)
    kb = r6.T @ np.asarray(matrix6, float) @ r6
    la = rigid_link(np.asarray(location, float) - np.asarray(node_a, float))
    if node_b is None:
        g = -la
    else:
        lb = rigid_link(np.asarray(location, float) - np.asarray(node_b, float))
        g = np.concatenate([-la, lb], axis=1)
    out = g.T @ kb @ g
    return 0.5 * (out + out.T)


def interpolation_matrix(
    reference: np.ndarray,
    positions: np.ndarray,
    directions: np.ndarray,
    weights: np.ndarray,
    *,
    rotational: np.ndarray | None = None,
    length_m: float | None = None,
    where: str = "interpolation",
) -> np.ndarray:
    """RBE3: the reference point's 6 DOFs from independent components (NASTRAN's fit).

    The reference motion ``q`` (translation and rotation at ``reference``) minimises
    ``sum_k w_k (S_k q - s_k)^2`` over the independent components ``s_k``: a translation
    component ``s_k = e_k . u_k`` has ``S_k = [e_k, d_k x e_k]`` (``e_k . (q_t + q_r x d_k)``,
    ``d_k`` the source position minus the reference), a rotation component
    ``s_k = e_k . theta_k`` has ``S_k = [0, e_k]`` and its weight multiplied by ``L_c^2``, the
    square of the mean distance from the reference to the independent grids (MSC/NX Quick
    Reference Guide, RBE3 remarks; pyyeti's ``n2p.formrbe3``, checked there against NX 9's
    GM matrix).  So ``q = (S^T W S)^-1 S^T W s``; a rigid motion of the sources is returned
    exactly.

    Parameters
    ----------
    reference : ndarray (3,)
        Reference node position, m.
    positions : ndarray (k, 3)
        Position of the node of each source component, m.
    directions : ndarray (k, 3)
        Unit direction of each source component (basic frame): a translation's, or the axis
        of a rotation's.
    weights : ndarray (k,)
        > 0 (NASTRAN WTi, dimensionless: translations and rotations alike).
    rotational : ndarray (k,) of bool, optional
        Which components are rotations (default none).
    length_m : float, optional
        ``L_c``, m: the mean distance from ``reference`` to the independent grids, each grid
        counted once (a grid coincident with the reference counts as 0); default the mean
        over the distinct ``positions``.  Used only when a rotation is among the sources.
    where : str
        The element, for errors.

    Returns
    -------
    ndarray (6, k)
        ``q = W_rbe3 @ s``.
    """
    d = np.asarray(positions, float) - np.asarray(reference, float)
    e = np.asarray(directions, float)
    w = np.asarray(weights, float).copy()
    rot = np.zeros(w.size, bool) if rotational is None else np.asarray(rotational, bool)
    S = np.concatenate([e, np.cross(d, e)], axis=1)  # e.(q_t + q_r x d) = e.q_t + (d x e).q_r
    if rot.any():
        S[rot, :3] = 0.0
        S[rot, 3:] = e[rot]
        if length_m is None:
            grids = np.unique(np.asarray(positions, float), axis=0)
            length_m = float(np.linalg.norm(grids - np.asarray(reference, float), axis=1).mean())
        if length_m > 1e-12:  # NASTRAN (and pyyeti) scale only a non-zero length
            w[rot] *= length_m**2
    N = S.T @ (w[:, None] * S)
    diag = np.diag(N).copy()
    if not np.all(diag > 0):
        raise InputError(
            "its independent components do not determine the reference's six motions "
            f"(none acts on reference DOF {int(np.flatnonzero(~(diag > 0))[0]) + 1})",
            where=where,
            fix="add independent nodes or components",
        )
    js = 1.0 / np.sqrt(diag)  # Jacobi scaling: the test is independent of units and weights
    if np.linalg.cond(N * np.outer(js, js)) > INTERPOLATION_COND_MAX:
        raise InputError(
            "its independent components do not determine the reference's six motions "
            "(too few nodes, or collinear ones)",
            where=where,
            fix="add independent nodes off the line, or give them more components",
        )
    return np.linalg.solve(N, S.T * w[None, :])
