"""Chatter indicators on synthetic signals with known content."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.dynamics.chatter import harmonic_analysis, vibration_growth


def test_harmonic_analysis_finds_chatter_frequency():
    """Spindle harmonics at 50 Hz plus a 137 Hz component carrying 20 % of the energy."""
    fs, T = 5000.0, 4.0
    t = np.arange(int(fs * T)) / fs
    x = np.sin(2 * np.pi * 50 * t) + 0.5 * np.sin(2 * np.pi * 100 * t) + 0.559 * np.sin(
        2 * np.pi * 137 * t)
    ratio, f = harmonic_analysis(x, fs, 50.0)
    assert f == pytest.approx(137.0, abs=0.5)
    assert ratio == pytest.approx(0.559**2 / (1 + 0.25 + 0.559**2), rel=0.05)


def test_harmonic_analysis_pure_harmonics():
    fs = 4000.0
    t = np.arange(8000) / fs
    ratio, _ = harmonic_analysis(np.sin(2 * np.pi * 40 * t) + 0.2 * np.cos(2 * np.pi * 120 * t),
                                 fs, 40.0)
    assert ratio < 1e-3


def test_vibration_growth_of_growing_and_periodic_motion():
    s = 100
    t = np.arange(20 * s)
    periodic = np.column_stack([np.sin(2 * np.pi * t / s), np.zeros_like(t), np.zeros_like(t)])
    periodic[:s] += 1e-3 * np.sin(0.7 * t[:s])[:, None]  # an initial transient only
    assert vibration_growth(periodic, s) < 1e-6
    grow = np.column_stack([np.exp(t / (5.0 * s)) * np.sin(0.37 * t), 0 * t, 0 * t])
    assert vibration_growth(grow, s) > 10
