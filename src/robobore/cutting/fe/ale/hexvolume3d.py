"""Volumes of trilinear hexahedra and of the regions their faces sweep, for the 3D remap
(:mod:`robobore.cutting.fe.ale.remap3d`).

A node moving on a straight line from its old to its new place makes a face (bilinear in
its two parameters) sweep the region of the map
``(s, t, tau) -> (1 - tau) X_old(s, t) + tau X_new(s, t)``, which is trilinear: the 8-node
hexahedron with the old face as its bottom and the new face as its top. Its signed volume
is computed with the Flanagan-Belytschko volume derivatives of
:mod:`robobore.cutting.fe.hex.element` (``V = sum_I x_I dV/dx_I``; exact for a trilinear
hexahedron), in coordinates relative to the face's first old corner.

The functions are scalar (``*_py`` originals, ``njit`` versions without the suffix, inlined
into the callers' ``prange`` loops); :func:`element_volumes3` is the allocating wrapper.

Face numbering: face ``f`` of an element has the node set of
:data:`robobore.cutting.fe.physics.thermal3d.HEX_FACES` ``[f]`` (so the neighbour table of
:func:`robobore.cutting.fe.physics.thermal3d.face_neighbours` serves as the remap's
``fnbr``), taken in the cyclic order of :data:`FACES_OUT` whose right-hand normal points out
of the element.
"""
# ruff: noqa: E501

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = [
    "FACES_OUT", "dv_py", "dv", "hex_volume_py", "hex_volume", "face_corner_py",
    "face_corner", "swept_face_py", "swept_face", "elem_volume_py", "elem_volume",
    "corner_gradient_py", "corner_gradient", "element_volumes3",
]


#: corners of each face, cyclic with the right-hand normal pointing out of the element; the
#: node sets (and the face numbers) of ``thermal3d.HEX_FACES``: xi = -1, xi = +1, eta = -1,
#: eta = +1, zeta = -1, zeta = +1
FACES_OUT = np.array([(0, 4, 7, 3), (1, 2, 6, 5), (0, 1, 5, 4), (3, 7, 6, 2), (0, 3, 2, 1),
                      (4, 5, 6, 7)], np.int64)
_CODES = tuple(int(sum(int(c) << (3 * (3 - j)) for j, c in enumerate(f))) for f in FACES_OUT)
_C0, _C1, _C2, _C3, _C4, _C5 = _CODES


def face_corner_py(f, j):
    """Corner (0-7) number ``j`` (0-3) of face ``f`` (0-5) of :data:`FACES_OUT`."""
    if f == 0:
        code = _C0
    elif f == 1:
        code = _C1
    elif f == 2:
        code = _C2
    elif f == 3:
        code = _C3
    elif f == 4:
        code = _C4
    else:
        code = _C5
    return (code >> (3 * (3 - j))) & 7


def dv_py(c, p, q):
    """``dV/dx_c`` of a trilinear hexahedron's volume with respect to corner ``c``'s x, given
    the corners' y (``p``) and z (``q``), each a tuple of the 8 corners' coordinates; cyclic:
    ``dV/dy_c = dv(c, z, x)``, ``dV/dz_c = dv(c, x, y)`` (Flanagan & Belytschko 1981, eq. 79:
    the coefficients of :func:`robobore.cutting.fe.hex.element.hex_element_py`)."""
    p0, p1, p2, p3, p4, p5, p6, p7 = p
    q0, q1, q2, q3, q4, q5, q6, q7 = q
    if c == 0:
        return (p1*(-q2-q3+q4+q5) + p2*(q1-q3) + p3*(q1+q2-q4-q7) + p4*(-q1+q3-q5+q7) + p5*(-q1+q4) + p7*(q3-q4)) / 12.0
    elif c == 1:
        return (p0*(q2+q3-q4-q5) + p2*(-q0-q3+q5+q6) + p3*(-q0+q2) + p4*(q0-q5) + p5*(q0-q2+q4-q6) + p6*(-q2+q5)) / 12.0
    elif c == 2:
        return (p0*(-q1+q3) + p1*(q0+q3-q5-q6) + p3*(-q0-q1+q6+q7) + p5*(q1-q6) + p6*(q1-q3+q5-q7) + p7*(-q3+q6)) / 12.0
    elif c == 3:
        return (p0*(-q1-q2+q4+q7) + p1*(q0-q2) + p2*(q0+q1-q6-q7) + p4*(-q0+q7) + p6*(q2-q7) + p7*(-q0+q2-q4+q6)) / 12.0
    elif c == 4:
        return (p0*(q1-q3+q5-q7) + p1*(-q0+q5) + p3*(q0-q7) + p5*(-q0-q1+q6+q7) + p6*(-q5+q7) + p7*(q0+q3-q5-q6)) / 12.0
    elif c == 5:
        return (p0*(q1-q4) + p1*(-q0+q2-q4+q6) + p2*(-q1+q6) + p4*(q0+q1-q6-q7) + p6*(-q1-q2+q4+q7) + p7*(q4-q6)) / 12.0
    elif c == 6:
        return (p1*(q2-q5) + p2*(-q1+q3-q5+q7) + p3*(-q2+q7) + p4*(q5-q7) + p5*(q1+q2-q4-q7) + p7*(-q2-q3+q4+q5)) / 12.0
    return (p0*(-q3+q4) + p2*(q3-q6) + p3*(q0-q2+q4-q6) + p4*(-q0-q3+q5+q6) + p5*(-q4+q6) + p6*(q2+q3-q4-q5)) / 12.0


