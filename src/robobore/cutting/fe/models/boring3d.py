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

from robobore.cutting.fe.config.boring3d import BoringFEConfig
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.chunk_driver import energy_check, energy_error
from robobore.cutting.fe.engine.state3d import FEState3
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.models.boring_setup import BoringSetup
from robobore.cutting.fe.models.choose import choose_boring
from robobore.cutting.fe.models.results import (
    XYZ,
    BoringSummary,
    ComponentComparison,
    Energies3D,
    MechanisticComparison,
    RotatingForce,
    ToolSupport3D,
)
from robobore.cutting.geometry import chip_area

__all__ = ["setup_boring", "simulate_boring", "BoringFEResult", "compare_with_mechanistic",
           "write_vtk", "check_boring_device"]


def setup_boring(cfg: BoringFEConfig, source: str | None = None) -> BoringSetup:
    """Mesh, insert, support and state for ``cfg``, on the frame the config chooses
    (:func:`robobore.cutting.fe.models.choose.choose_boring`)."""
    return choose_boring(cfg, source=source).setup(source)


@dataclass(frozen=True)
class BoringFEResult:
    """Outcome of a 3D boring run: its figures, histories and the final state."""

    #: the run's figures (:class:`robobore.cutting.fe.models.results.BoringSummary`)
    summary: BoringSummary
    #: arrays over the samples, named with their unit (``time_s``, ``force_X_N``...)
    history: dict[str, np.ndarray]
    #: the model as set up, its state at the end of the run
    setup: BoringSetup

    def to_dict(self) -> dict[str, Any]:
        """The summary's JSON (the keys ``robobore fe boring --json`` writes before the
        mechanistic comparison and the warnings)."""
        return self.summary.to_dict()


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
    """ConfigError for an unknown device, the GPU with the tool frame (the default frame;
    its ALE pass runs on the CPU only) or a GPU that is not there
    (:func:`robobore.cutting.fe.models.choose.choose_boring`)."""
    choose_boring(cfg, device, source)


