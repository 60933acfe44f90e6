"""Muscle forces over the gait trial: moment arms two ways, optimality of the per-frame solutions.

* Moment arms -dL/dq of the paths (biomech.skeleton) against the generalized-force map of the
  Cartesian core: a unit tension applied as point forces on the segments of the driven Cartesian
  model changes the multipliers by d(lambda) with Phi_q^T d(lambda) = Q_muscle, hence the
  coordinates' generalized forces by -r (the actuators need r less); a moving path point adds
  its own term f . R du/dq (its location moves in its body with the coordinate).
* Static optimisation on the real trial (tier 3): the moment equations at every frame, the
  bounds, and the optimum of the activation criterion against scipy's SLSQP.
"""

from pathlib import Path

import numpy as np
import pytest

from biomech.inverse_dynamics import inverse_dynamics, load_trial
from biomech.muscle_forces import muscle_inputs, muscle_redundancy, reserve_optimal_forces
from biomech.osim import MovingPathPoint, read_force_set
from biomech.sagittal import build_sagittal_model
from biomech.skeleton import Skeleton
from core.dynamics import minimum_norm_multipliers

DATA = Path(__file__).resolve().parents[2] / "data" / "biomech" / "opensim" / "gait10dof18musc_subject01_walk"


@pytest.fixture(scope="module")
def trial():
    return load_trial(DATA / "subject01.osim", DATA / "subject01_walk_IK.mot", DATA / "subject01_walk_grf.xml",
                      window=(0.8, 1.0))


@pytest.fixture(scope="module")
def moments(trial):
    return inverse_dynamics(trial)


@pytest.fixture(scope="module")
def inputs(trial, moments):
    return muscle_inputs(trial, moments)


@pytest.mark.parametrize("k", [0, 6])
def test_moment_arms_equal_the_cartesian_force_map(trial, moments, k):
    sm = build_sagittal_model(trial.osim, trial.kinematics, trial.loads)
    m = sm.model
    t = float(trial.kinematics.q["time"].iloc[k])
    q_cart = moments.attrs["cartesian"]["q"][k]
    J = m.Phi_q(t, q_cart)
    sk = Skeleton(trial.osim)
    names = list(sk.coordinate_names)
    qk = np.array([trial.kinematics.q[c].iloc[k] for c in names])
    geom = sk.muscle_geometry(qk[None, :])
    for j, mus in enumerate(sk.muscle_names):
        path = sk.muscle_path(mus, qk[None, :])
        P = path.positions
        u = np.diff(P, axis=0)
        u /= np.linalg.norm(u, axis=1)[:, None]
        f = np.zeros_like(P)  # unit tension pulls each point towards its neighbours
        f[:-1] += u
        f[1:] -= u
        Q = np.zeros(m.n_v)
        extra = np.zeros(len(names))
        points = {p.name: p for p in trial.osim.muscle(mus).path}
        for i, b in enumerate(path.bodies):
            sl = m.v_slice(b)
            rb = q_cart[m.q_slice(b)][:2]
            arm = P[i, :2] - rb
            Q[sl] += [f[i, 0], f[i, 1], arm[0] * f[i, 1] - arm[1] * f[i, 0]]
            pt = points[path.point_names[i]]
            if isinstance(pt, MovingPathPoint):  # f . R_b du/dq for the coordinates it moves with
                R = sk.forward_kinematics(qk[None, :]).rotation[0, sk.body_index(b)]
                for c in names:
                    du = pt.location_derivative(dict(zip(names, qk)), c)
                    extra[names.index(c)] += f[i] @ (R @ du)
        dlam, res = minimum_norm_multipliers(J, Q)
        assert res < 1e-9
        tau = {}
        for uc in sm.joints:
            for c, v in zip(uc.jt.coordinates, uc.generalized_forces(q_cart, t, dlam[sm.rows[uc.name]])):
                tau[c] = v
        r_core = np.array([-tau[c] for c in names]) + extra
        np.testing.assert_allclose(r_core, geom.moment_arm[0, j], atol=1e-10, err_msg=mus)


