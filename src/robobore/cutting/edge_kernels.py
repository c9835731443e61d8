"""Compiled scalar functions of the boring insert's edge (:mod:`robobore.cutting.geometry`):
the edge profile by arc length (:func:`edge_point`), the profile's width at a drop
(:func:`profile_width`) and the pass that builds the edge elements (:func:`element_pass`).
The formulas and their sources are in :mod:`robobore.cutting.geometry`; its functions are the
public entry points.
"""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True, inline="always")
def edge_point(s, r, k, ke):  # pragma: no cover - numba
    """``(zeta, drop, kappa_local)`` of the edge point at arc length ``s`` [m] from the tip
    (nose radius ``r``, approach angle ``k``, end-edge angle ``ke``): the nose arc
    (``psi = s / r``, ``zeta = r sin psi``, ``drop = r (1 - cos psi)``) for
    ``-r ke <= s <= r k``, the straight major edge at ``k`` beyond it, the straight minor edge
    at ``-ke`` behind it."""
    if s >= -r * ke and s <= r * k:
        psi = s / r
        return r * math.sin(psi), r * (1 - math.cos(psi)), psi
    if s > r * k:
        t = s - r * k
        return r * math.sin(k) + t * math.cos(k), r * (1 - math.cos(k)) + t * math.sin(k), k
    t = -s - r * ke
    return (-r * math.sin(ke) - t * math.cos(ke), r * (1 - math.cos(ke)) + t * math.sin(ke),
            -ke)


@nb.njit(cache=True)
def edge_points(s, r, k, ke, zeta, drop, kl):  # pragma: no cover - numba
    for i in range(s.size):
        zeta[i], drop[i], kl[i] = edge_point(s[i], r, k, ke)


@nb.njit(cache=True, inline="always")
def width_constants(r, k, ke):  # pragma: no cover - numba
    """The constants of :func:`profile_width` for nose radius ``r``, approach angle ``k`` and
    end-edge angle ``ke``: the drops where the arc meets the major and the minor edge, and
    each straight edge's offset and slope."""
    return (r * (1 - math.cos(k)), r * (1 - math.cos(ke)), r * math.sin(k), math.tan(k),
            r * math.sin(ke), math.tan(ke))


@nb.njit(cache=True, inline="always")
def profile_width(d, r, d_lead, d_trail, rsk, tk, rske, tke, k90):  # pragma: no cover
    """Width ``b(d) - a(d)`` [m] of the tool profile at drop ``d`` [m] (the insert's constants
    from :func:`width_constants`): the leading side ``b`` on the arc up to ``d_lead``, then on
    the major edge (``r`` for a 90 deg edge, ``k90``); the trailing side ``a`` on the arc up
    to ``d_trail``, then on the minor edge."""
    x = r - min(d, 2 * r)
    circ = math.sqrt(max(r * r - x * x, 0.0))
    if d <= d_lead:
        b = circ
    elif k90:
        b = r
    else:
        b = rsk + (d - d_lead) / tk
    if d <= d_trail:
        a = -circ
    else:
        a = -(rske + (d - d_trail) / tke)
    return b - a


@nb.njit(cache=True)
def profile_widths(d, r, k, ke, k90, out):  # pragma: no cover - numba
    d_lead, d_trail, rsk, tk, rske, tke = width_constants(r, k, ke)
    for i in range(d.size):
        out[i] = profile_width(d[i], r, d_lead, d_trail, rsk, tk, rske, tke, k90)


@nb.njit(cache=True)
def element_pass(insert, depth, fz, s_end, s_i, counts, quad, out):  # pragma: no cover
    """The elements of :func:`robobore.cutting.geometry.edge_elements` into the rows of
    ``out`` (7, n_str + n_arc + n): ``s, zeta, drop, kappa, h, db, dS``, trailing elements
    first. ``insert``: ``(r, k, ke, k90)`` (nose radius, approach and end-edge angles, a
    90 deg major edge); ``counts``: ``(n, n_str, n_arc)``; ``quad``: Gauss-Legendre nodes and
    weights (2, n_quad).

    Trailing side: from ``s_i`` to the tip, ``n_str`` elements of equal length on the straight
    minor edge and ``n_arc`` on the arc (the corner ``-r ke`` a node; without a straight part
    ``n_arc`` from ``s_i``), ``h = db = 0``. Leading side: ``n`` elements of equal arc length
    from the tip to ``s_end`` (where the edge reaches the pre-bore surface); the radial levels
    of an element's ends are its ends' drops (capped at the depth, the last one the depth), its
    chip area ``integral min(f, w(d)) dd`` between them (Gauss-Legendre ``xg``, ``wg`` on
    [-1, 1]), ``h = area / dS``, ``db = dS``. The nodes are numpy.linspace's
    (``i * step + start``, the last node the stop); element centres and local angles are those
    of :func:`edge_point` at the centre. Returns ``sum(h db)`` over the leading side, the
    elements' chip area."""
    r, k, ke, k90 = insert
    n, n_str, n_arc = counts
    xg = quad[0]
    wg = quad[1]
    nt = n_str + n_arc
    s_corner = -r * ke
    for j in range(nt):
        if j < n_str:
            st = (s_corner - s_i) / n_str
            a0 = j * st + s_i
            a1 = s_corner if j + 1 == n_str else (j + 1) * st + s_i
        else:
            i = j - n_str
            if n_str > 0:
                st = (0.0 - s_corner) / n_arc
                a0 = s_corner if i == 0 else i * st + s_corner
                a1 = 0.0 if i + 1 == n_arc else (i + 1) * st + s_corner
            else:
                st = (0.0 - s_i) / n_arc
                a0 = i * st + s_i
                a1 = 0.0 if i + 1 == n_arc else (i + 1) * st + s_i
        sc = 0.5 * (a1 + a0)
        out[0, j] = sc
        out[1, j], out[2, j], out[3, j] = edge_point(sc, r, k, ke)
        out[4, j] = 0.0
        out[5, j] = 0.0
        out[6, j] = a1 - a0
    d_lead, d_trail, rsk, tk, rske, tke = width_constants(r, k, ke)
    step = s_end / n
    area = 0.0
    e0 = 0.0
    d0 = min(edge_point(0.0, r, k, ke)[1], depth)
    for i in range(n):
        e1 = s_end if i + 1 == n else (i + 1) * step + 0.0
        d1 = depth if i + 1 == n else min(edge_point(e1, r, k, ke)[1], depth)
        ds = e1 - e0
        sc = 0.5 * (e1 + e0)
        j = nt + i
        out[0, j] = sc
        out[1, j], out[2, j], out[3, j] = edge_point(sc, r, k, ke)
        acc = 0.0
        for q in range(xg.size):
            dq = 0.5 * (d0 + d1) + 0.5 * (d1 - d0) * xg[q]
            w = profile_width(dq, r, d_lead, d_trail, rsk, tk, rske, tke, k90)
            acc += min(fz, w) * wg[q]
        out[4, j] = (0.5 * (d1 - d0)) * acc / ds
        out[5, j] = ds
        out[6, j] = ds
        area += out[4, j] * ds
        e0, d0 = e1, d1
    return area


__all__ = ["edge_point", "edge_points", "width_constants", "profile_width", "profile_widths",
           "element_pass"]
