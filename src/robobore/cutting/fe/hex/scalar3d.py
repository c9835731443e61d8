"""The 3D engine's state layout and scalar functions (hexahedra, SI units, forces in N).

The index layout of the tool state and of the history columns, and the per-node and tool
updates, written in the device-ready style of the 2D engine (``_py`` original + ``njit``):
the CPU loops of :mod:`robobore.cutting.fe.engine.kernels3d` call the ``njit`` versions and the GPU
kernels of :mod:`robobore.cutting.fe.engine.gpu.kernels3d` the device versions of the same code.

* :func:`insert_gap3_py` -- signed distance of a point to a boring insert with nose radius,
  approach and end-edge angles, rake, clearance, edge radius and inclination;
* :func:`contact_force3_py` -- the 2D contact law (:func:`tool_contact.contact_force_py`: mass-
  proportional penalty, viscous normal damping, Coulomb friction, shear-stress cap) with a
  tangential *vector*;
* :func:`friction_at3_py` -- the 2D engine's friction table lookup
  (:func:`robobore.cutting.fe.quad.node_contact.make_friction_at`, the same code made for the 3D
  parameter slots);
* :func:`hex_node_py` -- gather, contact and central-difference update of one node;
* :func:`tool_kinematics_py`, :func:`tool_step_py` -- the tool's position and its support's
  step in the boring frame; :func:`lane_sum3_py` -- one lane of the contact-force total;
  :func:`is_conduction_step_py` -- the steps that end with a conduction pass.

Frames: see :mod:`robobore.cutting.fe.engine.kernels3d`.
"""

from __future__ import annotations

import math

from numba import njit

from robobore.cutting.fe.hex.layout3d import (
    P_CDAMP,
    P_CLR,
    P_COND_EVERY,
    P_CX,
    P_CY,
    P_CZ,
    P_GATE,
    P_KAPPA,
    P_KEND,
    P_KX,
    P_KY,
    P_KZ,
    P_MU,
    P_MUTAB_MU,
    P_MUTAB_N,
    P_MUTAB_V,
    P_MX,
    P_MY,
    P_MZ,
    P_PEN,
    P_RADIUS,
    P_RAKE,
    P_RE,
    P_RN,
    P_SLIP_TAU,
    P_SUPPORT,
    P_TANI,
    P_TAU,
    P_TOOL,
    P_VC,
    P_VF,
)
from robobore.cutting.fe.physics.tool_contact import normal_force, tool_gap, tool_support_step
from robobore.cutting.fe.quad.node_contact import make_friction_at

__all__ = [
    "FIX_X", "FIX_Y", "FIX_Z", "T_GX", "T_GY", "T_GZ", "T_UX", "T_UY", "T_UZ", "T_VX", "T_VY",
    "T_VZ", "T_FX", "T_FY", "T_FZ", "T_THETA", "N_TOOL", "H_T", "H_FX", "H_FY", "H_FZ", "H_UX",
    "H_UY", "H_UZ", "H_TIPX", "H_THETA", "H_EKIN", "H_EINT", "H_EPL", "H_EHG", "H_EFRIC",
    "H_EEXT", "H_EERO", "H_NCONT", "N_HIST", "edge_section_py", "edge_section",
    "insert_gap3_py", "contact_force3_py", "insert_gap3", "contact_force3", "friction_at3_py",
    "friction_at3", "hex_node_py", "hex_node", "tool_kinematics_py", "tool_kinematics",
    "tool_step_py", "tool_step", "lane_sum3_py", "lane_sum3", "is_conduction_step_py",
    "is_conduction_step",
]

# --- fixed-dof bit mask (velocity component held at its current value)
FIX_X, FIX_Y, FIX_Z = 1, 2, 4
# --- tool state: guide (tip reference) position, local frame [m]; support displacement and
# velocity in the boring frame [m, m/s]; force on the tool, local frame [N]; bar angle [rad]
T_GX, T_GY, T_GZ, T_UX, T_UY, T_UZ, T_VX, T_VY, T_VZ = 0, 1, 2, 3, 4, 5, 6, 7, 8
T_FX, T_FY, T_FZ, T_THETA = 9, 10, 11, 12
N_TOOL = 13
# --- history columns, in the order of robobore.cutting.fe.engine.history: the time [s]; the time
# averages over each sample interval (force on the tool, local frame [N]; tool support
# displacement, boring frame [m]; contact nodes); the guide's x [m] and the bar angle [rad];
# the energies at the interval's end [J]
H_T, H_FX, H_FY, H_FZ, H_UX, H_UY, H_UZ, H_NCONT = range(8)
H_TIPX, H_THETA = 8, 9
H_EKIN, H_EINT, H_EPL, H_EHG, H_EFRIC, H_EEXT, H_EERO = range(10, 17)
N_HIST = 17


