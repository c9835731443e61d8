"""Uncertainty of identified modes (jackknife over hits) on SYNTHETIC hammer tests with known
noise: the 95 % intervals must cover the true frequency and damping in 90-99 % of cases.

The coverage check: 200 virtual hammer tests (seeds 0-199) of a two-mode structure (12 Hz /
2 %, 31 Hz / 4 %; 3 accelerometers, one hammer point, 5 hits, white noise 2 % of each
channel's RMS on force and responses), 400 intervals each for f and zeta.
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.modal.frf import combine_hits, estimate_frf
from robobore.modal.identify import ModalResult, identify_modes
from robobore.modal.virtual import ModalTruth, simulate_hammer_test


def two_modes() -> ModalTruth:
    po = np.array([[0.10, 0.06], [0.05, -0.09], [0.08, 0.04]])
    return ModalTruth(np.array([12.0, 31.0]), np.array([0.02, 0.04]), po, po[:1])


def _test(truth: ModalTruth, seed: int, noise: float = 0.02, hits: int = 5):
    rec = simulate_hammer_test(truth, n_hits=hits, sample_rate_Hz=128.0, duration_s=8.0,
                               noise_force=noise, noise_response=noise, seed=seed)
    return estimate_frf(rec)


def test_95_percent_intervals_cover_the_truth_in_90_to_99_percent():
    truth = two_modes()
    cover_f, cover_z = [], []
    for seed in range(200):
        res = identify_modes(_test(truth, seed), band_Hz=(2.0, 60.0), max_order=20).result
        assert len(res.modes) == 2
        for m, ft, zt in zip(res.modes, truth.frequencies_Hz, truth.damping_ratios,
                             strict=True):
            u = m.uncertainty
            lo, hi = u.frequency_ci_Hz
            cover_f.append(lo <= ft <= hi)
            lo, hi = u.damping_ci
            cover_z.append(lo <= zt <= hi)
    cf, cz = np.mean(cover_f), np.mean(cover_z)
    assert 0.90 <= cf <= 0.99, cf
    assert 0.90 <= cz <= 0.99, cz


def test_intervals_shrink_with_noise_and_hold_the_estimate():
    truth = two_modes()
    lo_noise = identify_modes(_test(truth, 3, 0.005), band_Hz=(2.0, 60.0),
                              max_order=20).result
    hi_noise = identify_modes(_test(truth, 3, 0.04), band_Hz=(2.0, 60.0), max_order=20).result
    for a, b in zip(lo_noise.modes, hi_noise.modes, strict=True):
        assert a.uncertainty.frequency_std_Hz < b.uncertainty.frequency_std_Hz
        assert a.uncertainty.damping_std < b.uncertainty.damping_std
        lo, hi = a.uncertainty.frequency_ci_Hz
        assert lo < a.frequency_Hz < hi
        assert a.uncertainty.dof == pytest.approx(4.0, abs=0.5)  # one input, 5 hits
        assert 0.99 < a.uncertainty.shape_mac_min <= 1.0
        assert len(a.uncertainty.shape_std) == 3


def test_json_round_trip_and_frf_input_uses_the_residual_bootstrap():
    truth = two_modes()
    est = _test(truth, 0)
    res = identify_modes(est, band_Hz=(2.0, 60.0), max_order=20).result
    back = ModalResult.from_dict(res.to_dict())
    assert back.modes[0].uncertainty == res.modes[0].uncertainty
    assert res.stabilisation["uncertainty"]["replicates"] == 5
    frf_only = identify_modes(est.frf, band_Hz=(2.0, 60.0), max_order=20).result
    assert frf_only.stabilisation["uncertainty"]["method"].startswith("wild bootstrap")
    u = frf_only.modes[0].uncertainty
    assert u.method == "bootstrap of the fit residuals" and u.n_replicates == 12
    assert u.frequency_ci_Hz[0] < frf_only.modes[0].frequency_Hz < u.frequency_ci_Hz[1]
    none = identify_modes(est.frf, band_Hz=(2.0, 60.0), max_order=20, uncertainty=False)
    assert none.result.modes[0].uncertainty is None


def test_frf_only_intervals_cover_the_truth_in_90_to_99_percent():
    """200 SYNTHETIC FRF sets (the two-mode structure's exact accelerance, 0.125 Hz lines,
    complex white noise 2 % of each FRF's mean magnitude): bootstrap of the residuals."""
    from robobore.modal.frf_data import FRFData

    truth = two_modes()
    f = np.arange(0.0, 64.0, 0.125)
    H = truth.frf(f, "accelerance")
    cover_f, cover_z = [], []
    for seed in range(200):
        rng = np.random.default_rng(seed)
        Hn = H + 0.02 * np.abs(H).mean(axis=2, keepdims=True) * (
            rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape)) / np.sqrt(2)
        res = identify_modes(FRFData(f, Hn, "accelerance"), band_Hz=(2.0, 60.0),
                             max_order=20).result
        assert len(res.modes) == 2
        for m, ft, zt in zip(res.modes, truth.frequencies_Hz, truth.damping_ratios,
                             strict=True):
            cover_f.append(m.uncertainty.frequency_ci_Hz[0] <= ft
                           <= m.uncertainty.frequency_ci_Hz[1])
            cover_z.append(m.uncertainty.damping_ci[0] <= zt <= m.uncertainty.damping_ci[1])
    cf, cz = np.mean(cover_f), np.mean(cover_z)
    assert 0.90 <= cf <= 0.99, cf
    assert 0.90 <= cz <= 0.99, cz


def test_combine_hits_reproduces_the_average_and_refuses_empty_inputs():
    est = _test(two_modes(), 1)
    np.testing.assert_allclose(combine_hits(est, np.ones((1, 5))).frf, est.frf.frf, rtol=1e-12)
    w = np.ones((1, 5))
    w[0, 2] = 0
    one_out = combine_hits(est, w).frf
    assert not np.allclose(one_out, est.frf.frf)
    from robobore.errors import InputError

    with pytest.raises(InputError, match="every input needs a hit"):
        combine_hits(est, np.zeros((1, 5)))


def test_intervals_propagate_to_the_equivalent_model():
    from robobore.equivalent import EquivalentModel
    from robobore.modal.virtual import robot_boring_truth

    truth = robot_boring_truth()
    rec = simulate_hammer_test(truth, n_hits=5, sample_rate_Hz=256.0, duration_s=6.0,
                               noise_force=0.02, noise_response=0.02, seed=4)
    res = identify_modes(estimate_frf(rec), band_Hz=(3.0, 60.0)).result
    ks = {"x": 1.588e6, "y": 1.306e6, "z": 1.143e6}
    em = EquivalentModel.from_stiffness_and_modes(ks, res)
    for a in "xyz":
        u = em.uncertainty[a]
        assert u["frequency_Hz"][0] < em.frequency_Hz[a] < u["frequency_Hz"][1]
        assert u["mass_kg"][0] < em.mass_kg[a] < u["mass_kg"][1]  # m = k / w^2
        assert u["damping_N_s_per_m"][0] < em.damping_N_s_per_m[a] < \
            u["damping_N_s_per_m"][1]
    # the ranges travel in the equivalent JSON (lobes --band reads them) and come back equal
    d = em.to_dict()
    assert d["uncertainty"] == em.uncertainty
    assert EquivalentModel.from_dict(d).uncertainty == em.uncertainty
    # modes without intervals: none
    plain = EquivalentModel.from_stiffness_and_modes(
        ks, identify_modes(estimate_frf(rec).frf, band_Hz=(3.0, 60.0),
                           uncertainty=False).result)
    assert plain.uncertainty == {}
