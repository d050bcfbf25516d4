"""The computation of a block of cases by linearity: one modal solve, then matrix products.

For a model variant the modes are solved once (:func:`solve_basis`, the steps of
:func:`microg.analysis.run_analysis`: discretise, solve, keep the rigid modes and the elastic
ones up to ``max_freq``).  Only the translation maps of the study's points are kept:
``T_P phi`` (3, m) at every application and observed point.

The response is linear in the force.  A force ``f(t)`` at point P along ``d`` drives mode
``j`` with ``gamma_j f(t)``, ``gamma = (T_P phi)^T d``, and every mode's equation is its own,
so its acceleration is ``gamma_j h_j(t)`` with ``h_j`` the modal acceleration under the unit
modal force ``f(t)`` (:func:`~microg.dynamics.response.modal_pwl_response`, once per force,
damping value and variant: :func:`modal_group`).  At the observed point O, axis ``i``::

    a_i(t) = sum_j (T_O phi)_ij gamma_j h_j(t) = c . h(t),    c_j = (T_O phi)_ij gamma_j,

so every case is one row ``c`` of a coefficient matrix and all of them are ``C @ H``.  The
rigid-body modes share one ``h`` (omega = zeta = 0: double integration of ``f``), so their
coefficients are summed first (one row instead of six, and no cancellation between them).
An isolator (package on a mount, base-excited) is a linear time-invariant filter of the
observed acceleration: it is applied to the rows of ``H`` (the package response to each
``h_j``, :func:`~microg.isolation.timedomain.package_response`), and the same products give
the package's acceleration.

What each case reports, as :func:`microg.environment.metrics.assess` defines it:

* peak and RMS of the magnitude and of each axis, from the sampled record ``C @ H`` (computed
  in blocks of cases and of time, so the (cases, 3, samples) array is never held whole);
* band RMS: the band mean square is a quadratic form of the coefficients,
  ``P_b = c^T Q_b c`` with ``Q_b[j, k]`` the band integral of the cross-periodogram of
  ``h_j`` and ``h_k``, by the one band rule (:func:`~microg.environment.metrics.band_weights`,
  the linear map :func:`~microg.environment.metrics.band_rms` applies to a periodogram).  It is
  held factored, ``Q_b = R_b^T R_b`` with ``R_b`` (m', m') triangular from the band's
  weighted DFT columns (:func:`_band_factors`), so a case costs one product with every
  band's factor and ``P_b = |R_b c|^2`` is a sum of squares (no cancellation between terms);
* exact peaks only where the verdict may depend on them (``[record] peaks = "verdict"``, the
  default: a peak limit between a case's sampled peak and its certified bound), or for every
  case (``"exact"``); the others report the sampled record's peaks (``peak_certified``);
* the verdict: every resolved band of every axis within its limit, no unresolved band's
  estimate above its limit, the peak limit when the requirement has one, and the verified
  transient criteria of the set :func:`~microg.environment.metrics.assess` judges (``iss``);
  the margin is the smallest ``limit / band RMS`` over the resolved bands and axes (the
  assessment's ``worst_band.margin``; NaN when the record resolves no band).

Everything here is a pure function of arrays and small frozen inputs, run with one BLAS
thread, so the serial and the distributed paths give the same bits.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg.dynamics.forces import ForceHistory
from microg.dynamics.pwl import ModalState, check_inputs, prepare
from microg.dynamics.response import combined_modal_force, modal_pwl_response
from microg.environment.metrics import Spectrum, acceleration_psd, band_rms, band_weights
from microg.environment.requirements import Requirement
from microg.environment.requirements import requirement as requirement_by_name
from microg.environment.transient import transient_criteria
from microg.errors import InputError
from microg.isolation.timedomain import IsolatorModel, package_response
from microg.study.peaks import _CELLS, PEAK_RTOL, _exact_peaks, _time_stats
from microg.units import G0

__all__ = [
    "TRANSIENT_SET",
    "PEAK_RTOL",
    "Basis",
    "KernelPlan",
    "BlockWork",
    "ModalGroup",
    "BlockResult",
    "solve_basis",
    "modal_group",
    "compute_block",
    "run_blocks",
    "clear_groups",
    "catalogue_block",
    "kernel_plan",
    "peak_limits",
]

#: the transient criteria set the analysis' assessment judges (assess's default)
TRANSIENT_SET = "iss"


@dataclass(frozen=True)
class Basis:
    """The modal basis of one model variant, at the study's points (what every block needs).

    Attributes
    ----------
    model, variant : labels
    omega : (m,) rad/s of the modes in the response; rigid : (m,) bool; freq_hz : (m,)
    mode_numbers : (m,) 1-based numbers of those modes among all solved
    at_maps : (n_at, 3, m) ``T_P phi`` at each application point, 1/sqrt(kg)
    obs_maps : (n_obs, 3, m) ``T_O phi`` at each observed point
    reach : (n_at, n_dir) fraction of a force along each direction the model can carry
    n_dof, n_solved : size of the structure and number of modes solved
    warnings : lines for the user (missing modes, half-Nyquist)
    catalogue : (force, damping) index -> the frequency-domain assessment of a source
        catalogue at the observed points: ``rms_g`` (n_obs, 3, nb), ``margin``, ``complies``
        (n_obs,)
    """

    model: str
    variant: str
    omega: np.ndarray
    rigid: np.ndarray
    freq_hz: np.ndarray
    mode_numbers: np.ndarray
    at_maps: np.ndarray = field(repr=False)
    obs_maps: np.ndarray = field(repr=False)
    reach: np.ndarray = field(repr=False)
    n_dof: int = 0
    n_solved: int = 0
    warnings: tuple[str, ...] = ()
    catalogue: dict[tuple[int, int], dict[str, np.ndarray]] = field(
        default_factory=dict, repr=False
    )

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (the modes in the response)."""
        return {
            "model": self.model,
            "variant": self.variant,
            "n_dof": self.n_dof,
            "modes_solved": self.n_solved,
            "modes_used": int(self.omega.size),
            "rigid": int(np.sum(self.rigid)),
            "freq_hz": [float(f) for f in self.freq_hz],
            "mode_numbers": [int(k) for k in self.mode_numbers],
            "warnings": list(self.warnings),
        }


