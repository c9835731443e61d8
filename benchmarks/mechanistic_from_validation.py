"""Mechanistic coefficients calibrated from the validated FE model's nine points: the
mechanistic orthogonal forces against their FE points and against the measurements, with
leave-one-speed-out cross-validation (issue 27's acceptance on the coefficients).

Reads the FE forces the validated model gave at the nine measured conditions (the bundled
validation record data/fe_validation/tc4_default_model.json, the ``--json`` output of
``robobore fe validate examples/fe_orthogonal.toml``: 10 um elements, 0.3 mm, rake 15 deg,
edge radius 20 um; or ``--record`` another) and runs
:func:`robobore.cutting.calibrate.mechanistic_check` on them: the calibration of ``robobore
calibrate forces`` (pooled set + per-speed fits), the forces through the boring model's own
coefficient path at each point's cutting speed (speed-dependent: per-speed fits interpolated
linearly in ln(vc), held outside the calibrated speeds), compared with the FE point (target 5 %)
and the measurement (../shared/data/ti64_orthogonal_cutting_forces.json; Fc 10 %, Ff 25 %).
The pooled set (``speed_dependent = false``) is printed for comparison. No FE is run.

    python benchmarks/mechanistic_from_validation.py [--data PATH] [--record PATH] [--json]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from robobore.cutting import calibrate as cal
from robobore.cutting.fe.models.validate import read_measured
from robobore.cutting.fe.models.validation_record import (
    bundled_validation_path,
    load_validation_record,
)
from robobore.io.config import load_toml

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "fe_orthogonal.toml"
DATA = ROOT.parent / "shared" / "data" / "ti64_orthogonal_cutting_forces.json"
if not DATA.is_file():  # the same measured data, bundled with the package
    DATA = ROOT / "src" / "robobore" / "cutting" / "coefficients" / DATA.name


def _pct(x: float | None) -> str:
    return "    -" if x is None else f"{100 * x:+6.1f}"


def _table(rows: list[dict]) -> None:
    print(f"{'h':>4} {'vc':>4} | {'Fc mech':>7} {'Fc FE':>7} {'vs FE%':>6} {'vs meas%':>8} | "
          f"{'Ff mech':>7} {'Ff FE':>6} {'vs FE%':>6} {'vs meas%':>8}")
    for r in rows:
        print(f"{r['h_um']:4.0f} {r['vc_m_per_min']:4.0f} | {r['Fc_N_per_m'] / 1e3:7.1f} "
              f"{r['Fc_fe_N_per_m'] / 1e3:7.1f} {_pct(r['error_vs_fe']['Fc'])} "
              f"{_pct(r['error_vs_measured']['Fc']):>8} | {r['Ff_N_per_m'] / 1e3:7.1f} "
              f"{r['Ff_fe_N_per_m'] / 1e3:6.1f} {_pct(r['error_vs_fe']['Ff'])} "
              f"{_pct(r['error_vs_measured']['Ff']):>8}")


def _summary(label: str, s: dict) -> None:
    parts = []
    for ref, name in (("error_vs_fe", "vs FE"), ("error_vs_measured", "vs measured")):
        for q in ("Fc", "Ff"):
            e = s[ref][q]
            if e is not None:
                parts.append(f"{name} {q} max {100 * e['max_abs']:.1f} % mean "
                             f"{100 * e['mean_abs']:.1f} %")
    print(f"# {label}: " + "; ".join(parts))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=DATA)
    ap.add_argument("--record", type=Path, default=bundled_validation_path(),
                    help="FE validation record (robobore fe validate --json)")
    ap.add_argument("--json", action="store_true", help="print the checks as JSON")
    a = ap.parse_args()
    measured = read_measured(a.data)
    cfg, recs = cal.validation_calibration(load_validation_record(a.record), load_toml(EXAMPLE),
                                           source=str(EXAMPLE))
    t0 = time.perf_counter()
    dep = cal.mechanistic_check(cfg, recs, measured)
    t_dep = time.perf_counter() - t0
    pooled = cal.mechanistic_check(cfg, recs, measured, speed_dependent=False)
    if a.json:
        for r in (dep, pooled):
            r.pop("coefficients")
        print(json.dumps({"speed_dependent": dep, "pooled": pooled}, indent=1))
        return
    tol = dep["tolerances"]
    print(f"# targets: vs FE {100 * tol['fe_point']:.0f} %; vs measured Fc "
          f"{100 * tol['measured']['Fc']:.0f} %, Ff {100 * tol['measured']['Ff']:.0f} %")
    print("# speed-dependent coefficients (per-speed fits at "
          + ", ".join(f"{v:g}" for v in cfg.cutting_speed_m_per_min) + " m/min, linear in ln(vc))")
    _table(dep["points"])
    _summary("speed-dependent", dep["summary"])
    print(f"# within all targets: {dep['passes']}")
    print("# leave-one-speed-out cross-validation (calibrated from the other speeds)")
    for c in dep["cross_validation"]:
        print(f"## held out {c['held_out_m_per_min']:g} m/min, {c['kind']}")
        _table(c["points"])
        _summary(f"held out {c['held_out_m_per_min']:g} m/min", c["summary"])
    _summary("pooled set (speed_dependent = false)", pooled["summary"])
    print(f"# pooled set within all targets: {pooled['passes']}")
    n = len(recs) + sum(len(c["points"]) for c in dep["cross_validation"])
    print(f"# throughput: {n} point evaluations ({1 + len(dep['cross_validation'])} "
          f"calibrations) in {t_dep * 1e3:.1f} ms = {n / t_dep:.0f} points/s")


if __name__ == "__main__":
    main()
