"""The one-point quadrilateral of the plane-strain engine and its parallel element update.

Element: 4-node quadrilateral, one-point (centroid) integration -- no volumetric locking in
isochoric plastic flow -- with Flanagan-Belytschko (1981) hourglass control, viscous plus
stiffness (the stiffness part stored per element and co-rotated with the element spin).
Stress update: hypoelastic, Jaumann rate, Johnson-Cook radial return
(:func:`robobore.material.johnson_cook.radial_return`), adiabatic heating with the
Taylor-Quinney factor, Johnson-Cook damage, bulk viscosity (von Neumann-Richtmyer linear +
quadratic, in compression); element erosion by damage and by distortion.

Reference: Flanagan D.P., Belytschko T. (1981), "A uniform strain hexahedron and quadrilateral
with orthogonal hourglass control", IJNME 17, 679-706; Belytschko, Liu, Moran (2000),
*Nonlinear Finite Elements for Continua and Structures*, ch. 6.

``quad_element_py`` and its helpers are plain-Python scalar functions that allocate nothing;
:func:`element_update` calls their ``njit`` versions (``inline="always"``) over all elements
and :mod:`robobore.cutting.fe.engine.gpu.backend2d` compiles the same source for an NVIDIA GPU.
"""

from __future__ import annotations

import math

from numba import njit, prange

from robobore.cutting.fe.engine.groups2d import (
    QS_DMG,
    QS_EPS_P,
    QS_PRES,
    QS_QHX,
    QS_QHY,
    QS_SDX,
    QS_SDXY,
    QS_SDY,
    QS_SDZ,
    QS_TEMP,
)
from robobore.cutting.fe.engine.layout import (
    ERODE_LAYER,
    P_BV1,
    P_BV2,
    P_DIST,
    P_DT_ERODE,
    P_GATE,
    P_HGS,
    P_HGV,
    P_MS,
    P_NFX,
    P_NFY,
    P_NRX,
    P_NRY,
    P_R,
    P_TCX,
    P_TCY,
)
from robobore.cutting.fe.physics.tool_contact import tool_gap
from robobore.material import johnson_cook as jc
from robobore.material.johnson_cook import jc_damage_increment, radial_return


def quad_area_corners_py(x1, x2, x3, x4, y1, y2, y3, y4):
    """Area of a quad and its smallest corner Jacobian (twice the corner triangle area; all
    > 0 for a convex, counter-clockwise quad)."""
    A = 0.5 * ((x3 - x1) * (y4 - y2) + (x2 - x4) * (y3 - y1))
    c1 = (x2 - x1) * (y4 - y1) - (y2 - y1) * (x4 - x1)
    c2 = (x3 - x2) * (y1 - y2) - (y3 - y2) * (x1 - x2)
    c3 = (x4 - x3) * (y2 - y3) - (y4 - y3) * (x2 - x3)
    c4 = (x1 - x4) * (y3 - y4) - (y1 - y4) * (x3 - x4)
    return A, min(min(c1, c2), min(c3, c4))


def quad_retire_py(e, fex, fey, dte):
    """Zero the nodal forces of element ``e`` and give it an infinite stable step."""
    for k in range(4):
        fex[e, k] = 0.0
        fey[e, k] = 0.0
    dte[e] = 1e30


