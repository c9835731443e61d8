"""Cutting-coefficient files (TOML or JSON, as ``robobore calibrate forces`` writes them):
reading and checking them (:func:`read_coefficients_file`, :func:`load_coefficients`), their
per-speed fits evaluated at a cutting speed (:func:`coefficients_at_speed`), the domain they
were calibrated over (:func:`calibrated_domain`), the inline ``[coefficients]`` table of a
dynamics config (:func:`inline_coefficients`) and the check that a file was made for the
material and insert of a config (:func:`check_coefficients_identity`). The values are a
:class:`robobore.cutting.forces.CuttingCoefficients`.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from robobore.cutting.forces import CuttingCoefficients
from robobore.errors import ConfigError
from robobore.io.ranges import check_value

__all__ = ["read_coefficients_file", "PER_SPEED_KEYS", "read_per_speed_fits",
           "coefficients_at_speed", "SPEED_TOLERANCE", "calibrated_domain",
           "inline_coefficients", "load_coefficients", "check_coefficients_identity"]


def read_coefficients_file(path: str | Path) -> dict[str, Any]:
    """The content of a coefficient file (TOML or JSON) as a dict, its coefficients checked
    (:meth:`CuttingCoefficients.from_dict`); unreadable, non-UTF-8 or unparsable files and a
    top level that is not a table are a ConfigError naming the file."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError("coefficient file not found", file=str(p),
                          expected="a TOML or JSON file")
    if p.suffix.lower() == ".json":
        from robobore.io.readers import load_json

        data = load_json(p, "coefficient file", "a JSON object of cutting coefficients")
    else:
        from robobore.io.config import load_toml

        data = load_toml(p)
    if not isinstance(data, dict):
        raise ConfigError("not a table of coefficients", file=str(p), value=type(data).__name__,
                          expected='an object {"coefficients": {"Ktc_N_per_m2": ..., ...}}')
    inner = data.get("coefficients", data)
    if not isinstance(inner, dict):
        raise ConfigError("not a table of coefficients", file=str(p), field="coefficients",
                          value=type(inner).__name__, expected='{"Ktc_N_per_m2": ..., ...}')
    CuttingCoefficients.from_dict(inner, source=str(p))
    read_per_speed_fits(data, str(p))
    return data


#: the orthogonal coefficients of one per-speed fit (``per_speed_fits`` of a calibration file)
PER_SPEED_KEYS = ("Ktc_N_per_m2", "Kte_N_per_m", "Kfc_N_per_m2", "Kfe_N_per_m")


def read_per_speed_fits(data: dict[str, Any], source: str | None = None
                        ) -> dict[float, dict[str, float]]:
    """The ``per_speed_fits`` block of a coefficients file, checked: cutting speed [m/min] ->
    ``{Ktc_N_per_m2, Kte_N_per_m, Kfc_N_per_m2, Kfe_N_per_m}``, sorted by speed ({} when the
    file has none). Speeds are the block's keys (``"10"`` = 10 m/min): finite, positive,
    distinct; the coefficients are numbers within their plausible ranges
    (:mod:`robobore.io.ranges`) with ``Ktc > 0``. A malformed block is a ConfigError naming the
    file, the key, the value and what is expected."""
    block = data.get("per_speed_fits")
    if block is None:
        return {}
    expected_block = ('a table {"<cutting speed in m/min>": {"Ktc_N_per_m2": .., '
                      '"Kte_N_per_m": .., "Kfc_N_per_m2": .., "Kfe_N_per_m": ..}}')
    if not isinstance(block, dict):
        raise ConfigError("per-speed fits are not a table", file=source,
                          field="per_speed_fits", value=type(block).__name__,
                          expected=expected_block)
    out: dict[float, dict[str, float]] = {}
    for key, vals in block.items():
        where = f"per_speed_fits.{key}"
        try:
            vc = float(key)
        except (TypeError, ValueError):
            raise ConfigError("per-speed fit key is not a cutting speed", file=source,
                              field=where, value=key,
                              expected="a cutting speed in m/min, e.g. \"10\"") from None
        if not (math.isfinite(vc) and vc > 0):
            raise ConfigError("per-speed fit at a non-positive or non-finite cutting speed",
                              file=source, field=where, value=key,
                              expected="a cutting speed > 0 m/min")
        check_value(vc, "cutting_speed_m_per_min", file=source, field=where, kind=ConfigError)
        if vc in out:
            raise ConfigError("cutting speed listed twice in the per-speed fits", file=source,
                              field=where, value=key, expected="distinct cutting speeds")
        if not isinstance(vals, dict):
            raise ConfigError("per-speed fit is not a table", file=source, field=where,
                              value=type(vals).__name__, expected=expected_block)
        fit: dict[str, float] = {}
        for k in PER_SPEED_KEYS:
            if k not in vals:
                raise ConfigError("missing key in a per-speed fit", file=source,
                                  field=f"{where}.{k}",
                                  expected="a number in " + ("N/m^2" if k.endswith("m2")
                                                             else "N/m"))
            fit[k] = check_value(vals[k], k, file=source, field=f"{where}.{k}",
                                 kind=ConfigError)
        if fit["Ktc_N_per_m2"] <= 0:
            raise ConfigError("tangential shearing coefficient must be positive", file=source,
                              field=f"{where}.Ktc_N_per_m2", value=fit["Ktc_N_per_m2"],
                              expected="> 0 N/m^2")
        out[vc] = fit
    return dict(sorted(out.items()))


