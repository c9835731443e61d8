"""robobore plan posture: the paper's bore (acceptance), the JSON contract, outputs, and the
errors for bad input. Identification inputs are computed from the bundled (SYNTHETIC) data at
test time, so the tests do not depend on their exact numbers."""

from __future__ import annotations

import dataclasses
import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import ConfigError, DataError, InputError
from robobore.io.records import json_mismatches
from robobore.io.results import to_jsonable
from robobore.plan.posture import plan_posture
from robobore.robot.description import get_robot
from robobore.robot.kinematics import fk

runner = CliRunner()
EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "plan_paper_bore.toml"
COEFFS = Path(__file__).resolve().parents[2] / "src" / "robobore" / "data" / "paper_example" / \
    "tc4_fe_coefficients.json"
PAPER_Q_DEG = [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95]


@pytest.fixture(scope="module")
def ident(tmp_path_factory):
    d = tmp_path_factory.mktemp("ident")
    for what, name in (("stiffness", "joint_stiffness.json"), ("modes", "modes.json")):
        r = runner.invoke(app, ["identify", what, "--example", "--json"])
        assert r.exit_code == 0, r.output
        (d / name).write_text(r.stdout)
    return d


def write_config(folder: Path, ident: Path, **edits: str) -> Path:
    """The example config with the identification files of ``ident`` copied next to it and
    ``edits`` (key line prefix -> replacement line) applied."""
    folder.mkdir(parents=True, exist_ok=True)
    sub = folder / "id"
    sub.mkdir(exist_ok=True)
    for f in ident.iterdir():
        shutil.copy(f, sub / f.name)
    text = EXAMPLE.read_text()
    text = text.replace("plan_paper_bore/joint_stiffness.json", "id/joint_stiffness.json")
    text = text.replace("plan_paper_bore/modes.json", "id/modes.json")
    text = text.replace('"../src/robobore/data/paper_example/tc4_fe_coefficients.json"',
                        json.dumps(str(COEFFS)))
    text = re.sub(r"\[workspace\].*", "", text, flags=re.S)
    for key, line in edits.items():
        text, n = re.subn(rf"(?m)^{re.escape(key)} =.*$", line, text)
        assert n == 1, key
    p = folder / "plan.toml"
    p.write_text(text)
    return p


@pytest.fixture(scope="module")
def paper_result(ident, tmp_path_factory):
    cfg = write_config(tmp_path_factory.mktemp("paper"), ident)
    return plan_posture(cfg)


def test_paper_bore_every_candidate_reaches_within_limits(paper_result):
    r = paper_result.to_dict()
    rb = get_robot("irb6600-175-2.55")
    point, axis = np.asarray(r["bore"]["point_m"]), np.asarray(r["bore"]["axis"])
    Q = np.radians([c["joints_deg"] for c in r["candidates"]])
    assert Q.shape[0] == r["counts"]["candidates"] > 0
    T = fk(rb, Q, r["tcp_m"])
    assert np.linalg.norm(T[:, :3, 3] - point, axis=1).max() <= 1e-4
    ang = np.degrees(np.arccos(np.clip(T[:, :3, 2] @ axis, -1, 1)))
    assert ang.max() <= 0.05
    lo, hi = np.array(rb.lower_limit_rad), np.array(rb.upper_limit_rad)
    assert np.all((Q >= lo - 1e-9) & (Q <= hi + 1e-9))
    assert all(c["singularity_measure"] >= 0.02 for c in r["candidates"])
    # 360 rotations x 8 branches tried
    assert r["counts"]["rotations"] == 360 and r["counts"]["ik_solutions_tried"] == 2880


