"""FE orthogonal validation against the nine measured Ti6Al4V points, with run times and
throughput: a thin caller of :mod:`robobore.cutting.fe.models.validate` (the same protocol as
``robobore fe validate``).

Reference: ../shared/data/ti64_orthogonal_cutting_forces.json (Ducobu, Pantale et al., CIRP
2022). Acceptance (issue 27): |Fc error| <= 10 %, |Ff error| <= 25 % at every point.

Usage::

    python benchmarks/validate_fe_orthogonal.py [--config examples/fe_orthogonal.toml]
        [--data PATH] [--points 60:30,40:5] [--out DIR] [--device cpu|gpu]

Prints one row per point (measured, simulated, signed error, wall time, element updates per
second), the summary and the machine load. Per-point results are kept in ``--out`` (default
/tmp/fe_validate_<config>): a rerun reuses them (delete the folder to time again).
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.models.validate import parse_points, read_measured, run_validation
from robobore.io.config import load_toml

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "ti64_orthogonal_cutting_forces.json"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", type=Path, default=ROOT / "examples" / "fe_orthogonal.toml")
    ap.add_argument("--data", type=Path,
                    default=Path(os.environ.get("ROBOBORE_TI64_DATA", DATA)))
    ap.add_argument("--points", default=None, help="h_um:vc list, e.g. 60:30,40:5")
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--device", default="cpu")
    a = ap.parse_args()
    base = load_toml(a.config)
    parse_config(base, str(a.config))
    out = a.out or Path(tempfile.gettempdir()) / f"fe_validate_{a.config.stem}"
    print(f"# FE validation of {a.config} against {a.data}; device {a.device}, numba threads "
          f"{os.environ.get('NUMBA_NUM_THREADS', 'default')}, load "
          f"{os.getloadavg()[0]:.1f}; results in {out}")
    print(f"{'h um':>5} {'vc':>4} | {'Fc meas':>7} {'Fc sim':>7} {'err%':>6} | {'Ff meas':>7} "
          f"{'Ff sim':>7} {'err%':>6} | {'r meas':>6} {'r sim':>6} | {'wall s':>6} "
          f"{'elem-upd/s':>10} reused")

    def f(v, fm):
        return format("-" if v is None else v, fm if v is not None else ">" + fm.split(".")[0])

    res = run_validation(base, read_measured(a.data), source=str(a.config),
                         points=None if a.points is None else parse_points(a.points),
                         out_dir=out, device=a.device).to_dict()
    for p in res["points"]:
        m, e = p["measured"], p["relative_error"]
        pct = {k: None if v is None else 100 * v for k, v in e.items()}
        print(f"{p['uncut_chip_thickness_um']:5.0f} {p['cutting_speed_m_per_min']:4.0f} | "
              f"{f(m['cutting_force_N_per_mm'], '7.1f')} {p['cutting_force_N_per_mm']:7.1f} "
              f"{f(pct['cutting_force'], '+6.1f')} | {f(m['feed_force_N_per_mm'], '7.1f')} "
              f"{p['feed_force_N_per_mm']:7.1f} {f(pct['feed_force'], '+6.1f')} | "
              f"{f(m['chip_ratio'], '6.2f')} {f(p['chip_ratio'], '6.2f')} | "
              f"{f(p['wall_time_s'], '6.0f')} {f(p['element_updates_per_s'], '10.3g')} "
              f"{p['reused']}")
    s = res["summary"]
    for k in ("cutting_force", "feed_force", "chip_ratio"):
        mx, mn = s["max_abs_error"][k], s["mean_abs_error"][k]
        if mx is not None:
            print(f"# {k}: mean |error| {100 * mn:.1f} %, max {100 * mx:.1f} % "
                  f"({s['n_measured'][k]} points)")


if __name__ == "__main__":
    main()
