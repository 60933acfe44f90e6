r"""The ``coaster-analytic`` scene: bodies on analytic tracks against their closed forms.

A body runs through the path-following joint (:mod:`coaster.path_joint`, arc length L as an
extra coordinate) on six tracks built from :mod:`coaster.track` segments and
:mod:`coaster.frames` frames, and each run is compared with its closed form
(notes/coaster.md, "Closed forms for tests"); g = 9.81 m/s², gravity along −z.

==================  =====================================  ==========================================
case                body, frame                            closed form
==================  =====================================  ==========================================
helix               rigid car (m, J_t, J_n, J_b), Frenet   L̈ = −m g sin α/(m + J_zz/h²), J_zz = J_t
                                                           sin²α + J_b cos²α, sin α = c/h; F·n = m κ
                                                           L̇², F·b = m g R/h; n = F/(m g) at the centre
vertical loop       bead (J = 0), RMF (b to the centre)    v² = v_b² − 2gR(1 − cos φ); N = F·b = m(v²/R
                                                           + g cos φ); t_top = (2R/v_b) F(π/2, k),
                                                           k² = 4gR/v_b²; N_b − N_t = 6 m g
banked circle       rigid car, RMF rolled by β, rider      q = v²/(gR), speed constant; at the rider
                    1 m above the track                    R_P = R − h sin β, q_P = ω² R_P/g, ω = v/R:
                                                           n_y = q_P cos β − sin β, n_z = q_P sin β +
                                                           cos β; tan β = q: n_y = 0 at the track
clothoid            bead, RMF                              κ = L/a; speed constant; n_y = v² κ/g,
                                                           jerk_y = v³/(a g), n_z = 1
ballistic parabola  bead, RMF                              z = x tan γ − g x²/(2 v₀² cos²γ) is the free
                                                           flight from v₀: λ = 0, n = 0 (weightless)
S-curve             bead, RMF; frames compared             κ linear through 0: n_y = v² κ/g changes
                                                           sign smoothly; Frenet flips by π there
==================  =====================================  ==========================================

Load factors are those of :func:`coaster.rider.rider_loads` (car axes x forward, y left, z up).

**Tolerances from the integrator's settings.**  Every run uses ``dop853-projection`` with
rtol = atol = ``RTOL`` (1e-10).  A comparison passes when ``|simulated − closed form|`` ≤
K · rtol · scale with K = ``K_TOL`` = 1e3 (the global error of an rtol-controlled explicit
method over the 10²–10³ steps of a run stays within 10–100 rtol; K leaves a further factor 10)
and scale the size of the quantity: 1 + ``|L|`` (m) for arc lengths, 1 + v (m/s) for speeds,
m (g + v²/ρ) (N) for forces, 1 + q (g) for load factors, 1 + q/τ (g/s) for the jerk with τ the
time to cross the track.  The rotation-minimising frame is a quintic Hermite table; with
``max_step`` = 0.25 m its interpolation error (h|ω|)⁶/46080 is below 1e-14 on these tracks,
far inside the tolerances for positions, forces and loads; the jerk, a third derivative, feels
the table more (measured 2.4e-8 g/s on the clothoid and 2.5e-8 g/s on the S-curve, the same for
ε = 1e-5 … 1e-3 s and already at the exact initial state, about 0.2 of its tolerance).  Zero
closed forms (the parabola's multipliers) are compared against
K · rtol · m g.

**Frames where Frenet breaks.**  On a straight the Frenet frame is undefined (κ = 0: an
:class:`core.errors.InputError`, or an explicit fallback); on the S-curve's inflection its
normal flips by π between neighbouring samples (:meth:`coaster.frames.FrenetFrame.check`),
while the rotation-minimising frame turns smoothly (:func:`coaster.frames.frame_quality`).

References
----------
Pombo, J. and Ambrósio, J. (2003). General spatial curve joint for rail guided vehicles.
Multibody Syst. Dyn. 9:237-264; (2007) Modelling tracks for roller coaster dynamics. Int. J.
Vehicle Design 45(4):470-500 (the joint and the roller-coaster scenario).
Bishop, R. L. (1975). There is more than one way to frame a curve. Amer. Math. Monthly 82:246-251.
Byrd, P. F. and Friedman, M. D. (1971). Handbook of Elliptic Integrals, 2nd ed. (pendulum-type
time integral, F(φ, k), for the time to the top of the loop).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.special import ellipkinc

from core.errors import InputError
from core.model import ModelBuilder
from core.simulation import simulate

from .frames import FrenetFrame, RotationMinimisingFrame, frame_quality
from .path_joint import PathFollowingJoint
from .rider import read_acceleration_limits, rider_loads, time_above_limits
from .track import CircularArc, Clothoid, Helix, Segment, Straight

__all__ = ["G", "K_TOL", "METHOD", "RTOL", "SCENE", "Parabola", "analytic_cases", "coaster_analytic_scene",
           "run_body_on_track"]

G = 9.81
METHOD = "dop853-projection"
RTOL = 1e-10
K_TOL = 1e3
SCENE = "coaster-analytic"


# ---------------------------------------------------------------------------------------------
# the ballistic parabola as an analytic segment
# ---------------------------------------------------------------------------------------------
class Parabola(Segment):
    r"""The trajectory of free flight as a track: z = x tan γ − x²/(2p), p = v₀² cos²γ/g.

    In the plane x–z (local x forward).  With the slope u(x) = tan γ − x/p and
    F(u) = ½ (u √(1 + u²) + asinh u), the arc length is L(x) = p [F(tan γ) − F(u(x))]; x(L)
    by Newton's method (x ← x − (L(x) − L)/√(1 + u²)).  Derivatives in L by the inverse-
    function formulas of :class:`coaster.track.SplineCentreline` with g_x = (1, 0, u),
    g_xx = (0, 0, −1/p), g_xxx = g_xxxx = 0.  The segment ends where it is back at its start
    height (x = 2 p tan γ).

    Parameters
    ----------
    speed : float
        v₀ (m/s) at the start, the speed of the free flight this parabola carries.
    angle : float
        γ (rad), the start grade, in (0, π/2).
    gravity : float
        g (m/s²).
    """

    def __init__(self, speed, angle, gravity=G, origin=None, rotation=None, name=None):
        nm = name or "Parabola"
        self.speed = self._positive(nm, "speed", speed)
        self.angle = float(angle)
        if not 0.0 < self.angle < 0.5 * math.pi:
            raise InputError(f"{nm}: angle must be in (0, pi/2) rad, got {angle!r}")
        self.gravity = self._positive(nm, "gravity", gravity)
        self.p = self.speed**2 * math.cos(self.angle) ** 2 / self.gravity
        self.u0 = math.tan(self.angle)
        self.length = 2.0 * self.p * self._F(self.u0)
        super().__init__(origin, rotation, name)

    @staticmethod
    def _F(u):
        return 0.5 * (u * np.sqrt(1.0 + u * u) + np.arcsinh(u))

    def L_of_x(self, x):
        """Arc length (m) at the horizontal distance x (m)."""
        return self.p * (self._F(self.u0) - self._F(self.u0 - np.asarray(x, float) / self.p))

    def x_of_L(self, L):
        """Horizontal distance x (m) at arc length L (m), Newton's method to 1e-14 relative."""
        L = np.asarray(L, float)
        x = L * math.cos(self.angle)
        for _ in range(50):
            u = self.u0 - x / self.p
            step = (self.L_of_x(x) - L) / np.sqrt(1.0 + u * u)
            x = x - step
            if np.all(np.abs(step) <= 1e-14 * max(1.0, self.length)):
                return x
        raise InputError(f"{self.name}: arc-length inversion did not converge")  # pragma: no cover

    def _local(self, L):
        x = self.x_of_L(L)
        p = self.p
        u = self.u0 - x / p
        n = x.size
        g0 = np.column_stack([x, np.zeros(n), x * self.u0 - x * x / (2 * p)])
        g1 = np.column_stack([np.ones(n), np.zeros(n), u])
        g2 = np.column_stack([np.zeros(n), np.zeros(n), np.full(n, -1.0 / p)])
        s = np.sqrt(1.0 + u * u)
        s1 = -u / (p * s)
        s2 = (1.0 / p**2 - s1**2) / s
        s3 = -3.0 * s1 * s2 / s
        u1 = 1.0 / s
        u2 = -s1 / s**3
        u3 = u1 * (-s2 / s**3 + 3.0 * s1**2 / s**4)
        u4 = -s3 / s**5 + 10.0 * s1 * s2 / s**6 - 15.0 * s1**3 / s**7
        c = lambda a: a[:, None]  # noqa: E731
        out = np.empty((5, n, 3))
        out[0] = g0
        out[1] = g1 * c(u1)
        out[2] = g2 * c(u1**2) + g1 * c(u2)
        out[3] = 3.0 * g2 * c(u1 * u2) + g1 * c(u3)
        out[4] = g2 * c(3.0 * u2**2 + 4.0 * u1 * u3) + g1 * c(u4)
        return out


