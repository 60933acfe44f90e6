r"""Prescribed motions of time used by driving constraints and applied loads.

A :class:`TimeFunction` returns the value and its first two time derivatives,
``(f(t), ḟ(t), f̈(t))``, which driving constraints need for ``ν = ḟ`` and ``γ ⊃ f̈``.

* :func:`motion` wraps user callables; derivatives are taken from user callables when given,
  otherwise from central differences with step ``h = 1e-4·max(1, |t|)`` (error O(h²), stated
  in the function's docstring so a user can decide).
* :func:`tabulated` interpolates measured data (e.g. joint angles of a gait trial) with a
  twice-differentiable cubic spline (:class:`scipy.interpolate.CubicSpline`), whose derivatives
  are exact for the interpolant.
* :func:`polynomial`, :func:`ramp` and :func:`harmonic` are common closed forms.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.interpolate import CubicSpline


class TimeFunction:
    """A scalar function of time with its first two derivatives.

    Parameters
    ----------
    f, fd, fdd : callable(t) -> float
        Value and first and second derivatives.
    label : str
        Used in error messages.
    """

    def __init__(self, f: Callable[[float], float], fd: Callable[[float], float], fdd: Callable[[float], float], label: str = "f(t)"):
        self.f, self.fd, self.fdd, self.label = f, fd, fdd, label

    def __call__(self, t: float) -> tuple[float, float, float]:
        return float(self.f(t)), float(self.fd(t)), float(self.fdd(t))

    def __repr__(self) -> str:
        return f"TimeFunction({self.label})"


def motion(f: Callable[[float], float], fd: Callable[[float], float] | None = None,
           fdd: Callable[[float], float] | None = None, label: str = "f(t)") -> TimeFunction:
    """Wrap a callable as a :class:`TimeFunction`.

    Missing derivatives are central differences with ``h = 1e-4·max(1, |t|)``: the first
    derivative then carries an error of order h²·f‴/6 and the second h²·f⁗/12. Supply analytic
    derivatives for tight-tolerance work.
    """
    if not callable(f):
        raise TypeError(f"motion {label!r}: f must be callable, got {type(f).__name__}")

    def _h(t):
        return 1e-4 * max(1.0, abs(t))

    if fd is None:
        def fd(t):  # noqa: E306
            h = _h(t)
            return (f(t + h) - f(t - h)) / (2 * h)
    if fdd is None:
        def fdd(t):  # noqa: E306
            h = _h(t)
            return (f(t + h) - 2 * f(t) + f(t - h)) / (h * h)
    return TimeFunction(f, fd, fdd, label)


def constant(value: float) -> TimeFunction:
    """f(t) = value."""
    return TimeFunction(lambda t: value, lambda t: 0.0, lambda t: 0.0, f"{value}")


def polynomial(coefficients) -> TimeFunction:
    """f(t) = Σ c_k t^k with coefficients in increasing order."""
    c = np.polynomial.Polynomial(np.asarray(coefficients, float))
    d1, d2 = c.deriv(1), c.deriv(2)
    return TimeFunction(c, d1, d2, f"poly{list(coefficients)}")


def ramp(rate: float, start: float = 0.0) -> TimeFunction:
    """f(t) = start + rate·t (constant velocity drive)."""
    return polynomial([start, rate])


def harmonic(amplitude: float, omega: float, phase: float = 0.0, offset: float = 0.0) -> TimeFunction:
    """f(t) = offset + amplitude·sin(ωt + phase)."""
    return TimeFunction(
        lambda t: offset + amplitude * np.sin(omega * t + phase),
        lambda t: amplitude * omega * np.cos(omega * t + phase),
        lambda t: -amplitude * omega**2 * np.sin(omega * t + phase),
        f"{amplitude}·sin({omega}t+{phase})",
    )


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
        If False, evaluating outside ``[times[0], times[-1]]`` raises ValueError.
    """
    t = np.asarray(times, float)
    y = np.asarray(values, float)
    if t.ndim != 1 or t.shape != y.shape or len(t) < 4:
        raise ValueError(f"table {label!r}: need ≥ 4 samples of equal length, got {t.shape} and {y.shape}")
    if not np.all(np.isfinite(t)) or not np.all(np.isfinite(y)):
        bad = int(np.flatnonzero(~(np.isfinite(t) & np.isfinite(y)))[0])
        raise ValueError(f"table {label!r}: non-finite sample at row {bad} (t={t[bad]}, value={y[bad]})")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.flatnonzero(dt <= 0)[0])
        raise ValueError(f"table {label!r}: times not strictly increasing at row {k + 1} (t={t[k + 1]} after {t[k]})")
    cs = CubicSpline(t, y, bc_type=bc_type, extrapolate=True)
    d1, d2 = cs.derivative(1), cs.derivative(2)
    lo, hi = t[0], t[-1]

    def guard(fn):
        def g(tt):
            if not extrapolate and (tt < lo - 1e-12 * max(1, abs(lo)) or tt > hi + 1e-12 * max(1, abs(hi))):
                raise ValueError(f"table {label!r}: time {tt} outside the tabulated range [{lo}, {hi}]")
            return fn(tt)
        return g

    return TimeFunction(guard(cs), guard(d1), guard(d2), label)


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
    raise TypeError(f"{label}: cannot interpret {type(obj).__name__} as a function of time")
