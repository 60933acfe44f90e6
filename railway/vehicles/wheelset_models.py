r"""Canonical single-wheelset models on the core, shared by tests, scenes and benchmarks.

* :func:`free_wheelset` — the "flying" wheelset: one wheelset rolling on straight track with no
  suspension, released with a lateral offset (its kinematic oscillation, Klingel).
* :func:`suspended_wheelset` — a wheelset held by a lateral spring k_y and a yaw spring k_ψ to
  a frame moving at a prescribed speed V (the model of :mod:`railway.vehicles.hunting`).  The frame is a
  body on a translational joint along the track, driven by a point driver x = x0 + V t.  The
  springs are two bushings at ±b on the axle (points on the axle, so the spin does not load
  them) with lateral stiffness k_y/2 each and longitudinal stiffness k_x, giving the yaw
  stiffness k_ψ = 2 k_x b².  The wheelset's vertical, roll and spin motions are free (carried by
  the contact and the creep forces).
* :func:`eigen_critical_speed` — its linear critical speed from core's eigenvalues (nominal-spin
  formulation), with any of the contact element's reductions (:data:`TEXTBOOK`: all of them,
  the classical two-degree-of-freedom wheelset);
* :func:`linear_wheelset` — the inputs of :class:`railway.vehicles.hunting.LinearWheelset` for the same
  wheelset from the rigid contact geometry and Hertz alone (the like-for-like closed form).

Wheelsets start at the rigid contact position of their lateral offset, sunk by the Hertz approach
of their static load so that the contacts carry the weight, moving at V and spinning at V / r,
r the rolling radius at the contact.
"""

from __future__ import annotations

import numpy as np

from core import frames
from core.model import ModelBuilder

from ..contact.geometry import rigid_contact
from ..contact.profiles import WheelProfile
from ..track import RailMounting, Track
from .vehicle import GRAVITY
from .wheel_rail import WheelRailContact

__all__ = ["free_wheelset", "suspended_wheelset", "WHEELSET", "TEXTBOOK", "hunting_mode", "eigen_critical_speed",
           "linear_wheelset", "released_contact_geometry"]

#: Mass and inertias of the Manchester coach's wheelset (kg, kg m²: roll, spin, yaw)
WHEELSET = dict(mass=1813.0, inertia=(1120.0, 112.0, 1120.0))


def _start(wheel, rails, y0, E, nu):
    """(height, roll, rolling radius, Hertz approach) of a wheelset at lateral offset y0."""
    from core.contact_laws import hertz_from_load

    z, roll, res, act = rigid_contact([y0], wheel=wheel, rail=rails.profile, gauge=rails.gauge,
                                      inclination=rails.inclination, accept=getattr(rails, "accept", ()))
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
    :class:`~railway.vehicles.wheel_rail.WheelRailContact` (for linearisation): the body does not spin,
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


#: options of :class:`~railway.vehicles.wheel_rail.WheelRailContact` that reduce the multibody wheelset
#: (with ``nominal_spin=True``) to the classical two-degree-of-freedom wheelset of
#: :mod:`railway.vehicles.hunting`: no gyroscopic moment of the spin, no roll rate in the creepages, the
#: normal forces without their tilt (no gravitational stiffness, and the roll decoupled from the
#: lateral motion), creep forces in the wheelset's own frame (no contact angle), no spin creepage
TEXTBOOK = dict(gyroscopic=False, roll_rate_creepage=False, gravitational_stiffness=False,
                contact_angle=False, spin_creepage=False)


def hunting_mode(model):
    """(real [1/s], imag [rad/s]) of the least damped hunting eigenvalue of a suspended wheelset
    model (``nominal_spin=True``): core's :func:`~core.analysis.eigen` about the model's start,
    the mode whose largest component is the wheelset's lateral or yaw velocity."""
    import warnings

    from core.analysis import AnalysisWarning, eigen

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AnalysisWarning)
        tab, modes = eigen(model, model.q0, model.v0, 0.0)
    best = (-np.inf, np.nan)
    for i in tab.index:
        dom = modes[f"mode {i}"].abs().idxmax()
        if dom in ("wheelset.vy [m/s]", "wheelset.wz [rad/s]") and tab.loc[i, "imag [rad/s]"] > 1.0:
            if tab.loc[i, "real [1/s]"] > best[0]:
                best = (float(tab.loc[i, "real [1/s]"]), float(tab.loc[i, "imag [rad/s]"]))
    return best


def eigen_critical_speed(k_y, k_psi, bracket, wheel=None, rails=None, xtol=1e-4, **options):
    """Critical speed V_c [m/s] and hunting frequency [rad/s] of :func:`suspended_wheelset` (in
    the nominal-spin formulation) from core's eigenvalues: Brent's method on the real part of the
    hunting eigenvalue (:func:`hunting_mode`) in ``bracket`` (m/s, a sign change), to ``xtol``
    (m/s).  ``options`` go to the contact element (e.g. ``**TEXTBOOK``)."""
    from scipy.optimize import brentq

    def model(V):
        return suspended_wheelset(V, k_y, k_psi, wheel=wheel, rails=rails, nominal_spin=True, **options)

    Vc = brentq(lambda V: hunting_mode(model(V))[0], *bracket, xtol=xtol)
    return float(Vc), hunting_mode(model(Vc))[1]


