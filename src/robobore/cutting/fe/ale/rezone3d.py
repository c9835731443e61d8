"""The tool-frame ALE pass of the 3D engine: node placement in the z-planes + the exact
swept-volume donor-cell remap (:func:`rezone3d`), the 3D counterpart of
:func:`robobore.cutting.fe.ale.rezone.rezone` for the z-sliced tool-frame mesh of
:mod:`robobore.cutting.fe.mesh.toolframe3d`.

**Placement** (:func:`toolframe3d_targets`). Every node keeps its slice: its new z is its
plane's, ``z0 + off_z`` (``z0`` its z at the start, ``off_z`` the insert's z travel since then),
so the mesh is Eulerian along z and the material's out-of-plane flow -- the chip's side flow --
crosses the z-faces in the remap. In its plane each node is placed by the 2D tool-frame passes
of :mod:`robobore.cutting.fe.ale.rezone`, applied to the nodes' (x, y) with the node's place
``(x0 + off_x, y0)`` (``x0, y0`` its place at the start, ``off_x`` the insert's x travel since
then): rigid nodes (inflow face, bottom) to their place, surface-chain nodes sliding along their
surface polyline (its in-plane projection) towards it, chain ends along their outflow line,
outflow-face nodes spread between their ends (keeping their offset off the chord of a face the
slice's plane bends, :func:`tf_face3_py`), interior nodes to their place plus a mesh
displacement interpolated from the boundary's (``TF_SWEEPS`` Jacobi sweeps over the node's four
in-plane edge neighbours); moves limited to ``max_move`` of the local size. The class of a node
and its in-plane neighbours (global indices) are ``acls`` (n, 7) of
:attr:`robobore.cutting.fe.mesh.toolframe3d.ToolFrameMesh3D.acls`; ``aflt`` (n, 6) the 2D
meaning, per slice in the slice's plane (:func:`toolframe3d_ale_data`). The per-node passes are
the 2D scalar functions themselves, run on the 3D x, y arrays: ``tf_place_py`` made again
(:func:`robobore.cutting.fe.ale.rezone.make_tf_place` given :func:`keep_py`) to leave out its 2D
"off tool" step, which :func:`off_insert_py` replaces with the 3D insert's: a surface node whose
placed point lies deeper in the insert than its old point (or in it at all when the old point
was outside) is pushed back along the in-plane part ``(nx, ny)`` of the insert's outward normal
by ``(g_t - g_1) / (nx^2 + ny^2)`` -- the first-order in-plane move that restores the gap ``g_t
= min(g_old, 0)`` -- with ``nx^2 + ny^2`` held at least :data:`OFF_NMIN2` (an insert normal
nearly along z, which a slice of the nose never sees, moves a node at most twice the gap
deficit). The insert's signed distance is :func:`robobore.cutting.fe.hex.scalar3d.insert_gap3`
with the engine's parameter vector ``prm`` (slots ``P_RN, P_KAPPA, P_KEND, P_RAKE, P_CLR, P_RE,
P_TANI``; none when ``prm[P_TOOL] <= 0.5``) relative to the insert tip's current position ``(cx,
cy, cz)``.

**Remap.** Then :func:`robobore.cutting.fe.ale.remap3d.remap3d` transports the element
state, the reference volumes, the nodal velocities and the lumped masses from the old
positions to the placed ones (which it copies into ``x, y, z``).

Frames and places: ``x0, y0, z0`` are the nodes' places at the start in the frame of the
tip position ``(cx, cy, cz)``: the mesh's nodes (built with the insert tip at the origin)
plus the tip's start position ``(cx_s, cy_s, cz_s)``; ``off_x = cx - cx_s`` and
``off_z = cz - cz_s`` the insert's travel since then, so a node's place now is
``(x0 + off_x, y0, z0 + off_z)``. ``cy`` enters the "off tool" gap only: a support
deflection of the insert in y moves the insert, not the places.

The passes are scalar functions of one node (``*_py`` originals, ``njit`` versions without
the suffix), each reading only what the previous pass wrote and allocating nothing, run from
``prange`` loops on the CPU; a GPU kernel can compile the same source (with device
versions of ``make_tf_place``'s ``limit`` and of ``off_insert_py``'s ``insert_gap3``).
"""

from __future__ import annotations

import inspect
import math

import numpy as np
from numba import njit, prange

