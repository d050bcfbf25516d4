"""Assembly of a graph model's element matrices on 6 basic-frame DOFs per node.

:func:`assemble_frame` evaluates the element kernels (:mod:`microg.structure.elements`;
shells :mod:`microg.structure.shells`) of every beam, rod, shell, spring, scalar spring,
scalar mass and concentrated mass of a :class:`~microg.models.graph_model.GraphModel`,
rotates them to the basic frame (beam end offsets as rigid links, skew sections about their
principal axes, pin flags released) and sums them into sparse stiffness, mass and damping
matrices (the g-set); the rigid elements are resolved into the transformation to the
independent DOFs (:mod:`microg.structure.links`).
:func:`microg.structure.frame.build_frame` makes the structure from these.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from microg.errors import InputError
from microg.models.graph_check import validate_graph
from microg.models.graph_model import MASS_FORMULATIONS, BeamSection, GraphModel
from microg.structure.elements import (
    BAR_COUPLED_FORMS,
    bar_mass_coupled_local,
    beam_mass_consistent_local,
    beam_mass_lumped_local,
    beam_stiffness_local,
    bush_matrix,
    frame_rotation,
    point_mass_matrix,
    release_ends,
    rigid_link,
    rod_mass_local,
    rod_stiffness_local,
    shear_parameter,
)
from microg.structure.links import link_transform
from microg.structure.shells import shell_matrices

if TYPE_CHECKING:  # scipy loads on first use (see microg.structure.fem)
    import scipy.sparse as sp

__all__ = ["MAX_FEM_DOF", "FrameMatrices", "assemble_frame"]

#: largest frame model (degrees of freedom, 6 per node) assembled (and a station meshed into:
#: checked before any node is made).  A 500,000-DOF sparse model takes ~0.5 GB for its matrices and
#: 60 modes (~6 s to solve on this project's machine, 1 thread); the shipped IOC model has
#: ~42,000 nodes (250,000 DOFs) at the CLI's largest --elements 10,000.
MAX_FEM_DOF = 500_000


@dataclass(frozen=True)
class FrameMatrices:
    """The assembled graph before DOF elimination: 6 basic-frame DOFs per node (g-set).

    Attributes
    ----------
    stiffness, mass, damping, structural_damping : sparse CSR (6 nn, 6 nn)
        SI; ``damping`` viscous (N s/m), ``structural_damping`` sum of ``GE_e K_e``.
    positions : ndarray (nn, 3)
        Node positions, m.
    names : tuple of str
        Node names.
    transform : sparse CSR (6 nn, n_ind)
        ``u_g = transform @ u_ind``: the rigid links and interpolations eliminated.
    independent : ndarray of int
        The g-set DOFs kept as coordinates of ``transform``.
    beam_rotation : ndarray (nb, 3, 3)
        Station-to-element rotation of each beam element (rows: local x, y, z; the principal
        bending axes of a skewed section), in the order of ``graph.beams``.
    beam_length : ndarray (nb,)
        Length of each beam element between its (offset) ends, m.
    working : sparse CSR (6 nn, 6 nn) or None
        ``u_basic = working @ u_work``: the independent DOFs of the nodes
        :func:`~microg.structure.links.turned_nodes` picks are along their own axes; None:
        every independent DOF is a basic-frame one.
    """

    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    structural_damping: sp.csr_matrix
    positions: np.ndarray
    names: tuple[str, ...]
    transform: sp.csr_matrix
    independent: np.ndarray
    beam_rotation: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))
    beam_length: np.ndarray = field(default_factory=lambda: np.zeros(0))
    working: sp.csr_matrix | None = None


def _coo(
    rows: list[np.ndarray], cols: list[np.ndarray], vals: list[np.ndarray], n: int
) -> sp.csr_matrix:
    import scipy.sparse as sp

    if not rows:
        return sp.csr_matrix((n, n))
    a = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    ).tocsr()
    a = 0.5 * (a + a.T)
    a.eliminate_zeros()
    return sp.csr_matrix(a)


def _scatter(
    dofs: np.ndarray,
    mats: np.ndarray,
    out_r: list[np.ndarray],
    out_c: list[np.ndarray],
    out_v: list[np.ndarray],
) -> None:
    ne, nd = dofs.shape
    out_r.append(np.broadcast_to(dofs[:, :, None], (ne, nd, nd)).ravel())
    out_c.append(np.broadcast_to(dofs[:, None, :], (ne, nd, nd)).ravel())
    out_v.append(np.asarray(mats).reshape(ne, nd, nd).ravel())


def _element_transform(R: np.ndarray, off_a: np.ndarray, off_b: np.ndarray) -> np.ndarray:
    """Local 12 DOFs from the two nodes' basic DOFs through rigid end offsets (ne, 12, 12)."""
    ne = R.shape[0]
    A = np.zeros((ne, 12, 12))
    for blk, t in ((0, rigid_link(off_a)), (1, rigid_link(off_b))):
        o = 6 * blk
        A[:, o : o + 3, o : o + 6] = R @ t[:, :3, :]
        A[:, o + 3 : o + 6, o : o + 6] = R @ t[:, 3:, :]
    return A


