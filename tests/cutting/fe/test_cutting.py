"""Orthogonal cutting on a coarse, short setting (CI budget), tool on springs.

Reference data: ../shared/data/ti64_orthogonal_cutting_forces.json (Ducobu, Pantale et al.
2022): h = 60 um, vc = 30 m/min: Fc = 118.23 N/mm, Ff = 50.3 N/mm, chip ratio 1.23.
Coarse setting: 20 um elements (h/3), 0.3 mm of cut, averaging over its last 50 %.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

FC_MEAS, FF_MEAS, R_MEAS = 118.23, 50.3, 1.23
BASE = {
    "parameters": "a_priori",
    "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
    "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
            "length_mm": 0.3, "width_mm": 1.0},
    "contact": {"friction": 0.18},
    "mesh": {"element_size_um": 20.0, "frame": "workpiece"},
    "solver": {"mass_scaling": 100.0, "n_samples": 150, "heat_conduction": False},
}
SUPPORT = {"stiffness_N_per_m": 1.0e7, "damping_N_s_per_m": 95.0, "mass_kg": 0.0025}


@pytest.fixture(scope="module")
def rigid():
    return simulate_orthogonal(parse_config(copy.deepcopy(BASE)))


@pytest.fixture(scope="module")
def supported():
    d = copy.deepcopy(BASE)
    d["tool_support"] = dict(SUPPORT)
    return simulate_orthogonal(parse_config(d))


def test_energy_balance_and_no_nan(rigid):
    s = rigid.summary
    assert s.energy_error < 0.05  # acceptance: energy balance error < 5 %
    for k, v in rigid.history.items():
        assert np.all(np.isfinite(v)), k
    # plastic work dominates the external work in cutting; hourglass stays a small share
    assert 0.6 < s.energy_plastic_J_per_m / s.energy_external_J_per_m < 1.0
    assert s.hourglass_fraction < 0.10
    # a chip forms (heated by plastic work) and the separation layer erodes
    assert s.peak_temperature_K > 600.0
    assert s.eroded_damage > 5


def test_work_equals_force_times_distance(rigid):
    """External work = integral of Fc over the tool path (the tool moves only along x)."""
    h = rigid.history
    w = np.trapezoid(h["cutting_force_N_per_mm"] * 1e3, h["cut_length_mm"] * 1e-3)
    assert w == pytest.approx(h["energy_external_J_per_m"][-1], rel=0.05)


def test_chip_ratio_within_measured_band(rigid):
    """Acceptance: chip ratio within the measured value +-30 % (1.23 at 60 um, 30 m/min)."""
    r = rigid.summary.chip_ratio
    assert math.isfinite(r)
    assert abs(r - R_MEAS) <= 0.3 * R_MEAS
    phi = rigid.summary.shear_angle_deg
    assert phi == pytest.approx(math.degrees(math.atan2(math.cos(math.radians(15)),
                                                        r - math.sin(math.radians(15)))))


@pytest.mark.xfail(strict=True, reason="known shortfall (docs/fe.md): the separation-layer "
                   "model under-predicts Fc by ~20 % and Ff by ~75 % at this point")
def test_forces_within_acceptance(rigid):
    """Issue 5 acceptance: Fc within 10 %, Ff within 35 % of the measurement."""
    s = rigid.summary
    assert abs(s.cutting_force_N_per_mm - FC_MEAS) <= 0.10 * FC_MEAS
    assert abs(s.feed_force_N_per_mm - FF_MEAS) <= 0.35 * FF_MEAS


def test_tool_support_mean_deflection_is_force_over_stiffness(supported):
    s = supported.summary
    k = SUPPORT["stiffness_N_per_m"]
    # mean of m u'' + c u' + k u = F over the window: k <u> = <F> (to the residual
    # oscillation of the decaying transient)
    width_mm = BASE["cut"]["width_mm"]
    assert s.tool_support.tool_dx_mean_um == pytest.approx(
        s.cutting_force_N_per_mm * width_mm / k * 1e6, rel=0.05)
    sup = s.tool_support
    assert sup.tool_dx_mean_um == pytest.approx(sup.tool_dx_static_um, rel=0.05)


def test_tool_vibration_changes_forces(rigid, supported):
    hr = rigid.history
    hs = supported.history
    # the tool is pushed back and overshoots (damping ratio 0.3: ~37 % overshoot) ...
    static = supported.summary.tool_support.tool_dx_static_um
    assert np.max(hs["tool_dx_um"]) > 1.1 * static
    # ... which changes the force history compared with the rigidly guided tool
    n = min(len(hr["time_s"]), len(hs["time_s"]))
    diff = np.abs(hs["cutting_force_N_per_mm"][:n] - hr["cutting_force_N_per_mm"][:n])
    assert np.max(diff) > 0.1 * rigid.summary.cutting_force_N_per_mm


def test_force_by_face_sums_to_the_total(rigid):
    """The rake / edge / flank split (quad.node_contact.contact_split) adds up to the tool force
    in every sample (same per-node forces, summed in another order: 1e-9 relative)."""
    h = rigid.history
    for comp in ("cutting", "feed"):
        parts = sum(h[f"{face}_{comp}_force_N_per_mm"] for face in ("rake", "edge", "flank"))
        tot = h[f"{comp}_force_N_per_mm"]
        assert np.allclose(parts, tot, rtol=1e-9, atol=1e-9 * np.max(np.abs(tot)))
    f = rigid.summary.force_by_face_N_per_mm
    # with rake 15 deg and mu 0.18 the rake face pulls the tool into the work (feed < 0,
    # N (mu cos a - sin a) < 0); the edge arc pushes it out (feed > 0); both resist the cut
    assert f.rake.feed < 0.0
    assert f.edge.feed > 0.0
    assert f.rake.cutting > 0.0 and f.edge.cutting > 0.0


def test_contact_split_classifies_by_face():
    """Nodes placed on the rake face, the edge arc and the flank of a tool with rake 15 deg,
    clearance 2 deg, r = 20 um at the origin: each force lands in its face's slot."""
    from robobore.cutting.fe.quad.node_contact import contact_split

    r = 20e-6
    rake, clr = math.radians(15.0), math.radians(2.0)
    nrx, nry = -math.cos(rake), math.sin(rake)
    nfx, nfy = math.sin(clr), -math.cos(clr)
    trx, try_ = nry, -nrx  # up the rake face
    tfx, tfy = -nfy, nfx  # back along the flank
    pts = [  # (x, y, face index)
        (r * nrx + 30e-6 * trx, r * nry + 30e-6 * try_, 0),  # on the rake face
        (0.0, -r, 1),  # lowest point of the arc
        (-r * math.sqrt(0.5), -r * math.sqrt(0.5), 1),  # front of the arc
        (r * nfx + 25e-6 * tfx, r * nfy + 25e-6 * tfy, 2),  # on the flank
    ]
    n = len(pts) + 1  # one node without contact
    x = np.zeros(n)
    y = np.full(n, -1.0)
    cfx = np.zeros(n)
    cfy = np.zeros(n)
    for i, (px, py, _) in enumerate(pts):
        x[i], y[i] = px, py
        cfx[i], cfy[i] = 1.0 + i, 10.0 * (1.0 + i)
    out = np.zeros(6)
    contact_split(cfx, cfy, x, y, (0.0, 0.0, nrx, nry, nfx, nfy), out)
    want = np.zeros(6)
    for i, (_, _, k) in enumerate(pts):
        want[2 * k] -= cfx[i]
        want[2 * k + 1] -= cfy[i]
    assert np.array_equal(out, want)
