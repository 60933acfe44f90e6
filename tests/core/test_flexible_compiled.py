"""Flexible bodies on the compiled path (core.flexible.compiled, issue 23).

Tier 1: with ``inertia="undeformed"`` and mean axes the numpy body is a rigid body plus modal
oscillators; with the inertia of the deformed body (or an undeformed inertia that couples the frame
and the modes) it is a *mass group* whose mass matrix M(q_f) the compiled kernels rebuild at every
evaluation.  Either way the compiled kernels give the numpy model's Φ, Φ_q, γ, M, Q, accelerations
and multipliers to round-off, planar and spatial, with and without geometric stiffening.  Tier 2: a
run of the compiled integrators equals the numpy one to the integration tolerance; energy is
conserved; the spin-up beam turns past the angles where a row choice made at the start would make
the Schur complement singular.  Tier 3: the undeformed inertia against the exact one on a slowly
rotating body (difference of the order of the dropped terms).  Refusals name the body and the
reason.
"""

from __future__ import annotations

import numpy as np
import pytest

from core import frames
from core.compiled import compile_model, make_workspace
from core.compiled import dynamics as D
from core.compiled import protocol as P
from core.dynamics import accelerations as accelerations_numpy
from core.errors import ModelError, NotCompilable
from core.flexible import BeamMesh, FEModel, free_interface
from core.flexible.compiled import MAX_COMPILED_MODES
from core.flexible.models import spin_up_beam
from core.model import ModelBuilder
from core.simulation import simulate
from tests.core.test_compiled import _jacobian_from_slots
from tests.core.test_flexible_body import SECTION


def _close(a, b, what, rtol=1e-12):
    """|a − b| ≤ rtol · max(1, |b|) (the tolerance of tests/core/test_compiled.py with another rtol)."""
    from tests.core.test_compiled import _close as close

    close(a, b, what, rtol)


def _l_shaped_centred(dim):
    """Two perpendicular beams (an L) with the node coordinates' origin at the centre of mass."""
    if dim == 2:
        nodes = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 0.4], [1.0, 0.8]])
    else:
        nodes = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.4, 0.1], [1.0, 0.8, 0.2]])
    seg = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    mid = 0.5 * (nodes[1:] + nodes[:-1])
    centre = (seg[:, None] * mid).sum(0) / seg.sum()  # uniform beams: the centre of mass
    mesh = BeamMesh(nodes - centre, np.array([[0, 1], [1, 2], [2, 3], [3, 4]]), orientation=(0.3, 0.2, 1.0))
    return FEModel.from_beam(mesh, SECTION)


def _model(dim, inertia="undeformed", n_modes=3, gravity=True, damping=0.02, seed=0, centred=True, dissipation=True,
           stiffening=False):
    """A free L-shaped flexible body hung from the ground by a bushing at one node frame, a second
    node frame carrying a rigid mass on a spring."""
    fe = _l_shaped_centred(dim)
    if not centred:
        fe = FEModel.from_beam(BeamMesh(fe.nodes + 0.3, fe.beam[0].elements, orientation=(0.3, 0.2, 1.0)), SECTION)
    modes = free_interface(fe.M, fe.K, fe.nodes, fe.dofs_per_node, n_modes).orthonormalized(drop_rigid=True)
    rng = np.random.default_rng(seed)
    g = (0.0, -9.81) if dim == 2 else (0.0, 0.0, -9.81)
    b = ModelBuilder(dim, "flexible L", gravity=g if gravity else np.zeros(dim))
    if dim == 2:
        pose = dict(position=(0.3, -0.2), orientation=0.4, velocity=(0.05, -0.03), angular_velocity=0.2)
    else:
        pose = dict(position=(0.3, -0.2, 0.1), orientation=frames.axis_angle_to_euler(np.array([1.0, 2.0, 0.5]) / 2.29, 0.7),
                    velocity=(0.05, -0.03, 0.02), angular_velocity=(0.1, -0.2, 0.15))
    m = modes.T.shape[1]
    b.add_flexible_body("L", fe, modes, modal_coordinates=1e-4 * rng.standard_normal(m),
                        modal_velocities=0.01 * rng.standard_normal(m), damping_ratio=damping, inertia=inertia,
                        geometric_stiffening=stiffening, **pose)
    n0 = b.add_node_frame("L", 0)
    n4 = b.add_node_frame("L", 4)
    model0 = b.build()
    p0 = model0.point_position(model0.q0, n0, np.zeros(dim))
    p4 = model0.point_position(model0.q0, n4, np.zeros(dim))
    rot = 0.0 if dim == 2 else 50.0
    b.add_bushing("hanger", "ground", n0, at=p0, translational_stiffness=2e4, rotational_stiffness=rot,
                  translational_damping=5.0 if dissipation else 0.0, rotational_damping=0.0)
    if dim == 2:
        b.add_body("weight", 0.2, 1e-4, p4 + np.array([0.0, -0.1]))
    else:
        b.add_body("weight", 0.2, np.diag([1e-4, 1e-4, 1e-4]), p4 + np.array([0.0, 0.0, -0.1]))
    b.add_spring_damper("weight spring", n4, "weight", p4, p4 + (np.array([0.0, -0.1]) if dim == 2 else np.array([0.0, 0.0, -0.1])),
                        stiffness=3e3, damping=1.0 if dissipation else 0.0)
    return b.build()


