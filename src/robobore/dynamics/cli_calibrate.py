"""CLI command ``robobore calibrate dynamics``: the equivalent model corrected by observed cuts
(:mod:`robobore.dynamics.calibrate`; registered by ``robobore.cli``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from robobore.clitools import JSON_OPTION, emit, fmt, handle_errors, kv_table, stage_progress, stdout
from robobore.errors import ConfigError


def observations_path(cfg: Any, config: Path, option: Path | None) -> Path:
    """The observations CSV: the option (as given) or ``[calibration] observations`` of the
    config (relative to the config's folder)."""
    if option is not None:
        return option
    cal = getattr(cfg, "calibration", None)
    if cal is None or cal.observations is None:
        raise ConfigError("no observations", file=str(config), field="calibration.observations",
                          expected="--observations FILE.csv or [calibration] observations = "
                                   "\"FILE.csv\" in the config")
    from robobore.io.paths import resolve_config_path

    return Path(resolve_config_path(cal.observations, config, "calibration.observations",
                                    what="observations file"))


@handle_errors
def calibrate_dynamics_cmd(
    config: Path = typer.Argument(..., help="Dynamics TOML config (as `lobes` and `simulate "
                                            "boring` take) with the robot's equivalent model."),
    observations: Path | None = typer.Option(
        None, "--observations", help="Observed cuts CSV: speed_rpm, depth_mm, verdict "
                                     "(chatter|stable), optional feed_mm_per_rev, "
                                     "chatter_frequency_hz, feed_amplitude_um (docs/measure.md)."),
    label_noise: float | None = typer.Option(
        None, "--label-noise", help="Rate at which a verdict is wrong (default 0.1 or "
                                    "[calibration] label_noise)."),
    speeds: int = typer.Option(40, "--speeds", help="Speeds of the band over the config's "
                                                    "[speed_rpm] range."),
    no_process_damping: bool = typer.Option(
        False, "--no-process-damping", help="Do not consider a process-damping coefficient."),
    out: Path | None = typer.Option(
        None, "--out", help="Write calibration.json, calibration.nc and equivalent_corrected."
                            "json (an equivalent model `lobes --equivalent-file` takes) here."),
    plot: Path | None = typer.Option(None, "--plot", help="Write calibration_lobes.png here."),
    propose: int = typer.Option(
        0, "--propose", help="Propose this many next test cuts (speed, depth) where the "
                             "posterior is least sure of the critical depth "
                             "(robobore.dynamics.design; among the band's --speeds), no deeper "
                             "than [calibration] max_depth_mm and the depth-of-cut range."),
    as_json: bool = JSON_OPTION,
) -> None:
    """Correct the robot's equivalent model by observed cuts; lobes with a confidence band."""
    import numpy as np

    from robobore.dynamics.calibrate import LikelihoodSettings, calibrate, read_observations
    from robobore.dynamics.config import load_dynamics_config, speed_range
    from robobore.io.outputs import check_output_dir

    check_output_dir(out, "--out", "the calibration files")
    check_output_dir(plot, "--plot", "calibration_lobes.png")
    if not 2 <= speeds <= 2000:
        raise ConfigError("band speeds out of range", field="--speeds", value=speeds,
                          expected="2 .. 2000 speeds")
    if not 0 <= propose <= 100:
        raise ConfigError("number of proposed cuts out of range", field="--propose",
                          value=propose, expected="0 .. 100 cuts")
    cfg, raw = load_dynamics_config(config)
    obs_file = observations_path(cfg, config, observations)
    obs = read_observations(obs_file)
    eps = label_noise
    if eps is None and cfg.calibration is not None:
        eps = cfg.calibration.label_noise
    settings = LikelihoodSettings() if eps is None else LikelihoodSettings(label_noise=eps)
    sp, _ = speed_range(cfg)
    grid = np.linspace(sp.min, sp.max, speeds)
    with stage_progress(not as_json) as prog:
        cal = calibrate(cfg, obs, settings, speeds=grid, source=str(config), progress=prog,
                        allow_process_damping=not no_process_damping)
    result = cal.to_dict()
    result["observations_file"] = str(obs_file)
    result["kind"] = result["kind"] + (" (SYNTHETIC observations)"
                                       if "SYNTHETIC" in obs_file.read_text(
                                           errors="replace")[:2000] else "")
    if propose:
        from robobore.dynamics.design import propose_cuts

        cap = None if cfg.calibration is None or cfg.calibration.max_depth_mm is None else (
            cfg.calibration.max_depth_mm * 1e-3)
        result["proposed_cuts"] = [c.to_dict() for c in propose_cuts(cal, propose,
                                                                     max_depth_m=cap)]
    if out is not None:
        from robobore.io.results import write_json, write_netcdf

        write_json(out / "calibration.json", result)
        write_json(out / "equivalent_corrected.json", cal.equivalent.to_dict())
        write_netcdf(cal.to_dataset(), out / "calibration.nc", config=raw)
        result["files"] = [str(out / n) for n in ("calibration.json", "calibration.nc",
                                                  "equivalent_corrected.json")]
    if plot is not None:
        from robobore.dynamics.plots import plot_band

        result["plot"] = str(plot_band(cal.band, plot, cal.nominal_m, obs,
                                       name="calibration_lobes.png",
                                       title="lobes corrected by the observed cuts "
                                             "(90 % band)"))

    def render(r: dict[str, Any]) -> None:
        rows = [(f"{p['name']} ({p['unit']})",
                 f"{fmt(p['value'])}  [90 %: {fmt(p['p05'])} .. {fmt(p['p95'])}]")
                for p in r["parameters"]]
        sel = r["model_selection"]
        rows.append(("model", f"{sel['chosen']} (BIC {fmt(sel['bic'])}"
                     + (f"; other {fmt(sel['alternative_bic'])}" if "alternative_bic" in sel
                        else "") + ")"))
        n_ch = sum(o["verdict"] == "chatter" for o in r["observations"])
        rows.append(("observations (chatter / all)", f"{n_ch} / {len(r['observations'])}"))
        b = r["band"]
        from robobore.dynamics.band import DEPTH_FLOOR_M

        med = np.asarray(b["critical_depth_p50_mm"])
        floor = med <= DEPTH_FLOOR_M * 1e3 * (1 + 1e-9)
        i = int(np.argmin(np.where(floor, np.inf, med))) if not floor.all() else 0
        if floor.any():
            rows.append(("speeds unstable at vanishing depth (median at the scan's bottom)",
                         f"{int(floor.sum())} of {med.size}"))
        rows.append(("lowest median critical depth (mm)",
                     f"{fmt(b['critical_depth_p50_mm'][i])} [90 %: "
                     f"{fmt(b['critical_depth_p05_mm'][i])} .. "
                     f"{fmt(b['critical_depth_p95_mm'][i])}] at {fmt(b['speed_rpm'][i])} r/min"))
        nom = np.asarray(r["nominal_critical_depth_mm"])
        nom = nom[nom > DEPTH_FLOOR_M * 1e3 * (1 + 1e-9)]
        rows.append(("lowest nominal critical depth (mm)", fmt(nom.min()) if nom.size else "-"))
        for k, c in enumerate(r.get("proposed_cuts", []), start=1):
            rows.append((f"proposed cut {k}",
                         f"{fmt(c['speed_rpm'])} r/min, {fmt(c['depth_mm'])} mm (P(chatter) "
                         f"{c['p_chatter']:.2f}, {c['expected_information_bits']:.2f} bit): "
                         + c["why"]))
        rows.append(("run time (s)", fmt(r["seconds"])))
        for f in r.get("files", []):
            rows.append(("written", f))
        if "plot" in r:
            rows.append(("plot", r["plot"]))
        for n in r["notes"]:
            rows.append(("note", n))
        stdout.print(kv_table("calibrate dynamics", rows))

    emit(result, as_json, render)


def register(groups: dict[str, typer.Typer]) -> None:
    """Add ``calibrate dynamics``."""
    groups["calibrate"].command("dynamics")(calibrate_dynamics_cmd)


def band_uncertainty(cfg: Any, source: str, n_speeds: int) -> dict[str, Any]:
    """The config's equivalent-model uncertainty for ``lobes --band``; a ConfigError when it
    has none or the band's speed count is out of range (checked before the lobes run)."""
    unc = None if cfg.equivalent is None else cfg.equivalent.uncertainty
    if not unc:
        raise ConfigError("no uncertainty to draw a band from", file=source,
                          field="equivalent.uncertainty",
                          expected="an equivalent model with 95 % ranges (model equivalent "
                                   "from modes with intervals, or calibrate dynamics' "
                                   "equivalent_corrected.json)")
    if not 2 <= n_speeds <= 2000:
        raise ConfigError("band speeds out of range", field="--band-speeds", value=n_speeds,
                          expected="2 .. 2000 speeds")
    return unc


def lobes_band(cfg: Any, structure: Any, process: Any, speeds: Any, plot: Path | None,
               source: str, show: bool) -> dict[str, Any]:
    """``lobes --band``: the band of :func:`robobore.dynamics.band.modal_band` from the
    config's equivalent-model uncertainty (a ConfigError when it has none), its dict, and
    ``lobes_band.png`` in ``plot``."""
    from robobore.clitools import progress_bar
    from robobore.dynamics.band import band_evaluations, modal_band, modal_covariance

    unc = band_uncertainty(cfg, source, len(speeds))
    n = band_evaluations(modal_covariance(unc)[0]) * len(speeds)
    with progress_bar("band (modal intervals)", n, show) as adv:
        b = modal_band(structure, process, speeds, unc,
                       progress=lambda k: adv(k * len(speeds)))
    out = b.to_dict()
    if plot is not None:
        from robobore.dynamics.plots import plot_band

        out["plot"] = str(plot_band(b, plot, name="lobes_band.png"))
    return out
