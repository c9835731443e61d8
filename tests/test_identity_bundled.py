"""No bundled example config, example robot or data file (also ../shared/data) is refused
by the identity checks: each goes through the reader its command uses, which checks the
identity of the files it names (robot, posture, modes fit, coefficients' material and
insert)."""

from __future__ import annotations

from pathlib import Path

import pytest

from robobore.errors import ConfigError

REPO = Path(__file__).resolve().parents[1]
EX = REPO / "examples"
DATA = REPO / "src" / "robobore" / "data"
SHARED = REPO.parent / "shared" / "data"
PB = EX / "plan_paper_bore"


def _load(path: Path) -> None:
    n = path.name
    if n.startswith("plan_"):
        from robobore.plan.config import load_plan_config

        load_plan_config(path)
    elif n.startswith("fe_boring"):
        from robobore.cutting.fe.config.boring3d import load_boring_config

        load_boring_config(path)
    elif n.startswith("fe_"):
        from robobore.cutting.fe.config.orthogonal import load_fe_config

        load_fe_config(path)
    elif n.startswith("calibration"):
        from robobore.cutting.calibration_config import load_calibration_config

        load_calibration_config(path)
    elif n.startswith("sweep"):
        from robobore.study.conditions import load_sweep_config

        load_sweep_config(path)
    elif n == "paper.toml":
        from robobore.study.paper_config import load_paper_config

        load_paper_config(path)
    else:  # process configs: lobes / simulate boring
        from robobore.dynamics.config import build_coefficients, load_dynamics_config

        try:
            cfg, _ = load_dynamics_config(path)
        except ConfigError:  # a process-only config: the robot from the example files
            cfg, _ = load_dynamics_config(path, stiffness_file=PB / "joint_stiffness.json",
                                          modes_file=PB / "modes.json")
        if cfg.is_boring:
            build_coefficients(cfg, str(path))


CONFIGS = sorted([*EX.glob("*.toml"), DATA / "paper_example" / "paper.toml"])


@pytest.mark.parametrize("path", CONFIGS, ids=lambda p: p.name)
def test_bundled_config_passes_the_identity_checks(path):
    _load(path)


@pytest.mark.parametrize("path", sorted((EX / "robots").glob("*.toml")), ids=lambda p: p.name)
def test_example_robot_loads(path):
    from robobore.robot.description import get_robot

    assert get_robot(str(path)).links


def test_bundled_and_shared_data_files_pass_their_readers():
    import json

    from robobore.cutting.fe.models.validate import read_measured
    from robobore.io.identity import cut_identity_of
    from robobore.modal.example import example_path
    from robobore.modal.io import load_input

    coef = DATA / "paper_example" / "tc4_fe_coefficients.json"
    ident = cut_identity_of(json.loads(coef.read_text()), str(coef))
    assert ident["material"] == "TC4" and ident["insert"]["rake_deg"] == 7.0
    load_input(example_path())
    for p in sorted(SHARED.glob("*.json")) + sorted(DATA.rglob("ti64_orthogonal*.json")):
        read_measured(p)
