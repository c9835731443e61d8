"""Identity where files are handed on: a plan config without a robot adopts the files'
robot and says so; the boring frame's X hint; a modal model that does not fit the
stiffness file; identity in the coefficients and FE results JSON."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import ConfigError

runner = CliRunner()
REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
KUKA = EX / "robots" / "kr240-r2900.toml"


def _plan_copy(tmp_path: Path, *, robot_section: bool = True, **subs: str) -> Path:
    shutil.copytree(EX / "plan_paper_bore", tmp_path / "plan_paper_bore")
    cfg = (EX / "plan_paper_bore.toml").read_text().replace(
        '"../src/robobore', f'"{REPO}/src/robobore')
    if not robot_section:
        cfg = re.sub(r'\[robot\]\nname = "irb6600-175-2.55"\n', "", cfg)
        assert "[robot]" not in cfg
    for a, b in subs.items():
        assert a in cfg, a
        cfg = cfg.replace(a, b)
    p = tmp_path / "p.toml"
    p.write_text(cfg)
    return p


def _set_identity(path: Path, **identity) -> None:
    d = json.loads(path.read_text())
    d.setdefault("identity", {}).update(identity)
    path.write_text(json.dumps(d))


# --- a plan config without robot.name ---------------------------------------------------------


def test_plan_without_robot_adopts_the_stiffness_files_robot_and_says_so(tmp_path):
    from robobore.plan.config import load_plan_config

    p = _plan_copy(tmp_path, robot_section=False)
    kuka = {"robot": "kr240-r2900", "robot_hash": "5bff4dea45217869", "robot_file": str(KUKA)}
    for name in ("joint_stiffness.json", "modes.json"):
        _set_identity(tmp_path / "plan_paper_bore" / name, **kuka)
    inp = load_plan_config(p)
    assert inp.robot.name == "kr240-r2900"
    assert len(inp.notes) == 1 and "kr240-r2900" in inp.notes[0]
    assert "joint_stiffness.json" in inp.notes[0]


def test_plan_without_robot_keeps_the_default_for_the_bundled_files(tmp_path):
    from robobore.plan.config import load_plan_config

    inp = load_plan_config(_plan_copy(tmp_path, robot_section=False))
    assert inp.robot.name == "irb6600-175-2.55"
    assert inp.notes and "irb6600-175-2.55" in inp.notes[0]


def test_plan_without_robot_stiffness_and_modes_of_different_robots_refused(tmp_path):
    from robobore.plan.config import load_plan_config

    p = _plan_copy(tmp_path, robot_section=False)
    _set_identity(tmp_path / "plan_paper_bore" / "joint_stiffness.json", robot="kr240-r2900",
                  robot_hash="5bff4dea45217869", robot_file=str(KUKA))
    _set_identity(tmp_path / "plan_paper_bore" / "modes.json", robot="irb6600-175-2.55")
    with pytest.raises(ConfigError) as ei:
        load_plan_config(p)
    msg = str(ei.value)
    assert "kr240-r2900" in msg and "irb6600-175-2.55" in msg and "modes.json" in msg


def test_plan_named_robot_still_refuses_another_robots_file(tmp_path):
    from robobore.plan.config import load_plan_config

    p = _plan_copy(tmp_path)
    _set_identity(tmp_path / "plan_paper_bore" / "joint_stiffness.json", robot="kr240-r2900",
                  robot_hash="5bff4dea45217869")
    with pytest.raises(ConfigError, match="robot.name"):
        load_plan_config(p)


def test_plan_without_robot_old_file_naming_a_robot_is_adopted(tmp_path):
    """A stiffness file without identity block but with its top-level "robot" key."""
    from robobore.plan.config import load_plan_config

    p = _plan_copy(tmp_path, robot_section=False)
    for name in ("joint_stiffness.json", "modes.json"):
        f = tmp_path / "plan_paper_bore" / name
        d = json.loads(f.read_text())
        d.pop("identity", None)
        f.write_text(json.dumps(d))
    inp = load_plan_config(p)
    assert inp.robot.name == json.loads(
        (tmp_path / "plan_paper_bore" / "joint_stiffness.json").read_text())["robot"]
    assert inp.notes


# --- the boring frame's X hint ---------------------------------------------------------------


@pytest.mark.parametrize("axis", [(0, 0, -1.0), (0, 0, 1.0), (1.0, 0, 0), (0.3, -0.5, 0.8)])
def test_x_hint_sets_the_boring_frames_x(axis):
    from robobore.plan.candidates import boring_frame

    z = np.asarray(axis) / np.linalg.norm(axis)
    h = np.array([0.2, 1.0, 0.1])
    R = boring_frame(np.asarray(axis, float), h)
    x = h - (h @ z) * z
    assert np.allclose(R[:, 0], x / np.linalg.norm(x))
    assert np.allclose(R[:, 2], z)
    assert np.allclose(R.T @ R, np.eye(3)) and np.linalg.det(R) > 0


def test_x_hint_along_the_bore_axis_or_not_a_vector_refused():
    from robobore.robot.stiffness import process_frame, x_hint_arg

    R = np.column_stack([np.zeros(3), np.zeros(3), [0, 0, 1.0]])
    with pytest.raises(ConfigError, match="along the bore axis"):
        process_frame(R, "boring", x_hint=[0, 0, 2.0])
    for bad in ([0, 0, 0], [1, 2], ["a", 1, 2], [np.nan, 0, 1]):
        with pytest.raises(ConfigError, match="not a direction"):
            x_hint_arg(bad)


def test_plan_config_x_hint_checked_and_rotated_with_the_part(tmp_path):
    from robobore.plan.config import load_plan_config

    axis = "axis = [-0.9992052193, -0.0398392954, -0.0013267225]"
    p = _plan_copy(tmp_path, **{axis: "axis = [0.0, 0.0, -1.0]\nx_hint = [0.0, 0.0, 1.0]"})
    with pytest.raises(ConfigError) as ei:
        load_plan_config(p)
    assert ei.value.field == "bore.x_hint" and str(p) in str(ei.value)
    p.write_text(p.read_text().replace("x_hint = [0.0, 0.0, 1.0]", "x_hint = [0.0, 2.0, 0.0]"))
    inp = load_plan_config(p)
    assert np.allclose(inp.x_hint, [0, 1, 0])
    inp2 = load_plan_config(p, x_hint=[1.0, 0.0, 0.0])  # the CLI's --x-hint wins
    assert np.allclose(inp2.x_hint, [1, 0, 0])


def test_plan_posture_vertical_bore_with_x_hint(tmp_path):
    """A vertical bore the paper's robot reaches (the measured posture's tool point, axis
    down): the plan's boring frame takes X from --x-hint, and the directional stiffness of
    the recommended posture is the same posture's with X and Y from that frame."""
    from robobore.plan.posture import plan_posture

    axis = "axis = [-0.9992052193, -0.0398392954, -0.0013267225]"
    p = _plan_copy(tmp_path, **{axis: "axis = [0.0, 0.0, -1.0]",
                                "rotation_step_deg = 1.0": "rotation_step_deg = 30.0"})
    p.write_text(re.sub(r"(?s)\[workspace\].*", "", p.read_text()))
    r0 = plan_posture(p).to_dict()
    r1 = plan_posture(p, x_hint=[0.0, 1.0, 0.0]).to_dict()
    cols0 = np.array(r0["bore"]["boring_frame_columns"])
    cols1 = np.array(r1["bore"]["boring_frame_columns"])
    assert np.allclose(cols0[0], [1, 0, 0]) and np.allclose(cols1[0], [0, 1, 0])
    assert r1["bore"]["x_hint"] == [0.0, 1.0, 0.0]
    # the same candidates; X and Y stiffness swap roles between the two frames
    k0 = {tuple(np.round(c["joints_deg"], 3)): c["directional_stiffness_N_per_m"]
          for c in r0["candidates"]}
    k1 = {tuple(np.round(c["joints_deg"], 3)): c["directional_stiffness_N_per_m"]
          for c in r1["candidates"]}
    common = sorted(set(k0) & set(k1))
    assert common
    for q in common:
        assert k1[q]["x"] == pytest.approx(k0[q]["y"], rel=1e-9)
        assert k1[q]["y"] == pytest.approx(k0[q]["x"], rel=1e-9)
        assert k1[q]["z"] == pytest.approx(k0[q]["z"], rel=1e-9)