# ---------------------------------------------------------------------------------------------
# one run
# ---------------------------------------------------------------------------------------------
def run_body_on_track(name, curve, L0, Ld0, t_end, mass=1.0, inertia=(0.0, 0.0, 0.0), t_eval=None, n_output=101,
                      rtol=RTOL):
    r"""One body on a framed track through the path-following joint, integrated by :data:`METHOD`.

    The body ``car`` (mass m, principal inertias J) is locked to the track frame at arc length L,
    an extra coordinate: the six rows Φ1 = r + A s′ − g(L), n·u_ξ, b·u_ξ, n·u_ζ of
    :class:`coaster.path_joint.PathFollowingJoint` (Pombo & Ambrósio 2003), with L̈ from the
    equations of motion under gravity (0, 0, −g), g = :data:`G`; rtol = atol = ``rtol``.

    Parameters
    ----------
    name : str
        The run's name (model name; in the error message of a failed run).
    curve : core.curves.FramedCurve
        The track with its frame (:mod:`coaster.frames`).
    L0, Ld0 : float
        Initial arc length (m) and speed along the track (m/s).
    t_end : float
        End time (s).
    mass : float
        m (kg).
    inertia : (3,) array_like
        J_t, J_n, J_b (kg m²) about the body axes (0 for a bead).
    t_eval : (n,) array_like, optional
        Output times (s); default ``n_output`` equally spaced.
    n_output : int
    rtol : float
        rtol = atol of the integrator.

    Returns
    -------
    model : core.model.Model
    joint : coaster.path_joint.PathFollowingJoint
    res : core.results.SimulationResult
    reactions : pandas.DataFrame
        :meth:`~coaster.path_joint.PathFollowingJoint.reaction_table` (track frame, N and N m).

    Raises
    ------
    RuntimeError
        If the run failed (its message).
    """
    joint = PathFollowingJoint("path", "car", curve, "L")
    r, p, v, w = joint.initial_state(L0, Ld0)
    b = ModelBuilder(3, name.replace(" ", "_").replace("-", "_"), gravity=(0.0, 0.0, -G))
    b.add_body("car", mass, inertia, r, orientation=p, velocity=v, angular_velocity=w)
    b.add_coordinate("L", L0, Ld0)
    b.add_joint(joint)
    model = b.build()
    res = simulate(model, (0.0, t_end), METHOD, rtol=rtol, atol=rtol, t_eval=t_eval, n_output=n_output)
    if res.status == "failed":
        raise RuntimeError(f"{SCENE}: the {name} run failed: {res.message}")
    reac = joint.reaction_table(model, res)
    return model, joint, res, reac


