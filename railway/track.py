"""Track centreline, moving track frame and rail mounting.

Centreline and frame
--------------------
The design centreline is parameterised by its arc length s (m) and built from straights,
circular curves and clothoid transitions.  Horizontal curvature kappa(s) is constant on straights
(0) and curves (1/R, R > 0 for a curve to the left) and linear in s on a clothoid; the cant
(superelevation) angle phi(s) is constant on curves and linear on transitions::

    psi(s) = psi_0 + int kappa ds                (heading, exact: piecewise quadratic)
    X(s) = X_0 + int cos psi ds,  Y(s) = Y_0 + int sin psi ds   (Gauss-Legendre per interval)
    phi = -sign(kappa) asin(h / b0)               (h cant height of the outer rail, b0 = 1.5 m)

The track frame R = [t, n, b] (columns: tangent, lateral to the left, up) is the heading
rotation followed by the cant roll about t::

    R = Rz(psi) Rx(phi),   t = (c_psi, s_psi, 0),  n = (-s_psi c_phi, c_psi c_phi, s_phi),
    b = (s_psi s_phi, -c_psi s_phi, c_phi)
    dR/ds = [omega]x R,    omega = psi' e_z + phi' t     (Darboux vector)

Optional irregularities y_i(s) (lateral alignment) and z_i(s) (vertical level) from a table,
interpolated by a C2 cubic spline, displace the centreline in the frame::

    r(s) = (X, Y, 0) + y_i n + z_i b
    r'(s) = (X', Y', 0) + y_i' n + z_i' b + omega x (y_i n + z_i b)

s stays the arc length of the design line (irregularities are small; the usual convention of
vehicle-dynamics codes).  psi, phi, X, Y and the irregularities are stored as one vector-valued
piecewise quintic Hermite polynomial (exact for psi, phi and the cubic irregularity spline) and
evaluated with their first and second derivatives in one vectorised call; ``Track.evaluate``
assembles the frame from them exactly (R orthonormal to round-off).

The fast path of the contact search (``Track.evaluate_raw``) uses the frame table of
:class:`core.curves.TabulatedFramedCurve`: r, R and omega as quintic Hermite pieces from their
exact values and first two derivatives (r', r'', omega', omega'' from the formulas above and
below, one-sided at segment joints) at both ends of every interval.  ``Track`` is a
:class:`core.curves.FramedCurve`, the interface it shares with other domains.  The derivatives
of the Darboux vector that the table needs are::

    omega' = (phi'' c_psi - phi' s_psi kappa, phi'' s_psi + phi' c_psi kappa, kappa')
    omega'' = (-2 phi'' s_psi kappa - phi' (c_psi kappa^2 + s_psi kappa'),
               2 phi'' c_psi kappa + phi' (-s_psi kappa^2 + c_psi kappa'), 0)
    (phi and kappa linear in s inside a segment, so phi''' = kappa'' = 0)

Rail mounting
-------------
A rail profile v(u) (u > 0 field side, v up) is inclined by alpha = atan(inclination) towards the
track centre and placed so that its highest point is at z = 0 of the track frame and its gauge
point (the gauge-side point ``gauge_depth`` = 14 mm below the highest point) is at lateral
distance gauge/2 from the centreline.  In the outward lateral coordinate Yo (= sigma y, sigma =
+1 left rail, -1 right rail) and height Z::

    Yo(u) = Y0 + u cos(alpha) - v(u) sin(alpha),   Z(u) = Z0 + u sin(alpha) + v(u) cos(alpha)

References
----------
Pombo, J. and Ambrosio, J. (2003). General spatial curve joint for rail guided vehicles:
kinematics and dynamics. Multibody System Dynamics 9(3):237-264 (moving track frame).
EN 13848-1:2019, Track geometry quality (gauge measured 14 mm below the running surface).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from core.curves import (
    CurveFrame,
    FramedCurve,
    PiecewisePoly,
    TabulatedFramedCurve,
    quintic_hermite_coeffs,
)
from core.errors import DataRangeError, InputError


__all__ = [
    "Curve",
    "Irregularities",
    "RailMounting",
    "Straight",
    "Track",
    "TrackFrame",
    "Transition",
    "parse_inclination",
]


def _parse_segment(seg, names):
    """Numbers in m, or strings with a unit (``Curve("200 m", "1.2 km", cant="150 mm")``),
    converted to floats; the ranges are checked by :class:`Track` (naming the segment)."""
    from core.inputs import parse_quantity

    for name in names:
        raw = getattr(seg, name)
        if isinstance(raw, (float, int)) and not isinstance(raw, bool):
            object.__setattr__(seg, name, float(raw))
            continue
        object.__setattr__(seg, name, float(parse_quantity(raw, "m", where=f"{type(seg).__name__}({name}=...)")))


@dataclass(frozen=True)
class Straight:
    """Straight track of ``length`` (m; a number in m or a string with a unit)."""

    length: float

    def __post_init__(self):
        _parse_segment(self, ("length",))


@dataclass(frozen=True)
class Curve:
    """Circular curve: ``radius`` (m, > 0 turns left, < 0 right), cant height ``cant`` (m).

    Numbers are in m; strings carry a unit (``Curve("200 m", "1.2 km", cant="150 mm")``).
    :class:`Track` checks the radius (magnitude), cant and length against their plausible
    ranges (``data/railway/plausible_ranges.csv``: curve_radius, cant, track_segment_length).
    """

    length: float
    radius: float
    cant: float = 0.0

    def __post_init__(self):
        _parse_segment(self, ("length", "radius", "cant"))


@dataclass(frozen=True)
class Transition:
    """Clothoid transition: curvature and cant change linearly between its neighbours; its
    ``length`` (m) is checked by :class:`Track` against the plausible range transition_length."""

    length: float

    def __post_init__(self):
        _parse_segment(self, ("length",))


@dataclass
class Irregularities:
    """Lateral (alignment) and vertical (level) centreline irregularities y_i(s), z_i(s) (m).

    Zero outside [s[0], s[-1]]; the table should start and end at zero (else an
    :class:`railway.ranges.IrregularityStepWarning`: the centreline steps there).  The
    amplitudes and the arc-length step are checked against their plausible ranges
    (irregularity_amplitude, irregularity_sample_spacing in ``data/railway/plausible_ranges.csv``),
    so that millimetres given as metres are refused with the slip named; ``accept`` waives a
    range, ``source`` names the table in messages.
    """

    s: np.ndarray
    lateral: np.ndarray
    vertical: np.ndarray
    source: str = "irregularities"
    accept: tuple = ()

    def __post_init__(self):
        src = self.source
        cols = {}
        for name in ("s", "lateral", "vertical"):
            raw = getattr(self, name)
            try:
                a = np.asarray(raw, dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"{src}: column {name} must be numbers in m, got {raw!r:.60}") from None
            cols[name] = a
        self.s, self.lateral, self.vertical = cols["s"], cols["lateral"], cols["vertical"]
        for name, a in (("s", self.s), ("lateral", self.lateral), ("vertical", self.vertical)):
            if a.ndim != 1 or a.size != self.s.size:
                raise InputError(f"{src}: column {name} must be 1-D of length {self.s.size}, got shape {a.shape}")
            bad = ~np.isfinite(a)
            if np.any(bad):
                i = int(np.argmax(bad))
                raise InputError(f"{src}: {name}[{i}] = {a[i]!r} is not finite")
        if self.s.size < 4:
            raise InputError(f"{src}: at least 4 rows are needed, got {self.s.size}")
        d = np.diff(self.s)
        if np.any(d <= 0):
            i = int(np.argmax(d <= 0)) + 1
            raise InputError(f"{src}: s must increase strictly; s[{i}] = {self.s[i]!r}")
        from .ranges import IrregularityStepWarning, ranges

        R = ranges()
        acc = [self.accept] if isinstance(self.accept, str) else list(self.accept)
        units = getattr(self, "_units", {})
        for name, a, q in (("s step", d, "irregularity_sample_spacing"),
                           ("lateral", self.lateral, "irregularity_amplitude"),
                           ("vertical", self.vertical, "irregularity_amplitude")):
            r = R[q]
            out = ~((a >= r.low) & (a <= r.high))
            if q in acc or not np.any(out):
                continue
            i = int(np.argmax(np.where(out, np.abs(a), -1.0)))  # the largest value out of range
            col = name.split()[0]
            unit = units.get(col, "m")
            head = f" (column '{col} [{unit}]')" if units else ""
            written = float(a[i]) * (1e3 if unit == "mm" else 1.0)  # the number as written
            R.check(q, written, unit=unit, where=f"{src}{head} {name}[{i}]", accept=acc)
        for name, a in (("lateral", self.lateral), ("vertical", self.vertical)):
            ends = [(k, a[k]) for k in (0, -1) if abs(a[k]) > 1e-4]
            if ends:
                k, v = ends[0]
                warnings.warn(f"{src}: {name} irregularity is {v * 1e3:.3g} mm at s = {self.s[k]:g} m, the "
                              f"{'start' if k == 0 else 'end'} of the table (zero outside it): the centreline "
                              f"steps by that much there; taper the table to zero",
                              IrregularityStepWarning, stacklevel=3)
                break  # one warning per table

    @classmethod
    def from_csv(cls, path, accept=()):
        """Read columns ``s [m]``, ``lateral [m]``, ``vertical [m]`` (header required; columns
        in mm named ``s [mm]``, ``lateral [mm]``, ``vertical [mm]`` are converted).  Values
        outside the plausible amplitudes are refused naming the column's header and the likely
        slip (mm written under a header in m); ``accept`` waives a range."""
        import pandas as pd
        from core.errors import DataFileError

        try:
            df = pd.read_csv(path)
        except FileNotFoundError:
            raise DataFileError(f"irregularity file {path} does not exist") from None
        except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
            raise DataFileError(f"irregularity file {path}: not a CSV table ({str(exc).strip()[:100]})") from None
        cols = {c.strip().lower(): c for c in df.columns}
        units = {}

        def col(base):
            for unit, f in (("m", 1.0), ("mm", 1e-3)):
                key = f"{base} [{unit}]"
                if key in cols:
                    units[base] = unit
                    try:
                        return pd.to_numeric(df[cols[key]], errors="raise").to_numpy(float) * f
                    except (ValueError, TypeError):
                        bad = pd.to_numeric(df[cols[key]], errors="coerce").isna().to_numpy()
                        i = int(np.argmax(bad))
                        raise DataFileError(f"{path}: column '{cols[key]}' row {i + 1}: "
                                            f"{df[cols[key]].iloc[i]!r} is not a number") from None
            unitless = [c for c in df.columns if c.strip().lower() == base]
            hint = (f"; column '{unitless[0]}' has no unit: name it '{base} [m]' or '{base} [mm]'"
                    if unitless else "")
            from core.inputs import closest

            hint = hint or closest(f"{base} [m]", list(df.columns))
            raise DataFileError(f"{path}: missing column '{base} [m]' (or [mm]){hint}; found {list(df.columns)}")

        s, lat, ver = col("s"), col("lateral"), col("vertical")
        obj = cls.__new__(cls)
        obj.s, obj.lateral, obj.vertical, obj.source, obj.accept = s, lat, ver, str(path), tuple(accept)
        obj._units = units
        obj.__post_init__()
        return obj


@dataclass
class TrackFrame(CurveFrame):
    """Track frame and derivatives at arc lengths s (arrays over N points).

    A :class:`core.curves.CurveFrame` (r, r', r'', R = [t, n, b], omega, omega') with the
    railway quantities of the design line; the normal n is the lateral direction (to the left)
    and the binormal b is up.

    Attributes
    ----------
    position, dposition, ddposition : (N, 3) ndarray
        Centreline r(s) (m), r'(s) (-), r''(s) (1/m).
    R : (N, 3, 3) ndarray
        Columns tangent t, lateral n (left), up b.
    omega, domega : (N, 3) ndarray
        Darboux vector (1/m) with dR/ds = [omega]x R, and its derivative (1/m^2).
    curvature, cant_angle, heading : (N,) ndarray
        kappa (1/m), phi (rad), psi (rad).
    """

    curvature: np.ndarray
    cant_angle: np.ndarray
    heading: np.ndarray

    @property
    def lateral(self):
        """Lateral direction n (to the left), (N, 3); the frame's normal."""
        return self.R[:, :, 1]

    @property
    def up(self):
        """Up direction b, (N, 3); the frame's binormal."""
        return self.R[:, :, 2]


