"""Hand-offs into the dynamics stage: the previous stages' objects as config sections.

:func:`with_equivalent` turns an :class:`~robobore.equivalent.EquivalentModel` (or its dict
form) into the ``[equivalent]`` section of a process-only config; :func:`with_coefficients`
turns the cutting stage's :class:`~robobore.cutting.forces.CuttingCoefficients` or a
coefficients-file content into the ``[coefficients]`` table. Used by
:mod:`robobore.dynamics.api` and :func:`robobore.dynamics.config.resolve_model_files`.
"""

from __future__ import annotations

from typing import Any

from robobore.errors import ConfigError, InputError

#: the keys of :meth:`robobore.equivalent.EquivalentModel.to_dict` (``model equivalent --json``)
EQUIVALENT_KEYS = frozenset({"stiffness_N_per_m", "frequency_Hz", "damping_ratio", "mass_kg",
                              "damping_N_s_per_m", "frame", "foot", "notes",
                              "identity", "uncertainty"})


def equivalent_arg(equivalent: Any, name: str = "equivalent"):
    """An :class:`~robobore.equivalent.EquivalentModel` from the model or its dict form
    (:meth:`~robobore.equivalent.EquivalentModel.to_dict`, the JSON of ``robobore model
    equivalent``); anything else is an :class:`InputError` naming the argument ``name``."""
    from robobore.equivalent import EquivalentModel

    if isinstance(equivalent, EquivalentModel):
        return equivalent
    if isinstance(equivalent, dict):
        extra = sorted(set(equivalent) - EQUIVALENT_KEYS)
        if extra:
            raise ConfigError("unknown key of an equivalent model", field=f"{name}.{extra[0]}",
                              expected="the keys of EquivalentModel.to_dict ("
                                       + ", ".join(sorted(EQUIVALENT_KEYS)) + "); a pressure "
                                       "foot for the process goes in the config's [equivalent] "
                                       "pressure_foot")
        return EquivalentModel.from_dict(equivalent)
    raise InputError("not an equivalent model", field=name, value=type(equivalent).__name__,
                     expected="an EquivalentModel or its dict form (model equivalent --json)")


def equivalent_section(em: Any, note: str) -> dict[str, Any]:
    """The ``[equivalent]`` section of an :class:`~robobore.equivalent.EquivalentModel`
    (its values, frame and whether a pressure foot is included), with ``note``."""
    return {"stiffness_N_per_m": dict(em.stiffness_N_per_m),
            "frequency_Hz": dict(em.frequency_Hz),
            "damping_ratio": dict(em.damping_ratio),
            "frame": [list(r) for r in em.frame],
            "foot_included": em.foot is not None,
            "note": note,
            **({"uncertainty": {a: dict(v) for a, v in em.uncertainty.items()}}
               if em.uncertainty else {})}


def equivalent_extras(raw: dict[str, Any], given_twice: str, otherwise: str,
                      source: str | None) -> dict[str, Any]:
    """The ``[equivalent]`` keys of ``raw`` that may stand beside a robot model given
    elsewhere (``pressure_foot``, ``note``); any other value there gives the model twice
    (ConfigError naming ``given_twice``; ``otherwise`` completes what is expected)."""
    eq_raw = raw.get("equivalent")
    if eq_raw is None:
        return {}
    if not isinstance(eq_raw, dict) or set(eq_raw) - {"pressure_foot", "note"}:
        raise ConfigError(f"the robot model is given twice ({given_twice})", file=source,
                          field="equivalent",
                          expected=f"[equivalent] with only pressure_foot/note, or {otherwise}")
    return dict(eq_raw)


def with_equivalent(raw: dict[str, Any], equivalent: Any, source: str | None = None
                    ) -> dict[str, Any]:
    """``raw`` with its ``[equivalent]`` section made from ``equivalent`` (an
    :class:`~robobore.equivalent.EquivalentModel` or its dict form): the process config then
    holds only the process. An ``[equivalent]`` there may carry only ``pressure_foot``/``note``
    (kept); ``[model]`` files or equivalent values would give the robot twice (ConfigError)."""
    em = equivalent_arg(equivalent)
    sec = raw.get("model")
    if isinstance(sec, dict) and any(sec.get(k) is not None for k in
                                     ("stiffness_file", "modes_file", "equivalent_file")):
        raise ConfigError("the robot model is given twice ([model] files and the equivalent "
                          "argument)", file=source, field="model",
                          expected="a config without [model] files when an equivalent model "
                                   "is given")
    extra = equivalent_extras(raw, "[equivalent] values and the equivalent argument",
                              "none", source)
    out = dict(raw)
    out["equivalent"] = {**equivalent_section(em, "; ".join(em.notes)), **extra}
    return out


def with_coefficients(raw: dict[str, Any]) -> dict[str, Any]:
    """``raw`` with a ``coefficients`` entry given as the cutting stage's result turned into
    the ``[coefficients]`` table: a :class:`~robobore.cutting.forces.CuttingCoefficients`
    (its values, used as given at every speed) or a coefficients-file content (the output of
    ``robobore calibrate forces``,
    :func:`~robobore.cutting.coefficient_files.read_coefficients_file`:
    :func:`~robobore.cutting.coefficient_files.inline_coefficients`, per-speed fits included). A
    table of the section's own keys is left as it is."""
    c = raw.get("coefficients")
    if c is None or (isinstance(c, dict) and not isinstance(c.get("coefficients"), dict)):
        return raw
    from robobore.cutting.coefficient_files import inline_coefficients
    from robobore.cutting.forces import CuttingCoefficients

    if isinstance(c, CuttingCoefficients):
        return {**raw, "coefficients": c.to_dict()}
    if isinstance(c, dict):
        return {**raw, "coefficients": inline_coefficients(c)}
    return raw


__all__ = ["EQUIVALENT_KEYS", "equivalent_arg", "equivalent_extras", "equivalent_section",
           "with_equivalent", "with_coefficients"]
