"""A sweep killed (SIGKILL) halfway and started again finishes with every condition
computed exactly once and nothing lost: the real command in a subprocess, killed for real."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from collections import Counter
from pathlib import Path

import xarray as xr
from conftest import robobore_cmd, subprocess_env, write_sweep_toml

from robobore.study.store import ResultsStore
from robobore.study.sweep import plan_from_file


def _markers(d: Path) -> Counter:
    return Counter(p.name.split(".")[0] for p in d.glob("*.run"))


def test_killed_sweep_resumes_without_loss_or_recomputation(tmp_path):
    marks = tmp_path / "marks"
    # 12 conditions, 0.25 s each, 2 Dask thread workers: ~1.5 s of work in the first run
    cfg = write_sweep_toml(tmp_path / "c.toml", runner_options=(
        f'marker_dir = "{marks}"\nsleep_s = 0.25'))
    plan = plan_from_file(cfg)
    keys = {i.key for i in plan.items}
    store_dir = tmp_path / "store"
    cmd = robobore_cmd("sweep", str(cfg), "--out", str(store_dir), "--workers", "2",
                       "--threads", "--json")

    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=subprocess_env(), start_new_session=True)
    try:
        deadline = time.monotonic() + 90
        results = store_dir / "results"
        while True:
            n_done = len(list(results.glob("*.nc"))) if results.exists() else 0
            if n_done >= 4:
                break
            assert proc.poll() is None, proc.communicate()[1].decode()[-2000:]
            assert time.monotonic() < deadline, "sweep did not store 4 conditions in 90 s"
            time.sleep(0.02)
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL

    st = ResultsStore(store_dir)
    done_before = st.done_keys()
    assert 4 <= len(done_before) < len(keys), "the kill must land halfway"
    started_before = _markers(marks)
    # every stored file is complete (opens, has its data and summary)
    for k in done_before:
        with xr.open_dataset(st.result_path(k)) as ds:
            assert ds.sizes["time_s"] > 10 and "feed_amplitude_um" in ds

    # restart: the same command finishes the sweep
    res = subprocess.run(cmd, capture_output=True, env=subprocess_env(), timeout=120)
    assert res.returncode == 0, res.stderr.decode()[-2000:]
    out = json.loads(res.stdout)
    assert out["skipped"] == len(done_before)
    assert out["computed"] == len(keys) - len(done_before)
    assert out["failed"] == 0 and out["pending"] == 0

    assert st.done_keys() == keys  # nothing lost
    after = _markers(marks)
    for k in done_before:  # stored before the kill: never computed again
        assert after[k] == 1, k
    for k in keys - done_before:  # computed (again, if it was in flight) exactly once more
        assert after[k] == started_before.get(k, 0) + 1, k
    for k in keys:
        assert st.read_record(k).attempt == 1  # no condition was stored twice
    # no half files anywhere in the store
    assert not [p for p in store_dir.rglob("*") if p.name.endswith(".tmp")]
    idx = json.loads((store_dir / "index.json").read_text())
    assert idx["counts"] == {"done": len(keys), "failed": 0, "pending": 0}


def _run_until(cmd, store_dir: Path, n_target: int, extra_s: float) -> None:
    """Start the sweep, SIGKILL it once ``n_target`` results are stored plus ``extra_s``."""
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=subprocess_env(), start_new_session=True)
    try:
        deadline = time.monotonic() + 90
        results = store_dir / "results"
        while True:
            n_done = len(list(results.glob("*.nc"))) if results.exists() else 0
            if n_done >= n_target or proc.poll() is not None:
                break
            assert time.monotonic() < deadline, "sweep did not progress in 90 s"
            time.sleep(0.01)
        time.sleep(extra_s)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)


def test_sweep_killed_at_random_points_computes_each_condition_once(tmp_path):
    """Three SIGKILLs at random points (seeded), then a run to the end: every condition is
    stored exactly once, and none stored before a kill is ever started again."""
    import random

    rng = random.Random(2811)
    marks = tmp_path / "marks"
    cfg = write_sweep_toml(tmp_path / "c.toml", speeds=(200, 400, 600, 800),
                           runner_options=f'marker_dir = "{marks}"\nsleep_s = 0.15')
    keys = {i.key for i in plan_from_file(cfg).items}  # 16 conditions
    store_dir = tmp_path / "store"
    cmd = robobore_cmd("sweep", str(cfg), "--out", str(store_dir), "--workers", "2",
                       "--threads", "--json")
    snapshots = []  # (stored keys, start markers) after each kill
    target = 0
    for _ in range(3):
        target = min(target + rng.randint(1, 4), len(keys) - 1)
        _run_until(cmd, store_dir, target, rng.uniform(0.0, 0.2))
        st = ResultsStore(store_dir)
        snapshots.append((st.done_keys(), _markers(marks)))
    res = subprocess.run(cmd, capture_output=True, env=subprocess_env(), timeout=120)
    assert res.returncode == 0, res.stderr.decode()[-2000:]
    st = ResultsStore(store_dir)
    assert st.done_keys() == keys
    final = _markers(marks)
    for done, marks_then in snapshots:
        for k in done:  # stored before this kill: never started again afterwards
            assert final[k] == marks_then[k], k
    for k in keys:
        assert st.read_record(k).attempt == 1  # stored exactly once
        assert final[k] >= 1
    assert not [p for p in store_dir.rglob("*") if p.name.endswith(".tmp")]


def test_zero_byte_and_unreadable_results_are_recomputed_with_a_warning(tmp_path):
    """A result file left empty (a crash of the disk, not of robobore: its own writes are
    atomic) or unreadable counts as missing: set aside as .invalid, recomputed, warned."""
    marks = tmp_path / "marks"
    cfg = write_sweep_toml(tmp_path / "c.toml", runner_options=f'marker_dir = "{marks}"')
    store_dir = tmp_path / "store"
    cmd = robobore_cmd("sweep", str(cfg), "--out", str(store_dir), "--workers", "0", "--json")
    res = subprocess.run(cmd, capture_output=True, env=subprocess_env(), timeout=120)
    assert res.returncode == 0, res.stderr.decode()[-2000:]
    st = ResultsStore(store_dir)
    keys = sorted(st.done_keys())
    assert len(keys) == 12
    empty, garbage = keys[0], keys[1]
    st.result_path(empty).write_bytes(b"")
    st.result_path(garbage).write_bytes(b"not a netCDF file" * 10)
    assert not st.is_done(empty)  # an empty file is not a result
    assert st.result_problem(garbage) is not None

    res = subprocess.run(cmd, capture_output=True, env=subprocess_env(), timeout=120)
    assert res.returncode == 0, res.stderr.decode()[-2000:]
    out = json.loads(res.stdout)
    assert out["computed"] == 2 and out["skipped"] == 10
    assert len(out["warnings"]) == 2
    assert any(empty in w and "zero-byte" in w for w in out["warnings"])
    assert any(garbage in w and "unreadable" in w for w in out["warnings"])
    assert (st.results_dir / f"{empty}.nc.invalid").is_file()
    after = _markers(marks)
    assert after[empty] == 2 and after[garbage] == 2  # computed again, once
    assert all(after[k] == 1 for k in keys[2:])
    with xr.open_dataset(st.result_path(empty)) as ds:
        assert "feed_amplitude_um" in ds
