"""Figures and HTML of ``microg analyze`` (reads an :class:`~microg.analysis.Analysis`)."""

from __future__ import annotations

import gc
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from functools import lru_cache, partial
from typing import TYPE_CHECKING, Any

from microg._io import to_jsonable

if TYPE_CHECKING:
    from microg.analysis import Analysis, ModesReady
    from microg.report.render import FigureJob, FigureRenderer

__all__ = [
    "PRELOAD",
    "SHARED",
    "UNPICKLE",
    "early_figures",
    "figure_jobs",
    "figure_names",
    "figures",
    "render_analysis",
    "report_files",
    "setup_jobs",
    "start_renderer",
]


def figure_names(names: list[str]) -> dict[str, str]:
    """Unique, stable file-name stems for point names (``a/b`` and ``a_b`` never collide)."""
    from microg._io import safe_filenames

    return dict(safe_filenames(names))


#: relative drawing costs of the figures (measured), to share them between processes
_WEIGHTS = {
    "model": 2.0,
    "modes": 1.0,
    "forces": 0.8,
    "bands": 1.8,
    "psd": 1.2,
    "integrated": 1.0,
    "isolated": 1.0,
    "vibratory": 1.5,
    "sources": 1.5,
}


def _job(name: str, kind: str, build: Callable[[], Any]) -> FigureJob:
    """A figure job drawing ``build()``'s figure to PNG, weighted by its kind."""
    from microg.report.render import FigureJob

    def draw() -> bytes:
        from microg.plotting.common import png_bytes

        return png_bytes(build())

    return FigureJob(name, _WEIGHTS[kind], draw)


def setup_jobs(ready: ModesReady) -> list[FigureJob]:
    """The figures of the model, its modes and the forces: those known before any response.

    :func:`figure_jobs` begins with these, built from the same values of the result, so a
    figure drawn from the :class:`~microg.analysis.ModesReady` of a run is the one its
    result's report shows (the renderer's early figures, :func:`early_figures`).
    """
    opts = ready.options
    force_pts = {d.point: d.unit_direction for d in opts.disturbances}
    if opts.sources is not None:
        for s in opts.sources.sources:
            force_pts.setdefault(s.at, s.direction)
    observed = list(dict.fromkeys(opts.observe))  # the observations' names, in order

    def model() -> Any:
        from microg.plotting.analysis import model_figure

        return model_figure(ready.structure, ready.modes, force_pts, observed)

    def modes() -> Any:
        from microg.plotting.analysis import modes_figure

        return modes_figure(ready)

    def forces() -> Any:
        from microg.plotting.analysis import force_figure

        return force_figure(list(opts.disturbances), opts.duration_s)

    jobs = [_job("model.png", "model", model), _job("modes.png", "modes", modes)]
    if opts.disturbances:
        jobs.append(_job("forces.png", "forces", forces))
    return jobs


def figure_jobs(result: Analysis) -> list[FigureJob]:
    """Every figure of the report as a job (file name, cost, how to draw it), in order.

    Nothing is drawn (nor matplotlib imported) until a job's ``draw`` is called.
    """
    from microg.analysis import ModesReady

    ready = ModesReady(result.model, result.options, result.structure, result.modes, result.used)
    jobs = setup_jobs(ready)
    stems = figure_names(list(result.observations))
    for name, ob in result.observations.items():
        jobs += _observation_jobs(_job, stems[name], name, ob)
    fd = result.frequency_domain
    if fd is not None:
        vstems = figure_names(list(fd.points))
        for name in fd.points:
            s = vstems[name]
            for kind, plot in (("vibratory", "bands"), ("sources", "contributions")):
                jobs.append(_job(f"{s}-{kind}.png", kind, partial(fd.plot, name, kind=plot)))
    return jobs


def early_figures(renderer: FigureRenderer | None) -> Callable[[ModesReady], object] | None:
    """An ``on_modes`` callback for :func:`microg.analyze` that starts the setup figures.

    With a running renderer, the callback sends :func:`setup_jobs` to its helper, which
    draws them while the response is computed; :func:`figures` then takes them from it.
    None without a renderer (nothing to start).
    """
    if renderer is None or not renderer.active:
        return None

    def start(ready: ModesReady) -> None:
        # never the analysis' failure: at worst these figures are drawn with the others
        with suppress(Exception):
            renderer.draw_early(setup_jobs, ready, omit=_unread(ready.structure))

    return start


