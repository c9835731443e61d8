"""Stability of single-point cutting / boring: lobes, semi-discretisation, mode coupling.

Linearised dynamics (see :mod:`robobore.dynamics.process`): for depth of cut ``a`` and delay
``tau = 60 / (N n)``::

    M q'' + C q' + K q = D^T [ -a A(t) (r(t) - mu r(t - tau)) + P(t) r(t) ],   r = D q

Zero-order frequency domain (:mod:`robobore.dynamics.zero_order`; Altintas & Budak 1995):
the characteristic equation ``det(I + a (1 - mu e^{-i w tau}) G(iw) A0) = 0`` with ``A0`` the
revolution-averaged directional matrix, solved per eigenvalue of ``G(iw) A0``. The
non-regenerative depth-modulation stiffness ``P`` is NOT in the frequency-domain solution (it
does not scale with depth); semi-discretisation includes it.

Semi-discretisation (:mod:`robobore.dynamics.semidiscretization`; Insperger & Stepan 2002,
2004): the monodromy matrix over one delay; stable iff its spectral radius < 1.

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

import numpy as np

from robobore.dynamics.process import CuttingProcess
from robobore.dynamics.semidiscretization import (
    DEPTH_SCAN_HI_M,
    chatter_free_windows,
)
from robobore.dynamics.structure import ToolPointStructure
from robobore.dynamics.zero_order import (
    envelope,
    frequency_grid,
    lobe_branches,
    mode_coupling_line,
    oriented_eigenvalues,
)
from robobore.errors import ConfigError


@dataclass(frozen=True)
class LobeResult:
    """Stability lobes: ``speed_rpm`` (n,), ``critical_depth_m`` (n,), ``chatter_frequency_Hz``
    (n,), ``absolute_limit_m`` and its frequency; ``method``; ``depth_scan_max_m``: the top of
    the semi-discretisation depth scan (``inf`` depths mean stable up to it; ``None`` for the
    frequency domain); ``interrupted_below_m`` (n,) (semi-discretisation): the depth below
    which the steady forced vibration takes the tool out of the material (0: nowhere), so that
    the chatter-free depths at a speed lie between it and the critical depth
    (:func:`~robobore.dynamics.semidiscretization.chatter_free_window`)."""

    speed_rpm: np.ndarray
    critical_depth_m: np.ndarray
    chatter_frequency_Hz: np.ndarray
    absolute_limit_m: float
    absolute_limit_frequency_Hz: float
    method: str
    depth_scan_max_m: float | None = None
    interrupted_below_m: np.ndarray | None = None

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
        if self.interrupted_below_m is not None:
            d["interrupted_below_mm"] = self.interrupted_below_m * 1e3
            d["interrupted_speeds"] = int(np.sum(self.interrupted_below_m > 0))
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


#: Depth grid of the frequency-domain lobes of a depth-dependent process: from
#: DEPTH_SCAN_HI_M * 10**-FD_DEPTH_DECADES to DEPTH_SCAN_HI_M, neighbours FD_DEPTH_RATIO apart.
FD_DEPTH_DECADES = 4.0
FD_DEPTH_RATIO = 1.2


def lobes_frequency_domain(structure: ToolPointStructure, process: CuttingProcess,
                           speed_rpm: np.ndarray, omega: np.ndarray | None = None) -> LobeResult:
    """Zero-order frequency-domain lobes at the given spindle speeds (any number of modes).

    A depth-dependent (boring) process is judged at each depth on its own chip: the
    revolution-averaged directional matrix of ``process.at_depth(a)`` on a geometric depth
    grid (:data:`FD_DEPTH_RATIO`), the limit ``L(n; a)`` of each, and at each speed the first
    depth where ``a >= L(n; a)`` (interpolated linearly in ``log a`` between grid depths);
    ``inf`` when no grid depth reaches its limit, 0 when the lowest does."""
    speeds = np.asarray(speed_rpm, float)
    w = frequency_grid(structure) if omega is None else np.asarray(omega, float)
    if process.depth_dependent and process.overlap > 1.0 - 1e-9:
        return _lobes_frequency_domain_by_depth(structure, process, speeds, w)
    return _lobes_frequency_domain(structure, process, speeds, w)


def _lobes_frequency_domain_by_depth(structure, process, speeds, w) -> LobeResult:
    n = int(math.ceil(FD_DEPTH_DECADES * math.log(10.0) / math.log(FD_DEPTH_RATIO))) + 1
    grid = np.geomspace(DEPTH_SCAN_HI_M * 10.0 ** (-FD_DEPTH_DECADES), DEPTH_SCAN_HI_M, n)
    lim = np.empty((n, speeds.size))
    frq = np.empty((n, speeds.size))
    alim = np.empty(n)
    afrq = np.empty(n)
    for j, a in enumerate(grid):
        r = _lobes_frequency_domain(structure, process.at_depth(float(a)), speeds, w)
        lim[j], frq[j], alim[j], afrq[j] = (r.critical_depth_m, r.chatter_frequency_Hz,
                                            r.absolute_limit_m, r.absolute_limit_frequency_Hz)
    out = np.empty(speeds.size)
    out_f = np.empty(speeds.size)
    for i in range(speeds.size):
        out[i], out_f[i] = _first_fixed_point(grid, lim[:, i], frq[:, i])
    a_abs, f_abs = _first_fixed_point(grid, alim, afrq)
    return LobeResult(speeds, out, out_f, a_abs, f_abs, "frequency")


def _first_fixed_point(grid: np.ndarray, limit: np.ndarray, freq: np.ndarray
                       ) -> tuple[float, float]:
    """First depth of ``grid`` where ``a >= limit(a)``, interpolated in ``log a``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.log(grid) - np.log(np.where(limit > 0, limit, np.nan))
    g = np.where(np.isnan(g), np.where(limit <= 0, np.inf, -np.inf), g)  # limit 0: unstable
    hit = np.nonzero(g >= 0.0)[0]
    if hit.size == 0:
        return math.inf, math.nan
    j = int(hit[0])
    if j == 0:
        return 0.0, float(freq[0])
    g0, g1 = g[j - 1], g[j]
    if not (math.isfinite(g0) and math.isfinite(g1)) or g1 <= g0:
        return float(grid[j]), float(freq[j])
    t = -g0 / (g1 - g0)
    a = math.exp(math.log(grid[j - 1]) + t * (math.log(grid[j]) - math.log(grid[j - 1])))
    return a, float(freq[j] if t >= 0.5 else freq[j - 1])


