"""Canonical models (core.models) and published DAE test problems (core.benchmarks.testset).

Oracles: published reference solutions of the Bari test set (Andrews at t = 0.03 s, car axis at
t = 3), the minimal-coordinate chain ODE integrated by DOP853 at 1e-13, closed-form motions
(bead on a helix, pendulum tension), finite differences for Φ_q, ν and γ, and agreement of
planar and spatial formulations of the same mechanism.
"""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import core.integrators as CI
from core import models as M
from core.benchmarks.references import n_link_chain_reference
from core.benchmarks.testset import AndrewsSqueezer, CarAxis
from core.dynamics import accelerations
from core.system import as_dense

for _mod in pkgutil.iter_modules(CI.__path__):  # integrator families register on import
    importlib.import_module(f"core.integrators.{_mod.name}")


def _method(*preferred: str) -> str:
    for name in preferred:
        if name in CI.METHODS:
            return name
    raise AssertionError(f"none of the integrators {preferred} is registered: {sorted(CI.METHODS)}")


MODEL_FACTORIES = {
    "pendulum point": lambda: M.simple_pendulum(),
    "pendulum rod": lambda: M.simple_pendulum(bob="rod"),
    "pendulum point spatial": lambda: M.simple_pendulum(planar=False),
    "pendulum rod spatial": lambda: M.simple_pendulum(bob="rod", planar=False, angle0=0.4, rate0=1.0),
    "double pendulum": lambda: M.double_pendulum(angles0=(0.3, 1.2), rates0=(0.5, -1.0)),
    "double pendulum spatial": lambda: M.double_pendulum(planar=False),
    "slider crank driven": lambda: M.slider_crank(crank_angle0=0.4),
    "slider crank free": lambda: M.slider_crank(driven=False, crank_angle0=0.3, gravity=9.81),
    "four bar": lambda: M.four_bar(),
    "four bar driven": lambda: M.four_bar(crank_speed=10.0, crank_angle0=1.0),
    "chain 5": lambda: M.n_link_chain(5),
    "chain 3 spatial": lambda: M.n_link_chain(3, spatial=True),
    "helix": lambda: M.body_on_helix(),
}


def _derivative_errors(system, t, q, v, a, h=1e-6):
    """Errors of Φ_q (vs central differences of Φ), ν and γ (vs differences along a path).

    Along ``q(s) = q ⊕ (s v + ½ s² a)``, ``v(s) = v + s a`` at time ``t + s``:
    ``dΦ/ds = Φ_q v − ν`` and ``d/ds(Φ_q v − ν) = Φ_q a − γ`` at s = 0.
    """
    J = as_dense(system.Phi_q(t, q))
    Jfd = np.column_stack([
        (system.Phi(t, system.retract(q, h * e)) - system.Phi(t, system.retract(q, -h * e))) / (2 * h)
        for e in np.eye(system.n_v)
    ])

    def path(s):
        return system.retract(q, s * v + 0.5 * s * s * a), v + s * a

    def phidot(s):
        qs, vs = path(s)
        return as_dense(system.Phi_q(t + s, qs)) @ vs - system.nu(t + s, qs)

    qp, _ = path(h)
    qm, _ = path(-h)
    dphi = (system.Phi(t + h, qp) - system.Phi(t - h, qm)) / (2 * h)
    ddphi = (phidot(h) - phidot(-h)) / (2 * h)
    e_jac = np.abs(J - Jfd).max()
    e_nu = np.abs(dphi - (J @ v - system.nu(t, q))).max()
    e_gamma = np.abs(ddphi - (J @ a - system.gamma(t, q, v))).max()
    return e_jac, e_nu, e_gamma


# ------------------------------------------------------------------------------------------------
# every canonical model builds consistently
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("label", sorted(MODEL_FACTORIES))
def test_model_builds_consistent_and_solvable(label):
    m = MODEL_FACTORIES[label]()
    m.check_sizes()
    if m.n_c:
        assert np.abs(m.Phi(0.0, m.q0)).max() < 1e-12
        assert np.abs(m.velocity_violation(0.0, m.q0, m.v0)).max() < 1e-12
    a, lam = accelerations(m, 0.0, m.q0, m.v0)
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(lam))
    # the acceleration satisfies the acceleration-level constraints
    if m.n_c:
        J = as_dense(m.Phi_q(0.0, m.q0))
        assert np.abs(J @ a - m.gamma(0.0, m.q0, m.v0)).max() < 1e-8 * max(1.0, np.abs(a).max())


