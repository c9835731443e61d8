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
:func:`robobore.cutting.fe.config.spec_build.build_spec` builds the spec from the config and
raises a ConfigError naming any key the config gives that the chosen variants have no place
for. :meth:`ModelSpec.write_prm` writes
the model-choice slots of an engine's parameter vector, in one place.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Literal

import numpy as np

from robobore.errors import ConfigError

__all__ = [
    "ToolFrame", "NodeSplit", "ErosionLayer", "OnePointQuad", "BBarQuad", "WorkpieceFrame",
    "CoulombFriction", "SlidingSpeedFriction", "Adiabatic", "Conduction", "PlainHardening",
    "HardeningHold", "ModelSpec", "write_friction", "write_thermal", "HexElement",
    "EdgePathLayer", "WorkpieceFrame3D", "ToolFrame3D",
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
