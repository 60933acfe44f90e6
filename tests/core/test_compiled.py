"""Compiled (numba) path: kernels, registration of element kinds, and the compiled integrators.

Independent computations the compiled path is checked against:

* the vectorised numpy path of :class:`core.model.Model` (Φ, Φ_q, ν, γ, Q and the index-1
  accelerations/multipliers of :func:`core.dynamics.accelerations`) for every compiled joint,
  driver and force kind, planar and spatial, at perturbed states (constraints violated, random
  velocities, t ≠ 0): the formulas are the same, so they agree to round-off (1e-12 relative);
* scipy's ``RK45``/``DOP853`` driving the numpy right-hand side (same tableaux and step-size
  controller): with one output point the step sequences are identical, so step counts match exactly
  and the final states to the round-off accumulated over the run (1e-9 relative);
* the minimal-coordinate reference of the N-link chain (core_benchmarks.md §1), the closed-form
  slider-crank kinematics and the closed-form motion of a bead on a helix (a massless extra
  coordinate): the error scales with the tolerance.

A force kind defined in this test module (outside ``core/``) with its own kernel shows that domain
packages join the compiled path through registration alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from core import drivers, frames, models
from core.benchmarks.references import n_link_chain_reference
from core.compiled import (
    CompiledForces,
    NotCompilable,
    accept_kernel,
    compile_model,
    force_jacobian_kernel,
    force_kernel,
    make_workspace,
)
from core.compiled import dynamics as D
from core.compiled import protocol as P
from core.compiled.timefunctions import encode, evaluate
from core.flexible.models import spin_up_angle
from core.dynamics import accelerations as accelerations_numpy
from core.errors import DataRangeError
from core.forces import ForceElement, ForceEval, ForceJacobian, ForceKind
from core.integrators import METHODS, simulate
from core.integrators.compiled_rk import COMPILED_METHODS
from core.model import ModelBuilder

FINISHED = ("finished", "finished with warnings")
RT = 1e-12  # round-off agreement of two evaluations of the same formulas


def _unit(rng, d=3):
    x = rng.standard_normal(d)
    return x / np.linalg.norm(x)


def _body(b, rng, name):
    if b.space.dim == 2:
        return b.add_body(name, rng.uniform(0.5, 2.0), rng.uniform(0.05, 0.3), rng.uniform(-1, 1, 2),
                          orientation=rng.uniform(-np.pi, np.pi))
    J = np.diag(rng.uniform(0.1, 0.2, 3))  # principal moments of a rigid body: J_a <= J_b + J_c
    R = frames.euler_to_matrix(frames.axis_angle_to_euler(_unit(rng), rng.uniform(0, np.pi)))
    p = frames.axis_angle_to_euler(_unit(rng), rng.uniform(-np.pi, np.pi))
    return b.add_body(name, rng.uniform(0.5, 2.0), R @ J @ R.T, rng.uniform(-1, 1, 3), orientation=p)


def _model(dim, joint, seed, ground=False, springs=True, loads=False):
    """Two random bodies, one joint (or driver) of the given kind, optionally force elements."""
    rng = np.random.default_rng(seed)
    b = ModelBuilder(dim, f"compiled-{dim}d-{joint}")
    _body(b, rng, "a")
    _body(b, rng, "b")
    bi = "ground" if ground else "a"
    at = rng.uniform(-1, 1, dim)
    axis = _unit(rng, dim)
    if joint in ("revolute", "angle-driver"):
        b.add_revolute("J", bi, "b", at, None if dim == 2 else axis)
        if joint == "angle-driver":
            b.add_angle_driver("drive", "J", drivers.harmonic(0.3, 2.0, 0.1))
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
    elif joint == "point-driver":
        t = np.linspace(0.0, 2.0, 9)
        b.add_point_driver("push", "b", at, axis, drivers.tabulated(t, 0.2 * np.sin(t) + 0.05 * t ** 2))
    if springs:
        b.add_point_spring("ps", "ground", "a", rng.uniform(-1, 1, dim), stiffness=150.0, damping=2.0)
        b.add_spring_damper("sd", "a", "b", rng.uniform(-1, 1, dim), rng.uniform(-1, 1, dim), 80.0, 1.5,
                            free_length=0.4, actuator=drivers.polynomial([0.5, -1.0, 0.3]))
        b.add_rotational_spring_damper("rsd", "a", "b", 40.0, 0.8, free_angle=0.2,
                                       actuator=drivers.harmonic(0.5, 3.0), axis=None if dim == 2 else axis)
        ang = rng.uniform(-np.pi, np.pi)
        axes = (np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]]) if dim == 2 else
                frames.euler_to_matrix(frames.axis_angle_to_euler(_unit(rng), ang)))
        b.add_bushing("bush", bi, "b", rng.uniform(-1, 1, dim), rng.uniform(50.0, 200.0, dim),
                      rng.uniform(5.0, 20.0, 1 if dim == 2 else 3), rng.uniform(0.5, 2.0, dim),
                      rng.uniform(0.1, 0.5, 1 if dim == 2 else 3), axes=axes,
                      point_j=rng.uniform(-1, 1, dim))
    if loads:
        b.add_applied_force("F", "a", rng.uniform(-1, 1, dim), [drivers.harmonic(2.0, 3.0), 1.5] + [0.5] * (dim - 2),
                            frame="body")
        b.add_applied_force("Fg", "b", rng.uniform(-1, 1, dim), [0.3] * dim)
        b.add_applied_torque("T", "b", 0.7 if dim == 2 else [0.2, drivers.ramp(0.4), -0.1])
        ball_at = (rng.uniform(-1, 1, dim))
        b.add_plane_contact("C", "a", ball_at, 0.2, ball_at - 0.15 * _unit(rng, dim), _unit(rng, dim),
                            restitution=0.8, impact_velocity=1.0, stiffness=1e4, friction=0.3)
    return b.build(assemble=joint.endswith("driver"))


def _perturbed(model, seed):
    rng = np.random.default_rng(seed + 100)
    q = model.retract(model.q0, 0.05 * rng.standard_normal(model.n_v))
    v = rng.standard_normal(model.n_v)
    return q, v


JOINTS_2D = ["revolute", "translational", "fixed", "distance", "angle-driver", "point-driver"]
JOINTS_3D = ["spherical", "revolute", "translational", "cylindrical", "universal", "fixed", "distance",
             "angle-driver", "point-driver"]
CASES = [(2, j) for j in JOINTS_2D] + [(3, j) for j in JOINTS_3D]


def _close(a, b, what, rtol=RT):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(1.0, float(np.max(np.abs(b))) if b.size else 1.0)
    err = float(np.max(np.abs(a - b))) if b.size else 0.0
    assert err <= rtol * scale, f"{what}: {err:.3e} > {rtol:g} × {scale:.3g}"


def _jacobian_from_slots(cm, ws, model):
    """Dense Φ_q (model rows) assembled from the kernels' slot blocks."""
    f = cm.fields
    J = np.zeros((cm.m_all, model.n_v))
    for row in range(cm.m_all):
        for slot in range(P.MAX_SLOTS):
            blk = f["r_blk"][row, slot]
            if blk < 0 or f["blk_w"][blk] == 0:
                continue
            o, w = f["blk_v0"][blk], f["blk_w"][blk]
            J[row, o:o + w] += ws.G[row, slot, :w]
    return J


