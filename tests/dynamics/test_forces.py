"""Tests of microg.dynamics.forces: Eq. 2.16, piecewise-linear histories, CSV files, specs, library.

References: the report's Eq. 2.16 written out independently below; np.interp for linear
interpolation; the magnitudes Klute measured on the KC-135 ("Pilot Investigation: Nominal
Crew Induced Forces in Zero-G", SAE).
"""

from __future__ import annotations

import json
from pathlib import Path

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
        ("time [s], force [m]\n0, 0\n1, 1\n", 1, "not a unit of force"),
        ("time [s], force\n0, 0\n1, 1\n", 1, "no unit"),
        ("time [s], force [N], colour\n0, 0, red\n", 1, "not a known column"),
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


def test_library_magnitudes_are_klutes():
    lib = activity_library()
    # Klute's KC-135 values: foot push-off max 534 N, mean 311 N; hand 267 N, 151 N
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


# ------------------------------------------------------------------------------ the CSV reader


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        ("time [s],force [N]\n0,0\n1,caf\xe9\n".encode("latin-1"), "not UTF-8 text (byte"),
        ("time [s],force [N]\n0,0\n1,1\n".encode("utf-16"), "UTF-16"),
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "binary content"),
    ],
)
def test_csv_latin1_utf16_binary_is_one_line(tmp_path, content, needle):
    p = tmp_path / "f.csv"
    p.write_bytes(content)
    with pytest.raises(InputError) as err:
        from_csv(p)
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_csv_utf8_bom_is_accepted(tmp_path):
    p = tmp_path / "f.csv"
    p.write_bytes(b"\xef\xbb\xbftime [s],force [N]\n0,0\n1,2\n")
    assert np.array_equal(from_csv(p).force, [0.0, 2.0])


def test_csv_10_mb_cell(tmp_path):
    # was a _csv.Error traceback
    p = tmp_path / "f.csv"
    p.write_text("time [s],force [N]\n0,0\n1," + "9" * 10_000_000 + "\n")
    with pytest.raises(InputError, match="line 3 is longer than 4096 characters"):
        from_csv(p)


def test_proc_self_environ_is_not_echoed(tmp_path, monkeypatch):
    # `--force /proc/self/environ` printed the first line of the environment
    monkeypatch.setenv("MICROG_TEST_SECRET", "hunter2-do-not-print")
    for spec in ("/proc/self/environ",):
        with pytest.raises(InputError) as err:
            parse_force_spec(spec)
        assert "hunter2" not in str(err.value) and "MICROG_TEST_SECRET" not in str(err.value)
    # a text file of secrets given by mistake: no cell is quoted
    p = tmp_path / "secrets.csv"
    p.write_text("API_KEY=hunter2-do-not-print\nTOKEN=abc\n")
    with pytest.raises(InputError) as err:
        from_csv(p)
    assert "hunter2" not in str(err.value) and "not a known column" in str(err.value)
    p.write_text("time [s],force [hunter2]\n0,0\n1,hunter2\n")
    with pytest.raises(InputError) as err:
        from_csv(p)
    assert "hunter2" not in str(err.value)


@pytest.mark.parametrize("value", ["1.7e308", "-1.7e308", "1e400", "inf", "nan", "1_0", "\u0663"])
def test_csv_non_finite_or_huge_value_names_its_line(tmp_path, value):
    # +/-1.7e308 ended in a ValueError from arange; "1_0" and Arabic digits are not plain
    p = tmp_path / "f.csv"
    p.write_text(f"time [s],force [N]\n0,0\n1,0\n2,{value}\n3,0\n")
    with pytest.raises(InputError) as err:
        from_csv(p)
    assert "line 4" in str(err.value) and "force" in str(err.value)


@pytest.mark.slow  # about 8 s, most of it writing the file (run in CI too)
def test_csv_a_million_rows_vectorised_and_bad_row_found(tmp_path):
    # the 1e6-row reproduction (more than 60 s before); read vectorised (measured: about
    # 1.5 s for 1e6 rows of two columns, see the report).  Checked against numpy's own parse.
    n = 1_000_000
    t = np.arange(n) * 1e-3
    f = np.round(100 * np.sin(t), 6)
    body = "\n".join(f"{a:.3f},{b:.6f}" for a, b in zip(t, f, strict=True))
    p = tmp_path / "big.csv"
    p.write_text("time [ms],force [kN]\n" + body + "\n")
    h = from_csv(p)
    assert h.timepts.size == n
    np.testing.assert_allclose(h.timepts, np.round(t, 3) * 1e-3, rtol=1e-15, atol=0)
    np.testing.assert_allclose(h.force, f * 1e3, rtol=1e-15, atol=0)  # kN -> N, exact x1000
    bad = body.split("\n")
    bad[765_432] = "765.432,abc"
    p.write_text("time [ms],force [kN]\n" + "\n".join(bad) + "\n")
    with pytest.raises(InputError, match="line 765434: force is not a number"):
        from_csv(p)