def _observation_jobs(job: Any, s: str, name: str, ob: Any) -> list[FigureJob]:
    """The figures of one observed point: history and bands, PSD, integrals, isolation."""

    def live() -> tuple[tuple[str, ...], list[int]]:
        from microg.plotting.analysis import live_axes

        rows = live_axes(ob.response.acceleration)
        return tuple("xyz"[i] for i in rows) or ("x",), rows or [0]

    def bands() -> Any:
        from microg.plotting.analysis import observation_figure

        return observation_figure(ob)

    def psd() -> Any:
        from microg.environment.metrics import Spectrum
        from microg.plotting.environment import plot_psd

        axes, rows = live()
        spec = ob.assessment.spectrum
        return plot_psd(
            Spectrum(spec.freq_hz, spec.psd[rows], spec.df_hz, spec.nyquist_hz, spec.method),
            axes=axes,
            title=f"PSD at {name}",
        )

    def integrated() -> Any:
        from microg.plotting.environment import plot_integrated_acceleration

        axes, rows = live()
        r = ob.response
        return plot_integrated_acceleration(
            r.timepts,
            r.acceleration[rows],
            axes=axes,
            title=f"10-s integrated acceleration at {name}",
        )

    def isolated() -> Any:
        from microg.plotting.analysis import isolation_figure

        return isolation_figure(ob)

    out = [
        job(f"{s}-bands.png", "bands", bands),
        job(f"{s}-psd.png", "psd", psd),
        job(f"{s}-integrated.png", "integrated", integrated),
    ]
    if ob.isolation.package_accel is not None:
        out.append(job(f"{s}-isolated.png", "isolated", isolated))
    return out


def figures(
    result: Analysis,
    renderer: FigureRenderer | None = None,
    while_waiting: Callable[[], object] | None = None,
) -> dict[str, bytes]:
    """PNG bytes of every figure of the report, keyed by file name, in report order.

    Parameters
    ----------
    result : Analysis
    renderer : FigureRenderer, optional
        Helper processes started before the computation (see :mod:`microg.report.render`):
        they draw the figures while this process loads the HTML template and runs
        ``while_waiting``.  Without one, or if it fails, the figures are drawn here (the
        library's default), with the cyclic garbage collector paused.  The bytes are the
        same either way.
    while_waiting : callable, optional
        Work of the caller's to do while helpers draw (run in any case, before drawing
        in-process when there are none).
    """
    done = False

    def meanwhile() -> None:
        nonlocal done
        _analysis_template()
        if while_waiting is not None:
            while_waiting()
        done = True

    if renderer is not None and renderer.active:
        out = renderer.render(
            figure_jobs,
            result,
            while_waiting=meanwhile,
            omit=_unread(result.structure),
            reuse_early=_same_setup(renderer.early_payload, result),
        )
        if out is not None:
            return out
    if while_waiting is not None and not done:  # exactly once, on every path
        while_waiting()
    with _collector_paused():
        return {j.name: j.draw() for j in figure_jobs(result)}


def report_files(
    result: Analysis,
    renderer: FigureRenderer | None = None,
    while_waiting: Callable[[dict[str, Any]], object] | None = None,
) -> dict[str, Any]:
    """The report's files: every figure's PNG bytes, in report order, then ``report.html``.

    Parameters
    ----------
    result : Analysis
    renderer : FigureRenderer, optional
        Helper processes started before the computation (:func:`start_renderer`): they
        draw the figures and write the HTML page while this process runs
        ``while_waiting``.  Without one, or if it fails, all is done here, as
        :func:`figures` and :func:`render_analysis` do; the files are the same either way.
    while_waiting : callable, optional
        Work of the caller's to do meanwhile, given ``result.to_dict()`` (run once on every
        path; e.g. writing the JSON text).
    """
    summary = result.to_dict()
    done = False

    def meanwhile() -> None:
        nonlocal done
        if while_waiting is not None:
            while_waiting(summary)
        done = True

    if renderer is not None and renderer.active:
        # the page is written by the helper from the caller's summary: a structure's
        # matrices are not sent (:func:`_unread`), and the summary's effective masses need them
        out = renderer.render(
            _report_jobs,
            (result, summary),
            while_waiting=meanwhile,
            omit=_unread(result.structure),
            finish=_html_file,
            reuse_early=_same_setup(renderer.early_payload, result),
        )
        if out is not None and "report.html" in out:
            return out
    if while_waiting is not None and not done:  # exactly once, on every path
        while_waiting(summary)
    figs = figures(result)
    return {**figs, "report.html": render_analysis(result, figs, summary)}


def _report_jobs(request: tuple[Analysis, dict[str, Any]]) -> list[FigureJob]:
    """The figure jobs of a :func:`report_files` request (the result, its summary)."""
    return figure_jobs(request[0])