@pytest.mark.parametrize("ground", [False, True])
@pytest.mark.parametrize("dim,joint", CASES)
def test_kernels_match_numpy_model(dim, joint, ground):
    model = _model(dim, joint, seed=len(joint) + dim, ground=ground, loads=not ground)
    cm = compile_model(model)
    ws = make_workspace(cm)
    st = cm.initial_states()
    q, v = _perturbed(model, 3)
    t = 0.37
    D.body_states(cm.fields["lay"], q, v, ws)
    assert D.constraints(cm.data, ws, t, q, v, P.WANT_ALL) == P.OK
    _close(ws.phi[: model.n_c], model.Phi(t, q), f"{joint} Φ")
    _close(ws.nu[: model.n_c], model.nu(t, q), f"{joint} ν")
    _close(ws.gam[: model.n_c], model.gamma(t, q, v), f"{joint} γ")
    _close(_jacobian_from_slots(cm, ws, model), model.Phi_q(t, q).toarray(), f"{joint} Φ_q")
    Q = np.zeros(model.n_v)
    assert D.forces(cm.data, st, ws, t, q, v, Q) == P.OK
    _close(Q, model.Q(t, q, v), f"{joint} Q")
    a = np.zeros(model.n_v)
    lam = np.zeros(max(model.n_c, 1))
    assert D.accelerations(cm.data, st, ws, t, q, v, 0.0, 0.0, a, lam) == P.OK
    a_ref, lam_ref = accelerations_numpy(model, t, q, v)
    _close(a, a_ref, f"{joint} accelerations", 1e-10)
    _close(lam[: model.n_c], lam_ref, f"{joint} multipliers", 1e-10)


def _suspension_model(dim, seed, ground=False, bump_stops=True):
    """Two random bodies with bump stops (symmetric with damping, one-sided) and two series
    spring-dampers (each with its node coordinate), plus a revolute joint."""
    rng = np.random.default_rng(seed)
    b = ModelBuilder(dim, f"suspension-{dim}d")
    _body(b, rng, "a")
    _body(b, rng, "b")
    bi = "ground" if ground else "a"
    at = rng.uniform(-1, 1, dim)
    b.add_revolute("J", "ground", "a", rng.uniform(-1, 1, dim), None if dim == 2 else _unit(rng))
    if bump_stops:
        b.add_bump_stop("stop", bi, "b", at, _unit(rng, dim), [[0.005, 0.0], [0.02, 30.0], [0.05, 100.0], [0.2, 150.0]],
                        damping=2.0, point_j=at + 0.05 * rng.standard_normal(dim))
        b.add_bump_stop("stop-", "b", bi, at, _unit(rng, dim), [[0.0, 0.0], [0.01, 50.0], [0.03, 400.0]],
                        damping=0.0, sides="negative")
    b.add_series_spring_damper("yaw", bi, "b", at, at + rng.uniform(0.3, 1.0, dim), 200.0, 3.0, 0.05)
    b.add_series_spring_damper("yaw2", "b", "a", at, at + rng.uniform(0.3, 1.0, dim), 100.0, 5.0, 0.02,
                               free_length=0.9)
    return b.build()


@pytest.mark.parametrize("ground", [False, True])
@pytest.mark.parametrize("dim", [2, 3])
def test_suspension_kernels_match_numpy_model(dim, ground):
    """Bump-stop and series spring-damper kernels: forces and accelerations equal the numpy path to
    round-off at perturbed states (stops in and out of contact, nodes off their rest positions);
    the series element's exact Jacobian kernel equals the numpy Jacobian to round-off, and the
    differenced Jacobian of the bump stops equals the numpy one to the forward-difference error
    O(√ε) relative."""
    model = _suspension_model(dim, seed=20 + dim, ground=ground)
    only_series = _suspension_model(dim, seed=20 + dim, ground=ground, bump_stops=False)
    engaged = set()
    for m in (model, only_series):
        cm = compile_model(m)
        ws = make_workspace(cm)
        st = cm.initial_states()
        for seed in range(3):
            q, v = _perturbed(m, seed)
            t = 0.37
            Q = np.zeros(m.n_v)
            D.body_states(cm.fields["lay"], q, v, ws)
            assert D.forces(cm.data, st, ws, t, q, v, Q) == P.OK
            _close(Q, m.Q(t, q, v), "suspension Q")
            a = np.zeros(m.n_v)
            lam = np.zeros(max(m.n_c, 1))
            assert D.accelerations(cm.data, st, ws, t, q, v, 0.0, 0.0, a, lam) == P.OK
            a_ref, _ = accelerations_numpy(m, t, q, v)
            _close(a, a_ref, "suspension accelerations", 1e-10)
            K, Dm = np.zeros((m.n_v, m.n_v)), np.zeros((m.n_v, m.n_v))
            work = np.zeros(m.n_q), np.zeros(m.n_v), np.zeros(m.n_v), np.zeros(m.n_v)
            assert D.force_jacobian(cm.data, st, ws, t, q, v, K, Dm, *work) == P.OK
            Kq, Kv = m.Q_jacobians(t, q, v)
            if m is only_series:  # exact kernel
                _close(K, Kq.toarray(), "series ∂Q/∂q", RT)
                _close(Dm, Kv.toarray(), "series ∂Q/∂v", RT)
            else:  # forward differences, step h = √ε: truncation O(h |∂²Q|) and round-off O(ε |Q| / h)
                h = np.sqrt(np.finfo(float).eps)
                scale = max(1.0, float(np.max(np.abs(Q))), float(np.max(np.abs(Kq.toarray()))))
                assert np.max(np.abs(K - Kq.toarray())) <= 10 * h * scale, "suspension ∂Q/∂q"
                assert np.max(np.abs(Dm - Kv.toarray())) <= 10 * h * scale, "suspension ∂Q/∂v"
            for fk in m.force_kinds:
                if "engaged" in (out := fk.outputs(m.body_states(q, v), t)):
                    engaged |= set(out["engaged"].tolist())
    assert engaged == {0.0, 1.0}  # the states cover stops in and out of contact