def test_paper_bore_recommended_is_best_and_paper_posture_is_a_candidate(paper_result):
    r = paper_result.to_dict()
    rated = [c for c in r["candidates"]
             if c["critical_depth_method"] == "semi-discretization"]
    crit = np.array([c["critical_depth_mm"] for c in rated], float)
    assert r["criterion"] == "critical_depth" and len(rated) >= 2
    assert r["recommended"]["critical_depth_mm"] >= crit.max() * (1 - 1e-6)
    # the rating is the semi-discretisation limit at the cutting speed; the lowest limit of
    # the lobes over the speed range is reported beside it
    lm = r["lobes"]["measured"]
    assert lm["method"] == "semi-discretization"
    assert lm["cutting_speed_rpm"] == r["cutting"]["speed_rpm"]
    assert r["measured"]["critical_depth_mm"] == pytest.approx(
        lm["critical_depth_at_speed_mm"], rel=1e-12, abs=1e-12)
    assert r["measured"]["critical_depth_range_min_mm"] == pytest.approx(
        min(lm["critical_depth_mm"]), rel=1e-12, abs=1e-12)
    assert r["measured"] is not None
    assert np.allclose(r["measured"]["joints_deg"], PAPER_Q_DEG, atol=1e-6)
    assert r["measured_posture_reaches_bore"]


def test_rated_at_the_cutting_speed_as_the_lobes_and_simulate_boring(paper_result):
    """On the bundled robot the lowest limit over 150-1100 r/min is 0 at every rated
    candidate (some speed has no chatter-free depth), which ranks nothing; the rating at the
    [cutting] speed is positive. Planner vs lobes at the same posture and model: the
    semi-discretisation answer of `robobore lobes` at that speed on the structure the plan
    rated (its tool_point_modes as a [structure]) within 1 %; its feed amplitude vs
    `simulate boring` on that structure within 10 % (measured: 0 % and 4e-4 %)."""
    from robobore.dynamics.api import critical_depth_at, run_boring

    r = paper_result.to_dict()
    rated = [c for c in r["candidates"] if c["critical_depth_method"] == "semi-discretization"]
    assert all(c["critical_depth_range_min_mm"] == 0.0 for c in rated)
    assert all(c["critical_depth_mm"] > 0.0 for c in rated)
    co = paper_result.arrays.inputs.cfg
    cfg = {"structure": {"modes": r["lobes"]["measured"]["tool_point_modes"]},
           "insert": co.insert.model_dump(), "bore": {"diameter_mm": co.bore.diameter_mm},
           "cutting": co.cutting.model_dump(),
           "coefficients": co.coefficients.model_dump(exclude_none=True)}
    at = critical_depth_at(cfg, co.cutting.speed_rpm)
    assert r["measured"]["critical_depth_mm"] == pytest.approx(at.critical_depth_mm,
                                                               rel=0.01)
    sim = run_boring(cfg)
    assert not sim.chatter
    assert r["measured"]["feed_amplitude_um"] == pytest.approx(sim.feed_amplitude_um,
                                                               rel=0.10)


def test_json_contract(paper_result):
    r = paper_result.to_dict()
    json.dumps(r)  # serialisable as is
    assert {"recommended", "candidates", "criterion", "wall_time_s"} <= set(r)
    # the bundled inputs belong together (calibration 29 % rms: no mix-up warning), but the
    # calibration's per-mode residuals above 10 % and its scale factors at their bounds are
    # said, and the flat map (a tool axis along the flange axis) too
    assert not any("may not belong together" in w for w in r["warnings"])
    assert any("identified mode" in w and "above 10 %" in w for w in r["warnings"])
    assert any("at the bounds" in w for w in r["warnings"])
    assert r["identity"]["robot"] == "irb6600-175-2.55" and r["identity"]["synthetic"]
    for c in [r["recommended"], *r["candidates"][:5]]:
        assert len(c["joints_deg"]) == 6
        assert isinstance(c["tool_axis_rotation_deg"], float)
        assert isinstance(c["branch"], int)
        assert set(c["directional_stiffness_N_per_m"]) == {"x", "y", "z"}
        assert all({"frequency_Hz", "damping_ratio"} <= set(m) for m in c["modes"])
        assert c["critical_depth_mm"] >= 0
        assert c["critical_depth_method"] in ("semi-discretization", "frequency (screening)")
    cal = r["calibration"]
    assert len(cal["frequency_residual_percent"]) == cal["matched_modes"]


