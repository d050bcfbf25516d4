"""Active-isolation figures: transmissibility against the target, noise floor, time check, loops.

They draw the numbers of an :class:`~microg.isolation.active.result.ActiveIsolation`; they
compute nothing of their own.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from microg.plotting.common import figure_axes, figure_grid, png_bytes
from microg.units import G0

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from microg.isolation.active.result import ActiveIsolation

__all__ = ["plot_active", "active_figures", "KINDS"]

#: the figures of :func:`plot_active`
KINDS = ("transmissibility", "noise", "time", "margins", "bands")
_AXES = ("x", "y", "z")


def _axes(ax: Any, width: float = 7.5, height: float = 4.4) -> tuple[Figure, Any]:
    return figure_axes(ax, width, height)


def _transmissibility(res: ActiveIsolation, ax: Any) -> Figure:
    fig, ax = _axes(ax)
    f = res.freq_hz
    t = res.transmissibility_axis()
    for i, a in enumerate(_AXES):
        ax.loglog(f, t[i], lw=1.4, label=f"active, {a}")
    ax.loglog(
        f, np.abs(res.passive[0, 0]), "k--", lw=0.9, label="umbilicals only (controller off), x"
    )
    lim = res.target.limit(f)
    fin = np.isfinite(lim)
    if fin.sum() > 1:
        ax.loglog(f[fin], lim[fin], color="crimson", lw=1.6, label=f"target: {res.target.name}")
    for lo, hi, lev in zip(res.target.lo_hz, res.target.hi_hz, res.target.level, strict=True):
        if lo == hi or fin.sum() <= 1:
            ax.plot([lo], [lev], "v", color="crimson", ms=8)
    ax.axhline(1.0, color="0.5", lw=0.6)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("|a_platform / a_station|")
    ax.set_title(
        f"{res.plant.name}: transmissibility, {res.controller.kind} controller"
        f" ({'meets' if res.meets_target else 'misses'} the target)"
    )
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    return fig


def _noise(res: ActiveIsolation, ax: Any) -> Figure:
    fig, ax = _axes(ax)
    c = res.noise_center_hz
    for i, a in enumerate(_AXES):
        ax.loglog(c, res.noise_band_rms_g[i], "o-", ms=3, lw=1.0, label=f"sensor noise floor, {a}")
    ax.step(c, res.noise_limit_g, where="mid", color="crimson", lw=1.4, label="requirement")
    tm = res.time
    if tm is not None:
        to = tm.isolated.third_octave
        ax.loglog(
            to.center_hz,
            to.rms_g.max(axis=0),
            "s-",
            ms=3,
            color="k",
            lw=1.0,
            label="isolated platform (time domain), worst axis",
        )
    ax.set_xlabel("1/3-octave band centre (Hz)")
    ax.set_ylabel("band RMS (g)")
    ax.set_title("noise floor the sensors put on the platform")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def _time(res: ActiveIsolation, ax: Any) -> Figure:
    tm = res.time
    if ax is not None or tm is None:
        fig, ax = _axes(ax)
        if tm is None:
            ax.text(0.5, 0.5, "no station response given", ha="center", transform=ax.transAxes)
            return fig
        axs = [ax]
    else:
        fig, grid = figure_grid(None, 3, 1, width_in=7.5, height_in=7.0, sharex=True)
        axs = list(grid[:, 0])
    t = tm.timepts
    j = int(np.argmax(np.max(np.abs(tm.base_accel), axis=1)))
    axs[0].plot(
        t,
        tm.base_accel[j] / G0 * 1e6,
        lw=0.8,
        color="0.5",
        label=f"station at {tm.point}, {_AXES[j]}",
    )
    axs[0].plot(t, tm.platform_accel[j] / G0 * 1e6, lw=1.0, label=f"platform, {_AXES[j]}")
    axs[0].set_ylabel("acceleration (micro-g)")
    axs[0].legend(fontsize=8)
    axs[0].set_title("the station's response through the closed loop")
    if len(axs) > 1:
        stroke_lim, force_lim = res.plant.limits()
        for i, a in enumerate(_AXES):
            axs[1].plot(t, tm.stroke[i] * 1e3, lw=0.9, label=a)
            axs[2].plot(t, tm.force[i], lw=0.9, label=a)
        for k, (lim, scale) in enumerate(((stroke_lim[0], 1e3), (force_lim[0], 1.0))):
            for sgn in (1, -1):
                axs[k + 1].axhline(sgn * lim * scale, color="crimson", lw=1.0)
        axs[1].set_ylabel("stroke (mm)")
        axs[2].set_ylabel("actuator force (N)")
        axs[1].legend(fontsize=8)
    axs[-1].set_xlabel("time (s)")
    return fig


def _margins(res: ActiveIsolation, ax: Any) -> Figure:
    fig, ax = _axes(ax, 6.0, 6.0)
    names = ("x", "y", "z", "rx", "ry", "rz")
    for i, n in enumerate(names):
        lr = res.loop_response[i]
        if np.any(lr):
            ax.plot(lr.real, lr.imag, lw=1.0, label=f"loop {n}")
    th = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(th), np.sin(th), color="0.6", lw=0.6)
    ax.plot([-1], [0], "+", color="crimson", ms=12, mew=2)
    ax.set_xlim(-3, 3)
    ax.set_ylim(-3, 3)
    ax.set_aspect("equal")
    ax.set_xlabel("Re L")
    ax.set_ylabel("Im L")
    cont = [m for m in res.margins if m.model == "continuous"]
    if cont:
        pm = min(m.phase_margin_deg for m in cont)
        gm = min(m.gain_margin_factor for m in cont)
        ax.set_title(
            f"Nyquist, each loop broken (others closed): PM >= {pm:.3g} deg, GM >= {20 * np.log10(gm):.3g} dB"  # noqa: E501
        )
    else:
        ax.set_title("controller off: no loop")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def _bands(res: ActiveIsolation, ax: Any) -> Figure:
    fig, ax = _axes(ax)
    tm = res.time
    if tm is None:
        ax.text(0.5, 0.5, "no station response given", ha="center", transform=ax.transAxes)
        return fig
    to = tm.isolated.third_octave
    bo = tm.base.third_octave
    ax.loglog(
        bo.center_hz, bo.rms_g.max(axis=0), "o-", ms=3, color="0.5", label=f"station at {tm.point}"
    )
    ax.loglog(to.center_hz, to.rms_g.max(axis=0), "s-", ms=3, label="platform, time domain")
    ax.loglog(
        to.center_hz,
        tm.spectral_rms_g.max(axis=0)[: to.center_hz.size],
        "x",
        ms=5,
        label="platform, frequency domain",
    )
    ax.step(to.center_hz, to.limit_g, where="mid", color="crimson", lw=1.4, label="requirement")
    ax.set_xlabel("1/3-octave band centre (Hz)")
    ax.set_ylabel("band RMS, worst axis (g)")
    ax.set_title(
        f"band verdict: {'complies' if tm.complies else 'does not comply'} (noise included)"
    )
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_active(res: ActiveIsolation, kind: str = "transmissibility", ax: Any = None) -> Figure:
    """One figure of ``res``: one of :data:`KINDS`; on ``ax`` when given."""
    from microg.errors import InputError

    draw = {
        "transmissibility": _transmissibility,
        "noise": _noise,
        "time": _time,
        "margins": _margins,
        "bands": _bands,
    }.get(kind)
    if draw is None:
        raise InputError(f"unknown plot {kind!r}", where="kind", fix=f"use {', '.join(KINDS)}")
    return draw(res, ax)


def active_figures(res: ActiveIsolation) -> dict[str, bytes]:
    """Every figure of ``res`` as PNG bytes, file name -> bytes."""
    kinds = KINDS if res.time is not None else ("transmissibility", "noise", "margins")
    return {f"{k}.png": png_bytes(plot_active(res, k)) for k in kinds}
