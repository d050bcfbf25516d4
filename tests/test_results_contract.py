"""The results contract: every public result type has ``to_dict()`` that is
JSON-ready through ``microg._io.dumps``, and where it applies ``to_xarray()`` with a ``units``
attribute on every data variable and coordinate, and ``.plot()`` returning a
``matplotlib.figure.Figure`` whose drawn data are the result's own numbers.

References: the drawn lines are compared with the result's arrays (or its ``to_xarray()``
numbers) exactly or to float rounding (a plotted array is the same array, scaled by a constant
such as 1e6 / G0); the dict is compared with the dataclass fields after a json round trip.
The inventory test walks every public dataclass of the stage modules so that a new result type
cannot slip past this file.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import json
import pkgutil

import numpy as np
import pytest
from matplotlib.figure import Figure

from microg._io import dumps
from microg.units import G0

# --------------------------------------------------------------------------- fixtures

DT = 0.1
T = np.arange(2000) * DT  # 200 s, short enough that no line is drawn through an envelope
F0 = 0.5  # Hz
A0 = 1e-3 * G0  # 1 milli-g: far above the ISS limit at 0.5 Hz (9 micro-g)


def _accel() -> np.ndarray:
    w = 2 * np.pi * F0
    return np.vstack(
        [A0 * np.sin(w * T), 0.3 * A0 * np.sin(2 * w * T), 1e-3 * A0 * np.ones_like(T)]
    )


@pytest.fixture(scope="module")
def assessment():
    from microg.environment.metrics import assess

    return assess(T, _accel(), "iss")


@pytest.fixture(scope="module")
def advice(assessment):
    from microg.dynamics.response import PointResponse
    from microg.environment.requirements import iss_requirement
    from microg.isolation.advise import advise_isolation

    a = _accel()
    w = 2 * np.pi * F0
    resp = PointResponse("lab", T, -a / w**2, np.zeros_like(a), a)
    return advise_isolation("lab", assessment, resp, iss_requirement(), package_mass=450.0)


def _lines(fig: Figure) -> list[tuple[np.ndarray, np.ndarray]]:
    return [
        (np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float))
        for ax in fig.axes
        for ln in ax.get_lines()
    ]


def _drawn(fig: Figure, x: np.ndarray, y: np.ndarray, rtol: float = 1e-12) -> bool:
    """Some line of ``fig`` has exactly these x and y data (to rounding of a unit scale)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    for lx, ly in _lines(fig):
        if (
            lx.shape == x.shape
            and np.allclose(lx, x, rtol=rtol, atol=0)
            and np.allclose(ly, y, rtol=rtol, atol=0, equal_nan=True)
        ):
            return True
    return False


def _check_dict(obj, *args) -> dict:
    d = obj.to_dict(*args)
    assert isinstance(d, dict)
    back = json.loads(dumps(d))  # JSON-ready: dumps refuses NaN and unknown types
    assert set(back) == set(d)
    return back


def _check_xarray(ds) -> None:
    import xarray as xr

    assert isinstance(ds, xr.Dataset | xr.DataArray)
    variables = [ds] if isinstance(ds, xr.DataArray) else list(ds.data_vars.values())
    assert variables
    for v in variables:
        assert "units" in v.attrs, f"{v.name} has no units"
    for name, c in ds.coords.items():
        if c.dtype.kind in "fiu":
            assert "units" in c.attrs, f"coordinate {name} has no units"
    for key, value in ds.attrs.items():  # storable in netCDF / zarr attributes
        assert isinstance(value, str | int | float | list), (key, value)


def _check_figure(fig) -> Figure:
    assert isinstance(fig, Figure)
    assert fig.axes
    return fig


# ------------------------------------------------------------------- environment results


def test_spectrum(assessment):
    s = assessment.spectrum
    d = _check_dict(s)
    assert d["freq_hz"] == s.freq_hz.tolist()  # the same numbers after a json round trip
    np.testing.assert_allclose(d["psd_g2_per_hz_axis"]["x"], s.psd[0] / G0**2, rtol=1e-15)
    ds = s.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.psd_g2_per_hz.values, s.psd / G0**2)
    fig = _check_figure(s.plot())
    # plot_psd leaves out the 0-Hz bin and floors at 1e-300 (log axis); x row drawn as is
    assert _drawn(fig, s.freq_hz[1:], np.maximum(s.psd[0, 1:] / G0**2, 1e-300))


