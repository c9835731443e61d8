"""What a file describes travels with it and is checked on arrival (robobore.io.identity):
a second robot (KUKA-like, examples/robots/kr240-r2900.toml) through campaign,
identification and stiffness; the residual test; the radians warning; the API's checks."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore import api
from robobore.cli import app
from robobore.errors import ConfigError, InputError
from robobore.io.identity import check_pair, make_identity, read_identity

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
KUKA = REPO / "examples" / "robots" / "kr240-r2900.toml"
POSTURES = ("20,20,10,0,-30,0; 0,40,-10,0,30,0; -30,10,20,20,40,10; 45,30,-20,-30,-20,30; "
            "10,50,-30,40,50,-20; -60,0,30,0,60,0")
Q = "20,20,10,0,-30,0"


def _ok(args):
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    return r


def _err(args):
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    return " ".join(r.output.split())


@pytest.fixture(scope="module")
def kuka(tmp_path_factory):
    """A SYNTHETIC campaign of the KUKA-like robot and its identification JSON."""
    d = tmp_path_factory.mktemp("kuka")
    camp = d / "kuka_campaign.csv"
    _ok(["robot", "campaign", str(camp), "--robot-file", str(KUKA), "--postures-deg",
         POSTURES])
    r = _ok(["identify", "stiffness", str(camp), "--robot-file", str(KUKA), "--tcp-m",
             "0,0,0.35", "--json"])
    s = d / "s.json"
    s.write_text(r.stdout)
    return d, camp, s


def test_identification_records_identity_and_synthetic(kuka):
    _, camp, s = kuka
    d = json.loads(s.read_text())
    idn = d["identity"]
    assert idn["robot"] == "kr240-r2900" and len(idn["robot_hash"]) == 16
    assert np.allclose(idn["joints_deg"], [20, 20, 10, 0, -30, 0])
    assert idn["tcp_m"] == [0.0, 0.0, 0.35] and idn["frame"] == "boring"
    # the campaign's identity file carries SYNTHETIC into the identification
    assert idn["synthetic"] is True and d["synthetic"] is True
    assert d["residual_test"]["passed"], d["residual_test"]


def test_robot_stiffness_uses_the_files_robot(kuka):
    _, _, s = kuka
    r = _ok(["robot", "stiffness", f"--joints-deg={Q}", "--joint-stiffness-file", str(s),
             "--tcp-m", "0,0,0.35", "--json"])
    d = json.loads(r.stdout)
    assert d["robot"] == "kr240-r2900"
    assert any("taken from" in n for n in d["notes"])
    ref = json.loads(_ok(["robot", "stiffness", f"--joints-deg={Q}", "--joint-stiffness-file",
                          str(s), "--tcp-m", "0,0,0.35", "--robot-file", str(KUKA),
                          "--json"]).stdout)
    assert d["directional_stiffness_N_per_m"] == ref["directional_stiffness_N_per_m"]


def test_robot_stiffness_refuses_another_robot(kuka):
    _, _, s = kuka
    msg = _err(["robot", "stiffness", f"--joints-deg={Q}", "--joint-stiffness-file", str(s),
                "--robot", "irb6600-175-2.55"])
    assert "was identified for kr240-r2900" in msg and "--robot is irb6600-175-2.55" in msg
    assert str(s) in msg


def test_robot_stiffness_file_with_wrong_joint_count(tmp_path):
    f = tmp_path / "five.json"
    f.write_text(json.dumps({"joint_stiffness_Nm_per_rad": [1e6] * 5}))
    msg = _err(["robot", "stiffness", f"--joints-deg={Q}", "--joint-stiffness-file", str(f)])
    assert str(f) in msg and "got 5 joint stiffnesses" in msg and "6 values" in msg


def test_old_file_without_identity_is_accepted_with_a_note(kuka, tmp_path):
    _, _, s = kuka
    d = json.loads(s.read_text())
    del d["identity"]
    d["robot"] = "irb6600-175-2.55"
    old = tmp_path / "old.json"
    old.write_text(json.dumps(d))
    out = json.loads(_ok(["robot", "stiffness", f"--joints-deg={Q}", "--joint-stiffness-file",
                          str(old), "--json"]).stdout)
    assert any("could not be checked" in n for n in out["notes"])


def test_campaign_of_another_robot_refused_by_its_identity_file(kuka):
    _, camp, _ = kuka
    msg = _err(["identify", "stiffness", str(camp), "--robot", "irb6600-175-2.55"])
    assert "kr240-r2900" in msg and "irb6600-175-2.55" in msg


def test_residual_test_flags_the_wrong_robot(kuka, tmp_path):
    """A measured campaign (no identity file) of the KUKA-like robot identified as an IRB
    6600: the chi-square test at 99.9 % says the residual is more than tracker noise."""
    _, camp, _ = kuka
    measured = tmp_path / "measured.csv"
    measured.write_text(camp.read_text())
    d = json.loads(_ok(["identify", "stiffness", str(measured), "--robot",
                        "irb6600-175-2.55", "--json"]).stdout)
    t = d["residual_test"]
    assert not t["passed"] and t["chi2"] > t["chi2_limit"]
    assert any("wrong robot, tool point or reflector file" in n for n in d["notes"])
    assert d["synthetic"] is False  # no identity file: measured


def test_bundled_campaign_passes_the_residual_test_and_is_synthetic():
    d = json.loads(_ok(["identify", "stiffness", "--example", "--json"]).stdout)
    assert d["residual_test"]["passed"] and d["identity"]["synthetic"] is True
    ident = api.identify_joint_stiffness()
    assert ident.synthetic and ident.identity["robot"] == "irb6600-175-2.55"


def test_radians_warning():
    r = _ok(["robot", "fk", "--joints-deg=-0.84,0.96,0.12,-0.95,1.87,-0.38", "--json"])
    assert "radians?" in " ".join(r.output.split())
    assert json.loads(r.stdout)["notes"]
    r = _ok(["robot", "fk", "--joints-deg=-48.38,54.82,6.86,-54.16,107.43,-21.95", "--json"])
    assert json.loads(r.stdout)["notes"] == []


def test_api_stiffness_at_pose_identity(kuka):
    _, _, s = kuka
    d = json.loads(s.read_text())
    with pytest.warns(UserWarning, match="taken from"):
        r = api.stiffness_at_pose(d, [20, 20, 10, 0, -30, 0], tcp_m=[0, 0, 0.35])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ref = api.stiffness_at_pose(d, [20, 20, 10, 0, -30, 0], robot=str(KUKA),
                                    tcp_m=[0, 0, 0.35])
    assert r.directional_stiffness_N_per_m == ref.directional_stiffness_N_per_m
    with pytest.raises(ConfigError, match="identified for kr240-r2900"):
        api.stiffness_at_pose(d, [20, 20, 10, 0, -30, 0], robot="irb6600-175-2.55")
    with pytest.raises(InputError, match="tcp_m"):
        api.stiffness_at_pose(d, [20, 20, 10, 0, -30, 0], tcp_m=[0, 0, 300])
    with pytest.raises(InputError, match="joints_deg"):
        api.stiffness_at_pose(d, "abc")
    with pytest.raises(InputError, match="robot"):
        api.stiffness_at_pose(d, robot=5)
    with pytest.raises(InputError, match="joint_stiffness"):
        api.stiffness_at_pose("nonsense")


def test_identity_pair_checks():
    a = make_identity("joint stiffness", robot="r1", robot_hash="a" * 16,
                      joints_deg=[0, 10, 20, 0, 0, 0], frame="boring")
    b = make_identity("modes", robot="r1", robot_hash="a" * 16, joints_deg=[0, 10, 20, 0, 0, 0])
    check_pair(a, "s.json", b, "m.json")
    c = dict(b, robot="r2", robot_hash="b" * 16)
    with pytest.raises(ConfigError, match="s.json describes robot r1.*m.json describes robot r2"):
        check_pair(a, "s.json", c, "m.json")
    d = dict(b, joints_deg=[0, 10, 25, 0, 0, 0])
    with pytest.raises(ConfigError, match="posture"):
        check_pair(a, "s.json", d, "m.json")
    e = dict(b, frame="tool")
    with pytest.raises(ConfigError, match="frame"):
        check_pair(a, "s.json", e, "m.json")
    with pytest.raises(ConfigError, match="identity.synthetic"):
        read_identity({"identity": {"synthetic": "yes"}}, "x.json")
    assert read_identity({"robot": "r1"}, "x.json") is None
