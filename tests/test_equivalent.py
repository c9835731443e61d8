"""Equivalent mass-spring-damper model (paper eq. 1-3) against hand calculations."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robobore.equivalent import EquivalentModel, PressureFoot, assign_modes, principal_frame
from robobore.errors import ConfigError

STIFF = {"directional_stiffness_N_per_m": {"x": 1.2e6, "y": 0.9e6, "z": 1.5e6}}
MODES = {"modes": [
    {"frequency_Hz": 6.9, "damping_ratio": 0.035, "mpc": 0.9},
    {"frequency_Hz": 16.8, "damping_ratio": 0.028, "mpc": 0.9},
    {"frequency_Hz": 24.6, "damping_ratio": 0.020, "mpc": 0.9},
    {"frequency_Hz": 25.34, "damping_ratio": 0.022, "mpc": 0.9},
    {"frequency_Hz": 47.5, "damping_ratio": 0.050, "mpc": 0.9},
]}


def test_mass_and_damping_hand_calculation():
    """m = k / wn^2 and c = 2 zeta sqrt(k m) (paper eq. 3), default mode i -> axis i."""
    em = EquivalentModel.from_stiffness_and_modes(STIFF, MODES)
    wn = 2 * math.pi * 6.9
    m = 1.2e6 / wn**2
    assert em.mass_kg["x"] == pytest.approx(m, rel=1e-12)
    assert em.damping_N_s_per_m["x"] == pytest.approx(2 * 0.035 * math.sqrt(1.2e6 * m), rel=1e-12)
    assert em.frequency_Hz["z"] == 24.6
    assert "default" in em.notes[0]


def test_given_damping_coefficient_implies_tiny_ratio():
    """The paper's c = 23.7 N s/m gives zeta = c / (2 sqrt(k m)) -- about 1e-4 for a robot."""
    em = EquivalentModel.from_stiffness_and_modes(STIFF, MODES, damping_N_s_per_m=23.7)
    m = 1.2e6 / (2 * math.pi * 6.9) ** 2
    assert em.damping_ratio["x"] == pytest.approx(23.7 / (2 * math.sqrt(1.2e6 * m)), rel=1e-12)
    assert em.damping_ratio["x"] < 1e-3


def test_assignment_by_direction_and_by_mapping():
    modes = {"modes": [
        {"frequency_Hz": 10.0, "damping_ratio": 0.02, "direction": [0.1, 0.9, 0.1]},
        {"frequency_Hz": 12.0, "damping_ratio": 0.03, "direction": "z"},
        {"frequency_Hz": 20.0, "damping_ratio": 0.04, "shape": [0.8, 0.2, 0.0]},
    ]}
    em = EquivalentModel.from_stiffness_and_modes(STIFF, modes)
    assert em.frequency_Hz == {"x": 20.0, "y": 10.0, "z": 12.0}
    chosen, how = assign_modes(MODES["modes"], {"x": 4, "y": 0, "z": 1})
    assert chosen == {"x": 4, "y": 0, "z": 1} and "user" in how
    with pytest.raises(ConfigError, match="assignment.x"):
        assign_modes(MODES["modes"], {"x": 9, "y": 0, "z": 1})


def test_roundtrip_and_modes_contract():
    em = EquivalentModel.from_stiffness_and_modes(STIFF, MODES, foot=PressureFoot())
    em2 = EquivalentModel.from_dict(em.to_dict())
    assert em2.stiffness_N_per_m == em.stiffness_N_per_m
    assert em2.damping_ratio == em.damping_ratio
    modes = em.tool_point_modes()
    assert len(modes) == 3 and modes[2]["direction"] == [0.0, 0.0, 1.0]


def test_pressure_foot_stiffens_normal_direction():
    """Foot force p A; Hertz k_n = (6 F E*^2 R)^(1/3); tangential mu F / delta (hand calc)."""
    foot = PressureFoot(pressure_Pa=0.3e6, piston_area_m2=2e-3)
    assert foot.force_N == pytest.approx(600.0)
    assert foot.normal_stiffness() == pytest.approx((6 * 600 * 2e9**2 * 0.1) ** (1 / 3))
    assert foot.tangential_stiffness() == pytest.approx(0.3 * 600 / 20e-6)
    bare = EquivalentModel.from_stiffness_and_modes(STIFF, MODES)
    em = EquivalentModel.from_stiffness_and_modes(STIFF, MODES, foot=foot)
    assert em.stiffness_N_per_m["z"] == pytest.approx(1.5e6 + foot.normal_stiffness())
    assert em.stiffness_N_per_m["x"] == pytest.approx(1.2e6 + foot.tangential_stiffness())
    assert em.mass_kg["z"] == pytest.approx(bare.mass_kg["z"])  # mass unchanged
    assert em.frequency_Hz["z"] > bare.frequency_Hz["z"]


