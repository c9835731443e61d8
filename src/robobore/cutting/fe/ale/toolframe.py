"""Tool-frame ALE mesh for orthogonal cutting: the mesh travels with the tool, the material
flows through it (``mesh.frame = "tool"``).

Why. A Lagrangian mesh split at a fixed parting line deletes, by distortion erosion at the
stagnation point, exactly the thin layer that the edge radius ploughs under itself (see
docs/fe.md, "Tool-frame ALE model"): the edge and flank forces -- most of the feed force --
are lost.
With a mesh fixed relative to the tool no element is carried through the stagnation point:
material enters ahead of the tool, divides round the edge wherever the flow divides (no
separation criterion, no erosion) and leaves through the machined surface behind the flank
and through the top of the chip. This is the arbitrary Lagrangian-Eulerian (ALE)
formulation of steady orthogonal cutting used by Abaqus/Explicit ALE models and by
Movahhedy, Gadala and Altintas (2000), "Simulation of the orthogonal metal cutting process
using an arbitrary Lagrangian-Eulerian finite-element method", J. Mater. Process. Technol.
103, 267-275, and Arrazola and Oezel (2010), "Investigations on the effects of friction
modeling in finite element simulation of machining", Int. J. Mech. Sci. 52, 31-42 (Eulerian
inflow/outflow boundaries, Lagrangian free surfaces, a pre-shaped chip).

The time step is the engine's Lagrangian step (workpiece frame: the tool moves at -vc, the
workpiece far below is fixed). Every ``solver.ale_interval`` steps
:func:`robobore.cutting.fe.ale.rezone.rezone` moves every node back to its
place in the tool's frame and remaps the element state (donor cell) and the nodal velocities:

* inflow face and bottom (``TF_RIGID``): fixed in the workpiece (v = 0), carried with the
  tool in x; virgin material (no stress, no plastic strain, room temperature) enters through
  the inflow face;
* free surfaces and the surface against the tool (``TF_CHAIN``): Lagrangian along their
  normal (the surface keeps its shape: the chip thickness, the springback of the machined
  surface, the contact length come out of the solution), Eulerian along it (each node slides
  along the surface polyline to the point nearest its place in the tool frame);
* chain ends on the outflow lines (``TF_LINE``): where the surface crosses the chip's top
  face or the back face;
* outflow faces (``TF_FACE``): spread between their two ends; material leaves through them;
* interior (``TF_INTERIOR``): at their place in the tool frame plus a mesh displacement that
  is the discrete Laplace interpolation (Jacobi sweeps, carried from pass to pass) of the
  boundary nodes' displacements, so the mesh follows the free surfaces smoothly.

Mesh (built by :func:`build_toolframe_mesh`): two structured blocks joined along the line
y = join height ahead of the tool. Block A, the workpiece that passes under the tool: from
the inflow face to the back face, from the bottom to the join line ahead of the tool, the
edge arc under the join point and the machined surface behind the tool. Block B, the chip:
from the inflow face above the join line, bent round the edge and up the rake face to the
chip's top face; its outer side is the workpiece's free surface ahead of the tool and the
chip's back surface, initially at ``initial_chip_ratio * h`` from the rake face, joined by
the shear plane. Elements are ``edge`` sized round the edge and grow away from it.

Coordinates: the workpiece frame of the Lagrangian engine -- free surface y = 0, cut line
y = -h, the tool moving in -x (material ahead of it at smaller x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robobore.cutting.fe.ale.remap import BF_OPEN, BF_VIRGIN
from robobore.cutting.fe.ale.rezone import TF_CHAIN, TF_FACE, TF_INTERIOR, TF_LINE, TF_RIGID
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.mesh.orthogonal import MeshSizes
from robobore.cutting.fe.models.output import ChipGeometry, point_polyline_distance, shear_angle_deg


@dataclass
class ToolFrameMesh(MeshSizes):
    """Quad mesh (``nodes`` (n, 2) [m], ``conn`` (e, 4) counter-clockwise) of the tool-frame
    model with its ALE data: ``acls`` (n, 7) int = class, two surface/face neighbours, four
    edge neighbours (-1 pad); ``aflt`` (n, 6) = face fraction (outflow-face nodes) or the
    longest slide along the line (chain ends), line direction (2), reference local size,
    mesh displacement (2); ``bflag`` (e, 4) flux type of each element edge;
    ``fixed`` (n,) nodes held in x and y (inflow face, bottom); ``chip`` (e,) block B.
    ``tool_center`` (cx, cy) [m] at the start; for the outputs the node lists of the chip's
    free surface (``chip_top_nodes``, inflow -> chip top), its underside along the tool
    (``chip_under_nodes``, join point -> chip top), the chip's top face (``outflow_nodes``,
    rake side first) and the machined surface (``machined_nodes``, join point -> back face).
    """

    nodes: np.ndarray
    conn: np.ndarray
    fixed: np.ndarray
    chip: np.ndarray
    acls: np.ndarray
    aflt: np.ndarray
    bflag: np.ndarray
    tool_center: tuple[float, float]
    chip_top_nodes: np.ndarray
    chip_under_nodes: np.ndarray
    outflow_nodes: np.ndarray
    machined_nodes: np.ndarray
    h: float
    edge_size: float
    element_size: float


def _graded_steps(length: float, first: float, largest: float, ratio: float) -> np.ndarray:
    """Positions 0..length with steps starting at ``first``, growing by ``ratio`` up to
    ``largest``, scaled so that the last lands on ``length``."""
    if length <= 0.0:
        raise ValueError("non-positive length")
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
    return pos * (length / pos[-1])


def key_points(h: float, r: float, rake: float, chip_ratio: float, hj: float | None = None):
    """The key points of the tool-frame section (edge-centre frame, SI units): returns
    ``(hj, tc, cx, cy, nr, tr, T, th_s, S, th_t, R)``: the join height ``hj`` (default
    min(r, h) / 2), the chip thickness ``tc``, the edge centre (cx, cy), the rake normal
    ``nr`` (towards the chip) and tangent ``tr`` (up the rake face), the rake tangent point
    ``T``, the join point ``S`` on the front of the arc at height ``hj`` above the lowest
    point and its angle ``th_s``, the arc's end angle ``th_t`` at the rake face, and the chip
    root ``R`` where the chip's back line (offset ``tc`` from the rake face) meets y = 0."""
    hj = min(0.5 * r, 0.5 * h) if hj is None else hj
    tc = chip_ratio * h
    cx, cy = 0.0, -h + r
    nr = np.array([-math.cos(rake), math.sin(rake)])
    tr = np.array([math.sin(rake), math.cos(rake)])
    T = np.array([cx, cy]) + r * nr
    th_s = math.acos(1.0 - hj / r)
    S = np.array([cx - r * math.sin(th_s), -h + hj])
    th_t = 0.5 * math.pi + rake
    s_R = (-T[1] - tc * nr[1]) / tr[1]
    R = T + s_R * tr + tc * nr
    return hj, tc, cx, cy, nr, tr, T, th_s, S, th_t, R