def test_band_table_and_requirement():
    from microg.environment.requirements import iss_requirement

    req = iss_requirement()
    d = _check_dict(req)
    assert d["limit_g"] == req.limit_g.tolist() and d["center_hz"] == req.bands.center_hz.tolist()
    bt = _check_dict(req.bands)
    assert bt["lower_hz"] == req.bands.lower_hz.tolist()
    _check_xarray(req.bands.to_xarray())
    ds = req.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.limit_g.values, req.limit_g)
    fig = _check_figure(req.plot())
    # the limit as steps: each band's limit from its lower to its upper edge (micro-g)
    x = np.column_stack([req.bands.lower_hz, req.bands.upper_hz]).ravel()
    assert _drawn(fig, x, np.repeat(req.limit_g, 2) * 1e6)


def test_band_rms(assessment):
    from microg.environment.metrics import band_rms
    from microg.environment.requirements import iss_requirement

    br = band_rms(assessment.spectrum, iss_requirement().bands)
    d = _check_dict(br)
    np.testing.assert_allclose(d["rms_g_axis"]["x"], br.rms[0] / G0, rtol=1e-15)
    ds = br.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.rms_g.values, br.rms / G0)
    # the same bands as the assessment's: same numbers (one definition of band RMS)
    np.testing.assert_allclose(ds.rms_g.values, assessment.third_octave.rms_g, rtol=1e-14)


def test_third_octave(assessment):
    to = assessment.third_octave
    d = _check_dict(to)
    assert d == json.loads(dumps(assessment.to_dict()["third_octave"]))  # one definition
    ds = to.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.rms_g.values, to.rms_g)
    fig = _check_figure(to.plot())
    assert _drawn(fig, to.center_hz, np.maximum(to.rms_g[0] * 1e6, 1e-12))


@pytest.mark.parametrize("which", ["integrated_sliding", "integrated_pims"])
def test_integrals(assessment, which):
    integ = getattr(assessment, which)
    d = _check_dict(integ)
    assert d["max_mps_axis"]["x"] == float(integ.max_mps[0])
    assert d["window_s"] == integ.window_s
    ds = integ.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.delta_v_mps.values, integ.delta_v)
    fig = _check_figure(integ.plot())
    assert _drawn(fig, integ.t_start, integ.delta_v[0] / G0 * 1e6)  # plotted in micro-g s


def test_worst_band(assessment):
    wb = assessment.worst_band
    assert wb is not None
    d = _check_dict(wb)
    assert d["center_hz"] == wb.center_hz and d["margin"] == wb.margin


def test_assessment_still_passes(assessment):
    _check_dict(assessment)
    _check_xarray(assessment.to_xarray())
    _check_figure(assessment.plot())


def test_measured_record():
    from microg.environment.measured import MeasuredRecord, PadHeader

    rec = MeasuredRecord("r.csv", "csv", "s1", T, _accel(), 1 / DT, cutoff_hz=4.0)
    _check_dict(rec)
    da = rec.to_xarray()
    _check_xarray(da)
    assert da.dims == ("axis", "time") and da.attrs["units"] == "m/s^2"
    np.testing.assert_array_equal(da.values, rec.accel)
    fig = _check_figure(rec.plot())
    # plot_time_history draws micro-g
    assert _drawn(fig, T, rec.accel[0] / G0 * 1e6)
    hdr = PadHeader("h", "sams2_accel", "s1", 500.0, 200.0, None, "binary", "d.bin")
    assert _check_dict(hdr)["sample_rate_hz"] == 500.0


# --------------------------------------------------------------------- isolation results


def test_absorber_tuning_and_peak():
    from microg.isolation.absorber import den_hartog, peak_over_band, tune_absorber
    from microg.isolation.transmissibility import accel_magnification

    for tuning in (den_hartog(0.05), tune_absorber(0.05, (0.8, 1.25))):
        d = _check_dict(tuning)
        assert d["k"] == tuning.k and d["peak_Ma"] == tuning.peak_Ma
        assert tuning.contract().items() <= d.items()  # the CLI contract is a subset
        ds = tuning.to_xarray()
        _check_xarray(ds)
        r = ds.r.values
        # reference: Eq. 4.3 solved, evaluated directly
        np.testing.assert_array_equal(
            ds.Ma.values, accel_magnification(tuning.k, 0.05, tuning.zeta, r)
        )
        fig = _check_figure(tuning.plot())
        assert _drawn(fig, r, ds.Ma.values)
        assert _drawn(fig, [tuning.r_peak], [tuning.peak_Ma])
    pk = peak_over_band(10.0, 0.05, 0.2, (0.5, 1.5))
    assert _check_dict(pk) == {"peak_Ma": pk.peak_Ma, "r_peak": pk.r_peak}


