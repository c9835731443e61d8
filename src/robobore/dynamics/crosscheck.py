"""Lobes against the time domain on random SYNTHETIC boring cuts: the check that holds the
stability answers of robobore to each other.

A cut (:class:`CrossCheckCut`) is a robot-like three-axis equivalent model, an insert, a feed
and a speed drawn from documented ranges (:func:`random_cut`; SYNTHETIC ground truth: no
measurement is involved). :func:`check_cut` computes the semi-discretisation critical depth
``a_c`` of the cut and simulates it in the time domain at ``0.8 a_c`` and ``1.25 a_c``, at the
default sampling and at twice it: the lobes and the time domain agree when the first two say
no chatter and the last two say chatter. Where the critical depth is 0 (no chatter-free
depth), the time domain at a depth where the lobes say chatter -- 1.25 x the depth below which
the steady cut is interrupted (or the first depth above it, in steps of 1.25, where the steady
cut is in the material), or the scan's lowest depth where it is in the material down to
vanishing depth -- must say chatter (:attr:`CrossCheckResult.zero_confirmed`). ``benchmarks/chatter_agreement.py`` runs the set
and prints the agreement table; ``tests/dynamics/test_dyn_agreement.py`` holds a sample of
it.

Ranges (the held-out description of the robots and cuts robobore is judged on): three
orthogonal units in a random frame, 5-60 Hz, damping ratio 1-6 %, stiffness 0.3-10 N/um;
spindle speed 150-1500 r/min; feed 0.05-0.5 mm/r; nose radius 0.2-1.2 mm; approach angle
90 deg; one insert; bore 40 mm; the TC4 coefficients of `material = "TC4"` at the cut's speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robobore.cutting.coefficient_sets import ti64_coefficients
from robobore.cutting.forces import CuttingCoefficients
from robobore.cutting.geometry import BoringInsert
from robobore.dynamics.process import CuttingProcess, boring_process
from robobore.dynamics.structure import ToolPointStructure

#: Ranges of :func:`random_cut` (see the module docstring).
FREQUENCY_HZ = (5.0, 60.0)
DAMPING_RATIO = (0.01, 0.06)
STIFFNESS_N_PER_M = (3e5, 1e7)
SPEED_RPM = (150.0, 1500.0)
FEED_MM_PER_REV = (0.05, 0.5)
NOSE_RADIUS_MM = (0.2, 1.2)
BORE_DIAMETER_M = 0.04
#: Deepest run of :func:`check_cut` [m] (the time domain's depth range ends
#: at 20 mm).
MAX_SIMULATED_DEPTH_M = 0.02
#: Depth at which a process is first built (its geometry is rebuilt at every trial depth).
REFERENCE_DEPTH_M = 0.05e-3


@dataclass(frozen=True)
class CrossCheckCut:
    """One SYNTHETIC cut: the structure, the insert, the feed [m/rev], the speed [r/min] and
    the coefficients."""

    structure: ToolPointStructure
    insert: BoringInsert
    feed_per_rev_m: float
    speed_rpm: float
    coefficients: CuttingCoefficients
    label: str = ""

    def process(self, depth_m: float = REFERENCE_DEPTH_M) -> CuttingProcess:
        """The boring process of the cut at ``depth_m``."""
        return boring_process(self.insert, self.coefficients, depth_m, self.feed_per_rev_m)

    def describe(self) -> dict[str, Any]:
        st = self.structure
        return {"label": self.label, "speed_rpm": self.speed_rpm,
                "feed_mm_per_rev": self.feed_per_rev_m * 1e3,
                "nose_radius_mm": self.insert.nose_radius_m * 1e3,
                "frequency_Hz": st.frequency_Hz.tolist(),
                "damping_ratio": st.damping_ratio.tolist(),
                "stiffness_N_per_um": (st.stiffness_N_per_m * 1e-6).tolist()}


def random_structure(rng: np.random.Generator) -> ToolPointStructure:
    """Three orthogonal units in a random frame, frequencies, damping ratios and stiffnesses
    drawn in the ranges of the module (stiffness log-uniform)."""
    q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    f = np.sort(rng.uniform(*FREQUENCY_HZ, 3))
    lo, hi = STIFFNESS_N_PER_M
    k = 10 ** rng.uniform(math.log10(lo), math.log10(hi), 3)
    z = rng.uniform(*DAMPING_RATIO, 3)
    return ToolPointStructure.from_modes([
        {"frequency_Hz": float(f[i]), "damping_ratio": float(z[i]),
         "stiffness_N_per_m": float(k[i]), "direction": q[:, i].tolist()} for i in range(3)])


def random_cut(rng: np.random.Generator, label: str = "") -> CrossCheckCut:
    """A SYNTHETIC cut drawn from the module's ranges."""
    st = random_structure(rng)
    n = float(rng.uniform(*SPEED_RPM))
    f = float(rng.uniform(*FEED_MM_PER_REV)) * 1e-3
    r = float(rng.uniform(*NOSE_RADIUS_MM)) * 1e-3
    ins = BoringInsert(nose_radius_m=r, approach_angle_deg=90.0)
    coef = ti64_coefficients(math.pi * BORE_DIAMETER_M * n)
    return CrossCheckCut(st, ins, f, n, coef, label)


