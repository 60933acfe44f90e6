"""Suspension force elements of core: :class:`core.forces.BumpStop` and :class:`core.forces.SeriesSpringDamper`.

Tier 2 (properties) and tier 1 (closed forms):

* bump stop: ``Q_q``/``Q_v`` against central differences at random poses with the deflection placed
  inside the clearance, on each segment of the table on each side, beyond the last row, and on the
  inactive side of one-sided stops; its force–deflection curve against the table (the Manchester
  benchmark vehicle's lateral stop, an independent ``np.interp`` of the table); the direction of
  the force (it resists the deflection, along the axis fixed to body i); damping only while
  engaged; a mass bouncing between two undamped linear stops: period
  ``T = 4 g/v + 2π √(m/k)`` and energy, on the numpy and compiled integrators;
* series spring-damper (Maxwell element): the signs of the generalized forces against the virtual
  work; the dynamic stiffness of the linearised model against ``k* = k_s (iωc − m_n ω²)/(k_s +
  iωc − m_n ω²)`` (round-off) and against the massless-node Maxwell form ``k_s iωτ/(1 + iωτ)``
  within the bound the node mass implies; a very stiff k_s behaves like the plain damper and a very
  large c like the plain spring (jit-radau runs, bounds derived from τ = c/k_s); a forced
  oscillation started on its steady state stays on it (jit-radau and the numpy Radau); the
  stiffness of the node (explicit methods report it, jit-radau does not);
* bad input raises :class:`core.errors.ModelError` naming the element.

The Jacobian tolerances are those of ``tests/core/test_elements.py`` (central differences, step
1e-6: truncation O(h²), round-off O(ε/h)).
"""

from __future__ import annotations

import numpy as np
import pytest

from core import drivers, frames
from core.analysis import linearize
from core.errors import ModelError
from core.integrators import simulate
from core.model import ModelBuilder

EPS = 1e-6  # finite-difference step
RTOL = 1e-6  # relative tolerance of the finite-difference comparisons

#: Lateral bump stop between bogie frame and car body of the Manchester benchmark vehicle 1
#: (S. Iwnicki (ed.), "The Manchester benchmarks for rail vehicle simulation", Vehicle System
#: Dynamics 30(3–4) (1998) 295–313; values as transcribed in the task brief of this element):
#: clearance 25 mm, total displacement [mm] and force [N].
MANCHESTER_STOP_MM = np.array([25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0, 65.0])
MANCHESTER_STOP_N = np.array([0.0, 600.0, 1760.0, 3730.0, 6870.0, 11580.0, 17170.0, 29200.0, 230000.0])
MANCHESTER_TABLE = np.column_stack([MANCHESTER_STOP_MM * 1e-3, MANCHESTER_STOP_N])


def _close(actual, expected, rtol=RTOL, what=""):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    scale = max(1.0, float(np.max(np.abs(expected))))
    err = float(np.max(np.abs(actual - expected)))
    assert err <= rtol * scale, f"{what}: max error {err:.3e} > {rtol:g} × {scale:.3g}"


def _unit(rng, d=3):
    x = rng.standard_normal(d)
    return x / np.linalg.norm(x)


def _random_body(b, rng, name):
    if b.space.dim == 2:
        return b.add_body(name, rng.uniform(0.5, 2.0), rng.uniform(0.05, 0.3), rng.uniform(-1, 1, 2),
                          orientation=rng.uniform(-np.pi, np.pi))
    J = np.diag(rng.uniform(0.1, 0.2, 3))
    R = frames.euler_to_matrix(frames.axis_angle_to_euler(_unit(rng), rng.uniform(0, np.pi)))
    return b.add_body(name, rng.uniform(0.5, 2.0), R @ J @ R.T, rng.uniform(-1, 1, 3),
                      orientation=frames.axis_angle_to_euler(_unit(rng), rng.uniform(-np.pi, np.pi)))


def _fd_Q(m, t, q, v):
    I = np.eye(m.n_v)
    Qq = np.array([(m.Q(t, m.retract(q, EPS * e), v) - m.Q(t, m.retract(q, -EPS * e), v)) / (2 * EPS) for e in I]).T
    Qv = np.array([(m.Q(t, q, v + EPS * e) - m.Q(t, q, v - EPS * e)) / (2 * EPS) for e in I]).T
    return Qq, Qv


def _interp_table(table, s):
    """Independent evaluation of the tabulated magnitude g(s) (np.interp, last slope beyond)."""
    d, f = table[:, 0], table[:, 1]
    slope = (f[-1] - f[-2]) / (d[-1] - d[-2])
    g = np.interp(s, d, f, left=0.0)
    return np.where(s > d[-1], f[-1] + slope * (s - d[-1]), g)


# ============================================================================================
# bump stop
# ============================================================================================

