"""The one place that chooses an FE model: the config's frame and the device, read once.

:func:`choose_orthogonal` (a 2D :class:`~robobore.cutting.fe.config.orthogonal.FEConfig`) and
:func:`choose_boring` (a 3D :class:`~robobore.cutting.fe.config.boring3d.BoringFEConfig`)
check the device (``"cpu"`` or ``"gpu"``; a GPU that is missing, or a model the GPU does not
run, is a ConfigError here) and return the model object of the config's frame:

==========================  ====================  ==================================
model                       frame                 set-up (mesh, state)
==========================  ====================  ==================================
:class:`Orthogonal2DTool`   ``mesh.frame="tool"``  ``models.orthogonal.setup_orthogonal``
:class:`Orthogonal2DWork`   ``"workpiece"``        ``models.orthogonal.setup_orthogonal``
:class:`Boring3DTool`       ``"tool"``             ``models.toolframe3d.setup_boring_toolframe``
:class:`Boring3DWork`       ``"workpiece"``        ``models.boring_setup.setup_boring_workpiece``
==========================  ====================  ==================================

Each model object knows its memory estimate (``estimated_elements``, from
:mod:`robobore.cutting.fe.mesh.memory`), its parameter layout (``layout``: the module of its
``P_*`` slots), its loop on the chosen device (``advance``), whether it is a tool frame
(``tool_frame``) and the frame-dependent parts of its typed result (the 2D chip measure, the
3D mesh facts). The model choices inside a frame (element, friction law, thermal model,
hardening) are the frozen :class:`~robobore.cutting.fe.config.spec.ModelSpec` of the set-up,
which also chooses the compiled step. The entry points that run a model --
:func:`robobore.cutting.fe.models.orthogonal.simulate_orthogonal`,
:func:`robobore.cutting.fe.models.boring3d.simulate_boring` -- start here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any, ClassVar

import numpy as np

from robobore.cutting.fe.config.boring3d import BoringFEConfig
from robobore.cutting.fe.config.orthogonal import FEConfig
from robobore.cutting.fe.engine import layout as layout2d
from robobore.cutting.fe.hex import layout3d, scalar3d
from robobore.cutting.fe.mesh import memory
from robobore.cutting.fe.models.boring_setup import BoringSetup, setup_boring_workpiece
from robobore.cutting.fe.models.results import ToolFrameMeshSummary
from robobore.errors import ConfigError

__all__ = ["DEVICES", "check_device", "Orthogonal2D", "Orthogonal2DTool", "Orthogonal2DWork",
           "Boring3D", "Boring3DTool", "Boring3DWork", "MeshFacts3D", "choose_orthogonal",
           "choose_boring"]

#: the devices a model runs on
DEVICES = ("cpu", "gpu")

#: a loop: (state, end time, chunk steps, progress, energy check, spec) -> steps taken
Loop = Callable[..., int]


def check_device(device: str, source: str | None = None) -> None:
    """ConfigError unless ``device`` is one of :data:`DEVICES`."""
    if device not in DEVICES:
        raise ConfigError("unknown device", file=source, field="--device", value=device,
                          expected="cpu or gpu")


# --- loops per device (the compiled step follows the spec on the CPU)

def _cpu2d(st: Any, t_end: float, chunk_steps: int, progress: Any, check: Any,
           spec: Any) -> int:
    from robobore.cutting.fe.engine.chunk_driver import advance
    from robobore.cutting.fe.engine.chunk_loop import step_for

    # the loop compiled for the spec's element, frame and thermal model
    return advance(st, t_end, chunk_steps=chunk_steps, progress=progress, check=check,
                   step=None if spec is None else step_for(spec))


def _gpu2d(st: Any, t_end: float, chunk_steps: int, progress: Any, check: Any,
           spec: Any) -> int:
    from robobore.cutting.fe.engine.gpu.backend2d import advance_gpu

    return advance_gpu(st, t_end, chunk_steps=chunk_steps, progress=progress, check=check)


def _cpu3d(st: Any, t_end: float, chunk_steps: int, progress: Any, check: Any,
           spec: Any) -> int:
    from robobore.cutting.fe.engine.kernels3d import run_chunk3_for
    from robobore.cutting.fe.engine.state3d import advance3

    return advance3(st, t_end, chunk_steps=chunk_steps, progress=progress, check=check,
                    step=None if spec is None else run_chunk3_for(spec))


def _gpu3d(st: Any, t_end: float, chunk_steps: int, progress: Any, check: Any,
           spec: Any) -> int:
    from robobore.cutting.fe.engine.gpu.backend3d import advance3_gpu

    return advance3_gpu(st, t_end, chunk_steps=chunk_steps, progress=progress, check=check)


# --- the 2D orthogonal model

@dataclass(frozen=True)
class Orthogonal2D:
    """The orthogonal-cutting model (2D plane strain) of ``cfg`` on ``device``."""

    cfg: FEConfig
    device: str
    #: the loop of the device (:func:`choose_orthogonal` sets it)
    loop: Loop
    #: the 2D parameter and history layout
    layout: ClassVar[ModuleType] = layout2d
    #: the mesh stays round the tool (the ALE model)
    tool_frame: ClassVar[bool]
    #: the config's name of the frame
    frame: ClassVar[str]

    def estimated_elements(self) -> float:
        """The mesh's element count, estimated from the config before it is built."""
        raise NotImplementedError

    def advance(self, st: Any, t_end: float, *, progress: Any = None, check: Any = None,
                spec: Any = None) -> int:
        """Run ``st`` to ``t_end`` on the model's device; the steps taken."""
        return self.loop(st, t_end, self.cfg.solver.chunk_steps, progress, check, spec)

    def measure_chip(self, setup: Any) -> tuple[Any, float, int]:
        """The chip measured at the end of the run: (chip, chip ratio from the chip's
        velocity, the nodes it rests on)."""
        raise NotImplementedError


