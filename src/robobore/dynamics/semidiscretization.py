"""Semi-discretisation stability solution: step matrices, monodromy, critical-depth scan.

Semi-discretisation (Insperger & Stepan 2002, 2004; first-order interpolation of the delayed
term, Insperger, Stepan & Turi 2008): the delay is split into ``r`` steps, the ODE is solved
exactly over each step with the delayed state linearly interpolated; the monodromy matrix over
one delay is the product of the step matrices; stable iff its spectral radius < 1.

For the rotating boring bar with depth modulation the dynamics are linearised about the steady
deflected path (:func:`deflected_depth_weights`). The lobe diagram built from the critical
depths is :func:`robobore.dynamics.stability.lobes_semidiscretization`.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from scipy.linalg import expm

from robobore.dynamics.process import CuttingProcess
from robobore.dynamics.structure import ToolPointStructure

from contextlib import contextmanager, nullcontext
from contextvars import ContextVar

try:  # a single BLAS thread: the many mid-size eigenproblems are slower multi-threaded
    from threadpoolctl import ThreadpoolController
except ImportError:  # pragma: no cover - optional
    ThreadpoolController = None

_BLAS = {"controller": None, "depth": 0}


@contextmanager
def blas_thread_limit(limits: int = 1):
    """Limit BLAS to ``limits`` threads inside the block (``threadpoolctl``; a no-op without
    it). The libraries are looked up once per process, and a nested block inside another one
    of this function keeps the outer limit without querying the libraries again."""
    if ThreadpoolController is None or _BLAS["depth"] > 0:
        ctx = nullcontext()
    else:
        if _BLAS["controller"] is None:
            _BLAS["controller"] = ThreadpoolController()
        ctx = _BLAS["controller"].limit(limits=limits)
    _BLAS["depth"] += 1
    try:
        with ctx:
            yield
    finally:
        _BLAS["depth"] -= 1


#: Depth range of the critical-depth scan [m]: the largest depth of cut a config accepts (50 mm)
#: and four decades below it. "Unconditionally stable" means: no instability up to the top.
DEPTH_SCAN_HI_M = 0.05
DEPTH_SCAN_DECADES = 4.0
#: Ratio between neighbouring depths of the scan grid (an unstable window narrower than this
#: in depth can be missed between two grid points).
DEPTH_SCAN_RATIO = 1.25
#: Monodromy matrices up to this size are solved densely; larger ones by an explicitly
#: restarted Arnoldi iteration on the matrix-free product (the eigenvalue of largest modulus),
#: falling back to the dense solver if it does not converge.
DENSE_EIG_MAX = 40
#: Richardson extrapolation of the spectral radius (:func:`monodromy_spectral_radius`) when
#: half the steps are at least this many.
RICHARDSON_MIN_STEPS = 12
#: Samples per revolution of the steady deflected path (:func:`deflected_depth_weights`).
DEFLECTION_SAMPLES = 360


def _step_matrices(Lc: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Phi = e^{L dt}, Gamma0 = int e^{L(dt-s)} ds, Gamma1 = int e^{L(dt-s)} s ds (Van Loan).

    ``Lc`` is one (n, n) matrix or a stack (k, n, n); the result has the same leading shape.
    Reference implementation (scipy's Pade expm of the augmented 3n x 3n matrix); the
    monodromy uses :func:`_step_matrices_modal`, which a test holds to this one."""
    n = Lc.shape[-1]
    H = np.zeros(Lc.shape[:-2] + (3 * n, 3 * n))
    H[..., :n, :n] = Lc
    H[..., :n, n:2 * n] = np.eye(n)
    H[..., n:2 * n, 2 * n:] = np.eye(n)
    E = expm(H * dt)
    return E[..., :n, :n], E[..., :n, n:2 * n], E[..., :n, 2 * n:]


@nb.njit(cache=True)
def _balance(L):  # pragma: no cover - numba
    """Diagonal scaling ``d`` (powers of 2) balancing the sum of the moduli of the stack ``L``
    (k, n, n) (Parlett & Reinsch 1969): ``D^-1 L D`` has rows and columns of like norms."""
    k_n, n, _ = L.shape
    M = np.zeros((n, n))
    for q in range(k_n):
        for i in range(n):
            for j in range(n):
                M[i, j] += abs(L[q, i, j])
    d = np.ones(n)
    for _ in range(100):
        done = True
        for i in range(n):
            c = 0.0
            r = 0.0
            for j in range(n):
                if j != i:
                    c += M[j, i]
                    r += M[i, j]
            if c == 0.0 or r == 0.0:
                continue
            tot = c + r
            f = 1.0
            g = r / 2.0
            while c < g:
                f *= 2.0
                c *= 4.0
            g = r * 2.0
            while c >= g:
                f /= 2.0
                c /= 4.0
            if (c + r) / f < 0.95 * tot:
                done = False
                d[i] *= f
                for j in range(n):
                    M[j, i] *= f
                    M[i, j] /= f
        if done:
            break
    return d


