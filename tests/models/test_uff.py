"""UFF 15/2411 + 55 + 164 read/write, 58 time histories, IOC FE export and read-back."""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.forces import ForceHistory
from microg.dynamics.modes import solve_modes
from microg.dynamics.response import generalized_force_vector, response_at_points
from microg.errors import InputError
from microg.models.load import load_model
from microg.models.modal import build_modal_model, parse_units
from microg.models.toml import load_station
from microg.models.uff import modal_model_from_uff, write_uff_modes, write_uff_time
from microg.structure.discretize import discretize
from microg.structure.modal import modal_structure

pytestmark = pytest.mark.nastran


@pytest.fixture(scope="module")
def ioc():
    s = discretize(load_station("ioc"))
    return s, solve_modes(s, 30)


@pytest.fixture(scope="module")
def model(ioc):
    s, md = ioc
    n = len(s.meta["node_names"])
    samp = s.samples
    phi = np.concatenate(
        [samp.displacement(md.phi)[:n], md.phi[np.asarray(samp.rot_index)[:n]]], axis=1
    )
    return build_modal_model(
        name="ioc",
        grid_ids=np.arange(1, n + 1) * 3,
        xyz_m=np.asarray(samp.position)[:n],
        freq_hz_signed=md.freq_hz,
        phi=phi,
        units=parse_units("m, N, s"),
        source="ioc-fe",
        zeta=np.where(md.rigid, 0.0, 0.01)[:30],
    )


def test_round_trip_double_equals_original(model, tmp_path):
    f = write_uff_modes(model, tmp_path / "m.unv", precision="double")
    back = modal_model_from_uff(f)
    assert np.array_equal(back.grid_ids, model.grid_ids)
    # E25.16 carries 17 significant digits: equal to rounding (the contract asks 1e-12)
    assert np.max(np.abs(back.phi - model.phi)) <= 1e-12 * np.max(np.abs(model.phi))
    assert np.max(np.abs(back.omega - model.omega)) <= 1e-12 * model.omega.max()
    assert np.max(np.abs(back.xyz_m - model.xyz_m)) <= 1e-12 * np.abs(model.xyz_m).max()
    assert np.allclose(back.zeta, model.zeta, rtol=1e-12, atol=0)
    assert back.replaced_rigid.count == 6 and back.replaced_rigid.max_file_freq_hz == 0.0


def test_single_precision_is_the_standard_and_pyuff_reads_it(model, tmp_path):
    pyuff = pytest.importorskip("pyuff")
    f = write_uff_modes(model, tmp_path / "m.unv")
    sets = pyuff.UFF(str(f)).read_sets()
    modes = [d for d in sets if d["type"] == 55]
    nodes = [d for d in sets if d["type"] == 15][0]
    assert len(modes) == 30 and [d for d in sets if d["type"] == 164]
    # independent reader (pyuff, fixed 13-column fields): 6 significant digits
    assert np.allclose(nodes["x"], model.xyz_m[:, 0], rtol=5e-6, atol=1e-9)
    j = 10
    got = np.column_stack([modes[j][f"r{k}"] for k in range(1, 7)])
    ref = model.phi[:, :, j]
    assert np.max(np.abs(got - ref)) <= 5e-6 * np.max(np.abs(ref))
    assert modes[j]["freq"] == pytest.approx(model.freq_hz[j], rel=5e-6)
    back = modal_model_from_uff(f)
    assert np.max(np.abs(back.phi - model.phi)) <= 5e-6 * np.max(np.abs(model.phi))


def test_ioc_fe_modes_export_and_analysis(ioc, tmp_path):
    """FE modes of IOC -> UFF -> ModalModel: the response at named points is the FE's."""
    s, md = ioc
    t = np.arange(0.0, 30.0, 0.01)
    f = ForceHistory(np.array([0.0, 0.5, 1.0, 1.5]), np.array([0.0, 100.0, 100.0, 0.0]))

    def resp(struct, modes):
        b = generalized_force_vector(struct.point("crew").translation, np.array([1.0, 0.0, 0.5]))
        z = np.where(modes.rigid, 0.0, 0.005)
        maps = {n: struct.point(n).translation for n in ("lab", "keel-tip")}
        return response_at_points(modes.omega, z, modes.phi, maps, f, b, t)

    ref = resp(s, md)
    for precision, tol in (("double", 1e-10), ("single", 5e-5)):
        uf = write_uff_modes(
            md,
            tmp_path / f"{precision}.unv",
            precision=precision,
            points_path=tmp_path / f"{precision}.toml",
        )
        mm = load_model(uf, points=tmp_path / f"{precision}.toml")
        st = modal_structure(mm, ["crew", "lab", "keel-tip"], samples=False)
        got = resp(st, solve_modes(st))
        for name in ("lab", "keel-tip"):
            a, b = got[name].acceleration, ref[name].acceleration
            # double: rounding; single: 6 printed digits per shape value (5e-6 each) summed
            # over 30 modes and two shape factors (force and observation)
            assert np.max(np.abs(a - b)) <= tol * np.max(np.abs(b)), (precision, name)


def test_time_histories_58_read_by_pyuff(ioc, tmp_path):
    pyuff = pytest.importorskip("pyuff")
    from microg.dynamics.response import PointResponse

    t = np.arange(0.0, 1.0, 0.01)
    acc = np.vstack([np.sin(t), np.cos(t), t**2])
    r = {"lab": PointResponse("lab", t, acc * 0, acc * 0, acc)}
    f = write_uff_time(r, tmp_path / "a.unv", precision="double")
    sets = [d for d in pyuff.UFF(str(f)).read_sets() if d["type"] == 58]
    assert len(sets) == 3
    for k in range(3):
        # independent reader; E20.12: 13 significant digits
        assert np.allclose(sets[k]["data"], acc[k], rtol=1e-11, atol=1e-13)
        assert np.allclose(sets[k]["x"], t, atol=1e-12)


def test_bad_uff_files(tmp_path, model):
    f = write_uff_modes(model, tmp_path / "m.unv")
    text = f.read_text()
    cut = tmp_path / "cut.unv"
    cut.write_text(text[: len(text) // 2].rsplit("\n", 3)[0] + "\n")
    with pytest.raises(InputError) as exc:
        modal_model_from_uff(cut)
    assert exc.value.where == str(cut)
    no164 = tmp_path / "no164.unv"
    no164.write_text(text.split("\n", 6)[-1])  # drop the 164 block (6 lines)
    with pytest.raises(InputError, match="no units"):
        modal_model_from_uff(no164)
    assert modal_model_from_uff(no164, units=parse_units("m, N, s")).n_modes == 30


@pytest.mark.parametrize(
    "units, wtmass, message",
    [
        ("m, N, ms", None, "declared time unit disagrees with the file's dataset 164"),
        ("in, lbf, s", None, "declared length unit disagrees"),
        ("m, N, s", 1.0, "applies to NASTRAN files only"),
    ],
)
def test_declarations_contradicting_a_uff_file_are_errors(model, tmp_path, units, wtmass, message):
    # the file's dataset 164 states SI (write_uff_modes); UFF has no WTMASS, and 164 has no
    # time factor (seconds): any other declaration contradicts the file

    f = write_uff_modes(model, tmp_path / "m.unv")
    with pytest.raises(InputError, match=message):
        load_model(f, units=units, wtmass=wtmass)
