"""Virtual hammer test of any robot from its pose-dependent multibody model (SYNTHETIC), and
the equivalent model's checks that the stiffness and the modes are of one robot.

Acceptance: the test's static driving-point stiffness within 10 % of the robot's directional
stiffness at the same posture, for the IRB 6600 and for a second robot given as a TOML
(``tests/modal/data/synthetic-6r-mid.toml``, SYNTHETIC); measured exactly for the truth
(1e-9) and within 0.03 % from the modes identified from the simulated test.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.equivalent import EquivalentModel, EquivalentWarning
from robobore.errors import ConfigError
from robobore.modal.frf import estimate_frf
from robobore.modal.identify import identify_modes
from robobore.modal.virtual import EXAMPLE_POSTURE_DEG, simulate_hammer_test
from robobore.plan.virtual_hammer import robot_truth, sample_rate_for, static_stiffness
from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD as K_IRB
from robobore.robot.description import get_robot
from robobore.robot.kinematics import fk_jacobian
from robobore.robot.stiffness import compliance_matrix, process_frame

runner = CliRunner()
MID = Path(__file__).parent / "data" / "synthetic-6r-mid.toml"
MID_Q = (20.0, 30.0, 10.0, 0.0, 60.0, 0.0)
MID_K = (1.5e6, 2.0e6, 1.2e6, 2.5e5, 2.2e5, 1.5e5)
CASES = [("irb6600-175-2.55", EXAMPLE_POSTURE_DEG, K_IRB), (str(MID), MID_Q, MID_K)]


def directional(robot, q_deg, k):
    """The robot's directional stiffness by the stiffness stage's own path (Jacobian)."""
    rb = get_robot(robot)
    T, J = fk_jacobian(rb, np.radians(q_deg))
    R = process_frame(T[:3, :3], "boring")
    return 1.0 / np.diag(R.T @ compliance_matrix(J, k)[:3, :3] @ R)


@pytest.mark.parametrize("robot,q,k", CASES)
def test_static_stiffness_is_the_robots(robot, q, k):
    truth, info = robot_truth(robot, q, k)
    ks = directional(robot, q, k)
    st = static_stiffness(truth)
    np.testing.assert_allclose([st[a] for a in "xyz"], ks, rtol=1e-9)
    np.testing.assert_allclose([info["directional_stiffness_N_per_m"][a] for a in "xyz"], ks,
                               rtol=1e-9)
    assert truth.n_modes == 6 and np.all(np.diff(truth.frequencies_Hz) > 0)
    # identified from the simulated test: the modes' static stiffness within 10 %
    rec = simulate_hammer_test(truth, n_hits=5, sample_rate_Hz=sample_rate_for(truth),
                               duration_s=8.0, noise_force=0.01, noise_response=0.01, seed=1)
    fr = dataclasses.replace(estimate_frf(rec).frf,
                             output_dofs=((1, 1), (1, 2), (1, 3), (2, 1), (2, 2), (2, 3)),
                             input_dofs=((1, 1), (1, 2), (1, 3)))
    res = identify_modes(fr, band_Hz=(2.0, 150.0)).result
    assert len(res.modes) >= 5
    for d, a in enumerate("xyz"):
        kk = [m.modal_mass_kg[f"hammer_{a}"] * (2 * np.pi * m.frequency_Hz) ** 2
              for m in res.modes if f"hammer_{a}" in m.modal_mass_kg]
        k_static = 1.0 / sum(1.0 / v for v in kk)
        assert k_static == pytest.approx(ks[d], rel=0.10)


def test_cli_robot_file_test_then_modes_then_equivalent(tmp_path):
    s = tmp_path / "s.json"
    s.write_text(json.dumps({"robot": "synthetic-6r-mid",
                             "joint_stiffness_Nm_per_rad": list(MID_K)}))
    uff = tmp_path / "mid.uff"
    q = ",".join(str(v) for v in MID_Q)
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(uff), "--robot-file",
                            str(MID), f"--joints-deg={q}", "--joint-stiffness-file", str(s),
                            "--duration-s", "8", "--json"])
    assert r.exit_code == 0, r.output
    info = json.loads(r.stdout)
    ks = directional(MID, MID_Q, MID_K)
    np.testing.assert_allclose([info["static_stiffness_N_per_m"][a] for a in "xyz"], ks,
                               rtol=1e-9)
    assert info["robot"]["robot"] == "synthetic-6r-mid" and info["settings"]["sample_rate_Hz"] == 2048
    mj = tmp_path / "modes.json"
    r = runner.invoke(app, ["identify", "modes", str(uff), "--band-hz", "2", "150",
                            "--no-uncertainty", "--out", str(mj), "--json"])
    assert r.exit_code == 0, r.output
    modes = json.loads(mj.read_text())
    assert modes["robot"] == "synthetic-6r-mid" and modes["joints_deg"] == list(MID_Q)
    stiff = {"robot": "synthetic-6r-mid", "joints_deg": list(MID_Q),
             "directional_stiffness_N_per_m": dict(zip("xyz", ks.tolist(), strict=True))}
    EquivalentModel.from_stiffness_and_modes(stiff, modes)  # one robot, one posture
    with pytest.raises(ConfigError, match="different robots"):
        EquivalentModel.from_stiffness_and_modes(dict(stiff, robot="irb6600-175-2.55"), modes)
    with pytest.raises(ConfigError, match="different postures"):
        EquivalentModel.from_stiffness_and_modes(
            dict(stiff, joints_deg=[0.0, 30.0, 10.0, 0.0, 60.0, 0.0]), modes)
    sf = tmp_path / "stiff.json"
    sf.write_text(json.dumps(dict(stiff, robot="irb6600-175-2.55")))
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-file", str(sf),
                            "--modes-file", str(mj)])
    assert r.exit_code == 2 and "different robots" in " ".join(r.output.split())


def test_factor_two_warning():
    """The bundled IRB 6600 hammer modes with a stiffness 3x lower (another robot): the
    direction's mode is 3x stiffer than the direction: warned, in the notes."""
    modes = {"modes": [
        {"frequency_Hz": 6.9, "damping_ratio": 0.03, "direction": "x",
         "modal_stiffness_N_per_m": {"hammer_x": 1.75e6}},
        {"frequency_Hz": 16.8, "damping_ratio": 0.03, "direction": "y",
         "modal_stiffness_N_per_m": {"hammer_y": 1.43e6}},
        {"frequency_Hz": 24.6, "damping_ratio": 0.03, "direction": "z",
         "modal_stiffness_N_per_m": {"hammer_z": 1.25e6}}]}
    same = {"x": 1.588e6, "y": 1.306e6, "z": 1.143e6}
    em = EquivalentModel.from_stiffness_and_modes(same, modes)
    assert not any("WARNING" in n for n in em.notes)
    other = {"x": 1.588e6 / 3, "y": 1.306e6, "z": 1.143e6}
    with pytest.warns(EquivalentWarning, match="x: static stiffness"):
        em = EquivalentModel.from_stiffness_and_modes(other, modes)
    assert sum("WARNING" in n for n in em.notes) == 1


