"""The set-up of the 3D boring model (:mod:`robobore.cutting.fe.models.boring3d`): the
:class:`BoringSetup` record, the parameter vector of a boring config (:func:`boring_prm`) and
the tool support's step check (:func:`check_support_step`), shared by the two frames, and the
workpiece frame's set-up (:func:`setup_boring_workpiece`; the tool frame's is
:func:`robobore.cutting.fe.models.toolframe3d.setup_boring_toolframe`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.cutting.fe.config.boring3d import BoringFEConfig
from robobore.cutting.fe.config.engine_settings import apply_numerics
from robobore.cutting.fe.config.spec import ModelSpec
from robobore.cutting.fe.config.spec_build import build_boring_spec
from robobore.cutting.fe.engine.state3d import FEState3, default_prm3, make_state3
from robobore.cutting.fe.hex import layout3d
from robobore.cutting.fe.mesh.boring3d import build_boring_mesh
from robobore.cutting.geometry import BoringInsert
from robobore.errors import ConfigError
from robobore.material.library import Material, load_material

__all__ = ["BoringSetup", "boring_prm", "check_support_step", "setup_boring_workpiece"]


@dataclass
class BoringSetup:
    cfg: BoringFEConfig
    material: Material
    insert: BoringInsert
    #: the workpiece frame's ``mesh.boring3d.BoringMesh`` or the tool frame's
    #: ``mesh.toolframe3d.ToolFrameMesh3D``
    mesh: Any
    state: FEState3
    ap: float
    f: float
    vc: float
    t_end: float
    t_contact: float
    #: the model choices the state was built from
    spec: ModelSpec | None = None
    #: the insert tip's x [m] at which the cut length is 0
    x_cut_start: float = 0.0


def boring_prm(cfg: BoringFEConfig, spec: ModelSpec, ins: BoringInsert, vc: float,
               f: float) -> np.ndarray:
    """The 3D parameter vector of a boring config (either frame) before the run's times:
    numerics, the spec's model choices, contact, insert, kinematics and tool support."""
    s = cfg.solver
    R = 0.5 * cfg.cut.bore_diameter_mm * 1e-3
    n_rps = cfg.cut.speed_rpm / 60.0
    p = spec.write_prm(apply_numerics(default_prm3(), s, layout3d), layout3d, vc * 60.0)
    p[layout3d.P_PEN] = cfg.contact.penalty_factor
    p[layout3d.P_CDAMP] = cfg.contact.damping_for(spec.frame.tool_frame)
    p[layout3d.P_TOOL] = 1.0
    p[layout3d.P_RN] = ins.nose_radius_m
    p[layout3d.P_KAPPA] = math.radians(ins.approach_angle_deg)
    p[layout3d.P_KEND] = math.radians(ins.end_edge_angle_deg)
    p[layout3d.P_RAKE] = math.radians(ins.rake_deg)
    p[layout3d.P_CLR] = math.radians(ins.clearance_deg)
    p[layout3d.P_RE] = ins.edge_radius_m
    p[layout3d.P_TANI] = math.tan(math.radians(ins.inclination_deg))
    p[layout3d.P_VC] = vc
    p[layout3d.P_VF] = f * n_rps
    p[layout3d.P_RADIUS] = R
    ts = cfg.tool_support
    if ts is not None:
        p[layout3d.P_SUPPORT] = 1.0
        p[layout3d.P_KX], p[layout3d.P_KY], p[layout3d.P_KZ] = ts.total_stiffness()
        p[layout3d.P_CX], p[layout3d.P_CY], p[layout3d.P_CZ] = ts.damping_N_s_per_m
        p[layout3d.P_MX], p[layout3d.P_MY], p[layout3d.P_MZ] = ts.mass_kg
        p[layout3d.P_THETA0] = math.radians(ts.theta0_deg)
    return p


def check_support_step(cfg: BoringFEConfig, st: FEState3, source: str | None) -> None:
    """ConfigError when the tool support is too stiff for the state's explicit step."""
    ts = cfg.tool_support
    if ts is not None:
        dt = float(st.clock[1])
        for i, (k, m) in enumerate(zip(ts.total_stiffness(), ts.mass_kg, strict=True)):
            if dt * math.sqrt(k / m) > 0.5:
                raise ConfigError("tool support too stiff for the explicit time step", source,
                                  field=f"tool_support.stiffness_N_per_m[{i}]", value=k,
                                  expected=f"k < {0.25 * m / dt**2:.3g} N/m for mass {m} kg "
                                  f"and time step {dt:.3g} s")


def setup_boring_workpiece(cfg: BoringFEConfig, source: str | None = None) -> BoringSetup:
    """Mesh, insert, support and state of the workpiece-frame boring model of ``cfg``
    (``mesh.frame = "workpiece"``): the bore-wall block with the previous revolution's feed
    marks (:func:`robobore.cutting.fe.mesh.boring3d.build_boring_mesh`), the insert half an
    element before the block."""
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
    spec = build_boring_spec(cfg, mat, vc * 60.0, source)
    p = boring_prm(cfg, spec, ins, vc, f)
    gap0 = 0.5 * le
    x0 = -(ins.edge_radius_m + gap0)
    t_contact = gap0 / vc
    t_end = (L + ins.edge_radius_m + gap0) / vc
    p[layout3d.P_SAMPLE_DT] = t_end / s.n_samples
    st = make_state3(mesh.nodes, mesh.conn, mesh.fixed, mat, prm=p, n_samples=s.n_samples,
                     tool_tip=(x0, 0.0, 0.0), layer=mesh.layer, twin=mesh.twin)
    check_support_step(cfg, st, source)
    return BoringSetup(cfg=cfg, material=mat, insert=ins, mesh=mesh, state=st, ap=ap, f=f,
                       vc=vc, t_end=t_end, t_contact=t_contact, spec=spec,
                       x_cut_start=-(ins.edge_radius_m
                                     + 0.5 * cfg.mesh.element_size_um * 1e-6))
