"""Vectorised wheel-rail contact search (Pombo & Ambrosio four-condition method).

Equations
---------
For a wheel surface p(theta, y) (surface of revolution, see :mod:`railway.surfaces`) and a rail
surface q(s, u) (profile swept along the track), with d = p - q and the rail outward normal n_r,
candidate contact points satisfy the four conditions of Pombo, Ambrosio & Silva (2007)::

    h1 = n_r . t_theta = 0,   h2 = n_r . t_y = 0      (normals parallel)
    h3 = d . t_s = 0,         h4 = d . t_u = 0        (distance vector along the normal)

for the four surface parameters x = (theta, y, s, u).  The gap is g = d . n_r; the wheel is in
contact where g <= 0, with penetration delta = -g.  n_r points from the rail into the wheel (the
normal force on the wheel acts along +n_r).

Solution strategy
-----------------
* Every wheel has two candidates, tread and flange (zones of the profile coordinate y, see
  :class:`railway.profiles.WheelProfile`), solved as separate problems, so that two-point contact
  (tread plus flange) is found.  A candidate is valid when Newton converged inside its zone.
* Newton's method with the analytic Jacobian of the four conditions (or, optionally, forward
  differences evaluated at the 5 P points x and x + h e_k in one vectorised pass); the P 4x4
  systems are solved in one batched ``np.linalg.solve``.  A step that does not reduce the merit
  |W h|^2 is retried from the last accepted point with a quarter of its length.  Steps are
  limited and the parameters kept inside their zones.
* The tread gap of S1002 on UIC60 1:40 has near-equal local minima, so the contact point jumps
  across the tread.  A coarse scan of each zone in the cross-section (grid uniform in the
  profile's arc length over the whole zone, overlap included; lowest point of each wheel
  circle, rail point of the same tangent angle, sign changes of the fourth condition) gives the
  ``n_seeds`` best stationary points as seeds; Newton runs from them (and from the warm start)
  side by side and the lowest valid gap wins.  On a trajectory (``warm=True``) the warm start is
  extrapolated linearly from the last two solutions, only candidates that had a contact are
  refined, and the global re-seeding runs every ``reseed_every`` calls and whenever a contact is
  lost.
* Where Newton does not solve a scan seed (a stationary point lies near, by a sign change of
  the fourth condition), the seed is refined by a derivative-free minimisation instead
  (:meth:`ContactSearch._robust`): for a fixed wheel profile coordinate y the other three
  conditions (h1, h3, h4) are solved for (theta, s, u) -- a well-conditioned 3x3 Newton, the
  wheel point's projection on the rail -- which gives the gap psi(y) of that profile line, and
  by the envelope theorem dpsi/dy = n . t_y = h2::

      psi(y) = d . n  at  h1 = h3 = h4 = 0,        dpsi/dy = h2

  so the four-condition solutions are the stationary points of psi and the contact is its
  minimum.  psi is sampled densely in the seed's bracket and its minimum refined by Newton or,
  where that fails, golden-section search.  This finds the contact where Newton's 4x4 Jacobian
  is singular or jumps: the S1002 R13 flange root conformal with the UIC60 R13 gauge corner,
  the root/flank joint with its slope step of ~1e-5 (where the rigid contact sits over a band
  of shifts at the flange onset), and the ripples of splines through sampled, rounded profile
  points (a measured profile exported at 0.25 or 0.5 mm).
* A Newton step below ``tol_linear`` is applied without a further pass; the outputs are then
  linearised about the evaluated point (error O(step^2)).
* With numba installed the same iteration, and the seed scan, run in compiled kernels
  (:mod:`railway._kernels`); the numpy code is the reference (tests compare both).

References
----------
Pombo, J., Ambrosio, J. and Silva, M. (2007). A new wheel-rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165-189 (contact detection between the parametric
wheel and rail surfaces; equation numbers were not checked against the paper here).
Kiefer, J. (1953). Sequential minimax search for a maximum. Proc. Amer. Math. Soc.
4(3):502-506 (golden-section search).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from core.curves import concatenate
from core.errors import InputError

from .profiles import WheelProfile
from .track import RailMounting, Track

__all__ = ["ContactSearch", "ContactResult", "wheelset_pose"]

TREAD, FLANGE = 0, 1
_I1, _I2 = np.array([1, 2, 0]), np.array([2, 0, 1])


#: two solutions closer than this on the wheel profile (m) are one stationary point
_SAME_POINT = 1e-4


def _cross(a, b):
    """Cross product of (..., 3) arrays (cheaper than np.cross for small arrays)."""
    return a[..., _I1] * b[..., _I2] - a[..., _I2] * b[..., _I1]


def _rot_x(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def _rot_z(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def _arc_grid(profile, lo, hi, n):
    """n points of [lo, hi] (m) uniform in the arc length of the curve y -> (y, F(y))."""
    yd = np.linspace(lo, hi, 20 * n + 1)
    ds = np.sqrt(1.0 + profile.poly(yd)[1] ** 2)
    arc = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(yd))])
    y = np.interp(np.linspace(0.0, arc[-1], n), arc, yd)
    y[0], y[-1] = lo, hi
    return y


def wheelset_pose(track: Track, s, lateral=0.0, height=0.0, roll=0.0, yaw=0.0):
    """Wheelset centre position and orientation relative to the track frame.

    The wheelset centre is at r(s) + R(s) (0, lateral, height); its orientation is
    A = R(s) Rz(yaw) Rx(roll) (yaw about the track up axis, then roll about the wheelset's own
    longitudinal axis).

    Parameters
    ----------
    track : Track
    s, lateral, height, roll, yaw : (n,) array_like or float
        Arc length (m), lateral shift (m, left positive), height of the axle above the top-of-rail
        plane (m), roll (rad, positive lifts the left wheel), yaw (rad).

    Returns
    -------
    r : (n, 3) ndarray, A : (n, 3, 3) ndarray
    """
    s, lateral, height, roll, yaw = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, dtype=float)) for v in (s, lateral, height, roll, yaw)))
    for name, v in (("s", s), ("lateral", lateral), ("height", height), ("roll", roll), ("yaw", yaw)):
        bad = ~np.isfinite(v)
        if np.any(bad):
            raise InputError(f"wheelset pose: {name}[{int(np.argmax(bad))}] = {v[bad][0]!r} is not finite")
    fr = track.evaluate(s)
    loc = np.stack([np.zeros_like(s), lateral, height], axis=1)
    r = fr.position + np.einsum("nij,nj->ni", fr.R, loc)
    A = fr.R @ _rot_z(yaw) @ _rot_x(roll)
    return r, A


@dataclass
class ContactResult:
    """Contact candidates of all wheels: arrays of shape (n_wheels, 2, ...).

    Wheels are ordered wheelset by wheelset, left (side +1) then right (side -1); axis 1 is the
    candidate: 0 tread, 1 flange.  Invalid candidates (no stationary point inside the zone) have
    ``valid`` False, gap +inf and NaN geometry.

    Attributes
    ----------
    point_wheel, point_rail, normal : (n_wheels, 2, 3)
        Contact points on wheel and rail and rail outward unit normal (global, m).
    gap, penetration : (n_wheels, 2)
        g = (p - q) . n (m) and delta = -g.
    in_contact : (n_wheels, 2) bool
        valid and g <= 0.
    theta, y_wheel, s_rail, u_rail : (n_wheels, 2)
        Surface parameters (rad, m, m, m).
    rolling_radius : (n_wheels, 2)
        r0 + F(y_wheel) (m).
    contact_angle : (n_wheels, 2)
        Angle (rad) of the normal from the track up axis in the cross-section, positive when it
        leans towards the track centre (about +0.02 on the tread with 1:40, ~1.2 on the flange).
    wheel_angle : (n_wheels, 2)
        Profile slope angle atan(-F'(y)) in the wheelset frame (rad).
    k_wheel_rolling, k_wheel_lateral, k_rail_rolling, k_rail_lateral : (n_wheels, 2)
        Principal curvatures (1/m), convex positive (see :mod:`railway.surfaces`).
    flange : (n_wheels, 2) bool
        True for the flange candidate.
    residual : (n_wheels, 2)
        Largest |h_k| at the reported point.
    iterations : int
        Newton passes of the call.
    """

    point_wheel: np.ndarray
    point_rail: np.ndarray
    normal: np.ndarray
    gap: np.ndarray
    penetration: np.ndarray
    in_contact: np.ndarray
    valid: np.ndarray
    theta: np.ndarray
    y_wheel: np.ndarray
    s_rail: np.ndarray
    u_rail: np.ndarray
    rolling_radius: np.ndarray
    contact_angle: np.ndarray
    wheel_angle: np.ndarray
    k_wheel_rolling: np.ndarray
    k_wheel_lateral: np.ndarray
    k_rail_rolling: np.ndarray
    k_rail_lateral: np.ndarray
    flange: np.ndarray
    residual: np.ndarray
    iterations: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def radii(self):
        """Principal radii (R_wx, R_wy, R_rx, R_ry) (m), convex positive, inf where flat."""
        with np.errstate(divide="ignore"):
            return tuple(1.0 / k for k in (self.k_wheel_rolling, self.k_wheel_lateral,
                                           self.k_rail_rolling, self.k_rail_lateral))

    def to_frame(self):
        """One row per wheel and candidate, SI units in the column names."""
        import pandas as pd

        nw = self.gap.shape[0]
        wheel = np.repeat(np.arange(nw), 2)
        cols = {
            "wheel": wheel,
            "wheelset": wheel // 2,
            "side": np.where(wheel % 2 == 0, "left", "right"),
            "candidate": np.tile(["tread", "flange"], nw),
            "valid": self.valid.ravel(),
            "in_contact": self.in_contact.ravel(),
            "gap [m]": self.gap.ravel(),
            "penetration [m]": self.penetration.ravel(),
            "theta [rad]": self.theta.ravel(),
            "y_wheel [m]": self.y_wheel.ravel(),
            "s_rail [m]": self.s_rail.ravel(),
            "u_rail [m]": self.u_rail.ravel(),
            "rolling radius [m]": self.rolling_radius.ravel(),
            "contact angle [rad]": self.contact_angle.ravel(),
            "k_wheel_rolling [1/m]": self.k_wheel_rolling.ravel(),
            "k_wheel_lateral [1/m]": self.k_wheel_lateral.ravel(),
            "k_rail_rolling [1/m]": self.k_rail_rolling.ravel(),
            "k_rail_lateral [1/m]": self.k_rail_lateral.ravel(),
        }
        for k, lab in enumerate("xyz"):
            cols[f"wheel_{lab} [m]"] = self.point_wheel[..., k].ravel()
        for k, lab in enumerate("xyz"):
            cols[f"rail_{lab} [m]"] = self.point_rail[..., k].ravel()
        for k, lab in enumerate("xyz"):
            cols[f"n_{lab} [-]"] = self.normal[..., k].ravel()
        return pd.DataFrame(cols)


def scan_lead_angle(sig, F1, d, ax, tan):
    r"""Angle theta (P, G) of the wheel point of each profile line whose surface normal is square
    to the track tangent t, measured about the axle a from the lowest point direction -d.

    The wheel point at profile coordinate y and angle theta is P = c + sig (y + L) a - r(y) e_r
    with e_r = cos(theta) d + sin(theta) f, f = a x d; its normal is parallel to
    sig e_r + F'(y) a, so the condition n . t = 0 reads

    .. math:: \sigma (d\cdot t) \cos\theta + \sigma (f\cdot t) \sin\theta = -F'(y)\,(a\cdot t)

    i.e. R cos(theta - phi) = C; of its two roots the one nearer the lowest point.  An unyawed
    wheel (a . t = 0, d . t = 0) has theta = 0; a yawed one leads or lags by about
    arctan(F' tan psi) -- a few millimetres on the tread, 16 mm ahead on a 70 deg flange at
    12 mrad (the contact the cross-section of the lowest point would miss).
    """
    f = np.cross(ax, d)
    A = sig * np.einsum("pk,pk->p", d, tan)
    B = sig * np.einsum("pk,pk->p", f, tan)
    C = -F1 * np.einsum("pk,pk->p", ax, tan)[:, None]
    R = np.hypot(A, B)[:, None]
    phi = np.arctan2(B, A)[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        acs = np.arccos(np.clip(C / R, -1.0, 1.0))
    t1 = np.angle(np.exp(1j * (phi + acs)))
    t2 = np.angle(np.exp(1j * (phi - acs)))
    return np.where(np.abs(t1) <= np.abs(t2), t1, t2)


class ContactSearch:
    """Contact search for all wheels of one or more wheelsets on a track.

    Parameters
    ----------
    track : Track
    wheel : WheelProfile, optional
        Default S1002 with r0 = 0.46 m.
    rails : RailMounting or (RailMounting, RailMounting), optional
        Mounted rail profile for both rails, or (left, right).  Default UIC60 1:40, gauge 1.435.
    n_wheelsets : int
    flange_back_spacing : float
        m, default 1.360.
    tol : float
        Newton step tolerance on the parameters (rad and m); the reported point is the last
        evaluated one, so its parameter error is below tol and its gap error of order tol^2 / R.
    compiled : {"auto", True, False}
        Run the Newton iteration in the numba kernel of :mod:`railway._kernels` ("auto": when
        numba is installed).  Both implementations solve the same equations; tests compare them.
    tol_linear : float
        A Newton step smaller than this (m or rad) is applied without a further pass; the
        outputs are then linearised about the evaluated point, with errors O(tol_linear^2 / R)
        (1e-6 m gives below 1e-10 m on the gap).  Set it to ``tol`` for full iterations.
    max_iter : int
    reseed_every : int
        On trajectories, run the global tread scan every this many calls (1 = always).
    n_scan : int
        Grid points of the seed scan per zone (uniform in the profile's arc length).
    zone_overlap : float
        Overlap of the tread and flange zones (m) so that a contact at the split is found.
    fd_step : float
        Forward-difference step of the Jacobian (rad or m) when ``jacobian="fd"``.
    jacobian : {"analytic", "fd"}
        Newton Jacobian: analytic (default, see :meth:`_residual_jac`) or forward differences
        (5 P residual evaluations stacked in one vectorised pass).
    n_seeds : int
        Stationary points of the scan refined side by side at a re-seeding (the best by the
        scan's estimate of the gap; 2 by default, more where near-equal minima crowd, e.g. a
        contact-geometry table).
    extrapolate : bool
        Predict the warm start of a trajectory by linear extrapolation of the last two
        solutions (default); False starts from the last solution (for iterations that are not
        a trajectory, e.g. the Newton steps of the rigid contact, where extrapolation across
        a contact jump throws the start far off).
    flange_rail_u_max : float
        The flange candidate searches the rail only on the gauge side, u <= this value (m);
        otherwise the flange tip would pair with the rail crown (parallel normals, but the tip
        is beside the rail, not above it).
    max_penetration : float
        Stationary pairs with a gap below -max_penetration (m) are rejected: they pair a point of
        the flange lying beside the rail head with a rail point of the same normal direction
        (parallel normals, but no physical overlap).  Real penetrations are far smaller.
    """

    def __init__(self, track, wheel=None, rails=None, n_wheelsets=1, flange_back_spacing=1.360,
                 tol=1e-8, max_iter=15, reseed_every=10, n_scan=64, zone_overlap=1e-3,
                 fd_step=1e-7, flange_rail_u_max=-0.020, max_penetration=0.005,
                 jacobian="analytic", tol_linear=1e-6, compiled="auto", extrapolate=True,
                 n_seeds=2):
        self.track = track
        self.wheel = wheel if wheel is not None else WheelProfile.s1002()
        if rails is None:
            rails = RailMounting()
        if isinstance(rails, RailMounting):
            rails = (rails, rails)
        self.rails = tuple(rails)
        if not (isinstance(n_wheelsets, (int, np.integer)) and n_wheelsets >= 1):
            raise InputError(f"n_wheelsets = {n_wheelsets!r} must be a positive integer")
        if not (np.isfinite(flange_back_spacing) and 0.25 <= flange_back_spacing <= 2.0):
            raise InputError(
                f"flange-back spacing {flange_back_spacing!r} m is implausible (expected 0.25 to "
                "2.0 m, e.g. 1.360); it is in metres"
                + (" -- was it given in millimetres?" if flange_back_spacing > 2.0 else ""))
        self.n_wheelsets = int(n_wheelsets)
        self.flange_back_spacing = float(flange_back_spacing)
        self.L = 0.5 * self.flange_back_spacing - self.wheel.y_back
        self.tol, self.max_iter = float(tol), int(max_iter)
        self.reseed_every, self.n_scan = int(reseed_every), int(n_scan)
        self.fd_step = float(fd_step)
        self.max_penetration = float(max_penetration)
        self.max_iter_reseed = 8  # re-seeding with a warm start: seeds beyond reach are dropped
        if jacobian not in ("analytic", "fd"):
            raise InputError(f"jacobian must be 'analytic' or 'fd', got {jacobian!r}")
        self.jacobian = jacobian
        self.tol_linear = float(tol_linear)
        self.extrapolate = bool(extrapolate)
        if not (isinstance(n_seeds, (int, np.integer)) and n_seeds >= 1):
            raise InputError(f"n_seeds = {n_seeds!r} must be a positive integer")
        self.n_seeds = int(n_seeds)
        self._maxstep = np.array([0.02, 0.001, 0.01, 0.001])
        self._wts = np.array([1.0, 1.0, 1e3, 1e3])
        if compiled not in ("auto", True, False):
            raise InputError(f"compiled must be 'auto', True or False, got {compiled!r}")
        self._kernel = None
        self._scan_kernel = None
        if compiled:
            from ._kernels import newton_kernel, scan_kernel

            self._kernel = newton_kernel()
            self._scan_kernel = scan_kernel()
            if self._kernel is None and compiled is True:
                raise ImportError("compiled=True needs numba (pip install numba)")
        w = self.wheel
        bank, off = concatenate([w.poly, self.rails[0].profile.poly, self.rails[1].profile.poly])
        self._bank = bank
        self._off_w, self._off_rl, self._off_rr = off
        # problems for one wheelset: (left tread, left flange, right tread, right flange)
        sig = np.array([1.0, 1.0, -1.0, -1.0])
        cand = np.array([TREAD, FLANGE, TREAD, FLANGE])
        ylo = np.where(cand == TREAD, w.y_split - zone_overlap, w.y_flange_min)
        yhi = np.where(cand == TREAD, w.x_max, w.y_split + zone_overlap)
        mL, mR = self.rails
        ulo = np.where(sig > 0, mL.u_min, mR.u_min)
        uhi = np.where(sig > 0, mL.u_max, mR.u_max)
        uhi = np.where(cand == FLANGE, np.minimum(uhi, flange_rail_u_max), uhi)
        self._unit = dict(sig=sig, cand=cand, ylo=ylo, yhi=yhi, ulo=ulo, uhi=uhi,
                          ow=np.full(4, self._off_w), orr=np.where(sig > 0, self._off_rl, self._off_rr),
                          Y0=np.where(sig > 0, mL.Y0, mR.Y0), Z0=np.where(sig > 0, mL.Z0, mR.Z0),
                          ca=np.where(sig > 0, mL.ca, mR.ca), sa=np.where(sig > 0, mL.sa, mR.sa))
        # scan grids of the tread and flange zones, and the rail tangent-angle tables
        G = self.n_scan
        if G < 8:
            raise InputError(f"n_scan = {n_scan!r}: the seed scan needs at least 8 grid points")
        # scan grids of the whole zones (overlap included), uniform in the profile's arc length
        # so that the steep flank and the tight flange root get as many points per mm of
        # profile as the flat tread
        yz = np.stack([_arc_grid(w, ylo[0], yhi[0], G), _arc_grid(w, ylo[1], yhi[1], G)])
        Fz, F1z, _ = w.poly(yz)
        self._scan = dict(y=yz, r=w.r0 + Fz, F1=F1z)
        self._rail_tab = []
        for m in self.rails:
            ug = np.linspace(m.u_min, m.u_max, 4001)
            Yo, Z, a1, b1, _, _ = m.mounted(ug)
            beta = np.arctan2(b1, a1)  # decreasing along u for a convex head
            order = np.argsort(beta)
            self._rail_tab.append((beta[order], ug[order], Yo[order], Z[order]))
        self._problems = self._tile(self.n_wheelsets)
        self._subset_cache = {}
        self._x = None
        self._x_prev = None
        self._calls = 0

    # ------------------------------------------------------------------------------------
    def _tile(self, n_ws):
        P = 4 * n_ws
        pc = {k: np.tile(v, n_ws) for k, v in self._unit.items()}
        pc["ws"] = np.repeat(np.arange(n_ws), 4)
        pc["L"] = np.full(P, self.L)
        pc["r0"] = np.full(P, self.wheel.r0)
        lo = np.stack([np.full(P, -np.inf), pc["ylo"], np.full(P, -np.inf), pc["ulo"]], axis=1)
        hi = np.stack([np.full(P, np.inf), pc["yhi"], np.full(P, np.inf), pc["uhi"]], axis=1)
        pc["lo"], pc["hi"] = lo, hi
        pc["lo_e"], pc["hi_e"] = lo + 1e-12, hi - 1e-12  # strict-inside bounds
        pc["is_flange"] = pc["cand"] == FLANGE
        return pc

    def _rep(self, pc, k):
        """pc with every array repeated k times (cached: the problem sets are fixed)."""
        cache = self.__dict__.setdefault("_rep_cache", {})
        key = (id(pc), k)
        hit = cache.get(key)
        if hit is not None and hit[0] is pc:
            return hit[1]
        out = {key_: (np.concatenate([v] * k) if isinstance(v, np.ndarray) else v)
               for key_, v in pc.items()}
        if len(cache) > 16:
            cache.clear()
        cache[key] = (pc, out)
        return out

    def _residual_jac(self, x, pc, r_ws, AT):
        """Residuals h (M, 4) of the four contact conditions and their analytic Jacobian.

        With the wheel tangents t_theta (unit), t_y, the rail tangents t_s, t_u and
        n = sigma c/|c|, c = t_s x t_u, the derivatives are (omega the track's Darboux vector)::

            dp/dtheta = r t_theta, dp/dy = t_y, dq/ds = t_s, dq/du = t_u
            dt_theta/dtheta = A (-sin, 0, cos),  dt_y/dtheta = F' t_theta,
            dt_y/dy = A (F'' sin, 0, -F'' cos)
            dt_u/du = R (0, sigma Yo'', Z''),  dt_u/ds = dt_s/du = omega x t_u,
            dt_s/ds = q_ss = r'' + omega' x (R l) + omega x (omega x (R l))
            dn = (I - n n^T) sigma dc / |c|
        """
        M = x.shape[0]
        th, yw, s, u = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
        prof = self._bank.eval_raw(np.concatenate([yw + pc["ow"], u + pc["orr"]]))
        F, F1, F2 = prof[:M, 0], prof[:M, 1], prof[:M, 2]
        v, v1, v2 = prof[M:, 0], prof[M:, 1], prof[M:, 2]
        sig = pc["sig"]
        r = pc["r0"] + F
        st, ct = np.sin(th), np.cos(th)
        zero = np.zeros(M)
        loc = np.stack([r * st, sig * (yw + pc["L"]), -r * ct, ct, zero, st,
                        F1 * st, sig, -F1 * ct, -st, zero, ct, F2 * st, zero, -F2 * ct],
                       axis=1).reshape(M, 5, 3)
        gw = loc @ AT
        p = gw[:, 0] + r_ws
        tth, ty, dtth, dtyy = gw[:, 1], gw[:, 2], gw[:, 3], gw[:, 4]
        # rail
        pos, dpos, ddpos, R, om, dom = self.track._frame_fast(s)
        ca, sa = pc["ca"], pc["sa"]
        a = pc["Y0"] + u * ca - v * sa
        b = pc["Z0"] + u * sa + v * ca
        locr = np.stack([zero, sig * a, b, zero, sig * (ca - v1 * sa), sa + v1 * ca,
                         zero, -sig * v2 * sa, v2 * ca], axis=1).reshape(M, 3, 3)
        gr = locr @ np.swapaxes(R, 1, 2)
        Rl, tu, dtuu = gr[:, 0], gr[:, 1], gr[:, 2]
        q = pos + Rl
        # cross products batched in three calls
        c1 = _cross(np.stack([om, om, dom], axis=1), np.stack([Rl, tu, Rl], axis=1))
        omRl, omtu = c1[:, 0], c1[:, 1]
        ts = dpos + omRl
        qss = ddpos + c1[:, 2] + _cross(om, omRl)
        c3 = _cross(np.stack([ts, qss, ts, omtu, ts], axis=1),
                    np.stack([tu, tu, omtu, tu, dtuu], axis=1))
        c = c3[:, 0]
        cn = np.sqrt(np.einsum("ij,ij->i", c, c))
        n = c * (sig / cn)[:, None]
        d = p - q
        dcs = np.stack([c3[:, 1] + c3[:, 2], c3[:, 3] + c3[:, 4]], axis=1) * (sig / cn)[:, None, None]
        dn = dcs - np.einsum("mjk,mk->mj", dcs, n)[:, :, None] * n[:, None, :]  # (M, 2, 3)
        # residuals and Jacobian via stacked dot products
        Lv = np.stack([n, n, d, d,                                  # h
                       n, n, dn[:, 0], dn[:, 1],                    # dh1/d(th, y, s, u)
                       n, n, dn[:, 0], dn[:, 1],                    # dh2
                       ts, ts, ts, ts, d, d,                        # dh3
                       tu, tu, tu, tu, d, d], axis=1)               # dh4
        Rv = np.stack([tth, ty, ts, tu,
                       dtth, zero[:, None] * tth, tth, tth,
                       tth, dtyy, ty, ty,
                       tth, ty, -ts, -tu, qss, omtu,
                       tth, ty, -ts, -tu, omtu, dtuu], axis=1)
        dots = np.einsum("mkj,mkj->mk", Lv, Rv)
        h = dots[:, :4]
        J = np.empty((M, 4, 4))
        J[:, 0, :] = dots[:, 4:8]
        J[:, 0, 1] = 0.0
        J[:, 1, :] = dots[:, 8:12]
        J[:, 1, 0] *= F1
        J[:, 2, 0] = r * dots[:, 12]
        J[:, 2, 1] = dots[:, 13]
        J[:, 2, 2] = dots[:, 14] + dots[:, 16]
        J[:, 2, 3] = dots[:, 15] + dots[:, 17]
        J[:, 3, 0] = r * dots[:, 18]
        J[:, 3, 1] = dots[:, 19]
        J[:, 3, 2] = dots[:, 20] + dots[:, 22]
        J[:, 3, 3] = dots[:, 21] + dots[:, 23]
        info = dict(p=p, q=q, n=n, d=d, r=r, F1=F1, F2=F2, v1=v1, v2=v2, R=R, Rl=Rl, ts=ts,
                    qss=qss, tth=tth, ty=ty, tu=tu, dn=dn)
        return h, J, info

    def _residual(self, x, pc, r_ws, AT, full=False):
        """Residuals h (M, 4) of the four contact conditions at parameters x (M, 4)."""
        M = x.shape[0]
        th, yw, s, u = x[:, 0], x[:, 1], x[:, 2], x[:, 3]
        prof = self._bank.eval_raw(np.concatenate([yw + pc["ow"], u + pc["orr"]]))
        F, F1 = prof[:M, 0], prof[:M, 1]
        v, v1 = prof[M:, 0], prof[M:, 1]
        sig = pc["sig"]
        r = pc["r0"] + F
        st, ct = np.sin(th), np.cos(th)
        zero = np.zeros(M)
        loc = np.stack([r * st, sig * (yw + pc["L"]), -r * ct, ct, zero, st,
                        F1 * st, sig, -F1 * ct], axis=1).reshape(M, 3, 3)
        gw = loc @ AT
        p = gw[:, 0] + r_ws
        # rail
        pos, dpos, _, R, om, _ = self.track._frame_fast(s)
        ca, sa = pc["ca"], pc["sa"]
        a = pc["Y0"] + u * ca - v * sa
        b = pc["Z0"] + u * sa + v * ca
        a1 = ca - v1 * sa
        b1 = sa + v1 * ca
        locr = np.stack([zero, sig * a, b, zero, sig * a1, b1], axis=1).reshape(M, 2, 3)
        gr = locr @ np.swapaxes(R, 1, 2)
        Rl = gr[:, 0]
        q = pos + Rl
        ts = dpos + _cross(om, Rl)
        tu = gr[:, 1]
        n = _cross(ts, tu)
        n *= (sig / np.sqrt(np.einsum("ij,ij->i", n, n)))[:, None]
        d = p - q
        h = np.einsum("mkj,mkj->mk", np.stack([n, n, d, d], axis=1),
                      np.stack([gw[:, 1], gw[:, 2], ts, tu], axis=1))
        if not full:
            return h
        return h, dict(p=p, q=q, n=n, d=d, r=r, F1=F1, F2=prof[:M, 2], v1=v1, v2=prof[M:, 2],
                       R=R, Rl=Rl, ts=ts)

    def _newton(self, x, pc, r_ws, AP, max_iter=None):
        """Vectorised Newton on all problems; returns x, residual, converged, passes, info.

        Only the problems not yet finished are evaluated in a pass.
        """
        if self._kernel is not None and self.jacobian == "analytic":
            return self._newton_compiled(x, pc, r_ws, AP, max_iter or self.max_iter)
        AT = np.swapaxes(AP, 1, 2)
        max_iter = max_iter or self.max_iter
        P = x.shape[0]
        hstep = self.fd_step
        E = np.eye(4) * hstep
        lo_all, hi_all = pc["lo"], pc["hi"]
        maxstep = self._maxstep
        wts = self._wts  # merit weights (h3, h4 are lengths in m)
        x = x.copy()
        # a last step below tol_linear is applied without another pass, with the outputs
        # linearised about the evaluated point (error O(|dx|^2)); analytic Jacobian only
        tol_lin = max(self.tol, self.tol_linear) if self.jacobian == "analytic" else self.tol
        dx_fin = np.zeros_like(x)
        conv = np.zeros(P, dtype=bool)
        done = np.zeros(P, dtype=bool)
        was_clipped = np.zeros(P, dtype=bool)
        x_acc = x.copy()
        phi_acc = np.full(P, np.inf)
        dx_acc = np.zeros_like(x)
        alpha = np.ones(P)
        H0_all = np.zeros((P, 4))
        info_all = None
        idx = None  # None: all problems active
        for it in range(1, max_iter + 1):
            if idx is None:
                xa, pca, ra, Aa, lo, hi = x, pc, r_ws, AT, lo_all, hi_all
            else:
                xa = x[idx]
                pca = {k: (v[idx] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
                ra, Aa, lo, hi = r_ws[idx], AT[idx], lo_all[idx], hi_all[idx]
            n = xa.shape[0]
            if self.jacobian == "analytic":
                H0, J, info = self._residual_jac(xa, pca, ra, Aa)
            else:
                X = np.concatenate([xa, xa + E[0], xa + E[1], xa + E[2], xa + E[3]])
                H = self._residual(X, self._rep(pca, 5), np.concatenate([ra] * 5),
                                   np.concatenate([Aa] * 5))
                H0 = H[:n]
                info = self._residual_jac(xa, pca, ra, Aa)[2]  # outputs at the base points
                J = np.stack([(H[(k + 1) * n:(k + 2) * n] - H0) for k in range(4)], axis=2) / hstep
            with np.errstate(all="ignore"):
                try:
                    dx = -np.linalg.solve(J, H0[:, :, None])[:, :, 0]
                except np.linalg.LinAlgError:
                    dx = np.zeros_like(H0)
                    ok = np.abs(np.linalg.det(J)) > 1e-300
                    dx[ok] = -np.linalg.solve(J[ok], H0[ok][:, :, None])[:, :, 0]
            dx = np.where(np.isfinite(dx), dx, 0.0)
            scale = np.min(np.minimum(1.0, maxstep / (np.abs(dx) + 1e-300)), axis=1)
            dx *= scale[:, None]
            if idx is None:
                H0_all = H0
                info_all = info
                sl = slice(None)
            else:
                H0_all[idx] = H0
                for k, v in info.items():
                    info_all[k][idx] = v
                sl = idx
            # backtracking across passes on the merit |W h|^2: a step that does not reduce it
            # is retried from the last accepted point with a quarter of its length
            phi = np.sum((H0 * wts) ** 2, axis=1)
            pa, al = phi_acc[sl], alpha[sl]
            accept = (phi <= pa * (1.0 - 1e-4 * al)) | (phi < 1e-26) | ~np.isfinite(pa)
            cv = accept & ((np.max(np.abs(dx), axis=1) < tol_lin) | (phi < 1e-26))
            dx_fin[sl] = np.where(cv[:, None], dx, 0.0)
            al = np.where(accept, 1.0, 0.25 * al)
            xacc = np.where(accept[:, None], xa, x_acc[sl])
            dxacc = np.where(accept[:, None], dx, dx_acc[sl])
            xn = xacc + al[:, None] * dxacc
            clipped = accept & np.any((xn < lo) | (xn > hi), axis=1)
            stuck = (clipped & was_clipped[sl]) | (al < 1e-4)
            was_clipped[sl] = np.where(accept, clipped, was_clipped[sl])
            alpha[sl], x_acc[sl], dx_acc[sl] = al, xacc, dxacc
            phi_acc[sl] = np.where(accept, phi, pa)
            conv[sl] = cv
            dn = cv | stuck
            x[sl] = np.where(dn[:, None], xa, np.clip(xn, lo, hi))
            done[sl] = dn
            if np.all(done):
                break
            idx = np.nonzero(~done)[0]
        if self.jacobian == "analytic" and np.any(dx_fin):
            x = x + dx_fin
            info_all = self._linear_update(info_all, dx_fin)
        conv &= self._minimum(info_all)
        return x, H0_all, conv, it, info_all

    @staticmethod
    def _minimum(info):
        """Saddles are not contacts: a converged stationary point of the gap is a contact only
        where the gap has a minimum across the profiles, i.e. where the relative lateral
        curvature B = (k_wheel_lateral + k_rail_lateral)/2 is positive.  Where a concave wheel
        profile is more curved than the convex rail head under it (B < 0: e.g. the S1002 tread
        near 6 mm inboard of the taping line, radius 234 mm, on the UIC60 R300 crown) the
        stationary point is a maximum of the gap along the profile between two minima -- the
        contacts lie at those minima.  Hertz has no meaning there (its ellipse would be
        clipped to an elongated one, with semi-axes of decimetres and forces of hundreds of kN
        from micrometres of penetration)."""
        F1, F2, v1, v2 = info["F1"], info["F2"], info["v1"], info["v2"]
        B = 0.5 * (-F2 / (1.0 + F1**2) ** 1.5 - v2 / (1.0 + v1**2) ** 1.5)
        return B > 0.0

    def _newton_compiled(self, x, pc, r_ws, AP, max_iter):
        """The same Newton iteration in the compiled kernel of :mod:`railway._kernels`."""
        A = np.ascontiguousarray(AP)
        b, f = self._bank, self.track.pp_frame
        tol_lin = max(self.tol, self.tol_linear)
        X, H0, conv, it, gap, S, V = self._kernel(
            np.ascontiguousarray(x, dtype=float), pc["sig"], pc["r0"], pc["L"], pc["ow"],
            pc["orr"], pc["Y0"], pc["Z0"], pc["ca"], pc["sa"], pc["lo"], pc["hi"],
            np.ascontiguousarray(r_ws), A, b._inner, b.breaks, b._stack, f._inner, f.breaks,
            f._stack, tol_lin, max_iter, self._maxstep, self._wts)
        return X, H0, conv, int(it), dict(gap=gap, S=S, V=V)

    @staticmethod
    def _linear_update(info, dx):
        """First-order update of the contact outputs for a parameter step dx (P, 4)."""
        info = dict(info)
        dth, dy, ds, du = dx[:, 0:1], dx[:, 1:2], dx[:, 2:3], dx[:, 3:4]
        info["p"] = info["p"] + (info["r"][:, None] * dth) * info["tth"] + dy * info["ty"]
        info["q"] = info["q"] + ds * info["ts"] + du * info["tu"]
        n = info["n"] + ds * info["dn"][:, 0] + du * info["dn"][:, 1]
        info["n"] = n / np.sqrt(np.einsum("ij,ij->i", n, n))[:, None]
        info["d"] = info["p"] - info["q"]
        info["r"] = info["r"] + info["F1"] * dx[:, 1]
        info["Rl"] = info["Rl"] + du * info["tu"]
        return info

    def _seed_scan(self, pc, r_ws, A, s_ws, second=False, brackets=False, ranks=None):
        """Seeds (P, 4) from a coarse scan of each zone in the track cross-section.

        With ``second=True`` a list [best, second best] is returned, with ``ranks=k`` a list of
        the k best (``second`` is ``ranks=2``).  With ``brackets=True``
        each seed array has three more columns: 1.0 where the seed is a sign change of the
        fourth condition (a stationary point lies near) else 0.0, and the profile coordinates
        (m) of the grid points one interval either side of it, a bracket of that stationary
        point for :meth:`_robust`.

        For grid points y_i of the zone, the lowest point of the wheel circle (towards the rail)
        and its profile tangent angle beta_i in the cross-section are computed; the rail point
        u_i with the same tangent angle (normals parallel, the first two conditions) comes from
        the monotonic tangent-angle table of the convex rail head.  Along the grid the remaining
        condition h4_i = (P_i - Q_i) . t_u changes sign at the stationary points; the seed is the
        sign change with the smallest gap g_i = (P_i - Q_i) . n_i (global over the zone, so
        jumps of the contact across the tread are found), or the smallest gap when there is
        no sign change.
        """
        P = pc["sig"].size
        ws = pc["ws"]
        # frames and directions per wheelset, then per problem
        fr_pos, _, fr_R, _ = self.track._frame(s_ws)
        up_w = fr_R[:, :, 2]
        ax_w = A[:, :, 1]  # axle direction
        d_w = up_w - np.sum(up_w * ax_w, axis=1)[:, None] * ax_w
        d_w /= np.linalg.norm(d_w, axis=1)[:, None]  # lowest point direction is -d
        fr_pos, fr_R, ax, d = fr_pos[ws], fr_R[ws], ax_w[ws], d_w[ws]
        tan, lat, up = fr_R[:, :, 0], fr_R[:, :, 1], fr_R[:, :, 2]
        sig = pc["sig"]
        yg, rg, F1g = (self._scan[k][pc["cand"]] for k in ("y", "r", "F1"))  # (P, G)
        n_rank = int(ranks) if ranks else (2 if second else 1)
        listed = bool(ranks) or second
        if self._scan_kernel is not None:  # the same scan, compiled (railway._kernels)
            dl = np.einsum("pkj,pk->pj", A[ws], -d)
            theta = np.arctan2(dl[:, 0], -dl[:, 2])
            (b0, u0, Y0, Z0), (b1, u1, Y1, Z1) = self._rail_tab
            out = np.empty((n_rank, P, 7))
            self._scan_kernel(np.ascontiguousarray(r_ws[ws]), ax, d, fr_pos, tan, lat, up, sig,
                              self.L, yg, rg, F1g, sig > 0, b0, u0, Y0, Z0, b1, u1, Y1, Z1,
                              pc["ulo"], pc["uhi"], theta, s_ws[ws], out.shape[0], out)
            if not brackets:
                out = out[:, :, :4]
            return list(out) if listed else out[0]
        # the point of each profile line whose normal is square to the track tangent (the
        # contact leads or lags the lowest point of a yawed wheel): e_r = cos(th) d + sin(th) f
        th = scan_lead_angle(sig, F1g, d, ax, tan)  # (P, G)
        f = np.cross(ax, d)
        e_r = np.cos(th)[:, :, None] * d[:, None, :] + np.sin(th)[:, :, None] * f[:, None, :]
        ctr = r_ws[ws][:, None, :] + (sig[:, None] * (yg + self.L))[:, :, None] * ax[:, None, :]
        pts = ctr - rg[:, :, None] * e_r
        rel = pts - fr_pos[:, None, :]
        Yo = np.einsum("pgk,pk->pg", rel, lat) * sig[:, None]
        Zw = np.einsum("pgk,pk->pg", rel, up)
        xi = np.einsum("pgk,pk->pg", rel, tan)
        ty = -F1g[:, :, None] * e_r + (sig[:, None, None] * ax[:, None, :])
        beta = np.arctan2(np.einsum("pgk,pk->pg", ty, up),
                          np.einsum("pgk,pk->pg", ty, lat) * sig[:, None])
        ug = np.empty_like(beta)
        Yr = np.empty_like(beta)
        Zr = np.empty_like(beta)
        for side, (b_tab, u_tab, Y_tab, Z_tab) in zip((1.0, -1.0), self._rail_tab):
            m = sig == side
            ug[m] = np.interp(beta[m], b_tab, u_tab)
            Yr[m] = np.interp(beta[m], b_tab, Y_tab)
            Zr[m] = np.interp(beta[m], b_tab, Z_tab)
        cb, sb = np.cos(beta), np.sin(beta)
        dY, dZ = Yo - Yr, Zw - Zr
        ok = (ug > pc["ulo"][:, None]) & (ug < pc["uhi"][:, None])
        gap = np.where(ok, -dY * sb + dZ * cb, np.inf)
        h4 = dY * cb + dZ * sb
        change = (h4[:, :-1] * h4[:, 1:] <= 0.0) & ok[:, :-1] & ok[:, 1:]
        t = np.clip(h4[:, :-1] / np.where(change, h4[:, :-1] - h4[:, 1:], 1.0), 0.0, 1.0)
        with np.errstate(invalid="ignore"):
            gmid = np.where(change, gap[:, :-1] + t * (gap[:, 1:] - gap[:, :-1]), np.inf)
        ii = np.arange(P)
        j0 = np.argmin(np.where(np.isfinite(gap), gap, 1e300), axis=1)
        dl = np.einsum("pkj,pk->pj", A[ws], -d)
        theta = np.arctan2(dl[:, 0], -dl[:, 2])
        seeds = []
        j = np.zeros(P, dtype=int)
        for rank in range(n_rank):
            if rank:  # the next-best stationary point (near-equal minima of the tread gap)
                gmid = gmid.copy()
                gmid[ii, j] = np.inf
            j = np.argmin(gmid, axis=1)
            has = np.isfinite(gmid[ii, j])
            jj = np.where(has, j, np.minimum(j0, yg.shape[1] - 2))
            tj = np.where(has, t[ii, j], np.where(j0 == yg.shape[1] - 1, 1.0, 0.0))

            def lerp(a, jj=jj, tj=tj):
                return a[ii, jj] + tj * (a[ii, jj + 1] - a[ii, jj])

            cols = [theta - lerp(th), lerp(yg), s_ws[ws] + lerp(xi), lerp(ug)]
            if brackets:
                G = yg.shape[1]
                cols += [has.astype(float), yg[ii, np.maximum(jj - 1, 0)],
                         yg[ii, np.minimum(jj + 2, G - 1)]]
            seeds.append(np.stack(cols, axis=1))
        return seeds if listed else seeds[0]

    def _outputs(self, x, pc, info):
        """(gap (P,), S (P, 11), V (P, 3, 3)) from the numpy Newton's intermediate arrays."""
        if "S" in info:
            return info["gap"], info["S"], info["V"]
        n, d, R = info["n"], info["d"], info["R"]
        gap = np.einsum("ij,ij->i", d, n)
        F1, F2, v1, v2_, r = info["F1"], info["F2"], info["v1"], info["v2"], info["r"]
        wq = 1.0 + F1**2
        nR = np.einsum("ij,ijk->ik", n, R)  # normal in the track frame (t, lateral, up)
        k_rx = -np.einsum("ij,ij->i", n, info["qss"]) / np.einsum("ij,ij->i", info["ts"], info["ts"])
        S = np.stack([x[:, 0], x[:, 1], x[:, 2], x[:, 3], r,
                      np.arctan2(-pc["sig"] * nR[:, 1], nR[:, 2]), np.arctan(-F1),
                      1.0 / (r * np.sqrt(wq)), -F2 / wq**1.5, k_rx, -v2_ / (1.0 + v1**2) ** 1.5],
                     axis=1)
        return gap, S, np.stack([info["p"], info["q"], n], axis=1)

    def _finish(self, x, H0, conv, pc, info, iterations):
        """Validity, outputs and per-wheel (tread, flange) arrays."""
        P = x.shape[0]
        gap, S, V = self._outputs(x, pc, info)
        inside = np.all((x > pc["lo_e"]) & (x < pc["hi_e"]), axis=1)
        valid = conv & inside & (gap > -self.max_penetration) & np.isfinite(gap)
        # duplicates in the zone overlap: keep the candidate whose own zone holds the point
        v2, x2 = valid.reshape(-1, 2), x.reshape(-1, 2, 4)
        same = (v2[:, 0] & v2[:, 1] & (np.abs(x2[:, 0, 1] - x2[:, 1, 1]) < 1e-5)
                & (np.abs(x2[:, 0, 3] - x2[:, 1, 3]) < 1e-5))
        if np.any(same):
            in_flange = x2[:, 0, 1] < self.wheel.y_split
            valid &= ~np.stack([same & in_flange, same & ~in_flange], axis=1).reshape(-1)
        nanm = np.where(valid, 1.0, np.nan)
        S = (S * nanm[:, None]).reshape(P // 2, 2, 11)
        V = (V * nanm[:, None, None]).reshape(P // 2, 2, 3, 3)
        gap = np.where(valid, gap, np.inf).reshape(P // 2, 2)
        valid = valid.reshape(P // 2, 2)
        return ContactResult(
            point_wheel=V[:, :, 0], point_rail=V[:, :, 1], normal=V[:, :, 2], gap=gap,
            penetration=-gap, in_contact=valid & (gap <= 0.0), valid=valid,
            theta=S[..., 0], y_wheel=S[..., 1], s_rail=S[..., 2], u_rail=S[..., 3],
            rolling_radius=S[..., 4], contact_angle=S[..., 5], wheel_angle=S[..., 6],
            k_wheel_rolling=S[..., 7], k_wheel_lateral=S[..., 8], k_rail_rolling=S[..., 9],
            k_rail_lateral=S[..., 10], flange=pc["is_flange"].reshape(P // 2, 2),
            residual=np.max(np.abs(H0), axis=1).reshape(P // 2, 2), iterations=iterations)

    def _check_pose(self, r_ws, A, s_ws, n_ws):
        if (type(r_ws) is np.ndarray and type(A) is np.ndarray and type(s_ws) is np.ndarray
                and r_ws.dtype == np.float64 and A.dtype == np.float64 and s_ws.dtype == np.float64
                and r_ws.shape == (n_ws, 3) and A.shape == (n_ws, 3, 3) and s_ws.shape == (n_ws,)
                and np.isfinite(r_ws.sum() + A.sum() + s_ws.sum())):
            return r_ws, A, s_ws  # fast path on trajectories (a NaN or inf makes the sum non-finite)
        r_ws = np.asarray(r_ws, dtype=float).reshape(n_ws, 3)
        A = np.asarray(A, dtype=float).reshape(n_ws, 3, 3)
        s_ws = np.asarray(s_ws, dtype=float).reshape(n_ws)
        for name, arr in (("wheelset position", r_ws), ("wheelset rotation", A), ("arc length s", s_ws)):
            bad = ~np.isfinite(arr)
            if np.any(bad):
                idx = np.unravel_index(int(np.argmax(bad)), arr.shape)
                raise InputError(f"contact search: {name}{list(map(int, idx))} = {float(arr[idx])!r} is not finite")
        return r_ws, A, s_ws

    # ------------------------------------------------------------------------------------
    def search(self, r_ws, A, s_ws, warm=True, scan=None):
        """Contact candidates of all wheels for the given wheelset poses.

        Parameters
        ----------
        r_ws : (n_wheelsets, 3) array_like
            Wheelset centres (global, m).
        A : (n_wheelsets, 3, 3) array_like
            Wheelset orientations (columns: forward, axle to the left, up), without spin.
        s_ws : (n_wheelsets,) array_like
            Track arc length near each wheelset (m), used to evaluate the track frame for seeds.
        warm : bool
            Warm-start from the previous call (trajectory mode).
        scan : bool, optional
            Force (True) or suppress (False) the global tread scan; default: scan when there is no
            warm start, every ``reseed_every`` calls, or when a warm start failed.

        Returns
        -------
        ContactResult
        """
        n_ws = self.n_wheelsets
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, n_ws)
        return self._search(r_ws, A, s_ws, self._problems, warm, scan, store=True)

    def _search(self, r_ws, A, s_ws, pc, warm, scan, store):
        ws = pc["ws"]
        rP, AP = r_ws[ws], A[ws]
        have_warm = warm and self._x is not None and store and self._x.shape[0] == ws.size
        if scan is None:
            scan = (not have_warm) or (self._calls % self.reseed_every == 0)
        self._calls += 1
        if store:
            s_prev, self._s_prev = getattr(self, "_s_prev", s_ws), s_ws.copy()
        if have_warm:
            # predictor: linear extrapolation of the last two solutions (theta, y, u); the rail
            # arc length moves with the wheelset
            x0 = self._x.copy()
            xp = self._x_prev if self.extrapolate else None
            if xp is not None and xp.shape == x0.shape:
                ext = 2.0 * x0 - xp
                ok = np.isfinite(ext)
                x0 = np.where(ok, np.clip(ext, pc["lo"], pc["hi"]), x0)
            x0[:, 2] = self._x[:, 2] + (s_ws - s_prev)[ws]
            bad = ~np.isfinite(x0)
            if np.any(bad):
                x0 = np.where(bad, self._seed_scan(pc, r_ws, A, s_ws), x0)
        if have_warm and not scan:
            # only candidates that had a stationary point last time are refined; the others are
            # picked up by the periodic re-seeding when they come into reach
            act = self._valid_prev
            key = act.tobytes()
            if self._subset_cache.get("key") != key:
                ia = np.nonzero(act)[0]
                self._subset_cache = dict(key=key, ia=ia, wsi=ws[ia], pc={
                    k: (v[ia] if isinstance(v, np.ndarray) else v) for k, v in pc.items()})
            sc = self._subset_cache
            ia, pcs, wsi = sc["ia"], sc["pc"], sc["wsi"]
            xa, Ha, ca, it, infa = self._newton(x0[ia], pcs, r_ws[wsi], A[wsi])
            va, ga = self._valid_gap(xa, ca, infa, pcs)
            if not np.all(va):  # a contact that existed was lost: re-seed those problems
                bad = np.nonzero(~va)[0]
                pcb = {k: (v[bad] if isinstance(v, np.ndarray) else v) for k, v in pcs.items()}
                xs = self._seed_scan(pc, r_ws, A, s_ws)[ia[bad]]
                x2, H2, c2, it2, info2 = self._newton(xs, pcb, r_ws[wsi[bad]], A[wsi[bad]])
                v2, g2 = self._valid_gap(x2, c2, info2, pcb)
                j = bad[v2]
                xa[j], Ha[j], ca[j] = x2[v2], H2[v2], c2[v2]
                for k in infa:
                    infa[k][j] = info2[k][v2]
                it += it2
            if ia.size == ws.size:
                x, H0, conv, info = xa, Ha, ca, infa
            else:
                x, H0, conv = x0.copy(), np.full(x0.shape, np.inf), np.zeros(ws.size, dtype=bool)
                x[ia], H0[ia], conv[ia] = xa, Ha, ca
                info = {}
                for k, v in infa.items():
                    full = np.full((ws.size,) + v.shape[1:], np.nan)
                    full[ia] = v
                    info[k] = full
            res = self._finish(x, H0, conv, pc, info, it)
            if store:
                self._x_prev, self._x = self._x, x
                self._valid_prev = res.valid.ravel()
            return res
        # re-seeding: the two best stationary points of the scan (and the warm start), refined
        # side by side; the lowest valid gap wins
        scan_out = self._seed_scan(pc, r_ws, A, s_ws, brackets=True, ranks=self.n_seeds)
        seeds = [q[:, :4] for q in scan_out]
        if have_warm:
            seeds.insert(0, x0)
        return self._multistart(np.concatenate(seeds), pc, rP, AP, store, 0,
                                max_iter=self.max_iter_reseed if have_warm else None,
                                scan_out=scan_out)

    def _valid_gap(self, x, conv, info, pc):
        """Validity (converged inside the zones, plausible gap) and gap (inf when invalid)."""
        inside = np.all((x > pc["lo_e"]) & (x < pc["hi_e"]), axis=1)
        g = info["gap"] if "gap" in info else np.einsum("ij,ij->i", info["d"], info["n"])
        ok = conv & inside & (g > -self.max_penetration)
        return ok, np.where(ok, g, np.inf)

    def _multistart(self, x0, pc, rP, AP, store, it0, max_iter=None, scan_out=None,
                    return_all=False):
        """Newton from several seeds per problem side by side; keep the lowest valid gap.

        With ``scan_out`` (the bracketed scan seeds), scan seeds at a stationary point that
        Newton did not solve are handed to :meth:`_rescue`; its result replaces the Newton
        result where its gap is lower.  With ``return_all`` the Newton solutions of every seed
        (m, P, 4) and their gaps (m, P) (+inf where invalid) are returned as well.
        """
        P = rP.shape[0]
        m = x0.shape[0] // P
        pcm = self._rep(pc, m)
        x, H0, conv, it, info = self._newton(x0, pcm, np.concatenate([rP] * m),
                                             np.concatenate([AP] * m), max_iter=max_iter)
        _, g = self._valid_gap(x, conv, info, pcm)
        g = g.reshape(m, P)
        x_all, g_all = x.reshape(m, P, 4).copy(), g.copy()
        # seeds that Newton did not solve (converged inside the zones; a solved seed may still
        # be invalid by a too deep penetration, which no second attempt changes)
        solved = (conv & np.all((x > pcm["lo_e"]) & (x < pcm["hi_e"]), axis=1)).reshape(m, P)
        if scan_out is not None:
            # a scan seed at a stationary point that Newton could not solve is refined by
            # _rescue, unless a solved seed already gave a lower gap
            fail = np.stack([(q[:, 4] > 0.5) for q in scan_out]) & ~solved[m - len(scan_out):]
            lost = np.any(fail, axis=0)
            scan_out = [np.where(f[:, None], q, np.where(np.arange(q.shape[1]) == 4, 0.0, q))
                        for f, q in zip(fail, scan_out)]
        else:
            lost = ~np.any(solved, axis=0)
        best = np.argmin(g, axis=0)  # first seed (the warm start) wins ties
        sel = best * P + np.arange(P)
        info1 = {k: v[sel] for k, v in info.items()}
        x, H0, conv = x[sel], H0[sel], conv[sel]
        if scan_out is not None and np.any(lost):
            bad = np.nonzero(lost)[0]
            pcb = {k: (v[bad] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
            x2, H2, c2, info2, it2 = self._rescue(pcb, rP[bad], AP[bad], [q[bad] for q in scan_out],
                                                  newton=max_iter is not None)
            v2, g2 = self._valid_gap(x2, c2, info2, pcb)
            v2 &= g2 < g[best, np.arange(P)][bad]
            if np.any(v2):
                info1 = self._gsv(x, pc, info1)
                j = bad[v2]
                x[j], H0[j], conv[j] = x2[v2], H2[v2], c2[v2]
                for k in info1:
                    info1[k][j] = info2[k][v2]
            it += it2
        res = self._finish(x, H0, conv, pc, info1, it0 + it)
        if store:
            self._x_prev, self._x = None, x
            self._valid_prev = res.valid.ravel()
        if return_all:
            return res, x_all, g_all, x
        return res

    # ------------------------------------------------------------------------------------
    # stateless interface: for a force element whose search state is frozen between the
    # accepted steps of an integrator (railway.wheel_rail), nothing here reads or changes the
    # warm start of :meth:`search`
    def scan_seeds(self, r_ws, A, s_ws, ranks=None):
        """Seeds of the global cross-section scan at the given poses (no state is used or kept).

        Returns a list of ``ranks`` (default ``n_seeds``) arrays (P, 7): the seed (theta, y, s,
        u), a flag (1.0 where a stationary point lies near) and its bracket in y (see
        :meth:`_seed_scan`); P = 4 n_wheelsets problems, ordered wheelset, side, candidate.
        """
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, self.n_wheelsets)
        return self._seed_scan(self._problems, r_ws, A, s_ws, brackets=True,
                               ranks=ranks or self.n_seeds)

    def solve(self, seeds, r_ws, A, s_ws, scan_out=None, max_iter=None):
        """Contacts from explicit seeds, without any state (a pure function of its arguments).

        Newton runs from every seed of every problem side by side; per problem the lowest valid
        gap wins (ties: the first seed).  ``scan_out`` (from :meth:`scan_seeds`, whose seeds
        must be the last ones of ``seeds``) lets seeds that Newton cannot solve be refined by
        the robust route (:meth:`_robust`).

        Parameters
        ----------
        seeds : sequence of (P, 4) arrays
        r_ws, A, s_ws : see :meth:`search`

        Returns
        -------
        res : ContactResult
        x_all : (m, P, 4) ndarray
            Newton solution from every seed (before the robust route).
        g_all : (m, P) ndarray
            Their gaps (m), +inf where invalid.
        x_best : (P, 4) ndarray
            The parameters of ``res``.
        """
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, self.n_wheelsets)
        pc = self._problems
        ws = pc["ws"]
        x0 = np.concatenate([np.asarray(q, dtype=float)[:, :4] for q in seeds])
        return self._multistart(x0, pc, r_ws[ws], A[ws], False, 0, max_iter=max_iter,
                                scan_out=scan_out, return_all=True)

    def solve_pairs(self, x0, problem, r_ws, A, s_ws, robust=None, n_sample=96, secondary=None):
        """Contacts from explicit (seed, problem) pairs, without any state.

        Newton runs from every seed ``x0[k]`` (K, 4) for the problem ``problem[k]`` (an index
        into the P = 4 n_wheelsets problems; a problem may have several seeds or none); per
        problem the lowest valid gap wins (ties: the first pair).  Problems without a pair, or
        whose pairs all fail, have no contact (``valid`` False).  Cheaper than :meth:`solve` on
        trajectories, where only the candidates that had a contact at the last accepted step
        need iterating (no robust refinement here: that is :meth:`solve` with scan seeds).

        ``robust`` (P,) bool: problems that, when no pair gives them a valid contact, are
        refined by the robust minimisation of the profile-line gap over their whole zone
        (:func:`railway._kernels.reduced_min`, ``n_sample`` samples then golden-section search):
        a contact at the joint of two profile sections or a nearly conformal one, where Newton
        on the four conditions does not converge.

        ``secondary`` (m): also return, in ``res.extra["secondary"]``, a second contact patch
        per candidate: the lowest penetrating pair solution at least ``secondary`` away on the
        wheel profile from the primary one (two penetrating minima of the gap carry load
        together, so that the force stays continuous where the lowest minimum changes).

        Returns
        -------
        res : ContactResult
        x_pairs : (K, 4) ndarray
            Newton solution of every pair.
        g_pairs : (K,) ndarray
            Their gaps (m), +inf where invalid.
        """
        r_ws, A, s_ws = self._check_pose(r_ws, A, s_ws, self.n_wheelsets)
        pc = self._problems
        ws = pc["ws"]
        P = ws.size
        problem = np.asarray(problem, dtype=np.int64)
        x0 = np.asarray(x0, dtype=float).reshape(-1, 4)
        if problem.size:
            pck = {k: (v[problem] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
            xk, Hk, ck, it, infk = self._newton(x0, pck, r_ws[ws[problem]], A[ws[problem]])
            _, gk = self._valid_gap(xk, ck, infk, pck)
            gsv = self._gsv(xk, pck, infk)
        else:
            xk, Hk, ck, it, gk = x0.copy(), np.zeros((0, 4)), np.zeros(0, bool), 0, np.zeros(0)
            gsv = dict(gap=np.zeros(0), S=np.zeros((0, 11)), V=np.zeros((0, 3, 3)))
        # per problem: the pair with the lowest valid gap (the first one on ties)
        x = np.full((P, 4), np.nan)
        H0 = np.full((P, 4), np.inf)
        conv = np.zeros(P, dtype=bool)
        info = dict(gap=np.full(P, np.inf), S=np.full((P, 11), np.nan), V=np.full((P, 3, 3), np.nan))
        if problem.size:
            order = np.lexsort((np.arange(problem.size), gk, problem))  # problem, gap, pair
            first = order[np.r_[True, problem[order][1:] != problem[order][:-1]]]
            p = problem[first]
            x[p], H0[p], conv[p] = xk[first], Hk[first], ck[first] & np.isfinite(gk[first])
            for key in info:
                info[key][p] = gsv[key][first]
        x = np.where(np.isnan(x), pc["lo"].clip(-1.0, 1.0), x)  # placeholders of problems without pairs
        if robust is not None:
            g_best = np.where(conv, info["gap"], np.inf)
            ok_best = conv & np.all((x > pc["lo_e"]) & (x < pc["hi_e"]), axis=1) & (g_best > -self.max_penetration)
            todo = np.flatnonzero(np.asarray(robust, bool) & ~ok_best)
            if todo.size:
                xr, Hr, cr, infr = self._robust_zone(todo, x, r_ws, A, n_sample)
                x[todo], H0[todo], conv[todo] = xr, Hr, cr
                for key in info:
                    info[key][todo] = infr[key]
        res = self._finish(x, H0, conv, pc, info, it)
        if secondary is not None:
            res.extra["secondary"] = self._secondary(res, problem, xk, Hk, ck, gk, gsv, secondary)
        return res, xk, gk

    def _secondary(self, res, problem, xk, Hk, ck, gk, gsv, separation):
        """A second contact patch per candidate: the lowest *penetrating* pair solution whose wheel
        profile coordinate differs from the primary contact's by more than ``separation`` (m) and
        that is not the other zone's primary contact of the same wheel (closer than 0.1 mm to it);
        a ContactResult like ``res`` (invalid where there is none)."""
        pc = self._problems
        P = pc["ws"].size
        y1 = res.y_wheel.ravel()
        x2 = np.full((P, 4), np.nan)
        H2 = np.full((P, 4), np.inf)
        c2 = np.zeros(P, dtype=bool)
        info2 = dict(gap=np.full(P, np.inf), S=np.full((P, 11), np.nan), V=np.full((P, 3, 3), np.nan))
        if problem.size:
            far = res.valid.ravel()[problem] & (np.abs(xk[:, 1] - y1[problem]) > separation)
            # not the other zone's contact of the same wheel (the zones overlap at the split)
            other = problem ^ 1
            far &= ~(res.valid.ravel()[other] & (np.abs(xk[:, 1] - y1[other]) < _SAME_POINT))
            g = np.where(far & (gk < 0.0), gk, np.inf)
            order = np.lexsort((np.arange(problem.size), g, problem))
            first = order[np.r_[True, problem[order][1:] != problem[order][:-1]]]
            first = first[np.isfinite(g[first])]
            p = problem[first]
            x2[p], H2[p], c2[p] = xk[first], Hk[first], ck[first]
            for key in info2:
                info2[key][p] = gsv[key][first]
        x2 = np.where(np.isnan(x2), pc["lo"].clip(-1.0, 1.0), x2)
        return self._finish(x2, H2, c2, pc, info2, 0)

    def _robust_zone(self, todo, x, r_ws, A, n_sample):
        """Robust minimisation of the profile-line gap over the whole zone of problems ``todo``
        (compiled kernel; outputs at the minimum by one Newton evaluation).  Returns x, H,
        conv, info (gap, S, V) for those problems."""
        from ._kernels import reduced_min_kernel

        pc = self._problems
        ws = pc["ws"][todo]
        pct = {k: (v[todo] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
        x0 = x[todo].copy()
        # a start inside the zone: theta from the current x (finite), s the wheelset's arc length
        kern = reduced_min_kernel()
        if kern is None:  # numpy fallback: the bracketed robust route over the zone
            X, H, conv, info, _ = self._robust(x0, pct, r_ws[ws], A[ws], pct["lo_e"][:, 1], pct["hi_e"][:, 1])
            return X, H, conv, info
        b, f = self._bank, self.track.pp_frame
        X, ok = kern(np.ascontiguousarray(x0), pct["lo_e"][:, 1] + 1e-9, pct["hi_e"][:, 1] - 1e-9,
                     pct["sig"], pct["r0"], pct["L"], pct["ow"], pct["orr"], pct["Y0"], pct["Z0"],
                     pct["ca"], pct["sa"], pct["lo"], pct["hi"], np.ascontiguousarray(r_ws[ws]),
                     np.ascontiguousarray(A[ws]), b._inner, b.breaks, b._stack, f._inner, f.breaks,
                     f._stack, self._maxstep, int(n_sample), 1e-9)
        # outputs at the minimum: one evaluation of the Newton kernel (no step taken)
        X1, H, _, _, gap, S, V = self._kernel(
            np.ascontiguousarray(X), pct["sig"], pct["r0"], pct["L"], pct["ow"], pct["orr"], pct["Y0"],
            pct["Z0"], pct["ca"], pct["sa"], pct["lo"], pct["hi"], np.ascontiguousarray(r_ws[ws]),
            np.ascontiguousarray(A[ws]), b._inner, b.breaks, b._stack, f._inner, f.breaks, f._stack,
            0.0, 1, self._maxstep, self._wts)
        return X, H, ok & np.isfinite(gap), dict(gap=gap, S=S, V=V)

    def _gsv(self, x, pc, info):
        """Outputs in the compiled kernel's form dict(gap, S, V) (copies)."""
        if "S" in info:
            return {k: np.array(v, copy=True) for k, v in info.items()}
        gap, S, V = self._outputs(x, pc, info)
        return dict(gap=np.array(gap), S=np.array(S), V=np.array(V))

    def _rescue(self, pc, rP, AP, scan_out, newton=True):
        """Second chance for scan seeds that Newton did not solve (flag column 4 set).

        Each such seed is solved again with the full iteration count (``newton``: the first
        pass had the shorter re-seeding limit) and, if that fails too, refined by
        :meth:`_robust` in its bracket; the lowest valid gap per problem is returned as
        x, H, conv, info (gap, S, V), passes (gap +inf where nothing was found).
        """
        P = rP.shape[0]
        x = np.array(scan_out[0][:, :4])
        H = np.full((P, 4), np.inf)
        conv = np.zeros(P, dtype=bool)
        info = dict(gap=np.full(P, np.inf), S=np.full((P, 11), np.nan), V=np.full((P, 3, 3), np.nan))
        gbest = np.full(P, np.inf)
        it = 0

        def merge(todo, xn, Hn, cn, infn, gn):
            better = gn < gbest[todo]
            j = todo[better]
            x[j], H[j], conv[j], gbest[j] = xn[better], Hn[better], cn[better], gn[better]
            for k, v in info.items():
                v[j] = infn[k][better]

        for q in scan_out:
            todo = np.nonzero(q[:, 4] > 0.5)[0]
            if todo.size and newton:
                pct = {k: (v[todo] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
                xn, Hn, cn, itn, infn = self._newton(q[todo, :4], pct, rP[todo], AP[todo])
                it += itn
                _, gn = self._valid_gap(xn, cn, infn, pct)
                merge(todo, xn, Hn, cn, self._gsv(xn, pct, infn), gn)
                solved = cn & np.all((xn > pct["lo_e"]) & (xn < pct["hi_e"]), axis=1)
                todo = todo[~solved]
            if todo.size:
                pct = {k: (v[todo] if isinstance(v, np.ndarray) else v) for k, v in pc.items()}
                xn, Hn, cn, infn, itn = self._robust(q[todo, :4], pct, rP[todo], AP[todo],
                                                     q[todo, 5], q[todo, 6])
                it += itn
                _, gn = self._valid_gap(xn, cn, infn, pct)
                merge(todo, xn, Hn, cn, infn, gn)
        return x, H, conv, info, it

    def _reduced(self, x, pc, rP, AT, iters=12):
        """Solve h1 = h3 = h4 = 0 for (theta, s, u) at the fixed wheel coordinate y = x[:, 1].

        Returns x, h (all four residuals), info (numpy form) and psi: the gap g = d . n of the
        wheel point nearest to the rail, +inf where the rail point left the rail's range or the
        iteration did not converge.  psi(y) is the signed distance of the wheel profile line y
        from the rail, and dpsi/dy = n . t_y = h2 (envelope theorem): the four-condition
        solutions are the stationary points of psi.
        """
        k3 = np.array([0, 2, 3])
        x = x.copy()
        lo, hi = pc["lo"][:, k3], pc["hi"][:, k3]
        ms = self._maxstep[k3]
        for _ in range(iters):
            h, J, info = self._residual_jac(x, pc, rP, AT)
            Js = J[:, k3][:, :, k3]
            with np.errstate(all="ignore"):
                try:
                    dx = -np.linalg.solve(Js, h[:, k3, None])[:, :, 0]
                except np.linalg.LinAlgError:
                    dx = np.zeros((x.shape[0], 3))
                    ok = np.abs(np.linalg.det(Js)) > 1e-300
                    dx[ok] = -np.linalg.solve(Js[ok], h[ok][:, k3, None])[:, :, 0]
            dx = np.where(np.isfinite(dx), dx, 0.0)
            dx *= np.min(np.minimum(1.0, ms / (np.abs(dx) + 1e-300)), axis=1)[:, None]
            x[:, k3] = np.clip(x[:, k3] + dx, lo, hi)
            if np.max(np.abs(dx)) < 1e-13:  # converged (quadratically) to round-off
                break
        if np.max(np.abs(dx)) >= 1e-13:
            h, _, info = self._residual_jac(x, pc, rP, AT)
        g = np.einsum("ij,ij->i", info["d"], info["n"])
        ok = ((np.abs(h[:, 0]) < 1e-9) & (np.abs(h[:, 2]) < 1e-10) & (np.abs(h[:, 3]) < 1e-10)
              & (x[:, 3] > pc["lo_e"][:, 3]) & (x[:, 3] < pc["hi_e"][:, 3]) & np.isfinite(g))
        return x, h, info, np.where(ok, g, np.inf)

    def _robust(self, x0, pc, rP, AP, ylo, yhi, tol=1e-9, n_dense=64, max_shift=6):
        """Robust refinement: the minimum of psi(y) (see :meth:`_reduced`) in a bracket.

        Newton on the four conditions fails where the Jacobian is (nearly) singular or jumps:
        a concave flange root nearly conformal with the rail's gauge corner (S1002 R13 root on
        the UIC60 R13 corner), a stationary point at a joint of profile sections where the
        slope or curvature jumps (the S1002 root/flank joint has a slope step of about 1e-5),
        or the ripples of a spline through coarsely sampled, rounded points (slope noise of
        order 1e-4 where the tread is nearly conformal with the rail crown makes many
        stationary points).  The gap psi(y) of the wheel profile line y is continuous; here
        it is sampled at ``n_dense`` points of the bracket [ylo, yhi] (one vectorised call).
        From the lowest sample Newton on the four conditions is tried once more; where it
        converges between the neighbouring samples to a gap no higher than the sample's, that
        is the result.  Otherwise the minimum is refined by golden-section search (Kiefer
        1953; no derivative needed) between the neighbours of the lowest sample to ``tol``
        (m) on y.  A lowest sample at
        a bracket end that is not a zone end moves the bracket on by its width (at most
        ``max_shift`` times).  At a smooth minimum the result is the four-condition solution
        (h2 = dpsi/dy = 0 to the tolerance); at a slope step it is the minimum distance.

        Returns x, H, conv, info (gap, S, V), passes.
        """
        AT = np.swapaxes(AP, 1, 2)
        P = x0.shape[0]
        zlo, zhi = pc["lo_e"][:, 1], pc["hi_e"][:, 1]
        a_all = np.clip(np.minimum(ylo, yhi), zlo, zhi)
        b_all = np.clip(np.maximum(ylo, yhi), zlo, zhi)
        width = np.maximum(b_all - a_all, 1e-5)
        b_all = np.minimum(a_all + width, zhi)
        x_all = np.array(x0, dtype=float)
        y_all = np.clip(x_all[:, 1], zlo, zhi)
        passes = 0
        moving = np.ones(P, dtype=bool)
        found = np.zeros(P, dtype=bool)
        t = np.linspace(0.0, 1.0, n_dense)

        def sub(d, ix):
            return {key: (v[ix] if isinstance(v, np.ndarray) else v) for key, v in d.items()}

        for _ in range(max_shift + 1):
            idx = np.nonzero(moving)[0]
            k = idx.size
            a0, b0 = a_all[idx], b_all[idx]
            # dense samples: warm start with the rail point moved along with the wheel point
            Y = a0[:, None] + (b0 - a0)[:, None] * t[None, :]  # (k, n)
            Xs = np.repeat(x_all[idx], n_dense, axis=0)
            Xs[:, 3] += Y.ravel() - Xs[:, 1]
            Xs[:, 1] = Y.ravel()
            pcr = {key: (np.repeat(v[idx], n_dense, axis=0) if isinstance(v, np.ndarray) else v)
                   for key, v in pc.items()}
            Xs[:, 3] = np.clip(Xs[:, 3], pcr["lo_e"][:, 3], pcr["hi_e"][:, 3])
            Xs, _, _, G = self._reduced(Xs, pcr, np.repeat(rP[idx], n_dense, axis=0),
                                        np.repeat(AT[idx], n_dense, axis=0))
            passes += 1
            G = G.reshape(k, n_dense)
            Xs = Xs.reshape(k, n_dense, 4)
            ar = np.arange(k)
            im = np.argmin(G, axis=1)
            gm, xm = G[ar, im], Xs[ar, im]
            has = np.isfinite(gm)
            found[idx] = has
            a = Y[ar, np.maximum(im - 1, 0)]
            b = Y[ar, np.minimum(im + 1, n_dense - 1)]
            pci = sub(pc, idx)
            # Newton on the four conditions from the lowest sample: where it converges between
            # the neighbouring samples to a gap no higher than the sample's (a smooth minimum),
            # that is the result
            xn, _, cn, itn, infn = self._newton(xm, pci, rP[idx], AP[idx])
            passes += itn
            gn = infn["gap"] if "gap" in infn else np.einsum("ij,ij->i", infn["d"], infn["n"])
            newton_ok = (has & cn & np.all((xn > pci["lo_e"]) & (xn < pci["hi_e"]), axis=1)
                         & (xn[:, 1] >= a) & (xn[:, 1] <= b) & (gn <= gm + 1e-12))
            yb, xb = np.where(newton_ok, xn[:, 1], xm[:, 1]), np.where(newton_ok[:, None], xn, xm)
            # elsewhere golden section between the neighbours of the lowest sample
            gi = np.nonzero(has & ~newton_ok)[0]
            if gi.size:
                pcg, rg_, Ag = sub(pci, gi), rP[idx][gi], AT[idx][gi]

                def psi(y, xs, pcg=pcg, rg_=rg_, Ag=Ag):
                    xs = xs.copy()
                    xs[:, 1] = y
                    xs, _, _, g = self._reduced(xs, pcg, rg_, Ag)
                    return xs, g

                ag, bg, x_start = a[gi], b[gi], xm[gi]
                gr = 0.5 * (np.sqrt(5.0) - 1.0)
                c = bg - gr * (bg - ag)
                d = ag + gr * (bg - ag)
                xc, fc = psi(c, x_start)
                xd, fd = psi(d, x_start)
                n_gold = max(int(np.ceil(np.log(tol / max(np.max(bg - ag), tol)) / np.log(gr))), 1)
                passes += n_gold + 2
                for _ in range(n_gold):
                    left = fc <= fd  # the minimum lies in [a, d]
                    bg = np.where(left, d, bg)
                    ag = np.where(left, ag, c)
                    d_new = np.where(left, c, ag + gr * (bg - ag))
                    c_new = np.where(left, bg - gr * (bg - ag), d)
                    xe, fe = psi(np.where(left, c_new, d_new), np.where(left[:, None], xc, xd))
                    xc, fc, xd, fd = (np.where(left[:, None], xe, xd), np.where(left, fe, fd),
                                      np.where(left[:, None], xc, xe), np.where(left, fc, fe))
                    c, d = c_new, d_new
                pick = fc <= fd
                better = np.where(pick, fc, fd) <= gm[gi]  # else keep the lowest sample
                yb[gi] = np.where(better, np.where(pick, c, d), yb[gi])
                xb[gi] = np.where(better[:, None], np.where(pick[:, None], xc, xd), xb[gi])
            y_all[idx], x_all[idx] = yb, xb
            # the lowest sample at a bracket end (not a zone end): the minimum lies beyond it
            at_lo = has & (im == 0) & (a0 > zlo[idx] + tol)
            at_hi = has & (im == n_dense - 1) & (b0 < zhi[idx] - tol)
            moving[:] = False
            moving[idx] = at_lo | at_hi
            if not np.any(moving):
                break
            w = width[idx]
            a_all[idx] = np.clip(np.where(at_lo, a0 - w, np.where(at_hi, b0 - 0.1 * w, a0)),
                                 zlo[idx], zhi[idx])
            b_all[idx] = np.clip(np.where(at_hi, b0 + w, np.where(at_lo, a0 + 0.1 * w, b0)),
                                 zlo[idx], zhi[idx])
        x_all[:, 1] = y_all
        x, h, info, g = self._reduced(x_all, pc, rP, AT)
        passes += 1
        conv = np.isfinite(g) & found & ~moving
        return x, h, conv, self._gsv(x, pc, info), passes

    def reset(self):
        """Forget the warm start."""
        self._x = None
        self._x_prev = None
        self._calls = 0
