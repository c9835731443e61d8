"""Memory estimates checked before large arrays are allocated.

Commands whose memory grows with their input (FE meshes 2D/3D, time-domain samples,
virtual hammer tests) call :func:`check_memory` with a cheap estimate computed from
the config before they allocate anything. When the estimate exceeds the memory available
now (``MemAvailable`` of ``/proc/meminfo``; elsewhere the physical memory from
``os.sysconf``) the command is refused with a :class:`~robobore.errors.ConfigError` naming
the estimate, the available memory and the key to change, instead of allocating until the
machine runs out of memory.

The estimates are formulas, not measurements of a run: they count the arrays the command
holds at its peak, with a stated number of bytes per element/sample (module constants
below). The element counts are checked against the meshes the builders make for the bundled
FE examples (2D: 0.36-1.2 times the real count, the edge-refined mesh lowest; 3D: 0.89
times). They refuse requests that cannot fit, not runs that are merely large. Sweep grids
have a count limit instead (:data:`robobore.study.conditions.MAX_SWEEP_CONDITIONS`); lobe
maps are bounded by their config (at most 100 000 speeds, memory linear in the count).

``ROBOBORE_MEMORY_LIMIT_BYTES`` (environment), when set, replaces the available memory (a
cap for shared machines and for tests).
"""

from __future__ import annotations

import math
import os
from typing import Any

from robobore.errors import ConfigError

#: 2D explicit FE (robobore.cutting.fe): bytes per quadrilateral element at the peak. The
#: arrays of a set-up run (mesh, node and element state, contact) measure 770-1050 bytes per
#: element on the bundled fe_orthogonal*.toml examples; the rest is the history and the
#: copies taken for the output.
FE2D_BYTES_PER_ELEMENT = 1500
#: 3D explicit FE (robobore.cutting.fe.models.boring3d): bytes per hexahedral element at the peak
#: (a set-up run of examples/fe_boring_paper.toml measures 910 bytes per element).
FE3D_BYTES_PER_ELEMENT = 1500
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


def fe2d_elements(cfg: Any) -> float:
    """Element count of a 2D FE config (:class:`robobore.cutting.fe.config.orthogonal.FEConfig`).

    Workpiece frame: ``(length_mm + ahead_mm) / le`` columns times the rows of the fine zone
    (``(1 + fine_depth_factor) h / le``) plus the graded rows below it. Tool frame: the
    domain round the edge (inflow + back + chip length by depth + chip height) over
    ``le^2``. A lower estimate of the count (the coarse rows are few).
    """
    m, cut = cfg.mesh, cfg.cut
    le = float(m.element_size_um)
    h = float(cut.uncut_chip_thickness_um)
    if getattr(m, "frame", "workpiece") == "tool":
        chip = m.chip_length_um or max(1.5 * h, 80.0)
        width = ((m.inflow_length_um or max(1.5 * h, 60.0))
                 + (m.back_length_um or max(2.0 * h, 120.0)) + chip)
        height = (m.depth_um or max(2.5 * h, 120.0)) + m.initial_chip_ratio * h + chip
        return width * height / le**2
    length_um = (float(cut.length_mm) + float(m.ahead_mm)) * 1e3
    rows = (1.0 + float(m.fine_depth_factor)) * h / le
    g = float(m.grading)
    coarse_depth = max(float(m.height_factor) - float(m.fine_depth_factor), 0.0) * h
    if g > 1.0:  # rows of geometrically growing size filling the coarse depth
        rows += math.log1p(coarse_depth / le * (g - 1.0)) / math.log(g)
    else:
        rows += coarse_depth / le
    return length_um / le * rows


def check_fe2d(cfg: Any, source: str | None = None) -> None:
    """Refuse a 2D FE config whose mesh cannot fit in memory (see :func:`fe2d_elements`)."""
    n = fe2d_elements(cfg)
    check_memory(n * FE2D_BYTES_PER_ELEMENT,
                 f"the 2D FE mesh (about {n:.3g} elements)",
                 "mesh.element_size_um (or cut.length_mm)", file=source,
                 value=cfg.mesh.element_size_um)


def fe3d_elements(cfg: Any) -> float:
    """Element count of a 3D boring FE config (:class:`BoringFEConfig`). Workpiece frame: the
    block the mesh builder fills, ``(cut_length + ahead)`` along the cut, from half a feed
    behind the insert to the end of its engaged edge plus two side margins along the feed,
    and ``ap + max(depth_factor ap, 4 le)`` deep, over ``le^3``. Tool frame
    (``mesh.frame = "tool"``): :func:`toolframe3d_elements`."""
    from robobore.cutting.geometry import lead_end

    if getattr(cfg.mesh, "frame", "workpiece") == "tool":
        return toolframe3d_elements(cfg)
    le = float(cfg.mesh.element_size_um) * 1e-6
    ap = float(cfg.cut.depth_of_cut_mm) * 1e-3
    f = float(cfg.cut.feed_mm_per_rev) * 1e-3
    L = (float(cfg.cut.cut_length_mm) + float(cfg.mesh.ahead_mm)) * 1e-3
    side = float(cfg.mesh.side_margin_um) * 1e-6 or 3.0 * le
    width = 0.5 * f + float(lead_end(cfg.insert.to_insert(), ap)) + 2.0 * side
    depth = ap + max(float(cfg.mesh.depth_factor) * ap, 4.0 * le)
    return L * width * depth / le**3


def toolframe3d_elements(cfg: Any) -> float:
    """Hexahedra of a tool-frame 3D boring config's mesh: the count of
    :func:`robobore.cutting.fe.mesh.toolframe3d.toolframe3d_counts` (exact, from the slices'
    layout and the reference section, without the 3D mesh). A lower bound is taken first and
    returned when it alone does not fit in memory (no section is then built): every slice's
    section spans at least 180 x 120 um (inflow face 60 um ahead of the chip root and back
    face 120 um behind the edge, 120 um deep) in elements no larger than ``le``, and the
    slices are at most the slice spacing apart over the engaged edge. Where the geometry
    leaves the model's range the lower bound is returned (the setup says why)."""
    from robobore.cutting.fe.mesh.toolframe3d_layout import ToolFrame3DSizes, toolframe3d_counts
    from robobore.cutting.geometry import lead_end, trailing_intersection

    ins = cfg.insert.to_insert()
    ap = float(cfg.cut.depth_of_cut_mm) * 1e-3
    f = float(cfg.cut.feed_mm_per_rev) * 1e-3
    sizes = ToolFrame3DSizes.of_config(cfg.mesh)
    span = max(float(lead_end(ins, ap)) - float(trailing_intersection(ins, ap, f)), sizes.dz)
    lower = 180e-6 * 120e-6 / sizes.element_size**2 * span / sizes.dz
    if lower * FE3D_BYTES_PER_ELEMENT > available_memory_bytes():
        return lower
    try:
        return float(toolframe3d_counts(ins, ap, f, sizes)[1])
    except ValueError:
        return lower


def check_fe3d(cfg: Any, source: str | None = None) -> None:
    """Refuse a 3D boring FE config whose mesh cannot fit in memory."""
    n = fe3d_elements(cfg)
    check_memory(n * FE3D_BYTES_PER_ELEMENT,
                 f"the 3D FE mesh (about {n:.3g} elements)",
                 "mesh.element_size_um (or cut.cut_length_mm)", file=source,
                 value=cfg.mesh.element_size_um)


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
    "fe2d_elements",
    "fe3d_elements",
    "toolframe3d_elements",
    "check_fe2d",
    "check_fe3d",
    "timedomain_bytes",
    "check_timedomain",
    "hammer_test_bytes",
]
