"""OpenSim function types (biomech.functions): values, derivatives, end behaviour, XML parsing.

Each spline is checked against a property that pins its definition down independently of the
implementation: SimmSpline (Forsythe-Malcolm-Moler end conditions) reproduces any cubic exactly,
which a natural spline does not; NaturalCubicSpline agrees with scipy's natural CubicSpline; both
are C2 at interior knots and continue linearly with the end slopes, as OpenSim's SimmSpline does.
"""

from __future__ import annotations

import pickle
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from core.errors import DataFileError, InputError
from biomech.functions import (
    Constant,
    LinearFunction,
    MultiplierFunction,
    NaturalCubicSpline,
    PiecewiseLinearFunction,
    PolynomialFunction,
    SimmSpline,
    function_from_xml,
    function_in,
    linear_slope,
)

RNG = np.random.default_rng(20240521)


def _cubic(t):
    return 0.4 - 1.3 * t + 0.7 * t**2 - 0.25 * t**3, -1.3 + 1.4 * t - 0.75 * t**2, 1.4 - 1.5 * t


def _knots(n):
    return np.sort(RNG.uniform(-2.0, 2.0, n)) + np.arange(n) * 1e-3


def test_closed_forms_value_and_derivatives_vectorised():
    x = np.linspace(-2, 3, 7).reshape(7, 1)
    c = Constant(2.5)
    assert c(1.0) == 2.5 and isinstance(c(1.0), float)
    assert c.first_derivative(x).shape == (7, 1) and not np.any(c.first_derivative(x))
    lf = LinearFunction(-0.5, 0.2)
    np.testing.assert_array_equal(lf(x), -0.5 * x + 0.2)
    assert lf.first_derivative(3.0) == -0.5 and lf.second_derivative(3.0) == 0.0
    # highest power first (OpenSim PolynomialFunction): 2x^2 - 3x + 1
    p = PolynomialFunction((2.0, -3.0, 1.0))
    np.testing.assert_allclose(p(x), 2 * x**2 - 3 * x + 1, rtol=0, atol=1e-14)
    np.testing.assert_allclose(p.first_derivative(x), 4 * x - 3, rtol=0, atol=1e-14)
    np.testing.assert_allclose(p.second_derivative(x), np.full_like(x, 4.0))
    assert PolynomialFunction((5.0,)).second_derivative(1.0) == 0.0
    m = MultiplierFunction(p, -2.0)
    for order in (0, 1, 2):
        np.testing.assert_allclose(m.derivative(x, order), -2.0 * p.derivative(x, order))
    with pytest.raises(InputError, match="order must be 0, 1 or 2"):
        p.derivative(1.0, 3)


@pytest.mark.parametrize("n", [4, 5, 9, 17])
def test_simm_spline_reproduces_a_cubic_exactly(n):
    """FMM end conditions: the third derivative in the end intervals equals that of the cubic through
    the first / last four points, so a cubic is reproduced with its derivatives (to round-off)."""
    x = _knots(n)
    s = SimmSpline(x, _cubic(x)[0])
    t = np.linspace(x[0], x[-1], 301)
    f, df, d2f = _cubic(t)
    scale = 1e-12 * (1 + np.max(np.abs(f)))
    np.testing.assert_allclose(s(t), f, rtol=0, atol=50 * scale)
    np.testing.assert_allclose(s.first_derivative(t), df, rtol=0, atol=1e3 * scale)
    np.testing.assert_allclose(s.second_derivative(t), d2f, rtol=0, atol=1e5 * scale)


def test_natural_spline_differs_from_simm_spline_and_matches_scipy():
    x = _knots(8)
    y = _cubic(x)[0]
    nat = NaturalCubicSpline(x, y)
    ref = CubicSpline(x, y, bc_type="natural")
    t = np.linspace(x[0], x[-1], 200)
    for order in (0, 1, 2):
        np.testing.assert_allclose(nat.derivative(t, order), ref(t, order), rtol=0, atol=1e-10)
    assert nat.second_derivative(x[0]) == pytest.approx(0.0, abs=1e-12)
    assert nat.second_derivative(x[-1]) == pytest.approx(0.0, abs=1e-12)
    # the cubic has a nonzero second derivative at the ends: SimmSpline keeps it, natural cannot
    assert abs(SimmSpline(x, y).second_derivative(x[0]) - _cubic(x[0])[2]) < 1e-8
    assert abs(nat(0.5 * (x[0] + x[1])) - _cubic(0.5 * (x[0] + x[1]))[0]) > 1e-6


