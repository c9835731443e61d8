"""``robobore paper``: the paper's whole study in one command (the project's main job).

Pipeline (:func:`run_paper`), on the bundled SYNTHETIC example data by default
(``robobore/data/paper_example/paper.toml``):

1. joint stiffness from the laser-tracker campaign (``robot.identify``) and the directional
   stiffness at the paper's posture in the boring frame (X horizontal, Y vertical, Z feed);
2. the five best-supported modes of the hammer test (``modal.identify``);
3. the equivalent model (``equivalent``: k from 1, f_n and zeta from 2, m = k / w_n^2, modes
   assigned to X, Y, Z by their direction) without and with the pressure foot;
4. the force model: the FE calibration (``cutting.calibrate``; ``fast``: the stored file of
   the example, made by the same command) and the set the boring model uses
   (``paper_config.model_coefficients``: the measured TC4 default unless ``[coefficients]
   material = "TC4-FE"`` chooses the calibration);
5. the sweep of the paper's kind of conditions (one factor at a time around the paper's
   Fig. 7 condition) for the robot at P = 0 and 0.3 MPa and for a stiff machine tool, with a
   resumable results store under ``OUT/sweep``;
6. stability lobes (robot without and with the foot) at the base feed, and the posture plan
   (:func:`robobore.plan.paper.paper_posture_plan`);
7. comparison with the (SYNTHETIC) measured CSV and the paper's qualitative checks;
8. the report (``paper_report``), ``results.nc`` and ``paper_summary.json`` in OUT.

With ``workers`` (default 2) one process pool, forked from a server that imports the runner
and the planner once, is started with the study; the posture plan, the two lobe diagrams and
the sweep's conditions are submitted to it in that order (longest first) while this process
draws the modal figures and records the results; ``workers=0`` runs everything here. The
results are the same either way.

The config file (TOML) is documented in ``docs/paper.md`` and in the bundled example; its
model and reader are :mod:`robobore.study.paper_config`, the checks of step 7
:mod:`robobore.study.paper_checks`, the SYNTHETIC measured CSV of the example
:mod:`robobore.study.paper_synthetic`.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from robobore.dynamics.config import PressureFootCfg
from robobore.errors import ConfigError
from robobore.study.paper_checks import qualitative_checks
from robobore.study.paper_config import (
    PaperConfig,
    coefficient_set,
    load_paper_config,
    model_coefficients,
)
from robobore.study.results import PaperSummary

RUNNER = "boring"
PAPER_DAMPING_N_S_PER_M = 23.7  # the paper's equivalent damping coefficient


def _resolve(base: Path, name: str | None) -> Path | None:
    if name is None:
        return None
    q = Path(name)
    return q if q.is_absolute() else base.parent / q


# ----------------------------------------------------------------------------- stages
def identify_stiffness(cfg: PaperConfig, cfg_path: Path) -> dict[str, Any]:
    """Joint stiffness from the campaign + directional stiffness at the configured posture."""
    from robobore.robot.campaign_io import read_campaign
    from robobore.robot.description import get_robot
    from robobore.robot.identify import identify_joint_stiffness
    from robobore.robot.stiffness import directional_stiffness_xyz

    robot = get_robot(cfg.robot.name)
    camp_path = _resolve(cfg_path, cfg.robot.campaign)
    synthetic = camp_path is None
    if camp_path is None:
        camp_path = Path(str(resources.files("robobore") / "data" / "campaign_irb6600"
                             / "campaign.csv"))
    camp = read_campaign(camp_path, robot=robot)
    res = identify_joint_stiffness(camp, robot)
    d = res.to_dict()
    if len(cfg.robot.posture_deg) != len(d["joint_stiffness_Nm_per_rad"]):
        raise ConfigError("posture needs one angle per joint", field="robot.posture_deg",
                          value=cfg.robot.posture_deg,
                          expected=f"{len(d['joint_stiffness_Nm_per_rad'])} angles in deg")
    k = np.asarray([math.inf if v is None else v for v in d["joint_stiffness_Nm_per_rad"]])
    q = np.radians(cfg.robot.posture_deg)
    ku = directional_stiffness_xyz(robot, q, k, frame="boring", tcp_m=cfg.robot.tcp_m)
    d.pop("residuals", None)
    return {"identification": d, "directional_stiffness_N_per_m": ku,
            "posture_deg": list(cfg.robot.posture_deg), "tcp_m": list(cfg.robot.tcp_m),
            "campaign": str(camp_path), "synthetic": synthetic, "robot": cfg.robot.name}


def identify_modes(cfg: PaperConfig, cfg_path: Path) -> dict[str, Any]:
    """The ``n_modes`` lowest well-supported modes of the hammer test (modal JSON contract), and
    under ``"analysis"`` the :class:`~robobore.modal.identify.ModalAnalysis` (not JSON: the
    report draws its stabilisation diagram and FRF fit)."""
    from robobore.modal.example import example_path
    from robobore.modal.frf import estimate_frf
    from robobore.modal.frf_data import FRFData
    from robobore.modal.identify import identify_modes as _identify
    from robobore.modal.io import load_input

    path = _resolve(cfg_path, cfg.modal.file)
    synthetic = path is None
    path = example_path() if path is None else path
    data = load_input(path, None)
    if not isinstance(data, FRFData):
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            data = estimate_frf(data).frf
    band = tuple(cfg.modal.band_Hz)
    # the equivalent model takes the lowest well-supported modes (the paper's "top orders")
    an = _identify(data, band_Hz=(float(band[0]), float(band[1])), n_modes=cfg.modal.n_modes,
                   select="lowest", max_order=cfg.modal.max_order)
    d = an.result.to_dict()
    keep = ("frequency_Hz", "damping_ratio", "mpc", "direction", "modal_mass_kg",
            "modal_stiffness_N_per_m", "cluster_size", "shape")
    modes = [{k: m[k] for k in keep if k in m} for m in d["modes"]]
    return {"modes": modes, "source": str(path), "synthetic": synthetic,
            "fit_percent": d.get("fit_percent"), "analysis": an}


def build_equivalent(stiffness: dict[str, Any], modes: dict[str, Any],
                     foot: PressureFootCfg) -> dict[str, Any]:
    """Equivalent models without / with the foot, and what the paper's c would imply."""
    from robobore.equivalent import EquivalentModel

    st = {"directional_stiffness_N_per_m": stiffness["directional_stiffness_N_per_m"]}
    md = {"modes": [{k: v for k, v in m.items() if k in ("frequency_Hz", "damping_ratio",
                                                           "direction", "mpc")}
                    for m in modes["modes"]]}
    bare = EquivalentModel.from_stiffness_and_modes(st, md)
    with_foot = EquivalentModel.from_stiffness_and_modes(st, md, foot=foot.to_foot())
    paper_c = EquivalentModel.from_stiffness_and_modes(
        st, md, damping_N_s_per_m=PAPER_DAMPING_N_S_PER_M)
    return {"without_foot": bare, "with_foot": with_foot, "paper_c": paper_c,
            "pressure_MPa": foot.pressure_MPa}


