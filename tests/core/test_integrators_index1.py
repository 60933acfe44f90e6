"""Index-1 (scipy-backed) and half-explicit integrators against analytic oracles.

Oracles: the exact (elliptic-integral) period of a compound pendulum, Newton's law on the centre of
mass for the pivot reaction, an independently integrated minimal-coordinate equation for
convergence orders, constraint invariants, energy conservation.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from core import frames
from core.integrators import METHODS, simulate
from core.integrators.half_explicit import HEM3_TABLEAU, HEM4_TABLEAU
from core.integrators.index1 import INDEX1_METHODS
from core.model import ModelBuilder
from core.results import FINISHED_STATUSES
from core.system import ConstrainedSystem

G = 9.81
L = 1.0
MASS = 1.0


def rod(theta0: float, dimension: int = 2, omega0: float = 0.0):
    """Uniform rod (compound pendulum) pinned at the origin; ``theta0`` measured from hanging."""
    phi = -np.pi / 2 + theta0  # body x-axis direction (angle from +x)
    c = (L / 2 * np.cos(phi), L / 2 * np.sin(phi))
    vc = (-L / 2 * np.sin(phi) * omega0, L / 2 * np.cos(phi) * omega0)
    J = MASS * L * L / 12
    if dimension == 2:
        b = ModelBuilder(2, "rod")
        b.add_body("rod", MASS, J, c, orientation=phi, velocity=vc, angular_velocity=omega0)
        b.add_revolute("pivot", "ground", "rod", (0.0, 0.0))
    else:
        b = ModelBuilder(3, "rod3d", gravity=(0.0, -G, 0.0))
        b.add_body("rod", MASS, [J, J, J], (*c, 0.0), orientation=frames.axis_angle_to_euler([0, 0, 1], phi),
                   velocity=(*vc, 0.0), angular_velocity=(0.0, 0.0, omega0))
        b.add_revolute("pivot", "ground", "rod", (0.0, 0.0, 0.0), axis=(0, 0, 1))
    return b.build()


def exact_period(theta0: float) -> float:
    """T = 4 sqrt(I_O / (m g d)) K(sin²(θ0/2)), I_O = m L²/3, d = L/2."""
    return 4.0 * np.sqrt(2.0 * L / (3.0 * G)) * ellipk(np.sin(theta0 / 2) ** 2)


def zero_crossings(t, y):
    """Times of sign changes of y (linear interpolation between samples)."""
    k = np.flatnonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)
    return t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])


# --------------------------------------------------------------------------------------------
def test_registry_names():
    for m in ("rk45", "dop853", "radau", "bdf", "lsoda"):
        for suffix in ("", "-baumgarte", "-projection"):
            assert m + suffix in METHODS
            assert m + suffix in INDEX1_METHODS
    assert "hem4" in METHODS and "hem3" in METHODS
    assert METHODS["hem4"].fixed_step


@pytest.mark.parametrize("order,tab", [(4, HEM4_TABLEAU), (3, HEM3_TABLEAU)])
def test_tableaux_satisfy_classical_order_conditions(order, tab):
    A, b = tab["A"], tab["b"]
    c = A.sum(1)
    conds = [b.sum() - 1, b @ c - 1 / 2, b @ c**2 - 1 / 3, b @ A @ c - 1 / 6]
    if order >= 4:
        conds += [b @ c**3 - 1 / 4, b @ (c * (A @ c)) - 1 / 8, b @ A @ c**2 - 1 / 12, b @ A @ A @ c - 1 / 24]
    assert np.max(np.abs(conds)) < 1e-14


@pytest.mark.parametrize("method,kw", [
    ("rk45-projection", {}),
    ("dop853", {}),
    ("radau-projection", {}),
    ("bdf-baumgarte", {}),
    ("lsoda-projection", {}),
    ("hem4", {"h": 5e-3, "rtol": 1e-8}),  # the accuracy h = 5e-3 gives (fixed-step error estimate 0.2)
])
def test_compound_pendulum_period_matches_elliptic_integral(method, kw):
    theta0 = 0.5
    T = exact_period(theta0)
    kw = dict(kw)
    rtol = kw.pop("rtol", 1e-9)
    r = simulate(rod(theta0), (0.0, 1.1 * T), method, rtol=rtol, atol=1e-11, n_output=1001,
                 compute_multipliers=False, **kw)
    # an adaptive method's global error is a few times rtol (the period tolerance below allows
    # 1e3 rtol): the energy check (3 × rtol × peak kinetic energy) may flag the drift, nothing else
    assert r.status == "finished" or all(w.startswith("energy drift") for w in r.warnings), r.message
    omega = r.v[:, 2]
    tz = zero_crossings(r.t, omega)  # ω = 0 at the turning points, every T/2
    assert len(tz) >= 2
    period = 2.0 * (tz[1] - tz[0])
    # linear interpolation of the crossing: ω̈ = −k cos θ ω vanishes there, so the sampling error
    # is O(k dt³) (k = 3g/2L); integration error O(rtol) (adaptive) or O(h⁴) (hem4)
    dt = r.t[1] - r.t[0]
    k = 1.5 * G / L
    tol = 10 * k * dt**3 + (1e3 * rtol * T if "h" not in kw else 20 * kw["h"] ** 4 * T)
    assert abs(period - T) < tol, (period, T)
    # the large-amplitude correction matters at this amplitude: the small-angle period is off
    T0 = 2 * np.pi * np.sqrt(2 * L / (3 * G))
    assert abs(T0 - T) > 100 * tol


@pytest.mark.parametrize("method,kw", [("dop853-projection", {}), ("rk45", {}), ("hem4", {"h": 1e-3})])
def test_pivot_reaction_equals_newton_on_centre_of_mass(method, kw):
    """Rod released from horizontal: F = m a_cm − m g, with a_cm from the simulated φ, φ̇ and the
    exact angular acceleration φ̈ = −(3 g / 2 L) cos φ (moment balance about the pivot)."""
    model = rod(np.pi / 2)
    r = simulate(model, (0.0, 1.5), method, rtol=1e-10, atol=1e-12, n_output=151, **kw)
    assert r.status == "finished", r.message
    phi, om = r.q[:, 2], r.v[:, 2]
    al = -1.5 * G / L * np.cos(phi)
    acm = 0.5 * L * np.stack([-np.sin(phi) * al - np.cos(phi) * om**2, np.cos(phi) * al - np.sin(phi) * om**2], 1)
    F = MASS * acm - MASS * np.array([0.0, -G])
    R = r.reactions["pivot"]
    assert np.max(np.abs(R[:, :2] - F)) < 1e-6 * MASS * G
    assert np.max(np.abs(R[:, 2])) < 1e-6 * MASS * G * L  # revolute transmits no moment
    # and the energy integral: φ̇² = −(3g/L) sin φ
    assert np.max(np.abs(om**2 + 3 * G / L * np.sin(phi))) < 1e-6 * 3 * G / L


def _step_end_violations(method, model, t_end, **kw):
    integ = METHODS[method](model, (0.0, t_end), **kw)
    pos, vel = [], []
    while integ.status == "running":
        integ.step()
        pos.append(np.max(np.abs(model.Phi(integ.t, integ.q))))
        vel.append(np.max(np.abs(model.velocity_violation(integ.t, integ.q, integ.v))))
    # the constraints are what is measured here; a fixed-step run may carry its error warning
    assert integ.status in FINISHED_STATUSES, integ.message
    return np.array(pos), np.array(vel), integ


def test_constraint_drift_unstabilised_vs_baumgarte_vs_projection():
    model = rod(2.5, omega0=3.0)  # large swing, near-vertical top: strong nonlinearity
    rtol, atol = 1e-6, 1e-8
    p0, v0, _ = _step_end_violations("rk45", model, 10.0, rtol=rtol, atol=atol)
    pb, vb, _ = _step_end_violations("rk45-baumgarte", model, 10.0, rtol=rtol, atol=atol)
    pp, vp, integ = _step_end_violations("rk45-projection", model, 10.0, rtol=rtol, atol=atol)
    # the unstabilised index-1 solution drifts off the position manifold (well beyond atol) ...
    assert p0[-1] > 100 * atol
    assert p0[-1] > 10 * p0[len(p0) // 10]  # ... and keeps drifting
    # Baumgarte keeps it bounded and much smaller
    assert pb.max() < 0.1 * p0[-1]
    # projection holds both levels at every step end to the projection tolerance (= atol)
    assert pp.max() <= atol
    assert vp.max() <= 1e-3 * atol * max(1.0, np.max(np.abs(integ.v)))
    assert integ.counters["n_factor"] > 0 and integ.counters["n_rhs"] > 0


def test_energy_drift_small_with_projection():
    model = rod(2.0)
    r = simulate(model, (0.0, 5.0), "dop853-projection", rtol=1e-10, atol=1e-12)
    assert r.status == "finished"
    scale = MASS * G * L
    assert np.max(np.abs(r.energy - r.energy[0])) < 1e-7 * scale


@pytest.mark.parametrize("method,order", [("hem4", 4), ("hem3", 3)])
def test_half_explicit_convergence_order(method, order):
    model = rod(np.pi / 2)  # released from horizontal
    ref = solve_ivp(lambda t, y: [y[1], -1.5 * G / L * np.cos(y[0])], (0, 1), [0.0, 0.0],
                    method="DOP853", rtol=1e-13, atol=1e-13)
    hs = np.array([0.04, 0.02, 0.01])
    err = []
    for h in hs:
        r = simulate(model, (0.0, 1.0), method, h=h, n_output=2)
        # the coarse steps carry the fixed-step error warning (their error exceeds rtol = 1e-6)
        assert r.success, r.message
        err.append(abs(r.q[-1, 2] - ref.y[0, -1]) + abs(r.v[-1, 2] - ref.y[1, -1]))
        # velocity constraints hold at every step end by construction
        assert r.velocity_violation[-1] < 1e-12
    slope = np.polyfit(np.log(hs), np.log(err), 1)[0]
    assert abs(slope - order) < 0.5, (slope, err)


def test_half_explicit_projection_holds_positions():
    model = rod(2.5, omega0=3.0)
    p, v, _ = _step_end_violations("hem4", model, 5.0, h=0.01)
    pp, vp, _ = _step_end_violations("hem4", model, 5.0, h=0.01, projection=True, atol=1e-10)
    assert p.max() > 1e-9  # unprojected: O(h^p) position drift
    assert pp.max() <= 1e-10
    assert vp.max() < 1e-12 and v.max() < 1e-12


class PointPendulumNaN(ConstrainedSystem):
    """Point mass on a massless rod in Cartesian (x, y); the applied force turns NaN for t > 0.5 s."""

    name = "nan-pendulum"
    n_q = n_v = 2
    n_c = 1
    mass_is_constant = True

    def __init__(self):
        self.q0 = np.array([1.0, 0.0])
        self.v0 = np.zeros(2)
        self.coordinate_names = ["x [m]", "y [m]"]
        self.velocity_names = ["vx [m/s]", "vy [m/s]"]
        self.constraint_names = ["rod"]

    def M(self, t, q):
        return np.eye(2)

    def Q(self, t, q, v):
        return np.array([0.0, -G]) if t <= 0.5 else np.full(2, np.nan)

    def Phi(self, t, q):
        return np.array([0.5 * (q @ q - 1.0)])

    def Phi_q(self, t, q):
        return q[None, :].copy()

    def nu(self, t, q):
        return np.zeros(1)

    def gamma(self, t, q, v):
        return np.array([-(v @ v)])


@pytest.mark.parametrize("method,kw", [("rk45", {}), ("radau-projection", {}), ("lsoda", {}), ("hem4", {"h": 0.01})])
def test_nan_force_ends_failed_with_time_and_keeps_output(method, kw):
    r = simulate(PointPendulumNaN(), (0.0, 1.0), method, n_output=101, **kw)
    assert r.status == "failed"
    assert "t =" in r.message
    t_fail = float(r.message.split("t =")[1].split()[0])
    assert 0.3 < t_fail <= 0.5 + 1e-9
    assert r.t[-1] <= 0.5 + 1e-9 and r.t[-1] >= 0.4  # the output before the failure is kept
    assert np.all(np.isfinite(r.q)) and np.all(np.isfinite(r.v))
    # the hand-written system (dense M, no constraint_terms) runs correctly before the failure
    assert np.max(np.abs(np.sum(r.q**2, 1) - 1.0)) < 1e-4


@pytest.mark.parametrize("method,kw", [("rk45-projection", dict(rtol=1e-9, atol=1e-11)),
                                       ("hem4", dict(h=5e-3, rtol=1e-7, atol=1e-9))])  # hem4: h = 5e-3 gives ~1e-8
def test_spatial_rod_matches_planar(method, kw):
    theta0 = 1.0
    r2 = simulate(rod(theta0, 2), (0.0, 2.0), method, n_output=41, **kw)
    r3 = simulate(rod(theta0, 3), (0.0, 2.0), method, n_output=41, **kw)
    assert r2.status == r3.status == "finished", (r2.message, r3.message)
    assert np.max(np.abs(r3.q[:, :2] - r2.q[:, :2])) < 1e-7
    assert np.max(np.abs(r3.q[:, 2])) < 1e-9  # stays in the plane
    assert np.max(np.abs(r3.v[:, 5] - r2.v[:, 2])) < 1e-6  # body-frame ω_z = planar θ̇
    angle = 2 * np.arctan2(r3.q[:, 6], r3.q[:, 3])
    assert np.max(np.abs(np.angle(np.exp(1j * (angle - r2.q[:, 2]))))) < 1e-7
    assert r3.position_violation.max() < 1e-6


def test_options_validation():
    model = rod(0.3)
    with pytest.raises(TypeError):
        simulate(model, (0, 1), "rk45", alpha=3.0)  # Baumgarte parameters only for -baumgarte
    with pytest.raises(ValueError):
        simulate(model, (0, 1), "hem4")  # fixed step needs h
    r = simulate(model, (0, 0.5), "rk45-baumgarte", alpha=5.0, beta=5.0)
    assert r.status == "finished"
