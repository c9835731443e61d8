"""benchmarks/shear_plane_check.py: the Merchant / Oxley relations it uses, on constructed
cases (Oxley, "Mechanics of Machining", 1989, ch. 2-5; tolerances: round-off, 1e-9, and the
fixed point's own stopping tolerance, 1e-5)."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import pytest

from robobore.material.library import load_material

_PATH = Path(__file__).parents[3] / "benchmarks" / "shear_plane_check.py"
_spec = importlib.util.spec_from_file_location("shear_plane_check", _PATH)
spc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(spc)  # type: ignore[union-attr]


def test_merchant_geometry_recovers_a_constructed_shear_angle():
    alpha, phi = math.radians(15.0), math.radians(30.0)
    r = math.cos(phi - alpha) / math.sin(phi)  # chip ratio of that shear angle
    st = spc.shear_state(60e-6, 0.1, r, alpha)
    assert st["phi"] == pytest.approx(phi, rel=1e-12)
    # shear strain: cot(phi) + tan(phi - alpha)
    assert st["gamma"] == pytest.approx(1 / math.tan(phi) + math.tan(phi - alpha), rel=1e-12)
    assert st["vs"] == pytest.approx(0.1 * math.cos(alpha) / math.cos(phi - alpha), rel=1e-12)
    assert st["l"] == pytest.approx(60e-6 / math.sin(phi), rel=1e-12)


def test_shear_stress_from_forces_of_a_known_shear_stress():
    """Forces built from tau = 700 MPa on the shear plane (Merchant's circle, friction angle
    25 deg) give tau back; Oxley's contact length formula is positive and grows with h."""
    alpha, phi, beta, h, tau = (math.radians(15.0), math.radians(30.0), math.radians(25.0),
                                60e-6, 700e6)
    fs = tau * h / math.sin(phi)
    res = fs / math.cos(phi + beta - alpha)
    fc, ff = res * math.cos(beta - alpha), res * math.sin(beta - alpha)
    assert spc.measured_shear_stress(fc, ff, h, phi) == pytest.approx(tau, rel=1e-9)
    mat = load_material("TC4")
    r = math.cos(phi - alpha) / math.sin(phi)
    lc1 = spc.oxley_contact_length(mat, h, spc.shear_state(h, 0.1, r, alpha), alpha, fc, ff, 6)
    lc2 = spc.oxley_contact_length(mat, 2 * h, spc.shear_state(2 * h, 0.1, r, alpha), alpha,
                                   fc, ff, 6)
    assert 0 < lc1 < lc2
    # without hardening (n_eq -> 0) it is Oxley's h sin(theta) / (cos(lambda) sin(phi))
    theta = phi + beta - alpha
    assert lc1 > h * math.sin(theta) / (math.cos(beta) * math.sin(phi))


def test_boothroyd_beta_is_continuous_and_the_jc_fixed_point_holds():
    assert spc.boothroyd_beta(10.0 - 1e-12) == pytest.approx(spc.boothroyd_beta(10.0 + 1e-12),
                                                             abs=1e-9)
    assert spc.boothroyd_beta(1.0) == pytest.approx(0.5)
    mat = load_material("TC4")
    alpha = math.radians(15.0)
    h, vc, c0 = 60e-6, 5.0 / 60.0, 6.0
    st = spc.shear_state(h, vc, 1.97, alpha)
    k, temp = spc.jc_shear_flow_stress(mat, h, vc, st, c0)
    beta = spc.boothroyd_beta(mat.rho * mat.cp * vc * h / mat.k * math.tan(st["phi"]))
    assert temp == pytest.approx(mat.T_room + spc.ETA * (1 - beta) * k * st["gamma"]
                                 / (mat.rho * mat.cp), rel=1e-5)
    eps = st["gamma"] / (2 * math.sqrt(3))
    rate = c0 * st["vs"] / (math.sqrt(3) * st["l"])
    assert k == pytest.approx(mat.flow_stress(eps, rate, temp) / math.sqrt(3), rel=1e-5)


def test_rake_layer_reads_only_the_chip_layer_against_the_contact(tmp_path):
    """A constructed state: unit squares of 2 um laid along the rake line at 1 um from it
    (inside the 5 um layer) and at 8 um (outside), some beyond the contact's end. Only the
    first row within the contact is averaged, with the von Mises stress / sqrt 3."""
    import numpy as np

    rake, r = math.radians(15.0), 20e-6
    cx, cy = 0.0, -40e-6
    tx, ty = math.sin(rake), math.cos(rake)
    nx, ny = -math.cos(rake), math.sin(rake)
    sx, sy = cx - r * math.cos(rake), cy + r * math.sin(rake)
    xs, ys, conn, eps, temp, vm = [], [], [], [], [], []
    a = 1e-6  # half side
    for k, (s, n) in enumerate([(10e-6, 2e-6), (20e-6, 2e-6), (30e-6, 2e-6),  # in the layer
                                (20e-6, 9e-6),  # too far from the rake
                                (70e-6, 2e-6)]):  # beyond the contact's end
        c = (sx + s * tx + n * nx, sy + s * ty + n * ny)
        for dx, dy in ((-a, -a), (a, -a), (a, a), (-a, a)):
            xs.append(c[0] + dx)
            ys.append(c[1] + dy)
        conn.append([4 * k, 4 * k + 1, 4 * k + 2, 4 * k + 3])
        eps.append([2.0, 3.0, 4.0, 9.0, 9.0][k])
        temp.append([500.0, 600.0, 700.0, 1.0, 1.0][k])
        vm.append(math.sqrt(3.0) * 1e6 * np.array([900.0, 800.0, 700.0, 1.0, 1.0])[k])
    # contact nodes: one on the rake at s = 50 um sets the contact length
    xs.append(sx + 50e-6 * tx)
    ys.append(sy + 50e-6 * ty)
    cf = np.zeros((2, len(xs)))
    cf[0, -1] = -1.0
    f = tmp_path / "state.npz"
    np.savez(f, x=np.array(xs), y=np.array(ys), conn=np.array(conn), alive=np.ones(5, int),
             eps_p=np.array(eps), temperature_K=np.array(temp), von_mises_Pa=np.array(vm),
             tool_center=np.array([cx, cy]), contact_force_N_per_m=cf)
    assert spc.fe_contact_length(f, rake, r) == pytest.approx(50e-6, rel=1e-9)
    out = spc.fe_rake_layer(f, rake, r)
    assert out["rake_layer_elements"] == 3
    assert out["rake_layer_strain"] == pytest.approx(3.0, rel=1e-9)
    assert out["rake_layer_T_K"] == pytest.approx(600.0, rel=1e-9)
    assert out["rake_layer_tau_eq_MPa"] == pytest.approx(800.0, rel=1e-9)
