"""The virtual tests of the force calibration: one 2D FE orthogonal run per grid point
(:func:`run_grid`), in worker processes, each result cached.

FE results are cached (:class:`robobore.io.cache.ResultCache`, namespace ``fe-orthogonal``)
keyed by the full FE input after defaults (every setting), the package version and the
engine's :data:`robobore.cutting.fe.FE_ENGINE_REVISION`: a second calibration with the same
inputs runs no FE.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

from robobore.cutting.calibration_config import CalibrationConfig, fe_config_dict
from robobore.errors import NumericalError

FE_NAMESPACE = "fe-orthogonal"


_SUMMARY_KEYS = ("cutting_force_N_per_mm", "feed_force_N_per_mm", "cutting_force_std_N_per_mm",
                 "feed_force_std_N_per_mm", "chip_ratio", "shear_angle_deg", "energy_error",
                 "peak_temperature_K", "wall_time_s", "steps")


def run_fe_point(fe_cfg: dict[str, Any]) -> dict[str, Any]:
    """Run one virtual orthogonal test (in a worker process); returns the FE summary subset."""
    from robobore.cutting.fe.config.orthogonal import parse_config
    from robobore.cutting.fe.models.orthogonal import simulate_orthogonal

    res = simulate_orthogonal(parse_config(fe_cfg))
    s = res.to_dict()
    out: dict[str, Any] = {}
    for k in _SUMMARY_KEYS:
        v = s.get(k)
        if isinstance(v, float) and not math.isfinite(v):
            v = None
        out[k] = v
    for k in ("cutting_force_N_per_mm", "feed_force_N_per_mm"):
        if out[k] is None:
            raise NumericalError(f"FE gave no finite {k}", field=k,
                                 expected="a finite mean force")
    return out


def fe_cache_inputs(fe_cfg: dict[str, Any]) -> dict[str, Any]:
    """Cache key inputs: the full FE config after defaults (a changed default changes the
    key) and the engine's :data:`robobore.cutting.fe.FE_ENGINE_REVISION`."""
    from robobore.cutting import fe
    from robobore.cutting.fe.config.orthogonal import parse_config

    return {"fe_config": parse_config(fe_cfg).model_dump(mode="json"),
            "engine_revision": fe.FE_ENGINE_REVISION}


def _limit_numba_threads(n: int) -> None:
    """Process-pool initializer: at most ``n`` numba threads in this worker."""
    import numba

    numba.set_num_threads(max(1, min(n, numba.config.NUMBA_NUM_THREADS)))


def run_grid(cfg: CalibrationConfig, *, cache: Any | None = None, workers: int = 1,
             progress: Callable[[int], None] | None = None) -> list[dict[str, Any]]:
    """FE forces at every grid point (cached). Returns one record per point (h-major order):
    ``h_um, vc_m_per_min, Fc_N_per_m, Ff_N_per_m, cached, fe`` (the FE summary)."""
    import json

    from robobore.io.cache import ResultCache

    cache = cache if cache is not None else ResultCache()
    points = [(h, v) for h in cfg.uncut_chip_thickness_um for v in cfg.cutting_speed_m_per_min]
    cfgs = [fe_config_dict(cfg, h, v) for h, v in points]
    inputs = [fe_cache_inputs(c) for c in cfgs]
    summaries: list[dict[str, Any] | None] = []
    hits: list[bool] = []
    for inp in inputs:
        folder = cache.get(FE_NAMESPACE, inp)
        if folder is not None:
            summaries.append(json.loads((folder / "summary.json").read_text()))
            hits.append(True)
            if progress:
                progress(1)
        else:
            summaries.append(None)
            hits.append(False)
    # the thickest chips are the most expensive: start them first (better load balance)
    todo = sorted((i for i, s in enumerate(summaries) if s is None),
                  key=lambda i: -points[i][0] / points[i][1])

    def store(i: int, summ: dict[str, Any]) -> None:
        cache.put(FE_NAMESPACE, inputs[i], {"summary.json": json.dumps(summ, indent=1)})
        summaries[i] = summ
        if progress:
            progress(1)

    if todo and workers > 1 and len(todo) > 1:
        nproc = min(workers, len(todo))
        # each worker gets its share of the cores for numba's parallel loops: oversubscribed
        # numba threads slow the FE kernels 5-20x (docs/fe.md)
        threads = max(1, (os.cpu_count() or 1) // nproc)
        with ProcessPoolExecutor(max_workers=nproc, initializer=_limit_numba_threads,
                                 initargs=(threads,)) as ex:
            futs = {ex.submit(run_fe_point, cfgs[i]): i for i in todo}
            for f in as_completed(futs):
                store(futs[f], f.result())
    else:
        for i in todo:
            store(i, run_fe_point(cfgs[i]))
    out = []
    for (h, v), s, hit in zip(points, summaries, hits, strict=True):
        assert s is not None
        out.append({"h_um": h, "vc_m_per_min": v,
                    "Fc_N_per_m": s["cutting_force_N_per_mm"] * 1e3,
                    "Ff_N_per_m": s["feed_force_N_per_mm"] * 1e3, "cached": hit, "fe": s})
    return out

__all__ = ["FE_NAMESPACE", "run_fe_point", "fe_cache_inputs", "run_grid"]
