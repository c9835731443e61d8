"""``robobore paper`` (the main job), the boring runner and the paper report.

The full study (54 conditions) is measured by ``benchmarks/bench_paper.py``; here the
pipeline runs with ``--fast`` on a reduced one-factor-at-a-time set (2 levels per factor)
so that the test stays within the suite's budget.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from robobore.errors import ConfigError
from robobore.study import paper as pp
from robobore.study import paper_config as pc
from robobore.study import paper_synthetic
from robobore.study.paper_checks import qualitative_checks
from robobore.study.runners import boring_runner
from robobore.study.summary import summarise

EX = pc.example_dir()


def _small_config(tmp_path: Path, extra: str = "", drop: tuple[str, ...] = ()) -> Path:
    """The bundled example with 2 levels per factor, absolute data paths, fewer lobes."""
    text = (EX / "paper.toml").read_text()
    lines = []
    for ln in text.splitlines():
        key = ln.split("=")[0].strip()
        if key == "speed_rpm" and ln.startswith("speed_rpm = ["):
            ln = "speed_rpm = [300.0, 800.0]"
        elif key == "feed_mm_per_rev" and ln.startswith("feed_mm_per_rev = ["):
            ln = "feed_mm_per_rev = [0.15, 0.3]"
        elif key == "depth_of_cut_mm" and ln.startswith("depth_of_cut_mm = ["):
            ln = "depth_of_cut_mm = [0.05, 0.2]"
        elif key == "revolutions":
            ln = "revolutions = 40"
        elif key == "count":
            ln = "count = 40"
        elif key == "file" and "tc4_fe" in ln:
            ln = f'file = "{EX / "tc4_fe_coefficients.json"}"'
        elif key == "file" and "measured" in ln:
            ln = f'file = "{EX / "measured_synthetic.csv"}"'
        if key in drop:
            continue
        lines.append(ln)
    p = tmp_path / "paper_small.toml"
    p.write_text("\n".join(lines) + "\n" + extra)
    return p


def _dyn_model(coeffs: dict, system: str = "machine_tool", k: float = 1e10) -> dict:
    cfg, _, _ = pc.load_paper_config()
    dyn = {"insert": cfg.insert.model_dump(), "bore": cfg.bore.model_dump(),
           "coefficients": coeffs, "simulation": {"revolutions": 30}}
    dirs = {"x": [1.0, 0, 0], "y": [0, 1.0, 0], "z": [0, 0, 1.0]}
    dyn["structure"] = {"modes": [{"frequency_Hz": 400.0, "damping_ratio": 0.05,
                                   "stiffness_N_per_m": k, "direction": dirs[a]}
                                  for a in "xyz"]}
    return {"system": system, "dynamics": dyn}


def test_boring_runner_uses_the_coefficients():
    """The FE-calibrated coefficients are USED: on a (practically) rigid structure the runner's
    force amplitudes equal the static mechanistic forces of ``cutting.forces.boring_forces``
    with the same coefficients (within 1 %, the time-domain sampling of the max/min), and
    doubling every coefficient doubles them (within 1 %)."""
    from robobore.cutting.coefficient_files import load_coefficients
    from robobore.cutting.forces import boring_forces

    stored = json.loads((EX / "tc4_fe_coefficients.json").read_text())["coefficients"]
    cond = {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.1,
            "pressure_MPa": 0.0, "posture": "paper"}
    ds = boring_runner(cond, {"model": _dyn_model(stored)})
    s = summarise(ds)
    cfg, _, _ = pc.load_paper_config()
    ref = boring_forces(cfg.insert.to_insert(), 0.1e-3, 0.15e-3,
                        load_coefficients(EX / "tc4_fe_coefficients.json"))
    for i, ax in enumerate("xy"):
        assert s[f"force_amplitude_{ax}_N"] == pytest.approx(ref["amplitude_N"][i], rel=0.01)
    # no Ra tolerance in this model: the paper's criterion is not judged (absent), no chatter
    assert "stable" not in s and s["chatter"] is False
    assert "FE-calibrated" in ds.attrs["coefficients_provenance"]
    doubled = {k: (2 * v if k.startswith("K") else v) for k, v in stored.items()}
    s2 = summarise(boring_runner(cond, {"model": _dyn_model(doubled)}))
    assert s2["force_amplitude_x_N"] == pytest.approx(2 * s["force_amplitude_x_N"], rel=0.01)


def test_boring_runner_dataset_contract():
    """Summary contract as 0-d variables, decimated float32 histories, classification attrs."""
    stored = json.loads((EX / "tc4_fe_coefficients.json").read_text())["coefficients"]
    cond = {"speed_rpm": 600.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
            "pressure_MPa": 0.0, "posture": "paper"}
    ds = boring_runner(cond, {"model": _dyn_model(stored, k=5e7),
                              "runner_options": {"samples_per_rev_stored": 50}})
    for q in ("force_amplitude_x_N", "force_amplitude_y_N", "force_amplitude_z_N",
              "feed_amplitude_um", "chatter"):
        assert ds[q].ndim == 0
    # no Ra tolerance and no chatter: the paper's criterion is not judged, so not stored
    assert "stable" not in ds and int(ds["chatter"]) == 0
    tol = _dyn_model(stored, k=5e7)
    tol["dynamics"]["simulation"]["ra_tolerance_um"] = 1.6
    ds2 = boring_runner(cond, {"model": tol})
    assert ds2["stable"].ndim == 0 and int(ds2["stable"]) in (0, 1)
    assert ds["force"].dtype == np.float32
    assert ds.sizes["time"] <= 30 * 60 + 1
    assert ds.sizes["revolution"] == 30
    assert ds.attrs["system"] == "machine_tool"


def test_boring_runner_bad_model():
    cond = {"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
            "pressure_MPa": 0.3, "posture": "paper"}
    with pytest.raises(ConfigError, match="pressure foot applies to the robot only"):
        boring_runner(cond, {"model": _dyn_model({"material": "TC4"})})
    with pytest.raises(ConfigError, match="model.system"):
        boring_runner(cond, {"model": {"system": "lathe", "dynamics": {}}})


def test_boring_runner_is_registered():
    from robobore.study.sweep import resolve_runner

    assert resolve_runner("boring") is boring_runner


def test_study_conditions_of_the_example():
    """OFAT around the base: 7 speeds + 7 feeds + 6 depths - 2 repeats of the base = 18 per
    pressure (the levels of docs/study.md), 36 for the robot."""
    cfg, _, _ = pc.load_paper_config()
    conds = pp.study_conditions(cfg)
    assert len(conds) == 36
    assert {c["pressure_MPa"] for c in conds} == {0.0, 0.3}
    assert len({(c["speed_rpm"], c["feed_mm_per_rev"], c["depth_of_cut_mm"],
                 c["pressure_MPa"]) for c in conds}) == 36


def test_paper_coefficient_set_is_the_measured_default_unless_chosen():
    """The bundled config runs the boring model on the measured TC4 default; [coefficients]
    material = "TC4-FE" chooses the stored calibration inline, with its own domain."""
    cfg, raw, path = pc.load_paper_config()
    fe = pp.load_or_calibrate(cfg, raw, path, True, 1)
    assert pc.model_coefficients(cfg, fe) == {"material": "TC4"}
    assert pp.dynamics_model(cfg, pp.build_equivalent(
        pp.identify_stiffness(cfg, path), pp.identify_modes(cfg, path), cfg.pressure_foot),
        fe, "machine_tool")["dynamics"]["coefficients"] == {"material": "TC4"}
    cs = pc.coefficient_set(cfg, fe)
    assert cs["name"] == "TC4" and cs["domain"]["cutting_speed_m_per_min"] == [5.0, 30.0]
    # 200 r/min on the 40 mm bore is 25.1 m/min: inside, not warned; 300 r/min is not
    assert not any(w.startswith("coefficient set TC4 at 200 r/min") for w in cs["warnings"])
    assert cs["warnings"][0].startswith("coefficient set TC4 at 300 r/min (the base")
    cfg.coefficients.material = "TC4-FE"
    inline = pc.model_coefficients(cfg, fe)
    assert inline["Ktc_N_per_m2"] == fe["coefficients"]["Ktc_N_per_m2"]
    assert inline["grid"]["cutting_speed_m_per_min"] == [37.7]
    cs = pc.coefficient_set(cfg, fe)
    assert cs["name"] == "TC4-FE"
    assert cs["domain"] == {"cutting_speed_m_per_min": [37.7, 37.7],
                            "uncut_chip_thickness_um": [60.0, 90.0]}
    assert not any("at 300 r/min" in w for w in cs["warnings"])  # 37.699 m/min: calibrated
    assert any("at 200 r/min" in w for w in cs["warnings"])


def test_paper_coefficient_set_name_is_checked(tmp_path):
    p = _small_config(tmp_path)
    p.write_text(p.read_text().replace('material = "TC4"\nfile', 'material = "FE"\nfile'))
    with pytest.raises(ConfigError) as ei:
        pc.load_paper_config(p)
    assert "coefficients.material" in str(ei.value) and "TC4-FE" in str(ei.value)


def test_bad_paper_config(tmp_path):
    p = _small_config(tmp_path, extra="\n[unknown]\nx = 1\n")
    with pytest.raises(ConfigError) as e:
        pc.load_paper_config(p)
    assert "unknown" in str(e.value)
    p2 = tmp_path / "b.toml"
    p2.write_text((EX / "paper.toml").read_text().replace("diameter_mm = 40.0",
                                                          "diameter_mm = -4.0"))
    with pytest.raises(ConfigError) as e:
        pc.load_paper_config(p2)
    assert "bore.diameter_mm" in str(e.value)


def _rows(depth_amp, feed_amp, foot_factor):
    """Synthetic result rows for the checks: the base is n=300, f=0.15, ap=0.05."""
    rows = []
    for p, fac in ((0.0, 1.0), (0.3, foot_factor)):
        for ap, a in zip((0.05, 0.1, 0.2, 0.3), depth_amp, strict=True):
            rows.append({"system": "robot", "pressure_MPa": p, "speed_rpm": 300.0,
                         "feed_mm_per_rev": 0.15, "depth_of_cut_mm": ap, "key": f"d{ap}{p}",
                         "summary": {"feed_amplitude_um": a * fac, "force_amplitude_x_N":
                                     10 * a * fac, "stable": a < 1.0,
                                     "chatter": a >= 2.0}})
        for f, a in zip((0.1, 0.2, 0.3), feed_amp, strict=True):
            rows.append({"system": "robot", "pressure_MPa": p, "speed_rpm": 300.0,
                         "feed_mm_per_rev": f, "depth_of_cut_mm": 0.05, "key": f"f{f}{p}",
                         "summary": {"feed_amplitude_um": a * fac, "force_amplitude_x_N":
                                     10 * a * fac, "stable": a < 1.0,
                                     "chatter": a >= 2.0}})
    return rows


def test_qualitative_checks_are_computed_not_assumed():
    """Same checker, two data sets: paper-like results agree, reversed trends and a foot
    that amplifies vibration are reported as disagreements."""
    cfg, _, _ = pc.load_paper_config()
    good = {c["finding"]: c["agrees"]
            for c in qualitative_checks(_rows([0.2, 1.5, 3, 6], [0.1, 1.2, 2], 0.1), cfg)}
    bad = {c["finding"]: c["agrees"]
           for c in qualitative_checks(_rows([6, 3, 1.5, 0.2], [2, 1.2, 0.1], 3.0), cfg)}
    grow_d = "vibration grows with depth of cut (paper, robot without foot)"
    grow_f = "vibration grows with feed (paper, robot without foot)"
    foot = "the pressure foot (0.3 MPa) reduces the feed (vibration) amplitude"
    assert good[grow_d] and good[grow_f] and good[foot]
    assert bad[grow_d] is False and bad[grow_f] is False and bad[foot] is False
    # the onset check: paper-like onset at ap = 0.1 mm agrees, at 0.05 mm (base) it does not;
    # it is made twice, by the paper's criterion (stable flag, onset 0.1 mm here) and by the
    # chatter verdict (onset 0.2 mm here: disagrees), each row saying which
    onset = "vibratory from depth of cut >= 0.1 mm (paper, onset)"
    by = {(c["finding"], c["verdict"]): c
          for c in qualitative_checks(_rows([0.2, 1.5, 3, 6], [0.1, 1.2, 2], 0.1), cfg)}
    paper_v = "paper's criterion (Ra > 1.6 um)"
    chat_v = "chatter (vibration grows)"
    assert by[(onset, paper_v)]["agrees"] is True
    assert by[(onset, chat_v)]["agrees"] is False
    assert "first chattering depth of cut: 0.2 mm" in by[(onset, chat_v)]["ours"]
    bad_by = {(c["finding"], c["verdict"]): c["agrees"] for c in
              qualitative_checks(_rows([6, 3, 1.5, 0.2], [2, 1.2, 0.1], 3.0), cfg)}
    assert bad_by[(onset, paper_v)] is False
    assert "0.1" in by[(foot, "amplitudes")]["ours"]  # median ratio 0.1, not printed as 0.10/0.00


def _browser_or_skip():
    from robobore.study.browser import browser_available

    why = browser_available()
    if why is None:
        return
    if os.environ.get("ROBOBORE_SKIP_BROWSER") == "1":
        pytest.skip(f"ROBOBORE_SKIP_BROWSER=1 and no browser: {why}")
    pytest.fail(f"headless Chromium test cannot run: {why}")


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("paper")
    cfg = _small_config(tmp)
    out = tmp / "out"
    res = pp.run_paper(cfg, out, fast=True, workers=0,
                       progress=lambda *a: PROGRESS_CALLS.append(a))
    SMALL_RESULT.append(res)
    return res.to_dict(), out, cfg


#: the ``progress(task, done, total)`` calls of the ``small_run`` study
PROGRESS_CALLS: list[tuple] = []
#: the PaperSummary the ``small_run`` study returned
SMALL_RESULT: list = []
CONTRACT = Path(__file__).parent / "contract"


def test_paper_summary_is_the_written_json_and_the_stored_contract(small_run):
    """run_paper returns a frozen PaperSummary; its to_dict() is paper_summary.json, key for
    key, and keeps to contract/paper_summary.json (keys in order, JSON types)."""
    import dataclasses

    from robobore.io.records import json_mismatches, json_types
    from robobore.io.results import to_jsonable
    from robobore.study.results import PaperSummary

    _, out, _ = small_run
    res = SMALL_RESULT[0]
    assert isinstance(res, PaperSummary)
    spec = json.loads((CONTRACT / "paper_summary.json").read_text())["keys"]
    assert json_types(PaperSummary) == spec
    written = json.loads((out / "paper_summary.json").read_text())
    assert json.loads(json.dumps(to_jsonable(res.to_dict()))) == written
    assert list(res.to_dict()) == list(written)
    assert json_mismatches(written, spec) == []
    assert res.computed == written["computed"] and res.report == written["report"]
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.computed = 0  # type: ignore[misc]


def test_paper_reports_progress_through_the_callback(small_run):
    """Each stage reports ``(task, done, total)`` from 0 to its total, in order (no FE
    calibration stage with ``fast``)."""
    tasks = list(dict.fromkeys(c[0] for c in PROGRESS_CALLS))
    assert len(tasks) == 3 and tasks[1].startswith("sweep ")
    assert tasks[0] == "identify robot and modes" and tasks[2] == "lobes, comparison, report"
    for task in tasks:
        mine = [c for c in PROGRESS_CALLS if c[0] == task]
        assert mine[0][1] == 0 and mine[-1][1] == mine[-1][2] > 0
        assert [c[1] for c in mine] == sorted(c[1] for c in mine)


def test_paper_verdicts_by_cause(small_run):
    """Chatter means growing vibration: every condition called chatter has a feed amplitude
    that grows over the run; a cut made rough by its feed marks (f = 0.3 mm/r, Ra 4 um >
    1.6 um) is 'vibratory' by the paper's criterion but not chatter; the findings say which
    verdict they were checked by."""
    import xarray as xr

    from robobore.study.store import ResultsStore

    res, out, _ = small_run
    store = ResultsStore(out / "sweep")
    n_chatter = n_rough_only = 0
    for key in store.done_keys():
        ds = store.load(key)
        if int(ds["chatter"]):
            n_chatter += 1
            # the regenerative feed and radial amplitudes grow (fitted over the run)
            assert float(ds["feed_amplitude_growth"]) > 1, key
            assert float(ds["vibration_growth"]) > 1, key
        elif int(ds["stable"]) == 0:
            n_rough_only += 1
            assert float(ds["roughness_Ra_um"]) > 1.6
    assert n_chatter >= 1 and n_rough_only >= 1
    assert res["chatter"] == n_chatter
    with xr.open_dataset(out / "results.nc") as ds:
        for v in ("chatter", "surface_finish_ok", "tool_leaves_cut", "roughness_Ra_um"):
            assert v in ds
    verdicts = {c["verdict"] for c in res["qualitative_checks"]}
    assert {"chatter (vibration grows)", "paper's criterion (Ra > 1.6 um)"} <= verdicts


def test_paper_lobes_and_verdicts_agree(small_run):
    """The report's lobes and its verdicts tell one story: no swept robot condition at the
    base feed more than 10 % above the semi-discretisation limit at its speed is 'no chatter'
    and none more than 10 % below it is 'chatter', unless its verdict states the tool leaving
    the cut; the report says how many were checked."""
    res, out, _ = small_run
    c = res["lobe_consistency"]
    assert c["checked"] >= 3
    assert c["inconsistent"] == [], c["inconsistent"]
    assert {x["side"] for x in c["conditions"]} - {"near"}
    html = (out / "report.html").read_text()
    assert f"{c['consistent']} of {c['checked']} consistent" in html


def test_paper_fast_small_run_outputs(small_run):
    """The main job end to end (--fast, reduced set): JSON contract, files, every condition
    simulated once and recorded, comparison and checks present."""
    res, out, _ = small_run
    # OFAT 2 levels per factor: 4 distinct conditions per pressure, 2 pressures + tool
    assert res["conditions"] == 12
    assert res["computed"] + len(res["failed"]) == 12
    assert res["stable"] + res["vibratory"] == res["computed"]
    assert Path(res["report"]).is_file() and res["wall_time_s"] > 0
    for f in ("results.nc", "paper_summary.json", "coefficients.json",
              "equivalent_model.json", "sweep/index.json"):
        assert (out / f).is_file(), f
    import xarray as xr

    with xr.open_dataset(out / "results.nc") as ds:
        assert ds.sizes["condition"] == 12
        assert int((ds["system"] == "machine_tool").sum()) == 4
    s = json.loads((out / "paper_summary.json").read_text())
    assert s["coefficients_mode"] == "stored (--fast)"
    # the boring model runs on the measured TC4 default; the report names it, its domain,
    # and that the base condition's 37.7 m/min lies above the measured 5-30 m/min
    cs = s["coefficient_set"]
    assert cs["name"] == "TC4"
    assert cs["domain"] == {"cutting_speed_m_per_min": [5.0, 30.0],
                            "uncut_chip_thickness_um": [40.0, 80.0]}
    assert cs["base_cutting_speed_m_per_min"] == pytest.approx(37.699, abs=1e-3)
    base_w = [w for w in s["warnings"] if "(the base condition)" in w]
    assert len(base_w) == 1 and "37.7 m/min outside the measured 5-30 m/min" in base_w[0]
    assert "800 r/min" in " ".join(s["warnings"])
    from robobore.cutting.coefficient_sets import ti64_coefficients

    assert cs["coefficients"]["Ktc_N_per_m2"] == pytest.approx(ti64_coefficients(37.7).Ktc)
    html = (out / "report.html").read_text()
    assert "Coefficient set TC4:" in html and "Coefficient warnings" in html
    assert "37.7 m/min outside the measured 5-30 m/min" in html
    assert "opt-in set TC4-FE, not used above" in html
    # the runs themselves were simulated with the default set (their stored provenance)
    import netCDF4

    from robobore.study.store import ResultsStore

    recs = list(ResultsStore.open_existing(out / "sweep").records())
    with netCDF4.Dataset(recs[0].path) as nc:
        assert "Ducobu" in nc.getncattr("coefficients_provenance")
    assert any("37.7 m/min outside the measured" in w for r in recs
               for w in r.coefficient_warnings)
    assert s["comparison"]["groups"]
    assert any("pressure foot" in c["finding"] for c in s["qualitative_checks"])
    eq = s["equivalent_model"]
    # the foot stiffens every direction (assumed contact model adds stiffness)
    for a, b in zip(eq["without_foot"], eq["with_foot"], strict=True):
        assert b["stiffness_N_per_m"] > a["stiffness_N_per_m"]
        assert a["mass_kg"] == pytest.approx(
            a["stiffness_N_per_m"] / (2 * math.pi * a["frequency_Hz"]) ** 2, rel=1e-9)
    html = Path(res["report"]).read_text()
    for word in ("SYNTHETIC", "Equivalent model", "23.7", "Stability lobe", "Qualitative checks",
                 "3.22-15.54"):
        assert word in html, word


def test_paper_report_opens_in_headless_chromium(small_run):
    """Issue 6 acceptance: the paper report loads with no console error and every figure."""
    _browser_or_skip()
    from robobore.study.browser import check_html_in_browser

    res, _, _ = small_run
    chk = check_html_in_browser(res["report"])
    assert chk.problems == ()
    assert chk.images >= 6


def test_fast_needs_the_stored_file(tmp_path):
    p = _small_config(tmp_path)
    p.write_text(p.read_text().replace(str(EX / "tc4_fe_coefficients.json"),
                                       str(tmp_path / "missing.json")))
    with pytest.raises(ConfigError, match="coefficients"):
        pp.run_paper(p, tmp_path / "o", fast=True, workers=0)


def test_cli_paper_json_and_resume(tmp_path, small_run):
    """``robobore paper CONFIG --fast --json`` prints only JSON with the contract keys; run
    again on the same OUT it recomputes nothing (the sweep store is resumable)."""
    from typer.testing import CliRunner

    from robobore.cli import app

    _, out, cfg = small_run
    r = CliRunner().invoke(app, ["paper", str(cfg), "--out", str(out), "--fast", "--json",
                                 "--workers", "0"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    for k in ("report", "conditions", "stable", "vibratory", "wall_time_s"):
        assert k in d
    res, _, _ = small_run
    assert d["sweep"]["computed"] == 0
    assert d["sweep"]["skipped"] == res["computed"]
    assert (d["stable"], d["vibratory"]) == (res["stable"], res["vibratory"])
    # nothing recomputed, the coefficient set's own warnings still said
    assert d["coefficient_set"]["name"] == "TC4"
    assert any("(the base condition)" in w for w in d["warnings"])


def test_compare_carries_the_runs_coefficient_warnings(small_run):
    """``robobore compare`` on the paper job's results: the compared runs' coefficient
    warnings (the measured TC4 set above its 5-30 m/min) in the JSON ``warnings`` with the
    number of compared conditions each applies to, and in the human output."""
    from typer.testing import CliRunner

    from robobore.cli import app
    from robobore.study.compare import compare_results

    _, out, _ = small_run
    cmp = compare_results(EX / "measured_synthetic.csv", out)
    n = len(cmp.rows)
    cw = [w for w in cmp.warnings if w.startswith("coefficients (")]
    speed_w = [w for w in cw if "37.7 m/min outside the measured 5-30 m/min" in w]
    assert len(speed_w) == 1
    # every compared robot condition at 300 r/min carries it, and no other
    k = sum(1 for r in cmp.rows if r["condition"]["speed_rpm"] == 300.0)
    assert 0 < k <= n and speed_w[0].startswith(f"coefficients ({k} of {n} conditions)")
    assert any("800 r/min" not in w and "101 m/min" in w for w in cw)
    r = CliRunner().invoke(app, ["compare", str(EX / "measured_synthetic.csv"), str(out),
                                 "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["warnings"] == list(cmp.warnings)
    r = CliRunner().invoke(app, ["compare", str(EX / "measured_synthetic.csv"), str(out)])
    assert r.exit_code == 0 and "37.7 m/min outside the measured" in " ".join(r.output.split())


def test_synthetic_measured_is_reproducible(tmp_path):
    """The SYNTHETIC measured CSV is made by package code, deterministically (seeded)."""
    cfg = _small_config(tmp_path, drop=())
    text = cfg.read_text().replace("pressure_MPa = [0.0, 0.3]", "pressure_MPa = [0.3]")
    cfg.write_text(text)
    a = paper_synthetic.make_synthetic_measured(cfg, tmp_path / "a.csv").read_text()
    b = paper_synthetic.make_synthetic_measured(cfg, tmp_path / "b.csv").read_text()
    assert a == b
    assert a.startswith("# SYNTHETIC")
    assert len([ln for ln in a.splitlines() if ln and not ln.startswith("#")]) == 1 + 4


#: The workpiece-frame FE calibration the bundled example used before it calibrated from the
#: validated model (feed force 55-70 % low): with it the deepest cut of the study chatters
#: and drifts, the case that showed Ra ~96 um with the form left in.
_LOW_FEED_COEFFICIENTS = {"Ktc_N_per_m2": 1576371394.969606, "Krc_N_per_m2": 0.0,
                          "Kfc_N_per_m2": 93781277.00977457, "Kte_N_per_m": 20900.608960639354,
                          "Kre_N_per_m": 0.0, "Kfe_N_per_m": 27338.193228954256}


def test_deepest_cut_roughness_is_after_form_removal():
    """The study's deepest cut without foot (300 r/min, 0.15 mm/r, ap 0.3 mm) with the
    low-feed-force coefficients above: the tool drifts as the chatter grows, a taper of tens
    of um/mm that made Ra ~96 um when the form was left in; Ra after removing the
    least-squares line is ~10 um. The cut is chatter (its feed amplitude grows) and rough."""
    cfg, raw, path = pc.load_paper_config()
    eq = pp.build_equivalent(pp.identify_stiffness(cfg, path), pp.identify_modes(cfg, path),
                             cfg.pressure_foot)
    coeffs = dict(pp.load_or_calibrate(cfg, raw, path, True, 1))
    coeffs["coefficients"] = dict(_LOW_FEED_COEFFICIENTS, provenance="test")
    cfg.coefficients.material = "TC4-FE"  # the calibration (here replaced) is the model's set
    model = pp.dynamics_model(cfg, eq, coeffs, "robot")
    from robobore.study.runners import boring_runner

    ds = boring_runner({"speed_rpm": 300.0, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.3,
                        "pressure_MPa": 0.0}, {"model": model})
    assert int(ds["chatter"]) == 1 and int(ds["surface_finish_ok"]) == 0
    fa = ds["feed_amplitude"].values
    assert fa[-1] > 20 * fa[1]
    slope = float(ds["form_slope_um_per_mm"])
    ra, ra_form = float(ds["roughness_Ra_um"]), float(ds["roughness_Ra_with_form_um"])
    assert abs(slope) > 30.0
    assert ra_form > 5 * ra and 3.0 < ra < 30.0


def test_report_figures_units_legends_and_log_scale(small_run):
    """Every axis of the paper figures carries a unit; legends sit outside the data (figure
    legends or anchored outside the axes); the feed amplitude is on a log axis and a zero
    amplitude is drawn on the bottom edge, not confused with a small one."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from robobore.study import paper_figures as pr
    from robobore.study.store import ResultsStore

    res, out, cfg_path = small_run
    cfg, _, _ = pc.load_paper_config(cfg_path)
    base = {k: float(v) for k, v in cfg.study.base.items()}
    store = ResultsStore(out / "sweep")
    rows = [{**rec.condition, "system": rec.condition.get("system", "robot"),
             "summary": rec.summary, "key": rec.key} for rec in store.records()]
    # the stored condition has no system key for the machine tool: take it from the file
    for r in rows:
        r["system"] = store.load(r["key"]).attrs.get("system", "robot")
    zero = dict(rows[0])
    zero["summary"] = {**zero["summary"], "feed_amplitude_um": 0.0}
    rows_z = [zero, *rows[1:]]
    ds = store.load(rows[0]["key"])
    figs = [pr.fig_trends(rows_z, base), pr.fig_force_half_rev(ds, "t"),
            pr.fig_surface([("a", ds)]), pr.fig_feed_amplitude_time([("a", ds)])]
    for fig in figs:
        for ax in fig.axes:
            for lab in (ax.get_xlabel(), ax.get_ylabel()):
                if lab:
                    assert "[" in lab and "]" in lab, lab
            leg = ax.get_legend()
            if leg is not None:  # anchored outside the axes box
                bb = leg.get_bbox_to_anchor().transformed(ax.transAxes.inverted())
                assert bb.x0 >= 1.0 or bb.y1 <= 0.0, lab
    trends = figs[0]
    feed_axes = [ax for ax in trends.axes if "feed amplitude" in ax.get_ylabel()]
    assert feed_axes and all(ax.get_yscale() == "log" for ax in feed_axes)
    assert trends.legends  # one figure legend below the panels
    assert any("= 0" in t.get_text() for t in trends.legends[0].get_texts())
    for fig in figs:
        plt.close(fig)


