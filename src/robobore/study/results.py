"""Typed result of the paper study (:func:`robobore.study.paper.run_paper`).

:class:`PaperSummary` is a frozen record whose fields are documented one by one, in the unit
their names carry; ``to_dict()`` is ``paper_summary.json`` and the JSON of ``robobore paper
--json``: the same keys in the same order (:class:`robobore.io.records.Record`). The groups
the study's stages write (the sweep's outcome, the coefficient set, the comparison, the
checks, the posture plan, the calibration) are their own stages' dicts, described in
docs/paper.md. The sweep's and the comparison's entry points return their own typed results
(:class:`robobore.study.sweep.SweepOutcome`, :class:`robobore.study.compare.Comparison`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from robobore.io.records import Record

__all__ = ["PaperSummary"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PaperSummary(Record):
    """The summary of the paper study (``paper_summary.json``)."""

    #: the HTML report's path
    report: str
    #: conditions of the study (robot and machine tool)
    conditions: int
    #: conditions with a result
    computed: int
    #: the conditions without a result: key, system, condition, error
    failed: tuple[dict[str, Any], ...]
    #: computed conditions stable by the paper's criterion
    stable: int
    #: computed conditions vibratory by the paper's criterion
    vibratory: int
    #: what stable / vibratory are decided by
    stable_vibratory_by: str
    #: computed conditions that chatter
    chatter: int
    #: computed conditions whose surface is rough (Ra over the tolerance)
    rough: int
    #: computed conditions where the tool leaves the cut
    tool_leaves_cut: int
    #: the study ran with ``fast`` (the stored force calibration, no FE)
    fast: bool
    #: worker processes of the sweep
    workers: int
    #: the identification inputs are SYNTHETIC
    synthetic_inputs: bool
    #: the study config file
    config: str
    #: the output folder
    out: str
    #: the sweep's outcome (:meth:`robobore.study.sweep.SweepOutcome.to_dict`)
    sweep: dict[str, Any]
    #: the robot's directional stiffness at the paper posture [N/m], boring frame
    directional_stiffness_N_per_m: dict[str, Any]
    #: the identified natural frequencies [Hz]
    modes_Hz: tuple[float, ...]
    #: the equivalent model's per-axis tables without and with the foot
    equivalent_model: dict[str, Any]
    #: the cutting coefficients the boring model uses (SI)
    coefficients: dict[str, Any]
    #: the coefficient set: name, description, calibrated domain, warnings
    coefficient_set: dict[str, Any]
    #: warnings (the coefficient set's, the sweep's coefficient warnings)
    warnings: tuple[str, ...]
    #: how the coefficients were obtained (FE calibration, stored file, measured set)
    coefficients_mode: str | None
    #: the comparison with the measured table: groups and agreement (None without one)
    comparison: dict[str, Any] | None
    #: the paper's qualitative findings checked on the results
    qualitative_checks: tuple[dict[str, Any], ...]
    #: the swept conditions against the semi-discretisation limit
    lobe_consistency: dict[str, Any]
    #: the robobore version that ran the study
    robobore_version: str
    #: the posture plan of the paper's bore (``{"error": ...}`` when it cannot be made)
    posture_plan: dict[str, Any]
    #: the dynamics calibration from observed cuts (None without observations)
    calibration: dict[str, Any] | None
    #: the headless-browser check of the report (None: not asked)
    browser_check: dict[str, Any] | None = None
    #: wall time of each stage [s]
    timings_s: dict[str, float]
    #: wall time of the study [s]
    wall_time_s: float

    _OMIT = frozenset({"browser_check"})
