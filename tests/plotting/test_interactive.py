"""The interactive 3-D view (microg.plotting.interactive) and the notebook tables.

References: the named points' translation maps give each point's modal displacement
independently of the sample machinery (``PointMap.translation @ phi``); the deformed shape is
the definition ``position + 0.1 size u / max|u|``.
"""

from __future__ import annotations

import numpy as np
import pytest

import microg
from microg.plotting.interactive import model as interactive


@pytest.fixture(scope="module")
def modes():
    return microg.solve_modes(microg.load_station("ioc"))


def test_one_frame_per_elastic_mode_and_a_slider_step_each(modes):
    fig = modes.plot3d(force_points={"crew": np.array([1.0, 0.0, 0.0])}, observed=["lab"])
    elastic = np.flatnonzero(~modes.rigid & (modes.omega > 0))
    n = min(elastic.size, interactive.MAX_FRAMES)
    assert len(fig.frames) == n
    steps = fig.layout.sliders[0].steps
    assert [s.args[0][0] for s in steps] == [f.name for f in fig.frames]
    assert fig.frames[0].name == f"mode {elastic[0] + 1}"
    j = elastic[2]
    title = fig.frames[2].layout.title.text
    assert title.startswith(f"mode {j + 1}: {modes.freq_hz[j]:.4g} Hz")
    assert f"modal mass {modes.modal_mass[j]:.3g} kg" in title
    # only the deformed trace (1) changes from frame to frame
    assert all(list(f.traces) == [1] for f in fig.frames)


def test_frames_show_the_mode_shape_at_the_named_points(modes):
    # the named points are drawn as markers; their deformed position is checked here from the
    # points' own translation maps, against the samples the lines are drawn from
    st = modes.structure
    fig = modes.plot3d()
    elastic = np.flatnonzero(~modes.rigid & (modes.omega > 0))
    pos, u = interactive.sample_displacements(st, modes.phi[:, elastic[:1]])
    size = float(np.max(np.ptp(pos, axis=0)))
    peak = float(np.max(np.abs(u[:, :, 0])))
    shape = pos + 0.1 * size * u[:, :, 0] / peak
    xs = np.asarray(fig.frames[0].data[0].x, float)
    xs = xs[np.isfinite(xs)]  # NaN: the gaps between components
    # every drawn vertex is a deformed sample (the lines list each sample once per component),
    # to float32's rounding (6e-8 relative; 1e-6 of the model's size)
    assert np.all(np.min(np.abs(xs[:, None] - shape[None, :, 0]), axis=1) < 1e-6 * size)
    # the samples include each named point's own motion (an independent map)
    for name in ("lab", "crew"):
        p = st.points[name]
        d = p.translation @ modes.phi[:, elastic[0]]
        target = p.position + 0.1 * size * d / peak
        assert np.min(np.linalg.norm(shape - target, axis=1)) < 1e-6 * size


def test_large_models_are_decimated_and_say_so(modes, monkeypatch):
    monkeypatch.setattr(interactive, "MAX_SAMPLES", 20)
    monkeypatch.setattr(interactive, "MAX_FRAMES", 3)
    fig = modes.plot3d()
    note = fig.layout.annotations[0].text
    assert "lines show every" in note and "the lowest 3 of" in note
    assert len(fig.frames) == 3


def test_notebook_tables_follow_the_results(modes):
    html = modes._repr_html_()
    assert html.count("<tr>") == min(modes.n_modes, 60) + 1
    assert f"<td>{modes.freq_hz[6]:.4g}</td><td>elastic</td>" in html
    r = microg.analyze("ioc", observe=["lab", "keel-tip"], duration="60 s")
    table = r._repr_html_()
    for name, o in r.observations.items():
        row = table.split(f"<td>{name}</td>", 1)[1].split("</tr>", 1)[0]
        assert f"<td>{o.peak_accel_g:.3g}</td>" in row
        # the verdict word follows the verdict field
        assert ("<td>complies</td>" in row) == o.complies
        assert ("<td>fails</td>" in row) == (o.verdict == "fails")
    fig = r.plot3d()
    assert {t.name for t in fig.data} >= {"model (undeformed)", "mode shape", "force direction"}
