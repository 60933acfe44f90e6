"""core.curves: piecewise polynomials and the tabulated framed curve, without any domain package.

Reference curve: the circular helix of radius a and pitch parameter c (rise 2 pi c per turn) in
its arc length s, with w = 1/sqrt(a^2 + c^2)::

    r(s) = (a cos ws, a sin ws, c w s)
    t = r' = (-a w sin ws, a w cos ws, c w),   r'' = kappa n
    n = (-cos ws, -sin ws, 0),                 b = t x n = (c w sin ws, -c w cos ws, a w)
    kappa = a w^2 = a/(a^2 + c^2),             tau = c w^2 = c/(a^2 + c^2)
    omega = tau t + kappa b = (0, 0, w)        (constant: omega' = omega'' = 0)

Error bounds of the quintic Hermite table (interval length h, M6 = max |f^(6)| of a component f).
The interpolation error e = f - p has triple zeros at both ends of the interval, so

* value:  e(x) = f^(6)(xi)/6! x^3 (x - h)^3, and max |x^3 (x - h)^3| = (h/2)^6, hence
  E0 = M6 h^6 / 46080;
* first derivative: e' has double zeros at 0 and h and, by Rolle, one zero z in (0, h); p' is
  the quartic interpolating f' at {0, 0, h, h, z}, so e'(x) = f^(6)(eta)/5! x^2 (x - h)^2 (x - z)
  and E1 = M6 (h^4/16) h / 120 = M6 h^5 / 1920;
* second derivative: e'' vanishes at 0, h and (Rolle on e') once in (0, z) and once in (z, h);
  p'' is the cubic through these four points, so |e''| <= M6/4! x (h - x) h^2 and
  E2 = M6 h^4 / 96.

For the helix M6 = a w^6 for the components of r (x and y; z is linear and exact) and M6 <= w^6
for the entries of R (each is a constant or an amplitude <= 1 times cos or sin of ws); omega is
constant and reproduced exactly.  Round-off: the coefficients c3..c5 are differences of values of
size S divided by h^3..h^5 and multiplied back by t^k <= h^k, so the table loses a few hundred
ulps of S in values and that divided by h^k in the k-th derivative; we allow 1000 eps S / h^k.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.curves import (
    CurveFrame,
    FramedCurve,
    PiecewisePoly,
    TabulatedFramedCurve,
    concatenate,
    quintic_hermite_coeffs,
)

EPS = np.finfo(float).eps
A_HELIX, C_HELIX = 3.0, 1.0  # m


def helix(s, a=A_HELIX, c=C_HELIX):
    """Exact helix point, Frenet frame and Darboux vector at arc lengths s (CurveFrame with omega'')."""
    s = np.asarray(s, dtype=float)
    w = 1.0 / np.hypot(a, c)
    cs, sn, o, z = np.cos(w * s), np.sin(w * s), np.ones_like(s), np.zeros_like(s)
    r = np.stack([a * cs, a * sn, c * w * s], axis=1)
    t = np.stack([-a * w * sn, a * w * cs, c * w * o], axis=1)
    n = np.stack([-cs, -sn, z], axis=1)
    b = np.stack([c * w * sn, -c * w * cs, a * w * o], axis=1)
    ddr = a * w**2 * n
    om = np.stack([z, z, w * o], axis=1)
    zero = np.zeros_like(om)
    return CurveFrame(r, t, ddr, np.stack([t, n, b], axis=2), om, zero, ddomega=zero)


def rolled_helix(s, phi0=0.4, lam=20.0, a=A_HELIX, c=C_HELIX):
    """Helix whose frame is rolled about t by phi(s) = phi0 sin(2 pi s/lam): a banked track.

    R = [t, cos(phi) n + sin(phi) b, -sin(phi) n + cos(phi) b],  omega = (0, 0, w) + phi' t,
    omega' = phi'' t + phi' kappa n,  omega'' = phi''' t + 2 phi'' kappa n + phi' kappa (tau b - kappa t).
    """
    f = helix(s, a, c)
    w = 1.0 / np.hypot(a, c)
    kap, tau = a * w**2, c * w**2
    k = 2 * np.pi / lam
    s = np.asarray(s, dtype=float)
    phi, d1, d2, d3 = (phi0 * np.sin(k * s), phi0 * k * np.cos(k * s), -phi0 * k**2 * np.sin(k * s),
                       -phi0 * k**3 * np.cos(k * s))
    t, n, b = f.tangent, f.normal, f.binormal
    cf, sf = np.cos(phi)[:, None], np.sin(phi)[:, None]
    R = np.stack([t, cf * n + sf * b, -sf * n + cf * b], axis=2)
    om = f.omega + d1[:, None] * t
    dom = d2[:, None] * t + (d1 * kap)[:, None] * n
    ddom = d3[:, None] * t + (2 * d2 * kap)[:, None] * n + (d1 * kap)[:, None] * (tau * b - kap * t)
    return CurveFrame(f.position, f.dposition, f.ddposition, R, om, dom, ddomega=ddom)


def _table(fun, h, s0=-5.0, n=50, **kw):
    nodes = s0 + h * np.arange(n + 1)
    return nodes, TabulatedFramedCurve(nodes, fun(nodes), **kw)


def _between(nodes, rng):
    """Midpoints of every interval and random points strictly inside the intervals."""
    a, b = nodes[:-1], nodes[1:]
    x = rng.uniform(0.02, 0.98, size=(4, a.size))
    return np.concatenate([0.5 * (a + b), (a + x * (b - a)).ravel()])


def _skew_times(om, R):
    return np.cross(om[:, None, :], np.swapaxes(R, 1, 2)).swapaxes(1, 2)


# ---------------------------------------------------------------------------------------------
# tabulated framed curve: helix
# ---------------------------------------------------------------------------------------------
H = 0.8  # node spacing (m)
W = 1.0 / np.hypot(A_HELIX, C_HELIX)
E0_r = A_HELIX * W**6 * H**6 / 46080  # position, per component (m)
E1_r = A_HELIX * W**6 * H**5 / 1920  # r'
E2_r = A_HELIX * W**6 * H**4 / 96  # r''
E0_R = W**6 * H**6 / 46080  # entries of R
E1_R = W**6 * H**5 / 1920  # entries of dR/ds from the table
S_r = A_HELIX + C_HELIX * W * 40.0  # largest |r| component on [-5, 35] m
ROUND = 1000 * EPS


def test_helix_reproduces_position_frame_curvature_torsion_and_darboux():
    """Between nodes the table reproduces the helix to the quintic Hermite bounds E0, E1, E2.

    position: E0_r; tangent (column of R): E0_R; r': E1_r; r'': E2_r;
    curvature kappa = b . omega and torsion tau = t . omega (the Frenet frame has no omega
    component along n): the error of b or t is at most sqrt(3) E0_R in norm and omega is exact,
    so |error| <= |omega| sqrt(3) E0_R = w sqrt(3) E0_R; kappa = |r''| to sqrt(2) E2_r;
    omega itself (constant) to round-off, and omega = tau t + kappa b to w sqrt(3) E0_R.
    """
    nodes, curve = _table(helix, H)
    s = _between(nodes, np.random.default_rng(1))
    f, ex = curve.evaluate(s), helix(s)
    kap, tau = A_HELIX * W**2, C_HELIX * W**2
    assert kap == pytest.approx(A_HELIX / (A_HELIX**2 + C_HELIX**2), rel=1e-15)
    assert tau == pytest.approx(C_HELIX / (A_HELIX**2 + C_HELIX**2), rel=1e-15)

    err_r = np.max(np.abs(f.position - ex.position))
    assert err_r <= E0_r + ROUND * S_r
    assert err_r >= 0.5 * E0_r  # the bound is tight: the table really is a quintic interpolant
    assert np.max(np.abs(f.tangent - ex.tangent)) <= E0_R + ROUND
    assert np.max(np.abs(f.dposition - ex.tangent)) <= E1_r + ROUND * S_r / H
    assert np.max(np.abs(f.ddposition - ex.ddposition)) <= E2_r + ROUND * S_r / H**2
    assert np.max(np.abs(f.R - ex.R)) <= E0_R + ROUND

    tol_frame = W * np.sqrt(3) * E0_R + ROUND
    assert np.max(np.abs(np.einsum("ij,ij->i", f.binormal, f.omega) - kap)) <= tol_frame
    assert np.max(np.abs(np.einsum("ij,ij->i", f.tangent, f.omega) - tau)) <= tol_frame
    assert np.max(np.abs(np.linalg.norm(f.ddposition, axis=1) - kap)) <= np.sqrt(2) * E2_r + ROUND
    assert np.max(np.abs(f.omega - [0.0, 0.0, W])) <= ROUND
    assert np.max(np.abs(f.domega)) <= ROUND / H
    darboux = tau * f.tangent + kap * f.binormal
    assert np.max(np.abs(darboux - f.omega)) <= tol_frame


def test_helix_at_nodes_is_exact_and_raw_equals_evaluate():
    nodes, curve = _table(helix, H)
    f, ex = curve.evaluate(nodes), helix(nodes)
    for key in ("position", "dposition", "ddposition", "R", "omega", "domega"):
        assert np.max(np.abs(getattr(f, key) - getattr(ex, key))) <= ROUND * S_r / H**2, key
    s = _between(nodes, np.random.default_rng(2))
    raw = curve.evaluate_raw(s)
    f = curve.evaluate(s)
    for a, key in zip(raw, ("position", "dposition", "ddposition", "R", "omega", "domega"), strict=True):
        assert np.array_equal(a, getattr(f, key)), key
    assert curve.length == pytest.approx(50 * H, rel=1e-15) and not curve.closed
    assert isinstance(curve, FramedCurve)


def test_helix_frame_orthonormal():
    """R~ = R + E with |E_ij| <= E0_R: R~^T R~ - I = R^T E + E^T R + E^T E has entries at most
    2 sqrt(3) E0_R + 3 E0_R^2 (each column of E has norm <= sqrt(3) E0_R)."""
    nodes, curve = _table(helix, H)
    R = curve.evaluate(_between(nodes, np.random.default_rng(3))).R
    RtR = np.einsum("nki,nkj->nij", R, R)
    tol = 2 * np.sqrt(3) * E0_R + 3 * E0_R**2 + ROUND
    assert np.max(np.abs(RtR - np.eye(3))) <= tol
    assert np.max(np.abs(np.linalg.det(R) - 1.0)) <= 3 * tol


def test_table_dR_equals_darboux_cross_R():
    """The table's own derivative of R equals [omega]x R: |dR_table - R'| <= E1_R per entry and
    |[omega]x R~ - [omega]x R| <= |omega| sqrt(3) E0_R."""
    nodes, curve = _table(helix, H)
    s = _between(nodes, np.random.default_rng(4))
    _, d1, _ = curve.table(s)
    dR_table = d1[:, TabulatedFramedCurve.ROTATION].reshape(-1, 3, 3)
    f = curve.evaluate(s)
    tol = E1_R + W * np.sqrt(3) * E0_R + ROUND / H
    assert np.max(np.abs(dR_table - _skew_times(f.omega, f.R))) <= tol
    assert np.max(np.abs(dR_table - f.dR())) <= tol
    # and both equal the exact derivative of the Frenet frame
    ex = helix(s)
    assert np.max(np.abs(dR_table - _skew_times(ex.omega, ex.R))) <= E1_R + ROUND / H


# ---------------------------------------------------------------------------------------------
# tabulated framed curve: rolled helix (omega varies) -- sixth-order convergence
# ---------------------------------------------------------------------------------------------
def test_rolled_helix_converges_at_sixth_order():
    """With a roll phi(s) about t, omega, omega' and omega'' vary; halving h divides the value
    errors of r, R, omega by 2^6 = 64 (asymptotically; > 40 required) and the error of
    dR_table - [omega]x R by 2^5 = 32 (> 20 required)."""
    errs = []
    for h in (1.0, 0.5):
        nodes, curve = _table(rolled_helix, h, s0=0.0, n=round(40.0 / h))
        s = 0.5 * (nodes[:-1] + nodes[1:])
        f, ex = curve.evaluate(s), rolled_helix(s)
        _, d1, _ = curve.table(s)
        dR = d1[:, TabulatedFramedCurve.ROTATION].reshape(-1, 3, 3)
        errs.append(np.array([np.max(np.abs(f.position - ex.position)), np.max(np.abs(f.R - ex.R)),
                              np.max(np.abs(f.omega - ex.omega)),
                              np.max(np.abs(dR - _skew_times(f.omega, f.R)))]))
    ratio = errs[0] / errs[1]
    assert np.all(ratio[:3] > 40.0), ratio
    assert ratio[3] > 20.0, ratio
    assert np.all(errs[1] < 1e-6), errs[1]


def test_closed_curve_wraps_the_arc_length():
    """A circle (helix with c = 0) over one turn is closed; s is taken modulo its length."""
    a = 5.0
    L = 2 * np.pi * a
    nodes = np.linspace(0.0, L, 41)
    curve = TabulatedFramedCurve(nodes, helix(nodes, a=a, c=0.0), closed=True, name="loop")
    assert curve.closed and curve.length == pytest.approx(L)
    s = np.array([0.3, 7.0, 20.0])
    f0, f1, f2 = curve.evaluate(s), curve.evaluate(s + L), curve.evaluate(s - 3 * L)
    for g in (f1, f2):
        assert np.allclose(g.position, f0.position, atol=1e-12, rtol=0)
        assert np.allclose(g.R, f0.R, atol=1e-12, rtol=0)
    with pytest.raises(ValueError, match="does not close"):
        TabulatedFramedCurve(nodes[:-5], helix(nodes[:-5], a=a, c=0.0), closed=True)


def test_one_sided_end_values():
    """With ``end`` given, each interval uses its own right-end values (one-sided limits)."""
    nodes = np.array([0.0, 1.0, 2.0])
    start = helix(nodes[:-1])
    end = helix(nodes[1:])
    curve = TabulatedFramedCurve(nodes, start, end)
    ref = TabulatedFramedCurve(nodes, helix(nodes))
    s = np.linspace(0.0, 2.0, 17)
    assert np.array_equal(curve.table(s)[0], ref.table(s)[0])


class _ExactHelix(FramedCurve):
    """A FramedCurve written directly in closed form (only evaluate_raw is required)."""

    length = 10.0

    def evaluate_raw(self, s):
        f = helix(s)
        return f.position, f.dposition, f.ddposition, f.R, f.omega, f.domega


def test_framed_curve_interface():
    with pytest.raises(TypeError):
        FramedCurve()  # abstract
    c = _ExactHelix()
    f = c.evaluate(2.0)
    assert isinstance(f, CurveFrame) and f.R.shape == (1, 3, 3) and f.ddomega is None
    assert np.allclose(f.dR(), _skew_times(f.omega, f.R))
    with pytest.raises(ValueError, match=r"curve: non-finite arc length s\[1\] = inf"):
        c.evaluate([1.0, np.inf])


# ---------------------------------------------------------------------------------------------
# bad input
# ---------------------------------------------------------------------------------------------
def test_bad_input_names_the_value():
    _, curve = _table(helix, H)
    with pytest.raises(ValueError, match=r"non-finite arc length s\[2\] = nan"):
        curve.evaluate([0.0, 1.0, np.nan])
    bad = np.array([0.0, 1.0, 1.0, 2.0])
    with pytest.raises(ValueError, match=r"nodes\[2\] = 1\.0 after nodes\[1\] = 1\.0"):
        TabulatedFramedCurve(bad, helix(bad))
    bad = np.array([0.0, 2.0, 1.5, 3.0])
    with pytest.raises(ValueError, match=r"nodes\[2\] = 1\.5"):
        TabulatedFramedCurve(bad, helix(bad))
    bad = np.array([0.0, np.nan, 2.0])
    with pytest.raises(ValueError, match=r"nodes\[1\] = nan is not finite"):
        TabulatedFramedCurve(bad, helix(np.array([0.0, 1.0, 2.0])))
    with pytest.raises(ValueError, match="at least 2"):
        TabulatedFramedCurve([0.0], helix(np.array([0.0])))
    good = np.array([0.0, 1.0, 2.0])
    f = helix(good)
    f.omega[1, 2] = np.inf
    with pytest.raises(ValueError, match=r"start\.omega\[1, 2\] = inf is not finite"):
        TabulatedFramedCurve(good, f)
    f = helix(good)
    f.R[2] *= 1.01
    with pytest.raises(ValueError, match=r"start\.R\[2\] is not orthonormal"):
        TabulatedFramedCurve(good, f)
    f = helix(good)
    f.ddomega = None
    with pytest.raises(ValueError, match="ddomega"):
        TabulatedFramedCurve(good, f)
    with pytest.raises(ValueError, match=r"start\.position has shape \(3, 3\), expected \(2, 3\)"):
        TabulatedFramedCurve(good, helix(good), helix(good[1:]))


# ---------------------------------------------------------------------------------------------
# piecewise polynomials
# ---------------------------------------------------------------------------------------------
def test_quintic_hermite_reproduces_quintics():
    rng = np.random.default_rng(5)
    c = rng.normal(size=6)
    p = np.polynomial.Polynomial(c)
    x = np.array([-1.0, -0.3, 0.4, 1.2])
    pp = PiecewisePoly.from_hermite(x, p(x), p.deriv(1)(x), p.deriv(2)(x))
    xs = np.linspace(-1.0, 1.2, 101)
    f, d1, d2 = pp(xs)
    assert np.allclose(f, p(xs), atol=1e-12, rtol=0)
    assert np.allclose(d1, p.deriv(1)(xs), atol=1e-11, rtol=0)
    assert np.allclose(d2, p.deriv(2)(xs), atol=1e-10, rtol=0)
    # local coefficients of one interval are the Taylor coefficients about its left end
    q = quintic_hermite_coeffs(1.0, p(0.0), p.deriv(1)(0.0), p.deriv(2)(0.0),
                               p(1.0), p.deriv(1)(1.0), p.deriv(2)(1.0))
    assert np.allclose(q, c, atol=1e-12)


def test_vector_valued_and_shapes():
    x = np.array([0.0, 1.0, 3.0])
    f = np.stack([x**2, -x, np.ones_like(x)], axis=1)
    pp = PiecewisePoly.from_hermite(x, f, np.stack([2 * x, -np.ones(3), 0 * x], 1),
                                    np.stack([2 + 0 * x, 0 * x, 0 * x], 1))
    v, d1, d2 = pp(np.array([[0.5, 2.0]]))
    assert v.shape == (1, 2, 3) and d1.shape == (1, 2, 3)
    assert np.allclose(v[0], [[0.25, -0.5, 1.0], [4.0, -2.0, 1.0]])
    assert np.allclose(d2[0, :, 0], 2.0)
    assert pp.degree == 5 and pp.n_components == 3 and not pp.scalar


def test_from_scipy_matches_scipy_ppoly():
    from scipy.interpolate import CubicSpline

    x = np.linspace(0.0, 2.0, 9)
    cs = CubicSpline(x, np.sin(3 * x))
    pp = PiecewisePoly.from_scipy(cs)
    xs = np.linspace(-0.2, 2.2, 57)  # includes extrapolation with the end pieces
    f, d1, d2 = pp(xs)
    assert np.allclose(f, cs(xs), atol=1e-13) and np.allclose(d1, cs(xs, 1), atol=1e-12)
    assert np.allclose(d2, cs(xs, 2), atol=1e-11)
    assert pp.scalar and pp.x_min == 0.0 and pp.x_max == 2.0


def _bank():
    from scipy.interpolate import CubicSpline

    p1 = PiecewisePoly.from_scipy(CubicSpline([0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 0.0, 2.0]))
    x2 = np.array([-1.0, -0.5, 0.0])
    p2 = PiecewisePoly.from_hermite(x2, x2**2, 2 * x2, 2 + 0 * x2)
    return p1, p2, *concatenate([p1, p2])


def test_concatenate_bank_with_offsets():
    p1, p2, bank, off = _bank()
    xs1 = np.linspace(0.0, 3.0, 13)[:-1]  # [x_min, x_max) of a member followed by a filler
    xs2 = np.linspace(-1.0, 0.0, 9)  # the last member: closed range
    for p, o, xs in ((p1, off[0], xs1), (p2, off[1], xs2)):
        for a, b in zip(p(xs), bank(xs + o), strict=True):
            assert np.allclose(a, b, atol=1e-13)


@pytest.mark.xfail(strict=True, reason="known defect kept unchanged in this step: at the exact "
                   "right end of a member followed by another, the bank evaluates the zero filler")
def test_concatenate_right_end_of_inner_member():
    p1, _, bank, off = _bank()
    assert np.allclose(bank(np.array([3.0 + off[0]]))[0], p1(np.array([3.0]))[0])


def test_piecewise_poly_bad_breaks():
    with pytest.raises(ValueError, match=r"break 2 = 1\.0"):
        PiecewisePoly([0.0, 1.0, 1.0], np.zeros((2, 4)))
    with pytest.raises(ValueError, match="pieces"):
        PiecewisePoly([0.0, 1.0], np.zeros((2, 4)))
