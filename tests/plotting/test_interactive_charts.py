"""Interactive charts (microg.plotting.interactive): the numbers drawn are the results' numbers.

References: each chart's data are checked against the result fields it draws, converted by
the unit definitions (1 g = 9.80665 m/s^2, micro-g = 1e-6 g, micro-g s = 1e-6 g s), not
against the chart code's own conversion; the envelope against a brute-force min/max.  float32
carries 24 bits: a relative tolerance of 1e-6 is 8 ulps (2^-23 = 1.2e-7), and nothing else
rounds.
"""

from __future__ import annotations

import numpy as np
import pytest

import microg
from microg.environment.intervals import interval_products
from microg.environment.metrics import assess
from microg.plotting.interactive import common, maps, spectra

G0 = 9.80665
FS = 20.0
N = 12000  # 600 s at 20 Hz: above the chart's 4,000-point limit, so drawn through an envelope


def _b(trace_values) -> np.ndarray:
    return np.asarray(trace_values, float)


@pytest.fixture(scope="module")
def record():
    t = np.arange(N) / FS
    rng = np.random.default_rng(3)
    acc = G0 * np.vstack(
        [
            20e-6 * np.sqrt(2) * np.sin(2 * np.pi * 2.0 * t),
            3e-6 + 1e-7 * rng.standard_normal(N),
            2e-6 * np.sqrt(2) * np.sin(2 * np.pi * 0.5 * t),
        ]
    )
    acc[0, 7777] = G0 * 5e-4  # one spike: the envelope must keep it
    return t, acc


@pytest.fixture(scope="module")
def assessment(record):
    t, acc = record
    return assess(t, acc, "iss", transient_basis="pims", sample_rate_hz=FS)


def test_bands_chart_draws_the_table_and_marks_unjudged_bands(assessment):
    fig = assessment.plot_interactive("third_octave")
    to = assessment.third_octave
    limit, *axes = fig.data
    for k, tr in enumerate(axes):
        # micro-g: g * 1e6 (the table's g), float32
        np.testing.assert_allclose(_b(tr.y), np.maximum(to.rms_g[k] * 1e6, 1e-12), rtol=1e-6)
        np.testing.assert_allclose(_b(tr.x), to.center_hz, rtol=1e-6)
        hollow = [s == "circle-open" for s in tr.marker.symbol]
        assert hollow == [not r for r in to.resolved]
        assert any(hollow) and not all(hollow)  # this record has both kinds
        assert all(("NOT judged" in s) != r for s, r in zip(tr.text, to.resolved, strict=True))
    # the limit: each band's value from its lower to its upper edge
    x, y = _b(limit.x), _b(limit.y)
    for lo, hi, lim in zip(to.lower_hz, to.upper_hz, to.limit_g, strict=True):
        at = np.flatnonzero(np.isclose(x, lo, rtol=1e-6))
        assert np.any(np.isclose(y[at], lim * 1e6, rtol=1e-6))
        at = np.flatnonzero(np.isclose(x, hi, rtol=1e-6))
        assert np.any(np.isclose(y[at], lim * 1e6, rtol=1e-6))
    assert "band RMS [micro-g]" in fig.layout.yaxis.title.text
    assert f"judged: {int(np.sum(to.resolved))} of {to.center_hz.size} bands" in (
        fig.layout.annotations[0].text
    )


def test_integrated_chart_is_in_micro_g_s(assessment):
    fig = assessment.plot_interactive("integrated")
    integ = assessment.integrated_pims
    assert fig.layout.yaxis.title.text == "integral of acceleration [micro-g s]"
    for k, tr in enumerate(fig.data):
        # m/s -> micro-g s: divide by 9.80665 m/s^2 per g, times 1e6
        np.testing.assert_allclose(_b(tr.y), integ.delta_v[k] / G0 * 1e6, rtol=1e-6)
        assert "micro-g s" in tr.hovertemplate


def test_history_chart_keeps_every_extreme_and_says_it_is_enveloped(record):
    t, acc = record
    from microg.plotting.interactive.histories import history_chart

    fig = history_chart(t, acc)
    assert "min/max envelope" in fig.layout.annotations[0].text
    for k, tr in enumerate(fig.data):
        ug = acc[k] / G0 * 1e6
        y = _b(tr.y)
        assert y.size <= common.MAX_POINTS
        assert np.isclose(y.max(), ug.max(), rtol=1e-6) and np.isclose(y.min(), ug.min(), rtol=1e-6)
    # the spike (500 micro-g at sample 7777) is drawn at its time
    x0, y0 = _b(fig.data[0].x), _b(fig.data[0].y)
    i = int(np.argmax(y0))
    assert np.isclose(x0[i], t[7777], rtol=1e-6) and np.isclose(y0[i], 500.0, rtol=1e-6)


def test_short_lines_are_drawn_whole():
    from microg.plotting.interactive.histories import history_chart

    t = np.arange(100) * 0.1
    fig = history_chart(t, np.ones((1, 100)) * G0, axes=("x",))
    assert not fig.layout.annotations and _b(fig.data[0].y).size == 100
    np.testing.assert_allclose(_b(fig.data[0].y), 1e6, rtol=1e-6)  # 1 g = 1e6 micro-g


def test_log_envelope_keeps_lines_and_bounds_its_size():
    f = np.arange(1, 200_001) * 0.005
    y = 1e-12 + np.zeros_like(f)
    lines = [17, 9_876, 150_001]  # bins of three tones, low, middle and high
    y[lines] = [3e-6, 1e-5, 2e-7]
    x2, y2 = common.log_envelope(f, y, 4000)
    assert y2.size <= 4000
    for i in lines:  # every line kept, at its own frequency
        assert np.any((x2 == f[i]) & (y2 == y[i]))
    assert x2[0] == f[0] and x2[-1] == f[-1] and np.all(np.diff(x2) > 0)
    x3, y3 = common.log_envelope(f[:50], y[:50], 4000)
    assert x3.size == 50