@pytest.mark.parametrize("label", sorted(MODEL_FACTORIES))
def test_model_constraint_derivatives(label):
    m = MODEL_FACTORIES[label]()
    rng = np.random.default_rng(1)
    q = m.normalize(m.retract(m.q0, 0.05 * rng.standard_normal(m.n_v)))
    v = rng.standard_normal(m.n_v)
    a = rng.standard_normal(m.n_v)
    e_jac, e_nu, e_gamma = _derivative_errors(m, 0.37, q, v, a)
    assert e_jac < 1e-7 and e_nu < 1e-7 and e_gamma < 1e-6


# ------------------------------------------------------------------------------------------------
# pendulums: closed forms at the initial state
# ------------------------------------------------------------------------------------------------


def test_point_pendulum_free_fall_start_and_tension():
    g, l, m = 9.81, 1.0, 1.0
    pend = M.simple_pendulum(length=l, mass=m)  # horizontal, at rest: the bob starts in free fall
    a, lam = accelerations(pend, 0.0, pend.q0, pend.v0)
    assert np.allclose(a[:2], [0.0, -g], atol=1e-12) and abs(a[2] + g / l) < 1e-12
    assert np.abs(lam).max() < 1e-12  # rod force m(g cos θ + l θ̇²) = 0 at θ = 90°, rest
    w = 2.0
    low = M.simple_pendulum(length=l, mass=m, angle0=0.0, rate0=w)
    a, lam = accelerations(low, 0.0, low.q0, low.v0)
    reac = low.reactions(0.0, low.q0, lam)["joint1"]
    assert abs(np.hypot(reac[0], reac[1]) - m * (g + l * w * w)) < 1e-10  # rod tension at the bottom


def test_rod_pendulum_initial_angular_acceleration():
    # compound pendulum released horizontally: θ̈ = −(m g l/2)/(m l²/3) = −3g/(2l)
    pend = M.simple_pendulum(length=0.8, mass=2.0, bob="rod")
    a, _ = accelerations(pend, 0.0, pend.q0, pend.v0)
    assert abs(a[2] + 1.5 * 9.81 / 0.8) < 1e-10


# ------------------------------------------------------------------------------------------------
# N-link chain
# ------------------------------------------------------------------------------------------------


def test_chain_definition():
    n = 4
    m = M.n_link_chain(n)
    assert m.n_bodies == n and m.n_c == 2 * n
    assert np.allclose(M.chain_tip(m, m.q0), [1.0, 0.0])
    assert np.isclose(sum(b.mass for b in m.bodies), 1.0)
    assert np.allclose([b.inertia for b in m.bodies], (1 / n) * (1 / n) ** 2 / 12)
    ms = M.n_link_chain(n, spatial=True)
    assert ms.n_q == 7 * n and ms.n_c == 5 * n
    assert np.allclose(M.chain_tip(ms, ms.q0), [1.0, 0.0])
    with pytest.raises(ValueError, match="contradict"):
        M.n_link_chain(3, planar=True, spatial=True)
    with pytest.raises(ValueError, match="integer"):
        M.n_link_chain(0)


def test_crank_geometry_recovers_crank_and_rod_lengths():
    """r = |A − O| and l = |B − A| from the joints, at any initial crank angle and for overridden lengths."""
    r, l = M.crank_geometry(M.slider_crank())
    assert r == pytest.approx(0.15, abs=1e-15) and l == pytest.approx(0.30, abs=1e-15)
    r, l = M.crank_geometry(M.slider_crank(crank_angle0=1.1, l1=0.1, l2=0.45, J1=0.01, J2=0.01))
    assert r == pytest.approx(0.1, abs=1e-14) and l == pytest.approx(0.45, abs=1e-14)


def test_chain_reference_matches_single_rod_energy():
    # N = 1 is a compound pendulum; the reference must conserve its energy to ~rtol
    tip, hist = n_link_chain_reference(1, t_end=1.0)
    th, om = hist["theta_1 [rad]"].to_numpy(), hist["omega_1 [rad/s]"].to_numpy()
    E = 0.5 * (1.0 / 3.0) * om**2 + 9.81 * 0.5 * np.sin(th)
    assert np.abs(E - E[0]).max() < 1e-10
    assert np.allclose(tip, [np.cos(th[-1]), np.sin(th[-1])])


