"""Critical depth of cut over a spindle-speed range for many tool-point structures at once.

The same zero-order frequency-domain theory as
:func:`robobore.dynamics.stability.lobes_frequency_domain` (full regeneration, overlap 1):
for a chatter frequency ``w`` with an eigenvalue ``lambda`` of ``G(iw) A0`` and
``Re lambda < 0`` the lobes give the depth ``b = -1 / (2 Re lambda)`` at the speeds
``n_k = 60 w / (N (eps + 2 pi k))``, ``eps = pi + 2 arg(lambda) (mod 2 pi)``,
``k = 0, 1, ...``. The lowest point of the stability envelope over ``[n_min, n_max]`` is
therefore the smallest ``b(w)`` over the frequencies ``w`` for which some lobe number ``k``
puts ``n_k`` inside the range: a check per grid frequency, no speed grid. Where the
lowest point lies at an end of the range (high speeds, few lobes), it is found as in the
stability module's envelope: the three eigenvalue branches are followed from one grid point
to the next (nearest-neighbour pairing) and each lobe crossing ``n_min`` or ``n_max`` between
two points is interpolated linearly.

``G(iw) = sum_j u_j u_j^T / (w_j^2 - w^2 + 2 i zeta_j w_j w)`` is built from the modal
vectors, ``G A0 = sum_j h_j u_j (A0^T u_j)^T``, and its three eigenvalues are the roots of
the characteristic cubic (Cardano, polished by two Newton steps).

Grid per structure: ``n_global`` log-spaced points over 0.2 to 5 times the mode range and
``n_local`` points over ``w_j (1 +- 10 zeta_j)`` around each mode. Checked against
``lobes_frequency_domain`` (dense speed grid) in tests/plan/test_plan_model.py (within 0.5 %).
"""

from __future__ import annotations

import cmath
import math
from typing import Any

import numpy as np
from numba import njit, prange


@njit(cache=True)
def _cubic_roots(a, b, c, out):  # pragma: no cover - numba
    """Roots of x^3 + a x^2 + b x + c (complex coefficients) into out (3,)."""
    p = b - a * a / 3.0
    q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c
    D = q * q / 4.0 + p * p * p / 27.0
    s = cmath.sqrt(D)
    u1 = -q / 2.0 + s
    u2 = -q / 2.0 - s
    uu = u1 if abs(u1) >= abs(u2) else u2
    if abs(uu) == 0.0:
        u = 0j
    else:
        u = cmath.exp(cmath.log(uu) / 3.0)
    om = complex(-0.5, math.sqrt(3.0) / 2.0)
    om2 = complex(-0.5, -math.sqrt(3.0) / 2.0)
    for r in range(3):
        if r == 0:
            uk = u
        elif r == 1:
            uk = u * om
        else:
            uk = u * om2
        vk = -p / (3.0 * uk) if abs(uk) > 0.0 else 0j
        x = uk + vk - a / 3.0
        for _ in range(2):  # Newton polish
            f = ((x + a) * x + b) * x + c
            df = (3.0 * x + 2.0 * a) * x + b
            if abs(df) > 0.0:
                x = x - f / df
        out[r] = x


