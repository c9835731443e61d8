"""The config of ``robobore paper`` (TOML, documented in ``docs/paper.md`` and in the
bundled example ``robobore/data/paper_example/paper.toml``): its sections as pydantic models
(:class:`PaperConfig`) and its reader (:func:`load_paper_config`: ranges, the files it names
resolved against its folder, the ``[calibration]`` section checked even when ``--fast``
does not run it).
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, field_validator

from robobore.dynamics.config import BoreCfg, InsertCfg, PressureFootCfg
from robobore.errors import ConfigError
from robobore.io.sections import StrictModel


def example_dir() -> Path:
    """Folder of the bundled example (config, coefficients, SYNTHETIC measured CSV)."""
    return Path(str(resources.files("robobore") / "data" / "paper_example"))


def example_config_path() -> Path:
    return example_dir() / "paper.toml"


class XYZ(StrictModel):
    x: float = Field(gt=0)
    y: float = Field(gt=0)
    z: float = Field(gt=0)


class StudySection(StrictModel):
    name: str = "paper"
    title: str = "Robotic boring of TC4: the paper's study"
    revolutions: int = Field(60, ge=10, le=5000)
    ra_tolerance_um: float = Field(1.6, gt=0)
    samples_per_rev_stored: int = Field(120, ge=8, le=100000)
    speed_rpm: list[float] = Field(default_factory=lambda: [200.0, 300.0, 400.0, 500.0, 600.0,
                                                             800.0, 1000.0])
    feed_mm_per_rev: list[float] = Field(default_factory=lambda: [0.1, 0.125, 0.15, 0.2, 0.3,
                                                                   0.4, 0.5])
    depth_of_cut_mm: list[float] = Field(default_factory=lambda: [0.05, 0.1, 0.15, 0.2, 0.25,
                                                                   0.3])
    pressure_MPa: list[float] = Field(default_factory=lambda: [0.0, 0.3])
    base: dict[str, float] = Field(default_factory=lambda: {
        "speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05})
    design: Literal["ofat", "grid"] = "ofat"
    machine_tool: bool = True


class RobotSection(StrictModel):
    name: str = "irb6600-175-2.55"
    campaign: str | None = None  # None: bundled SYNTHETIC campaign
    posture_deg: list[float] = Field(
        default_factory=lambda: [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95])
    tcp_m: list[float] = Field(default_factory=lambda: [0.0, 0.0, 0.0])


class ModalSection(StrictModel):
    file: str | None = None  # None: bundled SYNTHETIC hammer test
    band_Hz: list[float] = Field(default_factory=lambda: [3.0, 60.0], min_length=2,
                                 max_length=2, description="analysis band [lo, hi], Hz")
    n_modes: int = Field(5, ge=3, le=50)
    max_order: int = Field(40, ge=4, le=200)


class MachineToolSection(StrictModel):
    note: str = ""
    stiffness_N_per_m: XYZ
    frequency_Hz: XYZ
    damping_ratio: XYZ


class LobesSection(StrictModel):
    speed_min_rpm: float = Field(150.0, gt=0)
    speed_max_rpm: float = Field(1100.0, gt=0)
    count: int = Field(200, ge=10, le=5000)
    method: Literal["frequency", "semidiscretization"] = "semidiscretization"


class MaterialSection(StrictModel):
    name: str = "TC4"


class CoefficientsSection(StrictModel):
    #: the set the boring model (sweep, lobes, posture plan) uses: "TC4" the measured default
    #: (robobore.cutting.coefficient_sets.ti64_coefficients, 5-30 m/min, h 40-80 um); "TC4-FE" the
    #: force calibration of this config (``file`` with --fast, the FE runs of [calibration]
    #: otherwise), also the way to use a coefficients file of one's own
    material: str = "TC4"
    #: the stored force calibration (FE-calibrated coefficients): the report's FE
    #: force-model section with --fast, and the set used with material = "TC4-FE"
    file: str
    #: per-speed fits at two or more speeds evaluated at each condition's cutting speed
    #: (robobore.cutting.coefficient_files.coefficients_at_speed); false: the pooled set
    speed_dependent: bool = True

    @field_validator("material")
    @classmethod
    def _material(cls, v: str) -> str:
        from robobore.cutting.coefficient_sets import TC4_FE_NAMES, TC4_NAMES

        if v.upper() not in TC4_NAMES + TC4_FE_NAMES:
            raise ValueError(f"unknown coefficient set {v!r}; expected 'TC4' (the measured "
                             "default) or 'TC4-FE' (this config's force calibration: the "
                             "stored file with --fast, the FE calibration otherwise)")
        return v

    def uses_calibration(self) -> bool:
        """True when the boring model uses this config's force calibration ("TC4-FE")."""
        from robobore.cutting.coefficient_sets import TC4_FE_NAMES

        return self.material.upper() in TC4_FE_NAMES