def edge_section_py(py, pz, rn, kappa, kend, re):
    """Position of a point relative to the insert's edge profile, in the y-z plane.

    The edge profile is the nose arc of radius ``rn`` (centre at y = rn, z = 0) spanning
    local approach angles -kend..kappa, continued by the major edge (approach angle
    ``kappa``) and the minor edge (end-edge angle ``kend``). Returns ``(s, arc, my, mz)``:
    ``s`` the distance of the point from the wedge apex line (the profile offset by the edge
    radius ``re`` into the tool), positive out of the tool, so the profile itself (the
    lowest points of the edge in its normal sections) is ``s = re``; ``arc`` the arc length
    along the edge from the tip; ``(my, mz)`` the unit outward normal of the profile there.
    """
    ra = rn - re
    qz = pz
    qy = py - rn
    psi = math.atan2(qz, -qy)
    if psi > kappa:
        mz = math.sin(kappa)
        my = -math.cos(kappa)
        s = (qz - ra * mz) * mz + (qy - ra * my) * my
        arc = rn * kappa - (qz - ra * mz) * my + (qy - ra * my) * mz
    elif psi < -kend:
        mz = -math.sin(kend)
        my = -math.cos(kend)
        s = (qz - ra * mz) * mz + (qy - ra * my) * my
        arc = -rn * kend - ((qz - ra * mz) * my - (qy - ra * my) * mz)
    else:
        d = math.sqrt(qz * qz + qy * qy)
        if d < 1e-300:
            d = 1e-300
        mz = qz / d
        my = qy / d
        s = d - ra
        arc = rn * psi
    return s, arc, my, mz


edge_section = njit(cache=True, inline="always")(edge_section_py)


