"""Free-free modes (Eqs. 2.9-2.12): rigid-body modes exact, shapes mass-orthonormal."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.linalg import eigh

from microg.dynamics.dense import solve_dense
from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.toml import load_station
from microg.structure.ritz import build_ritz


def _chain(masses: np.ndarray, springs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A free-free spring-mass chain: one rigid mode, the rest elastic."""
    n = masses.size
    k = np.zeros((n, n))
    for i, s in enumerate(springs):
        k[i : i + 2, i : i + 2] += s * np.array([[1, -1], [-1, 1]])
    return np.diag(masses), k


@given(
    m=st.lists(st.floats(0.1, 100.0), min_size=3, max_size=9),
    seed=st.integers(0, 2**31 - 1),
)
@settings(max_examples=50, deadline=None)
def test_chain_rigid_mode_exact_and_orthonormal(m: list[float], seed: int) -> None:
    rng = np.random.default_rng(seed)
    mass, stiff = _chain(np.array(m), rng.uniform(1.0, 1e4, len(m) - 1))
    omega, phi, rigid = solve_dense(mass, stiff, np.ones((len(m), 1)))
    assert rigid.sum() == 1 and omega[0] == 0.0 and rigid[0]  # exactly zero, not 1e-8
    # mass-orthonormality phi^T M phi = I (Eq. 2.12a with unit modal masses), to rounding
    assert np.allclose(phi.T @ mass @ phi, np.eye(len(m)), atol=1e-10)
    # K-orthogonality and Eq. 2.12b
    assert np.allclose(phi.T @ stiff @ phi, np.diag(omega**2), atol=1e-9 * omega.max() ** 2)
    # reference: scipy.linalg.eigh on the same pencil for the elastic frequencies
    lam = eigh(stiff, mass, eigvals_only=True)
    assert np.allclose(omega[1:] ** 2, lam[1:], rtol=1e-9)


def test_rigid_detected_without_candidates() -> None:
    mass, stiff = _chain(np.array([1.0, 2.0, 3.0]), np.array([10.0, 20.0]))
    omega, _, rigid = solve_dense(mass, stiff)
    assert omega[0] == 0.0 and rigid.tolist() == [True, False, False]


def test_massless_unrestrained_coordinate_is_a_mechanism() -> None:
    # coordinate 2 has neither mass nor stiffness: no finite mode, a mechanism (refused);
    # with stiffness it is condensed: one mode, omega^2 = k1 k2 / (k1 + k2) / m
    with pytest.raises(InputError, match="mechanism"):
        solve_dense(np.diag([1.0, 0.0]), np.diag([1.0, 0.0]))
    k = np.array([[3.0, -2.0], [-2.0, 2.0]])  # ground 1 N/m, spring 2 N/m to a massless node
    sol = solve_dense(np.diag([4.0, 0.0]), k)
    assert sol.omega.size == 1  # series springs k = 1: reference by hand
    assert sol.omega[0] == pytest.approx(np.sqrt(1.0 / 4.0), rel=1e-13)


def test_ioc_ritz_modes_effective_mass_sums_to_total() -> None:
    # the translation's effective masses over all modes sum to the total mass (completeness)
    st_ = load_station("ioc")
    s = build_ritz(st_, "xz", 3, gravity_gradient=False)
    modes = solve_modes(s)
    assert modes.n_rigid == 2  # translation and rotation: gravity gradient off
    assert np.all(modes.omega[modes.rigid] == 0.0)
    assert modes.effective_mass["x"].sum() == pytest.approx(s.total_mass, rel=1e-10)
    d = modes.to_dict()
    assert d["method"] == "ritz" and len(d["modes"]) == s.n_dof
    assert [m["omega"] for m in d["modes"]] == sorted(m["omega"] for m in d["modes"])


def test_ioc_gravity_gradient_leaves_one_rigid_mode() -> None:
    s = build_ritz(load_station("ioc"), "xz", 1, gravity_gradient=True)
    modes = solve_modes(s)
    assert modes.n_rigid == 1
    assert 1e-3 < modes.omega[1] < 3e-3  # the librational mode, ~sqrt(3) w0


