"""The typed results of the process stage (robobore.dynamics.results): each entry point of
robobore.dynamics.api returns a frozen record whose ``to_dict()`` is the JSON the CLI writes.

The contract files under contract/ store each record's keys, in order, with the JSON types of
their values (robobore.io.records.json_types); a change to a record's fields changes the
JSON contract and must change the stored file with it.
"""

from __future__ import annotations

import dataclasses
import json
import typing
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.dynamics import results as R
from robobore.dynamics.api import critical_depth_at, lobes, run_boring
from robobore.io.records import json_mismatches, json_types
from robobore.io.results import to_jsonable

EX = Path(__file__).resolve().parents[2] / "examples"
CONTRACT = Path(__file__).parent / "contract"
runner = CliRunner()
#: the small case: 4 revolutions at 64 samples per revolution of the paper example
SMALL = ["--revolutions", "4", "--samples-per-rev", "64"]
#: keys the lobes command adds beside the entry point's (its notes and the process label)
LOBES_CLI_KEYS = {"notes", "process"}
#: keys of the entry point that the lobes command writes into its notes
LOBES_API_NOTES = {"speed_note", "coefficient_note"}


def _stored(name: str) -> dict:
    return json.loads((CONTRACT / f"{name}.json").read_text())["keys"]


def _json(obj) -> typing.Any:
    return json.loads(json.dumps(to_jsonable(obj)))


@pytest.mark.parametrize(("cls", "name"), [(R.BoringResult, "simulate_boring"),
                                           (R.LobesResult, "lobes"),
                                           (R.CriticalDepth, "critical_depth_at")])
def test_the_records_keys_and_types_are_the_stored_contract(cls, name):
    assert json_types(cls) == _stored(name)


def test_simulate_boring_json_is_the_records_to_dict():
    r = runner.invoke(app, ["simulate", "boring", str(EX / "boring_paper.toml"), *SMALL,
                            "--json"])
    assert r.exit_code == 0, r.output
    cli = json.loads(r.stdout)
    assert json_mismatches(cli, _stored("simulate_boring")) == []
    res = run_boring(EX / "boring_paper.toml", revolutions=4, samples_per_rev=64)
    assert isinstance(res, R.BoringResult) and res.dataset is None and res.config is None
    assert _json(res.to_dict()) == cli
    assert list(res.to_dict()) == list(cli)  # the same order
    # the attributes are the JSON's values
    assert res.force_mean_N.x == cli["force_mean_N"]["x"]
    assert res.verdicts.paper_criterion == cli["verdicts"]["paper_criterion"]
    assert list(res.reasons) == cli["reasons"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.chatter = True  # type: ignore[misc]
    assert not hasattr(res, "__dict__")  # slots
    # with the dataset: the same summary, the dataset and the config beside it
    full = run_boring(EX / "boring_paper.toml", revolutions=4, samples_per_rev=64,
                      return_dataset=True)
    d = full.to_dict()
    assert list(d)[-2:] == ["dataset", "config"]
    assert int(d["dataset"].attrs["samples_per_rev"]) == 64
    assert _json({k: v for k, v in d.items() if k not in ("dataset", "config")}) == cli


def test_a_sampling_check_is_a_record_in_the_json():
    chk = R.SamplingCheck(samples_per_rev=128, chatter=False, agrees=True)
    assert chk.to_dict() == {"samples_per_rev": 128, "chatter": False, "agrees": True}
    spec = _stored("simulate_boring")["sampling_check"]
    assert json_mismatches({"sampling_check": chk.to_dict()},
                           {"sampling_check": spec}) == []
    assert json_mismatches({"sampling_check": {"samples_per_rev": 1.5}},
                           {"sampling_check": spec}) != []


def test_lobes_json_is_the_records_to_dict():
    cfg = EX / "lobes_single_point.toml"
    r = runner.invoke(app, ["lobes", str(cfg), "--method", "frequency", "--json"])
    assert r.exit_code == 0, r.output
    cli = json.loads(r.stdout)
    res = lobes(cfg, method="frequency")
    assert isinstance(res, R.LobesResult) and isinstance(res.critical_depth_mm, np.ndarray)
    d = _json(res.to_dict())
    assert json_mismatches(d, _stored("lobes")) == []
    assert set(cli) - set(d) <= LOBES_CLI_KEYS
    assert set(d) - set(cli) <= LOBES_API_NOTES
    assert {k: v for k, v in d.items() if k in cli} == {
        k: v for k, v in cli.items() if k in d}
    # the CLI's notes hold the entry point's notes
    for k in LOBES_API_NOTES & set(d):
        assert d[k] in cli["notes"]


def test_critical_depth_at_is_the_lobes_json_at_the_first_speed(tmp_path):
    """No command writes critical_depth_at; its answer is the semi-discretisation lobes'
    (``robobore lobes --json``) at the first speed of a range (no neighbour to continue
    from)."""
    text = (EX / "boring_paper.toml").read_text()
    text = text.replace("min = 100.0\nmax = 3000.0\ncount = 300",
                        "min = 300.0\nmax = 400.0\ncount = 2")
    assert "count = 2" in text
    (tmp_path / "one.toml").write_text(text)
    r = runner.invoke(app, ["lobes", str(tmp_path / "one.toml"), "--json"])
    assert r.exit_code == 0, r.output
    cli = json.loads(r.stdout)
    res = critical_depth_at(EX / "boring_paper.toml", 300.0)
    assert isinstance(res, R.CriticalDepth)
    d = _json(res.to_dict())
    assert json_mismatches(d, _stored("critical_depth_at")) == []
    # the same search at the same speed; the two differ by round-off (measured 6e-15 rel)
    assert list(d) == ["speed_rpm", "critical_depth_mm", "interrupted_below_mm"]
    assert d == pytest.approx({"speed_rpm": cli["speed_rpm"][0],
                               "critical_depth_mm": cli["critical_depth_mm"][0],
                               "interrupted_below_mm": cli["interrupted_below_mm"][0]},
                              rel=1e-12)


def test_json_mismatches_names_what_departs():
    spec = {"a": ["number"], "b": ["absent", "string"], "c": [{"x": ["boolean"]}, "null"]}
    assert json_mismatches({"a": 1.0, "c": None}, spec) == []
    assert json_mismatches({"a": None, "b": "s", "c": {"x": True}}, spec) == []
    bad = json_mismatches({"c": {"x": 1}, "a": "1", "z": 0}, spec)
    assert any(m.startswith("z:") for m in bad)  # a key not in the contract
    assert any("out of order" in m for m in bad)
    assert any(m.startswith("a: str") for m in bad)
    assert any(m.startswith("c.x: int") for m in bad)
    assert json_mismatches({"c": None}, spec) == ["a: missing"]


def test_every_field_of_a_result_is_documented():
    # each field carries a "#:" comment in results.py (the field-by-field documentation)
    src = Path(R.__file__).read_text().splitlines()
    for name in R.__all__:
        cls = getattr(R, name)
        start = next(i for i, line in enumerate(src) if line.startswith(f"class {name}("))
        for f in dataclasses.fields(cls):
            i = next(j for j in range(start, len(src))
                     if src[j].strip().startswith(f"{f.name}:"))
            assert src[i - 1].strip().startswith("#:"), f"{name}.{f.name} undocumented"
