"""Time-domain simulation of regenerative single-point cutting / robotic boring.

The tool point moves on the modal model of :mod:`robobore.dynamics.structure`; the cutting
force follows the process of :mod:`robobore.dynamics.process` with the chip thickness taken
from the surface left by the previous passes:

* the surface is stored per angular sample (``samples_per_rev`` per revolution, an integer
  multiple of the number of inserts): the tool displacement ``r_s`` when that angle was last
  cut and the time step of that cut; an insert reaching the angle sees
  ``h_e = p h0_e - n_e . B (r - mu r_s)`` where ``p`` counts the passes since the last cut
  (several when the tool had left the cut), so multiple inserts give the delay 1/(N n);
* the tool leaves the cut where ``h_e <= 0``: no shearing force there, and the surface is not
  updated at an angle where no element cut (it keeps the older surface); the edge (ploughing)
  forces act on the nominally engaged edge -- including the rubbing-only elements on the
  trailing side of the nose (``h0 = 0``, depth-independent length ``edge_fixed_m``) -- while
  the insert cuts at all and vanish when it has left the cut (switching them element by
  element at ``h = 0`` would act as a relay and sustain an artificial micro-vibration);
* the entry into and exit from the cut are located within the step: ``h_e`` and the depth
  factor are linear over the step (the velocity extrapolation below), the shearing force is
  integrated over the part of the step where both are positive (midpoint rule on that part)
  and the edge force is weighted by the insert's in-cut fraction, so that the force impulse
  of a step the tool leaves or enters the cut in is second order in the step (switched per
  whole step it is first order, and the interrupted cut does not converge in the sampling);
  a step wholly in the cut is the plain midpoint rule; the surface at an angular sample is
  renewed when its midpoint is cut;
* the modal equations are integrated by exact discretisation with the force held over the step
  (zero-order hold; unconditionally stable, exact for the free response), the force being
  evaluated with the displacement extrapolated to the step midpoint (second order in the
  step: a plain hold lags half a step, which acts as a spurious damping change when the
  process stiffness is comparable to the structure's, as on a robot); the loop is one numba
  function with all arrays allocated before it.

Outputs (:func:`simulate`): an ``xarray.Dataset`` with units in attributes -- forces on the
tool (x horizontal, y vertical, z feed) [N], tool-point displacement [m] and acceleration
[m/s^2], the rotating-frame acceleration of the tool point (``rotational_acceleration``: the
acceleration of the tool point resolved on the rotating insert's radial and tangential
directions, i.e. what an accelerometer fixed to the bar would read without the constant
centripetal term), the chip area, the feed-direction amplitude per revolution, the machined
surface profile along the feed at one angle and its roughness (Ra, Rz) after removing the
form (a least-squares line along the bore: a taper or a drifting tool is form, not roughness).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
import xarray as xr

from robobore.dynamics.process import CuttingProcess
from robobore.dynamics.structure import ToolPointStructure
from robobore.errors import ConfigError, NumericalError
from robobore.io.ranges import check_positive


def modal_zoh(structure: ToolPointStructure, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH discretisation per mode: ``x+ = Phi x + Gam f`` with ``x = (q, q')``.

    Returns ``Phi`` (m, 2, 2) and ``Gam`` (m, 2) for a unit modal force [N] (``f = d_j . F``):
    closed-form exponential of the underdamped oscillator, ``Gam = A^-1 (Phi - I) B``.
    """
    m = structure.n_modes
    Phi = np.empty((m, 2, 2))
    Gam = np.empty((m, 2))
    for j in range(m):
        w = float(structure.omega[j])
        z = float(structure.damping_ratio[j])
        wd = w * math.sqrt(1.0 - z * z)  # 0 <= zeta < 1 is validated
        e = math.exp(-z * w * dt)
        c, sn = math.cos(wd * dt), math.sin(wd * dt)
        P = e * np.array([[c + z * w / wd * sn, sn / wd],
                          [-w * w / wd * sn, c - z * w / wd * sn]])
        Ainv = np.array([[-2 * z / w, -1 / (w * w)], [1.0, 0.0]])
        Phi[j] = P
        Gam[j] = Ainv @ (P - np.eye(2)) @ np.array([0.0, 1.0 / structure.modal_mass[j]])
    return Phi, Gam


@nb.njit(cache=True, inline="always")
def _positive_part(v, dv):  # pragma: no cover - compiled
    """The part ``[lo, hi]`` of ``s`` in ``[0, 1]`` where ``v + (s - 1/2) dv > 0`` (a value
    linear over the step, ``v`` at its midpoint); ``lo >= hi`` when there is none."""
    va = v - 0.5 * dv
    vb = v + 0.5 * dv
    if va > 0.0 and vb > 0.0:
        return 0.0, 1.0
    if va <= 0.0 and vb <= 0.0:
        return 1.0, 0.0
    sz = va / (va - vb)  # the zero crossing
    if va > 0.0:
        return 0.0, sz
    return sz, 1.0


