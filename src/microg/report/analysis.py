"""Figures and HTML of ``microg analyze`` (reads an :class:`~microg.analysis.Analysis`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from microg._io import to_jsonable

if TYPE_CHECKING:
    from microg.analysis import Analysis

__all__ = ["figure_names", "figures", "render_analysis"]


def figure_names(names: list[str]) -> dict[str, str]:
    """Unique, stable file-name stems for point names (``a/b`` and ``a_b`` never collide)."""
    from microg._io import safe_filenames

    return dict(safe_filenames(names))


def figures(result: Analysis) -> dict[str, bytes]:
    """PNG bytes of every figure of the report, keyed by file name."""
    from microg.plotting.analysis import (
        force_figure,
        isolation_figure,
        model_figure,
        modes_figure,
        observation_figure,
    )
    from microg.plotting.common import png_bytes
    from microg.plotting.environment import plot_integrated_acceleration, plot_psd

    opts = result.options
    force_pts = {d.point: d.unit_direction for d in opts.disturbances}
    if opts.sources is not None:
        for s in opts.sources.sources:
            force_pts.setdefault(s.at, s.direction)
    observed = list(result.observations) or list(opts.observe)
    out = {
        "model.png": png_bytes(model_figure(result.structure, result.modes, force_pts, observed)),
        "modes.png": png_bytes(modes_figure(result)),
    }
    if opts.disturbances:
        out["forces.png"] = png_bytes(force_figure(list(opts.disturbances), opts.duration_s))
    stems = figure_names(list(result.observations))
    for name, ob in result.observations.items():
        s = stems[name]
        r = ob.response
        from microg.plotting.analysis import live_axes

        live = live_axes(r.acceleration)
        axes = tuple("xyz"[i] for i in live) or ("x",)
        rows = live or [0]
        out[f"{s}-bands.png"] = png_bytes(observation_figure(ob))
        spec = ob.assessment.spectrum
        from microg.environment.metrics import Spectrum

        out[f"{s}-psd.png"] = png_bytes(
            plot_psd(
                Spectrum(spec.freq_hz, spec.psd[rows], spec.df_hz, spec.nyquist_hz, spec.method),
                axes=axes,
                title=f"PSD at {name}",
            )
        )
        out[f"{s}-integrated.png"] = png_bytes(
            plot_integrated_acceleration(
                r.timepts,
                r.acceleration[rows],
                axes=axes,
                title=f"10-s integrated acceleration at {name}",
            )
        )
        if ob.isolation.package_accel is not None:
            out[f"{s}-isolated.png"] = png_bytes(isolation_figure(ob))
    fd = result.frequency_domain
    if fd is not None:
        vstems = figure_names(list(fd.points))
        for name in fd.points:
            s = vstems[name]
            out[f"{s}-vibratory.png"] = png_bytes(fd.plot(name, kind="bands"))
            out[f"{s}-sources.png"] = png_bytes(fd.plot(name, kind="contributions"))
    return out


def render_analysis(result: Analysis, figs: dict[str, bytes]) -> str:
    """Self-contained HTML of the analysis, figures embedded as data URIs."""
    from microg import __version__
    from microg.plotting.common import png_data_uri
    from microg.report.html import environment

    data = to_jsonable(result.to_dict())
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
    return (
        environment()
        .get_template("analyze.html")
        .render(
            version=__version__,
            d=data,
            obs=obs,
            vib=vib,
            model_fig=uris["model.png"],
            forces_fig=uris.get("forces.png"),
            modes_fig=uris["modes.png"],
        )
    )
