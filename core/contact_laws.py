r"""Contact laws of two elastic bodies: Hertz from principal curvatures, and continuous normal-force
laws with hysteresis damping (Lankarani–Nikravesh, Flores et al., Hunt–Crossley).

One definition for every package: :class:`core.forces.contact.PlaneContact` and the railway
wheel–rail contact (:mod:`railway.contact.forces`, :mod:`railway.contact.quasi_static`, :mod:`railway.contact.creep_curve`)
use these functions; the compiled railway kernel evaluates the same equations and is tested
against them.

1. Hertz theory (Johnson 1985, sect. 4.2; Timoshenko & Goodier 1951, art. 140)
-------------------------------------------------------------------------------
Two bodies touch at a point whose principal directions x and y are common to both (a wheel on a
rail: x rolling, y lateral; a sphere on a plane: any pair).  Body i has principal radii
``R_ix`` (curvature in the x–z plane) and ``R_iy``; a radius is positive for a convex surface,
negative for a concave one and ``inf`` for a straight line.  Relative curvatures::

    A = 1/2 (1/R1x + 1/R2x),   B = 1/2 (1/R1y + 1/R2y)                                    (H1)

A Hertzian contact needs A > 0 and B > 0.  With k_i = (1 - nu_i^2)/(pi E_i) and the effective
modulus E* = 1/((1 - nu1^2)/E1 + (1 - nu2^2)/E2) = 1/(pi (k1 + k2)), the ellipse ratio
g = b/a <= 1 (minor over major, e^2 = 1 - g^2, K = K(e), E = E(e) with the parameter m = e^2)::

    B'/A' = [(1/g^2) E - K] / (K - E),          A' = min(A, B),  B' = max(A, B)          (H2)
    cos(theta) = |B - A| / (A + B),             B'/A' = (1 + cos theta)/(1 - cos theta)
    m_H = (2 E / (pi g^2))^(1/3),  n_H = m_H g                                           (H3)
    a_maj = m_H [3 pi N (k1 + k2) / (4 (A + B))]^(1/3),   b_min = n_H [...]^(1/3)         (H4)
    delta = 2 K / (pi m_H) [(3 pi N (k1 + k2) / 4)^2 (A + B)]^(1/3)                       (H5)
    N = K_h delta^(3/2),  K_h = (2 m_H / (3 (k1 + k2) K))^(3/2) (3 pi (k1 + k2) / (4 (A + B)))^(1/2)  (H6)
    p0 = 3 N / (2 pi a b)                                                                (H7)

The major axis lies along the direction of the smaller relative curvature; the semi-axes are
returned as ``a`` along x and ``b`` along y.  For a sphere of radius R on a plane
(A = B = 1/(2R), g = 1, K = E = pi/2, m_H = 1) (H6) reduces to the closed form
``K_h = (4/3) E* sqrt(R)`` (Johnson 1985, Eq. 4.23), which :func:`hertz_sphere_plane_stiffness`
evaluates through the general route; the tests check it against the closed form.

The ellipse ratio is found by a vectorised bisection in ln g of the well-conditioned Carlson form
of (H2) (K = R_F(0, g^2, 1), K - E = (e^2/3) R_D(0, g^2, 1))::

    B'/A' = (3 R_F / R_D - 1) / g^2                                                      (H2')

which avoids the cancellation of K - E near g = 1; no table look-up is involved.

2. Continuous normal force with hysteresis damping
--------------------------------------------------
For a penetration delta > 0 and its rate delta_dot (> 0 approaching)::

    F = max(0, K delta^p [1 + chi(e) delta_dot / delta_dot^-]),      F = 0 for delta <= 0  (N1)

with K the contact stiffness (Hertz: K_h of (H6), p = 3/2), e the coefficient of restitution and
delta_dot^- the approach velocity at the start of the impact.  The clip at zero keeps the law
from pulling the bodies together in fast separation.  The partial derivatives used by exact
Jacobians are, where the force is positive (zero elsewhere)::

    dF/d delta     = p K delta^(p-1) [1 + chi delta_dot / delta_dot^-]                  (N2)
    dF/d delta_dot = K delta^p chi / delta_dot^-                                        (N3)

The hysteresis factor chi(e) names the law (:data:`HYSTERESIS_LAWS`):

======================== ======================= ========= ===================================
name                     chi(e)                  e range   source
======================== ======================= ========= ===================================
``lankarani-nikravesh``  3 (1 - e^2) / 4          [0, 1]    Lankarani & Nikravesh 1990, Eq. 17
``flores``               8 (1 - e) / (5 e)        (0, 1]    Flores et al. 2011, Eq. 24
``hunt-crossley``        3 (1 - e) / 2            [0, 1]    Hunt & Crossley 1975
======================== ======================= ========= ===================================

Lankarani–Nikravesh and Hunt–Crossley equate the energy lost in one impact, computed along the
undamped (elastic) trajectory, with the loss (1 - e^2) m v^2/2 of the impact; they are first
order in the dissipation and so accurate for e near 1.  Flores et al. integrate the damped
trajectory instead and are built to hold for any e in (0, 1] (chi grows without bound as e -> 0).
Every law gives chi(1) = 0 (no damping).

References
----------
.. [1] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, ch. 4 (sect. 4.2,
   elliptical contact of general profiles; Eq. 4.23, sphere on a plane).
.. [2] S. P. Timoshenko and J. N. Goodier, *Theory of Elasticity*, 2nd ed., McGraw-Hill, 1951,
   art. 140 (table of m, n against cos theta).
.. [3] B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
   Numer. Algorithms 10 (1995) 13-26 (R_F, R_D).
.. [4] H. M. Lankarani and P. E. Nikravesh, "A contact force model with hysteresis damping for
   impact analysis of multibody systems", J. Mech. Design 112 (1990) 369-376, Eq. 17.
.. [5] P. Flores, M. Machado, M. T. Silva and J. M. Martins, "On the continuous contact force
   models for soft materials in multibody dynamics", Multibody Syst. Dyn. 25 (2011) 357-375,
   Eq. 24.
.. [6] K. H. Hunt and F. R. E. Crossley, "Coefficient of restitution interpreted as damping in
   vibroimpact", J. Appl. Mech. 42 (1975) 440-445 (damping 3 (1 - e)/2 K / delta_dot^-).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from scipy import special

from .errors import InputError
from .registry import Registry

__all__ = [
    "effective_modulus",
    "relative_curvatures",
    "ellipse_ratio",
    "hertz_coefficients",
    "HertzContact",
    "hertz_from_load",
    "hertz_from_penetration",
    "hertz_sphere_plane_stiffness",
    "HysteresisLaw",
    "HYSTERESIS_LAWS",
    "NormalForce",
    "hysteresis_force",
]


# --------------------------------------------------------------------------------------------
# input checks
# --------------------------------------------------------------------------------------------

def _as_array(name: str, value) -> np.ndarray:
    """``value`` as a float array; NaN raises :class:`InputError` naming ``name`` and the index."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a number or an array of numbers, got {value!r}") from None
    if np.any(np.isnan(arr)):
        idx = np.argwhere(np.isnan(np.atleast_1d(arr)))[0].tolist()
        raise InputError(f"{name} contains NaN at index {idx}")
    return arr


