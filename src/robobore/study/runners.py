"""The real boring runner of sweeps: one cutting condition through ``dynamics.api.run_boring``.

``boring_runner(condition, context) -> xarray.Dataset`` (registered as ``"boring"`` in
:data:`robobore.study.sweep.RUNNERS`). ``context["model"]`` (hashed into every condition's
key) holds:

* ``system``: ``"robot"`` (the equivalent model of the robot, ``[equivalent]`` section; the
  condition's ``pressure_MPa`` sets the pressure foot, 0 = no foot) or ``"machine_tool"``
  (a stiff machine tool given as ``[structure] modes``; the condition's pressure must be 0);
* ``dynamics``: the process-stage config (``robobore simulate boring`` contract, see
  ``docs/process.md``) without the cutting condition: ``equivalent`` or ``structure``,
  ``insert``, ``bore``, ``coefficients`` (put the coefficient VALUES inline, so that the key
  changes when they change), ``simulation``.

``context["runner_options"]`` (not hashed): ``samples_per_rev_stored`` (default 120): the
time series are decimated to about this many samples per revolution and stored as float32
(the full-rate simulation is summarised before decimation, so the summary is exact).

The Dataset carries the summary contract of :mod:`robobore.study.summary` as 0-d
variables (``force_amplitude_{x,y,z}_N``, ``feed_amplitude_um``, ``stable`` (the paper's
criterion) as int8 0/1, absent where it is not judged), the verdicts by cause (``chatter``, ``surface_finish_ok``,
``tool_leaves_cut`` as int8 0/1, ``roughness_Ra_um`` after form removal,
``feed_amplitude_growth``), the force / displacement / rotational-acceleration histories
(boring frame), the feed amplitude per revolution, the machined-surface profile, and in the
attributes the reasons, chatter frequency and mean forces.
"""

from __future__ import annotations

import json
from typing import Any

from robobore.errors import ConfigError

SYSTEMS = ("robot", "machine_tool")


def _dynamics_config(condition: dict[str, Any], model: dict[str, Any]) -> dict[str, Any]:
    system = model.get("system", "robot")
    if system not in SYSTEMS:
        raise ConfigError("unknown system", field="model.system", value=system,
                          expected=f"one of {SYSTEMS}")
    dyn = model.get("dynamics")
    if not isinstance(dyn, dict):
        raise ConfigError("missing model table", field="model.dynamics",
                          expected="the process-stage config (insert, bore, coefficients, ...)")
    cfg = json.loads(json.dumps(dyn))  # deep copy, plain types
    cfg["cutting"] = {"speed_rpm": float(condition["speed_rpm"]),
                      "feed_mm_per_rev": float(condition["feed_mm_per_rev"]),
                      "depth_mm": float(condition["depth_of_cut_mm"])}
    if system == "robot":
        if "equivalent" not in cfg:
            raise ConfigError("a robot needs the equivalent model",
                              field="model.dynamics.equivalent",
                              expected="stiffness_N_per_m, frequency_Hz, damping_ratio per axis")
    else:
        if float(condition.get("pressure_MPa", 0.0)) != 0.0:
            raise ConfigError("a pressure foot applies to the robot only",
                              field="condition.pressure_MPa", value=condition["pressure_MPa"],
                              expected="0 MPa for the machine tool")
        if "structure" not in cfg:
            raise ConfigError("a machine tool needs its modes", field="model.dynamics.structure",
                              expected="[structure] modes (frequency_Hz, damping_ratio, "
                              "stiffness_N_per_m, direction)")
        cfg.pop("equivalent", None)
    return cfg


