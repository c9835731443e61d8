"""Where along the insert's edge the 3D boring FE carries its force, against the mechanistic model.

    python benchmarks/fe3d_edge_distribution.py [--size 12.5] [--cut-mm 0.15]
        [--mass-scaling 400] [--coefficients FILE] [--json OUT]

Runs the paper condition (`examples/fe_boring_paper.toml`, the default physics, no tool
support) and, every 200 steps over the averaging window (the last half of the cut), sums the
contact force on every workpiece node in 10 um bins of the node's feed-direction
position relative to the insert's tip (z < 0: the trailing side of the nose, z > 0 the
leading side up to the pre-bore surface at z = 194 um). The mechanistic model
(`cutting.forces.boring_forces`, the bundled FE-calibrated coefficients unless
`--coefficients`) is binned the same way by its edge elements' position `zeta`, once with its
own chip attribution (radial levels, Kaymakci et al. 2012: the chip slice at each radial level
goes to the leading edge point at that level, `h = f sin kappa` up to the pre-bore surface) and
once with the chip thickness measured along each edge point's normal up to the uncut surface
(the previous pass's profile capped by the pre-bore surface; 0 at both ends of the engaged
edge), the definition of the classical nose-radius models, here a diagnostic only. Prints the
tangential / radial / feed force [N] per zone (trailing, 0-60, 60-120, 120-260 um) and in
total. The figures and what they show are in docs/fe3d.md ("Where the thrust is missing").
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from robobore.cutting import geometry as G  # noqa: E402
from robobore.cutting.coefficient_files import load_coefficients  # noqa: E402
from robobore.cutting.fe.config.boring3d import parse_boring_config  # noqa: E402
from robobore.cutting.fe.engine.state3d import advance3  # noqa: E402
from robobore.cutting.fe.hex.scalar3d import T_GZ, T_UZ  # noqa: E402
from robobore.cutting.fe.models.boring3d import setup_boring  # noqa: E402
from robobore.cutting.forces import boring_forces  # noqa: E402
from robobore.io.config import load_toml  # noqa: E402
from robobore.io.results import atomic_write_bytes  # noqa: E402

BINS_M = np.arange(-150e-6, 261e-6, 10e-6)
ZONES_UM = ((-150, 0), (0, 60), (60, 120), (120, 260))
COEF = ROOT / "src" / "robobore" / "data" / "paper_example" / "tc4_fe_coefficients.json"


def fe_distribution(size_um: float, cut_mm: float, mass_scaling: float,
                    every: int = 200) -> tuple[np.ndarray, dict]:
    """(bins, 3) mean contact force on the workpiece nodes [N] (x = cutting, y = out of the
    wall, z = feed) over the averaging window (a snapshot every ``every`` steps), and the
    run's setup facts."""
    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    d.pop("tool_support", None)
    d["mesh"]["frame"] = "workpiece"  # the model whose missing thrust this locates
    d["mesh"]["element_size_um"] = size_um
    d["cut"]["cut_length_mm"] = cut_mm
    d.setdefault("solver", {})["mass_scaling"] = mass_scaling
    cfg = parse_boring_config(d)
    s = setup_boring(cfg)
    st = s.state
    t0 = s.t_end - cfg.solver.steady_window_fraction * cut_mm * 1e-3 / s.vc
    nb = BINS_M.size - 1
    acc = np.zeros((nb, 3))
    n = [0]

    def snapshot(state) -> None:
        if state.time < t0:
            return
        dz = state.z - (state.tool[T_GZ] + state.tool[T_UZ])
        idx = np.digitize(dz, BINS_M) - 1
        ok = (idx >= 0) & (idx < nb)
        for k in range(3):
            acc[:, k] += np.bincount(idx[ok], weights=state.cf[ok, k], minlength=nb)
        n[0] += 1

    advance3(st, s.t_end, chunk_steps=every, check=snapshot)
    return acc / max(n[0], 1), {"insert": s.insert, "ap": s.ap, "f": s.f, "snapshots": n[0],
                                "vc_m_per_min": s.vc * 60.0, "n_elements": st.n_elements}


