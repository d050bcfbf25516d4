"""Assumed modes (the report's method, Section 2.4-2.5) against converged frame finite elements.

Model: the shipped IOC (``ioc``, with orbiter) and ``ioc-no-orbiter``, X-Z plane, push-off
along x at the horizontal lab (z = -55 ft, Section 3).  Both discretisations describe the
same Euler-Bernoulli structure; gravity gradient is left out of both (the FE default) so that
the rigid-body modes are the same.

Modes are paired by shape, not by order: the 3-D frame model also has Y-Z bending and keel
torsion modes.  Each model's mode shapes are reduced to their x displacement at common
stations (every main-body mass, ten stations on each beam) and paired by the modal assurance
criterion, MAC = (a.b)^2 / (a.a b.b).

What the test establishes (numbers in docs/convergence-ritz.md):

* the report's model (one function per beam) gives the fundamental to under 1 % and the
  second X-Z mode 13-16 % too high; the node of the fundamental on the main body to
  within 0.1 ft; the peak at the lab within 15 %;
* the assumed modes converge on the FE values (8 functions per beam: < 0.2 %);
* the assumed-modes antisymmetric boom mode (3.5 rad/s) is, in the frame model, a coupled
  boom-bending/keel-torsion mode at 0.80 rad/s: the planar Ritz model has no keel torsion.
  A push on the keel axis does not excite it.  (Without the orbiter no FE mode matches it.)
"""

from __future__ import annotations

import numpy as np
import pytest

from microg.dynamics.crew import CrewPushoff
from microg.dynamics.forces import REPORT_F0_N
from microg.dynamics.modes import solve_modes
from microg.location.amap import acceleration_map, elastic_mask, in_plane_fraction, sample_shapes
from microg.models.toml import load_station
from microg.structure.fem import build_fem
from microg.structure.ritz import build_ritz

FT = 0.3048
CREW = CrewPushoff(REPORT_F0_N)
FEM_ELEMENTS = 20  # per beam (more where masses cut it); 4..40 agree to 5 digits, see below


def _profiles(station, structure, phi):
    """x displacement (k, m) at the common stations: body masses, ten points per beam."""
    pos, comp, sh = sample_shapes(structure, phi)
    rows = []
    for beam in station.beams:
        sel = comp == beam.name
        s = (pos[sel] - beam.root) @ beam.direction
        o = np.argsort(s)
        q = np.linspace(0.1, 1.0, 10) * beam.length
        rows.append(
            np.stack([np.interp(q, s[o], sh[sel][o, 0, j]) for j in range(phi.shape[1])], 1)
        )
    body = station.bodies[0]
    sel = comp == body.name
    z = pos[sel][:, 2]
    o = np.argsort(z)
    zq = np.unique([m.position[2] for m in body.masses])
    rows.append(np.stack([np.interp(zq, z[o], sh[sel][o, 0, j]) for j in range(phi.shape[1])], 1))
    return np.concatenate(rows)


def _mac(a, b):
    """MAC of every column of a with every column of b.

    A column of b whose x profile is below 1e-8 of the largest is an out-of-plane mode: its x
    displacement is rounding, and MAC (which scales the size away) would pair noise.  Its
    MAC is 0.
    """
    na, nb = (a * a).sum(0), (b * b).sum(0)
    mac = (a.T @ b) ** 2 / np.outer(na, np.where(nb > 0, nb, 1.0))
    return np.where(np.sqrt(nb) > 1e-8 * np.sqrt(nb.max()), mac, 0.0)


def _lab_index(amap, structure):
    return int(np.argmin(np.linalg.norm(amap.positions - structure.point("lab").position, axis=1)))


@pytest.fixture(scope="module", params=["ioc", "ioc-no-orbiter"])
def case(request):
    station = load_station(request.param)
    fem = build_fem(station, elements_per_beam=FEM_ELEMENTS)
    fm = solve_modes(fem, n_modes=30)
    el = elastic_mask(fm.omega, fm.rigid)
    amap = acceleration_map(fem, fm, "crew", "x", CREW, include_rigid=False)
    return {
        "station": station,
        "fem": fem,
        "fm": fm,
        "omega": fm.omega[el],
        "profiles": _profiles(station, fem, fm.phi[:, el]),
        "xz": in_plane_fraction(fem, fm, "xz")[el],
        "amap": amap,
    }


def _ritz(station, n):
    s = build_ritz(station, "xz", n, gravity_gradient=False)
    m = solve_modes(s)
    el = elastic_mask(m.omega, m.rigid)
    return s, m, m.omega[el], _profiles(station, s, m.phi[:, el])


def _paired(case, n):
    """Ritz elastic frequencies, the MAC-paired FE frequencies and the MACs."""
    _, _, w, prof = _ritz(case["station"], n)
    mac = _mac(prof, case["profiles"])
    k = np.argmax(mac, axis=1)
    return w, case["omega"][k], mac[np.arange(w.size), k], k


