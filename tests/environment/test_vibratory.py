"""Tests of microg.environment.vibratory and .allocation: the frequency-domain assessment.

References: the requirement object's own bands and limits (compliance is rms <= limit per band
and axis, by definition); the kernel microg.dynamics.frequency (checked against quad and a dense
solve in tests/dynamics/test_frequency.py); and the forward path itself for the allocation (a
source at the allocated level must bring the governing axis of every band to margin 1).
"""

from __future__ import annotations

import numpy as np
import pytest

from microg._io import dumps
from microg.dynamics.modes import solve_modes
from microg.environment.allocation import allocate
from microg.environment.requirements import BandTable, Requirement, iss_requirement
from microg.environment.sources import BandLevels, Source, example_sources, loads_sources
from microg.environment.vibratory import assess_sources
from microg.errors import InputError
from microg.models.toml import load_station
from microg.structure.ritz import build_ritz

ZETA = 0.01
KEYS = {"center_hz", "lower_hz", "upper_hz", "rms_g", "limit_g", "margin"}


@pytest.fixture(scope="module")
def modes():
    return solve_modes(build_ritz(load_station("ioc"), None, 2, gravity_gradient=False))


@pytest.fixture(scope="module")
def example(modes):
    return assess_sources(modes, example_sources(), ["lab", "boom-tip"], zeta=ZETA)


def test_contract_keys_and_json(example):
    d = example.to_dict()
    assert set(d) == {"lab", "boom-tip"}
    for entry in d.values():
        assert set(entry["third_octave"]) >= KEYS
        assert isinstance(entry["complies"], bool)
        assert entry["contributions"]["unit"] == "g RMS"
        for band in entry["contributions"]["bands"]:
            assert {"center_hz", "axis", "rms_g", "sources", "modes"} <= set(band)
    text = dumps(d)
    assert "NaN" not in text and "Infinity" not in text  # strict JSON
    info = example.info_dict()
    assert info["illustrative_sources"] and info["excluded_sources"] == ["antenna gimbal"]
    assert any("ILLUSTRATIVE" in w for w in example.warnings)


def test_a_band_without_power_has_the_documented_infinite_margin(example):
    # docs/assessment.md: an infinite margin (a band with no power) is the string "inf" in
    # JSON; null means "not computed".  The example's sources leave the lowest bands empty.
    worst = example.margin[0].min(axis=0)
    empty = np.isinf(worst)
    assert empty.any()
    margin = example.to_dict()["lab"]["third_octave"]["margin"]
    assert all(m == "inf" for m, e in zip(margin, empty, strict=True) if e)
    assert all(isinstance(m, float) for m, e in zip(margin, empty, strict=True) if not e)


def test_bands_and_limits_come_from_the_requirement(example):
    req = iss_requirement()
    assert np.array_equal(example.center_hz, req.bands.center_hz)
    assert np.array_equal(example.lower_hz, req.bands.lower_hz)
    assert np.array_equal(example.upper_hz, req.bands.upper_hz)
    assert np.array_equal(example.limit_g, req.limit_g)


def test_verdict_follows_the_band_margins(example):
    d = example.to_dict()
    for i, p in enumerate(example.points):
        # definition: complies iff every band and axis has rms <= limit
        assert example.complies[i] == bool(np.all(example.rms_g[i] <= example.limit_g))
        to = d[p]["third_octave"]
        worst = np.nanmin(np.array(to["margin"], dtype=float))
        assert d[p]["complies"] == (worst >= 1.0)
        # the per-point rms_g is the governing (largest) axis, margin its limit / rms
        assert np.allclose(to["rms_g"], example.rms_g[i].max(axis=0))


def test_contribution_shares_sum_to_one(example):
    for entry in example.to_dict().values():
        for band in entry["contributions"]["bands"]:
            s = sum(x["share"] for x in band["sources"])
            m = sum(x["share"] for x in band["modes"]) + band["other_modes_share"]
            assert s == pytest.approx(1.0, abs=1e-9)
            assert m == pytest.approx(1.0, abs=1e-8)
            # RSS of independent groups = total: each source alone never exceeds the total
            # unless it is cancelled by a coherent partner
            assert all(x["rms_g"] >= 0 for x in band["sources"])


def test_off_sources_are_left_out_and_duty_weighting(modes):
    text = """
[[source]]
name = "a"
at = "crew"
direction = "x"
harmonic = { amplitude = "1 N", frequency = "2 Hz" }
duty = 0.25
source = "test"

[[source]]
name = "b"
at = "crew"
direction = "x"
harmonic = { amplitude = "5 N", frequency = "2 Hz" }
state = "off"
source = "test"
"""
    cat = loads_sources(text, "t.toml")
    full = assess_sources(modes, cat, ["lab"], zeta=ZETA)
    avg = assess_sources(modes, cat, ["lab"], zeta=ZETA, duty_weighted=True)
    assert [s.name for s in full.sources] == ["a"] and full.excluded == ("b",)
    # duty scales the mean square: RMS x sqrt(duty)
    assert np.allclose(avg.rms_g, full.rms_g * 0.5, rtol=1e-12)


