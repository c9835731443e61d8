"""Stiffness model: compliance / Cartesian / directional / principal stiffness, CCT, frames."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.errors import IdentificationError, InputError, NumericalError
from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD as K_TRUE
from robobore.robot.campaign import deflect
from robobore.robot.description import get_robot
from robobore.robot.kinematics import fk, fk_jacobian, rotation_vector
from robobore.robot.stiffness import (
    JointStiffness,
    cartesian_stiffness,
    complementary_stiffness,
    compliance_matrix,
    directional_stiffness,
    directional_stiffness_xyz,
    principal_stiffness,
    process_frame,
    stiffness_at,
)

PAPER_Q = np.radians([-48.38, 54.82, 6.86, -54.16, 107.43, -21.95])


@pytest.fixture(scope="module")
def rb():
    return get_robot("irb6600-175-2.55")


def test_identity_jacobian_hand_calculation():
    """J = I: C = diag(1/k), K = diag(k), k along x = k1; along (1,1,0)/sqrt2:
    1/(0.5/k1 + 0.5/k2) (hand calculation)."""
    k = np.array([1.0, 2.0, 4.0, 8.0, 16.0, 32.0])
    C = compliance_matrix(np.eye(6), k)
    assert np.allclose(C, np.diag(1 / k))
    assert np.allclose(cartesian_stiffness(np.eye(6), k), np.diag(k))
    assert directional_stiffness(C, [1, 0, 0]) == pytest.approx(1.0)
    assert directional_stiffness(C, [1, 1, 0]) == pytest.approx(1 / (0.5 / 1 + 0.5 / 2))


def test_compliance_is_inverse_of_stiffness(rb):
    _, J = fk_jacobian(rb, PAPER_Q, [0, 0, 0.3])
    C = compliance_matrix(J, K_TRUE)
    K = cartesian_stiffness(J, K_TRUE)
    assert np.allclose(C @ K, np.eye(6), atol=1e-9)


def test_directional_stiffness_is_force_over_deflection(rb):
    """k_u = 1/(u^T C_tt u) is the force along u divided by the deflection along u when only a
    force along u is applied (deflections from the joint-spring model, linear)."""
    _, J = fk_jacobian(rb, PAPER_Q)
    u = np.array([0.3, -0.5, 0.8])
    u /= np.linalg.norm(u)
    F = 1000.0 * u
    dq = (J.T @ np.concatenate([F, np.zeros(3)])) / np.asarray(K_TRUE)
    dx = J @ dq
    assert directional_stiffness(compliance_matrix(J, K_TRUE), u) == pytest.approx(
        1000.0 / (u @ dx[:3]), rel=1e-12)


def test_principal_directions(rb):
    _, J = fk_jacobian(rb, PAPER_Q)
    C = compliance_matrix(J, K_TRUE)
    kp, V = principal_stiffness(C)
    assert np.allclose(V.T @ V, np.eye(3), atol=1e-12) and np.linalg.det(V) > 0
    assert kp[0] >= kp[1] >= kp[2] > 0
    for i in range(3):
        assert directional_stiffness(C, V[:, i]) == pytest.approx(kp[i], rel=1e-10)


def test_cct_matches_finite_difference_tangent(rb):
    """Chen & Kao (2000) CCT: K_C = J^-T (Ktheta - K_G) J^-1 with W the external wrench on the
    robot. Reference: the tangent of the nonlinear equilibrium diag(k) dq = J(q+dq)^T W computed
    by central differences of the force (deflect(), Newton-converged). To make K_G matter, soft
    joints (k/10) and a 15 kN load (joint deflections ~0.02 rad); tolerance 1e-4 relative on
    the translational compliance, while the unloaded K is off by more than 1 % (so the test
    can fail)."""
    k = np.asarray(K_TRUE) / 10.0
    tcp = np.array([0.0, 0.0, 0.4])
    F0 = np.array([-1.0e4, 0.5e4, -1.0e4])
    dq0 = deflect(rb, PAPER_Q, k, F0, tcp)
    q1 = PAPER_Q + dq0
    h = 20.0
    Cn = np.zeros((3, 3))
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        pp = fk(rb, PAPER_Q + deflect(rb, PAPER_Q, k, F0 + e, tcp), tcp)[:3, 3]
        pm = fk(rb, PAPER_Q + deflect(rb, PAPER_Q, k, F0 - e, tcp), tcp)[:3, 3]
        Cn[:, j] = (pp - pm) / (2 * h)
    KC = complementary_stiffness(rb, q1, k, np.concatenate([F0, np.zeros(3)]), tcp)
    C_cct = np.linalg.inv(KC)[:3, :3]
    _, J1 = fk_jacobian(rb, q1, tcp)
    C_plain = compliance_matrix(J1, k)[:3, :3]
    scale = np.abs(Cn).max()
    assert np.abs(C_cct - Cn).max() / scale < 1e-4
    assert np.abs(C_plain - Cn).max() / scale > 1e-2
    # zero load: CCT = plain Cartesian stiffness
    assert np.allclose(complementary_stiffness(rb, PAPER_Q, k, np.zeros(6), tcp),
                       cartesian_stiffness(fk_jacobian(rb, PAPER_Q, tcp)[1], k), rtol=1e-10)


def test_process_frames(rb):
    T = fk(rb, PAPER_Q)
    Rb = process_frame(T[:3, :3], "boring")
    assert np.allclose(Rb.T @ Rb, np.eye(3)) and np.linalg.det(Rb) > 0
    assert np.allclose(Rb[:, 2], T[:3, 2])  # Z = feed = tool z
    assert abs(Rb[2, 0]) < 1e-12  # X horizontal
    assert Rb[2, 1] > 0.99  # Y vertical (up) because the bore axis is horizontal here
    assert np.allclose(process_frame(T[:3, :3], "tool"), T[:3, :3])
    with pytest.raises(InputError):
        process_frame(T[:3, :3], np.diag([1.0, 1.0, -1.0]))


def test_directional_xyz_frames_consistent(rb):
    d_tool = directional_stiffness_xyz(rb, PAPER_Q, K_TRUE, frame="tool")
    T = fk(rb, PAPER_Q)
    d_user = directional_stiffness_xyz(rb, PAPER_Q, K_TRUE, frame=T[:3, :3])
    assert d_tool == pytest.approx(d_user, rel=1e-12)
    res = stiffness_at(rb, PAPER_Q, K_TRUE, frame="base")
    assert res.directional_stiffness_N_per_m == pytest.approx(
        res.directional_stiffness_base_N_per_m)


def test_joint_stiffness_roundtrip_and_unidentified_joint(rb):
    js = JointStiffness("irb6600-175-2.55", (3e6, 4e6, 2.5e6, 5e5, 4.5e5, None),
                        std_Nm_per_rad=(1e4, 1e4, 1e4, 1e3, 1e3, None),
                        status=("identified",) * 5 + ("unidentifiable",), synthetic=True)
    assert JointStiffness.from_dict(js.to_dict()) == js
    with pytest.raises(IdentificationError, match="joint"):
        js.as_array()
    # joint 6 does not move a tool point on its own axis: z-direction stiffness still defined
    d = directional_stiffness_xyz(rb, PAPER_Q, js, frame="tool", tcp_m=[0, 0, 0.3])
    full = directional_stiffness_xyz(rb, PAPER_Q, list(K_TRUE[:5]) + [1e30], frame="tool",
                                     tcp_m=[0, 0, 0.3])
    for a in "xyz":
        assert d[a] == pytest.approx(full[a], rel=1e-9)
    # an off-axis tool point is moved by joint 6 -> unknown -> None (not a made-up number)
    d2 = directional_stiffness_xyz(rb, PAPER_Q, js, frame="tool", tcp_m=[0.1, 0, 0.3])
    assert d2["x"] is None or d2["y"] is None
    with pytest.raises(InputError, match="joint_stiffness_Nm_per_rad"):
        JointStiffness.from_dict({"joint_stiffness_Nm_per_rad": [1, "a"]})


def test_bad_stiffness_and_singular_posture(rb):
    with pytest.raises(InputError):
        compliance_matrix(np.eye(6), [1, 2, 3, 4, 5, -6])
    _, J = fk_jacobian(rb, np.radians([0, 0, 0, 0, 0, 0]))  # q5 = 0: wrist singular
    with pytest.raises(NumericalError, match="singular"):
        cartesian_stiffness(J, K_TRUE)


def test_rotation_vector_small_angle_consistency(rb):
    R = fk(rb, PAPER_Q + 1e-7)[:3, :3] @ fk(rb, PAPER_Q)[:3, :3].T
    assert np.linalg.norm(rotation_vector(R)) < 1e-6


def test_directional_map_matches_single_posture(rb):
    from robobore.robot.stiffness import directional_stiffness_map

    rng = np.random.default_rng(5)
    Q = PAPER_Q + rng.normal(scale=0.2, size=(5, 6))
    for frame in ("tool", "base", "boring"):
        M = directional_stiffness_map(rb, Q, K_TRUE, frame=frame, tcp_m=[0, 0, 0.3])
        for i in range(5):
            d = directional_stiffness_xyz(rb, Q[i], K_TRUE, frame=frame, tcp_m=[0, 0, 0.3])
            assert np.allclose(M[i], [d["x"], d["y"], d["z"]], rtol=1e-12)
