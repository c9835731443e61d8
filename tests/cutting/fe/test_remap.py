"""The donor-cell remap of the ALE pass (:mod:`robobore.cutting.fe.ale.remap`) on a small
structured mesh whose interior nodes move at random (the outline stays, so no edge on it
sweeps area): the element mass and the integrals of the remapped fields are conserved to
round-off, a uniform field stays uniform, a linear velocity field is remapped exactly
(first-order Taylor with the exact element gradient), and the lumped nodal masses follow the
remapped element masses. The scalar ``_py`` passes are what the CPU pass and the GPU kernels
compile.
"""

from __future__ import annotations

import numpy as np
import pytest

from robobore.cutting.fe.ale.remap import (
    N_RZ_FIELDS,
    rz_flux_py,
    rz_node_mass_py,
    rz_velocity_py,
    rz_write_py,
)
from robobore.cutting.fe.ale.stencils import edge_neighbours

NX, NY, H = 7, 6, 10e-6
RHO_S = 4430.0 * 100.0


def _grid(seed: int):
    """Nodes, counter-clockwise quads, node-to-element lists and the moved interior nodes."""
    i, j = np.meshgrid(np.arange(NX), np.arange(NY))
    x = (i.ravel() * H).astype(float)
    y = (j.ravel() * H).astype(float)
    conn = np.array([[jj * NX + ii, jj * NX + ii + 1, (jj + 1) * NX + ii + 1, (jj + 1) * NX + ii]
                     for jj in range(NY - 1) for ii in range(NX - 1)], np.int64)
    counts = np.bincount(conn.ravel(), minlength=x.size)
    ptr = np.zeros(x.size + 1, np.int64)
    ptr[1:] = np.cumsum(counts)
    order = np.argsort(conn.ravel(), kind="stable")
    nel = (order // 4).astype(np.int64)
    interior = np.array([n for n in range(x.size)
                         if 0 < n % NX < NX - 1 and 0 < n // NX < NY - 1], np.int64)
    rng = np.random.default_rng(seed)
    # a distorted starting mesh, then the pass's target positions (at most 0.1 H away)
    x[interior] += 0.15 * H * rng.uniform(-1, 1, interior.size)
    y[interior] += 0.15 * H * rng.uniform(-1, 1, interior.size)
    xn, yn = x.copy(), y.copy()
    xn[interior] += 0.07 * H * rng.uniform(-1, 1, interior.size)
    yn[interior] += 0.07 * H * rng.uniform(-1, 1, interior.size)
    return x, y, xn, yn, conn, ptr, nel, interior, rng


def _areas(x, y, c):
    return 0.5 * ((x[c[:, 2]] - x[c[:, 0]]) * (y[c[:, 3]] - y[c[:, 1]])
                  + (x[c[:, 1]] - x[c[:, 3]]) * (y[c[:, 2]] - y[c[:, 0]]))


def _remap(x, y, xn, yn, vx, vy, conn, ptr, nel, interior, f, area0, mass):
    """One remap in the order of the ALE pass (fluxes, velocities, write, positions, masses)."""
    ne = conn.shape[0]
    alive = np.ones(ne, np.int64)
    enbr = edge_neighbours(conn)
    buf = np.zeros((ne, N_RZ_FIELDS))
    vbuf = np.zeros((x.size, 2))
    for e in range(ne):
        rz_flux_py(e, conn, alive, (x, y), (xn, yn), enbr, np.zeros((0, 4), np.int64), buf,
                   (f, area0), 293.0)
    moved = sum(rz_velocity_py(n, x, y, xn, yn, vx, vy, ptr, nel, conn, vbuf)
                for n in interior)
    vx[interior] += vbuf[interior, 0]
    vy[interior] += vbuf[interior, 1]
    for e in range(ne):
        rz_write_py(e, alive, buf, f, area0)
    x[:] = xn
    y[:] = yn
    for n in range(x.size):
        rz_node_mass_py(n, ptr, nel, area0, RHO_S, mass)
    return moved


def _fields(ne, rng):
    """The element state (N_QS, e), rows sdx, sdy, sdz, sdxy, pres, eps_p, temp, dmg, qhx, qhy:
    random but temp uniform."""
    f = np.array([rng.standard_normal(ne) for _ in range(10)])
    f[6][:] = 500.0
    return f


@pytest.mark.parametrize("seed", [1, 2])
def test_remap_conserves_mass_and_field_integrals(seed):
    x, y, xn, yn, conn, ptr, nel, interior, rng = _grid(seed)
    ne = conn.shape[0]
    f = _fields(ne, rng)
    a_old = _areas(x, y, conn)
    area0 = a_old * (1.0 + 0.01 * rng.standard_normal(ne))
    mass0 = area0.sum()
    ints_old = [np.sum(g * a_old) for g in f]
    scale = [np.sum(np.abs(g) * a_old) for g in f]
    mass = np.zeros(x.size)
    moved = _remap(x, y, xn, yn, np.zeros(x.size), np.zeros(x.size), conn, ptr, nel,
                   interior, f, area0, mass)
    assert moved == interior.size
    a_new = _areas(x, y, conn)
    assert area0.sum() == pytest.approx(mass0, rel=1e-13)
    for g, o, sc in zip(f, ints_old, scale, strict=True):
        assert abs(np.sum(g * a_new) - o) <= 1e-12 * sc
    np.testing.assert_allclose(f[6], 500.0, rtol=1e-12)
    # the state changed (the test is not trivially satisfied by a pass that moves nothing)
    assert np.max(np.abs(a_new - a_old)) > 1e-3 * H * H
    m = np.zeros(x.size)
    np.add.at(m, conn.ravel(), np.repeat(0.25 * RHO_S * area0, 4))
    np.testing.assert_allclose(mass, m, rtol=1e-12)


def test_remap_moves_a_linear_velocity_field_exactly():
    x, y, xn, yn, conn, ptr, nel, interior, rng = _grid(3)
    ne = conn.shape[0]
    a, b, c, d = 0.3, 2.0e4, -0.1, 5.0e3
    vx = a + b * y
    vy = c + d * x
    _remap(x, y, xn, yn, vx, vy, conn, ptr, nel, interior, _fields(ne, rng),
           _areas(x, y, conn), np.zeros(x.size))
    np.testing.assert_allclose(vx, a + b * y, rtol=0, atol=1e-12)
    np.testing.assert_allclose(vy, c + d * x, rtol=0, atol=1e-12)
