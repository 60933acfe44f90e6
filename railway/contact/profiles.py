"""Wheel and rail cross-section profiles as smooth parametric curves.

Conventions (SI units inside, metres; files and the S1002/UIC60 definitions are in mm)
------------------------------------------------------------------------------------------
Wheel profile
    ``y`` lateral coordinate from the taping line, **negative towards the flange** (S1002 /
    EN 13715 convention); ``F(y)`` radius increase, so the wheel radius is ``r(y) = r0 + F(y)``.
    The back face of the flange lies at ``y = y_back`` (-70 mm for S1002): the taping line is
    ``-y_back`` from the back face.
Rail profile
    ``u`` lateral coordinate in the rail's own (un-inclined) frame, origin on the rail axis,
    **positive towards the field side**; ``v(u)`` height, 0 at the crown, negative below.
    Inclination and mounting are applied by :class:`railway.track.RailMounting`.

Both profiles are graphs z = f(x) evaluated as piecewise quintic Hermite polynomials built from
the exact (f, f', f'') of each analytic section (C2 inside a section, C1 at section joints where
the exact profile is C1, the curvature jump at a joint represented exactly), or as a cubic
(smoothing) spline through measured points.  The parametric curve is x -> (x, f(x)) with
tangent (1, f'), curvature kappa = f'' / (1 + f'^2)^(3/2).

Measured profile files
----------------------
Two numeric columns, lateral and vertical in mm, separated by commas, semicolons or whitespace;
lines starting with ``#`` and a non-numeric header line are skipped.  The lateral coordinate must
be strictly monotonic (increasing or decreasing; it is sorted ascending).  Accepted sign
conventions, chosen by arguments:

* wheel: ``flange_side="negative"`` (default, S1002 convention) or ``"positive"`` (mirror y);
  ``vertical="radius_increase"`` (default; F grows towards the flange) or ``"height"``
  (z measured upwards on a wheel standing on the rail, i.e. F = -z).
* rail: ``field_side="positive"`` (default) or ``"negative"``; ``vertical="height"`` (default,
  v up) or ``"depth"`` (positive downwards, v = -depth).

Wheel profiles must cover only the part that is a graph over y (trim the vertical back of the
flange), and rail profiles only the head (trim the under-cut flanks).

References
----------
EN 13715:2006+A1:2010, Railway applications - Wheelsets and bogies - Wheels - Tread profile
(S1002 definition).  EN 13674-1:2011, Railway applications - Track - Rail - Part 1 (60E1/UIC60).
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from core.curves import PiecewisePoly
from core.errors import DataFileError, InputError
from core.paths import data_path

__all__ = [
    "DATA_DIR",
    "ProfileCurve",
    "WheelProfile",
    "RailProfile",
    "s1002_exact",
    "uic60_exact",
    "read_profile_file",
    "rail_crown_problem",
    "data_resolution",
    "R0_RANGE",
    "MIN_FLANGE_HEIGHT",
]

DATA_DIR = data_path("railway", must_exist=False)
_MM = 1e-3

#: Smallest flange height (m) of a wheel profile: new S1002 28 mm, worn flanges grow higher;
#: a profile with less at negative y is taken for a file read with the wrong signs.
MIN_FLANGE_HEIGHT = 0.010

#: Plausible nominal rolling radii (m): from a 1:5 scale roller-rig wheel (about 0.09 m) to the
#: largest locomotive wheels (about 1 m); a value outside is taken for a unit slip.
R0_RANGE = (0.05, 1.5)


def data_resolution(values, max_decimals=9):
    """Quantum of numbers written with a fixed number of decimals (same unit as the values).

    The smallest 10^-k (k = 0 ... ``max_decimals``) of which every value is an integer
    multiple (to 1e-4 of the quantum); 0.0 when there is none (full-precision data).  For a
    profile exported in mm with 4 decimals it is 1e-4 mm: the data cannot resolve heights, nor
    slopes over a spacing h, better than that quantum (slopes to about quantum / h).
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return 0.0
    for k in range(max_decimals + 1):
        s = v * 10.0**k
        if np.all(np.abs(s - np.round(s)) < 1e-4):
            return 10.0**-k
    return 0.0


