"""The main job (microg.analysis) end to end, against a direct integration of M q'' + K q = b f."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microg._vectors import AXES
from microg.analysis import AnalysisOptions, Disturbance, run_analysis
from microg.dynamics.forces import crew_pushoff
from microg.models.toml import load_station
from microg.structure.ritz import build_ritz


@pytest.fixture(scope="module")
def station():
    return load_station("ioc")


def _opts(**kw) -> AnalysisOptions:
    base = dict(
        disturbances=[Disturbance(crew_pushoff(), "crew", AXES["x"])],
        observe=["lab", "keel-tip"],
        duration_s=40.0,
        dt_s=0.02,
    )
    base.update(kw)
    return AnalysisOptions(**base)


def test_ritz_response_equals_direct_integration(station) -> None:
    # reference: solve_ivp (DOP853, rtol 1e-11) of the physical equations M q'' + K q = b f(t)
    # of the same (3-D) assumed-modes model, integrated between the force's breakpoints; the modal
    # route keeps every mode (undamped), so both are the same ODE: agreement to 1e-6 of the peak
    # (dt = 2.5 ms: Nyquist 200 Hz above the model's highest mode, 88 Hz, as the job requires)
    res = run_analysis(
        station, _opts(method="ritz", n=2, zeta=0.0, max_freq_hz=1e6, duration_s=20.0, dt_s=0.0025)
    )
    s = build_ritz(station, None, 2, gravity_gradient=False)  # the 3-D assumed-modes model
    f = crew_pushoff()
    b = s.point("crew").translation.T @ AXES["x"]
    minv_k = np.linalg.solve(s.mass, s.stiffness)
    minv_b = np.linalg.solve(s.mass, b)
    n = s.n_dof
    t_out = res.timepts
    edges = np.unique(np.concatenate([f.timepts, [t_out[-1]]]))
    y = np.zeros(2 * n)
    q = np.zeros((n, t_out.size))
    for a, c in zip(edges[:-1], edges[1:], strict=True):
        mid = 0.5 * (a + c)
        f_mid, slope = f.at(mid), (f.at(c - 1e-9) - f.at(a + 1e-9)) / (c - a - 2e-9)

        def rhs(t, y, f_mid=f_mid, slope=slope, mid=mid):
            ft = f_mid + slope * (t - mid)
            return np.concatenate([y[n:], minv_b * ft - minv_k @ y[:n]])

        sel = (t_out > a) & (t_out <= c)
        sol = solve_ivp(rhs, (a, c), y, rtol=1e-11, atol=1e-14, method="DOP853", dense_output=True)
        if sel.any():
            yy = sol.sol(t_out[sel])
            q[:, sel] = (minv_b[:, None] * (f_mid + slope * (t_out[sel] - mid))) - minv_k @ yy[:n]
        y = sol.y[:, -1]
    acc_ref = s.point("lab").translation @ q
    acc = res.responses["lab"].acceleration
    # at a jump instant the reference holds the value before the jump, the kernel the one after
    keep = ~np.isin(t_out, f.timepts)
    err = np.abs(acc - acc_ref)[:, keep]
    assert np.max(err) <= 1e-6 * np.max(np.abs(acc_ref))


def test_linear_in_force(station) -> None:
    # the response is linear: twice the push-off gives twice every acceleration (rounding)
    r1 = run_analysis(station, _opts())
    r2 = run_analysis(
        station,
        _opts(disturbances=[Disturbance(crew_pushoff(f0=2 * 111.20554), "crew", AXES["x"])]),
    )
    a1 = r1.responses["lab"].acceleration
    a2 = r2.responses["lab"].acceleration
    assert np.allclose(a2, 2 * a1 * 111.20554 / crew_pushoff().force.max(), rtol=0, atol=1e-12)


def test_rigid_translation_during_push(station) -> None:
    # with the elastic modes removed, the lab's x acceleration is Newton's: f/m + f d_a d_e/I_yy
    # (rigid translation plus rotation about the centre of mass; the station's own mass
    # properties). 1e-6: the frame elements add the beams' cross-section rotary inertia
    # (1.8e-6 of I_yy) that the rigid-body formula leaves out
    r = run_analysis(station, _opts(max_freq_hz=1e-9))  # rigid-body modes only
    t = r.timepts
    f = crew_pushoff()
    total, cm, inertia = station.mass_properties()
    lever = r.structure.point("crew").position[2] - cm[2]
    arm_lab = r.structure.point("lab").position[2] - cm[2]
    expect = f.at(t) / total + f.at(t) * lever * arm_lab / inertia[1, 1]
    got = r.responses["lab"].acceleration[0]
    assert np.max(np.abs(got - expect)) <= 1e-6 * np.abs(expect).max()


def test_contract_and_compliance_fields(station) -> None:
    r = run_analysis(station, _opts())
    d = r.to_dict()
    assert {"modes", "observations"} <= set(d)
    assert d["modes"]["method"] == "fem" and d["modes"]["modes"][0]["rigid"]
    for name in ("lab", "keel-tip"):
        o = d["observations"][name]
        assert {"peak_accel_g", "rms_accel_g", "third_octave", "complies"} <= set(o)
        assert {"center_hz", "rms_g", "limit_g"} <= set(o["third_octave"])
        assert isinstance(o["complies"], bool)
        # complies is exactly "every band's estimate within its limit, and some band resolved"
        # (an unresolved band above its limit cannot be shown to comply)
        rms = np.array([np.nan if v is None else v for v in o["third_octave"]["rms_g"]], float)
        lim = np.array(o["third_octave"]["limit_g"], float)
        resolved = np.array(o["third_octave"]["resolved"], bool)
        ok = np.isnan(rms) | (rms <= lim)
        assert o["complies"] == bool(np.all(ok) and resolved.any())


# ------------------------------------------------------------------ the public API


@pytest.fixture(scope="module")
def default_result():
    import microg

    return microg.analyze("ioc", observe=["lab", "keel-tip"], duration=40.0, dt=0.02)


def test_api_contract(default_result) -> None:
    # the names of the contract, called as documented
    from matplotlib.figure import Figure

    import microg

    station = microg.load_station("ioc")
    modes = microg.solve_modes(station, method="fem")
    assert modes.n_rigid == 6 and np.all(modes.omega[modes.rigid] == 0.0)
    result = microg.analyze(station, force="crew-pushoff", at="crew", observe=["lab"])
    lab = result.observations["lab"]
    assert lab.peak_accel_g == result.to_dict()["observations"]["lab"]["peak_accel_g"]
    assert isinstance(lab.plot(), Figure) and isinstance(result.plot(), Figure)
    da = lab.to_xarray()
    assert da.dims == ("axis", "time") and da.attrs["units"] == "m/s^2"
    # the defaults are the CLI's: the first crew point, the experiment points, 200 s at 10 ms
    assert result.options.disturbances[0].point == "crew"
    assert result.options.duration_s == 200.0 and result.options.dt_s == 0.01
    assert list(microg.analyze(station, duration=40, dt=0.02).observations) == ["lab"]


def test_peak_is_exact_and_the_modes_sum_to_it(default_result) -> None:
    # the reported peak is the certified exact one: at least the largest sample, at most its
    # bound; the per-mode table at the peak sums to it (rounding of ~30 terms: 1e-9)
    for ob in default_result.observations.values():
        acc = ob.response.acceleration
        sampled = np.linalg.norm(acc, axis=0).max() / 9.80665
        peak = ob.assessment.peak_accel_g
        assert sampled <= peak * (1 + 1e-12)
        assert peak * 9.80665 <= ob.peak.upper_bound_mps2 <= peak * 9.80665 * (1 + 1e-8)
        c = ob.contributions
        assert abs(c.at_peak_g.sum() - peak) <= 1e-9 * peak
        assert np.all(c.own_peak_g >= 0) and c.mode.min() >= 1


def test_peak_between_samples(station) -> None:
    # a jump at 13.000000001 s, off the 0.01-s grid, must give the same peak as the
    # jump on the grid (the sampled peak drops ~1 %); exact peaks agree to 1e-6
    import microg
    from microg.dynamics.forces import piecewise_linear

    def pulse(t13: float):
        tp = np.array([0.0, 1.0, 1.0, t13, t13, t13 + 1.0])
        f = np.array([0.0, 111.2, 0.0, 0.0, -111.2, 0.0])
        return piecewise_linear(tp, f, name="pulse")

    kw = dict(observe=["lab"], duration=40.0, dt=0.01, isolation=False)
    on = microg.analyze(station, force=pulse(13.0), **kw).observations["lab"]
    off = microg.analyze(station, force=pulse(13.000000001), **kw).observations["lab"]
    assert off.peak_accel_g == pytest.approx(on.peak_accel_g, rel=1e-6)


def test_several_forces_superpose(station) -> None:
    # two forces at once = the sum of each alone (linearity), per axis, to rounding
    import microg

    kw = dict(observe=["lab"], duration=40.0, dt=0.02, isolation=False)
    both = microg.analyze(
        station, force=["crew-pushoff", "hand-pushoff-mean"], direction=["x", "z"], **kw
    )
    one = microg.analyze(station, force="crew-pushoff", direction="x", **kw)
    two = microg.analyze(station, force="hand-pushoff-mean", direction="z", **kw)
    a = both.responses["lab"].acceleration
    ref = one.responses["lab"].acceleration + two.responses["lab"].acceleration
    assert np.max(np.abs(a - ref)) <= 1e-12 * np.max(np.abs(ref))


# ----------------------------------------------------- verdicts without warnings


def test_force_that_does_not_end_at_zero_warns(station) -> None:
    # 100 N held for the rest of the record: the warning states the hold and the impulse over
    # the record (100 N x (40 - 1) s + the 50 N s ramp), not just the file's span
    import microg
    from microg.dynamics.forces import piecewise_linear

    f = piecewise_linear(np.array([0.0, 1.0]), np.array([0.0, 100.0]), name="held")
    r = microg.analyze(station, force=f, observe=["lab"], duration=40.0, dt=0.02)
    w = [x for x in r.warnings if "does not end at zero" in x]
    assert len(w) == 1 and "held" in w[0] and f"{50.0 + 100.0 * 39.0:.4g}" in w[0]
    assert w[0] in r.to_dict()["warnings"]


def test_record_shorter_than_force_is_refused(station) -> None:
    # the push-off lands at 13-14 s: a 5-s record cannot judge it
    import microg
    from microg.errors import InputError

    with pytest.raises(InputError) as exc:
        microg.analyze(station, duration=5.0, dt=0.01)
    assert exc.value.where == "duration" and "14 s" in str(exc.value)


def test_dt_too_coarse_for_the_modes_is_refused(station) -> None:
    # dt = 1 s: Nyquist 0.5 Hz, modes up to 10 Hz in the response -> aliased bands
    import microg
    from microg.errors import InputError

    with pytest.raises(InputError) as exc:
        microg.analyze(station, dt=1.0, duration=200.0)
    assert exc.value.where == "dt" and "Nyquist" in str(exc.value)
    # the same record with the response limited below Nyquist is accepted
    r = microg.analyze(station, dt=1.0, duration=400.0, max_freq=0.4, isolation=False)
    assert float(r.modes.freq_hz[r.used].max()) < 0.5


def test_force_normal_to_a_planar_model_is_refused(station) -> None:
    # the report's X-Z model cannot carry a force along y: the response would be zero
    import microg
    from microg.errors import InputError

    with pytest.raises(InputError) as exc:
        microg.analyze(station, method="ritz", plane="xz", direction="y", duration=40, dt=0.02)
    assert exc.value.where == "direction" and "no work" in str(exc.value)
    r = microg.analyze(
        station, method="ritz", plane="xz", direction="1 1 0", duration=40, dt=0.02, isolation=False
    )
    assert any("of the force" in w and "dropped" in w for w in r.warnings)


def test_failing_mount_is_never_recommended(station) -> None:
    # a requirement 1000x stricter than the ISS's: no spring-damper mount can meet it, so the
    # advice must say so, give the attenuation per band, name active isolation, and recommend
    # nothing (the design it verified fails its own time-domain check)
    from dataclasses import replace

    import microg
    from microg.environment.requirements import iss_requirement

    strict = replace(iss_requirement(), name="iss/1000", limit_g=iss_requirement().limit_g * 1e-3)
    r = microg.analyze(station, observe=["keel-tip"], requirement=strict)
    adv = r.observations["keel-tip"].isolation
    assert adv.isolated is not None
    assert adv.status == "no-passive-mount" and adv.recommended is False
    d = r.to_dict()["observations"]["keel-tip"]["isolation"]
    assert d["recommended_mount"] is None and "Recommended" not in d["note"]
    assert "active isolation" in d["note"] and d["attenuation_needed"]
    assert all(b["factor"] > 1 for b in d["attenuation_needed"])


def test_recommended_means_verified(station) -> None:
    # README example 1 (keel tip, foot push-off, 1 % damping): whatever the outcome, a mount is
    # "recommended" exactly when the package complies in the time-domain check and the record
    # resolves the mount's resonance (f_n at or above the lowest resolved band edge)
    import microg

    r = microg.analyze(station, force="foot-pushoff-max", observe=["lab", "keel-tip"], damping=0.01)
    for ob in r.observations.values():
        adv = ob.isolation
        if adv.isolated is not None:
            to = ob.assessment.third_octave
            floor = float(np.min(to.lower_hz[np.asarray(to.resolved, bool)]))
            f_n = adv.mount.freq_hz_n if adv.verified == "screened" else adv.design.freq_hz_n
            assert adv.verifiable == (f_n >= floor)
            assert adv.recommended == (bool(adv.isolated.complies) and f_n >= floor)
            d = ob.to_dict()["isolation"]
            assert (d["recommended_mount"] is not None) == adv.recommended


def test_provenance(default_result) -> None:
    # reference: the shipped file's bytes hashed here, independently of the library
    import hashlib
    import re
    from importlib import resources

    import microg

    meta = default_result.to_dict()["meta"]
    assert meta["microg_version"] == microg.__version__
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", meta["created_utc"])
    data = resources.files("microg").joinpath("data/ioc.toml").read_bytes()
    assert meta["model_sha256"] == hashlib.sha256(data).hexdigest()
    d = default_result.to_dict()["disturbances"][0]
    assert d["direction_axis"] == "x" and d["end_s"] == 14.0


def test_interval_margins_recomputed(station) -> None:
    # the worst 100-s interval margin equals each interval assessed on its own here (only the
    # bands one interval resolves are judged, as in the whole-record verdict)
    import microg
    from microg.environment.metrics import assess

    r = microg.analyze(station, observe=["keel-tip"], isolation=False)
    ob = r.observations["keel-tip"]
    t, a = ob.response.timepts, ob.response.acceleration
    per = int(round(100.0 / 0.01))
    margins = []
    for i in range(t.size // per):
        sub = assess(t[i * per : (i + 1) * per], a[:, i * per : (i + 1) * per], r.requirement)
        to = sub.third_octave
        margins.append(float(np.min(to.margin[:, np.asarray(to.resolved, bool)])))
    assert ob.interval["count"] == 2
    assert ob.interval["min_margin"] == pytest.approx(min(margins), rel=1e-9)


def test_sources_frequency_domain_contract(station) -> None:
    # analyze --sources adds `frequency_domain` keyed by observed point, with the transient
    # block's band keys; it is the library's assess_sources on the same modes and damping
    import microg
    from microg.environment.sources import load_sources
    from microg.environment.vibratory import assess_sources

    r = microg.analyze(station, sources="example", observe=["lab"])
    d = r.to_dict()
    assert d["observations"] == {} and d["report_criterion"] is None  # no force: no transient
    fd = d["frequency_domain"]["lab"]
    keys = {"center_hz", "lower_hz", "upper_hz", "rms_g", "limit_g", "margin"}
    assert keys <= set(fd["third_octave"]) and isinstance(fd["complies"], bool)
    assert fd["contributions"]["bands"]
    assert d["complies"] == fd["complies"]
    modes = r.modes
    ref = assess_sources(
        modes, load_sources("example"), ["lab"], r.requirement, np.where(modes.rigid, 0, 0.005)
    ).to_dict()["lab"]
    assert fd["third_octave"]["rms_g"] == ref["third_octave"]["rms_g"]
    # with a force too, both regimes are judged
    both = microg.analyze(
        station, force="crew-pushoff", sources="example", observe=["lab"], isolation=False
    )
    assert set(both.to_dict()["observations"]) == {"lab"} and both.frequency_domain is not None
    assert both.complies == (both.observations["lab"].complies and fd["complies"])


def test_unstable_libration_refuses_a_transient_verdict() -> None:
    # Iy < Iz with gravity gradient: a mode grows as exp(g t); the response has no bound, so
    # the main job refuses (naming the inertia condition) rather than treat it as rigid
    from pathlib import Path

    import microg
    from microg.errors import InputError

    model = Path(__file__).parent / "data" / "models" / "solver_unstable.toml"
    with pytest.raises(InputError) as exc:
        microg.analyze(model, at="lab", gravity_gradient=True, duration=40, dt=0.02)
    assert exc.value.where == "gravity_gradient" and "unstable" in str(exc.value)
    assert "I_y" in str(exc.value)
    # free-free, the same model is analysed
    assert microg.analyze(model, at="lab", duration=40, dt=0.02, isolation=False).observations


def test_three_component_force_is_the_sum_of_its_components(station, tmp_path) -> None:
    # a CSV force t, Fx, Fy, Fz with a direction that turns: the response is the sum of the
    # responses to each component along its axis (linearity; independent per-axis runs)
    import microg
    from microg.dynamics.forces import piecewise_linear

    t = np.array([0.0, 1.0, 2.0, 3.0])
    fx, fy, fz = [0.0, 100.0, 0.0, 0.0], [0.0, 0.0, 80.0, 0.0], [0.0, 30.0, -30.0, 0.0]
    csv = tmp_path / "turning.csv"
    rows = "\n".join(f"{a},{b},{c},{d}" for a, b, c, d in zip(t, fx, fy, fz, strict=True))
    csv.write_text("t [s],Fx [N],Fy [N],Fz [N]\n" + rows + "\n")
    kw = dict(observe=["lab"], duration=40.0, dt=0.02, isolation=False)
    r = microg.analyze(station, force=str(csv), **kw)
    ref = sum(
        microg.analyze(station, force=piecewise_linear(t, np.array(v)), direction=ax, **kw)
        .responses["lab"]
        .acceleration
        for v, ax in ((fx, "x"), (fy, "y"), (fz, "z"))
    )
    a = r.responses["lab"].acceleration
    assert np.max(np.abs(a - ref)) <= 1e-12 * np.max(np.abs(ref))
    d = r.to_dict()["disturbances"][0]
    assert d["direction"] is None and d["peak_force_N"] == pytest.approx(np.hypot(100, 30))


def test_bare_numbers_take_the_models_unit_system():
    # the IOC file declares units = "US": a bare f0 is lbf (25 lbf = 111.205 N exactly by
    # the definitions lbf = 0.45359237 kg x 9.80665 m/s^2), so it gives the same peak as
    # "25 lbf" bit for bit, and differs from 25 N by the ratio of the forces (linearity)
    import microg

    st = microg.load_station("ioc")
    assert st.unit_system == "US"
    kw = dict(at="crew", observe=["lab"], duration="100 s", dt="0.02 s")

    def peak(f: str) -> float:
        return microg.analyze(st, force=f, **kw).observations["lab"].peak_accel_g

    bare, lbf, newton = (peak(f"crew-pushoff:f0=25{u}") for u in ("", " lbf", " N"))
    assert bare == lbf
    assert bare / newton == pytest.approx(4.4482216152605, rel=1e-9)
    # a model without a declared system refuses the bare number, naming the parameter
    si = load_station(Path(__file__).parent / "data" / "models" / "small_si.toml")
    assert si.unit_system is None
    with pytest.raises(microg.InputError, match="no unit"):
        microg.analyze(si, force="crew-pushoff:f0=25", duration="100 s")


def test_results_as_xarray_carry_units_and_the_same_numbers():
    # reference: the result objects' own arrays (to_xarray is a relabelling, bit for bit)
    import microg

    r = microg.analyze("ioc", observe=["lab", "crew"], duration="50 s", dt="0.02 s")
    ds = r.to_xarray()
    assert list(ds.point.values) == ["lab", "crew"]
    for i, name in enumerate(("lab", "crew")):
        ob = r.observations[name]
        np.testing.assert_array_equal(ds.accel_mps2.values[i], ob.response.acceleration)
        assert ds.peak_accel_g.values[i] == ob.assessment.peak_accel_g
        da = ob.to_xarray()
        assert da.name == "accel_mps2" and da.attrs["units"] == "m/s^2"
        assert da.time.attrs["units"] == "s"
        c = ob.contributions.to_xarray()
        np.testing.assert_array_equal(c.at_peak_g.values, ob.contributions.at_peak_g)
        assert c.freq_hz.attrs["units"] == "Hz"
    np.testing.assert_array_equal(ds.time.values, r.timepts)
    assert ds.accel_mps2.attrs["units"] == "m/s^2" and ds.time.attrs["units"] == "s"


def test_no_mode_in_the_response_is_refused_not_a_green_verdict():
    # the clamped NASTRAN beam (tests/data/nastran, SOL 103, SPC'd: no rigid-body mode) has
    # its first mode at 456.66 Hz (the F06): below the default 10-Hz max_freq no mode enters,
    # the response would be identically zero, and "complies" would rest on nothing
    import microg

    path = Path(__file__).parent / "data" / "nastran" / "beam_modes" / "beam_modes_m2.op2"
    model = microg.load_model(path, units="in,lbf,s")
    with pytest.raises(microg.InputError, match="no mode enters the response") as err:
        microg.analyze(model, force="crew-pushoff", at="grid:11", observe=["grid:6"])
    assert err.value.where == "max_freq" and "456.7 Hz" in err.value.fix


def test_rigid_only_response_is_said():
    # max_freq below the IOC's first elastic mode (0.17 Hz, the modes table): the response
    # is the rigid-body motion alone, which the result says
    import microg

    r = microg.analyze("ioc", observe=["lab"], max_freq="0.05 Hz", duration="100 s")
    assert any("no elastic mode below max_freq" in w for w in r.warnings)
    assert not any(r.used & r.modes.elastic)


def test_to_dict_is_strict_json_and_carries_the_force_parameters():
    # the review board's provenance: the push-off's parameters as given (40 lbf = 177.929 N
    # by the definition of the lbf; t1 as written), and to_dict() is plain JSON (no numpy
    # arrays, no NaN/Infinity tokens), equal to the CLI's writer's output
    import json

    import microg
    from microg._io import dumps

    r = microg.analyze(
        "ioc", force="crew-pushoff:f0=40lbf,t1=0.5s", observe=["lab"], duration="100 s"
    )
    d = r.to_dict()
    assert json.loads(json.dumps(d, allow_nan=False)) == json.loads(dumps(d))
    p = d["disturbances"][0]["params"]
    assert p["f0_N"] == pytest.approx(40 * 4.4482216152605, rel=1e-12)
    assert p["t1_s"] == 0.5 and p["t13_s"] == 13.0 and p["t14_s"] == 14.0
    assert d["disturbances"][0]["direction"] == [1.0, 0.0, 0.0]


def test_a_negative_duration_is_blamed_on_the_duration():
    import microg

    with pytest.raises(microg.InputError) as err:
        microg.analyze("ioc", duration="-200 s")
    assert err.value.where == "duration" and "must be > 0" in str(err.value)


@pytest.mark.parametrize("zeta", [1.0, -0.01, float("nan")])
def test_damping_outside_0_1_is_refused_once_at_the_boundary(station, zeta) -> None:
    """The damping ratio is checked once, for analyze() and run_analysis() alike (the response
    kernels trust it): a ratio of 1 or more, a negative one or NaN names the damping."""
    import microg

    with pytest.raises(microg.InputError) as err:
        run_analysis(station, _opts(zeta=zeta))
    assert err.value.where == "damping" and "0 <= zeta < 1" in str(err.value)
    with pytest.raises(microg.InputError) as err:
        microg.analyze(station, damping=zeta)
    assert err.value.where == "damping"


def test_provenance_hash_of_a_file_read_in_blocks(tmp_path) -> None:
    # reference: hashlib over the whole file at once; the file (> 8 MiB, one block and a
    # piece) is hashed by the library in blocks, in a background thread
    import hashlib

    from microg.analysis.provenance import Provenance

    class FileModel:
        source = str(tmp_path / "big.bin")

    data = np.random.default_rng(0).bytes((1 << 23) + 12345)
    (tmp_path / "big.bin").write_bytes(data)
    meta = Provenance(FileModel(), "microg analyze big.bin").result()
    assert meta["model_sha256"] == hashlib.sha256(data).hexdigest()
    assert meta["model_path"] == str((tmp_path / "big.bin").resolve())
    assert meta["command"] == "microg analyze big.bin"
