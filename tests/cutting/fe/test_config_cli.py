"""Config validation (clear errors) and the CLI wiring."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.cutting.fe.config.orthogonal import load_fe_config, parse_config
from robobore.errors import ConfigError

EXAMPLE = Path(__file__).parents[3] / "examples" / "fe_orthogonal.toml"
BASE = {
    "parameters": "a_priori",
    "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
    "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
            "length_mm": 1.0, "width_mm": 1.0},
    "contact": {"friction": 0.18},
    "mesh": {"element_size_um": 10.0, "frame": "workpiece"},
    "solver": {"mass_scaling": 100.0, "heat_conduction": False},
}


def _with(section, key, value):
    d = copy.deepcopy(BASE)
    d.setdefault(section, {})[key] = value
    return d


def test_contract_example_parses():
    cfg = load_fe_config(EXAMPLE)
    # the validated model's defaults: the calibrated table's nominal value at 30 m/min
    assert cfg.friction_coefficient() == 0.27
    assert cfg.solver.mass_scaling == 100.0 and cfg.mesh.frame == "tool"


@pytest.mark.parametrize("name", sorted(p.name for p in EXAMPLE.parent.glob("fe_orthogonal*.toml")))
def test_every_orthogonal_example_parses(name):
    cfg = load_fe_config(EXAMPLE.parent / name)
    assert cfg.cut.length_mm > 0


def test_separation_line_must_leave_a_chip_row():
    with pytest.raises(ConfigError, match="separation_height_um"):
        parse_config(_with("mesh", "separation_height_um", 55.0))


def test_friction_table_interpolates():
    cfg = parse_config(_with("contact", "friction", "table"))
    assert cfg.friction_coefficient() == pytest.approx(0.18)
    d = _with("contact", "friction", "table")
    d["cut"]["cutting_speed_m_per_min"] = 15.0
    assert parse_config(d).friction_coefficient() == pytest.approx(0.20)


@pytest.mark.parametrize("section,key,value,field", [
    ("cut", "uncut_chip_thickness_um", -60.0, "cut.uncut_chip_thickness_um"),
    ("cut", "length_mm", 0.0, "cut.length_mm"),
    ("mesh", "element_size_um", -1.0, "mesh.element_size_um"),
    ("tool", "rake_deg", 45.0, "tool.rake_deg"),
    ("tool", "rake_deg", -31.0, "tool.rake_deg"),
    ("tool", "edge_radius_um", -5.0, "tool.edge_radius_um"),
    ("solver", "mass_scaling", 0.5, "solver.mass_scaling"),
])
def test_bad_values_name_the_key(section, key, value, field):
    with pytest.raises(ConfigError) as ei:
        parse_config(_with(section, key, value), source="c.toml")
    assert ei.value.field == field
    assert "c.toml" in str(ei.value)


def test_element_too_large_for_chip():
    with pytest.raises(ConfigError, match=r"mesh.element_size_um.*25.*at most.*20 um"):
        parse_config(_with("mesh", "element_size_um", 25.0), source="c.toml")


def test_unknown_material_from_cli(tmp_path):
    txt = EXAMPLE.read_text().replace('name = "TC4"', 'name = "UNOBTAINIUM"')
    f = tmp_path / "c.toml"
    f.write_text(txt)
    r = CliRunner().invoke(app, ["fe", "orthogonal", str(f), "--json"])
    assert r.exit_code == 2
    assert "unknown material" in r.output and "UNOBTAINIUM" in r.output


def test_bad_tool_support(tmp_path):
    d = _with("tool_support", "stiffness_N_per_m", [1e7, -1.0])
    d["tool_support"].update(damping_N_s_per_m=10.0, mass_kg=0.1)
    with pytest.raises(ConfigError, match="tool_support.stiffness_N_per_m"):
        parse_config(d)


def test_tool_support_too_stiff_for_the_step():
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    d = _with("tool_support", "stiffness_N_per_m", [1e13, 1e7])
    d["tool_support"].update(damping_N_s_per_m=10.0, mass_kg=0.001)
    d["cut"]["length_mm"] = 0.05
    d["mesh"]["element_size_um"] = 20.0
    # 1e13 N/m is outside the plausible stiffness range: accepted here by the override
    d["range_check"] = {"allow": ["tool_support.stiffness_N_per_m"]}
    with pytest.raises(ConfigError, match=r"tool_support.stiffness_N_per_m\[0\]"):
        setup_orthogonal(parse_config(d), source="c.toml")


def test_cli_runs_a_short_cut(tmp_path):
    """A very short, coarse cut through the CLI: JSON keys, netCDF, VTK and PNG files."""
    txt = (EXAMPLE.read_text().replace("length_mm = 0.3", "length_mm = 0.05")
           .replace("element_size_um = 10.0", "element_size_um = 20.0"))
    f = tmp_path / "c.toml"
    f.write_text(txt)
    r = CliRunner().invoke(app, ["fe", "orthogonal", str(f), "--json", "--out",
                                 str(tmp_path / "r.nc"), "--vtk", str(tmp_path / "vtk"),
                                 "--plot", str(tmp_path / "png")])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    for k in ("cutting_force_N_per_mm", "feed_force_N_per_mm", "chip_ratio",
              "peak_temperature_K", "energy_error", "wall_time_s", "element_updates_per_s"):
        assert k in out
    assert out["cutting_force_N_per_mm"] > 0
    assert out["device"] == "cpu"
    assert (tmp_path / "r.nc").is_file()
    assert (tmp_path / "vtk" / "fe_orthogonal_final.vtu").is_file()
    assert (tmp_path / "png" / "fe_chip_temperature_K.png").is_file()
    import xarray as xr

    ds = xr.open_dataset(tmp_path / "r.nc")
    assert ds["cutting_force_N_per_mm"].attrs["units"] == "N/mm"
    assert "robobore_config" in ds.attrs
    # the force split by tool face: JSON, netCDF histories and attributes, force plot
    assert set(out["force_by_face_N_per_mm"]) == {"rake", "edge", "flank"}
    assert ds["edge_feed_force_N_per_mm"].attrs["units"] == "N/mm"
    assert ds.attrs["edge_cutting_force_N_per_mm"] == pytest.approx(
        out["force_by_face_N_per_mm"]["edge"]["cutting"])
    assert (tmp_path / "png" / "fe_forces.png").is_file()
