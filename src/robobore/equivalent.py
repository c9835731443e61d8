"""Equivalent mass-spring-damper model of the robotic boring system (paper eq. 1-3).

The robot + end-effector is replaced, in each direction of the boring frame (X horizontal,
Y vertical, Z feed), by one mass-spring-damper unit::

    m_d x_d'' + c_d x_d' + k_d x_d = F_d          d in {x, y, z}
    m_d = k_d / omega_n,d^2                        (eq. 3 of the paper)
    c_d = 2 zeta_d sqrt(k_d m_d)                   (from a modal damping ratio)
    zeta_d = c_d / (2 sqrt(k_d m_d))               (from a given damping coefficient)

Inputs are plain numbers, the other stages' result objects or their JSON contracts:

* robot stiffness: ``{"directional_stiffness_N_per_m": {"x": .., "y": .., "z": ..}}`` (the
  JSON of ``robobore identify stiffness``), the ``{"x", "y", "z"}`` table of
  :func:`robobore.robot.stiffness.directional_stiffness_xyz`, a
  :class:`~robobore.robot.identify.StiffnessIdentification` (its directional stiffness at the
  campaign's first posture) or a :class:`~robobore.robot.stiffness.StiffnessResult` of
  ``stiffness_at`` (its ``directional_stiffness_N_per_m``)
* modal analysis: ``{"modes": [{"frequency_Hz": .., "damping_ratio": .., "mpc": ..,
  optional "direction": [3] or "x"/"y"/"z", optional "shape": [3]}]}`` (the JSON of
  ``robobore identify modes``), a :class:`~robobore.modal.identify.ModalResult` or a
  :class:`~robobore.modal.identify.ModalAnalysis` (its ``result``)

How modes are assigned to X, Y, Z (:meth:`EquivalentModel.from_stiffness_and_modes`):

1. if every mode carries a ``direction`` (3-vector or axis letter) or a 3-component
   ``shape``, each axis takes the lowest-frequency mode whose direction has its largest
   absolute component on that axis (a mode can serve one axis only);
2. otherwise the user's ``assignment`` mapping ``{"x": i, "y": j, "z": k}`` (0-based mode
   indices) is used;
3. default: mode 0 -> X, mode 1 -> Y, mode 2 -> Z.

Principal directions: with equal masses in all directions (the paper's assumption) the
uncoupled principal directions are the eigenvectors of the 3x3 stiffness matrix, i.e. a
rotation of the frame (:func:`principal_frame`).

Pressure foot (:class:`PressureFoot`): a documented, configurable ASSUMED contact model. The
foot is pressed on the workpiece by a pneumatic piston: foot force ``F = p A``. It adds a normal
contact stiffness along the foot normal (Hertz sphere-on-flat ``k_n = (6 F E*^2 R)^(1/3)``, or a
user value), a friction-limited tangential stiffness ``k_t = mu F / delta_slip`` in the plane
normal to it, and contact damping ``c = 2 zeta_c sqrt(k_add m)`` per direction. Defaults (piston
diameter 50 mm, E* = 2 GPa pad, R = 0.1 m, mu = 0.3, delta_slip = 20 um, zeta_c = 0.05) are
assumptions for illustration, not measured values; replace them with the cell's data.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from robobore.errors import ConfigError, InputError
from robobore.io.ranges import check_value

AXES = ("x", "y", "z")
_AXIS_VEC = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def _xyz(d: Any, key: str) -> dict[str, Any]:
    """The ``{"x", "y", "z"}`` table under ``key`` (a list or number there is an error)."""
    v = d.get(key) if isinstance(d, dict) else None
    if not isinstance(v, dict):
        raise ConfigError("not a table over x, y, z", field=key,
                          value=v if not isinstance(v, dict | list) else type(v).__name__,
                          expected='{"x": .., "y": .., "z": ..}')
    return v


def _positive(name: str, value: Any, unit: str) -> float:
    if isinstance(value, bool):
        raise ConfigError("a boolean where a number is expected", field=name, value=value,
                          expected=f"a positive number in {unit}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError("not a number", field=name, value=value,
                          expected=f"a positive number in {unit}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise ConfigError("must be positive and finite", field=name, value=value,
                          expected=f"a positive number in {unit}")
    return check_value(v, name, kind=ConfigError)  # plausible range of the unit


def _nonneg(name: str, value: Any, unit: str) -> float:
    if isinstance(value, bool):
        raise ConfigError("a boolean where a number is expected", field=name, value=value,
                          expected=f"a number >= 0 in {unit}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError("not a number", field=name, value=value,
                          expected=f"a number >= 0 in {unit}") from None
    if not math.isfinite(v) or v < 0.0:
        raise ConfigError("must be >= 0 and finite", field=name, value=value,
                          expected=f"a number >= 0 in {unit}")
    return check_value(v, name, kind=ConfigError)  # plausible range of the unit


class EquivalentWarning(UserWarning):
    """The stiffness and the modes of an equivalent model do not agree (different robots or
    postures suspected)."""


#: a direction's static stiffness and its mode's modal stiffness further apart than this
#: factor draw a warning: a mode of the same robot carries part of the direction's
#: compliance, so its modal stiffness exceeds the static one by 1/share (1.1 at the bundled
#: test's coupled tool point), not by 2
STIFFNESS_MISMATCH_FACTOR = 2.0


def _posture_of(d: Any) -> list[float] | None:
    if not isinstance(d, dict):
        return None
    for key in ("joints_deg", "posture_deg", "directional_posture_deg"):
        v = d.get(key)
        if isinstance(v, list | tuple) and v and all(isinstance(x, int | float) for x in v):
            return [float(x) for x in v]
    return None


def _robot_of(d: Any) -> str | None:
    if not isinstance(d, dict) or not d.get("robot"):
        return None
    r = str(d["robot"]).strip()
    return r[:-5].rsplit("/", 1)[-1] if r.endswith(".toml") else r


def check_same_robot(stiffness: Any, modes: Any) -> None:
    """Refuse a stiffness and modes that name different robots or postures (ConfigError);
    files that do not name them pass."""
    rs, rm = _robot_of(stiffness), _robot_of(modes)
    if rs and rm and rs != rm:
        raise ConfigError("the stiffness and the modes are of different robots",
                          field="robot", value=f"stiffness: {rs}, modes: {rm}",
                          expected="the stiffness and the hammer test of one robot")
    qs, qm = _posture_of(stiffness), _posture_of(modes)
    if qs and qm and (len(qs) != len(qm) or max(abs(a - b) for a, b in
                                                 zip(qs, qm, strict=False)) > 0.01):
        raise ConfigError("the stiffness and the modes are of different postures",
                          field="joints_deg", value=f"stiffness: {qs}, modes: {qm}",
                          expected="the stiffness and the hammer test at one posture "
                                   "(within 0.01 deg)")


def _mode_stiffness(md: dict[str, Any], axis: str) -> float | None:
    """The modal stiffness (N/m) of a mode at the driving point of ``axis``, if given."""
    ks = md.get("modal_stiffness_N_per_m")
    if not isinstance(ks, dict):
        return None
    for name, v in ks.items():
        n = str(name).strip().lower()
        if (n == axis or (len(n) >= 2 and n[-1] == axis and n[-2] in "_-+ .")) and \
                isinstance(v, int | float) and v > 0 and math.isfinite(v):
            return float(v)
    return None


def stiffness_mismatch_notes(ks: dict[str, Any], assigned: dict[str, dict[str, Any]]
                             ) -> tuple[str, ...]:
    """Warnings (also issued as :class:`EquivalentWarning`) for the directions whose static
    stiffness and the modal stiffness of the mode assigned to them differ by more than
    :data:`STIFFNESS_MISMATCH_FACTOR`."""
    import warnings

    out = []
    for a in AXES:
        k, km = ks.get(a), _mode_stiffness(assigned[a], a)
        if k is None or km is None or not k > 0:
            continue
        r = km / float(k)
        if r > STIFFNESS_MISMATCH_FACTOR or r < 1.0 / STIFFNESS_MISMATCH_FACTOR:
            msg = (f"WARNING: {a}: static stiffness {float(k):.4g} N/m, the modal stiffness of "
                   f"its mode {km:.4g} N/m (x{r:.3g}, beyond a factor "
                   f"{STIFFNESS_MISMATCH_FACTOR:g}): the mode carries little of the "
                   "direction's compliance (a coupled tool point) or the stiffness and the "
                   "hammer test are of different robots or postures; the unit's mass k/w^2 "
                   "does not represent the mode")
            warnings.warn(msg, EquivalentWarning, stacklevel=3)
            out.append(msg)
    return tuple(out)


def _stiffness_contract(stiffness: Any) -> Any:
    """The robot-stiffness JSON contract of ``stiffness`` (module docstring); a dict other
    than the ``{"x", "y", "z"}`` table is returned as it is."""
    if isinstance(stiffness, dict):
        if set(stiffness) == set(AXES):  # directional_stiffness_xyz's table
            return {"directional_stiffness_N_per_m": stiffness}
        return stiffness
    from robobore.robot.identify import StiffnessIdentification
    from robobore.robot.stiffness import JointStiffness, StiffnessResult

    if isinstance(stiffness, StiffnessIdentification):
        return dict(stiffness.directional)
    if isinstance(stiffness, StiffnessResult):
        return {"directional_stiffness_N_per_m": dict(stiffness.directional_stiffness_N_per_m)}
    hint = (" (joint stiffnesses need a posture: robobore.robot.stiffness.stiffness_at)"
            if isinstance(stiffness, JointStiffness) else "")
    raise InputError(f"not a robot stiffness{hint}", field="stiffness",
                     value=type(stiffness).__name__,
                     expected="a StiffnessIdentification, a StiffnessResult, a dict with "
                              "directional_stiffness_N_per_m or {x, y, z} in N/m")


def _modes_contract(modes: Any) -> Any:
    """The modal JSON contract of ``modes`` (module docstring); a dict as it is."""
    if isinstance(modes, dict):
        return modes
    from robobore.modal.identify import ModalAnalysis, ModalResult

    if isinstance(modes, ModalAnalysis):
        modes = modes.result
    if isinstance(modes, ModalResult):
        return modes.to_dict()
    raise InputError("not identified modes", field="modes", value=type(modes).__name__,
                     expected='a ModalResult, a ModalAnalysis or a dict with "modes"')


@dataclass(frozen=True)
class PressureFoot:
    """Pressure-foot contact model (ASSUMED defaults, see module docstring).

    Attributes are SI: ``pressure_Pa`` piston pressure, ``piston_area_m2`` piston area,
    ``normal`` unit vector of the foot normal in the boring frame (default Z, the bore axis),
    ``normal_stiffness_N_per_m`` user value of the contact stiffness (``None``: Hertz from
    ``contact_modulus_Pa`` and ``contact_radius_m``), ``friction_coefficient``,
    ``slip_displacement_m`` (tangential displacement at which the contact slides),
    ``contact_damping_ratio`` (damping added per unit of added stiffness).
    """

    pressure_Pa: float = 0.3e6
    piston_area_m2: float = math.pi * 0.025**2
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    normal_stiffness_N_per_m: float | None = None
    contact_modulus_Pa: float = 2.0e9
    contact_radius_m: float = 0.1
    friction_coefficient: float = 0.3
    slip_displacement_m: float = 20e-6
    contact_damping_ratio: float = 0.05

    @property
    def force_N(self) -> float:
        """Foot force F = p A [N]."""
        return self.pressure_Pa * self.piston_area_m2

    def normal_stiffness(self) -> float:
        """Normal contact stiffness [N/m]: user value or Hertz sphere-on-flat dF/d(delta)."""
        if self.normal_stiffness_N_per_m is not None:
            return float(self.normal_stiffness_N_per_m)
        f = self.force_N
        if f <= 0:
            return 0.0
        return (6.0 * f * self.contact_modulus_Pa**2 * self.contact_radius_m) ** (1.0 / 3.0)

    def tangential_stiffness(self) -> float:
        """Friction-limited tangential stiffness mu F / delta_slip [N/m]."""
        return self.friction_coefficient * self.force_N / self.slip_displacement_m

    def stiffness_matrix(self) -> np.ndarray:
        """Added stiffness matrix (3, 3) [N/m] in the boring frame."""
        n = np.asarray(self.normal, float)
        n = n / np.linalg.norm(n)
        nn = np.outer(n, n)
        return self.normal_stiffness() * nn + self.tangential_stiffness() * (np.eye(3) - nn)

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["normal"] = list(self.normal)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> PressureFoot:
        d = dict(d)
        if "normal" in d:
            n = np.asarray(d["normal"], float)
            if n.shape != (3,) or np.linalg.norm(n) < 1e-12:
                raise ConfigError("foot normal must be a non-zero 3-vector", field="normal",
                                  value=d["normal"], expected="[nx, ny, nz]")
            d["normal"] = tuple(float(v) for v in n / np.linalg.norm(n))
        for key in ("pressure_Pa", "piston_area_m2", "friction_coefficient",
                    "contact_damping_ratio"):
            if key in d:
                _nonneg(key, d[key], "SI units")
        for key in ("contact_modulus_Pa", "contact_radius_m", "slip_displacement_m"):
            if key in d:
                _positive(key, d[key], "SI units")
        return cls(**d)


@dataclass(frozen=True)
class DirectionUnit:
    """One mass-spring-damper unit: k [N/m], natural frequency [Hz], m [kg], c [N s/m], zeta."""

    stiffness_N_per_m: float
    frequency_Hz: float
    mass_kg: float
    damping_N_s_per_m: float
    damping_ratio: float


def check_modes_in_band(ml: list[dict[str, Any]], band: Any, file: str | None = None) -> None:
    """Modes identified in a band (``band_Hz`` of ``robobore identify modes --json``) lie in
    it (within 10 %): a frequency far outside is a value edited or scaled by hand (kHz for
    Hz), or modes of another test; a ConfigError naming ``file``."""
    if not (isinstance(band, list | tuple) and len(band) == 2
            and all(isinstance(b, int | float) and not isinstance(b, bool) for b in band)):
        return
    lo, hi = float(min(band)), float(max(band))
    for i, md in enumerate(ml):
        f = float(md["frequency_Hz"])
        if not lo * 0.9 <= f <= hi * 1.1:
            hint = " (looks like kHz or a scaled value)" if f > hi * 1.1 else ""
            raise ConfigError(f"mode frequency outside the band it was identified in{hint}",
                              file=file, field=f"modes[{i}].frequency_Hz", value=f,
                              expected=f"{lo:g} .. {hi:g} Hz (the file's band_Hz)")


@dataclass(frozen=True)
class EquivalentModel:
    """Per-direction equivalent model of the robot at the tool point (boring frame).

    ``stiffness_N_per_m``, ``frequency_Hz``, ``damping_ratio`` are dicts over the axes
    ``x, y, z``. ``frame`` is the 3x3 rotation matrix whose columns are the directions of the
    three units in the boring frame (identity: the units act along X, Y, Z). ``foot`` is the
    pressure-foot model whose stiffness/damping has already been added (``None``: no foot).
    ``notes`` records how the model was built (mode assignment, damping source).
    """

    stiffness_N_per_m: dict[str, float]
    frequency_Hz: dict[str, float]
    damping_ratio: dict[str, float]
    frame: tuple[tuple[float, float, float], ...] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0),
                                                     (0.0, 0.0, 1.0))
    foot: PressureFoot | None = None
    notes: tuple[str, ...] = field(default_factory=tuple)
    #: what the model describes (robot, posture, tool point, SYNTHETIC; robobore.io.identity)
    identity: dict[str, Any] = field(default_factory=dict)
    #: 95 % ranges per axis propagated from the modes' intervals (empty when the modes carry
    #: none): ``{axis: {"frequency_Hz": [lo, hi], "damping_ratio": [..], "mass_kg": [..],
    #: "damping_N_s_per_m": [..]}}``, or the posterior ranges of ``calibrate dynamics``
    #: (``damping_ratio``, ``stiffness_N_per_m``); in :meth:`to_dict` under ``uncertainty``
    #: when not empty, and what ``lobes --band`` draws its band from
    uncertainty: dict[str, dict[str, list[float]]] = field(default_factory=dict)

    # ------------------------------------------------------------------ construction
    @classmethod
    def build(
        cls,
        stiffness_N_per_m: dict[str, float],
        frequency_Hz: dict[str, float],
        damping_ratio: dict[str, float] | None = None,
        damping_N_s_per_m: float | dict[str, float] | None = None,
        frame: np.ndarray | None = None,
        foot: PressureFoot | None = None,
        notes: tuple[str, ...] = (),
        uncertainty: dict[str, dict[str, list[float]]] | None = None,
    ) -> EquivalentModel:
        """Plain constructor from numbers.

        Give either ``damping_ratio`` per axis or ``damping_N_s_per_m`` (one value for all
        axes, like the paper's c = 23.7 N s/m, or per axis); the implied ratio is
        ``zeta = c / (2 sqrt(k m))``. A pressure foot adds its stiffness along the unit
        directions (diagonal of ``R^T K_foot R``) and contact damping, keeping each unit's mass.
        """
        k = {a: _positive(f"stiffness_N_per_m.{a}", stiffness_N_per_m.get(a), "N/m")
             for a in AXES}
        fn = {a: _positive(f"frequency_Hz.{a}", frequency_Hz.get(a), "Hz") for a in AXES}
        m = {a: k[a] / (2 * math.pi * fn[a]) ** 2 for a in AXES}
        notes = list(notes)
        if damping_N_s_per_m is not None:
            cd = (damping_N_s_per_m if isinstance(damping_N_s_per_m, dict)
                  else dict.fromkeys(AXES, damping_N_s_per_m))
            c = {a: _nonneg(f"damping_N_s_per_m.{a}", cd.get(a), "N s/m") for a in AXES}
            z = {a: c[a] / (2.0 * math.sqrt(k[a] * m[a])) for a in AXES}
            notes.append("damping from a given coefficient c; implied ratios "
                         + ", ".join(f"{a}: {z[a]:.3e}" for a in AXES))
        elif damping_ratio is not None:
            z = {a: _nonneg(f"damping_ratio.{a}", damping_ratio.get(a), "(ratio)") for a in AXES}
        else:
            raise ConfigError("give damping ratios or a damping coefficient",
                              field="damping", expected="damping_ratio or damping_N_s_per_m")
        R = np.eye(3) if frame is None else np.asarray(frame, float)
        if R.shape != (3, 3) or not np.allclose(R.T @ R, np.eye(3), atol=1e-6):
            raise ConfigError("frame must be a 3x3 rotation matrix", field="frame",
                              value=None if frame is None else np.asarray(frame).tolist(),
                              expected="orthonormal columns")
        if foot is not None:
            kf = R.T @ foot.stiffness_matrix() @ R
            for i, a in enumerate(AXES):
                dk = float(kf[i, i])
                c_old = 2 * z[a] * math.sqrt(k[a] * m[a])
                c_add = 2 * foot.contact_damping_ratio * math.sqrt(max(dk, 0.0) * m[a])
                k[a] = k[a] + dk
                fn[a] = math.sqrt(k[a] / m[a]) / (2 * math.pi)
                z[a] = (c_old + c_add) / (2 * math.sqrt(k[a] * m[a]))
            notes.append(f"pressure foot added: F = {foot.force_N:.1f} N, "
                         f"k_n = {foot.normal_stiffness():.3e} N/m, "
                         f"k_t = {foot.tangential_stiffness():.3e} N/m (assumed contact model)")
        return cls(stiffness_N_per_m=k, frequency_Hz=fn, damping_ratio=z,
                   frame=tuple(tuple(float(v) for v in row) for row in R), foot=foot,
                   notes=tuple(notes),
                   uncertainty=check_uncertainty(uncertainty) if uncertainty else {})

    @classmethod
    def from_stiffness_and_modes(
        cls,
        stiffness: Any,
        modes: Any,
        assignment: dict[str, int] | None = None,
        damping_N_s_per_m: float | None = None,
        foot: PressureFoot | None = None,
        names: tuple[str, str] = ("the stiffness", "the modes"),
    ) -> EquivalentModel:
        """Build from the robot-stiffness and modal stages' results or their JSON contracts
        (see module docstring; an object and its dict form give the same model).

        Their identities (:mod:`robobore.io.identity`) must agree: stiffness and modes of
        different robots, postures, tool points or frames are a ``ConfigError`` naming both
        (``names``: how to call them, e.g. their files); the model records the merged
        identity (SYNTHETIC when either input is), and a note where an input has none.

        If ``stiffness`` carries a full ``"stiffness_matrix_N_per_m"`` (3x3, boring frame),
        the units act along its principal directions (:func:`principal_frame`, equal-mass
        assumption of the paper) with the principal stiffnesses, and mode directions are
        compared with those principal axes.
        """
        from robobore.io.identity import check_pair, merged, read_identity, unchecked_note

        id_s = getattr(stiffness, "identity", None) or None
        stiffness = _stiffness_contract(stiffness)
        modes = _modes_contract(modes)
        if id_s is None:
            id_s = read_identity(stiffness, names[0])
        id_m = read_identity(modes, names[1])
        check_pair(id_s, names[0], id_m, names[1])
        id_notes = tuple(unchecked_note(nm) for nm, idn in zip(names, (id_s, id_m),
                                                               strict=True) if idn is None)
        R = None
        if isinstance(stiffness, dict) and "stiffness_matrix_N_per_m" in stiffness:
            kp, R = principal_frame(np.asarray(stiffness["stiffness_matrix_N_per_m"], float))
            ks = dict(zip(AXES, (float(v) for v in kp), strict=True))
        else:
            try:
                ks = stiffness["directional_stiffness_N_per_m"]
            except (KeyError, TypeError):
                raise ConfigError("missing key", field="directional_stiffness_N_per_m",
                                  expected='{"x": .., "y": .., "z": ..} in N/m') from None
            ks = _xyz(stiffness, "directional_stiffness_N_per_m")
        try:
            ml = modes["modes"]
        except (KeyError, TypeError):
            raise ConfigError("missing key", field="modes",
                              expected='a list of {"frequency_Hz", "damping_ratio"}') from None
        if not isinstance(ml, list) or not all(isinstance(md, dict) for md in ml):
            raise ConfigError("not a list of mode tables", field="modes", value=ml,
                              expected='a list of {"frequency_Hz", "damping_ratio"}')
        if len(ml) < 1:
            raise ConfigError("no modes given", field="modes", expected="at least one mode")
        for i, md in enumerate(ml):
            if not isinstance(md, dict):
                raise ConfigError("mode is not a table", field=f"modes[{i}]",
                                  value=type(md).__name__,
                                  expected='{"frequency_Hz": .., "damping_ratio": ..}')
            _positive(f"modes[{i}].frequency_Hz", md.get("frequency_Hz"), "Hz")
            _nonneg(f"modes[{i}].damping_ratio", md.get("damping_ratio", 0.0), "(ratio)")
        check_modes_in_band(ml, modes.get("band_Hz"))
        if len(ml) < len(AXES) and assignment is None:
            raise ConfigError(
                f"{names[1]} has {len(ml)} mode(s); {names[0]} gives the stiffness along "
                f"{len(AXES)} directions ({', '.join(AXES)}), each of which needs its mode",
                field="modes", value=len(ml),
                expected=f"{len(AXES)} or more modes, or an assignment of modes to the axes")
        if R is not None:  # compare mode directions with the principal axes
            ml = [dict(md) for md in ml]
            for md in ml:
                d = _mode_direction(md, signed=True)
                if d is not None:
                    md["direction"] = list(np.abs(R.T @ d))
                    md.pop("shape", None)
        check_same_robot(stiffness, modes)
        chosen, how = assign_modes(ml, assignment)
        fn = {a: float(ml[chosen[a]]["frequency_Hz"]) for a in AXES}
        zr = {a: float(ml[chosen[a]].get("damping_ratio", 0.0)) for a in AXES}
        notes = (how + ": " + ", ".join(f"{a} <- mode {chosen[a]} ({fn[a]:.4g} Hz)"
                                        for a in AXES),)
        if R is not None:
            notes = notes + ("units along the principal directions of the stiffness matrix",)
        if R is None:
            notes = notes + stiffness_mismatch_notes(ks, {a: ml[chosen[a]] for a in AXES})
        kk = {a: ks.get(a) for a in AXES}
        em = cls.build(kk, fn, damping_ratio=zr, damping_N_s_per_m=damping_N_s_per_m, frame=R,
                       foot=foot, notes=notes + id_notes)
        import dataclasses

        em = dataclasses.replace(em, identity=merged(id_s, id_m, kind="equivalent model"))
        unc = {a: ml[chosen[a]].get("uncertainty") for a in AXES}
        if all(isinstance(u, dict) and "frequency_ci95_Hz" in u for u in unc.values()):
            from dataclasses import replace as _replace

            ends = []
            for side in (0, 1):  # the model at the intervals' low and high ends
                fs_ = {a: max(float(unc[a]["frequency_ci95_Hz"][side]), 1e-9) for a in AXES}
                zs_ = {a: max(float(unc[a]["damping_ci95"][side]), 0.0) for a in AXES}
                ends.append(cls.build(kk, fs_, damping_ratio=zs_,
                                      damping_N_s_per_m=damping_N_s_per_m, frame=R, foot=foot))
            rng = {}
            for a in AXES:
                vals = {"frequency_Hz": [e.frequency_Hz[a] for e in ends],
                        "damping_ratio": [e.damping_ratio[a] for e in ends],
                        "mass_kg": [e.mass_kg[a] for e in ends],
                        "damping_N_s_per_m": [e.damping_N_s_per_m[a] for e in ends]}
                rng[a] = {k: [float(min(v)), float(max(v))] for k, v in vals.items()}
            em = _replace(em, uncertainty=rng, notes=em.notes + (
                "95 % ranges of f, zeta, m and c from the modes' intervals (stiffness taken "
                "as exact)",))
        return em

    # ------------------------------------------------------------------ derived
    def unit(self, axis: str) -> DirectionUnit:
        k = self.stiffness_N_per_m[axis]
        fn = self.frequency_Hz[axis]
        m = k / (2 * math.pi * fn) ** 2
        z = self.damping_ratio[axis]
        return DirectionUnit(k, fn, m, 2 * z * math.sqrt(k * m), z)

    @property
    def mass_kg(self) -> dict[str, float]:
        return {a: self.unit(a).mass_kg for a in AXES}

    @property
    def damping_N_s_per_m(self) -> dict[str, float]:
        return {a: self.unit(a).damping_N_s_per_m for a in AXES}

    def directions(self) -> np.ndarray:
        """Unit directions of the three units in the boring frame, shape (3, 3) rows = x, y, z."""
        return np.asarray(self.frame, float).T

    def tool_point_modes(self) -> list[dict[str, Any]]:
        """The model as general tool-point modes (the ``[structure] modes`` contract)."""
        D = self.directions()
        return [{"frequency_Hz": self.frequency_Hz[a], "damping_ratio": self.damping_ratio[a],
                 "stiffness_N_per_m": self.stiffness_N_per_m[a],
                 "direction": [float(v) for v in D[i]]} for i, a in enumerate(AXES)]

    def table(self) -> list[dict[str, Any]]:
        """Per-direction rows: axis, k, f_n, m, c, zeta."""
        rows = []
        for a in AXES:
            u = self.unit(a)
            rows.append({"axis": a, "stiffness_N_per_m": u.stiffness_N_per_m,
                         "frequency_Hz": u.frequency_Hz, "mass_kg": u.mass_kg,
                         "damping_N_s_per_m": u.damping_N_s_per_m,
                         "damping_ratio": u.damping_ratio})
        return rows

    def to_dict(self) -> dict[str, Any]:
        return {"stiffness_N_per_m": dict(self.stiffness_N_per_m),
                "frequency_Hz": dict(self.frequency_Hz),
                "damping_ratio": dict(self.damping_ratio),
                "mass_kg": self.mass_kg, "damping_N_s_per_m": self.damping_N_s_per_m,
                "frame": [list(r) for r in self.frame],
                "foot": None if self.foot is None else self.foot.to_dict(),
                "notes": list(self.notes),
                "identity": dict(self.identity) if self.identity else None,
                **({"uncertainty": {a: {k: list(v) for k, v in u.items()}
                                    for a, u in self.uncertainty.items()}}
                   if self.uncertainty else {})}

    @classmethod
    def from_dict(cls, d: dict[str, Any], source: str = "<equivalent model>"
                  ) -> EquivalentModel:
        """Inverse of :meth:`to_dict` (the foot is already included in k, f, zeta); zero
        damping and a ``mass_kg`` that does not fit ``k / (2 pi f)^2`` are refused."""
        for key in ("stiffness_N_per_m", "frequency_Hz", "damping_ratio"):
            if key not in d:
                raise ConfigError("missing key", field=key, expected="a dict over x, y, z")
        k = {a: _positive(f"stiffness_N_per_m.{a}", _xyz(d, "stiffness_N_per_m").get(a), "N/m")
             for a in AXES}
        f = {a: _positive(f"frequency_Hz.{a}", _xyz(d, "frequency_Hz").get(a), "Hz")
             for a in AXES}
        z = {a: _nonneg(f"damping_ratio.{a}", _xyz(d, "damping_ratio").get(a), "(ratio)")
             for a in AXES}
        for a in AXES:
            if z[a] == 0.0:
                raise ConfigError("zero damping", field=f"damping_ratio.{a}", value=0.0,
                                  expected="a damping ratio > 0 (a real structure dissipates; "
                                           "robots: 0.01 .. 0.2)")
        given_m = d.get("mass_kg")
        if isinstance(given_m, dict):
            for a in AXES:
                mk = given_m.get(a)
                if mk is None:
                    continue
                m_a = _positive(f"mass_kg.{a}", mk, "kg")
                m_kf = k[a] / (2 * math.pi * f[a]) ** 2
                if abs(m_a - m_kf) > 1e-3 * m_kf:
                    raise ConfigError("mass does not fit k / (2 pi f)^2", field=f"mass_kg.{a}",
                                      value=mk, expected=f"{m_kf:.6g} kg from stiffness_N_per_m."
                                      f"{a} and frequency_Hz.{a} (frequency in rad/s?)")
        from robobore.io.identity import read_identity

        ident = read_identity(d, source) or {}
        frame = d.get("frame", np.eye(3).tolist())
        foot = None if d.get("foot") is None else PressureFoot.from_dict(d["foot"])
        unc = d.get("uncertainty")
        return cls(k, f, z, tuple(tuple(float(v) for v in r) for r in frame), foot,
                   tuple(d.get("notes", ())), ident,
                   check_uncertainty(unc) if unc else {})


#: Keys an axis of :attr:`EquivalentModel.uncertainty` may carry (each a ``[lo, hi]`` range).
UNCERTAINTY_KEYS = ("frequency_Hz", "damping_ratio", "stiffness_N_per_m", "mass_kg",
                    "damping_N_s_per_m")


def check_uncertainty(unc: Any) -> dict[str, dict[str, list[float]]]:
    """The ``uncertainty`` block checked: ``{axis: {key: [lo, hi]}}`` over the axes x, y, z
    and :data:`UNCERTAINTY_KEYS`, ``0 <= lo <= hi`` finite; a ``ConfigError`` naming the key
    otherwise."""
    exp = "{axis: {key: [lo, hi]}} with axes x, y, z and keys " + ", ".join(UNCERTAINTY_KEYS)
    if not isinstance(unc, dict):
        raise ConfigError("not a table", field="uncertainty", value=type(unc).__name__,
                          expected=exp)
    out: dict[str, dict[str, list[float]]] = {}
    for a, u in unc.items():
        if a not in AXES or not isinstance(u, dict):
            raise ConfigError("not an axis table", field=f"uncertainty.{a}", expected=exp)
        out[a] = {}
        for key, rng in u.items():
            where = f"uncertainty.{a}.{key}"
            if key not in UNCERTAINTY_KEYS:
                raise ConfigError("unknown key", field=where, expected=exp)
            try:
                lo, hi = (float(v) for v in rng)
            except (TypeError, ValueError):
                raise ConfigError("not a [lo, hi] range", field=where, value=rng,
                                  expected="two numbers lo <= hi") from None
            if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 <= lo <= hi):
                raise ConfigError("not a range", field=where, value=rng,
                                  expected="finite 0 <= lo <= hi")
            out[a][key] = [lo, hi]
    return out


def _mode_direction(md: dict[str, Any], signed: bool = False) -> np.ndarray | None:
    """Mode direction (3,): absolute components, or (``signed``) the real shape after
    removing the phase of its largest component."""
    d = md.get("direction", md.get("shape"))
    if d is None:
        return None
    if isinstance(d, str):
        if d.lower() not in _AXIS_VEC:
            raise ConfigError("unknown axis", field="direction", value=d, expected="x, y or z")
        return np.asarray(_AXIS_VEC[d.lower()])
    c = np.asarray(d, dtype=complex).ravel()
    v = np.abs(c)
    if c.shape != (3,) or not np.isfinite(v).all() or v.max() <= 0:
        return None
    if signed:
        ph = c[int(np.argmax(v))] / v.max()
        return np.real(c / ph)
    return v


def assign_modes(modes: list[dict[str, Any]],
                 assignment: dict[str, int] | None = None) -> tuple[dict[str, int], str]:
    """Choose the mode index for each axis (rules in the module docstring).

    Returns ``({"x": i, "y": j, "z": k}, how)``.
    """
    dirs = [_mode_direction(md) for md in modes]
    if all(d is not None for d in dirs) and len(modes) >= 3:
        order = sorted(range(len(modes)), key=lambda i: modes[i]["frequency_Hz"])
        chosen: dict[str, int] = {}
        used: set[int] = set()
        for ax_i, a in enumerate(AXES):
            for i in order:
                if i in used:
                    continue
                if int(np.argmax(dirs[i])) == ax_i:
                    chosen[a] = i
                    used.add(i)
                    break
        if len(chosen) == 3:
            return chosen, "assigned by mode direction"
    if assignment is not None:
        out = {}
        for a in AXES:
            if a not in assignment:
                raise ConfigError("assignment misses an axis", field=f"assignment.{a}",
                                  expected="a 0-based mode index")
            i = int(assignment[a])
            if not 0 <= i < len(modes):
                raise ConfigError("mode index out of range", field=f"assignment.{a}", value=i,
                                  expected=f"0 .. {len(modes) - 1}")
            out[a] = i
        return out, "assigned by user mapping"
    if len(modes) < 3:
        raise ConfigError("need 3 modes (or an assignment) for X, Y, Z", field="modes",
                          value=len(modes), expected="3 or more modes")
    return {"x": 0, "y": 1, "z": 2}, "default assignment (mode i -> axis i)"


def principal_frame(stiffness_matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal (uncoupled) directions of a symmetric 3x3 stiffness matrix [N/m].

    With equal masses in all directions the uncoupling transformation is a rotation of the
    frame (paper, after eq. 3). Returns ``(k_principal (3,), R (3, 3))`` with
    ``K = R diag(k) R^T``, ``R`` a proper rotation (det +1) whose columns are the principal
    directions in the input frame, sorted by ascending stiffness.
    """
    K = np.asarray(stiffness_matrix, float)
    if K.shape != (3, 3) or not np.all(np.isfinite(K)):
        raise ConfigError("stiffness matrix must be a finite 3x3 array", field="stiffness_matrix",
                          expected="3x3 in N/m")
    if not np.allclose(K, K.T, rtol=1e-6, atol=1e-9 * np.abs(K).max()):
        raise ConfigError("stiffness matrix must be symmetric", field="stiffness_matrix")
    w, V = np.linalg.eigh(0.5 * (K + K.T))
    if w.min() <= 0:
        raise ConfigError("stiffness matrix must be positive definite", field="stiffness_matrix",
                          value=float(w.min()), expected="all eigenvalues > 0 N/m")
    if np.linalg.det(V) < 0:
        V[:, 2] *= -1
    return w, V


__all__ = ["EquivalentModel", "PressureFoot", "DirectionUnit", "assign_modes",
           "principal_frame", "AXES", "EquivalentWarning", "check_same_robot",
           "stiffness_mismatch_notes", "STIFFNESS_MISMATCH_FACTOR", "check_uncertainty",
           "UNCERTAINTY_KEYS", "check_modes_in_band"]
