"""Two-point (tread plus flange) wheel-rail contact: a profile where it occurs, its rigid onset,
and a brute-force gap scan that checks both contacts independently of the Newton search.

Why not S1002
-------------
New S1002 on UIC60 1:40 has no two-point contact: the concave S1002 flange root (R13 arc and the
polynomial section C) is as wide as the R13 gauge corner of the rail, so the contact runs
continuously across the root from the tread to the flank.  Two-point contact needs a flange
root that is *tighter* than the gauge corner (concave wheel radius smaller than the convex rail
radius): the gauge corner cannot enter the root, and at the onset of flange contact the wheel
touches the rail on the tread and on the flank at the same time.  This happens with conical
(e.g. 1:40 or 1:20) and worn "two-point" profiles.

Constructed conical profile (:func:`conical_wheel_points`)
----------------------------------------------------------
In the S1002 convention (y from the taping line, negative towards the flange, F radius
increase)::

    tread   F = -c y                          (cone 1:(1/c)), y >= y_T1
    root    F = F_c - sqrt(R^2 - (y - y_c)^2)   concave arc of radius R, y_T2 <= y <= y_T1
    flange  S1002 (70 deg flank, section E extended to y_T2, then sections F, G, H)

The root arc is tangent to both straight lines (F + c y = 0 and the S1002 flank
F + B_E y + A_E = 0): its centre lies at distance R above both,

    F_c + c y_c = R sqrt(1 + c^2),   F_c + B_E y_c = R sqrt(1 + B_E^2) - A_E,

and the tangent points are the feet of the perpendiculars from the centre.

Rigid onset (:func:`two_point_contact`)
---------------------------------------
For a lateral shift y of the wheelset (and yaw psi) the rigid contact (zero gap on both wheels,
:func:`railway.contact.geometry.rigid_contact`) leaves, on the flange side, a tread gap g_T(y)
and a flange gap g_F(y), one of them zero.  f(y) = g_F - g_T is positive while the wheel runs on
its tread and negative once it rides on its flange; its root y* (Brent's method) is the rigid
two-point configuration where both touch.  Under load (elastic contact) the two-point range
widens around y*; rigidly it is one shift.

Brute-force check (:func:`gap_scan`)
------------------------------------
Straight track: the rail is a prism along x, so the vertical gap of a wheel surface point
(X, Y, Z) is g_v = Z - Z_rail(Y) with Z_rail from the mounted rail profile.  The wheel surface
is sampled densely in (theta, y) and g_v minimised over theta for every profile coordinate y.
At a contact the vertical and the normal gap vanish together, so both local minima of
min_theta g_v(theta, y) must be zero at y* (and no point may penetrate), and the theta of the
flange minimum gives the lead independently of the four-condition search.

Lead
----
The longitudinal position of a contact point ahead of its wheel centre along the track.  For
a wheel of radius r yawed by psi the classical estimate is ``|x|`` ~ r tan(gamma) tan(psi)
(gamma the contact angle): the flange contact leads (or lags) the axle by about 13 mm at
psi = 10 mrad and gamma = 70 deg.

References
----------
Pombo, J., Ambrosio, J. and Silva, M. (2007). VSD 45(2):165-189 (tread and flange as separate
candidates; two-point contact).  Shabana, A. A., Zaazaa, K. E. and Sugiyama, H. (2008).
Railroad Vehicle Dynamics: A Computational Approach, CRC Press, ch. 5 (two-point contact,
flange lead).  Wickens, A. H. (2003). Fundamentals of Rail Vehicle Dynamics, ch. 2.
EN 13715 (S1002 definition).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from core.errors import InputError

from .geometry import rigid_contact
from .search import FLANGE, TREAD
from .profiles import WheelProfile, s1002_exact, _load_s1002
from ..track import RailMounting

__all__ = ["conical_wheel_points", "conical_wheel", "two_point_contact", "gap_scan",
           "local_minima"]


def conical_wheel_points(cone=1 / 40, root_radius_mm=8.0, y_min_mm=-62.0, y_max_mm=60.0,
                         step_mm=0.1):
    """Points (mm) of a conical tread joined to the S1002 flange by a concave root arc.

    Parameters
    ----------
    cone : float
        Tread conicity c (tan of the cone angle), e.g. 1/40 or 1/20; below 0.5.
    root_radius_mm : float
        Radius R of the concave flange root (mm); below 13 mm (the UIC60 gauge corner) the
        profile has two-point contact at flange onset.
    y_min_mm, y_max_mm, step_mm : float
        Range and spacing of the points.

    Returns
    -------
    y, F : (n,) ndarray
        Lateral coordinate and radius increase (mm), S1002 sign convention.
    y_joint : float
        Tangent point of the root arc on the flank (mm): boundary of the convex flange zone.
    """
    if not (0.0 < cone < 0.5):
        raise InputError(f"two-point wheel: cone = {cone!r} must lie in (0, 0.5) (tan of the tread cone, e.g. 0.025 "
                         "for 1:40)")
    if not (0.0 < root_radius_mm < 30.0):
        raise InputError(f"two-point wheel: root_radius_mm = {root_radius_mm!r} must lie in (0, 30) mm")
    rows = {name: coef for name, _, _, coef in _load_s1002()}
    AE, BE = rows["E"][0], rows["E"][1]
    R, c = float(root_radius_mm), float(cone)
    q1, q2 = np.hypot(1.0, c), np.hypot(1.0, BE)
    yc = (R * q2 - AE - R * q1) / (BE - c)
    Fc = R * q1 - c * yc
    y_t1 = yc - R * c / q1
    y_t2 = yc - R * BE / q2
    if not y_t2 < y_t1:
        raise InputError(f"two-point wheel: cone = {cone!r}, root_radius_mm = {root_radius_mm!r}: no concave root arc joins "
                         "the tread to the flank")
    y = np.arange(y_min_mm, y_max_mm + 0.5 * step_mm, step_mm)
    F = np.empty_like(y)
    tread = y >= y_t1
    root = (y < y_t1) & (y >= y_t2)
    flank = (y < y_t2) & (y >= -39.7642)
    rest = y < -39.7642
    F[tread] = -c * y[tread]
    F[root] = Fc - np.sqrt(np.maximum(R**2 - (y[root] - yc) ** 2, 0.0))
    F[flank] = -AE - BE * y[flank]
    F[rest] = s1002_exact(y[rest])[0]
    return y, F, float(y_t2)


def conical_wheel(path=None, r0=0.46, **kw):
    """Conical wheel as a :class:`WheelProfile`, through the measured-profile reader.

    With ``path`` the points are written to that two-column file (mm) and read back with
    :meth:`WheelProfile.from_file`; otherwise :meth:`WheelProfile.from_points` is used.
    Keyword arguments go to :func:`conical_wheel_points`.
    """
    y, F, y_joint = conical_wheel_points(**kw)
    name = f"cone 1:{1 / kw.get('cone', 1 / 40):g}, root R{kw.get('root_radius_mm', 8.0):g}"
    if path is not None:
        path = Path(path)
        path.write_text("# lateral_mm radius_increase_mm (" + name + ")\n"
                        + "\n".join(f"{a:.4f} {b:.9f}" for a, b in zip(y, F)) + "\n",
                        encoding="utf-8")
        w = WheelProfile.from_file(path, r0=r0, y_split=y_joint * 1e-3)
        w.name = name
        return w
    return WheelProfile.from_points(y, F, r0=r0, y_back=-70.0, name=name, y_split=y_joint * 1e-3)


def _side_arrays(res, active_side=0):
    """(gap_T, gap_F) of one side (0 left) per shift from a rigid_contact result."""
    g = res.gap.reshape(-1, 2, 2)
    return g[:, active_side, TREAD], g[:, active_side, FLANGE]


def two_point_contact(wheel, yaw=0.0, rail=None, gauge=1.435, inclination=1 / 40,
                      flange_back_spacing=1.360, y_max=0.012, n_bracket=49, xtol=1e-8):
    """Rigid two-point contact of the left wheel: the shift where tread and flange both touch.

    Parameters
    ----------
    wheel : WheelProfile
    yaw : float
        Wheelset yaw angle (rad).
    rail, gauge, inclination, flange_back_spacing :
        As in :func:`railway.contact.geometry.rigid_contact`.
    y_max : float
        Largest lateral shift of the bracketing scan (m).
    n_bracket : int
        Shifts of the bracketing scan over [0, y_max].
    xtol : float
        Tolerance on the shift (m) of Brent's method.

    Returns
    -------
    DataFrame
        Two rows (tread, flange) with ``shift [m]``, ``yaw [rad]``, ``z [m]``, ``roll [rad]``,
        ``gap [m]``, ``y_wheel [m]``, ``u_rail [m]``, ``contact angle [rad]``,
        ``rolling radius [m]``, ``lead [m]``, ``Y_contact [m]``; ``df.attrs`` holds the inputs.

    Raises
    ------
    ValueError
        If no sign change of g_F - g_T is found on [0, y_max] (no two-point contact: e.g. S1002).
    """
    from scipy.optimize import brentq

    kw = dict(wheel=wheel, rail=rail, gauge=gauge, inclination=inclination,
              flange_back_spacing=flange_back_spacing)
    ys = np.linspace(0.0, y_max, n_bracket)
    _, _, res, _ = rigid_contact(ys, yaw, **kw)
    gT, gF = _side_arrays(res)
    f = np.where(np.isfinite(gF), gF, 1.0) - np.where(np.isfinite(gT), gT, 1.0)
    ch = np.flatnonzero((f[:-1] > 0) & (f[1:] <= 0))
    if ch.size == 0:
        raise InputError(f"{wheel.name}: no two-point contact (tread and flange touching together) "
                         f"for lateral shifts in [0, {y_max!r}] m at yaw {yaw!r} rad")
    k = int(ch[0])
    # g_F - g_T changes sign continuously only where neither gap is infinite (both candidates
    # valid); a change across an invalid candidate is a jump (S1002 runs across its root)
    if not (np.isfinite(gT[k]) and np.isfinite(gF[k]) and np.isfinite(gT[k + 1]) and np.isfinite(gF[k + 1])):
        raise InputError(f"{wheel.name}: tread or flange candidate vanishes at the flange onset "
                         f"(shift {float(ys[k])!r}..{float(ys[k + 1])!r} m): the contact runs across the flange "
                         "root, no two-point contact")

    def fun(y):
        _, _, r1, _ = rigid_contact([y], yaw, **kw)
        a, b = _side_arrays(r1)
        return float(b[0] - a[0])

    y_star = brentq(fun, ys[k], ys[k + 1], xtol=xtol)
    z, roll, r1, _ = rigid_contact([y_star], yaw, **kw)
    rows = []
    for cand, label in ((TREAD, "tread"), (FLANGE, "flange")):
        rows.append({
            "contact": label, "shift [m]": y_star, "yaw [rad]": float(yaw), "z [m]": float(z[0]),
            "roll [rad]": float(roll[0]), "gap [m]": float(r1.gap[0, cand]),
            "y_wheel [m]": float(r1.y_wheel[0, cand]), "u_rail [m]": float(r1.u_rail[0, cand]),
            "contact angle [rad]": float(r1.contact_angle[0, cand]),
            "rolling radius [m]": float(r1.rolling_radius[0, cand]),
            "lead [m]": float(r1.extra["lead"][0, cand]),
            "Y_contact [m]": float(r1.point_rail[0, cand, 1]),
        })
    df = pd.DataFrame(rows)
    df.attrs.update(wheel=wheel.name, gauge=gauge, inclination=inclination,
                    flange_back_spacing=flange_back_spacing)
    return df


def gap_scan(wheel, shift, z, roll=0.0, yaw=0.0, rail=None, gauge=1.435, inclination=1 / 40,
             flange_back_spacing=1.360, side=1, dy=5e-6, theta_max=0.06, n_theta=1201,
             y_range=None):
    """Brute-force vertical gap of one wheel on straight track (independent of the search).

    Parameters
    ----------
    wheel : WheelProfile
    shift, z, roll, yaw : float
        Wheelset pose relative to the straight track (m, m, rad, rad), as in
        :func:`railway.contact.search.wheelset_pose`.
    rail, gauge, inclination, flange_back_spacing :
        Track and wheelset data.
    side : {1, -1}
        Left (+1) or right (-1) wheel.
    dy : float
        Spacing of the profile coordinate y (m).
    theta_max, n_theta :
        Wheel angle grid [-theta_max, theta_max] (rad).
    y_range : (float, float), optional
        Profile-coordinate window (m); default the whole profile.

    Returns
    -------
    DataFrame
        ``y_wheel [m]``, ``gap [m]`` (min over theta of the vertical gap; +inf where no rail
        lies under the wheel point), ``theta [rad]`` and ``lead [m]`` (longitudinal position
        of the minimising point ahead of the wheel centre).
    """
    from scipy.spatial.transform import Rotation

    mount = RailMounting(rail, gauge=gauge, inclination=inclination)
    L = 0.5 * flange_back_spacing - wheel.y_back
    u = np.linspace(mount.u_min, mount.u_max, 20001)
    Yo, Zr, *_ = mount.mounted(u)
    order = np.argsort(Yo)
    Yo, Zr = Yo[order], Zr[order]
    y_lo, y_hi = (wheel.x_min + 1e-5, wheel.x_max) if y_range is None else y_range
    y = np.arange(max(y_lo, wheel.x_min + 1e-5), min(y_hi, wheel.x_max), dy)
    th = np.linspace(-theta_max, theta_max, n_theta)
    r = wheel.radius(y)
    A = Rotation.from_euler("ZX", [yaw, roll]).as_matrix()  # Rz(yaw) Rx(roll)
    centre = np.array([0.0, shift, z])
    gmin = np.full(y.size, np.inf)
    tmin = np.zeros(y.size)
    lead = np.zeros(y.size)
    wheel_centre = centre + side * L * A[:, 1]
    for j0 in range(0, y.size, 2000):  # blocks keep the (n_theta, block) arrays small
        sl = slice(j0, j0 + 2000)
        yy, rr = y[sl], r[sl]
        loc = np.stack([rr[None, :] * np.sin(th)[:, None],
                        np.broadcast_to(side * (yy + L), (th.size, yy.size)),
                        -rr[None, :] * np.cos(th)[:, None]], axis=-1)
        P = loc @ A.T + centre
        Yl = side * P[..., 1]  # lateral coordinate on the rail side of this wheel
        zr = np.interp(Yl, Yo, Zr, left=np.nan, right=np.nan)
        g = np.where(np.isfinite(zr), P[..., 2] - zr, np.inf)
        i = np.argmin(g, axis=0)
        cols = np.arange(yy.size)
        gmin[sl] = g[i, cols]
        tmin[sl] = th[i]
        lead[sl] = P[i, cols, 0] - wheel_centre[0]
    return pd.DataFrame({"y_wheel [m]": y, "gap [m]": gmin, "theta [rad]": tmin, "lead [m]": lead})


def local_minima(scan, max_gap=1e-3):
    """Local minima of a :func:`gap_scan` (rows whose gap is below both neighbours and max_gap)."""
    g = scan["gap [m]"].to_numpy()
    m = np.zeros(g.size, dtype=bool)
    m[1:-1] = (g[1:-1] <= g[:-2]) & (g[1:-1] < g[2:]) & (g[1:-1] < max_gap)
    return scan[m].reset_index(drop=True)