@nb.njit(cache=True)
def _simulate_kernel(n_steps, Ns, N, Phi, Gam, D, basis, h0, w, ds, dsf, nrm, shr, edg, dd,
                     inv_depth, mu, om, zeta, minv, half_dt, q, qd, sr, tlast, F_out, X_out,
                     A_out, area_out, limit):  # pragma: no cover - compiled
    """Integrate ``n_steps``; returns the number of steps done (fewer when the tool-point
    displacement leaves ``[-limit, limit]`` or is not finite: a diverging cut)."""
    m = D.shape[0]
    E = h0.shape[0]
    spp = Ns // N
    for i in range(n_steps):
        # displacement at the step start (output) and, for the cutting force held over the
        # step, extrapolated to the step midpoint (removes the half-step lag of a plain hold)
        px = 0.0
        py = 0.0
        pz = 0.0
        rx = 0.0
        ry = 0.0
        rz = 0.0
        vx = 0.0
        vy = 0.0
        vz = 0.0
        for j in range(m):
            px += D[j, 0] * q[j]
            py += D[j, 1] * q[j]
            pz += D[j, 2] * q[j]
            qm = q[j] + half_dt * qd[j]
            rx += D[j, 0] * qm
            ry += D[j, 1] * qm
            rz += D[j, 2] * qm
            # displacement change over the step (the same linear extrapolation)
            vx += D[j, 0] * qd[j]
            vy += D[j, 1] * qd[j]
            vz += D[j, 2] * qd[j]
        vx *= 2.0 * half_dt
        vy *= 2.0 * half_dt
        vz *= 2.0 * half_dt
        fx = 0.0
        fy = 0.0
        fz = 0.0
        for p in range(N):
            jj = (i + p * spp) % Ns
            passes = (i - tlast[jj]) // spp
            ux = rx - mu * sr[jj, 0]
            uy = ry - mu * sr[jj, 1]
            uz = rz - mu * sr[jj, 2]
            c0 = basis[jj, 0, 0] * ux + basis[jj, 0, 1] * uy + basis[jj, 0, 2] * uz
            c1 = basis[jj, 1, 0] * ux + basis[jj, 1, 1] * uy + basis[jj, 1, 2] * uz
            c2 = basis[jj, 2, 0] * ux + basis[jj, 2, 1] * uy + basis[jj, 2, 2] * uz
            # change of the chip-frame displacement over the step
            d0 = basis[jj, 0, 0] * vx + basis[jj, 0, 1] * vy + basis[jj, 0, 2] * vz
            d1 = basis[jj, 1, 0] * vx + basis[jj, 1, 1] * vy + basis[jj, 1, 2] * vz
            d2 = basis[jj, 2, 0] * vx + basis[jj, 2, 1] * vy + basis[jj, 2, 2] * vz
            g = 1.0
            dg = 0.0
            if inv_depth > 0.0:
                a0 = basis[jj, 0, 0] * rx + basis[jj, 0, 1] * ry + basis[jj, 0, 2] * rz
                a1 = basis[jj, 1, 0] * rx + basis[jj, 1, 1] * ry + basis[jj, 1, 2] * rz
                a2 = basis[jj, 2, 0] * rx + basis[jj, 2, 1] * ry + basis[jj, 2, 2] * rz
                g = 1.0 + inv_depth * (dd[0] * a0 + dd[1] * a1 + dd[2] * a2)
                dg = inv_depth * (dd[0] * d0 + dd[1] * d1 + dd[2] * d2)
            # depth factor over the step: g(s) = g + (s - 1/2) dg, s in [0, 1]; the part of
            # the step with g > 0
            glo = 0.0
            ghi = 1.0
            if g - 0.5 * dg <= 0.0 or g + 0.5 * dg <= 0.0:
                glo, ghi = _positive_part(g, dg)
            area = 0.0
            f0 = 0.0
            f1 = 0.0
            f2 = 0.0
            e0 = 0.0
            e1 = 0.0
            e2 = 0.0
            ilo = 1.0  # the part of the step in which the insert cuts (any element)
            ihi = 0.0
            mid_cut = False
            for e in range(E):
                h = passes * h0[e] - (nrm[e, 0] * c0 + nrm[e, 1] * c1 + nrm[e, 2] * c2)
                if w[e] <= 0.0:
                    continue  # no shearing width (a rubbing-only element): no chip
                if h > 0.0 and g > 0.0:
                    mid_cut = True
                dh = -(nrm[e, 0] * d0 + nrm[e, 1] * d1 + nrm[e, 2] * d2)
                if ghi > glo and h - 0.5 * dh > 0.0 and h + 0.5 * dh > 0.0 and glo == 0.0 \
                        and ghi == 1.0:
                    # in the cut over the whole step: the midpoint rule
                    a = h * w[e] * (g if g > 0.0 else 0.0)
                    lo = 0.0
                    hi = 1.0
                else:
                    # the chip crosses zero within the step: the in-cut part [lo, hi]
                    # (h > 0 and g > 0, both linear in s), the midpoint rule over it
                    lo, hi = _positive_part(h, dh)
                    if glo > lo:
                        lo = glo
                    if ghi < hi:
                        hi = ghi
                    a = 0.0
                    if hi > lo:
                        sm = 0.5 * (lo + hi) - 0.5
                        a = (hi - lo) * (h + sm * dh) * w[e] * (g + sm * dg)
                if hi > lo:
                    if lo < ilo:
                        ilo = lo
                    if hi > ihi:
                        ihi = hi
                if a > 0.0:
                    area += a
                    f0 += shr[e, 0] * a
                    f1 += shr[e, 1] * a
                    f2 += shr[e, 2] * a
            if ihi > ilo:
                # edge (ploughing) forces act on the nominally engaged edge over the part of
                # the step in which the insert is in the cut (switching them per element at
                # h = 0 would make a relay); the engaged edge length: the leading part
                # stretches with the actual depth, the trailing side of the nose (dsf, set
                # by the feed) does not
                ge = g + (0.5 * (ilo + ihi) - 0.5) * dg
                if ge < 0.0:
                    ge = 0.0
                frac = ihi - ilo
                for e in range(E):
                    s = (ds[e] * ge + dsf[e]) * frac
                    e0 += edg[e, 0] * s
                    e1 += edg[e, 1] * s
                    e2 += edg[e, 2] * s
                f0 += e0
                f1 += e1
                f2 += e2
            if mid_cut:
                # the angular sample is cut at its midpoint: the surface there is new
                sr[jj, 0] = rx
                sr[jj, 1] = ry
                sr[jj, 2] = rz
                tlast[jj] = i
            area_out[i, p] = area
            fx += f0 * basis[jj, 0, 0] + f1 * basis[jj, 1, 0] + f2 * basis[jj, 2, 0]
            fy += f0 * basis[jj, 0, 1] + f1 * basis[jj, 1, 1] + f2 * basis[jj, 2, 1]
            fz += f0 * basis[jj, 0, 2] + f1 * basis[jj, 1, 2] + f2 * basis[jj, 2, 2]
        F_out[i, 0] = fx
        F_out[i, 1] = fy
        F_out[i, 2] = fz
        X_out[i, 0] = px
        X_out[i, 1] = py
        X_out[i, 2] = pz
        ax = 0.0
        ay = 0.0
        az = 0.0
        for j in range(m):
            fm = D[j, 0] * fx + D[j, 1] * fy + D[j, 2] * fz
            qdd = fm * minv[j] - 2.0 * zeta[j] * om[j] * qd[j] - om[j] * om[j] * q[j]
            ax += D[j, 0] * qdd
            ay += D[j, 1] * qdd
            az += D[j, 2] * qdd
            qn = Phi[j, 0, 0] * q[j] + Phi[j, 0, 1] * qd[j] + Gam[j, 0] * fm
            qdn = Phi[j, 1, 0] * q[j] + Phi[j, 1, 1] * qd[j] + Gam[j, 1] * fm
            q[j] = qn
            qd[j] = qdn
        A_out[i, 0] = ax
        A_out[i, 1] = ay
        A_out[i, 2] = az
        if not (abs(px) <= limit and abs(py) <= limit and abs(pz) <= limit):
            return i + 1
    return n_steps


