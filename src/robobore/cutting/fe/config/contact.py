"""The ``[contact]`` section of the FE configs (the 2D orthogonal config and the 3D boring
config, whose :class:`robobore.cutting.fe.config.boring3d.ContactSection` derives from it):
the friction (a bundled law, a user table or a constant), the normal penalty and its
damping, the thermal contact with the tool.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import Field, PrivateAttr, field_validator, model_validator

from robobore.cutting.fe.engine.layout import MU_TABLE_MAX
from robobore.io.sections import StrictModel as Strict
from robobore.material.friction import CALIBRATED_LAW, friction_law, friction_laws

__all__ = ["ContactSection", "FRICTION_TABLE_VC_M_MIN", "FRICTION_TABLE_MU"]

#: Coulomb friction coefficient vs cutting speed [m/min] for Ti6Al4V on uncoated WC
#: (Rech et al. 2013, as used by Ducobu, Pantale et al. 2022; see
#: ../shared/data/ti64_orthogonal_cutting_forces.json). Used when ``contact.friction`` is
#: "table": linear interpolation, constant beyond the ends.
FRICTION_TABLE_VC_M_MIN = np.array([5.0, 7.5, 10.0, 20.0, 30.0, 40.0])
FRICTION_TABLE_MU = np.array([0.24, 0.22, 0.21, 0.19, 0.18, 0.17])


class ContactSection(Strict):
    #: the friction: a bundled friction law by name (robobore/material/friction_laws.toml:
    #: "rech2013_calibrated", CALIBRATED, or "rech2013", A-PRIORI; the law gives the table,
    #: the velocity it is read at and the shear cap, the last two overridable by their
    #: keys), "table" (the friction_table_* keys, or without them the Rech et al. 2013
    #: table at the cutting speed), or a constant Coulomb coefficient. None: the law of
    #: ``parameters`` (the FE config's top-level key)
    friction: float | str | None = None
    #: cap on the contact shear stress [MPa]. None: the friction law's (rech2013: 576 MPa,
    #: the Ducobu/Pantale model input; rech2013_calibrated: 5000, no cap), else 576
    shear_limit_MPa: float | None = Field(default=None, gt=0.0)
    #: penalty factor: normal stiffness = factor * nodal mass / dt^2 (0 < factor <= 0.5)
    penalty_factor: float = Field(default=0.1, gt=0.0, le=0.5)
    #: thermal contact with the tool, used with ``solver.heat_conduction`` (adiabatic runs
    #: exchange no heat): interface conductance [W/(m^2 K)] between the workpiece surface
    #: in contact and the tool, a heat sink at ``tool_temperature_K`` (0: adiabatic tool)
    thermal_conductance_W_per_m2K: float = Field(default=1.0e5, ge=0.0, le=1.0e9)
    #: fraction of the frictional dissipation that heats the workpiece (chip underside and
    #: machined surface); the rest goes into the tool
    friction_heat_fraction: float = Field(default=0.5, ge=0.0, le=1.0)
    #: viscous damping of the contact's normal penalty spring, as a fraction of its critical
    #: damping (LS-DYNA's VDC); it damps the contact chatter, through which an explicit
    #: penalty contact otherwise creates energy (k dg^2 / 2 a step), and its dissipation is
    #: booked with the friction's. None: 0 for mesh.frame = "workpiece", 1 (critical) for "tool"
    #: (whose edge-arc nodes are in contact for the whole run)
    normal_damping: float | None = Field(default=None, ge=0.0, le=1.0)
    #: temperature of the tool [K]; None: the material's room temperature
    tool_temperature_K: float | None = Field(default=None, gt=0.0, le=3000.0)

    #: what the friction table's velocity is (friction = "table"): "cutting_speed" -- one
    #: coefficient for the whole run, the table at cut.cutting_speed_m_per_min -- or
    #: "sliding" -- every node in contact, every step, uses the table at its own sliding
    #: speed relative to the tool (the chip's speed ~vc / r up the rake, ~0 in the stagnation
    #: zone at the edge): how a tribometer's mu(sliding velocity) is read, as Abaqus'
    #: slip-rate-dependent friction; constant beyond the table's ends (2D and 3D engines).
    #: None: the friction law's, else "cutting_speed"
    friction_velocity: Literal["cutting_speed", "sliding"] | None = None
    #: the friction table's velocities [m/min], increasing, 2..8 points; None: the Rech et
    #: al. 2013 table (FRICTION_TABLE_VC_M_MIN). Give friction_table_mu with it
    friction_table_velocity_m_per_min: list[float] | None = None
    #: the friction table's Coulomb coefficients (0..2), one per velocity
    friction_table_mu: list[float] | None = None
    #: friction_velocity = "sliding": time constant of the low-pass filter on each node's
    #: sliding speed, as the tool's travel in it [um] (a contact node's velocity chatters
    #: from step to step; the filtered speed is the material's mean sliding speed there)
    sliding_filter_um: float = Field(default=1.0, gt=0.0, le=1000.0)

    #: the bundled friction law the table came from (None: "table" or a constant)
    _law: str | None = PrivateAttr(default=None)

    @field_validator("friction")
    @classmethod
    def _mu(cls, v: Any) -> Any:
        if isinstance(v, float) and not (0.0 <= v <= 2.0):
            raise ValueError("friction coefficient must be within 0..2")
        if isinstance(v, str) and v != "table" and v not in friction_laws():
            raise ValueError(f"unknown friction {v!r}: expected a Coulomb coefficient "
                             f'0..2, "table" or a friction law, one of {sorted(friction_laws())}')
        return v

    @model_validator(mode="after")
    def _table(self) -> ContactSection:
        fs = set(self.model_fields_set)
        v, mu = self.friction_table_velocity_m_per_min, self.friction_table_mu
        if (v is None) != (mu is None):
            raise ValueError("friction_table_velocity_m_per_min and friction_table_mu go "
                             "together: give both or neither")
        if self.friction is None:
            self.friction = CALIBRATED_LAW
        if isinstance(self.friction, str) and self.friction != "table":
            if v is not None:
                raise ValueError(f"friction = {self.friction!r} is a friction law with its "
                                 'own table: give friction = "table" with a user table')
            law = friction_law(self.friction)
            self._law = law.name
            self.friction = "table"
            v = self.friction_table_velocity_m_per_min = list(law.velocity_m_per_min)
            mu = self.friction_table_mu = list(law.mu)
            if self.friction_velocity is None:
                self.friction_velocity = law.read_at
            if self.shear_limit_MPa is None:
                self.shear_limit_MPa = law.shear_limit_MPa
        if self.shear_limit_MPa is None:
            self.shear_limit_MPa = 576.0
        table_keys = v is not None or "friction_velocity" in fs
        if self.friction_velocity is None:
            self.friction_velocity = "cutting_speed"
        if self.friction != "table" and table_keys:
            raise ValueError(f"friction = {self.friction!r} is a constant coefficient: the "
                             "friction table keys (friction_table_*, friction_velocity) need "
                             'friction = "table"')
        if "sliding_filter_um" in self.model_fields_set and self.friction_velocity != "sliding":
            raise ValueError("sliding_filter_um filters the sliding speed of "
                             'friction_velocity = "sliding"; it is not used otherwise')
        if v is not None and mu is not None:
            if not 2 <= len(v) <= MU_TABLE_MAX or len(mu) != len(v):
                raise ValueError(f"friction table: {len(v)} velocities and {len(mu)} "
                                 f"coefficients; expected the same number, 2..{MU_TABLE_MAX}")
            if v[0] < 0.0 or any(b <= a for a, b in zip(v, v[1:], strict=False)):
                raise ValueError(f"friction_table_velocity_m_per_min = {v}: expected "
                                 "increasing velocities >= 0 m/min")
            if any(not 0.0 <= m <= 2.0 for m in mu):
                raise ValueError(f"friction_table_mu = {mu}: expected coefficients in 0..2")
        return self

    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """The friction table: velocities [m/min] and Coulomb coefficients."""
        if self.friction_table_velocity_m_per_min is None:
            return FRICTION_TABLE_VC_M_MIN, FRICTION_TABLE_MU
        return (np.asarray(self.friction_table_velocity_m_per_min, float),
                np.asarray(self.friction_table_mu, float))

    def damping_for(self, tool_frame: bool) -> float:
        """``normal_damping``, or its default for the frame: 1 (critical) in the tool frame,
        0 in the workpiece frame."""
        if self.normal_damping is not None:
            return float(self.normal_damping)
        return 1.0 if tool_frame else 0.0

    def coefficient_at(self, vc_m_per_min: float) -> float:
        """Coulomb coefficient at a cutting speed [m/min]: the constant given, or the table
        there (with ``friction_velocity = "sliding"`` the nominal value: each contact node
        then reads the table at its own sliding speed)."""
        if self.friction == "table":
            v, mu = self.table()
            return float(np.interp(vc_m_per_min, v, mu))
        return float(self.friction)

    def law_description(self) -> str:
        """The friction law in words (for summaries)."""
        if self.friction != "table":
            return f"Coulomb {float(self.friction):g}"
        law = self._law
        src = (f"law {law} ({friction_law(law).status})" if law is not None else
               "Rech et al. 2013" if self.friction_table_velocity_m_per_min is None else "user")
        arg = "each node's sliding speed" if self.friction_velocity == "sliding" else \
            "the cutting speed"
        return f"Coulomb, {src} table at {arg}"
