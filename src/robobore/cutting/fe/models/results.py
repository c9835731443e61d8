"""Typed summaries of the FE runs: the orthogonal 2D run, the 3D boring run and the 3D slab;
the 3D run against the mechanistic model; the validation against measured forces.

Each summary is a frozen dataclass whose fields are documented one by one (``#:`` above the
field, in the unit its name carries); ``to_dict()`` gives the JSON the CLI writes
(``robobore fe orthogonal|boring --json``): the same keys, in the same order, with tuples as
lists and the nested groups as objects. A field listed in ``_FLAT`` is a group whose keys sit
at the top level of the JSON (the tool-support deflections); a field listed in ``_OMIT`` is
left out of the JSON while it is None (a group the run does not have).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, is_dataclass
from typing import Any

__all__ = ["RotatingForce", "XYZ", "FaceForce", "FaceForces", "Energies3D",
           "ToolSupport2D", "OrthogonalSummary", "ToolFrameMeshSummary", "ToolSupport3D",
           "BoringSummary", "SlabSummary", "ComponentComparison", "MechanisticComparison",
           "PerQuantity", "MeasuredValues", "ValidationPoint", "ValidationSummary",
           "ValidationResult"]


def _plain(v: Any) -> Any:
    if is_dataclass(v) and not isinstance(v, type):
        return v.to_dict()  # type: ignore[attr-defined]
    if isinstance(v, tuple):
        return [_plain(x) for x in v]
    return v


class _Record:
    """``to_dict``: the fields in order, ``_FLAT`` groups merged into the top level,
    ``_OMIT`` fields left out while None."""

    _FLAT: frozenset[str] = frozenset()
    _OMIT: frozenset[str] = frozenset()

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for f in fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if v is None and (f.name in self._OMIT or f.name in self._FLAT):
                continue
            if f.name in self._FLAT:
                out.update(v.to_dict())
            else:
                out[f.name] = _plain(v)
        return out


@dataclass(frozen=True)
class RotatingForce(_Record):
    """A force on the tool in the rotating frame of the bar [N]."""

    #: against the cutting velocity (positive when the tool is pushed back)
    tangential: float
    #: along e_r, positive outwards
    radial: float
    #: along +Z, the feed
    feed: float


@dataclass(frozen=True)
class XYZ(_Record):
    """A vector in the boring frame (X horizontal, Y vertical, Z feed), unit in the field
    that holds it."""

    x: float
    y: float
    z: float


@dataclass(frozen=True)
class FaceForce(_Record):
    """The force per unit width on one tool face [N/mm]."""

    #: along the cutting direction
    cutting: float
    #: along the feed (thrust) direction
    feed: float


@dataclass(frozen=True)
class FaceForces(_Record):
    """The mean force per unit width on each tool face over the averaging window [N/mm]
    (the faces of :data:`robobore.cutting.fe.engine.layout.FACES`)."""

    rake: FaceForce
    edge: FaceForce
    flank: FaceForce


@dataclass(frozen=True)
class ToolSupport2D(_Record):
    """The tool's deflection on its springs over the averaging window [um] (2D)."""

    #: mean deflection along the cutting direction
    tool_dx_mean_um: float
    #: mean deflection along the feed direction
    tool_dy_mean_um: float
    #: standard deviation along the cutting direction
    tool_dx_std_um: float
    #: standard deviation along the feed direction
    tool_dy_std_um: float
    #: the static deflection: mean cutting force x width / kx
    tool_dx_static_um: float
    #: the static deflection: mean feed force x width / ky
    tool_dy_static_um: float