@pytest.mark.parametrize("mu", [None, 0.05])
def test_mount_design(mu):
    from microg.isolation.design import design_mount

    d = design_mount(450.0, (2.0, 6.0), 0.5, mu=mu)
    out = _check_dict(d)
    assert out["k1_N_per_m"] == d.k1 and out["sag_1g_m"] == d.sag_1g and out["mass_kg"] == 450.0
    ds = d.to_xarray()
    _check_xarray(ds)
    f = ds.freq_hz.values
    # the design meets its target over its band: M_a <= target at the band's frequencies
    band = (f >= d.band_hz[0]) & (f <= d.band_hz[1])
    assert band.sum() > 10
    assert ds.Ma.values[band].max() <= d.target * (1 + 1e-6)  # bisection tolerance 1e-4 in r
    if mu is None:  # reference: 1 / |1 - r^2| (Eq. 4.3 with m2 = 0)
        np.testing.assert_allclose(ds.Ma.values, 1 / np.abs(1 - (f / d.freq_hz_n) ** 2), 1e-12)
    fig = _check_figure(d.plot())
    assert _drawn(fig, f, ds.Ma.values)


def test_mount_choice(assessment):
    from microg.environment.requirements import iss_requirement
    from microg.isolation.mount import search_mount

    # k_max off the bins: an undamped mount resonant exactly on a PSD bin divides by zero in
    # search_mount (reported)
    mc = search_mount(
        assessment.spectrum, iss_requirement(), 450.0, 450.0 * (2 * np.pi) ** 2 * 1.37
    )
    out = _check_dict(mc)
    assert out["k1_N_per_m"] == mc.k1
    ds = mc.to_xarray()
    _check_xarray(ds)
    f = ds.freq_hz.values
    # reference: |T| of a spring-damper, (k + i c w) / (k - m w^2 + i c w), written out here
    w = 2 * np.pi * f
    m = mc.k1 / (2 * np.pi * mc.freq_hz_n) ** 2
    t = np.abs((mc.k1 + 1j * mc.c1 * w) / (mc.k1 - m * w**2 + 1j * mc.c1 * w))
    np.testing.assert_allclose(ds.transmissibility.values, t, rtol=1e-9)
    fig = _check_figure(mc.plot())
    assert _drawn(fig, f, ds.transmissibility.values)


def test_section42_claims():
    from microg.isolation.design import check_section42_claims

    c = check_section42_claims()
    d = _check_dict(c)
    assert [x["id"] for x in d["checks"]] == [x.id for x in c.checks]
    assert d["checks"][0]["holds"] == c.checks[0].holds


def test_isolation_advice(advice):
    assert advice.needed and advice.attenuation_needed
    d = _check_dict(advice)
    ds = advice.to_xarray()
    _check_xarray(ds)
    centers = sorted(advice.attenuation_needed)
    np.testing.assert_array_equal(ds.center_hz.values, centers)
    np.testing.assert_array_equal(
        ds.attenuation_needed.values, [advice.attenuation_needed[c] for c in centers]
    )
    assert [a["center_hz"] for a in d["attenuation_needed"]] == centers
    fig = _check_figure(advice.plot())
    assert _drawn(fig, ds.center_hz.values, 1 / ds.attenuation_needed.values)
    if advice.design is not None:
        assert _drawn(fig, ds.freq_hz.values, advice.design.magnification(ds.freq_hz.values))
    if advice.mount is not None:
        assert d["screened_mount"] == json.loads(dumps(advice.mount.to_dict()))


def test_advice_not_needed_still_plots():
    from microg.isolation.advise import IsolationAdvice

    adv = IsolationAdvice.not_assessed("lab")
    _check_dict(adv)
    assert adv.to_xarray().sizes == {"center_hz": 0, "freq_hz": 0}
    _check_figure(adv.plot())


# ------------------------------------------------------------- dynamics and isolation


@pytest.fixture(scope="module")
def modal_run():
    """Two oscillators and a rigid mode under a 1-N, 2-s pulse (exact closed-form response)."""
    from microg.dynamics.response import modal_pwl_response

    omega = np.array([0.0, 2 * np.pi * 0.3, 2 * np.pi * 1.1])
    tf = np.array([0.0, 0.0, 2.0, 2.0])
    p = np.outer([1.0, 0.5, -0.2], [0.0, 1.0, 1.0, 0.0])
    return modal_pwl_response(omega, 0.01, tf, p, T)


