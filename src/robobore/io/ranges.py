"""Plausibility ranges of the physical quantities robobore reads from files and options.

Every number read at the package's edges (config TOML, material and robot TOML, campaign and
measured CSV, coefficient / modes / stiffness JSON, UFF and NPZ frequency data) is checked
against the range of its quantity. The quantity is found from the key or column name: the
unit is in the name (``stiffness_N_per_m``, ``x_m``, ``E_GPa``), a few constants are named by
their section (``johnson_cook.n``, ``damage.D1``). The ranges are chosen so that real robots,
machine tools, tools and materials pass and a unit slip by 1e3 or 1e2 (mm in a ``*_m``
column, N/um where N/m is expected, a damping ratio in percent, MPa where GPa is expected)
fails. The table is documented in ``docs/inputs.md``; :func:`range_table` prints it.

A value outside its range is a :class:`~robobore.errors.InputError` (a ``ConfigError`` for
config files, a ``DataError`` for data files) naming the file, the row or dotted key, the
value, the range with its unit and, when dividing or multiplying by 1e3 / 1e6 / 100 would
bring the value into range, the likely slip ("looks like mm; expected m"). NaN and infinity
are refused everywhere; a boolean is never taken as a number.

Escapes, for the rare legitimate outlier:

* ``robobore --no-range-check <command> ...`` (or the environment variable
  ``ROBOBORE_NO_RANGE_CHECK=1``, which worker processes inherit) turns the range checks off;
  an out-of-range value is then accepted with a warning, and config files read while it is
  off carry ``range_check = {disabled = "--no-range-check"}`` in their provenance.
* In a config file, a top-level table ``[range_check]`` with ``allow = ["dotted.key", ...]``
  accepts out-of-range values under those keys (a key prefix covers its sub-keys); the table
  stays in the config recorded in the results. NaN, infinity and booleans are refused anyway.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from robobore.errors import ConfigError, DataError, InputError

ENV_VAR = "ROBOBORE_NO_RANGE_CHECK"
#: top-level config table of per-key overrides (``allow = [...]``); never part of a model
OVERRIDE_KEY = "range_check"


class RangeCheckWarning(UserWarning):
    """An out-of-range value accepted because the range check is off for it."""


@dataclass(frozen=True)
class Range:
    """The plausible range of one quantity.

    ``lo``..``hi`` bound the value (or its magnitude when ``signed``); ``zero_ok`` also lets
    an exact 0 pass when ``lo`` > 0 (coefficients that a model may set to 0). ``slips`` are
    ``(factor, words)``: when ``value / factor`` is in range the error says the value looks
    like it was given in the unit ``words`` names.
    """

    quantity: str
    unit: str
    lo: float
    hi: float
    signed: bool = False
    zero_ok: bool = False
    slips: tuple[tuple[float, str], ...] = ()
    examples: str = ""

    def contains(self, v: float) -> bool:
        x = abs(v) if self.signed else v
        if self.zero_ok and v == 0.0:
            return True
        return self.lo <= x <= self.hi

    def bounds(self) -> str:
        """The range in words with its unit (``"magnitude 0 .. 50 m"``)."""
        unit = "" if self.unit == "-" else f" {self.unit}"
        text = f"{self.lo:g} .. {self.hi:g}{unit}"
        if self.signed:
            text = "magnitude " + text
        if self.zero_ok and self.lo > 0:
            text += ", or 0"
        return text

    def describe(self) -> str:
        """The range and the quantity, as error messages give it."""
        return f"{self.bounds()} ({self.quantity})"

    def slip_hint(self, v: float) -> str | None:
        for factor, words in self.slips:
            if v != 0.0 and self.contains(v / factor):
                return words
        return None


_MM = ((1e3, "looks like mm; expected m"),)
_PCT = ((100.0, "looks like percent; expected a ratio 0..1"),)

#: Ranges by quantity. Keys are the names used in :data:`BY_NAME` and :data:`BY_SUFFIX`.
RANGES: dict[str, Range] = {
    "position_m": Range(
        "position (laser tracker, load point)", "m", 0.0, 50.0, signed=True, slips=_MM,
        examples="robot cells are a few m across; trackers measure to about 40 m"),
    "length_m": Range(
        "robot length (D-H a/d, tool point)", "m", 0.0, 10.0, signed=True, slips=_MM,
        examples="largest industrial robots: links up to about 3 m"),
    "length_mm": Range("length", "mm", 0.0, 1e4, signed=True,
                       slips=((1e3, "looks like um; expected mm"),),
                       examples="bores, pistons, tools: 0.1 .. 2000 mm"),
    "length_um": Range("small length", "um", 0.0, 1e5, signed=True,
                       slips=((1e3, "looks like nm; expected um"),),
                       examples="edge radii, element sizes, amplitudes: 0.1 .. 1000 um"),
    "depth_mm": Range("depth of cut", "mm", 1e-3, 20.0, zero_ok=True,
                      slips=((1e3, "looks like um; expected mm"),
                             (1e-3, "looks like m; expected mm")),
                      examples="boring: 0.01 .. 5 mm"),
    "feed_mm_per_rev": Range("feed per revolution", "mm/r", 1e-3, 5.0, zero_ok=True,
                             slips=((1e3, "looks like um/r; expected mm/r"),
                                    (1e-3, "looks like m/r; expected mm/r")),
                             examples="boring: 0.02 .. 0.6 mm/r"),
    "speed_rpm": Range("spindle speed", "r/min", 0.0, 1e5,
                       examples="robotic boring 100 .. 3000 r/min; HSM up to 60000"),
    "speed_m_per_min": Range("cutting speed", "m/min", 1.0, 2000.0, zero_ok=True,
                             slips=((1 / 60, "looks like m/s; expected m/min"),),
                             examples="titanium 20 .. 120 m/min; aluminium up to 2000"),
    "angle_deg": Range("angle", "deg", 0.0, 1000.0, signed=True,
                       examples="joint angles within their limits (+-300 deg at most)"),
    "force_N": Range("force", "N", 0.0, 1e5, signed=True,
                     examples="test loads and cutting forces: 1 .. 10000 N"),
    "stiffness_N_per_m": Range(
        "stiffness", "N/m", 1e4, 1e11,
        slips=((1e-6, "looks like N/um; expected N/m (x 1e6)"),
               (1e-3, "looks like N/mm; expected N/m (x 1e3)")),
        examples="robot tool point 1e5 .. 1e8, machine-tool spindles 1e7 .. 1e9 N/m"),
    "joint_stiffness_Nm_per_rad": Range(
        "joint stiffness", "N m/rad", 1e2, 1e10,
        slips=((1e-3, "looks like N m/mrad or kN m/rad; expected N m/rad (x 1e3)"),),
        examples="industrial robot joints 1e5 .. 1e8 N m/rad"),
    "damping_N_s_per_m": Range("viscous damping", "N s/m", 0.0, 1e8,
                               examples="tool-point damping 10 .. 1e5 N s/m"),
    "damping_ratio": Range("damping ratio", "-", 0.0, 0.999, slips=_PCT,
                           examples="structures 0.001 .. 0.3"),
    "ratio": Range("ratio / fraction", "-", 0.0, 1.0, slips=_PCT),
    "coherence": Range("coherence", "-", 0.0, 1.0 + 1e-9,
                       examples="ordinary coherence is 0 .. 1 by definition"),
    "frequency_Hz": Range("frequency", "Hz", 0.0, 1e5,
                          slips=((1e3, "looks like mHz; expected Hz"),
                                 (1e6, "looks like uHz; expected Hz")),
                          examples="structural modes 1 .. 5000 Hz; hammer-test bands "
                          "up to 20 kHz"),
    "coefficient_N_per_m2": Range(
        "cutting (shearing) coefficient", "N/m^2", 1e6, 1e11, signed=True, zero_ok=True,
        slips=((1e-6, "looks like N/mm^2 (MPa); expected N/m^2 (x 1e6)"),),
        examples="titanium Ktc about 1.5e9, aluminium about 7e8 N/m^2"),
    "edge_coefficient_N_per_m": Range(
        "cutting edge coefficient", "N/m", 1e2, 1e6, signed=True, zero_ok=True,
        slips=((1e-3, "looks like N/mm; expected N/m (x 1e3)"),),
        examples="Kte/Kfe 1e3 .. 1e5 N/m"),
    "pressure_MPa": Range("pressure", "MPa", 0.0, 50.0,
                          slips=((1e6, "looks like Pa; expected MPa"),
                                 (1e3, "looks like kPa; expected MPa")),
                          examples="pressure foot 0 .. 1 MPa"),
    "stress_MPa": Range("stress / strength", "MPa", 0.0, 1e4, signed=True,
                        slips=((1e6, "looks like Pa; expected MPa"),),
                        examples="Johnson-Cook A, B 100 .. 3000 MPa"),
    "modulus_GPa": Range("elastic modulus", "GPa", 1.0, 1500.0,
                         slips=((1e3, "looks like MPa; expected GPa"),
                                (1e9, "looks like Pa; expected GPa")),
                         examples="metals 40 .. 450 GPa, carbide 600 GPa"),
    "modulus_Pa": Range("elastic modulus", "Pa", 1e9, 1.5e12,
                        slips=((1e-6, "looks like MPa; expected Pa"),
                               (1e-9, "looks like GPa; expected Pa")),
                        examples="metals 4e10 .. 4.5e11 Pa"),
    "temperature_K": Range("temperature", "K", 1.0, 5000.0,
                           examples="room 293 K; titanium melts at 1873 K"),
    "density_kg_m3": Range("density", "kg/m^3", 100.0, 3e4,
                           slips=((1e-3, "looks like g/cm^3; expected kg/m^3"),),
                           examples="metals 1700 .. 20000 kg/m^3"),
    "heat_capacity_J_kgK": Range("specific heat", "J/(kg K)", 10.0, 1e4,
                                 slips=((1e-3, "looks like kJ/(kg K); expected J/(kg K)"),)),
    "conductivity_W_mK": Range("thermal conductivity", "W/(m K)", 0.01, 2000.0),
    "mass_kg": Range("mass", "kg", 0.0, 1e5, examples="tools, bars, robots"),
    "jc_stress_MPa": Range("Johnson-Cook yield / hardening stress A, B", "MPa", 10.0, 1e4,
                           slips=((1e6, "looks like Pa; expected MPa"),
                                  (1e-3, "looks like GPa; expected MPa")),
                           examples="Ti-6Al-4V A 998, B 653 MPa; steels A 200 .. 1500 MPa"),
    "jc_n": Range("Johnson-Cook hardening exponent n", "-", 0.0, 2.0),
    "jc_C": Range("Johnson-Cook strain-rate constant C", "-", 0.0, 1.0),
    "jc_m": Range("Johnson-Cook thermal exponent m", "-", 0.0, 5.0),
    "jc_eps0": Range("Johnson-Cook reference strain rate", "1/s", 1e-6, 1e6),
    "damage_D1": Range("Johnson-Cook damage constant D1", "-", 0.0, 5.0, signed=True,
                       examples="Ti-6Al-4V -0.09; "
                       "4340 steel 0.05, Armco iron -2.20, OFHC copper 0.54 (Johnson & Cook 1985)"),
    "damage_D2": Range("Johnson-Cook damage constant D2", "-", 0.0, 20.0, signed=True,
                       examples="Ti-6Al-4V 0.25; "
                       "4340 steel 3.44, Armco iron 5.43, OFHC copper 4.89"),
    "damage_D3": Range("Johnson-Cook damage constant D3", "-", 0.0, 20.0, signed=True,
                       examples="Ti-6Al-4V -0.5; "
                       "4340 steel -2.12, Armco iron -0.47, OFHC copper -3.03"),
    "damage_D4": Range("Johnson-Cook damage constant D4", "-", 0.0, 1.0, signed=True,
                       examples="Ti-6Al-4V 0.014; "
                       "4340 steel 0.002, Armco iron 0.016, OFHC copper 0.014"),
    "damage_D5": Range("Johnson-Cook damage constant D5", "-", 0.0, 50.0, signed=True,
                       examples="Ti-6Al-4V 3.87; "
                       "4340 steel 0.61, Armco iron 0.63, OFHC copper 1.12"),
    "poisson": Range("Poisson's ratio", "-", 0.0, 0.5),
    "edge_radius_um": Range("cutting-edge radius", "um", 0.5, 500.0, zero_ok=True,
                            slips=((1e-3, "looks like mm; expected um"),),
                            examples="ground or honed edges 2 .. 100 um; 0 = sharp"),
    "inertia_kg_m2": Range("moment / product of inertia", "kg m^2", 0.0, 1e5, signed=True,
                           slips=((1e6, "looks like kg mm^2; expected kg m^2"),),
                           examples="robot links 0.01 .. 100 kg m^2, tools 1e-4 .. 1"),
    "area_m2": Range("area", "m^2", 0.0, 100.0,
                     slips=((1e6, "looks like mm^2; expected m^2"),
                            (1e4, "looks like cm^2; expected m^2")),
                     examples="pressure-foot pistons 1e-4 .. 1e-2 m^2"),
    "time_s": Range("time", "s", 0.0, 1e5,
                    slips=((1e3, "looks like ms; expected s"),),
                    examples="hammer-test records 1 .. 60 s, windows 0.01 .. 10 s"),
    "noise_um": Range("measurement noise (1-sigma)", "um", 0.0, 1e4,
                      examples="laser trackers 5 .. 50 um per coordinate"),
    "record_s": Range("record length", "s", 1e-3, 600.0,
                      slips=((1e3, "looks like ms; expected s"),),
                      examples="impact-hammer records 1 .. 60 s"),
    "sample_rate_Hz": Range("sampling rate", "Hz", 1.0, 1e6,
                            examples="hammer tests 256 Hz .. 102.4 kHz"),
    "condition_limit": Range("condition-number limit", "-", 1.0, 1e16,
                             examples="1e3 .. 1e12"),
    "modal_mass_kg": Range("modal mass", "kg", 0.0, 1e6),
    "plastic_strain": Range("plastic strain", "-", 0.0, 50.0,
                            examples="hardening hold of the bundled TC4 0.6; strains in a "
                            "secondary shear zone reach 5-10"),
}

#: Exact names (last key component, or ``section.name``) and their quantity.
BY_NAME: dict[str, str] = {
    "johnson_cook.A_MPa": "jc_stress_MPa", "johnson_cook.B_MPa": "jc_stress_MPa",
    "johnson_cook.n": "jc_n", "johnson_cook.C": "jc_C", "johnson_cook.m": "jc_m",
    "johnson_cook.eps_dot0_per_s": "jc_eps0",
    "hardening_strain_limit": "plastic_strain",
    **{f"damage.D{i}": f"damage_D{i}" for i in range(1, 6)},
    "elastic.nu": "poisson", "thermal.taylor_quinney": "ratio",
    "d_m": "length_m", "a_m": "length_m", "tcp_m": "length_m", "com_m": "length_m",
    "duration_s": "time_s", "exp_window_tau_s": "time_s", "noise": "ratio",
    "cond_limit": "condition_limit", "edge_radius_um": "edge_radius_um",
    "sample_rate_Hz": "sample_rate_Hz",
    "record_duration_s": "record_s", "sigma_um": "noise_um",
    "depth_mm": "depth_mm", "depth_of_cut_mm": "depth_mm", "max_depth_mm": "depth_mm",
    "feed_mm_per_rev": "feed_mm_per_rev", "speed_rpm": "speed_rpm",
    "coherence": "coherence", "mpc": "ratio",
    "damping_ratio": "damping_ratio", "contact_damping_ratio": "damping_ratio",
    "damping_ratios": "damping_ratio",
    "pressure_MPa": "pressure_MPa", "modal_mass_kg": "modal_mass_kg",
    "E": "modulus_Pa", "Kte_N_per_m": "edge_coefficient_N_per_m",
    "Kre_N_per_m": "edge_coefficient_N_per_m", "Kfe_N_per_m": "edge_coefficient_N_per_m",
}

#: Name endings (units) and their quantity; the longest matching ending wins.
BY_SUFFIX: dict[str, str] = {
    "_m": "position_m", "_mm": "length_mm", "_um": "length_um", "_deg": "angle_deg",
    "_N": "force_N", "_N_per_m": "stiffness_N_per_m", "_N_per_m2": "coefficient_N_per_m2",
    "_Nm_per_rad": "joint_stiffness_Nm_per_rad", "_N_s_per_m": "damping_N_s_per_m",
    "_Hz": "frequency_Hz", "_rpm": "speed_rpm", "_m_per_min": "speed_m_per_min",
    "_MPa": "stress_MPa", "_GPa": "modulus_GPa", "_K": "temperature_K",
    "_kg_m3": "density_kg_m3", "_J_kgK": "heat_capacity_J_kgK", "_W_mK": "conductivity_W_mK",
    "_kg": "mass_kg", "_damping_ratio": "damping_ratio", "_fraction": "ratio",
    "_kg_m2": "inertia_kg_m2", "_m2": "area_m2",
}

#: Key components that name a part of a quantity, not the quantity (``stiffness.x``).
_PART = {"x", "y", "z", "min", "max", "start", "stop", "value", "values"}


def enabled() -> bool:
    """Whether range checks are on (off with ``--no-range-check`` / the environment var)."""
    return os.environ.get(ENV_VAR, "").strip().lower() in ("", "0", "false", "no")


def set_enabled(on: bool) -> None:
    """Turn the range checks on or off for this process and the processes it starts."""
    if on:
        os.environ.pop(ENV_VAR, None)
    else:
        os.environ[ENV_VAR] = "1"


def quantity_of(path: str | Iterable[Any]) -> Range | None:
    """The :class:`Range` of a dotted key or column name, or None when no rule applies."""
    parts = path.split(".") if isinstance(path, str) else [str(p) for p in path]
    parts = [p for p in parts if not p.isdigit()]
    name_i = len(parts) - 1
    while name_i > 0 and parts[name_i] in _PART:
        name_i -= 1
    if name_i < 0:
        return None
    name = parts[name_i]
    section = parts[name_i - 1] if name_i > 0 else ""
    q = BY_NAME.get(f"{section}.{name}") or BY_NAME.get(name)
    if q is None:
        best = ""
        for suf in BY_SUFFIX:
            if name.endswith(suf) and len(suf) > len(best) and len(name) > len(suf):
                best = suf
        if not best:
            return None
        q = BY_SUFFIX[best]
    return RANGES[q]


def option_name(option: str) -> str:
    """The key name of a command-line option, with its unit suffix spelt as in
    :data:`BY_SUFFIX` (``--sample-rate-hz`` -> ``sample_rate_Hz``,
    ``--foot-pressure-MPa`` -> ``foot_pressure_MPa``), so that it picks its range."""
    name = option.lstrip("-").replace("-", "_")
    if quantity_of(name) is not None:
        return name
    low = name.lower()
    for suf in sorted(BY_SUFFIX, key=len, reverse=True):
        if low.endswith(suf.lower()) and len(name) > len(suf):
            return name[: -len(suf)] + suf
    return name


def _error(kind: type[InputError], message: str, **kw: Any) -> InputError:
    return kind(message, **kw)


def check_value(value: Any, name: str, *, file: str | None = None, row: int | None = None,
                field: str | None = None, allowed: bool = False,
                kind: type[InputError] = DataError) -> float:
    """Check one number against the range of the quantity ``name`` names.

    ``name`` is a column name or dotted key (it picks the range); ``field`` is what the
    error names (default ``name``). Returns the value as float. Booleans, non-numbers and
    non-finite values are refused always; an out-of-range value unless ``allowed`` or the
    checks are off (then a :class:`RangeCheckWarning`).
    """
    where = dict(file=file, row=row, field=field or name)
    rng = quantity_of(name)
    unit = f" in {rng.unit}" if rng is not None and rng.unit != "-" else ""
    if isinstance(value, bool):
        raise _error(kind, "a boolean where a number is expected", value=value,
                     expected=f"a number{unit}", **where)
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise _error(kind, "not a number", value=value, expected=f"a number{unit}",
                     **where) from None
    if not math.isfinite(v):
        raise _error(kind, "not a finite number", value=value,
                     expected=f"a finite number{unit}", **where)
    if rng is None or rng.contains(v):
        return v
    hint = rng.slip_hint(v)
    if v < 0 and not rng.signed:
        msg = "a negative value where a positive quantity is expected"
    else:
        msg = "value out of the plausible range" + (f" ({hint})" if hint else "")
    if allowed or not enabled():
        why = "allowed by [range_check]" if allowed else "range check off"
        loc = ", ".join(str(x) for x in (file, None if row is None else f"row {row}",
                                          field or name) if x is not None)
        warnings.warn(f"{loc}: {msg} (got {v!r}; expected {rng.describe()}); accepted: "
                      f"{why}", RangeCheckWarning, stacklevel=2)
        return v
    raise _error(kind, msg, value=v, expected=rng.describe(), **where)


def check_positive(value: Any, name: str, *, file: str | None = None,
                   field: str | None = None, kind: type[InputError] = ConfigError) -> float:
    """:func:`check_value` for a quantity that must be above 0 (a cut's depth, feed and
    speed): 0 or less is refused whether or not the range check is on, then the value is
    checked against the range of ``name``. The command-line options, the config sections and
    :mod:`robobore.api` call this (or :func:`check_tree`, which gives the same message for
    an out-of-range value), so that each quantity has one range."""
    v = check_value(value, name, file=file, field=field, kind=kind) if not (
        isinstance(value, int | float) and not isinstance(value, bool) and value <= 0) \
        else float(value)
    if v <= 0.0:
        rng = quantity_of(name)
        raise kind("a cut needs a positive value", file=file, field=field or name, value=v,
                   expected=f"> 0 ({rng.describe()})" if rng is not None else "> 0")
    return v


def check_array(values: Any, name: str, *, file: str | None = None, field: str | None = None,
                kind: type[InputError] = DataError) -> None:
    """Check every element of a numeric array (a frequency axis, a coherence) against the
    range of ``name``; the error names the first offending element's index."""
    import numpy as np

    a = np.asarray(values)
    if a.dtype == bool:
        raise kind("booleans where numbers are expected", file=file, field=field or name,
                   expected="a numeric array")
    if not np.issubdtype(a.dtype, np.number):
        raise kind("not a numeric array", file=file, field=field or name,
                   value=str(a.dtype), expected="numbers")
    a = np.real(a).astype(float).ravel()
    rng = quantity_of(name)
    bad = ~np.isfinite(a)
    if rng is not None and enabled():
        x = np.abs(a) if rng.signed else a
        out = (x < rng.lo) | (x > rng.hi)
        if rng.zero_ok:
            out &= a != 0.0
        bad |= out
    if bad.any():
        i = int(np.argmax(bad))
        v = float(a[i])
        where = f"{field or name}[{i}]"
        if rng is None or not math.isfinite(v):
            check_value(v, name, file=file, field=where, kind=kind)  # raises: not finite
            return
        if v < 0 and not rng.signed:
            msg = "a negative value where a positive quantity is expected"
        else:  # a unit slip is named only when it explains the whole array
            hint = next((words for factor, words in rng.slips
                         if all(rng.contains(x) for x in (a.min() / factor, a.max() / factor))),
                        None)
            msg = "value out of the plausible range" + (f" ({hint})" if hint else "")
        raise kind(msg, file=file, field=where, value=v, expected=rng.describe())