@nb.njit(cache=True)
def _step_matrices_modal(L, dt, Phi, G0, G1):  # pragma: no cover - numba
    """Phi, Gamma0, Gamma1 of :func:`_step_matrices` for a stack ``L`` (k, n, n) of the modal
    system matrices of :func:`_step_coefficients` (``L = [[0, I], [K, C]]``, ``C`` diagonal),
    in place; ``G0`` and ``G1`` only their last ``m`` columns (k, 2m, m), the ones the delayed
    term multiplies.

    The stack is balanced first by one diagonal similarity of powers of 2 (exact in floating
    point; :func:`_balance`): ``L' = D^-1 L D``, whose norm is of the order of the modes'
    angular frequencies rather than their squares, so that few doublings are needed. Then a
    Taylor series on ``h = dt / 2^s`` with ``||L' h||_1 <= 1/2``, of the lowest degree (at
    most 16) whose first omitted term is below 1e-17 relative, and ``s`` doublings:
    ``Phi(2h) = Phi^2``, ``G0(2h) = Phi G0 + G0``, ``G1(2h) = Phi G1 + h G0 + G1`` (split the
    integral at h); finally ``Phi = D Phi' D^-1`` and likewise both Gammas. Each Taylor
    product ``T A`` uses the blocks of ``A = L' h`` (a diagonal upper right and lower right, a
    full lower left), which the balancing keeps."""
    k_n, n, _ = L.shape
    m = n // 2
    d = _balance(L)
    T = np.empty((n, n))
    W1 = np.empty((n, n))
    W3 = np.empty((n, n))
    V1 = np.empty((n, m))
    V2 = np.empty((n, m))
    A21 = np.empty((m, m))
    e12 = np.empty(m)
    g22 = np.empty(m)
    for q in range(k_n):
        nrm = 0.0
        for j in range(n):
            c = 0.0
            for i in range(n):
                c += abs(L[q, i, j] * d[j] / d[i])
            nrm = max(nrm, c)
        nrm *= dt
        s = 0
        if nrm > 0.5:
            s = int(math.ceil(math.log2(nrm / 0.5)))
        h = dt / 2.0**s
        for j in range(m):
            e12[j] = L[q, j, m + j] * d[m + j] / d[j] * h
            g22[j] = L[q, m + j, m + j] * h
            for k in range(m):
                A21[j, k] = L[q, m + j, k] * d[k] / d[m + j] * h
        for i in range(n):
            for j in range(n):
                T[i, j] = 1.0 if i == j else 0.0
                Phi[q, i, j] = T[i, j]
            for j in range(m):
                G0[q, i, j] = T[i, m + j] * h
                G1[q, i, j] = T[i, m + j] * h * h * 0.5
        nh = nrm / 2.0**s
        deg = 16
        term = nh
        for j in range(1, 17):
            term *= nh / (j + 1)
            if term < 1e-17:
                deg = j
                break
        for mm in range(1, deg + 1):
            # T <- T A / mm with A = [[0, diag e12], [A21, diag g22]]
            for i in range(n):
                for k in range(m):
                    acc = 0.0
                    for c in range(m):
                        acc += T[i, m + c] * A21[c, k]
                    W1[i, k] = acc
                for k in range(m):
                    W1[i, m + k] = T[i, k] * e12[k] + T[i, m + k] * g22[k]
            for i in range(n):
                for j in range(n):
                    T[i, j] = W1[i, j] / mm
            c0 = h / (mm + 1)
            c1 = h * h / ((mm + 1) * (mm + 2))
            for i in range(n):
                for j in range(n):
                    Phi[q, i, j] += T[i, j]
                for j in range(m):
                    G0[q, i, j] += c0 * T[i, m + j]
                    G1[q, i, j] += c1 * T[i, m + j]
        for _ in range(s):
            for i in range(n):
                for j in range(m):
                    a1 = 0.0
                    a2 = 0.0
                    for k in range(n):
                        a1 += Phi[q, i, k] * G1[q, k, j]
                        a2 += Phi[q, i, k] * G0[q, k, j]
                    V1[i, j] = a1
                    V2[i, j] = a2
                for j in range(n):
                    acc = 0.0
                    for k in range(n):
                        acc += Phi[q, i, k] * Phi[q, k, j]
                    W3[i, j] = acc
            for i in range(n):
                for j in range(m):
                    G1[q, i, j] = V1[i, j] + h * G0[q, i, j] + G1[q, i, j]
                    G0[q, i, j] = V2[i, j] + G0[q, i, j]
                for j in range(n):
                    Phi[q, i, j] = W3[i, j]
            h *= 2.0
        for i in range(n):
            for j in range(n):
                Phi[q, i, j] *= d[i] / d[j]
            for j in range(m):
                sc = d[i] / d[m + j]
                G0[q, i, j] *= sc
                G1[q, i, j] *= sc


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
    if depth_m is not None:
        process = process.at_depth(depth_m)
    parts = _deflection_parts(structure, process, speed_rpm)
    return None if parts is None else _deflected_weights(parts, process, theta, depth_m)


def _deflection_parts(structure: ToolPointStructure, process: CuttingProcess,
                      speed_rpm: float) -> tuple[np.ndarray, np.ndarray | None] | None:
    """Steady deflection per unit depth ``r_1`` and the depth-independent ``r_0`` (or None),
    each (720, 3) over one revolution; ``None`` when there is no depth modulation."""
    if not process.rotating or not np.any(process.depth_direction):
        return None
    cache = process.memo
    key = ("deflection", float(speed_rpm), id(structure))
    hit = cache.get(key)
    if hit is not None and hit[0] is structure:
        return hit[1]
    out = _deflection_parts_uncached(structure, process, speed_rpm)
    if len(cache) > 4096:
        cache.clear()
    cache[key] = (structure, out)
    return out


def _deflection_parts_uncached(structure, process, speed_rpm):
    """:func:`~robobore.dynamics.timedomain.nominal_cut_deflection` at
    :data:`DEFLECTION_SAMPLES` samples per revolution, ``r_0`` None where the process has no
    depth-independent edge length."""
    from robobore.dynamics.timedomain import nominal_cut_deflection

    parts = nominal_cut_deflection(structure, process, speed_rpm, DEFLECTION_SAMPLES)
    if parts is None:
        return None
    r1, r0 = parts
    return (r1, r0) if np.any(process.edge_fixed_m) else (r1, None)


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


def interrupted_below(structure: ToolPointStructure, process: CuttingProcess,
                      speed_rpm: float, depth_m: float) -> float:
    """Depth [m] below which the steady forced vibration takes an insert out of the material,
    estimated with the steady deflections of the cut at ``depth_m`` (``a r_1 + r_0``, the
    process built at ``depth_m``; the depth's own geometry changes them little): the largest
    depth up to ``depth_m`` where the smallest actual/nominal depth ratio
    ``1 + e_r . (r_1 + r_0 / a)`` is at or below 0. 0 when the cut stays in the material
    down to vanishing depth (or has no depth modulation); ``depth_m`` itself when it is
    interrupted there (then at every smaller depth too, the ratio falling with the depth where
    ``r_0`` pulls the tool out, or staying below 0 where ``r_1`` alone does)."""
    process = process.at_depth(depth_m)
    parts = _deflection_parts(structure, process, speed_rpm)
    if parts is None:
        return 0.0
    rp, r0 = parts
    ang = 2 * np.pi * np.arange(rp.shape[0]) / rp.shape[0]
    N = process.n_inserts
    u1 = np.empty((N, rp.shape[0]))
    u0 = np.zeros((N, rp.shape[0]))
    for p in range(N):
        B = process.basis(ang + 2 * np.pi * p / N)
        u1[p] = np.einsum("k,nki,ni->n", process.depth_direction, B, rp)
        if r0 is not None:
            u0[p] = np.einsum("k,nki,ni->n", process.depth_direction, B, r0)

    def gmin(a: float) -> float:
        return float(np.min(1.0 + u1 + u0 / a))

    if gmin(depth_m) <= 0.0:
        return float(depth_m)
    lo = depth_m * 1e-6
    if gmin(lo) > 0.0:
        return 0.0
    hi = float(depth_m)
    for _ in range(50):  # gmin(lo) <= 0 < gmin(hi)
        mid = math.sqrt(lo * hi)
        if gmin(mid) <= 0.0:
            lo = mid
        else:
            hi = mid
        if hi / lo < 1.0 + 1e-4:
            break
    return lo


def chatter_free_window(structure: ToolPointStructure, process: CuttingProcess,
                        speed_rpm: float, guess_m: float | None = None,
                        **kwargs) -> tuple[float, float]:
    """``(interrupted_below_m, critical_depth_m)`` at one speed: the linear chatter limit
    (:func:`critical_depth_semidiscretization`, keyword arguments passed on) and the depth
    below which the steady forced vibration takes the tool out of the material
    (:func:`interrupted_below`, evaluated at the limit, or at the top of the scan when the cut
    is stable up to it). Depths between the two are chatter-free. When the cut is interrupted
    at the limit itself there is no chatter-free depth at that speed: the critical depth is
    then reported as 0 (with ``interrupted_below_m`` the linear limit). Where the spectral
    radius is at or above 1 at vanishing depth because the steady cut is interrupted there
    (the linearisation does not hold), the linear limit is the first crossing above the depth
    up to which the cut stays interrupted (:func:`_above_interruption`); 0 with
    ``interrupted_below_m`` 0 only where the cut is in the material at vanishing depth."""
    return _window(structure, process, speed_rpm, guess_m, None, **kwargs)[:2]


