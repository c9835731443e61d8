"""Shared helpers of the study tests."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest


def write_sweep_toml(path: Path, *, speeds=(200, 400, 600), feeds=(0.1, 0.3),
                     depths=(0.05, 0.2), pressures=(0.0,), runner_options: str = "",
                     name: str = "t") -> Path:
    """A small demo sweep config file."""
    text = f"""
[sweep]
name = "{name}"
runner = "demo"
seed = 3

[grid]
speed_rpm = {list(speeds)}
feed_mm_per_rev = {list(feeds)}
depth_of_cut_mm = {list(depths)}
pressure_MPa = {list(pressures)}

[model]
duration_s = 2.0

[runner_options]
{runner_options}
"""
    path.write_text(text)
    return path


@pytest.fixture
def sweep_toml(tmp_path: Path) -> Path:
    return write_sweep_toml(tmp_path / "sweep.toml")


def robobore_cmd(*args: str) -> list[str]:
    """Command line that runs ``robobore ARGS`` with this interpreter."""
    return [sys.executable, "-c", "from robobore.cli import main; main()", *args]


def subprocess_env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONUNBUFFERED"] = "1"
    return env
