"""Cutting conditions of a study and the sweep configuration (TOML) that lists them.

A :class:`Condition` is one boring experiment: spindle speed, feed per revolution, radial
depth of cut, pressure-foot pressure and robot posture, in the human units of the paper
(the unit is in the name; the runner converts to SI once with :meth:`Condition.to_si`).

A sweep config (see ``docs/study.md`` and ``examples/sweep_demo.toml``)::

    [sweep]
    name = "demo"            # a label
    runner = "demo"          # a registered runner name or "package.module:function"
    seed = 0                 # base seed; each condition gets its own derived seed

    [grid]                   # full factorial (Cartesian product) of the levels
    speed_rpm = [200, 400, 600, 800, 1000]            # or {start = 200, stop = 1000, num = 5}
    feed_mm_per_rev = [0.1, 0.3, 0.5]
    depth_of_cut_mm = [0.05, 0.1, 0.2, 0.3]
    pressure_MPa = [0.0, 0.3]
    posture = ["paper"]      # optional

    [[conditions]]           # and/or an explicit list of conditions
    speed_rpm = 300
    feed_mm_per_rev = 0.15
    depth_of_cut_mm = 0.05
    pressure_MPa = 0.0

    [model]                  # runner parameters: part of every condition's key
    [runner_options]         # runner options that do not change results (not hashed)
    [postures.paper]         # optional named postures (joint angles in deg)
    joints_deg = [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95]

``[sweep] levels = "paper-ofat"`` or ``"paper-grid"`` adds the built-in paper levels
(:data:`PAPER_LEVELS`). A condition listed twice is an error, not silently merged.
"""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator, model_validator

from robobore.errors import ConfigError
from robobore.io.config import load_toml, validate_model
from robobore.io.hashing import stable_hash
from robobore.io.ranges import check_positive

#: Quantities that identify a condition, in CSV/config order.
CONDITION_FIELDS = ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm", "pressure_MPa")

#: Posture name used when a condition names none.
DEFAULT_POSTURE = "paper"

#: Levels of the paper's kind of study (Table 6 of the paper is missing from our copy; the
#: ranges are those the text and issue 6 give: speed 200-1000 r/min, feed 0.1-0.5 mm/r,
#: depth of cut 0.05-0.3 mm, foot pressure 0 and 0.3 MPa). The levels include every value
#: the text quotes (n = 300 r/min; f = 0.125, 0.15, 0.5 mm/r; ap = 0.05, 0.1 mm) and the
#: resonance speeds it mentions (400 and 1000 r/min). ``PAPER_BASE`` is the condition of the
#: paper's Fig. 7 (ap = 0.05 mm, f = 0.15 mm/r, n = 300 r/min), around which the
#: one-factor-at-a-time design varies one quantity at a time (Figs. 9 and 10).
PAPER_LEVELS: dict[str, tuple[float, ...]] = {
    "speed_rpm": (200.0, 300.0, 400.0, 500.0, 600.0, 800.0, 1000.0),
    "feed_mm_per_rev": (0.1, 0.125, 0.15, 0.2, 0.3, 0.4, 0.5),
    "depth_of_cut_mm": (0.05, 0.1, 0.15, 0.2, 0.25, 0.3),
    "pressure_MPa": (0.0, 0.3),
}
PAPER_BASE: dict[str, float] = {
    "speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
}


