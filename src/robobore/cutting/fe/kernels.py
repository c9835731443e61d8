"""Numba kernels of the explicit plane-strain cutting engine (SI units, per unit width).

Element: 4-node quadrilateral, one-point (centroid) integration -- no volumetric locking in
isochoric plastic flow -- with Flanagan-Belytschko (1981) hourglass control, viscous plus
stiffness (the stiffness part stored per element and co-rotated with the element spin).
Stress update: hypoelastic, Jaumann rate, Johnson-Cook radial return
(:func:`robobore.material.johnson_cook.radial_return`), adiabatic heating with the
Taylor-Quinney factor, Johnson-Cook damage, bulk viscosity (von Neumann-Richtmyer linear +
quadratic, in compression). Time integration: central difference, lumped mass.

Reference: Flanagan D.P., Belytschko T. (1981), "A uniform strain hexahedron and quadrilateral
with orthogonal hourglass control", IJNME 17, 679-706; Belytschko, Liu, Moran (2000),
*Nonlinear Finite Elements for Continua and Structures*, ch. 6 (explicit, stable step,
energy balance).

The per-element, per-node, conduction and tool updates are plain-Python scalar functions
(``quad_element_py``, ``quad_node_py``, ``quad_centroid_py``, ``quad_conduct_py``,
``tool_kinematics_py``, ``tool_step_py``, ``sum_energies_py``) that allocate nothing; the CPU
loops below call their ``njit`` versions (``inline="always"``: the compiled loops are those of
inline code) and keep the reductions, and :mod:`robobore.cutting.fe.gpu2d` compiles the same
source for an NVIDIA GPU.

Layout of the small state arrays (indices are module constants):
``prm`` float64 parameters, ``tool`` float64 tool state, ``en`` float64 energy accumulators,
``ist`` int64 counters/status, ``hist`` (n_samples, N_HIST) time-averaged histories.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from robobore.cutting.fe.physics import (
    contact_force,
    jc_damage_increment,
    radial_return,
    tool_face,
    tool_gap,
    tool_support_step,
)
from robobore.cutting.fe.rezone import rezone
from robobore.material import johnson_cook as jc

# --- prm indices (float parameters)
P_CFL, P_MS, P_HGV, P_HGS, P_BV1, P_BV2, P_DIST = 0, 1, 2, 3, 4, 5, 6
P_MU, P_TAU, P_PEN, P_R = 7, 8, 9, 10
P_NRX, P_NRY, P_NFX, P_NFY = 11, 12, 13, 14
P_VC, P_KX, P_KY, P_CX, P_CY, P_MX, P_MY, P_WIDTH = 15, 16, 17, 18, 19, 20, 21, 22
P_SAMPLE_DT, P_DTMIN, P_TEND, P_EROSION, P_SUPPORT = 23, 24, 25, 26, 27
P_RZ_EVERY, P_RZ_OMEGA, P_RZ_MAXMOVE, P_DT_ERODE = 28, 29, 30, 31
#: separation gate [m] (a layer element erodes only with a node within this distance of the
#: tool surface; < 0: no gate) and the current tool edge centre (set every step)
P_GATE, P_TCX, P_TCY = 32, 33, 34
#: heat conduction: steps between conduction updates (0: adiabatic), time accumulated since
#: the last one [s]
P_COND_EVERY, P_COND_ACC = 35, 36
#: element formulation: ELEM_Q4R (one-point quad + hourglass control) or ELEM_Q4BBAR (2x2
#: Gauss points with mean-dilatation B-bar, no hourglass modes)
P_ELEM = 37
#: thermal contact with the tool (heat conduction runs only): interface conductance
#: [W/(m^2 K)] to a tool held at ``P_TTOOL`` [K], and the fraction of the frictional
#: dissipation that heats the workpiece (the rest goes into the tool)
P_HC, P_FHEAT, P_TTOOL = 38, 39, 40
#: node relocation of the rezoning passes (rezone.MODE_LAPLACE or rezone.MODE_ROWS)
P_RZ_MODE = 41
#: tool-frame ALE: the tool edge centre's x at the start [m] (the mesh travels with the tool)
P_ALE_X0 = 42
#: viscous contact damping, fraction of the contact spring's critical damping
P_CDAMP = 43
#: friction vs sliding velocity (``contact.friction_velocity = "sliding"``): number of table
#: points (0: the constant ``P_MU``), then MU_TABLE_MAX velocities [m/s] (increasing) and
#: MU_TABLE_MAX coefficients; each contact node uses the table at its own sliding speed
P_MUTAB_N = 44
MU_TABLE_MAX = 8
P_MUTAB_V = 45
P_MUTAB_MU = P_MUTAB_V + MU_TABLE_MAX
#: time constant [s] of the filter on the sliding speed the friction table is read at
P_SLIP_TAU = P_MUTAB_MU + MU_TABLE_MAX
N_PRM = P_SLIP_TAU + 1
ELEM_Q4R, ELEM_Q4BBAR = 0, 1
#: per-Gauss-point state of the B-bar element: deviatoric stress xx, yy, zz, xy, plastic strain
G_SX, G_SY, G_SZ, G_SXY, G_EPS = 0, 1, 2, 3, 4
N_GPS = 5
# erosion modes
ERODE_NONE, ERODE_LAYER, ERODE_ALL = 0, 1, 2
# --- tool state: guide x, y; displacement u, v; velocity of displacement; force
T_GX, T_GY, T_UX, T_UY, T_VUX, T_VUY, T_FX, T_FY = 0, 1, 2, 3, 4, 5, 6, 7
N_TOOL = 8
# --- energies
E_EXT, E_KIN, E_INT, E_PLAST, E_HG, E_FRIC, E_NODEWORK, E_ERODED, E_EROKE = range(9)
N_EN = 9
# --- int state
I_STEP, I_SAMPLE, I_STATUS, I_ERODED_DAMAGE, I_ERODED_DIST, I_BADELEM = 0, 1, 2, 3, 4, 5
N_IST = 6
STATUS_OK, STATUS_NONFINITE, STATUS_DT_COLLAPSE, STATUS_DONE, STATUS_INVERTED = 0, 1, 2, 3, 4
STATUS_NO_ELEMENTS = 5
# --- history columns (time averages over each sample interval)
H_T, H_FX, H_FY, H_UX, H_UY, H_TIP_X, H_EKIN, H_EINT, H_EPL, H_EHG, H_EFRIC, H_EEXT = range(12)
H_EERO, H_NCONT = 12, 13
# force on the tool by face (rake, edge arc, flank), x and y [N/m]; CPU engine only (the GPU
# engine leaves these columns NaN)
H_FX_RAKE, H_FY_RAKE, H_FX_EDGE, H_FY_EDGE, H_FX_FLANK, H_FY_FLANK = range(14, 20)
N_HIST = 20
#: names of the tool faces of that split, in column order (summary ``force_by_face_N_per_mm``)
FACES = ("rake", "edge", "flank")


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


def quad_distorted_py(e, alive, fex, fey, dte, area0, A, cmin, dlim):
    """True (and the element retired) when quad ``e`` is inverted (``alive`` = -2: an error
    unless the distortion limit caught it) or below the distortion limit (-1)."""
    if cmin <= 0.0 or A <= 0.0 or cmin < dlim * area0[e] or A < dlim * area0[e]:
        alive[e] = -1 if (dlim > 0.0 and A > 0.0) else -2
        quad_retire(e, fex, fey, dte)
        return True
    return False


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


def damage_erosion_py(e, conn, x, y, alive, layer, dmg, prm, erosion):
    """Erode quad ``e`` once its Johnson-Cook damage reached 1 (everywhere, or in the
    separation layer; there optionally only with a node within ``prm[P_GATE]`` of the tool)."""
    if dmg[e] >= 1.0 and (erosion == ERODE_ALL or (erosion == ERODE_LAYER and layer[e])):
        gate = prm[P_GATE]
        if gate < 0.0 or not layer[e]:
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


quad_area_corners = njit(cache=True, inline="always")(quad_area_corners_py)
quad_retire = njit(cache=True, inline="always")(quad_retire_py)
quad_distorted = njit(cache=True, inline="always")(quad_distorted_py)
quad_bvectors = njit(cache=True, inline="always")(quad_bvectors_py)
quad_step = njit(cache=True, inline="always")(quad_step_py)
damage_erosion = njit(cache=True, inline="always")(damage_erosion_py)


def quad_element_py(e, conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres, eps_p,
                    temp, dmg, qhx, qhy, area0, ie, hge, fex, fey, dte, plast, rate, mat, prm, dt,
                    erosion):
    """Stress update and nodal forces of quad ``e`` (one element, scalar code).

    The whole per-element update of :func:`element_update`: kinematics at the new
    configuration, Jaumann rotation, elastic trial, Johnson-Cook radial return, adiabatic
    heating, damage, bulk viscosity, stable step, internal energy, Flanagan-Belytschko
    hourglass forces, erosion (damage, optionally gated by the tool distance; distortion;
    time step). Reads and writes array elements only and allocates nothing, so the same
    source is compiled for the CPU (:data:`quad_element`) and for a GPU
    (``numba.cuda.jit(device=True)`` after :func:`robobore.material.johnson_cook.rebind`,
    in :mod:`robobore.cutting.fe.gpu2d`).

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
    p_old = pres[e]
    oxx = sdx[e] - p_old
    oyy = sdy[e] - p_old
    oxy = sdxy[e]
    # Jaumann rotation of the deviatoric stress (zz unaffected in plane strain)
    sx = sdx[e]
    sy = sdy[e]
    sxy = sdxy[e]
    rs = dt * spin
    sx_r = sx + 2.0 * rs * sxy
    sy_r = sy - 2.0 * rs * sxy
    sxy_r = sxy + rs * (sy - sx)
    # elastic trial
    tr3 = trd * dt / 3.0
    tx = sx_r + 2.0 * G * (dxx * dt - tr3)
    ty = sy_r + 2.0 * G * (dyy * dt - tr3)
    tz = sdz[e] + 2.0 * G * (-tr3)
    txy = sxy_r + 2.0 * G * dxy * dt
    p_new = p_old - K * trd * dt
    nsx, nsy, nsz, nsxy, dep, syld = radial_return(tx, ty, tz, txy, eps_p[e], temp[e], dt,
                                                   G, a_, b_, n_, c_, m_, e0, tr_, tm_, eh_)
    if dep > 0.0:
        eps_p[e] += dep
        rate[e] = dep / dt
        wp = syld * dep
        plast[e] += wp * A
        temp[e] += beta * wp / rcp
        q = syld
        if q > 0.0:
            triax = -p_new / q
        else:
            triax = 0.0
        dmg[e] += jc_damage_increment(dep, triax, dep / dt, temp[e], mat[jc.D1],
                                      mat[jc.D2], mat[jc.D3], mat[jc.D4], mat[jc.D5],
                                      e0, tr_, tm_)
    else:
        rate[e] = 0.0
    sdx[e] = nsx
    sdy[e] = nsy
    sdz[e] = nsz
    sdxy[e] = nsxy
    pres[e] = p_new
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
    hsx = qhx[e]
    hsy = qhy[e]
    hsx, hsy = hsx + rs * hsy, hsy - rs * hsx
    kh = hgs * G * A * bsum
    hsx += dt * kh * qx
    hsy += dt * kh * qy
    qhx[e] = hsx
    qhy[e] = hsy
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
    damage_erosion(e, conn, x, y, alive, layer, dmg, prm, erosion)
    return dte_e, False


