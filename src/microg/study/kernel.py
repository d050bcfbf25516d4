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
  ``h_j`` and ``h_k``.  ``Q_b`` is obtained with the one band rule,
  :func:`~microg.environment.metrics.band_rms`, applied to periodogram rows of
  ``h_j / s_j +- h_k / s_k`` (polarisation: ``Re(X conj Y) = (|X + Y|^2 - |X - Y|^2) / 4``;
  ``s_j`` scales each row to unit power so that no row dwarfs another);
* the verdict: every resolved band of every axis within its limit, no unresolved band's
  estimate above its limit, the peak limit when the requirement has one, and the verified
  transient criteria of the set :func:`~microg.environment.metrics.assess` judges (``iss``);
  the margin is the smallest ``limit / band RMS`` over the resolved bands and axes (the
  assessment's ``worst_band.margin``; NaN when the record resolves no band).

Everything here is a pure function of arrays and small frozen inputs, run with one BLAS
thread, so the serial and the distributed paths give the same bits.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from microg.dynamics.forces import ForceHistory
from microg.dynamics.peaks import certified_peaks
from microg.dynamics.pwl import ModalState, check_inputs, prepare
from microg.dynamics.response import combined_modal_force, modal_pwl_response
from microg.environment.metrics import Spectrum, acceleration_psd, band_rms
from microg.environment.requirements import Requirement
from microg.environment.requirements import requirement as requirement_by_name
from microg.environment.transient import transient_criteria
from microg.errors import InputError
from microg.isolation.timedomain import IsolatorModel, package_response
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
    "catalogue_block",
    "kernel_plan",
    "peak_limits",
]

#: the transient criteria set the analysis' assessment judges (assess's default)
TRANSIENT_SET = "iss"
#: cases per product ``C @ H`` and samples per time chunk (about 12 MB of work array)
_CELLS = 512
_TIME = 1024
#: cases per call of the exact-peak search on one window
_PEAK_CELLS = 8
#: candidate runs closer than this many samples are searched as one window
_MERGE = 200
#: longest window of one batch of cases, samples
_SPAN = 2000
#: relative tolerance of the exact peaks: well inside the analysis' own certified 1e-9
PEAK_RTOL = 1e-10
#: refinement rounds of the exact-peak search (peak_response's default)
_PEAK_ROUNDS = 30


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
    # extended precision: an FFT's rounding is relative to the whole row, and a row's large
    # low-frequency content would otherwise blur the small high-frequency bins that a
    # combination of rows keeps (the analysis transforms the combined record): band RMS
    # agree with the analysis' to ~1e-12 this way, ~1e-10 with a double-precision FFT
    x = h.astype(np.longdouble)
    x -= x.mean(axis=1, keepdims=True)
    X = np.fft.rfft(x, axis=1)[:, :nk]
    xr = np.ascontiguousarray(X.real, dtype=float)
    xi = np.ascontiguousarray(X.imag, dtype=float)
    delta = np.zeros(t.size)
    delta[0] = 1.0
    scale = acceleration_psd(t, delta, demean=False).psd[0, :nk]
    grid = Spectrum(base.freq_hz[:nk], base.psd[:, :nk], base.df_hz, base.nyquist_hz,
                    base.method, base.record_s)  # fmt: skip
    return np.stack([xr, xi]), scale, grid, ref


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