def _Ldot(res, model):
    return res.v[:, model.n_bodies * 6]


def _row(case, quantity, unit, sim, exact, scale, rtol=RTOL):
    sim = np.atleast_1d(np.asarray(sim, float))
    exact = np.broadcast_to(np.asarray(exact, float), sim.shape)
    err = np.abs(sim - exact)
    k = int(np.argmax(err))
    tol = K_TOL * rtol * float(scale)
    return {"case": case, "quantity": quantity, "unit": unit, "simulated": float(sim[k]),
            "closed form": float(exact[k]), "|error|": float(err[k]), "tolerance": tol,
            "error/tolerance": float(err[k] / tol), "samples": int(sim.size), "pass": bool(err[k] <= tol)}


# ---------------------------------------------------------------------------------------------
# the cases
# ---------------------------------------------------------------------------------------------
def _helix(fast):
    R, c, m, J = 10.0, 2.0, 500.0, (100.0, 200.0, 250.0)
    h = math.hypot(R, c)
    sa, ca, kappa = c / h, R / h, R / h**2
    acc = -m * G * sa / (m + (J[0] * sa**2 + J[2] * ca**2) / h**2)
    L0, Ld0, T = 5.0, 15.0, (1.0 if fast else 2.0)
    curve = FrenetFrame(Helix(R, c, 6 * math.pi), name="Frenet frame of a helix")
    model, joint, res, reac = run_body_on_track("helix", curve, L0, Ld0, T, m, J)
    t = res.t
    L, Ld = res.q[:, model.n_bodies * 7], _Ldot(res, model)
    Lx, Vx = L0 + Ld0 * t + 0.5 * acc * t**2, Ld0 + acc * t
    loads = rider_loads(model, res, "car", coordinate="L")
    q = kappa * Ld0**2 / G
    rows = [_row("helix", "L", "m", L, Lx, 1 + np.abs(Lx).max()),
            _row("helix", "speed", "m/s", Ld, Vx, 1 + Ld0),
            _row("helix", "F_t", "N", reac["F_t [N]"], m * (acc + G * sa), m * (G + kappa * Ld0**2)),
            _row("helix", "F_n", "N", reac["F_n [N]"], m * kappa * Vx**2, m * (G + kappa * Ld0**2)),
            _row("helix", "F_b", "N", reac["F_b [N]"], m * G * ca, m * (G + kappa * Ld0**2)),
            _row("helix", "n_x", "g", loads["n_x [g]"], (acc + G * sa) / G, 1 + q),
            _row("helix", "n_y", "g", loads["n_y [g]"], kappa * Vx**2 / G, 1 + q),
            _row("helix", "n_z", "g", loads["n_z [g]"], ca * np.ones_like(t), 1 + q)]
    panel = dict(x=t, xlabel="t [s]", ylabel="F_n [N]", sim=reac["F_n [N]"].to_numpy(), exact=m * kappa * Vx**2,
                 title="helix (rigid car, Frenet frame): normal reaction")
    return rows, res, panel, None


