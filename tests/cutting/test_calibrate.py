"""FE -> mechanistic coefficient calibration (robobore.cutting.calibrate).

References: ordinary least squares with standard errors ``cov = s^2 (A^T A)^-1``,
``s^2 = RSS/(n-2)`` (e.g. Montgomery & Runger, *Applied Statistics and Probability for
Engineers*, ch. 11); the linear edge-force model ``F = Ke + Kc h`` (Altintas,
*Manufacturing Automation*, 2nd ed., ch. 2); orthogonal-to-oblique transformation (Budak,
Altintas & Armarego 1996) as implemented in ``cutting/coefficient_sets.py``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from robobore.cutting import calibrate as cal
from robobore.cutting import calibration_config as calcfg
from robobore.cutting import calibration_runs as calruns
from robobore.cutting.coefficient_files import load_coefficients
from robobore.errors import ConfigError
from robobore.io.cache import ResultCache
from robobore.study.paper_config import PaperConfig, example_config_path, example_dir

STORED = example_dir() / "tc4_fe_coefficients.json"


def _cfg(**kw):
    d = {"calibration": {"uncut_chip_thickness_um": [60.0, 90.0],
                         "cutting_speed_m_per_min": [40.0, 120.0]},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0, "clearance_deg": 7.0},
         "material": {"name": "TC4"}}
    d["calibration"].update(kw)
    return calcfg.calibration_from_mapping(d, source="test.toml")


def test_fit_exact_linear_data():
    """Noise-free F = Ke + Kc h is recovered exactly (to rounding)."""
    h = np.array([20e-6, 40e-6, 60e-6, 100e-6])
    f = 25e3 + 1.7e9 * h
    r = cal.fit_edge_model(h, f)
    assert r["Kc"] == pytest.approx(1.7e9, rel=1e-10)
    assert r["Ke"] == pytest.approx(25e3, rel=1e-9)
    assert r["Kc_se"] < 1e-3 * 1.7e9
    assert r["max_rel_residual"] < 1e-10


def test_fit_standard_errors_match_monte_carlo():
    """The residual-based standard errors equal the scatter of the estimates over noise
    realisations (OLS theory). Tolerance 10 % (1500 realisations: MC error ~2 %)."""
    rng = np.random.default_rng(3)
    h = np.array([30e-6, 60e-6, 90e-6, 120e-6, 150e-6, 180e-6])
    kc, ke = [], []
    se_c, se_e = [], []
    for _ in range(1500):
        f = 20e3 + 1.5e9 * h + rng.normal(0.0, 3e3, h.size)
        r = cal.fit_edge_model(h, f)
        kc.append(r["Kc"])
        ke.append(r["Ke"])
        se_c.append(r["Kc_se"])
        se_e.append(r["Ke_se"])
    # E[s^2] = sigma^2, so compare the root-mean-square SE with the MC standard deviation
    assert math.sqrt(np.mean(np.square(se_c))) == pytest.approx(np.std(kc), rel=0.10)
    assert math.sqrt(np.mean(np.square(se_e))) == pytest.approx(np.std(ke), rel=0.10)


def test_fit_needs_two_distinct_h():
    with pytest.raises(ConfigError, match="distinct"):
        cal.fit_edge_model(np.array([50e-6, 50e-6]), np.array([1.0, 2.0]))


def _fake_records(cfg, kc=1.6e9, ke=30e3, kfc=0.4e9, kfe=40e3):
    recs = []
    for h in cfg.uncut_chip_thickness_um:
        for v in cfg.cutting_speed_m_per_min:
            recs.append({"h_um": h, "vc_m_per_min": v,
                         "Fc_N_per_m": ke + kc * h * 1e-6, "Ff_N_per_m": kfe + kfc * h * 1e-6,
                         "cached": False,
                         "fe": {"chip_ratio": None, "cutting_force_std_N_per_mm": 1.0}})
    return recs


def test_calibrate_file_round_trip(tmp_path):
    """Coefficients fitted from known forces are recovered, and the written file is loaded
    by cutting.coefficient_files.load_coefficients with the same values and an FE provenance."""
    cfg = _cfg()
    data = cal.calibrate(cfg, _fake_records(cfg))
    c = data["coefficients"]
    assert c["Ktc_N_per_m2"] == pytest.approx(1.6e9, rel=1e-9)
    assert c["Kte_N_per_m"] == pytest.approx(30e3, rel=1e-9)
    assert c["Kfc_N_per_m2"] == pytest.approx(0.4e9, rel=1e-9)
    assert c["Kfe_N_per_m"] == pytest.approx(40e3, rel=1e-9)
    assert c["Krc_N_per_m2"] == 0.0
    p = tmp_path / "c.json"
    p.write_text(json.dumps(data))
    loaded = load_coefficients(p)
    assert loaded.Ktc == pytest.approx(c["Ktc_N_per_m2"])
    assert loaded.Kfe == pytest.approx(c["Kfe_N_per_m"])
    assert "FE-calibrated" in loaded.provenance
    for k in ("material", "insert", "fe_settings", "grid", "robobore_version", "fit"):
        assert k in data


def test_inclined_insert_uses_oblique_transformation():
    """With inclination the shearing coefficients go through orthogonal_to_oblique: a lateral
    Krc appears, and for i -> 0 the orthogonal values are recovered."""
    cfg = _cfg(inclination_deg=10.0)
    d = cal.calibrate(cfg, _fake_records(cfg))
    assert d["coefficients"]["Krc_N_per_m2"] > 0
    assert "orthogonal-to-oblique" in d["coefficients"]["provenance"]
    cfg0 = _cfg(inclination_deg=1e-9)
    d0 = cal.calibrate(cfg0, _fake_records(cfg0))
    assert d0["coefficients"]["Ktc_N_per_m2"] == pytest.approx(1.6e9, rel=1e-6)
    assert d0["coefficients"]["Kfc_N_per_m2"] == pytest.approx(0.4e9, rel=1e-6)


def _linear_fe(monkeypatch) -> list:
    """Replace the FE point runner by an exactly linear one (Kte 30 N/mm, Ktc 1.6 GPa, Kfe
    40 N/mm, Kfc 0.4 GPa); returns the list the FE configs it is called with land in."""
    calls: list = []

    def fake(fe_cfg):
        calls.append(fe_cfg)
        h = fe_cfg["cut"]["uncut_chip_thickness_um"] * 1e-6
        return {"cutting_force_N_per_mm": (30e3 + 1.6e9 * h) * 1e-3,
                "feed_force_N_per_mm": (40e3 + 0.4e9 * h) * 1e-3, "chip_ratio": None}

    monkeypatch.setattr(calruns, "run_fe_point", fake)
    return calls


def test_grid_is_cached(tmp_path, monkeypatch):
    """FE results are cached by their inputs: a second run computes nothing; a changed FE
    setting computes again."""
    calls = _linear_fe(monkeypatch)
    cache = ResultCache(tmp_path / "cache")
    cfg = _cfg()
    r1 = cal.calibrate_forces(cfg, cache=cache, out=tmp_path / "a.json")
    assert len(calls) == 4 and r1["fe_cached_points"] == 0
    r2 = cal.calibrate_forces(cfg, cache=cache)
    assert len(calls) == 4 and r2["fe_cached_points"] == 4
    assert r2["coefficients"] == r1["coefficients"]
    cal.calibrate_forces(_cfg(fe={"length_mm": 0.5}), cache=cache)
    assert len(calls) == 8
    # a new engine revision (physics changed) does not reuse the old engine's forces
    import robobore.cutting.fe as fe

    monkeypatch.setattr(fe, "FE_ENGINE_REVISION", fe.FE_ENGINE_REVISION + 1)
    r3 = cal.calibrate_forces(cfg, cache=cache)
    assert len(calls) == 12 and r3["fe_cached_points"] == 0


def test_bad_config_names_field():
    with pytest.raises(ConfigError) as e:
        _cfg(fe={"element_size_um": 25.0})
    assert "calibration.fe.element_size_um" in str(e.value)
    assert "um" in str(e.value)
    with pytest.raises(ConfigError) as e:
        _cfg(uncut_chip_thickness_um=[60.0, -5.0])
    assert "uncut_chip_thickness_um" in str(e.value)


def test_sections_beside_the_calibration_are_those_the_caller_names():
    """A paper config's sections are accepted when its reader names them; a typo is not."""
    d = {"calibration": {"uncut_chip_thickness_um": [60.0, 90.0],
                         "cutting_speed_m_per_min": [40.0]},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0}, "study": {}}
    with pytest.raises(ConfigError) as e:
        calcfg.calibration_from_mapping(d, source="t.toml")
    assert "study" in str(e.value) and "t.toml" in str(e.value)
    c = calcfg.calibration_from_mapping(d, source="t.toml", other_sections=PaperConfig.model_fields)
    assert c.uncut_chip_thickness_um == [60.0, 90.0]
    with pytest.raises(ConfigError, match="studdy"):
        calcfg.calibration_from_mapping({**d, "studdy": {}}, source="t.toml",
                                     other_sections=PaperConfig.model_fields)


