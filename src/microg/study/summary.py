"""The summary of a sweep: worst cases, complying fraction, heat maps, reproduction commands.

:func:`summarize` reads the store once, block by block (memory bounded by one block,
whatever the size of the study), and keeps:

* the number of cases computed and the fraction that comply, and how many of them needed the
  exact (certified) peak search;
* the worst cases per observed point (smallest margin; a case whose record resolves no
  band, margin NaN, counts as worst: it cannot be shown to comply);
* the worst margin over two chosen axes (the minimum over every other axis): the heat map;
* the complying fraction for each value of each axis;
* for any case, the ``microg analyze`` command line that reproduces it alone
  (:func:`case_command`).
"""

from __future__ import annotations

import shlex
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from microg._json import json_number
from microg.errors import InputError
from microg.study.cases import CASE_DIMS, Study, default_n_modes
from microg.study.store import SweepStore

__all__ = [
    "Summary",
    "summarize",
    "default_heatmap",
    "case_command",
    "case_python",
    "model_file",
    "check_heatmap",
]


class SweepRecord(Protocol):
    """What a summary reads of a sweep (:class:`microg.study.run.SweepResult` is one).

    The summary depends on the plan and the store only, never on the runner that wrote them.
    """

    @property
    def study(self) -> Study:
        """The plan."""

    @property
    def store(self) -> SweepStore:
        """The results, block by block."""

    @property
    def out(self) -> Path | None:
        """The output directory (None: in memory)."""

    @property
    def bases(self) -> Mapping[str, Any]:
        """``"model/variant"`` -> the modes in its response (JSON-ready)."""

    @property
    def warnings(self) -> Sequence[str]:
        """What the user should know."""

    @property
    def dataset(self) -> Any:
        """The results as a labelled ``xarray.Dataset``."""


#: requirement names as ``microg analyze --requirement`` spells them
_CLI_REQUIREMENT = {"iss": "iss", "ssp41000": "ssp41000", "flat": "flat", "report-1e-5g": "flat"}


