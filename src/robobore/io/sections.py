"""Config sections shared by several commands: one definition each.

:class:`StrictModel` is the base of every config section (unknown keys are refused, so that a
typo is an error rather than a silently ignored key). :class:`InsertSection` is the
``[insert]`` table -- the geometry of a boring insert -- that ``robobore lobes``,
``simulate boring``, ``plan posture`` and ``robobore.api`` read; the bounds below are the only
ones, and :class:`robobore.cutting.geometry.BoringInsert` checks the same constants.

The bounds and why (a bound is physical: it refuses a value no real insert has, or a unit
slip, and admits every standard tool):

* nose radius ``0 < r <= 10 mm``: ISO 1832 nose radii run 0.1 .. 3.2 mm (codes 01 .. 32);
  a round insert is a nose radius with no straight edge engaged, and round boring inserts go
  up to 20 mm across (r = 10 mm). Above it the value is a diameter or in um.
* approach angle ``5 .. 107.5 deg`` (:func:`check_approach_angle`): boring bars take 45 ..
  107.5 deg (107.5 deg: the most undercut standard bar, a 35 deg V insert); below 5 deg the
  value looks like radians.
* end-edge (minor edge) angle ``0 < kappa' < 90 deg``: ``kappa' = 180 - kappa_r - epsilon``
  for an insert of included angle epsilon; real pairs reach about 82.5 deg (a 35 deg V insert
  in a 62.5 deg holder). At 90 deg the minor edge stands square to the feed and the nose no
  longer leads.
* rake ``-30 .. 30 deg``, clearance ``0 .. 30 deg``: the span of ISO 1832 inserts (clearance
  codes N .. P reach 30 deg) and negative-rake holders (-6 .. -15 deg) with margin; a value
  beyond is in radians*100 or a sign-convention slip.
* inclination ``-15 .. 15 deg``: holders set the edge inclination within about -8 .. +8 deg
  (ISO 5608 / 6261 boring bars); 15 deg leaves room for special tools, and the 3D FE
  insert is meshed within it.
* edge radius ``0 .. 200 um`` (:data:`EDGE_RADIUS_MAX_UM`; 0 = the sharp, ideal edge, and
  values in ``(0, 0.5) um`` are refused as a slip from mm): ground and honed edges are
  2 .. 100 um, heavy chamfer-hones up to about 150 um.
"""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field, field_validator

from robobore.errors import ConfigError

__all__ = ["StrictModel", "InsertSection", "check_approach_angle", "APPROACH_ANGLE_MIN_DEG",
           "APPROACH_ANGLE_MAX_DEG", "NOSE_RADIUS_MAX_MM", "END_EDGE_ANGLE_MAX_DEG",
           "RAKE_MAX_DEG", "CLEARANCE_MAX_DEG", "INCLINATION_MAX_DEG", "EDGE_RADIUS_MAX_UM"]


class StrictModel(BaseModel):
    """A config section that refuses unknown keys (the base of every section)."""

    model_config = ConfigDict(extra="forbid")


#: The approach angles (kappa_r, deg) the geometry and force model accept: from
#: :data:`APPROACH_ANGLE_MIN_DEG` (below it the value looks like radians) to
#: :data:`APPROACH_ANGLE_MAX_DEG` (the most undercut standard boring bars, e.g. 107.5 deg
#: with a 35 deg V insert).
APPROACH_ANGLE_MIN_DEG = 5.0
APPROACH_ANGLE_MAX_DEG = 107.5
#: largest nose radius [mm]: a round boring insert 20 mm across
NOSE_RADIUS_MAX_MM = 10.0
#: end-edge (minor cutting edge) angle, open bound [deg]
END_EDGE_ANGLE_MAX_DEG = 90.0
#: normal rake magnitude [deg]
RAKE_MAX_DEG = 30.0
#: clearance (relief) angle [deg]
CLEARANCE_MAX_DEG = 30.0
#: edge inclination magnitude [deg]
INCLINATION_MAX_DEG = 15.0
#: cutting-edge (hone) radius [um]
EDGE_RADIUS_MAX_UM = 200.0


def check_approach_angle(value: float, field: str = "insert.approach_angle_deg",
                         file: str | None = None) -> float:
    """``value`` (deg) if it is a plausible approach angle, else a ConfigError naming it."""
    v = float(value)
    if not (math.isfinite(v) and APPROACH_ANGLE_MIN_DEG <= v <= APPROACH_ANGLE_MAX_DEG):
        hint = " (looks like radians)" if math.isfinite(v) and 0 < v < APPROACH_ANGLE_MIN_DEG \
            else ""
        raise ConfigError(f"approach angle out of range{hint}", file=file, field=field,
                          value=value, expected=f"{APPROACH_ANGLE_MIN_DEG:g} .. "
                          f"{APPROACH_ANGLE_MAX_DEG:g} deg (boring bars 45 .. 107.5 deg)")
    return v


class InsertSection(StrictModel):
    """The ``[insert]`` table: a boring insert's geometry in human units (defaults: a
    CCMT 060204-type insert in a 90-deg boring bar). Bounds: the module docstring."""

    nose_radius_mm: float = Field(0.4, gt=0, le=NOSE_RADIUS_MAX_MM)
    approach_angle_deg: float = 90.0  # range: check_approach_angle
    end_edge_angle_deg: float = Field(5.0, gt=0, lt=END_EDGE_ANGLE_MAX_DEG)
    rake_deg: float = Field(7.0, ge=-RAKE_MAX_DEG, le=RAKE_MAX_DEG)
    inclination_deg: float = Field(0.0, ge=-INCLINATION_MAX_DEG, le=INCLINATION_MAX_DEG)
    clearance_deg: float = Field(7.0, ge=0, le=CLEARANCE_MAX_DEG)
    edge_radius_um: float = Field(20.0, ge=0, le=EDGE_RADIUS_MAX_UM)

    # unit slips downwards, which the upper bounds do not catch: an angle in radians, an
    # edge radius in mm (a ground edge is 2 .. 100 um; 0 = sharp, the ideal edge)
    @field_validator("approach_angle_deg")
    @classmethod
    def _kappa(cls, v: float) -> float:
        try:
            return check_approach_angle(v)
        except ConfigError as exc:
            raise ValueError(f"{exc.message} (got {v:g} deg); expected {exc.expected}"
                             ) from None

    @field_validator("edge_radius_um")
    @classmethod
    def _edge(cls, v: float) -> float:
        if 0.0 < v < 0.5:
            raise ValueError(f"edge radius {v:g} um is below 0.5 um (looks like mm; expected "
                             "um: ground edges 2 .. 100 um, or 0 for a sharp edge)")
        return v