def _html_file(request: tuple[Analysis, dict[str, Any]], figs: dict[str, bytes]) -> dict[str, str]:
    """``report.html`` of a :func:`report_files` request and its figures (``finish`` step)."""
    result, summary = request
    return {"report.html": render_analysis(result, figs, summary)}


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off for the block, back as it was after it.

    Importing matplotlib and drawing a figure make many objects, which start collections
    of the whole heap (~0.1 s of the ~0.5 s the report's figures take); the few figures'
    reference cycles are collected once, after the block.
    """
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


#: what a renderer for :func:`figures` imports before its warm-up: the figure modules
PRELOAD = (
    "microg.plotting.analysis",
    "microg.plotting.environment",
    "microg.report.analysis",
)

#: ... and after it, while it waits: the modules an :class:`~microg.analysis.Analysis` of a
#: frame model needs to unpickle that a caller forking before its computation has not
#: imported yet.  None of them loads scipy (the matrices are omitted: :func:`_unread`)
UNPICKLE = ("microg.structure.fem", "microg.structure.frame")

#: ... and what the caller imports before the fork, because both processes use it: a
#: station's frame model (discretising it, and unpickling its structure), numpy's masked
#: arrays (matplotlib draws through them; ``numpy.unique`` loads them), and the standard
#: modules that pydantic and scipy import in the caller and matplotlib in the helper
#: (~0.06 s that each process would otherwise pay)
SHARED = (
    "logging",
    "subprocess",
    "socket",
    "decimal",
    "fractions",
    "zoneinfo",
    "calendar",
    "numpy.ma",
    "microg.structure.fem",
    "microg.structure.frame",
)


def _unread(structure: Any) -> Callable[[object], bool]:
    """What a figure request omits: the structure's mass and stiffness matrices.

    No figure reads them, and sending them (scipy sparse matrices) would make the figure
    helper import scipy (~0.12 s) only to unpickle them.  The objects themselves, by
    identity: other sparse matrices (a frame model's sample rows) are sent.
    """
    ids = {id(structure.mass), id(structure.stiffness)}
    return lambda obj: id(obj) in ids


def _same_setup(ready: Any, result: Analysis) -> bool:
    """Whether an early request's :class:`~microg.analysis.ModesReady` is ``result``'s own.

    Only then do the early figures stand for the result's (the same objects, not merely
    equal ones: a renderer reused for another analysis draws everything again).
    """
    if ready is None:
        return False
    same = all(getattr(ready, k) is getattr(result, k) for k in ("options", "structure", "modes"))
    return same and ready.used is result.used and ready.model == result.model


def start_renderer(processes: int | None = None) -> FigureRenderer:
    """Start the helper processes of :func:`figures` now, before the computation.

    They import matplotlib, the figure modules and the HTML template on another core while
    the caller computes; pass the renderer to :func:`figures` or :func:`report_files` (use
    it as a context manager, so the helpers stop if the computation fails).  See
    :mod:`microg.report.render`.
    """
    from microg.report.render import FigureRenderer

    return FigureRenderer.start(
        PRELOAD, processes, then=UNPICKLE, warm=_analysis_template, shared=SHARED
    )


@lru_cache(maxsize=1)
def _analysis_template() -> Any:
    """The compiled ``analyze.html`` template (compiling it takes ~0.15 s: once a process)."""
    from microg.report.html import environment

    return environment().get_template("analyze.html")


def render_analysis(
    result: Analysis, figs: dict[str, bytes], summary: dict[str, Any] | None = None
) -> str:
    """Self-contained HTML of the analysis, figures embedded as data URIs.

    Parameters
    ----------
    result : Analysis
    figs : dict of str to bytes
        PNG bytes by file name (:func:`figures`).
    summary : dict, optional
        ``result.to_dict()``, if the caller has it already.
    """
    from microg import __version__
    from microg.report.html import png_data_uri

    data = to_jsonable(result.to_dict() if summary is None else summary)
    uris = {k: png_data_uri(v) for k, v in figs.items()}
    stems = figure_names(list(result.observations))
    obs = []
    for name in result.observations:
        s = stems[name]
        keys = ["bands", "psd", "integrated", "isolated"]
        obs.append(
            {
                "name": name,
                "data": data["observations"][name],
                "figs": [uris[f"{s}-{k}.png"] for k in keys if f"{s}-{k}.png" in uris],
            }
        )
    vib = []
    fd = result.frequency_domain
    if fd is not None:
        vstems = figure_names(list(fd.points))
        for name in fd.points:
            s = vstems[name]
            entry = data["frequency_domain"][name]
            worst = entry.get("worst_band")
            top = None
            if worst is not None:
                bands = entry["contributions"]["bands"]
                band = next((b for b in bands if b["center_hz"] == worst["center_hz"]), None)
                top = band
            vib.append(
                {
                    "name": name,
                    "data": entry,
                    "worst": top,
                    "figs": [uris[f"{s}-{k}.png"] for k in ("vibratory", "sources")],
                }
            )
    return str(
        _analysis_template().render(
            version=__version__,
            d=data,
            obs=obs,
            vib=vib,
            model_fig=uris["model.png"],
            forces_fig=uris.get("forces.png"),
            modes_fig=uris["modes.png"],
        )
    )