@pytest.mark.parametrize("cls", [SimmSpline, NaturalCubicSpline])
def test_spline_interpolates_is_c2_and_extrapolates_linearly(cls):
    x = _knots(11)
    y = np.sin(2 * x) + 0.3 * x
    s = cls(x, y)
    np.testing.assert_allclose(s(x), y, rtol=0, atol=1e-13)
    eps = 1e-9
    inner = x[1:-1]
    for order in (0, 1, 2):  # continuous at the interior knots up to the second derivative
        left = s.derivative(inner - eps, order)
        right = s.derivative(inner + eps, order)
        # |left-right| <= 2 eps * max|next derivative|; third derivative of the pieces is bounded by
        # 6 max|d_i| (here < 1e3), so 1e-5 is a safe bound for all orders
        np.testing.assert_allclose(left, right, rtol=0, atol=1e-5)
    # outside: straight lines with the end slopes, second derivative 0 (SimmSpline::calcValue)
    b0, b1 = s.first_derivative(x[0]), s.first_derivative(x[-1])
    out_lo = x[0] - np.array([0.1, 1.0, 5.0])
    out_hi = x[-1] + np.array([0.1, 1.0, 5.0])
    np.testing.assert_allclose(s(out_lo), y[0] + b0 * (out_lo - x[0]), rtol=1e-13)
    np.testing.assert_allclose(s(out_hi), y[-1] + b1 * (out_hi - x[-1]), rtol=1e-13)
    np.testing.assert_array_equal(s.second_derivative(np.r_[out_lo, out_hi]), 0.0)
    np.testing.assert_allclose(s.first_derivative(out_hi), b1)


def test_spline_derivatives_against_central_differences():
    """Inside an interval S is a cubic, so the central difference error is h^2/6 |S'''| (first) and
    h^2/12 |S''''| = 0 + round-off (second); S''' <= max over pieces of 6|d_i|."""
    x = _knots(9)
    s = SimmSpline(x, np.cos(x))
    t = 0.5 * (x[:-1] + x[1:])
    h = 1e-5
    d3 = np.max(np.abs(s._e)) * 6.0
    fd1 = (s(t + h) - s(t - h)) / (2 * h)
    fd2 = (s(t + h) - 2 * s(t) + s(t - h)) / h**2
    np.testing.assert_allclose(s.first_derivative(t), fd1, rtol=0, atol=h**2 / 6 * d3 + 1e-9)
    np.testing.assert_allclose(s.second_derivative(t), fd2, rtol=0, atol=1e-4)


def test_small_splines_are_a_line_and_a_parabola():
    line = SimmSpline([0.0, 2.0], [1.0, 5.0])
    assert line(1.0) == 3.0 and line(-1.0) == -1.0 and line.second_derivative(1.0) == 0.0
    par = SimmSpline([0.0, 1.0, 3.0], [0.0, 1.0, 9.0])  # third differences taken as 0: y = x^2
    assert par(2.0) == pytest.approx(4.0, abs=1e-13)
    assert par.second_derivative(0.5) == pytest.approx(2.0, abs=1e-12)


def test_piecewise_linear_function():
    f = PiecewiseLinearFunction([0.0, 1.0, 3.0], [0.0, 2.0, 1.0])
    np.testing.assert_allclose(f([0.5, 2.0, 3.0]), [1.0, 1.5, 1.0])
    np.testing.assert_allclose(f([-1.0, 4.0]), [-2.0, 0.5])  # end slopes continue
    np.testing.assert_allclose(f.first_derivative([0.5, 1.0, 2.0, 5.0]), [2.0, -0.5, -0.5, -0.5])
    assert not np.any(f.second_derivative(np.linspace(-1, 4, 9)))


@pytest.mark.parametrize("x, y, match", [
    ([0.0, 1.0, 1.0], [0.0, 1.0, 2.0], "strictly increasing"),
    ([0.0], [1.0], "at least 2 points"),
    ([0.0, 1.0], [1.0], "equal length"),
    ([0.0, np.nan], [1.0, 2.0], "finite"),
])
def test_bad_knots_are_refused(x, y, match):
    with pytest.raises(InputError, match=match):
        SimmSpline(x, y)