TABLE = np.array([[0.01, 0.0], [0.02, 40.0], [0.04, 100.0], [0.07, 400.0]])


def _bump_stop_model(dim, seed, sides="both", damping=3.0, ground=False):
    rng = np.random.default_rng(seed)
    b = ModelBuilder(dim, f"bump-stop-{dim}d")
    _random_body(b, rng, "a")
    _random_body(b, rng, "b")
    at = rng.uniform(-1, 1, dim)
    b.add_bump_stop("stop", "ground" if ground else "a", "b", at, _unit(rng, dim), TABLE, damping=damping,
                    sides=sides, point_j=at + 0.2 * rng.standard_normal(dim))
    return b.build()


def _state_with_deflection(m, seed, u_target):
    """A random perturbed state (poses, velocities) with body b shifted along the stop axis so that
    the deflection is exactly ``u_target`` (a translation of body j changes u by its axial part)."""
    rng = np.random.default_rng(seed + 500)
    q = m.retract(m.q0, 0.1 * rng.standard_normal(m.n_v))
    v = rng.standard_normal(m.n_v)
    fk = m.force_kinds[0]
    bs = m.body_states(q, v)
    u = fk.outputs(bs, 0.0)["u [m]"][0]
    e = bs.A[fk.bi[0]] @ fk.ei[0]
    q = q.copy()
    k0 = m.q_slice("b").start
    q[k0: k0 + m.space.dim] += (u_target - u) * e
    bs = m.body_states(q, v)
    assert abs(fk.outputs(bs, 0.0)["u [m]"][0] - u_target) < 1e-12
    return q, v


# deflections: inside the clearance, each segment on both sides, beyond the last row (all ≥ 2 mm
# from a table row, far beyond the FD step)
DEFLECTIONS = [0.0, 0.004, -0.007, 0.015, -0.015, 0.03, -0.033, 0.05, -0.06, 0.09, -0.1]


@pytest.mark.parametrize("ground", [False, True])
@pytest.mark.parametrize("sides", ["both", "positive", "negative"])
@pytest.mark.parametrize("dim", [2, 3])
def test_bump_stop_jacobians_against_finite_differences(dim, sides, ground):
    m = _bump_stop_model(dim, seed=dim + len(sides), sides=sides, ground=ground)
    fk = m.force_kinds[0]
    seen = set()
    for k, u in enumerate(DEFLECTIONS):
        q, v = _state_with_deflection(m, k, u)
        out = fk.outputs(m.body_states(q, v), 0.2)
        seen.add(bool(out["engaged"][0]))
        Qq, Qv = m.Q_jacobians(0.2, q, v)
        Qq_fd, Qv_fd = _fd_Q(m, 0.2, q, v)
        _close(Qq.toarray(), Qq_fd, what=f"bump stop u = {u}: Q_q")
        _close(Qv.toarray(), Qv_fd, what=f"bump stop u = {u}: Q_v")
    assert seen == {True, False}


@pytest.mark.parametrize("dim", [2, 3])
def test_bump_stop_potential_and_conservative(dim):
    """Undamped: ``Q = −∂V/∂q`` (central differences of the energy at v = 0, no gravity) on every
    segment; the model reports itself conservative."""
    rng = np.random.default_rng(4)
    b = ModelBuilder(dim, "stop-potential", gravity=np.zeros(dim))
    _random_body(b, rng, "a")
    _random_body(b, rng, "b")
    at = rng.uniform(-1, 1, dim)
    b.add_bump_stop("stop", "a", "b", at, _unit(rng, dim), TABLE)
    m = b.build()
    assert m.is_conservative
    z = np.zeros(m.n_v)
    for k, u in enumerate(DEFLECTIONS):
        q, _ = _state_with_deflection(m, k, u)
        grad = np.array([(m.energy(0.0, m.retract(q, EPS * e), z) - m.energy(0.0, m.retract(q, -EPS * e), z)) / (2 * EPS)
                         for e in np.eye(m.n_v)])
        _close(m.Q(0.0, q, z), -grad, what=f"u = {u}: Q vs −dV/dq")


def _stop_on_ground(sides="both", damping=0.0, table=MANCHESTER_TABLE, axis=(0.0, 1.0)):
    """Body 'body' at the origin, the stop between the ground (body i, axis fixed to the ground) and it."""
    d = len(axis)
    b = ModelBuilder(d, "stop", gravity=np.zeros(d))
    b.add_body("body", 1000.0, 100.0 if d == 2 else [100.0, 100.0, 100.0], np.zeros(d))
    b.add_bump_stop("lateral stop", "ground", "body", np.zeros(d), axis, table, damping=damping, sides=sides)
    return b.build()


