"""The paper report's lobes corrected by observed cuts: ``[measured] observations`` of the
paper config (a CSV as ``calibrate dynamics`` reads, relative to the config) calibrate the
robot's equivalent model (:func:`robobore.dynamics.calibrate.calibrate`) and give the band
figure and a table row of the report."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np


def paper_calibration(cfg: Any, cfg_path: Path, robot_model: dict[str, Any],
                      outdir: Path) -> dict[str, Any] | None:
    """None without ``[measured] observations``; else the calibration's summary (factors,
    band at the lowest median critical depth, ``plot``: ``calibration_lobes.png`` in
    ``outdir``) and ``calibration.json`` written there."""
    name = getattr(cfg.measured, "observations", None)
    if not name:
        return None
    from robobore.dynamics.calibrate import calibrate, read_observations
    from robobore.dynamics.plots import plot_band
    from robobore.dynamics.config import DynamicsConfig
    from robobore.dynamics.handoff import with_coefficients
    from robobore.io.config import validate_model
    from robobore.io.paths import resolve_config_path
    from robobore.io.results import write_json

    path = resolve_config_path(name, cfg_path, "measured.observations",
                               what="observations file")
    obs = read_observations(path)
    dyn = json.loads(json.dumps(robot_model["dynamics"]))
    dyn["equivalent"].pop("pressure_foot", None)
    dyn["cutting"] = {"speed_rpm": float(cfg.study.base["speed_rpm"]),
                      "feed_mm_per_rev": float(cfg.study.base["feed_mm_per_rev"]),
                      "depth_mm": float(cfg.study.base["depth_of_cut_mm"])}
    dcfg = validate_model(DynamicsConfig, with_coefficients(dyn), source=str(cfg_path))
    speeds = np.linspace(cfg.lobes.speed_min_rpm, cfg.lobes.speed_max_rpm, 40)
    cal = calibrate(dcfg, obs, speeds=speeds, source=str(cfg_path))
    d = cal.to_dict()
    write_json(outdir / "calibration.json", d)
    plot = plot_band(cal.band, outdir, cal.nominal_m, obs, name="calibration_lobes.png",
                     title="lobes corrected by the observed cuts (P = 0, 90 % band)")
    b = cal.band
    i = int(np.argmin(b.median_m))
    return {"observations": str(path), "cuts": len(obs), "plot": str(plot),
            "factors": {p["name"]: p["value"] for p in d["parameters"]},
            "lowest_critical_depth_mm": [float(b.lower_m[i] * 1e3), float(b.median_m[i] * 1e3),
                                         float(b.upper_m[i] * 1e3)],
            "at_speed_rpm": float(b.speed_rpm[i]), "model": d["model_selection"]["chosen"],
            "seconds": cal.seconds}


__all__ = ["paper_calibration"]
