"""Shear-plane check of the Johnson-Cook constants against the measured cutting tests.

An analytical cross-check of the FE validation (docs/fe.md, "Validation against the measured
forces"), independent of the FE engine: for every point of
``../shared/data/ti64_orthogonal_cutting_forces.json``

1. **What the measurement implies.** The measured chip ratio r gives the shear angle
   (Merchant's geometry, rake alpha): tan(phi) = cos(alpha) / (r - sin(alpha)). The measured
   forces give the force along the shear plane, Fs = Fc cos(phi) - Ff sin(phi), and the mean
   shear stress on it, tau = Fs sin(phi) / h. Two variants: all of the measured force, and
   the measured force less its edge part -- the h -> 0 intercepts of the least-squares lines
   of Fc and Ff through the three thicknesses at that speed (the force that does not grow
   with h: the ploughing of the 20 um edge radius, which does not act on the shear plane).
2. **What the Johnson-Cook constants give** at the deformation state of that shear plane,
   after Oxley ("Mechanics of Machining", 1989, ch. 4-5): on the plane AB halfway through
   the primary shear zone the equivalent strain is half the total,
   eps_AB = gamma / (2 sqrt 3) with gamma = cos(alpha) / (sin(phi) cos(phi - alpha)); the
   strain rate eps_dot_AB = C0 Vs / (sqrt 3 l_AB) with the shear velocity
   Vs = vc cos(alpha) / cos(phi - alpha), the shear-plane length l_AB = h / sin(phi) and
   Oxley's zone-thickness constant C0 (his fits for steels: about 3-10; reported here at
   3, 6 and 10); the temperature T_AB = T0 + eta (1 - beta) tau gamma / (rho c) with
   eta = 0.9 (Oxley; the plastic work to heat is the material's Taylor-Quinney 0.9 as well,
   folded into eta as in Oxley) and beta, the share of the shear-zone heat that goes into
   the workpiece, from Boothroyd's empirical fit to Weiner's solution (as used by Oxley):
   beta = 0.5 - 0.35 log10(R_T tan phi) for 0.04 <= R_T tan phi <= 10,
   beta = 0.3 - 0.15 log10(R_T tan phi) above, R_T = rho c vc h / k. The shear flow stress
   k_JC = sigma_JC(eps_AB, eps_dot_AB, T_AB) / sqrt 3 is solved with the temperature it
   itself produces (fixed point), as in the FE model, where the heat comes from the JC
   stress.

With ``--fe-state FILE.npz:H_UM:VC`` (a final state saved by ``validate_fe_orthogonal.py
--save-dir``, tool-frame model) the script also reads the FE model's own primary shear zone:
the elements between 0.2 h and 0.8 h below the free surface, ahead of the tool, whose plastic
strain is 0.4-0.6 of the chip's median (Oxley's AB line, half the chip's strain) -- their
area-weighted strain, temperature and shear flow stress (von Mises / sqrt 3) -- and the
Merchant shear stress of the FE's own rake-face forces and chip ratio (from the JSON row next
to the state, when given as ``FILE.npz:H_UM:VC:ROW.json``).
It also reads the chip's layer against the rake face (the secondary shear zone: elements
within 5 um of the rake line, up to the farthest contact node): its strain, temperature and
equivalent shear stress, to compare with the AB line's.

The tool-chip contact length is estimated after Oxley as well (his eq. for h in ch. 5):
l_c = h sin(theta) / (cos(lambda) sin(phi)) (1 + C0 n_eq / (3 tan theta)), with the friction
angle lambda from the measured force less its edge part, theta = phi + lambda - alpha and
the equivalent strain-hardening index of the JC law at AB, n_eq = n B eps^n / (A + B eps^n);
C0 = 6. For a saved FE state the script reports the FE's own contact length: the farthest
node in contact up the rake, measured from where the rake face starts.

The ratio k_JC / tau says how much harder (> 1) the constants make the material than the
measured forces and chip imply. It is an estimate: Oxley's AB state, C0 and Boothroyd's beta
are approximations, and the measured chip of the 30 m/min points is segmented (the
continuous-chip geometry of step 1 does not hold there). It does not use the FE engine.

    python benchmarks/shear_plane_check.py [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

from robobore.cutting.fe.models.output import shear_angle_deg
from robobore.material.library import load_material

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "ti64_orthogonal_cutting_forces.json"
RAKE_DEG = 15.0
EDGE_RADIUS = 20e-6  # the measured tools' edge radius [m] (the data file's description)
RAKE_LAYER = 5e-6  # depth of the chip layer against the rake read from an FE state [m]: two
# 2.5 um edge elements of the tool-frame mesh
C0_VALUES = (3.0, 6.0, 10.0)
ETA = 0.9


def boothroyd_beta(rt_tan_phi: float) -> float:
    """Share of the shear-zone heat conducted into the workpiece (Boothroyd's fit to
    Weiner's solution, as in Oxley 1989); clipped to [0, 1]."""
    x = max(rt_tan_phi, 1e-12)
    b = 0.5 - 0.35 * math.log10(x) if x <= 10.0 else 0.3 - 0.15 * math.log10(x)
    return min(max(b, 0.0), 1.0)


def shear_state(h: float, vc: float, r: float, alpha: float) -> dict:
    """Merchant geometry from the chip ratio: shear angle [rad], total shear strain, shear
    velocity [m/s], shear-plane length [m]."""
    phi = math.radians(shear_angle_deg(r, alpha))
    gamma = math.cos(alpha) / (math.sin(phi) * math.cos(phi - alpha))
    vs = vc * math.cos(alpha) / math.cos(phi - alpha)
    return {"phi": phi, "gamma": gamma, "vs": vs, "l": h / math.sin(phi)}


def measured_shear_stress(fc: float, ff: float, h: float, phi: float) -> float:
    """Mean shear stress on the shear plane [Pa] from forces per width [N/m]."""
    fs = fc * math.cos(phi) - ff * math.sin(phi)
    return fs * math.sin(phi) / h


def jc_shear_flow_stress(mat, h: float, vc: float, st: dict, c0: float) -> tuple[float, float]:
    """Oxley's AB-plane shear flow stress [Pa] of the JC constants and its temperature [K],
    solved with the heat it produces (fixed point)."""
    eps = st["gamma"] / (2.0 * math.sqrt(3.0))
    rate = c0 * st["vs"] / (math.sqrt(3.0) * st["l"])
    rt = mat.rho * mat.cp * vc * h / mat.k
    beta = boothroyd_beta(rt * math.tan(st["phi"]))
    k = mat.flow_stress(eps, rate, mat.T_room) / math.sqrt(3.0)
    temp = mat.T_room
    for _ in range(200):
        temp = mat.T_room + ETA * (1.0 - beta) * k * st["gamma"] / (mat.rho * mat.cp)
        k_new = mat.flow_stress(eps, rate, temp) / math.sqrt(3.0)
        if abs(k_new - k) < 1e-6 * k:
            k = k_new
            break
        k = 0.5 * (k + k_new)  # damped: the softening makes the plain iteration oscillate
    return k, temp


def oxley_contact_length(mat, h: float, st: dict, alpha: float, fc: float, ff: float,
                         c0: float) -> float:
    """Oxley's tool-chip contact length [m] from the measured shear angle and the friction
    angle of the forces ``fc``, ``ff`` [N/m] on the rake."""
    lam = alpha + math.atan2(ff, fc)
    theta = st["phi"] + lam - alpha
    eps = st["gamma"] / (2.0 * math.sqrt(3.0))
    bn = mat.B * eps ** mat.n
    n_eq = mat.n * bn / (mat.A + bn)
    return (h * math.sin(theta) / (math.cos(lam) * math.sin(st["phi"]))
            * (1.0 + c0 * n_eq / (3.0 * math.tan(theta))))


def _quad_areas(x: np.ndarray, y: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Areas of the quads ``conn`` (half the cross product of their diagonals)."""
    return np.abs(0.5 * ((x[conn[:, 2]] - x[conn[:, 0]]) * (y[conn[:, 3]] - y[conn[:, 1]])
                         - (x[conn[:, 3]] - x[conn[:, 1]]) * (y[conn[:, 2]] - y[conn[:, 0]])))


def _rake_coordinates(d, px, py, rake: float, r: float):
    """Points' distance up the rake face from where it starts and their distance from the
    rake line towards the chip [m], for the tool of a saved FE state ``d``."""
    cx, cy = d["tool_center"]
    sx, sy = cx - r * math.cos(rake), cy + r * math.sin(rake)  # where the rake face starts
    along = (px - sx) * math.sin(rake) + (py - sy) * math.cos(rake)
    normal = -(px - sx) * math.cos(rake) + (py - sy) * math.sin(rake)
    return along, normal


def _contact_length(d, rake: float, r: float) -> float:
    cf = d["contact_force_N_per_m"]
    on = (cf[0] != 0.0) | (cf[1] != 0.0)
    s, _ = _rake_coordinates(d, d["x"], d["y"], rake, r)
    return float(s[on].max()) if on.any() else float("nan")


def fe_contact_length(path: Path, rake: float, r: float) -> float:
    """Farthest contact node up the rake of a saved FE state, from the rake's start [m]."""
    return _contact_length(np.load(path), rake, r)


def fe_rake_layer(path: Path, rake: float, r: float, depth: float = RAKE_LAYER) -> dict:
    """The chip's layer against the rake face in a saved FE state (the secondary shear
    zone): area-weighted plastic strain, temperature [K] and equivalent shear stress [MPa]
    (von Mises / sqrt 3: the shear flow stress where the layer yields, less where it is
    elastic) of the elements whose centroid lies within ``depth`` of the rake line, between
    where the rake face starts and the farthest contact node."""
    d = np.load(path)
    x, y, conn = d["x"], d["y"], d["conn"]
    s, nrm = _rake_coordinates(d, x[conn].mean(1), y[conn].mean(1), rake, r)
    sel = ((nrm > 0.0) & (nrm < depth) & (s > 0.0) & (s < _contact_length(d, rake, r))
           & (d["alive"] > 0))
    w = _quad_areas(x, y, conn)[sel]
    return {"rake_layer_elements": int(sel.sum()),
            "rake_layer_strain": float(np.average(d["eps_p"][sel], weights=w)),
            "rake_layer_T_K": float(np.average(d["temperature_K"][sel], weights=w)),
            "rake_layer_tau_eq_MPa": float(np.average(d["von_mises_Pa"][sel], weights=w)
                                      / math.sqrt(3.0) / 1e6)}


def fe_shear_zone(mat, path: Path, h: float) -> dict:
    """Oxley's AB line in a saved tool-frame FE state (coordinates of the workpiece frame:
    free surface y = 0, the tool moving in -x): area-weighted strain, temperature [K] and
    shear flow stress [MPa] of the elements 0.2 h - 0.8 h below the free surface, ahead of
    the tool's edge centre, with 0.4-0.6 of the chip's median plastic strain."""
    d = np.load(path)
    x, y, conn = d["x"], d["y"], d["conn"]
    xc = x[conn].mean(1)
    yc = y[conn].mean(1)
    cx = float(d["tool_center"][0])
    eps = d["eps_p"]
    chip = (yc > 0.3 * h) & (xc > cx - 3 * h)
    eps_chip = float(np.median(eps[chip]))
    sel = ((yc > -0.8 * h) & (yc < -0.2 * h) & (xc < cx)
           & (eps > 0.4 * eps_chip) & (eps < 0.6 * eps_chip))
    w = _quad_areas(x, y, conn)[sel]
    return {"chip_strain": eps_chip, "ab_elements": int(sel.sum()),
            "ab_strain": float(np.average(eps[sel], weights=w)),
            "ab_T_K": float(np.average(d["temperature_K"][sel], weights=w)),
            "ab_k_MPa": float(np.average(d["von_mises_Pa"][sel], weights=w)
                              / math.sqrt(3.0) / 1e6)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=Path(os.environ.get("ROBOBORE_TI64_DATA", DATA)))
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--fe-state", action="append", default=[],
                    help="FILE.npz:H_UM:VC[:ROW.json] final state of a tool-frame FE run")
    args = ap.parse_args()
    meas = json.loads(args.data.read_text())["measured"]
    mat = load_material("TC4")
    alpha = math.radians(RAKE_DEG)
    hs = sorted(meas["Fc"], key=float)
    vcs = sorted(meas["Fc"][hs[0]], key=float)
    # edge part: h -> 0 intercepts of the least-squares lines through the thicknesses
    edge = {}
    for v in vcs:
        x = np.array([float(h) for h in hs])
        fc = np.array([meas["Fc"][h][v] for h in hs])
        ff = np.array([meas["Ff"][h][v] for h in hs])
        edge[v] = (float(np.polyfit(x, fc, 1)[1]), float(np.polyfit(x, ff, 1)[1]))
    rows = []
    print(f"# shear-plane check, TC4 Johnson-Cook constants of the material library; Oxley AB "
          f"state, C0 = {', '.join(f'{c:g}' for c in C0_VALUES)}, eta {ETA}")
    print(f"{'h um':>5} {'vc':>4} | {'phi':>5} {'gamma':>5} | {'tau all':>7} {'tau-edge':>8} | "
          + " ".join(f"{'kJC C0=' + format(c, 'g'):>10} {'T K':>5}" for c in C0_VALUES)
          + f" | {'ratio (C0 6) all / -edge':>25} | {'l_c um':>6}")
    for h in hs:
        for v in vcs:
            hm = float(h) * 1e-6
            vc = float(v) / 60.0
            st = shear_state(hm, vc, meas["chip_ratio"][h][v], alpha)
            fc = meas["Fc"][h][v] * 1e3  # N/mm -> N/m
            ff = meas["Ff"][h][v] * 1e3
            tau_all = measured_shear_stress(fc, ff, hm, st["phi"])
            tau_cut = measured_shear_stress(fc - edge[v][0] * 1e3, ff - edge[v][1] * 1e3, hm,
                                            st["phi"])
            jc = {c: jc_shear_flow_stress(mat, hm, vc, st, c) for c in C0_VALUES}
            lc = oxley_contact_length(mat, hm, st, alpha, fc - edge[v][0] * 1e3,
                                      ff - edge[v][1] * 1e3, 6.0)
            row = {"h_um": float(h), "vc_m_per_min": float(v),
                   "shear_angle_deg": math.degrees(st["phi"]), "shear_strain": st["gamma"],
                   "tau_measured_MPa": tau_all / 1e6,
                   "tau_measured_less_edge_MPa": tau_cut / 1e6,
                   "edge_intercepts_N_per_mm": list(edge[v]),
                   "k_jc_MPa": {f"{c:g}": jc[c][0] / 1e6 for c in C0_VALUES},
                   "T_AB_K": {f"{c:g}": jc[c][1] for c in C0_VALUES},
                   "ratio_C0_6_all": jc[6.0][0] / tau_all,
                   "ratio_C0_6_less_edge": jc[6.0][0] / tau_cut,
                   "oxley_contact_length_um": lc * 1e6}
            rows.append(row)
            print(f"{float(h):5.0f} {float(v):4.0f} | {row['shear_angle_deg']:5.1f} "
                  f"{st['gamma']:5.2f} | {tau_all / 1e6:7.0f} {tau_cut / 1e6:8.0f} | "
                  + " ".join(f"{jc[c][0] / 1e6:10.0f} {jc[c][1]:5.0f}" for c in C0_VALUES)
                  + f" | {row['ratio_C0_6_all']:11.2f} / {row['ratio_C0_6_less_edge']:.2f}"
                  + f"{'':>9} | {lc * 1e6:6.0f}", flush=True)
    print("# edge intercepts (Fc, Ff) N/mm: "
          + ", ".join(f"{v} m/min {edge[v][0]:.1f} / {edge[v][1]:.1f}" for v in vcs))
    fe_rows = []
    for spec in args.fe_state:
        parts = spec.split(":")
        fe = fe_shear_zone(mat, Path(parts[0]), float(parts[1]) * 1e-6)
        fe.update(state=parts[0], h_um=float(parts[1]), vc_m_per_min=float(parts[2]),
                  contact_length_um=fe_contact_length(Path(parts[0]), alpha, EDGE_RADIUS)
                  * 1e6)
        fe.update(fe_rake_layer(Path(parts[0]), alpha, EDGE_RADIUS))
        if len(parts) > 3:
            run = json.loads(Path(parts[3]).read_text())
            run = run["rows"] if isinstance(run, dict) else run
            rows_run = [r for r in run if r["h_um"] == float(parts[1])
                        and r["vc_m_per_min"] == float(parts[2])]
            run = rows_run[0]
            rake = run["force_by_face_N_per_mm"]["rake"]
            st = shear_state(float(parts[1]) * 1e-6, float(parts[2]) / 60.0,
                             run["chip_ratio_sim"], alpha)
            fe["merchant_tau_rake_MPa"] = measured_shear_stress(
                rake["cutting"] * 1e3, rake["feed"] * 1e3, float(parts[1]) * 1e-6,
                st["phi"]) / 1e6
            fe["friction"] = run["friction"]
        fe_rows.append(fe)
        print("# FE state " + json.dumps({k: (round(v, 3) if isinstance(v, float) else v)
                                          for k, v in fe.items()}))
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=args.json.parent, suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            json.dump({"rake_deg": RAKE_DEG, "C0": list(C0_VALUES), "eta": ETA,
                       "rows": rows, "fe_states": fe_rows}, f, indent=1)
        os.replace(tmp, args.json)


if __name__ == "__main__":
    main()