@pytest.mark.parametrize("dim", [2, 3])
def test_undeformed_inertia_is_a_rigid_body_plus_modal_oscillators(dim):
    """Mean axes with the origin at the centre of mass: M̂₀ = diag(m I, J̄₀, μ_k); the forces are
    weight, the Euler gyroscopic moment and −K q − D q̇ (no term of the deformation's inertia)."""
    model = _model(dim)
    f = model.flexible[0]
    data = f.data
    q, v = model.q0.copy(), np.random.default_rng(5).standard_normal(model.n_v)
    M = model.M(0.0, q).toarray()[np.ix_(f.vi, f.vi)]
    a = dim + data.n_rot
    _close(M[:dim, :dim], data.mass * np.eye(dim), "translation block", 1e-12)
    off = M.copy()
    off[:dim, :dim] = 0.0
    off[dim:a, dim:a] = 0.0
    off[a:, a:] -= np.diag(np.diag(M[a:, a:]))
    assert np.max(np.abs(off)) <= 1e-10 * np.max(np.abs(M)), "M̂₀ is block diagonal"
    A = model.body_frame(q, "L")
    vb = v[f.vi]
    qf, qfd = q[f.qi[model.space.n_q:]], vb[a:]
    Mb, Qb = data.mass_and_forces(A, vb[:dim], vb[dim:a], qf, qfd, model.gravity)
    J = M[dim:a, dim:a]
    w = vb[dim:a]
    gyro = -np.cross(w, J @ w) if dim == 3 else np.zeros(1)
    _close(Qb[:dim], data.mass * model.gravity, "weight", 1e-10)
    _close(Qb[dim:a], gyro, "gyroscopic moment", 1e-10)
    _close(Qb[a:], -data.K @ qf - data.D @ qfd, "modal forces", 1e-10)


@pytest.mark.parametrize("dim", [2, 3])
def test_flexible_kernels_match_the_numpy_model(dim):
    model = _model(dim)
    cm = compile_model(model)
    ws = make_workspace(cm)
    st = cm.initial_states()
    rng = np.random.default_rng(11)
    q = model.retract(model.q0, 0.05 * rng.standard_normal(model.n_v))
    v = rng.standard_normal(model.n_v)
    t = 0.2
    D.body_states(cm.fields["lay"], q, v, ws)
    _equations_match_the_numpy_model(model, cm, ws, st, t, q, v)


