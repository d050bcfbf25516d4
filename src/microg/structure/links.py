"""Rigid elements and constraints on frame DOFs: RBE2 and RBE3 eliminated exactly.

**Rigid links** (RBE2): the dependent components are eliminated exactly,
  ``u_d = u_i + theta_i x (x_d - x_i)``, ``theta_d = theta_i`` (no penalty).  **Interpolation**
(RBE3): the reference node's motion is the weighted least-squares rigid-body fit of the
  independent nodes' translations (the sources' components along their axes), eliminated
  exactly the same way; it adds no stiffness and moves rigid-body motion exactly.  Chains
  of links are resolved; a component dependent twice, or a cycle, is an error.

Single-point constraints (SPC) and the links name components along a node's axes:
:func:`basic_dofs` maps them to basic-frame DOFs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from microg.errors import InputError
from microg.models.graph_model import GraphModel, Node
from microg.structure.elements import interpolation_matrix, rigid_link

if TYPE_CHECKING:  # scipy loads on first use
    import scipy.sparse as sp

__all__ = ["basic_dofs", "link_transform"]


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


def link_transform(
    graph: GraphModel, P: np.ndarray, index: dict[str, int]
) -> tuple[sp.csr_matrix, np.ndarray]:
    """``u_g = T u_ind`` from the rigid links and interpolations (chains resolved exactly).

    Each dependent component is a linear equation in the node DOFs (the rigid link
    ``u_d = u_i + theta_i x d``, or the RBE3 fit); with ``G`` those equations,
    ``u_m = G_mm u_m + G_mn u_n`` is solved for the dependent set ``m``:
    ``X = (I - G_mm)^-1 G_mn`` (a chain of links through a sparse LU).

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
    independent : ndarray of int
        The g-set DOFs that are the columns of ``T``.
    """
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    n = 6 * P.shape[0]
    eq_rows: list[np.ndarray] = []
    eq_cols: list[np.ndarray] = []
    eq_vals: list[np.ndarray] = []
    dep: dict[int, str] = {}
    count = 0

    def add(dof: int, cols: np.ndarray, vals: np.ndarray, owner: str) -> None:
        nonlocal count
        if dof in dep:
            node = graph.nodes[dof // 6].name
            raise InputError(
                f"component {dof % 6 + 1} of node {node!r} is dependent in both "
                f"{dep[dof]} and {owner}",
                where=owner,
                fix="make each component dependent in one rigid element only",
            )
        dep[dof] = owner
        eq_rows.append(np.full(cols.size, count))
        eq_cols.append(cols)
        eq_vals.append(vals)
        count += 1

    for rl in graph.rigid_links:
        ii = index[rl.independent]
        for dn in rl.dependents:
            di = index[dn]
            t = rigid_link(P[di] - P[ii])
            for k in basic_dofs(graph.nodes[di], rl.components, where=rl.name):
                nz = np.flatnonzero(t[k])
                add(6 * di + k, 6 * ii + nz, t[k, nz], rl.name)
    for ip in graph.interpolations:
        ri = index[ip.reference]
        pos, dirs, wts, cols = [], [], [], []
        for nd, comps, w in ip.sources:
            i = index[nd]
            for ch in comps:
                c = int(ch) - 1
                pos.append(P[i])
                dirs.append(graph.nodes[i].axes[c])
                wts.append(w)
                cols.append(6 * i + np.arange(3))
        W = interpolation_matrix(P[ri], np.array(pos), np.array(dirs), np.array(wts), where=ip.name)
        # source component s_k = e_k . u_k: expand W (6, k) onto the sources' basic DOFs
        full_cols = np.concatenate(cols)
        full_vals = (W[:, :, None] * np.array(dirs)[None, :, :]).reshape(6, -1)
        for k in basic_dofs(graph.nodes[ri], ip.components, where=ip.name):
            add(6 * ri + k, full_cols, full_vals[k], ip.name)
    if not dep:
        return sp.identity(n, format="csr"), np.arange(n)
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
    T.eliminate_zeros()
    return T, ind


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