@pytest.fixture(scope="module")
def solutions(trial, inputs):
    reserves = reserve_optimal_forces(read_force_set(DATA / "gait10dof_Reserve_Actuators.xml", trial.osim),
                                      inputs["coordinates"])
    return reserves, {c: muscle_redundancy(inputs, reserves, criterion=c) for c in ("stress", "activation")}


def test_every_frame_is_optimal_and_meets_the_moments(inputs, solutions):
    _, sols = solutions
    F0 = inputs["muscle_set"].max_isometric_force
    for crit, df in sols.items():
        assert (df["status"] == "optimal").all(), crit
        a = df[[f"a_{m} [-]" for m in inputs["muscles"]]].to_numpy()
        assert a.min() >= -1e-7 and a.max() <= 1 + 1e-7
        F = df[[f"F_{m} [N]" for m in inputs["muscles"]]].to_numpy()
        u = df[[c for c in df.columns if c.startswith("reserve_")]].to_numpy()
        # moment equations recomputed here from the inputs: R F + reserves = tau
        lhs = np.einsum("nqm,nm->nq", inputs["R"], F) + u
        # Clarabel's primal tolerance 1e-8 relative on O(10-100) N m right-hand sides
        np.testing.assert_allclose(lhs, inputs["tau"], atol=1e-5 * np.abs(inputs["tau"]).max())
        assert np.all(F <= F0 * 1.0 + inputs["P"] + 1e-6)


def test_activation_criterion_equals_slsqp_on_real_frames(inputs, solutions):
    from scipy.optimize import minimize

    reserves, sols = solutions
    df = sols["activation"]
    assert (reserves > 0).all()  # gait10dof_Reserve_Actuators.xml: one reserve per coordinate
    for k in (0, 5):
        R, A, P, tau = inputs["R"][k], inputs["A"][k], inputs["P"][k], inputs["tau"][k]
        n = A.size
        # coordinates no muscle spans (pelvis, lumbar) are held by their reserve alone: u = tau / r_opt
        # exactly; SLSQP solves the rest (the large fixed controls would only spoil its scaling)
        free = np.abs(R).sum(axis=1) > 0
        fixed_u = (tau[~free] - R[~free] @ P) / reserves[~free]
        res_free = reserves[free]
        Rf, tf = R[free], tau[free]

        def J(x):
            return np.sum(x**2)

        def cons(x):
            return Rf @ (A * x[:n] + P) + res_free * x[n:] - tf

        x0 = np.concatenate([np.full(n, 0.1), np.zeros(free.sum())])
        bounds = [(0.0, 1.0)] * n + [(None, None)] * int(free.sum())
        # SLSQP stops when the objective changes by less than ftol (absolute); the objective is
        # 130-630 here, so 1e-14 lies below its round-off (630 eps = 1.4e-13) and SLSQP may end at
        # the optimum with "Positive directional derivative for linesearch" (seen with scipy 1.17.1
        # on an AVX-512 host: same optimum to 15 digits as with 1e-12). 1e-12 is far below the
        # comparison tolerances (objective 1e-6 relative, activations 2e-4).
        r = minimize(J, x0, jac=lambda x: 2 * x, constraints={"type": "eq", "fun": cons}, bounds=bounds,
                     method="SLSQP", options=dict(ftol=1e-12, maxiter=1000))
        assert r.success, r.message
        a_ours = df[[f"a_{m} [-]" for m in inputs["muscles"]]].to_numpy()[k]
        u_ours = df[[c for c in df.columns if c.startswith("u_")]].to_numpy()[k]
        coords_with_reserve = [c for c, rr in zip(inputs["coordinates"], reserves) if rr > 0]
        u_cols = dict(zip(coords_with_reserve, u_ours))
        u_fixed_ours = np.array([u_cols[c] for c, f in zip(inputs["coordinates"], free) if not f])
        u_free_ours = np.array([u_cols[c] for c, f in zip(inputs["coordinates"], free) if f])
        np.testing.assert_allclose(u_fixed_ours, fixed_u, rtol=1e-7, atol=1e-9)
        # objective to the solvers' tolerances; the minimiser of a strictly convex QP is unique
        assert J(np.concatenate([a_ours, u_free_ours])) == pytest.approx(r.fun, rel=1e-6, abs=1e-8)
        np.testing.assert_allclose(a_ours, r.x[:n], atol=2e-4)
