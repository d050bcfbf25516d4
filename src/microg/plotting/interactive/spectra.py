"""Interactive charts against frequency: PSD, cumulative RMS, spectrogram.

PSDs in g^2/Hz (log-log, the 0-Hz bin left out, 12 decades below the top shown as the static
figure does), cumulative RMS in micro-g, the spectrogram as log10 PSD (g^2/Hz) over time (s)
and frequency (Hz).  Spectra longer than
:data:`~microg.plotting.interactive.common.MAX_POINTS` bins are drawn through the min/max of
log-spaced slices (every spectral line's peak kept) and the chart says so; a spectrogram above
:data:`MAX_CELLS` cells keeps each block's largest value.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from microg.plotting.interactive.common import (
    AXIS_COLOURS,
    chart,
    envelope_note,
    f32,
    log_line,
)
from microg.units import G0

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from microg.environment.intervals import CumulativeRMS, Spectrogram
    from microg.environment.spectrum import Spectrum

__all__ = ["MAX_CELLS", "cumulative_chart", "psd_chart", "spectrogram_chart"]

#: largest number of cells of a spectrogram heat map; above it, blocks keep their maximum
MAX_CELLS = 20_000


def psd_chart(
    spectrum: Spectrum,
    *,
    axes: Sequence[str] = ("x", "y", "z"),
    rows: Sequence[int] | None = None,
    title: str = "",
) -> go.Figure:
    """PSD per axis in g^2/Hz against frequency (log-log), hover with the units.

    Parameters
    ----------
    spectrum : Spectrum
        One-sided PSD, (m/s^2)^2/Hz per axis (shown / G0^2).
    axes : names of the rows of ``spectrum.psd``
    rows : the rows drawn (default: all)
    title : chart title (default: the method)
    """
    import plotly.graph_objects as go

    f = np.asarray(spectrum.freq_hz, float)[1:]
    psd = np.atleast_2d(np.asarray(spectrum.psd, float))[:, 1:] / G0**2
    top = max(float(np.max(psd, initial=0.0)), 1e-300)
    floor = top * 1e-12  # 12 decades: below that is rounding noise
    traces, cut = [], False
    for i in range(len(axes)) if rows is None else rows:
        name = axes[i]
        x, y, c = log_line(f, np.maximum(psd[i], floor))
        cut |= c
        traces.append(
            go.Scatter(
                x=x,
                y=y,
                mode="lines",
                name=name,
                line={"width": 1, "color": AXIS_COLOURS.get(name)},
                hovertemplate=f"{name}: %{{y:.4g}} g^2/Hz at %{{x:.5g}} Hz<extra></extra>",
            )
        )
    return chart(
        traces,
        title=title or f"PSD ({spectrum.method}, resolution {spectrum.df_hz:.3g} Hz)",
        x_title="frequency [Hz]",
        y_title="PSD [g^2/Hz]",
        x_log=True,
        y_log=True,
        y_range=(np.log10(floor), np.log10(top * 10)),
        notes=envelope_note(cut, "spectra"),
    )


def cumulative_chart(res: CumulativeRMS, *, title: str = "") -> go.Figure:
    """Cumulative RMS per axis and their RSS against frequency (log x), micro-g.

    Parameters
    ----------
    res : CumulativeRMS
        RMS (g) of the content up to each frequency (Hz).
    title : chart title
    """
    import plotly.graph_objects as go

    f = np.asarray(res.freq_hz, float)
    keep = f > 0
    rows = [(n, np.asarray(res.rms_g)[i]) for i, n in enumerate(res.axes)]
    traces, cut = [], False
    for name, v in [*rows, ("rss", np.asarray(res.rss_g))]:
        x, y, c = log_line(f[keep], np.asarray(v, float)[keep] * 1e6)
        cut |= c
        traces.append(
            go.Scatter(
                x=x,
                y=y,
                mode="lines",
                name="RSS" if name == "rss" else name,
                line={"width": 1.6 if name == "rss" else 1.0, "color": AXIS_COLOURS.get(name)},
                hovertemplate=f"{name}: %{{y:.4g}} micro-g up to %{{x:.5g}} Hz<extra></extra>",
            )
        )
    return chart(
        traces,
        title=title or "Cumulative RMS against frequency",
        x_title="frequency [Hz]",
        y_title="cumulative RMS [micro-g]",
        x_log=True,
        notes=envelope_note(cut, "curves"),
    )


def _block_max(z: np.ndarray, limit: int) -> tuple[np.ndarray, int, int]:
    """``z`` (nf, nt) reduced to at most ``limit`` cells by the maximum of blocks; the steps."""
    nf, nt = z.shape
    if nf * nt <= limit:
        return z, 1, 1
    step = int(np.ceil(np.sqrt(nf * nt / limit)))
    sf, st = min(step, nf), min(step, nt)
    while (-(-nf // sf)) * (-(-nt // st)) > limit:
        sf, st = min(sf + 1, nf), min(st + 1, nt)
    pf, pt = (-nf) % sf, (-nt) % st
    zz = np.pad(z, ((0, pf), (0, pt)), constant_values=-np.inf)
    out = zz.reshape(zz.shape[0] // sf, sf, zz.shape[1] // st, st).max(axis=(1, 3))
    return out, sf, st


def spectrogram_chart(res: Spectrogram, *, axis: str | None = None, title: str = "") -> go.Figure:
    """log10 PSD (g^2/Hz) over time (s) and frequency (Hz) of one axis, a heat map.

    Parameters
    ----------
    res : Spectrogram
        PSD per axis, frequency and segment (g^2/Hz).
    axis : the axis shown (default: the one with the most power)
    title : chart title
    """
    import plotly.graph_objects as go

    from microg.errors import InputError

    if axis is None:
        i = int(np.argmax(res.psd_g2_per_hz.sum(axis=(1, 2))))
    elif axis in res.axes:
        i = list(res.axes).index(axis)
    else:
        raise InputError(f"unknown axis {axis!r}", where="axis", fix=f"use one of {res.axes}")
    z = np.asarray(res.psd_g2_per_hz[i], float)
    top = float(np.max(z, initial=0.0))
    lz = np.log10(np.maximum(z, max(top, 1e-300) * 1e-12))
    lz, sf, st = _block_max(lz, MAX_CELLS)
    f = np.asarray(res.freq_hz, float)[::sf][: lz.shape[0]]
    t = np.asarray(res.time_s, float)[::st][: lz.shape[1]]
    notes = []
    if sf > 1 or st > 1:
        notes.append(
            f"above {MAX_CELLS:,} cells: each cell is the largest of {sf} frequencies x {st} "
            "segments"
        )
    trace = go.Heatmap(
        x=f32(t),
        y=f32(f),
        z=lz.astype(np.float32),
        colorscale="Viridis",
        colorbar={"title": {"text": "log10 PSD<br>[g^2/Hz]"}},
        hovertemplate="t %{x:.4g} s, %{y:.4g} Hz<br>log10 PSD %{z:.3g} (g^2/Hz)<extra></extra>",
    )
    return chart(
        [trace],
        title=title or f"Spectrogram, {res.axes[i]}-axis (Hann, {res.segment_s:.3g}-s segments)",
        x_title="time [s]",
        y_title="frequency [Hz]",
        notes=notes,
    )
