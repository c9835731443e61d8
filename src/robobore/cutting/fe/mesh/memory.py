"""Memory estimates of the FE meshes, from the config, before anything is built.

:func:`check_fe2d` and :func:`check_fe3d` run when an FE config is parsed
(:func:`robobore.cutting.fe.config.orthogonal.parse_config`,
:func:`robobore.cutting.fe.config.boring3d.parse_boring_config`): a mesh whose estimate exceeds
the available memory is refused by :func:`robobore.io.memory.check_memory` with the estimate,
the memory available and the key to change.

The element counts are formulas checked against the meshes the builders make for the bundled
FE examples (2D: 0.36-1.2 times the real count, the edge-refined mesh lowest; 3D workpiece
frame: 0.89 times; 3D tool frame: the exact count of the mesh's slice layout).
"""

from __future__ import annotations

import math
from typing import Any

from robobore.cutting.fe.config.frame import Frame
from robobore.io.memory import available_memory_bytes, check_memory

__all__ = ["FE2D_BYTES_PER_ELEMENT", "FE3D_BYTES_PER_ELEMENT", "fe2d_elements",
           "toolframe2d_elements", "workpiece2d_elements", "check_fe2d", "fe3d_elements",
           "workpiece3d_elements", "toolframe3d_elements", "check_fe3d"]

#: 2D explicit FE: bytes per quadrilateral element at the peak. The arrays of a set-up run
#: (mesh, node and element state, contact) measure 770-1050 bytes per element on the bundled
#: fe_orthogonal*.toml examples; the rest is the history and the copies taken for the output.
FE2D_BYTES_PER_ELEMENT = 1500
#: 3D explicit FE (robobore.cutting.fe.models.boring3d): bytes per hexahedral element at the peak
#: (a set-up run of examples/fe_boring_paper.toml measures 910 bytes per element).
FE3D_BYTES_PER_ELEMENT = 1500


def fe2d_elements(cfg: Any) -> float:
    """Element count of a 2D FE config (:class:`robobore.cutting.fe.config.orthogonal.FEConfig`)
    on its frame: :func:`toolframe2d_elements` or :func:`workpiece2d_elements` (the choice of
    the config check, before the model is chosen)."""
    if Frame(getattr(cfg.mesh, "frame", Frame.WORKPIECE)).is_tool:
        return toolframe2d_elements(cfg)
    return workpiece2d_elements(cfg)


def toolframe2d_elements(cfg: Any) -> float:
    """Element count of a 2D tool-frame config: the domain round the edge (inflow + back +
    chip length by depth + chip height) over ``le^2``."""
    m, cut = cfg.mesh, cfg.cut
    le = float(m.element_size_um)
    h = float(cut.uncut_chip_thickness_um)
    chip = m.chip_length_um or max(1.5 * h, 80.0)
    width = ((m.inflow_length_um or max(1.5 * h, 60.0))
             + (m.back_length_um or max(2.0 * h, 120.0)) + chip)
    height = (m.depth_um or max(2.5 * h, 120.0)) + m.initial_chip_ratio * h + chip
    return width * height / le**2


def workpiece2d_elements(cfg: Any) -> float:
    """Element count of a 2D workpiece-frame config: ``(length_mm + ahead_mm) / le`` columns
    times the rows of the fine zone (``(1 + fine_depth_factor) h / le``) plus the graded rows
    below it. A lower estimate of the count (the coarse rows are few)."""
    m, cut = cfg.mesh, cfg.cut
    le = float(m.element_size_um)
    h = float(cut.uncut_chip_thickness_um)
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
    """Element count of a 3D boring FE config (:class:`BoringFEConfig`) on its frame:
    :func:`toolframe3d_elements` (``mesh.frame = "tool"``) or :func:`workpiece3d_elements`
    (the choice of the config check, before the model is chosen)."""
    if Frame(getattr(cfg.mesh, "frame", Frame.WORKPIECE)).is_tool:
        return toolframe3d_elements(cfg)
    return workpiece3d_elements(cfg)


def workpiece3d_elements(cfg: Any) -> float:
    """Element count of a workpiece-frame 3D boring config: the block the mesh builder
    fills, ``(cut_length + ahead)`` along the cut, from half a feed behind the insert to the
    end of its engaged edge plus two side margins along the feed, and
    ``ap + max(depth_factor ap, 4 le)`` deep, over ``le^3``."""
    from robobore.cutting.geometry import lead_end

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
