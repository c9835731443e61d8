"""TOML configuration of the process stage (``robobore lobes``, ``robobore simulate boring``).

Two kinds of file are accepted.

General single-point cutting (the contract)::

    [structure]   # tool-point modes, boring frame: x horizontal, y vertical, z feed
    modes = [ { frequency_Hz = 250.0, damping_ratio = 0.012, stiffness_N_per_m = 2.26e8,
                direction = [0.866, 0.5, 0.0] } ]
    [process]
    cutting_coefficient_N_per_m2 = 1.0e9
    force_direction = [1.0, 0.0, 0.0]
    chip_normal = [1.0, 0.0, 0.0]
    feed_mm_per_rev = 0.1
    # optional: overlap_factor = 1.0, n_inserts = 1
    [speed_rpm]
    min = 2000.0
    max = 14000.0
    count = 601

Boring (rotating bar): instead of ``[process]`` give ``[insert]``, ``[bore]``, ``[cutting]``
and optionally ``[coefficients]``; instead of (or besides) ``[structure]`` an ``[equivalent]``
section (per-direction stiffness, frequency and damping, optional ``[equivalent.pressure_foot]``;
from Python it can be made from an :class:`~robobore.equivalent.EquivalentModel`,
:func:`with_equivalent`).
Optional ``[simulation]`` (revolutions, samples per revolution, roughness tolerance).
Without ``[speed_rpm]`` the lobes use :data:`DEFAULT_SPEED_RPM` (100 .. 3000 r/min, 300
speeds) and say so in their notes.
Human units are in the key names and converted to SI here, once. ``[coefficients] file`` is
resolved against the config file's folder (:mod:`robobore.io.paths`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field, field_validator, model_validator

from robobore.dynamics.handoff import equivalent_extras, equivalent_section, with_equivalent
from robobore.errors import ConfigError
from robobore.io.config import load_toml, validate_model
from robobore.io.paths import resolve_config_path
from robobore.io.sections import InsertSection, StrictModel


def _unit(v: list[float], tol: float = 0.01) -> list[float]:
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise ValueError("must be 3 finite numbers (a unit vector)")
    n = math.sqrt(sum(x * x for x in v))
    if n < 1e-9:
        raise ValueError("zero-length direction; expected a unit vector")
    if abs(n - 1.0) > tol:
        raise ValueError(f"length {n:.4f} is more than 1% off unit length; expected |d| = 1")
    return [x / n for x in v]


class ModeCfg(StrictModel):
    frequency_Hz: float = Field(gt=0, le=1e6)
    damping_ratio: float = Field(ge=0, lt=1)
    stiffness_N_per_m: float = Field(gt=0, le=1e12)
    direction: list[float]

    @field_validator("direction")
    @classmethod
    def _dir(cls, v: list[float]) -> list[float]:
        return _unit(v)


class StructureCfg(StrictModel):
    modes: list[ModeCfg] = Field(min_length=1)


class XYZ(StrictModel):
    x: float
    y: float
    z: float


class PressureFootCfg(StrictModel):
    pressure_MPa: float = Field(0.3, ge=0, le=10)
    piston_diameter_mm: float = Field(50.0, gt=0, le=1000)
    normal: list[float] = [0.0, 0.0, 1.0]
    normal_stiffness_N_per_m: float | None = Field(None, gt=0)
    contact_modulus_GPa: float = Field(2.0, gt=0)
    contact_radius_mm: float = Field(100.0, gt=0)
    friction_coefficient: float = Field(0.3, ge=0, le=2)
    slip_displacement_um: float = Field(20.0, gt=0)
    contact_damping_ratio: float = Field(0.05, ge=0, lt=1)

    @field_validator("normal")
    @classmethod
    def _dir(cls, v: list[float]) -> list[float]:
        return _unit(v)

    def to_foot(self):
        from robobore.equivalent import PressureFoot

        return PressureFoot(
            pressure_Pa=self.pressure_MPa * 1e6,
            piston_area_m2=math.pi * (self.piston_diameter_mm * 1e-3 / 2) ** 2,
            normal=tuple(self.normal), normal_stiffness_N_per_m=self.normal_stiffness_N_per_m,
            contact_modulus_Pa=self.contact_modulus_GPa * 1e9,
            contact_radius_m=self.contact_radius_mm * 1e-3,
            friction_coefficient=self.friction_coefficient,
            slip_displacement_m=self.slip_displacement_um * 1e-6,
            contact_damping_ratio=self.contact_damping_ratio)


class EquivalentCfg(StrictModel):
    stiffness_N_per_m: XYZ
    frequency_Hz: XYZ
    damping_ratio: XYZ | None = None
    damping_N_s_per_m: float | None = Field(None, ge=0)
    pressure_foot: PressureFootCfg | None = None
    note: str = ""
    # rotation R, listed by rows, whose columns are the directions of the x, y, z units in
    # the boring frame (as `frame` of `model equivalent --json`); None: along X, Y, Z
    frame: list[list[float]] | None = None
    # the stiffness/frequency/damping already include a pressure foot (equivalent JSON)
    foot_included: bool = False
    # 95 % ranges per axis ({axis: {key: [lo, hi]}}, EquivalentModel.uncertainty): `lobes --band`
    uncertainty: dict[str, dict[str, list[float]]] | None = None

    @field_validator("stiffness_N_per_m", "frequency_Hz")
    @classmethod
    def _pos(cls, v: XYZ) -> XYZ:
        for a in "xyz":
            if not (getattr(v, a) > 0 and math.isfinite(getattr(v, a))):
                raise ValueError(f"component {a} must be positive")
        return v

    @model_validator(mode="after")
    def _damping(self):
        if (self.damping_ratio is None) == (self.damping_N_s_per_m is None):
            raise ValueError("give exactly one of damping_ratio or damping_N_s_per_m")
        if self.foot_included and self.pressure_foot is not None:
            raise ValueError("the model already includes a pressure foot; remove "
                             "pressure_foot (or use the model without the foot)")
        return self

    def to_model(self):
        from robobore.equivalent import EquivalentModel

        return EquivalentModel.build(
            self.stiffness_N_per_m.model_dump(), self.frequency_Hz.model_dump(),
            damping_ratio=None if self.damping_ratio is None else self.damping_ratio.model_dump(),
            damping_N_s_per_m=self.damping_N_s_per_m,
            frame=None if self.frame is None else np.asarray(self.frame, float),
            foot=None if self.pressure_foot is None else self.pressure_foot.to_foot(),
            notes=(self.note,) if self.note else (), uncertainty=self.uncertainty or {})


class ProcessCfg(StrictModel):
    cutting_coefficient_N_per_m2: float = Field(gt=0, le=1e12)
    force_direction: list[float]
    chip_normal: list[float]
    feed_mm_per_rev: float = Field(gt=0)  # range: robobore.io.ranges
    overlap_factor: float = Field(1.0, ge=0, le=1)
    n_inserts: int = Field(1, ge=1, le=12)

    @field_validator("force_direction", "chip_normal")
    @classmethod
    def _dir(cls, v: list[float]) -> list[float]:
        return _unit(v)


class SpeedCfg(StrictModel):
    min: float = Field(gt=0)  # range: robobore.io.ranges
    max: float = Field(gt=0)
    count: int = Field(gt=1, le=100000)

    @model_validator(mode="after")
    def _order(self):
        if self.max <= self.min:
            raise ValueError("max must be larger than min (r/min)")
        return self


#: The speed range of ``robobore lobes`` when the config has no ``[speed_rpm]`` section
#: (r/min): 100 .. 3000 r/min, 300 speeds -- robotic boring's range; the command says so.
DEFAULT_SPEED_RPM = SpeedCfg(min=100.0, max=3000.0, count=300)


def speed_range(cfg: DynamicsConfig) -> tuple[SpeedCfg, str | None]:
    """The ``[speed_rpm]`` section, or :data:`DEFAULT_SPEED_RPM` and a note saying so."""
    if cfg.speed_rpm is not None:
        return cfg.speed_rpm, None
    d = DEFAULT_SPEED_RPM
    return d, (f"no [speed_rpm] section: the default range {d.min:g} .. {d.max:g} r/min "
               f"({d.count} speeds) is used")


class InsertCfg(InsertSection):
    """The shared ``[insert]`` section (:class:`robobore.io.sections.InsertSection`) and the
    number of inserts on the bar."""

    n_inserts: int = Field(1, ge=1, le=12)

    def to_insert(self):
        from robobore.cutting.geometry import BoringInsert

        return BoringInsert(self.nose_radius_mm * 1e-3, self.approach_angle_deg,
                            self.end_edge_angle_deg, self.rake_deg, self.inclination_deg,
                            self.clearance_deg, self.edge_radius_um * 1e-6, self.n_inserts)


class BoreCfg(StrictModel):
    diameter_mm: float = Field(gt=1, le=2000)


class CuttingCfg(StrictModel):
    # upper bounds: the one range of each quantity, robobore.io.ranges (check_tree)
    speed_rpm: float = Field(gt=0)
    feed_mm_per_rev: float = Field(gt=0)
    depth_mm: float = Field(gt=0)
    overlap_factor: float = Field(1.0, ge=0, le=1)
    depth_modulation: bool = True
    # edge (ploughing) force also on the engaged trailing side of the nose (from the tip to
    # where it meets the previous pass); false: the leading edge only
    trailing_edge: bool = True


class CoefficientsCfg(StrictModel):
    material: str | None = None
    file: str | None = None
    oblique: bool = False
    Ktc_N_per_m2: float | None = None
    Krc_N_per_m2: float | None = None
    Kfc_N_per_m2: float | None = None
    Kte_N_per_m: float | None = None
    Kre_N_per_m: float | None = None
    Kfe_N_per_m: float | None = None
    provenance: str = "config file"
    #: a calibration's per-speed fits (``robobore.cutting.coefficient_files.read_per_speed_fits``:
    #: "<vc m/min>" -> {Ktc_N_per_m2, Kte_N_per_m, Kfc_N_per_m2, Kfe_N_per_m}), inline with
    #: the K values; from a ``file`` they are read from the file
    per_speed_fits: dict[str, Any] | None = None
    #: with per-speed fits at two or more speeds, evaluate them at the cutting speed pi D n
    #: (linear in ln(vc), held outside the calibrated speeds); false: the pooled set
    speed_dependent: bool = True
    #: the calibration's grid (``uncut_chip_thickness_um``, ``cutting_speed_m_per_min``), inline
    #: with the K values: the domain the set's warnings are judged on
    #: (``robobore.cutting.coefficient_files.calibrated_domain``); from a ``file`` it is read
    #: from the file
    grid: dict[str, list[float]] | None = None

    @model_validator(mode="after")
    def _one(self):
        given = [self.material is not None and self.file is None, self.file is not None,
                 self.Ktc_N_per_m2 is not None]
        if sum(given) != 1:
            raise ValueError("give exactly one of material, file or Ktc_N_per_m2 (+ others); "
                             "material with file names the file's material (checked)")
        if self.file is not None:  # material: what the file must be for (checked on reading)
            return self
        if self.per_speed_fits is not None and self.Ktc_N_per_m2 is None:
            raise ValueError("per_speed_fits go with inline Ktc_N_per_m2 (+ others); a "
                             "coefficients file carries its own")
        if self.material is not None and not self.speed_dependent:
            raise ValueError("speed_dependent = false applies to calibrated coefficients (file "
                             "or inline per_speed_fits); the measured TC4 default is always "
                             "interpolated at the cutting speed")
        from robobore.cutting.coefficient_sets import TC4_FE_NAMES, TC4_NAMES

        if self.material is not None and self.material.upper() not in TC4_NAMES + TC4_FE_NAMES:
            raise ValueError(f"unknown material {self.material!r}; expected 'TC4' (Ti-6Al-4V, "
                             "the measured default), 'TC4-FE' (the paper example's "
                             "FE-calibrated set, opt-in), or a coefficients file / inline "
                             "Ktc_N_per_m2 for another material")
        if self.material is not None and self.material.upper() in TC4_FE_NAMES and self.oblique:
            raise ValueError("oblique applies to the measured TC4 default; the FE-calibrated "
                             "'TC4-FE' set is for the paper's insert (inclination 0)")
        return self


class SimulationCfg(StrictModel):
    revolutions: int = Field(150, ge=1, le=20000)
    samples_per_rev: int = Field(0, ge=0, le=200000)
    # a run whose chatter verdict is within the growth estimate's uncertainty is lengthened
    # (doubling, up to 4 x revolutions) unless revolutions are given as an argument
    extend_undecided: bool = True
    ra_tolerance_um: float | None = Field(None, gt=0, le=100)

    @field_validator("ra_tolerance_um")
    @classmethod
    def _ra(cls, v: float | None) -> float | None:
        if v is not None and v < 0.01:
            raise ValueError(f"Ra tolerance {v:g} um is below 0.01 um (looks like mm; "
                             "expected um: machined bores 0.1 .. 12.5 um)")
        return v


class ModelFilesCfg(StrictModel):
    """``[model]``: the robot from identification outputs; paths relative to the TOML."""

    stiffness_file: str | None = None   # robobore identify stiffness --json
    modes_file: str | None = None       # robobore identify modes --json
    equivalent_file: str | None = None  # robobore model equivalent --json
    assign: list[int] | None = Field(None, min_length=3, max_length=3)  # modes for x, y, z
    damping_N_s_per_m: float | None = Field(None, ge=0)


class CalibrationCfg(StrictModel):
    """``[calibration]``: the observed cuts of ``calibrate dynamics`` (a CSV, relative to the
    TOML), the verdicts' label-noise rate and the largest depth of cut a proposed test cut may
    have (what the insert's cutting edge, the machine and the part allow; range:
    robobore.io.ranges ``depth_mm``, which also caps a proposal without it)."""

    observations: str | None = None
    label_noise: float | None = Field(None, ge=0, lt=0.5)
    max_depth_mm: float | None = Field(None, gt=0)  # range: robobore.io.ranges


class DynamicsConfig(StrictModel):
    model: ModelFilesCfg | None = None
    calibration: CalibrationCfg | None = None
    structure: StructureCfg | None = None
    equivalent: EquivalentCfg | None = None
    process: ProcessCfg | None = None
    insert: InsertCfg | None = None
    bore: BoreCfg | None = None
    cutting: CuttingCfg | None = None
    coefficients: CoefficientsCfg | None = None
    speed_rpm: SpeedCfg | None = None
    simulation: SimulationCfg = SimulationCfg()

    @model_validator(mode="after")
    def _sections(self):
        if self.structure is None and self.equivalent is None:
            raise ValueError("missing section 'structure' (tool-point modes) or 'equivalent'")
        if self.process is None:
            missing = [k for k in ("insert", "bore", "cutting") if getattr(self, k) is None]
            if missing:
                raise ValueError("missing section 'process' (single-point cutting) or the "
                                 "boring section(s) " + ", ".join(f"'{m}'" for m in missing))
        return self

    @property
    def is_boring(self) -> bool:
        return self.process is None


def _read_json_file(path: Path, what: str, source: str) -> dict[str, Any]:
    from robobore.io.readers import load_json

    if not path.is_file():
        raise ConfigError(f"{what} file not found", file=str(path),
                          expected=f"an existing JSON file (named in {source})")
    return load_json(path, f"{what} file", f"the JSON object written by {what}")


def resolve_model_files(raw: dict[str, Any], path: str | Path,
                        stiffness_file: str | Path | None = None,
                        modes_file: str | Path | None = None,
                        equivalent_file: str | Path | None = None) -> dict[str, Any]:
    """Replace the robot model given as identification outputs by an ``[equivalent]`` section.

    The files come from the options (paths as given) or from ``[model]`` in the TOML (paths
    relative to the TOML): a joint-stiffness JSON (``robobore identify stiffness --json``) and
    a modes JSON (``robobore identify modes --json``), combined as ``robobore model
    equivalent`` does (modes assigned by direction, or ``assign``), or one equivalent-model
    JSON (``robobore model equivalent --json``). The TOML may then hold only the process; an
    ``[equivalent]`` there may carry only ``pressure_foot``/``note``. Returns a new raw dict
    (``[model]`` with the resolved absolute paths, ``[equivalent]`` with the values used)."""
    from robobore.equivalent import EquivalentModel

    src = str(path)
    base = Path(path).resolve().parent
    sec = raw.get("model")
    mcfg = (validate_model(ModelFilesCfg, sec, source=f"{src} [model]")
            if isinstance(sec, dict) else ModelFilesCfg())
    if sec is not None and not isinstance(sec, dict):
        raise ConfigError("must be a table", file=src, field="model",
                          expected="[model] with stiffness_file/modes_file/equivalent_file")

    def pick(opt, key):
        if opt is not None:
            return Path(opt).resolve(), f"--{key.replace('_', '-')}"
        v = getattr(mcfg, key)
        return (None, None) if v is None else ((base / Path(v)).resolve(), f"model.{key}")

    sf, sf_where = pick(stiffness_file, "stiffness_file")
    mf, mf_where = pick(modes_file, "modes_file")
    ef, ef_where = pick(equivalent_file, "equivalent_file")
    if sf is None and mf is None and ef is None:
        return raw
    if ef is not None and (sf is not None or mf is not None):
        raise ConfigError("give either an equivalent-model file or a stiffness file and a "
                          "modes file, not both", file=src, field=ef_where,
                          expected="--equivalent-file, or --stiffness-file with --modes-file")
    if ef is None and (sf is None or mf is None):
        missing = "modes_file" if mf is None else "stiffness_file"
        raise ConfigError("a stiffness file needs a modes file and the other way round",
                          file=src, field=missing.replace("_", "-"),
                          expected="both --stiffness-file (identify stiffness --json) and "
                                   "--modes-file (identify modes --json), or [model] keys")
    extra = equivalent_extras(raw, "identification files and [equivalent] values",
                              "no model files", src)
    try:
        if ef is not None:
            em = EquivalentModel.from_dict(_read_json_file(ef, "model equivalent --json", src),
                                           str(ef))
            files = {"equivalent_file": str(ef)}
        else:
            em = EquivalentModel.from_stiffness_and_modes(
                _read_json_file(sf, "identify stiffness --json", src),
                _read_json_file(mf, "identify modes --json", src),
                None if mcfg.assign is None else dict(zip("xyz", mcfg.assign, strict=True)),
                damping_N_s_per_m=mcfg.damping_N_s_per_m, names=(str(sf), str(mf)))
            files = {"stiffness_file": str(sf), "modes_file": str(mf)}
    except ConfigError as exc:
        if exc.file is not None:
            raise
        where = str(ef) if ef is not None else f"{sf} + {mf}"
        raise ConfigError(exc.message, file=where, field=exc.field, value=exc.value,
                          expected=exc.expected) from None
    eq = equivalent_section(em, "; ".join(["from " + ", ".join(files.values()), *em.notes]))
    eq.update(extra)
    out = dict(raw)
    out["model"] = {**(sec if isinstance(sec, dict) else {}), **files}
    out["equivalent"] = eq
    return out


def load_dynamics_config(path: str | Path, stiffness_file: str | Path | None = None,
                         modes_file: str | Path | None = None,
                         equivalent_file: str | Path | None = None,
                         equivalent: Any = None,
                         ) -> tuple[DynamicsConfig, dict[str, Any]]:
    """Read and validate a config file; returns the model and the raw dict (for provenance).

    The robot may come from identification outputs (options or ``[model]``), see
    :func:`resolve_model_files`, or from ``equivalent`` (an EquivalentModel or its dict
    form, :func:`with_equivalent`); the raw dict then holds the ``[equivalent]`` values
    used."""
    raw = load_toml(path)
    if equivalent is not None:
        if stiffness_file is not None or modes_file is not None or equivalent_file is not None:
            raise ConfigError("the robot model is given twice (model files and the equivalent "
                              "argument)", file=str(path), field="equivalent",
                              expected="either model files or an equivalent model")
        raw = with_equivalent(raw, equivalent, str(path))
    raw = resolve_model_files(raw, path, stiffness_file, modes_file, equivalent_file)
    cfg = validate_model(DynamicsConfig, raw, source=path)
    if cfg.coefficients is not None and cfg.coefficients.file is not None:
        # the one rule (robobore.io.paths): relative to the config's folder; the absolute
        # path goes into the config recorded in the results
        f = str(resolve_config_path(cfg.coefficients.file, path, "coefficients.file",
                                    what="coefficients file"))
        cfg.coefficients.file = f
        raw = {**raw, "coefficients": {**raw["coefficients"], "file": f}}
    return cfg, raw


def build_structure(cfg: DynamicsConfig, source: str | None = None):
    """Tool-point structure: ``[structure]`` modes plus the ``[equivalent]`` units (if both)."""
    from robobore.dynamics.structure import ToolPointStructure

    modes: list[dict[str, Any]] = []
    if cfg.equivalent is not None:
        modes += cfg.equivalent.to_model().tool_point_modes()
    if cfg.structure is not None:
        modes += [m.model_dump() for m in cfg.structure.modes]
    return ToolPointStructure.from_modes(modes, file=source)


def cutting_speed_m_per_min(cfg: DynamicsConfig) -> float | None:
    """The cutting speed pi D n [m/min] of a boring config (None without bore or cutting)."""
    if cfg.bore is None or cfg.cutting is None:
        return None
    return math.pi * cfg.bore.diameter_mm * 1e-3 * cfg.cutting.speed_rpm


def build_coefficients(cfg: DynamicsConfig, source: str | None = None):
    """The cutting coefficients of ``[coefficients]`` at the config's cutting speed pi D n:
    the measured TC4 default interpolated at vc (``material = "TC4"``, also without a
    ``[coefficients]`` section); the paper example's FE-calibrated set with
    ``material = "TC4-FE"`` (opt-in; warned outside its 37.7 m/min); a calibration (file, or inline values with
    ``per_speed_fits``) with fits at several speeds evaluated at vc
    (:func:`robobore.cutting.coefficient_files.coefficients_at_speed`;
    ``speed_dependent = false``: the pooled set); inline values as given."""
    from robobore.cutting import coefficient_files, coefficient_sets

    c = cfg.coefficients
    vc = cutting_speed_m_per_min(cfg)
    if (c is not None and c.material is not None and c.file is None
            and c.material.upper() in coefficient_sets.TC4_FE_NAMES):
        return coefficient_sets.tc4_fe_coefficients(vc)
    if c is None or (c.material is not None and c.file is None):
        if c is not None and c.oblique:
            return coefficient_sets.ti64_oblique_coefficients(cfg.insert.to_insert(),
                                                              30.0 if vc is None else vc)
        return coefficient_sets.ti64_coefficients(vc)
    if c.file is not None:
        cf = resolve_config_path(c.file, source, "coefficients.file", what="coefficients file")
        coef = coefficient_files.load_coefficients(cf, vc, speed_dependent=c.speed_dependent)
        return coefficient_files.check_coefficients_identity(
            coef, cf, material=c.material, insert=cfg.insert,
            material_by=f"coefficients.material of {source or 'the config'}",
            insert_by=f"[insert] of {source or 'the config'}")
    d = {k: v for k, v in c.model_dump().items() if v is not None and k.startswith("K")}
    d["provenance"] = c.provenance
    data: dict[str, Any] = {"coefficients": d}
    if c.per_speed_fits is not None:
        data["per_speed_fits"] = c.per_speed_fits
    if c.grid is not None:
        data["grid"] = c.grid
    return coefficient_files.coefficients_at_speed(data, vc, speed_dependent=c.speed_dependent,
                                        source=source)


def lobe_coefficient_note(cfg: DynamicsConfig, coefficients: Any = None,
                          source: str | None = None) -> str | None:
    """The note of a lobe diagram whose coefficients (``coefficients``, already built, or
    None: :func:`build_coefficients`) depend on the cutting speed: they are evaluated once, at
    the ``[cutting]`` speed, not at each lobe speed (None otherwise)."""
    c = build_coefficients(cfg, source) if coefficients is None else coefficients
    vc = cutting_speed_m_per_min(cfg)
    if c.speed_m_per_min is None or cfg.cutting is None or vc is None:
        return None
    return (f"cutting coefficients evaluated at the cutting section's speed "
            f"{cfg.cutting.speed_rpm:g} r/min (vc {vc:.3g} m/min) and used at every lobe speed; "
            "they depend on the "
            "cutting speed (the process is linearised once)"
            + "".join(f"; {w}" for w in c.warnings))


def build_process(cfg: DynamicsConfig, source: str | None = None, depth_m: float | None = None,
                  coefficients: Any = None):
    """Process model: the ``[process]`` contract or the boring bar from insert + cutting,
    with ``coefficients`` (None: :func:`build_coefficients`)."""
    from robobore.dynamics.process import boring_process, single_point_process

    if cfg.process is not None:
        p = cfg.process
        return single_point_process(p.cutting_coefficient_N_per_m2, p.force_direction,
                                    p.chip_normal, p.feed_mm_per_rev * 1e-3, p.n_inserts,
                                    p.overlap_factor)
    ins = cfg.insert.to_insert()
    cut = cfg.cutting
    if ins.nose_radius_m * 2 >= cfg.bore.diameter_mm * 1e-3:
        raise ConfigError("nose radius too large for the bore", file=source,
                          field="insert.nose_radius_mm", value=cfg.insert.nose_radius_mm,
                          expected=f"< bore radius {cfg.bore.diameter_mm / 2} mm")
    coef = build_coefficients(cfg, source) if coefficients is None else coefficients
    return boring_process(ins, coef,
                          cut.depth_mm * 1e-3 if depth_m is None else depth_m,
                          cut.feed_mm_per_rev * 1e-3, overlap=cut.overlap_factor,
                          depth_modulation=cut.depth_modulation,
                          trailing_edge=cut.trailing_edge)


__all__ = ["DynamicsConfig", "load_dynamics_config", "resolve_model_files", "build_structure",
           "build_process", "build_coefficients", "cutting_speed_m_per_min",
           "lobe_coefficient_note", "DEFAULT_SPEED_RPM", "speed_range"]
