"""The hexahedral mesh of the 3D FE boring model (:mod:`robobore.cutting.fe.models.boring3d`): a
locally flat block of the bore wall whose top surface carries the feed marks of the previous
revolution, with the separation layer along the insert's edge path and, for node splitting,
the parting surface and its twin nodes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robobore.cutting.fe.engine.state3d import hex_conn, split_node_layer
from robobore.cutting.fe.hex import scalar3d
from robobore.cutting.geometry import BoringInsert, lead_end

__all__ = ["BoringMesh", "parting_surface", "build_boring_mesh"]


@dataclass(frozen=True)
class BoringMesh:
    """Hexahedral mesh of the wall block. nodes (n, 3) [m], conn (e, 8), fixed (n,) bit mask."""

    nodes: np.ndarray
    conn: np.ndarray
    fixed: np.ndarray
    chip: np.ndarray  # (e,) bool: element centroid above the current edge profile
    layer: np.ndarray  # (e,) bool: separation layer (element crossed by the edge path)
    shape: tuple[int, int, int]
    z_range: tuple[float, float]
    length: float
    y_bottom: float
    #: node splitting: partner of each node on the parting surface (-1: none), else None
    twin: np.ndarray | None = None


def parting_surface(insert: BoringInsert, zs: np.ndarray, height: float,
                    y_low: float) -> np.ndarray:
    """Height y(z) [m] of the surface ``height`` [m] above the insert's edge profile.

    The offset is along the profile normal (in each normal section of the edge, the 2D
    engine's parting line ``height`` above the edge's lowest point): the points whose
    :func:`hex.scalar3d.edge_section` distance is ``re - height``. Solved by bisection in y on
    [y_low, nose radius] at each z of ``zs``.
    """
    rn, re = insert.nose_radius_m, insert.edge_radius_m
    kap = math.radians(insert.approach_angle_deg)
    kend = math.radians(insert.end_edge_angle_deg)
    target = re - height
    out = np.empty(zs.size)
    for i, z in enumerate(zs):
        lo, hi = y_low, rn * (1.0 - 1e-9)
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if scalar3d.edge_section(mid, float(z), rn, kap, kend, re)[0] > target:
                lo = mid
            else:
                hi = mid
        out[i] = 0.5 * (lo + hi)
    return out


def build_boring_mesh(insert: BoringInsert, ap: float, f: float, le: float, length: float,
                      depth_factor: float = 1.5, side_margin: float = 0.0,
                      ahead: float = 0.06e-3, split_height: float | None = None,
                      chip_rows: int = 0) -> BoringMesh:
    """Wall block with the previous revolution's feed marks on its top surface (SI).

    Without ``split_height`` every node column is divided uniformly from the bottom to the
    top surface and the separation layer (elements crossed by the edge path y = drop(z))
    is marked for damage erosion. With ``split_height`` [m] (node splitting) the node rows
    follow the parting surface (:func:`parting_surface`, ``split_height`` above the edge
    profile): ``chip_rows`` rows between it and the top surface, the rest below, and the
    nodes of the parting surface are doubled (``twin``; the chip's rows use the copies).
    Where the chip above the parting surface would be thinner than ``chip_rows`` x 0.25 le
    (its thin ends, where the 2D picture has almost only ploughing) the parting surface is
    lowered to keep that thickness, so no element is thinner than 0.25 le; there the edge
    path crosses chip rows, and the chip elements it crosses form an erosion layer (damage
    erosion, as without splitting).
    """
    z_end = lead_end(insert, ap)
    margin = side_margin if side_margin > 0 else 3 * le
    z0 = -0.5 * f - margin
    z1 = z_end + margin
    depth = max(depth_factor * ap, 4 * le)
    lx = length + ahead
    nx = max(2, int(math.ceil(lx / le)))
    nz = max(2, int(math.ceil((z1 - z0) / le)))
    xs = np.linspace(0.0, lx, nx + 1)
    zs = np.linspace(z0, z1, nz + 1)
    ytop = np.minimum(ap, insert.drop(zs + f))
    twin = None
    if split_height is None:
        ny = max(3, int(math.ceil((depth + ap) / le)))
        eta = np.linspace(0.0, 1.0, ny + 1)
        Y = -depth + (ytop[None, :] + depth) * eta[:, None]  # (ny + 1, nz + 1)
        js = -1
    else:
        ys0 = parting_surface(insert, zs, split_height, -depth)
        n_up = chip_rows if chip_rows > 0 else max(3, int(round(float(np.max(ytop - ys0)) / le)))
        ys = np.minimum(ys0, ytop - n_up * 0.25 * le)
        lowered = ys < ys0 - 1e-12 * le
        n_dn = max(3, int(math.ceil((depth + float(np.max(ys))) / le)))
        ny = n_dn + n_up
        js = n_dn
        e_dn = np.linspace(0.0, 1.0, n_dn + 1)[:, None]
        e_up = np.linspace(0.0, 1.0, n_up + 1)[1:, None]
        Y = np.vstack([-depth + (ys[None, :] + depth) * e_dn,
                       ys[None, :] + (ytop - ys)[None, :] * e_up])
    X = np.broadcast_to(xs[:, None, None], (nx + 1, ny + 1, nz + 1))
    Y = np.broadcast_to(Y[None, :, :], (nx + 1, ny + 1, nz + 1))
    Z = np.broadcast_to(zs[None, None, :], (nx + 1, ny + 1, nz + 1))
    nodes = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1).copy()
    idx = np.arange(nodes.shape[0]).reshape(nx + 1, ny + 1, nz + 1)
    # VTK order needs the (x, y, z) index grid to be right-handed: it is (x, y, z)
    fixed = np.zeros(nodes.shape[0], np.int64)
    fixed[idx[:, 0, :].ravel()] = 7
    fixed[idx[-1, :, :].ravel()] = 7
    fixed[idx[:, :, 0].ravel()] = 7
    fixed[idx[:, :, -1].ravel()] = 7
    conn = hex_conn(idx)
    if js > 0:
        # double the free nodes of the parting surface; the rows above take the copies
        nodes, conn, fixed, twin = split_node_layer(nodes, conn, fixed, idx, js)
    cen = nodes[conn].mean(axis=1)
    prof = insert.drop(cen[:, 2])
    chip = cen[:, 1] > prof
    ye = nodes[conn][:, :, 1]
    layer = (ye.min(axis=1) <= prof) & (ye.max(axis=1) >= prof)
    if js > 0:
        # where the parting surface had to be lowered the edge path crosses chip rows: those
        # elements erode by damage (the erosion layer), elsewhere the chip parts at the pairs
        _, erow, kz = np.unravel_index(np.arange(conn.shape[0]), (nx, ny, nz))
        layer &= (lowered[kz] | lowered[kz + 1]) & (erow >= js)
    return BoringMesh(nodes=nodes, conn=conn, fixed=fixed, chip=chip, layer=layer,
                      shape=(nx, ny, nz), z_range=(z0, z1), length=lx, y_bottom=-depth,
                      twin=twin)