@dataclass(frozen=True)
class CrossCheckResult:
    """Critical depth [m] and the four time-domain verdicts of one cut (``None``: the limit
    is 0 or beyond the scan, nothing to simulate)."""

    cut: CrossCheckCut
    critical_depth_m: float
    runs: tuple[dict[str, Any], ...]
    interrupted_below_m: float = 0.0

    @property
    def applicable(self) -> bool:
        return 0.0 < self.critical_depth_m < math.inf

    @property
    def agrees(self) -> bool | None:
        """Every run's verdict on the side of the limit its depth is on, or stating the
        nonlinear cause (the tool leaving the cut) that takes it outside the linear lobes;
        None when there is nothing to check."""
        if not self.applicable:
            return None
        return all(run_agrees(r) for r in self.runs)

    @property
    def interrupted_confirmed(self) -> bool | None:
        """For a speed without a chatter-free depth (interrupted up to the linear limit):
        whether the time domain below that limit finds the tool leaving the cut."""
        runs = [r for r in self.runs if r.get("interrupted")]
        return None if not runs else all(r["tool_leaves_cut"] for r in runs)

    @property
    def zero_confirmed(self) -> bool | None:
        """For a speed without a chatter-free depth (critical depth 0): whether the time
        domain says chatter at the depth where the lobes say chatter as soon as the cut is in
        the material (1.25 x ``interrupted_below_m`` or the first depth above it, in steps of
        1.25, where the steady cut is in the material; the scan's lowest depth where the cut
        is in the material down to vanishing depth). None when there is no such run (the
        steady cut interrupted up to 20 mm)."""
        runs = [r for r in self.runs if r.get("zero_check")]
        return None if not runs else all(r["chatter"] for r in runs)

    @property
    def nonlinear(self) -> bool:
        """Some run leaves the linear model (the tool leaves the cut)."""
        return any(r["tool_leaves_cut"] for r in self.runs)

    def to_dict(self) -> dict[str, Any]:
        return {**self.cut.describe(),
                "critical_depth_mm": (self.critical_depth_m * 1e3
                                      if math.isfinite(self.critical_depth_m) else None),
                "interrupted_below_mm": self.interrupted_below_m * 1e3,
                "agrees": self.agrees, "runs": list(self.runs)}


def _run_record(ds: Any, v: Any, **where: Any) -> dict[str, Any]:
    """One simulated run of :func:`check_cut`: where it was (``where``) and its verdict."""
    return {**where, "chatter": bool(v.chatter), "decided": bool(v.chatter_decided),
            "cause": v.chatter_cause, "floquet_multiplier": v.floquet_multiplier,
            "vibration_growth": v.vibration_growth,
            "revolutions": int(ds.attrs["revolutions"]),
            "samples_per_rev": int(ds.attrs["samples_per_rev"]),
            "tool_leaves_cut": bool(v.tool_leaves_cut)}


def run_agrees(run: dict[str, Any]) -> bool:
    """A run at ``factor`` x the critical depth agrees when it chatters above the limit and
    does not below it, or when its verdict states the tool leaving the cut; a run checking a
    critical depth of 0 (``zero_check``) agrees when it chatters."""
    if run.get("zero_check"):
        return bool(run["chatter"])
    return bool(run["tool_leaves_cut"] or run["chatter"] == (run["factor"] > 1.0))


