"""Band mean squares of modal outputs under force spectra, their combination and contributions.

The pure kernel (:func:`band_mean_squares`) of the frequency-domain band table: natural
frequencies, damping, output rows ``T phi`` and the sources' generalized forces in, mean squares
per band out.  The conventions of the combination over sources (independent groups add in mean
square, members of one coherent group in amplitude) and of the contributions are in
:mod:`microg.dynamics.frequency`.

Each band's response is summed in amplitude at the nodes of the converged quadrature
(:mod:`microg.dynamics.bandquad`; never from squared sums, so a response that is small by
cancellation between modes keeps its relative accuracy): the modes whose natural frequency lies
within two band widths of the band node by node, the others -- smooth over the band -- through a
16-point Chebyshev interpolant of their sum, each far mode's interpolant checked at 49 points
across the band to 1e-14 of the mode's size there (a mode that fails is summed node by node).
Harmonic lines are evaluated exactly at their frequencies.

An optional real **weight** per output row, ``w_p(f) >= 0`` (e.g. ``|T(f)|^2``, the squared
transmissibility of an isolator on the observed point), multiplies the integrand of row ``p``:
``int w_p(f) |H_p(f)|^2 S(f) df``.  The responses at the quadrature nodes are scaled by
``sqrt(w_p)`` at each node's own frequency and a harmonic line's by ``sqrt(w_p)`` at the line's
frequency, so the combination over sources and the contributions keep their meaning; the
convergence check of :mod:`microg.dynamics.bandquad` is then made on the weighted integrand.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from microg.dynamics.bandquad import converged_quadrature, default_order
from microg.dynamics.frf import factor_parts
from microg.dynamics.spectra import ForceSpectrum, HarmonicLines, same_frequency_index
from microg.errors import InputError

__all__ = ["MAX_LINES", "BandArrays", "RowWeight", "band_mean_squares"]

#: a real weight per output row: frequencies (n,) in Hz -> (p, n) values >= 0
RowWeight = Callable[[np.ndarray], np.ndarray]

#: largest number of harmonic lines over all sources
MAX_LINES = 100_000


@dataclass(frozen=True)
class BandArrays:
    """Band mean squares of output rows (pure-array result of :func:`band_mean_squares`).

    All mean squares in (output unit)^2, e.g. (m/s^2)^2; shares are mean squares too (they
    sum to ``total``).

    Attributes
    ----------
    total : (p, nb) band mean square of each output row
    source_alone : (p, s, nb) each source acting alone
    source_share : (p, s, nb) ``sum Re(Y_s conj(Y_g))``; sums over s to ``total``
    group : (p, g, nb) each independent group
    mode_alone : (p, m, nb) each mode's term alone (all sources)
    mode_share : (p, m, nb) ``sum_g Re(Y_gj conj(Y_g))``; sums over modes to ``total``
    quad_nodes : number of quadrature nodes
    quad_error : (nb,) convergence estimate of each band (relative)
    near_modes : (nb,) modes summed node by node in each band (the others, smooth over the
        band, through their Chebyshev interpolant)
    refinements : interval halvings done by the convergence check
    warnings : messages
    """

    total: np.ndarray
    source_alone: np.ndarray
    source_share: np.ndarray
    group: np.ndarray
    mode_alone: np.ndarray
    mode_share: np.ndarray
    quad_nodes: int
    quad_error: np.ndarray
    near_modes: np.ndarray
    refinements: int
    warnings: tuple[str, ...]


def _group_index(groups: Sequence[int] | None, ns: int) -> np.ndarray:
    if groups is None:
        return np.arange(ns)
    g = np.asarray(groups, int)
    if g.shape != (ns,) or np.any(g < 0):
        raise InputError("need one non-negative group index per source", where="groups")
    _, inv = np.unique(g, return_inverse=True)
    return inv.reshape(-1)


#: Chebyshev points of the interpolant of the modes far from a band
_N_CHEB = 16
#: modes within this many band widths of a band are summed node by node from the start
_NEAR_WIDTHS = 2.0
#: relative accuracy a far mode's interpolant must reach, else the mode is summed node by node
_CHEB_TOL = 1e-14


def _cheb_matrix(x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev points (first kind) on [-1, 1] and the barycentric interpolation matrix to x.

    Returns ``xk`` (n,) and ``ell`` (n, len(x)) with ``g(x) ~ g(xk) @ ell`` (Berrut &
    Trefethen, SIAM Review 46 (2004) 501, Eq. 5.1 with the first-kind weights).
    """
    theta = (2 * np.arange(n) + 1) * np.pi / (2 * n)
    xk = np.cos(theta)
    wk = (-1.0) ** np.arange(n) * np.sin(theta)
    d = x[None, :] - xk[:, None]
    hit = d == 0
    t = wk[:, None] / np.where(hit, 1.0, d)
    ell = t / np.sum(t, axis=0, keepdims=True)
    cols = np.any(hit, axis=0)
    if np.any(cols):
        ell[:, cols] = hit[:, cols]
    return xk, ell


