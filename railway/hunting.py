r"""Closed forms of wheelset hunting: Klingel's kinematic wavelength and the critical speed of a
wheelset held by a lateral and a yaw spring.

Kinematic oscillation (Klingel 1883)
------------------------------------
A wheelset with conical wheels of conicity λ, rolling radius r0 and half contact spacing l,
rolling without slip, moves on the sinusoid y'' + λ y / (r0 l) = 0 (primes: d/dx along the
track), of wavelength

.. math::

    L_K = 2\pi \sqrt{\frac{r_0\, l}{\lambda}}

(Wickens 2003, Sec. 2.2; EN 15302 defines the equivalent conicity of real profiles as the λ with
the same wavelength).  Its frequency at speed V is f = V / L_K.

Suspended wheelset (linear creep)
---------------------------------
Lateral displacement y and yaw ψ of a wheelset of mass m and yaw inertia I, held by a lateral
spring k_y and a yaw spring k_ψ to a frame moving at speed V; linear (Kalker) creep with the
longitudinal and lateral creep coefficients f11 = G a b C11 and f22 = G a b C22 of each contact;
spin creep, gravitational stiffness and the contact angle neglected (Wickens 2003, ch. 2; the
equations of ``../shared/notes/railway.md`` Sec. 4):

.. math::

    m\ddot y + \frac{2 f_{22}}{V}\dot y - 2 f_{22}\,\psi + k_y\, y = 0, \qquad
    I\ddot\psi + \frac{2 f_{11} l^2}{V}\dot\psi + \frac{2 f_{11} l\lambda}{r_0}\, y + k_\psi\,\psi = 0.

Its characteristic polynomial a4 s⁴ + a3 s³ + a2 s² + a1 s + a0 has

.. math::

    a_4 = m I,\quad a_3 = \frac{2(f_{22} I + f_{11} l^2 m)}{V},\quad
    a_2 = m k_\psi + I k_y + \frac{4 f_{11} f_{22} l^2}{V^2},\quad
    a_1 = \frac{2(f_{22} k_\psi + f_{11} l^2 k_y)}{V},\quad
    a_0 = k_y k_\psi + \frac{4 f_{11} f_{22} l \lambda}{r_0},

and the Routh–Hurwitz stability boundary a3 a2 a1 = a4 a1² + a3² a0, in which V enters only as
1/V² after dividing by a1 a3, gives the critical speed in closed form (derived here; the
derivation is elementary and checked in ``tests/railway/test_hunting.py`` against the
eigenvalues of the matrices):

.. math::

    V_c^2 = \frac{4 l r_0 (f_{22} I + f_{11} l^2 m)(f_{11} l^2 k_y + f_{22} k_\psi)}
                 {4\lambda (f_{22} I + f_{11} l^2 m)^2 - l r_0 (I k_y - m k_\psi)^2},

with the hunting frequency ω_c² = a1/a3 = (f22 k_ψ + f11 l² k_y)/(f22 I + f11 l² m) there.  A
non-positive denominator means the wheelset is stable at every speed; k_y = k_ψ = 0 (a free
wheelset) is unstable at every speed.

Gyroscopic term.  A wheelset spinning at Ω = V/r0 with spin inertia I_y rolls with its lateral
displacement (φ = ρ y; for a cone on a rail with a curved head ρ ≈ λ/l, from the rigid contact
geometry) and the roll rate gives the yaw moment −I_y Ω φ̇ (Euler's equations; Wickens 2003,
ch. 2, keeps this term).  The yaw equation gains I_y ρ V/r0 · ẏ, the polynomial's a1 gains
2 f22 I_y ρ V / r0, and the boundary becomes, with u = 1/V², α = 2(f22 I + f11 l² m),
β = m k_ψ + I k_y, γ = 4 f11 f22 l², δ = 2(f22 k_ψ + f11 l² k_y), ε = 2 f22 I_y ρ/r0,
a4 = m I, a0 = k_y k_ψ + 4 f11 f22 l λ/r0, the cubic

.. math::

    αγδ\,u^3 + (αβδ + αγε − a_4δ^2 − α^2 a_0)\,u^2 + (αβε − 2 a_4 δ ε)\,u − a_4 ε^2 = 0,

whose largest positive root gives the critical speed V_c = u^{-1/2} (for ε = 0 it reduces to the
formula above).

References
----------
Klingel, J. (1883). Über den Lauf der Eisenbahnwagen auf gerader Bahn. Organ für die
Fortschritte des Eisenbahnwesens 38:113–123.  Wickens, A. H. (2003). Fundamentals of Rail
Vehicle Dynamics, Swets & Zeitlinger, ch. 2.  EN 15302:2008+A1:2010 (equivalent conicity).
"""

from __future__ import annotations

import numpy as np

from core.errors import InputError

