"""SYNTHETIC richer-truth validation of the pose-dependent model (robobore.plan.synthetic).

Truth: joint springs + link bending (lower arm and forearm, springs from beam estimates of
their sections) + distributed link masses different from the library's estimates. The
planner's model gets joint stiffnesses fitted over a 12-posture campaign and the truth's
modes below 60 Hz at the paper's posture, calibrates there and predicts at 24 held-out
postures (0.23-3.7 m from the measured tool point; at least 0.05 from a singularity).
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.plan.synthetic import run_validation


@pytest.fixture(scope="module")
def val():
    return run_validation()


def test_first_three_frequencies_within_5_percent_at_heldout_postures(val):
    err = np.abs(np.asarray(val["frequency_error_percent"]))
    assert err.shape == (24, 3)
    assert err.max() <= 5.0
    # the postures really are spread: the truth's frequencies change by a factor > 2
    lo, hi = val["truth_frequency_ratio_to_measured_range"]
    assert lo < 0.9 and hi > 2.0
    assert val["heldout_distance_from_measured_m"][1] > 3.0


def test_directional_stiffness_at_heldout_postures(val):
    """Measured state (docs/plan.md): the 5 % target holds at 21 of the 24 postures and in
    the rms (2.4 %); the largest error is 8.4 %, where link bending carries 2.3 times its
    share of the compliance at the calibration posture, which joint springs cannot follow."""
    err = np.abs(np.asarray(val["stiffness_error_percent"]))
    assert err.shape == (24, 3)
    assert val["rms_stiffness_error_percent"] <= 5.0
    assert val["heldout_within_5_percent"]["stiffness"] >= 20
    assert err.max() <= 10.0


def test_calibration_residual_and_identified_stiffness(val):
    assert val["calibration"]["rms_frequency_residual_percent"] < 2.0
    k = np.asarray(val["identified_joint_stiffness_Nm_per_rad"])
    kt = np.asarray(val["truth_joint_stiffness_Nm_per_rad"])
    # the joint springs absorb the bending: identified values are softer, not wildly off
    assert np.all(k <= kt * 1.01) and np.all(k >= 0.8 * kt)