def test_fd_colouring_groups_columns_whose_rows_do_not_meet():
    """Curtis–Powell–Reid grouping: a chain of pair elements 0-1, 1-2, 2-3 needs three colours
    (bodies 0 and 3 share one), one group per body one colour, a body in no group no columns; a
    group naming a body outside the layout is refused by name."""
    from core.compiled.layout import fd_colouring

    @dataclass
    class Rec:
        groups: list | None
        what: str = "test kind"
        names: tuple = ("e0",)

    ncol, col, reach = fd_colouring([Rec([[0, 1], [1, 2], [2, 3]]), Rec([[0], [2], [3, 5]]), Rec(None)], 5)
    assert ncol[0] == 3 and list(col[0]) == [0, 1, 2, 0, -1]
    assert list(reach[0, 1]) == [1, 1, 1, 0, 0] and list(reach[0, 3]) == [0, 0, 1, 1, 0]
    assert ncol[1] == 1 and list(col[1]) == [0, -1, 0, 0, -1]  # index 5 = the ground: ignored
    assert ncol[2] == -1 and list(col[2]) == [-1] * 5
    with pytest.raises(ValueError, match=r"test kind 'e0'.*\[7\]"):
        fd_colouring([Rec([[0, 7]])], 5)
    with pytest.raises(ValueError, match=r"test kind 'e0'.*sequence of body indices, got 0"):
        fd_colouring([Rec([0, 1])], 5)  # a flat list is not two groups


def grouped_and_column_jacobians(cm, m, t, q, v):
    """``[(K, D) by column groups, (K, D) column by column]`` of the compiled force Jacobian at
    ``(t, q, v)``.  ``compile_model`` caches per model, so both come from the one packed model:
    its colouring ``frc_ncol`` is switched off for the second and always restored."""
    grouped = cm.data.frc_ncol.copy()
    out = []
    try:
        for ncol in (grouped, -1):  # by column groups, then every column on its own
            cm.data.frc_ncol[:] = ncol
            ws, st = make_workspace(cm), cm.initial_states()
            K, Dm = np.zeros((m.n_v, m.n_v)), np.zeros((m.n_v, m.n_v))
            work = np.zeros(m.n_q), np.zeros(m.n_v), np.zeros(m.n_v), np.zeros(m.n_v)
            assert D.force_jacobian(cm.data, st, ws, t, q, v, K, Dm, *work) == P.OK
            out.append((K, Dm))
    finally:
        cm.data.frc_ncol[:] = grouped
    return out


@pytest.mark.parametrize("dim", [2, 3])
def test_grouped_differences_equal_column_by_column(dim):
    """The differenced Jacobian by column groups (bushings, bump stops, rotational spring-dampers,
    applied loads and plane contacts name their bodies) equals the column-by-column differences
    of the same kernels: a group's rows do not depend on the other bodies perturbed with it, so
    the two agree to the forward differences' round-off (ε|Q|/√ε relative)."""
    models = [_model(dim, "revolute", seed=31 + dim, loads=True), _suspension_model(dim, seed=40 + dim)]
    for m in models:
        # compile_model caches per model: one packed model, its colouring switched off and back
        cm = compile_model(m)
        grouped = cm.data.frc_ncol.copy()
        assert any(n >= 0 for n in grouped[:len(cm.force_kinds)])
        for seed in range(2):
            q, v = _perturbed(m, seed)
            out = grouped_and_column_jacobians(cm, m, 0.37, q, v)
            assert np.array_equal(cm.data.frc_ncol, grouped)  # the colouring is back
            Q = m.Q(0.37, q, v)
            tol = 100 * np.finfo(float).eps / np.sqrt(np.finfo(float).eps) * max(1.0, float(np.max(np.abs(Q))))
            assert np.max(np.abs(out[0][0] - out[1][0])) <= tol
            assert np.max(np.abs(out[0][1] - out[1][1])) <= tol
            assert np.max(np.abs(out[1][0])) > 0.0


def test_qdot_retract_normalize_match_model():
    model = _model(3, "spherical", seed=4)
    lay = compile_model(model).fields["lay"]
    q, v = _perturbed(model, 5)
    out = np.zeros(model.n_q)
    D.qdot(lay, q, v, out)
    _close(out, model.qdot(q, v), "q̇")
    dv = 0.3 * np.random.default_rng(6).standard_normal(model.n_v)
    qr = q.copy()
    D.retract(lay, qr, dv)
    _close(qr, model.retract(q, dv), "retract")
    qn = 1.1 * q
    D.normalize(lay, qn)
    _close(qn, model.normalize(1.1 * q), "normalize")


def test_baumgarte_terms_enter_the_acceleration_equation():
    """With α, β the constraint rows satisfy Φ_q v̇ = γ − 2α (Φ_q v − ν) − β² Φ (Baumgarte 1972),
    here with a driver (ν ≠ 0)."""
    model = _model(3, "angle-driver", seed=7, springs=False)
    cm = compile_model(model)
    ws = make_workspace(cm)
    q, v = _perturbed(model, 8)
    t = 0.21
    a = np.zeros(model.n_v)
    lam = np.zeros(model.n_c)
    alpha, beta = 7.0, 11.0
    assert D.accelerations(cm.data, cm.initial_states(), ws, t, q, v, alpha, beta, a, lam) == P.OK
    J = model.Phi_q(t, q)
    rhs = model.gamma(t, q, v) - 2 * alpha * (J @ v - model.nu(t, q)) - beta**2 * model.Phi(t, q)
    _close(J @ a, rhs, "Φ_q v̇")
    _close(model.M(t, q) @ a + J.T @ lam, model.Q(t, q, v), "M v̇ + Φ_qᵀλ = Q")


def test_rcm_envelope_is_a_band_on_chains():
    """The Schur complement of a chain is factorised in a band (row widths ≤ 4 in RCM order)."""
    cm = compile_model(models.n_link_chain(32, planar=True))
    widths = np.arange(cm.n_reg) - cm.fields["env_first"]
    assert widths.max() <= 4


# --------------------------------------------------------------------------------------------
# functions of time
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("fn", [
    drivers.constant(1.7),
    drivers.ramp(0.5, -0.2),
    drivers.polynomial([0.1, -2.0, 0.7, 0.05]),
    drivers.harmonic(0.3, 4.0, 0.2, 1.0),
    drivers.tabulated(np.linspace(0.0, 2.0, 11), np.cos(np.linspace(0.0, 2.0, 11)) ** 2),
    drivers.cycloidal(-1.2, 1.3, 0.4),  # rest, motion, rest on [0, 2]
    spin_up_angle(6.0, 1.5),            # the cycloidal law's time integral: spin-up, then constant rate
])
def test_compiled_time_functions_equal_the_numpy_ones(fn):
    prog = encode(fn, "test")
    for t in np.linspace(0.0, 2.0, 23):
        st, *vals = evaluate(prog, t)
        assert st == P.OK
        _close(vals, fn(t), f"{fn!r} at t = {t}", 1e-13)


def test_tabulated_function_past_its_range_is_a_status_not_a_value():
    fn = drivers.tabulated([0.0, 0.5, 1.0, 1.5], [0.0, 0.2, 0.1, 0.4], label="angle table")
    assert evaluate(encode(fn, "test"), 1.6)[0] == P.OUT_OF_RANGE
    with pytest.raises(DataRangeError, match="angle table"):
        fn(1.6)


