"""Validation of an FE orthogonal-cutting config against measured forces
(``robobore fe validate CONFIG --measured FILE``).

The config is run at every condition of a measured-forces file (or the ``--points`` given):
its uncut chip thickness and cutting speed are replaced per point, everything else is the
config's (with the default ``solver.mass_scaling``, 100 (30 / vc)^2, the inertia ratio follows
the speed). Simulated cutting force, feed force and chip ratio are compared with the
measurement: relative error = simulated / measured - 1 (signed; None where the file has no
measurement), and the mean and max absolute error per quantity over the points that have one.

Measured-forces file (JSON; the format of ../shared/data/ti64_orthogonal_cutting_forces.json,
docs/fe.md "robobore fe validate")::

    {"units": {"Fc": "N per mm of width", "Ff": "N per mm of width",
               "chip_ratio": "chip thickness / uncut chip thickness"},     (optional)
     "measured": {"Fc": {"<h um>": {"<vc m/min>": value, ...}, ...},
                  "Ff": {...}, "chip_ratio": {...}}}

``Fc`` and ``Ff`` are forces per mm of width [N/mm]; every quantity is optional, a point is a
(h, vc) pair found under any of them; a file that gives both forces gives them at the same
points (a speed one of them lacks is an error). Everything is checked on read
(:func:`read_measured`): errors name the file, the key path, the value and what is expected.

Each point's result is written atomically to ``OUT/h<h>_vc<vc>.json`` with the full point
config it ran; a rerun with the same ``OUT`` reuses a point whose stored config is the same
(an interrupted validation resumes) and reruns it otherwise.
"""

from __future__ import annotations

import copy
import json
import math
import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from robobore.cutting.fe.models.results import (
    MeasuredValues,
    PerQuantity,
    ValidationPoint,
    ValidationResult,
    ValidationSummary,
)
from robobore.errors import ConfigError, DataError
from robobore.io.readers import load_json

#: the measured quantities: file key -> (result key, relative-error key, unit)
QUANTITIES = {
    "Fc": ("cutting_force_N_per_mm", "cutting_force", "N/mm"),
    "Ff": ("feed_force_N_per_mm", "feed_force", "N/mm"),
    "chip_ratio": ("chip_ratio", "chip_ratio", "-"),
}
#: plausible ranges of the measured values (per mm of width; a chip thicker than 10 h or
#: forces of 1e5 N/mm are unit slips)
#: (a continuous chip is thicker than the uncut chip: a ratio below 1 is the inverse,
#: uncut / chip thickness)
_RANGES = {"Fc": (0.0, 1e5), "Ff": (-1e5, 1e5), "chip_ratio": (1.0, 10.0)}
#: the force unit the file may state: N per mm of width, spelt "N/mm", "N per mm", with or
#: without "of width" (case and spaces free); anything else (kN/mm, N/m, lbf/in) is refused
_FORCE_UNIT = re.compile(r"^n\s*(/|per)\s*mm(\s*(of\s*)?width)?$")
#: plausible chip thickness [um] and cutting speed [m/min] of a measured point
_H_RANGE, _VC_RANGE = (0.1, 2000.0), (0.01, 2000.0)


@dataclass(frozen=True)
class MeasuredPoint:
    """One measured condition; a quantity the file does not give is None."""

    h_um: float
    vc_m_per_min: float
    Fc: float | None = None
    Ff: float | None = None
    chip_ratio: float | None = None


def _num(s: str, file: str, field: str, what: str, lo: float, hi: float) -> float:
    try:
        v = float(s)
    except (TypeError, ValueError):
        raise DataError(f"a {what} key must be a number", file=file, field=field, value=s,
                        expected=f"a {what} within {lo:g}..{hi:g}") from None
    if not (math.isfinite(v) and lo <= v <= hi):
        raise DataError(f"{what} out of range", file=file, field=field, value=s,
                        expected=f"a {what} within {lo:g}..{hi:g}")
    return v


