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
    rec = make_record(_signal(3.0, fc=900.0), FS, ["acc"])
    assert detect_chatter(rec, DetectSettings(speed_rpm=1470.0 * 1.0)).chatter


def test_modes_restrict_the_search():
    rec = make_record(_signal(3.0), FS, ["acc"])
    assert detect_chatter(rec, DetectSettings(speed_rpm=1500.0, modes_Hz=(1250.0,))).chatter
    assert not detect_chatter(rec, DetectSettings(speed_rpm=1500.0, modes_Hz=(400.0,))).chatter