def check_cut(cut: CrossCheckCut, factors: tuple[float, ...] = (0.8, 1.25),
              sampling: tuple[int, ...] = (1, 2), process: CuttingProcess | None = None,
              revolutions: int | None = None) -> CrossCheckResult:
    """Semi-discretisation critical depth of ``cut`` and the time-domain verdicts at
    ``factors`` x that depth, at the default samples per revolution times each of
    ``sampling``. ``process``: the process whose lobes are checked (default: the cut's,
    rebuilt at every depth); the time domain always integrates the cut's process at its own
    depth. ``revolutions``: the run length (default: the time domain's own choice)."""
    from robobore.dynamics.chatter import classify
    from robobore.dynamics.semidiscretization import (
        chatter_free_window,
        critical_depth_semidiscretization,
        depth_scan_grid,
        interrupted_below,
        monodromy_spectral_radius,
    )
    from robobore.dynamics.timedomain import SimulationSettings, auto_samples_per_rev, simulate

    pr = cut.process() if process is None else process
    if process is None:
        below, ac = chatter_free_window(cut.structure, pr, cut.speed_rpm)
    else:
        below, ac = 0.0, critical_depth_semidiscretization(cut.structure, pr, cut.speed_rpm)
    runs: list[dict[str, Any]] = []
    if ac == 0.0 and below > 0.0 and 0.8 * below <= MAX_SIMULATED_DEPTH_M:
        # no chatter-free depth: the steady cut is interrupted up to the linear limit; the
        # time domain at 0.8 x that limit must find the tool leaving the cut
        a = 0.8 * below
        ds = simulate(cut.structure, cut.process(a), SimulationSettings(cut.speed_rpm, a),
                      cut.insert)
        runs.append(_run_record(ds, classify(ds), factor=0.8, sampling=1, depth_mm=a * 1e3,
                                interrupted=True))
    a = 1.25 * below if below > 0.0 else float(depth_scan_grid()[0])
    if ac == 0.0 and process is None:
        # where the steady cut is interrupted at and above the linear limit, the first depth
        # above it (steps of 1.25) where the steady cut is in the material
        while a <= MAX_SIMULATED_DEPTH_M and interrupted_below(
                cut.structure, pr, cut.speed_rpm, a) >= a:
            a *= 1.25
    if ac == 0.0 and a <= MAX_SIMULATED_DEPTH_M:
        # no chatter-free depth: the lobes say chatter as soon as the cut is in the material
        # (just above the interrupted cut, or at the scan's lowest depth where it is in the
        # material down to vanishing depth); the time domain there must say chatter
        rho_sd = monodromy_spectral_radius(cut.structure, pr, cut.speed_rpm, a)
        ds = simulate(cut.structure, cut.process(a), SimulationSettings(cut.speed_rpm, a),
                      cut.insert)
        runs.append(_run_record(ds, classify(ds), factor=None, sampling=1, depth_mm=a * 1e3,
                                zero_check=True, sd_spectral_radius=rho_sd))
    if 0.0 < ac < math.inf:
        base = auto_samples_per_rev(cut.structure, cut.speed_rpm, cut.insert.n_inserts)
        for fac in factors:
            a = fac * ac
            if a > MAX_SIMULATED_DEPTH_M:
                continue
            pa = cut.process(a)
            for s in sampling:
                kw = {} if revolutions is None else {"revolutions": int(revolutions)}
                ds = simulate(cut.structure, pa,
                              SimulationSettings(cut.speed_rpm, a, samples_per_rev=base * s,
                                                 **kw), cut.insert)
                runs.append(_run_record(ds, classify(ds), factor=fac, sampling=s,
                                        depth_mm=a * 1e3))
    return CrossCheckResult(cut, ac, tuple(runs), below)


__all__ = ["CrossCheckCut", "CrossCheckResult", "run_agrees", "random_cut", "random_structure",
           "check_cut",
           "FREQUENCY_HZ", "DAMPING_RATIO", "STIFFNESS_N_PER_M", "SPEED_RPM", "FEED_MM_PER_REV",
           "NOSE_RADIUS_MM"]
