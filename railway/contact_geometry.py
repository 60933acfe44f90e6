"""Rigid contact-geometry table of a wheelset on track and the equivalent conicity.

Rigid contact (zero penetration)
--------------------------------
For each lateral shift y (and yaw angle psi) of the wheelset relative to the track, the height z
of the axle and the roll angle phi follow from zero gap on both wheels::

    g_L(z, phi) = 0,   g_R(z, phi) = 0,     g_side = min(g_tread, g_flange)

g from the four-condition contact search (:mod:`railway.contact_search`).  The equations are
solved by Newton's method vectorised over all shifts; the Jacobian follows from the envelope
theorem (the gap is stationary in the surface parameters), with n the rail normal, p the wheel
contact point, r the wheelset centre and a the wheelset's longitudinal axis::

    dg/dz = n . b_track,   dg/dphi = n . (a x (p - r))

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

from .contact_search import FLANGE, TREAD, ContactSearch, wheelset_pose
from .profiles import WheelProfile
from .track import RailMounting, Track

__all__ = ["rigid_contact", "contact_geometry_table", "equivalent_conicity", "conicity_table",
           "flange_contact_onset"]


def rigid_contact(lateral, yaw=0.0, wheel=None, rail=None, gauge=1.435, inclination=1 / 40,
                  flange_back_spacing=1.360, tol=1e-10, max_iter=40):
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
        lead of a yawed wheelset).
    active : (N, 2) ndarray of int
        Candidate (0 tread, 1 flange) with the smaller gap on each wheel.
    """
    y = np.atleast_1d(np.asarray(lateral, dtype=float))
    bad = ~np.isfinite(y)
    if np.any(bad):
        raise ValueError(f"lateral shift [{int(np.argmax(bad))}] = {y[bad][0]!r} is not finite")
    yaw = np.broadcast_to(np.asarray(yaw, dtype=float), y.shape).copy()
    if np.any(~np.isfinite(yaw)):
        raise ValueError(f"yaw angle {yaw[~np.isfinite(yaw)][0]!r} is not finite")
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    mount = RailMounting(rail, gauge=gauge, inclination=inclination)
    track = Track.straight(20.0)
    N = y.size
    cs = ContactSearch(track, wheel=wheel, rails=mount, n_wheelsets=N,
                       flange_back_spacing=flange_back_spacing, tol_linear=1e-8)
    s = np.full(N, 10.0)
    z = np.full(N, wheel.r0 + 0.0005)  # start slightly above the rails
    roll = np.zeros(N)
    missing = np.zeros(N, dtype=bool)
    verify = False
    last_dz = np.zeros(N)
    last_dr = np.zeros(N)
    for it in range(max_iter):
        r, A = wheelset_pose(track, s, y, z, roll, yaw)
        # global re-seeding (tread jumps) at the start and to verify a converged solution
        res = cs.search(r, A, s, warm=it > 0, scan=(it == 0) or verify or bool(np.any(missing)))
        g = res.gap.reshape(N, 2, 2)  # shift, side, candidate
        active = np.argmin(g, axis=2)
        ii = np.arange(N)[:, None]
        jj = np.arange(2)[None, :]
        gs = g[ii, jj, active]
        missing = ~np.all(np.isfinite(gs), axis=1)
        if not np.any(missing) and np.max(np.abs(gs)) < tol:
            if verify:
                break
            verify = True
            continue
        verify = False
        n = res.normal.reshape(N, 2, 2, 3)[ii, jj, active]
        p = res.point_wheel.reshape(N, 2, 2, 3)[ii, jj, active]
        up = np.array([0.0, 0.0, 1.0])
        a = A[:, :, 0]
        Jz = n @ up
        Jr = np.einsum("nsk,nsk->ns", n, np.cross(a[:, None, :], p - r[:, None, :]))
        det = Jz[:, 0] * Jr[:, 1] - Jz[:, 1] * Jr[:, 0]
        with np.errstate(invalid="ignore"):
            dz = -(Jr[:, 1] * gs[:, 0] - Jr[:, 0] * gs[:, 1]) / det
            dr = -(-Jz[:, 1] * gs[:, 0] + Jz[:, 0] * gs[:, 1]) / det
        # a shift whose search failed (too deep a penetration after a step across a contact
        # jump) goes back half its last step and is re-seeded next time
        # (last_dz, last_dr: step taken from the last pose where every wheel had a contact)
        dz = np.where(missing, -0.5 * last_dz, np.clip(dz, -0.002, 0.002))
        dr = np.where(missing, -0.5 * last_dr, np.clip(dr, -0.005, 0.005))
        last_dz = np.where(missing, 0.5 * last_dz, dz)
        last_dr = np.where(missing, 0.5 * last_dr, dr)
        z += dz
        roll += dr
    else:
        if np.any(missing):
            k = int(np.argmax(missing))
            raise RuntimeError(f"rigid contact: no contact found at lateral shift {float(y[k])!r} m "
                               f"(axle height {float(z[k])!r} m, roll {float(roll[k])!r} rad)")
        raise RuntimeError(f"rigid contact: no convergence in {max_iter} iterations "
                           f"(largest gap {np.max(np.abs(gs))!r} m)")
    # lead: longitudinal position of each contact point ahead of its wheel centre (the centre
    # of the taping-line circle), measured along the track tangent; non-zero with a yaw angle
    sig = np.array([1.0, -1.0])
    centre = r[:, None, :] + (sig[None, :, None] * cs.L) * A[:, None, :, 1]  # (N, 2, 3)
    tangent = track.evaluate(s).R[:, :, 0]
    rel = res.point_wheel.reshape(N, 2, 2, 3) - centre[:, :, None, :]
    res.extra["lead"] = np.einsum("nsck,nk->nsc", rel, tangent).reshape(2 * N, 2)
    return z, roll, res, active


