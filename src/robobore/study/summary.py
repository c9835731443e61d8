"""The summary contract: the few numbers per condition that are compared with measurements.

A runner returns an ``xarray.Dataset`` for each condition. Its summary is read from these
names, either as 0-d (scalar) data variables or as global attributes (a data variable wins
when both exist):

=====================  ======  ==================================================================
name                   unit    meaning
=====================  ======  ==================================================================
force_amplitude_x_N    N       average cutting-force amplitude, horizontal X (boring frame)
force_amplitude_y_N    N       average cutting-force amplitude, vertical Y
force_amplitude_z_N    N       average cutting-force amplitude, feed Z
feed_amplitude_um      um      average vibration amplitude of the tool in the feed direction Z
stable                 --      the paper's criterion: true = stable, false = vibratory (Ra above
                               the tolerance, or the run diverged; a roughness criterion)
=====================  ======  ==================================================================

Verdicts by cause (optional, from the time-domain runner; :mod:`robobore.dynamics.chatter`):

=====================  ======  ==================================================================
chatter                --      true = the vibration grows (regenerative chatter) or diverged
surface_finish_ok      --      Ra (form removed) within the tolerance
tool_leaves_cut        --      an insert leaves the material during the cut
roughness_Ra_um        um      Ra of the machined profile after removing its form (line)
feed_amplitude_growth  --      last / first revolution amplitude of the feed-direction
                               regenerative displacement (> 1: it grows)
=====================  ======  ==================================================================

Each is optional (a runner that does not compute a quantity leaves it out); a present value
must be finite and >= 0 (amplitudes), or a boolean (``stable`` and the verdict flags: bool,
0/1, or the strings "true"/"false"); ``roughness_Ra_um`` and ``feed_amplitude_growth`` are
left out when not finite (a run too short to measure a growth). "Amplitude" is whatever the
runner documents as the paper's "average amplitude" (the paper's Figs. 9 and 10); the
measured CSV must use the same definition.

The same summary as JSON (what ``robobore simulate`` style commands print) nests the forces:
``{"force_amplitude_N": {"x": .., "y": .., "z": ..}, "feed_amplitude_um": .., "stable": ..}``;
:func:`summary_to_json` and :func:`summary_from_json` convert between the two forms.
"""

from __future__ import annotations

import math
from typing import Any

from robobore.errors import DataError

#: Amplitude quantities (float, >= 0), with their units.
AMPLITUDE_QUANTITIES: dict[str, str] = {
    "force_amplitude_x_N": "N",
    "force_amplitude_y_N": "N",
    "force_amplitude_z_N": "N",
    "feed_amplitude_um": "um",
}
#: Every summary quantity, amplitudes then the stability flag (the paper's criterion).
SUMMARY_QUANTITIES: tuple[str, ...] = (*AMPLITUDE_QUANTITIES, "stable")
#: Boolean verdicts by cause (optional).
VERDICT_FLAGS: tuple[str, ...] = ("chatter", "surface_finish_ok", "tool_leaves_cut")
#: Numbers behind the verdicts (optional, finite and >= 0 when present).
VERDICT_VALUES: dict[str, str] = {"roughness_Ra_um": "um", "feed_amplitude_growth": "-"}
_BOOL_KEYS = ("stable", *VERDICT_FLAGS)

_TRUE = {"true", "1", "yes"}
_FALSE = {"false", "0", "no"}


def parse_bool(value: Any) -> bool | None:
    """``True``/``False`` for a boolean-like value (bool, 0/1, "true"/"false"/"yes"/"no"
    in any case), ``None`` when it is not one."""
    import numpy as np

    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer) and int(value) in (0, 1):
        return bool(int(value))
    if isinstance(value, float | np.floating) and float(value) in (0.0, 1.0):
        return bool(float(value))
    if isinstance(value, str | bytes):
        s = value.decode() if isinstance(value, bytes) else value
        s = s.strip().lower()
        if s in _TRUE:
            return True
        if s in _FALSE:
            return False
    return None


