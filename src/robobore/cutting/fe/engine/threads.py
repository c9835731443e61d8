"""The CPU engines' thread count on a shared machine.

The CPU time loop (2D ``run_chunk_*``, 3D ``run_chunk3``) launches two parallel regions per time
step (node update, element update) and more every few steps (heat conduction, the tool frame's
remap); on the 2D meshes each region is a few tens of microseconds of work and ends in a
barrier. When another process holds one of the cores, every region waits for the thread the
operating system has descheduled, and the run collapses: on two cores beside one CPU-bound
process the 2D contract model on two fixed threads ran at 4-25 % of its quiet throughput
(depending on the host), with the governor at 56-61 %; the 3D boring model at 11-32 % and
43-53 % (docs/fe.md, "Throughput on a shared machine"; ``benchmarks/bench_fe_shared.py``).

:class:`ThreadGovernor` chooses, chunk by chunk, between all of numba's threads and one: it
times every chunk, runs on the count that currently delivers more steps per second, and
re-tries the other count on a short chunk (a quarter of the steps, at most 50 ms' worth at the
current rate): at first after two chunks, then at doubling intervals while it keeps losing (at
most every 32 chunks), and soon again when the current count's rate moves by more than a
quarter (the load changed); never before the current count has run twenty times the last
probe's time, so a probe of a collapsed count costs at most about 5 % of the run.

The results do not depend on the thread count: the engines' parallel loops write disjoint
entries and reduce only by minimum, so a run gives the same digits on one or many threads
(tests/cutting/fe/test_fe_threads.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numba

#: chunks between a probe of the other thread count right after a switch or a load change
PROBE_FIRST = 2
#: the longest interval between probes [chunks]
PROBE_MAX = 32
#: a change of the current count's steps per second by more than this fraction re-probes
RATE_CHANGE = 0.25
#: the other count must be faster by more than this fraction to take over
SWITCH_MARGIN = 0.05
#: a probe (and the first measurement of each count) runs this fraction of a chunk's steps,
#: at most ...
PROBE_FRACTION = 0.25
#: ... the steps the current count runs in this time [s]
PROBE_SECONDS = 0.05
#: between two probes the current count runs at least this many times the last probe's wall
#: time: on a crowded machine the losing count can be a hundred times slower, and the probes
#: then still cost at most about 1/20 of the run
PROBE_COST_RATIO = 20.0


@dataclass
class ThreadGovernor:
    """Picks the thread count of each chunk from the measured steps per second.

    ``max_threads``: the parallel count (default: numba's current count, i.e.
    ``NUMBA_NUM_THREADS`` or :func:`numba.set_num_threads`). With one thread there is nothing
    to choose and the governor leaves numba as it is. Use: ``threads, steps =
    next_chunk(chunk_steps)``, run ``steps`` steps on ``threads`` threads, then
    ``record(threads, steps_taken, wall_s)``.
    """

    max_threads: int = 0
    current: int = 0
    #: the last measured steps per second of each count
    rate: dict[int, float] = field(default_factory=dict)
    gap: int = PROBE_FIRST
    since_probe: int = 0
    wall_since_probe: float = 0.0
    last_probe_s: float = 0.0
    warmed: bool = False
    #: (threads, steps, wall seconds) of every chunk, for benchmarks and tests
    log: list[tuple[int, int, float]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.max_threads <= 0:
            self.max_threads = numba.get_num_threads()
        self.current = self.max_threads

    @property
    def active(self) -> bool:
        return self.max_threads > 1

    def other(self) -> int:
        return 1 if self.current == self.max_threads else self.max_threads

    def next_chunk(self, chunk_steps: int) -> tuple[int, int]:
        """(threads, steps) for the next chunk: the current count, or a short probe of the
        other one when it is due."""
        short = max(10, int(chunk_steps * PROBE_FRACTION))
        if not self.active:
            return self.current, chunk_steps
        if not self.warmed or self.current not in self.rate:
            return self.current, short
        if self.other() not in self.rate:
            return self.other(), short
        if (self.since_probe >= self.gap
                and self.wall_since_probe >= PROBE_COST_RATIO * self.last_probe_s):
            steps = min(short, int(self.rate[self.current] * PROBE_SECONDS))
            return self.other(), max(10, steps)
        return self.current, chunk_steps

    def record(self, threads: int, steps: int, wall_s: float) -> None:
        """Account a finished chunk of ``steps`` steps run on ``threads`` threads."""
        self.log.append((threads, steps, wall_s))
        if not self.active or steps <= 0 or wall_s <= 0.0:
            return
        if not self.warmed:  # the first chunk may include compiling or loading the cache
            self.warmed = True
            return
        r = steps / wall_s
        if threads == self.current:
            old = self.rate.get(threads)
            self.rate[threads] = r
            self.since_probe += 1
            self.wall_since_probe += wall_s
            if old is not None and abs(r / old - 1.0) > RATE_CHANGE:
                self.gap = PROBE_FIRST  # the load changed: probe soon
                self.since_probe = self.gap
            return
        self.rate[threads] = r
        self.since_probe = 0
        self.wall_since_probe = 0.0
        self.last_probe_s = wall_s
        if r > self.rate[self.current] * (1.0 + SWITCH_MARGIN):
            self.current = threads
            self.gap = PROBE_FIRST
        else:
            self.gap = min(2 * self.gap, PROBE_MAX)
