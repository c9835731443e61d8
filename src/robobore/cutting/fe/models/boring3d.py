"""The paper's equivalent 3D FE boring model: an insert with nose radius cutting the bore wall.

Model (all choices documented in ``docs/fe3d.md``; the configuration schema is
:mod:`robobore.cutting.fe.config.boring3d`, the mesh builder
:mod:`robobore.cutting.fe.mesh.boring3d`; this module sets the model up, runs it and
compares it with the mechanistic model):

* **Workpiece** -- a block of the bore wall, *locally flat* (the wall unrolled): for a bore
  diameter D >> the chip (D = 40 mm vs a 0.3 mm cut length: sagitta L^2 / (4 D) ~ 0.6 um, 1 %
  of ap = 50 um) the curvature is negligible. Local frame: x along the cutting velocity of
  the insert (tangent to the circle, e_t), y normal to the wall pointing out of the material
  (towards the bore axis, -e_r), z along the feed (bore axis, e_z). The top surface carries
  the **feed marks of the previous revolution**: ``y_top(z) = min(ap, drop(z + f))`` with
  ``drop`` the insert's edge profile (:meth:`robobore.cutting.geometry.BoringInsert.drop`),
  so the material above the current edge profile ``drop(z)`` is exactly the boring chip of
  the mechanistic model (area ``ap f - scallop``). The new bore surface is y = 0.
* **Insert** -- rigid, analytic signed distance (:func:`hex.scalar3d.insert_gap3_py`): nose
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
from typing import Any

import numpy as np

from robobore.cutting.fe.config.boring3d import (
    BoringFEConfig,
    load_boring_config,
    parse_boring_config,
)
from robobore.cutting.fe.config.spec import build_boring_spec
from robobore.cutting.fe.engine import kernels3d as K3
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import energy_check
from robobore.cutting.fe.engine.state3d import (
    FEState3,
    advance3,
    energy_error,
    make_state3,
)
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.mesh.boring3d import BoringMesh, build_boring_mesh, parting_surface
from robobore.cutting.fe.models.boring_setup import BoringSetup, boring_prm, check_support_step
from robobore.cutting.geometry import chip_area
from robobore.errors import ConfigError
from robobore.material import load_material

__all__ = ["BoringFEConfig", "load_boring_config", "parse_boring_config", "BoringMesh",
           "build_boring_mesh", "parting_surface", "BoringSetup", "setup_boring", "simulate_boring",
           "BoringFEResult", "compare_with_mechanistic", "write_vtk", "boring_prm",
           "check_support_step", "check_boring_device"]


def setup_boring(cfg: BoringFEConfig, source: str | None = None) -> BoringSetup:
    """Mesh, insert, support and state for ``cfg`` (``mesh.frame = "tool"``:
    :func:`robobore.cutting.fe.models.toolframe3d.setup_boring_toolframe`)."""
    if cfg.mesh.frame == "tool":
        from robobore.cutting.fe.models.toolframe3d import setup_boring_toolframe

        return setup_boring_toolframe(cfg, source)
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
    if st.prm[layout3d.P_MUTAB_N] <= 0.0 or not inc.any():
        return None
    return float(np.mean(st.cf[inc, 3]))


def _mean_amp(v: np.ndarray) -> tuple[float, float]:
    return float(np.mean(v)), float(0.5 * (np.max(v) - np.min(v)))


def check_boring_device(cfg: BoringFEConfig, device: str, source: str | None = None) -> None:
    """ConfigError for the GPU with the tool frame (the default frame; its ALE pass runs on
    the CPU only)."""
    if device == "gpu" and cfg.mesh.frame == "tool":
        raise ConfigError("the 3D tool-frame model (the default mesh.frame) runs on the CPU "
                          "only", file=source, field="--device", value=device,
                          expected='cpu, or set [mesh] frame = "workpiece" in the config for '
                          "the GPU (the workpiece-frame model: radial and feed forces 22-38 % "
                          "low at the paper's condition, docs/fe3d.md)")


def simulate_boring(cfg: BoringFEConfig, *, source: str | None = None,
                    progress: Callable[[float], None] | None = None,
                    device: str = "cpu") -> BoringFEResult:
    """Set up and run the boring model; returns a :class:`BoringFEResult`.

    ``device``: "cpu" (numba, parallel) or "gpu" (numba-cuda,
    :mod:`robobore.cutting.fe.engine.gpu.backend3d`).
    """
    from robobore.cutting.forces import rotating_to_boring

    check_boring_device(cfg, device, source)
    setup = setup_boring(cfg, source)
    st = setup.state
    dt0 = float(st.clock[1])
    mass0 = float(np.sum(st.vol0))
    limit = cfg.solver.energy_error_limit

    check = energy_check(setup.t_contact, setup.t_end, limit)

    t0 = time.perf_counter()
    if device == "gpu":
        from robobore.cutting.fe.engine.gpu.backend3d import advance3_gpu

        steps = advance3_gpu(st, setup.t_end, chunk_steps=cfg.solver.chunk_steps,
                             progress=progress, check=check)
    elif device == "cpu":
        steps = advance3(st, setup.t_end, chunk_steps=cfg.solver.chunk_steps,
                         progress=progress, check=check,
                         step=None if setup.spec is None else K3.run_chunk3_for(setup.spec))
    else:
        raise ConfigError("unknown device", field="--device", value=device,
                          expected="cpu or gpu")
    wall = time.perf_counter() - t0
    hh = st.hist[np.isfinite(st.hist[:, scalar3d.H_T])]
    t = hh[:, scalar3d.H_T]
    L = cfg.cut.cut_length_mm * 1e-3
    t0w = setup.t_end - cfg.solver.steady_window_fraction * L / setup.vc
    win = t >= t0w
    if not win.any():
        win = np.ones_like(t, bool)
    Ft = -hh[:, scalar3d.H_FX]
    Fr = -hh[:, scalar3d.H_FY]
    Fz = hh[:, scalar3d.H_FZ]
    ft_m, fr_m, fz_m = float(np.mean(Ft[win])), float(np.mean(Fr[win])), float(np.mean(Fz[win]))
    th = np.linspace(0.0, 2 * np.pi, 360, endpoint=False)
    FB = rotating_to_boring(ft_m, fr_m, fz_m, th)
    thr = hh[:, scalar3d.H_THETA]
    FBt = rotating_to_boring(1.0, 0.0, 0.0, thr) * Ft + rotating_to_boring(0.0, 1.0, 0.0, thr) \
        * Fr + rotating_to_boring(0.0, 0.0, 1.0, thr) * Fz
    en = st.en
    n_el = st.n_elements
    cut_mm = (hh[:, scalar3d.H_TIPX] - setup.x_cut_start) * 1e3
    alive = st.alive == 1
    # the pre-bore surface's highest point: the workpiece block's top; ap in the tool frame
    # (whose initial mesh carries the pre-shaped chip above it)
    ytop_max = (setup.ap if cfg.mesh.frame == "tool"
                else float(np.max(setup.mesh.nodes[:, 1])))
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
        "energy_J": {"external": float(en[layout.E_EXT]), "kinetic": float(en[layout.E_KIN]),
                     "internal": float(en[layout.E_INT]), "plastic": float(en[layout.E_PLAST]),
                     "hourglass": float(en[layout.E_HG]), "contact": float(en[layout.E_FRIC]),
                     "eroded": float(en[layout.E_ERODED])},
        "hourglass_fraction": float(en[layout.E_HG] / max(en[layout.E_INT], 1e-300)),
        "feed_amplitude_um": None,
        "wall_time_s": wall,
        "element_updates_per_s": n_el * steps / max(wall, 1e-12),
        "steps": int(steps),
        "time_step_s": dt0,
        "n_elements": n_el,
        "n_nodes": int(st.x.shape[0]),
        "frame": cfg.mesh.frame,
        "element_size_um": cfg.mesh.element_size_um,
        "cutting_speed_m_per_min": setup.vc * 60.0,
        "friction_coefficient": float(st.prm[layout3d.P_MU]),
        "friction_law": cfg.friction_law(),
        "sliding_speed_mean_m_per_s": _mean_sliding_speed(st),
        "separation": cfg.mesh.separation if cfg.mesh.frame == "workpiece" else None,
        "pairs_parted": int(np.sum((st.twin >= 0) & (st.tied == 0)) // 2),
        "eroded_damage": int(np.sum(st.alive == 0)),
        "eroded_distortion": int(np.sum(st.alive == -1)),
        "device": device,
    }
    if cfg.mesh.frame == "tool":
        from robobore.cutting.fe.models.toolframe3d import toolframe_mesh_summary

        summary["toolframe_mesh"] = toolframe_mesh_summary(setup.mesh)
        # material in the mesh at the end over the start (inflow - outflow of the passes)
        summary["toolframe_mesh"]["mass_ratio"] = float(np.sum(st.vol0)) / mass0
        if st.msf.shape[0] > 0:
            # the inertia added to the thin chip elements (thin_element_factors)
            summary["toolframe_mesh"]["inertia_factor_max"] = float(np.max(st.msf))
            summary["toolframe_mesh"]["inertia_factor_elements"] = int(np.sum(st.msf > 1.0))
            summary["toolframe_mesh"]["added_inertia_fraction"] = float(
                np.sum(st.vol0 * (st.msf - 1.0)) / np.sum(st.vol0))
    else:
        summary["mesh_shape"] = list(setup.mesh.shape)
    if cfg.tool_support is not None:
        if cfg.mesh.frame == "tool":
            # the insert's deflection along the wall normal (local y; tool_kinematics_py),
            # which the tool-frame mesh's placement does not follow, against the edge element
            uy = -np.cos(thr) * hh[:, scalar3d.H_UX] - np.sin(thr) * hh[:, scalar3d.H_UY]
            tf = summary["toolframe_mesh"]
            tf["radial_deflection_max_um"] = float(np.max(np.abs(uy))) * 1e6
            tf["edge_element_um"] = setup.mesh.sizes.edge * 1e6
        k = cfg.tool_support.total_stiffness()
        uz = hh[:, scalar3d.H_UZ] * 1e6
        mean_z, amp_z = _mean_amp(uz[win])
        summary.update({
            "feed_amplitude_um": amp_z,
            "tool_dz_mean_um": mean_z,
            "tool_dz_static_um": fz_m / k[2] * 1e6 if k[2] > 0 else math.nan,
            "tool_dx_mean_um": float(np.mean(hh[win, scalar3d.H_UX]) * 1e6),
            "tool_dy_mean_um": float(np.mean(hh[win, scalar3d.H_UY]) * 1e6),
        })
    history = {
        "time_s": t, "cut_length_mm": cut_mm, "bar_angle_rad": thr,
        "force_tangential_N": Ft, "force_radial_N": Fr, "force_feed_N": Fz,
        "force_X_N": FBt[0], "force_Y_N": FBt[1], "force_Z_N": FBt[2],
        "tool_dX_um": hh[:, scalar3d.H_UX] * 1e6, "tool_dY_um": hh[:, scalar3d.H_UY] * 1e6,
        "tool_dZ_um": hh[:, scalar3d.H_UZ] * 1e6, "contact_nodes": hh[:, scalar3d.H_NCONT],
        "energy_external_J": hh[:, scalar3d.H_EEXT], "energy_kinetic_J": hh[:, scalar3d.H_EKIN],
        "energy_internal_J": hh[:, scalar3d.H_EINT], "energy_hourglass_J": hh[:, scalar3d.H_EHG],
        "energy_contact_J": hh[:, scalar3d.H_EFRIC],
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