def _first_bad(name: str, arr: np.ndarray, bad: np.ndarray, rule: str, unit: str = "") -> None:
    """Raise :class:`InputError` for the first ``bad`` entry of ``arr``: '{name} {rule}, got ...'."""
    if np.any(bad):
        flat = np.atleast_1d(arr)
        i = int(np.flatnonzero(np.atleast_1d(bad))[0])
        where = f" at index {i}" if flat.size > 1 else ""
        raise InputError(f"{name} {rule}, got {float(flat[i])!r}{unit}{where}")


def _check_material(E, nu, label: str):
    E = _as_array(f"E{label}", E)
    nu = _as_array(f"nu{label}", nu)
    _first_bad(f"Young's modulus E{label}", E, ~(E > 0), "must be > 0", " Pa")
    _first_bad(f"Poisson ratio nu{label}", nu, (nu < 0) | (nu > 0.5), "must lie in [0, 0.5]")
    return E, nu


# --------------------------------------------------------------------------------------------
# 1. Hertz
# --------------------------------------------------------------------------------------------

def effective_modulus(E1, nu1, E2, nu2) -> np.ndarray:
    """Effective (combined) contact modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2) [Pa].

    Parameters
    ----------
    E1, E2 : float or (n,) array_like
        Young's moduli of bodies 1 and 2 [Pa], > 0.
    nu1, nu2 : float or (n,) array_like
        Poisson ratios, in [0, 0.5].

    Returns
    -------
    ndarray
        E* [Pa], broadcast shape of the inputs; equal to 1/(pi (k1 + k2)) in the Hertz notation.

    Raises
    ------
    InputError
        NaN, E <= 0 or nu outside [0, 0.5] (names the value).

    References
    ----------
    Johnson (1985), sect. 4.2.
    """
    E1, nu1 = _check_material(E1, nu1, "1")
    E2, nu2 = _check_material(E2, nu2, "2")
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def relative_curvatures(R1x, R1y, R2x=np.inf, R2y=np.inf):
    """Relative curvatures A (along x) and B (along y) from the principal radii, Eq. (H1) [1/m].

    ``A = (1/R1x + 1/R2x)/2``, ``B = (1/R1y + 1/R2y)/2``.  Radii are signed: positive convex,
    negative concave, ``inf`` for a straight line (the default for body 2 is a plane).

    Parameters
    ----------
    R1x, R1y : float or (n,) array_like
        Principal radii of body 1 in the x–z and y–z planes [m], nonzero.
    R2x, R2y : float or (n,) array_like, optional
        Principal radii of body 2 [m], nonzero; ``inf`` (default) for a flat body.

    Returns
    -------
    A, B : (n,) ndarray
        Relative curvatures [1/m].

    Raises
    ------
    InputError
        A zero or NaN radius, or a combination that is not Hertzian (A <= 0 or B <= 0:
        conformal or non-convex contact), naming the contact index and the radii.

    References
    ----------
    Johnson (1985), sect. 4.2.
    """
    names = ("R1x", "R1y", "R2x", "R2y")
    arrs = np.broadcast_arrays(*(np.atleast_1d(_as_array(n, v)) for n, v in zip(names, (R1x, R1y, R2x, R2y))))
    for name, R in zip(names, arrs):
        if np.any(R == 0):
            raise InputError(f"{name} has a zero radius at index {int(np.flatnonzero(R == 0)[0])}")
    r1x, r1y, r2x, r2y = arrs
    A = 0.5 * (1.0 / r1x + 1.0 / r2x)
    B = 0.5 * (1.0 / r1y + 1.0 / r2y)
    bad = (A <= 0) | (B <= 0)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InputError(
            f"non-Hertzian contact at index {i}: A={float(A[i])!r} 1/m, B={float(B[i])!r} 1/m "
            f"(R1x={float(r1x[i])!r}, R1y={float(r1y[i])!r}, R2x={float(r2x[i])!r}, R2y={float(r2y[i])!r} m); "
            "a concave radius must be larger in magnitude than the convex radius it meets")
    return A, B


