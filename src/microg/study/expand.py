"""From a study file's tables to the case plan: every axis value parsed and checked, once.

Every force (parsed), every point (present in each model it is used on), every variant (the
mass exists, the position is on its carrier), every isolator (sized), the record; every error
is one line naming the file and the field (``study.toml: axes.force[2]: ...``).  The plan
(:class:`~microg.study.cases.Study`) holds SI values only.  The full product is the default;
``[[case]]`` tables list sub-products instead, and extra named points (``[[point]]``) are
added to every station model.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from microg._vectors import axis_name, parse_direction
from microg.analysis import DEFAULTS
from microg.dynamics.forces import activity_library, parse_force_spec
from microg.errors import InputError
from microg.isolation.timedomain import IsolatorModel
from microg.models.messages import toml_repr
from microg.study.cases import (
    CASE_DIMS,
    DirectionItem,
    Discretisation,
    ForceItem,
    IsolatorItem,
    ModelItem,
    Record,
    Study,
    VariantItem,
    moved_station,
)
from microg.study.schema import CaseIn, IsolatorIn, ModelIn, StudyFileIn, VariantIn
from microg.units import parse_quantity

__all__ = ["MAX_CASES", "MAX_SAMPLES", "build_study"]

#: most cases of one study (the product or the listed cases)
MAX_CASES = 100_000_000
#: the analysis' limit on output samples, repeated: a record is refused beyond it
MAX_SAMPLES = 2_000_000


def build_study(doc: StudyFileIn, filename: str, base_dir: Path, text: str) -> Study:
    """The case plan of a validated study file (every value parsed, checked and in SI).

    Parameters
    ----------
    doc : StudyFileIn
        The file's tables, as the schema read them.
    filename : str
        The file's name in messages.
    base_dir : Path
        Folder against which relative paths (models, force files) are resolved.
    text : str
        The file's text (its sha256 and the fingerprint of the computation).
    """
    return _Builder(doc, filename, base_dir, text).build()


class _Builder:
    def __init__(self, doc: StudyFileIn, file: str, base: Path, text: str):
        self.doc, self.file, self.base, self.text = doc, file, base, text
        self.warnings: list[str] = []

    def where(self, path: str) -> str:
        return f"{self.file}: {path}"

    def err(self, path: str, what: str, fix: str | None = None) -> InputError:
        return InputError(what, where=self.where(path), fix=fix)

    def rewrap(self, exc: InputError, path: str) -> InputError:
        inner = f"{exc.where}: {exc.what}" if exc.where else exc.what
        return InputError(inner, where=self.where(path), fix=exc.fix)

    def q(self, value: str | float, dim: str, path: str) -> float:
        try:
            return parse_quantity(value, dim, where=self.where(path), default_unit=self.bare(dim))
        except InputError as exc:
            raise InputError(exc.what, where=self.where(path), fix=exc.fix) from None

    def bare(self, dim: str) -> str | None:
        from microg.models.schema import UNIT_SYSTEMS
        from microg.units import DIMENSIONS

        units = self.doc.study.units
        if units is None:
            return DIMENSIONS.get(dim) or None
        return UNIT_SYSTEMS.get(units, {}).get(dim)

    # ---------------------------------------------------------------- models
    def resolve(self, path: str) -> str:
        from microg.models.catalog import shipped_models

        if path in shipped_models():
            return path
        p = Path(path)
        return str(p if p.is_absolute() else (self.base / p))

    def model(self, ref: str | ModelIn, path: str) -> ModelItem:
        from microg.models.load import load_model

        spec = ref if isinstance(ref, ModelIn) else ModelIn(path=ref)
        resolved = self.resolve(spec.path)
        points = None if spec.points is None else self.resolve(spec.points)
        try:
            obj = load_model(resolved, units=spec.units, points=points)
        except InputError as exc:
            raise self.rewrap(exc, path) from None
        label = spec.name or (spec.path if resolved == spec.path else Path(spec.path).stem)
        item = ModelItem(label, resolved, obj, spec.units, points)
        return self.with_points(item, path)

    def with_points(self, item: ModelItem, path: str) -> ModelItem:
        pts = self.doc.point
        if not pts:
            return item
        from microg.models.station import Station
        from microg.models.toml import dump_station, loads_station

        if not isinstance(item.model, Station):
            raise self.err(
                "point",
                f"extra points apply to station models only; model {item.label!r} is a "
                f"{type(item.model).__name__}",
                "name the points in the model's points file instead",
            )
        st = item.model
        known = {p.name for p in st.points}
        for i, p in enumerate(pts):
            if p.name in known:
                raise self.err(f"point[{i}].name", f"model {item.label!r} already has {p.name!r}")
        lines = dump_station(st).splitlines()
        if self.doc.study.units:
            lines.insert(lines.index("[station]") + 1, f"units = {toml_repr(self.doc.study.units)}")
        for p in pts:
            lines += ["", "[[point]]"]
            for key, value in p.model_dump(exclude_none=True).items():
                lines.append(f"{key} = {toml_repr(value, 10_000)}")
        offset = len(st.points)
        try:
            new = loads_station("\n".join(lines) + "\n", filename=self.file, source=st.source)
        except InputError as exc:
            where = re.sub(
                r"point\[(\d+)\]", lambda m: f"point[{int(m.group(1)) - offset}]", exc.where or ""
            )
            raise InputError(exc.what, where=where, fix=exc.fix) from None
        return dataclasses.replace(item, model=new, derived=True)

    # ---------------------------------------------------------------- axes
    def build(self) -> Study:
        d = self.doc
        refs = d.study.model if isinstance(d.study.model, list) else [d.study.model]
        models = tuple(
            self.model(r, "study.model" if len(refs) == 1 else f"study.model[{i}]")
            for i, r in enumerate(refs)
        )
        self.unique([m.label for m in models], "study.model", "give each a name = ...")
        disc = self.discretisation()
        record = self.record()
        ax = d.axes
        variants = self.variants(ax.variant, models)
        isolators = self.isolators(ax.isolator)
        forces = self.forces(ax.force)
        damping = self.damping(ax.damping)
        directions = self.directions(ax.direction)
        at = self.names(ax.at, "at")
        observe = self.names(ax.observe, "observe")
        if ax.at is None:
            at = (self.default_crew(models[0].model),)
        if ax.observe is None:
            observe = self.default_observe(models[0].model)
        case_sets = None
        coords = {
            "model": [m.label for m in models],
            "variant": [v.label for v in variants],
            "isolator": [i.label for i in isolators],
            "damping": list(damping),
            "force": [f.label for f in forces],
            "at": list(at),
            "direction": [x.label for x in directions],
            "observe": list(observe),
        }
        if d.case is not None:
            if not d.case:
                raise self.err("case", "no [[case]] table", "list at least one case, or remove it")
            case_sets = tuple(self.case_set(i, c, coords) for i, c in enumerate(d.case))
        study = Study(
            file=self.file,
            sha256=hashlib.sha256(self.text.encode("utf-8")).hexdigest(),
            name=d.study.name or Path(self.file).stem,
            description=d.study.description,
            models=models,
            variants=variants,
            isolators=isolators,
            damping=damping,
            forces=forces,
            at=at,
            directions=directions,
            observe=observe,
            record=record,
            discretisation=disc,
            case_sets=case_sets,
            text=self.text,
            warnings=tuple(self.warnings),
        )
        size = math.prod(study.shape)  # Python integers: no 64-bit overflow
        if size > MAX_CASES:
            raise self.err(
                "axes",
                f"the product of the axes has {size:,} cases, more than {MAX_CASES:,}",
                "split the study, or list the cases wanted with [[case]] tables",
            )
        self.check_points(study)
        self.check_record(study)
        self.check_catalogues(study)
        return study

    def unique(self, labels: Sequence[Any], path: str, fix: str) -> None:
        seen: set[Any] = set()
        for i, lab in enumerate(labels):
            if lab in seen:
                raise self.err(f"{path}[{i}]", f"{lab!r} appears twice", fix)
            seen.add(lab)

    def empty(self, values: Sequence[Any] | None, name: str) -> None:
        if values is not None and len(values) == 0:
            raise self.err(
                f"axes.{name}",
                "empty axis: no case could be formed",
                f"give at least one value, or leave {name} out for its default",
            )

    def discretisation(self) -> Discretisation:
        s = self.doc.study
        if s.method not in ("fem", "ritz"):
            raise self.err("study.method", f"unknown method {s.method!r}", "use fem or ritz")
        if s.plane not in ("3d", "xz", "yz"):
            raise self.err("study.plane", f"unknown plane {s.plane!r}", "use 3d, xz or yz")
        if s.units is not None and s.units not in ("SI", "US"):
            raise self.err("study.units", f"unknown unit system {s.units!r}", "use SI or US")
        wrong, right = (
            ("elements", "functions") if s.method == "ritz" else ("functions", "elements")
        )
        if getattr(s, wrong) is not None:
            raise self.err(
                f"study.{wrong}",
                f"applies to method {'fem' if s.method == 'ritz' else 'ritz'}",
                f"use study.{right} with method {s.method}",
            )
        n = getattr(s, right)
        if s.n is not None:
            if n is not None:
                raise self.err("study.n", f"give study.{right} only", "n is its old name")
            n = s.n
        return Discretisation(s.method, s.plane, n, s.n_modes, s.gravity_gradient)

    def record(self) -> Record:
        from microg.environment.requirements import requirement

        r = self.doc.record
        rec = Record(
            duration_s=self.q(r.duration, "time", "record.duration"),
            dt_s=self.q(r.dt, "time", "record.dt"),
            max_freq_hz=self.q(r.max_freq, "frequency", "record.max_freq"),
            requirement=r.requirement,
            peaks=r.peaks,
        )
        try:
            requirement(r.requirement)
        except InputError as exc:
            raise InputError(
                exc.what, where=self.where("record.requirement"), fix=exc.fix
            ) from None
        if not (rec.dt_s > 0 and rec.duration_s > rec.dt_s):
            raise self.err(
                "record.dt",
                f"need 0 < dt < duration, got dt = {rec.dt_s:g} s, duration = {rec.duration_s:g} s",
            )
        if rec.duration_s / rec.dt_s > MAX_SAMPLES:
            raise self.err(
                "record.duration",
                f"{rec.duration_s / rec.dt_s:.3g} output samples is more than {MAX_SAMPLES:,}",
                "shorten the duration or lengthen dt",
            )
        if not rec.max_freq_hz > 0:
            raise self.err("record.max_freq", f"must be > 0, got {rec.max_freq_hz:g} Hz")
        return rec

    def variants(self, raw: Sequence[VariantIn] | None, models: Sequence[ModelItem]) -> tuple:
        self.empty(raw, "variant")
        if raw is None:
            return (VariantItem("base", "base"),)
        out = []
        for i, v in enumerate(raw):
            path = f"axes.variant[{i}]"
            given = [k for k in ("move", "model") if getattr(v, k) is not None]
            if len(given) > 1:
                raise self.err(path, "give move or model, not both")
            if v.move is None and (v.to is not None or v.s is not None):
                raise self.err(
                    f"{path}.to", "a position without move = ...", 'add move = "body/mass"'
                )
            if v.model is not None:
                if len(models) > 1:
                    raise self.err(
                        f"{path}.model",
                        "a model-file variant replaces the model, so the study needs one model",
                        "list the models in [study] model instead",
                    )
                out.append(VariantItem(v.name, "model", model=self.model(v.model, f"{path}.model")))
                continue
            if v.move is None:
                out.append(VariantItem(v.name, "base"))
                continue
            if (v.to is None) == (v.s is None):
                raise self.err(
                    path,
                    "a moved mass needs exactly one of to = [x, y, z] or s = (arc length on a "
                    "beam)",
                    'e.g. to = ["0 m", "0 m", "-40 m"]',
                )
            to = None
            if v.to is not None:
                to = np.array([self.q(c, "length", f"{path}.to[{k}]") for k, c in enumerate(v.to)])
            s = None if v.s is None else self.q(v.s, "length", f"{path}.s")
            item = VariantItem(v.name, "move", move=v.move, to_m=to, s_m=s)
            for m in models:
                moved_station(m.model, item, self.where(path))  # validates on every model
            out.append(item)
        self.unique([v.label for v in out], "axes.variant", "give each variant its own name")
        return tuple(out)

    def isolators(self, raw: Sequence[IsolatorIn] | None) -> tuple:
        self.empty(raw, "isolator")
        if raw is None:
            return (IsolatorItem("none", None, "no isolator"),)
        default_m = DEFAULTS["package_mass_kg"]
        if self.doc.study.package_mass is not None:
            default_m = self.q(self.doc.study.package_mass, "mass", "study.package_mass")
        out = []
        for i, r in enumerate(raw):
            path = f"axes.isolator[{i}]"
            m1 = (
                default_m
                if r.package_mass is None
                else self.q(r.package_mass, "mass", f"{path}.package_mass")
            )
            if not m1 > 0:
                raise self.err(f"{path}.package_mass", f"must be > 0, got {m1:g} kg")
            if not 0.0 <= r.zeta1 < 1.0:
                raise self.err(f"{path}.zeta1", f"must be 0 <= zeta1 < 1, got {r.zeta1:g}")
            kinds = [k for k in ("k1", "f_n") if getattr(r, k) is not None]
            if r.report_rule and kinds:
                raise self.err(path, "give k1 (or f_n) or report_rule = true, not both")
            if len(kinds) > 1:
                raise self.err(f"{path}.f_n", "give k1 or f_n, not both")
            if r.report_rule:
                out.append(self.report_rule(r, m1, path))
                continue
            if not kinds:
                if r.zeta1 or r.band is not None or r.mu is not None:
                    raise self.err(path, "mount parameters without k1, f_n or report_rule")
                out.append(IsolatorItem(r.name, None, "no isolator"))
                continue
            if r.k1 is not None:
                k1 = self.q(r.k1, "stiffness", f"{path}.k1")
            else:
                assert r.f_n is not None
                fn = self.q(r.f_n, "frequency", f"{path}.f_n")
                k1 = m1 * (2 * math.pi * fn) ** 2
            if not (k1 > 0 and math.isfinite(k1)):
                raise self.err(f"{path}.k1", f"must be > 0, got {k1:g} N/m")
            c1 = 2.0 * r.zeta1 * math.sqrt(k1 * m1)
            fn_hz = math.sqrt(k1 / m1) / (2 * math.pi)
            desc = (
                f"package {m1:.4g} kg on k1 = {k1:.4g} N/m (f_n = {fn_hz:.4g} Hz), "
                f"zeta1 = {r.zeta1:g}"
            )
            out.append(IsolatorItem(r.name, IsolatorModel(m1=m1, k1=k1, c1=c1), desc))
        self.unique([x.label for x in out], "axes.isolator", "give each isolator its own name")
        return tuple(out)

    def report_rule(self, r: IsolatorIn, m1: float, path: str) -> IsolatorItem:
        from microg.isolation.design import design_mount

        if r.band is None:
            raise self.err(
                f"{path}.band",
                "the report's rule sizes a mount for a band: required",
                'add band = ["0.1 Hz", "1 Hz"]',
            )
        lo = self.q(r.band[0], "frequency", f"{path}.band[0]")
        hi = self.q(r.band[1], "frequency", f"{path}.band[1]")
        if not 0 < lo < hi:
            raise self.err(f"{path}.band", f"need 0 < LO < HI, got {lo:g}, {hi:g} Hz")
        if not 0 < r.target <= 1:
            raise self.err(f"{path}.target", f"must be in (0, 1], got {r.target:g}")
        try:
            d = design_mount(m1, (2 * math.pi * lo, 2 * math.pi * hi), r.target, mu=r.mu)
        except InputError as exc:
            raise self.rewrap(exc, path) from None
        mount = IsolatorModel(m1=m1, k1=d.k1, m2=d.m2 or 0.0, k2=d.k2 or 0.0, c=d.c or 0.0)
        desc = (
            f"report's rule for {lo:.4g}-{hi:.4g} Hz, M_a <= {r.target:g}: package {m1:.4g} kg "
            f"on k1 = {d.k1:.4g} N/m" + (f" with an absorber (mu = {r.mu:g})" if r.mu else "")
        )
        return IsolatorItem(r.name, mount, desc)

    def forces(self, raw: Sequence[str] | None) -> tuple:
        self.empty(raw, "force")
        specs = list(raw) if raw is not None else [DEFAULTS["force"]]
        out = []
        lib = ("crew-pushoff", *activity_library())
        for i, spec in enumerate(specs):
            path = f"axes.force[{i}]" if raw is not None else "axes.force"
            head = spec.partition(":")[0].strip().lower()
            if head == "sources":
                out.append(self.catalogue(spec, path))
                continue
            resolved = spec
            if head not in lib:
                p = Path(spec)
                resolved = str(p if p.is_absolute() else self.base / p)
            try:
                hist = parse_force_spec(resolved, where="force")
            except InputError as exc:
                raise self.rewrap(exc, path) from None
            if hist.is_vector:
                raise self.err(
                    path,
                    f"force {spec!r} changes direction in time; a sweep takes forces along one "
                    "direction",
                    "split it into components, or run microg analyze on it",
                )
            if hist.direction is not None:
                self.warnings.append(
                    f"force {spec!r} carries its own direction "
                    f"({axis_name(hist.direction) or list(np.round(hist.direction, 6))}); the "
                    "direction axis does not apply to it"
                )
            out.append(ForceItem(spec, resolved, hist))
        self.unique([f.label for f in out], "axes.force", "list each force once")
        return tuple(out)

    def catalogue(self, spec: str, path: str) -> ForceItem:
        from microg.environment.sources import load_sources

        name = spec.partition(":")[2].strip()
        if not name:
            raise self.err(path, "no catalogue file after sources:", 'write "sources:FILE.toml"')
        p = Path(name)
        resolved = name if name == "example" else str(p if p.is_absolute() else self.base / p)
        try:
            cat = load_sources(resolved)
        except InputError as exc:
            raise self.rewrap(exc, path) from None
        return ForceItem(spec, resolved, None, "catalogue", cat)

    def damping(self, raw: Sequence[float] | None) -> tuple[float, ...]:
        self.empty(raw, "damping")
        vals = list(raw) if raw is not None else [DEFAULTS["damping"]]
        for i, z in enumerate(vals):
            if not 0.0 <= z < 1.0:
                raise self.err(f"axes.damping[{i}]", f"must be 0 <= zeta < 1, got {z!r}")
        self.unique(vals, "axes.damping", "list each value once")
        return tuple(float(z) for z in vals)

    def directions(self, raw: Sequence[str | list[float]] | None) -> tuple:
        self.empty(raw, "direction")
        vals = list(raw) if raw is not None else [DEFAULTS["direction"]]
        out = []
        for i, v in enumerate(vals):
            path = f"axes.direction[{i}]" if raw is not None else "axes.direction"
            try:
                u = parse_direction(v, self.where(path))
            except InputError as exc:
                raise InputError(exc.what, where=self.where(path), fix=exc.fix) from None
            label = v if isinstance(v, str) else " ".join(f"{c:g}" for c in v)
            out.append(DirectionItem(label, u))
        self.unique([d.label for d in out], "axes.direction", "list each direction once")
        return tuple(out)

    def names(self, raw: Sequence[str] | None, name: str) -> tuple[str, ...]:
        self.empty(raw, name)
        vals = tuple(raw or ())
        self.unique(vals, f"axes.{name}", "list each point once")
        return vals

    def default_crew(self, model: Any) -> str:
        crew = [p for p, k in _point_names(model) if k == "crew"]
        if not crew:
            raise self.err(
                "axes.at", "the model has no crew point", "list the points in at = [...]"
            )
        return crew[0]

    def default_observe(self, model: Any) -> tuple[str, ...]:
        pts = _point_names(model)
        return tuple(p for p, k in pts if k == "experiment") or tuple(p for p, _ in pts)

    def case_set(self, i: int, c: CaseIn, coords: Mapping[str, list[Any]]) -> tuple:
        out = []
        for dim in CASE_DIMS:
            value = getattr(c, dim)
            labels = coords[dim]
            if value is None:
                out.append(tuple(range(len(labels))))
                continue
            items = value if isinstance(value, list) and not _is_vec(value, dim) else [value]
            idx = []
            for k, item in enumerate(items):
                key = item
                if dim == "direction" and not isinstance(item, str):
                    key = " ".join(f"{x:g}" for x in item)
                if key not in labels:
                    path = f"case[{i}].{dim}" + (f"[{k}]" if len(items) > 1 else "")
                    shown = ", ".join(map(str, labels[:12]))
                    raise self.err(
                        path,
                        f"{key!r} is not a value of the {dim} axis",
                        f"add it to [axes] {dim}, or use one of: {shown}",
                    )
                idx.append(labels.index(key))
            out.append(tuple(sorted(set(idx))))
        return tuple(out)

    def check_points(self, study: Study) -> None:
        sets = study.case_sets or (tuple(tuple(range(n)) for n in study.shape),)
        for im, m in enumerate(study.models):
            for iv, v in enumerate(study.variants):
                if not any(im in cs[0] and iv in cs[1] for cs in sets):
                    continue
                model = v.model.model if v.model is not None else m.model
                label = v.model.label if v.model is not None else m.label
                known = [p for p, _ in _point_names(model)]
                for name in ("at", "observe"):
                    k = CASE_DIMS.index(name)
                    used = sorted({i for cs in sets if im in cs[0] and iv in cs[1] for i in cs[k]})
                    for j in used:
                        p = getattr(study, name)[j]
                        if p not in known and not _is_grid_of(model, p):
                            given = getattr(self.doc.axes, name) is not None
                            raise self.err(
                                f"axes.{name}[{j}]" if given else f"axes.{name}",
                                f"point {p!r} is not in model {label!r}",
                                f"known points: {', '.join(known) or '(none)'}; "
                                + ("grid:N for a grid of the model; " if _grids(model) else "")
                                + "or declare it in [[point]]",
                            )

    def check_catalogues(self, study: Study) -> None:
        """A catalogue needs damped modes, no isolator, and its points in every model."""
        from microg.environment.sources import validate_source_points

        cats = [i for i, f in enumerate(study.forces) if f.kind == "catalogue"]
        if not cats:
            return
        sets = study.case_sets or (tuple(tuple(range(n)) for n in study.shape),)
        for k, cs in enumerate(sets):
            used = [i for i in cs[4] if i in cats]
            if not used:
                continue
            where = f"case[{k}]" if study.case_sets else "axes"
            if any(study.isolators[i].mount is not None for i in cs[2]):
                raise self.err(
                    f"{where}.isolator" if study.case_sets else "axes.isolator",
                    "a source catalogue is assessed in the frequency domain without an isolator",
                    'list the catalogue\'s cases with [[case]] isolator = "none"',
                )
            for j in cs[3]:
                if not study.damping[j] > 0:
                    raise self.err(
                        f"axes.damping[{j}]",
                        "a source catalogue needs damped modes (an undamped resonance inside a "
                        "band has an infinite band integral)",
                        "use damping > 0 for its cases",
                    )
            for im in set(cs[0]):
                for iv in set(cs[1]):
                    model = study.variant_model(im, iv)
                    names = [p for p, _ in _point_names(model)]
                    for i in used:
                        try:
                            validate_source_points(study.forces[i].catalogue.sources, names)
                        except InputError as exc:
                            raise self.rewrap(exc, f"axes.force[{i}]") from None

    def check_record(self, study: Study) -> None:
        rec = study.record
        for i, f in enumerate(study.forces):
            if f.history is None:
                continue
            end = float(f.history.timepts[-1])
            if end > rec.duration_s:
                raise self.err(
                    "record.duration",
                    f"force {f.label!r} (axes.force[{i}]) lasts until {end:g} s, after the "
                    f"{rec.duration_s:g}-s record ends",
                    f"use a duration of at least {end:g} s (and time for the response to decay)",
                )
            fv = np.asarray(f.history.force, float)
            last = float(fv[-1])
            peak = float(np.max(np.abs(fv)))
            if peak > 0 and abs(last) > 1e-9 * peak:
                self.warnings.append(
                    f"force {f.label!r} does not end at zero: it holds {last:.4g} N to the end "
                    "of the record (a quasi-steady load, not a transient)"
                )


def _point_names(model: Any) -> list[tuple[str, str]]:
    """(name, kind) of a model's named points (stations: a tuple; modal models: a mapping)."""
    pts = getattr(model, "points", ())
    if isinstance(pts, Mapping):
        return [(n, getattr(p, "kind", "point")) for n, p in pts.items()]
    return [(p.name, getattr(p, "kind", "point")) for p in pts]


def _grids(model: Any) -> set[str]:
    """``grid:N`` of an imported modal model's grids or a frame model's nodes (else empty)."""
    ids = getattr(model, "grid_ids", None)
    if ids is not None:
        return {f"grid:{int(g)}" for g in ids}
    if type(model).__name__ == "GraphModel":
        return {n.name for n in model.nodes}
    return set()


def _is_grid_of(model: Any, name: str) -> bool:
    """True when ``name`` is ``grid:N`` of one of the model's grids (as analyze accepts)."""
    return name.startswith("grid:") and name in _grids(model)


def _is_vec(value: Any, dim: str) -> bool:
    """A direction written as three numbers (one value, not a list of three)."""
    return dim == "direction" and len(value) == 3 and all(isinstance(v, float) for v in value)
