"""Contradictions in robobore's outputs: a record that says two incompatible things at once.

:func:`contradictions` walks a JSON-like output (the ``to_dict()`` of ``simulate boring``,
``lobes``, ``plan posture``, ``paper`` and ``compare``, or any dict/list nesting of them) and
returns one line per contradiction it finds, naming the path of the record. The rules, each
applied to every dict that holds the keys it names:

* a cut that chatters (``chatter`` true) or diverged is not ``stable`` and its paper's
  criterion (``paper_criterion``, or ``verdicts.paper_criterion``) is not "stable";
* a diverged run chatters and has no chatter frequency;
* a chatter frequency is given only for a cut that chatters, and it is positive and finite;
* without an Ra tolerance the paper's criterion is never "stable" (``stable`` null, or false
  for a cut that chatters), and where ``stable`` is false the cut chatters, diverged or is
  rough;
* ``stable`` true and ``surface_finish`` "rough" do not go together;
* the tool leaves the cut exactly when ``tool_left_cut_fraction`` is above 0;
* every flag has its reason: ``reasons`` names chatter when the cut chatters, roughness when
  it is rough, the tool leaving the cut when it does, and an undecided verdict when
  ``chatter_decided`` is false;
* lobes (``critical_depth_mm`` list beside ``absolute_limit_mm``): no negative depth, and the
  absolute limit is the lowest of the finite limits;
* a study summary (``computed``, ``stable``, ``vibratory``, ``chatter``): stable and vibratory
  count at most the computed conditions, and every chattering or rough condition is
  vibratory;
* a stable/vibratory agreement (``n``, ``agree``, ``both_stable``, ``both_vibratory``): the
  agreeing conditions are the both-stable and both-vibratory ones, and no more than ``n``.

``tests/test_output_consistency.py`` holds every command's output to it over random cuts.
"""

from __future__ import annotations

import math
from typing import Any


def _num(v: Any) -> float | None:
    if isinstance(v, bool) or v is None:
        return None
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def _reasons(d: dict[str, Any]) -> list[str] | None:
    r = d.get("reasons")
    if isinstance(r, str):
        return [x for x in r.split("; ") if x]
    if isinstance(r, list | tuple):
        return [str(x) for x in r]
    return None


def _record(d: dict[str, Any], where: str) -> list[str]:
    out: list[str] = []

    def bad(msg: str) -> None:
        out.append(f"{where or '<top>'}: {msg}")

    chatter = d.get("chatter")
    stable = d.get("stable")
    diverged = d.get("diverged")
    verdicts = d.get("verdicts") if isinstance(d.get("verdicts"), dict) else {}
    paper = d.get("paper_criterion", verdicts.get("paper_criterion"))
    finish = d.get("surface_finish", verdicts.get("surface_finish"))
    if isinstance(chatter, bool) and not isinstance(d.get("computed"), int):
        if chatter and stable is True:
            bad("stable and chatter")
        if chatter and paper == "stable":
            bad("the paper's criterion says stable and the cut chatters")
        if diverged is True and not chatter:
            bad("diverged but no chatter")
        if diverged is True and d.get("chatter_frequency_Hz") is not None:
            bad("a diverged run with a chatter frequency")
        f = _num(d.get("chatter_frequency_Hz"))
        if d.get("chatter_frequency_Hz") is not None:
            if not chatter:
                bad(f"chatter frequency {d['chatter_frequency_Hz']} Hz without chatter")
            elif f is None or not math.isfinite(f) or f <= 0:
                bad(f"chatter frequency {d['chatter_frequency_Hz']} Hz")
        if "ra_tolerance_um" in d and d["ra_tolerance_um"] is None and stable is True:
            bad("the paper's criterion judged stable without an Ra tolerance")
        if stable is False and not chatter and diverged is not True and finish != "rough":
            bad("vibratory by the paper's criterion with neither chatter nor roughness")
        if stable is True and finish == "rough":
            bad("stable and rough")
        left = d.get("tool_leaves_cut")
        frac = _num(d.get("tool_left_cut_fraction"))
        if isinstance(left, bool) and frac is not None and left != (frac > 0):
            bad(f"tool_leaves_cut {left} with tool_left_cut_fraction {frac}")
        reasons = _reasons(d)
        if reasons is not None:
            text = " | ".join(reasons)
            if chatter and "chatter:" not in text:
                bad("chatter without its reason")
            if finish == "rough" and "rough" not in text:
                bad("rough without its reason")
            if left is True and "leaves the cut" not in text:
                bad("the tool leaves the cut without its reason")
            if d.get("chatter_decided") is False and "undecided" not in text:
                bad("an undecided verdict without its reason")
    depths = d.get("critical_depth_mm")
    if isinstance(depths, list | tuple) and "absolute_limit_mm" in d:
        vals = [_num(x) for x in depths]
        finite = [x for x in vals if x is not None and math.isfinite(x)]
        if any(x < 0 for x in finite):
            bad("a negative critical depth")
        lim = _num(d["absolute_limit_mm"])
        if finite and lim is not None and not math.isclose(lim, min(finite), rel_tol=1e-9,
                                                          abs_tol=1e-12):
            bad(f"absolute limit {lim} mm is not the lowest limit {min(finite)} mm")
    if isinstance(d.get("computed"), int) and isinstance(d.get("stable"), int):
        n, s, v = d["computed"], d["stable"], d.get("vibratory")
        if isinstance(v, int):
            if s + v > n:
                bad(f"{s} stable + {v} vibratory of {n} computed")
            for key in ("chatter", "rough"):
                c = d.get(key)
                if isinstance(c, int) and not isinstance(c, bool) and c > v:
                    bad(f"{c} {key} but only {v} vibratory")
    if all(isinstance(d.get(k), int) for k in ("n", "agree", "both_stable", "both_vibratory")):
        if d["agree"] != d["both_stable"] + d["both_vibratory"] or d["agree"] > d["n"]:
            bad(f"agreement {d['agree']} of {d['n']} is not both-stable "
                f"{d['both_stable']} + both-vibratory {d['both_vibratory']}")
    return out


def contradictions(output: Any, where: str = "") -> list[str]:
    """Every contradiction in ``output`` (module docstring), one line each naming its path;
    an empty list when the output tells one story."""
    found: list[str] = []
    if isinstance(output, dict):
        found += _record(output, where)
        for k, v in output.items():
            if isinstance(v, dict | list | tuple):
                found += contradictions(v, f"{where}.{k}" if where else str(k))
    elif isinstance(output, list | tuple):
        for i, v in enumerate(output):
            if isinstance(v, dict | list | tuple):
                found += contradictions(v, f"{where}[{i}]")
    return found


__all__ = ["contradictions"]
