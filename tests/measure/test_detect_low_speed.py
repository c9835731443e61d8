"""Chatter detection at low spindle speeds (150-1000 r/min, chatter at rotation-harmonic order
30-1000): SYNTHETIC records of the low-speed regime (robobore.measure.synthetic.LOW_SPEED),
labelled by the simulation's own verdict; hand-made signals with rotation harmonics, forced
lines near a mode and a chatter line between the harmonics; short records."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.measure.detect import PERSIST_WINDOWS, DetectSettings, detect_chatter
from robobore.measure.records import make_record
from robobore.measure.synthetic import LOW_SPEED, labelled_set

FS = 10000.0


@pytest.fixture(scope="module")
def records():
    return labelled_set(60, seed=5000, **LOW_SPEED)


@pytest.mark.parametrize("given", [False, True], ids=["speed estimated", "speed given"])
def test_low_speed_synthetic_accuracy(records, given):
    conf = {"tp": 0, "tn": 0, "fp": 0, "fn": 0}
    ferr = []
    for r in records:
        t = r.truth
        assert r.kind == "SYNTHETIC" and 150.0 <= t["speed_rpm"] <= 1000.0
        d = detect_chatter(r, DetectSettings(speed_rpm=t["speed_rpm"] if given else None,
                                             n_inserts=t["n_inserts"]))
        conf[("t" if d.chatter == t["chatter"] else "f") + ("p" if d.chatter else "n")] += 1
        if d.chatter and t["chatter"]:
            ferr.append(abs(d.chatter_frequency_Hz / t["chatter_frequency_Hz"] - 1))
    right = (conf["tp"] + conf["tn"]) / len(records)
    ferr = np.array(ferr)
    print(f"low speed, speed {'given' if given else 'estimated'}: {conf}, right {right:.3f}, "
          f"frequency within 2 % {np.mean(ferr <= 0.02):.3f}")
    assert 0.25 * len(records) < conf["tp"] + conf["fn"] < 0.75 * len(records)
    assert right >= 0.98
    assert conf["fp"] == 0
    assert np.mean(ferr <= 0.02) >= 0.9


def _turning_record(rpm: float, rng: np.random.Generator, chatter: bool, T: float = 8.0):
    """Rotation harmonics 1-8, forced harmonics amplified round a mode at 800-2500 Hz,
    white noise and, with ``chatter``, a growing line near the mode 0.55-0.95 of the harmonic
    spacing above a harmonic. Returns the record and the chatter frequency."""
    t = np.arange(int(T * FS)) / FS
    f0 = rpm / 60.0
    x = sum(np.sin(2 * np.pi * k * f0 * t + rng.uniform(0, 2 * np.pi)) / k for k in range(1, 9))
    fn = rng.uniform(800.0, 2500.0)
    for k in range(int(0.9 * fn / f0), int(1.1 * fn / f0)):
        fk = k * f0
        x = x + 0.0025 / abs(1 - (fk / fn) ** 2 + 0.04j * fk / fn) * np.sin(
            2 * np.pi * fk * t + rng.uniform(0, 2 * np.pi))
    x = x + 0.3 * rng.standard_normal(t.size)
    fc = None
    if chatter:
        fc = (int(fn / f0) + rng.uniform(0.55, 0.95)) * f0
        x = x + 3.0 * np.minimum(1.0, np.exp(3.0 * (t - 1.0))) * np.sin(2 * np.pi * fc * t)
    return make_record(x * 10 ** rng.uniform(-3, 3), FS, ["acc"]), fc


def test_chatter_between_high_order_harmonics_is_found():
    """320-425 r/min: the windows' harmonic bands cover most of the spacing at the chatter
    line's order (200-500), so that line is not the spindle's by its frequency."""
    rng = np.random.default_rng(45)
    wrong = []
    n = 0
    for rpm in (320.0, 370.0, 425.0):
        for i in range(6):
            chatter = i % 2 == 0
            rec, fc = _turning_record(rpm, rng, chatter)
            for given in (None, rpm):
                d = detect_chatter(rec, DetectSettings(speed_rpm=given))
                n += 1
                if d.chatter != chatter or (chatter and abs(d.chatter_frequency_Hz / fc - 1)
                                            > 0.002):
                    wrong.append((rpm, given, chatter, d.chatter, d.chatter_frequency_Hz, fc))
    print(f"{n - len(wrong)} of {n} right: wrong {wrong}")
    assert len(wrong) <= 1


def test_short_low_speed_record_keeps_persistence_windows():
    rng = np.random.default_rng(7)
    rec, fc = _turning_record(320.0, rng, True, T=3.2)  # 17 revolutions
    d = detect_chatter(rec, DetectSettings(speed_rpm=320.0))
    assert len(d.windows) >= PERSIST_WINDOWS
    assert d.window_s * 320.0 / 60.0 >= 8.0 - 1e-6
    assert d.chatter and d.chatter_frequency_Hz == pytest.approx(fc, rel=2e-3)


def test_record_too_short_for_resolved_windows_keeps_persistence_windows():
    rng = np.random.default_rng(8)
    for chatter in (False, True):
        rec, fc = _turning_record(150.0, rng, chatter, T=3.0)  # 7.5 revolutions
        d = detect_chatter(rec, DetectSettings(speed_rpm=150.0))
        assert len(d.windows) == PERSIST_WINDOWS
        assert d.chatter == chatter
        if chatter:
            assert d.chatter_frequency_Hz == pytest.approx(fc, rel=2e-3)
        assert any("short record" in r and "16 revolutions" in r for r in d.reasons)


def test_interruption_draws_leave_the_rest_of_the_record():
    """The interruption has its own generator: without it a low-speed record is the record
    of the same seed and speed range; with it the other draws are the same (the signals
    differ: the forced lines, and the mains and noise levels relative to the RMS)."""
    from robobore.measure.synthetic import simulated_record

    kw = {k: v for k, v in LOW_SPEED.items() if k != "interruption_probability"}
    seen = set()
    for seed in range(5000, 5012):
        a = simulated_record(seed, **LOW_SPEED)
        b = simulated_record(seed, interruption_probability=0.0, **kw)
        assert {k: v for k, v in a.truth.items() if k != "interruption"} == \
            {k: v for k, v in b.truth.items() if k != "interruption"}
        same = np.array_equal(a.signals, b.signals)
        assert same == (a.truth["interruption"] is None)
        seen.add(same)
    assert seen == {True, False}