def test_bump_stop_force_deflection_matches_the_manchester_table():
    """Force on the car body displaced by u along the stop axis: ``−σ(u) g(|u|) e`` with g the table
    interpolated linearly (0 within the 25 mm clearance, the last slope beyond 65 mm), at every
    table row, between rows, inside the clearance and beyond, on both sides."""
    u = np.concatenate([MANCHESTER_TABLE[:, 0], 0.5 * (MANCHESTER_TABLE[1:, 0] + MANCHESTER_TABLE[:-1, 0]),
                        [0.0, 0.01, 0.0249, 0.07, 0.08]])
    u = np.concatenate([u, -u])
    expected = np.sign(u) * _interp_table(MANCHESTER_TABLE, np.abs(u))
    m = _stop_on_ground()
    z = np.zeros(m.n_v)
    F = []
    for uk in u:
        q = m.q0.copy()
        q[1] = uk
        F.append(m.Q(0.0, q, z)[1])
        out = m.force_kinds[0].outputs(m.body_states(q, z), 0.0)
        assert out["u [m]"][0] == pytest.approx(uk, abs=1e-15)
        assert out["F [N]"][0] == pytest.approx(-F[-1], rel=1e-14, abs=1e-9)
        assert out["engaged"][0] == float(abs(uk) > 0.025)
    np.testing.assert_allclose(F, -expected, rtol=1e-12, atol=1e-9)
    # published points: 3730 N at 40 mm; 65 mm: 230 kN; 70 mm: the last slope (40.16 kN/mm) continued
    q = m.q0.copy()
    q[1] = -0.040
    assert m.Q(0.0, q, z)[1] == pytest.approx(3730.0, rel=1e-12)
    q[1] = 0.070
    assert m.Q(0.0, q, z)[1] == pytest.approx(-(230000.0 + (230000.0 - 29200.0)), rel=1e-12)
    # no lateral or rotational components
    assert np.all(m.Q(0.0, q, z)[[0, 2]] == 0.0)


