"""CSV readers of measured acceleration (microg.environment.measured): header forms and units.

Reference: the unit definitions (1 g = 9.80665 m/s^2, 1 ug = 1e-6 g, 1 ft = 0.3048 m) applied
by hand to the numbers written into the file.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from microg.environment.measured import read_accel_csv, read_measured
from microg.errors import InputError
from microg.units import G0


def _write(path: Path, header: str, rows: int = 40, comment: str = "") -> Path:
    t = np.arange(rows) * 0.01
    body = "\n".join(f"{ti:.4f},{i},{-i}" for i, ti in enumerate(t))
    path.write_text(comment + header + "\n" + body + "\n")
    return path


@pytest.mark.parametrize(
    ("header", "fx", "fz"),
    [
        ("time [s], x [m/s^2], z [m/s^2]", 1.0, 1.0),
        ("time (s), x (g), z (ug)", G0, 1e-6 * G0),
        ("time_s, x_ug, z_mg", 1e-6 * G0, 1e-3 * G0),
        ("t [ms], ax [ft/s^2], az [m/s2]", 0.3048, 1.0),
    ],
)
def test_header_forms_and_units(tmp_path: Path, header: str, fx: float, fz: float) -> None:
    rec = read_accel_csv(_write(tmp_path / "a.csv", header))
    assert rec.axes == ("x", "z")
    i = np.arange(40)
    assert np.allclose(rec.accel[0], i * fx, rtol=1e-14)  # unit factors applied by hand
    assert np.allclose(rec.accel[1], -i * fz, rtol=1e-14)
    dt = 0.01 * (1e-3 if "[ms]" in header else 1.0)
    assert rec.sample_rate_hz == pytest.approx(1 / dt, rel=1e-9)


def test_comments_name_sensor_and_cutoff(tmp_path: Path) -> None:
    p = _write(
        tmp_path / "b.csv", "time [s], x [g], y [g]", comment="# sensor: es05\n# cutoff: 6 Hz\n"
    )
    rec = read_measured(p)
    assert rec.sensor == "es05" and rec.cutoff_hz == 6.0 and rec.key == "es05"
    p = _write(tmp_path / "c.csv", "time [s], x [g], y [g]")
    assert read_measured(p).key == "sensor"


def test_an_unknown_column_is_not_quoted(tmp_path: Path) -> None:
    # a file named by mistake (an environment dump, a password file) must not leak through
    # the error: the column is named by its position only
    with pytest.raises(InputError) as e:
        read_accel_csv(_write(tmp_path / "env.csv", "SECRET_TOKEN=abc123, x [g]"))
    assert "SECRET" not in str(e.value) and "abc123" not in str(e.value)
    assert e.value.where.endswith("env.csv: line 1, column 1")


def test_errors_name_file_and_line(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not a known column") as e:
        read_accel_csv(_write(tmp_path / "d.csv", "time [s], w [g], y [g]"))
    assert e.value.where.endswith("d.csv: line 1, column 2")
    with pytest.raises(InputError, match="not an acceleration|acceleration"):
        read_accel_csv(_write(tmp_path / "e.csv", "time [s], x [N], y [g]"))
    p = tmp_path / "f.csv"
    p.write_text(
        "time [s], x [g]\n0,1\n0.01,2,3\n" + "".join(f"{i / 100},0\n" for i in range(2, 30))
    )
    with pytest.raises(InputError, match="2 cells|3 cells") as e:
        read_accel_csv(p)
    assert e.value.where.endswith("f.csv: line 3")


# --------------------------------------------------------------------------- UFF 58


def _accel(n: int = 600, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * 0.01
    return t, np.random.default_rng(seed).standard_normal((3, n)) * 1e-4


def _pyuff_58(node: int, direction: int, y, *, x=None, t0=0.0, dt=0.01, even=1, **kw) -> dict:
    """A dataset 58 as pyuff (an independent UFF writer) writes it."""
    import pyuff

    n = len(y)
    fields = dict(
        binary=0,
        id1=kw.pop("id1", "NONE"),
        id3=kw.pop("id3", "NONE"),
        func_type=kw.pop("func_type", 1),
        rsp_ent_name=kw.pop("entity", "TEST"),
        rsp_node=node,
        rsp_dir=direction,
        ref_ent_name="NONE",
        ref_node=0,
        ref_dir=0,
        abscissa_spacing=even,
        abscissa_spec_data_type=17,
        ordinate_spec_data_type=kw.pop("spec", 12),
        ordinate_axis_units_lab=kw.pop("unit", "NONE"),
        orddenom_spec_data_type=0,
        z_axis_spec_data_type=0,
        data=np.asarray(y),
        x=t0 + np.arange(n) * dt if x is None else np.asarray(x),
    )
    fields.update(kw)
    return pyuff.prepare_58(**fields)


def _pyuff_file(path: Path, sets: list[dict], *, inch: bool = False) -> Path:
    import pyuff

    u = pyuff.UFF(str(path))
    if inch:  # SI = file value / factor: 1 m = 39.37... in, 1 N = 0.2248... lbf
        u.write_sets(
            pyuff.prepare_164(
                units_code=2,
                units_description="in lbf s",
                temp_mode=1,
                length=1 / 0.0254,
                force=1 / 4.4482216152605,
                temp=1.0,
                temp_offset=273.15,
            ),
            mode="overwrite",
        )
    u.write_sets(sets, mode="add" if inch else "overwrite")
    return path


def test_uff58_from_microg_writer_groups_nodes(tmp_path: Path) -> None:
    from microg.dynamics.response import PointResponse
    from microg.environment.measured import read_measured_all, read_uff58
    from microg.models.uff import write_uff_time

    t, a = _accel()
    _, b = _accel(seed=1)
    resp = {n: PointResponse(n, t, 0 * v, 0 * v, v) for n, v in (("lab", a), ("node-2", b))}
    for precision, rtol in (("double", 5e-12), ("single", 5e-6)):
        f = write_uff_time(resp, tmp_path / f"{precision}.unv", precision=precision)
        recs = read_uff58(f)
        assert [r.sensor for r in recs] == ["lab", "node-2"]  # ID line 1 names the sensor
        for r, ref in zip(recs, (a, b), strict=True):
            assert r.format == "uff58" and r.axes == ("x", "y", "z")
            # reference: the arrays written; E20.12 keeps 13 digits, E13.5 6
            np.testing.assert_allclose(r.accel, ref, rtol=0, atol=rtol * np.abs(ref).max())
            assert r.sample_rate_hz == pytest.approx(100.0, rel=1e-12)
            np.testing.assert_allclose(r.timepts, t, atol=1e-12)
        assert [r.sensor for r in read_measured_all(f)] == ["lab", "node-2"]
    with pytest.raises(InputError, match="holds 2 sensors"):
        read_measured(f)
    assert read_measured(f, sensor="node-2").sensor == "node-2"


def test_uff58_from_pyuff_with_units_and_signs(tmp_path: Path) -> None:
    pytest.importorskip("pyuff")
    from microg.environment.measured import read_uff58

    t, a = _accel()
    # dataset 164 in inches; node 7's x axis recorded as -X; no units labels
    sets = [_pyuff_58(7, d, a[abs(d) - 1] * (1 if d > 0 else -1)) for d in (-1, 2, 3)]
    sets += [_pyuff_58(9, d, 2 * a[d - 1], id1="es05") for d in (3, 1, 2)]
    recs = read_uff58(_pyuff_file(tmp_path / "in.unv", sets, inch=True))
    # sensor names: "ENTITY:NODE" when ID line 1 is NONE, else ID line 1
    assert [r.sensor for r in recs] == ["TEST:7", "es05"]
    # reference: the numbers written, in in/s^2 -> x 0.0254 m/s^2 (dataset 164, length
    # exponent 1), the -X record's sign flipped; pyuff writes %20.11e (12 digits)
    tol = 5e-12 * 0.0254 * np.abs(a).max() * 2
    np.testing.assert_allclose(recs[0].accel, 0.0254 * a, rtol=0, atol=tol)
    np.testing.assert_allclose(recs[1].accel, 0.0254 * 2 * a, rtol=0, atol=tol)
    assert recs[0].metadata["units"] == "dataset 164"


def test_uff58_uneven_abscissa_and_unit_label(tmp_path: Path) -> None:
    pytest.importorskip("pyuff")
    from microg.environment.measured import read_uff58

    t, a = _accel()
    # no dataset 164: the record's own units label (g); uneven x, y pairs on a uniform grid
    sets = [_pyuff_58(1, d, a[d - 1], unit="g", even=0, t0=5.0) for d in (1, 2, 3)]
    (rec,) = read_uff58(_pyuff_file(tmp_path / "g.unv", sets))
    np.testing.assert_allclose(rec.accel, G0 * a, rtol=0, atol=5e-12 * G0 * np.abs(a).max())
    # the abscissa is written E13.5 (6 digits) in uneven records: t0 + i dt to that
    np.testing.assert_allclose(rec.timepts, 5.0 + t, rtol=0, atol=5e-6 * 11.0)
    assert any("uneven abscissa" in w for w in rec.warnings)


@pytest.mark.parametrize(
    ("case", "match"),
    [
        ("gap", "non-uniform abscissa"),
        ("velocity", "the ordinate is velocity, not acceleration"),
        ("missing", "has no z axis"),
        ("twice", "has axis y twice"),
        ("frf", "function type 4"),
        ("rotation", "is a rotation"),
        ("complex", "complex"),
        ("nounits", "no units"),
        ("contradiction", "contradicts dataset 164"),
        ("short", "only 10 samples"),
    ],
)
def test_uff58_bad_input_names_file_and_record(tmp_path: Path, case: str, match: str) -> None:
    pytest.importorskip("pyuff")
    from microg.environment.measured import read_uff58

    t, a = _accel()
    unit = "m/s^2"
    ok = [_pyuff_58(1, d, a[d - 1], unit=unit) for d in (1, 2, 3)]
    inch = False
    sets = list(ok)
    if case == "gap":
        x = t.copy()
        x[300:] += 0.05
        sets[1] = _pyuff_58(1, 2, a[1], unit=unit, even=0, x=x)
    elif case == "velocity":
        sets[1] = _pyuff_58(1, 2, a[1], unit="m/s", spec=11)
    elif case == "missing":
        sets = sets[:2]
    elif case == "twice":
        sets.append(_pyuff_58(1, -2, a[1], unit=unit))
    elif case == "frf":
        sets[1] = _pyuff_58(1, 2, a[1], unit=unit, func_type=4)
    elif case == "rotation":
        sets[1] = _pyuff_58(1, 5, a[1], unit=unit)
    elif case == "complex":
        sets[1] = _pyuff_58(1, 2, a[1] * (1 + 1j), unit=unit)
    elif case == "nounits":
        sets[1] = _pyuff_58(1, 2, a[1])
    elif case == "contradiction":
        inch = True  # dataset 164 in inches, the record labelled m/s^2
    elif case == "short":
        sets[1] = _pyuff_58(1, 2, a[1][:10], unit=unit)
    f = _pyuff_file(tmp_path / f"{case}.unv", sets, inch=inch)
    with pytest.raises(InputError, match=match) as e:
        read_uff58(f)
    k = {"missing": 1, "twice": 4, "contradiction": 1}.get(case, 2)
    assert e.value.where.startswith(f"{f}: dataset 58 #{k} (line "), e.value.where


def test_uff_files_without_time_histories(tmp_path: Path) -> None:
    pytest.importorskip("pyuff")
    import pyuff

    from microg.environment.measured import read_uff58

    p = tmp_path / "bin.unv"  # a binary 58b header line (pyuff binary=1 writes this form)
    p.write_bytes(b"    -1\n    58b     1     2          11        8000     0     0\n\x00\x0a\x01")
    with pytest.raises(InputError, match="line 2: dataset 58b is binary UFF"):
        read_uff58(p)
    q = tmp_path / "nodes.unv"
    pyuff.UFF(str(q)).write_sets(
        pyuff.prepare_15(
            node_nums=[1, 2],
            def_cs=[0, 0],
            disp_cs=[0, 0],
            color=[1, 1],
            x=[0.0, 1.0],
            y=[0.0, 0.0],
            z=[0.0, 0.0],
        ),
        mode="overwrite",
    )
    with pytest.raises(InputError, match=r"no time histories \(dataset 58; datasets present: 15\)"):
        read_uff58(q)
