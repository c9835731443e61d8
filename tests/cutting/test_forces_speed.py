"""Speed-dependent coefficients from a calibration file (robobore.cutting.forces
coefficients_at_speed / load_coefficients, dynamics.config.build_coefficients).

Ground truth (SYNTHETIC, defined here): per-speed fits at 10, 20 and 40 m/min whose
coefficients fall linearly in ln(vc): K(vc) = K(10) (1 - 0.1 ln(vc / 10)); the pooled set is
another, speed-independent value. Interpolation in ln(vc) between the calibrated speeds must
reproduce the ground truth exactly; outside, the end values hold.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import pytest

from robobore.cutting.coefficient_files import (
    coefficients_at_speed,
    inline_coefficients,
    load_coefficients,
    read_coefficients_file,
)
from robobore.cutting.forces import CuttingCoefficients
from robobore.errors import ConfigError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
K10 = {"Ktc_N_per_m2": 1.6e9, "Kte_N_per_m": 30e3, "Kfc_N_per_m2": 0.4e9, "Kfe_N_per_m": 40e3}


def truth(vc: float) -> dict[str, float]:
    return {k: v * (1 - 0.1 * math.log(vc / 10.0)) for k, v in K10.items()}


def _data(speeds=(10.0, 20.0, 40.0), **extra) -> dict:
    return {"format": "robobore cutting coefficients 1",
            "coefficients": {"Ktc_N_per_m2": 1.5e9, "Krc_N_per_m2": 0.0, "Kfc_N_per_m2": 0.38e9,
                             "Kte_N_per_m": 28e3, "Kre_N_per_m": 0.0, "Kfe_N_per_m": 39e3,
                             "provenance": "SYNTHETIC test calibration"},
            "per_speed_fits": {f"{v:g}": truth(v) for v in speeds},
            "insert": {"inclination_deg": 0.0}, **extra}


def _vals(c: CuttingCoefficients) -> tuple[float, ...]:
    return (c.Ktc, c.Krc, c.Kfc, c.Kte, c.Kre, c.Kfe)


def _same(c: CuttingCoefficients, k: dict[str, float]) -> None:
    assert c.Ktc == pytest.approx(k["Ktc_N_per_m2"], rel=1e-12)
    assert c.Kte == pytest.approx(k["Kte_N_per_m"], rel=1e-12)
    assert c.Kfc == pytest.approx(k["Kfc_N_per_m2"], rel=1e-12)
    assert c.Kfe == pytest.approx(k["Kfe_N_per_m"], rel=1e-12)


@pytest.mark.parametrize("vc", [10.0, 14.0, 20.0, 31.5, 40.0])
def test_interpolates_in_ln_vc_between_calibrated_speeds(vc):
    c = coefficients_at_speed(_data(), vc)
    _same(c, truth(vc))
    assert c.speed_m_per_min == vc and c.warnings == ()
    assert "speed-dependent" in c.provenance and "ln(vc)" in c.provenance


@pytest.mark.parametrize("vc,edge", [(3.0, 10.0), (120.0, 40.0)])
def test_held_at_the_end_values_outside_with_a_warning(vc, edge):
    c = coefficients_at_speed(_data(), vc)
    _same(c, truth(edge))
    assert c.speed_m_per_min == edge
    assert len(c.warnings) == 1 and "outside the calibrated speeds 10-40" in c.warnings[0]
    assert c.warnings[0] in c.provenance


def test_pooled_set_when_forced_one_speed_or_speed_unknown():
    pooled = CuttingCoefficients.from_dict(_data()["coefficients"])
    c = coefficients_at_speed(_data(), 20.0, speed_dependent=False)
    assert _vals(c) == _vals(pooled) and c.warnings == () and c.speed_m_per_min is None
    assert "speed_dependent = false" in c.provenance
    one = coefficients_at_speed(_data(speeds=(20.0,)), 35.0)
    assert one == pooled and one.provenance == pooled.provenance  # as without per-speed fits
    unknown = coefficients_at_speed(_data(), None)
    assert _vals(unknown) == _vals(pooled) and "cutting speed not known" in unknown.warnings[0]
    # an inclined insert's set went through orthogonal-to-oblique: the pooled one is kept
    inc = coefficients_at_speed(_data(insert={"inclination_deg": 10.0}), 20.0)
    assert _vals(inc) == _vals(pooled) and "inclined insert" in inc.warnings[0]


def test_load_coefficients_from_a_file_at_a_speed(tmp_path):
    p = tmp_path / "c.json"
    p.write_text(json.dumps(_data()))
    _same(load_coefficients(p, 20.0), truth(20.0))
    pooled = CuttingCoefficients.from_dict(_data()["coefficients"])
    assert _vals(load_coefficients(p)) == _vals(pooled)


@pytest.mark.parametrize("mutate,field,words", [
    (lambda d: d.update(per_speed_fits=[1, 2]), "per_speed_fits", "not a table"),
    (lambda d: d["per_speed_fits"].update({"fast": truth(10.0)}), "per_speed_fits.fast",
     "not a cutting speed"),
    (lambda d: d["per_speed_fits"].update({"-5": truth(10.0)}), "per_speed_fits.-5",
     "non-positive"),
    (lambda d: d["per_speed_fits"].update({"nan": truth(10.0)}), "per_speed_fits.nan",
     "non-positive or non-finite"),
    (lambda d: d["per_speed_fits"].update({"10.0": truth(10.0)}), "per_speed_fits.10.0",
     "listed twice"),
    (lambda d: d["per_speed_fits"].update({"30": 5}), "per_speed_fits.30", "not a table"),
    (lambda d: d["per_speed_fits"]["20"].pop("Kfe_N_per_m"), "per_speed_fits.20.Kfe_N_per_m",
     "missing key"),
    (lambda d: d["per_speed_fits"]["20"].update(Kte_N_per_m="big"),
     "per_speed_fits.20.Kte_N_per_m", "not a number"),
    (lambda d: d["per_speed_fits"]["20"].update(Ktc_N_per_m2=1600.0),
     "per_speed_fits.20.Ktc_N_per_m2", "plausible range"),
    (lambda d: d["per_speed_fits"]["20"].update(Ktc_N_per_m2=-1.6e9),
     "per_speed_fits.20.Ktc_N_per_m2", ""),
])
def test_malformed_per_speed_block_names_file_key_value(tmp_path, mutate, field, words):
    d = copy.deepcopy(_data())
    mutate(d)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(d))
    with pytest.raises(ConfigError) as e:
        read_coefficients_file(p)
    assert e.value.file == str(p) and e.value.field == field
    assert words in str(e.value) and e.value.expected


def _dyn_config(tmp_path: Path, coef_lines: str) -> Path:
    text = (EXAMPLES / "boring_paper.toml").read_text().replace('material = "TC4"',
                                                                coef_lines)
    p = tmp_path / "c.toml"
    p.write_text(text)
    return p


@pytest.mark.parametrize("rpm", [100.0, 200.0, 300.0])
def test_build_coefficients_evaluates_a_file_at_pi_d_n(tmp_path, rpm):
    """The boring model's coefficients come from the file at vc = pi D n (D 40 mm)."""
    from robobore.dynamics.config import build_coefficients, load_dynamics_config

    (tmp_path / "coef.json").write_text(json.dumps(_data()))
    cfg, _ = load_dynamics_config(_dyn_config(tmp_path, 'file = "coef.json"'))
    cfg.cutting = cfg.cutting.model_copy(update={"speed_rpm": rpm})
    vc = math.pi * 0.040 * rpm
    _same(build_coefficients(cfg), truth(min(vc, 40.0)))
    cfg2, _ = load_dynamics_config(_dyn_config(
        tmp_path, 'file = "coef.json"\nspeed_dependent = false'))
    assert _vals(build_coefficients(cfg2)) == _vals(
        CuttingCoefficients.from_dict(_data()["coefficients"]))


