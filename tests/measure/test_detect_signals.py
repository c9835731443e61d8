"""Chatter detection on constructed signals with known content, and the contract."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.measure.detect import DetectSettings, detect_chatter, find_spindle, window_spectra
from robobore.measure.records import make_record

FS = 10000.0


def _signal(chatter_amp: float, seed: int = 0, T: float = 4.0, f1: float = 25.0,
            fc: float = 1234.5, onset: float = 1.0, mains: float = 50.0):
    rng = np.random.default_rng(seed)
    t = np.arange(int(T * FS)) / FS
    x = sum(np.cos(2 * np.pi * k * f1 * t + rng.uniform(0, 6)) / k for k in range(1, 12))
    x = x + 0.3 * np.sin(2 * np.pi * mains * t) + 0.1 * np.sin(2 * np.pi * 3 * mains * t)
    grow = np.clip((t - onset) / 0.3, 0.0, 1.0)
    x = x + chatter_amp * grow * np.sin(2 * np.pi * fc * t)
    return x + 0.05 * rng.standard_normal(t.size)


def test_stable_and_chatter_with_onset():
    rec = make_record(_signal(0.0), FS, ["acc"])
    d = detect_chatter(rec, DetectSettings(speed_rpm=1500.0))
    assert not d.chatter and d.chatter_frequency_Hz is None
    rec = make_record(_signal(3.0), FS, ["acc"])
    d = detect_chatter(rec, DetectSettings(speed_rpm=1500.0))
    assert d.chatter
    assert d.chatter_frequency_Hz == pytest.approx(1234.5, rel=1e-3)
    assert 0.5 <= d.onset_s <= 1.3
    assert d.spindle_frequency_Hz == pytest.approx(25.0, rel=1e-3)
    assert any(abs(v - 50.0) < 1 for v in d.fixed_lines_Hz)
    out = d.to_dict()
    for key in ("chatter", "chatter_frequency_Hz", "onset_s", "windows"):
        assert key in out
    assert {"t0_s", "t1_s", "chatter"} <= set(out["windows"][0])
    assert not out["windows"][0]["chatter"] and out["windows"][-1]["chatter"]


def test_spindle_estimated_without_speed():
    x = _signal(0.0, f1=31.0)
    f, _, P = window_spectra(x[None, :], FS, 20000, 10000)
    avg = (P / P.sum(axis=2, keepdims=True)).mean(axis=(0, 1))
    f0, src, n = find_spindle(f, avg, None, 2.0, 4500.0)
    assert f0 == pytest.approx(31.0, rel=1e-3) and n >= 3


def test_a_chatter_line_on_a_mains_multiple_is_not_taken_for_mains():
    # chatter at 900 Hz = 18 x 50 Hz, far stronger than the mains fundamental
    rec = make_record(_signal(3.0, fc=900.0, f1=23.3), FS, ["acc"])  # 900 / 23.3 = 38.6
    assert detect_chatter(rec, DetectSettings(speed_rpm=60 * 23.3)).chatter
    assert detect_chatter(rec).chatter


def test_modes_restrict_the_search():
    rec = make_record(_signal(3.0), FS, ["acc"])
    assert detect_chatter(rec, DetectSettings(speed_rpm=1500.0, modes_Hz=(1250.0,))).chatter
    assert not detect_chatter(rec, DetectSettings(speed_rpm=1500.0, modes_Hz=(400.0,))).chatter


def _forced_with_drift(drift: float, chatter_amp: float = 0.0, seed: int = 2, T: float = 6.0):
    """Insert-passing harmonics (2 inserts, 25 Hz spindle) amplified by a mode at 1200 Hz
    (2 % damping), the speed wandering by +-drift (period 4 s), white noise; optionally a
    chatter line at 1234.5 Hz."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(T * FS)) / FS
    f1 = 25.0
    phase = 2 * np.pi * f1 * (t - drift * 4.0 / (2 * np.pi) * np.cos(2 * np.pi * t / 4.0))
    x = np.zeros_like(t)
    for k in range(1, 120):
        fk = k * f1
        r = fk / 1200.0
        h = r**2 / abs(1 - r**2 + 0.04j * r)  # acceleration receptance shape
        a = h / k**0.5 * (1.0 if k % 2 == 0 else 0.2)
        x += a * np.cos(k * phase + rng.uniform(0, 2 * np.pi))
    x += chatter_amp * np.sin(2 * np.pi * 1234.5 * t)
    return x + 0.05 * rng.standard_normal(t.size)


def test_forced_vibration_of_a_wandering_spindle_is_stable():
    for drift in (0.0, 0.002):
        rec = make_record(_forced_with_drift(drift), FS, ["acc"])
        for speed in (None, 1500.0):
            d = detect_chatter(rec, DetectSettings(speed_rpm=speed, n_inserts=2))
            assert not d.chatter, (drift, speed, d.reasons)
        assert d.spindle_frequency_Hz == pytest.approx(25.0, rel=2e-3)
    rec = make_record(_forced_with_drift(0.002, chatter_amp=20.0), FS, ["acc"])
    d = detect_chatter(rec)
    assert d.chatter and d.chatter_frequency_Hz == pytest.approx(1234.5, rel=2e-3)


def test_a_ramp_channel_and_a_drift_are_not_chatter():
    x = _signal(0.0)
    t = np.arange(x.size) / FS
    rec = make_record(np.vstack([x + 5.0 * t, np.arange(x.size, dtype=float)]), FS,
                      ["acc", "sample_index"])
    assert not detect_chatter(rec, DetectSettings(speed_rpm=1500.0)).chatter
