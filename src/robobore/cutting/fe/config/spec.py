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

The 3D engine (the boring model, the 3D slab) has its own frames in the same spec:
:class:`ToolFrame3D` (the tool-frame ALE mesh: no separation, no erosion) and
:class:`WorkpieceFrame3D` (its separation, :class:`NodeSplit` or :class:`EdgePathLayer`, damage
and time-step erosion), each with the :class:`HexElement`. Each frame writes its own slots of
the parameter vector (``write_prm``) and says whether it is a tool frame (``tool_frame``) and
which engine it runs on (``dim``).

A combination without a meaning (a gate in the tool frame, a B-bar element with hourglass
coefficients, a tool temperature in an adiabatic run) has no type to be built from.
:func:`build_spec` builds the spec from the config and raises a ConfigError naming any key the
config gives that the chosen variants have no place for. :meth:`ModelSpec.write_prm` writes
the model-choice slots of an engine's parameter vector, in one place.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from robobore.errors import ConfigError
from robobore.material import Material

__all__ = [
    "ToolFrame", "NodeSplit", "ErosionLayer", "OnePointQuad", "BBarQuad", "WorkpieceFrame",
    "CoulombFriction", "SlidingSpeedFriction", "Adiabatic", "Conduction", "PlainHardening",
    "HardeningHold", "ModelSpec", "build_spec", "friction_spec", "thermal_spec", "write_friction",
    "write_thermal", "MODEL_KEYS", "HexElement", "EdgePathLayer", "WorkpieceFrame3D",
    "build_boring_spec", "BORING_MODEL_KEYS", "ToolFrame3D",
]


# --- frame, separation, element

def _check_type(value: Any, types: tuple[type, ...], field: str) -> None:
    """ConfigError unless ``value`` is one of ``types`` (a spec built from parts that do not
    belong together)."""
    if not isinstance(value, types):
        raise ConfigError("model choice without a meaning", field=field,
                          value=type(value).__name__,
                          expected=" or ".join(t.__name__ for t in types))


@dataclass(frozen=True)
class OnePointQuad:
    """The one-point quadrilateral with Flanagan-Belytschko hourglass control."""

    hourglass_viscous: float
    hourglass_stiffness: float

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """The hourglass slots (``P_HGV``, ``P_HGS``) of the layout ``k``."""
        p[k.P_HGV] = self.hourglass_viscous
        p[k.P_HGS] = self.hourglass_stiffness


@dataclass(frozen=True)
class BBarQuad:
    """The fully integrated B-bar quadrilateral: no hourglass modes, no coefficients."""

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """No slot: the B-bar element has no hourglass control."""


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
    #: the mesh stays round the tool (the contact damping and the compiled step follow)
    tool_frame: ClassVar[bool] = True
    #: the engine: 2 (quadrilaterals) or 3 (hexahedra)
    dim: ClassVar[int] = 2

    def __post_init__(self) -> None:
        _check_type(self.element, (OnePointQuad,), "solver.element")

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """The frame's slots of the 2D layout ``k``: no erosion, no gate, the ALE pass."""
        p[k.P_EROSION] = k.ERODE_NONE
        p[k.P_DT_ERODE] = 0.0
        p[k.P_GATE] = -1.0
        p[k.P_RZ_EVERY] = self.ale_interval
        p[k.P_RZ_MAXMOVE] = ToolFrame.MAX_MOVE
        self.element.write_prm(p, k)


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
    tool_frame: ClassVar[bool] = False
    dim: ClassVar[int] = 2

    def __post_init__(self) -> None:
        _check_type(self.separation, (NodeSplit, ErosionLayer), "mesh.separation")
        _check_type(self.element, (OnePointQuad, BBarQuad), "solver.element")

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """The frame's slots of the 2D layout ``k``: time-step erosion, the separation's
        erosion and gate, no ALE pass."""
        sep = self.separation
        p[k.P_DT_ERODE] = -self.erode_time_step_fraction
        if isinstance(sep, NodeSplit):
            p[k.P_EROSION] = k.ERODE_NONE
            p[k.P_GATE] = sep.gate_um * 1e-6
        else:
            p[k.P_EROSION] = k.ERODE_LAYER if sep.damage_erosion else k.ERODE_NONE
            p[k.P_GATE] = -1.0 if sep.gate_um is None else sep.gate_um * 1e-6
        p[k.P_RZ_EVERY] = 0
        p[k.P_RZ_MAXMOVE] = ToolFrame.MAX_MOVE
        self.element.write_prm(p, k)