def test_inline_per_speed_fits_as_the_paper_study_passes_them(tmp_path):
    """The studies put the file's values inline (inline_coefficients); the boring model then
    evaluates the per-speed fits at each condition's speed, as from the file."""
    from robobore.dynamics.config import (
        DynamicsConfig,
        build_coefficients,
        load_dynamics_config,
        lobe_coefficient_note,
    )

    cfg, raw = load_dynamics_config(_dyn_config(tmp_path, 'material = "TC4"'))
    raw = dict(raw)
    raw["coefficients"] = inline_coefficients(_data())
    assert set(raw["coefficients"]["per_speed_fits"]) == {"10", "20", "40"}
    c = build_coefficients(DynamicsConfig.model_validate(raw))  # vc = 37.7 m/min
    _same(c, truth(math.pi * 0.040 * 300.0))
    assert "37.7 m/min" in lobe_coefficient_note(DynamicsConfig.model_validate(raw))
    raw["coefficients"] = inline_coefficients(_data(), speed_dependent=False)
    assert raw["coefficients"]["speed_dependent"] is False
    assert _vals(build_coefficients(DynamicsConfig.model_validate(raw))) == _vals(
        CuttingCoefficients.from_dict(_data()["coefficients"]))


def test_bundled_paper_calibration_has_one_speed_so_the_study_uses_its_one_set():
    """The bundled file has one speed (37.7 m/min): the inline table is the coefficients as
    they are (no per-speed fits), so the paper study's conditions are unchanged; the
    calibration's grid goes with them (the domain of their warnings)."""
    from robobore.study.paper_config import example_dir

    d = read_coefficients_file(example_dir() / "tc4_fe_coefficients.json")
    assert list(d["per_speed_fits"]) == ["37.7"]
    inline = inline_coefficients(d)
    assert inline.pop("grid") == d["grid"]
    assert inline == dict(d["coefficients"])