def test_python_callable_driver_is_refused_by_name():
    b = ModelBuilder(2, "callable-drive")
    b.add_body("m", 1.0, 0.1, (1.0, 0.0))
    b.add_revolute("pin", "ground", "m", (0.0, 0.0))
    b.add_angle_driver("spin", "pin", lambda t: 0.3 * t)
    with pytest.raises(NotCompilable, match="driver 'spin'.*Python callable"):
        compile_model(b.build(assemble=True))


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
    ref, _ = n_link_chain_reference(n)
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


def test_driven_slider_crank_on_the_compiled_path():
    """Simeon's slider crank driven at 150 rad/s by a ramp (a compiled driver): the slider follows
    x = r cos θ + √(l² − r² sin² θ) to the projection tolerance, as on the numpy path."""
    model = models.slider_crank()
    assert METHODS["jit-dop853-projection"].applicable(model) is None
    t = np.linspace(0.0, 2 * np.pi / 150.0, 9)
    res = simulate(model, (0.0, t[-1]), "jit-dop853-projection", t_eval=t, rtol=1e-8, atol=1e-10,
                   projection_tol=1e-11, compute_multipliers=False)
    ref = simulate(model, (0.0, t[-1]), "dop853-projection", t_eval=t, rtol=1e-8, atol=1e-10,
                   projection_tol=1e-11, compute_multipliers=False)
    assert res.status == "finished", res.message
    p = models.SLIDER_CRANK_PARAMETERS
    th = 150.0 * t
    x_exact = p["l1"] * np.cos(th) + np.sqrt(p["l2"] ** 2 - (p["l1"] * np.sin(th)) ** 2)
    slider = model.body_names.index("slider")
    assert np.max(np.abs(res.q[:, 3 * slider] - x_exact)) < 1e-9
    _close(res.q, ref.q, "jit vs numpy slider crank", 1e-8)


def test_massless_extra_coordinate_bead_on_a_helix():
    """The helix parameter s is a massless extra coordinate (the border of the compiled Schur solve):
    s(t) = s0 + ṡ0 t − ½ g c t²/(R² + c²) is reproduced to the tolerance, as on the numpy path."""
    model = models.body_on_helix()
    assert METHODS["jit-dop853-projection"].applicable(model) is None
    t = np.linspace(0.0, 1.0, 6)
    res = simulate(model, (0.0, 1.0), "jit-dop853-projection", t_eval=t, rtol=1e-10, atol=1e-10,
                   compute_multipliers=True)
    assert res.status == "finished", res.message
    s_ref, sd_ref = models.helix_analytic(t)
    assert np.max(np.abs(res.q[:, -1] - s_ref)) < 1e-8
    assert np.max(np.abs(res.v[:, -1] - sd_ref)) < 1e-8
    cm = compile_model(model)
    assert cm.n_x == 1  # one massless coordinate in the border
    ws = make_workspace(cm)
    q, v = _perturbed(model, 11)
    a = np.zeros(model.n_v)
    lam = np.zeros(model.n_c)
    assert D.accelerations(cm.data, cm.initial_states(), ws, 0.0, q, v, 0.0, 0.0, a, lam) == P.OK
    a_ref, lam_ref = accelerations_numpy(model, 0.0, q, v)
    _close(a, a_ref, "helix accelerations", 1e-10)
    _close(lam, lam_ref, "helix multipliers", 1e-10)


@pytest.mark.parametrize("method", ["jit-dop853-projection", "jit-rk45-baumgarte"])
def test_body_with_a_singular_mass_block_point_mass_pendulum(method):
    """A point mass (no rotational inertia) has a singular mass block: its coordinates join the
    border of the compiled saddle solve.  The pendulum's angle follows the exact Jacobi-elliptic
    solution (IFToMM A01 geometry, released horizontally) to the tolerance."""
    from core.benchmarks.references import pendulum_angle_exact

    model = models.simple_pendulum()
    cm = compile_model(model)
    assert cm.n_x == 3 and cm.n_reg == 0  # the bob's (x, y, θ) are border coordinates
    t = np.linspace(0.0, 1.0, 5)
    res = simulate(model, (0.0, 1.0), method, t_eval=t, rtol=1e-10, atol=1e-10, compute_multipliers=False)
    assert res.status == "finished", res.message
    angle = np.arctan2(res.q[:, 0], -res.q[:, 1])  # from the downward vertical
    assert np.max(np.abs(angle - pendulum_angle_exact(t))) < 1e-7


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
    assert set(COMPILED_METHODS) == {f"jit-{k}{s}" for k in ("rk45", "dop853", "rk4")
                                     for s in ("", "-baumgarte", "-projection")}
    assert all(name in METHODS for name in COMPILED_METHODS)
    assert [n for n in COMPILED_METHODS if METHODS[n].fixed_step] == ["jit-rk4", "jit-rk4-baumgarte", "jit-rk4-projection"]


# --------------------------------------------------------------------------------------------
# the compiled fixed-step classical RK4
# --------------------------------------------------------------------------------------------


