"""Quasi-static elastic wheel-rail contact of a wheelset under vertical wheel loads.

For a prescribed lateral shift y (and yaw psi) of a wheelset on straight track, find the axle
height z and roll phi such that the Hertz normal forces of all loaded contacts balance the
vertical load Q of each wheel (creep forces neglected, the lateral force is whatever the track
must supply to hold the shift)::

    sum_c N_c(z, phi) n_c . e_up = Q     for the left and for the right wheel
    N_c = K_h(A_c, B_c) delta_c^(3/2)    (Hertz, delta_c = -gap_c > 0; Eq. H6 of core.contact_laws)

solved by Newton's method with a forward-difference 2x2 Jacobian per shift, vectorised over
shifts (one contact search for the base poses and the two perturbed poses of all shifts).
Conformal contacts are clipped to B/A >= 1e-3 as in :mod:`railway.contact.forces`.  Reported per
contact: normal force N, its vertical (N n_up) and lateral (N n_lat, positive to the left)
components, penetration, contact angle and the ellipse semi-axes.

:func:`quasi_static_rolling` adds the creep forces to the balance, as CONTACT does for the
Manchester benchmark: a wheelset rolling at speed V on straight track with prescribed lateral
shift y and yaw psi; unknowns axle height z, roll phi and spin (pitch) rate Omega about the
axle e_a; with the force F_c = N_c n_c + Fx_c t_c + Fy_c l_c and spin moment Mz_c n_c of each
contact c on the wheel (:class:`railway.contact.forces.ContactForces` with the Hertz normal force and
any registered creep law, creepages of the rigid-body motion v = V e_track, omega = Omega e_a)::

    sum_{c of wheel w} F_c . e_up = Q                     for w = left, right    (track frame)
    sum_c [ (p_c - r_ws) x F_c + Mz_c n_c ] . e_a = 0     (free rolling: no net axle torque)

solved by Newton's method with a forward-difference 3x3 Jacobian per case (vectorised over
cases); the lateral force is again whatever the track supplies.

References
----------
Johnson, K. L. (1985). Contact Mechanics, ch. 4 (Hertz).  Pombo, J., Ambrosio, J. and Silva, M.
(2007). VSD 45(2):165-189.  Vollebregt, E. A. H. CONTACT user guide, sect. 5.7 (the Manchester
benchmark: prescribed vertical force per wheel, zero net rolling moment).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.contact_laws import hertz_from_penetration
from core.errors import InputError
from core.inputs import checked_options

from ..assessment import wheel_forces_track
from .geometry import rigid_contact
from .search import FLANGE, ContactSearch, wheelset_pose
from .profiles import WheelProfile
from ..track import RailMounting, Track

__all__ = ["quasi_static_contact", "quasi_static_summary", "quasi_static_rolling",
           "quasi_static_wheel_table"]


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


@checked_options
def quasi_static_contact(lateral, wheel_load, yaw=0.0, wheel=None, rail=None, gauge=1.435,
                         inclination=1 / 40, flange_back_spacing=1.360, E=2.1e11, nu=0.28,
                         tol=None, max_iter=50, accept=()):
    """Wheelset position under vertical wheel loads and the forces of every contact.

    Parameters
    ----------
    lateral : float or (N,) array_like
        Lateral shifts of the wheelset (m, positive to the left).
    wheel_load : float
        Vertical load Q per wheel (N), > 0.
    yaw : float
        Yaw angle (rad).
    wheel, rail, gauge, inclination, flange_back_spacing, accept :
        As in :func:`railway.contact.geometry.rigid_contact` (``accept=["gauge"]`` for a gauge
        outside its plausible range).
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
                                            flange_back_spacing, errors="mark", accept=accept)
    rig_status = rig.extra["status"]
    ok = rig_status == "ok"
    y_all = y
    y, z, roll = y_all[ok], z_all[ok], roll_all[ok]
    n = y.size
    if n == 0:
        return _assemble([], y_all, rig_status, wheel, Q, yaw)
    mount = RailMounting(rail, gauge=gauge, inclination=inclination, accept=accept)
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


# ------------------------------------------------------------------------------------------
# quasi-static rolling with creep forces
# ------------------------------------------------------------------------------------------

