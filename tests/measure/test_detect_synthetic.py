"""Chatter detection on SYNTHETIC records of robobore's time-domain simulation, labelled by
the simulation's own verdict (robobore.measure.synthetic): accuracy and chatter frequency,
with and without the spindle speed; level independence."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.measure.detect import DetectSettings, detect_chatter
from robobore.measure.records import make_record
from robobore.measure.synthetic import labelled_set

N_RECORDS = 60


@pytest.fixture(scope="module")
def records():
    return labelled_set(N_RECORDS, seed=1000)


def _score(records, given: bool):
    conf = {"tp": 0, "tn": 0, "fp": 0, "fn": 0}
    ferr = []
    for r in records:
        t = r.truth
        d = detect_chatter(r, DetectSettings(speed_rpm=t["speed_rpm"] if given else None,
                                             n_inserts=t["n_inserts"]))
        key = ("t" if d.chatter == t["chatter"] else "f") + ("p" if d.chatter else "n")
        conf[key] += 1
        if d.chatter and t["chatter"]:
            ferr.append(abs(d.chatter_frequency_Hz / t["chatter_frequency_Hz"] - 1))
    return conf, np.array(ferr)


def test_labels_hold_both_classes(records):
    n_ch = sum(r.truth["chatter"] for r in records)
    assert 0.25 * N_RECORDS < n_ch < 0.75 * N_RECORDS
    assert all(r.kind == "SYNTHETIC" for r in records)


@pytest.mark.parametrize("given", [False, True], ids=["speed estimated", "speed given"])
def test_detection_accuracy_and_frequency(records, given):
    conf, ferr = _score(records, given)
    right = (conf["tp"] + conf["tn"]) / N_RECORDS
    print(f"speed {'given' if given else 'estimated'}: confusion {conf}, right {right:.3f}, "
          f"frequency error max {ferr.max():.4f}, within 2 % {np.mean(ferr <= 0.02):.3f}")
    assert right >= 0.98  # the target on records of the simulation
    assert conf["fp"] <= 1  # a stable cut is not called chatter
    assert np.mean(ferr <= 0.02) >= 0.95


def test_gain_changes_nothing(records):
    for r in records[:6]:
        a = detect_chatter(r)
        b = detect_chatter(make_record(r.signals * 100.0, r.sample_rate_Hz, r.channels))
        c = detect_chatter(make_record(r.signals * 1e-4 + 3.0, r.sample_rate_Hz, r.channels))
        assert a.chatter == b.chatter == c.chatter
        assert [w["chatter"] for w in a.windows] == [w["chatter"] for w in b.windows]
        if a.chatter:
            assert b.chatter_frequency_Hz == pytest.approx(a.chatter_frequency_Hz, rel=1e-9)


def test_speed_error_of_one_percent_is_tolerated(records):
    for r in records[:10]:
        t = r.truth
        a = detect_chatter(r, DetectSettings(speed_rpm=t["speed_rpm"]))
        b = detect_chatter(r, DetectSettings(speed_rpm=1.01 * t["speed_rpm"]))
        assert a.chatter == b.chatter
