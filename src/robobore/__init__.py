"""robobore: robotic boring and robotic machining dynamics.

Pipeline (see docs/ARCHITECTURE.md): robot stiffness identification -> modal analysis ->
equivalent mass-spring-damper model -> cutting (mechanistic forces, explicit FE) ->
process dynamics (time domain, stability lobes) -> study (sweeps, comparison, report).
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("robobore")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