@dataclass(frozen=True)
class Summary:
    """What the sweep's report and ``--json`` say.

    Attributes
    ----------
    cases : cases computed; planned : cases of the plan
    complying : cases that comply; complying_fraction : complying / cases (None: no case)
    peaks_certified : cases whose peaks are the certified exact maxima (the others report
        the sampled record's: the verdict does not depend on the difference)
    worst : per observed point, its worst cases (dicts: case labels, margin, peak, ...)
    heatmap_dims : the two axes of the heat map; heatmap_labels : their labels
    heatmap : (n1, n2) the worst margin over every other axis (NaN: nothing computed)
    fraction_by : axis -> [(label, complying fraction or None), ...]
    requirement, record : what the cases were judged against
    bases : the modes of each variant; warnings : the sweep's warnings
    out : the output directory (None: in memory)
    study : the plan (JSON-ready)
    worst_bands : per observed point, the band RMS (3, nb) of its worst case, with the
        band centres, limits and which bands are judged (for the figure)
    """

    cases: int
    planned: int
    complying: int
    complying_fraction: float | None
    worst: dict[str, list[dict[str, Any]]]
    heatmap_dims: tuple[str, str]
    heatmap_labels: tuple[list[Any], list[Any]]
    heatmap: np.ndarray = field(repr=False)
    fraction_by: dict[str, list[tuple[Any, float | None]]] = field(repr=False)
    requirement: str = ""
    record: dict[str, Any] = field(default_factory=dict)
    bases: dict[str, Any] = field(default_factory=dict, repr=False)
    warnings: list[str] = field(default_factory=list)
    out: str | None = None
    study: dict[str, Any] = field(default_factory=dict, repr=False)
    worst_bands: dict[str, dict[str, Any]] = field(default_factory=dict, repr=False)
    peaks_certified: int = 0

    def worst_list(self) -> list[dict[str, Any]]:
        """The worst case of every observed point, worst first."""
        rows = [v[0] for v in self.worst.values() if v]
        return sorted(rows, key=_sort_key)

    def to_dict(self) -> dict[str, Any]:
        """``{"cases", "complying_fraction", "worst", ...}`` (the ``microg sweep --json``)."""
        return {
            "cases": self.cases,
            "complying_fraction": self.complying_fraction,
            "worst": self.worst_list(),
            "planned": self.planned,
            "complying": self.complying,
            "peaks_certified": self.peaks_certified,
            "worst_per_point": self.worst,
            "heatmap": {
                "dims": list(self.heatmap_dims),
                "labels": [list(x) for x in self.heatmap_labels],
                "margin": [[json_number(v) for v in row] for row in self.heatmap],
            },
            "fraction_by": {
                k: [{"value": lab, "complying_fraction": fr} for lab, fr in v]
                for k, v in self.fraction_by.items()
            },
            "requirement": self.requirement,
            "record": self.record,
            "modes": self.bases,
            "warnings": list(self.warnings),
            "out": self.out,
            "dataset": None if self.out is None else f"{self.out}/results.zarr",
        }

    def to_xarray(self) -> Any:
        """The heat map as an ``xarray.Dataset``: ``margin`` over its two axes (NaN: no case)."""
        import xarray as xr

        d0, d1 = self.heatmap_dims
        l0, l1 = (list(x) for x in self.heatmap_labels)
        return xr.Dataset(
            {
                "margin": (
                    (d0, d1),
                    np.asarray(self.heatmap, float),
                    {
                        "units": "1",
                        "long_name": "worst margin (limit / band RMS) over every other axis",
                    },
                )
            },
            coords={d0: [str(v) for v in l0], d1: [str(v) for v in l1]},
            attrs={
                "cases": int(self.cases),
                "planned": int(self.planned),
                "complying": int(self.complying),
                "peaks_certified": int(self.peaks_certified),
                "complying_fraction": float("nan")
                if self.complying_fraction is None
                else float(self.complying_fraction),
                "requirement": self.requirement,
            },
        )

    def _repr_html_(self) -> str:
        """The summary in a notebook: the verdict, each point's worst case, the heat map.

        The numbers are :meth:`to_dict`'s (margin = limit / band RMS, below 1 fails); the heat
        map's cells are its worst margins over every other axis ("-": no case computed).
        """
        from html import escape

        def num(v: Any) -> str:
            if v is None:
                return "-"
            if v == "inf":
                return "inf"
            f = float(v)
            return "-" if np.isnan(f) else f"{f:.3g}"

        frac = self.complying_fraction
        share = "-" if frac is None else f"{100.0 * frac:.1f} %"
        planned = f" of {self.planned} planned" if self.planned != self.cases else ""
        head = (
            f"<p><b>sweep</b>: {self.cases} cases{planned}, {self.complying} comply with "
            f"{escape(self.requirement)} ({share})</p>"
        )
        rows = []
        for name, worst in self.worst.items():
            if not worst:
                continue
            w = worst[0]
            case = ", ".join(
                f"{escape(str(k))}={escape(str(v))}" for k, v in w["case"].items() if k != "observe"
            )
            verdict = "complies" if w.get("complies") else "does not comply"
            rows.append(
                f"<tr><td>{escape(name)}</td><td>{num(w.get('margin'))}</td>"
                f"<td>{verdict}</td><td>{case}</td></tr>"
            )
        worst_table = (
            "<table><tr><th>observed point</th><th>worst margin</th><th>verdict</th>"
            f"<th>its case</th></tr>{''.join(rows)}</table>"
        )
        d0, d1 = self.heatmap_dims
        l0, l1 = self.heatmap_labels
        cells = "".join(
            f"<tr><th>{escape(str(a))}</th>"
            + "".join(f"<td>{num(v)}</td>" for v in np.asarray(self.heatmap, float)[i])
            + "</tr>"
            for i, a in enumerate(l0)
        )
        heat = (
            f"<p>worst margin over the other axes, {escape(d0)} (rows) by {escape(d1)}</p>"
            f"<table><tr><th></th>{''.join(f'<th>{escape(str(b))}</th>' for b in l1)}</tr>"
            f"{cells}</table>"
            if len(l0) * len(l1) <= 400
            else ""
        )
        warn = "".join(f"<p>warning: {escape(w)}</p>" for w in self.warnings)
        return head + worst_table + heat + warn

    def plot(self, ax: Any = None) -> Any:
        """The heat map of the worst margins (:func:`microg.plotting.study.heatmap_figure`).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.study import heatmap_figure

        return heatmap_figure(self, ax=ax)


def _sort_key(row: dict[str, Any]) -> tuple[float, float]:
    m = row["margin"]
    key = -np.inf if m is None else (np.inf if m == "inf" else float(m))
    peak = row["peak_accel_g"]
    return (key, -(peak if isinstance(peak, float) and np.isfinite(peak) else 0.0))


def default_heatmap(study: Study) -> tuple[str, str]:
    """The heat map's axes when none are asked.

    At x observe when both vary, else the two axes with the most values.
    """
    sizes = dict(zip(CASE_DIMS, study.shape, strict=True))
    varying = [d for d in CASE_DIMS if sizes[d] > 1]
    if "at" in varying and "observe" in varying:
        return ("at", "observe")
    ranked = sorted(varying, key=lambda d: -sizes[d])[:2]
    for d in ("at", "observe", "force", "direction"):
        if len(ranked) >= 2:
            break
        if d not in ranked:
            ranked.append(d)
    order = [d for d in CASE_DIMS if d in ranked]
    return (order[0], order[1])


def check_heatmap(study: Study, dims: Sequence[str] | None) -> tuple[str, str]:
    """The heat map's two axes: ``dims`` checked, or :func:`default_heatmap`."""
    if dims is None:
        return default_heatmap(study)
    dims = [str(d).strip() for d in dims]
    if len(dims) != 2 or dims[0] == dims[1] or any(d not in CASE_DIMS for d in dims):
        raise InputError(
            f"expected two different axes, got {','.join(dims)!r}",
            where="heatmap",
            fix=f"name two of: {', '.join(CASE_DIMS)}, e.g. at,observe",
        )
    return (dims[0], dims[1])


