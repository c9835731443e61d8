"""Typed results of the process stage's entry points (:mod:`robobore.dynamics.api`).

:class:`BoringResult` (:func:`~robobore.dynamics.api.run_boring`, ``robobore simulate boring
--json``), :class:`LobesResult` (:func:`~robobore.dynamics.api.lobes`, the ``robobore lobes
--json`` keys without ``notes`` and ``process``) and :class:`CriticalDepth`
(:func:`~robobore.dynamics.api.critical_depth_at`). Each is a frozen dataclass whose fields
are documented one by one, in the unit their names carry; ``to_dict()`` gives the dict the
JSON is written from: the same keys in the same order (:class:`robobore.io.records.Record`).
The verdicts are those of :mod:`robobore.dynamics.chatter`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.io.records import Record

__all__ = ["Vector3", "Verdicts", "SamplingCheck", "BoringResult", "LobesResult",
           "CriticalDepth"]


@dataclass(frozen=True, slots=True)
class Vector3(Record):
    """A vector in the boring frame (X, Y radial, Z the feed), in the unit of the field that
    holds it."""

    #: X component
    x: float
    #: Y component
    y: float
    #: Z component (the feed direction)
    z: float


@dataclass(frozen=True, slots=True)
class Verdicts(Record):
    """The named verdicts of a simulated cut."""

    #: the vibration grows from pitch to pitch (or a nonlinear cause of ``chatter_cause``)
    chatter: bool
    #: "ok" / "rough" (Ra, form removed, against the tolerance); None without a tolerance
    surface_finish: str | None
    #: the tool leaves the material during the cut
    tool_leaves_cut: bool
    #: the paper's criterion: "stable" / "vibratory"; None when not judged
    paper_criterion: str | None


@dataclass(frozen=True, slots=True)
class SamplingCheck(Record):
    """The same run at twice the samples per revolution, made when the tool leaves the cut."""

    #: samples per revolution of the check run
    samples_per_rev: int
    #: the check run's chatter verdict
    chatter: bool
    #: both runs give the same chatter verdict
    agrees: bool


@dataclass(frozen=True, slots=True)
class BoringResult(Record):
    """The summary of one simulated boring condition (``robobore simulate boring --json``).

    ``dataset`` and ``config`` are set only with ``return_dataset=True`` and are left out of
    ``to_dict()`` otherwise."""

    #: the paper's criterion: False when Ra exceeds the tolerance, the cut chatters or the run
    #: diverged; None without a tolerance otherwise
    stable: bool | None
    #: the named verdicts (``paper_criterion`` as "stable" / "vibratory" / None)
    verdicts: Verdicts
    #: the vibration grows from pitch to pitch
    chatter: bool
    #: "ok" / "rough" against ``ra_tolerance_um``; None without a tolerance
    surface_finish: str | None
    #: the tool leaves the material during the cut
    tool_leaves_cut: bool
    #: the chatter frequency [Hz]; None without chatter
    chatter_frequency_Hz: float | None
    #: False when the multiplier is within its uncertainty of 1 after lengthening the run, or
    #: when the sampling check gives the other verdict
    chatter_decided: bool
    #: the run at twice the samples per revolution (None when not made)
    sampling_check: SamplingCheck | None
    #: "regenerative" or a nonlinear cause; None without chatter
    chatter_cause: str | None
    #: "forced vibration" or "regenerative vibration"; None while the tool stays in the cut
    tool_leaves_cut_cause: str | None
    #: the Floquet multiplier of the simulated cut (growth per insert pitch, dimensionless)
    floquet_multiplier: float
    #: its standard error (ln)
    floquet_multiplier_se: float
    #: growth of the vibration envelope (dimensionless ratio)
    vibration_growth: float
    #: growth of the feed-direction amplitude (dimensionless ratio)
    feed_amplitude_growth: float
    #: growth of the radial amplitude (dimensionless ratio)
    radial_amplitude_growth: float
    #: the mean cutting force [N], boring frame
    force_mean_N: Vector3
    #: the force amplitude (half peak-to-peak) [N], boring frame
    force_amplitude_N: Vector3
    #: the feed-direction vibration amplitude [um]
    feed_amplitude_um: float
    #: False below the amplitude resolution
    feed_amplitude_resolved: bool
    #: the amplitude resolution [um]
    amplitude_resolution_um: float
    #: the vibration energy off the spindle harmonics / the total (dimensionless)
    nonharmonic_energy_ratio: float
    #: Ra of the bore wall, form removed [um]
    roughness_Ra_um: float
    #: Rz of the bore wall, form removed [um]
    roughness_Rz_um: float
    #: Ra with the form [um]
    roughness_Ra_with_form_um: float
    #: the taper of the bore wall [um/mm]
    form_slope_um_per_mm: float
    #: the Ra tolerance of the config [um]; None without one
    ra_tolerance_um: float | None
    #: the fraction of the time the tool is out of the material
    tool_left_cut_fraction: float
    #: why the verdicts are what they are
    reasons: tuple[str, ...]
    #: the integration diverged
    diverged: bool
    #: the spindle speed [r/min]
    speed_rpm: float
    #: the depth of cut [mm]
    depth_mm: float
    #: revolutions asked for (after lengthening an undecided run)
    revolutions: int
    #: revolutions simulated
    revolutions_simulated: int
    #: samples per revolution
    samples_per_rev: int
    #: the process's label
    process: str
    #: the model's name
    model: str
    #: the provenance of the coefficients set at this cutting speed (None for a linear
    #: process)
    coefficients_provenance: str | None
    #: the coefficients' domain warnings at this condition
    coefficient_warnings: tuple[str, ...]
    #: all warnings (the coefficients' ones)
    warnings: tuple[str, ...]
    #: the xarray Dataset of the time histories (``return_dataset=True`` only)
    dataset: Any = None
    #: the config dict the run was built from (``return_dataset=True`` only)
    config: dict[str, Any] | None = None

    _OMIT = frozenset({"dataset", "config"})


@dataclass(frozen=True, slots=True)
class LobesResult(Record):
    """The stability lobes of a config (``robobore lobes --json`` without ``notes`` and
    ``process``). The arrays are numpy arrays, one value per speed."""

    #: "frequency" or "semidiscretization"
    method: str
    #: the speeds [r/min]
    speed_rpm: np.ndarray
    #: the critical depth at each speed [mm] (inf: stable up to the scan top; 0: no
    #: chatter-free depth)
    critical_depth_mm: np.ndarray
    #: the lowest critical depth over the speeds [mm]
    absolute_limit_mm: float
    #: the chatter frequency at the absolute limit [Hz]
    absolute_limit_frequency_Hz: float
    #: the chatter frequency at each speed [Hz]
    chatter_frequency_Hz: np.ndarray
    #: the top of the depth scan [mm] (semi-discretisation only)
    depth_scan_max_mm: float | None = None
    #: speeds stable up to the scan top (semi-discretisation only)
    stable_speeds: int | None = None
    #: the depth below which the forced vibration takes the tool out of the cut [mm], per
    #: speed (semi-discretisation only)
    interrupted_below_mm: np.ndarray | None = None
    #: speeds with an interrupted cut below the limit (semi-discretisation only)
    interrupted_speeds: int | None = None
    #: the mode-coupling limit [mm]; None when there is none
    mode_coupling_limit_mm: float | None = None
    #: the default speed range's note (None when the config gives ``[speed_rpm]``)
    speed_note: str | None = None
    #: the coefficients' domain warnings
    warnings: tuple[str, ...] = ()
    #: the note on the coefficients of speed-dependent lobes (None when there is none)
    coefficient_note: str | None = None

    _OMIT = frozenset({"depth_scan_max_mm", "stable_speeds", "interrupted_below_mm",
                       "interrupted_speeds", "speed_note", "coefficient_note"})


@dataclass(frozen=True, slots=True)
class CriticalDepth(Record):
    """The semi-discretisation answer of the lobes at one speed."""

    #: the spindle speed [r/min]
    speed_rpm: float
    #: the critical depth [mm]; None: stable up to the scan top; 0: no chatter-free depth
    critical_depth_mm: float | None
    #: the depth below which the forced vibration takes the tool out of the cut [mm]
    interrupted_below_mm: float
