"""One-call entry points of the process stage for other stages (sweeps, reports).

:func:`run_boring` simulates one cutting condition from a config (path, dict or validated
:class:`~robobore.dynamics.config.DynamicsConfig`) and returns a
:class:`~robobore.dynamics.results.BoringResult`, whose ``to_dict()`` is the JSON-ready
summary of ``robobore simulate boring --json``; :func:`lobes` returns a
:class:`~robobore.dynamics.results.LobesResult` (the ``robobore lobes --json`` contents) and
:func:`critical_depth_at` a :class:`~robobore.dynamics.results.CriticalDepth` (the fields of
each documented in :mod:`robobore.dynamics.results`). Conditions given as arguments
override the config (speed, depth, feed, foot pressure), so a sweep needs only one config
file. Both take the robot as the
equivalent-model stage's object (``equivalent=``, an
:class:`~robobore.equivalent.EquivalentModel` or its dict form) when the config holds only
the process; a dict config's ``coefficients`` may be the cutting stage's
:class:`~robobore.cutting.forces.CuttingCoefficients` or a coefficients-file content
(:func:`robobore.dynamics.handoff.with_coefficients`).

The summary's verdicts (:mod:`robobore.dynamics.chatter`): ``chatter`` (the vibration
grows from pitch to pitch: the Floquet multiplier of the simulated cut above 1, or a
nonlinear cause named in ``chatter_cause``), ``chatter_decided`` (False when the multiplier is
within its uncertainty of 1 even after the run was lengthened, or when the tool leaves the
cut and the same run at twice the samples per revolution, ``sampling_check``, gives the other
verdict), ``tool_leaves_cut_cause`` (why the tool leaves the cut: "forced vibration", not
chatter, or "regenerative vibration"; None while it stays in the cut),
``surface_finish`` ("ok" /
"rough": Ra after form removal against ``ra_tolerance_um``; None without a tolerance),
``tool_leaves_cut``, and ``stable``: the paper's criterion (vibratory when Ra exceeds the
tolerance, the cut chatters or the run diverged; None without a tolerance otherwise), also
under ``verdicts["paper_criterion"]``. ``feed_amplitude_resolved`` is False below the
documented resolution (1 nm, :data:`robobore.dynamics.chatter.AMPLITUDE_RESOLUTION_M`).
"""


from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from robobore.dynamics.config import (
    DynamicsConfig,
    PressureFootCfg,
    build_coefficients,
    build_process,
    build_structure,
    load_dynamics_config,
    resolve_model_files,
)
from robobore.dynamics.handoff import with_coefficients, with_equivalent
from robobore.dynamics.results import (
    BoringResult,
    CriticalDepth,
    LobesResult,
    SamplingCheck,
    Vector3,
    Verdicts,
)
from robobore.errors import ConfigError, InputError
from robobore.io.config import validate_model
from robobore.io.ranges import check_positive

#: An undecided run (:attr:`~robobore.dynamics.chatter.ChatterVerdict.chatter_decided`) is
#: lengthened, doubling its revolutions, up to this factor of the configured revolutions.
UNDECIDED_MAX_FACTOR = 4


def _config(config: str | Path | dict[str, Any] | DynamicsConfig, source: str | None = None,
            equivalent: Any = None, **model_files: Any
            ) -> tuple[DynamicsConfig, dict[str, Any], str | None]:
    if isinstance(config, DynamicsConfig):
        if equivalent is None:
            return config.model_copy(deep=True), config.model_dump(), source
        config = config.model_dump()
    if isinstance(config, dict):
        if equivalent is not None:
            config = with_equivalent(config, equivalent, source)
        config = with_coefficients(config)
        # [model] file names of a dict config are relative to its source file's folder when
        # one is named, else to the working directory
        base = Path(source) if source else Path.cwd() / "<config dict>"
        config = resolve_model_files(config, base, **model_files)
        return (validate_model(DynamicsConfig, config, source=source or "<config>"), config,
                source)
    if not isinstance(config, str | Path):
        raise InputError("not a process config", field="config", value=type(config).__name__,
                         expected="a TOML path, a config dict or a DynamicsConfig")
    cfg, raw = load_dynamics_config(config, equivalent=equivalent, **model_files)
    return cfg, raw, str(config)


