"""Hertz normal contact and the Lankarani-Nikravesh law, checked against physics.

Oracles: the closed-form sphere-on-plane solution; an independent numerical integration of Hertz's potential integrals (scipy.integrate.quad);
the coefficient of restitution of a simulated impact.
"""

import numpy as np
import pytest
from scipy import integrate

from railway.hertz import (
    effective_modulus,
    ellipse_ratio,
    hertz_coefficients,
    hertz_from_load,
    hertz_from_penetration,
    lankarani_nikravesh_force,
    relative_curvatures,
)

E_STEEL = 210e9
NU_STEEL = 0.3


def test_sphere_on_plane_closed_form():
    # Johnson (1985) eq. for a sphere of radius R on a plane: a^3 = 3NR/(4E*), delta = a^2/R,
    # N = (4/3) E* sqrt(R) delta^(3/2).
    R = np.array([0.01, 0.46, 2.0])
    N = np.array([10.0, 1e5, 3e4])
    Es = effective_modulus(E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    A = B = 1.0 / (2.0 * R)
    h = hertz_from_load(N, A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    a_ref = np.cbrt(3.0 * N * R / (4.0 * Es))
    np.testing.assert_allclose(h.a, a_ref, rtol=1e-12)
    np.testing.assert_allclose(h.b, a_ref, rtol=1e-12)
    np.testing.assert_allclose(h.delta, a_ref**2 / R, rtol=1e-12)
    np.testing.assert_allclose(h.stiffness, 4.0 / 3.0 * Es * np.sqrt(R), rtol=1e-12)
    np.testing.assert_allclose(h.p0, 3.0 * N / (2.0 * np.pi * a_ref**2), rtol=1e-12)


def _hertz_integrals(a, b, N, Es):
    """A, B, delta of an elliptical Hertz pressure on a half space by the potential integrals.

    delta - A x^2 - B y^2 = 3N/(4 pi E*) int_0^inf [1 - x^2/(a^2+w) - y^2/(b^2+w)]
                                                   dw / sqrt((a^2+w)(b^2+w) w)
    (Johnson 1985, sect. 3.6 / 4.2; the sphere case reproduces delta = a^2/R, A = B = 1/(2R)).
    Substitute w = u^2 to remove the end-point singularity.
    """
    k = 3.0 * N / (4.0 * np.pi * Es)

    def I(f):
        val, _ = integrate.quad(lambda u: 2.0 * f(u * u) / np.sqrt((a * a + u * u) * (b * b + u * u)),
                                0.0, np.inf, epsabs=0.0, epsrel=1e-13, limit=500)
        return val

    delta = k * I(lambda w: 1.0)
    A = k * I(lambda w: 1.0 / (a * a + w))
    B = k * I(lambda w: 1.0 / (b * b + w))
    return A, B, delta


@pytest.mark.parametrize("a_over_b", [0.05, 0.2, 0.5, 0.9, 1.0, 1.7, 4.0, 25.0])
def test_against_numerical_hertz_integrals(a_over_b):
    Es = effective_modulus(E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    N = 7.5e4
    b = 5e-3
    a = a_over_b * b
    A, B, delta = _hertz_integrals(a, b, N, Es)
    h = hertz_from_load(N, A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    # quad at epsrel 1e-13 and the bisection at machine precision: agree to ~1e-9
    np.testing.assert_allclose(h.a, a, rtol=1e-8)
    np.testing.assert_allclose(h.b, b, rtol=1e-8)
    np.testing.assert_allclose(h.delta, delta, rtol=1e-8)
    np.testing.assert_allclose(h.stiffness * h.delta**1.5, N, rtol=1e-8)
    # the Hertz coefficients from cos(theta) give the same ellipse ratio
    m, n, g = hertz_coefficients(abs(B - A) / (A + B))
    np.testing.assert_allclose(g, min(a, b) / max(a, b), rtol=1e-8)
    np.testing.assert_allclose(n / m, g, rtol=1e-14)


def test_ellipse_ratio_vectorised_and_consistent_with_legendre_form():
    from scipy import special

    r = np.geomspace(1.0, 1e8, 200)
    g = ellipse_ratio(r)
    assert np.all(np.diff(g) < 0)  # larger curvature ratio -> more elongated ellipse
    m = 1.0 - g[1:] ** 2
    K, E = special.ellipk(m), special.ellipe(m)
    ratio = (E / g[1:] ** 2 - K) / (K - E)
    # the Legendre form suffers cancellation ~ eps/(1-g^2) near g = 1
    # and ellipk/ellipe near m = 1 see 1 - m = g^2 rounded: ~ eps/g^2
    tol = 8 * np.finfo(float).eps * (1.0 / m + 1.0 / g[1:] ** 2)
    assert np.all(np.abs(ratio / r[1:] - 1.0) <= tol)


def test_penetration_inverse_of_load_and_no_contact():
    A, B = np.array([1.1, 30.0]), np.array([40.0, 2.0])
    h = hertz_from_load([2e4, 9e4], A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    h2 = hertz_from_penetration(h.delta, A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    np.testing.assert_allclose(h2.normal_force, [2e4, 9e4], rtol=1e-12)
    np.testing.assert_allclose(h2.a, h.a, rtol=1e-12)
    h3 = hertz_from_penetration([-1e-5, 0.0], A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    assert np.all(h3.normal_force == 0) and np.all(h3.a == 0) and np.all(h3.p0 == 0)


def test_orientation_of_axes_wheel_on_rail():
    # tread contact: wheel R 0.46 m, rail crown R 0.3 m: A = 1/(2*0.46) < B = (1/0.3)/2 + 0
    A, B = relative_curvatures(0.46, np.inf, 0.3)
    h = hertz_from_load(1e5, A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    assert h.a[0] > h.b[0]  # smaller curvature along x -> major axis along the rolling direction
    # gauge-corner contact R13 rail against a convex R20 flange: lateral curvature dominates
    A2, B2 = relative_curvatures(0.47, 0.020, 0.013)
    h2 = hertz_from_load(1e5, A2, B2, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    assert h2.a[0] > 3 * h2.b[0]


def test_concave_flange_root_on_gauge_corner():
    # flange root R -13.1 mm (concave) on gauge corner R 13 mm: nearly conformal lateral curvature
    A, B = relative_curvatures(0.46, -0.0131, 0.013)
    np.testing.assert_allclose(B, 0.5 * (1 / 0.013 - 1 / 0.0131), rtol=1e-12)
    h = hertz_from_load(5e4, A, B, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    assert h.b[0] > h.a[0]  # B small now -> long lateral axis
    # concave radius smaller in magnitude than the convex one: not Hertzian
    with pytest.raises(ValueError, match="non-Hertzian contact at index 1"):
        relative_curvatures([0.46, 0.46], [-0.014, -0.012], [0.013, 0.013])


@pytest.mark.parametrize("kwargs, match", [
    (dict(normal_force=-1.0), "normal_force must be >= 0, got -1.0"),
    (dict(normal_force=np.nan), "normal_force contains NaN"),
    (dict(nu1=0.6), "nu1 must lie in \\[0, 0.5\\], got 0.6"),
    (dict(nu2=-0.1), "nu2 must lie in \\[0, 0.5\\], got -0.1"),
    (dict(E2=0.0), "E2 must be > 0, got 0.0"),
    (dict(A=-2.0), "A=-2.0"),
])
def test_bad_input(kwargs, match):
    args = dict(normal_force=1e4, A=1.0, B=2.0, E1=E_STEEL, nu1=NU_STEEL, E2=E_STEEL, nu2=NU_STEEL)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        hertz_from_load(**args)


def test_lankarani_nikravesh_limits():
    K = 1e10
    d = np.array([-1e-5, 1e-5, 1e-5, 1e-5])
    dd = np.array([1.0, 0.0, 0.05, -50.0])
    F = lankarani_nikravesh_force(d, dd, K, restitution=0.8)
    hertz = K * 1e-5**1.5
    assert F[0] == 0.0
    assert F[1] == pytest.approx(hertz, rel=1e-14)  # steady rolling, no rate: pure Hertz
    # floor 0.1 m/s used when no engagement velocity is given (documented steady-rolling choice)
    assert F[2] == pytest.approx(hertz * (1 + 0.75 * 0.36 * 0.05 / 0.1), rel=1e-14)
    assert F[3] == 0.0  # fast separation: clipped, never adhesive
    F2 = lankarani_nikravesh_force(1e-5, 0.05, K, 0.8, approach_velocity=2.0)
    assert F2[0] == pytest.approx(hertz * (1 + 0.75 * 0.36 * 0.05 / 2.0), rel=1e-14)
    F3 = lankarani_nikravesh_force(1e-5, 0.05, K, 1.0)
    assert F3[0] == pytest.approx(hertz, rel=1e-14)
    with pytest.raises(ValueError, match="restitution must lie in \\[0, 1\\], got 1.5"):
        lankarani_nikravesh_force(1e-5, 0.0, K, 1.5)


@pytest.mark.parametrize("ce", [0.95, 0.9])
def test_lankarani_nikravesh_restitution_of_an_impact(ce):
    """A sphere dropped on a plane rebounds with ~c_e (the law is derived for c_e near 1).

    Lankarani & Nikravesh derive the damping from the energy lost in one impact to first order in
    (1 - c_e^2); the simulated restitution therefore agrees with c_e to O((1 - c_e)^2).
    """
    R, mass, v0 = 0.01, 0.05, 1.0
    h = hertz_from_load(1.0, 1 / (2 * R), 1 / (2 * R), E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    K = h.stiffness[0]

    def rhs(t, y):
        d, ddot = y
        return [ddot, -lankarani_nikravesh_force(d, ddot, K, ce, approach_velocity=v0)[0] / mass]

    def leave(t, y):
        return y[0]

    leave.terminal, leave.direction = True, -1
    sol = integrate.solve_ivp(rhs, (0, 1e-2), [1e-12, v0], events=leave, rtol=1e-10, atol=1e-16,
                              method="DOP853")
    v_out = -sol.y_events[0][0][1]
    assert v_out / v0 == pytest.approx(ce, abs=2 * (1 - ce) ** 2 + 1e-6)
