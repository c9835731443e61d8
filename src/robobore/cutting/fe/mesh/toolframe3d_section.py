"""The normal-section geometry of the z-sliced tool-frame mesh
(:mod:`robobore.cutting.fe.mesh.toolframe3d`, whose docstring describes the model): the
common topology of the slices (:class:`SectionPlan`, :func:`section_plan`), one slice's 2D
nodes at its own thickness (:func:`section_nodes`), the exact map between a slice's
normal-section frame and its z-plane (:func:`slice_map`, :func:`section_coords`,
:func:`s_of_y`), and the uncut thickness along the feed and the clamp's fictitious chip area
(:func:`uncut_thickness`, :func:`clamp_area`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from robobore.cutting.fe.ale.toolframe import free_surface_join, key_points
from robobore.cutting.fe.hex.scalar3d import edge_section
from robobore.cutting.geometry import BoringInsert, lead_end, trailing_intersection

__all__ = ["SectionPlan", "section_plan", "section_nodes", "slice_map",
           "section_coords", "s_of_y", "uncut_thickness", "clamp_area"]


def _graded_fractions(length: float, first: float, largest: float, ratio: float) -> np.ndarray:
    """The step positions of the 2D builder (steps from ``first`` growing by ``ratio`` up to
    ``largest``, the last short one merged) as fractions 0..1 of ``length``."""
    steps = []
    s = first
    tot = 0.0
    while tot < length - 1e-12 * length:
        steps.append(s)
        tot += s
        s = min(s * ratio, largest)
    if len(steps) > 1 and steps[-1] < 0.5 * steps[-2]:
        steps[-2] += steps[-1]
        steps.pop()
    pos = np.concatenate([[0.0], np.cumsum(steps)])
    return pos / pos[-1]


@dataclass(frozen=True)
class SectionPlan:
    """The common topology of the slices: the 2D construction's counts and step fractions at
    the reference thickness, and the extents shared by all slices (2D normal-section frame
    of :func:`build_toolframe_mesh`: edge centre at x = 0, material entering from x < 0).
    ``x_in``, ``x_out`` [m] inflow and back faces; ``chip_length`` [m]; ``q1`` fractions of
    the stations ahead of the join point, ``n_arc_a``/``n_arc_b`` arc intervals of blocks A
    and B, ``q_xb`` fractions behind the edge centre, ``eta_a``/``eta_b`` row fractions,
    ``q_sr`` fractions along the rake face; ``h_ref`` [m] the reference thickness. A slice
    thinner than the reference spaces its chip rows ``eta_b`` between the reference's
    grading and uniform rows in proportion ``h / h_ref`` (the chip's first row would
    otherwise shrink with ``h`` at the same fraction)."""

    h_ref: float
    r: float
    rake: float
    clearance: float
    element_size: float
    edge_size: float
    chip_ratio: float
    ratio: float
    x_in: float
    x_out: float
    chip_length: float
    q1: np.ndarray
    n_arc_a: int
    q_xb: np.ndarray
    eta_a: np.ndarray
    n_arc_b: int
    q_sr: np.ndarray
    eta_b: np.ndarray


def section_plan(h_ref: float, r: float, rake: float, clearance: float, *, element_size: float,
                 edge_size: float, chip_ratio: float, ratio: float, x_in: float, x_out: float,
                 depth: float, chip_length: float) -> SectionPlan:
    """The counts and fractions of :func:`build_toolframe_mesh` at ``h_ref`` with the inflow
    face at ``x_in``, the back face at ``x_out`` (edge-centre frame), the bottom ``depth``
    below the cut line and the chip's top face ``chip_length`` up the rake face."""
    hj, tc, cx, cy, nr, tr, T, th_s, S, th_t, R = key_points(h_ref, r, rake, chip_ratio)
    fine, coarse = edge_size, element_size
    q1 = _graded_fractions(S[0] - x_in, fine, coarse, ratio)[::-1]
    n_arc_a = max(2, int(math.ceil(r * th_s / fine)))
    q_xb = _graded_fractions(x_out - cx, fine, coarse, ratio)
    y_bot = -h_ref - depth
    col_depth = S[1] - y_bot
    eta_a = 1.0 - _graded_fractions(col_depth, fine, coarse, ratio)[::-1]
    n_arc_b = max(3, int(math.ceil(r * (th_t - th_s) / fine)))
    q_sr = _graded_fractions(chip_length, fine, coarse, ratio)
    n_jb = max(6, int(math.ceil(tc / (0.5 * (fine + coarse)))) + 2)
    eta_b = _graded_fractions(1.0, fine / tc, 1.0 / (n_jb - 3), ratio)
    return SectionPlan(h_ref=h_ref, r=r, rake=rake, clearance=clearance, element_size=element_size,
                       edge_size=edge_size, chip_ratio=chip_ratio, ratio=ratio, x_in=x_in,
                       x_out=x_out, chip_length=chip_length, q1=q1, n_arc_a=n_arc_a, q_xb=q_xb,
                       eta_a=eta_a, n_arc_b=n_arc_b, q_sr=q_sr, eta_b=eta_b)


