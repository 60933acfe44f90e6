"""Static optimisation (:mod:`biomech.static_optimization`): optimality, not stored numbers.

Synthetic but physiologically scaled problems: every muscle crosses one to three coordinates with
moment arms of 0.01-0.06 m (either sign), F0 of 300-3000 N, active capacities from Thelen muscles
at random fibre lengths (0.7-1.3 l_opt) and velocities (|v| <= 0.3 v_max), and generalized forces
that a random activation pattern produces, scaled to at most 100 N m.  Frames are drawn from
``np.random.default_rng(seed)``.

Tolerances are tied to Clarabel's stopping rule (tol_feas = tol_gap_abs = tol_gap_rel = 1e-8 by
default): it stops when ||A x + s - b|| <= tol_feas (1 + ||b|| + ||x|| + ||s||) in the cone
programme's own (unscaled) units, where the moment equations are rows of A x + s = b.  The moment
residual is therefore checked against ``tol_feas (1 + ||b|| + 2 ||x|| + sqrt(n_rows))`` with x all
the problem's variables (the slacks s are bounded by ||x|| plus one per bound row).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy.optimize import minimize

from biomech.muscles import ThelenMuscleSet
from biomech.static_optimization import SPECIFIC_TENSION, StaticOptimization
from core.errors import InputError, ModelError, UnknownOptionError

TOL_FEAS = 1e-8  # Clarabel's default


# ---- synthetic models and frames -----------------------------------------------------------


def synthetic_model(rng, n_coords, n_muscles):
    """Muscle set and a moment-arm pattern: each muscle spans 1-3 coordinates."""
    muscles = ThelenMuscleSet(
        names=[f"m{j:02d}" for j in range(n_muscles)],
        max_isometric_force=rng.uniform(300, 3000, n_muscles),
        optimal_fiber_length=rng.uniform(0.04, 0.15, n_muscles),
        tendon_slack_length=rng.uniform(0.05, 0.35, n_muscles),
        pennation_angle_at_optimal=rng.uniform(0.0, 0.4, n_muscles),
    )
    pattern = np.zeros((n_coords, n_muscles))
    for j in range(n_muscles):
        span = rng.choice(n_coords, size=rng.integers(1, min(3, n_coords) + 1), replace=False)
        pattern[span, j] = rng.choice([-1.0, 1.0], size=span.size) * rng.uniform(0.01, 0.06, span.size)
    for i in range(n_coords):  # every coordinate has a flexor and an extensor
        if not (pattern[i] > 0).any():
            pattern[i, rng.integers(n_muscles)] = rng.uniform(0.01, 0.06)
        if not (pattern[i] < 0).any():
            j = int(np.flatnonzero(pattern[i] >= 0)[rng.integers((pattern[i] >= 0).sum())])
            pattern[i, j] = -rng.uniform(0.01, 0.06)
    coords = [f"q{i}" for i in range(n_coords)]
    return muscles, coords, pattern


def synthetic_frames(rng, muscles, pattern, n_frames, effort=(0.0, 0.6), max_moment=100.0):
    """Moment arms, capacities A, passive forces P and feasible generalized forces tau."""
    n = muscles.n_muscles
    lt = rng.uniform(0.7, 1.3, (n_frames, n))
    h = muscles.parallelogram_height
    l_mt = muscles.tendon_slack_length + np.sqrt((lt * muscles.optimal_fiber_length) ** 2 - h**2)
    v_mt = rng.uniform(-0.3, 0.3, (n_frames, n)) * muscles.max_contraction_velocity * muscles.optimal_fiber_length
    forces = muscles.rigid_tendon_forces(l_mt, v_mt)
    R = pattern[None] * (1.0 + 0.3 * rng.uniform(-1, 1, (n_frames,) + pattern.shape))
    a_true = rng.uniform(*effort, (n_frames, n))
    A, P = forces.active_force_per_activation, forces.passive_force
    # scale the activation pattern down (never up) so that its active moments stay <= max_moment;
    # a scaled pattern is still within [0, 1], so every frame is feasible without reserves
    active = np.einsum("kij,kj->ki", R, A * a_true)
    scale = np.minimum(1.0, max_moment / np.abs(active).max(axis=1))
    tau = active * scale[:, None] + np.einsum("kij,kj->ki", R, P)
    return R, A, P, tau


def saturating_frames(rng, muscles, pattern, n_frames, excess=5.0):
    """Frames beyond the muscles' capacity on q0: every muscle with a positive arm on q0 at a = 1,
    the others off, and `excess` N m more on q0 that only q0's reserve can supply."""
    R, A, P, _ = synthetic_frames(rng, muscles, pattern, n_frames)
    a_max = (R[:, 0, :] > 0).astype(float)
    tau = np.einsum("kij,kj->ki", R, A * a_max + P)
    tau[:, 0] += excess
    return R, A, P, tau


