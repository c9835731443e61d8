"""What the force calibration runs: the grid, the insert, the material and the FE model of
its virtual tests (:mod:`robobore.cutting.calibrate` fits the coefficients to them).

The FE model of the virtual tests is a full FE orthogonal config (``fe_config``: a TOML file,
resolved next to the calibration config, or an inline table; everything ``robobore fe
orthogonal`` accepts): each virtual test overrides only its uncut chip thickness and cutting
speed, and runs at the insert's own rake angle, edge radius and clearance. An FE config whose
``[tool]`` gives another rake or edge radius than the insert is refused. Without
``fe_config`` the ``fe`` table is a shorthand of a few settings for the workpiece-frame model
with the a-priori parameters (:class:`FESettings`). Every grid point's FE config is checked
by the engine's config model when the calibration config is read, before any run.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, field_validator

from robobore.errors import ConfigError
from robobore.io.sections import StrictModel


class FESettings(StrictModel):
    """Shorthand FE settings of the virtual tests when no ``fe_config`` is given: the
    workpiece-frame model with the a-priori parameters (see docs/fe.md; coarse but within the
    engine's checks: element size <= h/3)."""

    length_mm: float = Field(0.4, gt=0, le=10, description="length of cut, mm")
    element_size_um: float = Field(20.0, gt=0, le=200, description="element size, um")
    mass_scaling: float = Field(100.0, ge=1, le=1e6)
    friction: float | Literal["table"] = "table"
    shear_limit_MPa: float = Field(576.0, gt=0)
    clearance_deg: float = Field(7.0, gt=0, le=30)
    steady_window_fraction: float = Field(0.5, gt=0, le=1)
    #: the engine's mesh.separation and mesh.separation_height_um (docs/fe.md)
    separation: Literal["node_split", "erosion_layer"] = "erosion_layer"
    separation_height_um: float | None = Field(None, ge=0)


class CalibrationConfig(StrictModel):
    """What to calibrate: material, insert edge, grid and FE settings."""

    material: str = "TC4"
    rake_deg: float = Field(7.0, ge=-30, le=40, description="insert rake angle, deg")
    edge_radius_um: float = Field(20.0, ge=0, le=200, description="edge radius, um")
    inclination_deg: float = Field(0.0, ge=-30, le=30, description="inclination, deg")
    uncut_chip_thickness_um: list[float] = Field(min_length=2)
    cutting_speed_m_per_min: list[float] = Field(min_length=1)
    fe: FESettings = FESettings()
    #: the full FE config of the virtual tests (resolved: a file's content or the inline
    #: table, with the insert's tool and the material filled in); None: the ``fe`` shorthand
    fe_config: dict[str, Any] | None = None
    #: where ``fe_config`` came from: the resolved file path, or "inline"
    fe_config_source: str | None = None

    @field_validator("uncut_chip_thickness_um", "cutting_speed_m_per_min")
    @classmethod
    def _pos(cls, v: list[float]) -> list[float]:
        for x in v:
            if not (math.isfinite(x) and x > 0):
                raise ValueError(f"value {x} must be positive and finite")
        if len(set(v)) != len(v):
            raise ValueError("levels must be distinct")
        return [float(x) for x in v]


def calibration_from_mapping(data: dict[str, Any], source: str | None = None,
                             other_sections: Collection[str] = ()) -> CalibrationConfig:
    """Calibration config from a TOML mapping.

    Accepts either a file with a ``[calibration]`` table (and optionally ``[insert]``
    (rake_deg, edge_radius_um, inclination_deg, clearance_deg) and ``[material] name``, which
    fill the calibration's insert and material when it does not give them), or the
    calibration keys at top level. ``other_sections``: the further top-level sections of a
    config that holds a calibration (a paper config's); any other section is refused.
    """
    from robobore.io.config import validate_model

    if "calibration" in data:  # a typo'd section is an error, not ignored
        known = {"calibration", "insert", "material", "range_check", *other_sections}
        extra = sorted(set(data) - known)
        if extra:
            raise ConfigError("unknown section (a typo?)", file=source, field=extra[0],
                              expected="the sections [calibration], [insert], [material] (or "
                              "those of a paper config)")
    cal = dict(data.get("calibration", data))
    user_fe = "fe" in cal
    ins = data.get("insert", {}) if "calibration" in data else {}
    mat = data.get("material", {}) if "calibration" in data else {}
    for k in ("rake_deg", "edge_radius_um", "inclination_deg"):
        if k in ins and k not in cal:
            cal[k] = ins[k]
    if "clearance_deg" in ins:
        fe = dict(cal.get("fe", {}))
        fe.setdefault("clearance_deg", ins["clearance_deg"])
        cal["fe"] = fe
    if isinstance(mat, dict) and "name" in mat and "material" not in cal:
        cal["material"] = mat["name"]
    for k in ("insert", "material"):
        if "calibration" not in data:
            cal.pop(k, None)
    prefix = "calibration." if "calibration" in data else ""
    fe_full = cal.pop("fe_config", None)
    cal.pop("fe_config_source", None)
    if fe_full is not None and user_fe:
        raise ConfigError("give the FE model once", file=source, field=f"{prefix}fe",
                          value=cal["fe"], expected=f"either {prefix}fe_config (a full FE "
                          f"config) or the {prefix}fe shorthand, not both")
    cfg = validate_model(CalibrationConfig, cal, source=source)
    from robobore.material.library import load_material, resolve_material_name

    mat_field = f"{prefix}material" if "material" in cal else "material.name"
    cfg.material = resolve_material_name(cfg.material, source, mat_field)
    load_material(cfg.material, source=source, field=mat_field)  # read and checked now
    if fe_full is not None:
        full, src = _resolve_fe_config(fe_full, source, f"{prefix}fe_config")
        cfg = cfg.model_copy(update={"fe_config": _with_insert(cfg, full, source, prefix, src),
                                     "fe_config_source": src})
        _check_grid(cfg, source, f"{prefix}fe_config")
        return cfg
    smallest = min(cfg.uncut_chip_thickness_um)
    if cfg.fe.element_size_um > smallest / 3 + 1e-9:
        raise ConfigError("FE element too large for the thinnest chip", file=source,
                          field="calibration.fe.element_size_um", value=cfg.fe.element_size_um,
                          expected=f"<= h/3 = {smallest / 3:.4g} um (FE engine check)")
    _check_grid(cfg, source, f"{prefix}fe")
    return cfg


def _resolve_fe_config(value: Any, source: str | None, field: str) -> tuple[dict[str, Any], str]:
    """The FE config of ``fe_config``: a TOML file path (relative to the calibration config's
    folder) or an inline table; returns (a fresh dict, its source)."""
    import copy

    from robobore.io.config import load_toml

    if isinstance(value, dict):
        return copy.deepcopy(value), "inline"
    if not isinstance(value, str) or not value.strip():
        raise ConfigError("bad FE config", file=source, field=field, value=value,
                          expected="a path to an FE orthogonal config TOML (relative to this "
                          "file) or an inline table")
    from robobore.io.paths import resolve_config_path

    p = resolve_config_path(value, source, field, what="FE config file")
    return load_toml(p), str(p)


def _with_insert(cfg: CalibrationConfig, full: dict[str, Any], source: str | None,
                 prefix: str, src: str) -> dict[str, Any]:
    """The FE config at the insert's rake, edge radius and clearance and the calibration's
    material; a different rake, edge radius or material in the FE config is an error."""
    tool = full.get("tool", {})
    if not isinstance(tool, dict):
        raise ConfigError("[tool] must be a table", file=src, field="tool", value=tool,
                          expected="a table (or nothing: the insert's values are used)")
    insert = {"rake_deg": cfg.rake_deg, "edge_radius_um": cfg.edge_radius_um,
              "clearance_deg": cfg.fe.clearance_deg}
    for k in ("rake_deg", "edge_radius_um"):
        if k in tool and float(tool[k]) != float(insert[k]):
            raise ConfigError("the FE config's tool differs from the insert", file=src,
                              field=f"tool.{k}", value=tool[k],
                              expected=f"the insert's {k} = {insert[k]:g} (the virtual tests "
                              "run at the insert's own edge; or leave the key out)")
    clear = tool.get("clearance_deg", insert["clearance_deg"])
    full["tool"] = {**tool, "rake_deg": insert["rake_deg"],
                    "edge_radius_um": insert["edge_radius_um"], "clearance_deg": clear}
    mat = full.get("material", {})
    if isinstance(mat, dict):
        name = mat.get("name")
        if name is not None and str(name) != cfg.material:
            raise ConfigError("the FE config's material differs from the calibration's",
                              file=src, field="material.name", value=name,
                              expected=f"{cfg.material!r} (the {prefix}material or "
                              "[material] name), or leave the key out")
        full["material"] = {**mat, "name": cfg.material}
    return full


#: the FE engine's key of each ``fe`` shorthand setting (errors name the shorthand's key)
_SHORTHAND_KEYS = {"cut.length_mm": "length_mm", "mesh.element_size_um": "element_size_um",
                   "solver.mass_scaling": "mass_scaling", "contact.friction": "friction",
                   "contact.shear_limit_MPa": "shear_limit_MPa",
                   "tool.clearance_deg": "clearance_deg",
                   "solver.steady_window_fraction": "steady_window_fraction",
                   "mesh.separation": "separation",
                   "mesh.separation_height_um": "separation_height_um"}
_GRID_KEYS = {"cut.uncut_chip_thickness_um": "uncut_chip_thickness_um",
              "cut.cutting_speed_m_per_min": "cutting_speed_m_per_min",
              "tool.rake_deg": "rake_deg", "tool.edge_radius_um": "edge_radius_um"}


def _check_grid(cfg: CalibrationConfig, source: str | None, field: str) -> None:
    """Every virtual test's config passes the engine's checks (before any run). An error
    names the key as the user wrote it: the shorthand's (``calibration.fe.<key>``), the
    inline table's (``calibration.fe_config.<key>``), the FE config file's own key (with that
    file), or the grid's key for h and vc."""
    from robobore.cutting.fe.config.orthogonal import parse_config

    for h in cfg.uncut_chip_thickness_um:
        for v in cfg.cutting_speed_m_per_min:
            try:
                parse_config(fe_config_dict(cfg, h, v), cfg.fe_config_source)
            except ConfigError as exc:
                key = exc.field
                if cfg.fe_config is None and key in _SHORTHAND_KEYS:
                    key = f"{field}.{_SHORTHAND_KEYS[key]}"
                elif key in _GRID_KEYS:  # the grid's or the insert's own key
                    key = f"{field.rsplit('.', 1)[0]}.{_GRID_KEYS[key]}" if "." in field \
                        else _GRID_KEYS[key]
                elif cfg.fe_config_source == "inline" and key:  # the key in this file
                    key = f"{field}.{key}"
                expected = exc.expected
                if expected is None and exc.field in ("cut.uncut_chip_thickness_um",
                                                      "cut.cutting_speed_m_per_min"):
                    expected = _engine_range(exc.field)
                msg = exc.message.removesuffix(f" (got {exc.value!r})")  # said once below
                raise ConfigError(f"{field} at the grid point h {h:g} um, vc {v:g} m/min: "
                                  f"{msg}",
                                  file=source if exc.file in (None, "inline", "<config>")
                                  else exc.file,
                                  field=key,
                                  value=exc.value, expected=expected) from None


def _engine_range(key: str) -> str:
    """The FE engine's accepted range of a ``cut`` key, in words."""
    from robobore.cutting.fe.config.orthogonal import CutSection

    name = key.split(".")[-1]
    b = {k: getattr(m, k) for m in CutSection.model_fields[name].metadata
         for k in ("gt", "ge", "lt", "le") if getattr(m, k, None) is not None}
    sym = {"gt": ">", "ge": ">=", "lt": "<", "le": "<="}
    unit = "um" if name.endswith("_um") else "m/min"
    return (" and ".join(f"{sym[k]} {v:g}" for k, v in b.items()) + f" {unit} (the FE "
            f"engine's range of {key})")


def load_calibration_config(path: str | Path, other_sections: Collection[str] = ()
                            ) -> CalibrationConfig:
    """The calibration config of a TOML file (``other_sections``: see
    :func:`calibration_from_mapping`)."""
    from robobore.io.config import load_toml

    return calibration_from_mapping(load_toml(path), source=str(path),
                                    other_sections=other_sections)


def fe_config_dict(cfg: CalibrationConfig, h_um: float, vc_m_per_min: float) -> dict[str, Any]:
    """The FE engine's config (``robobore fe orthogonal`` contract) of one grid point."""
    if cfg.fe_config is not None:
        from robobore.cutting.fe.models.validate import point_config

        return point_config(cfg.fe_config, h_um, vc_m_per_min)
    fe = cfg.fe
    return {
        "parameters": "a_priori",
        "material": {"name": cfg.material},
        "tool": {"rake_deg": cfg.rake_deg, "clearance_deg": fe.clearance_deg,
                 "edge_radius_um": cfg.edge_radius_um},
        "cut": {"uncut_chip_thickness_um": float(h_um),
                "cutting_speed_m_per_min": float(vc_m_per_min),
                "length_mm": fe.length_mm, "width_mm": 1.0},
        "contact": {"friction": fe.friction, "shear_limit_MPa": fe.shear_limit_MPa},
        "mesh": {"frame": "workpiece", "element_size_um": fe.element_size_um,
                 "separation": fe.separation,
                 **({} if fe.separation_height_um is None
                    else {"separation_height_um": fe.separation_height_um})},
        "solver": {"mass_scaling": fe.mass_scaling, "heat_conduction": False,
                   "steady_window_fraction": fe.steady_window_fraction},
    }


#: where the validated model was checked against measured forces (docs/fe.md, "Model choice":
#: ../shared/data/ti64_orthogonal_cutting_forces.json, TC4)
VALIDATION_DOMAIN = {"uncut_chip_thickness_um": (40.0, 80.0),
                     "cutting_speed_m_per_min": (5.0, 30.0), "rake_deg": 15.0,
                     "edge_radius_um": 20.0, "element_size_um": 10.0, "length_mm": 0.3,
                     "material": "TC4"}


def domain_departures(h_um: Sequence[float], vc_m_per_min: Sequence[float], *,
                      rake_deg: float, edge_radius_um: float, element_size_um: float,
                      length_mm: float, material: str) -> list[str]:
    """How FE runs at the chip thicknesses ``h_um`` and cutting speeds ``vc_m_per_min`` with
    this tool, mesh, cut length and material leave :data:`VALIDATION_DOMAIN`, one line per
    departure in words (empty: inside it). Used by ``robobore fe orthogonal`` (its
    ``warnings``) and by the calibration's FE model description."""
    d = VALIDATION_DOMAIN
    out = []
    for key, vals in (("uncut_chip_thickness_um", h_um), ("cutting_speed_m_per_min", vc_m_per_min)):
        lo, hi = d[key]
        off = [v for v in vals if not lo <= v <= hi]
        if off:
            out.append(f"{key} {', '.join(f'{v:g}' for v in off)} outside the validated "
                       f"{lo:g}-{hi:g}")
    for key, val in (("rake_deg", rake_deg), ("edge_radius_um", edge_radius_um)):
        if val != d[key]:
            out.append(f"{key} {val:g} (validated at {d[key]:g})")
    if element_size_um > d["element_size_um"]:
        out.append(f"element_size_um {element_size_um:g} coarser than the validated "
                   f"{d['element_size_um']:g}")
    if length_mm < d["length_mm"]:
        out.append(f"length_mm {length_mm:g} shorter than the validated {d['length_mm']:g}")
    if material != d["material"]:
        out.append(f"material {material} (validated on {d['material']})")
    return out


def fe_model_description(cfg: CalibrationConfig) -> dict[str, Any]:
    """The FE model of the virtual tests in words, with its validation status: whether its
    physics (frame, friction, material, conduction) are the engine's validated defaults."""
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.models.choose import choose_orthogonal

    h0, v0 = cfg.uncut_chip_thickness_um[0], cfg.cutting_speed_m_per_min[0]
    c = parse_config(fe_config_dict(cfg, h0, v0))
    ref = parse_config({k: c.model_dump()[k] for k in ("tool", "cut")} |
                       {"mesh": {"element_size_um": c.mesh.element_size_um}})
    model = choose_orthogonal(c)
    same = (type(model) is type(choose_orthogonal(ref))
            and c.contact.model_dump() == ref.contact.model_dump()
            and c.material.model_dump() == ref.material.model_dump()
            and c.parameters == ref.parameters
            and c.solver.heat_conduction == ref.solver.heat_conduction
            and c.tool_support is None)
    law = c.friction_law()
    summary = (f"{model.frame}-frame model, {c.mesh.element_size_um:g} um elements, "
               f"{c.cut.length_mm:g} mm of {'tool travel' if model.tool_frame else 'cut'}, "
               f"friction {law}, parameters {c.parameters}")
    validation = ("the engine's validated model (docs/fe.md, 'Model choice': Fc within 10 % "
                  "and Ff within 25 % of the nine measured Ti6Al4V points, h 40-80 um, "
                  "vc 5-30 m/min, 10 um elements; CALIBRATED friction law and hardening "
                  "hold chosen on those points)" if same else
                  "not the engine's validated model (docs/fe.md, 'Model choice')")
    return {"source": cfg.fe_config_source or "fe shorthand (workpiece frame, a-priori)",
            "summary": summary, "validation": validation, "validated_physics": same,
            "outside_validation": domain_departures(
                cfg.uncut_chip_thickness_um, cfg.cutting_speed_m_per_min,
                rake_deg=cfg.rake_deg, edge_radius_um=cfg.edge_radius_um,
                element_size_um=c.mesh.element_size_um, length_mm=c.cut.length_mm,
                material=cfg.material),
            "config": None if cfg.fe_config is None else cfg.fe_config}

__all__ = ["FESettings", "CalibrationConfig", "calibration_from_mapping",
           "load_calibration_config", "fe_config_dict", "fe_model_description", "domain_departures",
           "VALIDATION_DOMAIN"]