def run_boring(config: str | Path | dict[str, Any] | DynamicsConfig,
               speed_rpm: float | None = None, depth_mm: float | None = None,
               feed_mm_per_rev: float | None = None, pressure_MPa: float | None = None,
               revolutions: int | None = None, samples_per_rev: int | None = None,
               return_dataset: bool = False, source: str | None = None,
               equivalent: Any = None) -> BoringResult:
    """Simulate one condition; returns the summary (:class:`BoringResult`, its ``to_dict()``
    the ``simulate boring --json`` contents; ``dataset`` and ``config`` set if asked).

    ``source`` names where a dict or model config came from (a file, a section), for error
    messages. ``equivalent``: the robot as the equivalent-model stage's
    :class:`~robobore.equivalent.EquivalentModel` (or its dict form), when the config holds
    only the process (:func:`robobore.dynamics.handoff.with_equivalent`).

    ``pressure_MPa`` (boring configs with an ``[equivalent]`` section) replaces the pressure
    foot: 0 removes it, a positive value sets ``pressure_MPa`` keeping the other foot keys.
    """
    from robobore.dynamics.chatter import (AMPLITUDE_RESOLUTION_M, chatter_decision, classify,
                                           resolved)
    from robobore.dynamics.timedomain import SimulationSettings, TimeDomainRun, summarize

    cfg, raw, src = _config(config, source, equivalent)
    if feed_mm_per_rev is not None:
        check_positive(feed_mm_per_rev, "feed_mm_per_rev", file=src, field="feed_mm_per_rev")
    if cfg.cutting is not None:
        upd = {}
        if speed_rpm is not None:
            upd["speed_rpm"] = speed_rpm
        if depth_mm is not None:
            upd["depth_mm"] = depth_mm
        if feed_mm_per_rev is not None:
            upd["feed_mm_per_rev"] = feed_mm_per_rev
        cfg.cutting = cfg.cutting.model_copy(update=upd)
    elif feed_mm_per_rev is not None and cfg.process is not None:
        cfg.process = cfg.process.model_copy(update={"feed_mm_per_rev": feed_mm_per_rev})
    if pressure_MPa is not None:
        if cfg.equivalent is None:
            raise ConfigError("a foot pressure needs an [equivalent] section", file=src,
                              field="pressure_MPa", value=pressure_MPa)
        if cfg.equivalent.foot_included:
            raise ConfigError("the equivalent model already includes a pressure foot", file=src,
                              field="pressure_MPa", value=pressure_MPa,
                              expected="the model without the foot (model equivalent without "
                                       "--foot-pressure-MPa) to set the pressure here")
        foot = cfg.equivalent.pressure_foot or PressureFootCfg()
        cfg.equivalent = cfg.equivalent.model_copy(update={
            "pressure_foot": None if pressure_MPa == 0 else foot.model_copy(
                update={"pressure_MPa": float(pressure_MPa)})})
    n = speed_rpm if speed_rpm is not None else (cfg.cutting.speed_rpm if cfg.cutting else None)
    a = depth_mm if depth_mm is not None else (cfg.cutting.depth_mm if cfg.cutting else None)
    if n is None:
        raise ConfigError("no spindle speed", file=src, field="speed_rpm",
                          expected="a speed in r/min or a [cutting] section")
    if a is None:
        raise ConfigError("no depth of cut", file=src, field="depth_mm",
                          expected="a depth in mm or a [cutting] section")
    check_positive(n, "speed_rpm", file=src, field="speed_rpm")
    check_positive(a, "depth_mm", file=src, field="depth_mm")
    revs = revolutions if revolutions is not None else cfg.simulation.revolutions
    nspr = samples_per_rev if samples_per_rev is not None else cfg.simulation.samples_per_rev
    st = build_structure(cfg, src)
    coef = build_coefficients(cfg, src) if cfg.is_boring else None
    pr = build_process(cfg, src, depth_m=a * 1e-3 if cfg.is_boring else None, coefficients=coef)
    tol = cfg.simulation.ra_tolerance_um
    ins = cfg.insert.to_insert() if cfg.is_boring else None
    extend = revolutions is None and cfg.simulation.extend_undecided

    def decision(r: TimeDomainRun):  # the chatter verdict of a run (classify's), no Dataset
        X, area = r.record()
        return chatter_decision(X, area, r.Ns, r.N, r.settings.depth_m,
                                r.process.feed_per_rev_m, r.diverged)

    run = None
    while True:
        try:
            if run is None:
                run = TimeDomainRun(st, pr, SimulationSettings(float(n), a * 1e-3, int(revs),
                                                               int(nspr)), ins,
                                    reserve_revolutions=UNDECIDED_MAX_FACTOR * int(revs)
                                    if extend else None)
            else:  # continued: the run of twice the revolutions, paying only the new ones
                run.extend(run.revolutions)
        except ConfigError as exc:  # a settings error (size guard): name the config file
            if exc.file is None and src is not None:
                raise ConfigError(exc.message, file=src, field=exc.field, value=exc.value,
                                  expected=exc.expected) from None
            raise
        # near the stability limit the growth per pitch is within its uncertainty of 1:
        # lengthen the run (up to UNDECIDED_MAX_FACTOR x) before saying so
        dec = None  # the decision on the run's final length, where it was made here
        if not extend or run.revolutions >= UNDECIDED_MAX_FACTOR * int(revs):
            break
        dec = decision(run)
        if dec.decided:
            break
    ds = run.dataset()
    v = classify(ds, ra_tolerance_m=None if tol is None else tol * 1e-6, decision=dec)
    revs = run_revs = run.revolutions
    # where the tool leaves the cut the force is not smooth in the displacement and the
    # verdict can depend on where the steps fall: the same run at twice the samples per
    # revolution must agree, or the verdict is undecided (said, with both verdicts)
    sampling_check = None
    if v.tool_leaves_cut and not int(ds.attrs["diverged"]):
        spr2 = 2 * int(ds.attrs["samples_per_rev"])
        try:  # only its chatter verdict is compared
            v2 = decision(TimeDomainRun(st, pr, SimulationSettings(float(n), a * 1e-3,
                                                                   run_revs, spr2), ins))
        except ConfigError:  # the doubled run is over the size guard: no check
            v2 = None
        if v2 is not None:
            sampling_check = SamplingCheck(samples_per_rev=spr2, chatter=bool(v2.chatter),
                                           agrees=bool(v2.chatter == v.chatter))
            if v2.chatter != v.chatter:
                v = replace(v, chatter_decided=False, reasons=v.reasons + (
                    f"undecided: the tool leaves the cut and the verdict changes with the "
                    f"sampling ({'chatter' if v.chatter else 'no chatter'} at "
                    f"{int(ds.attrs['samples_per_rev'])} samples per revolution, "
                    f"{'chatter' if v2.chatter else 'no chatter'} at {spr2}): an interrupted, "
                    "nonlinear cut; below the depth "
                    "where the forced vibration leaves the cut (interrupted_below_mm of "
                    "`robobore lobes`) the cut is not chatter-free",))
    s = summarize(ds)
    coef_warn = tuple([] if coef is None else coef.domain_warnings(pr.h0))
    return BoringResult(
        stable=v.paper_stable,
        verdicts=Verdicts(**v.verdicts()),
        chatter=v.chatter,
        surface_finish=v.surface_finish,
        tool_leaves_cut=v.tool_leaves_cut,
        chatter_frequency_Hz=v.chatter_frequency_Hz,
        chatter_decided=v.chatter_decided,
        sampling_check=sampling_check,
        chatter_cause=v.chatter_cause,
        tool_leaves_cut_cause=v.tool_leaves_cut_cause,
        floquet_multiplier=v.floquet_multiplier,
        floquet_multiplier_se=v.floquet_multiplier_se,
        vibration_growth=v.vibration_growth,
        feed_amplitude_growth=v.feed_amplitude_growth,
        radial_amplitude_growth=v.radial_amplitude_growth,
        force_mean_N=Vector3(**s["force_mean_N"]),
        force_amplitude_N=Vector3(**s["force_amplitude_N"]),
        feed_amplitude_um=s["feed_amplitude_m"] * 1e6,
        feed_amplitude_resolved=resolved(s["feed_amplitude_m"]),
        amplitude_resolution_um=AMPLITUDE_RESOLUTION_M * 1e6,
        nonharmonic_energy_ratio=v.nonharmonic_energy_ratio,
        roughness_Ra_um=ds.attrs["Ra_m"] * 1e6,
        roughness_Rz_um=ds.attrs["Rz_m"] * 1e6,
        roughness_Ra_with_form_um=ds.attrs["Ra_with_form_m"] * 1e6,
        form_slope_um_per_mm=ds.attrs["form_slope_um_per_mm"],
        ra_tolerance_um=tol,
        tool_left_cut_fraction=v.tool_left_cut_fraction,
        reasons=tuple(v.reasons),
        diverged=bool(ds.attrs["diverged"]),
        speed_rpm=float(n), depth_mm=float(a), revolutions=int(revs),
        revolutions_simulated=int(ds.attrs["revolutions"]),
        samples_per_rev=int(ds.attrs["samples_per_rev"]), process=pr.label,
        model="robobore.dynamics time-domain boring (regenerative, mechanistic forces)",
        # the set used at this condition's cutting speed (speed-dependent coefficients)
        coefficients_provenance=None if coef is None else coef.provenance,
        coefficient_warnings=coef_warn,
        warnings=coef_warn,
        dataset=ds if return_dataset else None,
        config=raw if return_dataset else None,
    )