@dataclass(frozen=True)
class KernelPlan:
    """What the blocks need besides the basis: small, sent to the workers once.

    Attributes
    ----------
    timepts : (nt,) output times, s
    requirement : the band requirement
    forces : force histories of the force axis (s, N); None for a source catalogue
    damping : damping values of the damping axis
    mounts : isolator of each value of the isolator axis (None: no isolator)
    directions : (n_dir, 3) unit vectors of the direction axis
    catalogues : the source catalogue of each force value (None: a time history)
    peaks : ``"verdict"``: the exact peak is searched only for the cases whose verdict it
        may change (:func:`peak_limits`); ``"exact"``: for every case without an isolator
    """

    timepts: np.ndarray = field(repr=False)
    requirement: Requirement = field(repr=False)
    forces: tuple[ForceHistory | None, ...] = field(repr=False)
    damping: tuple[float, ...]
    mounts: tuple[IsolatorModel | None, ...]
    directions: np.ndarray
    catalogues: tuple[Any, ...] = ()
    peaks: str = "verdict"


@dataclass(frozen=True)
class BlockWork:
    """One block to compute: its id, axis indices, at/observe runs and the case mask."""

    id: int
    index: tuple[int, int, int, int, int]
    at: slice
    observe: slice
    mask: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class ModalGroup:
    """The modal accelerations of one (variant, isolator, damping, force), and their bands.

    Attributes
    ----------
    rows : (m', m) 0/1 map of the modes onto the rows of ``h`` (the rigid modes share one)
    h : (m', nt) acceleration of each row under the unit modal force, m/s^2 per unit gamma
    omega, zeta : (m',) frequency (rad/s) and damping of each row's mode
    gram_r : (m', m') triangular factor of ``h h^T`` (``h^T = q r``): the record's mean square
        of ``c . h`` is ``|r c|^2 / nt``
    exact_peaks : the rows are modal accelerations (no isolator): peaks are the certified exact
        maxima (:func:`~microg.dynamics.response.peak_response`, as the analysis reports);
        behind an isolator they are the package record's sampled maxima (as the isolation
        module's time-domain check reports)
    x : (2, m', nf) real and imaginary DFT of the demeaned rows of ``h``
    scale : (nf,) the periodogram's scale: the PSD of ``c . h`` is ``scale |c . (x0 + i x1)|^2``
    grid : the spectrum's grid (frequencies, df, Nyquist, record length)
    band_r : (nb, m', m') the band operators' triangular factors: the band mean square of
        ``c . h`` is ``|band_r[b] c|^2`` (:func:`_band_factors`)
    limit_g, resolved : (nb,) the requirement's limits (g) and the bands the record resolves
    center_hz, lower_hz, upper_hz : (nb,) the bands kept (lower edge below Nyquist)
    dv : window -> (m', nw) sliding integrals of ``h`` (only for verified integral criteria)
    state : the modal state of the rows under the unit modal force at every force segment's
        start (:func:`~microg.dynamics.pwl.prepare`), shared by every exact-peak search of
        the group; None behind an isolator
    """

    rows: np.ndarray = field(repr=False)
    h: np.ndarray = field(repr=False)
    omega: np.ndarray = field(repr=False)
    zeta: np.ndarray = field(repr=False)
    gram_r: np.ndarray = field(repr=False)
    exact_peaks: bool
    x: np.ndarray = field(repr=False)
    scale: np.ndarray = field(repr=False)
    grid: Spectrum = field(repr=False)
    band_r: np.ndarray = field(repr=False)
    limit_g: np.ndarray
    resolved: np.ndarray
    center_hz: np.ndarray
    lower_hz: np.ndarray
    upper_hz: np.ndarray
    dv: dict[float, np.ndarray] = field(default_factory=dict, repr=False)
    state: ModalState | None = field(default=None, repr=False)


