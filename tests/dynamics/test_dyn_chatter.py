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


# ----------------------------------------------------------------------------- verdicts
def _cut(X: np.ndarray, ns: int, z: np.ndarray, h: np.ndarray, area: np.ndarray | None = None,
         speed_rpm: float = 600.0):
    """A Dataset with the fields :func:`classify` reads, from a constructed displacement
    ``X`` (n, 3) [m] sampled ``ns`` per revolution (one insert) and a surface profile."""
    import xarray as xr

    from robobore.dynamics.timedomain import roughness

    r = roughness(z, h)
    n = X.shape[0]
    area = np.full((n, 1), 1e-8) if area is None else area
    return xr.Dataset(
        {"displacement": (("time", "axis"), X), "chip_area": (("time", "insert"), area)},
        attrs={"samples_per_rev": ns, "n_inserts": 1, "dt_s": 60.0 / (speed_rpm * ns),
               "speed_rpm": speed_rpm, "diverged": 0, "Ra_m": r["Ra_m"], "Rz_m": r["Rz_m"],
               "form_slope_um_per_mm": r["form_slope_um_per_mm"]})


def _cusps(feed_m: float, nose_m: float, n_pass: int = 40, n: int = 4000):
    """Ideal feed marks of a round nose: envelope of circles every ``feed_m``."""
    zk = np.arange(n_pass) * feed_m
    z = np.linspace(zk[2], zk[-3], n)
    h = np.max([-(nose_m - np.sqrt(np.maximum(nose_m**2 - (z - c) ** 2, 0.0)))
                for c in zk], axis=0)
    return z, h


NS = 64


def _steady(revs: int = 40, amp: float = 2e-6) -> np.ndarray:
    t = np.arange(revs * NS)
    return np.column_stack([amp * np.cos(2 * np.pi * t / NS), amp * np.sin(2 * np.pi * t / NS),
                            0.3 * amp * np.sin(4 * np.pi * t / NS)])


def test_verdict_growing_oscillation_is_chatter():
    """A non-harmonic oscillation growing 20x over the run on top of the forced motion:
    chatter, at its own frequency (7.3 x the spindle frequency), mostly non-harmonic."""
    from robobore.dynamics.chatter import classify

    revs = 40
    t = np.arange(revs * NS)
    g = 1e-7 * np.exp(np.log(20.0) * t / t[-1]) * np.sin(2 * np.pi * 7.3 * t / NS)
    X = _steady(revs) + np.column_stack([g, 0.5 * g, g])
    z, h = _cusps(0.1e-3, 0.4e-3)
    v = classify(_cut(X, NS, z, h), ra_tolerance_m=1.6e-6)
    assert v.chatter
    assert v.feed_amplitude_growth > 10 and v.radial_amplitude_growth > 10
    assert v.chatter_frequency_Hz == pytest.approx(7.3 * 600 / 60, rel=0.02)
    # the growth per revolution (one insert: per pitch) is 20^(1/40) = 1.0778
    assert v.floquet_multiplier == pytest.approx(20.0 ** (1 / 40), rel=2e-3)
    assert v.chatter_decided and v.chatter_cause == "regenerative"
    # a smooth surface, but the cut chatters: the paper's criterion cannot say "stable"
    assert v.surface_finish == "ok" and v.paper_stable is False
    assert v.verdicts()["paper_criterion"] == "vibratory"


def test_verdict_steady_oscillation_is_not_chatter():
    """A large forced (spindle-periodic) motion plus a decaying transient: not chatter,
    whatever its size."""
    from robobore.dynamics.chatter import classify

    revs = 40
    t = np.arange(revs * NS)
    tr = 5e-6 * np.exp(-t / (3.0 * NS)) * np.sin(2 * np.pi * 3.1 * t / NS)
    X = _steady(revs, amp=50e-6) + np.column_stack([tr, tr, tr])
    z, h = _cusps(0.1e-3, 0.4e-3)
    v = classify(_cut(X, NS, z, h), ra_tolerance_m=1.6e-6)
    assert not v.chatter and v.chatter_frequency_Hz is None
    assert v.feed_amplitude_growth < 1 and v.vibration_growth < 1
    assert not v.tool_leaves_cut


def test_verdict_pure_taper_is_not_rough():
    """A smooth but tapered bore (71 um/mm): form, not roughness; Ra ~ 0 after removal while
    the raw mean deviation is tens of um."""
    from robobore.dynamics.chatter import classify
    from robobore.dynamics.timedomain import roughness

    z = np.linspace(0.0, 4e-3, 2000)
    h = 71e-6 / 1e-3 * z
    r = roughness(z, h)
    assert r["Ra_m"] < 1e-12 and r["form_slope_um_per_mm"] == pytest.approx(71.0, rel=1e-9)
    assert np.mean(np.abs(h - h.mean())) > 50e-6
    v = classify(_cut(_steady(), NS, z, h), ra_tolerance_m=1.6e-6)
    assert v.surface_finish == "ok" and v.paper_stable and not v.chatter


