"""The paper report's force-model section: it names the FE model the coefficients were
calibrated from, lists how the calibration's FE tests depart from the validated
configuration, and shows the bundled validation table of that model (nine measured points,
robobore/data/fe_validation); a model without the validated physics gets no table."""

from __future__ import annotations

import copy
import json
import re

import pytest

from robobore.cutting.fe.models.validation_record import (
    bundled_validation_path,
    load_validation_record,
)
from robobore.errors import DataError
from robobore.study import paper_config as pc
from robobore.study.paper_report import force_model_fe_text, force_model_validation
from robobore.study.report import Report

COEFFS = json.loads((pc.example_dir() / "tc4_fe_coefficients.json").read_text())


def _section(coeffs: dict, record=None) -> str:
    rep = Report("t").add_section("Force model (FE-calibrated)")
    force_model_fe_text(rep, coeffs)
    force_model_validation(rep, coeffs, record)
    return "".join(rep._parts)


def _tables(html: str) -> list[str]:
    return re.findall(r"<table>.*?</table>", html, flags=re.S)


def test_bundled_record_is_the_nine_point_validation_of_the_default_model():
    rec = load_validation_record(bundled_validation_path())
    assert len(rec.points) == 9
    assert rec.config.endswith("fe_orthogonal.toml")
    hv = {(p.uncut_chip_thickness_um, p.cutting_speed_m_per_min) for p in rec.points}
    assert hv == {(h, v) for h in (40.0, 60.0, 80.0) for v in (5.0, 10.0, 30.0)}
    for p in rec.points:  # every error is simulated / measured - 1 of the stored values
        m = p.measured.cutting_force_N_per_mm
        assert p.relative_error.cutting_force == pytest.approx(
            p.cutting_force_N_per_mm / m - 1, rel=1e-9)


def test_section_names_the_model_lists_departures_and_shows_nine_rows():
    html = _section(COEFFS)
    m = COEFFS["fe_model"]
    assert m["validated_physics"]
    assert "FE model of the virtual tests: tool-frame model" in html
    assert "rech2013_calibrated" in html
    # the departures from the validated configuration, one list item each
    items = re.findall(r"<li>(.*?)</li>", html)
    assert items == [re.sub("'", "&#x27;", x) for x in m["outside_validation"]] and items
    (table,) = _tables(html)
    assert "Validation of the FE model" in table
    assert len(re.findall(r"<tr>", table)) == 1 + 9  # header + nine measured points
    for col in ("Fc meas [N/mm]", "Fc sim [N/mm]", "Fc err [%]", "Ff meas [N/mm]",
                "Ff sim [N/mm]", "Ff err [%]", "chip ratio sim"):
        assert col in table
    rec = load_validation_record(bundled_validation_path())
    mx = rec.summary.max_abs_error.cutting_force
    assert f"Fc {100 * mx:.1f} / " in html
    assert "not an independent validation" in html and "fe validate" in html


def test_model_without_the_validated_physics_gets_no_table():
    c = copy.deepcopy(COEFFS)
    c["fe_model"]["validated_physics"] = False
    c["fe_model"]["validation"] = "not the engine's validated model"
    html = _section(c)
    assert not _tables(html) and "no validation against measured forces applies" in html
    c2 = copy.deepcopy(COEFFS)
    del c2["fe_model"]
    assert "does not name the FE model" in _section(c2)


def test_bad_validation_record_is_a_data_error(tmp_path):
    f = tmp_path / "rec.json"
    f.write_text(json.dumps({"points": [{"uncut_chip_thickness_um": 40}], "summary": {}}))
    with pytest.raises(DataError, match="lacks a key") as e:
        _section(COEFFS, f)
    assert e.value.file == str(f) and e.value.field.startswith("points[0].")
    assert "missing from this installation" in _section(COEFFS, tmp_path / "none.json")
