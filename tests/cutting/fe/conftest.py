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


def edge_band_dict(**sections) -> dict:
    """A short cut on the edge-refined mesh (node splitting 5 um, 5 um band, h 30 um,
    0.04 mm), as a fresh dict; ``sections`` (e.g. ``mesh={...}``) update its tables."""
    d = {
        "parameters": "a_priori",
        "material": {"name": "TC4"},
        "tool": {"rake_deg": 7.0, "clearance_deg": 7.0, "edge_radius_um": 20.0},
        "cut": {"uncut_chip_thickness_um": 30.0, "cutting_speed_m_per_min": 37.7,
                "length_mm": 0.04, "width_mm": 1.0},
        "contact": {"friction": 0.2},
        "mesh": {"frame": "workpiece", "element_size_um": 10.0, "separation": "node_split",
                 "separation_height_um": 5.0, "edge_element_um": 5.0},
        "solver": {"mass_scaling": 100.0, "heat_conduction": False},
    }
    for sec, kv in sections.items():
        d[sec].update(kv)
    return d
