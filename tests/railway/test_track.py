"""Track centreline and frame: orthonormality, derivatives, circle and clothoid curvature."""

import numpy as np
import pytest

from core.curves import CurveFrame, FramedCurve, TabulatedFramedCurve
from railway.track import Curve, Irregularities, Straight, Track, TrackFrame, Transition


def _track(irr=False):
    segs = [Straight(50.0), Transition(40.0), Curve(120.0, 400.0, 0.10), Transition(40.0),
            Straight(30.0), Transition(30.0), Curve(60.0, -250.0, 0.05), Transition(30.0),
            Straight(20.0)]
    ir = None
    if irr:
        s = np.linspace(10.0, 400.0, 391)
        w = np.sin(np.pi * (s - 10.0) / 390.0) ** 2  # starts and ends at zero
        ir = Irregularities(s, 2e-3 * w * np.sin(s / 5.0), 1.5e-3 * w * np.cos(s / 7.0))
    return Track(segs, irregularities=ir)


@pytest.mark.parametrize("irr", [False, True])
def test_frame_orthonormal(irr):
    tr = _track(irr)
    f = tr.evaluate(np.linspace(0.0, tr.length, 997))
    RtR = np.einsum("nki,nkj->nij", f.R, f.R)
    assert np.max(np.abs(RtR - np.eye(3))) < 1e-13
    assert np.allclose(np.linalg.det(f.R), 1.0, atol=1e-13)


@pytest.mark.parametrize("irr", [False, True])
def test_frame_derivatives_by_finite_differences(irr):
    tr = _track(irr)
    s = np.linspace(1.0, tr.length - 1.0, 301)
    s = s[np.min(np.abs(s[:, None] - tr.s_joints[None, :]), axis=1) > 1e-3]  # avoid joints
    h = 1e-5
    f, fp, fm = tr.evaluate(s), tr.evaluate(s + h), tr.evaluate(s - h)
    # central differences: truncation h^2 |x'''|/6 ~ 1e-10 * 1e-2 -> tolerance 1e-8 relative
    assert np.max(np.abs((fp.position - fm.position) / (2 * h) - f.dposition)) < 1e-8
    assert np.max(np.abs((fp.R - fm.R) / (2 * h) - f.dR())) < 1e-8
    assert np.max(np.abs((fp.dposition - fm.dposition) / (2 * h) - f.ddposition)) < 1e-6
    assert np.max(np.abs((fp.omega - fm.omega) / (2 * h) - f.domega)) < 1e-8


def test_arc_length_parameterisation():
    tr = _track(False)
    f = tr.evaluate(np.linspace(0.0, tr.length, 2001))
    assert np.max(np.abs(np.linalg.norm(f.dposition, axis=1) - 1.0)) < 1e-9


def test_circle_curvature_and_radius():
    R = 400.0
    tr = Track([Straight(10.0), Curve(200.0, R)])
    s = np.linspace(12.0, 208.0, 50)
    f = tr.evaluate(s)
    assert np.allclose(np.linalg.norm(f.dR()[:, :, 0], axis=1), 1.0 / R, rtol=1e-10)
    # points on a circle of radius R about the centre at (10, R) (the curve starts at x=10
    # heading along +x and turns left)
    c = np.array([10.0, R, 0.0])
    assert np.max(np.abs(np.linalg.norm(f.position - c, axis=1) - R)) < 1e-8
    assert np.allclose(f.curvature, 1.0 / R)


def test_clothoid_curvature_linear_and_heading_quadratic():
    R, L = 300.0, 80.0
    tr = Track([Straight(20.0), Transition(L), Curve(50.0, R, 0.12)])
    s = np.linspace(20.0, 20.0 + L, 41)
    f = tr.evaluate(s)
    x = s - 20.0
    assert np.allclose(f.curvature, x / (L * R), atol=1e-14)
    assert np.allclose(f.heading, x**2 / (2 * L * R), atol=1e-13)
    # cant ramps linearly to -asin(h/1.5) (left-hand curve: frame rolls to the left)
    assert np.allclose(f.cant_angle, -np.arcsin(0.12 / 1.5) * x / L, atol=1e-14)
    # clothoid position against an independent quadrature of (cos, sin) of the heading
    from scipy.integrate import quad

    X = 20.0 + quad(lambda t: np.cos(t**2 / (2 * L * R)), 0.0, L, epsabs=1e-13)[0]
    Y = quad(lambda t: np.sin(t**2 / (2 * L * R)), 0.0, L, epsabs=1e-13)[0]
    end = tr.evaluate([20.0 + L]).position[0]
    assert end[0] == pytest.approx(X, abs=1e-9) and end[1] == pytest.approx(Y, abs=1e-9)


def test_irregularities_displace_the_centreline():
    s = np.linspace(0.0, 100.0, 101)
    lat = 1e-3 * np.sin(2 * np.pi * s / 50.0)
    ver = -2e-3 * np.sin(2 * np.pi * s / 25.0)
    tr = Track([Straight(100.0)], irregularities=Irregularities(s, lat, ver))
    q = np.array([12.5, 37.3, 61.0])
    f = tr.evaluate(q)
    assert np.allclose(f.position[:, 1], 1e-3 * np.sin(2 * np.pi * q / 50.0), atol=2e-7)
    assert np.allclose(f.position[:, 2], -2e-3 * np.sin(2 * np.pi * q / 25.0), atol=2e-6)


def test_bad_track_input():
    with pytest.raises(ValueError, match="segment 1"):
        Track([Straight(10.0), Curve(10.0, 0.0)])
    with pytest.raises(ValueError, match="lateral"):
        Irregularities([0, 1, 2, 3], [0, np.nan, 0, 0], [0, 0, 0, 0])
    with pytest.raises(ValueError, match="nan"):
        Track.straight(10.0).evaluate([1.0, np.nan])


@pytest.mark.parametrize("irr", [False, True])
def test_track_is_a_framed_curve_and_fast_path_matches_evaluate(irr):
    """The track shares core's FramedCurve interface; its fast path (the frame table) agrees with
    the exact assembly of ``evaluate``.

    Interpolation error of the table: about (h |omega|)^6 / 46080 < 1e-17 for h <= 2 m and
    |omega| < 5e-3 1/m, so the differences are round-off of the table coefficients, at most
    about 1000 eps times the size of each quantity divided by h_min^k for its k-th derivative
    (|r| <= 500 m, |R_ij| <= 1, max |omega|).
    """
    tr = _track(irr)
    assert isinstance(tr, FramedCurve) and not tr.closed
    assert isinstance(tr.frame_table, TabulatedFramedCurve)
    assert tr.pp_frame is tr.frame_table.table
    s = np.linspace(0.0, tr.length, 4001)
    f = tr.evaluate(s)
    assert isinstance(f, TrackFrame) and isinstance(f, CurveFrame)
    assert np.array_equal(f.normal, f.lateral) and np.array_equal(f.binormal, f.up)
    raw = tr.evaluate_raw(s)
    for a, b in zip(raw, tr._frame_fast(s), strict=True):
        assert np.array_equal(a, b)
    h = np.min(np.diff(tr.frame_table.nodes))
    u, om = 1000 * np.finfo(float).eps, np.max(np.abs(f.omega))
    tols = (u * 500.0, u * 500.0 / h, u * 500.0 / h**2, u, u * om, u * om / h)
    keys = ("position", "dposition", "ddposition", "R", "omega", "domega")
    for a, key, tol in zip(raw, keys, tols, strict=True):
        assert np.max(np.abs(a - getattr(f, key))) <= tol, key