def residual_bound(so, tau_net):
    """tol_feas (1 + ||b|| + 2||x|| + sqrt(n_rows)) for the frame just solved (module docstring)."""
    x = np.concatenate([np.atleast_1d(v.value) for v in so.problem.variables()])
    n_rows = sum(c.size for c in so.problem.constraints)
    return TOL_FEAS * (1.0 + np.linalg.norm(tau_net) + 2.0 * np.linalg.norm(x) + math.sqrt(n_rows))


def criterion_gradient(so, a, u, A, P):
    """Gradient of J with respect to a and u (module docstring of static_optimization)."""
    p, w = so.exponent, so.reserve_weight
    if so.criterion == "activation":
        ga = p * np.abs(a) ** (p - 1)
    else:
        c = A / so.stress_force_scale
        s = c * a + P / so.stress_force_scale
        ga = p * c * np.abs(s) ** (p - 1)
    gu = w * p * np.abs(u) ** (p - 1) * np.sign(u)
    return ga, gu


CASES = [("activation", None), ("stress", None), ("activation", 1.5), ("stress", 2.0), ("stress", 4.0)]
# For p < 2 the gradient p |u|^(p-1) sign(u) is not Lipschitz at u = 0 (a reserve that is nearly
# unused), so stationarity cannot be checked to a tolerance tied to the solver's; those exponents
# are compared with SLSQP instead.
KKT_CASES = [("activation", None), ("stress", None), ("activation", 3.0), ("stress", 2.0), ("stress", 4.0)]


# ---- the formulation -------------------------------------------------------------------------


def test_problem_is_dpp_with_one_matrix_parameter():
    rng = np.random.default_rng(1)
    muscles, coords, _ = synthetic_model(rng, 4, 10)
    for criterion in ("activation", "stress"):
        so = StaticOptimization.from_muscles(muscles, coords, criterion=criterion, reserve_optimal_force=1.0,
                                             epigraph="power_cone")
        assert so.problem.is_dpp()
        shapes = sorted(p.shape for p in so.problem.parameters())
        # B = R diag(A) is one (m x n) parameter, b = tau - R P one vector; the stress criterion
        # adds c and d (n,)
        expected = [(4,), (4, 10)] if criterion == "activation" else [(4,), (4, 10), (10,), (10,)]
        assert shapes == sorted(expected)
        if criterion == "stress":
            cones = [c for c in so.problem.constraints if type(c).__name__ == "PowCone3D"]
            assert len(cones) == 2  # muscles' and reserves' epigraphs, natively as 3-D power cones