_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_I1, _I2 = np.array([1, 2, 0]), np.array([2, 0, 1])


def _cross(a, b):
    """Cross product of (..., 3) arrays (cheaper than np.cross for small arrays)."""
    return a[..., _I1] * b[..., _I2] - a[..., _I2] * b[..., _I1]


class Track(FramedCurve):
    """Track centreline from segments, with cant and optional irregularities.

    A :class:`core.curves.FramedCurve`: ``evaluate`` assembles the frame exactly from the
    heading, cant and irregularity table (module docstring) and returns a :class:`TrackFrame`;
    ``evaluate_raw`` is the fast path of the frame table ``frame_table``
    (:class:`core.curves.TabulatedFramedCurve`).

    Parameters
    ----------
    segments : sequence of Straight, Curve, Transition
    cant_base : float
        Distance between the rail running circles used to turn cant height into an angle (m).
    irregularities : Irregularities, optional
    max_step : float
        Largest interval of the internal piecewise-polynomial table (m).
    origin : (3,) array_like, heading : float
        Start point (m) and heading (rad) of the centreline.
    accept : sequence of str
        Quantities whose plausible range is not enforced (curve_radius, cant, transition_length,
        track_segment_length, cant_base; ``data/railway/plausible_ranges.csv``).

    Attributes
    ----------
    length : float
        Length of the design line (m); s runs from 0 to ``length``.
    s_joints : (n_segments + 1,) ndarray
        Arc lengths of the segment ends (m).
    pp : PiecewisePoly
        Base table of (psi, phi, X, Y, y_i, z_i).
    frame_table : TabulatedFramedCurve
        Frame table of r, R and omega over the same node grid.
    """

    name = "track"
    closed = False

    def __init__(self, segments, cant_base=1.5, irregularities=None, max_step=2.0,
                 origin=(0.0, 0.0, 0.0), heading=0.0, accept=()):
        segments = list(segments)
        if irregularities is not None and not isinstance(irregularities, Irregularities):
            raise InputError(f"track: irregularities must be an Irregularities table (Irregularities(s, "
                             f"lateral, vertical) or Irregularities.from_csv(path)), got {type(irregularities).__name__}")
        if not segments:
            raise InputError("track: at least one segment is needed")
        for i, seg in enumerate(segments):
            if not isinstance(seg, (Straight, Curve, Transition)):
                raise InputError(f"track: segment {i} is {seg!r}, not Straight/Curve/Transition")
            if not (np.isfinite(seg.length) and seg.length > 0):
                raise InputError(f"track: segment {i} length {seg.length!r} must be positive")
            if isinstance(seg, Curve):
                if not (np.isfinite(seg.radius) and seg.radius != 0):
                    raise InputError(f"track: segment {i} radius {seg.radius!r} must be finite, non-zero")
                if not (np.isfinite(seg.cant) and 0.0 <= seg.cant < cant_base):
                    raise InputError(f"track: segment {i} cant {seg.cant!r} m must be in [0, {cant_base})"
                                     + (": the cant is the height of the outer rail (>= 0), the direction of "
                                        "the curve the sign of the radius" if seg.cant < 0 else
                                        f": did you mean {seg.cant:g} mm?" if seg.cant >= 1 else ""))
        self._check_ranges(segments, cant_base, accept)
        self.segments = segments
        self.cant_base = float(cant_base)
        self.irregularities = irregularities
        # curvature and cant at segment ends
        n = len(segments)
        k_c = [1.0 / s.radius if isinstance(s, Curve) else 0.0 for s in segments]
        p_c = [-np.sign(1.0 / s.radius) * np.arcsin(s.cant / cant_base) if isinstance(s, Curve)
               else 0.0 for s in segments]
        k0, k1, p0, p1 = (np.zeros(n) for _ in range(4))
        for i, seg in enumerate(segments):
            if isinstance(seg, Transition):
                k0[i] = k_c[i - 1] if i > 0 and not isinstance(segments[i - 1], Transition) else 0.0
                k1[i] = k_c[i + 1] if i + 1 < n and not isinstance(segments[i + 1], Transition) else 0.0
                p0[i] = p_c[i - 1] if i > 0 and not isinstance(segments[i - 1], Transition) else 0.0
                p1[i] = p_c[i + 1] if i + 1 < n and not isinstance(segments[i + 1], Transition) else 0.0
            else:
                k0[i] = k1[i] = k_c[i]
                p0[i] = p1[i] = p_c[i]
        L = np.array([s.length for s in segments], dtype=float)
        s0 = np.concatenate([[0.0], np.cumsum(L)])
        self.s_joints = s0
        self.length = float(s0[-1])
        psi0 = np.zeros(n)
        psi0[0] = heading
        for i in range(1, n):
            psi0[i] = psi0[i - 1] + 0.5 * (k0[i - 1] + k1[i - 1]) * L[i - 1]
        self._seg = dict(s0=s0[:-1], L=L, k0=k0, k1=k1, p0=p0, p1=p1, psi0=psi0)
        # node grid: segment grids plus irregularity knots
        nodes = [np.linspace(s0[i], s0[i + 1], max(2, int(np.ceil(L[i] / max_step)) + 1))
                 for i in range(n)]
        grid = np.unique(np.concatenate(nodes))
        spline = None
        if irregularities is not None:
            from scipy.interpolate import CubicSpline

            ir = irregularities
            spline = CubicSpline(ir.s, np.column_stack([ir.lateral, ir.vertical]), bc_type="natural")
            knots = ir.s[(ir.s > 0.0) & (ir.s < self.length)]
            grid = np.unique(np.concatenate([grid, knots]))
        self._spline = spline
        self._build(grid, origin)

    @staticmethod
    def _check_ranges(segments, cant_base, accept):
        """Plausible ranges of the segments (``data/railway/plausible_ranges.csv``) and of the cant
        base; ``accept`` waives a quantity (e.g. ``accept=["curve_radius"]``)."""
        from .ranges import ranges

        R = ranges()
        accept = [accept] if isinstance(accept, str) else list(accept)
        R.check("cant_base", cant_base, where="track: cant_base", accept=accept)
        for i, seg in enumerate(segments):
            kind = type(seg).__name__
            where = f"track: segment {i} ({kind})"
            R.check("transition_length" if kind == "Transition" else "track_segment_length", seg.length,
                    where=f"{where} length", accept=accept)
            if kind == "Curve":
                R.check("curve_radius", abs(seg.radius), where=f"{where} radius", accept=accept)
                R.check("cant", seg.cant, where=f"{where} cant", accept=accept)

    @classmethod
    def straight(cls, length=1000.0, **kw):
        """A straight track of ``length`` (m)."""
        return cls([Straight(length)], **kw)

    # -- segment formulas ---------------------------------------------------------------
    def _seg_index(self, s, owner=None):
        sj = self.s_joints
        x = s if owner is None else owner
        return np.clip(np.searchsorted(sj, x, side="right") - 1, 0, len(self.segments) - 1)

    def _exact_heading(self, s, i):
        g = self._seg
        x = s - g["s0"][i]
        dk = (g["k1"][i] - g["k0"][i]) / g["L"][i]
        psi = g["psi0"][i] + g["k0"][i] * x + 0.5 * dk * x**2
        kap = g["k0"][i] + dk * x
        dp = (g["p1"][i] - g["p0"][i]) / g["L"][i]
        phi = g["p0"][i] + dp * x
        return psi, kap, dk + 0 * x, phi, dp + 0 * x

    def _irr(self, s):
        """(y_i, z_i) with first and second derivatives, zero outside the table."""
        out = np.zeros((3, s.size, 2))
        if self._spline is None:
            return out
        ir = self.irregularities
        m = (s >= ir.s[0]) & (s <= ir.s[-1])
        for k in range(3):
            out[k, m] = self._spline(s[m], k)
        return out

    def _build(self, grid, origin):
        a, b = grid[:-1], grid[1:]
        mid = 0.5 * (a + b)
        seg = self._seg_index(None, owner=mid)
        h = b - a
        # positions at nodes by Gauss-Legendre integration of (cos psi, sin psi) per interval
        sq = mid[:, None] + 0.5 * h[:, None] * _GL_X[None, :]
        psi_q = self._exact_heading(sq, seg[:, None])[0]
        dX = 0.5 * h * (np.cos(psi_q) @ _GL_W)
        dY = 0.5 * h * (np.sin(psi_q) @ _GL_W)
        X = origin[0] + np.concatenate([[0.0], np.cumsum(dX)])
        Y = origin[1] + np.concatenate([[0.0], np.cumsum(dY)])
        self._z0 = float(origin[2])

        def ends(sv, XY):
            psi, kap, dk, phi, dp = self._exact_heading(sv, seg)
            c, s_ = np.cos(psi), np.sin(psi)
            f = np.column_stack([psi, phi, XY[0], XY[1]])
            d1 = np.column_stack([kap, dp, c, s_])
            d2 = np.column_stack([dk, 0 * dp, -kap * s_, kap * c])
            return f, d1, d2

        fa, da, dda = ends(a, (X[:-1], Y[:-1]))
        fb, db, ddb = ends(b, (X[1:], Y[1:]))
        ia, ib = self._irr(a), self._irr(b)
        fa = np.column_stack([fa, ia[0]]); da = np.column_stack([da, ia[1]])
        dda = np.column_stack([dda, ia[2]])
        fb = np.column_stack([fb, ib[0]]); db = np.column_stack([db, ib[1]])
        ddb = np.column_stack([ddb, ib[2]])
        c = quintic_hermite_coeffs(h[:, None], fa, da, dda, fb, db, ddb)  # (n, 6 comps, 6)
        self.pp = PiecewisePoly(grid, np.transpose(c, (0, 2, 1)))
        # frame table for the contact search: r, R and omega as quintic Hermite pieces from
        # their exact values and first two derivatives at both ends of every interval (one-sided
        # at segment joints), so that one evaluation gives r, r', r'', R, omega and omega'
        idx = np.arange(h.size)
        frames = []
        for t in (np.zeros_like(h), h):
            pos, dpos, ddpos, R, om, dom, ddom = self._assemble(self.pp.eval_piece(idx, t), True)
            frames.append(CurveFrame(pos, dpos, ddpos, R, om, dom, ddomega=ddom))
        self.frame_table = TabulatedFramedCurve(grid, *frames, name=self.name)

    @property
    def pp_frame(self) -> PiecewisePoly:
        """The frame table's piecewise polynomial (layout in :class:`TabulatedFramedCurve`)."""
        return self.frame_table.table

    # -- evaluation ---------------------------------------------------------------------
    #: arc length (m) by which an evaluation may pass an end of an open track as round-off
    END_TOLERANCE = 1e-9

    def evaluate(self, s, extrapolate=False) -> TrackFrame:
        """Track frame and derivatives at arc lengths s (m), any 1-D array.

        Assembled exactly from the base table (R orthonormal to round-off).

        Parameters
        ----------
        s : float or array_like
            Arc lengths (m), within [0, ``length``] of an open track.
        extrapolate : bool
            For internal callers that look a little past an end on purpose (a search seed, a
            placement or a projection with a margin): continue the track with its end pieces.

        Raises
        ------
        core.errors.InputError
            A non-finite arc length (named).
        core.errors.DataRangeError
            An arc length beyond the ends of an open track (the end and s named); raised during
            a run it ends the run as failed, keeping what was computed.
        """
        s = np.atleast_1d(np.asarray(s, dtype=float)).reshape(-1)
        if not (extrapolate or self.closed):
            tol = self.END_TOLERANCE * max(1.0, self.length)
            with np.errstate(invalid="ignore"):
                out = (s < -tol) | (s > self.length + tol)
            if np.any(out):
                i = int(np.argmax(out))
                end = ("before its start at s = 0 m" if s[i] < 0 else f"beyond its end at s = {self.length:g} m")
                raise DataRangeError(f"{self.name}: evaluated at s[{i}] = {float(s[i]):g} m, {end}: the track "
                                     f"is open (0 <= s <= {self.length:g} m) and is not extrapolated; make it "
                                     "longer or keep the vehicle on it")
        return super().evaluate(s)

    def _evaluate(self, s):
        return self._frame(s, second=True)

    def _frame(self, s, second=False):
        out = self._assemble(self.pp.eval_raw(s), False)
        pos, dpos, ddpos, R, om, dom = out
        if not second:
            return pos, dpos, R, om
        if second == "raw":
            return pos, dpos, ddpos, R, om, dom
        o = self.pp.eval_raw(s)
        return TrackFrame(pos, dpos, ddpos, R, om, dom, o[:, 6], o[:, 1], o[:, 0])

    def evaluate_raw(self, s):
        """(r, r', r'', R, omega, omega') from the frame table (one vectorised evaluation).

        R is interpolated (quintic Hermite of its exact values and derivatives): orthonormal to
        round-off for the interval lengths used (<= max_step).  See
        :meth:`core.curves.TabulatedFramedCurve.evaluate_raw`.
        """
        return self.frame_table.evaluate_raw(s)

    _frame_fast = evaluate_raw  # name used by railway.contact.search

    def _assemble(self, o, third):
        """Frame quantities from raw (value, d1, d2) rows of the base table."""
        psi, phi, X, Y, yi, zi = o[:, 0], o[:, 1], o[:, 2], o[:, 3], o[:, 4], o[:, 5]
        kap, dphi, dX, dY, dyi, dzi = (o[:, 6 + k] for k in range(6))
        dkap, ddphi, ddX, ddY, ddyi, ddzi = (o[:, 12 + k] for k in range(6))
        cp, sp, cf, sf = np.cos(psi), np.sin(psi), np.cos(phi), np.sin(phi)
        z = np.zeros_like(psi)
        t = np.stack([cp, sp, z], axis=1)
        n = np.stack([-sp * cf, cp * cf, sf], axis=1)
        bb = np.stack([sp * sf, -cp * sf, cf], axis=1)
        R = np.stack([t, n, bb], axis=2)
        om = np.stack([dphi * cp, dphi * sp, kap], axis=1)
        off = yi[:, None] * n + zi[:, None] * bb
        pos = np.stack([X, Y, z + self._z0], axis=1) + off
        doff_local = dyi[:, None] * n + dzi[:, None] * bb
        dpos = np.stack([dX, dY, z], axis=1) + doff_local + _cross(om, off)
        dom = np.stack([ddphi * cp - dphi * sp * kap, ddphi * sp + dphi * cp * kap, dkap], axis=1)
        ddpos = (np.stack([ddX, ddY, z], axis=1) + ddyi[:, None] * n + ddzi[:, None] * bb
                 + 2.0 * _cross(om, doff_local) + _cross(dom, off)
                 + _cross(om, _cross(om, off)))
        if not third:
            return pos, dpos, ddpos, R, om, dom
        # second derivative of omega; phi and kappa are linear in s inside a segment
        ddom = np.stack([-2 * ddphi * sp * kap - dphi * (cp * kap**2 + sp * dkap),
                         2 * ddphi * cp * kap + dphi * (-sp * kap**2 + cp * dkap), z], axis=1)
        return pos, dpos, ddpos, R, om, dom, ddom