def test_cli_reads_the_paper_config_as_a_calibration_config(tmp_path, monkeypatch):
    """``robobore calibrate forces`` (default: the bundled paper config) accepts the paper
    config's other sections; a misspelt section is refused (FE runs replaced)."""
    from typer.testing import CliRunner

    from robobore.cli import app

    calls = _linear_fe(monkeypatch)
    monkeypatch.setenv("ROBOBORE_CACHE_DIR", str(tmp_path / "cache"))
    r = CliRunner().invoke(app, ["calibrate", "forces", "--workers", "1", "--json"])
    assert r.exit_code == 0, r.output
    c = calcfg.load_calibration_config(example_config_path(),
                                       other_sections=PaperConfig.model_fields)
    assert len(calls) == len(c.uncut_chip_thickness_um) * len(c.cutting_speed_m_per_min)
    assert json.loads(r.stdout)["orthogonal"]["Ktc_N_per_m2"] == pytest.approx(1.6e9, rel=1e-9)
    bad = tmp_path / "paper.toml"
    bad.write_text(example_config_path().read_text().replace("[lobes]", "[lobbes]"))
    r = CliRunner().invoke(app, ["calibrate", "forces", str(bad), "--workers", "1"])
    assert r.exit_code == 2 and "lobbes" in r.output