def _inclined(data: dict[str, Any], base: CuttingCoefficients) -> bool:
    ins = data.get("insert")
    incl = ins.get("inclination_deg", 0.0) if isinstance(ins, dict) else 0.0
    return bool(base.Krc != 0.0 or base.Kre != 0.0
                or (isinstance(incl, int | float) and incl != 0.0))


def coefficients_at_speed(data: dict[str, Any], cutting_speed_m_per_min: float | None,
                          *, speed_dependent: bool = True,
                          source: str | None = None) -> CuttingCoefficients:
    """The coefficients of a coefficients-file content at a cutting speed [m/min].

    With per-speed fits at two or more speeds (``per_speed_fits``, written by ``robobore
    calibrate forces`` over a grid of several speeds) and ``speed_dependent`` (the default):
    each of Ktc, Kte, Kfc, Kfe interpolated linearly in ``ln(vc)`` between the calibrated
    speeds, held at the end values outside the calibrated range (said in the provenance and
    in ``warnings``). ``ln(vc)`` rather than ``vc`` (which
    :func:`~robobore.cutting.coefficient_sets.ti64_coefficients` uses for the measured fits):
    the strain-rate term of the flow stress is logarithmic, and it predicts held-out FE points
    better (docs/process.md, "Speed-dependent coefficients").
    Otherwise -- one calibrated speed, ``speed_dependent = False``, an unknown cutting speed,
    or an inclined insert (the per-speed fits are orthogonal; the file's set went through
    the orthogonal-to-oblique transformation) -- the file's pooled ``coefficients`` set.
    """
    inner = data.get("coefficients", data)
    base = CuttingCoefficients.from_dict(inner, source=source)
    h_rng, v_rng = calibrated_domain(data)
    base = replace(base, chip_thickness_range_m=h_rng)
    fits = read_per_speed_fits(data, source)
    if len(fits) < 2:
        if v_rng is None or cutting_speed_m_per_min is None:
            return base
        vc = float(cutting_speed_m_per_min)
        lo, hi = v_rng
        if lo * (1 - SPEED_TOLERANCE) <= vc <= hi * (1 + SPEED_TOLERANCE):
            return base
        at = f"{lo:g} m/min" if hi == lo else f"{lo:g}-{hi:g} m/min"
        w = (f"cutting speed {vc:.4g} m/min outside the calibrated speed{'' if hi == lo else 's'}"
             f" {at} of the cutting coefficients: the set is used as calibrated there "
             "(no speed dependence)")
        return replace(base, provenance=base.provenance + "; " + w, warnings=(w,),
                       speed_m_per_min=vc)
    speeds = np.array(list(fits))
    rng = f"{speeds[0]:g}-{speeds[-1]:g} m/min"
    why = None
    if not speed_dependent:
        why = "speed_dependent = false"
    elif cutting_speed_m_per_min is None:
        why = "cutting speed not known"
    elif _inclined(data, base):
        why = ("inclined insert: the per-speed fits are orthogonal, the set is the "
               "orthogonal-to-oblique transform of the pooled fit")
    if why is not None:
        note = (f"pooled set over the calibrated speeds {rng} ({why}); the per-speed fits "
                "are not used")
        return CuttingCoefficients(base.Ktc, base.Krc, base.Kfc, base.Kte, base.Kre, base.Kfe,
                                   provenance=base.provenance + "; " + note,
                                   warnings=(note,) if speed_dependent else (),
                                   chip_thickness_range_m=h_rng)
    vc = float(cutting_speed_m_per_min)
    if not (math.isfinite(vc) and vc > 0):
        raise ConfigError("cutting speed must be positive and finite", file=source,
                          field="cutting_speed_m_per_min", value=vc, expected="> 0 m/min")
    vq = float(np.clip(vc, speeds[0], speeds[-1]))
    # linear in ln(vc): the strain-rate term of the flow stress is logarithmic in the rate
    # (Johnson-Cook), and on the validated FE model's 5/10/30 m/min fits the 10 m/min points
    # predicted from the 5 and 30 m/min fits miss their FE Fc by at most 1.6 % in ln(vc),
    # 5.2 % linear in vc (benchmarks/mechanistic_from_validation.py, docs/process.md)
    vals = {k: float(np.interp(math.log(vq), np.log(speeds), [fits[s][k] for s in fits]))
            for k in PER_SPEED_KEYS}
    at = ", ".join(f"{s:g}" for s in fits)
    prov = (base.provenance + f"; speed-dependent: per-speed fits at {at} m/min "
            f"interpolated linearly in ln(vc) at {vq:.4g} m/min")
    warnings: tuple[str, ...] = ()
    if vq != vc:
        w = (f"cutting speed {vc:.4g} m/min outside the calibrated speeds {rng}: coefficients "
             f"held at the {vq:g} m/min fit")
        prov += "; " + w
        warnings = (w,)
    return CuttingCoefficients(Ktc=vals["Ktc_N_per_m2"], Krc=0.0, Kfc=vals["Kfc_N_per_m2"],
                               Kte=vals["Kte_N_per_m"], Kre=0.0, Kfe=vals["Kfe_N_per_m"],
                               provenance=prov, warnings=warnings, speed_m_per_min=vq,
                               chip_thickness_range_m=h_rng)


