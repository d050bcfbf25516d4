"""Natural frequencies and mode shapes of a free-free station (Eqs. 2.9-2.12).

Rigid-body modes are never left to the eigensolver's round-off.  The rigid-body vectors a
:class:`~microg.structure.Structure` declares are tested against ``K``; those it annihilates
are the exact zero-frequency modes, set to ``omega = 0`` and M-orthonormalised, and the
elastic modes are solved in their M-orthogonal complement.  A rotation restrained by the
gravity-gradient stiffness is not rigid: it comes out as the librational mode, or, when the
attitude is unstable (``I_z`` not the smallest moment), as an **unstable** mode with a growth
rate instead of a frequency.

Dense models (assumed modes) use :func:`~microg.dynamics.dense.solve_dense`, sparse ones
(frame elements) :func:`~microg.dynamics.eigsparse.solve_sparse`, with the exact tree
flexibility of :class:`~microg.structure.fem.FrameStructure` where the model has one.  BLAS
runs with the threads the process has (the library never changes them).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from microg import defaults
from microg.dynamics.dense import Eigensolution, solve_dense
from microg.dynamics.rigid import RIGID_TOL
from microg.structure.structure import Structure

__all__ = [
    "DEFAULT_N_MODES",
    "EFFECTIVE_MASS_ZERO",
    "Modes",
    "solve_modes",
    "solve_dense",
    "effective_mass",
    "characteristic_length",
]

#: modes computed for a sparse (frame) model when the caller does not say: the main job's
#: choice.  On the shipped IOC frame model (10 elements per beam) the 60th mode is at
#: ~36 Hz, above the 1/3-octave bands a crew disturbance excites, and 60 modes cost about
#: 0.1 s.  Dense (assumed-modes) models return all their modes.
DEFAULT_N_MODES = defaults.N_MODES
#: a participation factor ``|phi_j^T M r_d|`` at most this multiple of its own rounding bound
#: ``eps |phi_j|^T |M| |r_d|`` is round-off of an exact zero (an elastic mode of a free-free
#: structure is M-orthogonal to every rigid motion): it is returned as exactly 0.  The factor
#: covers the accumulated rounding of the shapes' M-orthogonalisation (a few products of the
#: same size); a gravity-gradient coupling (~1e-7 of the mode) is far above it.
EFFECTIVE_MASS_ZERO = 64.0
_EPS = float(np.finfo(float).eps)
#: what ``Modes.modal_mass`` is normalised to (the modes table and ``--json`` say it)
MODAL_MASS_NORMALISATION = (
    "shape scaled to a largest point motion of 1 m: max(|u|, L_c |theta|) over the named "
    "points and the structure's samples, L_c the radius of gyration about the centre of mass"
)


@dataclass(frozen=True)
class Modes:
    """Modes of a structure: rigid ones first, then unstable ones, then ascending frequency.

    Attributes
    ----------
    omega : ndarray (m,)
        Circular frequencies, rad/s; exactly 0.0 for rigid-body modes and 0.0 for unstable
        modes (see ``growth_rate``).
    phi : ndarray (n, m)
        Mode shapes, one per column, mass-normalised (``phi.T @ M @ phi = I``).
    rigid : ndarray (m,) of bool
        True for the exact zero-frequency (rigid-body) modes.
    modal_mass : ndarray (m,)
        Generalized mass of each shape scaled to a **largest generalized point motion of
        1 m**, kg: the motion of a point is ``max(|u|, L_c |theta|)`` (translation ``u`` in
        m, small rotation ``theta`` in rad) over the named points and the structure's
        samples, with ``L_c`` = :func:`characteristic_length` (the station's radius of
        gyration about its centre of mass).  A mass-normalised shape with a largest motion
        ``p`` has modal mass ``1/p^2``.  Counting rotations means that no division by a
        vanishing translation can occur: a torsion mode that barely translates any point
        has a modal mass bounded by the mass it moves, not 1e26 kg.  (An imported mode that
        moves only coordinates without a position, such as NASTRAN scalar points, which the
        reader drops with a warning, has no such bound: its modal mass is not meaningful.)
    effective_mass : mapping of str to ndarray (m,)
        Modal effective mass ``(phi_j^T M r_d)^2`` per rigid-body direction ``r_d`` (kg for
        x, y, z; kg m^2 for rx, ry, rz about the centre of mass).  Exactly 0 where the
        participation factor is round-off of an exact zero (:data:`EFFECTIVE_MASS_ZERO`):
        every elastic mode of a free-free structure.
    participation : mapping of str to ndarray (m,)
        Modal participation factors ``phi_j^T M r_d`` per direction (same zeros).
    method : str
        Discretisation that produced the structure.
    structure : Structure
        The structure the modes belong to.
    unstable : ndarray (m,) of bool
        Modes with a negative stiffness (e.g. a gravity-gradient libration of an unstable
        attitude): the motion grows as ``exp(growth_rate t)`` instead of oscillating.
    growth_rate : ndarray (m,)
        ``sqrt(-lambda)`` of the unstable modes (an imaginary frequency), rad/s; 0 for others.
    notes : tuple of str
        What a reader must know about these modes (unstable modes and the inertia condition
        causing them, massless coordinates condensed, mesh notes).
    """

    omega: np.ndarray
    phi: np.ndarray
    rigid: np.ndarray
    modal_mass: np.ndarray
    effective_mass: Mapping[str, np.ndarray]
    participation: Mapping[str, np.ndarray]
    method: str
    structure: Structure = field(repr=False)
    unstable: np.ndarray | None = None
    growth_rate: np.ndarray | None = None
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        m = np.asarray(self.omega).size
        if self.unstable is None:
            object.__setattr__(self, "unstable", np.zeros(m, bool))
        if self.growth_rate is None:
            object.__setattr__(self, "growth_rate", np.zeros(m))

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

    @property
    def elastic(self) -> np.ndarray:
        """The one "elastic" rule: modes that are neither rigid nor unstable, bool (m,).

        Every mode with ``omega > 0`` is elastic in this sense, including a gravity-gradient
        libration (``omega ~ 1e-3 rad/s``, a vibration about a stable attitude); nothing is
        decided by a frequency threshold.
        """
        return ~np.asarray(self.rigid, bool) & ~np.asarray(self.unstable, bool)

    @property
    def effective_mass_fraction(self) -> dict[str, np.ndarray]:
        """Effective mass per direction as a fraction of the station's ``r_d^T M r_d``.

        For a translation ``r_d^T M r_d`` is the station's mass; for a rotation about the
        centre of mass, its moment of inertia about that axis.  Over all modes of a complete
        model the fractions sum to 1 (completeness of the modes).
        """
        s = self.structure
        out = {}
        for d, r in s.rigid_body.items():
            r = np.asarray(r, float)
            total = float(r @ (s.mass @ r))
            if d in self.effective_mass and total > 0:
                out[d] = np.asarray(self.effective_mass[d]) / total
        return out

    @property
    def modal_mass_exceeds_model(self) -> np.ndarray:
        """(m,) modes whose modal mass exceeds the model's total mass.

        Scaled to a largest point motion of 1 m, a shape's generalized mass is at most the
        mass it moves, so at most the model's mass when every coordinate has a position.
        Above it the shape barely moves any point with a position: its motion lies on
        coordinates without one (an imported model's scalar points, dropped), and its modal
        mass is not a physical mass.
        """
        total = float(getattr(self.structure, "total_mass", 0.0) or 0.0)
        if total <= 0:
            return np.zeros(self.n_modes, bool)
        return np.asarray(self.modal_mass, float) > total * (1.0 + 1e-9)

    def subset(self, index: np.ndarray | slice) -> Modes:
        """The modes selected by ``index``."""
        assert self.unstable is not None and self.growth_rate is not None
        return Modes(
            omega=self.omega[index],
            phi=self.phi[:, index],
            rigid=self.rigid[index],
            modal_mass=self.modal_mass[index],
            effective_mass={k: v[index] for k, v in self.effective_mass.items()},
            participation={k: v[index] for k, v in self.participation.items()},
            method=self.method,
            structure=self.structure,
            unstable=self.unstable[index],
            growth_rate=self.growth_rate[index],
            notes=self.notes,
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``microg modes --json`` contract: method, notes and one object per mode.

        Per mode: ``omega`` (rad/s), ``freq_hz``, ``rigid``, ``unstable``,
        ``growth_rate_rad_s``, ``elastic``, ``modal_mass`` (kg, see the class docstring and
        ``modal_mass_normalised_to``), ``modal_mass_exceeds_model_mass``
        (:attr:`modal_mass_exceeds_model`),
        ``effective_mass`` (kg or kg m^2 per direction) and ``effective_mass_fraction``
        (per direction, of ``r^T M r``).
        """
        assert self.unstable is not None and self.growth_rate is not None
        frac = self.effective_mass_fraction
        el = self.elastic
        over = self.modal_mass_exceeds_model
        return {
            "method": self.method,
            "notes": list(self.notes),
            "modal_mass_normalised_to": MODAL_MASS_NORMALISATION,
            "modes": [
                {
                    "omega": float(self.omega[j]),
                    "freq_hz": float(self.freq_hz[j]),
                    "rigid": bool(self.rigid[j]),
                    "unstable": bool(self.unstable[j]),
                    "growth_rate_rad_s": float(self.growth_rate[j]),
                    "elastic": bool(el[j]),
                    "modal_mass": float(self.modal_mass[j]),
                    "modal_mass_exceeds_model_mass": bool(over[j]),
                    "effective_mass": {d: float(v[j]) for d, v in self.effective_mass.items()},
                    "effective_mass_fraction": {d: float(v[j]) for d, v in frac.items()},
                }
                for j in range(self.n_modes)
            ],
        }

    def to_xarray(self) -> Any:
        """The modes as an :class:`xarray.Dataset` with dims ``mode`` and ``dof``.

        Variables: ``omega`` (rad/s), ``freq_hz``, ``rigid``, ``unstable``, ``growth_rate``
        (rad/s), ``elastic``, ``modal_mass`` (kg), ``effective_mass_<d>`` (kg or kg m^2),
        ``effective_mass_fraction_<d>`` and ``phi`` (dof, mode; mass-normalised, m/sqrt(kg)
        per coordinate unit).  Units are in each variable's ``units`` attribute.
        """
        import xarray as xr

        assert self.unstable is not None and self.growth_rate is not None
        mode = np.arange(1, self.n_modes + 1)
        labels = list(self.structure.dof_labels) or [str(i) for i in range(self.phi.shape[0])]
        data: dict[str, Any] = {
            "omega": ("mode", self.omega, {"units": "rad/s"}),
            "freq_hz": ("mode", self.freq_hz, {"units": "Hz"}),
            "rigid": ("mode", np.asarray(self.rigid, bool), {"units": "1"}),
            "unstable": ("mode", np.asarray(self.unstable, bool), {"units": "1"}),
            "growth_rate": ("mode", self.growth_rate, {"units": "rad/s"}),
            "elastic": ("mode", self.elastic, {"units": "1"}),
            "modal_mass": ("mode", self.modal_mass, {"units": "kg"}),
            "phi": (("dof", "mode"), self.phi, {"units": "coordinate unit per sqrt(kg)"}),
        }
        for d, v in self.effective_mass.items():
            unit = "kg" if d in ("x", "y", "z") else "kg m^2"
            data[f"effective_mass_{d}"] = ("mode", np.asarray(v), {"units": unit})
        for d, v in self.effective_mass_fraction.items():
            data[f"effective_mass_fraction_{d}"] = ("mode", v, {"units": "1"})
        return xr.Dataset(
            data,
            coords={"mode": mode, "dof": labels},
            attrs={"method": self.method, "notes": "; ".join(self.notes)},
        )

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """A stem chart of the frequencies (:func:`microg.plotting.modes.plot_modes`).

        ``ax``: the matplotlib axes to draw into (default: a new figure).
        """
        from microg.plotting.modes import plot_modes

        return plot_modes(self, ax=ax, **kwargs)

    def plot3d(self, **kwargs: Any) -> Any:
        """The model in 3-D with a slider over the elastic modes (a plotly Figure).

        Keywords as :func:`microg.plotting.interactive.modes_3d` (``force_points``,
        ``observed``, ``title``).
        """
        from microg.plotting.interactive import modes_3d

        return modes_3d(self, **kwargs)

    def _repr_html_(self) -> str:
        """The modes table in a notebook: number, frequency, kind, modal mass."""
        from html import escape

        kind = np.where(self.rigid, "rigid", "elastic")
        if self.unstable is not None:
            kind = np.where(self.unstable, "unstable", kind)
        rows = "".join(
            f"<tr><td>{j + 1}</td><td>{self.freq_hz[j]:.4g}</td><td>{kind[j]}</td>"
            f"<td>{self.modal_mass[j]:.3g}</td></tr>"
            for j in range(min(self.n_modes, 60))
        )
        more = f"<p>... {self.n_modes - 60} more</p>" if self.n_modes > 60 else ""
        return (
            f"<p><b>{escape(str(self.method))}</b>: {self.n_modes} modes, "
            f"{int(np.count_nonzero(self.rigid))} rigid</p><table><tr><th>mode</th>"
            f"<th>frequency (Hz)</th><th>kind</th><th>modal mass (kg)</th></tr>{rows}</table>{more}"
        )


#: a mode's frequency whose rounding bound exceeds this (relative) is said in the notes
ROUNDING_NOTE_REL = 1e-4


def _rounding_note(stiffness: Any, sol: Any) -> list[str]:
    """A note where the assembled stiffness's rounding bounds an elastic frequency loosely.

    Rounding each entry of ``K`` by ``eps`` moves an eigenvalue by up to
    ``eps |phi|^T |K| |phi|`` (first-order perturbation, ``phi`` M-normalised), so a
    frequency is known to about half of ``eps |phi|^T |K| |phi| / lambda``: near 1 when the
    stiffness spans ~1/eps over the mode (a bar of L/r 1e5 in thousands of elements).  Said
    when the bound exceeds :data:`ROUNDING_NOTE_REL` for some mode; the bound is the one
    the mechanism test uses.

    Parameters
    ----------
    stiffness : ndarray or sparse (n, n)
        N/m (SI coordinates).
    sol : the solver's eigensolution (``omega``, ``phi``, ``rigid``)
    """
    el = np.flatnonzero(~np.asarray(sol.rigid) & (np.asarray(sol.omega) > 0))
    if el.size == 0:
        return []
    phi = np.abs(np.asarray(sol.phi)[:, el])
    energy = np.einsum("ij,ij->j", phi, np.asarray(abs(stiffness) @ phi))
    lam = np.asarray(sol.omega)[el] ** 2
    rel = 0.5 * _EPS * energy / lam  # on a frequency: half the eigenvalue's
    worst = int(np.argmax(rel))
    if not rel[worst] > ROUNDING_NOTE_REL:
        return []
    n_loose = int(np.count_nonzero(rel > ROUNDING_NOTE_REL))
    return [
        f"the assembled stiffness's rounding bounds {n_loose} elastic frequencies only loosely: "
        f"mode {int(el[worst]) + 1} ({sol.omega[el[worst]] / (2 * np.pi):.4g} Hz) to about "
        f"{100 * rel[worst]:.2g}% (eps |phi|^T |K| |phi| / (2 lambda): the stiffness spans "
        "nearly 1/eps over it, e.g. a very slender bar in many elements); fewer elements or a "
        "stiffer section condition it better"
    ]


def effective_mass(
    mass: Any, phi: np.ndarray, rigid_body: Mapping[str, np.ndarray]
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Participation factors ``L_jd = phi_j^T M r_d`` and effective masses ``L_jd^2``.

    A factor within :data:`EFFECTIVE_MASS_ZERO` times its rounding bound
    ``eps |phi_j|^T |M| |r_d|`` is returned as exactly 0 (an exact zero in exact arithmetic).

    Parameters
    ----------
    mass : ndarray or sparse (n, n)
        kg, kg m, kg m^2 per coordinate unit.
    phi : ndarray (n, m)
        Mass-normalised shapes.
    rigid_body : mapping of direction to ndarray (n,)
        Unit rigid-body vectors (1 m or 1 rad).
    """
    part = {}
    eff = {}
    abs_m = abs(mass)
    abs_phi = np.abs(phi)
    for d, r in rigid_body.items():
        r = np.asarray(r, float)
        lj = np.asarray(phi.T @ (mass @ r)).ravel()
        bound = _EPS * np.asarray(abs_phi.T @ (abs_m @ np.abs(r))).ravel()
        lj = np.where(np.abs(lj) <= EFFECTIVE_MASS_ZERO * bound, 0.0, lj)
        part[d] = lj
        eff[d] = lj**2
    return eff, part


def characteristic_length(structure: Structure) -> float:
    """The station's radius of gyration about its centre of mass, m.

    ``sqrt(trace(I_cm) / (2 m))``: the rms distance of its mass from the centre of mass, the
    length that turns a small rotation into a typical translation of the station's mass.
    """
    m = float(structure.total_mass)
    tr = float(np.trace(np.asarray(structure.inertia_cm, float)))
    if m > 0 and tr > 0:
        return float(np.sqrt(tr / (2.0 * m)))
    return 1.0


def _modal_mass_unit_peak(structure: Structure, phi: np.ndarray) -> np.ndarray:
    """``1 / p^2`` with ``p`` the largest ``max(|u|, L_c |theta|)`` over points and samples."""
    lc = characteristic_length(structure)
    peaks: list[np.ndarray] = []
    n = phi.shape[0]
    for p in structure.points.values():
        t = np.reshape(p.translation, (-1, n)) @ phi
        rot = np.reshape(p.rotation, (-1, n)) @ phi
        peaks.append(np.max(np.abs(t), axis=0))
        peaks.append(lc * np.max(np.abs(rot), axis=0))
    samples = structure.samples
    if samples is not None and hasattr(samples, "peak_translation"):
        # modal-model samples (microg.structure.modal.ModalSamples): the largest translation
        # of each column without forming the (grids, 3, modes) displacements
        peaks.append(np.asarray(samples.peak_translation(phi), float))
        peaks.append(lc * np.asarray(samples.peak_rotation(phi), float))
    elif samples is not None and hasattr(samples, "displacement"):
        # sparse-friendly samples (microg.structure.fem.NodeSamples): translations + rotations
        peaks.append(np.max(np.abs(samples.displacement(phi)), axis=(0, 1)))
        rot_index = getattr(samples, "rot_index", None)
        if rot_index is not None:
            peaks.append(lc * np.max(np.abs(phi[np.asarray(rot_index).ravel()]), axis=0))
    elif samples is not None:
        for attr, scale in (("translation", 1.0), ("rotation", lc)):
            a = getattr(samples, attr, None)
            if a is not None:
                peaks.append(scale * np.max(np.abs(np.reshape(a, (-1, n)) @ phi), axis=0))
    if not peaks:
        peaks.append(np.max(np.abs(phi), axis=0))
    peak = np.max(np.stack(peaks), axis=0)
    # a mass-normalised shape moves some massive point: p > 0 unless every sample misses
    # its mass, and then the shape's own largest coordinate is the reference
    peak = np.where(peak > 0, peak, np.max(np.abs(phi), axis=0))
    peak = np.where(peak > 0, peak, 1.0)
    return 1.0 / peak**2


def _unstable_note(structure: Structure, sol: Eigensolution) -> list[str]:
    """The inertia condition behind an unstable gravity-gradient libration."""
    if not np.any(sol.unstable):
        return []
    ix, iy, iz = np.diag(np.asarray(structure.inertia_cm, float))
    why = []
    if iy < iz:
        why.append(
            f"I_y = {iy:.4g} < I_z = {iz:.4g} kg m^2: the gravity-gradient roll "
            "stiffness 3 w0^2 (I_y - I_z) is negative"
        )
    if ix < iz:
        why.append(
            f"I_x = {ix:.4g} < I_z = {iz:.4g} kg m^2: the gravity-gradient pitch "
            "stiffness 3 w0^2 (I_x - I_z) is negative"
        )
    rate = float(np.max(sol.growth_rate))
    cause = "; ".join(why) if why else "a negative stiffness"
    return [
        f"unstable libration (growth rate {rate:.4g} rad/s, e-folding time {1.0 / rate:.4g} s): "
        f"{cause}; the attitude is stable only with I_z the smallest principal moment "
        "(keel along the local vertical)"
    ]


def solve_modes(
    structure: Structure, n_modes: int | None = None, *, tol: float = RIGID_TOL
) -> Modes:
    """Modes of ``structure``: dense for small models, sparse inverse iteration for large ones.

    Parameters
    ----------
    structure : Structure
    n_modes : int, optional
        Number of lowest modes, rigid ones included (default: all for a dense model,
        :data:`DEFAULT_N_MODES` for a sparse one).
    tol : float
        Relative tolerance for rigid-body detection.

    Returns
    -------
    Modes
    """
    rb = structure.rigid_body
    cand = np.column_stack(list(rb.values())) if rb else None
    labels = structure.dof_labels or None
    flex = None
    if structure.is_sparse:
        from microg.dynamics.eigsparse import solve_sparse  # large frame models

        tree = getattr(structure, "tree", None)
        exact = None
        if tree is not None and all(d in rb for d in tree.free):
            flex = tree.factor()
            exact = (
                np.column_stack([rb[d] for d in tree.free])
                if tree.free
                else np.zeros((structure.n_dof, 0))
            )
        sol = solve_sparse(
            structure.mass,
            structure.stiffness,
            cand,
            n_modes=n_modes or DEFAULT_N_MODES,
            tol=tol,
            labels=labels,
            flexibility=flex,
            rigid_vectors=exact,
        )
    else:
        m, k = structure.dense()
        sol = solve_dense(m, k, cand, tol=tol, labels=labels)
        if n_modes is not None:
            sol = sol.truncate(n_modes)
    eff, part = effective_mass(structure.mass, sol.phi, rb)
    modal_mass = _modal_mass_unit_peak(structure, sol.phi)
    notes = [
        nt
        for nt in sol.notes
        if not nt.endswith("from its equilibrium instead of vibrating about it")
    ]
    notes += _unstable_note(structure, sol)
    if flex is None:  # not from an exact flexibility: the assembled K's rounding bounds them
        notes += _rounding_note(structure.stiffness, sol)
    return Modes(
        omega=sol.omega,
        phi=sol.phi,
        rigid=sol.rigid,
        modal_mass=modal_mass,
        effective_mass=eff,
        participation=part,
        method=structure.method,
        structure=structure,
        unstable=sol.unstable,
        growth_rate=sol.growth_rate,
        notes=tuple(notes),
    )
