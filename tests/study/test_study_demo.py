"""The DEMO runner against closed forms (it must be right even though it is a toy).

References: Altintas, *Manufacturing Automation*, 2nd ed. (2012), Sec. 3.2: the
single-DOF regenerative chatter model; the absolute (all-speed) stability limit
``b_lim = 2 k zeta (1 + zeta) / K_f`` (Eq. 3.29 there, Tlusty's result).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.study.demo import DemoParams, critical_depth_m, demo_runner, simulate
from robobore.study.summary import summarise


def test_minimum_critical_depth_over_speeds_equals_tlusty_closed_form():
    p = DemoParams()
    closed = 2 * p.stiffness_N_per_m * p.damping_ratio * (1 + p.damping_ratio) \
        / p.K_feed_N_per_m2
    speeds = np.linspace(150, 1500, 400)
    b = min(critical_depth_m(p, n, 0.0, n_freq=40_000) for n in speeds)
    # the lobes' minima touch the closed form; sampled speeds/frequencies sit within 1 %
    assert b == pytest.approx(closed, rel=0.01)
    assert b >= closed * (1 - 1e-3)  # never below the absolute limit


def test_stable_cut_forces_equal_the_mechanistic_closed_form():
    # stable, well inside the limit: h -> h0, so F_t = K_t b h0, F_r = K_r b h0 and the
    # rotating X/Y components peak at sqrt(F_t^2 + F_r^2); F_z = K_z b h0 (tolerance 0.5 %)
    p = DemoParams()
    r = simulate(p, 300.0, 0.15, 0.03, 0.0)
    b, h0 = 0.03e-3, 0.15e-3
    res = math.hypot(p.K_tangential_N_per_m2, p.K_radial_N_per_m2) * b * h0
    assert r["stable"]
    assert r["force_amplitude_x_N"] == pytest.approx(res, rel=5e-3)
    assert r["force_amplitude_y_N"] == pytest.approx(res, rel=5e-3)
    assert r["force_amplitude_z_N"] == pytest.approx(p.K_feed_N_per_m2 * b * h0, rel=5e-3)
    # the static deflection K_z b h0 / k (closed form) is what the tool settles at
    assert r["z_m"][-1] == pytest.approx(p.K_feed_N_per_m2 * b * h0 / p.stiffness_N_per_m,
                                         rel=1e-3)


@pytest.mark.parametrize("pressure", [0.0, 0.3])
def test_time_domain_stability_agrees_with_linear_theory(pressure):
    # away from the boundary (b < 0.8 b_crit or b > 1.25 b_crit) the time-domain flag must
    # agree with the frequency-domain limit of the same model
    p = DemoParams()
    checked = 0
    for n in (200, 300, 400, 500, 600, 800, 1000):
        bc = critical_depth_m(p, n, pressure) * 1e3
        for a in (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4):
            if 0.8 * bc <= a <= 1.25 * bc:
                continue
            r = simulate(p, n, 0.15, a, pressure)
            assert r["stable"] == (a < bc), (n, a, bc)
            checked += 1
    assert checked >= 30


def test_pressure_foot_raises_the_limit_and_vibration_grows_with_depth():
    p = DemoParams()
    assert critical_depth_m(p, 400, 0.3) > critical_depth_m(p, 400, 0.0)
    amps = [simulate(p, 400, 0.15, a, 0.0)["feed_amplitude_m"] for a in (0.05, 0.1, 0.2)]
    assert amps[0] < amps[1] < amps[2]


def test_runner_dataset_follows_the_summary_contract():
    ds = demo_runner({"speed_rpm": 300, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
                      "pressure_MPa": 0.0}, {"model": {"duration_s": 1.0}})
    s = summarise(ds)
    assert set(s) == {"force_amplitude_x_N", "force_amplitude_y_N", "force_amplitude_z_N",
                      "feed_amplitude_um", "stable"}
    assert "DEMO" in ds.attrs["model"]
    assert ds.sizes["time_s"] <= DemoParams().output_points
    assert ds["z_um"].attrs["units"] == "um"
