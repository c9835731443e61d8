"""Johnson-Cook plasticity and damage as scalar functions (SI units).

Every function here takes and returns plain floats and allocates nothing, so the same source
can be compiled for the CPU (``numba.njit``) and later for a GPU
(``numba.cuda.jit(device=True)``). The plain-Python originals keep the ``_py`` suffix; the
compiled versions (``njit``) drop it. A function that needs another one is written inside
a factory that receives its callees (``make_jc_return(jc_athermal, homologous_temperature)``,
``make_radial_return(jc_return)``, ``make_jc_failure_strain``, ``make_jc_damage_increment``):
the module makes the CPU versions from the compiled functions here, a GPU port makes its
device versions from device functions (``robobore.cutting.fe.engine.gpu.shared``). The factory
versions compile without numba's cache (numba cannot key a cache on a closure over compiled
functions); the FE engines' cached loops hold them.

References
----------
Johnson G.R., Cook W.H. (1983), "A constitutive model and data for metals subjected to large
strains, high strain rates and high temperatures", 7th Int. Symp. Ballistics, 541-547.
Johnson G.R., Cook W.H. (1985), "Fracture characteristics of three metals subjected to
various strains, strain rates, temperatures and pressures", Eng. Fract. Mech. 21, 31-48.
Simo J.C., Hughes T.J.R. (1998), *Computational Inelasticity*, Springer, sec. 3.3 (radial
return) -- the consistency equation solved here is their (3.3.10) with a rate- and
temperature-dependent yield stress.
"""

from __future__ import annotations

import math

from numba import njit

#: Indices of the Johnson-Cook parameters in the flat material array ``mat`` used by kernels.
A, B, N, C, M, EPS0, TROOM, TMELT = 0, 1, 2, 3, 4, 5, 6, 7
D1, D2, D3, D4, D5 = 8, 9, 10, 11, 12
E_MOD, NU, RHO, CP, KCOND, BETA_TQ = 13, 14, 15, 16, 17, 18
#: plastic strain beyond which the hardening term stays at its value (inf: none)
EPS_HMAX = 19
N_MAT = 20


def homologous_temperature_py(T, Troom, Tmelt):
    """T* = (T - Troom)/(Tmelt - Troom), clipped to [0, 1]."""
    ts = (T - Troom) / (Tmelt - Troom)
    if ts < 0.0:
        return 0.0
    if ts > 1.0:
        return 1.0
    return ts


def jc_athermal_py(eps_p, eps_rate, a, b, n, c, eps0, ehmax):
    """The strain and rate factors of the Johnson-Cook flow stress [Pa],
    (A + B eps_p^n) (1 + C ln(max(eps_rate/eps0, 1))), eps_p clipped to [0, ehmax]: the flow
    stress is this times the thermal factor 1 - T*^m (:func:`jc_return_py` computes that
    factor once per increment). ``ehmax`` (the material's hardening strain limit, inf for
    none) holds the hardening term at its value beyond that strain."""
    ep = eps_p if eps_p > 0.0 else 0.0
    ep = ep if ep < ehmax else ehmax
    hard = a + b * ep**n
    r = eps_rate / eps0
    rate = 1.0 + c * math.log(r) if r > 1.0 else 1.0
    return hard * rate


def jc_flow_stress_py(eps_p, eps_rate, T, a, b, n, c, m, eps0, Troom, Tmelt, ehmax):
    """Johnson-Cook flow stress [Pa].

    sigma_y = (A + B eps_p^n) (1 + C ln(max(eps_rate/eps0, 1))) (1 - T*^m).
    The rate term is clipped at eps_rate = eps0 (no strengthening below the reference rate,
    and no logarithm of zero); T* is clipped to [0, 1]; eps_p in the hardening term is
    clipped at ``ehmax`` (inf: the plain law).
    """
    ts = homologous_temperature(T, Troom, Tmelt)
    return jc_athermal(eps_p, eps_rate, a, b, n, c, eps0, ehmax) * (1.0 - ts**m)