def summarize(
    result: SweepRecord, heatmap: Sequence[str] | None = None, n_worst: int = 5
) -> Summary:
    """The summary of a sweep's results (one pass over the store, block by block).

    Parameters
    ----------
    result : the sweep (a :class:`~microg.study.run.SweepResult`)
    heatmap : the two axes of the heat map (default: :func:`default_heatmap`)
    n_worst : worst cases kept per observed point
    """
    study = result.study
    dims = check_heatmap(study, heatmap)
    shape = dict(zip(CASE_DIMS, study.shape, strict=True))
    heat = np.full((shape[dims[0]], shape[dims[1]]), np.nan)
    n_comp = {d: np.zeros(shape[d], np.int64) for d in CASE_DIMS}
    n_ok = {d: np.zeros(shape[d], np.int64) for d in CASE_DIMS}
    best: list[list[tuple[float, float, tuple[int, ...]]]] = [[] for _ in study.observe]
    total = ok_total = certified = 0
    names = ("margin", "peak_accel_g", "complies", "computed", "peak_certified")
    for blk in study.blocks():
        v = result.store.read(blk, names)
        comp = v["computed"]
        if not comp.any():
            continue
        index = [np.array([i]) for i in blk.index] + [
            np.arange(blk.at.start, blk.at.stop),
            np.arange(shape["direction"]),
            np.arange(blk.observe.start, blk.observe.stop),
        ]
        full = [x[(None,) * 5] for x in (v["margin"], v["peak_accel_g"], comp, v["complies"])]
        margin, peak, comp8, ok8 = full
        ok8 = ok8 & comp8
        total += int(comp8.sum())
        certified += int((v["peak_certified"] & comp).sum())
        ok_total += int(ok8.sum())
        for k, d in enumerate(CASE_DIMS):
            other = tuple(j for j in range(8) if j != k)
            np.add.at(n_comp[d], index[k], comp8.sum(axis=other))
            np.add.at(n_ok[d], index[k], ok8.sum(axis=other))
        a, b = CASE_DIMS.index(dims[0]), CASE_DIMS.index(dims[1])
        other = tuple(j for j in range(8) if j not in (a, b))
        m = np.where(comp8, margin, np.nan)
        with np.errstate(invalid="ignore"):
            red = np.fmin.reduce(m, axis=other, initial=np.inf, where=comp8)
        red = np.where(comp8.any(axis=other), red, np.nan)
        if a > b:
            red = red.T
        sub = heat[np.ix_(index[a], index[b])]
        heat[np.ix_(index[a], index[b])] = np.fmin(sub, red)
        # worst cases per observed point in this block
        key = np.where(np.isnan(margin), -np.inf, margin)
        for jo, o in enumerate(index[7]):
            kk = key[..., jo].ravel()
            cc = comp8[..., jo].ravel()
            cand = np.flatnonzero(cc)
            if cand.size == 0:
                continue
            order = cand[np.lexsort((-peak[..., jo].ravel()[cand], kk[cand]))][:n_worst]
            sub_shape = key[..., jo].shape
            for flat in order:
                loc = np.unravel_index(int(flat), sub_shape)
                case = tuple(int(index[d][loc[d]]) for d in range(7)) + (int(o),)
                best[o].append((float(kk[flat]), -float(peak[..., jo].ravel()[flat]), case))
            best[o].sort(key=lambda x: (x[0], x[1]))
            del best[o][n_worst:]
        del margin, peak
    worst: dict[str, list[dict[str, Any]]] = {}
    bands: dict[str, dict[str, Any]] = {}
    rows = _case_values(result, sorted({case for b in best for _, _, case in b}))
    for o, kept in enumerate(best):
        worst[study.observe[o]] = [_case_row(result, rows, case) for _, _, case in kept]
        if kept:
            first = rows["cases"][kept[0][2]]
            bands[study.observe[o]] = {
                "case": worst[study.observe[o]][0]["case"],
                "center_hz": rows["center_hz"],
                "rms_g": rows["band_rms_g"][first],
                "limit_g": rows["limit_g"],
                "judged": rows["judged"],
            }
    fraction_by = {
        d: [
            (lab, (float(n_ok[d][i] / n_comp[d][i]) if n_comp[d][i] else None))
            for i, lab in enumerate(study.coords[d])
        ]
        for d in CASE_DIMS
    }
    rec = study.record
    return Summary(
        cases=total,
        planned=study.n_cases,
        complying=ok_total,
        complying_fraction=(ok_total / total) if total else None,
        worst=worst,
        heatmap_dims=dims,
        heatmap_labels=(list(study.coords[dims[0]]), list(study.coords[dims[1]])),
        heatmap=heat,
        fraction_by=fraction_by,
        requirement=rec.requirement,
        record={
            "duration_s": rec.duration_s,
            "dt_s": rec.dt_s,
            "max_freq_hz": rec.max_freq_hz,
            "requirement": rec.requirement,
        },
        bases=dict(result.bases),
        warnings=list(result.warnings),
        out=None if result.out is None else str(result.out),
        study=study.to_dict(),
        worst_bands=bands,
        peaks_certified=certified,
    )


