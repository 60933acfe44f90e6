r"""Inverse dynamics of spatial OpenSim models in generalized coordinates (biomech.spatial_dynamics).

Oracles, each independent of the module's route (Newton–Euler projected on analytic Jacobians):

1. Tier 1, closed form: a body hung from ground by a two-axis CustomJoint (ψ about the vertical,
   then θ about the tilted x axis), centre of mass a distance l below the joint, principal central
   inertia diag(A, B, C).  Lagrange's equations of L = ½(ml² + A)θ̇² + ½K(θ)ψ̇² + mgl cos θ,
   K = (ml² + C) sin²θ + B cos²θ, give

       τ_ψ = K ψ̈ + 2(ml² + C − B) sin θ cos θ θ̇ ψ̇,
       τ_θ = (ml² + A) θ̈ − (ml² + C − B) sin θ cos θ ψ̇² + mgl sin θ,

   minus the generalized forces F·∂P/∂q + T·∂ω/∂q̇ of a load at a body point P at distance l'.
2. The planar Cartesian-core pipeline (:func:`biomech.inverse_dynamics.inverse_dynamics`:
   absolute coordinates, driving constraints, Lagrange multipliers) on gait10dof18musc.
3. OpenSim 4.6's InverseDynamicsTool on gait2392 (when ``import opensim`` works).
4. Properties: the analytic J̇q̇ (recursion) against central differences of the Jacobians, and
   τ linear in q̈ with a symmetric positive-definite M(q).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy.interpolate import CubicSpline

from core.errors import InputError, ModelError
from core.paths import data_path
from biomech.inverse_dynamics import GaitTrial, inverse_dynamics, load_trial
from biomech.osim import read_osim
from biomech.spatial_dynamics import SpatialInverseDynamics, spatial_inverse_dynamics
from biomech.storage import ExternalForceData, ExternalForceSpec, ExternalLoads, ExternalLoadsSpec

OPENSIM = data_path("biomech", "opensim")
G10 = OPENSIM / "gait10dof18musc_subject01_walk"
G2392 = OPENSIM / "gait2392_subject01_walk"
G2392_FILES = (G2392 / "subject01_simbody_adjusted.osim", G2392 / "subject01_walk1_ik.mot",
               G2392 / "subject01_walk1_grf.xml")

_cache: dict = {}


def gait2392_trial():
    # the GRF file covers 0-2.5 s, the IK file 0.5-4 s: load_trial's default window is the common one
    if "g2392" not in _cache:
        _cache["g2392"] = load_trial(*G2392_FILES, order=3)
    return _cache["g2392"]


# ---------------------------------------------------------------------------------------------
# tier 1: a two-axis pendulum in closed form
# ---------------------------------------------------------------------------------------------

M, L, L_LOAD, A, B, C = 2.5, 0.4, 0.7, 0.04, 0.03, 0.06   # kg, m, m, kg m² (A + B > C etc.)
H = 0.25      # the joint frame sits 0.25 m above the body origin (exercises the child offset)
PIVOT = np.array([0.1, 1.2, -0.05])


def _axis(name, coord, axis, linear):
    fn = ("<LinearFunction name=\"function\"><coefficients>1 0</coefficients></LinearFunction>" if linear
          else "<Constant name=\"function\"><value>0</value></Constant>")
    return (f"<TransformAxis name=\"{name}\"><coordinates>{coord}</coordinates><axis>{axis}</axis>{fn}"
            f"</TransformAxis>")


def write_pendulum(tmp_path):
    axes = (_axis("rotation1", "psi", "0 1 0", True) + _axis("rotation2", "theta", "1 0 0", True)
            + _axis("rotation3", "", "0 0 1", False) + _axis("translation1", "", "1 0 0", False)
            + _axis("translation2", "", "0 1 0", False) + _axis("translation3", "", "0 0 1", False))
    coord = ("<Coordinate name=\"{}\"><default_value>0</default_value><range>-10 10</range>"
             "<clamped>false</clamped><locked>false</locked></Coordinate>")
    text = f"""<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
  <Model name="pendulum">
    <Ground name="ground"/>
    <gravity>0 -9.80665 0</gravity>
    <length_units>meters</length_units>
    <force_units>N</force_units>
    <BodySet name="bodyset"><objects>
      <Body name="bob">
        <mass>{M}</mass>
        <mass_center>0 {H - L} 0</mass_center>
        <inertia>{A} {B} {C} 0 0 0</inertia>
      </Body>
    </objects></BodySet>
    <JointSet name="jointset"><objects>
      <CustomJoint name="swing">
        <socket_parent_frame>ground_offset</socket_parent_frame>
        <socket_child_frame>bob_offset</socket_child_frame>
        <coordinates>{coord.format("psi")}{coord.format("theta")}</coordinates>
        <frames>
          <PhysicalOffsetFrame name="ground_offset"><socket_parent>/ground</socket_parent>
            <translation>{PIVOT[0]} {PIVOT[1]} {PIVOT[2]}</translation><orientation>0 0 0</orientation>
          </PhysicalOffsetFrame>
          <PhysicalOffsetFrame name="bob_offset"><socket_parent>/bodyset/bob</socket_parent>
            <translation>0 {H} 0</translation><orientation>0 0 0</orientation>
          </PhysicalOffsetFrame>
        </frames>
        <SpatialTransform>{axes}</SpatialTransform>
      </CustomJoint>
    </objects></JointSet>
  </Model>
