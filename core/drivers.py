r"""Prescribed motions of time used by driving constraints and applied loads.

A :class:`TimeFunction` returns the value and its first two time derivatives,
``(f(t), ḟ(t), f̈(t))``, which driving constraints need for ``ν = ḟ`` and ``γ ⊃ f̈``.

* :func:`motion` wraps user callables; derivatives are taken from user callables when given,
  otherwise from central differences with step ``h = 1e-4·max(1, |t|)`` (error O(h²), stated
  in the function's docstring so a user can decide).
* :func:`tabulated` interpolates measured data (e.g. joint angles of a gait trial) with a
  twice-differentiable cubic spline (:class:`scipy.interpolate.CubicSpline`), whose derivatives
  are exact for the interpolant.
* :func:`polynomial`, :func:`ramp` and :func:`harmonic` are common closed forms; :func:`cycloidal`
  is the cam designer's rest-to-rest law (a deployment, a move between two positions).

The closed forms and tables carry a ``spec`` (kind and parameters) from which the compiled path
(:mod:`core.compiled.timefunctions`) evaluates the same function in numba; a :func:`motion` of a
Python callable has none and keeps a model off the compiled integrators (refused by name).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.interpolate import CubicSpline

from .errors import DataRangeError, InputError


class ModelInputTypeError(InputError, TypeError):
    """A value of the wrong type where a function of time is expected."""


class TimeFunction:
    """A scalar function of time with its first two derivatives.

    Parameters
    ----------
    f, fd, fdd : callable(t) -> float
        Value and first and second derivatives.
    label : str
        Used in error messages.
    spec : tuple, optional
        ``(kind, *parameters)`` of a closed form or table (``"const"``, ``"poly"``,
        ``"harmonic"``, ``"spline"``, ``"cycloidal"``) that the compiled path can evaluate; None for
        callables.
    """

    def __init__(self, f: Callable[[float], float], fd: Callable[[float], float], fdd: Callable[[float], float],
                 label: str = "f(t)", spec: tuple | None = None):
        self.f, self.fd, self.fdd, self.label = f, fd, fdd, label
        self.spec = spec

    def __call__(self, t: float) -> tuple[float, float, float]:
        return float(self.f(t)), float(self.fd(t)), float(self.fdd(t))

    def values(self, t, order: int = 0) -> np.ndarray:
        """The value (``order`` 0) or a derivative (1, 2) at many times, shape of ``t``.

        Tables and closed forms evaluate the array in one call; a user's callable, which may take
        scalars only, is called once per time.
        """
        fn = (self.f, self.fd, self.fdd)[order]
        t = np.asarray(t, float)
        if isinstance(fn, _RangeGuard):
            return np.asarray(fn.many(t), float)
        return np.array([float(fn(ti)) for ti in t.ravel()]).reshape(t.shape)

    def __repr__(self) -> str:
        return f"TimeFunction({self.label})"


# Module-level callables instead of lambdas/closures, so that TimeFunctions -- and with them
# models holding drivers and actuators -- can be pickled (process-pool sweeps).


class _CentralDifference:
    """First (order 1) or second (order 2) central difference of f with h = 1e-4·max(1, |t|)."""

    def __init__(self, f: Callable[[float], float], order: int):
        self.f, self.order = f, order

    def __call__(self, t):
        h = 1e-4 * max(1.0, abs(t))
        if self.order == 1:
            return (self.f(t + h) - self.f(t - h)) / (2 * h)
        return (self.f(t + h) - 2 * self.f(t) + self.f(t - h)) / (h * h)


class _Constant:
    def __init__(self, value: float):
        self.value = value

    def __call__(self, t):
        return self.value


class _Harmonic:
    """Derivative ``order`` of offset + amplitude·sin(ωt + phase)."""

    def __init__(self, amplitude, omega, phase, offset, order):
        self.a, self.w, self.ph, self.off, self.order = amplitude, omega, phase, offset, order

    def __call__(self, t):
        x = self.w * t + self.ph
        if self.order == 0:
            return self.off + self.a * np.sin(x)
        if self.order == 1:
            return self.a * self.w * np.cos(x)
        return -self.a * self.w**2 * np.sin(x)


class _RangeGuard:
    """Evaluate ``fn`` after checking t against the tabulated range (unless extrapolating)."""

    def __init__(self, fn, lo, hi, label, extrapolate):
        self.fn, self.lo, self.hi, self.label, self.extrapolate = fn, lo, hi, label, extrapolate

    def __call__(self, tt):
        lo, hi = self.lo, self.hi
        if not self.extrapolate and (tt < lo - 1e-12 * max(1, abs(lo)) or tt > hi + 1e-12 * max(1, abs(hi))):
            raise DataRangeError(f"table {self.label!r}: time {tt} outside the tabulated range [{lo}, {hi}]")
        return self.fn(tt)

    def many(self, tt: np.ndarray):
        """Evaluate at an array of times (the same range check on each)."""
        lo, hi = self.lo, self.hi
        if not self.extrapolate and tt.size:
            bad = (tt < lo - 1e-12 * max(1, abs(lo))) | (tt > hi + 1e-12 * max(1, abs(hi)))
            if np.any(bad):
                t0 = float(tt.ravel()[np.flatnonzero(bad.ravel())[0]])
                raise DataRangeError(f"table {self.label!r}: time {t0} outside the tabulated range [{lo}, {hi}]")
        return self.fn(tt)


def motion(f: Callable[[float], float], fd: Callable[[float], float] | None = None,
           fdd: Callable[[float], float] | None = None, label: str = "f(t)") -> TimeFunction:
    """Wrap a callable as a :class:`TimeFunction`.

    Missing derivatives are central differences with ``h = 1e-4·max(1, |t|)``: the first
    derivative then carries an error of order h²·f‴/6 and the second h²·f⁗/12. Supply analytic
    derivatives for tight-tolerance work.
    """
    if not callable(f):
        raise ModelInputTypeError(f"motion {label!r}: f must be callable, got {type(f).__name__}")

    if fd is None:
        fd = _CentralDifference(f, 1)
    if fdd is None:
        fdd = _CentralDifference(f, 2)
    return TimeFunction(f, fd, fdd, label)


def constant(value: float) -> TimeFunction:
    """f(t) = value."""
    return TimeFunction(_Constant(value), _Constant(0.0), _Constant(0.0), f"{value}", spec=("const", float(value)))


def polynomial(coefficients) -> TimeFunction:
    """f(t) = Σ c_k t^k with coefficients in increasing order."""
    coef = np.asarray(coefficients, float)
    if coef.ndim != 1 or len(coef) == 0 or not np.all(np.isfinite(coef)):
        raise InputError(f"polynomial: coefficients must be a non-empty list of finite numbers, got {coefficients!r}")
    c = np.polynomial.Polynomial(coef)
    d1, d2 = c.deriv(1), c.deriv(2)
    return TimeFunction(c, d1, d2, f"poly{list(coefficients)}", spec=("poly", coef.copy()))


def ramp(rate: float, start: float = 0.0) -> TimeFunction:
    """f(t) = start + rate·t (constant velocity drive)."""
    return polynomial([start, rate])


def harmonic(amplitude: float, omega: float, phase: float = 0.0, offset: float = 0.0) -> TimeFunction:
    """f(t) = offset + amplitude·sin(ωt + phase)."""
    return TimeFunction(
        _Harmonic(amplitude, omega, phase, offset, 0),
        _Harmonic(amplitude, omega, phase, offset, 1),
        _Harmonic(amplitude, omega, phase, offset, 2),
        f"{amplitude}·sin({omega}t+{phase})",
        spec=("harmonic", float(amplitude), float(omega), float(phase), float(offset)),
    )


class _Cycloidal:
    """Derivative ``order`` of the cycloidal rest-to-rest law (:func:`cycloidal`)."""

    def __init__(self, change, duration, start, order):
        self.h, self.T, self.t0, self.order = change, duration, start, order

    def __call__(self, t):
        tau = (t - self.t0) / self.T
        if tau <= 0.0:
            return 0.0
        if tau >= 1.0:
            return self.h if self.order == 0 else 0.0
        c = 2.0 * np.pi
        if self.order == 0:
            return self.h * (tau - np.sin(c * tau) / c)
        if self.order == 1:
            return self.h / self.T * (1.0 - np.cos(c * tau))
        return self.h * c / self.T**2 * np.sin(c * tau)


def cycloidal(change: float, duration: float, start: float = 0.0) -> TimeFunction:
    r"""The cycloidal rest-to-rest law: ``f`` moves by ``change`` in ``duration`` seconds from ``start``.

    With :math:`\tau = (t - t_0)/T` (Norton, *Design of Machinery*, cam design, the cycloidal
    displacement),

    .. math::

        f = h\,\Big(\tau - \frac{\sin 2\pi\tau}{2\pi}\Big),\qquad
        \dot f = \frac{h}{T}\,(1 - \cos 2\pi\tau),\qquad
        \ddot f = \frac{2\pi h}{T^2}\,\sin 2\pi\tau \qquad (0 \le \tau \le 1),

    ``f = 0`` before and ``f = h`` after.  ``change`` is in the driven coordinate's SI unit (rad or
    m), or a string with its unit (``"90 deg"``); ``duration`` and ``start`` in s or with a unit.
    Velocity and acceleration are continuous (zero at both ends); the jerk jumps at both ends.  Peak velocity ``2h/T``, peak acceleration ``2πh/T²``.
    The compiled path evaluates the same formulas (:mod:`core.compiled.timefunctions`).
    """
    from .inputs import UnitError, parse_quantity

    if isinstance(change, str):  # "90 deg" for an angle driver, "0.2 m" for a point driver
        try:
            h = parse_quantity(change, "rad", where="cycloidal change")
        except UnitError:
            h = parse_quantity(change, "m", where="cycloidal change (an angle or a length)")
    else:
        h = parse_quantity(change, "1", where="cycloidal change")
    T = parse_quantity(duration, "s", where="cycloidal duration")
    t0 = parse_quantity(start, "s", where="cycloidal start")
    for name, value in (("change", h), ("duration", T), ("start", t0)):
        if np.ndim(value) != 0:
            raise InputError(f"cycloidal: {name} must be one number, got {value!r} (one law per driver)")
    if not T > 0.0:
        raise InputError(f"cycloidal: duration = {duration!r} must be a positive time")
    return TimeFunction(*(_Cycloidal(h, T, t0, k) for k in range(3)), f"cycloidal {h:g} in {T:g} s from {t0:g} s",
                        spec=("cycloidal", float(h), float(T), float(t0), False))


def tabulated(times, values, label: str = "table", bc_type: str = "not-a-knot",
              extrapolate: bool = False) -> TimeFunction:
    """Cubic-spline interpolation of tabulated data (C² continuous).

    Parameters
    ----------
    times : array_like, shape (n,)
        Strictly increasing sample times [s].
    values : array_like, shape (n,)
    label : str
        Names the table in error messages (e.g. the file and column).
    extrapolate : bool
        If False, evaluating outside ``[times[0], times[-1]]`` raises :class:`core.errors.DataRangeError`.
    """
    t = np.asarray(times, float)
    y = np.asarray(values, float)
    if t.ndim != 1 or t.shape != y.shape or len(t) < 4:
        raise InputError(f"table {label!r}: need ≥ 4 samples of equal length, got {t.shape} and {y.shape}")
    if not np.all(np.isfinite(t)) or not np.all(np.isfinite(y)):
        bad = int(np.flatnonzero(~(np.isfinite(t) & np.isfinite(y)))[0])
        raise InputError(f"table {label!r}: non-finite sample at row {bad} (t={t[bad]}, value={y[bad]})")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.flatnonzero(dt <= 0)[0])
        raise InputError(f"table {label!r}: times not strictly increasing at row {k + 1} (t={t[k + 1]} after {t[k]})")
    cs = CubicSpline(t, y, bc_type=bc_type, extrapolate=True)
    d1, d2 = cs.derivative(1), cs.derivative(2)
    lo, hi = t[0], t[-1]

    spec = ("spline", np.asarray(cs.x, float).copy(), np.asarray(cs.c, float).copy(), bool(extrapolate), float(lo), float(hi))
    return TimeFunction(*(_RangeGuard(fn, lo, hi, label, extrapolate) for fn in (cs, d1, d2)), label, spec=spec)


def as_time_function(obj, label: str = "f(t)") -> TimeFunction:
    """Coerce a number, a callable, a (times, values) pair or a TimeFunction."""
    if isinstance(obj, TimeFunction):
        return obj
    if isinstance(obj, (int, float)):
        return constant(float(obj))
    if callable(obj):
        return motion(obj, label=label)
    if isinstance(obj, tuple) and len(obj) == 2:
        return tabulated(obj[0], obj[1], label=label)
    raise ModelInputTypeError(f"{label}: cannot interpret {type(obj).__name__} as a function of time "
                              "(give a number, a callable f(t), a (times, values) table or a TimeFunction)")
