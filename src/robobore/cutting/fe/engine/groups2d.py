"""The plane-strain engine's arrays grouped by concern for its parallel passes
(:func:`robobore.cutting.fe.quad.element.element_update`,
:func:`robobore.cutting.fe.quad.bbar.element_update_bbar`,
:func:`robobore.cutting.fe.quad.node_contact.node_update`,
:func:`robobore.cutting.fe.ale.rezone.rezone`): named tuples of arrays, one
definition of each group's fields, read by name.

The compiled loop builds them from its state (:func:`nodes_of` ... :func:`ale_of`, by
field name), Python callers from an :class:`~robobore.cutting.fe.engine.state2d.FEState`
(:func:`groups_of`, by the same field names), so no caller can pass the arrays in another
order.

The element state is one array ``qs`` (:data:`N_QS`, e), a row per field
(:data:`QS_FIELDS`, ``qs[QS_SDX, e]``): one argument for the ten fields, each row as
contiguous as a separate array, so the CPU's and the GPU's memory traffic are those of ten
arrays.

``prange`` bodies read flat locals, each bound by its own statement before the loop
(``x = nodes.x``), because numba (0.68) drops, as dead code, a ``prange`` body's writes into
an array it reaches through a tuple: a field of a named or plain tuple read inside the body
(passed in, or built in the body, once the body is inlined), or a local unpacked from a tuple
of same-typed arrays (``a, b, c, d = g.a, g.b, g.c, g.d`` packs one; ``a, b, c = g`` too); the
loop then reads correctly and writes nothing. The parallel passes therefore take the groups
and bind their arrays one statement each; the per-element and per-node functions the body
inlines take the arrays they write one by one, and the arrays they only read in plain tuples
built at the call from those locals (``tool_heat_node(n, (conn, x, y, ...), ...)``,
unpacked at the top of the function), which costs nothing measurable in the small ones
(``benchmarks/bench_rezone3d.py``); the large element and node updates (``quad_element_py``,
``quad_bbar_py``, ``quad_node_py``) take every argument flat, as the tuples cost the element
update 1-2 % (``benchmarks/measured/fe_before_after/qs_tuples_2d_paired.txt``).
``tests/cutting/fe/test_groups2d.py`` checks that a parallel pass so written writes every
array. A per-element function that takes the groups
and is compiled apart (``njit`` without ``inline="always"``, called from the body with the
groups) keeps the writes, but runs the 2D contract case at 0.62-0.63 of the inlined flat form
(paired, one thread: ``benchmarks/measured/fe_before_after/
quad_element_groups_apart_2d_paired.txt``), and called once per task of 256 elements (a serial
loop compiled apart, the ``prange`` over the tasks) at 0.83-0.85
(``quad_element_chunked_2d_paired.txt``). Reading a group passed into the parallel pass by
field name inside an inlined per-node function keeps the writes but costs about 3 % in the
thermal contact pass (``tool_heat_node_groups_2d_paired.txt``).

Shapes: ``n`` nodes, ``e`` quads.
"""

from __future__ import annotations

from collections import namedtuple

from numba import njit

__all__ = ["Nodes2", "Quads2", "QS_FIELDS", "QS_SDX", "QS_SDY", "QS_SDZ", "QS_SDXY", "QS_PRES",
           "QS_EPS_P", "QS_TEMP", "QS_DMG", "QS_QHX", "QS_QHY", "N_QS", "QuadOut2", "Contact2",
           "Ale2", "groups_of", "nodes_of", "quads_of", "out_of", "contact_of", "ale_of"]

#: the nodes: positions ``x, y`` (n,) [m], velocities ``vx, vy`` (n,) [m/s], lumped ``mass``
#: (n,) [kg/m], ``fixed`` (n,) held in x and y, and the node-to-element lists ``ptr`` (n + 1,),
#: ``nel``, ``ncorner`` (CSR: the elements of node n and its corner in each)
Nodes2 = namedtuple("Nodes2", "x y vx vy mass fixed ptr nel ncorner")

#: the quads: corners ``conn`` (e, 4), separation-layer flag ``layer`` (e,), ``alive`` (e,)
#: (1 alive, 0 / -1 / -2 eroded or inverted), reference area ``area0`` (e,) [m^2]
Quads2 = namedtuple("Quads2", "conn layer alive area0")