@dataclass(frozen=True)
class OrthogonalSummary(_Record):
    """The outcome of an orthogonal-cutting run (2D plane strain), in the units of its
    names; forces on the tool per unit width, averaged over the steady window."""

    #: mean cutting force per unit width over the steady window
    cutting_force_N_per_mm: float
    #: mean feed (thrust) force per unit width over the steady window
    feed_force_N_per_mm: float
    #: standard deviation of the cutting force over the window
    cutting_force_std_N_per_mm: float
    #: standard deviation of the feed force over the window
    feed_force_std_N_per_mm: float
    #: the window's first and last cut length (NaN, NaN without samples in it)
    averaging_window_mm: tuple[float, float]
    #: chip thickness / uncut chip thickness, measured on the deformed chip
    chip_ratio: float
    #: points of the chip's free surface the ratio rests on
    chip_ratio_points: int
    #: chip ratio from the chip's velocity (cutting speed / chip speed)
    chip_ratio_velocity: float
    #: nodes the velocity ratio rests on
    chip_ratio_velocity_points: int
    #: measured chip thickness
    chip_thickness_um: float
    #: shear angle from the chip ratio and the rake angle
    shear_angle_deg: float
    #: highest temperature of a live element at the end
    peak_temperature_K: float
    #: energy balance error at the end (relative)
    energy_error: float
    #: wall time of the time loop
    wall_time_s: float
    #: elements x steps / wall time
    element_updates_per_s: float
    #: time steps taken
    steps: int
    #: "cpu" or "gpu"
    device: str
    #: the initial stable time step
    time_step_s: float
    #: elements of the mesh
    n_elements: int
    #: nodes of the mesh
    n_nodes: int
    #: the Coulomb coefficient at the cutting speed (nominal with a table)
    friction_coefficient: float
    #: the friction law's name (``FEConfig.friction_law``)
    friction_law: str
    #: the config's uncut chip thickness
    uncut_chip_thickness_um: float
    #: the config's cutting speed
    cutting_speed_m_per_min: float
    #: elements eroded by damage
    eroded_damage: int
    #: elements eroded by distortion or time step
    eroded_distortion: int
    #: eroded chip elements' initial area / the chip's initial area
    eroded_chip_mass_fraction: float
    #: external work per unit width
    energy_external_J_per_m: float
    #: plastic work per unit width
    energy_plastic_J_per_m: float
    #: hourglass energy per unit width
    energy_hourglass_J_per_m: float
    #: friction (contact) work per unit width
    energy_contact_J_per_m: float
    #: kinetic energy per unit width
    energy_kinetic_J_per_m: float
    #: internal energy per unit width
    energy_internal_J_per_m: float
    #: hourglass / internal energy
    hourglass_fraction: float
    #: force on each tool face (None when the faces are not recorded in the window)
    force_by_face_N_per_mm: FaceForces | None = None
    #: the tool's deflections (None for a rigid tool); flat keys in the JSON
    tool_support: ToolSupport2D | None = None

    _OMIT = frozenset({"force_by_face_N_per_mm"})
    _FLAT = frozenset({"tool_support"})


@dataclass(frozen=True)
class Energies3D(_Record):
    """The energy balance of a 3D run at the end [J]."""

    external: float
    kinetic: float
    internal: float
    plastic: float
    hourglass: float
    #: friction work
    contact: float
    #: energy removed with eroded elements
    eroded: float


@dataclass(frozen=True)
class ToolFrameMeshSummary(_Record):
    """The mesh facts of a 3D tool-frame run
    (:func:`robobore.cutting.fe.models.toolframe3d.toolframe_mesh_summary`)."""

    #: nodes of the mesh
    nodes: int
    #: hexahedra of the mesh
    hexahedra: int
    #: normal sections along the edge
    slices: int
    #: sections that cut
    engaged_slices: int
    #: the clamp on the chip's thickness
    t_min_um: float
    #: the shortest element edge
    min_element_edge_um: float
    #: the chip area of the mechanistic model (ap f - scallop)
    chip_area_mm2: float
    #: the mesh's chip area above the edge
    mesh_chip_area_mm2: float
    #: the area the clamp adds
    clamp_area_mm2: float
    #: the clamp's added area / the chip area
    clamp_area_fraction: float
    #: material in the mesh at the end / at the start (a run sets it)
    mass_ratio: float | None = None
    #: the largest inertia factor on a thin chip element (with thin-element scaling)
    inertia_factor_max: float | None = None
    #: elements with an inertia factor above 1
    inertia_factor_elements: int | None = None
    #: the inertia added / the mesh's inertia
    added_inertia_fraction: float | None = None
    #: the insert's largest deflection along the wall normal (on a tool support)
    radial_deflection_max_um: float | None = None
    #: the edge element's size (on a tool support)
    edge_element_um: float | None = None

    _OMIT = frozenset({"mass_ratio", "inertia_factor_max", "inertia_factor_elements",
                       "added_inertia_fraction", "radial_deflection_max_um",
                       "edge_element_um"})