def section_nodes(plan: SectionPlan, h: float, depth: float) -> tuple[np.ndarray, dict]:
    """Node positions (n, 2) [m] of the 2D tool-frame section for uncut thickness ``h`` and
    the bottom ``depth`` below the cut line, in the node order of
    :func:`build_toolframe_mesh`, with the plan's counts and fractions (2D frame: free
    surface y = 0, cut line y = -h, edge centre at x = 0). Returns the nodes and the block
    sizes ``{"na", "ja", "nb", "jb", "n1", "i_s"}``."""
    r, rake = plan.r, plan.rake
    hj, tc, cx, cy, nr, tr, T, th_s, S, th_t, R = key_points(h, r, rake, plan.chip_ratio)
    if not (0.0 < hj <= r and hj <= 0.75 * h):
        raise ValueError(f"join height {hj} m off the edge arc for h = {h} m")
    if R[0] >= S[0] - h:
        raise ValueError(f"chip ratio too small for h = {h} m")
    if plan.x_in >= R[0]:
        raise ValueError(f"inflow face x = {plan.x_in} m not ahead of the chip root "
                         f"{R[0]} m for h = {h} m")
    Ob = T + plan.chip_length * tr
    Ot = Ob + tc * nr
    x_in, x_out = plan.x_in, plan.x_out
    y_bot = -h - depth
    xs1 = S[0] - plan.q1 * (S[0] - x_in)
    n1 = xs1.size - 1
    tha = np.linspace(th_s, 0.0, plan.n_arc_a + 1)
    arc_a = np.column_stack([cx - r * np.sin(tha), cy - r * np.cos(tha)])
    xb = cx + plan.q_xb * (x_out - cx)
    top_a = np.vstack([np.column_stack([xs1, np.full(n1 + 1, S[1])])[:-1], arc_a,
                       np.column_stack([xb[1:], np.full(xb.size - 1, -h)])])
    na = top_a.shape[0] - 1
    eta_a = plan.eta_a
    ja = eta_a.size - 1
    thb = np.linspace(th_s, th_t, plan.n_arc_b + 1)
    arc_b = np.column_stack([cx - r * np.sin(thb), cy - r * np.cos(thb)])
    sr = plan.q_sr * plan.chip_length
    rake_pts = T[None, :] + sr[1:, None] * tr[None, :]
    seg2_bot = np.vstack([arc_b, rake_pts])
    n2 = seg2_bot.shape[0] - 1
    poly, cum, s_p = free_surface_join(x_in, R, Ot, S, th_s)
    if s_p is None:
        raise ValueError(f"cannot place the chip block's mesh line from the join point for "
                         f"h = {h} m")

    def along(sv):
        return np.column_stack([np.interp(sv, cum, poly[:, 0]), np.interp(sv, cum, poly[:, 1])])

    f1 = (xs1 - xs1[0]) / (xs1[-1] - xs1[0])
    f1 = 0.5 * f1 + 0.5 * np.linspace(0.0, 1.0, n1 + 1)
    top1 = along(f1 * s_p)
    seg_len = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(seg2_bot, axis=0).T))])
    f2 = 0.5 * seg_len / seg_len[-1] + 0.5 * np.linspace(0.0, 1.0, n2 + 1)
    top2 = along(s_p + f2 * (cum[-1] - s_p))
    bot_b = np.vstack([np.column_stack([xs1, np.full(n1 + 1, S[1])]), seg2_bot[1:]])
    top_b = np.vstack([top1, top2[1:]])
    nb = bot_b.shape[0] - 1
    jb = plan.eta_b.size - 1
    w = min(1.0, h / plan.h_ref)
    eta_b = w * plan.eta_b + (1.0 - w) * np.linspace(0.0, 1.0, jb + 1)
    s_top = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(top_a, axis=0).T))])
    x_bot = x_in + (x_out - x_in) * s_top / s_top[-1]
    E = eta_a[None, :]
    ax = x_bot[:, None] + E * (top_a[:, 0:1] - x_bot[:, None])
    ay = y_bot + E * (top_a[:, 1:2] - y_bot)
    nodes_a = np.stack([ax.ravel(), ay.ravel()], axis=1)  # i-major, as the 2D builder
    Eb = eta_b[None, 1:, None]
    pb = bot_b[:, None, :] + Eb * (top_b - bot_b)[:, None, :]  # rows j >= 1
    rows = [pb[i] if i <= n1 else np.vstack([bot_b[i][None, :], pb[i]]) for i in range(nb + 1)]
    nodes = np.vstack([nodes_a] + rows)
    return nodes, {"na": na, "ja": ja, "nb": nb, "jb": jb, "n1": n1, "i_s": n1}