@dataclass(frozen=True)
class Orthogonal2DTool(Orthogonal2D):
    """The 2D tool-frame ALE model (the validated default)."""

    tool_frame: ClassVar[bool] = True
    frame: ClassVar[str] = "tool"

    def estimated_elements(self) -> float:
        return memory.toolframe2d_elements(self.cfg)

    def measure_chip(self, setup: Any) -> tuple[Any, float, int]:
        from robobore.cutting.fe.ale.toolframe import measure_chip_toolframe

        return measure_chip_toolframe(setup.state, setup.mesh, setup.h, setup.rake, setup.vc)


@dataclass(frozen=True)
class Orthogonal2DWork(Orthogonal2D):
    """The 2D Lagrangian workpiece-frame model (node splitting or an erosion layer)."""

    tool_frame: ClassVar[bool] = False
    frame: ClassVar[str] = "workpiece"

    def estimated_elements(self) -> float:
        return memory.workpiece2d_elements(self.cfg)

    def measure_chip(self, setup: Any) -> tuple[Any, float, int]:
        from robobore.cutting.fe.models.output import chip_ratio_from_velocity, measure_chip

        chip = measure_chip(setup.state, setup.mesh, setup.h, setup.rake, setup.vc)
        r_vel, n_vel = chip_ratio_from_velocity(setup.state, setup.mesh, setup.h, setup.rake,
                                                setup.vc)
        return chip, r_vel, n_vel


def choose_orthogonal(cfg: FEConfig, device: str = "cpu",
                      source: str | None = None) -> Orthogonal2D:
    """The 2D model of ``cfg`` on ``device``; ConfigError for an unknown device, a GPU that
    is not there or an option the GPU engine does not run."""
    check_device(device, source)
    if device == "gpu":
        from robobore.cutting.fe.engine.gpu.backend2d import check_gpu_supported
        from robobore.cutting.fe.engine.gpu.shared import require_gpu

        check_gpu_supported(cfg.solver.element, source)
        require_gpu()
    cls = Orthogonal2DTool if cfg.mesh.frame.is_tool else Orthogonal2DWork
    return cls(cfg=cfg, device=device, loop=_gpu2d if device == "gpu" else _cpu2d)


# --- the 3D boring model

@dataclass(frozen=True)
class MeshFacts3D:
    """The frame-dependent facts of a 3D boring run's summary."""

    #: the pre-bore surface's highest point [m] (the chip height is measured from it)
    top: float
    #: the workpiece frame's separation (None in the tool frame)
    separation: str | None
    #: the tool-frame mesh's facts (None in the workpiece frame)
    toolframe_mesh: ToolFrameMeshSummary | None
    #: the workpiece block's hexahedra along x, y, z (None in the tool frame)
    mesh_shape: tuple[int, int, int] | None


@dataclass(frozen=True)
class Boring3D:
    """The 3D boring model of ``cfg`` on ``device``."""

    cfg: BoringFEConfig
    device: str
    loop: Loop
    #: the 3D parameter and history layout
    layout: ClassVar[ModuleType] = layout3d
    #: the mesh stays round the insert (the ALE model)
    tool_frame: ClassVar[bool]
    #: the config's name of the frame
    frame: ClassVar[str]

    def estimated_elements(self) -> float:
        """The mesh's element count, estimated from the config before it is built."""
        raise NotImplementedError

    def setup(self, source: str | None = None) -> BoringSetup:
        """Mesh, insert, support and state of the model."""
        raise NotImplementedError

    def advance(self, st: Any, t_end: float, *, progress: Any = None, check: Any = None,
                spec: Any = None) -> int:
        """Run ``st`` to ``t_end`` on the model's device; the steps taken."""
        return self.loop(st, t_end, self.cfg.solver.chunk_steps, progress, check, spec)

    def mesh_facts(self, setup: BoringSetup, hh: np.ndarray, mass0: float) -> MeshFacts3D:
        """The frame's facts for the summary of a run (``hh``: the history's finite rows,
        ``mass0``: the mesh's volume at the start)."""
        raise NotImplementedError


