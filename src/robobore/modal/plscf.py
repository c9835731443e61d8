"""Poly-reference least-squares complex frequency-domain estimator (pLSCF, "PolyMAX").

Written from Peeters, Van der Auweraer, Guillaume & Leuridan (2004), *The PolyMAX frequency-
domain method: a new standard for modal parameter estimation*, Shock and Vibration 11,
395-409 (eqs. 1-14), Guillaume et al. (2003, IMAC XXI) and Cauberghe (2004, PhD thesis,
VUB, ch. 3).

Model (right matrix-fraction, per output ``o``; ``l`` = number of inputs)::

    H_o(w) = N_o(w) D(w)^-1,    N_o = sum_r Omega_r(w) beta_or  (1 x l),
                                 D   = sum_r Omega_r(w) alpha_r  (l x l),  r = 0..p
    Omega_r(w) = z^r,  z = exp(j w Ts),  Ts = 1 / (2 f_hi)    (z-domain basis, band upper edge)

Linearised equation error ``W_o(w) (N_o(w) - H_o(w) D(w))`` gives, with real coefficients,
the reduced normal equations (Peeters 2004 eq. 8-10)::

    R_o = Re(G^H G),  S_o = Re(G^H Y_o),  T_o = Re(Y_o^H Y_o)
    M = 2 sum_o (T_o - S_o^T R_o^-1 S_o),   M alpha = 0,  alpha_p = I  (constraint)

Because ``Omega_r^* Omega_s = z^(s-r)`` every block depends only on ``s - r``: ``R_o`` is
Toeplitz and ``S_o``, ``T_o`` are block-Toeplitz. One matrix product over the frequency
lines gives all lags ``-p..p`` for all outputs at once (:func:`normal_equation_lags`); the
blocks of any lower order ``n`` are the leading sub-blocks, so the equations are built once for
the highest order and reduced per order (:func:`solve_orders`).

Poles and participation factors come from the block companion matrix of
``D(z)^T`` (left null vectors of ``D`` = participation factors): eigenvalues ``z_i`` give
``lambda_i = ln(z_i) / Ts``; the first ``l`` rows of the eigenvectors are the participation
vectors.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.errors import IdentificationError, InputError
from robobore.modal.frf_data import FRFData


@contextmanager
def single_thread_blas() -> Iterator[None]:
    """Run the many small LAPACK calls (solves, eigenvalues of <= 200x200 matrices) on one
    BLAS thread. Multi-threaded OpenBLAS gains nothing at these sizes and, on a loaded
    machine, its spinning threads made the pLSCF order loop 10x slower (measured:
    0.77 s single-threaded vs 8.6 s threaded at load 8 on 2 cores). Uses threadpoolctl when
    it is installed, else does nothing."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - optional
        yield
        return
    with threadpool_limits(limits=1, user_api="blas"):
        yield


