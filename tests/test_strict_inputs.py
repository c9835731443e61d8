"""Inputs as a new user gives them: other CSV separators, a CSV given as a UFF, messages that
name their file, a Dask scheduler that accepts and never answers, the FE validation store."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import ConfigError, DataError, RoboboreError

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
DATA = REPO / "src" / "robobore" / "data"
EX = REPO / "examples"


def _err(args):
    r = runner.invoke(app, args)
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output
    return " ".join(r.output.split())


@pytest.mark.parametrize("sep", [";", "\t"])
def test_campaign_with_another_separator_is_read(tmp_path, sep):
    from robobore.robot.campaign_io import read_campaign

    src = DATA / "campaign_irb6600" / "campaign.csv"
    ref = read_campaign(src)
    text = src.read_text().replace(",", sep)
    if sep == ";":  # a European spreadsheet: decimal commas as well
        text = text.replace(".", ",")
    f = tmp_path / "semi.csv"
    f.write_text(text)
    c = read_campaign(f)
    assert c.n_rows == ref.n_rows
    assert (c.xyz_m == ref.xyz_m).all() and (c.q_deg == ref.q_deg).all()


def test_campaign_with_a_space_separated_header_is_named(tmp_path):
    from robobore.robot.campaign_io import read_campaign

    src = DATA / "campaign_irb6600" / "campaign.csv"
    f = tmp_path / "space.csv"
    f.write_text(src.read_text().replace(",", " "))
    with pytest.raises(DataError, match="separated by ' ', not by commas") as ei:
        read_campaign(f)
    assert str(f) in str(ei.value)


def test_measured_csv_with_semicolons_is_read(tmp_path):
    from robobore.study.compare import read_measured_csv

    src = DATA / "paper_example" / "measured_synthetic.csv"
    ref = read_measured_csv(src)
    f = tmp_path / "m.csv"
    f.write_text(src.read_text().replace(",", ";"))
    t = read_measured_csv(f)
    assert len(t.rows) == len(ref.rows)
    assert [r.values for r in t.rows] == [r.values for r in ref.rows]


def test_csv_given_as_uff_is_named(tmp_path):
    f = tmp_path / "hammer.uff"
    f.write_text("time_s,force_N,acc_x\n0,0,0\n0.01,1,2\n-1\n")
    msg = _err(["identify", "modes", str(f)])
    assert str(f) in msg and "a CSV / text table" in msg


def test_unknown_robot_in_a_plan_names_the_file(tmp_path):
    import shutil

    from robobore.plan.config import load_plan_config

    shutil.copytree(EX / "plan_paper_bore", tmp_path / "plan_paper_bore")
    cfg = (EX / "plan_paper_bore.toml").read_text().replace(
        'name = "irb6600-175-2.55"', 'name = "irb6600"')
    (tmp_path / "p.toml").write_text(cfg)
    with pytest.raises(ConfigError) as ei:
        load_plan_config(tmp_path / "p.toml")
    msg = str(ei.value)
    assert str(tmp_path / "p.toml") in msg and "robot.name" in msg
    assert "did you mean 'irb6600-175-2.55'" in msg


def test_unknown_robot_option_names_the_option():
    msg = _err(["robot", "fk", "--robot", "irb6600", "--joints-deg", "0,0,0,0,10,0"])
    assert "--robot" in msg and "irb6600-175-2.55" in msg


def test_unknown_material_names_file_key_and_value(tmp_path):
    f = tmp_path / "bp.toml"
    f.write_text((EX / "boring_process.toml").read_text().replace('material = "TC4"',
                                                                    'material = "Inconel"'))
    msg = _err(["lobes", str(f)])
    assert str(f) in msg and "coefficients" in msg and "'Inconel'" in msg and "TC4" in msg


def test_unknown_runner_names_the_file(tmp_path):
    f = tmp_path / "sw.toml"
    f.write_text((EX / "sweep_demo.toml").read_text().replace('runner = "demo"',
                                                                'runner = "boreing"'))
    msg = _err(["sweep", str(f), "--out", str(tmp_path / "o"), "--workers", "0"])
    assert str(f) in msg and "sweep.runner" in msg and "boreing" in msg


def test_silent_scheduler_fails_in_seconds(tmp_path):
    """A loopback server that accepts the connection and never answers."""
    pytest.importorskip("distributed")
    from robobore.study.store import ResultsStore
    from robobore.study.sweep import plan_from_file, run_sweep

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    port = srv.getsockname()[1]
    conns = []
    stop = threading.Event()

    def accept():
        srv.settimeout(0.2)
        while not stop.is_set():
            try:
                conns.append(srv.accept()[0])
            except OSError:
                pass

    t = threading.Thread(target=accept, daemon=True)
    t.start()
    try:
        plan = plan_from_file(EX / "sweep_demo.toml")
        t0 = time.monotonic()
        with pytest.raises(RoboboreError, match="does not answer|cannot connect"):
            run_sweep(plan, ResultsStore(tmp_path / "store"),
                      scheduler=f"tcp://127.0.0.1:{port}", connect_timeout_s=2.0)
        assert time.monotonic() - t0 < 30
    finally:
        stop.set()
        t.join()
        for c in conns:
            c.close()
        srv.close()


def test_95_deg_boring_bar_accepted_and_110_refused(tmp_path):
    import json

    s = tmp_path / "s.json"
    r = runner.invoke(app, ["identify", "stiffness", "--example", "--json"])
    s.write_text(r.stdout)
    m = tmp_path / "m.json"
    m.write_text(runner.invoke(app, ["identify", "modes", "--example", "--json"]).stdout)
    base = (EX / "boring_process.toml").read_text()
    assert "approach_angle_deg = 90.0" in base
    f95 = tmp_path / "b95.toml"
    f95.write_text(base.replace("approach_angle_deg = 90.0", "approach_angle_deg = 95.0"))
    r = runner.invoke(app, ["lobes", str(f95), "--stiffness-file", str(s), "--modes-file",
                            str(m), "--method", "frequency", "--json"])
    assert r.exit_code == 0, r.output
    assert min(json.loads(r.stdout)["critical_depth_mm"]) > 0
    f110 = tmp_path / "b110.toml"
    f110.write_text(base.replace("approach_angle_deg = 90.0", "approach_angle_deg = 110.0"))
    msg = _err(["lobes", str(f110), "--stiffness-file", str(s), "--modes-file", str(m)])
    assert str(f110) in msg and "insert.approach_angle_deg" in msg and "107.5" in msg


@pytest.mark.parametrize(("call", "arg"), [
    (lambda api: api.identify_modes(band_Hz="3-60"), "band_Hz"),
    (lambda api: api.identify_modes(n_modes="5"), "n_modes"),
    (lambda api: api.load_campaign(5), "path"),
    (lambda api: api.identify_joint_stiffness(sigma_m="10"), "sigma_m"),
    (lambda api: api.cutting_coefficients("fast"), "cutting_speed_m_per_min"),
    (lambda api: api.load_hammer_test(7), "path"),
    (lambda api: api.stiffness_at_pose([3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5],
                                       wrench_N_Nm=[1, 2]), "wrench_N_Nm"),
    (lambda api: api.stiffness_at_pose([3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5],
                                       tcp_m=[0, 0, 300]), "tcp_m"),
])
def test_api_arguments_of_the_wrong_type_are_named(call, arg):
    from robobore import api
    from robobore.errors import InputError

    with pytest.raises(InputError) as ei:
        call(api)
    assert ei.value.field == arg