def test_speed_dependent_false_with_the_measured_default_is_refused(tmp_path):
    from robobore.dynamics.config import load_dynamics_config

    with pytest.raises(ConfigError) as e:
        load_dynamics_config(_dyn_config(tmp_path, 'material = "TC4"\nspeed_dependent = false'))
    assert "speed_dependent" in str(e.value)


def test_simulate_reports_a_speed_outside_the_calibrated_range(tmp_path):
    """run_boring (robobore simulate boring) lists the hold as a coefficients warning; inside
    the calibrated speeds there is none. The lobes note names the [cutting] speed."""
    from robobore.dynamics.api import run_boring
    from robobore.dynamics.config import load_dynamics_config, lobe_coefficient_note

    (tmp_path / "coef.json").write_text(json.dumps(_data(speeds=(10.0, 20.0))))
    p = _dyn_config(tmp_path, 'file = "coef.json"')
    r = run_boring(p, revolutions=4, samples_per_rev=64)  # 300 r/min, D 40 mm: 37.7 m/min
    assert len(r.coefficient_warnings) == 1
    assert "37.7 m/min outside the calibrated speeds 10-20" in r.coefficient_warnings[0]
    r2 = run_boring(p, speed_rpm=120.0, revolutions=4, samples_per_rev=64)  # 15.1 m/min
    assert r2.coefficient_warnings == ()
    assert "interpolated linearly in ln(vc) at 15.08 m/min" in r2.coefficients_provenance
    cfg, _ = load_dynamics_config(p)
    assert "300 r/min (vc 37.7 m/min)" in lobe_coefficient_note(cfg)
    (tmp_path / "one.json").write_text(json.dumps(_data(speeds=(20.0,))))
    cfg1, _ = load_dynamics_config(_dyn_config(tmp_path, 'file = "one.json"'))
    assert lobe_coefficient_note(cfg1) is None  # one set for every speed: nothing to say
