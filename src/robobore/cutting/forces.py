"""Mechanistic edge-element force model for boring (Atabey, Lazoglu & Altintas 2003 type).

Per edge element (``robobore.cutting.geometry.EdgeElements``), with local uncut chip
thickness ``h``, chip width ``db`` and edge length ``dS``::

    dFt = Ktc h db + Kte dS      tangential (against the cutting velocity of the insert)
    dFf = Kfc h db + Kfe dS      thrust, normal to the local edge in the tool-profile plane
                                 (the orthogonal-cutting "feed/thrust" force; along the feed
                                 when the local approach angle is 90 deg)
    dFl = Krc h db + Kre dS      lateral, along the local edge towards its leading end
                                 (non-zero for inclined / oblique edges)

The thrust acts along the local chip-thickness direction ``(-sin k, -cos k)`` in (feed, radial)
coordinates, i.e. it is resolved by the local approach angle ``k`` into
``feed = -dFf sin k + dFl cos k`` and ``radial = -dFf cos k - dFl sin k`` (forces ON THE TOOL,
radial positive outwards). Every element is engaged edge and carries its edge forces
(``K*e dS``), including the rubbing-only elements on the trailing side of the nose
(``h = 0``, ``k < 0``; see :func:`robobore.cutting.geometry.edge_elements`): there the edge
normal leans the other way along the feed, so their thrust has a feed component of the
opposite sign (``-Kfe dS sin k > 0``) that partly cancels the leading side's.

The rotating-frame totals ``(F_tangential, F_radial, F_feed)`` go to the boring frame
(X horizontal, Y vertical, Z feed) with the bar's rotation angle ``theta`` (from X towards Y;
the insert moves along ``e_t = (-sin theta, cos theta, 0)``)::

    F = -Ft e_t(theta) + Fr e_r(theta) + Fz e_z

Coefficients (:class:`CuttingCoefficients`): shearing ``K*c`` in N/m^2, edge ``K*e`` in N/m.
The TC4 default is fitted by code from the bundled measured orthogonal data (see
``coefficients/README.md``); :func:`orthogonal_to_oblique` gives the classical
orthogonal-to-oblique transformation (Armarego; Budak, Altintas & Armarego 1996; Altintas'
textbook eq. 2.x) from shear stress, shear angle, friction angle, rake and inclination.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from robobore.cutting.geometry import BoringInsert, EdgeElements, edge_elements
from robobore.errors import ConfigError
from robobore.io.ranges import check_value

COEFF_DIR = Path(__file__).with_name("coefficients")
DUCOBU_FILE = COEFF_DIR / "ti64_orthogonal_cutting_forces.json"

_KEYS = {"Ktc": "Ktc_N_per_m2", "Krc": "Krc_N_per_m2", "Kfc": "Kfc_N_per_m2",
         "Kte": "Kte_N_per_m", "Kre": "Kre_N_per_m", "Kfe": "Kfe_N_per_m"}


@dataclass(frozen=True)
class CuttingCoefficients:
    """Linear edge-force model coefficients (shearing N/m^2, edge N/m) and their source."""

    Ktc: float
    Krc: float
    Kfc: float
    Kte: float = 0.0
    Kre: float = 0.0
    Kfe: float = 0.0
    provenance: str = "user"
    #: plain-language warnings on how the set was chosen (a cutting speed outside the
    #: calibrated speeds, a pooled set where per-speed fits exist); not part of the values
    warnings: tuple[str, ...] = field(default=(), compare=False)
    #: the cutting speed [m/min] a speed-dependent set was evaluated at (None: one set for
    #: every speed)
    speed_m_per_min: float | None = field(default=None, compare=False)
    #: the uncut chip thicknesses [m] the set was fitted over (None: not known)
    chip_thickness_range_m: tuple[float, float] | None = field(default=None, compare=False)

    def domain_warnings(self, chip_thickness_m: Any) -> list[str]:
        """The set's warnings plus one when the nominal chip thickness of a cut (the largest
        ``h0`` of its elements) exceeds the fitted range: the linear law extrapolated beyond
        its thickest test. Thinner chips are what the edge term of the law is for (towards
        the nose tip every boring chip thins to zero), so they are not flagged."""
        out = list(self.warnings)
        rng = self.chip_thickness_range_m
        h = np.asarray(chip_thickness_m, float)
        if rng is not None and h.size and float(h.max()) > rng[1] * (1 + 1e-9):
            out.append(f"cutting coefficients fitted over chip thicknesses "
                       f"{rng[0] * 1e6:g}-{rng[1] * 1e6:g} um, used up to "
                       f"{float(h.max()) * 1e6:.3g} um (the linear force law extrapolated)")
        return out

    def __post_init__(self) -> None:
        for name in _KEYS:
            v = getattr(self, name)
            if not isinstance(v, int | float) or not math.isfinite(v):
                raise ConfigError("not a finite number", field=_KEYS[name], value=v,
                                  expected="a number in " + ("N/m^2" if name[-1] == "c"
                                                             else "N/m"))
        if self.Ktc <= 0:
            raise ConfigError("tangential shearing coefficient must be positive",
                              field="Ktc_N_per_m2", value=self.Ktc, expected="> 0 N/m^2")

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {_KEYS[k]: float(getattr(self, k)) for k in _KEYS}
        d["provenance"] = self.provenance
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any], source: str | None = None) -> CuttingCoefficients:
        """From ``{"Ktc_N_per_m2": .., ..., "provenance": ..}`` (missing edge terms are 0)."""
        vals: dict[str, Any] = {}
        for short, key in _KEYS.items():
            if key not in d:
                if short in ("Ktc", "Kfc"):
                    raise ConfigError("missing key", file=source, field=key,
                                      expected="a number in N/m^2")
                continue
            # a number (never a boolean), finite, within the plausible range of its unit
            # (robobore.io.ranges: N/mm^2 for N/m^2 is refused with a hint)
            vals[short] = check_value(d[key], key, file=source, field=key, kind=ConfigError)
        vals.setdefault("Krc", 0.0)
        return cls(**vals, provenance=str(d.get("provenance", source or "user")))


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
    in ``warnings``). ``ln(vc)`` rather than ``vc`` (which :func:`ti64_coefficients` uses for
    the measured fits): the strain-rate term of the flow stress is logarithmic, and it
    predicts held-out FE points better (docs/process.md, "Speed-dependent coefficients").
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


# ---------------------------------------------------------------------------- fitting
def fit_linear_edge_model(h_m: np.ndarray, force_N_per_m: np.ndarray) -> tuple[float, float]:
    """Least-squares fit ``F = Ke + Kc h`` (per unit width); returns ``(Kc [N/m^2], Ke [N/m])``."""
    h = np.asarray(h_m, float)
    F = np.asarray(force_N_per_m, float)
    A = np.column_stack([h, np.ones_like(h)])
    (kc, ke), *_ = np.linalg.lstsq(A, F, rcond=None)
    return float(kc), float(ke)


@lru_cache(maxsize=1)
def _ducobu() -> dict[str, Any]:
    return json.loads(DUCOBU_FILE.read_text())


def ducobu_fits() -> dict[float, dict[str, float]]:
    """Per cutting speed [m/min]: fitted Ktc, Kte, Kfc, Kfe and chip ratio (bundled TC4 data)."""
    data = _ducobu()["measured"]
    hs = sorted(data["Fc"], key=float)
    speeds = sorted(data["Fc"][hs[0]], key=float)
    out = {}
    for v in speeds:
        h = np.array([float(x) * 1e-6 for x in hs])
        fc = np.array([data["Fc"][x][v] for x in hs]) * 1e3  # N/mm -> N/m
        ff = np.array([data["Ff"][x][v] for x in hs]) * 1e3
        ktc, kte = fit_linear_edge_model(h, fc)
        kfc, kfe = fit_linear_edge_model(h, ff)
        rc = float(np.mean([data["chip_ratio"][x][v] for x in hs]))
        out[float(v)] = {"Ktc": ktc, "Kte": kte, "Kfc": kfc, "Kfe": kfe, "chip_ratio": rc}
    return out


def ti64_coefficients(cutting_speed_m_per_min: float | None = 30.0) -> CuttingCoefficients:
    """TC4 (Ti-6Al-4V) default coefficients from the bundled measured orthogonal data.

    Linear interpolation of the per-speed fits in cutting speed; held constant outside the
    measured range 5-30 m/min (said in the provenance). Rake 15 deg, inclination 0, so the
    lateral coefficients are 0; use :func:`orthogonal_to_oblique` for an inclined insert.
    """
    fits = ducobu_fits()
    v = np.array(sorted(fits))
    vc = float(v[-1] if cutting_speed_m_per_min is None else cutting_speed_m_per_min)
    note = ""
    if vc < v[0] or vc > v[-1]:
        note = f"; vc = {vc:.3g} m/min outside the measured {v[0]:g}-{v[-1]:g} m/min: held at edge"
    vq = float(np.clip(vc, v[0], v[-1]))
    vals = {k: float(np.interp(vq, v, [fits[s][k] for s in v]))
            for k in ("Ktc", "Kte", "Kfc", "Kfe")}
    prov = ("TC4: least-squares fit Fc = Kte + Ktc h, Ff = Kfe + Kfc h of measured orthogonal "
            "forces (Ducobu et al., CIRP 2022; rake 15 deg, edge radius 20 um), "
            f"interpolated at vc = {vq:.3g} m/min" + note)
    warn = (f"cutting speed {vc:.3g} m/min outside the measured {v[0]:g}-{v[-1]:g} m/min of "
            f"the TC4 coefficients: held at the {vq:g} m/min fit",) if note else ()
    return CuttingCoefficients(Ktc=vals["Ktc"], Krc=0.0, Kfc=vals["Kfc"], Kte=vals["Kte"],
                               Kre=0.0, Kfe=vals["Kfe"], provenance=prov, speed_m_per_min=vq,
                               warnings=warn, chip_thickness_range_m=TI64_CHIP_THICKNESS_M)


#: Uncut chip thicknesses [m] of the measured TC4 data the default coefficients are fitted to.
TI64_CHIP_THICKNESS_M = (40e-6, 80e-6)

#: The FE-calibrated TC4 set of the paper example (rake 7 deg, edge radius 20 um, h 60-90 um,
#: 37.7 m/min): opt-in as ``material = "TC4-FE"``; the validated default is the measured set
#: (:func:`ti64_coefficients`; the evidence: docs/process.md, "The TC4 coefficient sets").
TC4_FE_FILE = Path(__file__).resolve().parents[1] / "data" / "paper_example" / \
    "tc4_fe_coefficients.json"
#: Names of the TC4 sets for ``[coefficients] material``: the measured default, the FE opt-in.
TC4_NAMES = ("TC4", "TI6AL4V", "TI-6AL-4V")
TC4_FE_NAMES = ("TC4-FE",)


def tc4_fe_coefficients(cutting_speed_m_per_min: float | None = None) -> CuttingCoefficients:
    """The paper example's FE-calibrated TC4 set (:data:`TC4_FE_FILE`), with the warning of a
    cutting speed outside its calibrated 37.7 m/min and its chip-thickness range 60-90 um
    (:meth:`CuttingCoefficients.domain_warnings`)."""
    return load_coefficients(TC4_FE_FILE, cutting_speed_m_per_min)


@dataclass(frozen=True)
class OrthogonalParameters:
    """Orthogonal cutting parameters: shear stress [Pa], shear angle, friction angle, rake [rad]."""

    shear_stress_Pa: float
    shear_angle_rad: float
    friction_angle_rad: float
    rake_rad: float


def orthogonal_parameters_from_data(Ktc: float, Kfc: float, chip_ratio: float,
                                    rake_rad: float) -> OrthogonalParameters:
    """Shear angle, friction angle and shear stress from orthogonal shearing coefficients.

    ``chip_ratio`` = chip thickness / uncut chip thickness (> 1). Merchant/Armarego relations:
    ``tan phi = r cos a / (1 - r sin a)`` with ``r = 1/chip_ratio``;
    ``beta = a + atan(Kfc/Ktc)``; ``tau_s = (Ktc cos phi - Kfc sin phi) sin phi``.
    """
    r = 1.0 / chip_ratio
    phi = math.atan2(r * math.cos(rake_rad), 1.0 - r * math.sin(rake_rad))
    beta = rake_rad + math.atan2(Kfc, Ktc)
    tau = (Ktc * math.cos(phi) - Kfc * math.sin(phi)) * math.sin(phi)
    return OrthogonalParameters(tau, phi, beta, rake_rad)


def orthogonal_to_oblique(shear_stress_Pa: float, shear_angle_rad: float,
                          friction_angle_rad: float, rake_rad: float,
                          inclination_rad: float = 0.0,
                          chip_flow_angle_rad: float | None = None) -> tuple[float, float, float]:
    """Orthogonal-to-oblique transformation: returns ``(Ktc, Kfc, Krc)`` in N/m^2.

    Assumptions (Armarego & Whitfield; Budak, Altintas & Armarego 1996): normal shear angle =
    orthogonal shear angle, normal rake = rake, chip flow angle = inclination (Stabler) unless
    given, normal friction angle from ``tan beta_n = tan beta_a cos eta``::

        Ktc = tau/sin(phi_n) (cos(bn-an) + tan i tan eta sin bn) / W
        Kfc = tau/(sin(phi_n) cos i) sin(bn-an) / W
        Krc = tau/sin(phi_n) (cos(bn-an) tan i - tan eta sin bn) / W
        W = sqrt(cos^2(phi_n + bn - an) + tan^2 eta sin^2 bn)

    Here Kfc is the thrust (normal to the edge) and Krc the lateral (along the edge) coefficient.
    """
    i = inclination_rad
    eta = i if chip_flow_angle_rad is None else chip_flow_angle_rad
    an = rake_rad
    bn = math.atan(math.tan(friction_angle_rad) * math.cos(eta))
    pn = shear_angle_rad
    W = math.sqrt(math.cos(pn + bn - an) ** 2 + math.tan(eta) ** 2 * math.sin(bn) ** 2)
    t = shear_stress_Pa / math.sin(pn)
    ktc = t * (math.cos(bn - an) + math.tan(i) * math.tan(eta) * math.sin(bn)) / W
    kfc = t / math.cos(i) * math.sin(bn - an) / W
    krc = t * (math.cos(bn - an) * math.tan(i) - math.tan(eta) * math.sin(bn)) / W
    return ktc, kfc, krc


def ti64_oblique_coefficients(insert: BoringInsert,
                              cutting_speed_m_per_min: float = 30.0) -> CuttingCoefficients:
    """TC4 coefficients for an inclined insert via the orthogonal-to-oblique route.

    Shear stress, shear angle and friction angle come from the bundled measured data
    (:func:`orthogonal_parameters_from_data`, measured rake 15 deg); the friction angle is
    shifted with the rake (beta - alpha kept, Merchant) to the insert's rake. Edge
    coefficients are kept from the linear fit.
    """
    base = ti64_coefficients(cutting_speed_m_per_min)
    fits = ducobu_fits()
    v = np.array(sorted(fits))
    vq = float(np.clip(cutting_speed_m_per_min, v[0], v[-1]))
    rc = float(np.interp(vq, v, [fits[s]["chip_ratio"] for s in v]))
    p = orthogonal_parameters_from_data(base.Ktc, base.Kfc, rc, math.radians(15.0))
    a = math.radians(insert.rake_deg)
    phi = p.shear_angle_rad + 0.5 * (a - p.rake_rad)
    ktc, kfc, krc = orthogonal_to_oblique(p.shear_stress_Pa, phi, p.friction_angle_rad, a,
                                          math.radians(insert.inclination_deg))
    return CuttingCoefficients(ktc, krc, kfc, base.Kte, 0.0, base.Kfe,
                               provenance=base.provenance + "; orthogonal-to-oblique with "
                               f"tau_s = {p.shear_stress_Pa / 1e6:.0f} MPa, "
                               f"beta = {math.degrees(p.friction_angle_rad):.1f} deg, "
                               f"phi = {math.degrees(phi):.1f} deg",
                               speed_m_per_min=base.speed_m_per_min)


# ---------------------------------------------------------------------------- forces
@dataclass(frozen=True)
class ElementForces:
    """Per-element local forces [N] (arrays of shape (n,)) and rotating-frame totals [N].

    ``tangential``/``radial``/``feed`` totals are the force ON THE TOOL along
    ``-e_t`` (i.e. opposite to the insert velocity, given as a positive magnitude), ``e_r``
    (positive outwards) and ``e_z`` (positive along the feed).
    """

    dFt: np.ndarray
    dFf: np.ndarray
    dFl: np.ndarray
    tangential: float
    radial: float
    feed: float


def element_forces(el: EdgeElements, c: CuttingCoefficients) -> ElementForces:
    """Edge-element forces and their rotating-frame sums (see module docstring).

    Shearing terms on the chip ``h db`` of each element, edge terms on its length ``dS``:
    every element of ``el`` is engaged edge, those with ``h = 0`` (trailing side of the nose)
    carry the edge forces only."""
    dA = el.h * el.db
    dS = el.dS
    dFt = c.Ktc * dA + c.Kte * dS
    dFf = c.Kfc * dA + c.Kfe * dS
    dFl = c.Krc * dA + c.Kre * dS
    sk, ck = np.sin(el.kappa), np.cos(el.kappa)
    feed = float(np.sum(-dFf * sk + dFl * ck))
    radial = float(np.sum(-dFf * ck - dFl * sk))
    return ElementForces(dFt, dFf, dFl, float(dFt.sum()), radial, feed)


def rotating_to_boring(tangential: float, radial: float, feed: float,
                       theta: np.ndarray) -> np.ndarray:
    """Boring-frame force on the tool, shape (3, n_theta) [N], for bar angles ``theta`` [rad]."""
    th = np.asarray(theta, float)
    et = np.stack([-np.sin(th), np.cos(th), np.zeros_like(th)])
    er = np.stack([np.cos(th), np.sin(th), np.zeros_like(th)])
    ez = np.stack([np.zeros_like(th), np.zeros_like(th), np.ones_like(th)])
    return -tangential * et + radial * er + feed * ez


def boring_forces(insert: BoringInsert, depth_m: float, feed_per_rev_m: float,
                  coefficients: CuttingCoefficients, n_theta: int = 360,
                  n_elements: int = 40, trailing_edge: bool = True) -> dict[str, Any]:
    """Static (rigid-tool) boring forces over one revolution.

    Returns a dict with ``theta_rad`` (n,), ``force_N`` (3, n) in the boring frame (sum over
    the inserts, equally spaced), rotating-frame totals per insert, chip area, and per-axis
    mean and amplitude (half peak-to-peak). ``trailing_edge`` (default True): edge forces
    also on the engaged trailing side of the nose
    (:func:`robobore.cutting.geometry.edge_elements`); False gives the
    leading edge only.
    """
    fz = feed_per_rev_m / insert.n_inserts
    el = edge_elements(insert, depth_m, fz, n_elements, trailing_edge=trailing_edge)
    ef = element_forces(el, coefficients)
    th = np.linspace(0.0, 2 * np.pi, n_theta, endpoint=False)
    F = np.zeros((3, n_theta))
    for p in range(insert.n_inserts):
        F += rotating_to_boring(ef.tangential, ef.radial, ef.feed,
                                th + 2 * np.pi * p / insert.n_inserts)
    return {"theta_rad": th, "force_N": F, "tangential_N": ef.tangential,
            "radial_N": ef.radial, "feed_N": ef.feed, "chip_area_m2": el.area,
            "mean_N": F.mean(axis=1), "amplitude_N": 0.5 * (F.max(axis=1) - F.min(axis=1)),
            "elements": el, "element_forces": ef}


__all__ = ["CuttingCoefficients", "load_coefficients", "check_coefficients_identity", "coefficients_at_speed",
           "read_per_speed_fits", "inline_coefficients", "PER_SPEED_KEYS",
           "fit_linear_edge_model", "ducobu_fits",
           "ti64_coefficients", "orthogonal_parameters_from_data", "orthogonal_to_oblique",
           "tc4_fe_coefficients", "calibrated_domain", "TC4_FE_FILE", "TC4_NAMES",
           "TC4_FE_NAMES", "SPEED_TOLERANCE",
           "ti64_oblique_coefficients", "ElementForces", "element_forces",
           "rotating_to_boring", "boring_forces", "OrthogonalParameters"]
