"""Hexahedral element of the 3D explicit engine, as one scalar function of the element index.

:func:`hex_element_py` is the whole per-element update (kinematics, Jaumann-rate hypoelastic
trial stress, Johnson-Cook return via the shared :func:`robobore.material.johnson_cook.jc_return`,
adiabatic heating, Johnson-Cook damage, bulk viscosity, stable step, internal energy,
Flanagan-Belytschko hourglass control, internal nodal forces). It reads and writes array
elements only and allocates nothing, so the same source is compiled for the CPU
(:data:`hex_element`, called from a ``prange`` loop in :mod:`robobore.cutting.fe.engine.kernels3d`)
and for an NVIDIA GPU (:func:`make_hex_element` given device versions of its callees, then
``numba.cuda.jit(device=True)``, in :mod:`robobore.cutting.fe.engine.gpu.kernels3d`).

Element: 8-node trilinear hexahedron (VTK node order: 0-3 the face zeta = -1 counter-clockwise
seen from +zeta, 4-7 above them), one-point (uniform strain) integration with the mean
gradient ``b_I = (1/V) dV/dx_I``, which is exact for any trilinear hexahedron, so a
constant strain field is reproduced on distorted meshes (patch test) -- Flanagan D.P.,
Belytschko T. (1981), IJNME 17, 679-706, eqs. (16), (79). Hourglass base vectors
``h = (eta zeta, zeta xi, xi eta, xi eta zeta)`` with the orthogonal gamma vectors
``gamma_a = (h_a - (h_a . x_i) b_i) / 8`` (FB eq. 59); the hourglass resistance is a stored,
co-rotated stiffness part plus a viscous part (coefficients ``P_HGS``, ``P_HGV``). Stable step
``dt = l / (q + sqrt(q^2 + c^2))`` with ``l = 1 / sqrt(2 b_iI b_iI)`` (the exact one-point
hexahedron bound for a cube of side h: l = h / sqrt(3)).

The unrolled terms below are generated (the volume derivative coefficients are
``12 C_IJK = 12 int eps_abc N_I,a N_J,b N_K,c`` on the reference cube); they are checked
against a numerical derivative of the element volume in ``tests/cutting/fe3d``.
"""
# ruff: noqa: E501

from __future__ import annotations

import math

from numba import njit

from robobore.cutting.fe.hex.layout3d import (
    ERODE_LAYER,
    P_BV1,
    P_BV2,
    P_DIST,
    P_DT_ERODE,
    P_HGS,
    P_HGV,
    P_MS,
)
from robobore.material.johnson_cook import (
    BETA_TQ,
    CP,
    D1,
    D2,
    D3,
    D4,
    D5,
    E_MOD,
    EPS0,
    EPS_HMAX,
    NU,
    RHO,
    TMELT,
    TROOM,
    jc_damage_increment,
    jc_return,
)
from robobore.material.johnson_cook import A as JA
from robobore.material.johnson_cook import B as JB
from robobore.material.johnson_cook import C as JC
from robobore.material.johnson_cook import M as JM
from robobore.material.johnson_cook import N as JN