dv = njit(cache=True, inline="always")(dv_py)


def _relative_py(a):
    # the 8 corners' coordinates relative to corner 0 (corner 0 itself: 0)
    a0 = a[0]
    return (0.0, a[1] - a0, a[2] - a0, a[3] - a0, a[4] - a0, a[5] - a0, a[6] - a0, a[7] - a0)


_relative = njit(cache=True, inline="always")(_relative_py)


def hex_volume_py(x, y, z):
    """Signed volume of the trilinear hexahedron with corners 0-7 in VTK order (positive for
    the node order of :mod:`robobore.cutting.fe.hex.element`), given the tuples ``x, y, z``
    of the 8 corners' coordinates: ``sum_I x_I dV/dx_I`` with the element's volume
    derivatives (:func:`dv_py`), exact for any trilinear hexahedron; evaluated in coordinates
    relative to corner 0."""
    xr = _relative(x)
    yr = _relative(y)
    zr = _relative(z)
    v = 0.0
    for c in range(1, 8):
        v += xr[c] * dv(c, yr, zr)
    return v


hex_volume = njit(cache=True, inline="always")(hex_volume_py)


def swept_face_py(e, f, conn, x, y, z, xn, yn, zn):
    """Volume swept outward by face ``f`` of element ``e`` moving from ``x, y, z`` to
    ``xn, yn, zn`` (the trilinear hexahedron old face -> new face, see the module
    docstring); negative when the face moves into the element."""
    a = conn[e, face_corner(f, 0)]
    b = conn[e, face_corner(f, 1)]
    c = conn[e, face_corner(f, 2)]
    d = conn[e, face_corner(f, 3)]
    if (x[a] == xn[a] and y[a] == yn[a] and z[a] == zn[a] and x[b] == xn[b] and y[b] == yn[b]
            and z[b] == zn[b] and x[c] == xn[c] and y[c] == yn[c] and z[c] == zn[c]
            and x[d] == xn[d] and y[d] == yn[d] and z[d] == zn[d]):
        return 0.0  # a face that does not move sweeps nothing (not a round-off residue)
    return hex_volume((x[a], x[b], x[c], x[d], xn[a], xn[b], xn[c], xn[d]),
                      (y[a], y[b], y[c], y[d], yn[a], yn[b], yn[c], yn[d]),
                      (z[a], z[b], z[c], z[d], zn[a], zn[b], zn[c], zn[d]))


face_corner = njit(cache=True, inline="always")(face_corner_py)
swept_face = njit(cache=True, inline="always")(swept_face_py)


def elem_volume_py(e, conn, x, y, z):
    """Signed volume of hexahedron ``e`` of ``conn`` over the nodes ``x, y, z``."""
    i0, i1, i2, i3 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
    i4, i5, i6, i7 = conn[e, 4], conn[e, 5], conn[e, 6], conn[e, 7]
    return hex_volume((x[i0], x[i1], x[i2], x[i3], x[i4], x[i5], x[i6], x[i7]),
                      (y[i0], y[i1], y[i2], y[i3], y[i4], y[i5], y[i6], y[i7]),
                      (z[i0], z[i1], z[i2], z[i3], z[i4], z[i5], z[i6], z[i7]))


elem_volume = njit(cache=True, inline="always")(elem_volume_py)


def corner_gradient_py(e, c, conn, x, y, z):
    """``dV/dx_c`` (3 components) of hexahedron ``e``'s volume with respect to its corner
    ``c`` (:func:`dv_py`, in coordinates relative to corner 0)."""
    i0, i1, i2, i3 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
    i4, i5, i6, i7 = conn[e, 4], conn[e, 5], conn[e, 6], conn[e, 7]
    xr = _relative((x[i0], x[i1], x[i2], x[i3], x[i4], x[i5], x[i6], x[i7]))
    yr = _relative((y[i0], y[i1], y[i2], y[i3], y[i4], y[i5], y[i6], y[i7]))
    zr = _relative((z[i0], z[i1], z[i2], z[i3], z[i4], z[i5], z[i6], z[i7]))
    gx = dv(c, yr, zr)
    gy = dv(c, zr, xr)
    gz = dv(c, xr, yr)
    return gx, gy, gz


corner_gradient = njit(cache=True, inline="always")(corner_gradient_py)


@njit(cache=True)
def _volumes(conn, x, y, z, out):
    for e in range(conn.shape[0]):
        out[e] = elem_volume(e, conn, x, y, z)


def element_volumes3(nodes: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Volumes (e,) [m^3] of the hexahedra ``conn`` (e, 8) over ``nodes`` (n, 3), by
    :func:`hex_volume_py` (equal to :func:`robobore.cutting.fe.engine.state3d.hex_volumes`
    to round-off)."""
    nodes = np.ascontiguousarray(nodes, np.float64)
    out = np.empty(conn.shape[0])
    _volumes(np.ascontiguousarray(conn, np.int64), nodes[:, 0].copy(), nodes[:, 1].copy(),
             nodes[:, 2].copy(), out)
    return out
