"""Results store: atomic per-condition files, status, failures, derived index."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from robobore.errors import DataError
from robobore.study.store import ResultsStore
from robobore.study.summary import summarise, summary_from_json, summary_to_json

COND = {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
        "pressure_MPa": 0.0, "posture": "paper"}


def _ds(stable=True, fx=10.0):
    return xr.Dataset({"x": ("t", np.arange(5.0)), "force_amplitude_x_N": ((), fx),
                       "stable": ((), stable)}, attrs={"feed_amplitude_um": 2.5})


def test_write_read_status_and_provenance(tmp_path):
    st = ResultsStore(tmp_path / "s")
    assert st.status("k1") == "pending"
    st.write_result("k1", COND, _ds(), runner="demo", config={"model": {"a": 1}}, seed=7,
                    wall_time_s=0.5, worker="h:1")
    assert st.status("k1") == "done" and st.done_keys() == {"k1"}
    rec = st.read_record("k1")
    assert rec.condition == COND
    assert rec.summary == {"force_amplitude_x_N": 10.0, "feed_amplitude_um": 2.5,
                           "stable": True}
    assert rec.attempt == 1 and rec.wall_time_s == 0.5 and rec.runner == "demo"
    ds = st.load("k1")
    assert ds.attrs["robobore_seed"] == 7
    assert json.loads(ds.attrs["robobore_config"])["model"] == {"a": 1}
    np.testing.assert_array_equal(ds["x"].values, np.arange(5.0))
    assert summarise(ds) == rec.summary


def test_failure_then_success_counts_attempts(tmp_path):
    st = ResultsStore(tmp_path)
    st.write_failure("k", COND, "RuntimeError: boom", "Traceback ...")
    st.write_failure("k", COND, "RuntimeError: boom again", "Traceback ...")
    assert st.status("k") == "failed" and st.failure("k")["attempts"] == 2
    st.write_result("k", COND, _ds(), runner="demo")
    assert st.status("k") == "done" and st.failure("k") is None
    assert st.read_record("k").attempt == 3


def test_result_breaking_the_summary_contract_is_not_stored(tmp_path):
    st = ResultsStore(tmp_path)
    with pytest.raises(DataError, match="force_amplitude_x_N"):
        st.write_result("k", COND, _ds(fx=-1.0), runner="demo")
    with pytest.raises(DataError, match="stable"):
        st.write_result("k", COND, _ds(stable="maybe"), runner="demo")
    assert st.status("k") == "pending" and not list((tmp_path / "results").iterdir())


def test_cleanup_removes_only_temporary_files(tmp_path):
    st = ResultsStore(tmp_path)
    st.write_result("k", COND, _ds(), runner="demo")
    half = tmp_path / "results" / ".k2.nc.abc123.tmp"
    half.write_bytes(b"\x89HDF half written")
    removed = st.cleanup_partial()
    assert removed == [half] and not half.exists() and st.is_done("k")


def test_index_and_summary_csv(tmp_path):
    st = ResultsStore(tmp_path)
    st.write_result("a", COND, _ds(), runner="demo")
    st.write_failure("b", {**COND, "speed_rpm": 400.0}, "E: x")
    items = [("a", COND), ("b", {**COND, "speed_rpm": 400.0}),
             ("c", {**COND, "speed_rpm": 500.0})]
    idx = st.write_index("t", "demo", items)
    assert idx["counts"] == {"done": 1, "failed": 1, "pending": 1}
    on_disk = json.loads((tmp_path / "index.json").read_text())
    assert [e["status"] for e in on_disk["conditions"]] == ["done", "failed", "pending"]
    assert on_disk["conditions"][1]["error"] == "E: x"
    lines = st.write_summary_csv().read_text().splitlines()
    assert lines[0].startswith("key,speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa")
    assert len(lines) == 2 and lines[1].startswith("a,300.0,0.15,0.05,0.0,paper,10.0")
    assert lines[1].endswith(",2.5,true")


def test_refuses_a_folder_that_is_not_a_store(tmp_path):
    (tmp_path / "something.txt").write_text("x")
    with pytest.raises(DataError, match="not a results store"):
        ResultsStore(tmp_path)
    with pytest.raises(DataError, match="no store.json"):
        ResultsStore.open_existing(tmp_path / "nothing")
    (tmp_path / "s").mkdir()
    (tmp_path / "s" / "store.json").write_text('{"store_format": 99}')
    with pytest.raises(DataError, match="store_format"):
        ResultsStore(tmp_path / "s")


def test_summary_json_round_trip():
    flat = {"force_amplitude_x_N": 1.0, "force_amplitude_z_N": 3.0, "feed_amplitude_um": 4.0,
            "stable": False}
    js = summary_to_json(flat)
    assert js == {"force_amplitude_N": {"x": 1.0, "z": 3.0}, "feed_amplitude_um": 4.0,
                  "stable": False}
    assert summary_from_json(js) == flat
    with pytest.raises(DataError, match="stable"):
        summary_from_json({"stable": "perhaps"})


def test_a_store_is_used_by_one_sweep_at_a_time(tmp_path):
    import subprocess
    import sys

    from robobore.errors import RoboboreError

    st = ResultsStore(tmp_path)
    with st.lock():
        with pytest.raises(RoboboreError, match="in use by another sweep"):
            with ResultsStore(tmp_path).lock():
                pass
        # another process is refused too, and is told who holds the store
        code = ("from robobore.study.store import ResultsStore\n"
                f"with ResultsStore({str(tmp_path)!r}).lock(): pass\n")
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           timeout=60)
        assert r.returncode != 0 and "in use by another sweep (pid" in r.stderr
    with ResultsStore(tmp_path).lock():  # released
        pass
