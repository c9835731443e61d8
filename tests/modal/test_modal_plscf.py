"""pLSCF (PolyMAX): normal equations, poles, participation factors, errors.

Reference: Peeters, Van der Auweraer, Guillaume & Leuridan (2004), Shock and Vibration 11,
eqs. 1-14. A continuous-time modal FRF is not exactly rational in z = exp(j w Ts), so the
z-domain model needs some over-modelling: on noise-free data the physical poles converge to
the true ones as the order rises (measured: SDOF 4e-5 at order 4, 2e-9 at order 10; robot
7x3 1e-2 at order 4, 2e-5 at 10, 6e-7 at 13). The tolerances below sit a decade above those.
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.errors import InputError
from robobore.modal.frf_data import FRFData
from robobore.modal.plscf import _blocks, normal_equation_lags, plscf
from robobore.modal.stabilization import mac
from robobore.modal.virtual import ModalTruth, robot_boring_truth


def test_toeplitz_blocks_equal_direct_jacobian_products():
    """R, S, T built from lag sums equal Re(G^H G), Re(G^H Y), Re(Y^H Y) formed directly
    from the Jacobian (Peeters 2004 eq. 8-9), to round-off."""
    rng = np.random.default_rng(0)
    no, l, nf, p = 2, 2, 30, 3
    f = np.sort(rng.uniform(1, 50, nf))
    H = rng.standard_normal((no, l, nf)) + 1j * rng.standard_normal((no, l, nf))
    w = rng.uniform(0.5, 2.0, (no, nf))
    r, s, t = normal_equation_lags(f, H, p, 50.0, w)
    R, S, T = _blocks(r, s, t, p)
    z = np.exp(1j * np.pi * f / 50.0)
    Om = z[:, None] ** np.arange(p + 1)[None, :]  # (nf, p+1)
    for o in range(no):
        G = w[o][:, None] * Om
        # Y[k, (s, i)] = -w Omega_s H_oi
        Y = -(w[o][:, None, None] * Om[:, :, None] * H[o].T[:, None, :]).reshape(nf, -1)
        np.testing.assert_allclose(R[o], (G.conj().T @ G).real, atol=1e-10)
        np.testing.assert_allclose(S[o], (G.conj().T @ Y).real, atol=1e-10)
        np.testing.assert_allclose(T[o], (Y.conj().T @ Y).real, atol=1e-10)


def test_sdof_pole_exact():
    """A single mode, noise-free, receptance and accelerance: the pole converges with the
    order (over-modelling): < 1e-3 at order 4, < 1e-7 at order 10 (relative)."""
    t = ModalTruth(np.array([12.0]), np.array([0.03]), np.array([[0.3]]), np.array([[0.3]]))
    f = np.linspace(1, 40, 400)
    lam_true = t.poles()[0]
    for typ in ("receptance", "accelerance"):
        res = plscf(t.frf_data(f, typ), max_order=10)
        for ps, tol in ((res.pole_sets[3], 1e-3), (res.pole_sets[9], 1e-7)):
            assert np.min(np.abs(ps.poles / lam_true - 1)) < tol


def test_mimo_poles_and_participation_noise_free():
    """Robot truth, 7x3 exact accelerances: at order 13 all five poles are found to 1e-5
    and each participation vector is parallel to the mode's hammer-point shape phi_in[:, r]
    (proportional damping: residue = phi_out phi_in^T / (2 j w_d)); MAC > 0.9999."""
    t = robot_boring_truth()
    f = np.linspace(2, 60, 1200)
    res = plscf(t.frf_data(f), max_order=13)
    ps = res.pole_sets[-1]
    for r, lam in enumerate(t.poles()):
        k = int(np.argmin(np.abs(ps.poles - lam)))
        assert abs(ps.poles[k] / lam - 1) < 1e-5
        assert mac(ps.participation[k], t.phi_in[:, r]) > 0.9999


def test_close_pair_needs_enough_order():
    """With 3 inputs the pair 24.6/25.34 Hz is two distinct poles at order 7 (within 0.1 %)."""
    t = robot_boring_truth()
    f = np.linspace(2, 60, 1200)
    res = plscf(t.frf_data(f), max_order=7)
    fr = res.pole_sets[-1].frequency_Hz
    assert np.min(np.abs(fr / 24.6 - 1)) < 1e-3 and np.min(np.abs(fr / 25.34 - 1)) < 1e-3


def test_plscf_bad_input():
    t = robot_boring_truth()
    d = t.frf_data(np.linspace(2, 60, 100))
    with pytest.raises(InputError, match="max order"):
        plscf(d, max_order=0)
    with pytest.raises(InputError, match="too few frequency lines") as e:
        plscf(d, band_Hz=(10, 20), max_order=60)
    assert "max_order" in str(e.value)
    with pytest.raises(InputError, match="outside the data"):
        plscf(d, band_Hz=(100, 200))
    with pytest.raises(InputError, match="min order"):
        plscf(d, max_order=5, min_order=6)
    with pytest.raises(InputError, match="weights"):
        plscf(d, max_order=5, weighting=np.ones((2, 3)))


def test_exp_window_shift_applied():
    t = ModalTruth(np.array([12.0]), np.array([0.03]), np.array([[0.3]]), np.array([[0.3]]))
    f = np.linspace(1, 40, 400)
    d = t.frf_data(f, "receptance")
    d2 = FRFData(d.frequency_Hz, d.frf, d.frf_type, exp_window_tau_s=0.5)
    a = plscf(d, max_order=2).pole_sets[-1].poles
    b = plscf(d2, max_order=2).pole_sets[-1].poles
    np.testing.assert_allclose(b - a, 2.0, atol=1e-9)


def test_narrow_band_far_from_zero_still_identifies():
    """Band 20-30 Hz covers only 1/3 of the unit-circle arc (Ts = 1/(2 f_hi)); R becomes
    numerically singular at high order and the minimum-norm elimination takes over: the
    close pair is still found to 0.1 % (noise-free) over orders up to 40."""
    from robobore.modal.identify import identify_modes

    t = robot_boring_truth()
    d = t.frf_data(np.linspace(2, 60, 1200))
    res = identify_modes(d, band_Hz=(20.0, 30.0), max_order=40).result
    np.testing.assert_allclose(res.frequencies_Hz, [24.6, 25.34], rtol=1e-3)
    np.testing.assert_allclose(res.damping_ratios, [0.020, 0.022], rtol=1e-2)