def _loop(fast):
    R, vb, m = 10.0, 20.0, 1.0
    k2 = 4 * G * R / vb**2
    t_top = 2 * R / vb * ellipkinc(0.5 * math.pi, k2)
    t_eval = np.linspace(0.0, t_top, 41 if fast else 121)
    from .track import VerticalLoop

    curve = RotationMinimisingFrame(VerticalLoop(R), max_step=0.25, tol=1e-12, name="RMF of a vertical loop")
    model, joint, res, reac = run_body_on_track("vertical loop", curve, 0.0, vb, t_top, m, (0.0, 0.0, 0.0), t_eval=t_eval)
    L, Ld = res.q[:, model.n_bodies * 7], _Ldot(res, model)
    phi = L / R
    v2 = vb**2 - 2 * G * R * (1 - np.cos(phi))
    N = m * (v2 / R + G * np.cos(phi))
    loads = rider_loads(model, res, "car", coordinate="L")
    q = vb**2 / (G * R)
    Fs = m * (G + vb**2 / R)
    Nb, Nt = reac["F_b [N]"].iloc[0], reac["F_b [N]"].iloc[-1]
    rows = [_row("vertical loop", "L at t_top", "m", L[-1], math.pi * R, 1 + math.pi * R),
            _row("vertical loop", "speed", "m/s", Ld, np.sqrt(v2), 1 + vb),
            _row("vertical loop", "F_b (normal, to the centre)", "N", reac["F_b [N]"], N, Fs),
            _row("vertical loop", "F_t", "N", reac["F_t [N]"], 0 * N, Fs),
            _row("vertical loop", "N_bottom - N_top", "N", Nb - Nt, 6 * m * G, Fs),
            _row("vertical loop", "n_z", "g", loads["n_z [g]"], N / (m * G), 1 + q),
            _row("vertical loop", "n_x", "g", loads["n_x [g]"], 0 * N, 1 + q)]
    panel = dict(x=np.degrees(phi), xlabel="loop angle φ [deg]", ylabel="n_z [g]", sim=loads["n_z [g]"].to_numpy(),
                 exact=N / (m * G), title="vertical loop (bead, RMF): vertical load factor")
    limits = time_above_limits(loads, read_acceleration_limits())
    return rows, res, panel, (loads, limits)


