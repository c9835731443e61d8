"""The paper's qualitative findings checked on the study's results (computed, never
assumed): trends of the vibration with depth and feed, the onset of vibration per factor,
the pressure foot's and the machine tool's effect. Findings about vibrating are checked
twice: against the chatter verdict and against the paper's roughness criterion
(:func:`vibrates`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from robobore.study.paper_config import PaperConfig


def _rank_corr(x: list[float], y: list[float]) -> float | None:
    if len(x) < 3:
        return None
    rx = np.argsort(np.argsort(x)).astype(float)
    ry = np.argsort(np.argsort(y)).astype(float)
    if rx.std() == 0 or ry.std() == 0:
        return None
    return float(np.corrcoef(rx, ry)[0, 1])


def series(rows: list[dict[str, Any]], cfg: PaperConfig, vary: str, system: str,
           pressure: float) -> list[dict[str, Any]]:
    """Rows of the one-factor series ``vary`` (others at the base), sorted by ``vary``."""
    base = cfg.study.base
    others = [n for n in ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm") if n != vary]
    sel = [r for r in rows if r["system"] == system and r["pressure_MPa"] == pressure
           and all(math.isclose(r[o], base[o]) for o in others) and r.get("summary")]
    return sorted(sel, key=lambda r: r[vary])


def qualitative_checks(rows: list[dict[str, Any]], cfg: PaperConfig) -> list[dict[str, Any]]:
    """The paper's qualitative findings, checked on our results (computed, never assumed).

    Each check: ``finding`` (the paper's), ``verdict`` (what decides "vibrating": the chatter
    verdict, the paper's roughness criterion, or the amplitudes), ``ours`` (what our results
    show), ``agrees``. Findings about vibrating / not vibrating are checked twice, against the
    chatter verdict and, separately, against the paper's criterion.
    """
    out: list[dict[str, Any]] = []
    p_foot = cfg.pressure_foot.pressure_MPa
    paper_onset = {"speed_rpm": 500.0, "feed_mm_per_rev": 0.2, "depth_of_cut_mm": 0.1}
    names = {"speed_rpm": ("spindle speed", "r/min"), "feed_mm_per_rev": ("feed", "mm/r"),
             "depth_of_cut_mm": ("depth of cut", "mm")}
    for vary in ("depth_of_cut_mm", "feed_mm_per_rev"):
        s = series(rows, cfg, vary, "robot", 0.0)
        x = [r[vary] for r in s]
        fa = [r["summary"].get("feed_amplitude_um", math.nan) for r in s]
        fx = [r["summary"].get("force_amplitude_x_N", math.nan) for r in s]
        rho_a, rho_f = _rank_corr(x, fa), _rank_corr(x, fx)
        ok = rho_a is not None and rho_f is not None and rho_a > 0.5 and rho_f > 0.5
        out.append({
            "finding": f"vibration grows with {names[vary][0]} (paper, robot without foot)",
            "verdict": "amplitudes",
            "ours": (f"rank correlation with {names[vary][0]}: feed amplitude "
                     f"{_f(rho_a)}, X force amplitude {_f(rho_f)} ({len(s)} levels)"),
            "agrees": bool(ok) if rho_a is not None else None})
    for verdict in VERDICTS:
        vname = VERDICT_NAMES[verdict].format(tol=cfg.study.ra_tolerance_um)
        word = "chattering" if verdict == "chatter" else "vibratory"
        for vary in ("speed_rpm", "feed_mm_per_rev", "depth_of_cut_mm"):
            s = series(rows, cfg, vary, "robot", 0.0)
            vib = [r[vary] for r in s if vibrates(r["summary"], verdict) is True]
            onset = min(vib) if vib else None
            name, unit = names[vary]
            po = paper_onset[vary]
            levels = [r[vary] for r in s]
            if onset is None:
                ours = f"no {word} level of {name} in {_lv(levels)} {unit}"
                agrees = False
            else:
                above = [r for r in s if r[vary] >= onset]
                mono = all(vibrates(r["summary"], verdict) is True for r in above)
                ours = (f"first {word} {name}: {onset:g} {unit}"
                        + ("" if mono else f" (not {word} at every higher level)"))
                # agreement: our onset falls between the level below the paper's and the
                # paper's
                below = [v for v in levels if v < po]
                lo = max(below) if below else -math.inf
                agrees = lo < onset <= po * 1.0000001 and mono
            out.append({"finding": f"vibratory from {name} >= {po:g} {unit} (paper, onset)",
                        "verdict": vname, "ours": ours, "agrees": agrees})
    pairs = []
    by = {(r["speed_rpm"], r["feed_mm_per_rev"], r["depth_of_cut_mm"]): r for r in rows
          if r["system"] == "robot" and r["pressure_MPa"] == 0.0 and r.get("summary")}
    for r in rows:
        if r["system"] == "robot" and r["pressure_MPa"] == p_foot and r.get("summary"):
            b = by.get((r["speed_rpm"], r["feed_mm_per_rev"], r["depth_of_cut_mm"]))
            if b is not None:
                pairs.append((b["summary"], r["summary"]))
    if pairs:
        from robobore.dynamics.chatter import AMPLITUDE_RESOLUTION_M

        res_um = AMPLITUDE_RESOLUTION_M * 1e6
        # a pair is a finding only where the amplitude without the foot is resolved; one
        # below resolution with the foot counts as lower, and ratios are of resolved values
        resolved = [(a, b) for a, b in pairs if a.get("feed_amplitude_um", 0) >= res_um]
        lower = sum(1 for a, b in resolved
                    if b.get("feed_amplitude_um", 0) < a.get("feed_amplitude_um", 0))
        lower_f = sum(1 for a, b in pairs
                      if b.get("force_amplitude_x_N", 0) < a.get("force_amplitude_x_N", 0))
        ratio = [b["feed_amplitude_um"] / a["feed_amplitude_um"] for a, b in resolved
                 if b.get("feed_amplitude_um", 0) >= res_um]
        below = sum(1 for _, b in resolved if b.get("feed_amplitude_um", 0) < res_um)
        med = float(np.median(ratio)) if ratio else None
        detail = (f"median ratio with/without {_f(med)}" if med is not None
                  else "no pair resolved on both sides")
        if below:
            detail += f"; with the foot below the {res_um * 1e3:g} nm resolution in {below}"
        if len(resolved) < len(pairs):
            detail += (f"; {len(pairs) - len(resolved)} pair(s) below resolution without the "
                       "foot (not a finding)")
        out.append({"finding": f"the pressure foot ({p_foot:g} MPa) reduces the feed "
                               "(vibration) amplitude",
                    "verdict": "amplitudes",
                    "ours": (f"feed amplitude lower with the foot in {lower}/{len(resolved)} "
                             f"resolved conditions ({detail})"),
                    "agrees": bool(resolved) and lower >= 0.8 * len(resolved)})
        out.append({"finding": f"the pressure foot ({p_foot:g} MPa) reduces the cutting-force "
                               "amplitude",
                    "verdict": "amplitudes",
                    "ours": f"X force amplitude lower with the foot in {lower_f}/{len(pairs)} "
                            "conditions",
                    "agrees": lower_f >= 0.8 * len(pairs)})
        for verdict in VERDICTS:
            word = "chattering" if verdict == "chatter" else "vibratory"
            vib0 = sum(1 for a, _ in pairs if vibrates(a, verdict) is True)
            vib1 = sum(1 for _, b in pairs if vibrates(b, verdict) is True)
            out.append({"finding": "the pressure foot suppresses vibration (fewer vibratory "
                                   "cuts)",
                        "verdict": VERDICT_NAMES[verdict].format(tol=cfg.study.ra_tolerance_um),
                        "ours": f"{word}: {vib0} without the foot, {vib1} with it "
                                f"(of {len(pairs)})",
                        "agrees": vib1 <= vib0})
    mt = {(r["speed_rpm"], r["feed_mm_per_rev"], r["depth_of_cut_mm"]): r for r in rows
          if r["system"] == "machine_tool" and r.get("summary")}
    if mt:
        n = lower = 0
        for k, r in mt.items():
            b = by.get(k)
            if b is None:
                continue
            n += 1
            lower += r["summary"]["feed_amplitude_um"] <= b["summary"]["feed_amplitude_um"]
        vibs = {v: sum(1 for r in mt.values() if vibrates(r["summary"], v) is True)
                for v in VERDICTS}
        out.append({"finding": "a (stiff) machine tool vibrates less than the robot",
                    "verdict": "feed amplitude",
                    "ours": f"machine tool feed amplitude <= robot's in {lower}/{n} conditions; "
                            f"machine tool chattering in {vibs['chatter']}/{len(mt)}, "
                            f"vibratory by the paper's criterion in {vibs['paper']}/{len(mt)}",
                    "agrees": lower >= 0.8 * n if n else None})
    return out


#: The verdicts the paper's findings are checked against (:func:`vibrates`).
VERDICTS = ("chatter", "paper")
VERDICT_NAMES = {"chatter": "chatter (vibration grows)",
                 "paper": "paper's criterion (Ra > {tol:g} um)"}


def vibrates(summary: dict[str, Any] | None, verdict: str) -> bool | None:
    """Whether a condition's summary counts as vibrating under ``verdict``: ``"chatter"``
    (the vibration grows, :mod:`robobore.dynamics.chatter`) or ``"paper"`` (the paper's
    criterion, the summary's ``stable`` flag: Ra above the tolerance). None when unknown."""
    if not summary:
        return None
    if verdict == "chatter":
        v = summary.get("chatter")
        return None if v is None else bool(v)
    st = summary.get("stable")
    return None if st is None else not st


def _f(v: float | None) -> str:
    return "n/a" if v is None or not math.isfinite(v) else f"{v:.3g}"


def _lv(levels: list[float]) -> str:
    return ", ".join(f"{v:g}" for v in levels)


__all__ = ["qualitative_checks", "series", "vibrates", "VERDICTS", "VERDICT_NAMES"]
