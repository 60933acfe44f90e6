r"""Functions of time in compiled code: the closed forms and tables of :mod:`core.drivers`.

A :class:`core.drivers.TimeFunction` built by ``constant``, ``polynomial``, ``ramp``,
``harmonic``, ``tabulated`` or ``cycloidal`` carries a ``spec``; :func:`encode` turns it into one float row (a
"program") that :func:`evaluate` reads in numba, returning ``(status, f, ḟ, f̈)``:

==========  ====================================  ==============================================
kind        program row                           value (derivatives analytic)
==========  ====================================  ==============================================
constant    ``[0, c]``                            ``c``
polynomial  ``[1, n, c₀ … c_{n−1}]``              ``Σ c_k tᵏ`` (Horner)
harmonic    ``[2, a, ω, φ, f₀]``                  ``f₀ + a sin(ωt + φ)``
spline      ``[3, n, extrapolate, t_lo, t_hi,     cubic piece ``i`` with ``x = t − t_i``:
            t₀ … t_n, c₀₀ c₁₀ c₂₀ c₃₀ …]``        ``((c₀x + c₁)x + c₂)x + c₃`` (scipy ``PPoly``
                                                  coefficients, highest power first)
cycloidal   ``[4, h, T, t₀, integrated]``         with ``τ = (t − t₀)/T`` on ``0 < τ < 1``:
                                                  ``h(τ − sin 2πτ / 2π)`` (:func:`core.drivers.cycloidal`);
                                                  integrated: its time integral
                                                  ``hT(τ²/2 + (cos 2πτ − 1)/4π²)``, then
                                                  ``h(t − t₀ − T/2)`` (a spin-up to a constant rate,
                                                  :func:`core.flexible.models.spin_up_angle`)
==========  ====================================  ==============================================

A spline evaluated outside ``[t_lo, t_hi]`` (with a relative margin of 1e-12, as the numpy
path) without ``extrapolate`` returns :data:`core.compiled.protocol.OUT_OF_RANGE`.  A
:func:`core.drivers.motion` of a Python callable has no spec: :func:`encode` raises
:class:`core.errors.NotCompilable` naming the element.  The compiled values equal the numpy
ones (the same formulas; tested to round-off).
"""

from __future__ import annotations

import numba
import numpy as np

from ..drivers import TimeFunction
from ..errors import NotCompilable
from .protocol import OK, OUT_OF_RANGE

__all__ = ["encode", "encode_rows", "evaluate", "TF_CONST", "TF_POLY", "TF_HARMONIC", "TF_SPLINE", "TF_CYCLOIDAL"]

TF_CONST, TF_POLY, TF_HARMONIC, TF_SPLINE, TF_CYCLOIDAL = 0, 1, 2, 3, 4


def encode(fn: TimeFunction, element: str) -> np.ndarray:
    """The program row of ``fn`` (see the module docstring); NotCompilable naming ``element``."""
    spec = getattr(fn, "spec", None)
    if spec is None:
        raise NotCompilable(f"{element}: its function of time {getattr(fn, 'label', fn)!r} is a Python callable; "
                            "the compiled path evaluates core.drivers constant/polynomial/ramp/harmonic/tabulated/cycloidal")
    kind = spec[0]
    if kind == "const":
        return np.array([TF_CONST, spec[1]], float)
    if kind == "poly":
        c = np.asarray(spec[1], float)
        return np.concatenate([[TF_POLY, len(c)], c])
    if kind == "harmonic":
        return np.array([TF_HARMONIC, *spec[1:5]], float)
    if kind == "spline":
        x, c, extrapolate, lo, hi = spec[1:6]
        n = len(x) - 1
        return np.concatenate([[TF_SPLINE, n, 1.0 if extrapolate else 0.0, lo, hi], np.asarray(x, float),
                               np.asarray(c, float).T.ravel()])
    if kind == "cycloidal":
        return np.array([TF_CYCLOIDAL, *spec[1:4], 1.0 if spec[4] else 0.0], float)
    raise NotCompilable(f"{element}: function of time of kind {kind!r} has no compiled form")  # pragma: no cover