__all__ = ["klingel_wavelength", "suspended_wheelset_coefficients", "suspended_wheelset_matrices",
           "suspended_wheelset_critical_speed"]


def _positive(**kw):
    for k, v in kw.items():
        if not (np.all(np.isfinite(v)) and np.all(np.asarray(v) > 0)):
            raise InputError(f"{k} = {v!r} must be positive and finite")


def klingel_wavelength(r0, l, conicity):
    """Kinematic wavelength L_K = 2π sqrt(r0 l / λ) [m] (module docstring)."""
    _positive(r0=r0, l=l, conicity=conicity)
    return 2.0 * np.pi * np.sqrt(np.asarray(r0) * l / np.asarray(conicity))


def suspended_wheelset_matrices(V, m, I, k_y, k_psi, f11, f22, l, r0, conicity, spin_inertia=0.0,
                                roll_per_lateral=0.0):
    """(M, C, K) of the linear suspended wheelset in (y, ψ) at speed V (module docstring)."""
    _positive(V=V, m=m, I=I, f11=f11, f22=f22, l=l, r0=r0, conicity=conicity)
    M = np.diag([m, I])
    C = np.array([[2.0 * f22 / V, 0.0],
                  [spin_inertia * roll_per_lateral * V / r0, 2.0 * f11 * l**2 / V]])
    K = np.array([[k_y, -2.0 * f22], [2.0 * f11 * l * conicity / r0, k_psi]])
    return M, C, K


def suspended_wheelset_coefficients(V, m, I, k_y, k_psi, f11, f22, l, r0, conicity):
    """(a4, a3, a2, a1, a0) of the characteristic polynomial (module docstring)."""
    _positive(V=V)
    a4 = m * I
    a3 = 2.0 * (f22 * I + f11 * l**2 * m) / V
    a2 = m * k_psi + I * k_y + 4.0 * f11 * f22 * l**2 / V**2
    a1 = 2.0 * (f22 * k_psi + f11 * l**2 * k_y) / V
    a0 = k_y * k_psi + 4.0 * f11 * f22 * l * conicity / r0
    return a4, a3, a2, a1, a0


def suspended_wheelset_critical_speed(m, I, k_y, k_psi, f11, f22, l, r0, conicity, spin_inertia=0.0,
                                      roll_per_lateral=0.0):
    """Critical speed V_c [m/s] and hunting frequency ω_c [rad/s] at it (module docstring).

    ``spin_inertia`` I_y [kg m²] and ``roll_per_lateral`` ρ = dφ/dy [rad/m] add the gyroscopic
    yaw moment (module docstring); with either zero the classical formula applies.  Returns
    (inf, nan) when the wheelset is stable at every speed; raises InputError for a free
    wheelset (k_y = k_ψ = 0: unstable at every speed).
    """
    _positive(m=m, I=I, f11=f11, f22=f22, l=l, r0=r0, conicity=conicity)
    if not (k_y >= 0 and k_psi >= 0):
        raise InputError(f"spring stiffnesses must be >= 0, got k_y = {k_y!r}, k_psi = {k_psi!r}")
    if k_y == 0 and k_psi == 0:
        raise InputError("a free wheelset (k_y = k_psi = 0) is unstable at every speed: no critical speed")
    eps = 2.0 * f22 * spin_inertia * roll_per_lateral / r0
    if eps != 0.0:
        al, be = 2.0 * (f22 * I + f11 * l**2 * m), m * k_psi + I * k_y
        ga, de = 4.0 * f11 * f22 * l**2, 2.0 * (f22 * k_psi + f11 * l**2 * k_y)
        a4, a0 = m * I, k_y * k_psi + 4.0 * f11 * f22 * l * conicity / r0
        roots = np.roots([al * ga * de, al * be * de + al * ga * eps - a4 * de**2 - al**2 * a0,
                          al * be * eps - 2.0 * a4 * de * eps, -a4 * eps**2])
        u = roots[(np.abs(roots.imag) < 1e-12 * np.abs(roots).max()) & (roots.real > 0)].real
        if u.size == 0:
            return np.inf, np.nan
        Vc = float(1.0 / np.sqrt(u.max()))
        a = suspended_wheelset_coefficients(Vc, m, I, k_y, k_psi, f11, f22, l, r0, conicity)
        a1 = a[3] + eps * Vc
        return Vc, float(np.sqrt(a1 / a[1]))
    P = f22 * I + f11 * l**2 * m
    S = f11 * l**2 * k_y + f22 * k_psi
    den = 4.0 * conicity * P**2 - l * r0 * (I * k_y - m * k_psi) ** 2
    if den <= 0:
        return np.inf, np.nan
    return float(np.sqrt(4.0 * l * r0 * P * S / den)), float(np.sqrt(S / P))