from robobore.cutting.fe.ale import rezone as RZ
from robobore.cutting.fe.ale.groups3d import ToolFrameAle3
from robobore.cutting.fe.ale.remap3d import (
    VEL_MOMENTUM,
    remap3d,
    remap3d_groups,
    remap3d_inputs,
    remap3d_outputs,
    remap3d_py,
)
from robobore.cutting.fe.ale.rezone import (
    TF_CHAIN,
    TF_FACE,
    TF_INTERIOR,
    TF_LINE,
    TF_RIGID,
    TF_SWEEPS,
    tf_interior,
    tf_sweep,
    tf_sweep_copy,
)
from robobore.cutting.fe.hex.layout3d import (
    P_CLR,
    P_KAPPA,
    P_KEND,
    P_RAKE,
    P_RE,
    P_RN,
    P_TANI,
    P_TOOL,
)
from robobore.cutting.fe.hex.scalar3d import insert_gap3

__all__ = ["OFF_NMIN2", "keep_py", "off_insert_py", "off_insert", "tf_place_plane_py",
           "tf_place_plane", "place3_py", "place3", "tf_face3_py", "tf_face3",
           "toolframe3d_targets", "rezone3d", "toolframe3d_ale_data",
           "toolframe3d_targets_py", "rezone3d_py", "REMAP3D_OPTIONS"]

#: the least squared in-plane part of the insert normal the "off tool" push divides by
OFF_NMIN2 = 0.25


def keep_py(px, py, qx, qy, tg):
    """The 2D "off tool" step left out: ``(qx, qy)`` as it is."""
    return qx, qy


_keep = njit(cache=True, inline="always")(keep_py)

#: :func:`robobore.cutting.fe.ale.rezone.tf_place_py` without its 2D "off tool" step (the
#: same source, :func:`robobore.cutting.fe.ale.rezone.make_tf_place` given :func:`keep_py` for
#: ``off_tool``): rigid nodes, surface chains and chain ends on the outflow lines, in the plane
#: of the node
tf_place_plane_py = RZ.make_tf_place(RZ.limit, _keep)
tf_place_plane = njit(inline="always")(tf_place_plane_py)


def off_insert_py(px, py, pz, qx, qy, qz, prm, cx, cy, cz):
    """``(qx, qy)`` (in the plane ``z = qz``) pushed back out of the insert if it lies deeper
    in it than the old point ``(px, py, pz)`` (or in it at all when the old point was
    outside): along the in-plane part of the insert normal by the first-order move that
    restores the gap (see the module docstring). Insert tip at ``(cx, cy, cz)``."""
    g0, _n0x, _n0y, _n0z = insert_gap3(px - cx, py - cy, pz - cz, prm[P_RN], prm[P_KAPPA],
                                       prm[P_KEND], prm[P_RAKE], prm[P_CLR], prm[P_RE],
                                       prm[P_TANI])
    g1, nx, ny, _nz = insert_gap3(qx - cx, qy - cy, qz - cz, prm[P_RN], prm[P_KAPPA],
                                  prm[P_KEND], prm[P_RAKE], prm[P_CLR], prm[P_RE], prm[P_TANI])
    gt = min(g0, 0.0)
    if g1 < gt:
        nn2 = nx * nx + ny * ny
        if nn2 < OFF_NMIN2:
            nn2 = OFF_NMIN2
        d = (gt - g1) / nn2
        return qx + d * nx, qy + d * ny
    return qx, qy


off_insert = njit(cache=True, inline="always")(off_insert_py)


def place3_py(n, pos, xn, yn, zn, start, travel, prm, tip, tool):
    """First pass, node ``n``: z into its plane; a rigid node, a surface-chain node or a
    chain end on an outflow line placed in the plane (:func:`tf_place_plane_py`), the
    surface nodes then kept out of the insert (:func:`off_insert_py`, when ``tool``); other
    classes keep their old x, y for now. Reads the old positions only.

    Read-only groups (tuples): ``pos`` = ``(x, y, z)`` the old positions (n,) [m]; ``start``
    = ``(x0, y0, z0, acls, aflt)`` the places at the start and the tool-frame data of
    :func:`toolframe3d_ale_data`; ``travel`` = ``(off_x, off_z, max_move)`` and ``tip`` =
    ``(cx, cy, cz)`` as in :func:`rezone3d`; ``prm`` the parameter vector. Writes ``xn, yn,
    zn`` (n,) [m] at ``n``."""
    x, y, z = pos
    x0, y0, z0, acls, aflt = start
    off_x, off_z, max_move = travel
    cx, cy, cz = tip
    xn[n] = x[n]
    yn[n] = y[n]
    zn[n] = z0[n] + off_z
    tf_place_plane(n, x, y, xn, yn, x0, y0, acls, aflt, off_x, max_move, prm)
    c = acls[n, 0]
    if tool and (c == TF_CHAIN or c == TF_LINE):
        tx, ty = off_insert(x[n], y[n], z[n], xn[n], yn[n], zn[n], prm, cx, cy, cz)
        xn[n] = tx
        yn[n] = ty