def test_study_pool_gives_the_serial_study(small_run, tmp_path):
    """With workers the posture plan, the lobes and the conditions run on the study pool
    (the main job's route); the summary is the serial study's, up to the run's own records
    (wall times, where it ran) and the last digits of the lobes (BLAS in other processes)."""
    serial, _, cfg = small_run
    pooled = pp.run_paper(cfg, tmp_path / "pooled", fast=True, workers=2).to_dict()
    assert pooled["sweep"]["mode"].startswith("local process pool")
    drop = ("timings_s", "wall_time_s", "out", "report", "sweep", "workers", "warnings",
            "lobe_consistency", "posture_plan")
    assert {k: v for k, v in pooled.items() if k not in drop} == \
        {k: v for k, v in serial.items() if k not in drop}
    a, b = pooled["lobe_consistency"], serial["lobe_consistency"]
    assert [c["consistent"] for c in a["conditions"]] == [c["consistent"] for c in b["conditions"]]
    np.testing.assert_allclose([c["critical_depth_mm"] for c in a["conditions"]],
                               [c["critical_depth_mm"] for c in b["conditions"]], rtol=1e-9)
    pa, pb = dict(pooled["posture_plan"]), dict(serial["posture_plan"])
    pa.pop("wall_time_s", None)
    pb.pop("wall_time_s", None)
    assert pa == pb
    assert [w for w in pooled["warnings"] if not w.startswith("posture plan")] == \
        [w for w in serial["warnings"] if not w.startswith("posture plan")]


