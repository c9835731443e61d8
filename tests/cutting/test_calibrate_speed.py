"""Issue 27's acceptance on the mechanistic coefficients, on the stored FE validation rows
(no FE run), and the speed-dependent calibration path of ``robobore calibrate forces``.

The FE forces are the validated 2D model's at the nine measured Ti6Al4V conditions (h 40/60/80
um x vc 5/10/30 m/min; the bundled validation record data/fe_validation/tc4_default_model.json,
``robobore fe validate examples/fe_orthogonal.toml``, 10 um elements); the measurements are
the bundled Ducobu et al. (CIRP 2022) data.
Targets: the mechanistic orthogonal forces reproduce their FE points within 5 % and the
measurements within Fc 10 % / Ff 25 % (the FE model's own validation targets).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from robobore.cutting import calibrate as cal
from robobore.cutting import calibration_config as calcfg
from robobore.cutting import calibration_runs as calruns
from robobore.cutting.coefficient_files import load_coefficients
from robobore.cutting.coefficient_sets import DUCOBU_FILE
from robobore.cutting.fe.models.validate import read_measured
from robobore.cutting.fe.models.validation_record import (
    bundled_validation_path,
    load_validation_record,
)
from robobore.io.config import load_toml

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fe_orthogonal.toml"


def _validation_grid():
    """The bundled validation record of the default model (robobore fe validate
    examples/fe_orthogonal.toml, nine points) as a calibration, without running the FE."""
    rec = load_validation_record(bundled_validation_path())
    cfg, recs = cal.validation_calibration(rec, load_toml(EXAMPLE), source=str(EXAMPLE))
    assert len(recs) == 9
    return cfg, recs


def test_speed_dependent_coefficients_meet_the_acceptance_on_the_validated_fe():
    """Every one of the nine points: within 5 % of its FE point, Fc within 10 % and Ff within
    25 % of the measurement (forces through the boring model's coefficient path at vc)."""
    cfg, recs = _validation_grid()
    r = cal.mechanistic_check(cfg, recs, read_measured(DUCOBU_FILE))
    assert len(r["points"]) == 9
    for p in r["points"]:
        assert abs(p["error_vs_fe"]["Fc"]) <= 0.05 and abs(p["error_vs_fe"]["Ff"]) <= 0.05, p
        assert abs(p["error_vs_measured"]["Fc"]) <= 0.10, p
        assert abs(p["error_vs_measured"]["Ff"]) <= 0.25, p
    assert r["passes"]
    # the pooled set over the three speeds misses Fc 10 % (the speed effect is lost): the
    # acceptance depends on the speed-dependent form
    pooled = cal.mechanistic_check(cfg, recs, read_measured(DUCOBU_FILE),
                                   speed_dependent=False)
    assert pooled["summary"]["error_vs_measured"]["Fc"]["max_abs"] > 0.10
    assert not pooled["passes"]


def test_leave_one_speed_out_cross_validation_on_the_validated_fe():
    """Calibrated from two speeds, the third predicted: the interpolated 10 m/min within 5 %
    of its FE points and within the measured tolerances; the held (extrapolated) 5 and 30
    m/min reported with their kind."""
    cfg, recs = _validation_grid()
    r = cal.mechanistic_check(cfg, recs, read_measured(DUCOBU_FILE))
    cv = {c["held_out_m_per_min"]: c for c in r["cross_validation"]}
    assert set(cv) == {5.0, 10.0, 30.0}
    assert cv[10.0]["kind"] == "interpolation"
    assert cv[5.0]["kind"].startswith("extrapolation (held at 10")
    assert cv[30.0]["kind"].startswith("extrapolation (held at 10")
    s = cv[10.0]["summary"]
    assert s["error_vs_fe"]["Fc"]["max_abs"] <= 0.05
    assert s["error_vs_fe"]["Ff"]["max_abs"] <= 0.05
    assert s["error_vs_measured"]["Fc"]["max_abs"] <= 0.10
    assert s["error_vs_measured"]["Ff"]["max_abs"] <= 0.25
    for c in cv.values():
        assert len(c["points"]) == 3
        assert all(p["vc_m_per_min"] == c["held_out_m_per_min"] for p in c["points"])


def test_cross_validation_recovers_a_ln_vc_ground_truth():
    """SYNTHETIC FE forces whose coefficients fall linearly in ln(vc): the held-out middle
    speed is predicted exactly; the held ends miss by the truth's change."""
    def k(vc):
        f = 1 - 0.1 * math.log(vc / 10.0)
        return 1.6e9 * f, 30e3 * f, 0.4e9 * f, 40e3 * f

    cfg = calcfg.calibration_from_mapping(
        {"calibration": {"uncut_chip_thickness_um": [40.0, 60.0, 80.0],
                         "cutting_speed_m_per_min": [10.0, 20.0, 40.0],
                         "fe": {"element_size_um": 10.0}},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0, "clearance_deg": 7.0},
         "material": {"name": "TC4"}}, source="test")
    recs = []
    for v in cfg.cutting_speed_m_per_min:
        ktc, kte, kfc, kfe = k(v)
        for h in cfg.uncut_chip_thickness_um:
            recs.append({"h_um": h, "vc_m_per_min": v, "Fc_N_per_m": kte + ktc * h * 1e-6,
                         "Ff_N_per_m": kfe + kfc * h * 1e-6, "cached": True, "fe": {}})
    r = cal.mechanistic_check(cfg, recs)
    assert r["summary"]["error_vs_fe"]["Fc"]["max_abs"] < 1e-9
    assert r["summary"]["error_vs_measured"]["Fc"] is None
    cv = {c["held_out_m_per_min"]: c for c in r["cross_validation"]}
    assert cv[20.0]["summary"]["error_vs_fe"]["Fc"]["max_abs"] < 1e-9
    held = cv[40.0]["summary"]["error_vs_fe"]["Fc"]["max_abs"]
    assert held == pytest.approx(k(20.0)[0] / k(40.0)[0] - 1, rel=1e-6)


