"""The 3D engine's arrays grouped by concern for the ALE pass (:func:`robobore.cutting.fe.ale.
remap3d.remap3d`, :func:`robobore.cutting.fe.ale.rezone3d.rezone3d`) and the parallel element
and node passes (:func:`robobore.cutting.fe.engine.kernels3d.element_update3`,
:func:`~robobore.cutting.fe.engine.kernels3d.node_update3`): named tuples of arrays, which
numba compiles as typed records (a field is read by name).

``prange`` bodies read flat locals, each bound by its own statement before the loop, because
numba (0.68) drops, as dead code, a ``prange`` body's writes into an array it reaches through a
tuple (a field read in the body, or a local unpacked from a tuple of same-typed arrays; the
loop reads correctly and writes nothing: :mod:`robobore.cutting.fe.engine.groups2d`).
Arrays a per-item function only reads come to it in plain tuples built at the call, in the
body, from those locals (``rz3_flux(e, conn, (x, y, z), ...)``, unpacked at the top of the
function); the arrays it writes come one by one. Built there, the tuples cost nothing
measurable (the remap of ``benchmarks/bench_rezone3d.py``, one thread: 11.2-12.3 ms per pass
with tuples and with flat arguments, load 0.6).

The compiled loop (:func:`robobore.cutting.fe.engine.kernels3d.run_chunk3_ale`), the allocating
wrappers (``remap3d_py``, ``rezone3d_py``), :func:`groups3_of` and the benchmarks build them
from these definitions by field name, so no caller can pass the arrays in another order.

Shapes: ``n`` nodes, ``e`` hexahedra (VTK order).
"""

from __future__ import annotations

from collections import namedtuple

__all__ = ["Nodes3", "Cells3", "ElementState3", "RemapWork3", "ToolFrameAle3",
           "ElementOut3", "Contact3", "groups3_of"]

#: the nodes: positions ``x, y, z`` (n,) [m], velocities ``vx, vy, vz`` (n,) [m/s], lumped
#: ``mass`` (n,) [kg] (rebuilt by the remap), ``fixed`` (n,) int64 bit mask of held
#: directions, and the node-to-element map ``ptr`` (n + 1,), ``nel`` (8 e,) int64 (CSR)
Nodes3 = namedtuple("Nodes3", "x y z vx vy vz mass fixed ptr nel")

#: the hexahedra: ``conn`` (e, 8) int64, ``alive`` (e,) int64 (1 live, 0 / -1 eroded),
#: ``fnbr`` (e, 6) int64 face neighbours (-1: outline), ``bflag`` (e, 6) int64 the outline
#: faces' flux types (``hexvolume3d.FACES_OUT``...; (0, 6): closed)
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

#: the element outputs: internal and hourglass work ``ie, hge`` (e,) [J], nodal forces ``fe``
#: (e, 24) [N], stable step ``dte`` (e,) [s], plastic work ``plast`` (e,) [J], plastic strain
#: rate ``rate`` (e,) [1/s]
ElementOut3 = namedtuple("ElementOut3", "ie hge fe dte plast rate")

#: the contact and node energies: ``cf`` (n, 4) the contact force [N] and the filtered sliding
#: speed [m/s],
#: friction work ``fric`` and penalty energy ``pen`` (n,) [J], ``ndead`` (n,) nodes of eroded
#: elements, ``ero_ke`` (n,) their kinetic energy [J], ``nwork`` (n,) work of the held nodes
#: [J], node splitting ``pairs`` (n, 2) int64
Contact3 = namedtuple("Contact3", "cf fric pen ndead ero_ke nwork pairs")

#: the state's name of a group field where it differs
_STATE_NAME = {"fnbr": "enbr"}


def groups3_of(st, **over):
    """The groups ``(nodes, cells, elems, out, contact)`` (:data:`Nodes3`, :data:`Cells3`,
    :data:`ElementState3`, :data:`ElementOut3`, :data:`Contact3`) of a 3D state ``st``
    (:class:`~robobore.cutting.fe.engine.state3d.FEState3`), each array read by its field
    name (``fnbr``: ``st.enbr``); ``over`` replaces arrays by field name (``vx=...``)."""
    return tuple(g(*(over[f] if f in over else getattr(st, _STATE_NAME.get(f, f))
                     for f in g._fields))
                 for g in (Nodes3, Cells3, ElementState3, ElementOut3, Contact3))