</OpenSimDocument>
"""
    path = tmp_path / "pendulum.osim"
    path.write_text(text)
    return path


def pendulum_motion(t):
    psi = 0.3 + 2.0 * t + 0.5 * np.sin(3.0 * t)
    psid = 2.0 + 1.5 * np.cos(3.0 * t)
    psidd = -4.5 * np.sin(3.0 * t)
    th = 0.6 + 0.4 * np.sin(2.0 * t + 0.1)
    thd = 0.8 * np.cos(2.0 * t + 0.1)
    thdd = -1.6 * np.sin(2.0 * t + 0.1)
    return (np.column_stack([psi, th]), np.column_stack([psid, thd]), np.column_stack([psidd, thdd]))


def pendulum_loads(t, psi, th):
    n = len(t)
    rng = np.random.default_rng(7)
    F = rng.normal(0.0, 20.0, (n, 3))
    T = rng.normal(0.0, 2.0, (n, 3))
    # the load point: on the body, l' below the joint (given in ground, as a centre of pressure)
    P = PIVOT - L_LOAD * np.column_stack([np.sin(psi) * np.sin(th), np.cos(th), np.cos(psi) * np.sin(th)])
    spec = ExternalForceSpec("push", "bob", "ground", "ground", "F", "P", "T", None, True)
    data = ExternalForceData(spec, t, F, P, T, {})
    loads = ExternalLoads(ExternalLoadsSpec("loads", "memory", None, (spec,)), "memory", t, (data,))
    return loads, F, P, T


def pendulum_closed_form(q, qd, qdd, F, T):
    psi, th = q.T
    psid, thd = qd.T
    psidd, thdd = qdd.T
    g = 9.80665
    s, c = np.sin(th), np.cos(th)
    K = (M * L**2 + C) * s**2 + B * c**2
    k = M * L**2 + C - B
    tau_psi = K * psidd + 2.0 * k * s * c * thd * psid
    tau_th = (M * L**2 + A) * thdd - k * s * c * psid**2 + M * g * L * s
    # generalized forces of the load: dP/dq for P = pivot - l' (sin psi sin th, cos th, cos psi sin th)
    dP_dpsi = -L_LOAD * np.column_stack([np.cos(psi) * s, 0 * s, -np.sin(psi) * s])
    dP_dth = -L_LOAD * np.column_stack([np.sin(psi) * c, -s, np.cos(psi) * c])
    dw_dpsi = np.array([0.0, 1.0, 0.0])
    dw_dth = np.column_stack([np.cos(psi), 0 * psi, -np.sin(psi)])
    Q_psi = np.sum(F * dP_dpsi, axis=1) + T @ dw_dpsi
    Q_th = np.sum(F * dP_dth, axis=1) + np.sum(T * dw_dth, axis=1)
    return np.column_stack([tau_psi - Q_psi, tau_th - Q_th])


@pytest.mark.parametrize("bias", ["analytic", "central"])
def test_two_axis_pendulum_equals_lagranges_equations(tmp_path, bias):
    osim = read_osim(write_pendulum(tmp_path))
    t = np.linspace(0.0, 2.0, 9)
    q, qd, qdd = pendulum_motion(t)
    loads, F, P, T = pendulum_loads(t, q[:, 0], q[:, 1])

    def frame(x):
        df = pd.DataFrame(x, columns=["psi", "theta"])
        df.insert(0, "time", t)
        return df

    trial = GaitTrial(osim, SimpleNamespace(q=frame(q), qdot=frame(qd), qddot=frame(qdd)), loads, (0.0, 2.0))
    out = spatial_inverse_dynamics(trial, bias=bias)
    assert list(out.columns) == ["time [s]", "psi_moment [N m]", "theta_moment [N m]"]
    ref = pendulum_closed_form(q, qd, qdd, F, T)
    # analytic: rounding only (|tau| ~ 10 N m, ~50 operations: ~1e-13); central difference, Eq. (7):
    # truncation delta^2/6 |J'''| |qdot|^2 ~ 1e-10 and rounding eps/delta |J| |qdot|^2 ~ 1e-10 N m
    tol = 1e-10 if bias == "analytic" else 1e-7
    np.testing.assert_allclose(out.iloc[:, 1:].to_numpy(), ref, rtol=0, atol=tol)


def test_the_load_point_in_a_body_frame_and_a_missing_point_follow_opensim(tmp_path):
    # OpenSim's ExternalForce: point expressed in point_expressed_in_body, force and torque in
    # force_expressed_in_body; without a point the force acts at the body origin
    osim = read_osim(write_pendulum(tmp_path))
    sid = SpatialInverseDynamics(osim)
    t = np.array([0.0, 0.4])
    q, qd, qdd = pendulum_motion(t)
    loads, F, P, T = pendulum_loads(t, q[:, 0], q[:, 1])
    motion = sid.body_motion(q, qd, qdd)
    ref = sid.external_forces(motion, loads)
    R, x = motion.rotation[:, 0], motion.origin[:, 0]
    f = loads.forces[0]
    local = np.einsum("nji,nj->ni", R, P - x)                     # the same point, in the body frame
    Fb, Tb = np.einsum("nji,nj->ni", R, F), np.einsum("nji,nj->ni", R, T)
    spec = ExternalForceSpec("push", "bob", "bob", "bob", "F", "P", "T", None, True)
    moved = ExternalLoads(loads.spec, "memory", t, (ExternalForceData(spec, t, Fb, local, Tb, {}),))
    np.testing.assert_allclose(sid.external_forces(motion, moved), ref, rtol=0, atol=1e-12)
    no_point = ExternalLoads(loads.spec, "memory", t, (ExternalForceData(f.spec, t, F, None, None, {}),))
    at_origin = ExternalLoads(loads.spec, "memory", t, (ExternalForceData(f.spec, t, F, x, None, {}),))
    np.testing.assert_allclose(sid.external_forces(motion, no_point), sid.external_forces(motion, at_origin),
                               rtol=0, atol=1e-12)


def test_bad_inputs_name_what_is_at_fault(tmp_path):
    osim = read_osim(write_pendulum(tmp_path))
    with pytest.raises(InputError, match="bias"):
        SpatialInverseDynamics(osim, bias="forward")
    sid = SpatialInverseDynamics(osim)
    t = np.array([0.0, 0.4])
    q, qd, qdd = pendulum_motion(t)
    loads, *_ = pendulum_loads(t, q[:, 0], q[:, 1])
    f = loads.forces[0]
    wrong = ExternalForceSpec("push", "calcn_r", "ground", "ground", "F", "P", "T", None, True)
    bad = ExternalLoads(loads.spec, "grf.mot", t, (ExternalForceData(wrong, t, f.force, f.point, f.torque, {}),))
    with pytest.raises(ModelError, match=r"'push'.*grf\.mot.*'calcn_r'"):
        sid.external_forces(sid.body_motion(q, qd, qdd), bad)
    with pytest.raises(InputError, match="grf.mot.*3 frames|sampled at 2 times"):
        sid.external_forces(sid.body_motion(np.vstack([q, q[:1]]), 0.0, 0.0), bad)
    with pytest.raises(InputError, match="qdot.*'theta'"):
        sid.body_motion(q, np.array([[0.0, np.nan], [0.0, 0.0]]), 0.0)


# ---------------------------------------------------------------------------------------------
# the planar model: equal to the Cartesian-core pipeline
# ---------------------------------------------------------------------------------------------


def test_planar_model_equals_the_cartesian_core_pipeline():
    # a window around the right heel strike (0.618 s): both feet loaded, fast motion
    trial = load_trial(G10 / "subject01.osim", G10 / "subject01_walk_IK.mot", G10 / "subject01_walk_grf.xml",
                       window=(0.55, 0.75), order=3)
    ref = inverse_dynamics(trial)
    out = spatial_inverse_dynamics(trial)
    assert list(out.columns) == list(ref.columns)
    np.testing.assert_array_equal(out["time [s]"], ref["time [s]"])
    # the Cartesian pipeline solves Phi = 0 and the driven mechanism's velocities/accelerations to
    # its kinematic tolerance; the two routes agreed to ~1e-12 N m when written (1e-3 is the brief's bound)
    np.testing.assert_allclose(out.iloc[:, 1:].to_numpy(), ref[out.columns[1:]].to_numpy(), rtol=0, atol=1e-3)


# ---------------------------------------------------------------------------------------------
# properties on gait2392
# ---------------------------------------------------------------------------------------------


def test_analytic_bias_accelerations_equal_central_differences_of_the_jacobians():
    trial = gait2392_trial()
    K = trial.kinematics
    frames = slice(20, 120, 20)
    q, qd = K.q.iloc[frames], K.qdot.iloc[frames]
    an = SpatialInverseDynamics(trial.osim).body_motion(q, qd, 0.0)
    cd = SpatialInverseDynamics(trial.osim, bias="central").body_motion(q, qd, 0.0)
    # Eq. (7): truncation + rounding ~1e-10 |J| |qdot|^2; |qdot| <~ 10 rad/s, |J| <~ 2 m here
    scale = np.max(np.abs(qd.drop(columns="time").to_numpy())) ** 2
    assert np.max(np.abs(an.com_bias - cd.com_bias)) < 1e-8 * scale
    assert np.max(np.abs(an.angular_bias - cd.angular_bias)) < 1e-8 * scale
    # and the bias is not trivially small: the gyroscopic and centripetal terms matter in gait
    assert np.max(np.abs(an.com_bias)) > 1.0


def test_generalized_forces_are_linear_in_qddot_with_a_positive_definite_mass_matrix():
    trial = gait2392_trial()
    K = trial.kinematics
    sid = SpatialInverseDynamics(trial.osim)
    k = [10, 60]
    q = K.q.iloc[k]
    qd = K.qdot.iloc[k]
    qdd = K.qddot.iloc[k].drop(columns="time").to_numpy()
    Mq = sid.mass_matrix(q)
    tau = sid.generalized_forces(q, qd, qdd)
    tau0 = sid.generalized_forces(q, qd, 0.0)
    np.testing.assert_allclose(tau - tau0, np.einsum("nij,nj->ni", Mq, qdd), rtol=0, atol=1e-9)
    np.testing.assert_allclose(Mq, np.swapaxes(Mq, 1, 2), rtol=0, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(Mq) > 0)


# ---------------------------------------------------------------------------------------------
# gait2392 against OpenSim 4.6
# ---------------------------------------------------------------------------------------------


def test_gait2392_agrees_with_opensims_inverse_dynamics_tool(tmp_path):
    pytest.importorskip("opensim")
    from biomech.opensim_peer import run_inverse_dynamics

    trial = gait2392_trial()
    out = spatial_inverse_dynamics(trial)
    t = out["time [s]"].to_numpy()
    assert (t[0], t[-1], len(t)) == (pytest.approx(0.5), pytest.approx(2.5), 121)
    peer, _ = run_inverse_dynamics(*G2392_FILES, t[0], t[-1], out_dir=tmp_path)
    tp = peer["time"].to_numpy()
    assert len(tp) == len(t)
    # OpenSim evaluates on its padded, filtered storage, whose times sit up to 1.5 us before the
    # file's (0.4999993 s ...); compare at OpenSim's times (our tau by a cubic spline in time)
    assert np.max(np.abs(tp - t)) < 2e-6
    rms = {}
    for col in out.columns[1:]:
        name = col.split(" [")[0]
        d = CubicSpline(t, out[col].to_numpy())(tp) - peer[name].to_numpy()
        rms[name] = float(np.sqrt(np.mean(d**2)))
        # Same equations, filter (3rd-order Butterworth, forward-backward, padded by reflection),
        # quintic spline and cubic GRF spline on both sides: what remains are the filters' start-up
        # conditions, OpenSim's 8-digit output and the interpolation onto its times, measured at
        # <= 2e-3 N m (N) (rms <= 5e-4).  An error in the model terms would be far larger: a 1 mm
        # error of the centre-of-pressure arm under 700 N is 0.7 N m, the thigh's gyroscopic term
        # omega x I omega ~ 0.1 kg m^2 (5 rad/s)^2 = 2.5 N m.
        assert np.max(np.abs(d)) < 1e-2, (name, np.max(np.abs(d)))
    assert max(rms.values()) < 2e-3, rms
