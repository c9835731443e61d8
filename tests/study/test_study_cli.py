"""`robobore sweep`: JSON output, resume, exit codes, clear errors."""

from __future__ import annotations

import json
from pathlib import Path

from conftest import write_sweep_toml
from typer.testing import CliRunner

from robobore.cli import app
from robobore.io.records import json_mismatches

CONTRACT = Path(__file__).parent / "contract"


def test_sweep_json_then_resume(tmp_path, sweep_toml):
    r = CliRunner()
    args = ["sweep", str(sweep_toml), "--out", str(tmp_path / "s"), "--workers", "0", "--json"]
    res = r.invoke(app, args)
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert (d["total"], d["computed"], d["skipped"], d["failed"]) == (12, 12, 0, 0)
    assert d["runner"] == "demo" and d["mode"] == "serial (no Dask)"
    d2 = json.loads(r.invoke(app, args).stdout)
    assert (d2["computed"], d2["skipped"]) == (0, 12)
    # the JSON keeps to the stored contract; after name and runner it is the SweepOutcome's
    # to_dict() (the same resumed run in-process; its wall time aside)
    spec = json.loads((CONTRACT / "sweep.json").read_text())["keys"]
    assert json_mismatches(d, spec) == [] and json_mismatches(d2, spec) == []
    from robobore.study.sweep import plan_from_file, run_sweep

    out = run_sweep(plan_from_file(sweep_toml), tmp_path / "s", workers=0)
    timing = ("wall_time_s", "conditions_per_s")
    mine = json.loads(json.dumps(out.to_dict()))
    assert {k: v for k, v in mine.items() if k not in timing} == {
        k: v for k, v in d2.items() if k not in ("name", "runner", *timing)}
    assert list(d2)[2:] == list(mine)
    res = r.invoke(app, args[:-1])  # table output
    assert res.exit_code == 0 and "already done" in res.output


def test_sweep_with_failures_exits_1_and_lists_them(tmp_path):
    cfg = write_sweep_toml(tmp_path / "c.toml", speeds=(300, 600), feeds=(0.1,),
                           runner_options="fail_speeds_rpm = [600]")
    res = CliRunner().invoke(app, ["sweep", str(cfg), "--out", str(tmp_path / "s"),
                                   "--workers", "1", "--threads",
                                   "--report", str(tmp_path / "r.html")])
    assert res.exit_code == 1
    text = " ".join(res.output.split())
    assert "failed conditions" in text and "asked to fail at 600" in text
    html = (tmp_path / "r.html").read_text()
    # 1 stability map (P = 0) + 4 trend figures (depth of cut is the only varied factor left)
    assert "Failed conditions" in html and html.count("data:image/png;base64,") == 5


def test_sweep_bad_inputs_are_one_line_errors(tmp_path, sweep_toml):
    r = CliRunner()
    res = r.invoke(app, ["sweep", str(tmp_path / "none.toml")])
    assert res.exit_code == 2 and "config file not found" in res.output
    bad = tmp_path / "bad.toml"
    bad.write_text('[sweep]\nrunner = "nope"\n[grid]\nspeed_rpm = [300]\n'
                   'feed_mm_per_rev = [0.1]\ndepth_of_cut_mm = [0.1]\n')
    res = r.invoke(app, ["sweep", str(bad)])
    assert res.exit_code == 2 and "unknown runner" in " ".join(res.output.split())
    res = r.invoke(app, ["sweep", str(sweep_toml), "--scheduler", "tcp://127.0.0.1:9",
                         "--workers", "2"])
    assert res.exit_code == 2 and "either --scheduler or --workers" in " ".join(
        res.output.split())
    notstore = tmp_path / "notstore"
    notstore.mkdir()
    (notstore / "x.txt").write_text("mine")
    res = r.invoke(app, ["sweep", str(sweep_toml), "--out", str(notstore), "--workers", "0"])
    assert res.exit_code == 2 and "not a results store" in " ".join(res.output.split())


def test_sweep_status_computes_nothing(tmp_path):
    cfg = write_sweep_toml(tmp_path / "c.toml", speeds=(300, 600), feeds=(0.1,),
                           runner_options="fail_speeds_rpm = [600]")
    r = CliRunner()
    base = ["sweep", str(cfg), "--out", str(tmp_path / "s")]
    d = json.loads(r.invoke(app, [*base, "--status", "--json"]).stdout)
    assert (d["total"], d["done"], d["failed"], d["pending"]) == (4, 0, 0, 4)
    assert not (tmp_path / "s").exists()
    assert r.invoke(app, [*base, "--workers", "0"]).exit_code == 1
    d = json.loads(r.invoke(app, [*base, "--status", "--json"]).stdout)
    assert (d["done"], d["failed"], d["pending"]) == (2, 2, 0)
    assert "asked to fail" in d["failures"][0]["error"] and d["failures"][0]["attempts"] == 1
    res = r.invoke(app, [*base, "--status"])
    assert res.exit_code == 0 and "status only" in res.output
