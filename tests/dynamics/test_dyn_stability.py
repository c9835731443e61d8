"""Stability lobes: closed-form SDOF, frequency domain vs semi-discretisation, mode coupling."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.dynamics.process import single_point_process
from robobore.dynamics.semidiscretization import critical_depth_semidiscretization
from robobore.dynamics.stability import (
    lobes_frequency_domain,
    lobes_semidiscretization,
    mode_coupling,
    mode_coupling_limit,
    sdof_absolute_limit,
    sdof_pocket_speeds,
)
from robobore.dynamics.structure import ToolPointStructure
from robobore.errors import ConfigError


def _cos2(st):
    return float(st.directions[0] @ np.array([1.0, 0.0, 0.0])) ** 2


def test_absolute_limit_closed_form(sdof, contract_process):
    """Tlusty: a_lim = 2 k zeta (1 + zeta) / (K cos^2) for a mode at an angle to the chip
    normal (Altintas, Manufacturing Automation 2nd ed., eq. 3.x). Tolerance 0.5 %."""
    ref = sdof_absolute_limit(2.26e8, 0.012, 1.0e9, _cos2(sdof))
    res = lobes_frequency_domain(sdof, contract_process, np.linspace(2000, 14000, 601))
    assert res.absolute_limit_m == pytest.approx(ref, rel=5e-3)
    assert np.nanmin(res.critical_depth_m) == pytest.approx(ref, rel=5e-3)
    assert np.all(res.critical_depth_m >= ref * (1 - 5e-3))


@pytest.mark.parametrize("k", [0, 1, 2, 3])
def test_pocket_speeds_closed_form(sdof, contract_process, k):
    """Lobe minima at n_k = 60 w_c / (eps + 2 pi k), w_c = w_n sqrt(1 + 2 zeta),
    eps = pi + 2 atan(sqrt(1 + 2 zeta)) (closed form); the computed lobe diagram has its
    minimum there within 0.5 % in speed, with the absolute-limit depth (0.5 %)."""
    pk = sdof_pocket_speeds(250.0, 0.012, 1, 4)[k]
    s = np.linspace(0.97 * pk, 1.03 * pk, 1201)
    res = lobes_frequency_domain(sdof, contract_process, s)
    i = int(np.argmin(res.critical_depth_m))
    assert s[i] == pytest.approx(pk, rel=5e-3)
    ref = sdof_absolute_limit(2.26e8, 0.012, 1.0e9, _cos2(sdof))
    assert res.critical_depth_m[i] == pytest.approx(ref, rel=5e-3)
    assert res.chatter_frequency_Hz[i] == pytest.approx(250 * np.sqrt(1.024), rel=5e-3)


def test_other_angle_and_damping():
    """Same closed form for a stiffer, better damped mode at 60 deg (cos^2 = 0.25)."""
    st = ToolPointStructure.from_modes([{"frequency_Hz": 800.0, "damping_ratio": 0.04,
                                         "stiffness_N_per_m": 5e7,
                                         "direction": [0.5, 0.0, np.sqrt(0.75)]}])
    pr = single_point_process(2e9, [1, 0, 0], [1, 0, 0], 1e-4)
    res = lobes_frequency_domain(st, pr, np.linspace(3000, 30000, 200))
    ref = sdof_absolute_limit(5e7, 0.04, 2e9, 0.25)
    assert res.absolute_limit_m == pytest.approx(ref, rel=5e-3)


def test_frequency_domain_vs_semidiscretization_two_modes():
    """Two modes (250 Hz along x, 320 Hz along y), force at 30 deg, chip normal at 20 deg:
    zero-order frequency domain and semi-discretisation (Insperger & Stepan) agree to 2 %."""
    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 250.0, "damping_ratio": 0.012, "stiffness_N_per_m": 2.26e8,
         "direction": [1, 0, 0]},
        {"frequency_Hz": 320.0, "damping_ratio": 0.02, "stiffness_N_per_m": 3.0e8,
         "direction": [0, 1, 0]}])
    a, b = np.radians(30.0), np.radians(20.0)
    pr = single_point_process(1e9, [np.cos(a), np.sin(a), 0], [np.cos(b), np.sin(b), 0], 1e-4)
    sp = np.array([3000.0, 4500.0, 5250.0, 6000.0, 8250.0, 9000.0, 10500.0, 12000.0])
    fd = lobes_frequency_domain(st, pr, sp)
    sd = lobes_semidiscretization(st, pr, sp)
    assert np.allclose(sd.critical_depth_m, fd.critical_depth_m, rtol=0.02)


def test_mode_coupling_limit_equals_frequency_domain_without_regeneration(coupling_case):
    """Overlap 0 (no regeneration): the frequency-domain limit (lambda crossing the negative
    real axis, Tlusty) equals the eigenvalue criterion and semi-discretisation (1e-3)."""
    st, pr = coupling_case(overlap=0.0)
    mc = mode_coupling_limit(st, pr)
    fd = lobes_frequency_domain(st, pr, np.array([1000.0])).critical_depth_m[0]
    sd = critical_depth_semidiscretization(st, pr, 1000.0)
    assert np.isfinite(mc)
    assert fd == pytest.approx(mc, rel=1e-3)
    assert sd == pytest.approx(mc, rel=1e-3)


def test_single_mode_has_no_mode_coupling(sdof, contract_process):
    assert mode_coupling_limit(sdof, contract_process) == np.inf
    assert not mode_coupling(sdof, contract_process, 0.01).unstable


def test_partial_overlap_needs_semidiscretization(sdof):
    pr = single_point_process(1e9, [1, 0, 0], [1, 0, 0], 1e-4, overlap=0.5)
    with pytest.raises(ConfigError, match="overlap"):
        lobes_frequency_domain(sdof, pr, np.array([5000.0]))


def test_undamped_mode_coupling_closed_form():
    """Two orthogonal modes of equal mass along x and y, force u and chip normal n in the plane
    (Tlusty; Pan et al. 2006): K + p u n^T has complex eigenvalues when
    (k1 - k2 + p a)^2 + 4 p^2 c < 0, a = ux nx - uy ny, c = ux uy nx ny; the smallest positive
    root p* gives the depth p*/K. The eigen criterion matches it to 1e-6."""
    k1, k2, m = 1.0e6, 1.1e6, 50.0
    f = [np.sqrt(k / m) / (2 * np.pi) for k in (k1, k2)]
    st = ToolPointStructure.from_modes([
        {"frequency_Hz": f[0], "damping_ratio": 0.0, "stiffness_N_per_m": k1,
         "direction": [1, 0, 0]},
        {"frequency_Hz": f[1], "damping_ratio": 0.0, "stiffness_N_per_m": k2,
         "direction": [0, 1, 0]}])
    b_, a_ = np.radians(70.0), np.radians(-25.0)
    u = np.array([np.cos(b_), np.sin(b_), 0.0])
    n = np.array([np.cos(a_), np.sin(a_), 0.0])
    K = 2e9
    pr = single_point_process(K, u, n, 1e-4)
    a = u[0] * n[0] - u[1] * n[1]
    c = u[0] * u[1] * n[0] * n[1]
    roots = np.roots([a * a + 4 * c, 2 * (k1 - k2) * a, (k1 - k2) ** 2])
    p = min(r.real for r in roots if abs(r.imag) < 1e-9 and r.real > 0)
    assert mode_coupling_limit(st, pr, damped=False) == pytest.approx(p / K, rel=1e-6)


@pytest.mark.parametrize("k", [0, 2])
def test_critical_multiplier_frequency_closed_form(sdof, contract_process, k):
    """At an SDOF lobe minimum (closed form above) the semi-discretisation's critical Floquet
    multiplier lies on the unit circle at the limit and its chatter frequency is
    ``f_n sqrt(1 + 2 zeta)`` (0.5 %); just below the limit the multiplier is inside."""
    from robobore.dynamics.semidiscretization import critical_multiplier

    pk = sdof_pocket_speeds(250.0, 0.012, 1, 4)[k]
    a = critical_depth_semidiscretization(sdof, contract_process, pk)
    mu, f, mode = critical_multiplier(sdof, contract_process, pk, a)
    assert abs(mu) == pytest.approx(1.0, abs=5e-3)
    assert f == pytest.approx(250 * np.sqrt(1.024), rel=5e-3)
    assert mode == 0
    mu_lo, f_lo, _ = critical_multiplier(sdof, contract_process, pk, 0.8 * a)
    assert abs(mu_lo) < 0.99
    # the branch nearest a given frequency is one insert period's harmonic away
    _, f_up, _ = critical_multiplier(sdof, contract_process, pk, a, near_Hz=f + pk / 60.0)
    assert f_up == pytest.approx(f + pk / 60.0, rel=1e-9)