@dataclass(frozen=True)
class HexElement:
    """The 8-node hexahedron of the 3D engine with its hourglass control coefficients."""

    hourglass_viscous: float
    hourglass_stiffness: float

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """The hourglass slots (``P_HGV``, ``P_HGS``) of the 3D layout ``k``."""
        p[k.P_HGV] = self.hourglass_viscous
        p[k.P_HGS] = self.hourglass_stiffness


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
    """The model choices of an FE config (see the module docstring): one spec for the three
    models, the frame telling them apart -- :class:`ToolFrame` or :class:`WorkpieceFrame`
    (the orthogonal 2D model), :class:`ToolFrame3D` or :class:`WorkpieceFrame3D` (the 3D
    boring model and the 3D slab). Each frame carries its element and only the options it
    has (a tool frame has no separation and no erosion); parts that do not belong together
    raise a ConfigError when the spec is built."""

    frame: ToolFrame | WorkpieceFrame | ToolFrame3D | WorkpieceFrame3D
    friction: CoulombFriction | SlidingSpeedFriction
    thermal: Adiabatic | Conduction
    hardening: PlainHardening | HardeningHold

    def __post_init__(self) -> None:
        _check_type(self.frame, (ToolFrame, WorkpieceFrame, ToolFrame3D, WorkpieceFrame3D),
                    "mesh.frame")
        _check_type(self.friction, (CoulombFriction, SlidingSpeedFriction), "contact.friction")
        _check_type(self.thermal, (Adiabatic, Conduction), "solver.heat_conduction")
        _check_type(self.hardening, (PlainHardening, HardeningHold), "material")

    def write_prm(self, p: np.ndarray, layout: Any, vc_m_per_min: float) -> np.ndarray:
        """Write the model-choice slots of the engine's parameter vector ``p`` (returned):
        frame, separation, element, erosion, friction and thermal slots. ``layout`` is the
        engine's layout module (its ``P_*`` indices and ``ERODE_*`` codes:
        :mod:`robobore.cutting.fe.engine.layout` for a 2D frame,
        :mod:`robobore.cutting.fe.hex.layout3d` for a 3D one). The element type, the frame
        and the thermal model also choose the compiled step
        (:func:`robobore.cutting.fe.engine.chunk_loop.step_for`,
        :func:`robobore.cutting.fe.engine.kernels3d.run_chunk3_for`)."""
        self.frame.write_prm(p, layout)
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
    element: HexElement
    #: inertia factors on the elements whose stable step is below the nose-tip section's
    #: smallest (:func:`robobore.cutting.fe.models.toolframe3d.thin_element_factors`)
    thin_element_mass_scaling: bool = True
    #: largest node move of an ALE pass, fraction of the local element size (the 2D value)
    MAX_MOVE = ToolFrame.MAX_MOVE
    tool_frame: ClassVar[bool] = True
    dim: ClassVar[int] = 3

    def __post_init__(self) -> None:
        _check_type(self.element, (HexElement,), "solver.element")

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """The frame's slots of the 3D layout ``k``: no erosion, no gate, the ALE pass with
        the Taylor velocity remap."""
        from robobore.cutting.fe.ale.remap3d import VEL_TAYLOR

        self.element.write_prm(p, k)
        p[k.P_DT_ERODE] = 0.0
        p[k.P_EROSION] = k.ERODE_NONE
        p[k.P_GATE] = -1.0
        p[k.P_RZ_EVERY] = self.ale_interval
        p[k.P_RZ_MAXMOVE] = self.MAX_MOVE
        p[k.P_RZ_VEL] = VEL_TAYLOR


@dataclass(frozen=True)
class WorkpieceFrame3D:
    """The Lagrangian 3D workpiece block: its separation, :class:`NodeSplit` (parting
    surface, gate) or :class:`EdgePathLayer`; damage erosion of the layer elements on the
    edge path on or off (both separations have them); time-step erosion (the fraction of
    the initial smallest step below which an element erodes; 0: off); the hexahedron."""

    separation: NodeSplit | EdgePathLayer
    damage_erosion: bool
    erode_time_step_fraction: float
    element: HexElement
    tool_frame: ClassVar[bool] = False
    dim: ClassVar[int] = 3

    def __post_init__(self) -> None:
        _check_type(self.separation, (NodeSplit, EdgePathLayer), "mesh.separation")
        _check_type(self.element, (HexElement,), "solver.element")

    def write_prm(self, p: np.ndarray, k: Any) -> None:
        """The frame's slots of the 3D layout ``k``: time-step and damage erosion, the
        parting surface's gate."""
        self.element.write_prm(p, k)
        p[k.P_DT_ERODE] = -self.erode_time_step_fraction
        p[k.P_EROSION] = k.ERODE_LAYER if self.damage_erosion else k.ERODE_NONE
        sep = self.separation
        p[k.P_GATE] = sep.gate_um * 1e-6 if isinstance(sep, NodeSplit) else -1.0


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
    if cfg.mesh.frame == "tool":
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
