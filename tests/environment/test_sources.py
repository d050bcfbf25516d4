"""Tests of microg.environment.sources: the TOML source catalogue, units, validation, bands.

References: unit definitions (1 lbf = 4.4482216152605 N exactly, NIST SP 811), the IEC 61260-1
1/3-octave series (base-10 edges 10^((n +- 1/2)/10), base-2 edges 2^((k +- 1/2)/3)), and the
shipped IOC model's point names.
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.frequency import BandForceSpectrum, ForcePSD, HarmonicLines
from microg.environment.requirements import BandTable
from microg.environment.sources import (
    BandLevels,
    Source,
    example_sources,
    load_sources,
    loads_sources,
    third_octave_edges,
    validate_source_points,
)
from microg.errors import InputError
from microg.models.toml import load_station
from microg.units import LBF

IOC_POINTS = {p.name for p in load_station("ioc").points}

GOOD = """
[[source]]
name = "fan"
at = "lab"
direction = "x"
harmonic = { amplitude = "2 N", frequency = "0.5 Hz" }
source = "test"

[[source]]
name = "pump"
at = "crew"
direction = [0, 0.6, 0.8]
bands = { center_hz = [0.1, 0.125, 0.16], rms = [0.1, 0.2, 0.3], unit = "lbf" }

[[source]]
name = "treadmill"
at = "vertical-lab"
direction = "-z"
psd = { frequency_hz = [1, 10], value = [1e-2, 1e-3], unit = "lbf^2/Hz" }
coherent_group = "crew"
duty = 0.25
state = "off"

[[source]]
name = "motor"
at = "lab"
direction = "1 0 0"
harmonic = [{ amplitude = "1 N", frequency = "30 rpm", phase = "90 deg" },
            { amplitude = "0.5 N", frequency = "2 Hz" }]
