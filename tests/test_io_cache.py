"""Content-addressed cache: same inputs -> same entry, atomic commits, nothing on failure."""

from __future__ import annotations

import json
import multiprocessing as mp
from pathlib import Path

import numpy as np
import pytest

from robobore.errors import InputError
from robobore.io.cache import ResultCache, default_cache_dir

FE = {"material": "TC4", "h_um": 50.0, "v_m_per_min": 60, "mesh": {"n": 4000, "rake_deg": 5}}


def test_key_depends_on_content_and_version_only(tmp_path):
    c = ResultCache(tmp_path, version="1.0")
    same = {"mesh": {"rake_deg": 5.0, "n": np.int64(4000)}, "v_m_per_min": 60.0,
            "h_um": 50, "material": "TC4"}
    assert c.key("fe", FE) == c.key("fe", same)
    assert c.key("fe", FE) != c.key("fe", {**FE, "h_um": 51.0})
    assert c.key("fe", FE) != c.key("other", FE)
    assert c.key("fe", FE) != ResultCache(tmp_path, version="1.1").key("fe", FE)


def test_get_or_compute_computes_once_and_stores_inputs(tmp_path):
    c = ResultCache(tmp_path, version="1.0")
    calls = []

    def compute(folder: Path) -> None:
        calls.append(folder)
        np.save(folder / "forces.npy", np.array([1.0, 2.0, 3.0]))

    p1, hit1 = c.get_or_compute("fe", FE, compute)
    p2, hit2 = c.get_or_compute("fe", dict(reversed(list(FE.items()))), compute)
    assert (hit1, hit2) == (False, True) and p1 == p2 and len(calls) == 1
    np.testing.assert_array_equal(np.load(p2 / "forces.npy"), [1.0, 2.0, 3.0])
    assert json.loads((p1 / "inputs.json").read_text())["mesh"]["n"] == 4000
    meta = json.loads((p1 / "meta.json").read_text())
    assert meta["version"] == "1.0" and "forces.npy" in meta["files"]
    assert c.entries("fe") == [p1] and c.size_bytes() > 0


def test_failed_compute_leaves_nothing(tmp_path):
    c = ResultCache(tmp_path, version="1.0")

    def boom(folder: Path) -> None:
        (folder / "half.bin").write_bytes(b"x" * 100)
        raise RuntimeError("FE diverged")

    with pytest.raises(RuntimeError, match="FE diverged"):
        c.get_or_compute("fe", FE, boom)
    assert c.get("fe", FE) is None and c.entries() == []
    assert not [p for p in tmp_path.rglob("*") if p.is_file()]


def test_second_writer_of_the_same_entry_is_discarded(tmp_path):
    c = ResultCache(tmp_path, version="1.0")
    first = c.put("fe", FE, {"a.txt": "first"})
    second = c.put("fe", FE, {"a.txt": "second"})
    assert first == second and (first / "a.txt").read_text() == "first"
    assert len(list(first.parent.iterdir())) == 1  # no temporary folder left behind


def _put(args):
    root, i = args
    c = ResultCache(root, version="1.0")
    c.put("fe", FE, {"who.txt": str(i)})
    return c.get("fe", FE) is not None


def test_concurrent_writers_leave_one_complete_entry(tmp_path):
    with mp.get_context("spawn").Pool(2) as pool:
        assert all(pool.map(_put, [(str(tmp_path), i) for i in range(6)]))
    c = ResultCache(tmp_path, version="1.0")
    (entry,) = c.entries("fe")
    assert (entry / "who.txt").read_text() in {str(i) for i in range(6)}
    assert sorted(p.name for p in entry.iterdir()) == ["inputs.json", "meta.json", "who.txt"]
    assert len(list(entry.parent.iterdir())) == 1


def test_partial_folders_are_cleaned_and_bad_names_refused(tmp_path):
    c = ResultCache(tmp_path, version="1.0")
    (tmp_path / "fe" / "ab").mkdir(parents=True)
    (tmp_path / "fe" / "ab" / ".abcdef.x.tmp").mkdir()
    assert c.clean_partial() == 1
    with pytest.raises(InputError, match="file name"):
        c.put("fe", FE, {"../evil": b"x"})
    with pytest.raises(InputError, match="namespace"):
        c.key("a/b", FE)


def test_default_dir_honours_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("ROBOBORE_CACHE_DIR", str(tmp_path / "c"))
    assert default_cache_dir() == tmp_path / "c"
    monkeypatch.delenv("ROBOBORE_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert default_cache_dir() == tmp_path / "x" / "robobore"
