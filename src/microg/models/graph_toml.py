"""Graph model files: TOML text -> :class:`GraphModel`, and back.

The format is specified in ``docs/model-format.md``, "Graph models".  Reading goes in the
steps of the station format (:mod:`microg.models.toml`): :mod:`tomllib` parses the text (a
syntax error names the file, line and column); :mod:`microg.models.graph_schema`
(pydantic) checks the structure; :mod:`microg.models.graph_build` converts to SI and
checks the model; :func:`microg.models.messages.structure_error` words a structure error
as one line.  :func:`dump_graph` writes a model back in SI with a unit on every value.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from microg._io import loads_toml
from microg.errors import InputError, ModelError
from microg.models.graph_build import build_graph
from microg.models.graph_model import BeamSection, GraphModel
from microg.models.graph_schema import GRAPH_EXAMPLES, INERTIA_KEYS, SPRING_KEYS, GraphFileIn
from microg.models.messages import structure_error

__all__ = ["dump_graph", "load_graph", "loads_graph"]


def loads_graph(text: str, *, filename: str = "<string>") -> GraphModel:
    """Read a graph model from TOML text (format: ``docs/model-format.md``, "Graph models").

    Parameters
    ----------
    text : str
        The file's text.
    filename : str
        Name used for the file in messages and as the model's ``source``.

    Raises
    ------
    ModelError
        One line, ``FILE: table[i].key: what is wrong (how to fix)``; a fault of the
        model itself (:func:`~microg.models.graph_check.validate_graph`) is an InputError.
    """
    doc = loads_toml(text, filename, ModelError)
    try:
        data = GraphFileIn.model_validate(doc)
    except ValidationError as exc:
        raise structure_error(exc, filename, GraphFileIn, GRAPH_EXAMPLES) from None
    return build_graph(data, filename)


def load_graph(path: str | Path) -> GraphModel:
    """Read a graph model TOML file (UTF-8).

    Parameters
    ----------
    path : str or Path
        The file; its path is the model's ``source``.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the file: {exc}", where=str(path)) from None
    return loads_graph(text, filename=str(path))


# --------------------------------------------------------------------------- writer


def _tq(value: float, unit: str) -> str:
    return f'"{float(value):.17g} {unit}"'


def _tv(v: np.ndarray, unit: str = "m") -> str:
    return "[" + ", ".join(_tq(x, unit) for x in np.asarray(v, float)) + "]"


