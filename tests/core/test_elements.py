"""Tier-2 property tests for every joint, driver and force-element kind (DESIGN.md, "Tests").

For each element a small model is built with bodies at random (seeded) poses; the joints are
declared in that initial configuration, so they hold at ``q0``.  The checks are made at a
*perturbed* state ``q = retract(q0, dv)`` with random velocities ``v`` and accelerations ``a``:

* ``Φ_q`` against central differences of ``Φ`` along the retraction (velocity-space increments);
* ``ν`` against ``−∂Φ/∂t`` (central differences in t);
* ``γ`` against ``Φ_q a − Φ̈``, with ``Φ̈`` the central difference of ``Φ̇ = Φ_q v − ν`` along the
  path ``q(s) = retract(q, s v + ½ s² a)``, ``v(s) = v + s a``, ``t + s``;
* ``Q_q``/``Q_v`` (analytic, :meth:`Model.Q_jacobians`) against central differences of ``Q``;
* conservative elements: ``Q = −∂V/∂q`` (central differences of the energy at v = 0, g = 0);
* ``M`` symmetric positive definite;
* energy of a conservative spring pendulum conserved to a bound that scales with the tolerance.

Tolerances follow from the finite-difference truncation (O(h²)) and round-off (O(ε/h)) errors.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from core import drivers, frames
from core.contact_laws import hertz_sphere_plane_stiffness
from core.model import ModelBuilder

EPS = 1e-6  # finite-difference step for positions / velocities
RTOL = 1e-6  # relative tolerance of the finite-difference comparisons


def _dense(A):
    return A.toarray() if hasattr(A, "toarray") else np.asarray(A)


def _close(actual, expected, rtol=RTOL, what=""):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    scale = max(1.0, float(np.max(np.abs(expected))) if expected.size else 1.0)
    err = float(np.max(np.abs(actual - expected))) if expected.size else 0.0
    assert err <= rtol * scale, f"{what}: max error {err:.3e} > {rtol:g} × {scale:.3g}"


# --------------------------------------------------------------------------------------------
# random poses
# --------------------------------------------------------------------------------------------


def _unit(rng, d=3):
    x = rng.standard_normal(d)
    return x / np.linalg.norm(x)


def _add_random_body(b: ModelBuilder, rng, name: str):
    if b.space.dim == 2:
        return b.add_body(name, rng.uniform(0.5, 2.0), rng.uniform(0.05, 0.3), rng.uniform(-1, 1, 2),
                          orientation=rng.uniform(-np.pi, np.pi))
    J = np.diag(rng.uniform(0.1, 0.2, 3))  # principal moments of a rigid body: J_a <= J_b + J_c
    Rm = frames.euler_to_matrix(frames.axis_angle_to_euler(_unit(rng), rng.uniform(0, np.pi)))
    p = frames.axis_angle_to_euler(_unit(rng), rng.uniform(-np.pi, np.pi))
    return b.add_body(name, rng.uniform(0.5, 2.0), Rm @ J @ Rm.T, rng.uniform(-1, 1, 3), orientation=p)


def _two_bodies(dim, seed, ground_i=False):
    rng = np.random.default_rng(seed)
    b = ModelBuilder(dim, f"test{dim}d")
    _add_random_body(b, rng, "a")
    _add_random_body(b, rng, "b")
    bi = "ground" if ground_i else "a"
    return b, rng, bi, "b"


# --------------------------------------------------------------------------------------------
# joint and driver factories (each returns a built model)
# --------------------------------------------------------------------------------------------


def _joint_planar(kind, seed, ground_i=False):
    b, rng, bi, bj = _two_bodies(2, seed, ground_i)
    at = rng.uniform(-1, 1, 2)
    if kind == "revolute":
        b.add_revolute("J", bi, bj, at)
    elif kind == "translational":
        b.add_translational("J", bi, bj, at, _unit(rng, 2))
    elif kind == "fixed":
        b.add_fixed("J", bi, bj, at)
    elif kind == "distance":
        b.add_distance("J", bi, bj, at, at + rng.uniform(0.3, 1.0, 2))
    return b.build()


def _joint_spatial(kind, seed, ground_i=False):
    b, rng, bi, bj = _two_bodies(3, seed, ground_i)
    at = rng.uniform(-1, 1, 3)
    axis = _unit(rng)
    if kind == "spherical":
        b.add_spherical("J", bi, bj, at)
    elif kind == "revolute":
        b.add_revolute("J", bi, bj, at, axis)
    elif kind == "translational":
        b.add_translational("J", bi, bj, at, axis)
    elif kind == "cylindrical":
        b.add_cylindrical("J", bi, bj, at, axis)
    elif kind == "universal":
        other = np.cross(axis, _unit(rng))
        b.add_universal("J", bi, bj, at, axis, other / np.linalg.norm(other))
    elif kind == "fixed":
        b.add_fixed("J", bi, bj, at)
    elif kind == "distance":
        b.add_distance("J", bi, bj, at, at + rng.uniform(0.3, 1.0, 3))
    return b.build()


def _motion(name):
    if name == "ramp":
        return drivers.ramp(0.7, start=0.2)
    if name == "harmonic":
        return drivers.harmonic(0.4, 3.0, phase=0.3, offset=0.1)
    if name == "tabulated":
        t = np.linspace(0.0, 2.0, 21)
        return (t, 0.3 * np.sin(2.0 * t) + 0.1 * t**2)
    raise AssertionError(name)


def _driver_model(kind, dim, motion, seed):
    b, rng, bi, bj = _two_bodies(dim, seed)
    at = rng.uniform(-1, 1, dim)
    if kind == "angle":
        axis = None if dim == 2 else _unit(rng)
        b.add_revolute("J", bi, bj, at, axis)
        b.add_angle_driver("D", "J", _motion(motion))
    else:  # point driver on a free body
        b.add_point_driver("D", bj, at, _unit(rng, dim), _motion(motion))
    # the drivers move at t = 0: assembly corrects the (zero) initial velocities onto Φ_q v = ν
    return b.build(assemble=True)


PLANAR_JOINTS = ["revolute", "translational", "fixed", "distance"]
SPATIAL_JOINTS = ["spherical", "revolute", "translational", "cylindrical", "universal", "fixed", "distance"]
MOTIONS = ["ramp", "harmonic", "tabulated"]

def _helix_model(seed):
    from core.models import body_on_helix

    return body_on_helix(radius=0.3 + 0.1 * seed, pitch=0.15, sdot0=1.0 + seed)


def _coordinate_driver_model(motion_name, seed):
    """An extra coordinate (with inertia) prescribed by a CoordinateDriver, starting on f(0)."""
    from core.joints import CoordinateDriver

    f = drivers.as_time_function(_motion(motion_name), label="coordinate driver")
    x0, xd0 = (float(c) for c in f(0.0)[:2])
    b = ModelBuilder(3, "driven_coordinate")
    b.add_coordinate("x", x0, xd0, 1.0 + seed)
    b.add_joint(CoordinateDriver("D", "x", _motion(motion_name)))
    return b.build()


def _flexible_nodes_model(dim, seed, inertia="full"):
    """Node frames on a free flexible L-shaped body (core.flexible.body.FlexibleNodes)."""
    from tests.core.test_flexible_body import _free_body_model

    return _free_body_model(dim, seed, nodes=(0, 2, 4))[0]


MODEL_CASES = (
    [pytest.param(_helix_model, id="spatial-user-constraint-helix")]
    + [pytest.param(lambda s, d=d: _flexible_nodes_model(d, s), id=f"{'planar' if d == 2 else 'spatial'}-flexible-nodes")
       for d in (2, 3)]
    + [pytest.param(lambda s, mo=mo: _coordinate_driver_model(mo, s), id=f"coordinate-driver-{mo}") for mo in MOTIONS]
    + [pytest.param(lambda s, k=k, g=g: _joint_planar(k, s, g), id=f"planar-{k}{'-ground' if g else ''}")
     for k in PLANAR_JOINTS for g in (False, True)]
    + [pytest.param(lambda s, k=k, g=g: _joint_spatial(k, s, g), id=f"spatial-{k}{'-ground' if g else ''}")
       for k in SPATIAL_JOINTS for g in (False, True)]
    + [pytest.param(lambda s, k=k, d=d, mo=mo: _driver_model(k, d, mo, s), id=f"{'planar' if d == 2 else 'spatial'}-{k}-driver-{mo}")
       for k in ("angle", "point") for d in (2, 3) for mo in MOTIONS]
)


# --------------------------------------------------------------------------------------------
# finite-difference helpers
# --------------------------------------------------------------------------------------------


def _fd_Phi_q(m, t, q):
    cols = []
    for e in np.eye(m.n_v):
        cols.append((m.Phi(t, m.retract(q, EPS * e)) - m.Phi(t, m.retract(q, -EPS * e))) / (2 * EPS))
    return np.array(cols).T


def _fd_Q(m, t, q, v):
    Qq = np.array([(m.Q(t, m.retract(q, EPS * e), v) - m.Q(t, m.retract(q, -EPS * e), v)) / (2 * EPS) for e in np.eye(m.n_v)]).T
    Qv = np.array([(m.Q(t, q, v + EPS * e) - m.Q(t, q, v - EPS * e)) / (2 * EPS) for e in np.eye(m.n_v)]).T
    return Qq, Qv


def _perturbed_state(m, seed, scale=0.05):
    rng = np.random.default_rng(seed + 1000)
    q = m.retract(m.q0, scale * rng.standard_normal(m.n_v))
    v = rng.standard_normal(m.n_v)
    a = rng.standard_normal(m.n_v)
    return q, v, a


# --------------------------------------------------------------------------------------------
# constraints
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("factory", MODEL_CASES)
def test_constraint_derivatives(factory, seed):
    m = factory(seed)
    t = 0.7
    # consistent at q0 (build checked it), and the perturbed state violates it
    q, v, a = _perturbed_state(m, seed)
    J = _dense(m.Phi_q(t, q))
    assert J.shape == (m.n_c, m.n_v)
    _close(J, _fd_Phi_q(m, t, q), what="Phi_q vs FD(Phi)")
    # ν = −∂Φ/∂t
    h = 1e-5
    dPhi_dt = (m.Phi(t + h, q) - m.Phi(t - h, q)) / (2 * h)
    _close(m.nu(t, q), -dPhi_dt, what="nu vs −dPhi/dt")

    # γ = Φ_q a − Φ̈ along any path with acceleration a (time terms included)
    def phidot(s):
        qq = m.retract(q, s * v + 0.5 * s * s * a)
        return _dense(m.Phi_q(t + s, qq)) @ (v + s * a) - m.nu(t + s, qq)

    Phidd = (phidot(h) - phidot(-h)) / (2 * h)
    _close(m.gamma(t, q, v), J @ a - Phidd, rtol=1e-5, what="gamma vs FD along path")
    # one-pass constraint terms agree with the separate calls
    phi, J1, nu, gam = m.constraint_terms(t, q, v)
    np.testing.assert_allclose(phi, m.Phi(t, q), atol=1e-14)
    np.testing.assert_allclose(_dense(J1), J, atol=1e-14)
    np.testing.assert_allclose(nu, m.nu(t, q), atol=1e-14)
    np.testing.assert_allclose(gam, m.gamma(t, q, v), atol=1e-12)


@pytest.mark.parametrize("factory", MODEL_CASES)
def test_mass_matrix_spd_and_consistent_start(factory):
    from core.analysis import null_space_basis

    m = factory(3)
    M = _dense(m.M(0.0, m.q0))
    np.testing.assert_allclose(M, M.T, atol=0)
    # positive semi-definite (a massless extra coordinate has no inertia) and positive definite on
    # the motions the constraints allow (null space of Φ_q): the equations of motion are regular
    # (eigvalsh's backward error n·eps·‖M‖ can put an exact zero — massless node frames of a
    # flexible body next to its modal masses — a few 1e-17 below zero)
    assert np.min(np.linalg.eigvalsh(M)) >= -len(M) * np.finfo(float).eps * np.max(np.abs(M))
    N = null_space_basis(m.Phi_q(0.0, m.q0))
    assert N.shape[1] == 0 or np.min(np.linalg.eigvalsh(N.T @ M @ N)) > 0
    if not m.extra_names:
        assert np.min(np.linalg.eigvalsh(M)) > 0
    # joints hold at the initial configuration they were declared in
    assert np.max(np.abs(m.Phi(0.0, m.q0))) < 1e-12


def test_driver_follows_motion_exactly():
    """A driven revolute (spatial) reaches θ0 + f(t) − f(0): Φ = 0 at the rotated state."""
    rng = np.random.default_rng(5)
    b = ModelBuilder(3, "drv")
    _add_random_body(b, rng, "a")
    axis = _unit(rng)
    b.add_revolute("J", "ground", "a", (0.0, 0.0, 0.0), axis)
    f = drivers.harmonic(0.4, 3.0, phase=0.3)
    b.add_angle_driver("D", "J", f)
    m = b.build(assemble=True)
    np.testing.assert_allclose(m.velocity_violation(0.0, m.q0, m.v0), 0.0, atol=1e-10)
    t = 0.37
    dth = f(t)[0] - f(0.0)[0]
    # rotate body a about the global axis through the origin by dth
    Rg = frames.euler_to_matrix(frames.axis_angle_to_euler(axis, dth))
    q = m.q0.copy()
    q[:3] = Rg @ q[:3]
    q[3:7] = frames.matrix_to_euler(Rg @ frames.euler_to_matrix(q[3:7]))
    assert np.max(np.abs(m.Phi(t, q))) < 1e-12
    assert np.max(np.abs(m.Phi(t + 0.05, q))) > 1e-3


# --------------------------------------------------------------------------------------------
# force elements
# --------------------------------------------------------------------------------------------


def _force_model(dim, element, seed=0, gravity=None, conservative=False):
    b, rng, _, _ = _two_bodies(dim, seed)
    if gravity is not None:
        b.gravity = np.asarray(gravity, float)
    at = rng.uniform(-1, 1, dim)
    axis = None if dim == 2 else _unit(rng)
    nr = 1 if dim == 2 else 3
    c = 0.0 if conservative else 1.5
    if element == "spring-damper":
        b.add_spring_damper("F", "a", "b", at, at + rng.uniform(0.3, 1.0, dim), 40.0, c, free_length=0.5)
    elif element == "point-spring":
        b.add_point_spring("F", "a", "b", at, at + 0.1 * rng.standard_normal(dim), stiffness=60.0, damping=c)
    elif element == "point-spring-coincident":
        b.add_point_spring("F", "a", "b", at, stiffness=1e4, damping=10 * c)
    elif element == "rotational":
        b.add_rotational_spring_damper("F", "a", "b", 30.0, c, free_angle=0.2,
                                       actuator=None if conservative else drivers.harmonic(2.0, 1.5), axis=axis)
    elif element == "rotational-ground":
        b.add_rotational_spring_damper("F", "ground", "b", 30.0, c, free_angle=-0.1, axis=axis)
    elif element == "bushing":
        b.add_bushing("F", "a", "b", at, rng.uniform(10, 100, dim), rng.uniform(5, 50, nr),
                      0.0 if conservative else rng.uniform(0.1, 2, dim), 0.0 if conservative else rng.uniform(0.1, 2, nr),
                      axes=frames.rot2(rng.uniform(0, 6)) if dim == 2 else frames.euler_to_matrix(frames.axis_angle_to_euler(_unit(rng), 1.0)),
                      point_j=at + 0.1 * rng.standard_normal(dim))
    elif element == "bushing-ground":
        b.add_bushing("F", "b", "ground", at, 80.0, 20.0, 0.0 if conservative else 1.0, 0.0 if conservative else 0.5)
    elif element == "bump-stop":
        # clearance 5 mm, three segments and the last slope beyond; the perturbed states of the tests
        # below are engaged (|u| of a few cm)
        table = [[0.005, 0.0], [0.02, 30.0], [0.05, 100.0], [0.2, 150.0]]
        b.add_bump_stop("F", "a", "b", at, _unit(rng, dim), table, damping=c, point_j=at + 0.1 * rng.standard_normal(dim))
    elif element == "bump-stop-one-sided":
        table = [[0.0, 0.0], [0.01, 50.0], [0.03, 400.0]]
        b.add_bump_stop("F", "ground", "b", at, _unit(rng, dim), table, damping=2 * c, sides="negative")
    elif element == "series-spring-damper":
        b.add_series_spring_damper("F", "a", "b", at, at + rng.uniform(0.3, 1.0, dim), 200.0, 3 * c, 0.05,
                                   free_length=0.8)
    elif element == "series-spring-damper-ground":
        b.add_series_spring_damper("F", "b", "ground", at, at + rng.uniform(0.3, 1.0, dim), 500.0, c, 0.2)
    elif element == "applied-force":
        comps = [2.0, drivers.harmonic(3.0, 2.0), (np.linspace(0, 2, 9), np.linspace(0, 2, 9) ** 2)][:dim]
        b.add_applied_force("F", "a", at, comps)
    elif element == "applied-force-body":
        comps = [lambda t: 1.0 + t, -3.0, 0.5][:dim]
        b.add_applied_force("F", "a", at, comps, frame="body")
    elif element == "applied-torque":
        b.add_applied_torque("F", "a", drivers.harmonic(2.0, 3.0) if dim == 2 else [1.0, drivers.ramp(2.0), -0.5])
    elif element == "applied-torque-body":
        b.add_applied_torque("F", "a", 1.5 if dim == 2 else [1.0, -2.0, 0.5], frame="body")
    elif element == "plane-contact":
        # sphere on body a placed so that it penetrates the plane by a few mm
        n = _unit(rng, dim)
        centre = np.asarray(b.bodies["a"].position) + 0.1 * rng.standard_normal(dim)
        R = 0.2
        p0 = centre - (R - 0.01) * n
        b.add_plane_contact("F", "a", centre, R, p0, n, restitution=1.0 if conservative else 0.8,
                            impact_velocity=None if conservative else 2.0, materials=((2e8, 0.3), (1e8, 0.35)))
    else:
        raise AssertionError(element)
    return b.build()


FORCE_ELEMENTS = ["spring-damper", "point-spring", "point-spring-coincident", "rotational", "rotational-ground",
                  "bushing", "bushing-ground", "applied-force", "applied-force-body", "applied-torque",
                  "applied-torque-body", "plane-contact", "bump-stop", "bump-stop-one-sided",
                  "series-spring-damper", "series-spring-damper-ground"]
CONSERVATIVE = ["spring-damper", "point-spring", "point-spring-coincident", "rotational", "rotational-ground",
                "bushing", "bushing-ground", "plane-contact", "bump-stop", "bump-stop-one-sided",
                "series-spring-damper", "series-spring-damper-ground"]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("element", FORCE_ELEMENTS)
def test_force_jacobians_against_finite_differences(element, dim):
    m = _force_model(dim, element, seed=dim)
    fk = m.force_kinds[0]
    q, v, _ = _perturbed_state(m, 7, scale=0.03)
    t = 0.6
    bs = m.body_states(q, v)
    assert fk.jacobian(bs, t) is not None, "analytic Jacobian expected"
    Qq, Qv = m.Q_jacobians(t, q, v)
    Qq_fd, Qv_fd = _fd_Q(m, t, q, v)
    _close(_dense(Qq), Qq_fd, what=f"{element}: Q_q")
    _close(_dense(Qv), Qv_fd, what=f"{element}: Q_v")


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("element", CONSERVATIVE)
def test_conservative_forces_derive_from_their_potential(element, dim):
    m = _force_model(dim, element, seed=10 + dim, gravity=np.zeros(dim), conservative=True)
    assert m.is_conservative and all(fk.conservative for fk in m.force_kinds)
    q, _, _ = _perturbed_state(m, 3, scale=0.03)
    z = np.zeros(m.n_v)  # v = 0: no gyroscopic moment, no damping
    grad = np.array([(m.energy(0.0, m.retract(q, EPS * e), z) - m.energy(0.0, m.retract(q, -EPS * e), z)) / (2 * EPS)
                     for e in np.eye(m.n_v)])
    _close(m.Q(0.0, q, z), -grad, what=f"{element}: Q vs −dV/dq")


@pytest.mark.parametrize("dim", [2, 3])
def test_elements_unstressed_at_build(dim):
    """Free length/angle default to the initial configuration: no force at q0 with v = 0."""
    for element in ("bushing", "bushing-ground", "point-spring-coincident"):
        m = _force_model(dim, element, gravity=np.zeros(dim), conservative=True)
        np.testing.assert_allclose(m.Q(0.0, m.q0, np.zeros(m.n_v)), 0.0, atol=1e-9)
    b, rng, _, _ = _two_bodies(dim, 4)
    b.gravity = np.zeros(dim)
    b.add_rotational_spring_damper("r1", "a", "b", 10.0, axis=None if dim == 2 else _unit(rng))
    b.add_rotational_spring_damper("r2", "ground", "a", 10.0, axis=None if dim == 2 else _unit(rng))
    m = b.build()
    np.testing.assert_allclose(m.Q(0.0, m.q0, np.zeros(m.n_v)), 0.0, atol=1e-12)


def test_rotational_spring_planar_torque_sign_and_value():
    """Planar: T = k(θ_j − θ_i − θ0) + c(θ̇_j − θ̇_i) + T_a acts +T on i, −T on j."""
    b = ModelBuilder(2, "rs", gravity=(0.0, 0.0))
    b.add_body("i", 1.0, 0.1, (0.0, 0.0), orientation=0.2)
    b.add_body("j", 1.0, 0.1, (1.0, 0.0), orientation=0.5)
    k, c, th0, Ta = 12.0, 0.7, 0.05, 0.3
    b.add_rotational_spring_damper("rs", "i", "j", k, c, free_angle=th0, actuator=Ta)
    m = b.build()
    q, v = m.q0.copy(), np.zeros(6)
    q[2] += 0.1
    q[5] += 0.4
    v[2], v[5] = 0.3, -0.2
    T = k * ((0.4 - 0.1) - th0) + c * (-0.2 - 0.3) + Ta
    Q = m.Q(0.0, q, v)
    np.testing.assert_allclose([Q[2], Q[5]], [T, -T], rtol=1e-12)
    np.testing.assert_allclose(Q[[0, 1, 3, 4]], 0.0, atol=1e-12)


def test_rotational_spring_spatial_about_revolute_axis():
    """Spatial: torque −k θ about the axis on body j when j is turned by θ about the axis."""
    rng = np.random.default_rng(2)
    axis = _unit(rng)
    b = ModelBuilder(3, "rs3", gravity=(0.0, 0.0, 0.0))
    b.add_body("j", 1.0, [0.1, 0.2, 0.3], (0.0, 0.0, 0.0), orientation=frames.axis_angle_to_euler(_unit(rng), 0.7))
    b.add_rotational_spring_damper("rs", "ground", "j", 5.0, axis=axis)
    m = b.build()
    th = 0.6
    q = m.q0.copy()
    q[3:7] = frames.quat_multiply(frames.axis_angle_to_euler(axis, th), q[3:7])
    out = m.force_kinds[0].outputs(m.body_states(q, np.zeros(6)), 0.0)
    np.testing.assert_allclose(out["angle [rad]"], th, atol=1e-12)
    Q = m.Q(0.0, q, np.zeros(6))
    A = frames.euler_to_matrix(q[3:7])
    np.testing.assert_allclose(A @ Q[3:], -5.0 * th * axis, atol=1e-12)


def test_bushing_translational_force_in_marker_axes():
    """Pure translation of j by Δ (marker axes) gives force −K_t Δ on j, no moment about the marker."""
    b = ModelBuilder(3, "bu", gravity=(0.0, 0.0, 0.0))
    b.add_body("j", 1.0, [0.1, 0.1, 0.1], (0.3, 0.2, 0.1))
    axes = frames.euler_to_matrix(frames.axis_angle_to_euler([1.0, 1.0, 0.0], 0.5))
    kt = np.array([10.0, 20.0, 30.0])
    b.add_bushing("bu", "ground", "j", (0.3, 0.2, 0.1), kt, [1.0, 2.0, 3.0], axes=axes)
    m = b.build()
    delta = np.array([0.01, -0.02, 0.03])
    q = m.q0.copy()
    q[:3] += axes @ delta
    Q = m.Q(0.0, q, np.zeros(6))
    np.testing.assert_allclose(Q[:3], axes @ (-kt * delta), rtol=1e-12)
    np.testing.assert_allclose(Q[3:], 0.0, atol=1e-12)


def test_bushing_small_rotation_matches_rotation_vector():
    """Relative rotation φ about a marker axis: torque −k_r sin φ (small-angle definition)."""
    b = ModelBuilder(3, "bu", gravity=(0.0, 0.0, 0.0))
    b.add_body("j", 1.0, [0.1, 0.1, 0.1], (0.0, 0.0, 0.0))
    kr = np.array([4.0, 5.0, 6.0])
    b.add_bushing("bu", "ground", "j", (0.0, 0.0, 0.0), 100.0, kr)
    m = b.build()
    phi = 0.02
    q = m.q0.copy()
    q[3:7] = frames.axis_angle_to_euler([0.0, 1.0, 0.0], phi)
    out = m.force_kinds[0].outputs(m.body_states(q, np.zeros(6)), 0.0)
    np.testing.assert_allclose(out["ay [rad]"], np.sin(phi), rtol=1e-12)
    np.testing.assert_allclose(out["My [N m]"], -kr[1] * np.sin(phi), rtol=1e-12)


def test_applied_force_table_and_moment():
    b = ModelBuilder(2, "af", gravity=(0.0, 0.0))
    b.add_body("a", 2.0, 0.1, (0.0, 0.0))
    ts = np.linspace(0.0, 1.0, 11)
    b.add_applied_force("F", "a", (0.0, 0.5), [(ts, 3 * ts), 0.0])
    m = b.build()
    Q = m.Q(0.4, m.q0, np.zeros(3))
    # F = (1.2, 0) at (0, 0.5): moment −0.5·1.2
    np.testing.assert_allclose(Q, [1.2, 0.0, -0.6], atol=1e-12)


def test_plane_contact_hertz_static_equilibrium():
    """A sphere resting on the plane under its weight: δ = (m g / K)^(2/3) with K from Hertz."""
    R, mass, g = 0.05, 2.0, 9.81
    mat = ((210e9, 0.3), (70e9, 0.33))
    K = hertz_sphere_plane_stiffness(R, 210e9, 0.3, 70e9, 0.33)
    Estar = 1 / ((1 - 0.3**2) / 210e9 + (1 - 0.33**2) / 70e9)
    np.testing.assert_allclose(K, 4 / 3 * Estar * np.sqrt(R), rtol=1e-14)
    delta = (mass * g / K) ** (2.0 / 3.0)
    b = ModelBuilder(3, "ball")
    b.add_body("ball", mass, [1e-3] * 3, (0.0, 0.0, R - delta))
    b.add_plane_contact("c", "ball", (0.0, 0.0, R - delta), R, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), materials=mat)
    m = b.build()
    np.testing.assert_allclose(m.Q(0.0, m.q0, np.zeros(6)), 0.0, atol=1e-9 * mass * g)
    # lifted off: no force but gravity
    q = m.q0.copy()
    q[2] += 2 * delta
    np.testing.assert_allclose(m.Q(0.0, q, np.zeros(6))[:3], [0, 0, -mass * g], rtol=1e-14)


@pytest.mark.parametrize("model,e", [("flores", 0.8), ("lankarani-nikravesh", 0.95)])
def test_plane_contact_restitution(model, e):
    """Drop a ball (point mass) with approach speed equal to impact_velocity: rebound ≈ e·v⁻.

    The Flores et al. (2011) model is built to reproduce e for any e; Lankarani–Nikravesh for
    e close to 1 (their Eq. 17 assumes small dissipation).  The tolerance (2 %) is the known model
    error of these closed forms at these e (Flores et al. 2011, Fig. 6).
    """
    from scipy.integrate import solve_ivp

    v_in = 2.0
    b = ModelBuilder(2, "drop", gravity=(0.0, 0.0))
    b.add_body("ball", 1.0, 1e-3, (0.0, 0.1), velocity=(0.0, -v_in))
    b.add_plane_contact("c", "ball", (0.0, 0.1), 0.1, (0.0, 0.0), (0.0, 1.0), restitution=e, impact_velocity=v_in,
                        stiffness=1e7, model=model)
    m = b.build()

    def rhs(t, y):
        q, v = y[:3], y[3:]
        return np.concatenate([v, m.Q(t, q, v) / np.array([1.0, 1.0, 1e-3])])

    sol = solve_ivp(rhs, (0.0, 0.01), np.concatenate([m.q0, m.v0]), method="DOP853", rtol=1e-10, atol=1e-12)
    v_out = sol.y[4, -1]
    assert sol.y[1, -1] > 0.1  # separated
    np.testing.assert_allclose(v_out / v_in, e, rtol=0.02)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), element=st.sampled_from(["bushing", "rotational", "point-spring", "applied-force-body"]),
       dim=st.sampled_from([2, 3]))
def test_force_jacobians_property(seed, element, dim):
    m = _force_model(dim, element, seed=seed)
    q, v, _ = _perturbed_state(m, seed, scale=0.1)
    Qq, Qv = m.Q_jacobians(0.3, q, v)
    Qq_fd, Qv_fd = _fd_Q(m, 0.3, q, v)
    _close(_dense(Qq), Qq_fd, rtol=2e-6, what=f"{element}: Q_q")
    _close(_dense(Qv), Qv_fd, rtol=2e-6, what=f"{element}: Q_v")


def test_friction_falls_back_to_numerical_jacobian():
    b = ModelBuilder(3, "fr")
    b.add_body("ball", 1.0, [1e-3] * 3, (0.0, 0.0, 0.099))
    b.add_plane_contact("c", "ball", (0.0, 0.0, 0.099), 0.1, (0, 0, 0), (0, 0, 1), stiffness=1e6, friction=0.3)
    m = b.build()
    v = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert m.force_kinds[0].jacobian(m.body_states(m.q0, v), 0.0) is None
    Q = m.Q(0.0, m.q0, v)
    Fn = 1e6 * 0.001**1.5
    # sliding in +x: friction −μ F_n (regularised), moment +R·f about y (it spins the ball up towards rolling)
    np.testing.assert_allclose(Q[0], -0.3 * Fn / np.sqrt(1 + 1e-6), rtol=1e-12)
    np.testing.assert_allclose(Q[4], +0.1 * 0.3 * Fn / np.sqrt(1 + 1e-6), rtol=1e-12)  # r × F = (0,0,−R) × (−f,0,0)


# --------------------------------------------------------------------------------------------
# energy conservation of a conservative spring pendulum
# --------------------------------------------------------------------------------------------


def _spring_pendulum(dim):
    b = ModelBuilder(dim, f"spring-pendulum-{dim}d")
    if dim == 2:
        b.add_body("bob", 1.0, 0.02, (0.8, -0.6), orientation=0.3, velocity=(0.2, 0.5), angular_velocity=1.0)
        b.add_spring_damper("s", "ground", "bob", (0.0, 0.0), (0.8, -0.6), 80.0, free_length=0.7)
        b.add_rotational_spring_damper("r", "ground", "bob", 2.0)
        b.add_point_spring("p", "ground", "bob", (0.8, -0.5), (0.8, -0.6), stiffness=5.0)
        b.add_bushing("bu", "ground", "bob", (0.8, -0.6), 3.0, 0.5)
    else:
        r, om = np.array([0.8, 0.1, -0.6]), np.array([1.0, -0.5, 2.0])
        b.add_body("bob", 1.0, [0.02, 0.03, 0.04], r, orientation=frames.axis_angle_to_euler([1, 2, 3], 0.4),
                   velocity=np.cross(om, r), angular_velocity=om)  # consistent with the ball joint at 0
        b.add_spherical("sph", "ground", "bob", (0.0, 0.0, 0.0))
        b.add_rotational_spring_damper("r", "ground", "bob", 2.0, axis=(0, 0, 1))
        b.add_bushing("bu", "ground", "bob", (0.8, 0.1, -0.6), 3.0, 0.5)
    return b.build()


@pytest.mark.parametrize("dim", [2, 3])
def test_energy_conserved_spring_pendulum(dim):
    from core.integrators import METHODS, simulate

    method = "dop853-projection" if "dop853-projection" in METHODS else "rk45-projection"
    m = _spring_pendulum(dim)
    assert m.is_conservative
    E0 = m.energy(0.0, m.q0, m.v0)
    drift = []
    for rtol in (1e-6, 1e-9):
        res = simulate(m, (0.0, 1.0), method, rtol=rtol, atol=rtol * 1e-2, n_output=41, compute_multipliers=False)
        assert res.status == "finished", res.message
        drift.append(np.max(np.abs(res.energy - E0)) / max(1.0, abs(E0)))
    # the drift bound scales with the requested tolerance
    assert drift[0] < 1e2 * 1e-6
    assert drift[1] < 1e2 * 1e-9


# --------------------------------------------------------------------------------------------
# coverage: a new kind cannot skip the finite-difference checks above
# --------------------------------------------------------------------------------------------


def _core_subclasses(base) -> set[type]:
    """Concrete subclasses of ``base`` defined in the ``core`` package (not in tests)."""
    out, todo = set(), list(base.__subclasses__())
    while todo:
        c = todo.pop()
        todo.extend(c.__subclasses__())
        if c.__module__.startswith("core.") and not c.__name__.startswith("_"):
            out.add(c)
    return out


def test_every_force_element_kind_is_in_the_property_cases():
    from core.forces import ForceElement

    covered = set()
    for dim in (2, 3):
        for element in FORCE_ELEMENTS:
            covered |= {type(f) for f in _force_model(dim, element).force_elements}
    missing = _core_subclasses(ForceElement) - covered
    assert not missing, f"force elements without finite-difference checks: {sorted(c.__name__ for c in missing)}"


def test_every_joint_driver_and_primitive_kind_is_in_the_property_cases():
    from core.constraints import PrimitiveKind
    from core.joints import Joint, UserConstraint

    joints, kinds = set(), set()
    for case in MODEL_CASES:
        m = case.values[0](0)
        joints |= {type(j) for j in m.joints}
        kinds |= {type(k) for k in m.kinds}
    missing = (_core_subclasses(Joint) | _core_subclasses(UserConstraint)) - joints
    assert not missing, f"joints/drivers without finite-difference checks: {sorted(c.__name__ for c in missing)}"
    missing = {c for c in _core_subclasses(PrimitiveKind) if c.__module__ == "core.constraints"} - kinds
    assert not missing, f"constraint primitives without finite-difference checks: {sorted(c.__name__ for c in missing)}"