def make_hex_element(jc_return, jc_damage_increment):
    """:func:`hex_element_py` with its callees ``jc_return``, ``jc_damage_increment`` given
    (the CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def hex_element_py(e, conn, x, y, z, vx, vy, vz, alive, layer, sd, pres, eps_p, temp, dmg, qh, vol0,
                       ie, hge, fe, dte, plast, rate, mat, prm, dt, erosion):
        """Stress update and internal nodal forces of hexahedron ``e`` (one element, scalar code).

        Reads nodal positions/velocities, updates the element state in place (deviatoric stress
        ``sd[e]`` (xx, yy, zz, xy, yz, zx) [Pa], pressure, plastic strain, temperature, damage,
        hourglass stresses ``qh[e]`` (4 modes x 3), energies) and writes ``fe[e, 3 I + i]``
        (internal force on corner I along i [N]) and ``dte[e]`` (stable step [s]). Sets
        ``alive[e]`` to 0 (eroded by damage where ``layer[e]`` with ``erosion`` = ERODE_LAYER), -1 (distortion / time-step erosion) or -2 (inverted).
        Allocates nothing; compiled for the CPU (``hex_element``) and the GPU (``engine/gpu/kernels3d.py``).
        """
        if alive[e] != 1:
            for k in range(24):
                fe[e, k] = 0.0
            dte[e] = 1e30
            return
        n0 = conn[e, 0]
        n1 = conn[e, 1]
        n2 = conn[e, 2]
        n3 = conn[e, 3]
        n4 = conn[e, 4]
        n5 = conn[e, 5]
        n6 = conn[e, 6]
        n7 = conn[e, 7]
        x0 = x[n0]
        x1 = x[n1]
        x2 = x[n2]
        x3 = x[n3]
        x4 = x[n4]
        x5 = x[n5]
        x6 = x[n6]
        x7 = x[n7]
        y0 = y[n0]
        y1 = y[n1]
        y2 = y[n2]
        y3 = y[n3]
        y4 = y[n4]
        y5 = y[n5]
        y6 = y[n6]
        y7 = y[n7]
        z0 = z[n0]
        z1 = z[n1]
        z2 = z[n2]
        z3 = z[n3]
        z4 = z[n4]
        z5 = z[n5]
        z6 = z[n6]
        z7 = z[n7]
        C12 = 1.0 / 12.0
        # volume derivatives dV/dx_I (Flanagan & Belytschko 1981, eq. 79): exact for the trilinear hex
        ax0 = (y1*(-z2-z3+z4+z5) + y2*(z1-z3) + y3*(z1+z2-z4-z7) + y4*(-z1+z3-z5+z7) + y5*(-z1+z4) + y7*(z3-z4)) * C12
        ax1 = (y0*(z2+z3-z4-z5) + y2*(-z0-z3+z5+z6) + y3*(-z0+z2) + y4*(z0-z5) + y5*(z0-z2+z4-z6) + y6*(-z2+z5)) * C12
        ax2 = (y0*(-z1+z3) + y1*(z0+z3-z5-z6) + y3*(-z0-z1+z6+z7) + y5*(z1-z6) + y6*(z1-z3+z5-z7) + y7*(-z3+z6)) * C12
        ax3 = (y0*(-z1-z2+z4+z7) + y1*(z0-z2) + y2*(z0+z1-z6-z7) + y4*(-z0+z7) + y6*(z2-z7) + y7*(-z0+z2-z4+z6)) * C12
        ax4 = (y0*(z1-z3+z5-z7) + y1*(-z0+z5) + y3*(z0-z7) + y5*(-z0-z1+z6+z7) + y6*(-z5+z7) + y7*(z0+z3-z5-z6)) * C12
        ax5 = (y0*(z1-z4) + y1*(-z0+z2-z4+z6) + y2*(-z1+z6) + y4*(z0+z1-z6-z7) + y6*(-z1-z2+z4+z7) + y7*(z4-z6)) * C12
        ax6 = (y1*(z2-z5) + y2*(-z1+z3-z5+z7) + y3*(-z2+z7) + y4*(z5-z7) + y5*(z1+z2-z4-z7) + y7*(-z2-z3+z4+z5)) * C12
        ax7 = (y0*(-z3+z4) + y2*(z3-z6) + y3*(z0-z2+z4-z6) + y4*(-z0-z3+z5+z6) + y5*(-z4+z6) + y6*(z2+z3-z4-z5)) * C12
        ay0 = (z1*(-x2-x3+x4+x5) + z2*(x1-x3) + z3*(x1+x2-x4-x7) + z4*(-x1+x3-x5+x7) + z5*(-x1+x4) + z7*(x3-x4)) * C12
        ay1 = (z0*(x2+x3-x4-x5) + z2*(-x0-x3+x5+x6) + z3*(-x0+x2) + z4*(x0-x5) + z5*(x0-x2+x4-x6) + z6*(-x2+x5)) * C12
        ay2 = (z0*(-x1+x3) + z1*(x0+x3-x5-x6) + z3*(-x0-x1+x6+x7) + z5*(x1-x6) + z6*(x1-x3+x5-x7) + z7*(-x3+x6)) * C12
        ay3 = (z0*(-x1-x2+x4+x7) + z1*(x0-x2) + z2*(x0+x1-x6-x7) + z4*(-x0+x7) + z6*(x2-x7) + z7*(-x0+x2-x4+x6)) * C12
        ay4 = (z0*(x1-x3+x5-x7) + z1*(-x0+x5) + z3*(x0-x7) + z5*(-x0-x1+x6+x7) + z6*(-x5+x7) + z7*(x0+x3-x5-x6)) * C12
        ay5 = (z0*(x1-x4) + z1*(-x0+x2-x4+x6) + z2*(-x1+x6) + z4*(x0+x1-x6-x7) + z6*(-x1-x2+x4+x7) + z7*(x4-x6)) * C12
        ay6 = (z1*(x2-x5) + z2*(-x1+x3-x5+x7) + z3*(-x2+x7) + z4*(x5-x7) + z5*(x1+x2-x4-x7) + z7*(-x2-x3+x4+x5)) * C12
        ay7 = (z0*(-x3+x4) + z2*(x3-x6) + z3*(x0-x2+x4-x6) + z4*(-x0-x3+x5+x6) + z5*(-x4+x6) + z6*(x2+x3-x4-x5)) * C12
        az0 = (x1*(-y2-y3+y4+y5) + x2*(y1-y3) + x3*(y1+y2-y4-y7) + x4*(-y1+y3-y5+y7) + x5*(-y1+y4) + x7*(y3-y4)) * C12
        az1 = (x0*(y2+y3-y4-y5) + x2*(-y0-y3+y5+y6) + x3*(-y0+y2) + x4*(y0-y5) + x5*(y0-y2+y4-y6) + x6*(-y2+y5)) * C12
        az2 = (x0*(-y1+y3) + x1*(y0+y3-y5-y6) + x3*(-y0-y1+y6+y7) + x5*(y1-y6) + x6*(y1-y3+y5-y7) + x7*(-y3+y6)) * C12
        az3 = (x0*(-y1-y2+y4+y7) + x1*(y0-y2) + x2*(y0+y1-y6-y7) + x4*(-y0+y7) + x6*(y2-y7) + x7*(-y0+y2-y4+y6)) * C12
        az4 = (x0*(y1-y3+y5-y7) + x1*(-y0+y5) + x3*(y0-y7) + x5*(-y0-y1+y6+y7) + x6*(-y5+y7) + x7*(y0+y3-y5-y6)) * C12
        az5 = (x0*(y1-y4) + x1*(-y0+y2-y4+y6) + x2*(-y1+y6) + x4*(y0+y1-y6-y7) + x6*(-y1-y2+y4+y7) + x7*(y4-y6)) * C12
        az6 = (x1*(y2-y5) + x2*(-y1+y3-y5+y7) + x3*(-y2+y7) + x4*(y5-y7) + x5*(y1+y2-y4-y7) + x7*(-y2-y3+y4+y5)) * C12
        az7 = (x0*(-y3+y4) + x2*(y3-y6) + x3*(y0-y2+y4-y6) + x4*(-y0-y3+y5+y6) + x5*(-y4+y6) + x6*(y2+y3-y4-y5)) * C12
        V = x0 * ax0 + x1 * ax1 + x2 * ax2 + x3 * ax3 + x4 * ax4 + x5 * ax5 + x6 * ax6 + x7 * ax7
        v0e = vol0[e]
        dlim = prm[P_DIST]
        if V <= 0.0 or V < dlim * v0e:
            alive[e] = -1 if (dlim > 0.0 and V > 0.0) else -2
            for k in range(24):
                fe[e, k] = 0.0
            dte[e] = 1e30
            return
        iv = 1.0 / V
        bx0 = ax0 * iv
        bx1 = ax1 * iv
        bx2 = ax2 * iv
        bx3 = ax3 * iv
        bx4 = ax4 * iv
        bx5 = ax5 * iv
        bx6 = ax6 * iv
        bx7 = ax7 * iv
        by0 = ay0 * iv
        by1 = ay1 * iv
        by2 = ay2 * iv
        by3 = ay3 * iv
        by4 = ay4 * iv
        by5 = ay5 * iv
        by6 = ay6 * iv
        by7 = ay7 * iv
        bz0 = az0 * iv
        bz1 = az1 * iv
        bz2 = az2 * iv
        bz3 = az3 * iv
        bz4 = az4 * iv
        bz5 = az5 * iv
        bz6 = az6 * iv
        bz7 = az7 * iv
        u0 = vx[n0]
        u1 = vx[n1]
        u2 = vx[n2]
        u3 = vx[n3]
        u4 = vx[n4]
        u5 = vx[n5]
        u6 = vx[n6]
        u7 = vx[n7]
        v0 = vy[n0]
        v1 = vy[n1]
        v2 = vy[n2]
        v3 = vy[n3]
        v4 = vy[n4]
        v5 = vy[n5]
        v6 = vy[n6]
        v7 = vy[n7]
        w0 = vz[n0]
        w1 = vz[n1]
        w2 = vz[n2]
        w3 = vz[n3]
        w4 = vz[n4]
        w5 = vz[n5]
        w6 = vz[n6]
        w7 = vz[n7]
        L11 = u0 * bx0 + u1 * bx1 + u2 * bx2 + u3 * bx3 + u4 * bx4 + u5 * bx5 + u6 * bx6 + u7 * bx7
        L12 = u0 * by0 + u1 * by1 + u2 * by2 + u3 * by3 + u4 * by4 + u5 * by5 + u6 * by6 + u7 * by7
        L13 = u0 * bz0 + u1 * bz1 + u2 * bz2 + u3 * bz3 + u4 * bz4 + u5 * bz5 + u6 * bz6 + u7 * bz7
        L21 = v0 * bx0 + v1 * bx1 + v2 * bx2 + v3 * bx3 + v4 * bx4 + v5 * bx5 + v6 * bx6 + v7 * bx7
        L22 = v0 * by0 + v1 * by1 + v2 * by2 + v3 * by3 + v4 * by4 + v5 * by5 + v6 * by6 + v7 * by7
        L23 = v0 * bz0 + v1 * bz1 + v2 * bz2 + v3 * bz3 + v4 * bz4 + v5 * bz5 + v6 * bz6 + v7 * bz7
        L31 = w0 * bx0 + w1 * bx1 + w2 * bx2 + w3 * bx3 + w4 * bx4 + w5 * bx5 + w6 * bx6 + w7 * bx7
        L32 = w0 * by0 + w1 * by1 + w2 * by2 + w3 * by3 + w4 * by4 + w5 * by5 + w6 * by6 + w7 * by7
        L33 = w0 * bz0 + w1 * bz1 + w2 * bz2 + w3 * bz3 + w4 * bz4 + w5 * bz5 + w6 * bz6 + w7 * bz7
        E = mat[E_MOD]
        nu = mat[NU]
        G = E / (2.0 * (1.0 + nu))
        K = E / (3.0 * (1.0 - 2.0 * nu))
        dxx = L11
        dyy = L22
        dzz = L33
        dxy = 0.5 * (L12 + L21)
        dyz = 0.5 * (L23 + L32)
        dzx = 0.5 * (L31 + L13)
        wxy = 0.5 * (L12 - L21)
        wyz = 0.5 * (L23 - L32)
        wzx = 0.5 * (L31 - L13)
        trd = dxx + dyy + dzz
        p_old = pres[e]
        sxx = sd[e, 0]
        syy = sd[e, 1]
        szz = sd[e, 2]
        sxy = sd[e, 3]
        syz = sd[e, 4]
        szx = sd[e, 5]
        # Jaumann rotation: s + dt (W s - s W) = s + dt (A + A^T), A = W s
        A11 = wxy * sxy - wzx * szx
        A22 = -wxy * sxy + wyz * syz
        A33 = wzx * szx - wyz * syz
        A12 = wxy * syy - wzx * syz
        A21 = -wxy * sxx + wyz * szx
        A23 = -wxy * szx + wyz * szz
        A32 = wzx * sxy - wyz * syy
        A31 = wzx * sxx - wyz * sxy
        A13 = wxy * syz - wzx * szz
        tr3 = trd * dt / 3.0
        g2 = 2.0 * G * dt
        txx = sxx + 2.0 * dt * A11 + g2 * dxx - 2.0 * G * tr3
        tyy = syy + 2.0 * dt * A22 + g2 * dyy - 2.0 * G * tr3
        tzz = szz + 2.0 * dt * A33 + g2 * dzz - 2.0 * G * tr3
        txy = sxy + dt * (A12 + A21) + g2 * dxy
        tyz = syz + dt * (A23 + A32) + g2 * dyz
        tzx = szx + dt * (A31 + A13) + g2 * dzx
        p_new = p_old - K * trd * dt
        q = math.sqrt(1.5 * (txx * txx + tyy * tyy + tzz * tzz
                             + 2.0 * (txy * txy + tyz * tyz + tzx * tzx)))
        dep, syld = jc_return(q, eps_p[e], temp[e], dt, G, mat[JA], mat[JB], mat[JN], mat[JC],
                              mat[JM], mat[EPS0], mat[TROOM], mat[TMELT], mat[EPS_HMAX])
        if dep > 0.0:
            sc = syld / q
            txx *= sc
            tyy *= sc
            tzz *= sc
            txy *= sc
            tyz *= sc
            tzx *= sc
            eps_p[e] += dep
            rate[e] = dep / dt
            wp = syld * dep
            plast[e] += wp * V
            temp[e] += mat[BETA_TQ] * wp / (mat[RHO] * mat[CP])
            triax = -p_new / syld if syld > 0.0 else 0.0
            dmg[e] += jc_damage_increment(dep, triax, dep / dt, temp[e], mat[D1], mat[D2], mat[D3],
                                          mat[D4], mat[D5], mat[EPS0], mat[TROOM], mat[TMELT])
        else:
            rate[e] = 0.0
        sd[e, 0] = txx
        sd[e, 1] = tyy
        sd[e, 2] = tzz
        sd[e, 3] = txy
        sd[e, 4] = tyz
        sd[e, 5] = tzx
        pres[e] = p_new
        rho_c = mat[RHO] * prm[P_MS] * v0e / V
        c = math.sqrt((K + 4.0 * G / 3.0) / rho_c)
        bsum = (bx0 * bx0 + bx1 * bx1 + bx2 * bx2 + bx3 * bx3 + bx4 * bx4 + bx5 * bx5 + bx6 * bx6 + bx7 * bx7 + by0 * by0 + by1 * by1 + by2 * by2 + by3 * by3 + by4 * by4 + by5 * by5 + by6 * by6 + by7 * by7 + bz0 * bz0 + bz1 * bz1 + bz2 * bz2 + bz3 * bz3 + bz4 * bz4 + bz5 * bz5 + bz6 * bz6 + bz7 * bz7)
        le = 1.0 / math.sqrt(2.0 * bsum)
        qbv = 0.0
        qrate = 0.0
        if trd < 0.0:
            qrate = prm[P_BV1] * c + prm[P_BV2] * le * (-trd)
            qbv = rho_c * le * qrate * (-trd)
        dtl = le / (qrate + math.sqrt(qrate * qrate + c * c))
        dte[e] = dtl
        if dtl < prm[P_DT_ERODE]:
            alive[e] = -1
        fxx = txx - p_new - qbv
        fyy = tyy - p_new - qbv
        fzz = tzz - p_new - qbv
        oxx = sxx - p_old
        oyy = syy - p_old
        ozz = szz - p_old
        ie[e] += V * dt * (0.5 * ((oxx + fxx) * dxx + (oyy + fyy) * dyy + (ozz + fzz) * dzz)
                           + (sxy + txy) * dxy + (syz + tyz) * dyz + (szx + tzx) * dzx)
        # hourglass control (Flanagan-Belytschko 1981): stiffness part stored and co-rotated.
        # Scaled so that a hexahedron in plane strain resists an in-plane hourglass mode per unit
        # volume exactly as the 2D engine's quad does with the same coefficients (quad: hgs G A
        # b.b and 2 hgv rho c sqrt(A); a cube of side a: 2 hgs G a and 2 hgv rho c a^2 here),
        # so one [solver] setting means the same in both engines (docs/fe3d.md, "Element").
        kh = (4.0 / 3.0) * prm[P_HGS] * G * V * bsum
        cv = 2.0 * prm[P_HGV] * rho_c * c * V ** (2.0 / 3.0)
        ehg = 0.0
        hx0 = x0 + x1 - x2 - x3 - x4 - x5 + x6 + x7
        hy0 = y0 + y1 - y2 - y3 - y4 - y5 + y6 + y7
        hz0 = z0 + z1 - z2 - z3 - z4 - z5 + z6 + z7
        g0_0 = 0.125 * (1.0 - hx0 * bx0 - hy0 * by0 - hz0 * bz0)
        g0_1 = 0.125 * (1.0 - hx0 * bx1 - hy0 * by1 - hz0 * bz1)
        g0_2 = 0.125 * (-1.0 - hx0 * bx2 - hy0 * by2 - hz0 * bz2)
        g0_3 = 0.125 * (-1.0 - hx0 * bx3 - hy0 * by3 - hz0 * bz3)
        g0_4 = 0.125 * (-1.0 - hx0 * bx4 - hy0 * by4 - hz0 * bz4)
        g0_5 = 0.125 * (-1.0 - hx0 * bx5 - hy0 * by5 - hz0 * bz5)
        g0_6 = 0.125 * (1.0 - hx0 * bx6 - hy0 * by6 - hz0 * bz6)
        g0_7 = 0.125 * (1.0 - hx0 * bx7 - hy0 * by7 - hz0 * bz7)
        qu0 = u0 * g0_0 + u1 * g0_1 + u2 * g0_2 + u3 * g0_3 + u4 * g0_4 + u5 * g0_5 + u6 * g0_6 + u7 * g0_7
        qv0 = v0 * g0_0 + v1 * g0_1 + v2 * g0_2 + v3 * g0_3 + v4 * g0_4 + v5 * g0_5 + v6 * g0_6 + v7 * g0_7
        qw0 = w0 * g0_0 + w1 * g0_1 + w2 * g0_2 + w3 * g0_3 + w4 * g0_4 + w5 * g0_5 + w6 * g0_6 + w7 * g0_7
        sx = qh[e, 0]
        sy = qh[e, 1]
        sz = qh[e, 2]
        rx = sx + dt * (wxy * sy - wzx * sz) + dt * kh * qu0
        ry = sy + dt * (-wxy * sx + wyz * sz) + dt * kh * qv0
        rz = sz + dt * (wzx * sx - wyz * sy) + dt * kh * qw0
        qh[e, 0] = rx
        qh[e, 1] = ry
        qh[e, 2] = rz
        Qx0 = rx + cv * qu0
        Qy0 = ry + cv * qv0
        Qz0 = rz + cv * qw0
        ehg += Qx0 * qu0 + Qy0 * qv0 + Qz0 * qw0
        hx1 = x0 - x1 - x2 + x3 - x4 + x5 + x6 - x7
        hy1 = y0 - y1 - y2 + y3 - y4 + y5 + y6 - y7
        hz1 = z0 - z1 - z2 + z3 - z4 + z5 + z6 - z7
        g1_0 = 0.125 * (1.0 - hx1 * bx0 - hy1 * by0 - hz1 * bz0)
        g1_1 = 0.125 * (-1.0 - hx1 * bx1 - hy1 * by1 - hz1 * bz1)
        g1_2 = 0.125 * (-1.0 - hx1 * bx2 - hy1 * by2 - hz1 * bz2)
        g1_3 = 0.125 * (1.0 - hx1 * bx3 - hy1 * by3 - hz1 * bz3)
        g1_4 = 0.125 * (-1.0 - hx1 * bx4 - hy1 * by4 - hz1 * bz4)
        g1_5 = 0.125 * (1.0 - hx1 * bx5 - hy1 * by5 - hz1 * bz5)
        g1_6 = 0.125 * (1.0 - hx1 * bx6 - hy1 * by6 - hz1 * bz6)
        g1_7 = 0.125 * (-1.0 - hx1 * bx7 - hy1 * by7 - hz1 * bz7)
        qu1 = u0 * g1_0 + u1 * g1_1 + u2 * g1_2 + u3 * g1_3 + u4 * g1_4 + u5 * g1_5 + u6 * g1_6 + u7 * g1_7
        qv1 = v0 * g1_0 + v1 * g1_1 + v2 * g1_2 + v3 * g1_3 + v4 * g1_4 + v5 * g1_5 + v6 * g1_6 + v7 * g1_7
        qw1 = w0 * g1_0 + w1 * g1_1 + w2 * g1_2 + w3 * g1_3 + w4 * g1_4 + w5 * g1_5 + w6 * g1_6 + w7 * g1_7
        sx = qh[e, 3]
        sy = qh[e, 4]
        sz = qh[e, 5]
        rx = sx + dt * (wxy * sy - wzx * sz) + dt * kh * qu1
        ry = sy + dt * (-wxy * sx + wyz * sz) + dt * kh * qv1
        rz = sz + dt * (wzx * sx - wyz * sy) + dt * kh * qw1
        qh[e, 3] = rx
        qh[e, 4] = ry
        qh[e, 5] = rz
        Qx1 = rx + cv * qu1
        Qy1 = ry + cv * qv1
        Qz1 = rz + cv * qw1
        ehg += Qx1 * qu1 + Qy1 * qv1 + Qz1 * qw1
        hx2 = x0 - x1 + x2 - x3 + x4 - x5 + x6 - x7
        hy2 = y0 - y1 + y2 - y3 + y4 - y5 + y6 - y7
        hz2 = z0 - z1 + z2 - z3 + z4 - z5 + z6 - z7
        g2_0 = 0.125 * (1.0 - hx2 * bx0 - hy2 * by0 - hz2 * bz0)
        g2_1 = 0.125 * (-1.0 - hx2 * bx1 - hy2 * by1 - hz2 * bz1)
        g2_2 = 0.125 * (1.0 - hx2 * bx2 - hy2 * by2 - hz2 * bz2)
        g2_3 = 0.125 * (-1.0 - hx2 * bx3 - hy2 * by3 - hz2 * bz3)
        g2_4 = 0.125 * (1.0 - hx2 * bx4 - hy2 * by4 - hz2 * bz4)
        g2_5 = 0.125 * (-1.0 - hx2 * bx5 - hy2 * by5 - hz2 * bz5)
        g2_6 = 0.125 * (1.0 - hx2 * bx6 - hy2 * by6 - hz2 * bz6)
        g2_7 = 0.125 * (-1.0 - hx2 * bx7 - hy2 * by7 - hz2 * bz7)
        qu2 = u0 * g2_0 + u1 * g2_1 + u2 * g2_2 + u3 * g2_3 + u4 * g2_4 + u5 * g2_5 + u6 * g2_6 + u7 * g2_7
        qv2 = v0 * g2_0 + v1 * g2_1 + v2 * g2_2 + v3 * g2_3 + v4 * g2_4 + v5 * g2_5 + v6 * g2_6 + v7 * g2_7
        qw2 = w0 * g2_0 + w1 * g2_1 + w2 * g2_2 + w3 * g2_3 + w4 * g2_4 + w5 * g2_5 + w6 * g2_6 + w7 * g2_7
        sx = qh[e, 6]
        sy = qh[e, 7]
        sz = qh[e, 8]
        rx = sx + dt * (wxy * sy - wzx * sz) + dt * kh * qu2
        ry = sy + dt * (-wxy * sx + wyz * sz) + dt * kh * qv2
        rz = sz + dt * (wzx * sx - wyz * sy) + dt * kh * qw2
        qh[e, 6] = rx
        qh[e, 7] = ry
        qh[e, 8] = rz
        Qx2 = rx + cv * qu2
        Qy2 = ry + cv * qv2
        Qz2 = rz + cv * qw2
        ehg += Qx2 * qu2 + Qy2 * qv2 + Qz2 * qw2
        hx3 = -x0 + x1 - x2 + x3 + x4 - x5 + x6 - x7
        hy3 = -y0 + y1 - y2 + y3 + y4 - y5 + y6 - y7
        hz3 = -z0 + z1 - z2 + z3 + z4 - z5 + z6 - z7
        g3_0 = 0.125 * (-1.0 - hx3 * bx0 - hy3 * by0 - hz3 * bz0)
        g3_1 = 0.125 * (1.0 - hx3 * bx1 - hy3 * by1 - hz3 * bz1)
        g3_2 = 0.125 * (-1.0 - hx3 * bx2 - hy3 * by2 - hz3 * bz2)
        g3_3 = 0.125 * (1.0 - hx3 * bx3 - hy3 * by3 - hz3 * bz3)
        g3_4 = 0.125 * (1.0 - hx3 * bx4 - hy3 * by4 - hz3 * bz4)
        g3_5 = 0.125 * (-1.0 - hx3 * bx5 - hy3 * by5 - hz3 * bz5)
        g3_6 = 0.125 * (1.0 - hx3 * bx6 - hy3 * by6 - hz3 * bz6)
        g3_7 = 0.125 * (-1.0 - hx3 * bx7 - hy3 * by7 - hz3 * bz7)
        qu3 = u0 * g3_0 + u1 * g3_1 + u2 * g3_2 + u3 * g3_3 + u4 * g3_4 + u5 * g3_5 + u6 * g3_6 + u7 * g3_7
        qv3 = v0 * g3_0 + v1 * g3_1 + v2 * g3_2 + v3 * g3_3 + v4 * g3_4 + v5 * g3_5 + v6 * g3_6 + v7 * g3_7
        qw3 = w0 * g3_0 + w1 * g3_1 + w2 * g3_2 + w3 * g3_3 + w4 * g3_4 + w5 * g3_5 + w6 * g3_6 + w7 * g3_7
        sx = qh[e, 9]
        sy = qh[e, 10]
        sz = qh[e, 11]
        rx = sx + dt * (wxy * sy - wzx * sz) + dt * kh * qu3
        ry = sy + dt * (-wxy * sx + wyz * sz) + dt * kh * qv3
        rz = sz + dt * (wzx * sx - wyz * sy) + dt * kh * qw3
        qh[e, 9] = rx
        qh[e, 10] = ry
        qh[e, 11] = rz
        Qx3 = rx + cv * qu3
        Qy3 = ry + cv * qv3
        Qz3 = rz + cv * qw3
        ehg += Qx3 * qu3 + Qy3 * qv3 + Qz3 * qw3
        hge[e] += dt * ehg
        fe[e, 0] = V * (fxx * bx0 + txy * by0 + tzx * bz0) + Qx0 * g0_0 + Qx1 * g1_0 + Qx2 * g2_0 + Qx3 * g3_0
        fe[e, 1] = V * (txy * bx0 + fyy * by0 + tyz * bz0) + Qy0 * g0_0 + Qy1 * g1_0 + Qy2 * g2_0 + Qy3 * g3_0
        fe[e, 2] = V * (tzx * bx0 + tyz * by0 + fzz * bz0) + Qz0 * g0_0 + Qz1 * g1_0 + Qz2 * g2_0 + Qz3 * g3_0
        fe[e, 3] = V * (fxx * bx1 + txy * by1 + tzx * bz1) + Qx0 * g0_1 + Qx1 * g1_1 + Qx2 * g2_1 + Qx3 * g3_1
        fe[e, 4] = V * (txy * bx1 + fyy * by1 + tyz * bz1) + Qy0 * g0_1 + Qy1 * g1_1 + Qy2 * g2_1 + Qy3 * g3_1
        fe[e, 5] = V * (tzx * bx1 + tyz * by1 + fzz * bz1) + Qz0 * g0_1 + Qz1 * g1_1 + Qz2 * g2_1 + Qz3 * g3_1
        fe[e, 6] = V * (fxx * bx2 + txy * by2 + tzx * bz2) + Qx0 * g0_2 + Qx1 * g1_2 + Qx2 * g2_2 + Qx3 * g3_2
        fe[e, 7] = V * (txy * bx2 + fyy * by2 + tyz * bz2) + Qy0 * g0_2 + Qy1 * g1_2 + Qy2 * g2_2 + Qy3 * g3_2
        fe[e, 8] = V * (tzx * bx2 + tyz * by2 + fzz * bz2) + Qz0 * g0_2 + Qz1 * g1_2 + Qz2 * g2_2 + Qz3 * g3_2
        fe[e, 9] = V * (fxx * bx3 + txy * by3 + tzx * bz3) + Qx0 * g0_3 + Qx1 * g1_3 + Qx2 * g2_3 + Qx3 * g3_3
        fe[e, 10] = V * (txy * bx3 + fyy * by3 + tyz * bz3) + Qy0 * g0_3 + Qy1 * g1_3 + Qy2 * g2_3 + Qy3 * g3_3
        fe[e, 11] = V * (tzx * bx3 + tyz * by3 + fzz * bz3) + Qz0 * g0_3 + Qz1 * g1_3 + Qz2 * g2_3 + Qz3 * g3_3
        fe[e, 12] = V * (fxx * bx4 + txy * by4 + tzx * bz4) + Qx0 * g0_4 + Qx1 * g1_4 + Qx2 * g2_4 + Qx3 * g3_4
        fe[e, 13] = V * (txy * bx4 + fyy * by4 + tyz * bz4) + Qy0 * g0_4 + Qy1 * g1_4 + Qy2 * g2_4 + Qy3 * g3_4
        fe[e, 14] = V * (tzx * bx4 + tyz * by4 + fzz * bz4) + Qz0 * g0_4 + Qz1 * g1_4 + Qz2 * g2_4 + Qz3 * g3_4
        fe[e, 15] = V * (fxx * bx5 + txy * by5 + tzx * bz5) + Qx0 * g0_5 + Qx1 * g1_5 + Qx2 * g2_5 + Qx3 * g3_5
        fe[e, 16] = V * (txy * bx5 + fyy * by5 + tyz * bz5) + Qy0 * g0_5 + Qy1 * g1_5 + Qy2 * g2_5 + Qy3 * g3_5
        fe[e, 17] = V * (tzx * bx5 + tyz * by5 + fzz * bz5) + Qz0 * g0_5 + Qz1 * g1_5 + Qz2 * g2_5 + Qz3 * g3_5
        fe[e, 18] = V * (fxx * bx6 + txy * by6 + tzx * bz6) + Qx0 * g0_6 + Qx1 * g1_6 + Qx2 * g2_6 + Qx3 * g3_6
        fe[e, 19] = V * (txy * bx6 + fyy * by6 + tyz * bz6) + Qy0 * g0_6 + Qy1 * g1_6 + Qy2 * g2_6 + Qy3 * g3_6
        fe[e, 20] = V * (tzx * bx6 + tyz * by6 + fzz * bz6) + Qz0 * g0_6 + Qz1 * g1_6 + Qz2 * g2_6 + Qz3 * g3_6
        fe[e, 21] = V * (fxx * bx7 + txy * by7 + tzx * bz7) + Qx0 * g0_7 + Qx1 * g1_7 + Qx2 * g2_7 + Qx3 * g3_7
        fe[e, 22] = V * (txy * bx7 + fyy * by7 + tyz * bz7) + Qy0 * g0_7 + Qy1 * g1_7 + Qy2 * g2_7 + Qy3 * g3_7
        fe[e, 23] = V * (tzx * bx7 + tyz * by7 + fzz * bz7) + Qz0 * g0_7 + Qz1 * g1_7 + Qz2 * g2_7 + Qz3 * g3_7
        if dmg[e] >= 1.0 and erosion == ERODE_LAYER and layer[e]:
            alive[e] = 0

    return hex_element_py


#: CPU version. ``fastmath`` with FMA contraction only: reassociation, reciprocal
#: approximations or no-signed-zeros make the code numba loads from its cache compute other
#: last bits than the code it compiles in the process (a tool-frame run then differs by about
#: 1e-5 between the two: docs/fe3d.md); contraction alone gives one set of digits either way.
#: The Johnson-Cook callees keep their own flags (fastmath off: ``robobore.material.johnson_cook``),
#: so the material law has the same digits here as in the 2D engine.
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
hex_element_py = make_hex_element(jc_return, jc_damage_increment)
hex_element = njit(cache=False, fastmath={"contract"})(hex_element_py)
