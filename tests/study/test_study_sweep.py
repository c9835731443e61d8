"""Sweeps: serial, Dask and process-pool runs give the same stored results; failures
(a dead pool worker too) are recorded and do not stop the others; a second run recomputes
only what is missing or failed; a sweep runs on a Dask scheduler started separately on
loopback."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from conftest import write_sweep_toml

from robobore.errors import ConfigError, RoboboreError
from robobore.study.store import ResultsStore
from robobore.study.sweep import execute, plan_from_file, resolve_runner, run_sweep


def _markers(d: Path) -> Counter:
    return Counter(p.name.split(".")[0] for p in d.glob("*.run")) if d.exists() else Counter()


def test_serial_and_dask_threads_store_identical_results(tmp_path):
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml"))
    a = run_sweep(plan, tmp_path / "serial", workers=0)
    b = run_sweep(plan, tmp_path / "dask", workers=2, processes=False)
    assert a.computed == b.computed == len(plan.items) == 12
    assert a.failed == b.failed == 0 and a.pending == b.pending == 0
    sa, sb = ResultsStore(tmp_path / "serial"), ResultsStore(tmp_path / "dask")
    assert sa.done_keys() == sb.done_keys() == {i.key for i in plan.items}
    for item in plan.items:
        da, db = sa.load(item.key), sb.load(item.key)
        np.testing.assert_array_equal(da["z_um"].values, db["z_um"].values)
        assert sa.read_record(item.key).summary == sb.read_record(item.key).summary
        assert json.loads(da.attrs["robobore_condition"]) == item.condition
    idx = json.loads((tmp_path / "dask" / "index.json").read_text())
    assert idx["counts"] == {"done": 12, "failed": 0, "pending": 0}
    assert len((tmp_path / "dask" / "summary.csv").read_text().splitlines()) == 13


def test_process_pool_stores_the_serial_results_and_records_failures(tmp_path):
    marks = tmp_path / "marks"
    cfg = write_sweep_toml(tmp_path / "c.toml", runner_options=(
        f'marker_dir = "{marks}"\nfail_speeds_rpm = [400]'))
    plan = plan_from_file(cfg)
    a = run_sweep(plan, tmp_path / "serial", workers=0)
    b = run_sweep(plan, tmp_path / "pool", workers=2, pool="processes")
    assert b.mode == "local process pool, 2 worker(s)"
    assert (a.computed, a.failed) == (b.computed, b.failed) == (8, 4)
    sa, sb = ResultsStore(tmp_path / "serial"), ResultsStore(tmp_path / "pool")
    assert sa.done_keys() == sb.done_keys()
    for key in sa.done_keys():
        da, db = sa.load(key), sb.load(key)
        np.testing.assert_array_equal(da["z_um"].values, db["z_um"].values)
        assert sa.read_record(key).summary == sb.read_record(key).summary
    for i in plan.items:
        if i.condition["speed_rpm"] == 400:
            assert "asked to fail at 400" in sb.failure(i.key)["error"]
    assert sum(_markers(marks).values()) == 24


def _dies_at_400(condition, context):
    import os

    from robobore.study.demo import demo_runner

    if condition["speed_rpm"] == 400:
        os._exit(3)
    return demo_runner(condition, context)


def test_a_dead_pool_worker_is_a_recorded_failure_not_a_crash(tmp_path):
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(200, 400),
                                           feeds=(0.1,), depths=(0.05,)))
    out = run_sweep(plan, tmp_path / "s", workers=1, pool="processes", runner=_dies_at_400)
    assert out.computed + out.failed == len(plan.items) == 2 and out.failed >= 1
    assert all("worker process of the sweep pool died" in f["error"] for f in out.failures)
    again = run_sweep(plan, tmp_path / "s", workers=0)
    assert again.computed == out.failed and again.pending == 0


def test_unknown_pool_is_a_clear_error(tmp_path):
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(200,), feeds=(0.1,)))
    with pytest.raises(ConfigError, match="unknown sweep pool"):
        run_sweep(plan, tmp_path / "s", workers=1, pool="threads")


def test_progress_is_reported_through_the_callback(tmp_path):
    """``progress(task, done, total)``: done 0 first, then once per finished condition; a
    resumed sweep reports only what is left."""
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(200, 400),
                                           feeds=(0.1,), depths=(0.05,)))
    calls: list[tuple] = []
    run_sweep(plan, tmp_path / "s", workers=0, progress=lambda *a: calls.append(a))
    assert calls == [("sweep t", 0, 2), ("sweep t", 1, 2), ("sweep t", 2, 2)]
    calls.clear()
    run_sweep(plan, tmp_path / "s", workers=0, progress=lambda *a: calls.append(a))
    assert calls == [("sweep t", 0, 0)]


def test_failures_are_recorded_and_retried_only_they(tmp_path):
    marks = tmp_path / "marks"
    cfg = write_sweep_toml(tmp_path / "c.toml", runner_options=(
        f'marker_dir = "{marks}"\nfail_speeds_rpm = [400]'))
    plan = plan_from_file(cfg)
    out = run_sweep(plan, tmp_path / "s", workers=2, processes=False)
    assert (out.computed, out.failed, out.pending) == (8, 4, 4)
    st = ResultsStore(tmp_path / "s")
    failed = [i for i in plan.items if i.condition["speed_rpm"] == 400]
    for i in failed:
        rec = st.failure(i.key)
        assert st.status(i.key) == "failed" and rec["attempts"] == 1
        assert "asked to fail at 400" in rec["error"] and "Traceback" in rec["traceback"]
    assert sum(_markers(marks).values()) == 12

    # same config (the failure injection is a runner option, not part of the key) without
    # the failure: only the 4 failed conditions run again
    cfg2 = write_sweep_toml(tmp_path / "c2.toml", runner_options=f'marker_dir = "{marks}"')
    plan2 = plan_from_file(cfg2)
    assert [i.key for i in plan2.items] == [i.key for i in plan.items]
    out2 = run_sweep(plan2, tmp_path / "s", workers=2, processes=False)
    assert (out2.skipped, out2.computed, out2.failed, out2.pending) == (8, 4, 0, 0)
    m = _markers(marks)
    assert all(m[i.key] == 2 for i in failed)
    assert all(m[i.key] == 1 for i in plan.items if i not in failed)
    assert all(st.read_record(i.key).attempt == 2 for i in failed)

    out3 = run_sweep(plan2, tmp_path / "s", workers=2, processes=False)
    assert (out3.skipped, out3.computed) == (12, 0)
    assert sum(_markers(marks).values()) == 16


def _not_a_dataset(condition, context):
    return {"not": "a dataset"}


def _bad_summary(condition, context):
    return xr.Dataset({"feed_amplitude_um": ((), -3.0)})


def _unstorable(condition, context):
    return xr.Dataset({"stable": ((), True)}, attrs={"nested": {"not": "netCDF"}})


def _warned(condition, context):
    w = ("cutting speed 37.7 m/min outside the measured 5-30 m/min"
         if condition["speed_rpm"] > 250 else "")
    return xr.Dataset({"stable": ((), True)},
                      attrs={"coefficient_warnings": "; ".join(x for x in (
                          w, "chip thicknesses 40-80 um, used up to 95 um") if x)})


def test_coefficient_warnings_of_the_conditions_are_the_sweeps(tmp_path):
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(200, 300),
                                           feeds=(0.1,)))
    out = run_sweep(plan, tmp_path / "a", workers=0, runner=_warned)
    n = len(plan.items)
    assert out.computed == n and out.to_dict()["warnings"] == list(out.warnings)
    assert out.warnings == (f"coefficients ({n} of {n} conditions): chip thicknesses 40-80 um, "
                            "used up to 95 um",
                            f"coefficients ({n // 2} of {n} conditions): cutting speed 37.7 "
                            "m/min outside the measured 5-30 m/min")


def test_bad_runner_results_become_failures(tmp_path):
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(300,), feeds=(0.1,)))
    out = run_sweep(plan, tmp_path / "a", workers=0, runner=_not_a_dataset)
    assert out.failed == 2 and "expected xarray.Dataset" in out.failures[0]["error"]
    out = run_sweep(plan, tmp_path / "b", workers=0, runner=_bad_summary)
    assert out.failed == 2 and "feed_amplitude_um" in out.failures[0]["error"]
    out = run_sweep(plan, tmp_path / "c", workers=0, runner=_unstorable)
    assert out.failed == 2 and out.failures[0]["error"].startswith("TypeError")
    assert not list((tmp_path / "c" / "results").iterdir())  # no half file either
    assert execute(_not_a_dataset, {}, {})["ok"] is False


def test_runner_resolution_errors():
    assert callable(resolve_runner("demo"))
    assert callable(resolve_runner("robobore.study.demo:demo_runner"))
    assert callable(resolve_runner("boring"))  # the real boring runner (study.runners)
    with pytest.raises(ConfigError, match="unknown runner"):
        resolve_runner("no-such-runner")
    with pytest.raises(ConfigError, match="cannot import"):
        resolve_runner("robobore.nope:run")


def test_unreachable_scheduler_is_a_clear_error(tmp_path):
    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(300,), feeds=(0.1,)))
    with pytest.raises(RoboboreError, match="cannot connect to the Dask scheduler"):
        run_sweep(plan, tmp_path / "s", scheduler="tcp://127.0.0.1:9", connect_timeout_s=2)


def _stop(proc: subprocess.Popen) -> None:
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


def test_sweep_on_a_separately_started_scheduler(tmp_path):
    """`dask scheduler` and `dask worker` started as separate processes on loopback."""
    sched_file = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
             "--port", "0", "--no-dashboard", "--scheduler-file", str(sched_file)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + 60
        while not sched_file.exists():
            assert procs[0].poll() is None, "scheduler exited"
            assert time.monotonic() < deadline, "scheduler did not start in 60 s"
            time.sleep(0.1)
        time.sleep(0.2)  # the file is written in one go, but be safe about partial reads
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
             "--nworkers", "1", "--no-dashboard", "--no-nanny", "--host", "127.0.0.1"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        marks = tmp_path / "marks"
        plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml",
                                               runner_options=f'marker_dir = "{marks}"'))
        out = run_sweep(plan, tmp_path / "s", scheduler=address, connect_timeout_s=30)
        assert (out.computed, out.failed, out.pending) == (12, 0, 0)
        assert out.mode == f"dask scheduler {address}"
        st = ResultsStore(tmp_path / "s")
        assert st.done_keys() == {i.key for i in plan.items}
        # the work ran in the worker process, not in this one
        import os

        workers = {st.load(i.key).attrs["robobore_worker"] for i in plan.items}
        assert len(workers) == 1 and not next(iter(workers)).endswith(f":{os.getpid()}")
        assert sum(_markers(marks).values()) == 12
    finally:
        for p in reversed(procs):
            _stop(p)


class _FakeFuture:
    def __init__(self, status, exc=None):
        self.status, self._exc = status, exc

    def exception(self):
        if self.status == "cancelled":
            raise RuntimeError("cancelled future")
        return self._exc

    def traceback(self):
        return None


def test_unfinished_dask_tasks_become_readable_failures():
    from robobore.study.sweep import _dask_failure

    r = _dask_failure(_FakeFuture("error", ValueError("KilledWorker-like")))
    assert r == {"ok": False, "error": "ValueError: KilledWorker-like", "traceback": ""}
    assert "ended as 'cancelled'" in _dask_failure(_FakeFuture("cancelled"))["error"]
    assert "without a result" in _dask_failure(_FakeFuture("lost"))["error"]
