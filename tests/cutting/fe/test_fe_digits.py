"""The FE engines' results to 1e-9, stored: the default validation configuration, the contract
config, the tool-support example and the 3D paper condition (on the workpiece frame at mass
scaling 100) and in the tool frame, each on a short cut. A run gives the same digits whether
its process compiles the engines or loads them from numba's cache (the 3D element's fastmath is
FMA contraction only: robobore.cutting.fe.hex.element).

The engines are deterministic (the same digits on any thread count and chunk size,
tests/cutting/fe/test_fe_threads.py), so any change to the code that is meant to keep the
physics (a restructure, a faster loop) must reproduce these digits. A change that is meant to
change the physics updates them in the same commit, with the reason in the commit message.
The runs go through the CLI (`robobore fe orthogonal|boring CONFIG --json`), so the test does
not depend on how the engine's modules are laid out; each run's whole JSON (its keys in order
and their values to 1e-9, the wall time and throughput aside) is held to the one stored in
``tests/cutting/fe/contract/``, the JSON contract of the typed results' ``to_dict``.

Regenerate: ``python tests/cutting/fe/test_fe_digits.py`` prints the current digits;
``--contract`` also rewrites the stored JSON.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from robobore.io.config import dump_toml, load_toml

_EX = Path(__file__).parents[3] / "examples"

#: case -> (example file, section and key of the cut length, short cut length [mm], CLI
#: subcommand, outputs compared, other keys set {(section, key): value})
CASES = {
    "validation_config": ("fe_orthogonal_toolframe_calibrated.toml", ("cut", "length_mm"), 0.01,
                          "orthogonal", ("cutting_force_N_per_mm", "feed_force_N_per_mm",
                                         "steps"), {}),
    "contract": ("fe_orthogonal.toml", ("cut", "length_mm"), 0.01, "orthogonal",
                 ("cutting_force_N_per_mm", "feed_force_N_per_mm", "steps"), {}),
    "tool_support": ("fe_orthogonal_tool_support.toml", ("cut", "length_mm"), 0.03,
                     "orthogonal", ("cutting_force_N_per_mm", "feed_force_N_per_mm", "steps",
                                    "tool_dx_mean_um", "tool_dy_mean_um"), {}),
    "boring_paper": ("fe_boring_paper.toml", ("cut", "cut_length_mm"), 0.02, "boring",
                     ("force_rotating_N", "steps"),
                     {("mesh", "frame"): "workpiece", ("solver", "mass_scaling"): 100.0}),
    # the tool frame (ALE) on a coarser mesh at more mass scaling: about 5,000 steps
    "boring_paper_toolframe": ("fe_boring_paper.toml", ("cut", "cut_length_mm"), 0.016,
                               "boring", ("force_rotating_N", "steps"),
                               {("mesh", "element_size_um"): 16.0,
                                ("solver", "mass_scaling"): 1600.0}),
}

#: digits of the engines at the stored commit (see the module docstring)
EXPECTED: dict[str, dict] = {
    "validation_config": {
        "cutting_force_N_per_mm": 128.45242508266676,
        "feed_force_N_per_mm": 46.017717160532754,
        "steps": 18192
    },
    "contract": {
        "cutting_force_N_per_mm": 128.45242508266676,
        "feed_force_N_per_mm": 46.017717160532754,
        "steps": 18192
    },
    "tool_support": {
        "cutting_force_N_per_mm": 93.25557868854906,
        "feed_force_N_per_mm": 31.6974573140153,
        "steps": 18966,
        "tool_dx_mean_um": 4.034106611982266,
        "tool_dy_mean_um": 0.8414518106925286
    },
    "boring_paper": {
        "force_rotating_N": {
            "tangential": 17.095214502129565,
            "radial": -7.02022382076883,
            "feed": -1.2345788895525702
        },
        "steps": 15597
    },
    "boring_paper_toolframe": {
        "force_rotating_N": {
            "tangential": 22.421163072530415,
            "radial": -14.599143110549408,
            "feed": -2.3042958226527013
        },
        "steps": 5114
    }
}


def run_json(name: str, tmp: Path) -> dict:
    """The whole JSON ``robobore fe ... --json`` writes for the case ``name``."""
    example, (sec, key), length, sub, keys, other = CASES[name]
    d = load_toml(_EX / example)
    d[sec][key] = length
    for (s, k), v in other.items():
        d[s][k] = v
    cfg = tmp / f"{name}.toml"
    cfg.write_text(dump_toml(d))
    out = subprocess.run([sys.executable, "-m", "robobore", "fe", sub, str(cfg), "--json"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout)


def run_case(name: str, tmp: Path) -> dict:
    return {k: run_json(name, tmp)[k] for k in CASES[name][4]}


def _close(a, b, rel: float = 1e-9, floor: float = 1e-300) -> bool:
    if isinstance(a, dict):
        return (isinstance(b, dict) and list(a) == list(b)
                and all(_close(a[k], b[k], rel, floor) for k in a))
    if isinstance(a, list):
        return (isinstance(b, list) and len(a) == len(b)
                and all(_close(x, y, rel, floor) for x, y in zip(a, b, strict=True)))
    if isinstance(a, float) and isinstance(b, float):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return abs(a - b) <= max(rel * max(abs(a), abs(b)), floor)
    return type(a) is type(b) and a == b


#: the whole JSON of each case at the stored commit, timing figures set to None
#: (tests/cutting/fe/contract/CASE.json): the run's JSON contract, key by key
_CONTRACT = Path(__file__).parent / "contract"
_TIMING = ("wall_time_s", "element_updates_per_s")
#: the absolute floor of the JSON comparison: the X and Y means of the boring-frame force
#: over a revolution are sums that cancel to round-off (~1e-16 N; a force component of the
#: run's ~1e-15 relative round-off moves them by as much), compared to 1e-12 in their unit
_FLOOR = 1e-12


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_engine_reproduces_stored_digits(name, tmp_path):
    res = run_json(name, tmp_path)
    got = {k: res[k] for k in CASES[name][4]}
    assert _close(got, EXPECTED[name]), (name, got, EXPECTED[name])
    # the same keys in the same order, the same values (to 1e-9), as the stored JSON
    stored = json.loads((_CONTRACT / f"{name}.json").read_text())
    for k in _TIMING:
        assert isinstance(res[k], float) and res[k] > 0.0
        res[k] = None
    # the identity block (robobore.io.identity) names the run's config file, whose path
    # differs per run: checked by what it describes, the rest key by key
    ident = res.pop("identity")
    assert ident["kind"].startswith("fe ") and ident["synthetic"] is None, ident
    assert ident["material"] and ident["insert"], ident
    bad = [k for k in stored if k not in res or not _close(stored[k], res[k], floor=_FLOOR)]
    assert list(res) == list(stored) and not bad, (name, bad, list(res))


if __name__ == "__main__":
    import tempfile

    with tempfile.TemporaryDirectory() as t:
        runs = {n: run_json(n, Path(t)) for n in CASES}
    print(json.dumps({n: {k: r[k] for k in CASES[n][4]} for n, r in runs.items()}, indent=1))
    if "--contract" in sys.argv:  # rewrite the stored JSON of each case
        for n, r in runs.items():
            r.pop("identity")  # checked by what it describes, not stored
            (_CONTRACT / f"{n}.json").write_text(json.dumps({**r, **dict.fromkeys(_TIMING)},
                                                            indent=1))