def test_calibrate_forces_over_several_speeds_writes_fits_the_loader_uses(tmp_path,
                                                                           monkeypatch):
    """``robobore calibrate forces`` over a grid of three speeds (fake FE runner with a
    SYNTHETIC speed-dependent ground truth, no FE): the written file's per-speed fits are what
    load_coefficients returns at each calibrated speed, and between them the ln(vc)
    interpolation; the pooled set is different."""
    truth = {40.0: (1.7e9, 32e3, 0.45e9, 42e3), 80.0: (1.6e9, 30e3, 0.40e9, 40e3),
             160.0: (1.5e9, 28e3, 0.36e9, 38e3)}

    def fake(fe_cfg):
        h = fe_cfg["cut"]["uncut_chip_thickness_um"] * 1e-6
        ktc, kte, kfc, kfe = truth[fe_cfg["cut"]["cutting_speed_m_per_min"]]
        return {"cutting_force_N_per_mm": (kte + ktc * h) * 1e-3,
                "feed_force_N_per_mm": (kfe + kfc * h) * 1e-3, "chip_ratio": None}

    monkeypatch.setattr(calruns, "run_fe_point", fake)
    cfg = calcfg.calibration_from_mapping(
        {"calibration": {"uncut_chip_thickness_um": [60.0, 90.0],
                         "cutting_speed_m_per_min": [40.0, 80.0, 160.0]},
         "insert": {"rake_deg": 7.0, "edge_radius_um": 20.0, "clearance_deg": 7.0},
         "material": {"name": "TC4"}}, source="test.toml")
    out = tmp_path / "coef.json"
    cal.calibrate_forces(cfg, out=out)
    assert set(json.loads(out.read_text())["per_speed_fits"]) == {"40", "80", "160"}
    for v, (ktc, kte, kfc, kfe) in truth.items():
        c = load_coefficients(out, v)
        assert (c.Ktc, c.Kte, c.Kfc, c.Kfe) == pytest.approx((ktc, kte, kfc, kfe), rel=1e-9)
    mid = load_coefficients(out, 113.137)  # sqrt(80 * 160): halfway in ln(vc)
    assert mid.Ktc == pytest.approx(1.55e9, rel=1e-4)
    pooled = load_coefficients(out, 40.0, speed_dependent=False)
    assert pooled.Ktc == pytest.approx(1.6e9, rel=1e-9)
    assert load_coefficients(out, 40.0).Ktc != pytest.approx(pooled.Ktc, rel=1e-3)


def test_multi_speed_calibration_checks_the_per_speed_fits_and_the_cli_shows_them(
        tmp_path, monkeypatch):
    """With several speeds the fit warnings concern the per-speed fits (what the boring model
    uses) plus the pooled set's miss; predicted_forces and the CLI table show the per-speed
    fits. SYNTHETIC FE: the cutting force falls by 20 % from 40 to 160 m/min."""
    from typer.testing import CliRunner

    from robobore.cli import app

    def fake(fe_cfg):
        h = fe_cfg["cut"]["uncut_chip_thickness_um"] * 1e-6
        f = 1 - 0.2 * math.log(fe_cfg["cut"]["cutting_speed_m_per_min"] / 40.0) / math.log(4)
        return {"cutting_force_N_per_mm": (30e3 + 1.6e9 * h) * f * 1e-3,
                "feed_force_N_per_mm": (40e3 + 0.4e9 * h) * 1e-3, "chip_ratio": None}

    monkeypatch.setattr(calruns, "run_fe_point", fake)
    monkeypatch.setenv("ROBOBORE_CACHE_DIR", str(tmp_path / "cache"))
    toml = tmp_path / "cal.toml"
    toml.write_text('[calibration]\nuncut_chip_thickness_um = [60.0, 75.0, 90.0]\n'
                    'cutting_speed_m_per_min = [40.0, 80.0, 160.0]\n'
                    '[insert]\nrake_deg = 7.0\nedge_radius_um = 20.0\nclearance_deg = 7.0\n'
                    '[material]\nname = "TC4"\n')
    d = cal.calibrate_forces(calcfg.load_calibration_config(toml))
    assert len(d["warnings"]) == 1 and "pooled set" in d["warnings"][0]
    assert max(p["Fc_rel_error"] for p in cal.predicted_forces(d)) < 1e-9
    res = CliRunner().invoke(app, ["calibrate", "forces", str(toml), "--workers", "1",
                                   "--out", str(tmp_path / "c.json")])
    assert res.exit_code == 0, res.output
    assert "per-speed fits" in res.output and "pooled set" in res.output
    assert load_coefficients(tmp_path / "c.json", 80.0).Ktc == pytest.approx(
        1.6e9 * 0.9, rel=1e-9)
