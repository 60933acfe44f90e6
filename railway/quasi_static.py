"""Quasi-static elastic wheel-rail contact of a wheelset under vertical wheel loads.

For a prescribed lateral shift y (and yaw psi) of a wheelset on straight track, find the axle
height z and roll phi such that the Hertz normal forces of all loaded contacts balance the
vertical load Q of each wheel (creep forces neglected, the lateral force is whatever the track
must supply to hold the shift)::

    sum_c N_c(z, phi) n_c . e_up = Q     for the left and for the right wheel
    N_c = K_h(A_c, B_c) delta_c^(3/2)    (Hertz, delta_c = -gap_c > 0; Eq. H6 of core.contact_laws)

solved by Newton's method with a forward-difference 2x2 Jacobian per shift, vectorised over
shifts (one contact search for the base poses and the two perturbed poses of all shifts).
Conformal contacts are clipped to B/A >= 1e-3 as in :mod:`railway.forces`.  Reported per
contact: normal force N, its vertical (N n_up) and lateral (N n_lat, positive to the left)
components, penetration, contact angle and the ellipse semi-axes.

References
----------
Johnson, K. L. (1985). Contact Mechanics, ch. 4 (Hertz).  Pombo, J., Ambrosio, J. and Silva, M.
(2007). VSD 45(2):165-189.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.contact_laws import hertz_from_penetration
from core.errors import InputError

from .contact_geometry import rigid_contact
from .contact_search import FLANGE, ContactSearch, wheelset_pose
from .profiles import WheelProfile
from .track import RailMounting, Track

__all__ = ["quasi_static_contact", "quasi_static_summary"]


def _contact_forces(res, E, nu):
    """Hertz normal force (n_wheels, 2) and semi-axes of all penetrating candidates."""
    N = np.zeros(res.gap.shape)
    a = np.zeros(res.gap.shape)
    b = np.zeros(res.gap.shape)
    with np.errstate(invalid="ignore"):
        on = res.valid & (res.penetration > 0)
    if np.any(on):
        A = 0.5 * (res.k_wheel_rolling + res.k_rail_rolling)[on]
        B = np.clip(0.5 * (res.k_wheel_lateral + res.k_rail_lateral)[on], A * 1e-3, A * 1e3)
        h = hertz_from_penetration(res.penetration[on], A, B, E, nu, E, nu)
        N[on], a[on], b[on] = h.normal_force, h.a, h.b
    return N, a, b


def quasi_static_contact(lateral, wheel_load, yaw=0.0, wheel=None, rail=None, gauge=1.435,
                         inclination=1 / 40, flange_back_spacing=1.360, E=2.1e11, nu=0.28,
                         tol=None, max_iter=50):
    """Wheelset position under vertical wheel loads and the forces of every contact.

    Parameters
    ----------
    lateral : float or (N,) array_like
        Lateral shifts of the wheelset (m, positive to the left).
    wheel_load : float
        Vertical load Q per wheel (N), > 0.
    yaw : float
        Yaw angle (rad).
    wheel, rail, gauge, inclination, flange_back_spacing :
        As in :func:`railway.contact_geometry.rigid_contact`.
    E, nu : float
        Young's modulus (Pa) and Poisson ratio of wheel and rail.
    tol : float, optional
        Tolerance on the vertical force balance of each wheel (N); default 1e-6 Q.
    max_iter : int

    Returns
    -------
    DataFrame
        One row per shift, side and loaded candidate: ``y [m]``, ``z [m]``, ``roll [rad]``,
        ``side``, ``contact`` (tread/flange), ``N [N]``, ``Fz [N]`` (vertical component),
        ``Fy [N]`` (lateral component, positive to the left), ``penetration [m]``,
        ``contact angle [rad]``, ``y_wheel [m]``, ``a [m]``, ``b [m]``, ``converged`` and
        ``status``.  A shift whose force balance missed ``tol`` after ``max_iter`` iterations
        (e.g. deep in flange climbing or where the S1002 contact jumps) has ``converged`` False
        and status ``"no force balance: ..."``; its rows show the last iterate and must not
        enter any summary (:func:`quasi_static_summary` leaves them out).  A shift without a
        rigid contact (out of reach beyond the flange) has one row per side with NaN values
        and the rigid contact's status.  One shift never stops the others.

    Raises
    ------
    InputError
        Non-positive, implausibly small or non-finite load, non-finite shift.
    """
    Q = _check_load(wheel_load)
    y = np.atleast_1d(np.asarray(lateral, dtype=float))
    if np.any(~np.isfinite(y)):
        raise InputError(f"quasi-static contact: lateral shift {y[~np.isfinite(y)][0]!r} is not finite")
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    z_all, roll_all, rig, _ = rigid_contact(y, yaw, wheel, rail, gauge, inclination,
                                            flange_back_spacing, errors="mark")
    rig_status = rig.extra["status"]
    ok = rig_status == "ok"
    y_all = y
    y, z, roll = y_all[ok], z_all[ok], roll_all[ok]
    n = y.size
    if n == 0:
        return _assemble([], y_all, rig_status, wheel, Q, yaw)
    mount = RailMounting(rail, gauge=gauge, inclination=inclination)
    track = Track.straight(20.0)
    cs = ContactSearch(track, wheel=wheel, rails=mount, n_wheelsets=3 * n,
                       flange_back_spacing=flange_back_spacing, tol_linear=1e-9)
    s = np.full(3 * n, 10.0)
    tol = 1e-6 * Q if tol is None else float(tol)
    # first guess: sink the rigid pose by the Hertz approach of a tread contact under Q
    z = z - 1e-4 * (Q / 1e5) ** (2.0 / 3.0)
    hz, hr = 1e-8, 1e-8
    K_ref = 1e11  # N/m^1.5, order of a tread contact; only scales the Newton variable
    up = np.array([0.0, 0.0, 1.0])
    z_acc, roll_acc, r_acc = z.copy(), roll.copy(), np.full(n, np.inf)
    dz_acc, dr_acc, lam = np.zeros(n), np.zeros(n), np.ones(n)
    for it in range(max_iter):
        zz = np.concatenate([z, z + hz, z])
        rr = np.concatenate([roll, roll, roll + hr])
        r, A = wheelset_pose(track, s, np.tile(y, 3), zz, rr, yaw)
        res = cs.search(r, A, s, warm=it > 0, scan=True)
        N, a, b = _contact_forces(res, E, nu)
        Fz = np.sum(N * np.nan_to_num(res.normal @ up), axis=1).reshape(3, n, 2)
        if np.max(np.abs(Fz[0] - Q)) < tol:
            break
        # Newton on a generalised approach of each wheel, p = (Fz/K)^(2/3) when loaded and
        # -min(gap) when not: nearly linear in (z, roll) and continuous at first contact, so
        # the step neither overshoots from a lightly loaded state (F ~ delta^1.5) nor stalls
        # on an unloaded wheel
        gmin = np.min(res.gap, axis=1).reshape(3, n, 2)
        with np.errstate(invalid="ignore"):
            p = np.where(Fz > 0, (np.maximum(Fz, 0.0) / K_ref) ** (2.0 / 3.0), -gmin)
        R = p[0] - (Q / K_ref) ** (2.0 / 3.0)  # (n, 2) left, right
        # backtracking per shift: a step that does not reduce |R| is retried at half length
        # from the last accepted pose (flange climbing is strongly nonlinear)
        rn = np.max(np.abs(R), axis=1)
        done = np.max(np.abs(Fz[0] - Q), axis=1) < tol  # converged shifts stay where they are
        worse = (rn > r_acc) & ~done
        if np.any(worse):
            lam = np.where(worse, 0.5 * lam, lam)
            z = np.where(worse, z_acc + lam * dz_acc, z)
            roll = np.where(worse, roll_acc + lam * dr_acc, roll)
            if np.all(worse | done):
                if np.all(done | (lam < 1e-6)):
                    break  # converged or stalled (a contact jump between two iterates)
                continue
        keep = ~worse & ~done
        z_acc, roll_acc, r_acc = np.where(keep, z, z_acc), np.where(keep, roll, roll_acc), np.where(keep, rn, r_acc)
        lam = np.where(keep, 1.0, lam)
        z_acc, roll_acc = np.where(done, z, z_acc), np.where(done, roll, roll_acc)
        with np.errstate(invalid="ignore"):
            J = np.stack([(p[1] - p[0]) / hz, (p[2] - p[0]) / hr], axis=2)  # (n, 2, 2)
        det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
        with np.errstate(all="ignore"):
            dz = -(J[:, 1, 1] * R[:, 0] - J[:, 0, 1] * R[:, 1]) / det
            dr = -(-J[:, 1, 0] * R[:, 0] + J[:, 0, 0] * R[:, 1]) / det
        dz, dr = np.nan_to_num(dz), np.nan_to_num(dr)
        # limit the step as a whole (clipping the components apart would turn its direction)
        scale = np.minimum(1.0, np.minimum(2e-4 / (np.abs(dz) + 1e-300), 1e-3 / (np.abs(dr) + 1e-300)))
        dz, dr = dz * scale, dr * scale
        dz_acc = np.where(keep, dz, dz_acc)
        dr_acc = np.where(keep, dr, dr_acc)
        z = np.where(keep, z + dz, z)
        roll = np.where(keep, roll + dr, roll)
    resid = np.max(np.abs(Fz[0] - Q), axis=1)
    converged = resid < tol
    nw = 2 * n
    N, a, b = N[:nw], a[:nw], b[:nw]
    rows = []
    nrm = np.nan_to_num(res.normal[:nw])
    for i in range(n):
        for k, side in enumerate(("left", "right")):
            w = 2 * i + k
            for c in range(2):
                if N[w, c] <= 0:
                    continue
                rows.append({
                    "y [m]": y[i], "z [m]": z[i], "roll [rad]": roll[i], "side": side,
                    "contact": "flange" if c == FLANGE else "tread", "N [N]": N[w, c],
                    "Fz [N]": N[w, c] * nrm[w, c, 2], "Fy [N]": N[w, c] * nrm[w, c, 1],
                    "penetration [m]": res.penetration[w, c],
                    "contact angle [rad]": res.contact_angle[w, c],
                    "y_wheel [m]": res.y_wheel[w, c], "a [m]": a[w, c], "b [m]": b[w, c],
                    "converged": bool(converged[i]),
                    "status": "ok" if converged[i] else (
                        f"no force balance: vertical force residual {float(resid[i]):.4g} N "
                        f"after {max_iter} iterations")})
    return _assemble(rows, y_all, rig_status, wheel, Q, yaw)


_COLUMNS = ["y [m]", "z [m]", "roll [rad]", "side", "contact", "N [N]", "Fz [N]", "Fy [N]",
            "penetration [m]", "contact angle [rad]", "y_wheel [m]", "a [m]", "b [m]",
            "converged", "status"]


def _assemble(rows, y_all, rig_status, wheel, Q, yaw):
    """The result table: the solved rows plus one NaN row per side of each shift without a
    rigid contact, ordered by shift."""
    for yk, st in zip(y_all, rig_status):
        if st != "ok":
            for side in ("left", "right"):
                row = {c: np.nan for c in _COLUMNS}
                row.update({"y [m]": float(yk), "side": side, "contact": "none",
                            "converged": False, "status": str(st)})
                rows.append(row)
    df = pd.DataFrame(rows, columns=_COLUMNS)
    order = {float(v): k for k, v in enumerate(y_all)}
    df = df.iloc[np.argsort([order[float(v)] for v in df["y [m]"]], kind="stable")]
    df = df.reset_index(drop=True)
    df.attrs.update(wheel=wheel.name, wheel_load=Q, yaw=float(yaw))
    return df


def _check_load(wheel_load):
    """The wheel load (N) as a float; InputError naming the value for a zero, negative,
    non-finite or implausibly small load (a load given in kN where N are expected)."""
    try:
        Q = float(wheel_load)
    except (TypeError, ValueError):
        raise InputError(f"quasi-static contact: wheel load {wheel_load!r} N is not a number") from None
    if not (np.isfinite(Q) and Q > 0):
        raise InputError(f"quasi-static contact: wheel load {wheel_load!r} N must be positive")
    if Q < _MIN_WHEEL_LOAD:
        raise InputError(f"quasi-static contact: wheel load {wheel_load!r} N is implausibly small "
                         f"(below {_MIN_WHEEL_LOAD:g} N); the load is in newtons, e.g. 100e3 for "
                         "100 kN")
    return Q


#: Smallest plausible vertical wheel load (N): a 1:10 scale model of a 100 kN wheel carries 100 N.
_MIN_WHEEL_LOAD = 100.0


def quasi_static_summary(df):
    """Summary figures of a :func:`quasi_static_contact` table, from converged rows only.

    Rows with ``converged`` False (no force balance, or no rigid contact) are left out of
    every figure and counted instead.

    Returns
    -------
    dict
        ``shifts`` (number of shifts), ``converged shifts``, ``excluded shifts [m]`` (list of
        the shifts left out, each with its status in ``excluded status``), ``max N [N]``,
        ``max |Fy| [N]`` (NaN without a converged shift), ``two-point pairs`` (number of
        (shift, side) pairs with two loaded contacts) and ``first two-point shift [m]``.
    """
    shifts = pd.unique(df["y [m]"])
    good = df[df["converged"].astype(bool)]
    bad = df[~df["converged"].astype(bool)].drop_duplicates("y [m]")
    two = good.groupby(["y [m]", "side"]).size()
    two = two[two > 1]
    return {
        "shifts": len(shifts),
        "converged shifts": int(good["y [m]"].nunique()),
        "excluded shifts [m]": [float(v) for v in bad["y [m]"]],
        "excluded status": [str(v) for v in bad["status"]],
        "max N [N]": float(good["N [N]"].max()) if len(good) else float("nan"),
        "max |Fy| [N]": float(good["Fy [N]"].abs().max()) if len(good) else float("nan"),
        "two-point pairs": len(two),
        "first two-point shift [m]": float(min(v[0] for v in two.index)) if len(two) else float("nan"),
    }
