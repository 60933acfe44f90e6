"""Gait inverse dynamics on the Cartesian core against an independent computation.

Oracle: the equations of motion in the model's own coordinates, written from the planar forward
kinematics alone (no core, no constraints):

    tau = sum_b [ J_b^T m_b (a_b - g) + j_b^T I_b alpha_b ] - J_P^T F - j_calcn^T T_z

with J_b = d(centre of mass)/dq and j_b = d(angle)/dq by central differences in q, and
a_b = J_b qdd + (q' H q') from a second central difference along qdot.  The Cartesian model
gets the same numbers from its driving constraints' multipliers.
"""

from pathlib import Path

import numpy as np
import pytest

from biomech.inverse_dynamics import gait_events, inverse_dynamics, load_trial
from biomech.sagittal import planar_forward_kinematics

DATA = Path(__file__).resolve().parents[2] / "data" / "biomech" / "opensim" / "gait10dof18musc_subject01_walk"


@pytest.fixture(scope="module")
def trial():
    # a short window around the right heel strike (0.618 s): both feet loaded, fast motion
    return load_trial(DATA / "subject01.osim", DATA / "subject01_walk_IK.mot", DATA / "subject01_walk_grf.xml",
                      window=(0.55, 0.75))


def _oracle(trial, k):
    osim = trial.osim
    names = [c.name for c in osim.coordinates]
    K = trial.kinematics
    q = np.array([K.q[c].iloc[k] for c in names])
    qd = np.array([K.qdot[c].iloc[k] for c in names])
    qdd = np.array([K.qddot[c].iloc[k] for c in names])
    n = len(q)

    def fk(x):
        return planar_forward_kinematics(osim, dict(zip(names, x)))

    base = fk(q)
    h = 1e-6
    J = {b: np.zeros((2, n)) for b in base}
    jt = {b: np.zeros(n) for b in base}
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        fp, fm = fk(q + e), fk(q - e)
        for b in base:
            J[b][:, i] = (fp[b][2][0] - fm[b][2][0]) / (2 * h)
            jt[b][i] = (fp[b][1][0] - fm[b][1][0]) / (2 * h)
    hq = 1e-4
    fp, fm = fk(q + hq * qd), fk(q - hq * qd)
    g = np.asarray(osim.gravity, float)[:2]
    tau = np.zeros(n)
    for body in osim.bodies:
        b = body.name
        quad = (fp[b][2][0] - 2 * base[b][2][0] + fm[b][2][0]) / hq**2
        quad_t = (fp[b][1][0] - 2 * base[b][1][0] + fm[b][1][0]) / hq**2
        a = J[b] @ qdd + quad
        alpha = jt[b] @ qdd + quad_t
        tau += J[b].T @ (body.mass * (a - g)) + jt[b] * float(body.inertia[2, 2]) * alpha
    for f in trial.loads.forces:
        b = f.spec.applied_to_body
        F, p, T = f.force[k, :2], f.point[k, :2], f.torque[k, 2]
        arm = p - base[b][2][0]
        Jp = J[b] + np.outer([-arm[1], arm[0]], jt[b])
        tau -= Jp.T @ F + jt[b] * T
    return names, tau


@pytest.fixture(scope="module")
def moments(trial):
    return inverse_dynamics(trial)


def test_driven_mechanism_is_consistent(moments):
    # the motion is fully prescribed: Phi_q^T lambda = Q - M a has an exact solution
    assert moments.attrs["max_residual"] < 1e-8
    assert moments.attrs["kinematic_status"] == "finished"


def test_all_frames_at_once_equal_frame_by_frame(trial, moments, monkeypatch):
    """The sagittal joints evaluate all frames in one call, core solves every frame side by side
    (the batched path is taken), and the moments equal those of the frame-by-frame analyses."""
    from core import analysis as A
    from biomech.sagittal import build_sagittal_model

    sm = build_sagittal_model(trial.osim, trial.kinematics, trial.loads)
    times = trial.kinematics.q["time"].to_numpy(float)
    assert sm.model.frames_vectorised
    assert A._kinematic_frames(sm.model, times, sm.q_frames, 1e-10, 50) is not None
    monkeypatch.setattr(A, "_kinematic_frames", lambda *args: None)
    monkeypatch.setattr(A, "_inverse_dynamics_frames", lambda *args: None)
    slow = inverse_dynamics(trial)
    cols = list(moments.columns)
    assert cols == list(slow.columns)
    # both solve the same equations to the kinematic tolerance 1e-10 (quadratic last Newton step)
    np.testing.assert_allclose(moments[cols].to_numpy(), slow[cols].to_numpy(), rtol=0, atol=1e-8)


@pytest.mark.parametrize("k", [0, 4, 8, 12])
def test_moments_equal_the_equations_in_the_model_coordinates(trial, moments, k):
    names, tau = _oracle(trial, k)
    ctype = {c.name: c.motion_type for c in trial.osim.coordinates}
    for name, ref in zip(names, tau):
        col = f"{name}_moment [N m]" if ctype[name] == "rotational" else f"{name}_force [N]"
        # finite differences: O(h^2) in the Jacobians (1e-12 relative), O(hq^2 qdot^2) ~ 1e-7
        # relative and roundoff eps/hq^2 ~ 2e-8 m/s^2 in the accelerations: far below 1e-3
        assert moments[col].iloc[k] == pytest.approx(ref, abs=1e-3), name


def test_gait_events_of_the_trial(trial):
    full = load_trial(DATA / "subject01.osim", DATA / "subject01_walk_IK.mot", DATA / "subject01_walk_grf.xml")
    hs, to = gait_events(full.loads, "calcn_r")
    # the trial's events (data/biomech/README.md): right heel strikes 0.618 s and 1.853 s, toe-off 1.41 s
    assert hs == pytest.approx([0.618, 1.853], abs=5e-3)
    assert 1.41 == pytest.approx(to[to > 1.0][0], abs=5e-3)
    assert trial.body_mass == pytest.approx(72.6, abs=0.05)


def test_window_outside_the_force_data_names_the_files():
    from core.errors import DataRangeError

    with pytest.raises(DataRangeError, match="subject01_walk_IK.mot"):
        load_trial(DATA / "subject01.osim", DATA / "subject01_walk_IK.mot", DATA / "subject01_walk_grf.xml",
                   window=(0.5, 3.0))


def test_joint_reactions_balance_the_foot(trial, moments):
    """Newton's law for the right foot (talus, calcaneus, toes welded): the ankle reaction on the
    talus plus the ground reaction plus gravity equals the feet's mass times their centre-of-mass
    acceleration (accelerations from core's kinematic analysis, an independent use of them)."""
    R = moments.attrs["joint_reactions"]
    cart = moments.attrs["cartesian"]
    sm_bodies = [b.name for b in trial.osim.bodies]
    g = np.asarray(trial.osim.gravity, float)[:2]
    grf = next(f for f in trial.loads.forces if f.spec.applied_to_body == "calcn_r")
    for k in (0, 6, 12):
        ma = np.zeros(2)
        for name in ("talus_r", "calcn_r", "toes_r"):
            b = sm_bodies.index(name)
            body = trial.osim.bodies[b]
            ma += body.mass * (cart["a"][k][3 * b:3 * b + 2] - g)
        F = np.array([R["ankle_r_on_talus_r_Fx [N]"].iloc[k], R["ankle_r_on_talus_r_Fy [N]"].iloc[k]])
        np.testing.assert_allclose(F + grf.force[k, :2], ma, atol=1e-6 * np.abs(ma).max() + 1e-8)
