"""Rigid elements and constraints on frame DOFs: RBE2, RBE3 and MPC eliminated exactly.

**Rigid links** (RBE2): the dependent components are eliminated exactly,
  ``u_d = u_i + theta_i x (x_d - x_i)``, ``theta_d = theta_i`` (no penalty).  **Interpolation**
(RBE3): the reference node's motion is NASTRAN's weighted least-squares rigid-body fit of the
  independent components, translations and rotations
  (:func:`~microg.structure.elements.interpolation_matrix`), eliminated the same way; with UM
  the element's equations are solved for the UM components instead.  It adds no stiffness and
  moves rigid-body motion exactly.  **MPC**: ``sum a_j u_j = 0`` solved for its first term.
  Chains are resolved; a component dependent twice (naming both elements), or a cycle, is an
  error.

The equations are written on *working* DOFs: the basic-frame DOFs of each node, except at a
node with rotated axes that has dependent or constrained components (:func:`turned_nodes`),
whose DOFs are along its own axes (NASTRAN's global system), so that any subset of a triple
can be dependent.  Single-point constraints (SPC) and the links name components along a
node's axes: :func:`basic_dofs` maps them to basic-frame DOFs elsewhere.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from microg.errors import InputError
from microg.models.graph_model import GraphModel, Node
from microg.structure.elements import interpolation_matrix, rigid_link

if TYPE_CHECKING:  # scipy loads on first use
    import scipy.sparse as sp

__all__ = ["basic_dofs", "link_transform", "turned_nodes", "working_basis"]


def basic_dofs(node: Node, comps: str, *, where: str) -> list[int]:
    """Basic-frame DOF offsets (0-5) of a node's components: exact for full triples.

    Parameters
    ----------
    node : Node
        Its axes say which basic directions its components are.
    comps : str
        Component digits (``"123456"``).
    where : str
        The element or constraint, for errors (a partial triple along rotated axes).
    """
    rotated = not np.allclose(node.axes, np.eye(3), atol=1e-12)
    out: list[int] = []
    for base, triple in ((0, "123"), (3, "456")):
        have = [c for c in triple if c in comps]
        if rotated and 0 < len(have) < 3:
            raise InputError(
                f"components {''.join(have)} of node {node.name!r} are along its rotated axes "
                f"({node.frame}); only all of {triple} or none can be constrained there",
                where=where,
                fix=f"use all of {triple}, or give the node basic axes (CD = 0)",
            )
        out += [base + triple.index(c) for c in have]
    return out


def turned_nodes(graph: GraphModel) -> np.ndarray:
    """Which nodes take their DOFs along their own axes (NASTRAN's global system).

    A node with rotated axes (GRID CD) that is dependent somewhere (RBE2, RBE3 and its UM,
    MPC) or single-point constrained: its dependent or constrained components are then single
    DOFs, whatever subset of a triple they are.  Every other node keeps its basic-frame DOFs.

    Parameters
    ----------
    graph : GraphModel
    """
    index = graph.node_index()
    named: set[str] = set()
    for rl in graph.rigid_links:
        named.update(rl.dependents)
    for ip in graph.interpolations:
        named.add(ip.reference)
        named.update(nd for nd, _ in ip.moved)
    for mp in graph.mpcs:
        named.add(mp.terms[0][0])
    named.update(c.node for c in graph.constraints)
    out = np.zeros(len(graph.nodes), bool)
    for nd in named:
        i = index[nd]
        out[i] = not np.allclose(graph.nodes[i].axes, np.eye(3), atol=1e-12)
    return out


def working_basis(graph: GraphModel, turned: np.ndarray) -> sp.csr_matrix | None:
    """``u_basic = R u_work``: block-diagonal node axes (transposed) of the turned nodes.

    Parameters
    ----------
    graph : GraphModel
    turned : ndarray of bool
        :func:`turned_nodes`.

    Returns
    -------
    sparse CSR (6 nn, 6 nn), or None when no node is turned (``R = I``).
    """
    import scipy.sparse as sp

    if not turned.any():
        return None
    n = 6 * len(graph.nodes)
    rows: list[np.ndarray] = []
    cols: list[np.ndarray] = []
    vals: list[np.ndarray] = []
    plain = np.flatnonzero(~turned)
    d = (6 * plain[:, None] + np.arange(6)).ravel()
    rows.append(d)
    cols.append(d)
    vals.append(np.ones(d.size))
    for i in np.flatnonzero(turned):
        a = np.asarray(graph.nodes[i].axes, float)
        for b in (0, 3):
            base = 6 * i + b
            # u_basic[m] = sum_j axes[j, m] u_work[j]
            rows.append(np.repeat(base + np.arange(3), 3))
            cols.append(np.tile(base + np.arange(3), 3))
            vals.append(a.T.ravel())
    R = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )
    return R


class _Rows:
    """Node components and basic DOFs as rows over the working DOFs (private)."""

    def __init__(self, graph: GraphModel, turned: np.ndarray):
        self.nodes = graph.nodes
        self.turned = turned
        self.plain = np.array(
            [np.allclose(nd.axes, np.eye(3), atol=1e-12) for nd in graph.nodes], bool
        )

    def component(self, i: int, c: int) -> tuple[np.ndarray, np.ndarray]:
        """Component ``c`` (0-5, along the node's axes) of node ``i``."""
        if self.turned[i] or self.plain[i]:
            return np.array([6 * i + c]), np.ones(1)
        b = 3 * (c // 3)
        return 6 * i + b + np.arange(3), np.asarray(self.nodes[i].axes, float)[c % 3]

    def basic(self, i: int, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Basic DOF ``k`` (0-5) of node ``i``."""
        if not self.turned[i]:
            return np.array([6 * i + k]), np.ones(1)
        b = 3 * (k // 3)
        return 6 * i + b + np.arange(3), np.asarray(self.nodes[i].axes, float)[:, k % 3]

    def dependent(self, i: int, comps: str, where: str) -> list[tuple[int, np.ndarray]]:
        """(working DOF, weights over the node's 6 basic DOFs) of each dependent component.

        The working DOF is the component itself on a turned or basic node, else the basic
        DOF of a full triple (:func:`basic_dofs`).
        """
        if self.turned[i]:
            a6 = np.zeros((6, 6))
            a6[:3, :3] = a6[3:, 3:] = np.asarray(self.nodes[i].axes, float)
            return [(6 * i + int(ch) - 1, a6[int(ch) - 1]) for ch in comps]
        out = []
        for k in basic_dofs(self.nodes[i], comps, where=where):
            e = np.zeros(6)
            e[k] = 1.0
            out.append((6 * i + k, e))
        return out


def link_transform(
    graph: GraphModel, P: np.ndarray, index: dict[str, int]
) -> tuple[sp.csr_matrix, np.ndarray, sp.csr_matrix | None]:
    """``u_g = T u_ind`` from the rigid links, interpolations and MPCs (chains resolved).

    Each dependent component is a linear equation in the node DOFs (the rigid link
    ``u_d = u_i + theta_i x d``, the RBE3 fit, an MPC solved for its first term); with ``G``
    those equations, ``u_m = G_mm u_m + G_mn u_n`` is solved for the dependent set ``m``:
    ``X = (I - G_mm)^-1 G_mn`` (a chain of links through a sparse LU).  An RBE3 with UM has
    its equations ``q_ref - W s = 0`` solved for the UM components instead (their block must
    be invertible).  The equations are written on the *working* DOFs: basic-frame DOFs,
    except at the :func:`turned_nodes`, whose DOFs are along their own axes.

    Parameters
    ----------
    graph : GraphModel
    P : ndarray (nn, 3)
        Node positions, m.
    index : dict of str to int
        Node name -> row of ``P``.

    Returns
    -------
    T : sparse CSR (6 nn, n_ind)
        Basic-frame g-set DOFs from the independent working DOFs.
    independent : ndarray of int
        The working DOFs (``6 node + k``) that are the columns of ``T``.
    working : sparse CSR (6 nn, 6 nn) or None
        ``u_basic = working @ u_work`` (:func:`working_basis`); None: the working DOFs are
        the basic ones.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    n = 6 * P.shape[0]
    turned = turned_nodes(graph)
    R = working_basis(graph, turned)
    rows = _Rows(graph, turned)
    eq_rows: list[np.ndarray] = []
    eq_cols: list[np.ndarray] = []
    eq_vals: list[np.ndarray] = []
    dep: dict[int, str] = {}
    count = 0

    def dof_name(dof: int) -> str:
        node = graph.nodes[dof // 6]
        axis = "along its axes" if turned[dof // 6] or rows.plain[dof // 6] else "basic"
        return f"component {dof % 6 + 1} of node {node.name!r}" + (
            "" if axis == "along its axes" else f" (basic DOF {dof % 6 + 1})"
        )

    def add(dof: int, cols: np.ndarray, vals: np.ndarray, owner: str) -> None:
        nonlocal count
        if dof in dep:
            raise InputError(
                f"{dof_name(dof)} is dependent in both {dep[dof]} and {owner}",
                where=owner,
                fix="make each component dependent in one rigid element or MPC only",
            )
        dep[dof] = owner
        keep = cols != dof
        if not np.all(keep) and np.any(np.abs(vals[~keep]) > 1e-12):
            raise InputError(
                f"{dof_name(dof)} depends on itself", where=owner, fix="check the equation"
            )
        eq_rows.append(np.full(int(keep.sum()), count))
        eq_cols.append(cols[keep])
        eq_vals.append(vals[keep])
        count += 1

    def over_basic(i: int, coef6: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The row ``coef6 . u_basic(node i)`` over the working DOFs."""
        cs, vs = [], []
        for k in np.flatnonzero(coef6):
            c, v = rows.basic(i, int(k))
            cs.append(c)
            vs.append(coef6[k] * v)
        if not cs:
            return np.zeros(0, int), np.zeros(0)
        return np.concatenate(cs), np.concatenate(vs)

    for rl in graph.rigid_links:
        ii = index[rl.independent]
        for dn in rl.dependents:
            di = index[dn]
            t = rigid_link(P[di] - P[ii])  # u_d(basic) = t u_i(basic)
            for dof, a6 in rows.dependent(di, rl.components, rl.name):
                c, v = over_basic(ii, a6 @ t)
                add(dof, c, v, rl.name)
    for ip in graph.interpolations:
        ri = index[ip.reference]
        pos, dirs, wts, rot, cols, vals, nodes = [], [], [], [], [], [], set()
        for nd, comps, w in ip.sources:
            i = index[nd]
            nodes.add(i)
            for ch in comps:
                ci = int(ch) - 1
                pos.append(P[i])
                dirs.append(graph.nodes[i].axes[ci % 3])
                wts.append(w)
                rot.append(ci >= 3)
                cc, vv = rows.component(i, ci)
                cols.append(cc)
                vals.append(vv)
        others = sorted(nodes - {ri})
        lc = float(np.linalg.norm(P[others] - P[ri], axis=1).mean()) if others else 0.0
        W = interpolation_matrix(
            P[ri],
            np.array(pos),
            np.array(dirs),
            np.array(wts),
            rotational=np.array(rot),
            length_m=lc,
            where=ip.name,
        )
        # q(basic, 6) = W s: expand onto the sources' working DOFs
        src_cols = np.concatenate(cols)
        src_vals = np.concatenate([W[:, k : k + 1] * v[None, :] for k, v in enumerate(vals)], 1)
        deps = rows.dependent(ri, ip.components, ip.name) if not ip.moved else None
        if deps is not None:
            for dof, a6 in deps:
                add(dof, src_cols, a6 @ src_vals, ip.name)
            continue
        _moved(graph, ip, index, rows, src_cols, src_vals, add)
    for mp in graph.mpcs:
        terms = [(rows.component(index[nd], comp - 1), coef) for nd, comp, coef in mp.terms]
        (c0, v0), a0 = terms[0]
        if c0.size != 1:
            raise InputError(
                f"the dependent component {mp.terms[0][1]} of {mp.terms[0][0]!r} is not a "
                "single DOF",
                where=mp.name,
            )
        cs = np.concatenate([c for (c, _), _ in terms[1:]]) if len(terms) > 1 else np.zeros(0, int)
        vs = (
            np.concatenate([-a / a0 * v for (_, v), a in terms[1:]])
            if len(terms) > 1
            else np.zeros(0)
        )
        add(int(c0[0]), cs, vs, mp.name)
    if not dep:
        T0 = sp.identity(n, format="csr") if R is None else sp.csr_matrix(R)
        return T0, np.arange(n), R
    m_dofs = np.array(list(dep))
    is_dep = np.zeros(n, bool)
    is_dep[m_dofs] = True
    ind = np.flatnonzero(~is_dep)
    G = sp.coo_matrix(
        (np.concatenate(eq_vals), (np.concatenate(eq_rows), np.concatenate(eq_cols))),
        shape=(count, n),
    ).tocsc()
    Gmm = G[:, m_dofs]
    Gmn = G[:, ind]
    A = (sp.identity(m_dofs.size, format="csc") - Gmm).tocsc()
    if Gmm.nnz:
        try:
            lu = spla.splu(A)
        except RuntimeError:
            raise InputError(
                "rigid elements form a cycle (a node depends on itself through a chain)",
                where=", ".join(sorted(set(dep.values()))[:5]),
                fix="break the chain: one independent node per rigid assembly",
            ) from None
        X = (
            sp.csr_matrix(lu.solve(Gmn.toarray()))
            if m_dofs.size * ind.size <= 4e7
            else _chain_solve(A, Gmn)
        )
    else:
        X = sp.csr_matrix(Gmn)
    X = X.tocoo()
    t_rows = np.concatenate([ind, m_dofs[X.row]])
    t_cols = np.concatenate([np.arange(ind.size), X.col])
    t_vals = np.concatenate([np.ones(ind.size), X.data])
    T = sp.csr_matrix((t_vals, (t_rows, t_cols)), shape=(n, ind.size))
    if R is not None:
        T = sp.csr_matrix(R @ T)
    T.eliminate_zeros()
    return T, ind, R


def _moved(
    graph: GraphModel,
    ip: Any,
    index: dict[str, int],
    rows: _Rows,
    src_cols: np.ndarray,
    src_vals: np.ndarray,
    add: Any,
) -> None:
    """An RBE3's equations solved for its UM components (NASTRAN's alternate m-set).

    The element's equations are ``a_c . u_ref - (W s)_c = 0`` for each reference component
    ``c``; with ``E`` their coefficients over the element's working DOFs, the UM DOFs ``m``
    are ``u_m = -E_m^-1 E_n u_n`` (pyyeti ``n2p.formrbe3``'s UM option; NX 9's GM).
    """
    ri = index[ip.reference]
    eqs = []
    for _, a6 in rows.dependent(ri, ip.components, ip.name):
        c_ref, v_ref = [], []
        for k in np.flatnonzero(a6):
            c, v = rows.basic(ri, int(k))
            c_ref.append(c)
            v_ref.append(a6[k] * v)
        eqs.append((np.concatenate(c_ref), np.concatenate(v_ref), a6))
    # one dense block over the element's DOFs: small (at most 6 rows)
    lcols = sorted(set(src_cols.tolist()) | {int(c) for e in eqs for c in e[0]})
    pos = {c: j for j, c in enumerate(lcols)}
    E = np.zeros((len(eqs), len(lcols)))
    for r, (cr, vr, a6) in enumerate(eqs):
        np.add.at(E[r], [pos[int(c)] for c in cr], vr)
        np.add.at(E[r], [pos[int(c)] for c in src_cols], -(a6 @ src_vals))
    um: list[int] = []
    for nd, comps in ip.moved:
        i = index[nd]
        for ch in comps:
            c, _ = rows.component(i, int(ch) - 1)
            if c.size != 1 or int(c[0]) not in pos:
                raise InputError(
                    f"UM component {ch} of {nd!r} is not one of the element's DOFs",
                    where=ip.name,
                    fix="UM names components among REFC and the independent ones",
                )
            um.append(int(c[0]))
    if len(um) != len(eqs) or len(set(um)) != len(um):
        raise InputError(
            f"UM names {len(um)} distinct component(s) where REFC has {len(eqs)}",
            where=ip.name,
            fix="give UM as many components as REFC",
        )
    jm = [pos[c] for c in um]
    jn = [j for j in range(len(lcols)) if j not in set(jm)]
    Em = E[:, jm]
    if np.linalg.cond(Em) > 1e12:
        raise InputError(
            "the UM components cannot be solved for (their block of the equations is singular)",
            where=ip.name,
            fix="choose other UM components, as for a SUPORT",
        )
    X = -np.linalg.solve(Em, E[:, jn])
    cn = np.array([lcols[j] for j in jn], int)
    for r, dof in enumerate(um):
        nz = np.abs(X[r]) > 0
        add(dof, cn[nz], X[r, nz], ip.name)


def _chain_solve(A: sp.csc_matrix, B: sp.csc_matrix) -> sp.csr_matrix:
    """Sparse solve of (I - G_mm) X = G_mn by repeated substitution (acyclic chains)."""
    import scipy.sparse as sp

    Gmm = sp.identity(A.shape[0], format="csr") - A
    X = sp.csr_matrix(B)
    term = X
    for _ in range(A.shape[0] + 1):
        term = sp.csr_matrix(Gmm @ term)
        term.eliminate_zeros()
        if term.nnz == 0:
            return X
        X = X + term
    raise InputError("rigid elements form a cycle", fix="break the chain of dependent nodes")
