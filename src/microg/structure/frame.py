"""General frame finite elements: a graph model built into a free-free Structure.

:func:`build_frame` turns a :class:`~microg.models.graph_model.GraphModel` (closed loops
allowed) into a :class:`~microg.structure.Structure`.  Coordinates are the 6 DOFs of each
node (translations and small rotations in the basic frame), after the exact elimination of
rigid links and interpolation elements (:mod:`microg.structure.links`) and of the DOFs that
carry no mass.  The element matrices are :mod:`microg.structure.elements`', assembled by
:mod:`microg.structure.assembly`; a tree station becomes a graph in
:mod:`microg.structure.mesh`.  This module also gathers those modules' public names.

Degrees of freedom:

1. **Unconnected DOFs** (no stiffness and no mass: rotations of rod-only nodes, unused
   grids) are removed, as NASTRAN's ``AUTOSPC`` does; ``meta["removed"]`` counts them.
2. **Massless DOFs** (the lumped-mass rotations) are condensed exactly: with ``M_oo = 0``
   the equations of the massless set are static, ``u_o = -K_oo^-1 K_oa u_a``, so
   ``K_r = K_aa - K_ao K_oo^-1 K_oa`` and ``M_r = M_aa`` have the same finite eigenvalues as
   the full pencil, and forces on the massless set map exactly through the point maps.  The
   condensed stiffness is dense, so this is done up to :data:`CONDENSE_MAX` retained DOFs
   (``condense_max``).  Above that limit the massless DOFs are **kept as coordinates**: K
   stays sparse and M is sparse and positive semi-definite, its massless rows and columns
   exactly zero; :func:`~microg.dynamics.eigsparse.solve_sparse` solves that pencil (the
   massless directions have ``mu = 0`` in its inverse form, and its Rayleigh-Ritz step
   gives the shapes their static massless part).  ``meta["condensed"]`` is then 0,
   ``meta["massless_kept"]`` counts them, and a warning says so.  Either way a massless
   mechanism (``K_oo`` singular: e.g. a straight line of CBARs, which have no torsional
   inertia, turning about its axis) is refused, naming the DOFs.
3. **Rigid-body vectors** are the exact unit translations and rotations about the centre of
   mass (as :mod:`microg.structure.fem`'s), restricted to the retained DOFs (a rigid motion
   satisfies every link exactly).

The structure is free-free; ``constrained=True`` applies the model's single-point
constraints (NASTRAN SPC) instead, for validation against clamped decks.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.models.graph_model import GraphModel, GraphPoint
from microg.structure.assembly import MAX_FEM_DOF, FrameMatrices, assemble_frame
from microg.structure.elements import (
    DOF_NAMES,
    beam_mass_consistent_local,
    beam_mass_lumped_local,
    beam_stiffness_local,
    bush_matrix,
    frame_mass_local,
    frame_rotation,
    frame_stiffness_local,
    interpolation_matrix,
    point_mass_matrix,
    release_ends,
    rigid_link,
    rod_mass_local,
    rod_stiffness_local,
    shear_parameter,
)
from microg.structure.links import basic_dofs, turned_nodes
from microg.structure.mesh import (
    AXIAL_PENALTY,
    DEFAULT_ELEMENTS_PER_BEAM,
    GJ_ZERO_FRACTION,
    TORSION_PENALTY,
    StationMesh,
    graph_from_station,
    mesh_station,
    torsion_is_rigid,
)
from microg.structure.structure import PointMap, Structure

if TYPE_CHECKING:  # scipy loads on first use (see microg.structure.fem)
    import scipy.sparse as sp

__all__ = [
    "AXIAL_PENALTY",
    "CONDENSE_MAX",
    "DEFAULT_ELEMENTS_PER_BEAM",
    "DOF_NAMES",
    "GJ_ZERO_FRACTION",
    "MASS_BLOCK_MAX",
    "MAX_FEM_DOF",
    "StationMesh",
    "TORSION_PENALTY",
    "frame_mass_local",
    "frame_rotation",
    "frame_stiffness_local",
    "mass_properties_of",
    "mesh_station",
    "rigid_rows",
    "point_mass_matrix",
    "rigid_link",
    "torsion_is_rigid",
    "FrameMatrices",
    "FrameSamples",
    "assemble_frame",
    "beam_mass_consistent_local",
    "beam_mass_lumped_local",
    "beam_stiffness_local",
    "build_frame",
    "bush_matrix",
    "graph_from_station",
    "interpolation_matrix",
    "release_ends",
    "rod_mass_local",
    "rod_stiffness_local",
    "shear_parameter",
]

#: largest number of retained DOFs when massless DOFs are condensed (dense K_r)
CONDENSE_MAX = 2500


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class FrameSamples:
    """Translations of sample points (nodes and offset masses) from the coordinates.

    ``u_g = T (E q)`` with ``E`` the recovery of condensed massless DOFs
    (``u_o = X u_a``; none above the condensation limit, where the massless DOFs are
    coordinates themselves), then a sample rides rigidly on its node:
    ``u = u_node + theta_node x offset``.

    Attributes
    ----------
    position : ndarray (p, 3)
        m.
    labels : tuple of str
        ``"grid:7"``, ``"grid:11/conm2:21"``.
    component : ndarray (p,) of str
        Carrier of each sample for the acceleration maps: the label's prefix (``"keel"`` of
        ``"keel:n3"``, ``"grid"`` of ``"grid:7"``), as the maps read frame labels.
    offset : ndarray (p, 3)
        Sample position minus node position, m.
    rows : sparse CSR (6 p, n_ind)
        The g-set rows of the samples' nodes (translations then rotations).
    retained, condensed : ndarray of int
        Indices (in the independent set) of the coordinates and of the condensed DOFs.
    recovery : ndarray (n_condensed, n)
        ``X``.
    n_ind : int
        Size of the independent set.
    """

    position: np.ndarray
    labels: tuple[str, ...]
    component: np.ndarray
    offset: np.ndarray
    rows: sp.csr_matrix
    retained: np.ndarray
    condensed: np.ndarray
    recovery: np.ndarray
    n_ind: int

    def __len__(self) -> int:
        return int(self.position.shape[0])

    def expand(self, q: np.ndarray) -> np.ndarray:
        """Independent-set DOFs (n_ind,) or (n_ind, m) from coordinates ``q``."""
        q = np.asarray(q, float)
        u = np.zeros((self.n_ind, *q.shape[1:]))
        u[self.retained] = q
        if self.condensed.size:
            u[self.condensed] = self.recovery @ q
        return u

    def displacement(self, q: np.ndarray) -> np.ndarray:
        """Translations of the samples, m: (p, 3) for a vector ``q``, (p, 3, m) for a matrix."""
        q = np.asarray(q, float)
        u6 = np.asarray(self.rows @ self.expand(q))
        p = self.position.shape[0]
        if q.ndim == 1:
            u6 = u6.reshape(p, 6)
            return u6[:, :3] + np.cross(u6[:, 3:], self.offset)
        u6 = u6.reshape(p, 6, -1)
        return u6[:, :3] + np.cross(u6[:, 3:], self.offset[:, :, None], axisa=1, axisb=1, axisc=1)


class _PointMaps(Mapping[str, PointMap]):
    """Named points, plus every node by name on lookup (maps built on demand and cached).

    Iteration and ``len`` cover the named points only, so code that walks all points
    (modal-mass peaks) does not build a dense map per node of a large model.
    """

    def __init__(
        self,
        named: dict[str, PointMap],
        build_node: Any,
        node_names: set[str],
        scalar_names: set[str] | frozenset[str] = frozenset(),
    ):
        self._named = named
        self._build = build_node
        self._nodes = node_names
        self._scalar = scalar_names
        self._cache: dict[str, PointMap] = {}

    def __getitem__(self, key: str) -> PointMap:
        if key in self._named:
            return self._named[key]
        if key in self._scalar:
            raise InputError(
                f"{key!r} is a scalar point (SPOINT), not a point in space: it has no "
                "position and no acceleration to observe",
                where=key,
                fix="observe a grid",
            )
        if key in self._nodes:
            if key not in self._cache:
                self._cache[key] = self._build(key)
            return self._cache[key]
        raise KeyError(key)

    def __contains__(self, key: object) -> bool:
        # a scalar point is "in" so that looking it up says why it cannot be observed
        return key in self._named or key in self._nodes or key in self._scalar

    def __iter__(self) -> Iterator[str]:
        return iter(self._named)

    def __len__(self) -> int:
        return len(self._named)


# --------------------------------------------------------------------------- build


def _mass_props(M: Any, r: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, centre of mass and inertia about it from M and the rigid vectors (n, 6).

    The rotations of ``r`` are about a reference point; the centre of mass is returned
    relative to it.
    """
    mrr = np.asarray(r.T @ (M @ r))
    mrr = 0.5 * (mrr + mrr.T)
    total = float(np.trace(mrr[:3, :3]) / 3.0)
    if not total > 0:
        raise InputError("the model has no mass", fix="give elements density or add masses")
    first = np.array([mrr[1, 5], mrr[2, 3], mrr[0, 4]])  # sum m p, from the coupling block
    cm = first / total
    inertia = mrr[3:, 3:] - total * (float(cm @ cm) * np.eye(3) - np.outer(cm, cm))
    return total, cm, 0.5 * (inertia + inertia.T)