def test_modal_response(modal_run):
    r = modal_run
    d = _check_dict(r)
    assert d["n_modes"] == 3 and d["n_samples"] == T.size
    # reference: numpy's own maximum over each row of the arrays
    assert d["peak_eta_ddot"] == np.max(np.abs(r.eta_ddot), axis=1).tolist()
    ds = r.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.eta_ddot.values, r.eta_ddot)
    np.testing.assert_array_equal(ds.mode.values, [1, 2, 3])
    fig = _check_figure(r.plot(n_show=2))
    assert len(_lines(fig)) == 2  # the two largest, no more
    big = int(np.argmax(np.max(np.abs(r.eta_ddot), axis=1)))
    assert _drawn(fig, T, r.eta_ddot[big])  # 2,000 samples: drawn as they are


def test_point_response():
    from microg.dynamics.response import PointResponse

    a = _accel()
    w = 2 * np.pi * F0
    r = PointResponse("lab", T, -a / w**2, a / w, a)
    d = _check_dict(r)
    assert d["name"] == "lab" and d["t_end_s"] == float(T[-1])
    assert d["peak_accel_mps2_axis"] == np.max(np.abs(a), axis=1).tolist()
    assert d["sampled_peak_accel_g"] == pytest.approx(
        np.max(np.linalg.norm(a, axis=0)) / G0, rel=1e-15
    )
    ds = r.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.accel_mps2.values, a)
    np.testing.assert_array_equal(ds.displacement_m.values, -a / w**2)
    fig = _check_figure(r.plot())
    assert _drawn(fig, T, a[0] / G0 * 1e6)  # micro-g, as plot_time_history draws it


def test_peak_response():
    from microg.dynamics.forces import ForceHistory
    from microg.dynamics.response import peak_response

    omega = np.array([0.0, 2 * np.pi * 0.3, 2 * np.pi * 1.1])
    f = ForceHistory(np.array([0.0, 0.0, 2.0, 2.0]), np.array([0.0, 1.0, 1.0, 0.0]), "pulse")
    phi = np.eye(3)
    tmap = np.eye(3)
    pk = peak_response(omega, 0.01, phi, {"p": tmap}, [(f, np.array([1.0, 0.5, -0.2]))], T)["p"]
    _check_dict(pk)
    ds = pk.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.peak_accel_mps2.values, pk.peak_accel_mps2_axis)
    assert ds.attrs["magnitude_peak_accel_mps2"] == pk.peak_accel_mps2


def test_isolation_time_response():
    from microg.isolation.timedomain import IsolatorModel, package_response

    a = _accel()[0]
    r = package_response(IsolatorModel(m1=100.0, k1=100.0 * (2 * np.pi * 0.05) ** 2), T, a)
    d = _check_dict(r)
    assert d["peak_package_mps2"] == r.peak_package and d["peak_ratio"] == r.peak_ratio
    assert d["isolator"]["freq_hz_n"] == pytest.approx(0.05, rel=1e-12)
    ds = r.to_xarray()
    _check_xarray(ds)
    np.testing.assert_array_equal(ds.package_accel_mps2.values, r.package_accel)
    fig = _check_figure(r.plot())
    assert _drawn(fig, r.timepts, np.asarray(r.package_accel) / G0 * 1e6)


# ------------------------------------------------------------------------- inventory