@dataclass(frozen=True)
class PoleSet:
    """Poles of one model order (positive-frequency, complex-conjugate partners removed).

    poles: ``(n,)`` complex, rad/s. participation: ``(n, n_inputs)`` complex, unit norm.
    """

    order: int
    poles: np.ndarray
    participation: np.ndarray

    @property
    def frequency_Hz(self) -> np.ndarray:
        return np.abs(self.poles) / (2 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        return -self.poles.real / np.abs(self.poles)


def _weights(h: np.ndarray, weighting: str | np.ndarray | None) -> np.ndarray:
    """Weights ``(n_outputs, n_f)`` (real, >= 0)."""
    no, _, nf = h.shape
    if weighting is None or (isinstance(weighting, str) and weighting == "output"):
        # one constant weight per output: every output contributes equally (scale-free)
        rms = np.sqrt(np.mean(np.abs(h) ** 2, axis=(1, 2)))
        rms[rms == 0] = 1.0
        return np.repeat((1.0 / rms)[:, None], nf, axis=1)
    if isinstance(weighting, str) and weighting == "unit":
        return np.ones((no, nf))
    w = np.asarray(weighting, float)
    if w.shape != (no, nf) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise InputError("bad pLSCF weights", field="weighting", value=f"shape {w.shape}",
                         expected=f"finite non-negative weights of shape ({no}, {nf})")
    return w


def normal_equation_lags(frequency_Hz: np.ndarray, frf: np.ndarray, max_order: int,
                         f_hi_Hz: float, weights: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lag sums of the normal-equation blocks for lags ``d = -p..p``.

    Returns ``r (n_o, 2p+1)``, ``s (n_o, 2p+1, l)``, ``t (n_o, 2p+1, l, l)`` (real parts)::

        r[o, d]       = Re sum_k w_ok^2 z_k^d
        s[o, d, i]    = -Re sum_k w_ok^2 z_k^d H_oi(k)
        t[o, d, i, j] = Re sum_k w_ok^2 z_k^d conj(H_oi(k)) H_oj(k)
    """
    no, l, nf = frf.shape
    p = max_order
    x = np.pi * frequency_Hz / f_hi_Hz  # w Ts
    lags = np.arange(-p, p + 1)
    E = np.exp(1j * np.outer(lags, x))  # (2p+1, nf)
    w2 = weights**2  # (no, nf)
    g_r = w2.T  # (nf, no)
    g_s = (w2[:, None, :] * frf).transpose(2, 0, 1).reshape(nf, no * l)
    g_t = (w2[:, None, None, :] * np.conj(frf)[:, :, None, :] * frf[:, None, :, :])
    g_t = g_t.transpose(3, 0, 1, 2).reshape(nf, no * l * l)
    G = np.concatenate([g_r, g_s, g_t], axis=1)
    P = (E @ G).real  # (2p+1, no*(1+l+l^2))
    r = P[:, :no].T
    s = -P[:, no:no + no * l].reshape(2 * p + 1, no, l).transpose(1, 0, 2)
    t = P[:, no + no * l:].reshape(2 * p + 1, no, l, l).transpose(1, 0, 2, 3)
    return r, s, t


def _blocks(r: np.ndarray, s: np.ndarray, t: np.ndarray, p: int
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Full R (n_o,P,P), S (n_o,P,P*l), T (n_o,P*l,P*l) for the highest order p (P = p+1)."""
    no, _, l = s.shape
    P = p + 1
    idx = np.arange(P)[None, :] - np.arange(P)[:, None] + p  # s - r + p, (P, P)
    R = r[:, idx]  # (no, P, P)
    S = s[:, idx, :].reshape(no, P, P * l)  # [o, r, s*l + i]
    T = t[:, idx, :, :].transpose(0, 1, 3, 2, 4).reshape(no, P * l, P * l)
    return R, S, T


def _reduced_matrix(R: np.ndarray, S: np.ndarray, T: np.ndarray, n: int, l: int,
                    proportional: bool) -> np.ndarray:
    """``M = sum_o (T_o - S_o^T R_o^-1 S_o)`` for order ``n`` (leading sub-blocks)."""
    P = n + 1
    Rn = R[:, :P, :P]
    Sn = S[:, :P, :P * l]
    Tn = T[:, :P * l, :P * l].sum(axis=0)
    try:
        if proportional:
            # R_o = c_o R_0 (weights constant per output, the default): one Cholesky factor,
            # U = L^-1 [S_o / sqrt(c_o)], sum_o S_o^T R_o^-1 S_o = V^T V with V = vstack(U_o)
            c = Rn[:, 0, 0] / Rn[0, 0, 0]
            Lc = np.linalg.cholesky(Rn[0])
            Ss = (Sn / np.sqrt(c)[:, None, None]).transpose(1, 0, 2).reshape(P, -1)
            U = np.linalg.solve(Lc, Ss)  # (P, n_o * P l)
            V = U.reshape(P, -1, P * l).transpose(1, 0, 2).reshape(-1, P * l)
            return Tn - V.T @ V
        X = np.linalg.solve(Rn, Sn)
    except np.linalg.LinAlgError:
        # R is (numerically) singular: a narrow band far from 0 Hz covers only a short arc
        # of the unit circle, and high-order basis functions become dependent there. The
        # numerator elimination is then the minimum-norm least-squares one: R^+ from a
        # symmetric eigen-decomposition with relative cutoff 1e-12.
        ev, Q = np.linalg.eigh(Rn)  # (n_o, P), (n_o, P, P)
        cut = 1e-12 * ev.max(axis=1, keepdims=True)
        inv = np.where(ev > cut, 1.0 / np.where(ev > cut, ev, 1.0), 0.0)
        QtS = np.einsum("opa,opc->oac", Q, Sn)
        X = np.einsum("opa,oa,oac->opc", Q, inv, QtS)
    return Tn - np.einsum("oab,oac->bc", Sn, X, optimize=True)


def _companion(M: np.ndarray, n: int, l: int) -> tuple[np.ndarray, np.ndarray]:
    """Denominator ``alpha_0..alpha_{n-1}`` ``(n, l, l)`` (``alpha_n = I``) and the block
    companion matrix of ``D(z)^T``."""
    A = M[: n * l, : n * l]
    B = M[: n * l, n * l:]
    try:
        alpha = -np.linalg.solve(A, B)  # (n*l, l): alpha_0..alpha_{n-1} stacked
    except np.linalg.LinAlgError:
        alpha = -np.linalg.lstsq(A, B, rcond=None)[0]
    C = np.zeros((n * l, n * l))
    if n > 1:
        C[: (n - 1) * l, l:] = np.eye((n - 1) * l)
    ar = alpha.reshape(n, l, l)  # ar[r] = alpha_r
    C[(n - 1) * l:, :] = -ar.transpose(0, 2, 1).transpose(1, 0, 2).reshape(l, n * l)
    return ar, C


def _poles(ar: np.ndarray, z: np.ndarray, n: int, l: int, Ts: float) -> PoleSet:
    """Poles (positive frequency) and participation vectors from companion eigenvalues.

    Eigenvalues only are computed (eigenvectors cost 3x more); the participation vector of
    a pole is the left null vector of ``D(z_i)``, i.e. the null vector of ``D(z_i)^T`` (the
    first block of the companion eigenvector), taken from an ``l x l`` SVD.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = np.log(z.astype(complex)) / Ts
    keep = np.isfinite(lam) & (lam.imag > 0)
    lam = lam[keep]
    zk = z[keep]
    if l == 1:
        L = np.ones((lam.size, 1), complex)
    else:
        powers = zk[:, None] ** np.arange(n + 1)[None, :]  # (nk, n+1)
        full = np.concatenate([ar, np.eye(l)[None]], axis=0)  # alpha_0..alpha_n
        DT = np.einsum("kr,rab->kba", powers, full)  # D(z_k)^T, (nk, l, l)
        _, _, Vh = np.linalg.svd(DT)
        L = Vh[:, -1, :].conj()  # (nk, l): right-singular vector of the smallest sv
    nrm = np.linalg.norm(L, axis=1)
    nrm[nrm == 0] = 1.0
    L = L / nrm[:, None]
    order = np.argsort(lam.imag)
    return PoleSet(n, lam[order], L[order])


def solve_orders(R: np.ndarray, S: np.ndarray, T: np.ndarray, orders: np.ndarray,
                 l: int, Ts: float, proportional: bool = False,
                 workers: int | None = None) -> list[PoleSet]:
    """Solve the reduced normal equations for every order; companion matrix -> poles.

    The companion eigenvalue problems (the dominant cost, ``O((n l)^3)`` each) run on
    ``workers`` threads (default: CPU count, at most 4); LAPACK releases the GIL.
    """
    from concurrent.futures import ThreadPoolExecutor

    items = []
    for n in (int(v) for v in orders):
        M = _reduced_matrix(R, S, T, n, l, proportional)
        if not np.all(np.isfinite(M)):
            raise IdentificationError(f"pLSCF: non-finite normal equations at order {n}")
        items.append((n, *_companion(M, n, l)))
    nw = workers or min(4, os.cpu_count() or 1)
    big_first = sorted(range(len(items)), key=lambda i: -items[i][0])
    eig: dict[int, np.ndarray] = {}
    if nw > 1 and len(items) > 4:
        with ThreadPoolExecutor(nw) as ex:
            for i, z in zip(big_first, ex.map(lambda i: np.linalg.eigvals(items[i][2]),
                                              big_first), strict=True):
                eig[i] = z
    else:
        for i in big_first:
            eig[i] = np.linalg.eigvals(items[i][2])
    return [_poles(ar, eig[i], n, l, Ts) for i, (n, ar, _) in enumerate(items)]


@dataclass(frozen=True)
class PLSCFResult:
    """Poles of all orders and the settings that produced them."""

    pole_sets: tuple[PoleSet, ...]
    band_Hz: tuple[float, float]
    n_inputs: int
    sample_time_s: float
    pole_shift_rad_per_s: float  # exponential-window correction added to Re(lambda)

    def to_dict(self) -> dict[str, Any]:
        return {"band_Hz": list(self.band_Hz), "orders": [ps.order for ps in self.pole_sets],
                "sample_time_s": self.sample_time_s,
                "pole_shift_rad_per_s": self.pole_shift_rad_per_s}


def correct_poles_for_window(poles: np.ndarray, tau_s: float | None) -> np.ndarray:
    """Remove the exponential window's added damping: ``lambda_true = lambda_est + 1/tau``."""
    if tau_s is None:
        return poles
    return poles + 1.0 / tau_s


def plscf(data: FRFData, band_Hz: tuple[float, float] | None = None, max_order: int = 40,
          min_order: int = 1, weighting: str | np.ndarray | None = None,
          orders: Any = None) -> PLSCFResult:
    """Run pLSCF over the orders ``min_order..max_order``.

    Parameters
    ----------
    data: FRFs ``(n_outputs, n_inputs, n_f)`` (any FRF type; the model is rational in z).
    band_Hz: ``(lo, hi)`` analysis band in Hz (default: all lines above 0 Hz).
    max_order: highest polynomial order ``p`` (each order gives ``p * n_inputs`` poles).
    weighting: None/``"output"`` (one constant per output, equalising outputs), ``"unit"``,
        or an array ``(n_outputs, n_f_band)``.
    orders: solve only these orders (``max_order``/``min_order`` are then taken from them).

    Returns
    -------
    PLSCFResult; poles are corrected for an exponential window (``data.exp_window_tau_s``).
    """
    if orders is not None:
        orders = np.unique(np.asarray(orders, int))
        if orders.size == 0 or orders[0] < 1:
            raise InputError("orders must be positive integers", field="orders",
                             value=orders.tolist(), expected="integers >= 1")
        max_order, min_order = int(orders[-1]), int(orders[0])
    if not (isinstance(max_order, int | np.integer) and max_order >= 1):
        raise InputError("max order must be a positive integer", field="max_order",
                         value=max_order, expected="an integer >= 1")
    if not (1 <= min_order <= max_order):
        raise InputError("min order must be in 1..max_order", field="min_order",
                         value=min_order, expected=f"1 <= min_order <= {max_order}")
    lo, hi = band_Hz if band_Hz is not None else (float(data.frequency_Hz[0]),
                                                  float(data.frequency_Hz[-1]))
    d = data.band(lo, hi)
    f = d.frequency_Hz
    if f[0] == 0:
        d = d.band(f[1], f[-1])
        f = d.frequency_Hz
    no, l, nf = d.frf.shape
    n_eq = nf * no * l
    n_unk = (max_order + 1) * l * l
    if n_eq < 2 * n_unk:
        raise InputError("too few frequency lines for this model order", field="max_order",
                         value=max_order,
                         expected=f"a lower order or a wider band ({nf} lines in the band)")
    f_hi = float(f[-1])
    Ts = 1.0 / (2.0 * f_hi)
    w = _weights(d.frf, weighting)
    scale = np.max(np.abs(d.frf)) or 1.0
    with single_thread_blas():
        r, s, t = normal_equation_lags(f, d.frf / scale, max_order, f_hi, w)
        R, S, T = _blocks(r, s, t, max_order)
        proportional = bool(np.all(w == w[:, :1]))  # constant weight per output
        todo = np.arange(min_order, max_order + 1) if orders is None else orders
        sets = solve_orders(R, S, T, todo, l, Ts, proportional)
    tau = data.exp_window_tau_s
    shift = 0.0 if tau is None else 1.0 / tau
    if shift:
        sets = [PoleSet(ps.order, correct_poles_for_window(ps.poles, tau), ps.participation)
                for ps in sets]
    return PLSCFResult(tuple(sets), (float(f[0]), f_hi), l, Ts, shift)


def poles_near(data: FRFData, poles0: np.ndarray, orders: Any,
               band_Hz: tuple[float, float] | None = None,
               weighting: str | np.ndarray | None = None, iterations: int = 30,
               single_thread: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The pLSCF poles nearest ``poles0 (n_m,)`` (rad/s, window-corrected like
    :func:`plscf`'s) at each of ``orders``, without the companion eigenvalue problem: Newton
    iteration on ``det D(z) = 0`` from ``z0 = exp(lambda0 Ts)``, step
    ``1 / tr(D(z)^-1 D'(z))`` (all poles at once); the same normal equations and
    denominators as :func:`plscf`. ``single_thread``: limit BLAS to one thread here (the
    caller may do it once around many calls).

    Returns poles ``(n_orders, n_m)`` (NaN where Newton did not converge) and participation
    vectors ``(n_orders, n_m, n_inputs)`` (left null vectors of ``D(z)``, unit norm)."""
    from contextlib import nullcontext

    orders = np.unique(np.asarray(orders, int))
    lo, hi = band_Hz if band_Hz is not None else (float(data.frequency_Hz[0]),
                                                  float(data.frequency_Hz[-1]))
    d = data.band(lo, hi)
    f = d.frequency_Hz
    if f[0] == 0:
        d = d.band(f[1], f[-1])
        f = d.frequency_Hz
    no, l, nf = d.frf.shape
    p = int(orders[-1])
    f_hi = float(f[-1])
    Ts = 1.0 / (2.0 * f_hi)
    w = _weights(d.frf, weighting)
    scale = np.max(np.abs(d.frf)) or 1.0
    tau = data.exp_window_tau_s
    shift = 0.0 if tau is None else 1.0 / tau
    lam0 = np.asarray(poles0, complex).ravel() - shift
    nm = lam0.size
    out = np.full((orders.size, nm), np.nan + 0j)
    part = np.zeros((orders.size, nm, l), complex)
    with single_thread_blas() if single_thread else nullcontext():
        r, s_, t = normal_equation_lags(f, d.frf / scale, p, f_hi, w)
        R, S, T = _blocks(r, s_, t, p)
        proportional = bool(np.all(w == w[:, :1]))
        for io, n in enumerate(int(v) for v in orders):
            M = _reduced_matrix(R, S, T, n, l, proportional)
            ar, _ = _companion(M, n, l)
            full = np.concatenate([ar, np.eye(l)[None]], axis=0)  # alpha_0..alpha_n
            dfull = full[1:] * np.arange(1, n + 1)[:, None, None]  # r alpha_r
            z = np.exp(lam0 * Ts)
            done = np.zeros(nm, bool)
            bad = np.zeros(nm, bool)
            for _ in range(iterations):
                act = ~(done | bad)
                if not act.any():
                    break
                pw = z[act, None] ** np.arange(n + 1)[None, :]  # (na, n+1)
                D = np.einsum("kr,rab->kab", pw, full)
                Dp = np.einsum("kr,rab->kab", pw[:, :n], dfull)
                with np.errstate(all="ignore"):
                    try:
                        tr = np.trace(np.linalg.solve(D, Dp), axis1=1, axis2=2)
                    except np.linalg.LinAlgError:  # a singular D: that z is a root
                        tr = np.array([_trace_or_root(Dk, Dpk) for Dk, Dpk in zip(D, Dp,
                                                                                 strict=True)])
                    step = np.where(np.isfinite(tr) & (tr != 0), 1.0 / tr, 0.0)
                ia = np.flatnonzero(act)
                zn = z[ia] - step
                root = ~np.isfinite(tr)  # singular D
                ok = np.isfinite(zn) & (np.abs(zn) > 0) & (np.abs(zn) < 2)
                bad[ia[~ok & ~root]] = True
                z[ia[ok]] = zn[ok]
                conv = (np.abs(step) < 1e-13 * np.maximum(1.0, np.abs(zn))) & ok
                done[ia[conv | root]] = True
            good = done & ~bad
            with np.errstate(all="ignore"):
                lam = np.log(z) / Ts
            lam = np.where(lam.imag < 0, np.conj(lam), lam)
            zg = np.where(lam.imag < 0, np.conj(z), z)
            out[io, good] = lam[good] + shift
            if l == 1:
                part[io, good] = 1.0
            elif good.any():
                pw = zg[good, None] ** np.arange(n + 1)[None, :]
                DT = np.einsum("kr,rab->kba", pw, full)
                _, _, Vh = np.linalg.svd(DT)
                v = Vh[:, -1, :].conj()
                part[io, good] = v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True),
                                                1e-300)
    return out, part


def _trace_or_root(D: np.ndarray, Dp: np.ndarray) -> complex:
    """``tr(D^-1 D')``, or inf when ``D`` is singular (``z`` is a root)."""
    try:
        return complex(np.trace(np.linalg.solve(D, Dp)))
    except np.linalg.LinAlgError:
        return complex(np.inf)


__all__ = ["PoleSet", "PLSCFResult", "plscf", "normal_equation_lags", "solve_orders",
           "correct_poles_for_window", "poles_near"]
