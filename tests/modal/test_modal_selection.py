"""Mode selection by contribution (SYNTHETIC tool-point hammer tests, documented truth in
``robobore.modal.virtual.tool_point_truth``).

The truth has a well-damped end-mill mode that dominates the tool point and a spindle mode
that is weak at the tip but better supported in the stabilisation diagram (at 3 % noise):
``--modes 3`` must return the three modes that dominate the tool-point response, each within
2 % in frequency and 30 % in damping, and rank the shares like the truth's driving-point
peaks; ranking by support alone picks the spindle mode instead.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from robobore.errors import InputError
from robobore.modal.frf import estimate_frf
from robobore.modal.identify import ModalResult, identify_modes
from robobore.modal.virtual import simulate_hammer_test, tool_point_truth

BAND = (600.0, 3500.0)


def tool_point_frf(seed: int, noise: float = 0.03):
    truth = tool_point_truth()
    rec = simulate_hammer_test(truth, n_hits=5, sample_rate_Hz=12800.0, duration_s=0.32,
                               tip=1e-4, noise_force=noise, noise_response=noise, seed=seed)
    fr = estimate_frf(rec).frf
    # hammer and the first accelerometer at the same node and direction: the driving point
    return truth, dataclasses.replace(fr, output_dofs=tuple((k + 1, 1) for k in range(5)),
                                      input_dofs=((1, 1),))


def dominant_truth(truth, n: int) -> np.ndarray:
    w = 2 * np.pi * truth.frequencies_Hz
    peak = truth.phi_in[0] ** 2 / (2 * truth.damping_ratios * w**2)
    return np.sort(np.argsort(-peak)[:n])


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_modes_n_returns_the_dominant_modes(seed):
    truth, fr = tool_point_frf(seed)
    want = dominant_truth(truth, 3)
    res: ModalResult = identify_modes(fr, band_Hz=BAND, n_modes=3).result
    np.testing.assert_array_less(np.abs(res.frequencies_Hz / truth.frequencies_Hz[want] - 1),
                                 0.02)
    np.testing.assert_array_less(np.abs(res.damping_ratios / truth.damping_ratios[want] - 1),
                                 0.30)
    # the shares rank like the truth's driving-point peaks, the point is the tip
    w = 2 * np.pi * truth.frequencies_Hz[want]
    peak = truth.phi_in[0, want] ** 2 / (2 * truth.damping_ratios[want] * w**2)
    got = np.array([m.peak_compliance_m_per_N for m in res.modes])
    np.testing.assert_allclose(got, peak, rtol=0.05)
    assert [m.share_point for m in res.modes] == ["tip/hammer_tip"] * 3
    shares = np.array([m.share for m in res.modes])
    assert np.all((shares > 0) & (shares < 1))
    assert np.array_equal(np.argsort(-shares), np.argsort(-peak))
    # ranking by support alone drops a dominant mode for the weak spindle mode
    stable = identify_modes(fr, band_Hz=BAND, n_modes=3, select="stable").result
    assert not np.allclose(stable.frequencies_Hz, res.frequencies_Hz, rtol=0.02)
    # every physical mode is listed with its share, the selected ones flagged
    phys = res.stabilisation["physical_modes"]
    assert len(phys) == truth.n_modes and sum(p["selected"] for p in phys) == 3
    assert abs(sum(p["share"] for p in phys) - 1) < 1e-9


def test_select_lowest_and_user_point():
    truth, fr = tool_point_frf(0, noise=0.01)
    low = identify_modes(fr, band_Hz=BAND, n_modes=4, select="lowest").result
    np.testing.assert_allclose(low.frequencies_Hz, truth.frequencies_Hz[:4], rtol=0.005)
    # ranked at the housing (the truth's peaks there: the spindle mode, then 2610 Hz)
    hous = identify_modes(fr, band_Hz=BAND, n_modes=2, point="housing").result
    w = 2 * np.pi * truth.frequencies_Hz
    peak = np.abs(truth.phi_out[4] * truth.phi_in[0]) / (2 * truth.damping_ratios * w**2)
    want = np.sort(np.argsort(-peak)[:2])
    np.testing.assert_allclose(hous.frequencies_Hz, truth.frequencies_Hz[want], rtol=0.005)
    assert hous.modes[0].share_point.startswith("housing/")
    with pytest.raises(InputError, match="rank point"):
        identify_modes(fr, band_Hz=BAND, n_modes=2, point="nowhere")
    with pytest.raises(InputError, match="selection"):
        identify_modes(fr, band_Hz=BAND, n_modes=2, select="best")


def test_share_round_trips_in_json():
    _, fr = tool_point_frf(1, noise=0.01)
    res = identify_modes(fr, band_Hz=BAND, n_modes=3).result
    back = ModalResult.from_dict(res.to_dict())
    assert [m.share for m in back.modes] == [m.share for m in res.modes]
    assert back.modes[0].share_point == res.modes[0].share_point


@pytest.mark.parametrize("dofs", ["none", "opposite sign"])
def test_rank_point_without_matching_dofs_is_the_most_compliant_output(dofs):
    """Measured FRFs (5 % complex noise on the SYNTHETIC tool point) without driving-point
    DOFs: the modes are ranked at the tip (the most compliant output) or at the DOF whose
    direction sign differs, and the three tip-dominant modes come back."""
    from robobore.modal.frf_data import FRFData

    truth = tool_point_truth()
    f = np.arange(0.0, 5000.0, 2.0)
    H = truth.frf(f, "receptance")
    rng = np.random.default_rng(3)
    H = H + 0.05 * np.abs(H).mean(axis=2, keepdims=True) * (
        rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape)) / np.sqrt(2)
    kw = {} if dofs == "none" else {"output_dofs": tuple((k + 1, 3) for k in range(5)),
                                    "input_dofs": ((1, -3),)}
    d = FRFData(f, H, "receptance", None, truth.output_names, truth.input_names, **kw)
    res = identify_modes(d, band_Hz=BAND, n_modes=3).result
    np.testing.assert_allclose(res.frequencies_Hz, truth.frequencies_Hz[:3], rtol=0.02)
    rp = res.stabilisation["selection"]["rank_point"]
    assert ("tip" in rp) if dofs == "none" else ("sign ignored" in rp)
