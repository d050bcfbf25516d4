"""Natural frequencies and mode shapes of a free-free station (Eqs. 2.9-2.12).

Rigid-body modes are never left to the eigensolver's round-off.  The rigid-body vectors a
:class:`~microg.structure.Structure` declares are tested against ``K``; those it annihilates
are the exact zero-frequency modes, set to ``omega = 0`` and M-orthonormalised, and the
elastic modes are solved in their M-orthogonal complement.  A rotation restrained by the
gravity-gradient stiffness is not rigid: it comes out as the librational mode.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from microg.dynamics.dense import solve_dense
from microg.dynamics.rigid import RIGID_TOL
from microg.structure.structure import Structure

__all__ = ["Modes", "solve_modes", "solve_dense", "effective_mass"]


@dataclass(frozen=True)
class Modes:
    """Modes of a structure, ascending in frequency.

    Attributes
    ----------
    omega : ndarray (m,)
        Circular frequencies, rad/s; exactly 0.0 for rigid-body modes.
    phi : ndarray (n, m)
        Mode shapes, one per column, mass-normalised (``phi.T @ M @ phi = I``).
    rigid : ndarray (m,) of bool
        True for the exact zero-frequency (rigid-body) modes.
    modal_mass : ndarray (m,)
        Generalized mass of each mode scaled to a largest point translation of 1 m, kg.
    effective_mass : mapping of str to ndarray (m,)
        Modal effective mass per rigid-body direction (kg for x, y, z; kg m^2 for rx, ry, rz).
    participation : mapping of str to ndarray (m,)
        Modal participation factors ``phi_j^T M r_d`` per direction.
    method : str
        Discretisation that produced the structure.
    structure : Structure
        The structure the modes belong to.
    """

    omega: np.ndarray
    phi: np.ndarray
    rigid: np.ndarray
    modal_mass: np.ndarray
    effective_mass: Mapping[str, np.ndarray]
    participation: Mapping[str, np.ndarray]
    method: str
    structure: Structure = field(repr=False)

    @property
    def freq_hz(self) -> np.ndarray:
        """Natural frequencies, Hz."""
        return self.omega / (2.0 * np.pi)

    @property
    def n_modes(self) -> int:
        """Number of modes."""
        return int(self.omega.size)

    @property
    def n_rigid(self) -> int:
        """Number of exact rigid-body modes."""
        return int(np.count_nonzero(self.rigid))

    def subset(self, index: np.ndarray | slice) -> Modes:
        """The modes selected by ``index``."""
        return Modes(
            omega=self.omega[index],
            phi=self.phi[:, index],
            rigid=self.rigid[index],
            modal_mass=self.modal_mass[index],
            effective_mass={k: v[index] for k, v in self.effective_mass.items()},
            participation={k: v[index] for k, v in self.participation.items()},
            method=self.method,
            structure=self.structure,
        )

    def to_dict(self) -> dict:
        """The ``microg modes --json`` contract: method and one object per mode."""
        return {
            "method": self.method,
            "modes": [
                {
                    "omega": float(self.omega[j]),
                    "freq_hz": float(self.freq_hz[j]),
                    "rigid": bool(self.rigid[j]),
                    "modal_mass": float(self.modal_mass[j]),
                    "effective_mass": {d: float(v[j]) for d, v in self.effective_mass.items()},
                }
                for j in range(self.n_modes)
            ],
        }


def effective_mass(
    mass: np.ndarray, phi: np.ndarray, rigid_body: Mapping[str, np.ndarray]
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Participation factors ``L_jd = phi_j^T M r_d`` and effective masses ``L_jd^2``.

    Parameters
    ----------
    mass : ndarray or sparse (n, n)
    phi : ndarray (n, m)
        Mass-normalised shapes.
    rigid_body : mapping of direction to ndarray (n,)
        Unit rigid-body vectors (1 m or 1 rad).
    """
    part = {}
    eff = {}
    for d, r in rigid_body.items():
        lj = phi.T @ (mass @ np.asarray(r, float))
        part[d] = np.asarray(lj).ravel()
        eff[d] = part[d] ** 2
    return eff, part


def _modal_mass_unit_peak(structure: Structure, phi: np.ndarray) -> np.ndarray:
    maps = [p.translation for p in structure.points.values()]
    sample_peak = None
    samples = structure.samples
    if samples is not None and hasattr(samples, "displacement"):
        # sparse-friendly samples (microg.structure.fem.NodeSamples): (p, 3, m) translations
        sample_peak = np.max(np.abs(samples.displacement(phi)), axis=(0, 1))
    elif samples is not None:
        samp = samples.translation
        maps.extend(list(samp.reshape(-1, samp.shape[-1])[None]))
    if maps:
        t = np.concatenate([np.reshape(m, (-1, phi.shape[0])) for m in maps], axis=0)
        peak = np.max(np.abs(t @ phi), axis=0)
        if sample_peak is not None:
            peak = np.maximum(peak, sample_peak)
    elif sample_peak is not None:
        peak = sample_peak
    else:
        peak = np.max(np.abs(phi), axis=0)
    peak = np.where(peak > 0, peak, 1.0)
    return 1.0 / peak**2


def solve_modes(
    structure: Structure, n_modes: int | None = None, *, tol: float = RIGID_TOL
) -> Modes:
    """Modes of ``structure``: dense for small models, sparse shift-invert for large ones.

    Parameters
    ----------
    structure : Structure
    n_modes : int, optional
        Number of lowest modes (all, for the dense solver, when omitted).
    tol : float
        Relative tolerance for rigid-body detection.
    """
    rb = structure.rigid_body
    cand = np.column_stack(list(rb.values())) if rb else None
    if structure.is_sparse:
        from microg.dynamics.eigsparse import solve_sparse  # large frame models

        omega, phi, rigid = solve_sparse(
            structure.mass,
            structure.stiffness,
            cand,
            n_modes=n_modes or 30,
            tol=tol,
            labels=structure.dof_labels,
        )
    else:
        m, k = structure.dense()
        omega, phi, rigid = solve_dense(m, k, cand, tol=tol, labels=structure.dof_labels)
        if n_modes is not None:
            omega, phi, rigid = omega[:n_modes], phi[:, :n_modes], rigid[:n_modes]
    eff, part = effective_mass(structure.mass, phi, rb)
    return Modes(
        omega=omega,
        phi=phi,
        rigid=rigid,
        modal_mass=_modal_mass_unit_peak(structure, phi),
        effective_mass=eff,
        participation=part,
        method=structure.method,
        structure=structure,
    )