def test_plan_cli_x_hint_option_parsed(tmp_path):
    p = _plan_copy(tmp_path)
    r = runner.invoke(app, ["plan", "posture", str(p), "--x-hint", "1,2"])
    assert r.exit_code == 2 and "--x-hint" in r.output


# --- identity of the cutting coefficients -----------------------------------------------------

TC4_FILE = REPO / "src" / "robobore" / "data" / "paper_example" / "tc4_fe_coefficients.json"


def _dyn_cfg(tmp_path: Path, coef_file: Path, *, material: str | None = None,
             **subs: str) -> Path:
    cfg = (EX / "boring_paper.toml").read_text()
    sec = f'file = "{coef_file}"' + (f'\nmaterial = "{material}"' if material else "")
    cfg = cfg.replace('[coefficients]\nmaterial = "TC4"', f"[coefficients]\n{sec}")
    for a, b in subs.items():
        assert a in cfg, a
        cfg = cfg.replace(a, b)
    p = tmp_path / "d.toml"
    p.write_text(cfg)
    return p


def _coefficients(path: Path):
    from robobore.dynamics.config import build_coefficients, load_dynamics_config

    cfg, _ = load_dynamics_config(path)
    return build_coefficients(cfg, str(path))


def test_calibration_writes_the_coefficients_identity():
    """The identity block calibrate() writes: material, the insert edge, what produced it."""
    from robobore.io.identity import cut_identity_of, make_identity

    d = json.loads(TC4_FILE.read_text())
    ident = cut_identity_of(d, str(TC4_FILE))  # the bundled file: its top-level keys
    assert ident["material"] == "TC4"
    assert ident["insert"] == {"rake_deg": 7.0, "edge_radius_um": 20.0, "inclination_deg": 0.0,
                               "clearance_deg": 7.0}
    blk = make_identity("cutting coefficients", material="TC4", insert=d["insert"])
    assert blk["insert"]["rake_deg"] == 7.0 and blk["material"] == "TC4"


