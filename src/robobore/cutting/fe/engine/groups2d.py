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

``prange`` bodies read flat locals, each bound by its own statement before the loop
(``sdx = state.sdx``), because numba (0.68) drops, as dead code, a ``prange`` body's writes into
an array it reaches through a tuple: a field of a named or plain tuple read inside the body
(passed in, or built in the body, once the body is inlined), or a local unpacked from a tuple
of same-typed arrays (``a, b, c, d = g.a, g.b, g.c, g.d`` packs one; ``a, b, c = g`` too); the
loop then reads correctly and writes nothing. The parallel passes therefore take the groups
and bind their arrays one statement each; the per-element and per-node functions the body
inlines take those locals one by one (measured with numba 0.68.1: the bound groups run as
fast as flat arguments, one thread and two; ``tests/cutting/fe/test_groups2d.py`` checks that
a parallel pass so written writes every array). A per-element function that takes the groups
and is compiled apart (``njit`` without ``inline="always"``, called from the body with the
groups) keeps the writes, but runs the 2D contract case at 0.62-0.63 of the inlined flat form
(paired, one thread: ``benchmarks/measured/fe_before_after/
quad_element_groups_apart_2d_paired.txt``), and called once per task of 256 elements (a serial
loop compiled apart, the ``prange`` over the tasks) at 0.83-0.85
(``quad_element_chunked_2d_paired.txt``). Reading the groups by field name inside an inlined
per-node function keeps the writes but costs about 3 % in the thermal contact pass
(``tool_heat_node_groups_2d_paired.txt``). The arrays a per-item function only reads, and its
scalars, may reach it in plain tuples built at the call, in the body, from the flat locals,
and unpacked at the top of the function; the arrays it writes stay flat parameters
(:func:`robobore.cutting.fe.physics.thermal2d.tool_heat_node_py`).

Shapes: ``n`` nodes, ``e`` quads.
"""

from __future__ import annotations

from collections import namedtuple

from numba import njit

__all__ = ["Nodes2", "Quads2", "QuadState2", "QuadOut2", "Contact2", "Ale2", "groups_of",
           "nodes_of", "quads_of", "state_of", "out_of", "contact_of", "ale_of"]

#: the nodes: positions ``x, y`` (n,) [m], velocities ``vx, vy`` (n,) [m/s], lumped ``mass``
#: (n,) [kg/m], ``fixed`` (n,) held in x and y, and the node-to-element lists ``ptr`` (n + 1,),
#: ``nel``, ``ncorner`` (CSR: the elements of node n and its corner in each)
Nodes2 = namedtuple("Nodes2", "x y vx vy mass fixed ptr nel ncorner")

#: the quads: corners ``conn`` (e, 4), separation-layer flag ``layer`` (e,), ``alive`` (e,)
#: (1 alive, 0 / -1 / -2 eroded or inverted), reference area ``area0`` (e,) [m^2]
Quads2 = namedtuple("Quads2", "conn layer alive area0")

#: the element state: deviatoric stress ``sdx, sdy, sdz, sdxy`` [Pa], pressure ``pres`` [Pa],
#: plastic strain ``eps_p``, temperature ``temp`` [K], damage ``dmg``, stored hourglass forces
#: ``qhx, qhy`` [N/m], each (e,)
QuadState2 = namedtuple("QuadState2", "sdx sdy sdz sdxy pres eps_p temp dmg qhx qhy")

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

_GROUPS = (Nodes2, Quads2, QuadState2, QuadOut2, Contact2, Ale2)


def groups_of(st, **over):
    """The groups ``(nodes, quads, state, out, contact, ale)`` of a state ``st`` (any object with
    the fields as attributes: :class:`~robobore.cutting.fe.engine.state2d.FEState`), each
    array read by its field name; ``over`` replaces arrays by name (``vx=...``)."""
    return tuple(g(*(over[f] if f in over else getattr(st, f) for f in g._fields))
                 for g in _GROUPS)


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
def state_of(s):
    """:data:`QuadState2` of the loop state ``s``."""
    return QuadState2(sdx=s.sdx, sdy=s.sdy, sdz=s.sdz, sdxy=s.sdxy, pres=s.pres, eps_p=s.eps_p,
                      temp=s.temp, dmg=s.dmg, qhx=s.qhx, qhy=s.qhy)


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
