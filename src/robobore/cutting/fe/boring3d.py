"""The paper's equivalent 3D FE boring model: an insert with nose radius cutting the bore wall.

Model (all choices documented in ``docs/fe3d.md``):

* **Workpiece** -- a block of the bore wall, *locally flat* (the wall unrolled): for a bore
  diameter D >> the chip (D = 40 mm vs a 0.3 mm cut length: sagitta L^2 / (4 D) ~ 0.6 um, 1 %
  of ap = 50 um) the curvature is negligible. Local frame: x along the cutting velocity of
  the insert (tangent to the circle, e_t), y normal to the wall pointing out of the material
  (towards the bore axis, -e_r), z along the feed (bore axis, e_z). The top surface carries
  the **feed marks of the previous revolution**: ``y_top(z) = min(ap, drop(z + f))`` with
  ``drop`` the insert's edge profile (:meth:`robobore.cutting.geometry.BoringInsert.drop`),
  so the material above the current edge profile ``drop(z)`` is exactly the boring chip of
  the mechanistic model (area ``ap f - scallop``). The new bore surface is y = 0.
* **Insert** -- rigid, analytic signed distance (:func:`kernels3d.insert_gap3_py`): nose
  radius, approach and end-edge angles, normal rake, clearance, edge radius, inclination.
  It moves along +x at the cutting speed ``vc = pi D n`` and along +z at the feed speed
  ``f n``; the bar angle advances as ``theta = theta0 + vc t / R``.
* **Tool support** -- three spring-mass-damper units along the boring frame X (horizontal),
  Y (vertical), Z (feed) (the equivalent model of the paper), optionally stiffened by the
  pressure foot; the tool force is rotated into that frame with theta.
* **Forces** -- the force ON THE TOOL. Rotating frame: ``tangential`` = component against the
  cutting velocity (positive), ``radial`` (positive outwards, e_r), ``feed`` (along +Z);
  these are the quantities of :func:`robobore.cutting.forces.element_forces`. Boring frame:
  ``F = -Ft e_t(theta) + Fr e_r(theta) + Fz e_z`` (:func:`robobore.cutting.forces.
  rotating_to_boring`, e_t = (-sin theta, cos theta, 0)). The FE run covers a short arc, so
  the per-revolution X/Y mean and amplitude are those of the steady rotating-frame forces
  carried round the revolution (stable boring: the paper's Fig. 7 shows sinusoidal X, Y and a
  flat Z).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from robobore.cutting.fe import kernels3d as K3
from robobore.cutting.fe.config import ContactSection as ContactSection2D
from robobore.cutting.fe.config import MaterialSection, apply_parameter_set
from robobore.cutting.fe.solver import (
    apply_friction_settings,
    apply_solver_settings,
    apply_thermal_settings,
)
from robobore.cutting.fe.solver3d import (
    FEState3,
    advance3,
    default_prm3,
    energy_error,
    hex_conn,
    make_state3,
    split_node_layer,
)
from robobore.cutting.geometry import BoringInsert, chip_area, lead_end
from robobore.errors import ConfigError, NumericalError
from robobore.io.config import load_toml, validate_model
from robobore.material import Material, load_material
from robobore.material.library import resolve_material_name

__all__ = ["BoringFEConfig", "load_boring_config", "parse_boring_config", "BoringMesh",
           "build_boring_mesh", "BoringSetup", "setup_boring", "simulate_boring",
           "BoringFEResult", "compare_with_mechanistic", "write_vtk"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class InsertSection(_Strict):
    """Insert geometry (defaults: a CCMT 060204-type insert in a 90-deg boring bar)."""

    nose_radius_mm: float = Field(default=0.4, gt=0.0, le=5.0)
    approach_angle_deg: float = Field(default=90.0, gt=0.0, le=90.0)
    end_edge_angle_deg: float = Field(default=5.0, gt=0.0, le=60.0)
    rake_deg: float = Field(default=7.0, ge=-30.0, le=30.0)
    clearance_deg: float = Field(default=7.0, gt=0.0, le=30.0)
    edge_radius_um: float = Field(default=20.0, ge=0.0, le=200.0)
    inclination_deg: float = Field(default=0.0, ge=-15.0, le=15.0)

    def to_insert(self) -> BoringInsert:
        return BoringInsert(nose_radius_m=self.nose_radius_mm * 1e-3,
                            approach_angle_deg=self.approach_angle_deg,
                            end_edge_angle_deg=self.end_edge_angle_deg, rake_deg=self.rake_deg,
                            inclination_deg=self.inclination_deg,
                            clearance_deg=self.clearance_deg,
                            edge_radius_m=self.edge_radius_um * 1e-6)


class CutSection(_Strict):
    depth_of_cut_mm: float = Field(gt=0.0, le=2.0, description="radial depth ap, mm")
    feed_mm_per_rev: float = Field(gt=0.0, le=2.0)
    speed_rpm: float = Field(gt=0.0, le=20000.0)
    #: bore diameter after the pass [mm] (an assumption where the paper gives none)
    bore_diameter_mm: float = Field(default=40.0, gt=1.0, le=2000.0)
    #: length of cut along the wall simulated [mm]
    cut_length_mm: float = Field(default=0.3, gt=0.0, le=20.0)


#: keys of the 2D engine's [contact] that the 3D model does not use: its contact law has no
#: normal damping
_CONTACT_2D_ONLY = ("normal_damping",)


class ContactSection(ContactSection2D):
    """The 2D engine's ``[contact]`` (:class:`robobore.cutting.fe.config.ContactSection`):
    the same friction keys, values and defaults -- ``friction`` a bundled friction law
    (default ``rech2013_calibrated``: the Rech et al. 2013 table x 1.5 read at each contact
    node's filtered sliding speed, no shear cap), "table" or a constant Coulomb coefficient;
    ``friction_velocity``, ``friction_table_*``, ``sliding_filter_um``, ``shear_limit_MPa``,
    ``penalty_factor`` and the thermal contact (``thermal_conductance_W_per_m2K``,
    ``friction_heat_fraction``, ``tool_temperature_K``, used with ``solver.heat_conduction``)
    -- without ``normal_damping`` (the 3D contact has no normal damping)."""

    @model_validator(mode="after")
    def _no_2d_only(self) -> ContactSection:
        bad = sorted(set(_CONTACT_2D_ONLY) & self.model_fields_set)
        if bad:
            raise ValueError(f"{', '.join(bad)}: not used by the 3D boring model (its contact "
                             "has no normal damping); remove the key")
        return self


class MeshSection(_Strict):
    #: element size [um]; at most ap / 3 (3 elements through the chip's depth)
    element_size_um: float = Field(gt=0.0)
    #: material below the new bore surface, in depths of cut (>= 4 elements is enforced)
    depth_factor: float = Field(default=1.5, ge=0.5, le=20.0)
    #: material beyond the chip on each side along the feed axis [um] (0 = 3 elements)
    side_margin_um: float = Field(default=0.0, ge=0.0)
    #: uncut material left ahead of the insert at the end of the cut [mm]
    ahead_mm: float = Field(default=0.06, gt=0.0, le=5.0)
    #: how the chip separates from the workpiece: "erosion_layer" (elements crossed by the
    #: edge path erode by Johnson-Cook damage) or "node_split" (the nodes of a parting
    #: surface are doubled and tied, and part where they reach the insert: the 2D engine's
    #: method, used by the FE calibration of the mechanistic coefficients; with the 2-4
    #: elements through the boring chip that 3D affords on a CPU it gave larger forces than
    #: the layer, docs/fe3d.md)
    separation: Literal["node_split", "erosion_layer"] = "erosion_layer"
    #: node splitting: height of the parting surface above the edge's lowest points,
    #: along the profile normal [um] (the 2D calibration's 5 um = 0.25 edge radii)
    separation_height_um: float = Field(default=5.0, ge=0.0)
    #: node splitting: element rows of the chip above the parting surface (0 = about one
    #: per element size of the thickest chip section, at least 3)
    chip_rows: int = Field(default=0, ge=0, le=50)


class SolverSection(_Strict):
    mass_scaling: float = Field(default=100.0, ge=1.0, le=1e6)
    cfl: float = Field(default=0.8, gt=0.0, le=1.0)
    hourglass_viscous: float = Field(default=0.05, ge=0.0, le=0.5)
    hourglass_stiffness: float = Field(default=0.05, ge=0.0, le=0.5)
    bulk_viscosity_linear: float = Field(default=0.06, ge=0.0, le=1.0)
    bulk_viscosity_quadratic: float = Field(default=1.2, ge=0.0, le=4.0)
    #: erosion of elements whose Johnson-Cook damage reaches 1: "layer" (only in the
    #: separation layer, the elements crossed by the path of the cutting edge), "everywhere"
    #: or "none"
    erosion: Literal["layer", "everywhere", "none"] = "layer"
    #: erode an element whose volume ratio V/V0 falls below this (0 disables)
    distortion_limit: float = Field(default=0.05, ge=0.0, lt=1.0)
    #: erode an element whose stable step falls below this fraction of the initial one
    erode_time_step_fraction: float = Field(default=0.3, ge=0.0, lt=1.0)
    n_samples: int = Field(default=200, ge=10, le=100000)
    chunk_steps: int = Field(default=500, ge=10, le=10**7)
    #: fraction of the cut (from its end) averaged for the steady-state values
    steady_window_fraction: float = Field(default=0.5, gt=0.0, le=1.0)
    #: stop with NumericalError when the energy error exceeds this after 10 % of the cut
    energy_error_limit: float = Field(default=0.5, gt=0.0)
    #: node splitting: a tied pair parts within this distance of the insert [um]
    separation_gate_um: float = Field(default=0.0, ge=0.0)
    #: heat conduction between the workpiece's elements and the thermal contact with the
    #: insert (the 2D engine's model, :mod:`robobore.cutting.fe.thermal3d`), every
    #: ``conduction_interval`` steps; false: adiabatic
    heat_conduction: bool = True
    conduction_interval: int = Field(default=10, ge=1, le=10000)


def _triple(v: Any) -> list[float]:
    vals = [v, v, v] if isinstance(v, float | int) else list(v)
    if len(vals) != 3:
        raise ValueError("give one value or [X, Y, Z]")
    return [float(x) for x in vals]


class ToolSupportSection(_Strict):
    """Equivalent 3-direction model: per boring-frame axis X, Y, Z (one value or [X, Y, Z])."""

    stiffness_N_per_m: list[float]
    damping_N_s_per_m: list[float]
    mass_kg: list[float]
    #: extra stiffness of the pressure foot per axis [N/m] (0 = no foot)
    pressure_foot_N_per_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    #: bar angle at the start of the run [deg] (from X towards Y)
    theta0_deg: float = 0.0

    @field_validator("stiffness_N_per_m", "damping_N_s_per_m", "mass_kg",
                     "pressure_foot_N_per_m", mode="before")
    @classmethod
    def _t(cls, v: Any) -> Any:
        return _triple(v)

    @model_validator(mode="after")
    def _pos(self) -> ToolSupportSection:
        for name in ("stiffness_N_per_m", "damping_N_s_per_m", "pressure_foot_N_per_m"):
            if any(x < 0 for x in getattr(self, name)):
                raise ValueError(f"{name} must be >= 0")
        if any(m <= 0 for m in self.mass_kg):
            raise ValueError("mass_kg must be > 0")
        return self

    def total_stiffness(self) -> list[float]:
        return [a + b for a, b in zip(self.stiffness_N_per_m, self.pressure_foot_N_per_m,
                                      strict=True)]


class BoringFEConfig(_Strict):
    #: the 2D engine's switch (:class:`robobore.cutting.fe.config.FEConfig`): "calibrated"
    #: (default) -- friction law "rech2013_calibrated" and the material file's hardening
    #: hold (TC4: plastic strain 0.6), the validated 2D model's CALIBRATED choices;
    #: "a_priori" -- friction law "rech2013" and the plain Johnson-Cook law. Explicit
    #: contact.friction and material.hardening_strain_limit keys win over either
    parameters: Literal["calibrated", "a_priori"] = "calibrated"
    material: MaterialSection = MaterialSection()
    insert: InsertSection = InsertSection()
    cut: CutSection
    contact: ContactSection = ContactSection()
    mesh: MeshSection
    solver: SolverSection = SolverSection()
    tool_support: ToolSupportSection | None = None

    @model_validator(mode="before")
    @classmethod
    def _parameter_set(cls, data: Any) -> Any:
        # the 2D config's rule: the friction law and hardening of ``parameters`` where the
        # keys are not given
        return apply_parameter_set(data) if isinstance(data, dict) else data

    def friction_law(self) -> str:
        """The friction law in words (:meth:`ContactSection.law_description`)."""
        return self.contact.law_description()


def parse_boring_config(data: dict[str, Any], source: str | None = None) -> BoringFEConfig:
    """Validate a config dict (from TOML) and the cross-field rules."""
    cfg = validate_model(BoringFEConfig, data, source=source)
    cfg.material.name = resolve_material_name(cfg.material.name, source)  # config-relative
    load_material(cfg.material.name, source=source)  # read and checked at load, not at run
    ap_um = cfg.cut.depth_of_cut_mm * 1e3
    le = cfg.mesh.element_size_um
    if le > ap_um / 3.0 + 1e-9:
        raise ConfigError("element too large for the depth of cut", file=source,
                          field="mesh.element_size_um", value=le,
                          expected=f"at most cut.depth_of_cut_mm/3 = {ap_um / 3.0:.4g} um")
    if cfg.insert.edge_radius_um >= cfg.insert.nose_radius_mm * 1e3:
        raise ConfigError("edge radius not smaller than the nose radius", file=source,
                          field="insert.edge_radius_um", value=cfg.insert.edge_radius_um,
                          expected=f"< {cfg.insert.nose_radius_mm * 1e3:g} um")
    if cfg.cut.bore_diameter_mm < 20 * cfg.cut.cut_length_mm:
        raise ConfigError("bore too small for the locally flat wall model", file=source,
                          field="cut.bore_diameter_mm", value=cfg.cut.bore_diameter_mm,
                          expected=f">= 20 x cut.cut_length_mm = "
                          f"{20 * cfg.cut.cut_length_mm:g} mm")
    from robobore.io.memory import check_fe3d

    check_fe3d(cfg, source)  # refuse a mesh that cannot fit in memory, before meshing
    return cfg


def load_boring_config(path: str | Path) -> BoringFEConfig:
    """Read and validate a boring FE config file (TOML)."""
    return parse_boring_config(load_toml(path), source=str(path))


# ------------------------------------------------------------------------------------ mesh
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
    :func:`kernels3d.edge_section` distance is ``re - height``. Solved by bisection in y on
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
            if K3.edge_section(mid, float(z), rn, kap, kend, re)[0] > target:
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


# ---------------------------------------------------------------------------------- setup
@dataclass
class BoringSetup:
    cfg: BoringFEConfig
    material: Material
    insert: BoringInsert
    mesh: BoringMesh
    state: FEState3
    ap: float
    f: float
    vc: float
    t_end: float
    t_contact: float


def setup_boring(cfg: BoringFEConfig, source: str | None = None) -> BoringSetup:
    """Mesh, insert, support and state for ``cfg``."""
    mat = load_material(cfg.material.name, source=source,
                        hardening_strain_limit=cfg.material.strain_limit())
    ins = cfg.insert.to_insert()
    ap = cfg.cut.depth_of_cut_mm * 1e-3
    f = cfg.cut.feed_mm_per_rev * 1e-3
    le = cfg.mesh.element_size_um * 1e-6
    L = cfg.cut.cut_length_mm * 1e-3
    R = 0.5 * cfg.cut.bore_diameter_mm * 1e-3
    n_rps = cfg.cut.speed_rpm / 60.0
    vc = 2 * math.pi * R * n_rps
    split = cfg.mesh.separation == "node_split"
    mesh = build_boring_mesh(ins, ap, f, le, L, cfg.mesh.depth_factor,
                             cfg.mesh.side_margin_um * 1e-6, cfg.mesh.ahead_mm * 1e-3,
                             split_height=cfg.mesh.separation_height_um * 1e-6 if split
                             else None, chip_rows=cfg.mesh.chip_rows)
    s = cfg.solver
    p = apply_solver_settings(default_prm3(), s, K3)
    apply_friction_settings(p, cfg.contact, vc * 60.0, K3)
    p[K3.P_GATE] = cfg.solver.separation_gate_um * 1e-6 if split else -1.0
    p[K3.P_PEN] = cfg.contact.penalty_factor
    p[K3.P_TOOL] = 1.0
    p[K3.P_RN] = ins.nose_radius_m
    p[K3.P_KAPPA] = math.radians(ins.approach_angle_deg)
    p[K3.P_KEND] = math.radians(ins.end_edge_angle_deg)
    p[K3.P_RAKE] = math.radians(ins.rake_deg)
    p[K3.P_CLR] = math.radians(ins.clearance_deg)
    p[K3.P_RE] = ins.edge_radius_m
    p[K3.P_TANI] = math.tan(math.radians(ins.inclination_deg))
    p[K3.P_VC] = vc
    p[K3.P_VF] = f * n_rps
    p[K3.P_RADIUS] = R
    apply_thermal_settings(p, s, cfg.contact, mat, K3)
    gap0 = 0.5 * le
    x0 = -(ins.edge_radius_m + gap0)
    t_contact = gap0 / vc
    t_end = (L + ins.edge_radius_m + gap0) / vc
    p[K3.P_SAMPLE_DT] = t_end / s.n_samples
    ts = cfg.tool_support
    if ts is not None:
        p[K3.P_SUPPORT] = 1.0
        p[K3.P_KX], p[K3.P_KY], p[K3.P_KZ] = ts.total_stiffness()
        p[K3.P_CX], p[K3.P_CY], p[K3.P_CZ] = ts.damping_N_s_per_m
        p[K3.P_MX], p[K3.P_MY], p[K3.P_MZ] = ts.mass_kg
        p[K3.P_THETA0] = math.radians(ts.theta0_deg)
    st = make_state3(mesh.nodes, mesh.conn, mesh.fixed, mat, prm=p, n_samples=s.n_samples,
                     tool_tip=(x0, 0.0, 0.0), layer=mesh.layer, twin=mesh.twin)
    if ts is not None:
        dt = float(st.clock[1])
        for i, (k, m) in enumerate(zip(ts.total_stiffness(), ts.mass_kg, strict=True)):
            if dt * math.sqrt(k / m) > 0.5:
                raise ConfigError("tool support too stiff for the explicit time step", source,
                                  field=f"tool_support.stiffness_N_per_m[{i}]", value=k,
                                  expected=f"k < {0.25 * m / dt**2:.3g} N/m for mass {m} kg "
                                  f"and time step {dt:.3g} s")
    return BoringSetup(cfg=cfg, material=mat, insert=ins, mesh=mesh, state=st, ap=ap, f=f,
                       vc=vc, t_end=t_end, t_contact=t_contact)


@dataclass
class BoringFEResult:
    """Summary (JSON-ready dict), histories (arrays over samples) and the final state."""

    summary: dict[str, Any]
    history: dict[str, np.ndarray]
    setup: BoringSetup


def _mean_sliding_speed(st: FEState3) -> float | None:
    """Mean filtered sliding speed [m/s] of the nodes in contact at the end of the run (None
    without a friction table read at the sliding speed, or without contact)."""
    inc = np.any(st.cf[:, :3] != 0.0, axis=1)
    if st.prm[K3.P_MUTAB_N] <= 0.0 or not inc.any():
        return None
    return float(np.mean(st.cf[inc, 3]))


def _mean_amp(v: np.ndarray) -> tuple[float, float]:
    return float(np.mean(v)), float(0.5 * (np.max(v) - np.min(v)))


def simulate_boring(cfg: BoringFEConfig, *, source: str | None = None,
                    progress: Callable[[float], None] | None = None,
                    device: str = "cpu") -> BoringFEResult:
    """Set up and run the boring model; returns a :class:`BoringFEResult`.

    ``device``: "cpu" (numba, parallel) or "gpu" (numba-cuda, :mod:`robobore.cutting.fe.gpu`).
    """
    from robobore.cutting.forces import rotating_to_boring

    setup = setup_boring(cfg, source)
    st = setup.state
    dt0 = float(st.clock[1])
    limit = cfg.solver.energy_error_limit

    def check(s: FEState3) -> None:
        if s.time > setup.t_contact + 0.1 * (setup.t_end - setup.t_contact):
            err = energy_error(s.en)
            if err > limit:
                raise NumericalError(
                    f"energy balance lost at step {int(s.ist[K3.I_STEP])}, time {s.time:.6g} s:"
                    f" error {err:.3g} > solver.energy_error_limit {limit}")

    t0 = time.perf_counter()
    if device == "gpu":
        from robobore.cutting.fe.gpu import advance3_gpu

        steps = advance3_gpu(st, setup.t_end, chunk_steps=cfg.solver.chunk_steps,
                             progress=progress, check=check)
    elif device == "cpu":
        steps = advance3(st, setup.t_end, chunk_steps=cfg.solver.chunk_steps,
                         progress=progress, check=check)
    else:
        raise ConfigError("unknown device", field="--device", value=device,
                          expected="cpu or gpu")
    wall = time.perf_counter() - t0
    hh = st.hist[np.isfinite(st.hist[:, K3.H_T])]
    t = hh[:, K3.H_T]
    L = cfg.cut.cut_length_mm * 1e-3
    t0w = setup.t_end - cfg.solver.steady_window_fraction * L / setup.vc
    win = t >= t0w
    if not win.any():
        win = np.ones_like(t, bool)
    Ft = -hh[:, K3.H_FX]
    Fr = -hh[:, K3.H_FY]
    Fz = hh[:, K3.H_FZ]
    ft_m, fr_m, fz_m = float(np.mean(Ft[win])), float(np.mean(Fr[win])), float(np.mean(Fz[win]))
    th = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)
    FB = rotating_to_boring(ft_m, fr_m, fz_m, th)
    thr = hh[:, K3.H_THETA]
    FBt = rotating_to_boring(1.0, 0.0, 0.0, thr) * Ft + rotating_to_boring(0.0, 1.0, 0.0, thr) \
        * Fr + rotating_to_boring(0.0, 0.0, 1.0, thr) * Fz
    en = st.en
    n_el = st.n_elements
    cut_mm = (hh[:, K3.H_TIPX] - (-(setup.insert.edge_radius_m
                                    + 0.5 * cfg.mesh.element_size_um * 1e-6))) * 1e3
    alive = st.alive == 1
    ytop_max = float(np.max(setup.mesh.nodes[:, 1]))
    summary: dict[str, Any] = {
        "force_rotating_N": {"tangential": ft_m, "radial": fr_m, "feed": fz_m},
        "force_rotating_std_N": {"tangential": float(np.std(Ft[win])),
                                 "radial": float(np.std(Fr[win])),
                                 "feed": float(np.std(Fz[win]))},
        "force_mean_N": dict(zip("xyz", (float(v) for v in FB.mean(axis=1)), strict=True)),
        "force_amplitude_N": dict(zip("xyz", (float(v) for v in
                                              0.5 * (FB.max(axis=1) - FB.min(axis=1))),
                                      strict=True)),
        "force_at_run_angle_N": dict(zip("xyz", (float(np.mean(v[win])) for v in FBt),
                                         strict=True)),
        "bar_angle_deg": [float(np.degrees(thr[0])), float(np.degrees(thr[-1]))],
        "averaging_window_mm": [float(cut_mm[win][0]), float(cut_mm[win][-1])],
        "chip_area_mm2": chip_area(setup.insert, setup.ap, setup.f) * 1e6,
        "chip_max_height_um": float((np.max(st.y[~st.ndead]) - ytop_max) * 1e6),
        "peak_temperature_K": float(np.max(st.temp[alive])) if alive.any() else math.nan,
        "energy_error": energy_error(en),
        "energy_J": {"external": float(en[K3.E_EXT]), "kinetic": float(en[K3.E_KIN]),
                     "internal": float(en[K3.E_INT]), "plastic": float(en[K3.E_PLAST]),
                     "hourglass": float(en[K3.E_HG]), "contact": float(en[K3.E_FRIC]),
                     "eroded": float(en[K3.E_ERODED])},
        "hourglass_fraction": float(en[K3.E_HG] / max(en[K3.E_INT], 1e-300)),
        "feed_amplitude_um": None,
        "wall_time_s": wall,
        "element_updates_per_s": n_el * steps / max(wall, 1e-12),
        "steps": int(steps),
        "time_step_s": dt0,
        "n_elements": n_el,
        "n_nodes": int(st.x.shape[0]),
        "mesh_shape": list(setup.mesh.shape),
        "element_size_um": cfg.mesh.element_size_um,
        "cutting_speed_m_per_min": setup.vc * 60.0,
        "friction_coefficient": float(st.prm[K3.P_MU]),
        "friction_law": cfg.friction_law(),
        "sliding_speed_mean_m_per_s": _mean_sliding_speed(st),
        "separation": cfg.mesh.separation,
        "pairs_parted": int(np.sum((st.twin >= 0) & (st.tied == 0)) // 2),
        "eroded_damage": int(np.sum(st.alive == 0)),
        "eroded_distortion": int(np.sum(st.alive == -1)),
        "device": device,
    }
    if cfg.tool_support is not None:
        k = cfg.tool_support.total_stiffness()
        uz = hh[:, K3.H_UZ] * 1e6
        mean_z, amp_z = _mean_amp(uz[win])
        summary.update({
            "feed_amplitude_um": amp_z,
            "tool_dz_mean_um": mean_z,
            "tool_dz_static_um": fz_m / k[2] * 1e6 if k[2] > 0 else math.nan,
            "tool_dx_mean_um": float(np.mean(hh[win, K3.H_UX]) * 1e6),
            "tool_dy_mean_um": float(np.mean(hh[win, K3.H_UY]) * 1e6),
        })
    history = {
        "time_s": t, "cut_length_mm": cut_mm, "bar_angle_rad": thr,
        "force_tangential_N": Ft, "force_radial_N": Fr, "force_feed_N": Fz,
        "force_X_N": FBt[0], "force_Y_N": FBt[1], "force_Z_N": FBt[2],
        "tool_dX_um": hh[:, K3.H_UX] * 1e6, "tool_dY_um": hh[:, K3.H_UY] * 1e6,
        "tool_dZ_um": hh[:, K3.H_UZ] * 1e6, "contact_nodes": hh[:, K3.H_NCONT],
        "energy_external_J": hh[:, K3.H_EEXT], "energy_kinetic_J": hh[:, K3.H_EKIN],
        "energy_internal_J": hh[:, K3.H_EINT], "energy_hourglass_J": hh[:, K3.H_EHG],
        "energy_contact_J": hh[:, K3.H_EFRIC],
    }
    return BoringFEResult(summary=summary, history=history, setup=setup)


# ----------------------------------------------------------------------------- comparison
def compare_with_mechanistic(result: BoringFEResult,
                             coefficients: str | Path | None = None) -> dict[str, Any]:
    """FE rotating-frame forces vs the mechanistic boring model at the same condition.

    ``coefficients``: a coefficients file (:func:`robobore.cutting.forces.load_coefficients`)
    -- e.g. the FE-calibrated one -- or None for the default TC4 coefficients
    (:func:`robobore.cutting.forces.ti64_coefficients` at the run's cutting speed).
    Returns per component (tangential, radial, feed) the FE and model forces [N] and the
    relative difference (FE - model) / |model|.
    """
    from robobore.cutting.forces import boring_forces, load_coefficients, ti64_coefficients

    s = result.setup
    coef = (ti64_coefficients(s.vc * 60.0) if coefficients is None
            else load_coefficients(coefficients, s.vc * 60.0))
    mech = boring_forces(s.insert, s.ap, s.f, coef)
    fe = result.summary["force_rotating_N"]
    out: dict[str, Any] = {"coefficients": coef.provenance if hasattr(coef, "provenance")
                           else str(coefficients)}
    for comp, key in (("tangential", "tangential_N"), ("radial", "radial_N"),
                      ("feed", "feed_N")):
        m = float(mech[key])
        out[comp] = {"fe_N": fe[comp], "model_N": m,
                     "relative_difference": (fe[comp] - m) / abs(m) if m != 0 else math.nan}
    return out


# ------------------------------------------------------------------------------------ VTK
def write_vtk(result: BoringFEResult, directory: str | Path) -> list[Path]:
    """Initial and final workpiece meshes (live elements) as VTU files for ParaView."""
    import meshio

    from robobore.io.results import atomic_write_bytes

    st = result.setup.state
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    sd = st.sd
    vm = np.sqrt(1.5 * (np.sum(sd[:, :3] ** 2, axis=1) + 2 * np.sum(sd[:, 3:] ** 2, axis=1)))
    alive = st.alive == 1
    out = []
    for name, pts, mask in (("initial", result.setup.mesh.nodes, np.ones_like(alive)),
                            ("final", st.nodes(), alive)):
        cells = [("hexahedron", st.conn[mask])]
        cd = {"eps_p": [st.eps_p[mask]], "temperature_K": [st.temp[mask]],
              "damage": [st.dmg[mask]], "von_mises_Pa": [vm[mask]],
              "pressure_Pa": [st.pres[mask]]} if name == "final" else {}
        m = meshio.Mesh(pts * 1e3, cells, cell_data=cd)
        p = d / f"boring_{name}.vtu"
        tmp = d / f".boring_{name}.tmp.vtu"
        meshio.write(tmp, m)
        atomic_write_bytes(p, tmp.read_bytes())
        tmp.unlink()
        out.append(p)
    return out