def chatter_limit(structure: ToolPointStructure, process: CuttingProcess, speed_rpm: float,
                  guess_m: float | None = None) -> float:
    """The depth [m] above which the cut chatters at one speed, as the lobes
    (:func:`chatter_free_windows`) place it: the linear limit of
    :func:`critical_depth_semidiscretization` (``guess_m`` as there), except where the
    spectral radius is at or above 1 at vanishing depth because the steady cut is
    interrupted there: then the first crossing above the depth up to which the cut stays
    interrupted, or that depth where the cut is unstable as soon as it is in the material
    (:func:`_above_interruption`, as :func:`chatter_free_window` does). ``inf``: stable up to
    the scan's top (the top itself where the cut is interrupted up to it); 0: unstable in the
    material at vanishing depth. Below this depth the cut does not chatter; whether it is
    chatter-free or interrupted by the forced vibration there is
    :func:`chatter_free_window`'s answer. This is the limit that the chatter verdicts of
    observed cuts are compared with (:mod:`robobore.dynamics.calibrate`) and that the lobes'
    band spreads (:mod:`robobore.dynamics.band`)."""
    a_c = critical_depth_semidiscretization(structure, process, speed_rpm, guess_m=guess_m)
    if a_c != 0.0:
        return a_c
    below, a_c = _above_interruption(structure, process, speed_rpm, DEPTH_SCAN_HI_M, 0, 1e-3,
                                     True, True, DEPTH_SCAN_DECADES, DEPTH_SCAN_RATIO)
    return a_c if a_c > 0.0 else below


def _window(structure, process, speed_rpm, guess_m, slope, depth_hi_m=DEPTH_SCAN_HI_M,
            steps=0, tol=1e-3, include_process_stiffness=True, about_deflected=True,
            decades=DEPTH_SCAN_DECADES, ratio=DEPTH_SCAN_RATIO):
    """:func:`chatter_free_window` and the slope of :func:`_critical_depth`."""
    a_c, sl = _critical_depth(structure, process, speed_rpm, depth_hi_m, steps, tol,
                              include_process_stiffness, about_deflected, decades, ratio,
                              guess_m, slope)
    floor = 0.0  # the cut is interrupted below this depth, each depth with its own geometry
    if a_c == 0.0:
        floor, a_c = _above_interruption(structure, process, speed_rpm, depth_hi_m, steps, tol,
                                         include_process_stiffness, about_deflected, decades,
                                         ratio)
        if a_c == 0.0:
            return floor, 0.0, sl
    top = a_c if math.isfinite(a_c) else depth_hi_m
    below = interrupted_below(structure, process, speed_rpm, float(top) * (1.0 - 1e-3))
    if below >= float(top) * (1.0 - 1e-3):
        return float(top), 0.0, sl
    return max(below, floor), a_c, sl


def _above_interruption(structure, process, speed_rpm, depth_hi_m, steps, tol,
                        include_process_stiffness, about_deflected, decades, ratio
                        ) -> tuple[float, float]:
    """``(interrupted_below_m, critical_depth_m)`` where the spectral radius is at or above 1
    at vanishing depth (:func:`_scan` gave 0).

    Where the steady cut at the scan's lowest depth is interrupted (each depth with its own
    chip geometry, :func:`interrupted_below`), the linearisation does not hold there and its
    radius says nothing about chatter: the depth up to which the cut stays interrupted is
    found on the scan grid from the bottom up (narrowed to a relative width ``tol``), and the
    linear limit is the first crossing of ``rho = 1`` above it (the grid scan from there, then
    :func:`_narrow`). ``(below, 0)`` when the cut is unstable as soon as it is in the
    material, ``(below, inf)`` when it is stable from there up to ``depth_hi_m``; ``(0, 0)``
    when the cut is in the material at the lowest depth (an instability at vanishing depth,
    e.g. the depth-modulation stiffness) and ``(depth_hi_m, 0)`` when it is interrupted up to
    the scan's top."""
    grid = depth_scan_grid(depth_hi_m, decades, ratio)

    def interrupted(a: float) -> bool:
        return interrupted_below(structure, process, speed_rpm, a) >= a

    if not interrupted(float(grid[0])):
        return 0.0, 0.0
    k = 1
    while k < grid.size and interrupted(float(grid[k])):
        k += 1
    if k == grid.size:
        return float(depth_hi_m), 0.0
    lo, hi = float(grid[k - 1]), float(grid[k])
    while hi / lo - 1.0 > tol:
        mid = math.sqrt(lo * hi)
        if interrupted(mid):
            lo = mid
        else:
            hi = mid
    steps = steps or auto_steps(structure, process, speed_rpm)

    def rho(b: float) -> float:
        r = _rho(structure, process, speed_rpm, b, steps, include_process_stiffness,
                 about_deflected)
        return r if r == r else math.inf  # NaN counts as unstable

    with _search_scope():
        r_prev = rho(hi)
        if r_prev >= 1.0:
            return lo, 0.0
        prev = hi
        for a1 in grid[k + 1:]:
            r1 = rho(float(a1))
            if r1 >= 1.0:
                return lo, _narrow(rho, prev, r_prev, float(a1), r1, tol)
            prev, r_prev = float(a1), r1
        return lo, math.inf


