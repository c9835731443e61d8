"""The time-domain verdict on a user's own robot does not depend on the sampling.

A KUKA KR 240 R2900-like arm (``examples/robots/kr240-r2900.toml``, ASSUMED link data) through
the chain a user runs (all SYNTHETIC: virtual campaign, stiffness identification, virtual hammer
test, modal identification, equivalent model), then ``simulate boring
examples/boring_process.toml --equivalent-file ... --speed-rpm 380 --depth-mm 0.02`` at
``--samples-per-rev`` 1266, the default, 4000 and twice the default (and the default and twice it at 240
revolutions instead of the example's 60, and all four at 120), beside the
semi-discretisation critical depth at 380 r/min (``robobore lobes``' answer at that speed).

    python benchmarks/kuka_sampling.py
"""

from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path

from typer.testing import CliRunner

from robobore.cli import app

REPO = Path(__file__).resolve().parents[1]
KUKA = REPO / "examples" / "robots" / "kr240-r2900.toml"
PROCESS = REPO / "examples" / "boring_process.toml"
Q = "20,20,10,0,-30,0"
POSTURES = ("20,20,10,0,-30,0; 0,40,-10,0,30,0; -30,10,20,20,40,10; 45,30,-20,-30,-20,30; "
            "10,50,-30,40,50,-20; -60,0,30,0,60,0")
runner = CliRunner()


def run(args, out: Path | None = None):
    r = runner.invoke(app, [str(a) for a in args])
    if r.exit_code != 0:
        raise SystemExit(r.output)
    if out is not None:
        out.write_text(r.stdout)
        return json.loads(r.stdout)
    return None


def main() -> None:
    from robobore.dynamics.api import critical_depth_at

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        camp, s, uff, m, eq = (tmp / n for n in ("kc.csv", "ks.json", "kh.uff", "km.json",
                                                 "keq.json"))
        run(["robot", "campaign", camp, "--robot-file", KUKA, "--postures-deg", POSTURES])
        run(["identify", "stiffness", camp, "--robot-file", KUKA, "--json"], s)
        run(["identify", "virtual-hammer-test", uff, "--robot-file", KUKA, "--joints-deg", Q])
        run(["identify", "modes", uff, "--band-hz", "3", "60", "--json"], m)
        e = run(["model", "equivalent", "--stiffness-file", s, "--modes-file", m, "--json"], eq)
        print("KUKA-like equivalent model (SYNTHETIC chain): "
              + ", ".join(f"{a}: {e['stiffness_N_per_m'][a] * 1e-6:.3g} N/um" for a in "xyz"))
        keys = ("damping_N_s_per_m", "damping_ratio", "foot", "frame", "frequency_Hz",
                "identity", "mass_kg", "notes", "stiffness_N_per_m")
        at = critical_depth_at(PROCESS, 380.0, equivalent={k: v for k, v in e.items()
                                                           if k in keys})
        print(f"semi-discretisation at 380 r/min: critical depth {at.critical_depth_mm} mm, "
              f"interrupted below {at.interrupted_below_mm:.4g} mm")
        base = None
        for spr, revs in ((1266, None), (None, None), (4000, None), ("2x", None),
                          (1266, 120), (None, 120), (4000, 120), ("2x", 120),
                          (None, 240), ("2x", 240)):
            args = ["simulate", "boring", PROCESS, "--equivalent-file", eq, "--speed-rpm",
                    "380", "--depth-mm", "0.02", "--json"]
            if revs is not None:
                args += ["--revolutions", str(revs)]
            if spr == "2x":
                args += ["--samples-per-rev", str(2 * base)]
            elif spr is not None:
                args += ["--samples-per-rev", str(spr)]
            r = run(args, tmp / "sim.json")
            if spr is None:
                base = r["samples_per_rev"]
            feed = (f"{r['feed_amplitude_um']:.4g} um" if r["feed_amplitude_resolved"]
                    else f"< {r['amplitude_resolution_um']:g} um")
            rho = r["floquet_multiplier"]
            print(f"samples/rev {r['samples_per_rev']:5d} ({'default' if spr is None else spr}): "
                  f"chatter {r['chatter']} (decided {r['chatter_decided']}, cause "
                  f"{r['chatter_cause']}; same run at 2 x samples/rev: "
                  f"{(r['sampling_check'] or {}).get('chatter')}), Floquet multiplier "
                  f"{'-' if rho is None else f'{rho:.5f}'}, "
                  f"tool leaves cut {r['tool_leaves_cut']} (by {r['tool_leaves_cut_cause']}), diverged {r['diverged']}, feed "
                  f"amplitude {feed}, Ra {r['roughness_Ra_um']} um, revolutions "
                  f"{r['revolutions']}", flush=True)
    print(f"{time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