def _curvature_ratio(g: np.ndarray) -> np.ndarray:
    """B'/A' as a function of g = b/a in (0, 1], Eq. (H2') (Carlson form, exact at g = 1)."""
    g2 = g * g
    zero = np.zeros_like(g)
    one = np.ones_like(g)
    RF = special.elliprf(zero, g2, one)
    RD = special.elliprd(zero, g2, one)
    return (3.0 * RF / RD - 1.0) / g2


def ellipse_ratio(curvature_ratio, n_iter: int = 200) -> np.ndarray:
    """Solve Eq. (H2) B'/A' = [(1/g^2)E(e) - K(e)] / (K(e) - E(e)) for g = b/a in (0, 1].

    Vectorised bisection in ln g of the Carlson form (H2'), bracketed between g = 1 (ratio 1) and
    a lower bound widened until the ratio there exceeds the target; stops at machine precision
    in g.

    Parameters
    ----------
    curvature_ratio : float or (n,) array_like
        B'/A' >= 1 (larger over smaller relative curvature), finite.
    n_iter : int
        Maximum number of bisection steps (each halves the bracket in ln g).

    Returns
    -------
    (n,) ndarray
        g = b/a (minor over major semi-axis).

    Raises
    ------
    InputError
        A ratio below 1, infinite (line contact) or NaN.

    References
    ----------
    Johnson (1985), sect. 4.2; Carlson (1995).
    """
    r = np.atleast_1d(_as_array("curvature_ratio", curvature_ratio))
    _first_bad("curvature_ratio", r, r < 1.0, "must be >= 1")
    _first_bad("curvature_ratio", r, ~np.isfinite(r),
               "must be finite (line contact is not Hertzian-elliptic)")
    # bracket in t = ln g; f(t) = ln ratio(g) - ln r is decreasing in t
    hi = np.zeros_like(r)
    lo = np.minimum(-1.0, -np.log(r))  # g <= 1/r is a first guess for the lower end
    for _ in range(60):
        need = _curvature_ratio(np.exp(lo)) < r
        if not np.any(need):
            break
        lo = np.where(need, 2.0 * lo, lo)
    else:
        i = int(np.flatnonzero(need)[0])
        raise InputError(f"could not bracket the ellipse ratio; curvature_ratio {float(r[i])!r} "
                         f"at index {i} is too large")
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi)
        above = _curvature_ratio(np.exp(mid)) > r  # ratio too large -> g too small
        lo = np.where(above, mid, lo)
        hi = np.where(above, hi, mid)
        if np.all(hi - lo <= 4.0 * np.finfo(float).eps * np.maximum(1.0, np.abs(lo))):
            break
    g = np.exp(0.5 * (lo + hi))
    g[r == 1.0] = 1.0
    return g