def free_surface_join(x_in: float, R: np.ndarray, Ot: np.ndarray, S: np.ndarray,
                      th_s: float) -> tuple[np.ndarray, np.ndarray, float | None]:
    """The chip block's free surface, the polyline inflow top -> chip root ``R`` -> chip top
    ``Ot``, its cumulative arc lengths, and the arc length of the point P where the mesh line
    from the join point ``S`` (bisecting the corner between the join line and the edge arc
    at angle ``th_s``) meets it; ``None`` for P where the line misses the polyline."""
    poly = np.array([[x_in, 0.0], R, Ot])
    seg = np.hypot(*np.diff(poly, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    bis = np.array([-math.cos(th_s), math.sin(th_s)]) + np.array([-1.0, 0.0])
    bis /= np.linalg.norm(bis)
    for k in range(2):
        a, d = poly[k], poly[k + 1] - poly[k]
        m = np.array([[bis[0], -d[0]], [bis[1], -d[1]]])
        if abs(np.linalg.det(m)) < 1e-18:
            continue
        t, u = np.linalg.solve(m, a - S)
        if t > 0.0 and 0.0 <= u <= 1.0:
            return poly, cum, cum[k] + u * seg[k]
    return poly, cum, None


@dataclass(frozen=True)
class ToolFrameExtent:
    """The tool-frame mesh's extents [m] (None: the default, a function of the uncut chip
    thickness ``h`` and the initial chip thickness ``tc``): ``ahead`` the distance of the
    inflow face ahead of the chip's root (default max(1.5 h, 60 um)), ``behind`` of the back
    face behind the edge centre (max(2 h, 120 um)), ``depth`` of the bottom below the cut line
    (max(2.5 h, 120 um)), ``chip_length`` of the chip's top face from the rake face's start
    (max(1.5 tc, 80 um): a few contact lengths; a longer free chip curls and leaves its top
    face at a grazing angle)."""

    ahead: float | None = None
    behind: float | None = None
    depth: float | None = None
    chip_length: float | None = None

    def resolved(self, h: float, tc: float) -> tuple[float, float, float, float]:
        """``(ahead, behind, depth, chip_length)`` [m], the defaults filled in."""
        return (max(1.5 * h, 60e-6) if self.ahead is None else self.ahead,
                max(2.0 * h, 120e-6) if self.behind is None else self.behind,
                max(2.5 * h, 120e-6) if self.depth is None else self.depth,
                max(1.5 * tc, 80e-6) if self.chip_length is None else self.chip_length)


def build_toolframe_mesh(h: float, r: float, rake: float, clearance: float, *,
                         element_size: float, edge_size: float, chip_ratio: float = 1.6,
                         join_height: float | None = None,
                         extent: ToolFrameExtent = ToolFrameExtent(),
                         ratio: float = 1.15) -> ToolFrameMesh:
    """Build the two-block tool-frame mesh (SI units; angles in rad).

    ``h`` uncut chip thickness, ``r`` edge radius (> 0), ``element_size`` the largest element,
    ``edge_size`` the element round the edge; ``chip_ratio`` the initial chip thickness / h;
    ``join_height`` the height of the blocks' join point on the edge arc above the tool's
    lowest point (default min(r, h) / 2: a mesh choice, not a separation criterion -- the material
    divides wherever its flow does); ``extent`` the inflow, back, bottom and chip-top faces'
    places (:class:`ToolFrameExtent`); ``ratio`` the grading ratio of neighbouring elements.
    """
    if r <= 0.0:
        raise ValueError("the tool-frame mesh needs an edge radius > 0")
    if not (0.0 < edge_size <= element_size):
        raise ValueError("need 0 < edge_size <= element_size")
    hj = min(0.5 * r, 0.5 * h) if join_height is None else join_height
    if not (0.0 < hj <= r and hj <= 0.75 * h):
        raise ValueError("join height must lie on the lower front quarter of the edge arc "
                         "and at most 3/4 h above the cut line")
    tc = chip_ratio * h
    ahead, behind, depth, chip_length = extent.resolved(h, tc)
    _, _, cx, cy, nr, tr, T, th_s, S, th_t, R = key_points(h, r, rake, chip_ratio, hj)
    if R[0] >= S[0] - h:
        raise ValueError("chip ratio too small for this rake angle and edge radius")
    Ob = T + chip_length * tr
    Ot = Ob + tc * nr
    x_in = R[0] - ahead
    x_out = cx + behind
    y_bot = -h - depth
    fine, coarse = edge_size, element_size
    # ---- stations along the join line / free surface ahead of the tool (inflow -> S)
    d1 = _graded_steps(S[0] - x_in, fine, coarse, ratio)[::-1]
    xs1 = S[0] - d1  # x_in ... S
    n1 = xs1.size - 1
    # ---- block A top: S -> arc -> lowest point -> machined surface -> back face
    n_arc_a = max(2, int(math.ceil(r * th_s / fine)))
    tha = np.linspace(th_s, 0.0, n_arc_a + 1)
    arc_a = np.column_stack([cx - r * np.sin(tha), cy - r * np.cos(tha)])
    xb = cx + _graded_steps(x_out - cx, fine, coarse, ratio)
    top_a = np.vstack([np.column_stack([xs1, np.full(n1 + 1, S[1])])[:-1], arc_a,
                       np.column_stack([xb[1:], np.full(xb.size - 1, -h)])])
    na = top_a.shape[0] - 1  # intervals along block A
    i_s = n1  # column of S
    # rows of block A: fine at the top, graded to the bottom (fractions of the column)
    col_depth = S[1] - y_bot
    eta_a = 1.0 - _graded_steps(col_depth, fine, coarse, ratio)[::-1] / col_depth
    ja = eta_a.size - 1
    # ---- block B bottom: join line (shared) then S -> arc -> rake -> Ob
    n_arc_b = max(3, int(math.ceil(r * (th_t - th_s) / fine)))
    thb = np.linspace(th_s, th_t, n_arc_b + 1)
    arc_b = np.column_stack([cx - r * np.sin(thb), cy - r * np.cos(thb)])
    sr = _graded_steps(chip_length, fine, coarse, ratio)
    rake_pts = T[None, :] + sr[1:, None] * tr[None, :]
    seg2_bot = np.vstack([arc_b, rake_pts])  # S ... Ob
    n2 = seg2_bot.shape[0] - 1
    # block B top: the free surface, a polyline inflow top -> R -> Ot. The mesh line from
    # S bisects the corner between the join line and the arc and meets it at P; the top's
    # stations run inflow top -> P with the fractions of the bottom's segment 1 and P -> Ot
    # with those of its segment 2 (each blended half and half with uniform spacing)
    poly, cum, s_p = free_surface_join(x_in, R, Ot, S, th_s)
    if s_p is None:
        raise ValueError("cannot place the chip block's mesh line from the join point")

    def along(sv: np.ndarray) -> np.ndarray:
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
    # rows of block B: uniform-ish, first row at ~edge size on the tool side
    n_jb = max(6, int(math.ceil(tc / (0.5 * (fine + coarse)))) + 2)
    eta_b = _graded_steps(1.0, fine / tc, 1.0 / (n_jb - 3), ratio)
    jb = eta_b.size - 1
    # ---- assemble nodes: block A (i = 0..na, j = 0..ja), then block B rows j >= 1
    nodes = []
    # block A's mesh lines run from the top to bottom stations spaced like the top's arc
    # length (so the lines fan out under the edge arc instead of bunching up in x)
    s_top = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(top_a, axis=0).T))])
    x_bot = x_in + (x_out - x_in) * s_top / s_top[-1]
    idx_a = np.empty((na + 1, ja + 1), np.int64)
    for i in range(na + 1):
        xt, yt = top_a[i]
        for j in range(ja + 1):
            e = eta_a[j]
            idx_a[i, j] = len(nodes)
            nodes.append((x_bot[i] + e * (xt - x_bot[i]), y_bot + e * (yt - y_bot)))
    idx_b = np.empty((nb + 1, jb + 1), np.int64)
    for i in range(nb + 1):
        for j in range(jb + 1):
            if j == 0 and i <= n1:
                idx_b[i, j] = idx_a[i, ja]
                continue
            if j == 0:
                p = bot_b[i]
            else:
                p = bot_b[i] + eta_b[j] * (top_b[i] - bot_b[i])
            idx_b[i, j] = len(nodes)
            nodes.append((p[0], p[1]))
    nodes = np.array(nodes, np.float64)
    n_nodes = nodes.shape[0]
    conn = []
    chip = []
    bflag = []
    for i in range(na):
        for j in range(ja):
            conn.append((idx_a[i, j], idx_a[i + 1, j], idx_a[i + 1, j + 1], idx_a[i, j + 1]))
            chip.append(False)
            bflag.append((0, BF_OPEN if i == na - 1 else 0, 0, BF_VIRGIN if i == 0 else 0))
    for i in range(nb):
        for j in range(jb):
            conn.append((idx_b[i, j], idx_b[i + 1, j], idx_b[i + 1, j + 1], idx_b[i, j + 1]))
            chip.append(True)
            bflag.append((0, BF_OPEN if i == nb - 1 else 0, 0, BF_VIRGIN if i == 0 else 0))
    conn = np.array(conn, np.int64)
    bflag = np.array(bflag, np.int64)
    chip = np.array(chip, bool)
    # ---- ALE classes
    acls = np.full((n_nodes, 7), -1, np.int64)
    acls[:, 0] = TF_INTERIOR
    aflt = np.zeros((n_nodes, 6))
    fixed = np.zeros(n_nodes, bool)
    rigid = np.concatenate([idx_a[0, :], idx_a[:, 0], idx_b[0, :]])
    fixed[rigid] = True
    acls[rigid, 0] = TF_RIGID
    # chain 1: block B top row (free surface), inflow corner excluded, ends on the outflow
    for i in range(1, nb + 1):
        n = idx_b[i, jb]
        acls[n, 0] = TF_CHAIN if i < nb else TF_LINE
        acls[n, 1] = idx_b[i - 1, jb]
        acls[n, 2] = idx_b[i + 1, jb] if i < nb else -1
    # chain 2: Ob -> rake -> arc -> S -> arc -> machined surface -> back corner
    chain2 = [idx_b[i, 0] for i in range(nb, n1, -1)] + [idx_a[i, ja] for i in range(i_s, na + 1)]
    for k, n in enumerate(chain2):
        end = k == 0 or k == len(chain2) - 1
        acls[n, 0] = TF_LINE if end else TF_CHAIN
        if k == 0:
            acls[n, 1] = chain2[1]
        elif k == len(chain2) - 1:
            acls[n, 1] = chain2[-2]
        else:
            acls[n, 1] = chain2[k - 1]
            acls[n, 2] = chain2[k + 1]
    out_dir = (Ot - Ob) / np.linalg.norm(Ot - Ob)
    for n in (idx_b[nb, 0], idx_b[nb, jb]):
        aflt[n, 1:3] = out_dir
        aflt[n, 0] = 0.5 * tc  # a chip end slides at most half a chip thickness off its place
    aflt[idx_a[na, ja], 1:3] = (0.0, 1.0)
    aflt[idx_a[na, ja], 0] = 0.5 * h
    # outflow faces
    for j in range(1, jb):
        n = idx_b[nb, j]
        acls[n, 0] = TF_FACE
        acls[n, 1], acls[n, 2] = idx_b[nb, 0], idx_b[nb, jb]
        aflt[n, 0] = eta_b[j]
    for j in range(1, ja):
        n = idx_a[na, j]
        acls[n, 0] = TF_FACE
        acls[n, 1], acls[n, 2] = idx_a[na, 0], idx_a[na, ja]
        aflt[n, 0] = eta_a[j]
    # edge neighbours (for the Laplace interpolation) and reference local size
    nbrs: list[set[int]] = [set() for _ in range(n_nodes)]
    for el in conn:
        for k in range(4):
            a, b = int(el[k]), int(el[(k + 1) % 4])
            nbrs[a].add(b)
            nbrs[b].add(a)
    for n in range(n_nodes):
        lst = sorted(nbrs[n])
        if acls[n, 0] == TF_INTERIOR and len(lst) != 4:
            raise AssertionError("interior node without 4 neighbours")
        for k, m in enumerate(lst[:4]):
            acls[n, 3 + k] = m
        aflt[n, 3] = min(float(np.hypot(*(nodes[m] - nodes[n]))) for m in lst)
    return ToolFrameMesh(
        nodes=nodes, conn=conn, fixed=fixed, chip=chip, acls=acls, aflt=aflt, bflag=bflag,
        tool_center=(cx, cy),
        chip_top_nodes=idx_b[:, jb].copy(), chip_under_nodes=idx_b[n1:, 0].copy(),
        outflow_nodes=idx_b[nb, :].copy(), machined_nodes=idx_a[i_s:, ja].copy(), h=h,
        edge_size=edge_size, element_size=element_size)