@pytest.mark.parametrize("criterion, exponent", KKT_CASES)
def test_moment_equations_bounds_and_kkt(criterion, exponent):
    """Primal feasibility, bounds, and the KKT conditions from the cvxpy duals, frame by frame.

    Lagrangian (cvxpy's sign convention): J + nu.(B a + G u - b) + mu_lo.(a_lo - a) + mu_hi.(a - a_hi),
    so stationarity reads grad_a J + B^T nu - mu_lo + mu_hi = 0, grad_u J + G^T nu = 0, with
    mu >= 0 and mu_lo (a - a_lo) = mu_hi (a_hi - a) = 0.  Frames beyond the muscles' capacity on
    q0 put muscles at a = 1 so that the upper-bound multipliers are exercised.

    Tolerances: Clarabel stops at a duality gap of 1e-8 (relative); each complementary product is at
    most the gap, so mu (slack) <= 1e-8 (1 + J) up to the solver's internal scaling (checked with a
    factor 100); the cone multipliers that stand for grad J in the conic form differ from grad J at the
    returned point by O(sqrt(gap)) = 1e-4 (relative to the size of the terms of the stationarity
    equation), the accuracy interior-point iterates have near the cone boundary.

    Checked on the power-cone epigraph, whose bound constraints carry the whole multiplier of
    a >= 0: cvxpy's ``power`` atom (the default SOC form) adds the domain s >= 0 of its own, whose
    dual is not exposed, so the bound duals alone do not close the stationarity equation there.
    The SOC form's optimum equals this one (test_epigraph_forms_agree) and SLSQP's.
    """
    rng = np.random.default_rng(2)
    muscles, coords, pattern = synthetic_model(rng, 3, 9)
    so = StaticOptimization.from_muscles(muscles, coords, criterion=criterion, exponent=exponent,
                                         reserve_optimal_force=[1.0, 2.0, 0.0], epigraph="power_cone",
                                         fast_path=False)  # the duals come from cvxpy's own solve
    frames = [synthetic_frames(rng, muscles, pattern, 15), saturating_frames(rng, muscles, pattern, 10)]
    n_upper = n_lower = 0
    worst = [0.0, 0.0]
    for R, A, P, tau in frames:
        for k in range(len(tau)):
            sol = so.solve_frame(R[k], A[k], P[k], tau[k])
            assert sol.status == "optimal", sol.message
            a, u = sol.activations, sol.reserve_controls
            # primal feasibility
            assert sol.max_residual <= residual_bound(so, tau[k] - R[k] @ P[k])
            np.testing.assert_allclose(sol.residual, R[k] @ (A[k] * a + P[k]) + so.G @ u - tau[k], atol=1e-12)
            assert np.all(a >= -1e-8) and np.all(a <= 1 + 1e-8)
            # KKT
            nu = so.constraints["moment_equations"].dual_value
            mu_lo = so.constraints["activation_lower"].dual_value
            mu_hi = so.constraints["activation_upper"].dual_value
            ga, gu = criterion_gradient(so, a, u, A[k], P[k])
            B = R[k] * A[k]
            scale = max(1.0, np.abs(ga).max(), np.abs(B.T @ nu).max())
            np.testing.assert_allclose(ga + B.T @ nu - mu_lo + mu_hi, 0.0, atol=1e-4 * scale)
            np.testing.assert_allclose(gu + so.G.T @ nu, 0.0, atol=1e-4 * scale)
            assert np.all(mu_lo >= -1e-8 * scale) and np.all(mu_hi >= -1e-8 * scale)
            gap = 100 * 1e-8 * (1 + abs(sol.objective)) * scale
            np.testing.assert_allclose(mu_lo * a, 0.0, atol=gap)
            np.testing.assert_allclose(mu_hi * (1 - a), 0.0, atol=gap)
            worst[0] = max(worst[0], np.abs(ga + B.T @ nu - mu_lo + mu_hi).max() / scale)
            worst[1] = max(worst[1], np.abs(mu_lo * a).max() / scale, np.abs(mu_hi * (1 - a)).max() / scale)
            n_upper += int(np.sum(mu_hi > 1e-4 * scale))
            n_lower += int(np.sum(mu_lo > 1e-4 * scale))
    assert n_upper > 0 and n_lower > 0  # both bounds were active somewhere
    print(f"\n{criterion} p={so.exponent}: max stationarity {worst[0]:.1e}, max complementarity {worst[1]:.1e} (scaled)")