def _numpy_rk4(model, h, n_steps):
    """Kutta's classical RK4 written out on the numpy right-hand side (:func:`core.dynamics.accelerations`)."""
    def f(t, y):
        q, v = y[:model.n_q], y[model.n_q:]
        return np.concatenate([model.qdot(q, v), accelerations_numpy(model, t, q, v)[0]])

    y, t = np.concatenate([model.q0, model.v0]), 0.0
    for _ in range(n_steps):
        k1 = f(t, y)
        k2 = f(t + h / 2, y + h / 2 * k1)
        k3 = f(t + h / 2, y + h / 2 * k2)
        k4 = f(t + h, y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += h
    return y


@pytest.mark.parametrize("spatial", [False, True])
def test_rk4_is_the_classical_method(spatial):
    """The compiled loop takes the classical RK4 step: 40 steps on a penalty chain equal the same
    tableau written out on the numpy right-hand side to round-off."""
    model = models.n_link_chain(3, planar=not spatial, spatial=spatial, stiff_k=1e4)
    h, n = 2e-3, 40
    res = simulate(model, (0.0, n * h), "jit-rk4", h=h, t_eval=[n * h], compute_multipliers=False)
    assert res.counters["n_steps"] == n and res.counters["n_rhs"] == 4 * n + 1
    ref = _numpy_rk4(model, h, n)
    _close(res.q[-1], ref[:model.n_q], "rk4 q", 1e-10)
    _close(res.v[-1], ref[model.n_q:], "rk4 v", 1e-10)


def test_rk4_fourth_order_and_the_peer_step_on_the_stiff_chain():
    """Penalty chain N = 2, k = 1e6 N/m, 0.2 s against the independent DOP853 reference
    (core.benchmarks.references): halving h divides the tip error by 2⁴ (12–20 accepted), and at a
    step just inside the stability boundary the run is stable and accurate to 1e-6 m."""
    from core.benchmarks.references import stiff_chain_tip_reference

    model = models.n_link_chain(2, planar=True, stiff_k=1e6)
    t_end = 0.2
    ref = stiff_chain_tip_reference(2, 1e6, t_end=t_end)
    errs = {}
    for h in (t_end / 1000, t_end / 2000):
        res = simulate(model, (0.0, t_end), "jit-rk4", h=h, t_eval=[t_end], compute_multipliers=False)
        assert res.status in FINISHED, res.message
        errs[h] = float(np.linalg.norm(models.chain_tip(model, res.q[-1]) - ref))
    ratio = errs[t_end / 1000] / errs[t_end / 2000]
    assert 12.0 < ratio < 20.0, (errs, ratio)
    assert errs[t_end / 1000] < 1e-6


def test_rk4_beyond_the_stability_boundary_fails_and_keeps_the_last_state():
    """k = 1e8 N/m at h = 1 ms: h|λ| far beyond 2.78, the state diverges; the run fails naming the
    stability boundary and keeps the outputs computed before."""
    model = models.n_link_chain(2, planar=True, stiff_k=1e8)
    res = simulate(model, (0.0, 0.5), "jit-rk4", h=1e-3, t_eval=np.linspace(0.0, 0.5, 51),
                   compute_multipliers=False)
    assert res.status == "failed"
    assert "stability boundary" in res.message or "no correct digit" in res.message, res.message
    assert res.t[-1] < 0.5 and np.all(np.isfinite(res.q))


def test_rk4_global_error_estimate_and_output_times():
    """A fixed step too coarse for the tolerance ends "finished with warnings" with the summed
    estimate named; steps land on output times (a shortened step before each); options of the
    error-controlled methods (stiffness) and a missing h are refused."""
    from core.errors import InputError, UnknownOptionError

    model = models.n_link_chain(2, planar=True)
    t_eval = np.linspace(0.0, 1.0, 7)
    coarse = simulate(model, (0.0, 1.0), "jit-rk4-projection", h=0.01, t_eval=t_eval, rtol=1e-10, atol=1e-12)
    assert coarse.status == "finished with warnings" and "fixed step h = 0.01 s: estimated global error" in coarse.message
    np.testing.assert_array_equal(coarse.t, t_eval)
    assert coarse.counters["n_steps"] == 6 * 17  # 16 full steps and one of 2/3 h per output interval
    fine = simulate(model, (0.0, 1.0), "jit-rk4-projection", h=0.001, t_eval=t_eval, rtol=1e-4, atol=1e-6)
    assert fine.status == "finished", fine.message
    ref, _ = n_link_chain_reference(2)
    assert float(np.linalg.norm(models.chain_tip(model, fine.q[-1]) - ref)) < 1e-6
    with pytest.raises(UnknownOptionError, match=r"unknown option\(s\) \['stiffness'\]; this method takes no options"):
        simulate(model, (0.0, 1.0), "jit-rk4", h=0.01, stiffness="off")
    with pytest.raises(InputError, match="fixed-step method: give a step size h"):
        simulate(model, (0.0, 1.0), "jit-rk4")


# --------------------------------------------------------------------------------------------
# an element kind defined outside core joins the compiled path by registration
# --------------------------------------------------------------------------------------------


@force_kernel
def _drag_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """Linear drag ``F = −c ṙ`` at the centre of mass and ``M̄ = −c_r ω̄`` (fd: c, c_r; ix: body)."""
    nb, dim = lay[P.L_NB], lay[P.L_DIM]
    nvb = lay[P.L_NVB]
    for e in range(ix.shape[0]):
        b = ix[e, 0]
        c, cr = fd[e, 0], fd[e, 1]
        o = b * nvb
        for i in range(dim):
            Q[o + i] -= c * rd[b, i]
        if dim == 2:
            Q[o + 2] -= cr * w[b, 2]
        else:
            for i in range(3):
                Q[o + 3 + i] -= cr * w[b, i]
    _ = nb
    return P.OK


@force_jacobian_kernel
def _drag_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    nvb, dim = lay[P.L_NVB], lay[P.L_DIM]
    for e in range(ix.shape[0]):
        o = ix[e, 0] * nvb
        for i in range(nvb):
            D[o + i, o + i] -= fd[e, 0] if i < dim else fd[e, 1]
    return P.OK


@dataclass(frozen=True)
class Drag(ForceElement):
    """Linear translational and rotational drag on a body (a force kind written outside core)."""

    name: str
    body: str
    c: float
    c_rot: float

    @classmethod
    def compile(cls, elements, ctx):
        return DragKind(elements, ctx)


class DragKind(ForceKind):
    def __init__(self, elements, ctx):
        self.names = [e.name for e in elements]
        self.b = np.array([ctx.index(e.body, e.name) for e in elements], np.int64)
        self.c = np.array([[e.c, e.c_rot] for e in elements], float)

    def evaluate(self, bs, t):
        d = bs.space.dim
        Qb = np.zeros((len(self.b), bs.space.n_v))
        Qb[:, :d] = -self.c[:, :1] * bs.rdot[self.b]
        Qb[:, d:] = -self.c[:, 1:] * bs.w[self.b]
        return ForceEval(self.b, Qb)

    def jacobian(self, bs, t):
        n, nv, d = len(self.b), bs.space.n_v, bs.space.dim
        Kv = np.zeros((n, nv, nv))
        for i in range(nv):
            Kv[:, i, i] = -(self.c[:, 0] if i < d else self.c[:, 1])
        return ForceJacobian(self.b, self.b, np.zeros((n, nv, nv)), Kv)

    def compiled(self, layout):
        return CompiledForces(forces=_drag_forces, fd=self.c, ix=self.b[:, None], names=self.names,
                              jacobian=_drag_jacobian, what="drag")


@pytest.mark.parametrize("dim", [2, 3])
def test_element_kind_from_outside_core_runs_compiled(dim):
    """A kind registered by a module outside core (this test) runs on the compiled integrators: same
    forces as its numpy kind, and a freely falling body with drag follows the closed form
    ``v(t) = −(g m/c)(1 − e^{−c t/m})``."""
    b = ModelBuilder(dim, f"drag-{dim}d")
    m, c = 2.0, 3.0
    b.add_body("ball", m, 0.1 if dim == 2 else [0.1, 0.1, 0.1], np.zeros(dim),
               angular_velocity=1.0 if dim == 2 else [0.0, 0.0, 1.0])
    b.add_force(Drag("air", "ball", c, 0.5))
    model = b.build()
    cm = compile_model(model)
    ws = make_workspace(cm)
    q, v = _perturbed(model, 2)
    Q = np.zeros(model.n_v)
    D.body_states(cm.fields["lay"], q, v, ws)
    assert D.forces(cm.data, cm.initial_states(), ws, 0.0, q, v, Q) == P.OK
    _close(Q, model.Q(0.0, q, v), "drag Q")
    res = simulate(model, (0.0, 1.0), "jit-dop853", t_eval=[1.0], rtol=1e-10, atol=1e-12)
    assert res.status == "finished"
    g = 9.81
    v_exact = -(g * m / c) * (1.0 - np.exp(-c / m))
    assert abs(res.v[-1, 1 if dim == 2 else 2] - v_exact) < 1e-8


@accept_kernel
def _count_accepts(t, q, v, r, A, rd, w, lay, fd, ix, state, err):
    state[0, 0] += 1.0
    state[0, 1] = t
    return P.OK


@force_kernel
def _seeded_spring(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """A spring whose force reads the search state only as a seed: F = −k x (the count is not used)."""
    b = ix[0, 0]
    Q[b * lay[P.L_NVB]] -= fd[0, 0] * r[b, 0]
    return P.OK


@dataclass(frozen=True)
class SeededSpring(ForceElement):
    name: str
    body: str
    k: float

    @classmethod
    def compile(cls, elements, ctx):
        return SeededSpringKind(elements, ctx)


class SeededSpringKind(ForceKind):
    stateful = True

    def __init__(self, elements, ctx):
        self.names = [e.name for e in elements]
        self.b = np.array([ctx.index(e.body, e.name) for e in elements], np.int64)
        self.k = np.array([e.k for e in elements])

    def evaluate(self, bs, t):
        Qb = np.zeros((len(self.b), bs.space.n_v))
        Qb[:, 0] = -self.k * bs.r[self.b, 0]
        return ForceEval(self.b, Qb)

    def compiled(self, layout):
        return CompiledForces(forces=_seeded_spring, fd=self.k[:, None], ix=self.b[:, None], names=self.names,
                              accept=_count_accepts, state=np.zeros((1, 2)), what="seeded spring")


def test_compiled_search_state_kernel_runs_on_accepted_steps_only():
    """The accept kernel of a stateful kind runs once per accepted step (not per stage, rejected
    attempt or output), and each run starts from the kind's initial state."""
    b = ModelBuilder(2, "seeded")
    b.add_body("m", 1.0, 0.1, (1.0, 0.0))
    b.add_force(SeededSpring("spring", "m", 100.0))
    model = b.build()
    cm = compile_model(model)
    assert cm.stateful
    integ = METHODS["jit-dop853"](model, (0.0, 1.0), rtol=1e-6, atol=1e-8)
    for t_out in np.linspace(0.1, 1.0, 10):
        integ.advance(t_out)
    assert integ.status == "finished"
    count, t_last = integ._states[0], integ._states[1]
    assert count == integ.counters["n_steps"] and integ.counters["n_rejected"] + integ.counters["n_steps"] < \
        integ.counters["n_rhs"]
    assert t_last == pytest.approx(1.0)
    again = METHODS["jit-dop853"](model, (0.0, 1.0), rtol=1e-6, atol=1e-8)
    assert again._states[0] == 0.0  # a fresh copy per run


# --------------------------------------------------------------------------------------------
# honest refusal and failure
# --------------------------------------------------------------------------------------------


def test_not_compilable_names_the_element():
    b = ModelBuilder(2, "callable-actuator")
    b.add_body("m", 1.0, 0.1, (1.0, 0.0))
    b.add_spring_damper("muscle", "ground", "m", (0.0, 0.0), (1.0, 0.0), 10.0, actuator=lambda t: np.sin(t))
    with pytest.raises(NotCompilable, match="spring-damper 'muscle'"):
        simulate(b.build(), (0.0, 0.1), "jit-rk45")

    from core.joints import UserConstraint

    class Python(UserConstraint):
        name, rows, bodies = "python-only", 1, ("m",)

        def phi(self, t, q):
            return np.array([q[self.q_index[0]] - 1.0])

        def jacobian(self, t, q):
            return np.array([[1.0, 0.0, 0.0]])

        def gamma(self, t, q, v):
            return np.zeros(1)

    b = ModelBuilder(2, "user")
    b.add_body("m", 1.0, 0.1, (1.0, 0.0))
    b.add_joint(Python())
    reason = METHODS["jit-rk45"].applicable(b.build())
    assert reason is not None and "user constraint 'python-only'" in reason
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

    with pytest.raises(NotCompilable, match="redundant='remove'"):
        compile_model(four_bar_spatial("keep"))
    res = simulate(four_bar_spatial("remove"), (0.0, 0.5), "jit-dop853-projection", n_output=3)
    assert res.status == "finished" and np.max(res.position_violation) < 1e-7


def test_coincident_spring_points_are_refused_with_a_message():
    """A spring-damper whose points coincide has no direction: the kernel reports it by name."""
    b = ModelBuilder(2, "collapse")
    b.add_body("m", 1.0, 0.1, (0.0, 0.0))
    b.add_spring_damper("sd", "ground", "m", (0.0, 0.0), (0.0, 0.0), stiffness=10.0, free_length=0.5)
    with pytest.raises(ValueError, match="spring-damper 'sd': the attachment points of a spring-damper coincide"):
        simulate(b.build(), (0.0, 1.0), "jit-rk45")


def test_dependent_rows_give_a_non_positive_pivot():
    """The envelope Cholesky refuses a singular Schur complement (status code, not a wrong answer)."""
    model = models.n_link_chain(3, planar=True)
    cm = compile_model(model)
    ws = make_workspace(cm)
    q0, v0 = model.q0.copy(), model.v0.copy()  # writable: the kernels take mutable arrays
    D.body_states(cm.fields["lay"], q0, v0, ws)
    assert D.constraints(cm.data, ws, 0.0, q0, v0, 0) == P.OK
    assert D.factor(cm.data, ws) == P.OK
    ws.G[1] = ws.G[0]  # both rows of the ground pivot made equal: dependent rows
    assert D.factor(cm.data, ws) == P.SINGULAR


def test_stiffness_test_warns_or_stops():
    """Hairer's stiffness test: on the k = 1e8 penalty chain the explicit step is stability-limited
    (h|λ| beyond the boundary on 15 consecutive steps); the rigid chain never trips it."""
    stiff = models.n_link_chain(2, planar=True, stiff_k=1e8)
    kw = dict(t_eval=[0.02], rtol=1e-5, atol=1e-5, compute_multipliers=False)
    warn = simulate(stiff, (0.0, 0.02), "jit-dop853", **kw)
    assert warn.status == "finished with warnings" and warn.warnings[0].startswith("the problem became stiff at t =")
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


# --------------------------------------------------------------------------------------------
# the compiled Radau IIA integrator (stiff problems)
# --------------------------------------------------------------------------------------------


def test_radau_registry_names():
    from core.integrators.compiled_radau import RADAU_METHODS

    assert set(RADAU_METHODS) == {"jit-radau", "jit-radau-baumgarte", "jit-radau-projection"}
    assert all(name in METHODS for name in RADAU_METHODS)


@pytest.mark.parametrize("method", ["jit-radau-projection", "jit-radau-baumgarte"])
def test_radau_chain_against_minimal_coordinate_reference(method):
    """8-link chain at t = 1 s: the error of the order-5 method falls with the tolerance and
    reaches below 1e-8 m at rtol 1e-8 (the index-1 formulation with the saddle-point Newton solve)."""
    model = models.n_link_chain(8, planar=True)
    ref, _ = n_link_chain_reference(8)
    errs = []
    for tol in (1e-5, 1e-8):
        res = simulate(model, (0.0, 1.0), method, t_eval=[1.0], rtol=tol, atol=tol, compute_multipliers=False)
        assert res.status == "finished", res.message
        errs.append(float(np.linalg.norm(models.chain_tip(model, res.q[-1]) - ref)))
    assert errs[1] < 1e-8 and errs[1] < errs[0] / 100


@pytest.mark.parametrize("k", [1e6, 1e8])
def test_radau_stiff_chain_no_stability_limit(k):
    """Penalty chain N = 2 (k = 1e6, 1e8 N/m, undamped): Radau IIA is L-stable, so its step follows the
    accuracy asked for, never a stability bound (no stiffness warning); its error against the
    resolved DOP853 reference falls with the tolerance.  Reference: core.benchmarks.references' independent
    penalty right-hand side at rtol 1e-12."""
    from core.benchmarks.references import (
        stiff_chain_tip_reference as _stiff_chain_tip_reference,
    )

    model = models.n_link_chain(2, planar=True, stiff_k=k)
    t_end = 0.2
    ref = _stiff_chain_tip_reference(2, k, t_end=t_end)
    errs = []
    for tol in (1e-4, 1e-7):
        res = simulate(model, (0.0, t_end), "jit-radau", t_eval=[t_end], rtol=tol, atol=tol, compute_multipliers=False)
        assert res.status == "finished" and "stiff" not in res.message, res.message
        c = res.counters
        assert 0 <= c["n_newton_failures"] <= c["n_rejected"] and c["n_factor"] % 2 == 0  # real + complex pairs
        errs.append(float(np.linalg.norm(models.chain_tip(model, res.q[-1]) - ref)))
    assert errs[1] < errs[0] and errs[1] < 1e-6


def test_radau_output_by_collocation_polynomial_and_projection():
    """Outputs between steps come from the collocation polynomial (plus the linear blend of the
    projection correction): they agree with a tight DOP853 run to the tolerance, and with
    projection both constraint levels hold at every output."""
    model = models.n_link_chain(4, planar=True)
    t = np.linspace(0.0, 1.0, 201)
    res = simulate(model, (0.0, 1.0), "jit-radau-projection", t_eval=t, rtol=1e-5, atol=1e-5, projection_tol=1e-10)
    ref = simulate(model, (0.0, 1.0), "dop853-projection", t_eval=t, rtol=1e-11, atol=1e-11)
    assert res.status == "finished"
    assert res.counters["n_steps"] < len(t)  # fewer steps than outputs: outputs are interpolated
    _close(res.q, ref.q, "Radau dense output", 1e-5)
    assert np.max(res.position_violation) < 1e-5


def test_radau_massless_coordinate_and_driver():
    """The border of the compiled saddle solve (massless helix parameter) and a compiled driver
    (slider crank) also run through the Radau loop."""
    t = np.linspace(0.0, 1.0, 6)
    res = simulate(models.body_on_helix(), (0.0, 1.0), "jit-radau-projection", t_eval=t, rtol=1e-9, atol=1e-9)
    s_ref, _ = models.helix_analytic(t)
    assert res.status == "finished" and np.max(np.abs(res.q[:, -1] - s_ref)) < 1e-8
    model = models.slider_crank()
    tt = np.linspace(0.0, 2 * np.pi / 150.0, 9)
    res = simulate(model, (0.0, tt[-1]), "jit-radau-projection", t_eval=tt, rtol=1e-8, atol=1e-10)
    p = models.SLIDER_CRANK_PARAMETERS
    x = p["l1"] * np.cos(150 * tt) + np.sqrt(p["l2"] ** 2 - (p["l1"] * np.sin(150 * tt)) ** 2)
    assert res.status == "finished" and np.max(np.abs(res.q[:, 3 * model.body_names.index("slider")] - x)) < 1e-8


def test_radau_fails_honestly_on_a_singular_iteration_matrix():
    """A free point mass (no inertia about its axis and nothing fixing its rotation): the iteration
    matrix is singular and the run ends failed with that cause (not a wrong answer)."""
    b = ModelBuilder(2, "free-point")
    b.add_body("p", 1.0, 0.0, (0.0, 0.0))
    res = simulate(b.build(), (0.0, 0.1), "jit-radau", n_output=3)
    assert res.status == "failed" and ("singular" in res.message or "not positive" in res.message)


def test_radau_spatial_chain_against_dop853():
    """Spatial bodies (Euler parameters, 6-wide velocity blocks, the ``δθ̄ = 2 L(p) δp`` map of the
    Newton solve) through the Radau loop: the 4-link spatial chain at rtol 1e-8 agrees with a tight
    DOP853 run of the numpy model to 1e-6 in every coordinate, and the Euler parameters stay unit."""
    model = models.n_link_chain(4, spatial=True)
    t = np.linspace(0.0, 0.5, 6)
    ref = simulate(model, (0.0, 0.5), "dop853-projection", t_eval=t, rtol=1e-11, atol=1e-11)
    for method in ("jit-radau-projection", "jit-radau-baumgarte"):
        res = simulate(model, (0.0, 0.5), method, t_eval=t, rtol=1e-8, atol=1e-8)
        assert res.status == "finished", res.message
        _close(res.q, ref.q, f"{method} spatial chain", 1e-6)
        p = res.q[:, :28].reshape(len(t), 4, 7)[:, :, 3:]
        assert np.max(np.abs(np.linalg.norm(p, axis=2) - 1.0)) < 1e-10


def test_radau_stage_frames_invert_and_carry_angles_into_the_jacobians_frame():
    """The Newton solve's stage maps (compiled_radau, "Spinning bodies"): ``_from_frame`` inverts
    ``_to_frame`` for any increment (the normal component of δp included), and an increment
    ``δp = ½ L(p)ᵀ δθ̄`` of body-frame angle δθ̄ at the stage orientation maps to ``Rᵀ δθ̄``, its
    angle in the Jacobian's frame, with nothing along ``p``; velocities likewise ``Rᵀ δω̄``.  Two
    spatial bodies and one extra coordinate; planar: the identity."""
    import numba

    from core.integrators import compiled_radau as CR

    @numba.njit
    def maps(lay, nv, P, R, x, X, back):
        CR._to_frame(lay, nv, P, R, x, X)
        CR._from_frame(lay, nv, P, R, X, back)

    rng = np.random.default_rng(7)
    nb, ne = 2, 1
    nq, nv = 7 * nb + ne, 6 * nb + ne
    lay = np.array([nb, 3, 7 * nb, 6 * nb, nq, nv, ne], np.int64)
    P = rng.normal(size=(nb, 4))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    R = np.array([frames.euler_to_matrix(frames.axis_angle_to_euler(a / np.linalg.norm(a), 0.4 + b))
                  for b, a in enumerate(rng.normal(size=(nb, 3)))])
    x = rng.normal(size=nq + nv)
    X, back = np.zeros(2 * nv + nb), np.zeros(nq + nv)
    maps(lay, nv, P, R, x, X, back)
    np.testing.assert_allclose(back, x, rtol=0, atol=1e-14)
    # a pure rotation increment and an angular velocity increment of body 0
    th, om = np.array([0.3, -0.2, 0.5]), np.array([-1.0, 2.0, 0.7])
    e0, e = P[0, 0], P[0, 1:]
    L = np.column_stack([-e, -np.array([[0, -e[2], e[1]], [e[2], 0, -e[0]], [-e[1], e[0], 0]]) + e0 * np.eye(3)])
    x = np.zeros(nq + nv)
    x[3:7] = 0.5 * L.T @ th
    x[nq + 3:nq + 6] = om
    maps(lay, nv, P, R, x, X, back)
    np.testing.assert_allclose(X[3:6], R[0].T @ th, rtol=0, atol=1e-14)
    np.testing.assert_allclose(X[nv + 3:nv + 6], R[0].T @ om, rtol=0, atol=1e-14)
    assert abs(X[2 * nv]) < 1e-15
    lay2 = np.array([2, 2, 6, 6, 6, 6, 0], np.int64)
    x2 = rng.normal(size=12)
    X2, back2 = np.zeros(2 * 6 + 2), np.zeros(12)
    maps(lay2, 6, P, R, x2, X2, back2)
    np.testing.assert_array_equal(X2[:12], x2)
    np.testing.assert_array_equal(back2, x2)


def test_radau_keeps_the_body_frame_for_a_tumbling_asymmetric_body():
    """A torque-free body with inertia (1, 2, 3) kg m² tumbling near its intermediate axis: its
    body-frame inertia is constant in the body frame and turns in the spatial one, so the Radau
    loop's frame choice keeps the body frame, and the motion agrees with a tight DOP853 run to
    the tolerance asked for (rtol 1e-8: 1e-6 over 5 s of tumbling, the flip included)."""
    from core.integrators import get_method

    b = ModelBuilder(3, "tumbling body", gravity=(0.0, 0.0, 0.0))
    b.add_body("B", 2.0, np.diag([1.0, 2.0, 3.0]), (0.0, 0.0, 0.0), angular_velocity=(0.05, 6.0, 0.05))
    model = b.build()
    t = np.linspace(0.0, 5.0, 11)
    ref = simulate(model, (0.0, 5.0), "dop853", t_eval=t, rtol=1e-12, atol=1e-12)
    res = simulate(model, (0.0, 5.0), "jit-radau", t_eval=t, rtol=1e-8, atol=1e-8)
    assert res.status == "finished", res.message
    _close(res.q, ref.q, "tumbling body, jit-radau", 1e-6)
    _close(res.v, ref.v, "tumbling body, jit-radau", 1e-6)
    integ = get_method("jit-radau")(model, (0.0, 5.0), rtol=1e-8, atol=1e-8)
    integ.advance(5.0)
    assert integ.counters["n_jac"] > 2 and integ._rw.spatial[0] == 0.0


@pytest.mark.parametrize("method", ["jit-dop853-projection", "jit-radau-projection"])
def test_compiled_torsional_oscillator_and_bushing(method):
    """Rotational spring-damper and bushing kernels in motion (the implicit method with their
    difference Jacobians).  A rod pinned at its end to the ground with a torsion spring k, no
    gravity, released at θ = 0 with the free angle θ₀ = −0.3 rad: θ(t) = θ₀ (1 − cos ω t),
    ω² = k / (m l²/3).  A mass hanging on a damped bushing with rotated marker axes (isotropic
    translational stiffness k) settles under gravity to the static deflection m g / k, straight down."""
    m, L, k = 2.0, 0.8, 30.0
    b = ModelBuilder(2, "torsion", gravity=(0.0, 0.0))
    b.add_body("rod", m, m * L**2 / 12, (L / 2, 0.0))
    b.add_revolute("pin", "ground", "rod", (0.0, 0.0))
    b.add_rotational_spring_damper("torsion", "ground", "rod", k, free_angle=-0.3)
    model = b.build()
    t = np.linspace(0.0, 1.0, 6)
    res = simulate(model, (0.0, 1.0), method, t_eval=t, rtol=1e-10, atol=1e-10)
    assert res.status == "finished", res.message
    omega = np.sqrt(k / (m * L**2 / 3))
    assert np.max(np.abs(res.q[:, 2] + 0.3 * (1.0 - np.cos(omega * t)))) < 1e-7
    b = ModelBuilder(3, "bushing-mount")
    b.add_body("mass", 5.0, [0.1, 0.2, 0.3], (0.0, 0.0, 0.0))
    axes = frames.euler_to_matrix(frames.axis_angle_to_euler(np.array([1.0, 2.0, 2.0]) / 3.0, 0.7))
    b.add_bushing("mount", "ground", "mass", (0.0, 0.0, 0.0), 2e4, 500.0, 400.0, 5.0, axes=axes)
    model = b.build()
    res = simulate(model, (0.0, 3.0), method.replace("-projection", ""), t_eval=[3.0], rtol=1e-8, atol=1e-10)
    assert res.status == "finished", res.message
    assert abs(res.q[-1, 2] + 5.0 * 9.81 / 2e4) < 1e-6 and np.max(np.abs(res.q[-1, :2])) < 1e-6


@pytest.mark.parametrize("dim", [2, 3])
def test_force_kind_table_addresses_each_kinds_own_data(dim):
    """``frc_tab`` (one row per force kind, read by the right-hand side instead of eight offset
    arrays) addresses exactly the data, indices and search state each kind was packed with."""
    from core.compiled.protocol import FT_FD0, FT_FD1, FT_FW, FT_IW, FT_IX0, FT_IX1, FT_N, FT_ST0, FT_ST1, FT_STN, FT_STW

    cm = compile_model(_suspension_model(dim, seed=3, ground=True))
    f, tab, states = cm.fields, cm.fields["frc_tab"], cm.initial_states()
    assert len(cm.force_kinds) >= 2
    for k, rec in enumerate(cm.force_kinds):
        n = tab[k, FT_N]
        np.testing.assert_array_equal(f["frc_fd"][tab[k, FT_FD0]:tab[k, FT_FD1]].reshape(n, tab[k, FT_FW]), rec.fd)
        np.testing.assert_array_equal(f["frc_ix"][tab[k, FT_IX0]:tab[k, FT_IX1]].reshape(n, tab[k, FT_IW]), rec.ix)
        st = states[tab[k, FT_ST0]:tab[k, FT_ST1]].reshape(tab[k, FT_STN], tab[k, FT_STW])
        assert st.size == np.asarray(rec.state).size
        np.testing.assert_array_equal(tab[k], [f["frc_fo"][k], f["frc_fo"][k + 1], f["frc_n"][k], f["frc_fw"][k],
                                               f["frc_io"][k], f["frc_io"][k + 1], f["frc_iw"][k], f["st_off"][k],
                                               f["st_off"][k + 1], f["st_n"][k], f["st_w"][k]])
