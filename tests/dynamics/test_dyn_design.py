"""Adaptive test design (robobore.dynamics.design): the next cut from the posterior band, the
``calibrate dynamics --propose`` option and the SYNTHETIC sequential design."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.dynamics.band import DEPTH_FLOOR_M, Z90, LobeBand
from robobore.dynamics.design import expected_information, predictive_p_chatter, propose_cuts
from robobore.errors import ConfigError

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "boring_paper.toml"
runner = CliRunner()


def _band(speeds, median_m, log_sd, sensitivity=None) -> LobeBand:
    speeds, med, sd = (np.asarray(x, float) for x in (speeds, median_m, log_sd))
    depth = np.geomspace(1e-4, 1e-2, 5)
    return LobeBand(speeds, med, med * np.exp(-Z90 * sd), med * np.exp(Z90 * sd), sd, depth,
                    np.zeros((speeds.size, depth.size)), "test", ("a",), 1,
                    sensitivity=sensitivity)


def test_information_rises_with_the_spread_and_peaks_at_the_median():
    sd = np.array([0.0, 0.05, 0.1, 0.3, 1.0])
    i = expected_information(sd, 0.0, 0.1, 0.1)
    assert i[0] == pytest.approx(0.0, abs=1e-9)
    assert np.all(np.diff(i) > 0)
    assert i[-1] < 1.0  # a verdict is one bit at most
    off = np.array([-0.4, -0.1, 0.0, 0.1, 0.4])
    j = expected_information(np.full(5, 0.3), off, 0.1, 0.1)
    assert int(np.argmax(j)) == 2
    assert j[0] == pytest.approx(j[4], rel=1e-9)  # symmetric about the median
    assert predictive_p_chatter(0.3, 0.0, 0.1, 0.1) == pytest.approx(0.5)
    # label noise lowers what a verdict tells
    assert expected_information(0.3, 0.0, 0.2, 0.1)[0] < expected_information(0.3, 0.0, 0.1,
                                                                              0.1)[0]


def test_proposal_lands_at_the_widest_speed_at_the_median_depth():
    speeds = np.linspace(500.0, 2000.0, 7)
    med = np.array([2.0, 1.5, 1.0, 3.0, 2.5, 1.2, 0.8]) * 1e-3
    sd = np.full(7, 0.05)
    sd[4] = 0.6
    (c,) = propose_cuts(_band(speeds, med, sd))
    assert c.criterion == "point"  # a band without sensitivity
    assert c.speed_rpm == speeds[4]
    S = np.diag(sd)  # each speed on its own axis: the mean criterion lands there too
    (m,) = propose_cuts(_band(speeds, med, sd, S), criterion="mean")
    assert (m.criterion, m.speed_rpm, m.depth_m) == ("mean", speeds[4], med[4])
    assert m.mean_information_bits > 0
    assert c.depth_m == med[4]
    assert c.p_chatter == pytest.approx(0.5)
    assert c.log_sd == pytest.approx(0.6)
    assert "largest expected information" in c.why
    assert c.to_dict()["depth_mm"] == pytest.approx(2.5)


def test_several_proposals_spread_and_skip_speeds_without_a_limit():
    speeds = np.linspace(1000.0, 2000.0, 11)  # 100 r/min apart
    med = np.full(11, 1e-3)
    med[0] = DEPTH_FLOOR_M  # unstable at vanishing depth: not proposed
    sd = np.array([0.9, 0.5, 0.49, 0.48, 0.1, 0.1, 0.1, 0.3, 0.1, 0.1, 0.1])
    cuts = propose_cuts(_band(speeds, med, sd), 3, min_spacing_rpm=250.0)
    got = [c.speed_rpm for c in cuts]
    assert got == [1100.0, 1700.0, 1400.0]
    assert all(abs(a - b) >= 250.0 for k, a in enumerate(got) for b in got[:k])
    assert [c.information_bits for c in cuts] == sorted([c.information_bits for c in cuts],
                                                        reverse=True)
    # no spacing: the greedy order is the order of the information
    assert [c.speed_rpm for c in propose_cuts(_band(speeds, med, sd), 3,
                                              min_spacing_rpm=0.0)] == [1100.0, 1200.0, 1300.0]
    # the spacing leaves fewer candidates than asked
    assert len(propose_cuts(_band(speeds, med, sd), 5, min_spacing_rpm=600.0)) == 2
    with pytest.raises(ConfigError, match="proposed cuts"):
        propose_cuts(_band(speeds, med, sd), 0)


def test_mean_criterion_prefers_what_the_speeds_share():
    """A shared axis (all speeds) and a local one (one speed, the widest): the verdict's own
    information picks the widest speed, the mean information a speed that measures the shared
    axis; greedy picks update the covariance, so each adds less."""
    speeds = np.linspace(500.0, 2000.0, 7)
    med = np.full(7, 1e-3)
    S = np.zeros((7, 2))
    S[:, 0] = 0.3
    S[4, 1] = 0.35
    sd = np.sqrt((S ** 2).sum(axis=1))
    band = _band(speeds, med, sd, S)
    assert propose_cuts(band, criterion="point")[0].speed_rpm == speeds[4]
    cuts = propose_cuts(band, 3)
    assert cuts[0].speed_rpm != speeds[4]
    bits = [c.mean_information_bits for c in cuts]
    assert bits[0] > bits[1] > bits[2] > 0
    assert len({c.speed_rpm for c in cuts}) == 3
    with pytest.raises(ConfigError, match="criterion"):
        propose_cuts(band, criterion="widest")


def test_proposed_depth_is_capped_by_the_range_and_the_config():
    """A median deeper than the cut can be (a lobe's peak): the proposal sits at the smaller of
    the depth-of-cut range's top (robobore.io.ranges) and the config's largest depth, says
    which bound, and carries P(chatter) and information of the capped depth."""
    from robobore.dynamics.design import depth_cap
    from robobore.io.ranges import RANGES

    top = RANGES["depth_mm"].hi * 1e-3
    speeds = np.linspace(500.0, 2000.0, 4)
    med = np.array([1.0, 1.5 * top * 1e3, 2.0, 1.0]) * 1e-3  # 30 mm: under the scan's top
    sd = np.array([0.05, 0.6, 0.05, 0.05])
    band = _band(speeds, med, sd)
    (c,) = propose_cuts(band)
    assert c.speed_rpm == speeds[1]
    assert c.depth_m == pytest.approx(top) and c.median_depth_m == pytest.approx(med[1])
    assert "robobore.io.ranges" in c.depth_capped_by and "capped" in c.why
    off = np.log(top / med[1])
    assert c.p_chatter == pytest.approx(float(predictive_p_chatter(0.6, off, 0.1, 0.1)))
    assert c.p_chatter < 0.5
    assert c.information_bits == pytest.approx(float(expected_information(0.6, off, 0.1,
                                                                          0.1)[0]))
    # the config's limit binds where it is the smaller one, and only where the median is deeper
    cuts = propose_cuts(band, 4, max_depth_m=1.2e-3, min_spacing_rpm=0.0)
    by = {k.speed_rpm: k for k in cuts}
    for n, m in zip(speeds, med, strict=True):
        k = by[n]
        assert k.depth_m == pytest.approx(min(m, 1.2e-3))
        assert (k.depth_capped_by is not None) == (m > 1.2e-3)
    d = by[speeds[2]].to_dict()
    assert d["depth_mm"] == pytest.approx(1.2) and d["band_median_depth_mm"] == pytest.approx(2.0)
    assert d["depth_capped_by"] == "[calibration] max_depth_mm = 1.2 mm"
    assert by[speeds[0]].to_dict()["depth_capped_by"] is None
    # a config limit above the range's top: the range binds
    assert depth_cap(2 * top) == depth_cap(None)
    with pytest.raises(ConfigError, match="max_depth_mm"):
        depth_cap(-1e-3)


def test_calibrate_cli_caps_proposals_at_the_config_depth(tmp_path):
    from robobore.dynamics.calibrate import Observation, write_observations_csv

    obs = [Observation(i + 1, n, a * 1e-3, c) for i, (n, a, c) in enumerate(
        [(400, 0.2, False), (400, 3.0, True), (1200, 2.0, False), (1200, 15.0, True)])]
    csv = write_observations_csv(tmp_path / "cuts.csv", obs, "SYNTHETIC")
    cfg = tmp_path / "capped.toml"
    cfg.write_text(EXAMPLE.read_text() + "\n[calibration]\nmax_depth_mm = 0.1\n")
    args = ["calibrate", "dynamics", str(cfg), "--observations", str(csv), "--speeds", "5",
            "--no-process-damping", "--propose", "2"]
    r = runner.invoke(app, args + ["--json"])
    assert r.exit_code == 0, r.output
    cuts = json.loads(r.stdout)["proposed_cuts"]
    assert len(cuts) == 2
    for c in cuts:
        assert c["band_median_depth_mm"] > 0.1  # the medians are deeper than the limit
        assert c["depth_mm"] == pytest.approx(0.1)
        assert c["depth_capped_by"] == "[calibration] max_depth_mm = 0.1 mm"
        assert "capped at 0.1 mm" in c["why"]
        assert c["p_chatter"] < 0.5
    r2 = runner.invoke(app, args)
    assert r2.exit_code == 0, r2.output
    assert "capped" in r2.output
    bad = tmp_path / "bad.toml"
    bad.write_text(EXAMPLE.read_text() + "\n[calibration]\nmax_depth_mm = 500.0\n")
    r3 = runner.invoke(app, ["calibrate", "dynamics", str(bad), "--observations", str(csv),
                             "--propose", "1"])
    assert r3.exit_code != 0
    assert "max_depth_mm" in r3.output and "500" in r3.output and "mm" in r3.output


def test_calibrate_cli_proposes_cuts_at_the_band(tmp_path):
    from robobore.dynamics.calibrate import Observation, write_observations_csv

    # SYNTHETIC cuts: stable well below the example's limit, chatter well above it
    obs = [Observation(i + 1, n, a * 1e-3, c) for i, (n, a, c) in enumerate(
        [(400, 0.2, False), (400, 3.0, True), (1200, 2.0, False), (1200, 15.0, True)])]
    csv = write_observations_csv(tmp_path / "cuts.csv", obs, "SYNTHETIC")
    args = ["calibrate", "dynamics", str(EXAMPLE), "--observations", str(csv), "--speeds", "5",
            "--no-process-damping", "--propose", "2"]
    r = runner.invoke(app, args + ["--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    b = d["band"]
    cuts = d["proposed_cuts"]
    assert len(cuts) == 2
    sd = np.asarray(b["critical_depth_log_sd"])
    for c in cuts:
        i = b["speed_rpm"].index(c["speed_rpm"])
        assert c["depth_mm"] == pytest.approx(b["critical_depth_p50_mm"][i], rel=1e-12)
        assert c["p_chatter"] == pytest.approx(0.5)
        assert set(c) >= {"speed_rpm", "depth_mm", "p_chatter", "why"}
    assert all(c["criterion"] == "mean" for c in cuts)
    assert cuts[0]["speed_rpm"] != cuts[1]["speed_rpm"]
    assert cuts[0]["mean_information_bits"] > cuts[1]["mean_information_bits"] > 0
    assert cuts[0]["critical_depth_log_sd"] <= sd.max()
    r2 = runner.invoke(app, args)
    assert r2.exit_code == 0, r2.output
    assert "proposed cut 1" in r2.output and "proposed cut 2" in r2.output
    r3 = runner.invoke(app, args[:-1] + ["101"])
    assert r3.exit_code == 2
    assert "--propose" in r3.output


def test_sequential_design_proposes_from_the_posterior(monkeypatch):
    """One proposed cut after the stratified ones (N_CUTS lowered to 5): at a candidate
    speed, at the proposal's depth, labelled by the truth; the held-out speeds are those of
    the stratified design of the same seed."""
    import robobore.dynamics.calibrate_synthetic as cs
    from robobore.dynamics.band import critical_depths
    from robobore.dynamics.calibrate import Observation, build_problem
    from robobore.dynamics.config import load_dynamics_config

    cfg, _ = load_dynamics_config(EXAMPLE)
    pb = build_problem(cfg, [Observation(1, 1000.0, 1e-3, False)])
    monkeypatch.setattr(cs, "N_CUTS", 5)
    _, held_s, truth_s = cs.synthetic_observations(pb, (200.0, 3000.0), 3)
    obs, held, truth, props = cs.sequential_observations(cfg, pb, (200.0, 3000.0), 3)
    assert np.array_equal(held, held_s) and np.allclose(truth, truth_s)
    assert len(obs) == 5 and len(props) == 1
    quarters = np.linspace(200.0, 3000.0, 5)
    for k, o in enumerate(obs[:4]):
        assert quarters[k] <= o.speed_rpm <= quarters[k + 1]
    new = obs[4]
    assert new.speed_rpm in cs.candidate_speeds()
    assert not np.any(np.isclose(cs.candidate_speeds()[:, None], held[None, :], rtol=0,
                                 atol=1e-6))
    assert (new.speed_rpm, new.depth_m) == (props[0].speed_rpm, props[0].depth_m)
    a = critical_depths(cs.truth_structure(pb.structure), pb.process, np.array([new.speed_rpm]))
    rng = np.random.default_rng(3)
    rng.uniform(0, 1, 5)
    rng.uniform(size=5)
    flip = rng.uniform(0, 1, 5) < cs.LABEL_NOISE
    assert new.chatter == bool((new.depth_m > a[0]) != flip[4])
    with pytest.raises(ConfigError, match="design"):
        cs.validation_case(cfg, 0, design="adaptive")
