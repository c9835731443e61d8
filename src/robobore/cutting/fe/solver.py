"""The plane-strain explicit solver: the names of its modules in one place.

* :mod:`~robobore.cutting.fe.state2d`: :class:`FEState` (every array of a model, structure of
  arrays), :func:`make_state` from any quad mesh, :func:`default_prm`, :func:`parting_edges`,
  :func:`init_forces`.
* :mod:`~robobore.cutting.fe.chunk_driver`: :func:`advance` runs the compiled loop in chunks
  (progress between chunks) and turns a non-finite state or a collapsing time step into
  :class:`robobore.errors.NumericalError` (:func:`drive_chunks`, shared with the 3D engine);
  :func:`energy_error`.
* :mod:`~robobore.cutting.fe.engine_settings`: the config's solver, thermal and friction
  settings into the parameter vector (``apply_*_settings``, 2D and 3D).
* :mod:`~robobore.cutting.fe.orthogonal`: the orthogonal-cutting model
  (:func:`setup_orthogonal`, :func:`run_orthogonal`, :func:`simulate_orthogonal`).
"""

from __future__ import annotations

from robobore.cutting.fe.chunk_driver import (
    advance,
    drive_chunks,
    energy_error,
)
from robobore.cutting.fe.engine_settings import (
    apply_friction_settings,
    apply_solver_settings,
    apply_thermal_settings,
)
from robobore.cutting.fe.orthogonal import (
    CuttingSetup,
    check_device,
    run_orthogonal,
    setup_orthogonal,
    simulate_orthogonal,
)
from robobore.cutting.fe.state2d import (
    FEState,
    default_prm,
    init_forces,
    make_state,
    parting_edges,
)

__all__ = [
    "FEState",
    "default_prm",
    "make_state",
    "parting_edges",
    "init_forces",
    "drive_chunks",
    "advance",
    "CuttingSetup",
    "apply_solver_settings",
    "apply_thermal_settings",
    "apply_friction_settings",
    "setup_orthogonal",
    "energy_error",
    "check_device",
    "run_orthogonal",
    "simulate_orthogonal",
]