def _allow_list(data: Mapping[str, Any], file: str | None) -> tuple[str, ...]:
    rc = data.get(OVERRIDE_KEY)
    if rc is None:
        return ()
    allow = rc.get("allow", []) if isinstance(rc, Mapping) else None
    if not isinstance(allow, list) or not all(isinstance(a, str) for a in allow):
        raise ConfigError("bad range-check override", file=file, field=f"{OVERRIDE_KEY}.allow",
                          value=allow, expected='a list of dotted keys, e.g. allow = '
                          '["equivalent.stiffness_N_per_m"]')
    return tuple(allow)


def check_tree(data: Any, file: str | None = None, *, prefix: str = "",
               kind: type[InputError] = ConfigError,
               allow: tuple[str, ...] | None = None) -> None:
    """Check every number in a nested config mapping (TOML / JSON) against its range.

    The dotted key of each number picks its range (:func:`quantity_of`); numbers under a
    key without a rule are only checked for being finite. A top-level ``[range_check]``
    ``allow`` list names keys (or key prefixes) whose out-of-range values are accepted.
    """
    if allow is None:
        allow = _allow_list(data, file) if isinstance(data, Mapping) else ()
    _walk(data, prefix, file, kind, allow)


def _walk(node: Any, path: str, file: str | None, kind: type[InputError],
          allow: tuple[str, ...]) -> None:
    if isinstance(node, Mapping):
        for k, v in node.items():
            if not path and k == OVERRIDE_KEY:
                continue
            _walk(v, f"{path}.{k}" if path else str(k), file, kind, allow)
        return
    if isinstance(node, list | tuple):
        for i, v in enumerate(node):
            _walk(v, f"{path}.{i}", file, kind, allow)
        return
    if isinstance(node, bool) or not isinstance(node, int | float):
        return
    ok = any(path == a or path.startswith(a + ".") for a in allow)
    if quantity_of(path) is None:
        if not math.isfinite(float(node)):
            raise kind("not a finite number", file=file, field=path, value=node,
                       expected="a finite number")
        return
    check_value(node, path, file=file, field=path, allowed=ok, kind=kind)