@njit(cache=True)
def _lobe_check(lam, lp, first, w, wprev, n_min, n_max, n_ins, best):  # pragma: no cover
    """The lowest lobe depth that the eigenvalue ``lam`` at the grid frequency ``w`` (and the
    same branch ``lp`` at the previous point ``wprev``, unless ``first``) gives inside the
    speed range ``[n_min, n_max]``, if below ``best``: ``(depth, w, speed)``; ``(inf, nan,
    nan)`` when none is."""
    two_pi = 2.0 * math.pi
    out_b = np.inf
    out_w = np.nan
    out_n = np.nan
    lo = 60.0 * w / (n_ins * n_max)
    hi = 60.0 * w / (n_ins * n_min)
    b = -1.0 / (2.0 * lam.real)
    eps = (math.pi + 2.0 * math.atan2(lam.imag, lam.real)) % two_pi
    if b < best:
        kk = math.ceil((lo - eps) / two_pi)
        if kk < 0:
            kk = 0
        ph = eps + two_pi * kk
        if ph <= hi and ph > 0.0:
            best = b
            out_b = b
            out_w = w
            out_n = 60.0 * w / (n_ins * ph)
    # range ends: a lobe crossing n_min or n_max between this and the previous point of the
    # branch (linear interpolation, as the stability module does)
    if first or not lp.real < 0.0:
        return out_b, out_w, out_n
    b0 = -1.0 / (2.0 * lp.real)
    e0 = (math.pi + 2.0 * math.atan2(lp.imag, lp.real)) % two_pi
    if abs(eps - e0) > math.pi or min(b0, b) >= best:
        return out_b, out_w, out_n
    for side in range(2):
        nb = n_min if side == 0 else n_max
        tau = 60.0 / (n_ins * nb)
        p0 = (wprev * tau - e0) / two_pi
        p1 = (w * tau - eps) / two_pi
        jlo = math.ceil(min(p0, p1))
        if jlo < 0:
            jlo = 0
        j = jlo
        while j <= max(p0, p1):
            t = (j - p0) / (p1 - p0) if p1 != p0 else 0.0
            bb = b0 + t * (b - b0)
            if bb < best:
                best = bb
                out_b = bb
                out_w = wprev + t * (w - wprev)
                out_n = nb
            j += 1
    return out_b, out_w, out_n


@njit(cache=True, parallel=True)
def _critical_kernel(f_hz, zeta, u, v, ranges, n_ins, n_global, n_local, out_b, out_f,
                     out_n, roots, perms):  # pragma: no cover - numba
    """f_hz, zeta (n, m); u, v (n, m, 3); ranges (R, 2) speed ranges [r/min];
    out_b/out_f/out_n (n, R), out_b filled with inf; scratch roots (n, 3, 3)
    (current, previous, reordered); perms (6, 3) the permutations of 3."""
    n_ranges = ranges.shape[0]
    n = f_hz.shape[0]
    m = f_hz.shape[1]
    two_pi = 2.0 * math.pi
    for k in prange(n):
        fmin = np.inf
        fmax = 0.0
        for j in range(m):
            if f_hz[k, j] < fmin:
                fmin = f_hz[k, j]
            if f_hz[k, j] > fmax:
                fmax = f_hz[k, j]
        wprev = 0.0
        npts = n_global + m * n_local
        for i in range(npts):
            if i < n_global:
                w = two_pi * 0.2 * fmin * (25.0 * fmax / fmin) ** (i / (n_global - 1.0))
            else:
                jm = (i - n_global) // n_local
                il = (i - n_global) % n_local
                x = -10.0 + 20.0 * il / (n_local - 1.0)
                w = two_pi * f_hz[k, jm] * (1.0 + max(zeta[k, jm], 1e-4) * x)
                if w <= 0.0:
                    w = 1e-9
            # M = sum_j h_j u_j v_j^T
            M00 = 0j
            M01 = 0j
            M02 = 0j
            M10 = 0j
            M11 = 0j
            M12 = 0j
            M20 = 0j
            M21 = 0j
            M22 = 0j
            for j in range(m):
                wj = two_pi * f_hz[k, j]
                h = 1.0 / complex(wj * wj - w * w, 2.0 * zeta[k, j] * wj * w)
                a0 = h * u[k, j, 0]
                a1 = h * u[k, j, 1]
                a2 = h * u[k, j, 2]
                M00 += a0 * v[k, j, 0]
                M01 += a0 * v[k, j, 1]
                M02 += a0 * v[k, j, 2]
                M10 += a1 * v[k, j, 0]
                M11 += a1 * v[k, j, 1]
                M12 += a1 * v[k, j, 2]
                M20 += a2 * v[k, j, 0]
                M21 += a2 * v[k, j, 1]
                M22 += a2 * v[k, j, 2]
            tr = M00 + M11 + M22
            mi = M00 * M11 - M01 * M10 + M00 * M22 - M02 * M20 + M11 * M22 - M12 * M21
            de = (M00 * (M11 * M22 - M12 * M21) - M01 * (M10 * M22 - M12 * M20)
                  + M02 * (M10 * M21 - M11 * M20))
            _cubic_roots(-tr, mi, -de, roots[k, 0])
            # follow the three eigenvalue branches from the previous grid point of the same
            # (sorted) block: nearest-neighbour pairing over the 6 permutations
            first = i == 0 or (i >= n_global and (i - n_global) % n_local == 0)
            if not first:
                bestc = np.inf
                bp = 0
                for pi in range(6):
                    c = 0.0
                    for r in range(3):
                        c += abs(roots[k, 0, perms[pi, r]] - roots[k, 1, r])
                    if c < bestc:
                        bestc = c
                        bp = pi
                for r in range(3):
                    roots[k, 2, r] = roots[k, 0, perms[bp, r]]
                for r in range(3):
                    roots[k, 0, r] = roots[k, 2, r]
            for r in range(3):
                lam = roots[k, 0, r]
                if not lam.real < 0.0:
                    continue
                lp = roots[k, 1, r]
                for q in range(n_ranges):
                    b, f, sp = _lobe_check(lam, lp, first, w, wprev, ranges[q, 0],
                                           ranges[q, 1], n_ins, out_b[k, q])
                    if b < out_b[k, q]:
                        out_b[k, q] = b
                        out_f[k, q] = f
                        out_n[k, q] = sp
            for r in range(3):
                roots[k, 1, r] = roots[k, 0, r]
            wprev = w
        for q in range(n_ranges):
            out_f[k, q] = out_f[k, q] / two_pi


