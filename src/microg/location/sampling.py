"""Samples along the structure: their mode shapes, straight lines, and the nodes of a mode.

A :class:`~microg.structure.Structure` built by either discretisation carries ``samples``
(assumed modes: :class:`~microg.structure.ritz.RitzSamples`, 41 per beam and the masses of
each body; frame elements: :class:`~microg.structure.fem.NodeSamples`, the mesh nodes).
This module turns them into what the location stage needs:

* :func:`sample_shapes`: positions, carriers and modal translations of the samples;
* :func:`sample_lines`: the samples grouped into straight lines (a beam; a rigid body whose
  samples are collinear), rigid lines filled densely by their exact affine law;
* :func:`element_lines`: straight chains of two-node elements between samples (the beams
  and rods of a general frame model, whose nodes carry no beam names);
* :func:`find_nodes`: the sign changes of a displacement along each line (the nodes of the
  fundamental mode, report conclusion 7), located by linear interpolation.

Kernels take SI floats and numpy arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from microg.errors import InputError
from microg.structure.structure import Structure

__all__ = [
    "BODY_LINE_SAMPLES",
    "STRAIGHT_TOL",
    "Node",
    "SampleLine",
    "element_lines",
    "find_nodes",
    "sample_lines",
    "sample_shapes",
]

#: rigid-body lines are densified to at least this many samples
BODY_LINE_SAMPLES = 121
#: two elements meeting at a node continue one straight line when the cosine of the angle
#: between them is below ``-(1 - STRAIGHT_TOL)`` (about 4e-5 rad)
STRAIGHT_TOL = 1e-9


@dataclass(frozen=True)
class SampleLine:
    """A straight line of samples (a beam, or a rigid body whose samples are collinear).

    Attributes
    ----------
    component : str
        Beam or body name.
    index : ndarray (k,) of int
        Sample indices, ordered along the line.
    origin : ndarray (3,)
        Position of the first sample, m.
    axis : ndarray (3,)
        Unit vector along the line.
    rigid : bool
        True when every mode shape is affine along the line (a rigid body).
    """

    component: str
    index: np.ndarray
    origin: np.ndarray
    axis: np.ndarray
    rigid: bool


@dataclass(frozen=True)
class Node:
    """A node (sign change of the displacement) of a mode along a line of samples.

    Attributes
    ----------
    component : str
        Beam or body it lies on.
    position : ndarray (3,)
        Station-frame position, m.
    distance : float
        Distance along the line from its first sample, m.
    """

    component: str
    position: np.ndarray
    distance: float

    def to_dict(self) -> dict:
        """``{"component", "position_m", "distance_m"}``."""
        return {
            "component": self.component,
            "position_m": [float(v) for v in self.position],
            "distance_m": float(self.distance),
        }


def _sample_components(structure: Structure) -> np.ndarray:
    samples = structure.samples
    comp = getattr(samples, "component", None)
    if comp is not None:
        return np.asarray(comp).astype(str)
    labels = getattr(samples, "labels", None)
    if labels is None:
        raise InputError(
            "the structure has no samples",
            where="structure",
            fix="build it with microg.structure.discretize.discretize",
        )
    # frame samples: "beam:nK" nodes, "body/mass" masses, "body" master nodes
    return np.array([lab.split("/", 1)[0].split(":", 1)[0] for lab in labels])


def sample_shapes(
    structure: Structure, phi: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions (p, 3), carriers (p,) and modal translations (p, 3, m) of the samples.

    Parameters
    ----------
    structure : Structure
        With ``samples`` (:func:`microg.structure.discretize.discretize` builds them).
    phi : ndarray (n, m)
        Mode shapes, one per column (mass-normalised: translations in m/sqrt(kg)).

    Returns
    -------
    positions : ndarray (p, 3)
        m.
    component : ndarray (p,) of str
        Body or beam carrying each sample.
    shapes : ndarray (p, 3, m)
        Translation of each sample per unit modal coordinate.
    """
    samples = structure.samples
    if samples is None:
        raise InputError(
            "the structure has no samples",
            where="structure",
            fix="build it with microg.structure.discretize.discretize",
        )
    phi = np.asarray(phi, float)
    if hasattr(samples, "displacement"):
        shapes = np.asarray(samples.displacement(phi))
        if shapes.ndim == 2:
            shapes = shapes[:, :, None]
    else:
        shapes = np.einsum("pan,nm->pam", samples.translation, phi)
    return np.asarray(samples.position, float), _sample_components(structure), shapes


