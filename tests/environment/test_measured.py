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


def test_errors_name_file_and_line(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="unknown column") as e:
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
