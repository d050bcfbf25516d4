"""Flat shell element kernels: MITC4 quadrilaterals and MITC3 triangles (NASTRAN CQUAD4/CTRIA3).

Pure functions of SI arrays, vectorised over elements; six DOFs per node in the element axes
``(u, v, w, theta_x, theta_y, theta_z)`` (x, y in the mid-plane, z the normal), rotated to
the basic frame by :func:`shell_matrices`, which :mod:`microg.structure.assembly` calls.

* **Kinematics** (Reissner-Mindlin): ``u = u0 + z theta_y``, ``v = v0 - z theta_x``; the
  curvatures ``k = [d theta_y/dx, -d theta_x/dy, d theta_y/dy - d theta_x/dx]``, the
  transverse shear strains ``g = grad w + (theta_y, -theta_x)``.  Energies per area:
  ``e^T A e / 2 + k^T D k / 2 + g^T S g / 2`` (:class:`~microg.models.graph_model.ShellSection`).
* **CQUAD4: MITC4** (Dvorkin & Bathe, "A continuum mechanics based four-node shell element
  for general non-linear analysis", *Engineering Computations* 1 (1984) 77-88; Bathe,
  *Finite Element Procedures*, 2nd ed., 2014, sec. 5.4.2): bilinear membrane and bending,
  full 2x2 Gauss integration; the transverse shear strains are the covariant ones tied at
  the four edge midpoints, ``e_xi`` at ``(0, -1), (0, 1)`` and ``e_eta`` at ``(-1, 0),
  (1, 0)``, interpolated linearly across the element.  This removes shear locking and adds
  no spurious zero-energy mode; the element passes the membrane and bending patch tests.
* **CTRIA3: MITC3** (Lee & Bathe, "Development of MITC isotropic triangular shell finite
  elements", *Computers & Structures* 82 (2004) 945-962) with the constant-strain membrane:
  linear rotations and deflection; the assumed shear field is the lowest Nedelec space
  ``(a1 + c y, a2 - c x)``, fixed by the tangential shear strain of each edge at its
  midpoint (Lee & Bathe's tying, written without the natural coordinates).
* **Drilling rotation** (NASTRAN ``PARAM,K6ROT``): the penalty ``alpha (theta_z - omega)^2
  / 2`` per area with ``omega = (dv/dx - du/dy) / 2`` the membrane's own rotation and
  ``alpha = 1e-6 K6ROT G T`` (NASTRAN's scale; its default K6ROT is 100), integrated at the
  membrane's Gauss points.  Coupled to the membrane rotation, a rigid in-plane rotation
  costs nothing, and a flat coplanar mesh is not singular about its normal.
* **Warping** (a quadrilateral whose corners are off one plane): the element is built on the
  mean plane (normal ``(x3 - x1) x (x4 - x2)``, through the mean of the corners) and joined
  to its grids by rigid offsets ``h_i n``, so rigid-body motion stays exact; the warp ratio
  ``max |h_i| / mean diagonal`` above :data:`MAX_WARP` is refused.
* **Mass** (translational only, as NASTRAN's plate elements without rotary inertia):
  lumped (NASTRAN's default) ``m integral N_i dA`` on each corner's translations (equal shares
  for a parallelogram, a third each on a triangle); consistent (``PARAM,COUPMASS``)
  ``m integral N_i N_j dA`` (2x2 Gauss: exact for the bilinear quadrilateral).  Mass sits at
  the grids, not on the mean plane.
* **Element axes**: the material is isotropic, so the in-plane axes change nothing; the normal
  is NASTRAN's (``(G3 - G1) x (G4 - G2)``; triangle ``(G2 - G1) x (G3 - G1)``), x along the
  bisector of the diagonals (NASTRAN's CQUAD4 rule), G1 -> G2 on a triangle.
"""

from __future__ import annotations

import math

import numpy as np

from microg.errors import InputError
from microg.structure.elements import rigid_link

__all__ = [
    "MAX_WARP",
    "quad_local",
    "shell_matrices",
    "tria_local",
]