def load_or_calibrate(cfg: PaperConfig, raw: dict[str, Any], cfg_path: Path, fast: bool,
                      workers: int, progress: Callable[[int], None] | None = None
                      ) -> dict[str, Any]:
    """The coefficients file content: stored (``fast``) or freshly FE-calibrated (cached FE)."""
    from robobore.cutting.calibrate import calibrate_forces
    from robobore.cutting.calibration_config import calibration_from_mapping

    if fast:
        p = _resolve(cfg_path, cfg.coefficients.file)
        assert p is not None
        if not p.is_file():
            raise ConfigError("stored coefficients file not found", file=str(cfg_path),
                              field="coefficients.file", value=str(p),
                              expected="a JSON file written by 'robobore calibrate forces'")
        from robobore.cutting.coefficient_files import read_coefficients_file

        data = read_coefficients_file(p)  # clear errors for a corrupt file; ranges checked
        from robobore.io.identity import check_insert, check_material, cut_identity_of

        ident = cut_identity_of(data, str(p))  # made for this config's material and insert?
        check_material(ident, str(p), cfg.material.name, f"[material] name of {cfg_path}")
        check_insert(ident, str(p), cfg.insert, f"[insert] of {cfg_path}")
        data["file"] = str(p)
        data["mode"] = "stored (--fast)"
        return data
    ccfg = calibration_from_mapping(
        {"calibration": raw.get("calibration", {}), "insert": raw.get("insert", {}),
         "material": raw.get("material", {})}, source=str(cfg_path))
    data = calibrate_forces(ccfg, workers=workers, progress=progress)
    data["mode"] = "FE calibration (cached FE results reused)"
    return data


