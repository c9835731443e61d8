"""Where the slices of the 3D tool-frame mesh lie and what each one's section is, before any
3D node is placed (:mod:`robobore.cutting.fe.mesh.toolframe3d` builds the mesh from it): the
size control :class:`ToolFrame3DSizes`, the slice positions over the engaged edge with their
margins, the sections' thicknesses, the common topology and the reference section
(:func:`slice_layout`), and the mesh's node and hexahedron counts from them
(:func:`toolframe3d_counts`, the memory check's estimate)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.cutting.fe.ale.toolframe import (
    ToolFrameExtent,
    ToolFrameMesh,
    build_toolframe_mesh,
    key_points,
)
from robobore.cutting.fe.mesh.toolframe3d_section import (
    SectionPlan,
    s_of_y,
    section_nodes,
    section_plan,
    uncut_thickness,
)
from robobore.cutting.geometry import BoringInsert, lead_end, trailing_intersection

__all__ = ["ToolFrame3DSizes", "SliceLayout", "slice_layout", "toolframe3d_counts"]


@dataclass(frozen=True)
class ToolFrame3DSizes:
    """Element size control (SI): ``element_size`` the largest in-plane element,
    ``edge_size`` the element round the edge (default element_size / 4, the 2D model's),
    ``slice_spacing`` the largest z step between slices (default element_size), ``t_min``
    the clamp of the uncut thickness at the ends of the engagement (default 5 um),
    ``margin_slices`` block-A-only slices beyond each end, ``chip_ratio`` the pre-shaped
    chip's thickness / uncut thickness, ``ratio`` the element growth ratio."""

    element_size: float
    edge_size: float | None = None
    slice_spacing: float | None = None
    t_min: float = 5e-6
    margin_slices: int = 3
    chip_ratio: float = 1.6
    ratio: float = 1.15

    @property
    def edge(self) -> float:
        return self.element_size / 4.0 if self.edge_size is None else self.edge_size

    @property
    def dz(self) -> float:
        return self.element_size if self.slice_spacing is None else self.slice_spacing

    @classmethod
    def of_config(cls, mesh: Any) -> ToolFrame3DSizes:
        """The sizes of a boring config's ``[mesh]`` section (keys in um)."""
        um = 1e-6
        return cls(element_size=mesh.element_size_um * um,
                   edge_size=None if mesh.edge_element_um is None else mesh.edge_element_um * um,
                   slice_spacing=(None if mesh.slice_spacing_um is None
                                  else mesh.slice_spacing_um * um),
                   t_min=mesh.t_min_um * um, margin_slices=mesh.margin_slices,
                   chip_ratio=mesh.initial_chip_ratio)


def _slice_positions(z0: float, z1: float, dz: float, margin: int) -> tuple[np.ndarray, np.ndarray]:
    """Slices on [z0, z1] with z = 0 among them (z0 < 0 < z1), steps <= dz, plus ``margin``
    slices of step dz beyond each end. Returns (z, engaged)."""
    n_lo = max(1, int(math.ceil(-z0 / dz)))
    n_hi = max(1, int(math.ceil(z1 / dz)))
    zs = np.concatenate([np.linspace(z0, 0.0, n_lo + 1), np.linspace(0.0, z1, n_hi + 1)[1:]])
    lo = z0 - dz * np.arange(margin, 0, -1)
    hi = z1 + dz * np.arange(1, margin + 1)
    z = np.concatenate([lo, zs, hi])
    eng = np.concatenate([np.zeros(margin, bool), np.ones(zs.size, bool), np.zeros(margin, bool)])
    return z, eng


@dataclass(frozen=True)
class SliceLayout:
    """Where the slices of :func:`build_toolframe3d_mesh` lie and what each section is, before
    any 3D node is placed: ``z`` (k,) slice positions [m], ``eng`` (k,) engaged slices,
    ``t_true`` (k,) the true vertical uncut thickness, ``t_c`` (k,) the clamped one, ``y_top``
    (k,) the free surface's height, ``h2`` (k,) the normal-section thickness of each engaged
    slice (nan at the margins), ``h_ref`` the reference slice's (z = 0), ``depth`` the bottom's
    depth below the reference's cut line and ``y_bot`` its y [m], ``plan`` the slices' common
    topology, ``ref`` the reference slice's 2D mesh and ``blk`` its block sizes."""

    z: np.ndarray
    eng: np.ndarray
    t_true: np.ndarray
    t_c: np.ndarray
    y_top: np.ndarray
    h2: np.ndarray
    h_ref: float
    depth: float
    y_bot: float
    plan: SectionPlan
    ref: ToolFrameMesh
    blk: dict


def slice_layout(insert: BoringInsert, ap: float, f: float,
                 sizes: ToolFrame3DSizes) -> SliceLayout:
    """The slices and sections of :func:`build_toolframe3d_mesh` (its arguments; the same
    ValueErrors), without the 3D mesh: what the mesh and its size estimate
    (:func:`toolframe3d_counts`) are built from."""
    if insert.edge_radius_m <= 0.0:
        raise ValueError("the tool-frame mesh needs an edge radius > 0")
    if not (0.0 < sizes.t_min < ap):
        raise ValueError(f"t_min = {sizes.t_min} m must lie in (0, ap = {ap} m)")
    r = insert.edge_radius_m
    rake = math.radians(insert.rake_deg)
    clr = math.radians(insert.clearance_deg)
    z_t = trailing_intersection(insert, ap, f)
    z_l = lead_end(insert, ap)
    if not (z_t < 0.0 < z_l):
        raise ValueError("the engaged edge must contain the nose tip (z = 0)")
    dz = sizes.dz
    z, eng = _slice_positions(z_t, z_l, dz, sizes.margin_slices)
    nk = z.size
    t_true = uncut_thickness(insert, ap, f, z)
    t_c = np.where(eng, np.maximum(t_true, sizes.t_min), t_true)
    y_top = insert.drop(z) + t_c  # the mesh's free surface ahead of the edge
    y_top[~eng] = np.minimum(ap, insert.drop(z[~eng] + f))
    # normal-section thickness of each engaged slice: the free surface's distance from the
    # apex line, taken from the edge profile's (s = r)
    h2 = np.full(nk, np.nan)
    h2[eng] = r - s_of_y(insert, y_top[eng], z[eng])
    k0 = int(np.flatnonzero(eng & (z == 0.0))[0])
    h_ref = float(h2[k0])
    h_max = float(np.nanmax(h2))
    fine, coarse = sizes.edge, sizes.element_size
    # extents shared by the slices: the 2D builder's defaults for the thickest slice
    chip_length = max(1.5 * sizes.chip_ratio * h_max, 80e-6)
    x_in = min(key_points(float(hk), r, rake, sizes.chip_ratio)[10][0]
               - max(1.5 * float(hk), 60e-6) for hk in h2[eng])
    x_out = max(2.0 * h_max, 120e-6)
    depth = max(2.5 * h_max, 120e-6)
    y_bot = -depth  # flat bottom, the reference slice's depth below its cut line y = 0
    plan = section_plan(h_ref, r, rake, clr, element_size=coarse, edge_size=fine,
                        chip_ratio=sizes.chip_ratio, ratio=sizes.ratio, x_in=x_in, x_out=x_out,
                        depth=depth, chip_length=chip_length)
    ref = build_toolframe_mesh(h_ref, r, rake, clr, element_size=coarse, edge_size=fine,
                               chip_ratio=sizes.chip_ratio,
                               extent=ToolFrameExtent(
                                   ahead=key_points(h_ref, r, rake, sizes.chip_ratio)[10][0]
                                   - x_in, behind=x_out, depth=depth, chip_length=chip_length),
                               ratio=sizes.ratio)
    ref_nodes, blk = section_nodes(plan, h_ref, depth)
    if ref_nodes.shape != ref.nodes.shape or not np.allclose(ref_nodes, ref.nodes, rtol=0.0,
                                                            atol=1e-9 * fine):
        raise AssertionError("section_nodes does not reproduce build_toolframe_mesh at the "
                             "reference thickness")
    return SliceLayout(z=z, eng=eng, t_true=t_true, t_c=t_c, y_top=y_top, h2=h2, h_ref=h_ref,
                       depth=depth, y_bot=y_bot, plan=plan, ref=ref, blk=blk)


def toolframe3d_counts(insert: BoringInsert, ap: float, f: float,
                       sizes: ToolFrame3DSizes) -> tuple[int, int]:
    """``(nodes, hexahedra)`` of :func:`build_toolframe3d_mesh` (its arguments), counted from
    :func:`slice_layout` without building the 3D mesh: an engaged slice has the reference
    section's nodes, a margin slice block A's; between two engaged slices lie all the
    section's quadrilaterals as hexahedra, elsewhere block A's."""
    lay = slice_layout(insert, ap, f, sizes)
    na, ja = lay.blk["na"], lay.blk["ja"]
    nodes = np.where(lay.eng, lay.ref.nodes.shape[0], (na + 1) * (ja + 1))
    both = lay.eng[:-1] & lay.eng[1:]
    hexes = np.where(both, lay.ref.conn.shape[0], na * ja)
    return int(nodes.sum()), int(hexes.sum())