@pytest.mark.parametrize("args,words", [
    (["--robot", "irb6600-175-2.55", "--joint-stiffness-Nm-per-rad", "1,2,3,4,5,6"],
     "no posture given"),
    (["--robot", "nosuchrobot", "--joints-deg=0,0,0,0,30,0",
      "--joint-stiffness-Nm-per-rad", "1,2,3,4,5,6"], "unknown robot"),
    (["--robot", "irb6600-175-2.55", "--joints-deg=0,0,0",
      "--joint-stiffness-Nm-per-rad", "1,2,3,4,5,6"], "--joints-deg"),
])
def test_cli_robot_bad_input(tmp_path, args, words):
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(tmp_path / "x.uff")] + args)
    assert r.exit_code == 2, r.output
    assert words in " ".join(r.output.split())


def test_cli_stiffness_file_of_another_robot_is_refused(tmp_path):
    s = tmp_path / "s.json"
    s.write_text(json.dumps({"robot": "irb6600-175-2.55",
                             "joint_stiffness_Nm_per_rad": list(MID_K)}))
    r = runner.invoke(app, ["identify", "virtual-hammer-test", str(tmp_path / "x.uff"),
                            "--robot-file", str(MID), "--joints-deg=20,30,10,0,60,0",
                            "--joint-stiffness-file", str(s)])
    assert r.exit_code == 2 and "another robot" in " ".join(r.output.split())
