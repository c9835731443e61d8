"""Cases of the malformed-input corpus on the paths that join files: identity mix-ups (robot,
posture, tool point, frame), unit slips in identification files, the planner, FE validation's
measured file, the Python API, ``sweep --scheduler`` with a silent server, other CSV
separators.

Used by ``benchmarks/malformed_corpus.py`` (not run alone). :func:`build` writes the fixture
files under a folder (a SYNTHETIC campaign of the KUKA-like example robot
``examples/robots/kr240-r2900.toml`` and its identification, the bundled identification and
modes, an equivalent model) and returns the cases as ``(description, argv, pattern, mode)``
like ``malformed_corpus_more.build``: mode ``error`` expects a clear one-line error matching
``pattern``; mode ``script`` runs a Python script that exits 0 and prints ``OK`` when the
behaviour is right (a correct result, a warning that must be given, an API error that must
be a RoboboreError naming the argument), else it prints what went wrong. The description's
prefix is the input path (``id``, ``unit``, ``plan``, ``fe``, ``api``, ``sweep``, ``csv``).
"""
# ruff: noqa: E501

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
DATA = REPO / "src" / "robobore" / "data"
KUKA = EX / "robots" / "kr240-r2900.toml"
POSTURES = ("20,20,10,0,-30,0; 0,40,-10,0,30,0; -30,10,20,20,40,10; 45,30,-20,-30,-20,30; "
            "10,50,-30,40,50,-20; -60,0,30,0,60,0")
PY = sys.executable


def _rb(*args: str, out: Path | None = None) -> None:
    env = {**os.environ, "PYTHONPATH": str(REPO / "src"), "NUMBA_NUM_THREADS": "1"}
    r = subprocess.run([PY, "-m", "robobore", *args], capture_output=True, text=True, env=env)
    if r.returncode != 0:
        raise RuntimeError(f"fixture command failed: {args}: {r.stderr[-400:]}")
    if out is not None:
        out.write_text(r.stdout)


def _mut(src: Path, dst: Path, fn) -> Path:
    d = json.loads(src.read_text())
    fn(d)
    dst.write_text(json.dumps(d))
    return dst


#: a script: run ``code`` (with ``W`` the fixture folder); print OK or what went wrong
_API = '''
import sys, json, warnings
from pathlib import Path
W = Path(sys.argv[1])
from robobore import api
from robobore.errors import RoboboreError
try:
    {call}
except RoboboreError as e:
    msg = str(e)
    if all(w in msg for w in {words!r}):
        print("OK:", msg[:200]); sys.exit(0)
    print("error does not name", {words!r}, ":", msg[:300]); sys.exit(1)
print("no error"); sys.exit(1)
'''

_OK = '''
import sys, json, subprocess
from pathlib import Path
W = Path(sys.argv[1])
r = subprocess.run([sys.executable, "-m", "robobore", *{argv!r}], capture_output=True, text=True, cwd=sys.argv[2])
if "Traceback (most recent call last)" in r.stderr:
    print(r.stderr[-400:]); sys.exit(1)
{check}
'''


def _script_api(call: str, words: list[str]) -> list[str]:
    return [PY, "-c", _API.format(call=call, words=words), "{W}"]


def _script_cli(argv: list[str], check: str) -> list[str]:
    return [PY, "-c", _OK.format(argv=argv, check=check), "{W}", "{d}"]


_SILENT = '''
import socket, sys, threading, time, subprocess
srv = socket.socket(); srv.bind(("127.0.0.1", 0)); srv.listen(8)
port = srv.getsockname()[1]; conns = []
def acc():
    while True:
        try: conns.append(srv.accept()[0])
        except OSError: return
threading.Thread(target=acc, daemon=True).start()
t0 = time.monotonic()
r = subprocess.run([sys.executable, "-m", "robobore", "sweep", sys.argv[1], "--out", sys.argv[2] + "/store", "--scheduler", f"tcp://127.0.0.1:{port}"], capture_output=True, text=True, timeout=120)
dt = time.monotonic() - t0
if r.returncode == 2 and "scheduler" in r.stderr and dt < 40 and "Traceback" not in r.stderr:
    print(f"OK: refused in {dt:.1f} s"); sys.exit(0)
print(f"rc {r.returncode} after {dt:.1f} s: {r.stderr[-300:]}"); sys.exit(1)
'''