def read_measured(path: str | Path) -> list[MeasuredPoint]:
    """Read and check a measured-forces file; the points in (h, vc) order."""
    p = Path(path)
    f = str(p)
    if not p.is_file():
        raise DataError("measured-forces file not found", file=f,
                        expected="an existing JSON file (docs/fe.md, robobore fe validate)")
    data = load_json(p, "measured-forces file", "a JSON file (docs/fe.md, robobore fe "
                     "validate)", kind=None, error=DataError)
    if not isinstance(data, dict) or not isinstance(data.get("measured"), dict):
        raise DataError("no 'measured' table", file=f, field="measured",
                        expected='{"measured": {"Fc": {h_um: {vc_m_per_min: value}}, ...}}')
    units = data.get("units", {})
    if not isinstance(units, dict):
        raise DataError("'units' must be a table", file=f, field="units", value=units,
                        expected='{"Fc": "N per mm of width", ...}')
    for q in ("Fc", "Ff"):
        u = units.get(q)
        if u is not None and not (isinstance(u, str) and
                                  _FORCE_UNIT.match(" ".join(u.lower().split()))):
            hint = (" (kN: multiply the values by 1000)" if isinstance(u, str)
                    and u.strip().lower().startswith("kn") else "")
            raise DataError("force unit not supported" + hint, file=f, field=f"units.{q}",
                            value=u, expected="N per mm of width (N/mm)")
    meas = data["measured"]
    unknown = sorted(set(meas) - set(QUANTITIES))
    if unknown:
        raise DataError("unknown measured quantity", file=f, field=f"measured.{unknown[0]}",
                        value=unknown[0], expected=f"one of {list(QUANTITIES)}")
    values: dict[tuple[float, float], dict[str, float]] = {}
    keys: dict[str, dict[float, str]] = {}  # quantity -> h -> the file's h key
    for q, by_h in meas.items():
        if not isinstance(by_h, dict):
            raise DataError("expected a table of uncut chip thicknesses", file=f,
                            field=f"measured.{q}", value=by_h,
                            expected='{"<h um>": {"<vc m/min>": value}}')
        for hk, by_vc in by_h.items():
            field = f"measured.{q}.{hk}"
            h = _num(hk, f, field, "uncut chip thickness in um", *_H_RANGE)
            keys.setdefault(q, {})[h] = hk
            if not isinstance(by_vc, dict) or not by_vc:
                raise DataError("missing cutting speed: expected a table of cutting speeds",
                                file=f, field=field, value=by_vc,
                                expected='{"<vc m/min>": value, ...} (at least one speed)')
            for vk, val in by_vc.items():
                fv = f"{field}.{vk}"
                vc = _num(vk, f, fv, "cutting speed in m/min", *_VC_RANGE)
                lo, hi = _RANGES[q]
                unit = QUANTITIES[q][2]
                if q == "chip_ratio" and isinstance(val, int | float) and 0 < val < lo:
                    raise DataError("chip ratio below 1: the chip is thicker than the uncut "
                                    "chip, so this looks like the inverse (uncut / chip "
                                    "thickness)", file=f, field=fv, value=val,
                                    expected=f"chip thickness / uncut chip thickness, "
                                    f"{lo:g}..{hi:g} (Ti-6Al-4V: 1.1 .. 3)")
                if isinstance(val, bool) or not isinstance(val, int | float) or \
                        not math.isfinite(val) or not lo <= val <= hi:
                    raise DataError(f"{q} must be a finite number", file=f, field=fv,
                                    value=val, expected=f"a number within {lo:g}..{hi:g} "
                                    f"{unit}")
                key = (h, vc)
                if q in values.get(key, {}):
                    raise DataError("the same point twice", file=f, field=fv, value=val,
                                    expected="one value per (h, vc)")
                values.setdefault(key, {})[q] = float(val)
    if not values:
        raise DataError("no measured point", file=f, field="measured",
                        expected="at least one (h, vc) value")
    _check_force_points(values, keys, f)
    return [MeasuredPoint(h, vc, **values[(h, vc)]) for h, vc in sorted(values)]


def _check_force_points(values: dict[tuple[float, float], dict[str, float]],
                        keys: dict[str, dict[float, str]], f: str) -> None:
    """Fc and Ff, when the file gives both, are given at the same points (one dynamometer
    measures both): a speed one of them lacks is a missing entry, not a partial point."""
    if not {"Fc", "Ff"} <= set(keys):
        return
    at = {q: {hv for hv, d in values.items() if q in d} for q in ("Fc", "Ff")}
    for q, other in (("Fc", "Ff"), ("Ff", "Fc")):
        miss = sorted(at[other] - at[q])
        if miss:
            h, vc = miss[0]
            hk = keys[q].get(h, keys[other][h])
            have = sorted(v for hh, v in at[q] if hh == h)
            raise DataError(f"missing cutting speed: {q} has no value at h {h:g} um, "
                            f"vc {vc:g} m/min, where {other} has one", file=f,
                            field=f"measured.{q}.{hk}",
                            value=f"speeds {', '.join(f'{v:g}' for v in have) or 'none'}",
                            expected=f"a {q} value at vc {vc:g} m/min (Fc and Ff at the same "
                            "(h, vc) points; only chip_ratio may be partial)")