def test_coefficients_file_of_the_configs_insert_and_material_accepted(tmp_path):
    c = _coefficients(_dyn_cfg(tmp_path, TC4_FILE, material="Ti-6Al-4V"))
    assert c.Ktc > 0 and "not checked" not in c.provenance


def test_coefficients_file_for_another_rake_refused_naming_both(tmp_path):
    p = _dyn_cfg(tmp_path, TC4_FILE, **{"rake_deg = 7.0": "rake_deg = 0.0"})
    with pytest.raises(ConfigError) as ei:
        _coefficients(p)
    msg = str(ei.value)
    assert str(TC4_FILE) in msg and str(p) in msg and "rake_deg = 7" in msg
    assert "rake_deg = 0" in msg


def test_coefficients_file_for_another_edge_radius_refused(tmp_path):
    p = _dyn_cfg(tmp_path, TC4_FILE, **{"edge_radius_um = 20.0": "edge_radius_um = 50.0"})
    with pytest.raises(ConfigError, match="edge_radius_um"):
        _coefficients(p)


def test_coefficients_file_for_another_material_refused(tmp_path):
    f = tmp_path / "inconel.json"
    d = json.loads(TC4_FILE.read_text())
    d["identity"] = {"kind": "cutting coefficients", "material": "IN718",
                     "insert": d["insert"], "source": "test"}
    f.write_text(json.dumps(d))
    with pytest.raises(ConfigError) as ei:
        _coefficients(_dyn_cfg(tmp_path, f, material="TC4"))
    assert "IN718" in str(ei.value) and "TC4" in str(ei.value) and str(f) in str(ei.value)
    # without coefficients.material the config does not say: accepted
    assert _coefficients(_dyn_cfg(tmp_path, f)).Ktc > 0


def test_old_coefficients_file_without_identity_accepted_with_a_note(tmp_path):
    f = tmp_path / "old.json"
    d = json.loads(TC4_FILE.read_text())
    for k in ("material", "insert", "identity"):
        d.pop(k, None)
    f.write_text(json.dumps(d))
    c = _coefficients(_dyn_cfg(tmp_path, f, **{"rake_deg = 7.0": "rake_deg = 0.0"}))
    assert str(f) in c.provenance and "not checked" in c.provenance


def test_malformed_coefficients_identity_named(tmp_path):
    f = tmp_path / "bad.json"
    d = json.loads(TC4_FILE.read_text())
    d["identity"] = {"kind": "cutting coefficients", "insert": {"rake_deg": "seven"}}
    f.write_text(json.dumps(d))
    with pytest.raises(ConfigError) as ei:
        _coefficients(_dyn_cfg(tmp_path, f))
    assert ei.value.field == "identity.insert.rake_deg" and str(f) in str(ei.value)


# --- identity of the FE results ---------------------------------------------------------------


