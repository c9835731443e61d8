"""One definition of each input section and range: the command line, a config file and
``robobore.api`` refuse the same out-of-range value with the same message
(:mod:`robobore.io.sections`, :mod:`robobore.io.ranges`)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from typer.testing import CliRunner

from robobore import api
from robobore.cli import app
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics.config import InsertCfg, load_dynamics_config
from robobore.errors import ConfigError
from robobore.io import sections
from robobore.io.ranges import RANGES

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples" / "boring_paper.toml"
runner = CliRunner()


def _with(tmp_path, old: str, new: str) -> Path:
    text = EX.read_text(encoding="utf-8")
    assert old in text
    p = tmp_path / "c.toml"
    p.write_text(text.replace(old, new), encoding="utf-8")
    return p


def _process(**cutting):
    return {"insert": {"nose_radius_mm": 0.4}, "bore": {"diameter_mm": 40.0},
            "cutting": {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_mm": 0.05,
                        **cutting},
            "coefficients": {"material": "TC4"},
            "equivalent": {"stiffness_N_per_m": {"x": 3e6, "y": 2.5e6, "z": 4e6},
                           "frequency_Hz": {"x": 6.9, "y": 16.8, "z": 24.6},
                           "damping_ratio": {"x": 0.035, "y": 0.028, "z": 0.02}}}


@pytest.mark.parametrize("key, option, value, rng", [
    ("depth_mm", "--depth-mm", 30.0, "depth_mm"),
    ("feed_mm_per_rev", "--feed-mm-per-rev", 7.0, "feed_mm_per_rev"),
])
def test_config_api_and_cli_refuse_an_out_of_range_cut_alike(tmp_path, key, option, value, rng):
    old = {"depth_mm": "depth_mm = 0.05", "feed_mm_per_rev": "feed_mm_per_rev = 0.15"}[key]
    cfg = _with(tmp_path, old, f"{key} = {value}")
    with pytest.raises(ConfigError) as from_file:
        load_dynamics_config(cfg)
    with pytest.raises(ConfigError) as from_dict:
        api.simulate_boring(_process(**{key: value}), revolutions=2)
    kw = {"depth_mm": "depth_mm", "feed_mm_per_rev": "feed_mm_per_rev"}[key]
    with pytest.raises(ConfigError) as from_arg:
        api.simulate_boring(str(EX), revolutions=2, **{kw: value})
    errs = (from_file.value, from_dict.value, from_arg.value)
    msgs = {e.message for e in errs}
    assert len(msgs) == 1 and msgs.pop().startswith("value out of the plausible range")
    assert {e.expected for e in errs} == {RANGES[rng].describe()}
    assert from_file.value.field == f"cutting.{key}"
    r = runner.invoke(app, ["simulate", "boring", str(EX), option, str(value)])
    assert r.exit_code == 2
    flat = " ".join(r.output.split())
    assert from_file.value.message in flat and RANGES[rng].bounds() in flat
    assert option in flat


def test_zero_depth_is_refused_even_with_the_range_check_off(monkeypatch):
    monkeypatch.setenv("ROBOBORE_NO_RANGE_CHECK", "1")
    r = runner.invoke(app, ["simulate", "boring", str(EX), "--depth-mm", "0"])
    assert r.exit_code == 2 and "a cut needs a positive value" in " ".join(r.output.split())


@pytest.mark.parametrize("key, value, bound", [
    ("nose_radius_mm", 12.0, "10"),
    ("inclination_deg", 20.0, "15"),
    ("end_edge_angle_deg", 90.0, "90"),
])
def test_every_command_reads_one_insert_section(tmp_path, key, value, bound):
    old = {"nose_radius_mm": "nose_radius_mm = 0.4", "inclination_deg": "inclination_deg = 0.0",
           "end_edge_angle_deg": "end_edge_angle_deg = 5.0"}[key]
    cfg = _with(tmp_path, old, f"{key} = {value}")
    with pytest.raises(ConfigError) as from_file:
        load_dynamics_config(cfg)
    proc = _process()
    proc["insert"][key] = value
    with pytest.raises(ConfigError) as from_dict:
        api.stability_lobes(proc)
    a, b = from_file.value, from_dict.value
    assert a.field == b.field == f"insert.{key}"
    # the same pydantic line, only the source differs
    assert a.message.split("] ", 1)[1] == b.message.split("] ", 1)[1]
    assert bound in a.message
    r = runner.invoke(app, ["lobes", str(cfg)])
    assert r.exit_code == 2 and f"insert.{key}" in r.output
    # the geometry object holds the same bound in SI
    si = {"nose_radius_mm": ("nose_radius_m", value * 1e-3)}.get(key, (key, value))
    with pytest.raises(ConfigError):
        BoringInsert(**{si[0]: si[1]})
    # the largest admitted value passes everywhere
    top = {"nose_radius_mm": 10.0, "inclination_deg": 15.0, "end_edge_angle_deg": 82.5}[key]
    ok = InsertCfg(**{key: top})
    ok.to_insert()


def test_the_insert_sections_are_one_class():
    from robobore.plan.config import PlanConfig
    from robobore.study.paper_config import PaperConfig

    assert issubclass(InsertCfg, sections.InsertSection)
    for model in (PlanConfig, PaperConfig):
        ann = model.model_fields["insert"].annotation
        assert ann is InsertCfg, (model, ann)


def test_one_strict_base_model():
    """No config module defines its own extra="forbid" base: they import
    :class:`robobore.io.sections.StrictModel` (the FE package as ``Strict``)."""
    found = []
    for p in sorted((ROOT / "src" / "robobore").rglob("*.py")):
        rel = p.relative_to(ROOT / "src").as_posix()
        if rel == "robobore/io/sections.py":
            continue
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef) and "Strict" in node.name and any(
                    isinstance(b, ast.Name) and b.id == "BaseModel" for b in node.bases):
                found.append(f"{rel}:{node.lineno} {node.name}")
    assert not found, found
    from robobore.io.sections import StrictModel as Strict

    assert Strict is sections.StrictModel


def test_a_sweep_condition_has_the_same_range():
    from pydantic import ValidationError

    from robobore.study.conditions import Condition

    Condition(speed_rpm=300.0, feed_mm_per_rev=0.15, depth_of_cut_mm=20.0)
    with pytest.raises(ValidationError, match="value out of the plausible range") as exc:
        Condition(speed_rpm=300.0, feed_mm_per_rev=0.15, depth_of_cut_mm=30.0)
    assert RANGES["depth_mm"].describe() in str(exc.value)
