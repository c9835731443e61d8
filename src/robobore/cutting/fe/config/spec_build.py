"""From a validated FE config to its :class:`~robobore.cutting.fe.config.spec.ModelSpec`.

:func:`build_spec` (2D orthogonal) and :func:`build_boring_spec` (3D boring) choose each
variant of :mod:`robobore.cutting.fe.config.spec` from the config's keys and raise a
ConfigError naming any key the config gives that the chosen variants have no place for
(:data:`MODEL_KEYS`, :data:`BORING_MODEL_KEYS`); :func:`friction_spec` and
:func:`thermal_spec` are the friction and thermal parts both share.
"""

from __future__ import annotations

import math
from typing import Any

from robobore.cutting.fe.config.spec import (
    Adiabatic,
    BBarQuad,
    Conduction,
    CoulombFriction,
    EdgePathLayer,
    ErosionLayer,
    HardeningHold,
    HexElement,
    ModelSpec,
    NodeSplit,
    OnePointQuad,
    PlainHardening,
    SlidingSpeedFriction,
    ToolFrame,
    ToolFrame3D,
    WorkpieceFrame,
    WorkpieceFrame3D,
)
from robobore.errors import ConfigError
from robobore.material.library import Material

__all__ = ["build_spec", "build_boring_spec", "friction_spec", "thermal_spec", "MODEL_KEYS",
           "BORING_MODEL_KEYS"]


#: the keys of an FE config that belong to one model variant (checked by build_spec: a key
#: the chosen variants do not read is an error)
MODEL_KEYS = (
    "mesh.separation", "mesh.separation_layer", "mesh.separation_height_um",
    "mesh.edge_band_um", "mesh.initial_chip_ratio", "mesh.join_height_um",
    "mesh.chip_length_um", "mesh.depth_um", "mesh.inflow_length_um", "mesh.back_length_um",
    "mesh.fine_depth_factor", "mesh.height_factor", "mesh.grading", "mesh.ahead_mm",
    "solver.element", "solver.erosion", "solver.separation_gate_um",
    "solver.erode_time_step_fraction", "solver.ale_interval", "solver.hourglass_viscous",
    "solver.hourglass_stiffness", "solver.conduction_interval",
    "contact.thermal_conductance_W_per_m2K", "contact.friction_heat_fraction",
    "contact.tool_temperature_K",
)

#: what each variant is, for the message naming a key it has no place for
_VARIANT_TEXT = {
    "tool": 'mesh.frame = "tool" (the tool-frame ALE model: no separation, no damage or '
            "time-step erosion, the one-point quad, its own mesh keys)",
    "node_split": 'mesh.separation = "node_split" (no erosion layer: the parting line and '
                  "its gate)",
    "erosion_layer": 'mesh.separation = "erosion_layer" (no parting line: the layer, its '
                     "position and erosion)",
    "workpiece": 'mesh.frame = "workpiece" (no tool-frame ALE mesh)',
    "tool3d": 'mesh.frame = "tool" (the default: the 3D tool-frame ALE model, no workpiece '
              "block, no separation, no damage or time-step erosion; the key belongs to "
              'mesh.frame = "workpiece")',
    "bbar": 'solver.element = "q4_bbar" (no hourglass modes: no hourglass coefficients)',
    "adiabatic": "solver.heat_conduction = false (adiabatic: no conduction interval, no "
                 "thermal contact with the tool)",
}


class _Keys:
    """The keys a config gives (explicitly, in the TOML) and those the spec reads."""

    def __init__(self, cfg: Any, model_keys: tuple[str, ...] = MODEL_KEYS) -> None:
        self.cfg = cfg
        self.model_keys = model_keys
        self.given = {f"{sec}.{k}" for sec in ("mesh", "solver", "contact")
                      for k in getattr(cfg, sec).model_fields_set}
        self.read: set[str] = set()
        self.owner: dict[str, str] = {}

    def get(self, key: str) -> Any:
        self.read.add(key)
        sec, name = key.split(".")
        return getattr(getattr(self.cfg, sec), name)

    def exclude(self, variant: str, *keys: str) -> None:
        """``keys`` have no place in ``variant`` (the message's reason)."""
        for key in keys:
            self.owner.setdefault(key, variant)

    def check(self, source: str | None) -> None:
        for key in self.model_keys:
            if key in self.given and key not in self.read:
                variant = self.owner.get(key)
                why = _VARIANT_TEXT.get(variant or "", "the chosen model")
                raise ConfigError("key not used by the chosen model", file=source, field=key,
                                  value=self.get(key),
                                  expected=f"no value with {why}; remove the key")