@dataclass(frozen=True)
class Boring3DTool(Boring3D):
    """The 3D tool-frame ALE model (the default): no workpiece block, no separation."""

    tool_frame: ClassVar[bool] = True
    frame: ClassVar[str] = "tool"

    def estimated_elements(self) -> float:
        return memory.toolframe3d_elements(self.cfg)

    def setup(self, source: str | None = None) -> BoringSetup:
        from robobore.cutting.fe.models.toolframe3d import setup_boring_toolframe

        return setup_boring_toolframe(self.cfg, source)

    def mesh_facts(self, setup: BoringSetup, hh: np.ndarray, mass0: float) -> MeshFacts3D:
        from robobore.cutting.fe.models.toolframe3d import toolframe_mesh_summary

        st = setup.state
        # material in the mesh at the end over the start (inflow - outflow of the passes)
        extra: dict[str, Any] = {"mass_ratio": float(np.sum(st.vol0)) / mass0}
        if st.msf.shape[0] > 0:
            # the inertia added to the thin chip elements (thin_element_factors)
            extra.update(inertia_factor_max=float(np.max(st.msf)),
                         inertia_factor_elements=int(np.sum(st.msf > 1.0)),
                         added_inertia_fraction=float(
                             np.sum(st.vol0 * (st.msf - 1.0)) / np.sum(st.vol0)))
        if self.cfg.tool_support is not None:
            # the insert's deflection along the wall normal (local y; tool_kinematics_py),
            # which the tool-frame mesh's placement does not follow, against the edge element
            thr = hh[:, scalar3d.H_THETA]
            uy = -np.cos(thr) * hh[:, scalar3d.H_UX] - np.sin(thr) * hh[:, scalar3d.H_UY]
            extra.update(radial_deflection_max_um=float(np.max(np.abs(uy))) * 1e6,
                         edge_element_um=setup.mesh.sizes.edge * 1e6)
        # ap: the tool frame's initial mesh carries the pre-shaped chip above it
        return MeshFacts3D(top=setup.ap, separation=None,
                           toolframe_mesh=replace(toolframe_mesh_summary(setup.mesh), **extra),
                           mesh_shape=None)


@dataclass(frozen=True)
class Boring3DWork(Boring3D):
    """The 3D workpiece-frame model: the bore-wall block, node splitting or the edge-path
    erosion layer."""

    tool_frame: ClassVar[bool] = False
    frame: ClassVar[str] = "workpiece"

    def estimated_elements(self) -> float:
        return memory.workpiece3d_elements(self.cfg)

    def setup(self, source: str | None = None) -> BoringSetup:
        return setup_boring_workpiece(self.cfg, source)

    def mesh_facts(self, setup: BoringSetup, hh: np.ndarray, mass0: float) -> MeshFacts3D:
        # the pre-bore surface's highest point: the workpiece block's top
        return MeshFacts3D(top=float(np.max(setup.mesh.nodes[:, 1])),
                           separation=self.cfg.mesh.separation, toolframe_mesh=None,
                           mesh_shape=tuple(int(n) for n in setup.mesh.shape))


def choose_boring(cfg: BoringFEConfig, device: str = "cpu",
                  source: str | None = None) -> Boring3D:
    """The 3D boring model of ``cfg`` on ``device``; ConfigError for an unknown device, the
    GPU with the tool frame (its ALE pass runs on the CPU only) or a GPU that is not
    there."""
    check_device(device, source)
    tool = cfg.mesh.frame.is_tool
    if device == "gpu":
        if tool:
            raise ConfigError(
                "the 3D tool-frame model (the default mesh.frame) runs on the CPU only",
                file=source, field="--device", value=device,
                expected='cpu, or set [mesh] frame = "workpiece" in the config for the GPU '
                         "(the workpiece-frame model: radial and feed forces 22-38 % low at "
                         "the paper's condition, docs/fe3d.md)")
        from robobore.cutting.fe.engine.gpu.shared import require_gpu

        require_gpu()
    cls = Boring3DTool if tool else Boring3DWork
    return cls(cfg=cfg, device=device, loop=_gpu3d if device == "gpu" else _cpu3d)

