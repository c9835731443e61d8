"""FRF estimation: closed forms, windows, hit checks, bad input."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robobore.errors import DataError, InputError
from robobore.modal.frf import (
    DoubleHitWarning,
    HammerRecords,
    LeakageWarning,
    check_hit,
    estimate_frf,
    exponential_window,
)
from robobore.modal.frf_data import FRFData, check_frequencies, convert_frf
from robobore.modal.identify import identify_modes
from robobore.modal.virtual import ModalTruth, robot_boring_truth, simulate_hammer_test


def sdof_truth(f=10.0, z=0.02) -> ModalTruth:
    return ModalTruth(np.array([f]), np.array([z]), np.array([[0.2]]), np.array([[0.2]]))


def test_convert_frf_closed_form():
    """Accelerance = (j w)^2 receptance = j w mobility (definition)."""
    f = np.array([1.0, 2.0, 5.0])
    rec = np.array([[[1 + 1j, 2.0, -1j]]])
    w = 2 * np.pi * f
    acc = convert_frf(rec, f, "receptance", "accelerance")
    np.testing.assert_allclose(acc, -(w**2) * rec)
    mob = convert_frf(acc, f, "accelerance", "mobility")
    np.testing.assert_allclose(mob, 1j * w * rec)
    with pytest.raises(InputError, match="0 Hz"):
        convert_frf(rec, np.array([0.0, 1, 2]), "accelerance", "receptance")


def test_h1_noise_free_equals_exact_frf():
    """Without noise the estimator returns the modal FRF at the DFT lines exactly (the
    generator filters with H on a padded grid; the response has decayed within the record).
    Tolerance 1e-6 relative: the leakage of the 8 s record is exp(-zeta w T) ~ 1e-7."""
    truth = robot_boring_truth()
    rec = simulate_hammer_test(truth, n_hits=2, noise_force=0.0, noise_response=0.0,
                               duration_s=12.0, seed=1)
    est = estimate_frf(rec, use_force_window=False)
    f = est.frf.frequency_Hz
    m = (f > 2) & (f < 60)
    exact = truth.frf(f[m])
    err = np.abs(est.frf.frf[:, :, m] - exact).max() / np.abs(exact).max()
    assert err < 1e-6
    # coherence 1 up to the same ~1e-7 leakage, which differs slightly between hits
    np.testing.assert_allclose(est.frf.coherence[:, :, m], 1.0, atol=1e-6)
    assert est.n_averages.tolist() == [2, 2, 2]


def test_h1_h2_hv_bracket_with_force_noise():
    """Noise on the force biases H1 low and H2 high (Bendat & Piersol, ch. 9): at the
    resonance |H1| <= |Hv| <= |H2|."""
    truth = sdof_truth()
    rec = simulate_hammer_test(truth, n_hits=5, noise_force=0.3, noise_response=0.3, seed=3)
    out = {e: estimate_frf(rec, estimator=e, use_force_window=False).frf for e in
           ("H1", "H2", "Hv")}
    k = int(np.argmin(np.abs(out["H1"].frequency_Hz - 10.0)))
    a1, a2, av = (np.abs(out[e].frf[0, 0, k]) for e in ("H1", "H2", "Hv"))
    assert a1 <= av <= a2
    with pytest.raises(InputError, match="estimator"):
        estimate_frf(rec, estimator="H3")


def test_exponential_window_damping_correction():
    """Exponential window w = exp(-t/tau) shifts every pole by -1/tau (module docstring of
    robobore.modal.frf). A 2 s record of a 7 Hz, 1 % mode is cut before it decays
    (leakage); with tau = 0.5 s the estimate before correction has zeta ~ 0.01 + 1/(tau w_n)
    = 0.0555 and after correction recovers 0.01 within 5 %."""
    truth = ModalTruth(np.array([7.0, 23.0]), np.array([0.01, 0.02]),
                       np.array([[0.2, 0.1], [0.1, -0.15]]), np.array([[0.2, 0.1]]))
    rec = simulate_hammer_test(truth, n_hits=5, duration_s=2.0, noise_force=0.005,
                               noise_response=0.005, seed=4)
    with pytest.warns(LeakageWarning, match="has not decayed"):
        assert estimate_frf(rec).decay_ratio[0] > 0.2
    tau = 0.5
    d = estimate_frf(rec, exp_window_tau_s=tau).frf
    assert d.exp_window_tau_s == tau
    an = identify_modes(d, band_Hz=(3.0, 40.0), n_modes=2)
    z = an.result.damping_ratios
    np.testing.assert_allclose(an.result.frequencies_Hz, [7.0, 23.0], rtol=2e-3)
    np.testing.assert_allclose(z, [0.01, 0.02], rtol=0.05)
    # without the correction the window's damping would be there
    raw = FRFData(d.frequency_Hz, d.frf, d.frf_type)
    z_raw = identify_modes(raw, band_Hz=(3.0, 40.0), n_modes=2).result.damping_ratios
    np.testing.assert_allclose(z_raw[0], 0.01 + 1 / (tau * 2 * np.pi * 7.0), rtol=0.05)
    w = exponential_window(10, 10.0, 1.0, 0.2)
    np.testing.assert_allclose(w[:3], [1.0, 1.0, 1.0])
    np.testing.assert_allclose(w[5], np.exp(-0.3))


def test_double_hit_and_overload_are_detected_and_dropped():
    truth = robot_boring_truth()
    rec = simulate_hammer_test(truth, n_hits=4, double_hits=[(0, 1)], overloads=[(2, 3)],
                               seed=5)
    with pytest.warns(DoubleHitWarning) as rec_w:
        est = estimate_frf(rec)
    msgs = " ".join(str(w.message) for w in rec_w)
    assert "hammer_x hit 2: double hit" in msgs and "hammer_z hit 4: response overload" in msgs
    flagged = {(h.input_index, h.hit_index) for h in est.hits if h.flagged}
    assert flagged == {(0, 1), (2, 3)}
    assert est.n_averages.tolist() == [4, 4, 4]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DoubleHitWarning)
        est2 = estimate_frf(rec, drop_flagged=True)
    assert est2.n_averages.tolist() == [3, 4, 3]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DoubleHitWarning)
        est3 = estimate_frf(rec.drop_hits([(0, 1), (2, 3)]))
    np.testing.assert_allclose(est3.frf.frf, est2.frf.frf)
    # clean hits are not flagged
    clean = simulate_hammer_test(truth, n_hits=2, seed=6, noise_force=0.05, noise_response=0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DoubleHitWarning)
        warnings.simplefilter("error", LeakageWarning)  # 8 s records: decayed, no warning
        assert estimate_frf(clean).decay_ratio.max() < 0.1


def test_check_hit_hand_made():
    fs = 1000.0
    f = np.zeros(200)
    f[10:15] = [0.3, 0.9, 1.0, 0.9, 0.3]
    _, width, dbl, fo, _ = check_hit(f, np.zeros((1, 200)), fs)
    assert not dbl and not fo and width == pytest.approx(0.005)
    f2 = f.copy()
    f2[60:63] = [0.2, 0.4, 0.2]
    assert check_hit(f2, np.zeros((1, 200)), fs)[2]
    r = np.sin(np.arange(200) / 5.0)
    assert check_hit(f, np.clip(r, -0.8, 0.8)[None], fs)[4]
    assert check_hit(f, r[None], fs, response_range=1.0)[4]


def test_drop_hits_and_all_dropped_is_an_error():
    rec = simulate_hammer_test(sdof_truth(), n_hits=2, seed=0)
    r2 = rec.drop_hits([(0, 0)])
    assert estimate_frf(r2).n_averages.tolist() == [1]
    with pytest.raises(DataError, match="no valid hit"):
        estimate_frf(r2.drop_hits([(0, 1)]))
    with pytest.raises(InputError, match="no such hit"):
        rec.drop_hits([(1, 0)])


def test_frfdata_bad_input_messages():
    f = np.linspace(1, 10, 20)
    h = np.ones((2, 1, 20), complex)
    with pytest.raises(DataError, match="wrong shape") as e:
        FRFData(f, np.ones((2, 1, 19)), "accelerance", source="x.npz")
    assert "x.npz" in str(e.value) and "(n_outputs, n_inputs, 20)" in str(e.value)
    f_bad = f.copy()
    f_bad[5] = f_bad[4]
    with pytest.raises(DataError, match="not strictly increasing") as e:
        FRFData(f_bad, h)
    assert "row 6" in str(e.value) and "Hz" in str(e.value)
    h_nan = h.copy()
    h_nan[1, 0, 3] = np.nan
    with pytest.raises(DataError, match="non-finite") as e:
        FRFData(f, h_nan)
    assert "output 1, input 0" in str(e.value) and "row 4" in str(e.value)
    with pytest.raises(DataError, match="unknown FRF type"):
        FRFData(f, h, "inertance")
    d = FRFData(f, h)
    with pytest.raises(InputError, match="outside the data") as e:
        d.band(20.0, 30.0)
    assert "[1, 10] Hz" in str(e.value)
    with pytest.raises(InputError, match="extends beyond the data"):
        d.band(5.0, 12.0)
    with pytest.raises(InputError, match="LO < HI"):
        d.band(5.0, 2.0)
    with pytest.raises(InputError, match="fewer than 8"):
        d.band(1.0, 2.0)


def test_hammer_records_bad_input():
    f = np.zeros((1, 2, 64))
    with pytest.raises(DataError, match="response records have the wrong shape"):
        HammerRecords(100.0, f, np.zeros((1, 2, 3, 63)))
    r = np.zeros((1, 2, 3, 64))
    r[0, 1, 2, 10] = np.nan
    with pytest.raises(DataError, match="non-finite") as e:
        HammerRecords(100.0, f, r)
    assert "row 11" in str(e.value)
    with pytest.raises(DataError, match="sample rate"):
        HammerRecords(-1.0, f, np.zeros((1, 2, 3, 64)))
    rec = HammerRecords(100.0, f, np.zeros((1, 2, 3, 64)))
    with pytest.raises(DataError, match="all zeros"):
        estimate_frf(rec)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=0,
                max_size=12))
def test_check_frequencies_property(values):
    """Either a valid axis comes back unchanged or a DataError (never another exception)."""
    a = np.array(values, dtype=float)
    try:
        out = check_frequencies(a)
    except DataError:
        return
    assert out.ndim == 1 and out.size >= 2 and out[0] >= 0
    assert np.all(np.diff(out) > 0) and np.all(np.isfinite(out))
