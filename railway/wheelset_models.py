r"""Canonical single-wheelset models on the core, shared by tests, scenes and benchmarks.

* :func:`free_wheelset` — the "flying" wheelset: one wheelset rolling on straight track with no
  suspension, released with a lateral offset (its kinematic oscillation, Klingel).
* :func:`suspended_wheelset` — a wheelset held by a lateral spring k_y and a yaw spring k_ψ to
  a frame moving at a prescribed speed V (the model of :mod:`railway.hunting`).  The frame is a
  body on a translational joint along the track, driven by a point driver x = x0 + V t.  The
  springs are two bushings at ±b on the axle (points on the axle, so the spin does not load
  them) with lateral stiffness k_y/2 each and longitudinal stiffness k_x, giving the yaw
  stiffness k_ψ = 2 k_x b².  The wheelset's vertical, roll and spin motions are free (carried by
  the contact and the creep forces).

Wheelsets start at the rigid contact position of their lateral offset, sunk by the Hertz approach
of their static load so that the contacts carry the weight, moving at V and spinning at V / r,
r the rolling radius at the contact.
"""

from __future__ import annotations

import numpy as np

from core import frames
from core.model import ModelBuilder

from .contact_geometry import rigid_contact
from .profiles import WheelProfile
from .track import RailMounting, Track
from .vehicle import GRAVITY
from .wheel_rail import WheelRailContact

__all__ = ["free_wheelset", "suspended_wheelset", "WHEELSET"]

#: Mass and inertias of the Manchester coach's wheelset (kg, kg m²: roll, spin, yaw)
WHEELSET = dict(mass=1813.0, inertia=(1120.0, 112.0, 1120.0))


def _start(wheel, rails, y0, E, nu):
    """(height, roll, rolling radius, Hertz approach) of a wheelset at lateral offset y0."""
    from core.contact_laws import hertz_from_load

    z, roll, res, act = rigid_contact([y0], wheel=wheel, rail=rails.profile, gauge=rails.gauge,
                                      inclination=rails.inclination)
    i = np.arange(2)
    c = act[0]
    A = 0.5 * (res.k_wheel_rolling + res.k_rail_rolling)[i, c]
    B = 0.5 * (res.k_wheel_lateral + res.k_rail_lateral)[i, c]
    W = WHEELSET["mass"] * GRAVITY / 2.0
    h = hertz_from_load(W / np.cos(res.contact_angle[i, c]), A, np.clip(B, A / 1e3, A * 1e3), E, nu, E, nu)
    return float(z[0]), float(roll[0]), float(np.mean(res.rolling_radius[i, c])), float(np.mean(h.delta))


def _setup(wheel, rails, y0, contact, track_length, s0, name):
    """Profiles (S1002 / UIC60 1:40 by default), the statically loaded start (:func:`_start`), a
    straight track and a spatial model builder: what both wheelset models share."""
    wheel = wheel if wheel is not None else WheelProfile.s1002()
    rails = rails if rails is not None else RailMounting()
    z, roll, r, delta = _start(wheel, rails, y0, contact.get("E", 2.1e11), contact.get("nu", 0.28))
    track = Track.straight(track_length or max(400.0, s0 + 10.0))
    return wheel, rails, z, roll, r, delta, track, ModelBuilder(3, name, gravity=(0.0, 0.0, -GRAVITY))


def free_wheelset(speed, y0, wheel=None, rails=None, creep_law="kalker_linear", creep_params=None,
                  track_length=None, s0=10.0, mu=0.3, name="free wheelset", **contact):
    """A free wheelset released at lateral offset y0 (m) at speed V (module docstring)."""
    wheel, rails, z, roll, r, delta, track, b = _setup(wheel, rails, y0, contact, track_length, s0, name)
    b.add_body("wheelset", position=(s0, y0, z - delta),
               orientation=frames.rotation_vector_to_euler(np.array([roll, 0.0, 0.0])),
               velocity=(speed, 0.0, 0.0), angular_velocity=(0.0, speed / r, 0.0), **WHEELSET)
    b.add_force(WheelRailContact("wheel-rail", ["wheelset"], track, wheel=wheel, rails=rails,
                                 creep_law=creep_law, creep_params=creep_params, mu=mu, **contact))
    return b.build()


def suspended_wheelset(speed, k_y, k_psi, y0=0.0, wheel=None, rails=None, creep_law="kalker_linear",
                       creep_params=None, b_spring=1.0, track_length=None, s0=10.0, mu=0.3,
                       name="suspended wheelset", nominal_spin=False, **contact):
    """A wheelset held by springs k_y [N/m], k_ψ [N m/rad] to a frame moving at V (module
    docstring).  ``nominal_spin=True``: the non-rotating wheelset formulation of
    :class:`~railway.wheel_rail.WheelRailContact` (for linearisation): the body does not spin,
    the contact adds the nominal spin V / r."""
    from core.drivers import polynomial

    wheel, rails, z, roll, r, delta, track, b = _setup(wheel, rails, y0, contact, track_length, s0, name)
    zc = z - delta
    spin = speed / r
    b.add_body("wheelset", position=(s0, y0, zc),
               orientation=frames.rotation_vector_to_euler(np.array([roll, 0.0, 0.0])),
               velocity=(speed, 0.0, 0.0), angular_velocity=(0.0, 0.0 if nominal_spin else spin, 0.0),
               **WHEELSET)
    if nominal_spin:
        contact = dict(contact, nominal_spin=(spin, WHEELSET["inertia"][1]))
    b.add_body("frame", mass=100.0, inertia=(10.0, 10.0, 10.0), position=(s0, 0.0, zc), velocity=(speed, 0.0, 0.0))
    b.add_translational("frame guide", "ground", "frame", at=(s0, 0.0, zc), axis=(1.0, 0.0, 0.0))
    b.add_point_driver("frame speed", "frame", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), polynomial([s0, speed]))
    kx = k_psi / (2.0 * b_spring**2)
    for side, y in (("left", b_spring), ("right", -b_spring)):
        P = (s0, y, zc)
        b.add_bushing(f"spring {side}", "frame", "wheelset", at=P, point_j=(s0, y0 + y, zc),
                      translational_stiffness=(kx, 0.5 * k_y, 0.0), rotational_stiffness=0.0)
    b.add_force(WheelRailContact("wheel-rail", ["wheelset"], track, wheel=wheel, rails=rails,
                                 creep_law=creep_law, creep_params=creep_params, mu=mu, **contact))
    return b.build()
