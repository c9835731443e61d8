"""Robot stage benchmarks: FK + Jacobian throughput and identification time.

Prints figures; no assertions. Run: ``python benchmarks/bench_robot.py``.
The numba kernel is compared with a plain vectorised-numpy implementation of the same D-H
chain (reference in the same run). Note the machine load (``uptime``) with any figure.
"""

from __future__ import annotations

import os
import time

import numpy as np

from robobore.robot.campaign import (
    CampaignSpec,
    TrackerNoise,
    noisy_batch,
    simulate_campaign,
    simulate_clean,
)
from robobore.robot.description import get_robot
from robobore.robot.identify import identify_batch, identify_joint_stiffness
from robobore.robot.kinematics import fk_jacobian


def numpy_fk_jacobian(robot, q, tcp):
    """Reference: the same FK + geometric Jacobian with numpy broadcasting over postures."""
    d, a, al, off = robot.dh_arrays
    n = q.shape[0]
    T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    Z = [T[:, :3, 2].copy()]
    O = [T[:, :3, 3].copy()]
    for i in range(robot.n_joints):
        th = q[:, i] + off[i]
        ct, st = np.cos(th), np.sin(th)
        ca, sa = np.cos(al[i]), np.sin(al[i])
        A = np.zeros((n, 4, 4))
        A[:, 0, 0], A[:, 0, 1], A[:, 0, 2], A[:, 0, 3] = ct, -st * ca, st * sa, a[i] * ct
        A[:, 1, 0], A[:, 1, 1], A[:, 1, 2], A[:, 1, 3] = st, ct * ca, -ct * sa, a[i] * st
        A[:, 2, 1], A[:, 2, 2], A[:, 2, 3] = sa, ca, d[i]
        A[:, 3, 3] = 1.0
        T = T @ A
        Z.append(T[:, :3, 2].copy())
        O.append(T[:, :3, 3].copy())
    p = T[:, :3, 3] + np.einsum("nij,j->ni", T[:, :3, :3], tcp)
    J = np.empty((n, 6, robot.n_joints))
    for i in range(robot.n_joints):
        J[:, :3, i] = np.cross(Z[i], p - O[i])
        J[:, 3:, i] = Z[i]
    return p, J


def timeit(fn, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    print(f"load average: {os.getloadavg()}")
    rb = get_robot("irb6600-175-2.55")
    tcp = np.array([0.1, 0.0, 0.3])
    rng = np.random.default_rng(0)
    fk_jacobian(rb, rng.uniform(-1, 1, (10, 6)), tcp)  # compile / load cache
    for n in (1_000, 100_000, 1_000_000):
        Q = rng.uniform(-1, 1, (n, 6))
        tn = timeit(lambda Q=Q: fk_jacobian(rb, Q, tcp))
        tr = timeit(lambda Q=Q: numpy_fk_jacobian(rb, Q, tcp), repeat=1 if n > 100_000 else 3)
        T, J = fk_jacobian(rb, Q[:1000], tcp)
        p, Jr = numpy_fk_jacobian(rb, Q[:1000], tcp)
        assert np.allclose(T[:, :3, 3], p) and np.allclose(J, Jr)
        print(f"FK+Jacobian n={n:>9,d}: numba {n / tn:12,.0f} postures/s | numpy ref "
              f"{n / tr:12,.0f} postures/s | ratio {tr / tn:5.1f}x")

    spec = CampaignSpec(noise=TrackerNoise(sigma_m=5e-6))
    camp = simulate_campaign(spec)
    t = timeit(lambda: identify_joint_stiffness(camp, rb))
    print(f"identification, 6 postures x 5 steps x 3 reflectors ({camp.n_rows} rows): "
          f"{t * 1e3:.1f} ms")
    t = timeit(lambda: simulate_campaign(spec), repeat=2)
    print(f"virtual campaign generation (nonlinear equilibrium, Newton): {t * 1e3:.1f} ms")
    clean = simulate_clean(spec)
    xb = noisy_batch(clean, 1000, 1)
    t = timeit(lambda: identify_batch(camp, rb, xb), repeat=1)
    print(f"Monte-Carlo identification, 1000 noise repeats: {t:.2f} s "
          f"({1000 / t:,.0f} identifications/s)")
    post = tuple(tuple(x) for x in np.degrees(rng.uniform([-1.5, -0.5, -1.5, -2, 0.5, -2],
                                                          [1.5, 1.0, 0.5, 2, 1.8, 2], (60, 6))))
    dirs = tuple(tuple(x) for x in rng.normal(size=(60, 3)))
    big = CampaignSpec(postures_deg=post, force_directions=dirs,
                       noise=TrackerNoise(sigma_m=5e-6))
    cb = simulate_campaign(big)
    t = timeit(lambda: identify_joint_stiffness(cb, rb), repeat=2)
    print(f"identification, 60 postures x 5 steps ({cb.n_rows} rows): {t * 1e3:.1f} ms")
    acceptance_figures()
    print(f"load average: {os.getloadavg()}")


def acceptance_figures() -> None:
    """Issue-2 acceptance campaign (6 postures x 4 levels to 1 kN, lever arm, sigma 5 um):
    errors and 95 % coverage over 100 seeded repeats (the test asserts the limits)."""
    from robobore.robot.campaign import IRB6600_ASSUMED_JOINT_STIFFNESS_NM_PER_RAD as KT
    from robobore.robot.campaign import PAPER_POSTURE_DEG
    from robobore.robot.stiffness import directional_stiffness_xyz, process_frame

    spec = CampaignSpec(load_levels_N=(0.0, 1000.0 / 3, 2000.0 / 3, 1000.0),
                        noise=TrackerNoise(sigma_m=5e-6), seed=11)
    camp, clean = simulate_campaign(spec), simulate_clean(spec)
    kt = np.asarray(KT)
    out = identify_batch(camp, "irb6600-175-2.55", noisy_batch(clean, 100,
                                                               np.random.default_rng(2026)))
    err = np.abs(out["k"] / kt - 1)
    cover = ((out["ci_low"] <= kt) & (kt <= out["ci_high"])).mean(axis=0)
    rb = get_robot("irb6600-175-2.55")
    q = np.radians(PAPER_POSTURE_DEG)
    T, J = fk_jacobian(rb, q)
    g = (process_frame(T[:3, :3], "tool").T @ J[:3]) ** 2
    kd = 1.0 / (out["c"] @ g.T)
    kd_true = np.array(list(directional_stiffness_xyz(rb, q, kt).values()))
    print("acceptance campaign, 100 repeats:")
    print(f"  worst |k err| % per joint : {np.round(100 * err.max(axis=0), 2)}")
    print(f"  rms |k err| % per joint   : {np.round(100 * np.sqrt((err ** 2).mean(axis=0)), 2)}")
    kd_err = np.abs(kd / kd_true - 1).max(axis=0)
    print(f"  worst k_xx,k_yy,k_zz err %: {np.round(100 * kd_err, 2)}")
    print(f"  95 % coverage per joint   : {cover}")


if __name__ == "__main__":
    main()