def parse_points(text: str) -> list[tuple[float, float]]:
    """``--points`` "h:vc,h:vc" (um, m/min) as (h, vc) pairs."""
    out = []
    for item in (s.strip() for s in text.split(",")):
        parts = item.split(":")
        try:
            if len(parts) != 2:
                raise ValueError
            h, vc = float(parts[0]), float(parts[1])
            if not (math.isfinite(h) and math.isfinite(vc) and h > 0 and vc > 0):
                raise ValueError
        except ValueError:
            raise ConfigError("bad point", field="--points", value=item,
                              expected="h_um:vc_m_per_min pairs of positive numbers, "
                              "comma-separated, e.g. 60:30,40:5") from None
        out.append((h, vc))
    if len(set(out)) != len(out):
        raise ConfigError("a point is given twice", field="--points", value=text,
                          expected="distinct h_um:vc_m_per_min pairs")
    return out


def point_config(base: dict[str, Any], h_um: float, vc_m_per_min: float) -> dict[str, Any]:
    """The base config dict with only the uncut chip thickness and cutting speed replaced.

    A dict, not a typed result: it is the config as the TOML file gives it (the sections of
    ``robobore fe orthogonal``'s contract), the input of
    :func:`robobore.cutting.fe.config.orthogonal.parse_config` here and, through
    :func:`robobore.cutting.calibration_config.fe_config_dict`, the FE config of a calibration
    grid point, whose mapping is the key of the cached FE results
    (:func:`robobore.cutting.calibration_runs.fe_cache_inputs`)."""
    d = copy.deepcopy(base)
    cut = d.get("cut")
    if not isinstance(cut, dict):
        cut = {}
    d["cut"] = {**cut, "uncut_chip_thickness_um": float(h_um),
                "cutting_speed_m_per_min": float(vc_m_per_min)}
    return d


def _key(h: float, vc: float) -> str:
    return f"h{h:g}_vc{vc:g}"


def _rel(sim: float | None, meas: float | None) -> float | None:
    if sim is None or meas is None or meas == 0.0:
        return None
    return sim / meas - 1.0


def _finite(v: Any) -> float | None:
    return float(v) if isinstance(v, int | float) and math.isfinite(v) else None


@dataclass
class _Planned:
    point: MeasuredPoint
    cfg: Any  # FEConfig
    inputs: dict[str, Any]
    path: Path | None


