"""Creepages (longitudinal xi, lateral eta, spin phi) from rigid-body kinematics at the contact.

Equations
---------
Contact frame: unit normal ``n`` of the rail surface pointing into the wheel, unit rolling
direction ``t`` (tangent to both surfaces, the direction of travel) and the lateral direction
``l = n x t`` so that (t, l, n) is right-handed.  The velocities of the wheel and rail material
points that coincide at the contact point r_c are::

    v_w = v_W + omega_W x (r_c - r_W),      v_r = v_R + omega_R x (r_c - r_R)

and the creepages are the relative velocity divided by the rolling speed V::

    xi  = (v_w - v_r) . t / V
    eta = (v_w - v_r) . l / V
    phi = (omega_W - omega_R) . n / V                      [1/m]

By default V = ``|(v_W - v_R) . t|``: the speed of the wheel (body reference point) relative to the
rail body along the rolling direction, i.e. the vehicle speed on track and the roller surface
speed on a roller rig.  Pass ``rolling_speed`` to use another definition (e.g. the mean
circumferential speed).  With these definitions the slip field in the contact patch is
s_x = xi - phi y, s_y = eta + phi x (x along t, y along l), and the forces on the wheel of
:mod:`railway.contact.creep` oppose it (F_x = -G c^2 C11 xi ...).

References
----------
.. [1] J. J. Kalker, *Three-dimensional elastic bodies in rolling contact*, Kluwer, 1990, ch. 1
   (kinematics of rolling, creepage and spin).
.. [2] K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985, ch. 8.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from core.errors import InputError

__all__ = ["creepages", "contact_frame"]


def _vec3(name: str, value, n: int | None = None) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InputError(f"creepages: {name} must have shape (n, 3) or (3,), got {np.shape(value)}")
    if np.any(~np.isfinite(arr)):
        i = int(np.argwhere(~np.isfinite(arr))[0, 0])
        raise InputError(f"creepages: {name} has a non-finite value at contact {i}: {arr[i].tolist()}")
    return arr


def contact_frame(normal, rolling_direction, tol: float = 1e-6):
    """Orthonormal contact frame (t, l, n) from a normal and an approximate rolling direction.

    ``t`` is ``rolling_direction`` projected onto the tangent plane and normalised; l = n x t.

    Parameters
    ----------
    normal : (n, 3) array_like
        Rail surface normal pointing into the wheel (normalised here).
    rolling_direction : (n, 3) array_like
        Direction of travel (need not be exactly tangent).
    tol : float
        Minimum norm of the projected rolling direction (relative).

    Returns
    -------
    t, l, n : (n, 3) ndarray
    """
    nrm = _vec3("normal", normal)
    d = _vec3("rolling_direction", rolling_direction)
    nrm, d = np.broadcast_arrays(nrm, d)
    ln = np.linalg.norm(nrm, axis=1)
    if np.any(ln < tol):
        raise InputError(f"creepages: normal has zero length at contact {int(np.flatnonzero(ln < tol)[0])}")
    nrm = nrm / ln[:, None]
    t = d - np.sum(d * nrm, axis=1)[:, None] * nrm
    lt = np.linalg.norm(t, axis=1)
    bad = lt < tol * np.maximum(np.linalg.norm(d, axis=1), 1e-300)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"creepages: rolling_direction is (nearly) parallel to the normal or zero at contact {i}")
    t = t / lt[:, None]
    l = np.cross(nrm, t)
    return t, l, nrm


def creepages(contact_point, normal, rolling_direction, wheel_position, wheel_velocity,
              wheel_angular_velocity, rail_velocity=(0.0, 0.0, 0.0),
              rail_angular_velocity=(0.0, 0.0, 0.0), rail_position=(0.0, 0.0, 0.0),
              rolling_speed=None, min_rolling_speed: float = 1e-3,
              as_frame: bool = False):
    """Creepages xi, eta [-] and spin phi [1/m] of many wheel-rail contacts.

    Parameters
    ----------
    contact_point : (n, 3) array_like
        Contact point r_c in the global frame [m].
    normal : (n, 3) array_like
        Rail surface normal at the contact, pointing into the wheel.
    rolling_direction : (n, 3) array_like
        Direction of travel (projected onto the tangent plane here).
    wheel_position, wheel_velocity, wheel_angular_velocity : (n, 3) array_like
        Wheelset reference point r_W [m], its velocity v_W [m/s] and the wheelset angular velocity
        omega_W [rad/s], all global.
    rail_velocity, rail_angular_velocity, rail_position : (n, 3) array_like, optional
        Same for the rail body (zero for a fixed track; the roller of a roller rig otherwise).
    rolling_speed : float or (n,) array_like, optional
        V [m/s]; default ``|(v_W - v_R) . t|``.
    min_rolling_speed : float
        V below this raises ValueError (creepages are undefined at standstill) [m/s].
    as_frame : bool
        Return a DataFrame with columns "xi [-]", "eta [-]", "phi [1/m]", "V [m/s]".

    Returns
    -------
    xi, eta, phi : (n,) ndarray
        (or a DataFrame if ``as_frame``).

    Raises
    ------
    ValueError
        Wrong shapes, non-finite input, degenerate frame, or V < ``min_rolling_speed``.
    """
    rc = _vec3("contact_point", contact_point)
    rW = _vec3("wheel_position", wheel_position)
    vW = _vec3("wheel_velocity", wheel_velocity)
    wW = _vec3("wheel_angular_velocity", wheel_angular_velocity)
    vR = _vec3("rail_velocity", rail_velocity)
    wR = _vec3("rail_angular_velocity", rail_angular_velocity)
    rR = _vec3("rail_position", rail_position)
    t, l, nrm = contact_frame(normal, rolling_direction)
    rc, rW, vW, wW, vR, wR, rR, t, l, nrm = np.broadcast_arrays(rc, rW, vW, wW, vR, wR, rR, t, l, nrm)
    v_wheel = vW + np.cross(wW, rc - rW)
    v_rail = vR + np.cross(wR, rc - rR)
    dv = v_wheel - v_rail
    if rolling_speed is None:
        V = np.abs(np.sum((vW - vR) * t, axis=1))
    else:
        V = np.broadcast_to(np.asarray(rolling_speed, dtype=float), (rc.shape[0],)).copy()
    if np.any(~(V >= min_rolling_speed)):
        i = int(np.flatnonzero(~(V >= min_rolling_speed))[0])
        raise InputError(f"creepages: rolling speed V={float(V[i])!r} m/s at contact {i} is below "
                         f"min_rolling_speed={min_rolling_speed} m/s: creepages undefined")
    xi = np.sum(dv * t, axis=1) / V
    eta = np.sum(dv * l, axis=1) / V
    phi = np.sum((wW - wR) * nrm, axis=1) / V
    if as_frame:
        return pd.DataFrame({"xi [-]": xi, "eta [-]": eta, "phi [1/m]": phi, "V [m/s]": V})
    return xi, eta, phi
