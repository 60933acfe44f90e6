r"""What a railway engineer reads per contact and per wheel: Nadal's limit, Hertz pressure, wear
number, derailment quotient Y/Q.

All functions are vectorised (any array shapes that broadcast) and take SI units.  Acceptance
*limits* (EN 14363, UIC 518, TSI) are data, not code: the only one the project holds is the
second-hand Y/Q value in ``data/railway/assessment_limits.csv`` (:func:`assessment_limits`); no
EN 14363 numbers are hard-coded anywhere because they were not checked against the standard.

Equations
---------
Nadal's single-wheel derailment criterion (flange climbing starts when the lateral force ratio
of the climbing wheel reaches the friction-limited equilibrium on the flange of contact angle
gamma, with the friction force mu N acting fully against the climb)::

    (Y/Q)_lim = (tan gamma - mu) / (1 + mu tan gamma) = tan(gamma - arctan mu)           (A1)

Hertz's maximum pressure of an elliptical contact of semi-axes a, b under a normal force N
(the pressure is semi-ellipsoidal, p = p0 sqrt(1 - x^2/a^2 - y^2/b^2), whose integral is
(2/3) pi a b p0 = N)::

    p0 = 3 N / (2 pi a b)                                                                (A2)

Wear number (T-gamma): the work of the creep forces on the rigid creepages per unit distance
rolled, the quantity of wear and rolling-contact-fatigue damage functions::

    T_gamma = |Fx xi| + |Fy eta|            [N = J/m]                                    (A3)

The work rate of the creep forces on the rigid creepages is -V (Fx xi + Fy eta + Mz phi) with
the forces opposing the creepages; in full sliding at large creepage it is the frictional
dissipation of the patch (the elastic part of the local slip adds little): CONTACT's frictional
power for the Manchester cases equals it to 0.5 % where y >= 6.5 mm and to 3.5 % at the smallest
full-slip creepages (tested).  T_gamma is that work per metre *without the spin term* |Mz phi|:
T-gamma damage functions and the usual engineering definition (the project notes, section 5)
use the two creep forces only; pass ``Mz`` and ``phi`` to add it.

Derailment quotient of a wheel (Y the lateral force of the wheel on the rail, positive towards
the field side of that rail; Q the vertical force of the wheel on the rail, positive
downwards)::

    Y/Q,   NaN where Q <= 0 (the wheel is lifted: the quotient is undefined)             (A4)

so that Y/Q > 0 on a flange-climbing wheel (the flange pushes its rail outwards).  From the
contact-frame forces (N along the rail normal n into the wheel, Fx along t, Fy along
l = n x t, the frame of :class:`railway.forces.ContactForces`), the force on the wheel is
F = N n + Fx t + Fy l; summed over the contacts c of a wheel on side sigma (+1 left, -1 right)
with the track's lateral axis e_lat (to the left) and up axis e_up::

    Q = sum_c F_c . e_up,     Y = -sigma sum_c F_c . e_lat                               (A5)

References
----------
Nadal, M. J. (1908). Locomotives a vapeur. Collection Encyclopedie Scientifique, Paris (A1;
quoted second-hand, not read here: formula and attribution as given by public summaries of the
"Nadal formula"; Marquis & Greif (2011), ASME JRC2011-56064, discuss its assumption F_t = mu N,
conservative at small angles of attack).
Johnson, K. L. (1985). Contact Mechanics, Cambridge University Press, sect. 4.2 (A2; Eq. H7 of
:mod:`core.contact_laws`; equation number in the book not checked here).
UIC Code 518 (2003): Y/Q <= 0.8 (quoted second-hand from D. P. Prayitno, MSc thesis, UGM,
eq. 3.9; not checked against the code).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.errors import DataFileError, InputError

__all__ = [
    "nadal_limit",
    "max_pressure",
    "wear_number",
    "derailment_quotient",
    "wheel_forces_track",
    "assessment_limits",
]


def _arrays(names, values):
    arrs = [np.asarray(v, dtype=float) for v in values]
    try:
        arrs = np.broadcast_arrays(*arrs)
    except ValueError:
        shapes = {n: np.shape(v) for n, v in zip(names, arrs)}
        raise InputError(f"inputs do not broadcast: {shapes}") from None
    return arrs


def _finite(name, x, where):
    bad = ~np.isfinite(x)
    if np.any(bad):
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise InputError(f"{where}: {name}{list(idx)} = {float(x[idx])!r} is not finite")


def nadal_limit(contact_angle, mu):
    """Nadal's limit of the derailment quotient, Eq. (A1) of the module docstring [-].

    Parameters
    ----------
    contact_angle : float or array_like
        Flange contact angle gamma (rad), |gamma| < pi/2 (e.g. 70 deg = 1.22 rad for a new
        S1002 flank).
    mu : float or array_like
        Friction coefficient at the flange contact, >= 0.

    Returns
    -------
    ndarray
        (tan gamma - mu)/(1 + mu tan gamma) (broadcast shape); 1/mu as gamma -> 90 deg,
        tan gamma at mu = 0.

    Raises
    ------
    core.errors.InputError
        A non-finite value, |gamma| >= pi/2 or mu < 0 (names the value).

    References
    ----------
    Nadal (1908), quoted second-hand (see the module docstring).
    """
    g, m = _arrays(("contact_angle", "mu"), (contact_angle, mu))
    _finite("contact_angle", g, "Nadal limit")
    _finite("mu", m, "Nadal limit")
    if np.any(np.abs(g) >= 0.5 * np.pi):
        i = tuple(int(k) for k in np.argwhere(np.abs(g) >= 0.5 * np.pi)[0])
        raise InputError(f"Nadal limit: contact angle {float(g[i])!r} rad must lie inside "
                         "(-pi/2, pi/2); it is in radians")
    if np.any(m < 0):
        i = tuple(int(k) for k in np.argwhere(m < 0)[0])
        raise InputError(f"Nadal limit: friction coefficient mu = {float(m[i])!r} must be >= 0")
    t = np.tan(g)
    return (t - m) / (1.0 + m * t)


def max_pressure(N, a, b):
    """Hertz maximum contact pressure p0 = 3 N/(2 pi a b), Eq. (A2) [Pa].

    Parameters
    ----------
    N : float or array_like
        Normal force (N), >= 0.  Unloaded contacts (N = 0) give 0 whatever their semi-axes
        (e.g. zeros), as the creep laws do.
    a, b : float or array_like
        Semi-axes of the contact ellipse (m), > 0 where N > 0.

    Returns
    -------
    ndarray
        p0 (Pa), broadcast shape.

    Raises
    ------
    core.errors.InputError
        Non-finite input, N < 0, or a loaded contact with a <= 0 or b <= 0 (names it).

    References
    ----------
    Johnson (1985), sect. 4.2; Eq. (H7) of :mod:`core.contact_laws`.
    """
    N, a, b = _arrays(("N", "a", "b"), (N, a, b))
    for name, x in (("N", N), ("a", a), ("b", b)):
        _finite(name, x, "maximum pressure")
    if np.any(N < 0):
        i = tuple(int(k) for k in np.argwhere(N < 0)[0])
        raise InputError(f"maximum pressure: normal force N{list(i)} = {float(N[i])!r} N is negative")
    bad = (N > 0) & ((a <= 0) | (b <= 0))
    if np.any(bad):
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        raise InputError(f"maximum pressure: loaded contact {list(i)} (N = {float(N[i])!r} N) needs "
                         f"semi-axes > 0, got a = {float(a[i])!r} m, b = {float(b[i])!r} m")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(N > 0, 3.0 * N / (2.0 * np.pi * a * b), 0.0)


def wear_number(Fx, Fy, xi, eta, Mz=None, phi=None):
    """Wear number T_gamma = |Fx xi| + |Fy eta|, Eq. (A3) [N = J/m].

    Parameters
    ----------
    Fx, Fy : float or array_like
        Longitudinal and lateral creep forces (N) in the contact frame.
    xi, eta : float or array_like
        Longitudinal and lateral creepages [-].
    Mz, phi : float or array_like, optional
        Spin moment (N m) and spin creepage (1/m).  Given together, |Mz phi| is added, so the
        result is the whole frictional dissipation per metre rolled (module docstring); left
        out by default, as in the usual T-gamma definition.

    Returns
    -------
    ndarray
        T_gamma (N), broadcast shape.

    Raises
    ------
    core.errors.InputError
        Non-finite input, or only one of ``Mz``, ``phi`` given.
    """
    if (Mz is None) != (phi is None):
        raise InputError("wear number: give both Mz and phi (spin term) or neither")
    names = ("Fx", "Fy", "xi", "eta") + (("Mz", "phi") if Mz is not None else ())
    vals = (Fx, Fy, xi, eta) + ((Mz, phi) if Mz is not None else ())
    arrs = _arrays(names, vals)
    for n, x in zip(names, arrs):
        _finite(n, x, "wear number")
    T = np.abs(arrs[0] * arrs[2]) + np.abs(arrs[1] * arrs[3])
    if Mz is not None:
        T = T + np.abs(arrs[4] * arrs[5])
    return T


def derailment_quotient(Y, Q):
    """Derailment quotient Y/Q of a wheel, Eq. (A4); NaN where Q <= 0 (wheel lifted) [-].

    Parameters
    ----------
    Y : float or array_like
        Lateral force of the wheel on the rail (N), positive towards the field side of that
        rail (see :func:`wheel_forces_track`).
    Q : float or array_like
        Vertical force of the wheel on the rail (N), positive downwards.

    Returns
    -------
    ndarray
        Y/Q, broadcast shape, NaN where Q <= 0.

    Raises
    ------
    core.errors.InputError
        NaN or infinite input (names it).
    """
    Y, Q = _arrays(("Y", "Q"), (Y, Q))
    _finite("Y", Y, "derailment quotient")
    _finite("Q", Q, "derailment quotient")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(Q > 0, Y / np.where(Q > 0, Q, 1.0), np.nan)


def wheel_forces_track(N, Fx, Fy, normal, rolling_direction, side, lateral=(0.0, 1.0, 0.0),
                       up=(0.0, 0.0, 1.0)):
    """Y and Q of each wheel from its contacts' contact-frame forces, Eq. (A5).

    Parameters
    ----------
    N, Fx, Fy : (n_wheels, n_contacts) array_like
        Normal force and the creep forces along t and l = n x t of every contact candidate
        (the frame of :class:`railway.forces.ContactForces`), zero for unloaded candidates.
    normal : (n_wheels, n_contacts, 3) array_like
        Rail normal into the wheel (global); ignored (may be NaN) where N = Fx = Fy = 0.
    rolling_direction : (n_wheels, 3) or (n_wheels, n_contacts, 3) array_like
        Forward axis of the wheelset (projected onto each tangent plane here, as in
        :class:`railway.forces.ContactForces`).
    side : (n_wheels,) array_like
        +1 for a left wheel, -1 for a right wheel.
    lateral, up : (3,) or (n_wheels, 3) array_like
        Track lateral axis (to the left) and up axis, global.

    Returns
    -------
    Y, Q : (n_wheels,) ndarray
        Lateral force of the wheel on the rail, positive towards the field side, and vertical
        force of the wheel on the rail, positive downwards (N).
    F : (n_wheels, n_contacts, 3) ndarray
        Force of the rail on the wheel of every candidate (global, N).

    Raises
    ------
    core.errors.InputError
        Wrong shapes, a side other than +-1, a loaded contact with a non-finite normal, or a
        rolling direction parallel to a normal.
    """
    N = np.atleast_2d(np.asarray(N, dtype=float))
    Fx = np.asarray(Fx, dtype=float).reshape(N.shape)
    Fy = np.asarray(Fy, dtype=float).reshape(N.shape)
    nw, nc = N.shape
    n = np.asarray(normal, dtype=float)
    if n.shape != (nw, nc, 3):
        raise InputError(f"wheel forces: normal must have shape {(nw, nc, 3)}, got {n.shape}")
    d = np.asarray(rolling_direction, dtype=float)
    if d.shape == (nw, 3):
        d = np.broadcast_to(d[:, None, :], (nw, nc, 3))
    if d.shape != (nw, nc, 3):
        raise InputError(f"wheel forces: rolling_direction must have shape {(nw, 3)} or "
                         f"{(nw, nc, 3)}, got {d.shape}")
    sig = np.asarray(side, dtype=float).reshape(-1)
    if sig.shape != (nw,) or not np.all(np.abs(sig) == 1.0):
        raise InputError(f"wheel forces: side must be +1 (left) or -1 (right) for each of the "
                         f"{nw} wheels, got {np.asarray(side).tolist()!r}")
    loaded = (N != 0) | (Fx != 0) | (Fy != 0)
    if np.any(loaded & ~np.all(np.isfinite(n), axis=2)):
        i = tuple(int(k) for k in np.argwhere(loaded & ~np.all(np.isfinite(n), axis=2))[0])
        raise InputError(f"wheel forces: loaded contact {list(i)} has a non-finite normal")
    for name, x in (("N", N), ("Fx", Fx), ("Fy", Fy)):
        _finite(name, x, "wheel forces")
    nn = np.where(loaded[..., None], n, 0.0)
    t = d - np.sum(d * nn, axis=2)[..., None] * nn
    tn = np.linalg.norm(t, axis=2)
    if np.any(loaded & (tn < 1e-9)):
        i = tuple(int(k) for k in np.argwhere(loaded & (tn < 1e-9))[0])
        raise InputError(f"wheel forces: rolling direction parallel to the normal at contact {list(i)}")
    t = t / np.where(tn > 0, tn, 1.0)[..., None]
    l = np.cross(nn, t)
    F = N[..., None] * nn + Fx[..., None] * t + Fy[..., None] * l
    F = np.where(loaded[..., None], F, 0.0)
    lat = np.broadcast_to(np.asarray(lateral, dtype=float), (nw, 3))
    upv = np.broadcast_to(np.asarray(up, dtype=float), (nw, 3))
    Fs = F.sum(axis=1)
    Q = np.einsum("wk,wk->w", Fs, upv)
    Y = -sig * np.einsum("wk,wk->w", Fs, lat)
    return Y, Q, F


_LIMITS_FILE = ("railway", "assessment_limits.csv")


def assessment_limits():
    """Acceptance limits held as data (``data/railway/assessment_limits.csv``), with sources.

    Returns
    -------
    DataFrame
        Columns ``quantity``, ``limit [-]``, ``condition``, ``source``, ``status``.  Only
        values whose source is named; the status says whether they were checked against the
        original (none of them is).

    Raises
    ------
    core.errors.DataFileError
        The file is malformed (names it and the missing columns).
    """
    from core.paths import data_path

    path = data_path(*_LIMITS_FILE)
    df = pd.read_csv(path, comment="#")
    need = {"quantity", "limit [-]", "condition", "source", "status"}
    if not need <= set(df.columns):
        raise DataFileError(f"{path}: missing columns {sorted(need - set(df.columns))}")
    return df
