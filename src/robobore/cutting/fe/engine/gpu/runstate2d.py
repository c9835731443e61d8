"""The 2D GPU engine's device state: the arrays of the persistent kernel's state, in its
order (:data:`RUN_ARRAYS`, :data:`RunState`), and the slots of the reduction array ``red``
(:data:`R_FX` ... :data:`N_RED`), shared by the kernels
(:mod:`robobore.cutting.fe.engine.gpu.kernels2d`) and the host driver
(:mod:`robobore.cutting.fe.engine.gpu.backend2d`).
"""

from __future__ import annotations

from collections import namedtuple

__all__ = ["RUN_ARRAYS", "RunState", "R_FX", "R_FY", "R_NC", "R_SPLIT", "N_RED"]

# reduction slots on the device (engine.gpu.persistent's R_DTMIN, R_BAD, then the two sums of
# its contact-force total; the number of contact nodes, counted by atomic add)
R_FX, R_FY, R_NC = 2, 3, 4
#: the contact force by tool face (kernels.contact_split): rake x, y, edge arc x, y, flank x, y
R_SPLIT = 5
N_RED = 11

#: FEState arrays used by the kernels (copied to the device), in the order of the persistent
#: kernel's state
RUN_ARRAYS = ("x", "y", "vx", "vy", "mass", "fixed", "ptr", "nel", "ncorner", "conn", "layer",
              "alive", "qs", "area0", "ie", "hge", "fex", "fey", "dte", "plast", "rate", "cfx",
              "cfy", "fric", "pen", "ndead", "ero_ke", "nwork", "mat", "prm", "tool", "en", "ist",
              "clock", "hacc", "hist", "enbr", "twin", "tied", "tbuf", "fheat", "tcq", "ppair",
              "vslip", "snodes", "x0", "y0", "xn", "yn", "buf", "vbuf", "acls", "aflt", "bflag")
#: the persistent kernel's state: the arrays, then the erosion mode, the conduction interval
#: [steps] (read with conduction only), 1 with the thermal contact, the ALE interval [steps]
#: (read in the tool frame only)
RunState = namedtuple("RunState", RUN_ARRAYS + ("erosion", "cond_every", "theat", "rz_every"))
