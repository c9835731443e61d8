"""Typed result of the posture planner (:func:`robobore.plan.posture.plan_posture`).

:class:`PostureResult` is a frozen record whose fields are documented one by one, in the
unit their names carry; ``to_dict()`` is the JSON of ``robobore plan posture --json`` (and
``posture_plan.json``): the same keys in the same order (:class:`robobore.io.records.Record`).
The in-memory arrays the planner's dataset, plots and workspace map are made from are in
``arrays`` (:class:`PlanArrays`), which the JSON leaves out. The boring frame: X, Y normal
to the bore axis, Z along it (docs/plan.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.dynamics.results import Vector3
from robobore.io.records import Record

__all__ = ["PlanMode", "Candidate", "PostureError", "BoreFrame", "PlanCounts",
           "PostureLobes", "PlanArrays", "PostureResult"]


@dataclass(frozen=True, slots=True)
class PlanMode(Record):
    """One mode of a candidate's pose-dependent model."""

    #: natural frequency [Hz]
    frequency_Hz: float
    #: damping ratio (dimensionless)
    damping_ratio: float


@dataclass(frozen=True, slots=True)
class Candidate(Record):
    """One posture that holds the bore (a tool-axis rotation x an IK branch), rated."""

    #: the joint angles [deg]
    joints_deg: tuple[float, ...]
    #: the flange's rotation about the bore axis from the boring-frame X [deg]
    tool_axis_rotation_deg: float
    #: the IK branch (index)
    branch: int
    #: the IK branch in words (shoulder, elbow, wrist)
    branch_label: str
    #: the directional stiffness in the boring frame [N/m]
    directional_stiffness_N_per_m: Vector3
    #: the modes of the pose-dependent model
    modes: tuple[PlanMode, ...]
    #: the critical depth at the cutting speed [mm] (None: stable up to the scan top)
    critical_depth_mm: float | None
    #: the lowest critical depth over the speed range [mm] (None: stable up to the scan top)
    critical_depth_range_min_mm: float | None
    #: the speed of the lowest critical depth [r/min]
    critical_speed_rpm: float
    #: "semi-discretization" or "frequency (screening)"
    critical_depth_method: str
    #: the chatter frequency of the frequency-domain screen [Hz] (NaN when rated by
    #: semi-discretisation)
    chatter_frequency_Hz: float
    #: the feed-direction amplitude of the steady cut [um]
    feed_amplitude_um: float
    #: the smallest singular value of the scaled Jacobian (dimensionless; 0 at a singularity)
    singularity_measure: float
    #: the tool point's distance from the bore point [mm]
    position_error_mm: float
    #: the tool axis's angle from the bore axis [deg]
    axis_error_deg: float
    #: the criterion's value (recommended and measured postures only), in the plan's
    #: ``criterion_unit``
    criterion_value: float | None = None

    _OMIT = frozenset({"criterion_value"})


@dataclass(frozen=True, slots=True)
class PostureError(Record):
    """How far the measured posture holds the tool from the bore."""

    #: the tool point's distance from the bore point [mm]
    position_mm: float
    #: the tool axis's angle from the bore axis [deg]
    axis_deg: float


@dataclass(frozen=True, slots=True)
class BoreFrame(Record):
    """The bore and its boring frame (base frame)."""

    #: the bore point [m]
    point_m: tuple[float, ...]
    #: the bore axis (unit vector)
    axis: tuple[float, ...]
    #: the direction the boring frame's X is projected from (None: the default)
    x_hint: tuple[float, ...] | None
    #: the boring frame's X, Y, Z axes (rows: the frame's columns), base frame
    boring_frame_columns: tuple[tuple[float, ...], ...]


@dataclass(frozen=True, slots=True)
class PlanCounts(Record):
    """How many postures were tried and kept."""

    #: tool-axis rotations of the grid
    rotations: int
    #: IK solutions tried (rotations x branches)
    ik_solutions_tried: int
    #: solutions that reach the bore
    reaching: int
    #: of those, inside the joint limits
    inside_limits: int
    #: candidates (inside the limits and away from singularities)
    candidates: int