def dynamics_model(cfg: PaperConfig, eq: Any, coeffs: dict[str, Any],
                   system: str) -> dict[str, Any]:
    """The ``[model]`` of the boring runner for the robot (equivalent, no foot; the foot is
    set per condition) or the machine tool."""
    dyn: dict[str, Any] = {
        "insert": cfg.insert.model_dump(), "bore": cfg.bore.model_dump(),
        # the measured TC4 default, or the calibration ("TC4-FE") inline
        "coefficients": model_coefficients(cfg, coeffs),
        "simulation": {"revolutions": cfg.study.revolutions,
                       "ra_tolerance_um": cfg.study.ra_tolerance_um},
    }
    if system == "robot":
        m = eq["without_foot"]
        dyn["equivalent"] = {
            "stiffness_N_per_m": dict(m.stiffness_N_per_m),
            "frequency_Hz": dict(m.frequency_Hz), "damping_ratio": dict(m.damping_ratio),
            "pressure_foot": cfg.pressure_foot.model_dump(),
            "note": "identified from the example campaign and hammer test",
        }
    else:
        mt = cfg.machine_tool
        dirs = {"x": [1.0, 0.0, 0.0], "y": [0.0, 1.0, 0.0], "z": [0.0, 0.0, 1.0]}
        dyn["structure"] = {"modes": [
            {"frequency_Hz": getattr(mt.frequency_Hz, a),
             "damping_ratio": getattr(mt.damping_ratio, a),
             "stiffness_N_per_m": getattr(mt.stiffness_N_per_m, a), "direction": dirs[a]}
            for a in "xyz"]}
    return {"system": system, "dynamics": dyn}


def study_conditions(cfg: PaperConfig) -> list[dict[str, Any]]:
    """Conditions (human units) of the study: OFAT around ``study.base`` or the full grid,
    per foot pressure (robot). Ordered, without duplicates."""
    import itertools

    s = cfg.study
    names = ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm")
    combos: list[tuple[float, ...]] = []
    if s.design == "grid":
        combos = list(itertools.product(*(getattr(s, n) for n in names)))
    else:
        for vary in names:
            for v in getattr(s, vary):
                c = {n: float(s.base[n]) for n in names}
                c[vary] = float(v)
                combos.append(tuple(c[n] for n in names))
    out, seen = [], set()
    for p in s.pressure_MPa:
        for combo in combos:
            t = (*combo, float(p))
            if t in seen:
                continue
            seen.add(t)
            out.append({**dict(zip(names, combo, strict=True)), "pressure_MPa": float(p),
                        "posture": "paper"})
    return out


def build_plan(cfg: PaperConfig, robot_model: dict[str, Any],
               mt_model: dict[str, Any] | None) -> tuple[Any, list[dict[str, Any]]]:
    """One sweep plan holding the robot and machine-tool conditions (distinct keys)."""
    from robobore.study.conditions import Condition, condition_key, condition_seed
    from robobore.study.sweep import SweepItem, SweepPlan

    posture = {"joints_deg": list(cfg.robot.posture_deg)}
    opts = {"samples_per_rev_stored": cfg.study.samples_per_rev_stored}
    items, meta = [], []
    conds = study_conditions(cfg)
    runs = [("robot", robot_model, c) for c in conds]
    if mt_model is not None:
        runs += [("machine_tool", mt_model, c) for c in conds if c["pressure_MPa"] == 0.0]
    for system, model, c in runs:
        cond = Condition.from_dict(c)
        key = condition_key(cond, RUNNER, model, posture)
        ctx = {"model": model, "runner_options": {**opts, "system": system},
               "postures": {"paper": posture},
               "posture": posture, "seed": condition_seed(0, key), "key": key,
               "sweep": cfg.study.name}
        items.append(SweepItem(key=key, condition=cond.to_dict(), context=ctx))
        meta.append({"key": key, "system": system, **cond.to_dict()})
    plan = SweepPlan(name=cfg.study.name, runner=RUNNER, items=tuple(items),
                     config={"sweep": {"name": cfg.study.name, "runner": RUNNER},
                             "model": {"robot": robot_model, "machine_tool": mt_model},
                             "postures": {"paper": posture}})
    return plan, meta


def lobe_cases(cfg: PaperConfig) -> list[tuple[str, float]]:
    """The (label, foot pressure [MPa]) of the study's two lobe diagrams: without and with
    the foot."""
    return [("P = 0", 0.0), (f"P = {cfg.pressure_foot.pressure_MPa:g} MPa",
                             cfg.pressure_foot.pressure_MPa)]


