"""The posture-map section of the paper report (robobore.plan.paper), built from the paper
study's own identification at test time."""

from __future__ import annotations

import json

import numpy as np
import pytest

from robobore.plan.paper import add_posture_section, paper_posture_plan
from robobore.study.paper import identify_modes, identify_stiffness
from robobore.study.paper_config import load_paper_config
from robobore.study.report import Report


@pytest.fixture(scope="module")
def plan():
    cfg, raw, path = load_paper_config(None)
    stiff = identify_stiffness(cfg, path)
    modes = identify_modes(cfg, path)
    coeffs = json.loads((path.parent / cfg.coefficients.file).read_text())
    return paper_posture_plan(cfg, path, stiff, modes, coeffs)


def test_paper_posture_plan(plan):
    assert "error" not in plan, plan.get("error")
    json.dumps(plan)  # goes into paper_summary.json
    assert plan["measured"] is not None  # the paper's posture is a candidate
    assert np.allclose(plan["measured"]["joints_deg"],
                       [-48.38, 54.82, 6.86, -54.16, 107.43, -21.95], atol=1e-6)
    # the recommendation is the best of the candidates rated by the semi-discretisation
    rec = plan["recommended"]
    assert rec["critical_depth_method"] == "semi-discretization"
    assert plan["measured"]["critical_depth_method"] == "semi-discretization"
    assert plan["synthetic_inputs"] is True
    ws = np.array([[np.nan if v is None else v for v in row]
                   for row in plan["workspace"]["best_criterion"]], float)
    assert ws.shape == (5, 5) and np.isfinite(ws[2, 2]) and ws[2, 2] >= 0.0


def test_posture_section_renders(plan, tmp_path):
    rep = Report("t")
    add_posture_section(rep, plan)
    p = tmp_path / "r.html"
    rep.write(p)
    html = p.read_text()
    assert "Posture map for the paper" in html and "paper&#x27;s posture" in html.replace(
        "&#39;", "&#x27;") and "<img" in html


def test_posture_section_reports_an_error():
    rep = Report("t")
    add_posture_section(rep, {"error": "robot 'x' has no inertial data"})
    assert any("no inertial data" in part for part in rep._parts)


def test_posture_plan_in_a_process_of_its_own_is_the_same():
    """The study runs the posture plan in a forked process beside the lobes (workers > 0):
    the same result as in the study's own process (its wall time aside)."""
    from robobore.study.paper import _PosturePlan

    cfg, raw, path = load_paper_config(None)
    stiff = identify_stiffness(cfg, path)
    modes = identify_modes(cfg, path)
    coeffs = json.loads((path.parent / cfg.coefficients.file).read_text())
    side = _PosturePlan(cfg, path, stiff, modes, coeffs, parallel=True)
    assert side.fut is not None  # submitted to the process pool
    here = _PosturePlan(cfg, path, stiff, modes, coeffs, parallel=False).result()
    there = side.result()
    assert side.computed_in == "side process"  # not the fallback in this process
    assert "error" not in there, there.get("error")
    here.pop("wall_time_s")
    there.pop("wall_time_s")
    assert there == here