def radians_hint(joints_deg: Any, where: str) -> str | None:
    """A warning when joint angles given in deg look like radians: every value within
    +-pi and at least two of them non-zero (a real posture in deg almost always has a joint
    beyond 3.2 deg); None when they look like degrees."""
    import math

    try:
        q = [float(v) for v in joints_deg]
    except (TypeError, ValueError):
        return None
    nonzero = [v for v in q if abs(v) > 1e-9]
    if len(nonzero) >= 2 and all(abs(v) <= math.pi + 1e-9 for v in q):
        return (f"{where}: every joint angle is within +-pi "
                f"({', '.join(f'{v:g}' for v in q)}): radians? The values are read as deg "
                f"(in deg: {', '.join(f'{math.degrees(v):.4g}' for v in q)})")
    return None


def provenance() -> dict[str, Any] | None:
    """What to record in a config's provenance when the checks are off (else None)."""
    return None if enabled() else {"disabled": "--no-range-check"}


def range_table() -> list[dict[str, str]]:
    """The documented ranges as rows (quantity, unit, range, slips caught, examples)."""
    rows = []
    for key, r in RANGES.items():
        rows.append({"key": key, "quantity": r.quantity, "unit": r.unit,
                     "range": r.bounds(),
                     "slips": "; ".join(w for _, w in r.slips), "examples": r.examples})
    return rows


__all__ = ["radians_hint", "Range", "RANGES", "BY_NAME", "BY_SUFFIX", "RangeCheckWarning",
           "check_value",
           "check_positive", "check_array",
           "check_tree", "quantity_of", "option_name", "enabled", "set_enabled", "provenance",
           "range_table",
           "ENV_VAR", "OVERRIDE_KEY"]
