"""The set-up of the semi-discretisation at a trial depth (the steady deflection and the
process at that depth) equals the general routines it stands in for: the time domain's
nominal-cut orbit and the process rebuilt from the chip geometry."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.cutting.forces import ti64_coefficients
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics import semidiscretization as sd
from robobore.dynamics.process import boring_process
from robobore.dynamics.structure import ToolPointStructure
from robobore.dynamics.timedomain import nominal_cut_deflection

#: SYNTHETIC robot-like tool point: three modes of 7-25 Hz in three directions
MODES = [
    {"frequency_Hz": 6.9, "damping_ratio": 0.03, "stiffness_N_per_m": 1.2e6,
     "direction": [0.8, 0.6, 0.0]},
    {"frequency_Hz": 16.8, "damping_ratio": 0.025, "stiffness_N_per_m": 2.5e6,
     "direction": [-0.6, 0.8, 0.0]},
    {"frequency_Hz": 24.6, "damping_ratio": 0.02, "stiffness_N_per_m": 4.0e6,
     "direction": [0.0, 0.6, 0.8]},
]


@pytest.fixture(scope="module")
def structure():
    return ToolPointStructure.from_modes(MODES)


@pytest.mark.parametrize("n_inserts", [1, 2, 3])
@pytest.mark.parametrize("depth_m", [0.2e-3, 0.7e-3, 3.0e-3])
def test_deflection_kernel_is_the_time_domain_orbit(structure, n_inserts, depth_m):
    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=75.0, n_inserts=n_inserts)
    pr = boring_process(ins, ti64_coefficients(), depth_m, 0.15e-3)
    for speed in (150.0, 433.0, 1100.0):
        r1, r0 = nominal_cut_deflection(structure, pr, speed, sd.DEFLECTION_SAMPLES)
        q1, q0 = sd._deflection_parts_uncached(structure, pr, speed)
        assert q1.shape == r1.shape and q0.shape == r0.shape
        assert np.abs(q1 - r1).max() <= 1e-11 * np.abs(r1).max()
        assert np.abs(q0 - r0).max() <= 1e-11 * np.abs(r0).max()


def test_deflection_without_trailing_edge_has_no_fixed_part(structure):
    ins = BoringInsert(nose_radius_m=0.4e-3, approach_angle_deg=90.0)
    pr = boring_process(ins, ti64_coefficients(), 1e-3, 0.1e-3, trailing_edge=False)
    q1, q0 = sd._deflection_parts_uncached(structure, pr, 500.0)
    r1, _ = nominal_cut_deflection(structure, pr, 500.0, sd.DEFLECTION_SAMPLES)
    assert q0 is None
    assert np.abs(q1 - r1).max() <= 1e-11 * np.abs(r1).max()