def encode_rows(functions: list[TimeFunction], elements: list[str]) -> np.ndarray:
    """Programs of several functions as rows of one 2-D array (zero-padded to the longest)."""
    rows = [encode(f, e) for f, e in zip(functions, elements)]
    width = max((len(r) for r in rows), default=1)
    out = np.zeros((len(rows), width))
    for k, r in enumerate(rows):
        out[k, :len(r)] = r
    return out


@numba.njit(cache=True, fastmath=False, boundscheck=False)
def evaluate(prog, t):
    """``(status, f, ḟ, f̈)`` of the program row ``prog`` at time ``t`` (module docstring)."""
    kind = int(prog[0])
    if kind == TF_CONST:
        return OK, prog[1], 0.0, 0.0
    if kind == TF_POLY:
        n = int(prog[1])
        f = 0.0
        d1 = 0.0
        d2 = 0.0
        for k in range(n - 1, -1, -1):  # Horner for the value and both derivatives
            d2 = d2 * t + 2.0 * d1
            d1 = d1 * t + f
            f = f * t + prog[2 + k]
        return OK, f, d1, d2
    if kind == TF_HARMONIC:
        a, om, ph, off = prog[1], prog[2], prog[3], prog[4]
        x = om * t + ph
        s, c = np.sin(x), np.cos(x)
        return OK, off + a * s, a * om * c, -a * om * om * s
    if kind == TF_CYCLOIDAL:
        return _cycloidal(prog[1], prog[2], prog[3], prog[4] != 0.0, t)
    # spline
    n = int(prog[1])
    lo, hi = prog[3], prog[4]
    if prog[2] == 0.0:
        if t < lo - 1e-12 * max(1.0, abs(lo)) or t > hi + 1e-12 * max(1.0, abs(hi)):
            return OUT_OF_RANGE, 0.0, 0.0, 0.0
    xb = 5  # breaks start
    # piece: last break <= t (binary search), clamped to [0, n − 1]
    i0 = 0
    i1 = n
    while i1 - i0 > 1:
        mid = (i0 + i1) // 2
        if prog[xb + mid] <= t:
            i0 = mid
        else:
            i1 = mid
    i = i0
    x = t - prog[xb + i]
    cb = xb + n + 1 + 4 * i
    c0, c1, c2, c3 = prog[cb], prog[cb + 1], prog[cb + 2], prog[cb + 3]
    f = ((c0 * x + c1) * x + c2) * x + c3
    d1 = (3.0 * c0 * x + 2.0 * c1) * x + c2
    d2 = 6.0 * c0 * x + 2.0 * c1
    return OK, f, d1, d2


@numba.njit(cache=True, fastmath=False, boundscheck=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
def _cycloidal(h, T, t0, integrated, t):
    """``(OK, f, ḟ, f̈)`` of the cycloidal law or of its time integral (module docstring; the
    formulas of :class:`core.drivers._Cycloidal` and :class:`core.flexible.models._SpinUp`)."""
    tau = (t - t0) / T
    c = 2.0 * np.pi
    if not integrated:
        if tau <= 0.0:
            return OK, 0.0, 0.0, 0.0
        if tau >= 1.0:
            return OK, h, 0.0, 0.0
        return OK, h * (tau - np.sin(c * tau) / c), h / T * (1.0 - np.cos(c * tau)), h * c / T**2 * np.sin(c * tau)
    if tau <= 0.0:
        return OK, 0.0, 0.0, 0.0
    if tau >= 1.0:
        return OK, h * (t - t0 - 0.5 * T), h, 0.0
    w = c / T
    x = t - t0
    return OK, h / T * (x * x / 2.0 + (np.cos(w * x) - 1.0) / w**2), h / T * (x - np.sin(w * x) / w), \
        h / T * (1.0 - np.cos(w * x))