def chatter_free_windows(structure: ToolPointStructure, process: CuttingProcess,
                         speeds_rpm: np.ndarray, depth_hi_m: float = DEPTH_SCAN_HI_M,
                         steps: int = 0, progress=None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`chatter_free_window` at each speed of ``speeds_rpm`` in turn, each search
    continued from the last finite linear limit of the speeds before (``guess_m``; the
    interruption does not move it; a speed stable up to ``depth_hi_m`` starts the grid scan
    again) and started with the slope of ``log rho`` over ``log a`` measured there. Returns ``(interrupted_below_m, critical_depth_m)``, each (n,); ``progress(1)``
    is called after each speed."""
    speeds = np.asarray(speeds_rpm, float)
    out = np.empty(speeds.size)
    below = np.zeros(speeds.size)
    prev, slope = None, None
    with blas_thread_limit(1):
        for i, n in enumerate(speeds):
            below[i], out[i], sl = _window(structure, process, float(n), prev, slope,
                                           depth_hi_m=depth_hi_m, steps=steps)
            lin = out[i] if out[i] > 0.0 else below[i]
            if 0.0 < lin < depth_hi_m:
                prev, slope = float(lin), sl
            elif not np.isfinite(lin):  # stable up to the top: the scan again
                prev, slope = None, None
            # a 0 (unstable down to the scan's lowest depth) keeps the last finite limit
            if progress is not None:
                progress(1)
    return below, out


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
    rnd = _START_VECTORS.get(n)
    if rnd is None:
        rnd = np.random.default_rng(12345).standard_normal(n)  # deterministic start vector
        rnd /= np.linalg.norm(rnd)
        if len(_START_VECTORS) > 64:
            _START_VECTORS.clear()
        _START_VECTORS[n] = rnd
    search = _WARM_STARTS.get()
    warm = None if search is None else search.get(n)
    v = rnd.copy() if warm is None else (1.0 - ARNOLDI_RANDOM_SHARE) * warm + (
        ARNOLDI_RANDOM_SHARE * rnd)
    K = min(n - 1, ARNOLDI_VECTORS)
    V = np.empty((K + 1, n))
    H = np.empty((K + 1, K))
    work = (np.empty((2 * r, m)), np.empty(2 * m), np.empty(2 * m), np.empty(n))
    for _ in range(ARNOLDI_RESTARTS):
        k = _arnoldi(Phi, P0, P1, r, m, v, V, H, *work)
        if k < 0:  # overflow far beyond the limit: unstable
            return math.inf
        try:
            ev, Y = np.linalg.eig(H[:k, :k])
        except np.linalg.LinAlgError:
            return dense()
        i = int(np.argmax(np.abs(ev)))
        lam = abs(ev[i])
        y = Y[:, i] / np.linalg.norm(Y[:, i])
        v = V[:k].T @ (y.real + y.imag)
        nv = float(np.linalg.norm(v))
        if not (nv > 0.0 and math.isfinite(nv)):
            return dense()
        v /= nv
        resid = abs(H[k, k - 1] * y[k - 1]) if k == K else 0.0
        if resid <= ARNOLDI_TOL * max(lam, 1e-300):
            if search is not None:
                search[n] = v
            return float(lam)
    return dense()


@nb.njit(cache=True)
def _arnoldi(Phi, P0, P1, r, m, v0, V, H, Q, x, xn, w):  # pragma: no cover - numba
    """Arnoldi factorisation of the monodromy of :func:`_propagate` from ``v0``: orthonormal
    rows ``V[0..k]`` and the Hessenberg matrix ``H[:k+1, :k]`` (Gram-Schmidt twice), ``k`` =
    ``V.shape[0] - 1`` or fewer where the Krylov space closes (an invariant subspace, ``k``
    returned with ``H[k, k-1]`` irrelevant). -1 when a product overflows. The work arrays
    ``Q`` (2r, m), ``x``, ``xn`` (2m) and ``w`` (n) are overwritten; nothing is allocated."""
    K = V.shape[0] - 1
    n = v0.size
    n2 = 2 * m
    kc = Phi.shape[0]
    nrm = 0.0
    for a in range(n):
        nrm += v0[a] * v0[a]
    nrm = math.sqrt(nrm)
    for a in range(n):
        V[0, a] = v0[a] / nrm
    for i in range(K + 1):
        for j in range(K):
            H[i, j] = 0.0
    for j in range(K):
        # w = U V[j]: r steps, the delayed values in a buffer indexed by time
        for s_ in range(1, r + 1):
            for a in range(m):
                Q[r - s_, a] = V[j, n2 + (s_ - 1) * m + a]
        for a in range(n2):
            x[a] = V[j, a]
        for i in range(r):
            for a in range(m):
                Q[i + r, a] = x[a]
            p = i % kc
            for a in range(n2):
                acc = 0.0
                for b in range(n2):
                    acc += Phi[p, a, b] * x[b]
                for b in range(m):
                    acc += P0[p, a, b] * Q[i, b] + P1[p, a, b] * Q[i + 1, b]
                xn[a] = acc
            for a in range(n2):
                x[a] = xn[a]
        for a in range(n2):
            w[a] = x[a]
        for s_ in range(1, r + 1):
            for a in range(m):
                w[n2 + (s_ - 1) * m + a] = Q[2 * r - s_, a]
        wn0 = 0.0
        for a in range(n):
            wn0 += w[a] * w[a]
        if not math.isfinite(wn0):
            return -1
        for _ in range(2):  # classical Gram-Schmidt, twice (BLAS products)
            Vj = V[:j + 1]
            hv = np.dot(Vj, w)
            for i in range(j + 1):
                H[i, j] += hv[i]
            w -= np.dot(hv, Vj)
        wn = 0.0
        for a in range(n):
            wn += w[a] * w[a]
        wn = math.sqrt(wn)
        H[j + 1, j] = wn
        if wn <= 1e-13 * math.sqrt(wn0) or wn == 0.0:
            return j + 1
        for a in range(n):
            V[j + 1, a] = w[a] / wn
    return K


#: Arnoldi basis size of the spectral radius of large monodromy matrices.
ARNOLDI_VECTORS = 16
#: Explicit restarts (from the dominant Ritz vector) before the dense solver takes over.
ARNOLDI_RESTARTS = 30
#: Relative residual of the dominant Ritz pair at which the Arnoldi iteration stops.
ARNOLDI_TOL = 1e-10
#: Share of the fixed random vector in the Arnoldi start vector; the rest is the dominant
#: eigenvector of the last monodromy of the same dimension in the same critical-depth search
#: (a neighbouring depth at one speed, :func:`_search_scope`), so that the iteration starts
#: near the answer yet sees every direction. Outside a search, and for the first radius of
#: each search, the fixed random vector alone.
ARNOLDI_RANDOM_SHARE = 0.3
#: The fixed random start vector per dimension (a function of the dimension alone).
_START_VECTORS: dict = {}
#: The warm start vectors of the critical-depth search in progress (dimension -> vector), or
#: None outside one. Held per search, never across searches: a limit depends on its
#: arguments alone, not on what the process computed before it.
_WARM_STARTS: ContextVar[dict | None] = ContextVar("robobore_arnoldi_warm_starts",
                                                   default=None)


@contextmanager
def _search_scope():
    """A fresh set of Arnoldi warm starts for one critical-depth search (the searches nested
    in it get their own), dropped when it ends."""
    token = _WARM_STARTS.set({})
    try:
        yield
    finally:
        _WARM_STARTS.reset(token)


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
    with blas_thread_limit(1):
        return _rho(structure, process, speed_rpm, depth_m, steps, include_process_stiffness,
                    about_deflected)


def _rho(structure, process, speed_rpm, depth_m, steps, include_process_stiffness,
         about_deflected, parts=False, known=None):
    """Spectral radius with ``steps`` per delay, extrapolated to zero step (Richardson).

    First-order semi-discretisation converges as the square of the step (Insperger, Stepan &
    Turi 2008): ``rho(r) = rho* + C / r^2``, so the spectral radius with ``steps`` and with
    half of them give ``rho* = rho(r) + (rho(r) - rho(r/2)) / 3``. On the example robot at
    700 r/min (0.9 x its limit) 100 steps give 0.98392, 200 give 0.98414 and 800 give 0.98420;
    the extrapolation from 100 and 50 steps gives 0.98419.

    ``known`` (a dict kept by the critical-depth search at one speed): where the spectral
    radius with ``steps`` is farther from 1 than :data:`RICHARDSON_SIGN_MARGIN` times the
    largest extrapolation correction met so far (``known["correction"]``, at least
    :data:`RICHARDSON_SIGN_MIN`), the half-step solution is skipped and that value plus the
    last correction returned: the side of 1 is then certain, and the value only guides the
    search. Without ``known`` the extrapolation is always made."""
    with np.errstate(over="ignore", invalid="ignore"):
        if process.depth_dependent:
            at = process.at_depth(depth_m)
            if at is not process:
                process, parts = at, False
        if parts is False and about_deflected:
            parts = _deflection_parts(structure, process, speed_rpm)
        rho = _monodromy(structure, process, speed_rpm, depth_m, steps,
                         include_process_stiffness, about_deflected, parts)
        half = steps // 2
        if math.isfinite(rho) and half >= RICHARDSON_MIN_STEPS:
            if known is not None and "correction" in known and abs(rho - 1.0) > max(
                    RICHARDSON_SIGN_MIN, RICHARDSON_SIGN_MARGIN * known["largest"]):
                return max(0.0, rho + known["correction"])
            rho_h = _monodromy(structure, process, speed_rpm, depth_m, half,
                               include_process_stiffness, about_deflected, parts)
            if math.isfinite(rho_h):
                c = (rho - rho_h) / 3.0
                if known is not None:
                    known["correction"] = c
                    known["largest"] = max(abs(c), known.get("largest", 0.0))
                rho = max(0.0, rho + c)
    return rho if math.isfinite(rho) else math.inf


#: The Richardson half-step is skipped in the critical-depth search where the spectral radius
#: with the full steps is farther from 1 than this many times the largest correction met at
#: the speed (:func:`_rho`), and at least :data:`RICHARDSON_SIGN_MIN` from it.
RICHARDSON_SIGN_MARGIN = 10.0
RICHARDSON_SIGN_MIN = 0.02


def _monodromy(structure, process, speed_rpm, depth_m, steps, include_process_stiffness,
               about_deflected=True, parts=False):
    """``parts``: :func:`_deflection_parts` at this speed (``False``: compute them here).
    ``process`` is the process at ``depth_m`` (:func:`_rho` resolves
    :meth:`~robobore.dynamics.process.CuttingProcess.at_depth`)."""
    m = structure.n_modes
    tau = 60.0 / (process.n_inserts * speed_rpm)
    dt = tau / steps
    constant = (not process.rotating) or process.n_inserts == 0
    n_th = 1 if constant else steps
    rp = np.zeros((1, 3))
    weighted = False
    if about_deflected:
        if parts is False:
            parts = _deflection_parts(structure, process, speed_rpm)
        if parts is not None:
            rp, r0 = parts
            if r0 is not None and depth_m > 0.0:
                rp = rp + r0 / depth_m
            weighted = True
    core, vec, dd = _process_matrices(process)
    D, minv, om, zeta = _structure_arrays(structure)
    L = np.empty((n_th, 2 * m, 2 * m))
    W = np.empty((n_th, m, m))
    _step_coefficients(bool(process.rotating), int(process.n_inserts), float(dt),
                       float(speed_rpm), core, vec, dd, D, minv, om, zeta,
                       np.ascontiguousarray(rp), weighted, float(depth_m),
                       bool(include_process_stiffness), L, W)
    Phi, P0, P1 = np.empty_like(L), np.empty((n_th, 2 * m, m)), np.empty((n_th, 2 * m, m))
    if not _delay_matrices(L, W, float(dt), float(process.overlap * depth_m), Phi, P0, P1):
        return math.inf
    return _spectral_radius(Phi, P0, P1, int(steps), int(m))


def _process_matrices(process: CuttingProcess) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``core = sum_e w_e shear_e n_e^T``, ``vec = sum_e (w_e h0_e shear_e + s_e edge_e)``
    (:meth:`~robobore.dynamics.process.CuttingProcess.directional_matrix` and
    :meth:`~robobore.dynamics.process.CuttingProcess.process_stiffness` per unit depth) and
    the depth direction, kept with the process (for the same array objects: a copy made by
    :func:`dataclasses.replace` shares the memo, not necessarily the arrays)."""
    src = (process.width_per_depth, process.shear, process.normal, process.h0,
           process.edge_per_depth, process.edge, process.depth_direction)
    hit = process.memo.get("sd_matrices")
    if hit is not None and all(a is b for a, b in zip(hit[0], src, strict=True)):
        return hit[1]
    core = np.einsum("e,ei,ej->ij", process.width_per_depth, process.shear, process.normal)
    vec = (np.einsum("e,e,ei->i", process.width_per_depth, process.h0, process.shear)
           + np.einsum("e,ei->i", process.edge_per_depth, process.edge))
    out = (core, vec, np.asarray(process.depth_direction, float))
    process.memo["sd_matrices"] = (src, out)
    return out


_STRUCTURES: dict = {}


def _structure_arrays(structure: ToolPointStructure):
    """Modal directions (contiguous), inverse modal masses, angular frequencies and damping
    ratios, kept per structure (keyed by its values)."""
    key = (structure.frequency_Hz.tobytes(), structure.damping_ratio.tobytes(),
           structure.stiffness_N_per_m.tobytes(), np.asarray(structure.directions).tobytes())
    hit = _STRUCTURES.get(key)
    if hit is None:
        hit = (np.ascontiguousarray(structure.directions, dtype=float),
               1.0 / np.asarray(structure.modal_mass, float), np.asarray(structure.omega, float),
               np.asarray(structure.damping_ratio, float))
        if len(_STRUCTURES) > 256:
            _STRUCTURES.clear()
        _STRUCTURES[key] = hit
    return hit


@nb.njit(cache=True)
def _step_coefficients(rotating, N, dt, speed_rpm, core, vec, dd, D, minv, om, zeta, rp,
                       weighted, depth, with_p, L, W):  # pragma: no cover - numba
    """System matrices ``L`` (k, 2m, 2m) and the regenerative modal matrices ``W`` (k, m, m)
    per unit depth at the middle of each of the ``k`` steps (one for a constant process).

    At bar angle ``theta``: ``A = sum_p g_p B_p^T core B_p`` (:meth:`~robobore.dynamics.
    process.CuttingProcess.directional_matrix`; ``g_p = max(0, 1 + dd . B_p r(theta))`` along
    the steady deflected path ``r``, interpolated periodically in ``rp``, or 1 without
    ``weighted``), ``P = sum_p B_p^T vec dd^T B_p`` (:meth:`~robobore.dynamics.process.
    CuttingProcess.process_stiffness`, only ``with_p``), ``W = M^-1 D A D^T``,
    ``L = [[0, I], [-Omega^2 - a W + M^-1 D P D^T, -2 zeta Omega]]``."""
    k_n = L.shape[0]
    m = D.shape[0]
    M_r = rp.shape[0]
    B = np.zeros((3, 3))
    A = np.zeros((3, 3))
    P = np.zeros((3, 3))
    T = np.zeros((3, 3))
    rr = np.zeros(3)
    two_pi = 2.0 * math.pi
    for q in range(k_n):
        th = (q + 0.5) * dt * two_pi * speed_rpm / 60.0
        rr[0] = rr[1] = rr[2] = 0.0
        if weighted:
            t = th % two_pi
            u = t / two_pi * M_r
            i0 = int(math.floor(u))
            f = u - i0
            i0 = i0 % M_r
            i1 = (i0 + 1) % M_r
            for c in range(3):
                rr[c] = (1.0 - f) * rp[i0, c] + f * rp[i1, c]
        for a in range(3):
            for b in range(3):
                A[a, b] = 0.0
                P[a, b] = 0.0
        for p in range(max(N, 1)):
            for a in range(3):
                for b in range(3):
                    B[a, b] = 0.0
            if rotating:
                tp = th + two_pi * p / N
                c_, s_ = math.cos(tp), math.sin(tp)
                B[0, 0], B[0, 1] = -s_, c_
                B[1, 0], B[1, 1] = c_, s_
                B[2, 2] = 1.0
            else:
                B[0, 0] = B[1, 1] = B[2, 2] = 1.0
            g = 1.0
            if weighted:
                g = 1.0
                for a in range(3):
                    acc = 0.0
                    for b in range(3):
                        acc += B[a, b] * rr[b]
                    g += dd[a] * acc
                g = max(g, 0.0)
            # A += g B^T core B ; P += B^T (vec dd^T) B
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for c in range(3):
                        acc += core[a, c] * B[c, b]
                    T[a, b] = acc
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for c in range(3):
                        acc += B[c, a] * T[c, b]
                    A[a, b] += g * acc
            if with_p:
                for a in range(3):
                    bv = 0.0
                    for c in range(3):
                        bv += B[c, a] * vec[c]
                    for b in range(3):
                        bd = 0.0
                        for c in range(3):
                            bd += dd[c] * B[c, b]
                        P[a, b] += bv * bd
        for j in range(2 * m):
            for k in range(2 * m):
                L[q, j, k] = 0.0
        for j in range(m):
            L[q, j, m + j] = 1.0
            L[q, m + j, j] = -om[j] * om[j]
            L[q, m + j, m + j] = -2.0 * zeta[j] * om[j]
            for k in range(m):
                w_ = 0.0
                p_ = 0.0
                for a in range(3):
                    for b in range(3):
                        w_ += D[j, a] * A[a, b] * D[k, b]
                        p_ += D[j, a] * P[a, b] * D[k, b]
                W[q, j, k] = minv[j] * w_
                L[q, m + j, k] += -depth * minv[j] * w_ + minv[j] * p_


@nb.njit(cache=True)
def _delay_matrices(L, W, dt, overlap_depth, Phi, P0, P1):  # pragma: no cover - numba
    """Step matrices (:func:`_step_matrices_modal`) and the delayed-term matrices of
    :func:`_propagate`: with ``Rq = [0; mu a W]`` (2m, m), ``P1 = Gamma1 Rq / dt``
    (multiplies ``q_{i-r+1}``) and ``P0 = (Gamma0 - Gamma1 / dt) Rq`` (``q_{i-r}``). False
    when a step matrix is not finite (far beyond the limit)."""
    k_n, n2, _ = L.shape
    m = n2 // 2
    G0 = np.empty((k_n, n2, m))
    G1 = np.empty((k_n, n2, m))
    _step_matrices_modal(L, dt, Phi, G0, G1)
    for q in range(k_n):
        for a in range(n2):
            for b in range(n2):
                if not math.isfinite(Phi[q, a, b]):
                    return False
            for b in range(m):
                if not (math.isfinite(G0[q, a, b]) and math.isfinite(G1[q, a, b])):
                    return False
        for a in range(n2):
            for b in range(m):
                acc0 = 0.0
                acc1 = 0.0
                for c in range(m):
                    rq = overlap_depth * W[q, c, b]
                    g1 = G1[q, a, c] / dt
                    acc1 += g1 * rq
                    acc0 += (G0[q, a, c] - g1) * rq
                P0[q, a, b] = acc0
                P1[q, a, b] = acc1
    return True


def auto_steps(structure: ToolPointStructure, process: CuttingProcess, speed_rpm: float,
               per_cycle: int = 20, lo: int = 30, hi: int = 400) -> int:
    """Semi-discretisation steps per delay: ``per_cycle`` steps per period of the highest mode
    (even, within ``lo`` .. ``hi``)."""
    tau = 60.0 / (process.n_inserts * speed_rpm)
    r = int(min(hi, max(lo, math.ceil(per_cycle * structure.frequency_Hz.max() * tau))))
    return r + (r % 2)  # even: the Richardson step halves it


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
                                      ratio: float = DEPTH_SCAN_RATIO,
                                      guess_m: float | None = None) -> float:
    """Critical depth [m] at one speed: the first depth at which the monodromy spectral radius
    reaches 1.

    ``guess_m`` (the limit at a neighbouring speed, as :func:`lobes_semidiscretization`
    passes it): continuation instead of the grid scan. The spectral radius at the scan's
    lowest depth decides whether the cut is unstable there (then the grid scan as below);
    otherwise the crossing is bracketed from the guess outwards (``1 +- CONTINUATION_STEP``,
    the bracket doubling until it holds) and narrowed as below. It costs about a fifth of the
    grid scan and returns the same limit unless an unstable window lies between the scan's
    lowest depth and the crossing nearest the guess.

    The stability indicator ``rho(a) - 1`` is evaluated on the geometric grid of
    :func:`depth_scan_grid` from the bottom up; between the last stable and the first unstable
    grid depth the crossing is narrowed to a relative width ``tol`` by a bracketing root search
    on ``log rho`` over ``log a`` (Illinois false position, a bisection step whenever a value is
    not finite or the bracket shrank by less than half). Returns ``inf`` when no grid depth up
    to ``depth_hi_m`` is unstable (stable up to that depth) and 0 when the system is unstable
    already at ``depth_hi_m * 1e-3 * 10**-decades`` (an instability that does not need the
    cut, e.g. the depth-modulation stiffness). A spectral radius that overflows or is not a
    number counts as unstable. Never raises for a valid structure and process. Where the
    steady forced vibration takes the tool out of the material below the limit, the linear
    limit is not the whole answer: :func:`chatter_free_window` gives both ends."""
    return _critical_depth(structure, process, speed_rpm, depth_hi_m, steps, tol,
                           include_process_stiffness, about_deflected, decades, ratio,
                           guess_m, None)[0]