def _banked(fast, perfect):
    R, v, m, J, hs = 30.0, 20.0, 500.0, (100.0, 150.0, 200.0), 1.0
    q = v**2 / (G * R)
    beta = math.atan(q) if perfect else math.radians(30.0)
    arc = CircularArc(R, 2 * math.pi)
    # the rolled frame: b tilted by beta towards the centre of the turn
    sign = 1.0
    for s_ in (1.0, -1.0):
        fr = RotationMinimisingFrame(arc, bank=s_ * beta, max_step=0.25, tol=1e-12)
        Rm = fr.frame([0.0])[0][0]
        centre = np.array([0.0, R, 0.0]) - arc.derivatives([0.0])[0, 0]
        if Rm[:, 2] @ centre > 0:
            sign = s_
            break
    curve = RotationMinimisingFrame(arc, bank=sign * beta, max_step=0.25, tol=1e-12,
                                    name=f"RMF of a circle banked {math.degrees(beta):.1f} deg")
    T = 1.0 if fast else 3.0
    name = "banked circle (perfect bank)" if perfect else "banked circle"
    model, joint, res, reac = run_body_on_track(name, curve, 0.0, v, T, m, J)
    Ld = _Ldot(res, model)
    w = v / R
    RP = R - hs * math.sin(beta)
    qP = w**2 * RP / G
    at_track = rider_loads(model, res, "car", jerk=False)
    loads = rider_loads(model, res, "car", (0.0, 0.0, hs), jerk=False)
    ones = np.ones_like(res.t)
    Fs = m * G * (1 + q)
    rows = [_row(name, "speed", "m/s", Ld, v * ones, 1 + v),
            _row(name, "F_n", "N", reac["F_n [N]"], m * G * (q * math.cos(beta) - math.sin(beta)) * ones, Fs),
            _row(name, "F_b", "N", reac["F_b [N]"], m * G * (q * math.sin(beta) + math.cos(beta)) * ones, Fs),
            _row(name, "n_y at the track", "g", at_track["n_y [g]"], (q * math.cos(beta) - math.sin(beta)) * ones,
                 1 + q),
            _row(name, "n_y at the rider (1 m up)", "g", loads["n_y [g]"],
                 (qP * math.cos(beta) - math.sin(beta)) * ones, 1 + q),
            _row(name, "n_z at the rider (1 m up)", "g", loads["n_z [g]"],
                 (qP * math.sin(beta) + math.cos(beta)) * ones, 1 + q),
            _row(name, "n_x at the rider (1 m up)", "g", loads["n_x [g]"], 0 * ones, 1 + q)]
    point = (math.degrees(beta), float(at_track["n_y [g]"].mean()), float(at_track["n_z [g]"].mean()), q)
    return rows, res, point


def _clothoid(fast, s_curve):
    v, length, kmax = 15.0, 60.0, 1.0 / 30.0
    k0 = -kmax if s_curve else 0.0
    seg = Clothoid(length, k0, kmax)
    a = seg.a
    curve = RotationMinimisingFrame(seg, max_step=0.25, tol=1e-12)
    T = length / v * (0.5 if fast else 1.0)
    name = "S-curve" if s_curve else "clothoid"
    model, joint, res, reac = run_body_on_track(name, curve, 0.0, v, T, 1.0, (0.0, 0.0, 0.0))
    L, Ld = res.q[:, model.n_bodies * 7], _Ldot(res, model)
    loads = rider_loads(model, res, "car", coordinate="L")
    t = res.t
    kap = k0 + (v * t) / a
    q = v**2 * kmax / G
    ones = np.ones_like(t)
    rows = [_row(name, "L", "m", L, v * t, 1 + length),
            _row(name, "speed", "m/s", Ld, v * ones, 1 + v),
            _row(name, "n_y", "g", loads["n_y [g]"], v**2 * kap / G, 1 + q),
            _row(name, "n_z", "g", loads["n_z [g]"], ones, 1 + q),
            _row(name, "jerk_y", "g/s", loads["jerk_y [g/s]"], v**3 / (a * G) * ones, 1 + q * v / length),
            _row(name, "F_n", "N", reac["F_n [N]"], v**2 * kap, G * (1 + q))]
    panel = dict(x=L, xlabel="L [m]", ylabel="n_y [g]", sim=loads["n_y [g]"].to_numpy(), exact=v**2 * kap / G,
                 title=f"{name} (bead, RMF, {v:g} m/s): lateral load factor")
    return rows, res, panel