def _scalar(ds: Any, name: str) -> tuple[bool, Any]:
    if name in ds.data_vars:
        var = ds[name]
        if var.ndim != 0:
            raise DataError(
                f"summary variable has dimensions {var.dims}", field=name,
                expected="a scalar (0-d) variable",
            )
        return True, var.values.item()
    if name in ds.attrs:
        v = ds.attrs[name]
        try:
            import numpy as np

            if isinstance(v, np.ndarray):
                if v.size != 1:
                    raise DataError("summary attribute is an array", field=name, value=v.tolist(),
                                    expected="one value")
                v = v.item()
        except ImportError:  # pragma: no cover
            pass
        return True, v
    return False, None


def summarise(ds: Any, source: str | None = None) -> dict[str, Any]:
    """The summary of one condition's result (see module doc): only the quantities present.

    Raises :class:`DataError` naming ``source`` and the quantity when a value breaks the
    contract (not a number, negative, non-finite, not a boolean).
    """
    out: dict[str, Any] = {}
    for name, unit in AMPLITUDE_QUANTITIES.items():
        f, v = _number(ds, name, source, f"in {unit}")
        if f is None:
            continue
        if not math.isfinite(f) or f < 0:
            raise DataError("summary value out of range", file=source, field=name, value=v,
                            expected=f"a finite number >= 0 in {unit}")
        out[name] = f
    for name in _BOOL_KEYS:
        present, v = _scalar(ds, name)
        if present:
            b = parse_bool(v)
            if b is None:
                raise DataError("summary value is not a boolean", file=source, field=name,
                                value=v, expected="true or false")
            out[name] = b
    for name, unit in VERDICT_VALUES.items():
        f, _ = _number(ds, name, source, f"({unit})")
        if f is not None and math.isfinite(f) and f >= 0:  # a verdict value may be undefined
            out[name] = f
    return out


def _number(ds: Any, name: str, source: str | None, unit_words: str
            ) -> tuple[float | None, Any]:
    """The summary quantity ``name`` as (float, stored value); (None, None) when absent; a
    non-number is an error."""
    present, v = _scalar(ds, name)
    if not present:
        return None, None
    try:
        return float(v), v
    except (TypeError, ValueError):
        raise DataError("summary value is not a number", file=source, field=name, value=v,
                        expected=f"a finite number >= 0 {unit_words}") from None


def summary_to_json(summary: dict[str, Any]) -> dict[str, Any]:
    """Flat summary -> the nested JSON form (``force_amplitude_N: {x, y, z}``)."""
    out: dict[str, Any] = {}
    forces = {ax: summary[f"force_amplitude_{ax}_N"] for ax in "xyz"
              if f"force_amplitude_{ax}_N" in summary}
    if forces:
        out["force_amplitude_N"] = forces
    for k in ("feed_amplitude_um", "stable"):
        if k in summary:
            out[k] = summary[k]
    return out


def summary_from_json(d: dict[str, Any]) -> dict[str, Any]:
    """The nested JSON form -> the flat summary; unknown keys are ignored."""
    out: dict[str, Any] = {}
    forces = d.get("force_amplitude_N") or {}
    if not isinstance(forces, dict):
        raise DataError("force_amplitude_N must be an object", field="force_amplitude_N",
                        value=forces, expected='{"x": N, "y": N, "z": N}')
    for ax in "xyz":
        if ax in forces and forces[ax] is not None:
            out[f"force_amplitude_{ax}_N"] = float(forces[ax])
    if d.get("feed_amplitude_um") is not None:
        out["feed_amplitude_um"] = float(d["feed_amplitude_um"])
    if d.get("stable") is not None:
        b = parse_bool(d["stable"])
        if b is None:
            raise DataError("stable must be a boolean", field="stable", value=d["stable"],
                            expected="true or false")
        out["stable"] = b
    return out


def summary_attrs(summary: dict[str, Any]) -> dict[str, Any]:
    """The summary as netCDF-safe global attributes (``stable`` as the string
    "true"/"false", since netCDF attributes cannot hold booleans)."""
    out: dict[str, Any] = {}
    for k, v in summary.items():
        out[k] = ("true" if v else "false") if k in _BOOL_KEYS else float(v)
    return out


__all__ = [
    "AMPLITUDE_QUANTITIES",
    "SUMMARY_QUANTITIES",
    "VERDICT_FLAGS",
    "VERDICT_VALUES",
    "parse_bool",
    "summarise",
    "summary_to_json",
    "summary_from_json",
    "summary_attrs",
]
