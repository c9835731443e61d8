"""3D FE boring model: config validation, feed-mark geometry, a tiny workpiece-frame run
through the CLI (the tool frame's: tests/cutting/fe3d/test_toolframe3d_boring.py).

The long validation (paper's condition, mesh refinement, comparison with the mechanistic
model) is in ``benchmarks/bench_fe3d.py``; these tests keep the mesh tiny.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from robobore.cutting.fe.cli_boring import register_boring
from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.mesh.boring3d import build_boring_mesh
from robobore.cutting.geometry import BoringInsert, chip_area
from robobore.errors import ConfigError

TINY = """
[insert]
nose_radius_mm = 0.4
rake_deg = 7.0
clearance_deg = 7.0
edge_radius_um = 10.0
[cut]
depth_of_cut_mm = 0.06
feed_mm_per_rev = 0.15
speed_rpm = 300.0
bore_diameter_mm = 40.0
cut_length_mm = 0.06
[mesh]
element_size_um = 20.0
frame = "workpiece"
ahead_mm = 0.04
[solver]
n_samples = 40
steady_window_fraction = 0.5
[tool_support]
stiffness_N_per_m = 4.0e8
damping_N_s_per_m = 632.0
mass_kg = 1.0e-3
"""


def _base():
    return {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0},
            "mesh": {"element_size_um": 12.5}}


@pytest.mark.parametrize("path, value, match", [
    (("mesh", "element_size_um"), 20.0, "element too large"),
    (("cut", "depth_of_cut_mm"), -0.05, "depth_of_cut_mm"),
    (("cut", "bore_diameter_mm"), 2.0, "bore too small"),
    (("insert", "edge_radius_um"), 150.0, "edge radius"),
    (("insert", "rake_deg"), 45.0, "rake_deg"),
])
def test_bad_configs_name_the_field(path, value, match):
    d = _base()
    d.setdefault(path[0], {})[path[1]] = value
    if path == ("insert", "edge_radius_um"):
        d["insert"]["nose_radius_mm"] = 0.1
    with pytest.raises(ConfigError, match=match):
        parse_boring_config(d, source="bad.toml")


def test_unknown_material_is_a_clear_error():
    from robobore.cutting.fe.models.boring3d import setup_boring

    d = _base()
    d["material"] = {"name": "unobtainium"}
    with pytest.raises(ConfigError):
        setup_boring(parse_boring_config(d))


def test_feed_marks_give_the_boring_chip_area():
    """The mesh's top surface is min(ap, drop(z + f)); the material above the current edge
    profile has the exact boring chip area ap f - scallop (geometry.chip_area) to within
    the surface discretisation (1 %)."""
    ins = BoringInsert(nose_radius_m=0.4e-3, edge_radius_m=20e-6)
    ap, f, le = 0.05e-3, 0.15e-3, 5e-6
    m = build_boring_mesh(ins, ap, f, le, 0.05e-3)
    nx, ny, nz = m.shape
    top = m.nodes.reshape(nx + 1, ny + 1, nz + 1, 3)[0, -1]
    zs, ytop = top[:, 2], top[:, 1]
    np.testing.assert_allclose(ytop, np.minimum(ap, ins.drop(zs + f)), atol=1e-15)
    zf = np.linspace(zs[0], zs[-1], 20001)
    yt = np.interp(zf, zs, ytop)
    area = np.trapezoid(np.clip(yt - ins.drop(zf), 0.0, None), zf)
    assert area == pytest.approx(chip_area(ins, ap, f), rel=0.01)
    assert m.layer.any() and m.chip.any()


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("boring")
    cfg = d / "tiny.toml"
    cfg.write_text(TINY)
    app = typer.Typer()
    fe = typer.Typer()
    app.add_typer(fe, name="fe")
    register_boring({"fe": fe})
    res = CliRunner().invoke(app, ["fe", "boring", str(cfg), "--json", "--vtk", str(d / "vtk")])
    return res, d, app, cfg


def test_cli_json_contract(tiny_run):
    res, d, _, _ = tiny_run
    assert res.exit_code == 0, res.output
    out = json.loads(res.stdout)
    for key in ("force_mean_N", "force_amplitude_N"):
        assert set(out[key]) == {"x", "y", "z"}
    for key in ("feed_amplitude_um", "wall_time_s", "element_updates_per_s", "device",
                "energy_error", "n_elements", "mechanistic_comparison", "separation",
                "friction_coefficient"):
        assert key in out
    assert out["device"] == "cpu"
    # defaults: erosion layer; friction law rech2013_calibrated read at each node's sliding
    # speed (nominal: the Rech table x 1.5 at 300 r/min on a 40 mm bore, 37.7 m/min)
    assert out["separation"] == "erosion_layer" and out["pairs_parted"] == 0
    assert out["friction_coefficient"] == pytest.approx(1.5 * 0.1723, abs=1e-3)
    assert "rech2013_calibrated" in out["friction_law"] and "sliding" in out["friction_law"]
    # the chip slides over the insert slower than the cutting speed (0.63 m/s)
    assert 0.0 < out["sliding_speed_mean_m_per_s"] < 0.63 * 1.05
    assert all((d / "vtk" / f"boring_{n}.vtu").exists() for n in ("initial", "final"))
    # every run says that its radial and feed forces are not validated (docs/fe3d.md)
    assert any("radial and feed forces" in w for w in out["warnings"])


def test_tiny_run_physics(tiny_run):
    """Signs of the force on the tool (against the cutting velocity, pushed inwards, pushed
    back against the feed); the boring-frame X/Y amplitude over a revolution is
    sqrt(Ft^2 + Fr^2) with zero mean and Z is constant (rotating force, stable boring);
    energy balance within 5 %; the mean Z deflection of the tool on its spring equals
    feed force / kZ within 5 % (quasi-static support: natural frequency 100 kHz, zeta 0.5,
    averaging window 8 periods)."""
    res, *_ = tiny_run
    out = json.loads(res.stdout)
    f = out["force_rotating_N"]
    assert f["tangential"] > 0 and f["radial"] < 0 and f["feed"] < 0
    amp = math.hypot(f["tangential"], f["radial"])
    assert out["force_amplitude_N"]["x"] == pytest.approx(amp, rel=1e-3)
    assert abs(out["force_mean_N"]["x"]) < 1e-9 * amp
    assert out["force_mean_N"]["z"] == pytest.approx(f["feed"])
    assert out["energy_error"] < 0.05
    assert out["tool_dz_mean_um"] == pytest.approx(out["tool_dz_static_um"], rel=0.05)


def test_gpu_request_without_gpu_is_a_clear_error(tiny_run):
    from robobore.cutting.fe.engine.gpu.shared import cuda_available

    if cuda_available():
        pytest.skip("a CUDA device is present: the no-GPU error path does not apply")
    _, _, app, cfg = tiny_run
    res = CliRunner().invoke(app, ["fe", "boring", str(cfg), "--device", "gpu"])
    assert res.exit_code == 2
    assert "GPU" in res.output and "--device" in res.output