def _collinear(pos: np.ndarray, tol: float = 1e-9) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre, unit axis) if the points lie on one line (at least two distinct), else None."""
    if pos.shape[0] < 2:
        return None
    c = pos.mean(axis=0)
    _, s, vt = np.linalg.svd(pos - c, full_matrices=False)
    if s[0] <= 0:
        return None
    if s.size > 1 and s[1] > tol * s[0]:
        return None
    axis = vt[0]
    axis = axis * (1.0 if axis[np.argmax(np.abs(axis))] > 0 else -1.0)
    return c, axis


def _affine_fit(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, bool]:
    """Least-squares affine fit of rows ``y`` (k, q) in ``t`` (k,); True if exact to rounding."""
    design = np.column_stack([np.ones_like(t), t])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    resid = float(np.max(np.abs(design @ coef - y))) if y.size else 0.0
    return coef, resid <= 1e-9 * max(float(np.max(np.abs(y))) if y.size else 0.0, 1e-300)


def sample_lines(
    positions: np.ndarray, component: np.ndarray, shapes: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[SampleLine]]:
    """Group samples into straight lines; densify rigid lines (exact: shapes are affine there).

    A carrier's samples form a line when they are collinear.  The line is *rigid* when every
    mode shape is affine along it (checked to rounding).  Beyond each end, the nearest sample
    of another carrier lying on the line within one sample spacing joins it (a beam's root
    node owned by its parent, a beam root on a body), if on a rigid line it obeys the same
    affine law; so sign changes at joints are not missed.  Rigid lines are then filled to
    :data:`BODY_LINE_SAMPLES` evenly spaced samples by the affine law, which is exact.

    Parameters
    ----------
    positions : ndarray (p, 3)
        Sample positions, m.
    component : ndarray (p,) of str
        Carrier of each sample.
    shapes : ndarray (p, 3, m)
        Modal translations of the samples.

    Returns
    -------
    positions, component, shapes
        The samples with the densified ones appended (same layouts as the inputs).
    lines : list of SampleLine
    """
    lines: list[SampleLine] = []
    pos_out, comp_out, shp_out = [positions], [component], [shapes]
    n_total = positions.shape[0]
    scale = float(np.ptp(positions, axis=0).max()) or 1.0
    flat = shapes.reshape(shapes.shape[0], -1)
    for name in dict.fromkeys(component.tolist()):
        own = np.flatnonzero(component == name)
        geo = _collinear(positions[own])
        if geo is None:
            continue
        c, axis = geo
        rel = positions - c
        t_all = rel @ axis
        on_line = np.linalg.norm(rel - np.outer(t_all, axis), axis=1) <= 1e-9 * scale
        t_own = t_all[own]
        order = np.argsort(t_own, kind="stable")
        idx, t_idx = own[order], t_own[order]
        keep = np.r_[True, np.diff(t_idx) > 1e-9 * scale]
        idx, t_idx = idx[keep], t_idx[keep]
        if idx.size < 2:
            continue
        coef, rigid = _affine_fit(t_idx, flat[idx])
        step = float(np.max(np.diff(t_idx)))
        foreign = on_line & (component != name)
        for side in (-1.0, 1.0):
            end = t_idx[0] if side < 0 else t_idx[-1]
            gap = side * (t_all - end)
            cand = np.flatnonzero(foreign & (gap > 1e-9 * scale) & (gap <= 1.01 * step))
            if cand.size == 0:
                continue
            k = int(cand[np.argmin(gap[cand])])
            if rigid:
                pred = coef[0] + coef[1] * t_all[k]
                if np.max(np.abs(pred - flat[k])) > 1e-9 * max(np.max(np.abs(flat[idx])), 1e-300):
                    continue
            idx = np.r_[k, idx] if side < 0 else np.r_[idx, k]
            t_idx = np.r_[t_all[k], t_idx] if side < 0 else np.r_[t_idx, t_all[k]]
        if rigid and idx.size < BODY_LINE_SAMPLES:
            t_new = np.linspace(t_idx[0], t_idx[-1], BODY_LINE_SAMPLES)
            t_new = t_new[np.min(np.abs(t_new[:, None] - t_idx[None, :]), axis=1) > 1e-6 * scale]
            if t_new.size:
                new_flat = np.column_stack([np.ones_like(t_new), t_new]) @ coef
                pos_out.append(c + np.outer(t_new, axis))
                comp_out.append(np.full(t_new.size, name))
                shp_out.append(new_flat.reshape(t_new.size, *shapes.shape[1:]))
                new_idx = n_total + np.arange(t_new.size)
                n_total += t_new.size
                all_t = np.r_[t_idx, t_new]
                all_i = np.r_[idx, new_idx]
                order = np.argsort(all_t, kind="stable")
                idx, t_idx = all_i[order], all_t[order]
        lines.append(SampleLine(name, idx, c + t_idx[0] * axis, axis, rigid))
    return (
        np.concatenate(pos_out),
        np.concatenate(comp_out),
        np.concatenate(shp_out),
        lines,
    )


def find_nodes(
    lines: Sequence[SampleLine], positions: np.ndarray, lateral: np.ndarray
) -> tuple[Node, ...]:
    """Sign changes of ``lateral`` (p,) along each line, located by linear interpolation.

    Exact on rigid lines (the displacement is affine there); on a beam sampled 40 times
    the interpolated zero is within ``(h/L)^2 max|psi''| / 8`` of the peak of a cubic shape.

    Parameters
    ----------
    lines : sequence of SampleLine
    positions : ndarray (p, 3)
        Sample positions, m.
    lateral : ndarray (p,)
        The displacement whose zeros are wanted (any unit).
    """
    out: list[Node] = []
    seen: list[np.ndarray] = []
    scale = float(np.ptp(positions, axis=0).max()) or 1.0
    for line in lines:
        y = lateral[line.index]
        p = positions[line.index]
        a, b = y[:-1], y[1:]
        cross = (a * b < 0) | ((a == 0) & (b != 0))
        for k in np.flatnonzero(cross):
            frac = a[k] / (a[k] - b[k])
            pos = p[k] + frac * (p[k + 1] - p[k])
            if any(np.linalg.norm(pos - q) <= 1e-6 * scale for q in seen):
                continue
            seen.append(pos)
            out.append(Node(line.component, pos, float((pos - line.origin) @ line.axis)))
        if (
            y.size
            and y[-1] == 0
            and not any(np.linalg.norm(p[-1] - q) <= 1e-6 * scale for q in seen)
        ):
            seen.append(p[-1])
            out.append(Node(line.component, p[-1], float((p[-1] - line.origin) @ line.axis)))
    return tuple(out)


def element_lines(
    positions: np.ndarray,
    segments: np.ndarray,
    *,
    labels: Sequence[str] | None = None,
    covered: np.ndarray | None = None,
) -> list[SampleLine]:
    """Straight chains of two-node elements between samples (a frame model's beam lines).

    Two elements meeting at a node belong to one line when they continue each other
    straight through it (anti-parallel within :data:`STRAIGHT_TOL` in cosine) and neither
    has another straight continuation there (a node where three collinear elements meet
    ends the lines).  A line is the chain's samples ordered along its axis; it is never
    rigid (the displacement between samples is interpolated linearly, as along a meshed
    beam).

    Parameters
    ----------
    positions : ndarray (p, 3)
        Sample positions, m.
    segments : ndarray (s, 2) of int
        Sample indices of each element's two nodes.
    labels : sequence of str, optional
        Sample labels; a line is named ``"<first>..<last>"`` by its end samples (default
        ``"line:K"``).
    covered : ndarray (p,) of bool, optional
        Samples already on a line: elements with both ends covered are left out.

    Returns
    -------
    list of SampleLine
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    seg = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    if covered is not None:
        seg = seg[~(covered[seg[:, 0]] & covered[seg[:, 1]])]
    seg = np.sort(seg, axis=1)
    seg = seg[seg[:, 0] != seg[:, 1]]
    scale = float(np.ptp(positions, axis=0).max()) if positions.size else 1.0
    vec = positions[seg[:, 1]] - positions[seg[:, 0]]
    length = np.linalg.norm(vec, axis=1)
    keep = length > 1e-9 * (scale or 1.0)
    seg, vec, length = seg[keep], vec[keep], length[keep]
    if seg.size == 0:
        return []
    seg, first = np.unique(seg, axis=0, return_index=True)
    u = vec[first] / length[first, None]
    ns = seg.shape[0]
    # incidences: (node, element, unit vector from the node along the element)
    inc_node = np.r_[seg[:, 0], seg[:, 1]]
    inc_seg = np.r_[np.arange(ns), np.arange(ns)]
    inc_u = np.r_[u, -u]
    order = np.argsort(inc_node, kind="stable")
    inc_node, inc_seg, inc_u = inc_node[order], inc_seg[order], inc_u[order]
    _, start, count = np.unique(inc_node, return_index=True, return_counts=True)
    deg = np.repeat(count, count)
    rank = np.arange(inc_node.size) - np.repeat(start, count)
    pa_l, pb_l = [], []
    for off in range(1, int(count.max())):  # pairs at each node, by offset (<= degree)
        a = np.flatnonzero(rank + off < deg)
        b = a + off
        straight = np.einsum("ij,ij->i", inc_u[a], inc_u[b]) < -(1.0 - STRAIGHT_TOL)
        pa_l.append(a[straight])
        pb_l.append(b[straight])
    pa = np.concatenate(pa_l) if pa_l else np.zeros(0, np.int64)
    pb = np.concatenate(pb_l) if pb_l else np.zeros(0, np.int64)
    partners = np.bincount(np.r_[pa, pb], minlength=inc_node.size)
    join = (partners[pa] == 1) & (partners[pb] == 1)
    ea, eb = inc_seg[pa[join]], inc_seg[pb[join]]
    graph = coo_matrix((np.ones(ea.size), (ea, eb)), shape=(ns, ns))
    n_lines, which = connected_components(graph, directed=False)
    # order each line's samples along the axis of its first element
    lead = np.full(n_lines, -1)
    lead[which[::-1]] = np.arange(ns)[::-1]  # first element of each line
    axis = u[lead]
    axis = (
        axis
        * np.where(axis[np.arange(n_lines), np.argmax(np.abs(axis), axis=1)] > 0, 1, -1)[:, None]
    )
    ends = np.r_[seg[:, 0], seg[:, 1]]
    line_of = np.r_[which, which]
    pairs = np.unique(np.column_stack([line_of, ends]), axis=0)
    origin_ref = positions[seg[lead, 0]]
    t = np.einsum("ij,ij->i", positions[pairs[:, 1]] - origin_ref[pairs[:, 0]], axis[pairs[:, 0]])
    order = np.lexsort((t, pairs[:, 0]))
    pairs, t = pairs[order], t[order]
    cuts = np.flatnonzero(np.diff(pairs[:, 0])) + 1
    out = []
    line_ids = pairs[np.r_[0, cuts], 0]
    for k, (lid, idx) in enumerate(zip(line_ids, np.split(pairs[:, 1], cuts), strict=True)):
        name = f"{labels[idx[0]]}..{labels[idx[-1]]}" if labels is not None else f"line:{k + 1}"
        out.append(SampleLine(name, idx, positions[idx[0]], axis[lid], False))
    return out