def test_fe_result_identity_records_material_and_insert():
    from robobore.cutting.fe.config.boring3d import load_boring_config
    from robobore.cutting.fe.config.orthogonal import load_fe_config
    from robobore.io.identity import fe_identity, read_identity

    cfg = load_fe_config(EX / "fe_orthogonal.toml")
    ident = fe_identity("fe orthogonal", cfg, "fe_orthogonal.toml")
    assert ident["material"] == cfg.material.name
    assert ident["insert"]["rake_deg"] == cfg.tool.rake_deg
    assert ident["insert"]["edge_radius_um"] == cfg.tool.edge_radius_um
    assert "fe_orthogonal.toml" in ident["source"] and ident["synthetic"] is None
    assert read_identity({"identity": ident}, "x.json")["insert"] == ident["insert"]
    bcfg = load_boring_config(EX / "fe_boring_paper.toml")
    bident = fe_identity("fe boring", bcfg, "fe_boring_paper.toml")
    assert bident["insert"]["nose_radius_mm"] == bcfg.insert.nose_radius_mm
    assert bident["insert"]["rake_deg"] == bcfg.insert.rake_deg


def test_fe_boring_refuses_a_coefficients_file_of_another_insert(tmp_path):
    """Refused before the FE run starts (the check reads the file and the config only)."""
    d = json.loads(TC4_FILE.read_text())
    d["identity"] = {"kind": "cutting coefficients", "material": "TC4",
                     "insert": {"rake_deg": 15.0, "edge_radius_um": 20.0,
                                "inclination_deg": 0.0}}
    f = tmp_path / "rake15.json"
    f.write_text(json.dumps(d))
    r = runner.invoke(app, ["fe", "boring", str(EX / "fe_boring_paper.toml"),
                            "--coefficients", str(f)])
    assert r.exit_code == 2, r.output
    out = " ".join(r.output.split())
    assert "rake15.json" in out and "rake_deg = 15" in out


def test_calibrate_forces_writes_an_identity_the_readers_check(tmp_path):
    """calibrate() (on fitted-to-known forces, no FE run) writes the identity block; the
    written file is refused by a config whose insert has another edge radius."""
    from robobore.cutting import calibrate as cal
    from robobore.cutting import calibration_config as calcfg

    cfg = calcfg.calibration_from_mapping(
        {"calibration": {"uncut_chip_thickness_um": [60.0, 90.0],
                         "cutting_speed_m_per_min": [40.0]},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 10.0, "clearance_deg": 7.0},
         "material": {"name": "TC4"}}, source="test.toml")
    recs = [{"h_um": h, "vc_m_per_min": 40.0, "Fc_N_per_m": 3e4 + 1.6e9 * h * 1e-6,
             "Ff_N_per_m": 4e4 + 0.4e9 * h * 1e-6, "cached": False,
             "fe": {"chip_ratio": None}} for h in (60.0, 90.0)]
    data = cal.calibrate(cfg, recs)
    ident = data["identity"]
    assert ident["kind"] == "cutting coefficients" and ident["material"] == cfg.material
    assert ident["insert"]["edge_radius_um"] == 10.0 and "calibrate forces" in ident["source"]
    f = tmp_path / "c.json"
    f.write_text(json.dumps(data))
    with pytest.raises(ConfigError, match="edge_radius_um = 10"):
        _coefficients(_dyn_cfg(tmp_path, f))  # boring_paper.toml: edge radius 20 um
    ok = _dyn_cfg(tmp_path, f, **{"edge_radius_um = 20.0": "edge_radius_um = 10.0"})
    assert _coefficients(ok).Ktc == pytest.approx(1.6e9, rel=1e-9)


# --- a modal model that does not fit the stiffness file --------------------------------------


@pytest.fixture(scope="module")
def example_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("ex")
    out = {}
    for kind in ("stiffness", "modes"):
        r = runner.invoke(app, ["identify", kind, "--example", "--json"])
        assert r.exit_code == 0, r.output
        out[kind] = d / f"{kind}.json"
        out[kind].write_text(r.stdout)
    return out


def _modes_variant(src: Path, dst: Path, how: str) -> Path:
    d = json.loads(src.read_text())
    if how == "one":
        d["modes"] = d["modes"][:1]
    elif how == "two":
        d["modes"] = d["modes"][:2]
    elif how == "kHz":
        d["modes"][0]["frequency_Hz"] *= 10
    elif how == "tripled":
        d["modes"] = d["modes"] * 3
    dst.write_text(json.dumps(d))
    return dst


