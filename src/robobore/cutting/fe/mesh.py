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


@dataclass(frozen=True)
class CuttingMesh:
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

    @property
    def n_nodes(self) -> int:
        return int(self.nodes.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.conn.shape[0])


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
    fine_start = max(0.0, ahead - 3.0 * h)
    n_fx = max(1, int(round((total - fine_start) / le)))
    x_fine = np.linspace(fine_start, total, n_fx + 1)
    if fine_start > 0.25 * le:
        xs = np.cumsum(_graded(fine_start, le * grading, grading))
        x_left = fine_start - xs
        x_left[-1] = 0.0
        xc = np.concatenate([x_left[::-1], x_fine])
    else:
        x_fine[0] = 0.0
        xc = x_fine
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
        # double the parting-line nodes (not the fixed one at x = 0): the elements of the
        # row above (the chip's bottom row) take the new copies
        jrow = n_ey - n_chip  # node row of the parting line
        row_nodes = jrow * nxn + np.arange(1, nxn)
        n_old = nodes.shape[0]
        new_ids = n_old + np.arange(row_nodes.size)
        nodes = np.vstack([nodes, nodes[row_nodes]])
        remap = np.arange(nodes.shape[0])
        remap[row_nodes] = new_ids
        above = np.arange(jrow * n_ex, (jrow + 1) * n_ex)  # element row jrow (above line)
        conn[above] = remap[conn[above]]
        twin = -np.ones(nodes.shape[0], dtype=np.int64)
        twin[row_nodes] = new_ids
        twin[new_ids] = row_nodes
    fixed = (np.abs(nodes[:, 0]) < 1e-15) | (np.abs(nodes[:, 1] - yc[0]) < 1e-15)
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
                       length=total, height=-yc[0], y_cut=-h, element_size=le,
                       layer_top=top_chip, twin=twin)