def test_paper_and_compare_outputs_hold_no_contradiction(small_run):
    """paper_summary.json (with its comparison, lobe check and posture plan) and every
    condition's record hold no contradictory verdicts (robobore.io.consistency)."""
    from robobore.io.consistency import contradictions
    from robobore.study.store import ResultsStore

    res, out, _ = small_run
    assert contradictions(res) == []
    assert res["comparison"] is not None and contradictions(res["comparison"]) == []
    store = ResultsStore(out / "sweep")
    for key in store.done_keys():
        ds = store.load(key)
        rec = {"chatter": bool(int(ds["chatter"])),
               "stable": None if "stable" not in ds else bool(int(ds["stable"])),
               "tool_leaves_cut": bool(int(ds["tool_leaves_cut"])),
               "tool_left_cut_fraction": float(ds.attrs["tool_left_cut_fraction"]),
               "surface_finish": None if "surface_finish_ok" not in ds else (
                   "ok" if int(ds["surface_finish_ok"]) else "rough"),
               "chatter_frequency_Hz": (None if ds.attrs["chatter_frequency_Hz"] < 0
                                        else float(ds.attrs["chatter_frequency_Hz"])),
               "diverged": bool(int(ds.attrs.get("diverged", 0))),
               "reasons": ds.attrs["reasons"]}
        assert contradictions(rec, key) == []