def lobes_at_pressure(cfg: PaperConfig, robot_model: dict[str, Any],
                      pressure_MPa: float) -> dict[str, Any]:
    """The stability lobes of the robot at one foot pressure (0: no foot) at the base feed,
    as lists (one entry of :func:`compute_lobes`)."""
    from robobore.dynamics.api import lobes

    dyn = json.loads(json.dumps(robot_model["dynamics"]))
    if pressure_MPa == 0.0:
        dyn["equivalent"].pop("pressure_foot", None)
    dyn["cutting"] = {"speed_rpm": float(cfg.study.base["speed_rpm"]),
                      "feed_mm_per_rev": float(cfg.study.base["feed_mm_per_rev"]),
                      "depth_mm": float(cfg.study.base["depth_of_cut_mm"])}
    dyn["speed_rpm"] = {"min": cfg.lobes.speed_min_rpm, "max": cfg.lobes.speed_max_rpm,
                        "count": cfg.lobes.count}
    d = lobes(dyn, method=cfg.lobes.method).to_dict()
    return {k: (np.asarray(v).tolist() if isinstance(v, np.ndarray) else v)
            for k, v in d.items()}


def compute_lobes(cfg: PaperConfig, robot_model: dict[str, Any]) -> dict[str, Any]:
    """Stability lobes (robot without / with the foot) at the base feed, by label."""
    return {label: lobes_at_pressure(cfg, robot_model, p) for label, p in lobe_cases(cfg)}


#: Rule of the lobes-vs-verdicts check: a condition more than this fraction above the
#: semi-discretisation limit must chatter, more than this fraction below it must not, unless
#: its verdict states the tool leaving the cut (nonlinear).
LOBE_MARGIN = 0.10


def lobe_consistency(cfg: PaperConfig, robot_model: dict[str, Any],
                     rows: list[dict[str, Any]],
                     lobes: dict[str, Any] | None = None) -> dict[str, Any]:
    """The swept robot conditions at the base feed against the semi-discretisation limit at
    their own speed and foot pressure (the lobes of :func:`compute_lobes`, evaluated at the
    condition's speed): each is ``"above"`` (depth > (1 + LOBE_MARGIN) x limit), ``"below"``
    (< (1 - LOBE_MARGIN) x limit) or ``"near"``, and consistent when above means chatter and
    below means no chatter, or its verdict states the tool leaving the cut. Returns the
    counts and one record per condition; ``inconsistent`` lists the conditions that break
    the rule. ``lobes`` (:func:`compute_lobes`): each limit is continued from the lobes'
    limit interpolated at the condition's speed, as the lobes themselves are computed,
    instead of a fresh depth scan."""
    from robobore.dynamics.api import critical_depth_at

    base_f = float(cfg.study.base["feed_mm_per_rev"])
    cache: dict[tuple[float, float], float] = {}
    records = []
    for r in rows:
        s = r.get("summary")
        if r["system"] != "robot" or not s or not math.isclose(r["feed_mm_per_rev"], base_f):
            continue
        n, p = float(r["speed_rpm"]), float(r["pressure_MPa"])
        if (n, p) not in cache:
            dyn = json.loads(json.dumps(robot_model["dynamics"]))
            if p == 0.0:
                dyn["equivalent"].pop("pressure_foot", None)
            else:
                dyn["equivalent"]["pressure_foot"] = {
                    **(dyn["equivalent"].get("pressure_foot") or {}), "pressure_MPa": p}
            dyn["cutting"] = {"speed_rpm": n, "feed_mm_per_rev": base_f,
                              "depth_mm": float(cfg.study.base["depth_of_cut_mm"])}
            v = critical_depth_at(dyn, n,
                                  guess_mm=_lobe_guess_mm(lobes, p, n)).critical_depth_mm
            cache[(n, p)] = math.inf if v is None else float(v)
        lim = cache[(n, p)]
        a = float(r["depth_of_cut_mm"])
        side = ("above" if a > (1 + LOBE_MARGIN) * lim else
                "below" if a < (1 - LOBE_MARGIN) * lim else "near")
        ch = s.get("chatter")
        leaves = bool(s.get("tool_leaves_cut"))
        ok = (side == "near" or leaves or (side == "above" and ch is True)
              or (side == "below" and ch is False))
        records.append({"key": r["key"], "speed_rpm": n, "pressure_MPa": p, "depth_mm": a,
                        "critical_depth_mm": None if not math.isfinite(lim) else lim,
                        "side": side, "chatter": ch, "tool_leaves_cut": leaves,
                        "consistent": bool(ok)})
    bad = [x for x in records if not x["consistent"]]
    return {"rule": f"above (1 + {LOBE_MARGIN:g}) x the semi-discretisation limit: chatter; "
                    f"below (1 - {LOBE_MARGIN:g}) x: no chatter; unless the tool leaves the cut",
            "checked": len(records), "consistent": len(records) - len(bad),
            "nonlinear": sum(1 for x in records if x["tool_leaves_cut"]),
            "inconsistent": bad, "conditions": records}