quad_element = njit(cache=True, inline="always")(quad_element_py)


@njit(parallel=True, cache=True)
def element_update(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres, eps_p, temp,
                   dmg, qhx, qhy, area0, ie, hge, fex, fey, dte, plast, rate, mat, prm, dt,
                   erosion):
    """Stress update and element nodal forces at the new configuration.

    Returns ``(dtmin, bad)``: the smallest element stable step [s] (1e30 when no element is
    alive) and the largest index of an inverted element (-1: none).
    Writes ``fex``/``fey`` (n_elem, 4) internal nodal forces [N/m], ``dte`` (n_elem,) the
    element stable step [s], ``ie`` internal energy per element [J/m] (cumulative),
    ``plast`` plastic work per element [J/m], ``hge`` hourglass work [J/m]. Erodes
    elements (``alive`` = 0 damage, -1 distortion).
    """
    ne = conn.shape[0]
    dtmin = 1e30
    bad = -1
    for e in prange(ne):
        d, inv = quad_element(e, conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres,
                              eps_p, temp, dmg, qhx, qhy, area0, ie, hge, fex, fey, dte, plast,
                              rate, mat, prm, dt, erosion)
        dtmin = min(dtmin, d)
        if inv:
            bad = max(bad, e)
    return dtmin, bad


