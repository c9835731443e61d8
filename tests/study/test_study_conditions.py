"""Sweep configs: grid/list expansion, the paper's levels, validation errors, keys."""

from __future__ import annotations

from pathlib import Path

import pytest

from robobore.errors import ConfigError
from robobore.study.conditions import (
    PAPER_LEVELS,
    Condition,
    SweepConfig,
    condition_key,
    condition_seed,
    expand_conditions,
    load_sweep_config,
    paper_conditions,
)


def _cfg(**kw) -> SweepConfig:
    return SweepConfig.model_validate(kw)


def test_grid_is_full_factorial_in_stable_order():
    cfg = _cfg(grid={"speed_rpm": [200, 400], "feed_mm_per_rev": [0.1, 0.2, 0.3],
                     "depth_of_cut_mm": {"start": 0.05, "stop": 0.3, "num": 6},
                     "pressure_MPa": [0, 0.3]})
    conds = expand_conditions(cfg)
    assert len(conds) == 2 * 3 * 6 * 2
    assert conds[0].ident() == (200, 0.1, 0.05, 0.0, "paper")
    assert conds[1].ident() == (200, 0.1, 0.05, 0.3, "paper")
    assert [c.depth_of_cut_mm for c in conds[:12:2]] == [0.05, 0.1, 0.15, 0.2, 0.25, 0.3]


def test_list_and_grid_together_and_duplicates_are_errors(tmp_path):
    cfg = _cfg(grid={"speed_rpm": [300], "feed_mm_per_rev": [0.15], "depth_of_cut_mm": [0.05]},
               conditions=[{"speed_rpm": 500, "feed_mm_per_rev": 0.2, "depth_of_cut_mm": 0.1}])
    assert len(expand_conditions(cfg)) == 2
    dup = _cfg(grid={"speed_rpm": [300], "feed_mm_per_rev": [0.15], "depth_of_cut_mm": [0.05]},
               conditions=[{"speed_rpm": 300.0, "feed_mm_per_rev": 0.15,
                            "depth_of_cut_mm": 0.05, "pressure_MPa": 0}])
    with pytest.raises(ConfigError, match="listed twice") as ei:
        expand_conditions(dup, source="s.toml")
    assert ei.value.field == "conditions.0" and "grid[0]" in str(ei.value)


def test_bad_condition_names_file_key_value_and_unit(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text('[[conditions]]\nspeed_rpm = 300\nfeed_mm_per_rev = -0.1\n'
                 'depth_of_cut_mm = 0.05\n')
    with pytest.raises(ConfigError) as ei:
        load_sweep_config(p)
    msg = str(ei.value)
    assert "bad.toml" in msg and "conditions.0.feed_mm_per_rev" in msg and "-0.1" in msg
    assert "mm" in msg


def test_unknown_key_and_empty_config_are_errors(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text('[grid]\nspeed_rpm = [300]\nfeed_mm_per_rev = [0.1]\ndepth_of_cut_mm = [0.1]\n'
                 'speed = [1]\n')
    with pytest.raises(ConfigError, match="grid.speed"):
        load_sweep_config(p)
    p.write_text('[sweep]\nname = "x"\n')
    with pytest.raises(ConfigError, match="no conditions"):
        load_sweep_config(p)


def test_unknown_posture_is_an_error():
    cfg = _cfg(conditions=[{"speed_rpm": 300, "feed_mm_per_rev": 0.1, "depth_of_cut_mm": 0.1,
                            "posture": "other"}],
               postures={"paper": {"joints_deg": [0, 0, 0, 0, 0, 0]}})
    with pytest.raises(ConfigError, match="unknown posture") as ei:
        expand_conditions(cfg)
    assert ei.value.field == "conditions.0.posture"


def test_paper_levels_cover_the_issue_ranges_and_the_quoted_conditions():
    # issue 6: speed 200-1000 r/min, feed 0.1-0.5 mm/r, depth 0.05-0.3 mm, P = 0 and 0.3 MPa
    assert (min(PAPER_LEVELS["speed_rpm"]), max(PAPER_LEVELS["speed_rpm"])) == (200, 1000)
    assert (min(PAPER_LEVELS["feed_mm_per_rev"]), max(PAPER_LEVELS["feed_mm_per_rev"])) == (
        0.1, 0.5)
    assert (min(PAPER_LEVELS["depth_of_cut_mm"]), max(PAPER_LEVELS["depth_of_cut_mm"])) == (
        0.05, 0.3)
    ofat = paper_conditions("ofat")
    # 7 speeds + 7 feeds + 6 depths, minus the base counted three times -> 18, per pressure
    assert len(ofat) == 2 * (7 + 7 + 6 - 2)
    ids = {(c["speed_rpm"], c["feed_mm_per_rev"], c["depth_of_cut_mm"], c["pressure_MPa"])
           for c in ofat}
    assert (300.0, 0.15, 0.05, 0.0) in ids  # paper Fig. 7
    assert (300.0, 0.5, 0.05, 0.3) in ids  # paper Fig. 8
    assert len(paper_conditions("grid")) == 2 * 7 * 7 * 6
    cfg = _cfg(sweep={"levels": "paper-ofat"})
    assert len(expand_conditions(cfg)) == 36


def test_condition_key_is_stable_and_sensitive():
    c = Condition(speed_rpm=300, feed_mm_per_rev=0.15, depth_of_cut_mm=0.05)
    c2 = Condition(speed_rpm=300.0, feed_mm_per_rev=0.15, depth_of_cut_mm=0.05, pressure_MPa=0)
    m1 = {"a": 1.0, "b": {"c": 2}}
    m2 = {"b": {"c": 2.0}, "a": 1}
    k = condition_key(c, "demo", m1)
    assert len(k) == 20
    assert k == condition_key(c2, "demo", m2)
    assert k != condition_key(c, "demo", {"a": 1.5, "b": {"c": 2}})
    assert k != condition_key(c, "other", m1)
    assert k != condition_key(c.model_copy(update={"pressure_MPa": 0.3}), "demo", m1)
    assert k != condition_key(c, "demo", m1, {"joints_deg": [1, 2, 3, 4, 5, 6]})
    assert condition_seed(0, k) == condition_seed(0, k) != condition_seed(1, k)


def test_to_si_conversion():
    si = Condition(speed_rpm=600, feed_mm_per_rev=0.2, depth_of_cut_mm=0.1,
                   pressure_MPa=0.3).to_si()
    assert si["revolution_period_s"] == pytest.approx(0.1)
    assert si["spindle_speed_rad_per_s"] == pytest.approx(20 * 3.141592653589793)
    assert si["feed_m_per_rev"] == pytest.approx(2e-4)
    assert si["depth_of_cut_m"] == pytest.approx(1e-4)
    assert si["pressure_Pa"] == pytest.approx(3e5)


def test_example_config_loads():
    root = Path(__file__).resolve().parents[2]
    cfg, conds = load_sweep_config(root / "examples" / "sweep_demo.toml")
    assert len(conds) == 5 * 3 * 4 * 2 + 1
    assert cfg.sweep.runner == "demo"
