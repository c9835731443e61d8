"""Stable hashes: invariant to representation, sensitive to content."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robobore.errors import InputError
from robobore.io.hashing import canonical_json, stable_hash


def test_representation_does_not_change_the_hash():
    a = {"b": 1, "a": [1.0, 2, (3, 4)], "c": {"y": -0.0, "x": np.float64(0.5)}}
    b = {"c": {"x": 0.5, "y": 0}, "a": (np.int64(1), 2.0, [3.0, np.array([4])[0]]), "b": 1.0}
    assert canonical_json(a) == canonical_json(b)
    assert stable_hash(a) == stable_hash(b)


def test_content_changes_the_hash():
    base = {"speed_rpm": 300.0, "feed": 0.1}
    assert stable_hash(base) != stable_hash({"speed_rpm": 300.0, "feed": 0.1 + 1e-12})
    assert stable_hash(base) != stable_hash({"speed_rpm": 300.0, "feed": 0.1, "x": None})
    assert stable_hash([1, 2]) != stable_hash([2, 1])
    assert stable_hash(True) != stable_hash(1)  # a flag is not a number


def test_hash_is_fixed_across_runs():
    # SHA-256 of the canonical text, computed independently (hashlib on the literal bytes);
    # guards against accidental changes of the canonical format (which would orphan stores)
    import hashlib

    assert canonical_json({"b": [0.5, "x"], "a": 1.0}) == '{"a":1,"b":[0.5,"x"]}'
    assert stable_hash({"a": 1, "b": [0.5, "x"]}) == hashlib.sha256(
        b'{"a":1,"b":[0.5,"x"]}').hexdigest()
    assert stable_hash({"a": 1, "b": [0.5, "x"]}) == (
        "d9dda6d0c61c7433e4751740c766c964aa4c33cbf44060db3843e8fbbce9f537")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf, np.float32("nan")])
def test_non_finite_is_refused(bad):
    with pytest.raises(InputError, match="non-finite"):
        stable_hash({"x": [1.0, bad]})


def test_unhashable_object_is_refused():
    with pytest.raises(InputError, match="cannot hash"):
        stable_hash({"x": object()})


json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-10**12, 10**12)
    | st.floats(allow_nan=False, allow_infinity=False) | st.text(max_size=8),
    lambda kids: st.lists(kids, max_size=4) | st.dictionaries(st.text(max_size=5), kids,
                                                              max_size=4),
    max_leaves=20,
)


@given(json_values)
def test_canonical_json_is_a_fixed_point(v):
    import json

    once = canonical_json(v)
    assert canonical_json(json.loads(once)) == once