def _lobe_guess_mm(lobes: dict[str, Any] | None, pressure_MPa: float,
                   speed_rpm: float) -> float | None:
    """The limit of :func:`compute_lobes`' lobes at ``pressure_MPa`` interpolated at
    ``speed_rpm`` (finite positive limits only; None outside their speeds or without)."""
    if not lobes:
        return None
    label = "P = 0" if pressure_MPa == 0.0 else f"P = {pressure_MPa:g} MPa"
    L = lobes.get(label)
    if not L:
        return None
    sp = np.asarray(L.get("speed_rpm", []), float)
    a = np.asarray([math.nan if v is None else v for v in L.get("critical_depth_mm", [])],
                   float)
    ok = np.isfinite(a) & (a > 0.0)
    if sp.size != a.size or ok.sum() < 2 or not sp[ok].min() <= speed_rpm <= sp[ok].max():
        return None
    return float(np.interp(speed_rpm, sp[ok], a[ok]))


# ----------------------------------------------------------------------------- outputs
def results_dataset(rows: list[dict[str, Any]]) -> Any:
    """All conditions and their summaries as one Dataset (dimension ``condition``)."""
    import xarray as xr

    n = len(rows)
    def col(f, dtype=float):  # noqa: E306
        return np.array([f(r) for r in rows], dtype=dtype)

    def sv(name: str) -> np.ndarray:
        return col(lambda r: (r.get("summary") or {}).get(name, math.nan))

    ds = xr.Dataset({
        "speed_rpm": ("condition", col(lambda r: r["speed_rpm"])),
        "feed_mm_per_rev": ("condition", col(lambda r: r["feed_mm_per_rev"])),
        "depth_of_cut_mm": ("condition", col(lambda r: r["depth_of_cut_mm"])),
        "pressure_MPa": ("condition", col(lambda r: r["pressure_MPa"])),
        "system": ("condition", np.array([r["system"] for r in rows], dtype=object)),
        "key": ("condition", np.array([r["key"] for r in rows], dtype=object)),
        "force_amplitude_x_N": ("condition", sv("force_amplitude_x_N")),
        "force_amplitude_y_N": ("condition", sv("force_amplitude_y_N")),
        "force_amplitude_z_N": ("condition", sv("force_amplitude_z_N")),
        "feed_amplitude_um": ("condition", sv("feed_amplitude_um")),
        "stable": ("condition", col(lambda r: {True: 1, False: 0}.get(
            (r.get("summary") or {}).get("stable"), -1), np.int8)),
        "done": ("condition", col(lambda r: 1 if r.get("summary") else 0, np.int8)),
        **{name: ("condition", col(lambda r, name=name: {True: 1, False: 0}.get(
            (r.get("summary") or {}).get(name), -1), np.int8))
           for name in ("chatter", "surface_finish_ok", "tool_leaves_cut")},
        "roughness_Ra_um": ("condition", sv("roughness_Ra_um")),
        "feed_amplitude_growth": ("condition", sv("feed_amplitude_growth")),
    }, coords={"condition": np.arange(n)})
    ds["stable"].attrs["meaning"] = ("the paper's criterion (Ra after form removal within the "
                                     "tolerance): 1 stable, 0 vibratory, -1 not computed")
    ds["chatter"].attrs["meaning"] = "1 the vibration grows (chatter), 0 not, -1 not computed"
    ds["surface_finish_ok"].attrs["meaning"] = ("1 Ra (form removed) within the tolerance, "
                                                "0 above, -1 not computed")
    ds["tool_leaves_cut"].attrs["meaning"] = "1 an insert leaves the cut, 0 not, -1 unknown"
    ds["roughness_Ra_um"].attrs.update(units="um", long_name="Ra after form removal")
    ds["feed_amplitude_growth"].attrs["long_name"] = (
        "last / first revolution amplitude of the feed-direction regenerative displacement")
    for q, u in (("force_amplitude_x_N", "N"), ("feed_amplitude_um", "um")):
        ds[q].attrs["units"] = u
    return ds