def test_principal_frame_is_rotation():
    rng = np.random.default_rng(1)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    K = q @ np.diag([1e6, 2e6, 3e6]) @ q.T
    k, R = principal_frame(K)
    assert np.allclose(k, [1e6, 2e6, 3e6])
    assert np.isclose(np.linalg.det(R), 1.0)
    assert np.allclose(R @ np.diag(k) @ R.T, K)
    with pytest.raises(ConfigError, match="positive definite"):
        principal_frame(-K)


@pytest.mark.parametrize("bad, key", [
    ({"directional_stiffness_N_per_m": {"x": -1.0, "y": 1e6, "z": 1e6}}, "stiffness_N_per_m.x"),
    ({"directional_stiffness_N_per_m": {"x": 1e6, "z": 1e6}}, "stiffness_N_per_m.y"),
    ({"stiffness": {}}, "directional_stiffness_N_per_m"),
])
def test_bad_stiffness_names_key(bad, key):
    with pytest.raises(ConfigError) as ei:
        EquivalentModel.from_stiffness_and_modes(bad, MODES)
    assert ei.value.field == key


def test_bad_mode_names_key():
    with pytest.raises(ConfigError) as ei:
        EquivalentModel.from_stiffness_and_modes(STIFF, {"modes": [{"frequency_Hz": -2}] * 3})
    assert ei.value.field == "modes[0].frequency_Hz"


def test_principal_frame_from_stiffness_matrix():
    """Equal masses: the units act along the stiffness-matrix eigenvectors (a frame rotation);
    a mode whose direction lies along the softest principal axis is assigned to it."""
    c, s_ = np.cos(np.radians(30)), np.sin(np.radians(30))
    R = np.array([[c, -s_, 0], [s_, c, 0], [0, 0, 1.0]])
    K = R @ np.diag([1e6, 2e6, 3e6]) @ R.T
    modes = {"modes": [
        {"frequency_Hz": 30.0, "damping_ratio": 0.02, "direction": [0.0, 0.0, 1.0]},
        {"frequency_Hz": 12.0, "damping_ratio": 0.03, "direction": list(R[:, 0])},
        {"frequency_Hz": 20.0, "damping_ratio": 0.04, "direction": list(R[:, 1])},
    ]}
    em = EquivalentModel.from_stiffness_and_modes({"stiffness_matrix_N_per_m": K.tolist()}, modes)
    assert em.stiffness_N_per_m["x"] == pytest.approx(1e6)
    assert em.frequency_Hz == {"x": 12.0, "y": 20.0, "z": 30.0}
    D = em.directions()
    assert abs(D[0] @ R[:, 0]) == pytest.approx(1.0)
    assert np.allclose(em.tool_point_modes()[0]["direction"], D[0])


def test_mode_outside_the_files_identification_band_is_refused():
    """A modes JSON from `identify modes --json` carries its band: a mode far outside it is
    a value scaled by hand (here kHz for Hz), not an identified mode."""
    stiff = {"directional_stiffness_N_per_m": {"x": 3e6, "y": 2.5e6, "z": 4e6}}
    modes = {"band_Hz": [3.0, 60.0],
             "modes": [{"frequency_Hz": f, "damping_ratio": 0.03} for f in (6.9, 16.8, 24.6)]}
    EquivalentModel.from_stiffness_and_modes(stiff, modes)
    modes["modes"][1]["frequency_Hz"] = 16800.0
    with pytest.raises(ConfigError, match=r"modes\[1\]\.frequency_Hz.*outside the band.*"
                       r"3 \.\. 60 Hz"):
        EquivalentModel.from_stiffness_and_modes(stiff, modes)
    del modes["band_Hz"]  # no band recorded: only the general frequency range applies
    EquivalentModel.from_stiffness_and_modes(stiff, modes)