def test_chain_planar_and_spatial_agree():
    method = _method("dop853-projection", "dop853", "rk45-projection")
    rtol = 1e-10
    planar, spatial = M.n_link_chain(4), M.n_link_chain(4, spatial=True)
    rp = CI.simulate(planar, (0.0, 0.3), method, rtol=rtol, atol=rtol, n_output=7)
    rs = CI.simulate(spatial, (0.0, 0.3), method, rtol=rtol, atol=rtol, n_output=7)
    assert rp.status == "finished" and rs.status == "finished"
    diff = np.abs(M.chain_tip(planar, rp.q) - M.chain_tip(spatial, rs.q)).max()
    assert diff < 100 * rtol  # both within ~rtol of the same motion
    # and the spatial chain stays in the plane z = 0
    nb = spatial.n_bodies
    assert np.abs(rs.q[:, : nb * 7].reshape(len(rs.t), nb, 7)[:, :, 2]).max() < 100 * rtol


def test_chain_matches_minimal_coordinate_reference():
    method = _method("dop853-projection", "dop853", "rk45-projection")
    rtol = 1e-8
    tip_ref, _ = n_link_chain_reference(2, t_end=1.0)
    m = M.n_link_chain(2)
    r = CI.simulate(m, (0.0, 1.0), method, rtol=rtol, atol=rtol, n_output=2)
    assert r.status == "finished"
    assert np.linalg.norm(M.chain_tip(m, r.q[-1]) - tip_ref) < 100 * rtol


# ------------------------------------------------------------------------------------------------
# bead on a helix (user constraint + extra coordinate)
# ------------------------------------------------------------------------------------------------


def test_body_on_helix_analytic_motion_and_energy():
    method = _method("dop853-projection", "dop853", "rk45-projection")
    R, pitch, s0, sd0 = 0.5, 0.2, 0.3, 2.0
    m = M.body_on_helix(radius=R, pitch=pitch, s0=s0, sdot0=sd0)
    rtol = 1e-10
    r = CI.simulate(m, (0.0, 2.0), method, rtol=rtol, atol=rtol, n_output=21)
    assert r.status == "finished"
    s_exact, sd_exact = M.helix_analytic(r.t, R, pitch, s0, sd0)
    k_s = m.coordinate_names.index("s")
    assert np.abs(r.q[:, k_s] - s_exact).max() < 1e3 * rtol
    c = pitch / (2 * np.pi)
    pos = r.q[:, :3]
    on_helix = np.stack([R * np.cos(r.q[:, k_s]), R * np.sin(r.q[:, k_s]), c * r.q[:, k_s]], 1)
    assert np.abs(pos - on_helix).max() < 1e3 * rtol
    assert np.abs(r.energy - r.energy[0]).max() < 1e3 * rtol * abs(r.energy[0]) + 1e-12
    assert np.abs(r.v[:, 3:6]).max() < 1e3 * rtol  # the bead does not spin


def test_helix_needs_spatial_model():
    from core.model import ModelBuilder

    b = ModelBuilder(2, "bad")
    b.add_body("bead", 1.0, 0.1, (0.5, 0.0))
    b.add_coordinate("s", 0.0)
    b.add_joint(M.HelixConstraint("helix", "bead", "s", 0.5, 0.1))
    with pytest.raises(ValueError, match="helix"):
        b.build()


# ------------------------------------------------------------------------------------------------
# Andrews' squeezing mechanism
# ------------------------------------------------------------------------------------------------


def test_andrews_initial_state_matches_published():
    S = AndrewsSqueezer()
    S.check_sizes()
    assert np.abs(S.Phi(0.0, S.q0)).max() < 1e-14  # published angles are consistent to ~30 digits
    a, lam = accelerations(S, 0.0, S.q0, S.v0)
    ref = S.initial_reference
    assert np.allclose(a, ref["a"], rtol=1e-10, atol=1e-9)
    assert np.allclose(lam, ref["lam"], rtol=1e-10, atol=1e-10)