def simulate_boring(cfg: BoringFEConfig, *, source: str | None = None,
                    progress: Callable[[float], None] | None = None,
                    device: str = "cpu") -> BoringFEResult:
    """Set up and run the boring model; returns a :class:`BoringFEResult`.

    ``device``: "cpu" (numba, parallel) or "gpu" (numba-cuda,
    :mod:`robobore.cutting.fe.engine.gpu.backend3d`).
    """
    from robobore.cutting.forces import rotating_to_boring

    model = choose_boring(cfg, device, source)
    setup = model.setup(source)
    st = setup.state
    dt0 = float(st.clock[1])
    mass0 = float(np.sum(st.vol0))
    check = energy_check(setup.t_contact, setup.t_end, cfg.solver.energy_error_limit)
    t0 = time.perf_counter()
    steps = model.advance(st, setup.t_end, progress=progress, check=check, spec=setup.spec)
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
    facts = model.mesh_facts(setup, hh, mass0)
    support = None
    feed_amp = None
    if cfg.tool_support is not None:
        k = cfg.tool_support.total_stiffness()
        uz = hh[:, scalar3d.H_UZ] * 1e6
        mean_z, feed_amp = _mean_amp(uz[win])
        support = ToolSupport3D(
            tool_dz_mean_um=mean_z,
            tool_dz_static_um=fz_m / k[2] * 1e6 if k[2] > 0 else math.nan,
            tool_dx_mean_um=float(np.mean(hh[win, scalar3d.H_UX]) * 1e6),
            tool_dy_mean_um=float(np.mean(hh[win, scalar3d.H_UY]) * 1e6))
    fb_amp = 0.5 * (FB.max(axis=1) - FB.min(axis=1))
    summary = BoringSummary(
        force_rotating_N=RotatingForce(ft_m, fr_m, fz_m),
        force_rotating_std_N=RotatingForce(float(np.std(Ft[win])), float(np.std(Fr[win])),
                                           float(np.std(Fz[win]))),
        force_mean_N=XYZ(*(float(v) for v in FB.mean(axis=1))),
        force_amplitude_N=XYZ(*(float(v) for v in fb_amp)),
        force_at_run_angle_N=XYZ(*(float(np.mean(v[win])) for v in FBt)),
        bar_angle_deg=(float(np.degrees(thr[0])), float(np.degrees(thr[-1]))),
        averaging_window_mm=(float(cut_mm[win][0]), float(cut_mm[win][-1])),
        chip_area_mm2=chip_area(setup.insert, setup.ap, setup.f) * 1e6,
        chip_max_height_um=float((np.max(st.y[~st.ndead]) - facts.top) * 1e6),
        peak_temperature_K=float(np.max(st.temp[alive])) if alive.any() else math.nan,
        energy_error=energy_error(en),
        energy_J=Energies3D(
            external=float(en[layout.E_EXT]), kinetic=float(en[layout.E_KIN]),
            internal=float(en[layout.E_INT]), plastic=float(en[layout.E_PLAST]),
            hourglass=float(en[layout.E_HG]), contact=float(en[layout.E_FRIC]),
            eroded=float(en[layout.E_ERODED])),
        hourglass_fraction=float(en[layout.E_HG] / max(en[layout.E_INT], 1e-300)),
        feed_amplitude_um=feed_amp,
        wall_time_s=wall,
        element_updates_per_s=n_el * steps / max(wall, 1e-12),
        steps=int(steps),
        time_step_s=dt0,
        n_elements=n_el,
        n_nodes=int(st.x.shape[0]),
        frame=model.frame,
        element_size_um=cfg.mesh.element_size_um,
        cutting_speed_m_per_min=setup.vc * 60.0,
        friction_coefficient=float(st.prm[layout3d.P_MU]),
        friction_law=cfg.friction_law(),
        sliding_speed_mean_m_per_s=_mean_sliding_speed(st),
        separation=facts.separation,
        pairs_parted=int(np.sum((st.twin >= 0) & (st.tied == 0)) // 2),
        eroded_damage=int(np.sum(st.alive == 0)),
        eroded_distortion=int(np.sum(st.alive == -1)),
        device=device,
        toolframe_mesh=facts.toolframe_mesh,
        mesh_shape=facts.mesh_shape,
        tool_support=support,
    )
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
                             coefficients: str | Path | None = None) -> MechanisticComparison:
    """FE rotating-frame forces vs the mechanistic boring model at the same condition.

    ``coefficients``: a coefficients file
    (:func:`robobore.cutting.coefficient_files.load_coefficients`) -- e.g. the FE-calibrated
    one -- or None for the default TC4 coefficients
    (:func:`robobore.cutting.coefficient_sets.ti64_coefficients` at the run's cutting speed).
    Returns per component (tangential, radial, feed) the FE and model forces [N] and the
    relative difference (FE - model) / |model|, with the coefficients' provenance
    (:class:`~robobore.cutting.fe.models.results.MechanisticComparison`).
    """
    from robobore.cutting.coefficient_files import load_coefficients
    from robobore.cutting.coefficient_sets import ti64_coefficients
    from robobore.cutting.forces import boring_forces

    s = result.setup
    coef = (ti64_coefficients(s.vc * 60.0) if coefficients is None
            else load_coefficients(coefficients, s.vc * 60.0))
    mech = boring_forces(s.insert, s.ap, s.f, coef)
    fe = result.summary.force_rotating_N.to_dict()
    parts = {}
    for comp, key in (("tangential", "tangential_N"), ("radial", "radial_N"),
                      ("feed", "feed_N")):
        m = float(mech[key])
        parts[comp] = ComponentComparison(
            fe_N=fe[comp], model_N=m,
            relative_difference=(fe[comp] - m) / abs(m) if m != 0 else math.nan)
    return MechanisticComparison(
        coefficients=coef.provenance if hasattr(coef, "provenance") else str(coefficients),
        **parts)


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
