"""Shared fixtures of the process-stage tests (structures and processes from the contract)."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.dynamics.process import single_point_process
from robobore.dynamics.structure import ToolPointStructure

CONTRACT_MODE = {"frequency_Hz": 250.0, "damping_ratio": 0.012, "stiffness_N_per_m": 2.26e8,
                 "direction": [0.866, 0.5, 0.0]}


@pytest.fixture(scope="session")
def sdof():
    return ToolPointStructure.from_modes([CONTRACT_MODE])


@pytest.fixture(scope="session")
def contract_process():
    return single_point_process(1.0e9, [1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.1e-3)


def _coupling_case(overlap: float = 1.0):
    """Two orthogonal robot-like modes of close frequency (20, 21 Hz, 2 % damping) at 40 deg to
    the chip normal (x), the cutting force at 75 deg between them (Pan et al. 2006 geometry)."""
    t = np.radians(40.0)
    d1 = [np.cos(t), np.sin(t), 0.0]
    d2 = [-np.sin(t), np.cos(t), 0.0]
    k = 1.0e6
    st = ToolPointStructure.from_modes([
        {"frequency_Hz": 20.0, "damping_ratio": 0.02, "stiffness_N_per_m": k, "direction": d1},
        {"frequency_Hz": 21.0, "damping_ratio": 0.02, "stiffness_N_per_m": k * (21 / 20) ** 2,
         "direction": d2}])
    u = [np.cos(np.radians(75.0)), np.sin(np.radians(75.0)), 0.0]
    pr = single_point_process(2.0e9, u, [1.0, 0.0, 0.0], 0.1e-3, overlap=overlap)
    return st, pr


@pytest.fixture(scope="session")
def coupling_case():
    """Factory of the two-mode mode-coupling case (see ``_coupling_case``)."""
    return _coupling_case