@pytest.mark.parametrize("sides,active", [("positive", 1.0), ("negative", -1.0)])
def test_one_sided_stop_acts_on_its_side_only(sides, active):
    m = _stop_on_ground(sides=sides)
    z = np.zeros(m.n_v)
    for u in (0.03, 0.05, 0.07, -0.03, -0.05, -0.07):
        q = m.q0.copy()
        q[1] = u
        expected = -np.sign(u) * _interp_table(MANCHESTER_TABLE, abs(u)) if np.sign(u) == active else 0.0
        assert m.Q(0.0, q, z)[1] == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_bump_stop_resists_along_the_axis_fixed_to_body_i():
    """Spatial: body i turned by 40° about z carries the stop axis along; moving body j by u along
    the turned axis gives ``−f e`` on j and ``+f e`` on i (the pair pushes apart when the gap of the
    positive side closes), and a displacement across the axis gives no force."""
    b = ModelBuilder(3, "turned", gravity=(0.0, 0.0, 0.0))
    rot = frames.axis_angle_to_euler([0.0, 0.0, 1.0], np.radians(40.0))
    b.add_body("frame", 500.0, [50.0, 50.0, 50.0], (0.0, 0.0, 0.0), orientation=rot)
    b.add_body("body", 1000.0, [100.0, 100.0, 100.0], (0.0, 0.0, 0.0))
    e_global = frames.euler_to_matrix(rot) @ np.array([0.0, 1.0, 0.0])
    b.add_bump_stop("stop", "frame", "body", (0.0, 0.0, 0.0), e_global, MANCHESTER_TABLE)
    m = b.build()
    z = np.zeros(m.n_v)
    u = 0.045
    q = m.q0.copy()
    q[7:10] = u * e_global
    Q = m.Q(0.0, q, z)
    f = 6870.0
    np.testing.assert_allclose(Q[6:9], -f * e_global, rtol=1e-12)
    np.testing.assert_allclose(Q[0:3], f * e_global, rtol=1e-12)
    np.testing.assert_allclose(Q[3:6], 0.0, atol=1e-9)  # P and Q at the centres of mass
    q[7:10] = 0.05 * np.cross(e_global, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(m.Q(0.0, q, z), 0.0, atol=1e-12)


def test_bump_stop_damping_only_while_engaged():
    c = 2.0e4
    m = _stop_on_ground(damping=c)
    for u, ud in ((0.02, 0.3), (-0.02, -0.3), (0.03, 0.3), (0.03, -0.3), (-0.045, 0.2)):
        q, v = m.q0.copy(), np.zeros(m.n_v)
        q[1], v[1] = u, ud
        engaged = abs(u) > 0.025
        f = np.sign(u) * _interp_table(MANCHESTER_TABLE, abs(u)) + (c * ud if engaged else 0.0)
        assert m.Q(0.0, q, v)[1] == pytest.approx(-f, rel=1e-12, abs=1e-9)
        assert not m.is_conservative


def _bouncing_mass(two_elements, g=0.02, k=1.0e4, m=2.0, v=0.5):
    """A mass on a frictionless plane between two linear stops with clearance g (stiffness k)."""
    b = ModelBuilder(2, "bouncing", gravity=(0.0, 0.0))
    b.add_body("mass", m, 0.1, (0.0, 0.0), velocity=(v, 0.0))
    table = [[g, 0.0], [g + 0.01, k * 0.01]]
    if two_elements:
        b.add_bump_stop("right", "ground", "mass", (0.0, 0.0), (1.0, 0.0), table, sides="positive")
        b.add_bump_stop("left", "ground", "mass", (0.0, 0.0), (1.0, 0.0), table, sides="negative")
    else:
        b.add_bump_stop("both", "ground", "mass", (0.0, 0.0), (1.0, 0.0), table)
    return b.build()


@pytest.mark.parametrize("method,two", [("dop853", False), ("jit-dop853", True), ("jit-rk45", False),
                                        ("jit-radau", True)])
def test_mass_between_two_undamped_stops_period_and_energy(method, two):
    r"""Period of a mass m (speed v) between two linear stops of stiffness k with clearance g: it
    flies g/v to the right stop, stays in contact half an oscillation π√(m/k) (a linear spring
    returns it with the speed reversed), flies 2g/v to the left one, again π√(m/k), and g/v back:

    .. math::  T = 4 g / v + 2 π \sqrt{m / k}.

    The upward zero crossings of x lie in free flight (x linear in t), so linear interpolation of
    the output locates them exactly.  The force's slope jumps at the clearance, which degrades the
    local error estimates of every method there: the measured errors (energy and period) are
    10–1000 × rtol; the test asks for less than 1e3 × rtol at rtol = 1e-7 and 1e-10, and for an energy
    error at least 10× smaller at the tighter tolerance."""
    g, k, mass, v = 0.02, 1.0e4, 2.0, 0.5
    model = _bouncing_mass(two, g, k, mass, v)
    assert model.is_conservative
    T = 4 * g / v + 2 * np.pi * np.sqrt(mass / k)
    t = np.linspace(0.0, 3.2 * T, 161)  # spacing 0.005 s < the 0.08 s of free flight around x = 0
    errors = []
    for rtol in (1e-7, 1e-10):
        res = simulate(model, (0.0, t[-1]), method, t_eval=t, rtol=rtol, atol=1e-2 * rtol, compute_multipliers=False)
        assert res.status.startswith("finished"), res.message
        x = res.q[:, 0]
        i = np.flatnonzero((x[:-1] < 0.0) & (x[1:] >= 0.0))
        tc = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
        assert len(tc) == 3
        E0 = 0.5 * mass * v**2
        errors.append((np.max(np.abs(np.diff(tc) / T - 1.0)), np.max(np.abs(res.energy - E0)) / E0))
    for (p, e), rtol in zip(errors, (1e-7, 1e-10)):
        assert p < 1e3 * rtol and e < 1e3 * rtol, errors
    assert errors[1][1] < errors[0][1] / 10, errors  # the energy error falls with the tolerance


# ============================================================================================
# series spring-damper (Maxwell element)
# ============================================================================================


def _maxwell_model(M, ks, c, mn, v0=0.0, L=1.0, parallel=0.0, force=None, name="maxwell"):
    """Body 'car' (mass M) at x = L on a frictionless plane, the element from the ground at the
    origin to it along x, optionally a parallel spring and a harmonic force ``F0 sin ωt``."""
    b = ModelBuilder(2, name, gravity=(0.0, 0.0))
    b.add_body("car", M, 1.0, (L, 0.0), velocity=(v0, 0.0))
    b.add_series_spring_damper("damper", "ground", "car", (0.0, 0.0), (L, 0.0), ks, c, mn)
    if parallel:
        b.add_spring_damper("spring", "ground", "car", (0.0, 0.0), (L, 0.0), parallel)
    if force is not None:
        F0, w = force
        b.add_applied_force("push", "car", (L, 0.0), [drivers.harmonic(F0, w), 0.0])
    return b.build()


def test_series_spring_damper_forces_follow_the_virtual_work():
    """Stretched by δ with the node moving at ẋ: F_s = k_s (ℓ − x − ℓ_s0) = k_s(δ − Δx) pulls the car
    back (−F_s along PQ), the node gets F_s − c ẋ, the ground nothing to integrate; the node is the
    extra coordinate 'damper.node' with the given mass, initially half-way."""
    ks, c, mn = 5.0e6, 3.0e5, 5.0
    m = _maxwell_model(1000.0, ks, c, mn, L=2.0)
    assert m.extra_names == ["damper.node"]
    assert m.q0[-1] == pytest.approx(1.0) and m.M(0.0, m.q0).toarray()[-1, -1] == mn
    q, v = m.q0.copy(), np.zeros(m.n_v)
    q[0] += 0.004  # stretch δ = 4 mm
    q[-1] += 0.001  # node moved 1 mm towards Q
    v[-1] = 0.02
    Fs = ks * (0.004 - 0.001)
    Q = m.Q(0.0, q, v)
    np.testing.assert_allclose(Q, [-Fs, 0.0, 0.0, Fs - c * 0.02], rtol=1e-12, atol=1e-9)
    out = m.force_kinds[0].outputs(m.body_states(q, v), 0.0)
    assert out["spring force [N]"][0] == pytest.approx(Fs) and out["damper force [N]"][0] == pytest.approx(c * 0.02)
    # free length given: relaxed at ℓ = L_f with the node at its initial position
    b = ModelBuilder(2, "preloaded", gravity=(0.0, 0.0))
    b.add_body("car", 1.0, 1.0, (2.0, 0.0))
    b.add_series_spring_damper("d", "ground", "car", (0.0, 0.0), (2.0, 0.0), 100.0, 1.0, 0.1, free_length=2.5,
                               node_position=0.3)
    m2 = b.build()
    assert m2.q0[-1] == 0.3
    np.testing.assert_allclose(m2.Q(0.0, m2.q0, np.zeros(4)), [50.0, 0.0, 0.0, -50.0], rtol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_series_spring_damper_jacobian_at_random_states(dim):
    """Q_q, Q_v (bodies and node, couplings through ForceJacobian.entries) against central
    differences at random poses with the node off its rest position and moving."""
    for seed in range(3):
        rng = np.random.default_rng(seed)
        b = ModelBuilder(dim, "maxwell-fd")
        _random_body(b, rng, "a")
        _random_body(b, rng, "b")
        at = rng.uniform(-1, 1, dim)
        b.add_series_spring_damper("yaw", "a", "b", at, at + rng.uniform(0.3, 1.0, dim), 300.0, 7.0, 0.1)
        b.add_series_spring_damper("yaw-ground", "ground", "b", at, at + rng.uniform(0.3, 1.0, dim), 200.0, 2.0, 0.1,
                                   free_length=1.5)
        m = b.build()
        q = m.retract(m.q0, 0.1 * rng.standard_normal(m.n_v))
        v = rng.standard_normal(m.n_v)
        Qq, Qv = m.Q_jacobians(0.0, q, v)
        Qq_fd, Qv_fd = _fd_Q(m, 0.0, q, v)
        _close(Qq.toarray(), Qq_fd, what="series: Q_q")
        _close(Qv.toarray(), Qv_fd, what="series: Q_v")


def _dynamic_stiffness(model, omega):
    """k*(ω) between ground and car along x from the linearised model: the dynamic stiffness matrix
    ``Z = K + iω(D + G) − ω² M`` condensed to the car's x (node eliminated), the car's own inertia
    removed."""
    lin = linearize(model)
    N = lin.N
    Z = N @ (lin.K + 1j * omega * (lin.D + lin.G) - omega**2 * lin.M) @ N.T  # model velocity coordinates
    i, n = 0, model.n_v - 1  # car x, node
    k = Z[i, i] - Z[i, n] * Z[n, i] / Z[n, n]
    return k + omega**2 * model.M(0.0, model.q0).toarray()[i, i]


def test_series_dynamic_stiffness_matches_the_maxwell_closed_form():
    r"""The linearised model (core.analysis.linearize, i.e. the analytic Jacobians) gives
    ``k* = k_s (iωc − m_n ω²)/(k_s + iωc − m_n ω²)`` to round-off.  Against the massless-node
    Maxwell form ``k_M = k_s iωτ/(1 + iωτ)``: ``k*/k_M = (1 + iε₁)/(1 − ε₂)`` with
    ``ε₁ = m_n ω/c`` and ``ε₂ = m_n ω²/(k_s + iωc)``; since ``iε₁ + ε₂ = iε₁/(1 + iωτ)``,
    ``|k*/k_M − 1| = ε₁/(√(1 + ω²τ²) |1 − ε₂|) ≤ ε₁/(√(1 + ω²τ²)(1 − |ε₂|))``, which the test
    asserts (and that it is sharp to a factor 2).  Yaw damper of a bogie: c = 300 kN s/m,
    k_s = 5 MN/m (τ = 60 ms), m_n = 5 kg."""
    ks, c, mn = 5.0e6, 3.0e5, 5.0
    tau = c / ks
    model = _maxwell_model(2000.0, ks, c, mn)
    for omega in (0.1 / tau, 1.0 / tau, 10.0 / tau, 2 * np.pi * 8.0):
        k = _dynamic_stiffness(model, omega)
        exact = ks * (1j * omega * c - mn * omega**2) / (ks + 1j * omega * c - mn * omega**2)
        assert abs(k - exact) <= 1e-9 * abs(exact)
        maxwell = ks * 1j * omega * tau / (1 + 1j * omega * tau)
        e1, e2 = mn * omega / c, abs(mn * omega**2 / (ks + 1j * omega * c))
        bound = e1 / (np.sqrt(1 + (omega * tau) ** 2) * (1 - e2))
        assert bound / 2 <= abs(k / maxwell - 1.0) <= bound
    # the limits: k_s → ∞ a damper (k_M/(iωc) − 1 = −iωτ/(1 + iωτ), below ωτ), c → ∞ a spring
    # (k_M/k_s − 1 = −1/(1 + iωτ), below 1/(ωτ)); the node mass adds the bound above
    omega = 20.0
    for ks_, c_, limit, rel in ((5.0e9, 3.0e5, 1j * omega * 3.0e5, omega * 3.0e5 / 5.0e9),
                                (5.0e6, 3.0e9, 5.0e6, 5.0e6 / (omega * 3.0e9))):
        k = _dynamic_stiffness(_maxwell_model(2000.0, ks_, c_, mn), omega)
        e1, e2 = mn * omega / c_, abs(mn * omega**2 / (ks_ + 1j * omega * c_))
        assert abs(k / limit - 1.0) <= rel + (e1 + e2) / (1 - e2)


def test_very_stiff_series_spring_is_a_damper():
    r"""k_s = 10 MN/m, c = 100 N s/m (τ = 10 µs), car M = 10 kg moving at v₀ = 1 m/s, spring relaxed:
    a plain damper gives ``v = v₀ e^{−ct/M}``.  With the node massless the car obeys
    ``Mτ v̈ + M v̇ + c v = 0``, ``v(0) = v₀``, ``v̇(0) = 0``: the slow mode has amplitude
    ``v₀ s₂/(s₂ − s₁) = v₀(1 + cτ/M + …)`` and rate ``s₁ = −(c/M)(1 + cτ/M + …)``, so
    ``|v − v₀e^{−ct/M}| ≤ v₀ (cτ/M)(1 + 1/e) + O((cτ/M)²)``; the node mass m_n = 0.1 g adds
    ``m_n/M = 1e-5`` of the momentum.  Bound asserted: ``2 v₀ cτ/M`` (= 2e-4 m/s), and for x its
    time integral."""
    M, ks, c, mn, v0 = 10.0, 1.0e7, 100.0, 1.0e-4, 1.0
    tau = c / ks
    model = _maxwell_model(M, ks, c, mn, v0=v0)
    t = np.linspace(0.0, 0.3, 16)
    # atol 1e-10: the node rate follows the positions with gain 1/τ = 1e5 1/s, so its round-off is
    # ≈ ε ℓ/τ ≈ 2e-11 m/s; tolerances below that cannot be met (see SeriesSpringDamper)
    res = simulate(model, (0.0, 0.3), "jit-radau", t_eval=t, rtol=1e-8, atol=1e-10, compute_multipliers=False)
    assert res.status == "finished", res.message
    bound = 2 * v0 * c * tau / M
    assert np.max(np.abs(res.v[:, 0] - v0 * np.exp(-c * t / M))) <= bound
    x_ref = 1.0 + M * v0 / c * (1.0 - np.exp(-c * t / M))
    assert np.max(np.abs(res.q[:, 0] - x_ref)) <= bound * t[-1]
    assert np.max(np.abs(res.v[:, 0] - v0 * np.exp(-c * t / M))) > bound / 20  # the bound is not vacuous


def test_very_large_series_damping_is_a_spring():
    r"""c = 1e8 N s/m, k_s = 10 kN/m (τ = 1e4 s), car M = 10 kg launched at v₀ = 0.1 m/s: a plain
    spring gives ``x = L + (v₀/ω) sin ωt``, ``ω = √(k_s/M)``.  The Maxwell element's loss
    ``Im k*/Re k* ≈ 1/(ωτ)`` damps the amplitude A = v₀/ω by ``A t/(2τ)`` over t and the node creeps
    by ``≲ A/(ωτ)``; bound: ``A (t/(2τ) + 2/(ωτ))`` plus 10 rtol of the coordinate."""
    M, ks, c, mn, v0 = 10.0, 1.0e4, 1.0e8, 1.0, 0.1
    tau, omega = c / ks, np.sqrt(ks / M)
    A = v0 / omega
    model = _maxwell_model(M, ks, c, mn, v0=v0)
    t = np.linspace(0.0, 1.0, 41)
    res = simulate(model, (0.0, 1.0), "jit-radau", t_eval=t, rtol=1e-9, atol=1e-11, compute_multipliers=False)
    assert res.status == "finished", res.message
    err = np.max(np.abs(res.q[:, 0] - (1.0 + A * np.sin(omega * t))))
    assert err <= A * (t[-1] / (2 * tau) + 2 / (omega * tau)) + 10 * 1e-9


@pytest.mark.parametrize("method", ["jit-radau", "radau-ggl"])
def test_forced_oscillation_stays_on_its_steady_state(method):
    r"""Car M on a parallel spring k_p and the yaw-damper element, pushed by ``F₀ sin ωt`` at ω = 2π·3
    rad/s (ωτ ≈ 1.1).  The model is linear along PQ, so started on its steady state
    ``y = Im(Y e^{iωt})``, ``Y = F₀/(k_p + k*(ω) − Mω²)``, node ``Ξ = k_s Y/(k_s + iωc − m_n ω²)``, it
    stays there: the car and the node follow it over two periods to the integration tolerance
    (10 rtol of the 1 m coordinate), and the transmitted spring force ``k_s (y − ξ)`` is
    ``k*(ω)`` times y."""
    M, kp, ks, c, mn, F0 = 2000.0, 1.0e6, 5.0e6, 3.0e5, 5.0, 1.0e3
    omega = 2 * np.pi * 3.0
    model = _maxwell_model(M, ks, c, mn, parallel=kp, force=(F0, omega), name="forced")
    kstar = ks * (1j * omega * c - mn * omega**2) / (ks + 1j * omega * c - mn * omega**2)
    Y = F0 / (kp + kstar - M * omega**2)
    Xi = ks * Y / (ks + 1j * omega * c - mn * omega**2)
    q0, v0 = model.q0.copy(), model.v0.copy()
    q0[0] += Y.imag
    v0[0] = omega * Y.real
    q0[-1] += Xi.imag
    v0[-1] = omega * Xi.real
    period = 2 * np.pi / omega
    t = np.linspace(0.0, 2 * period, 25)
    rtol = 1e-8
    res = simulate(model, (0.0, t[-1]), method, t_eval=t, q0=q0, v0=v0, rtol=rtol, atol=1e-2 * rtol,
                   compute_multipliers=False)
    assert res.status == "finished", res.message
    y, xi = (Y * np.exp(1j * omega * t)).imag, (Xi * np.exp(1j * omega * t)).imag
    assert np.max(np.abs(res.q[:, 0] - 1.0 - y)) <= 10 * rtol
    assert np.max(np.abs(res.q[:, -1] - model.q0[-1] - xi)) <= 10 * rtol
    Fs = np.array([model.force_kinds[0].outputs(model.body_states(q, v), tt)["spring force [N]"][0]
                   for tt, q, v in zip(t, res.q, res.v)])
    assert np.max(np.abs(Fs - (kstar * Y * np.exp(1j * omega * t)).imag)) <= 10 * rtol * ks


@pytest.mark.parametrize("explicit_method,boundary", [("jit-rk45", 3.3), ("jit-dop853", 6.1)])
def test_series_node_makes_the_model_stiff(explicit_method, boundary):
    """Yaw damper (c = 300 kN s/m, m_n = 5 kg: node eigenvalue ≈ −c/m_n = −6e4 1/s): the explicit
    methods report the stiffness and need about ``t |λ| / β`` steps (β the method's stability
    boundary on the negative real axis: 3.3 Dormand–Prince 5(4), 6.1 DOP853), jit-radau takes
    steps set by accuracy alone and several times fewer of them; the end states agree."""
    model = _maxwell_model(2000.0, 5.0e6, 3.0e5, 5.0, v0=0.1)
    kw = dict(t_eval=[0.05], rtol=1e-6, atol=1e-8, compute_multipliers=False)
    explicit = simulate(model, (0.0, 0.05), explicit_method, **kw)
    implicit = simulate(model, (0.0, 0.05), "jit-radau", **kw)
    assert explicit.status == "finished with warnings" and "stiff" in explicit.warnings[0]
    assert implicit.status == "finished" and "stiff" not in implicit.message
    assert explicit.counters["n_steps"] >= 0.8 * 0.05 * 6e4 / boundary  # the stability bound h ≲ β/|λ|
    assert implicit.counters["n_steps"] * 5 < explicit.counters["n_steps"]
    np.testing.assert_allclose(implicit.q[-1], explicit.q[-1], atol=1e-6)


# ============================================================================================
# bad input
# ============================================================================================


def _builder():
    b = ModelBuilder(2, "bad", gravity=(0.0, 0.0))
    b.add_body("a", 1.0, 0.1, (0.0, 0.0))
    b.add_body("b", 1.0, 0.1, (1.0, 0.0))
    return b


@pytest.mark.parametrize("kwargs,match", [
    (dict(table=[[0.01, 0.0]]), "shape"),
    (dict(table=[0.01, 0.0, 0.02, 10.0]), "shape"),
    (dict(table=[[0.01, 0.0], [0.02, np.nan]]), "row 1 is not finite"),
    (dict(table=[[0.01, 5.0], [0.02, 10.0]]), "force 0"),
    (dict(table=[[-0.01, 0.0], [0.02, 10.0]]), "clearance.*≥ 0"),
    (dict(table=[[0.01, 0.0], [0.03, 10.0], [0.02, 20.0]]), "increase strictly"),
    (dict(table=[[0.01, 0.0], [0.02, 10.0], [0.02, 20.0]]), "increase strictly"),
    (dict(table=[[0.01, 0.0], [0.02, 10.0], [0.03, 5.0]]), "must not decrease"),
    (dict(table="stiff"), "table must"),
    (dict(sides="left"), "sides must be one of"),
    (dict(damping=-1.0), "damping must be a finite number ≥ 0"),
    (dict(axis=(0.0, 0.0)), "axis must be 2 finite numbers"),
    (dict(axis=(1.0, 0.0, 0.0)), "axis must be 2 finite numbers"),
    (dict(at=(0.0, np.inf)), "'at' and 'point_j' must be 2 finite numbers"),
    (dict(body_j="a"), "connects body 'a' to itself"),
    (dict(body_j="c"), "unknown body 'c'"),
])
def test_bump_stop_bad_input_names_the_element(kwargs, match):
    args = dict(name="stop 7", body_i="a", body_j="b", at=(0.5, 0.0), axis=(1.0, 0.0),
                table=[[0.01, 0.0], [0.02, 10.0]])
    args.update(kwargs)
    b = _builder()
    b.add_bump_stop(**args)
    with pytest.raises(ModelError, match=match) as err:
        b.build()
    assert "'stop 7'" in str(err.value)


@pytest.mark.parametrize("kwargs,match", [
    (dict(node_mass=0.0), "node mass must be a finite number > 0"),
    (dict(node_mass=-1.0), "node mass must be a finite number > 0"),
    (dict(node_mass=np.nan), "node mass must be a finite number > 0"),
    (dict(node_mass="heavy"), "node mass must be a finite number > 0"),
    (dict(node_position=np.nan), "node position must be a finite number"),
])
def test_series_spring_damper_bad_input_at_the_builder(kwargs, match):
    args = dict(name="yaw 2", body_i="a", body_j="b", point_i=(0.0, 0.0), point_j=(1.0, 0.0), stiffness=1e6,
                damping=1e5, node_mass=5.0)
    args.update(kwargs)
    b = _builder()
    with pytest.raises(ModelError, match=match) as err:
        b.add_series_spring_damper(**args)
    assert "'yaw 2'" in str(err.value)
    assert not b.extras and not b.forces  # nothing half-added


@pytest.mark.parametrize("kwargs,match", [
    (dict(stiffness=-1.0), "stiffness must be a finite number ≥ 0"),
    (dict(damping=np.nan), "damping must be a finite number ≥ 0"),
    (dict(free_length=-0.5), "free length must be a finite number ≥ 0"),
    (dict(point_j=(0.0, 0.0)), "points P and Q coincide"),
    (dict(point_j=(1.0, 0.0, 0.0)), "points must be 2 finite numbers"),
    (dict(point_j=(np.inf, 0.0)), "points must be 2 finite numbers"),
    (dict(body_j="a"), "connects body 'a' to itself"),
])
def test_series_spring_damper_bad_input_at_build(kwargs, match):
    args = dict(name="yaw 2", body_i="a", body_j="b", point_i=(0.0, 0.0), point_j=(1.0, 0.0), stiffness=1e6,
                damping=1e5, node_mass=5.0)
    args.update(kwargs)
    b = _builder()
    b.add_series_spring_damper(**args)
    with pytest.raises(ModelError, match=match) as err:
        b.build()
    assert "'yaw 2'" in str(err.value)


def test_series_spring_damper_node_coordinate_checks():
    from core.forces import SeriesSpringDamper

    b = _builder()
    b.add_force(SeriesSpringDamper("yaw", "a", "b", (0.0, 0.0), (1.0, 0.0), 1e6, 1e5, node="missing"))
    with pytest.raises(ModelError, match="element 'yaw' refers to unknown coordinate 'missing'"):
        b.build()
    b = _builder()
    b.add_series_spring_damper("yaw", "a", "b", (0.0, 0.0), (1.0, 0.0), 1e6, 1e5, 5.0)
    b.add_force(SeriesSpringDamper("yaw-2", "a", "b", (0.0, 0.0), (1.0, 0.0), 1e6, 1e5, node="yaw.node"))
    with pytest.raises(ModelError, match="'yaw-2': node coordinate 'yaw.node' is already the node of 'yaw'"):
        b.build()
    b = _builder()
    b.add_series_spring_damper("yaw", "a", "b", (0.0, 0.0), (1.0, 0.0), 1e6, 1e5, 5.0)
    with pytest.raises(ModelError, match="duplicate name 'yaw'"):
        b.add_series_spring_damper("yaw", "a", "b", (0.0, 0.0), (1.0, 0.0), 1e6, 1e5, 5.0)