def _parabola(fast):
    v0, gam, m = 20.0, math.radians(40.0), 1.0
    seg = Parabola(v0, gam)
    curve = RotationMinimisingFrame(seg, max_step=0.25, tol=1e-12, name="RMF of a ballistic parabola")
    T_flight = 2 * v0 * math.sin(gam) / G
    T = T_flight * (0.5 if fast else 0.95)
    model, joint, res, reac = run_body_on_track("ballistic parabola", curve, 0.0, v0, T, m, (0.0, 0.0, 0.0))
    t = res.t
    L, Ld = res.q[:, model.n_bodies * 7], _Ldot(res, model)
    Lx = seg.L_of_x(v0 * math.cos(gam) * t)
    Vx = np.hypot(v0 * math.cos(gam), v0 * math.sin(gam) - G * t)
    lam = joint.joint_multipliers(model, res.lam)
    loads = rider_loads(model, res, "car", coordinate="L")
    nmag = np.linalg.norm(loads[["n_x [g]", "n_y [g]", "n_z [g]"]].to_numpy(), axis=1)
    zero = np.zeros_like(t)
    rows = [_row("ballistic parabola", "L", "m", L, Lx, 1 + seg.length),
            _row("ballistic parabola", "speed", "m/s", Ld, Vx, 1 + v0),
            _row("ballistic parabola", "max |multiplier| (force rows)", "N", np.abs(lam[:, :3]).max(axis=1), zero,
                 m * G),
            _row("ballistic parabola", "max |multiplier| (orientation rows)", "N m",
                 np.abs(lam[:, 3:]).max(axis=1), zero, m * G),
            _row("ballistic parabola", "|n|", "g", nmag, zero, 1.0)]
    panel = dict(x=t, xlabel="t [s]", ylabel="speed [m/s]", sim=Ld, exact=Vx,
                 title="ballistic parabola (bead, RMF): speed of free flight, multipliers zero")
    return rows, res, panel


def _frames_where_frenet_breaks(n):
    """Frenet vs rotation-minimising frame on a straight, the S-curve and a helix (reference)."""
    tracks = {"straight (40 m)": Straight(40.0),
              "S-curve (clothoid, kappa -1/30 ... 1/30 1/m)": Clothoid(60.0, -1 / 30, 1 / 30),
              "helix (R 10 m, c 2 m)": Helix(10.0, 2.0, 2 * math.pi)}
    rows, curves = [], {}
    for tname, c in tracks.items():
        L = np.linspace(0.0, c.length, n)
        for fname, make in (("Frenet", lambda c: FrenetFrame(c)),
                            ("Frenet, vertical fallback", lambda c: FrenetFrame(c, fallback="vertical")),
                            ("rotation-minimising", lambda c: RotationMinimisingFrame(c, max_step=0.25, tol=1e-12))):
            fr = make(c)
            try:
                fr.check(L) if isinstance(fr, FrenetFrame) else None
                outcome = "defined and continuous"
            except InputError as exc:
                outcome = f"InputError: {str(exc).split(': ', 1)[1][:110]}"
            try:
                fq = frame_quality(fr, c, L=L)
            except InputError:
                fq = None
            row = {"track": tname, "frame": fname, "outcome": outcome}
            if fq is None:
                row.update({"max rotation step [rad]": np.nan, "expected step [rad]": np.nan,
                            "max orthonormality error [-]": np.nan})
            else:
                row.update({"max rotation step [rad]": float(fq["rotation_step_rad"].max()),
                            "expected step [rad]": float(fq["expected_step_rad"].max()),
                            "max orthonormality error [-]": float(fq["orthonormality"].max())})
                if tname.startswith("S-curve"):
                    curves[fname] = fq
            rows.append(row)
    return pd.DataFrame(rows), curves