@pytest.mark.parametrize("criterion, exponent", CASES)
def test_agrees_with_scipy_slsqp(criterion, exponent):
    """Independent solution by SLSQP (analytic gradients, ftol 1e-14).

    Both minimise the same strictly convex J over the same polytope.  Clarabel stops at a relative
    gap of 1e-8, so J agrees to ~1e-8 max(1, J) (checked to 1e-7 relative).  For a J with curvature
    m >= 1 along the feasible set (sum a^2: m = 2; the cubic stress criterion: 6 c^2 s ~ 1 for the
    active muscles) an objective error dJ allows the minimisers to differ by sqrt(2 dJ / m); with
    dJ <= 2e-8 (both solvers) that is 2e-4, the tolerance on a and u.
    """
    rng = np.random.default_rng(3)
    muscles, coords, pattern = synthetic_model(rng, 3, 9)
    so = StaticOptimization.from_muscles(muscles, coords, criterion=criterion, exponent=exponent,
                                         reserve_optimal_force=[1.0, 1.0, 5.0])
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 8, effort=(0.0, 0.9), max_moment=np.inf)
    n, n_r = so.n_muscles, so.n_reserves
    for k in range(len(tau)):
        sol = so.solve_frame(R[k], A[k], P[k], tau[k])
        assert sol.status == "optimal"
        B, b = R[k] * A[k], tau[k] - R[k] @ P[k]

        def fun(x, k=k):
            return so.objective_value(x[:n], x[n:], A[k], P[k])

        def jac(x, k=k):
            return np.concatenate(criterion_gradient(so, x[:n], x[n:], A[k], P[k]))

        M = np.hstack([B, so.G])
        x0 = np.concatenate([np.full(n, 0.2), np.zeros(n_r)])
        res = minimize(fun, x0, jac=jac, method="SLSQP",
                       bounds=[(0.0, 1.0)] * n + [(None, None)] * n_r,
                       constraints=[{"type": "eq", "fun": lambda x, M=M, b=b: M @ x - b, "jac": lambda x, M=M: M}],
                       options={"ftol": 1e-14, "maxiter": 3000})
        assert res.success, res.message
        assert np.abs(M @ res.x - b).max() < 1e-8
        assert sol.objective == pytest.approx(res.fun, rel=1e-7, abs=1e-10)
        np.testing.assert_allclose(sol.activations, res.x[:n], atol=2e-4)
        np.testing.assert_allclose(sol.reserve_controls, res.x[n:], atol=2e-4)


def test_reserve_rule_is_opensims_closed_form():
    """One coordinate, one muscle, one reserve, sum a^2 + u^2 subject to r A a + r_opt u = tau.

    OpenSim's rule (every actuator's control squared, force = control x optimal force) gives
    a = tau rA / ((rA)^2 + r_opt^2), u = tau r_opt / ((rA)^2 + r_opt^2): a weak reserve (small
    r_opt) takes little of the load.
    """
    for r_opt, weight in [(1.0, 1.0), (10.0, 1.0), (100.0, 1.0), (10.0, 4.0)]:
        so = StaticOptimization(["m"], ["q"], [1000.0], reserve_optimal_force=r_opt, reserve_weight=weight)
        rA, tau = 0.04 * 800.0, 10.0
        sol = so.solve_frame([[0.04]], [800.0], [0.0], [tau])
        # with weight w: minimise a^2 + w u^2 -> a = tau rA / (rA^2 + r_opt^2 / w)
        d = rA**2 + r_opt**2 / weight
        assert sol.activations[0] == pytest.approx(tau * rA / d, rel=1e-7)
        assert sol.reserve_forces[0] == pytest.approx(tau * r_opt**2 / weight / d, rel=1e-6)