#: public result types and the methods they have; a type missing here fails the inventory
CONTRACT: dict[str, tuple[str, ...]] = {
    "microg.analysis.result.Analysis": ("to_dict", "to_xarray", "plot"),
    # dynamics
    "microg.dynamics.response.ModalResponse": ("to_dict", "to_xarray", "plot"),
    "microg.dynamics.response.PointResponse": ("to_dict", "to_xarray", "plot"),
    "microg.dynamics.peaks.PeakResponse": ("to_dict", "to_xarray"),
    "microg.isolation.timedomain.IsolationTimeResponse": ("to_dict", "to_xarray", "plot"),
    "microg.analysis.result.Observation": ("to_dict", "to_xarray", "plot"),
    "microg.analysis.contributions.ModeContributions": ("to_dict", "to_xarray"),
    "microg.study.summary.Summary": ("to_dict", "to_xarray", "plot"),
    # environment
    "microg.environment.spectrum.Spectrum": ("to_dict", "to_xarray", "plot"),
    "microg.environment.bands.BandRMS": ("to_dict", "to_xarray"),
    "microg.environment.third_octave.ThirdOctave": ("to_dict", "to_xarray", "plot"),
    "microg.environment.integrated.IntegratedAcceleration": ("to_dict", "to_xarray", "plot"),
    "microg.environment.integrated.IntegratedBlocks": ("to_dict", "to_xarray", "plot"),
    "microg.environment.third_octave.WorstBand": ("to_dict",),
    "microg.environment.assessment.Assessment": ("to_dict", "to_xarray", "plot"),
    "microg.environment.requirements.BandTable": ("to_dict", "to_xarray"),
    "microg.environment.requirements.Requirement": ("to_dict", "to_xarray", "plot"),
    "microg.environment.record.MeasuredRecord": ("to_dict", "to_xarray", "plot"),
    "microg.environment.pad.PadHeader": ("to_dict",),
    "microg.environment.allocation.Allocation": ("to_dict", "to_xarray", "plot"),
    "microg.environment.intervals.IntervalBandRMS": ("to_dict", "to_xarray", "plot"),
    "microg.environment.intervals.IntervalStats": ("to_dict", "to_xarray", "plot"),
    "microg.environment.intervals.BandLimitedRMS": ("to_dict", "to_xarray", "plot"),
    "microg.environment.intervals.Spectrogram": ("to_dict", "to_xarray", "plot"),
    "microg.environment.intervals.CumulativeRMS": ("to_dict", "to_xarray", "plot"),
    "microg.environment.intervals.IntervalAnalysis": ("to_dict", "to_xarray", "plot"),
    "microg.environment.quasisteady.QuasiSteadyResult": ("to_dict", "to_xarray", "plot"),
    "microg.environment.quasisteady.QuasiSteadyMap": ("to_dict",),
    "microg.environment.quasisteady.PointQuasiSteady": ("to_dict",),
    "microg.environment.transient.TransientVerdict": ("to_dict",),
    "microg.environment.transient.TransientCheck": ("to_dict",),
    "microg.environment.vibratory.VibratoryAssessment": ("to_dict", "to_xarray", "plot"),
    # isolation
    "microg.isolation.absorber.PeakResult": ("to_dict",),
    "microg.isolation.absorber.AbsorberTuning": ("to_dict", "to_xarray", "plot"),
    "microg.isolation.design.MountDesign": ("to_dict", "to_xarray", "plot"),
    "microg.isolation.design.ClaimCheck": ("to_dict",),
    "microg.isolation.design.Section42Claims": ("to_dict",),
    "microg.isolation.mount.MountChoice": ("to_dict", "to_xarray", "plot"),
    "microg.isolation.advise.IsolationAdvice": ("to_dict", "to_xarray", "plot"),
    # location
    "microg.location.mapping.AccelerationMap": ("to_dict", "to_xarray", "plot"),
    "microg.location.pipeline.LocateResult": ("to_dict", "to_xarray", "plot"),
    "microg.location.mapping.Location": ("to_dict",),
    "microg.location.site.SitePeak": ("to_dict",),
    "microg.location.layout.LayoutResult": ("to_dict", "to_xarray", "plot"),
    "microg.location.sampling.Node": ("to_dict",),
    # dynamics (frequency.py)
    "microg.dynamics.frequency.AccelerationFRF": ("to_dict", "to_xarray", "plot"),
    "microg.dynamics.frequency.HarmonicResponse": ("to_dict", "to_xarray", "plot"),
    "microg.dynamics.frequency.BandResponse": ("to_dict", "to_xarray", "plot"),
    "microg.dynamics.modes.Modes": ("to_dict", "to_xarray", "plot"),
    "microg.environment.overlay.BandOverlay": ("to_dict", "to_xarray", "plot"),
    # study
    "microg.study.run.SweepResult": ("to_dict", "to_xarray", "plot"),
}

