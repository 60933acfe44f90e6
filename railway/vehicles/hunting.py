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

Complete linear wheelset
------------------------
The gyroscopic form above keeps one consequence of the roll φ = ρ y and leaves out the larger
one: the roll rate moves the contact point laterally, so the lateral creepage is
η = (1 + ρ h) ẏ / V − ψ with h = r0 + l tan δ0 (δ0 the contact angle), and the lateral creep
force acts on y with the same factor (virtual work).  :class:`LinearWheelset` derives and
collects this and every other first-order term of the multibody wheelset (roll inertia,
gravitational stiffness, contact angle, spin creepage and the static spin forces, the
gyroscopic moment in both equations), each switchable by the name of the multibody option that
removes it (:data:`TERMS`; :data:`railway.vehicles.wheelset_models.TEXTBOOK` removes all five).  With
all five off it is the classical model above, with only ``gyroscopic`` on the gyroscopic form.

References
----------
Klingel, J. (1883). Über den Lauf der Eisenbahnwagen auf gerader Bahn. Organ für die
Fortschritte des Eisenbahnwesens 38:113–123.  Wickens, A. H. (2003). Fundamentals of Rail
Vehicle Dynamics, Swets & Zeitlinger, ch. 2.  EN 15302:2008+A1:2010 (equivalent conicity).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.errors import InputError

__all__ = ["klingel_wavelength", "suspended_wheelset_coefficients", "suspended_wheelset_matrices",
           "suspended_wheelset_critical_speed", "LinearWheelset", "TERMS"]


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


# =============================================================================================
# The complete linear wheelset: every term of the multibody wheelset, each switchable
# =============================================================================================
#: the terms of :class:`LinearWheelset` beyond the classical model, named as the options of
#: :class:`railway.vehicles.wheel_rail.WheelRailContact` that switch them off in the multibody wheelset
TERMS = ("gyroscopic", "roll_rate_creepage", "gravitational_stiffness", "contact_angle", "spin_creepage")


