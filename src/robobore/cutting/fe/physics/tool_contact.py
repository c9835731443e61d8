"""The tool and its contact in the FE cutting engine (shared by the CPU and GPU engines); the
Johnson-Cook flow stress, failure strain, damage increment and radial return the engines use
are :mod:`robobore.material.johnson_cook`'s.

Plain-Python originals (suffix ``_py``) and their ``numba.njit(cache=True)`` versions:

* :func:`tool_face_py` -- the face of the tool (rake, edge arc, flank) closest to a point;
* :func:`tool_gap_py` -- signed distance of a point to the analytic rigid tool (rake face,
  edge-radius arc, flank with clearance) and the outward normal;
* :func:`normal_force_py` -- penalty normal force (optionally damped), shared by the 2D and
  3D contact laws;
* :func:`contact_force_py` -- that normal force, Coulomb friction with a shear-stress cap;
* :func:`tool_support_step_py` -- one central-difference step of a mass on a spring/damper.

All take and return floats and allocate nothing (device-function ready). A function that calls
another is written inside a factory that receives its callees (:func:`make_tool_gap`,
:func:`make_contact_force`): the CPU versions here are made from the compiled callees, a GPU
engine's from device functions.
"""

from __future__ import annotations

import math

from numba import njit

#: faces of the analytic tool (:func:`tool_face_py`)
FACE_RAKE, FACE_EDGE, FACE_FLANK = 0, 1, 2


def tool_face_py(dx, dy, nrx, nry, nfx, nfy):
    """Which face of the tool is closest to the point at (dx, dy) from the edge centre:
    FACE_RAKE or FACE_FLANK where the point's projection falls on that face (a point inside
    the wedge goes to the nearer face), FACE_EDGE (the edge-radius arc) otherwise. Normals
    as in :func:`tool_gap_py`."""
    sr = dx * nrx + dy * nry
    sf = dx * nfx + dy * nfy
    if sr <= 0.0 and sf <= 0.0:
        return FACE_RAKE if sr >= sf else FACE_FLANK
    if sr > 0.0 and (dx * nry - dy * nrx) >= 0.0:
        return FACE_RAKE
    if sf > 0.0 and (-dx * nfy + dy * nfx) >= 0.0:
        return FACE_FLANK
    return FACE_EDGE