def _equations_match_the_numpy_model(model, cm, ws, st, t, q, v):
    """Φ, γ, Φ_q (from the slots), Q, accelerations and multipliers of the compiled path against the
    numpy model at ``(t, q, v)`` (call after body_states and, with mass groups, mass_update)."""
    assert D.constraints(cm.data, ws, t, q, v, P.WANT_ALL) == P.OK
    _close(ws.phi[: model.n_c], model.Phi(t, q), "Φ")
    _close(ws.gam[: model.n_c], model.gamma(t, q, v), "γ")
    _close(_jacobian_from_slots(cm, ws, model), model.Phi_q(t, q).toarray(), "Φ_q")
    Q = np.zeros(model.n_v)
    assert D.forces(cm.data, st, ws, t, q, v, Q) == P.OK
    _close(Q, model.Q(t, q, v), "Q", 1e-11)
    acc = np.zeros(model.n_v)
    lam = np.zeros(max(model.n_c, 1))
    assert D.accelerations(cm.data, st, ws, t, q, v, 0.0, 0.0, acc, lam) == P.OK
    a_ref, lam_ref = accelerations_numpy(model, t, q, v)
    _close(acc, a_ref, "accelerations", 1e-9)
    _close(lam[: model.n_c], lam_ref, "multipliers", 1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_modal_force_jacobian_kernel_is_exact(dim):
    """The kind's Jacobian kernel equals forward differences of its force kernel (to 1e-6)."""
    from core.flexible.compiled import modal_forces, modal_forces_jacobian

    model = _model(dim)
    cm = compile_model(model)
    rec = cm.force_kinds[-1]
    assert rec.what.startswith("modal stiffness")
    ws = make_workspace(cm)
    q, v = model.q0.copy(), np.random.default_rng(2).standard_normal(model.n_v)
    D.body_states(cm.fields["lay"], q, v, ws)
    args = (0.0, q, v, ws.r, ws.A, ws.rd, ws.w, cm.fields["lay"], rec.fd, rec.ix)
    K = np.zeros((model.n_v, model.n_v))
    Dm = np.zeros((model.n_v, model.n_v))
    err = np.zeros(2, np.int64)
    st = np.zeros((0, 0))
    modal_forces_jacobian(*args, st, K, Dm, err)
    Q0 = np.zeros(model.n_v)
    modal_forces(*args, st, Q0, err)
    f = model.flexible[0]
    vi = f.vi[model.space.n_v:]
    qi = f.qi[model.space.n_q:]
    for j, (iq, iv) in enumerate(zip(qi, vi)):
        for which, M_ in (("q", K), ("v", Dm)):
            q2, v2 = q.copy(), v.copy()
            h = 1e-6
            if which == "q":
                q2[iq] += h
            else:
                v2[iv] += h
            Q1 = np.zeros(model.n_v)
            modal_forces(0.0, q2, v2, ws.r, ws.A, ws.rd, ws.w, cm.fields["lay"], rec.fd, rec.ix, st, Q1, err)
            _close(M_[:, iv], (Q1 - Q0) / h, f"∂Q/∂{which} column {j}", 1e-6)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("pair,T,rtol", [(("dop853", "jit-dop853"), 0.3, 1e-9),
                                         (("radau-projection", "jit-radau"), 0.03, 1e-7)])
def test_compiled_run_equals_numpy_run(dim, pair, T, rtol):
    """The same model on both paths: the end states agree to the integration tolerance (the node
    motion against its travel; the two Radau codes differ in their index reduction, so their
    agreement is that of two methods at rtol, not of one method on two paths)."""
    _paths_agree(_model(dim), pair, T, rtol)


def _paths_agree(model, pair, T, rtol):
    """The two methods of ``pair`` end within 1e3 rtol of the node travel of each other."""
    ends = []
    for method in pair:
        res = simulate(model, (0.0, T), method, rtol=rtol, atol=rtol * 1e-2, n_output=4)
        assert res.success, res.message
        ends.append(res.q[-1])
    travel = np.max(np.abs(ends[0] - model.q0))
    assert np.max(np.abs(ends[0] - ends[1])) < 1e3 * rtol * travel, np.max(np.abs(ends[0] - ends[1])) / travel


@pytest.mark.parametrize("inertia", ["undeformed", "full"])
def test_compiled_run_conserves_energy_without_damping(inertia):
    """No modal or element damping, no stiffening: kinetic (½vᵀM(q)v; T₀ for the undeformed inertia)
    plus gravity, strain and spring energy is conserved by the compiled run to the integration
    tolerance — with the full inertia, the mass group's quadratic-velocity vector is consistent with
    its mass matrix."""
    model = _model(3, inertia=inertia, damping=0.0, dissipation=False)
    res = simulate(model, (0.0, 0.3), "jit-dop853", rtol=1e-10, atol=1e-12, n_output=31)
    assert res.success, res.message
    E = np.array([model.energy(t, q, v) for t, q, v in zip(res.t, res.q, res.v)])
    T = np.array([0.5 * v @ (model.M(0.0, q) @ v) for q, v in zip(res.q, res.v)])
    assert np.max(np.abs(E - E[0])) < 1e-7 * np.max(T), np.max(np.abs(E - E[0])) / np.max(T)


def test_undeformed_against_full_inertia_on_a_slowly_rotating_body():
    """The dropped inertia terms are of order ω²/ω_k² and q_f/L: on this slowly turning body the two
    inertias give node motions within 1e-4 of the largest displacement (both on the compiled path,
    which equals the numpy one: the tests above)."""
    ends = []
    for inertia in ("full", "undeformed"):
        model = _model(3, inertia=inertia)
        res = simulate(model, (0.0, 0.3), "jit-dop853", rtol=1e-9, atol=1e-11, n_output=4)
        assert res.success
        ends.append(res.q[-1])
    q0 = _model(3).q0
    travel = np.max(np.abs(ends[1] - q0))
    assert np.max(np.abs(ends[0] - ends[1])) < 1e-4 * travel


# --------------------------------------------------------------------------------------------
# mass groups: the inertia of the deformed body on the compiled path
# --------------------------------------------------------------------------------------------

GROUP_CASES = [(2, "full", False), (3, "full", False), (2, "full", True), (3, "full", True),
               (3, "undeformed", False)]  # the last: undeformed inertia, origin off the centre of mass


def _group_model(dim, inertia, stiffening):
    return _model(dim, inertia=inertia, centred=inertia == "full", stiffening=stiffening)


@pytest.mark.parametrize("dim,inertia,stiffening", GROUP_CASES)
def test_mass_group_kernels_match_the_numpy_model(dim, inertia, stiffening):
    """The mass kernel gives the numpy M(q) block, the force kernel Q, and the saddle-point solve with
    the group's inverse the accelerations and multipliers, at an arbitrary (inconsistent) state."""
    model = _group_model(dim, inertia, stiffening)
    cm = compile_model(model)
    assert cm.n_grp == 1 and cm.mass_record.names == ["L"]
    ws = make_workspace(cm)
    st = cm.initial_states()
    rng = np.random.default_rng(7)
    q = model.retract(model.q0, 0.3 * rng.standard_normal(model.n_v))
    f = model.flexible[0]
    q[f.qi[model.space.n_q:]] = 0.05 * rng.standard_normal(len(f.qi) - model.space.n_q)  # visible deformation
    v = rng.standard_normal(model.n_v)
    t = 0.2
    D.body_states(cm.fields["lay"], q, v, ws)
    assert D.mass_update(cm.data, ws, t, q, v) == P.OK
    n = len(f.vi)
    M_ref = model.M(t, q).toarray()[np.ix_(f.vi, f.vi)]
    _close(ws.Mg[0, :n, :n], M_ref, "M(q) of the group", 1e-12)
    _close(ws.Mgi[0, :n, :n] @ M_ref, np.eye(n), "inverse of M(q)", 1e-9)
    _equations_match_the_numpy_model(model, cm, ws, st, t, q, v)  # Φ_q with the group's added slots


@pytest.mark.parametrize("dim", [2, 3])
def test_inertia_force_jacobian_kernel_equals_the_numpy_differences(dim):
    """The group's Jacobian kernel and the numpy path difference the same forces with the same steps
    (h = 1e-7): their ∂Q/∂q and ∂Q/∂v agree to the differences' error, truncation (1e-6 of the
    largest entry) plus round-off (10 ε max|Q| / h, the two paths round Q differently)."""
    model = _model(3 if dim == 3 else 2, inertia="full", stiffening=True)
    cm = compile_model(model)
    ws = make_workspace(cm)
    rng = np.random.default_rng(3)
    q = model.retract(model.q0, 0.2 * rng.standard_normal(model.n_v))
    v = rng.standard_normal(model.n_v)
    nv = model.n_v
    K, Dm = np.zeros((nv, nv)), np.zeros((nv, nv))
    work = (np.zeros(model.n_q), np.zeros(nv), np.zeros(nv), np.zeros(nv))
    rec = [r for r in cm.force_kinds if r.what.startswith("inertia")][0]
    D.body_states(cm.fields["lay"], q, v, ws)
    err = np.zeros(2, np.int64)
    rec.jacobian(0.0, q, v, ws.r, ws.A, ws.rd, ws.w, cm.fields["lay"], rec.fd, rec.ix, np.zeros((0, 0)), K, Dm, err)
    Kn, Dn = np.zeros((nv, nv)), np.zeros((nv, nv))
    for r_, c_, jq, jv in model._flexible_jacobian_entries(q, v):
        np.add.at(Kn, (r_, c_), jq)
        np.add.at(Dn, (r_, c_), jv)
    roundoff = 10 * np.finfo(float).eps * np.max(np.abs(model.Q(0.0, q, v))) / 1e-7
    assert np.max(np.abs(K - Kn)) <= 1e-6 * np.max(np.abs(Kn)) + roundoff
    assert np.max(np.abs(Dm - Dn)) <= 1e-6 * np.max(np.abs(Dn)) + roundoff


@pytest.mark.parametrize("dim,pair", [(2, ("dop853", "jit-dop853")), (3, ("dop853", "jit-dop853")),
                                      (2, ("radau-projection", "jit-radau-projection"))])
def test_full_inertia_compiled_run_equals_numpy_run(dim, pair):
    """The inertia of the deformed body on both paths (rtol 1e-8 for DOP853, 1e-7 for the two Radau
    codes, which differ in their index reduction): end states within 1e3 rtol of the travel."""
    rtol, T = (1e-8, 0.05) if "dop853" in pair else (1e-7, 0.01)
    _paths_agree(_model(dim, inertia="full", stiffening=True), pair, T, rtol)


def test_spin_up_beam_turns_past_the_angles_of_dependent_rows():
    """The hub pin's rows and the tip node frame's rows, restricted to the body, are dependent at
    0 and π/2: node-frame rows are solved with the border (layout), so a compiled run that turns the
    beam by several radians keeps its accuracy.  Radau on the compiled path against the numpy path,
    spin-up beam with 2 modes over 8 s (θ from 0 to 6.5 rad): tip deflection within 1e-6 of its peak."""
    from core.flexible.models import hub_frame_deflection, spin_up_angle

    model = spin_up_beam(n_elements=6, n_modes=2)
    cm = compile_model(model)
    nodes = [r for r in cm.constraint_kinds if r.what.startswith("node frame")][0]
    assert set(range(nodes._row0, nodes._row0 + nodes.rows)) <= set(cm.fields["ext"].tolist())
    t_eval = np.linspace(0.0, 8.0, 41)
    theta = np.array([spin_up_angle()(t)[0] for t in t_eval])
    v = {}
    for method in ("radau-projection", "jit-radau-projection"):
        res = simulate(model, (0.0, 8.0), method, rtol=1e-8, atol=1e-10, t_eval=t_eval)
        assert res.success, res.message
        tip = np.array([model.point_position(q, "beam.tip", np.zeros(2)) for q in res.q])
        v[method] = hub_frame_deflection(tip, theta, 10.0)[0]
    peak = np.max(np.abs(v["radau-projection"]))
    assert np.max(np.abs(v["radau-projection"] - v["jit-radau-projection"])) < 1e-6 * peak


def test_refusals_name_the_body_and_the_reason():
    with pytest.raises(NotCompilable, match=f"at most {MAX_COMPILED_MODES}"):
        compile_model(_model(3, n_modes=MAX_COMPILED_MODES + 1))
    with pytest.raises(NotCompilable, match=f"at most {MAX_COMPILED_MODES}"):
        compile_model(_model(3, inertia="full", n_modes=MAX_COMPILED_MODES + 1))
    # a joint between the frames of two flexible bodies with the deformed inertia touches both
    # bodies' frames and modes: 2 + 4 + 4 blocks, more than MAX_SLOTS
    fe = _l_shaped_centred(2)
    modes = free_interface(fe.M, fe.K, fe.nodes, fe.dofs_per_node, 4).orthonormalized(drop_rigid=True)
    b = ModelBuilder(2, "two flexible bodies")
    b.add_flexible_body("A", fe, modes)
    b.add_flexible_body("B", fe, modes, position=(1.0, 0.0))
    b.add_revolute("link", "A", "B", at=(0.5, 0.0))
    with pytest.raises(NotCompilable, match=r"'link/point' touches flexible body '[AB]'.*more than 8 blocks"):
        compile_model(b.build())
    fe = _l_shaped_centred(3)
    modes = free_interface(fe.M, fe.K, fe.nodes, fe.dofs_per_node, 2).orthonormalized(drop_rigid=True)
    with pytest.raises(ModelError, match="inertia='undeformd'.*did you mean 'undeformed'"):
        ModelBuilder(3).add_flexible_body("L", fe, modes, inertia="undeformd")
    with pytest.raises(ModelError, match="cannot be combined with inertia='undeformed'"):
        ModelBuilder(3).add_flexible_body("L", fe, modes, inertia="undeformed", geometric_stiffening=True)
