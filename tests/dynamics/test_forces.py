"""Tests of microg.dynamics.forces: Eq. 2.16, piecewise-linear histories, CSV files, specs, library.

References: the report's Eq. 2.16 written out independently below; np.interp for linear
interpolation; the magnitudes of /work/shared/reference/domain.md (Klute, KC-135).
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.forces import (
    REPORT_F0_N,
    ForceHistory,
    activity_library,
    crew_pushoff,
    from_csv,
    known_force_specs,
    parse_force_spec,
    piecewise_linear,
)
from microg.errors import InputError

LBF = 4.4482216152605  # N per lbf (exact definition)


def eq_2_16(t, f0, t1, t13, t14):
    """The report's Eq. 2.16, term by term (with t14 - t13 = t1 as in the report)."""
    return np.select(
        [(t > 0) & (t <= t1), (t > t1) & (t <= t13), (t > t13) & (t <= t14)],
        [f0 / t1 * t, 0.0 * t, f0 / t1 * (t - t14)],
        0.0,
    )


def test_crew_pushoff_is_eq_2_16():
    f = crew_pushoff()
    assert f.force.max() == pytest.approx(25 * LBF, rel=1e-15)  # 25 lbf = 111.2 N
    # sample away from the jump instants, where Eq. 2.16's left-continuous convention differs
    t = np.linspace(-1, 20, 2101)
    t = t[~np.isin(np.round(t, 9), [1.0, 13.0])]
    # both are linear interpolation of the same breakpoints: equal to rounding
    assert np.allclose(f.at(t), eq_2_16(t, REPORT_F0_N, 1, 13, 14), rtol=0, atol=1e-12)
    # right-continuous at the jumps: 0 just after t1, -f0 from t13
    assert f.at(1.0) == 0.0 and f.at(13.0) == pytest.approx(-REPORT_F0_N)
    assert f.impulse() == pytest.approx(0.0, abs=1e-12)  # push-off and landing cancel
    assert f.duration == 14.0


def test_crew_pushoff_general_impulse():
    f = crew_pushoff(10.0, 0.5, 3.0, 4.0)
    t = np.linspace(0, 5, 500_001)
    y = f.at(t)
    # trapezoid on a 1e-5 s grid differs from the exact integral only in the two jump cells
    numeric = np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t))
    assert f.impulse() == pytest.approx(10.0 * (0.5 - 1.0) / 2, rel=1e-12)
    assert numeric == pytest.approx(f.impulse(), abs=2 * 10.0 * 1e-5)


@pytest.mark.parametrize(
    "args",
    [(0.0, 1, 13, 14), (10, 0.0, 13, 14), (10, 2, 1, 14), (10, 1, 13, 13), (np.nan, 1, 13, 14)],
)
def test_crew_pushoff_validation(args):
    with pytest.raises(InputError):
        crew_pushoff(*args)


def test_piecewise_linear_at_and_hold():
    times, values = np.array([0.5, 1.0, 3.0, 4.0]), np.array([1.0, 2.0, -1.0, 5.0])
    f = piecewise_linear(times, values)
    t = np.linspace(0.5, 4.0, 351)
    assert np.allclose(f.at(t), np.interp(t, times, values), rtol=0, atol=1e-14)
    assert f.at(0.4) == 0.0  # zero before the first breakpoint
    assert f.at(9.0) == 5.0  # holds its last value
    with pytest.raises(InputError, match="must not decrease"):
        piecewise_linear([0, 2, 1], [0, 1, 2])
    with pytest.raises(InputError, match="finite"):
        piecewise_linear([0, 1], [0, np.nan])


def test_frozen_and_readonly():
    f = crew_pushoff()
    with pytest.raises(ValueError):
        f.force[0] = 1.0
    g = ForceHistory.from_breakpoints([0, 1], [0, 1], "x", direction=[0, 0, 2])
    assert np.array_equal(g.direction, [0, 0, 1])


