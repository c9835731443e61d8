"""The configuration schema of the 3D FE boring model (:mod:`robobore.cutting.fe.models.boring3d`):
its TOML sections (insert, cut, contact, mesh, solver, tool support, material), their units,
defaults and ranges, and the parser that checks them (errors name the key, the value and the
expected range). The options are documented in ``docs/fe3d.md``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, field_validator, model_validator

from robobore.cutting.fe.config.contact import ContactSection as ContactSection2D
from robobore.cutting.fe.config.frame import Frame
from robobore.cutting.fe.config.orthogonal import MaterialSection, ParameterSetConfig
from robobore.cutting.fe.config.solver import SolverSettings
from robobore.cutting.geometry import BoringInsert
from robobore.errors import ConfigError
from robobore.io.config import load_toml, validate_model
from robobore.io.sections import StrictModel as Strict
from robobore.material.library import load_material, resolve_material_name

__all__ = ["InsertSection", "CutSection", "ContactSection", "MeshSection", "SolverSection",
           "ToolSupportSection", "BoringFEConfig", "parse_boring_config", "load_boring_config"]


class InsertSection(Strict):
    """Insert geometry (defaults: a CCMT 060204-type insert in a 90-deg boring bar)."""

    nose_radius_mm: float = Field(default=0.4, gt=0.0, le=5.0)
    approach_angle_deg: float = Field(default=90.0, gt=0.0, le=90.0)
    end_edge_angle_deg: float = Field(default=5.0, gt=0.0, le=60.0)
    rake_deg: float = Field(default=7.0, ge=-30.0, le=30.0)
    clearance_deg: float = Field(default=7.0, gt=0.0, le=30.0)
    edge_radius_um: float = Field(default=20.0, ge=0.0, le=200.0)
    inclination_deg: float = Field(default=0.0, ge=-15.0, le=15.0)

    def to_insert(self) -> BoringInsert:
        return BoringInsert(nose_radius_m=self.nose_radius_mm * 1e-3,
                            approach_angle_deg=self.approach_angle_deg,
                            end_edge_angle_deg=self.end_edge_angle_deg, rake_deg=self.rake_deg,
                            inclination_deg=self.inclination_deg,
                            clearance_deg=self.clearance_deg,
                            edge_radius_m=self.edge_radius_um * 1e-6)


class CutSection(Strict):
    depth_of_cut_mm: float = Field(gt=0.0, le=2.0, description="radial depth ap, mm")
    feed_mm_per_rev: float = Field(gt=0.0, le=2.0)
    speed_rpm: float = Field(gt=0.0, le=20000.0)
    #: bore diameter after the pass [mm] (an assumption where the paper gives none)
    bore_diameter_mm: float = Field(default=40.0, gt=1.0, le=2000.0)
    #: length of cut along the wall simulated [mm] (tool frame: the insert's travel); default
    #: 0.15, that of the paper-condition checks of docs/fe3d.md, whose forces are steady over
    #: the averaged last half (``solver.steady_window_fraction``)
    cut_length_mm: float = Field(default=0.15, gt=0.0, le=20.0)


class ContactSection(ContactSection2D):
    """The 2D engine's ``[contact]``
    (:class:`robobore.cutting.fe.config.contact.ContactSection`): the same keys, values and
    defaults -- ``friction`` a bundled friction law (default ``rech2013_calibrated``: the Rech
    et al. 2013 table x 1.5 read at each contact node's filtered sliding speed, no shear cap),
    "table" or a constant Coulomb coefficient; ``friction_velocity``, ``friction_table_*``,
    ``sliding_filter_um``, ``shear_limit_MPa``, ``penalty_factor``, ``normal_damping``
    (default 1 in the tool frame, 0 in the workpiece frame, as in 2D) and the thermal contact
    (``thermal_conductance_W_per_m2K``, ``friction_heat_fraction``, ``tool_temperature_K``, used
    with ``solver.heat_conduction``)."""


class MeshSection(Strict):
    #: element size [um]; at most ap / 3 (3 elements through the chip's depth)
    element_size_um: float = Field(gt=0.0)
    #: material below the new bore surface, in depths of cut (>= 4 elements is enforced)
    depth_factor: float = Field(default=1.5, ge=0.5, le=20.0)
    #: material beyond the chip on each side along the feed axis [um] (0 = 3 elements)
    side_margin_um: float = Field(default=0.0, ge=0.0)
    #: uncut material left ahead of the insert at the end of the cut [mm]
    ahead_mm: float = Field(default=0.06, gt=0.0, le=5.0)
    #: how the chip separates from the workpiece: "erosion_layer" (elements crossed by the
    #: edge path erode by Johnson-Cook damage) or "node_split" (the nodes of a parting
    #: surface are doubled and tied, and part where they reach the insert: the 2D engine's
    #: method, used by the FE calibration of the mechanistic coefficients; with the 2-4
    #: elements through the boring chip that 3D affords on a CPU it gave larger forces than
    #: the layer, docs/fe3d.md)
    separation: Literal["node_split", "erosion_layer"] = "erosion_layer"
    #: node splitting: height of the parting surface above the edge's lowest points,
    #: along the profile normal [um] (the 2D calibration's 5 um = 0.25 edge radii)
    separation_height_um: float = Field(default=5.0, ge=0.0)
    #: node splitting: element rows of the chip above the parting surface (0 = about one
    #: per element size of the thickest chip section, at least 3)
    chip_rows: int = Field(default=0, ge=0, le=50)
    #: the mesh's frame: "tool" (default; the z-sliced tool-frame ALE mesh of
    #: robobore.cutting.fe.mesh.toolframe3d: it travels with the insert, material flows in
    #: ahead of the edge and out behind the flank and through the chip's top face, no
    #: separation criterion and no erosion; CPU only; the model checked against the
    #: mechanistic model at the paper's condition, docs/fe3d.md) or "workpiece" (Lagrangian
    #: block of the bore wall, chip and wall part by ``separation``; radial and feed forces
    #: 22-38 % low at the paper's condition; also on the GPU). With "tool",
    #: ``cut.cut_length_mm`` is the insert's travel and the workpiece keys
    #: (``depth_factor``, ``side_margin_um``, ``ahead_mm``, ``separation``,
    #: ``separation_height_um``, ``chip_rows``, ``solver.erosion``,
    #: ``solver.separation_gate_um``, ``solver.erode_time_step_fraction``) are an error
    frame: Frame = Frame.TOOL
    #: tool frame: element round the edge [um] (None: element_size_um / 4, the 2D model's)
    edge_element_um: float | None = Field(default=None, gt=0.0)
    #: tool frame: largest step between slices along the feed [um] (None: element_size_um)
    slice_spacing_um: float | None = Field(default=None, gt=0.0)
    #: tool frame: the uncut thickness is clamped to at least this at both ends of the
    #: engaged edge [um] (a slice needs a chip block; the clamp's fictitious chip area is
    #: reported)
    t_min_um: float = Field(default=5.0, gt=0.0)
    #: tool frame: slices of workpiece only beyond each end of the engaged edge
    margin_slices: int = Field(default=3, ge=1, le=50)
    #: tool frame: chip thickness / uncut thickness of the pre-shaped chip the run starts
    #: from (the 2D key)
    initial_chip_ratio: float = Field(default=1.6, ge=1.0, le=5.0)


class SolverSection(SolverSettings):
    """The shared solver keys (:class:`~robobore.cutting.fe.config.solver.SolverSettings`) and
    those of the 3D engine (defaults for its cost per step: a fixed mass scaling, fewer
    samples and shorter chunks)."""

    #: inertial density factor, a constant (default 400: the paper-condition checks of
    #: docs/fe3d.md, both frames)
    mass_scaling: float = Field(default=400.0, ge=1.0, le=1e6)
    n_samples: int = Field(default=200, ge=10, le=100000)
    chunk_steps: int = Field(default=500, ge=10, le=10**7)
    #: node splitting: a tied pair parts within this distance of the insert [um]
    separation_gate_um: float = Field(default=0.0, ge=0.0)
    #: tool frame (mesh.frame = "tool"): steps between the passes that move the mesh back
    #: to its place in the insert's frame and remap the element state and node velocities
    #: (the 2D key)
    ale_interval: int = Field(default=10, ge=1, le=10**4)
    #: tool frame: inertia added to the elements whose stable step is below the smallest of
    #: the nose-tip section (the thin chip elements at the ends of the engaged edge), so that
    #: the mesh runs at the time step of its nose-tip section (docs/fe3d.md)
    thin_element_mass_scaling: bool = True


def _triple(v: Any) -> list[float]:
    vals = [v, v, v] if isinstance(v, float | int) else list(v)
    if len(vals) != 3:
        raise ValueError("give one value or [X, Y, Z]")
    return [float(x) for x in vals]


class ToolSupportSection(Strict):
    """Equivalent 3-direction model: per boring-frame axis X, Y, Z (one value or [X, Y, Z])."""

    stiffness_N_per_m: list[float]
    damping_N_s_per_m: list[float]
    mass_kg: list[float]
    #: extra stiffness of the pressure foot per axis [N/m] (0 = no foot)
    pressure_foot_N_per_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    #: bar angle at the start of the run [deg] (from X towards Y)
    theta0_deg: float = 0.0

    @field_validator("stiffness_N_per_m", "damping_N_s_per_m", "mass_kg",
                     "pressure_foot_N_per_m", mode="before")
    @classmethod
    def _t(cls, v: Any) -> Any:
        return _triple(v)

    @model_validator(mode="after")
    def _pos(self) -> ToolSupportSection:
        for name in ("stiffness_N_per_m", "damping_N_s_per_m", "pressure_foot_N_per_m"):
            if any(x < 0 for x in getattr(self, name)):
                raise ValueError(f"{name} must be >= 0")
        if any(m <= 0 for m in self.mass_kg):
            raise ValueError("mass_kg must be > 0")
        return self

    def total_stiffness(self) -> list[float]:
        return [a + b for a, b in zip(self.stiffness_N_per_m, self.pressure_foot_N_per_m,
                                      strict=True)]


class BoringFEConfig(ParameterSetConfig):
    #: the 2D engine's switch (:class:`robobore.cutting.fe.config.orthogonal.FEConfig`):
    #: "calibrated" (default) -- friction law "rech2013_calibrated" and the material file's
    #: hardening hold (TC4: plastic strain 0.6), the validated 2D model's CALIBRATED choices;
    #: "a_priori" -- friction law "rech2013" and the plain Johnson-Cook law. Explicit
    #: contact.friction and material.hardening_strain_limit keys win over either
    parameters: Literal["calibrated", "a_priori"] = "calibrated"
    material: MaterialSection = MaterialSection()
    insert: InsertSection = InsertSection()
    cut: CutSection
    contact: ContactSection = ContactSection()
    mesh: MeshSection
    solver: SolverSection = SolverSection()
    tool_support: ToolSupportSection | None = None

    def friction_law(self) -> str:
        """The friction law in words (:meth:`ContactSection.law_description`)."""
        return self.contact.law_description()


def parse_boring_config(data: dict[str, Any], source: str | None = None) -> BoringFEConfig:
    """Validate a config dict (from TOML) and the cross-field rules."""
    cfg = validate_model(BoringFEConfig, data, source=source)
    cfg.material.name = resolve_material_name(cfg.material.name, source)  # config-relative
    # read and checked at load, not at run
    mat = load_material(cfg.material.name, source=source,
                        hardening_strain_limit=cfg.material.strain_limit())
    ap_um = cfg.cut.depth_of_cut_mm * 1e3
    le = cfg.mesh.element_size_um
    if le > ap_um / 3.0 + 1e-9:
        raise ConfigError("element too large for the depth of cut", file=source,
                          field="mesh.element_size_um", value=le,
                          expected=f"at most cut.depth_of_cut_mm/3 = {ap_um / 3.0:.4g} um")
    if cfg.insert.edge_radius_um >= cfg.insert.nose_radius_mm * 1e3:
        raise ConfigError("edge radius not smaller than the nose radius", file=source,
                          field="insert.edge_radius_um", value=cfg.insert.edge_radius_um,
                          expected=f"< {cfg.insert.nose_radius_mm * 1e3:g} um")
    if cfg.mesh.frame.is_tool:
        _check_tool_frame(cfg, source)
    if cfg.cut.bore_diameter_mm < 20 * cfg.cut.cut_length_mm:
        raise ConfigError("bore too small for the locally flat wall model", file=source,
                          field="cut.bore_diameter_mm", value=cfg.cut.bore_diameter_mm,
                          expected=f">= 20 x cut.cut_length_mm = "
                          f"{20 * cfg.cut.cut_length_mm:g} mm")
    from robobore.cutting.fe.config.spec_build import build_boring_spec
    from robobore.cutting.fe.mesh.memory import check_fe3d

    # the model choices: a key the chosen variants have no place for is an error at load
    vc_m_per_min = math.pi * cfg.cut.bore_diameter_mm * 1e-3 * cfg.cut.speed_rpm
    build_boring_spec(cfg, mat, vc_m_per_min, source)
    check_fe3d(cfg, source)  # refuse a mesh that cannot fit in memory, before meshing
    return cfg


def _check_tool_frame(cfg: BoringFEConfig, source: str | None) -> None:
    """The tool frame's cross-field rules: an edge radius, the clamp below ap, the edge
    element at most the element size, a travel of at least one element."""
    m = cfg.mesh
    ap_um = cfg.cut.depth_of_cut_mm * 1e3
    if cfg.insert.edge_radius_um <= 0.0:
        raise ConfigError("the tool-frame mesh needs an edge radius", file=source,
                          field="insert.edge_radius_um", value=cfg.insert.edge_radius_um,
                          expected='> 0 um with mesh.frame = "tool" (the default); '
                          'mesh.frame = "workpiece" for a sharp edge')
    if m.t_min_um >= ap_um:
        raise ConfigError("uncut-thickness clamp not below the depth of cut", file=source,
                          field="mesh.t_min_um", value=m.t_min_um,
                          expected=f"< cut.depth_of_cut_mm = {ap_um:g} um")
    if m.edge_element_um is not None and m.edge_element_um > m.element_size_um:
        raise ConfigError("edge element larger than the element size", file=source,
                          field="mesh.edge_element_um", value=m.edge_element_um,
                          expected=f"<= mesh.element_size_um = {m.element_size_um:g} um")
    if cfg.cut.cut_length_mm * 1e3 < m.element_size_um:
        raise ConfigError("insert travel shorter than one element", file=source,
                          field="cut.cut_length_mm", value=cfg.cut.cut_length_mm,
                          expected=f">= mesh.element_size_um = {m.element_size_um:g} um")


def load_boring_config(path: str | Path) -> BoringFEConfig:
    """Read and validate a boring FE config file (TOML)."""
    return parse_boring_config(load_toml(path), source=str(path))