def test_verdict_feed_marks_only_rough_not_chatter():
    """Feed marks of a 0.4 mm nose at 0.3 mm/r, no vibration: Ra = 0.0321 f^2 / r (the
    classical cusp formula) = 7.2 um > 1.6 um, with or without a superposed taper: rough
    by the finish verdict and 'vibratory' by the paper's criterion, but not chatter."""
    from robobore.dynamics.chatter import classify
    from robobore.dynamics.timedomain import roughness

    f, r = 0.3e-3, 0.4e-3
    z, h = _cusps(f, r)
    ra = roughness(z, h)["Ra_m"]
    assert ra == pytest.approx(0.0321 * f**2 / r, rel=0.03)
    assert roughness(z, h + 71e-3 * z)["Ra_m"] == pytest.approx(ra, rel=1e-6)
    v = classify(_cut(_steady(), NS, z, h), ra_tolerance_m=1.6e-6)
    assert not v.chatter
    assert v.surface_finish == "rough" and not v.paper_stable
    assert v.verdicts() == {"chatter": False, "surface_finish": "rough",
                            "tool_leaves_cut": False, "paper_criterion": "vibratory"}


def test_verdict_tool_leaves_cut():
    from robobore.dynamics.chatter import classify

    X = _steady()
    area = np.full((X.shape[0], 1), 1e-8)
    area[-NS:-NS + 5] = 0.0
    z, h = _cusps(0.1e-3, 0.4e-3)
    v = classify(_cut(X, NS, z, h, area=area))
    assert v.tool_leaves_cut and 0 < v.tool_left_cut_fraction < 0.02
    # the motion repeats every pitch: the forced vibration interrupts the cut, no chatter
    assert not v.chatter and v.chatter_decided
    assert v.tool_leaves_cut_cause == "forced vibration" and v.chatter_cause is None
    assert v.surface_finish is None  # no tolerance given
    # without a tolerance the paper's criterion is not judged (never "stable" by default)
    assert v.paper_stable is None and v.verdicts()["paper_criterion"] is None
    assert any("not judged" in r for r in v.reasons)


def test_floquet_multiplier_of_decaying_growing_and_periodic_motion():
    """The per-pitch growth of |r(t) - r(t - tau)| fitted on the second half: a decay of
    2 %/pitch and a growth of 0.5 %/pitch on top of a large periodic motion are found within
    1e-3, with standard errors far below the margin; an exactly periodic motion gives 0."""
    from robobore.dynamics.chatter import floquet_multiplier

    s, n = 90, 120
    t = np.arange(n * s)
    per = 1e-4 * np.column_stack([np.cos(2 * np.pi * t / s), np.sin(2 * np.pi * t / s),
                                  0.1 * np.cos(4 * np.pi * t / s)])
    for rate in (0.98, 1.005):
        v = 1e-6 * rate ** (t / s) * np.sin(2 * np.pi * 0.37 * t / s)
        rho, se, k = floquet_multiplier(per + np.column_stack([v, 0.3 * v, v]), s)
        assert rho == pytest.approx(rate, abs=1e-3) and se < 1e-3 and k >= 50
    assert floquet_multiplier(per, s)[0] == 0.0


def test_amplitude_growth_ignores_the_entry_transient_and_beats():
    """A large entry transient that decays, then slow exponential growth (3.5 %/rev, as in
    the bundled study's radial chatter at 800 r/min): growth > 1; the decaying transient
    followed by a slowly decaying vibration: not growth."""
    from robobore.dynamics.chatter import amplitude_growth

    ns, revs = 120, 60
    t = np.arange(revs * ns) / ns  # revolutions
    transient = 15e-6 * np.exp(-t / 2.0) * np.sin(2 * np.pi * 1.3 * t)
    growing = 4e-6 * np.exp(0.035 * t) * np.sin(2 * np.pi * 0.55 * t)
    X = np.column_stack([transient + growing, 0.5 * (transient + growing),
                         0.2 * (transient + growing)])
    ag = amplitude_growth(X, ns, ns)
    assert ag["radial"] > 2 and ag["feed"] > 2
    decaying = 4e-6 * np.exp(-0.01 * t) * np.sin(2 * np.pi * 0.55 * t)
    X = np.column_stack([transient + decaying, transient + decaying,
                         0.2 * (transient + decaying)])
    ag = amplitude_growth(X, ns, ns)
    assert ag["radial"] < 1 and ag["feed"] < 1


def test_regenerative_pass_is_the_delay_difference():
    """The compiled pass shared by the chatter measures is r(t) - r(t - tau) by definition:
    its norm, feed and radial parts and max |r| equal numpy's, bit for bit."""
    from robobore.dynamics.chatter import regenerative

    X = np.random.default_rng(3).normal(size=(1000, 3)) * 1e-5
    s = 37
    r = regenerative(X, s)
    D = X[s:] - X[:-s]
    assert np.array_equal(r.d, np.linalg.norm(D, axis=1))
    assert np.array_equal(r.feed, np.abs(D[:, 2]))
    assert np.array_equal(r.radial, np.linalg.norm(D[:, :2], axis=1))
    assert r.xmax == np.abs(X).max()
    assert regenerative(X[:10], s).d.shape == (0,)