def measure_chip_toolframe(st, mesh: ToolFrameMesh, h: float, rake: float,
                           vc: float) -> tuple[ChipGeometry, float, int]:
    """Chip thickness and ratio of the tool-frame model at the end of the run.

    Thickness: the median distance of the chip's free-surface nodes to the chip underside
    (the surface chain along the rake), over the straight part of the chip -- 40 to 90 % of
    the way from the edge to the chip's top face. Velocity ratio: ``vc`` over the mean speed
    of the material at the chip's top face relative to the tool (weighted by the face length
    each node represents); by continuity this is the chip ratio for a chip that leaves as a
    straight band in steady flow (a curling chip's speed varies across it). Returns
    (ChipGeometry, velocity ratio, number of face nodes).
    """
    x, y = st.x, st.y
    cx = st.tool[layout.T_GX] + st.tool[layout.T_UX]
    cy = st.tool[layout.T_GY] + st.tool[layout.T_UY]
    trx, try_ = math.sin(rake), math.cos(rake)
    top = mesh.chip_top_nodes
    under = mesh.chip_under_nodes
    s_top = (x[top] - cx) * trx + (y[top] - cy) * try_
    ob = mesh.outflow_nodes[0]
    s_end = (x[ob] - cx) * trx + (y[ob] - cy) * try_
    sel = top[(s_top > 0.4 * s_end) & (s_top < 0.9 * s_end)]
    if sel.size >= 2:
        d = point_polyline_distance(x[sel], y[sel], x[under], y[under])
        tc = float(np.median(d))
        geo = ChipGeometry(tc, h, tc / h, shear_angle_deg(tc / h, rake), int(sel.size))
    else:
        geo = ChipGeometry(math.nan, h, math.nan, math.nan, int(sel.size))
    face = mesh.outflow_nodes
    fx, fy = x[face], y[face]
    tvx = -vc + st.tool[layout.T_VUX]
    tvy = st.tool[layout.T_VUY]
    speed = np.hypot(st.vx[face] - tvx, st.vy[face] - tvy)
    seg = np.hypot(np.diff(fx), np.diff(fy))
    w = np.zeros(face.size)
    w[:-1] += 0.5 * seg
    w[1:] += 0.5 * seg
    if w.sum() <= 0.0:
        return geo, math.nan, int(face.size)
    vm = float(np.sum(speed * w) / np.sum(w))
    return geo, (vc / vm if vm > 0.0 else math.nan), int(face.size)


__all__ = ["ToolFrameMesh", "ToolFrameExtent", "build_toolframe_mesh", "measure_chip_toolframe"]