def quad_bbar_py(e, conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres, eps_p,
                 temp, dmg, gps, area0, ie, fex, fey, dte, plast, rate, mat, prm, dt, erosion):
    """Fully integrated quad ``e`` with mean-dilatation B-bar (scalar code, allocates nothing).

    Four Gauss points (2x2) each carry their own deviatoric stress and plastic strain
    (``gps[e, k, G_*]``); the pressure is one per element, from the element's mean
    dilatation rate (the centroid b-vectors of the one-point element are exactly the
    area-averaged shape-function gradients of the bilinear quad), so there is no volumetric
    locking in isochoric plastic flow (Nagtegaal, Parks & Rice 1974; Hughes 1980 "B-bar") and
    no hourglass mode at all: hourglass-shaped deformation strains the Gauss points, which
    resist it with the material's own (elastic or plastic) response. The temperature and the
    damage stay one per element (Gauss-point plastic work and damage increments are
    area-weighted); ``sdx``, ``sdy``, ``sdz``, ``sdxy``, ``eps_p`` and ``rate`` receive the
    area-weighted Gauss-point means (for the outputs, conduction and erosion).

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
    p_old = pres[e]
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
    t_e = temp[e]
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
    sdx[e] = ssx * iw
    sdy[e] = ssy * iw
    sdz[e] = ssz * iw
    sdxy[e] = ssxy * iw
    eps_p[e] = seps * iw
    rate[e] = srate * iw
    pres[e] = p_new
    if wp_tot > 0.0:
        plast[e] += wp_tot
        temp[e] += beta * wp_tot / (rcp * A)
        dmg[e] += dd * iw
    ie[e] += dt * pw
    if dte_e < dt_erode:
        alive[e] = -1
    damage_erosion(e, conn, x, y, alive, layer, dmg, prm, erosion)
    return dte_e, False


quad_bbar = njit(cache=True, inline="always")(quad_bbar_py)


@njit(parallel=True, cache=True)
def element_update_bbar(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres, eps_p,
                        temp, dmg, gps, area0, ie, fex, fey, dte, plast, rate, mat, prm, dt,
                        erosion):
    """:func:`quad_bbar_py` over all elements (parallel); returns ``(dtmin, bad)`` as
    :func:`element_update`."""
    ne = conn.shape[0]
    dtmin = 1e30
    bad = -1
    for e in prange(ne):
        d, inv = quad_bbar(e, conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy, pres,
                           eps_p, temp, dmg, gps, area0, ie, fex, fey, dte, plast, rate, mat,
                           prm, dt, erosion)
        dtmin = min(dtmin, d)
        if inv:
            bad = max(bad, e)
    return dtmin, bad


def friction_at_py(prm, speed):
    """Coulomb coefficient at the sliding speed ``speed`` [m/s] (>= 0).

    ``prm[P_MUTAB_N]`` = 0: the constant ``prm[P_MU]``; otherwise the table in
    ``prm[P_MUTAB_V:]`` / ``prm[P_MUTAB_MU:]``, linear between its points and constant beyond
    its ends (as Abaqus' slip-rate-dependent friction tables).
    """
    n = int(prm[P_MUTAB_N])
    if n == 0:
        return prm[P_MU]
    if speed <= prm[P_MUTAB_V]:
        return prm[P_MUTAB_MU]
    for i in range(1, n):
        v1 = prm[P_MUTAB_V + i]
        if speed <= v1:
            v0 = prm[P_MUTAB_V + i - 1]
            m0 = prm[P_MUTAB_MU + i - 1]
            return m0 + (prm[P_MUTAB_MU + i] - m0) * (speed - v0) / (v1 - v0)
    return prm[P_MUTAB_MU + n - 1]


friction_at = njit(cache=True, inline="always")(friction_at_py)


def quad_node_py(n, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0, fex, fey,
                 cfx, cfy, fric, pen, ndead, ero_ke, nwork, tool_cx, tool_cy, tool_vx,
                 tool_vy, prm, dt, twin, tied, vslip):
    """Gather element forces on node ``n``, add tool contact, advance its velocity and position.

    One node of :func:`node_update` (scalar code, allocates nothing: compiled for the CPU as
    :data:`quad_node` and for a GPU in :mod:`robobore.cutting.fe.gpu2d`). Returns
    ``(fx, fy, touched)``: this node's contact force on the workpiece [N/m] (``cfx[n]``,
    ``cfy[n]``) and whether it touched the tool. Contact uses positions at step n and
    velocities at n-1/2; ``cfx``/``cfy`` receive the contact force on the node [N/m]; ``fric``
    (cumulative) the frictional dissipation and the contact damping's, ``pen`` the current
    penalty energy, ``nwork``
    (cumulative) the contact work on the node [J/m]. A node left without a live element is
    retired (velocity zeroed, its kinetic energy booked in ``ero_ke``).

    Node splitting: a node with ``twin[n] >= 0`` and ``tied[n]`` moves with its twin as one
    node (forces and masses of both, summed in a fixed order so that both copies stay
    bitwise identical; the contact force is shared half and half). The pair is released
    (``tied`` = 0) when it comes within ``prm[P_GATE]`` of the tool surface: the material
    separates where it meets the cutting edge.

    Friction: the constant ``prm[P_MU]``, or with a table (``prm[P_MUTAB_N]`` > 0) the
    table at the node's sliding speed relative to the tool, low-pass filtered with the time
    constant ``prm[P_SLIP_TAU]`` and kept in ``vslip[n]`` [m/s] (:func:`friction_at_py`).
    """
    r = prm[P_R]
    nrx, nry, nfx, nfy = prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY]
    tau, pf = prm[P_TAU], prm[P_PEN]
    gate = prm[P_GATE]
    cfx[n] = 0.0
    cfy[n] = 0.0
    pen[n] = 0.0
    if ndead[n]:
        return 0.0, 0.0, False
    tw = twin[n]
    pair = tw >= 0 and tied[n] != 0
    # node ids as int64 (the prange index is unsigned: mixing would give floats); a
    # tied pair is gathered in a fixed order so that both copies compute the same sums
    na = np.int64(n)
    nb = np.int64(-1)
    share = 1.0
    if pair:
        nb = max(na, tw)
        na = min(na, tw)
        share = 0.5
    fx = 0.0
    fy = 0.0
    nlive = 0
    asum = 0.0
    m = 0.0
    for j in range(2):
        nk = na if j == 0 else nb
        if nk < 0:
            continue
        m += mass[nk]
        for k in range(ptr[nk], ptr[nk + 1]):
            e = nel[k]
            if alive[e] == 1:
                c = ncorner[k]
                fx -= fex[e, c]
                fy -= fey[e, c]
                nlive += 1
                asum += area0[e]
    if nlive == 0:
        ndead[n] = 1
        ero_ke[n] = 0.5 * mass[n] * (vx[n] * vx[n] + vy[n] * vy[n])
        vx[n] = 0.0
        vy[n] = 0.0
        return 0.0, 0.0, False
    if fixed[n]:
        vx[n] = 0.0
        vy[n] = 0.0
        return 0.0, 0.0, False
    gap, gnx, gny = tool_gap(x[n], y[n], tool_cx, tool_cy, nrx, nry, nfx, nfy, r)
    if pair and gap <= gate:
        tied[n] = 0
    fcx = 0.0
    fcy = 0.0
    ft = 0.0
    fd = 0.0
    vt0 = 0.0
    vn0 = 0.0
    if gap < 0.0:
        vrx = vx[n] - tool_vx
        vry = vy[n] - tool_vy
        trib = math.sqrt(asum / nlive)
        vt0 = -vrx * gny + vry * gnx
        mu = prm[P_MU]
        if prm[P_MUTAB_N] > 0.0:
            # the sliding speed, filtered over the time constant prm[P_SLIP_TAU]: a contact
            # node's velocity chatters from step to step, its mean is the material's sliding
            tau_s = prm[P_SLIP_TAU]
            a = dt / tau_s if tau_s > dt else 1.0  # tau_s <= dt: no filter
            vs = vslip[n] + a * (abs(vt0) - vslip[n])
            vslip[n] = vs
            mu = friction_at(prm, vs)
        fcx, fcy, fn, ft, fd = contact_force(gap, gnx, gny, vrx, vry, m, trib, mu, tau, pf,
                                             dt, prm[P_CDAMP], fx, fy)
        vn0 = vrx * gnx + vry * gny
        pen[n] = share * 0.5 * (fn - fd) * (-gap)
    cfx[n] = share * fcx
    cfy[n] = share * fcy
    touched = fcx != 0.0 or fcy != 0.0
    ox = vx[n]
    oy = vy[n]
    nvx = ox + dt * (fx + fcx) / m
    nvy = oy + dt * (fy + fcy) / m
    vx[n] = nvx
    vy[n] = nvy
    x[n] += dt * nvx
    y[n] += dt * nvy
    if gap < 0.0:
        nwork[n] += share * dt * (fcx * 0.5 * (ox + nvx) + fcy * 0.5 * (oy + nvy))
        vt1 = -(nvx - tool_vx) * gny + (nvy - tool_vy) * gnx
        fric[n] -= share * dt * ft * 0.5 * (vt0 + vt1)
        if fd != 0.0:  # contact damping: booked with the frictional dissipation
            vn1 = (nvx - tool_vx) * gnx + (nvy - tool_vy) * gny
            fric[n] -= share * dt * fd * 0.5 * (vn0 + vn1)
    return share * fcx, share * fcy, touched


quad_node = njit(cache=True, inline="always")(quad_node_py)


@njit(parallel=True, cache=True)
def node_update(x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0, fex, fey,
                cfx, cfy, fric, pen, ndead, ero_ke, nwork, tool_cx, tool_cy, tool_vx, tool_vy,
                prm, dt, twin, tied, vslip):
    """:func:`quad_node_py` over all nodes (parallel).

    Returns the number of nodes in contact; their contact forces are in ``cfx``/``cfy``
    (summed in a fixed order by :func:`contact_total`).
    """
    ncont = 0
    for n in prange(x.shape[0]):
        _fcx, _fcy, touched = quad_node(n, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive,
                                        area0, fex, fey, cfx, cfy, fric, pen, ndead, ero_ke,
                                        nwork, tool_cx, tool_cy, tool_vx, tool_vy, prm, dt,
                                        twin, tied, vslip)
        if touched:
            ncont += 1
    return ncont


#: lanes of the fixed-order contact-force total (one GPU block of this many threads)
N_SUM_LANES = 256


def lane_sum_py(a, lane, lanes):
    """Sum of ``a[lane], a[lane + lanes], ...`` in index order (one lane of
    :func:`contact_total_py`)."""
    s = 0.0
    for n in range(lane, a.shape[0], lanes):
        s += a[n]
    return s


lane_sum = njit(cache=True, inline="always")(lane_sum_py)


@njit(cache=True)
def contact_total(cfx, cfy):
    """Total contact force on the workpiece [N/m] from the per-node forces, summed in a fixed
    order: ``N_SUM_LANES`` strided lane sums, then the lanes in order. The GPU engine sums
    the same way (one thread per lane), so both devices get the same bits whatever the
    thread count."""
    fx = 0.0
    fy = 0.0
    for lane in range(N_SUM_LANES):
        fx += lane_sum(cfx, lane, N_SUM_LANES)
        fy += lane_sum(cfy, lane, N_SUM_LANES)
    return fx, fy


def contact_split_node_py(i, cfx, cfy, x, y, cx, cy, nrx, nry, nfx, nfy, out, o):
    """Node ``i``'s contact force on the tool added to its face's pair in ``out[o:o + 6]``
    = [Fx, Fy] of the rake face, the edge arc and the flank [N/m]. A node belongs to the
    face that gives its gap (:func:`robobore.cutting.fe.physics.tool_face_py`). Called in
    increasing node order by one thread on both devices (:func:`contact_split`, the GPU's
    block 0), so the sums have the same bits."""
    fx = cfx[i]
    fy = cfy[i]
    if fx == 0.0 and fy == 0.0:
        return
    k = tool_face(x[i] - cx, y[i] - cy, nrx, nry, nfx, nfy)
    out[o + 2 * k] -= fx
    out[o + 2 * k + 1] -= fy


def tool_geometry_py(prm):
    """The tool's edge centre x, y, rake and flank normals and edge radius from ``prm``: the
    tool geometry tuple of the ALE passes (:mod:`robobore.cutting.fe.rezone`)."""
    return (prm[P_TCX], prm[P_TCY], prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY],
            prm[P_R])


contact_split_node = njit(cache=True, inline="always")(contact_split_node_py)
tool_geometry = njit(cache=True, inline="always")(tool_geometry_py)


@njit(cache=True)
def contact_split(cfx, cfy, x, y, cx, cy, nrx, nry, nfx, nfy, out):
    """Contact force on the tool by face into ``out`` = [Fx, Fy] of the rake face, the edge
    arc and the flank [N/m] (serial, fixed order: :func:`contact_split_node_py`)."""
    for j in range(6):
        out[j] = 0.0
    for i in range(cfx.shape[0]):
        contact_split_node(i, cfx, cfy, x, y, cx, cy, nrx, nry, nfx, nfy, out, 0)


def quad_centroid_py(e, conn, x, y, tbuf):
    """Centroid x, y and area of quad ``e`` into ``tbuf[e, 0:3]`` (first pass of conduction)."""
    i1, i2, i3, i4 = conn[e, 0], conn[e, 1], conn[e, 2], conn[e, 3]
    tbuf[e, 0] = 0.25 * (x[i1] + x[i2] + x[i3] + x[i4])
    tbuf[e, 1] = 0.25 * (y[i1] + y[i2] + y[i3] + y[i4])
    tbuf[e, 2] = 0.5 * ((x[i3] - x[i1]) * (y[i4] - y[i2]) + (x[i2] - x[i4]) * (y[i3] - y[i1]))


def quad_conduct_py(e, conn, x, y, alive, enbr, temp, tbuf, kcond, rcp, dt_th):
    """New temperature of quad ``e`` into ``tbuf[e, 3]`` (second pass of conduction).

    Needs ``tbuf[:, 0:3]`` of every element (:func:`quad_centroid_py`); reads ``temp`` only,
    so all elements can run at once. See :func:`conduct`.
    """
    tbuf[e, 3] = temp[e]
    ae = tbuf[e, 2]
    if alive[e] != 1 or ae <= 0.0:
        return
    dq = 0.0
    for k in range(4):
        nb = enbr[e, k]
        if nb < 0 or alive[nb] != 1:
            continue
        an = tbuf[nb, 2]
        na = conn[e, k]
        nb2 = conn[e, (k + 1) % 4]
        ledge = math.sqrt((x[nb2] - x[na]) ** 2 + (y[nb2] - y[na]) ** 2)
        d = math.sqrt((tbuf[nb, 0] - tbuf[e, 0]) ** 2 + (tbuf[nb, 1] - tbuf[e, 1]) ** 2)
        if d <= 0.0 or an <= 0.0:
            continue
        g = kcond * ledge / d * dt_th
        gmax = 0.25 * rcp * min(ae, an)
        if g > gmax:
            g = gmax
        dq += g * (temp[nb] - temp[e])
    tbuf[e, 3] = temp[e] + dq / (rcp * ae)


quad_centroid = njit(cache=True, inline="always")(quad_centroid_py)
quad_conduct = njit(cache=True, inline="always")(quad_conduct_py)


@njit(parallel=True, cache=True)
def conduct(conn, x, y, alive, enbr, temp, tbuf, kcond, rcp, dt_th):
    """Explicit heat conduction between live elements over ``dt_th`` [s] (finite volumes).

    Element temperatures are cell values on the current (deformed) mesh; across each edge
    shared by two live elements flows ``G (T_nb - T_e)`` with the two-point conductance
    ``G = k L_edge / d_centroids * dt_th`` [J/K per m of width]. ``G`` is capped at a quarter
    of the smaller of the two heat capacities ``rho cp A`` (stability of the explicit update
    for any element shape; symmetric, so heat is conserved exactly). Eroded elements and
    free surfaces are adiabatic (so is the tool). ``tbuf`` (n_elem, 4) is scratch: centroid
    x, y and area of every element, then its new temperature.
    """
    ne = conn.shape[0]
    for e in prange(ne):
        quad_centroid(e, conn, x, y, tbuf)
    for e in prange(ne):
        quad_conduct(e, conn, x, y, alive, enbr, temp, tbuf, kcond, rcp, dt_th)
    for e in prange(ne):
        temp[e] = tbuf[e, 3]


def parting_edge_py(i, ppair, x, y, alive, tied, temp, tbuf, kcond, rcp, dt_th):
    """Conduction across parting-line edge ``i`` while both its node pairs are still tied.

    ``ppair`` (m, 4): an element, the element across the parting line, and the first one's
    two nodes on the edge (:func:`robobore.cutting.fe.solver.parting_edges`). The two
    elements share no nodes (the line's nodes are doubled), so :func:`conduct` sees the
    line as a free surface; while the pairs are tied the material is continuous there and
    heat flows across with the two-point conductance (and cap) of :func:`quad_conduct_py`.
    Needs the centroids and areas in ``tbuf[:, 0:3]``. An element lies on at most one edge
    of ``ppair``, so all edges can run at once; heat is conserved exactly.
    """
    ea, eb, na, nb = ppair[i, 0], ppair[i, 1], ppair[i, 2], ppair[i, 3]
    if alive[ea] != 1 or alive[eb] != 1 or tied[na] == 0 or tied[nb] == 0:
        return
    aa = tbuf[ea, 2]
    ab = tbuf[eb, 2]
    d = math.sqrt((tbuf[eb, 0] - tbuf[ea, 0]) ** 2 + (tbuf[eb, 1] - tbuf[ea, 1]) ** 2)
    if d <= 0.0 or aa <= 0.0 or ab <= 0.0:
        return
    ledge = math.sqrt((x[nb] - x[na]) ** 2 + (y[nb] - y[na]) ** 2)
    g = kcond * ledge / d * dt_th
    gmax = 0.25 * rcp * min(aa, ab)
    if g > gmax:
        g = gmax
    q = g * (temp[eb] - temp[ea])
    temp[ea] += q / (rcp * aa)
    temp[eb] -= q / (rcp * ab)


def tool_heat_node_py(n, conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric, fheat,
                      temp, tbuf, tcq, rcp, hc, eta, t_tool, dt_th):
    """Heat [J/m] node ``n`` exchanges with the tool since the last call, into ``tcq[n]``.

    The node takes ``eta`` of the frictional dissipation booked on it since the last call
    (``fric - fheat``; the rest heats the tool). A node in contact (non-zero contact force)
    exchanges ``hc L_n (t_tool - T_n) dt_th`` with the tool, a heat sink at ``t_tool``:
    ``T_n`` is the area-weighted mean temperature of the node's live elements, ``L_n`` half
    the length of each free-surface edge joining it to another node in contact. The
    conductance is capped at a quarter of the heat capacity of the node's elements
    (stability, as in :func:`quad_conduct_py`). ``tcq[n]`` = (heat, area of the node's live
    elements). Needs the areas in ``tbuf[:, 2]``.
    """
    q = eta * (fric[n] - fheat[n])
    fheat[n] = fric[n]
    touching = hc > 0.0 and (cfx[n] != 0.0 or cfy[n] != 0.0)
    if q == 0.0 and not touching:
        tcq[n, 0] = 0.0  # nothing to hand on: the element pass skips this node
        return
    asum = 0.0
    tsum = 0.0
    for k in range(ptr[n], ptr[n + 1]):
        e = nel[k]
        if alive[e] == 1:
            a = tbuf[e, 2]
            asum += a
            tsum += a * temp[e]
    tcq[n, 1] = asum
    if asum <= 0.0:
        tcq[n, 0] = 0.0
        return
    if touching:
        ln = 0.0
        for k in range(ptr[n], ptr[n + 1]):
            e = nel[k]
            if alive[e] != 1:
                continue
            c = ncorner[k]
            for j in range(2):
                # edge c (n -> next corner), then edge c - 1 (previous corner -> n)
                kk = c if j == 0 else (c + 3) % 4
                o = conn[e, (c + 1) % 4] if j == 0 else conn[e, (c + 3) % 4]
                nb = enbr[e, kk]
                if nb >= 0 and alive[nb] == 1:
                    continue
                if cfx[o] == 0.0 and cfy[o] == 0.0:
                    continue
                ln += 0.5 * math.sqrt((x[o] - x[n]) ** 2 + (y[o] - y[n]) ** 2)
        g = hc * ln * dt_th
        gmax = 0.25 * rcp * asum
        if g > gmax:
            g = gmax
        q += g * (t_tool - tsum / asum)
    tcq[n, 0] = q


def tool_heat_elem_py(e, conn, alive, temp, tcq, rcp):
    """Element ``e`` takes, from each corner node, heat / (rho cp area of that node's live
    elements): a node's heat goes to its elements in proportion to their areas."""
    if alive[e] != 1:
        return
    dT = 0.0
    for c in range(4):
        n = conn[e, c]
        if tcq[n, 0] != 0.0 and tcq[n, 1] > 0.0:
            dT += tcq[n, 0] / (rcp * tcq[n, 1])
    temp[e] += dT


parting_edge = njit(cache=True, inline="always")(parting_edge_py)
tool_heat_node = njit(cache=True, inline="always")(tool_heat_node_py)
tool_heat_elem = njit(cache=True, inline="always")(tool_heat_elem_py)


@njit(parallel=True, cache=True)
def parting_conduct(ppair, x, y, alive, tied, temp, tbuf, kcond, rcp, dt_th):
    """:func:`parting_edge_py` over all parting-line edges (after :func:`conduct`)."""
    for i in prange(ppair.shape[0]):
        parting_edge(i, ppair, x, y, alive, tied, temp, tbuf, kcond, rcp, dt_th)


@njit(parallel=True, cache=True)
def tool_heat(conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric, fheat, temp, tbuf,
              tcq, rcp, hc, eta, t_tool, dt_th):
    """Thermal contact with the tool over ``dt_th`` [s] (after :func:`conduct`): frictional
    heat and the interface conductance, node by node (:func:`tool_heat_node_py`), then into
    the elements (:func:`tool_heat_elem_py`). Heat is conserved between nodes and
    elements."""
    for n in prange(x.shape[0]):
        tool_heat_node(n, conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric, fheat,
                       temp, tbuf, tcq, rcp, hc, eta, t_tool, dt_th)
    for e in prange(conn.shape[0]):
        tool_heat_elem(e, conn, alive, temp, tcq, rcp)


def sum_energies_py(mass, vx, vy, ie, plast, hge, alive, fric, pen, ero_ke, nwork, en):
    """Totals of the energy accumulators into ``en`` [J/m] (serial, a fixed order)."""
    ke = 0.0
    for n in range(mass.shape[0]):
        ke += 0.5 * mass[n] * (vx[n] * vx[n] + vy[n] * vy[n])
    si = 0.0
    sp = 0.0
    sh = 0.0
    se = 0.0
    for e in range(ie.shape[0]):
        si += ie[e]
        sp += plast[e]
        sh += hge[e]
        if alive[e] != 1:
            se += ie[e]
    sf = 0.0
    spn = 0.0
    sek = 0.0
    sw = 0.0
    for n in range(mass.shape[0]):
        sf += fric[n]
        spn += pen[n]
        sek += ero_ke[n]
        sw += nwork[n]
    en[E_KIN] = ke
    en[E_INT] = si
    en[E_PLAST] = sp
    en[E_HG] = sh
    en[E_FRIC] = sf + spn
    en[E_NODEWORK] = sw
    en[E_ERODED] = se + sek
    en[E_EROKE] = sek


_sum_energies = njit(cache=True)(sum_energies_py)


def tool_kinematics_py(tool, prm):
    """Tool edge centre (cx, cy) [m] and velocity (tvx, tvy) [m/s] at the start of a step."""
    return (tool[T_GX] + tool[T_UX], tool[T_GY] + tool[T_UY], -prm[P_VC] + tool[T_VUX],
            tool[T_VUY])


def tool_step_py(tool, prm, fwx, fwy, dt):
    """Advance the tool over one step under the contact force (fwx, fwy) on the workpiece.

    Stores the force on the tool, integrates the support springs (when ``prm[P_SUPPORT]``),
    moves the guide point at -vc, records the new edge centre in ``prm[P_TCX]``/``[P_TCY]``
    (for the erosion gate) and returns the work of the tool on the workpiece over the step
    [J/m] (midpoint velocities).
    """
    vc = prm[P_VC]
    width = prm[P_WIDTH]
    tvx = -vc + tool[T_VUX]
    tvy = tool[T_VUY]
    # force on the tool = - force on the workpiece [N/m]
    tool[T_FX] = -fwx
    tool[T_FY] = -fwy
    if prm[P_SUPPORT] > 0.5:
        ux, vux = tool_support_step(tool[T_UX], tool[T_VUX], -fwx * width, prm[P_KX],
                                    prm[P_CX], prm[P_MX], dt)
        uy, vuy = tool_support_step(tool[T_UY], tool[T_VUY], -fwy * width, prm[P_KY],
                                    prm[P_CY], prm[P_MY], dt)
        tool[T_UX] = ux
        tool[T_VUX] = vux
        tool[T_UY] = uy
        tool[T_VUY] = vuy
    tool[T_GX] -= vc * dt
    tvx_new = -vc + tool[T_VUX]
    tvy_new = tool[T_VUY]
    prm[P_TCX] = tool[T_GX] + tool[T_UX]
    prm[P_TCY] = tool[T_GY] + tool[T_UY]
    return dt * (fwx * 0.5 * (tvx + tvx_new) + fwy * 0.5 * (tvy + tvy_new))


tool_kinematics = njit(cache=True)(tool_kinematics_py)
tool_step = njit(cache=True)(tool_step_py)


@njit(cache=True)
def run_chunk(n_steps, x, y, vx, vy, mass, fixed, ptr, nel, ncorner, conn, layer, alive,
              sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0, ie, hge, fex, fey,
              dte, plast, rate, cfx, cfy, fric, pen, ndead, ero_ke, nwork, mat, prm, tool,
              en, ist, clock, hacc, hist, enbr, snodes, snbr, xn, yn, buf, twin, tied, tbuf,
              gps, fheat, tcq, ppair, x0, y0, vbuf, acls, aflt, bflag, vslip):
    """Advance up to ``n_steps`` central-difference steps (the whole loop in numba).

    ``clock`` = [t, dt, t_acc] (time [s], current step [s], time accumulated in the current
    sample interval). Stops early with ``ist[I_STATUS]`` = STATUS_DONE at ``prm[P_TEND]``,
    STATUS_NONFINITE or STATUS_DT_COLLAPSE. Returns the number of steps taken.
    """
    erosion = int(prm[P_EROSION])
    bbar = int(prm[P_ELEM]) == ELEM_Q4BBAR
    cfl = prm[P_CFL]
    rz_every = int(prm[P_RZ_EVERY])
    rho_s = mat[jc.RHO] * prm[P_MS]
    fsplit = np.zeros(6)
    taken = 0
    for _s in range(n_steps):
        dt = clock[1]
        t = clock[0]
        cx, cy, tvx, tvy = tool_kinematics(tool, prm)
        ncont = node_update(x, y, vx, vy, mass, fixed, ptr, nel, ncorner, alive, area0, fex,
                            fey, cfx, cfy, fric, pen, ndead, ero_ke, nwork, cx, cy, tvx, tvy,
                            prm, dt, twin, tied, vslip)
        fwx, fwy = contact_total(cfx, cfy)
        contact_split(cfx, cfy, x, y, cx, cy, prm[P_NRX], prm[P_NRY], prm[P_NFX], prm[P_NFY],
                      fsplit)
        en[E_EXT] += tool_step(tool, prm, fwx, fwy, dt)
        if rz_every > 0 and ist[I_STEP] % rz_every == 0 and snodes.shape[0] > 0:
            rezone(x, y, vx, vy, mass, conn, alive, ptr, nel, enbr, snodes, snbr, xn, yn, buf,
                   sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy, area0, rho_s,
                   prm[P_RZ_OMEGA], prm[P_RZ_MAXMOVE], int(prm[P_RZ_MODE]), tied, x0, y0,
                   vbuf, tool_geometry(prm), acls, aflt, bflag, mat[jc.TROOM],
                   prm[P_TCX] - prm[P_ALE_X0])
        if bbar:
            dtmin, bad = element_update_bbar(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz,
                                             sdxy, pres, eps_p, temp, dmg, gps, area0, ie, fex,
                                             fey, dte, plast, rate, mat, prm, dt, erosion)
        else:
            dtmin, bad = element_update(conn, x, y, vx, vy, alive, layer, sdx, sdy, sdz, sdxy,
                                        pres, eps_p, temp, dmg, qhx, qhy, area0, ie, hge, fex,
                                        fey, dte, plast, rate, mat, prm, dt, erosion)
        cond_every = int(prm[P_COND_EVERY])
        if cond_every > 0:
            prm[P_COND_ACC] += dt
            if ist[I_STEP] % cond_every == 0:
                rcp = mat[jc.RHO] * mat[jc.CP]
                conduct(conn, x, y, alive, enbr, temp, tbuf, mat[jc.KCOND], rcp,
                        prm[P_COND_ACC])
                if ppair.shape[0] > 0:
                    parting_conduct(ppair, x, y, alive, tied, temp, tbuf, mat[jc.KCOND], rcp,
                                    prm[P_COND_ACC])
                if prm[P_HC] > 0.0 or prm[P_FHEAT] > 0.0:
                    tool_heat(conn, x, y, ptr, nel, ncorner, alive, enbr, cfx, cfy, fric,
                              fheat, temp, tbuf, tcq, rcp, prm[P_HC], prm[P_FHEAT],
                              prm[P_TTOOL], prm[P_COND_ACC])
                prm[P_COND_ACC] = 0.0
        if bad >= 0:
            ist[I_BADELEM] = bad
            ist[I_STATUS] = STATUS_INVERTED
            return taken + 1
        if dtmin >= 1e30:
            ist[I_STATUS] = STATUS_NO_ELEMENTS
            return taken + 1
        new_dt = cfl * dtmin
        t += dt
        clock[0] = t
        taken += 1
        ist[I_STEP] += 1
        if not (math.isfinite(fwx) and math.isfinite(fwy) and math.isfinite(new_dt)):
            ist[I_STATUS] = STATUS_NONFINITE
            return taken
        if new_dt < prm[P_DTMIN]:
            ist[I_STATUS] = STATUS_DT_COLLAPSE
            clock[1] = new_dt
            return taken
        clock[1] = new_dt
        # time-averaged histories
        hacc[H_FX] += dt * tool[T_FX]
        hacc[H_FY] += dt * tool[T_FY]
        hacc[H_UX] += dt * tool[T_UX]
        hacc[H_UY] += dt * tool[T_UY]
        hacc[H_NCONT] += dt * ncont
        for j in range(6):
            hacc[H_FX_RAKE + j] += dt * fsplit[j]
        clock[2] += dt
        k = ist[I_SAMPLE]
        if t >= (k + 1) * prm[P_SAMPLE_DT] and k < hist.shape[0]:
            ta = clock[2]
            _sum_energies(mass, vx, vy, ie, plast, hge, alive, fric, pen, ero_ke, nwork, en)
            if not math.isfinite(en[E_KIN]):
                ist[I_STATUS] = STATUS_NONFINITE
                return taken
            hist[k, H_T] = t
            hist[k, H_FX] = hacc[H_FX] / ta
            hist[k, H_FY] = hacc[H_FY] / ta
            hist[k, H_UX] = hacc[H_UX] / ta
            hist[k, H_UY] = hacc[H_UY] / ta
            hist[k, H_NCONT] = hacc[H_NCONT] / ta
            for j in range(6):
                hist[k, H_FX_RAKE + j] = hacc[H_FX_RAKE + j] / ta
            hist[k, H_TIP_X] = tool[T_GX] + tool[T_UX]
            hist[k, H_EKIN] = en[E_KIN]
            hist[k, H_EINT] = en[E_INT]
            hist[k, H_EPL] = en[E_PLAST]
            hist[k, H_EHG] = en[E_HG]
            hist[k, H_EFRIC] = en[E_FRIC]
            hist[k, H_EEXT] = en[E_EXT]
            hist[k, H_EERO] = en[E_ERODED]
            for j in range(hacc.shape[0]):
                hacc[j] = 0.0
            clock[2] = 0.0
            ist[I_SAMPLE] = k + 1
        if t >= prm[P_TEND]:
            ist[I_STATUS] = STATUS_DONE
            _sum_energies(mass, vx, vy, ie, plast, hge, alive, fric, pen, ero_ke, nwork, en)
            return taken
    return taken