def make_tool_gap(tool_face):
    """:func:`tool_gap_py` with its callees ``tool_face`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def tool_gap_py(px, py, cx, cy, nrx, nry, nfx, nfy, r):
        """Signed gap of point (px, py) to the rigid tool and the tool's outward normal.

        The tool is the set of points within ``r`` (edge radius) of the wedge with apex at the
        edge centre (cx, cy) bounded by the rake face (outward unit normal (nrx, nry)) and the
        flank face (outward unit normal (nfx, nfy)). The rake face runs from the edge up along
        t_r = (nry, -nrx); the flank runs from the edge back along t_f = (-nfy, nfx). The closest
        face is :func:`tool_face_py`'s.

        Returns ``(gap, nx, ny)``: gap > 0 outside (distance to the surface), gap < 0 inside
        (penetration depth); (nx, ny) the outward normal of the closest surface point [m].
        """
        dx = px - cx
        dy = py - cy
        face = tool_face(dx, dy, nrx, nry, nfx, nfy)
        if face == FACE_RAKE:
            return dx * nrx + dy * nry - r, nrx, nry
        if face == FACE_FLANK:
            return dx * nfx + dy * nfy - r, nfx, nfy
        d = math.sqrt(dx * dx + dy * dy)
        return d - r, dx / d, dy / d

    return tool_gap_py


def normal_force_py(gap, vn, mass, pen_factor, dt, damping):
    """Normal contact force of the penalty law [N, or N per m of width in 2D]: the penalty
    ``pen_factor * mass / dt**2 * (-gap)`` plus the viscous damping ``-c vn`` with
    ``c = 2 damping sqrt(k m)`` (``vn`` the relative normal velocity [m/s]; ``damping`` the
    fraction of the penalty spring's critical damping, 0: none, and then not computed), the
    total kept >= 0 (no adhesion). For ``gap`` < 0. Returns ``(fn, fd)``: the normal force
    and its damping part. Shared by the 2D and 3D contact laws."""
    fp = pen_factor * mass / (dt * dt) * (-gap)
    fd = 0.0
    if damping > 0.0:
        fd = -2.0 * damping * math.sqrt(pen_factor) * mass / dt * vn
        if fp + fd < 0.0:
            fd = -fp
    return fp + fd, fd


def make_contact_force(normal_force):
    """:func:`contact_force_py` with its callees ``normal_force`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def contact_force_py(gap, normal, vr, fo, mass, trib_len, dt, law):
        """Contact force on a node touching the rigid tool [N per m of width].

        ``gap`` the signed gap [m] (< 0: penetration), ``normal`` = ``(nx, ny)`` the tool's
        outward unit normal, ``vr`` = ``(vrx, vry)`` the node's velocity relative to the tool
        [m/s], ``fo`` = ``(fox, foy)`` the node's other forces this step (its element forces)
        [N/m], ``mass`` the node's (scaled) mass [kg/m], ``trib_len`` its tributary contact
        length [m], ``dt`` the time step [s], ``law`` = ``(mu, tau_max, pen_factor, damping)``:
        the Coulomb coefficient, the shear-stress cap [Pa], the penalty factor and the
        fraction of critical damping (all but ``tau_max`` dimensionless).

        Normal: penalty ``Fn = pen_factor * mass / dt**2 * (-gap)`` (mass-proportional penalty,
        stable for ``pen_factor`` << 1 and independent of mass scaling: penetration under a force
        F is F dt^2 / (pen_factor m)), plus a viscous contact damping ``-c v_n`` on the relative
        normal velocity with ``c = 2 damping sqrt(k m)`` (``damping``: fraction of the contact
        spring's critical damping, as LS-DYNA's VDC; 0: none), the total kept >= 0 (no
        adhesion). Tangential: a return mapping on the trial sliding velocity ``vt* = vt + dt
        (fo . t) / mass`` -- the velocity the node would slide with after this step's other
        forces ``(fox, foy)`` [N/m] (its element forces) -- the stick force that stops it,
        ``mass |vt*| / dt``, limited by Coulomb ``mu * Fn`` and by the shear-stress cap
        ``tau_max * trib_len`` (the node's tributary contact length), opposite to ``vt*``.
        (Stopping only the start-of-step velocity instead would let the element forces
        re-accelerate the node every step: a viscous interface ``mass v / dt ~ rho c v`` that
        undercuts Coulomb wherever the contact pressure is high.)

        Returns ``(fx, fy, fn, ft, fd)`` with fn >= 0 the normal force, ft the signed tangential
        component along t = (-ny, nx) and fd the damping part of fn. Zero for gap >= 0.
        """
        if gap >= 0.0:
            return 0.0, 0.0, 0.0, 0.0, 0.0
        nx, ny = normal
        vrx, vry = vr
        fox, foy = fo
        mu, tau_max, pen_factor, damping = law
        fn, fd = normal_force(gap, vrx * nx + vry * ny, mass, pen_factor, dt, damping)
        tx = -ny
        ty = nx
        vt = vrx * tx + vry * ty + dt * (fox * tx + foy * ty) / mass
        fstick = mass * abs(vt) / dt
        fcap = mu * fn
        if tau_max * trib_len < fcap:
            fcap = tau_max * trib_len
        fmag = fstick if fstick < fcap else fcap
        ft = -fmag if vt > 0.0 else fmag
        return fn * nx + ft * tx, fn * ny + ft * ty, fn, ft, fd

    return contact_force_py


def tool_support_step_py(u, v, force, k, c, m, dt):
    """One central-difference step of m u'' + c u' + k u = force.

    ``u`` is the displacement at step n, ``v`` the velocity at n-1/2; returns
    ``(u_next, v_half_next)``. The damping term uses the average of v at n-1/2 and n+1/2
    (unconditionally stable in c); the spring is explicit (stable for dt < 2 sqrt(m/k)).
    """
    h = 0.5 * c * dt / m
    vn = (v * (1.0 - h) + dt * (force - k * u) / m) / (1.0 + h)
    return u + dt * vn, vn


tool_face = njit(cache=True, inline="always")(tool_face_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
tool_gap_py = make_tool_gap(tool_face)
tool_gap = njit(cache=False)(tool_gap_py)
normal_force = njit(cache=True, inline="always")(normal_force_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
contact_force_py = make_contact_force(normal_force)
contact_force = njit(cache=False)(contact_force_py)
tool_support_step = njit(cache=True)(tool_support_step_py)
