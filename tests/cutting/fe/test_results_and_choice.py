"""The typed FE results' JSON (``to_dict``) and the model chooser, without running a model.

The values of a run's JSON are held by tests/cutting/fe/test_fe_digits.py (the whole JSON of
each stored case); here the keys a summary writes, in order, against the stored JSON, and the
model each config and device choose.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from robobore.cutting.fe.config.boring3d import load_boring_config, parse_boring_config
from robobore.cutting.fe.config.orthogonal import load_fe_config
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.hex import layout3d
from robobore.cutting.fe.mesh import memory
from robobore.cutting.fe.models import choose as C
from robobore.cutting.fe.models import results as R
from robobore.errors import ConfigError
from robobore.io.config import load_toml

EX = Path(__file__).parents[3] / "examples"
CONTRACT = Path(__file__).parent / "contract"
#: keys the CLI adds to a summary's JSON
CLI_KEYS = ("warnings", "mechanistic_comparison")


def _filled(cls, **given):
    """An instance of the record ``cls`` with every field without a default set to a value of
    its type (nested records filled alike), ``given`` on top."""
    out = {}
    for f in dataclasses.fields(cls):
        if f.name in given or f.default is not dataclasses.MISSING:
            continue
        t = str(f.type)
        sub = getattr(R, t, None)
        if sub is not None and dataclasses.is_dataclass(sub):
            out[f.name] = _filled(sub)
        elif t.startswith("tuple"):
            out[f.name] = (1.0, 2.0)
        elif t in ("int",):
            out[f.name] = 1
        elif t.startswith("str"):
            out[f.name] = "x"
        else:
            out[f.name] = 1.5
    return cls(**out, **given)


def _stored_keys(name: str) -> list[str]:
    return [k for k in json.loads((CONTRACT / f"{name}.json").read_text()) if k not in CLI_KEYS]


def test_orthogonal_summary_writes_the_stored_keys_in_order():
    faces = R.FaceForces(*(R.FaceForce(1.0, 2.0) for _ in range(3)))
    s = _filled(R.OrthogonalSummary, force_by_face_N_per_mm=faces)
    assert list(s.to_dict()) == _stored_keys("contract")
    assert s.to_dict()["force_by_face_N_per_mm"]["edge"] == {"cutting": 1.0, "feed": 2.0}
    sup = _filled(R.ToolSupport2D)
    d = dataclasses.replace(s, tool_support=sup).to_dict()
    assert list(d) == _stored_keys("tool_support")  # the support's keys flat, at the end
    assert "force_by_face_N_per_mm" not in dataclasses.replace(
        s, force_by_face_N_per_mm=None).to_dict()
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.steps = 2  # type: ignore[misc]


def test_boring_summary_writes_the_stored_keys_in_order():
    s = _filled(R.BoringSummary, feed_amplitude_um=None, sliding_speed_mean_m_per_s=None,
                separation="erosion_layer", mesh_shape=(4, 5, 6))
    d = s.to_dict()
    assert list(d) == _stored_keys("boring_paper")
    assert d["mesh_shape"] == [4, 5, 6] and d["feed_amplitude_um"] is None
    assert d["force_rotating_N"] == {"tangential": 1.5, "radial": 1.5, "feed": 1.5}
    tf = _filled(R.ToolFrameMeshSummary, mass_ratio=1.0)
    d = dataclasses.replace(s, mesh_shape=None, toolframe_mesh=tf).to_dict()
    assert "mesh_shape" not in d and d["toolframe_mesh"]["mass_ratio"] == 1.0
    assert "inertia_factor_max" not in d["toolframe_mesh"]


def test_every_field_of_a_result_is_documented():
    # each field carries a "#:" comment in results.py (the field-by-field documentation)
    src = (Path(R.__file__)).read_text().splitlines()
    for cls in (R.OrthogonalSummary, R.BoringSummary, R.SlabSummary, R.ToolSupport2D,
                R.ToolSupport3D, R.ToolFrameMeshSummary, R.RotatingForce):
        start = next(i for i, line in enumerate(src) if line.startswith(f"class {cls.__name__}("))
        body = src[start:]
        for f in dataclasses.fields(cls):
            i = next(i for i, line in enumerate(body) if line.startswith(f"    {f.name}:"))
            assert body[i - 1].strip().startswith("#:"), (cls.__name__, f.name)


def test_the_chooser_picks_the_model_of_the_frame():
    cfg = load_fe_config(EX / "fe_orthogonal_toolframe_calibrated.toml")
    m = C.choose_orthogonal(cfg)
    assert type(m) is C.Orthogonal2DTool and m.tool_frame and m.layout is layout
    assert m.estimated_elements() == memory.fe2d_elements(cfg)
    w = C.choose_orthogonal(load_fe_config(EX / "fe_orthogonal_nodesplit.toml"))
    assert type(w) is C.Orthogonal2DWork and not w.tool_frame and w.frame == "workpiece"
    b = load_boring_config(EX / "fe_boring_paper.toml")
    bm = C.choose_boring(b)
    assert type(bm) is C.Boring3DTool and bm.layout is layout3d
    d = load_toml(EX / "fe_boring_paper.toml")
    d["mesh"]["frame"] = "workpiece"
    bw = C.choose_boring(parse_boring_config(d))
    assert type(bw) is C.Boring3DWork and bw.estimated_elements() == memory.fe3d_elements(
        parse_boring_config(d))


def test_the_chooser_refuses_a_device_a_model_cannot_run_on():
    b = load_boring_config(EX / "fe_boring_paper.toml")
    with pytest.raises(ConfigError, match="CPU only") as ei:
        C.choose_boring(b, "gpu", "b.toml")
    assert ei.value.field == "--device" and "b.toml" in str(ei.value)
    for choose, cfg in ((C.choose_boring, b),
                        (C.choose_orthogonal, load_fe_config(EX / "fe_orthogonal.toml"))):
        with pytest.raises(ConfigError, match="unknown device"):
            choose(cfg, "tpu")
