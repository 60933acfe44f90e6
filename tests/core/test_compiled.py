"""Compiled (numba) kernels and the compiled explicit Runge–Kutta integrators.

Independent computations the compiled path is checked against:

* the vectorised numpy path of :class:`core.model.Model` (Φ, Φ_q, γ, Q and the index-1
  accelerations/multipliers of :func:`core.dynamics.accelerations`) for every compiled joint and
  force kind, planar and spatial, at perturbed states (constraints violated, random velocities):
  the formulas are the same, so they agree to round-off (1e-12 relative);
* scipy's ``RK45``/``DOP853`` driving the numpy right-hand side (same tableaux and step-size
  controller): with one output point the step sequences are identical, so step counts match exactly
  and the final states to the round-off accumulated over the run (1e-9 relative);
* the minimal-coordinate reference of the N-link chain (core_benchmarks.md §1): the error scales
  with the tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from core import compiled, frames, models
from core.dynamics import accelerations as accelerations_numpy
from core.integrators import METHODS, simulate
from core.integrators.compiled_rk import COMPILED_METHODS
from core.model import ModelBuilder

RT = 1e-12  # round-off agreement of two evaluations of the same formulas


def _unit(rng, d=3):
    x = rng.standard_normal(d)
    return x / np.linalg.norm(x)


def _body(b, rng, name):
    if b.space.dim == 2:
        return b.add_body(name, rng.uniform(0.5, 2.0), rng.uniform(0.05, 0.3), rng.uniform(-1, 1, 2),
                          orientation=rng.uniform(-np.pi, np.pi))
    J = np.diag(rng.uniform(0.05, 0.3, 3))
    R = frames.euler_to_matrix(frames.axis_angle_to_euler(_unit(rng), rng.uniform(0, np.pi)))
    p = frames.axis_angle_to_euler(_unit(rng), rng.uniform(-np.pi, np.pi))
    return b.add_body(name, rng.uniform(0.5, 2.0), R @ J @ R.T, rng.uniform(-1, 1, 3), orientation=p)


def _model(dim, joint, seed, ground=False, springs=True):
    """Two random bodies, one joint of the given kind, optionally a point spring and a spring-damper."""
    rng = np.random.default_rng(seed)
    b = ModelBuilder(dim, f"compiled-{dim}d-{joint}")
    _body(b, rng, "a")
    _body(b, rng, "b")
    bi = "ground" if ground else "a"
    at = rng.uniform(-1, 1, dim)
    axis = _unit(rng, dim)
    if joint == "revolute":
        b.add_revolute("J", bi, "b", at, None if dim == 2 else axis)
    elif joint == "spherical":
        b.add_spherical("J", bi, "b", at)
    elif joint == "translational":
        b.add_translational("J", bi, "b", at, axis)
    elif joint == "cylindrical":
        b.add_cylindrical("J", bi, "b", at, axis)
    elif joint == "universal":
        other = np.cross(axis, _unit(rng))
        b.add_universal("J", bi, "b", at, axis, other / np.linalg.norm(other))
    elif joint == "fixed":
        b.add_fixed("J", bi, "b", at)
    elif joint == "distance":
        b.add_distance("J", bi, "b", at, at + rng.uniform(0.3, 1.0, dim))
    if springs:
        b.add_point_spring("ps", "ground", "a", rng.uniform(-1, 1, dim), stiffness=150.0, damping=2.0)
        b.add_spring_damper("sd", "a", "b", rng.uniform(-1, 1, dim), rng.uniform(-1, 1, dim), 80.0, 1.5,
                            free_length=0.4)
    return b.build()


def _perturbed(model, seed):
    rng = np.random.default_rng(seed + 100)
    q = model.retract(model.q0, 0.05 * rng.standard_normal(model.n_v))
    v = rng.standard_normal(model.n_v)
    return q, v


JOINTS_2D = ["revolute", "translational", "fixed", "distance"]
JOINTS_3D = ["spherical", "revolute", "translational", "cylindrical", "universal", "fixed", "distance"]
CASES = [(2, j) for j in JOINTS_2D] + [(3, j) for j in JOINTS_3D]


def _close(a, b, what, rtol=RT):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, float(np.max(np.abs(b))) if b.size else 1.0)
    err = float(np.max(np.abs(a - b))) if b.size else 0.0
    assert err <= rtol * scale, f"{what}: {err:.3e} > {rtol:g} × {scale:.3g}"


@pytest.mark.parametrize("ground", [False, True])
@pytest.mark.parametrize("dim,joint", CASES)
def test_kernels_match_numpy_model(dim, joint, ground):
    model = _model(dim, joint, seed=len(joint) + dim, ground=ground)
    cd = compiled.compile_model(model)
    ws = compiled.make_workspace(cd)
    q, v = _perturbed(model, 3)
    compiled.body_states(cd, q, v, ws)
    compiled.constraint_terms(cd, ws, True, True)
    _close(ws.phi[: model.n_c], model.Phi(0.0, q), f"{joint} Φ")
    _close(ws.gam[: model.n_c], model.gamma(0.0, q, v), f"{joint} γ")
    J = model.Phi_q(0.0, q).toarray()
    Jc = np.zeros_like(J)
    nvb = cd.nvb
    for row in range(model.n_c):
        for slot in range(2):
            bdy = cd.r_b[row, slot]
            if bdy < cd.nb:
                Jc[row, bdy * nvb:(bdy + 1) * nvb] += ws.G[row, slot, :nvb]
    _close(Jc, J, f"{joint} Φ_q")
    Q = np.zeros(model.n_v)
    assert compiled.applied_forces(cd, ws, Q) == compiled.OK
    _close(Q, model.Q(0.0, q, v), f"{joint} Q")
    a = np.zeros(model.n_v)
    lam = np.zeros(max(model.n_c, 1))
    assert compiled.accelerations(cd, ws, q, v, 0.0, 0.0, a, lam) == compiled.OK
    a_ref, lam_ref = accelerations_numpy(model, 0.0, q, v)
    _close(a, a_ref, f"{joint} accelerations", 1e-10)
    _close(lam[: model.n_c], lam_ref, f"{joint} multipliers", 1e-10)


def test_qdot_retract_normalize_match_model():
    model = _model(3, "spherical", seed=4)
    cd = compiled.compile_model(model)
    q, v = _perturbed(model, 5)
    out = np.zeros(model.n_q)
    compiled.qdot(cd, q, v, out)
    _close(out, model.qdot(q, v), "q̇")
    dv = 0.3 * np.random.default_rng(6).standard_normal(model.n_v)
    qr = q.copy()
    compiled.retract(cd, qr, dv)
    _close(qr, model.retract(q, dv), "retract")
    qn = 1.1 * q
    compiled.normalize(cd, qn)
    _close(qn, model.normalize(1.1 * q), "normalize")


def test_baumgarte_terms_enter_the_acceleration_equation():
    """With α, β the constraint rows satisfy Φ_q v̇ = γ − 2α Φ_q v − β² Φ (Baumgarte 1972)."""
    model = _model(3, "revolute", seed=7, springs=False)
    cd = compiled.compile_model(model)
    ws = compiled.make_workspace(cd)
    q, v = _perturbed(model, 8)
    a = np.zeros(model.n_v)
    lam = np.zeros(model.n_c)
    alpha, beta = 7.0, 11.0
    assert compiled.accelerations(cd, ws, q, v, alpha, beta, a, lam) == compiled.OK
    J = model.Phi_q(0.0, q)
    rhs = model.gamma(0.0, q, v) - 2 * alpha * (J @ v) - beta**2 * model.Phi(0.0, q)
    _close(J @ a, rhs, "Φ_q v̇")
    _close(model.M(0.0, q) @ a + J.T @ lam, model.Q(0.0, q, v), "M v̇ + Φ_qᵀλ = Q")


def test_rcm_envelope_is_a_band_on_chains():
    """The Schur complement of a chain is factorised in a band (row widths ≤ 4 in RCM order)."""
    cd = compiled.compile_model(models.n_link_chain(32, planar=True))
    widths = np.arange(cd.m) - cd.env_first
    assert widths.max() <= 4


# --------------------------------------------------------------------------------------------
# integrators
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("key", ["rk45", "dop853"])
@pytest.mark.parametrize("spatial", [False, True])
def test_same_steps_and_result_as_scipy(key, spatial):
    """Same tableau and controller as scipy: identical step sequence, final state to round-off."""
    model = models.n_link_chain(4, spatial=spatial, planar=not spatial)
    kw = dict(t_eval=[0.6], rtol=1e-7, atol=1e-7, compute_multipliers=False)
    ref = simulate(model, (0.0, 0.6), key, **kw)
    jit = simulate(model, (0.0, 0.6), f"jit-{key}", **kw)
    assert ref.status == jit.status == "finished"
    assert jit.counters["n_steps"] == ref.counters["n_steps"]
    _close(jit.q[-1], ref.q[-1], f"{key} q(t_end)", 1e-9)
    _close(jit.v[-1], ref.v[-1], f"{key} v(t_end)", 1e-9)


@pytest.mark.parametrize("stab", ["baumgarte", "projection"])
def test_stabilised_variants_match_scipy(stab):
    model = models.n_link_chain(3, planar=True)
    kw = dict(t_eval=[0.5], rtol=1e-6, atol=1e-6, compute_multipliers=False)
    ref = simulate(model, (0.0, 0.5), f"rk45-{stab}", **kw)
    jit = simulate(model, (0.0, 0.5), f"jit-rk45-{stab}", **kw)
    assert jit.counters["n_steps"] == ref.counters["n_steps"]
    _close(jit.q[-1], ref.q[-1], f"{stab} q(t_end)", 1e-9)


@pytest.mark.parametrize("method", ["jit-dop853", "jit-rk45-baumgarte", "jit-dop853-projection"])
def test_chain_tip_error_against_minimal_coordinate_reference(method):
    """8-link chain at t = 1 s: tip error below 1e-6 m at tol 1e-8 and shrinking with the tolerance."""
    n = 8
    model = models.n_link_chain(n, planar=True)
    ref, _ = models.n_link_chain_reference(n)
    errs = []
    for tol in (1e-5, 1e-8):
        res = simulate(model, (0.0, 1.0), method, t_eval=[1.0], rtol=tol, atol=tol, compute_multipliers=False)
        assert res.status == "finished", res.message
        tip = models.chain_tip(model, res.q[-1])
        errs.append(float(np.linalg.norm(tip - ref)))
    assert errs[1] < 1e-6
    assert errs[1] < errs[0] / 10


def test_projection_holds_both_constraint_levels():
    model = models.n_link_chain(8, planar=True)
    tol = 1e-9
    res = simulate(model, (0.0, 1.0), "jit-dop853-projection", n_output=11, rtol=1e-6, atol=1e-6,
                   projection_tol=tol, compute_multipliers=False)
    assert res.status == "finished"
    assert np.max(res.position_violation) <= tol
    assert np.max(res.velocity_violation) <= 1e-9
    plain = simulate(model, (0.0, 1.0), "jit-dop853", n_output=11, rtol=1e-6, atol=1e-6, compute_multipliers=False)
    assert np.max(plain.position_violation) > 10 * tol  # the unstabilised index-1 ODE drifts


def test_steps_land_on_output_times_and_counters_add_up():
    model = models.n_link_chain(2, planar=True)
    t_eval = np.linspace(0.0, 1.0, 11)
    res = simulate(model, (0.0, 1.0), "jit-rk45", t_eval=t_eval, rtol=1e-6, atol=1e-8)
    np.testing.assert_array_equal(res.t, t_eval)
    dense = simulate(model, (0.0, 1.0), "rk45", t_eval=t_eval, rtol=1e-10, atol=1e-12)
    _close(res.q, dense.q, "q at output times", 1e-5)
    c = res.counters
    assert c["n_steps"] >= 10 and c["n_rhs"] >= 6 * (c["n_steps"] + c["n_rejected"])
    assert np.all(np.isfinite(res.lam))  # multipliers recomputed at the output states


def test_step_contract_one_step_per_call():
    cls = METHODS["jit-dop853"]
    integ = cls(models.n_link_chain(2, planar=True), (0.0, 1.0), rtol=1e-6, atol=1e-6)
    t0 = integ.t
    assert integ.step() is None
    assert integ.counters["n_steps"] == 1 and integ.t > t0 and integ.t_old == t0
    q, v = integ.dense_output()(0.5 * (integ.t + integ.t_old))
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(v))
    while integ.status == "running":
        integ.step()
    assert integ.status == "finished" and integ.t == 1.0


def test_registry_names():
    assert set(COMPILED_METHODS) == {f"jit-{k}{s}" for k in ("rk45", "dop853") for s in ("", "-baumgarte", "-projection")}
    assert all(name in METHODS for name in COMPILED_METHODS)


# --------------------------------------------------------------------------------------------
# honest refusal and failure
# --------------------------------------------------------------------------------------------


def test_not_compilable_names_the_element():
    with pytest.raises(compiled.NotCompilable, match="crank drive"):
        simulate(models.slider_crank(), (0.0, 0.1), "jit-rk45")
    with pytest.raises(compiled.NotCompilable, match="link1.*singular mass"):
        compiled.compile_model(models.simple_pendulum())
    reason = METHODS["jit-rk45"].applicable(models.body_on_helix())
    assert reason is not None and "extra coordinate" in reason
    assert METHODS["jit-rk45"].applicable(models.n_link_chain(2, planar=True)) is None


def test_redundant_rows_must_be_removed():
    def four_bar_spatial(redundant):
        b = ModelBuilder(3, "four-bar-3d")
        pts = [np.array(p, float) for p in ((0, 0, 0), (0, 1, 0), (2, 1.2, 0), (2, 0, 0))]
        for k, (p, q) in enumerate(zip(pts[:-1], pts[1:])):
            b.add_body(f"l{k}", 1.0, np.diag([0.01, 0.1, 0.1]), 0.5 * (p + q))
        b.add_revolute("A", "ground", "l0", pts[0], (0, 0, 1))
        b.add_revolute("B", "l0", "l1", pts[1], (0, 0, 1))
        b.add_revolute("C", "l1", "l2", pts[2], (0, 0, 1))
        b.add_revolute("D", "l2", "ground", pts[3], (0, 0, 1))
        with pytest.warns(UserWarning, match="redundant constraint"):
            return b.build(redundant=redundant)

    with pytest.raises(compiled.NotCompilable, match="redundant='remove'"):
        compiled.compile_model(four_bar_spatial("keep"))
    res = simulate(four_bar_spatial("remove"), (0.0, 0.5), "jit-dop853-projection", n_output=3)
    assert res.status == "finished" and np.max(res.position_violation) < 1e-7


def test_coincident_spring_points_are_refused_with_a_message():
    """A spring-damper whose points coincide has no direction: the kernel reports it by name."""
    b = ModelBuilder(2, "collapse")
    b.add_body("m", 1.0, 0.1, (0.0, 0.0))
    b.add_spring_damper("sd", "ground", "m", (0.0, 0.0), (0.0, 0.0), stiffness=10.0, free_length=0.5)
    with pytest.raises(ValueError, match="attachment points of a spring-damper coincide"):
        simulate(b.build(), (0.0, 1.0), "jit-rk45")


def test_dependent_rows_give_a_non_positive_pivot():
    """The envelope Cholesky refuses a singular Schur complement (status code, not a wrong answer)."""
    model = models.n_link_chain(3, planar=True)
    cd = compiled.compile_model(model)
    ws = compiled.make_workspace(cd)
    compiled.body_states(cd, model.q0, model.v0, ws)
    compiled.constraint_terms(cd, ws, False, False)
    assert compiled.factor_schur(cd, ws) == compiled.OK
    ws.G[1] = ws.G[0]  # both rows of the ground pivot made equal: dependent rows
    assert compiled.factor_schur(cd, ws) == compiled.SINGULAR


def test_stiffness_test_warns_or_stops():
    """Hairer's stiffness test: on the k = 1e8 penalty chain the explicit step is stability-limited
    (h|λ| beyond the boundary on 15 consecutive steps); the rigid chain never trips it."""
    stiff = models.n_link_chain(2, planar=True, stiff_k=1e8)
    kw = dict(t_eval=[0.02], rtol=1e-5, atol=1e-5, compute_multipliers=False)
    warn = simulate(stiff, (0.0, 0.02), "jit-dop853", **kw)
    assert warn.status == "finished" and "became stiff at t =" in warn.message
    stop = simulate(stiff, (0.0, 0.02), "jit-dop853", stiffness="fail", **kw)
    assert stop.status == "failed" and "use an implicit method" in stop.message
    assert stop.t[-1] < 0.02 and np.all(np.isfinite(stop.q))  # what was computed is kept
    off = simulate(stiff, (0.0, 0.02), "jit-dop853", stiffness="off", **kw)
    assert off.status == "finished" and "stiff" not in off.message
    np.testing.assert_array_equal(off.q[-1], warn.q[-1])  # the test only observes
    rigid = simulate(models.n_link_chain(8, planar=True), (0.0, 1.0), "jit-rk45", **{**kw, "t_eval": [1.0]})
    assert rigid.status == "finished" and "stiff" not in rigid.message
    with pytest.raises(ValueError, match="stiffness must be one of"):
        simulate(stiff, (0.0, 0.02), "jit-rk45", stiffness="maybe")
