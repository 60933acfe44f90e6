"""Wheelset poses relative to the track frame (the input of a contact search)."""

from __future__ import annotations

import numpy as np

from core.errors import InputError

from ...track import Track

__all__ = ["wheelset_pose"]


def _rot_x(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def _rot_z(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


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