#: A cutting speed within this relative distance of a calibrated speed range counts as inside
#: it (a 40 mm bore at 300 r/min cuts at 37.699 m/min; the paper's FE set is at 37.7).
SPEED_TOLERANCE = 0.01


def calibrated_domain(data: dict[str, Any]
                      ) -> tuple[tuple[float, float] | None, tuple[float, float] | None]:
    """``(chip thickness range [m], cutting speed range [m/min])`` a coefficients-file
    content was calibrated over, from its ``grid`` (``uncut_chip_thickness_um``,
    ``cutting_speed_m_per_min``, as ``robobore calibrate forces`` writes it); None where the
    file does not say."""
    g = data.get("grid") if isinstance(data, dict) else None
    out: list[tuple[float, float] | None] = []
    for key, scale in (("uncut_chip_thickness_um", 1e-6), ("cutting_speed_m_per_min", 1.0)):
        v = g.get(key) if isinstance(g, dict) else None
        try:
            a = np.asarray(v, float).ravel() if v is not None else np.empty(0)
        except (TypeError, ValueError):
            a = np.empty(0)
        a = a[np.isfinite(a) & (a > 0)]
        out.append((float(a.min()) * scale, float(a.max()) * scale) if a.size else None)
    return out[0], out[1]


def inline_coefficients(data: dict[str, Any], speed_dependent: bool = True) -> dict[str, Any]:
    """A coefficients-file content as the inline ``[coefficients]`` table of a dynamics
    config: the pooled values and provenance, plus ``per_speed_fits`` when the file has fits
    at two or more speeds (then the boring model evaluates them at each condition's speed;
    with ``speed_dependent`` False the table says ``speed_dependent = false``)."""
    inner = data.get("coefficients", data)
    out = {k: v for k, v in inner.items() if k.startswith("K") or k == "provenance"}
    g = data.get("grid")
    if isinstance(g, dict):
        out["grid"] = {k: [float(x) for x in g[k]] for k in
                       ("uncut_chip_thickness_um", "cutting_speed_m_per_min")
                       if isinstance(g.get(k), list)}
    fits = read_per_speed_fits(data)
    if len(fits) >= 2:
        base = CuttingCoefficients.from_dict(inner)
        if _inclined(data, base):
            out["provenance"] = str(out.get("provenance", "")) + (
                "; pooled set over the calibrated speeds (inclined insert: the per-speed fits "
                "are orthogonal)")
        else:
            out["per_speed_fits"] = {f"{v:g}": dict(f) for v, f in fits.items()}
            if not speed_dependent:
                out["speed_dependent"] = False
    return out


def load_coefficients(path: str | Path, cutting_speed_m_per_min: float | None = None, *,
                      speed_dependent: bool = True) -> CuttingCoefficients:
    """Load a coefficient file (TOML or JSON, keys as :meth:`CuttingCoefficients.to_dict`),
    at a cutting speed [m/min] when the file has per-speed fits at several speeds
    (:func:`coefficients_at_speed`)."""
    data = read_coefficients_file(path)
    return coefficients_at_speed(data, cutting_speed_m_per_min,
                                 speed_dependent=speed_dependent, source=str(path))


def check_coefficients_identity(coef: CuttingCoefficients, path: str | Path, *,
                                material: str | None, insert: Any, material_by: str,
                                insert_by: str) -> CuttingCoefficients:
    """``coef`` (read from ``path``) if the file was made for ``material`` (None: not
    checked) and the edge of ``insert`` (rake, edge radius, inclination;
    :func:`robobore.io.identity.check_insert`), else a ConfigError naming the file, the
    config and both values. A file that records neither is accepted, with a note in the
    provenance."""
    import dataclasses

    from robobore.io.identity import check_cut_file

    note = check_cut_file(path, material=material, insert=insert, material_by=material_by,
                          insert_by=insert_by)
    if note is None:
        return coef
    return dataclasses.replace(coef, provenance=f"{coef.provenance}; {note}")
