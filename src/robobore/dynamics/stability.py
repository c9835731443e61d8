"""Stability of single-point cutting / boring: lobes, semi-discretisation, mode coupling.

Linearised dynamics (see :mod:`robobore.dynamics.process`): for depth of cut ``a`` and delay
``tau = 60 / (N n)``::

    M q'' + C q' + K q = D^T [ -a A(t) (r(t) - mu r(t - tau)) + P(t) r(t) ],   r = D q

Frequency domain, zero-order (Altintas' oriented transfer function; Altintas & Budak 1995 for
the averaged directional matrix): with ``A0`` the revolution-averaged directional matrix, the
characteristic equation is ``det(I + a (1 - mu e^{-i w tau}) G(iw) A0) = 0``. With ``lambda(w)``
an eigenvalue of ``G(iw) A0`` (for one mode and ``A0 = K u n^T``: ``lambda = K n^T G u``) and
``mu = 1``::

    a_lim = -1 / (2 Re lambda),   eps = 3 pi + 2 arg(lambda)  (mod 2 pi),
    n = 60 w / (N (eps + 2 pi k)),   k = 0, 1, 2, ...

(for ``mu < 1`` the phase condition is solved on the circle ``1 - mu e^{-i eps}``). The
non-regenerative depth-modulation stiffness ``P`` is NOT in the frequency-domain solution (it
does not scale with depth); semi-discretisation includes it.

Semi-discretisation (Insperger & Stepan 2002, 2004; first-order interpolation of the delayed
term, Insperger, Stepan & Turi 2008): the delay is split into ``r`` steps, the ODE is solved
exactly over each step with the delayed state linearly interpolated; the monodromy matrix over
one delay is the product of the step matrices; stable iff its spectral radius < 1.

Mode coupling (Tlusty & Polacek 1963; for robots Pan et al. 2006): the non-delayed system
``M q'' + C q' + (K + a D^T A0 D - D^T P D) q = 0`` (chip thickness driven by the current
displacement, no regeneration); unstable when an eigenvalue has a positive real part (with
damping) or, undamped, when two eigenfrequencies coalesce and become complex (Pan's
criterion).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
from scipy.linalg import expm

from robobore.dynamics.process import CuttingProcess
from robobore.dynamics.structure import ToolPointStructure
from robobore.errors import ConfigError

try:  # a single BLAS thread: the many mid-size eigenproblems are slower multi-threaded
    from threadpoolctl import threadpool_limits as _limits
except ImportError:  # pragma: no cover - optional
    from contextlib import nullcontext as _null

    def _limits(*_a, **_k):  # type: ignore[no-redef]
        return _null()


# --------------------------------------------------------------------------- frequency domain
def frequency_grid(structure: ToolPointStructure, n_global: int = 6000,
                   n_local: int = 4000) -> np.ndarray:
    """Chatter-frequency grid [rad/s]: log-spaced over 0.2-5 x the mode range, dense near modes."""
    f = structure.frequency_Hz
    z = np.maximum(structure.damping_ratio, 1e-4)
    parts = [np.geomspace(0.2 * f.min(), 5.0 * f.max(), n_global)]
    for fj, zj in zip(f, z, strict=True):
        parts.append(fj * (1 + zj * np.linspace(-30, 30, n_local)))
    g = np.unique(np.concatenate(parts))
    return 2 * np.pi * g[g > 0]


def oriented_eigenvalues(structure: ToolPointStructure, A0: np.ndarray,
                         omega: np.ndarray) -> np.ndarray:
    """Eigenvalues of ``G(iw) A0`` (dimensionless per unit depth x depth), shape (n_branch, n_w).

    Rank-one ``A0`` (the single-point contract) has a single non-zero eigenvalue, the trace.
    Otherwise the three eigenvalues are tracked across frequency by nearest-neighbour matching.
    """
    G = structure.frf(omega)  # (3,3,nw)
    M = np.einsum("oiw,ij->woj", G, A0)
    sv = np.linalg.svd(A0, compute_uv=False)
    if sv[1] <= 1e-12 * sv[0]:
        return np.trace(M, axis1=1, axis2=2)[None, :]
    ev = np.linalg.eigvals(M)  # (nw, 3)
    out = np.empty_like(ev)
    out[0] = ev[0]
    perms = [(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)]
    for i in range(1, ev.shape[0]):
        best, cost = None, np.inf
        for p in perms:
            c = np.abs(ev[i, list(p)] - out[i - 1]).sum()
            if c < cost:
                best, cost = p, c
        out[i] = ev[i, list(best)]
    return out.T


def lobe_branches(lam: np.ndarray, overlap: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Critical depth ``b`` and phase ``eps`` [rad] per branch and frequency.

    ``lam``: (n_branch, n_w). Returns ``(b, eps)`` of shape (n_branch * roots, n_w) with
    ``b = inf`` where no positive real depth satisfies the characteristic equation.
    """
    mu = float(overlap)
    psi = np.angle(lam)
    mag = np.abs(lam)
    theta = np.angle(np.exp(1j * (np.pi - psi)))
    ct = np.cos(theta)
    bs, es = [], []
    if mu >= 1.0 - 1e-12:
        rho = 2 * ct
        roots = [rho]
    else:
        disc = ct**2 - (1 - mu**2)
        sq = np.sqrt(np.where(disc >= 0, disc, np.nan))
        roots = [ct + sq, ct - sq]
    for rho in roots:
        ok = np.isfinite(rho) & (rho > 1e-12) & (mag > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            b = np.where(ok, 1.0 / (rho * mag), np.inf)
            w = 1 - rho * np.exp(1j * theta)
            eps = np.mod(-np.angle(w), 2 * np.pi)
        bs.append(b)
        es.append(np.where(ok, eps, np.nan))
    return np.concatenate(bs), np.concatenate(es)


@nb.njit(cache=True, parallel=True)
def _envelope(speeds_rpm, n_inserts, omega, b, eps, out_b, out_w):  # pragma: no cover - numba
    """Lower envelope of the lobes at each speed (parallel over speeds).

    For speed n, delay tau = 60/(N n); along each branch the phase ``w tau - eps(w)`` crosses
    2 pi k (k >= 0) where a lobe passes this speed; ``b`` is interpolated linearly there.
    """
    nbr, nw = b.shape
    for s in nb.prange(speeds_rpm.size):
        tau = 60.0 / (n_inserts * speeds_rpm[s])
        best = np.inf
        wbest = np.nan
        for k in range(nbr):
            for i in range(nw - 1):
                b0 = b[k, i]
                b1 = b[k, i + 1]
                if not (b0 < np.inf and b1 < np.inf):
                    continue
                e0 = eps[k, i]
                e1 = eps[k, i + 1]
                if abs(e1 - e0) > np.pi:
                    continue
                p0 = (omega[i] * tau - e0) / (2 * np.pi)
                p1 = (omega[i + 1] * tau - e1) / (2 * np.pi)
                lo = min(p0, p1)
                hi = max(p0, p1)
                j = math.ceil(lo)
                if j < 0:
                    j = 0
                while j <= hi:
                    if p1 != p0:
                        t = (j - p0) / (p1 - p0)
                    else:
                        t = 0.0
                    bb = b0 + t * (b1 - b0)
                    if bb < best:
                        best = bb
                        wbest = omega[i] + t * (omega[i + 1] - omega[i])
                    j += 1
        out_b[s] = best
        out_w[s] = wbest


@nb.njit(cache=True)
def _mode_coupling_line(omega, lam, out):  # pragma: no cover - numba
    """mu = 0: b where lambda crosses the negative real axis (speed independent)."""
    best = np.inf
    wb = np.nan
    for i in range(lam.size - 1):
        a0 = lam[i].imag
        a1 = lam[i + 1].imag
        if a0 == 0.0 or a0 * a1 < 0:
            t = a0 / (a0 - a1) if a1 != a0 else 0.0
            re = lam[i].real + t * (lam[i + 1].real - lam[i].real)
            if re < 0 and -1.0 / re < best:
                best = -1.0 / re
                wb = omega[i] + t * (omega[i + 1] - omega[i])
    out[0] = best
    out[1] = wb


@dataclass(frozen=True)
class LobeResult:
    """Stability lobes: ``speed_rpm`` (n,), ``critical_depth_m`` (n,), ``chatter_frequency_Hz``
    (n,), ``absolute_limit_m`` and its frequency; ``method``; ``depth_scan_max_m``: the top of
    the semi-discretisation depth scan (``inf`` depths mean stable up to it; ``None`` for the
    frequency domain)."""

    speed_rpm: np.ndarray
    critical_depth_m: np.ndarray
    chatter_frequency_Hz: np.ndarray
    absolute_limit_m: float
    absolute_limit_frequency_Hz: float
    method: str
    depth_scan_max_m: float | None = None

    @property
    def unconditionally_stable(self) -> bool:
        """No critical depth at any speed (within the scanned depth range)."""
        return not bool(np.any(np.isfinite(self.critical_depth_m)))

    def to_dict(self) -> dict[str, Any]:
        d = {"method": self.method, "speed_rpm": self.speed_rpm,
             "critical_depth_mm": self.critical_depth_m * 1e3,
             "absolute_limit_mm": self.absolute_limit_m * 1e3,
             "absolute_limit_frequency_Hz": self.absolute_limit_frequency_Hz,
             "chatter_frequency_Hz": self.chatter_frequency_Hz}
        if self.depth_scan_max_m is not None:
            d["depth_scan_max_mm"] = self.depth_scan_max_m * 1e3
            d["stable_speeds"] = int(np.sum(~np.isfinite(self.critical_depth_m)))
        return d


def _refine_min(omega: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Minimum of b(w) on the grid refined by a parabola through the 3 nearest points."""
    i = int(np.nanargmin(b))
    if 0 < i < b.size - 1 and np.all(np.isfinite(b[i - 1:i + 2])):
        x = omega[i - 1:i + 2]
        y = b[i - 1:i + 2]
        c = np.polyfit(x - x[1], y, 2)
        if c[0] > 0:
            xm = -c[1] / (2 * c[0])
            if abs(xm) <= max(abs(x[0] - x[1]), abs(x[2] - x[1])):
                return float(np.polyval(c, xm)), float(x[1] + xm)
    return float(b[i]), float(omega[i])


def lobes_frequency_domain(structure: ToolPointStructure, process: CuttingProcess,
                           speed_rpm: np.ndarray, omega: np.ndarray | None = None) -> LobeResult:
    """Zero-order frequency-domain lobes at the given spindle speeds (any number of modes)."""
    speeds = np.asarray(speed_rpm, float)
    w = frequency_grid(structure) if omega is None else np.asarray(omega, float)
    A0 = process.mean_directional_matrix()
    lam = oriented_eigenvalues(structure, A0, w)
    mu = process.overlap
    if 1e-9 < mu < 1.0 - 1e-9:
        raise ConfigError("the frequency-domain lobes support overlap 1 (full regeneration) or "
                          "0 (mode coupling only)", field="process.overlap_factor", value=mu,
                          expected="1.0 or 0.0, or use the semi-discretization method")
    if mu <= 1e-9:
        best = np.full(lam.shape[0], np.inf)
        wb = np.full(lam.shape[0], np.nan)
        tmp = np.empty(2)
        for k in range(lam.shape[0]):
            _mode_coupling_line(w, lam[k], tmp)
            best[k], wb[k] = tmp
        k = int(np.argmin(best))
        return LobeResult(speeds, np.full(speeds.size, best[k]),
                          np.full(speeds.size, wb[k] / (2 * np.pi)), float(best[k]),
                          float(wb[k] / (2 * np.pi)), "frequency (mu = 0: no regeneration)")
    b, eps = lobe_branches(lam, mu)
    out_b = np.empty(speeds.size)
    out_w = np.empty(speeds.size)
    _envelope(speeds, int(process.n_inserts), w, b, np.nan_to_num(eps, nan=0.0), out_b, out_w)
    bmin = np.min(b, axis=0)
    alim, walim = _refine_min(w, np.where(np.isfinite(bmin), bmin, np.nan)) if np.any(
        np.isfinite(bmin)) else (np.inf, np.nan)
    return LobeResult(speeds, out_b, out_w / (2 * np.pi), alim, walim / (2 * np.pi),
                      "frequency")


def lobe_curves(structure: ToolPointStructure, process: CuttingProcess, n_lobes: int = 10,
                omega: np.ndarray | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Individual lobes (speed_rpm, depth_m) for k = 0 .. n_lobes-1 (for plots)."""
    w = frequency_grid(structure) if omega is None else omega
    lam = oriented_eigenvalues(structure, process.mean_directional_matrix(), w)
    b, eps = lobe_branches(lam, max(process.overlap, 1e-6))
    out = []
    for br in range(b.shape[0]):
        ok = np.isfinite(b[br])
        for k in range(n_lobes):
            n = 60 * w[ok] / (process.n_inserts * (eps[br, ok] + 2 * np.pi * k))
            out.append((n, b[br, ok]))
    return out


# --------------------------------------------------------------------------- semi-discretisation
#: Depth range of the critical-depth scan [m]: the largest depth of cut a config accepts (50 mm)
#: and four decades below it. "Unconditionally stable" means: no instability up to the top.
DEPTH_SCAN_HI_M = 0.05
DEPTH_SCAN_DECADES = 4.0
#: Ratio between neighbouring depths of the scan grid (an unstable window narrower than this
#: in depth can be missed between two grid points).
DEPTH_SCAN_RATIO = 1.25
#: Monodromy matrices up to this size are solved densely; larger ones by ARPACK (the few
#: eigenvalues of largest modulus), falling back to the dense solver if ARPACK does not converge.
DENSE_EIG_MAX = 120


def _step_matrices(Lc: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Phi = e^{L dt}, Gamma0 = int e^{L(dt-s)} ds, Gamma1 = int e^{L(dt-s)} s ds (Van Loan).

    ``Lc`` is one (n, n) matrix or a stack (k, n, n); the result has the same leading shape.
    Reference implementation (scipy's Pade expm of the augmented 3n x 3n matrix); the
    monodromy uses :func:`_step_matrices_batch`, which tests compare with this one."""
    n = Lc.shape[-1]
    H = np.zeros(Lc.shape[:-2] + (3 * n, 3 * n))
    H[..., :n, :n] = Lc
    H[..., :n, n:2 * n] = np.eye(n)
    H[..., n:2 * n, 2 * n:] = np.eye(n)
    E = expm(H * dt)
    return E[..., :n, :n], E[..., :n, n:2 * n], E[..., :n, 2 * n:]


@nb.njit(cache=True)
def _matmul_into(A, B, out):  # pragma: no cover - numba
    n = A.shape[0]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += A[i, k] * B[k, j]
            out[i, j] = acc


@nb.njit(cache=True)
def _step_matrices_batch(L, dt, Phi, G0, G1):  # pragma: no cover - numba
    """Phi, Gamma0, Gamma1 of :func:`_step_matrices` for a stack ``L`` (k, n, n), in place.

    Taylor series of degree 16 on ``h = dt / 2^s`` with ``||L h||_1 <= 1/2`` (truncation
    below 1e-18 relative), then ``s`` doublings: ``Phi(2h) = Phi^2``,
    ``G0(2h) = Phi G0 + G0``, ``G1(2h) = Phi G1 + h G0 + G1`` (split the integral at h)."""
    k_n, n, _ = L.shape
    T = np.empty((n, n))
    A = np.empty((n, n))
    W1 = np.empty((n, n))
    W2 = np.empty((n, n))
    W3 = np.empty((n, n))
    for q in range(k_n):
        nrm = 0.0
        for j in range(n):
            c = 0.0
            for i in range(n):
                c += abs(L[q, i, j])
            nrm = max(nrm, c)
        nrm *= dt
        s = 0
        if nrm > 0.5:
            s = int(math.ceil(math.log2(nrm / 0.5)))
        h = dt / 2.0**s
        for i in range(n):
            for j in range(n):
                A[i, j] = L[q, i, j] * h
                T[i, j] = 1.0 if i == j else 0.0  # (A)^m / m! accumulated as T
                Phi[q, i, j] = T[i, j]
                G0[q, i, j] = T[i, j] * h
                G1[q, i, j] = T[i, j] * h * h * 0.5
        for m in range(1, 17):
            _matmul_into(T, A, W1)  # T <- T A / m  (= A^m / m!)
            for i in range(n):
                for j in range(n):
                    T[i, j] = W1[i, j] / m
            c0 = h / (m + 1)                  # A^m/(m+1)! = (A^m/m!) / (m+1)
            c1 = h * h / ((m + 1) * (m + 2))  # A^m/(m+2)! = (A^m/m!) / ((m+1)(m+2))
            for i in range(n):
                for j in range(n):
                    Phi[q, i, j] += T[i, j]
                    G0[q, i, j] += c0 * T[i, j]
                    G1[q, i, j] += c1 * T[i, j]
        for _ in range(s):
            _matmul_into(Phi[q], G1[q], W1)
            _matmul_into(Phi[q], G0[q], W2)
            _matmul_into(Phi[q], Phi[q], W3)
            for i in range(n):
                for j in range(n):
                    G1[q, i, j] = W1[i, j] + h * G0[q, i, j] + G1[q, i, j]
                    G0[q, i, j] = W2[i, j] + G0[q, i, j]
                    Phi[q, i, j] = W3[i, j]
            h *= 2.0


def deflected_depth_weights(structure: ToolPointStructure, process: CuttingProcess,
                            speed_rpm: float, theta: np.ndarray,
                            depth_m: float | None = None) -> np.ndarray | None:
    """Actual/nominal depth of each insert along the steady deflected path, shape (n, N).

    The steady deflection is ``r(a) = a r_1 + r_0``: ``r_1`` from the force that scales with
    the depth, ``r_0`` from the depth-independent edge force on the trailing side of the nose
    (``process.edge_fixed_m``). The ratio ``1 + e_r . r(a) / a`` is evaluated at ``depth_m``;
    without it (or without such edge lengths) only ``r_1`` counts, which does not depend on
    the depth. ``None`` for fixed-direction processes or without depth modulation (no such
    effect)."""
    parts = _deflection_parts(structure, process, speed_rpm)
    return None if parts is None else _deflected_weights(parts, process, theta, depth_m)


def _deflection_parts(structure: ToolPointStructure, process: CuttingProcess,
                      speed_rpm: float) -> tuple[np.ndarray, np.ndarray | None] | None:
    """Steady deflection per unit depth ``r_1`` and the depth-independent ``r_0`` (or None),
    each (720, 3) over one revolution; ``None`` when there is no depth modulation."""
    if not process.rotating or not np.any(process.depth_direction):
        return None
    from robobore.dynamics.timedomain import forced_response

    Ns = 720
    rp = forced_response(structure, process, speed_rpm, 1.0, Ns)  # (Ns,3), a = 1 m
    if np.any(process.edge_fixed_m):
        r0 = forced_response(structure, process, speed_rpm, 0.0, Ns)  # fixed edge force only
        return rp - r0, r0
    return rp, None


def _deflected_weights(parts, process: CuttingProcess, theta: np.ndarray,
                       depth_m: float | None) -> np.ndarray:
    rp, r0 = parts
    if r0 is not None and depth_m is not None and depth_m > 0.0:
        rp = rp + r0 / depth_m
    ang = 2 * np.pi * np.arange(rp.shape[0]) / rp.shape[0]
    th = np.mod(np.atleast_1d(theta), 2 * np.pi)
    r = np.column_stack([np.interp(th, ang, rp[:, k], period=2 * np.pi) for k in range(3)])
    N = process.n_inserts
    w = np.empty((th.size, N))
    for p in range(N):
        B = process.basis(th + 2 * np.pi * p / N)  # (n,3,3)
        w[:, p] = 1.0 + np.einsum("k,nki,ni->n", process.depth_direction, B, r)
    return np.clip(w, 0.0, None)


def _modal_mats(structure: ToolPointStructure, process: CuttingProcess, theta: np.ndarray,
                include_process_stiffness: bool = True, insert_weights=None):
    D = structure.directions  # (m,3)
    minv = 1.0 / structure.modal_mass
    A = process.directional_matrix(theta, insert_weights)  # (n,3,3)
    W = minv[None, :, None] * np.einsum("jo,noi,ki->njk", D, A, D)
    if include_process_stiffness:
        P = process.process_stiffness(theta)
        Pm = minv[None, :, None] * np.einsum("jo,noi,ki->njk", D, P, D)
    else:
        Pm = np.zeros_like(W)
    return W, Pm


@nb.njit(cache=True)
def _propagate(Phi, P0, P1, r, m, Z, out):  # pragma: no cover - numba
    """Apply the monodromy (``r`` semi-discretisation steps over one delay) to the columns of Z.

    State ``z_i = [x_i (2m), q_{i-1}, ..., q_{i-r}]`` with ``q = x[:m]`` (modal displacements);
    step ``i`` (coefficients ``Phi[i % k]``, ``P0``, ``P1``; ``k`` = 1 for constant ones)::

        x_{i+1} = Phi_i x_i + P0_i q_{i-r} + P1_i q_{i-r+1}

    ``Z``: (n, c) initial states; ``out`` (n, c) receives ``z_r`` = [x_r, q_{r-1}, ..., q_0].
    The delayed values live in a buffer indexed by time (no shifting), so one column costs
    O(r m^2) and the whole matrix O(r m^2 n)."""
    n2 = 2 * m
    c = Z.shape[1]
    k = Phi.shape[0]
    Q = np.empty((2 * r, m, c))  # Q[j + r] = q_j, j = -r .. r-1
    for s in range(1, r + 1):
        for a in range(m):
            for col in range(c):
                Q[r - s, a, col] = Z[n2 + (s - 1) * m + a, col]
    x = np.empty((n2, c))
    xn = np.empty((n2, c))
    for a in range(n2):
        for col in range(c):
            x[a, col] = Z[a, col]
    for i in range(r):
        for a in range(m):
            for col in range(c):
                Q[i + r, a, col] = x[a, col]
        p = i % k
        for a in range(n2):
            for col in range(c):
                xn[a, col] = 0.0
            for b in range(n2):
                w = Phi[p, a, b]
                for col in range(c):
                    xn[a, col] += w * x[b, col]
            for b in range(m):
                w0 = P0[p, a, b]
                w1 = P1[p, a, b]
                for col in range(c):
                    xn[a, col] += w0 * Q[i, b, col] + w1 * Q[i + 1, b, col]
        x, xn = xn, x
    for a in range(n2):
        for col in range(c):
            out[a, col] = x[a, col]
    for s in range(1, r + 1):
        for a in range(m):
            for col in range(c):
                out[n2 + (s - 1) * m + a, col] = Q[2 * r - s, a, col]


def _spectral_radius(Phi: np.ndarray, P0: np.ndarray, P1: np.ndarray, r: int, m: int) -> float:
    """Spectral radius of the monodromy matrix of :func:`_propagate` (dimension 2m + r m)."""
    n = 2 * m + r * m

    def dense() -> float:
        U = np.empty((n, n))
        _propagate(Phi, P0, P1, r, m, np.eye(n), U)
        if not np.all(np.isfinite(U)):  # overflow far beyond the limit: unstable
            return math.inf
        try:
            return float(np.max(np.abs(np.linalg.eigvals(U))))
        except np.linalg.LinAlgError:  # no convergence of the dense solver: counted unstable
            return math.inf

    if n <= DENSE_EIG_MAX:
        return dense()
    from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, LinearOperator, eigs

    buf = np.empty((n, 1))

    def mv(v: np.ndarray) -> np.ndarray:
        _propagate(Phi, P0, P1, r, m, np.ascontiguousarray(v, float).reshape(n, 1), buf)
        return buf[:, 0].copy()

    op = LinearOperator((n, n), matvec=mv, dtype=float)
    v0 = np.random.default_rng(12345).standard_normal(n)  # deterministic start vector
    try:
        ev = eigs(op, k=4, which="LM", tol=1e-9, ncv=min(n - 1, 20), maxiter=50 * n, v0=v0,
                  return_eigenvectors=False)
    except (ArpackNoConvergence, ArpackError, ValueError, np.linalg.LinAlgError):
        return dense()
    return float(np.max(np.abs(ev)))


def monodromy_spectral_radius(structure: ToolPointStructure, process: CuttingProcess,
                              speed_rpm: float, depth_m: float, steps: int = 0,
                              include_process_stiffness: bool = True,
                              about_deflected: bool = True) -> float:
    """Spectral radius of the semi-discretised monodromy matrix over one delay (< 1: stable).

    ``steps`` per delay (0: :func:`auto_steps`). ``about_deflected``: for the rotating bar
    with depth modulation, linearise about the steady deflected path (each insert's actual
    depth along the forced response, :func:`deflected_depth_weights`) rather than the
    undeflected nominal cut. ``inf`` when the step matrices overflow (far beyond the limit)."""
    steps = steps or auto_steps(structure, process, speed_rpm)
    with _limits(1):
        return _rho(structure, process, speed_rpm, depth_m, steps, include_process_stiffness,
                    about_deflected)


def _rho(structure, process, speed_rpm, depth_m, steps, include_process_stiffness,
         about_deflected, parts=False):
    with np.errstate(over="ignore", invalid="ignore"):
        rho = _monodromy(structure, process, speed_rpm, depth_m, steps,
                         include_process_stiffness, about_deflected, parts)
    return rho if math.isfinite(rho) else math.inf


def _monodromy(structure, process, speed_rpm, depth_m, steps, include_process_stiffness,
               about_deflected=True, parts=False):
    """``parts``: :func:`_deflection_parts` at this speed (``False``: compute them here)."""
    m = structure.n_modes
    tau = 60.0 / (process.n_inserts * speed_rpm)
    dt = tau / steps
    om = structure.omega
    base = np.zeros((2 * m, 2 * m))
    base[:m, m:] = np.eye(m)
    base[m:, :m] = -np.diag(om**2)
    base[m:, m:] = -np.diag(2 * structure.damping_ratio * om)
    constant = (not process.rotating) or process.n_inserts == 0
    n_th = 1 if constant else steps
    # coefficient angle at the middle of each step (delay = one insert pitch)
    theta = (np.arange(n_th) + 0.5) * dt * 2 * np.pi * speed_rpm / 60.0
    wts = None
    if about_deflected:
        if parts is False:
            parts = _deflection_parts(structure, process, speed_rpm)
        if parts is not None:
            wts = _deflected_weights(parts, process, theta, depth_m)
    W, Pm = _modal_mats(structure, process, theta, include_process_stiffness, wts)
    L = np.broadcast_to(base, (n_th, 2 * m, 2 * m)).copy()
    L[:, m:, :m] += -depth_m * W + Pm
    Phi, G0, G1 = np.empty_like(L), np.empty_like(L), np.empty_like(L)
    _step_matrices_batch(L, float(dt), Phi, G0, G1)
    if not (np.all(np.isfinite(Phi)) and np.all(np.isfinite(G0)) and np.all(np.isfinite(G1))):
        return math.inf
    Rq = np.zeros((n_th, 2 * m, m))
    Rq[:, m:, :] = process.overlap * depth_m * W
    P1 = (G1 / dt) @ Rq             # multiplies q_{i-r+1}
    P0 = (G0 - G1 / dt) @ Rq        # multiplies q_{i-r}
    return _spectral_radius(np.ascontiguousarray(Phi), np.ascontiguousarray(P0),
                            np.ascontiguousarray(P1), int(steps), int(m))


def auto_steps(structure: ToolPointStructure, process: CuttingProcess, speed_rpm: float,
               per_cycle: int = 20, lo: int = 30, hi: int = 400) -> int:
    """Semi-discretisation steps per delay: ``per_cycle`` steps per period of the highest mode."""
    tau = 60.0 / (process.n_inserts * speed_rpm)
    return int(min(hi, max(lo, math.ceil(per_cycle * structure.frequency_Hz.max() * tau))))


def depth_scan_grid(depth_hi_m: float = DEPTH_SCAN_HI_M, decades: float = DEPTH_SCAN_DECADES,
                    ratio: float = DEPTH_SCAN_RATIO) -> np.ndarray:
    """Geometric depth grid [m] of the critical-depth scan: ``depth_hi_m * 10**-decades`` up to
    ``depth_hi_m``, neighbouring depths ``ratio`` apart."""
    n = int(math.ceil(decades * math.log(10.0) / math.log(ratio))) + 1
    return np.geomspace(depth_hi_m * 10.0 ** (-decades), depth_hi_m, n)


def critical_depth_semidiscretization(structure: ToolPointStructure, process: CuttingProcess,
                                      speed_rpm: float,
                                      depth_hi_m: float = DEPTH_SCAN_HI_M,
                                      steps: int = 0, tol: float = 1e-3,
                                      include_process_stiffness: bool = True,
                                      about_deflected: bool = True,
                                      decades: float = DEPTH_SCAN_DECADES,
                                      ratio: float = DEPTH_SCAN_RATIO) -> float:
    """Critical depth [m] at one speed: the first depth at which the monodromy spectral radius
    reaches 1.

    The stability indicator ``rho(a) - 1`` is evaluated on the geometric grid of
    :func:`depth_scan_grid` from the bottom up; between the last stable and the first unstable
    grid depth the crossing is narrowed to a relative width ``tol`` by a bracketing root search
    on ``log rho`` over ``log a`` (Illinois false position, a bisection step whenever a value is
    not finite or the bracket shrank by less than half). Returns ``inf`` when no grid depth up
    to ``depth_hi_m`` is unstable (stable up to that depth) and 0 when the system is unstable
    already at ``depth_hi_m * 1e-3 * 10**-decades`` (an instability that does not need the
    cut, e.g. the depth-modulation stiffness). A spectral radius that overflows or is not a
    number counts as unstable. Never raises for a valid structure and process."""
    steps = steps or auto_steps(structure, process, speed_rpm)
    parts = _deflection_parts(structure, process, speed_rpm) if about_deflected else None

    def rho(b: float) -> float:
        r = _rho(structure, process, speed_rpm, b, steps, include_process_stiffness,
                 about_deflected, parts)
        return r if r == r else math.inf  # NaN counts as unstable

    with _limits(1):
        return _scan(rho, depth_hi_m, tol, decades, ratio)


def _scan(rho, depth_hi_m: float, tol: float, decades: float, ratio: float) -> float:
    """First crossing of ``rho(depth) = 1`` on the scan grid, then narrowed (see the caller)."""
    grid = depth_scan_grid(depth_hi_m, decades, ratio)
    r = rho(float(grid[0]))
    if r >= 1.0:
        floor = float(grid[0]) * 1e-3
        r_floor = rho(floor)
        if r_floor >= 1.0:
            return 0.0
        lo, r_lo, hi, r_hi = floor, r_floor, float(grid[0]), r
    else:
        lo = hi = None
        r_prev = r
        for a0, a1 in zip(grid[:-1], grid[1:], strict=True):
            r1 = rho(float(a1))
            if r1 >= 1.0:
                lo, r_lo, hi, r_hi = float(a0), r_prev, float(a1), r1
                break
            r_prev = r1
        if lo is None:
            return math.inf
    # Illinois false position on f = log rho over x = log a; f(x0) < 0 <= f(x1)
    x0, x1 = math.log(lo), math.log(hi)
    f0 = math.log(max(r_lo, 1e-300))
    f1 = math.log(r_hi) if math.isfinite(r_hi) else math.inf
    side = 0
    width_tol = math.log1p(tol)
    while x1 - x0 > width_tol:
        w = x1 - x0
        if math.isfinite(f1) and f1 > f0:
            x = x1 - f1 * w / (f1 - f0)
            x = min(max(x, x0 + 0.01 * w), x1 - 0.01 * w)
        else:
            x = 0.5 * (x0 + x1)
        rx = rho(math.exp(x))
        if rx >= 1.0:
            x1, f1 = x, (math.log(rx) if math.isfinite(rx) else math.inf)
            if side == -1 and math.isfinite(f0):
                f0 *= 0.5
            side = -1
        else:
            x0, f0 = x, math.log(max(rx, 1e-300))
            if side == 1 and math.isfinite(f1):
                f1 *= 0.5
            side = 1
        if x1 - x0 > 0.5 * w:  # slow progress: bisect once
            xm = 0.5 * (x0 + x1)
            rm = rho(math.exp(xm))
            if rm >= 1.0:
                x1, f1, side = xm, (math.log(rm) if math.isfinite(rm) else math.inf), -1
            else:
                x0, f0, side = xm, math.log(max(rm, 1e-300)), 1
    return math.exp(0.5 * (x0 + x1))


def lobes_semidiscretization(structure: ToolPointStructure, process: CuttingProcess,
                             speed_rpm: np.ndarray, steps: int = 0,
                             depth_hi_m: float = DEPTH_SCAN_HI_M,
                             progress=None) -> LobeResult:
    """Critical depth at each speed (:func:`critical_depth_semidiscretization`).

    ``inf`` at a speed: stable up to ``depth_hi_m`` (reported as unconditionally stable up to
    that depth). ``absolute_limit_m`` is the smallest finite critical depth (``inf`` if none)."""
    speeds = np.asarray(speed_rpm, float)
    out = np.empty(speeds.size)
    with _limits(1):
        for i, n in enumerate(speeds):
            out[i] = critical_depth_semidiscretization(structure, process, float(n),
                                                       depth_hi_m, steps)
            if progress is not None:
                progress(1)
    fin = out[np.isfinite(out)]
    alim = float(fin.min()) if fin.size else math.inf
    return LobeResult(speeds, out, np.full(speeds.size, np.nan), alim, math.nan,
                      "semi-discretization", depth_hi_m)

# --------------------------------------------------------------------------- mode coupling
@dataclass(frozen=True)
class ModeCoupling:
    """Mode-coupling analysis at one depth: eigenfrequencies [Hz], growth rates [1/s]."""

    depth_m: float
    unstable: bool
    undamped_coalescence: bool
    frequencies_Hz: np.ndarray
    growth_rate_per_s: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def mode_coupling(structure: ToolPointStructure, process: CuttingProcess,
                  depth_m: float) -> ModeCoupling:
    """Tlusty/Pan mode-coupling criterion at depth ``depth_m`` (no regeneration)."""
    m = structure.n_modes
    D = structure.directions
    minv = 1.0 / structure.modal_mass
    A0 = process.mean_directional_matrix()
    P0 = process.process_stiffness(np.linspace(0, 2 * np.pi, 720, endpoint=False)).mean(
        axis=0)
    Km = np.diag(structure.omega**2) + minv[:, None] * (D @ (depth_m * A0 - P0) @ D.T)
    L = np.zeros((2 * m, 2 * m))
    L[:m, m:] = np.eye(m)
    L[m:, :m] = -Km
    L[m:, m:] = -np.diag(2 * structure.damping_ratio * structure.omega)
    ev = np.linalg.eigvals(L)
    ev_u = np.linalg.eigvals(Km)
    coal = bool(np.any(np.abs(ev_u.imag) > 1e-9 * np.abs(ev_u).max()) or np.any(ev_u.real < 0))
    up = ev[ev.imag >= 0]
    return ModeCoupling(float(depth_m), bool(np.max(ev.real) > 0), coal,
                        np.abs(up.imag) / (2 * np.pi), up.real)


def mode_coupling_limit(structure: ToolPointStructure, process: CuttingProcess,
                        depth_hi_m: float = 0.05, damped: bool = True) -> float:
    """Smallest depth [m] at which the mode-coupling criterion flags instability (inf: none)."""

    def bad(b: float) -> bool:
        mc = mode_coupling(structure, process, b)
        return mc.unstable if damped else mc.undamped_coalescence

    grid = np.geomspace(depth_hi_m * 1e-7, depth_hi_m, 120)
    flags = [bad(b) for b in grid]
    if flags[0]:
        return 0.0
    if not any(flags):
        return math.inf
    i = flags.index(True)
    lo, hi = grid[i - 1], grid[i]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if bad(mid):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def sdof_absolute_limit(k: float, zeta: float, K: float, cos_factor: float) -> float:
    """Closed-form SDOF absolute limit 2 k zeta (1 + zeta) / (K cos_factor) [m] (Tlusty)."""
    return 2 * k * zeta * (1 + zeta) / (K * cos_factor)


def sdof_pocket_speeds(f_n: float, zeta: float, n_inserts: int, lobes: int) -> np.ndarray:
    """Speeds [rpm] of the lobe minima (pockets) of a SDOF system, closed form.

    The minimum of ``-1/(2 Re G)`` is at ``r^2 = 1 + 2 zeta`` where the phase gives
    ``eps = pi + 2 atan(r)``; lobe ``k`` passes there at ``n = 60 w_c / (N (eps + 2 pi k))``.
    """
    r = math.sqrt(1 + 2 * zeta)
    wc = 2 * math.pi * f_n * r
    eps = math.pi + 2 * math.atan(r)
    k = np.arange(lobes)
    return 60 * wc / (n_inserts * (eps + 2 * np.pi * k))


__all__ = ["LobeResult", "DEPTH_SCAN_HI_M", "depth_scan_grid", "frequency_grid",
           "oriented_eigenvalues", "lobe_branches",
           "lobes_frequency_domain", "lobe_curves", "monodromy_spectral_radius",
           "critical_depth_semidiscretization", "lobes_semidiscretization", "auto_steps",
           "deflected_depth_weights",
           "ModeCoupling",
           "mode_coupling", "mode_coupling_limit", "sdof_absolute_limit", "sdof_pocket_speeds"]
