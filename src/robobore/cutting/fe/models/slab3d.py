"""Cross-check of the 3D engine against the 2D engine: an orthogonal cut on a 3D slab.

The 2D orthogonal-cutting config (:class:`robobore.cutting.fe.config.orthogonal.FEConfig`, node
splitting) is rebuilt as a thin 3D slab in plane strain -- ``n_z`` hexahedra across the width,
z velocities held on both faces -- and cut by the 3D engine's insert with a straight edge
(nose radius 1 m, so every normal section of the edge is the 2D wedge: same rake, clearance
and edge radius). Material, friction, parting-line height, mass scaling, hourglass, bulk
viscosity and erosion limits are the 2D config's. Both engines share the constitutive and
contact functions, so in the resolved regime the two must give the same forces per unit
width; ``benchmarks/validate_fe3d_planestrain.py`` prints the comparison and
``tests/cutting/fe3d/test_fe3d_planestrain.py`` holds it (docs/fe3d.md, "Plane-strain
cross-check").

The **tool-frame slab** (:func:`setup_slab3_toolframe`, :func:`simulate_slab3_toolframe`) does
the same for the 2D tool-frame ALE model (``mesh.frame = "tool"``): the 2D tool-frame mesh of
the config, extruded across the slab
(:func:`robobore.cutting.fe.mesh.toolframe3d.extrude_toolframe_mesh`), z held on both side
faces, run by the 3D engine's tool-frame loop (:func:`robobore.cutting.fe.engine.kernels3d.
run_chunk3_ale`: the ALE pass of :mod:`robobore.cutting.fe.ale.rezone3d` every
``solver.ale_interval`` steps) with the same straight-edged insert; the cross-check of the 3D
tool-frame plumbing (``tests/cutting/fe3d/test_toolframe3d_slab.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.cutting.fe.config.engine_settings import (
    apply_numerics,
)
from robobore.cutting.fe.config.orthogonal import FEConfig
from robobore.cutting.fe.config.spec import HexElement, ModelSpec, WorkpieceFrame, WorkpieceFrame3D
from robobore.cutting.fe.config.spec_build import build_spec
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import energy_error
from robobore.cutting.fe.engine.state3d import (
    FEState3,
    advance3,
    default_prm3,
    hex_conn,
    make_state3,
    split_node_layer,
)
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.models.choose import choose_orthogonal
from robobore.cutting.fe.models.results import SlabSummary
from robobore.errors import ConfigError
from robobore.material.library import load_material

__all__ = ["SlabSetup", "setup_slab3", "simulate_slab3", "setup_slab3_toolframe",
           "simulate_slab3_toolframe"]


@dataclass
class SlabSetup:
    state: FEState3
    t_end: float
    width: float
    vc: float
    cut_length: float


def setup_slab3(cfg: FEConfig, *, n_z: int = 2, depth_factor: float = 1.5,
                ahead: float = 0.1e-3) -> SlabSetup:
    """3D plane-strain slab of the 2D config ``cfg`` (workpiece frame, node splitting only)."""
    if choose_orthogonal(cfg).tool_frame:
        raise ConfigError("the 3D slab cross-check is a workpiece-frame model",
                          field="mesh.frame", value=cfg.mesh.frame.value, expected='"workpiece"')
    if cfg.mesh.separation != "node_split":
        raise ConfigError("the 3D slab cross-check needs node splitting",
                          field="mesh.separation", value=cfg.mesh.separation,
                          expected="node_split")
    mat = load_material(cfg.material.name,
                        hardening_strain_limit=cfg.material.strain_limit())
    h = cfg.cut.uncut_chip_thickness_um * 1e-6
    le = cfg.mesh.element_size_um * 1e-6
    L = cfg.cut.length_mm * 1e-3
    re = cfg.tool.edge_radius_um * 1e-6
    sep = (cfg.mesh.separation_height_um or 0.0) * 1e-6
    vc = cfg.cut.cutting_speed_m_per_min / 60.0
    depth = max(depth_factor * h, 4 * le)
    nx = max(2, int(round((L + ahead) / le)))
    n_up = max(1, int(round((h - sep) / le)))
    n_dn = max(3, int(round((depth + sep) / le)))
    xs = np.linspace(0.0, L + ahead, nx + 1)
    ys = np.concatenate([np.linspace(-depth, sep, n_dn + 1), np.linspace(sep, h, n_up + 1)[1:]])
    width = n_z * le
    zs = np.linspace(0.0, width, n_z + 1)
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    ny = ys.size - 1
    idx = np.arange(nodes.shape[0]).reshape(nx + 1, ny + 1, n_z + 1)
    conn = hex_conn(idx)
    fixed = np.zeros(nodes.shape[0], np.int64)
    fixed[idx[:, :, 0].ravel()] |= scalar3d.FIX_Z
    fixed[idx[:, :, -1].ravel()] |= scalar3d.FIX_Z
    fixed[idx[:, 0, :].ravel()] = 7
    fixed[idx[-1, :, :].ravel()] = 7
    # parting line: double its nodes (not the fully fixed ones); the chip rows take the copies
    nodes, conn, fixed, twin = split_node_layer(nodes, conn, fixed, idx, n_dn)
    # the 2D config's model choices on the hexahedron (the parting line's gate, friction,
    # heat, hardening as in 2D)
    spec2 = build_spec(cfg, mat)
    frame = spec2.frame
    assert isinstance(frame, WorkpieceFrame)
    spec = ModelSpec(frame=WorkpieceFrame3D(
        separation=frame.separation, damage_erosion=cfg.solver.erosion == "layer",
        erode_time_step_fraction=frame.erode_time_step_fraction,
        element=HexElement(cfg.solver.hourglass_viscous, cfg.solver.hourglass_stiffness)),
        friction=spec2.friction, thermal=spec2.thermal, hardening=spec2.hardening)
    p0 = apply_numerics(default_prm3(), cfg.solver, layout3d)
    p = _straight_insert(spec.write_prm(p0, layout3d,
                                        cfg.cut.cutting_speed_m_per_min), cfg, vc,
                         tool_frame=False)
    gap0 = 0.5 * le
    t_end = (L + re + gap0) / vc
    n_samples = cfg.solver.n_samples
    p[layout3d.P_SAMPLE_DT] = t_end / n_samples
    st = make_state3(nodes, conn, fixed, mat, prm=p, n_samples=n_samples,
                     tool_tip=(-(re + gap0), 0.0, 0.5 * width), twin=twin)
    return SlabSetup(state=st, t_end=t_end, width=width, vc=vc, cut_length=L)


def _straight_insert(p: np.ndarray, cfg: FEConfig, vc: float, *, tool_frame: bool) -> np.ndarray:
    # the insert with a straight edge over the slab: nose radius 1 m, the 2D wedge in every
    # normal section; the 2D config's contact
    p[layout3d.P_PEN] = cfg.contact.penalty_factor
    p[layout3d.P_CDAMP] = cfg.contact.damping_for(tool_frame)
    p[layout3d.P_TOOL] = 1.0
    p[layout3d.P_RN] = 1.0
    p[layout3d.P_KAPPA] = 0.5 * math.pi
    p[layout3d.P_KEND] = 0.49 * math.pi
    p[layout3d.P_RAKE] = math.radians(cfg.tool.rake_deg)
    p[layout3d.P_CLR] = math.radians(cfg.tool.clearance_deg)
    p[layout3d.P_RE] = cfg.tool.edge_radius_um * 1e-6
    p[layout3d.P_VC] = vc
    return p


def setup_slab3_toolframe(cfg: FEConfig, *, n_z: int = 2) -> SlabSetup:
    """3D plane-strain slab of the 2D tool-frame config ``cfg``: its 2D tool-frame mesh
    (the mesh :func:`robobore.cutting.fe.models.orthogonal.setup_orthogonal` builds)
    extruded over ``n_z`` hexahedra of the element size across (z centred on the insert's
    tip), the 2D config's model choices on the hexahedron (friction, heat, hardening, ALE
    interval), the tool-frame boundary conditions of
    :func:`robobore.cutting.fe.models.toolframe3d.toolframe_fixed`."""
    from robobore.cutting.fe.config.spec import ToolFrame, ToolFrame3D
    from robobore.cutting.fe.mesh.toolframe3d import extrude_toolframe_mesh
    from robobore.cutting.fe.models.orthogonal import setup_orthogonal
    from robobore.cutting.fe.models.toolframe3d import attach_toolframe, toolframe_fixed

    if not choose_orthogonal(cfg).tool_frame:
        raise ConfigError("the tool-frame slab needs the 2D tool-frame model",
                          field="mesh.frame", value=cfg.mesh.frame.value, expected='"tool"')
    setup2 = setup_orthogonal(cfg)
    spec2 = setup2.spec
    assert spec2 is not None and isinstance(spec2.frame, ToolFrame)
    le = cfg.mesh.element_size_um * 1e-6
    width = n_z * le
    mesh = extrude_toolframe_mesh(setup2.mesh, np.linspace(-0.5 * width, 0.5 * width, n_z + 1))
    vc = cfg.cut.cutting_speed_m_per_min / 60.0
    spec = ModelSpec(frame=ToolFrame3D(
        ale_interval=spec2.frame.ale_interval,
        element=HexElement(spec2.frame.element.hourglass_viscous,
                           spec2.frame.element.hourglass_stiffness)),
        friction=spec2.friction, thermal=spec2.thermal, hardening=spec2.hardening)
    p0 = apply_numerics(default_prm3(), cfg.solver, layout3d)
    p = _straight_insert(spec.write_prm(p0, layout3d,
                                        cfg.cut.cutting_speed_m_per_min), cfg, vc,
                         tool_frame=True)
    L = cfg.cut.length_mm * 1e-3
    t_end = L / vc
    p[layout3d.P_SAMPLE_DT] = t_end / cfg.solver.n_samples
    tip = (0.0, 0.0, 0.0)
    st = make_state3(mesh.nodes, mesh.conn, toolframe_fixed(mesh), setup2.material, prm=p,
                     n_samples=cfg.solver.n_samples, tool_tip=tip)
    attach_toolframe(st, mesh, tip)
    return SlabSetup(state=st, t_end=t_end, width=width, vc=vc, cut_length=L)


def simulate_slab3_toolframe(cfg: FEConfig, *, n_z: int = 2, steady_fraction: float = 0.5,
                             progress: Any = None) -> SlabSummary:
    """Run the tool-frame slab (:func:`setup_slab3_toolframe`); the outputs of
    :func:`simulate_slab3`."""
    s = setup_slab3_toolframe(cfg, n_z=n_z)
    return _slab_summary(s, advance3(s.state, s.t_end, chunk_steps=cfg.solver.chunk_steps,
                                     progress=progress), steady_fraction)


def simulate_slab3(cfg: FEConfig, *, n_z: int = 2, steady_fraction: float = 0.5,
                   **kw: Any) -> SlabSummary:
    """Run the slab; a :class:`robobore.cutting.fe.models.results.SlabSummary`: forces on the
    tool per unit width [N/mm] averaged over the last ``steady_fraction`` of the cut, energy
    error, hourglass fraction, eroded elements."""
    s = setup_slab3(cfg, n_z=n_z, **kw)
    return _slab_summary(s, advance3(s.state, s.t_end), steady_fraction)


def _slab_summary(s: SlabSetup, steps: int, steady_fraction: float) -> SlabSummary:
    # forces per unit width over the window, energy balance, counts
    st = s.state
    hh = st.hist[np.isfinite(st.hist[:, scalar3d.H_T])]
    win = hh[:, scalar3d.H_T] >= s.t_end - steady_fraction * s.cut_length / s.vc
    w_mm = s.width * 1e3
    return SlabSummary(
        cutting_force_N_per_mm=float(-np.mean(hh[win, scalar3d.H_FX]) / w_mm),
        feed_force_N_per_mm=float(np.mean(hh[win, scalar3d.H_FY]) / w_mm),
        out_of_plane_force_N_per_mm=float(np.mean(hh[win, scalar3d.H_FZ]) / w_mm),
        energy_error=energy_error(st.en),
        hourglass_fraction=float(st.en[layout.E_HG] / max(st.en[layout.E_INT], 1e-300)),
        eroded=int(np.sum(st.alive != 1)),
        n_elements=st.n_elements,
        steps=int(steps),
        final_time_step_s=float(st.clock[1]),
    )
