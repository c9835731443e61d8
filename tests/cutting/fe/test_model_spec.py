"""The typed model spec (:mod:`robobore.cutting.fe.config.spec`): what each bundled config
chooses, the parameter slots the spec writes, and the ConfigError for a key the chosen
variants have no place for (named with its value and what is expected)."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from robobore.cutting.fe.config.frame import Frame
from robobore.cutting.fe.config.orthogonal import load_fe_config, parse_config
from robobore.cutting.fe.config.spec import (
    Adiabatic,
    BBarQuad,
    Conduction,
    CoulombFriction,
    ErosionLayer,
    HardeningHold,
    NodeSplit,
    OnePointQuad,
    PlainHardening,
    SlidingSpeedFriction,
    ToolFrame,
    WorkpieceFrame,
)
from robobore.cutting.fe.config.spec_build import build_spec
from robobore.cutting.fe.engine import chunk_loop as CL
from robobore.cutting.fe.engine import layout
from robobore.cutting.fe.engine.state2d import default_prm
from robobore.errors import ConfigError
from robobore.material import load_material

EX = Path(__file__).parents[3] / "examples"


def _spec(cfg):
    mat = load_material(cfg.material.name, hardening_strain_limit=cfg.material.strain_limit())
    return build_spec(cfg, mat)


def _base(frame="workpiece", **sections):
    d = {"tool": {"rake_deg": 15.0, "clearance_deg": 2.0, "edge_radius_um": 20.0},
         "cut": {"uncut_chip_thickness_um": 60.0, "cutting_speed_m_per_min": 30.0,
                 "length_mm": 0.02},
         "mesh": {"element_size_um": 10.0, "frame": frame}, "solver": {}, "contact": {}}
    for sec, kv in sections.items():
        d.setdefault(sec, {}).update(kv)
    return d


def test_the_bundled_configs_choose_their_variants():
    s = _spec(load_fe_config(EX / "fe_orthogonal.toml"))
    assert s.frame == ToolFrame(ale_interval=10, element=OnePointQuad(0.05, 0.05))
    assert isinstance(s.friction, SlidingSpeedFriction) and s.friction.filter_um == 1.0
    assert s.friction.mu == (0.36, 0.33, 0.315, 0.285, 0.27, 0.255)
    assert isinstance(s.thermal, Conduction) and s.thermal.interval == 10
    assert s.hardening == HardeningHold(0.6)
    a = _spec(load_fe_config(EX / "fe_orthogonal_toolframe.toml"))  # the a-priori set
    assert isinstance(a.friction, CoulombFriction) and a.friction.shear_limit_MPa == 576.0
    assert a.friction.mu == pytest.approx(0.18) and a.hardening == PlainHardening()
    w = _spec(load_fe_config(EX / "fe_orthogonal_tool_support.toml"))
    assert isinstance(w.frame, WorkpieceFrame) and w.thermal == Adiabatic()
    assert w.frame.separation == ErosionLayer("centred", None, True, None)
    n = _spec(load_fe_config(EX / "fe_orthogonal_nodesplit.toml"))
    assert n.frame.separation == NodeSplit(height_um=5.0, gate_um=0.0)
    assert n.frame.erode_time_step_fraction == 0.05
    b = _spec(parse_config(_base(solver={"element": "q4_bbar"})))
    assert b.frame.element == BBarQuad()
    with pytest.raises(dataclasses.FrozenInstanceError):
        b.frame = s.frame  # type: ignore[misc]


def test_the_config_holds_the_frame_typed():
    """``[mesh] frame`` is a :class:`Frame` read through ``is_tool``; its TOML/JSON value, its
    equality with the string and the message of an unknown frame are those of the string."""
    tool, work = parse_config(_base("tool")), parse_config(_base("workpiece"))
    assert tool.mesh.frame is Frame.TOOL and tool.mesh.frame.is_tool
    assert work.mesh.frame is Frame.WORKPIECE and not work.mesh.frame.is_tool
    assert tool.mesh.frame == "tool" and work.model_dump(mode="json")["mesh"]["frame"] == \
        "workpiece"
    with pytest.raises(ConfigError, match="Input should be 'workpiece' or 'tool'"):
        parse_config(_base("sideways"))


def test_the_spec_chooses_the_compiled_step():
    # the element, frame and thermal types pick one loop each; no kernel branches on them
    cases = [
        (load_fe_config(EX / "fe_orthogonal.toml"), CL.Phases("q4r", True, True),
         CL.run_chunk_ale_heat),
        (parse_config(_base("tool", solver={"heat_conduction": False})),
         CL.Phases("q4r", True, False), CL.run_chunk_ale),
        (load_fe_config(EX / "fe_orthogonal_tool_support.toml"),
         CL.Phases("q4r", False, False), CL.run_chunk_q4r),
        (parse_config(_base(solver={"element": "q4_bbar"})), CL.Phases("bbar", False, True),
         CL.run_chunk_bbar_heat),
        (parse_config(_base(solver={"element": "q4_bbar", "heat_conduction": False})),
         CL.Phases("bbar", False, False), CL.run_chunk_bbar),
        (parse_config(_base(solver={"heat_conduction": True})),
         CL.Phases("q4r", False, True), CL.run_chunk_q4r_heat),
    ]
    for cfg, phases, run in cases:
        spec = _spec(cfg)
        assert CL.phases_of(spec) == phases
        assert CL.step_for(spec) is run
    # six distinct compiled functions, each cached under its own name
    names = {f.py_func.__qualname__ for f in CL.RUN_CHUNK.values()}
    assert len(names) == len(CL.RUN_CHUNK) == 6
    with pytest.raises(ValueError, match="one-point quad only"):
        CL.run_chunk_for(CL.Phases("bbar", True, False))


def test_the_spec_writes_the_model_slots():
    tool = _spec(load_fe_config(EX / "fe_orthogonal.toml")).write_prm(default_prm(), layout, 30.0)
    assert tool[layout.P_EROSION] == layout.ERODE_NONE and tool[layout.P_GATE] == -1.0
    assert tool[layout.P_DT_ERODE] == 0.0 and tool[layout.P_RZ_EVERY] == 10
    assert tool[layout.P_MUTAB_N] == 6
    assert tool[layout.P_MUTAB_V + 5] == pytest.approx(40.0 / 60.0)
    assert tool[layout.P_SLIP_TAU] == pytest.approx(1e-6 / 0.5) and tool[layout.P_COND_EVERY] == 10
    ns = _spec(parse_config(_base(mesh={"separation": "node_split"},
                                  solver={"heat_conduction": False},
                                  contact={"friction": 0.3})))
    p = ns.write_prm(default_prm(), layout, 30.0)
    assert p[layout.P_GATE] == 0.0 and p[layout.P_RZ_EVERY] == 0 and p[layout.P_COND_EVERY] == 0
    assert p[layout.P_DT_ERODE] == -0.3 and p[layout.P_MUTAB_N] == 0 and p[layout.P_MU] == 0.3
    el = _spec(parse_config(_base(solver={"separation_gate_um": 2.0, "element": "q4_bbar"})))
    p = el.write_prm(default_prm(), layout, 30.0)
    assert p[layout.P_GATE] == pytest.approx(2e-6) and p[layout.P_EROSION] == layout.ERODE_LAYER
    none = _spec(parse_config(_base(solver={"erosion": "none"})))
    assert none.write_prm(default_prm(), layout, 30.0)[layout.P_EROSION] == layout.ERODE_NONE


@pytest.mark.parametrize("frame, sections, field, words", [
    ("tool", {"mesh": {"separation": "node_split"}}, "mesh.separation", 'mesh.frame = "tool"'),
    ("tool", {"solver": {"separation_gate_um": 1.0}}, "solver.separation_gate_um",
     'mesh.frame = "tool"'),
    ("tool", {"solver": {"erosion": "none"}}, "solver.erosion", "no damage"),
    ("tool", {"mesh": {"grading": 1.1}}, "mesh.grading", "its own mesh keys"),
    ("workpiece", {"solver": {"ale_interval": 5}}, "solver.ale_interval",
     'mesh.frame = "workpiece"'),
    ("workpiece", {"mesh": {"initial_chip_ratio": 2.0}}, "mesh.initial_chip_ratio",
     "no tool-frame ALE mesh"),
    ("workpiece", {"mesh": {"separation": "node_split"}, "solver": {"erosion": "layer"}},
     "solver.erosion", 'mesh.separation = "node_split"'),
    ("workpiece", {"mesh": {"separation": "node_split", "separation_layer": "centred"}},
     "mesh.separation_layer", "no erosion layer"),
    ("workpiece", {"mesh": {"edge_band_um": [5.0, 5.0]}}, "mesh.edge_band_um",
     'mesh.separation = "erosion_layer"'),
    ("workpiece", {"solver": {"element": "q4_bbar", "hourglass_viscous": 0.1}},
     "solver.hourglass_viscous", "no hourglass coefficients"),
    ("workpiece", {"solver": {"heat_conduction": False},
                   "contact": {"tool_temperature_K": 400.0}}, "contact.tool_temperature_K",
     "adiabatic"),
    ("tool", {"solver": {"heat_conduction": False, "conduction_interval": 5}},
     "solver.conduction_interval", "adiabatic"),
])
def test_a_key_without_a_place_in_the_chosen_model_is_an_error(frame, sections, field, words):
    with pytest.raises(ConfigError) as ei:
        parse_config(_base(frame, **copy.deepcopy(sections)), "cfg.toml")
    e = ei.value
    assert e.field == field
    msg = str(e)
    assert "cfg.toml" in msg and words in msg and "remove the key" in msg


def test_keys_of_the_chosen_variants_are_accepted():
    parse_config(_base("tool", solver={"ale_interval": 5, "hourglass_viscous": 0.1},
                       mesh={"initial_chip_ratio": 2.0}))
    parse_config(_base(mesh={"separation": "node_split", "edge_band_um": [10.0, 10.0],
                             "separation_height_um": 5.0},
                       solver={"separation_gate_um": 0.5, "heat_conduction": True,
                               "conduction_interval": 5},
                       contact={"tool_temperature_K": 400.0}))
    p = _spec(parse_config(_base(solver={"erosion": "none"}))).write_prm(
        np.zeros(layout.N_PRM), layout, 30.0)
    assert p[layout.P_EROSION] == layout.ERODE_NONE


def _boring(frame: str | None = "workpiece", **sections):
    d = {"cut": {"depth_of_cut_mm": 0.05, "feed_mm_per_rev": 0.15, "speed_rpm": 300.0,
                 "cut_length_mm": 0.02},
         "mesh": {"element_size_um": 16.6}, "solver": {}, "contact": {}}
    if frame is not None:
        d["mesh"]["frame"] = frame
    for sec, kv in sections.items():
        d[sec].update(kv)
    return d


def test_the_boring_spec_and_its_slots():
    from robobore.cutting.fe.config.boring3d import load_boring_config, parse_boring_config
    from robobore.cutting.fe.config.spec import (
        EdgePathLayer,
        HexElement,
        ToolFrame3D,
        WorkpieceFrame3D,
    )
    from robobore.cutting.fe.config.spec_build import build_boring_spec
    from robobore.cutting.fe.engine.state3d import default_prm3
    from robobore.cutting.fe.hex import layout3d

    # the defaults: the tool frame, the hexahedron's hourglass control, conduction, the
    # calibrated friction law read at the sliding speed and the hardening hold
    for cfg in (load_boring_config(EX / "fe_boring_paper.toml"),
                parse_boring_config(_boring(frame=None))):
        mat = load_material(cfg.material.name,
                            hardening_strain_limit=cfg.material.strain_limit())
        s = build_boring_spec(cfg, mat, 37.7)
        assert s.frame == ToolFrame3D(ale_interval=10, element=HexElement(0.05, 0.05),
                                      thin_element_mass_scaling=True)
        assert isinstance(s.thermal, Conduction)
        assert isinstance(s.friction, SlidingSpeedFriction)
        assert s.hardening == HardeningHold(0.6)
        p = s.write_prm(default_prm3(), layout3d, 37.7)
        assert p[layout3d.P_GATE] == -1.0 and p[layout3d.P_EROSION] == layout3d.ERODE_NONE
        assert p[layout3d.P_RZ_EVERY] == 10
        assert p[layout3d.P_MUTAB_N] == 6 and p[layout3d.P_COND_EVERY] == 10
    assert cfg.solver.mass_scaling == 400.0 and cfg.cut.cut_length_mm == 0.02
    # the workpiece frame: the erosion layer with damage erosion by default
    s = build_boring_spec(parse_boring_config(_boring()), mat, 37.7)
    assert isinstance(s.frame, WorkpieceFrame3D) and not s.frame.tool_frame
    assert s.frame.separation == EdgePathLayer() and s.frame.damage_erosion
    p = s.write_prm(default_prm3(), layout3d, 37.7)
    assert p[layout3d.P_GATE] == -1.0 and p[layout3d.P_EROSION] == layout3d.ERODE_LAYER
    ns = parse_boring_config(_boring(mesh={"separation": "node_split", "chip_rows": 4},
                                     solver={"separation_gate_um": 1.0}))
    s2 = build_boring_spec(ns, mat, 37.7)
    assert s2.frame.separation == NodeSplit(height_um=5.0, gate_um=1.0)
    assert s2.write_prm(default_prm3(), layout3d, 37.7)[layout3d.P_GATE] == pytest.approx(1e-6)


@pytest.mark.parametrize("sections, field, words", [
    ({"solver": {"separation_gate_um": 1.0}}, "solver.separation_gate_um", "erosion_layer"),
    ({"mesh": {"chip_rows": 4}}, "mesh.chip_rows", "no parting line"),
    ({"solver": {"heat_conduction": False}, "contact": {"friction_heat_fraction": 0.3}},
     "contact.friction_heat_fraction", "adiabatic"),
    # a workpiece key on the default (tool) frame names the frame it belongs to
    ({"frame": None, "mesh": {"ahead_mm": 0.03}}, "mesh.ahead_mm",
     'the default: the 3D tool-frame ALE model'),
    ({"frame": None, "mesh": {"separation": "node_split"}}, "mesh.separation",
     'belongs to mesh.frame = "workpiece"'),
])
def test_a_boring_key_without_a_place_is_an_error(sections, field, words):
    from robobore.cutting.fe.config.boring3d import parse_boring_config

    with pytest.raises(ConfigError) as ei:
        parse_boring_config(_boring(**copy.deepcopy(sections)), "b.toml")
    assert ei.value.field == field and words in str(ei.value) and "b.toml" in str(ei.value)


def test_a_spec_of_parts_that_do_not_belong_together_cannot_be_built():
    from robobore.cutting.fe.config.spec import (
        EdgePathLayer,
        HexElement,
        ModelSpec,
        ToolFrame3D,
        WorkpieceFrame3D,
    )

    hexa = HexElement(0.05, 0.05)
    rest = {"friction": CoulombFriction(mu=0.3, shear_limit_MPa=500.0),
            "thermal": Adiabatic(), "hardening": HardeningHold(0.6)}
    # a tool frame has no separation and no erosion: there is no field to give them
    with pytest.raises(TypeError):
        ToolFrame3D(ale_interval=10, element=hexa,
                    separation=NodeSplit(height_um=5.0, gate_um=1.0))  # type: ignore[call-arg]
    # a 2D separation, element or frame where a 3D one belongs is a ConfigError
    with pytest.raises(ConfigError) as ei:
        WorkpieceFrame3D(separation=ErosionLayer("centred", None, True, None),
                         damage_erosion=True, erode_time_step_fraction=0.0, element=hexa)
    assert ei.value.field == "mesh.separation" and "EdgePathLayer" in str(ei.value)
    with pytest.raises(ConfigError) as ei:
        WorkpieceFrame3D(separation=EdgePathLayer(), damage_erosion=True,
                         erode_time_step_fraction=0.0, element=OnePointQuad(0.1, 0.1))
    assert ei.value.field == "solver.element"
    with pytest.raises(ConfigError) as ei:
        ToolFrame(ale_interval=10, element=hexa)  # type: ignore[arg-type]
    assert ei.value.field == "solver.element"
    with pytest.raises(ConfigError) as ei:
        ModelSpec(frame=NodeSplit(height_um=5.0, gate_um=1.0), **rest)  # type: ignore[arg-type]
    assert ei.value.field == "mesh.frame"
    with pytest.raises(ConfigError) as ei:
        ModelSpec(frame=ToolFrame3D(ale_interval=10, element=hexa),
                  **{**rest, "thermal": PlainHardening()})  # type: ignore[arg-type]
    assert ei.value.field == "solver.heat_conduction"
    ok = ModelSpec(frame=ToolFrame3D(ale_interval=10, element=hexa), **rest)
    assert ok.frame.tool_frame and ok.frame.dim == 3