class Condition(BaseModel):
    """One cutting condition (human units, as in the paper and the measured CSV).

    ``speed_rpm`` spindle speed in r/min; ``feed_mm_per_rev`` feed per revolution in mm;
    ``depth_of_cut_mm`` radial depth of cut in mm; ``pressure_MPa`` pressure-foot pressure
    in MPa (0 = no foot); ``posture`` the name of a robot posture.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    # upper bounds: the one range of each quantity (robobore.io.ranges), checked below
    speed_rpm: float = Field(gt=0, description="spindle speed, r/min")
    feed_mm_per_rev: float = Field(gt=0, description="feed per revolution, mm")
    depth_of_cut_mm: float = Field(gt=0, description="radial depth of cut, mm")
    pressure_MPa: float = Field(default=0.0, ge=0, le=100, description="foot pressure, MPa")
    posture: str = Field(default=DEFAULT_POSTURE, min_length=1)

    @field_validator("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm")
    @classmethod
    def _plausible(cls, v: float, info: ValidationInfo) -> float:
        # a ConfigError is a ValueError: pydantic reports it with the field
        return check_positive(v, info.field_name, field=info.field_name)

    def to_dict(self) -> dict[str, Any]:
        return self.model_dump()

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Condition:
        return cls.model_validate(d)

    def to_si(self) -> dict[str, float]:
        """The same condition in SI: spindle speed in rad/s and r/s, feed and depth in m,
        pressure in Pa, revolution period in s."""
        return {
            "spindle_speed_rad_per_s": self.speed_rpm * 2.0 * 3.141592653589793 / 60.0,
            "spindle_speed_rev_per_s": self.speed_rpm / 60.0,
            "revolution_period_s": 60.0 / self.speed_rpm,
            "feed_m_per_rev": self.feed_mm_per_rev * 1e-3,
            "depth_of_cut_m": self.depth_of_cut_mm * 1e-3,
            "pressure_Pa": self.pressure_MPa * 1e6,
        }

    def ident(self) -> tuple[float, float, float, float, str]:
        """The values that identify the condition (for duplicate detection and matching)."""
        return (
            self.speed_rpm, self.feed_mm_per_rev, self.depth_of_cut_mm, self.pressure_MPa,
            self.posture,
        )

    def label(self) -> str:
        return (
            f"n={self.speed_rpm:g} r/min f={self.feed_mm_per_rev:g} mm/r "
            f"ap={self.depth_of_cut_mm:g} mm P={self.pressure_MPa:g} MPa [{self.posture}]"
        )


class RangeSpec(BaseModel):
    """Evenly spaced levels ``start .. stop`` (both included), ``num`` of them."""

    model_config = ConfigDict(extra="forbid")
    start: float
    stop: float
    num: int = Field(ge=1, le=10_000)

    def levels(self) -> list[float]:
        if self.num == 1:
            return [self.start]
        step = (self.stop - self.start) / (self.num - 1)
        # round to 12 significant digits so 0.1 + 2*0.1 style noise does not leak into keys
        return [float(f"{self.start + i * step:.12g}") for i in range(self.num)]


Levels = list[float] | RangeSpec


class GridSpec(BaseModel):
    """Full-factorial grid: every combination of the listed levels."""

    model_config = ConfigDict(extra="forbid")
    speed_rpm: Levels
    feed_mm_per_rev: Levels
    depth_of_cut_mm: Levels
    pressure_MPa: Levels = Field(default_factory=lambda: [0.0])
    posture: list[str] = Field(default_factory=lambda: [DEFAULT_POSTURE], min_length=1)

    def count(self) -> int:
        """Number of conditions of the grid, without expanding it."""
        n = len(self.posture)
        for name in CONDITION_FIELDS:
            v = getattr(self, name)
            n *= v.num if isinstance(v, RangeSpec) else len(v)
        return n

    def expand(self) -> list[dict[str, Any]]:
        lv = {}
        for name in CONDITION_FIELDS:
            v = getattr(self, name)
            lv[name] = v.levels() if isinstance(v, RangeSpec) else list(v)
            if not lv[name]:
                raise ConfigError("empty list of levels", field=f"grid.{name}",
                                  expected="at least one level")
        out = []
        for n, f, a, p, pos in itertools.product(
            lv["speed_rpm"], lv["feed_mm_per_rev"], lv["depth_of_cut_mm"], lv["pressure_MPa"],
            self.posture,
        ):
            out.append({"speed_rpm": n, "feed_mm_per_rev": f, "depth_of_cut_mm": a,
                        "pressure_MPa": p, "posture": pos})
        return out


class SweepSection(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: str = Field(default="sweep", min_length=1)
    runner: str = Field(default="demo", min_length=1)
    seed: int = Field(default=0, ge=0)
    levels: Literal["paper-ofat", "paper-grid"] | None = None


class SweepConfig(BaseModel):
    """The whole sweep config file (see module docstring)."""

    model_config = ConfigDict(extra="forbid")
    sweep: SweepSection = Field(default_factory=SweepSection)
    grid: GridSpec | None = None
    conditions: list[dict[str, Any]] = Field(default_factory=list)
    model: dict[str, Any] = Field(default_factory=dict)
    runner_options: dict[str, Any] = Field(default_factory=dict)
    postures: dict[str, dict[str, Any]] = Field(default_factory=dict)

    @model_validator(mode="after")
    def _has_conditions(self) -> SweepConfig:
        if self.grid is None and not self.conditions and self.sweep.levels is None:
            raise ValueError("no conditions: give a [grid], [[conditions]] or sweep.levels")
        return self


def paper_conditions(design: Literal["ofat", "grid"] = "ofat") -> list[dict[str, Any]]:
    """The paper's kind of conditions (:data:`PAPER_LEVELS`), for P = 0 and 0.3 MPa.

    ``"ofat"``: one factor at a time around :data:`PAPER_BASE` (speed, feed and depth of cut
    each varied over its levels with the other two at the base value), 18 conditions per
    pressure; ``"grid"``: the full factorial, 294 conditions per pressure.
    """
    out: list[dict[str, Any]] = []
    seen: set[tuple[float, ...]] = set()
    names = ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm")
    for p in PAPER_LEVELS["pressure_MPa"]:
        if design == "grid":
            combos = itertools.product(*(PAPER_LEVELS[n] for n in names))
        else:
            combos = []
            for vary in names:
                for v in PAPER_LEVELS[vary]:
                    c = dict(PAPER_BASE)
                    c[vary] = v
                    combos.append(tuple(c[n] for n in names))
        for combo in combos:
            t = (*combo, p)
            if t in seen:
                continue
            seen.add(t)
            out.append({**dict(zip(names, combo, strict=True)), "pressure_MPa": p,
                        "posture": DEFAULT_POSTURE})
    return out


#: The most conditions one sweep plans (each is planned, keyed and tracked in memory and in
#: ``index.json``; at about 0.1 s per condition the largest sweep is days of computing).
MAX_SWEEP_CONDITIONS = 100_000


def expand_conditions(cfg: SweepConfig, source: str | Path = "<config>") -> list[Condition]:
    """All conditions of a sweep config, validated, in a stable order; duplicates are errors.

    Order: built-in levels, then the grid, then the explicit list. A sweep of more than
    :data:`MAX_SWEEP_CONDITIONS` conditions is refused before anything is expanded.
    """
    try:
        n_grid = cfg.grid.count() if cfg.grid is not None else 0
        grid = cfg.grid.expand() if cfg.grid is not None and n_grid <= MAX_SWEEP_CONDITIONS \
            else []
    except ConfigError as exc:  # (the grid's own checks) name the config file
        if exc.file is not None:
            raise
        raise ConfigError(exc.message, file=str(source), field=exc.field, value=exc.value,
                          expected=exc.expected) from None
    if n_grid + len(cfg.conditions) > MAX_SWEEP_CONDITIONS:
        raise ConfigError(
            f"the sweep has {n_grid + len(cfg.conditions):.4g} conditions, more than the "
            f"{MAX_SWEEP_CONDITIONS} one sweep plans; reduce the levels of [grid] (or split "
            "the study into several sweeps sharing one store)", file=str(source),
            field="grid", value=n_grid + len(cfg.conditions),
            expected=f"at most {MAX_SWEEP_CONDITIONS} conditions")
    raw: list[tuple[str, dict[str, Any]]] = []
    if cfg.sweep.levels is not None:
        design = "ofat" if cfg.sweep.levels == "paper-ofat" else "grid"
        raw += [(f"sweep.levels[{i}]", d) for i, d in enumerate(paper_conditions(design))]
    if cfg.grid is not None:
        raw += [(f"grid[{i}]", d) for i, d in enumerate(grid)]
    raw += [(f"conditions.{i}", d) for i, d in enumerate(cfg.conditions)]

    out: list[Condition] = []
    where_of: dict[tuple[Any, ...], str] = {}
    for where, d in raw:
        try:
            c = Condition.model_validate(d)
        except Exception as exc:  # pydantic ValidationError -> ConfigError with the key
            errs = getattr(exc, "errors", lambda: [])()
            first = errs[0] if errs else {}
            key = ".".join(str(x) for x in first.get("loc", ()))
            raise ConfigError(
                f"bad condition: {first.get('msg', exc)}",
                file=str(source), field=f"{where}.{key}" if key else where,
                value=first.get("input") if not isinstance(first.get("input"), dict) else None,
                expected="speed_rpm > 0 in r/min, feed_mm_per_rev > 0 in mm, "
                "depth_of_cut_mm > 0 in mm, pressure_MPa >= 0 in MPa",
            ) from None
        if cfg.postures and c.posture not in cfg.postures:
            raise ConfigError(
                "unknown posture", file=str(source), field=f"{where}.posture", value=c.posture,
                expected=f"one of the [postures] tables: {sorted(cfg.postures)}",
            )
        ident = c.ident()
        if ident in where_of:
            raise ConfigError(
                f"condition listed twice (also at {where_of[ident]}): {c.label()}",
                file=str(source), field=where,
                expected="each condition once",
            )
        where_of[ident] = where
        out.append(c)
    return out


def load_sweep_config(path: str | Path) -> tuple[SweepConfig, list[Condition]]:
    """Read a sweep TOML file; returns the validated config and its conditions."""
    cfg = validate_model(SweepConfig, load_toml(path), source=path)
    coef = (cfg.model.get("dynamics") or {}).get("coefficients") if isinstance(
        cfg.model.get("dynamics"), dict) else None
    if isinstance(coef, dict) and isinstance(coef.get("file"), str):
        # the one rule (robobore.io.paths): relative to the sweep config's folder, not the
        # workers' current directory; the absolute path is part of the condition keys
        from robobore.io.paths import resolve_config_path

        coef["file"] = str(resolve_config_path(coef["file"], path,
                                               "model.dynamics.coefficients.file",
                                               what="coefficients file"))
    return cfg, expand_conditions(cfg, source=path)


def condition_key(condition: Condition, runner: str, model: dict[str, Any],
                  posture_def: dict[str, Any] | None = None) -> str:
    """Stable 20-hex-character key of a condition computed with a runner and model config.

    The key changes when anything that changes the result changes (condition, runner name,
    model config, posture definition) and nothing else (not dict order, not 1 vs 1.0).
    """
    return stable_hash(
        {"condition": condition.to_dict(), "runner": runner, "model": model,
         "posture": posture_def or {}},
        length=20,
    )


def condition_seed(base_seed: int, key: str) -> int:
    """A per-condition seed that depends only on the base seed and the condition key
    (so the result of a condition does not depend on the order conditions run in)."""
    return (int(key[:15], 16) ^ int(base_seed)) % (2**63)


__all__ = [
    "CONDITION_FIELDS",
    "MAX_SWEEP_CONDITIONS",
    "DEFAULT_POSTURE",
    "PAPER_LEVELS",
    "PAPER_BASE",
    "Condition",
    "GridSpec",
    "RangeSpec",
    "SweepConfig",
    "paper_conditions",
    "expand_conditions",
    "load_sweep_config",
    "condition_key",
    "condition_seed",
]
