"""Rigid contact-geometry table of a wheelset on track and the equivalent conicity.

Rigid contact (zero penetration)
--------------------------------
For each lateral shift y (and yaw angle psi) of the wheelset relative to the track, the height z
of the axle and the roll angle phi follow from zero gap on both wheels::

    g_L(z, phi) = 0,   g_R(z, phi) = 0,     g_side = min(g_tread, g_flange)

g from the four-condition contact search (:mod:`railway.contact.search`).  The equations are
solved by Newton's method vectorised over all shifts; the Jacobian follows from the envelope
theorem (the gap is stationary in the surface parameters), with n the rail normal, p the wheel
contact point, r the wheelset centre and a the wheelset's longitudinal axis::

    dg/dz = n . b_track,   dg/dphi = n . (a x (p - r))

A shift without a solution never stops a table: its row gets a status ("out of reach" when
an independent sampled rigid contact touches the rail with the flange tip or the back of the
flange, beyond the profile's contact zones; "no contact found" / "no convergence" otherwise)
and NaN values, and every summary (conicity, flange onset, transitions) skips it.

Transitions
-----------
The contact point moves continuously with the shift except where two local minima of the
gap swap places (a jump) or where the contact reaches the flange (flag).  Between two table
rows such a transition is located by bisection on the shift (:func:`contact_transitions`),
to 0.1 um by default; the flange-contact onset is reported at that exact shift, not at the
table's grid point.

Equivalent conicity (EN 15302)
------------------------------
EN 15302 defines the equivalent conicity tan(gamma_e) at amplitude y_hat as the conicity of the
conical wheelset that has the same wavelength of kinematic (Klingel) oscillation as the actual
wheelset, on the basis of the rolling-radius-difference function Delta r(y).  Implemented:

``method="wavelength"`` (default)
    The exact wavelength of the nonlinear kinematic equation y'' + Delta r(y) / (2 r0 e) = 0
    (x the distance travelled, e half the contact-point spacing) from its energy integral, with
    W(y) = int_0^y Delta r / 2 dy (r0 e cancels)::

        L / sqrt(r0 e) = 2 (I+ + I-),   I+ = int_0^A dy / sqrt(2 (W(A) - W(y)))
        I- likewise over [-A', 0] with W(-A') = W(A);   tan(gamma_e) = 4 pi^2 / (L^2/(r0 e))

    so that a cone Delta r = 2 lambda y gives exactly lambda.  This is the kinematic-wavelength
    definition of EN 15302 evaluated without linearisation (in the spirit of its integral-
    equation method for a given Delta r function); we did not have the standard's text to
    check it clause by clause.
``method="harmonic"``
    Harmonic linearisation (describing function) of Delta r::

        tan(gamma_e) = 1/(2 pi A) int_0^{2 pi} Delta r(A sin t) sin t dt
``method="simple"``
    Delta r(A) / (2 A).

The contact-angle and roll effects that EN 15302 neglects for the standard definition are
neglected here as well (only Delta r enters).

References
----------
EN 15302:2008+A1:2010, Railway applications - Method for determining the equivalent conicity.
Pombo, J., Ambrosio, J. and Silva, M. (2007). A new wheel-rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165-189.
Wickens, A. H. (2003). Fundamentals of Rail Vehicle Dynamics, Swets & Zeitlinger, ch. 2
(kinematic oscillation, Klingel wavelength L = 2 pi sqrt(r0 e / lambda)).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.errors import InputError, NumericalFailure
from core.inputs import checked_options

from .search import FLANGE, ContactSearch, wheelset_pose
from .profiles import WheelProfile
from ..track import RailMounting, Track

__all__ = ["rigid_contact", "contact_geometry_table", "equivalent_conicity", "conicity_table",
           "flange_contact_onset", "contact_transitions"]


@checked_options
def rigid_contact(lateral, yaw=0.0, wheel=None, rail=None, gauge=1.435, inclination=1 / 40,
                  flange_back_spacing=1.360, tol=1e-10, max_iter=40, errors="raise", n_scan=64,
                  n_seeds=4, accept=()):
    """Solve the rigid (zero-penetration) contact of a wheelset for many lateral shifts.

    Parameters
    ----------
    lateral : (N,) array_like
        Lateral shifts of the wheelset centre (m, positive to the left).
    yaw : float or (N,) array_like
        Yaw angle (rad).
    wheel : WheelProfile, optional
        Default S1002 with r0 = 0.46 m.
    rail : RailProfile, optional
        Default UIC60.
    gauge, inclination, flange_back_spacing :
        Track gauge (m), rail inclination (tan alpha or "1:40"), flange-back spacing (m).
    tol : float
        Largest ``|gap|`` (m) of both wheels at a solution.  Profiles from measured points carry
        a vertical data resolution q (``profile.resolution``, e.g. 1e-7 m for values in mm
        with 4 decimals); their spline has slope ripples of order q / spacing, which give the
        nearly conformal tread many stationary points whose gaps differ by less than q, so
        that the contact may hop between them from one iteration to the next.  A shift whose
        iteration stalls is accepted when its largest ``|gap|`` is below max(tol, q_wheel +
        q_rail): the data cannot decide below that.  ``res.extra["gap_residual"]`` holds the
        largest ``|gap|`` reached for every shift.
    max_iter : int
        Newton iterations on (z, roll).
    errors : {"raise", "mark"}
        What a shift without a solution does: raise (``"raise"``; an
        :class:`core.errors.InputError` when the shift is out of reach, a
        :class:`core.errors.NumericalFailure` when the search or the iteration failed) or only set its status (``"mark"``): its z,
        roll and contact outputs are then NaN and the other shifts are unaffected.
    n_scan, n_seeds : int
        Grid points per zone of the contact search's seed scan, and stationary points of the
        scan refined side by side (see :class:`railway.contact.search.ContactSearch`).
    accept : sequence of str
        ``["gauge"]`` for a gauge outside its plausible range (:class:`railway.track.RailMounting`).

    Returns
    -------
    z : (N,) ndarray
        Axle height above the top-of-rail plane (m).
    roll : (N,) ndarray
        Roll angle (rad, positive lifts the left wheel).
    res : ContactResult
        Contacts at the solution (wheels ordered shift by shift, left then right);
        ``res.extra["lead"]`` (2N, 2) holds the longitudinal position (m) of each candidate's
        wheel contact point ahead of its wheel centre along the track tangent (the flange
        lead of a yawed wheelset); ``res.extra["status"]`` (N,) is ``"ok"`` or why the shift
        has no solution (``"out of reach: ..."``, ``"no contact found: ..."``,
        ``"no convergence: ..."``).
    active : (N, 2) ndarray of int
        Candidate (0 tread, 1 flange) with the smaller gap on each wheel.
    """
    if errors not in ("raise", "mark"):
        raise InputError(f"rigid contact: errors must be 'raise' or 'mark', got {errors!r}")
    y = np.atleast_1d(np.asarray(lateral, dtype=float))
    bad = ~np.isfinite(y)
    if np.any(bad):
        raise InputError(f"lateral shift [{int(np.argmax(bad))}] = {y[bad][0]!r} is not finite")
    yaw = np.broadcast_to(np.asarray(yaw, dtype=float), y.shape).copy()
    if np.any(~np.isfinite(yaw)):
        raise InputError(f"yaw angle {yaw[~np.isfinite(yaw)][0]!r} is not finite")
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    mount = RailMounting(rail, gauge=gauge, inclination=inclination, accept=accept)
    track = Track.straight(20.0)
    N = y.size
    cs = ContactSearch(track, wheel=wheel, rails=mount, n_wheelsets=N,
                       flange_back_spacing=flange_back_spacing, tol_linear=1e-8, n_scan=n_scan,
                       flange_rail_u_max=mount.u_top, extrapolate=False, n_seeds=n_seeds)
    s = np.full(N, 10.0)
    z = np.full(N, wheel.r0 + 0.0005)  # start slightly above the rails
    roll = np.zeros(N)
    missing = np.zeros(N, dtype=bool)
    ever = np.zeros(N, dtype=bool)  # a pose with a contact on both wheels was seen
    verify = False
    last_dz = np.zeros(N)
    last_dr = np.zeros(N)
    ii = np.arange(N)[:, None]
    jj = np.arange(2)[None, :]
    up = np.array([0.0, 0.0, 1.0])
    always_scan = False
    for it in range(max_iter):
        r, A = wheelset_pose(track, s, y, z, roll, yaw)
        # global re-seeding (tread jumps) at the start and to verify a converged solution; once
        # a verification found a lower contact than the warm-started search had followed, every
        # later search re-seeds (else the warm start falls back onto the higher local minimum
        # and the iteration cycles between the two)
        res = cs.search(r, A, s, warm=it > 0,
                        scan=(it == 0) or verify or always_scan or bool(np.any(missing)))
        g = res.gap.reshape(N, 2, 2)  # shift, side, candidate
        active = np.argmin(g, axis=2)
        gs = g[ii, jj, active]
        missing = ~np.all(np.isfinite(gs), axis=1)
        ever |= ~missing
        done = ~missing & (np.max(np.abs(np.where(np.isfinite(gs), gs, np.inf)), axis=1) < tol)
        if np.all(done):
            if verify:
                break
            verify = True
            continue
        # a verification that failed, or an iteration that has not settled after 8 steps
        # (the warm start following a higher local minimum of a contact jump), re-seeds from now
        always_scan |= verify or it >= 8
        verify = False
        n = res.normal.reshape(N, 2, 2, 3)[ii, jj, active]
        p = res.point_wheel.reshape(N, 2, 2, 3)[ii, jj, active]
        a = A[:, :, 0]
        Jz = n @ up
        Jr = np.einsum("nsk,nsk->ns", n, np.cross(a[:, None, :], p - r[:, None, :]))
        det = Jz[:, 0] * Jr[:, 1] - Jz[:, 1] * Jr[:, 0]
        with np.errstate(invalid="ignore", divide="ignore"):
            dz = -(Jr[:, 1] * gs[:, 0] - Jr[:, 0] * gs[:, 1]) / det
            dr = -(-Jz[:, 1] * gs[:, 0] + Jz[:, 0] * gs[:, 1]) / det
        dz, dr = np.nan_to_num(dz), np.nan_to_num(dr)
        # a shift whose search found no contact on a wheel (too deep a penetration after a step
        # across a contact jump) goes back half its last step and is re-seeded next time
        # (last_dz, last_dr: step taken from the last pose where every wheel had a contact);
        # without such a pose the wheelset is lifted by 1 mm
        lift = missing & ~ever
        dz = np.where(missing, np.where(lift, 1e-3, -0.5 * last_dz), np.clip(dz, -0.002, 0.002))
        dr = np.where(missing, np.where(lift, 0.0, -0.5 * last_dr), np.clip(dr, -0.005, 0.005))
        last_dz = np.where(missing, np.where(lift, 0.0, 0.5 * last_dz), dz)
        last_dr = np.where(missing, np.where(lift, 0.0, 0.5 * last_dr), dr)
        z += dz
        roll += dr
    else:  # the last step moved the poses: the contacts at the final poses
        r, A = wheelset_pose(track, s, y, z, roll, yaw)
        res = cs.search(r, A, s, warm=True, scan=True)
        g = res.gap.reshape(N, 2, 2)
        active = np.argmin(g, axis=2)
        gs = g[ii, jj, active]
        missing = ~np.all(np.isfinite(gs), axis=1)
        done = ~missing & (np.max(np.abs(np.where(np.isfinite(gs), gs, np.inf)), axis=1) < tol)
    tol_accept = max(tol, getattr(wheel, "resolution", 0.0)
                     + getattr(mount.profile, "resolution", 0.0))
    with np.errstate(invalid="ignore"):
        resid = np.max(np.abs(gs), axis=1)
    done |= ~missing & (resid <= tol_accept)
    status = np.full(N, "ok", dtype=object)
    for k in np.nonzero(~done)[0]:
        reach = _out_of_reach(wheel, mount, cs.L, y[k])
        if reach:
            status[k] = reach
        elif missing[k]:
            sides = [lab for lab, m in zip(("left", "right"), ~np.isfinite(gs[k])) if m]
            status[k] = (f"no contact found: {' and '.join(sides)} wheel at lateral shift "
                         f"{float(y[k])!r} m (axle height {float(z[k])!r} m, roll "
                         f"{float(roll[k])!r} rad)")
        else:
            status[k] = (f"no convergence: largest gap {float(np.max(np.abs(gs[k])))!r} m after "
                         f"{max_iter} iterations at lateral shift {float(y[k])!r} m")
    failed = status != "ok"
    if np.any(failed) and errors == "raise":
        k = int(np.argmax(failed))
        if status[k].startswith("out of reach"):
            raise InputError(f"rigid contact: {status[k]}")
        raise NumericalFailure(f"rigid contact of wheel {wheel.name} on rail {mount.profile.name}, gauge "
                               f"{mount.gauge * 1e3:g} mm: {status[k]}")
    # lead: longitudinal position of each contact point ahead of its wheel centre (the centre
    # of the taping-line circle), measured along the track tangent; non-zero with a yaw angle
    sig = np.array([1.0, -1.0])
    centre = r[:, None, :] + (sig[None, :, None] * cs.L) * A[:, None, :, 1]  # (N, 2, 3)
    tangent = track.evaluate(s).R[:, :, 0]
    rel = res.point_wheel.reshape(N, 2, 2, 3) - centre[:, :, None, :]
    res.extra["lead"] = np.einsum("nsck,nk->nsc", rel, tangent).reshape(2 * N, 2)
    if np.any(failed):
        z, roll = np.where(failed, np.nan, z), np.where(failed, np.nan, roll)
        fw = np.repeat(failed, 2)
        for name in ("point_wheel", "point_rail", "normal", "theta", "y_wheel", "s_rail", "u_rail",
                     "rolling_radius", "contact_angle", "wheel_angle", "k_wheel_rolling",
                     "k_wheel_lateral", "k_rail_rolling", "k_rail_lateral", "residual"):
            arr = getattr(res, name)
            arr[fw] = np.nan
        res.gap[fw] = np.nan
        res.penetration[fw] = np.nan
        res.valid[fw] = False
        res.in_contact[fw] = False
        res.extra["lead"][fw] = np.nan
    res.extra["status"] = status
    res.extra["gap_residual"] = np.where(failed, np.nan, resid)
    return z, roll, res, active


def _lowest_points(wheel, mount, L, shift, roll, n=20001):
    """Vertical approach a (m) and profile coordinate (m) of each wheel's lowest point over
    its rail, in the cross-section of a wheelset at height 0 (left, right); inf and NaN where
    no point of a wheel lies over the rail.

    For the vertical gap g_v(y) = Z_wheel(y) - Z_rail(Y_wheel(y)) of the profile line y,
    a = min_y g_v at axle height 0: at height z the gap of that wheel is z + a (a vertical
    translation moves every point alike), so that the rigid contact of both wheels solves
    a_L(roll) = a_R(roll) with z = -a_L (yaw neglected).
    """
    y = np.linspace(wheel.x_min, wheel.x_max, n)
    rw = wheel.r0 + wheel.evaluate(y)[0]
    u = np.linspace(mount.u_min, mount.u_max, n)
    Yo, Zr = mount.mounted(u)[:2]
    c, s_ = np.cos(roll), np.sin(roll)
    a, at = np.full(2, np.inf), np.full(2, np.nan)
    for k, sig in enumerate((1.0, -1.0)):
        lat = sig * (y + L)
        zr = np.interp(sig * (shift + c * lat + s_ * rw), Yo, Zr, left=np.nan, right=np.nan)
        gv = np.where(np.isfinite(zr), s_ * lat - c * rw - zr, np.inf)
        i = int(np.argmin(gv))
        if np.isfinite(gv[i]):
            a[k], at[k] = gv[i], y[i]
    return a, at


def _out_of_reach(wheel, mount, L, shift):
    """Status text when the rigid contact of a shift lies beyond a flange, else None.

    An independent, sampled rigid contact in the cross-section (:func:`_lowest_points`;
    the roll from a_L(roll) = a_R(roll) by Brent's method) tells where each wheel touches.
    When a wheel touches with its flange tip or the back of its flange (y < y_flange_min +
    0.1 mm: at or beyond the end of the profile's contact zones), or lies beside its rail, the
    lateral shift is out of reach: the flange has climbed over the rail.  Otherwise the
    contact lies in the zones the search covers, and the caller reports a failure instead.
    """
    from scipy.optimize import brentq

    def f(roll):
        a = _lowest_points(wheel, mount, L, shift, roll, n=4001)[0]
        return a[0] - a[1]

    rolls = np.linspace(-0.06, 0.06, 25)  # bracket on a grid (far rolls leave the rail)
    fr = np.array([f(q) for q in rolls])
    ch = np.nonzero(np.isfinite(fr[:-1]) & np.isfinite(fr[1:]) & (fr[:-1] * fr[1:] <= 0))[0]
    roll = brentq(f, rolls[ch[0]], rolls[ch[0] + 1], xtol=1e-9) if ch.size else None
    if roll is None:
        return (f"out of reach: lateral shift {float(shift)!r} m -- no rigid position of the "
                "wheelset with both wheels over their rails")
    _, at = _lowest_points(wheel, mount, L, shift, roll)
    # at the flange tip (within 0.1 mm of the zone's end) or beyond it
    beyond = [lab for lab, yk in zip(("left", "right"), at)
              if not np.isfinite(yk) or yk < wheel.y_flange_min + 1e-4]
    if not beyond:
        return None
    return (f"out of reach: lateral shift {float(shift)!r} m is beyond the flange "
            f"({' and '.join(beyond)} wheel: it would touch the rail with its flange tip or "
            "the back of its flange, at or beyond the end of the profile's contact zones)")


@checked_options
def contact_geometry_table(lateral=None, yaw=0.0, wheel=None, rail=None, gauge=1.435,
                           inclination=1 / 40, flange_back_spacing=1.360, flange_angle=np.pi / 4,
                           accept=()):
    """Rigid contact-geometry table of a wheelset against lateral shift.

    Parameters
    ----------
    lateral : (N,) array_like, optional
        Lateral shifts (m); default 401 values over [-0.010, 0.010].
    yaw, wheel, rail, gauge, inclination, flange_back_spacing :
        See :func:`rigid_contact`.
    flange_angle : float
        A contact whose contact angle exceeds this (rad, default 45 deg) is flagged as flange
        contact (flank or flange root), as is any contact found by the flange candidate.
    accept : sequence of str
        ``["gauge"]`` for a gauge outside its plausible range (kept in ``attrs``).

    Returns
    -------
    DataFrame
        One row per shift: ``y [m]``, ``yaw [rad]``, ``status`` (``"ok"``, or why the shift
        has no rigid contact, e.g. ``"out of reach: ..."`` beyond the flange; the numbers of
        such a row are NaN and its flags False), ``max |gap| [m]`` (the larger ``|gap|`` of the two
        wheels at the solution, see ``tol`` of :func:`rigid_contact`), ``z [m]``,
        ``roll [rad]``, ``delta_r [m]``
        and per side (``_L``, ``_R``): ``y_wheel`` (profile coordinate of the contact from the
        taping line), ``u_rail`` (rail profile coordinate from the rail axis, field side
        positive), ``Y_contact`` (lateral position of the rail contact point in the track frame),
        ``r`` (rolling radius), ``gamma`` (contact angle), ``flange`` (flag), ``two_point``
        (tread and flange both touching within 1 um) and, when a yaw angle is given,
        ``lead`` (longitudinal position of the contact point ahead of the wheel centre along
        the track, m).  One shift without a solution never stops the table.
    """
    if lateral is None:
        lateral = np.linspace(-0.010, 0.010, 401)
    y = np.atleast_1d(np.asarray(lateral, dtype=float))
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    z, roll, res, active = rigid_contact(y, yaw, wheel, rail, gauge, inclination,
                                         flange_back_spacing, errors="mark", accept=accept)
    status = res.extra["status"]
    ok = status == "ok"
    N = y.size
    ii = np.arange(N)[:, None]
    jj = np.arange(2)[None, :]

    def pick(a):
        return a.reshape((N, 2, 2) + a.shape[2:])[ii, jj, active]

    gap = res.gap.reshape(N, 2, 2)
    r = pick(res.rolling_radius)
    gam = pick(res.contact_angle)
    with np.errstate(invalid="ignore"):
        flange = ((active == FLANGE) | (gam > flange_angle)) & ok[:, None]
        two = np.all(np.abs(gap) < 1e-6, axis=2) & ok[:, None]
    cols = {"y [m]": y, "yaw [rad]": np.broadcast_to(yaw, y.shape).astype(float),
            "status": status.astype(str), "max |gap| [m]": res.extra["gap_residual"],
            "z [m]": z, "roll [rad]": roll, "delta_r [m]": r[:, 0] - r[:, 1]}
    for k, lab in enumerate("LR"):
        cols[f"y_wheel_{lab} [m]"] = pick(res.y_wheel)[:, k]
        cols[f"u_rail_{lab} [m]"] = pick(res.u_rail)[:, k]
        cols[f"Y_contact_{lab} [m]"] = pick(res.point_rail)[:, k, 1]
        cols[f"r_{lab} [m]"] = r[:, k]
        cols[f"gamma_{lab} [rad]"] = gam[:, k]
        cols[f"flange_{lab}"] = flange[:, k]
        cols[f"two_point_{lab}"] = two[:, k]
        if np.any(np.asarray(yaw) != 0.0):
            cols[f"lead_{lab} [m]"] = pick(res.extra["lead"])[:, k]
    df = pd.DataFrame(cols)
    df.attrs.update(wheel=wheel.name, r0=wheel.r0, rail=(rail.name if rail is not None else "UIC60"),
                    gauge=gauge, inclination=inclination, flange_back_spacing=flange_back_spacing,
                    flange_angle=flange_angle, accept=tuple([accept] if isinstance(accept, str) else accept))
    return df


def _ok_rows(table):
    """The rows of a contact-geometry table that have a rigid contact (status "ok")."""
    if "status" not in table.columns:
        return table
    return table[table["status"] == "ok"]


def contact_transitions(table, wheel=None, rail=None, xtol=1e-7, jump=2e-4):
    """Where the contact jumps or flange contact starts, located by bisection on the shift.

    Between two neighbouring rows of a contact-geometry table the contact of a wheel makes a
    *jump* when its wheel profile coordinate changes by more than ``jump`` (the rigid contact
    point moves continuously with the shift except where two local minima of the gap swap
    places), and reaches *flange contact* when the ``flange`` flag turns on (flange candidate,
    or contact angle above the table's ``flange_angle``).  Each such interval [y_a, y_b] is
    halved until it is shorter than ``xtol``: the midpoint y_m is solved
    (:func:`rigid_contact`) and replaces the end whose contact it resembles (for a jump: the
    end whose y_wheel is nearer; for the flange flag: the end with the same flag).  The
    transition is reported at the midpoint of the final interval, exact to ``xtol / 2``, with
    the contacts on both sides of it.

    Parameters
    ----------
    table : DataFrame
        From :func:`contact_geometry_table` (its ``attrs`` give gauge, inclination,
        flange-back spacing, yaw, flange angle and the profile names).
    wheel, rail : WheelProfile, RailProfile, optional
        The profiles of the table; required unless the table was computed for S1002 / UIC60.
    xtol : float
        Width (m) of the final interval.
    jump : float
        Change of y_wheel (m) between neighbouring rows that counts as a jump.

    Returns
    -------
    DataFrame
        One row per transition: ``side`` (left/right), ``kind`` ("flange contact" or
        "contact jump"), ``y [m]`` (the transition: midpoint of the final interval),
        ``y_before [m]`` < ``y_after [m]`` (the final interval), the contact at its two ends
        (``y_wheel_before/after [m]``, ``gamma_before/after [rad]``,
        ``flange_before/after``) and ``status`` ("ok", or why the bisection stopped).  A
        candidate interval whose contact turns out to move continuously (steep, but no jump:
        the ends of the final interval differ by less than ``jump / 2`` in y_wheel) is
        dropped.
    """
    from .profiles import RailProfile

    at = table.attrs
    need = {"gauge", "inclination", "flange_back_spacing", "wheel", "r0"}
    if not need <= set(at):
        raise InputError(f"contact transitions: the table lacks the attributes {sorted(need - set(at))}; "
                         "pass a table from contact_geometry_table")
    if wheel is None:
        if at["wheel"] != "S1002":
            raise InputError(f"contact transitions: the table is for wheel {at['wheel']!r}; pass that "
                             "WheelProfile as wheel=")
        wheel = WheelProfile.s1002(r0=at["r0"])
    if rail is None and at.get("rail", "UIC60") != "UIC60":
        raise InputError(f"contact transitions: the table is for rail {at['rail']!r}; pass that "
                         "RailProfile as rail=")
    rail = rail if rail is not None else RailProfile.uic60()
    if not (np.isfinite(xtol) and xtol > 0):
        raise InputError(f"contact transitions: xtol = {xtol!r} m must be positive")
    flange_angle = float(at.get("flange_angle", np.pi / 4))
    kw = dict(wheel=wheel, rail=rail, gauge=at["gauge"], inclination=at["inclination"],
              flange_back_spacing=at["flange_back_spacing"], accept=at.get("accept", ()))
    t = table.sort_values("y [m]").reset_index(drop=True)
    if "status" in t.columns:
        ok = (t["status"] == "ok").to_numpy()
    else:
        ok = np.ones(len(t), dtype=bool)
    ys = t["y [m]"].to_numpy()
    yaw = t["yaw [rad]"].to_numpy()
    brackets = []  # (side index, kind, y_a, y_b, yaw, value_a, value_b)
    for k, lab in enumerate("LR"):
        yw = t[f"y_wheel_{lab} [m]"].to_numpy()
        fl = t[f"flange_{lab}"].to_numpy().astype(bool)
        for i in range(len(t) - 1):
            if not (ok[i] and ok[i + 1]) or yaw[i] != yaw[i + 1]:
                continue
            if fl[i] != fl[i + 1]:
                brackets.append([k, "flange contact", ys[i], ys[i + 1], yaw[i], fl[i], fl[i + 1],
                                 yw[i], yw[i + 1]])
            elif abs(yw[i + 1] - yw[i]) > jump:
                brackets.append([k, "contact jump", ys[i], ys[i + 1], yaw[i], fl[i], fl[i + 1],
                                 yw[i], yw[i + 1]])
    cols = ["side", "kind", "y [m]", "y_before [m]", "y_after [m]", "y_wheel_before [m]",
            "y_wheel_after [m]", "gamma_before [rad]", "gamma_after [rad]", "flange_before",
            "flange_after", "status"]
    if not brackets:
        return pd.DataFrame({c: [] for c in cols})
    B = len(brackets)
    side = np.array([b[0] for b in brackets])
    kind = np.array([b[1] for b in brackets])
    ya = np.array([b[2] for b in brackets])
    yb = np.array([b[3] for b in brackets])
    yaw_b = np.array([b[4] for b in brackets])
    fa = np.array([b[5] for b in brackets])
    wa = np.array([b[7] for b in brackets])
    wb = np.array([b[8] for b in brackets])
    ga = np.full(B, np.nan)
    gb = np.full(B, np.nan)
    fb = np.array([b[6] for b in brackets])
    status = np.full(B, "ok", dtype=object)
    sel = np.arange(B)
    while True:
        live = np.abs(yb - ya) > xtol
        live &= status == "ok"
        # a contact that moves continuously stops being a jump candidate as soon as its two
        # ends come closer than jump / 2 (a real jump keeps its size while the interval shrinks)
        live &= (kind == "flange contact") | (np.abs(wb - wa) > 0.5 * jump)
        if not np.any(live):
            break
        idx = sel[live]
        ym = 0.5 * (ya[idx] + yb[idx])
        _, _, res, act = rigid_contact(ym, yaw_b[idx], errors="mark", **kw)
        n = idx.size
        st = res.extra["status"]
        ywm = res.y_wheel.reshape(n, 2, 2)[np.arange(n), side[idx], act[np.arange(n), side[idx]]]
        gm = res.contact_angle.reshape(n, 2, 2)[np.arange(n), side[idx], act[np.arange(n), side[idx]]]
        with np.errstate(invalid="ignore"):
            fm = (act[np.arange(n), side[idx]] == FLANGE) | (gm > flange_angle)
        for q, b in enumerate(idx):
            if st[q] != "ok":
                status[b] = f"not located: {st[q]}"
                continue
            if kind[b] == "flange contact":
                to_a = fm[q] == fa[b]
            else:
                to_a = abs(ywm[q] - wa[b]) < abs(ywm[q] - wb[b])
            if to_a:
                ya[b], wa[b], ga[b] = ym[q], ywm[q], gm[q]
            else:
                yb[b], wb[b], gb[b] = ym[q], ywm[q], gm[q]
    # contact angles at the final ends (those never moved were grid rows)
    for arr, ends in ((ga, ya), (gb, yb)):
        miss = np.isnan(arr) & (status == "ok")
        if np.any(miss):
            _, _, res, act = rigid_contact(ends[miss], yaw_b[miss], errors="mark", **kw)
            n = int(np.sum(miss))
            arr[miss] = res.contact_angle.reshape(n, 2, 2)[np.arange(n), side[miss],
                                                            act[np.arange(n), side[miss]]]
    # a jump candidate whose contact moved continuously (steep but continuous y_wheel) is no
    # transition: at the final interval its two ends have nearly the same contact
    keep = (kind == "flange contact") | (status != "ok") | (np.abs(wb - wa) > 0.5 * jump)
    side, kind, ya, yb, wa, wb, ga, gb, fa, fb, status = (
        v[keep] for v in (side, kind, ya, yb, wa, wb, ga, gb, fa, fb, status))
    df = pd.DataFrame({
        "side": np.where(side == 0, "left", "right"), "kind": kind,
        "y [m]": 0.5 * (ya + yb), "y_before [m]": ya, "y_after [m]": yb,
        "y_wheel_before [m]": wa, "y_wheel_after [m]": wb,
        "gamma_before [rad]": ga, "gamma_after [rad]": gb,
        "flange_before": fa.astype(bool), "flange_after": fb.astype(bool),
        "status": status.astype(str)})
    df.attrs.update(xtol=xtol, jump=jump)
    return df


def _sample_delta_r(y, delta_r):
    y = np.asarray(y, dtype=float)
    dr = np.asarray(delta_r, dtype=float)
    order = np.argsort(y)
    y, dr = y[order], dr[order]
    if np.any(np.diff(y) <= 0):
        raise InputError("equivalent conicity: lateral shifts must be distinct")
    if np.any(~np.isfinite(dr)):
        raise InputError(f"equivalent conicity: delta_r has non-finite value at y = {y[~np.isfinite(dr)][0]!r}")
    return y, dr


def equivalent_conicity(y, delta_r, amplitudes, method="wavelength", n_nodes=2000):
    """Equivalent conicity from a Delta r(y) function (EN 15302), see the module docstring.

    Parameters
    ----------
    y, delta_r : (N,) array_like
        Lateral shift (m) and rolling radius difference r_L - r_R (m), covering +-amplitude.
    amplitudes : (K,) array_like
        Amplitudes y_hat (m).
    method : {"wavelength", "harmonic", "simple"}

    Returns
    -------
    (K,) ndarray
        tan(gamma_e) (-).
    """
    y, dr = _sample_delta_r(y, delta_r)
    A = np.atleast_1d(np.asarray(amplitudes, dtype=float))
    if np.any(~np.isfinite(A)) or np.any(A <= 0):
        raise InputError(f"equivalent conicity: amplitudes must be positive, got {A!r}")
    if np.any(A > y[-1]) or np.any(A > -y[0]):
        raise InputError(f"equivalent conicity: amplitude {A.max()!r} m exceeds the table range "
                         f"[{y[0]!r}, {y[-1]!r}] m")
    if method == "simple":
        return np.interp(A, y, dr) / (2.0 * A)
    if method == "harmonic":
        t = (np.arange(n_nodes) + 0.5) * (2.0 * np.pi / n_nodes)
        ya = A[:, None] * np.sin(t)[None, :]
        return np.mean(np.interp(ya, y, dr) * np.sin(t)[None, :], axis=1) / A
    if method != "wavelength":
        raise InputError(f"equivalent conicity: unknown method {method!r}")
    # W(y) = int_0^y dr/2, exact for Delta r linear between table rows (piecewise quadratic)
    h = np.diff(y)
    slope = np.diff(dr) / h
    Wnode = np.concatenate([[0.0], np.cumsum(0.5 * (dr[:-1] * h + 0.5 * slope * h**2))])

    def W(q):
        i = np.clip(np.searchsorted(y, q, side="right") - 1, 0, h.size - 1)
        t = q - y[i]
        return Wnode[i] + 0.5 * (dr[i] * t + 0.5 * slope[i] * t**2)

    W0 = W(0.0)
    x, w = np.polynomial.legendre.leggauss(200)
    phi = 0.25 * np.pi * (x + 1.0)  # [0, pi/2]
    wphi = 0.25 * np.pi * w
    out = np.empty(A.size)
    yneg = np.linspace(y[0], 0.0, 20001)
    Wneg = W(yneg)
    for k, a in enumerate(A):
        WA = W(a) - W0
        # negative turning point -a': W(-a') = W(a) (W decreasing on the negative side)
        a_neg = -np.interp(WA, (Wneg - W0)[::-1], yneg[::-1])
        for _ in range(3):  # Newton polish: dW/dy = dr/2
            a_neg -= (W(-a_neg) - W0 - WA) / (-0.5 * np.interp(-a_neg, y, dr))
        total = 0.0
        for amp, sgn in ((a, 1.0), (a_neg, -1.0)):
            yy = sgn * amp * np.sin(phi)
            diff = np.maximum(WA - (W(yy) - W0), 1e-300)
            total += np.sum(wphi * amp * np.cos(phi) / np.sqrt(2.0 * diff))
        Lnorm = 2.0 * total  # wavelength / sqrt(r0 e)
        out[k] = 4.0 * np.pi**2 / Lnorm**2
    return out


def conicity_table(table, amplitudes=(0.002, 0.003, 0.004)):
    """Equivalent conicity of a contact-geometry table at the given amplitudes, all methods.

    Only rows with a rigid contact (status "ok") enter; an amplitude whose range [-A, A] is
    not covered by consecutive such rows around y = 0 gets NaN (no interpolation across rows
    without a contact).
    """
    t = table.sort_values("y [m]")
    y, dr = t["y [m]"].to_numpy(), t["delta_r [m]"].to_numpy()
    ok = np.isfinite(dr)
    if "status" in t.columns:
        ok &= (t["status"] == "ok").to_numpy()
    A = np.asarray(amplitudes, dtype=float)
    cols = {"amplitude [m]": A}
    names = {"wavelength": "conicity wavelength [-]", "harmonic": "conicity harmonic [-]",
             "simple": "delta_r/2y [-]"}
    # the run of good rows that contains y = 0 (or the row nearest to it)
    if not np.any(ok):
        return pd.DataFrame({**cols, **{v: np.full(A.size, np.nan) for v in names.values()}})
    i0 = int(np.argmin(np.where(ok, np.abs(y), np.inf)))
    lo, hi = i0, i0
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi < y.size - 1 and ok[hi + 1]:
        hi += 1
    ys, drs = y[lo:hi + 1], dr[lo:hi + 1]
    inside = (A > 0) & (A <= ys[-1]) & (A <= -ys[0]) if ys.size > 1 else np.zeros(A.size, bool)
    for method, name in names.items():
        out = np.full(A.size, np.nan)
        if np.any(inside):
            out[inside] = equivalent_conicity(ys, drs, A[inside], method)
        cols[name] = out
    return pd.DataFrame(cols)


def flange_contact_onset(table, wheel=None, rail=None, exact=True, xtol=1e-7, transitions=None):
    """Smallest positive shift with flange contact on the left wheel, and its contact angle.

    Parameters
    ----------
    table : DataFrame
        From :func:`contact_geometry_table`; rows whose status is not "ok" are skipped.
    wheel, rail : optional
        The table's profiles (see :func:`contact_transitions`), needed with ``exact`` unless
        the table is for S1002 / UIC60.
    exact : bool
        Locate the onset between the table's rows by bisection (:func:`contact_transitions`,
        to ``xtol``); with False the first table row with flange contact is returned.
    xtol : float
        Width (m) of the final bisection interval.
    transitions : DataFrame, optional
        :func:`contact_transitions` of this table, if already computed (not repeated).

    Returns
    -------
    (y_flange [m], gamma [rad]) or (nan, nan) when the table shows no flange contact.  With
    ``exact`` y_flange is the midpoint of the final interval and gamma the contact angle at
    its flange end.

    Raises
    ------
    core.errors.InputError
        The left wheel is in flange contact already at the row before the first positive shift
        with flange contact (the wheelset does not fit between the rails), or ``transitions``
        are not of this table (the message names the profiles, the gauge and the rows).
    core.errors.NumericalFailure
        With ``exact``: the rigid contact failed inside the bracketing rows, so the bisection
        stopped; the message gives the interval reached (``exact=False`` gives the first row).
    """
    t = _ok_rows(table).sort_values("y [m]")
    pos = t[t["y [m]"] > 0]
    hit = pos[pos["flange_L"]]
    if hit.empty:
        return float("nan"), float("nan")
    row = hit.iloc[0]
    if not exact:
        return float(row["y [m]"]), float(row["gamma_L [rad]"])
    k = t.index.get_loc(row.name)
    if k == 0:  # no row before it: the onset lies below the table's range
        return float(row["y [m]"]), float(row["gamma_L [rad]"])
    pair = t.iloc[k - 1:k + 1]
    y_a, y_b = float(pair["y [m]"].iloc[0]), float(pair["y [m]"].iloc[1])
    if transitions is not None:
        tr = transitions[(transitions["y [m]"] > y_a) & (transitions["y [m]"] < y_b)]
    else:
        tr = contact_transitions(pair, wheel=wheel, rail=rail, xtol=xtol)
    tr = tr[(tr["side"] == "left") & (tr["kind"] == "flange contact") & tr["flange_after"]]
    at = table.attrs
    what = (f"wheel {wheel.name if wheel is not None else at.get('wheel', 'S1002')} on rail "
            f"{rail.name if rail is not None else at.get('rail', 'UIC60')}"
            + (f", gauge {float(at['gauge']) * 1e3:g} mm" if "gauge" in at else "")
            + (f", flange-back spacing {float(at['flange_back_spacing']) * 1e3:g} mm"
               if "flange_back_spacing" in at else ""))
    rows = f"between the table rows y = {y_a * 1e3:.4f} and {y_b * 1e3:.4f} mm"
    if bool(pair["flange_L"].iloc[0]):
        raise InputError(f"flange contact onset of {what}: the left wheel is in flange contact already at "
                         f"y = {y_a * 1e3:.4f} mm, before the first positive shift: the wheelset does not fit "
                         "between the rails (check the gauge, the flange-back spacing and the profiles)")
    if tr.empty:
        raise InputError(f"flange contact onset of {what}: the transitions given have no flange-contact "
                         f"transition of the left wheel {rows}: pass contact_transitions() of this table, "
                         "or none")
    if tr["status"].iloc[0] != "ok":
        lo, hi = float(tr["y_before [m]"].iloc[0]), float(tr["y_after [m]"].iloc[0])
        raise NumericalFailure(
            f"flange contact onset of {what}: not located {rows}: the rigid contact within them failed "
            f"({tr['status'].iloc[0].removeprefix('not located: ')}); the onset lies between "
            f"{lo * 1e3:.4f} and {hi * 1e3:.4f} mm (exact=False gives the first row with flange contact, "
            f"{y_b * 1e3:.4f} mm)")
    r = tr.iloc[0]
    return float(r["y [m]"]), float(r["gamma_after [rad]"])