def test_andrews_derivatives_and_lagrange_consistency():
    S = AndrewsSqueezer()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = S.q0 + 0.3 * rng.standard_normal(7)
        v = 100.0 * rng.standard_normal(7)
        a = 1e4 * rng.standard_normal(7)
        e_jac, e_nu, e_gamma = _derivative_errors(S, 0.0, q, v, a, h=1e-7)
        assert e_jac < 1e-8 and e_nu < 1e-8 and e_gamma < 1e-6 * np.abs(v).max() ** 2 * 0.05
        # the velocity terms of f are Lagrange's: f_v = −Ṁ q̇ + ½ ∂(q̇ᵀ M q̇)/∂q
        h = 1e-6
        Mdot = sum(((S.M(0, q + h * e) - S.M(0, q - h * e)) / (2 * h)) * ve for e, ve in zip(np.eye(7), v))
        dT = np.array([(v @ S.M(0, q + h * e) @ v - v @ S.M(0, q - h * e) @ v) / (4 * h) for e in np.eye(7)])
        f_vel = S.Q(0, q, v) - S.Q(0, q, np.zeros(7))
        assert np.allclose(f_vel, -Mdot @ v + dT, rtol=1e-6, atol=1e-9 * np.abs(f_vel).max())
        assert np.allclose(S.M(0, q), S.M(0, q).T) and np.all(np.linalg.eigvalsh(S.M(0, q)) > 0)


def test_andrews_reaches_published_solution():
    """Test set reference at t = 0.03 s (PSIDE, tol 1e-14): angles to 1e-6 relative."""
    method = _method("dop853-projection", "dop853", "radau-projection")
    S = AndrewsSqueezer()
    ref = S.reference
    r = CI.simulate(S, (0.0, ref["t"]), method, rtol=1e-10, atol=1e-10, n_output=2)
    assert r.status == "finished"
    assert np.allclose(r.q[-1], ref["q"], rtol=1e-6, atol=0.0)
    assert np.allclose(r.v[-1], ref["v"], rtol=1e-5, atol=0.0)
    assert np.allclose(r.lam[-1], ref["lam"], rtol=1e-5, atol=0.0)
    # conserved energy (constant drive torque and spring)
    assert abs(r.energy[-1] - r.energy[0]) < 1e-8 * abs(r.energy[0])


# ------------------------------------------------------------------------------------------------
# car axis
# ------------------------------------------------------------------------------------------------


def test_car_axis_consistency_and_derivatives():
    S = CarAxis()
    S.check_sizes()
    assert np.abs(S.Phi(0.0, S.q0)).max() < 1e-15
    assert np.abs(S.velocity_violation(0.0, S.q0, S.v0)).max() < 1e-15
    rng = np.random.default_rng(4)
    for t in (0.0, 0.13, 1.7):
        q = S.q0 + 0.1 * rng.standard_normal(4)
        v = rng.standard_normal(4)
        a = rng.standard_normal(4)
        e_jac, e_nu, e_gamma = _derivative_errors(S, t, q, v, a)
        assert e_jac < 1e-9 and e_nu < 1e-8 and e_gamma < 1e-7
        Qq = S.Q_q(t, q, v)
        Qq_fd = np.column_stack([(S.Q(t, q + 1e-7 * e, v) - S.Q(t, q - 1e-7 * e, v)) / 2e-7 for e in np.eye(4)])
        assert np.abs(Qq - Qq_fd).max() < 1e-7


def test_car_axis_reaches_published_solution():
    """Test set reference at t = 3 (caraxis.f, subroutine soln)."""
    method = _method("dop853-projection", "radau-projection", "dop853")
    S = CarAxis()
    ref = S.reference
    r = CI.simulate(S, (0.0, ref["t"]), method, rtol=1e-10, atol=1e-10, n_output=2)
    assert r.status == "finished"
    assert np.allclose(r.q[-1], ref["q"], rtol=1e-6, atol=0.0)
    assert np.allclose(r.v[-1], ref["v"], rtol=1e-5, atol=0.0)
    assert np.allclose(r.lam[-1], ref["lam"], rtol=1e-5, atol=0.0)


@pytest.mark.slow
def test_benchmark_problems_independent_of_core_integrators():
    """Plain scipy DOP853 on the index-1 ODE reproduces both references (model, not integrator, check)."""
    for S in (AndrewsSqueezer(), CarAxis()):
        n = S.n_q

        def rhs(t, y, S=S, n=n):
            a, _ = accelerations(S, t, y[:n], y[n:])
            return np.concatenate([y[n:], a])

        sol = solve_ivp(rhs, (0.0, S.reference["t"]), np.concatenate([S.q0, S.v0]), method="DOP853",
                        rtol=1e-11, atol=1e-11)
        assert sol.status == 0
        assert np.allclose(sol.y[:n, -1], S.reference["q"], rtol=1e-6, atol=0.0)


# ------------------------------------------------------------------------------------------------
# stiff (penalty-joint) chain
# ------------------------------------------------------------------------------------------------


