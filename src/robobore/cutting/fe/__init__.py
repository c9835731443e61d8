"""Explicit FE cutting engines: 2D orthogonal and 3D boring (docs/fe.md, docs/fe3d.md)."""

#: revision of the FE engine's physics: part of the key of cached FE results (the force
#: calibration's virtual tests) and of the stored validation runs. Bump it whenever a change
#: of the engine changes its results for the same config, so that FE forces of another
#: revision are not reused. Revision 2: the contact's stick/slip return mapping on the trial
#: velocity
FE_ENGINE_REVISION = 2

__all__ = ["FE_ENGINE_REVISION"]