@njit(cache=True)
def _y_of_s(s_t, z, rn, kappa, kend, re, y_lo, y_hi, out):
    """y in the plane z with ``edge_section(y, z)[0] = s_t`` (decreasing in y), by
    bisection on [y_lo, y_hi]; NaN where the plane holds no such point."""
    for k in range(s_t.shape[0]):
        lo = y_lo
        hi = y_hi
        s_lo = edge_section(lo, z[k], rn, kappa, kend, re)[0]
        s_hi = edge_section(hi, z[k], rn, kappa, kend, re)[0]
        if not (s_lo >= s_t[k] >= s_hi):
            out[k] = np.nan
            continue
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if edge_section(mid, z[k], rn, kappa, kend, re)[0] > s_t[k]:
                lo = mid
            else:
                hi = mid
            if hi - lo <= 1e-16 * (abs(lo) + abs(hi)) + 1e-22:
                break
        out[k] = 0.5 * (lo + hi)


def _insert_args(insert: BoringInsert) -> tuple[float, float, float, float]:
    return (insert.nose_radius_m, math.radians(insert.approach_angle_deg),
            math.radians(insert.end_edge_angle_deg), insert.edge_radius_m)


def s_of_y(insert: BoringInsert, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Distance [m] of points (y, z) from the edge's apex line (positive out of the tool)."""
    rn, kap, kend, re = _insert_args(insert)
    y = np.broadcast_to(np.asarray(y, float), np.broadcast(y, z).shape).ravel()
    z = np.broadcast_to(np.asarray(z, float), np.broadcast(y, z).shape).ravel()
    return np.array([edge_section(float(a), float(b), rn, kap, kend, re)[0]
                     for a, b in zip(y, z, strict=True)])


def slice_map(insert: BoringInsert, z: float, xy2: np.ndarray, h2: float) -> np.ndarray:
    """Points (n, 2) of a 2D section (frame of :func:`build_toolframe_mesh` for uncut
    thickness ``h2``, edge centre at x = 0, y = r - h2) to the plane ``z`` of the 3D frame
    (n, 3): ``u = -x2`` along the cutting velocity, ``s = -(y2 - (r - h2))`` from the apex
    line; ``x = u + tan(inclination) arc``, ``y`` with ``edge_section(y, z) = s``."""
    rn, kap, kend, re = _insert_args(insert)
    r = re
    u = -xy2[:, 0]
    s = -(xy2[:, 1] - (r - h2))
    zz = np.full(s.size, float(z))
    y = np.empty(s.size)
    _y_of_s(np.ascontiguousarray(s), zz, rn, kap, kend, re, -10.0 * rn, rn * (1.0 - 1e-9), y)
    if np.any(~np.isfinite(y)):
        raise ValueError(f"slice z = {z} m: a section point has no image in the plane (the "
                         "chip reaches past the nose)")
    tani = math.tan(math.radians(insert.inclination_deg))
    x = u.copy()
    if tani != 0.0:
        arc = np.array([edge_section(float(a), float(z), rn, kap, kend, re)[1] for a in y])
        x = u + tani * arc
    return np.column_stack([x, y, zz])


@njit(cache=True)
def _section_coords(x, y, z, h2, rn, kappa, kend, re, tani, out):
    for k in range(x.shape[0]):
        s, arc, _my, _mz = edge_section(y[k], z[k], rn, kappa, kend, re)
        out[k, 0] = -(x[k] - tani * arc)
        out[k, 1] = (re - h2[k]) - s


def section_coords(insert: BoringInsert, xyz: np.ndarray, h2: np.ndarray) -> np.ndarray:
    """The inverse of :func:`slice_map`: points (n, 3) of the 3D frame to the 2D
    normal-section frame (n, 2) of a slice built for normal thickness ``h2`` (scalar or per
    point) -- the frame in which the 2D tool-frame placement (``ale.rezone.tf_*``) works."""
    rn, kap, kend, re = _insert_args(insert)
    xyz = np.ascontiguousarray(xyz, np.float64)
    h = np.ascontiguousarray(np.broadcast_to(np.asarray(h2, float), (xyz.shape[0],)))
    out = np.empty((xyz.shape[0], 2))
    _section_coords(xyz[:, 0].copy(), xyz[:, 1].copy(), xyz[:, 2].copy(), h, rn, kap, kend,
                    re, math.tan(math.radians(insert.inclination_deg)), out)
    return out


def uncut_thickness(insert: BoringInsert, ap: float, f: float, z: np.ndarray) -> np.ndarray:
    """Vertical uncut thickness ``t(z) = min(ap, drop(z + f)) - drop(z)`` [m] (negative
    where the insert clears the surface)."""
    z = np.asarray(z, float)
    return np.minimum(ap, insert.drop(z + f)) - insert.drop(z)


def clamp_area(insert: BoringInsert, ap: float, f: float, t_min: float,
               n_grid: int = 200001) -> float:
    """Fictitious chip area [m^2] the clamp adds: ``int max(0, t_min - t(z)) dz`` over the
    engaged edge (trapezoid rule on ``n_grid`` points)."""
    z0 = trailing_intersection(insert, ap, f)
    z1 = lead_end(insert, ap)
    z = np.linspace(z0, z1, n_grid)
    return float(np.trapezoid(np.maximum(t_min - uncut_thickness(insert, ap, f, z), 0.0), z))