@dataclass(frozen=True)
class LinearWheelset:
    r"""The suspended wheelset of the module docstring with every first-order term of the
    multibody wheelset (:func:`railway.vehicles.wheelset_models.suspended_wheelset`), each of which can
    be switched off by the name of the multibody option that removes it there (:data:`TERMS`).

    Coordinates y (lateral) and ψ (yaw); the rigid contact geometry slaves the roll to the
    lateral displacement, φ = ρ y, and the height, z = ½ z_yy y² + ½ z_ψψ ψ²; the x and spin
    perturbations are decoupled from (y, ψ) by the left–right symmetry.  Contact angle δ0 (left
    normal n_L = (0, −s, c) leaning towards the track centre; s = sin δ0, c = cos δ0), contact
    points at (0, ±l, −r0) from the centre, contact-plane axes t (the wheelset's forward axis
    projected) and l = n × t.

    *Lateral creepage.*  The left wheel's material point at the contact moves with
    v_L = (ẋ − r0 β̇ − l ψ̇ − V λ y / r0, ẏ + r0 φ̇ − V ψ, l φ̇) plus, on a yawed wheel, the spin
    velocity −Ω x_c u of the contact point's lead x_c = r0 s ψ / c (Ω = V / r0).  With
    l_L = (−c ψ, c, s):

    .. math::

        \eta = \frac{v_L \cdot l_L}{V} = \kappa_\eta \frac{\dot y}{V} - \frac{\psi}{c},
        \qquad \kappa_\eta = c\,(1 + \rho h), \qquad h = r_0 + l \tan\delta_0,

    the same on the right wheel: ρ h ẏ / V is the roll-rate part of the lateral creepage, h the
    lever of the contact point about the roll axis (Kalker 1990, ch. 1: creepage from the
    rigid-body velocity of the material point).  The earlier extended form (module docstring,
    "Gyroscopic term") lacked it; it is most of the difference to the multibody wheelset.

    *Forces on y.*  The normal forces do no work on a motion that keeps both contacts closed, so
    a lateral creep force F_y acts on y with the virtual velocity of its point,
    κ_F = c (1 + ρ h) (virtual work; Nikravesh 1988, Eq. 6.178), the roll inertia adds I_x ρ² to
    the mass and gravity through the height gives the gravitational stiffness m g z_yy (and
    m g z_ψψ in yaw; Wickens 2003, ch. 2).  Without the normal forces' tilt (multibody option
    ``gravitational_stiffness=False``) none of these act and κ_F = c.

    *Spin creepage.*  About its static value φ0 = ∓ s / r0 the spin creepage of a contact is
    φ_s = c (ψ̇ / V − Γ_w y / r0), Γ_w = dδ_L/dy − ρ the change of the contact angle relative to
    the wheel (zero for a cone); Kalker's F_y = −f22 η − f23 φ_s and M_z = f23 η − f33 φ_s
    (f23 = G c³ C23, f33 = G c⁴ C33, notes Sec. 3).  The static spin forces F0 = f23 s / r0
    (outwards on both wheels) add two terms: they are proportional to the wheel load (f23 ∝ c³ ∝
    N), so the load transfer ΔN = N_L − N_R that balances the roll moments gives the lateral
    force ε κ_F ΔN (ε = F0 / N0, N0 the static wheel load along the normal), with

    .. math::

        (l c - \nu r_0 s + c h \varepsilon)\,\Delta N = I_x \rho \ddot y - c h \textstyle\sum F_y
        - I_y \Omega \dot\psi,

    and, turning with the yaw (l_L has the component −c ψ along t) and moving with the lead, the
    yaw moment 2 F0 (l c + r0 s) ψ.

    *Gyroscopic moment.*  The spinning wheelset (spin inertia I_y) has −I_y Ω (ω × a): yaw
    moment −I_y Ω ρ ẏ and roll moment I_y Ω ψ̇, which acts on y through φ = ρ y when the
    normal forces tilt.

    Collecting, with ν = 1 with the normal forces' tilt (else 0), σ = 1 with spin creepage,
    ``contact_angle`` off giving c = 1, s = 0, h = r0, Γ_w = 0, ``roll_rate_creepage`` off
    κ_η = c, and e = ε κ_F / (l c − ν r0 s + c h ε) (σ = 1 and the contact angle on, else 0):

    .. math::

        M = \begin{bmatrix} m + \nu I_x\rho^2 - e I_x \rho & 0 \\ 0 & I \end{bmatrix},

    .. math::

        C = \begin{bmatrix} 2 f_{22}\kappa_\eta (\kappa_F - e c h) / V &
                             2\sigma f_{23} c (\kappa_F - e c h) / V + (e - \nu\rho) I_y\Omega \\
                             I_y\Omega\rho - 2\sigma f_{23} c\,\kappa_\eta / V &
                             2 f_{11} l^2 / V + 2\sigma f_{33} c^2 / V \end{bmatrix}

    .. math::

        K = \begin{bmatrix} k_y + \nu m g z_{yy} - 2\sigma f_{23} c (\kappa_F - e c h)\Gamma_w / r_0 &
                             -2 f_{22} (\kappa_F - e c h) / c \\
                             2 f_{11} l\lambda / r_0 - 2\sigma f_{33} c^2\Gamma_w / r_0 &
                             k_\psi + \nu m g z_{\psi\psi} + 2\sigma f_{23} - 2\sigma F_0 (l c + r_0 s)
                             \end{bmatrix}.

    With every term off these are the classical matrices of :func:`suspended_wheelset_matrices`;
    with only ``gyroscopic`` on, the earlier extended form.  The critical speed is where the
    Hurwitz determinant H = a3 a2 a1 − a4 a1² − a3² a0 of det(M s² + C s + K) changes sign
    (Routh–Hurwitz, as in the module docstring; found by Brent's method on H(V) from a scan for
    its first sign change, since the entries now mix 1/V and V), the hunting frequency
    ω_c² = a1 / a3 there.

    Left out (second order in the roll, or the contact's elasticity): the load transfer that the
    geometry itself causes at a lateral shift, the turning of the static spin forces with the
    contact angle, the Hertz compliance of the roll and the changes of the Hertz ellipses with
    the load.  Against the multibody wheelset (tests/railway/test_hunting_like_for_like.py) the
    complete form is within 0.012 % (V_c) at cone 1:40 and 0.40 % at cone 0.4 (conicity 0.54).

    Parameters
    ----------
    m, I, k_y, k_psi, f11, f22, l, r0, conicity : float
        As in :func:`suspended_wheelset_matrices` (SI).
    f23, f33 : float
        Kalker's spin coefficients G c³ C23 [N m] and G c⁴ C33 [N m²] of one contact.
    roll_per_lateral : float
        ρ = dφ/dy [rad/m] of the rigid contact geometry.
    contact_angle_slope : float
        dδ_L/dy [rad/m] of the left contact angle (ρ for a cone).
    delta0 : float
        Contact angle δ0 at the central position [rad].
    spin_inertia, roll_inertia : float
        I_y and I_x [kg m²].
    z_yy, z_psipsi : float
        Curvatures of the wheelset centre's height in y [1/m] and ψ [m/rad²] (rigid contact).
    normal_load : float
        Static normal force N0 of a wheel [N] (for ε = F0 / N0; 0 leaves the load-transfer
        terms of the static spin forces out).
    gravity : float
        m/s².

    References
    ----------
    Wickens (2003), ch. 2 (the linear wheelset with gravitational stiffness, spin and
    gyroscopic terms).  Kalker, J. J. (1990). Three-dimensional elastic bodies in rolling
    contact, ch. 1.  Nikravesh, P. E. (1988). Computer-Aided Analysis of Mechanical Systems,
    Eq. 6.178.
    """

    m: float
    I: float
    k_y: float
    k_psi: float
    f11: float
    f22: float
    l: float
    r0: float
    conicity: float
    f23: float = 0.0
    f33: float = 0.0
    roll_per_lateral: float = 0.0
    contact_angle_slope: float = 0.0
    delta0: float = 0.0
    spin_inertia: float = 0.0
    roll_inertia: float = 0.0
    z_yy: float = 0.0
    z_psipsi: float = 0.0
    normal_load: float = 0.0
    gravity: float = 9.81

    def _terms(self, terms):
        unknown = set(terms) - set(TERMS)
        if unknown:
            raise InputError(f"LinearWheelset: unknown terms {sorted(unknown)}; the terms are {list(TERMS)}")
        return {k: bool(terms.get(k, True)) for k in TERMS}

    def _parts(self, **terms):
        """(M, C0, C1, K): C = C0 / V + C1 V (module docstring of the class)."""
        on = self._terms(terms)
        rho, Iy, Om_V = self.roll_per_lateral, self.spin_inertia, 1.0 / self.r0  # Ω = V / r0
        if on["contact_angle"]:
            c, h, Gw = np.cos(self.delta0), self.r0 + self.l * np.tan(self.delta0), self.contact_angle_slope - rho
        else:
            c, h, Gw = 1.0, self.r0, 0.0
        k_eta = c * (1.0 + rho * h) if on["roll_rate_creepage"] else c
        nu = 1.0 if on["gravitational_stiffness"] else 0.0
        k_F = c * (1.0 + rho * h) if nu else c
        sg = 1.0 if on["spin_creepage"] else 0.0
        gy = 1.0 if on["gyroscopic"] else 0.0
        f11, f22, f23, f33, l, r0 = self.f11, self.f22, self.f23, self.f33, self.l, self.r0
        M = np.diag([self.m + nu * self.roll_inertia * rho**2, self.I])
        C0 = np.array([[2.0 * f22 * k_F * k_eta, 2.0 * sg * f23 * k_F * c],
                       [-2.0 * sg * f23 * c * k_eta, 2.0 * f11 * l**2 + 2.0 * sg * f33 * c**2]])
        C1 = gy * Iy * rho * Om_V * np.array([[0.0, -nu], [1.0, 0.0]])
        g = self.gravity
        K = np.array([[self.k_y + nu * self.m * g * self.z_yy - 2.0 * sg * f23 * k_F * c * Gw / r0,
                       -2.0 * f22 * k_F / c],
                      [2.0 * f11 * l * self.conicity / r0 - 2.0 * sg * f33 * c**2 * Gw / r0,
                       self.k_psi + nu * self.m * g * self.z_psipsi + 2.0 * sg * f23]])
        if sg and on["contact_angle"] and self.normal_load > 0:
            # load transfer × static spin force (class docstring): -Q = -e [I_x ρ ÿ - c h ΣF_y - I_y Ω ψ̇]
            s0 = np.sin(self.delta0)
            eps = f23 * s0 / (r0 * self.normal_load)
            arm = l * c - (r0 * s0 if nu else 0.0)
            e = eps * k_F / (arm + c * h * eps)
            M[0, 0] -= e * self.roll_inertia * rho
            C0[0, 0] -= 2.0 * e * c * h * f22 * k_eta
            C0[0, 1] -= 2.0 * e * c**2 * h * f23
            C1[0, 1] += e * gy * Iy * Om_V
            K[0, 0] += 2.0 * e * c**2 * h * f23 * Gw / r0
            K[0, 1] += 2.0 * e * h * f22
            # the static spin forces F0 turn with the yaw and move with the contacts' lead
            K[1, 1] -= 2.0 * f23 * s0 / r0 * (l * c + r0 * s0)
        return M, C0, C1, K

    def matrices(self, V, **terms):
        """(M, C, K) at speed V [m/s]; keyword ``term=False`` switches a term of :data:`TERMS` off."""
        _positive(V=V)
        M, C0, C1, K = self._parts(**terms)
        return M, C0 / V + C1 * V, K

    def coefficients(self, V, **terms):
        """(a4, a3, a2, a1, a0) of det(M s² + C s + K)."""
        M, C, K = self.matrices(V, **terms)
        p11 = [M[0, 0], C[0, 0], K[0, 0]]
        p22 = [M[1, 1], C[1, 1], K[1, 1]]
        p12, p21 = [M[0, 1], C[0, 1], K[0, 1]], [M[1, 0], C[1, 0], K[1, 0]]
        return tuple(np.polysub(np.polymul(p11, p22), np.polymul(p12, p21)))

    def hurwitz(self, V, **terms):
        """Hurwitz determinant H = a3 a2 a1 − a4 a1² − a3² a0 (positive: stable), made
        dimensionless by a3 a2 a1."""
        a4, a3, a2, a1, a0 = self.coefficients(V, **terms)
        return (a3 * a2 * a1 - a4 * a1**2 - a3**2 * a0) / abs(a3 * a2 * a1)

    def critical_speed(self, V_max=500.0, n_scan=400, **terms):
        """Critical speed V_c [m/s] and hunting frequency ω_c [rad/s]: the first sign change of
        the Hurwitz determinant above 0.1 m/s (class docstring); (inf, nan) when stable up to
        ``V_max``."""
        from scipy.optimize import brentq

        self._terms(terms)
        Vs = np.geomspace(0.1, V_max, n_scan)
        H = np.array([self.hurwitz(V, **terms) for V in Vs])
        k = np.flatnonzero((H[:-1] > 0) & (H[1:] <= 0))
        if k.size == 0:
            return np.inf, np.nan
        Vc = brentq(lambda V: self.hurwitz(V, **terms), Vs[k[0]], Vs[k[0] + 1], xtol=1e-12, rtol=1e-15)
        a = self.coefficients(Vc, **terms)
        return float(Vc), float(np.sqrt(a[3] / a[1]))