place3 = njit(cache=True, inline="always")(place3_py)


def tf_face3_py(n, xn, yn, x0, y0, acls, aflt, off):
    """Second pass, node ``n`` (after :func:`place3_py` of every node): the 2D
    :func:`robobore.cutting.fe.ale.rezone.tf_face_py` with the face node's offset off the
    chord of its face: an outflow-face node at its fraction ``aflt[n, 0]`` along the chord
    between its two (placed) ends plus ``aflt[n, 1]`` chord lengths along the chord's left
    normal (zero on a straight face, as every face of a 2D mesh is; a slice's plane bends
    the chip's top face slightly); then, for every node but an interior one, its mesh
    displacement (the boundary values of the interpolation)."""
    c = acls[n, 0]
    if c == TF_FACE:
        a = acls[n, 1]
        b = acls[n, 2]
        f = aflt[n, 0]
        g = aflt[n, 1]
        dx = xn[b] - xn[a]
        dy = yn[b] - yn[a]
        xn[n] = xn[a] + f * dx - g * dy
        yn[n] = yn[a] + f * dy + g * dx
    if c != TF_INTERIOR:
        aflt[n, 4] = xn[n] - x0[n] - off
        aflt[n, 5] = yn[n] - y0[n]


tf_face3 = njit(cache=True, inline="always")(tf_face3_py)


@njit(parallel=True, cache=True)
def toolframe3d_targets(x, y, z, xn, yn, zn, ale, prm, travel, tip):
    """New node positions ``xn, yn, zn`` of the z-sliced tool-frame mesh (module docstring)
    from the current ``x, y, z``; ``ale`` the
    :class:`~robobore.cutting.fe.ale.groups3d.ToolFrameAle3` (``aflt[:, 4:6]``, the in-plane
    mesh displacement, updated; ``scratch`` (n, >= 2) work), ``prm`` the engine's parameter
    vector, ``travel`` and ``tip`` as in :func:`rezone3d`. Allocates nothing."""
    # the prange bodies read flat locals, one bound per statement (ale.groups3d)
    x0 = ale.x0
    y0 = ale.y0
    z0 = ale.z0
    acls = ale.acls
    aflt = ale.aflt
    scratch = ale.scratch
    off_x = travel[0]
    max_move = travel[2]
    nn = x.shape[0]
    tool = prm[P_TOOL] > 0.5
    # 1. z into the planes; rigid nodes, surface chains and the chain ends in the planes
    for n in prange(nn):
        place3(n, (x, y, z), xn, yn, zn, (x0, y0, z0, acls, aflt), travel, prm, tip, tool)
    # 2. outflow faces between their (now placed) ends; the boundary values of the mesh
    # displacement
    for n in prange(nn):
        tf_face3(n, xn, yn, x0, y0, acls, aflt, off_x)
    # 3. Jacobi sweeps of the interior (in-plane neighbours)
    for _sweep in range(TF_SWEEPS):
        for n in prange(nn):
            tf_sweep(n, acls, aflt, scratch)
        for n in prange(nn):
            tf_sweep_copy(n, acls, aflt, scratch)
    for n in prange(nn):
        tf_interior(n, x, y, xn, yn, x0, y0, acls, aflt, off_x, max_move)


