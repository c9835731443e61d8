"""Bundled tool-workpiece friction laws (``robobore/material/friction_laws.toml``).

A law is a Coulomb coefficient vs velocity table, the velocity it is read at (the cutting
speed, or each contact node's sliding speed) and a cap on the contact shear stress; the FE
configs name one with ``contact.friction = "<name>"``. Each law is labelled A-PRIORI (from a
source) or CALIBRATED (chosen against measured forces, which ``calibrated_on`` names).
"""

from __future__ import annotations

import tomllib
from functools import cache
from importlib import resources
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

#: the law of the validated FE model (the engine's default, CALIBRATED)
CALIBRATED_LAW = "rech2013_calibrated"
#: the source's law, nothing fitted (``parameters = "a_priori"``)
A_PRIORI_LAW = "rech2013"


class FrictionLaw(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
    name: str
    status: Literal["A-PRIORI", "CALIBRATED"]
    description: str
    source: str
    calibrated_on: str | None = None
    velocity_m_per_min: tuple[float, ...]
    mu: tuple[float, ...]
    read_at: Literal["cutting_speed", "sliding"]
    shear_limit_MPa: float = Field(gt=0.0)

    @model_validator(mode="after")
    def _check(self) -> FrictionLaw:
        v, mu = self.velocity_m_per_min, self.mu
        if len(v) != len(mu) or len(v) < 2 or any(b <= a for a, b in zip(v, v[1:], strict=False)):
            raise ValueError(f"friction law {self.name}: expected increasing velocities "
                             "and one coefficient per velocity")
        if (self.status == "CALIBRATED") != (self.calibrated_on is not None):
            raise ValueError(f"friction law {self.name}: a CALIBRATED law names the data it "
                             "was calibrated on (calibrated_on), an A-PRIORI law none")
        return self


@cache
def friction_laws() -> dict[str, FrictionLaw]:
    """The bundled friction laws by name."""
    f = resources.files("robobore.material") / "friction_laws.toml"
    data = tomllib.loads(f.read_text(encoding="utf-8"))
    return {k: FrictionLaw(name=k, **v) for k, v in data.items()}


def friction_law(name: str) -> FrictionLaw:
    """One bundled law; ``KeyError`` naming the known laws when ``name`` is not one."""
    laws = friction_laws()
    if name not in laws:
        raise KeyError(f"unknown friction law {name!r}; expected one of {sorted(laws)}")
    return laws[name]