def test_stiff_chain_converges_to_rigid_chain_like_one_over_k():
    """Penalty joints: the constraint violation, hence the motion error, is O(1/k) (λ ≈ −k Φ)."""
    method = _method("dop853", "dop853-projection", "rk45")
    tip_ref, _ = n_link_chain_reference(2, t_end=0.3)
    errs = []
    for k in (1e4, 1e5):
        m = M.n_link_chain(2, stiff_k=k)
        assert m.n_c == 0 and m.is_conservative
        r = CI.simulate(m, (0.0, 0.3), method, rtol=1e-9, atol=1e-9, n_output=4)
        assert r.status == "finished"
        assert np.abs(r.energy - r.energy[0]).max() < 1e-6
        errs.append(np.linalg.norm(M.chain_tip(m, r.q[-1]) - tip_ref))
    assert 5.0 < errs[0] / errs[1] < 20.0  # ten times stiffer -> about ten times closer
    ms = M.n_link_chain(2, stiff_k=1e4, spatial=True)
    rs = CI.simulate(ms, (0.0, 0.3), method, rtol=1e-9, atol=1e-9, n_output=4)
    m = M.n_link_chain(2, stiff_k=1e4)
    rp = CI.simulate(m, (0.0, 0.3), method, rtol=1e-9, atol=1e-9, n_output=4)
    assert np.abs(M.chain_tip(ms, rs.q) - M.chain_tip(m, rp.q)).max() < 1e-6


# ------------------------------------------------------------------------------------------------
# bouncing ball
# ------------------------------------------------------------------------------------------------


def _rebound_height(model, h0, r, g, method, rtol):
    """Apex height of the first rebound from the ballistic state just after the impact."""
    t_drop = np.sqrt(2 * h0 / g)
    res = CI.simulate(model, (0.0, t_drop + 0.05), method, rtol=rtol, atol=rtol, n_output=2)
    # through the stiff contact the energy error is above 3 rtol (the check flags it for e = 1); the
    # height is compared below with its own tolerance
    assert res.status == "finished" or all(w.startswith("energy drift") for w in res.warnings), res.message
    y, vy = res.q[-1, 1] - r, res.v[-1, 1]
    assert y > 0 and vy > 0  # out of contact, going up
    return y + vy * vy / (2 * g)


def _rebound_height_1d(h0, r, g, K, p, e, m=1.0):
    """Independent 1-D integration of m ÿ = −m g + max(0, K δ^p (1 + χ δ̇/v0)), χ = 3(1 − e²)/4."""
    v0 = np.sqrt(2 * g * h0)
    chi = 0.75 * (1 - e * e)

    def rhs(t, s):
        delta, ddelta = r - s[0], -s[1]
        F = max(0.0, K * delta**p * (1 + chi * ddelta / v0)) if delta > 0 else 0.0
        return [s[1], -g + F / m]

    t_end = np.sqrt(2 * h0 / g) + 0.05
    sol = solve_ivp(rhs, (0.0, t_end), [h0 + r, 0.0], method="DOP853", rtol=1e-12, atol=1e-12, max_step=1e-4)
    y, vy = sol.y[0, -1] - r, sol.y[1, -1]
    return y + vy * vy / (2 * g)


def test_bouncing_ball_rebound_height():
    method = _method("dop853", "dop853-projection", "rk45")
    h0, r, g, K = 1.0, 0.1, 9.81, 1e7
    rtol = 1e-9
    # e = 1: no dissipation, the ball returns to its drop height (energy conserved)
    h = _rebound_height(M.bouncing_ball(radius=r, height0=h0, restitution=1.0, stiffness=K), h0, r, g, method, rtol)
    assert abs(h - h0) < 1e-5
    rel = {}
    for e in (0.99, 0.95):
        model = M.bouncing_ball(radius=r, height0=h0, restitution=e, stiffness=K)
        h = _rebound_height(model, h0, r, g, method, rtol)
        # the model realises its contact law exactly (independent 1-D integration)
        assert abs(h - _rebound_height_1d(h0, r, g, K, 1.5, e)) < 1e-5
        rel[e] = abs(h - e * e * h0) / (e * e * h0)
    # Lankarani–Nikravesh is exact to first order in (1 − e²): the error in e² h0 vanishes faster
    # than (1 − e) (second order), and is small for e close to 1
    assert rel[0.99] < rel[0.95] * (0.01 / 0.05) ** 1.5
    assert all(rel[e] < 10 * (1 - e) ** 2 for e in rel)
    with pytest.raises(ValueError, match="restitution"):
        M.bouncing_ball(restitution=0.0)