def _ts(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def dump_graph(graph: GraphModel) -> str:
    """A graph model as graph TOML, SI with a unit on every value.

    Loading the text reproduces the model to round-off, with two exceptions that raise an
    :class:`InputError` here rather than write something else: a node whose axes are not
    those of one of the model's frames at its position, and a spring whose axes are not
    representable (written as an orientation, which needs non-coincident nodes).

    Parameters
    ----------
    graph : GraphModel
        Any graph model without scalar springs, scalar masses, scalar points, MPCs, RBE3 UM
        or rotational RBE3 sources, or coupled 6x6 spring terms (each refused).
    """
    lines = [
        "[graph]",
        f"name = {_ts(graph.name)}",
        f"description = {_ts(graph.description)}",
        f'mass = "{graph.mass_formulation}"',
        "",
    ]
    frames = {f.name: f for f in graph.frames}
    for f in graph.frames:
        z = f.rotation[2]
        lines += [
            "[[frame]]",
            f"name = {_ts(f.name)}",
            f'kind = "{f.kind}"',
            f"origin = {_tv(f.origin)}",
            f"z_axis = [{', '.join(f'{x:.17g}' for x in z)}]",
            f"xz_point = {_tv(f.origin + f.rotation[0])}",
            "",
        ]
    for n in graph.nodes:
        lines += ["[[node]]", f"name = {_ts(n.name)}", f"at = {_tv(n.position)}"]
        if n.frame != "basic":
            fr = frames.get(n.frame)
            if fr is None or not np.allclose(fr.axes_at(n.position), n.axes, atol=1e-12):
                raise InputError(f"node {n.name!r}: its axes are not those of a model frame")
            lines.append(f"frame = {_ts(n.frame)}")
        elif not np.allclose(n.axes, np.eye(3), atol=1e-12):
            raise InputError(f"node {n.name!r}: rotated axes without a frame cannot be written")
        lines.append("")
    secs: dict[str, BeamSection] = {}
    for b in graph.beams:
        secs.setdefault(b.section.name, b.section)
    for s in secs.values():
        lines += [
            "[[section]]",
            f"name = {_ts(s.name)}",
            f"ea = {_tq(s.ea_N, 'N')}",
            f"ei_y = {_tq(s.ei_y_N_m2, 'N*m^2')}",
            f"ei_z = {_tq(s.ei_z_N_m2, 'N*m^2')}",
            f"gj = {_tq(s.gj_N_m2, 'N*m^2')}",
            f"mass_per_length = {_tq(s.mass_per_length_kg_per_m, 'kg/m')}",
        ]
        if s.ei_yz_N_m2:
            lines.append(f"ei_yz = {_tq(s.ei_yz_N_m2, 'N*m^2')}")
        if s.mass_per_length_kg_per_m > 0:
            r_p = math.sqrt(s.polar_mass_kg_m / s.mass_per_length_kg_per_m)
            lines.append(f"polar_gyration = {_tq(r_p, 'm')}")
        for k, v in (("shear_y", s.shear_y_N), ("shear_z", s.shear_z_N)):
            if v is not None:
                lines.append(f"{k} = {_tq(v, 'N')}")
        if s.rotary_y_kg_m or s.rotary_z_kg_m:
            lines.append("rotary_inertia = true")
        lines.append("")
    for b in graph.beams:
        lines += [
            "[[beam]]",
            f"name = {_ts(b.name)}",
            f"nodes = [{_ts(b.nodes[0])}, {_ts(b.nodes[1])}]",
            f"section = {_ts(b.section.name)}",
            f"orientation = [{', '.join(f'{x:.17g}' for x in b.orientation)}]",
            f'kind = "{b.kind}"',
        ]
        if np.any(b.offsets):
            lines.append(f"offsets = [{_tv(b.offsets[0])}, {_tv(b.offsets[1])}]")
        if any(b.releases):
            lines.append(f"releases = [{_ts(b.releases[0])}, {_ts(b.releases[1])}]")
        lines.append("")
    for r in graph.rods:
        lines += [
            "[[rod]]",
            f"name = {_ts(r.name)}",
            f"nodes = [{_ts(r.nodes[0])}, {_ts(r.nodes[1])}]",
            f"ea = {_tq(r.ea_N, 'N')}",
            f"gj = {_tq(r.gj_N_m2, 'N*m^2')}",
            f"mass_per_length = {_tq(r.mass_per_length_kg_per_m, 'kg/m')}",
            "",
        ]
    for spr in graph.springs:
        for mat in (spr.stiffness, spr.damping):
            if np.count_nonzero(mat - np.diag(np.diag(mat))):
                raise InputError(f"spring {spr.name!r}: coupled 6x6 terms cannot be written")
        nodes = [spr.nodes[0]] if spr.nodes[1] is None else list(spr.nodes)
        units_k = ("N/m",) * 3 + ("N*m/rad",) * 3
        units_c = ("N*s/m",) * 3 + ("N*m*s/rad",) * 3
        kk = ", ".join(
            f"{c} = {_tq(spr.stiffness[i, i], units_k[i])}" for i, c in enumerate(SPRING_KEYS)
        )
        cc = ", ".join(
            f"{c} = {_tq(spr.damping[i, i], units_c[i])}" for i, c in enumerate(SPRING_KEYS)
        )
        lines += [
            "[[spring]]",
            f"name = {_ts(spr.name)}",
            "nodes = [" + ", ".join(_ts(str(n)) for n in nodes) + "]",
            f"stiffness = {{ {kk} }}",
            f"damping = {{ {cc} }}",
            f"at = {_tv(spr.location)}",
            "axes = ["
            + ", ".join("[" + ", ".join(f"{x:.17g}" for x in row) + "]" for row in spr.axes)
            + "]",
            "",
        ]
    if graph.scalar_springs:
        raise InputError("scalar springs (CELAS) have no graph TOML form; keep the deck")
    for what, present in (
        ("scalar masses (CMASS)", bool(graph.scalar_masses)),
        ("multipoint constraints (MPC)", bool(graph.mpcs)),
        ("scalar points (SPOINT)", any(n.scalar for n in graph.nodes)),
        ("RBE3 UM components", any(ip.moved for ip in graph.interpolations)),
        (
            "RBE3 rotational independent components",
            any(set(c) & set("456") for ip in graph.interpolations for _, c, _ in ip.sources),
        ),
    ):
        if present:
            raise InputError(f"{what} have no graph TOML form; keep the deck")
    for m in graph.masses:
        j = m.inertia_kg_m2
        inertia = ", ".join(
            f"{k} = {_tq(j[a, b], 'kg*m^2')}"
            for k, (a, b) in zip(
                INERTIA_KEYS, ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)), strict=True
            )
        )
        at = graph.node(m.node).position + m.offset_m
        lines += [
            "[[mass]]",
            f"name = {_ts(m.name)}",
            f"node = {_ts(m.node)}",
            f"mass = {_tq(m.mass_kg, 'kg')}",
            f"at = {_tv(at)}",
            f"inertia = {{ {inertia} }}",
            "",
        ]
    for rl in graph.rigid_links:
        lines += [
            "[[rigid]]",
            f"name = {_ts(rl.name)}",
            f"independent = {_ts(rl.independent)}",
            "dependents = [" + ", ".join(_ts(d) for d in rl.dependents) + "]",
            f'components = "{rl.components}"',
            "",
        ]
    for ip in graph.interpolations:
        srcs = ", ".join(
            f'{{ node = {_ts(n)}, components = "{c}", weight = {w:.17g} }}'
            for n, c, w in ip.sources
        )
        lines += [
            "[[interpolation]]",
            f"name = {_ts(ip.name)}",
            f"reference = {_ts(ip.reference)}",
            f'components = "{ip.components}"',
            f"sources = [{srcs}]",
            "",
        ]
    for p in graph.points:
        lines += [
            "[[point]]",
            f"name = {_ts(p.name)}",
            f"node = {_ts(p.node)}",
            f"at = {_tv(p.position)}",
            f'kind = "{p.kind}"',
            f"description = {_ts(p.description)}",
            "",
        ]
    for c in graph.constraints:
        lines += ["[[constraint]]", f"node = {_ts(c.node)}", f'components = "{c.components}"', ""]
    return "\n".join(lines)