@njit(cache=True)
def rezone3d(nodes, cells, elems, work, ale, rho_s, t_room, vel_mode, prm, travel, tip):
    """One tool-frame ALE pass of the 3D engine: the placement (:func:`toolframe3d_targets`)
    into ``work.xn, yn, zn``, then :func:`robobore.cutting.fe.ale.remap3d.remap3d`
    (``nodes, cells, elems, work, rho_s, t_room, vel_mode`` as there), which copies the new
    positions into the nodes' ``x, y, z``. ``ale`` the
    :class:`~robobore.cutting.fe.ale.groups3d.ToolFrameAle3` (the places at the start, the
    tool-frame data of :func:`toolframe3d_ale_data`, ``aflt[:, 4:6]`` carried from pass to
    pass, the scratch array); ``travel`` = ``(off_x, off_z, max_move)``: the insert's travel
    since the start [m] and the move limit as a fraction of the local size; ``prm`` the
    engine's parameter vector and ``tip`` = ``(cx, cy, cz)`` the insert tip's current
    position (the "off tool" correction). Returns the number of nodes whose velocity was
    remapped. Allocates nothing."""
    toolframe3d_targets(nodes.x, nodes.y, nodes.z, work.xn, work.yn, work.zn, ale, prm,
                        travel, tip)
    return remap3d(nodes, cells, elems, work, rho_s, t_room, vel_mode)


