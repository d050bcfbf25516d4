"""The interactive 3-D view (microg.plotting.interactive) and the notebook tables.

References: the named points' translation maps give each point's modal displacement
independently of the sample machinery (``PointMap.translation @ phi``); the deformed shape is
the definition ``position + 0.1 size u / max|u|``; the force cones and observed markers are
compared with the analysis's own options (``Disturbance.unit_direction``, the points'
positions); the frame titles with ``Modes.effective_mass_fraction``.
"""

from __future__ import annotations

import numpy as np
import pytest

import microg
from microg.dynamics.modes import solve_modes
from microg.models.toml import load_station
from microg.plotting.interactive import model as interactive
from microg.structure.ritz import build_ritz


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


@pytest.fixture(scope="module")
def two_force_analysis():
    # two push-offs in directions off the axes (the default IOC model is planar in x-z), at
    # two points; isolation off: only the view is under test
    return microg.analyze(
        "ioc",
        force=["crew-pushoff", "crew-pushoff"],
        at=["crew", "lab"],
        direction=["1 0 1", "0 0 -1"],
        observe=["lab", "keel-tip"],
        duration="20 s",
        isolation=False,
    )


def _trace(fig, name):
    found = [t for t in fig.data if t.name == name]
    assert len(found) == 1, [t.name for t in fig.data]
    return found[0]


def test_force_cones_point_along_each_disturbance_at_its_point(two_force_analysis):
    r = two_force_analysis
    pts = r.modes.structure.points
    cone = _trace(r.plot3d(), "force direction")
    assert cone.anchor == "tail"  # the cone starts at the force point and points away
    base = np.column_stack([cone.x, cone.y, cone.z]).astype(float)
    vec = np.column_stack([cone.u, cone.v, cone.w]).astype(float)
    dist = r.options.disturbances
    assert len(dist) == 2 and base.shape == vec.shape == (2, 3)
    for i, d in enumerate(dist):
        # reference: the analysis's own option and the point's position; exact copies of
        # float64 values (plotly keeps them), so only the sqrt(2) normalisation rounds (1e-15)
        np.testing.assert_allclose(base[i], pts[d.point].position, rtol=0, atol=1e-12)
        np.testing.assert_allclose(vec[i], d.unit_direction, rtol=0, atol=1e-15)
    # the directions asked, normalised: (1, 0, 1)/sqrt(2) at crew, -z at lab
    np.testing.assert_allclose(vec[0], np.array([1.0, 0.0, 1.0]) / np.sqrt(2), atol=1e-15)
    np.testing.assert_allclose(vec[1], [0.0, 0.0, -1.0], atol=0)


def test_observed_points_are_one_trace_at_their_positions(two_force_analysis):
    r = two_force_analysis
    pts = r.modes.structure.points
    obs = _trace(r.plot3d(), "observed points")
    names = list(r.observations)
    assert list(obs.text) == names == ["lab", "keel-tip"]
    xyz = np.column_stack([obs.x, obs.y, obs.z]).astype(float)
    want = np.array([pts[n].position for n in names])
    # the positions themselves, copied exactly; the shape (2, 3) says no other named point is
    # in it (the named-points trace holds all five)
    np.testing.assert_array_equal(xyz, want)
    assert len(_trace(r.plot3d(), "named points (force red, observed blue)").x) == len(pts) > 2


def test_frame_titles_list_the_effective_mass_fractions_above_one_percent(modes):
    # gravity gradient makes the pitch rotation a libration mode: an elastic mode (framed) that
    # carries the whole ry effective mass (fraction 1 of the station's inertia), the other
    # elastic modes none (free-free: exactly 0)
    gg = solve_modes(build_ritz(load_station("ioc"), "xz", 3, gravity_gradient=True))
    for m in (gg, modes):
        frac = m.effective_mass_fraction
        fig = m.plot3d()
        elastic = np.flatnonzero(~m.rigid & (m.omega > 0))
        assert len(fig.frames) == min(elastic.size, interactive.MAX_FRAMES)
        for f, j in zip(fig.frames, elastic, strict=False):
            title = f.layout.title.text
            assert title.startswith(f"mode {j + 1}: {m.freq_hz[j]:.4g} Hz, ")
            # reference: Modes.effective_mass_fraction; a direction is listed iff its fraction
            # exceeds 1 % (the threshold of the title), with its percentage to 3 digits
            shown = {d: v[j] for d, v in frac.items() if v[j] > 0.01}
            for d, v in frac.items():
                assert (f" {d} {100 * v[j]:.3g}%" in title) == (d in shown), (title, d, v[j])
            assert ("below 1% in every direction" in title) == (not shown)
    lib = int(np.flatnonzero(~gg.rigid & (gg.omega > 0))[0])
    assert gg.effective_mass_fraction["ry"][lib] == pytest.approx(1.0, rel=1e-9)
    assert gg.plot3d().frames[0].layout.title.text.endswith("effective mass ry 100%")


def test_frame_titles_list_every_participating_direction(modes):
    # several directions above 1 % and one below: effective masses set by hand (a Modes whose
    # elastic modes participate, as a constrained or imported model's do)
    from dataclasses import replace

    j = int(np.flatnonzero(~modes.rigid & (modes.omega > 0))[0])
    st = modes.structure
    total = {d: float(np.asarray(r) @ (st.mass @ np.asarray(r))) for d, r in st.rigid_body.items()}
    eff = {d: np.zeros(modes.n_modes) for d in modes.effective_mass}
    want = {"x": 0.35, "z": 0.02, "ry": 0.005}
    for d, share in want.items():
        if d in eff and total.get(d, 0) > 0:
            eff[d][j] = share * total[d]
    m = replace(modes, effective_mass=eff)
    frac = m.effective_mass_fraction
    assert frac["x"][j] == pytest.approx(0.35, rel=1e-12)
    title = m.plot3d().frames[0].layout.title.text
    assert title.endswith(", effective mass x 35%, z 2%")  # ry 0.5 % is under the threshold