def parse_inclination(value):
    """Rail inclination as tan(alpha) >= 0 from 0.025, "1:40", "1/40", "1:20" or "vertical".

    A negative value (rail tilted away from the track centre) is rejected.
    """
    given = value
    if isinstance(value, str):
        v = value.strip().lower()
        if v in ("vertical", "0", "none"):
            return 0.0
        if ":" in v or "/" in v:
            num, den = v.split(":" if ":" in v else "/", 1)
            try:
                value = float(num) / float(den)
            except (ValueError, ZeroDivisionError):
                raise InputError(f"rail inclination {value!r}: expected e.g. '1:40'") from None
        else:
            try:
                value = float(v)
            except ValueError:
                raise InputError(f"rail inclination {value!r}: expected e.g. '1:40', 0.025 or 'vertical'") from None
    value = float(value)
    if not np.isfinite(value):
        raise InputError(f"rail inclination {value!r} is not finite")
    if value < 0.0:
        raise InputError(
            f"rail inclination {value!r}"
            + (f" (given as {given!r})" if isinstance(given, str) else "")
            + " is negative: rails are inclined towards the track "
            "centre, give tan(alpha) >= 0 (e.g. 1/40 = 0.025)")
    if value > 0.2:
        hint = (f": did you mean '1:{value:g}' (= {1 / value:.4g})?" if value >= 5 else
                f": did you mean {value:g} degrees (tan = {np.tan(np.radians(value)):.4g})?" if value <= 5 else "")
        raise InputError(f"rail inclination {value!r}"
                         + (f" (given as {given!r})" if isinstance(given, str) else "")
                         + f" is implausibly large (tan alpha > 0.2){hint}")
    return value