def make_jc_failure_strain(homologous_temperature):
    """:func:`jc_failure_strain_py` with its callees ``homologous_temperature`` given (the
    CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def jc_failure_strain_py(triax, eps_rate, T, d1, d2, d3, d4, d5, eps0, Troom, Tmelt):
        """Johnson-Cook (1985) equivalent plastic strain at failure.

        eps_f = (D1 + D2 exp(D3 sigma*)) (1 + D4 ln(max(eps_rate/eps0, 1))) (1 + D5 T*),
        sigma* = mean stress / von Mises stress (triaxiality). Floored at 1e-3 so that the
        damage increment stays finite where the fit goes negative (high triaxiality).
        """
        r = eps_rate / eps0
        rate = 1.0 + d4 * math.log(r) if r > 1.0 else 1.0
        ts = homologous_temperature(T, Troom, Tmelt)
        ef = (d1 + d2 * math.exp(d3 * triax)) * rate * (1.0 + d5 * ts)
        if ef < 1e-3:
            ef = 1e-3
        return ef

    return jc_failure_strain_py


def make_jc_damage_increment(jc_failure_strain):
    """:func:`jc_damage_increment_py` with its callees ``jc_failure_strain`` given (the
    CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def jc_damage_increment_py(deps_p, triax, eps_rate, T, d1, d2, d3, d4, d5, eps0, Troom, Tmelt):
        """Damage increment dD = d(eps_p) / eps_f (Johnson-Cook 1985, linear accumulation)."""
        if deps_p <= 0.0:
            return 0.0
        return deps_p / jc_failure_strain(triax, eps_rate, T, d1, d2, d3, d4, d5, eps0, Troom,
                                          Tmelt)

    return jc_damage_increment_py


def make_jc_return(jc_athermal, homologous_temperature):
    """:func:`jc_return_py` with its callees ``jc_athermal``, ``homologous_temperature``
    given (the CPU's compiled functions here, a GPU engine's device functions in its port)."""

    def jc_return_py(q, eps_p, T, dt, G, a, b, n, c, m, eps0, Troom, Tmelt, ehmax):
        """Scalar Johnson-Cook return mapping: plastic strain increment and flow stress.

        Parameters
        ----------
        q:
            von Mises equivalent of the trial deviatoric stress, sqrt(3/2 s:s) [Pa].
        eps_p, T, dt, G:
            Equivalent plastic strain at the start of the increment [-], temperature [K] (held
            fixed over the increment), time increment [s], shear modulus [Pa].

        Returns
        -------
        (deps_p, sigma_y):
            Plastic strain increment (0.0 when the trial state is elastic) and the flow stress
            at the end of the increment [Pa]. A caller scales its trial deviator by
            ``sigma_y / q`` when ``deps_p > 0`` (radial return, any dimension).

        The scalar consistency equation q - 3 G d - sigma_y(eps_p + d, d/dt, T) = 0 is solved by
        Newton's method safeguarded by bisection on [0, q/(3G)]; f is strictly decreasing in d,
        so the root is unique.

        The start is the smaller of two upper bounds of the root: the perfectly plastic
        increment (q - sigma_y0) / (3 G), and the increment whose rate term alone takes the
        flow stress to q, dt eps0 exp((q / sigma_y0 - 1) / C) (sigma_y0: the flow stress at
        eps_p and the reference rate). The first alone overestimates the root by orders of
        magnitude at cutting rates (it ignores the 20-30 % the rate term adds), which cost
        ~10 safeguarded iterations a return; from the smaller bound Newton takes ~4
        (``benchmarks/jc_return_iterations.py``; docs/fe.md, "Model").
        """
        # T is held over the increment: the thermal factor is evaluated once; each iteration
        # then costs one power and one logarithm (flow stress and its derivative share them)
        therm = 1.0 - homologous_temperature(T, Troom, Tmelt) ** m
        sy0 = jc_athermal(eps_p, 0.0, a, b, n, c, eps0, ehmax) * therm
        if q <= sy0:
            return 0.0, sy0
        lo = 0.0
        hi = q / (3.0 * G)
        d = (q - sy0) / (3.0 * G)
        if c > 0.0 and sy0 > 0.0:
            x = (q / sy0 - 1.0) / c
            if x < 700.0:
                d_rate = dt * eps0 * math.exp(x)
                if d_rate < d:
                    d = d_rate
        for _ in range(60):
            ep = eps_p + d
            held = ep >= ehmax  # beyond the hardening strain limit: no hardening
            ep = ehmax if held else ep
            epn = ep**n
            hard = a + b * epn
            r = d / (dt * eps0)
            rate = 1.0 + c * math.log(r) if r > 1.0 else 1.0
            sy = hard * rate * therm
            f = q - 3.0 * G * d - sy
            if f == 0.0:
                break
            if f > 0.0:
                lo = d
            else:
                hi = d
            # derivative of sigma_y wrt d (hardening + rate), analytic
            if held:
                dhard = 0.0
            else:
                dhard = n * b * epn / ep if ep > 1e-12 else 1e12 * b
            drate = c / d if r > 1.0 else 0.0
            dsy = (dhard * rate + hard * drate) * therm
            fp = -3.0 * G - dsy
            dn = d - f / fp
            if not (dn > lo and dn < hi):
                dn = 0.5 * (lo + hi)
            if abs(dn - d) <= 1e-14 + 1e-12 * d:
                d = dn
                break
            d = dn
        return d, jc_athermal(eps_p + d, d / dt, a, b, n, c, eps0, ehmax) * therm

    return jc_return_py


def make_radial_return(jc_return):
    """:func:`radial_return_py` with its callees ``jc_return`` given (the CPU's compiled
    functions here, a GPU engine's device functions in its port)."""

    def radial_return_py(sxx, syy, szz, sxy, eps_p, T, dt, G, a, b, n, c, m, eps0, Troom, Tmelt,
                         ehmax):
        """Radial return of a trial deviatoric stress onto the Johnson-Cook yield surface.

        Parameters
        ----------
        sxx, syy, szz, sxy:
            Trial *deviatoric* stress components [Pa] (plane strain: xz = yz = 0).
        eps_p:
            Equivalent plastic strain at the start of the increment [-].
        T:
            Temperature [K] (held fixed over the increment, explicit coupling).
        dt:
            Time increment [s]; the plastic strain rate is d(eps_p)/dt.
        G:
            Shear modulus [Pa].

        Returns
        -------
        (sxx, syy, szz, sxy, deps_p, sigma_y):
            Returned deviatoric stress, plastic strain increment, flow stress at the end.

        The scalar solve is :func:`jc_return_py` (shared with the 3D engine).
        """
        q = math.sqrt(1.5 * (sxx * sxx + syy * syy + szz * szz + 2.0 * sxy * sxy))
        d, sy = jc_return(q, eps_p, T, dt, G, a, b, n, c, m, eps0, Troom, Tmelt, ehmax)
        if d <= 0.0:
            return sxx, syy, szz, sxy, 0.0, sy
        scale = sy / q
        return sxx * scale, syy * scale, szz * scale, sxy * scale, d, sy

    return radial_return_py


# fastmath=False on each: numba compiles a callee that does not set its flags with its first
# caller's (the 3D element's fastmath) and keeps, and caches, that one compilation for every
# later caller; set, the shared law has the same digits in every engine whatever compiled first
# (tests/material/test_johnson_cook.py)
homologous_temperature = njit(cache=True, fastmath=False)(homologous_temperature_py)
jc_athermal = njit(cache=True, fastmath=False)(jc_athermal_py)
jc_flow_stress = njit(cache=True, fastmath=False)(jc_flow_stress_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
jc_failure_strain_py = make_jc_failure_strain(homologous_temperature)
jc_failure_strain = njit(cache=False, fastmath=False)(jc_failure_strain_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
jc_damage_increment_py = make_jc_damage_increment(jc_failure_strain)
jc_damage_increment = njit(cache=False, fastmath=False)(jc_damage_increment_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
jc_return_py = make_jc_return(jc_athermal, homologous_temperature)
jc_return = njit(cache=False, fastmath=False)(jc_return_py)
# a closure over compiled functions: numba keys no cache on it (its callers' caches hold it)
radial_return_py = make_radial_return(jc_return)
radial_return = njit(cache=False, fastmath=False)(radial_return_py)


__all__ = [
    "make_jc_failure_strain",
    "make_jc_damage_increment",
    "make_jc_return",
    "make_radial_return",
    "homologous_temperature_py",
    "jc_athermal_py",
    "jc_flow_stress_py",
    "jc_failure_strain_py",
    "jc_damage_increment_py",
    "radial_return_py",
    "jc_return_py",
    "jc_return",
    "homologous_temperature",
    "jc_athermal",
    "jc_flow_stress",
    "jc_failure_strain",
    "jc_damage_increment",
    "radial_return",
]
