"""Memory estimates checked before large arrays are allocated.

Commands whose memory grows with their input (FE meshes, time-domain samples, virtual hammer
tests) call :func:`check_memory` with a cheap estimate computed from the config before they
allocate anything. When the estimate exceeds the memory available now (``MemAvailable`` of
``/proc/meminfo``; elsewhere the physical memory from ``os.sysconf``) the command is refused
with a :class:`~robobore.errors.ConfigError` naming the estimate, the available memory and the
key to change, instead of allocating until the machine runs out of memory.

The estimates are formulas, not measurements of a run: they count the arrays the command
holds at its peak, with a stated number of bytes per element/sample (module constants). This
module holds the generic check and the estimates of the stages below the FE engine (time
domain, hammer tests); each stage that owns a large model keeps its own estimate next to it
and calls :func:`check_memory` (the FE meshes: :mod:`robobore.cutting.fe.mesh.memory`). They
refuse requests that cannot fit, not runs that are merely large. Sweep grids have a count
limit instead (:data:`robobore.study.conditions.MAX_SWEEP_CONDITIONS`); lobe maps are bounded
by their config (at most 100 000 speeds, memory linear in the count).

``ROBOBORE_MEMORY_LIMIT_BYTES`` (environment), when set, replaces the available memory (a
cap for shared machines and for tests).
"""

from __future__ import annotations

import math
import os
from typing import Any

from robobore.errors import ConfigError

#: time-domain boring (robobore.dynamics.timedomain): float64 values held per time step:
#: force, displacement and acceleration (3 each) and the chip area per insert, times three
#: for the Dataset built from them and the derived series (time, angle, surface).
TIMEDOMAIN_VALUES_PER_STEP = 9


def available_memory_bytes() -> int:
    """Memory available to a new allocation now, in bytes (see module doc)."""
    cap = os.environ.get("ROBOBORE_MEMORY_LIMIT_BYTES")
    if cap:
        try:
            return int(float(cap))
        except ValueError:
            raise ConfigError("not a number of bytes", field="ROBOBORE_MEMORY_LIMIT_BYTES",
                              value=cap, expected="an integer number of bytes") from None
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - exotic platforms
        return 1 << 62


def fmt_bytes(n: float) -> str:
    """``1.5 GiB`` style."""
    if not math.isfinite(n):
        return "infinitely many bytes"
    for unit, size in (("TiB", 1 << 40), ("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def check_memory(estimate_bytes: float, what: str, key: str, *, file: str | None = None,
                 value: Any = None, fraction: float = 0.9) -> None:
    """Refuse (ConfigError) when ``estimate_bytes`` exceeds ``fraction`` of the available
    memory. ``what`` says what would be allocated, ``key`` which config key or option sets
    its size (``value`` its value), ``file`` the config file."""
    avail = available_memory_bytes()
    if math.isfinite(estimate_bytes) and estimate_bytes <= fraction * avail:
        return
    raise ConfigError(
        f"{what} would need about {fmt_bytes(estimate_bytes)} of memory, more than the "
        f"{fmt_bytes(avail)} available; reduce {key}",
        file=file, field=key, value=value,
        expected=f"a size that fits in {fmt_bytes(fraction * avail)}")


# --- estimates --------------------------------------------------------------------------


def timedomain_bytes(n_steps: int, n_inserts: int) -> float:
    """Peak bytes of a time-domain simulation of ``n_steps`` steps."""
    return 3.0 * 8.0 * n_steps * (TIMEDOMAIN_VALUES_PER_STEP + n_inserts) + 16.0 * n_steps


def check_timedomain(revolutions: int, samples_per_rev: int, n_inserts: int,
                     source: str | None = None) -> None:
    """Refuse a time-domain run of ``revolutions x samples_per_rev`` steps that cannot fit."""
    n = int(revolutions) * int(samples_per_rev)
    check_memory(timedomain_bytes(n, n_inserts),
                 f"the time-domain simulation ({revolutions} revolutions x {samples_per_rev} "
                 f"samples per revolution = {n:.3g} steps)",
                 "simulation.revolutions or simulation.samples_per_rev "
                 "(--revolutions, --samples-per-rev)", file=source, value=n)


def hammer_test_bytes(n_inputs: int, n_hits: int, n_outputs: int, n_samples: int) -> float:
    """Peak bytes of a virtual hammer test: force and responses of every hit (float64),
    zero-padded to twice the length, with complex spectra for the synthesis."""
    return float(n_inputs) * n_hits * (1 + n_outputs) * n_samples * 8.0 * 2.0 * 3.0


__all__ = [
    "available_memory_bytes",
    "check_memory",
    "fmt_bytes",
    "timedomain_bytes",
    "check_timedomain",
    "hammer_test_bytes",
]