def hertz_coefficients(cos_theta):
    """Hertz coefficients m, n (Timoshenko & Goodier's notation) and g = n/m from cos(theta).

    cos(theta) = ``|B - A|``/(A + B); g from (H2) with B'/A' = (1 + cos theta)/(1 - cos theta);
    m = (2 E(e)/(pi g^2))^(1/3), n = m g, Eq. (H3).

    Parameters
    ----------
    cos_theta : float or (n,) array_like
        In [0, 1).

    Returns
    -------
    m, n, g : (n,) ndarray
        Dimensionless.

    Raises
    ------
    InputError
        cos_theta outside [0, 1) or NaN.

    References
    ----------
    Timoshenko & Goodier (1951), art. 140.
    """
    c = np.atleast_1d(_as_array("cos_theta", cos_theta))
    _first_bad("cos_theta", c, (c < 0) | (c >= 1), "must lie in [0, 1)")
    g = ellipse_ratio((1.0 + c) / (1.0 - c))
    E = special.ellipe(1.0 - g * g)
    m = (2.0 * E / (np.pi * g * g)) ** (1.0 / 3.0)
    return m, m * g, g


@dataclass(frozen=True)
class HertzContact:
    """Result of a Hertz computation; every field is an (n,) ndarray in SI units.

    Attributes
    ----------
    a, b : (n,) ndarray
        Semi-axes along x and along y [m] (Eq. H4; the railway uses x = rolling direction).
    delta : (n,) ndarray
        Approach (penetration) [m], Eq. (H5).
    normal_force : (n,) ndarray
        N [N].
    stiffness : (n,) ndarray
        K_h in N = K_h delta^(3/2) [N/m^1.5], Eq. (H6).
    p0 : (n,) ndarray
        Peak pressure 3N/(2 pi a b) [Pa], Eq. (H7); 0 where N = 0.
    g : (n,) ndarray
        Minor/major axis ratio [-].
    m, n : (n,) ndarray
        Hertz coefficients [-], Eq. (H3).
    """

    a: np.ndarray
    b: np.ndarray
    delta: np.ndarray
    normal_force: np.ndarray
    stiffness: np.ndarray
    p0: np.ndarray
    g: np.ndarray
    m: np.ndarray
    n: np.ndarray


def _geometry(A, B, E1, nu1, E2, nu2):
    """Checked curvatures and the load-independent Hertz quantities (H2, H3, H6)."""
    A = np.atleast_1d(_as_array("A", A))
    B = np.atleast_1d(_as_array("B", B))
    A, B = np.broadcast_arrays(A, B)
    bad = (A <= 0) | (B <= 0) | ~np.isfinite(A) | ~np.isfinite(B)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"relative curvatures must be finite and > 0; contact {i}: "
                         f"A={float(A[i])!r}, B={float(B[i])!r} 1/m")
    Estar = effective_modulus(E1, nu1, E2, nu2)
    ksum = 1.0 / (np.pi * Estar)
    Amin = np.minimum(A, B)
    Bmax = np.maximum(A, B)
    g = ellipse_ratio(Bmax / Amin)
    msq = 1.0 - g * g
    Kel = special.ellipk(msq)
    Eel = special.ellipe(msq)
    mH = (2.0 * Eel / (np.pi * g * g)) ** (1.0 / 3.0)
    nH = mH * g
    S = A + B
    Kh = (2.0 * mH / (3.0 * ksum * Kel)) ** 1.5 * np.sqrt(3.0 * np.pi * ksum / (4.0 * S))
    return A, B, ksum, S, g, Kel, mH, nH, Kh