def _case_values(result: SweepRecord, cases: Sequence[tuple[int, ...]]) -> dict[str, Any]:
    """The stored values of the given cases, in one read of the store.

    ``cases`` maps each case to its row in the arrays ``margin``, ``peak_accel_g``,
    ``rms_accel_g``, ``complies``, ``peak_certified`` (n,) and ``band_rms_g`` (n, 3, nb);
    ``center_hz``, ``limit_g`` and ``judged`` (nb,) are the bands'.
    """
    import xarray as xr

    names = ("margin", "peak_accel_g", "rms_accel_g", "complies", "band_rms_g", "peak_certified")
    out: dict[str, Any] = {"cases": {c: i for i, c in enumerate(cases)}}
    ds = result.dataset
    if cases:
        idx = np.asarray(cases, int)
        sel = {d: xr.DataArray(idx[:, k], dims="_case") for k, d in enumerate(CASE_DIMS)}
        sub = ds[list(names)].isel(sel).transpose("_case", ...).compute()
        out.update({n: np.asarray(sub[n].values) for n in names})
    out["center_hz"] = np.asarray(ds.band.values, float)
    out["limit_g"] = np.asarray(ds.limit_g.values, float)
    out["judged"] = np.asarray(ds.judged.values, bool)
    return out


def _case_row(result: SweepRecord, rows: dict[str, Any], case: tuple[int, ...]) -> dict[str, Any]:
    """One worst case's line of the summary, from :func:`_case_values`."""
    study = result.study
    labels = study.case(case)
    i = rows["cases"][case]
    to = rows["band_rms_g"][i]  # (3, nb)
    lim = rows["limit_g"]
    judged = rows["judged"]
    with np.errstate(divide="ignore", invalid="ignore"):
        margin_b = np.where(to > 0, lim / np.where(to > 0, to, 1.0), np.inf)
    wb = None
    if judged.any():
        mm = np.where(judged[None, :], margin_b, np.inf)
        ax, band = np.unravel_index(int(np.argmin(mm)), mm.shape)
        wb = {
            "center_hz": float(rows["center_hz"][band]),
            "axis": "xyz"[ax],
            "rms_g": float(to[ax, band]),
            "limit_g": float(lim[band]),
        }
    return {
        "case": {k: (float(v) if k == "damping" else v) for k, v in labels.items()},
        "index": [int(i) for i in case],
        "margin": json_number(float(rows["margin"][i])),
        "peak_accel_g": float(rows["peak_accel_g"][i]),
        "peak_certified": bool(rows["peak_certified"][i]),
        "rms_accel_g": float(rows["rms_accel_g"][i]),
        "complies": bool(rows["complies"][i]),
        "worst_band": wb,
        "command": case_command(result, labels),
        "python": case_python(result, labels),
        "isolated": study.isolators[case[2]].mount is not None,
    }


