"""Draw the figures of README.md and docs/*.md from the bundled data with robobore's own API
and commands (``python docs/figures/make.py``; CI runs it after the tests, so the figures
never go stale). Every input is the bundled SYNTHETIC example data (or a short FE cut of the
bundled TC4); each figure says so in its title.

Figures (docs/figures/*.png):

* ``lobes_verdicts.png``  semi-discretisation lobes of the identified robot with the
  time-domain verdicts (chatter / no chatter) of runs below and above the limit;
* ``posture_map.png``     the workspace map of ``robobore plan posture
  examples/plan_paper_bore.toml --plot`` (coarser steps);
* ``fe_chip.png``         a short 2D FE cut of TC4 (``examples/fe_orthogonal.toml`` with
  0.05 mm of travel and 20 um elements), the chip coloured by temperature;
* ``frf_fit.png``, ``cmif.png``  the modal identification of the bundled hammer test;
* ``directional_stiffness.png``  ``robobore robot stiffness --plot`` at the paper's posture;
* ``chatter_spectrogram.png``    ``robobore detect chatter --plot`` on a SYNTHETIC record that
  chatters (``robobore measure synthetic --seed 0``).

Run time on 2 cores once the numba kernels are compiled (they are, after the test suite):
about a minute; ``--only NAME`` draws one figure.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
EXAMPLES = ROOT / "examples"


def _cli(*args: str) -> str:
    """Run one ``robobore`` command in this process; its output, or SystemExit on failure."""
    from typer.testing import CliRunner

    from robobore.cli import app

    r = CliRunner().invoke(app, [str(a) for a in args])
    if r.exit_code != 0:
        raise SystemExit(f"robobore {' '.join(map(str, args))} failed ({r.exit_code}):\n"
                         f"{r.output}")
    return r.stdout


def _take(src: Path, name: str) -> Path:
    if not src.is_file():
        raise SystemExit(f"{src} was not written")
    dst = HERE / name
    shutil.copyfile(src, dst)
    return dst


def lobes_verdicts(tmp: Path) -> Path:
    """Lobes of the identified robot and time-domain verdicts at points around them."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from robobore import api

    joints = api.identify_joint_stiffness()
    pose = api.stiffness_at_pose(joints, joints_deg=api.PAPER_POSTURE_DEG)
    modes = api.identify_modes(api.load_hammer_test(), band_Hz=(3.0, 60.0), n_modes=5)
    robot = api.equivalent_model(pose, modes)
    process = {
        "insert": {"nose_radius_mm": 0.4, "rake_deg": 7.0, "edge_radius_um": 20.0},
        "bore": {"diameter_mm": 40.0},
        "cutting": {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_mm": 0.05},
        "coefficients": api.bundled_coefficients(),
        "speed_rpm": {"min": 150.0, "max": 1100.0, "count": 39},
    }
    lobes = api.stability_lobes(process, robot)
    n = np.asarray(lobes.speed_rpm, float)
    d = np.asarray(lobes.critical_depth_mm, float)
    fig, ax = plt.subplots(figsize=(8, 4.5))
    top = float(np.nanmax(d[np.isfinite(d)])) * 2.2
    ax.fill_between(n, np.where(np.isfinite(d), d, top), top, color="tab:red", alpha=0.10,
                    label="unstable (lobes)")
    ax.plot(n, d, color="tab:blue", lw=1.6, label="critical depth (semi-discretisation)")
    ib = lobes.interrupted_below_mm
    if ib is not None:
        ib = np.asarray(ib, float)
        ax.plot(n, np.where(ib > 0, ib, np.nan), color="tab:orange", lw=1.0, ls="--",
                label="steady cut interrupted below (the tool leaves the cut)")
    # time-domain runs at half and at twice the limit at six speeds where the limit is above
    # 0.02 mm, and at 0.05 mm at two speeds where the lobes give no chatter-free depth
    pos = np.flatnonzero(np.isfinite(d) & (d > 0.02))
    zero = np.flatnonzero(d == 0.0)
    runs = [(n[i], f * d[i]) for i in pos[np.linspace(0, pos.size - 1, 6).astype(int)]
            for f in (0.5, 2.0)]
    runs += [(n[i], 0.05) for i in zero[np.linspace(0, zero.size - 1, 2).astype(int)]]
    pts = []
    for s, a in runs:
        run = api.simulate_boring(process, robot, speed_rpm=float(s), depth_mm=float(a),
                                  revolutions=60)
        kind = ("undecided" if not run.chatter_decided else
                "chatter" if run.chatter else
                "leaves" if run.tool_leaves_cut else "steady")
        pts.append((s, a, kind))
    for kind, mk, col, lab in (
            ("steady", "o", "tab:green", "time domain: no chatter, in the cut"),
            ("leaves", "^", "tab:orange", "time domain: no chatter, the tool leaves the cut"),
            ("chatter", "x", "tab:red", "time domain: chatter"),
            ("undecided", "s", "tab:gray", "time domain: undecided (at its limit)")):
        sel = [(s, a) for s, a, k in pts if k == kind]
        if sel:
            ax.plot(*zip(*sel, strict=True), mk, color=col, ms=8, mew=2, ls="none", label=lab)
    ax.set_ylim(0, top)
    ax.set_xlim(n.min(), n.max())
    ax.set_xlabel("spindle speed [r/min]")
    ax.set_ylabel("radial depth of cut [mm]")
    ax.set_title("stability lobes and time-domain verdicts, identified robot without the "
                 "foot\n(SYNTHETIC campaign and hammer test, bundled TC4 coefficients)",
                 fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    out = HERE / "lobes_verdicts.png"
    fig.savefig(out, dpi=110)
    plt.close(fig)
    decided = [(s, a, k) for s, a, k in pts if k != "undecided"]
    agree = sum(1 for s, a, k in decided if (k == "chatter") == (a > d[np.argmin(abs(n - s))]))
    print(f"  lobes: {agree}/{len(decided)} decided time-domain verdicts on the lobes' side "
          f"({len(pts) - len(decided)} undecided); "
          + ", ".join(f"{s:.0f} r/min {a:.3f} mm {k}" for s, a, k in pts))
    return out


def posture_map(tmp: Path) -> Path:
    """The planner's workspace map on the bundled bore (the best lowest critical depth over
    part placements shifted by dx, dy), every 3 deg of tool-axis rotation (the example takes
    1 deg) and 20 deg in the workspace (the example 10 deg): the same map at a third of the
    cost."""
    src = EXAMPLES / "plan_paper_bore.toml"
    txt = src.read_text(encoding="utf-8")
    for old, new in (('"plan_paper_bore/', f'"{EXAMPLES.as_posix()}/plan_paper_bore/'),
                     ("[plan]\nrotation_step_deg = 1.0", "[plan]\nrotation_step_deg = 3.0"),
                     ("rotation_step_deg = 10.0", "rotation_step_deg = 20.0")):
        if old not in txt:
            raise SystemExit(f"{src} has no '{old}'")
        txt = txt.replace(old, new)
    cfg = tmp / "plan.toml"
    cfg.write_text(txt, encoding="utf-8")
    _cli("plan", "posture", cfg, "--plot", tmp / "plan")
    return _take(tmp / "plan" / "posture_workspace.png", "posture_map.png")


def fe_chip(tmp: Path) -> Path:
    txt = (EXAMPLES / "fe_orthogonal.toml").read_text(encoding="utf-8")
    for old, new in (("length_mm = 0.3", "length_mm = 0.05"),
                     ("element_size_um = 10.0", "element_size_um = 20.0")):
        if old not in txt:
            raise SystemExit(f"examples/fe_orthogonal.toml has no '{old}'")
        txt = txt.replace(old, new)
    cfg = tmp / "fe_short.toml"
    cfg.write_text(txt, encoding="utf-8")
    out = json.loads(_cli("fe", "orthogonal", cfg, "--json", "--plot", tmp / "fe"))
    print(f"  FE: Fc {out['cutting_force_N_per_mm']:.1f} N/mm, peak "
          f"{out['peak_temperature_K']:.0f} K, {out['wall_time_s']:.1f} s")
    return _take(tmp / "fe" / "fe_chip_temperature_K.png", "fe_chip.png")


def modal(tmp: Path) -> list[Path]:
    from robobore import api
    from robobore.modal.plots import plot_cmif, plot_frf_fit

    an = api.identify_modes(api.load_hammer_test(), band_Hz=(3.0, 60.0), n_modes=5)
    return [plot_frf_fit(an, HERE / "frf_fit.png"), plot_cmif(an, HERE / "cmif.png")]


def stiffness(tmp: Path) -> Path:
    from robobore import api

    joints = api.identify_joint_stiffness()
    s = tmp / "s.json"
    s.write_text(json.dumps(joints.to_dict()), encoding="utf-8")
    q = ",".join(f"{v:g}" for v in api.PAPER_POSTURE_DEG)
    _cli("robot", "stiffness", f"--joints-deg={q}", "--joint-stiffness-file", s,
         "--plot", tmp / "k")
    return _take(tmp / "k" / "directional_stiffness.png", "directional_stiffness.png")


def spectrogram(tmp: Path) -> Path:
    import os

    here = Path.cwd()
    os.chdir(tmp)  # the plot's title names the record as given: a short relative name
    try:
        rec = "synthetic_acc.csv"
        _cli("measure", "synthetic", rec, "--seed", "0")  # its truth: chatter, 2.3 x critical
        _cli("detect", "chatter", rec, "--plot", "chatter")
    finally:
        os.chdir(here)
    return _take(tmp / "chatter" / "chatter_spectrogram.png", "chatter_spectrogram.png")


FIGURES = {"lobes": lobes_verdicts, "posture": posture_map, "fe": fe_chip, "modal": modal,
           "stiffness": stiffness, "spectrogram": spectrogram}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=sorted(FIGURES), action="append",
                    help="draw only this figure (repeatable)")
    args = ap.parse_args(argv)
    t00 = time.perf_counter()
    with tempfile.TemporaryDirectory() as td:
        for name in args.only or FIGURES:
            t0 = time.perf_counter()
            FIGURES[name](Path(td))
            print(f"{name}: {time.perf_counter() - t0:.1f} s", flush=True)
    print(f"figures in {HERE.relative_to(ROOT)}: {time.perf_counter() - t00:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
