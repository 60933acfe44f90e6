"""Parametric wheel and rail surfaces with analytic tangents and normals.

Wheel (surface of revolution about the axle), in the wheelset frame (x forward, y along the axle
to the left, z up; no spin rotation since the surface is axisymmetric), for the wheel on side
sigma (+1 left, -1 right) with taping line at lateral distance L from the wheelset centre::

    p(theta, y) = ( r sin(theta),  sigma (y + L),  -r cos(theta) ),   r = r0 + F(y)
    t_theta = dp/dtheta / r = ( cos(theta), 0, sin(theta) )
    t_y     = dp/dy       = ( F' sin(theta), sigma, -F' cos(theta) )
    n_w = ( sin(theta), -sigma F', -cos(theta) ) / sqrt(1 + F'^2)     (outward, down at theta=0)

y is the profile coordinate from the taping line (negative towards the flange), so the flange
is on the track-centre side of both wheels.  The wheel is split into a tread zone and a flange
zone of y (see :class:`railway.contact.profiles.WheelProfile`).

Rail (profile swept along the track centreline), global coordinates, with the track frame
R(s) = [t, n, b], Darboux vector omega (see :mod:`railway.track`) and the mounted profile
(Yo(u), Z(u)) of :class:`railway.track.RailMounting`::

    q(s, u) = r(s) + R(s) l(u),           l(u) = (0, sigma Yo(u), Z(u))
    t_s = dq/ds = r'(s) + omega x (R l),  t_u = dq/du = R (0, sigma Yo'(u), Z'(u))
    n_r = sigma (t_s x t_u) / |t_s x t_u|                 (outward: up at the crown)

Principal curvatures used by Hertz (positive when convex, i.e. the centre of curvature inside the
body).  The wheel's principal directions are the parallel circle and the meridian; by Meusnier's
theorem the normal curvature of the parallel circle of radius r is cos(gamma_w)/r, with gamma_w
the angle between the surface normal and the radial direction, cos(gamma_w) = 1/sqrt(1+F'^2)::

    k_wx = 1 / (r sqrt(1 + F'^2))       (rolling direction: radius r / cos(gamma_w))
    k_wy = -F'' / (1 + F'^2)^(3/2)      (lateral: the S1002 tread is concave, k_wy < 0)
    k_ry = -v'' / (1 + v'^2)^(3/2)      (rail lateral: UIC60 crown 1/0.3 m)
    k_rx = -n_r . q_ss / |q_s|^2         (rail rolling: 0 on straight track)

References
----------
Pombo, J., Ambrosio, J. and Silva, M. (2007). A new wheel-rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165-189 (wheel and rail surface parameterisation,
surface tangents and normals).
"""

from __future__ import annotations

import numpy as np

from core.errors import InputError

from .profiles import WheelProfile
from ..track import RailMounting, Track

__all__ = ["WheelSurface", "RailSurface"]


class WheelSurface:
    """Wheel surface of revolution for one side of a wheelset.

    Parameters
    ----------
    profile : WheelProfile
    side : {+1, -1}
        +1 left wheel (y > 0 in the wheelset frame), -1 right wheel.
    flange_back_spacing : float
        Distance between the flange back faces (m), default 1.360; the taping line lies at
        L = flange_back_spacing/2 - profile.y_back from the wheelset centre (0.750 m for S1002).
    """

    def __init__(self, profile: WheelProfile, side=1, flange_back_spacing=1.360):
        if side not in (1, -1):
            raise InputError(f"wheel surface: side must be +1 (left) or -1 (right), got {side!r}")
        if not (np.isfinite(flange_back_spacing) and 1.0 < flange_back_spacing < 2.0):
            raise InputError(f"wheel surface: flange-back spacing {flange_back_spacing!r} m is not plausible "
                             "(expected 1 to 2 m, e.g. 1.360; it is in metres)")
        self.profile = profile
        self.side = int(side)
        self.L = 0.5 * float(flange_back_spacing) - profile.y_back

    def evaluate(self, theta, y):
        """Point, unit tangents and outward normal in the wheelset frame.

        Parameters
        ----------
        theta, y : (N,) array_like
            Angle from the downward vertical (rad, positive forward) and profile coordinate (m).

        Returns
        -------
        dict with ``point``, ``t_theta`` (unit), ``t_y``, ``normal`` (unit), each (N, 3), and
        ``radius``, ``F1``, ``F2`` (N,).
        """
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        y = np.atleast_1d(np.asarray(y, dtype=float))
        F, F1, F2 = self.profile.evaluate(y)
        r = self.profile.r0 + F
        st, ct = np.sin(theta), np.cos(theta)
        sg = self.side
        z = np.zeros_like(r)
        p = np.stack([r * st, sg * (y + self.L) + z, -r * ct], axis=1)
        tth = np.stack([ct, z, st], axis=1)
        ty = np.stack([F1 * st, sg + z, -F1 * ct], axis=1)
        n = np.stack([st, -sg * F1, -ct], axis=1) / np.sqrt(1.0 + F1**2)[:, None]
        return dict(point=p, t_theta=tth, t_y=ty, normal=n, radius=r, F1=F1, F2=F2)

    def curvatures(self, y):
        """Principal curvatures (k_rolling, k_lateral) (1/m), convex positive, at y (m)."""
        F, F1, F2 = self.profile.evaluate(y)
        r = self.profile.r0 + F
        w = 1.0 + F1**2
        return 1.0 / (r * np.sqrt(w)), -F2 / w**1.5


class RailSurface:
    """Rail surface: a mounted rail profile swept along the track centreline.

    Parameters
    ----------
    track : Track
    mounting : RailMounting
    side : {+1, -1}
        +1 left rail, -1 right rail.
    """

    def __init__(self, track: Track, mounting: RailMounting, side=1):
        if side not in (1, -1):
            raise InputError(f"rail surface: side must be +1 (left) or -1 (right), got {side!r}")
        self.track = track
        self.mounting = mounting
        self.side = int(side)

    def evaluate(self, s, u):
        """Global point, tangents, outward normal and curvatures at (s, u).

        Returns
        -------
        dict with ``point``, ``t_s``, ``t_u``, ``normal`` (N, 3), ``k_rolling``, ``k_lateral`` (N,).
        """
        s = np.atleast_1d(np.asarray(s, dtype=float))
        u = np.atleast_1d(np.asarray(u, dtype=float))
        fr = self.track.evaluate(s)
        Yo, Z, a1, b1, a2, b2 = self.mounting.mounted(u)
        sg = self.side
        z = np.zeros_like(Yo)
        loc = np.stack([z, sg * Yo, Z], axis=1)
        Rl = np.einsum("nij,nj->ni", fr.R, loc)
        q = fr.position + Rl
        ts = fr.dposition + np.cross(fr.omega, Rl)
        tu = np.einsum("nij,nj->ni", fr.R, np.stack([z, sg * a1, b1], axis=1))
        n = sg * np.cross(ts, tu)
        n /= np.linalg.norm(n, axis=1)[:, None]
        qss = (fr.ddposition + np.cross(fr.domega, Rl) + np.cross(fr.omega, np.cross(fr.omega, Rl)))
        k_x = -np.sum(n * qss, axis=1) / np.sum(ts * ts, axis=1)
        _, v1, v2 = self.mounting.profile.evaluate(u)
        k_y = -v2 / (1.0 + v1**2) ** 1.5
        return dict(point=q, t_s=ts, t_u=tu, normal=n, k_rolling=k_x, k_lateral=k_y)
