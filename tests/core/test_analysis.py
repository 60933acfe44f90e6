"""Tests of core.analysis against closed forms and independent computations.

Reference solutions:
* slider-crank position, velocity and acceleration in closed form (crank r, rod l, θ = θ0 + ωt);
* spring-loaded compound pendulum: tan φ = k a L / (m g c) (zero-free-length spring to (a, 0));
* driven compound pendulum: τ = J_O θ̈ + m g c cos θ;
* compound pendulum frequency ω² = m g c / J_O (planar and spatial), mass-spring ω² = k/m,
  ζ = c/(2√(km)); linearised double pendulum from its 2×2 angle-space M and K.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import scipy.linalg as sla

from core import analysis as A
from core.drivers import constant, harmonic, ramp
from core.dynamics import accelerations
from core.forces import AppliedTorque
from core.errors import AssemblyError
from core.model import ModelBuilder
from core.system import ConstrainedSystem

G = 9.81


# ------------------------------------------------------------------------------------------------
# models
# ------------------------------------------------------------------------------------------------

R_CRANK, L_ROD, OMEGA, TH0 = 0.1, 0.3, 2.0, 0.3


def slider_crank_config(th, r=R_CRANK, l=L_ROD):
    B = np.array([r * np.cos(th), r * np.sin(th)])
    x = r * np.cos(th) + np.sqrt(l * l - (r * np.sin(th)) ** 2)
    C = np.array([x, 0.0])
    phi = np.arctan2(C[1] - B[1], C[0] - B[0])
    return B, C, phi


def slider_crank():
    B, C, phi = slider_crank_config(TH0)
    b = ModelBuilder(2, "slider-crank")
    b.add_body("crank", 1.0, 0.01, B / 2, orientation=TH0)
    b.add_body("rod", 1.5, 0.02, (B + C) / 2, orientation=phi)
    b.add_body("slider", 0.5, 0.001, C)
    b.add_revolute("O", "ground", "crank", (0.0, 0.0))
    b.add_revolute("A", "crank", "rod", B)
    b.add_revolute("B", "rod", "slider", C)
    b.add_translational("T", "ground", "slider", C, (1.0, 0.0))
    b.add_angle_driver("drive", "O", ramp(OMEGA))
    return b.build(assemble=True)


def slider_x_closed_form(th, r=R_CRANK, l=L_ROD, w=OMEGA):
    """x, ẋ, ẍ of the slider for θ̇ = w constant."""
    s, c = np.sin(th), np.cos(th)
    S = np.sqrt(l * l - r * r * s * s)
    x = r * c + S
    dx = -r * s - r * r * s * c / S
    ddx = -r * c - r * r * np.cos(2 * th) / S - r**4 * s * s * c * c / S**3
    return x, dx * w, ddx * w * w


def compound_pendulum(theta0=-np.pi / 2, m=2.0, Lr=0.8, motion=None, spatial=False):
    """Uniform rod of length Lr pinned at the origin, centre of mass at c = Lr/2."""
    c, Jc = Lr / 2, m * Lr**2 / 12
    if not spatial:
        b = ModelBuilder(2, "pendulum")
        b.add_body("rod", m, Jc, (c * np.cos(theta0), c * np.sin(theta0)), orientation=theta0)
        b.add_revolute("pivot", "ground", "rod", (0.0, 0.0))
        if motion is not None:
            b.add_angle_driver("drive", "pivot", motion)
        return b.build(assemble=True), m, c, Jc
    b = ModelBuilder(3, "pendulum3d")
    # hanging along −z, swinging about the global x axis; rod inertia about x is Jc
    b.add_body("rod", m, [Jc, Jc, 0.05 * Jc], (0.0, 0.0, -c))
    b.add_revolute("pivot", "ground", "rod", (0.0, 0.0, 0.0), axis=(1.0, 0.0, 0.0))
    return b.build(), m, c, Jc


def double_pendulum(m1=1.0, L1=1.0, m2=0.7, L2=0.6, torque=None, drivers=False):
    """Two uniform links hanging straight down from the origin (angles from the downward vertical)."""
    b = ModelBuilder(2, "double-pendulum")
    b.add_body("l1", m1, m1 * L1**2 / 12, (0.0, -L1 / 2), orientation=-np.pi / 2)
    b.add_body("l2", m2, m2 * L2**2 / 12, (0.0, -L1 - L2 / 2), orientation=-np.pi / 2)
    b.add_revolute("j1", "ground", "l1", (0.0, 0.0))
    b.add_revolute("j2", "l1", "l2", (0.0, -L1))
    if torque is not None:
        b.add_force(AppliedTorque("tau", "l1", torque))
    if drivers:
        b.add_angle_driver("d1", "j1", constant(0.0))
        b.add_angle_driver("d2", "j2", constant(0.0))
    return b.build()


class CircleFollower(ConstrainedSystem):
    """Generalized coordinates (x, y): x² + y² = 1 and x = f(t) (zero degrees of freedom)."""

    name = "circle-follower"
    n_q = n_v = n_c = 2
    q0 = np.array([0.0, 1.0])
    v0 = np.zeros(2)
    coordinate_names = ["x [m]", "y [m]"]
    velocity_names = ["vx [m/s]", "vy [m/s]"]
    constraint_names = ["circle", "drive"]

    def M(self, t, q):
        return np.eye(2)

    def Q(self, t, q, v):
        return np.array([0.0, -G])

    def Phi(self, t, q):
        return np.array([q[0] ** 2 + q[1] ** 2 - 1.0, q[0] - t])

    def Phi_q(self, t, q):
        return np.array([[2 * q[0], 2 * q[1]], [1.0, 0.0]])

    def nu(self, t, q):
        return np.array([0.0, 1.0])

    def gamma(self, t, q, v):
        return np.array([-2 * v @ v, 0.0])


class PointPendulum(ConstrainedSystem):
    """Point mass on a massless rod of length l in generalized coordinates (x, y)."""

    name = "point-pendulum"
    n_q = n_v = 2
    n_c = 1
    coordinate_names = ["x [m]", "y [m]"]
    velocity_names = ["vx [m/s]", "vy [m/s]"]
    constraint_names = ["rod"]

    def __init__(self, length=0.5, mass=0.3):
        self.l, self.m = length, mass
        self.q0 = np.array([0.1, -0.4])  # rough, off the circle
        self.v0 = np.zeros(2)

    def M(self, t, q):
        return self.m * np.eye(2)

    def Q(self, t, q, v):
        return np.array([0.0, -self.m * G])

    def Phi(self, t, q):
        return np.array([0.5 * (q @ q - self.l**2)])

    def Phi_q(self, t, q):
        return q[None, :].copy()

    def nu(self, t, q):
        return np.zeros(1)

    def gamma(self, t, q, v):
        return np.array([-(v @ v)])


# ------------------------------------------------------------------------------------------------
# assembly and kinematics
# ------------------------------------------------------------------------------------------------


def test_slider_crank_kinematics_closed_form():
    model = slider_crank()
    times = np.linspace(0.0, 2 * np.pi / OMEGA, 73)  # a full crank revolution
    df = A.kinematic_analysis(model, times)
    assert df.attrs["status"] == "finished" and len(df) == len(times)
    th = TH0 + OMEGA * times
    x, xd, xdd = slider_x_closed_form(th)
    np.testing.assert_allclose(df["slider.x [m]"], x, atol=1e-9)
    np.testing.assert_allclose(df["slider.vx [m/s]"], xd, atol=1e-9)
    np.testing.assert_allclose(df["d(slider.vx)/dt [m/s^2]"], xdd, atol=1e-9)
    np.testing.assert_allclose(df["crank.theta [rad]"], th, atol=1e-9)
    np.testing.assert_allclose(df["crank.omega [rad/s]"], OMEGA, atol=1e-9)
    np.testing.assert_allclose(df[["slider.y [m]", "slider.theta [rad]"]].to_numpy(), 0.0, atol=1e-9)


def test_slider_crank_driver_power_balance():
    """Driver effort × ω equals vᵀ(M a − Q): ideal joints do no work (independent of λ's sign)."""
    model = slider_crank()
    times = np.linspace(0.0, 3.0, 31)
    kin = A.kinematic_analysis(model, times)
    inv = A.inverse_dynamics_from_kinematics(model, kin)
    _, vn, an = A._names(model)
    M = model.M(0.0, model.q0).toarray()
    qn = model.coordinate_names
    for i in range(len(times)):
        q, v, a = kin[qn].to_numpy()[i], kin[vn].to_numpy()[i], kin[an].to_numpy()[i]
        power = v @ (M @ a - model.Q(times[i], q, v))
        assert inv["drive effort [N m]"].iloc[i] * OMEGA == pytest.approx(power, abs=1e-9 * (1 + abs(power)))
    assert inv.attrs["max_residual"] < 1e-9


def test_assembly_from_rough_guess():
    model = slider_crank()
    rng = np.random.default_rng(1)
    q_guess = model.q0 + 0.05 * rng.standard_normal(model.n_q)
    q, v = A.assemble_state(model, q_guess, np.zeros(model.n_v), t=0.25)
    th = TH0 + OMEGA * 0.25
    B, C, phi = slider_crank_config(th)
    x, xd, _ = slider_x_closed_form(th)
    np.testing.assert_allclose(q[model.q_slice("slider")], [x, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(q[model.q_slice("rod")], [*((B + C) / 2), phi], atol=1e-9)
    np.testing.assert_allclose(v[model.v_slice("slider")][0], xd, atol=1e-9)
    assert np.max(np.abs(model.Phi(0.25, q))) < 1e-10
    assert np.max(np.abs(model.velocity_violation(0.25, q, v))) < 1e-10
    # Model wrapper keeps the model and replaces the state
    m2 = A.assemble(model, q_guess)
    np.testing.assert_allclose(m2.q0, A.assemble_state(model, q_guess)[0])


def test_assembly_generalized_coordinates_and_velocity_weighting():
    sys_ = PointPendulum()
    v_guess = np.array([1.0, 2.0])
    q, v = A.assemble_state(sys_, v_guess=v_guess)
    assert np.linalg.norm(q) == pytest.approx(sys_.l, abs=1e-12)
    # minimum-norm position correction is radial: the guess's direction is kept
    np.testing.assert_allclose(q / np.linalg.norm(q), sys_.q0 / np.linalg.norm(sys_.q0), atol=1e-12)
    # velocity: projection of the guess onto the tangent (M ∝ I so both weightings agree)
    tang = np.array([-q[1], q[0]]) / sys_.l
    np.testing.assert_allclose(v, (v_guess @ tang) * tang, atol=1e-12)
    _, v_id = A.assemble_state(sys_, v_guess=v_guess, velocity_weighting="identity")
    np.testing.assert_allclose(v_id, v, atol=1e-12)


def test_assembly_failure_names_constraint():
    sys_ = CircleFollower()
    with pytest.raises(AssemblyError, match="'circle'"):
        A.assemble_state(sys_, t=1.5)


def test_kinematic_analysis_generalized_and_partial_failure():
    sys_ = CircleFollower()
    times = np.array([0.0, 0.2, 0.4, 0.6, 0.8, 1.2, 1.4])
    with pytest.warns(A.AnalysisWarning, match="t = 1.2"):
        df = A.kinematic_analysis(sys_, times)
    assert df.attrs["status"] == "failed"
    assert "1.2" in df.attrs["message"] and "circle" in df.attrs["message"]
    assert len(df) == 5  # rows before the failure are kept
    t = df["t [s]"].to_numpy()
    y = np.sqrt(1 - t**2)
    np.testing.assert_allclose(df["x [m]"], t, atol=1e-12)
    np.testing.assert_allclose(df["y [m]"], y, atol=1e-10)
    np.testing.assert_allclose(df["vy [m/s]"], -t / y, atol=1e-9)
    np.testing.assert_allclose(df["d(vy)/dt [m/s^2]"], -1 / y**3, atol=1e-8)


def test_kinematic_analysis_rejects_free_mechanism():
    model, *_ = compound_pendulum()
    with pytest.raises(ValueError, match="1 degree"):
        A.kinematic_analysis(model, [0.0, 0.1])


# ------------------------------------------------------------------------------------------------
# statics
# ------------------------------------------------------------------------------------------------


def spring_pendulum(m=2.0, Lr=1.0, k=30.0, a=0.6):
    c = Lr / 2
    b = ModelBuilder(2, "spring-pendulum")
    b.add_body("rod", m, m * Lr**2 / 12, (0.0, -c), orientation=-np.pi / 2)
    b.add_revolute("pivot", "ground", "rod", (0.0, 0.0))
    b.add_spring_damper("spring", "ground", "rod", (a, 0.0), (0.0, -Lr), stiffness=k, free_length=0.0)
    return b.build(), m, Lr, c, k, a


def test_static_equilibrium_spring_pendulum():
    model, m, Lr, c, k, a = spring_pendulum()
    res = A.static_equilibrium(model)
    # V(φ) = −m g c cos φ + ½k|P(φ) − (a, 0)|², P = L(sin φ, −cos φ):  V' = m g c sin φ − k a L cos φ
    phi = np.arctan(k * a * Lr / (m * G * c))
    th = res.q[model.q_slice("rod")][2]
    assert th + np.pi / 2 == pytest.approx(phi, abs=1e-10)
    assert res.stable and res.min_stiffness > 0
    # tier-3 optimality: stationarity residual and reduced gradient vanish
    assert res.stationarity < 1e-9 and res.reduced_gradient < 1e-9 and res.constraint_violation <= 1e-10
    # the potential is a minimum along the feasible set
    def V(phi_):
        q = np.array([c * np.sin(phi_), -c * np.cos(phi_), phi_ - np.pi / 2])
        return model.energy(0.0, q, np.zeros(3))
    assert V(phi) < V(phi + 1e-3) and V(phi) < V(phi - 1e-3)
    # pivot reaction balances gravity and the spring: R = −m g − k (A − P)
    P = Lr * np.array([np.sin(phi), -np.cos(phi)])
    R_expected = -m * np.array([0.0, -G]) - k * (np.array([a, 0.0]) - P)
    np.testing.assert_allclose(res.reactions["pivot"][:2], R_expected, atol=1e-8)
    tab = res.reactions_table()
    assert tab.loc["pivot", "Fx [N]"] == pytest.approx(R_expected[0], abs=1e-8)
    assert list(res.coordinates().columns) == model.coordinate_names


def test_static_equilibrium_finds_unstable_point_and_flags_it():
    model, m, c, Jc = compound_pendulum(theta0=np.pi / 2 + 0.05)  # near the upright position
    res = A.static_equilibrium(model, method="newton")
    assert res.q[2] == pytest.approx(np.pi / 2, abs=1e-10)
    # orthonormal N in (x, y, θ): the rotation mode is (−c sin θ, c cos θ, 1)/√(1 + c²)
    assert not res.stable and res.min_stiffness * (1 + c * c) == pytest.approx(-m * G * c, rel=1e-6)
    # the energy method descends to the stable hanging position from the same guess
    res_e = A.static_equilibrium(model, method="energy")
    assert np.cos(res_e.q[2]) == pytest.approx(0.0, abs=1e-10) and np.sin(res_e.q[2]) == pytest.approx(-1.0)
    assert res_e.stable and res_e.min_stiffness * (1 + c * c) == pytest.approx(m * G * c, rel=1e-6)


# ------------------------------------------------------------------------------------------------
# inverse dynamics
# ------------------------------------------------------------------------------------------------


def test_inverse_dynamics_driven_compound_pendulum():
    th0, amp, w = 0.2, 0.7, 3.0
    model, m, c, Jc = compound_pendulum(theta0=th0, motion=harmonic(amp, w))
    times = np.linspace(0.0, 2.0, 41)
    kin = A.kinematic_analysis(model, times)
    inv = A.inverse_dynamics_from_kinematics(model, kin)
    th = th0 + amp * np.sin(w * times)
    thdd = -amp * w * w * np.sin(w * times)
    tau = (Jc + m * c * c) * thdd + m * G * c * np.cos(th)
    np.testing.assert_allclose(inv["drive effort [N m]"], tau, atol=1e-9)
    # the driver's reaction moment on the rod is the same torque
    np.testing.assert_allclose(inv["drive.Mz [N m]"], tau, atol=1e-9)
    assert inv["residual"].max() < 1e-10


def test_inverse_dynamics_recovers_applied_torque_from_simulation():
    from core.integrators import simulate

    T = lambda t: 2.0 * np.sin(3.0 * t) + 0.5  # noqa: E731
    actuated = double_pendulum(torque=T)
    q0 = actuated.q0.copy()
    res = simulate(actuated, (0.0, 1.0), method="dop853-projection", t_eval=np.linspace(0, 1, 401),
                   rtol=1e-11, atol=1e-12)
    assert res.success
    # forward accelerations on the actuated model: dynamically consistent (residual ≈ 0)
    fwd = A.inverse_dynamics_from_result(actuated, res, method="forward")
    assert fwd["residual"].max() < 1e-9
    # the same motion imposed on a driven twin without the torque: the driver efforts are the torques
    twin = double_pendulum(drivers=True)
    np.testing.assert_allclose(twin.q0, q0)
    acc = np.array([accelerations(actuated, t, q, v)[0] for t, q, v in zip(res.t, res.q, res.v)])
    inv = A.inverse_dynamics(twin, res.t, res.q, res.v, acc)
    np.testing.assert_allclose(inv["d1 effort [N m]"], T(res.t), atol=1e-9)
    np.testing.assert_allclose(inv["d2 effort [N m]"], 0.0, atol=1e-9)
    # accelerations by spline differentiation of the sampled velocities (independent of the KKT)
    inv_d = A.inverse_dynamics_from_result(twin, res, method="differentiate")
    inner = slice(10, -10)  # spline end conditions
    np.testing.assert_allclose(inv_d["d1 effort [N m]"].to_numpy()[inner], T(res.t)[inner], atol=1e-5)


def test_redundant_constraints_min_norm_multipliers():
    """Pendulum with a revolute plus a (redundant) pivot–centre distance constraint."""
    m, Lr, th0 = 2.0, 0.8, -np.pi / 2 + 0.4
    c, Jc = Lr / 2, m * Lr**2 / 12

    def build(redundant):
        b = ModelBuilder(2, "redundant-pendulum")
        b.add_body("rod", m, Jc, (c * np.cos(th0), c * np.sin(th0)), orientation=th0)
        b.add_revolute("pivot", "ground", "rod", (0.0, 0.0))
        if redundant:
            b.add_distance("link", "ground", "rod", (0.0, 0.0), (c * np.cos(th0), c * np.sin(th0)))
        with pytest.warns(UserWarning) if redundant else _nullcontext():
            return b.build(assemble=True, redundant="keep")

    red, ref = build(True), build(False)
    assert red.n_c == 3 and len(red.redundant_rows) == 1
    # assembly from a rough guess with redundant rows
    q, _ = A.assemble_state(red, red.q0 + np.array([0.03, -0.02, 0.05]))
    assert np.max(np.abs(red.Phi(0.0, q))) < 1e-10
    # inverse dynamics of a free swing: a from the reference (non-redundant) forward dynamics
    v = np.array([0.0, 0.0, 1.3])
    v = A.assemble_state(red, red.q0, v)[1]
    a_ref, lam_ref = accelerations(ref, 0.0, red.q0, v)
    inv = A.inverse_dynamics(red, [0.0], red.q0[None], v[None], a_ref[None])
    lam = inv[[c_ for c_ in inv.columns if c_.startswith("lambda[")]].to_numpy()[0]
    J = red.Phi_q(0.0, red.q0).toarray()
    Jref = ref.Phi_q(0.0, red.q0).toarray()
    np.testing.assert_allclose(J.T @ lam, Jref.T @ lam_ref, atol=1e-10)  # same constraint force
    assert inv["residual"].iloc[0] < 1e-10
    # minimum norm: λ lies in the row space of Φ_q, i.e. is orthogonal to the null space of Φ_qᵀ
    nullJt = sla.null_space(J.T)
    assert nullJt.shape[1] == 1 and abs(nullJt[:, 0] @ lam) < 1e-10
    # statics and linearisation cope with the redundancy
    st = A.static_equilibrium(red)
    assert st.q[2] == pytest.approx(-np.pi / 2, abs=1e-10)
    tab, _ = A.eigen(red, st.q, lam=st.lam)
    assert len(tab) == 1
    assert 2 * np.pi * tab["frequency [Hz]"].iloc[0] == pytest.approx(np.sqrt(m * G * c / (Jc + m * c * c)), rel=1e-7)


class _nullcontext:
    def __enter__(self):
        return None

    def __exit__(self, *a):
        return False


# ------------------------------------------------------------------------------------------------
# linearisation and eigenanalysis
# ------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("spatial", [False, True])
def test_compound_pendulum_frequency(spatial):
    model, m, c, Jc = compound_pendulum(spatial=spatial)
    st = A.static_equilibrium(model)
    lin = A.linearize(model, st.q, lam=st.lam)
    assert lin.n_dof == 1
    w_exact = np.sqrt(m * G * c / (Jc + m * c * c))
    # hanging down the stiffness is entirely the constraint-force (geometric) term
    np.testing.assert_allclose(lin.K, lin.K_geometric, atol=1e-8 * abs(lin.K[0, 0]))
    tab, modes = A.eigen(lin)
    assert 2 * np.pi * tab["frequency [Hz]"].iloc[0] == pytest.approx(w_exact, rel=1e-7)
    assert tab["damping ratio [-]"].iloc[0] == pytest.approx(0.0, abs=1e-9)
    # the mode is a rotation about the pivot: |v_cm| = c |ω|
    mv = modes.iloc[:, 0].to_numpy()
    if spatial:
        assert np.linalg.norm(mv[:3]) == pytest.approx(c * abs(mv[3]), rel=1e-7)
        np.testing.assert_allclose(mv[4:], 0.0, atol=1e-9)
    else:
        assert np.linalg.norm(mv[:2]) == pytest.approx(c * abs(mv[2]), rel=1e-7)


def test_point_pendulum_generalized_coordinates():
    sys_ = PointPendulum(length=0.5, mass=0.3)
    st = A.static_equilibrium(sys_)
    np.testing.assert_allclose(st.q, [0.0, -0.5], atol=1e-10)
    tab, _ = A.eigen(sys_, st.q)
    assert 2 * np.pi * tab["frequency [Hz]"].iloc[0] == pytest.approx(np.sqrt(G / 0.5), rel=1e-7)


def test_mass_spring_damper_frequency_and_damping():
    m, k, cd = 1.5, 600.0, 3.0
    b = ModelBuilder(2, "mass-spring")
    b.add_body("mass", m, 0.01, (0.0, 0.0))
    b.add_translational("slide", "ground", "mass", (0.0, 0.0), (1.0, 0.0))
    b.add_spring_damper("spring", "ground", "mass", (-1.0, 0.0), (0.0, 0.0), stiffness=k, damping=cd)
    model = b.build()
    tab, modes = A.eigen(model)
    wn = np.sqrt(k / m)
    zeta = cd / (2 * np.sqrt(k * m))
    assert 2 * np.pi * tab["natural frequency [Hz]"].iloc[0] == pytest.approx(wn, rel=1e-9)
    assert tab["damping ratio [-]"].iloc[0] == pytest.approx(zeta, rel=1e-9)
    assert 2 * np.pi * tab["frequency [Hz]"].iloc[0] == pytest.approx(wn * np.sqrt(1 - zeta**2), rel=1e-9)
    np.testing.assert_allclose(np.abs(modes.iloc[:, 0].to_numpy()), [1.0, 0.0, 0.0], atol=1e-12)


def test_double_pendulum_frequencies():
    m1, L1, m2, L2 = 1.0, 1.0, 0.7, 0.6
    model = double_pendulum(m1, L1, m2, L2)
    st = A.static_equilibrium(model)
    tab, _ = A.eigen(model, st.q, lam=st.lam)
    # angles from the downward vertical: T = ½θ̇ᵀMθ̇, V ≈ ½θᵀKθ
    J1, J2, c1, c2 = m1 * L1**2 / 12, m2 * L2**2 / 12, L1 / 2, L2 / 2
    Mth = np.array([[J1 + m1 * c1**2 + m2 * L1**2, m2 * L1 * c2], [m2 * L1 * c2, J2 + m2 * c2**2]])
    Kth = G * np.diag([m1 * c1 + m2 * L1, m2 * c2])
    w = np.sqrt(sla.eigh(Kth, Mth, eigvals_only=True))
    np.testing.assert_allclose(2 * np.pi * tab["frequency [Hz]"].to_numpy(), np.sort(w), rtol=1e-7)
    assert isinstance(tab, pd.DataFrame) and "damping ratio [-]" in tab.columns
