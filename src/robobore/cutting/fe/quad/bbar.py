"""The fully integrated quadrilateral with mean-dilatation B-bar (2x2 Gauss points, no
hourglass modes) and its parallel element update (``solver.element = "q4_bbar"``).

Same material model and erosion as :mod:`robobore.cutting.fe.quad.element`; the
per-Gauss-point state lives in ``gps`` (``layout.G_*``).
"""

from __future__ import annotations

import math

from numba import njit, prange

from robobore.cutting.fe.engine.groups2d import (
    QS_DMG,
    QS_EPS_P,
    QS_PRES,
    QS_SDX,
    QS_SDXY,
    QS_SDY,
    QS_SDZ,
    QS_TEMP,
)
from robobore.cutting.fe.engine.layout import (
    G_EPS,
    G_SX,
    G_SXY,
    G_SY,
    G_SZ,
    P_BV1,
    P_BV2,
    P_DIST,
    P_DT_ERODE,
    P_MS,
)
from robobore.cutting.fe.quad.element import (
    damage_erosion,
    quad_area_corners,
    quad_bvectors,
    quad_distorted,
    quad_retire,
    quad_step,
)
from robobore.material import johnson_cook as jc
from robobore.material.johnson_cook import jc_damage_increment, radial_return


def quad_bbar_py(e, conn, layer, area0, x, y, vx, vy, alive, qs, gps, ie, fex, fey, dte, plast,
                 rate, mat, prm, dt, erosion):
    """Fully integrated quad ``e`` with mean-dilatation B-bar (scalar code, allocates nothing).

    Four Gauss points (2x2) each carry their own deviatoric stress and plastic strain
    (``gps[e, k, G_*]``); the pressure is one per element, from the element's mean
    dilatation rate (the centroid b-vectors of the one-point element are exactly the
    area-averaged shape-function gradients of the bilinear quad), so there is no volumetric
    locking in isochoric plastic flow (Nagtegaal, Parks & Rice 1974; Hughes 1980 "B-bar") and
    no hourglass mode at all: hourglass-shaped deformation strains the Gauss points, which
    resist it with the material's own (elastic or plastic) response. The temperature and the
    damage stay one per element (Gauss-point plastic work and damage increments are
    area-weighted); the rows ``sdx``, ``sdy``, ``sdz``, ``sdxy``, ``eps_p`` of the element
    state ``qs`` and ``rate`` receive the area-weighted Gauss-point means (for the outputs,
    conduction and erosion). The other arguments as in
    :func:`robobore.cutting.fe.quad.element.make_quad_element`'s ``quad_element_py``.

    Internal force ``f_I = sum_k detJ_k B_k^T sigma_k`` with ``sigma_k = s_k - p``: for a
    deviatoric ``s_k`` and an element-constant ``p`` this equals the B-bar force
    ``sum_k detJ_k Bbar_k^T sigma_k`` (Belytschko, Liu, Moran 2000, sec. 8.5). Stable step,
    bulk viscosity and erosion as :func:`quad_element_py`; returns ``(dte, inverted)``.
    """
    if alive[e] != 1:
        quad_retire(e, fex, fey, dte)
        return 1e30, False
    E = mat[jc.E_MOD]
    nu = mat[jc.NU]
    G = E / (2.0 * (1.0 + nu))
    K = E / (3.0 * (1.0 - 2.0 * nu))
    rho_s = mat[jc.RHO] * prm[P_MS]
    rcp = mat[jc.RHO] * mat[jc.CP]
    beta = mat[jc.BETA_TQ]
    a_, b_, n_, c_, m_ = mat[jc.A], mat[jc.B], mat[jc.N], mat[jc.C], mat[jc.M]
    e0, tr_, tm_, eh_ = mat[jc.EPS0], mat[jc.TROOM], mat[jc.TMELT], mat[jc.EPS_HMAX]
    bv1 = prm[P_BV1]
    bv2 = prm[P_BV2]
    dlim = prm[P_DIST]
    dt_erode = prm[P_DT_ERODE]
    i1 = conn[e, 0]
    i2 = conn[e, 1]
    i3 = conn[e, 2]
    i4 = conn[e, 3]
    x1, x2, x3, x4 = x[i1], x[i2], x[i3], x[i4]
    y1, y2, y3, y4 = y[i1], y[i2], y[i3], y[i4]
    A, cmin = quad_area_corners(x1, x2, x3, x4, y1, y2, y3, y4)
    if quad_distorted(e, alive, fex, fey, dte, area0, A, cmin, dlim):
        return 1e30, alive[e] == -2
    u1, u2, u3, u4 = vx[i1], vx[i2], vx[i3], vx[i4]
    w1, w2, w3, w4 = vy[i1], vy[i2], vy[i3], vy[i4]
    # mean dilatation rate from the centroid (area-averaged) gradients
    bx1, bx2, bx3, bx4, by1, by2, by3, by4 = quad_bvectors(x1, x2, x3, x4, y1, y2, y3, y4, A)
    trd = (u1 * bx1 + u2 * bx2 + u3 * bx3 + u4 * bx4
           + w1 * by1 + w2 * by2 + w3 * by3 + w4 * by4)
    p_old = qs[QS_PRES, e]
    p_new = p_old - K * trd * dt
    bsum = (bx1 * bx1 + bx2 * bx2 + bx3 * bx3 + bx4 * bx4
            + by1 * by1 + by2 * by2 + by3 * by3 + by4 * by4)
    _rho_c, _c, qbv, dte_e = quad_step(rho_s, area0[e], A, K, G, bsum, trd, bv1, bv2)
    dte[e] = dte_e
    # bilinear map x = a0 + a1 xi + a2 eta + a3 xi eta (same for y)
    ax1 = 0.25 * (-x1 + x2 + x3 - x4)
    ax2 = 0.25 * (-x1 - x2 + x3 + x4)
    ax3 = 0.25 * (x1 - x2 + x3 - x4)
    ay1 = 0.25 * (-y1 + y2 + y3 - y4)
    ay2 = 0.25 * (-y1 - y2 + y3 + y4)
    ay3 = 0.25 * (y1 - y2 + y3 - y4)
    gq = 0.5773502691896258  # 1 / sqrt(3)
    f1x = f2x = f3x = f4x = f1y = f2y = f3y = f4y = 0.0
    wsum = 0.0
    ssx = 0.0
    ssy = 0.0
    ssz = 0.0
    ssxy = 0.0
    seps = 0.0
    srate = 0.0
    wp_tot = 0.0
    dd = 0.0
    pw = 0.0
    t_e = qs[QS_TEMP, e]
    therm = 1.0 - jc.homologous_temperature(t_e, tr_, tm_) ** m_
    for k in range(4):
        xi = -gq if (k == 0 or k == 3) else gq
        eta = -gq if k < 2 else gq
        xx = ax1 + ax3 * eta  # dx/dxi
        xe = ax2 + ax3 * xi   # dx/deta
        yx = ay1 + ay3 * eta
        ye = ay2 + ay3 * xi
        dj = xx * ye - yx * xe
        idj = 1.0 / dj
        # dN/dxi and dN/deta of nodes 1..4 at (xi, eta): nodes at (-1,-1),(1,-1),(1,1),(-1,1)
        nx1 = -0.25 * (1.0 - eta)
        nx2 = 0.25 * (1.0 - eta)
        nx3 = 0.25 * (1.0 + eta)
        nx4 = -0.25 * (1.0 + eta)
        ne1 = -0.25 * (1.0 - xi)
        ne2 = -0.25 * (1.0 + xi)
        ne3 = 0.25 * (1.0 + xi)
        ne4 = 0.25 * (1.0 - xi)
        gx1 = (ye * nx1 - yx * ne1) * idj
        gx2 = (ye * nx2 - yx * ne2) * idj
        gx3 = (ye * nx3 - yx * ne3) * idj
        gx4 = (ye * nx4 - yx * ne4) * idj
        gy1 = (-xe * nx1 + xx * ne1) * idj
        gy2 = (-xe * nx2 + xx * ne2) * idj
        gy3 = (-xe * nx3 + xx * ne3) * idj
        gy4 = (-xe * nx4 + xx * ne4) * idj
        dvxdx = u1 * gx1 + u2 * gx2 + u3 * gx3 + u4 * gx4
        dvxdy = u1 * gy1 + u2 * gy2 + u3 * gy3 + u4 * gy4
        dvydx = w1 * gx1 + w2 * gx2 + w3 * gx3 + w4 * gx4
        dvydy = w1 * gy1 + w2 * gy2 + w3 * gy3 + w4 * gy4
        dxx = dvxdx
        dyy = dvydy
        dxy = 0.5 * (dvxdy + dvydx)
        rs = dt * 0.5 * (dvxdy - dvydx)
        sx = gps[e, k, G_SX]
        sy = gps[e, k, G_SY]
        sz = gps[e, k, G_SZ]
        sxy = gps[e, k, G_SXY]
        ep = gps[e, k, G_EPS]
        oxx = sx - p_old
        oyy = sy - p_old
        oxy = sxy
        sx_r = sx + 2.0 * rs * sxy
        sy_r = sy - 2.0 * rs * sxy
        sxy_r = sxy + rs * (sy - sx)
        # deviatoric trial from the Gauss point's own strain rate
        tr3 = (dxx + dyy) * dt / 3.0
        tx = sx_r + 2.0 * G * (dxx * dt - tr3)
        ty = sy_r + 2.0 * G * (dyy * dt - tr3)
        tz = sz + 2.0 * G * (-tr3)
        txy = sxy_r + 2.0 * G * dxy * dt
        # elastic check first (the same yield test as radial_return, with the element's
        # thermal factor computed once): most Gauss points of the mesh stay elastic
        qt = math.sqrt(1.5 * (tx * tx + ty * ty + tz * tz + 2.0 * txy * txy))
        sy0 = (a_ + b_ * (ep if ep < eh_ else eh_)**n_) * therm
        if qt <= sy0:
            nsx, nsy, nsz, nsxy, dep, syld = tx, ty, tz, txy, 0.0, sy0
        else:
            nsx, nsy, nsz, nsxy, dep, syld = radial_return(tx, ty, tz, txy, ep, t_e, dt, G,
                                                           a_, b_, n_, c_, m_, e0, tr_, tm_,
                                                           eh_)
        if dep > 0.0:
            ep += dep
            wp_tot += syld * dep * dj
            if syld > 0.0:
                triax = -p_new / syld
            else:
                triax = 0.0
            dd += dj * jc_damage_increment(dep, triax, dep / dt, t_e, mat[jc.D1],
                                           mat[jc.D2], mat[jc.D3], mat[jc.D4], mat[jc.D5],
                                           e0, tr_, tm_)
            srate += dj * dep / dt
        gps[e, k, G_SX] = nsx
        gps[e, k, G_SY] = nsy
        gps[e, k, G_SZ] = nsz
        gps[e, k, G_SXY] = nsxy
        gps[e, k, G_EPS] = ep
        fxx = nsx - p_new - qbv
        fyy = nsy - p_new - qbv
        pw += dj * (0.5 * (oxx + fxx) * dxx + 0.5 * (oyy + fyy) * dyy + (oxy + nsxy) * dxy)
        f1x += dj * (fxx * gx1 + nsxy * gy1)
        f2x += dj * (fxx * gx2 + nsxy * gy2)
        f3x += dj * (fxx * gx3 + nsxy * gy3)
        f4x += dj * (fxx * gx4 + nsxy * gy4)
        f1y += dj * (nsxy * gx1 + fyy * gy1)
        f2y += dj * (nsxy * gx2 + fyy * gy2)
        f3y += dj * (nsxy * gx3 + fyy * gy3)
        f4y += dj * (nsxy * gx4 + fyy * gy4)
        wsum += dj
        ssx += dj * nsx
        ssy += dj * nsy
        ssz += dj * nsz
        ssxy += dj * nsxy
        seps += dj * ep
    fex[e, 0] = f1x
    fex[e, 1] = f2x
    fex[e, 2] = f3x
    fex[e, 3] = f4x
    fey[e, 0] = f1y
    fey[e, 1] = f2y
    fey[e, 2] = f3y
    fey[e, 3] = f4y
    iw = 1.0 / wsum
    qs[QS_SDX, e] = ssx * iw
    qs[QS_SDY, e] = ssy * iw
    qs[QS_SDZ, e] = ssz * iw
    qs[QS_SDXY, e] = ssxy * iw
    qs[QS_EPS_P, e] = seps * iw
    rate[e] = srate * iw
    qs[QS_PRES, e] = p_new
    if wp_tot > 0.0:
        plast[e] += wp_tot
        qs[QS_TEMP, e] += beta * wp_tot / (rcp * A)
        qs[QS_DMG, e] += dd * iw
    ie[e] += dt * pw
    if dte_e < dt_erode:
        alive[e] = -1
    damage_erosion(e, conn, x, y, alive, layer, qs[QS_DMG, e], prm, erosion)
    return dte_e, False