def make_insert_gap3(tool_gap, edge_section):
    """:func:`insert_gap3_py` with its callees ``tool_gap``, ``edge_section`` given (the
    CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def insert_gap3_py(px, py, pz, rn, kappa, kend, rake, clr, re, tani):
        """Signed distance of a point to the boring insert and the insert's outward normal.

        ``(px, py, pz)`` [m] is the point relative to the insert's tip reference (the lowest
        point of the nose, on the cutting edge) in the local frame (x cutting direction, y out
        of the workpiece, z feed). The edge profile in the y-z plane is the nose arc of radius
        ``rn`` (centre at y = rn, z = 0) spanning local approach angles -kend..kappa, continued
        by the major edge (approach angle ``kappa`` to the feed axis) and the minor (end) edge
        (angle ``kend``). In every normal section of the edge the insert is the 2D wedge of the
        2D engine (:func:`tool_contact.tool_gap_py`: normal rake ``rake``, clearance ``clr``,
        edge radius ``re`` [rad, m]); the wedge apex runs along the profile offset by ``re``
        into the tool. The inclination enters as ``x -> x - tani * s`` with ``s`` the arc length
        along the edge from the tip (small-angle model). Exact for points in a normal section;
        near the surface (where contact acts) the error is second order in the distance.

        Returns ``(gap, nx, ny, nz)``: gap > 0 outside, < 0 penetration depth [m]; unit normal.
        """
        s, arc, my, mz = edge_section(py, pz, rn, kappa, kend, re)
        u = px - tani * arc
        # 2D wedge of the 2D engine, mirrored (it cuts along -x): apex at the origin
        gap, n2x, n2y = tool_gap(-u, -s, 0.0, 0.0, -math.cos(rake), math.sin(rake),
                                 math.sin(clr), -math.cos(clr), re)
        # local "up" (into the tool, normal to the edge in the profile plane) is -m
        return gap, -n2x, -n2y * my, -n2y * mz

    return insert_gap3_py


def make_contact_force3(normal_force):
    """:func:`contact_force3_py` with its callees ``normal_force`` given (the CPU's
    compiled functions here, a GPU engine's device functions in its port)."""

    def contact_force3_py(gap, normal, vr, fo, mass, trib_area, dt, law):
        """Contact force on a node touching the rigid insert [N] (3D form of the 2D law).

        ``gap`` the signed gap [m] (< 0: penetration), ``normal`` = ``(nx, ny, nz)`` the
        insert's outward unit normal, ``vr`` = ``(vrx, vry, vrz)`` the node's velocity relative
        to the tool [m/s], ``fo`` = ``(fox, foy, foz)`` the node's element forces this step
        [N], ``mass`` the node's (scaled) mass [kg], ``trib_area`` its tributary contact area
        [m^2], ``dt`` the time step [s], ``law`` = ``(mu, tau_max, pen_factor, damping)``: the
        Coulomb coefficient, the shear-stress cap [Pa], the penalty factor and the fraction of
        critical damping (all but ``tau_max`` dimensionless), as
        :func:`tool_contact.contact_force_py`.

        Normal: :func:`tool_contact.normal_force_py` (penalty plus viscous damping on the
        relative normal velocity, kept >= 0), as :func:`tool_contact.contact_force_py`.
        Tangential: the same return mapping on the trial sliding velocity (the tangential part
        of ``v_r + dt fo / mass``): the force that stops it in one step, limited by Coulomb
        ``mu Fn`` and by the shear cap ``tau_max * trib_area``, opposite to the trial sliding
        direction.

        Returns ``(fx, fy, fz, fn, ft, tx, ty, tz, fd)``: force, normal magnitude, tangential
        magnitude, the unit sliding direction (zero vector when not sliding) and the damping part
        of the normal magnitude.
        """
        if gap >= 0.0:
            return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        nx, ny, nz = normal
        vrx, vry, vrz = vr
        fox, foy, foz = fo
        mu, tau_max, pen_factor, damping = law
        fn, fd = normal_force(gap, vrx * nx + vry * ny + vrz * nz, mass, pen_factor, dt, damping)
        wx = vrx + dt * fox / mass
        wy = vry + dt * foy / mass
        wz = vrz + dt * foz / mass
        vn = wx * nx + wy * ny + wz * nz
        vtx = wx - vn * nx
        vty = wy - vn * ny
        vtz = wz - vn * nz
        vt = math.sqrt(vtx * vtx + vty * vty + vtz * vtz)
        if vt <= 0.0:
            return fn * nx, fn * ny, fn * nz, fn, 0.0, 0.0, 0.0, 0.0, fd
        tx = vtx / vt
        ty = vty / vt
        tz = vtz / vt
        fstick = mass * vt / dt
        fcap = mu * fn
        if tau_max * trib_area < fcap:
            fcap = tau_max * trib_area
        ft = fstick if fstick < fcap else fcap
        return (fn * nx - ft * tx, fn * ny - ft * ty, fn * nz - ft * tz, fn, ft, tx, ty, tz, fd)

    return contact_force3_py


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
insert_gap3_py = make_insert_gap3(tool_gap, edge_section)
insert_gap3 = njit(cache=False)(insert_gap3_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
contact_force3_py = make_contact_force3(normal_force)
contact_force3 = njit(cache=False)(contact_force3_py)

#: Coulomb coefficient at a sliding speed [m/s]: the 2D engine's lookup
#: (:func:`robobore.cutting.fe.quad.node_contact.make_friction_at`: the constant ``prm[P_MU]``
#: when ``prm[P_MUTAB_N]`` = 0, else the table, linear between its points, constant beyond its
#: ends) made for the 3D engine's parameter slots
friction_at3_py = make_friction_at(P_MU, P_MUTAB_N, P_MUTAB_V, P_MUTAB_MU, "friction_at3_py")
friction_at3 = njit(cache=False, inline="always")(friction_at3_py)


def make_hex_node(insert_gap3, contact_force3, friction_at3):
    """:func:`hex_node_py` with its callees ``insert_gap3``, ``contact_force3``,
    ``friction_at3`` given (the CPU's compiled functions here, a GPU engine's device
    functions in its port)"""

    def hex_node_py(n, x, y, z, vx, vy, vz, mass, fixed, ptr, nel, ncorner, alive, vol0, fe, cf,
                    fric, pen, ndead, ero_ke, nwork, prm, cx, cy, cz, tvx, tvy, tvz, dt, pairs):
        """Gather element forces on node ``n``, add insert contact, advance v and x (one node).

        Contact uses positions at step n and velocities at n-1/2 (as the 2D engine).
        ``cf[n, 0:3]`` receives the contact force on the node [N] (``cf[n, 3]``: its filtered
        sliding speed, kept from step to step; one (n, 4) array rather than two, see below);
        ``fric`` (cumulative) frictional dissipation, ``pen`` the current penalty energy,
        ``nwork`` (cumulative) the contact work [J]. A node left without a live element is
        retired (its kinetic energy booked in ``ero_ke``).
        ``fixed[n]`` bit mask (1 x, 2 y, 4 z): that velocity component is held (prescribed).
        ``(cx, cy, cz)`` tool tip reference, ``(tvx, tvy, tvz)`` tool velocity (local frame).

        Friction (the 2D engine's rule, :func:`quad.node_contact.quad_node_py`): the constant
        ``prm[P_MU]``, or with a table (``prm[P_MUTAB_N]`` > 0) the table at the node's sliding
        speed relative to the insert (the tangential part of its relative velocity), low-pass
        filtered with the time constant ``prm[P_SLIP_TAU]`` and kept in ``cf[n, 3]`` [m/s]
        (:func:`friction_at3_py`).

        Node splitting (the 2D engine's rule, :func:`quad.node_contact.node_update`): ``pairs[n]`` =
        (twin, tied); a node with ``twin >= 0`` and ``tied`` moves with its twin as one node --
        forces and masses of both copies summed in a fixed order (lower id first) so that both
        stay bitwise identical, the contact force computed once with the pair's mass and booked
        half on each copy. The pair is released (``tied`` = 0 on both, which compute the same
        gap) when it comes within ``prm[P_GATE]`` of the insert: the material parts where it
        meets the edge.
        (One (n, 2) array rather than two: with one more array argument LLVM stops inlining this
        function into the node loops, which then run 40 % slower.)
        """
        cf[n, 0] = 0.0
        cf[n, 1] = 0.0
        cf[n, 2] = 0.0
        pen[n] = 0.0
        if ndead[n]:
            return
        tw = pairs[n, 0]
        pair = tw >= 0 and pairs[n, 1] != 0
        # a tied pair: both copies gather in the same order (lower id first), bitwise equal sums
        na = min(n, tw) if pair else n
        nb = max(n, tw) if pair else -1
        share = 0.5 if pair else 1.0
        fx = 0.0
        fy = 0.0
        fz = 0.0
        nlive = 0
        vsum = 0.0
        m = 0.0
        for j in range(2):
            nk = na if j == 0 else nb
            if nk < 0:
                continue
            m += mass[nk]
            for k in range(ptr[nk], ptr[nk + 1]):
                e = nel[k]
                if alive[e] == 1:
                    c3 = 3 * ncorner[k]
                    fx -= fe[e, c3]
                    fy -= fe[e, c3 + 1]
                    fz -= fe[e, c3 + 2]
                    nlive += 1
                    vsum += vol0[e]
        if nlive == 0:
            ndead[n] = 1
            ero_ke[n] = 0.5 * mass[n] * (vx[n] * vx[n] + vy[n] * vy[n] + vz[n] * vz[n])
            vx[n] = 0.0
            vy[n] = 0.0
            vz[n] = 0.0
            return
        fcx = 0.0
        fcy = 0.0
        fcz = 0.0
        ft = 0.0
        vt0 = 0.0
        tx = 0.0
        ty = 0.0
        tz = 0.0
        fd = 0.0
        vn0 = 0.0
        gnx = 0.0
        gny = 0.0
        gnz = 0.0
        gap = 1.0
        fb = fixed[n]  # held velocity components: no element force in the trial slip, no update
        px = x[n] - cx
        # cheap bound: a node ahead of the rounded edge and of a non-negative-rake face is free
        # (and farther than the separation gate)
        ahead = prm[P_RE] + (prm[P_GATE] if prm[P_GATE] > 0.0 else 0.0)
        if prm[P_TOOL] > 0.5 and not (px > ahead and prm[P_RAKE] >= 0.0 and prm[P_TANI] == 0.0):
            gap, gnx, gny, gnz = insert_gap3(px, y[n] - cy, z[n] - cz, prm[P_RN],
                                             prm[P_KAPPA], prm[P_KEND], prm[P_RAKE], prm[P_CLR],
                                             prm[P_RE], prm[P_TANI])
            if pair and gap <= prm[P_GATE]:
                pairs[n, 1] = 0
            if gap < 0.0:
                vrx = vx[n] - tvx
                vry = vy[n] - tvy
                vrz = vz[n] - tvz
                trib = (vsum / nlive) ** (2.0 / 3.0)
                mu = prm[P_MU]
                if prm[P_MUTAB_N] > 0.0:
                    # the sliding speed, filtered over the time constant prm[P_SLIP_TAU]: a
                    # contact node's velocity chatters from step to step, its mean is the
                    # material's sliding speed
                    vrn = vrx * gnx + vry * gny + vrz * gnz
                    sx = vrx - vrn * gnx
                    sy = vry - vrn * gny
                    sz = vrz - vrn * gnz
                    tau_s = prm[P_SLIP_TAU]
                    a = dt / tau_s if tau_s > dt else 1.0  # tau_s <= dt: no filter
                    vs = cf[n, 3] + a * (math.sqrt(sx * sx + sy * sy + sz * sz) - cf[n, 3])
                    cf[n, 3] = vs
                    mu = friction_at3(prm, vs)
                fcx, fcy, fcz, fn, ft, tx, ty, tz, fd = contact_force3(
                    gap, (gnx, gny, gnz), (vrx, vry, vrz),
                    (0.0 if (fb & 1) else fx, 0.0 if (fb & 2) else fy, 0.0 if (fb & 4) else fz),
                    m, trib, dt, (mu, prm[P_TAU], prm[P_PEN], prm[P_CDAMP]))
                vt0 = vrx * tx + vry * ty + vrz * tz
                if fd != 0.0:
                    vn0 = vrx * gnx + vry * gny + vrz * gnz
                pen[n] = share * 0.5 * (fn - fd) * (-gap)
        cf[n, 0] = share * fcx
        cf[n, 1] = share * fcy
        cf[n, 2] = share * fcz
        ox = vx[n]
        oy = vy[n]
        oz = vz[n]
        nvx = ox if (fb & 1) else ox + dt * (fx + fcx) / m
        nvy = oy if (fb & 2) else oy + dt * (fy + fcy) / m
        nvz = oz if (fb & 4) else oz + dt * (fz + fcz) / m
        vx[n] = nvx
        vy[n] = nvy
        vz[n] = nvz
        x[n] += dt * nvx
        y[n] += dt * nvy
        z[n] += dt * nvz
        if gap < 0.0:
            nwork[n] += share * dt * (fcx * 0.5 * (ox + nvx) + fcy * 0.5 * (oy + nvy)
                                      + fcz * 0.5 * (oz + nvz))
            vt1 = (nvx - tvx) * tx + (nvy - tvy) * ty + (nvz - tvz) * tz
            fric[n] += share * dt * ft * 0.5 * (vt0 + vt1)
            if fd != 0.0:  # contact damping: booked with the frictional dissipation
                vn1 = (nvx - tvx) * gnx + (nvy - tvy) * gny + (nvz - tvz) * gnz
                fric[n] -= share * dt * fd * 0.5 * (vn0 + vn1)

    return hex_node_py


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
hex_node_py = make_hex_node(insert_gap3, contact_force3, friction_at3)
hex_node = njit(cache=False)(hex_node_py)


def tool_kinematics_py(tool, prm):
    """Tool tip position and velocity in the local frame from the tool state.

    The support displacement/velocity (boring frame) is rotated into the local frame of the
    run with the current bar angle: e_x = e_t = (-sin th, cos th, 0), e_y = -e_r, e_z = Z.
    Returns ``(cx, cy, cz, vx, vy, vz)`` [m, m/s].
    """
    th = tool[T_THETA]
    s = math.sin(th)
    c = math.cos(th)
    ux = -s * tool[T_UX] + c * tool[T_UY]
    uy = -c * tool[T_UX] - s * tool[T_UY]
    wx = -s * tool[T_VX] + c * tool[T_VY]
    wy = -c * tool[T_VX] - s * tool[T_VY]
    return (tool[T_GX] + ux, tool[T_GY] + uy, tool[T_GZ] + tool[T_UZ], prm[P_VC] + wx, wy,
            prm[P_VF] + tool[T_VZ])


tool_kinematics = njit(cache=True)(tool_kinematics_py)


def make_tool_step(tool_kinematics, tool_support_step):
    """:func:`tool_step_py` with its callees ``tool_kinematics``, ``tool_support_step``
    given (the CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def tool_step_py(tool, prm, fwx, fwy, fwz, dt):
        """Advance the tool one step given the contact force ON THE WORKPIECE (local) [N].

        Stores the force on the tool (local), steps the three boring-frame spring-damper units
        (:func:`tool_contact.tool_support_step_py`; force rotated with the bar angle), moves the
        guide (cutting speed along x, feed speed along z) and the bar angle. Returns the work done
        on the workpiece during the step [J] (tool velocity averaged over the step).
        """
        cx, cy, cz, tvx, tvy, tvz = tool_kinematics(tool, prm)
        tool[T_FX] = -fwx
        tool[T_FY] = -fwy
        tool[T_FZ] = -fwz
        if prm[P_SUPPORT] > 0.5:
            th = tool[T_THETA]
            s = math.sin(th)
            c = math.cos(th)
            FX = -s * (-fwx) - c * (-fwy)
            FY = c * (-fwx) - s * (-fwy)
            ux, vux = tool_support_step(tool[T_UX], tool[T_VX], FX, prm[P_KX], prm[P_CX],
                                        prm[P_MX], dt)
            uy, vuy = tool_support_step(tool[T_UY], tool[T_VY], FY, prm[P_KY], prm[P_CY],
                                        prm[P_MY], dt)
            uz, vuz = tool_support_step(tool[T_UZ], tool[T_VZ], -fwz, prm[P_KZ], prm[P_CZ],
                                        prm[P_MZ], dt)
            tool[T_UX] = ux
            tool[T_VX] = vux
            tool[T_UY] = uy
            tool[T_VY] = vuy
            tool[T_UZ] = uz
            tool[T_VZ] = vuz
        tool[T_GX] += prm[P_VC] * dt
        tool[T_GZ] += prm[P_VF] * dt
        if prm[P_RADIUS] > 0.0:
            tool[T_THETA] += prm[P_VC] * dt / prm[P_RADIUS]
        cx2, cy2, cz2, tvx2, tvy2, tvz2 = tool_kinematics(tool, prm)
        return dt * (fwx * 0.5 * (tvx + tvx2) + fwy * 0.5 * (tvy + tvy2) + fwz * 0.5 * (tvz + tvz2))

    return tool_step_py


# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
tool_step_py = make_tool_step(tool_kinematics, tool_support_step)
tool_step = njit(cache=False)(tool_step_py)


def lane_sum3_py(cf, lane, lanes):
    """Lane ``lane`` of :func:`contact_total3`: the sums of ``cf[n, 0:3]`` over ``n = lane,
    lane + lanes, ...`` in index order and the number of those nodes in contact."""
    sx = 0.0
    sy = 0.0
    sz = 0.0
    nc = 0
    for n in range(lane, cf.shape[0], lanes):
        if cf[n, 0] != 0.0 or cf[n, 1] != 0.0 or cf[n, 2] != 0.0:
            sx += cf[n, 0]
            sy += cf[n, 1]
            sz += cf[n, 2]
            nc += 1
    return sx, sy, sz, nc


lane_sum3 = njit(cache=True, inline="always")(lane_sum3_py)


def is_conduction_step_py(step, prm):
    """True where step number ``step`` (counted from 0) ends with a conduction pass."""
    every = int(prm[P_COND_EVERY])
    return every > 0 and step % every == 0


is_conduction_step = njit(cache=True, inline="always")(is_conduction_step_py)
