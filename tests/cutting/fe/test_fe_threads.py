"""The CPU engines' thread governor: its choices on timed chunks, and results that do not
depend on the thread count."""

from __future__ import annotations

from pathlib import Path

import numba
import numpy as np
import pytest

from robobore.cutting.fe.engine import threads as T
from robobore.cutting.fe.engine.threads import ThreadGovernor

ROOT = Path(__file__).resolve().parents[3]


def _drive(gov: ThreadGovernor, rates: dict[int, float], n_chunks: int,
           chunk_steps: int = 1000) -> list[tuple[int, int]]:
    """Run ``n_chunks`` chunks whose steps per second are ``rates[threads]`` (a callable of
    the chunk index, or a number); returns (threads, steps) per chunk."""
    out = []
    for i in range(n_chunks):
        t, n = gov.next_chunk(chunk_steps)
        r = rates[t](i) if callable(rates[t]) else rates[t]
        gov.record(t, n, n / r)
        out.append((t, n))
    return out


def test_quiet_machine_stays_on_all_threads_and_backs_off_its_probes():
    gov = ThreadGovernor(max_threads=2)
    rates = {2: 5000.0, 1: 3500.0}
    chunks = _drive(gov, rates, 200)
    assert gov.current == 2
    wall = sum(n / rates[t] for t, n in chunks)
    best = sum(n for _, n in chunks) / rates[2]
    assert wall / best - 1.0 < 0.01  # the probes cost less than 1 % of the throughput
    assert gov.gap == T.PROBE_MAX


def test_shared_machine_moves_to_one_thread_and_its_probes_stay_cheap():
    """Two threads collapsed (a hundred times slower than one): the governor runs on one and
    the probes of two threads cost a bounded share of the time."""
    gov = ThreadGovernor(max_threads=2)
    chunks = _drive(gov, {2: 40.0, 1: 4000.0}, 2000)
    assert gov.current == 1
    assert [t for t, _ in chunks[3:]].count(2) < 30
    time_on_2 = sum(n / 40.0 for t, n in chunks[1:] if t == 2)
    time_on_1 = sum(n / 4000.0 for t, n in chunks[1:] if t == 1)
    assert time_on_2 / (time_on_1 + time_on_2) < 0.07  # PROBE_COST_RATIO: about 1/20
    # a probe never runs more than 50 ms of the current count's steps
    assert all(n <= 4000.0 * T.PROBE_SECONDS + 1 for t, n in chunks[5:] if t == 2)


def test_a_change_of_load_is_followed_both_ways():
    """Quiet, then another process arrives (two threads collapse), then it leaves."""
    def two(i):
        return 5000.0 if i < 60 or i >= 160 else 200.0

    gov = ThreadGovernor(max_threads=2)
    chunks = _drive(gov, {2: two, 1: 3500.0}, 240)
    assert chunks[55][0] == 2
    assert [t for t, _ in chunks[70:150]].count(1) > 70  # on one thread while shared
    assert [t for t, _ in chunks[200:240]].count(2) > 35  # back on two once quiet


def test_one_thread_has_nothing_to_choose():
    gov = ThreadGovernor(max_threads=1)
    assert not gov.active
    assert _drive(gov, {1: 1000.0}, 10) == [(1, 1000)] * 10


class Alternating(ThreadGovernor):
    """Every chunk on the other thread count: the hardest case for reproducibility."""

    def next_chunk(self, chunk_steps: int) -> tuple[int, int]:
        return (self.max_threads if len(self.log) % 2 else 1), chunk_steps


needs_threads = pytest.mark.skipif(numba.get_num_threads() < 2,
                                   reason="numba has one thread (NUMBA_NUM_THREADS=1)")


@needs_threads
def test_2d_default_model_gives_the_same_digits_on_any_thread_count():
    from robobore.cutting.fe.config.orthogonal import load_fe_config
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal

    cfg = load_fe_config(ROOT / "examples" / "fe_orthogonal.toml")
    cfg.cut.length_mm = 0.005
    runs = []
    for adaptive, gov in ((False, None), (True, Alternating())):
        s = setup_orthogonal(cfg)
        advance(s.state, s.t_end, chunk_steps=300, adaptive_threads=adaptive, governor=gov)
        runs.append(s.state)
    a, b = runs
    assert np.array_equal(a.hist, b.hist, equal_nan=True)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.temp, b.temp)
    assert numba.get_num_threads() == numba.config.NUMBA_NUM_THREADS  # restored


@needs_threads
def test_3d_boring_model_gives_the_same_digits_on_any_thread_count():
    from robobore.cutting.fe.config.boring3d import parse_boring_config
    from robobore.cutting.fe.engine.state3d import advance3
    from robobore.cutting.fe.models.boring3d import setup_boring

    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0,
                 "cut_length_mm": 0.02},
         "mesh": {"element_size_um": 16.6, "frame": "workpiece", "ahead_mm": 0.03},
         "solver": {"mass_scaling": 400.0, "n_samples": 10}}
    runs = []
    for adaptive, gov in ((False, None), (True, Alternating())):
        s = setup_boring(parse_boring_config(d))
        advance3(s.state, s.t_end, chunk_steps=100, adaptive_threads=adaptive, governor=gov)
        runs.append(s.state)
    a, b = runs
    assert np.array_equal(a.hist, b.hist, equal_nan=True)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.temp, b.temp)
