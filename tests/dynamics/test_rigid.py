"""Tests of microg.dynamics.rigid: rigid basis order, isostatic support coordinates."""

from __future__ import annotations

import numpy as np

from microg.dynamics.rigid import m_orthonormal, support_coordinates
from microg.models.toml import load_station
from microg.structure.fem import build_fem


def test_rigid_basis_keeps_translations_first_and_named() -> None:
    # Gram-Schmidt in the candidates' order: the x, y, z modes are pure translations
    s = build_fem(load_station("ioc"), elements_per_beam=4)
    c = np.column_stack([s.rigid_body[d] for d in ("x", "y", "z", "rx", "ry", "rz")])
    b = m_orthonormal(s.mass, c)
    np.testing.assert_allclose(b.T @ (s.mass @ b), np.eye(6), atol=1e-12)
    np.testing.assert_allclose(b[:, 0] * np.sqrt(s.total_mass), s.rigid_body["x"], atol=1e-12)


def test_support_coordinates_hold_every_rigid_motion() -> None:
    # the r held coordinates leave no rigid motion: B restricted to them is invertible
    s = build_fem(load_station("ioc"), elements_per_beam=4)
    b = np.column_stack(list(s.rigid_body.values()))
    sup = support_coordinates(b)
    assert sup.size == 6
    sv = np.linalg.svd(b[sup], compute_uv=False)
    assert sv.min() > 1e-3 * sv.max()
