"""Plot stored FE validation runs in the plane of their force errors, with the acceptance box.

Every JSON row file written by ``validate_fe_orthogonal.py --json`` in a folder (default:
``benchmarks/measured/fe_validation_2026-11-23``) that holds the chosen point is read; each
run is a dot at (cutting-force error, feed-force error) in per cent, labelled with its file
name, and issue 5's acceptance box (|Fc error| <= 10 %, |Ff error| <= 35 %) is drawn. The
picture shows which model settings reach the box at that point (docs/fe.md, "Limits").

    python benchmarks/plot_fe_error_plane.py [--dir DIR] [--point 60:5] [--out FILE.png]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

FC_TOL, FF_TOL = 10.0, 35.0  # issue 5's acceptance: per cent of the measurement


def rows_at(folder: Path, h_um: float, vc: float) -> list[tuple[str, float, float]]:
    """(file stem, Fc error %, Ff error %) of every stored row at (h, vc), sorted by name."""
    out = []
    for f in sorted(folder.glob("*.json")):
        data = json.loads(f.read_text())
        rows = data if isinstance(data, list) else data.get("rows", [])
        for r in rows:
            if (isinstance(r, dict) and r.get("Fc_err_pct") is not None and r.get("h_um") == h_um
                    and r.get("vc_m_per_min") == vc):
                out.append((f.stem, float(r["Fc_err_pct"]), float(r["Ff_err_pct"])))
    return out


def clusters(rows, tol: float = 1.0) -> list[tuple[list[str], float, float]]:
    """Runs whose errors agree within ``tol`` per cent in both forces share one dot (the
    mean) and one label listing their files."""
    groups: list[list[tuple[str, float, float]]] = []
    for r in rows:
        for g in groups:
            if abs(g[0][1] - r[1]) <= tol and abs(g[0][2] - r[2]) <= tol:
                g.append(r)
                break
        else:
            groups.append([r])
    return [([n for n, _, _ in g], sum(x[1] for x in g) / len(g), sum(x[2] for x in g) / len(g))
            for g in groups]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", type=Path, default=Path(__file__).resolve().parent / "measured"
                    / "fe_validation_2026-11-23")
    ap.add_argument("--point", default="60:5", help="h_um:vc_m_per_min")
    ap.add_argument("--out", type=Path, default=None,
                    help="PNG (default: DIR/error_plane_h<h>_vc<vc>.png)")
    args = ap.parse_args()
    h, vc = (float(x) for x in args.point.split(":"))
    rows = rows_at(args.dir, h, vc)
    if not rows:
        raise SystemExit(f"no rows at h {h:g} um, vc {vc:g} m/min in {args.dir}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(11.0, 6.0))
    fig.subplots_adjust(left=0.08, right=0.55, bottom=0.1, top=0.92)
    ax.add_patch(plt.Rectangle((-FC_TOL, -FF_TOL), 2 * FC_TOL, 2 * FF_TOL, fill=True,
                               alpha=0.12, color="tab:green", label="acceptance box"))
    for name, fc, ff in rows:
        print(f"{name:50s} Fc {fc:+6.1f} %  Ff {ff:+6.1f} %")
    key = []
    for k, (names, fc, ff) in enumerate(clusters(rows), start=1):
        ax.plot(fc, ff, "o", ms=6)
        ax.annotate(str(k), (fc, ff), fontsize=8, xytext=(5, 4), textcoords="offset points")
        key.append(f"{k}: ({fc:+.1f} %, {ff:+.1f} %) " + ", ".join(names))
    fig.text(0.57, 0.92, "\n".join(key), fontsize=7, va="top", family="monospace", wrap=True)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.axvline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("cutting-force error, % of the measurement")
    ax.set_ylabel("feed-force error, % of the measurement")
    ax.set_title(f"FE runs at h {h:g} um, vc {vc:g} m/min (Ti6Al4V, Ducobu et al. 2022 data)")
    ax.legend(loc="lower right", fontsize=8)
    out = args.out or args.dir / f"error_plane_h{h:g}_vc{vc:g}.png"
    fig.savefig(out, dpi=130)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
