"""The run length and sampling check of ``run_boring``: the chatter decision on a record is
classify's on its Dataset, a run extended in reserved records is the longer run, and the
verdict and numbers of a lengthened or sampling-checked run are those of classify on a fresh
simulation of its final length."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from robobore.cutting.coefficient_sets import ti64_coefficients
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics.chatter import chatter_decision, classify
from robobore.dynamics.config import (build_coefficients, build_process, build_structure,
                                      load_dynamics_config)
from robobore.dynamics.process import boring_process
from robobore.dynamics.structure import ToolPointStructure
from robobore.dynamics.timedomain import SimulationSettings, TimeDomainRun, simulate

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "boring_paper.toml"


def _bar():
    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 40.0, "damping_ratio": 0.03, "stiffness_N_per_m": 2e6,
         "direction": [1, 0, 0]},
        {"frequency_Hz": 55.0, "damping_ratio": 0.02, "stiffness_N_per_m": 3e6,
         "direction": [0, 1, 0]}])
    return st, lambda depth_mm: boring_process(BoringInsert(), ti64_coefficients(30.0),
                                               depth_mm * 1e-3, 0.15e-3)


def _same_decision(ds):
    v = classify(ds, ra_tolerance_m=1.6e-6)
    d = chatter_decision(ds["displacement"].values, ds["chip_area"].values,
                         int(ds.attrs["samples_per_rev"]), int(ds.attrs["n_inserts"]),
                         float(ds.attrs["depth_m"]), float(ds.attrs["feed_per_rev_m"]),
                         bool(ds.attrs["diverged"]))
    assert (d.chatter, d.decided, d.cause) == (v.chatter, v.chatter_decided, v.chatter_cause)
    assert d.left_cause == v.tool_leaves_cut_cause
    assert (d.tool_left_cut_fraction > 0) is v.tool_leaves_cut
    for a, b in ((d.floquet_multiplier, v.floquet_multiplier),
                 (d.floquet_multiplier_se, v.floquet_multiplier_se),
                 (d.vibration_growth, v.vibration_growth),
                 (d.feed_amplitude_growth, v.feed_amplitude_growth),
                 (d.radial_amplitude_growth, v.radial_amplitude_growth)):
        assert a == b or (math.isnan(a) and math.isnan(b))
    return d, v


@pytest.mark.parametrize("depth_mm, revs, rule", [(0.03, 24, "multiplier"),  # decays
                                                  (0.1, 24, "multiplier"),  # grows
                                                  (0.3, 24, "grown out of the cut"),
                                                  (3.0, 24, "diverged"),
                                                  (0.03, 3, "too short")])
def test_chatter_decision_is_classify_s_on_a_bar(depth_mm, revs, rule):
    st, process = _bar()
    ds = simulate(st, process(depth_mm), SimulationSettings(600.0, depth_mm * 1e-3, revs, 240))
    d, v = _same_decision(ds)
    assert d.rule == rule
    if rule == "diverged":
        assert v.chatter and bool(ds.attrs["diverged"])


@pytest.mark.parametrize("speed, depth_mm, decided, leaves",
                         [(554.3, 0.695, False, False),  # at the limit: undecided at 60
                          (554.3, 0.869, True, False),  # 1.25 x the limit: chatter
                          (1000.0, 0.3, True, True)])  # the forced vibration leaves the cut
def test_chatter_decision_is_classify_s_on_the_example(speed, depth_mm, decided, leaves):
    from robobore.dynamics.api import run_boring

    r = run_boring(EXAMPLE, speed_rpm=speed, depth_mm=depth_mm, revolutions=60,
                   return_dataset=True)
    d, v = _same_decision(r.dataset)
    assert d.decided is decided and v.tool_leaves_cut is leaves


def test_the_record_is_the_dataset_s():
    st, process = _bar()
    run = TimeDomainRun(st, process(0.3), SimulationSettings(600.0, 0.3e-3, 12, 240))
    X, area = run.record()
    ds = run.dataset()
    assert np.array_equal(X, ds["displacement"].values)
    assert np.array_equal(area, ds["chip_area"].values)


@pytest.mark.parametrize("depth_mm", [0.3, 3.0])
def test_a_run_extended_in_its_reserve_is_the_longer_run(depth_mm):
    st, process = _bar()
    pr = process(depth_mm)
    run = TimeDomainRun(st, pr, SimulationSettings(600.0, depth_mm * 1e-3, 6, 240),
                        reserve_revolutions=24)
    rows = run.room_steps
    run.extend(6)
    run.extend(12)
    assert run.room_steps == rows == 24 * 240  # written in place
    cont = run.dataset()
    full = simulate(st, pr, SimulationSettings(600.0, depth_mm * 1e-3, 24, 240))
    assert cont.attrs == full.attrs
    for name in full.data_vars:
        assert np.array_equal(cont[name].values, full[name].values, equal_nan=True), name


def test_a_reserve_over_the_memory_guard_is_not_taken(monkeypatch):
    """The run the guard accepts is run (in records of its own length) when its reserve would
    not fit, and extending it beyond grows them: the same run."""
    import robobore.io.memory as memory

    st, process = _bar()
    pr = process(0.3)
    fits = memory.timedomain_bytes(12 * 240, 1) / 0.9
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: fits)
    run = TimeDomainRun(st, pr, SimulationSettings(600.0, 0.3e-3, 6, 240),
                        reserve_revolutions=48)
    assert run.room_steps == 6 * 240
    run.extend(6)
    assert run.room_steps == 12 * 240
    monkeypatch.undo()
    full = simulate(st, pr, SimulationSettings(600.0, 0.3e-3, 12, 240))
    assert np.array_equal(run.dataset()["force"].values, full["force"].values)


def _example():
    return load_dynamics_config(EXAMPLE)[0], str(EXAMPLE)


def _fields(v):
    return (v.chatter, v.chatter_decided, v.floquet_multiplier, v.floquet_multiplier_se,
            v.vibration_growth, v.nonharmonic_energy_ratio, v.reasons)


def test_a_lengthened_run_is_classify_on_its_final_length():
    """554 r/min, 0.695 mm (the example's limit) is undecided at 60 and 120 revolutions: the
    result is classify on the 240-revolution run, simulated afresh."""
    from robobore.dynamics.api import run_boring
    from robobore.dynamics.timedomain import summarize

    r = run_boring(EXAMPLE, speed_rpm=554.3, depth_mm=0.695, return_dataset=True)
    assert r.revolutions_simulated == 240
    cfg, src = _example()
    pr = build_process(cfg, src, depth_m=0.695e-3, coefficients=build_coefficients(cfg, src))
    ds = simulate(build_structure(cfg, src), pr,
                  SimulationSettings(554.3, 0.695e-3, 240, cfg.simulation.samples_per_rev),
                  cfg.insert.to_insert())
    v = classify(ds, ra_tolerance_m=cfg.simulation.ra_tolerance_um * 1e-6)
    assert (r.chatter, r.chatter_decided, r.floquet_multiplier, r.floquet_multiplier_se,
            r.vibration_growth, r.nonharmonic_energy_ratio, r.reasons) == _fields(v)
    assert r.roughness_Ra_um == ds.attrs["Ra_m"] * 1e6
    assert r.force_amplitude_N.to_dict() == summarize(ds)["force_amplitude_N"]
    for name in ds.data_vars:
        assert np.array_equal(r.dataset[name].values, ds[name].values, equal_nan=True), name


def test_the_sampling_check_is_classify_s_verdict_at_twice_the_samples():
    from robobore.dynamics.api import run_boring

    r = run_boring(EXAMPLE, speed_rpm=1000.0, depth_mm=0.3)
    chk = r.sampling_check
    assert r.tool_leaves_cut and chk is not None and chk.samples_per_rev == 2 * r.samples_per_rev
    cfg, src = _example()
    pr = build_process(cfg, src, depth_m=0.3e-3, coefficients=build_coefficients(cfg, src))
    v2 = classify(simulate(build_structure(cfg, src), pr,
                           SimulationSettings(1000.0, 0.3e-3, r.revolutions_simulated,
                                              chk.samples_per_rev), cfg.insert.to_insert()))
    assert chk.chatter is v2.chatter and chk.agrees is (v2.chatter == r.chatter)


def test_the_rotating_frame_and_feed_amplitude_are_the_array_formulas():
    """The compiled per-revolution pass gives, digit for digit, ``ax cos + ay sin``,
    ``-ax sin + ay cos`` and the half peak-to-peak feed displacement per revolution."""
    st, process = _bar()
    ds = simulate(st, process(0.3), SimulationSettings(600.0, 0.3e-3, 12, 240))
    Ns, revs = int(ds.attrs["samples_per_rev"]), int(ds.attrs["revolutions"])
    th = 2 * np.pi * np.arange(Ns) / Ns
    acc = ds["acceleration"].values
    ax, ay = acc[:, 0].reshape(revs, Ns), acc[:, 1].reshape(revs, Ns)
    rot = ds["rotational_acceleration"].values
    assert np.array_equal(rot[:, 0], (ax * np.cos(th) + ay * np.sin(th)).ravel())
    assert np.array_equal(rot[:, 1], (-ax * np.sin(th) + ay * np.cos(th)).ravel())
    z = ds["displacement"].values[:, 2].reshape(revs, Ns)
    assert np.array_equal(ds["feed_amplitude"].values, 0.5 * (z.max(axis=1) - z.min(axis=1)))


@pytest.mark.parametrize("cols", [1, 2, 3, 26])
def test_column_means_are_numpy_s_digit_for_digit(cols):
    from robobore.dynamics.timedomain import column_means

    rng = np.random.default_rng(44)
    for n in (1, 7, 1000, 57528):
        x = rng.standard_normal((n, cols)) * 1e-6 + rng.standard_normal(cols)
        for y in (x, x[n // 3:], x[:, :1], np.asfortranarray(x)):
            assert np.array_equal(column_means(y), y.mean(axis=0))