_ROLL_COLUMNS = [
    "case", "y [m]", "yaw [rad]", "z [m]", "roll [rad]", "omega [rad/s]", "side", "contact",
    "N [N]", "Fx [N]", "Fs [N]", "Mz [N m]", "Fx track [N]", "Fy track [N]", "Fz track [N]",
    "contact angle [rad]", "y_wheel [m]", "y_contact [m]", "z_contact [m]", "rolling radius [m]",
    "penetration [m]", "a [m]", "b [m]", "p_max [Pa]", "xi [-]", "eta [-]", "phi [1/m]",
    "T_gamma [N]", "Y [N]", "Q [N]", "Y/Q [-]", "Nadal limit [-]", "converged", "status"]


def _slice_result(res, idx):
    """A ContactResult holding the wheels ``idx`` of ``res`` (every per-wheel array sliced)."""
    from dataclasses import fields, replace

    nw = res.gap.shape[0]
    kw = {f.name: getattr(res, f.name)[idx] for f in fields(res)
          if isinstance(getattr(res, f.name), np.ndarray) and getattr(res, f.name).shape[:1] == (nw,)}
    return replace(res, **kw)


def quasi_static_rolling(lateral, yaw, wheel_load, speed, creep_law="fastsim", mu=0.3,
                         E=2.1e11, nu=0.28, creep_params=None, wheel=None, rail=None,
                         gauge=1.435, inclination=1 / 40, flange_back_spacing=1.360, tol=None,
                         max_iter=60, compiled=False):
    r"""Steady rolling of a wheelset with prescribed shift and yaw: creep forces in the balance.

    For each case (lateral shift y, yaw psi) the axle height z, roll phi and spin rate Omega
    are found such that the vertical force of each wheel in track coordinates -- normal and
    creep-force components -- equals ``wheel_load`` and the net moment about the axle is zero
    (free rolling); see the module docstring for the equations.  The creepages follow from
    the rigid-body motion (wheelset centre moving at ``speed`` along the track, angular
    velocity Omega about the axle) by :mod:`railway.contact.creepage`; the forces from Hertz (no
    damping) and the creep law, by :class:`railway.contact.forces.ContactForces`.

    Parameters
    ----------
    lateral : float or (n,) array_like
        Lateral shifts (m, positive to the left).
    yaw : float or (n,) array_like
        Yaw angles (rad, positive turns the nose to the left).
    wheel_load : float
        Vertical force Q per wheel (N), > 0.
    speed : float
        Rolling speed V (m/s), > 0.
    creep_law : str, CreepModel class or CreepModel
        Any law of :data:`railway.contact.creep.CREEP_MODELS` (``"fastsim"``, ``"polach2000"``,
        ``"kalker_linear"``, ...).  Kalker linear does not saturate: in flange contact its
        forces exceed mu N many times (a property of the law, not of this solver).
    mu : float
        Friction coefficient (> 0; for Polach 2005 the static value mu0).
    E, nu : float
        Young's modulus (Pa) and Poisson ratio of wheel and rail (G = E / (2 (1 + nu))).
    creep_params : dict, optional
        Constructor parameters of a creep law given by name (e.g. FASTSIM's ``n_x, n_y``).
    wheel, rail, gauge, inclination, flange_back_spacing :
        As in :func:`railway.contact.geometry.rigid_contact`.
    tol : float, optional
        Tolerance on the vertical force of each wheel and on the axle moment divided by the
        nominal radius (N); default 1e-6 Q.
    max_iter : int
        Newton iterations.
    compiled : {"auto", True, False}
        Passed to :class:`railway.contact.forces.ContactForces`.  Default False: the reference path
        with the exact Hertz solution (that of :func:`quasi_static_contact`); the compiled
        kernel tabulates the Hertz coefficients (relative error ~1e-4) and serves only Kalker
        linear and Polach 2000 -- speed is not the point of a quasi-static table.

    Returns
    -------
    DataFrame
        One row per case, side and loaded contact candidate (columns with SI units):
        ``case``, ``y [m]``, ``yaw [rad]``, ``z [m]``, ``roll [rad]``, ``omega [rad/s]``
        (spin about the axle), ``side``, ``contact`` (tread/flange), ``N [N]``, ``Fx [N]``,
        ``Fs [N]`` (creep forces along t and l = n x t: Fs is the lateral force in the
        contact plane), ``Mz [N m]``, ``Fx track [N]``, ``Fy track [N]`` (positive to the
        left), ``Fz track [N]`` (force of the rail on the wheel in the track frame),
        ``contact angle [rad]``, ``y_wheel [m]`` (on the wheel profile, negative towards the
        flange), ``y_contact [m]``, ``z_contact [m]`` (the rail contact point in the track
        frame), ``rolling radius [m]``, ``penetration [m]``, ``a [m]``, ``b [m]``,
        ``p_max [Pa]``, ``xi [-]``, ``eta [-]``, ``phi [1/m]``, ``T_gamma [N]`` (wear number
        without spin), per wheel ``Y [N]``, ``Q [N]`` and ``Y/Q [-]``
        (:func:`railway.assessment.wheel_forces_track`), ``Nadal limit [-]`` of the contact's
        angle at ``mu``, ``converged`` and ``status``.  A case whose balance missed ``tol``
        has ``converged`` False and status ``"no balance: ..."`` (its rows show the last
        iterate and must not enter a summary: :func:`quasi_static_wheel_table` flags them);
        a case without a rigid contact has one NaN row per side with the rigid status.

    Raises
    ------
    core.errors.InputError
        A bad load, speed, shift or yaw (named), or a bad creep-law parameter.
    core.errors.UnknownNameError
        An unknown creep law.

    References
    ----------
    See the module docstring; Kalker (1990), ch. 1 (creepages); the creep laws of
    :mod:`railway.contact.creep`.
    """
    from ..assessment import derailment_quotient, max_pressure, nadal_limit, wear_number
    from .forces import ContactForces

    Q = _check_load(wheel_load)
    V = float(speed) if np.ndim(speed) == 0 else np.nan
    if not (np.isfinite(V) and V > 0):
        raise InputError(f"quasi-static rolling: speed {speed!r} m/s must be a positive number")
    y_all = np.atleast_1d(np.asarray(lateral, dtype=float))
    if y_all.ndim != 1:
        raise InputError(f"quasi-static rolling: lateral must be a scalar or 1-D, got shape {y_all.shape}")
    if np.any(~np.isfinite(y_all)):
        raise InputError(f"quasi-static rolling: lateral shift {y_all[~np.isfinite(y_all)][0]!r} is not finite")
    try:
        psi_all = np.broadcast_to(np.asarray(yaw, dtype=float), y_all.shape).copy()
    except ValueError:
        raise InputError(f"quasi-static rolling: yaw of shape {np.shape(yaw)} does not match the "
                         f"{y_all.size} lateral shifts") from None
    if np.any(~np.isfinite(psi_all)):
        raise InputError(f"quasi-static rolling: yaw {psi_all[~np.isfinite(psi_all)][0]!r} rad is not finite")
    forces = ContactForces(E=E, nu=nu, mu=mu, creep_model=creep_law, restitution=1.0,
                           compiled=compiled, creep_params=creep_params)
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    z_all, roll_all, rig, active = rigid_contact(y_all, psi_all, wheel, rail, gauge, inclination,
                                                 flange_back_spacing, errors="mark")
    rig_status = np.asarray(rig.extra["status"])
    ok = rig_status == "ok"
    meta = dict(wheel=wheel.name, wheel_load=Q, speed=V, creep_law=forces.creep_model,
                mu=float(mu), E=float(E), nu=float(nu))
    if not np.any(ok):
        return _assemble_rolling([], y_all, psi_all, rig_status, meta)
    cases = np.flatnonzero(ok)
    y, psi = y_all[ok], psi_all[ok]
    n = y.size
    # rolling radius of the rigid contacts -> first spin rate (equal and opposite xi)
    rr = rig.rolling_radius.reshape(-1, 2, 2)[ok]
    act = np.asarray(active)[ok]
    r_act = np.take_along_axis(rr, act[:, :, None], axis=2)[:, :, 0]
    Om = 2.0 * V / np.sum(r_act, axis=1)
    z = z_all[ok] - 1e-4 * (Q / 1e5) ** (2.0 / 3.0)
    roll = roll_all[ok].copy()
    mount = RailMounting(rail, gauge=gauge, inclination=inclination)
    track = Track.straight(20.0)
    cs = ContactSearch(track, wheel=wheel, rails=mount, n_wheelsets=3 * n,
                       flange_back_spacing=flange_back_spacing, tol_linear=1e-9)
    s3 = np.full(3 * n, 10.0)
    tol = 1e-6 * Q if tol is None else float(tol)
    r0 = float(wheel.r0)
    hz, hr, hw = 1e-8, 1e-8, 1e-7 * V / r0
    K_ref = 1e11
    pQ = (Q / K_ref) ** (2.0 / 3.0)
    fwd_track = track.evaluate(np.array([10.0])).R[0, :, 0]
    up = np.array([0.0, 0.0, 1.0])
    wheels_of = lambda blocks: np.concatenate([np.arange(2 * b * n, 2 * (b + 1) * n) for b in blocks])

    def evaluate(z, roll, Om, warm):
        zz = np.concatenate([z, z + hz, z])
        rl = np.concatenate([roll, roll, roll + hr])
        r, A = wheelset_pose(track, s3, np.tile(y, 3), zz, rl, np.tile(psi, 3))
        res3 = cs.search(r, A, s3, warm=warm, scan=True)
        # block 3: the base geometry with the spin perturbed
        res = _slice_result(res3, wheels_of((0, 1, 2, 0)))
        r4 = np.concatenate([r, r[:n]])
        A4 = np.concatenate([A, A[:n]])
        Om4 = np.concatenate([Om, Om, Om, Om + hw])
        v4 = np.broadcast_to(V * fwd_track, (4 * n, 3))
        w4 = Om4[:, None] * A4[:, :, 1]
        f = forces(res, r4, A4, v4, w4)
        F = f["force"]  # (8n, 2, 3) on the wheel
        Fz = np.einsum("wck,k->wc", F, up).sum(axis=1).reshape(4, n, 2)
        P = np.nan_to_num(res.point_wheel)
        arm = P - np.repeat(r4, 2, axis=0)[:, None, :]
        mom = np.cross(arm, F) + f["moment"]
        ax = np.repeat(A4[:, :, 1], 2, axis=0)
        M = np.einsum("wck,wk->wc", mom, ax).sum(axis=1).reshape(4, n, 2).sum(axis=2)
        gmin = np.min(res.gap, axis=1).reshape(4, n, 2)
        with np.errstate(invalid="ignore"):
            p = np.where(Fz > 0, (np.maximum(Fz, 0.0) / K_ref) ** (2.0 / 3.0), -gmin)
        R = np.concatenate([p - pQ, (M / r0)[:, :, None]], axis=2)  # (4, n, 3)
        return res, f, Fz, M, R, r4, A4

    x = np.stack([z, roll, Om], axis=1)
    x_acc, m_acc = x.copy(), np.full(n, np.inf)
    dx_acc, lam = np.zeros_like(x), np.ones(n)
    scale_R = np.array([pQ, pQ, Q])
    step_max = np.array([2e-4, 1e-3, 0.01 * V / r0])
    for it in range(max_iter):
        res, f, Fz, M, R, r4, A4 = evaluate(x[:, 0], x[:, 1], x[:, 2], warm=it > 0)
        err = np.maximum(np.max(np.abs(Fz[0] - Q), axis=1), np.abs(M[0]) / r0)
        done = err < tol
        if np.all(done):
            break
        merit = np.max(np.abs(R[0]) / scale_R, axis=1)
        worse = (merit > m_acc) & ~done
        if np.any(worse):
            lam = np.where(worse, 0.5 * lam, lam)
            x = np.where(worse[:, None], x_acc + lam[:, None] * dx_acc, x)
            if np.all(worse | done):
                if np.all(done | (lam < 1e-6)):
                    break  # converged or stalled
                continue
        keep = ~worse & ~done
        x_acc = np.where(keep[:, None], x, x_acc)
        m_acc = np.where(keep, merit, m_acc)
        lam = np.where(keep, 1.0, lam)
        with np.errstate(invalid="ignore"):
            J = np.stack([(R[1] - R[0]) / hz, (R[2] - R[0]) / hr, (R[3] - R[0]) / hw], axis=2)
        J = np.where(np.isfinite(J), J, 0.0)
        # Newton steps of the active cases: batched 3x3 solves on row-scaled systems (the
        # pseudo-inverse where a Jacobian is singular, e.g. a wheel without contact)
        dx = np.zeros_like(x)
        ia = np.flatnonzero(keep)
        if ia.size:
            Js = J[ia] / scale_R[None, :, None]
            rhs = -R[0, ia] / scale_R[None, :]
            try:
                dx[ia] = np.linalg.solve(Js, rhs[:, :, None])[:, :, 0]
            except np.linalg.LinAlgError:
                dx[ia] = np.einsum("nij,nj->ni", np.linalg.pinv(Js), rhs)
        dx = np.nan_to_num(dx)
        sc = np.minimum(1.0, np.min(step_max / (np.abs(dx) + 1e-300), axis=1))
        dx = dx * sc[:, None]
        dx_acc = np.where(keep[:, None], dx, dx_acc)
        x = np.where(keep[:, None], x + dx, x)
    err = np.maximum(np.max(np.abs(Fz[0] - Q), axis=1), np.abs(M[0]) / r0)
    converged = err < tol
    # outputs of the base block at the evaluated state
    nw = 2 * n
    g = {k: f[k][:nw] for k in ("N", "Fx", "Fy", "Mz", "xi", "eta", "phi", "a", "b")}
    Fw = f["force"][:nw]
    side_sign = np.tile([1.0, -1.0], n)
    Y, Qw, _ = wheel_forces_track(g["N"], g["Fx"], g["Fy"], np.nan_to_num(res.normal[:nw]),
                                  np.repeat(A4[:n, :, 0], 2, axis=0), side_sign)
    YQ = derailment_quotient(Y, Qw)
    with np.errstate(invalid="ignore"):
        pmax = max_pressure(g["N"], np.where(g["N"] > 0, g["a"], 0.0), np.where(g["N"] > 0, g["b"], 0.0))
    Tg = wear_number(g["Fx"], g["Fy"], g["xi"], g["eta"])
    gam = np.where(g["N"] > 0, res.contact_angle[:nw], 0.0)
    nadal = nadal_limit(np.clip(gam, -1.5, 1.5), mu)
    rows = []
    for i in range(n):
        st = "ok" if converged[i] else (
            f"no balance: vertical force / axle moment residual {float(err[i]):.4g} N after "
            f"{it + 1} iterations")
        for k, side in enumerate(("left", "right")):
            w = 2 * i + k
            for c in range(2):
                if not g["N"][w, c] > 0:
                    continue
                rows.append({
                    "case": int(cases[i]), "y [m]": y[i], "yaw [rad]": psi[i], "z [m]": x[i, 0],
                    "roll [rad]": x[i, 1], "omega [rad/s]": x[i, 2], "side": side,
                    "contact": "flange" if c == FLANGE else "tread", "N [N]": g["N"][w, c],
                    "Fx [N]": g["Fx"][w, c], "Fs [N]": g["Fy"][w, c], "Mz [N m]": g["Mz"][w, c],
                    "Fx track [N]": Fw[w, c, 0], "Fy track [N]": Fw[w, c, 1], "Fz track [N]": Fw[w, c, 2],
                    "contact angle [rad]": res.contact_angle[w, c], "y_wheel [m]": res.y_wheel[w, c],
                    "y_contact [m]": res.point_rail[w, c, 1], "z_contact [m]": res.point_rail[w, c, 2],
                    "rolling radius [m]": res.rolling_radius[w, c],
                    "penetration [m]": res.penetration[w, c], "a [m]": g["a"][w, c], "b [m]": g["b"][w, c],
                    "p_max [Pa]": pmax[w, c], "xi [-]": g["xi"][w, c], "eta [-]": g["eta"][w, c],
                    "phi [1/m]": g["phi"][w, c], "T_gamma [N]": Tg[w, c], "Y [N]": Y[w], "Q [N]": Qw[w],
                    "Y/Q [-]": YQ[w], "Nadal limit [-]": nadal[w, c], "converged": bool(converged[i]),
                    "status": st})
    meta["iterations"] = it + 1
    return _assemble_rolling(rows, y_all, psi_all, rig_status, meta)