def normal_chip_elements(insert, ap: float, f: float, n: int = 400):
    """Edge elements from the trailing intersection to the pre-bore surface with the chip
    thickness along each point's edge normal (towards the nose centre) up to the uncut surface
    ``min(ap, drop(zeta + f))``: (zeta, kappa, h, dS) [m, rad, m, m]."""
    z_i = G.trailing_intersection(insert, ap, f)
    s_all = np.linspace(-2.0 * insert.nose_radius_m, 2.0 * insert.nose_radius_m, 400001)
    z_all, d_all, _, _ = insert.point(s_all)
    lead = s_all > 0.0
    edges = np.linspace(float(np.interp(z_i, z_all, s_all)),
                        float(np.interp(ap, d_all[lead], s_all[lead])), n + 1)
    s = 0.5 * (edges[1:] + edges[:-1])
    zeta, drop, kap, _ = insert.point(s)

    def gap(t):
        return drop + t * np.cos(kap) - np.minimum(ap, insert.drop(zeta - t * np.sin(kap) + f))

    lo, hi = np.zeros_like(s), np.full_like(s, 2.0 * f)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = gap(mid) < 0.0
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    h = np.where(gap(np.zeros_like(s)) < 0.0, 0.5 * (lo + hi), 0.0)
    return zeta, kap, h, np.diff(edges)


def model_bins(zeta, kap, h, dS, coef) -> np.ndarray:
    """(bins, 3) tangential, radial, feed force on the tool [N] of edge elements."""
    dFt = coef.Ktc * h * dS + coef.Kte * dS
    dFf = coef.Kfc * h * dS + coef.Kfe * dS
    idx = np.digitize(zeta, BINS_M) - 1
    nb = BINS_M.size - 1
    return np.stack([np.bincount(idx, dFt, nb), np.bincount(idx, -dFf * np.cos(kap), nb),
                     np.bincount(idx, -dFf * np.sin(kap), nb)], axis=1)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=float, default=12.5, help="element size [um]")
    ap.add_argument("--cut-mm", type=float, default=0.15)
    ap.add_argument("--mass-scaling", type=float, default=400.0)
    ap.add_argument("--coefficients", default=str(COEF))
    ap.add_argument("--json", default=None)
    a = ap.parse_args(argv)
    fe_nodes, facts = fe_distribution(a.size, a.cut_mm, a.mass_scaling)
    # node force -> force on the tool: tangential = node x, radial = node y, feed = -node z
    fe = np.stack([fe_nodes[:, 0], fe_nodes[:, 1], -fe_nodes[:, 2]], axis=1)
    ins, apm, fm = facts["insert"], facts["ap"], facts["f"]
    coef = load_coefficients(a.coefficients, facts["vc_m_per_min"])
    el = boring_forces(ins, apm, fm, coef, n_elements=200)["elements"]
    levels = model_bins(el.zeta, el.kappa, el.h, el.dS, coef)
    normal = model_bins(*normal_chip_elements(ins, apm, fm), coef)
    rows = []
    print(f"3D FE {a.size} um ({facts['n_elements']} hexahedra) vs the mechanistic model, "
          "tangential / radial / feed [N]")
    print(f"{'zone [um]':>12s} | {'FE':>20s} | {'model (radial levels)':>22s} | "
          f"{'model (edge normal)':>20s}")
    for lo, hi in (*ZONES_UM, (-150, 260)):
        sel = (BINS_M[:-1] >= lo * 1e-6 - 1e-12) & (BINS_M[:-1] < hi * 1e-6 - 1e-12)
        r = {"zone_um": [lo, hi], "fe_N": fe[sel].sum(0).tolist(),
             "model_radial_levels_N": levels[sel].sum(0).tolist(),
             "model_edge_normal_N": normal[sel].sum(0).tolist()}
        rows.append(r)
        name = "total" if (lo, hi) == (-150, 260) else f"{lo}..{hi}"
        print(f"{name:>12s} | " + " | ".join(
            " ".join(f"{v:6.2f}" for v in r[k])
            for k in ("fe_N", "model_radial_levels_N", "model_edge_normal_N")))
    if a.json:
        atomic_write_bytes(a.json, json.dumps({
            "element_size_um": a.size, "cut_mm": a.cut_mm, "mass_scaling": a.mass_scaling,
            "coefficients": a.coefficients, "bins_um": (BINS_M * 1e6).tolist(),
            "fe_N": fe.tolist(), "model_radial_levels_N": levels.tolist(),
            "model_edge_normal_N": normal.tolist(), "zones": rows,
            "snapshots": facts["snapshots"]}, indent=1).encode())


if __name__ == "__main__":
    main()
