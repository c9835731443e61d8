"""Identity checks where files meet: stiffness + modes -> equivalent model, the planner's
identification files; the equivalent model's physical checks; the vertical bore."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.equivalent import EquivalentModel
from robobore.errors import ConfigError

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"


def _json(args):
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


@pytest.fixture(scope="module")
def bundled(tmp_path_factory):
    d = tmp_path_factory.mktemp("bundled")
    s = d / "s.json"
    s.write_text(json.dumps(_json(["identify", "stiffness", "--example", "--json"])))
    m = d / "m.json"
    m.write_text(json.dumps(_json(["identify", "modes", "--example", "--json"])))
    return d, s, m


def test_modes_record_the_hammer_tests_identity(bundled):
    _, _, m = bundled
    idn = json.loads(m.read_text())["identity"]
    assert idn["robot"] == "irb6600-175-2.55" and idn["synthetic"] is True
    assert np.allclose(idn["joints_deg"], [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95])


def test_equivalent_model_carries_the_merged_identity(bundled):
    _, s, m = bundled
    d = _json(["model", "equivalent", "--stiffness-file", str(s), "--modes-file", str(m),
               "--json"])
    assert d["identity"]["robot"] == "irb6600-175-2.55" and d["identity"]["synthetic"] is True
    assert not any("could not be checked" in n for n in d["notes"])
    em = EquivalentModel.from_dict(d)
    assert em.identity["robot"] == "irb6600-175-2.55"


def _mutated(src: Path, dst: Path, **identity):
    d = json.loads(src.read_text())
    d["identity"].update(identity)
    dst.write_text(json.dumps(d))
    return dst


def test_stiffness_and_modes_of_different_robots_refused(bundled, tmp_path):
    _, s, m = bundled
    other = _mutated(s, tmp_path / "other.json", robot="kr240-r2900", robot_hash="0" * 16)
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-file", str(other),
                            "--modes-file", str(m)])
    assert r.exit_code == 2, r.output
    out = " ".join(r.output.split())
    assert str(other) in out and str(m) in out and "kr240-r2900" in out
    assert "irb6600-175-2.55" in out


def test_stiffness_and_modes_of_different_postures_refused(bundled, tmp_path):
    _, s, m = bundled
    moved = _mutated(m, tmp_path / "moved.json", joints_deg=[0, 10, 20, 0, 30, 0])
    with pytest.raises(ConfigError, match="posture"):
        EquivalentModel.from_stiffness_and_modes(json.loads(s.read_text()),
                                                 json.loads(moved.read_text()),
                                                 names=(str(s), str(moved)))


def test_lobes_with_model_files_of_different_robots_refused(bundled, tmp_path):
    _, s, m = bundled
    other = _mutated(s, tmp_path / "other.json", robot="kr240-r2900", robot_hash="0" * 16)
    r = runner.invoke(app, ["lobes", str(EX / "boring_process.toml"), "--stiffness-file",
                            str(other), "--modes-file", str(m), "--method", "frequency"])
    assert r.exit_code == 2, r.output
    assert "kr240-r2900" in " ".join(r.output.split())


def test_old_files_without_identity_give_a_note(bundled, tmp_path):
    _, s, m = bundled
    d = json.loads(m.read_text())
    del d["identity"]
    old = tmp_path / "old_modes.json"
    old.write_text(json.dumps(d))
    em = EquivalentModel.from_stiffness_and_modes(json.loads(s.read_text()), d,
                                                  names=(str(s), str(old)))
    assert any(str(old) in n and "could not be checked" in n for n in em.notes)


def test_equivalent_model_zero_damping_and_bad_mass_refused(bundled):
    _, s, m = bundled
    d = _json(["model", "equivalent", "--stiffness-file", str(s), "--modes-file", str(m),
               "--json"])
    z = json.loads(json.dumps(d))
    z["damping_ratio"]["x"] = 0.0
    with pytest.raises(ConfigError, match="zero damping"):
        EquivalentModel.from_dict(z)
    w = json.loads(json.dumps(d))
    w["frequency_Hz"]["y"] *= 2 * math.pi  # rad/s given as Hz: the mass no longer fits
    with pytest.raises(ConfigError, match="rad/s"):
        EquivalentModel.from_dict(w)


def test_plan_refuses_another_robots_stiffness(tmp_path):
    from robobore.plan.config import load_plan_config

    shutil.copytree(EX / "plan_paper_bore", tmp_path / "plan_paper_bore")
    s = tmp_path / "plan_paper_bore" / "joint_stiffness.json"
    d = json.loads(s.read_text())
    d["identity"] = {"kind": "joint stiffness", "robot": "kr240-r2900",
                     "robot_hash": "0" * 16}
    s.write_text(json.dumps(d))
    cfg = (EX / "plan_paper_bore.toml").read_text().replace(
        '"../src/robobore', f'"{REPO}/src/robobore')
    (tmp_path / "p.toml").write_text(cfg)
    with pytest.raises(ConfigError, match="identified for kr240-r2900"):
        load_plan_config(tmp_path / "p.toml")


def test_plan_accepts_a_vertical_bore_and_refuses_a_tiny_rotation_step(tmp_path):
    from robobore.plan.config import load_plan_config

    shutil.copytree(EX / "plan_paper_bore", tmp_path / "plan_paper_bore")
    cfg = (EX / "plan_paper_bore.toml").read_text().replace(
        '"../src/robobore', f'"{REPO}/src/robobore')
    cfg = cfg.replace("axis = [-0.9992052193, -0.0398392954, -0.0013267225]",
                      "axis = [0.0, 0.0, -1.0]")
    (tmp_path / "v.toml").write_text(cfg)
    inp = load_plan_config(tmp_path / "v.toml")
    assert np.allclose(inp.bore_axis, [0, 0, -1])
    (tmp_path / "t.toml").write_text(cfg.replace("rotation_step_deg = 1.0",
                                                 "rotation_step_deg = 1e-6"))
    with pytest.raises(ConfigError, match="rotation_step_deg"):
        load_plan_config(tmp_path / "t.toml")


@pytest.mark.parametrize("z", [(0, 0, 1.0), (0, 0, -1.0), (0.01, 0, -1.0)])
def test_vertical_boring_frame_takes_x_from_the_base(z):
    from robobore.plan.candidates import boring_frame

    R = boring_frame(np.asarray(z, float))
    zz = np.asarray(z, float) / np.linalg.norm(z)
    ex = np.array([1.0, 0, 0]) - zz[0] * zz
    assert np.allclose(R[:, 2], zz)
    assert np.allclose(R[:, 0], ex / np.linalg.norm(ex))
    assert np.allclose(R.T @ R, np.eye(3)) and np.linalg.det(R) > 0


def test_horizontal_boring_frame_unchanged():
    from robobore.plan.candidates import boring_frame

    R = boring_frame(np.array([1.0, 0, 0]))
    assert np.allclose(R[:, 0], np.cross([0, 0, 1.0], [1.0, 0, 0]))
    assert np.allclose(R[:, 1], [0, 0, 1.0])


def test_plan_warns_on_a_calibration_that_does_not_fit(tmp_path):
    """Joint stiffnesses x 1000 (N m/rad given as N mm/rad): the model calibrated at the
    measured posture misses the identified modes by about 2,240 % rms; said, not silent."""
    import re as _re

    from robobore.plan.posture import CALIBRATION_WARN_PERCENT, plan_posture

    shutil.copytree(EX / "plan_paper_bore", tmp_path / "plan_paper_bore")
    s = tmp_path / "plan_paper_bore" / "joint_stiffness.json"
    d = json.loads(s.read_text())
    d["joint_stiffness_Nm_per_rad"] = [k * 1000 for k in d["joint_stiffness_Nm_per_rad"]]
    s.write_text(json.dumps(d))
    cfg = (EX / "plan_paper_bore.toml").read_text().replace(
        '"../src/robobore', f'"{REPO}/src/robobore').replace("rotation_step_deg = 1.0",
                                                            "rotation_step_deg = 10.0")
    cfg = _re.sub(r"(?s)\[workspace\].*", "", cfg)
    (tmp_path / "p.toml").write_text(cfg)
    r = plan_posture(tmp_path / "p.toml").to_dict()
    assert r["calibration"]["rms_frequency_residual_percent"] > CALIBRATION_WARN_PERCENT
    assert r["warnings"] and "joint_stiffness.json" in r["warnings"][0]


def test_plan_posture_in_radians(tmp_path):
    """The measured posture given in radians: refused where the modes file records its
    posture, warned where it does not."""
    import re as _re

    from robobore.plan.config import load_plan_config
    from robobore.plan.posture import plan_posture

    shutil.copytree(EX / "plan_paper_bore", tmp_path / "plan_paper_bore")
    q_rad = [round(math.radians(v), 4) for v in (-48.38, 54.82, 6.86, -54.16, 107.43, -21.95)]
    cfg = (EX / "plan_paper_bore.toml").read_text().replace(
        '"../src/robobore', f'"{REPO}/src/robobore').replace("rotation_step_deg = 1.0",
                                                            "rotation_step_deg = 10.0")
    cfg = _re.sub(r"(?m)^posture_deg = .*$", f"posture_deg = {q_rad}", cfg)
    cfg = _re.sub(r"(?s)\[workspace\].*", "", cfg)
    (tmp_path / "p.toml").write_text(cfg)
    mfile = tmp_path / "plan_paper_bore" / "modes.json"
    d = json.loads(mfile.read_text())
    if d.get("identity", {}).get("joints_deg") or d.get("posture_deg"):
        with pytest.raises(ConfigError, match="posture"):
            load_plan_config(tmp_path / "p.toml")
    d.pop("identity", None)
    d.pop("posture_deg", None)
    mfile.write_text(json.dumps(d))
    r = plan_posture(tmp_path / "p.toml").to_dict()
    assert any("radians?" in w for w in r["warnings"])
