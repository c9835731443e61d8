"""The FE orthogonal-cutting config (TOML) as a pydantic model, with documented defaults.

Human units in the key names (um, mm, m/min, deg, MPa). Only the contract keys are required
(tool, cut, mesh.element_size_um; see ``examples/fe_orthogonal.toml``); every other key has
the default documented on its field. The defaults are the validated model (docs/fe.md,
"Model choice"): the tool-frame ALE mesh, heat conduction, mass scaling 100 (30 / vc)^2, the
CALIBRATED friction law ``rech2013_calibrated`` and the bundled material's CALIBRATED
hardening hold (TC4: plastic strain 0.6). ``parameters = "a_priori"`` is the one switch back
to the source's values (friction law ``rech2013``, plain Johnson-Cook hardening).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import (
    BaseModel,
    Field,
    field_validator,
    model_validator,
)

from robobore.cutting.fe.config.contact import ContactSection
from robobore.cutting.fe.config.frame import Frame
from robobore.cutting.fe.config.solver import SolverSettings
from robobore.errors import ConfigError
from robobore.io.config import load_toml, validate_model
from robobore.io.sections import StrictModel as Strict
from robobore.material.friction import (
    A_PRIORI_LAW,
    CALIBRATED_LAW,
)


class MaterialSection(Strict):
    #: bundled material name (e.g. "TC4") or a path to a material TOML file
    name: str = "TC4"
    #: plastic strain beyond which the Johnson-Cook hardening term B eps^n is held at its
    #: value (replaces the material file's ``hardening_strain_limit``); "none": the plain
    #: law. None: the file's (the bundled TC4: 0.6, CALIBRATED), or "none" with
    #: ``parameters = "a_priori"``
    hardening_strain_limit: float | Literal["none"] | None = None

    @field_validator("hardening_strain_limit")
    @classmethod
    def _hold(cls, v: Any) -> Any:
        if isinstance(v, float) and not v > 0.0:
            raise ValueError('must be > 0 (a plastic strain), or "none" for the plain law')
        return v

    def strain_limit(self) -> float | None:
        """The value for :func:`robobore.material.load_material`: None (the file's), a
        plastic strain, or inf (the plain law)."""
        v = self.hardening_strain_limit
        return float("inf") if v == "none" else v


class ToolSection(Strict):
    rake_deg: float = Field(ge=-30.0, le=40.0, description="rake angle, -30..40 deg")
    clearance_deg: float = Field(gt=0.0, le=30.0, description="clearance angle, 0..30 deg")
    edge_radius_um: float = Field(ge=0.0, le=200.0, description="cutting-edge radius, um")


class CutSection(Strict):
    uncut_chip_thickness_um: float = Field(gt=0.0, le=2000.0)
    cutting_speed_m_per_min: float = Field(gt=0.0, le=2000.0)
    #: length of cut simulated [mm] (the tool's travel in the tool frame); at least one
    #: element (mesh.element_size_um)
    length_mm: float = Field(gt=0.0, le=50.0, description="length of cut simulated, mm")
    #: width of cut [mm]; 2D results are per unit width, totals (tool support) use it; at
    #: least the uncut chip thickness (plane strain)
    width_mm: float = Field(default=1.0, gt=0.0)


class MeshSection(Strict):
    #: element size in the cutting zone and chip layer [um]; at most h/3
    element_size_um: float = Field(gt=0.0)
    #: depth of the fine zone below the cut line, in uncut chip thicknesses
    fine_depth_factor: float = Field(default=1.0, ge=0.2, le=10.0)
    #: total workpiece height below the free surface, in uncut chip thicknesses
    height_factor: float = Field(default=5.0, ge=2.0, le=50.0)
    #: growth ratio of element size outside the fine zone (1 = uniform)
    grading: float = Field(default=1.25, ge=1.0, le=2.0)
    #: position of the one-element separation layer: "above_cut_line" (its bottom on the
    #: tool's lowest point: everything below is ploughed under the edge and rubs the flank)
    #: "centred" (centred on the cut line: half of it lies below the tool) or
    #: "below_cut_line" (its top on the cut line: the chip layer is the full h and the
    #: layer is the material crushed under the edge)
    separation_layer: Literal["above_cut_line", "centred", "below_cut_line"] = "centred"
    #: how chip and workpiece part: "node_split" (doubled nodes along a parting line, tied
    #: until the tool edge reaches them) or "erosion_layer" (a one-element layer eroded by
    #: Johnson-Cook damage, placed by ``separation_layer``)
    separation: Literal["node_split", "erosion_layer"] = "erosion_layer"
    #: height of the parting line (node_split) -- or of the erosion layer's bottom, when
    #: given -- above the tool's lowest point [um]: the material below it (the stagnation
    #: zone) is ploughed under the edge radius instead of leaving with the chip
    separation_height_um: float | None = Field(default=None, ge=0.0)
    #: uncut material left ahead of the tool at the end of the cut [mm]
    ahead_mm: float = Field(default=0.3, gt=0.0, le=20.0)
    #: element size [um] in a band round the parting line, where the material passes the
    #: cutting edge (node splitting only); element_size_um / edge_element_um must be 2, 4
    #: or 8 (conforming 2:1 transition rows). None: uniform element_size_um
    edge_element_um: float | None = Field(default=None, gt=0.0)
    #: extent of the refined band above and below the parting line [um]
    edge_band_um: tuple[float, float] = (10.0, 10.0)
    #: the mesh's frame: "workpiece" (Lagrangian: the mesh moves with the material, chip and
    #: workpiece part by ``separation``) or "tool" (ALE: the mesh travels with the tool,
    #: material flows in ahead of it and out behind the flank and through the chip's top,
    #: no separation criterion and no erosion; see robobore.cutting.fe.ale.toolframe). With
    #: "tool", ``cut.length_mm`` is the tool's travel, ``edge_element_um`` the element
    #: round the edge (default element_size_um / 4), and the separation keys are an error
    #: (a key the chosen model has no place for is refused: robobore.cutting.fe.config.spec)
    frame: Frame = Frame.TOOL
    #: tool frame: chip thickness / h of the pre-shaped chip the run starts from (the
    #: chip's shape then follows from the flow)
    initial_chip_ratio: float = Field(default=1.6, ge=1.0, le=5.0)
    #: tool frame: height [um] above the tool's lowest point where the mesh's chip and
    #: workpiece blocks meet on the edge arc (a mesh choice, not where the material divides);
    #: None: min(edge radius, h) / 2
    join_height_um: float | None = Field(default=None, gt=0.0)
    #: tool frame: length [um] of the pre-shaped chip up the rake face, from where the rake
    #: face starts to the chip's top face (an outflow boundary); None: max(1.5 chip
    #: thicknesses, 80 um). It must exceed the tool-chip contact length: a chip that still
    #: touches the rake at its top face is held there by the boundary (docs/fe.md, "Mesh")
    chip_length_um: float | None = Field(default=None, gt=0.0)
    #: tool frame: depth [um] of the mesh's bottom below the cut line; the bottom is held
    #: fixed in the workpiece (a rigid base). None: max(2.5 h, 120 um)
    depth_um: float | None = Field(default=None, gt=0.0)
    #: tool frame: distance [um] of the inflow face ahead of the chip's root. None:
    #: max(1.5 h, 60 um)
    inflow_length_um: float | None = Field(default=None, gt=0.0)
    #: tool frame: distance [um] of the back face (the outflow of the machined surface)
    #: behind the edge centre. None: max(2 h, 120 um)
    back_length_um: float | None = Field(default=None, gt=0.0)

    @field_validator("edge_band_um")
    @classmethod
    def _band(cls, v: tuple[float, float]) -> tuple[float, float]:
        if any(not (x > 0.0) for x in v):
            raise ValueError("both extents (above, below) must be > 0 um")
        return v


class SolverSection(SolverSettings):
    """The shared solver keys (:class:`~robobore.cutting.fe.config.solver.SolverSettings`) and
    those of the plane-strain engine."""

    #: density factor applied to the inertial (not the thermal) mass: time step grows by
    #: sqrt(mass_scaling); 1 = none. None: the validation protocol's 100 (30 / vc)^2 with vc
    #: in m/min (at least 1), which keeps vc / (scaled wave speed) and hence the steps per
    #: mm of cut the same at every speed
    mass_scaling: float | None = Field(default=None, ge=1.0, le=1e6)
    #: element formulation: "q4r" (one-point quad with Flanagan-Belytschko hourglass
    #: control) or "q4_bbar" (2x2 Gauss points with mean-dilatation B-bar: no hourglass
    #: modes, about 2x the element cost; the hourglass coefficients are an error with it)
    element: Literal["q4r", "q4_bbar"] = "q4r"
    #: when given, a separation-layer element whose damage reached 1 erodes only once one of
    #: its nodes is within this distance [um] of the tool surface (the material separates
    #: at the cutting edge, not ahead of it); None: erode wherever the damage reaches 1
    separation_gate_um: float | None = Field(default=None, ge=0.0)
    #: tool frame (mesh.frame = "tool"): steps between the passes that move the mesh back
    #: to its place in the tool's frame and remap the element state and node velocities
    ale_interval: int = Field(default=10, ge=1, le=10**4)
    #: number of force/tool samples over the whole run
    n_samples: int = Field(default=400, ge=10, le=100000)
    #: steps per compiled chunk between progress updates
    chunk_steps: int = Field(default=2000, ge=10, le=10**7)


class ToolSupport(Strict):
    """Spring/damper/mass holding the tool to its guide point; (x, y) pairs or one value."""

    stiffness_N_per_m: float | list[float]
    damping_N_s_per_m: float | list[float]
    mass_kg: float | list[float]

    @field_validator("stiffness_N_per_m", "damping_N_s_per_m", "mass_kg")
    @classmethod
    def _pair(cls, v: Any) -> Any:
        vals = [v, v] if isinstance(v, float | int) else list(v)
        if len(vals) != 2:
            raise ValueError("give one value or [x, y]")
        if any(x < 0 for x in vals):
            raise ValueError("must be >= 0")
        return [float(x) for x in vals]

    @model_validator(mode="after")
    def _pos(self) -> ToolSupport:
        if any(m <= 0 for m in self.mass_kg):  # type: ignore[union-attr]
            raise ValueError("mass_kg must be > 0")
        return self


#: the friction law each ``parameters`` value selects when ``contact.friction`` is not given
PARAMETER_SETS = {"calibrated": CALIBRATED_LAW, "a_priori": A_PRIORI_LAW}


def auto_mass_scaling(cutting_speed_m_per_min: float) -> float:
    """The default mass scaling: 100 (30 / vc)^2, at least 1 (vc in m/min)."""
    return max(1.0, 100.0 * (30.0 / cutting_speed_m_per_min) ** 2)


def _apply_parameter_set(data: dict[str, Any]) -> dict[str, Any]:
    """A raw config dict with the friction law and the hardening of its ``parameters`` set
    ("calibrated", the default, or "a_priori") filled in where ``contact.friction`` and
    ``material.hardening_strain_limit`` are not given (the 2D and the 3D boring configs)."""
    params = data.get("parameters", "calibrated")
    contact = data.get("contact", {})
    if params in PARAMETER_SETS and isinstance(contact, dict) and "friction" not in contact:
        data = {**data, "contact": {**contact, "friction": PARAMETER_SETS[params]}}
    mat = data.get("material", {})
    if params == "a_priori" and isinstance(mat, dict) and "hardening_strain_limit" not in mat:
        data = {**data, "material": {**mat, "hardening_strain_limit": "none"}}
    return data


class ParameterSetConfig(Strict):
    """The base of the FE configs (2D orthogonal, 3D boring): before validation, the friction
    law and the hardening of the config's ``parameters`` set are filled in where
    ``contact.friction`` and ``material.hardening_strain_limit`` are not given."""

    @model_validator(mode="before")
    @classmethod
    def _parameter_set(cls, data: Any) -> Any:
        return _apply_parameter_set(data) if isinstance(data, dict) else data


class FEConfig(ParameterSetConfig):
    #: "calibrated" (default): the validated model's CALIBRATED choices -- friction law
    #: "rech2013_calibrated" and the material file's hardening hold; "a_priori": the
    #: source's values, nothing chosen against measured forces -- friction law "rech2013"
    #: and the plain Johnson-Cook law. Explicit contact.friction and
    #: material.hardening_strain_limit keys win over either
    parameters: Literal["calibrated", "a_priori"] = "calibrated"
    material: MaterialSection = MaterialSection()
    tool: ToolSection
    cut: CutSection
    contact: ContactSection = ContactSection()
    mesh: MeshSection
    solver: SolverSection = SolverSection()
    tool_support: ToolSupport | None = None

    @model_validator(mode="before")
    @classmethod
    def _parameter_set(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        if not isinstance(data.get("solver", {}), BaseModel):
            data = {**data, "solver": dict(data.get("solver", {}))}
        return _apply_parameter_set(data)

    @model_validator(mode="after")
    def _mass_scaling(self) -> FEConfig:
        if self.solver.mass_scaling is None:
            self.solver.mass_scaling = auto_mass_scaling(self.cut.cutting_speed_m_per_min)
        return self

    def friction_coefficient(self) -> float:
        """Coulomb coefficient at the cutting speed (:meth:`ContactSection.coefficient_at`)."""
        return self.contact.coefficient_at(self.cut.cutting_speed_m_per_min)

    def friction_law(self) -> str:
        """The friction law in words (:meth:`ContactSection.law_description`)."""
        return self.contact.law_description()


def check_config(cfg: FEConfig, source: str | None = None) -> FEConfig:
    """Cross-field checks (element size vs chip thickness, cut length vs element size,
    width vs chip thickness)."""
    h = cfg.cut.uncut_chip_thickness_um
    le = cfg.mesh.element_size_um
    if le > h / 3.0 + 1e-12:
        raise ConfigError("element too large for the chip thickness", file=source,
                          field="mesh.element_size_um", value=le,
                          expected=f"an element size in um at most uncut_chip_thickness_um/3 "
                          f"= {h / 3.0:.4g} um")
    length_um = cfg.cut.length_mm * 1e3
    if length_um < le - 1e-9:
        raise ConfigError("cut too short for the mesh", file=source, field="cut.length_mm",
                          value=cfg.cut.length_mm,
                          expected=f"at least one element of cut, mesh.element_size_um = "
                          f"{le:g} um = {le * 1e-3:.4g} mm (a shorter cut moves no material "
                          "through an element of the cutting zone; a steady state takes many "
                          "more: the validated runs cut 0.3 mm, 30 elements of 10 um)")
    if cfg.cut.width_mm * 1e3 < h - 1e-9:
        raise ConfigError("width of cut below the uncut chip thickness", file=source,
                          field="cut.width_mm", value=cfg.cut.width_mm,
                          expected=f"at least uncut_chip_thickness_um = {h:g} um = "
                          f"{h * 1e-3:.4g} mm (the 2D model is plane strain: the width must "
                          "exceed the chip thickness)")
    sh = cfg.mesh.separation_height_um
    if sh is not None and sh > h - le + 1e-12:
        raise ConfigError("separation line too high for the chip thickness", file=source,
                          field="mesh.separation_height_um", value=sh,
                          expected=f"a height in um at most uncut_chip_thickness_um - "
                          f"element_size_um = {h - le:.4g} um (one element row of chip)")
    ee = cfg.mesh.edge_element_um
    if cfg.mesh.frame.is_tool:
        return _check_tool_frame(cfg, source)
    if ee is not None:
        if cfg.mesh.separation != "node_split":
            raise ConfigError("edge refinement needs node splitting", file=source,
                              field="mesh.edge_element_um", value=ee,
                              expected='no value, or mesh.separation = "node_split"')
        ratio = le / ee
        if min(abs(ratio - r) for r in (2, 4, 8)) > 1e-6 * ratio:
            raise ConfigError("edge element size must divide the element size by 2, 4 or 8",
                              file=source, field="mesh.edge_element_um", value=ee,
                              expected=f"one of {le / 2:.4g}, {le / 4:.4g}, {le / 8:.4g} um "
                              f"(element_size_um / 2, 4, 8)")
    return cfg


def _check_tool_frame(cfg: FEConfig, source: str | None) -> FEConfig:
    """Cross-field checks of the tool-frame ALE model (mesh.frame = "tool")."""
    le = cfg.mesh.element_size_um
    ee = cfg.mesh.edge_element_um
    if ee is not None and ee > le:
        raise ConfigError("edge element larger than the element size", file=source,
                          field="mesh.edge_element_um", value=ee,
                          expected=f"at most mesh.element_size_um = {le:.4g} um")
    if cfg.tool.edge_radius_um <= 0.0:
        raise ConfigError("the tool-frame mesh wraps the cutting edge: it needs an edge "
                          "radius", file=source, field="tool.edge_radius_um",
                          value=cfg.tool.edge_radius_um, expected='> 0 um with mesh.frame '
                          '= "tool"')
    jh = cfg.mesh.join_height_um
    r = cfg.tool.edge_radius_um
    h = cfg.cut.uncut_chip_thickness_um
    if jh is not None and (jh > r or jh > 0.75 * h):
        raise ConfigError("join height off the lower front of the edge arc", file=source,
                          field="mesh.join_height_um", value=jh,
                          expected=f"at most the edge radius ({r:.4g} um) and 3/4 of the "
                          f"uncut chip thickness ({0.75 * h:.4g} um)")
    cl = cfg.mesh.chip_length_um
    if cl is not None and cl < 2.0 * h:
        raise ConfigError("chip too short for the tool-frame mesh", file=source,
                          field="mesh.chip_length_um", value=cl,
                          expected=f"at least 2 uncut chip thicknesses ({2 * h:.4g} um)")
    for name, val, low, what in (
            ("depth_um", cfg.mesh.depth_um, h, "the uncut chip thickness"),
            ("inflow_length_um", cfg.mesh.inflow_length_um, h, "the uncut chip thickness"),
            ("back_length_um", cfg.mesh.back_length_um, max(2.0 * r, h),
             "the larger of 2 edge radii and the uncut chip thickness")):
        if val is not None and val < low:
            raise ConfigError("tool-frame domain too small", file=source,
                              field=f"mesh.{name}", value=val,
                              expected=f"at least {what} ({low:.4g} um)")
    # solver.element, the separation and erosion keys: no place in the tool frame's spec
    # (config.spec_build.build_spec)
    return cfg


def parse_config(data: dict[str, Any], source: str | None = None) -> FEConfig:
    """Validate a config dict (as read from TOML); a material file named in it is resolved
    against the config file's folder (robobore.io.paths)."""
    from robobore.cutting.fe.config.spec_build import build_spec
    from robobore.cutting.fe.mesh.memory import check_fe2d
    from robobore.material.library import load_material, resolve_material_name

    cfg = validate_model(FEConfig, data, source=source or "<config>")
    cfg.material.name = resolve_material_name(cfg.material.name, source)
    # the material is read and checked now, not first when the run starts
    material = load_material(cfg.material.name, source=source,
                             hardening_strain_limit=cfg.material.strain_limit())
    cfg = check_config(cfg, source)
    # the model choices: a key the chosen variants have no place for is an error at load
    build_spec(cfg, material, source)
    check_fe2d(cfg, source)  # refuse a mesh that cannot fit in memory, before meshing
    return cfg


def load_fe_config(path: str | Path) -> FEConfig:
    """Read and validate an FE config TOML file."""
    return parse_config(load_toml(path), str(path))
