"""Time the 3D tool-frame ALE pass (:func:`robobore.cutting.fe.ale.rezone3d.rezone3d`) on the
paper condition's z-sliced tool-frame mesh (ap 0.05 mm, f 0.15 mm/rev, the insert of
``examples/fe_boring_paper.toml``), and its two parts: the placement
(``toolframe3d_targets``) and the remap (``remap3d``).

The state is a random Lagrangian drift of every node but the rigid ones (0.01 of the local
size) and an insert travel of 0.1 um, restored before every pass. Prints ms per pass and
nodes per second; run with the thread count of interest, e.g.
``NUMBA_NUM_THREADS=1 python benchmarks/bench_rezone3d.py``.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--element-um", type=float, default=12.5, help="element size [um]")
    ap.add_argument("--repeat", type=int, default=20, help="timed passes")
    args = ap.parse_args()

    import numba

    from robobore.cutting.fe.ale.groups3d import ToolFrameAle3
    from robobore.cutting.fe.ale.remap3d import remap3d, remap3d_groups, remap3d_inputs
    from robobore.cutting.fe.ale.rezone import TF_RIGID
    from robobore.cutting.fe.ale.rezone3d import rezone3d, toolframe3d_ale_data, toolframe3d_targets
    from robobore.cutting.fe.hex.layout3d import (
        N_PRM,
        P_CLR,
        P_KAPPA,
        P_KEND,
        P_RAKE,
        P_RE,
        P_RN,
        P_TOOL,
    )
    from robobore.cutting.fe.mesh.toolframe3d import build_toolframe3d_mesh
    from robobore.cutting.fe.mesh.toolframe3d_layout import ToolFrame3DSizes
    from robobore.cutting.geometry import BoringInsert

    insert = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=90.0,
                          end_edge_angle_deg=5.0, rake_deg=7.0, clearance_deg=7.0,
                          edge_radius_m=20e-6, inclination_deg=0.0)
    mesh = build_toolframe3d_mesh(insert, 0.05e-3, 0.15e-3,
                                  ToolFrame3DSizes(args.element_um * 1e-6))
    acls, aflt0 = toolframe3d_ale_data(mesh)
    prm = np.zeros(N_PRM)
    prm[P_RN], prm[P_KAPPA], prm[P_KEND] = 0.4e-3, math.pi / 2, math.radians(5.0)
    prm[P_RAKE], prm[P_CLR], prm[P_RE], prm[P_TOOL] = (math.radians(7.0), math.radians(7.0),
                                                       20e-6, 1.0)
    rng = np.random.default_rng(0)
    cur = mesh.nodes.copy()
    mov = acls[:, 0] != TF_RIGID
    cur[mov] += rng.uniform(-0.01, 0.01, (int(mov.sum()), 3)) * aflt0[mov, 3:4]
    off_x = 0.1e-6
    n, ne = mesh.n_nodes, mesh.n_elements
    a0 = remap3d_inputs(cur, mesh.conn, {}, bflag=mesh.bflag)
    x0, y0, z0 = (mesh.nodes[:, k].copy() for k in range(3))
    xn, yn, zn = np.empty(n), np.empty(n), np.empty(n)
    scratch = np.zeros((n, 3))
    rho_s = 4430.0 * 100.0

    def fresh():
        a = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in a0.items()}
        return a, aflt0.copy()

    def groups(a):
        nodes, cells, elems, work = remap3d_groups(a)
        return nodes, cells, elems, work._replace(xn=xn, yn=yn, zn=zn)

    def run_rezone(a, aflt):
        ale = ToolFrameAle3(x0=x0, y0=y0, z0=z0, acls=acls, aflt=aflt, scratch=scratch)
        return rezone3d(*groups(a), ale, rho_s, 293.15, 0, prm, (off_x, 0.0, 0.25),
                        (off_x, 0.0, 0.0))

    def run_targets(a, aflt):
        ale = ToolFrameAle3(x0=x0, y0=y0, z0=z0, acls=acls, aflt=aflt, scratch=scratch)
        toolframe3d_targets(a["x"], a["y"], a["z"], xn, yn, zn, ale, prm, (off_x, 0.0, 0.25),
                            (off_x, 0.0, 0.0))

    def run_remap(a, aflt):
        remap3d(*groups(a), rho_s, 293.15, 0)

    print(f"paper mesh, {args.element_um:g} um elements: {n} nodes, {ne} hexahedra; "
          f"{numba.get_num_threads()} thread(s)")
    for name, fn in (("rezone3d (placement + remap)", run_rezone),
                     ("placement (toolframe3d_targets)", run_targets),
                     ("remap (remap3d)", run_remap)):
        a, aflt = fresh()
        run_targets(a, aflt)  # xn, yn, zn for the remap alone; compiles
        fn(a, aflt)
        best = math.inf
        for _ in range(args.repeat):
            a, aflt = fresh()
            run_targets(a, aflt)
            t = time.perf_counter()
            fn(a, aflt)
            best = min(best, time.perf_counter() - t)
        print(f"  {name:34s} {best * 1e3:8.2f} ms per pass  {n / best / 1e6:7.2f} M nodes/s")


if __name__ == "__main__":
    main()
