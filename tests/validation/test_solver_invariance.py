"""Property: a free structure's modes do not depend on where its model sits.

Random tree stations (bodies with point masses, beams on bodies and on beams, with and
without ``ea``, some massless beams carrying point masses) are translated and rotated as a
whole.  The reference is the same model untransformed: physics is invariant under a rigid
motion of the frame, so the elastic frequencies must agree to 1e-9 relative (the solvers
resolve each to ~1e-11; the transformed model's inputs differ by rounding, ~1e-16 of each
value) and both must have exactly six rigid-body modes with ``omega = 0``.  (The higher
modes of models with a penalty stiffness are checked to 1e-7: see the comment below.)
"""

from __future__ import annotations

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from microg.dynamics.modes import solve_modes
from microg.models.station import Beam, Orbit, PointMass, RigidBody, Station
from microg.structure.fem import build_fem
from microg.structure.ritz import build_ritz


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def random_tree(seed: int, n_beams: int) -> Station:
    """A random tree station (SI): a root body, beams on the body or on earlier beams."""
    rng = np.random.default_rng(seed)
    masses = tuple(
        PointMass(f"m{i}", float(rng.uniform(10, 1e3)), rng.uniform(-5, 5, 3), np.eye(3))
        for i in range(int(rng.integers(1, 3)))
    )
    beams: list[Beam] = []
    for i in range(n_beams):
        if i == 0 or rng.random() < 0.3:
            parent, root = "core", rng.uniform(-3, 3, 3)
        else:
            pb = beams[int(rng.integers(0, len(beams)))]
            parent, root = pb.name, pb.root + rng.uniform(0.2, 1.0) * pb.length * pb.direction
        d = _unit(rng.standard_normal(3))
        o = rng.standard_normal(3)
        o = _unit(o - (o @ d) * d)
        length = float(rng.uniform(1.0, 15.0))
        ei = float(10 ** rng.uniform(5, 8))
        mpl = 0.0 if rng.random() < 0.2 else float(rng.uniform(1.0, 40.0))
        tip = (PointMass(f"p{i}", float(rng.uniform(5, 100)), root + length * d),)
        beams.append(
            Beam(
                f"b{i}",
                parent,
                root,
                d,
                length,
                o,
                ei,
                ei * float(rng.uniform(0.5, 2.0)),
                ei * float(rng.uniform(0.3, 1.0)),
                ei * 50.0 if rng.random() < 0.5 else None,
                mpl,
                tip if (mpl == 0.0 or rng.random() < 0.4) else (),
            )
        )
    return Station("rand", (RigidBody("core", masses),), tuple(beams), (), Orbit(6.8e6), 10.0)


def moved(station: Station, rot: np.ndarray, shift: np.ndarray) -> Station:
    """The station turned by ``rot`` and translated by ``shift`` as a whole."""

    def pm(p: PointMass) -> PointMass:
        return PointMass(p.name, p.mass, rot @ p.position + shift, rot @ p.inertia @ rot.T)

    bodies = tuple(
        RigidBody(
            b.name,
            tuple(pm(p) for p in b.masses),
            b.parent,
            None if b.attach is None else rot @ b.attach + shift,
        )
        for b in station.bodies
    )
    beams = tuple(
        Beam(
            b.name,
            b.parent,
            rot @ b.root + shift,
            rot @ b.direction,
            b.length,
            rot @ b.orientation,
            b.ei_y,
            b.ei_z,
            b.gj,
            b.ea,
            b.mass_per_length,
            tuple(pm(p) for p in b.masses),
        )
        for b in station.beams
    )
    return Station(station.name, bodies, beams, (), station.orbit, station.reference_length)


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


@given(
    seed=st.integers(0, 2**31 - 1),
    n_beams=st.integers(1, 4),
    offset=st.floats(-200.0, 200.0),
)
@example(seed=339, n_beams=3, offset=4.0)  # a high mode off by 1.09e-7 (see the tolerance)
# the higher modes of a small tree were solved in the complement of the flexibility's modes
# (not the assembled K's own): off by 1.1e-5 against a 40-digit solve; now 2.4e-10
@example(seed=339, n_beams=4, offset=0.0)
@settings(max_examples=25, deadline=None)
def test_modes_invariant_under_rigid_motion_of_the_model(seed: int, n_beams: int, offset: float):
    base = random_tree(seed, n_beams)
    rng = np.random.default_rng(seed + 1)
    other = moved(base, _rotation(rng), offset * _unit(rng.standard_normal(3)))
    # the assumed-modes rotation coordinates turn about the origin (the report's convention),
    # so moving the model a distance D away conditions them by (1 + (D / 10 m)^2)
    ritz_scale = 1.0 + (offset / 10.0) ** 2
    for build, scale in (
        (lambda s: build_fem(s, elements_per_beam=3), 1.0),
        (lambda s: build_ritz(s, None, 2, gravity_gradient=False), ritz_scale),
    ):
        a, b = solve_modes(build(base)), solve_modes(build(other))
        assert a.n_rigid == 6 and b.n_rigid == 6  # exactly six, omega exactly 0
        assert np.all(a.omega[a.rigid] == 0.0) and np.all(b.omega[b.rigid] == 0.0)
        wa, wb = a.omega[~a.rigid], b.omega[~b.rigid]
        assert wa.size == wb.size
        # the modes up to 100x the first elastic frequency (the solvers' first, exact level:
        # the tree flexibility or the unshifted inverse, ~1e-12) to 1e-9; the higher modes of
        # a model with an axially rigid massless beam (a penalty 1e6 x its bending stiffness)
        # carry that stiffness spread times the rounding of the assembly: the penalty (1e6)
        # times the trees' own spread (EI 1e5-1e8 over lengths 1-15 m: ~1e3) is a condition
        # of ~1e9, so ~1e9 x eps = 2e-7 (hypothesis found 1.09e-7: the example above); 1e-6
        low = wa <= 100.0 * wa[0]
        np.testing.assert_allclose(wb[low], wa[low], rtol=1e-9 * scale)
        np.testing.assert_allclose(wb, wa, rtol=1e-6 * scale)