def _critical_depth(structure, process, speed_rpm, depth_hi_m, steps, tol,
                    include_process_stiffness, about_deflected, decades, ratio, guess_m,
                    slope):
    """:func:`critical_depth_semidiscretization` and the slope ``d log rho / d log a`` at the
    crossing (``None`` where none was measured), given a ``slope`` hint (or ``None``)."""
    steps = steps or auto_steps(structure, process, speed_rpm)
    parts = (_deflection_parts(structure, process, speed_rpm)
             if about_deflected and not process.depth_dependent else False)

    known: dict = {}

    def rho(b: float) -> float:
        r = _rho(structure, process, speed_rpm, b, steps, include_process_stiffness,
                 about_deflected, parts, known)
        return r if r == r else math.inf  # NaN counts as unstable

    with blas_thread_limit(1), _search_scope():
        if guess_m is not None and 0.0 < guess_m < depth_hi_m:
            return _continue(rho, guess_m, depth_hi_m, tol, decades, ratio, slope)
        return _scan(rho, depth_hi_m, tol, decades, ratio), None


#: First relative step of the continuation bracket (:func:`critical_depth_semidiscretization`)
#: when the secant steps from the guess do not bracket the crossing.
CONTINUATION_STEP = 0.03
#: Slope ``d log rho / d log a`` assumed at the guess when no neighbouring speed gave one.
CONTINUATION_SLOPE = 0.5
#: Largest secant step of the continuation, in ``log a`` (a factor of 1.5 in depth).
CONTINUATION_MAX_STEP = math.log(1.5)
#: Secant steps of the continuation before it falls back to the doubling bracket.
CONTINUATION_SECANT_STEPS = 4