@dataclass(frozen=True)
class BlockResult:
    """The results of one block, shaped (n_at, n_dir, n_obs[, 3][, nb]); NaN outside the plan.

    Attributes
    ----------
    id : block id
    values : variable name -> array
    """

    id: int
    values: dict[str, np.ndarray] = field(repr=False)


# ----------------------------------------------------------------------------- the basis


def solve_basis(
    model: Any,
    *,
    model_label: str,
    variant_label: str,
    method: str,
    plane: str,
    n: int | None,
    n_modes: int | None,
    gravity_gradient: bool,
    max_freq_hz: float,
    dt_s: float,
    at: Sequence[str],
    observe: Sequence[str],
    directions: np.ndarray,
    where: str = "record.dt",
    threads: int = 1,
    catalogues: Sequence[tuple[int, int, Any, float]] = (),
    requirement: str = "iss",
) -> Basis:
    """Discretise and solve one model variant; keep ``T phi`` at the study's points.

    The steps and rules are those of :func:`microg.analysis.run_analysis`: ``n_modes``
    (default :data:`microg.dynamics.modes.DEFAULT_N_MODES`, or
    :data:`microg.analysis.DEFAULT_SOURCE_MODES` when source catalogues are assessed) for
    sparse models, an unstable mode refused, the rigid modes and the elastic ones up to
    ``max_freq_hz``, and a record too coarse for them refused.

    Parameters
    ----------
    model : Station, ModalModel or GraphModel
    model_label, variant_label : labels of the results
    method, plane, n, n_modes, gravity_gradient : discretisation (see :func:`microg.analyze`)
    max_freq_hz : elastic modes up to this frequency (Hz) enter the response
    dt_s : output interval, s (the Nyquist check)
    at, observe : application and observed point names
    directions : (n_dir, 3) force directions (unit vectors)
    where : name of the record's dt in errors
    threads : BLAS threads
    catalogues : (force index, damping index, SourceCatalogue, zeta) to assess in the
        frequency domain on these modes (all the modes solved), with
        :func:`microg.environment.vibratory.assess_sources`
    requirement : the requirement's name (for the catalogues)
    """
    from microg.analysis import DEFAULT_SOURCE_MODES
    from microg.dynamics.modes import DEFAULT_N_MODES, solve_modes
    from microg.structure.discretize import discretize

    with threadpool_limits(threads, user_api="blas"):
        structure = discretize(model, method, plane=plane, n=n, gravity_gradient=gravity_gradient)
        n_req = None
        if structure.is_sparse:
            default = DEFAULT_SOURCE_MODES if catalogues else DEFAULT_N_MODES
            n_req = min(structure.n_dof - 1, n_modes or default)
        modes = solve_modes(structure, n_req)
        unstable = np.asarray(modes.unstable, bool)
        if np.any(unstable):
            k = int(np.flatnonzero(unstable)[0])
            rate = float(np.asarray(modes.growth_rate, float)[k])
            raise InputError(
                f"mode {k + 1} of {model_label}/{variant_label} is unstable (growth rate "
                f"{rate:.3g} rad/s): the transient response grows without "
                "bound, so no verdict can be drawn",
                where=where.replace("record.dt", "study.gravity_gradient"),
                fix="analyse the free-free structure (no gravity gradient), or correct the "
                "inertias",
            )
        warnings: list[str] = []
        used = modes.rigid | (np.asarray(modes.elastic) & (modes.freq_hz <= max_freq_hz))
        if structure.is_sparse and not modes.rigid[-1] and modes.freq_hz[-1] <= max_freq_hz:
            warnings.append(
                f"only {modes.n_modes} modes computed; the highest ({modes.freq_hz[-1]:.3g} Hz) "
                f"is below max_freq {max_freq_hz:g} Hz: modes between are missing from the "
                "response"
            )
        idx = np.flatnonzero(used)
        phi = modes.phi[:, idx]
        freq = modes.freq_hz[idx]
        nyquist = 0.5 / dt_s
        f_top = float(np.max(freq, initial=0.0))
        if f_top >= nyquist:
            raise InputError(
                f"dt = {dt_s:g} s samples at {1 / dt_s:g} Hz, too coarse for the modes in the "
                f"response of {model_label}/{variant_label} (up to {f_top:.3g} Hz, above the "
                f"{nyquist:.3g}-Hz Nyquist frequency)",
                where=where,
                fix=f"use dt <= {0.25 / f_top:.3g} s, or max_freq below {nyquist:.3g} Hz",
            )
        if f_top > 0.5 * nyquist:
            warnings.append(
                f"the highest mode in the response ({f_top:.3g} Hz) is above half the Nyquist "
                f"frequency ({nyquist:.3g} Hz): bands near Nyquist are approximate"
            )
        at_maps = np.stack([structure.point(p).translation @ phi for p in at])
        obs_maps = np.stack([structure.point(p).translation @ phi for p in observe])
        reach = np.empty((len(at), directions.shape[0]))
        for i, p in enumerate(at):
            t = structure.point(p).translation
            proj = t @ np.linalg.pinv(t) if t.size else np.zeros((3, 3))
            reach[i] = np.linalg.norm(directions @ proj.T, axis=1)
        cat: dict[tuple[int, int], dict[str, np.ndarray]] = {}
        if catalogues:
            from microg.environment.vibratory import assess_sources

            req = requirement_by_name(requirement)
            keep = req.bands.lower_hz < nyquist  # the bands of the results
            for i_f, i_z, sources, z in catalogues:
                zeta_all = np.where(modes.rigid, 0.0, z)  # as the analysis passes it
                va = assess_sources(modes, sources, list(observe), req, zeta_all, workers=1)
                cat[(i_f, i_z)] = {
                    "rms_g": np.asarray(va.rms_g, float)[:, :, keep],
                    "margin": np.min(va.margin, axis=(1, 2)),
                    "complies": np.asarray(va.complies, bool),
                }
                warnings.extend(f"{sources.name or 'catalogue'}: {w}" for w in va.warnings)
    return Basis(
        model=model_label,
        variant=variant_label,
        omega=np.asarray(modes.omega[idx], float),
        rigid=np.asarray(modes.rigid[idx], bool),
        freq_hz=np.asarray(freq, float),
        mode_numbers=idx + 1,
        at_maps=at_maps,
        obs_maps=obs_maps,
        reach=reach,
        n_dof=int(structure.n_dof),
        n_solved=int(modes.n_modes),
        warnings=tuple(dict.fromkeys(warnings)),
        catalogue=cat,
    )