def test_stress_criterion_minimiser_independent_of_sigma():
    """Sum (F/PCSA)^3 = sigma^3 sum (F/F0)^3 when PCSA = F0/sigma: same minimiser for any sigma.

    The solutions are compared to 2e-4, the accuracy of the minimiser that Clarabel's relative gap
    of 1e-8 implies for this criterion (see test_agrees_with_scipy_slsqp).
    """
    rng = np.random.default_rng(4)
    muscles, coords, pattern = synthetic_model(rng, 3, 9)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 10)
    f0 = muscles.max_isometric_force
    runs = {}
    for sigma in (SPECIFIC_TENSION, 0.5 * SPECIFIC_TENSION, 3.0 * SPECIFIC_TENSION):
        so = StaticOptimization.from_muscles(muscles, coords, criterion="stress", pcsa=f0 / sigma,
                                             specific_tension=sigma, reserve_optimal_force=1.0)
        runs[sigma] = so.solve_trial(np.arange(10) * 0.01, R, A, P, tau)
    cols = [c for c in runs[SPECIFIC_TENSION].columns if c.startswith("a_")]
    ref = runs[SPECIFIC_TENSION][cols].to_numpy()
    for sigma, df in runs.items():
        assert (df["status"] == "optimal").all()
        np.testing.assert_allclose(df[cols].to_numpy(), ref, atol=2e-4)
    # Anatomical PCSAs (not F0/sigma) and no reserves: sigma = k sigma0 only scales J by k^-3.
    # Clarabel's gap test is absolute for J < 1, so the run with the k^3 times smaller J gets
    # tolerances k^3 times tighter, i.e. the same accuracy relative to J.
    pcsa = f0 / SPECIFIC_TENSION * rng.uniform(0.5, 2.0, 9)
    sols = []
    for k in (1.0, 2.0):
        tol = 1e-8 / k**3
        so = StaticOptimization.from_muscles(muscles, coords, criterion="stress", pcsa=pcsa,
                                             specific_tension=k * SPECIFIC_TENSION,
                                             solver_options={"tol_gap_abs": tol, "tol_gap_rel": tol, "tol_feas": tol})
        df = so.solve_trial(np.arange(10) * 0.01, R, A, P, tau)
        assert (df["status"] == "optimal").all(), df["message"]
        sols.append(df)
        # the paper's criterion in (N/cm^2)^3 is sigma^3 J
        forces = df[[c for c in df.columns if c.startswith("F_")]].to_numpy()
        raw = np.sum((forces / (pcsa * 1e4)) ** 3, axis=1)
        np.testing.assert_allclose(raw, (k * SPECIFIC_TENSION / 1e4) ** 3 * df["objective [-]"].to_numpy(), rtol=1e-10)
    np.testing.assert_allclose(sols[0][cols].to_numpy(), sols[1][cols].to_numpy(), atol=2e-4)


def test_epigraph_forms_agree():
    """Power-cone and second-order-cone epigraphs of sum s^3 give the same solution (to 2e-4, the
    accuracy of the minimiser at a relative gap of 1e-8; see test_agrees_with_scipy_slsqp)."""
    rng = np.random.default_rng(5)
    muscles, coords, pattern = synthetic_model(rng, 4, 12)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 10)
    dfs = [StaticOptimization.from_muscles(muscles, coords, criterion="stress", reserve_optimal_force=1.0,
                                           epigraph=e).solve_trial(np.arange(10), R, A, P, tau)
           for e in ("power_cone", "soc")]
    cols = [c for c in dfs[0].columns if c.startswith(("a_", "u_"))]
    assert all((df["status"] == "optimal").all() for df in dfs)
    np.testing.assert_allclose(dfs[0][cols].to_numpy(), dfs[1][cols].to_numpy(), atol=2e-4)


# ---- failures are reported, the trial goes on ------------------------------------------------


def test_infeasible_frame_reported_and_trial_continues():
    rng = np.random.default_rng(6)
    muscles, coords, pattern = synthetic_model(rng, 3, 9)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 6)
    capacity = np.where(R[2] > 0, R[2] * (A[2] + P[2]), R[2] * P[2]).sum(axis=1)  # max moment per coordinate
    tau[2, 1] = 3.0 * capacity[1]  # beyond what the muscles can do on q1
    tau[4, 0] = np.nan  # bad input in another frame
    so = StaticOptimization.from_muscles(muscles, coords)  # no reserves
    df = so.solve_trial(np.arange(6) * 0.01, R, A, P, tau)
    assert list(df["status"]) == ["optimal", "optimal", "infeasible", "optimal", "invalid_input", "optimal"]
    res = df["max |R F + r - tau| [N m]"]
    assert res[2] > 0.5 * capacity[1]  # the deficit is reported ...
    assert "coordinate 'q1'" in df.loc[2, "message"]  # ... and located
    acts = df[[c for c in df.columns if c.startswith("a_")]].to_numpy()
    assert np.all(acts[2] >= -1e-9) and np.all(acts[2] <= 1 + 1e-9)
    assert "generalized_forces" in df.loc[4, "message"] and "'q0'" in df.loc[4, "message"]
    assert np.isnan(acts[4]).all() and np.isnan(res[4])
    assert df.attrs["status_counts"] == {"optimal": 4, "infeasible": 1, "invalid_input": 1}


