"""Checks of a graph model: names, references, signs and geometry (one error, one line).

:func:`validate_graph` runs on every :class:`~microg.models.graph_model.GraphModel` before it
is used: the graph TOML reader (:mod:`microg.models.graph_build`) and the NASTRAN deck
reader (:mod:`microg.models.bdf`) call it on what they built, and
:func:`microg.structure.assembly.assemble_frame` on what it is given.  Each fault is an
:class:`~microg.errors.InputError` naming the model's source and the item
(``frame.toml: ab: has zero length (its ends coincide) (...)``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from microg.errors import InputError
from microg.models.graph_model import (
    MASS_FORMULATIONS,
    MAX_GRAPH_ITEMS,
    PARALLEL_TOL,
    ZERO_LENGTH_TOL,
    BeamSection,
    GraphModel,
    ShellSection,
    nearest_names,
    parse_components,
)

__all__ = ["validate_graph"]


def validate_graph(graph: GraphModel) -> None:
    """Check names, references, signs and geometry of ``graph`` (InputError on the first fault).

    Checked: unique names per kind; every node an element, mass, link or point names
    exists; finite values; positive section stiffnesses and non-negative masses; a
    symmetric positive semidefinite inertia per mass; symmetric stiffness and damping
    matrices of springs; non-zero beam and rod lengths; an orientation not parallel to its
    beam; a rigid link's independent node not among its dependents; orthonormal axes;
    at most :data:`~microg.models.graph_model.MAX_GRAPH_ITEMS` items of each kind.

    Parameters
    ----------
    graph : GraphModel
        The model; its ``source`` (else its name) begins each message.
    """
    src = graph.source or graph.name
    if graph.mass_formulation not in MASS_FORMULATIONS:
        raise InputError(
            f"unknown mass formulation {graph.mass_formulation!r}",
            where=f"{src}: mass",
            fix="use " + ", ".join(MASS_FORMULATIONS),
        )
    for label, items in (
        ("node", graph.nodes),
        ("beam", graph.beams),
        ("rod", graph.rods),
        ("shell", graph.shells),
        ("spring", graph.springs),
        ("scalar spring", graph.scalar_springs),
        ("scalar mass", graph.scalar_masses),
        ("multipoint constraint", graph.mpcs),
        ("mass", graph.masses),
        ("rigid link", graph.rigid_links),
        ("interpolation", graph.interpolations),
        ("point", graph.points),
    ):
        if len(items) > MAX_GRAPH_ITEMS:
            raise InputError(
                f"{len(items)} {label}s exceed the limit of {MAX_GRAPH_ITEMS}",
                where=src,
                fix="split or condense the model",
            )
        seen: set[str] = set()
        for it in items:
            name = it.name
            if name in seen:
                raise InputError(f"duplicate {label} name {name!r}", where=f"{src}: {name}")
            seen.add(name)
    if not graph.nodes:
        raise InputError("the model has no node", where=src, fix="add nodes and elements")
    index = graph.node_index()
    pos = np.array([n.position for n in graph.nodes], float).reshape(-1, 3)
    if not np.all(np.isfinite(pos)):
        bad = graph.nodes[int(np.flatnonzero(~np.isfinite(pos).all(axis=1))[0])].name
        raise InputError("position is not finite", where=f"{src}: {bad}")
    scalar = {n.name for n in graph.nodes if n.scalar}
    spatial = pos[[not n.scalar for n in graph.nodes]]
    scale = max(float(np.ptp(spatial, axis=0).max()) if spatial.shape[0] > 1 else 0.0, 1e-300)
    try:
        axes = np.array([n.axes for n in graph.nodes], float).reshape(-1, 3, 3)
    except ValueError:
        axes = np.full((len(graph.nodes), 3, 3), np.nan)
    err = np.abs(axes @ np.swapaxes(axes, 1, 2) - np.eye(3)).max(axis=(1, 2))
    if not np.all(err <= 1e-9):
        bad = graph.nodes[int(np.flatnonzero(~(err <= 1e-9))[0])].name
        raise InputError("axes are not orthonormal", where=f"{src}: {bad}")

    def ref(node: str | None, where: str) -> None:
        if node is not None and node not in index:
            raise InputError(
                f"node {node!r} does not exist",
                where=f"{src}: {where}",
                fix=nearest_names(node, list(index)),
            )

    def spatial_ref(node: str | None, where: str) -> None:
        ref(node, where)
        if node in scalar:
            raise InputError(
                f"{node!r} is a scalar point (SPOINT): it has no position or rotation",
                where=f"{src}: {where}",
                fix="connect a grid (a scalar point takes scalar elements and MPCs)",
            )

    def dof_ref(node: str, comp: Any, where: str) -> None:
        ref(node, where)
        top = 1 if node in scalar else 6
        if not (isinstance(comp, int) and 1 <= comp <= top):
            raise InputError(
                f"component {comp!r} of {node!r} is not 1-{top}"
                + (" (a scalar point has one)" if top == 1 else ""),
                where=f"{src}: {where}",
            )

    checked: set[int] = set()
    for b in graph.beams:
        for nd in b.nodes:
            spatial_ref(nd, b.name)
        s = b.section
        if id(s) not in checked:
            _check_section(s, f"{src}: {b.name}")
            checked.add(id(s))
        if b.kind not in ("beam", "bar"):
            raise InputError(f"unknown beam kind {b.kind!r}", where=f"{src}: {b.name}")
        for rel in b.releases:
            if rel:
                parse_components(rel, where=f"{src}: {b.name}: releases")
    if graph.beams:
        ia = np.array([index[b.nodes[0]] for b in graph.beams])
        ib = np.array([index[b.nodes[1]] for b in graph.beams])
        off = np.array([b.offsets for b in graph.beams], float).reshape(-1, 2, 3)
        axis = (pos[ib] + off[:, 1]) - (pos[ia] + off[:, 0])
        length = np.linalg.norm(axis, axis=1)
        short = np.flatnonzero(~(length > ZERO_LENGTH_TOL * scale))
        if short.size:
            raise InputError(
                "has zero length (its ends coincide)",
                where=f"{src}: {graph.beams[int(short[0])].name}",
                fix="connect two distinct points, or use a spring (CBUSH) or rigid link (RBE2)",
            )
        ov = np.array([b.orientation for b in graph.beams], float).reshape(-1, 3)
        nv = np.linalg.norm(ov, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            sine = np.linalg.norm(np.cross(axis / length[:, None], ov / nv[:, None]), axis=1)
        para = np.flatnonzero(~(sine > PARALLEL_TOL))
        if para.size:
            raise InputError(
                "orientation vector is zero or parallel to the beam",
                where=f"{src}: {graph.beams[int(para[0])].name}",
                fix="give a vector in the beam's x-y plane, not along its axis",
            )
    for r in graph.rods:
        for nd in r.nodes:
            spatial_ref(nd, r.name)
        if not (math.isfinite(r.ea_N) and r.ea_N > 0 and r.gj_N_m2 >= 0):
            raise InputError("needs EA > 0 and GJ >= 0", where=f"{src}: {r.name}")
        if not r.mass_per_length_kg_per_m >= 0:
            raise InputError("negative mass per length", where=f"{src}: {r.name}")
        d = pos[index[r.nodes[1]]] - pos[index[r.nodes[0]]]
        if float(np.linalg.norm(d)) <= ZERO_LENGTH_TOL * scale:
            raise InputError(
                "has zero length (its nodes coincide)",
                where=f"{src}: {r.name}",
                fix="connect two distinct nodes, or use a spring (CBUSH/CELAS)",
            )
    for sh in graph.shells:
        if len(sh.nodes) not in (3, 4) or len(set(sh.nodes)) != len(sh.nodes):
            raise InputError("a shell needs 3 or 4 distinct nodes", where=f"{src}: {sh.name}")
        for nd in sh.nodes:
            ref(nd, sh.name)
        if id(sh.section) not in checked:
            _check_shell_section(sh.section, f"{src}: {sh.name}")
            checked.add(id(sh.section))
    for sp_ in graph.springs:
        spatial_ref(sp_.nodes[0], sp_.name)
        spatial_ref(sp_.nodes[1], sp_.name)
        for mat, what in ((sp_.stiffness, "stiffness"), (sp_.damping, "damping")):
            a = np.asarray(mat, float)
            if a.shape != (6, 6) or not np.all(np.isfinite(a)):
                raise InputError(f"{what} must be a finite 6x6 matrix", where=f"{src}: {sp_.name}")
            if np.max(np.abs(a - a.T)) > 1e-12 * max(np.max(np.abs(a)), 1e-300):
                raise InputError(f"{what} matrix is not symmetric", where=f"{src}: {sp_.name}")
            if np.any(np.diag(a) < 0):
                raise InputError(f"negative {what}", where=f"{src}: {sp_.name}")
        ax = np.asarray(sp_.axes, float)
        if ax.shape != (3, 3) or not np.allclose(ax @ ax.T, np.eye(3), atol=1e-9):
            raise InputError("axes are not orthonormal", where=f"{src}: {sp_.name}")
    for cs in graph.scalar_springs:
        for d_ in cs.dofs:
            if d_ is not None:
                dof_ref(d_[0], d_[1], cs.name)
        if cs.dofs[0] is None and cs.dofs[1] is None:
            raise InputError("connects nothing (both ends grounded)", where=f"{src}: {cs.name}")
        if not (math.isfinite(cs.stiffness) and math.isfinite(cs.damping)):
            raise InputError("stiffness and damping must be finite", where=f"{src}: {cs.name}")
    for sm in graph.scalar_masses:
        for d_ in sm.dofs:
            if d_ is not None:
                dof_ref(d_[0], d_[1], sm.name)
        if sm.dofs[0] is None and sm.dofs[1] is None:
            raise InputError("connects nothing (both ends grounded)", where=f"{src}: {sm.name}")
        if not (math.isfinite(sm.mass) and sm.mass >= 0):
            raise InputError(f"mass {sm.mass} must be finite and >= 0", where=f"{src}: {sm.name}")
    for mp in graph.mpcs:
        if not mp.terms:
            raise InputError("has no term", where=f"{src}: {mp.name}")
        for nd, comp, coef in mp.terms:
            dof_ref(nd, comp, mp.name)
            if not math.isfinite(coef):
                raise InputError(f"coefficient {coef} is not finite", where=f"{src}: {mp.name}")
        if mp.terms[0][2] == 0:
            raise InputError(
                "the first (dependent) term's coefficient is zero",
                where=f"{src}: {mp.name}",
                fix="give the dependent component a non-zero coefficient",
            )
    for m in graph.masses:
        spatial_ref(m.node, m.name)
        j = np.asarray(m.inertia_kg_m2, float)
        if not (math.isfinite(m.mass_kg) and m.mass_kg >= 0) or j.shape != (3, 3):
            raise InputError("needs a mass >= 0 and a 3x3 inertia", where=f"{src}: {m.name}")
        if not np.all(np.isfinite(j)) or np.max(np.abs(j - j.T)) > 1e-12 * max(
            np.max(np.abs(j)), 1e-300
        ):
            raise InputError("inertia is not a symmetric finite tensor", where=f"{src}: {m.name}")
        tr = float(np.trace(j))
        if tr and float(np.linalg.eigvalsh(j).min()) < -1e-9 * tr:
            raise InputError(
                "inertia tensor is not positive semidefinite",
                where=f"{src}: {m.name}",
                fix="check the signs of the products of inertia",
            )
    for rl in graph.rigid_links:
        spatial_ref(rl.independent, rl.name)
        for d in rl.dependents:
            spatial_ref(d, rl.name)
        if rl.independent in rl.dependents:
            raise InputError(
                f"independent node {rl.independent!r} is also dependent", where=f"{src}: {rl.name}"
            )
        parse_components(rl.components, where=f"{src}: {rl.name}")
    for ip in graph.interpolations:
        spatial_ref(ip.reference, ip.name)
        parse_components(ip.components, where=f"{src}: {ip.name}")
        if not ip.sources:
            raise InputError("has no independent node", where=f"{src}: {ip.name}")
        for nd, comps, w in ip.sources:
            spatial_ref(nd, ip.name)
            parse_components(comps, where=f"{src}: {ip.name}")
            if not (math.isfinite(w) and w > 0):
                raise InputError(f"weight {w} must be > 0", where=f"{src}: {ip.name}")
        for nd, comps in ip.moved:
            spatial_ref(nd, ip.name)
            parse_components(comps, where=f"{src}: {ip.name}: UM")
    for p in graph.points:
        spatial_ref(p.node, p.name)
        if p.kind not in ("crew", "experiment", "point"):
            raise InputError(f"unknown kind {p.kind!r}", where=f"{src}: {p.name}")
    for c in graph.constraints:
        ref(c.node, f"constraint on {c.node}")
        parse_components(
            c.components,
            where=f"{src}: constraint on {c.node}",
            allowed="1" if c.node in scalar else "123456",
        )


def _check_shell_section(s: ShellSection, where: str) -> None:
    for mat, shape, what in (
        (s.membrane_N_per_m, (3, 3), "membrane"),
        (s.bending_N_m, (3, 3), "bending"),
        (s.shear_N_per_m, (2, 2), "transverse shear"),
    ):
        a = np.asarray(mat, float)
        if a.shape != shape or not np.all(np.isfinite(a)):
            raise InputError(
                f"section {s.name!r}: {what} matrix must be finite {shape}", where=where
            )
        big = max(float(np.max(np.abs(a))), 1e-300)
        if np.max(np.abs(a - a.T)) > 1e-12 * big or np.linalg.eigvalsh(a).min() < -1e-9 * big:
            raise InputError(
                f"section {s.name!r}: {what} matrix is not symmetric positive semidefinite",
                where=where,
            )
    if not (math.isfinite(s.mass_per_area_kg_per_m2) and s.mass_per_area_kg_per_m2 >= 0):
        raise InputError(f"section {s.name!r}: negative mass per area", where=where)
    if not (math.isfinite(s.drilling_N_per_m) and s.drilling_N_per_m >= 0):
        raise InputError(f"section {s.name!r}: negative drilling stiffness", where=where)


def _check_section(s: BeamSection, where: str) -> None:
    vals = (s.ea_N, s.ei_y_N_m2, s.ei_z_N_m2, s.gj_N_m2)
    if not all(math.isfinite(v) and v > 0 for v in vals):
        raise InputError(
            f"section {s.name!r} needs EA, EI_y, EI_z, GJ > 0, got {vals}",
            where=where,
            fix="give positive stiffnesses (E, G and the section's A, I1, I2, J)",
        )
    if s.ei_yz_N_m2 and s.ei_y_N_m2 * s.ei_z_N_m2 <= s.ei_yz_N_m2**2:
        raise InputError(f"section {s.name!r}: I1 I2 must exceed I12^2", where=where)
    for v, what in (
        (s.mass_per_length_kg_per_m, "mass per length"),
        (s.polar_mass_kg_m, "polar mass moment"),
        (s.rotary_y_kg_m, "rotary inertia"),
        (s.rotary_z_kg_m, "rotary inertia"),
    ):
        if not (math.isfinite(v) and v >= 0):
            raise InputError(f"section {s.name!r}: negative {what}", where=where)
    for sv in (s.shear_y_N, s.shear_z_N):
        if sv is not None and not (math.isfinite(sv) and sv > 0):
            raise InputError(
                f"section {s.name!r}: shear stiffness must be > 0 (or absent)", where=where
            )
