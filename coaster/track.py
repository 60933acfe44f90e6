"""Roller-coaster track centrelines g(L) in arc length L, with g', g'', g''', g''''.

A centreline is a space curve parameterised by its arc length L (m); every centreline here
returns the point and its first four derivatives in L at once (:meth:`Centreline.derivatives`)::

    g(L),  g' = t (unit tangent),  g'' = kappa n,  g''',  g''''

from which the frames of :mod:`coaster.frames` take the curvature, torsion and Darboux vector
(Frenet: g' ... g''''; rotation-minimising: g' ... g'''' for the table of omega'').

Two kinds of centreline are provided:

* **Splines through control points** (:class:`SplineCentreline`): cubic C2 (natural, not-a-knot
  or periodic), quintic C4 (not-a-knot or periodic), and shape-preserving C1 (PCHIP or Akima),
  open or closed, fitted in the chord-length parameter u and reparameterised by arc length
  (Gauss-Legendre quadrature of ``|g_u|`` per span, Newton inversion u(L); formulas in the class).
* **Analytic segments** with exact derivatives: :class:`Straight`, :class:`CircularArc`,
  :class:`Helix`, :class:`Clothoid`, :class:`VerticalLoop`, joined into a
  :class:`CompositeCentreline` (use :func:`chain` to place them end to end).

:func:`read_circuit` reads the shared closed circuit (``data/coaster``), converting Unreal
Engine's left-handed centimetre axes to right-handed metres.

References
----------
Pombo, J. and Ambrosio, J. (2007). Modelling tracks for roller coaster dynamics. Int. J. Vehicle
Design 45(4):470-500 (cubic, Akima and shape-preserving splines for coaster tracks; arc-length
parameterisation).  Equation numbers were not checked against the paper here.
Fritsch, F. N. and Carlson, R. E. (1980). Monotone piecewise cubic interpolation. SIAM J. Numer.
Anal. 17(2):238-246 (PCHIP).  Akima, H. (1970). J. ACM 17(4):589-602 (Akima spline).
"""

from __future__ import annotations

import abc
import csv
import math
from dataclasses import dataclass
from typing import NamedTuple
from pathlib import Path

import numpy as np
import scipy.interpolate as si
import scipy.special as sp

from core.errors import DataFileError, InputError, NumericalFailure
from core.inputs import checked_options

__all__ = [
    "Centreline",
    "CircuitData",
    "CircularArc",
    "Clothoid",
    "CompositeCentreline",
    "Helix",
    "Segment",
    "SplineCentreline",
    "Straight",
    "VerticalLoop",
    "Clearance",
    "chain",
    "check_clearance",
    "circuit_centreline",
    "read_circuit",
    "CIRCUIT_FILE",
]

DATA_DIR = Path(__file__).resolve().parent.parent / "data" / "coaster"
#: The shared closed circuit (203 control points, centimetres, left-handed; see its README).
CIRCUIT_FILE = DATA_DIR / "yarlung_track_coaster-sim_MIT.csv"


