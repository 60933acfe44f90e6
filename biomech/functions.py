r"""OpenSim's functions of one variable, evaluable with their first two derivatives.

An OpenSim model describes every coordinate-dependent quantity that is not a rigid-body constant
with a *function* element: the six axes of a ``CustomJoint`` (e.g. the tibia's translation as a
spline of the knee angle), the location of a ``MovingPathPoint`` (the quadriceps insertion), the
dependent coordinate of a ``CoordinateCouplerConstraint``.  This module gives each of those
function types as a small immutable object with

* ``f(x)`` / :meth:`Function1D.value` -- the value,
* :meth:`Function1D.first_derivative` -- df/dx,
* :meth:`Function1D.second_derivative` -- d²f/dx²,

all vectorised over numpy arrays (a scalar in gives a float out).  The independent variable is a
coordinate in SI units (radians for rotational, metres for translational coordinates); values are
in whatever unit the function maps to (metres for joint translations and path-point locations,
radians for a rotation axis).

==============================  ===========================================================
XML element                     class
==============================  ===========================================================
``Constant``                    :class:`Constant`               f = c
``LinearFunction``              :class:`LinearFunction`         f = a x + b (coefficients "a b")
``PolynomialFunction``          :class:`PolynomialFunction`     coefficients highest power first
``PiecewiseLinearFunction``     :class:`PiecewiseLinearFunction`
``SimmSpline``                  :class:`SimmSpline`             cubic spline, FMM end conditions
``NaturalCubicSpline``          :class:`SimmSpline` (!)         OpenSim reads this tag as SimmSpline
``natCubicSpline``              :class:`SimmSpline` (!)         old name, same
``MultiplierFunction``          :class:`MultiplierFunction`     f = s · g(x)
==============================  ===========================================================

**SimmSpline is not a natural spline.**  OpenSim's ``SimmSpline`` (``OpenSim/Common/SimmSpline.cpp``)
is the interpolating cubic spline of Forsythe, Malcolm & Moler (1977): its end conditions make the
third derivative in the first and last interval equal to that of the cubic through the first (last)
four points, so a cubic polynomial is reproduced exactly; outside the knots it continues linearly
with the end slopes.  OpenSim 4 registers the XML tags ``NaturalCubicSpline`` and ``natCubicSpline``
as aliases of ``SimmSpline`` (``RegisterTypes_osimCommon.cpp``: "temporarily map old
NaturalCubicSpline (which wasn't a natural cubic spline) to renamed SimmSpline class"), and
:func:`function_from_xml` does the same, so a model file means what it means in OpenSim.  A true
natural cubic spline (zero second derivative at both ends) is available as
:class:`NaturalCubicSpline` for use from Python.

Unsupported function types (``GCVSpline``, ``Sine``, ``StepFunction``, ``PiecewiseConstantFunction``,
``MultivariatePolynomialFunction``, ``ExpressionBasedFunction``, ...) raise
:class:`core.errors.DataFileError` naming the file and element: a joint or muscle path evaluated
with a wrong function would be wrong without any sign of it.

References
----------
OpenSim 4.x source, ``OpenSim/Common/{Constant,LinearFunction,PolynomialFunction,
PiecewiseLinearFunction,SimmSpline,MultiplierFunction}.{h,cpp}`` and
``RegisterTypes_osimCommon.cpp`` (github.com/opensim-org/opensim-core; read for the definitions).
Forsythe G.E., Malcolm M.A., Moler C.B. (1977) *Computer Methods for Mathematical Computations*,
Prentice-Hall, Sec. 4.4 (subroutines SPLINE/SEVAL: the end conditions used by SimmSpline).
Burden R.L., Faires J.D. (2011) *Numerical Analysis*, 9th ed., Sec. 3.5, Algorithm 3.4 (natural
cubic spline).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.linalg import solve_banded

from core.errors import DataFileError, InputError

__all__ = [
    "Function1D",
    "Constant",
    "LinearFunction",
    "PolynomialFunction",
    "PiecewiseLinearFunction",
    "SimmSpline",
    "NaturalCubicSpline",
    "MultiplierFunction",
    "SUPPORTED_FUNCTION_TAGS",
    "function_from_xml",
    "function_in",
    "linear_slope",
    "is_constant",
]


def _as_array(x) -> tuple[np.ndarray, bool]:
    arr = np.asarray(x, dtype=float)
    return arr, arr.ndim == 0


def _out(values: np.ndarray, scalar: bool):
    return float(values) if scalar else values


class Function1D:
    """Base class: a function of one variable with value and first two derivatives.

    Subclasses implement ``_eval(x, order)`` for a float array ``x`` and ``order`` in {0, 1, 2}.
    """

    def _eval(self, x: np.ndarray, order: int) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def value(self, x):
        """f(x); ``x`` scalar or array (shape kept)."""
        arr, scalar = _as_array(x)
        return _out(self._eval(arr, 0), scalar)

    __call__ = value

    def first_derivative(self, x):
        """df/dx at ``x``."""
        arr, scalar = _as_array(x)
        return _out(self._eval(arr, 1), scalar)

    def second_derivative(self, x):
        """d²f/dx² at ``x``."""
        arr, scalar = _as_array(x)
        return _out(self._eval(arr, 2), scalar)

    def derivative(self, x, order: int = 1):
        """Derivative of order 0, 1 or 2 at ``x``."""
        if order not in (0, 1, 2):
            raise InputError(f"{type(self).__name__}: derivative order must be 0, 1 or 2, got {order!r}")
        arr, scalar = _as_array(x)
        return _out(self._eval(arr, order), scalar)


@dataclass(frozen=True, eq=False)
class Constant(Function1D):
    """f(x) = c (OpenSim ``Constant``; XML property ``value``)."""

    c: float

    def _eval(self, x, order):
        return np.full(x.shape, float(self.c) if order == 0 else 0.0)


@dataclass(frozen=True, eq=False)
class LinearFunction(Function1D):
    """f(x) = a·x + b (OpenSim ``LinearFunction``; XML ``coefficients`` = "a b", slope first)."""

    slope: float
    intercept: float

    def _eval(self, x, order):
        if order == 0:
            return self.slope * x + self.intercept
        return np.full(x.shape, float(self.slope) if order == 1 else 0.0)


@dataclass(frozen=True, eq=False)
class PolynomialFunction(Function1D):
    """f(x) = c₀ xⁿ + c₁ xⁿ⁻¹ + … + cₙ (OpenSim ``PolynomialFunction``).

    Parameters
    ----------
    coefficients : tuple of float, length n + 1
        Highest power first, as in the XML property ``coefficients`` ("from highest to lowest
        order", ``PolynomialFunction.h``).
    """

    coefficients: tuple[float, ...]

    def __post_init__(self):
        c = np.asarray(self.coefficients, float)
        if c.ndim != 1 or c.size == 0 or not np.all(np.isfinite(c)):
            raise InputError(f"PolynomialFunction: coefficients must be a non-empty list of finite numbers, "
                             f"got {self.coefficients!r}")
        object.__setattr__(self, "coefficients", tuple(float(v) for v in c))

    def _eval(self, x, order):
        c = np.asarray(self.coefficients)
        if order:
            c = np.polyder(c, order) if c.size > order else np.zeros(1)
        return np.polyval(c, x)


def _check_knots(x, y, name: str, minimum: int = 2) -> tuple[np.ndarray, np.ndarray]:
    xa = np.asarray(x, float)
    ya = np.asarray(y, float)
    if xa.ndim != 1 or xa.shape != ya.shape:
        raise InputError(f"{name}: x and y must be 1-D of equal length, got shapes {xa.shape} and {ya.shape}")
    if xa.size < minimum:
        raise InputError(f"{name}: needs at least {minimum} points, got {xa.size}")
    if not (np.all(np.isfinite(xa)) and np.all(np.isfinite(ya))):
        raise InputError(f"{name}: x and y must be finite")
    dx = np.diff(xa)
    if np.any(dx <= 0):
        k = int(np.flatnonzero(dx <= 0)[0])
        raise InputError(f"{name}: x must be strictly increasing, x[{k + 1}] = {float(xa[k + 1])!r} follows "
                         f"x[{k}] = {float(xa[k])!r}")
    return xa, ya


class _PiecewiseCubic(Function1D):
    r"""Piecewise cubic S(x) = y_i + b_i d + c_i d² + e_i d³, d = x − x_i on [x_i, x_{i+1}],
    continued linearly outside [x_0, x_{n−1}] with the end slopes b_0 and b_{n−1} (second
    derivative zero there), as SimmSpline and PiecewiseLinearFunction do."""

    x: np.ndarray
    y: np.ndarray
    _b: np.ndarray
    _c: np.ndarray
    _e: np.ndarray

    def _eval(self, xq, order):
        x, y, b, c, e = self.x, self.y, self._b, self._c, self._e
        n = x.size
        i = np.clip(np.searchsorted(x, xq, side="right") - 1, 0, n - 2)
        d = xq - x[i]
        if order == 0:
            out = y[i] + d * (b[i] + d * (c[i] + d * e[i]))
        elif order == 1:
            out = b[i] + d * (2.0 * c[i] + 3.0 * d * e[i])
        else:
            out = 2.0 * c[i] + 6.0 * d * e[i]
        lo = xq < x[0]
        hi = xq > x[-1]
        if np.any(lo) or np.any(hi):
            out = np.array(out, dtype=float, copy=True)
            if order == 0:
                out[lo] = y[0] + (xq[lo] - x[0]) * b[0]
                out[hi] = y[-1] + (xq[hi] - x[-1]) * b[-1]
            elif order == 1:
                out[lo] = b[0]
                out[hi] = b[-1]
            else:
                out[lo] = 0.0
                out[hi] = 0.0
        return out

    @property
    def n_points(self) -> int:
        """Number of knots."""
        return int(self.x.size)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n_points={self.x.size}, x=[{self.x[0]:g} … {self.x[-1]:g}])"


def _cubic_coefficients(x: np.ndarray, y: np.ndarray, sigma: np.ndarray):
    """Polynomial coefficients from σ_i = S''(x_i)/6 (see :class:`SimmSpline`)."""
    h = np.diff(x)
    delta = np.diff(y) / h
    b = np.empty_like(x)
    b[:-1] = delta - h * (sigma[1:] + 2.0 * sigma[:-1])
    b[-1] = delta[-1] + h[-1] * (sigma[-2] + 2.0 * sigma[-1])
    c = 3.0 * sigma
    e = np.empty_like(x)
    e[:-1] = (sigma[1:] - sigma[:-1]) / h
    e[-1] = e[-2]
    return b, c, e


def _solve_sigma(x: np.ndarray, y: np.ndarray, natural: bool) -> np.ndarray:
    """Solve the tridiagonal system for σ_i = S''(x_i)/6 (equations in :class:`SimmSpline`)."""
    n = x.size
    h = np.diff(x)
    delta = np.diff(y) / h
    diag = np.empty(n)
    upper = np.zeros(n)  # upper[i] couples σ_i and σ_{i+1}
    lower = np.zeros(n)  # lower[i] couples σ_i and σ_{i−1}
    rhs = np.zeros(n)
    diag[1:-1] = 2.0 * (h[:-1] + h[1:])
    upper[1:-1] = h[1:]
    lower[1:-1] = h[:-1]
    rhs[1:-1] = delta[1:] - delta[:-1]
    if natural:
        diag[0] = diag[-1] = 1.0
    else:
        # third derivative at the ends = that of the cubic through the first / last four points
        diag[0], upper[0] = -h[0], h[0]
        diag[-1], lower[-1] = -h[-1], h[-1]
        if n > 3:
            d3_first = ((delta[2] - delta[1]) / (x[3] - x[1]) - (delta[1] - delta[0]) / (x[2] - x[0])) / (x[3] - x[0])
            d3_last = ((delta[-1] - delta[-2]) / (x[-1] - x[-3]) - (delta[-2] - delta[-3]) / (x[-2] - x[-4])) / (x[-1] - x[-4])
            rhs[0] = h[0] ** 2 * d3_first
            rhs[-1] = -h[-1] ** 2 * d3_last
    ab = np.zeros((3, n))
    ab[0, 1:] = upper[:-1]
    ab[1] = diag
    ab[2, :-1] = lower[1:]
    return solve_banded((1, 1), ab, rhs)


class SimmSpline(_PiecewiseCubic):
    r"""OpenSim's ``SimmSpline``: interpolating cubic spline with Forsythe–Malcolm–Moler ends.

    With knots x_0 < … < x_{n−1}, h_i = x_{i+1} − x_i, Δ_i = (y_{i+1} − y_i)/h_i and unknowns
    σ_i = S''(x_i)/6, C² continuity at the interior knots gives (i = 1 … n−2)

    .. math:: h_{i-1}σ_{i-1} + 2(h_{i-1}+h_i)σ_i + h_iσ_{i+1} = Δ_i − Δ_{i-1},

    and the end conditions (FMM 1977, Sec. 4.4) set the third derivative in the first and last
    interval, 6(σ_1 − σ_0)/h_0 and 6(σ_{n−1} − σ_{n−2})/h_{n−2}, equal to that of the cubic
    interpolating the first (last) four points, 6·f[x_0, x_1, x_2, x_3] (third divided difference):

    .. math:: −h_0σ_0 + h_0σ_1 = h_0^2 f[x_0..x_3], \qquad
              h_{n-2}σ_{n-2} − h_{n-2}σ_{n-1} = −h_{n-2}^2 f[x_{n-4}..x_{n-1}].

    With three points the divided differences are taken as zero (the spline is the parabola through
    them); with two it is the straight line.  On [x_i, x_{i+1}], d = x − x_i,
    S = y_i + b_i d + 3σ_i d² + (σ_{i+1} − σ_i)/h_i d³ with b_i = Δ_i − h_i(σ_{i+1} + 2σ_i).
    Outside [x_0, x_{n−1}] S continues linearly with the end slopes (second derivative 0 there,
    so S'' jumps at the end knots), as in ``SimmSpline::calcValue``/``calcDerivative``.  A cubic
    polynomial is reproduced exactly (n ≥ 4).

    Parameters
    ----------
    x, y : array_like, shape (n,)
        Knots (strictly increasing, n ≥ 2) and values.
    """

    def __init__(self, x, y):
        xa, ya = _check_knots(x, y, type(self).__name__)
        self.x, self.y = xa, ya
        if xa.size == 2:
            slope = (ya[1] - ya[0]) / (xa[1] - xa[0])
            self._b = np.full(2, slope)
            self._c = np.zeros(2)
            self._e = np.zeros(2)
        else:
            self._b, self._c, self._e = _cubic_coefficients(xa, ya, _solve_sigma(xa, ya, natural=self._natural))
        for arr in (self.x, self.y, self._b, self._c, self._e):
            arr.flags.writeable = False

    _natural = False

    def __reduce__(self):
        return (type(self), (self.x.copy(), self.y.copy()))


class NaturalCubicSpline(SimmSpline):
    r"""Natural interpolating cubic spline: S''(x_0) = S''(x_{n−1}) = 0.

    Same interior equations as :class:`SimmSpline` (Burden & Faires 2011, Algorithm 3.4), with the
    end conditions σ_0 = σ_{n−1} = 0; outside the knots S continues linearly with the end slopes,
    which keeps S twice continuously differentiable everywhere.

    Note that the XML tag ``NaturalCubicSpline`` of an OpenSim file is *not* read as this class
    but as :class:`SimmSpline`, as OpenSim 4 does (see the module docstring).
    """

    _natural = True


class PiecewiseLinearFunction(_PiecewiseCubic):
    r"""OpenSim ``PiecewiseLinearFunction``: straight lines between the points.

    f = y_i + Δ_i (x − x_i) on [x_i, x_{i+1}), Δ_i = (y_{i+1} − y_i)/(x_{i+1} − x_i); linear
    extrapolation with the first and last slopes.  df/dx is taken from the interval to the right of
    an interior knot; d²f/dx² is 0 everywhere (OpenSim returns 0 for derivative orders above 1).
    """

    def __init__(self, x, y):
        xa, ya = _check_knots(x, y, "PiecewiseLinearFunction")
        self.x, self.y = xa, ya
        slopes = np.diff(ya) / np.diff(xa)
        self._b = np.append(slopes, slopes[-1])
        self._c = np.zeros_like(xa)
        self._e = np.zeros_like(xa)
        for arr in (self.x, self.y, self._b, self._c, self._e):
            arr.flags.writeable = False

    def __reduce__(self):
        return (type(self), (self.x.copy(), self.y.copy()))


@dataclass(frozen=True, eq=False)
class MultiplierFunction(Function1D):
    """f(x) = scale · g(x) (OpenSim ``MultiplierFunction``: how the Scale tool scales a joint's
    translation splines and the moving path points)."""

    function: Function1D
    scale: float = 1.0

    def _eval(self, x, order):
        return self.scale * self.function._eval(x, order)


# --------------------------------------------------------------------------------------------
# helpers for model readers
# --------------------------------------------------------------------------------------------


def linear_slope(function: Function1D) -> float | None:
    """Slope of a function that is exactly linear (``LinearFunction``, possibly wrapped in
    ``MultiplierFunction`` objects: slope × scales), else None.  Used to tell a pure rotation or
    translation from a coupled one (see :mod:`biomech.osim`)."""
    scale = 1.0
    f = function
    while isinstance(f, MultiplierFunction):
        scale *= f.scale
        f = f.function
    if isinstance(f, LinearFunction):
        return scale * f.slope
    return None


def is_constant(function: Function1D) -> bool:
    """True for a ``Constant`` (possibly wrapped in ``MultiplierFunction`` objects)."""
    f = function
    while isinstance(f, MultiplierFunction):
        f = f.function
    return isinstance(f, Constant) or (isinstance(f, PolynomialFunction) and len(f.coefficients) == 1)


# --------------------------------------------------------------------------------------------
# XML
# --------------------------------------------------------------------------------------------


def _line_suffix(element, line_of) -> str:
    if line_of is None:
        return ""
    line = line_of(element)
    return f", line {line}" if line else ""


def _describe(element, where: str, line_of) -> str:
    name = element.get("name")
    label = f"<{element.tag}" + (f" name={name!r}" if name else "") + ">"
    return f"{where}{_line_suffix(element, line_of)}: {label}"


def _numbers(element, prop: str, where: str, line_of, *, required: bool = True, default=None) -> np.ndarray | None:
    child = element.find(prop)
    if child is None or child.text is None or not child.text.strip():
        if required:
            raise DataFileError(f"{_describe(element, where, line_of)} has no <{prop}> values")
        return default
    try:
        return np.array([float(tok) for tok in child.text.split()], dtype=float)
    except ValueError:
        raise DataFileError(f"{_describe(element, where, line_of)}: <{prop}> is not a list of numbers: "
                            f"{child.text.strip()[:80]!r}") from None


def _xy(element, where, line_of, cls):
    x = _numbers(element, "x", where, line_of)
    y = _numbers(element, "y", where, line_of)
    try:
        return cls(x, y)
    except InputError as exc:
        reason = str(exc).split(": ", 1)[-1]
        raise DataFileError(f"{_describe(element, where, line_of)}: {reason}") from None


def _parse_constant(element, where, line_of):
    v = _numbers(element, "value", where, line_of)
    if v.size != 1:
        raise DataFileError(f"{_describe(element, where, line_of)}: <value> must be one number, got {v.size}")
    return Constant(float(v[0]))


def _parse_linear(element, where, line_of):
    c = _numbers(element, "coefficients", where, line_of)
    if c.size != 2:
        raise DataFileError(f"{_describe(element, where, line_of)}: <coefficients> must be 'slope intercept' "
                            f"(2 numbers), got {c.size}")
    return LinearFunction(float(c[0]), float(c[1]))


def _parse_polynomial(element, where, line_of):
    c = _numbers(element, "coefficients", where, line_of)
    try:
        return PolynomialFunction(tuple(c))
    except InputError as exc:
        raise DataFileError(f"{_describe(element, where, line_of)}: {exc}") from None


def _parse_multiplier(element, where, line_of):
    inner = function_in(element, where, line_of=line_of, container="function")
    if inner is None:
        raise DataFileError(f"{_describe(element, where, line_of)} has no inner <function>")
    scale = _numbers(element, "scale", where, line_of, required=False, default=np.array([1.0]))
    if scale.size != 1:
        raise DataFileError(f"{_describe(element, where, line_of)}: <scale> must be one number")
    return MultiplierFunction(inner, float(scale[0]))


_PARSERS: dict[str, Callable[..., Function1D]] = {
    "Constant": _parse_constant,
    "LinearFunction": _parse_linear,
    "PolynomialFunction": _parse_polynomial,
    "PiecewiseLinearFunction": lambda e, w, l: _xy(e, w, l, PiecewiseLinearFunction),
    "SimmSpline": lambda e, w, l: _xy(e, w, l, SimmSpline),
    # OpenSim 4 maps these old tags onto SimmSpline (RegisterTypes_osimCommon.cpp)
    "NaturalCubicSpline": lambda e, w, l: _xy(e, w, l, SimmSpline),
    "natCubicSpline": lambda e, w, l: _xy(e, w, l, SimmSpline),
    "MultiplierFunction": _parse_multiplier,
}

#: XML tags :func:`function_from_xml` reads.
SUPPORTED_FUNCTION_TAGS: tuple[str, ...] = tuple(_PARSERS)


def function_from_xml(element: Any, where: str, line_of: Callable[[Any], int | None] | None = None) -> Function1D:
    """Build the function an OpenSim XML function element describes.

    Parameters
    ----------
    element : xml.etree.ElementTree.Element
        The function element itself; its tag is the type (``<SimmSpline>``, ``<LinearFunction
        name="function">``, ...).
    where : str
        Names the file and the owning element for error messages, e.g.
        ``"subject01.osim, joint 'knee_r', TransformAxis 'translation1'"``.
    line_of : callable, optional
        ``line_of(element)`` returns the element's line in the file (or None); used in messages.

    Returns
    -------
    Function1D

    Raises
    ------
    core.errors.DataFileError
        Unsupported function type (the message names the file, element and the supported types),
        missing or non-numeric properties, spline knots that are not strictly increasing.
    """
    parser = _PARSERS.get(element.tag)
    if parser is None:
        raise DataFileError(f"{_describe(element, where, line_of)}: unsupported function type {element.tag!r}; "
                            f"supported: {', '.join(SUPPORTED_FUNCTION_TAGS)}")
    return parser(element, where, line_of)


def function_in(element: Any, where: str, *, line_of: Callable[[Any], int | None] | None = None,
                container: str | None = None) -> Function1D | None:
    """The function held by a property element, or None if it holds none.

    OpenSim writes a function-valued property in two forms, both accepted:
    ``<x_location><SimmSpline>…</SimmSpline></x_location>`` (a container holding one function
    element), or the function element itself tagged with its type and named after the property,
    ``<LinearFunction name="function">…`` inside the owner.

    Parameters
    ----------
    element : Element
        With ``container`` None: the property element whose single child element is the function.
        With ``container`` given (e.g. ``"function"``): the *owner*; the function is either a child
        ``<container>`` holding the function or a child function element with ``name=container``.
    where : str
        For error messages (file and owner).
    """
    if container is not None:
        holder = element.find(container)
        if holder is None:
            for child in element:
                if child.get("name") == container:
                    return function_from_xml(child, where, line_of)
            return None
        element = holder
    children = [c for c in element if isinstance(c.tag, str)]
    if not children:
        return None
    if len(children) > 1:
        raise DataFileError(f"{_describe(element, where, line_of)} must hold one function element, "
                            f"found {len(children)}: {', '.join(c.tag for c in children)}")
    return function_from_xml(children[0], where, line_of)