class MeasuredSection(StrictModel):
    file: str | None = None
    # observed cuts (calibrate dynamics CSV): the report shows the corrected lobes' band
    observations: str | None = None
    truth_note: str = ""


class PaperConfig(StrictModel):
    study: StudySection = StudySection()
    robot: RobotSection = RobotSection()
    modal: ModalSection = ModalSection()
    insert: InsertCfg = InsertCfg()
    bore: BoreCfg
    material: MaterialSection = MaterialSection()
    pressure_foot: PressureFootCfg = PressureFootCfg()
    machine_tool: MachineToolSection
    calibration: dict[str, Any]
    coefficients: CoefficientsSection
    measured: MeasuredSection = MeasuredSection()
    lobes: LobesSection = LobesSection()


def model_coefficients(cfg: PaperConfig, calibration: dict[str, Any]) -> dict[str, Any]:
    """The ``[coefficients]`` table of the boring model of every stage (sweep, lobes, lobe
    check, posture plan): ``{"material": "TC4"}`` (the measured default, interpolated at each
    condition's cutting speed) or, with ``material = "TC4-FE"``, the force calibration
    ``calibration`` (a coefficients-file content) inline, with its grid and per-speed fits."""
    from robobore.cutting.coefficient_files import inline_coefficients

    if cfg.coefficients.uses_calibration():
        return inline_coefficients(calibration, cfg.coefficients.speed_dependent)
    return {"material": "TC4"}


def coefficient_set(cfg: PaperConfig, calibration: dict[str, Any],
                    mode: str | None = None) -> dict[str, Any]:
    """What the report and ``paper_summary.json`` say about the set the boring model uses:
    ``name``, ``description``, the calibrated ``domain`` (cutting speeds [m/min], uncut chip
    thicknesses [um]), the values at the base condition's cutting speed (``coefficients``)
    and ``warnings``: the set's own warning at each study speed outside its calibrated
    speeds (the base condition's first). The per-condition warnings (chip thickness
    included) are the sweep's."""
    from robobore.cutting import coefficient_files, coefficient_sets

    if cfg.coefficients.uses_calibration():
        h, v = coefficient_files.calibrated_domain(calibration)
        name = "TC4-FE"
        desc = ("this config's force calibration (FE-calibrated, opt-in: [coefficients] "
                f"material = \"TC4-FE\"; {mode or 'calibration'})")
    else:
        fits = sorted(coefficient_sets.ducobu_fits())
        h, v = coefficient_sets.TI64_CHIP_THICKNESS_M, (fits[0], fits[-1])
        name = "TC4"
        desc = ("the measured TC4 default (least-squares fit of measured orthogonal forces, "
                "Ducobu et al., CIRP 2022), interpolated at each condition's cutting speed; "
                "the FE-calibrated set is opt-in ([coefficients] material = \"TC4-FE\")")
    n_base = float(cfg.study.base["speed_rpm"])
    speeds = [n_base] + sorted({float(n) for n in cfg.study.speed_rpm} - {n_base})
    warnings: list[str] = []
    base_c = None
    for n in speeds:  # the base condition's speed first
        vc = math.pi * cfg.bore.diameter_mm * 1e-3 * n
        c = (coefficient_files.coefficients_at_speed(calibration, vc,
                                          speed_dependent=cfg.coefficients.speed_dependent)
             if cfg.coefficients.uses_calibration() else coefficient_sets.ti64_coefficients(vc))
        base_c = c if base_c is None else base_c
        warnings += [f"coefficient set {name} at {n:g} r/min"
                     + (" (the base condition)" if n == n_base else "") + f": {w}"
                     for w in c.warnings]
    vc_base = math.pi * cfg.bore.diameter_mm * 1e-3 * float(cfg.study.base["speed_rpm"])
    return {
        "name": name, "description": desc,
        "domain": {"cutting_speed_m_per_min": None if v is None else [v[0], v[1]],
                   "uncut_chip_thickness_um": None if h is None else
                   [round(h[0] * 1e6, 6), round(h[1] * 1e6, 6)]},
        "base_cutting_speed_m_per_min": vc_base,
        "coefficients": base_c.to_dict(), "warnings": warnings,
    }