def test_stiffness_criterion_recommends_the_stiffest(ident, tmp_path):
    cfg = write_config(tmp_path, ident, criterion='criterion = "stiffness_min"',
                       rotation_step_deg="rotation_step_deg = 10.0")
    r = plan_posture(cfg).to_dict()
    kmin = np.array([min(c["directional_stiffness_N_per_m"].values()) for c in r["candidates"]])
    rec = r["recommended"]
    assert min(rec["directional_stiffness_N_per_m"].values()) >= kmin.max() * (1 - 1e-6)
    assert r["counts"]["rotations"] == 36


def test_offset_spindle_changes_the_map(ident, tmp_path):
    """A tool point off the flange axis: the rotation moves the wrist centre, so stiffness
    varies with the rotation (on the axis only joint 6 turns and the map is flat)."""
    rb = get_robot("irb6600-175-2.55")
    tcp = [0.2, 0.0, 0.3]
    T = fk(rb, np.radians(PAPER_Q_DEG), tcp)
    cfg = write_config(tmp_path, ident, tcp_m=f"tcp_m = {tcp}",
                       point_m=f"point_m = {T[:3, 3].tolist()}",
                       axis=f"axis = {T[:3, 2].tolist()}",
                       rotation_step_deg="rotation_step_deg = 5.0")
    r = plan_posture(cfg).to_dict()
    k = np.array([c["directional_stiffness_N_per_m"]["x"] for c in r["candidates"]])
    assert k.max() / k.min() > 1.05
    assert r["measured"] is not None