@pytest.mark.parametrize("criterion", ["activation", "stress"])
def test_trial_table_equals_frame_by_frame(criterion):
    """solve_trial checks the frames and forms forces, residuals and criterion for all frames at
    once; every row equals solve_frame of that frame (optimal, infeasible and invalid frames)."""
    rng = np.random.default_rng(11)
    muscles, coords, pattern = synthetic_model(rng, 3, 6)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 6)
    capacity = np.where(R[1] > 0, R[1] * (A[1] + P[1]), R[1] * P[1]).sum(axis=1)
    tau[1, 2] = 3.0 * capacity[2]                  # infeasible without reserves
    A[3, 4] = -5.0                                 # invalid: negative active force
    R[4, 0, 1] = np.inf                            # invalid: non-finite moment arm
    P[5, 0] = -1.0                                 # invalid for the stress criterion only
    so = StaticOptimization.from_muscles(muscles, coords, criterion=criterion)
    df = so.solve_trial(np.arange(6) * 0.01, R, A, P, tau)
    res_col = "max |R F + r - tau| [N m]"
    # each row and solve_frame are separate interior-point solves (the direct route or cvxpy's),
    # equal to Clarabel's tolerances (1e-8): activations to 1e-7, forces to 1e-7 F0
    for k in range(6):
        f = so.solve_frame(R[k], A[k], P[k], tau[k])
        row = df.loc[k]
        assert row["status"] == f.status and row["message"] == f.message, k
        np.testing.assert_allclose(row[[f"a_{m} [-]" for m in so.muscle_names]].to_numpy(float), f.activations,
                                   rtol=0, atol=1e-7)
        np.testing.assert_allclose(row[[f"F_{m} [N]" for m in so.muscle_names]].to_numpy(float), f.forces,
                                   rtol=0, atol=1e-7 * float(np.max(muscles.max_isometric_force)))
        np.testing.assert_allclose(row[res_col], f.max_residual, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(row["objective [-]"], f.objective, rtol=1e-6, atol=1e-9)
    assert list(df["status"][3:5]) == ["invalid_input"] * 2
    assert df["status"][1] == "infeasible"
    assert (df["status"][5] == "invalid_input") == (criterion == "stress")


def test_least_deficit_closed_form():
    """One coordinate, all moment arms positive, tau beyond capacity: all muscles at a = 1."""
    so = StaticOptimization(["a", "b", "c"], ["knee"], [1000.0, 2000.0, 500.0])
    R, A, P = np.array([[0.03, 0.05, 0.02]]), np.array([900.0, 1500.0, 400.0]), np.array([10.0, 0.0, 5.0])
    capacity = float(R[0] @ (A + P))
    sol = so.solve_frame(R, A, P, [capacity + 20.0])
    assert sol.status == "infeasible"
    np.testing.assert_allclose(sol.activations, 1.0, atol=1e-6)
    assert sol.residual[0] == pytest.approx(-20.0, rel=1e-5)


def test_solver_failure_is_a_status_not_an_exception(monkeypatch):
    import cvxpy as cp

    rng = np.random.default_rng(7)
    muscles, coords, pattern = synthetic_model(rng, 3, 9)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 4)
    # the failure is injected into cvxpy's problem.solve: the direct route is switched off here
    so = StaticOptimization.from_muscles(muscles, coords, reserve_optimal_force=1.0, fast_path=False)
    real_solve = so.problem.solve
    calls = []

    def flaky(*args, **kwargs):
        calls.append(kwargs)
        if np.allclose(so._b.value, tau[1] - R[1] @ P[1]):
            raise cp.SolverError("Solver 'CLARABEL' failed.")
        return real_solve(*args, **kwargs)

    monkeypatch.setattr(so.problem, "solve", flaky)
    df = so.solve_trial(np.arange(4), R, A, P, tau)
    assert list(df["status"]) == ["optimal", "solver_error", "optimal", "optimal"]
    assert "retried with" in df.loc[1, "message"] and np.isnan(df.loc[1, "a_m00 [-]"])
    # retries changed max_step_fraction; the next frame is solved with the default again
    assert calls[-1]["max_step_fraction"] == 0.99