def rigid_rows(
    positions: np.ndarray,
    point: np.ndarray,
    scalar: np.ndarray | None = None,
    basis: Any = None,
) -> np.ndarray:
    """Exact rigid-body vectors (6 nn, 6) about ``point`` on the working DOFs of the nodes.

    Unit translations and small rotations of every node, ``u = t + theta x (x - point)``;
    zero on scalar points (they take no part in rigid-body motion, as in NASTRAN's rigid-body
    geometry); turned to the nodes' own axes where ``basis`` (``u_basic = basis u_work``,
    :attr:`~microg.structure.assembly.FrameMatrices.working`) says so.

    Parameters
    ----------
    positions : ndarray (nn, 3)
        Node positions, m.
    point : ndarray (3,)
        The rotations' centre, m.
    scalar : ndarray (nn,) of bool, optional
        Scalar points.
    basis : sparse (6 nn, 6 nn), optional
        Orthonormal: ``u_work = basis^T u_basic``.
    """
    r = rigid_link(np.asarray(positions, float) - point).reshape(-1, 6)
    if scalar is not None and np.any(scalar):
        rows = np.flatnonzero(np.repeat(np.asarray(scalar, bool), 6))
        r[rows] = 0.0
    if basis is not None:
        r = np.asarray(basis.T @ r)
    return r


