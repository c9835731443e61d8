"""The ``[solver]`` keys the 2D orthogonal and the 3D boring configs share, with one meaning
and one default in both (:class:`SolverSettings`); each config's ``SolverSection`` extends it
with the keys of its own engine (:mod:`.orthogonal`, :mod:`.boring3d`). ``Strict`` is
:class:`robobore.io.sections.StrictModel`, the base of every config section: unknown keys are
an error.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from robobore.io.sections import StrictModel as Strict

__all__ = ["SolverSettings"]


class SolverSettings(Strict):
    """Time integration, element numerics, erosion limits, heat and the run's checks."""

    #: fraction of the stable time step (element length / dilatational wave speed)
    cfl: float = Field(default=0.8, gt=0.0, le=1.0)
    #: Flanagan-Belytschko hourglass control coefficients (viscous, stiffness); a hexahedron
    #: in plane strain resists an in-plane hourglass mode per unit volume exactly as the
    #: quad does with the same values (docs/fe3d.md, "Element")
    hourglass_viscous: float = Field(default=0.05, ge=0.0, le=0.5)
    hourglass_stiffness: float = Field(default=0.05, ge=0.0, le=0.5)
    #: bulk viscosity (linear, quadratic), active in compression
    bulk_viscosity_linear: float = Field(default=0.06, ge=0.0, le=1.0)
    bulk_viscosity_quadratic: float = Field(default=1.2, ge=0.0, le=4.0)
    #: where elements erode when their Johnson-Cook damage reaches 1: "layer" (the
    #: separation layer along the path of the cutting edge) or "none"
    erosion: Literal["layer", "none"] = "layer"
    #: erode an element whose area (2D) or volume (3D) ratio to its initial one, or whose
    #: corner Jacobian, falls below this (numerical safety against inverted elements;
    #: counted and reported separately); 0 disables
    distortion_limit: float = Field(default=0.05, ge=0.0, lt=1.0)
    #: erode an element whose stable time step falls below this fraction of the initial
    #: smallest one (time-step erosion, as LS-DYNA's ERODE option); 0 disables
    erode_time_step_fraction: float = Field(default=0.3, ge=0.0, lt=1.0)
    #: heat conduction between workpiece elements (finite volumes on the deformed mesh,
    #: explicit, every ``conduction_interval`` steps), with the thermal contact to the tool
    #: (``contact.thermal_conductance_W_per_m2K``, ``friction_heat_fraction``); the other
    #: free surfaces are adiabatic. False: adiabatic heating only
    heat_conduction: bool = True
    conduction_interval: int = Field(default=10, ge=1, le=10000)
    #: fraction of the cut (from its end) averaged for the steady-state values
    steady_window_fraction: float = Field(default=0.5, gt=0.0, le=1.0)
    #: stop with NumericalError when |energy error| exceeds this after 10 % of the cut
    energy_error_limit: float = Field(default=0.5, gt=0.0)