def _log_rho(r: float) -> float:
    return math.log(r) if math.isfinite(r) and r > 0.0 else (
        math.inf if r >= 1.0 else math.log(1e-300))


def _continue(rho, guess: float, depth_hi_m: float, tol: float, decades: float,
              ratio: float, slope: float | None = None) -> tuple[float, float | None]:
    """Crossing of ``rho = 1`` found from ``guess``, after checking the scan's lowest depth
    (unstable there: the grid scan); returns it and the slope of ``log rho`` over ``log a``
    at the final bracket.

    Secant steps on ``f = log rho`` over ``x = log a`` (the first with the ``slope`` hint,
    each aimed a quarter of the tolerance past the estimated root, so that a good estimate
    brackets the crossing in one evaluation, and at most :data:`CONTINUATION_MAX_STEP`);
    once two points lie on either side of ``rho = 1`` the bracket is narrowed by
    :func:`_narrow`. When the secant steps do not bracket the crossing (no finite slope, a
    slope of the wrong sign, or :data:`CONTINUATION_SECANT_STEPS` steps) the bracket is grown
    outwards from the last point (``1 +- CONTINUATION_STEP``, doubling)."""
    lowest = float(depth_scan_grid(depth_hi_m, decades, ratio)[0])
    if guess <= lowest:
        return _scan(rho, depth_hi_m, tol, decades, ratio), None
    r = rho(guess)  # first: near the crossing, it measures the extrapolation correction
    if rho(lowest) >= 1.0:
        return _scan(rho, depth_hi_m, tol, decades, ratio), None
    x_lo, x_hi = math.log(lowest), math.log(depth_hi_m)
    width_tol = math.log1p(tol)
    x = math.log(guess)
    f = _log_rho(r)
    s = slope if slope is not None and math.isfinite(slope) and slope > 0.0 else (
        CONTINUATION_SLOPE)
    pts = [(x, r, f)]
    for _ in range(CONTINUATION_SECANT_STEPS):
        if not math.isfinite(f) or not s > 0.0:
            break
        d = -f / s
        d += math.copysign(0.25 * width_tol, d if d != 0.0 else -f)
        d = max(-CONTINUATION_MAX_STEP, min(CONTINUATION_MAX_STEP, d))
        xn = min(max(x + d, x_lo), x_hi)
        if xn == x:
            break
        rn = rho(math.exp(xn))
        fn = _log_rho(rn)
        if (rn >= 1.0) != (r >= 1.0):  # bracketed
            pts.append((xn, rn, fn))
            lo, hi = ((x, r), (xn, rn)) if r < 1.0 else ((xn, rn), (x, r))
            a = _narrow(rho, math.exp(lo[0]), lo[1], math.exp(hi[0]), hi[1], tol, pts)
            return a, _bracket_slope(pts)
        if not math.isfinite(fn):
            x, r, f = xn, rn, fn
            break
        s = (fn - f) / (xn - x)
        x, r, f = xn, rn, fn
        pts.append((x, r, f))
        if x >= x_hi and r < 1.0:
            return math.inf, None
    a = _grow(rho, math.exp(x), r, depth_hi_m, lowest, tol, decades, ratio)
    return a, None