@dataclass(frozen=True)
class _BandPart:
    total: np.ndarray  # (p,)
    source_alone: np.ndarray  # (p, L)
    source_share: np.ndarray  # (p, L)
    groups: np.ndarray  # (G,) global group indices
    group: np.ndarray  # (p, G)
    mode_alone: np.ndarray  # (p, m)
    mode_share: np.ndarray  # (p, m)
    n_near: int


def _spectral_band(
    T: np.ndarray,
    F: np.ndarray,
    gl: np.ndarray,
    amp: np.ndarray,
    rre: np.ndarray,
    rim: np.ndarray,
    freq: np.ndarray,
    lo: float,
    hi: float,
    wm: np.ndarray,
    zm: np.ndarray,
    near: np.ndarray,
    contributions: bool = True,
    sw: np.ndarray | None = None,
) -> _BandPart:
    """Mean squares in one band from spectral sources (node by node, in amplitude).

    ``amp[s, n] = sqrt(S_s(f_n) w_n)``; the response of each output row and source at the nodes
    is ``H = sum_near c_j r_j + (far-mode sum at Chebyshev points) @ ell``: the modes far from
    the band enter through a 16-point interpolant of their (smooth) sum, each far mode's
    interpolant checked at 49 points across the band to ``_CHEB_TOL`` (a mode that fails is
    summed node by node).  Amplitudes, not squares, are summed, so a response that is small by
    cancellation between modes keeps its relative accuracy.  ``sw`` (p, nn): the square root of
    each row's weight at the nodes (None: no weight).
    """
    p, m = T.shape
    L, nn = amp.shape
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    xk, ell = _cheb_matrix((freq - mid) / half, _N_CHEB)
    far = np.flatnonzero(~near)
    if far.size:
        cre, cim = factor_parts(wm[far], zm[far], 2.0 * np.pi * (mid + half * xk))
        # check each far mode's interpolant at test points between the Chebyshev points
        xt = np.cos(np.linspace(0.0, np.pi, 3 * _N_CHEB + 1))
        ell_t = _cheb_matrix(xt, _N_CHEB)[1]
        tre, tim = factor_parts(wm[far], zm[far], 2.0 * np.pi * (mid + half * xt))
        scale = np.maximum(np.max(np.abs(tre) + np.abs(tim), axis=1), 1e-300)
        e = np.abs(cre @ ell_t - tre) + np.abs(cim @ ell_t - tim)
        bad = np.max(e, axis=1) > _CHEB_TOL * scale
        if np.any(bad):
            near = near.copy()
            near[far[bad]] = True
            far = far[~bad]
            cre, cim = cre[~bad], cim[~bad]
    nr = np.flatnonzero(near)
    mn = nr.size
    # responses at the nodes, (L, p, nn), amplitude included: H_s = (coef_s @ basis) amp_s
    # with the basis [r_near; ell] and the coefficients [c_near, far-mode sum at the points]:
    # one product for every source and row, then each source's amplitude at each node
    cn = T[None, :, nr] * F[:, None, nr]  # (L, p, mn)
    bre = np.concatenate([rre[nr], ell]) if far.size else rre[nr]  # (K, nn)
    bim = np.concatenate([rim[nr], ell]) if far.size else rim[nr]
    if far.size:
        Tf = T[:, far]
        hf_re = Tf[None] @ (F[:, far, None] * cre[None])  # (L, p, nc): far sum at the points
        hf_im = Tf[None] @ (F[:, far, None] * cim[None])
        cre_re = np.concatenate([cn, hf_re], axis=2)  # (L, p, K)
        cre_im = np.concatenate([cn, hf_im], axis=2)
    else:
        cre_re = cre_im = cn
    K = bre.shape[0]
    Hre = (np.ascontiguousarray(cre_re).reshape(L * p, K) @ bre).reshape(L, p, nn)
    Him = (np.ascontiguousarray(cre_im).reshape(L * p, K) @ bim).reshape(L, p, nn)
    Hre *= amp[:, None, :]
    Him *= amp[:, None, :]
    if sw is not None:  # the weighted responses sqrt(w_p) H_p
        Hre = Hre * sw[None]
        Him = Him * sw[None]
    ug, ginv = np.unique(gl, return_inverse=True)
    ginv = ginv.reshape(-1)
    alone = np.einsum("spn,spn->ps", Hre, Hre) + np.einsum("spn,spn->ps", Him, Him)
    # each source's group response: itself when alone in its group
    count = np.bincount(ginv)[ginv]
    share = alone.copy()
    gms = np.zeros((p, ug.size))
    gms[:, ginv[count == 1]] = alone[:, count == 1]
    multi = np.flatnonzero(count > 1)
    Ym_re = Ym_im = np.zeros((0, p, nn))
    if multi.size:
        gm = ginv[multi]
        same = (gm[:, None] == gm[None, :]).astype(float)  # same-group indicator
        Ym_re = np.tensordot(same, Hre[multi], axes=(1, 0))  # (M, p, nn)
        Ym_im = np.tensordot(same, Him[multi], axes=(1, 0))
        share[:, multi] = np.einsum("spn,spn->ps", Hre[multi], Ym_re) + np.einsum(
            "spn,spn->ps", Him[multi], Ym_im
        )
        first = np.unique(gm, return_index=True)[1]
        gms[:, gm[first]] = np.einsum("spn,spn->ps", Ym_re[first], Ym_re[first]) + np.einsum(
            "spn,spn->ps", Ym_im[first], Ym_im[first]
        )
    mode_share = np.zeros((p, m))
    mode_alone = np.zeros((p, m))
    if not contributions:
        return _BandPart(gms.sum(axis=1), alone, share, ug, gms, mode_alone, mode_share, mn)
    # mode shares: T_pj sum_s F_sj Re sum_n r_j(n) amp_s(n) conj(Y_g(s)(n)); the sums over the
    # nodes are products with the amplitude-scaled basis: near columns give the near modes, the
    # Chebyshev columns the far modes through r_j(n) ~ sum_k r_j(x_k) l_k(n)
    # (a weight enters once more: the mode's term is weighted as the total it projects on)
    Rre = bre[None] * amp[:, None, :]  # (L, K, nn): the amplitude-scaled basis
    Rim = bim[None] * amp[:, None, :]
    RreT, RimT = np.swapaxes(Rre, 1, 2), np.swapaxes(Rim, 1, 2)
    w1 = 1.0 if sw is None else sw[None]
    Are = (Hre * w1) @ RreT  # (L, p, K): sum_n Yre a b, Y = H for a source alone in its group
    Aim = (Him * w1) @ RimT
    if multi.size:
        Are[multi] = (Ym_re * w1) @ RreT[multi]
        Aim[multi] = (Ym_im * w1) @ RimT[multi]
    if mn:
        W = Are[:, :, :mn] + Aim[:, :, :mn]  # Re(conj(Y) a r_j)
        mode_share[:, nr] = T[:, nr] * np.einsum("sj,spj->pj", F[:, nr], W)
    if far.size:
        # sum_s F_sj Re sum_k r_j(x_k) P_sk, P_sk = sum_n a conj(Y) l_k
        Zre = np.tensordot(Are[:, :, mn:], F[:, far], axes=(0, 0))  # (p, nc, mf)
        Zim = np.tensordot(Aim[:, :, mn:], F[:, far], axes=(0, 0))
        Wf = np.einsum("pkj,jk->pj", Zre, cre) + np.einsum("pkj,jk->pj", Zim, cim)
        mode_share[:, far] = T[:, far] * Wf
    # modes alone: T_pj^2 sum_g int |r_j|^2 |sum_{s in g} F_sj a_s|^2
    rr = rre * rre + rim * rim  # (m, nn)
    if sw is None:
        D = rr @ (amp * amp).T  # (m, L)
        A = np.sum(F.T**2 * D, axis=1)[None, :]  # (1, m)
    else:  # per row: int w_p |r_j|^2 ...
        D = np.einsum("jn,pn,sn->pjs", rr, sw * sw, amp * amp)  # (p, m, L)
        A = np.sum(F.T[None] ** 2 * D, axis=2)  # (p, m)
    if multi.size:
        ia, ib = np.nonzero((ginv[:, None] == ginv[None, :]) & ~np.eye(L, dtype=bool))
        if sw is None:
            cross = rr @ (amp[ia] * amp[ib]).T  # (m, P)
            A = A + np.sum(F[ia].T * F[ib].T * cross, axis=1)[None, :]
        else:
            cross_w = np.einsum("jn,pn,kn->pjk", rr, sw * sw, amp[ia] * amp[ib])
            A = A + np.sum((F[ia].T * F[ib].T)[None] * cross_w, axis=2)
    mode_alone = T**2 * A
    return _BandPart(
        total=gms.sum(axis=1),
        source_alone=alone,
        source_share=share,
        groups=ug,
        group=gms,
        mode_alone=mode_alone,
        mode_share=mode_share,
        n_near=int(mn),
    )


