"""The orthogonal-cutting model: :func:`setup_orthogonal` builds mesh, tool and state from an
:class:`~robobore.cutting.fe.config.orthogonal.FEConfig`, :func:`run_orthogonal` runs it on the CPU
or the GPU, :func:`simulate_orthogonal` sets up, runs and measures it (forces, chip, energies)
into an :class:`~robobore.cutting.fe.models.output.FEResult`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robobore.cutting.fe.ale.rezone import TF_RIGID
from robobore.cutting.fe.config.engine_settings import apply_numerics
from robobore.cutting.fe.config.orthogonal import FEConfig
from robobore.cutting.fe.config.spec import ModelSpec
from robobore.cutting.fe.config.spec_build import build_spec
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import energy_check, energy_error
from robobore.cutting.fe.engine.chunk_loop import phases_of
from robobore.cutting.fe.engine.state2d import (
    FEState,
    default_prm,
    make_state,
)
from robobore.cutting.fe.mesh.orthogonal import CuttingMesh, build_edge_refined_mesh, build_mesh
from robobore.cutting.fe.models.choose import choose_orthogonal
from robobore.errors import ConfigError
from robobore.material.library import Material, load_material


@dataclass
class CuttingSetup:
    """Everything derived from a config before the run."""

    cfg: FEConfig
    material: Material
    mesh: CuttingMesh
    state: FEState
    h: float
    vc: float
    rake: float
    t_end: float
    t_contact: float
    mu: float
    #: tool edge centre x [m] at which the cut length is 0 (the cut position of a sample is
    #: this minus the edge centre's x)
    x_cut_start: float = math.nan
    #: the model choices the state was built from
    spec: ModelSpec | None = None


def _layer_offset(cfg: FEConfig, le: float) -> float:
    """Top of the separation layer above the cut line, in element sizes (see build_mesh)."""
    if cfg.mesh.separation_height_um is not None:
        return 1.0 + cfg.mesh.separation_height_um * 1e-6 / le
    return {"above_cut_line": 1.0, "centred": 0.5, "below_cut_line": 0.0}[
        cfg.mesh.separation_layer]


def _split_height(cfg: FEConfig) -> float | None:
    """Parting-line height above the cut line [m] for node splitting, else None."""
    if cfg.mesh.separation != "node_split":
        return None
    sh = cfg.mesh.separation_height_um
    return (0.0 if sh is None else sh) * 1e-6


def _m_or_none(um: float | None) -> float | None:
    """An optional length in um as metres (None stays None: the mesh builder's default)."""
    return None if um is None else um * 1e-6


def setup_orthogonal(cfg: FEConfig, source: str | None = None) -> CuttingSetup:
    """Build mesh, tool and state for the orthogonal-cutting model of ``cfg``."""
    mat = load_material(cfg.material.name, source=source,
                        hardening_strain_limit=cfg.material.strain_limit())
    h = cfg.cut.uncut_chip_thickness_um * 1e-6
    le = cfg.mesh.element_size_um * 1e-6
    L = cfg.cut.length_mm * 1e-3
    vc = cfg.cut.cutting_speed_m_per_min / 60.0
    r = cfg.tool.edge_radius_um * 1e-6
    rake = math.radians(cfg.tool.rake_deg)
    clr = math.radians(cfg.tool.clearance_deg)
    cm = cfg.mesh
    tool_frame = choose_orthogonal(cfg, source=source).tool_frame
    if tool_frame:
        from robobore.cutting.fe.ale.toolframe import ToolFrameExtent, build_toolframe_mesh

        ee = (cm.element_size_um / 4.0 if cm.edge_element_um is None else cm.edge_element_um)
        try:
            mesh = build_toolframe_mesh(
                h, r, rake, clr, element_size=le, edge_size=ee * 1e-6,
                chip_ratio=cm.initial_chip_ratio,
                join_height=_m_or_none(cm.join_height_um),
                extent=ToolFrameExtent(ahead=_m_or_none(cm.inflow_length_um),
                                       behind=_m_or_none(cm.back_length_um),
                                       depth=_m_or_none(cm.depth_um),
                                       chip_length=_m_or_none(cm.chip_length_um)))
        except ValueError as exc:
            raise ConfigError(str(exc), file=source, field="mesh.initial_chip_ratio",
                              value=cm.initial_chip_ratio,
                              expected="a larger initial chip ratio (the chip's root must "
                              "lie ahead of the edge)") from exc
    elif cm.edge_element_um is not None:
        try:
            mesh = build_edge_refined_mesh(
                h, le, L, split_height=_split_height(cfg) or 0.0,
                levels=int(round(math.log2(cm.element_size_um / cm.edge_element_um))),
                band_above=cm.edge_band_um[0] * 1e-6, band_below=cm.edge_band_um[1] * 1e-6,
                ahead=cm.ahead_mm * 1e-3, fine_depth_factor=cm.fine_depth_factor,
                height_factor=cm.height_factor, grading=cm.grading)
        except ValueError as exc:
            raise ConfigError(str(exc), file=source, field="mesh.edge_element_um",
                              value=cm.edge_element_um,
                              expected="fewer refinement levels, smaller elements or a "
                              "lower mesh.separation_height_um") from exc
    else:
        mesh = build_mesh(h, le, L, ahead=cm.ahead_mm * 1e-3,
                          fine_depth_factor=cm.fine_depth_factor,
                          height_factor=cm.height_factor, grading=cm.grading,
                          layer_offset=_layer_offset(cfg, le),
                          split_height=_split_height(cfg))
    s = cfg.solver
    spec = build_spec(cfg, mat, source)
    p = spec.write_prm(apply_numerics(default_prm(), s, layout), layout,
                       cfg.cut.cutting_speed_m_per_min)
    p[layout.P_PEN] = cfg.contact.penalty_factor
    p[layout.P_CDAMP] = cfg.contact.damping_for(tool_frame)
    p[layout.P_R] = r
    p[layout.P_NRX], p[layout.P_NRY] = -math.cos(rake), math.sin(rake)
    p[layout.P_NFX], p[layout.P_NFY] = math.sin(clr), -math.cos(clr)
    p[layout.P_VC] = vc
    p[layout.P_WIDTH] = cfg.cut.width_mm * 1e-3
    if tool_frame:
        cx0, cy0 = mesh.tool_center  # the mesh starts round the tool
        t_contact = 0.0
        t_end = L / vc
        x_cut_start = cx0
    else:
        gap0 = 0.5 * le
        cx0 = mesh.length + r + gap0
        cy0 = -h + r
        t_contact = gap0 / vc
        t_end = (L + r + gap0) / vc
        x_cut_start = mesh.length + r
    p[layout.P_SAMPLE_DT] = t_end / s.n_samples
    ts = cfg.tool_support
    if ts is not None:
        p[layout.P_SUPPORT] = 1.0
        p[layout.P_KX], p[layout.P_KY] = ts.stiffness_N_per_m  # type: ignore[misc]
        p[layout.P_CX], p[layout.P_CY] = ts.damping_N_s_per_m  # type: ignore[misc]
        p[layout.P_MX], p[layout.P_MY] = ts.mass_kg  # type: ignore[misc]
    if tool_frame:
        # the mesh travels with the tool from its start
        p[layout.P_ALE_X0], p[layout.P_TCX], p[layout.P_TCY] = cx0, cx0, cy0
    st = make_state(mesh.nodes, mesh.conn, mesh.fixed, mat, prm=p,
                    layer=getattr(mesh, "layer", None), n_samples=s.n_samples,
                    tool_center=(cx0, cy0), twin=getattr(mesh, "twin", None),
                    phases=phases_of(spec))
    if tool_frame:
        st.acls, st.aflt, st.bflag = mesh.acls.copy(), mesh.aflt.copy(), mesh.bflag.copy()
        st.snodes = np.where(mesh.acls[:, 0] != TF_RIGID)[0].astype(np.int64)
    if ts is not None:
        dt = st.clock[1]
        for i, (k, m) in enumerate(zip(ts.stiffness_N_per_m, ts.mass_kg, strict=True)):  # type: ignore[arg-type]
            if dt * math.sqrt(k / m) > 0.5:
                raise ConfigError("tool support too stiff for the explicit time step",
                                  file=source, field=f"tool_support.stiffness_N_per_m[{i}]",
                                  value=k, expected=f"k < {0.25 * m / dt**2:.3g} N/m for "
                                  f"mass {m} kg and time step {dt:.3g} s")
    return CuttingSetup(cfg=cfg, material=mat, mesh=mesh, state=st, h=h, vc=vc, rake=rake,
                        t_end=t_end, t_contact=t_contact, mu=float(p[layout.P_MU]),
                        x_cut_start=x_cut_start, spec=spec)


def check_device(device: str, cfg: FEConfig, source: str | None = None) -> None:
    """ConfigError unless ``device`` is "cpu" or a usable "gpu" that runs every option
    (:func:`robobore.cutting.fe.models.choose.choose_orthogonal`)."""
    choose_orthogonal(cfg, device, source)


def run_orthogonal(setup: CuttingSetup, progress: Callable[[float], None] | None = None,
                   device: str = "cpu"):
    """Run the cutting model to the end; returns (wall time [s], steps taken).

    ``device``: "cpu" (numba, parallel; the default) or "gpu" (numba-cuda,
    :func:`robobore.cutting.fe.engine.gpu.backend2d.advance_gpu`).
    """
    model = choose_orthogonal(setup.cfg, device)
    st = setup.state
    check = energy_check(setup.t_contact, setup.t_end, setup.cfg.solver.energy_error_limit)
    t0 = time.perf_counter()
    steps = model.advance(st, setup.t_end, progress=progress, check=check, spec=setup.spec)
    return time.perf_counter() - t0, steps


def _final_fields(setup: CuttingSetup) -> dict[str, np.ndarray]:
    from robobore.cutting.fe.models.output import tool_outline

    st = setup.state
    cfg = setup.cfg
    cx = st.tool[layout.T_GX] + st.tool[layout.T_UX]
    cy = st.tool[layout.T_GY] + st.tool[layout.T_UY]
    sxx, syy, szz, sxy = st.sdx, st.sdy, st.sdz, st.sdxy
    vm = np.sqrt(1.5 * (sxx**2 + syy**2 + szz**2 + 2 * sxy**2))
    ox, oy = tool_outline(cx, cy, cfg.tool.edge_radius_um * 1e-6, setup.rake,
                          math.radians(cfg.tool.clearance_deg), 4 * setup.h)
    return {"x": st.x.copy(), "y": st.y.copy(), "x0": st.x0.copy(), "y0": st.y0.copy(),
            "conn": st.conn.copy(), "alive": st.alive.copy(), "eps_p": st.eps_p.copy(),
            "temperature_K": st.temp.copy(), "damage": st.dmg.copy(), "von_mises_Pa": vm,
            "pressure_Pa": st.pres.copy(), "tool_outline": np.array([ox, oy]),
            "tool_center": np.array([cx, cy]), "vx": st.vx.copy(), "vy": st.vy.copy(),
            "tool_velocity": np.array([-setup.vc + st.tool[layout.T_VUX], st.tool[layout.T_VUY]]),
            "deviatoric_stress_Pa": np.array([sxx, syy, szz, sxy]),
            "contact_force_N_per_m": np.array([st.cfx, st.cfy]),
            "sliding_speed_m_per_s": st.vslip.copy()}


def simulate_orthogonal(cfg: FEConfig, *, source: str | None = None,
                        progress: Callable[[float], None] | None = None,
                        device: str = "cpu"):
    """Set up and run the orthogonal-cutting model; returns an :class:`FEResult`.

    ``device``: "cpu" (default) or "gpu" (see :func:`run_orthogonal`); checked before the
    mesh is built.
    """
    from robobore.cutting.fe.models.output import FEResult, steady_window
    from robobore.cutting.fe.models.results import (
        FaceForce,
        FaceForces,
        OrthogonalSummary,
        ToolSupport2D,
    )

    model = choose_orthogonal(cfg, device, source)
    setup = setup_orthogonal(cfg, source)
    st = setup.state
    dt0 = float(st.clock[1])
    wall, steps = run_orthogonal(setup, progress, device)
    hist = st.hist
    ok = np.isfinite(hist[:, layout.H_T])
    hh = hist[ok]
    t = hh[:, layout.H_T]
    L = cfg.cut.length_mm * 1e-3
    frac = cfg.solver.steady_window_fraction
    t0w = setup.t_end - frac * L / setup.vc
    win = steady_window(t, t0w, setup.t_end + 1e-12)
    fc = hh[:, layout.H_FX] * 1e-3
    ff = hh[:, layout.H_FY] * 1e-3
    cut_pos_mm = (setup.x_cut_start - hh[:, layout.H_TIP_X]) * 1e3
    chip, r_vel, n_vel = model.measure_chip(setup)
    en = st.en
    n_el = st.n_elements
    faces = hh[:, layout.H_FX_RAKE:layout.H_FX_RAKE + 6] * 1e-3
    has_faces = bool(win.any() and np.all(np.isfinite(faces[win])))
    by_face = None
    if has_faces:  # recorded by both devices
        fm = faces[win].mean(axis=0)
        by_face = FaceForces(**{face: FaceForce(cutting=float(fm[2 * j]),
                                                feed=float(fm[2 * j + 1]))
                                for j, face in enumerate(layout.FACES)})
    fc_mean, ff_mean = float(np.mean(fc[win])), float(np.mean(ff[win]))
    support = None
    if cfg.tool_support is not None:
        kx, ky = cfg.tool_support.stiffness_N_per_m  # type: ignore[misc]
        w = cfg.cut.width_mm
        dx = hh[:, layout.H_UX] * 1e6
        dy = hh[:, layout.H_UY] * 1e6
        support = ToolSupport2D(
            tool_dx_mean_um=float(np.mean(dx[win])), tool_dy_mean_um=float(np.mean(dy[win])),
            tool_dx_std_um=float(np.std(dx[win])), tool_dy_std_um=float(np.std(dy[win])),
            tool_dx_static_um=fc_mean * w / kx * 1e6, tool_dy_static_um=ff_mean * w / ky * 1e6)
    summary = OrthogonalSummary(
        cutting_force_N_per_mm=fc_mean,
        feed_force_N_per_mm=ff_mean,
        cutting_force_std_N_per_mm=float(np.std(fc[win])),
        feed_force_std_N_per_mm=float(np.std(ff[win])),
        averaging_window_mm=(float(cut_pos_mm[win][0]) if win.any() else math.nan,
                             float(cut_pos_mm[win][-1]) if win.any() else math.nan),
        chip_ratio=chip.ratio,
        chip_ratio_points=chip.n_points,
        chip_ratio_velocity=r_vel,
        chip_ratio_velocity_points=n_vel,
        chip_thickness_um=chip.thickness * 1e6,
        shear_angle_deg=chip.shear_angle_deg,
        peak_temperature_K=float(np.max(st.temp[st.alive == 1])),
        energy_error=energy_error(en),
        wall_time_s=wall,
        element_updates_per_s=n_el * steps / max(wall, 1e-12),
        steps=int(steps),
        device=device,
        time_step_s=dt0,
        n_elements=n_el,
        n_nodes=int(st.x.shape[0]),
        friction_coefficient=setup.mu,
        friction_law=cfg.friction_law(),
        uncut_chip_thickness_um=cfg.cut.uncut_chip_thickness_um,
        cutting_speed_m_per_min=cfg.cut.cutting_speed_m_per_min,
        eroded_damage=int(np.sum(st.alive == 0)),
        eroded_distortion=int(np.sum(st.alive == -1)),
        eroded_chip_mass_fraction=float(
            np.sum(st.area0[(st.alive != 1) & setup.mesh.chip])
            / max(np.sum(st.area0[setup.mesh.chip]), 1e-300)),
        energy_external_J_per_m=float(en[layout.E_EXT]),
        energy_plastic_J_per_m=float(en[layout.E_PLAST]),
        energy_hourglass_J_per_m=float(en[layout.E_HG]),
        energy_contact_J_per_m=float(en[layout.E_FRIC]),
        energy_kinetic_J_per_m=float(en[layout.E_KIN]),
        energy_internal_J_per_m=float(en[layout.E_INT]),
        hourglass_fraction=float(en[layout.E_HG] / max(en[layout.E_INT], 1e-300)),
        force_by_face_N_per_mm=by_face,
        tool_support=support,
    )
    history = {
        "time_s": t,
        "cut_length_mm": cut_pos_mm,
        "cutting_force_N_per_mm": fc,
        "feed_force_N_per_mm": ff,
        "tool_dx_um": hh[:, layout.H_UX] * 1e6,
        "tool_dy_um": hh[:, layout.H_UY] * 1e6,
        "tool_tip_x_mm": hh[:, layout.H_TIP_X] * 1e3,
        "contact_nodes": hh[:, layout.H_NCONT],
        "energy_external_J_per_m": hh[:, layout.H_EEXT],
        "energy_kinetic_J_per_m": hh[:, layout.H_EKIN],
        "energy_internal_J_per_m": hh[:, layout.H_EINT],
        "energy_plastic_J_per_m": hh[:, layout.H_EPL],
        "energy_hourglass_J_per_m": hh[:, layout.H_EHG],
        "energy_contact_J_per_m": hh[:, layout.H_EFRIC],
        "energy_eroded_J_per_m": hh[:, layout.H_EERO],
    }
    if has_faces:
        for j, face in enumerate(layout.FACES):
            history[f"{face}_cutting_force_N_per_mm"] = faces[:, 2 * j]
            history[f"{face}_feed_force_N_per_mm"] = faces[:, 2 * j + 1]
    return FEResult(summary=summary, history=history, config=cfg.model_dump(),
                    final=_final_fields(setup))