#: public dataclasses that are inputs or internal steps, not results (no contract)
NOT_RESULTS = {
    "microg.environment.attitude.Attitude",
    "microg.environment.drag.Drag",
    "microg.environment.drag.AtmosphereInputs",
    "microg.environment.orbit.OrbitInputs",
    "microg.environment.orbit.OrbitSamples",
    "microg.environment.quasisteady.QuasiSteadyRequirement",
    "microg.environment.sources.BandLevels",
    "microg.environment.sources.Source",
    "microg.environment.sources.SourceCatalogue",
    "microg.environment.transient.TransientCriterion",
    "microg.environment.criteria.CriterionVerdict",  # a line of Assessment.criteria (its to_dict)
    "microg.environment.transient.TransientCriteria",
    "microg.location.layout.MovableMass",
    "microg.location.sampling.SampleLine",
    "microg.dynamics.spectra.HarmonicLines",
    "microg.dynamics.spectra.BandForceSpectrum",
    "microg.dynamics.spectra.ForcePSD",
    "microg.dynamics.spectra.Load",
    "microg.dynamics.bandquad.BandQuadrature",
    "microg.dynamics.bands.BandArrays",
    "microg.location.peaks.PointPeaks",  # the kernel's step; the map and SitePeak are results
    "microg.isolation.timedomain.IsolatorModel",
    "microg.dynamics.crew.CrewPushoff",
    "microg.dynamics.forces.ForceHistory",
    "microg.dynamics.forces.Activity",
    "microg.dynamics.dense.Eigensolution",  # a solver's step; Modes is the result
    "microg.dynamics.pwl.ModalState",  # the kernel's state between its two steps
    "microg.dynamics.superposition.ModalLoad",
    "microg.dynamics.superposition.Superposition",  # the main job's step; Observation is the result
}

#: result types in files this contract's owner does not edit, still short of the contract
#: (reported to their owners); the test fails when one is fixed, so the entry is removed
KNOWN_GAPS: dict[str, tuple[str, ...]] = {}

_STAGES = ("analysis", "environment", "isolation", "location", "dynamics", "study")


def _public_dataclasses() -> dict[str, type]:
    out: dict[str, type] = {}
    names: list[str] = []
    for stage in _STAGES:
        pkg = importlib.import_module(f"microg.{stage}")
        names += [f"microg.{stage}.{m.name}" for m in pkgutil.iter_modules(pkg.__path__)]
    for name in names:
        mod = importlib.import_module(name)
        for cname in getattr(mod, "__all__", ()):
            c = getattr(mod, cname, None)
            if inspect.isclass(c) and dataclasses.is_dataclass(c) and c.__module__ == name:
                out[f"{name}.{cname}"] = c
    return out


def test_inventory_of_result_types():
    """Every public dataclass of the stages is a result with its methods, an input, or a gap."""
    found = _public_dataclasses()
    for qual, methods in CONTRACT.items():
        assert qual in found, f"{qual} is no longer public: update CONTRACT"
        missing = [m for m in methods if not callable(getattr(found[qual], m, None))]
        assert not missing, f"{qual} lacks {missing}"
    for qual, methods in KNOWN_GAPS.items():
        if qual not in found:
            continue
        still = [m for m in methods if not callable(getattr(found[qual], m, None))]
        assert still == list(methods), f"{qual} now has {set(methods) - set(still)}: update"
    unknown = set(found) - set(CONTRACT) - NOT_RESULTS - set(KNOWN_GAPS)
    # analysis/ and study/ (other owners) hold further public dataclasses; they are listed
    # by name in the report rather than here
    unknown = {q for q in unknown if not q.startswith(("microg.analysis.", "microg.study."))}
    assert not unknown, f"public dataclasses not classified: {sorted(unknown)}"


def test_every_plot_takes_the_callers_axes():
    """Every result's ``.plot`` has ``ax=`` (the matplotlib axes to draw into)."""
    found = _public_dataclasses()
    lacking = [
        qual
        for qual, methods in CONTRACT.items()
        if "plot" in methods and "ax" not in inspect.signature(found[qual].plot).parameters
    ]
    assert lacking == []


def test_a_plot_draws_into_the_callers_axes(assessment, advice):
    # reference: the caller's own figure and axes; the lines drawn are the result's numbers
    from matplotlib.figure import Figure as MplFigure

    from microg.environment.requirements import iss_requirement

    req = iss_requirement()
    fig = MplFigure()
    left, right = fig.subplots(1, 2)
    assert req.plot(ax=left) is fig
    assert assessment.plot(kind="psd", ax=right) is fig
    assert fig.axes == [left, right]  # nothing added: both drawn where the caller said
    x = np.column_stack([req.bands.lower_hz, req.bands.upper_hz]).ravel()
    assert _drawn(fig, x, np.repeat(req.limit_g, 2) * 1e6)
    assert right.get_xscale() == "log" and right.get_lines()
    assert advice.plot(ax=left) is fig  # a second drawing into the same axes
