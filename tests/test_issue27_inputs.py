"""Bad input to the FE validation and calibration paths is found when the config is loaded,
before any FE run: the material an FE config names (read and checked by ``load_fe_config``,
the 3D boring loader and ``load_calibration_config``), the cut's length and width against the
mesh and the chip, an unknown key in the FE base config of a calibration or a paper study,
and a calibration grid outside the engine's checks. Each error names the file, the key, the
value and what is expected."""

from __future__ import annotations

import shutil
import tomllib
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.cutting import calibration_config as calcfg
from robobore.cutting import calibration_runs as calruns
from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.config.orthogonal import load_fe_config, parse_config
from robobore.errors import ConfigError

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
TC4 = ROOT / "src" / "robobore" / "material" / "library" / "tc4.toml"


def _no_run(*a, **k):
    raise AssertionError("an FE run started before the config error was found")


@pytest.fixture(autouse=True)
def _never_run(monkeypatch):
    monkeypatch.setattr(calruns, "run_fe_point", _no_run)
    monkeypatch.setattr("robobore.cutting.fe.models.orthogonal.simulate_orthogonal", _no_run)


def _garbled_material(tmp_path: Path) -> Path:
    m = tmp_path / "ti64_mine.toml"
    m.write_text(TC4.read_text().replace("A_MPa = 997.9", 'A_MPa = "997.9 MPa"'))
    return m


def _fe_with_material(tmp_path: Path, name: str) -> Path:
    c = tmp_path / "fe.toml"
    c.write_text(EX.joinpath("fe_orthogonal.toml").read_text()
                 .replace('name = "TC4"', f'name = "{name}"'))
    return c


# --- the material is read at config load ---------------------------------------------------

def test_fe_config_reads_its_material_file_at_load(tmp_path):
    m = _garbled_material(tmp_path)
    with pytest.raises(ConfigError) as e:
        load_fe_config(_fe_with_material(tmp_path, m.name))
    assert e.value.file == str(m) and e.value.field == "johnson_cook.A_MPa"
    assert "997.9 MPa" in str(e.value)
    with pytest.raises(ConfigError, match="not found") as e:
        load_fe_config(_fe_with_material(tmp_path, "nope.toml"))
    assert e.value.field == "material.name"
    with pytest.raises(ConfigError, match="unknown material") as e:
        load_fe_config(_fe_with_material(tmp_path, "TC5"))
    assert e.value.field == "material.name" and e.value.value == "TC5"
    ok = tmp_path / "ok.toml"
    shutil.copy(TC4, ok)
    assert load_fe_config(_fe_with_material(tmp_path, "ok.toml")).material.name == str(ok)


def test_boring_config_reads_its_material_file_at_load(tmp_path):
    m = _garbled_material(tmp_path)
    d = tomllib.loads(EX.joinpath("fe_boring_paper.toml").read_text())
    d["material"] = {"name": m.name}
    with pytest.raises(ConfigError) as e:
        parse_boring_config(d, str(tmp_path / "boring.toml"))
    assert e.value.file == str(m) and e.value.field == "johnson_cook.A_MPa"


def test_calibration_config_reads_its_material_file_at_load(tmp_path):
    m = _garbled_material(tmp_path)
    c = tmp_path / "cal.toml"
    c.write_text(f'[material]\nname = "{m.name}"\n[insert]\nrake_deg = 7.0\n'
                 "[calibration]\nuncut_chip_thickness_um = [60.0, 90.0]\n"
                 "cutting_speed_m_per_min = [37.7]\n")
    with pytest.raises(ConfigError) as e:
        calcfg.load_calibration_config(c)
    assert e.value.file == str(m) and e.value.field == "johnson_cook.A_MPa"


# --- cut length and width -----------------------------------------------------------------

def _contract(**cut) -> dict:
    d = tomllib.loads(EX.joinpath("fe_orthogonal.toml").read_text())
    d["cut"].update(cut)
    return d


def test_cut_shorter_than_one_element_is_refused():
    with pytest.raises(ConfigError, match="cut too short") as e:
        parse_config(_contract(length_mm=0.0003), "fe.toml")  # metres typed for mm
    assert e.value.field == "cut.length_mm" and e.value.value == 0.0003
    assert "10 um" in e.value.expected and e.value.file == "fe.toml"
    parse_config(_contract(length_mm=0.01))  # one 10 um element: accepted