def _stage(progress: Callable[[str, int, int], None] | None, task: str,
           total: int) -> Callable[[int], None]:
    """``advance(n)`` of one stage, reported as ``progress(task, done, total)`` (done 0 now)."""
    done = [0]

    def advance(n: int) -> None:
        done[0] += n
        if progress is not None:
            progress(task, done[0], total)

    advance(0)
    return advance


def _pool_ready() -> bool:
    """A task the study pool runs first on each worker: it starts the workers (forked from
    the server that has imported the runner and the planner) while this process identifies
    the robot."""
    return True


class _StudyPool:
    """The study's ``workers`` processes, forked from one forkserver that imports the boring
    runner's modules and the posture planner once (:func:`robobore.study.sweep.pool_preload`);
    started at the beginning of the study so that the imports overlap the identification.
    The posture plan, the two lobe diagrams and the sweep's conditions are submitted to it in
    that order (longest first); results do not depend on which worker computes what."""

    def __init__(self, workers: int) -> None:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        from robobore.study.runners import boring_runner
        from robobore.study.sweep import pool_preload

        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload([*pool_preload(boring_runner), "robobore.plan.paper",
                                    "robobore.dynamics.api", __name__])
        self.ex = ProcessPoolExecutor(max_workers=workers, mp_context=ctx)
        for _ in range(workers):
            self.ex.submit(_pool_ready)

    def submit(self, fn: Callable[..., Any], *args: Any) -> Any:
        return self.ex.submit(fn, *args)

    def close(self) -> None:
        self.ex.shutdown(wait=True, cancel_futures=True)


class _PosturePlan:
    """:func:`robobore.plan.paper.paper_posture_plan` of the study, computed on a worker of
    the study pool (``pool``; ``parallel=True`` without one: a pool of its own) or in this
    process; the same result either way (a pool that breaks falls back to this process)."""

    def __init__(self, cfg: PaperConfig, cfg_path: Path, stiff: dict[str, Any],
                 modes: dict[str, Any], coeffs: dict[str, Any], parallel: bool,
                 pool: _StudyPool | None = None) -> None:
        from robobore.plan.paper import paper_posture_plan

        self.args = (cfg, cfg_path, stiff, modes, coeffs, model_coefficients(cfg, coeffs))
        self.own = None
        self.fut = None
        #: where the plan was computed: "side process", "this process", or a warning that
        #: the side process died and the plan was computed again here
        self.computed_in = ""
        if parallel and pool is None:
            pool = self.own = _StudyPool(1)
        if pool is not None:
            self.fut = pool.submit(paper_posture_plan, *self.args)

    def result(self) -> dict[str, Any]:
        from concurrent.futures.process import BrokenProcessPool

        from robobore.plan.paper import paper_posture_plan

        if self.fut is not None:
            try:
                plan = self.fut.result()
                self.computed_in = "side process"
                return plan
            except BrokenProcessPool as exc:
                self.computed_in = (f"posture plan: its side process died ({exc}); computed "
                                    "again in the study's process")
            finally:
                if self.own is not None:
                    self.own.close()
        else:
            self.computed_in = "this process"
        return paper_posture_plan(*self.args)


def _lobes_result(cfg: PaperConfig, robot_model: dict[str, Any],
                  futures: list[tuple[str, float, Any]]) -> dict[str, Any]:
    """The lobe diagrams submitted to the study pool (computed here if the pool broke)."""
    from concurrent.futures.process import BrokenProcessPool

    out = {}
    for label, p, fut in futures:
        try:
            out[label] = fut.result()
        except BrokenProcessPool:
            out[label] = lobes_at_pressure(cfg, robot_model, p)
    return out


def run_paper(config: str | Path | None = None, out: str | Path = "paper-results", *,
              fast: bool = False, workers: int | None = None,
              progress: Callable[[str, int, int], None] | None = None,
              browser_check: bool = False) -> PaperSummary:
    """Run the whole study (see module doc); returns the :class:`PaperSummary` (its
    ``to_dict()`` is ``paper_summary.json``, also written).

    ``progress(task, done, total)``, if given, is called as each stage advances; the stages
    in order: "identify robot and modes", "FE force calibration" (not with ``fast``),
    "sweep <name>" (:func:`robobore.study.sweep.run_sweep`), "lobes, comparison, report".
    """
    from robobore.study.compare import read_measured_csv

    t0 = time.perf_counter()
    cfg, raw, cfg_path = load_paper_config(config)
    outdir = Path(out)
    outdir.mkdir(parents=True, exist_ok=True)
    if cfg.measured.file is not None:  # a bad measured file stops the study before it runs
        read_measured_csv(_resolve(cfg_path, cfg.measured.file))
    nw = workers if workers is not None else 2
    timings: dict[str, float] = {}
    pool = _StudyPool(nw) if nw > 0 else None  # its workers start while the robot is identified
    try:
        return _run_stages(cfg, raw, cfg_path, outdir, fast=fast, nw=nw, pool=pool,
                           progress=progress, browser_check=browser_check, timings=timings,
                           t0=t0)
    finally:
        if pool is not None:
            pool.close()