# ---------------------------------------------------------------------------------------------
# interface
# ---------------------------------------------------------------------------------------------
class Centreline(abc.ABC):
    """A track centreline g(L) in arc length L with its first four derivatives.

    Attributes
    ----------
    length : float
        Arc length (m); L runs over [0, length].
    closed : bool
        The curve closes on itself (L is taken modulo ``length``).
    breaks : (m,) ndarray
        Arc lengths (m) where a derivative of g may jump (knots, segment joints), including 0
        and ``length``.  Tables built on the curve put nodes there and use one-sided values.
    name : str
        Label in error messages.
    """

    length: float
    closed: bool = False
    breaks: np.ndarray
    name: str = "centreline"

    def derivatives(self, L, side: str = "right"):
        """g and its first four derivatives in L at the arc lengths ``L``.

        Parameters
        ----------
        L : float or array_like
            Arc lengths (m), flattened.  A closed curve takes L modulo ``length``; an open one
            extrapolates its end pieces.
        side : {"right", "left"}
            At a break, use the piece to the right (L+) or to the left (L-).

        Returns
        -------
        (5, N, 3) ndarray
            g (m), g' (-), g'' (1/m), g''' (1/m^2), g'''' (1/m^3).

        Raises
        ------
        InputError
            A non-finite arc length (named with its index) or a bad ``side``.
        """
        L = np.atleast_1d(np.asarray(L, dtype=float)).reshape(-1)
        bad = ~np.isfinite(L)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{self.name}: non-finite arc length L[{i}] = {float(L[i])!r}")
        if side not in ("right", "left"):
            raise InputError(f"{self.name}: side must be 'right' or 'left', got {side!r}")
        if self.closed:
            Lw = np.mod(L, self.length)
            if side == "left":  # L = 0 from the left is the end of the last piece
                Lw = np.where(Lw == 0.0, self.length, Lw)
            L = Lw
        return self._derivatives(L, side)

    @abc.abstractmethod
    def _derivatives(self, L, side):
        """:meth:`derivatives` after validation (L finite, 1-D, wrapped if closed)."""

    def curvature_torsion(self, L):
        """Curvature kappa = ``|g''|`` (1/m) and torsion tau = g'.(g'' x g''')/kappa^2 (1/m).

        tau is NaN where kappa = 0 (undefined there).
        """
        d = self.derivatives(L)
        k = np.linalg.norm(d[2], axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            tau = np.einsum("ij,ij->i", d[1], np.cross(d[2], d[3])) / k**2
        return k, tau


# ---------------------------------------------------------------------------------------------
# splines through control points
# ---------------------------------------------------------------------------------------------
_SPLINE_KINDS = ("cubic", "quintic", "pchip", "akima", "makima")


def _check_spacing(name, chords, closed, accept=()):
    """Plausible control-point spacing and, on a closed track, a closing chord that is not a gap.

    The typical spacing is the median chord |P_j+1 - P_j| (a coordinate slip, mm or km for m,
    moves it out of ``control_point_spacing`` in data/coaster/plausible_ranges.csv).  A closed
    track adds the chord from the last point back to the first; when that chord is longer than
    twice the median and longer than every other chord, the points do not describe a closed
    track (the spline would bridge the gap silently): refused with the gap, the typical chord
    and how to declare the track open.
    """
    from .inputs import check

    inner = chords[:-1] if closed else chords
    med = float(np.median(inner)) if inner.size else float(chords[0])
    check("control_point_spacing", med, where=f"{name}: control points",
          accept=accept)
    if closed and inner.size and "closure_gap" not in set(accept):
        gap = float(chords[-1])
        if gap > 2.0 * med and gap > float(np.max(inner)):
            raise InputError(
                f"{name}: closed=True, but the last control point is {gap:.4g} m from the first, "
                f"{gap / med:.2g} times the typical chord {med:.4g} m (median; longest other chord "
                f"{float(np.max(inner)):.4g} m): the points do not close the track and the spline would "
                f"bridge the gap; add the missing control points, or declare the track open (closed=False); "
                f"to bridge it deliberately, accept=['closure_gap']")


class SplineCentreline(Centreline):
    """Interpolating spline through control points, reparameterised by arc length.

    **Fit.**  The points P_j (m) get chord-length parameters u_0 = 0, u_j = u_{j-1} +
    ``|P_j - P_{j-1}|`` (a closed curve adds the closing chord), and each coordinate is interpolated in u
    with scipy (its interpolators are well-tested, return a ``PPoly`` whose local polynomials we
    evaluate directly, and cover every kind below, so nothing is re-implemented):

    =========== =============================== ========== =======================================
    kind        scipy                           continuity boundary (open / closed)
    =========== =============================== ========== =======================================
    ``cubic``   ``CubicSpline``                 C2         ``bc`` natural or not-a-knot / periodic
    ``quintic`` ``make_interp_spline(k=5)``     C4         not-a-knot / periodic
    ``pchip``   ``PchipInterpolator``           C1         one-sided 3-point / wrapped neighbours
    ``akima``   ``Akima1DInterpolator``         C1         Akima's ends / wrapped neighbours
    ``makima``  ``Akima1DInterpolator(makima)`` C1         as akima
    =========== =============================== ========== =======================================

    Shape-preserving kinds act per coordinate: where all three coordinates have a local extremum
    at the same control point the curve has zero speed there (a cusp), which is refused.
    A closed shape-preserving curve is fitted to the points padded by three wrapped neighbours
    at each end; PCHIP and Akima slopes depend on at most two neighbours, so the derivative at
    the seam equals the periodic one.  Continuity matters for the forces (notes/coaster.md):
    C1 splines make the curvature jump at every knot, a cubic makes g''' (torsion) jump, a
    quintic is C4.

    **Arc length.**  With the speed s(u) = ``|g_u|`` (s_u, s_uu, s_uuu its u-derivatives)::

        L(u) = L_i + int_{u_i}^{u} s(v) dv          (Gauss-Legendre, n_gauss points per span)
        u <- u - (L(u) - L*) / s(u)                  (Newton inversion, from the chord guess)
        u' = 1/s,  u'' = -s_u/s^3,  u''' = u'(-s_uu/s^3 + 3 s_u^2/s^4),
        u'''' = -s_uuu/s^5 + 10 s_u s_uu/s^6 - 15 s_u^3/s^7
        s_u = g_u.g_uu/s,  s_uu = (g_uu.g_uu + g_u.g_uuu - s_u^2)/s,
        s_uuu = (3 g_uu.g_uuu + g_u.g_uuuu - 3 s_u s_uu)/s
        g_L = g_u u',  g_LL = g_uu u'^2 + g_u u'',
        g_LLL = g_uuu u'^3 + 3 g_uu u' u'' + g_u u''',
        g_LLLL = g_uuuu u'^4 + 6 g_uuu u'^2 u'' + g_uu (3 u''^2 + 4 u' u''') + g_u u''''

    (Faa di Bruno for the inverse function; notes/coaster.md "Frames").  The quadrature error
    of a panel is of order (Delta u)^(2 n_gauss) ``|s^(2 n_gauss)|``; every span is split into
    ``n_sub`` equal panels, doubled (up to 256) until the total length changes by less than
    1e-13 relative (the last change is kept in ``quadrature_change``).

    Parameters
    ----------
    points : (N, 3) array_like
        Control points (m), N >= 4; a closed curve must not repeat its first point at the end
        (an exact repetition is dropped).
    kind : {"cubic", "quintic", "pchip", "akima", "makima"}
    closed : bool
    bc : {"not-a-knot", "natural"}
        End condition of an open cubic (ignored otherwise).
    n_gauss : int
        Gauss-Legendre points per span for the arc length.
    name : str
    accept : sequence of str
        Checks not to enforce: ``"control_point_spacing"`` (a median chord outside the plausible
        range of data/coaster/plausible_ranges.csv), ``"closure_gap"`` (a closed track whose
        closing chord is a gap).

    Attributes
    ----------
    u_knots : (n+1,) ndarray
        Parameter breakpoints of the spline pieces.
    L_knots : (n+1,) ndarray
        Arc length at those breakpoints (m); ``breaks``.
    L_points : (N,) ndarray
        Arc length at the control points (m).
    length : float

    Raises
    ------
    InputError
        Fewer than 4 points, a non-finite coordinate, two equal points, consecutive or not
        (the message names both indices), an unknown kind or end condition, a closed track
        whose closing chord is a gap (longer than twice the median chord and than every other
        chord: names the gap and the typical chord).
    core.inputs.ImplausibleValueError
        A median chord outside the plausible control-point spacing (coordinates in mm or km).

    References
    ----------
    Pombo, J. and Ambrosio, J. (2007). Int. J. Vehicle Design 45(4):470-500 (splines for
    coaster tracks, arc-length parameterisation).
    """

    def __init__(self, points, kind="cubic", closed=False, bc="not-a-knot", n_gauss=8,
                 name="spline centreline", accept=()):
        self.name = str(name)
        if kind not in _SPLINE_KINDS:
            raise InputError(f"{self.name}: unknown spline kind {kind!r}; use one of {_SPLINE_KINDS}")
        if bc not in ("not-a-knot", "natural"):
            raise InputError(f"{self.name}: unknown end condition bc={bc!r}; use 'not-a-knot' or 'natural'")
        P = np.asarray(points, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3:
            raise InputError(f"{self.name}: points must have shape (N, 3), got {P.shape}")
        bad = ~np.isfinite(P)
        if np.any(bad):
            i, j = np.unravel_index(int(np.argmax(bad)), P.shape)
            raise InputError(f"{self.name}: point {i} coordinate {j} = {float(P[i, j])!r} is not finite")
        if closed and P.shape[0] > 1 and np.array_equal(P[0], P[-1]):
            P = P[:-1]
        if P.shape[0] < 4:
            raise InputError(f"{self.name}: need at least 4 control points, got {P.shape[0]}")
        chords = np.linalg.norm(np.diff(np.vstack([P, P[:1]]) if closed else P, axis=0), axis=1)
        scale = float(np.max(np.abs(P - P.mean(axis=0)))) or 1.0
        tiny = chords <= 1e-12 * scale
        if np.any(tiny):
            i = int(np.argmax(tiny))
            j = (i + 1) % P.shape[0]
            raise InputError(f"{self.name}: control points {i} and {j} coincide ({P[i].tolist()}); "
                             f"consecutive points must differ")
        _check_spacing(self.name, chords, closed, accept)
        self.points = P
        self.kind = kind
        self.closed = bool(closed)
        self.bc = bc
        self.n_gauss = int(n_gauss)
        u = np.concatenate([[0.0], np.cumsum(chords)])  # closed: N+1 values, last = first point
        Y = np.vstack([P, P[:1]]) if closed else P
        if not closed:
            u = u[: P.shape[0]]
        self._fit(u, Y)  # first: a shape-preserving cusp (a retraced track) is the more specific error
        # a repeated point further along passes the track through the same place twice
        from scipy.spatial import cKDTree

        pairs = sorted(cKDTree(P).query_pairs(1e-12 * scale))
        if pairs:
            i, j = pairs[0]
            raise InputError(f"{self.name}: control points {i} and {j} coincide ({P[i].tolist()}): a duplicate "
                             f"control point (the track would pass the same place twice); remove it")
        self._arc_length()
        self.L_points = self._L_of_u(u[: P.shape[0]])
        self.breaks = self.L_knots

    # --- fit -----------------------------------------------------------------------------
    def _fit(self, u, Y):
        kind, closed = self.kind, self.closed
        if kind == "cubic":
            pp = si.CubicSpline(u, Y, axis=0, bc_type="periodic" if closed else self.bc)
            x, c = pp.x, pp.c  # (4, n, 3) descending
        elif kind == "quintic":
            b = si.make_interp_spline(u, Y, k=5, axis=0, bc_type="periodic" if closed else None)
            pps = [si.PPoly.from_spline(si.BSpline(b.t, b.c[:, j], 5)) for j in range(3)]
            x, c = pps[0].x, np.stack([p.c for p in pps], axis=-1)
        else:
            if closed:
                U, n = u[-1], u.size - 1
                pad = 3
                uu = np.concatenate([u[n - pad:n] - U, u, u[1:pad + 1] + U])
                YY = np.vstack([Y[n - pad:n], Y, Y[1:pad + 1]])
            else:
                uu, YY = u, Y
            if kind == "pchip":
                pp = si.PchipInterpolator(uu, YY, axis=0)
            else:
                pp = si.Akima1DInterpolator(uu, YY, axis=0, method=kind)
            x, c = pp.x, pp.c
        keep = (x[:-1] >= u[0] - 1e-12 * u[-1]) & (x[1:] <= u[-1] * (1 + 1e-12)) & (np.diff(x) > 0)
        idx = np.flatnonzero(keep)
        self.u_knots = np.concatenate([x[idx], x[idx[-1] + 1:idx[-1] + 2]])
        c = c[:, idx, :]
        k = c.shape[0] - 1
        self._coef = np.ascontiguousarray(c[::-1].transpose(1, 0, 2))  # (n, k+1, 3) ascending
        self.degree = k
        n = self._coef.shape[0]
        sp = self._speed(np.arange(n), np.zeros(n))
        small = sp <= 1e-9 * max(1.0, float(np.max(sp)))
        if np.any(small):
            j = int(np.argmax(small))
            raise InputError(f"{self.name}: the {kind} spline has zero speed |dg/du| at u = "
                             f"{float(self.u_knots[j])!r} (knot {j}): a cusp, where every coordinate "
                             f"has a local extremum (PCHIP/Akima set such slopes to zero); add or move "
                             f"control points or use a cubic/quintic spline")

    def _poly(self, i, du, nder):
        """g_u derivatives 0..nder of pieces i at local offsets du: (nder+1, N, 3)."""
        c = self._coef[i]  # (N, k+1, 3)
        k = self.degree
        out = np.zeros((nder + 1,) + du.shape + (3,))
        for d in range(nder + 1):
            if d > k:
                break
            j = np.arange(d, k + 1)
            fac = np.array([math.perm(int(jj), d) for jj in j], dtype=float)
            powr = du[:, None] ** (j - d)  # (N, k+1-d)
            out[d] = np.einsum("nj,njc->nc", powr * fac, c[:, j, :])
        return out

    def _speed(self, i, du):
        g1 = self._poly(i, du, 1)[1]
        return np.linalg.norm(g1, axis=-1)

    def _arc_length(self):
        xg, wg = np.polynomial.legendre.leggauss(self.n_gauss)
        self._xg, self._wg = xg, wg
        h = np.diff(self.u_knots)
        i = np.arange(h.size)
        self.n_sub = 1
        dL = self._partial_L(i, h)
        while True:
            self.n_sub *= 2
            dL2 = self._partial_L(i, h)
            change = float(np.max(np.abs(dL2 - dL)))
            if change <= 1e-13 * float(np.sum(dL2)) or self.n_sub >= 256:
                break
            dL = dL2
        self.quadrature_change = change
        self.L_knots = np.concatenate([[0.0], np.cumsum(dL2)])
        self.length = float(self.L_knots[-1])

    def _partial_L(self, i, du):
        """int_0^du s(u_i + v) dv by composite Gauss-Legendre (n_sub panels) on [0, du]."""
        ng, m = self.n_gauss, self.n_sub
        x = ((np.arange(m)[:, None] + 0.5 * (self._xg[None, :] + 1.0)) / m).reshape(-1)  # (m*ng,)
        w = np.tile(self._wg, m) / m
        v = x[None, :] * du[:, None]
        s = self._speed(np.repeat(i, m * ng), v.reshape(-1)).reshape(-1, m * ng)
        return 0.5 * du * (s @ w)

    def _L_of_u(self, u):
        i = np.clip(np.searchsorted(self.u_knots, u, side="right") - 1, 0, self.u_knots.size - 2)
        return self.L_knots[i] + self._partial_L(i, u - self.u_knots[i])

    def u_of_L(self, L, side="right", tol=1e-13, max_iter=30):
        """Spline parameter u and piece index at arc lengths L (Newton inversion, class docstring).

        Returns
        -------
        i : (N,) int ndarray
            Piece index.
        du : (N,) ndarray
            Offset u - u_i in the piece.

        Raises
        ------
        NumericalFailure
            Newton does not converge (names the arc length).
        """
        nk = self.L_knots.size
        i = np.searchsorted(self.L_knots, L, side=side) - 1
        i = np.clip(i, 0, nk - 2)
        h = np.diff(self.u_knots)[i]
        dL = np.diff(self.L_knots)[i]
        target = L - self.L_knots[i]
        du = target / dL * h
        for _ in range(max_iter):
            F = self._partial_L(i, du) - target
            s = self._speed(i, du)
            step = F / s
            du = du - step
            if np.all(np.abs(step) <= tol * max(1.0, float(self.u_knots[-1]))):
                return i, du
        j = int(np.argmax(np.abs(step)))
        raise NumericalFailure(f"{self.name}: arc-length inversion did not converge at L = {float(L[j])!r} m "
                               f"(last step {float(step[j])!r})")

    def _derivatives(self, L, side):
        i, du = self.u_of_L(L, side)
        G = self._poly(i, du, 4)
        g0, g1, g2, g3, g4 = G
        dot = lambda a, b: np.einsum("ij,ij->i", a, b)  # noqa: E731
        s = np.linalg.norm(g1, axis=1)
        s1 = dot(g1, g2) / s
        s2 = (dot(g2, g2) + dot(g1, g3) - s1**2) / s
        s3 = (3.0 * dot(g2, g3) + dot(g1, g4) - 3.0 * s1 * s2) / s
        u1 = 1.0 / s
        u2 = -s1 / s**3
        u3 = u1 * (-s2 / s**3 + 3.0 * s1**2 / s**4)
        u4 = -s3 / s**5 + 10.0 * s1 * s2 / s**6 - 15.0 * s1**3 / s**7
        c = lambda a: a[:, None]  # noqa: E731
        gL = g1 * c(u1)
        gLL = g2 * c(u1**2) + g1 * c(u2)
        gLLL = g3 * c(u1**3) + 3.0 * g2 * c(u1 * u2) + g1 * c(u3)
        gLLLL = (g4 * c(u1**4) + 6.0 * g3 * c(u1**2 * u2) + g2 * c(3.0 * u2**2 + 4.0 * u1 * u3)
                 + g1 * c(u4))
        return np.stack([g0, gL, gLL, gLLL, gLLLL])


# ---------------------------------------------------------------------------------------------
# analytic segments
# ---------------------------------------------------------------------------------------------
def _rot_z(psi):
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class Segment(Centreline):
    """An analytic segment: a local closed form g_loc(L) placed by a rigid motion.

        g(L) = origin + Q g_loc(L),   g^(k)(L) = Q g_loc^(k)(L)

    with g_loc(0) = 0.  Subclasses implement ``_local(L)`` returning (5, N, 3).

    Parameters
    ----------
    origin : (3,) array_like, optional
        Start point (m); default 0.
    rotation : (3, 3) array_like, optional
        Proper rotation Q (local to global); default identity.
    """

    closed = False

    def __init__(self, origin=None, rotation=None, name=None):
        self.name = name or type(self).__name__
        self.origin = np.zeros(3) if origin is None else np.asarray(origin, dtype=float).reshape(3)
        Q = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
        if Q.shape != (3, 3) or not np.allclose(Q.T @ Q, np.eye(3), atol=1e-10) or np.linalg.det(Q) < 0:
            raise InputError(f"{self.name}: rotation must be a proper 3x3 rotation matrix")
        if not np.all(np.isfinite(self.origin)):
            raise InputError(f"{self.name}: origin {self.origin.tolist()} is not finite")
        self.rotation = Q
        self.breaks = np.array([0.0, self.length])

    def placed(self, origin, rotation):
        """A copy of the segment at another origin and rotation."""
        import copy

        new = copy.copy(self)
        Segment.__init__(new, origin, rotation, self.name)
        return new

    def _derivatives(self, L, side):
        d = self._local(L)
        out = d @ self.rotation.T
        out[0] += self.origin
        return out

    @abc.abstractmethod
    def _local(self, L):
        """(5, N, 3) local g_loc and derivatives."""

    @staticmethod
    def _positive(name, label, value):
        value = float(value)
        if not np.isfinite(value) or value <= 0.0:
            raise InputError(f"{name}: {label} must be positive and finite, got {value!r}")
        return value


class Straight(Segment):
    """Straight line at grade angle gamma (rad, positive uphill) heading along local x.

        g = L (cos gamma, 0, sin gamma),  g' = (cos gamma, 0, sin gamma),  g'' = g''' = g'''' = 0
    """

    def __init__(self, length, grade=0.0, origin=None, rotation=None, name=None):
        self.length = self._positive(name or "Straight", "length", length)
        self.grade = float(grade)
        super().__init__(origin, rotation, name)

    def _local(self, L):
        e = np.array([math.cos(self.grade), 0.0, math.sin(self.grade)])
        out = np.zeros((5, L.size, 3))
        out[0] = L[:, None] * e
        out[1] = e
        return out


def _helix_local(L, R, c, sign):
    """Helix about local z through (0, sign R, 0): g = (R sin phi, sign R (1 - cos phi), c phi).

    phi = L/h, h = sqrt(R^2 + c^2); d^k/dL^k = h^-k d^k/dphi^k with
    (sin)^(k) = sin(phi + k pi/2), (1 - cos)^(k) = -cos(phi + k pi/2) for k >= 1.
    """
    h = math.hypot(R, c)
    phi = L / h
    out = np.zeros((5, L.size, 3))
    out[0, :, 0] = R * np.sin(phi)
    out[0, :, 1] = sign * R * (1.0 - np.cos(phi))
    out[0, :, 2] = c * phi
    for k in range(1, 5):
        out[k, :, 0] = R * np.sin(phi + 0.5 * k * np.pi) / h**k
        out[k, :, 1] = -sign * R * np.cos(phi + 0.5 * k * np.pi) / h**k
    out[1, :, 2] = c / h
    return out


class Helix(Segment):
    """Circular helix of radius R (m) and rise c (m per radian) about the local vertical.

        g = (R sin phi, sigma R (1 - cos phi), c phi),  phi = L/h,  h = sqrt(R^2 + c^2)

    (sigma = +1 turns left, -1 right); curvature kappa = R/h^2, torsion tau = sigma c/h^2,
    Darboux vector sigma e_z/h (notes/coaster.md, closed forms).  The start tangent is
    (R, 0, c)/h: on grade atan(c/R).

    Parameters
    ----------
    radius : float
        R (m).
    rise : float
        c (m per radian of turn); 2 pi c per turn.  0 gives a horizontal circular arc.
    angle : float
        Turned angle phi_end (rad), positive; length = h phi_end.
    turn : {+1, -1}
        sigma.
    """

    def __init__(self, radius, rise, angle, turn=1, origin=None, rotation=None, name=None):
        nm = name or type(self).__name__
        self.radius = self._positive(nm, "radius", radius)
        self.rise = float(rise)
        self.angle = self._positive(nm, "angle", angle)
        if turn not in (1, -1):
            raise InputError(f"{nm}: turn must be +1 (left) or -1 (right), got {turn!r}")
        self.turn = int(turn)
        self.h = math.hypot(self.radius, self.rise)
        self.length = self.h * self.angle
        super().__init__(origin, rotation, name)

    def _local(self, L):
        return _helix_local(L, self.radius, self.rise, self.turn)


class CircularArc(Helix):
    """Horizontal circular arc of radius R (m) through ``angle`` (rad); turn +1 left, -1 right.

        g = (R sin(L/R), sigma R (1 - cos(L/R)), 0),  kappa = 1/R
    """

    def __init__(self, radius, angle, turn=1, origin=None, rotation=None, name=None):
        super().__init__(radius, 0.0, angle, turn, origin, rotation, name)


class VerticalLoop(Segment):
    """Circular vertical loop of radius R (m), displaced sideways by ``offset`` (m) per loop.

    A helix about the local lateral axis y (entering horizontally along x at the bottom)::

        g = (R sin phi, sigma d phi, R (1 - cos phi)),  phi = L/h,  d = offset/(2 pi),
        h = sqrt(R^2 + d^2),  length = 2 pi h

    kappa = R/h^2; with offset 0 the exit coincides with the entry (a closed circle).
    """

    def __init__(self, radius, offset=0.0, origin=None, rotation=None, name=None):
        nm = name or type(self).__name__
        self.radius = self._positive(nm, "radius", radius)
        self.offset = float(offset)
        d = self.offset / (2.0 * math.pi)
        self.h = math.hypot(self.radius, d)
        self.length = 2.0 * math.pi * self.h
        super().__init__(origin, rotation, name)

    def _local(self, L):
        d = self.offset / (2.0 * math.pi)
        hel = _helix_local(L, self.radius, d, 1)  # (R sin, R(1-cos), d phi)
        return hel[:, :, [0, 2, 1]]


class Clothoid(Segment):
    """Horizontal clothoid (Euler spiral): curvature linear in L from k_start to k_end (1/m).

        kappa(L) = k0 + L/a,   a = length/(k_end - k_start)  (a = +-A^2, signed)
        heading theta(L) = k0 L + L^2/(2a)
        g' = (cos theta, sin theta, 0) = T,  N = (-sin theta, cos theta, 0),
        g'' = kappa N,  g''' = N/a - kappa^2 T,  g'''' = -3 kappa T/a - kappa^3 N

    The position is the standard clothoid c(s) = int_0^s (cos(v^2/2a), sin(v^2/2a)) dv,
    c(s) = sqrt(pi ``|a|``) (C(z), sgn(a) S(z)), z = s / sqrt(pi ``|a|``) (Fresnel integrals),
    taken from s0 = k0 a and turned so that the local start tangent is x:
    g_loc(L) = Rz(-theta_0) (c(s0 + L) - c(s0)), theta_0 = s0^2/(2a).  Positive curvature
    turns left.  Clothoids in a vertical plane (a clothoid loop) are placed with a rotation
    about x (``rotation``).
    """

    def __init__(self, length, k_start, k_end, origin=None, rotation=None, name=None):
        nm = name or type(self).__name__
        self.length = self._positive(nm, "length", length)
        self.k_start, self.k_end = float(k_start), float(k_end)
        if not (np.isfinite(self.k_start) and np.isfinite(self.k_end)) or self.k_start == self.k_end:
            raise InputError(f"{nm}: k_start ({self.k_start!r}) and k_end ({self.k_end!r}) must be finite "
                             f"and differ (use CircularArc or Straight for constant curvature)")
        self.a = self.length / (self.k_end - self.k_start)
        super().__init__(origin, rotation, name)

    def _std(self, s):
        a = self.a
        sc = math.sqrt(math.pi * abs(a))
        S, C = sp.fresnel(s / sc)
        return np.stack([sc * C, np.sign(a) * sc * S], axis=-1)

    def _local(self, L):
        a, k0 = self.a, self.k_start
        s0 = k0 * a
        th0 = s0**2 / (2 * a)
        c0 = self._std(np.array([s0]))[0]
        p = self._std(s0 + L) - c0
        cth, sth = math.cos(th0), math.sin(th0)
        out = np.zeros((5, L.size, 3))
        out[0, :, 0] = cth * p[:, 0] + sth * p[:, 1]
        out[0, :, 1] = -sth * p[:, 0] + cth * p[:, 1]
        th = k0 * L + L**2 / (2 * a)
        k = k0 + L / a
        T = np.stack([np.cos(th), np.sin(th), 0 * th], axis=-1)
        N = np.stack([-np.sin(th), np.cos(th), 0 * th], axis=-1)
        out[1] = T
        out[2] = k[:, None] * N
        out[3] = N / a - (k**2)[:, None] * T
        out[4] = -3.0 * (k / a)[:, None] * T - (k**3)[:, None] * N
        return out


class CompositeCentreline(Centreline):
    """Segments joined end to end: g(L) = segment_k(L - L_k) on [L_k, L_{k+1}].

    Parameters
    ----------
    segments : sequence of Centreline
        Already placed (see :func:`chain`); each joint must be G1 (position within ``tol`` m,
        unit tangents within ``tol``).
    closed : bool
        The last segment must end where the first starts (G1).
    tol : float

    Raises
    ------
    InputError
        A joint (named by its index and the two segments) with a gap or a kink.
    """

    def __init__(self, segments, closed=False, tol=1e-8, name="composite centreline"):
        self.name = str(name)
        self.segments = list(segments)
        if not self.segments:
            raise InputError(f"{self.name}: no segments")
        lengths = np.array([s.length for s in self.segments])
        self.offsets = np.concatenate([[0.0], np.cumsum(lengths)])
        self.length = float(self.offsets[-1])
        self.closed = bool(closed)
        pairs = list(zip(range(len(self.segments) - 1), range(1, len(self.segments))))
        if closed:
            pairs.append((len(self.segments) - 1, 0))
        for a, b in pairs:
            ea = self.segments[a].derivatives([self.segments[a].length], side="left")
            sb = self.segments[b].derivatives([0.0])
            gap = float(np.linalg.norm(ea[0, 0] - sb[0, 0]))
            kink = float(np.linalg.norm(ea[1, 0] - sb[1, 0]))
            if gap > tol or kink > tol:
                raise InputError(f"{self.name}: joint {a}->{b} ({self.segments[a].name} -> "
                                 f"{self.segments[b].name}) is not G1: gap {gap!r} m, tangent jump {kink!r}")
        br = [self.offsets[k] + s.breaks for k, s in enumerate(self.segments)]
        self.breaks = np.unique(np.concatenate(br))

    def _derivatives(self, L, side):
        k = np.clip(np.searchsorted(self.offsets, L, side=side) - 1, 0, len(self.segments) - 1)
        out = np.empty((5, L.size, 3))
        for j in np.unique(k):
            m = k == j
            out[:, m] = self.segments[j]._derivatives(L[m] - self.offsets[j], side)
        return out


def chain(segments, start=(0.0, 0.0, 0.0), heading=0.0):
    """Place segments end to end by translating and turning each about the vertical.

    Segment k is rotated about e_z (composed with its own ``rotation``) so that the horizontal
    heading of its start tangent equals that of the previous end tangent, and translated to the
    previous end point.  Grades must already match (e.g. a :class:`Straight` on grade
    atan(c/R) before a :class:`Helix`); :class:`CompositeCentreline` reports a mismatch.

    Parameters
    ----------
    segments : sequence of Segment
    start : (3,) array_like
        Start point of the first segment (m).
    heading : float
        Heading of the first segment's start tangent (rad from x towards y).

    Returns
    -------
    list of Segment
        Placed copies.
    """
    out = []
    p = np.asarray(start, dtype=float)
    psi_prev = float(heading)
    for seg in segments:
        d0 = seg._local(np.array([0.0]))[1, 0] @ seg.rotation.T
        psi0 = math.atan2(d0[1], d0[0])
        Q = _rot_z(psi_prev - psi0) @ seg.rotation
        new = seg.placed(p, Q)
        end = new.derivatives([new.length], side="left")
        p = end[0, 0]
        psi_prev = math.atan2(end[1, 0, 1], end[1, 0, 0])
        out.append(new)
    return out


# ---------------------------------------------------------------------------------------------
# self-intersection within the gauge
# ---------------------------------------------------------------------------------------------
class Clearance(NamedTuple):
    """Result of :func:`check_clearance`: the closest approach of non-neighbouring track points.

    Attributes
    ----------
    distance : float
        ``|g(L_a) - g(L_b)|`` (m); inf when no pair of non-neighbours came within
        ``clearance + spacing``.
    L_a, L_b : float
        Arc lengths of the two points (m), L_a < L_b (NaN with distance inf).
    clearance : float
        The required clearance (m).
    window : float
        Along-track separation (m) below which two points count as neighbours.
    """

    distance: float
    L_a: float
    L_b: float
    clearance: float
    window: float


def check_clearance(centreline: Centreline, clearance, spacing=None, raise_error=True) -> Clearance:
    """Check that a track does not come back within ``clearance`` of itself (self-intersection).

    Two track points g(L_a), g(L_b) are *neighbours* when their along-track separation
    d(L_a, L_b) = ``|L_b - L_a|`` (on a closed track min(``|L_b - L_a|``, length - ``|L_b - L_a|``)) is at
    most the window w = (pi/2) c, c the clearance (e.g. the wheel gauge plus the car's width).
    Non-neighbours must stay at least c apart::

        min { |g(L_a) - g(L_b)| : d(L_a, L_b) > w } >= c

    Why w = (pi/2) c: on an arc of radius rho the chord over a separation s is 2 rho sin(s/2 rho)
    >= (2/pi) s for s <= pi rho, so points more than w apart along a track that curves no tighter
    than rho = c/2 are more than c apart; only a genuine return of the track (a loop without
    enough lateral offset, helix turns closer than c, a crossing) or a curve tighter than its own
    gauge (rho < c/2) is reported.

    Method: samples every ``spacing`` (default c/4) into a k-d tree; pairs of non-neighbours
    closer than c + spacing (the most two samples can overestimate a distance) are refined by
    bounded minimisation of ``|g(a) - g(b)|^2`` in (a, b) with its exact gradient
    (d.g'(a), -d.g'(b)), d = g(a) - g(b), within one spacing of the samples.

    Parameters
    ----------
    centreline : Centreline
    clearance : float
        c (m), positive.
    spacing : float, optional
        Sample spacing (m); default c/4.
    raise_error : bool
        Raise on a violation (default) or only return the closest approach.

    Returns
    -------
    Clearance

    Raises
    ------
    InputError
        A non-positive clearance or spacing, or (``raise_error``) a track that comes within c of
        itself: the message names both arc lengths and the distance.
    """
    from scipy.optimize import minimize
    from scipy.spatial import cKDTree

    name = getattr(centreline, "name", "centreline")
    c = float(clearance)
    if not (np.isfinite(c) and c > 0):
        raise InputError(f"{name}: clearance must be positive and finite (m), got {clearance!r}")
    from .inputs import check

    c = float(check("clearance", c, where=f"{name}: check_clearance(clearance=...)"))
    h = c / 4.0 if spacing is None else float(spacing)
    if not (np.isfinite(h) and h > 0):
        raise InputError(f"{name}: spacing must be positive and finite (m), got {spacing!r}")
    w = 0.5 * math.pi * c
    Ltot = float(centreline.length)
    n = max(2, int(math.ceil(Ltot / h)) + 1)
    L = np.linspace(0.0, Ltot, n)
    if centreline.closed:
        L = L[:-1]
    P = centreline.derivatives(L)[0]
    pairs = np.array(sorted(cKDTree(P).query_pairs(c + h)), dtype=int).reshape(-1, 2)

    def sep(a, b):
        d = np.abs(b - a)
        return np.minimum(d, Ltot - d) if centreline.closed else d

    if pairs.size:
        pairs = pairs[sep(L[pairs[:, 0]], L[pairs[:, 1]]) > w]
    best = Clearance(float("inf"), float("nan"), float("nan"), c, w)
    if pairs.size:
        dist = np.linalg.norm(P[pairs[:, 0]] - P[pairs[:, 1]], axis=1)
        order = np.argsort(dist)[:64]

        def f(x):
            d = centreline.derivatives(x)
            e = d[0, 0] - d[0, 1]
            return float(e @ e), np.array([2 * e @ d[1, 0], -2 * e @ d[1, 1]])

        for k in order:
            a0, b0 = L[pairs[k, 0]], L[pairs[k, 1]]
            bounds = [(a0 - h, a0 + h), (b0 - h, b0 + h)]
            if not centreline.closed:
                bounds = [(max(0.0, lo), min(Ltot, hi)) for lo, hi in bounds]
            res = minimize(f, np.array([a0, b0]), jac=True, method="L-BFGS-B", bounds=bounds)
            x = res.x if res.fun <= dist[k] ** 2 else np.array([a0, b0])
            d = math.sqrt(min(float(res.fun), float(dist[k]) ** 2))
            if sep(x[0], x[1]) > w and d < best.distance:
                la, lb = (x % Ltot if centreline.closed else x)
                best = Clearance(d, float(min(la, lb)), float(max(la, lb)), c, w)
    if raise_error and best.distance < c:
        raise InputError(f"{name}: the track comes within {best.distance:.4g} m of itself between L = "
                         f"{best.L_a:.6g} m and L = {best.L_b:.6g} m (clearance {c:g} m, neighbours within "
                         f"{w:.4g} m along the track excluded): it self-intersects within the gauge")
    return best


# ---------------------------------------------------------------------------------------------
# the shared circuit
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CircuitData:
    """Control points of a coaster circuit in SI units and right-handed axes.

    Attributes
    ----------
    points : (N, 3) ndarray
        Control points (m): x forward, y left, z up.
    roll : (N,) ndarray
        Roll (bank) angle about the forward direction (rad), right-handed (positive rolls the
        track's up vector towards -y, i.e. to the right when looking forward).
    section : (N,) ndarray of str
        Section names (Station, Lift, ...).
    index : (N,) int ndarray
        The file's ``idx`` column.
    path : Path
    """

    points: np.ndarray
    roll: np.ndarray
    section: np.ndarray
    index: np.ndarray
    path: Path


_COLUMNS = ["idx", "x", "y", "z", "roll_deg", "section", "terrain_z"]


def read_circuit(path=None, accept=()) -> CircuitData:
    """Read a coaster-sim track CSV (Unreal Engine units) into SI, right-handed axes.

    The file has columns ``idx,x,y,z,roll_deg,section,terrain_z`` in centimetres and degrees in
    Unreal Engine's left-handed axes (X forward, Y right, Z up).  The conversion
    (data/coaster/SOURCE.md) is::

        (x, y, z)_SI = (x, -y, z) / 100 m,     roll_SI = -roll_deg * pi/180 rad

    (mirroring y reverses the sense of every rotation).  ``terrain_z`` is ignored.

    Parameters
    ----------
    path : str or Path, optional
        Default :data:`CIRCUIT_FILE`.
    accept : sequence of str
        ``["control_point_spacing"]`` accepts a median point spacing outside the plausible range.

    Returns
    -------
    CircuitData

    Raises
    ------
    DataFileError
        Missing file, wrong header, a row with the wrong number of fields, a non-numeric or
        non-finite value, or ``idx`` not counting 0, 1, 2, ... (the message names the file,
        the data row and its line); a median point spacing outside the plausible control-point
        spacing (a file written in metres or millimetres instead of centimetres: the message
        names the likely unit).
    """
    path = Path(CIRCUIT_FILE if path is None else path)
    if not path.is_file():
        raise DataFileError(f"{path}: circuit file not found")
    pts, roll, sec, idx = [], [], [], []
    with path.open(newline="") as fh:
        rd = csv.reader(fh)
        header = next(rd, None)
        if header is None or [h.strip() for h in header] != _COLUMNS:
            raise DataFileError(f"{path}: line 1: header must be {','.join(_COLUMNS)}, got {header!r}")
        for row_no, row in enumerate(rd):
            line = row_no + 2
            if not row or all(not f.strip() for f in row):
                continue
            where = f"{path}: row {row_no} (line {line})"
            if len(row) != len(_COLUMNS):
                raise DataFileError(f"{where}: expected {len(_COLUMNS)} fields, got {len(row)}")
            try:
                vals = [float(row[k]) for k in (0, 1, 2, 3, 4)]
            except ValueError as exc:
                raise DataFileError(f"{where}: non-numeric value ({exc})") from None
            bad = [(_COLUMNS[k], v) for k, v in zip((0, 1, 2, 3, 4), vals) if not math.isfinite(v)]
            if bad:
                raise DataFileError(f"{where}: column {bad[0][0]} = {bad[0][1]!r} is not finite")
            if vals[0] != len(idx):
                raise DataFileError(f"{where}: idx = {row[0]!r}, expected {len(idx)}")
            idx.append(int(vals[0]))
            pts.append([vals[1] / 100.0, -vals[2] / 100.0, vals[3] / 100.0])
            roll.append(-math.radians(vals[4]))
            sec.append(row[5].strip())
    if len(idx) < 4:
        raise DataFileError(f"{path}: only {len(idx)} data rows, need at least 4")
    from .inputs import check

    P = np.array(pts)
    med_cm = 100.0 * float(np.median(np.linalg.norm(np.diff(P, axis=0), axis=1)))
    try:
        check("control_point_spacing", med_cm, unit="cm", accept=accept,
              where=f"{path}: columns x, y, z (centimetres by the format; median spacing of the points)")
    except InputError as exc:
        raise DataFileError(str(exc)) from None
    return CircuitData(np.array(pts), np.array(roll), np.array(sec), np.array(idx), path)


def circuit_centreline(data: CircuitData | None = None, kind="quintic", n_gauss=8):
    """Closed spline centreline through the circuit's control points.

    Parameters
    ----------
    data : CircuitData, optional
        Default: :func:`read_circuit` of the shared file.
    kind : str
        Spline kind of :class:`SplineCentreline` (quintic: C4, as a Frenet-locked body needs).

    Returns
    -------
    SplineCentreline
    """
    data = read_circuit() if data is None else data
    return SplineCentreline(data.points, kind=kind, closed=True, n_gauss=n_gauss,
                            name=f"circuit {data.path.name} ({kind})")


# ---------------------------------------------------------------------------------------------
# bank: check against the turns, design from the speed
# ---------------------------------------------------------------------------------------------
_EZ = np.array([0.0, 0.0, 1.0])
#: g used by the bank check and design when none is given (m/s²; coaster.train.G)
G_BANK = 9.81


def _vertical_frame(g1):
    """Horizontal lateral n_v = e_z x t/|e_z x t| (left) and v_v = t x n_v (up) at tangents g1 (N, 3)."""
    nv = np.cross(_EZ, g1)
    s = np.linalg.norm(nv, axis=1)
    if np.any(s < 1e-9):
        i = int(np.argmin(s))
        raise InputError(f"bank: the lateral direction is undefined on vertical track (sample {i})")
    nv /= s[:, None]
    return nv, np.cross(g1, nv)


def speed_from_energy(centreline: Centreline, L0: float, v0: float, gravity: float = G_BANK):
    """Speed along the track of a frictionless train released at ``L0`` with speed ``v0``.

    v(L) = sqrt(max(0, v0^2 + 2 g (z(L0) - z(L))))  (energy of a point mass on the centreline;
    0 where the train cannot get).  Returns a callable ``v(L)`` (m/s) for :func:`design_bank` and
    :func:`check_bank`.
    """
    L0, v0, gravity = float(L0), float(v0), float(gravity)
    z0 = float(centreline.derivatives([L0])[0, 0, 2])

    def v(L):
        z = centreline.derivatives(np.asarray(L, float))[0][:, 2]
        return np.sqrt(np.maximum(0.0, v0**2 + 2.0 * gravity * (z0 - z)))

    v.description = f"energy speed from v = {v0:g} m/s at L = {L0:g} m"
    return v


def _speed_samples(speed, L, centreline, where):
    """The speed (m/s) at arc lengths L from: None (1 everywhere: geometry only), a number, a
    callable v(L), an (L_i, v_i) pair of arrays, or a run with ``L`` and ``Ldot`` (lead wheelset)."""
    if speed is None:
        return np.ones_like(L)
    if callable(speed):
        v = np.asarray(speed(L), float).reshape(-1)
    elif hasattr(speed, "L") and hasattr(speed, "Ldot"):
        Ls = np.asarray(speed.L, float)[:, 0]
        vs = np.asarray(speed.Ldot, float)[:, 0]
        if centreline.closed:  # the first lap only (a later pass at another speed would interleave)
            first = Ls < Ls[0] + centreline.length
            Ls, vs = Ls[first], vs[first]
        v = _interp_speed(Ls, vs, L, centreline, where)
    elif isinstance(speed, tuple) and len(speed) == 2:
        v = _interp_speed(np.asarray(speed[0], float).reshape(-1), np.asarray(speed[1], float).reshape(-1), L,
                          centreline, where)
    else:
        from .inputs import check

        v = np.full(L.shape, float(check("track_speed", speed, where=f"{where}(speed=...)")))
    if v.shape != L.shape or not np.all(np.isfinite(v)):
        raise InputError(f"{where}: the speed must give one finite value per arc length (got shape {v.shape})")
    return np.abs(v)


def _interp_speed(Ls, vs, L, centreline, where):
    if Ls.shape != vs.shape or Ls.size < 2:
        raise InputError(f"{where}: speed samples (L_i, v_i) must be two arrays of equal length >= 2")
    length = float(centreline.length)
    if centreline.closed:
        Ls = np.mod(Ls, length)
    order = np.argsort(Ls, kind="stable")
    Ls, vs = Ls[order], vs[order]
    keep = np.concatenate([[True], np.diff(Ls) > 0])
    Ls, vs = Ls[keep], vs[keep]
    gaps = np.diff(np.concatenate([Ls, [Ls[0] + length]])) if centreline.closed else np.diff(Ls)
    ends = (Ls[0], length - Ls[-1]) if not centreline.closed else (0.0, 0.0)
    worst = max(float(np.max(gaps)), *ends)
    if worst > max(20.0, 0.1 * length):  # a few output steps or a station stop are bridged linearly
        raise InputError(f"{where}: the speed samples cover L = {Ls[0]:.6g} ... {Ls[-1]:.6g} m of the "
                         f"{length:.6g} m track with a gap of {worst:.4g} m: run over the whole track, or give "
                         f"the speed as a function (e.g. coaster.track.speed_from_energy)")
    if centreline.closed:
        return np.interp(np.mod(L, length), Ls, vs, period=length)
    return np.interp(L, Ls, vs)


def _samples(centreline, step):
    n = max(8, int(math.ceil(centreline.length / float(step))))
    return np.linspace(0.0, centreline.length, n, endpoint=not centreline.closed)


class BankCheck(NamedTuple):
    """Result of :func:`check_bank` (numbers measured on samples every ``step`` m).

    Attributes
    ----------
    outward_share : float
        Share of the lateral demand sum ``|v^2 kappa_h|`` carried where the bank tilts the riders
        outward (0: every turn banked inward; 1: every turn banked outward).
    n_turns, n_outward : int
        Turns (runs of one sign of kappa_h whose peak demand exceeds ``turn_level``) and those
        banked outward over most of their demand.
    lateral_rms_banked, lateral_rms_flat : float
        RMS of the quasi-static lateral load factor at the track f.n/g with the track's bank and
        with flat track (g), over the samples.
    lateral_max_banked, lateral_max_flat : float
        Largest ``|f.n|``/g with the bank and flat (g).
    turns : pandas.DataFrame
        One row per turn: ``L_start [m]``, ``L_end [m]``, ``direction``, ``peak v2k/g [g]``,
        ``mean bank [deg]``, ``outward share [-]``, ``banked``.
    """

    outward_share: float
    n_turns: int
    n_outward: int
    lateral_rms_banked: float
    lateral_rms_flat: float
    lateral_max_banked: float
    lateral_max_flat: float
    turns: object


@checked_options
def check_bank(frame, speed=None, *, step=1.0, gravity=G_BANK, turn_level=0.1, min_bank=math.radians(2.0),
               warn=True) -> BankCheck:
    r"""Compare the sign of a track's bank with the sign of its turns, weighted by v^2 kappa.

    At samples every ``step`` m: t = g', the horizontal lateral n_v = e_z x t/``|e_z x t|`` (left),
    v_v = t x n_v, the signed lateral curvature kappa_h = g''.n_v (> 0 turning left), the bank
    relative to the vertical phi = atan2(-b.n_v, b.v_v) of the frame's up axis b (> 0 rolls the
    up axis to the right, the convention of :func:`read_circuit`).  A bank tilts the riders
    *into* the turn when b leans towards the centre of curvature (phi kappa_h < 0) and *out of*
    it when phi kappa_h > 0.  Weights w = v^2 ``|kappa_h|`` (the lateral demand of flat track; with
    ``speed=None`` the curvature alone)::

        outward share = sum w [phi kappa_h > 0, |phi| > min_bank] / sum w

    The quasi-static lateral load factor at the track (no roll-rate terms, the rider on the
    centreline) is n_y = f.n/g with f = v^2 g'' + g e_z (the tangential part drops out), flat
    track n = n_v.

    Parameters
    ----------
    frame : core.curves.FramedCurve
        A framed track with a ``centreline`` (e.g. :class:`coaster.frames.RotationMinimisingFrame`).
    speed : None, float, callable, (L, v) arrays or a TrainRun
        Speed along the track (m/s): a run's lead speed, :func:`speed_from_energy`, or a constant.
    step : float
        Sample spacing (m).
    turn_level : float
        A turn is a run of one sign of kappa_h whose peak v^2 kappa_h/g exceeds this (g; with
        ``speed=None`` the threshold is on kappa_h in 1/m divided by 100).
    min_bank : float
        Banks smaller than this (rad) count as flat.
    warn : bool
        Issue :class:`coaster.inputs.OutwardBankWarning` when the outward share exceeds 1/2.

    Returns
    -------
    BankCheck

    Warns
    -----
    coaster.inputs.OutwardBankWarning
        Most of the lateral demand is on outward banking (the message gives the share, the turns
        and the RMS lateral loads with the bank and flat, and points to :func:`design_bank`).
    """
    import warnings

    import pandas as pd

    from .inputs import OutwardBankWarning

    cl = getattr(frame, "centreline", None)
    if cl is None:
        raise InputError(f"check_bank: {getattr(frame, 'name', frame)!r} has no centreline (give a framed track such "
                         f"as a RotationMinimisingFrame)")
    L = _samples(cl, step)
    d = cl.derivatives(L)
    v = _speed_samples(speed, L, cl, "check_bank")
    R = frame.evaluate(L).R
    nv, vv = _vertical_frame(d[1])
    b, n = R[:, :, 2], R[:, :, 1]
    phi = np.arctan2(-np.einsum("ij,ij->i", b, nv), np.einsum("ij,ij->i", b, vv))
    kh = np.einsum("ij,ij->i", d[2], nv)
    w = v**2 * np.abs(kh)
    outward = (phi * kh > 0) & (np.abs(phi) > min_bank)
    total = float(np.sum(w))
    share = float(np.sum(w[outward]) / total) if total > 0 else 0.0
    f = v[:, None] ** 2 * d[2] + gravity * _EZ
    ny_b = np.einsum("ij,ij->i", f, n) / gravity
    ny_f = np.einsum("ij,ij->i", f, nv) / gravity
    level = turn_level if speed is not None else turn_level / 100.0
    demand = w / gravity if speed is not None else np.abs(kh)
    rows = []
    sgn = np.sign(kh)
    i = 0
    while i < L.size:
        j = i
        while j + 1 < L.size and sgn[j + 1] == sgn[i]:
            j += 1
        if sgn[i] != 0 and float(np.max(demand[i:j + 1])) > level:
            ws = w[i:j + 1]
            out = float(np.sum(ws[outward[i:j + 1]]) / max(float(np.sum(ws)), 1e-300))
            rows.append({"L_start [m]": float(L[i]), "L_end [m]": float(L[j]),
                         "direction": "left" if sgn[i] > 0 else "right",
                         "peak v2k/g [g]": float(np.max(w[i:j + 1]) / gravity) if speed is not None else np.nan,
                         "mean bank [deg]": float(np.degrees(np.average(phi[i:j + 1], weights=ws + 1e-300))),
                         "outward share [-]": out, "banked": "outward" if out > 0.5 else "inward or flat"})
        i = j + 1
    turns = pd.DataFrame(rows, columns=["L_start [m]", "L_end [m]", "direction", "peak v2k/g [g]", "mean bank [deg]",
                                        "outward share [-]", "banked"])
    n_out = int(np.sum(turns["banked"] == "outward")) if len(turns) else 0
    res = BankCheck(share, len(turns), n_out, float(np.sqrt(np.mean(ny_b**2))), float(np.sqrt(np.mean(ny_f**2))),
                    float(np.max(np.abs(ny_b))), float(np.max(np.abs(ny_f))), turns)
    if warn and share > 0.5:
        name = getattr(frame, "name", "track")
        warnings.warn(OutwardBankWarning(
            f"{name}: the bank tilts the riders out of the turns for {100 * share:.0f} % of the lateral demand "
            f"v^2 kappa ({n_out} of {len(turns)} turns banked outward); quasi-static lateral load at the track RMS "
            f"{res.lateral_rms_banked:.3g} g (max {res.lateral_max_banked:.3g} g) with this bank against "
            f"{res.lateral_rms_flat:.3g} g (max {res.lateral_max_flat:.3g} g) on flat track: is the roll sign flipped "
            f"(left-handed data)? coaster.track.design_bank designs a bank from the speed"), stacklevel=2)
    return res


@checked_options
def design_bank(centreline: Centreline, speed, *, step=2.0, gravity=G_BANK, min_vertical=1.0, smooth=10.0, name=None):
    r"""A bank (roll relative to the vertical) that cancels the quasi-static lateral load.

    The coaster designer's rule, roll = atan(v^2 kappa / g), in the general form for a track
    with grade and vertical curvature: the specific force on a rider moving at speed v on the
    centreline is f = a - g_vec = v' t + v^2 g'' + g e_z; its part normal to the track,
    f_perp = v^2 g'' + g (e_z - (e_z.t) t), lies in the plane of the up axis b and the lateral
    axis n; the lateral load f.n vanishes when b is parallel to f_perp.  With the horizontal
    lateral n_v = e_z x t/``|e_z x t|`` and v_v = t x n_v (f_perp.n_v = v^2 kappa_h,
    f_perp.v_v = v^2 kappa_v + g cos(gamma), kappa_h = g''.n_v, kappa_v = g''.v_v, gamma the
    grade)::

        phi(L) = atan2(-v^2 kappa_h, max(v^2 kappa_v + g cos(gamma), min_vertical g))

    (positive phi rolls the up axis to the right, as :func:`read_circuit`; on a level turn
    phi = -atan(v^2 kappa_h/g), the rider tilted into the turn by tan(beta) = v^2/(g R)).  The
    floor ``min_vertical`` (default 1 g: the designer's atan(v^2 kappa / g) over crests) keeps
    the bank moderate where the vertical load falls towards zero: on the circuit, a crest taken
    at 36 m/s with -0.2 g in a 530 m bend would otherwise get 51 deg of bank within 20 m (with a
    floor of 0.2 g the rider's lateral load spiked to 12 g from the roll acceleration).  The
    samples are then averaged over ``smooth`` m (centred moving average, a designer's roll
    spiral that bounds the roll acceleration v^2 phi'').  The design is on the track centreline
    (the rider's heartline taken as the centreline: a rider h above the track in a turn of
    radius R keeps a lateral load of order q h/R, q = v^2/(g R)).

    Parameters
    ----------
    centreline : Centreline
    speed : float, callable, (L, v) arrays or a TrainRun
        Speed along the track (m/s): a run's lead speed (the run must cover the track), a
        callable v(L) such as :func:`speed_from_energy`, or a constant.
    step : float
        Spacing of the bank samples (m); the bank is the quintic spline through them
        (:meth:`coaster.frames.Bank.from_samples`, periodic on a closed track).
    gravity : float
        g (m/s²).
    min_vertical : float
        Floor of the vertical load factor in the rule (g), 0 < min_vertical <= 1.
    smooth : float
        Length of the moving average of the bank samples (m); 0 for none.

    Returns
    -------
    coaster.frames.Bank
        phi(L) relative to the vertical: use it as
        ``RotationMinimisingFrame(centreline, bank=b, bank_reference="vertical")``.  Its
        ``samples`` attribute holds the (L, phi) samples.

    References
    ----------
    notes/coaster.md "Closed forms": banked horizontal circle, tan(beta) = q is the perfect bank.
    """
    from .frames import Bank

    if speed is None:
        raise InputError("design_bank: a speed is needed (a run, speed_from_energy(...), or a number in m/s)")
    if not (0.0 < float(min_vertical) <= 1.0):
        raise InputError(f"design_bank: min_vertical must be in (0, 1] g, got {min_vertical!r}")
    if not (np.isfinite(smooth) and smooth >= 0):
        raise InputError(f"design_bank: smooth must be a length >= 0 (m), got {smooth!r}")
    L = _samples(centreline, step)
    d = centreline.derivatives(L)
    v = _speed_samples(speed, L, centreline, "design_bank")
    nv, vv = _vertical_frame(d[1])
    kh = np.einsum("ij,ij->i", d[2], nv)
    kv = np.einsum("ij,ij->i", d[2], vv)
    cos_grade = np.linalg.norm(np.cross(_EZ, d[1]), axis=1)
    den = np.maximum(v**2 * kv + gravity * cos_grade, float(min_vertical) * gravity)
    phi = np.arctan2(-(v**2) * kh, den)
    if smooth > 0:  # centred moving average over `smooth` metres (periodic on a closed track)
        m = max(1, int(round(float(smooth) / (L[1] - L[0]))))
        if m > 1:
            k = np.ones(m) / m
            if centreline.closed:
                ext = np.concatenate([phi[-m:], phi, phi[:m]])
                phi = np.convolve(ext, k, mode="same")[m:-m]
            else:
                ext = np.concatenate([np.full(m, phi[0]), phi, np.full(m, phi[-1])])
                phi = np.convolve(ext, k, mode="same")[m:-m]
    bank = Bank.from_samples(L, phi, closed=centreline.closed, length=centreline.length if centreline.closed else None)
    bank.name = name or f"designed bank of {centreline.name} (roll = atan(v^2 kappa / g))"
    bank.samples = (L, phi)
    bank.reference = "vertical"
    return bank