def lobes(config: str | Path | dict[str, Any] | DynamicsConfig,
          method: str = "semidiscretization", progress=None,
          equivalent: Any = None) -> LobesResult:
    """Lobes of a config (:class:`LobesResult`: the ``robobore lobes --json`` contents,
    without ``notes`` and ``process``).

    ``method``: ``"semidiscretization"`` (default; includes the rotating bar's periodic
    directions and depth modulation) or ``"frequency"`` (zero-order, fast). ``equivalent``:
    the robot as an :class:`~robobore.equivalent.EquivalentModel` (or its dict form) for a
    config that holds only the process, as in :func:`run_boring`."""
    import numpy as np

    from robobore.dynamics import stability

    cfg, _, src = _config(config, equivalent=equivalent)
    st = build_structure(cfg, src)
    coef = build_coefficients(cfg, src) if cfg.is_boring else None
    pr = build_process(cfg, src, coefficients=coef)
    from robobore.dynamics.config import speed_range

    sp, default_note = speed_range(cfg)  # DEFAULT_SPEED_RPM without [speed_rpm]
    speeds = np.linspace(sp.min, sp.max, sp.count)
    if method == "frequency":
        res = stability.lobes_frequency_domain(st, pr, speeds)
    elif method == "semidiscretization":
        res = stability.lobes_semidiscretization(st, pr, speeds, progress=progress)
    else:
        raise ConfigError("unknown method", field="method", value=method,
                          expected="frequency or semidiscretization")
    mc = stability.mode_coupling_limit(st, pr)
    note = None
    if coef is not None:
        from robobore.dynamics.config import lobe_coefficient_note

        note = lobe_coefficient_note(cfg, coef)
    return LobesResult(**res.to_dict(),
                       mode_coupling_limit_mm=mc * 1e3 if math.isfinite(mc) else None,
                       speed_note=default_note,
                       warnings=tuple([] if coef is None else coef.domain_warnings(pr.h0)),
                       coefficient_note=note)


