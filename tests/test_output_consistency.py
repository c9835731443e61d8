"""No output of robobore holds contradictory verdicts (robobore.io.consistency).

The checker is held to catch each kind of contradiction; ``simulate boring`` and ``lobes``
are held to it over random SYNTHETIC cuts (robot-like equivalent models, speeds, feeds, nose
radii, depths around the limit, with and without an Ra tolerance), ``plan posture`` over
random cuts of the bundled paper bore; ``paper`` and ``compare`` on their outputs in
tests/study/test_paper.py.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from robobore.io.consistency import contradictions
from robobore.io.results import to_jsonable

RUN = {"chatter": False, "stable": True, "diverged": False, "chatter_frequency_Hz": None,
       "surface_finish": "ok", "tool_leaves_cut": False, "tool_left_cut_fraction": 0.0,
       "ra_tolerance_um": 1.6, "chatter_decided": True, "reasons": []}


@pytest.mark.parametrize("change, word", [
    ({"chatter": True, "reasons": ["chatter: grows"]}, "stable and chatter"),
    ({"chatter": True, "stable": False, "verdicts": {"paper_criterion": "stable"},
      "reasons": ["chatter: grows"]}, "paper's criterion says stable"),
    ({"diverged": True, "stable": False}, "diverged but no chatter"),
    ({"diverged": True, "chatter": True, "stable": False, "chatter_frequency_Hz": 30.0,
      "reasons": ["chatter: diverged"]}, "diverged run with a chatter frequency"),
    ({"chatter": True, "stable": False, "chatter_frequency_Hz": 0.0,
      "reasons": ["chatter: grows"]}, "chatter frequency 0.0 Hz"),
    ({"chatter_frequency_Hz": 12.0}, "without chatter"),
    ({"ra_tolerance_um": None}, "without an Ra tolerance"),
    ({"stable": False}, "neither chatter nor roughness"),
    ({"surface_finish": "rough", "reasons": ["rough: Ra"]}, "stable and rough"),
    ({"tool_leaves_cut": True, "reasons": ["tool leaves the cut"]}, "tool_left_cut_fraction"),
    ({"chatter": True, "stable": False}, "chatter without its reason"),
    ({"chatter_decided": False}, "undecided verdict without its reason"),
])
def test_the_checker_finds_each_contradiction(change, word):
    assert contradictions(RUN) == []
    found = contradictions({"runs": [{**RUN, **change}]})
    assert found and any(word in f for f in found), found
    assert found[0].startswith("runs[0]")


def test_the_checker_reads_lobes_summaries_and_agreements():
    lob = {"critical_depth_mm": [0.3, 0.2, math.inf], "absolute_limit_mm": 0.2}
    assert contradictions(lob) == []
    assert contradictions({**lob, "absolute_limit_mm": 0.3})
    assert contradictions({**lob, "critical_depth_mm": [-0.1, 0.2]})
    summ = {"computed": 10, "stable": 6, "vibratory": 4, "chatter": 2, "rough": 3}
    assert contradictions(summ) == []
    assert contradictions({**summ, "chatter": 5})
    assert contradictions({**summ, "stable": 7})
    agr = {"n": 10, "agree": 8, "both_stable": 5, "both_vibratory": 3}
    assert contradictions(agr) == []
    assert contradictions({**agr, "agree": 9})


def _random_config(draw_vals: dict) -> dict:
    v = draw_vals
    return {
        "equivalent": {
            "stiffness_N_per_m": {a: v[f"k{a}"] for a in "xyz"},
            "frequency_Hz": {a: v[f"f{a}"] for a in "xyz"},
            "damping_ratio": {a: v[f"z{a}"] for a in "xyz"},
            "note": "SYNTHETIC random robot-like model (tests/test_output_consistency.py)"},
        "insert": {"nose_radius_mm": v["nose"], "approach_angle_deg": 90.0,
                   "end_edge_angle_deg": 5.0, "rake_deg": 7.0, "inclination_deg": 0.0,
                   "clearance_deg": 7.0, "edge_radius_um": 20.0, "n_inserts": 1},
        "bore": {"diameter_mm": 40.0},
        "cutting": {"speed_rpm": v["speed"], "feed_mm_per_rev": v["feed"], "depth_mm": 0.05},
        "coefficients": {"material": "TC4"},
        "speed_rpm": {"min": 150.0, "max": 1500.0, "count": 40},
        "simulation": {"revolutions": 40,
                       **({"ra_tolerance_um": 1.6} if v["tol"] else {})},
    }


CUT = {**{f"k{a}": st.floats(3e5, 1e7) for a in "xyz"},
       **{f"f{a}": st.floats(5.0, 60.0) for a in "xyz"},
       **{f"z{a}": st.floats(0.01, 0.06) for a in "xyz"},
       "nose": st.floats(0.2, 1.2), "speed": st.floats(150.0, 1500.0),
       "feed": st.floats(0.05, 0.5), "tol": st.booleans(),
       "fac": st.sampled_from([0.5, 0.9, 1.1, 2.0])}


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow],
          phases=[Phase.explicit, Phase.reuse, Phase.generate])
@given(**CUT)
def test_simulate_boring_and_lobes_never_contradict_themselves(**v):
    """Over random cuts, at depths around the lobes' limit at the cut's speed: the JSON of
    ``lobes`` and of ``simulate boring`` holds no contradiction."""
    from robobore.dynamics.api import critical_depth_at, lobes, run_boring
    from robobore.errors import NumericalError

    cfg = _random_config(v)
    lob = to_jsonable(lobes(cfg).to_dict())
    assert contradictions(lob) == []
    ac = critical_depth_at(cfg, v["speed"]).to_dict()["critical_depth_mm"]
    depth = min(5.0, v["fac"] * ac) if ac and 0 < ac < math.inf else 0.05
    try:
        res = run_boring(cfg, depth_mm=max(depth, 1e-3)).to_dict()
    except NumericalError as exc:  # diverges within the first revolution: an error
        assert "diverges at once" in str(exc)
        return
    assert contradictions(to_jsonable(res)) == []


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(speed=st.floats(200.0, 1200.0), depth=st.floats(0.02, 0.5),
       feed=st.floats(0.05, 0.4))
def test_plan_posture_never_contradicts_itself(tmp_path_factory, speed, depth, feed):
    """The posture plan of the bundled paper bore at random cuts holds no contradiction."""
    import re
    from pathlib import Path

    from robobore.plan.posture import plan_posture

    ex = Path(__file__).resolve().parents[1] / "examples" / "plan_paper_bore.toml"
    text = ex.read_text().replace('"plan_paper_bore/', f'"{ex.parent.as_posix()}/plan_paper_bore/')
    for key, val in (("speed_rpm", speed), ("feed_mm_per_rev", feed), ("depth_mm", depth)):
        text, n = re.subn(rf"(?m)^{key} = [0-9.]+", f"{key} = {val!r}", text, count=1)
        assert n == 1, key
    p = tmp_path_factory.mktemp("plan") / "plan.toml"
    p.write_text(text)
    assert contradictions(to_jsonable(plan_posture(p).to_dict())) == []