@pytest.mark.parametrize("criterion", ["activation", "stress"])
def test_direct_route_equals_cvxpy_solve(criterion):
    """The per-frame route through cvxpy's parameter tensor (_ClarabelData) gives the solution of
    problem.solve: same statuses, activations and reserves to the solver's tolerance."""
    rng = np.random.default_rng(11)
    muscles, coords, pattern = synthetic_model(rng, 4, 12)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 12)
    fast = StaticOptimization.from_muscles(muscles, coords, criterion=criterion, reserve_optimal_force=1.0)
    slow = StaticOptimization.from_muscles(muscles, coords, criterion=criterion, reserve_optimal_force=1.0,
                                           fast_path=False)
    a = fast.solve_trial(np.arange(12), R, A, P, tau)
    b = slow.solve_trial(np.arange(12), R, A, P, tau)
    assert fast._fast is not None and fast._fast.ok and fast._fast.verified == 2  # the route was used
    assert list(a["status"]) == list(b["status"]) == ["optimal"] * 12
    cols = [c for c in a.columns if c.startswith(("a_", "u_"))]
    np.testing.assert_allclose(a[cols].to_numpy(), b[cols].to_numpy(), atol=1e-6)
    # the parameter vector written directly (no cvxpy value checks) is cvxpy's own layout
    values = {fast._B: R[-1] * A[-1], fast._b: tau[-1] - R[-1] @ P[-1]}
    if criterion == "stress":
        values |= {fast._c: A[-1] / fast.stress_force_scale, fast._d: P[-1] / fast.stress_force_scale}
    fast._set_parameters(values)
    np.testing.assert_array_equal(fast._fast.param_vec(values), fast._fast._param_vec())


def test_direct_route_failure_falls_back_to_cvxpy(monkeypatch):
    from biomech import static_optimization as so_mod

    rng = np.random.default_rng(12)
    muscles, coords, pattern = synthetic_model(rng, 3, 9)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 3)
    so = StaticOptimization.from_muscles(muscles, coords, reserve_optimal_force=1.0)

    def broken(self, options, p=None):
        raise RuntimeError("an internal API of cvxpy changed")

    monkeypatch.setattr(so_mod._ClarabelData, "solve", broken)
    df = so.solve_trial(np.arange(3), R, A, P, tau)
    assert (df["status"] == "optimal").all() and not so._fast_enabled


# ---- status and speed on larger random sets --------------------------------------------------


@pytest.mark.parametrize("n_coords, n_muscles", [(6, 18), (23, 92)])
def test_power_cone_cubic_optimal_on_200_frames(n_coords, n_muscles):
    """The cubic stress criterion with native power cones ends 'optimal' on 200 random frames.

    Solve times are reported (``pytest -s``), not asserted.  Retries (see the module docstring) are
    counted; the frame's message lists them.
    """
    rng = np.random.default_rng(8 + n_muscles)
    muscles, coords, pattern = synthetic_model(rng, n_coords, n_muscles)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 200)
    so = StaticOptimization.from_muscles(muscles, coords, criterion="stress", reserve_optimal_force=1.0,
                                         epigraph="power_cone")
    df = so.solve_trial(np.arange(200) / 60.0, R, A, P, tau)
    assert (df["status"] == "optimal").all(), df.loc[df["status"] != "optimal", ["status", "message"]]
    retried = int((df["message"] != "").sum())
    assert retried <= 10  # measured: at most 1 in 200 on the development machine
    for k in range(200):
        # the bound of residual_bound with ||x|| <= n_muscles: x holds a <= 1, t = s^3 <= ~1 and
        # small reserve controls (the frames are feasible without reserves)
        b = tau[k] - R[k] @ P[k]
        assert df.loc[k, "max |R F + r - tau| [N m]"] <= TOL_FEAS * (1 + np.linalg.norm(b) + 2 * n_muscles)
    t = df["solve time [s]"].to_numpy()[1:]
    print(f"\n{n_muscles} muscles, {n_coords} coordinates: first frame (with DPP compile) "
          f"{1e3 * df['solve time [s]'][0]:.1f} ms; later frames median {1e3 * np.median(t):.2f} ms "
          f"(Clarabel {1e3 * np.median(df['solver time [s]'][1:]):.2f} ms), 90th percentile "
          f"{1e3 * np.percentile(t, 90):.2f} ms; retried frames: {retried}")


