"""Figures and HTML of ``microg analyze`` (reads an :class:`~microg.analysis.Analysis`)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from microg import __version__  # noqa: E402
from microg._io import to_jsonable  # noqa: E402
from microg.analysis import Analysis  # noqa: E402
from microg.plotting.environment import (  # noqa: E402
    plot_integrated_acceleration,
    plot_psd,
    plot_third_octave,
    plot_time_history,  # noqa: E402
)
from microg.plotting.seed import png_bytes, png_data_uri  # noqa: E402
from microg.report.html import environment  # noqa: E402
from microg.units import G0  # noqa: E402

__all__ = ["figures", "render_analysis"]


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)


def _modes_figure(result: Analysis) -> Figure:
    fig = Figure(figsize=(7.5, 3.8), layout="constrained")
    ax = fig.add_subplot()
    m = result.modes
    el = ~m.rigid
    idx = np.arange(m.n_modes)
    ax.semilogy(idx[el], m.freq_hz[el], "o", ms=4, label="elastic")
    ax.axhline(result.options.max_freq_hz, color="k", lw=0.8, ls="--", label="--max-freq")
    ax.set_xlabel("mode index")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title(f"Modes of {result.model} ({m.n_rigid} rigid-body modes at 0 Hz)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return fig


def _isolation_figure(result: Analysis, name: str) -> Figure:
    adv = result.isolation[name]
    package_accel = adv.package_accel
    assert package_accel is not None  # the caller draws this figure only for isolated points
    r = result.responses[name]
    axis = int(np.argmax(np.max(np.abs(r.acceleration), axis=1)))
    fig = Figure(figsize=(7.5, 4.0), layout="constrained")
    ax = fig.add_subplot()
    ax.plot(r.timepts, r.acceleration[axis] / G0 * 1e6, lw=0.8, label="mount (station)")
    ax.plot(r.timepts, package_accel[axis] / G0 * 1e6, lw=0.9, label="isolated package")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"acceleration, {'xyz'[axis]} [micro-g]")
    ax.set_title(f"What the package feels at {name} on the advised mount")
    ax.grid(True, alpha=0.3)
    ax.legend()
    return fig


def figures(result: Analysis) -> dict[str, bytes]:
    """PNG bytes of every figure, keyed by file name."""
    out = {"modes.png": png_bytes(_modes_figure(result))}
    axes = ("x", "y", "z")
    for name, a in result.assessments.items():
        r = result.responses[name]
        s = _safe(name)
        out[f"{s}-time.png"] = png_bytes(
            plot_time_history(r.timepts, r.acceleration, axes=axes, title=f"Acceleration at {name}")
        )
        out[f"{s}-psd.png"] = png_bytes(plot_psd(a.spectrum, axes=axes, title=f"PSD at {name}"))
        out[f"{s}-third-octave.png"] = png_bytes(
            plot_third_octave(a, title=f"1/3-octave band RMS at {name} vs {a.requirement}")
        )
        adv = result.isolation[name]
        if adv.package_accel is not None:
            out[f"{s}-isolated.png"] = png_bytes(_isolation_figure(result, name))
        out[f"{s}-integrated.png"] = png_bytes(
            plot_integrated_acceleration(
                r.timepts,
                r.acceleration,
                axes=axes,
                title=f"10-s integrated acceleration at {name}",
            )
        )
    return out


def render_analysis(result: Analysis, figs: dict[str, bytes]) -> str:
    """Self-contained HTML of the analysis, figures embedded as data URIs."""
    data = to_jsonable(result.to_dict())
    uris = {k: png_data_uri(v) for k, v in figs.items()}
    obs = []
    for name in result.assessments:
        s = _safe(name)
        keys = ["time", "psd", "third-octave", "integrated", "isolated"]
        obs.append(
            {
                "name": name,
                "data": data["observations"][name],
                "figs": [uris[f"{s}-{k}.png"] for k in keys if f"{s}-{k}.png" in uris],
            }
        )
    return (
        environment()
        .get_template("analyze.html")
        .render(version=__version__, d=data, obs=obs, modes_fig=uris["modes.png"])
    )