# ----------------------------------------------------------------------- the modal group


def _row_map(h: np.ndarray, rigid: np.ndarray) -> np.ndarray:
    """(m', m) map merging the rigid rows of ``h`` (identical: omega = zeta = 0) into one."""
    m = rigid.size
    r = np.flatnonzero(rigid)
    keep = [j for j in range(m) if not rigid[j]]
    merge = r.size > 1 and all(np.array_equal(h[r[0]], h[j]) for j in r[1:])
    groups = ([list(r)] if merge else [[j] for j in r]) + [[j] for j in keep]
    groups.sort(key=lambda g: g[0])
    rows = np.zeros((len(groups), m))
    for i, g in enumerate(groups):
        rows[i, g] = 1.0
    return rows


def _row_dft(h: np.ndarray, nk: int) -> np.ndarray:
    """DFT bins ``0 .. nk - 1`` of each demeaned row of ``h``, each bin to its own scale.

    An FFT's rounding is relative to the whole row (``eps |x|`` in every bin), so a row's
    large low-frequency content blurs its small high-frequency bins, which a combination of
    rows keeps (the analysis transforms the combined record).  The first differences
    ``d_n = x_(n+1) - x_n`` (``n < N - 1``; exact where neighbours are within a factor of 2,
    Sterbenz) carry the high frequencies without that content, and the circular difference's
    DFT is ``(e^(i theta_k) - 1) X_k`` (``theta_k = 2 pi k / N``), so

        X_k = (D_k + J e^(i theta_k)) / (e^(i theta_k) - 1),   J = x_0 - x_(N-1),

    with ``e^(i theta) - 1 = -2 sin^2(theta / 2) + i sin theta`` (no cancellation).  Each bin
    takes the form with the smaller rounding bound: the differences' where
    ``|e^(i theta_k) - 1| |x| > |d| + |J|``, the direct FFT of the demeaned row elsewhere.
    Against an extended-precision FFT of the same rows (one study group, 25 rows x 20,001
    samples): the band energies agree to 1.4e-13 (1.1e-12 for the direct FFT alone), at a
    tenth of its cost.

    Parameters
    ----------
    h : (m, N) rows, any unit
    nk : bins kept (``<= N // 2 + 1``)
    """
    n = h.shape[1]
    x = h - h.mean(axis=1, keepdims=True)
    direct = np.fft.rfft(x, axis=1)[:, :nk]
    d = np.zeros_like(h)
    d[:, :-1] = h[:, 1:] - h[:, :-1]
    jump = h[:, 0] - h[:, -1]
    theta = 2.0 * np.pi * np.arange(nk) / n
    z = -2.0 * np.sin(0.5 * theta) ** 2 + 1j * np.sin(theta)
    use = (
        np.abs(z)[None, :] * np.linalg.norm(x, axis=1)[:, None]
        > (np.linalg.norm(d, axis=1) + np.abs(jump))[:, None]
    )
    use[:, 0] = False  # the mean: the direct FFT's (zero to rounding)
    if not use.any():
        return direct
    dk = np.fft.rfft(d, axis=1)[:, :nk] + jump[:, None] * np.exp(1j * theta)[None, :]
    z[0] = 1.0
    return np.where(use, dk / z[None, :], direct)


