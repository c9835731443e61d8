"""The 3D engine's arrays grouped by concern for the ALE pass (:func:`robobore.cutting.fe.ale.
remap3d.remap3d`, :func:`robobore.cutting.fe.ale.rezone3d.rezone3d`): named tuples of arrays,
which numba compiles as typed records (a field is read by name, in nopython code and in
``prange`` loops alike).

The compiled loop (:func:`robobore.cutting.fe.engine.kernels3d.run_chunk3_ale`), the allocating
wrappers (``remap3d_py``, ``rezone3d_py``) and the benchmarks build them from these definitions
by field name, so no caller can pass the arrays in another order.

Shapes: ``n`` nodes, ``e`` hexahedra (VTK order).
"""

from __future__ import annotations

from collections import namedtuple

__all__ = ["Nodes3", "Cells3", "ElementState3", "RemapWork3", "ToolFrameAle3"]

#: the nodes: positions ``x, y, z`` (n,) [m], velocities ``vx, vy, vz`` (n,) [m/s], lumped
#: ``mass`` (n,) [kg] (rebuilt by the remap), ``fixed`` (n,) int64 bit mask of held
#: directions, and the node-to-element map ``ptr`` (n + 1,), ``nel`` (8 e,) int64 (CSR)
Nodes3 = namedtuple("Nodes3", "x y z vx vy vz mass fixed ptr nel")

#: the hexahedra: ``conn`` (e, 8) int64, ``alive`` (e,) int64 (1 live, 0 / -1 eroded),
#: ``fnbr`` (e, 6) int64 face neighbours (-1: outline), ``bflag`` (e, 6) int64 the outline
#: faces' flux types (``remap3d.FACES_OUT``...; (0, 6): closed)
Cells3 = namedtuple("Cells3", "conn alive fnbr bflag")

#: the element state the remap transports: deviatoric stress ``sd`` (e, 6) [Pa], pressure
#: ``pres`` (e,) [Pa], plastic strain ``eps_p`` (e,), temperature ``temp`` (e,) [K], damage
#: ``dmg`` (e,), hourglass forces ``qh`` (e, 12) [N], reference volume ``vol0`` (e,) [m^3],
#: inertia factors ``msf`` (e,) (empty: 1)
ElementState3 = namedtuple("ElementState3", "sd pres eps_p temp dmg qh vol0 msf")

#: the remap's work arrays: the new positions ``xn, yn, zn`` (n,) [m], ``buf`` (e, N_RZ3),
#: ``vbuf`` (n, 3)
RemapWork3 = namedtuple("RemapWork3", "xn yn zn buf vbuf")

#: the tool-frame mesh's ALE data: the nodes' places at the start ``x0, y0, z0`` (n,) [m],
#: ``acls`` (n, 7) int64 node classes and in-plane neighbours, ``aflt`` (n, 6) their floats
#: (``rezone3d.toolframe3d_ale_data``; columns 4, 5 the mesh displacement, carried from pass
#: to pass), ``scratch`` (n, >= 2) work
ToolFrameAle3 = namedtuple("ToolFrameAle3", "x0 y0 z0 acls aflt scratch")