# ---------------------------------------------------------------------------------------------
# analytic S1002
# ---------------------------------------------------------------------------------------------
def _load_s1002(path=None):
    path = Path(path) if path is not None else DATA_DIR / "s1002_definition.csv"
    rows = []
    with open(path, newline="", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            coef = [float(row[k]) if row[k].strip() else 0.0 for k in "ABCDEFGH"]
            rows.append((row["section"], float(row["y_min_mm"]), float(row["y_max_mm"]), coef))
    rows.sort(key=lambda r: r[1])
    return rows


def _s1002_section(name, coef, y):
    """F, F', F'' (mm, -, 1/mm) of one S1002 section at y (mm)."""
    A, B, C, D, E, F_, G, H = coef
    if name == "A":
        return A - B * y, -B + 0 * y, 0 * y
    if name in ("B", "C"):
        if name == "B":
            p = np.array([0.0, -A, B, -C, D, -E, F_, -G, H])
        else:
            p = -np.array([A, B, C, D, E, F_, G, H])
        P = np.polynomial.Polynomial(p)
        return P(y), P.deriv(1)(y), P.deriv(2)(y)
    if name == "E":
        return -A - B * y, -B + 0 * y, 0 * y
    # arcs: D lower branch F = A - sqrt(B^2-(y+C)^2); F, G, H upper branch F = A + sqrt(...)
    w = np.sqrt(np.maximum(B**2 - (y + C) ** 2, 1e-300))
    sgn = -1.0 if name == "D" else 1.0
    return A + sgn * w, -sgn * (y + C) / w, -sgn * B**2 / w**3


def s1002_exact(y, path=None):
    """Exact S1002 radius increase from the analytic definition.

    Parameters
    ----------
    y : array_like
        Lateral coordinate from the taping line in **mm** (negative towards the flange),
        within [-70, 60].
    path : path-like, optional
        Definition table (default ``data/railway/s1002_definition.csv``).

    Returns
    -------
    F, dF, d2F : ndarray
        Radius increase (mm), slope dF/dy (-), second derivative (1/mm).
    """
    y = np.asarray(y, dtype=float)
    rows = _load_s1002(path)
    out = [np.full(y.shape, np.nan) for _ in range(3)]
    for name, lo, hi, coef in rows:
        m = (y >= lo) & (y <= hi)
        if np.any(m):
            vals = _s1002_section(name, coef, y[m])
            for o, v in zip(out, vals):
                o[m] = v
    return tuple(out)


# ---------------------------------------------------------------------------------------------
# analytic UIC60 head
# ---------------------------------------------------------------------------------------------
_UIC60 = dict(R300=300.0, R80=80.0, c80_u=7.700, c80_d=80.135, R13=13.0, c13_u=23.016,
              c13_d=14.909, u1=10.500, u2=25.988)


def _uic60_half_sections():
    """Sections of the UIC60 head for u >= 0 (mm): (u_lo, u_hi, centre_u, centre_v, R)."""
    g = _UIC60
    # crown centre 300 below crown; v = centre_v + sqrt(R^2 - (u-cu)^2)
    # the tangency points follow from the arc centres (arcs mutually tangent).  The centre
    # depths printed to 1e-3 mm (80.135, 14.909) leave the R80 arc 0.23 um inside the R300
    # arc (|c300 - c80| = 219.99977 instead of 300 - 80), a 0.21 um step of the head at
    # |u| = 10.5 mm that a contact search sees; the depths are therefore taken from the
    # tangency conditions |c300 - c80| = R300 - R80, |c80 - c13| = R80 - R13 at the printed
    # lateral positions (80.13480, 14.90884 mm: within 0.3 um of the printed values).
    d80 = g["R300"] - np.sqrt((g["R300"] - g["R80"]) ** 2 - g["c80_u"] ** 2)
    d13 = d80 - np.sqrt((g["R80"] - g["R13"]) ** 2 - (g["c13_u"] - g["c80_u"]) ** 2)
    c300 = np.array([0.0, -g["R300"]])
    c80 = np.array([g["c80_u"], -d80])
    c13 = np.array([g["c13_u"], -d13])
    t1 = c300 + g["R300"] * (c80 - c300) / np.linalg.norm(c80 - c300)
    t2 = c80 + g["R80"] * (c13 - c80) / np.linalg.norm(c13 - c80)
    # flank 1:20 tangent to R13: outward normal (1, -0.05)/|.| in (u, v)
    nf = np.array([1.0, -0.05]) / np.hypot(1.0, 0.05)
    t3 = c13 + g["R13"] * nf
    return [(0.0, t1[0], c300, g["R300"]), (t1[0], t2[0], c80, g["R80"]),
            (t2[0], t3[0], c13, g["R13"])], t3


def uic60_exact(u):
    """Exact UIC60 (60E1) head height v(u) from its arcs (symmetric about the rail axis).

    Parameters
    ----------
    u : array_like
        Lateral coordinate from the rail axis in **mm**, ``|u|`` up to the widest point 36.016 mm.

    Returns
    -------
    v, dv, d2v : ndarray
        Height below the crown as a negative number (mm), slope (-), second derivative (1/mm).
    """
    u = np.asarray(u, dtype=float)
    au = np.abs(u)
    sg = np.where(u < 0, -1.0, 1.0)
    secs, _ = _uic60_half_sections()
    out = [np.full(u.shape, np.nan) for _ in range(3)]
    last = len(secs) - 1
    for k, (lo, hi, c, R) in enumerate(secs):
        hi_k = c[0] + R if k == last else hi
        m = (au >= lo) & (au <= hi_k)
        x = au[m] - c[0]
        w = np.sqrt(np.maximum(R**2 - x**2, 1e-300))
        out[0][m] = c[1] + w
        out[1][m] = sg[m] * (-x / w)
        out[2][m] = -(R**2) / w**3
    return tuple(out)


# ---------------------------------------------------------------------------------------------
# file reading and validation
# ---------------------------------------------------------------------------------------------
#: Smallest lateral extent (mm) of a wheel or rail profile: a rail head is about 70 mm wide, a
#: wheel tread and flange about 135 mm; a profile spanning less than 5 mm was given in metres.
MIN_PROFILE_SPAN_MM = 5.0


#: Half-width (m) of the probe around the highest point of a rail head that measures its crown
#: radius: UIC60 falls by 0.015 mm over it (R300), a flat head by nothing, a V by millimetres.
CROWN_PROBE = 0.003


def rail_crown_problem(profile) -> str:
    """What keeps ``profile`` from being a rail head with a crown, or "" when it has one.

    A rail head rises to one highest point (its crown) inside the profile and falls on both
    sides of it with a crown radius R = d^2 / (drop_left + drop_right) over d =
    :data:`CROWN_PROBE` within the plausible range of ``profile_lateral_radius``
    (``data/railway/plausible_ranges.csv``): a flat head (R beyond it) has no crown on which a
    wheel's contact could settle and no top at an inclination, a V-shaped one (R below it) a knife
    edge.
    """
    from ..ranges import ranges

    rng = ranges()["profile_lateral_radius"]
    u = np.linspace(profile.x_min, profile.x_max, 4001)
    v = profile.poly(u)[0]
    width = (u[-1] - u[0]) / _MM
    if not np.all(np.isfinite(v)):
        return "the fitted profile is not finite"
    if float(np.ptp(v)) < 1e-5:
        return (f"it is flat (its heights vary by {float(np.ptp(v)) / _MM:.3g} mm over its width of "
                f"{width:.4g} mm); a rail head rises to a rounded crown (UIC60: R300)")
    i = int(np.argmax(v))
    ut = float(u[i])
    if ut - CROWN_PROBE < u[0] or ut + CROWN_PROBE > u[-1]:
        edge = "first" if ut - CROWN_PROBE < u[0] else "last"
        return (f"its highest point, u = {ut / _MM:.4g} mm, lies within {CROWN_PROBE / _MM:g} mm of its "
                f"{edge} point: the heights rise towards the edge instead of falling on both sides of a "
                "crown (are they depths? read the file with vertical='depth')")
    vl, vr = profile.poly(np.array([ut - CROWN_PROBE, ut + CROWN_PROBE]))[0]
    drop = float(2.0 * v[i] - vl - vr)
    R = CROWN_PROBE**2 / drop if drop > 0 else np.inf
    where = (f"within +-{CROWN_PROBE / _MM:g} mm of its highest point (u = {ut / _MM:.4g} mm) it falls by "
             f"{drop / 2 / _MM:.3g} mm on average")
    if R > rng.high:
        return (f"it is flat at the top: {where} (crown radius {R:.4g} m, above {rng.high:g} m); a rail head "
                "has a rounded crown (UIC60: R300 mm)")
    if R < rng.low:
        return (f"it comes to a point (V-shaped): {where} (crown radius {R / _MM:.3g} mm, below "
                f"{rng.low / _MM:g} mm); a rail head has a rounded crown (UIC60: R300 mm)")
    return ""


def _validate_xy(x, z, source):
    x = np.asarray(x, dtype=float)
    z = np.asarray(z, dtype=float)
    if x.ndim != 1 or x.shape != z.shape:
        raise InputError(f"{source}: lateral and vertical columns must be 1-D of equal length")
    if x.size < 4:
        raise InputError(f"{source}: at least 4 profile points are needed, got {x.size}")
    for name, a in (("lateral", x), ("vertical", z)):
        bad = ~np.isfinite(a)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise InputError(f"{source}: {name} coordinate of point {i} is {float(a[i])} (not finite)")
    span = float(np.ptp(x))
    if span < MIN_PROFILE_SPAN_MM and float(np.max(np.abs(np.concatenate([x, z])))) < 1.0:
        raise InputError(
            f"{source}: values look like metres (the lateral coordinate spans {span:.4g}, the heights "
            f"{float(np.ptp(z)):.4g}); profile files are in mm: multiply by 1000")
    if span < MIN_PROFILE_SPAN_MM:
        raise InputError(f"{source}: the lateral coordinate spans only {span:.4g} mm; a wheel or rail "
                         f"profile spans tens of mm (the values are in mm)")
    dx = np.diff(x)
    if np.all(dx < 0):
        x, z = x[::-1], z[::-1]
        dx = -dx[::-1]
    if not np.all(dx > 0):
        sign = 1.0 if np.sum(dx > 0) >= np.sum(dx < 0) else -1.0
        i = int(np.argmax(sign * dx <= 0)) + 1
        raise InputError(
            f"{source}: lateral coordinate is not strictly monotonic at point {i} "
            f"(value {float(x[i])} after {float(x[i - 1])}); trim the profile to a graph over the lateral "
            f"coordinate")
    return x, z


def read_profile_file(path):
    """Read a two-column profile file (lateral, vertical in mm); returns two arrays in mm."""
    path = Path(path)
    xs, zs = [], []
    raw = path.read_bytes()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise DataFileError(f"{path}: not a text profile file (byte {raw[exc.start]:#04x} at offset "
                            f"{exc.start} is not UTF-8; expected two columns, lateral and vertical in "
                            "mm)") from None
    if "\x00" in text:
        raise DataFileError(f"{path}: not a text profile file (it contains NUL bytes; expected two "
                            "columns, lateral and vertical in mm)")
    for lineno, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        parts = [p for p in re.split(r"[,;\s]+", s) if p]
        if len(parts) < 2:
            raise DataFileError(f"{path}:{lineno}: expected two columns, got {s!r}")
        try:
            a, b = float(parts[0]), float(parts[1])
        except ValueError:
            if not xs:  # header line
                continue
            raise DataFileError(f"{path}:{lineno}: non-numeric value in {s!r}") from None
        if not (np.isfinite(a) and np.isfinite(b)):
            raise DataFileError(f"{path}:{lineno}: point ({a}, {b}) is not finite (in {s!r})")
        xs.append(a)
        zs.append(b)
    if not xs:
        raise DataFileError(f"{path}: no profile points found")
    return np.array(xs), np.array(zs)


def _spline_ppoly(x, z, smoothing):
    from scipy.interpolate import CubicSpline, make_smoothing_spline

    if smoothing is None:
        pp = CubicSpline(x, z, bc_type="not-a-knot")
        return PiecewisePoly.from_scipy(pp)
    from scipy.interpolate import PPoly

    spl = make_smoothing_spline(x, z, lam=float(smoothing))
    return PiecewisePoly.from_scipy(PPoly.from_spline(spl))


# ---------------------------------------------------------------------------------------------
# classes
# ---------------------------------------------------------------------------------------------
class ProfileCurve:
    """A profile z = f(x) on [x_min, x_max] (metres) with first and second derivatives.

    Parameters
    ----------
    poly : PiecewisePoly
        Scalar piecewise polynomial in metres.
    name : str
        Label used in messages and tables.
    """

    def __init__(self, poly: PiecewisePoly, name: str, resolution: float = 0.0):
        self.poly = poly
        self.name = name
        #: vertical resolution of the data (m): 0 for an analytic profile, the quantum of the
        #: written values for measured points (e.g. 1e-7 m for values in mm with 4 decimals);
        #: no geometric result can be trusted below it
        self.resolution = float(resolution)

    @property
    def x_min(self) -> float:
        return self.poly.x_min

    @property
    def x_max(self) -> float:
        return self.poly.x_max

    def evaluate(self, x):
        """Return (f, df/dx, d2f/dx2) at x (m); shapes follow x."""
        x = np.asarray(x, dtype=float)
        if np.any(~np.isfinite(x)):
            raise InputError(f"{self.name}: non-finite profile coordinate {x[~np.isfinite(x)][0]!r}")
        return self.poly(x)

    def curvature(self, x):
        """Signed curvature f''/(1+f'^2)^(3/2) (1/m) of the curve x -> (x, f(x))."""
        _, d1, d2 = self.evaluate(x)
        return d2 / (1.0 + d1**2) ** 1.5

    def points(self, n=500):
        """(n, 2) array of (x, f(x)) in metres, for plotting."""
        x = np.linspace(self.x_min, self.x_max, n)
        return np.column_stack([x, self.evaluate(x)[0]])


class WheelProfile(ProfileCurve):
    """Wheel profile: radius increase F(y) over the lateral coordinate y from the taping line.

    The wheel radius is r(y) = r0 + F(y) (m); y is negative towards the flange.  The profile is
    split into a tread zone [y_split, y_max] and a flange zone [y_flange_min, y_split] which
    the contact search treats as separate candidates (two-point contact).

    Parameters
    ----------
    poly : PiecewisePoly
        F(y) in metres.
    r0 : float
        Nominal rolling radius at the taping line (m).
    y_back : float
        Lateral coordinate of the flange back face (m), -0.070 for S1002.
    y_split : float, optional
        Boundary between the tread and flange zones (m).  Default: where the convex flange
        (flank and tip, F'' <= 0) meets the concave flange root (F'' > 0 over at least
        0.5 mm), so that the flange zone is convex; -38.43 mm for S1002 (joint of the R13 root
        arc and the 70 deg flank).
    y_flange_min : float, optional
        Lowest y admitted for flange contact (m); default the flange tip (maximum of F).
    name : str
    """

    def __init__(self, poly, r0=0.46, y_back=-0.070, y_split=None, y_flange_min=None,
                 name="wheel", resolution=0.0):
        super().__init__(poly, name, resolution)
        for key, val in (("r0", r0), ("y_back", y_back)):
            if not np.isfinite(val):
                raise InputError(f"{name}: {key} = {val!r} is not finite")
        if r0 <= 0.0:
            raise InputError(f"{name}: nominal rolling radius r0 = {r0!r} m must be positive")
        if not (R0_RANGE[0] <= r0 <= R0_RANGE[1]):
            raise InputError(
                f"{name}: nominal rolling radius r0 = {r0!r} m is implausible (expected "
                f"{R0_RANGE[0]:g} to {R0_RANGE[1]:g} m, e.g. 0.46); r0 is in metres"
                + (" -- was it given in millimetres?" if r0 > R0_RANGE[1] else ""))
        self.r0 = float(r0)
        self.y_back = float(y_back)
        ys = np.linspace(self.x_min, min(0.0, self.x_max), 4001)
        F, _, F2 = self.poly(ys)
        i_tip = int(np.argmax(F))
        self.y_tip = float(ys[i_tip])
        # the flange lies at negative y and F grows towards it (the convention of S1002 and of
        # every sign option of the readers): a profile read with the wrong flange side or
        # vertical sign has no such flange -- refuse it instead of computing with it
        y0 = min(max(0.0, self.x_min), self.x_max)
        F0 = float(self.poly(np.array([y0]))[0][0])
        h_neg = float(F[i_tip]) - F0
        yp = np.linspace(y0, self.x_max, 2001)
        h_pos = float(np.max(self.poly(yp)[0])) - F0
        if not (h_neg >= MIN_FLANGE_HEIGHT and h_neg > h_pos):
            raise InputError(
                f"{name}: no flange at negative lateral coordinates (the radius increase rises "
                f"{h_neg * 1e3:.3g} mm above the taping line towards negative y and "
                f"{h_pos * 1e3:.3g} mm towards positive y; a flange is at least "
                f"{MIN_FLANGE_HEIGHT * 1e3:g} mm high): check the flange side (flange_side="
                "'positive' mirrors y) and the vertical sign (vertical='height' flips it)")
        if y_flange_min is None:
            y_flange_min = self.y_tip
        if y_split is None:
            # the flange proper is convex (F'' <= 0: flank and flange tip); the root between it
            # and the tread is concave.  Split where, going from the flange tip towards the
            # taping line, the profile turns concave (F'' > 0) for good: the first stretch of
            # F'' > 0 at least 0.5 mm long.  (A cubic spline through sampled points rings
            # around the curvature jumps of the flank's joints: F'' changes sign along the
            # straight flank in stretches of about one sample spacing, which must not count.)
            m = (ys > self.y_tip) & (F2 > 1e-6)
            edges = np.diff(np.concatenate([[0], m.astype(int), [0]]))
            starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
            long_ = [a for a, b in zip(starts, ends) if ys[b - 1] - ys[a] >= 5e-4]
            if not long_:
                raise InputError(f"{name}: no concave flange root found; give y_split explicitly")
            y_split = float(ys[long_[0]])
        self.y_split = float(y_split)
        self.y_flange_min = float(y_flange_min)
        if not (self.x_min <= self.y_flange_min < self.y_split < self.x_max):
            raise InputError(
                f"{name}: need y_min <= y_flange_min < y_split < y_max, got {self.x_min}, "
                f"{self.y_flange_min}, {self.y_split}, {self.x_max}")

    @property
    def y_flank_top(self):
        """Top of the flank: the point of maximum flange angle nearest the flange tip (m).

        The flange angle arctan|F'| is largest on the flank (70 deg on S1002's straight flank,
        section E of EN 13715, -38.43 to -39.76 mm); beyond this point, towards the tip, it
        falls.  A contact that has moved past it is climbing: Nadal's limit Y/Q falls with the angle, so the climb
        goes on by itself (the derailment criterion of :class:`railway.vehicles.wheel_rail.WheelRailContact`).
        Points within 0.01 deg of the maximum count as the flank.
        """
        if getattr(self, "_y_flank_top", None) is None:
            ys = np.linspace(self.y_tip, self.y_split, 4001)
            ang = np.degrees(np.arctan(np.abs(self.poly(ys)[1])))
            self._y_flank_top = float(ys[ang >= ang.max() - 0.01].min())
        return self._y_flank_top

    def climb_limit(self, height):
        """Lateral coordinate (m) at which a contact has climbed ``height`` (m, radius increase)
        above the top of the flank (:attr:`y_flank_top`); the flange tip if the flange is lower.
        F grows monotonically from the flank top to the tip, so the root is unique (Brent)."""
        from scipy.optimize import brentq

        y0 = self.y_flank_top
        F0 = float(self.poly(np.array([y0]))[0][0])

        def rise(y):
            return float(self.poly(np.array([y]))[0][0]) - F0 - height

        if rise(self.y_tip) <= 0.0:
            return self.y_tip
        return float(brentq(rise, self.y_tip, y0, xtol=1e-9))

    def radius(self, y):
        """Wheel radius r0 + F(y) (m)."""
        return self.r0 + self.evaluate(y)[0]

    @property
    def tread_zone(self):
        return (self.y_split, self.x_max)

    @property
    def flange_zone(self):
        return (self.y_flange_min, self.y_split)

    @classmethod
    def s1002(cls, r0=0.46, y_min_mm=-68.0, y_max_mm=60.0, max_step_mm=0.25, path=None, **kw):
        """S1002 from its analytic definition (sections A-H of ``s1002_definition.csv``).

        The table is built section by section from the exact F, F', F'' at nodes spaced at most
        ``max_step_mm`` apart in arc length; the vertical back of the flange (y -> -70 mm) is
        excluded by ``y_min_mm``.
        """
        rows = _load_s1002(path)
        secs = []
        for name, lo, hi, coef in rows:
            lo_, hi_ = max(lo, y_min_mm), min(hi, y_max_mm)
            if hi_ > lo_:
                secs.append((lo_, hi_, (lambda x, n=name, c=coef: _s1002_section(n, c, x))))
        return cls(_table_from_sections(secs, max_step_mm), r0=r0, y_back=-0.070, name="S1002",
                   **kw)

    @classmethod
    def from_points(cls, y, F, r0, y_back, flange_side="negative", vertical="radius_increase",
                    smoothing=None, name="measured wheel", source=None, resolution=None, **kw):
        """Wheel profile from measured points (mm), fitted with a C2 cubic (smoothing) spline.

        Parameters
        ----------
        y, F : (n,) array_like
            Lateral (mm) and vertical (mm) coordinates, see the module docstring for signs.
        r0 : float
            Nominal rolling radius (m).
        y_back : float
            Flange back face position in the file's lateral coordinate (mm).
        smoothing : float, optional
            ``lam`` of :func:`scipy.interpolate.make_smoothing_spline` (mm^3 units); None
            interpolates.
        resolution : float, optional
            Vertical resolution of the data (mm); default :func:`data_resolution` of ``F``
            (1e-4 mm for values written with 4 decimals).  Stored in metres as
            ``self.resolution``; :func:`railway.contact.geometry.rigid_contact` accepts a
            rigid solution to this level.
        """
        source = source or name
        if flange_side not in ("negative", "positive"):
            raise InputError(f"{source}: flange_side must be 'negative' or 'positive', got {flange_side!r}")
        if vertical not in ("radius_increase", "height"):
            raise InputError(f"{source}: vertical must be 'radius_increase' or 'height', got {vertical!r}")
        y = np.asarray(y, dtype=float)
        F = np.asarray(F, dtype=float)
        if flange_side == "positive":
            y, y_back = -y, -y_back
        if vertical == "height":
            F = -F
        y, F = _validate_xy(y, F, source)
        if y_back > y[0]:
            raise InputError(f"{source}: flange back y_back = {y_back!r} mm lies inside the profile")
        res = data_resolution(F) if resolution is None else float(resolution)
        poly = _spline_ppoly(y * _MM, F * _MM, smoothing)
        return cls(poly, r0=r0, y_back=y_back * _MM, name=name, resolution=res * _MM, **kw)

    @classmethod
    def from_file(cls, path, r0, y_back=-70.0, **kw):
        """Read a measured wheel profile (two columns, mm); see :meth:`from_points`."""
        y, F = read_profile_file(path)
        return cls.from_points(y, F, r0=r0, y_back=y_back, name=Path(path).name,
                               source=str(path), **kw)


class RailProfile(ProfileCurve):
    """Rail head profile v(u) (m) in the rail's own frame (u > 0 field side, v up, crown v=0)."""

    @classmethod
    def uic60(cls, u_max_mm=36.012, max_step_mm=0.25):
        """UIC60 (60E1) head from its R300/R80/R13 arcs, ``|u|`` <= ``u_max_mm``.

        The default limit 36.012 mm is where the gauge-corner slope reaches 40 (vertical after a
        1:40 inclination); beyond it the head is under-cut and not a graph.
        """
        half, _ = _uic60_half_sections()
        edges = [0.0] + [h[1] for h in half]
        edges[-1] = u_max_mm
        secs = []
        for k in range(len(half) - 1, -1, -1):  # gauge/left side, u < 0
            c, R = half[k][2], half[k][3]
            secs.append((-edges[k + 1], -edges[k], (lambda x, c=c, R=R: _arc_up(-x, c, R, -1.0))))
        for k in range(len(half)):
            c, R = half[k][2], half[k][3]
            secs.append((edges[k], edges[k + 1], (lambda x, c=c, R=R: _arc_up(x, c, R, 1.0))))
        return cls(_table_from_sections(secs, max_step_mm), name="UIC60")

    @classmethod
    def from_points(cls, u, v, field_side="positive", vertical="height", smoothing=None,
                    name="measured rail", source=None, resolution=None):
        """Rail profile from measured points (mm), fitted with a C2 cubic (smoothing) spline.

        The crown is shifted to v = 0 (highest point of the un-inclined profile).
        ``resolution`` (mm) as in :meth:`WheelProfile.from_points`.
        """
        source = source or name
        if field_side not in ("negative", "positive"):
            raise InputError(f"{source}: field_side must be 'negative' or 'positive', got {field_side!r}")
        if vertical not in ("height", "depth"):
            raise InputError(f"{source}: vertical must be 'height' or 'depth', got {vertical!r}")
        u = np.asarray(u, dtype=float)
        v = np.asarray(v, dtype=float)
        if field_side == "negative":
            u = -u
        if vertical == "depth":
            v = -v
        u, v = _validate_xy(u, v, source)
        res = data_resolution(v) if resolution is None else float(resolution)
        v = v - np.max(v)
        prof = cls(_spline_ppoly(u * _MM, v * _MM, smoothing), name=name, resolution=res * _MM)
        problem = rail_crown_problem(prof)
        if problem:
            raise InputError(f"{source}: rail head has no crown: {problem}")
        return prof

    @classmethod
    def from_file(cls, path, **kw):
        """Read a measured rail profile (two columns, mm); see :meth:`from_points`."""
        u, v = read_profile_file(path)
        return cls.from_points(u, v, name=Path(path).name, source=str(path), **kw)


def _arc_up(x, c, R, sg):
    """Upper branch v = c_v + sqrt(R^2 - (x - c_u)^2) (mm) at mirrored abscissa x; slope sign sg."""
    d = x - c[0]
    w = np.sqrt(np.maximum(R**2 - d**2, 1e-300))
    return c[1] + w, sg * (-d / w), -(R**2) / w**3


def _table_from_sections(secs, max_step_mm):
    """Quintic Hermite table (metres) from analytic sections [(lo, hi, f(x)->(f, f', f''))] in mm.

    Nodes are placed uniformly in arc length inside each section (dense where the slope is
    steep); the values at both ends of an interval come from the section that owns it, so a
    curvature jump at a joint is represented exactly.
    """
    xs, f0, f1, f2, g0, g1, g2 = [], [], [], [], [], [], []
    for lo, hi, fun in secs:
        xd = np.linspace(lo, hi, 4001)
        sl = fun(xd)[1]
        ds = np.sqrt(1.0 + sl**2)
        s_arc = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(xd))])
        n = max(2, int(np.ceil(s_arc[-1] / max_step_mm)) + 1)
        x = np.interp(np.linspace(0.0, s_arc[-1], n), s_arc, xd)
        x[0], x[-1] = lo, hi
        F, d1, d2 = fun(x)
        xs.append(x[:-1])
        f0.append(F[:-1]); f1.append(d1[:-1]); f2.append(d2[:-1])
        g0.append(F[1:]); g1.append(d1[1:]); g2.append(d2[1:])
    x = np.append(np.concatenate(xs), secs[-1][1]) * _MM
    cat = np.concatenate
    return PiecewisePoly.from_hermite(
        x, np.append(cat(f0), 0.0) * _MM, np.append(cat(f1), 0.0), np.append(cat(f2), 0.0) / _MM,
        f_right=cat(g0) * _MM, df_right=cat(g1), d2f_right=cat(g2) / _MM)
