"""Tool-point modal model: FRF against the SDOF closed form, input validation."""

from __future__ import annotations

import numpy as np
import pytest

from robobore.dynamics.structure import ToolPointStructure
from robobore.errors import ConfigError


def test_frf_matches_sdof_closed_form(sdof):
    """G_xx(w) = d_x^2 / (k (1 - r^2 + 2 i zeta r)); at resonance |G| = 1/(2 k zeta) d_x^2."""
    w = 2 * np.pi * np.array([100.0, 250.0, 400.0])
    G = sdof.frf(w)
    d = sdof.directions[0]
    r = w / (2 * np.pi * 250.0)
    ref = d[0] ** 2 / (2.26e8 * (1 - r**2 + 2j * 0.012 * r))
    assert np.allclose(G[0, 0], ref, rtol=1e-12)
    assert abs(G[0, 0, 1]) == pytest.approx(d[0] ** 2 / (2 * 2.26e8 * 0.012), rel=1e-12)
    assert np.allclose(G[0, 1], G[1, 0])  # reciprocity


@pytest.mark.parametrize("mode, key, words", [
    ({"stiffness_N_per_m": -2.0e8}, "structure.modes[0].stiffness_N_per_m", "out of range"),
    ({"direction": [0.0, 0.0, 0.0]}, "structure.modes[0].direction", "zero-length"),
    ({"direction": [1.02, 0.0, 0.0]}, "structure.modes[0].direction", "off unit length"),
    ({"damping_ratio": 1.5}, "structure.modes[0].damping_ratio", "out of range"),
    ({"frequency_Hz": "fast"}, "structure.modes[0].frequency_Hz", "not a number"),
])
def test_bad_modes_name_the_key(mode, key, words):
    m = {"frequency_Hz": 250.0, "damping_ratio": 0.01, "stiffness_N_per_m": 1e8,
         "direction": [1.0, 0.0, 0.0]}
    m.update(mode)
    with pytest.raises(ConfigError) as ei:
        ToolPointStructure.from_modes([m], file="cfg.toml")
    assert ei.value.field == key
    assert words in str(ei.value) and "cfg.toml" in str(ei.value)


def test_direction_within_one_percent_is_normalised():
    st = ToolPointStructure.from_modes([{"frequency_Hz": 100.0, "damping_ratio": 0.02,
                                         "stiffness_N_per_m": 1e7, "direction": [0.995, 0, 0]}])
    assert np.allclose(st.directions[0], [1.0, 0.0, 0.0])