def test_width_below_the_chip_thickness_is_refused():
    with pytest.raises(ConfigError, match="width of cut") as e:
        parse_config(_contract(width_mm=0.05), "fe.toml")  # h = 60 um
    assert e.value.field == "cut.width_mm" and "60 um" in e.value.expected
    parse_config(_contract(width_mm=0.06))


# --- the calibration grid and the FE base config -----------------------------------------

def _cal(fe_config=None, h=(60.0, 90.0), vc=(37.7,), **fe):
    d = {"calibration": {"uncut_chip_thickness_um": list(h), "cutting_speed_m_per_min": list(vc),
                         **({} if fe_config is None else {"fe_config": fe_config}),
                         **({"fe": fe} if fe else {})},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0}, "material": {"name": "TC4"}}
    return calcfg.calibration_from_mapping(d, source="cal.toml")


FULL = {"cut": {"length_mm": 0.2}, "mesh": {"element_size_um": 20.0}}


@pytest.mark.parametrize("kw, field, words", [
    # grid beyond the engine's accepted ranges: named by the grid's own key
    ({"fe_config": FULL, "h": (60.0, 2500.0)}, "calibration.uncut_chip_thickness_um",
     "h 2500 um"),
    # beyond the plausible range of a cutting speed: refused when the grid is read
    ({"fe_config": FULL, "vc": (37.7, 3000.0)}, "cutting_speed_m_per_min.1",
     "plausible range"),
    ({"h": (60.0, 2500.0)}, "calibration.uncut_chip_thickness_um", "h 2500 um"),
    # element too coarse for the thinnest chip (the FE config's and the shorthand's)
    ({"fe_config": FULL, "h": (45.0, 90.0)}, "calibration.fe_config.mesh.element_size_um",
     "h 45 um"),
    ({"element_size_um": 20.0, "h": (45.0, 90.0)}, "calibration.fe.element_size_um",
     "thinnest chip"),
    # a cut shorter than one element, in the FE config and in the shorthand
    ({"fe_config": {**FULL, "cut": {"length_mm": 0.01}}}, "calibration.fe_config.cut.length_mm",
     "too short"),
    ({"length_mm": 0.01}, "calibration.fe.length_mm", "too short"),
    # an unknown key in the inline FE base config
    ({"fe_config": {**FULL, "solver": {"n_sample": 10}}}, "calibration.fe_config.solver.n_sample",
     "grid point"),
])
def test_calibration_grid_errors_at_load(kw, field, words):
    with pytest.raises(ConfigError, match=words) as e:
        _cal(**kw)
    assert e.value.field == field and e.value.file == "cal.toml"
    assert e.value.expected


def test_fe_base_config_file_unknown_key_names_that_file(tmp_path):
    fe = tmp_path / "fe_base.toml"
    fe.write_text("[cut]\nlength_mm = 0.2\n[mesh]\nelement_size_um = 20.0\nsize = 3\n")
    c = tmp_path / "cal.toml"
    c.write_text("[insert]\nrake_deg = 7.0\n[calibration]\nuncut_chip_thickness_um = [60, 90]\n"
                 'cutting_speed_m_per_min = [37.7]\nfe_config = "fe_base.toml"\n')
    with pytest.raises(ConfigError, match="grid point") as e:
        calcfg.load_calibration_config(c)
    assert e.value.file == str(fe.resolve()) and e.value.field == "mesh.size"
    r = CliRunner().invoke(app, ["calibrate", "forces", str(c), "--json"])
    assert r.exit_code == 2 and "mesh.size" in r.output and "Traceback" not in r.output


def test_paper_config_with_a_bad_fe_base_config_fails_at_load(tmp_path):
    """The paper study checks its [calibration] FE model when its config is read (even under
    --fast, which does not run it), before identification, sweep or FE."""
    from robobore.study import paper_config as pp

    text = (pp.example_dir() / "paper.toml").read_text()
    assert "mesh = { element_size_um = 20.0 }" in text
    c = tmp_path / "paper.toml"
    c.write_text(text.replace("mesh = { element_size_um = 20.0 }",
                              "mesh = { element_size_um = 20.0, elemnt = 1 }"))
    for f in pp.example_dir().iterdir():  # the data files named next to the config
        if f.name != "paper.toml" and f.is_file():
            (tmp_path / f.name).symlink_to(f)
    with pytest.raises(ConfigError, match="elemnt") as e:
        pp.load_paper_config(c)
    assert e.value.file == str(c) and e.value.field == "calibration.fe_config.mesh.elemnt"