def _xz_modes(w, wf, mac, k, case):
    """Indices of Ritz modes paired (MAC > 0.8) with a mostly in-plane FE mode."""
    return [j for j in range(w.size) if mac[j] > 0.8 and case["xz"][k[j]] > 0.75]


def test_fe_is_converged():
    # the reference must not move with the mesh: 4 and 40 elements per beam agree to 1e-5
    # (Hermite cubics are exact for the static deflection between point masses, which
    # dominate the IOC's mass; the distributed beam mass is ~1 %)
    station = load_station("ioc")
    w = [
        solve_modes(build_fem(station, elements_per_beam=n), n_modes=16).omega[6:] for n in (4, 40)
    ]
    np.testing.assert_allclose(w[0], w[1], rtol=1e-5)


def test_converged_ritz_matches_fe(case):
    w, wf, mac, k = _paired(case, 8)
    xz = _xz_modes(w, wf, mac, k, case)
    assert len(xz) >= 3
    first_two = xz[:2]
    # same structure, both converged: the residual is the Ritz truncation after 8
    # polynomials per beam (observed 4e-5 and 7e-4; N=4 gives 6e-4 and 1.2e-2), so 2e-3
    for j in first_two:
        assert mac[j] > 0.99
        assert w[j] / wf[j] - 1 == pytest.approx(0.0, abs=2e-3)


def test_ritz_is_an_upper_bound_decreasing_with_functions(case):
    # nested admissible spaces (the basis of N functions contains that of N-1): Rayleigh-Ritz
    # frequencies can only decrease as N grows (to rounding)
    prev = None
    for n in (1, 2, 4, 8):
        _, _, w, _ = _ritz(case["station"], n)
        if prev is not None:
            assert np.all(w[: prev.size] <= prev * (1 + 1e-10))
        prev = w


def test_reports_model_against_converged(case):
    w, wf, mac, k = _paired(case, 1)
    xz = _xz_modes(w, wf, mac, k, case)
    assert len(xz) == 2  # the report's two elastic modes per plane (Table 4)
    err = w[xz] / wf[xz] - 1
    # the fundamental (the mode that carries the acceleration, conclusion 4) within 2 %:
    # observed +0.88 % (orbiter) and +0.39 % (no orbiter); positive, as one cubic per beam
    # is a constrained (stiffer) approximation of the same structure
    assert 0 < err[0] < 0.02
    # the second X-Z mode is poor: observed +15.7 % and +12.7 % (MAC 0.85): one function
    # per beam cannot give the keel its second bending shape.  Guards "more than 5 % high".
    assert err[1] > 0.05
    # the remaining Ritz mode (antisymmetric boom bending, 3.52 rad/s) has no FE
    # counterpart near it: in the frame model that motion twists the keel (0.80 rad/s with
    # the orbiter); the planar Ritz model has no torsion coordinate
    (anti,) = [j for j in range(w.size) if j not in xz]
    assert not (mac[anti] > 0.8 and abs(w[anti] / wf[anti] - 1) < 0.1)


def test_lab_acceleration_and_node(case):
    amap_f = case["amap"]
    i_f = _lab_index(amap_f, case["fem"])
    node_f = [n.position[2] for n in amap_f.nodes if n.component == "main"]
    for n_fun, tol in ((1, 0.15), (8, 0.05)):
        s, m, _, _ = _ritz(case["station"], n_fun)
        amap = acceleration_map(s, m, "crew", "x", CREW, include_rigid=False)
        i = _lab_index(amap, s)
        rel = amap.elastic_peak[i] / amap_f.elastic_peak[i_f] - 1
        # the peak of a multi-mode sum over a 30 s window depends on the modes' relative
        # phases: a 0.1 % frequency difference shifts mode 2's phase by ~0.1 rad by the end
        # of the window, worth a few % near the node where modes 1 and 2 are comparable;
        # 5 % for the converged model (observed -0.1 % and +2.0 %).  The report's model:
        # observed -11.9 % (orbiter) and -2.1 % (no orbiter); 15 % guards "within 15 %".
        assert abs(rel) < tol
        node = [n.position[2] for n in amap.nodes if n.component == "main"]
        # the node of the fundamental on the main body: observed within 0.06 ft (n = 1:
        # -90.07 vs -90.12 ft with the orbiter, -51.67 vs -51.64 ft without);
        # 0.5 ft is well under the 1-ft scale that matters for siting a rack
        assert len(node) == len(node_f) == 1
        assert abs(node[0] - node_f[0]) < 0.5 * FT
    # fundamental's own Eq. 3.1 term at the lab (no phases involved): converged Ritz within
    # 1 % of FE (its frequency and shape agree to < 0.1 %, the term goes as phi^2/omega)
    s, m, _, _ = _ritz(case["station"], 8)
    amap = acceleration_map(s, m, "crew", "x", CREW, include_rigid=False)
    a_r = amap.per_mode[amap.fundamental, _lab_index(amap, s)]
    a_f = amap_f.per_mode[amap_f.fundamental, i_f]
    assert a_r == pytest.approx(a_f, rel=1e-2)