def _lobes_frequency_domain(structure, process, speeds, w) -> LobeResult:
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
            mode_coupling_line(w, lam[k], tmp)
            best[k], wb[k] = tmp
        k = int(np.argmin(best))
        return LobeResult(speeds, np.full(speeds.size, best[k]),
                          np.full(speeds.size, wb[k] / (2 * np.pi)), float(best[k]),
                          float(wb[k] / (2 * np.pi)), "frequency (mu = 0: no regeneration)")
    b, eps = lobe_branches(lam, mu)
    out_b = np.empty(speeds.size)
    out_w = np.empty(speeds.size)
    envelope(speeds, int(process.n_inserts), w, b, np.nan_to_num(eps, nan=0.0), out_b, out_w)
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



def lobes_semidiscretization(structure: ToolPointStructure, process: CuttingProcess,
                             speed_rpm: np.ndarray, steps: int = 0,
                             depth_hi_m: float = DEPTH_SCAN_HI_M,
                             progress=None) -> LobeResult:
    """Critical depth at each speed (:func:`critical_depth_semidiscretization`), each speed's
    search continued from the previous speed's finite limit (``guess_m``).

    ``inf`` at a speed: stable up to ``depth_hi_m`` (reported as unconditionally stable up to
    that depth). ``absolute_limit_m`` is the smallest finite critical depth (``inf`` if none)."""
    speeds = np.asarray(speed_rpm, float)
    below, out = chatter_free_windows(structure, process, speeds, depth_hi_m=depth_hi_m,
                                      steps=steps, progress=progress)
    fin = out[np.isfinite(out)]
    alim = float(fin.min()) if fin.size else math.inf
    return LobeResult(speeds, out, np.full(speeds.size, np.nan), alim, math.nan,
                      "semi-discretization", depth_hi_m, below)


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
    """Tlusty/Pan mode-coupling criterion at depth ``depth_m`` (no regeneration), on the
    process's chip at that depth (:meth:`~robobore.dynamics.process.CuttingProcess.at_depth`)."""
    process = process.at_depth(depth_m)
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
    for _ in range(40):
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


__all__ = ["LobeResult", "lobes_frequency_domain", "lobe_curves", "lobes_semidiscretization",
           "ModeCoupling", "mode_coupling", "mode_coupling_limit", "sdof_absolute_limit",
           "sdof_pocket_speeds"]