# ---- the table and bad input -----------------------------------------------------------------


def test_result_table_layout():
    rng = np.random.default_rng(9)
    muscles, coords, pattern = synthetic_model(rng, 3, 5)
    R, A, P, tau = synthetic_frames(rng, muscles, pattern, 4)
    so = StaticOptimization.from_muscles(muscles, coords, reserve_optimal_force=[1.0, 0.0, 2.0],
                                         coordinate_units=["N m", "N m", "N"])
    df = so.solve_trial(np.linspace(0, 0.05, 4), R, A, P, tau)
    assert isinstance(df, pd.DataFrame) and len(df) == 4
    assert list(df.columns[:11]) == (["time [s]"] + [f"a_m0{j} [-]" for j in range(5)]
                                     + [f"F_m0{j} [N]" for j in range(5)])
    assert ["u_q0 [-]", "reserve_q0 [N m]", "u_q2 [-]", "reserve_q2 [N]"] == list(df.columns[11:15])
    assert "max |R F + r - tau| [N or N m]" in df.columns
    for col in ("status", "message", "objective [-]", "solve time [s]", "solver time [s]", "iterations"):
        assert col in df.columns
    np.testing.assert_allclose(df["F_m02 [N]"], A[:, 2] * df["a_m02 [-]"] + P[:, 2], rtol=1e-12)
    np.testing.assert_allclose(df["reserve_q2 [N]"], 2.0 * df["u_q2 [-]"], rtol=1e-12)
    assert df.attrs["criterion"] == "activation" and df.attrs["exponent"] == 2.0
    assert df.attrs["reserve_optimal_force"] == {"q0": 1.0, "q2": 2.0}


def test_bad_options_and_shapes():
    f0 = [1000.0, 500.0]
    with pytest.raises(UnknownOptionError, match="criterion 'effort'"):
        StaticOptimization(["a", "b"], ["q"], f0, criterion="effort")
    with pytest.raises(InputError, match="exponent"):
        StaticOptimization(["a", "b"], ["q"], f0, exponent=0.5)
    with pytest.raises(ModelError, match="muscle 'b'.*activation bounds"):
        StaticOptimization(["a", "b"], ["q"], f0, activation_bounds=(0.0, [1.0, 1.5]))
    with pytest.raises(ModelError, match="muscle 'b'.*max_isometric_force"):
        StaticOptimization(["a", "b"], ["q"], [1000.0, 0.0])
    with pytest.raises(ModelError, match="coordinate 'q'.*reserve optimal force"):
        StaticOptimization(["a", "b"], ["q"], f0, reserve_optimal_force=-1.0)
    with pytest.raises(ModelError, match="duplicate muscle name 'a'"):
        StaticOptimization(["a", "a"], ["q"], f0)
    with pytest.raises(UnknownOptionError, match="epigraph"):
        StaticOptimization(["a", "b"], ["q"], f0, epigraph="exp")
    so = StaticOptimization(["a", "b"], ["q"], f0)
    with pytest.raises(InputError, match=r"moment_arms must have shape \(1, 2\)"):
        so.solve_frame([0.01, 0.02], [900.0, 400.0], None, [1.0])
    with pytest.raises(InputError, match="generalized_forces must have shape"):
        so.solve_trial([0.0, 0.1], np.zeros((2, 1, 2)), np.ones((2, 2)), None, np.zeros((3, 1)))
    neg = so.solve_frame([[0.01, 0.02]], [900.0, -1.0], None, [1.0])
    assert neg.status == "invalid_input" and "muscle 'b'" in neg.message
