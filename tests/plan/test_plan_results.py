"""The typed result of the posture planner (robobore.plan.results): the stored contract of
its keys and types, and the field-by-field documentation. The equality of ``to_dict()`` with
the JSON ``robobore plan posture`` writes is checked in test_plan_posture.py (it needs the
identification fixture)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from robobore.io.records import json_types
from robobore.plan import results as R

CONTRACT = Path(__file__).parent / "contract"


def stored(name: str) -> dict:
    return json.loads((CONTRACT / f"{name}.json").read_text())["keys"]


@pytest.mark.parametrize(("cls", "name"), [(R.PostureResult, "plan_posture"),
                                           (R.Candidate, "candidate")])
def test_the_records_keys_and_types_are_the_stored_contract(cls, name):
    assert json_types(cls) == stored(name)


def test_the_arrays_stay_out_of_the_json():
    assert "arrays" not in json_types(R.PostureResult)
    assert "arrays" in {f.name for f in dataclasses.fields(R.PostureResult)}


def test_every_field_of_a_result_is_documented():
    src = Path(R.__file__).read_text().splitlines()
    for name in R.__all__:
        cls = getattr(R, name)
        start = next(i for i, line in enumerate(src) if line.startswith((f"class {name}(", f"class {name}:")))
        for f in dataclasses.fields(cls):
            i = next(j for j in range(start, len(src))
                     if src[j].strip().startswith(f"{f.name}:"))
            assert src[i - 1].strip().startswith("#:"), f"{name}.{f.name} undocumented"
