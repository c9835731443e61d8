"""Experimental modal analysis of impact-hammer tests.

FRF estimation (:mod:`.frf`), CMIF (:mod:`.cmif`), poly-reference LSCF / PolyMAX
(:mod:`.plscf`), stabilisation diagram and automatic pole selection (:mod:`.stabilization`),
LSFD mode shapes (:mod:`.lsfd`), the pipeline and its result contract (:mod:`.identify`:
:class:`ModalResult`), SYNTHETIC virtual hammer tests (:mod:`.virtual`), files (:mod:`.io`)
and plots (:mod:`.plots`). Imports are lazy so that ``import robobore.modal`` stays light.
"""

from __future__ import annotations

from typing import Any

_EXPORTS = {
    "FRFData": "frf_data", "HammerRecords": "frf", "estimate_frf": "frf",
    "convert_frf": "frf_data",
    "cmif": "cmif", "CMIF": "cmif", "plscf": "plscf", "PLSCFResult": "plscf",
    "stabilisation": "stabilization", "select_poles": "stabilization", "mac": "stabilization",
    "lsfd": "lsfd", "mpc": "lsfd", "identify_modes": "identify", "ModalResult": "identify",
    "Mode": "identify", "ModalAnalysis": "identify", "ModalTruth": "virtual",
    "robot_boring_truth": "virtual", "simulate_hammer_test": "virtual", "read_uff": "io",
    "write_uff_time": "io", "write_uff_frf": "io", "load_npz": "io", "save_npz": "io",
    "load_input": "io",
}


def __getattr__(name: str) -> Any:
    if name in _EXPORTS:
        import importlib

        return getattr(importlib.import_module(f"robobore.modal.{_EXPORTS[name]}"), name)
    raise AttributeError(name)


__all__ = sorted(_EXPORTS)
