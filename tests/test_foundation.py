"""Foundation: error messages, config validation, atomic writes, CLI wiring."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from pydantic import BaseModel, Field
from typer.testing import CliRunner

from robobore.cli import app
from robobore.errors import ConfigError, InputError
from robobore.io.config import dump_toml, load_toml, validate_model
from robobore.io.results import atomic_write_text, to_jsonable, write_json, write_netcdf


def test_input_error_names_everything():
    e = InputError("not a number", file="c.csv", row=3, field="q1_deg", value="abc",
                   expected="a number in deg")
    s = str(e)
    for part in ("c.csv", "row 3", "q1_deg", "'abc'", "a number in deg"):
        assert part in s


class _Inner(BaseModel):
    stiffness_N_per_m: float = Field(gt=0)


class _Cfg(BaseModel):
    inner: _Inner


def test_validate_model_names_key_and_file():
    with pytest.raises(ConfigError) as ei:
        validate_model(_Cfg, {"inner": {"stiffness_N_per_m": -1.0}}, source="x.toml")
    assert ei.value.field == "inner.stiffness_N_per_m"
    assert "x.toml" in str(ei.value) and "-1.0" in str(ei.value)
    # the value is shown once (it was doubled: "(got -1.0) (got -1.0)") and kept as data
    assert str(ei.value).count("(got -1.0)") == 1, str(ei.value)
    assert ei.value.value == -1.0


def test_load_toml_errors(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_toml(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[a\nb = ")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_toml(bad)


def test_dump_toml_reads_back_every_example_and_edge_values():
    for f in sorted((Path(__file__).parents[1] / "examples").glob("*.toml")):
        d = load_toml(f)
        assert tomllib.loads(dump_toml(d)) == d, f.name
    d = {"top": 1, "a b": "x\"y", "t": {"nested": {"flag": False, "v": [1.5, -2]}, "e": {}},
         "rows": [{"k": 1, "sub": {"q": "w"}}, {"k": 2}], "inline": [[1, 2], []],
         "odd": {"nan": float("nan"), "inf": float("-inf")}}
    r = tomllib.loads(dump_toml(d))
    assert math.isnan(r["odd"].pop("nan")) and math.isnan(d["odd"].pop("nan"))
    assert r == d
    with pytest.raises(TypeError):
        dump_toml({"x": object()})


def test_atomic_write_leaves_no_temp(tmp_path):
    p = atomic_write_text(tmp_path / "sub" / "a.txt", "hello")
    assert p.read_text() == "hello"
    assert [f.name for f in p.parent.iterdir()] == ["a.txt"]
    assert p.stat().st_mode & 0o044 == 0o044  # readable by others under the usual umask 022


def test_json_and_netcdf_roundtrip(tmp_path):
    obj = {"a": np.float64(1.5), "b": np.arange(3), "c": float("nan"), "d": np.bool_(True)}
    assert to_jsonable(obj) == {"a": 1.5, "b": [0, 1, 2], "c": None, "d": True}
    write_json(tmp_path / "r.json", obj)
    assert json.loads((tmp_path / "r.json").read_text())["b"] == [0, 1, 2]
    ds = xr.Dataset({"f": ("t", np.arange(4.0))})
    ds["f"].attrs["units"] = "N"
    write_netcdf(ds, tmp_path / "r.nc", config={"k": 1}, seed=7)
    back = xr.open_dataset(tmp_path / "r.nc")
    assert back.attrs["robobore_seed"] == 7
    assert json.loads(back.attrs["robobore_config"]) == {"k": 1}
    assert back["f"].attrs["units"] == "N"
    back.close()


def test_cli_version_and_help():
    r = CliRunner().invoke(app, ["--version"])
    assert r.exit_code == 0 and "robobore" in r.stdout
    r = CliRunner().invoke(app, ["--help"])
    assert r.exit_code == 0


def test_installed_package_has_every_data_file():
    """Every non-Python file in the source tree ships with the installed package (the tests
    may run against a wheel install, as in CI; a file left out of package-data breaks users)."""
    from pathlib import Path

    import robobore

    src = Path(__file__).resolve().parents[1] / "src" / "robobore"
    if not src.is_dir():
        pytest.skip("no source tree beside the tests")
    installed = Path(robobore.__file__).resolve().parent
    skip_parts = {"__pycache__"}
    missing = []
    for f in src.rglob("*"):
        if f.is_dir() or f.suffix in {".py", ".pyc", ".nbi", ".nbc"}:
            continue
        rel = f.relative_to(src)
        if skip_parts & set(rel.parts) or rel.name.startswith("."):
            continue
        if not (installed / rel).is_file():
            missing.append(str(rel))
    assert not missing, f"not installed (add to package-data in pyproject.toml): {missing}"


def test_cli_error_keeps_square_brackets():
    """Rich markup must not eat '[process]' or '[mm]' from error messages and tables."""
    import typer

    from robobore.clitools import handle_errors, kv_table

    demo = typer.Typer()

    @demo.command()
    @handle_errors
    def boom() -> None:
        raise ConfigError("missing section", field="[process]", expected="depth in [mm]")

    r = CliRunner().invoke(demo, [])
    assert r.exit_code == 2
    assert "[process]" in r.output and "[mm]" in r.output
    from rich.console import Console

    con = Console(record=True, width=80)
    con.print(kv_table("t", [("depth [mm]", 1.0)]))
    assert "depth [mm]" in con.export_text()


@pytest.mark.parametrize("cmd", [
    ["robot", "fk"], ["robot", "stiffness"], ["robot", "campaign"],
    ["identify", "stiffness"], ["identify", "modes"],
    ["model", "equivalent"], ["simulate", "boring"], ["lobes"],
    ["fe", "orthogonal"], ["fe", "boring"],
    ["calibrate", "forces"], ["sweep"], ["compare"], ["paper"],
])
def test_every_contract_command_is_reachable(cmd):
    """The commands the issues' contracts name exist on the one `robobore` app."""
    r = CliRunner().invoke(app, [*cmd, "--help"])
    assert r.exit_code == 0, r.output
    assert "--json" in r.output