def _time_stats(c: np.ndarray, h: np.ndarray) -> dict[str, np.ndarray]:
    """Sampled peaks (magnitude and per axis) of the records ``c @ h``, m/s^2.

    In blocks of cases and of time, so the (cases, 3, samples) array is never held whole.
    Also the largest squared magnitude and squared axis value in each time chunk of
    :data:`_TIME` samples (``chunk_f2`` (n, nc), ``chunk_a2`` (n, 3, nc)), m^2/s^4.
    """
    n, nt = c.shape[0], h.shape[1]
    nc = -(-nt // _TIME)
    chunk_f2 = np.zeros((n, nc))
    chunk_a2 = np.zeros((n, 3, nc))
    for c0 in range(0, n, _CELLS):
        cc = c[c0 : c0 + _CELLS]
        k = cc.shape[0]
        flat = cc.reshape(3 * k, -1)
        buf = np.empty((3 * k, min(_TIME, nt)))
        mag2 = np.empty((k, min(_TIME, nt)))
        for j, t0 in enumerate(range(0, nt, _TIME)):
            w = min(_TIME, nt - t0)
            a = buf[:, :w]
            np.matmul(flat, h[:, t0 : t0 + w], out=a)
            np.multiply(a, a, out=a)
            a3 = a.reshape(k, 3, w)
            m2 = mag2[:, :w]
            np.add(a3[:, 0], a3[:, 1], out=m2)
            m2 += a3[:, 2]
            chunk_f2[c0 : c0 + k, j] = m2.max(axis=1)
            chunk_a2[c0 : c0 + k, :, j] = a3.max(axis=2)
    return {
        "peak": np.sqrt(chunk_f2.max(axis=1)),
        "peak_axis": np.sqrt(chunk_a2.max(axis=2)),
        "chunk_f2": chunk_f2,
        "chunk_a2": chunk_a2,
    }


def _segment_bounds(
    group: ModalGroup, force: ForceHistory, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Bounds of |h|, |h'|, |h''| of every row on every force segment, each (m', K), and starts.

    Within a segment the unit force is linear, so each modal acceleration obeys the free
    equation ``a'' + 2 sigma a' + omega^2 a = 0``, whose energy ``E = a'^2 + omega^2 a^2`` does
    not increase: ``|a'| <= sqrt(E_k)``, ``|a| <= min(sqrt(E_k)/omega, |a_k| + sqrt(E_k) tau)``,
    ``|a''| <= 2 sigma |a'| + omega^2 |a|`` (rigid rows: ``a = a_k + s tau``, omega = 0).  The
    state at a segment start (``a_k``, and the jerk ``s_k - 2 sigma a_k - omega^2 v_k``) comes
    from :func:`~microg.dynamics.response.modal_pwl_response`.  These are the bounds with which
    :func:`~microg.dynamics.response.peak_response` certifies its search.
    """
    tb, fb = force.breakpoints
    starts = np.unique(tb)
    m = group.omega.size
    r = modal_pwl_response(group.omega, group.zeta, tb, np.outer(np.ones(m), fb), starts)
    a_k, v_k = r.eta_ddot, r.eta_dot  # (m', K), right-continuous at the starts
    right = np.searchsorted(tb, starts, side="right") - 1  # last value at each start
    left = np.searchsorted(tb, starts, side="left")  # first value at each start
    slope = np.zeros(starts.size)
    if starts.size > 1:
        slope[:-1] = (fb[left[1:]] - fb[right[:-1]]) / np.diff(starts)
    w = group.omega[:, None]
    sig = (group.zeta * group.omega)[:, None]
    jerk = slope[None, :] - 2.0 * sig * a_k - w * w * v_k
    sqrt_e = np.hypot(jerk, w * a_k)
    seg_end = np.r_[starts[1:], np.inf]
    tau = np.maximum(np.minimum(seg_end, t[-1]) - starts, 0.0)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        by_energy = np.where(w > 0, sqrt_e / w, np.inf)
    b0 = np.minimum(by_energy, np.abs(a_k) + sqrt_e * tau)
    b1 = sqrt_e
    b2 = 2.0 * sig * b1 + w * w * b0
    return b0, b1, b2, starts


def _candidates(
    c: np.ndarray,
    h: np.ndarray,
    t: np.ndarray,
    bounds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    sampled: dict[str, np.ndarray],
) -> list[np.ndarray]:
    """For each case, the sample intervals whose exact maximum may exceed the sampled one.

    An interval of length ``dt`` inside one force segment cannot exceed the larger of its end
    values by more than ``M2 dt^2 / 8`` (``M2`` bounds the second derivative of the axis, or of
    ``|a|^2``, on the segment).  An interval holding a force breakpoint ``b`` is split there:
    each part cannot exceed its end sample by more than ``M1`` times its length (``M1`` bounds
    the first derivative on its segment), which covers both one-sided limits at ``b``.  Only
    the time chunks whose sampled maximum plus the largest such slack reaches the sampled
    peak are examined sample by sample.
    """
    b0, b1, b2, starts = bounds
    n, nt = c.shape[0], t.size
    dt = float(t[1] - t[0])
    seg = np.searchsorted(starts, t[:-1], side="right") - 1  # segment of each interval
    live = seg >= 0
    segc = np.maximum(seg, 0)
    # intervals holding a breakpoint strictly inside or at their right end
    brk = np.searchsorted(t, starts, side="left") - 1
    ok = (brk >= 0) & (brk < nt - 1)
    brk, bt = brk[ok], starts[ok]
    seg_before = np.searchsorted(starts, bt, side="left") - 1  # the segment ending at b
    seg_after = np.searchsorted(starts, bt, side="right") - 1  # the segment starting at b
    lo_f = sampled["peak"] ** 2 * (1.0 - 1e-9)
    lo_ax = sampled["peak_axis"] * (1.0 - 1e-9)
    ac = np.abs(c)
    B0, B1, B2 = ac @ b0, ac @ b1, ac @ b2  # (n, 3, K)
    bF = 2.0 * np.sum(B1 * B1 + B0 * B2, axis=1)  # (n, K): bound of |(|a|^2)''|
    dF = 2.0 * np.sum(B0 * B1, axis=1)  # (n, K): bound of |(|a|^2)'|
    q = dt * dt / 8.0
    slack_f = bF.max(axis=1) * q  # the largest slack of any interval inside a segment
    slack_a = B2.max(axis=2) * q
    out: list[list[np.ndarray]] = [[] for _ in range(n)]
    # chunk j holds intervals [j T, (j + 1) T): their right ends reach into the next chunk
    nc = sampled["chunk_f2"].shape[1]
    cf = np.maximum(sampled["chunk_f2"], np.r_["1", sampled["chunk_f2"][:, 1:], np.zeros((n, 1))])
    ca = np.maximum(sampled["chunk_a2"], np.concatenate(
        [sampled["chunk_a2"][:, :, 1:], np.zeros((n, 3, 1))], axis=2))  # fmt: skip
    need = (cf + slack_f[:, None] > lo_f[:, None]) | np.any(
        np.sqrt(ca) + slack_a[:, :, None] > lo_ax[:, :, None], axis=1
    )
    for j in range(nc):
        cases = np.flatnonzero(need[:, j])
        i0, i1 = j * _TIME, min((j + 1) * _TIME, nt - 1)  # intervals i0 .. i1 - 1
        if cases.size == 0 or i1 <= i0:
            continue
        for c0 in range(0, cases.size, _CELLS):
            sel = cases[c0 : c0 + _CELLS]
            k = sel.size
            a = (c[sel].reshape(3 * k, -1) @ h[:, i0 : i1 + 1]).reshape(k, 3, -1)
            aa = np.abs(a)
            F = np.einsum("kat,kat->kt", a, a)
            sg = segc[i0:i1]
            uf = np.maximum(F[:, :-1], F[:, 1:]) + bF[sel][:, sg] * q
            ua = np.maximum(aa[:, :, :-1], aa[:, :, 1:]) + B2[sel][:, :, sg] * q
            cand = (uf > lo_f[sel, None]) | np.any(ua > lo_ax[sel, :, None], axis=1)
            cand &= live[None, i0:i1]
            for r, case in enumerate(sel):
                idx = np.flatnonzero(cand[r])
                if idx.size:
                    out[case].append(idx + i0)
    if brk.size:  # the intervals holding a breakpoint, for every case
        left_len, right_len = bt - t[brk], t[brk + 1] - bt
        sb, sa, pre = np.maximum(seg_before, 0), seg_after, seg_before >= 0
        for c0 in range(0, n, _CELLS):
            sel = np.arange(c0, min(c0 + _CELLS, n))
            k = sel.size
            ends = np.r_[brk, brk + 1]
            a = (c[sel].reshape(3 * k, -1) @ h[:, ends]).reshape(k, 3, -1)
            al, ar = a[:, :, : brk.size], a[:, :, brk.size :]
            Fl, Fr = np.sum(al * al, axis=1), np.sum(ar * ar, axis=1)
            ufl = np.where(pre, Fl + dF[sel][:, sb] * left_len, 0.0)
            ufr = Fr + dF[sel][:, sa] * right_len
            ual = np.where(pre, np.abs(al) + B1[sel][:, :, sb] * left_len, 0.0)
            uar = np.abs(ar) + B1[sel][:, :, sa] * right_len
            cand = (np.maximum(ufl, ufr) > lo_f[sel, None]) | np.any(
                np.maximum(ual, uar) > lo_ax[sel, :, None], axis=1
            )
            for r, case in enumerate(sel):
                if cand[r].any():
                    out[case].append(brk[cand[r]])
    return [np.unique(np.concatenate(x)) if x else np.zeros(0, int) for x in out]


def _peak_upper(
    c: np.ndarray,
    t: np.ndarray,
    bounds: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    sampled: dict[str, np.ndarray],
    h: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Certified upper bounds of the exact peaks, magnitude (n,) and per axis (n, 3), m/s^2.

    The rule of :func:`_candidates` over the whole record at once: no interval inside a force
    segment exceeds the sampled maximum by more than the case's largest ``M2 dt^2 / 8``, and
    each part of an interval holding a breakpoint stays within ``M1`` times its length of its
    end sample.
    """
    b0, b1, b2, starts = bounds
    nt = t.size
    ac = np.abs(c)
    B0, B1, B2 = ac @ b0, ac @ b1, ac @ b2  # (n, 3, K)
    q = float(t[1] - t[0]) ** 2 / 8.0 if nt > 1 else 0.0
    up_f = sampled["peak"] ** 2 + 2.0 * np.sum(B1 * B1 + B0 * B2, axis=1).max(axis=1) * q
    up_a = sampled["peak_axis"] + B2.max(axis=2) * q
    brk = np.searchsorted(t, starts, side="left") - 1
    ok = (brk >= 0) & (brk < nt - 1)
    brk, bt = brk[ok], starts[ok]
    if brk.size:
        seg_before = np.searchsorted(starts, bt, side="left") - 1
        seg_after = np.searchsorted(starts, bt, side="right") - 1
        left_len, right_len = bt - t[brk], t[brk + 1] - bt
        sb, pre = np.maximum(seg_before, 0), seg_before >= 0
        dF = 2.0 * np.sum(B0 * B1, axis=1)
        n = c.shape[0]
        a = (c.reshape(3 * n, -1) @ h[:, np.r_[brk, brk + 1]]).reshape(n, 3, -1)
        al, ar = a[:, :, : brk.size], a[:, :, brk.size :]
        ufl = np.where(pre, np.sum(al * al, axis=1) + dF[:, sb] * left_len, 0.0)
        ufr = np.sum(ar * ar, axis=1) + dF[:, seg_after] * right_len
        ual = np.where(pre, np.abs(al) + B1[:, :, sb] * left_len, 0.0)
        uar = np.abs(ar) + B1[:, :, seg_after] * right_len
        up_f = np.maximum(up_f, np.maximum(ufl, ufr).max(axis=1))
        up_a = np.maximum(up_a, np.maximum(ual, uar).max(axis=2))
    return np.sqrt(up_f), up_a


def _straddles(value: np.ndarray, upper: np.ndarray, limits: Sequence[float]) -> np.ndarray:
    """Cases whose exact peak, known to lie in ``[value, upper]``, may fall on either side of
    a limit (widened by 1e-9 relative: the g conversion's rounding cannot flip a verdict)."""
    need = np.zeros(value.shape, bool)
    for lim in limits:
        need |= (value * (1.0 - 1e-9) <= lim) & (lim < upper * (1.0 + 1e-9))
    return need


def _exact_peaks(
    c: np.ndarray,
    group: ModalGroup,
    force: ForceHistory,
    t: np.ndarray,
    limits: tuple[Sequence[float], Sequence[float]] | None = None,
) -> dict[str, np.ndarray]:
    """Certified exact peaks (magnitude and per axis) of the records ``c @ h``, m/s^2.

    The sampled maxima first (:func:`_time_stats`); then
    :func:`~microg.dynamics.peaks.certified_peaks` (the search of
    :func:`~microg.dynamics.response.peak_response`, the analysis' exact peak) on the windows
    of consecutive candidate intervals (:func:`_candidates`), in the rows' coordinates
    (``phi = I``, the unit modal force on every row, each case a "point" whose translation map
    is its coefficients), with the group's prepared modal state and the sampled values of the
    records.  Outside the windows no value can exceed the sampled maximum, so the largest value
    found is the certified supremum over the record (to :data:`PEAK_RTOL`).  Cases sharing a
    window are refined in one call.

    ``limits`` (m/s^2: the magnitude's and the largest axis value's limits of the verdict)
    restricts the search to the cases whose sampled peak and certified upper bound
    (:func:`_peak_upper`) straddle one of them; the others keep their sampled peaks, which
    decide the verdict as the exact ones would.  ``certified`` (n,) marks the cases searched.
    """
    sampled = _time_stats(c, group.h)
    peak = sampled["peak"].copy()
    peak_ax = sampled["peak_axis"].copy()
    n = c.shape[0]
    if limits is None:
        todo = np.arange(n)
    else:
        todo = np.zeros(0, int)
        if any(len(x) for x in limits):
            bounds = _segment_bounds(group, force, t)
            up, up_ax = _peak_upper(c, t, bounds, sampled, group.h)
            need = _straddles(peak, up, limits[0]) | _straddles(
                peak_ax.max(axis=1), up_ax.max(axis=1), limits[1]
            )
            todo = np.flatnonzero(need)
    certified = np.zeros(n, bool)
    certified[todo] = True
    if todo.size == 0:
        return {"peak": peak, "peak_axis": peak_ax, "certified": certified}
    sub = c if todo.size == n else c[todo]
    sub_sampled = {k: v[todo] for k, v in sampled.items()}
    cands = _candidates(sub, group.h, t, _segment_bounds(group, force, t), sub_sampled)
    # windows: each case's candidate intervals, runs closer than _MERGE samples joined
    wins: list[tuple[int, int, int]] = []  # (first sample, last sample, case)
    for j, iv in enumerate(cands):
        if iv.size == 0:
            continue
        case = int(todo[j])
        cut = np.flatnonzero(np.diff(iv) > _MERGE)
        for i0, i1 in zip(np.r_[iv[0], iv[cut + 1]], np.r_[iv[cut], iv[-1]], strict=True):
            wins.append((int(i0), int(i1) + 1, case))
    wins.sort()
    st = group.state
    assert st is not None
    k = 0
    while k < len(wins):
        # a batch: consecutive windows whose hull stays short, at most _PEAK_CELLS of them
        lo, hi, _ = wins[k]
        j = k + 1
        while (j < len(wins) and j - k < _PEAK_CELLS
               and max(hi, wins[j][1]) - lo <= _SPAN):  # fmt: skip
            hi = max(hi, wins[j][1])
            j += 1
        batch = wins[k:j]
        k = j
        names = [str(i) for i in range(len(batch))]
        proj = c[[case for _, _, case in batch]].reshape(3 * len(batch), -1)
        # the sampled values of the records: their rows of h at the window's times
        vals = proj @ group.h[:, lo : hi + 1]
        res = certified_peaks(st, names, proj, t[lo : hi + 1], rtol=PEAK_RTOL,
                              max_rounds=_PEAK_ROUNDS, grid_vals=vals)  # fmt: skip
        for i, (_, _, case) in enumerate(batch):
            r = res[str(i)]
            peak[case] = max(peak[case], r.peak_accel_mps2)
            peak_ax[case] = np.maximum(peak_ax[case], r.peak_accel_mps2_axis)
    return {"peak": peak, "peak_axis": peak_ax, "certified": certified}


def _rms(c: np.ndarray, gram_r: np.ndarray, nt: int) -> dict[str, np.ndarray]:
    """RMS over the record of the magnitude and of each axis of ``c @ h``, m/s^2."""
    y = c @ gram_r.T  # (cells, 3, r)
    ms_axis = np.einsum("cak,cak->ca", y, y) / nt
    return {"rms": np.sqrt(ms_axis.sum(axis=1)), "rms_axis": np.sqrt(ms_axis)}


def _band_rms(c: np.ndarray, group: ModalGroup, req: Requirement) -> np.ndarray:
    """(cells, 3, nb) band RMS of the records ``c @ h``, m/s^2.

    The periodogram of each record (``c @ X``, the DFT being linear) through the band rule
    :func:`band_rms`.
    """
    n = c.shape[0]
    g = group.grid
    out = np.empty((n, 3, group.center_hz.size))
    for c0 in range(0, n, _CELLS // 4):
        cc = c[c0 : c0 + _CELLS // 4]
        k = cc.shape[0]
        flat = cc.reshape(3 * k, -1)
        re = flat @ group.x[0]
        im = flat @ group.x[1]
        np.multiply(re, re, out=re)
        re += im * im
        re *= group.scale
        spec = Spectrum(g.freq_hz, re, g.df_hz, g.nyquist_hz, g.method, g.record_s)
        out[c0 : c0 + k] = band_rms(spec, req.bands).rms.reshape(k, 3, -1)
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


def run_blocks(
    basis: Basis, plan: KernelPlan, works: Sequence[BlockWork], threads: int = 1
) -> list[BlockResult]:
    """Compute a batch of blocks of one variant (a task): each modal group once.

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
                group = modal_group(basis, plan, *k)
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