coherent_group = "crew"
"""


def test_good_catalogue_reads_with_units():
    cat = loads_sources(GOOD, "good.toml")
    assert cat.names == ("fan", "pump", "treadmill", "motor")
    fan, pump, tread, motor = cat.sources
    assert isinstance(fan.spectrum, HarmonicLines) and fan.kind == "harmonic"
    assert fan.spectrum.amplitude_n[0] == 2.0 and fan.spectrum.freq_hz[0] == 0.5
    # lbf -> N exactly (1 lbf = 4.4482216152605 N), lbf^2/Hz -> N^2/Hz
    assert isinstance(pump.spectrum, BandLevels)
    assert np.allclose(pump.spectrum.rms_n, np.array([0.1, 0.2, 0.3]) * LBF, rtol=1e-14)
    assert isinstance(tread.spectrum, ForcePSD)
    assert np.allclose(tread.spectrum.value_n2_per_hz, np.array([1e-2, 1e-3]) * LBF**2, rtol=1e-12)
    assert np.allclose(pump.direction, [0, 0.6, 0.8])
    assert tread.state == "off" and tread.duty == 0.25 and tread.coherent_group == "crew"
    # 30 rpm = 0.5 Hz; 90 deg = pi/2 rad
    assert motor.spectrum.freq_hz[0] == pytest.approx(0.5)
    assert motor.spectrum.phase_rad[0] == pytest.approx(np.pi / 2)
    assert fan.origin == "good.toml: source[0]"
    validate_source_points(cat.sources, IOC_POINTS)


def test_example_catalogue_is_illustrative_and_fits_the_ioc_model():
    cat = example_sources()
    assert cat.illustrative
    assert all("ILLUSTRATIVE" in (s.source or "") for s in cat.sources)
    cat.validate_points(IOC_POINTS)
    kinds = {s.kind for s in cat.sources}
    assert kinds == {"harmonic", "bands", "psd"}
    assert any(s.coherent_group for s in cat.sources) and any(s.state == "off" for s in cat)
    assert load_sources("example").names == cat.names


def _one(spectrum: str, extra: str = "") -> str:
    return f'[[source]]\nname = "s"\nat = "lab"\ndirection = "x"\n{spectrum}\n{extra}\n'


BAD = [
    # (text, where the error must point, a word of the message)
    (
        _one('bands = { center_hz = [1.0, 1.1], rms = [1, 1], unit = "N" }'),
        "bad.toml: source[0].bands.center_hz[1]",
        "not a 1/3-octave",
    ),
    (
        _one('bands = { center_hz = [1.0, 1.25], rms = [1, -1], unit = "N" }'),
        "bad.toml: source[0].bands.rms[1]",
        "negative",
    ),
    (
        _one('bands = { center_hz = [1.0, 1.25], rms = [1, nan], unit = "N" }'),
        "bad.toml: source[0].bands.rms[1]",
        "finite",
    ),
    (
        _one("bands = { center_hz = [1.0, 1.25], rms = [1, 1] }"),
        "bad.toml: source[0].bands.unit",
        "missing",
    ),
    (
        _one('bands = { center_hz = [1.0, 1.25], rms = [1, 1], unit = "kg" }'),
        "bad.toml: source[0].bands.unit",
        "not a unit of force",
    ),
    (
        _one('bands = { center_hz = [1.25, 1.0], rms = [1, 1], unit = "N" }'),
        "bad.toml: source[0].bands.center_hz[1]",
        "increase",
    ),
    (
        _one('bands = { center_hz = [1.0, 1.25], rms = [1], unit = "N" }'),
        "bad.toml: source[0].bands.rms",
        "1 values for 2",
    ),
    (
        _one('psd = { frequency_hz = [1, 10], value = [1e-2, -1e-3], unit = "N^2/Hz" }'),
        "bad.toml: source[0].psd.value[1]",
        "negative",
    ),
    (
        _one('psd = { frequency_hz = [1, 10], value = [nan, 1e-3], unit = "N^2/Hz" }'),
        "bad.toml: source[0].psd.value[0]",
        "finite",
    ),
    (
        _one('psd = { frequency_hz = [10, 1], value = [1, 1], unit = "N^2/Hz" }'),
        "bad.toml: source[0].psd.frequency_hz[1]",
        "increase",
    ),
    (
        _one('psd = { frequency_hz = [1, 10], value = [1, 1], unit = "N" }'),
        "bad.toml: source[0].psd.unit",
        "not a unit",
    ),
    (
        _one('harmonic = { amplitude = 2, frequency = "1 Hz" }'),
        "bad.toml: source[0].harmonic.amplitude",
        "no unit",
    ),
    (
        _one('harmonic = { amplitude = "2 m", frequency = "1 Hz" }'),
        "bad.toml: source[0].harmonic.amplitude",
        "force",
    ),
    (
        _one('harmonic = { amplitude = "-2 N", frequency = "1 Hz" }'),
        "bad.toml: source[0].harmonic.amplitude",
        "negative",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "0 Hz" }'),
        "bad.toml: source[0].harmonic.frequency",
        "not in",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "1 Hz", phase = 0.5 }'),
        "bad.toml: source[0].harmonic.phase",
        "no unit",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequncy = "1 Hz" }'),
        "bad.toml: source[0].harmonic.frequncy",
        "unknown field",
    ),
    (
        _one(
            'harmonic = { amplitude = "2 N", frequency = "1 Hz" }\npsd = { frequency_hz = [1, 2], '
            'value = [1, 1], unit = "N^2/Hz" }'
        ),
        "bad.toml: source[0]",
        "harmonic and psd",
    ),
    (_one(""), "bad.toml: source[0]", "no spectrum"),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "1 Hz" }', "duty = 1.5"),
        "bad.toml: source[0].duty",
        "not in (0, 1]",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "1 Hz" }', 'state = "standby"'),
        "bad.toml: source[0].state",
        "unknown state",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "1 Hz" }', 'colour = "red"'),
        "bad.toml: source[0].colour",
        "unknown field",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "1 Hz" }').replace('"x"', '"sideways"'),
        "bad.toml: source[0].direction",
        "direction",
    ),
    (
        _one('harmonic = { amplitude = "2 N", frequency = "1 Hz" }') * 2,
        "bad.toml: source[1].name",
        "also source[0]",
    ),
    ("[[source]\nname = 1", "bad.toml: line 1", "invalid TOML"),
    ("", "bad.toml: source", "no [[source]]"),
]


@pytest.mark.parametrize(("text", "where", "word"), BAD)
def test_bad_catalogues_give_one_line_naming_file_and_field(text, where, word):
    with pytest.raises(InputError) as exc:
        loads_sources(text, "bad.toml")
    err = exc.value
    assert err.where is not None and err.where.startswith(where), err.where
    assert word in str(err)
    assert "\n" not in str(err)  # one line at the CLI
    assert err.fix  # every refusal says how to fix it


def test_unknown_point_is_named_with_file_and_source():
    cat = loads_sources(GOOD.replace('at = "crew"', 'at = "galley"'), "cat.toml")
    with pytest.raises(InputError) as exc:
        cat.validate_points(IOC_POINTS)
    assert exc.value.where == "cat.toml: source[1].at"
    assert "galley" in str(exc.value) and "lab" in exc.value.fix


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_sources(tmp_path / "none.toml")
    p = tmp_path / "s.toml"
    p.write_text(GOOD, encoding="utf-8")
    assert len(load_sources(p)) == 4


# ------------------------------------------------------------------------- band edges


def test_nominal_base10_centres_take_contiguous_iec_edges():
    c = np.array([0.8, 1.0, 1.25, 1.6, 2.0, 2.5, 3.15])
    lo, hi = third_octave_edges(c)
    n = np.round(10 * np.log10(c))
    assert np.allclose(lo, 10 ** ((n - 0.5) / 10), rtol=1e-14)
    assert np.allclose(hi, 10 ** ((n + 0.5) / 10), rtol=1e-14)
    assert np.allclose(lo[1:], hi[:-1], rtol=1e-14)


def test_base2_centres_take_base2_edges():
    k = np.arange(-20, -14)
    lo, hi = third_octave_edges(2.0 ** (k / 3))
    assert np.allclose(lo, 2.0 ** ((k - 0.5) / 3), rtol=1e-14)
    assert np.allclose(hi, 2.0 ** ((k + 0.5) / 3), rtol=1e-14)


def test_centres_on_a_table_take_its_edges():
    table = BandTable(
        center_hz=np.array([0.1, 0.125, 0.16]),
        lower_hz=np.array([0.0891, 0.1122, 0.1413]),
        upper_hz=np.array([0.1122, 0.1413, 0.1778]),
    )
    spec = BandLevels([0.1, 0.125, 0.16, 0.2], [1, 1, 1, 1]).resolve(table)
    assert isinstance(spec, BandForceSpectrum)
    assert np.array_equal(spec.lower_hz[:3], table.lower_hz)
    assert np.array_equal(spec.upper_hz[:3], table.upper_hz)
    assert spec.lower_hz[3] == pytest.approx(10 ** (-7.5 / 10))  # not in the table: series
    assert spec.lower_hz[3] >= spec.upper_hz[2]


def test_source_in_python_and_its_load():
    s = Source("x", "lab", "y", BandLevels([1.0, 1.25], [0.1, 0.2]), duty=0.5)
    ld = s.load(None, mean_square_scale=0.5)
    assert isinstance(ld.spectrum, BandForceSpectrum)
    assert np.allclose(ld.spectrum.rms_n, np.array([0.1, 0.2]) * np.sqrt(0.5))
    assert s.to_dict()["bands"]["rms_n"] == [0.1, 0.2]
    with pytest.raises(InputError, match="duty"):
        Source("x", "lab", "y", BandLevels([1.0], [0.1]), duty=0.0)


def test_reading_a_catalogue_does_not_load_pint():
    """Units come from microg.units' built-in table: no pint registry at startup."""
    import subprocess
    import sys

    code = (
        "import sys; from microg.environment.sources import example_sources; "
        "example_sources(); assert 'pint' not in sys.modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