def _assemble_rolling(rows, y_all, psi_all, rig_status, meta):
    for k, (yk, pk, st) in enumerate(zip(y_all, psi_all, rig_status)):
        if st != "ok":
            for side in ("left", "right"):
                row = {c: np.nan for c in _ROLL_COLUMNS}
                row.update({"case": k, "y [m]": float(yk), "yaw [rad]": float(pk), "side": side,
                            "contact": "none", "converged": False, "status": str(st)})
                rows.append(row)
    df = pd.DataFrame(rows, columns=_ROLL_COLUMNS)
    df = df.sort_values(["case"], kind="stable").reset_index(drop=True)
    df["case"] = df["case"].astype(int)
    df.attrs.update(meta)
    return df


def quasi_static_wheel_table(df):
    """One row per case and wheel from a :func:`quasi_static_rolling` table.

    Per wheel: the number of loaded contacts, the total normal force and the track-frame
    force sums, Y, Q, Y/Q, the contact angle, position and Nadal limit of the contact with
    the largest normal force (the one a single-patch code such as CONTACT reports), the
    largest maximum pressure and the summed wear number.

    Parameters
    ----------
    df : DataFrame
        The table of :func:`quasi_static_rolling`.

    Returns
    -------
    DataFrame
        Columns ``case``, ``y [m]``, ``yaw [rad]``, ``side``, ``contacts``, ``N [N]`` (sum),
        ``N main [N]``, ``Fx track [N]``, ``Fy track [N]``, ``Fz track [N]`` (sums),
        ``Y [N]``, ``Q [N]``, ``Y/Q [-]``, ``contact angle [rad]``, ``y_wheel [m]``,
        ``y_contact [m]``, ``z_contact [m]``, ``Nadal limit [-]`` (of the main contact),
        ``p_max [Pa]`` (largest), ``T_gamma [N]`` (sum), ``z [m]``, ``roll [rad]``,
        ``omega [rad/s]``, ``converged``, ``status``.  Non-converged cases keep their rows
        (``converged`` False) so that they can be listed; a summary must leave them out.
    """
    rows = []
    for (case, side), sub in df.groupby(["case", "side"], sort=True):
        loaded = sub[sub["N [N]"] > 0]
        base = sub.iloc[0]
        row = {"case": int(case), "y [m]": base["y [m]"], "yaw [rad]": base["yaw [rad]"],
               "side": side, "contacts": int(len(loaded))}
        if len(loaded):
            main = loaded.loc[loaded["N [N]"].idxmax()]
            row.update({
                "N [N]": loaded["N [N]"].sum(), "N main [N]": main["N [N]"],
                "Fx track [N]": loaded["Fx track [N]"].sum(), "Fy track [N]": loaded["Fy track [N]"].sum(),
                "Fz track [N]": loaded["Fz track [N]"].sum(), "Y [N]": main["Y [N]"],
                "Q [N]": main["Q [N]"], "Y/Q [-]": main["Y/Q [-]"],
                "contact angle [rad]": main["contact angle [rad]"], "y_wheel [m]": main["y_wheel [m]"],
                "y_contact [m]": main["y_contact [m]"], "z_contact [m]": main["z_contact [m]"],
                "Nadal limit [-]": main["Nadal limit [-]"], "p_max [Pa]": loaded["p_max [Pa]"].max(),
                "T_gamma [N]": loaded["T_gamma [N]"].sum()})
        row.update({"z [m]": base["z [m]"], "roll [rad]": base["roll [rad]"],
                    "omega [rad/s]": base["omega [rad/s]"], "converged": bool(base["converged"]),
                    "status": base["status"]})
        rows.append(row)
    cols = ["case", "y [m]", "yaw [rad]", "side", "contacts", "N [N]", "N main [N]", "Fx track [N]",
            "Fy track [N]", "Fz track [N]", "Y [N]", "Q [N]", "Y/Q [-]", "contact angle [rad]",
            "y_wheel [m]", "y_contact [m]", "z_contact [m]", "Nadal limit [-]", "p_max [Pa]",
            "T_gamma [N]", "z [m]", "roll [rad]", "omega [rad/s]", "converged", "status"]
    out = pd.DataFrame(rows, columns=cols)
    out.attrs = dict(df.attrs)
    return out
