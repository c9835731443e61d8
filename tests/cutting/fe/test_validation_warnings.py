"""`robobore fe orthogonal` says in its output where a config leaves the validated model or
the domain it was checked on (docs/fe.md, "Validation against the measured forces")."""

from __future__ import annotations

from pathlib import Path

from robobore.cutting.fe.cli import validation_warnings
from robobore.cutting.fe.config.orthogonal import load_fe_config, parse_config
from robobore.io.config import load_toml

_EX = Path(__file__).parents[3] / "examples"


def test_validated_configs_get_no_warning():
    for name in ("fe_orthogonal.toml", "fe_orthogonal_toolframe_calibrated.toml"):
        assert validation_warnings(load_fe_config(_EX / name)) == [], name


def test_each_departure_is_named():
    d = load_toml(_EX / "fe_orthogonal.toml")
    d["cut"]["uncut_chip_thickness_um"] = 100.0
    d["cut"]["cutting_speed_m_per_min"] = 60.0
    d["tool"]["rake_deg"] = 7.0
    d["contact"] = {"friction": 0.3}
    w = " | ".join(validation_warnings(parse_config(d)))
    for text in ("Coulomb 0.3", "uncut_chip_thickness_um 100 outside the validated 40-80",
                 "cutting_speed_m_per_min 60 outside the validated 5-30",
                 "rake_deg 7 (validated at 15)"):
        assert text in w, (text, w)
    # a unit slip inside the ranges the engine accepts is still flagged (h 60 -> 6 um needs
    # 2 um elements, which pass the engine's own checks)
    d = load_toml(_EX / "fe_orthogonal.toml")
    d["cut"]["uncut_chip_thickness_um"] = 6.0
    d["mesh"]["element_size_um"] = 2.0
    assert any("uncut_chip_thickness_um 6 " in x for x in validation_warnings(parse_config(d)))
    # a cut shorter than the validated 0.3 mm is named too
    d = load_toml(_EX / "fe_orthogonal.toml")
    d["cut"]["length_mm"] = 0.1
    assert any("length_mm 0.1 shorter than the validated 0.3" in x
               for x in validation_warnings(parse_config(d)))


def test_variants_are_flagged():
    w = validation_warnings(load_fe_config(_EX / "fe_orthogonal_nodesplit.toml"))
    assert any(x.startswith("workpiece-frame model") for x in w)
    assert any(x.startswith("a-priori parameters") for x in w)