def test_csv_unit_suffix_after_underscore(tmp_path):
    # time_s,force_N (and time_ms,force_lbf)
    p = write(tmp_path, "time_s,force_N\n0,0\n1,5\n")
    assert np.array_equal(from_csv(p).force, [0.0, 5.0])
    p = write(tmp_path, "time_ms,force_lbf\n0,0\n500,2\n")
    h = from_csv(p)
    assert h.timepts[1] == 0.5 and h.force[1] == pytest.approx(2 * LBF, rel=1e-15)


def test_csv_three_force_components_give_a_varying_direction(tmp_path):
    # t [s],Fx [N],Fy [N],Fz [N]
    p = write(tmp_path, "t [s],Fx [N],Fy [N],Fz [N]\n0,0,0,0\n1,3,4,0\n2,0,0,5\n3,0,0,0\n")
    h = from_csv(p)
    assert h.is_vector and h.direction is None
    expected = np.array([[0, 3, 0, 0], [0, 4, 0, 0], [0, 0, 5, 0]], float)
    assert np.array_equal(h.components(), expected)
    assert np.array_equal(h.components(np.array([1.0, 0, 0])), expected)  # its own wins
    assert np.allclose(h.force, [0, 5, 5, 0])  # magnitudes
    # linear in each component between breakpoints: halfway from (3,4,0) to (0,0,5)
    np.testing.assert_allclose(h.at(1.5), [1.5, 2.0, 2.5], rtol=0, atol=1e-15)
    np.testing.assert_allclose(h.at(np.array([-1.0, 9.0])), [[0, 0], [0, 0], [0, 0]])
    # impulse vector by trapezoids: x 3, y 4, z 5 (N s); its magnitude
    assert h.impulse() == pytest.approx(np.sqrt(3.0**2 + 4.0**2 + 5.0**2), rel=1e-15)


def test_csv_parallel_components_become_scalar_with_direction(tmp_path):
    p = write(tmp_path, "time [s],fx [lbf],fy [lbf],fz [lbf]\n0,0,0,0\n1,0,-2,0\n2,0,1,0\n")
    h = from_csv(p)
    assert not h.is_vector and np.array_equal(h.direction, [0, -1, 0])
    np.testing.assert_allclose(h.force, [0, 2 * LBF, -LBF], rtol=1e-15)
    np.testing.assert_allclose(h.components(), [[0, 0, 0], [0, -2 * LBF, LBF], [0, 0, 0]])