def contact_geometry_table(lateral=None, yaw=0.0, wheel=None, rail=None, gauge=1.435,
                           inclination=1 / 40, flange_back_spacing=1.360, flange_angle=np.pi / 4):
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

    Returns
    -------
    DataFrame
        One row per shift: ``y [m]``, ``yaw [rad]``, ``z [m]``, ``roll [rad]``, ``delta_r [m]``
        and per side (``_L``, ``_R``): ``y_wheel`` (profile coordinate of the contact from the
        taping line), ``u_rail`` (rail profile coordinate from the rail axis, field side
        positive), ``Y_contact`` (lateral position of the rail contact point in the track frame),
        ``r`` (rolling radius), ``gamma`` (contact angle), ``flange`` (flag), ``two_point``
        (tread and flange both touching within 1 um) and, when a yaw angle is given,
        ``lead`` (longitudinal position of the contact point ahead of the wheel centre along
        the track, m).
    """
    if lateral is None:
        lateral = np.linspace(-0.010, 0.010, 401)
    y = np.atleast_1d(np.asarray(lateral, dtype=float))
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    z, roll, res, active = rigid_contact(y, yaw, wheel, rail, gauge, inclination,
                                         flange_back_spacing)
    N = y.size
    ii = np.arange(N)[:, None]
    jj = np.arange(2)[None, :]

    def pick(a):
        return a.reshape((N, 2, 2) + a.shape[2:])[ii, jj, active]

    gap = res.gap.reshape(N, 2, 2)
    r = pick(res.rolling_radius)
    gam = pick(res.contact_angle)
    flange = (active == FLANGE) | (gam > flange_angle)
    two = np.all(np.abs(gap) < 1e-6, axis=2)
    cols = {"y [m]": y, "yaw [rad]": np.broadcast_to(yaw, y.shape).astype(float),
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
    df.attrs.update(wheel=wheel.name, r0=wheel.r0, gauge=gauge, inclination=inclination,
                    flange_back_spacing=flange_back_spacing)
    return df


def _sample_delta_r(y, delta_r):
    y = np.asarray(y, dtype=float)
    dr = np.asarray(delta_r, dtype=float)
    order = np.argsort(y)
    y, dr = y[order], dr[order]
    if np.any(np.diff(y) <= 0):
        raise ValueError("equivalent conicity: lateral shifts must be distinct")
    if np.any(~np.isfinite(dr)):
        raise ValueError(f"equivalent conicity: delta_r has non-finite value at y = {y[~np.isfinite(dr)][0]!r}")
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
        raise ValueError(f"equivalent conicity: amplitudes must be positive, got {A!r}")
    if np.any(A > y[-1]) or np.any(A > -y[0]):
        raise ValueError(f"equivalent conicity: amplitude {A.max()!r} m exceeds the table range "
                         f"[{y[0]!r}, {y[-1]!r}] m")
    if method == "simple":
        return np.interp(A, y, dr) / (2.0 * A)
    if method == "harmonic":
        t = (np.arange(n_nodes) + 0.5) * (2.0 * np.pi / n_nodes)
        ya = A[:, None] * np.sin(t)[None, :]
        return np.mean(np.interp(ya, y, dr) * np.sin(t)[None, :], axis=1) / A
    if method != "wavelength":
        raise ValueError(f"equivalent conicity: unknown method {method!r}")
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
    """Equivalent conicity of a contact-geometry table at the given amplitudes, all methods."""
    y, dr = table["y [m]"].to_numpy(), table["delta_r [m]"].to_numpy()
    A = np.asarray(amplitudes, dtype=float)
    return pd.DataFrame({
        "amplitude [m]": A,
        "conicity wavelength [-]": equivalent_conicity(y, dr, A, "wavelength"),
        "conicity harmonic [-]": equivalent_conicity(y, dr, A, "harmonic"),
        "delta_r/2y [-]": equivalent_conicity(y, dr, A, "simple"),
    })


def flange_contact_onset(table):
    """Smallest positive shift with flange contact on the left wheel, and its contact angle.

    Returns
    -------
    (y_flange [m], gamma [rad]) or (nan, nan) when the table shows no flange contact.
    """
    pos = table[table["y [m]"] > 0].sort_values("y [m]")
    hit = pos[pos["flange_L"]]
    if hit.empty:
        return float("nan"), float("nan")
    row = hit.iloc[0]
    return float(row["y [m]"]), float(row["gamma_L [rad]"])