def _same(a, b, rel: float = 1e-9) -> bool:
    """``a`` and ``b`` (parsed JSON) equal, floats within ``rel``."""
    if isinstance(a, dict):
        return isinstance(b, dict) and list(a) == list(b) and all(
            _same(a[k], b[k], rel) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(
            _same(x, y, rel) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float):
        return math.isclose(a, b, rel_tol=rel, abs_tol=1e-300)
    return a == b


def test_cli_writes_netcdf_json_and_plots(ident, tmp_path):
    import xarray as xr

    cfg = write_config(tmp_path / "c", ident, rotation_step_deg="rotation_step_deg = 10.0")
    out, plots = tmp_path / "out", tmp_path / "plots"
    r = runner.invoke(app, ["plan", "posture", str(cfg), "--json", "--out", str(out),
                            "--plot", str(plots)])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["criterion"] == "critical_depth" and d["wall_time_s"] > 0
    ds = xr.open_dataset(out / "posture_plan.nc")
    assert ds.sizes["candidate"] == len(d["candidates"])
    assert int(ds.attrs["recommended_candidate"]) >= 0
    ds.close()
    written = json.loads((out / "posture_plan.json").read_text())
    assert written["criterion"] == "critical_depth"
    # the JSON is the PostureResult's to_dict(), key for key (the wall time aside), and keeps
    # to the stored contract (contract/plan_posture.json)
    spec = json.loads((Path(__file__).parent / "contract" / "plan_posture.json").read_text())
    assert json_mismatches(written, spec["keys"]) == []
    assert json_mismatches({k: v for k, v in d.items() if k not in ("out", "plots")},
                           spec["keys"]) == []
    res = plan_posture(cfg)
    mine = json.loads(json.dumps(to_jsonable(res.to_dict())))
    assert list(mine) == list(written)
    # a second plan in the same process: the semi-discretisation lobes' warm-started
    # eigenvalue iteration differs by round-off between calls (1e-13), so numbers are
    # compared to 1e-9 relative, everything else exactly
    assert _same(mine["lobes"], written["lobes"])
    assert {k: v for k, v in mine.items() if k not in ("wall_time_s", "lobes")} == {
        k: v for k, v in written.items() if k not in ("wall_time_s", "lobes")}
    assert res.recommended.joints_deg == tuple(written["recommended"]["joints_deg"])
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.criterion = "stiffness_x"  # type: ignore[misc]
    assert (plots / "posture_map.png").stat().st_size > 0
    # readable table by default
    r2 = runner.invoke(app, ["plan", "posture", str(cfg)])
    assert r2.exit_code == 0 and "posture plan" in r2.output


# ----------------------------------------------------------------------------- bad input
def _err(cfg: Path, exc=(ConfigError, InputError, DataError)):
    with pytest.raises(exc) as ei:
        plan_posture(cfg)
    return str(ei.value)


def test_bore_out_of_reach(ident, tmp_path):
    cfg = write_config(tmp_path, ident, point_m="point_m = [6.0, 0.0, 0.5]")
    msg = _err(cfg)
    assert str(cfg) in msg and "bore.point_m" in msg and "6.0" in msg and "reach" in msg


def test_zero_length_axis(ident, tmp_path):
    cfg = write_config(tmp_path, ident, axis="axis = [0.0, 0.0, 0.0]")
    msg = _err(cfg)
    assert str(cfg) in msg and "bore.axis" in msg and "zero-length" in msg and "unit" in msg


def test_non_unit_axis(ident, tmp_path):
    cfg = write_config(tmp_path, ident, axis="axis = [-2.0, 0.0, 0.0]")
    msg = _err(cfg)
    assert str(cfg) in msg and "bore.axis" in msg and "-2.0" in msg and "unit" in msg


def test_tcp_in_millimetres(ident, tmp_path):
    cfg = write_config(tmp_path, ident, tcp_m="tcp_m = [0.0, 0.0, 350.0]")
    msg = _err(cfg)
    assert str(cfg) in msg and "tool.tcp_m" in msg and "350" in msg and "millimetres" in msg
    assert "in m" in msg or "expected m" in msg


def test_robot_without_inertial_data(ident, tmp_path):
    rb = get_robot("irb6600-175-2.55")
    d = rb.to_dict()
    d["name"] = "no-inertia"
    lines = [f"{k} = {json.dumps(v)}" for k, v in d.items()]
    rfile = tmp_path / "no-inertia.toml"
    rfile.write_text("\n".join(lines) + "\n")
    cfg = write_config(tmp_path, ident, name='name = "no-inertia.toml"')
    msg = _err(cfg)
    assert "no-inertia.toml" in msg and "inertial data" in msg and "mass_kg" in msg


def test_modes_without_posture(ident, tmp_path):
    cfg = write_config(tmp_path, ident)
    text = re.sub(r"(?m)^posture_deg =.*$", "", cfg.read_text())
    cfg.write_text(text)
    mfile = tmp_path / "id" / "modes.json"
    d = json.loads(mfile.read_text())
    assert d["identity"]["joints_deg"] is not None  # the hammer test's posture travels ...
    from robobore.plan.config import load_plan_config

    assert np.allclose(np.degrees(load_plan_config(cfg).q_meas_rad), d["identity"]["joints_deg"])
    d.pop("identity")  # ... a modes file without it needs identification.posture_deg
    mfile.write_text(json.dumps(d))
    msg = _err(cfg)
    assert str(cfg) in msg and "identification.posture_deg" in msg and "modes.json" in msg


def test_modes_file_from_another_posture(ident, tmp_path):
    cfg = write_config(tmp_path, ident)
    mfile = tmp_path / "id" / "modes.json"
    d = json.loads(mfile.read_text())
    d["posture_deg"] = [-30.0, 40.0, 10.0, -50.0, 100.0, 0.0]
    mfile.write_text(json.dumps(d))
    msg = _err(cfg)
    assert str(cfg) in msg and "identification.posture_deg" in msg and "-30.0" in msg
    # the posture recorded in the file alone is accepted (no posture in the config)
    cfg.write_text(re.sub(r"(?m)^posture_deg =.*$", "", cfg.read_text()))
    d["posture_deg"] = PAPER_Q_DEG
    mfile.write_text(json.dumps(d))
    r = runner.invoke(app, ["plan", "posture", str(cfg), "--json"])
    assert r.exit_code == 0, r.output


def test_cli_error_is_one_line_exit_2(ident, tmp_path):
    cfg = write_config(tmp_path, ident, axis="axis = [0.0, 0.0, 0.0]")
    r = runner.invoke(app, ["plan", "posture", str(cfg)])
    assert r.exit_code == 2
    assert "bore.axis" in r.output and "Traceback" not in r.output


def test_missing_identification_file(ident, tmp_path):
    cfg = write_config(tmp_path, ident)
    (tmp_path / "id" / "modes.json").unlink()
    msg = _err(cfg)
    assert "identification.modes" in msg and "modes.json" in msg and math.isfinite(1.0)


def test_part_frame_placement_gives_the_same_bore(ident, tmp_path, paper_result):
    """[bore] in a part frame placed by [part] origin_m / yaw_deg: the same bore in the base
    frame gives the same candidates."""
    p = np.asarray(paper_result.bore.point_m)
    a = np.asarray(paper_result.bore.axis)
    yaw = math.radians(30.0)
    Rz = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0],
                   [0, 0, 1.0]])
    origin = np.array([0.5, -0.2, 0.1])
    cfg = write_config(tmp_path, ident, point_m=f"point_m = {(Rz.T @ (p - origin)).tolist()}",
                       axis=f"axis = {(Rz.T @ a).tolist()}",
                       rotation_step_deg="rotation_step_deg = 10.0")
    cfg.write_text(cfg.read_text() + f"\n[part]\norigin_m = {origin.tolist()}\nyaw_deg = 30.0\n")
    r = plan_posture(cfg).to_dict()
    assert np.allclose(r["bore"]["point_m"], p, atol=1e-12)
    assert r["measured"] is not None
    assert r["recommended"]["critical_depth_mm"] == pytest.approx(
        paper_result.recommended.critical_depth_mm, rel=1e-9)


