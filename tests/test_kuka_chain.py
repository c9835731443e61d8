"""A second robot of the user's own, given as TOML (examples/robots/kr240-r2900.toml, a
KUKA KR 240 R2900-like arm), through the whole chain: virtual campaign, identification,
virtual hammer test, modal identification, equivalent model, lobes and the planner, with
no identity mix-up and no warning; SYNTHETIC carried to the end."""

from __future__ import annotations

import json
import re
from pathlib import Path

from typer.testing import CliRunner

from robobore.cli import app

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
KUKA = EX / "robots" / "kr240-r2900.toml"
Q = "20,20,10,0,-30,0"
POSTURES = ("20,20,10,0,-30,0; 0,40,-10,0,30,0; -30,10,20,20,40,10; 45,30,-20,-30,-20,30; "
            "10,50,-30,40,50,-20; -60,0,30,0,60,0")


def _run(args, out: Path | None = None, allow: tuple[str, ...] = ()):
    """Run a command; no warning line on stderr except those starting with ``allow``."""
    r = runner.invoke(app, [str(a) for a in args])
    assert r.exit_code == 0, r.output
    warns = [ln for ln in r.output.lower().splitlines() if "warning:" in ln]
    assert all(any(ln.split("warning:", 1)[1].strip().startswith(a) for a in allow)
               for ln in warns), r.output
    if out is not None:
        out.write_text(r.stdout)
        return json.loads(r.stdout)
    return None


def test_kuka_like_robot_whole_chain(tmp_path):
    camp, s, uff, m = (tmp_path / n for n in ("kc.csv", "ks.json", "kh.uff", "km.json"))
    _run(["robot", "campaign", camp, "--robot-file", KUKA, "--postures-deg", POSTURES])
    sd = _run(["identify", "stiffness", camp, "--robot-file", KUKA, "--json"], s)
    assert sd["residual_test"]["passed"] and sd["identity"]["synthetic"] is True
    _run(["identify", "virtual-hammer-test", uff, "--robot-file", KUKA, "--joints-deg", Q])
    md = _run(["identify", "modes", uff, "--band-hz", "3", "60", "--json"], m)
    assert md["identity"]["robot"] == "kr240-r2900" and md["synthetic"] is True
    eq = _run(["model", "equivalent", "--stiffness-file", s, "--modes-file", m, "--json"],
              tmp_path / "keq.json")
    assert eq["identity"]["robot"] == "kr240-r2900" and eq["identity"]["synthetic"] is True
    assert not any("could not be checked" in n for n in eq["notes"])
    # the hammer test's static stiffness is the campaign robot's: the equivalent model's k_z
    # is the directional stiffness of robot stiffness at the test posture (same robot, file)
    rs = _run(["robot", "stiffness", f"--joints-deg={Q}", "--joint-stiffness-file", s,
               "--json"], tmp_path / "rs.json")
    assert rs["robot"] == "kr240-r2900"
    assert abs(eq["stiffness_N_per_m"]["z"] / rs["directional_stiffness_N_per_m"]["z"] - 1) < 1e-6
    lob = _run(["lobes", EX / "boring_process.toml", "--equivalent-file",
                tmp_path / "keq.json", "--method", "frequency", "--json"], tmp_path / "l.json")
    assert min(lob["critical_depth_mm"]) > 0
    # a user's own robot at 380 r/min, ap 0.02 mm (below the depth where the forced vibration
    # takes the tool out of the cut): with the entry and exit of the cut located within the
    # step, every sampling gives the same decided verdict (no chatter: a bounded forced
    # vibration), the doubled run agrees, and the feed amplitude changes by less than 5 %
    runs = []
    for spr in ("1266", None, "4000", "2332"):
        runs.append(_run(["simulate", "boring", EX / "boring_process.toml", "--equivalent-file",
                          tmp_path / "keq.json", "--speed-rpm", "380", "--depth-mm", "0.02",
                          "--json"] + ([] if spr is None else ["--samples-per-rev", spr]),
                         tmp_path / "sim.json"))
    assert all(r["chatter_decided"] and not r["chatter"] for r in runs), [
        (r["samples_per_rev"], r["chatter"], r["chatter_decided"]) for r in runs]
    for r in runs:
        sc = r["sampling_check"]
        assert r["tool_leaves_cut"] and sc["samples_per_rev"] == 2 * r["samples_per_rev"]
        assert sc["agrees"] and r["tool_leaves_cut_cause"] == "forced vibration"
        assert any("forced vibration takes the tool out" in w for w in r["reasons"])
    fa = [r["feed_amplitude_um"] for r in runs]
    assert max(fa) / min(fa) - 1 < 0.05, fa
    fk = _run(["robot", "fk", "--robot-file", KUKA, f"--joints-deg={Q}", "--json"],
              tmp_path / "fk.json")
    t = (EX / "plan_paper_bore.toml").read_text()
    t = t.replace('name = "irb6600-175-2.55"', f'name = "{KUKA}"')
    t = t.replace('"plan_paper_bore/joint_stiffness.json"', f'"{s}"')
    t = t.replace('"plan_paper_bore/modes.json"', f'"{m}"')
    t = re.sub(r"(?m)^posture_deg = .*$", "", t)  # the modes file records it
    t = re.sub(r"(?m)^point_m = .*$", f"point_m = {fk['position_m']}", t)
    t = re.sub(r"(?m)^axis = \[-0.99.*$", f"axis = {[r[2] for r in fk['rotation']]}", t)
    t = t.replace('"../src/robobore', f'"{REPO}/src/robobore')
    t = t.replace("rotation_step_deg = 1.0", "rotation_step_deg = 10.0")
    (tmp_path / "kplan.toml").write_text(re.sub(r"(?s)\[workspace\].*", "", t))
    # the planner's model of this ASSUMED robot calibrates poorly (its link data are guesses)
    # and its map is flat (tool axis along the flange axis); the default TC4 coefficients are
    # used above their measured speeds (37.7 vs 5-30 m/min): said, but no mix-up warning
    plan = _run(["plan", "posture", tmp_path / "kplan.toml", "--json"], tmp_path / "p.json",
                allow=("calibration:", "the critical_depth criterion does not vary",
                       "coefficients: cutting speed 37.7 m/min outside the measured"))
    assert plan["robot"] == "kr240-r2900"
    assert not any("may not belong together" in w for w in plan["warnings"])
    assert plan["measured"] is not None and plan["identity"]["synthetic"] is True
    # the lowest semi-discretisation limit over the speed range (0: some speed has no
    # chatter-free depth)
    assert plan["recommended"]["critical_depth_mm"] >= 0
    assert plan["recommended"]["critical_depth_method"] == "semi-discretization"