def test_splines_pickle():
    s = MultiplierFunction(SimmSpline([0.0, 1.0, 2.0, 4.0], [1.0, 0.0, 2.0, 1.0]), 1.5)
    s2 = pickle.loads(pickle.dumps(s))
    t = np.linspace(-1, 5, 13)
    np.testing.assert_array_equal(s(t), s2(t))


# ---- XML ----------------------------------------------------------------------------------


def _xml(text):
    return ET.fromstring(text)


def test_function_from_xml_reads_each_supported_type():
    f = function_from_xml(_xml("<Constant><value> 0.02 </value></Constant>"), "test.osim")
    assert isinstance(f, Constant) and f(7.0) == 0.02
    f = function_from_xml(_xml('<LinearFunction name="function"><coefficients> 2 -1</coefficients></LinearFunction>'), "t")
    assert f(3.0) == 5.0 and linear_slope(f) == 2.0
    f = function_from_xml(_xml("<PolynomialFunction><coefficients>1 0 -1</coefficients></PolynomialFunction>"), "t")
    assert f(2.0) == 3.0
    f = function_from_xml(_xml("<PiecewiseLinearFunction><x>0 1</x><y>0 3</y></PiecewiseLinearFunction>"), "t")
    assert f(0.5) == 1.5
    f = function_from_xml(_xml("<MultiplierFunction><function><SimmSpline><x>0 1 2 3</x><y>0 1 8 27</y>"
                               "</SimmSpline></function><scale>2</scale></MultiplierFunction>"), "t")
    assert isinstance(f, MultiplierFunction) and f(1.5) == pytest.approx(2 * 1.5**3, abs=1e-12)
    lin = function_from_xml(_xml("<MultiplierFunction><function><LinearFunction><coefficients>1 0</coefficients>"
                                 "</LinearFunction></function><scale>-1</scale></MultiplierFunction>"), "t")
    assert linear_slope(lin) == -1.0


@pytest.mark.parametrize("tag", ["NaturalCubicSpline", "natCubicSpline"])
def test_natural_cubic_spline_tag_is_read_as_simm_spline_like_opensim(tag):
    """OpenSim 4 renames these tags to SimmSpline (RegisterTypes_osimCommon.cpp)."""
    f = function_from_xml(_xml(f"<{tag}><x>0 1 2 3 4</x><y>0 1 8 27 64</y></{tag}>"), "t")
    assert type(f) is SimmSpline
    assert f(2.5) == pytest.approx(2.5**3, abs=1e-12)  # cubic reproduced: not a natural spline


def test_unsupported_function_names_file_and_element():
    el = _xml('<GCVSpline name="function"><degree>5</degree><x>0 1</x><y>0 1</y></GCVSpline>')
    with pytest.raises(DataFileError, match=r"model\.osim, joint 'knee_r'.*<GCVSpline name='function'>.*"
                                            r"unsupported function type 'GCVSpline'.*supported: Constant"):
        function_from_xml(el, "model.osim, joint 'knee_r'")
    owner = _xml('<TransformAxis name="translation1"><GCVSpline name="function"><x>0 1</x></GCVSpline></TransformAxis>')
    with pytest.raises(DataFileError, match="unsupported function type 'GCVSpline'"):
        function_in(owner, "m.osim", container="function")
    with pytest.raises(DataFileError, match=r"<SimmSpline>: x must be strictly increasing"):
        function_from_xml(_xml("<SimmSpline><x>0 2 1</x><y>0 1 2</y></SimmSpline>"), "m.osim")
    with pytest.raises(DataFileError, match=r"<LinearFunction>: <coefficients> is not a list of numbers"):
        function_from_xml(_xml("<LinearFunction><coefficients>1 a</coefficients></LinearFunction>"), "m.osim")
    with pytest.raises(DataFileError, match=r"must hold one function element, found 2"):
        function_in(_xml("<x_location><Constant><value>1</value></Constant><Constant><value>2</value></Constant>"
                         "</x_location>"), "m.osim")


def test_function_in_reads_both_property_forms():
    typed = _xml('<TransformAxis><LinearFunction name="function"><coefficients>1 0</coefficients></LinearFunction>'
                 '</TransformAxis>')
    wrapped = _xml("<TransformAxis><function><LinearFunction><coefficients>1 0</coefficients></LinearFunction>"
                   "</function></TransformAxis>")
    for el in (typed, wrapped):
        assert function_in(el, "t", container="function")(0.3) == 0.3
    assert function_in(_xml("<prescribed_function/>"), "t") is None
    assert function_in(_xml("<Coordinate/>"), "t", container="prescribed_function") is None
