"""Both engines stop a run whose energy balance is lost (``solver.energy_error_limit``), with
an error naming the step, the time and the limit, once a tenth of the cut after first contact
is done (engine.chunk_driver.energy_check)."""

from __future__ import annotations

import re

import pytest

from robobore.cutting.fe.config.boring3d import parse_boring_config
from robobore.cutting.fe.config.orthogonal import parse_config
from robobore.cutting.fe.engine.chunk_driver import energy_check
from robobore.cutting.fe.models.boring3d import simulate_boring
from robobore.cutting.fe.models.orthogonal import simulate_orthogonal
from robobore.errors import NumericalError

_MSG = re.compile(r"energy balance lost at step \d+, time [0-9.e-]+ s: error [0-9.e-]+ > "
                  r"solver.energy_error_limit 1e-09")


def test_check_waits_for_a_tenth_of_the_cut_after_contact():
    class S:
        def __init__(self, t):
            self.time = t
            self.en = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
            self.ist = [7]

    check = energy_check(t_contact=1.0, t_end=11.0, limit=0.5)
    check(S(1.9))  # before contact + 1.0: not checked even though the balance is lost
    with pytest.raises(NumericalError, match="energy balance lost at step 7"):
        check(S(2.1))


def test_2d_run_stops_on_a_lost_balance():
    cfg = parse_config({"tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
                        "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                                "length_mm": 0.02},
                        "mesh": {"element_size_um": 10.0},
                        "solver": {"energy_error_limit": 1e-9}})
    with pytest.raises(NumericalError, match=_MSG):
        simulate_orthogonal(cfg)


def test_3d_run_stops_on_a_lost_balance():
    cfg = parse_boring_config({
        "insert": {"edge_radius_um": 10.0},
        "cut": {"depth_of_cut_mm": 0.06, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0,
                "cut_length_mm": 0.06},
        "mesh": {"element_size_um": 20.0, "frame": "workpiece", "ahead_mm": 0.04},
        "solver": {"n_samples": 40, "energy_error_limit": 1e-9}})
    with pytest.raises(NumericalError, match=_MSG):
        simulate_boring(cfg)