@pytest.mark.parametrize(
    ("header", "needle"),
    [
        ("time [s],fx [N],fy [N]", "missing column(s) fz"),
        ("time [s],force [N],fx [N],fy [N],fz [N]", "either force or fx"),
        ("time [s],fx [N],fy [N],fz [N],direction", "direction column goes with force"),
    ],
)
def test_csv_component_header_errors(tmp_path, header, needle):
    p = write(tmp_path, header + "\n0,0,0,0,0\n")
    with pytest.raises(InputError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        from_csv(p)


def test_components_of_a_scalar_force():
    f = crew_pushoff()
    with pytest.raises(InputError, match="no direction"):
        f.components()
    c = f.components(np.array([0.0, 0.0, 2.0]))
    assert np.array_equal(c, np.outer([0, 0, 1], f.force))
    g = f.with_direction(np.array([0.0, 3.0, 4.0]))
    np.testing.assert_allclose(
        g.components(np.array([1.0, 0, 0])), np.outer([0, 0.6, 0.8], f.force)
    )


@pytest.mark.parametrize(
    ("spec", "needle"),
    [
        ("crew-pushoff:f0=40lbf,f0=50lbf", "f0 is given twice"),  # kept 50 lbf silently
        ("crew-pushoff:f0=2**5000 lbf", "only one number"),  # a traceback
        ("crew-pushoff:f0=9**9**9 lbf", "only one number"),  # a hang
        ("crew-pushoff:f0=lbf", "has a unit but no number"),  # meant 1 lbf
        ("crew-pushoff:f0=1e300 lbf", "beyond the physical limit"),  # ValueError in plotting
        ("crew-pushoff:f0=-5 lbf", "must be > 0"),
        ("crew-pushoff:f0=40lbf,", "empty parameter"),
        ("crew-pushoff:t1=1,5 s", "decimal comma"),
        ("crew-pushoff:g=3 N", "cannot read parameter"),
        ("crew-pushoff:t14=2e7 s", "beyond the physical limit"),
        ("a" * 5000, "longer than"),
        ("x\x00y.csv", "NUL"),
    ],
)
def test_force_spec_errors(spec, needle):
    with pytest.raises(InputError) as err:
        parse_force_spec(spec)
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_force_history_limits():
    with pytest.raises(InputError, match="beyond the limit of 1e\\+07 N"):
        piecewise_linear([0, 1], [0, 1e300])
    with pytest.raises(InputError, match="beyond the limit of 1e\\+07 s"):
        piecewise_linear([0, 1.7e308], [0, 1])


def test_csv_value_overflowing_in_si_names_its_line(tmp_path):
    # 1.7e308 kN is a finite number whose SI value overflows (no RuntimeWarning)
    p = write(tmp_path, "time [h],fx [kN],fy [kN],fz [kN]\n0,0,0,1.7e308\n1,0,0,0\n")
    with pytest.raises(InputError, match="line 2: force is beyond the limit"):
        from_csv(p)


_INPUTS = Path(__file__).parents[1] / "data" / "inputs"
_EXPECTED = json.loads((_INPUTS / "expected.json").read_text())


@pytest.mark.parametrize("name", sorted(n for n in _EXPECTED if n.endswith(".csv")))
def test_reproduction_force_files(name):
    # small files reproducing defects once found (the message each must give)
    path = _INPUTS / name
    if not _EXPECTED[name]:
        h = parse_force_spec(str(path))
        assert h.timepts.size >= 3 and np.all(np.isfinite(h.components(np.array([1.0, 0, 0]))))
        return
    with pytest.raises(InputError) as err:
        parse_force_spec(str(path))
    msg = str(err.value)
    assert _EXPECTED[name] in msg and "\n" not in msg and "do-not-print" not in msg


def test_csv_header_unit_9_pow_9_pow_9(tmp_path):
    # the header unit "9**9**9 s" hung every quantity reader
    p = write(tmp_path, "time [9**9**9 s],force [N]\n0,0\n1,1\n")
    with pytest.raises(InputError, match="line 1: the unit of the time column is not a unit"):
        from_csv(p)


@pytest.mark.parametrize("gap", ["\n", "   \n", "\t\n", "# c\n", "\n\n"])
def test_csv_blank_and_comment_lines_anywhere(tmp_path, gap):
    p = write(tmp_path, f"time [s],force [N]\n{gap}0,0\n{gap}1,2\n {gap}2,0\n")
    h = from_csv(p)
    assert np.array_equal(h.timepts, [0, 1, 2]) and np.array_equal(h.force, [0, 2, 0])


def test_breakpoints_leave_out_rows_inside_a_constant_piece():
    # a push, a long run of zeros (sampled rows), a jump and a hold: only the rows inside the
    # runs of equal values go; the jump at t = 5 (a repeated time) and both ends stay
    t = np.r_[0.0, 0.5, 1.0, np.linspace(1.1, 5.0, 40), 5.0, 5.5, 6.0, 7.0]
    f = np.r_[0.0, 20.0, 0.0, np.zeros(40), 3.0, 3.0, 3.0, 3.0]
    h = ForceHistory(t, f)
    tb, fb = h.breakpoints
    np.testing.assert_array_equal(tb, [0.0, 0.5, 1.0, 5.0, 5.0, 7.0])
    np.testing.assert_array_equal(fb, [0.0, 20.0, 0.0, 0.0, 3.0, 3.0])
    # the same function everywhere, bit for bit on a dense grid: each piece that remains is
    # the same line through the same two end values
    u = np.linspace(-1.0, 8.0, 9001)
    np.testing.assert_array_equal(ForceHistory(tb, fb).at(u), h.at(u))
    # nothing to leave out: the arrays themselves
    g = crew_pushoff(REPORT_F0_N, 1.0, 5.0, 6.0)
    assert g.breakpoints[0] is g.timepts


def test_breakpoints_of_a_vector_history_need_every_component_equal():
    t = np.arange(5.0)
    v = np.array([[0.0, 1.0, 1.0, 1.0, 0.0], [0.0, 0.0, 0.0, 2.0, 2.0], [0.0, 0.0, 0.0, 0.0, 0.0]])
    h = ForceHistory.from_vectors(t, v)
    tb, vb = h.breakpoints
    # x is constant over t = 1..3 but y changes at 2..3: every row stays
    np.testing.assert_array_equal(tb, t)
    np.testing.assert_array_equal(vb, v)


def test_crew_force_keeps_the_pushoff_closed_form():
    # locate and optimize read analyze's force grammar; the push-off stays a CrewPushoff
    # (its exact [A]max), parameters from the spec, the rest the report's (25 lbf, 1, 13, 14 s)
    from microg.dynamics.crew import CrewPushoff
    from microg.dynamics.forces import ForceHistory, crew_force

    f = crew_force("crew-pushoff:f0=40lbf,t1=0.5s")
    # 1 lbf = 4.4482216152605 N exactly (NIST SP 811)
    assert f == CrewPushoff(40 * 4.4482216152605, 0.5, 13.0, 14.0)
    assert crew_force(None) == crew_force("crew-pushoff") == CrewPushoff(25 * 4.4482216152605)
    assert crew_force("crew-pushoff:f0=100", bare_units={"force": "N"}).f0 == 100.0
    assert isinstance(crew_force("foot-pushoff-max"), ForceHistory)
    with pytest.raises(InputError) as exc:
        crew_force("crew-pushoff:t14=12s", where="force")
    assert exc.value.where.startswith("force crew-pushoff:t14=12s: t14")