def make_quad_distorted(quad_retire):
    """:func:`quad_distorted_py` with its callees ``quad_retire`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def quad_distorted_py(e, alive, fex, fey, dte, area0, A, cmin, dlim):
        """True (and the element retired) when quad ``e`` is inverted (``alive`` = -2: an error
        unless the distortion limit caught it) or below the distortion limit (-1)."""
        if cmin <= 0.0 or A <= 0.0 or cmin < dlim * area0[e] or A < dlim * area0[e]:
            alive[e] = -1 if (dlim > 0.0 and A > 0.0) else -2
            quad_retire(e, fex, fey, dte)
            return True
        return False

    return quad_distorted_py


def quad_bvectors_py(x1, x2, x3, x4, y1, y2, y3, y4, A):
    """Centroid gradients b_I = dN_I/dx, dN_I/dy of the bilinear quad (= their area means;
    Flanagan & Belytschko 1981)."""
    inv2a = 0.5 / A
    return ((y2 - y4) * inv2a, (y3 - y1) * inv2a, (y4 - y2) * inv2a, (y1 - y3) * inv2a,
            (x4 - x2) * inv2a, (x1 - x3) * inv2a, (x2 - x4) * inv2a, (x3 - x1) * inv2a)


def quad_step_py(rho_s, a0, A, K, G, bsum, trd, bv1, bv2):
    """Current density, wave speed, bulk-viscosity pressure and stable step of a quad.

    ``rho_s`` scaled density, ``a0``/``A`` initial/current area, ``bsum`` = sum b_I . b_I
    (element length 1/sqrt(bsum)), ``trd`` the dilatation rate; the bulk viscosity (linear
    ``bv1``, quadratic ``bv2``) acts in compression only. Returns ``(rho_c, c, qbv, dte)``.
    """
    rho_c = rho_s * a0 / A
    c = math.sqrt((K + 4.0 * G / 3.0) / rho_c)
    le = 1.0 / math.sqrt(bsum)
    qbv = 0.0
    qrate = 0.0
    if trd < 0.0:
        qrate = bv1 * c + bv2 * le * (-trd)
        qbv = rho_c * le * qrate * (-trd)
    return rho_c, c, qbv, le / (qrate + math.sqrt(qrate * qrate + c * c))


def make_damage_erosion(tool_gap):
    """:func:`damage_erosion_py` with its callees ``tool_gap`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def damage_erosion_py(e, conn, x, y, alive, layer, damage, prm, erosion):
        """Erode quad ``e`` of the separation layer once its Johnson-Cook ``damage`` reached 1
        (``erosion`` = ERODE_LAYER; optionally only with a node within ``prm[P_GATE]`` of the
        tool)."""
        if damage >= 1.0 and erosion == ERODE_LAYER and layer[e]:
            gate = prm[P_GATE]
            if gate < 0.0:
                alive[e] = 0
            else:
                gmin = 1e30
                for k in range(4):
                    nk = conn[e, k]
                    g, _gx, _gy = tool_gap(x[nk], y[nk], prm[P_TCX], prm[P_TCY], prm[P_NRX],
                                           prm[P_NRY], prm[P_NFX], prm[P_NFY], prm[P_R])
                    if g < gmin:
                        gmin = g
                if gmin <= gate:
                    alive[e] = 0

    return damage_erosion_py


quad_area_corners = njit(cache=True, inline="always")(quad_area_corners_py)
quad_retire = njit(cache=True, inline="always")(quad_retire_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
quad_distorted_py = make_quad_distorted(quad_retire)
quad_distorted = njit(cache=False, inline="always")(quad_distorted_py)
quad_bvectors = njit(cache=True, inline="always")(quad_bvectors_py)
quad_step = njit(cache=True, inline="always")(quad_step_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
damage_erosion_py = make_damage_erosion(tool_gap)
damage_erosion = njit(cache=False, inline="always")(damage_erosion_py)


def make_quad_element(radial_return, jc_damage_increment, quad_retire, quad_area_corners,
                      quad_distorted, quad_bvectors, quad_step, damage_erosion):
    """:func:`quad_element_py` with its callees ``radial_return``, ``jc_damage_increment``,
    ``quad_retire``, ``quad_area_corners``, ``quad_distorted``, ``quad_bvectors``,
    ``quad_step``, ``damage_erosion`` given (the CPU's compiled functions here, a GPU
    engine's device functions in its port)"""

    def quad_element_py(e, conn, layer, area0, x, y, vx, vy, alive, qs, ie, hge, fex, fey, dte,
                        plast, rate, mat, prm, dt, erosion):
        """Stress update and nodal forces of quad ``e`` (one element, scalar code).

        Reads the quads' corners, layer flags and reference areas, the nodes' positions [m]
        and velocities [m/s], the material and parameter vectors, the step ``dt`` [s] and the
        erosion mode; updates the element state ``qs``
        (:data:`~robobore.cutting.fe.engine.groups2d.QS_FIELDS` rows), ``alive`` and the
        outputs of :data:`~robobore.cutting.fe.engine.groups2d.QuadOut2` at ``e``. The
        arguments come one by one: the same function reading its read-only arrays from
        tuples built at the call ran the element pass about 1-2 % slower
        (``benchmarks/measured/fe_before_after/qs_tuples_2d_paired.txt``).

        The whole per-element update of :func:`element_update`: kinematics at the new
        configuration, Jaumann rotation, elastic trial, Johnson-Cook radial return, adiabatic
        heating, damage, bulk viscosity, stable step, internal energy, Flanagan-Belytschko
        hourglass forces, erosion (damage, optionally gated by the tool distance; distortion;
        time step). Reads and writes array elements only and allocates nothing, so the same
        source is compiled for the CPU (:data:`quad_element`) and for a GPU
        (:func:`make_quad_element` given device versions of its callees, then
        ``numba.cuda.jit(device=True)``, in :mod:`robobore.cutting.fe.engine.gpu.device2d`).

        Returns ``(dte, inverted)``: the element's stable step [s] (1e30 when it is not alive or
        was just eroded by distortion) and whether it just turned inside out (``alive`` = -2).
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
        hgv = prm[P_HGV]
        hgs = prm[P_HGS]
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
        bx1, bx2, bx3, bx4, by1, by2, by3, by4 = quad_bvectors(x1, x2, x3, x4, y1, y2, y3, y4, A)
        u1, u2, u3, u4 = vx[i1], vx[i2], vx[i3], vx[i4]
        w1, w2, w3, w4 = vy[i1], vy[i2], vy[i3], vy[i4]
        dvxdx = u1 * bx1 + u2 * bx2 + u3 * bx3 + u4 * bx4
        dvxdy = u1 * by1 + u2 * by2 + u3 * by3 + u4 * by4
        dvydx = w1 * bx1 + w2 * bx2 + w3 * bx3 + w4 * bx4
        dvydy = w1 * by1 + w2 * by2 + w3 * by3 + w4 * by4
        dxx = dvxdx
        dyy = dvydy
        dxy = 0.5 * (dvxdy + dvydx)
        spin = 0.5 * (dvxdy - dvydx)
        trd = dxx + dyy
        # old total stress (for the midpoint stress power)
        p_old = qs[QS_PRES, e]
        oxx = qs[QS_SDX, e] - p_old
        oyy = qs[QS_SDY, e] - p_old
        oxy = qs[QS_SDXY, e]
        # Jaumann rotation of the deviatoric stress (zz unaffected in plane strain)
        sx = qs[QS_SDX, e]
        sy = qs[QS_SDY, e]
        sxy = qs[QS_SDXY, e]
        rs = dt * spin
        sx_r = sx + 2.0 * rs * sxy
        sy_r = sy - 2.0 * rs * sxy
        sxy_r = sxy + rs * (sy - sx)
        # elastic trial
        tr3 = trd * dt / 3.0
        tx = sx_r + 2.0 * G * (dxx * dt - tr3)
        ty = sy_r + 2.0 * G * (dyy * dt - tr3)
        tz = qs[QS_SDZ, e] + 2.0 * G * (-tr3)
        txy = sxy_r + 2.0 * G * dxy * dt
        p_new = p_old - K * trd * dt
        nsx, nsy, nsz, nsxy, dep, syld = radial_return(tx, ty, tz, txy, qs[QS_EPS_P, e],
                                                       qs[QS_TEMP, e], dt, G, a_, b_, n_, c_,
                                                       m_, e0, tr_, tm_, eh_)
        if dep > 0.0:
            qs[QS_EPS_P, e] += dep
            rate[e] = dep / dt
            wp = syld * dep
            plast[e] += wp * A
            qs[QS_TEMP, e] += beta * wp / rcp
            q = syld
            if q > 0.0:
                triax = -p_new / q
            else:
                triax = 0.0
            qs[QS_DMG, e] += jc_damage_increment(dep, triax, dep / dt, qs[QS_TEMP, e],
                                                 mat[jc.D1], mat[jc.D2], mat[jc.D3], mat[jc.D4],
                                                 mat[jc.D5], e0, tr_, tm_)
        else:
            rate[e] = 0.0
        qs[QS_SDX, e] = nsx
        qs[QS_SDY, e] = nsy
        qs[QS_SDZ, e] = nsz
        qs[QS_SDXY, e] = nsxy
        qs[QS_PRES, e] = p_new
        # bulk viscosity (compression only) and stable step
        bsum = (bx1 * bx1 + bx2 * bx2 + bx3 * bx3 + bx4 * bx4
                + by1 * by1 + by2 * by2 + by3 * by3 + by4 * by4)
        rho_c, c, qbv, dte_e = quad_step(rho_s, area0[e], A, K, G, bsum, trd, bv1, bv2)
        dte[e] = dte_e
        if dte_e < dt_erode:
            # time-step erosion (LS-DYNA *CONTROL_TIMESTEP ERODE-type): a crushed/sheared
            # element whose stable step fell below the floor is deleted
            alive[e] = -1
        fxx = nsx - p_new - qbv
        fyy = nsy - p_new - qbv
        # stress power (midpoint) -> internal energy
        ie[e] += A * dt * (0.5 * (oxx + fxx) * dxx + 0.5 * (oyy + fyy) * dyy
                           + (oxy + nsxy) * dxy)
        # hourglass (Flanagan-Belytschko): gamma vectors for h = (1, -1, 1, -1)
        hx = x1 - x2 + x3 - x4
        hy = y1 - y2 + y3 - y4
        g1 = 0.25 * (1.0 - hx * bx1 - hy * by1)
        g2 = 0.25 * (-1.0 - hx * bx2 - hy * by2)
        g3 = 0.25 * (1.0 - hx * bx3 - hy * by3)
        g4 = 0.25 * (-1.0 - hx * bx4 - hy * by4)
        qx = g1 * u1 + g2 * u2 + g3 * u3 + g4 * u4
        qy = g1 * w1 + g2 * w2 + g3 * w3 + g4 * w4
        # stiffness part: stored, co-rotated, rate-form
        hsx = qs[QS_QHX, e]
        hsy = qs[QS_QHY, e]
        hsx, hsy = hsx + rs * hsy, hsy - rs * hsx
        kh = hgs * G * A * bsum
        hsx += dt * kh * qx
        hsy += dt * kh * qy
        qs[QS_QHX, e] = hsx
        qs[QS_QHY, e] = hsy
        cv = 2.0 * hgv * rho_c * c * math.sqrt(A)
        Qx = hsx + cv * qx
        Qy = hsy + cv * qy
        hge[e] += dt * (Qx * qx + Qy * qy)
        fex[e, 0] = A * (fxx * bx1 + nsxy * by1) + Qx * g1
        fex[e, 1] = A * (fxx * bx2 + nsxy * by2) + Qx * g2
        fex[e, 2] = A * (fxx * bx3 + nsxy * by3) + Qx * g3
        fex[e, 3] = A * (fxx * bx4 + nsxy * by4) + Qx * g4
        fey[e, 0] = A * (nsxy * bx1 + fyy * by1) + Qy * g1
        fey[e, 1] = A * (nsxy * bx2 + fyy * by2) + Qy * g2
        fey[e, 2] = A * (nsxy * bx3 + fyy * by3) + Qy * g3
        fey[e, 3] = A * (nsxy * bx4 + fyy * by4) + Qy * g4
        # erosion by Johnson-Cook damage (in the layer optionally only at the tool's edge)
        damage_erosion(e, conn, x, y, alive, layer, qs[QS_DMG, e], prm, erosion)
        return dte_e, False

    return quad_element_py


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
quad_element_py = make_quad_element(radial_return, jc_damage_increment, quad_retire,
                                    quad_area_corners, quad_distorted, quad_bvectors,
                                    quad_step, damage_erosion)
quad_element = njit(cache=False, inline="always")(quad_element_py)


@njit(parallel=True, cache=True)
def element_update(nodes, quads, qs, out, mat, prm, dt, erosion):
    """Stress update and element nodal forces at the new configuration.

    The groups of :mod:`robobore.cutting.fe.engine.groups2d`: ``nodes`` (Nodes2), ``quads``
    (Quads2), ``qs`` the element state (N_QS, e), ``out`` (QuadOut2); ``mat`` the material
    vector, ``prm`` the parameter vector, ``dt`` the step [s], ``erosion`` the erosion mode.
    Returns ``(dtmin, bad)``: the smallest element stable step [s] (1e30 when no element is
    alive) and the largest index of an inverted element (-1: none).
    Writes ``fex``/``fey`` (n_elem, 4) internal nodal forces [N/m], ``dte`` (n_elem,) the
    element stable step [s], ``ie`` internal energy per element [J/m] (cumulative),
    ``plast`` plastic work per element [J/m], ``hge`` hourglass work [J/m]. Erodes
    elements (``alive`` = 0 damage, -1 distortion).
    """
    # the prange body reads flat locals, one bound per statement (engine.groups2d)
    x = nodes.x
    y = nodes.y
    vx = nodes.vx
    vy = nodes.vy
    conn = quads.conn
    layer = quads.layer
    alive = quads.alive
    area0 = quads.area0
    ie, hge, fex, fey, dte, plast, rate = (out.ie, out.hge, out.fex, out.fey, out.dte,
                                           out.plast, out.rate)
    ne = conn.shape[0]
    dtmin = 1e30
    bad = -1
    for e in prange(ne):
        d, inv = quad_element(e, conn, layer, area0, x, y, vx, vy, alive, qs, ie, hge, fex,
                              fey, dte, plast, rate, mat, prm, dt, erosion)
        dtmin = min(dtmin, d)
        if inv:
            bad = max(bad, e)
    return dtmin, bad