quad_bbar = njit(cache=True, inline="always")(quad_bbar_py)


@njit(parallel=True, cache=True)
def element_update_bbar(nodes, quads, qs, out, gps, mat, prm, dt, erosion):
    """:func:`quad_bbar_py` over all elements (parallel); the groups and the result as
    :func:`robobore.cutting.fe.quad.element.element_update` (the rows ``qhx``/``qhy`` of
    ``qs`` and ``out.hge`` unused), ``gps`` the B-bar element's Gauss-point state."""
    # the prange body reads flat locals, one bound per statement (engine.groups2d)
    x = nodes.x
    y = nodes.y
    vx = nodes.vx
    vy = nodes.vy
    conn = quads.conn
    layer = quads.layer
    alive = quads.alive
    area0 = quads.area0
    ie = out.ie
    fex = out.fex
    fey = out.fey
    dte = out.dte
    plast = out.plast
    rate = out.rate
    ne = conn.shape[0]
    dtmin = 1e30
    bad = -1
    for e in prange(ne):
        d, inv = quad_bbar(e, conn, layer, area0, x, y, vx, vy, alive, qs, gps, ie, fex, fey,
                           dte, plast, rate, mat, prm, dt, erosion)
        dtmin = min(dtmin, d)
        if inv:
            bad = max(bad, e)
    return dtmin, bad
