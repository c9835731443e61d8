"""Graded structured quad mesh of the orthogonal-cutting workpiece (SI units).

Frame: x along the workpiece (the tool moves towards -x), y up; the free surface is y = 0,
the tool's lowest point (cut line) is at y = -h. Layout from top to bottom:

* chip layer, 0 > y > -h + f le, uniform rows of about ``le`` (element size);
* the separation layer, one row of height ``le`` from -h + f le down to -h - (1 - f) le
  (f = ``layer_offset``: 1 puts the layer just above the cut line, 0.5 centres it on it);
* a fine zone of ``fine_depth_factor * h`` below it, uniform ``le``;
* rows growing geometrically (ratio ``grading``) down to y = -height_factor * h.

Columns are uniform (``le``) over the cut and ``3 h`` beyond its end, then grow
geometrically towards the fixed back end x = 0. Nodes on x = 0 and on the bottom are fixed.
Elements are numbered row by row, nodes counter-clockwise (n1..n4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def _graded(length: float, h0: float, ratio: float) -> np.ndarray:
    """Element sizes (first = h0, growing by ``ratio``) that fill ``length`` exactly."""
    sizes: list[float] = []
    total = 0.0
    s = h0
    while total + s < length - 1e-12 * length:
        sizes.append(s)
        total += s
        s *= ratio
    rest = length - total
    if sizes and rest < 0.5 * sizes[-1]:
        sizes[-1] += rest
    else:
        sizes.append(rest)
    return np.array(sizes)


class MeshSizes:
    """``n_nodes`` and ``n_elements`` of a mesh with ``nodes`` (n, dim), ``conn`` (e, corners)."""

    nodes: np.ndarray
    conn: np.ndarray

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.conn.shape[0])


@dataclass(frozen=True)
class CuttingMesh(MeshSizes):
    """Quad mesh: ``nodes`` (n_nodes, 2) [m], ``conn`` (n_elem, 4) counter-clockwise.

    ``layer`` (n_elem,) bool: separation-layer elements; ``chip`` (n_elem,) bool: elements
    of the uncut chip layer; ``fixed`` (n_nodes,) bool: nodes held in x and y;
    ``surface`` (n_nodes,) bool: nodes on the initial free surface y = 0.
    ``node_elems_ptr``/``node_elems`` (CSR) and ``node_corner`` list the elements (and the
    node's local corner 0..3) around each node.
    """

    nodes: np.ndarray
    conn: np.ndarray
    layer: np.ndarray
    chip: np.ndarray
    fixed: np.ndarray
    surface: np.ndarray
    node_elems_ptr: np.ndarray
    node_elems: np.ndarray
    node_corner: np.ndarray
    length: float
    height: float
    y_cut: float
    element_size: float
    layer_top: float
    #: node splitting (``split_height`` given): partner of each node on the parting line
    #: (-1 elsewhere); the copy used by the chip elements above is the one added last
    twin: np.ndarray | None = None

    @property
    def upper(self) -> np.ndarray | None:
        """Node splitting: True for the parting-line copies the chip elements use."""
        if self.twin is None:
            return None
        return (self.twin >= 0) & (self.twin < np.arange(self.twin.size))


def build_mesh(h: float, le: float, cut_length: float, *, ahead: float = 0.3e-3,
               fine_depth_factor: float = 1.0, height_factor: float = 5.0,
               grading: float = 1.25, layer_offset: float = 0.5,
               split_height: float | None = None) -> CuttingMesh:
    """Graded mesh for uncut chip thickness ``h`` [m], element size ``le`` [m], cut length [m].

    The workpiece spans x in [0, ahead + cut_length]; the cut runs from the right end to
    x = ahead. ``layer_offset`` places the separation layer: its top is at
    y = -h + layer_offset * le (1: the layer lies just above the cut line, 0.5: centred on it).

    With ``split_height`` [m] there is no separation layer: the nodes of the parting line
    y = -h + split_height are doubled (the chip elements above use one copy, the workpiece
    below the other; ``twin`` pairs them) so the solver can tie them and split them where
    the tool edge reaches them.
    """
    if split_height is not None:
        top_chip = -(h - split_height)
    else:
        top_chip = -(h - layer_offset * le)
    n_chip = max(1, int(round(-top_chip / le)))
    y_rows = [0.0]
    y_rows += list(np.linspace(0.0, top_chip, n_chip + 1)[1:])
    if split_height is None:
        y_rows.append(top_chip - le)  # separation layer
        layer_row = n_chip  # row index from the top
    else:
        layer_row = -10  # no layer row
    fine_depth = fine_depth_factor * h
    n_fine = max(1, int(round(fine_depth / le)))
    y0 = y_rows[-1]
    y_rows += [y0 - le * (i + 1) for i in range(n_fine)]
    depth_rest = height_factor * h - (-y_rows[-1])
    if depth_rest > 0.25 * le:
        ys = np.cumsum(_graded(depth_rest, le * grading, grading))
        y_rows += list(y_rows[-1] - ys)
    y_top_down = np.array(y_rows)
    yc = y_top_down[::-1].copy()  # bottom -> top
    n_ey = len(yc) - 1
    layer_e_row = n_ey - 1 - layer_row
    chip_rows = set(range(n_ey - n_chip, n_ey))

    total = ahead + cut_length
    xc = _columns(h, le, total, ahead, grading)
    n_ex = len(xc) - 1

    X, Y = np.meshgrid(xc, yc)  # (ny, nx)
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    nxn = n_ex + 1
    conn = np.empty((n_ex * n_ey, 4), dtype=np.int64)
    layer = np.zeros(n_ex * n_ey, dtype=bool)
    chip = np.zeros(n_ex * n_ey, dtype=bool)
    e = 0
    for j in range(n_ey):
        for i in range(n_ex):
            n1 = j * nxn + i
            conn[e] = (n1, n1 + 1, n1 + 1 + nxn, n1 + nxn)
            layer[e] = j == layer_e_row
            chip[e] = j in chip_rows
            e += 1
    twin = None
    if split_height is not None:
        # the parting line's nodes (not the fixed one at x = 0); the elements of the row
        # above it (the chip's bottom row) take the new copies
        jrow = n_ey - n_chip  # node row of the parting line
        above = np.arange(jrow * n_ex, (jrow + 1) * n_ex)  # element row jrow (above line)
        nodes, twin = _split_nodes(nodes, conn, jrow * nxn + np.arange(1, nxn), above)
    return _finish(nodes, conn, layer, chip, yc[0], total, h, le, top_chip, twin)


def _columns(h: float, le: float, total: float, ahead: float, grading: float) -> np.ndarray:
    """Column lines of the coarse grid: uniform ``le`` over the cut and 3 h beyond, graded
    towards x = 0 (as :func:`build_mesh`)."""
    fine_start = max(0.0, ahead - 3.0 * h)
    n_fx = max(1, int(round((total - fine_start) / le)))
    x_fine = np.linspace(fine_start, total, n_fx + 1)
    if fine_start > 0.25 * le:
        xs = np.cumsum(_graded(fine_start, le * grading, grading))
        x_left = fine_start - xs
        x_left[-1] = 0.0
        return np.concatenate([x_left[::-1], x_fine])
    x_fine[0] = 0.0
    return x_fine


def _subdivide(xc: np.ndarray, k: int) -> np.ndarray:
    """Each interval of ``xc`` cut into 2**k equal parts."""
    n = 2 ** k
    t = np.arange(n) / n
    inner = (xc[:-1, None] + t[None, :] * np.diff(xc)[:, None]).ravel()
    return np.append(inner, xc[-1])


def build_edge_refined_mesh(h: float, le: float, cut_length: float, *, split_height: float,
                            levels: int, band_above: float, band_below: float,
                            ahead: float = 0.3e-3, fine_depth_factor: float = 1.0,
                            height_factor: float = 5.0, grading: float = 1.25) -> CuttingMesh:
    """Node-splitting mesh refined ``levels`` times (element size ``le / 2**levels``) in a
    band round the parting line, where the material passes the cutting edge.

    Frame and boundaries as :func:`build_mesh`. The parting line y_p = -h + split_height
    carries the finest nodes (doubled, ``twin``). The band has ``band_above`` [m] of fine
    rows above y_p (the stagnation zone and the chip underside that wraps round the edge)
    and ``band_below`` [m] below it (the material ploughed under the edge radius). Each
    size change is a conforming 2:1 transition row: over every pair of coarse columns
    six quads join the four fine columns below (or above) to the two coarse ones, with
    three mid-height nodes, the row as tall as the coarse element (no hanging nodes, so
    the solver needs nothing special). Above the band the chip keeps rows of about ``le``;
    below it a zone of ``le`` rows reaches ``fine_depth_factor * h`` under the cut line,
    then rows grow by ``grading`` down to ``height_factor * h``.
    """
    if levels < 1:
        raise ValueError("levels must be >= 1 (use build_mesh for a uniform mesh)")
    a = [le / 2 ** k for k in range(levels + 1)]  # element size of each level
    af = a[levels]
    y_p = -h + split_height
    trans_h = sum(a[:levels])  # transition rows, coarse-level height each
    chip_above = -y_p
    n_up = max(1, int(math.ceil(band_above / af - 1e-9)))
    while n_up > 1 and chip_above - n_up * af - trans_h < -1e-9 * le:
        n_up -= 1
    coarse_top = chip_above - n_up * af - trans_h
    if coarse_top < -1e-9 * le:
        raise ValueError(
            f"the chip above the parting line ({chip_above * 1e6:.4g} um) is too thin for "
            f"{levels} refinement levels of {le * 1e6:.4g} um elements (needs "
            f"{(af + trans_h) * 1e6:.4g} um)")
    n_ctop = int(round(coarse_top / le))
    # rows from the top down: (y_top, y_bottom, level_top, level_bottom)
    rows: list[tuple[float, float, int, int]] = []
    y = 0.0
    if n_ctop >= 1:
        hc = coarse_top / n_ctop
        for _ in range(n_ctop):
            rows.append((y, y - hc, 0, 0))
            y -= hc
        hf = af
    else:
        hf = (n_up * af + max(coarse_top, 0.0)) / n_up  # spread the rest over the fine rows
    for k in range(levels):  # transitions above the band: coarse on top
        rows.append((y, y - a[k], k, k + 1))
        y -= a[k]
    for _ in range(n_up):
        rows.append((y, y - hf, levels, levels))
        y -= hf
    y = y_p  # exact parting line
    rows[-1] = (rows[-1][0], y_p, levels, levels)
    n_dn = max(1, int(math.ceil(band_below / af - 1e-9)))
    for _ in range(n_dn):
        rows.append((y, y - af, levels, levels))
        y -= af
    for k in range(levels - 1, -1, -1):  # transitions below: fine on top
        rows.append((y, y - a[k], k + 1, k))
        y -= a[k]
    y_fine_end = -h - fine_depth_factor * h
    n_fz = max(1, int(round((y - y_fine_end) / le))) if y - y_fine_end > 0.25 * le else 0
    if n_fz:
        hz = (y - y_fine_end) / n_fz
        for _ in range(n_fz):
            rows.append((y, y - hz, 0, 0))
            y -= hz
    depth_rest = height_factor * h + y
    if depth_rest > 0.25 * le:
        for s in _graded(depth_rest, le * grading, grading):
            rows.append((y, y - s, 0, 0))
            y -= s
    y_bottom = y

    total = ahead + cut_length
    xc = _columns(h, le, total, ahead, grading)
    if (len(xc) - 1) % 2:  # transition templates need pairs of coarse columns
        xc = np.insert(xc, 1, 0.5 * (xc[0] + xc[1]))
    xl = [_subdivide(xc, k) for k in range(levels + 1)]

    nodes: list[tuple[float, float]] = []

    def line(yv: float, lev: int) -> np.ndarray:
        ids = np.arange(len(nodes), len(nodes) + xl[lev].size)
        nodes.extend((float(xv), yv) for xv in xl[lev])
        return ids

    conn: list[tuple[int, int, int, int]] = []

    # build bottom -> top so elements and nodes run row by row upwards
    rows_up = rows[::-1]
    lower = line(rows_up[0][1], rows_up[0][3])
    for (yt, yb, lt, lb) in rows_up:
        upper = line(yt, lt)
        if lt == lb:
            for i in range(lower.size - 1):
                conn.append((lower[i], lower[i + 1], upper[i + 1], upper[i]))
        else:
            # the template is counter-clockwise with the fine line below; mirrored (fine
            # line above) its quads run clockwise and are reversed
            fine_below = lb > lt
            fine, coarse = (lower, upper) if fine_below else (upper, lower)
            ym = 0.5 * (yt + yb)
            xf = xl[max(lt, lb)]
            mid = -np.ones(xf.size, dtype=np.int64)
            for i in range(xf.size):
                if i % 4:
                    mid[i] = len(nodes)
                    nodes.append((float(xf[i]), ym))
            for p in range(coarse.size // 2):
                b = fine[4 * p:4 * p + 5]
                t = coarse[2 * p:2 * p + 3]
                m = mid[4 * p:4 * p + 5]
                for q in ((b[0], b[1], m[1], t[0]), (b[1], b[2], m[2], m[1]),
                          (b[2], b[3], m[3], m[2]), (b[3], b[4], t[2], m[3]),
                          (m[1], m[2], t[1], t[0]), (m[2], m[3], t[2], t[1])):
                    conn.append(q if fine_below else (q[0], q[3], q[2], q[1]))
        lower = upper
    xy = np.array(nodes)
    conn_a = np.array(conn, dtype=np.int64)
    cy = xy[conn_a, 1].mean(axis=1)
    chip = cy > y_p
    # node splitting: the parting line's nodes (not the fixed one at x = 0); the chip
    # elements above take the new copies
    tol = 1e-6 * af
    on_line = np.where((np.abs(xy[:, 1] - y_p) < tol) & (xy[:, 0] > tol))[0]
    xy, twin = _split_nodes(xy, conn_a, on_line, np.where(chip)[0])
    return _finish(xy, conn_a, np.zeros(conn_a.shape[0], dtype=bool), chip, y_bottom,
                   total, h, le, y_p, twin)


def _split_nodes(nodes: np.ndarray, conn: np.ndarray, line: np.ndarray,
                 above: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Double the nodes ``line`` (copies appended in that order); the elements ``above``
    take the copies (``conn`` is changed in place). Returns the new node array and ``twin``
    (partner of each doubled node, -1 elsewhere)."""
    new_ids = nodes.shape[0] + np.arange(line.size)
    nodes = np.vstack([nodes, nodes[line]])
    remap = np.arange(nodes.shape[0])
    remap[line] = new_ids
    conn[above] = remap[conn[above]]
    twin = -np.ones(nodes.shape[0], dtype=np.int64)
    twin[line] = new_ids
    twin[new_ids] = line
    return nodes, twin


def _finish(nodes, conn, layer, chip, y_bottom, total, h, le, layer_top, twin) -> CuttingMesh:
    """Boundary flags and the node -> element CSR of a cutting mesh."""
    fixed = (np.abs(nodes[:, 0]) < 1e-15) | (np.abs(nodes[:, 1] - y_bottom) < 1e-15)
    surface = np.abs(nodes[:, 1]) < 1e-15
    n_nodes = nodes.shape[0]
    counts = np.bincount(conn.ravel(), minlength=n_nodes)
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    ptr[1:] = np.cumsum(counts)
    ne = np.empty(ptr[-1], dtype=np.int64)
    nc = np.empty(ptr[-1], dtype=np.int64)
    fill = ptr[:-1].copy()
    for el in range(conn.shape[0]):
        for k in range(4):
            n = conn[el, k]
            ne[fill[n]] = el
            nc[fill[n]] = k
            fill[n] += 1
    return CuttingMesh(nodes=nodes, conn=conn, layer=layer, chip=chip, fixed=fixed,
                       surface=surface, node_elems_ptr=ptr, node_elems=ne, node_corner=nc,
                       length=total, height=-y_bottom, y_cut=-h, element_size=le,
                       layer_top=layer_top, twin=twin)
