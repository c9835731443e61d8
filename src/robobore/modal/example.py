"""The bundled SYNTHETIC robotic-boring hammer test (``robobore/data/hammer_test``).

Regenerate with ``robobore identify virtual-hammer-test --example OUT.uff`` (same seed, same
file). Settings are the constants below; the ground truth is
:func:`robobore.modal.virtual.robot_boring_truth`.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from robobore.modal.virtual import robot_boring_truth, simulate_hammer_test

EXAMPLE_FILE = "robot_hammer_test.uff"
EXAMPLE_SETTINGS = {"n_hits": 5, "sample_rate_Hz": 256.0, "duration_s": 6.0, "tip": "soft",
                    "peak_force_N": 200.0, "noise_force": 0.02, "noise_response": 0.02,
                    "seed": 2026}
#: (node, direction) of the channels in the UFF file: node 1 tool point, 2 spindle housing,
#: 3 robot wrist; directions 1/2/3 = boring-frame X/Y/Z. Hammer at the tool point.
EXAMPLE_OUTPUT_DOFS = [(1, 1), (1, 2), (1, 3), (2, 1), (2, 2), (3, 1), (3, 3)]
EXAMPLE_INPUT_DOFS = [(1, 1), (1, 2), (1, 3)]
EXAMPLE_BAND_HZ = (3.0, 60.0)


def example_path() -> Path:
    """Path of the bundled example UFF file."""
    return Path(str(resources.files("robobore") / "data" / "hammer_test" / EXAMPLE_FILE))


def make_example(path: str | Path) -> Path:
    """Write the example time records (UFF 58 + 164) to ``path``."""
    from robobore.modal.io import write_uff_time

    rec = simulate_hammer_test(robot_boring_truth(), **EXAMPLE_SETTINGS)
    return write_uff_time(rec, path, EXAMPLE_INPUT_DOFS, EXAMPLE_OUTPUT_DOFS,
                          "SYNTHETIC robobore virtual hammer test (robot boring example)")


__all__ = ["example_path", "make_example", "EXAMPLE_SETTINGS", "EXAMPLE_BAND_HZ"]
