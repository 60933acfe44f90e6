"""Hertzian normal contact of two elastic bodies and the Lankarani-Nikravesh force law.

Equations (Johnson 1985, sect. 4.2; Timoshenko & Goodier 1951, art. 140)
------------------------------------------------------------------------
Relative curvatures along the rolling direction x and the lateral direction y (principal directions
of both bodies aligned, as for a wheel on a rail)::

    A = 1/2 (1/R1x + 1/R2x),   B = 1/2 (1/R1y + 1/R2y)          (1 wheel, 2 rail)

A radius is positive for a convex surface and negative for a concave one (the wheel flange root,
R < 0, on the rail gauge corner).  A Hertzian contact needs A > 0 and B > 0.
With k_i = (1 - nu_i^2)/(pi E_i), the combined modulus 1/E* = pi (k1 + k2), and the ellipse ratio
g = b/a <= 1 (minor over major, e^2 = 1 - g^2, K = K(e), E = E(e) with the parameter m = e^2)::

    B'/A' = [(1/g^2) E - K] / (K - E)          A' = min(A, B), B' = max(A, B)
    m_H = (2 E / (pi g^2))^(1/3),  n_H = m_H g
    a_maj = m_H [3 pi N (k1 + k2) / (4 (A + B))]^(1/3),   b_min = n_H [...]^(1/3)
    delta = 2 K / (pi m_H) [(3 pi N (k1 + k2) / 4)^2 (A + B)]^(1/3)
    N = K_h delta^(3/2),   K_h = (2 m_H / (3 (k1 + k2) K))^(3/2) (3 pi (k1 + k2) / (4 (A + B)))^(1/2)

The major axis lies along the direction of the smaller relative curvature.  The semi-axes are
returned as ``a`` along the rolling direction and ``b`` lateral, which is what the creep laws use.

The ellipse ratio is found by a vectorised bisection in ln g of the well-conditioned Carlson form
of the same equation (K = R_F(0, g^2, 1), K - E = (e^2/3) R_D(0, g^2, 1))::

    B'/A' = (3 R_F / R_D - 1) / g^2

which avoids the cancellation of K - E near g = 1; no table look-up is involved.

References
----------
.. [1] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, ch. 4 (sect. 4.2,
   elliptical contact of general profiles).
.. [2] S. P. Timoshenko and J. N. Goodier, *Theory of Elasticity*, 2nd ed., McGraw-Hill, 1951,
   art. 140 (table of m, n against cos theta).
.. [3] H. M. Lankarani and P. E. Nikravesh, "A contact force model with hysteresis damping for
   impact analysis of multibody systems", J. Mech. Design 112 (1990) 369-376.
.. [4] B. C. Carlson, "Numerical computation of real or complex elliptic integrals",
   Numer. Algorithms 10 (1995) 13-26 (R_F, R_D).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import special

__all__ = [
    "HertzContact",
    "relative_curvatures",
    "ellipse_ratio",
    "hertz_coefficients",
    "hertz_from_load",
    "hertz_from_penetration",
    "lankarani_nikravesh_force",
    "effective_modulus",
]


def _as_array(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if np.any(np.isnan(arr)):
        idx = np.argwhere(np.isnan(np.atleast_1d(arr)))[0].tolist()
        raise ValueError(f"{name} contains NaN at index {idx}")
    return arr


def _check_material(E, nu, label: str):
    E = _as_array(f"E{label}", E)
    nu = _as_array(f"nu{label}", nu)
    if np.any(E <= 0):
        bad = np.atleast_1d(E)[np.atleast_1d(E) <= 0][0]
        raise ValueError(f"Young's modulus E{label} must be > 0, got {float(bad)!r}")
    if np.any((nu < 0) | (nu > 0.5)):
        flat = np.atleast_1d(nu)
        bad = flat[(flat < 0) | (flat > 0.5)][0]
        raise ValueError(f"Poisson ratio nu{label} must lie in [0, 0.5], got {float(bad)!r}")
    return E, nu


def effective_modulus(E1, nu1, E2, nu2) -> np.ndarray:
    """Combined contact modulus E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2) [Pa].

    Parameters
    ----------
    E1, E2 : float or (n,) array_like
        Young's moduli of both bodies [Pa].
    nu1, nu2 : float or (n,) array_like
        Poisson ratios, in [0, 0.5].

    Returns
    -------
    (n,) ndarray
        E* [Pa]; equal to 1/(pi (k1 + k2)) in the Hertz notation.
    """
    E1, nu1 = _check_material(E1, nu1, "1")
    E2, nu2 = _check_material(E2, nu2, "2")
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def relative_curvatures(R_wheel_rolling, R_wheel_lateral, R_rail_lateral, R_rail_rolling=np.inf):
    """Relative curvatures A (rolling direction) and B (lateral) from principal radii [1/m].

    ``A = (1/R_wheel_rolling + 1/R_rail_rolling)/2``, ``B = (1/R_wheel_lateral + 1/R_rail_lateral)/2``.
    Radii are signed: positive convex, negative concave (flange root), ``inf`` for a straight line.

    Parameters
    ----------
    R_wheel_rolling : float or (n,) array_like
        Wheel rolling radius [m] (> 0).
    R_wheel_lateral : float or (n,) array_like
        Wheel profile radius in the lateral plane [m]; negative where the profile is concave.
    R_rail_lateral : float or (n,) array_like
        Rail head profile radius [m].
    R_rail_rolling : float or (n,) array_like, optional
        Rail radius along the track (``inf`` for straight rail, finite for a roller rig).

    Returns
    -------
    A, B : (n,) ndarray
        Relative curvatures [1/m].

    Raises
    ------
    ValueError
        If a combination is not Hertzian (A <= 0 or B <= 0: conformal or non-convex contact),
        naming the contact index and the radii.
    """
    arrs = np.broadcast_arrays(*(np.atleast_1d(_as_array(n, v)) for n, v in (
        ("R_wheel_rolling", R_wheel_rolling), ("R_wheel_lateral", R_wheel_lateral),
        ("R_rail_lateral", R_rail_lateral), ("R_rail_rolling", R_rail_rolling))))
    Rwx, Rwy, Rry, Rrx = arrs
    for name, R in (("R_wheel_rolling", Rwx), ("R_wheel_lateral", Rwy),
                    ("R_rail_lateral", Rry), ("R_rail_rolling", Rrx)):
        if np.any(R == 0):
            raise ValueError(f"{name} has a zero radius at index {int(np.flatnonzero(R == 0)[0])}")
    A = 0.5 * (1.0 / Rwx + 1.0 / Rrx)
    B = 0.5 * (1.0 / Rwy + 1.0 / Rry)
    bad = (A <= 0) | (B <= 0)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"non-Hertzian contact at index {i}: A={float(A[i])!r} 1/m, B={float(B[i])!r} 1/m "
            f"(R_wheel_rolling={float(Rwx[i])!r}, R_wheel_lateral={float(Rwy[i])!r}, R_rail_lateral={float(Rry[i])!r}, "
            f"R_rail_rolling={float(Rrx[i])!r}); a concave radius must be larger in magnitude than the "
            "convex radius it meets")
    return A, B


def _curvature_ratio(g: np.ndarray) -> np.ndarray:
    """B'/A' as a function of g = b/a in (0, 1] (Carlson form, exact at g = 1)."""
    g2 = g * g
    zero = np.zeros_like(g)
    one = np.ones_like(g)
    RF = special.elliprf(zero, g2, one)
    RD = special.elliprd(zero, g2, one)
    return (3.0 * RF / RD - 1.0) / g2


def ellipse_ratio(curvature_ratio, n_iter: int = 200) -> np.ndarray:
    """Solve B'/A' = [(1/g^2)E(e) - K(e)] / (K(e) - E(e)) for g = b/a in (0, 1].

    Vectorised bisection in ln g, bracketed between g = 1 (ratio 1) and a lower bound widened until
    the ratio there exceeds the target; stops at machine precision in g.

    Parameters
    ----------
    curvature_ratio : float or (n,) array_like
        B'/A' >= 1 (larger over smaller relative curvature).
    n_iter : int
        Maximum number of bisection steps (each halves the bracket in ln g).

    Returns
    -------
    (n,) ndarray
        g = b/a (minor over major semi-axis).
    """
    r = np.atleast_1d(_as_array("curvature_ratio", curvature_ratio))
    if np.any(r < 1.0):
        raise ValueError(f"curvature_ratio must be >= 1, got {float(r[r < 1.0][0])!r}")
    if np.any(~np.isfinite(r)):
        raise ValueError("curvature_ratio must be finite (line contact is not Hertzian-elliptic)")
    # bracket in t = ln g; f(t) = ln ratio(g) - ln r is decreasing in t
    hi = np.zeros_like(r)
    lo = np.minimum(-1.0, -np.log(r))  # g <= 1/r is a first guess for the lower end
    for _ in range(60):
        need = _curvature_ratio(np.exp(lo)) < r
        if not np.any(need):
            break
        lo = np.where(need, 2.0 * lo, lo)
    else:
        raise ValueError("could not bracket the ellipse ratio; curvature ratio too large")
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

    cos(theta) = |B - A|/(A + B); m = (2 E(e)/(pi g^2))^(1/3), n = m g.

    Parameters
    ----------
    cos_theta : float or (n,) array_like
        In [0, 1).

    Returns
    -------
    m, n, g : (n,) ndarray
    """
    c = np.atleast_1d(_as_array("cos_theta", cos_theta))
    if np.any((c < 0) | (c >= 1)):
        raise ValueError(f"cos_theta must lie in [0, 1), got {float(c[(c < 0) | (c >= 1)][0])!r}")
    g = ellipse_ratio((1.0 + c) / (1.0 - c))
    E = special.ellipe(1.0 - g * g)
    m = (2.0 * E / (np.pi * g * g)) ** (1.0 / 3.0)
    return m, m * g, g