@dataclass(frozen=True)
class ToolSupport3D(_Record):
    """The tool's deflection on the 3-direction support over the averaging window [um]."""

    #: mean feed-direction (Z) deflection
    tool_dz_mean_um: float
    #: the static Z deflection: mean feed force / kZ (NaN with kZ = 0)
    tool_dz_static_um: float
    #: mean X deflection
    tool_dx_mean_um: float
    #: mean Y deflection
    tool_dy_mean_um: float


@dataclass(frozen=True)
class BoringSummary(_Record):
    """The outcome of a 3D boring run, in the units of its names; forces on the tool,
    averaged over the steady window (see :mod:`robobore.cutting.fe.models.boring3d`)."""

    #: mean force, rotating frame
    force_rotating_N: RotatingForce
    #: standard deviation of the force, rotating frame
    force_rotating_std_N: RotatingForce
    #: the boring-frame force's mean over a revolution
    force_mean_N: XYZ
    #: the boring-frame force's amplitude over a revolution
    force_amplitude_N: XYZ
    #: the boring-frame force at the simulated bar angles (window mean)
    force_at_run_angle_N: XYZ
    #: the bar angle at the first and last sample
    bar_angle_deg: tuple[float, float]
    #: the window's first and last cut length
    averaging_window_mm: tuple[float, float]
    #: the chip area ap f - scallop
    chip_area_mm2: float
    #: the chip's highest point above the pre-bore surface
    chip_max_height_um: float
    #: highest temperature of a live element (NaN with none)
    peak_temperature_K: float
    #: energy balance error at the end (relative)
    energy_error: float
    #: the energy balance at the end
    energy_J: Energies3D
    #: hourglass / internal energy
    hourglass_fraction: float
    #: the feed-direction tool amplitude over the window (None for a rigid tool)
    feed_amplitude_um: float | None
    #: wall time of the time loop
    wall_time_s: float
    #: elements x steps / wall time
    element_updates_per_s: float
    #: time steps taken
    steps: int
    #: the initial stable time step
    time_step_s: float
    #: hexahedra of the mesh
    n_elements: int
    #: nodes of the mesh
    n_nodes: int
    #: "workpiece" or "tool"
    frame: str
    #: the config's element size
    element_size_um: float
    #: the cutting speed at the bore wall
    cutting_speed_m_per_min: float
    #: the Coulomb coefficient (nominal: at the cutting speed)
    friction_coefficient: float
    #: the friction law's name
    friction_law: str
    #: mean sliding speed of the contact nodes (None without a sliding-speed table)
    sliding_speed_mean_m_per_s: float | None
    #: the workpiece frame's chip separation (None in the tool frame)
    separation: str | None
    #: node pairs parted by node splitting
    pairs_parted: int
    #: elements eroded by damage
    eroded_damage: int
    #: elements eroded by distortion or time step
    eroded_distortion: int
    #: "cpu" or "gpu"
    device: str
    #: the tool-frame mesh (None in the workpiece frame)
    toolframe_mesh: ToolFrameMeshSummary | None = None
    #: the workpiece block's hexahedra along x, y, z (None in the tool frame)
    mesh_shape: tuple[int, int, int] | None = None
    #: the tool's deflections (None for a rigid tool); flat keys in the JSON
    tool_support: ToolSupport3D | None = None

    _OMIT = frozenset({"toolframe_mesh", "mesh_shape"})
    _FLAT = frozenset({"tool_support"})


@dataclass(frozen=True)
class SlabSummary(_Record):
    """The outcome of a 3D plane-strain slab run (:mod:`robobore.cutting.fe.models.slab3d`):
    forces on the tool per unit width averaged over the steady window."""

    #: mean cutting force per unit width
    cutting_force_N_per_mm: float
    #: mean feed force per unit width
    feed_force_N_per_mm: float
    #: mean out-of-plane (z) force per unit width (zero in plane strain)
    out_of_plane_force_N_per_mm: float
    #: energy balance error at the end (relative)
    energy_error: float
    #: hourglass / internal energy
    hourglass_fraction: float
    #: elements eroded (damage or distortion)
    eroded: int
    #: hexahedra of the slab
    n_elements: int
    #: time steps taken
    steps: int
    #: the stable time step at the end
    final_time_step_s: float