def _finish(A, B, N, ksum, S, g, mH, nH, Kh, delta):
    """Semi-axes (H4) oriented along x, y and the peak pressure (H7)."""
    base = np.cbrt(3.0 * np.pi * N * ksum / (4.0 * S))
    a_maj = mH * base
    b_min = nH * base
    along_x_major = A <= B  # smaller curvature along x -> major axis along x
    a = np.where(along_x_major, a_maj, b_min)
    b = np.where(along_x_major, b_min, a_maj)
    with np.errstate(invalid="ignore", divide="ignore"):
        p0 = np.where(N > 0, 3.0 * N / (2.0 * np.pi * a * b), 0.0)
    return HertzContact(a=a, b=b, delta=delta, normal_force=N, stiffness=Kh, p0=p0,
                        g=g, m=mH, n=nH)


def hertz_from_load(normal_force, A, B, E1, nu1, E2, nu2) -> HertzContact:
    """Hertz contact ellipse, approach and stiffness for a given normal load, Eqs. (H2)-(H7).

    Parameters
    ----------
    normal_force : float or (n,) array_like
        Normal load N >= 0 [N].
    A, B : float or (n,) array_like
        Relative curvatures along x and y [1/m], both finite and > 0
        (see :func:`relative_curvatures`).
    E1, nu1, E2, nu2 : float or (n,) array_like
        Young's moduli [Pa] and Poisson ratios of bodies 1 and 2.

    Returns
    -------
    HertzContact
        Fields (n,).

    Raises
    ------
    InputError
        Negative or NaN load, nu outside [0, 0.5], E <= 0, non-positive curvature.

    References
    ----------
    Johnson (1985), sect. 4.2; Timoshenko & Goodier (1951), art. 140.
    """
    N = np.atleast_1d(_as_array("normal_force", normal_force))
    if np.any(N < 0):
        i = int(np.flatnonzero(N < 0)[0])
        raise InputError(f"normal_force must be >= 0, got {float(N[i])!r} N at index {i}")
    A, B, ksum, S, g, Kel, mH, nH, Kh = _geometry(A, B, E1, nu1, E2, nu2)
    N = np.broadcast_to(N, A.shape).astype(float)
    delta = 2.0 * Kel / (np.pi * mH) * np.cbrt((3.0 * np.pi * N * ksum / 4.0) ** 2 * S)
    return _finish(A, B, N, ksum, S, g, mH, nH, Kh, delta)


def hertz_from_penetration(penetration, A, B, E1, nu1, E2, nu2) -> HertzContact:
    """Hertz contact for a given approach delta; N = K_h max(delta, 0)^(3/2), Eq. (H6).

    Parameters
    ----------
    penetration : float or (n,) array_like
        Approach delta [m]; values <= 0 give no contact (N = 0, a = b = 0).
    A, B, E1, nu1, E2, nu2 :
        As in :func:`hertz_from_load`.

    Returns
    -------
    HertzContact
        Fields (n,).

    Raises
    ------
    InputError
        As :func:`hertz_from_load` (NaN penetration included).
    """
    d = np.atleast_1d(_as_array("penetration", penetration))
    A, B, ksum, S, g, _, mH, nH, Kh = _geometry(A, B, E1, nu1, E2, nu2)
    d = np.broadcast_to(d, A.shape).astype(float)
    N = Kh * np.maximum(d, 0.0) ** 1.5
    return _finish(A, B, N, ksum, S, g, mH, nH, Kh, d)