def boring_runner(condition: dict[str, Any], context: dict[str, Any]) -> Any:
    """Simulate one boring condition; returns the Dataset described in the module doc."""
    import numpy as np
    import xarray as xr

    from robobore.dynamics.api import run_boring

    model = context.get("model", {})
    opts = context.get("runner_options", {}) or {}
    src = context.get("config_file")
    try:
        cfg = _dynamics_config(condition, model)
    except ConfigError as exc:
        if src is not None and exc.file is None:
            raise ConfigError(exc.message, file=src, field=exc.field, value=exc.value,
                              expected=exc.expected) from None
        raise
    system = model.get("system", "robot")
    res = run_boring(cfg, source=f"{src} [model.dynamics]" if src else None,
                     speed_rpm=float(condition["speed_rpm"]),
                     depth_mm=float(condition["depth_of_cut_mm"]),
                     feed_mm_per_rev=float(condition["feed_mm_per_rev"]),
                     pressure_MPa=(float(condition.get("pressure_MPa", 0.0))
                                   if system == "robot" else None),
                     return_dataset=True)
    full = res.dataset
    r = res.to_dict()  # the simulate boring --json keys (and the dataset, the config)
    ns = int(full.attrs["samples_per_rev"])
    keep = int(opts.get("samples_per_rev_stored", 120))
    stride = max(1, ns // max(keep, 1))
    t_idx = slice(None, None, stride)
    data_vars: dict[str, Any] = {}
    for name in ("force", "displacement", "rotational_acceleration"):
        if name in full:
            data_vars[name] = full[name].isel(time=t_idx).astype(np.float32)
    for name in ("feed_amplitude", "surface_profile"):
        if name in full:
            data_vars[name] = full[name]
    # the 0-d summary variables join the dict: the Dataset is built once (one alignment)
    fa = r["force_amplitude_N"]
    for ax in "xyz":
        data_vars[f"force_amplitude_{ax}_N"] = xr.DataArray(float(fa[ax]))
        data_vars[f"force_mean_{ax}_N"] = xr.DataArray(float(r["force_mean_N"][ax]))
    data_vars["feed_amplitude_um"] = xr.DataArray(float(r["feed_amplitude_um"]))
    if r["stable"] is not None:  # absent: not judged (no Ra tolerance, no chatter)
        data_vars["stable"] = xr.DataArray(
            np.int8(1 if r["stable"] else 0),
            attrs={"meaning": "the paper's criterion: Ra (form removed) <= tolerance and no "
                              "chatter"})
    data_vars["chatter"] = xr.DataArray(np.int8(1 if r["chatter"] else 0))
    data_vars["tool_leaves_cut"] = xr.DataArray(np.int8(1 if r["tool_leaves_cut"] else 0))
    if r["surface_finish"] is not None:
        data_vars["surface_finish_ok"] = xr.DataArray(np.int8(1 if r["surface_finish"] == "ok"
                                                              else 0))
    for name in ("roughness_Ra_um", "roughness_Rz_um", "roughness_Ra_with_form_um",
                 "form_slope_um_per_mm", "vibration_growth", "feed_amplitude_growth",
                 "radial_amplitude_growth"):
        data_vars[name] = xr.DataArray(float(r[name]))
    ds = xr.Dataset(data_vars)
    attrs = {k: v for k, v in full.attrs.items() if isinstance(v, str | int | float)}
    attrs.update({
        "system": system,
        "stored_time_stride": int(stride),
        "reasons": "; ".join(r["reasons"]) if r["reasons"] else "",
        "chatter_frequency_Hz": (float(r["chatter_frequency_Hz"])
                                 if r["chatter_frequency_Hz"] is not None else -1.0),
        "nonharmonic_energy_ratio": float(r["nonharmonic_energy_ratio"]),
        "tool_left_cut_fraction": float(r["tool_left_cut_fraction"]),
        "model": r["model"],
        "coefficients_provenance": str(r.get("coefficients_provenance")
                                       or cfg.get("coefficients", {}).get("provenance", "")),
        "coefficient_warnings": "; ".join(r.get("coefficient_warnings", [])),
    })
    ds.attrs = attrs
    return ds


#: imported once by the server the sweep's process pool forks its workers from
_PRELOAD = ("numpy", "xarray", "robobore.dynamics.api", "robobore.dynamics.timedomain",
            "robobore.dynamics.chatter")
boring_runner.preload_modules = _PRELOAD  # type: ignore[attr-defined]

__all__ = ["boring_runner", "SYSTEMS"]
