"""The case plan of a study: the values of every axis (SI), the case grid and its blocks.

The case grid has one dimension per axis (:data:`CASE_DIMS`); it is cut into blocks
(:class:`Block`): one model, variant, isolator, damping value and force, a run of application
points, every direction and a run of observed points.  A block is the unit of work, of
storage (one zarr chunk per variable) and of resumption.  A :class:`Study` is built from a
study file by :mod:`microg.study.expand` (every value checked there, once).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from microg.analysis import DEFAULTS
from microg.dynamics.forces import ForceHistory
from microg.errors import InputError
from microg.isolation.timedomain import IsolatorModel

__all__ = [
    "BLOCK_CELLS",
    "CASE_DIMS",
    "Block",
    "DirectionItem",
    "Discretisation",
    "ForceItem",
    "IsolatorItem",
    "ModelItem",
    "Record",
    "Study",
    "VariantItem",
    "default_n_modes",
    "moved_station",
]

#: the case dimensions of the results, in storage order
CASE_DIMS = ("model", "variant", "isolator", "damping", "force", "at", "direction", "observe")
#: target number of cases of one block (a block is about a second of work on the IOC model)
BLOCK_CELLS = 1024


@dataclass(frozen=True)
class ModelItem:
    """One model of the study.

    Attributes
    ----------
    label : name in the results (the ``model`` coordinate)
    path : the path or shipped name as written (resolved against the study's folder)
    model : the loaded model (Station, ModalModel or GraphModel), with the study's extra points
    units, points : the unit declaration and points file of a modal file
    derived : True when the model differs from its file (extra points added)
    """

    label: str
    path: str
    model: Any = field(repr=False)
    units: str | None = None
    points: str | None = None
    derived: bool = False


@dataclass(frozen=True)
class VariantItem:
    """One model variant: ``base`` (as is), ``move`` (a mass moved) or ``model`` (a file)."""

    label: str
    kind: str
    move: str | None = None
    to_m: np.ndarray | None = field(default=None, repr=False)
    s_m: float | None = None
    model: ModelItem | None = None


@dataclass(frozen=True)
class IsolatorItem:
    """One mount design: the package on a spring (and damper, absorber), or none.

    The package is driven by the observed point's acceleration (base excitation; its mass is
    not fed back into the station), as in the isolation advice's time-domain check
    (:func:`microg.isolation.timedomain.package_response`).
    """

    label: str
    mount: IsolatorModel | None
    description: str = ""


@dataclass(frozen=True)
class ForceItem:
    """One value of the ``force`` axis: a spec as written, and what it is.

    ``kind`` is ``"time"`` (``history``: a piecewise-linear force, s and N: a library activity,
    a spec, a CSV file; it acts at the case's point along its direction) or ``"catalogue"``
    (``catalogue``: a frequency-domain source catalogue, ``sources:FILE``, whose sources carry
    their own points and directions, assessed by
    :func:`microg.environment.vibratory.assess_sources`; the ``at`` and ``direction`` axes do
    not apply to it).
    """

    label: str
    spec: str
    history: ForceHistory | None = field(default=None, repr=False)
    kind: str = "time"
    catalogue: Any = field(default=None, repr=False)


@dataclass(frozen=True)
class DirectionItem:
    """One force direction: its label and unit vector."""

    label: str
    vector: np.ndarray


@dataclass(frozen=True)
class Record:
    """The output record and the requirement, SI.

    ``peaks``: ``"verdict"`` searches the exact (certified) peak of a case only where the
    verdict may depend on it (the sampled peak and its certified bound straddle a peak limit);
    ``"exact"`` searches it for every case without an isolator.
    """

    duration_s: float
    dt_s: float
    max_freq_hz: float
    requirement: str
    peaks: str = "verdict"

    @property
    def timepts(self) -> np.ndarray:
        """Output times, s (as the analysis builds them)."""
        return np.arange(0.0, self.duration_s + 0.5 * self.dt_s, self.dt_s)


@dataclass(frozen=True)
class Discretisation:
    """How station models are discretised and how many modes are solved (analysis' options)."""

    method: str = DEFAULTS["method"]
    plane: str = DEFAULTS["plane"]
    n: int | None = None
    n_modes: int | None = None
    gravity_gradient: bool = DEFAULTS["gravity_gradient"]


@dataclass(frozen=True)
class Block:
    """A block of cases: one model, variant, isolator, damping and force; runs of at/observe.

    Attributes
    ----------
    id : flat index in the block grid (C order)
    index : (model, variant, isolator, damping, force) indices
    at, observe : slices of the at and observe axes
    n_cases : cases of the plan inside the block
    """

    id: int
    index: tuple[int, int, int, int, int]
    at: slice
    observe: slice
    n_cases: int


@dataclass(frozen=True)
class Study:
    """A validated study: the axes, the record, the models, the case plan.

    Attributes
    ----------
    file : the study file's name (for messages)
    sha256 : of the study text
    name, description
    models, variants, isolators, damping, forces, at, directions, observe : the axes
    record : Record
    discretisation : Discretisation
    case_sets : None (the full product) or per [[case]] the indices of each axis
    text : the study file's text
    warnings : what the user should know about the plan
    """

    file: str
    sha256: str
    name: str
    description: str
    models: tuple[ModelItem, ...]
    variants: tuple[VariantItem, ...]
    isolators: tuple[IsolatorItem, ...]
    damping: tuple[float, ...]
    forces: tuple[ForceItem, ...]
    at: tuple[str, ...]
    directions: tuple[DirectionItem, ...]
    observe: tuple[str, ...]
    record: Record
    discretisation: Discretisation
    case_sets: tuple[tuple[tuple[int, ...], ...], ...] | None = None
    text: str = field(default="", repr=False)
    warnings: tuple[str, ...] = ()

    # ------------------------------------------------------------------ the grid
    @property
    def coords(self) -> dict[str, list[Any]]:
        """The labels of every case dimension."""
        return {
            "model": [m.label for m in self.models],
            "variant": [v.label for v in self.variants],
            "isolator": [i.label for i in self.isolators],
            "damping": list(self.damping),
            "force": [f.label for f in self.forces],
            "at": list(self.at),
            "direction": [d.label for d in self.directions],
            "observe": list(self.observe),
        }

    @property
    def shape(self) -> tuple[int, ...]:
        """Size of each case dimension (:data:`CASE_DIMS`)."""
        return tuple(len(v) for v in self.coords.values())

    @property
    def chunks(self) -> tuple[int, ...]:
        """Chunk size of each case dimension: one block per chunk."""
        n_at, n_dir, n_obs = self.shape[5:]
        co = min(n_obs, max(1, BLOCK_CELLS // n_dir))
        ca = min(n_at, max(1, BLOCK_CELLS // (n_dir * co)))
        return (1, 1, 1, 1, 1, ca, n_dir, co)

    @property
    def block_grid(self) -> tuple[int, ...]:
        """Number of blocks along (model, variant, isolator, damping, force, at, observe)."""
        s, c = self.shape, self.chunks
        return (*s[:5], -(-s[5] // c[5]), -(-s[7] // c[7]))

    def block(self, block_id: int) -> Block:
        """The block with flat index ``block_id``."""
        grid = self.block_grid
        idx = np.unravel_index(block_id, grid)
        ca, co = self.chunks[5], self.chunks[7]
        a0, o0 = int(idx[5]) * ca, int(idx[6]) * co
        at = slice(a0, min(a0 + ca, self.shape[5]))
        obs = slice(o0, min(o0 + co, self.shape[7]))
        head = (int(idx[0]), int(idx[1]), int(idx[2]), int(idx[3]), int(idx[4]))
        mask = self.block_mask(head, at, obs)
        return Block(block_id, head, at, obs, int(mask.sum()))

    def block_mask(self, head: tuple[int, ...], at: slice, obs: slice) -> np.ndarray:
        """(n_at, n_dir, n_obs) of bool: the cases of the plan inside a block."""
        n_dir = self.shape[6]
        shape = (at.stop - at.start, n_dir, obs.stop - obs.start)
        if self.case_sets is None:
            return np.ones(shape, bool)
        mask = np.zeros(shape, bool)
        for cs in self.case_sets:
            if not all(h in cs[k] for k, h in enumerate(head)):
                continue
            a = np.zeros(shape[0], bool)
            a[[i - at.start for i in cs[5] if at.start <= i < at.stop]] = True
            d = np.zeros(n_dir, bool)
            d[list(cs[6])] = True
            o = np.zeros(shape[2], bool)
            o[[i - obs.start for i in cs[7] if obs.start <= i < obs.stop]] = True
            mask |= a[:, None, None] & d[None, :, None] & o[None, None, :]
        return mask

    def blocks(self) -> Iterator[Block]:
        """Every block holding at least one case, in storage order."""
        for b in range(math.prod(self.block_grid)):
            blk = self.block(b)
            if blk.n_cases:
                yield blk

    @property
    def n_blocks(self) -> int:
        """Number of blocks of the grid (with or without cases)."""
        return math.prod(self.block_grid)

    @property
    def n_cases(self) -> int:
        """Number of cases of the plan."""
        if self.case_sets is None:
            return math.prod(self.shape)
        return sum(b.n_cases for b in self.blocks())

    @property
    def fingerprint(self) -> str:
        """What identifies the computation (the study text and the microg version)."""
        from microg import __version__

        h = hashlib.sha256()
        h.update(self.text.encode("utf-8"))
        h.update(b"\0" + __version__.encode())
        for m in (*self.models, *(v.model for v in self.variants if v.model is not None)):
            h.update(b"\0" + _model_digest(m).encode())
        for f in self.forces:
            h.update(b"\0" + f.label.encode())
            if f.history is not None:
                h.update(np.asarray(f.history.timepts).tobytes())
                h.update(np.asarray(f.history.force).tobytes())
            else:
                h.update(repr(f.catalogue.to_dict()).encode())
        return h.hexdigest()

    # ------------------------------------------------------------------ models
    def variant_model(self, im: int, iv: int) -> Any:
        """The model of (model ``im``, variant ``iv``): the base, a moved mass, or a file."""
        base = self.models[im]
        v = self.variants[iv]
        if v.kind == "base":
            return base.model
        if v.kind == "model":
            assert v.model is not None
            return v.model.model
        return moved_station(base.model, v, f"{self.file}: axes.variant[{iv}]")

    def case(self, index: Sequence[int]) -> dict[str, Any]:
        """The labels of the case at ``index`` (one index per case dimension)."""
        return {d: self.coords[d][int(i)] for d, i in zip(CASE_DIMS, index, strict=True)}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary of the plan."""
        return {
            "file": self.file,
            "sha256": self.sha256,
            "name": self.name,
            "description": self.description,
            "dims": list(CASE_DIMS),
            "coords": self.coords,
            "shape": list(self.shape),
            "cases": self.n_cases,
            "full_product": self.case_sets is None,
            "record": dataclasses.asdict(self.record),
            "discretisation": dataclasses.asdict(self.discretisation),
            "models": [
                {"label": m.label, "path": m.path, "units": m.units, "points": m.points}
                for m in self.models
            ],
            "variants": [
                {
                    "label": v.label,
                    "kind": v.kind,
                    "move": v.move,
                    "to_m": None if v.to_m is None else [float(x) for x in v.to_m],
                    "s_m": v.s_m,
                    "model": None if v.model is None else v.model.path,
                }
                for v in self.variants
            ],
            "isolators": [
                {
                    "label": i.label,
                    "description": i.description,
                    "mount": None if i.mount is None else dataclasses.asdict(i.mount),
                }
                for i in self.isolators
            ],
            "forces": [{"label": f.label, "spec": f.spec, "kind": f.kind} for f in self.forces],
            "directions": [
                {"label": d.label, "vector": [float(x) for x in d.vector]} for d in self.directions
            ],
            "warnings": list(self.warnings),
        }


def _model_digest(m: ModelItem) -> str:
    src = getattr(m.model, "source", "") or ""
    p = Path(src)
    try:
        if src and p.is_file():
            return hashlib.sha256(p.read_bytes()).hexdigest()
    except OSError:
        pass
    return f"{m.path}|{src}"


def moved_station(model: Any, v: VariantItem, where: str) -> Any:
    """A copy of a station with the variant's mass moved (``to`` or ``s`` on its carrier).

    Parameters
    ----------
    model : Station
        The base model (another kind of model is an InputError naming ``where``).
    v : VariantItem
        A ``move`` variant: the mass (``body/mass``) and its new position (``to_m``, m) or
        arc length on its beam (``s_m``, m).
    where : str
        The study file's field, for the errors.
    """
    from microg.location.layout import resolve_mass
    from microg.models.schema import ON_AXIS_TOL
    from microg.models.station import Beam, Station

    if not isinstance(model, Station):
        raise InputError(
            f"a moved mass needs a station model, not a {type(model).__name__}",
            where=where,
            fix="give the variant as another model file: model = ...",
        )
    assert v.move is not None
    try:
        comp, pm = resolve_mass(model, v.move)
    except InputError as exc:
        raise InputError(exc.what, where=f"{where}.move", fix=exc.fix) from None
    if isinstance(comp, Beam):
        if v.s_m is not None:
            s = v.s_m
        else:
            assert v.to_m is not None
            to = np.asarray(v.to_m, float)
            s = comp.arc_length(to)
            off = float(np.linalg.norm(comp.station_position(s) - to))
            if off > ON_AXIS_TOL * comp.length:
                raise InputError(
                    f"{v.move!r} rides on beam {comp.name!r}; the position is {off:.4g} m off "
                    "its axis",
                    where=f"{where}.to",
                    fix="give a point on the beam, or s = (arc length from its root)",
                )
        if not -ON_AXIS_TOL * comp.length <= s <= comp.length * (1 + ON_AXIS_TOL):
            raise InputError(
                f"s = {s:.6g} m is off beam {comp.name!r} (0 to {comp.length:.6g} m)",
                where=f"{where}.{'s' if v.s_m is not None else 'to'}",
            )
        pos = np.asarray(comp.station_position(min(max(s, 0.0), comp.length)), float)
    else:
        if v.to_m is None:
            raise InputError(
                f"{v.move!r} is on body {comp.name!r}: give its position to = [x, y, z]",
                where=f"{where}.s",
            )
        pos = np.asarray(v.to_m, float)
    new_pm = dataclasses.replace(pm, position=pos)

    def moved(c: Any) -> Any:
        if c.name != comp.name:
            return c
        return dataclasses.replace(c, masses=tuple(new_pm if m is pm else m for m in c.masses))

    return dataclasses.replace(
        model,
        bodies=tuple(moved(b) for b in model.bodies),
        beams=tuple(moved(b) for b in model.beams),
    )


def default_n_modes(study: Study) -> int | None:
    """The modes a sparse model's solve asks for when the study names none.

    The analysis' default, or its default with sources when the study has source catalogues
    (so that the per-case path solves the same modes).
    """
    if not any(f.catalogue is not None for f in study.forces):
        return None
    from microg.analysis import DEFAULT_SOURCE_MODES

    return int(DEFAULT_SOURCE_MODES)