def analytic_cases(fast=False):
    """Run every case of the module docstring's table against its closed form.

    A comparison passes when ``|simulated − closed form|`` ≤ :data:`K_TOL` · rtol · scale (module
    docstring, "Tolerances from the integrator's settings").

    Parameters
    ----------
    fast : bool
        Shorter runs and fewer samples (the scene's fast mode).

    Returns
    -------
    comparison : pandas.DataFrame
        One row per (case, quantity): the simulated value and the closed form at the sample of
        largest error, ``|error|``, ``tolerance``, ``error/tolerance``, ``samples``, ``pass``.
    runs : pandas.DataFrame
        One row per run: method, tolerances, status, steps, largest position violation, energy
        drift, wall time.
    panels : list of dict
        Per figure panel ``x``, ``sim``, ``exact`` (arrays) and ``xlabel``, ``ylabel``, ``title``.
    frames : pandas.DataFrame
        Frenet against the rotation-minimising frame on a straight, the S-curve and a helix.
    extras : dict
        ``loop_loads`` (rider loads on the loop), ``loop_limits`` (their time above the
        acceleration limits), ``bank_points`` ((β [deg], n_y, n_z, q) of the two banked runs),
        ``frame_curves`` (:func:`coaster.frames.frame_quality` of each frame on the S-curve).
    """
    rows, runs, panels = [], [], []

    def add_run(name, res):
        e = res.energy
        runs.append({"case": name, "method": res.meta.get("method"), "rtol [-]": res.meta.get("rtol"),
                     "atol [-]": res.meta.get("atol"), "status": res.status, "output times [-]": len(res.t),
                     "steps [-]": int(res.counters.get("n_steps", 0)),
                     "max position violation [m]": float(np.max(res.position_violation)),
                     "energy drift [J]": float(np.max(np.abs(e - e[0]))) if e is not None else np.nan,
                     "wall time [s]": float(res.meta.get("wall_time_s", np.nan))})

    r, res, panel, _ = _helix(fast)
    rows += r
    panels.append(panel)
    add_run("helix", res)
    r, res, panel, (loop_loads, loop_limits) = _loop(fast)
    rows += r
    panels.append(panel)
    add_run("vertical loop", res)
    bank_points = []
    for perfect in (False, True):
        r, res, point = _banked(fast, perfect)
        rows += r
        bank_points.append(point)
        add_run("banked circle (perfect bank)" if perfect else "banked circle", res)
    for s_curve in (False, True):
        r, res, panel = _clothoid(fast, s_curve)
        rows += r
        panels.append(panel)
        add_run("S-curve" if s_curve else "clothoid", res)
    r, res, panel = _parabola(fast)
    rows += r
    panels.append(panel)
    add_run("ballistic parabola", res)
    frames_table, frame_curves = _frames_where_frenet_breaks(601 if fast else 2001)
    extras = {"loop_loads": loop_loads, "loop_limits": loop_limits, "bank_points": bank_points,
              "frame_curves": frame_curves}
    return pd.DataFrame(rows), pd.DataFrame(runs), panels, frames_table, extras


# ---------------------------------------------------------------------------------------------
# the scene: examples/coaster/analytic.py
# ---------------------------------------------------------------------------------------------
def coaster_analytic_scene():
    """The ``coaster-analytic`` scene: the example script ``examples/coaster/analytic.py``."""
    from core.scenes import example_scene

    return example_scene(SCENE, "coaster/analytic.py",
                         "Coaster analytic: bodies on a helix, loop, banked circle, clothoid, parabola and S-curve "
                         "against closed forms",
                         "Path-following joint (Pombo & Ambrosio 2003) on analytic tracks, each run against its closed "
                         "form (speed, reactions, rider load factors, zero multiplier on the ballistic parabola), "
                         "tolerances from the integrator's rtol; Frenet vs rotation-minimising frame where Frenet "
                         "breaks.")