def run_validation(base: dict[str, Any], measured: list[MeasuredPoint], *,
                   source: str = "<config>", points: list[tuple[float, float]] | None = None,
                   out_dir: str | Path | None = None, device: str = "cpu",
                   progress: Callable[[float], None] | None = None,
                   simulate: Callable[..., Any] | None = None) -> ValidationResult:
    """Run ``base`` at every measured point (or at ``points``, measured or not) and compare.

    Every point's config is built and checked before the first run. With ``out_dir``, each
    point's result is written there atomically and reused on a rerun with the same point
    config. ``progress(fraction of all points done)``. Returns a
    :class:`~robobore.cutting.fe.models.results.ValidationResult`: the points and their
    summary (``to_dict()``: the ``--json`` contract, docs/fe.md) plus the config's name, the
    device and the results folder.
    """
    from robobore import __version__
    from robobore.cutting.fe import FE_ENGINE_REVISION
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.models.orthogonal import (
        check_device,
        setup_orthogonal,
        simulate_orthogonal,
    )

    simulate = simulate or simulate_orthogonal
    by_hv = {(m.h_um, m.vc_m_per_min): m for m in measured}
    if points is None:
        todo = list(measured)
    else:
        todo = [by_hv.get((h, vc), MeasuredPoint(h, vc)) for h, vc in points]
    out = None if out_dir is None else Path(out_dir)
    if out is not None and out.exists() and not out.is_dir():
        raise ConfigError("results folder is a file", field="--out", value=str(out),
                          expected="a folder (created if missing)")
    plan: list[_Planned] = []
    for m in todo:  # every config checked before any run
        try:
            cfg = parse_config(point_config(base, m.h_um, m.vc_m_per_min), source)
            check_device(device, cfg, source)
            # the mesh and state are built too (cheap): errors found there come before any run
            setup_orthogonal(cfg, source)
        except ConfigError as exc:
            raise ConfigError(f"at the point h {m.h_um:g} um, vc {m.vc_m_per_min:g} m/min: "
                              f"{exc.message}", file=exc.file, row=exc.row, field=exc.field,
                              value=exc.value, expected=exc.expected) from None
        inputs = {"fe_config": cfg.model_dump(mode="json"), "device": device,
                  "engine_revision": FE_ENGINE_REVISION, "robobore_version": __version__}
        plan.append(_Planned(m, cfg, inputs,
                             None if out is None else out / f"{_key(m.h_um, m.vc_m_per_min)}.json"))
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    rows = []
    n = max(len(plan), 1)
    for i, pl in enumerate(plan):
        stored = _load_stored(pl.path, pl.inputs)
        if stored is None:
            t0 = time.perf_counter()

            def prog(frac: float, i: int = i) -> None:
                if progress:
                    progress((i + min(max(frac, 0.0), 1.0)) / n)

            res = simulate(pl.cfg, source=source, progress=prog, device=device)
            s = res.summary
            stored = {"inputs": pl.inputs,
                      "result": {"cutting_force_N_per_mm": _finite(s.cutting_force_N_per_mm),
                                 "feed_force_N_per_mm": _finite(s.feed_force_N_per_mm),
                                 "chip_ratio": _finite(s.chip_ratio),
                                 "energy_error": _finite(s.energy_error),
                                 "steps": s.steps, "n_elements": s.n_elements,
                                 "element_updates_per_s": _finite(s.element_updates_per_s),
                                 "friction_law": s.friction_law,
                                 "wall_time_s": time.perf_counter() - t0}}
            if pl.path is not None:
                from robobore.io.results import write_json

                write_json(pl.path, stored)
            cached = False
        else:
            cached = True
        if progress:
            progress((i + 1) / n)
        rows.append(_row(pl.point, stored["result"], cached,
                         None if pl.path is None else str(pl.path)))
    return ValidationResult(points=tuple(rows), summary=_summarize(rows), config=source,
                            device=device, out_dir=None if out is None else str(out))


def _load_stored(path: Path | None, inputs: dict[str, Any]) -> dict[str, Any] | None:
    """A stored point result for the same inputs, else None (missing, empty, corrupt or
    another config: the point is run again)."""
    if path is None or not path.is_file():
        return None
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    if not isinstance(d, dict) or d.get("inputs") != json.loads(json.dumps(inputs)) or \
            not isinstance(d.get("result"), dict):
        return None
    return d


def _row(m: MeasuredPoint, r: dict[str, Any], cached: bool, file: str | None
         ) -> ValidationPoint:
    sim = {q: r.get(QUANTITIES[q][0]) for q in QUANTITIES}
    meas = {q: getattr(m, q) for q in QUANTITIES}
    return ValidationPoint(
        uncut_chip_thickness_um=m.h_um,
        cutting_speed_m_per_min=m.vc_m_per_min,
        cutting_force_N_per_mm=sim["Fc"],
        feed_force_N_per_mm=sim["Ff"],
        chip_ratio=sim["chip_ratio"],
        relative_error=PerQuantity(**{QUANTITIES[q][1]: _rel(sim[q], meas[q])
                                      for q in QUANTITIES}),
        measured=MeasuredValues(**{QUANTITIES[q][0]: meas[q] for q in QUANTITIES}),
        energy_error=r.get("energy_error"),
        wall_time_s=r.get("wall_time_s"),
        element_updates_per_s=r.get("element_updates_per_s"),
        reused=cached,
        file=file,
    )


def _summarize(rows: list[ValidationPoint]) -> ValidationSummary:
    """Max and mean absolute relative error per quantity (None where no point has one)."""
    out: dict[str, dict[str, Any]] = {"max_abs_error": {}, "mean_abs_error": {},
                                      "n_measured": {}}
    for _, key, _ in QUANTITIES.values():
        errs = [abs(getattr(r.relative_error, key)) for r in rows
                if getattr(r.relative_error, key) is not None]
        out["max_abs_error"][key] = max(errs) if errs else None
        out["mean_abs_error"][key] = sum(errs) / len(errs) if errs else None
        out["n_measured"][key] = len(errs)
    return ValidationSummary(**{k: PerQuantity(**v) for k, v in out.items()})


__all__ = ["MeasuredPoint", "read_measured", "parse_points", "point_config", "run_validation",
           "QUANTITIES"]