def friction_spec(contact: Any, vc_m_per_min: float) -> CoulombFriction | SlidingSpeedFriction:
    """The friction of a validated ``[contact]`` section (2D, or the 3D one built on it) at
    the cutting speed ``vc_m_per_min``."""
    c = contact
    if c.friction == "table" and c.friction_velocity == "sliding":
        tv, tmu = c.table()
        return SlidingSpeedFriction(
            velocity_m_per_min=tuple(float(v) for v in tv), mu=tuple(float(m) for m in tmu),
            filter_um=float(c.sliding_filter_um), nominal_mu=c.coefficient_at(vc_m_per_min),
            shear_limit_MPa=float(c.shear_limit_MPa))
    return CoulombFriction(mu=c.coefficient_at(vc_m_per_min),
                           shear_limit_MPa=float(c.shear_limit_MPa))


def thermal_spec(solver: Any, contact: Any, material: Material) -> Adiabatic | Conduction:
    """The thermal model of a validated ``[solver]`` and ``[contact]`` (2D or 3D): conduction
    with the thermal contact (tool temperature None: the material's room temperature), or
    adiabatic."""
    if not solver.heat_conduction:
        return Adiabatic()
    tt = contact.tool_temperature_K
    return Conduction(interval=int(solver.conduction_interval),
                      conductance_W_per_m2K=float(contact.thermal_conductance_W_per_m2K),
                      friction_heat_fraction=float(contact.friction_heat_fraction),
                      tool_temperature_K=float(material.T_room if tt is None else tt))


#: The keys that the heat conduction reads (and that an adiabatic run leaves unused).
THERMAL_KEYS = ("solver.conduction_interval", "contact.thermal_conductance_W_per_m2K",
                "contact.friction_heat_fraction", "contact.tool_temperature_K")


def _thermal_keys(keys: _Keys, heat_conduction: bool) -> None:
    """Mark the thermal keys read (with heat conduction) or excluded as "adiabatic"."""
    if heat_conduction:
        for key in THERMAL_KEYS:
            keys.get(key)
    else:
        keys.exclude("adiabatic", *THERMAL_KEYS)


def build_spec(cfg: Any, material: Material, source: str | None = None) -> ModelSpec:
    """The :class:`ModelSpec` of a validated orthogonal FE config ``cfg`` (``material``: the
    config's material as loaded, whose ``hardening_strain_limit`` is the hold in force).

    Raises ConfigError naming a key the config gives that the chosen variants have no place
    for (for example ``mesh.separation`` with ``mesh.frame = "tool"``, or
    ``contact.tool_temperature_K`` with ``solver.heat_conduction = false``)."""
    keys = _Keys(cfg)
    tool_frame_keys = ("mesh.initial_chip_ratio", "mesh.join_height_um", "mesh.chip_length_um",
                       "mesh.depth_um", "mesh.inflow_length_um", "mesh.back_length_um",
                       "solver.ale_interval")
    workpiece_mesh_keys = ("mesh.fine_depth_factor", "mesh.height_factor", "mesh.grading",
                           "mesh.ahead_mm")
    hourglass = ("solver.hourglass_viscous", "solver.hourglass_stiffness")
    if cfg.mesh.frame.is_tool:
        keys.exclude("tool", "mesh.separation", "mesh.separation_layer",
                     "mesh.separation_height_um", "mesh.edge_band_um", *workpiece_mesh_keys,
                     "solver.element",
                     "solver.erosion", "solver.separation_gate_um",
                     "solver.erode_time_step_fraction")
        for key in tool_frame_keys:
            keys.get(key)
        frame: ToolFrame | WorkpieceFrame = ToolFrame(
            ale_interval=int(keys.get("solver.ale_interval")),
            element=OnePointQuad(float(keys.get(hourglass[0])), float(keys.get(hourglass[1]))))
    else:
        keys.exclude("workpiece", *tool_frame_keys)
        for key in workpiece_mesh_keys:
            keys.get(key)
        sep: NodeSplit | ErosionLayer
        if keys.get("mesh.separation") == "node_split":
            keys.exclude("node_split", "mesh.separation_layer", "solver.erosion")
            keys.get("mesh.edge_band_um")
            h = keys.get("mesh.separation_height_um")
            gate = keys.get("solver.separation_gate_um")
            sep = NodeSplit(height_um=0.0 if h is None else float(h),
                            gate_um=0.0 if gate is None else float(gate))
        else:
            keys.exclude("erosion_layer", "mesh.edge_band_um")
            gate = keys.get("solver.separation_gate_um")
            h = keys.get("mesh.separation_height_um")
            sep = ErosionLayer(position=keys.get("mesh.separation_layer"),
                               height_um=None if h is None else float(h),
                               damage_erosion=keys.get("solver.erosion") == "layer",
                               gate_um=None if gate is None else float(gate))
        if keys.get("solver.element") == "q4_bbar":
            keys.exclude("bbar", *hourglass)
            element: OnePointQuad | BBarQuad = BBarQuad()
        else:
            element = OnePointQuad(float(keys.get(hourglass[0])), float(keys.get(hourglass[1])))
        frame = WorkpieceFrame(separation=sep, element=element,
                               erode_time_step_fraction=float(
                                   keys.get("solver.erode_time_step_fraction")))
    friction = friction_spec(cfg.contact, cfg.cut.cutting_speed_m_per_min)
    _thermal_keys(keys, cfg.solver.heat_conduction)
    thermal = thermal_spec(cfg.solver, cfg.contact, material)
    limit = material.hardening_strain_limit
    hardening: PlainHardening | HardeningHold = (
        HardeningHold(float(limit)) if limit is not None and math.isfinite(limit)
        else PlainHardening())
    keys.check(source)
    return ModelSpec(frame=frame, friction=friction, thermal=thermal, hardening=hardening)