def band_mean_squares(
    omega_modes: np.ndarray,
    zeta: np.ndarray,
    out_modal: np.ndarray,
    in_modal: np.ndarray,
    spectra: Sequence[ForceSpectrum],
    lower_hz: np.ndarray,
    upper_hz: np.ndarray,
    *,
    groups: Sequence[int] | None = None,
    order: int | None = None,
    rtol: float = 1e-9,
    workers: int | None = None,
    contributions: bool = True,
    weight: RowWeight | None = None,
    weight_breakpoints_hz: Sequence[float] | np.ndarray = (),
) -> BandArrays:
    """Band mean squares, their combination over sources and the contributions (pure kernel).

    Parameters
    ----------
    omega_modes : (m,) natural frequencies, rad/s (0: rigid)
    zeta : (m,) modal damping ratios (> 0 for elastic modes)
    out_modal : (p, m) output rows (``T_out @ phi``), m per unit modal coordinate
    in_modal : (s, m) generalized force per newton of each source on each mode
    spectra : s force spectra (:class:`HarmonicLines`, :class:`BandForceSpectrum`,
        :class:`ForcePSD`), N and Hz
    lower_hz, upper_hz : (nb,) band edges, Hz
    groups : (s,) coherent group index per source (default: all independent)
    order : Gauss-Legendre points per sub-interval (None: :func:`default_order` of ``rtol``)
    rtol : convergence tolerance of the band integration (relative)
    workers : threads over bands (default the number of CPUs); BLAS keeps the process's threads
    contributions : compute the per-mode contributions (``mode_alone``, ``mode_share``; zero
        when False, about half the work)
    weight : a real weight per output row (module docstring): ``weight(f_hz)`` for (n,)
        frequencies, Hz, returns (p, n) values >= 0 (dimensionless for ``|T|^2``); None: 1
    weight_breakpoints_hz : frequencies where the weight changes quickly (e.g. the poles of the
        isolator's loop), Hz: breakpoints of the quadrature

    Returns
    -------
    BandArrays (mean squares in output-unit^2, e.g. (m/s^2)^2 for acceleration rows).
    """
    wm = np.asarray(omega_modes, float)
    zm = np.asarray(zeta, float)
    T = np.asarray(out_modal, float)
    F = np.asarray(in_modal, float)
    lo = np.asarray(lower_hz, float)
    hi = np.asarray(upper_hz, float)
    p, m = T.shape
    ns, nb = F.shape[0], lo.size
    if F.shape != (ns, m) or len(spectra) != ns or zm.shape != (m,) or wm.shape != (m,):
        raise InputError("inconsistent shapes of modes, outputs and sources", where="band")
    if not (np.all(lo > 0) and np.all(hi > lo)):
        raise InputError("bands need 0 < lower < upper", where="bands")
    gidx = _group_index(groups, ns)

    def weight_at(freq: np.ndarray) -> np.ndarray:
        assert weight is not None
        w = np.asarray(weight(np.asarray(freq, float)), float)
        if w.shape != (p, freq.size) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InputError(
                f"must return ({p}, n) finite values >= 0 for n frequencies", where="weight"
            )
        return w

    ng = int(gidx.max()) + 1 if ns else 0
    total = np.zeros((p, nb))
    src_alone = np.zeros((p, ns, nb))
    src_share = np.zeros((p, ns, nb))
    grp = np.zeros((p, ng, nb))
    mode_alone = np.zeros((p, m, nb))
    mode_share = np.zeros((p, m, nb))
    warnings: list[str] = []

    # ---------------------------------------------------------------- spectral sources
    spec_idx = np.array(
        [i for i, s in enumerate(spectra) if not isinstance(s, HarmonicLines)], dtype=int
    )
    near_count = np.zeros(nb, int)
    quad_nodes, refinements = 0, 0
    qerr = np.zeros(nb)
    if spec_idx.size:
        Fs = F[spec_idx]
        scale = np.max(np.abs(T), axis=0) * np.max(np.abs(Fs), axis=0)  # (m,) max |c_j|
        spec_list = [spectra[i] for i in spec_idx]
        quad, qerr, refinements, w = converged_quadrature(
            lo,
            hi,
            wm,
            zm,
            scale,
            spec_list,
            default_order(rtol) if order is None else order,
            rtol,
            weight=None if weight is None else weight_at,
            breakpoints_hz=weight_breakpoints_hz,
        )
        warnings += w
        quad_nodes = int(quad.freq_hz.size)
        S = np.array([s.psd_at(quad.freq_hz) for s in spec_list])  # (ss, N), N^2/Hz
        re_all, im_all = factor_parts(wm, zm, 2.0 * np.pi * quad.freq_hz)  # (m, N)
        sw_all = None if weight is None else np.sqrt(weight_at(quad.freq_hz))  # (p, N)
        fm = wm / (2.0 * np.pi)
        elastic = wm > 0
        gs = gidx[spec_idx]

        def one_band(b: int) -> tuple[int, np.ndarray, _BandPart] | None:
            n0, n1 = quad.start[b], quad.start[b + 1]
            if n1 <= n0:
                return None
            live = np.flatnonzero(np.any(S[:, n0:n1] > 0, axis=1))
            if live.size == 0:
                return None
            width = hi[b] - lo[b]
            part = _spectral_band(
                T,
                Fs[live],
                gs[live],
                np.sqrt(S[live, n0:n1] * quad.weight_hz[None, n0:n1]),
                re_all[:, n0:n1],
                im_all[:, n0:n1],
                quad.freq_hz[n0:n1],
                lo[b],
                hi[b],
                wm,
                zm,
                elastic & (fm > lo[b] - _NEAR_WIDTHS * width) & (fm < hi[b] + _NEAR_WIDTHS * width),
                contributions=contributions,
                sw=None if sw_all is None else sw_all[:, n0:n1],
            )
            return b, live, part

        # bands in parallel threads; BLAS keeps the process's thread setting (a library
        # call never changes it: ``microg`` starts BLAS on one thread)
        nworkers = max(1, min(int(workers or os.cpu_count() or 1), nb))
        if nworkers == 1:
            results = [one_band(b) for b in range(nb)]
        else:
            with ThreadPoolExecutor(max_workers=nworkers) as pool:
                results = list(pool.map(one_band, range(nb)))
        for res in results:
            if res is None:
                continue
            b, live, part = res
            near_count[b] = part.n_near
            total[:, b] += part.total
            src = spec_idx[live]
            src_alone[:, src, b] += part.source_alone
            src_share[:, src, b] += part.source_share
            for k, g in enumerate(part.groups):
                grp[:, g, b] += part.group[:, k]
            mode_alone[:, :, b] += part.mode_alone
            mode_share[:, :, b] += part.mode_share

    # ----------------------------------------------------------------- harmonic lines
    harm = [(i, s) for i, s in enumerate(spectra) if isinstance(s, HarmonicLines)]
    if harm:
        src = np.concatenate([np.full(s.freq_hz.size, i) for i, s in harm])
        if src.size > MAX_LINES:
            raise InputError(f"{src.size:,} harmonic lines is more than {MAX_LINES:,}")
        fl = np.concatenate([s.freq_hz for _, s in harm])
        al = np.concatenate(
            [s.amplitude_n * np.exp(1j * np.asarray(s.phase_rad)) for _, s in harm]
        ) / np.sqrt(2.0)  # RMS phasors
        key = same_frequency_index(fl, gidx[src])
        nu = int(key.max()) + 1
        fu = np.zeros(nu)
        fu[key] = fl
        gu = np.zeros(nu, int)
        gu[key] = gidx[src]
        member = (fu[:, None] >= lo[None, :]) & (fu[:, None] < hi[None, :])
        top = int(np.argmax(hi))
        member[:, top] |= fu == hi[top]  # the top band is closed
        outside = ~np.any(member, axis=1)
        if np.any(outside):
            warnings.append(
                f"{int(outside.sum())} harmonic line(s) lie outside every band (not assessed), "
                f"e.g. at {fu[outside][0]:.4g} Hz"
            )
        re, im = factor_parts(wm, zm, 2.0 * np.pi * fu)
        r = re + 1j * im  # (m, U)
        B = np.zeros((m, nu), complex)  # sum_s F_sj A_s at each distinct (group, freq)
        np.add.at(B.T, key, F[src] * al[:, None])
        Y = T @ (r * B)  # (p, U) group response phasors (RMS)
        Hs = T @ (r[:, key] * F[src].T * al[None, :])  # (p, lines): each line alone
        swl = np.ones((p, nu)) if weight is None else np.sqrt(weight_at(fu))  # at each line
        Y = Y * swl
        Hs = Hs * swl[:, key]
        # each source's lines at one frequency add first (a source's own phasor sum)
        sk = src * nu + key
        uk, inv = np.unique(sk, return_inverse=True)
        Hsum_t = np.zeros((uk.size, p), complex)
        np.add.at(Hsum_t, inv.reshape(-1), Hs.T)
        Hsum = Hsum_t.T
        us, uu = uk // nu, uk % nu
        Mf = member.astype(float)
        alone = np.abs(Hsum) ** 2
        share = np.real(Hsum * np.conj(Y[:, uu]))
        Ms = np.zeros((uk.size, ns))
        Ms[np.arange(uk.size), us] = 1.0
        src_alone += np.einsum("pk,ks,kb->psb", alone, Ms, Mf[uu])
        src_share += np.einsum("pk,ks,kb->psb", share, Ms, Mf[uu])
        gms = np.abs(Y) ** 2  # (p, U)
        total += gms @ Mf
        Mg = np.zeros((nu, ng))
        Mg[np.arange(nu), gu] = 1.0
        grp += np.einsum("pu,ug,ub->pgb", gms, Mg, Mf)
        for c0 in range(0, nu if contributions else 0, 256):  # chunks keep (p, m, chunk) small
            c1 = min(nu, c0 + 256)
            term = T[:, :, None] * (r[:, c0:c1] * B[:, c0:c1])[None] * swl[:, None, c0:c1]
            mode_alone += np.abs(term) ** 2 @ Mf[c0:c1]
            mode_share += np.real(term * np.conj(Y[:, None, c0:c1])) @ Mf[c0:c1]

    return BandArrays(
        total=total,
        source_alone=src_alone,
        source_share=src_share,
        group=grp,
        mode_alone=mode_alone,
        mode_share=mode_share,
        quad_nodes=quad_nodes,
        quad_error=qerr,
        near_modes=near_count,
        refinements=refinements,
        warnings=tuple(warnings),
    )