def test_example_config_is_valid():
    c = calcfg.load_calibration_config(example_config_path(),
                                       other_sections=PaperConfig.model_fields)
    assert c.rake_deg == 7.0 and c.material == "TC4"


def test_boring_chip_calibration_example_is_valid():
    """examples/calibration_boring_chip.toml (thin chips of the paper's boring condition)
    parses, and its FE points respect the engine's element size <= h / 3 check."""
    from pathlib import Path

    from robobore.cutting.fe.config.orthogonal import parse_config

    path = Path(__file__).parents[2] / "examples" / "calibration_boring_chip.toml"
    c = calcfg.load_calibration_config(path)
    assert c.fe.separation == "node_split"
    for h in c.uncut_chip_thickness_um:
        parse_config(calcfg.fe_config_dict(c, h, c.cutting_speed_m_per_min[0]))


def test_fit_warnings_flag_bad_fits():
    """A thrust force that is not linear in h (the FE scatter seen in the example) is
    flagged, a good fit is not."""
    cfg = _cfg(uncut_chip_thickness_um=[80.0, 100.0, 120.0], cutting_speed_m_per_min=[80.0])
    recs = _fake_records(cfg)
    assert cal.calibrate(cfg, recs)["warnings"] == []
    recs[1]["Ff_N_per_m"] *= 3.0
    d = cal.calibrate(cfg, recs)
    assert any(w.startswith("Ff fit misses an FE point") for w in d["warnings"])
    assert "WARNING" in d["coefficients"]["provenance"]


def test_stored_coefficients_reproduce_fe_cutting_forces_within_5_percent():
    """Issue 6 acceptance: the FE-calibrated coefficients (the bundled file, made by
    ``robobore calibrate forces``) reproduce the FE CUTTING forces they were fitted to within
    5 %. The FE thrust (feed) force of the example grid is not linear in h (8.6, 37.6,
    12.1 N/mm at h = 80, 100, 120 um): no linear model reproduces it within 5 %, and the file
    must say so (warning) rather than hide it."""
    data = json.loads(STORED.read_text())
    pts = cal.predicted_forces(data)
    assert len(pts) >= 3
    for p in pts:
        assert p["Fc_rel_error"] <= 0.05, p
    ff_bad = max(p["Ff_rel_error"] for p in pts) > cal.FIT_TOLERANCE
    assert ff_bad == any(w.startswith("Ff fit") for w in data["warnings"])
    c = load_coefficients(STORED)
    assert c.Ktc > 0 and "FE-calibrated" in c.provenance
    assert data["material"] == "TC4" and data["robobore_version"]


# --- the FE model as a full FE config (calibration.fe_config) --------------------------------

_FULL = {"cut": {"length_mm": 0.2}, "mesh": {"element_size_um": 20.0}}