def load_paper_config(path: str | Path | None = None) -> tuple[PaperConfig, dict[str, Any], Path]:
    """Read and validate a paper config; returns the model, the raw dict and its path."""
    from robobore.io.config import load_toml, validate_model

    p = Path(path) if path is not None else example_config_path()
    raw = load_toml(p)
    cfg = validate_model(PaperConfig, raw, source=p)
    for name in ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm"):
        lv = getattr(cfg.study, name)
        if not lv or any(not (math.isfinite(v) and v > 0) for v in lv):
            raise ConfigError("levels must be positive numbers", file=str(p),
                              field=f"study.{name}", value=lv,
                              expected="a non-empty list of positive values")
        if name not in cfg.study.base:
            raise ConfigError("missing base value", file=str(p), field=f"study.base.{name}",
                              expected="the base condition of the one-factor-at-a-time design")
    if any(v < 0 for v in cfg.study.pressure_MPa) or not cfg.study.pressure_MPa:
        raise ConfigError("bad foot pressures", file=str(p), field="study.pressure_MPa",
                          value=cfg.study.pressure_MPa, expected="a list of values >= 0 MPa")
    if not 0.0 <= cfg.modal.band_Hz[0] < cfg.modal.band_Hz[1]:
        raise ConfigError("empty analysis band", file=str(p), field="modal.band_Hz",
                          value=cfg.modal.band_Hz, expected="[lo, hi] with 0 <= lo < hi (Hz)")
    if cfg.lobes.speed_max_rpm <= cfg.lobes.speed_min_rpm:
        raise ConfigError("lobe speed range empty", file=str(p), field="lobes.speed_max_rpm",
                          value=cfg.lobes.speed_max_rpm,
                          expected=f"> speed_min_rpm = {cfg.lobes.speed_min_rpm} r/min")
    raw = _resolve_files(cfg, raw, p)
    # the [calibration] section is validated even when --fast does not run it
    from robobore.cutting.calibration_config import calibration_from_mapping

    try:
        calibration_from_mapping({"calibration": raw.get("calibration", {}),
                                  "insert": raw.get("insert", {}),
                                  "material": raw.get("material", {})}, source=str(p))
    except ConfigError as exc:  # keys of the calibration model: name them in the file's terms
        f = exc.field or ""
        if f and not f.startswith(("calibration", "insert", "material")):
            raise ConfigError(exc.message, file=exc.file, field=f"calibration.{f}",
                              value=exc.value, expected=exc.expected) from None
        raise
    return cfg, raw, p


def _resolve_files(cfg: PaperConfig, raw: dict[str, Any], p: Path) -> dict[str, Any]:
    """Files named in the config, resolved against its folder (robobore.io.paths); the
    absolute paths replace the names in ``cfg`` and in the raw config kept as provenance."""
    from robobore.io.paths import names_a_path, resolve_config_path

    for sec, key, must, what in (("robot", "campaign", True, "campaign CSV"),
                                 ("modal", "file", True, "hammer-test file"),
                                 ("coefficients", "file", False, "coefficients file"),
                                 ("measured", "file", True, "measured CSV")):
        v = getattr(getattr(cfg, sec), key)
        if v is None:
            continue
        a = str(resolve_config_path(v, p, f"{sec}.{key}", must_exist=must, what=what))
        setattr(getattr(cfg, sec), key, a)
        raw = {**raw, sec: {**raw.get(sec, {}), key: a}}
    if names_a_path(cfg.robot.name):
        a = str(resolve_config_path(cfg.robot.name, p, "robot.name", what="robot file"))
        cfg.robot.name = a
        raw = {**raw, "robot": {**raw.get("robot", {}), "name": a}}
    return raw


__all__ = ["PaperConfig", "load_paper_config", "model_coefficients", "coefficient_set", "example_config_path", "example_dir",
           "StudySection", "RobotSection", "ModalSection", "MachineToolSection",
           "LobesSection", "MaterialSection", "CoefficientsSection", "MeasuredSection", "XYZ"]