def hertz_sphere_plane_stiffness(radius, E1, nu1, E2, nu2):
    r"""Hertz stiffness K_h of a sphere on a plane [N/m^1.5] (the special case A = B = 1/(2R)).

    Evaluated through the general route, Eq. (H6) with g = 1; it equals the closed form

    .. math:: K_h = \tfrac{4}{3} E^* \sqrt{R}, \qquad 1/E^* = (1-ν_1^2)/E_1 + (1-ν_2^2)/E_2

    (Johnson 1985, Eq. 4.23) to rounding, which the tests check.

    Parameters
    ----------
    radius : float or (n,) array_like
        Sphere radius R [m], finite and > 0.
    E1, nu1 : float or (n,) array_like
        Young's modulus [Pa] and Poisson ratio of the sphere.
    E2, nu2 : float or (n,) array_like
        Of the plane.

    Returns
    -------
    float or (n,) ndarray
        K_h [N/m^1.5]; a float when every input is a scalar.

    Raises
    ------
    InputError
        Radius not finite and > 0, or bad material constants (names the value).
    """
    R = _as_array("radius", radius)
    _first_bad("sphere radius", R, ~((R > 0) & np.isfinite(R)), "must be finite and > 0", " m")
    A = 1.0 / (2.0 * R)
    K = _geometry(A, A, E1, nu1, E2, nu2)[-1]
    if all(np.ndim(x) == 0 for x in (radius, E1, nu1, E2, nu2)):
        return float(K[0])
    return K


# --------------------------------------------------------------------------------------------
# 2. continuous normal force with hysteresis damping
# --------------------------------------------------------------------------------------------

class NormalForce(NamedTuple):
    """A normal force of Eq. (N1) and its partial derivatives (N2), (N3); each (n,) ndarray.

    Attributes
    ----------
    force : (n,) ndarray
        F >= 0 [N].
    d_penetration : (n,) ndarray
        dF/d delta [N/m]; 0 where F = 0.
    d_rate : (n,) ndarray
        dF/d delta_dot [N s/m]; 0 where F = 0.
    """

    force: np.ndarray
    d_penetration: np.ndarray
    d_rate: np.ndarray


def hysteresis_force(penetration, penetration_rate, stiffness, chi, approach_velocity,
                     exponent=1.5, validate: bool = True) -> NormalForce:
    """Continuous normal force with hysteresis damping and its derivatives, Eqs. (N1)-(N3).

    F = max(0, K delta^p [1 + chi delta_dot / delta_dot^-]) for delta > 0, else 0.

    Parameters
    ----------
    penetration : float or (n,) array_like
        delta [m] (> 0 in contact).
    penetration_rate : float or (n,) array_like
        d delta/dt [m/s] (> 0 approaching).
    stiffness : float or (n,) array_like
        K [N/m^p], >= 0 (Hertz: :attr:`HertzContact.stiffness` with p = 3/2).
    chi : float or (n,) array_like
        Hysteresis factor chi(e) >= 0, e.g. ``HYSTERESIS_LAWS["flores"].factor(e)``.
    approach_velocity : float or (n,) array_like
        delta_dot^- [m/s], > 0 (the approach speed at the start of the impact).
    exponent : float or (n,) array_like
        p >= 1 (3/2 for Hertz).
    validate : bool
        Check the inputs (default).  Callers that checked their constant parameters once (a
        compiled force kind evaluated inside an integrator) pass False.

    Returns
    -------
    NormalForce
        ``force`` [N], ``d_penetration`` [N/m], ``d_rate`` [N s/m], each of the broadcast shape.

    Raises
    ------
    InputError
        With ``validate``: NaN, K < 0, chi < 0, p < 1 or delta_dot^- <= 0 (names the value).

    References
    ----------
    Lankarani & Nikravesh (1990); Flores et al. (2011); Hunt & Crossley (1975).
    """
    if validate:
        penetration = _as_array("penetration", penetration)
        penetration_rate = _as_array("penetration_rate", penetration_rate)
        stiffness = _as_array("stiffness", stiffness)
        chi = _as_array("chi", chi)
        approach_velocity = _as_array("approach_velocity", approach_velocity)
        exponent = _as_array("exponent", exponent)
        _first_bad("stiffness", stiffness, stiffness < 0, "must be >= 0")
        _first_bad("hysteresis factor chi", chi, (chi < 0) | ~np.isfinite(chi), "must be finite and >= 0")
        _first_bad("approach_velocity", approach_velocity,
                   ~((approach_velocity > 0) & np.isfinite(approach_velocity)), "must be finite and > 0", " m/s")
        _first_bad("exponent", exponent, ~((exponent >= 1) & np.isfinite(exponent)), "must be finite and >= 1")
    delta = np.asarray(penetration, dtype=float)
    rate = np.asarray(penetration_rate, dtype=float)
    K = np.asarray(stiffness, dtype=float)
    p = np.asarray(exponent, dtype=float)
    on = delta > 0
    dp = np.where(on, delta, 0.0)
    base = K * dp**p
    damp = 1.0 + chi * rate / approach_velocity
    F = base * damp
    active = on & (F > 0)
    F = np.where(active, F, 0.0)
    dF_ddelta = np.where(active, p * K * np.where(on, dp, 1.0) ** (p - 1.0) * damp, 0.0)
    dF_drate = np.where(active, base * chi / approach_velocity, 0.0)
    return NormalForce(np.atleast_1d(F), np.atleast_1d(dF_ddelta), np.atleast_1d(dF_drate))


