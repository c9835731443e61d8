"""Chatter detection with a wandering spindle speed: SYNTHETIC records whose spindle-locked
lines (runout, insert passing) follow a speed that wanders with a relative standard deviation
of 0.3 % (robobore.measure.synthetic, "Speed wander"), labelled by the simulation's verdict.
Each harmonic ``k`` moves by ``k`` times the speed's change, past a steady speed's bands."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import InputError
from robobore.measure.detect import DetectSettings, detect_chatter
from robobore.measure.records import make_record
from robobore.measure.synthetic import simulated_record

WANDER = 0.003
#: Stable records (default regime) that bands for a steady speed (one line wide about each
#: harmonic, spread 0) call chatter at this wander.
STABLE_SEEDS = (5, 29, 71, 112, 175, 195)


def test_steady_speed_record_is_unchanged_and_has_no_spread():
    a = simulated_record(7)
    b = simulated_record(7, speed_wander=0.0)
    assert np.array_equal(a.signals, b.signals)
    spreads = np.array([detect_chatter(simulated_record(s)).speed_spread for s in range(10)])
    # the windows' own estimates scatter a little about a steady speed (one record in ten
    # here, by 0.08 %); a spread that small widens no band beyond its two bins
    assert np.median(spreads) == 0.0 and spreads.max() < 1e-3, spreads


def test_spread_measured_and_level_free():
    spreads = []
    for s in STABLE_SEEDS[:3]:
        r = simulated_record(s, speed_wander=WANDER)
        assert r.truth["speed_wander"] == WANDER
        d = detect_chatter(r)
        g = make_record(r.signals * 250.0, r.sample_rate_Hz, list(r.channels), list(r.units))
        assert detect_chatter(g).speed_spread == pytest.approx(d.speed_spread, rel=1e-9)
        assert d.to_dict()["speed_spread"] == d.speed_spread
        spreads.append(d.speed_spread)
    # the windows average the wander within each 0.5 s: their spread is below the speed's
    assert all(0.2 * WANDER < v < 1.5 * WANDER for v in spreads), spreads


@pytest.mark.parametrize("given", [False, True], ids=["speed estimated", "speed given"])
def test_wandering_stable_records_are_stable(given):
    wrong = []
    for s in STABLE_SEEDS:
        r = simulated_record(s, speed_wander=WANDER)
        t = r.truth
        assert t["chatter"] is False
        d = detect_chatter(r, DetectSettings(speed_rpm=t["speed_rpm"] if given else None,
                                             n_inserts=t["n_inserts"]))
        if d.chatter:
            wrong.append(s)
    assert wrong == []


def test_steady_bands_call_the_wandering_stable_records_chatter(monkeypatch):
    """The records above are a case for the spread: with it held at 0 (bands for a steady
    speed) they are called chatter."""
    import robobore.measure.detect as detect

    monkeypatch.setattr(detect, "speed_spread", lambda *a: 0.0)
    called = [s for s in STABLE_SEEDS
              if detect.detect_chatter(simulated_record(s, speed_wander=WANDER)).chatter]
    assert called == list(STABLE_SEEDS)


def test_wandering_chatter_records_still_chatter():
    n, ferr = 0, []
    for s in range(40):
        r = simulated_record(s, speed_wander=WANDER)
        t = r.truth
        if not t["chatter"] or s == 34:  # 34: period-doubled, missed at a steady speed too
            continue
        n += 1
        d = detect_chatter(r, DetectSettings(n_inserts=t["n_inserts"]))
        assert d.chatter, s
        ferr.append(abs(d.chatter_frequency_Hz / t["chatter_frequency_Hz"] - 1))
    assert n >= 15 and np.mean(np.array(ferr) <= 0.02) >= 0.95


def test_speed_wander_input_checked():
    with pytest.raises(InputError, match="speed wander"):
        simulated_record(0, speed_wander=0.3)


def test_cli_synthetic_speed_wander(tmp_path):
    runner = CliRunner()
    p = tmp_path / "w.csv"
    r = runner.invoke(app, ["measure", "synthetic", str(p), "--seed", "29", "--speed-wander",
                            str(WANDER), "--json"])
    assert r.exit_code == 0, r.output
    truth = json.loads(r.stdout)["truth"]
    assert truth["speed_wander"] == WANDER and truth["chatter"] is False
    r = runner.invoke(app, ["detect", "chatter", str(p), "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert out["chatter"] is False and out["speed_spread"] > 0.0
    r = runner.invoke(app, ["measure", "synthetic", str(tmp_path / "f.txt"), "--kind", "force",
                            "--speed-wander", "0.003"])
    assert r.exit_code == 2 and "--speed-wander" in r.output


def test_cli_speed_wander_out_of_range_names_the_option(tmp_path):
    """0.3 for 0.3 % (a percent slip by 100) is refused naming the option and its range."""
    r = CliRunner().invoke(app, ["measure", "synthetic", str(tmp_path / "w.csv"),
                                 "--speed-wander", "0.3"])
    assert r.exit_code == 2
    assert "--speed-wander" in r.output and "0 .. 0.05" in r.output
    assert not (tmp_path / "w.csv").exists()