def test_psd_chart_in_g2_per_hz(assessment):
    fig = assessment.plot_interactive("psd")
    spec = assessment.spectrum
    tr = fig.data[0]
    # the 2-Hz line's peak in g^2/Hz: (m/s^2)^2/Hz / 9.80665^2
    want = spec.psd[0, 1:].max() / G0**2
    assert np.isclose(_b(tr.y).max(), want, rtol=1e-6)
    assert fig.layout.yaxis.title.text == "PSD [g^2/Hz]"


def test_interval_charts(record):
    t, acc = record
    iv = interval_products(t, acc, "iss", interval_s=100, sample_rate_hz=FS)
    fig = iv.bands.plot_interactive()
    k = iv.bands.rows.index("rss")
    med = iv.bands.percentile_rms_g[list(iv.bands.percentiles).index(50.0), k] * 1e6
    np.testing.assert_allclose(_b(fig.data[1].y), np.maximum(med, 1e-12), rtol=1e-6)
    fig = iv.stats.plot_interactive()
    np.testing.assert_allclose(_b(fig.data[1].y), iv.stats.max_g[:, 0] * 1e6, rtol=1e-6)
    fig = iv.band_limited.plot_interactive()
    np.testing.assert_allclose(_b(fig.data[-1].y), iv.band_limited.rss_g * 1e6, rtol=1e-6)
    fig = iv.cumulative.plot_interactive()
    # the cumulative RSS ends at the whole record's RMS (its last value), micro-g
    assert np.isclose(_b(fig.data[-1].y)[-1], iv.cumulative.rss_g[-1] * 1e6, rtol=1e-6)
    fig = iv.spectrogram.plot_interactive()
    z = np.asarray(fig.data[0].z, float)
    assert z.size <= spectra.MAX_CELLS


def test_spectrogram_blocks_keep_their_maximum(monkeypatch):
    z = np.arange(35.0).reshape(5, 7)
    out, sf, st = spectra._block_max(z, 6)
    assert out.size <= 6
    # brute force: each block's maximum
    want = [[z[i : i + sf, j : j + st].max() for j in range(0, 7, st)] for i in range(0, 5, sf)]
    np.testing.assert_array_equal(out, want)


@pytest.fixture(scope="module")
def located():
    from microg.location.amap import locate

    return locate("ioc")


def test_locate_map_colours_the_structure_by_the_peak(located):
    fig = located.plot3d()
    amap = located.amap
    lines, samples = fig.data[0], fig.data[1]
    peak_g = amap.total_peak / G0
    pos = amap.positions
    xs, ys, zs = _b(samples.x), _b(samples.y), _b(samples.z)
    # each sample's hover value is its own total peak (g), found by its position
    for x, y, z, v in zip(xs, ys, zs, _b(samples.customdata), strict=True):
        i = int(np.argmin(np.linalg.norm(pos - [x, y, z], axis=1)))
        assert np.isclose(v, peak_g[i], rtol=1e-6)
    # the colour is log10 of the peak, on a bar labelled in g
    np.testing.assert_allclose(
        _b(samples.marker.color), np.log10(_b(samples.customdata)), atol=1e-5
    )
    assert "[g]" in samples.marker.colorbar.title.text
    assert samples.marker.cmin == pytest.approx(np.log10(peak_g.min()))
    # the line trace joins the samples of each line, NaN after each (a sample on no line is a
    # group of its own)
    on_lines = set(np.concatenate([ln.index for ln in amap.lines]).tolist())
    alone = amap.positions.shape[0] - len(on_lines)
    assert np.isnan(_b(lines.x)).sum() == len(amap.lines) + alone
    assert len(_b(lines.line.color)) == len(_b(lines.x))
    best = fig.data[-1]
    assert np.allclose([best.x[0], best.y[0], best.z[0]], located.best.position, rtol=1e-6)


def test_large_maps_are_thinned_and_say_so(located, monkeypatch):
    monkeypatch.setattr(maps, "MAX_MAP_SAMPLES", 40)
    fig = located.plot3d()
    assert "samples drawn" in fig.layout.annotations[0].text
    assert len(fig.data[1].x) <= 40 + 2 * len(located.amap.lines)


def test_quasi_steady_map_in_micro_g():
    from microg.environment.quasisteady import quasi_steady

    r = quasi_steady(microg.load_station("ioc"))
    fig = r.plot3d()
    pk = r.map.peak_magnitude_mps2 / G0 * 1e6
    np.testing.assert_allclose(_b(fig.data[0].customdata), pk, rtol=1e-6)
    within = [s == "circle" for s in fig.data[0].marker.symbol]
    assert within == list(r.map.within)
    assert "[micro-g]" in fig.data[0].marker.colorbar.title.text


def test_every_hover_of_the_analyze_charts_names_its_unit():
    # each drawn trace of an observed point's four charts shows its value with a unit on
    # hover (micro-g, micro-g s, g^2/Hz, Hz, s): the hovertemplate names one
    r = microg.analyze("ioc", observe=["lab"], duration=40.0, dt=0.02, isolation=False)
    ob = r.observations["lab"]
    units = ("micro-g", "g^2/Hz", " Hz", " s")
    for kind in ("history", "bands", "psd", "integrated"):
        seen = 0
        for tr in ob.plot_interactive(kind).data:
            if tr.hoverinfo == "skip" or tr.visible is False:
                continue
            tpl = tr.hovertemplate or ""
            assert any(u in tpl for u in units), (kind, tr.name, tpl)
            seen += 1
        assert seen >= 1, kind  # every chart has a hover
