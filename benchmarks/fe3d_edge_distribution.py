"""3D boring FE: where along the cutting edge the force is, against the mechanistic model.

Usage::

    python benchmarks/fe3d_edge_distribution.py [--element-um 10] [--cut-mm 0.15]
        [--mass-scaling 400] [--coefficients FILE] [--bin-um 10] [--out FILE.json]

Runs ``examples/fe_boring_paper.toml`` (erosion layer, Rech friction) at one element size
and, every 200 steps over the last half of the cut, takes the per-node contact forces on the
tool, binned by ``zeta = z - z_tip`` (feed direction, measured from the insert tip: positive
on the leading side, which cuts the chip up to the depth of cut; negative on the trailing
side of the nose). Prints per bin the mean tangential / radial / feed force (rotating frame,
on the tool, as ``force_rotating_N``) next to the mechanistic model's edge-element forces
(``cutting.forces.boring_forces``, the coefficients file given, default TC4 otherwise) and
the totals of both sides. The snapshot mean is checked against the run's own mean force.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    from robobore.cutting.fe.engine import kernels3d as K3
    from robobore.cutting.fe.engine.state3d import advance3
    from robobore.cutting.fe.models.boring3d import parse_boring_config, setup_boring
    from robobore.cutting.forces import boring_forces, load_coefficients, ti64_coefficients
    from robobore.io.config import load_toml
    from robobore.io.results import atomic_write_bytes

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--element-um", type=float, default=10.0)
    ap.add_argument("--cut-mm", type=float, default=0.15)
    ap.add_argument("--mass-scaling", type=float, default=400.0)
    ap.add_argument("--coefficients", type=Path, default=None)
    ap.add_argument("--bin-um", type=float, default=10.0)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()

    d = load_toml(ROOT / "examples" / "fe_boring_paper.toml")
    d["mesh"]["element_size_um"] = a.element_um
    d["cut"]["cut_length_mm"] = a.cut_mm
    d["solver"]["mass_scaling"] = a.mass_scaling
    d.setdefault("contact", {})["friction"] = "table"
    cfg = parse_boring_config(d)
    setup = setup_boring(cfg)
    st = setup.state
    ins = setup.insert
    lo = -ins.nose_radius_m
    hi = ins.nose_radius_m
    bins = np.arange(lo, hi + 1e-12, a.bin_um * 1e-6)
    nb = len(bins) - 1
    acc = np.zeros((nb, 3))
    nsnap = 0
    t_half = setup.t_end - 0.5 * a.cut_mm * 1e-3 / setup.vc

    def snapshot(s) -> None:
        nonlocal nsnap
        if s.clock[0] < t_half:
            return
        cz = s.tool[K3.T_GZ] + s.tool[K3.T_UZ]
        on = np.any(s.cf != 0.0, axis=1)
        # force on the tool = -cf; rotating frame as in boring3d: Ft = -F_x, Fr = -F_y, Fz = F_z
        f = np.column_stack([s.cf[on, 0], s.cf[on, 1], -s.cf[on, 2]])
        idx = np.clip(np.digitize(s.z[on] - cz, bins) - 1, 0, nb - 1)
        for k in range(3):
            acc[:, k] += np.bincount(idx, f[:, k], minlength=nb)
        nsnap += 1

    advance3(st, setup.t_end, chunk_steps=200, check=snapshot)
    acc /= max(nsnap, 1)
    coef = (load_coefficients(a.coefficients) if a.coefficients is not None
            else ti64_coefficients(setup.vc * 60.0))
    m = boring_forces(ins, setup.ap, setup.f, coef)
    el, ef = m["elements"], m["element_forces"]
    sk, ck = np.sin(el.kappa), np.cos(el.kappa)
    per = (ef.dFt, -ef.dFf * ck - ef.dFl * sk, -ef.dFf * sk + ef.dFl * ck)
    mb = np.zeros((nb, 3))
    idx = np.clip(np.digitize(el.zeta, bins) - 1, 0, nb - 1)
    for k in range(3):
        mb[:, k] = np.bincount(idx, per[k], minlength=nb)
    print(f"# {a.element_um} um, {st.n_elements} elements, {nsnap} snapshots; FE total "
          f"t/r/f {acc.sum(0).round(3).tolist()} N, model {m['tangential_N']:.3f} "
          f"{m['radial_N']:.3f} {m['feed_N']:.3f} N")
    print(f"{'zeta um':>8} | {'FE Ft':>7} {'Fr':>7} {'Fz':>7} | {'model Ft':>8} {'Fr':>7} "
          f"{'Fz':>7}")
    for i in range(nb):
        if np.any(acc[i] != 0.0) or np.any(mb[i] != 0.0):
            print(f"{1e6 * bins[i]:8.0f} | {acc[i, 0]:7.3f} {acc[i, 1]:7.3f} {acc[i, 2]:7.3f} | "
                  f"{mb[i, 0]:8.3f} {mb[i, 1]:7.3f} {mb[i, 2]:7.3f}")
    tr = bins[:-1] < 0.0
    res = {"element_size_um": a.element_um, "n_elements": st.n_elements, "snapshots": nsnap,
           "zeta_bins_um": (bins * 1e6).tolist(), "fe_N": acc.tolist(), "model_N": mb.tolist(),
           "fe_trailing_N": acc[tr].sum(0).tolist(), "fe_leading_N": acc[~tr].sum(0).tolist(),
           "model_total_N": [m["tangential_N"], m["radial_N"], m["feed_N"]]}
    print(f"trailing side (zeta < 0) FE {np.round(res['fe_trailing_N'], 3).tolist()} N, "
          f"leading side FE {np.round(res['fe_leading_N'], 3).tolist()} N")
    if a.out is not None:
        atomic_write_bytes(a.out, json.dumps(res, indent=1).encode())


if __name__ == "__main__":
    main()
