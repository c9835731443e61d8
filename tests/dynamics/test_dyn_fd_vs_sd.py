"""Semi-discretisation against the zero-order frequency domain on the same linear delay
equation (no depth-modulation stiffness, linearised about the undeflected cut), on random
SYNTHETIC cuts of ``dynamics.crosscheck`` (seed 44): with fixed directions (a time-invariant
delay equation, where the zero-order solution is exact) the two agree within 2 % (measured on
20 cuts: max 0.028 %, ``benchmarks/chatter_acceptance.py --part a``); with the rotating bar
(a time-periodic equation: the directional matrix turns with the insert) the zero-order
average misses the periodic terms (median 34 %, max 2200 % on the 20 cuts) and the time
domain on the same process sides with the semi-discretisation on every one of them."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from robobore.dynamics.chatter import classify
from robobore.dynamics.crosscheck import random_cut
from robobore.dynamics.process import boring_process
from robobore.dynamics.semidiscretization import critical_depth_semidiscretization
from robobore.dynamics.stability import lobes_frequency_domain
from robobore.dynamics.timedomain import SimulationSettings, auto_samples_per_rev, simulate

LINEAR = {"include_process_stiffness": False, "about_deflected": False}


@pytest.fixture(scope="module")
def cuts():
    rng = np.random.default_rng(44)
    return [random_cut(rng, f"cut {i}") for i in range(22)]


@pytest.mark.parametrize("i", [1, 4, 11])
def test_fixed_directions_fd_equals_sd(cuts, i):
    c = cuts[i]
    pf = replace(c.process(0.05e-3).fixed(), rotating=False)
    a_sd = critical_depth_semidiscretization(c.structure, pf, c.speed_rpm, **LINEAR)
    a_fd = float(lobes_frequency_domain(c.structure, pf, np.array([c.speed_rpm]))
                 .critical_depth_m[0])
    assert 0 < a_sd < math.inf
    assert a_fd == pytest.approx(a_sd, rel=0.02)


@pytest.mark.parametrize("i, fd_side", [(1, "below"), (21, "above")])
def test_rotating_bar_time_domain_sides_with_sd(cuts, i, fd_side):
    """cut 1 (304 r/min): FD 37 % below SD; cut 21 (557 r/min): FD 23 % above SD. At the
    geometric mean of the two limits the time domain (same linear process) says what SD says."""
    c = cuts[i]
    pr = boring_process(c.insert, c.coefficients, 0.05e-3, c.feed_per_rev_m,
                        depth_modulation=False)
    a_sd = critical_depth_semidiscretization(c.structure, pr, c.speed_rpm, **LINEAR)
    a_fd = float(lobes_frequency_domain(c.structure, pr, np.array([c.speed_rpm]))
                 .critical_depth_m[0])
    assert (a_fd < 0.9 * a_sd) if fd_side == "below" else (a_fd > 1.1 * a_sd)
    a = math.sqrt(a_sd * a_fd)
    base = auto_samples_per_rev(c.structure, c.speed_rpm, c.insert.n_inserts)
    v = classify(simulate(c.structure, pr.at_depth(a),
                          SimulationSettings(c.speed_rpm, a, samples_per_rev=base), c.insert))
    assert v.chatter_decided and not v.tool_leaves_cut
    assert v.chatter == (a > a_sd)
