"""The bundled SYNTHETIC campaign and hammer test are one virtual robot.

The campaign (data/campaign_irb6600, ground-truth joint stiffness) and the hammer test
(data/hammer_test, :func:`robobore.modal.virtual.robot_boring_truth`) describe the same tool
point at the paper's posture: the modal model's static driving-point stiffness
``1 / H_dd(0) = 1 / sum_r phi_dr^2 / w_r^2`` is the campaign's directional stiffness. The
identification of both bundled files recovers it.
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.modal.virtual import robot_boring_truth, tool_point_compliance, truth_table
from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD
from robobore.robot.description import get_robot
from robobore.robot.stiffness import directional_stiffness_xyz
from robobore.study import paper as pp
from robobore.study import paper_config as pc


def test_truth_static_stiffness_is_the_campaign_robot():
    cfg, _, _ = pc.load_paper_config()
    k_dir = directional_stiffness_xyz(get_robot(cfg.robot.name),
                                      np.radians(cfg.robot.posture_deg),
                                      IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD,
                                      frame="boring", tcp_m=cfg.robot.tcp_m)
    t = truth_table(robot_boring_truth())
    for a in "xyz":
        assert t["static_stiffness_N_per_m"][a] == pytest.approx(k_dir[a], rel=1e-9)
    # the full 3x3 tool-point compliance, not only its diagonal
    truth = robot_boring_truth()
    w = 2 * np.pi * truth.frequencies_Hz
    C_modal = (truth.phi_in / w) @ (truth.phi_in / w).T
    np.testing.assert_allclose(C_modal, tool_point_compliance(), rtol=1e-9)
    # modes 1, 2, 3 are dominated by X, Y, Z and carry most of that direction's compliance
    share = np.array(t["compliance_share"])
    assert np.all(np.diag(share[:, :3]) > 0.85)
    assert list(np.argmax(share, axis=1)) == [0, 1, 2]


def test_identification_recovers_one_robot():
    """identify stiffness (campaign) and identify modes (hammer test) on the bundled files:
    per direction the hammer test's driving-point stiffness from the identified modes
    agrees with the campaign's identified directional stiffness within 10 % (measured:
    -1.4, -0.8, -1.2 %), so does the modal stiffness of the direction's own mode (+8.8, +9.4,
    +8.9 %), and the identified values match the ground truth within 3 %."""
    cfg, _, path = pc.load_paper_config()
    st = pp.identify_stiffness(cfg, path)["directional_stiffness_N_per_m"]
    modes = pp.identify_modes(cfg, path)["modes"]
    truth = truth_table(robot_boring_truth())
    for d, a in enumerate("xyz"):
        key = f"hammer_{a}"
        k_modes = [m["modal_stiffness_N_per_m"][key] for m in modes]
        k_static = 1.0 / sum(1.0 / k for k in k_modes)
        assert k_static == pytest.approx(st[a], rel=0.10)
        assert k_static == pytest.approx(truth["static_stiffness_N_per_m"][a], rel=0.03)
        dom = next(m for m in modes if m["direction"] == a)
        # the mode of that direction alone: stiffer by the compliance the other modes carry
        # (the tool point is coupled), still within 10 % of the campaign's
        assert dom["modal_stiffness_N_per_m"][key] == pytest.approx(st[a], rel=0.10)
        assert dom["modal_stiffness_N_per_m"][key] == pytest.approx(
            truth["modal_stiffness_N_per_m"][d][d], rel=0.03)