@dataclass(frozen=True)
class HertzContact:
    """Result of a Hertz computation; every field is an (n,) ndarray in SI units.

    Attributes
    ----------
    a, b : semi-axes along the rolling direction and lateral [m]
    delta : approach (penetration) [m]
    normal_force : N [N]
    stiffness : K_h in N = K_h delta^(3/2) [N/m^1.5]
    p0 : peak pressure 3N/(2 pi a b) [Pa]
    g : minor/major axis ratio [-]
    m, n : Hertz coefficients [-]
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
    A = np.atleast_1d(_as_array("A", A))
    B = np.atleast_1d(_as_array("B", B))
    A, B = np.broadcast_arrays(A, B)
    bad = (A <= 0) | (B <= 0) | ~np.isfinite(A) | ~np.isfinite(B)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"relative curvatures must be finite and > 0; contact {i}: "
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
    """Hertz contact ellipse, approach and stiffness for a given normal load.

    Parameters
    ----------
    normal_force : float or (n,) array_like
        Normal load N >= 0 [N].
    A, B : float or (n,) array_like
        Relative curvatures along the rolling direction and lateral [1/m], both > 0
        (see :func:`relative_curvatures`).
    E1, nu1, E2, nu2 : float or (n,) array_like
        Young's moduli [Pa] and Poisson ratios of wheel and rail.

    Returns
    -------
    HertzContact

    Raises
    ------
    ValueError
        Negative or NaN load, nu outside [0, 0.5], non-positive curvature.
    """
    N = np.atleast_1d(_as_array("normal_force", normal_force))
    if np.any(N < 0):
        i = int(np.flatnonzero(N < 0)[0])
        raise ValueError(f"normal_force must be >= 0, got {float(N[i])!r} N at index {i}")
    A, B, ksum, S, g, Kel, mH, nH, Kh = _geometry(A, B, E1, nu1, E2, nu2)
    N = np.broadcast_to(N, A.shape).astype(float)
    delta = 2.0 * Kel / (np.pi * mH) * np.cbrt((3.0 * np.pi * N * ksum / 4.0) ** 2 * S)
    return _finish(A, B, N, ksum, S, g, mH, nH, Kh, delta)


def hertz_from_penetration(penetration, A, B, E1, nu1, E2, nu2) -> HertzContact:
    """Hertz contact for a given approach delta; N = K_h max(delta, 0)^(3/2).

    Parameters
    ----------
    penetration : float or (n,) array_like
        Approach delta [m]; values <= 0 give no contact (N = 0, a = b = 0).
    A, B, E1, nu1, E2, nu2 :
        As in :func:`hertz_from_load`.

    Returns
    -------
    HertzContact
    """
    d = np.atleast_1d(_as_array("penetration", penetration))
    A, B, ksum, S, g, Kel, mH, nH, Kh = _geometry(A, B, E1, nu1, E2, nu2)
    d = np.broadcast_to(d, A.shape).astype(float)
    N = Kh * np.maximum(d, 0.0) ** 1.5
    return _finish(A, B, N, ksum, S, g, mH, nH, Kh, d)


def lankarani_nikravesh_force(penetration, penetration_rate, stiffness, restitution,
                              approach_velocity=None, approach_velocity_floor=0.1):
    """Lankarani-Nikravesh normal force with hysteresis damping [N].

    F_N = K_h delta^(3/2) [1 + 3 (1 - c_e^2)/4 * delta_dot / v0]  for delta > 0, else 0,
    with v0 = max(|approach_velocity|, approach_velocity_floor), and F_N clipped at >= 0.

    Choice for steady rolling (documented trap): the law was derived for impacts, where
    delta_dot^(-) is the approach velocity at first touch.  In steady rolling there is no impact and
    delta_dot^(-) is undefined (it would be ~0, making the damping term singular).  We therefore use
    the engagement velocity when the caller knows it (``approach_velocity``, e.g. the value stored
    by a contact element when a flange contact is first detected) and never less than the floor
    ``approach_velocity_floor`` (default 0.1 m/s).  With ``approach_velocity=None`` the floor alone
    is used, so the law acts as a Hertz spring with the linear-in-rate damper
    c(delta) = 3 (1 - c_e^2) K_h delta^(3/2) / (4 v0).  The force is clipped at zero because the
    law would otherwise pull the bodies together in fast separation (delta_dot < -4 v0/(3(1-c_e^2))).

    Parameters
    ----------
    penetration : float or (n,) array_like
        delta [m].
    penetration_rate : float or (n,) array_like
        d delta/dt [m/s] (> 0 approaching).
    stiffness : float or (n,) array_like
        K_h [N/m^1.5] (from :func:`hertz_from_load`).
    restitution : float or (n,) array_like
        Coefficient of restitution c_e in [0, 1].
    approach_velocity : float, (n,) array_like or None
        Velocity at engagement [m/s]; None in steady rolling.
    approach_velocity_floor : float
        Lower bound v0 [m/s] (> 0).

    Returns
    -------
    (n,) ndarray
        Normal force [N].

    References
    ----------
    Lankarani & Nikravesh (1990), J. Mech. Design 112: 369-376.
    """
    d = np.atleast_1d(_as_array("penetration", penetration))
    dd = np.atleast_1d(_as_array("penetration_rate", penetration_rate))
    K = np.atleast_1d(_as_array("stiffness", stiffness))
    ce = np.atleast_1d(_as_array("restitution", restitution))
    if np.any((ce < 0) | (ce > 1)):
        raise ValueError(f"restitution must lie in [0, 1], got {float(ce[(ce < 0) | (ce > 1)][0])!r}")
    if np.any(K < 0):
        raise ValueError(f"stiffness must be >= 0, got {float(K[K < 0][0])!r}")
    if not approach_velocity_floor > 0:
        raise ValueError(f"approach_velocity_floor must be > 0, got {approach_velocity_floor!r}")
    v0 = np.full(1, float(approach_velocity_floor))
    if approach_velocity is not None:
        v0 = np.maximum(np.abs(np.atleast_1d(_as_array("approach_velocity", approach_velocity))), v0)
    dpos = np.maximum(d, 0.0)
    F = K * dpos**1.5 * (1.0 + 0.75 * (1.0 - ce**2) * dd / v0)
    return np.where(d > 0, np.maximum(F, 0.0), 0.0)