@pytest.mark.parametrize("k", [1.0, 1e4, 1e5])
def test_soft_restraint_is_not_called_rigid(k: float) -> None:
    # a two-mass chain with a tiny ground spring (gravity-gradient-like, 3.6e-6 N/m): the
    # soft mode is sqrt(k_g / (m1 + m2)) to O(k_g/k); a whole-matrix norm test would call it
    # rigid (exactly 0) once k_g/k < 1e-9. The row-wise test resolves restraints down to
    # RIGID_TOL = 1e-12 of a row's stiffness (k_g/2k = 1.8e-11 at k = 1e5); exact rigid
    # vectors of the frame models score ~1e-16. Reference: the two-mass closed form
    kg = 3.6e-6
    stiff = np.array([[k + kg, -k], [-k, k]])
    mass = np.eye(2)
    # storing k + kg keeps kg only to eps k / kg (6e-6 at k = 1e5): no solver of the stored
    # matrix can do better, so the frequency is checked to that (half of it in omega)
    rtol = max(1e-12, 2.0 * np.finfo(float).eps * k / kg)
    for cand in (None, np.ones((2, 1))):
        omega, _, rigid = solve_dense(mass, stiff, cand)
        assert not rigid.any()
        # reference: the 2x2 closed form, the small root det / (larger root), no cancellation
        lam = k * kg / (0.5 * (2 * k + kg + np.hypot(2 * k, kg)))
        assert omega[0] == pytest.approx(np.sqrt(lam), rel=rtol)


def test_many_ritz_functions_keep_the_libration_mode() -> None:
    # gravity gradient restrains the rotation coordinate; with 16 functions per beam the
    # elastic stiffness is ~1e12 times larger, and the libration mode must still come out
    s = build_ritz(load_station("ioc"), "xz", 16, gravity_gradient=True)
    modes = solve_modes(s)
    assert modes.n_rigid == 1
    assert modes.omega[1] == pytest.approx(1.911e-3, rel=1e-3)  # Eq. 2.30 with the model's I


def test_modes_api_elastic_fraction_dict_xarray_plot() -> None:
    # one "elastic" rule (not rigid, not unstable), effective-mass fractions of r^T M r that
    # sum to 1 over a complete set (completeness), to_dict keys, to_xarray dims and units
    s = build_ritz(load_station("ioc"), "xz", 3, gravity_gradient=True)
    modes = solve_modes(s)
    assert modes.elastic.tolist() == (~modes.rigid & ~modes.unstable).tolist()
    assert modes.elastic[1] and modes.omega[1] < 3e-3  # the libration counts as elastic
    frac = modes.effective_mass_fraction
    assert frac["x"].sum() == pytest.approx(1.0, rel=1e-10)
    d = modes.to_dict()
    keys = {"omega", "freq_hz", "rigid", "modal_mass", "effective_mass", "unstable"}
    assert keys | {"growth_rate_rad_s", "effective_mass_fraction", "elastic"} <= set(d["modes"][0])
    ds = modes.to_xarray()
    assert ds["phi"].dims == ("dof", "mode") and ds["omega"].attrs["units"] == "rad/s"
    assert ds.sizes["mode"] == modes.n_modes and ds["modal_mass"].attrs["units"] == "kg"
    from matplotlib.figure import Figure

    fig = modes.plot()
    assert isinstance(fig, Figure) and fig.axes[0].get_yscale() == "log"


def test_rounding_note_only_where_the_assembled_stiffness_bounds_a_frequency_loosely():
    # the note is the first-order bound eps |phi|^T |K| |phi| / (2 lambda) of a frequency
    # (see microg.dynamics.modes._rounding_note); on an ordinary deck and on the report's
    # Ritz model it is below 1e-4 for every mode, so nothing is said (the slender-bar deck
    # that needs it is tests/validation/test_nastran_decks_real.py's cant_beam)
    from pathlib import Path

    from microg.models.bdf import load_bdf
    from microg.structure.discretize import discretize

    deck = Path(__file__).resolve().parents[1] / "data" / "nastran" / "rdop2gpwg_1.dat"
    for s in (
        discretize(load_bdf(deck, units="in, lbf, s")),
        discretize(load_station("ioc"), "ritz"),
    ):
        md = solve_modes(s, 12)
        assert not any("rounding bounds" in n for n in md.notes)