def critical_depth_at(config: str | Path | dict[str, Any] | DynamicsConfig, speed_rpm: float,
                      equivalent: Any = None, guess_mm: float | None = None) -> CriticalDepth:
    """The semi-discretisation answer of :func:`lobes` at one speed
    (:class:`CriticalDepth`): ``critical_depth_mm``
    (None: stable up to the scan top; 0: no chatter-free depth) and
    ``interrupted_below_mm`` (:func:`robobore.dynamics.semidiscretization.chatter_free_window`)
    of the config's robot and process. ``guess_mm``: the limit at a neighbouring speed (the
    lobes' own), to continue from as :func:`lobes` does instead of the depth scan."""
    from robobore.dynamics.semidiscretization import chatter_free_window

    cfg, _, src = _config(config, equivalent=equivalent)
    check_positive(speed_rpm, "speed_rpm", file=src, field="speed_rpm")
    st = build_structure(cfg, src)
    coef = build_coefficients(cfg, src) if cfg.is_boring else None
    pr = build_process(cfg, src, coefficients=coef)
    guess = (float(guess_mm) * 1e-3 if guess_mm is not None and math.isfinite(guess_mm)
             and guess_mm > 0.0 else None)
    below, a = chatter_free_window(st, pr, float(speed_rpm), guess_m=guess)
    return CriticalDepth(speed_rpm=float(speed_rpm),
                         critical_depth_mm=a * 1e3 if math.isfinite(a) else None,
                         interrupted_below_mm=below * 1e3)


__all__ = ["run_boring", "lobes", "critical_depth_at", "UNDECIDED_MAX_FACTOR"]