def _spectra(
    t: np.ndarray, h: np.ndarray, req: Requirement
) -> tuple[np.ndarray, np.ndarray, Spectrum, Any]:
    """Real and imaginary DFT of the demeaned rows, the periodogram's scale, and the grid.

    ``psd = scale * |c . X|^2`` is the periodogram of the record ``c . h`` (the DFT is
    linear), with ``scale`` the periodogram's own: the PSD of a unit impulse, whose DFT is 1
    at every bin.  Only the bins up to the top band's upper edge are kept: the band rule's
    running sums over them are the same, bit for bit, as over the whole spectrum.
    """
    base = acceleration_psd(t, h[:1])  # the grid: freq, df, Nyquist, record length
    ref = band_rms(base, req.bands)  # the bands kept (below Nyquist) and which are resolved
    top = float(np.minimum(ref.bands.upper_hz, base.nyquist_hz).max(initial=0.0))
    nk = min(base.freq_hz.size, int(np.ceil(top / base.df_hz + 0.5)) + 2)
    X = _row_dft(h, nk)
    xr = np.ascontiguousarray(X.real)
    xi = np.ascontiguousarray(X.imag)
    delta = np.zeros(t.size)
    delta[0] = 1.0
    scale = acceleration_psd(t, delta, demean=False).psd[0, :nk]
    grid = Spectrum(base.freq_hz[:nk], base.psd[:, :nk], base.df_hz, base.nyquist_hz,
                    base.method, base.record_s)  # fmt: skip
    return np.stack([xr, xi]), scale, grid, ref


def _band_factors(x: np.ndarray, scale: np.ndarray, grid: Spectrum, ref: Any) -> np.ndarray:
    """(nb, m', m') triangular factors ``R_b`` of the band operators: ``P_b = |R_b c|^2``.

    The band rule is linear in the periodogram, ``P_b = sum_k W[b, k] psd_k``
    (:func:`~microg.environment.metrics.band_weights`, the integration
    :func:`~microg.environment.metrics.band_rms` applies), and the periodogram of ``c . h`` is
    ``scale_k ((c . x0_k)^2 + (c . x1_k)^2)``, so ``P_b = |L_b^T c|^2`` with the columns
    ``sqrt(W[b, k] scale_k) x0_k`` and ``... x1_k`` over the bins of band ``b``.  ``R_b`` is
    the triangular factor of ``L_b^T = Q R_b`` (as the record's ``gram_r``): the same sum of
    squares, with ``m'`` terms instead of two per bin, and no squared cancellation.
    """
    m = x.shape[1]
    w = band_weights(grid.freq_hz, grid.df_hz, grid.nyquist_hz, ref.bands).tocsr()
    out = np.zeros((w.shape[0], m, m))
    for b in range(w.shape[0]):
        k = w.indices[w.indptr[b] : w.indptr[b + 1]]
        wb = w.data[w.indptr[b] : w.indptr[b + 1]]
        if k.size == 0:
            continue
        if np.any(wb < 0):  # not a sum of squares: the band rule must have changed
            raise AssertionError("band weights must be >= 0")
        root = np.sqrt(wb * scale[k])
        lt = np.concatenate([x[0][:, k] * root, x[1][:, k] * root], axis=1).T  # (2 nk_b, m')
        r = np.asarray(np.linalg.qr(lt, mode="r"))
        out[b, : r.shape[0]] = r
    return out


