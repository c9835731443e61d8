"""z-sliced tool-frame mesh of the 3D boring model: the 2D tool-frame ALE mesh
(:mod:`robobore.cutting.fe.ale.toolframe`) stacked along the feed axis under the insert's
nose.

**What the 3D tool-frame model is.** The 3D counterpart of the validated 2D tool-frame ALE
model (docs/fe.md): the mesh travels with the insert and the material flows through it --
in ahead of the edge, round the edge radius (where a workpiece-frame mesh with an erosion
layer or node splitting deletes or parts the ploughed layer and loses most of the thrust,
docs/fe3d.md "Limits of the workpiece frame"), out through the machined surface behind the
flank and through the chip's top face. Frame: the local frame of
:mod:`robobore.cutting.fe.models.boring3d` (x along the cutting velocity of the insert, y
normal to the bore wall out of the material, z along the feed), the insert's tip reference
(its lowest point, on the edge) at the origin.
The current edge profile is ``y = drop(z)``, the surface left by the previous revolution
``y_top(z) = min(ap, drop(z + f))``; the true chip is the material between them, of local
(vertical) thickness ``t(z) = y_top(z) - drop(z)`` on the engaged edge
``z_trail <= z <= z_lead`` (:func:`robobore.cutting.geometry.trailing_intersection`,
:func:`~robobore.cutting.geometry.lead_end`), of area ``ap f - scallop``
(:func:`robobore.cutting.geometry.chip_area`).

**Slices.** Planes ``z = const`` contain the cutting velocity and the wall normal. On the
nose arc the engaged edge's tangent is at most the local approach angle ``psi`` off the z
axis (29 deg at the lead end of ap 0.05 mm on a 0.4 mm nose), so each plane cuts the edge
at most ``psi`` off its normal section and is treated as a 2D tool-frame section (the
out-of-plane flow -- the chip's side flow -- crosses the z-faces and is remapped there).
Each slice k is the 2D two-block mesh of
:func:`robobore.cutting.fe.ale.toolframe.build_toolframe_mesh` (block A: the workpiece from
the inflow face under the edge to the back face, the rigid bottom, the edge arc and the
machined surface; block B: the chip, from the inflow face round the edge and up the rake
face to its top outflow face), built in the edge's *normal section* for the normal uncut
thickness of the slice and carried into the plane by the exact map of :func:`slice_map`: a
point at distance ``u`` along the cutting direction and ``s`` from the edge's apex line in
the normal section goes to ``x = u + tan(i) arc``, ``y`` with ``edge_section(y, z) = s``
(:func:`robobore.cutting.fe.hex.scalar3d.edge_section_py`). The map is the one the engine's
insert (:func:`~robobore.cutting.fe.hex.scalar3d.insert_gap3_py`) is defined by, so nodes on
the 2D tool surface lie on the 3D insert (zero gap), the 2D free surface ``y2 = 0`` goes to
``y = y_top(z)`` and the 2D cut line to ``y = drop(z)``: the chip block's vertical
thickness is ``t(z)`` exactly. On the nose tip (z = 0) the map is a mirror in x and a shift
in y, and the slice is the 2D mesh itself.

**One topology.** The element counts of every slice are those of the 2D mesh of the
reference slice z = 0 (the deepest point of the nose, the 2D model at ``h = t(0)``), and
the node positions of slice k are that mesh's construction at the slice's own thickness
with the reference's step fractions (:func:`section_nodes`), so slices k and k+1 stack
into hexahedra. The x extent (inflow and back faces), the chip's top face and the flat
rigid bottom are common to all slices, chosen by the 2D builder's rules for the thickest
slice.

**The clamp.** At both ends of the engagement the chip thins to zero; a slice needs a chip
block, so ``t`` is clamped to ``t_min`` (:class:`ToolFrame3DSizes`). The clamp adds a
fictitious chip of area ``int max(0, t_min - t) dz`` (:func:`clamp_area`): for the paper's
condition 0.96 % of the true chip area at t_min = 5 um, 3.7 % at 10 um; the mesh's own
figure (top surface interpolated between slices) is in :attr:`ToolFrameMesh3D.areas`. The
price of a small ``t_min``: the chip block keeps the reference's rows (spaced towards
uniform in thin slices, :class:`SectionPlan`), so its elements at the ends are about
``t_min / t(0)`` times thinner than at the tip and the explicit step falls with them. At
the paper's condition with 12.5 um elements the hexahedra's stable-step length
``1 / sqrt(2 b.b)`` is 0.22 um at the thin ends for t_min = 5 um and 0.36 um for 10 um,
against 1.02 um in the nose-tip slice (10 um elements: 0.18 / 0.31 / 0.89 um; 6.25 um:
0.12 / 0.22 / 0.57 um); :attr:`ToolFrameMesh3D.min_edge` is the shortest element edge.

**Margins.** ``margin_slices`` slices beyond each end of the engagement carry block A only,
its top flat at ``y_top(z)``, which lies below the edge there (the insert clears the
surface): the chip block's hexahedra stop at the end slices, whose z-faces are the chip's
sides (:data:`FK_CHIP_SIDE`). They are outflow faces (``BF_OPEN``): the placement keeps
their nodes in their planes, so the material that flows sideways past an end slice (the
chip's side flow) leaves the model there, as through the chip's top face (the run's
``mass_ratio`` counts it with the other outflow).

**Node classes and faces.** Every node carries its slice, its 2D node class
(``TF_RIGID / TF_CHAIN / TF_LINE / TF_FACE / TF_INTERIOR`` of
:mod:`robobore.cutting.fe.ale.rezone`) and the 2D class's neighbours within its slice (as
global indices), so the in-plane tool-frame placement of each slice is the 2D one; in a
margin slice block A's top row is a free-surface chain. Every hexahedron face carries a
kind (:data:`FK_INTERIOR` ... :data:`FK_CHIP_SIDE`) and the remap's flux flag
(``BF_VIRGIN`` on the inflow face, ``BF_OPEN`` on the outflow faces and the chip's sides,
:mod:`robobore.cutting.fe.ale.remap3d`), in the face numbering of
:data:`robobore.cutting.fe.ale.hexvolume3d.FACES_OUT`.

**The ALE pass** on this mesh is :func:`robobore.cutting.fe.ale.rezone3d.rezone3d` (nodes
kept in their planes, the 2D tool-frame placement in each plane, the 3D insert's "off tool"
push, then :func:`robobore.cutting.fe.ale.remap3d.remap3d`), with the per-slice ``aflt`` of
:func:`robobore.cutting.fe.ale.rezone3d.toolframe3d_ale_data`. :func:`extrude_toolframe_mesh`
builds the same kind of mesh from one 2D tool-frame mesh in every plane (a straight edge
across a slab), for the plane-strain cross-check against the 2D engine.

**Open points of the mesh and its placement.**

1. In the thin end slices the chip block's elements are sheared: their height across the
   rows is down to 0.095 of their shortest edge at the paper's condition (0.43 in the 2D
   mesh), and the placement's move limit ``max_move`` is a fraction of the shortest edge
   (the 2D meaning of ``aflt[:, 3]``), so a move near the limit there would sweep more than
   the element's height (remap Courant number above 1). The Lagrangian drift between ALE
   passes is far below it; a limit on the height would make it safe by construction. The
   same thin rows lose height as the chip forms (a drift of 0.1 um is a third of a row at
   the clamp), which the engine's renewed inertia factors absorb
   (:func:`robobore.cutting.fe.engine.kernels3d.renew_inertia_factors_py`).
2. Block A's top faces in the hexahedra between a margin slice and the first (last) engaged
   slice are on the 3D outline, but in the engaged slice their nodes are in-plane interior
   nodes (the chip block's join line): they are placed as interior nodes and the volume
   their faces sweep is dropped as a closed face's.
3. No GPU port: the placement's and the remap's scalar passes would compile for the device
   as the 2D ones do (``tf_place_py`` rebound with the device ``_limit`` and
   :func:`~robobore.cutting.fe.ale.rezone3d.keep_py`, ``off_insert_py`` with the device
   ``insert_gap3``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robobore.cutting.fe.ale.remap import BF_CLOSED, BF_OPEN, BF_VIRGIN
from robobore.cutting.fe.ale.rezone import TF_CHAIN, TF_INTERIOR, TF_LINE, TF_RIGID
from robobore.cutting.fe.ale.toolframe import ToolFrameMesh
from robobore.cutting.fe.mesh.orthogonal import MeshSizes
from robobore.cutting.fe.mesh.toolframe3d_layout import ToolFrame3DSizes, slice_layout
from robobore.cutting.fe.mesh.toolframe3d_section import (
    SectionPlan,
    clamp_area,
    s_of_y,
    section_nodes,
    slice_map,
)
from robobore.cutting.geometry import BoringInsert, chip_area

__all__ = ["ToolFrameMesh3D", "FK_INTERIOR", "FK_INFLOW", "FK_OUTFLOW", "FK_TOOL", "FK_FREE",
           "FK_BOTTOM", "FK_SIDE", "FK_CHIP_SIDE", "build_toolframe3d_mesh",
           "extrude_toolframe_mesh", "tip_slice_nodes", "reference_blocks"]

#: kind of a hexahedron face: shared by two elements, inflow face (virgin material enters),
#: outflow face (machined-surface side back face, chip top face), on the insert (rake face
#: and edge arc), free surface (the chip's free side and back, the machined surface, the
#: top of the margins), rigid bottom, the side planes of the block (first and last slice),
#: the chip's side faces at the first and last engaged slices (outflow of the side flow)
FK_INTERIOR, FK_INFLOW, FK_OUTFLOW, FK_TOOL, FK_FREE, FK_BOTTOM, FK_SIDE, FK_CHIP_SIDE = range(8)


@dataclass
class ToolFrameMesh3D(MeshSizes):
    """The z-sliced tool-frame mesh (SI, the 3D frame of the module docstring).

    ``nodes`` (n, 3); ``conn`` (e, 8) VTK order (positive volumes); ``chip`` (e,) block B;
    ``node_slice`` (n,) slice index, ``node_local`` (n,) index of the node in its slice's 2D
    node order, ``node_class`` (n,) 2D class (``TF_*``), ``acls`` (n, 7) the class and the
    2D class's neighbours within the slice (global indices, -1 pad: see
    :class:`robobore.cutting.fe.ale.toolframe.ToolFrameMesh`); ``elem_slice`` (e,) the lower
    slice of each hexahedron; ``fkind`` (e, 6) face kinds (``FK_*``) and ``bflag`` (e, 6)
    the remap's flux flags, faces numbered as ``hexvolume3d.FACES_OUT``; ``rigid`` (n,) the
    inflow face and bottom; ``z_slices`` (k,) [m], ``engaged`` (k,) slices with a chip block;
    ``t`` (k,) true vertical uncut thickness, ``t_mesh`` (k,) the clamped one; ``h2`` (k,)
    the normal-section thickness each slice was built for; ``reference`` the 2D mesh of the
    reference slice (z = 0); ``plan`` the slices' common topology (None for an extruded
    mesh, :func:`extrude_toolframe_mesh`); ``blocks`` the 2D block sizes
    (:func:`reference_blocks`); ``areas`` the chip areas [m^2] (``chip``: mechanistic,
    ``mesh_above_edge``: the mesh's material above the edge profile, ``clamp``: the
    clamp's analytic part, ``clamp_mesh``: mesh minus chip); ``min_edge`` the shortest
    element edge [m]; ``sizes`` the size control.
    """

    nodes: np.ndarray
    conn: np.ndarray
    chip: np.ndarray
    node_slice: np.ndarray
    node_local: np.ndarray
    node_class: np.ndarray
    acls: np.ndarray
    elem_slice: np.ndarray
    fkind: np.ndarray
    bflag: np.ndarray
    rigid: np.ndarray
    z_slices: np.ndarray
    engaged: np.ndarray
    t: np.ndarray
    t_mesh: np.ndarray
    h2: np.ndarray
    y_bottom: float
    reference: ToolFrameMesh
    plan: SectionPlan | None
    sizes: ToolFrame3DSizes
    blocks: dict
    areas: dict = field(default_factory=dict)
    min_edge: float = 0.0


def build_toolframe3d_mesh(insert: BoringInsert, ap: float, f: float,
                           sizes: ToolFrame3DSizes) -> ToolFrameMesh3D:
    """The z-sliced tool-frame mesh for the boring insert at depth of cut ``ap`` and feed
    ``f`` [m] (see the module docstring). Raises ValueError when the geometry leaves the
    model's range (no engagement on both sides of the tip, a chip reaching past the nose)."""
    lay = slice_layout(insert, ap, f, sizes)
    z, eng, t_true, y_top, h2 = lay.z, lay.eng, lay.t_true, lay.y_top, lay.h2
    plan, ref, blk, y_bot = lay.plan, lay.ref, lay.blk, lay.y_bot
    r = insert.edge_radius_m
    nk = z.size
    na, ja = blk["na"], blk["ja"]
    n_a = (na + 1) * (ja + 1)  # block A nodes come first in the 2D order
    n2d = ref.nodes.shape[0]
    e_a = na * ja
    conn2 = ref.conn
    # ---- node positions slice by slice
    idx_a = np.arange(n_a).reshape(na + 1, ja + 1)
    coords, sl, loc = [], [], []
    offs = np.zeros(nk + 1, np.int64)
    for k in range(nk):
        if eng[k]:
            s_bot = float(s_of_y(insert, np.array([y_bot]), np.array([z[k]]))[0])
            sec, _ = section_nodes(plan, float(h2[k]), s_bot - r)
            p3 = slice_map(insert, float(z[k]), sec, float(h2[k]))
        else:
            p3 = None
        coords.append(p3)
        offs[k + 1] = offs[k] + (n2d if eng[k] else n_a)
    # margin slices: block A of the nearest engaged slice's columns, top flat at y_top(z)
    first, last = int(np.flatnonzero(eng)[0]), int(np.flatnonzero(eng)[-1])
    for k in range(nk):
        if eng[k]:
            continue
        src = coords[first if k < first else last][:n_a]
        top = src[idx_a[:, ja]]
        bot = src[idx_a[:, 0]]
        xa = bot[:, 0][:, None] + plan.eta_a[None, :] * (top[:, 0] - bot[:, 0])[:, None]
        ya = y_bot + plan.eta_a[None, :] * (y_top[k] - y_bot)
        coords[k] = np.column_stack([xa.ravel(), np.broadcast_to(ya, xa.shape).ravel(),
                                     np.full(n_a, z[k])])
    for k in range(nk):
        sl.append(np.full(coords[k].shape[0], k, np.int64))
        loc.append(np.arange(coords[k].shape[0], dtype=np.int64))
    nodes = np.vstack(coords)
    node_slice = np.concatenate(sl)
    node_local = np.concatenate(loc)
    conn, chip, elem_slice, elem_2d = _stack_hexahedra(conn2, eng, offs, e_a)
    # ---- node classes and in-slice neighbours
    acls = np.full((nodes.shape[0], 7), -1, np.int64)
    for k in range(nk):
        o = offs[k]
        if eng[k]:
            a = ref.acls.copy()
        else:
            a = ref.acls[:n_a].copy()
            top = idx_a[:, ja]
            # margin: block A's top row is one free-surface chain, inflow corner rigid,
            # back corner its end on the back face's line
            for i in range(1, na + 1):
                nd = top[i]
                a[nd, :] = -1
                a[nd, 0] = TF_CHAIN if i < na else TF_LINE
                a[nd, 1] = top[i - 1]
                a[nd, 2] = top[i + 1] if i < na else -1
            # edge neighbours within block A (the 2D builder's sorted lists)
            nbrs: list[set[int]] = [set() for _ in range(n_a)]
            for el in conn2[:e_a]:
                for c in range(4):
                    p0, p1 = int(el[c]), int(el[(c + 1) % 4])
                    nbrs[p0].add(p1)
                    nbrs[p1].add(p0)
            for nd in range(n_a):
                lst = sorted(nbrs[nd])[:4]
                if a[nd, 0] == TF_INTERIOR and len(lst) != 4:
                    raise AssertionError("block A interior node without 4 neighbours")
                a[nd, 3:7] = -1
                a[nd, 3:3 + len(lst)] = lst
        acls[o:o + a.shape[0]] = _offset_acls(a, o)
    node_class = acls[:, 0].copy()
    rigid = node_class == TF_RIGID
    # ---- face kinds and flux flags
    fkind, bflag = _face_kinds(conn, chip, elem_slice, elem_2d, eng, ref, blk)
    # ---- chip areas: the mesh's material above the edge profile
    areas = _chip_areas(insert, ap, f, sizes.t_min, z, eng, nodes, node_slice, offs, ref, blk)
    return ToolFrameMesh3D(
        nodes=nodes, conn=conn, chip=chip, node_slice=node_slice, node_local=node_local,
        node_class=node_class, acls=acls, elem_slice=elem_slice, fkind=fkind, bflag=bflag,
        rigid=rigid, z_slices=z, engaged=eng, t=t_true, t_mesh=y_top - insert.drop(z), h2=h2,
        y_bottom=y_bot, reference=ref, plan=plan, sizes=sizes, blocks=blk, areas=areas,
        min_edge=_min_edge(nodes, conn))


def _stack_hexahedra(conn2: np.ndarray, eng: np.ndarray, offs: np.ndarray, e_a: int):
    """Hexahedra between slices k and k + 1 (all the 2D quads ``conn2`` where both slices
    are engaged, block A's ``e_a`` first ones otherwise): the quads (counter-clockwise in the
    2D frame, clockwise after the mirror in x) reversed at slice k, the same at k + 1; slice k
    starts at node ``offs[k]``. Returns ``(conn, chip, elem_slice, elem_2d)``."""
    rev = conn2[:, [0, 3, 2, 1]]
    conns, chip, eslice, e2d = [], [], [], []
    for k in range(eng.size - 1):
        ne_k = conn2.shape[0] if (eng[k] and eng[k + 1]) else e_a
        q = rev[:ne_k]
        conns.append(np.hstack([q + offs[k], q + offs[k + 1]]))
        chip.append(np.arange(ne_k) >= e_a)
        eslice.append(np.full(ne_k, k, np.int64))
        e2d.append(np.arange(ne_k, dtype=np.int64))
    return (np.vstack(conns).astype(np.int64), np.concatenate(chip), np.concatenate(eslice),
            np.concatenate(e2d))


def _offset_acls(a: np.ndarray, o: int) -> np.ndarray:
    """A slice's ``acls`` (its 2D ones) with the neighbours shifted to global indices."""
    a = a.copy()
    nbr = a[:, 1:]
    a[:, 1:] = np.where(nbr >= 0, nbr + o, -1)
    return a


def _min_edge(nodes: np.ndarray, conn: np.ndarray) -> float:
    """The shortest hexahedron edge [m]."""
    edges = np.concatenate([np.linalg.norm(nodes[conn[:, a]] - nodes[conn[:, b]], axis=1)
                            for a, b in ((0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6),
                                         (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7))])
    return float(edges.min())


def reference_blocks(ref: ToolFrameMesh) -> dict:
    """The block sizes ``{"na", "ja", "nb", "jb", "n1", "i_s"}`` of a 2D tool-frame mesh
    (:func:`build_toolframe_mesh`), read from its node lists: block A (``(na + 1) (ja + 1)``
    nodes, i-major) first; the machined surface is block A's top row from column ``i_s``;
    block B has ``nb + 1`` columns of ``jb + 1`` nodes, its first ``n1 + 1`` bottom nodes
    shared with block A's top row."""
    mach = np.asarray(ref.machined_nodes)
    ja = int(mach[1] - mach[0]) - 1
    n_a = int(mach[-1]) + 1
    na = n_a // (ja + 1) - 1
    i_s = na + 1 - mach.size
    nb = int(np.asarray(ref.chip_top_nodes).size) - 1
    jb = int(np.asarray(ref.outflow_nodes).size) - 1
    n1 = nb + 1 - int(np.asarray(ref.chip_under_nodes).size)
    if (n_a != (na + 1) * (ja + 1) or n1 != i_s or int((~ref.chip).sum()) != na * ja
            or int(ref.chip.sum()) != nb * jb
            or ref.nodes.shape[0] != n_a + (nb + 1) * (jb + 1) - (n1 + 1)):
        raise ValueError("the 2D mesh is not a two-block tool-frame mesh of "
                         "build_toolframe_mesh")
    return {"na": na, "ja": ja, "nb": nb, "jb": jb, "n1": n1, "i_s": i_s}


def tip_slice_nodes(xy2: np.ndarray, h2: float) -> np.ndarray:
    """Points (n, 2) of a 2D section built for uncut thickness ``h2`` (frame of
    :func:`build_toolframe_mesh`) to the (x, y) of the nose-tip plane z = 0: there
    :func:`slice_map` is the mirror ``x = -x2`` and the shift ``y = y2 + h2`` (the cut line
    ``y2 = -h2`` to the tip reference ``y = 0``, the edge centre to ``y = r``), in closed
    form."""
    xy2 = np.asarray(xy2, np.float64)
    return np.column_stack([-xy2[:, 0], xy2[:, 1] + h2])


def extrude_toolframe_mesh(ref: ToolFrameMesh, z: np.ndarray) -> ToolFrameMesh3D:
    """The 2D tool-frame mesh ``ref`` extruded along z: every slice at ``z`` [m] (strictly
    increasing, at least two) is ``ref`` carried into the 3D frame as the nose-tip slice of
    :func:`build_toolframe3d_mesh` is (:func:`tip_slice_nodes`: the tip reference at the
    origin, the cutting velocity along +x), every slice engaged (the chip block in each),
    the z-faces of the first and last slices ``FK_SIDE``. The model of a straight edge
    across a slab (plane strain between the side planes when they are held in z): the 3D
    counterpart of the 2D model on ``ref``, for cross-checks of the 3D engine against the 2D
    one. ``t``, ``t_mesh``, ``h2`` are ``ref.h`` in every slice, ``sizes`` the 2D mesh's
    element and edge sizes with the largest slice step and ``t_min = ref.h``, ``plan``
    None; ``areas["chip"]`` the uncut chip area ``ref.h (z[-1] - z[0])``."""
    z = np.asarray(z, np.float64).ravel()
    if z.size < 2 or not np.all(np.diff(z) > 0.0):
        raise ValueError(f"extrusion planes z must be >= 2 strictly increasing values [m], "
                         f"got {z.tolist()}")
    blk = reference_blocks(ref)
    h = float(ref.h)
    nk = z.size
    n2d = ref.nodes.shape[0]
    e_a = blk["na"] * blk["ja"]
    eng = np.ones(nk, bool)
    xy = tip_slice_nodes(ref.nodes, h)
    nodes = np.column_stack([np.tile(xy, (nk, 1)), np.repeat(z, n2d)])
    offs = np.arange(nk + 1, dtype=np.int64) * n2d
    conn, chip, elem_slice, elem_2d = _stack_hexahedra(ref.conn, eng, offs, e_a)
    acls = np.vstack([_offset_acls(ref.acls, int(offs[k])) for k in range(nk)])
    node_class = acls[:, 0].copy()
    fkind, bflag = _face_kinds(conn, chip, elem_slice, elem_2d, eng, ref, blk)
    sizes = ToolFrame3DSizes(element_size=ref.element_size, edge_size=ref.edge_size,
                             slice_spacing=float(np.diff(z).max()), t_min=h, margin_slices=0)
    return ToolFrameMesh3D(
        nodes=nodes, conn=conn, chip=chip, node_slice=np.repeat(np.arange(nk), n2d),
        node_local=np.tile(np.arange(n2d, dtype=np.int64), nk), node_class=node_class,
        acls=acls, elem_slice=elem_slice, fkind=fkind, bflag=bflag,
        rigid=node_class == TF_RIGID, z_slices=z.copy(), engaged=eng, t=np.full(nk, h),
        t_mesh=np.full(nk, h), h2=np.full(nk, h), y_bottom=float(xy[:, 1].min()),
        reference=ref, plan=None, sizes=sizes, blocks=blk,
        areas={"chip": h * float(z[-1] - z[0])}, min_edge=_min_edge(nodes, conn))


def _face_kinds(conn, chip, elem_slice, elem_2d, eng, ref: ToolFrameMesh, blk: dict):
    """Face kinds (``FK_*``) and flux flags of every hexahedron face (``FACES_OUT`` order).

    In-plane faces take the kind of their 2D edge: with the quads reversed, hexahedron face
    0 / 3 / 1 / 2 is 2D edge 0 / 1 / 2 / 3 (bottom row j, right i + 1, top j + 1, left i);
    faces 4 and 5 lie in slices k and k + 1."""
    from robobore.cutting.fe.physics.thermal3d import face_neighbours

    na, ja, nb, jb = blk["na"], blk["ja"], blk["nb"], blk["jb"]
    e_a = na * ja
    fn = face_neighbours(conn)
    ne = conn.shape[0]
    fkind = np.zeros((ne, 6), np.int64)
    bflag = np.full((ne, 6), BF_CLOSED, np.int64)
    nk = eng.size
    face_of_edge = (0, 3, 1, 2)
    # block A's top row in the reference section: the join line ahead of the join point
    # (column i_s), the edge arc down to the lowest point (y = -h), the machined surface
    i_s = blk["i_s"]
    ytop_a = ref.nodes[np.arange((na + 1) * (ja + 1)).reshape(na + 1, ja + 1)[:, ja], 1]
    h = -ytop_a[-1]
    above = ytop_a > -h + 1e-9 * h
    on_arc_a = np.zeros(na, bool)  # top-row segment i -> i + 1 on the edge arc
    on_arc_a[i_s:] = above[i_s:-1] | above[i_s + 1:]
    for e in range(ne):
        k = elem_slice[e]
        full = eng[k] and eng[k + 1]
        q = elem_2d[e]
        if q < e_a:
            i, j = divmod(q, ja)
            last_i, last_j = na - 1, ja - 1
        else:
            i, j = divmod(q - e_a, jb)
            last_i, last_j = nb - 1, jb - 1
        for edge in range(4):
            fc = face_of_edge[edge]
            if fn[e, fc] >= 0:
                continue
            if edge == 3 and i == 0:
                kind = FK_INFLOW
            elif edge == 1 and i == last_i:
                kind = FK_OUTFLOW
            elif q < e_a and edge == 0 and j == 0:
                kind = FK_BOTTOM
            elif q < e_a and edge == 2 and j == last_j:
                # block A top: the join line (only without a chip block above), the arc
                # under the edge, the machined surface
                kind = FK_TOOL if (full and i >= i_s and on_arc_a[i]) else FK_FREE
            elif q >= e_a and edge == 0 and j == 0:
                kind = FK_TOOL  # block B bottom beyond the join point: arc and rake face
            elif q >= e_a and edge == 2 and j == last_j:
                kind = FK_FREE  # the chip's free surface
            else:
                raise AssertionError(f"unclassified boundary face: element {e}, edge {edge}")
            fkind[e, fc] = kind
        for fc in (4, 5):
            if fn[e, fc] >= 0:
                continue
            kk = k if fc == 4 else k + 1
            # block A has a z-neighbour in every slice but the block's side planes, so a
            # z-face without one inside them is the chip block's side at an end slice
            fkind[e, fc] = FK_SIDE if kk in (0, nk - 1) else FK_CHIP_SIDE
    bflag[fkind == FK_INFLOW] = BF_VIRGIN
    bflag[(fkind == FK_OUTFLOW) | (fkind == FK_CHIP_SIDE)] = BF_OPEN
    return fkind, bflag


def _chip_areas(insert, ap, f, t_min, z, eng, nodes, node_slice, offs, ref, blk) -> dict:
    """Chip areas [m^2]: the mechanistic ``ap f - scallop``; the mesh's material above the
    edge profile, ``int max(0, y_mesh(z) - drop(z)) dz`` with ``y_mesh`` the top edge of the
    inflow face (straight between slices, as the hexahedra's faces are); the clamp's
    analytic part (:func:`clamp_area`)."""
    ja = blk["ja"]
    # the inflow face's top node of each slice: block B's (i = 0, j = jb) in an engaged
    # slice, block A's (i = 0, j = ja) in a margin slice
    top_b = int(ref.chip_top_nodes[0])
    tops = np.array([offs[k] + (top_b if eng[k] else ja) for k in range(z.size)])
    y_in = nodes[tops, 1]
    # between slices the top edge is straight; where a slice pair has no chip block the
    # face's top is block A's (the join line at the engaged end)
    area = 0.0
    for k in range(z.size - 1):
        ya = y_in[k] if (eng[k] and eng[k + 1]) or not eng[k] else nodes[offs[k] + ja, 1]
        yb = y_in[k + 1] if (eng[k] and eng[k + 1]) or not eng[k + 1] else \
            nodes[offs[k + 1] + ja, 1]
        zz = np.linspace(z[k], z[k + 1], 401)
        ym = ya + (yb - ya) * (zz - z[k]) / (z[k + 1] - z[k])
        area += float(np.trapezoid(np.maximum(ym - insert.drop(zz), 0.0), zz))
    chip = chip_area(insert, ap, f)
    return {"chip": chip, "mesh_above_edge": area, "clamp": clamp_area(insert, ap, f, t_min),
            "clamp_mesh": area - chip}
