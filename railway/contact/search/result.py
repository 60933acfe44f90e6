"""What a contact search returns: the candidates of every wheel (tread, flange).

Every wheel has two candidates, tread and flange, solved as separate problems (zones of the
wheel profile coordinate y, see :class:`railway.contact.profiles.WheelProfile`), so that
two-point contact (tread plus flange) is found; :data:`TREAD` and :data:`FLANGE` index them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["ContactResult", "FLANGE", "TREAD"]

TREAD, FLANGE = 0, 1


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
        Principal curvatures (1/m), convex positive (see :mod:`railway.contact.surfaces`).
    flange : (n_wheels, 2) bool
        True for the flange candidate.
    residual : (n_wheels, 2)
        Largest ``|h_k|`` at the reported point.
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