def build(W: Path) -> list[tuple[str, list, str, str]]:  # noqa: N803, PLR0915
    """Write the fixtures under ``W`` and return the cases."""
    shutil.rmtree(W, ignore_errors=True)
    W.mkdir(parents=True)
    camp = W / "kuka_campaign.csv"
    _rb("robot", "campaign", str(camp), "--robot-file", str(KUKA), "--postures-deg", POSTURES)
    sk = W / "s_kuka.json"
    _rb("identify", "stiffness", str(camp), "--robot-file", str(KUKA), "--json", out=sk)
    sk35 = W / "s_kuka_tcp.json"
    _rb("identify", "stiffness", str(camp), "--robot-file", str(KUKA), "--tcp-m", "0,0,0.35",
        "--json", out=sk35)
    s = W / "s.json"
    _rb("identify", "stiffness", "--example", "--json", out=s)
    m = W / "m.json"
    _rb("identify", "modes", "--example", "--json", out=m)
    s35 = W / "s_tcp.json"
    _rb("identify", "stiffness", "--example", "--tcp-m", "0,0,0.35", "--json", out=s35)
    eq = W / "eq.json"
    _rb("model", "equivalent", "--stiffness-file", str(s), "--modes-file", str(m), "--json",
        out=eq)
    measured_kuka = W / "measured_kuka.csv"
    measured_kuka.write_text(camp.read_text())  # no identity file: a measured campaign
    (W / "semi.csv").write_text(camp.read_text().replace(",", ";"))
    (W / "space.csv").write_text(camp.read_text().replace(",", " "))
    (W / "hammer.uff").write_text("time_s,force_N,acc_x_m_per_s2\n0,0,0\n0.01,1,2\n    -1\n")
    # mutated identification files
    m_post = _mut(m, W / "m_other_posture.json",
                  lambda d: d["identity"].update(joints_deg=[0, 10, 20, 0, 30, 0]))
    m_kuka = _mut(m, W / "m_kuka.json",
                  lambda d: d["identity"].update(robot="kr240-r2900", robot_hash="5" * 16))
    s_frame = _mut(s, W / "s_tool_frame.json", lambda d: d["identity"].update(frame="tool"))
    s_hash = _mut(s, W / "s_edited_robot.json",
                  lambda d: d["identity"].update(robot_hash="0123456789abcdef"))
    s_synth = _mut(s, W / "s_bad_identity.json",
                   lambda d: d["identity"].update(synthetic="yes"))
    s_key = _mut(s, W / "s_identity_key.json", lambda d: d["identity"].update(robott="x"))
    s_old = _mut(s, W / "s_old.json", lambda d: d.pop("identity"))
    s5 = _mut(s, W / "s_five.json", lambda d: d.update(
        joint_stiffness_Nm_per_rad=d["joint_stiffness_Nm_per_rad"][:5]))
    eq_z = _mut(eq, W / "eq_zero_damping.json", lambda d: d["damping_ratio"].update(x=0.0))
    eq_rad = _mut(eq, W / "eq_rad_per_s.json", lambda d: d["frequency_Hz"].update(
        y=d["frequency_Hz"]["y"] * 6.283185307179586))
    eq_negm = _mut(eq, W / "eq_negative_mass.json", lambda d: d["mass_kg"].update(z=-50.0))
    eq_kuka = _mut(eq, W / "eq_kuka.json",
                   lambda d: d["identity"].update(robot="kr240-r2900", robot_hash="5" * 16))
    # process configs
    bp = (EX / "boring_process.toml").read_text()
    (W / "b95.toml").write_text(bp.replace("approach_angle_deg = 90.0", "approach_angle_deg = 95.0"))
    (W / "b110.toml").write_text(bp.replace("approach_angle_deg = 90.0", "approach_angle_deg = 110.0"))
    (W / "brad.toml").write_text(bp.replace("approach_angle_deg = 90.0", "approach_angle_deg = 1.66"))
    (W / "bmat.toml").write_text(bp.replace('material = "TC4"', 'material = "Inconel"'))
    # plan configs (paths of the bundled plan example, copied)
    shutil.copytree(EX / "plan_paper_bore", W / "plan_paper_bore")
    plan = (EX / "plan_paper_bore.toml").read_text().replace('"../src/robobore', f'"{REPO}/src/robobore')
    plan = plan.replace("rotation_step_deg = 1.0", "rotation_step_deg = 10.0")
    plan = re.sub(r"(?s)\[workspace\].*", "", plan)

    def plan_with(name: str, text: str, **files: Path) -> Path:
        d = W / name
        d.mkdir()
        shutil.copytree(EX / "plan_paper_bore", d / "plan_paper_bore")
        for k, v in files.items():
            shutil.copy(v, d / "plan_paper_bore" / f"{k}.json")
        (d / "p.toml").write_text(text)
        return d / "p.toml"

    p_kuka = plan_with("plan_kuka", plan, joint_stiffness=sk)
    p_mkuka = plan_with("plan_mkuka", plan, modes=m_kuka)
    p_vert = plan_with("plan_vertical", plan.replace(
        "point_m = [1.0730531857, -1.4406555317, 0.4886557433]", "point_m = [1.6, 0.0, 0.6]").replace(
        "axis = [-0.9992052193, -0.0398392954, -0.0013267225]", "axis = [0.0, 0.0, -1.0]"))
    p_step = plan_with("plan_step", plan.replace("rotation_step_deg = 10.0", "rotation_step_deg = 1e-6"))
    p_robot = plan_with("plan_robot", plan.replace('name = "irb6600-175-2.55"', 'name = "irb6600"'))
    p_axis = plan_with("plan_axis0", plan.replace(
        "axis = [-0.9992052193, -0.0398392954, -0.0013267225]", "axis = [0.0, 0.0, 0.0]"))
    s1000 = _mut(W / "plan_paper_bore" / "joint_stiffness.json", W / "s_x1000.json",
                 lambda d: d.update(joint_stiffness_Nm_per_rad=[
                     k * 1000 for k in d["joint_stiffness_Nm_per_rad"]]))
    p_1000 = plan_with("plan_x1000", plan, joint_stiffness=s1000)
    m_rad = _mut(W / "plan_paper_bore" / "modes.json", W / "m_rad_per_s.json",
                 lambda d: [md.update(frequency_Hz=md["frequency_Hz"] * 6.283185307179586)
                            for md in d["modes"]])
    p_mrad = plan_with("plan_mrad", plan, modes=m_rad)
    # FE validation measured files
    meas = json.loads((Path(REPO).parent / "shared" / "data" / "ti64_orthogonal_cutting_forces.json")
                      .read_text()) if (Path(REPO).parent / "shared" / "data").is_dir() else None
    if meas is None:
        meas = {"units": {"Fc": "N per mm of width"}, "measured": {"Fc": {"60": {"30": 118.0}},
                                                                    "chip_ratio": {"60": {"30": 1.3}}}}
    kn = json.loads(json.dumps(meas))
    kn["units"]["Fc"] = "kN per mm of width"
    (W / "meas_kN.json").write_text(json.dumps(kn))
    inv = json.loads(json.dumps(meas))
    h = next(iter(inv["measured"]["chip_ratio"]))
    v = next(iter(inv["measured"]["chip_ratio"][h]))
    inv["measured"]["chip_ratio"][h][v] = 1.0 / inv["measured"]["chip_ratio"][h][v]
    (W / "meas_inverted.json").write_text(json.dumps(inv))
    nm = json.loads(json.dumps(meas))
    nm["units"]["Fc"] = "N/m"
    (W / "meas_Nm.json").write_text(json.dumps(nm))
    fe = str(EX / "fe_orthogonal.toml")
    sw = W / "sw_runner.toml"
    sw.write_text((EX / "sweep_demo.toml").read_text().replace('runner = "demo"', 'runner = "boreing"'))
    Q = "--joints-deg=20,20,10,0,-30,0"
    lob = ["lobes", str(EX / "boring_process.toml"), "--method", "frequency"]
    sim = ["simulate", "boring", str(EX / "boring_process.toml"), "--revolutions", "20"]
    cases: list[tuple[str, list, str, str]] = [
        # ---- identity: robot
        ("id: robot stiffness, another robot's stiffness file with --robot",
         ["robot", "stiffness", Q, "--joint-stiffness-file", sk, "--robot", "irb6600-175-2.55"],
         r"s_kuka\.json.*kr240-r2900.*irb6600", "error"),
        ("id: robot stiffness takes the file's robot when none is given",
         _script_cli(["robot", "stiffness", Q, "--joint-stiffness-file", str(sk), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "if d['robot'] == 'kr240-r2900' and any('taken from' in n for n in d['notes']): print('OK'); sys.exit(0)\n"
                     "print(d['robot'], d.get('notes')); sys.exit(1)"), "", "script"),
        ("id: robot stiffness, the file's robot with --robot-file gives the same k",
         _script_cli(["robot", "stiffness", Q, "--joint-stiffness-file", str(sk35), "--tcp-m",
                      "0,0,0.35", "--robot-file", str(KUKA), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "kz = d['directional_stiffness_N_per_m']['z']\n"
                     "if d['robot'] == 'kr240-r2900' and 4e6 < kz < 7e6: print('OK', kz); sys.exit(0)\n"
                     "print(d['robot'], kz); sys.exit(1)"), "", "script"),
        ("id: robot stiffness, an edited robot description (same name, other hash)",
         ["robot", "stiffness", Q, "--joint-stiffness-file", s_hash, "--robot", "irb6600-175-2.55"],
         r"s_edited_robot\.json.*0123456789abcdef", "error"),
        ("id: identify stiffness, a campaign of another robot (identity file)",
         ["identify", "stiffness", camp, "--robot", "irb6600-175-2.55"],
         r"kuka_campaign\.csv.*kr240-r2900", "error"),
        ("id: identify stiffness, a measured campaign of another robot (residual test)",
         _script_cli(["identify", "stiffness", str(measured_kuka), "--robot", "irb6600-175-2.55", "--json"],
                     "d = json.loads(r.stdout)\n"
                     "if not d['residual_test']['passed'] and any('wrong robot' in n for n in d['notes']): print('OK'); sys.exit(0)\n"
                     "print(d['residual_test']); sys.exit(1)"), "", "script"),
        ("id: identify stiffness of the robot's own campaign is SYNTHETIC and passes",
         _script_cli(["identify", "stiffness", str(camp), "--robot-file", str(KUKA), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "if d['synthetic'] and d['residual_test']['passed']: print('OK'); sys.exit(0)\n"
                     "print(d['synthetic'], d['residual_test']); sys.exit(1)"), "", "script"),
        ("id: model equivalent, stiffness and modes of different robots",
         ["model", "equivalent", "--stiffness-file", sk, "--modes-file", m],
         r"s_kuka\.json.*m\.json|m\.json.*s_kuka\.json", "error"),
        ("id: model equivalent, modes of another posture",
         ["model", "equivalent", "--stiffness-file", s, "--modes-file", m_post],
         r"m_other_posture\.json.*posture", "error"),
        ("id: model equivalent, stiffness at another tool point than the modes",
         ["model", "equivalent", "--stiffness-file", s35, "--modes-file", m],
         r"s_tcp\.json.*tool point", "error"),
        ("id: model equivalent, stiffness in another frame",
         ["model", "equivalent", "--stiffness-file", s_frame, "--modes-file", m],
         r"s_tool_frame\.json.*frame", "error"),
        ("id: model equivalent, identity synthetic not a boolean",
         ["model", "equivalent", "--stiffness-file", s_synth, "--modes-file", m],
         r"s_bad_identity\.json.*identity\.synthetic", "error"),
        ("id: model equivalent, unknown identity key",
         ["model", "equivalent", "--stiffness-file", s_key, "--modes-file", m],
         r"s_identity_key\.json.*identity\.robott", "error"),
        ("id: model equivalent, an old file without identity (a note)",
         _script_cli(["model", "equivalent", "--stiffness-file", str(s_old), "--modes-file", str(m), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "if any('could not be checked' in n for n in d['notes']): print('OK'); sys.exit(0)\n"
                     "print(d['notes']); sys.exit(1)"), "", "script"),
        ("id: model equivalent of the bundled files carries SYNTHETIC",
         _script_cli(["model", "equivalent", "--stiffness-file", str(s), "--modes-file", str(m), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "if d['identity']['synthetic'] is True and d['identity']['robot'] == 'irb6600-175-2.55': print('OK'); sys.exit(0)\n"
                     "print(d['identity']); sys.exit(1)"), "", "script"),
        ("id: lobes, model files of different robots",
         [*lob, "--stiffness-file", sk, "--modes-file", m], r"s_kuka\.json.*kr240", "error"),
        ("id: lobes, modes of another posture",
         [*lob, "--stiffness-file", s, "--modes-file", m_post], r"m_other_posture\.json.*posture", "error"),
        ("id: simulate boring, model files of different robots",
         [*sim, "--stiffness-file", s, "--modes-file", m_kuka], r"m_kuka\.json.*kr240", "error"),
        ("id: plan posture, another robot's stiffness file",
         ["plan", "posture", p_kuka], r"joint_stiffness\.json.*kr240-r2900", "error"),
        ("id: plan posture, another robot's modes file",
         ["plan", "posture", p_mkuka], r"modes\.json.*kr240-r2900", "error"),
        ("id: robot stiffness, a stiffness file of 5 joints",
         ["robot", "stiffness", Q, "--joint-stiffness-file", s5], r"s_five\.json.*5 joint stiffnesses", "error"),
        # ---- unit slips in identification / model files
        ("unit: joint angles in radians to --joints-deg (a warning)",
         _script_cli(["robot", "fk", "--joints-deg=-0.84,0.96,0.12,-0.95,1.87,-0.38", "--json"],
                     "if 'radians?' in ' '.join(r.stderr.split()): print('OK'); sys.exit(0)\n"
                     "print(r.stderr[-300:]); sys.exit(1)"), "", "script"),
        ("unit: equivalent model with zero damping",
         [*lob, "--equivalent-file", eq_z], r"eq_zero_damping\.json.*damping", "error"),
        ("unit: equivalent model frequency in rad/s (mass does not fit)",
         [*lob, "--equivalent-file", eq_rad], r"eq_rad_per_s\.json.*mass_kg\.y", "error"),
        ("unit: equivalent model with a negative mass",
         [*lob, "--equivalent-file", eq_negm], r"eq_negative_mass\.json.*mass_kg\.z", "error"),
        ("unit: equivalent model of another robot than its name (identity kept)",
         _script_cli(["lobes", str(EX / "boring_process.toml"), "--method", "frequency", "--equivalent-file", str(eq_kuka), "--json"],
                     "print('OK' if r.returncode == 0 else r.stderr[-300:]); sys.exit(0 if r.returncode == 0 else 1)"), "", "script"),
        ("unit: plan with joint stiffnesses x1000 (calibration warning)",
         _script_cli(["plan", "posture", str(p_1000), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "if d['warnings'] and 'joint_stiffness.json' in d['warnings'][0]: print('OK'); sys.exit(0)\n"
                     "print(d['calibration']['rms_frequency_residual_percent']); sys.exit(1)"), "", "script"),
        ("unit: plan with mode frequencies in rad/s (outside the file's band, or a calibration warning)",
         _script_cli(["plan", "posture", str(p_mrad), "--json"],
                     "e = ' '.join(r.stderr.split())\n"
                     "if r.returncode == 2 and 'modes.json' in e and 'band' in e: print('OK'); sys.exit(0)\n"
                     "d = json.loads(r.stdout)\n"
                     "if d['warnings']: print('OK'); sys.exit(0)\n"
                     "print('no warning', d['calibration']['rms_frequency_residual_percent']); sys.exit(1)"), "", "script"),
        ("unit: approach angle in radians",
         [*lob, "--stiffness-file", s, "--modes-file", m, "--json"][:2] + ["--stiffness-file", s, "--modes-file", m],
         r"", "error"),  # replaced below
        ("unit: approach angle 110 deg (beyond 107.5)",
         ["lobes", W / "b110.toml", "--stiffness-file", s, "--modes-file", m],
         r"b110\.toml.*insert\.approach_angle_deg.*107\.5", "error"),
        ("unit: a 95 deg boring bar is accepted",
         _script_cli(["lobes", str(W / "b95.toml"), "--stiffness-file", str(s), "--modes-file", str(m), "--method", "frequency", "--json"],
                     "print('OK' if r.returncode == 0 else r.stderr[-300:]); sys.exit(0 if r.returncode == 0 else 1)"), "", "script"),
        ("unit: unknown material",
         ["lobes", W / "bmat.toml", "--stiffness-file", s, "--modes-file", m],
         r"bmat\.toml.*coefficients.*Inconel", "error"),
        # ---- planner
        ("plan: a vertical bore axis is planned",
         _script_cli(["plan", "posture", str(p_vert), "--json"],
                     "d = json.loads(r.stdout)\n"
                     "ok = r.returncode == 0 and d['recommended']['critical_depth_mm'] > 0\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("plan: rotation step 1e-6 deg", ["plan", "posture", p_step],
         r"p\.toml.*rotation_step_deg", "error"),
        ("plan: unknown robot name", ["plan", "posture", p_robot],
         r"p\.toml.*robot\.name.*irb6600", "error"),
        ("plan: zero bore axis", ["plan", "posture", p_axis], r"p\.toml.*bore\.axis", "error"),
        # ---- FE validation measured file (the FE never runs: refused before)
        ("fe: measured forces in kN per mm of width",
         ["fe", "validate", fe, "--measured", W / "meas_kN.json", "--out", W / "fe_out1"],
         r"meas_kN\.json.*units\.Fc", "error"),
        ("fe: an inverted chip ratio",
         ["fe", "validate", fe, "--measured", W / "meas_inverted.json", "--out", W / "fe_out2"],
         r"meas_inverted\.json.*chip_ratio", "error"),
        ("fe: measured forces in N/m",
         ["fe", "validate", fe, "--measured", W / "meas_Nm.json", "--out", W / "fe_out3"],
         r"meas_Nm\.json.*units\.Fc", "error"),
        ("fe: --out is a file", ["fe", "validate", fe, "--measured", W / "meas_Nm.json", "--out", sk],
         r"--out|meas_Nm", "error"),
        # ---- CSV and UFF
        ("csv: a ';' separated campaign is read",
         _script_cli(["identify", "stiffness", str(W / "semi.csv"), "--robot-file", str(KUKA), "--json"],
                     "ok = r.returncode == 0 and json.loads(r.stdout)['residual_test']['passed']\n"
                     "print('OK' if ok else r.stderr[-300:]); sys.exit(0 if ok else 1)"), "", "script"),
        ("csv: a space separated campaign is named",
         ["identify", "stiffness", W / "space.csv", "--robot-file", KUKA], r"space\.csv.*separated", "error"),
        ("csv: a CSV given as a UFF hammer test", ["identify", "modes", W / "hammer.uff"],
         r"hammer\.uff.*CSV", "error"),
        # ---- sweep
        ("sweep: --scheduler to a server that accepts and never answers",
         [PY, "-c", _SILENT, str(EX / "sweep_demo.toml"), "{d}"], "", "script"),
        ("sweep: unknown runner", ["sweep", sw, "--out", W / "sw_store", "--workers", "0"],
         r"sw_runner\.toml.*sweep\.runner.*boreing", "error"),
        # ---- Python API
        ("api: stiffness_at_pose with another robot's file and robot=",
         _script_api("api.stiffness_at_pose(json.loads((W / 's_kuka.json').read_text()), robot='irb6600-175-2.55')",
                     ["kr240-r2900", "irb6600-175-2.55"]), "", "script"),
        ("api: stiffness_at_pose(tcp_m=[0, 0, 300])",
         _script_api("api.stiffness_at_pose([3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5], tcp_m=[0, 0, 300])", ["tcp_m"]), "", "script"),
        ("api: stiffness_at_pose(joints_deg='abc')",
         _script_api("api.stiffness_at_pose([3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5], joints_deg='abc')", ["joints_deg"]), "", "script"),
        ("api: stiffness_at_pose(robot=5)",
         _script_api("api.stiffness_at_pose([3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5], robot=5)", ["robot"]), "", "script"),
        ("api: stiffness_at_pose(wrench_N_Nm=[1, 2])",
         _script_api("api.stiffness_at_pose([3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5], wrench_N_Nm=[1, 2])", ["wrench_N_Nm"]), "", "script"),
        ("api: stiffness_at_pose('nonsense')",
         _script_api("api.stiffness_at_pose('nonsense')", ["joint_stiffness"]), "", "script"),
        ("api: identify_modes(band_Hz='3-60')",
         _script_api("api.identify_modes(band_Hz='3-60')", ["band_Hz"]), "", "script"),
        ("api: identify_modes(n_modes='5')",
         _script_api("api.identify_modes(n_modes='5')", ["n_modes"]), "", "script"),
        ("api: load_campaign(5)", _script_api("api.load_campaign(5)", ["path"]), "", "script"),
        ("api: identify_joint_stiffness(sigma_m='10')",
         _script_api("api.identify_joint_stiffness(sigma_m='10')", ["sigma_m"]), "", "script"),
        ("api: cutting_coefficients('fast')",
         _script_api("api.cutting_coefficients('fast')", ["cutting_speed_m_per_min"]), "", "script"),
        ("api: load_hammer_test(7)", _script_api("api.load_hammer_test(7)", ["path"]), "", "script"),
        ("api: equivalent_model of another robot's stiffness and the bundled modes",
         _script_api("api.equivalent_model(json.loads((W / 's_kuka.json').read_text()), json.loads((W / 'm.json').read_text()))",
                     ["kr240-r2900", "irb6600-175-2.55"]), "", "script"),
        ("api: equivalent_model('x', 'y')", _script_api("api.equivalent_model('x', 'y')", ["stiffness"]), "", "script"),
        ("api: stability_lobes(123)", _script_api("api.stability_lobes(123)", ["config"]), "", "script"),
        ("api: simulate_boring with an equivalent model of zero damping",
         _script_api("api.simulate_boring(r'" + str(EX / "boring_process.toml") + "', "
                     "json.loads((W / 'eq_zero_damping.json').read_text()))", ["damping"]),
         "", "script"),
    ]
    # the radians-angle case with its own file
    cases = [c for c in cases if c[0] != "unit: approach angle in radians"]
    cases.append(("unit: approach angle in radians",
                  ["lobes", W / "brad.toml", "--stiffness-file", s, "--modes-file", m],
                  r"brad\.toml.*insert\.approach_angle_deg.*radians", "error"))
    out = []
    for desc, argv, pat, mode in cases:
        argv = [str(a).replace("{W}", str(W)) for a in argv]
        out.append((desc, argv, pat, mode))
    return out
