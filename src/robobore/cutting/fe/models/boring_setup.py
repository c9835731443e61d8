"""The set-up shared by the two frames of the 3D boring model
(:mod:`robobore.cutting.fe.models.boring3d`: workpiece frame; :mod:`robobore.cutting.fe.models.
toolframe3d`: tool frame): the :class:`BoringSetup` record, the parameter vector of a boring
config (:func:`boring_prm`) and the tool support's step check (:func:`check_support_step`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.cutting.fe.config.boring3d import BoringFEConfig
from robobore.cutting.fe.config.engine_settings import apply_numerics
from robobore.cutting.fe.config.spec import BoringSpec
from robobore.cutting.fe.engine.state3d import FEState3, default_prm3
from robobore.cutting.fe.hex import layout3d
from robobore.cutting.geometry import BoringInsert
from robobore.errors import ConfigError
from robobore.material import Material

__all__ = ["BoringSetup", "boring_prm", "check_support_step"]


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
    spec: BoringSpec | None = None
    #: the insert tip's x [m] at which the cut length is 0
    x_cut_start: float = 0.0


def boring_prm(cfg: BoringFEConfig, spec: BoringSpec, ins: BoringInsert, vc: float,
               f: float) -> np.ndarray:
    """The 3D parameter vector of a boring config (either frame) before the run's times:
    numerics, the spec's model choices, contact, insert, kinematics and tool support."""
    s = cfg.solver
    R = 0.5 * cfg.cut.bore_diameter_mm * 1e-3
    n_rps = cfg.cut.speed_rpm / 60.0
    p = spec.write_prm(apply_numerics(default_prm3(), s, layout3d), layout3d, vc * 60.0)
    p[layout3d.P_PEN] = cfg.contact.penalty_factor
    p[layout3d.P_CDAMP] = cfg.contact.damping_for(spec.tool_frame is not None)
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