@pytest.mark.parametrize("how,words", [("one", "has 1 mode"), ("two", "has 2 mode"),
                                       ("kHz", "outside the band")])
def test_equivalent_refuses_modes_that_do_not_fit(example_files, tmp_path, how, words):
    m = _modes_variant(example_files["modes"], tmp_path / f"m_{how}.json", how)
    r = runner.invoke(app, ["model", "equivalent", "--stiffness-file",
                            str(example_files["stiffness"]), "--modes-file", str(m)])
    assert r.exit_code == 2, r.output
    out = " ".join(r.output.split())
    assert words in out and m.name in out
    if how != "kHz":
        assert "stiffness.json" in out


@pytest.mark.parametrize("how,words", [("one", "has 1 mode"), ("two", "has 2 mode"),
                                       ("kHz", "outside the band"), ("tripled", "has 15 modes")])
def test_plan_refuses_modes_that_do_not_fit(example_files, tmp_path, how, words):
    from robobore.errors import DataError
    from robobore.plan.config import load_plan_config

    p = _plan_copy(tmp_path)
    mf = tmp_path / "plan_paper_bore" / "modes.json"
    _modes_variant(example_files["modes"], mf, how)
    with pytest.raises((ConfigError, DataError)) as ei:
        load_plan_config(p)
    msg = str(ei.value)
    assert words in msg and str(mf) in msg
    if how in ("one", "two", "tripled"):
        assert "joint_stiffness.json" in msg


def test_plan_accepts_the_example_modes_file(example_files, tmp_path):
    from robobore.plan.config import load_plan_config

    p = _plan_copy(tmp_path)
    shutil.copy(example_files["modes"], tmp_path / "plan_paper_bore" / "modes.json")
    assert load_plan_config(p).modes_f_Hz.size == 5


def test_api_directional_stiffness_adopts_the_files_robot_and_says_so():
    """api.directional_stiffness(robot=None) of a stiffness that records the KUKA-like
    robot uses that robot's kinematics (the same numbers as robot=its file) and warns."""
    import warnings

    from robobore import api

    js = {"joint_stiffness_Nm_per_rad": [3e6, 4e6, 2.5e6, 5e5, 4.5e5, 3e5],
          "identity": {"kind": "joint stiffness", "robot": "kr240-r2900",
                       "robot_hash": "5bff4dea45217869", "robot_file": str(KUKA)}}
    q = [20, 20, 10, 0, -30, 0]
    with pytest.warns(UserWarning, match="taken from"):
        k = api.directional_stiffness(js, q)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ref = api.directional_stiffness(js, q, robot=str(KUKA))
        irb = api.directional_stiffness({"joint_stiffness_Nm_per_rad":
                                         js["joint_stiffness_Nm_per_rad"]}, q)
    assert k == ref and k != irb
    with pytest.raises(ConfigError, match="kr240-r2900"):
        api.directional_stiffness(js, q, robot="irb6600-175-2.55")


def test_fe_validate_announces_its_default_store_and_records_the_identity(tmp_path,
                                                                           monkeypatch):
    """Without --out the resumable store goes to ./fe_validate_<config>, said on stderr
    before the work; the JSON carries the FE identity (the FE run itself is stubbed)."""
    shared = REPO.parent / "shared" / "data" / "ti64_orthogonal_cutting_forces.json"
    meas = shared if shared.is_file() else (
        REPO / "src" / "robobore" / "cutting" / "coefficients" /
        "ti64_orthogonal_cutting_forces.json")
    from robobore.cutting.fe.models.results import (
        PerQuantity,
        ValidationResult,
        ValidationSummary,
    )

    none = PerQuantity(None, None, None)
    monkeypatch.setattr("robobore.cutting.fe.models.validate.run_validation",
                        lambda *a, **k: ValidationResult(
                            points=(), summary=ValidationSummary(none, none, none),
                            config="<stub>", device="cpu", out_dir=None))
    monkeypatch.chdir(tmp_path)
    r = runner.invoke(app, ["fe", "validate", str(EX / "fe_orthogonal.toml"), "--measured",
                            str(meas), "--json"])
    assert r.exit_code == 0, r.output
    out = " ".join(r.output.split())
    assert "no --out given" in out and "fe_validate_fe_orthogonal" in out
    d = json.loads(r.stdout[r.stdout.index("{"):])
    assert d["identity"]["kind"] == "fe validate" and d["identity"]["material"]
