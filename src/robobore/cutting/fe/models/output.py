"""Results of an FE cutting run: steady-state values, chip geometry, Dataset, VTK, PNG.

Forces are on the tool, per unit width, reported in N/mm (cutting force Fc along the
cutting speed, feed force Ff normal to the machined surface, both positive when the
workpiece pushes the tool back / up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.models.results import OrthogonalSummary


@dataclass(frozen=True)
class ChipGeometry:
    """Chip thickness [m] measured on the deformed chip and the derived quantities."""

    thickness: float
    uncut_thickness: float
    ratio: float
    shear_angle_deg: float
    n_points: int


def shear_angle_deg(chip_ratio: float, rake_rad: float) -> float:
    """Merchant shear angle tan(phi) = cos(rake) / (r_c - sin(rake)), in degrees."""
    return math.degrees(math.atan2(math.cos(rake_rad), chip_ratio - math.sin(rake_rad)))


def point_polyline_distance(px: np.ndarray, py: np.ndarray, lx: np.ndarray,
                            ly: np.ndarray) -> np.ndarray:
    """Distance of each point to the polyline through (lx, ly) (ordered): the chip thickness
    of both mesh frames (:func:`measure_chip` and ``toolframe.measure_chip_toolframe``)."""
    ax, ay = lx[:-1], ly[:-1]
    bx, by = lx[1:], ly[1:]
    dx, dy = bx - ax, by - ay
    ll = np.maximum(dx * dx + dy * dy, 1e-300)
    t = np.clip(((px[:, None] - ax) * dx + (py[:, None] - ay) * dy) / ll, 0.0, 1.0)
    qx = ax + t * dx
    qy = ay + t * dy
    d = np.hypot(px[:, None] - qx, py[:, None] - qy)
    return d.min(axis=1)


def _passed_chip(st, mesh) -> tuple[float, float, np.ndarray]:
    """Tool edge centre (x, y) and the live nodes of chip-layer material the tool has passed
    (with node splitting without the work's copies of the parting line)."""
    le = mesh.element_size
    cx = st.tool[layout.T_GX] + st.tool[layout.T_UX]
    cy = st.tool[layout.T_GY] + st.tool[layout.T_UY]
    passed = ~st.ndead & (st.x0 > cx) & (st.y0 > mesh.layer_top - 1e-3 * le)
    if mesh.twin is not None:  # node splitting: the lower copies stay with the work
        passed &= ~((mesh.twin >= 0) & ~mesh.upper)
    return cx, cy, passed


def measure_chip(st, mesh, h: float, rake: float, vc: float) -> ChipGeometry:
    """Chip thickness from the deformed mesh.

    The chip is the material of the chip layer (rows above the separation layer) that has
    passed the tool. Outer surface: nodes that started on the free surface (y0 = 0). Inner
    surface: with node splitting, the chip's copies of the parting-line nodes (a material
    line: it stays the underside where fine elements next to it were eroded); with the
    erosion layer, in every original node column the lowest node still attached to a live
    element (the chip underside after the separation layer -- and any chip element
    deleted by time-step erosion -- is gone). Only formed chip is used: above the free
    surface by more than h and at least 1.5 h along the rake from the edge. For each outer
    node, thickness = distance to the inner polyline, and the ratio divides it by the
    original thickness of the surviving material of that column (0 - y0 of the inner node);
    the reported ratio is the median. With node splitting (no material lost) the ratio is
    the experimental one, chip thickness / uncut chip thickness h.
    """
    le = mesh.element_size
    x, y = st.x, st.y
    cx, cy, passed = _passed_chip(st, mesh)
    trx, try_ = math.sin(rake), math.cos(rake)
    s_along = (x - cx) * trx + (y - cy) * try_
    split = mesh.twin is not None
    formed = passed & (y > h) & (s_along > 1.5 * h)
    outer = formed & (np.abs(st.y0) < 1e-3 * le)
    h_chip0 = -mesh.layer_top
    nan = ChipGeometry(math.nan, h_chip0, math.nan, math.nan, int(outer.sum()))
    if outer.sum() < 2:
        return nan
    ix, iy, iy0, kept = [], [], [], []
    if split:
        # inner surface: the chip's copies of the parting-line nodes (a material line, so
        # the underside even where fine elements next to it were eroded), in material order
        line = np.where(passed & (mesh.twin >= 0) & mesh.upper)[0]
        line = line[np.argsort(st.x0[line], kind="stable")]
        ix, iy, iy0, kept = list(x[line]), list(y[line]), list(st.y0[line]), list(st.x0[line])
    else:
        # inner surface: lowest live node of each passed column
        for c in np.unique(st.x0[passed]):
            sel = np.where(passed & (np.abs(st.x0 - c) < 1e-3 * le))[0]
            j = sel[np.argmin(st.y0[sel])]
            if st.y0[j] < -0.5 * le:
                ix.append(x[j])
                iy.append(y[j])
                iy0.append(st.y0[j])
                kept.append(c)
    if len(ix) < 2:
        return nan
    lx, ly, ly0 = np.array(ix), np.array(iy), np.array(iy0)
    d = point_polyline_distance(x[outer], y[outer], lx, ly)
    # original thickness of the surviving material near each outer node's column
    near = np.argmin(np.abs(st.x0[outer][:, None] - np.array(kept)[None, :]), axis=1)
    t0 = -ly0[near]
    # node splitting loses no material: the ratio is the measured one, chip thickness / h
    ratios = d / h if split else d / t0
    tc = float(np.median(d))
    ratio = float(np.median(ratios))
    return ChipGeometry(tc, float(np.median(t0)), ratio, shear_angle_deg(ratio, rake),
                        int(outer.sum()))


def chip_ratio_from_velocity(st, mesh, h: float, rake: float, vc: float) -> tuple[float, int]:
    """Chip ratio from the chip's speed along the rake face: r = vc / v_chip.

    Plane-strain continuity in the tool's frame (h vc = t_c v_chip; Merchant 1945) gives the
    chip thickness ratio from the speed of the chip relative to the tool. The sample: live
    chip nodes (material of the chip layer that has passed the tool) between h and 3 h along
    the rake face from the edge centre and within 4 h of the rake line, where the chip has
    formed and still slides on or leaves the rake; their speeds relative to the tool,
    averaged with the nodal masses (so over the chip's cross-section, as continuity
    needs). Valid for a chip in steady flow only: a chip still thickening (upsetting)
    moves slower than continuity says. Needs the node velocities (``st.vx``, ``st.vy``, at
    step n - 1/2), masses and the tool velocity (guide speed -vc plus the support's
    ``T_VUX``, ``T_VUY``). Unlike the
    thickness measured on the deformed chip it does not need the chip's underside, which the
    distortion erosion at the edge takes away. Returns (ratio, number of nodes); NaN when
    fewer than 3 nodes qualify.
    """
    le = mesh.element_size
    cx, cy, chip = _passed_chip(st, mesh)
    tvx = -vc + st.tool[layout.T_VUX]
    tvy = st.tool[layout.T_VUY]
    trx, try_ = math.sin(rake), math.cos(rake)  # along the rake face, away from the edge
    nrx, nry = -math.cos(rake), math.sin(rake)  # rake normal, into the chip
    s_along = (st.x - cx) * trx + (st.y - cy) * try_
    s_norm = (st.x - cx) * nrx + (st.y - cy) * nry
    sel = chip & (s_along >= h) & (s_along <= 3.0 * h) & (s_norm >= -0.5 * le) \
        & (s_norm <= 4.0 * h)
    n = int(sel.sum())
    if n < 3:
        return math.nan, n
    v = np.hypot(st.vx[sel] - tvx, st.vy[sel] - tvy)
    # mass-weighted: the edge band's nodes are 16x denser than the chip's and sit in the
    # slow secondary shear zone; a plain median of node speeds would follow them
    vm = float(np.average(v, weights=st.mass[sel]))
    return (vc / vm if vm > 0.0 else math.nan), n


@dataclass(frozen=True)
class FEResult:
    """Outcome of an orthogonal-cutting run (SI inside; summary fields in human units)."""

    #: the run's figures (:class:`robobore.cutting.fe.models.results.OrthogonalSummary`)
    summary: OrthogonalSummary
    #: arrays over the samples, named with their unit (``time_s``, ``cutting_force_N_per_mm``...)
    history: dict[str, np.ndarray]
    #: the full config after defaults (``FEConfig.model_dump()``)
    config: dict[str, Any]
    #: the final mesh and fields (coordinates, connectivity, element fields, the tool outline)
    final: dict[str, np.ndarray] = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        """The summary's JSON (the keys ``robobore fe orthogonal --json`` writes)."""
        return self.summary.to_dict()


def steady_window(t: np.ndarray, t_start: float, t_end: float) -> np.ndarray:
    """Boolean mask of the samples inside [t_start, t_end]."""
    return (t >= t_start) & (t <= t_end)


def to_dataset(res: FEResult):
    """xarray Dataset: histories on the ``time`` axis, summary values as attributes."""
    import xarray as xr

    hist = res.history
    t = hist["time_s"]
    units = {
        "cutting_force_N_per_mm": "N/mm", "feed_force_N_per_mm": "N/mm",
        "tool_dx_um": "um", "tool_dy_um": "um", "tool_tip_x_mm": "mm",
        "energy_external_J_per_m": "J/m", "energy_kinetic_J_per_m": "J/m",
        "energy_internal_J_per_m": "J/m", "energy_plastic_J_per_m": "J/m",
        "energy_hourglass_J_per_m": "J/m", "energy_contact_J_per_m": "J/m",
        "energy_eroded_J_per_m": "J/m", "contact_nodes": "1",
    }
    for face in layout.FACES:
        units[f"{face}_cutting_force_N_per_mm"] = units[f"{face}_feed_force_N_per_mm"] = "N/mm"
    data = {k: ("time", np.asarray(v), {"units": units.get(k, "")})
            for k, v in hist.items() if k != "time_s"}
    ds = xr.Dataset(data, coords={"time": ("time", t, {"units": "s"})})
    summary = res.summary.to_dict()
    for k, v in summary.items():
        if isinstance(v, bool):
            ds.attrs[k] = int(v)
        elif isinstance(v, int | float | str):
            ds.attrs[k] = v
    for face, f in summary.get("force_by_face_N_per_mm", {}).items():
        for comp, val in f.items():
            ds.attrs[f"{face}_{comp}_force_N_per_mm"] = val
    return ds


def write_vtk(res: FEResult, path: str | Path) -> Path:
    """Deformed mesh with element fields (VTK unstructured grid, via meshio)."""
    import meshio

    f = res.final
    live = f["alive"] == 1
    pts = np.column_stack([f["x"], f["y"], np.zeros_like(f["x"])])
    cells = [("quad", f["conn"][live])]
    cd = {k: [f[k][live]] for k in ("eps_p", "temperature_K", "damage", "von_mises_Pa",
                                     "pressure_Pa")}
    mesh = meshio.Mesh(pts, cells, cell_data=cd)
    from robobore.io.results import atomic_path

    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(p, suffix=".vtu") as tmp:  # atomic and durable
        mesh.write(tmp)
    return p


def plot_chip(res: FEResult, path: str | Path, field_name: str = "temperature_K",
              window_mm: float | None = None) -> Path:
    """PNG of the chip region coloured by an element field, with the tool outline."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    f = res.final
    live = f["alive"] == 1
    conn = f["conn"][live]
    verts = np.stack([f["x"][conn] * 1e3, f["y"][conn] * 1e3], axis=-1)
    vals = f[field_name][live]
    fig, ax = plt.subplots(figsize=(8, 5), dpi=120)
    pc = PolyCollection(verts, array=vals, cmap="inferno", edgecolors="face", linewidths=0.1)
    ax.add_collection(pc)
    fig.colorbar(pc, ax=ax, label=field_name)
    tx, ty = f["tool_outline"]
    ax.fill(tx * 1e3, ty * 1e3, color="0.6", alpha=0.8, lw=0.5, ec="k")
    cx = float(f["tool_center"][0]) * 1e3
    w = window_mm if window_mm is not None else 0.5
    h = float(res.summary.uncut_chip_thickness_um) * 1e-3
    ax.set_xlim(cx - 0.5 * w, cx + 0.5 * w)
    ax.set_ylim(-3.5 * h, 0.6 * w)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    s = res.summary
    ax.set_title(f"Fc = {s.cutting_force_N_per_mm:.1f} N/mm, "
                 f"Ff = {s.feed_force_N_per_mm:.1f} N/mm, chip ratio = "
                 f"{s.chip_ratio:.2f}")
    from robobore.io.results import save_figure

    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    save_figure(fig, p)  # atomic and durable
    plt.close(fig)
    return p


def tool_outline(cx: float, cy: float, r: float, rake: float, clearance: float,
                 size: float) -> tuple[np.ndarray, np.ndarray]:
    """Polygon of the tool (rake face, edge arc, flank) of extent ``size`` [m]."""
    nr = np.array([-math.cos(rake), math.sin(rake)])
    nf = np.array([math.sin(clearance), -math.cos(clearance)])
    a0 = math.atan2(nr[1], nr[0])
    a1 = math.atan2(nf[1], nf[0])
    if a1 < a0:  # the edge arc runs from the rake normal round the bottom to the flank normal
        a1 += 2 * math.pi
    ang = np.linspace(a0, a1, 30)
    arc = np.column_stack([cx + r * np.cos(ang), cy + r * np.sin(ang)])
    tr = np.array([nr[1], -nr[0]])
    tf = np.array([-nf[1], nf[0]])
    top = arc[0] + size * tr
    back = arc[-1] + size * tf
    corner = back + size * tr
    poly = np.vstack([top[None], arc, back[None], corner[None]])
    return poly[:, 0], poly[:, 1]
