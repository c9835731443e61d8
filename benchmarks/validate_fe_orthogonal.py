"""Validate the FE orthogonal-cutting engine against the 9 measured Ti6Al4V points.

Reference: ../shared/data/ti64_orthogonal_cutting_forces.json (Ducobu, Pantale et al., CIRP
2022; forces per mm of width, chip ratio). Acceptance of issue 5: |Fc error| <= 10 %,
|Ff error| <= 35 %, chip ratio within the measured value +-30 %.

By default the friction coefficient comes from the source's Coulomb-vs-speed table (Rech et
al. 2013) through ``contact.friction = "table"``: the a-priori engine, nothing fitted to these
points. ``--base examples/fe_orthogonal_toolframe_calibrated.toml`` runs the CALIBRATED set
(friction and hardening choices found by probing against these nine points, docs/fe.md).

Usage::

    python benchmarks/validate_fe_orthogonal.py [--base CONFIG.toml] [--length-mm 1.0]
        [--element-um 10]
        [--data PATH] [--json OUT.json] [--points 60:30,40:5] [--separation node_split]
        [--separation-height-um 5] [--edge-um 2.5] [--band-um 10,10] [--conduction]
        [--frame tool] [--friction 0.3|table] [--friction-velocity sliding]
        [--shear-limit-mpa 576] [--save-dir DIR]

Prints a table (measured, simulated, error, pass) and the run times. A point the file does not
hold (``--points 60:60``, another speed of the campaign) is run with the same protocol and
printed as a prediction, not counted as a pass or a failure.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

from robobore.cutting.fe.config import FRICTION_TABLE_MU, FRICTION_TABLE_VC_M_MIN, parse_config
from robobore.cutting.fe.solver import simulate_orthogonal
from robobore.errors import ConfigError
from robobore.io.config import load_toml

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / \
    "ti64_orthogonal_cutting_forces.json"
#: the source's cap on the contact shear stress (its model_inputs_used_by_source)
SHEAR_LIMIT_MPA = 576.0
#: the tool-frame model's mesh keys this script sets: (option, mesh key, what the key is)
TOOLFRAME_MESH_OPTIONS = (
    ("--chip-length-um", "chip_length_um", "(default: max(1.5 chip thicknesses, 80 um))"),
    ("--depth-um", "depth_um", "(the fixed bottom's depth below the cut line; default: "
     "max(2.5 h, 120 um))"),
    ("--inflow-um", "inflow_length_um", "(default: max(1.5 h, 60 um))"),
    ("--back-um", "back_length_um", "(default: max(2 h, 120 um))"),
)


#: options copied as they are into a config key: (argparse dest, section, key)
_PLAIN_OPTIONS = (
    ("frame", "mesh", "frame"),
    ("separation", "mesh", "separation"),
    ("separation_height_um", "mesh", "separation_height_um"),
    ("edge_um", "mesh", "edge_element_um"),
    *((key, "mesh", key) for _, key, _ in TOOLFRAME_MESH_OPTIONS),
    ("distortion_limit", "solver", "distortion_limit"),
    ("erode_dt_fraction", "solver", "erode_time_step_fraction"),
    ("friction", "contact", "friction"),
    ("shear_limit_mpa", "contact", "shear_limit_MPa"),
    ("friction_velocity", "contact", "friction_velocity"),
    ("tool_conductance", "contact", "thermal_conductance_W_per_m2K"),
    ("friction_heat_fraction", "contact", "friction_heat_fraction"),
    ("hardening_strain_limit", "material", "hardening_strain_limit"),
)

def config(h_um: float, vc: float, length_mm: float, le_um: float, extra=None,
           mass_scaling_at_30: float = 100.0) -> dict:
    d = {
        "material": {"name": "TC4"},
        "tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
        "cut": {"uncut_chip_thickness_um": h_um, "cutting_speed_m_per_min": vc,
                "length_mm": length_mm, "width_mm": 1.0},
        "contact": {"friction": "table", "shear_limit_MPa": SHEAR_LIMIT_MPA},
        "mesh": {"element_size_um": le_um},
        # same inertia ratio as the contract (100 at 30 m/min): factor 100 (30/vc)^2 keeps
        # vc / (scaled wave speed) and hence the step count per mm of cut constant;
        # the thermal mass is never scaled
        "solver": {"mass_scaling": mass_scaling_at_30 * (30.0 / vc) ** 2},
    }
    for k, v in (extra or {}).items():
        d.setdefault(k, {}).update(v)
    return d


def _fmt(x, fmt: str) -> str:
    """``x`` formatted, or a right-aligned "-" of the same width where it is None."""
    return format(x, fmt) if x is not None else format("-", ">" + fmt.split(".")[0])


def protocol(args: argparse.Namespace, base: dict | None = None) -> tuple[float, float, float]:
    """(cut length mm, element size um, mass scaling at 30 m/min) of a run: the option where
    given, else the base file's (its mass scaling carried from its own speed to 30 m/min by the
    (30 / vc)^2 rule), else 1.0 mm, 10 um, 100."""
    base = base or {}
    bcut, bms = base.get("cut", {}), base.get("solver", {}).get("mass_scaling")
    ms_base = (None if bms is None
               else bms * (bcut.get("cutting_speed_m_per_min", 30.0) / 30.0) ** 2)

    def first(*vals, default):
        return next((v for v in vals if v is not None), default)

    return (first(args.length_mm, bcut.get("length_mm"), default=1.0),
            first(args.element_um, base.get("mesh", {}).get("element_size_um"), default=10.0),
            first(args.mass_scaling_at_30, ms_base, default=100.0))


def point_config(h: float, vc: float, args: argparse.Namespace, base: dict | None = None) -> dict:
    """The config dict of one point: config()'s protocol, then the base file's keys (``--base``:
    every section but the cut conditions; its cut length, element size and mass scaling where
    the matching option is not given, see ``protocol``), then the options given on the command
    line."""
    length_mm, le_um, ms30 = protocol(args, base)
    extra: dict = {}
    for sec, keys in (base or {}).items():
        if sec != "cut" and isinstance(keys, dict):
            extra[sec] = {k: v for k, v in keys.items() if (sec, k) not in
                          (("mesh", "element_size_um"), ("solver", "mass_scaling"))}
    opts: dict = {}
    for dest, sec, key in _PLAIN_OPTIONS:
        if getattr(args, dest) is not None:
            opts.setdefault(sec, {})[key] = getattr(args, dest)
    if args.band_um is not None:
        opts.setdefault("mesh", {})["edge_band_um"] = [float(v) for v in args.band_um.split(",")]
    if args.conduction:
        opts.setdefault("solver", {})["heat_conduction"] = True
    if args.friction_table_scale is not None:
        opts.setdefault("contact", {}).update(
            friction="table", friction_table_velocity_m_per_min=FRICTION_TABLE_VC_M_MIN.tolist(),
            friction_table_mu=(args.friction_table_scale * FRICTION_TABLE_MU).tolist())
    for sec, keys in opts.items():
        extra.setdefault(sec, {}).update(keys)
    return config(h, vc, length_mm, min(le_um, h / 3), extra, mass_scaling_at_30=ms30)


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", type=Path, default=None,
                    help="a FE config TOML whose material, tool, contact, mesh and solver keys "
                    "every point starts from (its cut length, element size and mass scaling "
                    "unless the options below give them; its cut conditions are replaced by "
                    "each point's), e.g. examples/fe_orthogonal_toolframe_calibrated.toml")
    ap.add_argument("--length-mm", type=float, default=None,
                    help="cut.length_mm (default: the base file's, else 1.0)")
    ap.add_argument("--element-um", type=float, default=None,
                    help="mesh.element_size_um, at most h / 3 (default: the base file's, "
                    "else 10)")
    ap.add_argument("--data", type=Path, default=Path(os.environ.get("ROBOBORE_TI64_DATA", DATA)))
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--points", type=str, default="", help="h_um:vc list, e.g. 60:30,40:5")
    ap.add_argument("--separation", choices=["node_split", "erosion_layer"], default=None,
                    help="mesh.separation (default: the engine's default)")
    ap.add_argument("--separation-height-um", type=float, default=None,
                    help="mesh.separation_height_um (default: the engine's default)")
    ap.add_argument("--conduction", action="store_true", help="solver.heat_conduction = true")
    ap.add_argument("--distortion-limit", type=float, default=None,
                    help="solver.distortion_limit (default: the engine's default)")
    ap.add_argument("--erode-dt-fraction", type=float, default=None,
                    help="solver.erode_time_step_fraction (default: the engine's default)")
    ap.add_argument("--edge-um", type=float, default=None,
                    help="mesh.edge_element_um: refined band round the parting line "
                    "(node splitting)")
    ap.add_argument("--band-um", type=str, default=None,
                    help="mesh.edge_band_um as ABOVE,BELOW (default: the engine's default)")
    ap.add_argument("--tool-conductance", type=float, default=None,
                    help="contact.thermal_conductance_W_per_m2K (with --conduction)")
    ap.add_argument("--friction-heat-fraction", type=float, default=None,
                    help="contact.friction_heat_fraction (with --conduction)")
    def friction(v: str) -> float | str:
        if v == "table":
            return v
        try:
            return float(v)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"--friction {v!r}: expected a Coulomb coefficient (e.g. 0.3) or 'table'"
            ) from None

    ap.add_argument("--friction", type=friction, default=None,
                    help='contact.friction: a number (e.g. 0.3, the paper\'s modified Coulomb '
                         'value) or "table" (Rech et al. 2013, the default of config())')
    ap.add_argument("--shear-limit-mpa", type=float, default=None,
                    help="contact.shear_limit_MPa: the cap on the contact shear stress (default "
                    f"{SHEAR_LIMIT_MPA:g}, the source's value; a large value lifts the cap)")
    ap.add_argument("--friction-velocity", choices=["cutting_speed", "sliding"], default=None,
                    help='contact.friction_velocity: read the friction table at the cutting '
                    'speed (default) or at each contact node\'s sliding speed')
    ap.add_argument("--frame", choices=["workpiece", "tool"], default=None,
                    help='mesh.frame: "tool" runs the tool-frame ALE model (--edge-um is then '
                    'the element round the edge; the separation options are not used)')
    ap.add_argument("--save-dir", type=Path, default=None,
                    help="write each point's final state (deformed mesh, fields, node "
                    "velocities) to DIR/h<h>_vc<vc>.npz")
    for flag, key, what in TOOLFRAME_MESH_OPTIONS:
        ap.add_argument(flag, dest=key, type=float, default=None,
                        help=f"mesh.{key} of the tool-frame model {what}")
    ap.add_argument("--friction-table-scale", type=float, default=None,
                    help="contact.friction = \"table\" with the Rech et al. 2013 table's "
                    "coefficients multiplied by this factor (a user table: "
                    "friction_table_velocity_m_per_min / friction_table_mu)")
    ap.add_argument("--hardening-strain-limit", type=float, default=None,
                    help="material.hardening_strain_limit: hold the Johnson-Cook hardening "
                    "term beyond this plastic strain (default: none, the plain law)")
    ap.add_argument("--mass-scaling-at-30", type=float, default=None,
                    help="solver.mass_scaling at 30 m/min; a point at vc gets this times "
                    "(30 / vc)^2, which keeps the step count per mm of cut the same "
                    "(default: the base file's factor carried to 30 m/min, else 100, the "
                    "contract's factor)")
    ap.add_argument("--device", choices=["cpu", "gpu"], default="cpu",
                    help="run each point on the CPU (numba) or the GPU (numba-cuda)")
    return ap


def main() -> None:
    args = parser().parse_args()
    ref = json.loads(args.data.read_text())["measured"]
    pts = [(float(h), float(v)) for h in ref["Fc"] for v in ref["Fc"][h]]
    if args.points:
        pts = [tuple(float(x) for x in p.split(":")) for p in args.points.split(",")]
    base = None
    if args.base is not None:
        # a missing, unreadable or invalid base file is a ConfigError naming the file and key
        try:
            base = load_toml(args.base)
            parse_config(base, str(args.base))
        except ConfigError as e:
            raise SystemExit(f"--base: {e}") from None
    rows = []
    d0 = point_config(*pts[0], args, base)
    ms30 = protocol(args, base)[2]
    # what every point runs with: the first point's keys (the cut conditions, the element's
    # h / 3 bound and the mass scaling's (30 / vc)^2 change from point to point); keys not
    # shown take the engine's defaults (docs/fe.md, "Config keys and defaults")
    print(f"# FE orthogonal validation: base {args.base or 'none'}, cut length "
          f"{d0['cut']['length_mm']} mm, mass scaling {ms30:g} (30/vc)^2, device "
          f"{args.device}, load {os.getloadavg()[0]:.1f}; the first point's config (the cut "
          "aside): " + json.dumps({k: v for k, v in d0.items() if k != "cut"}))
    hdr = (f"{'h um':>5} {'vc':>4} | {'Fc meas':>7} {'Fc sim':>7} {'err%':>6} | {'Ff meas':>7} "
           f"{'Ff sim':>7} {'err%':>6} | {'r meas':>6} {'r sim':>6} {'r vel':>6} | {'E err':>6} "
           f"{'ero%':>5} "
           f"{'wall s':>6}")
    print(hdr)
    for h, vc in pts:
        hk = f"{h:g}"
        vk = f"{vc:g}"
        t0 = time.perf_counter()
        d = point_config(h, vc, args, base)
        cfg = parse_config(d)
        res = simulate_orthogonal(cfg, device=args.device)
        s = res.summary
        if args.save_dir is not None:
            import numpy as np

            args.save_dir.mkdir(parents=True, exist_ok=True)
            np.savez_compressed(args.save_dir / f"h{hk}_vc{vk}.npz", **res.final)
        measured = hk in ref["Fc"] and vk in ref["Fc"][hk]
        fc_s, ff_s, r_s = (s["cutting_force_N_per_mm"], s["feed_force_N_per_mm"],
                           s["chip_ratio"])
        if measured:
            fc_m, ff_m, r_m = ref["Fc"][hk][vk], ref["Ff"][hk][vk], ref["chip_ratio"][hk][vk]
            efc = 100 * (fc_s - fc_m) / fc_m
            eff = 100 * (ff_s - ff_m) / ff_m
            ok = (abs(efc) <= 10, abs(eff) <= 35,
                  abs(r_s - r_m) <= 0.3 * r_m if r_s == r_s else False)
            ok_rv = bool(abs(s["chip_ratio_velocity"] - r_m) <= 0.3 * r_m)
        else:
            # a prediction at a condition the file does not hold (e.g. another speed of the
            # campaign): reported, never counted as a pass or a failure
            fc_m = ff_m = r_m = efc = eff = None
            ok = (None, None, None)
            ok_rv = None
        row = dict(h_um=h, vc_m_per_min=vc, measured=measured, Fc_meas=fc_m, Fc_sim=fc_s,
                   Fc_err_pct=efc, Ff_meas=ff_m, Ff_sim=ff_s,
                   Ff_err_pct=eff, chip_ratio_meas=r_m, chip_ratio_sim=r_s,
                   chip_ratio_velocity=s["chip_ratio_velocity"],
                   pass_chip_velocity=ok_rv,
                   energy_error=s["energy_error"], wall_s=time.perf_counter() - t0,
                   steps=s.get("steps"), n_elements=s.get("n_elements"),
                   element_updates_per_s=s.get("element_updates_per_s"),
                   device=args.device, mass_scaling=cfg.solver.mass_scaling,
                   base=None if args.base is None else str(args.base),
                   hardening_strain_limit=cfg.material.hardening_strain_limit,
                   pass_Fc=ok[0], pass_Ff=ok[1], pass_chip=ok[2],
                   friction=s["friction_coefficient"], friction_law=s.get("friction_law"),
                   eroded_distortion=s.get("eroded_distortion"),
                   eroded_chip_mass_fraction=s.get("eroded_chip_mass_fraction"),
                   peak_temperature_K=s.get("peak_temperature_K"),
                   force_by_face_N_per_mm=s.get("force_by_face_N_per_mm"))
        rows.append(row)

        verdict = ("(not in the measured file)" if not measured else
                   f"{'Fc ok' if ok[0] else 'Fc FAIL'} {'Ff ok' if ok[1] else 'Ff FAIL'} "
                   f"{'r ok' if ok[2] else 'r FAIL'}")
        print(f"{h:5.0f} {vc:4.0f} | {_fmt(fc_m, '7.1f')} {fc_s:7.1f} {_fmt(efc, '6.1f')} | "
              f"{_fmt(ff_m, '7.1f')} {ff_s:7.1f} {_fmt(eff, '6.1f')} | {_fmt(r_m, '6.2f')} "
              f"{r_s:6.2f} {row['chip_ratio_velocity']:6.2f} | "
              f"{row['energy_error']:6.3f} "
              f"{100 * (row['eroded_chip_mass_fraction'] or 0.0):5.1f} {row['wall_s']:6.0f}  "
              f"{verdict}", flush=True)
    rows_m = [r for r in rows if r["measured"]]
    n = len(rows_m)
    if len(rows) > n:
        print(f"# {len(rows) - n} point(s) not in the measured file: predictions only")
    print(f"# passed: Fc {sum(r['pass_Fc'] for r in rows_m)}/{n}, Ff "
          f"{sum(r['pass_Ff'] for r in rows_m)}/{n}, chip ratio "
          f"{sum(r['pass_chip'] for r in rows_m)}/{n} (from the chip speed: "
          f"{sum(r['pass_chip_velocity'] for r in rows_m)}/{n})")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
