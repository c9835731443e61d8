from __future__ import annotations

import numpy as np

from robobore.material import Material, load_material


def elastic_tc4() -> Material:
    """TC4 elastic constants with a yield stress so high it never yields."""
    d = load_material("TC4").to_dict()
    d.update(A=1e15, B=0.0)
    return Material.from_dict(d)


def strip_mesh(nx: int, ny: int, lx: float, ly: float):
    """Rectangular structured quad mesh, nodes counter-clockwise; returns nodes, conn."""
    xs = np.linspace(0.0, lx, nx + 1)
    ys = np.linspace(0.0, ly, ny + 1)
    X, Y = np.meshgrid(xs, ys)
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    conn = []
    for j in range(ny):
        for i in range(nx):
            n1 = j * (nx + 1) + i
            conn.append((n1, n1 + 1, n1 + nx + 2, n1 + nx + 1))
    return nodes, np.array(conn, dtype=np.int64)