def _run_stages(cfg: PaperConfig, raw: dict[str, Any], cfg_path: Path, outdir: Path, *,
                fast: bool, nw: int, pool: _StudyPool | None,
                progress: Callable[[str, int, int], None] | None, browser_check: bool,
                timings: dict[str, float], t0: float) -> PaperSummary:
    """The stages of :func:`run_paper` after the config is read (``pool``: the study pool,
    None for a serial run)."""
    from robobore import __version__
    from robobore.io.results import write_json, write_netcdf
    from robobore.study.compare import compare, read_measured_csv
    from robobore.study.paper_report import build_report, modal_figure_pngs
    from robobore.study.store import ResultsStore
    from robobore.study.sweep import run_sweep

    def lap(name: str, t: float) -> None:
        timings[name] = time.perf_counter() - t

    advance = _stage(progress, "identify robot and modes", 2)
    t = time.perf_counter()
    stiff = identify_stiffness(cfg, cfg_path)
    lap("stiffness", t)
    advance(1)
    t = time.perf_counter()
    modes = identify_modes(cfg, cfg_path)
    lap("modes", t)
    advance(1)
    t = time.perf_counter()
    eq = build_equivalent(stiff, modes, cfg.pressure_foot)
    lap("equivalent", t)
    t = time.perf_counter()
    n_fe = (len(cfg.calibration.get("uncut_chip_thickness_um", []))
            * len(cfg.calibration.get("cutting_speed_m_per_min", [])))
    advance = None if fast else _stage(progress, "FE force calibration", n_fe)
    coeffs = load_or_calibrate(cfg, raw, cfg_path, fast, max(nw, 1), progress=advance)
    lap("force_calibration", t)
    cset = coefficient_set(cfg, coeffs, coeffs.get("mode"))
    write_json(outdir / "coefficients.json", {k: v for k, v in coeffs.items()
                                              if k not in ("file",)})
    robot_model = dynamics_model(cfg, eq, coeffs, "robot")
    mt_model = dynamics_model(cfg, eq, coeffs, "machine_tool") if cfg.study.machine_tool \
        else None
    plan, meta = build_plan(cfg, robot_model, mt_model)
    # the posture plan and the lobes need only the identification and the force set: they go
    # to the study pool first (the longest tasks first), the sweep's conditions after them
    posture = _PosturePlan(cfg, cfg_path, stiff, modes, coeffs, parallel=False, pool=pool)
    lobe_futures = ([(label, p, pool.submit(lobes_at_pressure, cfg, robot_model, p))
                     for label, p in lobe_cases(cfg)] if pool is not None else [])
    an = modes.get("analysis")
    modal_pngs = None if an is None or pool is None else modal_figure_pngs(an)
    t = time.perf_counter()
    store = ResultsStore(outdir / "sweep")
    from dataclasses import replace as _replace

    plan = _replace(plan, source=str(cfg_path))  # per-condition errors name the config file
    # a process pool forked from one server that imports the runner once: on 2 cores it
    # takes about half the CPU time of a Dask local cluster for the same results
    outcome = run_sweep(plan, store, workers=nw, processes=nw > 0, progress=progress,
                        pool="processes", executor=None if pool is None else pool.ex)
    lap("sweep", t)
    rows = []
    for m in meta:
        r = dict(m)
        if store.is_done(m["key"]):
            r["summary"] = store.read_record(m["key"]).summary
        else:
            r["summary"] = None
            f = store.failure(m["key"]) or {}
            r["error"] = f.get("error", "not computed")
        rows.append(r)
    advance = _stage(progress, "lobes, comparison, report", 3)
    t = time.perf_counter()
    lob = (_lobes_result(cfg, robot_model, lobe_futures) if lobe_futures
           else compute_lobes(cfg, robot_model))
    from robobore.study.paper_calibration import paper_calibration

    calib = paper_calibration(cfg, cfg_path, robot_model, outdir)  # None without observations
    lap("lobes", t)
    advance(1)
    t = time.perf_counter()
    cmp = None
    mpath = _resolve(cfg_path, cfg.measured.file)
    if mpath is not None:
        table = read_measured_csv(mpath)
        sims = [({k: r[k] for k in ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm",
                                    "pressure_MPa", "posture")}, r["summary"])
                for r in rows if r["system"] == "robot" and r["summary"]]
        cmp = compare(table, sims)
    checks = qualitative_checks(rows, cfg)
    consistency = lobe_consistency(cfg, robot_model, rows, lob)
    lap("comparison", t)
    advance(1)
    t = time.perf_counter()
    ds = results_dataset(rows)
    write_netcdf(ds, outdir / "results.nc", config=raw)
    eq_json = {k: (v.to_dict() if hasattr(v, "to_dict") else v) for k, v in eq.items()}
    write_json(outdir / "equivalent_model.json", eq_json)
    summary_posture = posture.result()
    done = [r for r in rows if r["summary"]]
    n_stable = sum(1 for r in done if r["summary"].get("stable") is True)
    n_vib = sum(1 for r in done if r["summary"].get("stable") is False)
    summary: dict[str, Any] = {
        "report": str(outdir / "report.html"),
        "conditions": len(rows), "computed": len(done),
        "failed": [{"key": r["key"], "system": r["system"],
                    "condition": {k: r[k] for k in ("speed_rpm", "feed_mm_per_rev",
                                                    "depth_of_cut_mm", "pressure_MPa")},
                    "error": r.get("error")} for r in rows if not r["summary"]],
        "stable": n_stable, "vibratory": n_vib,
        "stable_vibratory_by": "the paper's criterion (Ra > tolerance)",
        "chatter": sum(1 for r in done if r["summary"].get("chatter") is True),
        "rough": sum(1 for r in done if r["summary"].get("surface_finish_ok") is False),
        "tool_leaves_cut": sum(1 for r in done
                               if r["summary"].get("tool_leaves_cut") is True),
        "fast": fast, "workers": nw, "synthetic_inputs": True,
        "config": str(cfg_path), "out": str(outdir),
        "sweep": outcome.to_dict(),
        "directional_stiffness_N_per_m": stiff["directional_stiffness_N_per_m"],
        "modes_Hz": [m["frequency_Hz"] for m in modes["modes"]],
        "equivalent_model": {"without_foot": eq["without_foot"].table(),
                             "with_foot": eq["with_foot"].table()},
        "coefficients": cset["coefficients"], "coefficient_set": cset,
        "warnings": cset["warnings"] + [w for w in outcome.warnings
                                        if w.startswith("coefficients")]
        + ([posture.computed_in] if posture.computed_in.startswith("posture plan") else []),
        "coefficients_mode": coeffs.get("mode"),
        "comparison": None if cmp is None else {"groups": cmp.groups,
                                                "agreement": cmp.agreement},
        "qualitative_checks": checks,
        "lobe_consistency": consistency,
        "robobore_version": __version__,
        "posture_plan": summary_posture,
        "calibration": calib,
    }
    rep = build_report(cfg, cfg_path, stiff=stiff, modes=modes, eq=eq, coeffs=coeffs,
                       rows=rows, store=store, lobes=lob, cmp=cmp, checks=checks,
                       summary=summary, modal_pngs=modal_pngs)
    rep.write(outdir / "report.html")
    lap("report", t)
    if browser_check:
        from robobore.study.browser import check_html_in_browser

        chk = check_html_in_browser(outdir / "report.html")
        summary["browser_check"] = {"ok": chk.ok}
    timings["total"] = time.perf_counter() - t0
    summary["timings_s"] = timings
    summary["wall_time_s"] = timings["total"]
    result = PaperSummary(**{k: tuple(v) if isinstance(v, list) else v
                             for k, v in summary.items()})
    write_json(outdir / "paper_summary.json", result.to_dict())
    advance(1)
    return result


__all__ = ["run_paper", "identify_stiffness", "identify_modes", "build_equivalent",
           "load_or_calibrate", "dynamics_model", "study_conditions", "build_plan",
           "compute_lobes", "lobe_consistency", "LOBE_MARGIN", "results_dataset", "RUNNER",
           "PAPER_DAMPING_N_S_PER_M"]