@dataclass(frozen=True)
class ComponentComparison(_Record):
    """One rotating-frame component of the FE force against the mechanistic model [N]."""

    #: the FE run's mean force
    fe_N: float
    #: the mechanistic boring model's force at the same condition
    model_N: float
    #: (FE - model) / |model| (nan where the model's force is 0)
    relative_difference: float


@dataclass(frozen=True)
class MechanisticComparison(_Record):
    """The FE boring forces against the mechanistic model
    (:func:`robobore.cutting.fe.models.boring3d.compare_with_mechanistic`); ``to_dict()`` is
    the ``mechanistic_comparison`` of ``robobore fe boring --json``."""

    #: the provenance of the mechanistic model's cutting coefficients
    coefficients: str
    #: against the cutting velocity
    tangential: ComponentComparison
    #: along e_r, positive outwards
    radial: ComponentComparison
    #: along +Z, the feed
    feed: ComponentComparison


@dataclass(frozen=True)
class PerQuantity(_Record):
    """One value per validated quantity (a relative error ``simulated / measured - 1``, a
    statistic of them or a count; None where there is none)."""

    #: of the cutting force
    cutting_force: float | int | None
    #: of the feed (thrust) force
    feed_force: float | int | None
    #: of the chip ratio (chip thickness / uncut chip thickness)
    chip_ratio: float | int | None


@dataclass(frozen=True)
class MeasuredValues(_Record):
    """The measured values of a validation point (None: not measured)."""

    #: cutting force per mm of width [N/mm]
    cutting_force_N_per_mm: float | None
    #: feed (thrust) force per mm of width [N/mm]
    feed_force_N_per_mm: float | None
    #: chip thickness / uncut chip thickness
    chip_ratio: float | None


@dataclass(frozen=True)
class ValidationPoint(_Record):
    """One point of an FE validation: the simulated values against the measured ones."""

    #: uncut chip thickness [um]
    uncut_chip_thickness_um: float
    #: cutting speed [m/min]
    cutting_speed_m_per_min: float
    #: simulated cutting force per mm of width [N/mm] (None: not finite)
    cutting_force_N_per_mm: float | None
    #: simulated feed force per mm of width [N/mm] (None: not finite)
    feed_force_N_per_mm: float | None
    #: simulated chip ratio (None: not measured in the run)
    chip_ratio: float | None
    #: simulated / measured - 1 per quantity (None: no measured value)
    relative_error: PerQuantity
    #: the measured values
    measured: MeasuredValues
    #: relative energy-balance error of the run
    energy_error: float | None
    #: wall time of the run [s] (of the run that stored a reused result)
    wall_time_s: float | None
    #: element updates per second of the run
    element_updates_per_s: float | None
    #: the result was read from the results folder, not run again
    reused: bool
    #: the stored result's file (None: no results folder)
    file: str | None


@dataclass(frozen=True)
class ValidationSummary(_Record):
    """The errors of a validation over its points, per quantity."""

    #: largest |relative error| (None: no point measured)
    max_abs_error: PerQuantity
    #: mean |relative error| (None: no point measured)
    mean_abs_error: PerQuantity
    #: number of points with a measured value
    n_measured: PerQuantity


@dataclass(frozen=True)
class ValidationResult(_Record):
    """An FE validation run (:func:`robobore.cutting.fe.models.validate.run_validation`);
    ``to_dict()`` is the ``--json`` of ``robobore fe validate`` (docs/fe.md) before the
    command adds the measured file and the identity."""

    #: the points, in the order run
    points: tuple[ValidationPoint, ...]
    #: the errors over the points
    summary: ValidationSummary
    #: the base config's name
    config: str
    #: the device the points ran on
    device: str
    #: the results folder (None: none)
    out_dir: str | None