def _full(fe_config, tmp_path=None, **kw):
    d = {"calibration": {"uncut_chip_thickness_um": [60.0, 90.0],
                         "cutting_speed_m_per_min": [37.7], "fe_config": fe_config, **kw},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0, "clearance_deg": 6.0},
         "material": {"name": "TC4"}}
    src = None if tmp_path is None else str(tmp_path / "cal.toml")
    return calcfg.calibration_from_mapping(d, source=src or "cal.toml")


def test_full_fe_config_inline_overrides_only_h_vc_and_the_insert():
    from robobore.cutting.fe.config.orthogonal import parse_config

    c = _full(_FULL)
    assert c.fe_config_source == "inline"
    d = calcfg.fe_config_dict(c, 90.0, 37.7)
    assert d["cut"] == {"length_mm": 0.2, "uncut_chip_thickness_um": 90.0,
                        "cutting_speed_m_per_min": 37.7}
    assert d["tool"] == {"rake_deg": 7.0, "edge_radius_um": 20.0, "clearance_deg": 6.0}
    assert d["mesh"] == {"element_size_um": 20.0} and d["material"] == {"name": "TC4"}
    p = parse_config(d)
    # everything else is the engine's default: the validated model
    assert p.mesh.frame == "tool" and p.contact.friction_velocity == "sliding"
    m = calcfg.fe_model_description(c)
    assert m["validated_physics"] and "validated model" in m["validation"]
    # the departures from the checked domain are named: rake 7, 20 um, 0.2 mm, h 90, vc 37.7
    out = " | ".join(m["outside_validation"])
    for words in ("uncut_chip_thickness_um 90 outside", "cutting_speed_m_per_min 37.7",
                  "rake_deg 7", "element_size_um 20", "length_mm 0.2"):
        assert words in out
    assert "edge_radius_um" not in out and "material" not in out
    assert not calcfg.fe_model_description(_full({**_FULL, "parameters": "a_priori"}))[
        "validated_physics"]


def test_full_fe_config_from_a_file_next_to_the_config(tmp_path):
    (tmp_path / "sub").mkdir()
    f = tmp_path / "sub" / "fe.toml"
    f.write_text('[cut]\nlength_mm = 0.2\n[mesh]\nelement_size_um = 20.0\n'
                 '[contact]\nfriction = "rech2013"\n')
    c = _full("sub/fe.toml", tmp_path)
    assert c.fe_config_source == str(f.resolve())
    assert c.fe_config["contact"] == {"friction": "rech2013"}
    with pytest.raises(ConfigError, match="not found") as e:
        _full("nope.toml", tmp_path)
    assert e.value.field == "calibration.fe_config"


@pytest.mark.parametrize("fe_config, kw, field, words", [
    ({**_FULL, "mesh": {"element_size_um": 25.0}}, {},
     "calibration.fe_config.mesh.element_size_um", "h 60 um"),
    ({**_FULL, "contact": {"frcition": 0.3}}, {}, "calibration.fe_config.contact.frcition",
     "grid point"),
    ({**_FULL, "tool": {"rake_deg": 15.0}}, {}, "tool.rake_deg", "insert"),
    ({**_FULL, "material": {"name": "TC5"}}, {}, "material.name", "material"),
    (_FULL, {"fe": {"length_mm": 0.5}}, "calibration.fe", "once"),
    (3, {}, "calibration.fe_config", "bad FE config"),
])
def test_full_fe_config_errors_before_any_run(monkeypatch, fe_config, kw, field, words):
    def no_run(*a, **k):
        raise AssertionError("an FE run started before the config error was found")

    monkeypatch.setattr(calruns, "run_fe_point", no_run)
    with pytest.raises(ConfigError, match=words) as e:
        _full(fe_config, **kw)
    assert e.value.field == field


def test_full_fe_config_grid_runs_and_is_cached(tmp_path, monkeypatch):
    calls = _linear_fe(monkeypatch)
    cache = ResultCache(tmp_path / "cache")
    r = cal.calibrate_forces(_full(_FULL), cache=cache)
    assert len(calls) == 2 and r["fe_settings"] is None
    assert r["fe_model"]["source"] == "inline" and r["fe_model"]["validated_physics"]
    assert "tool-frame model" in r["coefficients"]["provenance"]
    assert r["coefficients"]["Ktc_N_per_m2"] == pytest.approx(1.6e9, rel=1e-9)
    cal.calibrate_forces(_full({**_FULL, "parameters": "a_priori"}), cache=cache)
    assert len(calls) == 4