def mass_properties_of(
    M: Any,
    positions: np.ndarray,
    dofs: np.ndarray | None = None,
    *,
    scalar: np.ndarray | None = None,
    basis: Any = None,
) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass (kg), centre of mass (m) and inertia about it (kg m^2) of a frame model.

    ``r^T M r`` for the exact rigid-body vectors ``r`` about the model's mean node, then
    about the centre of mass so found (lever arms formed once, from each node's offset to
    that point: a model 5 km from the origin loses nothing to the shift).

    Parameters
    ----------
    M : sparse (n, n)
        Mass matrix on the DOFs ``dofs`` of the 6-DOF nodes at ``positions``.
    positions : ndarray (nn, 3)
        Node positions, m.
    dofs : ndarray of int, optional
        The node DOFs (``6 node + k``) the coordinates are (default: all, in order).
    scalar : ndarray (nn,) of bool, optional
        Scalar points (no rigid-body motion, no position).
    basis : sparse (6 nn, 6 nn), optional
        The working DOFs of :func:`rigid_rows` (``dofs`` index them).
    """
    P = np.asarray(positions, float)
    sel = slice(None) if dofs is None else np.asarray(dofs)
    spatial = P if scalar is None else P[~np.asarray(scalar, bool)]
    c0 = spatial.mean(axis=0) if spatial.size else np.zeros(3)
    total, d, _ = _mass_props(M, rigid_rows(P, c0, scalar, basis)[sel])
    cm = c0 + d
    total, d2, inertia = _mass_props(M, rigid_rows(P, cm, scalar, basis)[sel])
    return total, cm + d2, inertia


def build_frame(
    graph: GraphModel,
    *,
    mass: str | None = None,
    constrained: bool = False,
    condense_max: int = CONDENSE_MAX,
) -> Structure:
    """Assemble the free-free frame finite-element model of a graph.

    Parameters
    ----------
    graph : GraphModel
    mass : {"lumped", "consistent"}, optional
        Mass formulation; default the model's (a NASTRAN deck's is lumped unless COUPMASS).
    constrained : bool
        Apply the model's single-point constraints (for validation against clamped decks);
        the structure then has no rigid-body vectors.
    condense_max : int
        Largest number of retained DOFs when massless DOFs are condensed (dense); above it
        they are kept as coordinates (sparse K, singular sparse M).

    Returns
    -------
    Structure
        Method ``"fem"``; sparse CSR matrices, or dense ones when massless DOFs were
        condensed (at most ``condense_max`` retained DOFs); a :class:`PointMap` per named
        point (and per node on lookup by name), exact rigid-body vectors,
        :class:`FrameSamples` as ``samples``; ``meta`` carries the damping matrices
        (``damping``, ``structural_damping``, in the coordinates), the ``transform`` from
        the independent set to the 6 DOFs per node (``u_g = transform @
        samples.expand(q)``), the removed and condensed DOF counts, ``massless_kept``
        (massless DOFs kept as coordinates above the limit) and ``warnings``.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    fm = assemble_frame(graph, mass=mass)
    T = fm.transform
    warnings: list[str] = []
    n_ind = T.shape[1]
    keep = np.ones(n_ind, bool)
    applied: list[str] = []
    if graph.constraints and not constrained:
        nodes = sorted({c.node for c in graph.constraints})
        shown = ", ".join(nodes[:5]) + (", ..." if len(nodes) > 5 else "")
        warnings.append(
            f"the model's single-point constraints (SPC) at {len(nodes)} node(s) ({shown}) are "
            "not applied: this is the free-free structure (constrained=True, or --constrained, "
            "applies them, as a clamped NASTRAN run does)"
        )
    scalar = np.array([nd.scalar for nd in graph.nodes], bool)
    pos_ind = np.full(T.shape[0], -1)
    pos_ind[fm.independent] = np.arange(fm.independent.size)
    # a scalar point has one DOF: the other five slots of its node are not coordinates
    for si in np.flatnonzero(scalar):
        for k in range(1, 6):
            if pos_ind[6 * si + k] >= 0:
                keep[pos_ind[6 * si + k]] = False
    if constrained:
        index = graph.node_index()
        turned = turned_nodes(graph)
        for c in graph.constraints:
            i = index[c.node]
            ks = (
                [int(ch) - 1 for ch in c.components]
                if turned[i]
                else basic_dofs(graph.nodes[i], c.components, where=f"constraint on {c.node}")
            )
            for k in ks:
                j = pos_ind[6 * i + k]
                if j < 0:
                    raise InputError(
                        f"component {k + 1} of node {c.node!r} is constrained and dependent",
                        where=f"constraint on {c.node}",
                        fix="constrain the independent node of the rigid element instead",
                    )
                keep[j] = False
            applied.append(f"{c.node}:{c.components}")
    Kn = sp.csr_matrix(T.T @ fm.stiffness @ T)
    Mn = sp.csr_matrix(T.T @ fm.mass @ T)
    Cn = sp.csr_matrix(T.T @ fm.damping @ T)
    Gn = sp.csr_matrix(T.T @ fm.structural_damping @ T)
    k_abs = np.asarray(abs(Kn).sum(axis=1)).ravel()
    m_abs = np.asarray(abs(Mn).sum(axis=1)).ravel()
    k_scale = float(np.max(Kn.diagonal())) if Kn.nnz else 0.0
    m_scale = float(np.max(Mn.diagonal())) if Mn.nnz else 0.0
    # round-off, not a connection: a rigid element's coefficients of order eps leave ~1e-20
    # of stiffness and ~1e-35 of mass on a component nothing else reaches (an RBE3 whose UM
    # frees its reference grid's components), which must not pose as a massless mechanism
    unconnected = (
        keep & (k_abs <= 1e-14 * max(k_scale, 1e-300)) & (m_abs <= 1e-14 * max(m_scale, 1e-300))
    )
    keep &= ~unconnected
    live = np.flatnonzero(keep)
    names = fm.names
    along = turned_nodes(graph) if fm.working is not None else np.zeros(len(names), bool)
    ind_labels = [
        names[d // 6]
        if scalar[d // 6]
        else f"{names[d // 6]}:{d % 6 + 1}"
        if along[d // 6]
        else f"{names[d // 6]}:{DOF_NAMES[d % 6]}"
        for d in fm.independent
    ]
    # massless directions: zero rows, and null directions of small coupled mass blocks
    # (a node whose lumped torsional inertias span fewer than three axes)
    Q, null, ind_labels = _mass_basis(Mn, live, ind_labels)
    if Q is not None:
        T = sp.csr_matrix(T @ Q)
        Kn, Mn = sp.csr_matrix(Q.T @ Kn @ Q), sp.csr_matrix(Q.T @ Mn @ Q)
        Cn, Gn = sp.csr_matrix(Q.T @ Cn @ Q), sp.csr_matrix(Q.T @ Gn @ Q)
    massless = live[null[live]]
    retained = live[~null[live]]
    if retained.size == 0:
        raise InputError(
            "the model has no mass",
            where=graph.source or graph.name,
            fix="give elements density or add masses",
        )
    if unconnected.any():
        warnings.append(
            f"{int(unconnected.sum())} DOFs with neither stiffness nor mass removed "
            "(as NASTRAN AUTOSPC)"
        )
    Kaa = Kn[retained][:, retained]
    Maa = Mn[retained][:, retained]
    X = np.zeros((0, retained.size))
    kept_massless = 0
    K_out: Any
    M_out: Any
    C_out: Any
    G_out: Any
    pinned: list[int] = []
    if massless.size and not (constrained and applied):
        r0 = rigid_rows(fm.positions, fm.positions.mean(axis=0), scalar, fm.working)
        r0 = r0[fm.independent] if Q is None else np.asarray(Q.T @ r0[fm.independent])
        massless, pinned = _pin_massless_rigid(r0, retained, massless)
        if pinned:
            live = np.setdiff1d(live, pinned)
            warnings.append(
                f"{len(pinned)} rigid-body motion(s) move only DOFs without mass (a line of "
                "grids without rotary inertia about it: lumped mass, or NASTRAN's coupled CBAR "
                "mass, which has no torsional inertia): such a motion has neither mass nor "
                "stiffness, so it is no mode; held at "
                + ", ".join(ind_labels[j] for j in pinned)
                + f" (as NASTRAN AUTOSPC), leaving {6 - len(pinned)} rigid-body modes"
            )
    if massless.size:
        sparse_path = retained.size > condense_max
        Koo = Kn[massless][:, massless].tocsc()
        try:
            lu = spla.splu(Koo)
            piv = np.abs(lu.U.diagonal())
            singular = piv.min() <= 1e-12 * piv.max()
            if not sparse_path:
                X = -lu.solve(Kn[massless][:, retained].toarray())
        except RuntimeError:
            singular = True
        if singular or not np.all(np.isfinite(X)):
            d = _weak_dofs(Koo)
            labs = ", ".join(ind_labels[massless[i]] for i in d[:6])
            more = f" and {len(d) - 6} more" if len(d) > 6 else ""
            raise InputError(
                f"a massless part of the model is a mechanism (DOFs {labs}{more} have neither "
                "mass nor stiffness against it)",
                where=graph.source or graph.name,
                fix="connect it, or give it mass",
            )
    if massless.size and retained.size > condense_max:
        # above the dense limit the massless DOFs stay coordinates: sparse K and a sparse,
        # positive semi-definite M whose massless rows and columns are exactly zero (the
        # turned null directions of coupled blocks carry rounding otherwise); the sparse
        # solver's inverse form gives their directions mu = 0
        kept_massless = int(massless.size)
        warnings.append(
            f"{kept_massless} DOFs carry no mass (rotations without rotary inertia: lumped "
            "mass, shells, NASTRAN's coupled CBAR mass about the bars' axes); condensing them "
            f"would leave {retained.size} DOFs, a dense matrix beyond the limit of "
            f"{condense_max}, so they are kept as coordinates (a singular mass matrix) and the "
            "model is solved sparsely"
        )
        retained = live
        massless = live[:0]
        X = np.zeros((0, live.size))
        keep_m = np.ones(Mn.shape[0])
        keep_m[live[null[live]]] = 0.0
        Dm = sp.diags(keep_m)
        Mn = sp.csr_matrix(Dm @ Mn @ Dm)
        Mn.eliminate_zeros()
        K_out, M_out = Kn[live][:, live].tocsr(), Mn[live][:, live].tocsr()
        C_out = Cn[live][:, live].tocsr()
        G_out = Gn[live][:, live].tocsr()
    elif massless.size:
        Kd = Kaa.toarray() + np.asarray(Kn[retained][:, massless] @ X)
        K_out = 0.5 * (Kd + Kd.T)
        M_out = Maa.toarray()
        C_out = _condense_full(Cn, retained, massless, X)
        G_out = _condense_full(Gn, retained, massless, X)
    else:
        K_out, M_out = Kaa.tocsr(), Maa.tocsr()
        C_out = Cn[retained][:, retained].tocsr()
        G_out = Gn[retained][:, retained].tocsr()
    labels = tuple(ind_labels[i] for i in retained)

    # mass properties from the unconstrained mass and the exact rigid vectors about a point
    # of the model (its mean node: lever arms of the model's size, not of its distance from
    # the origin, whose rounding would cancel in the shift to the centre of mass)
    P = fm.positions
    total, cm, inertia = mass_properties_of(
        fm.transform.T @ fm.mass @ fm.transform,
        P,
        fm.independent,
        scalar=scalar,
        basis=fm.working,
    )
    # rigid-body vectors: exact unit motions about the centre of mass (lever arms formed once,
    # as microg.structure.fem does), restricted to the retained coordinates
    r_ind = rigid_rows(P, cm, scalar, fm.working)[fm.independent]
    r_ret = (r_ind if Q is None else np.asarray(Q.T @ r_ind))[retained]
    if scalar.any():
        r_ret = _scalar_rigid(K_out, r_ret, labels)
    rigid = (
        {}
        if constrained and applied
        else {d: r_ret[:, k].copy() for k, d in enumerate(("x", "y", "z", "rx", "ry", "rz"))}
    )

    samples = _samples(graph, fm.positions, fm.names, T, retained, massless, X, n_ind)

    node_map = _NodeMap(graph.node_index(), P, T, retained, massless, X, n_ind)
    named = {p.name: _named_map(node_map, p) for p in graph.points}
    points = _PointMaps(
        named,
        node_map,
        {nd.name for nd in graph.nodes if not nd.scalar},
        {nd.name for nd in graph.nodes if nd.scalar},
    )
    meta = {
        "model": graph.name,
        "source": graph.source,
        "format": "graph",
        "mass_formulation": graph.mass_formulation if mass is None else mass,
        "n_nodes": len(graph.nodes),
        "n_elements": len(graph.beams)
        + len(graph.rods)
        + len(graph.shells)
        + len(graph.springs)
        + len(graph.scalar_springs),
        "n_masses": len(graph.masses),
        "n_rigid_elements": len(graph.rigid_links) + len(graph.interpolations),
        "removed": int(unconnected.sum()),
        "condensed": int(massless.size),
        "massless_kept": kept_massless,
        "constraints_applied": tuple(applied),
        "transform": T,
        "damping": C_out,
        "structural_damping": G_out,
        "node_positions": P,
        "node_names": names,
        "warnings": tuple(warnings) + tuple(graph.meta.get("warnings", ())),
        "graph_meta": dict(graph.meta),
    }
    return Structure(
        mass=M_out,
        stiffness=K_out,
        dof_labels=labels,
        points=points,
        rigid_body=rigid,
        method="fem",
        plane=None,
        total_mass=total,
        center_of_mass=cm,
        inertia_cm=inertia,
        samples=samples,
        meta=meta,
    )


def _scalar_rigid(K: Any, r: np.ndarray, labels: tuple[str, ...]) -> np.ndarray:
    """Rigid-body vectors carried onto the scalar points their elements tie to the grids.

    A scalar point takes no part in rigid-body motion by itself (NASTRAN's rigid-body
    geometry is zero there), but one tied by springs to grid components moves with them: its
    motion is the static solution ``K_ss s = -K_sg r_g``.  When the extended vector is in
    the null space of K, it is the exact rigid-body mode; when it is not (a scalar point
    also grounded), the solver's test of ``K r`` rejects it as before.  A singular ``K_ss``
    (a scalar point without stiffness) leaves the vectors as they are.

    Parameters
    ----------
    K : ndarray or sparse (n, n)
        Stiffness on the coordinates.
    r : ndarray (n, 6)
        Rigid-body vectors (zero at the scalar points).
    labels : tuple of str
        Coordinate labels: a scalar point's is its node name (``"spoint:7"``).
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    sc = np.array([lab.startswith("spoint:") and lab.count(":") == 1 for lab in labels], bool)
    if not sc.any():
        return r
    Ks = sp.csr_matrix(K)
    s_idx, g_idx = np.flatnonzero(sc), np.flatnonzero(~sc)
    rhs = -np.asarray(Ks[s_idx][:, g_idx] @ r[g_idx])
    if not np.any(rhs):
        return r
    try:
        lu = spla.splu(sp.csc_matrix(Ks[s_idx][:, s_idx]))
        piv = np.abs(lu.U.diagonal())
        if piv.min() <= 1e-12 * piv.max():
            return r
        out = r.copy()
        out[s_idx] = lu.solve(rhs)
    except RuntimeError:
        return r
    return out


#: coupled mass blocks up to this many DOFs are checked for massless directions
MASS_BLOCK_MAX = 60


def _mass_basis(
    M: sp.csr_matrix, live: np.ndarray, labels: list[str]
) -> tuple[sp.csr_matrix | None, np.ndarray, list[str]]:
    """Orthonormal change of coordinates exposing the massless directions of ``M``.

    ``M`` splits into blocks (connected components of its sparsity among the live DOFs:
    for lumped mass, one node each).  A zero row is massless as it is.  A small block
    (<= MASS_BLOCK_MAX DOFs) with null directions that are not coordinate axes has its
    affected DOFs replaced by an orthonormal basis: the complement of the null space
    (coordinates kept, labelled ``node:dofs:k``) and the null space (massless).  Blocks
    larger than that (consistent mass) are taken as they are.

    Returns
    -------
    Q : sparse (n, n) or None
        ``u_old = Q u_new``; None when no block needed turning.
    null : ndarray (n,) of bool
        Massless coordinates (new).
    labels : list of str
        Coordinate labels (new).
    """
    import scipy.linalg as sla
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components

    n = M.shape[0]
    null = np.zeros(n, bool)
    diag = M.diagonal()
    rows_zero = np.asarray(abs(M).sum(axis=1)).ravel() == 0
    null[live] = rows_zero[live]
    sub = M[live][:, live]
    ncomp, comp = connected_components(sub != 0, directed=False)
    order = np.argsort(comp, kind="stable")
    bounds = np.searchsorted(comp[order], np.arange(ncomp + 1))
    q_rows: list[np.ndarray] = []
    q_cols: list[np.ndarray] = []
    q_vals: list[np.ndarray] = []
    turned = np.zeros(n, bool)
    labels = list(labels)
    for c in range(ncomp):
        idx = live[order[bounds[c] : bounds[c + 1]]]
        if idx.size < 2 or idx.size > MASS_BLOCK_MAX or not np.all(diag[idx] > 0):
            continue
        B = M[idx][:, idx].toarray()
        w, V = np.linalg.eigh(0.5 * (B + B.T))
        nul = w <= 1e-12 * max(float(w.max()), 1e-300)
        if not nul.any():
            continue
        N = V[:, nul]
        affected = np.flatnonzero(np.max(np.abs(N), axis=1) > 1e-12)
        Ns = N[affected]
        C = sla.null_space(Ns.T)
        basis = np.concatenate([C, Ns], axis=1)  # (a, a): kept combinations, then massless
        dofs = idx[affected]
        q_rows.append(np.repeat(dofs, dofs.size))
        q_cols.append(np.tile(dofs, dofs.size))
        q_vals.append(basis.ravel())
        turned[dofs] = True
        null[dofs[C.shape[1] :]] = True
        null[dofs[: C.shape[1]]] = False
        head = labels[dofs[0]].rsplit(":", 1)[0]
        names = "/".join(labels[d].rsplit(":", 1)[1] for d in dofs)
        for k, d in enumerate(dofs):
            labels[d] = f"{head}:{names}:{k + 1}"
    if not turned.any():
        return None, null, labels
    keep = np.flatnonzero(~turned)
    Q = sp.csr_matrix(
        (
            np.concatenate([np.ones(keep.size), *q_vals]),
            (np.concatenate([keep, *q_rows]), np.concatenate([keep, *q_cols])),
        ),
        shape=(n, n),
    )
    return Q, null, labels


@dataclass(frozen=True)
class _NodeMap:
    """The point map of a node, or of a position carried rigidly by it.

    A class rather than a closure, so that a frame model's structure pickles (for the
    figure helper of ``microg analyze`` and for process pools).

    Attributes
    ----------
    index : dict of str to int
        Node name -> row of ``positions``.
    positions : ndarray (n, 3)
        Node positions, m.
    transform : sparse matrix (6 n, n_ind)
        Node DOFs from the independent coordinates.
    retained, massless : ndarray of int
        Independent coordinates kept, and those condensed out by ``condensed``.
    condensed : ndarray or None
        The massless coordinates as a function of the retained ones.
    n_ind : int
        Number of independent coordinates.
    """

    index: dict[str, int]
    positions: np.ndarray
    transform: Any
    retained: np.ndarray
    massless: np.ndarray
    condensed: Any
    n_ind: int

    def __call__(self, name: str, position: np.ndarray | None = None) -> PointMap:
        i = self.index[name]
        node = self.positions[i]
        pos = node if position is None else np.asarray(position, float)
        full = np.zeros((6, self.n_ind))
        full[:] = self.transform[6 * i : 6 * i + 6].toarray()
        coords = full[:, self.retained] + (
            full[:, self.massless] @ self.condensed if self.massless.size else 0.0
        )
        tr = rigid_link(pos - node)[:3] @ coords
        return PointMap(name=name, position=pos.copy(), translation=tr, rotation=coords[3:].copy())


def _named_map(node_map: Any, p: GraphPoint) -> PointMap:
    m = node_map(p.node, p.position)
    return PointMap(
        name=p.name, position=m.position, translation=m.translation, rotation=m.rotation
    )


def _condense_full(A: sp.csr_matrix, a: np.ndarray, o: np.ndarray, X: np.ndarray) -> np.ndarray:
    """``E^T A E`` with ``E = [I; X]`` over the retained (a) and condensed (o) sets, dense."""
    Aaa = A[a][:, a].toarray()
    Aao = A[a][:, o]
    Aoo = A[o][:, o]
    out = Aaa + np.asarray(Aao @ X) + np.asarray(Aao @ X).T + X.T @ np.asarray(Aoo @ X)
    return 0.5 * (out + out.T)


def _pin_massless_rigid(
    r: np.ndarray, retained: np.ndarray, massless: np.ndarray
) -> tuple[np.ndarray, list[int]]:
    """Hold one massless DOF of each rigid-body motion that moves no DOF with mass.

    A rigid motion ``z = R c`` that is zero on every coordinate with mass (``R_r c = 0``) has
    neither mass nor stiffness (``K z = 0``, ``M z = 0``): it is no mode, and it makes the
    massless block ``K_oo`` singular.  Holding a DOF ``j`` where ``z_j != 0`` removes it and
    nothing else: every finite mode ``phi`` has the representative ``phi - (phi_j / z_j) z``
    (also a mode, since ``z`` adds neither energy nor inertia) that is zero at ``j``, so the
    finite eigenpairs are unchanged.  One DOF per such motion, each where the motion is
    largest once the earlier ones are held.

    Parameters
    ----------
    r : ndarray (n, 6)
        The rigid-body vectors on the independent coordinates.
    retained, massless : ndarray of int
        The coordinates with and without mass.

    Returns
    -------
    massless : ndarray of int
        Without the held DOFs.
    pinned : list of int
        The held DOFs (indices of the independent coordinates).
    """
    if massless.size == 0:
        return massless, []
    rr, ro = r[retained], r[massless]
    scale = max(float(np.abs(r).max()), 1e-300)
    # vt is (6, 6) either way; U stays small (n x 6, or n x n only when n < 6)
    _, s, vt = np.linalg.svd(rr, full_matrices=rr.shape[0] < 6)
    rank = int(np.count_nonzero(s > 1e-10 * scale * max(1.0, np.sqrt(rr.shape[0]))))
    c = vt[rank:].T  # combinations of the six motions that move no DOF with mass
    if c.size == 0:
        return massless, []
    z = ro @ c
    pinned: list[int] = []
    for k in range(z.shape[1]):
        col = z[:, k]
        if np.abs(col).max() <= 1e-10 * scale:
            continue  # no motion at all (fewer than six independent rigid motions)
        j = int(np.argmax(np.abs(col)))
        pinned.append(int(massless[j]))
        # the later motions, made zero at j (their span is what remains to hold)
        z[:, k + 1 :] -= np.outer(col / col[j], z[j, k + 1 :])
    keep = ~np.isin(massless, pinned)
    return massless[keep], pinned


def _weak_dofs(Koo: sp.csc_matrix) -> list[int]:
    """Indices of the DOFs that dominate the near-null space of a singular K_oo."""
    if Koo.shape[0] <= 3000:
        w, v = np.linalg.eigh(Koo.toarray())
        null = v[:, np.abs(w) <= 1e-10 * max(float(np.max(np.abs(w))), 1e-300)]
        if null.size:
            weight = np.max(np.abs(null), axis=1)
            return [int(i) for i in np.flatnonzero(weight > 0.1 * weight.max())]
    zero = [int(i) for i in np.flatnonzero(np.asarray(abs(Koo).sum(axis=1)).ravel() == 0)]
    if zero or Koo.shape[0] <= 3000:
        return zero
    # a large K_oo (a model above the dense limit): a few inverse iterations with a tiny
    # shift find the motion it barely resists
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    n = Koo.shape[0]
    scale = float(abs(Koo).max()) or 1.0
    try:
        lu = spla.splu(sp.csc_matrix(Koo + 1e-10 * scale * sp.identity(n)))
    except RuntimeError:
        return []
    v = np.random.default_rng(0).standard_normal(n)
    for _ in range(4):
        v = lu.solve(v)
        v /= np.linalg.norm(v)
    weight = np.abs(v)
    return [int(i) for i in np.flatnonzero(weight > 0.1 * weight.max())]


def _samples(
    graph: GraphModel,
    positions: np.ndarray,
    names: tuple[str, ...],
    T: sp.csr_matrix,
    retained: np.ndarray,
    massless: np.ndarray,
    X: np.ndarray,
    n_ind: int,
) -> FrameSamples:
    """Samples at the connected nodes and at the concentrated masses off their nodes."""
    import scipy.sparse as sp

    live = np.zeros(n_ind, bool)
    live[retained] = True
    live[massless] = True
    # a node is a sample if some DOF of it depends on a live coordinate (a scalar point is
    # not a point in space: never a sample)
    reach = np.asarray(abs(T) @ live.astype(float)).reshape(-1, 6).sum(axis=1) > 0
    reach &= ~np.array([nd.scalar for nd in graph.nodes], bool)
    nodes = [int(i) for i in np.flatnonzero(reach)]
    offs = [np.zeros(3)] * len(nodes)
    labels = [names[i] for i in nodes]
    index = graph.node_index()
    for m in graph.masses:
        if np.any(m.offset_m):
            i = index[m.node]
            nodes.append(i)
            offs.append(np.asarray(m.offset_m, float))
            # a station's body masses are named "body/mass" (graph_from_station): kept as they
            # are, the labels of microg.structure.fem's samples
            labels.append(m.name if "/" in m.name else f"{m.node}/{m.name}")
    # carriers as the acceleration maps read frame labels: "keel:n3" -> "keel" (a station's
    # beam, whose samples form a line), "core/orbiter" -> "core", "grid:7" -> "grid"
    comp = [lab.split("/", 1)[0].split(":", 1)[0] for lab in labels]
    nodes_arr = np.asarray(nodes, int)
    offset = np.array(offs, float).reshape(-1, 3)
    sel = (6 * nodes_arr[:, None] + np.arange(6)).ravel()
    rows = sp.csr_matrix(T[sel])
    # the independent set, with the condensed DOFs recovered and everything else zero
    keep_idx = np.zeros(n_ind, bool)
    keep_idx[retained] = True
    keep_idx[massless] = True
    rows = sp.csr_matrix(rows @ sp.diags(keep_idx.astype(float)))
    return FrameSamples(
        position=positions[nodes_arr] + offset,
        labels=tuple(labels),
        component=np.array(comp, dtype=str),
        offset=offset,
        rows=rows,
        retained=retained,
        condensed=massless,
        recovery=X,
        n_ind=n_ind,
    )