def modal_group(
    basis: Basis, plan: KernelPlan, isolator: int, damping: int, force: int
) -> ModalGroup:
    """The modal accelerations and band matrix of one (variant, isolator, damping, force).

    Parameters
    ----------
    basis : the variant's Basis
    plan : KernelPlan
    isolator, damping, force : indices into the plan's axes
    """
    t = plan.timepts
    f = plan.forces[force]
    assert f is not None
    zeta = np.where(basis.rigid, 0.0, plan.damping[damping])
    m = basis.omega.size
    unit = np.outer(np.ones(m), np.asarray(f.force, float))
    h_all = modal_pwl_response(basis.omega, zeta, f.timepts, unit, t).eta_ddot
    rows = _row_map(h_all, basis.rigid)
    first = np.argmax(rows > 0, axis=1)
    h = np.ascontiguousarray(h_all[first])
    del h_all
    mount = plan.mounts[isolator]
    if mount is not None:
        h = np.stack([package_response(mount, t, row).package_accel for row in h])
    req = plan.requirement
    x, scale, grid, ref = _spectra(t, h, req)
    keep = req.bands.lower_hz < grid.nyquist_hz
    dv: dict[float, np.ndarray] = {}
    crit = transient_criteria(TRANSIENT_SET)
    windows = sorted(
        {float(c.window_s) for c in crit.criteria if c.verified and c.window_s is not None}
    )
    if windows:
        from microg.environment.metrics import integrated_acceleration

        for w in windows:
            assert w is not None
            dv[float(w)] = integrated_acceleration(t, h, w).delta_v
    # mean square of c . h over the record: |r c|^2 / nt with h^T = q r (no squared cancellation)
    gram_r = np.asarray(np.linalg.qr(h.T, mode="r"))
    omega_r, zeta_r = np.asarray(basis.omega[first], float), np.asarray(zeta[first], float)
    state = None
    if mount is None:  # the exact-peak search's preparation, as peak_response makes it
        ones = np.ones(omega_r.size)
        tb, pf = combined_modal_force(np.eye(omega_r.size), [(f, ones)])
        om, ze, tb, pf, _ = check_inputs(omega_r, zeta_r, tb, pf, t[:1])
        state = prepare(om, ze, tb, pf)
    return ModalGroup(
        rows=rows,
        h=h,
        omega=omega_r,
        zeta=zeta_r,
        gram_r=gram_r,
        exact_peaks=mount is None,
        x=x,
        scale=scale,
        grid=grid,
        band_r=_band_factors(x, scale, grid, ref),
        limit_g=np.asarray(req.limit_g, float)[keep],
        resolved=np.asarray(ref.resolved, bool),
        center_hz=np.asarray(ref.bands.center_hz, float),
        lower_hz=np.asarray(ref.bands.lower_hz, float),
        upper_hz=np.asarray(ref.bands.upper_hz, float),
        dv=dv,
        state=state,
    )


# ------------------------------------------------------------------------------ a block


def _coefficients(
    basis: Basis, plan: KernelPlan, group: ModalGroup, work: BlockWork, force: ForceHistory
) -> tuple[np.ndarray, np.ndarray]:
    """(cells, 3, m') coefficients of the cases in the block's mask, and the cell indices."""
    at_maps = basis.at_maps[work.at]  # (na, 3, m)
    obs_maps = basis.obs_maps[work.observe]  # (no, 3, m)
    dirs = plan.directions
    if force.direction is not None:  # a force's own direction wins (as in the analysis)
        dirs = np.broadcast_to(np.asarray(force.direction, float), dirs.shape)
    cells = np.argwhere(work.mask)  # (cells, 3): a, d, o
    gamma = np.einsum("aim,di->adm", at_maps, dirs)  # (na, nd, m): (T_P phi)^T d
    c_full = obs_maps[cells[:, 2]] * gamma[cells[:, 0], cells[:, 1]][:, None, :]
    return c_full @ group.rows.T, cells


def _rms(c: np.ndarray, gram_r: np.ndarray, nt: int) -> dict[str, np.ndarray]:
    """RMS over the record of the magnitude and of each axis of ``c @ h``, m/s^2."""
    y = c @ gram_r.T  # (cells, 3, r)
    ms_axis = np.einsum("cak,cak->ca", y, y) / nt
    return {"rms": np.sqrt(ms_axis.sum(axis=1)), "rms_axis": np.sqrt(ms_axis)}


def _band_rms(c: np.ndarray, group: ModalGroup, req: Requirement) -> np.ndarray:
    """(cells, 3, nb) band RMS of the records ``c @ h``, m/s^2.

    ``sqrt(|R_b c|^2)`` with the group's band factors (:func:`_band_factors`): one product of
    the coefficients with every band's factor.
    """
    n, m = c.shape[0], c.shape[2]
    r = group.band_r
    nb = r.shape[0]
    rt = r.reshape(nb * m, m).T  # (m', nb m')
    out = np.empty((n, 3, nb))
    for c0 in range(0, n, _CELLS):
        cc = c[c0 : c0 + _CELLS]
        k = cc.shape[0]
        y = (cc.reshape(3 * k, m) @ rt).reshape(3 * k, nb, m)
        out[c0 : c0 + k] = np.sqrt(np.einsum("abj,abj->ab", y, y)).reshape(k, 3, nb)
    return out