def _principal(
    R: np.ndarray, secs: list[BeamSection]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rotate local y, z to the principal bending axes of the sections where I12 != 0.

    Returns the rotated frames ``R``, the principal ``EI_y``, ``EI_z`` (N m^2) and the indices
    of the skew sections.  Shear is not handled here: the caller drops the shear flexibility
    of the skew sections (NASTRAN ignores the shear factors when I12 != 0).
    """
    ei_y = np.array([s.ei_y_N_m2 for s in secs])
    ei_z = np.array([s.ei_z_N_m2 for s in secs])
    ei_yz = np.array([s.ei_yz_N_m2 for s in secs])
    skew = np.flatnonzero(ei_yz != 0)
    R = R.copy()
    for e in skew:
        # B = [[E int y^2, E int yz], [E int yz, E int z^2]] in (y, z); its eigenvectors are the
        # principal directions; deflection along eigenvector k has stiffness lambda_k
        B = np.array([[ei_z[e], ei_yz[e]], [ei_yz[e], ei_y[e]]])
        lam, Q = np.linalg.eigh(B)
        ey = Q[0, 0] * R[e, 1] + Q[1, 0] * R[e, 2]
        R[e, 1] = ey
        R[e, 2] = np.cross(R[e, 0], ey)
        ei_z[e], ei_y[e] = lam[0], lam[1]
    return R, ei_y, ei_z, skew


def assemble_frame(graph: GraphModel, *, mass: str | None = None) -> FrameMatrices:
    """Element matrices of ``graph`` assembled on 6 basic-frame DOFs per node, links resolved.

    Parameters
    ----------
    graph : GraphModel
    mass : {"lumped", "consistent", "coupled", "coupled-nx9"}, optional
        Overrides the model's mass formulation (:mod:`microg.structure.elements`: the two
        ``coupled`` forms are NASTRAN's COUPMASS mass of CBARs; other elements take the
        consistent mass under them).

    Returns
    -------
    FrameMatrices
    """
    validate_graph(graph)
    formulation = graph.mass_formulation if mass is None else mass
    if formulation not in MASS_FORMULATIONS:
        raise InputError(
            f"unknown mass formulation {formulation!r}",
            where="mass",
            fix="use " + ", ".join(MASS_FORMULATIONS),
        )
    lumped = formulation == "lumped"
    index = graph.node_index()
    P = np.array([n.position for n in graph.nodes], float).reshape(-1, 3)
    n = 6 * P.shape[0]
    if n > MAX_FEM_DOF:
        raise InputError(
            f"the frame model has {n:,} degrees of freedom ({P.shape[0]:,} nodes), beyond the "
            f"limit of {MAX_FEM_DOF:,}",
            where=graph.source or graph.name,
            fix="use a coarser mesh, or a modal model of the structure",
        )
    rk: list[np.ndarray] = []
    ck: list[np.ndarray] = []
    vk: list[np.ndarray] = []
    rm: list[np.ndarray] = []
    cm: list[np.ndarray] = []
    vm: list[np.ndarray] = []
    rc: list[np.ndarray] = []
    cc: list[np.ndarray] = []
    vc: list[np.ndarray] = []
    rg: list[np.ndarray] = []
    cg: list[np.ndarray] = []
    vg: list[np.ndarray] = []

    beam_R = np.zeros((0, 3, 3))
    beam_L = np.zeros(0)
    if graph.beams:
        bm = graph.beams
        a = np.array([index[b.nodes[0]] for b in bm])
        b_ = np.array([index[b.nodes[1]] for b in bm])
        off = np.array([b.offsets for b in bm], float).reshape(-1, 2, 3)
        xa = P[a] + off[:, 0]
        xb = P[b_] + off[:, 1]
        axis = xb - xa
        L = np.linalg.norm(axis, axis=1)
        R = frame_rotation(axis / L[:, None], np.array([b.orientation for b in bm], float))
        secs = [b.section for b in bm]
        R, ei_y, ei_z, skew = _principal(R, secs)
        beam_R, beam_L = R, L
        sy = np.array([np.inf if s.shear_y_N is None else s.shear_y_N for s in secs])
        sz = np.array([np.inf if s.shear_z_N is None else s.shear_z_N for s in secs])
        sy[skew] = np.inf  # NASTRAN: shear factors ignored when I12 != 0
        sz[skew] = np.inf
        phi_v = shear_parameter(L, ei_z, sy)
        phi_w = shear_parameter(L, ei_y, sz)
        ea = np.array([s.ea_N for s in secs])
        gj = np.array([s.gj_N_m2 for s in secs])
        mpl = np.array([s.mass_per_length_kg_per_m for s in secs])
        polar = np.array([s.polar_mass_kg_m for s in secs])
        kl = beam_stiffness_local(L, ea, ei_y, ei_z, gj, phi_v, phi_w)
        if lumped:
            ml = beam_mass_lumped_local(L, mpl, polar, np.array([b.kind == "beam" for b in bm]))
        else:
            ry = np.array([s.rotary_y_kg_m for s in secs])
            rz = np.array([s.rotary_z_kg_m for s in secs])
            if skew.size:
                ry[skew] = rz[skew] = 0.5 * (ry[skew] + rz[skew])
            ml = beam_mass_consistent_local(L, mpl, polar, phi_v, phi_w, ry, rz)
            bars = np.flatnonzero([b.kind == "bar" for b in bm])
            if formulation in BAR_COUPLED_FORMS and bars.size:
                ml[bars] = bar_mass_coupled_local(
                    L[bars],
                    mpl[bars],
                    phi_v[bars],
                    phi_w[bars],
                    end_rotation_coupling=BAR_COUPLED_FORMS[formulation],
                )
        rel = np.zeros((len(bm), 12), bool)
        for e, b in enumerate(bm):
            for end, comps in enumerate(b.releases):
                for ch in comps:
                    rel[e, 6 * end + int(ch) - 1] = True
        if rel.any():
            kl, ml = release_ends(kl, ml, rel)
        A = _element_transform(R, off[:, 0], off[:, 1])
        At = np.swapaxes(A, 1, 2)
        dofs = np.concatenate([6 * a[:, None] + np.arange(6), 6 * b_[:, None] + np.arange(6)], 1)
        _scatter(dofs, At @ kl @ A, rk, ck, vk)
        _scatter(dofs, At @ ml @ A, rm, cm, vm)

    if graph.rods:
        rd = graph.rods
        a = np.array([index[r.nodes[0]] for r in rd])
        b_ = np.array([index[r.nodes[1]] for r in rd])
        axis = P[b_] - P[a]
        L = np.linalg.norm(axis, axis=1)
        ex = axis / L[:, None]
        ori = np.zeros_like(ex)
        ori[np.arange(ex.shape[0]), np.argmin(np.abs(ex), axis=1)] = 1.0
        R = frame_rotation(ex, ori)
        kl = rod_stiffness_local(
            L, np.array([r.ea_N for r in rd]), np.array([r.gj_N_m2 for r in rd])
        )
        ml = rod_mass_local(L, np.array([r.mass_per_length_kg_per_m for r in rd]), lumped)
        zero = np.zeros((len(rd), 3))
        A = _element_transform(R, zero, zero)
        At = np.swapaxes(A, 1, 2)
        dofs = np.concatenate([6 * a[:, None] + np.arange(6), 6 * b_[:, None] + np.arange(6)], 1)
        _scatter(dofs, At @ kl @ A, rk, ck, vk)
        _scatter(dofs, At @ ml @ A, rm, cm, vm)

    for k in (4, 3):  # shells (CQUAD4, CTRIA3): microg.structure.shells
        sh = [e for e in graph.shells if len(e.nodes) == k]
        if sh:
            ids = np.array([[index[nd] for nd in e.nodes] for e in sh])
            sec = [e.section for e in sh]
            ks, mshell = shell_matrices(
                P[ids],
                np.array([q.membrane_N_per_m for q in sec], float),
                np.array([q.bending_N_m for q in sec], float),
                np.array([q.shear_N_per_m for q in sec], float),
                np.array([q.drilling_N_per_m for q in sec], float),
                np.array([q.mass_per_area_kg_per_m2 for q in sec], float),
                lumped,
                [graph.source + ": " + e.name if graph.source else e.name for e in sh],
            )
            dofs = (6 * ids[:, :, None] + np.arange(6)).reshape(len(sh), -1)
            _scatter(dofs, ks, rk, ck, vk)
            _scatter(dofs, mshell, rm, cm, vm)

    for s in graph.springs:
        ia = index[s.nodes[0]]
        ib = None if s.nodes[1] is None else index[s.nodes[1]]
        pb = None if ib is None else P[ib]
        d = 6 * ia + np.arange(6)
        if ib is not None:
            d = np.concatenate([d, 6 * ib + np.arange(6)])
        kb = bush_matrix(s.stiffness, s.axes, P[ia], pb, s.location)
        cb = bush_matrix(s.damping, s.axes, P[ia], pb, s.location)
        _scatter(d[None], kb[None], rk, ck, vk)
        _scatter(d[None], cb[None], rc, cc, vc)
        if s.structural_damping:
            _scatter(d[None], s.structural_damping * kb[None], rg, cg, vg)

    nodes = graph.nodes

    def scalar_vector(dofs: tuple[tuple[str, int] | None, ...]) -> tuple[np.ndarray, np.ndarray]:
        """DOFs and ``e_b - e_a`` of a scalar element's two components.

        A scalar point's one DOF is slot 0 of its node.
        """
        dl: list[np.ndarray] = []
        vl: list[np.ndarray] = []
        for end, dof in enumerate(dofs):
            if dof is None:
                continue
            i = index[dof[0]]
            c = dof[1] - 1
            v = np.zeros(6)
            v[3 * (c // 3) : 3 * (c // 3) + 3] = nodes[i].axes[c % 3]
            dl.append(6 * i + np.arange(6))
            vl.append(v if end else -v)
        return np.concatenate(dl), np.concatenate(vl)

    for sm in graph.scalar_masses:
        d, v = scalar_vector(sm.dofs)
        _scatter(d[None], (sm.mass * np.outer(v, v))[None], rm, cm, vm)
    for cs in graph.scalar_springs:
        dl: list[np.ndarray] = []
        vl: list[np.ndarray] = []
        for end, dof in enumerate(cs.dofs):
            if dof is None:
                continue
            i = index[dof[0]]
            c = dof[1] - 1
            v = np.zeros(6)
            v[3 * (c // 3) : 3 * (c // 3) + 3] = nodes[i].axes[c % 3]
            dl.append(6 * i + np.arange(6))
            vl.append(v if end else -v)
        d = np.concatenate(dl)
        ke = np.outer(np.concatenate(vl), np.concatenate(vl))
        _scatter(d[None], (cs.stiffness * ke)[None], rk, ck, vk)
        if cs.damping:
            _scatter(d[None], (cs.damping * ke)[None], rc, cc, vc)
        if cs.structural_damping:
            _scatter(d[None], (cs.structural_damping * cs.stiffness * ke)[None], rg, cg, vg)

    if graph.masses:
        ms = graph.masses
        m6 = point_mass_matrix(
            np.array([m.mass_kg for m in ms]),
            np.array([m.inertia_kg_m2 for m in ms], float).reshape(-1, 3, 3),
            np.array([m.offset_m for m in ms], float).reshape(-1, 3),
        )
        d6 = 6 * np.array([index[m.node] for m in ms])[:, None] + np.arange(6)
        _scatter(d6, m6, rm, cm, vm)

    K = _coo(rk, ck, vk, n)
    M = _coo(rm, cm, vm, n)
    C = _coo(rc, cc, vc, n)
    G = _coo(rg, cg, vg, n)
    T, ind, working = link_transform(graph, P, index)
    return FrameMatrices(
        K, M, C, G, P, tuple(nd.name for nd in nodes), T, ind, beam_R, beam_L, working
    )
