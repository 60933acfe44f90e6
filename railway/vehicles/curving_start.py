r"""Quasi-static curving: the steady state of a vehicle that follows the track at speed V.

A run that starts a vehicle in a curve or a transition must start from the state the vehicle
is in when it has run there for a while at constant speed — lateral shifts, roll and yaw of the
bodies following the track, suspension deflections, flange contact where the curve needs it,
creep forces, wheelsets rolling, every body moving with the track frame — or the run begins with
a transient that has nothing to do with the track (a vehicle dropped into a 200 m curve at
20 m/s with the straight-track preload lifts all four wheels of a bogie).  This module computes
that state on the *same* core model the run integrates (:class:`railway.vehicles.vehicle.Vehicle`): the
model's own forces (suspension, bump stops, wheel–rail contact with its creep law, speed control,
gravity, gyroscopic terms) are balanced against the accelerations of steady motion along the
track — the "quasi-static curving" analysis of vehicle-dynamics codes (Simpack Rail's
quasi-static curving and preload in the moving track frame; the steady curving of Pombo &
Ambrósio 2008), done here by the model's own right-hand side, so that a run started from it
stays there.

Reference geometry
------------------
The suspension of a core model is unloaded in the configuration it is built in.  A vehicle is
therefore always built in its straight design geometry (bodies in a line; on a curve or a
transition :func:`railway.vehicles.vehicle.build_vehicle` builds it on the tangent at s0 and then places
it on the track), so that the same vehicle — springs unloaded with the wheelsets parallel in the
bogie frame and the bogies parallel to the car body — runs wherever it starts; its primary and
secondary springs are deflected by the curve.  (A model built directly in the curved placement
would have its wheelsets "set" radial and its bogies set yawed against the car body.)

Kinematics of track-following motion
------------------------------------
Each body i has a nominal arc length s_i (car body s0, bogies s0 ± a_b, wheelsets s_b ± a_w,
as :func:`railway.vehicles.vehicle.build_vehicle` places them) and a pose *relative to the track frame*
there: position p_i = (Δx_i, y_i, z_i) and rotation vector θ_i (track-frame components, so
θ = (roll, pitch, yaw)).  With the track frame r_T(s), R(s) = [t, n, b] and its Darboux vector
ω_D(s) (dR/ds = [ω_D]× R, :mod:`railway.track`), the body moves with the frame while s grows at
ṡ = V and s̈ = a_t, its relative pose changing along the track at the rates p_i' = dp_i/ds,
θ_i' (Eq. 1a):

.. math::

    r_i = r_T + R\,p_i, \qquad A_i = R\,\exp[\theta_i]_\times, \qquad
    u_i = r_T' + \omega_D \times R p_i + R p_i', \qquad \dot r_i = V u_i,
    \qquad \omega_i = V\,(\omega_D + R\theta_i') + \Omega_i\,a_i                    \quad (1)

    \ddot r_i = a_t u_i + V^2\bigl(r_T'' + \omega_D' \times R p_i
              + \omega_D \times (\omega_D \times R p_i) + 2\,\omega_D \times R p_i'
              + R p_i''\bigr)                                                       \quad (2)

    \dot\omega_i = a_t(\omega_D + R\theta_i') + V^2\bigl(\omega_D' + \omega_D \times R\theta_i'
                 + R\theta_i''\bigr) + \Omega_i V\,(\omega_D + R\theta_i') \times a_i   \quad (3)

where a_i = A_i e_y is a wheelset's axle and Ω_i its spin relative to the track frame (zero for
the car body and bogies).  In a circular curve or on straight track p' = θ' = 0 and (1)–(3) are
the rigid rotation of the whole vehicle about the vertical axis through the curve centre at the
rate V κ: (2) is the centripetal acceleration of every body, (3) holds the gyroscopic
precession of the spinning wheelsets, and the angular velocity V κ e_z of the track frame is
the bodies' yaw rate.  In a transition ω_D also holds the cant rate φ' t, ω_D' and r'' the
change of curvature and cant (the car body's yaw acceleration V²κ'), and the relative poses
change with s: the car body rides on the chord of its bogies, whose offset from the centreline
grows with κ (at 20 m/s through a 40 m clothoid to R = 200 m, 0.11 m/s against the track), the
wheelsets' angles of attack grow with it.  These rates (Eq. 1a) are taken from the geometric
placement of the bodies on the chords (below), by central differences over ±0.25 m; the slower
change of the elastic part of the state (creep, deflections) is neglected, which is what
"quasi-static" means in a transition (no steady state exists there).

Equations solved
----------------
Core's equations of motion M v̇ = Q(t, q, v) (translations in global axes, body-frame angular
velocities ω̄ = Aᵀω, so that ω̄̇ = Aᵀω̇; :mod:`core.model`) hold along the motion (1)–(3) when

.. math::

    F(x) = Q\bigl(t_0, q(x), v(x)\bigr) - M\,\dot v(x) = 0                          \quad (4)

— six rows per body (plus one per extra coordinate, e.g. the node of a series spring–damper,
whose steady rate is zero).  The unknowns x are the relative poses (p_i, θ_i) of all bodies
except two gauges — the car body's Δx (it defines s0) and each wheelset's spin angle θ_y (a
wheel is a body of revolution) — which are replaced by:

* the spin Ω_i of every wheelset (its row: no net torque about the axle, the free-rolling
  condition of :func:`railway.contact.quasi_static.quasi_static_rolling`);
* one longitudinal unknown: with a :class:`railway.vehicles.traction.TrackSpeedControl` on the car body,
  the speed V at which the control force balances the curving resistance (a_t = dV_set/dt at
  t0); without it (a coasting vehicle), the deceleration a_t at the vehicle's speed.

The creep forces are those of the model's creep law at the creepages of the motion (1): in a
curve the leading wheelset of a bogie runs with an angle of attack against the track and shifts
outwards to flange contact, the trailing one stays near the centre (Wickens 2003, ch. 7); (4)
finds that balance and the deflections that carry it to the bogies and the car body.

Method
------
Pseudo-transient continuation (Ψtc; Kelley & Keyes 1998, Eq. 1.3) on (4):

.. math::

    \bigl(D/\delta_k - J_k\bigr)\,\Delta x_k = F(x_k), \qquad
    \delta_{k+1} = \delta_k\,\max\bigl(\|F_k\| / \|F_{k+1}\|, 1\bigr)^2 \cdot
    \begin{cases} 1.3 & \|F_{k+1}\| < \|F_k\| \\ 0.5 & \text{else} \end{cases}    \quad (5)

with D the inertia of each unknown on its own row (m_i, J_i, the spin inertia, the vehicle's
mass), δ_0 = 1e-3 s and δ capped at 1e8 s (then (5) is Newton's method).  Each step is a damped
implicit-Euler step of the first-order dynamics D ẋ = F: from the rough geometric guess it walks
along the stable path of the vehicle into the curve; as the residual falls, δ grows (switched
evolution relaxation, sharpened by the square and the factor 1.3: the plain SER ratio stalls in
a transition, where ‖F‖ falls by a percent per step) and the iteration becomes Newton's, with
quadratic convergence to the rounding level of the contact forces.  A step that raises ‖F‖
more than tenfold is refused and δ quartered; a step moves no wheelset more than 1 mm or 1 mrad
and no other body more than 20 mm or 20 mrad (the contact is stiff and piecewise: a longer
step jumps across flange contact).  Pure Newton with line search from the same guess stalls in
the curve (the linear model of the saturated creep forces holds for 1e-3 of its step).  J is
the forward-difference Jacobian of (4) (steps 1e-7 m, 1e-7 rad, 1e-6 m/s, 1e-6 rad/s) with the
contact search frozen at the iterate (:class:`railway.vehicles.wheel_rail.WheelRailKind`); the search
is refreshed by a fresh global search at every iterate.  Residual scaling: translational rows
by m_i g, rotational rows by m_i g · 1 m; converged when every scaled row is below ``tol``
(default 1e-9).

Initial guess: the geometric curving placement — wheelsets centred on the track and parallel
to their bogie frame, each bogie frame on the chord of its wheelsets, the car body on the chord
of the bogie centres, all at the design heights lowered by the Hertz approach of the static
wheel load, spins V / r0.

A start is refused (:class:`core.errors.InputError` naming s0, the speed and the reason) when
the unbalanced lateral acceleration a_q = V²κ cos φ + g sin φ reaches the rigid overturning
limit g b0 / (2 h_cg) (b0 the track's cant base, h_cg the vehicle's centre of gravity), when the
quasi-static state lifts a wheel (Q ≤ 0), when the model has no creep law or the speed is not
positive (creepages are relative to the rolling speed; a vehicle at rest in a curve is held by
static friction, which the creep laws do not describe), or when no steady state is found.

Measured (Manchester coach, Polach 2000, 20 m/s, R = 200 m, tests/railway/test_curve_start.py):
the state converges in 20–30 iterations (6–11 s); a run of 0.3 s from it (jit-dop853, rtol 1e-4)
keeps every wheel load within 0.4 N and every body's lateral displacement within 1e-10 m; the
rail forces balance m (V²κ cos φ + g sin φ) to 0.06 %.

References
----------
Pombo, J. and Ambrósio, J. (2008). Application of a wheel–rail contact model to railway
dynamics in small radius curved tracks. Multibody System Dynamics 19:91–114 (steady curving);
the moving track frame of Pombo & Ambrósio (2003), MSD 9:237–264.
Wickens, A. H. (2003). Fundamentals of Rail Vehicle Dynamics, ch. 7 (steady curving of a
bogie vehicle: equilibrium of the wheelsets under centripetal, gravitational, creep and flange
forces).
Kelley, C. T. and Keyes, D. E. (1998). Convergence analysis of pseudo-transient continuation.
SIAM J. Numer. Anal. 35(2):508–523 (Ψtc and the SER update of δ, Eq. 1.3).
SIMPACK Rail documentation, "Quasi-static curving" and "Preload" (equilibrium in the moving
track frame at the vehicle's speed).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from core import frames
from core.errors import InputError, NumericalFailure

__all__ = ["CurvingStart", "quasi_static_curving"]


def _rotation(theta):
    """Rotation matrices exp([θ]×) (Rodrigues), θ (n, 3) -> (n, 3, 3)."""
    th = np.asarray(theta, float)
    ang = np.linalg.norm(th, axis=-1)
    K = frames.skew(th)
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.where(ang > 1e-8, np.sin(ang) / np.where(ang > 0, ang, 1.0), 1.0 - ang**2 / 6.0)
        b = np.where(ang > 1e-8, (1.0 - np.cos(ang)) / np.where(ang > 0, ang, 1.0) ** 2, 0.5 - ang**2 / 24.0)
    return np.eye(3) + a[..., None, None] * K + b[..., None, None] * (K @ K)


def _rotation_vector(A):
    """Rotation vector of rotation matrices (n, 3, 3) -> (n, 3) (angles < pi)."""
    p = frames.matrix_to_euler(A)
    s = np.linalg.norm(p[..., 1:], axis=-1)
    ang = 2.0 * np.arctan2(s, p[..., 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        f = np.where(s > 1e-12, ang / np.where(s > 0, s, 1.0), 2.0)
    return f[..., None] * p[..., 1:]


@dataclass
class CurvingStart:
    """The quasi-static curving state of a vehicle (module docstring).

    Attributes
    ----------
    q, v : (n_q,), (n_v,) ndarray
        Coordinates and velocities of the model at the start.
    acceleration : (n_v,) ndarray
        v̇ of the steady motion (Eqs. 2–3 of the module docstring).
    speed : float
        Speed V of the track frame (m/s) the state moves at (with speed control: the speed at
        which the control balances the curving resistance).
    tangential_acceleration : float
        a_t (m/s²): zero with a constant speed control, else the deceleration of the coasting
        vehicle by its curving resistance.
    residual : float
        Largest scaled row of Eq. 4 at the solution.
    iterations : int
    method : str
    bodies : DataFrame
        One row per body: ``s [m]`` (nominal arc length), ``dx [m]``, ``y [m]``, ``z [m]``
        (relative to the track frame there), ``roll [rad]``, ``pitch [rad]``, ``yaw [rad]``
        (track-frame rotation vector), ``spin [rad/s]`` (wheelsets, relative to the track frame).
    wheels : DataFrame
        One row per wheel: ``Q [N]``, ``Y [N]``, ``Y/Q [-]``, ``flange contact``,
        ``flange force [N]``, ``Fx [N]``, ``Fy [N]`` (creep forces of the wheel, both patches),
        ``contact angle [rad]``, ``lateral displacement [m]``, ``angle of attack [rad]`` of the
        wheelset, ``sum Y [N]`` of the wheelset.
    balance : DataFrame
        The lateral equilibrium of the whole vehicle (an independent check): the rail forces
        along the lateral axis (−ΣY over the wheelsets) against m (V²κ cos φ + g sin φ) at the
        car body's s, and their relative difference.
    """

    q: np.ndarray
    v: np.ndarray
    acceleration: np.ndarray
    speed: float
    tangential_acceleration: float
    residual: float
    iterations: int
    method: str
    bodies: pd.DataFrame
    wheels: pd.DataFrame
    balance: pd.DataFrame
    history: list = field(default_factory=list)

    def state(self):
        """(q, v): the start of a run."""
        return self.q.copy(), self.v.copy()


class _Problem:
    """Eq. 4 of the module docstring for one vehicle: unknowns <-> (q, v, v̇), scaled residual."""

    def __init__(self, vehicle, t0, speed):
        from .traction import TrackSpeedControlKind
        from .vehicle_file import GRAVITY

        self.veh = vehicle
        m = self.model = vehicle.model
        D = vehicle.definition
        g = D.geometry
        self.t0 = float(t0)
        self.g = GRAVITY
        self.names = [vehicle.car_body] + list(vehicle.bogies) + list(vehicle.wheelsets)
        L_b, a_w = g["bogie_centre_semi_distance"], g["bogie_semi_wheelbase"]
        s0 = vehicle.s0
        s_b = [s0 + L_b, s0 - L_b]
        self.s = np.array([s0] + s_b + [s_b[0] + a_w, s_b[0] - a_w, s_b[1] + a_w, s_b[1] - a_w])
        self.nb = len(self.names)
        self.is_ws = np.array([n in vehicle.wheelsets for n in self.names])
        fr = vehicle.track.evaluate(self.s)
        self.rT, self.dr, self.ddr = fr.position, fr.dposition, fr.ddposition
        self.R, self.om, self.dom = fr.R, fr.omega, fr.domega
        # curvature and cant (a railway.track.Track reports them; any other framed curve: from
        # the frame, kappa = omega . b and phi = asin(n_z))
        self.kappa = getattr(fr, "curvature", np.einsum("ni,ni->n", fr.omega, fr.R[:, :, 2]))
        self.cant = getattr(fr, "cant_angle", np.arcsin(np.clip(fr.R[:, 2, 1], -1.0, 1.0)))
        self.bidx = np.array([m.body_index(n) for n in self.names])
        if sorted(self.bidx.tolist()) != list(range(m.n_bodies)):
            raise InputError(f"quasi-static curving: model {m.name!r} has bodies other than the vehicle's "
                             f"{self.names}")
        self.n_x = len(m.extra_names)
        # masses and scales per velocity row
        self.Mmat = m.M(0.0, m.q0)  # constant (body-frame inertia)
        Md = np.asarray(self.Mmat.diagonal()).ravel()
        self.Md = Md
        self.mass = Md[: 6 * m.n_bodies].reshape(m.n_bodies, 6)[:, 0]
        sc = np.empty(m.n_v)
        for k in range(m.n_bodies):
            sc[6 * k:6 * k + 3] = self.mass[k] * GRAVITY  # forces: m_i g
            sc[6 * k + 3:6 * k + 6] = self.mass[k] * GRAVITY * 1.0  # moments: m_i g x 1 m
        if self.n_x:
            sc[6 * m.n_bodies:] = np.maximum(Md[6 * m.n_bodies:], 1e-6) * GRAVITY
        self.scale = sc
        # the speed control on the car body, if any: V is then unknown, a_t = dV_set/dt
        self.control = None
        cb = m.body_index(vehicle.car_body)
        for k in m.force_kinds:
            if isinstance(k, TrackSpeedControlKind) and cb in k.b.tolist():
                i = k.b.tolist().index(cb)
                self.control = (k, i)
        self.speed = float(speed)
        if self.control is not None:
            k, i = self.control
            Vf = k.V[i]
            h = 1e-4
            self.a_set = float((Vf(self.t0 + h)[0] - Vf(self.t0 - h)[0]) / (2 * h)) if self.t0 >= h else \
                float((Vf(self.t0 + h)[0] - Vf(self.t0)[0]) / h)
            self.speed_set = float(Vf(self.t0)[0])
        # unknowns: free pose components, the longitudinal unknown, spins, extras
        free = []
        for k, nm in enumerate(self.names):
            comps = list(range(6))
            if k == 0:
                comps.remove(0)  # the car body's travel: s0
            if self.is_ws[k]:
                comps.remove(4)  # the spin angle
            free += [(k, c) for c in comps]
        self.free = free
        self.n_pose = len(free)
        self.i_long = self.n_pose
        self.i_spin = self.n_pose + 1
        self.ws_rows = np.nonzero(self.is_ws)[0]
        self.i_x = self.i_spin + len(self.ws_rows)
        self.n = self.i_x + self.n_x
        self.pose0 = np.zeros((self.nb, 6))
        self.dp, self.ddp = self._rates()

    # -- unknowns ------------------------------------------------------------------------
    def _chords(self, shift=0.0):
        """Geometric placement of the bodies relative to their track frames with the vehicle
        moved by ``shift`` (m) along the track: (nb, 6) of (Δx, y, 0, 0, 0, yaw) — wheelsets
        centred on the track and parallel to their bogie frame, each bogie frame on the chord of
        its wheelsets and the car body on the chord of the bogie centres ("Reference geometry"
        in the module docstring)."""
        fr = self.veh.track.evaluate(self.s + shift)
        rT, R = fr.position, fr.R
        ws = np.nonzero(self.is_ws)[0]
        centre = rT.copy()
        heading = np.zeros((self.nb, 3))
        for kb, (wf, wr) in ((1, (ws[0], ws[1])), (2, (ws[2], ws[3]))):
            centre[kb] = 0.5 * (rT[wf] + rT[wr])
            heading[kb] = rT[wf] - rT[wr]
        centre[0] = 0.5 * (centre[1] + centre[2])
        heading[0] = centre[1] - centre[2]
        for k in ws:
            heading[k] = heading[1 if k in ws[:2] else 2]
        pose = np.zeros((self.nb, 6))
        for k in range(self.nb):
            d = heading[k] / np.linalg.norm(heading[k])
            pose[k, 5] = np.arctan2(d @ R[k][:, 1], d @ R[k][:, 0])
            if not self.is_ws[k]:
                pose[k, :2] = (R[k].T @ (centre[k] - rT[k]))[:2]
        pose[0, 0] = 0.0  # the car body's travel is the gauge: at s0
        return pose

    def _rates(self, h=0.25):
        """dp/ds and d²p/ds² (nb, 6) of the geometric placement (central differences over
        ±h m, one-sided at the ends of the track): zero on straight track and in a curve, the
        growth of the chord offsets and angles of attack in a transition (Eq. 1a)."""
        L = np.inf if getattr(self.veh.track, "closed", False) else getattr(self.veh.track, "length", np.inf)
        lo = max(-h, -float(np.min(self.s)))
        hi = min(h, L - float(np.max(self.s)))
        if hi - lo < 1e-6:
            return np.zeros((self.nb, 6)), np.zeros((self.nb, 6))
        mid = 0.5 * (lo + hi)
        pa, pm, pb = self._chords(lo), self._chords(mid), self._chords(hi)
        half = 0.5 * (hi - lo)
        d1 = (pb - pa) / (2.0 * half)
        d2 = (pb - 2.0 * pm + pa) / half**2
        return d1, d2

    def guess(self):
        """The geometric curving placement (:meth:`_chords`) at the design heights lowered by
        the Hertz approach of the static wheel load; spins at V / r0."""
        m = self.model
        D = self.veh.definition
        gm = D.geometry
        ws = np.nonzero(self.is_ws)[0]
        drop = self._hertz_drop()
        pose = self._chords()
        pose[0, 2] = gm["car_body_cg_height"] - drop
        pose[1:3, 2] = gm["bogie_cg_height"] - drop
        pose[ws, 2] = D.r0 - drop
        self.pose0 = pose.copy()
        x = np.zeros(self.n)
        x[: self.n_pose] = [pose[k, c] for k, c in self.free]
        x[self.i_long] = self.speed_set if self.control is not None else 0.0
        x[self.i_spin:self.i_x] = self.speed / D.r0
        if self.n_x:
            x[self.i_x:] = m.q0[7 * m.n_bodies:]
        return x

    def _hertz_drop(self):
        """Mean drop (m) of the wheelsets from rigid contact under the static wheel load (as
        :meth:`railway.vehicles.vehicle.Vehicle._hertz_guess`)."""
        q = self.veh._hertz_guess()
        m = self.model
        k = self.bidx[self.is_ws]
        z_hertz = np.einsum("nk,nk->n", q.reshape(-1)[: 7 * m.n_bodies].reshape(m.n_bodies, 7)[k, :3]
                            - m.q0[: 7 * m.n_bodies].reshape(m.n_bodies, 7)[k, :3], self.R[self.is_ws][:, :, 2])
        z_built = np.einsum("nk,nk->n", m.q0[: 7 * m.n_bodies].reshape(m.n_bodies, 7)[k, :3] - self.rT[self.is_ws],
                            self.R[self.is_ws][:, :, 2])
        return float(np.mean(self.veh.definition.r0 - (z_built + z_hertz)))

    def unpack(self, x):
        pose = self.pose0.copy()
        for j, (k, c) in enumerate(self.free):
            pose[k, c] = x[j]
        if self.control is not None:
            V, at = x[self.i_long], self.a_set
        else:
            V, at = self.speed, x[self.i_long]
        spin = np.zeros(self.nb)
        spin[self.ws_rows] = x[self.i_spin:self.i_x]
        return pose, V, at, spin, x[self.i_x:]

    def state(self, x):
        """(q, v, v̇) of Eqs. 1–3 for the unknowns x."""
        m = self.model
        pose, V, at, spin, xe = self.unpack(x)
        R, om, dom = self.R, self.om, self.dom
        Rp = np.einsum("nij,nj->ni", R, pose[:, :3])
        A = R @ _rotation(pose[:, 3:])
        r = self.rT + Rp
        # relative rates along the track (Eq. 1a): translations and small rotations, track axes
        Rdp = np.einsum("nij,nj->ni", R, self.dp[:, :3])
        Rddp = np.einsum("nij,nj->ni", R, self.ddp[:, :3])
        Rdth = np.einsum("nij,nj->ni", R, self.dp[:, 3:])
        Rddth = np.einsum("nij,nj->ni", R, self.ddp[:, 3:])
        wRp = np.cross(om, Rp)
        u = self.dr + wRp + Rdp  # dr/ds
        rdot = V * u
        axle = A[:, :, 1]
        wb = om + Rdth  # body rotation per unit length (without the spin)
        w = V * wb + spin[:, None] * axle
        rdd = at * u + V**2 * (self.ddr + np.cross(dom, Rp) + np.cross(om, wRp) + 2.0 * np.cross(om, Rdp)
                               + Rddp)
        wd = at * wb + V**2 * (dom + np.cross(om, Rdth) + Rddth) + spin[:, None] * V * np.cross(wb, axle)
        q = np.empty(m.n_q)
        v = np.empty(m.n_v)
        a = np.empty(m.n_v)
        for k, b in enumerate(self.bidx):
            q[7 * b:7 * b + 3] = r[k]
            q[7 * b + 3:7 * b + 7] = frames.matrix_to_euler(A[k])
            v[6 * b:6 * b + 3] = rdot[k]
            v[6 * b + 3:6 * b + 6] = A[k].T @ w[k]
            a[6 * b:6 * b + 3] = rdd[k]
            a[6 * b + 3:6 * b + 6] = A[k].T @ wd[k]
        nb = m.n_bodies
        if self.n_x:
            q[7 * nb:] = xe
            v[6 * nb:] = 0.0
            a[6 * nb:] = 0.0
        return q, v, a

    def reset(self, x):
        """Fresh contact search (and speed-control projection) at x: the accepted iterate."""
        q, v, _ = self.state(x)
        self.model.begin_run(self.t0, q, v)

    def residual(self, x):
        q, v, a = self.state(x)
        Q = np.asarray(self.model.Q(self.t0, q, v), float)
        Ma = np.asarray(self.Mmat @ a).ravel()
        F = (Q - Ma) / self.scale
        # order the rows like the unknowns' bodies is not needed: the system is square
        return F

    def steps(self):
        """Forward-difference steps of the unknowns: 1e-7 m and rad for poses and extra
        coordinates (the contact search converges to 1e-10 m), 1e-6 m/s or m/s² and rad/s for
        the longitudinal unknown and the spins."""
        h = np.full(self.n, 1e-7)
        h[self.i_long] = 1e-6
        h[self.i_spin:self.i_x] = 1e-6
        return h

    def jacobian(self, x, F):
        h = self.steps()
        J = np.empty((F.size, self.n))
        for j in range(self.n):
            xp = x.copy()
            xp[j] += h[j]
            J[:, j] = (self.residual(xp) - F) / h[j]
        return J

    def step_limit(self, dx):
        """Largest fraction (<= 1) of dx that moves no wheelset by more than 1 mm or 1 mrad, no
        other body by more than 20 mm or 20 mrad, and no spin by more than 5 % of V / r0 (the
        contact is stiff and piecewise: a longer step jumps across flange contact)."""
        lim = np.full(self.n, np.inf)
        for j, (k, c) in enumerate(self.free):
            lim[j] = 1e-3 if self.is_ws[k] else 2e-2
        lim[self.i_spin:self.i_x] = 0.05 * max(self.speed, 1.0) / self.veh.definition.r0
        with np.errstate(divide="ignore"):
            f = np.min(lim / np.maximum(np.abs(dx), 1e-300))
        return min(1.0, float(f))

    def pseudo_mass(self):
        """D of the pseudo-transient (n, n): each unknown's inertia on its own row of Eq. 4
        (m_i or J_i of the body, J_y for a spin, the vehicle's mass for the longitudinal
        unknown), in the scaled units of the residual."""
        m = self.model
        Md = self.Md
        Dm = np.zeros((self.n, self.n))
        for j, (k, c) in enumerate(self.free):
            r = 6 * self.bidx[k] + c
            Dm[r, j] = Md[r] / self.scale[r]
        r = 6 * self.bidx[0]
        Dm[r, self.i_long] = self.veh.definition.total_mass / self.scale[r]
        for j, k in enumerate(self.ws_rows):
            r = 6 * self.bidx[k] + 4
            Dm[r, self.i_spin + j] = Md[r] / self.scale[r]
        for j in range(self.n_x):
            r = 6 * m.n_bodies + j
            Dm[r, self.i_x + j] = Md[r] / self.scale[r]
        return Dm

    def solve(self, x, tol, max_iter, delta0=1e-3):
        """Pseudo-transient continuation, Eq. 5 of the module docstring: (D/δ − J) Δx = F with
        δ grown by the sharpened switched evolution relaxation (Kelley & Keyes 1998, Eq. 1.3)
        and capped at 1e8 (a Newton step); a step that raises ‖F‖ more than tenfold is refused
        and δ quartered.  Returns (x, max|F|, iterations, history of max|F|)."""
        Dm = self.pseudo_mass()
        delta = delta0
        self.reset(x)
        F = self.residual(x)
        nF = float(np.linalg.norm(F))
        hist = [float(np.max(np.abs(F)))]
        it = 0
        for it in range(1, max_iter + 1):
            if not np.all(np.isfinite(F)):
                break
            if np.max(np.abs(F)) <= tol:
                it -= 1
                break
            J = self.jacobian(x, F)
            while True:
                try:
                    dx = np.linalg.solve(Dm / delta - J, F)
                except np.linalg.LinAlgError:
                    dx = np.linalg.lstsq(Dm / delta - J, F, rcond=None)[0]
                x1 = x + self.step_limit(dx) * dx
                self.reset(x1)
                F1 = self.residual(x1)
                n1 = float(np.linalg.norm(F1))
                if (np.isfinite(n1) and n1 <= 10.0 * nF) or delta < 1e-9:
                    break
                delta *= 0.25
                self.reset(x)
            delta = min(delta * max(nF / max(n1, 1e-300), 1.0) ** 2 * (1.3 if n1 < nF else 0.5), 1e8)
            x, F, nF = x1, F1, n1
            hist.append(float(np.max(np.abs(F))))
        return x, float(np.max(np.abs(F))), it, hist

    # -- results -------------------------------------------------------------------------
    def result(self, x, res, it, hist):
        from .vehicle_file import GRAVITY

        m = self.model
        q, v, a = self.state(x)
        pose, V, at, spin, _ = self.unpack(x)
        self.reset(x)
        bs = m.body_states(q, v)
        kind = self.veh.contact_kind
        out = kind.contact_outputs(bs, self.t0)
        w, c, s = out["wheels"], out["contacts"], out["wheelsets"]
        n_ws = len(self.veh.wheelsets)
        wheels = pd.DataFrame({
            "wheel": self.veh.wheel_names, "Q [N]": w["Q [N]"], "Y [N]": w["Y [N]"], "Y/Q [-]": w["Y/Q [-]"],
            "flange contact": w["flange contact"], "flange force [N]": w["flange force [N]"],
            "Fx [N]": c["Fx [N]"].sum(axis=1), "Fy [N]": c["Fy [N]"].sum(axis=1),
            "contact angle [rad]": w["contact angle [rad]"],
            "lateral displacement [m]": np.repeat(s["lateral displacement [m]"], 2),
            "angle of attack [rad]": np.repeat(s["angle of attack [rad]"], 2),
            "sum Y [N]": np.repeat(s["sum Y [N]"], 2)})
        bodies = pd.DataFrame({"body": self.names, "s [m]": self.s, "dx [m]": pose[:, 0], "y [m]": pose[:, 1],
                               "z [m]": pose[:, 2], "roll [rad]": pose[:, 3], "pitch [rad]": pose[:, 4],
                               "yaw [rad]": pose[:, 5], "spin [rad/s]": spin})
        mt = self.veh.definition.total_mass
        kap, phi = float(self.kappa[0]), float(self.cant[0])
        need = mt * (V**2 * kap * np.cos(phi) + GRAVITY * np.sin(phi))
        got = -float(np.sum(s["sum Y [N]"]))
        balance = pd.DataFrame([{
            "rail forces along the lateral axis [N]": got,
            "m (V^2 kappa cos(phi) + g sin(phi)) [N]": need,
            "difference [N]": got - need,
            "relative difference [-]": (got - need) / max(abs(need), mt * GRAVITY * 1e-6),
            "unbalanced lateral acceleration [m/s2]": need / mt}])
        return dict(q=q, v=v, acceleration=a, speed=float(V), tangential_acceleration=float(at), residual=res,
                    iterations=it, wheels=wheels, bodies=bodies, balance=balance, history=hist)


def _refuse(vehicle, why):
    return InputError(f"quasi-static curving start of {vehicle.model.name!r} at s0 = {vehicle.s0:g} m, "
                      f"speed = {vehicle.speed:g} m/s: {why}")


def quasi_static_curving(vehicle, t0: float = 0.0, tol: float = 1e-9, max_iter: int = 150) -> CurvingStart:
    """The quasi-static curving state of ``vehicle`` at its s0 and speed (module docstring).

    Parameters
    ----------
    vehicle : railway.vehicles.vehicle.Vehicle
        Built by :func:`railway.vehicles.vehicle.build_vehicle` with a creep law; its ``speed`` is the
        speed V (m/s) of the start, its ``s0`` the car body's arc length.
    t0 : float
        Start time (s) at which time-dependent inputs (the speed control) are evaluated.
    tol : float
        Convergence: every row of Eq. 4, scaled by m_i g (forces) or m_i g · 1 m (moments),
        below ``tol``.
    max_iter : int
        Iterations of the pseudo-transient continuation.

    Returns
    -------
    CurvingStart

    Raises
    ------
    InputError
        No creep law, a speed that is not positive, an unbalanced lateral acceleration beyond
        the rigid overturning limit g b0 / (2 h_cg), no convergence, or a solution with a
        lifted wheel; the message names s0, the speed and the reason.
    """
    from .vehicle_file import GRAVITY

    veh = vehicle
    if veh.creep_law is None:
        raise _refuse(veh, "the model has no creep law: a vehicle is steered through a curve at speed by its "
                           "creep forces (build it with creep_law=...)")
    if not (np.isfinite(veh.speed) and veh.speed > 0):
        raise _refuse(veh, "the speed must be > 0: creepages are relative to the rolling speed, and a "
                           "vehicle at rest in a curve is held by static friction, which the creep laws do "
                           "not describe (use Vehicle.preload() for a start at rest on straight track)")
    P = _Problem(veh, t0, veh.speed)
    # the rigid overturning estimate: the resultant of gravity and the centripetal acceleration
    # leaves the running circles (b0 / 2 from the centre) at the vehicle's centre of gravity
    D = veh.definition
    gm = D.geometry
    mt = D.total_mass
    h_cg = (D.car_body["mass"] * gm["car_body_cg_height"] + 2 * D.bogie["mass"] * gm["bogie_cg_height"]
            + 4 * D.wheelset["mass"] * D.r0) / mt
    b0 = getattr(veh.track, "cant_base", 1.5)
    a_q = veh.speed**2 * P.kappa * np.cos(P.cant) + GRAVITY * np.sin(P.cant)
    k = int(np.argmax(np.abs(a_q)))
    a_lim = GRAVITY * 0.5 * b0 / h_cg
    if abs(a_q[k]) >= a_lim:
        raise _refuse(veh, f"the unbalanced lateral acceleration V^2 kappa cos(phi) + g sin(phi) = "
                           f"{a_q[k]:.3g} m/s2 at s = {P.s[k]:g} m reaches the rigid overturning limit "
                           f"g b0 / (2 h_cg) = {a_lim:.3g} m/s2 (h_cg = {h_cg:.3g} m): the vehicle would overturn")
    try:
        x = P.guess()
        x, res, it, hist = P.solve(x, tol, max_iter)
    except (NumericalFailure, ArithmeticError, ValueError) as exc:
        raise _refuse(veh, f"the search for the steady state left the track's contact ({exc})") from None
    if not res <= tol:
        why = ""
        try:  # the wheel loads at the last iterate tell a vehicle that tips from one that does not settle
            w = P.result(x, res, it, hist)["wheels"]
            k = int(np.argmin(w["Q [N]"].to_numpy()))
            why = f"; at the last iterate wheel {w['wheel'][k]} carries Q = {w['Q [N]'][k]:.4g} N"
        except (NumericalFailure, ArithmeticError, ValueError):
            pass
        raise _refuse(veh, f"no quasi-static state found in {it} iterations (largest scaled residual {res:.3g}; "
                           f"unbalanced lateral acceleration {a_q[0]:.3g} m/s2, rigid overturning limit "
                           f"{a_lim:.3g} m/s2{why})")
    out = P.result(x, res, it, hist)
    lifted = out["wheels"][out["wheels"]["Q [N]"] <= 0.0]
    if len(lifted):
        raise _refuse(veh, f"wheel(s) {', '.join(lifted['wheel'])} lift in the quasi-static state (unbalanced "
                           f"lateral acceleration {a_q[0]:.3g} m/s2): the vehicle would tip over or climb the rail")
    return CurvingStart(method="pseudo-transient continuation", **out)
