"""The cuts of benchmarks/chatter_agreement.py (same seed) through another tree's lobes, time-domain
start and verdict: run with that tree's src on PYTHONPATH."""

import sys, math, importlib.util, numpy as np, time
import pathlib
spec = importlib.util.spec_from_file_location("cc", str(pathlib.Path(__file__).resolve().parents[3] / "src/robobore/dynamics/crosscheck.py"))
cc = importlib.util.module_from_spec(spec); sys.modules["cc"] = cc; spec.loader.exec_module(cc)
from robobore.dynamics.semidiscretization import critical_depth_semidiscretization
from robobore.dynamics.timedomain import simulate, SimulationSettings, auto_samples_per_rev
from robobore.dynamics.chatter import classify
import robobore; print(robobore.__file__)
n_cuts, seed = int(sys.argv[1]), int(sys.argv[2])
rng = np.random.default_rng(seed)
agree = dis = app = 0
t0 = time.time()
for i in range(n_cuts):
    cut = cc.random_cut(rng)
    pr = cut.process()
    ac = critical_depth_semidiscretization(cut.structure, pr, cut.speed_rpm)
    if not (0 < ac < math.inf):
        continue
    app += 1
    ok = True
    base = auto_samples_per_rev(cut.structure, cut.speed_rpm, 1)
    for fac in (0.8, 1.25):
        a = fac * ac
        if a > 0.05: continue
        pa = cut.process(a)
        for s in (1, 2):
            try:
                v = classify(simulate(cut.structure, pa, SimulationSettings(cut.speed_rpm, a, samples_per_rev=base*s), cut.insert))
                ch = v.chatter
            except Exception as e:
                ch = True  # diverged at once
            if ch != (fac > 1): ok = False
    agree += ok; dis += (not ok)
print(f"before: {n_cuts} cuts seed {seed}: finite limit {app}, agree {agree}/{app}; {time.time()-t0:.1f} s")
