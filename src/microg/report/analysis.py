"""Figures and HTML of ``microg analyze`` (reads an :class:`~microg.analysis.Analysis`).

The figures are drawn in this process by :mod:`microg.plotting` and saved as PNG with
``Figure.savefig``; the page embeds them as data URIs.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache, partial
from typing import TYPE_CHECKING, Any

from microg._io import to_jsonable

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from microg.analysis import Analysis

__all__ = [
    "OBSERVATION_CHARTS",
    "figure_builders",
    "figure_names",
    "figures",
    "interactive_charts",
    "interactive_model",
    "render_analysis",
    "report_files",
]


def figure_names(names: list[str]) -> dict[str, str]:
    """Unique, stable file-name stems for point names (``a/b`` and ``a_b`` never collide)."""
    from microg._io import safe_filenames

    return dict(safe_filenames(names))


def figure_builders(result: Analysis) -> dict[str, Callable[[], Figure]]:
    """Every figure of the report by file name, in report order, as a function drawing it.

    Nothing is drawn (nor matplotlib imported) until a function is called.

    Parameters
    ----------
    result : Analysis
    """
    opts = result.options
    force_pts = {d.point: d.unit_direction for d in opts.disturbances}
    if opts.sources is not None:
        for s in opts.sources.sources:
            force_pts.setdefault(s.at, s.direction)
    observed = list(dict.fromkeys(opts.observe))  # the observations' names, in order

    def model() -> Figure:
        from microg.plotting.analysis import model_figure

        return model_figure(result.structure, result.modes, force_pts, observed)

    def modes() -> Figure:
        from microg.plotting.analysis import modes_figure

        return modes_figure(result)

    def forces() -> Figure:
        from microg.plotting.analysis import force_figure

        return force_figure(list(opts.disturbances), opts.duration_s)

    out: dict[str, Callable[[], Figure]] = {"model.png": model, "modes.png": modes}
    if opts.disturbances:
        out["forces.png"] = forces
    stems = figure_names(list(result.observations))
    for name, ob in result.observations.items():
        out.update(_observation_builders(stems[name], name, ob))
    fd = result.frequency_domain
    if fd is not None:
        vstems = figure_names(list(fd.points))
        for name in fd.points:
            s = vstems[name]
            for kind, plot in (("vibratory", "bands"), ("sources", "contributions")):
                out[f"{s}-{kind}.png"] = partial(fd.plot, name, kind=plot)
    return out


def _observation_builders(s: str, name: str, ob: Any) -> dict[str, Callable[[], Figure]]:
    """The figures of one observed point: history and bands, PSD, integrals, isolation."""

    def live() -> tuple[tuple[str, ...], list[int]]:
        from microg.plotting.analysis import live_axes

        rows = live_axes(ob.response.acceleration)
        return tuple("xyz"[i] for i in rows) or ("x",), rows or [0]

    def bands() -> Figure:
        from microg.plotting.analysis import observation_figure

        return observation_figure(ob)

    def psd() -> Figure:
        from microg.environment.metrics import Spectrum
        from microg.plotting.environment import plot_psd

        axes, rows = live()
        spec = ob.assessment.spectrum
        return plot_psd(
            Spectrum(spec.freq_hz, spec.psd[rows], spec.df_hz, spec.nyquist_hz, spec.method),
            axes=axes,
            title=f"PSD at {name}",
        )

    def integrated() -> Figure:
        from microg.plotting.environment import plot_integrated_acceleration

        axes, rows = live()
        r = ob.response
        return plot_integrated_acceleration(
            r.timepts,
            r.acceleration[rows],
            axes=axes,
            title=f"10-s integrated acceleration at {name}",
        )

    def isolated() -> Figure:
        from microg.plotting.analysis import isolation_figure

        return isolation_figure(ob)

    out = {f"{s}-bands.png": bands, f"{s}-psd.png": psd, f"{s}-integrated.png": integrated}
    if ob.isolation.package_accel is not None:
        out[f"{s}-isolated.png"] = isolated
    return out


def figures(result: Analysis) -> dict[str, bytes]:
    """PNG bytes of every figure of the report, keyed by file name, in report order.

    Each figure is drawn and saved (``Figure.savefig``, PNG) in turn, then released.

    Parameters
    ----------
    result : Analysis
    """
    from microg.plotting.common import png_bytes

    return {name: png_bytes(build()) for name, build in figure_builders(result).items()}


def report_files(
    result: Analysis, summary: dict[str, Any] | None = None, *, static: bool = False
) -> dict[str, Any]:
    """The report's files: every figure's PNG bytes, in report order, then ``report.html``.

    Parameters
    ----------
    result : Analysis
    summary : dict, optional
        ``result.to_dict()``, if the caller has it already.
    static : bool
        PNG figures only: leave out the interactive 3-D view (and plotly.js, ~4.8 MB).
    """
    figs = figures(result)
    return {**figs, "report.html": render_analysis(result, figs, summary, static=static)}


def interactive_model(result: Analysis) -> str:
    """The 3-D model and mode-shape slider as an HTML fragment (plotly.js is in the head)."""
    from microg.report.html import chart_fragment

    return chart_fragment(result.plot3d(), div_id="model3d")


#: the interactive charts standing for an observed point's PNG figure (by the figure's kind)
OBSERVATION_CHARTS = {
    "bands": ("history", "bands"),
    "psd": ("psd",),
    "integrated": ("integrated",),
}


def interactive_charts(result: Analysis) -> dict[str, list[str]]:
    """Each observed point's interactive charts as HTML fragments, by the PNG they stand for.

    ``{s}-bands.png`` (history and bands) -> the history and band charts; ``{s}-psd.png`` ->
    the PSD; ``{s}-integrated.png`` -> the 10-s integrated acceleration.  Element ids are
    ``chart-N``, unique in the page.

    Parameters
    ----------
    result : Analysis
    """
    from microg.report.html import chart_fragment

    out: dict[str, list[str]] = {}
    stems = figure_names(list(result.observations))
    n = 0
    for name, ob in result.observations.items():
        for png, kinds in OBSERVATION_CHARTS.items():
            frags = []
            for kind in kinds:
                n += 1
                frags.append(chart_fragment(ob.plot_interactive(kind), div_id=f"chart-{n}"))
            out[f"{stems[name]}-{png}.png"] = frags
    return out


@lru_cache(maxsize=1)
def _analysis_template() -> Any:
    """The compiled ``analyze.html`` template (compiling it takes ~0.15 s: once a process)."""
    from microg.report.html import environment

    return environment().get_template("analyze.html")


def render_analysis(
    result: Analysis,
    figs: dict[str, bytes],
    summary: dict[str, Any] | None = None,
    *,
    static: bool = False,
) -> str:
    """Self-contained HTML of the analysis, figures embedded as data URIs.

    Parameters
    ----------
    result : Analysis
    figs : dict of str to bytes
        PNG bytes by file name (:func:`figures`).
    summary : dict, optional
        ``result.to_dict()``, if the caller has it already.
    static : bool
        PNG figures only: no interactive 3-D view or chart, no plotly.js.  Otherwise each
        figure with an interactive chart (:func:`interactive_charts`) is shown as the chart,
        its PNG left to the run directory.
    """
    from microg import __version__
    from microg.report.html import plotly_js, png_data_uri

    data = to_jsonable(result.to_dict() if summary is None else summary)
    charts = {} if static else interactive_charts(result)
    uris = {k: png_data_uri(v) for k, v in figs.items() if k not in charts}
    stems = figure_names(list(result.observations))
    obs = []
    for name in result.observations:
        s = stems[name]
        keys = [f"{s}-{k}.png" for k in ("bands", "psd", "integrated", "isolated")]
        obs.append(
            {
                "name": name,
                "data": data["observations"][name],
                "figs": [
                    {"file": k, "png": uris.get(k), "charts": charts.get(k)}
                    for k in keys
                    if k in figs
                ],
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
            model3d=None if static else interactive_model(result),
            plotlyjs=None if static else plotly_js(),
        )
    )
