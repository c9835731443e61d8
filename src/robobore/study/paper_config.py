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

from pydantic import Field

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
    file: str  # stored FE-calibrated coefficients (used by --fast)
    #: per-speed fits at two or more speeds evaluated at each condition's cutting speed
    #: (robobore.cutting.forces.coefficients_at_speed); false: the pooled set
    speed_dependent: bool = True


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


__all__ = ["PaperConfig", "load_paper_config", "example_config_path", "example_dir",
           "StudySection", "RobotSection", "ModalSection", "MachineToolSection",
           "LobesSection", "MaterialSection", "CoefficientsSection", "MeasuredSection", "XYZ"]