def toolframe3d_targets_py(nodes: np.ndarray, places: np.ndarray, acls: np.ndarray,
                           aflt: np.ndarray, *, off_x: float = 0.0, off_z: float = 0.0,
                           max_move: float = 0.25, prm: np.ndarray | None = None,
                           tip: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Allocating wrapper of :func:`toolframe3d_targets` for tests and scripts: the placed
    nodes (n, 3) for the current ``nodes`` (n, 3) and the places at the start ``places``
    (n, 3); ``aflt`` is updated in place (its mesh displacement); ``prm`` the 3D engine's
    parameter vector (None: no insert), ``tip`` the insert tip's current position [m]."""
    from robobore.cutting.fe.hex.layout3d import N_PRM

    nodes = np.ascontiguousarray(nodes, np.float64)
    places = np.ascontiguousarray(places, np.float64)
    if prm is None:
        prm = np.zeros(N_PRM)
    n = nodes.shape[0]
    xn, yn, zn = np.empty(n), np.empty(n), np.empty(n)
    ale = ToolFrameAle3(x0=places[:, 0].copy(), y0=places[:, 1].copy(), z0=places[:, 2].copy(),
                        acls=np.ascontiguousarray(acls, np.int64), aflt=aflt,
                        scratch=np.zeros((n, 3)))
    toolframe3d_targets(nodes[:, 0].copy(), nodes[:, 1].copy(), nodes[:, 2].copy(), xn, yn, zn,
                        ale, np.ascontiguousarray(prm, np.float64),
                        (float(off_x), float(off_z), float(max_move)),
                        (float(tip[0]), float(tip[1]), float(tip[2])))
    return np.stack([xn, yn, zn], axis=1)


#: the keyword options of :func:`robobore.cutting.fe.ale.remap3d.remap3d_py` that
#: :func:`rezone3d_py` passes on (the same meaning and defaults), read from its signature
REMAP3D_OPTIONS = tuple(name for name, p in inspect.signature(remap3d_py).parameters.items()
                        if p.kind is inspect.Parameter.KEYWORD_ONLY)


def rezone3d_py(nodes: np.ndarray, places: np.ndarray, conn: np.ndarray, acls: np.ndarray,
                aflt: np.ndarray, fields: dict, *,
                travel: tuple[float, float, float] = (0.0, 0.0, 0.25),
                prm: np.ndarray | None = None,
                tip: tuple[float, float, float] = (0.0, 0.0, 0.0), **remap) -> dict:
    """Allocating wrapper of :func:`rezone3d` for tests and scripts: ``nodes`` (n, 3) the
    current positions, ``places`` (n, 3) the places at the start, ``acls``/``aflt`` the
    tool-frame data (``aflt`` updated in place), ``fields`` as in
    :func:`robobore.cutting.fe.ale.remap3d.remap3d_py`; ``travel`` = ``(off_x, off_z,
    max_move)`` the insert's travel since the start [m] and the move limit (a fraction of the
    local size), ``prm`` the 3D engine's parameter vector (None: no insert), ``tip`` the
    insert tip's current position [m]; ``remap`` any of remap3d_py's keyword options
    (:data:`REMAP3D_OPTIONS`: ``vel, fixed, fnbr, bflag, alive, rho_s, t_room, vel_mode``,
    same defaults). Returns the dict of
    :func:`~robobore.cutting.fe.ale.remap3d.remap3d_py`."""
    from robobore.cutting.fe.hex.layout3d import N_PRM

    unknown = sorted(set(remap) - set(REMAP3D_OPTIONS))
    if unknown:
        raise TypeError(f"rezone3d_py: unknown keyword option(s) {unknown}; expected "
                        f"travel, prm, tip or one of {list(REMAP3D_OPTIONS)}")
    if len(travel) != 3:
        raise ValueError(f"rezone3d_py: travel = {travel!r}; expected (off_x [m], off_z [m], "
                         "max_move [fraction of the local size])")
    rho_s = float(remap.pop("rho_s", 1.0))
    vel_mode = int(remap.pop("vel_mode", VEL_MOMENTUM))
    t_room = float(remap.get("t_room", 293.15))
    a = remap3d_inputs(nodes, conn, fields, **remap)
    places = np.ascontiguousarray(places, np.float64)
    if prm is None:
        prm = np.zeros(N_PRM)
    n = places.shape[0]
    ale = ToolFrameAle3(x0=places[:, 0].copy(), y0=places[:, 1].copy(), z0=places[:, 2].copy(),
                        acls=np.ascontiguousarray(acls, np.int64), aflt=aflt,
                        scratch=np.zeros((n, 3)))
    moved = rezone3d(*remap3d_groups(a), ale, rho_s, t_room, vel_mode,
                     np.ascontiguousarray(prm, np.float64),
                     (float(travel[0]), float(travel[1]), float(travel[2])),
                     (float(tip[0]), float(tip[1]), float(tip[2])))
    return remap3d_outputs(a, moved)


def toolframe3d_ale_data(mesh) -> tuple[np.ndarray, np.ndarray]:
    """``(acls, aflt)`` of a z-sliced tool-frame mesh
    (:class:`robobore.cutting.fe.mesh.toolframe3d.ToolFrameMesh3D`): ``acls`` (n, 7) int64
    the mesh's; ``aflt`` (n, 6) float64 with the 2D meaning of
    :class:`robobore.cutting.fe.ale.toolframe.ToolFrameMesh`, computed per slice in the
    slice's plane from the 3D node positions (x, y):

    * outflow-face node: its fraction along the chord between its two face ends (the
      projection on it) and its offset off the chord along the chord's left normal in chord
      lengths (column 1; :func:`tf_face3_py`);
    * chain end on an outflow line: the unit direction of its face's chord, from the face's
      first (bottom) end to its second (top) one, and the longest slide along it -- half the
      chord (half the chip thickness) on the chip's top face, half the slice's vertical
      uncut thickness ``t_mesh`` (at least ``sizes.t_min``) on the back face;
    * every node: the reference local size, its shortest in-plane edge within the slice;
    * the mesh displacement (columns 4, 5): zero.
    """
    acls = np.ascontiguousarray(mesh.acls, np.int64).copy()
    p = np.ascontiguousarray(mesh.nodes[:, :2], np.float64)
    n = p.shape[0]
    aflt = np.zeros((n, 6))
    cls = acls[:, 0]
    # outflow faces: fraction along the chord; their ends' line directions and slides
    for m in np.flatnonzero(cls == TF_FACE):
        a, b = int(acls[m, 1]), int(acls[m, 2])
        d = p[b] - p[a]
        ll = float(d @ d)
        aflt[m, 0] = float((p[m] - p[a]) @ d) / ll
        aflt[m, 1] = float(d[0] * (p[m, 1] - p[a, 1]) - d[1] * (p[m, 0] - p[a, 0])) / ll
        chord = math.sqrt(ll)
        for end in (a, b):
            if cls[end] != TF_LINE:
                continue
            aflt[end, 1:3] = d / chord
            if cls[a] == TF_RIGID:  # the back face (its bottom end on the rigid bottom)
                k = int(mesh.node_slice[end])
                aflt[end, 0] = 0.5 * max(float(mesh.t_mesh[k]), float(mesh.sizes.t_min))
            else:  # the chip's top face
                aflt[end, 0] = 0.5 * chord
    if np.any(aflt[cls == TF_LINE, 0] <= 0.0):
        raise AssertionError("a chain end without an outflow face")
    # the reference local size: the shortest in-plane edge at the node
    conn = mesh.conn
    size = np.full(n, np.inf)
    for a, b in ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)):
        ia, ib = conn[:, a], conn[:, b]
        ln = np.hypot(*(p[ib] - p[ia]).T)
        np.minimum.at(size, ia, ln)
        np.minimum.at(size, ib, ln)
    if not np.all(np.isfinite(size)):
        raise AssertionError("a node without an in-plane edge")
    aflt[:, 3] = size
    return acls, aflt

