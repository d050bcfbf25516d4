"""Shell element kernels (MITC4 with QM6 membrane, MITC3 + CST): patch tests, rigid modes.

The patch tests are MacNeal & Harder's ("A proposed standard set of problems to test finite
element accuracy", Finite Elements in Analysis and Design 1 (1985) 3-20, Fig. 2): a
0.24 x 0.12 rectangle with four irregular interior nodes, E = 1e6, nu = 0.25, t = 0.001;
the boundary nodes take the exact field, the interior ones are solved for and must
reproduce it (membrane u = 1e-3 (x + y/2), v = 1e-3 (y + x/2); bending
w = 1e-3 (1 + x + y + x^2 + x y + y^2) / 2, theta_x = dw/dy, theta_y = -dw/dx).
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.modes import solve_modes
from microg.errors import InputError
from microg.models.bdf import load_bdf
from microg.models.graph_model import GraphModel, Node, ShellElement, ShellSection
from microg.structure.elements import rigid_link
from microg.structure.frame import assemble_frame, build_frame
from microg.structure.shells import shell_matrices

E, NU, T = 1.0e6, 0.25, 0.001
G = E / (2 * (1 + NU))
C = E / (1 - NU**2) * np.array([[1, NU, 0], [NU, 1, 0], [0, 0, (1 - NU) / 2]])
SECTION = ShellSection(
    "s", C * T, C * T**3 / 12, 5 / 6 * G * T * np.eye(2), 7.8, 1e-6 * 100 * G * T
)
# MacNeal-Harder patch: corners, then the interior nodes 1-4
XY = np.array(
    [[0, 0], [0.24, 0], [0.24, 0.12], [0, 0.12], [0.04, 0.02], [0.18, 0.03], [0.16, 0.08],
     [0.08, 0.08]]
)  # fmt: skip
QUADS = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7), (4, 5, 6, 7)]
TRIAS = [t for a, b, c, d in QUADS for t in ((a, b, c), (a, c, d))]


def _graph(xyz: np.ndarray, elements: list[tuple[int, ...]]) -> GraphModel:
    nodes = tuple(Node(f"n{i}", np.asarray(p, float)) for i, p in enumerate(xyz))
    shells = tuple(
        ShellElement(f"e{k}", tuple(f"n{i}" for i in e), SECTION) for k, e in enumerate(elements)
    )
    return GraphModel("patch", nodes, shells=shells, mass_formulation="lumped")


def _section_arrays(ne: int) -> tuple[np.ndarray, ...]:
    rep = lambda a: np.repeat(np.asarray(a, float)[None], ne, axis=0)  # noqa: E731
    return (
        rep(SECTION.membrane_N_per_m),
        rep(SECTION.bending_N_m),
        rep(SECTION.shear_N_per_m),
        np.full(ne, SECTION.drilling_N_per_m),
        np.full(ne, SECTION.mass_per_area_kg_per_m2),
    )


def _rotation() -> np.ndarray:
    q, _ = np.linalg.qr(np.random.default_rng(3).normal(size=(3, 3)))
    return q


@pytest.mark.parametrize(
    "corners",
    [
        [[0, 0, 0], [2, 0.1, 0], [1.8, 1.5, 0], [0.2, 1, 0]],  # irregular, flat
        [[0, 0, 0], [2, 0.1, 0.04], [1.8, 1.5, 0], [0.2, 1, 0.04]],  # warped (ratio 0.01)
        [[0, 0, 0], [2, 0.1, 0], [0.5, 1.5, 0]],  # triangle
    ],
)
def test_free_element_has_exactly_six_zero_energy_modes(corners):
    x = np.asarray(corners, float) @ _rotation().T + [3.0, -1.0, 7.0]
    k, m = shell_matrices(x[None], *_section_arrays(1), True, ["e"])
    w = np.linalg.eigvalsh(k[0])
    # round-off sits at 1e-16 of the largest eigenvalue, the smallest deformation (bending,
    # D / (E t) ~ t^2 / 12 ~ 1e-7) at 2e-8 of it: six below 1e-9, then a gap of 1e7 or more
    aw = np.sort(np.abs(w))
    assert np.sum(aw < 1e-9 * w.max()) == 6
    assert aw[6] > 1e6 * aw[5]
    r = rigid_link(x - x.mean(axis=0)).reshape(-1, 6)
    # the six rigid motions cost nothing to round-off
    assert np.abs(k[0] @ r).max() <= 1e-13 * np.abs(k[0]).max()
    # translational mass: rho t times the area, once per direction
    area = 0.5 * np.linalg.norm(np.cross(x[2] - x[0], x[-1] - x[1 if len(x) == 4 else 0]))
    if len(x) == 3:
        area = 0.5 * np.linalg.norm(np.cross(x[1] - x[0], x[2] - x[0]))
    tr = r[:, :3]
    np.testing.assert_allclose(tr.T @ m[0] @ tr, 7.8 * area * np.eye(3), rtol=1e-3)


def _patch(elements: list[tuple[int, ...]], exact: np.ndarray, tilt: bool) -> float:
    """Largest interior error of the patch, relative to the largest exact value."""
    R = _rotation() if tilt else np.eye(3)
    xyz = np.column_stack([XY, np.zeros(len(XY))]) @ R.T
    fm = assemble_frame(_graph(xyz, elements), mass="lumped")
    K = fm.stiffness.toarray()
    u = np.zeros(6 * len(XY))
    for i in range(len(XY)):  # the exact field, local axes -> basic
        u[6 * i : 6 * i + 3] = R @ exact[i, :3]
        u[6 * i + 3 : 6 * i + 6] = R @ exact[i, 3:]
    inner = (6 * np.arange(4, 8)[:, None] + np.arange(6)).ravel()
    outer = np.setdiff1d(np.arange(6 * len(XY)), inner)
    # the exact field is in equilibrium at the interior nodes: their residual force is
    # round-off of the terms that make it up (measured 6e-17 of |K| |u|)
    residual = np.abs(K[inner] @ u).max() / (np.abs(K).max() * np.abs(u).max())
    assert residual < 1e-14
    sol = np.linalg.solve(K[np.ix_(inner, inner)], -K[np.ix_(inner, outer)] @ u[outer])
    return float(np.abs(sol - u[inner]).max() / np.abs(u).max())


@pytest.mark.parametrize("elements", [QUADS, TRIAS], ids=["cquad4", "ctria3"])
@pytest.mark.parametrize("tilt", [False, True], ids=["flat", "tilted"])
def test_membrane_patch_test(elements, tilt):
    x, y = XY[:, 0], XY[:, 1]
    exact = np.zeros((len(XY), 6))
    exact[:, 0] = 1e-3 * (x + y / 2)
    exact[:, 1] = 1e-3 * (y + x / 2)
    # theta_z = omega = (dv/dx - du/dy) / 2 = 0 for this field
    # constant strain reproduced exactly; the solved interior carries the solve's round-off,
    # cond(K_ii) eps = 2.4e8 x 2.2e-16 = 5e-8 at most (measured 4e-10 to 3e-9)
    assert _patch(elements, exact, tilt) < 5e-8


@pytest.mark.parametrize("elements", [QUADS, TRIAS], ids=["cquad4", "ctria3"])
@pytest.mark.parametrize("tilt", [False, True], ids=["flat", "tilted"])
def test_bending_patch_test(elements, tilt):
    x, y = XY[:, 0], XY[:, 1]
    exact = np.zeros((len(XY), 6))
    exact[:, 2] = 1e-3 * (1 + x + y + x**2 + x * y + y**2) / 2
    exact[:, 3] = 1e-3 * (1 + x + 2 * y) / 2  # theta_x = dw/dy
    exact[:, 4] = -1e-3 * (1 + 2 * x + y) / 2  # theta_y = -dw/dx
    # constant curvature, zero transverse shear (the tied shear strains are exact for a
    # quadratic w and linear rotations): reproduced to the solve's round-off
    # (cond(K_ii) eps bounds the solve's error at 5e-8, as for the membrane)
    assert _patch(elements, exact, tilt) < 5e-8


@pytest.mark.parametrize("elements", [QUADS, TRIAS], ids=["cquad4", "ctria3"])
def test_free_mesh_has_six_rigid_modes_and_no_spurious_one(elements):
    xyz = np.column_stack([XY, 0.3 * XY[:, 0] * XY[:, 1]])  # a doubly curved patch
    g = _graph(xyz, elements)
    K = assemble_frame(g).stiffness.toarray()
    w = np.linalg.eigvalsh(K)
    # 6 zero eigenvalues of the assembled stiffness, and nothing near zero beyond them
    assert np.sum(np.abs(w) < 1e-10 * w.max()) == 6
    md = solve_modes(build_frame(g))
    assert md.n_rigid == 6 and np.all(md.omega[:6] == 0.0)
    assert md.omega[6] > 0


def _deck(tmp_path, card: str, extra: str = "") -> str:
    p = tmp_path / "s.bdf"
    p.write_text(
        "BEGIN BULK\nGRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.\nGRID,3,,1.,1.,0.\nGRID,4,,0.,1.,0.\n"
        f"MAT1,1,2.e11,,0.3,8000.\n{extra}{card}\nENDDATA\n"
    )
    return str(p)


@pytest.mark.parametrize(
    ("card", "extra", "says"),
    [
        ("CQUAD4,1,1,1,2,3,4,,0.01", "PSHELL,1,1,0.01,1,,1\n", "ZOFFS"),
        ("CQUAD4,1,1,1,2,3,4", "PSHELL,1,1,0.01,1,,1,,\n,,,2\n", "MID4"),
        ("CQUAD4,1,1,1,2,3,4", "PSHELL,1,1,,1,,1\n", "T must be > 0"),
        ("CQUAD4,1,1,1,2,3,4", "PSHELL,1,1,0.01,-1\n", "plane strain"),
        ("CQUAD4,1,1,1,2,3,4", "PSHELL,1,7,0.01\n", "material 7"),
        ("CQUAD4,1,9,1,2,3,4", "PSHELL,1,1,0.01\n", "property 9"),
        ("CQUAD4,1,1,1,3,2,4", "PSHELL,1,1,0.01,1,,1\n", "no area"),
        ("CQUAD4,1,1,1,2,5,4", "GRID,5,,.2,.2,0.\nPSHELL,1,1,0.01,1\n", "not convex"),
        ("CQUAD4,1,1,1,2,3,4,,\n,,,0.02,0.02,0.02,0.02", "PSHELL,1,1,0.01,1\n", "T1"),
        ("CTRIA3,1,1,1,2,2", "PSHELL,1,1,0.01,1\n", "repeat"),
        ("CQUAD4,1,1,1,2,3,5", "PSHELL,1,1,0.01,1\n", "G4 grid 5"),
    ],
)
def test_bad_shell_cards_are_one_line_errors(tmp_path, card, extra, says):
    with pytest.raises(InputError) as exc:  # the geometry is checked as the model is built
        build_frame(load_bdf(_deck(tmp_path, card, extra), units="m, N, s"))
    msg = str(exc.value)
    assert says in msg and "\n" not in msg and "s.bdf" in msg


def test_warped_quadrilateral_beyond_the_limit_is_refused(tmp_path):
    p = tmp_path / "w.bdf"
    p.write_text(
        "BEGIN BULK\nGRID,1,,0.,0.,0.\nGRID,2,,1.,0.,0.1\nGRID,3,,1.,1.,0.\nGRID,4,,0.,1.,0.1\n"
        "MAT1,1,2.e11,,0.3,8000.\nPSHELL,1,1,0.01,1\nCQUAD4,1,1,1,2,3,4\nENDDATA\n"
    )
    # corners 0.05 off the mean plane over a mean diagonal of 1.414: ratio 0.035, accepted
    g = load_bdf(p, units="m, N, s")
    assert len(g.shells) == 1 and g.meta["k6rot"] == 100.0
    p.write_text(p.read_text().replace("0.1\n", "0.2\n"))
    build_frame(g)
    with pytest.raises(InputError, match="warped"):  # ratio 0.071 > 0.05
        build_frame(load_bdf(p, units="m, N, s"))


def test_pshell_values_follow_nastran(tmp_path):
    # MAT1 E and NU: G = E / (2 (1 + NU)); 12I/T^3 = 2 doubles D; TS/T 0.5; NSM; WTMASS
    p = _deck(
        tmp_path,
        "CQUAD4,1,1,1,2,3,4",
        "PARAM,WTMASS,0.5\nPARAM,K6ROT,10.\nPSHELL,1,1,0.01,1,2.,1,0.5,3.\n",
    )
    s = load_bdf(p, units="m, N, s").shells[0].section
    g = 2e11 / 2.6
    q = 2e11 / (1 - 0.09)
    np.testing.assert_allclose(
        s.membrane_N_per_m, 0.01 * np.array([[q, 0.3 * q, 0], [0.3 * q, q, 0], [0, 0, g]])
    )
    np.testing.assert_allclose(s.bending_N_m, 2.0 * 0.01**3 / 12 * s.membrane_N_per_m / 0.01)
    np.testing.assert_allclose(s.shear_N_per_m, 0.5 * 0.01 * g * np.eye(2))
    assert s.mass_per_area_kg_per_m2 == pytest.approx((8000 * 0.01 + 3.0) * 0.5, rel=1e-15)
    assert s.drilling_N_per_m == pytest.approx(1e-6 * 10.0 * g * 0.01, rel=1e-15)
