"""Kinematics: D-H forward kinematics, geometric Jacobian, robot library, joint limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from robobore.errors import ConfigError, InputError
from robobore.robot.description import (
    available_robots,
    check_joint_limits,
    get_robot,
    load_robot_file,
)
from robobore.robot.kinematics import (
    fk,
    fk_jacobian,
    jacobian,
    jacobian_derivative,
    rotation_vector,
)

ROBOT = "irb6600-175-2.55"
PAPER_Q_DEG = (-48.38, 54.82, 6.86, -54.16, 107.43, -21.95)


@pytest.fixture(scope="module")
def rb():
    return get_robot(ROBOT)


def test_fk_reference_positions(rb):
    """Issue 2 reference (from the ABB data sheet geometry): q = 0 -> flange (1.662, 0, 2.055) m;
    paper posture (Chen et al., seed paper) -> about (1.073, -1.441, 0.489) m. Tolerance 1 mm."""
    p0 = fk(rb, np.zeros(6))[:3, 3]
    assert np.allclose(p0, [1.662, 0.0, 2.055], atol=1e-3)
    p1 = fk(rb, np.radians(PAPER_Q_DEG))[:3, 3]
    assert np.allclose(p1, [1.073, -1.441, 0.489], atol=1e-3)
    # the tool z-axis (spindle / feed) is horizontal at the boring posture
    assert abs(fk(rb, np.radians(PAPER_Q_DEG))[2, 2]) < 0.01


def _fd_jacobian(rb, q, tcp, h=1e-6):
    T0 = fk(rb, q, tcp)
    Jn = np.zeros((6, 6))
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = h
        Tp, Tm = fk(rb, q + dq, tcp), fk(rb, q - dq, tcp)
        Jn[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        Jn[3:, i] = (rotation_vector(Tp[:3, :3] @ T0[:3, :3].T)
                     - rotation_vector(Tm[:3, :3] @ T0[:3, :3].T)) / (2 * h)
    return Jn


def test_jacobian_matches_finite_differences(rb):
    """Geometric Jacobian vs central differences of FK (position and rotation vector), at random
    postures and random tool points: 1e-6 relative to the largest entry (issue 2 acceptance)."""
    rng = np.random.default_rng(1)
    lo, hi = np.array(rb.lower_limit_rad), np.array(rb.upper_limit_rad)
    Q = rng.uniform(lo, hi, size=(20, 6))
    tcps = rng.uniform(-0.4, 0.4, size=(20, 3))
    worst = 0.0
    for q, tcp in zip(Q, tcps, strict=True):
        J = jacobian(rb, q, tcp)
        Jn = _fd_jacobian(rb, q, tcp)
        worst = max(worst, np.abs(J - Jn).max() / np.abs(J).max())
    assert worst < 1e-6, worst


def test_vectorised_equals_single(rb):
    rng = np.random.default_rng(2)
    Q = rng.uniform(-1, 1, size=(7, 6))
    T, J = fk_jacobian(rb, Q, [0.1, 0.0, 0.3])
    assert T.shape == (7, 4, 4) and J.shape == (7, 6, 6)
    for k in range(7):
        Tk, Jk = fk_jacobian(rb, Q[k], [0.1, 0.0, 0.3])
        assert np.allclose(T[k], Tk, atol=1e-14) and np.allclose(J[k], Jk, atol=1e-14)


def test_jacobian_derivative_matches_finite_differences(rb):
    """Analytic dJ/dq_i (used by CCT) vs central differences of J; 1e-6 relative."""
    q = np.radians(PAPER_Q_DEG)
    tcp = [0.05, -0.1, 0.35]
    dJ = jacobian_derivative(rb, q, tcp)
    h = 1e-6
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = h
        num = (jacobian(rb, q + dq, tcp) - jacobian(rb, q - dq, tcp)) / (2 * h)
        assert np.abs(dJ[i] - num).max() < 1e-6 * np.abs(jacobian(rb, q, tcp)).max()


def test_joint_limit_error_names_joint_value_and_limit(rb):
    q = np.radians([0, 85, 0, 0, 0, 0])
    with pytest.raises(InputError) as ei:
        check_joint_limits(rb, q, file="c.csv", rows=[7])
    msg = str(ei.value)
    assert "joint 2" in msg and "85" in msg and "[-65, 80] deg" in msg
    assert "c.csv" in msg and "row 7" in msg and "q2_deg" in msg
    check_joint_limits(rb, np.radians(PAPER_Q_DEG))  # inside: no error


def test_unknown_robot_lists_library():
    with pytest.raises(ConfigError) as ei:
        get_robot("no-such-robot")
    assert "no-such-robot" in str(ei.value) and ROBOT in str(ei.value)


def test_user_robot_file_and_library_dir(tmp_path, monkeypatch, rb):
    d = rb.to_dict()
    d["name"] = "my-robot"
    lines = [f"{k} = {v!r}" if isinstance(v, str) else f"{k} = {list(map(float, v))}"
             for k, v in d.items()]
    text = "\n".join(x.replace("'", '"') for x in lines) + "\n"
    f = tmp_path / "my-robot.toml"
    f.write_text(text)
    r2 = load_robot_file(f)
    assert np.allclose(fk(r2, np.radians(PAPER_Q_DEG)), fk(rb, np.radians(PAPER_Q_DEG)))
    assert get_robot(str(f)).name == "my-robot"
    monkeypatch.setenv("ROBOBORE_ROBOT_PATH", str(tmp_path))
    assert "my-robot" in available_robots()
    assert get_robot("my-robot").name == "my-robot"


def test_bad_robot_file_names_key(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text('name = "b"\nd_m = [0.1, 0.2]\na_m = [0, 0]\nalpha_deg = [0, "x"]\n'
                 'theta_offset_deg = [0, 0]\nlower_limit_deg = [-1, -1]\n'
                 'upper_limit_deg = [1, 1]\n')
    with pytest.raises(ConfigError) as ei:
        load_robot_file(f)
    assert "alpha_deg" in str(ei.value) and "bad.toml" in str(ei.value)
    f.write_text('name = "b"\nd_m = [0.1, 0.2]\na_m = [0]\nalpha_deg = [0, 0]\n'
                 'theta_offset_deg = [0, 0]\nlower_limit_deg = [-1, -1]\n'
                 'upper_limit_deg = [1, 1]\n')
    with pytest.raises(ConfigError, match="a_m") as ei:
        load_robot_file(f)
    assert "bad.toml" in str(ei.value)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3),
       st.floats(0.0, math.pi * 0.999))
def test_rotation_vector_matches_scipy(axis, angle):
    a = np.asarray(axis)
    if np.linalg.norm(a) < 1e-3:
        a = np.array([0.0, 0.0, 1.0])
    rv = a / np.linalg.norm(a) * angle
    R = Rotation.from_rotvec(rv).as_matrix()
    assert np.allclose(rotation_vector(R), rv, atol=1e-9)


def test_inverse_kinematics_round_trip(rb):
    """IK (damped least squares) from a nearby start reaches the FK pose of a known posture
    to 1e-10 m / rad, and an unreachable target raises NumericalError."""
    from robobore.errors import NumericalError
    from robobore.robot.kinematics import inverse_kinematics

    rng = np.random.default_rng(3)
    q_true = np.radians(PAPER_Q_DEG)
    tcp = [0.1, 0.0, 0.35]
    T = fk(rb, q_true, tcp)
    q = inverse_kinematics(rb, T, q_true + rng.normal(scale=0.05, size=6), tcp)
    T2 = fk(rb, q, tcp)
    assert np.abs(T2[:3, 3] - T[:3, 3]).max() < 1e-10
    assert np.linalg.norm(rotation_vector(T2[:3, :3] @ T[:3, :3].T)) < 1e-10
    far = T.copy()
    far[:3, 3] = [10.0, 0.0, 0.0]
    with pytest.raises(NumericalError):
        inverse_kinematics(rb, far, q_true, tcp, max_iter=50)
