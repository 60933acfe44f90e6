"""Piecewise polynomials with value, first and second derivative in one vectorised call.

Internal helper of the railway geometry.  A piecewise polynomial of degree k on breakpoints
x_0 < x_1 < ... < x_n is stored with ascending local coefficients::

    f(x) = sum_j c[i, j] (x - x_i)^j        for x_i <= x < x_{i+1}

Evaluation returns f, f' and f'' together (one ``searchsorted``, one power table and one
matrix product), which keeps the numpy call count on hot paths small.  Arguments outside
[x_0, x_n] are extrapolated with the first or last piece.

Quintic Hermite pieces are built from exact (f, f', f'') at both ends of each interval::

    c0 = f0, c1 = f1, c2 = f2/2,
    D0 = g0 - (c0 + c1 h + c2 h^2),  D1 = g1 - (c1 + 2 c2 h),  D2 = g2 - 2 c2,
    c3 = (10 D0 - 4 D1 h + D2 h^2/2) / h^3
    c4 = (-15 D0 + 7 D1 h - D2 h^2) / h^4
    c5 = (6 D0 - 3 D1 h + D2 h^2/2) / h^5

so the interpolant is C2 inside a section and reproduces polynomials up to degree 5 exactly.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PiecewisePoly", "quintic_hermite_coeffs"]


def quintic_hermite_coeffs(h, f0, f1, f2, g0, g1, g2):
    """Ascending local coefficients (..., 6) of the quintic Hermite interpolant on [0, h]."""
    h = np.asarray(h, dtype=float)
    c0 = np.asarray(f0, dtype=float)
    c1 = np.asarray(f1, dtype=float)
    c2 = 0.5 * np.asarray(f2, dtype=float)
    D0 = g0 - (c0 + c1 * h + c2 * h**2)
    D1 = g1 - (c1 + 2.0 * c2 * h)
    D2 = g2 - 2.0 * c2
    c3 = (10.0 * D0 - 4.0 * D1 * h + 0.5 * D2 * h**2) / h**3
    c4 = (-15.0 * D0 + 7.0 * D1 * h - D2 * h**2) / h**4
    c5 = (6.0 * D0 - 3.0 * D1 * h + 0.5 * D2 * h**2) / h**5
    return np.stack(np.broadcast_arrays(c0, c1, c2, c3, c4, c5), axis=-1)


class PiecewisePoly:
    """Vector-valued piecewise polynomial evaluated with its first two derivatives.

    Parameters
    ----------
    breaks : (n+1,) ndarray
        Strictly increasing breakpoints.
    coeffs : (n, k+1) or (n, k+1, m) ndarray
        Ascending local coefficients of each piece (m components for a vector-valued curve).
    """

    def __init__(self, breaks, coeffs):
        breaks = np.asarray(breaks, dtype=float)
        coeffs = np.asarray(coeffs, dtype=float)
        if coeffs.ndim == 2:
            coeffs = coeffs[:, :, None]
            self.scalar = True
        else:
            self.scalar = False
        if breaks.ndim != 1 or breaks.size != coeffs.shape[0] + 1:
            raise ValueError(f"breaks ({breaks.size}) must number pieces + 1 ({coeffs.shape[0] + 1})")
        if np.any(np.diff(breaks) <= 0.0):
            i = int(np.argmax(np.diff(breaks) <= 0.0))
            raise ValueError(f"breakpoints must increase strictly; break {i + 1} = {breaks[i + 1]!r}")
        n, k1, m = coeffs.shape
        j = np.arange(k1, dtype=float)
        d1 = np.zeros_like(coeffs)
        d1[:, :-1] = coeffs[:, 1:] * j[1:, None]
        d2 = np.zeros_like(coeffs)
        d2[:, :-2] = coeffs[:, 2:] * (j[2:] * (j[2:] - 1.0))[:, None]
        # stack (n, k+1, 3*m): value, first, second derivative coefficients side by side
        self._stack = np.concatenate([coeffs, d1, d2], axis=2)
        self.breaks = breaks
        self._inner = breaks[1:-1].copy()
        self.coeffs = coeffs
        self.degree = k1 - 1
        self.n_components = m
        self._powers = np.arange(k1)

    @property
    def x_min(self) -> float:
        return float(self.breaks[0])

    @property
    def x_max(self) -> float:
        return float(self.breaks[-1])

    def eval_raw(self, x):
        """Return (len(x), 3*m) with value, d/dx and d2/dx2 blocks of m components each."""
        i = np.searchsorted(self._inner, x, side="right")
        t = x - self.breaks[i]
        T = t[:, None] ** self._powers
        return np.einsum("nk,nkq->nq", T, self._stack[i])

    def eval_piece(self, i, t):
        """Raw (value, d1, d2 blocks) of pieces i at local offsets t (one-sided at the ends)."""
        T = np.asarray(t, dtype=float)[:, None] ** self._powers
        return np.einsum("nk,nkq->nq", T, self._stack[i])

    def __call__(self, x):
        """Evaluate f, f', f'' at x (any shape); returns a tuple of three arrays."""
        x = np.asarray(x, dtype=float)
        shape = x.shape
        out = self.eval_raw(x.reshape(-1))
        m = self.n_components
        if self.scalar:
            return tuple(out[:, k].reshape(shape) for k in range(3))
        return tuple(out[:, k * m:(k + 1) * m].reshape(shape + (m,)) for k in range(3))

    @classmethod
    def from_hermite(cls, x, f, df, d2f, f_right=None, df_right=None, d2f_right=None):
        """Quintic Hermite interpolant from nodal values.

        ``f_right`` etc. (optional) give the right-end values of each interval when the data are
        one-sided (e.g. curvature jumps at section joints); by default the nodal values are used.
        """
        x = np.asarray(x, dtype=float)
        f, df, d2f = (np.asarray(a, dtype=float) for a in (f, df, d2f))
        h = np.diff(x)
        if f.ndim > 1:
            h = h[:, None]
        g0 = f[1:] if f_right is None else np.asarray(f_right, dtype=float)
        g1 = df[1:] if df_right is None else np.asarray(df_right, dtype=float)
        g2 = d2f[1:] if d2f_right is None else np.asarray(d2f_right, dtype=float)
        c = quintic_hermite_coeffs(h, f[:-1], df[:-1], d2f[:-1], g0, g1, g2)
        if c.ndim == 3:  # (n, m, 6) -> (n, 6, m)
            c = np.transpose(c, (0, 2, 1))
        return cls(x, c)

    @classmethod
    def from_scipy(cls, pp):
        """Convert a scipy ``PPoly`` (descending local coefficients) of a scalar function."""
        c = np.asarray(pp.c, dtype=float)[::-1].T  # (n, k+1) ascending
        return cls(pp.x, c)


def concatenate(polys, gap=1.0):
    """Join scalar piecewise polynomials into one bank with argument offsets.

    Returns (bank, offsets): polys[k] evaluated at x equals bank evaluated at x + offsets[k].
    Lets one vectorised call evaluate several profiles (e.g. wheel and rail).
    """
    breaks, coeffs, offsets = [], [], []
    start = 0.0
    deg = max(p.degree for p in polys)
    for k, p in enumerate(polys):
        off = start - p.x_min + (gap if k else 0.0)
        c = np.zeros((p.coeffs.shape[0], deg + 1))
        c[:, : p.degree + 1] = p.coeffs[:, :, 0]
        b = p.breaks + off
        if k:
            # bridge piece between banks: repeat the previous last piece's coefficients shifted
            # is unnecessary because arguments never fall in the gap; use a constant filler.
            filler = np.zeros((1, deg + 1))
            coeffs.append(filler)
            breaks.append(b[:1])
        else:
            breaks.append(b[:1])
        breaks.append(b[1:])
        coeffs.append(c)
        offsets.append(off)
        start = b[-1]
    return PiecewisePoly(np.concatenate(breaks), np.concatenate(coeffs)), np.array(offsets)