def _items(result: SweepRecord, labels: dict[str, Any]) -> tuple[Any, Any]:
    """The model item (the variant's file, or the study's model) and the variant of a case."""
    study = result.study
    im = study.coords["model"].index(labels["model"])
    iv = study.coords["variant"].index(labels["variant"])
    m, v = study.models[im], study.variants[iv]
    item = v.model if v.kind == "model" and v.model is not None else m
    return item, v


def _model_ref(result: SweepRecord, labels: dict[str, Any]) -> tuple[str | None, str]:
    """(path for ``microg analyze``, or None when the CLI cannot load it; Python expression)."""
    study = result.study
    m = study.models[study.coords["model"].index(labels["model"])]
    item, v = _items(result, labels)
    if v.kind == "move" or item.derived:
        written = None
        if result.out is not None:
            written = str(result.out / "models" / model_file(m.label, v.label))
        expr = f"microg.load_station({written!r})" if written else "<the variant's Station>"
        return written, expr
    if item.units is not None or item.points is not None:
        expr = (
            f"microg.models.load.load_model({item.path!r}, units={item.units!r}, "
            f"points={item.points!r})"
        )
        return item.path, expr
    return item.path, repr(item.path)


def model_file(model: str, variant: str) -> str:
    """File name of a derived model written beside the results (``models/NAME.toml``)."""
    from microg._io import safe_filenames

    key = f"{model}--{variant}"
    return safe_filenames([key])[key] + ".toml"


def case_command(result: SweepRecord, labels: dict[str, Any]) -> str | None:
    """The ``microg analyze`` command line that reproduces one case alone (no isolator).

    A source catalogue's case is ``microg analyze --sources FILE``.  None when the model
    cannot be named on a command line (an in-memory study): :func:`case_python` always can.
    """
    study = result.study
    path, _ = _model_ref(result, labels)
    d, r = study.discretisation, study.record
    force = study.forces[study.coords["force"].index(labels["force"])]
    if path is None:
        return None
    direc = study.directions[study.coords["direction"].index(labels["direction"])]
    axis = direc.label.lstrip("+-") in ("x", "y", "z")
    dtext = direc.label if axis else " ".join(repr(float(x)) for x in direc.vector)
    item, _ = _items(result, labels)
    args = ["microg", "analyze", path]
    if item.units is not None:
        args += ["--units", item.units]
    if item.points is not None:
        args += ["--points", item.points]
    if force.catalogue is not None:
        args += ["--sources", force.spec]
    else:
        args += ["--force", force.spec, "--at", labels["at"], "--direction", dtext]
    args += ["--observe", labels["observe"], "--damping", repr(float(labels["damping"]))]
    args += ["--method", d.method]
    if d.method == "ritz":
        args += ["--plane", d.plane]
    if d.n is not None:
        args += ["--elements", str(d.n)]
    n_modes = d.n_modes or default_n_modes(study)
    if n_modes is not None:
        args += ["--n-modes", str(n_modes)]
    if d.gravity_gradient:
        args += ["--gravity-gradient"]
    args += ["--max-freq", f"{r.max_freq_hz!r} Hz", "--duration", f"{r.duration_s!r} s"]
    args += ["--dt", f"{r.dt_s!r} s", "--requirement", _CLI_REQUIREMENT.get(r.requirement, "iss")]
    return " ".join(shlex.quote(a) for a in args)


def case_python(result: SweepRecord, labels: dict[str, Any]) -> str:
    """The Python call that reproduces one case alone with :func:`microg.analyze`."""
    study = result.study
    _, model = _model_ref(result, labels)
    d, r = study.discretisation, study.record
    force = study.forces[study.coords["force"].index(labels["force"])]
    direc = study.directions[study.coords["direction"].index(labels["direction"])]
    if force.catalogue is not None:
        what = f"sources={force.spec!r}"
    else:
        vec = [float(x) for x in direc.vector]
        what = f"force={force.spec!r}, at={labels['at']!r}, direction={vec!r}"
    return (
        f"microg.analyze({model}, {what}, observe=[{labels['observe']!r}], "
        f"damping={float(labels['damping'])!r}, method={d.method!r}, plane={d.plane!r}, "
        f"n={d.n!r}, n_modes={d.n_modes or default_n_modes(study)!r}, "
        f"gravity_gradient={d.gravity_gradient!r}, max_freq={r.max_freq_hz!r}, "
        f"duration={r.duration_s!r}, dt={r.dt_s!r}, requirement={r.requirement!r})"
    )
