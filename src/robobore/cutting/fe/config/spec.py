"""The model choices of an FE config as a frozen, typed spec (:class:`ModelSpec`).

A validated :class:`~robobore.cutting.fe.config.orthogonal.FEConfig` is a flat set of keys;
the spec is what they choose, one type per variant, each carrying only the values it uses:

* frame: :class:`ToolFrame` (the tool-frame ALE mesh: no separation, no damage erosion, the
  one-point quad) or :class:`WorkpieceFrame` (Lagrangian), whose ``separation`` is a
  :class:`NodeSplit` (parting line and its gate) or an :class:`ErosionLayer` (its position,
  damage erosion on or off, optional gate), and whose ``element`` is a :class:`OnePointQuad`
  (with its hourglass coefficients) or a :class:`BBarQuad` (none);
* friction: :class:`CoulombFriction` (one coefficient for the run: a constant, or a table read
  at the cutting speed) or :class:`SlidingSpeedFriction` (the table read at each contact
  node's filtered sliding speed);
* thermal: :class:`Adiabatic` or :class:`Conduction` (interval and the thermal contact with
  the tool);
* hardening: :class:`PlainHardening` or :class:`HardeningHold` (the plastic strain beyond
  which the Johnson-Cook hardening term is held).

A combination without a meaning (a gate in the tool frame, a B-bar element with hourglass
coefficients, a tool temperature in an adiabatic run) has no type to be built from.
:func:`build_spec` builds the spec from the config and raises a ConfigError naming any key the
config gives that the chosen variants have no place for. :meth:`ModelSpec.write_prm` writes
the model-choice slots of an engine's parameter vector, in one place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from robobore.errors import ConfigError
from robobore.material import Material

__all__ = [
    "ToolFrame", "NodeSplit", "ErosionLayer", "OnePointQuad", "BBarQuad", "WorkpieceFrame",
    "CoulombFriction", "SlidingSpeedFriction", "Adiabatic", "Conduction", "PlainHardening",
    "HardeningHold", "ModelSpec", "build_spec", "friction_spec", "thermal_spec", "write_friction",
    "write_thermal", "MODEL_KEYS", "HexElement", "EdgePathLayer", "BoringSpec",
    "build_boring_spec", "BORING_MODEL_KEYS", "ToolFrame3D",
]


# --- frame, separation, element

@dataclass(frozen=True)
class OnePointQuad:
    """The one-point quadrilateral with Flanagan-Belytschko hourglass control."""

    hourglass_viscous: float
    hourglass_stiffness: float


@dataclass(frozen=True)
class BBarQuad:
    """The fully integrated B-bar quadrilateral: no hourglass modes, no coefficients."""


@dataclass(frozen=True)
class ToolFrame:
    """The tool-frame ALE mesh: moved back to its place in the tool's frame every
    ``ale_interval`` steps; no separation criterion, no damage or time-step erosion (the mesh
    does not move with the material, and a hole would have no flux rule); the one-point
    quad."""

    ale_interval: int
    element: OnePointQuad
    #: largest node move of an ALE pass, fraction of the local element size
    MAX_MOVE = 0.2


@dataclass(frozen=True)
class NodeSplit:
    """Doubled nodes along a parting line ``height_um`` above the tool's lowest point, tied
    until they come within ``gate_um`` of the tool surface (0: touching)."""

    height_um: float
    gate_um: float


@dataclass(frozen=True)
class ErosionLayer:
    """A one-element layer along the cut line: its position (``position``, or its bottom
    ``height_um`` above the tool's lowest point when given), whether its elements erode when
    their Johnson-Cook damage reaches 1, and the optional gate [um] (erode only with a node
    within it of the tool surface)."""

    position: Literal["above_cut_line", "centred", "below_cut_line"]
    height_um: float | None
    damage_erosion: bool
    gate_um: float | None


@dataclass(frozen=True)
class WorkpieceFrame:
    """The Lagrangian workpiece mesh: its separation, element and time-step erosion (the
    fraction of the initial smallest step below which an element erodes; 0: off)."""

    separation: NodeSplit | ErosionLayer
    element: OnePointQuad | BBarQuad
    erode_time_step_fraction: float


@dataclass(frozen=True)
class HexElement:
    """The 8-node hexahedron of the 3D engine with its hourglass control coefficients."""

    hourglass_viscous: float
    hourglass_stiffness: float


@dataclass(frozen=True)
class EdgePathLayer:
    """3D separation by an erosion layer: the elements crossed by the path of the cutting
    edge."""


# --- friction, thermal, hardening

@dataclass(frozen=True)
class CoulombFriction:
    """One Coulomb coefficient for the whole run (a constant, or a table read at the cutting
    speed), capped by the contact shear stress [MPa]."""

    mu: float
    shear_limit_MPa: float


@dataclass(frozen=True)
class SlidingSpeedFriction:
    """A Coulomb-vs-speed table read at each contact node's sliding speed, low-pass filtered
    over ``filter_um`` of tool travel; ``nominal_mu`` is the table at the cutting speed (for
    summaries); capped by the contact shear stress [MPa]."""

    velocity_m_per_min: tuple[float, ...]
    mu: tuple[float, ...]
    filter_um: float
    nominal_mu: float
    shear_limit_MPa: float


@dataclass(frozen=True)
class Adiabatic:
    """Adiabatic heating only: no conduction, no heat exchange with the tool."""


@dataclass(frozen=True)
class Conduction:
    """Heat conduction every ``interval`` steps, with the thermal contact with the tool."""

    interval: int
    conductance_W_per_m2K: float
    friction_heat_fraction: float
    tool_temperature_K: float


@dataclass(frozen=True)
class PlainHardening:
    """The plain Johnson-Cook law."""


@dataclass(frozen=True)
class HardeningHold:
    """The Johnson-Cook hardening term held at its value beyond ``strain_limit``."""

    strain_limit: float


@dataclass(frozen=True)
class ModelSpec:
    """The model choices of an FE config (see the module docstring)."""

    frame: ToolFrame | WorkpieceFrame
    friction: CoulombFriction | SlidingSpeedFriction
    thermal: Adiabatic | Conduction
    hardening: PlainHardening | HardeningHold

    def write_prm(self, p: np.ndarray, layout: Any, vc_m_per_min: float) -> np.ndarray:
        """Write the model-choice slots of an engine's parameter vector ``p`` (returned):
        frame, separation, element, erosion, friction and thermal slots. ``layout`` is the
        engine's layout module (its ``P_*`` indices and ``ERODE_*`` codes:
        :mod:`robobore.cutting.fe.engine.layout`). The element type,
        the frame and the thermal model also choose the compiled step
        (:func:`robobore.cutting.fe.engine.chunk_loop.step_for`)."""
        k = layout
        fr = self.frame
        if isinstance(fr, ToolFrame):
            element: OnePointQuad | BBarQuad = fr.element
            p[k.P_EROSION] = k.ERODE_NONE
            p[k.P_DT_ERODE] = 0.0
            p[k.P_GATE] = -1.0
            p[k.P_RZ_EVERY] = fr.ale_interval
            p[k.P_RZ_MAXMOVE] = ToolFrame.MAX_MOVE
        else:
            element = fr.element
            sep = fr.separation
            p[k.P_DT_ERODE] = -fr.erode_time_step_fraction
            if isinstance(sep, NodeSplit):
                p[k.P_EROSION] = k.ERODE_NONE
                p[k.P_GATE] = sep.gate_um * 1e-6
            else:
                p[k.P_EROSION] = k.ERODE_LAYER if sep.damage_erosion else k.ERODE_NONE
                p[k.P_GATE] = -1.0 if sep.gate_um is None else sep.gate_um * 1e-6
            p[k.P_RZ_EVERY] = 0
            p[k.P_RZ_MAXMOVE] = ToolFrame.MAX_MOVE
        if isinstance(element, OnePointQuad):
            p[k.P_HGV] = element.hourglass_viscous
            p[k.P_HGS] = element.hourglass_stiffness
        write_friction(p, self.friction, layout, vc_m_per_min)
        write_thermal(p, self.thermal, layout)
        return p


def write_friction(p: np.ndarray, friction: CoulombFriction | SlidingSpeedFriction,
                   layout: Any, vc_m_per_min: float) -> np.ndarray:
    """The friction slots of either engine's parameter vector (``P_MU``, ``P_TAU``; for the
    sliding-speed table ``P_MUTAB_*`` with velocities in m/s and ``P_SLIP_TAU``, the filter's
    time constant: the time the tool takes to travel ``filter_um``)."""
    k = layout
    if isinstance(friction, SlidingSpeedFriction):
        tv = np.asarray(friction.velocity_m_per_min, float)
        p[k.P_MU] = friction.nominal_mu
        p[k.P_MUTAB_N] = tv.size
        p[k.P_MUTAB_V:k.P_MUTAB_V + tv.size] = tv / 60.0
        p[k.P_MUTAB_MU:k.P_MUTAB_MU + tv.size] = np.asarray(friction.mu, float)
        p[k.P_SLIP_TAU] = friction.filter_um * 1e-6 / (vc_m_per_min / 60.0)
    else:
        p[k.P_MU] = friction.mu
    p[k.P_TAU] = friction.shear_limit_MPa * 1e6
    return p


def write_thermal(p: np.ndarray, thermal: Adiabatic | Conduction, layout: Any) -> np.ndarray:
    """The heat slots of either engine's parameter vector (``P_COND_EVERY``: 0 adiabatic;
    ``P_HC``, ``P_FHEAT``, ``P_TTOOL``, read by the conduction passes only)."""
    k = layout
    if isinstance(thermal, Conduction):
        p[k.P_COND_EVERY] = thermal.interval
        p[k.P_HC] = thermal.conductance_W_per_m2K
        p[k.P_FHEAT] = thermal.friction_heat_fraction
        p[k.P_TTOOL] = thermal.tool_temperature_K
    else:
        p[k.P_COND_EVERY] = 0
        p[k.P_HC] = 0.0
        p[k.P_FHEAT] = 0.0
    return p


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
    if cfg.mesh.frame == "tool":
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
    if cfg.solver.heat_conduction:
        for key in ("solver.conduction_interval", "contact.thermal_conductance_W_per_m2K",
                    "contact.friction_heat_fraction", "contact.tool_temperature_K"):
            keys.get(key)
    else:
        keys.exclude("adiabatic", "solver.conduction_interval",
                     "contact.thermal_conductance_W_per_m2K", "contact.friction_heat_fraction",
                     "contact.tool_temperature_K")
    thermal = thermal_spec(cfg.solver, cfg.contact, material)
    limit = material.hardening_strain_limit
    hardening: PlainHardening | HardeningHold = (
        HardeningHold(float(limit)) if limit is not None and math.isfinite(limit)
        else PlainHardening())
    keys.check(source)
    return ModelSpec(frame=frame, friction=friction, thermal=thermal, hardening=hardening)


@dataclass(frozen=True)
class ToolFrame3D:
    """The 3D tool-frame ALE mesh (:mod:`robobore.cutting.fe.mesh.toolframe3d`): moved back to
    its place in the insert's frame every ``ale_interval`` steps; no separation, no damage or
    time-step erosion (as the 2D :class:`ToolFrame`); the hexahedron. Node moves of a pass
    are limited to ``ToolFrame.MAX_MOVE`` of the local element size and the nodal
    velocities are remapped by the 2D engine's Taylor step."""

    ale_interval: int
    #: inertia factors on the elements whose stable step is below the nose-tip section's
    #: smallest (:func:`robobore.cutting.fe.models.toolframe3d.thin_element_factors`)
    thin_element_mass_scaling: bool = True
    #: largest node move of an ALE pass, fraction of the local element size (the 2D value)
    MAX_MOVE = ToolFrame.MAX_MOVE


