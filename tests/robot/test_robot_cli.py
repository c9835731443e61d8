"""CLI of the robot stage: JSON contract keys, the README's first command, error exits."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app

runner = CliRunner()
PAPER = "-48.38,54.82,6.86,-54.16,107.43,-21.95"
K = "3e6,4e6,2.5e6,5e5,4.5e5,3e5"


def _json(args):
    r = runner.invoke(app, args)
    assert r.exit_code == 0, r.output
    return json.loads(r.stdout)


def test_robot_list():
    d = _json(["robot", "list", "--json"])
    assert d["robots"]["irb6600-175-2.55"]["joints"] == 6


def test_fk_json_contract():
    d = _json(["robot", "fk", "--robot", "irb6600-175-2.55", "--joints-deg", PAPER, "--json"])
    assert np.allclose(d["position_m"], [1.073, -1.441, 0.489], atol=1e-3)
    assert np.asarray(d["rotation"]).shape == (3, 3)


def test_stiffness_json_contract(tmp_path):
    d = _json(["robot", "stiffness", "--robot", "irb6600-175-2.55", "--joints-deg", PAPER,
               "--joint-stiffness-Nm-per-rad", K, "--json"])
    assert set(d["directional_stiffness_N_per_m"]) == {"x", "y", "z"}
    assert np.asarray(d["cartesian_stiffness"]).shape == (6, 6)
    d2 = _json(["robot", "stiffness", "--joints-deg", PAPER, "--joint-stiffness-Nm-per-rad", K,
                "--wrench-N-Nm", "0,0,-1000,0,0,0", "--frame", "boring", "--json",
                "--plot", str(tmp_path)])
    assert np.asarray(d2["complementary_stiffness"]).shape == (6, 6)
    assert d2["frame"] == "boring"
    assert (tmp_path / "directional_stiffness.png").is_file()


def test_identify_example_is_synthetic_and_complete():
    r = runner.invoke(app, ["identify", "stiffness", "--example"])
    assert r.exit_code == 0, r.output
    assert "SYNTHETIC" in r.stdout and "k_zz" in r.stdout
    d = _json(["identify", "stiffness", "--example", "--json"])
    assert d["synthetic"] is True
    assert len(d["joint_stiffness_Nm_per_rad"]) == 6
    assert len(d["joint_stiffness_std_Nm_per_rad"]) == 6
    assert set(d["directional_stiffness_N_per_m"]) == {"x", "y", "z"}
    byf = d["directional_stiffness_by_frame_N_per_m"]
    assert byf["boring"] == d["directional_stiffness_N_per_m"]  # default frame: boring
    # at the paper's posture tool x is vertical and tool y horizontal: boring X = tool y
    assert byf["boring"]["x"] == pytest.approx(byf["tool"]["y"], rel=0.02)
    assert byf["boring"]["z"] == pytest.approx(byf["tool"]["z"], rel=1e-9)


def test_campaign_then_identify_then_stiffness_chain(tmp_path):
    csv = tmp_path / "c.csv"
    d = _json(["robot", "campaign", str(csv), "--sigma-um", "5", "--seed", "3",
               "--load-levels-N", "0,500,1000", "--json"])
    assert d["synthetic"] is True and csv.is_file()
    ident = tmp_path / "k.json"
    r = runner.invoke(app, ["identify", "stiffness", str(csv), "--robot", "irb6600-175-2.55",
                            "--json", "--plot", str(tmp_path / "plots")])
    assert r.exit_code == 0, r.output
    ident.write_text(r.stdout)
    k = json.loads(r.stdout)["joint_stiffness_Nm_per_rad"]
    assert np.allclose(k[:3], [3e6, 4e6, 2.5e6], rtol=0.05)
    assert (tmp_path / "plots" / "identify_stiffness.png").is_file()
    s = _json(["robot", "stiffness", "--joints-deg", PAPER, "--joint-stiffness-file", str(ident),
               "--json"])
    assert s["directional_stiffness_N_per_m"]["z"] > 0


@pytest.mark.parametrize("args, needle", [
    (["robot", "fk", "--robot", "nope", "--joints-deg", PAPER], "unknown robot"),
    (["robot", "fk", "--joints-deg", "0,85,0,0,0,0"], "joint 2"),
    (["robot", "fk", "--joints-deg", "0,1,2"], "--joints-deg"),
    (["robot", "stiffness", "--joints-deg", PAPER, "--joint-stiffness-Nm-per-rad",
      "1e6,2e6,3e6,4e6,5e6,-6e6"], "positive"),
    (["identify", "stiffness"], "no campaign file"),
])
def test_errors_exit_2_with_one_line(args, needle):
    r = runner.invoke(app, args)
    assert r.exit_code == 2
    assert needle in r.output and "Traceback" not in r.output


def test_identify_bad_csv_names_row_and_column(tmp_path):
    from robobore.robot.cli import example_campaign_path

    lines = example_campaign_path().read_text().splitlines()
    cells = lines[3].split(",")
    cells[16] = "12,5mm".replace(",", ";")
    lines[3] = ",".join(cells)
    f = tmp_path / "bad.csv"
    f.write_text("\n".join(lines) + "\n")
    r = runner.invoke(app, ["identify", "stiffness", str(f), "--robot", "irb6600-175-2.55"])
    assert r.exit_code == 2
    assert "bad.csv" in r.output and "row 3" in r.output and "y_m" in r.output
    # one line, however long the temporary path (rich would wrap at the console width)
    assert len(r.output.strip().splitlines()) == 1