def write(tmp_path, text, name="f.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_csv_units_in_header(tmp_path):
    p = write(
        tmp_path,
        "# a comment\ntime [ms], force [lbf], direction\n0, 0, -y\n500, 25, -y\n1000, 0,\n",
    )
    f = from_csv(p)
    assert np.allclose(f.timepts, [0, 0.5, 1.0])
    assert np.allclose(f.force, [0, 25 * LBF, 0], rtol=1e-15)
    assert np.array_equal(f.direction, [0, -1, 0])
    assert f.name == "f.csv"


def test_csv_units_line(tmp_path):
    p = write(tmp_path, "time, force\ns, N\n0, 1\n2, 3\n")
    f = from_csv(p)
    assert np.array_equal(f.force, [1.0, 3.0])


@pytest.mark.parametrize(
    ("text", "line", "what"),
    [
        ("time [s], force [N]\n0, 0\n1, 1\n1, 2\n", 4, "does not increase"),
        ("time [s], force [N]\n0, 0\n2, 1\n1, 2\n", 4, "does not increase"),
        ("time [s], force [N]\n0, 0\n1, nan\n", 3, "finite"),
        ("time [s], force [N]\n0, 0\n1, abc\n", 3, "not a number"),
        ("time [s]\n0\n1\n", 1, "missing column 'force'"),
        ("time [s], force [m]\n0, 0\n1, 1\n", 1, "not a force"),
        ("time [s], force\n0, 0\n1, 1\n", 1, "no unit"),
        ("time [s], force [N], colour\n0, 0, red\n", 1, "unknown column"),
        ("time [s], force [N]\n0, 0\n1, 1, 3\n", 3, "expected 2 values"),
        ("time [s], force [N], direction\n0, 0, x\n1, 1, y\n", 3, "direction changes"),
    ],
)
def test_csv_errors_name_file_and_line(tmp_path, text, line, what):
    p = write(tmp_path, text)
    with pytest.raises(InputError) as err:
        from_csv(p)
    msg = str(err.value)
    assert str(p) in msg and f"line {line}" in msg and what in msg
    assert "\n" not in msg  # one line


def test_parse_force_spec(tmp_path):
    f = parse_force_spec("crew-pushoff")
    assert np.array_equal(f.timepts, crew_pushoff().timepts)
    assert np.allclose(f.force, crew_pushoff().force, rtol=1e-15, atol=0)  # pint vs constant
    g = parse_force_spec("crew-pushoff:f0=40lbf,t1=0.5s")
    assert g.force.max() == pytest.approx(40 * LBF, rel=1e-15)
    assert g.timepts[1] == 0.5 and g.timepts[3] == 13.0
    p = write(tmp_path, "time [s], force [N]\n0, 0\n1, 1\n")
    assert np.array_equal(parse_force_spec(str(p)).force, [0.0, 1.0])
    with pytest.raises(InputError, match="foot-pushoff-max"):
        parse_force_spec("jump")
    with pytest.raises(InputError, match="f0="):
        parse_force_spec("crew-pushoff:g=3N")
    with pytest.raises(InputError, match="not a force"):
        parse_force_spec("crew-pushoff:f0=3m")
    with pytest.raises(InputError, match="not found"):
        parse_force_spec(str(tmp_path / "missing.csv"))


def test_library_magnitudes_from_domain_notes():
    lib = activity_library()
    # Klute KC-135 values as listed in domain.md
    expected = {
        "foot-pushoff-max": 534.0,
        "foot-pushoff-mean": 311.0,
        "hand-pushoff-max": 267.0,
        "hand-pushoff-mean": 151.0,
    }
    for name, f0 in expected.items():
        assert lib[name].f0 == f0
        assert "Klute" in lib[name].source and "assumed" in lib[name].durations
        h = parse_force_spec(name)
        assert h.force.max() == f0 and h.impulse() == pytest.approx(0.0, abs=1e-12)
    assert lib["report-pushoff"].f0 == pytest.approx(REPORT_F0_N, rel=1e-15)
    assert parse_force_spec("hand-pushoff-mean:t1=0.3s,t14=10.8s").timepts[1] == 0.3
    assert set(expected) <= set(known_force_specs())