#: largest warp ratio ``max |h_i| / mean diagonal`` accepted for a CQUAD4 (h_i: corner
#: heights off the mean plane).  NASTRAN's GEOMCHECK warns above a warp coefficient of 0.05
#: (``Q4_WARP``); microg refuses above this value rather than solve a strongly warped element
#: with rigid offsets
MAX_WARP = 0.05
_G = 1.0 / math.sqrt(3.0)
_GAUSS = ((-_G, -_G), (_G, -_G), (_G, _G), (-_G, _G))
_XI = np.array([-1.0, 1.0, 1.0, -1.0])
_ETA = np.array([-1.0, -1.0, 1.0, 1.0])


def _q4(xi: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear shape functions (4,) and their derivatives (2, 4) in (xi, eta)."""
    n = 0.25 * (1 + _XI * xi) * (1 + _ETA * eta)
    d = np.stack([0.25 * _XI * (1 + _ETA * eta), 0.25 * _ETA * (1 + _XI * xi)])
    return n, d


def _membrane_bending_drill(
    nx: np.ndarray, ny: np.ndarray, n: np.ndarray, nd: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Strain-displacement rows at one point: membrane (ne, 3, nd), bending, drilling (ne, nd).

    ``nx``, ``ny`` (ne, k): shape derivatives in x, y; ``n`` (ne, k) or (k,): shape values.
    """
    ne, k = nx.shape
    bm = np.zeros((ne, 3, nd))
    bb = np.zeros((ne, 3, nd))
    bd = np.zeros((ne, nd))
    u, v, tx, ty, tz = (6 * np.arange(k) + j for j in (0, 1, 3, 4, 5))
    bm[:, 0, u] = nx
    bm[:, 1, v] = ny
    bm[:, 2, u] = ny
    bm[:, 2, v] = nx
    bb[:, 0, ty] = nx
    bb[:, 1, tx] = -ny
    bb[:, 2, ty] = ny
    bb[:, 2, tx] = -nx
    bd[:, tz] = np.broadcast_to(n, (ne, k))
    bd[:, v] = -0.5 * nx
    bd[:, u] = 0.5 * ny
    return bm, bb, bd


def _energy(b: np.ndarray, c: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``w B^T C B`` for (ne, r, nd) B, (ne, r, r) C, (ne,) weights."""
    return w[:, None, None] * np.einsum("eri,ers,esj->eij", b, c, b)


def quad_local(
    xy: np.ndarray,
    membrane: np.ndarray,
    bending: np.ndarray,
    shear: np.ndarray,
    drilling: np.ndarray,
    mass_per_area: np.ndarray,
    lumped: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MITC4 stiffness and mass in the element axes.

    Parameters
    ----------
    xy : ndarray (ne, 4, 2)
        Corner coordinates in the element's plane, m, ordered around the element.
    membrane, bending, shear : ndarray (ne, 3, 3), (ne, 3, 3), (ne, 2, 2)
        ``A`` (N/m), ``D`` (N m), ``S`` (N/m).
    drilling : ndarray (ne,)
        ``alpha``, N/m.
    mass_per_area : ndarray (ne,)
        kg/m^2.
    lumped : bool
        Lumped (row sums of the consistent translational mass) or consistent mass.

    Returns
    -------
    k, m : ndarray (ne, 24, 24)
        N/m (N, N m) and kg; DOFs ``6 corner + (u, v, w, theta_x, theta_y, theta_z)``.
    det_j : ndarray (ne, 4)
        The Jacobian determinant at the Gauss points (> 0 for a convex element).
    """
    ne = xy.shape[0]
    nd = 24
    K = np.zeros((ne, nd, nd))
    M = np.zeros((ne, 4, 4))
    w_, tx, ty = (6 * np.arange(4) + j for j in (2, 3, 4))
    # covariant transverse shear rows at the tying points (e_xi at (0, -+1), e_eta at (-+1, 0))
    tie: dict[tuple[float, float], np.ndarray] = {}
    for pt, which in (((0.0, -1.0), 0), ((0.0, 1.0), 0), ((-1.0, 0.0), 1), ((1.0, 0.0), 1)):
        n, d = _q4(*pt)
        jac = np.einsum("ak,ekb->eab", d, xy)  # rows d/dxi, d/deta; columns x, y
        row = np.zeros((ne, nd))
        row[:, w_] = d[which]
        row[:, ty] = n[None, :] * jac[:, which, 0:1]
        row[:, tx] = -n[None, :] * jac[:, which, 1:2]
        tie[pt] = row
    det = np.zeros((ne, 4))
    # incompatible membrane modes (QM6): u, v += a (1 - xi^2) + b (1 - eta^2), derivatives
    # through the centre's Jacobian and scaled by det J0 / det J, condensed out below
    _, d0 = _q4(0.0, 0.0)
    jac0 = np.einsum("ak,ekb->eab", d0, xy)
    inv0 = np.linalg.inv(jac0)
    det0 = np.linalg.det(jac0)
    kcc = np.zeros((ne, 4, 4))
    kcu = np.zeros((ne, 4, nd))
    for g, (xi, eta) in enumerate(_GAUSS):
        n, d = _q4(xi, eta)
        jac = np.einsum("ak,ekb->eab", d, xy)
        dj = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
        det[:, g] = dj
        inv = np.linalg.inv(jac)  # [gx, gy] = inv(J) [d/dxi, d/deta]
        dxy = np.einsum("eab,bk->eak", inv, d)
        bm, bb, bd = _membrane_bending_drill(dxy[:, 0], dxy[:, 1], n, nd)
        dinc = np.einsum("eab,bk->eak", inv0, np.array([[-2 * xi, 0.0], [0.0, -2 * eta]]))
        dinc *= (det0 / dj)[:, None, None]
        bc = np.zeros((ne, 3, 4))  # columns: u (xi), u (eta), v (xi), v (eta)
        bc[:, 0, 0:2] = dinc[:, 0]
        bc[:, 1, 2:4] = dinc[:, 1]
        bc[:, 2, 0:2] = dinc[:, 1]
        bc[:, 2, 2:4] = dinc[:, 0]
        kcc += _energy(bc, membrane, dj)
        kcu += dj[:, None, None] * np.einsum("eri,ers,esj->eij", bc, membrane, bm)
        e_xi = 0.5 * (1 - eta) * tie[(0.0, -1.0)] + 0.5 * (1 + eta) * tie[(0.0, 1.0)]
        e_eta = 0.5 * (1 - xi) * tie[(-1.0, 0.0)] + 0.5 * (1 + xi) * tie[(1.0, 0.0)]
        bs = np.einsum("eab,ebj->eaj", inv, np.stack([e_xi, e_eta], axis=1))
        K += _energy(bm, membrane, dj) + _energy(bb, bending, dj) + _energy(bs, shear, dj)
        K += (drilling * dj)[:, None, None] * bd[:, :, None] * bd[:, None, :]
        M += (mass_per_area * dj)[:, None, None] * np.outer(n, n)[None]
    live = np.abs(kcc).max(axis=(1, 2)) > 0  # a membrane at all
    if live.any():
        K[live] -= np.swapaxes(kcu[live], 1, 2) @ np.linalg.solve(kcc[live], kcu[live])
    return 0.5 * (K + np.swapaxes(K, 1, 2)), _mass6(M, lumped), det


def tria_local(
    xy: np.ndarray,
    membrane: np.ndarray,
    bending: np.ndarray,
    shear: np.ndarray,
    drilling: np.ndarray,
    mass_per_area: np.ndarray,
    lumped: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MITC3 (with the constant-strain membrane) stiffness and mass in the element axes.

    Parameters as :func:`quad_local`, with ``xy`` (ne, 3, 2).

    Returns
    -------
    k, m : ndarray (ne, 18, 18)
    area : ndarray (ne,)
        Signed area, m^2 (> 0: corners counter-clockwise about the normal).
    """
    ne = xy.shape[0]
    nd = 18
    x, y = xy[:, :, 0], xy[:, :, 1]
    j, k = [1, 2, 0], [2, 0, 1]
    area = 0.5 * (
        (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
    )
    nx = (y[:, j] - y[:, k]) / (2 * area[:, None])
    ny = (x[:, k] - x[:, j]) / (2 * area[:, None])
    bm, bb, _ = _membrane_bending_drill(nx, ny, np.zeros(3), nd)
    K = _energy(bm, membrane, area) + _energy(bb, bending, area)
    # assumed shear: gamma(x) = P(x) c, P = [[1, 0, y - yc], [0, 1, -(x - xc)]], c fixed by
    # t_k . gamma(m_k) = (w_j - w_i) / L_k + t_k . (beta_i + beta_j) / 2, beta = (ty, -tx)
    xc, yc = x.mean(axis=1), y.mean(axis=1)
    G = np.zeros((ne, 3, 3))
    E = np.zeros((ne, 3, nd))
    mids = []
    for e_, (a, b) in enumerate(((0, 1), (1, 2), (2, 0))):
        dx, dy = x[:, b] - x[:, a], y[:, b] - y[:, a]
        L = np.hypot(dx, dy)
        tx_, ty_ = dx / L, dy / L
        mx, my = 0.5 * (x[:, a] + x[:, b]), 0.5 * (y[:, a] + y[:, b])
        mids.append((mx, my))
        G[:, e_] = np.stack([tx_, ty_, tx_ * (my - yc) - ty_ * (mx - xc)], axis=1)
        E[:, e_, 6 * b + 2] += 1 / L
        E[:, e_, 6 * a + 2] -= 1 / L
        for nn in (a, b):
            E[:, e_, 6 * nn + 4] += 0.5 * tx_
            E[:, e_, 6 * nn + 3] -= 0.5 * ty_
    coef = np.linalg.solve(G, E)  # (ne, 3, nd)
    third = area / 3.0
    for mx, my in mids:  # the edge-midpoint rule: exact for the quadratic integrands
        P = np.zeros((ne, 2, 3))
        P[:, 0, 0] = P[:, 1, 1] = 1.0
        P[:, 0, 2] = my - yc
        P[:, 1, 2] = -(mx - xc)
        bs = np.einsum("eab,ebj->eaj", P, coef)
        K += _energy(bs, shear, third)
    # drilling: alpha (sum L_i theta_z,i - omega)^2, omega constant (CST), at the midpoints
    omega = np.zeros((ne, nd))
    omega[:, 6 * np.arange(3) + 1] = 0.5 * nx
    omega[:, 6 * np.arange(3)] = -0.5 * ny
    for a, b in ((0, 1), (1, 2), (2, 0)):
        bd = -omega.copy()
        bd[:, 6 * a + 5] += 0.5
        bd[:, 6 * b + 5] += 0.5
        K += (drilling * third)[:, None, None] * bd[:, :, None] * bd[:, None, :]
    mt = (mass_per_area * area)[:, None, None] * (np.ones((3, 3)) + np.eye(3))[None] / 12.0
    return 0.5 * (K + np.swapaxes(K, 1, 2)), _mass6(mt, lumped), area


def _mass6(m: np.ndarray, lumped: bool) -> np.ndarray:
    """Translational mass (ne, k, k) on the corners' 6 DOFs (ne, 6k, 6k); lumped: row sums."""
    ne, k, _ = m.shape
    if lumped:
        m = m.sum(axis=2)[:, :, None] * np.eye(k)[None]
    out = np.zeros((ne, 6 * k, 6 * k))
    for c in range(3):
        idx = 6 * np.arange(k) + c
        out[:, idx[:, None], idx[None, :]] = m
    return out


def _frames(x: np.ndarray, where: list[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Element axes (ne, 3, 3) (rows x, y, z), plane coordinates (ne, k, 2), offsets (ne, k, 3).

    The offsets go from each grid to its corner on the element's (mean) plane.
    """
    ne, k, _ = x.shape
    c = x.mean(axis=1)
    if k == 4:
        d13, d24 = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
        z = np.cross(d13, d24)
        ex = d13 / np.linalg.norm(d13, axis=1)[:, None] - d24 / np.linalg.norm(d24, axis=1)[:, None]
        diag = 0.5 * (np.linalg.norm(d13, axis=1) + np.linalg.norm(d24, axis=1))
    else:
        ex = x[:, 1] - x[:, 0]
        z = np.cross(ex, x[:, 2] - x[:, 0])
        diag = np.linalg.norm(ex, axis=1)
    zn = np.linalg.norm(z, axis=1)
    bad = np.flatnonzero(~(zn > 1e-12 * np.maximum(diag, 1e-300) ** 2))
    if bad.size:
        raise InputError(
            "the shell's corners are collinear or coincide (no area)",
            where=where[int(bad[0])],
            fix="give corners that span an area",
        )
    z = z / zn[:, None]
    ex = ex - np.einsum("ei,ei->e", ex, z)[:, None] * z
    ex = ex / np.linalg.norm(ex, axis=1)[:, None]
    R = np.stack([ex, np.cross(z, ex), z], axis=1)
    h = np.einsum("eki,ei->ek", x - c[:, None], z)
    if k == 4:
        warp = np.max(np.abs(h), axis=1) / diag
        bad = np.flatnonzero(warp > MAX_WARP)
        if bad.size:
            e = int(bad[0])
            raise InputError(
                f"the quadrilateral is warped: corners {warp[e]:.3g} of its mean diagonal off "
                f"its mean plane (limit {MAX_WARP})",
                where=where[e],
                fix="split it into two CTRIA3, or flatten it",
            )
    offsets = -h[:, :, None] * z[:, None, :]
    p = x + offsets - c[:, None]
    xy = np.einsum("eki,eai->eka", p, R[:, :2])
    return R, xy, offsets


def shell_matrices(
    positions: np.ndarray,
    membrane: np.ndarray,
    bending: np.ndarray,
    shear: np.ndarray,
    drilling: np.ndarray,
    mass_per_area: np.ndarray,
    lumped: bool,
    where: list[str],
) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and mass of flat shells on their grids' 6 basic DOFs each.

    ``K = T^T K_local T`` with ``T`` the element axes on each corner's translations and
    rotations after the rigid offset from the grid to the corner (zero unless warped); the
    translational mass is the same in any axes and sits at the grids.

    Parameters
    ----------
    positions : ndarray (ne, k, 3)
        Grid positions, basic frame, m; ``k`` = 4 (MITC4) or 3 (MITC3).
    membrane, bending, shear, drilling, mass_per_area : ndarray
        Per element, as :func:`quad_local` takes them.
    lumped : bool
        Lumped or consistent mass.
    where : list of str
        Each element's name, for errors.

    Returns
    -------
    k, m : ndarray (ne, 6k, 6k)
        Basic frame: N/m, N, N m and kg.
    """
    x = np.asarray(positions, float)
    ne, k, _ = x.shape
    R, xy, off = _frames(x, where)
    if k == 4:
        kl, m, det = quad_local(xy, membrane, bending, shear, drilling, mass_per_area, lumped)
        bad = np.flatnonzero(~(det.min(axis=1) > 0))
    else:
        kl, m, area = tria_local(xy, membrane, bending, shear, drilling, mass_per_area, lumped)
        bad = np.flatnonzero(~(area > 0))
    if bad.size:
        raise InputError(
            "the quadrilateral is not convex (or its corners are not in order around it)",
            where=where[int(bad[0])],
            fix="order the grids around the element, or split it into two CTRIA3",
        )
    T = np.zeros((ne, 6 * k, 6 * k))
    lk = rigid_link(off)  # (ne, k, 6, 6): grid DOFs -> corner DOFs
    for i in range(k):
        o = 6 * i
        T[:, o : o + 3, o : o + 6] = R @ lk[:, i, :3, :]
        T[:, o + 3 : o + 6, o : o + 6] = R @ lk[:, i, 3:, :]
    kg = np.swapaxes(T, 1, 2) @ kl @ T
    return 0.5 * (kg + np.swapaxes(kg, 1, 2)), m