def _bracket_slope(pts) -> float | None:
    """Slope of ``log rho`` over ``log a`` between the two finite points nearest the
    crossing on either side (``pts``: the evaluated ``(log a, rho, log rho)``)."""
    st = [p for p in pts if p[1] < 1.0 and math.isfinite(p[2])]
    un = [p for p in pts if p[1] >= 1.0 and math.isfinite(p[2])]
    if not st or not un:
        return None
    a = max(st, key=lambda p: p[2])
    b = min(un, key=lambda p: p[2])
    if b[0] == a[0]:
        return None
    sl = (b[2] - a[2]) / (b[0] - a[0])
    return sl if sl > 0.0 else None


def _grow(rho, start: float, r_start: float, depth_hi_m: float, lowest: float, tol: float,
          decades: float, ratio: float) -> float:
    """Crossing bracketed outwards from ``start`` (``1 +- CONTINUATION_STEP``, doubling), then
    narrowed; the grid scan where the cut is unstable down to the lowest depth."""
    step = 1.0 + CONTINUATION_STEP
    if r_start < 1.0:
        lo, r_lo = start, r_start
        while True:
            hi = min(lo * step, depth_hi_m)
            r_hi = rho(hi)
            if r_hi >= 1.0:
                break
            if hi >= depth_hi_m:
                return math.inf
            lo, r_lo, step = hi, r_hi, step * step
    else:
        hi, r_hi = start, r_start
        while True:
            lo = max(hi / step, lowest)
            r_lo = rho(lo)
            if r_lo < 1.0:
                break
            if lo <= lowest:  # unstable down to the lowest depth: the grid scan decides
                return _scan(rho, depth_hi_m, tol, decades, ratio)
            hi, r_hi, step = lo, r_lo, step * step
    return _narrow(rho, lo, r_lo, hi, r_hi, tol)


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
    return _narrow(rho, lo, r_lo, hi, r_hi, tol)


def _narrow(rho, lo: float, r_lo: float, hi: float, r_hi: float, tol: float,
            record: list | None = None) -> float:
    """Illinois false position on ``f = log rho`` over ``x = log a`` between a stable ``lo``
    and an unstable ``hi``, to a relative width ``tol``. Once the secant through the bracket
    puts the root within ``tol`` of the last point, the next point is placed just past that
    estimate (by 0.45 ``tol``), so that a good estimate closes the bracket in one evaluation;
    a bisection step whenever the bracket shrank by less than half."""
    x0, x1 = math.log(lo), math.log(hi)
    f0 = math.log(max(r_lo, 1e-300))
    f1 = math.log(r_hi) if math.isfinite(r_hi) else math.inf
    t0, t1 = f0, f1  # the true values (f0, f1 are scaled by the Illinois rule)
    side = 0
    width_tol = math.log1p(tol)

    def update(x: float, rx: float) -> float:
        nonlocal x0, x1, f0, f1, t0, t1, side
        fx = _log_rho(rx)
        if record is not None:
            record.append((x, rx, fx))
        if rx >= 1.0:
            x1, f1, t1 = x, fx, fx
            if side == -1 and math.isfinite(f0):
                f0 *= 0.5
            side = -1
        else:
            x0, f0, t0 = x, fx, fx
            if side == 1 and math.isfinite(f1):
                f1 *= 0.5
            side = 1
        return fx

    while x1 - x0 > width_tol:
        w = x1 - x0
        if math.isfinite(f1) and f1 > f0:
            x = x1 - f1 * w / (f1 - f0)
            x = min(max(x, x0 + 0.01 * w), x1 - 0.01 * w)
        else:
            x = 0.5 * (x0 + x1)
        fx = update(x, rho(math.exp(x)))
        if x1 - x0 <= width_tol:
            break
        if math.isfinite(fx) and math.isfinite(t0) and math.isfinite(t1) and t1 > t0:
            d = -fx * (x1 - x0) / (t1 - t0)  # secant distance from x to the root
            if abs(d) < width_tol:
                step = d + math.copysign(0.45 * width_tol, d if d != 0.0 else -fx)
                xs = min(max(x + step, x0 + 1e-3 * (x1 - x0)), x1 - 1e-3 * (x1 - x0))
                update(xs, rho(math.exp(xs)))
                continue
        if x1 - x0 > 0.5 * w:  # slow progress: bisect once
            xm = 0.5 * (x0 + x1)
            update(xm, rho(math.exp(xm)))
    return math.exp(0.5 * (x0 + x1))