#: Divergence limit of the time domain: this floor [m] plus this factor times the largest
#: steady forced displacement of the cut (:class:`SimulationSettings`).
DIVERGENCE_FLOOR_M = 2e-3
DIVERGENCE_FORCED_FACTOR = 10.0


@dataclass(frozen=True)
class SimulationSettings:
    """Spindle speed [rpm], depth of cut [m], revolutions, samples per revolution (0: auto).

    ``start``: ``"periodic"`` (default) starts on the steady forced response to the nominal
    cutting force (no start-up transient) plus a small displacement ``perturbation_m`` of every
    mode (default 1 % of the largest nominal chip thickness), so that ``vibration_growth``
    measures the growth of that perturbation; ``"rest"`` starts from zero displacement with the
    nominal chip (the tool is loaded suddenly).

    ``divergence_limit_m``: the run stops when the tool-point displacement exceeds this: the
    linear cutting model means nothing beyond it (the insert would break or the bar hit the
    wall). The Dataset is then cut at the last whole revolution and flagged ``diverged``; the
    cut is vibratory. Default (``None``): :data:`DIVERGENCE_FLOOR_M` (2 mm, tens of times a
    finishing cut's depth or feed) plus :data:`DIVERGENCE_FORCED_FACTOR` times the largest
    steady forced displacement of the cut, so that the deflection a deep cut causes by itself
    is not taken for a divergence.
    """

    speed_rpm: float
    depth_m: float
    revolutions: int = 150
    samples_per_rev: int = 0
    start: str = "periodic"
    perturbation_m: float | None = None
    divergence_limit_m: float | None = None

    def check(self) -> None:
        check_positive(self.speed_rpm, "speed_rpm", field="speed_rpm")
        check_positive(self.depth_m * 1e3, "depth_mm", field="depth_mm")
        if not 1 <= int(self.revolutions) <= 20000:
            raise ConfigError("revolutions out of range", field="revolutions",
                              value=self.revolutions, expected="1 .. 20000")
        if self.start not in ("periodic", "rest"):
            raise ConfigError("unknown start", field="start", value=self.start,
                              expected="periodic or rest")
        lim = self.divergence_limit_m
        if lim is not None and not (math.isfinite(lim) and lim > 0.0):
            raise ConfigError("divergence limit must be positive", field="divergence_limit_m",
                              value=self.divergence_limit_m, expected="a length > 0 in m")
        if self.samples_per_rev and not 8 <= self.samples_per_rev <= 200000:
            raise ConfigError("samples per revolution out of range", field="samples_per_rev",
                              value=self.samples_per_rev, expected="8 .. 200000")


def auto_samples_per_rev(structure: ToolPointStructure, speed_rpm: float, n_inserts: int,
                         per_period: int = 300, minimum: int = 720) -> int:
    """Samples per revolution: >= ``per_period`` per period of the highest mode, multiple of N.

    The default is generous on purpose: with a rotating bar and a process stiffness comparable
    to the robot's, the growth rate per revolution converges only slowly with the step (300
    samples per period of the highest mode keep it within ~0.1 % of the converged value;
    60 samples gave 1-2 % errors near the stability limit)."""
    f_rev = speed_rpm / 60.0
    ns = max(minimum, int(math.ceil(per_period * structure.frequency_Hz.max() / f_rev)))
    return int(math.ceil(ns / n_inserts) * n_inserts)