@dataclass(frozen=True)
class HysteresisLaw:
    """A named hysteresis factor chi(e) of the normal-force law (N1).

    Attributes
    ----------
    name : str
        Registry name (see :data:`HYSTERESIS_LAWS`).
    chi : callable
        ``chi(e)`` on an ndarray of restitution coefficients (no checks; use :meth:`factor`).
    formula : str
        chi(e) as text, for messages and tables.
    reference : str
        Paper and equation.
    zero_restitution : bool
        Whether e = 0 is allowed (False for Flores et al., whose chi is singular there).
    """

    name: str
    chi: Callable[[np.ndarray], np.ndarray]
    formula: str
    reference: str
    zero_restitution: bool = True

    def factor(self, restitution) -> np.ndarray:
        """chi(e) for coefficients of restitution e; ``chi(1) = 0``.

        Parameters
        ----------
        restitution : float or (n,) array_like
            e in [0, 1] (in (0, 1] when :attr:`zero_restitution` is False).

        Returns
        -------
        ndarray
            chi >= 0 [-], the shape of ``restitution``.

        Raises
        ------
        InputError
            e outside the law's range or NaN (names the law and the value).
        """
        e = _as_array(f"{self.name} law: restitution", restitution)
        if self.zero_restitution:
            _first_bad(f"{self.name} law: restitution", e, (e < 0) | (e > 1), "must lie in [0, 1]")
        else:
            _first_bad(f"{self.name} law: restitution", e, (e <= 0) | (e > 1), "must lie in (0, 1]")
        return self.chi(e)

    def force(self, penetration, penetration_rate, stiffness, restitution, approach_velocity,
              exponent=1.5) -> NormalForce:
        """The force (N1) of this law and its derivatives (N2), (N3).

        ``hysteresis_force(penetration, penetration_rate, stiffness, self.factor(restitution),
        approach_velocity, exponent)``; see :func:`hysteresis_force` for the parameters [SI].
        """
        return hysteresis_force(penetration, penetration_rate, stiffness, self.factor(restitution),
                                approach_velocity, exponent)


def _check_law(obj) -> None:
    if not isinstance(obj, HysteresisLaw):
        raise TypeError(f"the hysteresis-law registry takes HysteresisLaw objects, got {obj!r}")


#: Name → :class:`HysteresisLaw` of the normal-force law (N1); register a user law with
#: ``HYSTERESIS_LAWS.register(name, HysteresisLaw(name, chi, formula, reference))``.
HYSTERESIS_LAWS: Registry[HysteresisLaw] = Registry("hysteresis law", _check_law)

for _law in (
    HysteresisLaw("lankarani-nikravesh", lambda e: 0.75 * (1.0 - e * e), "3 (1 - e^2) / 4",
                  "Lankarani & Nikravesh, J. Mech. Design 112 (1990) 369-376, Eq. 17"),
    HysteresisLaw("flores", lambda e: 8.0 * (1.0 - e) / (5.0 * e), "8 (1 - e) / (5 e)",
                  "Flores et al., Multibody Syst. Dyn. 25 (2011) 357-375, Eq. 24", zero_restitution=False),
    HysteresisLaw("hunt-crossley", lambda e: 1.5 * (1.0 - e), "3 (1 - e) / 2",
                  "Hunt & Crossley, J. Appl. Mech. 42 (1975) 440-445"),
):
    HYSTERESIS_LAWS.register(_law.name, _law)
del _law