#: the keys of a 3D boring config that belong to one model variant (see MODEL_KEYS)
BORING_MODEL_KEYS = (
    "mesh.separation_height_um", "mesh.chip_rows", "solver.separation_gate_um",
    "mesh.depth_factor", "mesh.side_margin_um", "mesh.ahead_mm", "mesh.separation",
    "solver.erosion", "solver.erode_time_step_fraction", "mesh.edge_element_um",
    "mesh.slice_spacing_um", "mesh.t_min_um", "mesh.margin_slices", "mesh.initial_chip_ratio",
    "solver.ale_interval", "solver.thin_element_mass_scaling",
    "solver.conduction_interval", "contact.thermal_conductance_W_per_m2K",
    "contact.friction_heat_fraction", "contact.tool_temperature_K",
)


def build_boring_spec(cfg: Any, material: Material, vc_m_per_min: float,
                      source: str | None = None) -> ModelSpec:
    """The :class:`ModelSpec` (a 3D frame) of a validated 3D boring config (``material`` as
    loaded, ``vc_m_per_min`` the cutting speed at the bore wall). Raises ConfigError naming a
    key the config gives that the chosen variants have no place for (for example
    ``solver.separation_gate_um`` with ``mesh.separation = "erosion_layer"``)."""
    keys = _Keys(cfg, BORING_MODEL_KEYS)
    sep: NodeSplit | EdgePathLayer | None
    tool_keys = ("mesh.edge_element_um", "mesh.slice_spacing_um", "mesh.t_min_um",
                 "mesh.margin_slices", "mesh.initial_chip_ratio", "solver.ale_interval",
                 "solver.thin_element_mass_scaling")
    if cfg.mesh.frame.is_tool:
        keys.exclude("tool3d", "mesh.depth_factor", "mesh.side_margin_um", "mesh.ahead_mm",
                     "mesh.separation", "mesh.separation_height_um", "mesh.chip_rows",
                     "solver.erosion", "solver.separation_gate_um",
                     "solver.erode_time_step_fraction")
        for key in tool_keys:
            keys.get(key)
        sep = None
    else:
        keys.exclude("workpiece", *tool_keys)
        for key in ("mesh.depth_factor", "mesh.side_margin_um", "mesh.ahead_mm",
                    "mesh.separation", "solver.erosion", "solver.erode_time_step_fraction"):
            keys.get(key)
        if cfg.mesh.separation == "node_split":
            keys.get("mesh.chip_rows")
            sep = NodeSplit(height_um=float(keys.get("mesh.separation_height_um")),
                            gate_um=float(keys.get("solver.separation_gate_um")))
        else:
            keys.exclude("erosion_layer", "mesh.separation_height_um", "mesh.chip_rows",
                         "solver.separation_gate_um")
            sep = EdgePathLayer()
    _thermal_keys(keys, cfg.solver.heat_conduction)
    s = cfg.solver
    limit = material.hardening_strain_limit
    keys.check(source)
    element = HexElement(float(s.hourglass_viscous), float(s.hourglass_stiffness))
    frame: ToolFrame3D | WorkpieceFrame3D = (
        ToolFrame3D(ale_interval=int(s.ale_interval), element=element,
                    thin_element_mass_scaling=bool(s.thin_element_mass_scaling))
        if sep is None else
        WorkpieceFrame3D(separation=sep, damage_erosion=s.erosion == "layer",
                         erode_time_step_fraction=float(s.erode_time_step_fraction),
                         element=element))
    return ModelSpec(
        frame=frame,
        friction=friction_spec(cfg.contact, vc_m_per_min),
        thermal=thermal_spec(s, cfg.contact, material),
        hardening=(HardeningHold(float(limit)) if limit is not None and math.isfinite(limit)
                   else PlainHardening()))