#: the rows of the element state ``qs`` (N_QS, e), one array: deviatoric stress ``sdx, sdy,
#: sdz, sdxy`` [Pa], pressure ``pres`` [Pa], plastic strain ``eps_p``, temperature ``temp``
#: [K], damage ``dmg``, stored hourglass forces ``qhx, qhy`` [N/m]; ``qs[QS_TEMP]`` is the
#: temperatures (e,), ``qs[QS_TEMP, e]`` element ``e``'s (``tests/cutting/fe/test_groups2d.py``
#: checks the constants against this list)
QS_FIELDS = ("sdx", "sdy", "sdz", "sdxy", "pres", "eps_p", "temp", "dmg", "qhx", "qhy")
QS_SDX = 0
QS_SDY = 1
QS_SDZ = 2
QS_SDXY = 3
QS_PRES = 4
QS_EPS_P = 5
QS_TEMP = 6
QS_DMG = 7
QS_QHX = 8
QS_QHY = 9
N_QS = 10

#: the element outputs: internal and hourglass work ``ie, hge`` (e,) [J/m], nodal forces
#: ``fex, fey`` (e, 4) [N/m], stable step ``dte`` (e,) [s], plastic work ``plast`` (e,) [J/m],
#: plastic strain rate ``rate`` (e,) [1/s]
QuadOut2 = namedtuple("QuadOut2", "ie hge fex fey dte plast rate")

#: the contact and node energies: contact forces ``cfx, cfy`` (n,) [N/m], friction work
#: ``fric`` and penalty energy ``pen`` (n,) [J/m], ``ndead`` (n,) nodes of eroded elements,
#: ``ero_ke`` (n,) their kinetic energy [J/m], ``nwork`` (n,) work of the held nodes [J/m],
#: node splitting ``twin`` (n,), ``tied`` (n,), the friction's slip speeds ``vslip`` (n,)
Contact2 = namedtuple("Contact2", "cfx cfy fric pen ndead ero_ke nwork twin tied vslip")

#: the tool-frame ALE pass (:func:`robobore.cutting.fe.ale.rezone.rezone`): the quads' edge
#: neighbours ``enbr`` (e, 4) and outline flux types ``bflag`` (e, 4), the nodes whose
#: velocity is remapped ``snodes``, the nodes' places at the start ``x0, y0`` (n,) [m], their
#: classes ``acls`` and data ``aflt`` (:mod:`robobore.cutting.fe.ale.toolframe`), the work
#: arrays ``xn, yn`` (n,), ``buf`` (e, N_RZ_FIELDS), ``vbuf`` (n, 2)
Ale2 = namedtuple("Ale2", "enbr bflag snodes x0 y0 acls aflt xn yn buf vbuf")

def groups_of(st, **over):
    """The groups ``(nodes, quads, qs, out, contact, ale)`` of a state ``st`` (any object with
    the fields as attributes: :class:`~robobore.cutting.fe.engine.state2d.FEState`), each
    array read by its field name, ``qs`` the element state array; ``over`` replaces arrays by
    name (``vx=...``, ``qs=...``)."""
    def group(g):
        return g(*(over[f] if f in over else getattr(st, f) for f in g._fields))

    qs = over["qs"] if "qs" in over else st.qs
    return (group(Nodes2), group(Quads2), qs, group(QuadOut2), group(Contact2), group(Ale2))


# the compiled loop's builders (from its state named tuple, by field name):
# tests/cutting/fe/test_groups2d.py checks each against the group's fields


@njit(inline="always")
def nodes_of(s):
    """:data:`Nodes2` of the loop state ``s``."""
    return Nodes2(x=s.x, y=s.y, vx=s.vx, vy=s.vy, mass=s.mass, fixed=s.fixed, ptr=s.ptr,
                  nel=s.nel, ncorner=s.ncorner)


@njit(inline="always")
def quads_of(s):
    """:data:`Quads2` of the loop state ``s``."""
    return Quads2(conn=s.conn, layer=s.layer, alive=s.alive, area0=s.area0)


@njit(inline="always")
def out_of(s):
    """:data:`QuadOut2` of the loop state ``s``."""
    return QuadOut2(ie=s.ie, hge=s.hge, fex=s.fex, fey=s.fey, dte=s.dte, plast=s.plast,
                    rate=s.rate)


@njit(inline="always")
def contact_of(s):
    """:data:`Contact2` of the loop state ``s``."""
    return Contact2(cfx=s.cfx, cfy=s.cfy, fric=s.fric, pen=s.pen, ndead=s.ndead,
                    ero_ke=s.ero_ke, nwork=s.nwork, twin=s.twin, tied=s.tied, vslip=s.vslip)


@njit(inline="always")
def ale_of(s):
    """:data:`Ale2` of the loop state ``s``."""
    return Ale2(enbr=s.enbr, bflag=s.bflag, snodes=s.snodes, x0=s.x0, y0=s.y0, acls=s.acls,
                aflt=s.aflt, xn=s.xn, yn=s.yn, buf=s.buf, vbuf=s.vbuf)