def test_flat_requirement_verdict(modes):
    """A flat limit just above / below the computed worst band flips the verdict."""
    bands = iss_requirement().bands
    src = [Source("s", "crew", "z", BandLevels([1.0, 1.25, 1.6], [0.1, 0.1, 0.1]), source="t")]
    base = assess_sources(modes, src, ["lab"], zeta=ZETA)
    worst = float(base.rms_g.max())
    for factor, verdict in ((1.001, True), (0.999, False)):
        req = Requirement("flat", bands, np.full(bands.center_hz.size, worst * factor), "test")
        va = assess_sources(modes, src, ["lab"], req, zeta=ZETA)
        assert bool(va.complies[0]) is verdict


def test_unknown_point_in_catalogue_names_the_file(modes):
    text = (
        '[[source]]\nname = "s"\nat = "galley"\ndirection = "x"\n'
        'harmonic = { amplitude = "1 N", frequency = "1 Hz" }\n'
    )
    with pytest.raises(InputError) as exc:
        assess_sources(modes, loads_sources(text, "cat.toml"), ["lab"])
    assert exc.value.where == "cat.toml: source[0].at"


def test_plots_and_xarray(example):
    ds = example.to_xarray()
    assert ds.rms_g.dims == ("point", "axis", "band")
    assert ds.mode_rms_g.dims == ("point", "axis", "band", "mode")
    assert ds.source_rms_g.attrs["units"] == "g"
    assert example.plot("lab").axes
    assert example.plot("boom-tip", kind="contributions").axes


# ---------------------------------------------------------------------------- allocation


@pytest.mark.parametrize("with_existing", [False, True])
def test_allocated_source_brings_every_band_to_margin_one(modes, with_existing):
    existing = example_sources() if with_existing else None
    alloc = allocate(modes, "lab", "vertical-lab", "1 0 1", zeta=ZETA, existing=existing)
    ok = np.isfinite(alloc.allowed_rms_n) & (alloc.allowed_rms_n > 0)
    assert np.count_nonzero(ok) > 30
    new = alloc.as_source("new")
    srcs = ([*existing.sources] if existing else []) + [new]
    va = assess_sources(modes, srcs, ["lab"], zeta=ZETA)
    worst = va.margin[0].min(axis=0)  # governing axis of each band
    # forward recomputation with the same kernel and bands: margin 1 to rounding (the band
    # integrals are the same numbers, only added in a different order)
    assert np.allclose(worst[ok], 1.0, rtol=1e-9)
    assert not np.any(va.complies) or np.all(worst >= 1 - 1e-9)
    # a slightly larger source fails in every allocated band
    over = Source(
        "new",
        "vertical-lab",
        "1 0 1",
        BandLevels(alloc.center_hz, np.where(ok, alloc.allowed_rms_n * 1.01, 0.0)),
    )
    va2 = assess_sources(
        modes, ([*existing.sources] if existing else []) + [over], ["lab"], zeta=ZETA
    )
    assert np.all(va2.margin[0].min(axis=0)[ok] < 1.0)
    d = alloc.to_dict()
    assert dumps(d) and len(d["allowed_rms_n"]) == alloc.center_hz.size
    assert "independent" in d["assumptions"]
    assert alloc.plot().axes and alloc.to_xarray().allowed_rms_n.attrs["units"] == "N"


def test_allocation_is_zero_where_the_site_already_exceeds(modes):
    bands = iss_requirement().bands
    loud = [Source("loud", "crew", "x", BandLevels([1.0], [50.0]), source="t")]
    alloc = allocate(modes, "lab", "boom-tip", "z", zeta=ZETA, existing=loud)
    k = int(np.argmin(np.abs(bands.center_hz - 1.0)))
    assert alloc.exceeded[k] and alloc.allowed_rms_n[k] == 0.0
    assert any("already exceed" in w for w in alloc.warnings)


def test_custom_band_table_allocation(modes):
    """Allocation on a small custom table (bands from the requirement object)."""
    c = np.array([0.5, 1.0, 2.0])
    bands = BandTable(c, c / 2 ** (1 / 6), c * 2 ** (1 / 6))
    req = Requirement("test", bands, np.array([1e-6, 2e-6, 4e-6]), "test")
    alloc = allocate(modes, "boom-tip", "lab", "y", req, zeta=ZETA)
    new = alloc.as_source()
    va = assess_sources(modes, [new], ["boom-tip"], req, zeta=ZETA)
    assert np.allclose(va.margin[0].min(axis=0), 1.0, rtol=1e-9)