@dataclass(frozen=True, slots=True)
class PostureLobes(Record):
    """The semi-discretisation lobes at one posture (recommended or measured)."""

    #: "semi-discretization"
    method: str
    #: the speeds [r/min]
    speed_rpm: tuple[float, ...]
    #: the critical depth at each speed [mm]
    critical_depth_mm: tuple[float, ...]
    #: the depth below which the steady cut is interrupted, each speed [mm]
    interrupted_below_mm: tuple[float, ...]
    #: the cutting speed [r/min]
    cutting_speed_rpm: float
    #: the critical depth at the cutting speed [mm]
    critical_depth_at_speed_mm: float
    #: the interruption depth at the cutting speed [mm]
    interrupted_below_at_speed_mm: float
    #: the structure these lobes are of (``[structure]`` modes of a ``robobore lobes``
    #: config)
    tool_point_modes: tuple[dict[str, Any], ...]


@dataclass(frozen=True, slots=True)
class PlanArrays:
    """The planner's in-memory state (no JSON): candidates, their evaluation, the model."""

    #: the candidates (:class:`robobore.plan.candidates.Candidates`)
    cand: Any
    #: the per-candidate evaluation arrays (SI), by name
    ev: dict[str, np.ndarray]
    #: the criterion value of each candidate
    criterion: np.ndarray
    #: the index of the recommended candidate
    best: int
    #: the index of the measured posture (None: not a candidate)
    measured: int | None
    #: the tool-axis rotation grid [deg]
    rotations: np.ndarray
    #: the calibrated pose-dependent model (:class:`robobore.plan.model.PoseModel`)
    model: Any
    #: the validated inputs (:class:`robobore.plan.config.PlanInputs`)
    inputs: Any
    #: the cutting process (:class:`robobore.dynamics.process.CuttingProcess`)
    process: Any


@dataclass(frozen=True, slots=True)
class PostureResult(Record):
    """The posture plan of a bore (``robobore plan posture --json``)."""

    #: the plan config file
    config: str
    #: the robot's name
    robot: str
    #: the ranking criterion ("critical_depth", "stiffness_min", "stiffness_x", ...)
    criterion: str
    #: the criterion's unit
    criterion_unit: str
    #: the recommended posture
    recommended: Candidate
    #: the measured posture (None: not a candidate, it does not hold this bore)
    measured: Candidate | None
    #: the measured posture's joint angles [deg]
    measured_posture_deg: tuple[float, ...]
    #: the measured posture holds the bore (within the tolerances)
    measured_posture_reaches_bore: bool
    #: how far the measured posture is from the bore
    measured_posture_error: PostureError
    #: the calibration of the pose-dependent model at the measured posture
    #: (:meth:`robobore.plan.model.Calibration.to_dict`: residuals in %, scales, damping)
    calibration: dict[str, Any]
    #: the bore and its boring frame
    bore: BoreFrame
    #: the tool centre point in the flange frame [m]
    tcp_m: tuple[float, ...]
    #: how many postures were tried and kept
    counts: PlanCounts
    #: the largest tool-point error of a candidate [mm]
    max_position_error_mm: float
    #: the largest tool-axis error of a candidate [deg]
    max_axis_error_deg: float
    #: the lobes' speed range [r/min]
    speed_range_rpm: tuple[float, float]
    #: the ``[cutting]`` condition (speed r/min, feed mm/r, depth mm)
    cutting: dict[str, Any]
    #: every candidate, rated
    candidates: tuple[Candidate, ...]
    #: the semi-discretisation lobes at the recommended and measured postures, by name
    lobes: dict[str, PostureLobes]
    #: the equivalent model (per-axis table) at the recommended and measured postures
    equivalent_model: dict[str, list[dict[str, Any]]]
    #: the identification inputs are SYNTHETIC
    synthetic_inputs: bool
    #: notes on the inputs
    notes: tuple[str, ...]
    #: warnings (calibration, flat map, coefficients' domain)
    warnings: tuple[str, ...]
    #: what the plan describes (robot, posture, frame, SYNTHETIC; robobore.io.identity)
    identity: dict[str, Any]
    #: wall time of the plan [s]
    wall_time_s: float
    #: the best criterion value at each part placement of ``[workspace]``
    #: (:func:`robobore.plan.posture.workspace_map`; None: not mapped)
    workspace: dict[str, Any] | None = None
    #: the in-memory arrays (not in the JSON)
    arrays: PlanArrays | None = None

    _OMIT = frozenset({"workspace"})
    _SKIP = frozenset({"arrays"})