def linear_wheelset(k_y, k_psi, wheel=None, rails=None, E=2.1e11, nu=0.28, dy=1e-3, dpsi=1e-3):
    """The parameters of :class:`railway.vehicles.hunting.LinearWheelset` for the wheelset of
    :func:`suspended_wheelset`, from the rigid contact geometry and Hertz, independently of the
    dynamic model.

    Conicity λ = Δr / (2 y), roll ρ = dφ/dy, contact-angle slope dδ_L/dy and the height's
    curvature z_yy from fits over ``|y|`` ≤ ``dy`` (m) of
    :func:`~railway.contact.geometry.contact_geometry_table` (linear, quadratic for z), z_ψψ
    over ``|ψ|`` ≤ ``dpsi`` (rad); rolling radius r0, half contact spacing l and contact angle δ0
    of the central position; Hertz ellipse of the static wheel load m g / (2 cos δ0) along the
    normal and Kalker's f_ij = G c^k C_ij (c = √(ab)) from
    :func:`~railway.contact.creep.kalker_coefficients`, averaged over the two wheels; the wheelset's
    mass and inertias (:data:`WHEELSET`).
    """
    from core.contact_laws import hertz_from_load

    from ..contact.geometry import contact_geometry_table, rigid_contact
    from ..contact.creep import kalker_coefficients
    from .hunting import LinearWheelset

    wheel = wheel if wheel is not None else WheelProfile.s1002()
    rails = rails if rails is not None else RailMounting()
    geo = dict(wheel=wheel, rail=rails.profile, gauge=rails.gauge, inclination=rails.inclination,
               accept=getattr(rails, "accept", ()))
    ys = np.linspace(-dy, dy, 21)
    tab = contact_geometry_table(ys, **geo)
    lam = float(np.polyfit(ys, tab["delta_r [m]"], 1)[0] / 2.0)
    rho = float(np.polyfit(ys, tab["roll [rad]"], 1)[0])
    dgam = float(np.polyfit(ys, tab["gamma_L [rad]"], 1)[0])
    z_yy = float(2.0 * np.polyfit(ys, tab["z [m]"], 2)[0])
    ps = np.linspace(-dpsi, dpsi, 11)
    z_psi = [float(contact_geometry_table([0.0], yaw=p, **geo)["z [m]"].iloc[0]) for p in ps]
    z_pp = float(2.0 * np.polyfit(ps, z_psi, 2)[0])
    _, _, res, act = rigid_contact([0.0], **geo)
    i, c = np.arange(2), act[0]
    A = 0.5 * (res.k_wheel_rolling + res.k_rail_rolling)[i, c]
    B = 0.5 * (res.k_wheel_lateral + res.k_rail_lateral)[i, c]
    delta0 = float(np.mean(np.abs(res.contact_angle[i, c])))
    W = WHEELSET["mass"] * GRAVITY / 2.0
    h = hertz_from_load(W / np.cos(res.contact_angle[i, c]), A, np.clip(B, A / 1e3, A * 1e3), E, nu, E, nu)
    C11, C22, C23, C33 = kalker_coefficients(h.a / h.b, nu)
    G = E / (2.0 * (1.0 + nu))
    cc = np.sqrt(h.a * h.b)
    l = 0.5 * abs(res.point_wheel[0, c[0], 1] - res.point_wheel[1, c[1], 1])
    m, (Ix, Iy, Iz) = WHEELSET["mass"], WHEELSET["inertia"]
    return LinearWheelset(m=m, I=Iz, k_y=k_y, k_psi=k_psi, f11=float(np.mean(G * cc**2 * C11)),
                          f22=float(np.mean(G * cc**2 * C22)), l=float(l),
                          r0=float(np.mean(res.rolling_radius[i, c])), conicity=lam,
                          f23=float(np.mean(G * cc**3 * C23)), f33=float(np.mean(G * cc**4 * C33)),
                          roll_per_lateral=rho, contact_angle_slope=dgam, delta0=delta0, spin_inertia=Iy,
                          roll_inertia=Ix, z_yy=z_yy, z_psipsi=z_pp, gravity=GRAVITY,
                          normal_load=float(np.mean(W / np.cos(res.contact_angle[i, c]))))


def released_contact_geometry(model):
    """Rolling radius r0 [m] (mean of the two wheels) and half contact spacing l [m] of a single-
    wheelset model (:func:`free_wheelset`, :func:`suspended_wheelset`) at its initial state: the
    contacts its wheel-rail element finds there, with the search started from that pose.  These
    are the inputs of Klingel's wavelength 2π √(r0 l / λ) (:func:`railway.vehicles.hunting.klingel_wavelength`)
    for the wheelset as released."""
    kind = next(k for k in model.force_kinds if type(k).__name__ == "WheelRailKind")
    st = kind.sets[0]
    bs = model.body_states(model.q0, model.v0)
    kind.reset_state(bs, 0.0)
    r, A, v, w = st.states(bs)
    res = st.contacts(r, A, v, w)[0]
    l = 0.5 * abs(res.point_wheel[0, 0, 1] - res.point_wheel[1, 0, 1])
    return float(np.mean(res.rolling_radius[:, 0])), float(l)