_critical_kernel_serial = njit(cache=True)(_critical_kernel.py_func)


def critical_depth_range(frequency_Hz: np.ndarray, damping_ratio: np.ndarray, u: np.ndarray,
                         A0: np.ndarray, speed_min_rpm: float, speed_max_rpm: float,
                         n_inserts: int = 1, *, n_global: int = 400, n_local: int = 161
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lowest critical depth [m] over a speed range, for n structures at once.

    ``frequency_Hz``, ``damping_ratio`` (n, m); ``u`` (n, m, 3) modal vectors at the tool point
    in the process frame (``G = sum_j u_j u_j^T / (w_j^2 - w^2 + 2 i zeta_j w_j w)``);
    ``A0`` (3, 3) the revolution-averaged directional matrix [N/m^2] in the same frame.
    Returns (depth_m, chatter_frequency_Hz, speed_rpm) where the envelope is lowest, (n,) each;
    ``inf`` depth when no lobe falls in the range.
    """
    b, f, n = critical_depth_ranges(frequency_Hz, damping_ratio, u, A0,
                                    [(speed_min_rpm, speed_max_rpm)], n_inserts,
                                    n_global=n_global, n_local=n_local)
    return b[:, 0], f[:, 0], n[:, 0]


def critical_depth_ranges(frequency_Hz: np.ndarray, damping_ratio: np.ndarray, u: np.ndarray,
                          A0: np.ndarray, ranges: Any, n_inserts: int = 1, *,
                          n_global: int = 400, n_local: int = 161
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`critical_depth_range` over several speed ranges ``ranges`` ((R, 2) [r/min]; a
    range of one speed gives the limit at that speed) in one pass over the frequency grid (the
    eigenvalues are the same for every range): (depth_m, chatter_frequency_Hz, speed_rpm), each
    (n, R)."""
    f = np.ascontiguousarray(np.atleast_2d(frequency_Hz), dtype=float)
    z = np.ascontiguousarray(np.atleast_2d(damping_ratio), dtype=float)
    uu = np.ascontiguousarray(np.asarray(u, float).reshape(f.shape + (3,)))
    v = np.ascontiguousarray(np.einsum("ba,nmb->nma", np.asarray(A0, float), uu))
    rg = np.ascontiguousarray(np.asarray(ranges, float).reshape(-1, 2))
    n = f.shape[0]
    shape = (n, rg.shape[0])
    ob, of, on = np.full(shape, np.inf), np.full(shape, np.nan), np.full(shape, np.nan)
    roots = np.zeros((n, 3, 3), dtype=np.complex128)
    perms = np.array([[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]])
    kern = _critical_kernel if n >= 16 else _critical_kernel_serial
    kern(f, z, uu, v, rg, float(n_inserts), int(n_global), int(n_local), ob, of, on, roots,
         perms)
    return ob, of, on


__all__ = ["critical_depth_range", "critical_depth_ranges"]