class RailMounting:
    """A rail profile inclined towards the track centre and placed at the given gauge.

    Parameters
    ----------
    profile : RailProfile, optional
        Default UIC60.
    gauge : float
        Track gauge (m) between the gauge points, default 1.435.
    inclination : float or str
        tan(alpha) towards the track centre (1/40 default, "1:20", "vertical").
    gauge_depth : float
        Depth of the gauge point below the top of rail (m), default 0.014.
    accept : sequence of str
        Quantities whose plausible range is not enforced: ``["gauge"]`` for a gauge outside the
        ``gauge`` row of ``data/railway/plausible_ranges.csv`` (a deliberate outlier).

    Attributes
    ----------
    Y0, Z0 : float
        Offsets of the profile origin (rail axis at the crown) in (Yo, Z) (m).
    u_min, u_max : float
        Profile range usable for contact (the mounted profile is a graph over Yo there).
    u_gauge : float
        Profile coordinate of the gauge point.
    """

    def __init__(self, profile=None, gauge=1.435, inclination=1 / 40, gauge_depth=0.014, accept=()):
        # the rail profile is contact mechanics: imported here, when a rail is mounted, so that this
        # module, which both halves import, needs nothing of railway.contact at import time
        from .contact.profiles import RailProfile, rail_crown_problem
        from .ranges import ranges

        self.profile = profile if profile is not None else RailProfile.uic60()
        for key, val in (("gauge", gauge), ("gauge_depth", gauge_depth)):
            if not np.isfinite(val) or val <= 0:
                raise InputError(f"rail mounting: {key} = {val!r} must be positive and finite")
        accept = (accept,) if isinstance(accept, str) else tuple(accept)
        gauge = ranges().check("gauge", gauge, where="rail mounting: gauge", accept=accept)
        self.accept = accept
        if not (0.0 < gauge_depth < 0.05):
            raise InputError(f"rail mounting: gauge_depth = {gauge_depth!r} m is implausible (expected "
                             "below 0.05 m, e.g. 0.014); it is in metres")
        self.gauge = float(gauge)
        self.inclination = parse_inclination(inclination)
        self.gauge_depth = float(gauge_depth)
        al = np.arctan(self.inclination)
        self.ca, self.sa = float(np.cos(al)), float(np.sin(al))
        p = self.profile
        problem = rail_crown_problem(p)
        if problem:
            raise InputError(f"rail mounting: profile {p.name}: rail head has no crown: {problem}")
        u = np.linspace(p.x_min, p.x_max, 20001)
        v, v1, _ = p.evaluate(u)
        a1 = self.ca - v1 * self.sa
        ok = a1 > 0.02  # mounted profile a graph over Yo (slope below ~50)
        i0 = int(np.argmin(np.abs(u)))
        lo = i0
        while lo > 0 and ok[lo - 1]:
            lo -= 1
        hi = i0
        while hi < u.size - 1 and ok[hi + 1]:
            hi += 1
        self.u_min, self.u_max = float(u[lo]), float(u[hi])
        Z = u * self.sa + v * self.ca
        i_top = int(np.argmax(Z))
        # refine the top (dZ/du = 0) and the gauge point (Z = Z_top - depth on the gauge side)
        ut = self._newton(u[i_top], lambda x: self._mounted(x)[3], lambda x: self._mounted(x)[5],
                          what=f"the top of the inclined profile {p.name}")
        z_top = self._mounted(ut)[1]
        target = z_top - self.gauge_depth
        m = (u < ut) & (u >= self.u_min)
        j = np.nonzero(m & (Z <= target))[0]
        if j.size == 0:
            raise InputError(f"rail mounting: the profile {p.name} does not reach {gauge_depth} m "
                             f"below its top on the gauge side")
        ug0 = u[j[-1]]
        ug = self._newton(ug0, lambda x: self._mounted(x)[1] - target,
                          lambda x: self._mounted(x)[3], what=f"the gauge point of the profile {p.name}")
        self.u_top, self.u_gauge = float(ut), float(ug)
        yo_g = self._mounted(ug)[0]
        self.Y0 = 0.5 * self.gauge - yo_g
        self.Z0 = -z_top

    def _mounted(self, u):
        u = np.asarray(u, dtype=float)
        v, v1, v2 = self.profile.poly(u)
        ca, sa = self.ca, self.sa
        return (u * ca - v * sa, u * sa + v * ca, ca - v1 * sa, sa + v1 * ca, -v2 * sa, v2 * ca)

    def _newton(self, x, f, df, n=30, what="a point of the rail profile"):
        """Newton on f(x) = 0 from the grid point x; a zero or non-finite slope, or an iterate that
        leaves the profile, is a profile without that point (InputError naming it)."""
        x = x0 = float(x)
        lo, hi = self.profile.x_min, self.profile.x_max
        for _ in range(n):
            fx, dfx = float(f(x)), float(df(x))
            if not (np.isfinite(fx) and np.isfinite(dfx)) or dfx == 0.0:
                break
            dx = fx / dfx
            x -= dx
            if not lo <= x <= hi:
                break
            if abs(dx) < 1e-15:
                return x
        else:
            return x
        raise InputError(f"rail mounting: cannot locate {what} near u = {x0 * 1e3:.4g} mm (the profile is "
                         "not a smooth convex rail head there)")

    def mounted(self, u):
        """Mounted profile (Yo, Z, dYo/du, dZ/du, d2Yo/du2, d2Z/du2) at u (m), in the track
        frame's outward lateral coordinate and height."""
        Yo, Z, a1, b1, a2, b2 = self._mounted(u)
        return Yo + self.Y0, Z + self.Z0, a1, b1, a2, b2

    def lateral_to_u(self, yo):
        """Profile coordinate u at outward lateral position yo (m) on the running surface."""
        u = np.linspace(self.u_min, self.u_max, 4001)
        Yo = self.mounted(u)[0]
        return np.interp(yo, Yo, u)
