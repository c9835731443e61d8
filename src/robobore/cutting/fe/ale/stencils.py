"""Host-side stencils of the rezoning passes (:mod:`robobore.cutting.fe.ale.rezone`): the chip
nodes smoothed by ``MODE_LAPLACE`` and their neighbours (:func:`smoothing_stencil`), the
ploughed-layer nodes of ``MODE_ROWS`` (:func:`row_stencil`), and the element neighbours
across each edge that the remap needs (:func:`edge_neighbours`).
"""

from __future__ import annotations

import numpy as np


def smoothing_stencil(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Interior chip-layer nodes of a structured cutting mesh and their 4 neighbours.

    Returns ``nodes`` (k,) and ``nbr`` (k, 6) node indices (the 4 neighbours, then -1, -1:
    the layout of :func:`row_stencil`).
    """
    conn = mesh.conn
    # structured grid sizes from the node coordinates of row 0
    xs0 = mesh.nodes[:, 0]
    ys0 = mesh.nodes[:, 1]
    ny_nodes = len(np.unique(ys0))
    nx_nodes = mesh.n_nodes // ny_nodes
    assert nx_nodes * ny_nodes == mesh.n_nodes
    del conn, xs0
    yrows = ys0.reshape(ny_nodes, nx_nodes)[:, 0]
    # chip underside row: top of the separation layer; surface row: top
    under = int(np.argmin(np.abs(yrows - mesh.layer_top)))
    top = ny_nodes - 1
    nodes = []
    nbr = []
    for j in range(under + 1, top):
        for i in range(1, nx_nodes - 1):
            n = j * nx_nodes + i
            nodes.append(n)
            nbr.append((n - 1, n + 1, n - nx_nodes, n + nx_nodes, -1, -1))
    return np.array(nodes, dtype=np.int64), np.array(nbr, dtype=np.int64).reshape(-1, 6)


def row_stencil(mesh, depth: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes of the ploughed layer of a node-splitting mesh for ``MODE_ROWS``.

    The node rows (equal initial y) from the parting line (its workpiece-side copies) down
    to, but not including, ``depth`` [m] below it; in each row, the nodes whose left and
    right neighbours (by initial x) are joined to them by element edges. Fixed nodes are
    left out. Returns ``nodes`` (k,) and ``nbr`` (k, 6) = (left, right, parting-line node
    of the same column, node of the same column at ``depth`` (-1: none, or the node is on
    the parting line), node above, node below in the column (-1: none)); a node moves only
    once its parting-line node is released.
    """
    if mesh.twin is None:
        raise ValueError("row_stencil needs a node-splitting mesh (twin)")
    xy = mesh.nodes
    y_p = mesh.layer_top
    tol = 1e-6 * mesh.element_size
    idx = np.arange(mesh.n_nodes)
    upper = (mesh.twin >= 0) & (mesh.twin < idx)
    below = (xy[:, 1] <= y_p + tol) & (xy[:, 1] > y_p - depth - tol)
    cand = np.where(~upper & below)[0]
    edges: set[tuple[int, int]] = set()
    for el in mesh.conn:
        for k in range(4):
            a, b = int(el[k]), int(el[(k + 1) % 4])
            edges.add((a, b) if a < b else (b, a))

    def joined(a: int, b: int) -> bool:
        return (min(a, b), max(a, b)) in edges

    rkey = np.round((y_p - xy[cand, 1]) / tol).astype(np.int64)
    xkey = np.round(xy[cand, 0] / tol).astype(np.int64)
    at = {(int(r), int(c)): int(n) for r, c, n in zip(rkey, xkey, cand, strict=True)}
    rows = np.unique(rkey)
    bottom_key = int(np.round(depth / tol))
    nodes: list[int] = []
    nbr: list[tuple[int, int, int, int, int, int]] = []
    for j, key in enumerate(rows):
        if key >= bottom_key:
            break
        row = cand[rkey == key]
        row = row[np.argsort(xy[row, 0])]
        for i in range(1, row.size - 1):
            n, lft, rgt = int(row[i]), int(row[i - 1]), int(row[i + 1])
            if mesh.fixed[n] or not (joined(lft, n) and joined(n, rgt)):
                continue
            c = int(np.round(xy[n, 0] / tol))
            pc = at.get((int(rows[0]), c), -1)
            if pc < 0:
                continue
            up = at.get((int(rows[j - 1]), c), -1) if j > 0 else -1
            dn = at.get((int(rows[j + 1]), c), -1) if j + 1 < rows.size else -1
            bt = at.get((bottom_key, c), -1) if j > 0 else -1
            if up >= 0 and not joined(up, n):
                up = -1
            if dn >= 0 and not joined(n, dn):
                dn = -1
            if bt >= 0 and (up < 0 or dn < 0):
                bt = -1
            nodes.append(n)
            nbr.append((lft, rgt, pc, bt, up, dn))
    return np.array(nodes, dtype=np.int64), np.array(nbr, dtype=np.int64).reshape(-1, 6)


def edge_neighbours(conn: np.ndarray) -> np.ndarray:
    """(n_elem, 4): element across edge k (nodes k -> k+1), -1 on the boundary."""
    ne = conn.shape[0]
    out = -np.ones((ne, 4), dtype=np.int64)
    seen: dict[tuple[int, int], tuple[int, int]] = {}
    for e in range(ne):
        for k in range(4):
            a, b = int(conn[e, k]), int(conn[e, (k + 1) % 4])
            key = (a, b) if a < b else (b, a)
            if key in seen:
                e2, k2 = seen.pop(key)
                out[e, k] = e2
                out[e2, k2] = e
            else:
                seen[key] = (e, k)
    return out