def periodic_start(structure: ToolPointStructure, process: CuttingProcess, Ns: int,
                   depth_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steady forced response to the nominal (rigid-tool) cutting force.

    The nominal force per angular sample (all inserts) is expanded in harmonics of the
    spindle frequency and passed through each mode's receptance. In that periodic state the
    regenerative term vanishes (``r(t) = r(t - tau)``). Returns the modal displacement and
    velocity at t = 0, shape (m,), and the surface memory ``r_s`` per sample, shape (Ns, 3).
    (The depth-modulation stiffness is left out; it leaves a small transient.)
    """
    F = _nominal_force(process, 2 * np.pi * np.arange(Ns) / Ns, depth_m)
    fm = F @ structure.directions.T  # (Ns, m)
    c = np.fft.fft(fm, axis=0) / Ns
    k = np.fft.fftfreq(Ns, 1.0 / Ns)  # harmonic numbers
    om = 2 * np.pi * k[:, None]  # x spindle angular frequency, applied below
    return c, om, F


@nb.njit(cache=True)
def _orbit_kernel(Phi, Gam, D, dd, vec, fixed, N, half_dt, X_out):  # pragma: no cover - numba
    """Periodic orbits of the discrete map of :func:`_simulate_kernel` on the nominal chip.

    Step ``i``: ``x+ = Phi x + Gam (Fm_i + Pm_i (q + half_dt q'))`` per mode, the state
    ``x = (q_1..q_m, q'_1..q'_m)`` (2m). At the step midpoint ``theta_i = 2 pi (i + 1/2) / Ns``
    and insert ``p`` (``theta_i + 2 pi p / N``, basis ``B_p``): the depth-modulation stiffness
    in modal coordinates ``Pm_i = sum_p u_p v_p^T`` with ``u_p = D B_p^T vec``,
    ``v_p = D B_p^T dd``, and two load cases ``Fm_i = sum_p D B_p^T (vec, fixed)`` (the
    nominal force per unit depth and the depth-independent edge force). A step is the per-mode
    ``Phi`` plus one rank-one term per insert, ``(Gam u_p)(v_p, half_dt v_p)^T``, and is applied
    as such (:func:`_orbit_step`). Composes the Ns steps into ``x_Ns = T x_0 + c``, solves
    ``x_0 = T x_0 + c`` and writes both orbits' states at the step starts into ``X_out``
    (2, Ns, 2m), load case first. Returns False when ``I - T`` is singular or the composed
    map is not finite (it overflows over one revolution: a structure far softer than any
    robot's, as a band secant many standard deviations wide meets): no orbit."""
    Ns = X_out.shape[1]
    m = D.shape[0]
    n = 2 * m
    U = np.zeros((Ns, N, m))
    Vv = np.zeros((Ns, N, m))
    Fm = np.zeros((Ns, m, 2))
    two_pi = 2.0 * math.pi
    for i in range(Ns):
        th = two_pi * (i + 0.5) / Ns
        for p in range(N):
            tp = th + two_pi * p / N
            c_, s_ = math.cos(tp), math.sin(tp)
            # B^T x = x_t e_t + x_r e_r + x_z e_z, e_t = (-s, c, 0), e_r = (c, s, 0)
            fv0, fv1, fv2 = -s_ * vec[0] + c_ * vec[1], c_ * vec[0] + s_ * vec[1], vec[2]
            ff0, ff1, ff2 = (-s_ * fixed[0] + c_ * fixed[1], c_ * fixed[0] + s_ * fixed[1],
                             fixed[2])
            fe0, fe1, fe2 = -s_ * dd[0] + c_ * dd[1], c_ * dd[0] + s_ * dd[1], dd[2]
            for j in range(m):
                u = D[j, 0] * fv0 + D[j, 1] * fv1 + D[j, 2] * fv2
                U[i, p, j] = u
                Vv[i, p, j] = D[j, 0] * fe0 + D[j, 1] * fe1 + D[j, 2] * fe2
                Fm[i, j, 0] += u
                Fm[i, j, 1] += D[j, 0] * ff0 + D[j, 1] * ff1 + D[j, 2] * ff2
    # Z = [T | c] <- A Z + [0 | Gam Fm_i] (T (n, n), c (n, 2))
    Z = np.zeros((n, n + 2))
    for r in range(n):
        Z[r, r] = 1.0
    Z2 = np.empty((n, n + 2))
    w = np.empty(n + 2)
    for i in range(Ns):
        _orbit_step(Phi, Gam, U[i], Vv[i], Fm[i], half_dt, Z, Z2, n, w)
        Z, Z2 = Z2, Z
    for r in range(n):
        for col in range(n + 2):
            if not math.isfinite(Z[r, col]):  # the composed map overflowed: no orbit
                return False
    T = np.ascontiguousarray(Z[:, :n])
    c = np.ascontiguousarray(Z[:, n:])
    M = np.eye(n) - T
    if abs(np.linalg.det(M)) < 1e-300:
        return False
    x = np.ascontiguousarray(np.linalg.solve(M, c))
    x2 = np.empty((n, 2))
    for i in range(Ns):
        for r in range(n):
            X_out[0, i, r] = x[r, 0]
            X_out[1, i, r] = x[r, 1]
        _orbit_step(Phi, Gam, U[i], Vv[i], Fm[i], half_dt, x, x2, 0, w)
        x, x2 = x2, x
    return True


@nb.njit(cache=True)
def _orbit_step(Phi, Gam, U, Vv, Fm_i, half_dt, X, Y, c0, w):  # pragma: no cover - numba
    """``Y = A X + [0 | b]`` for one step of :func:`_orbit_kernel`:
    ``A = blockdiag_j Phi_j + sum_p (Gam u_p)(v_p, half_dt v_p)^T`` in the state order
    ``(q_1..q_m, q'_1..q'_m)``, ``b = Gam Fm_i`` added to X's columns from ``c0`` on (column
    ``c0 + k`` takes load case ``k``); ``w`` (at least X's columns) is work space."""
    m = Phi.shape[0]
    ncol = X.shape[1]
    for j in range(m):
        for col in range(ncol):
            x0 = X[j, col]
            x1 = X[m + j, col]
            Y[j, col] = Phi[j, 0, 0] * x0 + Phi[j, 0, 1] * x1
            Y[m + j, col] = Phi[j, 1, 0] * x0 + Phi[j, 1, 1] * x1
    for p in range(U.shape[0]):
        for col in range(ncol):
            acc = 0.0
            for k in range(m):
                acc += Vv[p, k] * (X[k, col] + half_dt * X[m + k, col])
            w[col] = acc
        for j in range(m):
            g0 = Gam[j, 0] * U[p, j]
            g1 = Gam[j, 1] * U[p, j]
            for col in range(ncol):
                Y[j, col] += g0 * w[col]
                Y[m + j, col] += g1 * w[col]
    for j in range(m):
        for col in range(c0, ncol):
            Y[j, col] += Gam[j, 0] * Fm_i[j, col - c0]
            Y[m + j, col] += Gam[j, 1] * Fm_i[j, col - c0]


def periodic_orbit(structure: ToolPointStructure, process: CuttingProcess, Ns: int,
                   depth_m: float, speed_rpm: float):
    """The steady periodic cut of the time-domain map, depth-modulation stiffness included.

    On the nominal chip (every insert cutting ``h0``, the surface one pitch old equal to the
    present path, so no regeneration) the simulated map is linear with period one revolution:
    the nominal force plus the depth-modulation stiffness ``P(theta) r``
    (:meth:`~robobore.dynamics.process.CuttingProcess.process_stiffness`) at the step
    midpoints, integrated as :func:`simulate` integrates it. Its periodic orbit is solved
    exactly (the Ns steps composed, ``x_0 = T x_0 + c``). Returns ``(q0, qd0, sr, r_t)`` as
    :func:`_periodic_state`; ``None`` when the process has no depth modulation (the harmonic
    solution is then exact) or the orbit does not exist (``I - T`` singular, or the map
    overflowing over one revolution)."""
    orbits = _orbits(structure, process, Ns, speed_rpm)
    if orbits is None:
        return None
    X = depth_m * orbits[0] + orbits[1]
    m = structure.n_modes
    dt = 60.0 / (speed_rpm * Ns)
    D = structure.directions
    q_t, qd_t = X[:, :m], X[:, m:]
    r_mid = (q_t + 0.5 * dt * qd_t) @ D  # what the kernel stores as the surface
    spp = Ns // int(process.n_inserts)
    sr = r_mid[np.arange(Ns) % spp]
    return X[0, :m].copy(), X[0, m:].copy(), np.ascontiguousarray(sr), q_t @ D


def _orbits(structure: ToolPointStructure, process: CuttingProcess, Ns: int,
            speed_rpm: float) -> np.ndarray | None:
    """States (2, Ns, 2m) of the nominal-chip orbit at the step starts, per unit depth
    (``X[0]``) and of the depth-independent edge force alone (``X[1]``): the orbit at depth
    ``a`` is ``a X[0] + X[1]`` (the map is linear, its matrix independent of the depth). None
    without depth modulation or orbit."""
    if not process.rotating or not np.any(process.depth_direction):
        return None
    dt = 60.0 / (speed_rpm * Ns)
    Phi, Gam = _zoh_kept(structure, dt)
    vec = ((process.width_per_depth * process.h0) @ process.shear
           + process.edge_per_depth @ process.edge)
    fixed = process.edge_fixed_m @ process.edge
    X = np.empty((2, Ns, 2 * structure.n_modes))
    if not _orbit_kernel(Phi, Gam, np.ascontiguousarray(structure.directions, dtype=float),
                         np.asarray(process.depth_direction, float), vec, fixed,
                         int(process.n_inserts), 0.5 * dt, X):
        return None
    return X


_ZOH: dict = {}


def _zoh_kept(structure: ToolPointStructure, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`modal_zoh`, kept per structure (keyed by its values) and step (the lobes ask for
    the orbit at every trial depth of a speed, each at the same step)."""
    key = (structure.frequency_Hz.tobytes(), structure.damping_ratio.tobytes(),
           structure.stiffness_N_per_m.tobytes(), float(dt))
    hit = _ZOH.get(key)
    if hit is not None:
        return hit
    out = modal_zoh(structure, dt)
    if len(_ZOH) > 4096:
        _ZOH.clear()
    _ZOH[key] = out
    return out


def nominal_cut_deflection(structure: ToolPointStructure, process: CuttingProcess,
                           speed_rpm: float, samples_per_rev: int = 720
                           ) -> tuple[np.ndarray, np.ndarray] | None:
    """Steady tool-point displacement of the nominal cut, split by what drives it: per unit
    depth ``r_1`` and the depth-independent part ``r_0`` (the trailing-side edge force), each
    (samples_per_rev, 3) at bar angles ``2 pi i / samples_per_rev``; the displacement at depth
    ``a`` is ``a r_1 + r_0``. The orbit of :func:`periodic_orbit` (depth-modulation stiffness
    included); None for a process without depth modulation."""
    N = int(process.n_inserts)
    Ns = int(math.ceil(samples_per_rev / N) * N)
    X = _orbits(structure, process, Ns, speed_rpm)
    if X is None:
        return None
    m = structure.n_modes
    return X[0, :, :m] @ structure.directions, X[1, :, :m] @ structure.directions


def _nominal_force(process: CuttingProcess, theta: np.ndarray, depth_m: float) -> np.ndarray:
    """Nominal (rigid-tool) force on the tool [N], all inserts, at bar angles ``theta``."""
    N = int(process.n_inserts)
    f0 = (np.einsum("e,e,ei->i", process.width_per_depth * depth_m, process.h0, process.shear)
          + np.einsum("e,ei->i", process.edge_per_depth * depth_m + process.edge_fixed_m,
                      process.edge))
    F = np.zeros((theta.size, 3))
    for p in range(N):
        B = process.basis(theta + 2 * np.pi * p / N)
        F += np.einsum("nki,k->ni", B, f0)
    return F


def _periodic_state(structure, process, Ns, depth_m, speed_rpm):
    orbit = periodic_orbit(structure, process, Ns, depth_m, speed_rpm)
    if orbit is not None:
        return orbit
    c, om, _ = periodic_start(structure, process, Ns, depth_m)
    w = om * speed_rpm / 60.0  # (Ns,1) rad/s
    H = structure.modal_frf(np.abs(w[:, 0])).T  # (Ns, m) receptance at |w|
    H = np.where(w >= 0, H, np.conj(H))
    Q = c * H
    q_t = np.real(np.fft.ifft(Q * Ns, axis=0))  # (Ns, m) modal displacement per sample
    q0 = np.real(Q.sum(axis=0))
    qd0 = np.real((Q * 1j * w).sum(axis=0))
    r_t = q_t @ structure.directions  # (Ns, 3)
    spp = Ns // int(process.n_inserts)
    sr = r_t[np.arange(Ns) % spp]
    return q0, qd0, np.ascontiguousarray(sr), r_t


def forced_response(structure: ToolPointStructure, process: CuttingProcess, speed_rpm: float,
                    depth_m: float, samples_per_rev: int = 720) -> np.ndarray:
    """Steady tool-point displacement [m] under the nominal cutting force over one revolution,
    shape (samples_per_rev, 3), at bar angles ``2 pi i / samples_per_rev``."""
    N = int(process.n_inserts)
    Ns = int(math.ceil(samples_per_rev / N) * N)
    return _periodic_state(structure, process, Ns, depth_m, speed_rpm)[3]


def simulate(structure: ToolPointStructure, process: CuttingProcess,
             settings: SimulationSettings, insert_profile=None) -> xr.Dataset:
    """Run the time-domain simulation; see the module docstring for the Dataset contents.

    A boring process is integrated as built at the simulated depth
    (:meth:`~robobore.dynamics.process.CuttingProcess.at_depth`).

    ``insert_profile``: optional :class:`robobore.cutting.geometry.BoringInsert` used to draw
    the machined bore profile along the feed (nose geometry + the tool's radial and axial
    position at each pass). Without it the surface record is the chip-normal displacement.
    The run is a :class:`TimeDomainRun` (which can be continued).
    """
    return TimeDomainRun(structure, process, settings, insert_profile).dataset()


class TimeDomainRun:
    """A time-domain run (:func:`simulate`) that can be continued: :meth:`extend` integrates
    more revolutions from where the run stopped (the modal state, the surface left at each
    angle and when it was cut), so that a run of ``R`` revolutions extended by ``R'`` is the
    run of ``R + R'`` revolutions, digit for digit, at the cost of the ``R'`` new ones.
    :meth:`dataset` is the Dataset of the revolutions integrated so far, :meth:`record` their
    displacement and chip area alone.

    ``reserve_revolutions``: the length the run may be extended to; the records are allocated
    for it at once (where the memory guard accepts a run of that length; else as the run
    grows), so that extending up to it writes in place."""

    def __init__(self, structure: ToolPointStructure, process: CuttingProcess,
                 settings: SimulationSettings, insert_profile=None,
                 reserve_revolutions: int | None = None) -> None:
        settings.check()
        process = process.at_depth(settings.depth_m)  # the chip geometry at the depth
        N = int(process.n_inserts)
        Ns = settings.samples_per_rev or auto_samples_per_rev(structure, settings.speed_rpm, N)
        Ns = int(math.ceil(Ns / N) * N)
        self.structure, self.process, self.insert_profile = structure, process, insert_profile
        self.settings, self.N, self.Ns = settings, N, Ns
        self.dt = 60.0 / (settings.speed_rpm * Ns)
        self.Phi, self.Gam = modal_zoh(structure, self.dt)
        theta = 2 * np.pi * (np.arange(Ns) + 0.5) / Ns  # directions at the step midpoints
        self.basis = np.ascontiguousarray(process.basis(theta))
        a = settings.depth_m
        m = structure.n_modes
        r_forced = None
        if settings.start == "periodic":
            q, qd, sr, r_forced = _periodic_state(structure, process, Ns, a, settings.speed_rpm)
            pert = settings.perturbation_m
            if pert is None:
                pert = 0.01 * float(np.max(process.h0))
            q = q + pert
        else:
            q = np.zeros(m)
            qd = np.zeros(m)
            sr = np.zeros((Ns, 3))
        limit = settings.divergence_limit_m
        if limit is None:
            if r_forced is None:
                r_forced = _periodic_state(structure, process, Ns, a, settings.speed_rpm)[3]
            limit = DIVERGENCE_FLOOR_M + DIVERGENCE_FORCED_FACTOR * float(np.abs(r_forced).max())
        self.limit = float(limit)
        self.q, self.qd, self.sr = q, qd, sr
        self.tlast = np.full(Ns, -(Ns // N), dtype=np.int64)  # step of the last cut, per angle
        self.n_steps = 0  # steps integrated
        self.n_done = 0  # steps done before a divergence (= n_steps without one)
        self.revolutions = 0  # revolutions asked for
        self.reserve_revolutions = int(reserve_revolutions or 0)
        # the records (force, displacement, acceleration, chip area), rows [:n_done] filled
        self._F = np.empty((0, 3))
        self._X = np.empty((0, 3))
        self._acc = np.empty((0, 3))
        self._area = np.empty((0, N))
        self.extend(int(settings.revolutions))

    @property
    def room_steps(self) -> int:
        """Steps the records have room for (the reserve, or the steps asked for)."""
        return int(self._F.shape[0])

    @property
    def F(self) -> np.ndarray:
        return self._F[:self.n_done]

    @property
    def X(self) -> np.ndarray:
        return self._X[:self.n_done]

    @property
    def acc(self) -> np.ndarray:
        return self._acc[:self.n_done]

    @property
    def area(self) -> np.ndarray:
        return self._area[:self.n_done]

    def _room(self, total: int) -> None:
        """Records with room for ``total`` revolutions (the reserve where it is longer and
        the memory guard accepts it), the steps done so far kept."""
        from robobore.io.memory import check_timedomain

        Ns, N = self.Ns, self.N
        rows = total * Ns
        if rows <= self._F.shape[0]:
            return
        if self.reserve_revolutions > total:
            try:
                check_timedomain(self.reserve_revolutions, Ns, N)
                rows = self.reserve_revolutions * Ns
            except ConfigError:
                pass  # room for this length only; a longer one reallocates
        done = self.n_done
        for name, width in (("_F", 3), ("_X", 3), ("_acc", 3), ("_area", N)):
            new = np.empty((rows, width))
            new[:done] = getattr(self, name)[:done]
            setattr(self, name, new)

    @property
    def diverged(self) -> bool:
        return self.n_done < self.n_steps

    def extend(self, revolutions: int) -> None:
        """Integrate ``revolutions`` more (nothing once the run has diverged)."""
        from robobore.io.memory import check_timedomain

        if self.diverged:
            return
        Ns, N, st, pr = self.Ns, self.N, self.structure, self.process
        total = self.revolutions + int(revolutions)
        check_timedomain(total, Ns, N)  # before the arrays are allocated
        n = int(revolutions) * Ns
        self._room(total)
        i0 = self.n_steps  # = n_done: the run has not diverged
        F, X = self._F[i0:i0 + n], self._X[i0:i0 + n]
        acc, area = self._acc[i0:i0 + n], self._area[i0:i0 + n]
        a = self.settings.depth_m
        tl = self.tlast - self.n_steps  # the kernel counts steps from 0
        inv_depth = 1.0 / a if np.any(pr.depth_direction) else 0.0
        done = _simulate_kernel(n, Ns, N, self.Phi, self.Gam, np.ascontiguousarray(st.directions),
                                self.basis, pr.h0, pr.width_per_depth * a, pr.edge_per_depth * a,
                                np.ascontiguousarray(pr.edge_fixed_m, dtype=np.float64),
                                pr.normal, pr.shear, pr.edge, pr.depth_direction, inv_depth,
                                pr.overlap, st.omega, st.damping_ratio, 1.0 / st.modal_mass,
                                0.5 * self.dt, self.q, self.qd, self.sr, tl, F, X, acc, area,
                                self.limit)
        self.tlast = tl + self.n_steps
        self.n_done = self.n_steps + int(done)
        self.n_steps += n
        self.revolutions = total

    def _whole_steps(self) -> tuple[int, int]:
        """The whole revolutions of the run so far (those before a divergence) and their
        steps; NumericalError where there is none or the record is not finite."""
        Ns, n_done, limit = self.Ns, self.n_done, self.limit
        revs = self.revolutions
        if self.diverged:
            revs = n_done // Ns  # keep the whole revolutions before the divergence
            if revs < 1:
                raise NumericalError(
                    f"the tool-point displacement exceeded {limit * 1e3:.3g} mm"
                    f" within the first revolution (t = {n_done * self.dt:.4g} s): the cut "
                    "diverges at once; check the structure (stiffness, mass) and the cutting "
                    "coefficients")
        n_steps = revs * Ns
        F, X = self._F[:n_steps], self._X[:n_steps]
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(F))):
            raise NumericalError("the simulation produced non-finite values (unstable "
                                 "integration)")
        return revs, n_steps

    def record(self) -> tuple[np.ndarray, np.ndarray]:
        """The tool-point displacement (n, 3) [m] and chip area (n, n_inserts) [m^2] of the
        run so far, the Dataset's ``displacement`` and ``chip_area`` (:meth:`dataset`, with
        its errors) without building it."""
        n_steps = self._whole_steps()[1]
        return self._X[:n_steps], self._area[:n_steps]

    def dataset(self) -> xr.Dataset:
        """The Dataset of the run so far (:func:`simulate`)."""
        revs, n_steps = self._whole_steps()
        return _run_dataset(self, self._F[:n_steps], self._X[:n_steps], self._acc[:n_steps],
                            self._area[:n_steps], revs, n_steps)


@nb.njit(cache=True)
def _rotating_frame(acc, X, c_rev, s_rev, a_rot, feed_amp):  # pragma: no cover - compiled
    """Per revolution of ``Ns = c_rev.size`` samples: the acceleration on the insert's radial
    and tangential directions (``a_rot``: ``ax c + ay s``, ``-ax s + ay c``) and the half
    peak-to-peak feed (z) displacement (``feed_amp``)."""
    Ns = c_rev.shape[0]
    for r in range(feed_amp.shape[0]):
        zmax = X[r * Ns, 2]
        zmin = zmax
        for k in range(Ns):
            i = r * Ns + k
            ax = acc[i, 0]
            ay = acc[i, 1]
            a_rot[i, 0] = ax * c_rev[k] + ay * s_rev[k]
            a_rot[i, 1] = -ax * s_rev[k] + ay * c_rev[k]
            z = X[i, 2]
            if z > zmax:
                zmax = z
            if z < zmin:
                zmin = z
        feed_amp[r] = 0.5 * (zmax - zmin)


def _run_dataset(run: TimeDomainRun, F: np.ndarray, X: np.ndarray, acc: np.ndarray,
                 area: np.ndarray, revs: int, n_steps: int) -> xr.Dataset:
    """The Dataset of ``run``'s first ``revs`` whole revolutions (:func:`simulate`)."""
    settings, process, Ns, N, dt = run.settings, run.process, run.Ns, run.N, run.dt
    insert_profile = run.insert_profile
    a = settings.depth_m
    diverged, n_done, limit = run.diverged, run.n_done, run.limit
    t = np.arange(n_steps) * dt
    th_rev = 2 * np.pi * np.arange(Ns) / Ns  # the insert's angle, the same every revolution
    c_rev, s_rev = np.cos(th_rev), np.sin(th_rev)
    a_rot = np.empty((n_steps, 2))
    feed_amp = np.empty(revs)
    _rotating_frame(acc, X, c_rev, s_rev, a_rot, feed_amp)
    ds_out = xr.Dataset(
        {
            "force": (("time", "axis"), F, {"units": "N", "long_name": "force on the tool"}),
            "displacement": (("time", "axis"), X, {"units": "m",
                                                   "long_name": "tool-point displacement"}),
            "acceleration": (("time", "axis"), acc, {"units": "m/s^2"}),
            "rotational_acceleration": (("time", "rot_axis"), a_rot, {
                "units": "m/s^2",
                "long_name": "tool-point acceleration on the rotating insert's radial and "
                             "tangential directions (no centripetal term)"}),
            "chip_area": (("time", "insert"), area, {"units": "m^2"}),
            "feed_amplitude": (("revolution",), feed_amp, {
                "units": "m", "long_name": "half peak-to-peak feed-direction (z) displacement "
                                           "per revolution"}),
        },
        coords={"time": ("time", t, {"units": "s"}), "axis": ["x", "y", "z"],
                "rot_axis": ["radial", "tangential"], "insert": np.arange(N),
                "revolution": np.arange(revs)},
        attrs={"speed_rpm": settings.speed_rpm, "depth_m": a, "revolutions": revs,
               "samples_per_rev": Ns, "n_inserts": N, "dt_s": dt, "overlap": process.overlap,
               "feed_per_rev_m": process.feed_per_rev_m, "process": process.label,
               "diverged": int(diverged), "revolutions_requested": int(run.revolutions),
               "diverged_at_s": n_done * dt if diverged else math.nan,
               "divergence_limit_m": float(limit),
               "frame": "boring frame: x horizontal, y vertical, z feed (bore axis)"},
    )
    prof_z, prof_r, ra, rz = surface_profile(X, area, Ns, N, process, insert_profile)
    ds_out["surface_profile"] = (("surface_z",), prof_r, {
        "units": "m", "long_name": "machined surface height along the feed at angle 0 "
                                   "(positive into the material; form not removed)"})
    ds_out = ds_out.assign_coords(surface_z=("surface_z", prof_z, {"units": "m"}))
    rough = roughness(prof_z, prof_r)
    ds_out.attrs["Ra_m"] = rough["Ra_m"]
    ds_out.attrs["Rz_m"] = rough["Rz_m"]
    ds_out.attrs["Ra_with_form_m"] = ra
    ds_out.attrs["Rz_with_form_m"] = rz
    ds_out.attrs["form_slope_um_per_mm"] = rough["form_slope_um_per_mm"]
    return ds_out


#: Degree of the least-squares polynomial removed from the profile before Ra/Rz (1: a line,
#: i.e. offset and taper; the nominal form of a straight bore wall along its axis).
FORM_DEGREE = 1


def roughness(z: np.ndarray, height: np.ndarray, form_degree: int = FORM_DEGREE
              ) -> dict[str, float]:
    """Ra and Rz of a profile after removing its form [m].

    The form is the least-squares polynomial of degree ``form_degree`` of ``height`` against
    ``z`` (ISO 4287 primary profile: the nominal form is removed by least squares before the
    roughness parameters; a straight bore's form is a line, so the default removes the offset
    and any taper). ``Ra`` is the mean absolute deviation of the residual, ``Rz`` its
    peak-to-valley over the evaluation length (single evaluation length, no cut-off filter).
    ``form_slope_um_per_mm``: the fitted line's slope (taper) [um/mm]. Non-finite heights
    (no pass cut there) are left out; fewer than ``form_degree + 2`` finite points give NaN.
    """
    z = np.asarray(z, float)
    h = np.asarray(height, float)
    ok = np.isfinite(h) & np.isfinite(z)
    nan = {"Ra_m": math.nan, "Rz_m": math.nan, "form_slope_um_per_mm": math.nan}
    if ok.sum() < form_degree + 2:
        return nan
    zz, hh = z[ok], h[ok]
    zc = zz - zz.mean()
    span = float(np.ptp(zc)) or 1.0
    coef = np.polynomial.polynomial.polyfit(zc / span, hh, form_degree)
    resid = hh - np.polynomial.polynomial.polyval(zc / span, coef)
    slope = float(coef[1] / span) if form_degree >= 1 else 0.0  # m/m at the centre
    return {"Ra_m": float(np.mean(np.abs(resid))), "Rz_m": float(resid.max() - resid.min()),
            "form_slope_um_per_mm": slope * 1e3}


def surface_profile(X: np.ndarray, area: np.ndarray, Ns: int, N: int, process: CuttingProcess,
                    insert=None, last_passes: int = 40, n_points: int = 4000):
    """Bore surface along the feed at angle 0 from the passes of the last revolutions.

    With an insert: each pass that cut leaves the nose profile at its axial position
    ``z_k = k f_z + dz_k`` and radius ``dr_k`` (radial displacement at that instant); the
    surface is the envelope ``max_k (dr_k - drop(z - z_k))``. Returns ``(z, height, Ra, Rz)``
    with Ra the mean absolute deviation from the mean and Rz the peak-to-valley over the
    evaluation length, form included (:func:`roughness` removes the form).
    """
    spp = Ns // N
    idx_all = np.arange(0, X.shape[0], spp)
    ins_all = ((-idx_all) % Ns) // spp  # insert p is at angular sample 0 at step i
    idx = idx_all[-last_passes:]
    ins = ins_all[-last_passes:]
    cut = area[idx, ins] > 0
    fz = process.feed_per_rev_m / N
    if insert is not None and process.rotating and fz > 0:
        dr = X[idx, 0]  # e_r at angle 0 is +x
        dz = X[idx, 2]
        zk = np.arange(idx.size) * fz + dz
        z = np.linspace(zk[2], zk[-3], n_points) if idx.size > 6 else np.linspace(
            zk[0], zk[-1], n_points)
        height = np.full(z.size, -np.inf)
        for k in range(idx.size):
            if not cut[k]:
                continue
            height = np.maximum(height, dr[k] - insert.drop(z - zk[k]))
        height = np.where(np.isfinite(height), height, np.nan)
    else:
        nrm = process.normal[0]
        height = -(X[idx] @ nrm)
        z = np.arange(idx.size) * max(fz, 1e-9)
    hh = height[np.isfinite(height)]
    if hh.size == 0:
        return z, height, math.nan, math.nan
    ra = float(np.mean(np.abs(hh - hh.mean())))
    rz = float(hh.max() - hh.min())
    return z, height, ra, rz


@nb.njit(cache=True)
def _column_sums(x):  # pragma: no cover - compiled
    out = np.zeros(x.shape[1])
    for i in range(x.shape[0]):
        for j in range(x.shape[1]):
            out[j] += x[i, j]
    return out


def column_means(x: np.ndarray) -> np.ndarray:
    """``x.mean(axis=0)`` of a (n, c) array, digit for digit. A C-ordered array of several
    columns and rows is summed row after row (the order numpy reduces its first axis in) in
    one compiled pass and divided by ``n``; any other is numpy's mean."""
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] < 1 or x.shape[1] < 2 or not x.flags.c_contiguous:
        return x.mean(axis=0)
    return _column_sums(x) / x.shape[0]


def summarize(ds: xr.Dataset, skip_revolutions: int | None = None) -> dict[str, Any]:
    """Mean and amplitude (half peak-to-peak) of the forces over the last revolutions [N],
    mean feed-direction amplitude [m]."""
    revs = int(ds.attrs["revolutions"])
    Ns = int(ds.attrs["samples_per_rev"])
    k0 = revs // 2 if skip_revolutions is None else min(skip_revolutions, revs - 1)
    F = ds["force"].values[k0 * Ns:]
    fa = ds["feed_amplitude"].values[k0:]
    # extremes per column (a strided pass each: faster than along the rows, the same values)
    fmax = np.array([F[:, c].max() for c in range(F.shape[1])])
    fmin = np.array([F[:, c].min() for c in range(F.shape[1])])
    return {
        "force_mean_N": dict(zip("xyz", column_means(F).tolist(), strict=True)),
        "force_amplitude_N": dict(zip("xyz", (0.5 * (fmax - fmin)).tolist(), strict=True)),
        "feed_amplitude_m": float(fa.mean()),
    }


__all__ = ["simulate", "TimeDomainRun", "SimulationSettings", "DIVERGENCE_FLOOR_M", "DIVERGENCE_FORCED_FACTOR", "modal_zoh", "auto_samples_per_rev",
           "periodic_start", "forced_response", "periodic_orbit", "nominal_cut_deflection",
           "surface_profile", "roughness", "summarize", "column_means", "FORM_DEGREE"]