@dataclass(frozen=True)
class BoringSpec:
    """The model choices of a 3D boring config: the frame -- the workpiece frame
    (``tool_frame`` None) with its separation, :class:`NodeSplit` (parting surface, gate) or
    :class:`EdgePathLayer`, and damage erosion of the layer elements on the edge path (both
    separations have them) on or off and time-step erosion; or the tool frame
    (:class:`ToolFrame3D`: ``separation`` None, no erosion) --, the hexahedron, friction,
    thermal model and hardening."""

    separation: NodeSplit | EdgePathLayer | None
    damage_erosion: bool
    element: HexElement
    erode_time_step_fraction: float
    friction: CoulombFriction | SlidingSpeedFriction
    thermal: Adiabatic | Conduction
    hardening: PlainHardening | HardeningHold
    tool_frame: ToolFrame3D | None = None

    def write_prm(self, p: np.ndarray, layout: Any, vc_m_per_min: float) -> np.ndarray:
        """Write the model-choice slots of the 3D parameter vector ``p`` (returned);
        ``layout`` the 3D layout module (:mod:`robobore.cutting.fe.hex.layout3d`). The frame
        also chooses the compiled step
        (:func:`robobore.cutting.fe.engine.kernels3d.run_chunk3_for`)."""
        k = layout
        p[k.P_HGV] = self.element.hourglass_viscous
        p[k.P_HGS] = self.element.hourglass_stiffness
        tf = self.tool_frame
        if tf is not None:
            from robobore.cutting.fe.ale.remap3d import VEL_TAYLOR

            p[k.P_DT_ERODE] = 0.0
            p[k.P_EROSION] = k.ERODE_NONE
            p[k.P_GATE] = -1.0
            p[k.P_RZ_EVERY] = tf.ale_interval
            p[k.P_RZ_MAXMOVE] = tf.MAX_MOVE
            p[k.P_RZ_VEL] = VEL_TAYLOR
        else:
            p[k.P_DT_ERODE] = -self.erode_time_step_fraction
            p[k.P_EROSION] = k.ERODE_LAYER if self.damage_erosion else k.ERODE_NONE
            sep = self.separation
            p[k.P_GATE] = sep.gate_um * 1e-6 if isinstance(sep, NodeSplit) else -1.0
        write_friction(p, self.friction, layout, vc_m_per_min)
        write_thermal(p, self.thermal, layout)
        return p


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
                      source: str | None = None) -> BoringSpec:
    """The :class:`BoringSpec` of a validated 3D boring config (``material`` as loaded,
    ``vc_m_per_min`` the cutting speed at the bore wall). Raises ConfigError naming a key the
    config gives that the chosen variants have no place for (for example
    ``solver.separation_gate_um`` with ``mesh.separation = "erosion_layer"``)."""
    keys = _Keys(cfg, BORING_MODEL_KEYS)
    sep: NodeSplit | EdgePathLayer | None
    tool_keys = ("mesh.edge_element_um", "mesh.slice_spacing_um", "mesh.t_min_um",
                 "mesh.margin_slices", "mesh.initial_chip_ratio", "solver.ale_interval",
                 "solver.thin_element_mass_scaling")
    tool_frame = None
    if cfg.mesh.frame == "tool":
        keys.exclude("tool3d", "mesh.depth_factor", "mesh.side_margin_um", "mesh.ahead_mm",
                     "mesh.separation", "mesh.separation_height_um", "mesh.chip_rows",
                     "solver.erosion", "solver.separation_gate_um",
                     "solver.erode_time_step_fraction")
        for key in tool_keys:
            keys.get(key)
        tool_frame = ToolFrame3D(
            ale_interval=int(keys.get("solver.ale_interval")),
            thin_element_mass_scaling=bool(keys.get("solver.thin_element_mass_scaling")))
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
    if cfg.solver.heat_conduction:
        for key in ("solver.conduction_interval", "contact.thermal_conductance_W_per_m2K",
                    "contact.friction_heat_fraction", "contact.tool_temperature_K"):
            keys.get(key)
    else:
        keys.exclude("adiabatic", "solver.conduction_interval",
                     "contact.thermal_conductance_W_per_m2K", "contact.friction_heat_fraction",
                     "contact.tool_temperature_K")
    s = cfg.solver
    limit = material.hardening_strain_limit
    keys.check(source)
    return BoringSpec(
        separation=sep, damage_erosion=tool_frame is None and s.erosion == "layer",
        element=HexElement(float(s.hourglass_viscous), float(s.hourglass_stiffness)),
        erode_time_step_fraction=float(s.erode_time_step_fraction),
        friction=friction_spec(cfg.contact, vc_m_per_min),
        thermal=thermal_spec(s, cfg.contact, material),
        hardening=(HardeningHold(float(limit)) if limit is not None and math.isfinite(limit)
                   else PlainHardening()),
        tool_frame=tool_frame)