def _integrals(c: np.ndarray, dv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Max |integral| per axis (cells, 3) and of the vector (cells,) over windows, m/s."""
    n = c.shape[0]
    ax = np.zeros((n, 3))
    mag = np.zeros(n)
    for c0 in range(0, n, _CELLS):
        cc = c[c0 : c0 + _CELLS]
        k = cc.shape[0]
        v = (cc.reshape(3 * k, -1) @ dv).reshape(k, 3, -1)
        ax[c0 : c0 + k] = np.max(np.abs(v), axis=2)
        mag[c0 : c0 + k] = np.max(np.sqrt(np.sum(v * v, axis=1)), axis=1)
    return ax, mag


def _verdict(
    group: ModalGroup,
    req: Requirement,
    rms_g: np.ndarray,
    peak_g: np.ndarray,
    transient_ok: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Compliance and worst margin of each cell (the rule of the assessment)."""
    limit = group.limit_g
    judged = group.resolved
    with np.errstate(divide="ignore", invalid="ignore"):
        margin = np.where(rms_g > 0, limit / np.where(rms_g > 0, rms_g, 1.0), np.inf)
    if np.any(judged):
        worst = np.min(margin[:, :, judged], axis=(1, 2))
        complies = np.all(rms_g[:, :, judged] <= limit[judged], axis=(1, 2))
    else:
        worst = np.full(rms_g.shape[0], np.nan)
        complies = np.zeros(rms_g.shape[0], bool)
    over = np.any((rms_g > limit)[:, :, ~judged], axis=(1, 2))
    complies &= ~over
    if req.peak_limit_g is not None:
        complies &= peak_g <= req.peak_limit_g
    return complies & transient_ok, worst


def peak_limits(req: Requirement) -> tuple[list[float], list[float]]:
    """The peak limits the verdict compares with, m/s^2: (magnitude's, largest axis value's).

    The requirement's peak limit, and the verified transient criteria of
    :data:`TRANSIENT_SET` on the peak (not the integral ones).
    """
    mag: list[float] = [] if req.peak_limit_g is None else [float(req.peak_limit_g) * G0]
    axis: list[float] = []
    for cr in transient_criteria(TRANSIENT_SET).criteria:
        if cr.verified and not cr.is_integral:
            (axis if cr.quantity.endswith("_axis") else mag).append(float(cr.limit))
    return mag, axis


def compute_block(
    basis: Basis, plan: KernelPlan, group: ModalGroup, work: BlockWork
) -> BlockResult:
    """Every case of one block (see the module docstring); NaN/False outside its mask.

    Parameters
    ----------
    basis : the variant's Basis
    plan : KernelPlan
    group : the block's ModalGroup (its isolator, damping and force)
    work : the block
    """
    force = plan.forces[work.index[4]]
    assert force is not None
    c, cells = _coefficients(basis, plan, group, work, force)
    if group.exact_peaks:
        limits = None if plan.peaks == "exact" else peak_limits(plan.requirement)
        stats = _exact_peaks(c, group, force, plan.timepts, limits)
    else:
        stats = _time_stats(c, group.h)
        stats["certified"] = np.zeros(c.shape[0], bool)
    stats.update(_rms(c, group.gram_r, plan.timepts.size))
    rms_g = _band_rms(c, group, plan.requirement) / G0
    peak_g = stats["peak"] / G0
    ok = np.ones(c.shape[0], bool)
    crit = transient_criteria(TRANSIENT_SET)
    integ: dict[float, tuple[np.ndarray, np.ndarray]] = {}
    for cr in crit.criteria:
        if not cr.verified:
            continue
        if cr.is_integral:
            assert cr.window_s is not None
            w = float(cr.window_s)
            if w not in integ:
                integ[w] = _integrals(c, group.dv[w])
            ax_v, mag_v = integ[w]
        else:
            ax_v, mag_v = stats["peak_axis"], stats["peak"]
        value = np.max(ax_v, axis=1) if cr.quantity.endswith("_axis") else mag_v
        ok &= value <= cr.limit
    complies, margin = _verdict(group, plan.requirement, rms_g, peak_g, ok)
    shape = work.mask.shape
    nb = rms_g.shape[2]

    def scatter(values: np.ndarray, fill: Any, tail: tuple[int, ...] = ()) -> np.ndarray:
        out = np.full((*shape, *tail), fill, dtype=values.dtype)
        out[cells[:, 0], cells[:, 1], cells[:, 2]] = values
        return out

    values = {
        "peak_accel_g": scatter(peak_g, np.nan),
        "rms_accel_g": scatter(stats["rms"] / G0, np.nan),
        "peak_accel_g_axis": scatter(stats["peak_axis"] / G0, np.nan, (3,)),
        "rms_accel_g_axis": scatter(stats["rms_axis"] / G0, np.nan, (3,)),
        "band_rms_g": scatter(rms_g, np.nan, (3, nb)),
        "margin": scatter(margin, np.nan),
        "complies": scatter(complies, False),
        "peak_certified": scatter(stats["certified"], False),
        "computed": scatter(np.ones(c.shape[0], bool), False),
    }
    return BlockResult(work.id, values)


def catalogue_block(basis: Basis, plan: KernelPlan, work: BlockWork) -> BlockResult:
    """A block of a source catalogue: its frequency-domain assessment at each observed point.

    The catalogue's sources carry their own points and directions, so every application point
    and direction of the block holds the same values; a frequency-domain assessment has no
    time record, so the peak and RMS are NaN.
    """
    res = basis.catalogue[(work.index[4], work.index[3])]
    shape = work.mask.shape
    m = work.mask
    obs = np.arange(work.observe.start, work.observe.stop)
    nb = res["rms_g"].shape[2]

    def spread(v: np.ndarray, fill: Any, tail: tuple[int, ...] = ()) -> np.ndarray:
        full = np.broadcast_to(v[obs][None, None], (*shape, *tail)).copy()
        full[~m] = fill
        return full

    nan = np.full(shape, np.nan)
    values = {
        "peak_accel_g": nan.copy(),
        "rms_accel_g": nan.copy(),
        "peak_accel_g_axis": np.full((*shape, 3), np.nan),
        "rms_accel_g_axis": np.full((*shape, 3), np.nan),
        "band_rms_g": spread(res["rms_g"], np.nan, (3, nb)),
        "margin": spread(res["margin"], np.nan),
        "complies": spread(res["complies"], False),
        "peak_certified": np.zeros(shape, bool),
        "computed": m.copy(),
    }
    return BlockResult(work.id, values)


#: modal groups kept between tasks (a process computes each group's shared work once)
_GROUPS_KEPT = 4
_GROUPS: OrderedDict[tuple[int, int, tuple[int, ...]], tuple[Basis, KernelPlan, ModalGroup]] = (
    OrderedDict()
)
_GROUPS_LOCK = threading.Lock()


def _group(basis: Basis, plan: KernelPlan, key: tuple[int, ...]) -> ModalGroup:
    """:func:`modal_group`, kept for the next task of the same basis and plan in this process.

    A group depends only on its basis, plan and indices, so a kept one gives the same bits; the
    entry holds the basis and plan, so their ids name them while it is kept.
    """
    k = (id(basis), id(plan), key)
    with _GROUPS_LOCK:
        hit = _GROUPS.get(k)
        if hit is not None and hit[0] is basis and hit[1] is plan:
            _GROUPS.move_to_end(k)
            return hit[2]
    group = modal_group(basis, plan, *key)
    with _GROUPS_LOCK:
        _GROUPS[k] = (basis, plan, group)
        while len(_GROUPS) > _GROUPS_KEPT:
            _GROUPS.popitem(last=False)
    return group


def clear_groups() -> None:
    """Forget the modal groups kept by :func:`run_blocks` (a sweep's end frees them)."""
    with _GROUPS_LOCK:
        _GROUPS.clear()


def run_blocks(
    basis: Basis, plan: KernelPlan, works: Sequence[BlockWork], threads: int = 1
) -> list[BlockResult]:
    """Compute a batch of blocks of one variant (a task): each modal group once per process.

    Parameters
    ----------
    basis : the variant's Basis (the blocks' model and variant)
    plan : KernelPlan
    works : blocks, in storage order (consecutive blocks share their group)
    threads : BLAS threads (1: the same bits in every process)
    """
    out = []
    key = None
    group: ModalGroup | None = None
    with threadpool_limits(threads, user_api="blas"):
        for w in works:
            if plan.forces[w.index[4]] is None:
                out.append(catalogue_block(basis, plan, w))
                continue
            k = w.index[2:5]
            if k != key:
                group = _group(basis, plan, k)
                key = k
            assert group is not None
            out.append(compute_block(basis, plan, group, w))
    return out


def kernel_plan(study: Any) -> KernelPlan:
    """The KernelPlan of a :class:`~microg.study.cases.Study` (its record's ``peaks`` rule)."""
    return KernelPlan(
        timepts=study.record.timepts,
        requirement=requirement_by_name(study.record.requirement),
        forces=tuple(f.history for f in study.forces),
        damping=tuple(study.damping),
        mounts=tuple(i.mount for i in study.isolators),
        directions=np.array([d.vector for d in study.directions], float),
        catalogues=tuple(f.catalogue for f in study.forces),
        peaks=study.record.peaks,
    )
