r"""The wheel–rail contact as a force element of the core: every wheel of a vehicle in one call.

A :class:`WheelRailContact` names the wheelset bodies of a model, the track they run on, the
wheel and rail profiles and the creep law.  At ``build()`` it becomes one :class:`WheelRailKind`
that evaluates all wheels together: contact search on the swept rails
(:mod:`railway.contact.search`: tread and flange candidates, so two-point contact is found),
Hertz normal force with Lankarani–Nikravesh hysteresis damping and the creep law
(:mod:`railway.contact.forces`), and the generalized forces on the wheelset bodies and, where the rails
belong to a body, on that body.

Wheelset bodies
---------------
A wheelset is a spatial rigid body whose centre of mass lies on the axle, the wheel centres at
±L along its body y axis (the axle, pointing to the left wheel); x is forward and z up in the
reference configuration.  The wheelset keeps its spin as a full coordinate (absolute
coordinates, Euler parameters): its rotation about the axle is integrated like any other
rotation, and the rolling speed ω_a = ω · a is an output.  Because a wheel is a body of
revolution about a, the contact geometry depends on the axle direction only; the search uses
the *unspun* frame

.. math::

    a = A e_y, \qquad f = \frac{a \times b_T}{|a \times b_T|}, \qquad u = f \times a,
    \qquad A_{ns} = [f, a, u]

(b_T the track's up vector at the wheelset), so that yaw and roll of the wheelset enter and
its spin does not.

Forces
------
For every loaded contact c of a wheelset with centre r, the force on the wheel is
F_c = N_c n_c + F_{x,c} t_c + F_{y,c} l_c at the wheel contact point p_c plus the spin moment
M_{z,c} n_c (:class:`railway.contact.forces.ContactForces`).  The generalized forces of the wheelset
(Nikravesh 1988, Eq. 6.178; body-frame moment as core uses it):

.. math::

    Q_r = \sum_c F_c, \qquad
    Q_\omega = A^T \sum_c \left[(p_c - r) \times F_c + M_{z,c} n_c\right],

and, when the rails are mounted on a body R (``rail_body``), the reaction −F_c at the same point
and −M_{z,c} n_c act on R.  The contact is then computed in R's frame: the track is defined in
R's body coordinates and the wheelset's pose and velocities are taken relative to R,

.. math::

    r' = A_R^T (r - r_R), \quad A' = A_R^T A, \quad
    v' = A_R^T (\dot r - \dot r_R - \omega_R \times (r - r_R)), \quad
    \omega' = A_R^T (\omega - \omega_R),

so that the creepages are the wheel's slip relative to the rail body's material.

The search state, and why the force is a function of (t, q, v)
--------------------------------------------------------------
The contact search is an iteration; its start (the *seeds*) is the kind's search state, which
follows core's rule (:mod:`core.forces.protocol`): :meth:`WheelRailKind.evaluate`,
:meth:`~WheelRailKind.jacobian` and :meth:`~WheelRailKind.contact_outputs` read it and never
change it, and it changes only in :meth:`~WheelRailKind.accept_step` (after accepted steps) and
:meth:`~WheelRailKind.reset_state` (start of a run).  The state holds, per contact candidate,
**two tracked stationary points** of the gap (the lowest and the next lowest distinct one) and
the arc length s_n of each wheelset at the last accepted step.  An evaluation at (t, q, v):

1. projects each wheelset centre on the track (Newton on (r − g(s))·g′(s) = 0 from s_n, to
   1e-10 m: a function of q alone);
2. runs the contact Newton iteration from both tracked points, their rail arc length moved by
   s − s_n, to convergence, and keeps the lowest valid gap per candidate;
3. turns the contacts into forces.

So every evaluation within a step — Runge–Kutta stages, Newton iterates of the implicit
integrators, rejected attempts and dense output — sees the same state and returns the same force
at the same (t, q, v), bit for bit.  Across histories the force at (t, q, v) differs at most by
the Newton tolerance of the search, as long as the history leaves the two lowest local minima of
the gap in the two tracked points; a contact *jump* between these two minima within a step is
found because both are iterated at every evaluation.  At each accepted step the tracked points
are refreshed by a global scan of the cross-section (every ``reseed_every`` accepted steps,
default 1, and whenever a tracked contact is lost), which is what finds a new minimum, and by
Newton from seeds beside every penetrating contact (below, "Nearby minima").  A fresh search at a
stored state (:meth:`~WheelRailKind.reset_state`) runs the same accepted-step search, so it and
the state tracked along a run hold the same points (``test_curving_forces_are_the_same_fresh_and_
after_any_history``: 43 curving states, histories from 0.2 to 1 s earlier, forces equal to 1e-6).
Where the scan sees no sign change at all at a contact the run already holds (a flange contact
of a yawed wheelset in a transition), the tracked search keeps it and a fresh one misses it: 2 of
63 outputs of a curving run at 10 m/s (README, Railway vehicles).

Nearby minima
-------------
The flange flank over the gauge corner is nearly conformal: the gap across the profile is a flat
valley that can hold two minima a fraction of a millimetre apart (measured: 0.34 mm apart, gaps
−10.06 and −7.99 µm, in the Manchester coach's curving at 10 m/s), closer than the scan's grid
(64 points per zone) resolves.  Which of the two the search held decided the wheel's flange load
(2.6 kN against 11.6 kN) and so made a fresh search at a stored state disagree with the run by up
to 35 kN of lateral force on the vehicle.  After every accepted step Newton therefore also starts
``NEIGHBOUR_OFFSETS`` (±0.5, ±1.5 mm) beside every penetrating contact, so the lower minimum is
found from either one.  The same holds for two tread minima 11 mm apart with a maximum between
them: the scan's sign changes are ranked by their interpolated gap, so the maximum can rank second
and hide the second minimum (``ACCEPT_RANKS`` = 4 refines four), and Newton from a scan seed next to
the maximum ends on it (refused, B < 0): neighbour seeds start beside every refused scan seed as
well.  Where a minimum and a maximum fall into one grid interval no sign changes at all; the
zone's lowest sampled point is then a seed too.  The second tracked point and the second patch of
a zone are never the other zone's contact of the same wheel (the zones overlap at the split).

Two patches per zone, and the patch set of a wheel
--------------------------------------------------
Each candidate zone (tread, flange) may hold two penetrating local minima of the gap at once,
e.g. where the S1002 tread and flange root both touch the rail near a contact jump.  Picking only
the lowest makes the force jump when the two minima exchange places; instead the lowest
penetrating solution of the other tracked point, at least ``SEPARATION`` (3 mm) away on the wheel
profile, is a second contact patch with its own Hertz ellipse and creep forces.  Two separate
patches both carry load; two ellipses that overlap (distance d between the points below the sum
of their lateral semi-axes b1 + b2: the nearly conformal S1002 tread on the UIC60 crown, one wide
patch) share one patch's load, handed from the shallower to the deeper one as their gaps g1, g2
differ:

.. math::

    w = \operatorname{clip}\left(\frac{d - (b_1 + b_2)}{(b_1 + b_2)/2},\ 0,\ 1\right),\quad
    \sigma = \tfrac12\left(1 + \tanh\frac{g_2 - g_1}{\varepsilon}\right),\quad
    s_1 = w + (1 - w)\,\sigma,\quad s_2 = w + (1 - w)(1 - \sigma),

with ε = ``BLEND_GAP`` = 10 µm; each patch's normal and creep forces are multiplied by its share.
The shares are symmetric in the two patches, so the force is continuous where the deeper minimum
changes (where the single-point model jumps), where a second patch appears (its force starts from
zero) and where two patches separate.  Without it the error-controlled integrators reject a
large share of their steps in curves (the force jumps when the S1002 contact point jumps), and
the results depend on where the steps fall.  The shares are a modelling choice of this code
between the deepest-point and the two-patch models, not a result of contact theory (CONTACT,
for comparison, combines patches closer than a distance and separates the others).  Wheel totals
(Q, Y, Tγ) include both patches; the per-candidate outputs are the primary patch's.

The two zones overlap by 1 mm at the split, so one stationary point can be found by both: as the
flange zone's primary and as the tread zone's second patch.  The wheel's patches (tread and
flange, primary and second) are therefore taken together: a patch at the point of an earlier
loaded one (closer than ``DUPLICATE`` = 0.1 mm) carries nothing, so a point is never loaded
twice (:func:`patch_shares`; before, the flange contact was counted twice whenever the tread
zone's second tracked point had found it).  Patches of different zones do not share load (the
tread and the flange root are a two-point contact); sharing them as well made the lateral force
swing with µm of gap at the flange root and the run rattle.

Jacobians
---------
∂Q/∂q (along velocity-space increments: δr global, δθ in body axes, at fixed body-frame ω̄) and
∂Q/∂v are central finite differences inside the kind, evaluated with the frozen search state
(so the differenced function is smooth): the six pose directions of all wheelsets are perturbed
together — a wheelset's force depends on its own pose only when the rails are the ground — so
that a full Jacobian costs 12 searches whatever the number of wheelsets; with a rail body the
wheelsets are perturbed one at a time.  Velocity columns only recompute the forces (the
geometry does not depend on v).  Steps: 1e-7 m and rad for poses, 1e-6 m/s and rad/s for
velocities.  ``tests/railway/test_wheel_rail.py`` measures them against the analytic
linearisation of a wheelset on its rails (vertical Hertz stiffness 3/2 N/δ, lateral creep
damping 2 f22/V, yaw creep damping 2 f11 l²/V).

Nominal spin: a non-rotating wheelset frame for linear analyses
---------------------------------------------------------------
A spinning wheelset's body frame turns at V / r0, so a linearisation about a running state in
body-frame coordinates is the snapshot of a periodic system, not a time-invariant one, and its
eigenvalues are not those of the hunting motion.  With ``nominal_spin = (Omega, I_y)`` the spin
is split: the wheelset bodies carry only the perturbation of their rotation (they start without
spin), the creepages use the angular velocity ω + Omega a, and the nominal spin's angular
momentum I_y Omega a enters as the gyroscopic moment

.. math::

    M_g = -\frac{d}{dt}(I_y \Omega a) = -I_y \Omega\, (\omega \times a)

(Euler's equations with a constant spin about the moving axle; the formulation of the linear
wheelset models, Wickens 2003, ch. 2).  The state is then time-invariant in steady running and
core's :func:`~core.analysis.linearize` / :func:`~core.analysis.eigen` apply (scene
``railway-critical-speed``).  Integrated runs use the absolute spin.

For like-for-like comparisons with the linear wheelset models, five options switch off what the
classical two-degree-of-freedom wheelset neglects: ``gyroscopic`` (the moment above),
``roll_rate_creepage``, ``gravitational_stiffness`` (the tilt of the normal forces),
``contact_angle`` (creep in the wheelset's frame) and ``spin_creepage`` (see
:class:`railway.contact.forces.ContactForces`, "Reduced models", and :class:`railway.vehicles.hunting.LinearWheelset`,
which has the same five terms).  All are on by default.

Loss of contact and derailment
------------------------------
A wheel that lifts off has no penetration and gets zero force.  After every accepted step the
kind checks that every wheel still runs on its rail: a loaded contact that has climbed more
than ``flange_climb_height`` (radius increase, default 5 mm) above the top of the flank -- the
point of maximum flange angle, :attr:`railway.contact.profiles.WheelProfile.y_flank_top`, beyond which
Nadal's limit Y/Q falls with the contact angle, so that the climb goes on by itself -- or a
wheelset whose lateral
displacement exceeds ``max_lateral_displacement`` or whose centre sank more than
``max_drop`` below its nominal height (it left the rail), ends the run with status ``failed``,
the time, the wheel and its last Y/Q (the integrators catch the :class:`NumericalFailure` raised
from ``accept_step``).

References
----------
Pombo, J., Ambrósio, J. and Silva, M. (2007). A new wheel–rail contact model for railway
dynamics. Vehicle System Dynamics 45(2):165–189.  Nikravesh, P. E. (1988). Computer-Aided
Analysis of Mechanical Systems, Eq. 6.178.  Shabana, A. A., Zaazaa, K. E. and Sugiyama, H.
(2008). Railroad Vehicle Dynamics: A Computational Approach, ch. 5 and 6.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from core import frames
from core.errors import DataRangeError, InputError, ModelError, NotCompilable, NumericalFailure
from core.forces.protocol import ForceElement, ForceEval, ForceJacobian, ForceKind
from core.inputs import checked_options

from ..contact.search import ContactSearch
from ..contact.forces import ContactForces
from ..contact.profiles import WheelProfile
from ..track import RailMounting
from .wheel_rail_rules import (
    ACCEPT_RANKS,
    BLEND_GAP,
    DUPLICATE,
    NEIGHBOUR_OFFSETS,
    SEPARATION,
    climb_message,
)

#: A wheelset that leaves an open track within this distance (m) of an end ran past that end (a
#: step moves it by far less); elsewhere it left the rails.
END_MARGIN = 10.0

__all__ = ["WheelRailContact", "WheelRailKind", "contact_history"]

#: finite-difference steps of the Jacobian: poses (m, rad) and velocities (m/s, rad/s)
FD_POSE, FD_VELOCITY = 1e-7, 1e-6


@dataclass(frozen=True, eq=False)
class WheelRailContact(ForceElement):
    """Wheel–rail contact of a set of wheelsets on one track (a core force element).

    Parameters
    ----------
    name : str
    wheelsets : sequence of str
        Names of the wheelset bodies (spatial; body y axis = axle towards the left wheel).
    track : railway.track.Track
        The track, in global coordinates (or in ``rail_body``'s body coordinates).
    wheel : WheelProfile, optional
        Default S1002 with r0 = 0.46 m.
    rails : RailMounting or (RailMounting, RailMounting), optional
        Default UIC60 inclined 1:40 at gauge 1435 mm.
    flange_back_spacing : float
        m, default 1.360.
    creep_law : str, CreepModel or None
        Any registered creep law (``"kalker_linear"``, ``"shen_hedrick_elkins"``,
        ``"polach2000"``, ``"polach2005"``, ``"fastsim"``, ...); None: normal forces only (a
        vehicle standing on its rails, e.g. the static preload).
    creep_params : dict, optional
        Parameters of the creep law (e.g. Polach 2005's ``k_A, k_S, A, B, speed``).
    E, nu, mu : float
        Young's modulus (Pa) and Poisson ratio of wheel and rail, friction coefficient.
    restitution, approach_velocity_floor : float
        Lankarani–Nikravesh damping (see :func:`railway.contact.forces.lankarani_nikravesh_force`).
    rail_body : str, optional
        Body carrying the rails (default: the ground).
    nominal_spin : (float, float), optional
        ``(Omega, I_spin)``: the non-rotating wheelset formulation for linear analyses (module
        docstring, "Nominal spin"): the wheelsets' spin is split into a constant nominal rate
        Omega [rad/s] about the axle, not integrated (the body frames do not turn with it), and
        the bodies' own rotation; I_spin [kg m²] is the wheelsets' inertia about the axle.  Numpy
        path only.
    gyroscopic : bool
        With ``nominal_spin``: False leaves out the nominal spin's gyroscopic moment
        −I_spin Ω (ω × a) (module docstring, "Nominal spin"); refused without ``nominal_spin``.
    spin_creepage, roll_rate_creepage, contact_angle, gravitational_stiffness : bool
        Terms of the contact forces (:class:`railway.contact.forces.ContactForces`, "Reduced models"),
        all on by default.  With ``gyroscopic`` these are the five mechanisms by which the
        multibody wheelset differs from the classical two-degree-of-freedom wheelset;
        :data:`railway.vehicles.wheelset_models.TEXTBOOK` switches all five off.  Numpy path only.
    reseed_every : int
        Global re-seeding of the tracked contacts every this many accepted steps (default 1).
    flange_climb_height, max_lateral_displacement, max_drop : float
        Derailment criteria (m): a loaded contact this high (radius increase) above the top
        of the flank (the point of maximum flange angle); lateral
        displacement of a wheelset from the track centre; drop of a wheelset centre below
        its nominal height r0 above the rail tops.
    """

    name: str
    wheelsets: Any
    track: Any
    wheel: Any = None
    rails: Any = None
    flange_back_spacing: float = 1.360
    creep_law: Any = "kalker_linear"
    creep_params: Any = None
    E: float = 2.1e11
    nu: float = 0.28
    mu: float = 0.3
    restitution: float = 0.9
    approach_velocity_floor: float = 0.1
    rail_body: Any = None
    nominal_spin: Any = None
    gyroscopic: bool = True
    spin_creepage: bool = True
    roll_rate_creepage: bool = True
    contact_angle: bool = True
    gravitational_stiffness: bool = True
    reseed_every: int = 1
    flange_climb_height: float = 5e-3
    max_lateral_displacement: float = 0.05
    max_drop: float = 0.03

    @classmethod
    def compile(cls, elements, ctx):
        return WheelRailKind(elements, ctx)


@dataclass
class _State:
    """Search state of one element (see the module docstring)."""

    seeds: np.ndarray      # (2, P, 4) tracked stationary points (theta, y, s, u)
    s_ws: np.ndarray       # (n_ws,) wheelset arc lengths at the last accepted step
    valid: np.ndarray      # (P,) candidates with a contact (a valid stationary point) then
    accepted: int = 0      # accepted steps since the run started
    last_YQ: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (n_wheels,) at the last accepted step


class _Set:
    """One WheelRailContact element compiled: bodies, search, forces and state."""

    def __init__(self, e: WheelRailContact, ctx):
        if ctx.space.dim != 3:
            raise ModelError(f"wheel-rail contact {e.name!r}: needs a spatial model (ModelBuilder(3))")
        names = [e.wheelsets] if isinstance(e.wheelsets, str) else list(e.wheelsets)
        if not names:
            raise ModelError(f"wheel-rail contact {e.name!r}: no wheelset bodies given")
        if len(set(names)) != len(names):
            raise ModelError(f"wheel-rail contact {e.name!r}: a wheelset body is listed twice: {names}")
        self.name = e.name
        self.bw = np.array([ctx.index(b, e.name) for b in names], np.int64)
        self.ground = len(ctx.body_names) if hasattr(ctx, "body_names") else ctx.bs0.r.shape[0] - 1
        if np.any(self.bw == self.ground):
            raise ModelError(f"wheel-rail contact {e.name!r}: the ground cannot be a wheelset")
        self.wheelset_names = names
        self.rb = None if e.rail_body is None else ctx.index(e.rail_body, e.name)
        if self.rb is not None and self.rb in set(self.bw.tolist()):
            raise ModelError(f"wheel-rail contact {e.name!r}: rail body {e.rail_body!r} is also a wheelset")
        self.track = e.track
        wheel = e.wheel if e.wheel is not None else WheelProfile.s1002()
        rails = e.rails if e.rails is not None else RailMounting()
        for key in ("reseed_every",):
            v = getattr(e, key)
            if not (isinstance(v, (int, np.integer)) and v >= 1):
                raise ModelError(f"wheel-rail contact {e.name!r}: {key} = {v!r} must be a positive integer")
        for key in ("flange_climb_height", "max_lateral_displacement", "max_drop"):
            v = float(getattr(e, key))
            if not (np.isfinite(v) and v > 0):
                raise ModelError(f"wheel-rail contact {e.name!r}: {key} = {v!r} m must be positive")
        self.e = e
        self.spin = None
        if e.nominal_spin is not None:
            try:
                Om, Iy = (float(x) for x in e.nominal_spin)
            except (TypeError, ValueError):
                raise ModelError(f"wheel-rail contact {e.name!r}: nominal_spin must be (Omega [rad/s], "
                                 f"I_spin [kg m^2]), got {e.nominal_spin!r}") from None
            if not (np.isfinite(Om) and np.isfinite(Iy) and Iy > 0):
                raise ModelError(f"wheel-rail contact {e.name!r}: nominal_spin = {e.nominal_spin!r} needs a finite "
                                 "rate and a positive spin inertia")
            self.spin = (Om, Iy)
        if not e.gyroscopic and self.spin is None:
            raise ModelError(f"wheel-rail contact {e.name!r}: gyroscopic=False needs the nominal-spin formulation "
                             "(nominal_spin); a spinning body's gyroscopic moment is part of its own dynamics")
        self.cs = ContactSearch(e.track, wheel=wheel, rails=rails, n_wheelsets=len(names),
                                flange_back_spacing=e.flange_back_spacing, n_seeds=2, tol=1e-11,
                                tol_linear=1e-11)
        try:
            self.cf = ContactForces(E=e.E, nu=e.nu, mu=e.mu, creep_model=e.creep_law,
                                    restitution=e.restitution,
                                    approach_velocity_floor=e.approach_velocity_floor,
                                    creep_params=e.creep_params, spin_creepage=e.spin_creepage,
                                    roll_rate_creepage=e.roll_rate_creepage, contact_angle=e.contact_angle,
                                    gravitational_stiffness=e.gravitational_stiffness)
        except ValueError as exc:
            raise ModelError(f"wheel-rail contact {e.name!r}: {exc}") from None
        self.wheel = wheel
        # derailment: a loaded contact beyond y_climb, i.e. higher than climb_height above the
        # top of the flank (F grows monotonically from there to the tip)
        self.y_climb = wheel.climb_limit(e.flange_climb_height)
        self.climb_height = float(wheel.evaluate(np.array([self.y_climb]))[0][0]
                                  - wheel.evaluate(np.array([wheel.y_flank_top]))[0][0])
        self.n_ws = len(names)
        self.state: _State | None = None
        # wheelsets must have their y axis along the track's lateral direction at build
        r, A, _, _ = self.states(ctx.bs0)
        s = self._project(r, None)
        R = self.track.evaluate_raw(s)[3]
        cos_axle = np.abs(np.einsum("ni,ni->n", A[:, :, 1], R[:, :, 1]))
        if np.any(cos_axle < 0.9):
            k = int(np.argmin(cos_axle))
            raise ModelError(f"wheel-rail contact {e.name!r}: wheelset {names[k]!r} has its body y axis "
                             f"at {np.degrees(np.arccos(min(cos_axle[k], 1.0))):.1f} deg from the track's "
                             "lateral direction; the body y axis must be the axle")

    # ---------------------------------------------------------------------------------------
    def batched(self, n):
        """This element with its wheelsets repeated ``n`` times side by side: wheelset k of copy b
        is wheelset ``b n_ws + k``, its problems ``4 (b n_ws + k) + 0..3``.  The contacts and
        forces of every wheelset depend only on its own pose, velocities and search state (the
        search's problems are independent: Newton per (seed, problem) pair, the lowest gap per
        problem), so :meth:`contacts` of the copy evaluates ``n`` states of the vehicle, each with
        its own search state, in one vectorised call (:func:`contact_history` on a recorded run).
        Poses are passed in (:meth:`states` of this element per state); the copy shares the
        profiles, track and tables and has its own search state.  Cached per ``n``."""
        import copy

        cache = self.__dict__.setdefault("_batched", {})
        b = cache.get(n)
        if b is None:
            b = copy.copy(self)
            b.__dict__.pop("_batched", None)
            b.n_ws = n * self.n_ws
            b.wheelset_names = list(self.wheelset_names) * n
            b.bw = np.tile(self.bw, n)
            b.state = None
            cs = copy.copy(self.cs)
            cs.__dict__.pop("_rep_cache", None)
            cs.n_wheelsets = b.n_ws
            cs._problems = cs._tile(b.n_ws)
            cs._subset_cache = {}
            cs.reset()
            b.cs = cs
            b.cf = copy.copy(self.cf)  # its own per-size index cache
            if len(cache) > 4:
                cache.clear()
            cache[n] = b
        return b

    def states(self, bs):
        """Wheelset centre, rotation, velocity and global angular velocity (with the nominal
        spin, if any), in the rail frame."""
        r, A = bs.r[self.bw], bs.A[self.bw]
        v = bs.rdot[self.bw]
        w = np.einsum("nij,nj->ni", A, bs.w[self.bw])  # global angular velocity
        if self.spin is not None:
            w = w + self.spin[0] * A[:, :, 1]
        if self.rb is None:
            return r, A, v, w
        rR, AR = bs.r[self.rb], bs.A[self.rb]
        wR = AR @ bs.w[self.rb]
        d = r - rR
        return (d @ AR, np.einsum("ji,njk->nik", AR, A),
                (v - bs.rdot[self.rb] - np.cross(wR, d)) @ AR, (w - wR) @ AR)

    def _project(self, r, s_guess):
        """Track arc length of the wheelset centres: Newton from ``s_guess`` (the last accepted
        step's), or from the nearest node of the track's frame table when there is no guess or
        the iteration from the guess does not converge (e.g. a wild Newton iterate of an
        implicit integrator).  NaN for a wheelset beyond the ends of an open track (it has no
        rail there: the centreline is not extrapolated)."""
        if s_guess is not None:
            try:
                return self._on_track(self.track.project(r, s_guess))
            except NumericalFailure:
                pass
        nodes = self.track.frame_table.nodes
        pos = self.track.evaluate_raw(nodes)[0]
        guess = nodes[np.argmin(np.linalg.norm(pos[None, :, :] - r[:, None, :], axis=2), axis=1)]
        try:
            s = self.track.project(r, guess)
        except NumericalFailure:  # point by point; NaN where a wheelset is nowhere near the track
            s = np.full(r.shape[0], np.nan)
            for k in range(r.shape[0]):
                try:
                    s[k] = self.track.project(r[k:k + 1], guess[k:k + 1])[0]
                except NumericalFailure:
                    pass
        return self._on_track(s)

    def _on_track(self, s):
        """NaN where s is beyond the ends of an open track (no rail there)."""
        if not getattr(self.track, "closed", False):
            s = np.where((s >= 0.0) & (s <= self.track.length), s, np.nan)
        return s

    def off_track_message(self, k, r, s_prev):
        """Why wheelset k has no track under it: past an end of an open track (judged from its
        last accepted arc length ``s_prev``) or far off the rails."""
        L = self.track.length
        name = f"wheelset {self.wheelset_names[k]!r} ({self.name})"
        if not getattr(self.track, "closed", False) and np.isfinite(s_prev):
            if s_prev > L - END_MARGIN:
                return (f"{name} ran past the end of the track at s = {L:g} m: the track is open and is not "
                        f"extrapolated; make it longer or the run shorter")
            if s_prev < END_MARGIN:
                return (f"{name} ran off the start of the track at s = 0 m: the track is open and is not "
                        f"extrapolated")
        at = f", at {np.round(r, 3).tolist()} m" if np.all(np.isfinite(r)) else ""
        return f"{name} is no longer over the track (far off the rails{at})"

    def unspun(self, A, s):
        """Wheelset frames without the spin: [f, a, u] (module docstring)."""
        up = self.track.evaluate_raw(s)[3][:, :, 2]
        a = A[:, :, 1]
        f = np.cross(a, up)
        f /= np.linalg.norm(f, axis=1)[:, None]
        return np.stack([f, a, np.cross(f, a)], axis=2)

    def pairs(self, s):
        """The (seed, problem) pairs an evaluation iterates: both tracked points of every
        candidate that had a contact at the last accepted step (the second only where it is a
        distinct stationary point), their rail arc length moved with the wheelsets."""
        seeds = self.predicted_seeds(s)
        act = self.state.valid
        distinct = act & (np.abs(seeds[1, :, 1] - seeds[0, :, 1]) > 1e-9)
        P = act.size
        prob = np.concatenate([np.flatnonzero(act), np.flatnonzero(distinct)])
        x0 = np.concatenate([seeds[0][act], seeds[1][distinct]])
        order = np.argsort(prob, kind="stable")
        return x0[order], prob[order] if P else prob

    def accept_pairs(self, r, Ans, s, reseed, robust=None):
        """The accepted step's search: both tracked points of the candidates that had a contact
        and, when re-seeding, the best scan seeds of every candidate (``ACCEPT_RANKS`` sign
        changes of the fourth condition, and the zone's lowest sampled point), then seeds beside
        every penetrating contact and every scan seed whose Newton iteration was refused
        (:func:`neighbour_seeds`); returns (res, X, G, problem) with the Newton solution and gap
        of every pair."""
        x0, prob = self.pairs(s)
        scan_seed = np.zeros(prob.size, bool)
        if reseed:
            scan = self.cs.scan_seeds(r, Ans, s, ranks=ACCEPT_RANKS)
            extra = [(q[q[:, 4] > 0.5, :4], np.flatnonzero(q[:, 4] > 0.5), True) for q in scan]
            # the zone's lowest sampled point also where the scan saw no sign change: a minimum
            # and a maximum of the gap within one grid interval (a flat valley) change no sign
            nf = scan[0][:, 4] <= 0.5
            extra.append((scan[0][nf, :4], np.flatnonzero(nf), False))
            # a candidate where the scan found a stationary point is refined robustly as well
            # when Newton fails there (e.g. a flange touching the rail after a lift-off)
            flagged = np.any([q[:, 4] > 0.5 for q in scan], axis=0)
            robust = flagged if robust is None else (np.asarray(robust, bool) | flagged)
            x0 = np.concatenate([x0] + [a for a, _, _ in extra])
            prob = np.concatenate([prob] + [b for _, b, _ in extra])
            scan_seed = np.concatenate([scan_seed] + [np.full(b.size, f) for _, b, f in extra])
            order = np.argsort(prob, kind="stable")
            x0, prob, scan_seed = x0[order], prob[order], scan_seed[order]
        res, X, G = self.cs.solve_pairs(x0, prob, r, Ans, s, robust=robust, secondary=SEPARATION)
        refused = scan_seed & ~np.isfinite(G)
        xn, pn = neighbour_seeds(res, x0[refused], prob[refused])
        if pn.size:  # a lower minimum of the gap next to a contact (module docstring)
            x0 = np.concatenate([x0, xn])
            prob = np.concatenate([prob, pn])
            order = np.argsort(prob, kind="stable")
            x0, prob = x0[order], prob[order]
            res, X, G = self.cs.solve_pairs(x0, prob, r, Ans, s, robust=robust, secondary=SEPARATION)
        return res, X, G, prob

    def predicted_seeds(self, s):
        """The tracked points with their rail arc length moved with the wheelsets."""
        st = self.state
        seeds = st.seeds.copy()
        ws = self.cs._problems["ws"]
        seeds[:, :, 2] += (s - st.s_ws)[ws][None, :]
        return seeds

    def contacts(self, r, A, v, w, s=None):
        """(res, forces, s, Ans): contacts from the frozen state and their forces.

        A wheelset that is not over the track (no projection, or beyond the ends of an open
        track: s is NaN) has no contact; it is searched at its last accepted arc length, and its
        contacts are marked invalid (zero force).
        """
        s = self._project(r, self.state.s_ws) if s is None else s
        off = ~np.isfinite(s)
        if np.any(off):
            s = np.where(off, self.state.s_ws, s)
        Ans = self.unspun(A, s)
        x0, prob = self.pairs(s)
        res = self.cs.solve_pairs(x0, prob, r, Ans, s, secondary=SEPARATION)[0]
        lost = self.state.valid & ~res.valid.ravel()
        if np.any(lost):
            # a tracked contact whose stationary point vanished (the gap's local minimum merged
            # with a maximum): seeds from the global scan at this pose (a function of q alone)
            scan = self.cs.scan_seeds(r, Ans, s, ranks=2)
            extra = [(q[(q[:, 4] > 0.5) & lost, :4], np.flatnonzero((q[:, 4] > 0.5) & lost)) for q in scan]
            x0 = np.concatenate([x0] + [a for a, _ in extra])
            prob = np.concatenate([prob] + [b for _, b in extra])
            order = np.argsort(prob, kind="stable")
            res = self.cs.solve_pairs(x0[order], prob[order], r, Ans, s, robust=lost,
                                      secondary=SEPARATION)[0]
        res2 = res.extra["secondary"]
        if np.any(off):
            gone = np.repeat(off, 2)
            for rr in (res, res2):
                rr.valid[gone] = False
                rr.in_contact[gone] = False
                rr.gap[gone] = np.inf
                rr.penetration[gone] = -np.inf
        f = self.forces(res, r, Ans, v, w, s)
        return res, f, np.where(off, np.nan, s), Ans

    def forces(self, res, r, Ans, v, w, s=None):
        """Forces of the primary contacts and of the second patches (``f["secondary"]``), the
        latter weighted by their separation from the primary (module docstring); ``s`` (the
        wheelsets' arc lengths) is needed only with ``gravitational_stiffness=False``."""
        up = None if self.cf.gravitational_stiffness else self.track.evaluate_raw(s)[3][:, :, 2]
        res2 = res.extra.get("secondary")
        try:  # name this element in the creep forces' refusal (e.g. a rolling speed below 1e-3 m/s)
            f = self.cf(res, r, Ans, v, w, up)
            f2 = None if res2 is None else self.cf(res2, r, Ans, v, w, up)
        except InputError as exc:
            raise InputError(f"wheel-rail contact {self.e.name!r}: {exc}") from None
        if res2 is None:
            zero = {k: np.zeros_like(v_) for k, v_ in f.items()}
            f["secondary"] = zero
            return f
        # the wheel's patches: (tread, flange) primary then (tread, flange) second
        stack = lambda a1, a2: np.concatenate([a1, a2], axis=-1)
        sh = patch_shares(stack(res.y_wheel, res2.y_wheel), stack(res.gap, res2.gap), stack(f["b"], f2["b"]),
                          stack(res.valid & (f["N"] > 0), res2.valid & (f2["N"] > 0)))
        for ff, shk in ((f, sh[:, :2]), (f2, sh[:, 2:])):
            for k in ("N", "Fx", "Fy", "Mz"):
                ff[k] = ff[k] * shk
            ff["force"] = ff["force"] * shk[..., None]
            ff["moment"] = ff["moment"] * shk[..., None]
        f["secondary"] = f2
        return f

    def generalized(self, r, A_body, res, f):
        """Force and moment sums of every wheelset's contacts (primary and secondary patches),
        rail-frame components: Ft, Mt (n_ws, 3) and the contacts' points, forces, moments
        (n_ws, 8, 3)."""
        ps, Fs, Ms = [], [], []
        for rr, ff in ((res, f), (res.extra["secondary"], f["secondary"])):
            valid = rr.valid[..., None]
            ps.append(np.where(valid, rr.point_wheel, 0.0).reshape(self.n_ws, 4, 3))
            Fs.append(ff["force"].reshape(self.n_ws, 4, 3))
            Ms.append(ff["moment"].reshape(self.n_ws, 4, 3))
        p, F, M = (np.concatenate(a, axis=1) for a in (ps, Fs, Ms))
        arm = np.where(np.any(p != 0.0, axis=2, keepdims=True), p - r[:, None, :], 0.0)
        Ft = F.sum(axis=1)
        Mt = (np.cross(arm, F) + M).sum(axis=1)
        return Ft, Mt, p, F, M

    def rhs(self, bs, s=None):
        """Generalized forces: list of (bodies, Qb) blocks."""
        r, A, v, w = self.states(bs)
        res, f, _, _ = self.contacts(r, A, v, w, s)
        Ft, Mt, p, F, M = self.generalized(r, A, res, f)
        if self.spin is not None and self.e.gyroscopic:  # gyroscopic moment of the nominal spin, -I Omega (omega x a)
            Om, Iy = self.spin
            a = A[:, :, 1]
            w_body = w - Om * a
            Mt = Mt - Iy * Om * np.cross(w_body, a)
        if self.rb is None:
            Qw = np.concatenate([Ft, np.einsum("nji,nj->ni", A, Mt)], axis=1)
            return self.bw, Qw
        AR, rR = bs.A[self.rb], bs.r[self.rb]
        Ag = bs.A[self.bw]  # actual body rotations (global)
        Ftg, Mtg = Ft @ AR.T, Mt @ AR.T
        Qw = np.concatenate([Ftg, np.einsum("nji,nj->ni", Ag, Mtg)], axis=1)
        # reaction on the rail body: -F at the contact points, -M
        pg = p @ AR.T + rR  # (n_ws, 4, 3) global contact points (zero-force where invalid)
        Fg = F @ AR.T
        Mg = M @ AR.T
        FR = -Fg.sum(axis=(0, 1))
        MR = -(np.cross(pg - rR, Fg) + Mg).sum(axis=(0, 1))
        QR = np.concatenate([FR, AR.T @ MR])[None, :]
        return np.concatenate([self.bw, [self.rb]]), np.concatenate([Qw, QR])


class WheelRailKind(ForceKind):
    """All :class:`WheelRailContact` elements of a model (module docstring)."""

    stateful = True
    conservative = False

    def __init__(self, elements, ctx):
        self.names = [e.name for e in elements]
        self.sets = [_Set(e, ctx) for e in elements]
        self._n_v = ctx.space.n_v

    # --- forces ----------------------------------------------------------------------------
    def _require_state(self, bs, t):
        for st in self.sets:
            if st.state is None:  # evaluated outside a run (analyses): start from this pose
                st.state = self._fresh_state(st, bs)

    def evaluate(self, bs, t):
        self._require_state(bs, t)
        blocks = [st.rhs(bs) for st in self.sets]
        return ForceEval(np.concatenate([b for b, _ in blocks]), np.concatenate([q for _, q in blocks]))

    def jacobian(self, bs, t):
        """Central differences with the frozen search state (module docstring)."""
        self._require_state(bs, t)
        blocks: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
        for st in self.sets:
            # all wheelsets at once when the rails are the ground (no coupling between them)
            groups = ([st.bw] if st.rb is None
                      else [np.array([b]) for b in list(st.bw) + [st.rb]])
            for g in groups:
                for k in range(6):
                    (bq, Qp), (_, Qm) = (st.rhs(_perturbed_pose(bs, g, k, h)) for h in (FD_POSE, -FD_POSE))
                    (_, Vp), (_, Vm) = (st.rhs(_perturbed_velocity(bs, g, k, h))
                                        for h in (FD_VELOCITY, -FD_VELOCITY))
                    dq = (Qp - Qm) / (2.0 * FD_POSE)
                    dv = (Vp - Vm) / (2.0 * FD_VELOCITY)
                    for m, body in enumerate(bq):
                        if st.rb is None:
                            col = int(body)  # block diagonal
                        else:
                            col = int(g[0])
                        Kq, Kv = blocks.setdefault((int(body), col), (np.zeros((6, 6)), np.zeros((6, 6))))
                        Kq[:, k] += dq[m]
                        Kv[:, k] += dv[m]
        keys = list(blocks)
        return ForceJacobian(np.array([a for a, _ in keys], np.int64), np.array([b for _, b in keys], np.int64),
                             np.array([blocks[key][0] for key in keys]), np.array([blocks[key][1] for key in keys]))

    # --- search state ----------------------------------------------------------------------
    def _fresh_state(self, st, bs):
        r, A, v, w = st.states(bs)
        s = st._project(r, None)
        if not np.all(np.isfinite(s)):
            k = int(np.argmax(~np.isfinite(s)))
            raise ModelError(f"wheel-rail contact {st.name!r}: wheelset {st.wheelset_names[k]!r} at "
                             f"{r[k].round(3).tolist()} m is not over the track")
        Ans = st.unspun(A, s)
        scan = st.cs.scan_seeds(r, Ans, s, ranks=4)
        res, X, G, xb = st.cs.solve([q[:, :4] for q in scan], r, Ans, s, scan_out=scan)
        state = _State(seeds=_two_lowest(xb, X, G), s_ws=s, valid=res.valid.ravel().copy(),
                       accepted=0, last_YQ=np.full(2 * st.n_ws, np.nan))
        # the accepted-step search from these points: the neighbours of every contact are
        # probed there, as after every accepted step of a run
        st.state = state
        res, X, G, prob = st.accept_pairs(r, Ans, s, True, robust=state.valid)
        xb = np.column_stack([res.theta.ravel(), res.y_wheel.ravel(), res.s_rail.ravel(), res.u_rail.ravel()])
        state.seeds = _two_lowest_pairs(xb, res.valid.ravel(), X, G, prob, state.seeds)
        state.valid = res.valid.ravel().copy()
        return state

    def reset_state(self, bs, t):
        for st in self.sets:
            st.state = self._fresh_state(st, bs)

    def accept_step(self, bs, t, reseed=False, check=True):
        """Search-state update after an accepted step (module docstring); ``reseed=True`` scans
        whatever ``reseed_every`` says and ``check=False`` skips the derailment checks (the replay
        of :func:`contact_history`, which also replays the last state of a derailed run)."""
        for st in self.sets:
            state = st.state
            if state is None:
                st.state = self._fresh_state(st, bs)
                continue
            r, A, v, w = st.states(bs)
            s = st._project(r, state.s_ws)
            if not np.all(np.isfinite(s)):
                k = int(np.argmax(~np.isfinite(s)))
                msg = st.off_track_message(k, r[k], state.s_ws[k])
                raise (DataRangeError if "of the track at" in msg else NumericalFailure)(msg)
            Ans = st.unspun(A, s)
            reseed = reseed or (state.accepted + 1) % st.e.reseed_every == 0
            res, X, G, prob = st.accept_pairs(r, Ans, s, reseed, robust=state.valid if reseed else None)
            if not reseed and np.any(state.valid & ~res.valid.ravel()):  # a tracked contact was lost
                res, X, G, prob = st.accept_pairs(r, Ans, s, True, robust=state.valid)
            f = st.forces(res, r, Ans, v, w, s)
            out = _wheel_quantities(st, res, f, r, Ans, s, w)
            if check:
                _check_derailment(st, res, out, state.last_YQ)
            xb = np.column_stack([res.theta.ravel(), res.y_wheel.ravel(), res.s_rail.ravel(), res.u_rail.ravel()])
            st.state = _State(seeds=_two_lowest_pairs(xb, res.valid.ravel(), X, G, prob, state.seeds),
                              s_ws=s, valid=res.valid.ravel().copy(), accepted=state.accepted + 1,
                              last_YQ=out["wheels"]["Y/Q [-]"].copy())

    # --- outputs ---------------------------------------------------------------------------
    def outputs(self, bs, t):
        """Per element: the largest Y/Q and the smallest wheel load of its wheels."""
        self._require_state(bs, t)
        yq, qmin = [], []
        for st in self.sets:
            out = self.contact_outputs(bs, t, st.name)
            yq.append(np.nanmax(out["wheels"]["Y/Q [-]"], initial=-np.inf))
            qmin.append(np.min(out["wheels"]["Q [N]"]))
        return {"max Y/Q [-]": np.array(yq), "min Q [N]": np.array(qmin)}

    def contact_outputs(self, bs, t, element=None):
        """What a railway engineer reads per wheel and per contact at (t, q, v).

        Returns
        -------
        dict
            ``"wheels"``: dict of arrays (n_wheels,) (see :func:`_wheel_quantities`);
            ``"contacts"``: dict of arrays (n_wheels, 2) per candidate (tread, flange);
            ``"wheelsets"``: dict of arrays (n_ws,).
        """
        self._require_state(bs, t)
        st = self._set(element)
        r, A, v, w = st.states(bs)
        res, f, s, Ans = st.contacts(r, A, v, w)
        return _wheel_quantities(st, res, f, r, Ans, s, w)

    # --- compiled path -----------------------------------------------------------------------
    #: ``(kind, layout) -> CompiledForces``: registered by :mod:`railway.vehicles.wheel_rail_compiled`
    #: when it is imported (the package :mod:`railway.vehicles` imports it), so that this numpy
    #: element never imports its compiled kernels (issue 22: no import circle)
    compiled_form = None
    #: ``(set, row) -> search state``: a compiled state row as the numpy search state (registered
    #: with :attr:`compiled_form`; used by :func:`contact_history` on recorded runs)
    state_from_compiled = None

    def compiled(self, layout):
        """Kernels for core's compiled integrators (:mod:`railway.vehicles.wheel_rail_compiled`)."""
        if WheelRailKind.compiled_form is None:
            raise NotCompilable(f"force element {self.names[0]!r} (WheelRailKind): its compiled kernels "
                                "(railway.vehicles.wheel_rail_compiled) were not imported")
        return WheelRailKind.compiled_form(self, layout)

    def _set(self, element):
        if element is None:
            return self.sets[0]
        for st in self.sets:
            if st.name == element:
                return st
        raise ModelError(f"no wheel-rail contact element {element!r}; there are {self.names}")


# ------------------------------------------------------------------------------------------
def patch_shares(y, g, b, loaded):
    """Shares of every patch of a wheel (module docstring, "The patch set of a wheel").

    Parameters: arrays (..., m) over the m patches of each wheel (tread and flange candidates'
    primary and second patches, in that order): wheel profile coordinate y (m), gap g (m), lateral
    semi-axis b (m), ``loaded`` (valid and penetrating).  A patch at the point of an earlier loaded
    patch (``|Δy|`` < ``DUPLICATE``: the same stationary point found from both zones) has share 0;
    every other loaded patch i gets s_i = Π_j [w_ij + (1 − w_ij) σ(g_j − g_i)] over the other
    loaded, distinct patches j.  Returns the shares (..., m) (1 where not loaded).
    """
    y, g, b = (np.asarray(a, float) for a in (y, g, b))
    loaded = np.asarray(loaded, bool) & np.isfinite(y) & np.isfinite(g)
    m = y.shape[-1]
    dup = np.zeros_like(loaded)
    for i in range(1, m):
        for j in range(i):
            dup[..., i] |= loaded[..., j] & ~dup[..., j] & (np.abs(y[..., i] - y[..., j]) < DUPLICATE)
    live = loaded & ~dup
    share = np.where(dup, 0.0, 1.0)
    with np.errstate(invalid="ignore", over="ignore"):
        for i in range(m):
            for j in range(m):
                if i == j or i % 2 != j % 2:  # patches of the same zone share
                    continue
                both = live[..., i] & live[..., j]
                bsum = b[..., i] + b[..., j]
                w = np.clip((np.abs(y[..., j] - y[..., i]) - bsum) / (0.5 * np.where(bsum > 0, bsum, 1.0)), 0.0, 1.0)
                sig = 0.5 * (1.0 + np.tanh((g[..., j] - g[..., i]) / BLEND_GAP))
                share[..., i] *= np.where(both, w + (1.0 - w) * sig, 1.0)
    return share


def neighbour_seeds(res, x_refused=None, p_refused=None):
    """Seeds ``NEIGHBOUR_OFFSETS`` beside every penetrating contact on the wheel profile (the rail
    coordinate moved alike) and beside every scan seed ``x_refused`` (problems ``p_refused``) whose
    Newton iteration was refused: (x0 (K, 4), problem (K,)).  A flat valley of the gap (the flange
    flank over the gauge corner, the S1002 tread near 6 mm) can hold two minima and a maximum
    within a fraction of a millimetre to a few millimetres, closer than the scan's grid resolves:
    Newton from a scan seed may end on the maximum (refused, B < 0), and from a tracked minimum
    stays there; Newton from both sides finds the other minimum whichever the search held."""
    valid = res.valid.ravel()
    xb = np.column_stack([res.theta.ravel(), res.y_wheel.ravel(), res.s_rail.ravel(), res.u_rail.ravel()])
    idx = np.flatnonzero(valid & (res.gap.ravel() < 0.0))
    centre, prob = xb[idx], idx
    if x_refused is not None and len(p_refused):
        centre = np.concatenate([centre, x_refused])
        prob = np.concatenate([prob, p_refused])
    if not prob.size:
        return np.zeros((0, 4)), np.zeros(0, np.int64)
    xs, ps = [], []
    for d in NEIGHBOUR_OFFSETS:
        xn = centre.copy()
        xn[:, 1] += d
        xn[:, 3] += d
        xs.append(xn)
        ps.append(prob)
    return np.concatenate(xs), np.concatenate(ps).astype(np.int64)


def _two_lowest_pairs(xb, valid, X, G, prob, old, distinct=1e-4):
    """Tracked points (2, P, 4) after an accepted step: per candidate the solution ``xb`` and the
    lowest other pair solution at least ``distinct`` (m) away in the wheel profile coordinate
    (else ``xb`` again); candidates without a contact keep their old tracked points."""
    P = xb.shape[0]
    first = np.where(valid[:, None], xb, old[0])
    second = first.copy()
    far = np.abs(X[:, 1] - xb[prob, 1]) > distinct
    # not the other zone's contact of the same wheel (the zones overlap at the split): the next
    # stationary point is tracked instead, as a fresh search tracks it
    other = prob ^ 1
    far &= ~(valid[other] & (np.abs(X[:, 1] - xb[other, 1]) < DUPLICATE))
    g = np.where(far & np.isfinite(G), G, np.inf)
    if g.size:
        order = np.lexsort((np.arange(g.size), g, prob))
        firstk = order[np.r_[True, prob[order][1:] != prob[order][:-1]]]
        ok = np.isfinite(g[firstk]) & valid[prob[firstk]]
        second[prob[firstk][ok]] = X[firstk][ok]
    return np.stack([first, second])


def _two_lowest(xb, X, G, distinct=1e-4):
    """Tracked points (2, P, 4): the best solution and the lowest other stationary point at
    least ``distinct`` (m) away in the wheel profile coordinate (else the best again)."""
    m, P, _ = X.shape
    second = xb.copy()
    far = np.abs(X[:, :, 1] - xb[None, :, 1]) > distinct
    Gf = np.where(far & np.isfinite(G), G, np.inf)
    j = np.argmin(Gf, axis=0)
    has = np.isfinite(Gf[j, np.arange(P)])
    second[has] = X[j[has], np.arange(P)[has]]
    first = np.where(np.all(np.isfinite(xb), axis=1)[:, None], xb, X[0])
    return np.stack([first, second])


def _perturbed_pose(bs, bodies, k, h):
    """Body states with the pose of ``bodies`` moved by h along velocity-space direction k
    (translation k < 3 global; rotation k >= 3 about body axis k - 3), velocities unchanged."""
    from core.bodies import BodyStates

    r, A = bs.r.copy(), bs.A.copy()
    if k < 3:
        r[bodies, k] += h
    else:
        e = np.zeros(3)
        e[k - 3] = h
        A[bodies] = A[bodies] @ frames.euler_to_matrix(frames.rotation_vector_to_euler(e))
    return BodyStates(bs.space, r, A, bs.rdot, bs.w, bs.x, bs.xdot)


def _perturbed_velocity(bs, bodies, k, h):
    from core.bodies import BodyStates

    rd, w = bs.rdot.copy(), bs.w.copy()
    if k < 3:
        rd[bodies, k] += h
    else:
        w[bodies, k - 3] += h
    return BodyStates(bs.space, bs.r, bs.A, rd, w, bs.x, bs.xdot)


def _wheel_quantities(st, res, f, r, Ans, s, w):
    """Per-wheel Q, Y, Y/Q and friends from contacts and forces (rail-frame quantities).

    Conventions: Q is the vertical force of the wheel on the rail (track up axis, positive
    downwards on the rail); Y the lateral force of the wheel on the rail, positive towards the
    field side of that rail (outwards), so that Y/Q > 0 on a flange-climbing wheel; the
    wheelset's ΣY is the lateral force of the axle on the track in the track's lateral axis
    (positive to the left).
    """
    from ..assessment import max_pressure, nadal_limit, wear_number

    n_ws = st.n_ws
    fr = st.track.evaluate_raw(s)
    pos, R = fr[0], fr[3]
    t_tr, lat, up = R[:, :, 0], R[:, :, 1], R[:, :, 2]
    f2 = f["secondary"]
    Fw = (f["force"] + f2["force"]).reshape(n_ws, 2, 2, 3)  # on the wheel, both patches
    side = np.array([1.0, -1.0])
    Fsum = Fw.sum(axis=2)  # per wheel
    Q = np.einsum("nsk,nk->ns", Fsum, up)
    Ylat = -np.einsum("nsk,nk->ns", Fsum, lat)  # wheel on rail, track lateral (left +)
    Y = Ylat * side[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        YQ = np.where(Q > 0, Y / Q, np.nan)
    N = f["N"].reshape(n_ws, 2, 2)
    N2 = f2["N"].reshape(n_ws, 2, 2)
    res2 = res.extra["secondary"]
    loaded = N > 0
    gam = np.where(res.valid, res.contact_angle, np.nan).reshape(n_ws, 2, 2)
    gam2 = np.where(res2.valid & (N2.reshape(-1, 2) > 0), res2.contact_angle, -np.inf).reshape(n_ws, 2, 2)
    # the flange contact of a wheel: the loaded candidate with the larger contact angle
    gmax = np.maximum(np.where(loaded, gam, -np.inf).max(axis=2), gam2.max(axis=2))
    flange = (loaded.any(axis=2) | (N2 > 0).any(axis=2)) & (gmax > np.radians(45.0))
    lim = np.where(flange, nadal_limit(np.where(np.isfinite(gmax), gmax, 0.0), st.e.mu), np.nan)
    a, b = f["a"].reshape(n_ws, 2, 2), f["b"].reshape(n_ws, 2, 2)
    a2, b2 = f2["a"].reshape(n_ws, 2, 2), f2["b"].reshape(n_ws, 2, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        pmax = np.where(loaded, max_pressure(N, a, b), 0.0)
        pmax2 = np.where(N2 > 0, max_pressure(N2, a2, b2), 0.0)
    Tg = (wear_number(f["Fx"], f["Fy"], f["xi"], f["eta"])
          + wear_number(f2["Fx"], f2["Fy"], f2["xi"], f2["eta"])).reshape(n_ws, 2, 2)
    d = r - pos
    y_ws = np.einsum("nk,nk->n", d, lat)
    z_ws = np.einsum("nk,nk->n", d, up)
    fwd = Ans[:, :, 0]
    yaw = np.arctan2(np.einsum("nk,nk->n", fwd, lat), np.einsum("nk,nk->n", fwd, t_tr))
    spin = np.einsum("nk,nk->n", w, Ans[:, :, 1])
    out = {
        "Q [N]": Q.ravel(), "Y [N]": Y.ravel(), "Y/Q [-]": YQ.ravel(),
        "flange contact": flange.ravel(),
        "flange force [N]": np.where(flange, np.maximum(N.max(axis=2), N2.max(axis=2)), 0.0).ravel(),
        "second patch N [N]": N2.sum(axis=2).ravel(),
        "Nadal limit [-]": lim.ravel(), "contact angle [rad]": np.where(np.isfinite(gmax), gmax, np.nan).ravel(),
        "p_max [Pa]": np.maximum(pmax, pmax2).max(axis=2).ravel(), "T gamma [N]": Tg.sum(axis=2).ravel(),
        "y_wheel [m]": res.y_wheel.reshape(n_ws, 2, 2)[..., 0].ravel(),
        "flange climb [m]": _flange_climb(st, res).ravel(),
    }
    contacts = {
        "N [N]": N, "Fx [N]": f["Fx"].reshape(n_ws, 2, 2), "Fy [N]": f["Fy"].reshape(n_ws, 2, 2),
        "Mz [N m]": f["Mz"].reshape(n_ws, 2, 2), "xi [-]": f["xi"].reshape(n_ws, 2, 2),
        "eta [-]": f["eta"].reshape(n_ws, 2, 2), "phi [1/m]": f["phi"].reshape(n_ws, 2, 2),
        "a [m]": a, "b [m]": b, "p_max [Pa]": pmax, "T gamma [N]": Tg, "contact angle [rad]": gam,
        "penetration [m]": np.where(res.valid, res.penetration, np.nan).reshape(n_ws, 2, 2),
        "y_wheel [m]": res.y_wheel.reshape(n_ws, 2, 2), "u_rail [m]": res.u_rail.reshape(n_ws, 2, 2),
        "rolling radius [m]": res.rolling_radius.reshape(n_ws, 2, 2),
    }
    wheelsets = {
        "s [m]": s, "lateral displacement [m]": y_ws, "height [m]": z_ws, "angle of attack [rad]": yaw,
        "spin [rad/s]": spin, "sum Y [N]": Ylat.sum(axis=1),
    }
    return {"wheels": out, "contacts": {k: v.reshape(2 * n_ws, 2) for k, v in contacts.items()},
            "wheelsets": wheelsets}


def _flange_climb(st, res):
    """Height (m, radius increase) of each wheel's highest penetrating contact above the top of the
    flank (:attr:`railway.contact.profiles.WheelProfile.y_flank_top`); 0 for a wheel whose penetrating
    contacts are all on the flank, its root or the tread."""
    res2 = res.extra["secondary"]
    with np.errstate(invalid="ignore"):
        y = np.concatenate([np.where(res.valid & (res.penetration > 0), res.y_wheel, np.nan),
                            np.where(res2.valid & (res2.penetration > 0), res2.y_wheel, np.nan)], axis=1)
    y_top = st.wheel.y_flank_top
    y_min = np.where(np.isnan(y), np.inf, y).min(axis=1)
    climbed = y_min < y_top
    F_top = st.wheel.evaluate(np.array([y_top]))[0][0]
    h = np.zeros(y.shape[0])
    if np.any(climbed):
        h[climbed] = st.wheel.evaluate(y_min[climbed])[0] - F_top
    return h.reshape(st.n_ws, 2)


def _check_derailment(st, res, out, last_YQ):
    """NumericalFailure naming the wheel when a wheel left its rail (module docstring)."""
    e = st.e
    labels = [f"{ws} {side}" for ws in st.wheelset_names for side in ("left", "right")]
    wh, wss = out["wheels"], out["wheelsets"]
    yq = wh["Y/Q [-]"]

    def last(i):
        v = last_YQ[i] if last_YQ.size else np.nan
        return f"last Y/Q {v:.3g} at the previous accepted step, {yq[i]:.3g} now"

    climb = wh["flange climb [m]"]
    if np.any(climb > st.climb_height):
        i = int(np.argmax(climb))
        raise NumericalFailure(climb_message(labels[i], e.name, climb[i], st.wheel, e.flange_climb_height,
                                             last(i)))
    y = wss["lateral displacement [m]"]
    drop = st.wheel.r0 - wss["height [m]"]
    bad = (np.abs(y) > e.max_lateral_displacement) | (drop > e.max_drop)
    if np.any(bad):
        k = int(np.argmax(bad))
        i = 2 * k + (0 if y[k] > 0 else 1)  # the wheel on the side it moved to
        raise NumericalFailure(
            f"derailment of wheelset {st.wheelset_names[k]!r} ({e.name}): it left the rails "
            f"(lateral displacement {y[k] * 1e3:.1f} mm, limit {e.max_lateral_displacement * 1e3:g} mm; "
            f"centre {drop[k] * 1e3:.1f} mm below its nominal height, limit {e.max_drop * 1e3:g} mm); "
            f"wheel {labels[i]!r}: {last(i)}")


def _hermite_state(model, q_a, v_a, q_b, v_b, h, s_, axle_bodies=()):
    r"""The state at the fraction ``s_`` of an interval of ``h`` seconds between two stored states,
    for moving the search seeds between rows far apart (:func:`contact_history`).

    Coordinates: the cubic Hermite through q̇ = Z(q) v at both ends (Euler parameters then
    normalised); velocities: linear.  The axles of the wheelsets ``axle_bodies`` (body indices) are
    then turned, each by the smallest rotation, onto the cubic Hermite of the axle direction a
    itself through ȧ = ω × a at both ends (ω in global axes; a normalised).  The contact geometry
    of a body of revolution depends on its centre and its axle, not on the spin angle, and the
    axle turns slowly (yaw with the curve, roll) while the wheelset spins 2.2 rad between rows
    50 ms apart at 20 m/s: the Hermite of the Euler parameters follows that spin only to (ω h)⁴
    and tilts the axle by up to 7e-5 rad there (measured against the accepted steps), the axle's
    own Hermite to 1e-10 rad.  A tilt of 2e-5 rad was enough for the scan to find a flange-root
    patch that the run never had (issue 21).
    """
    from core import frames

    q_a, v_a, q_b, v_b = (np.asarray(x, float) for x in (q_a, v_a, q_b, v_b))
    h00, h10, h01, h11 = 2 * s_**3 - 3 * s_**2 + 1, s_**3 - 2 * s_**2 + s_, -2 * s_**3 + 3 * s_**2, s_**3 - s_**2
    q = model.normalize(h00 * q_a + h10 * h * model.qdot(q_a, v_a) + h01 * q_b + h11 * h * model.qdot(q_b, v_b))
    v = (1.0 - s_) * v_a + s_ * v_b
    k = np.asarray(axle_bodies, dtype=np.int64)
    if model.space.dim == 2 or k.size == 0:
        return q, v

    def axle(qq, vv):  # axle direction a = A e_y and its rate omega x a (global axes)
        A = frames.euler_to_matrix(qq.reshape(-1, 7)[k, 3:])
        w = np.einsum("nij,nj->ni", A, vv.reshape(-1, 6)[k, 3:])
        return A[:, :, 1], np.cross(w, A[:, :, 1])

    nb = model.n_bodies
    (a_a, da_a), (a_b, da_b) = axle(q_a[: nb * 7], v_a[: nb * 6]), axle(q_b[: nb * 7], v_b[: nb * 6])
    a = h00 * a_a + h10 * h * da_a + h01 * a_b + h11 * h * da_b
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    qb_ = q[: nb * 7].reshape(nb, 7)
    a_h = frames.euler_to_matrix(qb_[k, 3:])[:, :, 1]
    c = np.cross(a_h, a)
    sn = np.linalg.norm(c, axis=1)
    ang = np.arctan2(sn, np.einsum("ni,ni->n", a_h, a))
    rv = np.where((sn > 0.0)[:, None], c * (ang / np.where(sn > 0.0, sn, 1.0))[:, None], 0.0)
    qb_[k, 3:] = frames.quat_multiply(frames.rotation_vector_to_euler(rv), qb_[k, 3:])
    return q, v


#: peaks refined by :func:`contact_history` at the accepted steps: (column, kind), kind "max",
#: "min" or "absmax" (largest magnitude)
#: rows of a recorded run that :func:`contact_history` evaluates in one vectorised call
#: (:meth:`_Set.batched`); a few hundred take the numpy overhead per call out of the rows
ROW_BATCH = 256

PEAK_COLUMNS = (("Q [N]", "max"), ("Q [N]", "min"), ("Y [N]", "absmax"), ("Y/Q [-]", "max"),
                ("flange force [N]", "max"))


@checked_options
def contact_history(model, result, element=None, wheels=None, max_step=2e-3, at="outputs", locate_lift=None,
                    lift_tol=1e-7, peak_samples=8, seed_path="auto"):
    """Per output time (or accepted step) and wheel, what a railway engineer reads (long format).

    The outputs of :meth:`WheelRailKind.contact_outputs` are evaluated at the stored states of
    ``result``, with the search state tracked along the run as the integrator tracks it
    (``seed_path``):

    * ``"steps"`` (the default, ``"auto"``, when ``result.steps`` holds the accepted steps of a run
      made with ``simulate(..., record_steps=True)``): reset at the first step, then carried
      through the accept hook at every accepted step up to each output time, on the run's own
      re-seeding schedule -- the search state the run had.  Each row is evaluated at its stored
      state with the state of the last accepted step at or before it, which is the state the run
      used for its forces there: the rows equal those of ``at="steps"`` where the times agree, and
      do not depend on the output step.  A compiled run records that state at every accepted step
      (:func:`core.results.search_states_at_steps`); the rows are then independent and are
      evaluated :data:`ROW_BATCH` at a time, the wheelsets of all of them side by side in one
      vectorised call (:meth:`_Set.batched`; the same numbers as one row at a time to round-off -- the
      track projection's Newton iterates every wheelset until the last one converged -- at a
      fifth of the time).
    * ``"hermite"`` (the default without recorded steps): reset at the first row, then carried from
      row to row through the accept hook at intermediate states at most ``max_step`` apart -- the
      positions interpolated by the cubic Hermite through q̇ = Z(q) v at both rows, the wheelsets'
      axle directions by their own Hermite (:func:`_hermite_state`), the velocities linearly --
      and at the row's stored state, at which the row is evaluated.  The intermediate states only
      move the seeds.  Positions interpolated linearly (chords) cut the arc of a curve: between
      rows 50 ms apart at 20 m/s in a 200 m curve a wheelset sat up to 0.53 mm inside the track
      with its axle 1.5 mrad off, and the scan found there a flange-root patch that the run never
      had (13.9 kN on a wheel load; issue 21, tests/railway/test_replay_seeds.py).  The Hermite
      follows that motion to 1e-9 m and 1e-10 rad; it cannot follow motion faster than the rows
      (e.g. a wheelset's bouncing on its Hertz springs), so the steps are preferred where
      recorded.

    A run re-seeds after every accepted step (~1 ms); replaying the tracked state only at the
    output times (50 ms, a metre of track at 20 m/s, apart) would lose patches that the run had,
    and a fresh global search at every row would pick the patches afresh where two of them share a
    zone -- either would misstate the forces the run applied.

    ``at="steps"`` evaluates at every accepted step of a run made with
    ``simulate(..., record_steps=True)`` (``result.steps``) instead of the output times: the
    replay then re-seeds where the run did, and the peaks, lifts and durations read from the
    table do not depend on the output step (:func:`railway.assessment.wheel_event_statistics`).
    With ``locate_lift`` (default: on for ``at="steps"``) every change of a wheel between loaded
    (Q > 0) and lifted (Q = 0) between two rows is located by bisection to ``lift_tol`` seconds on
    the condition Q > 0 evaluated at states interpolated within the step (cubic Hermite in the
    positions through q̇ = Z(q) v, linear in the velocities; the search state of the later row):
    event location of Q = 0.  The located times are in ``df.attrs["lift crossings"]``: per wheel
    a dict from the time of the row after the change to the located time.  With ``at="steps"``
    the peaks of :data:`PEAK_COLUMNS` are refined too: around every sample that is a local
    extreme and could, by the change to its neighbours, exceed the extreme found so far (by a
    quarter of the larger change: a smooth peak exceeds its best sample by at most an eighth),
    the two adjacent steps are sampled at ``peak_samples`` interpolated states each (the error of
    a sampled peak falls with the square of the sample spacing); ``df.attrs["peaks"]`` holds per
    wheel and column ``(kind, value, time)``.

    Returns
    -------
    DataFrame
        One row per output time and wheel: ``t [s]``, ``wheel``, ``wheelset``, ``side``, the
        wheel quantities (``Q [N]``, ``Y [N]``, ``Y/Q [-]``, ``flange contact``, ``flange force
        [N]``, ``Nadal limit [-]``, ``contact angle [rad]``, ``p_max [Pa]``, ``T gamma [N]``,
        ``y_wheel [m]``), per-candidate creepages and creep forces of the tread (``_tread``) and
        flange (``_flange``) candidates, and the wheelset quantities (``s [m]``, ``lateral
        displacement [m]``, ``angle of attack [rad]``, ``spin [rad/s]``, ``sum Y [N]``, ``speed
        [m/s]``).  ``attrs["at"]`` says which times the rows are.

    Raises
    ------
    core.errors.InputError
        ``at="steps"`` or ``seed_path="steps"`` for a result without recorded steps, or an unknown
        ``at`` or ``seed_path``.
    """
    import pandas as pd

    from core.errors import InputError

    steps = getattr(result, "steps", None)
    if seed_path not in ("auto", "steps", "hermite"):
        raise InputError(f"contact_history: seed_path must be 'auto', 'steps' or 'hermite', got {seed_path!r}")
    if at == "outputs":
        T, Qs, Vs = result.t, result.q, result.v
        if seed_path == "auto":
            seed_path = "hermite" if steps is None else "steps"
        if seed_path == "steps" and steps is None:
            raise InputError("contact_history(seed_path='steps'): the result holds no accepted steps; run "
                             "simulate(..., record_steps=True)")
    elif at == "steps":
        if steps is None:
            raise InputError("contact_history(at='steps'): the result holds no accepted steps; run simulate(..., "
                             "record_steps=True)")
        T, Qs, Vs = steps
        seed_path = "steps"
    else:
        raise InputError(f"contact_history: at must be 'outputs' or 'steps', got {at!r}")
    T = np.asarray(T, float)
    if locate_lift is None:
        locate_lift = at == "steps"
    kind = next(k for k in model.force_kinds if isinstance(k, WheelRailKind))
    st = kind._set(element)
    saved = st.state
    rows = []
    labels = [f"{ws} {sd}" for ws in st.wheelset_names for sd in ("left", "right")]
    crossings: dict[str, dict[float, float]] = {lab: {} for lab in labels}

    nw = 2 * st.n_ws

    def evaluate(qs, vs, states):
        """Outputs at the states (qs[b], vs[b]), each with the search state states[b], in one
        vectorised call (:meth:`_Set.batched`): wheels (B nw,), contacts (B nw, 2), wheelsets
        (B n_ws,), row-major."""
        poses = [st.states(model.body_states(np.asarray(q, float), np.asarray(v, float))) for q, v in zip(qs, vs)]
        r, A, v, w = (np.concatenate([p_[j] for p_ in poses]) for j in range(4))
        stb = st.batched(len(qs))
        stb.state = _State(seeds=np.concatenate([s_.seeds for s_ in states], axis=1),
                           s_ws=np.concatenate([s_.s_ws for s_ in states]),
                           valid=np.concatenate([s_.valid for s_ in states]))
        res, f, s, Ans = stb.contacts(r, A, v, w)
        out = _wheel_quantities(stb, res, f, r, Ans, s, w)
        out["wheelsets"]["speed [m/s]"] = np.einsum(
            "nk,nk->n", v, st.track.evaluate_raw(np.nan_to_num(s))[3][:, :, 0])
        return out

    def table_rows(ts, out):  # the rows of the long table at the times ts, from evaluate()
        B = len(ts)
        row = {"t [s]": np.repeat(np.asarray(ts, float), nw), "wheel": labels * B,
               "wheelset": np.tile(np.repeat(st.wheelset_names, 2), B), "side": ["left", "right"] * (st.n_ws * B)}
        row.update({k: np.asarray(v_) for k, v_ in out["wheels"].items()})
        for k in ("N [N]", "Fx [N]", "Fy [N]", "xi [-]", "eta [-]", "phi [1/m]"):
            for c, lab in enumerate(("tread", "flange")):
                row[f"{k.split(' ')[0]}_{lab} {k.split(' ')[1]}"] = out["contacts"][k][:, c]
        for k, v_ in out["wheelsets"].items():
            row[k] = np.repeat(np.asarray(v_), 2)
        return row

    def interpolated(k, taus):  # states interpolated in the step (T[k - 1], T[k]) at the times taus
        t_a, t_b = float(T[k - 1]), float(T[k])
        q_a, v_a, q_b, v_b = (np.asarray(x, float) for x in (Qs[k - 1], Vs[k - 1], Qs[k], Vs[k]))
        h = t_b - t_a
        qd_a, qd_b = model.qdot(q_a, v_a), model.qdot(q_b, v_b)
        qs, vs = [], []
        for tau in taus:
            s_ = (tau - t_a) / h
            h00, h10, h01, h11 = 2 * s_**3 - 3 * s_**2 + 1, s_**3 - 2 * s_**2 + s_, -2 * s_**3 + 3 * s_**2, s_**3 - s_**2
            qs.append(model.normalize(h00 * q_a + h10 * h * qd_a + h01 * q_b + h11 * h * qd_b))
            vs.append((1.0 - s_) * v_a + s_ * v_b)
        return qs, vs

    recorded = None  # the search states the compiled run had after every accepted step
    if seed_path == "steps":
        S_t, S_q, S_v = (np.asarray(x, float) for x in steps)
        from core.results import search_states_at_steps

        recorded = search_states_at_steps(result, kind.names)
        if recorded is not None and (WheelRailKind.state_from_compiled is None or len(recorded) != S_t.size):
            recorded = None
        e_row = kind.sets.index(st)
    else:
        axle_bodies = np.unique(np.concatenate([np.asarray(s_.bw, dtype=np.int64).ravel() for s_ in kind.sets]))
    n_done = 0  # accepted steps replayed (seed_path "steps")

    def carry(i, t, bs):  # carry the element's search state to row i (seed_path, docstring above)
        nonlocal n_done
        if seed_path == "steps":
            if i == 0:  # the run's start: its first recorded state
                kind.reset_state(model.body_states(S_q[0], S_v[0]), float(S_t[0]))
                n_done = 1
            # every accepted step at or before t, with the hook the integrator calls (its own
            # re-seeding schedule), the derailment checks off
            t_end = float(t) + 1e-12 * max(1.0, abs(float(t)))
            while n_done < S_t.size and S_t[n_done] <= t_end:
                kind.accept_step(model.body_states(S_q[n_done], S_v[n_done]), float(S_t[n_done]), check=False)
                n_done += 1
            return
        if i == 0:
            kind.reset_state(bs, float(t))
            return
        t_prev = float(T[i - 1])
        n_sub = int(np.ceil((float(t) - t_prev) / max_step))
        h = float(t) - t_prev
        for k in range(1, n_sub):
            qk, vk = _hermite_state(model, Qs[i - 1], Vs[i - 1], Qs[i], Vs[i], h, k / n_sub, axle_bodies)
            kind.accept_step(model.body_states(qk, vk), t_prev + k / n_sub * h, reseed=True, check=False)
        kind.accept_step(bs, float(t), reseed=True, check=False)

    sign = {"max": lambda x: x, "min": lambda x: -x, "absmax": np.abs}
    refine_peaks = at == "steps" and peak_samples > 0
    best = {pc: (np.full(nw, -np.inf), np.full(nw, np.nan)) for pc in PEAK_COLUMNS}
    # the rows' wheel quantities that the lift location and the peaks read (per row, (nw,))
    wanted = sorted({"Q [N]"} | {col for col, _ in PEAK_COLUMNS})
    if recorded is not None:
        # every row with the state the run had after the last accepted step at or before it:
        # the rows are independent, evaluated ROW_BATCH at a time
        m_of = np.maximum(np.searchsorted(S_t, T + 1e-12 * np.maximum(1.0, np.abs(T)), side="right") - 1, 0)

        def row_state(i):
            return WheelRailKind.state_from_compiled(st, recorded[m_of[i], e_row])

        parts = {col: [] for col in wanted}
        for c0 in range(0, len(T), ROW_BATCH):
            idx = range(c0, min(len(T), c0 + ROW_BATCH))
            out = evaluate([Qs[i] for i in idx], [Vs[i] for i in idx], [row_state(i) for i in idx])
            rows.append(table_rows(T[c0:c0 + len(idx)], out))
            for col in parts:
                parts[col].append(np.asarray(out["wheels"][col], float))
        W_rows = {col: np.concatenate(p_).reshape(len(T), nw) for col, p_ in parts.items()}

    def wheels_at(k, taus, state):  # wheel outputs at states interpolated in the step (T[k - 1], T[k])
        qs, vs = interpolated(k, taus)
        return evaluate(qs, vs, [state] * len(taus))["wheels"]

    def consider_peaks(i, recent, state_of):
        """Row i - 1 a local extreme of some (column, wheel)?  Refine over (T[i - 2], T[i]), at
        interpolated states with the search state of row i (``state_of()``, read only then)."""
        todo = []
        for pc in PEAK_COLUMNS:
            xa, xb, xc = (r_[0][pc] for r_ in recent)
            with np.errstate(invalid="ignore"):
                # a smooth peak exceeds its best sample by at most 1/8 of the larger change to
                # the neighbours (a parabola sampled with the peak midway between samples): 1/4 kept
                change = np.maximum(np.abs(xb - xa), np.abs(xb - xc))
                room = 0.25 * np.where(np.isfinite(change), change, 0.0)
                cand = (xb >= xa) & (xb >= xc) & np.isfinite(xb) & (xb + room > best[pc][0])
            if cand.any():
                todo.append((pc, np.flatnonzero(cand)))
        if not todo:
            return
        taus, qs, vs = [], [], []
        for k in (i - 1, i):  # both steps' samples in one call
            tk = [float(T[k - 1]) + j / peak_samples * (float(T[k]) - float(T[k - 1])) for j in range(1, peak_samples)]
            qk, vk = interpolated(k, tk)
            taus, qs, vs = taus + tk, qs + qk, vs + vk
        sampled = evaluate(qs, vs, [state_of()] * len(qs))["wheels"]
        taus.append(float(T[i - 1]))  # the row itself, last (the first sample wins a tie)
        for pc, ws_ in todo:
            col, kd = pc
            vals = np.concatenate([np.asarray(sampled[col], float).reshape(-1, nw), recent[1][1][col][None, :]])
            vals = np.nan_to_num(sign[kd](vals), nan=-np.inf)
            for w_ in ws_:
                j = int(np.argmax(vals[:, w_]))
                if vals[j, w_] > best[pc][0][w_]:
                    best[pc][0][w_], best[pc][1][w_] = vals[j, w_], taus[j]

    prev_loaded = None
    recent: list[tuple] = []  # the last three rows: (their signed peak columns, their quantities)
    try:
        for i, t in enumerate(T):
            if recorded is not None:
                wq = {col: W_rows[col][i] for col in wanted}
                state_i = None  # the row's search state, read when needed
            else:
                bs = model.body_states(Qs[i], Vs[i])
                carry(i, t, bs)
                state_i = st.state
                out = evaluate([Qs[i]], [Vs[i]], [state_i])
                rows.append(table_rows([t], out))
                wq = {col: np.asarray(out["wheels"][col], float) for col in wanted}
            loaded = wq["Q [N]"] > 0.0
            if locate_lift and prev_loaded is not None and np.any(loaded != prev_loaded):
                if state_i is None:
                    state_i = row_state(i)
                ta, tb = float(T[i - 1]), float(t)
                for w_ in np.flatnonzero(loaded != prev_loaded):
                    lo, hi = ta, tb  # the condition at lo is prev_loaded[w_], at hi loaded[w_]
                    while hi - lo > lift_tol:
                        mid = 0.5 * (lo + hi)
                        if (np.asarray(wheels_at(i, [mid], state_i)["Q [N]"])[w_] > 0.0) == prev_loaded[w_]:
                            lo = mid
                        else:
                            hi = mid
                    crossings[labels[w_]][tb] = 0.5 * (lo + hi)
            prev_loaded = loaded
            if refine_peaks:
                signed = {pc: np.nan_to_num(sign[pc[1]](wq[pc[0]]), nan=-np.inf)
                          for pc in PEAK_COLUMNS}  # once per row, for the best and the candidates
                recent.append((signed, wq))
                for pc, x in signed.items():  # every sample counts (the first, the last, a plateau)
                    better = x > best[pc][0]
                    best[pc][0][better], best[pc][1][better] = x[better], float(t)
                if len(recent) >= 3:
                    consider_peaks(i, recent, (lambda: state_i) if state_i is not None else (lambda: row_state(i)))
                    recent.pop(0)
    finally:
        st.state = saved
    df = pd.DataFrame({k: np.concatenate([np.asarray(r_[k]) for r_ in rows]) for k in rows[0]})
    if wheels is not None:
        df = df[df["wheel"].isin(wheels)].reset_index(drop=True)
    df.attrs["at"] = at
    df.attrs["seed path"] = seed_path
    if locate_lift:
        df.attrs["lift crossings"] = {lab: c for lab, c in crossings.items() if wheels is None or lab in wheels}
        df.attrs["lift tolerance [s]"] = float(lift_tol)
    if refine_peaks:
        back = {"max": 1.0, "min": -1.0, "absmax": 1.0}
        df.attrs["peaks"] = {lab: {col: (kd, float(back[kd] * best[(col, kd)][0][w_]), float(best[(col, kd)][1][w_]))
                                   for col, kd in PEAK_COLUMNS}
                             for w_, lab in enumerate(labels) if wheels is None or lab in wheels}
    return df