def _dominant_pair(Phi: np.ndarray, P0: np.ndarray, P1: np.ndarray, r: int, m: int):
    """The monodromy's eigenvalue of largest modulus (complex) and the modal displacements
    ``q`` (m, complex) of its eigenvector; ``None`` when a product overflows."""
    n = 2 * m + r * m

    def dense():
        U = np.empty((n, n))
        _propagate(Phi, P0, P1, r, m, np.eye(n), U)
        if not np.all(np.isfinite(U)):
            return None
        try:
            ev, X = np.linalg.eig(U)
        except np.linalg.LinAlgError:
            return None
        i = int(np.argmax(np.abs(ev)))
        return complex(ev[i]), X[:m, i]

    if n <= DENSE_EIG_MAX:
        return dense()
    v = np.random.default_rng(12345).standard_normal(n)
    v /= np.linalg.norm(v)
    K = min(n - 1, ARNOLDI_VECTORS)
    V = np.empty((K + 1, n))
    H = np.empty((K + 1, K))
    work = (np.empty((2 * r, m)), np.empty(2 * m), np.empty(2 * m), np.empty(n))
    for _ in range(ARNOLDI_RESTARTS):
        k = _arnoldi(Phi, P0, P1, r, m, v, V, H, *work)
        if k < 0:
            return None
        try:
            ev, Y = np.linalg.eig(H[:k, :k])
        except np.linalg.LinAlgError:
            return dense()
        i = int(np.argmax(np.abs(ev)))
        lam = abs(ev[i])
        y = Y[:, i] / np.linalg.norm(Y[:, i])
        resid = abs(H[k, k - 1] * y[k - 1]) if k == K else 0.0
        if resid <= ARNOLDI_TOL * max(lam, 1e-300):
            return complex(ev[i]), (V[:k].T @ y)[:m]
        v = V[:k].T @ (y.real + y.imag)
        nv = float(np.linalg.norm(v))
        if not (nv > 0.0 and math.isfinite(nv)):
            return dense()
        v /= nv
    return dense()


def critical_multiplier(structure: ToolPointStructure, process: CuttingProcess,
                        speed_rpm: float, depth_m: float, steps: int = 0,
                        include_process_stiffness: bool = True,
                        about_deflected: bool = True,
                        near_Hz: float | None = None) -> tuple[complex, float, int]:
    """The monodromy's critical (largest-modulus) Floquet multiplier ``mu`` at one speed and
    depth, the chatter frequency [Hz] it gives, and the structural mode that carries it.

    A multiplier ``mu = |mu| exp(i phi)`` over the delay ``T`` (one insert period) is the
    vibration ``exp(i (phi + 2 pi k) t / T)`` for every integer ``k``: the frequencies
    ``|phi / (2 pi) + k| / T``, one delay's harmonic apart (Insperger & Stepan 2011,
    *Semi-Discretization for Time-Delay Systems*, ch. 3). The spectrum shows the branch the
    structure amplifies: the one nearest the natural frequency of the mode with the largest
    share of the eigenvector's modal strain energy (``k_j |q_j|^2``), or the one nearest
    ``near_Hz`` where that is given (a measured chatter frequency, for comparing with it).
    Returns ``(mu, frequency_Hz, mode)``; ``(nan, nan, -1)`` when the step matrices overflow
    (far beyond the limit). ``steps`` per delay (0: :func:`auto_steps`); no Richardson
    extrapolation (the phase converges faster than the modulus is needed)."""
    steps = steps or auto_steps(structure, process, speed_rpm)
    m = structure.n_modes
    with np.errstate(over="ignore", invalid="ignore"), blas_thread_limit(1):
        pr = process.at_depth(depth_m) if process.depth_dependent else process
        tau = 60.0 / (pr.n_inserts * speed_rpm)
        dt = tau / steps
        constant = (not pr.rotating) or pr.n_inserts == 0
        n_th = 1 if constant else steps
        rp = np.zeros((1, 3))
        weighted = False
        if about_deflected:
            parts = _deflection_parts(structure, pr, speed_rpm)
            if parts is not None:
                rp, r0 = parts
                if r0 is not None and depth_m > 0.0:
                    rp = rp + r0 / depth_m
                weighted = True
        core = np.einsum("e,ei,ej->ij", pr.width_per_depth, pr.shear, pr.normal)
        vec = (np.einsum("e,e,ei->i", pr.width_per_depth, pr.h0, pr.shear)
               + np.einsum("e,ei->i", pr.edge_per_depth, pr.edge))
        L = np.empty((n_th, 2 * m, 2 * m))
        W = np.empty((n_th, m, m))
        _step_coefficients(bool(pr.rotating), int(pr.n_inserts), float(dt), float(speed_rpm),
                           core, vec, np.asarray(pr.depth_direction, float),
                           np.ascontiguousarray(structure.directions, dtype=float),
                           1.0 / np.asarray(structure.modal_mass, float),
                           np.asarray(structure.omega, float),
                           np.asarray(structure.damping_ratio, float),
                           np.ascontiguousarray(rp), weighted, float(depth_m),
                           bool(include_process_stiffness), L, W)
        Phi = np.empty_like(L)
        P0, P1 = np.empty((n_th, 2 * m, m)), np.empty((n_th, 2 * m, m))
        if not _delay_matrices(L, W, float(dt), float(pr.overlap * depth_m), Phi, P0, P1):
            return complex("nan"), math.nan, -1
        pair = _dominant_pair(Phi, P0, P1, int(steps), int(m))
    if pair is None:
        return complex("nan"), math.nan, -1
    mu, q = pair
    energy = np.asarray(structure.stiffness_N_per_m, float) * np.abs(q) ** 2
    mode = int(np.argmax(energy))
    target = float(structure.frequency_Hz[mode]) if near_Hz is None else float(near_Hz)
    base = math.atan2(mu.imag, mu.real) / (2.0 * math.pi)  # in (-1/2, 1/2]
    k0 = math.floor(target * tau)
    cands = [abs(s * base + k) / tau for k in range(k0 - 1, k0 + 3) for s in (1.0, -1.0)]
    f = min(cands, key=lambda c: abs(c - target))
    return mu, float(f), mode


__all__ = ["DEPTH_SCAN_HI_M", "DEPTH_SCAN_DECADES", "DEPTH_SCAN_RATIO", "DENSE_EIG_MAX",
           "blas_thread_limit", "depth_scan_grid", "auto_steps", "deflected_depth_weights",
           "monodromy_spectral_radius", "critical_depth_semidiscretization",
           "interrupted_below", "chatter_limit",
           "chatter_free_window", "chatter_free_windows", "CONTINUATION_STEP",
           "CONTINUATION_SLOPE", "CONTINUATION_MAX_STEP", "CONTINUATION_SECANT_STEPS",
           "RICHARDSON_MIN_STEPS", "DEFLECTION_SAMPLES", "critical_multiplier"]
