"""Zero-order frequency-domain stability solution: oriented transfer function, lobe branches,
and the numba kernels that turn them into the lobe envelope over spindle speed.

Zero-order frequency domain (Altintas' oriented transfer function; Altintas & Budak 1995 for
the averaged directional matrix): with ``A0`` the revolution-averaged directional matrix, the
characteristic equation is ``det(I + a (1 - mu e^{-i w tau}) G(iw) A0) = 0``. With ``lambda(w)``
an eigenvalue of ``G(iw) A0`` (for one mode and ``A0 = K u n^T``: ``lambda = K n^T G u``) and
``mu = 1``::

    a_lim = -1 / (2 Re lambda),   eps = 3 pi + 2 arg(lambda)  (mod 2 pi),
    n = 60 w / (N (eps + 2 pi k)),   k = 0, 1, 2, ...

(for ``mu < 1`` the phase condition is solved on the circle ``1 - mu e^{-i eps}``). The
non-regenerative depth-modulation stiffness ``P`` is NOT in the frequency-domain solution (it
does not scale with depth); semi-discretisation includes it.

The lobe diagram built from these is :func:`robobore.dynamics.stability.lobes_frequency_domain`.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from robobore.dynamics.structure import ToolPointStructure


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
    ev = np.ascontiguousarray(np.linalg.eigvals(M))  # (nw, 3)
    out = np.empty_like(ev)
    _track_eigenvalues(ev, _PERMS, out)
    return out.T


_PERMS = np.array([(0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)])


@nb.njit(cache=True)
def _track_eigenvalues(ev, perms, out):  # pragma: no cover - numba
    """Order the eigenvalues of each frequency (rows of ``ev``, (nw, 3)) by nearest-neighbour
    matching to the previous frequency's: the permutation of least summed distance."""
    out[0] = ev[0]
    for i in range(1, ev.shape[0]):
        best = 0
        cost = np.inf
        for q in range(perms.shape[0]):
            c = 0.0
            for k in range(3):
                c += abs(ev[i, perms[q, k]] - out[i - 1, k])
            if c < cost:
                best, cost = q, c
        for k in range(3):
            out[i, k] = ev[i, perms[best, k]]


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
def envelope(speeds_rpm, n_inserts, omega, b, eps, out_b, out_w):  # pragma: no cover - numba
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
def mode_coupling_line(omega, lam, out):  # pragma: no cover - numba
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


__all__ = ["frequency_grid", "oriented_eigenvalues", "lobe_branches", "envelope",
           "mode_coupling_line"]
