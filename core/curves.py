"""Piecewise polynomials, and spatial curves in arc length with their moving frames.

Domain-free geometry shared by the track of a railway and the centreline of a roller coaster.

Piecewise polynomials
---------------------
A piecewise polynomial of degree k on breakpoints x_0 < x_1 < ... < x_n is stored with ascending
local coefficients::

    f(x) = sum_j c[i, j] (x - x_i)^j        for x_i <= x < x_{i+1}

Evaluation returns f, f' and f'' together (one ``searchsorted``, one power table and one
matrix product), which keeps the numpy call count on hot paths small.  Arguments outside
[x_0, x_n] are extrapolated with the first or last piece.

Quintic Hermite pieces are built from exact (f, f', f'') at both ends of each interval
(f0, f1, f2 at the left end, g0, g1, g2 at the right end, h the interval length)::

    c0 = f0, c1 = f1, c2 = f2/2,
    D0 = g0 - (c0 + c1 h + c2 h^2),  D1 = g1 - (c1 + 2 c2 h),  D2 = g2 - 2 c2,
    c3 = (10 D0 - 4 D1 h + D2 h^2/2) / h^3
    c4 = (-15 D0 + 7 D1 h - D2 h^2) / h^4
    c5 = (6 D0 - 3 D1 h + D2 h^2/2) / h^5

so the interpolant is C2 inside a section and reproduces polynomials up to degree 5 exactly.
For a smooth f the error is the Hermite remainder with triple nodes at both ends::

    f(x) - p(x) = f^(6)(xi) / 6! (x - x_i)^3 (x - x_{i+1})^3,   |f - p| <= max|f^(6)| h^6 / 46080

Framed curves
-------------
A spatial curve r(s) parameterised by its arc length s (m) carries a moving frame
R(s) = [t, n, b] (columns: tangent, normal, binormal; for a track: tangent, lateral, up) that
rotates with the Darboux vector omega(s) (1/m, global components)::

    dR/ds = [omega]x R,            i.e.  t' = omega x t,  n' = omega x n,  b' = omega x b
    d2R/ds2 = [omega']x R + [omega]x dR/ds

The Frenet frame has omega = tau t + kappa b (curvature kappa, torsion tau); a track frame rolled
by a cant angle phi about t and turned by a heading psi about the vertical e_z has
omega = psi' e_z + phi' t.  :class:`FramedCurve` is the interface (``length``, ``closed``,
``evaluate`` and the fast ``evaluate_raw``); :class:`TabulatedFramedCurve` stores r, R and omega
as one vector-valued quintic Hermite table built from exact nodal values.

References
----------
Pombo, J. and Ambrosio, J. (2003). General spatial curve joint for rail guided vehicles:
kinematics and dynamics. Multibody System Dynamics 9(3):237-264 (track centreline parameterised
by arc length with a moving frame and its derivatives; equation numbers were not checked against
the paper here).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError

__all__ = [
    "CurveFrame",
    "FramedCurve",
    "PiecewisePoly",
    "TabulatedFramedCurve",
    "concatenate",
    "quintic_hermite_coeffs",
]


# ---------------------------------------------------------------------------------------------
# piecewise polynomials
# ---------------------------------------------------------------------------------------------
def quintic_hermite_coeffs(h, f0, f1, f2, g0, g1, g2):
    """Ascending local coefficients of the quintic Hermite interpolant on [0, h].

    Equations in the module docstring (c0 ... c5 from the end values and derivatives).

    Parameters
    ----------
    h : float or ndarray
        Interval lengths, broadcast against the values (e.g. shape (n, 1) for (n, m) values).
    f0, f1, f2 : ndarray
        Value, first and second derivative at the left end (any common shape ``S``).
    g0, g1, g2 : ndarray
        The same at the right end.

    Returns
    -------
    ``(*S, 6)`` ndarray
        Coefficients c0 ... c5 along the last axis.
    """
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

    f(x) = sum_j c[i, j] (x - x_i)^j on [x_i, x_{i+1}); arguments outside [x_0, x_n] use the
    first or last piece.

    Parameters
    ----------
    breaks : (n+1,) ndarray
        Strictly increasing breakpoints.
    coeffs : (n, k+1) or (n, k+1, m) ndarray
        Ascending local coefficients of each piece (m components for a vector-valued curve).

    Attributes
    ----------
    breaks : (n+1,) ndarray
    coeffs : (n, k+1, m) ndarray
    degree, n_components : int
    scalar : bool
        True when built from (n, k+1) coefficients; ``__call__`` then drops the component axis.
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
            raise InputError(f"breaks ({breaks.size}) must number pieces + 1 ({coeffs.shape[0] + 1})")
        if np.any(np.diff(breaks) <= 0.0):
            i = int(np.argmax(np.diff(breaks) <= 0.0))
            raise InputError(f"breakpoints must increase strictly; break {i + 1} = {float(breaks[i + 1])!r}")
        _, k1, m = coeffs.shape
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
        """Return (len(x), 3*m) with value, d/dx and d2/dx2 blocks of m components each.

        ``x`` must be a 1-D float array; it is not checked (hot path).
        """
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
    Lets one vectorised call evaluate several curves (e.g. wheel and rail profiles).

    Parameters
    ----------
    polys : sequence of PiecewisePoly
        Scalar piecewise polynomials.
    gap : float
        Width of the unused filler piece between two members of the bank.

    Returns
    -------
    bank : PiecewisePoly
    offsets : (len(polys),) ndarray
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


# ---------------------------------------------------------------------------------------------
# curves in arc length with a moving frame
# ---------------------------------------------------------------------------------------------
_I1, _I2 = np.array([1, 2, 0]), np.array([2, 0, 1])


def _cross(a, b):
    """Cross product of (..., 3) arrays (cheaper than np.cross for small arrays)."""
    return a[..., _I1] * b[..., _I2] - a[..., _I2] * b[..., _I1]


@dataclass
class CurveFrame:
    """Curve point, moving frame and their derivatives at N arc lengths.

    Attributes
    ----------
    position : (N, 3) ndarray
        r(s) (m).
    dposition : (N, 3) ndarray
        r'(s) (-); the unit tangent when s is the arc length of r.
    ddposition : (N, 3) ndarray
        r''(s) (1/m).
    R : (N, 3, 3) ndarray
        Frame with columns tangent t, normal n, binormal b (global components).
    omega : (N, 3) ndarray
        Darboux vector (1/m, global components) with dR/ds = [omega]x R.
    domega : (N, 3) ndarray
        d omega/ds (1/m^2).
    ddomega : (N, 3) ndarray or None
        d2 omega/ds2 (1/m^3), keyword only.  Needed as input of :class:`TabulatedFramedCurve`;
        ``evaluate`` leaves it None.
    """

    position: np.ndarray
    dposition: np.ndarray
    ddposition: np.ndarray
    R: np.ndarray
    omega: np.ndarray
    domega: np.ndarray
    ddomega: np.ndarray | None = field(default=None, kw_only=True)

    @property
    def tangent(self):
        """t, the first column of R, (N, 3)."""
        return self.R[:, :, 0]

    @property
    def normal(self):
        """n, the second column of R, (N, 3)."""
        return self.R[:, :, 1]

    @property
    def binormal(self):
        """b, the third column of R, (N, 3)."""
        return self.R[:, :, 2]

    def dR(self):
        """dR/ds = [omega]x R, (N, 3, 3) (1/m)."""
        return np.cross(self.omega[:, None, :], np.swapaxes(self.R, 1, 2)).swapaxes(1, 2)


class FramedCurve(abc.ABC):
    """A spatial curve in arc length with a moving frame: the interface shared by the domains.

    The curve is r(s) for s in [s_0, s_0 + length] with frame R(s) = [t, n, b] and Darboux
    vector omega(s), dR/ds = [omega]x R (module docstring).  Subclasses implement
    :meth:`evaluate_raw`; they may override :meth:`_evaluate` to return a richer
    :class:`CurveFrame` (extra fields) or to evaluate more exactly than the fast path.

    Attributes
    ----------
    length : float
        Arc length of the curve (m).
    closed : bool
        True when the curve closes on itself (s is taken modulo ``length``).
    name : str
        Label used in error messages.
    """

    length: float
    closed: bool = False
    name: str = "curve"

    def evaluate(self, s) -> CurveFrame:
        """Point, frame and derivatives at arc lengths s (m).

        Parameters
        ----------
        s : float or array_like
            Arc lengths (m); flattened to 1-D.

        Returns
        -------
        CurveFrame
            Arrays over the N = s.size points.

        Raises
        ------
        ValueError
            If an arc length is not finite (the message names it).
        """
        s = np.atleast_1d(np.asarray(s, dtype=float)).reshape(-1)
        bad = ~np.isfinite(s)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{self.name}: non-finite arc length s[{i}] = {float(s[i])!r}")
        return self._evaluate(s)

    def _evaluate(self, s) -> CurveFrame:
        """:meth:`evaluate` after validation; s is a finite 1-D float array."""
        return CurveFrame(*self.evaluate_raw(s))

    def project(self, points, s_guess, tol: float = 1e-10, max_iter: int = 20):
        """Arc lengths of the curve points nearest to ``points`` (foot of the perpendicular).

        Solves f(s) = (p - r(s)) . r'(s) = 0 by Newton's method from ``s_guess`` (vectorised
        over the points), with f'(s) = -``|r'|^2`` + (p - r) . r''; a Newton step is limited to
        a quarter of the distance ``|p - r|`` + 1 m, so that a guess far along the curve walks in
        instead of jumping.  The foot of the perpendicular is unique and the iteration converges
        from any guess within the curve's radius of curvature of the point (a point within a
        few metres of a track of radius >= 100 m converges from any guess within tens of
        metres).

        Parameters
        ----------
        points : (N, 3) array_like
            Points (m).
        s_guess : (N,) array_like
            Starting arc lengths (m).
        tol : float
            Step tolerance on s (m).
        max_iter : int

        Returns
        -------
        s : (N,) ndarray
            Arc lengths (m) where (p - r(s)) is perpendicular to the curve.

        Raises
        ------
        NumericalFailure
            Non-convergence (the message names the first point and its last step).
        """
        p = np.atleast_2d(np.asarray(points, dtype=float))
        s = np.array(np.broadcast_to(np.asarray(s_guess, dtype=float), p.shape[:1]))
        step = np.full(s.shape, np.inf)
        for _ in range(max_iter):
            r, d1, d2 = self.evaluate_raw(s)[:3]
            e = p - r
            f = np.einsum("ij,ij->i", e, d1)
            df = -np.einsum("ij,ij->i", d1, d1) + np.einsum("ij,ij->i", e, d2)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = -f / df
            lim = 0.25 * (np.linalg.norm(e, axis=1) + 1.0)
            step = np.where(np.isfinite(step), np.clip(step, -lim, lim), 0.0)
            s = s + step
            if np.max(np.abs(step)) < tol:
                return s
        from .errors import NumericalFailure

        i = int(np.argmax(np.abs(step)))
        raise NumericalFailure(f"{self.name}: projection of point {i} {p[i].tolist()} onto the curve "
                               f"did not converge in {max_iter} iterations (last step {step[i]!r} m)")

    @abc.abstractmethod
    def evaluate_raw(self, s):
        """Fast evaluation for hot paths, without input checks.

        Parameters
        ----------
        s : (N,) ndarray
            Finite arc lengths (m), float, 1-D.

        Returns
        -------
        tuple of ndarray
            r (N, 3), r' (N, 3), r'' (N, 3), R (N, 3, 3), omega (N, 3), omega' (N, 3).
        """


class TabulatedFramedCurve(FramedCurve):
    """A framed curve stored as one quintic Hermite table of r, R and omega.

    On every interval [s_i, s_{i+1}] (length h_i) each of the 15 components
    f in {r (3), R (9, row-major), omega (3)} is the quintic p_i with

        p_i(0) = f(s_i+),   p_i'(0) = f'(s_i+),   p_i''(0) = f''(s_i+)
        p_i(h_i) = f(s_{i+1}-),   p_i'(h_i) = f'(s_{i+1}-),   p_i''(h_i) = f''(s_{i+1}-)

    (coefficients in the module docstring), from exact values at both ends of every interval
    (one-sided limits where curvature or cant rate jump at a node).  The frame derivatives come
    from the Darboux vector::

        R' = [omega]x R,    R'' = [omega']x R + [omega]x R'

    One evaluation of the table gives r, r', r'', R, omega and omega' (``evaluate_raw``).  The
    error of each component is at most max|f^(6)| h^6 / 46080.  R is interpolated entrywise, so
    it is orthonormal and ``dR/ds = [omega]x R`` holds only to that error: with ``|R^(6)|`` ~
    ``|omega|^6``, about (h ``|omega|``)^6 / 46080, i.e. round-off for h ``|omega|`` below about 0.015
    (2 m intervals on a 150 m radius).  Outside [s_0, s_n] an open curve is extrapolated with the
    end pieces; a closed curve takes s modulo its length.

    Parameters
    ----------
    nodes : (n+1,) array_like
        Strictly increasing arc lengths s_0 < ... < s_n (m).
    start : CurveFrame
        Exact values with ``ddomega`` given.  With ``end`` None: at the n+1 nodes (data
        continuous across nodes).  Otherwise: at the left ends of the n intervals (s_i+).
    end : CurveFrame, optional
        Exact values at the right ends of the n intervals (s_{i+1}-), with ``ddomega``.
    closed : bool
        The curve closes on itself: r and R at s_n must equal those at s_0 (to 1e-9 relative
        to max(1, length) for r, 1e-9 for R).
    name : str
        Label used in error messages.

    Attributes
    ----------
    nodes : (n+1,) ndarray
    length : float
        s_n - s_0 (m).
    table : PiecewisePoly
        15 components: r in ``POSITION``, R (row-major) in ``ROTATION``, omega in ``DARBOUX``.
        ``table.eval_raw`` returns 45 columns: values 0-14, d/ds 15-29, d2/ds2 30-44 (compiled
        kernels rely on this layout).

    Raises
    ------
    ValueError
        On bad nodes or nodal values (the message names the value and its index), R not
        orthonormal at a node (to 1e-8), or a closed curve that does not close.

    References
    ----------
    Pombo, J. and Ambrosio, J. (2003). Multibody System Dynamics 9(3):237-264 (moving track
    frame with its derivatives along the arc length; equation numbers not checked here).
    """

    POSITION = slice(0, 3)
    ROTATION = slice(3, 12)
    DARBOUX = slice(12, 15)
    N_COMPONENTS = 15

    def __init__(self, nodes, start, end=None, *, closed=False, name="curve"):
        self.name = str(name)
        nodes = np.asarray(nodes, dtype=float)
        if nodes.ndim != 1 or nodes.size < 2:
            raise InputError(f"{self.name}: nodes must be a 1-D array of at least 2 arc lengths, "
                             f"got shape {nodes.shape}")
        bad = ~np.isfinite(nodes)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{self.name}: nodes[{i}] = {float(nodes[i])!r} is not finite")
        d = np.diff(nodes)
        if np.any(d <= 0.0):
            i = int(np.argmax(d <= 0.0)) + 1
            raise InputError(f"{self.name}: nodes must increase strictly; nodes[{i}] = "
                             f"{float(nodes[i])!r} after nodes[{i - 1}] = {float(nodes[i - 1])!r}")
        n = nodes.size - 1
        if end is None:
            a = self._nodal_arrays(start, n + 1, "start")
            ends = [tuple(x[:-1] for x in a), tuple(x[1:] for x in a)]
        else:
            ends = [self._nodal_arrays(start, n, "start"), self._nodal_arrays(end, n, "end")]
        self.nodes = nodes
        self.length = float(nodes[-1] - nodes[0])
        self.closed = bool(closed)
        h = np.diff(nodes)
        cols = []
        for pos, dpos, ddpos, R, om, dom, ddom in ends:
            dR = _cross(om[:, None, :], np.swapaxes(R, 1, 2)).swapaxes(1, 2)
            ddR = (_cross(dom[:, None, :], np.swapaxes(R, 1, 2))
                   + _cross(om[:, None, :], np.swapaxes(dR, 1, 2))).swapaxes(1, 2)
            cols.append((np.column_stack([pos, R.reshape(n, 9), om]),
                         np.column_stack([dpos, dR.reshape(n, 9), dom]),
                         np.column_stack([ddpos, ddR.reshape(n, 9), ddom])))
        (fa, da, dda), (fb, db, ddb) = cols
        if self.closed:
            gap_r = float(np.max(np.abs(fb[-1, self.POSITION] - fa[0, self.POSITION])))
            gap_R = float(np.max(np.abs(fb[-1, self.ROTATION] - fa[0, self.ROTATION])))
            if gap_r > 1e-9 * max(1.0, self.length) or gap_R > 1e-9:
                raise InputError(f"{self.name}: closed curve does not close: |r(end) - r(start)| "
                                 f"= {gap_r!r} m, |R(end) - R(start)| = {gap_R!r}")
        c = quintic_hermite_coeffs(h[:, None], fa, da, dda, fb, db, ddb)
        self.table = PiecewisePoly(nodes, np.transpose(c, (0, 2, 1)))

    def _nodal_arrays(self, frame, n, label):
        """Validated (r, r', r'', R, omega, omega', omega'') arrays of n rows from a CurveFrame."""
        if not isinstance(frame, CurveFrame):
            raise TypeError(f"{self.name}: {label} must be a CurveFrame, got {type(frame).__name__}")
        if frame.ddomega is None:
            raise InputError(f"{self.name}: {label}.ddomega (omega'') is needed for the table")
        names = ("position", "dposition", "ddposition", "R", "omega", "domega", "ddomega")
        out = []
        for key in names:
            a = np.asarray(getattr(frame, key), dtype=float)
            shape = (n, 3, 3) if key == "R" else (n, 3)
            if a.shape != shape:
                raise InputError(f"{self.name}: {label}.{key} has shape {a.shape}, expected {shape}")
            bad = ~np.isfinite(a)
            if np.any(bad):
                i = np.unravel_index(int(np.argmax(bad)), a.shape)
                raise InputError(f"{self.name}: {label}.{key}[{', '.join(map(str, i))}] = "
                                 f"{float(a[i])!r} is not finite")
            out.append(a)
        R = out[3]
        err = np.max(np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)), axis=(1, 2))
        if np.any(err > 1e-8):
            i = int(np.argmax(err > 1e-8))
            raise InputError(f"{self.name}: {label}.R[{i}] is not orthonormal "
                             f"(max |R^T R - I| = {float(err[i])!r})")
        return tuple(out)

    def evaluate_raw(self, s):
        """(r, r', r'', R, omega, omega') from the table in one vectorised evaluation.

        Parameters
        ----------
        s : (N,) ndarray
            Finite arc lengths (m), float, 1-D (not checked).

        Returns
        -------
        tuple of ndarray
            r (N, 3) m, r' (N, 3), r'' (N, 3) 1/m, R (N, 3, 3), omega (N, 3) 1/m,
            omega' (N, 3) 1/m^2 (views into one (N, 45) array).
        """
        if self.closed:
            s0 = self.nodes[0]
            s = s0 + np.mod(s - s0, self.length)
        o = self.table.eval_raw(s)
        M = s.shape[0]
        return (o[:, 0:3], o[:, 15:18], o[:, 30:33], o[:, 3:12].reshape(M, 3, 3), o[:, 12:15],
                o[:, 27:30])