def test_link_bending_data_flow_through_the_plan(ident, tmp_path):
    """Optional link compliance (VJM beams): more coordinates, modes and a softer tool point
    than the joint-only model with the same joint stiffness; reported in the calibration."""
    lb = ('posture_deg = [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95]\n'
          'link_bending = [{link = 2, EI_Nm2 = [5.7e7, 7.2e7]}, '
          '{link = 4, EI_Nm2 = [1.6e7, 1.6e7]}]')
    step = "rotation_step_deg = 30.0"
    r0 = plan_posture(write_config(tmp_path / "a", ident, rotation_step_deg=step)).to_dict()
    r1 = plan_posture(write_config(tmp_path / "b", ident, posture_deg=lb,
                                   rotation_step_deg=step)).to_dict()
    assert [d["link"] for d in r1["calibration"]["link_bending"]] == [2, 4]
    assert r0["calibration"]["link_bending"] == []
    k0, k1 = (r["recommended"]["directional_stiffness_N_per_m"] for r in (r0, r1))
    assert all(k1[a] < k0[a] for a in "xyz")
    assert len(r1["recommended"]["modes"]) == 12 and len(r0["recommended"]["modes"]) == 6


def test_link_bending_bad_input(ident, tmp_path):
    bad = ('posture_deg = [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95]\n'
           'link_bending = [{link = 2, EI_Nm2 = [0.0, 7.2e7]}]')
    cfg = write_config(tmp_path, ident, posture_deg=bad)
    msg = _err(cfg)
    assert str(cfg) in msg and "identification.link_bending[0].EI_Nm2" in msg and "N m^2" in msg
    bad = ('posture_deg = [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95]\n'
           'link_bending = [{link = 5, EI_Nm2 = [1e7, 1e7]}]')
    msg = _err(write_config(tmp_path / "z", ident, posture_deg=bad))
    assert "identification.link_bending[0].link" in msg and "zero length" in msg
