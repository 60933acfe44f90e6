"""Flexible bodies on the compiled path (core.flexible.compiled, issue 23).

Tier 1: with ``inertia="undeformed"`` the numpy body is a rigid body plus modal oscillators (its
mass block is the rigid body's and the modal masses, its forces the Euler equations and the modal
stiffness and damping); the compiled kernels give the numpy model's Φ, Φ_q, γ, Q, accelerations and
multipliers to round-off, planar and spatial.  Tier 2: a run of the compiled integrators equals the
numpy one to the integration tolerance; energy is conserved.  Tier 3: the undeformed inertia against
the exact one on a slowly rotating body (difference of the order of the dropped terms).  Refusals
name the body and the reason.
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


def _model(dim, inertia="undeformed", n_modes=3, gravity=True, damping=0.02, seed=0, centred=True, dissipation=True):
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
                        modal_velocities=0.01 * rng.standard_normal(m), damping_ratio=damping, inertia=inertia, **pose)
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
    model = _model(dim)
    ends = []
    for method in pair:
        res = simulate(model, (0.0, T), method, rtol=rtol, atol=rtol * 1e-2, n_output=4)
        assert res.success, res.message
        ends.append(res.q[-1])
    travel = np.max(np.abs(ends[0] - model.q0))
    assert np.max(np.abs(ends[0] - ends[1])) < 1e3 * rtol * travel, np.max(np.abs(ends[0] - ends[1])) / travel


def test_compiled_run_conserves_energy_without_damping():
    """Undeformed inertia, no modal or element damping: T₀ + gravity + strain + spring energy is
    conserved by the compiled run to the integration tolerance."""
    model = _model(3, damping=0.0, dissipation=False)
    res = simulate(model, (0.0, 0.3), "jit-dop853", rtol=1e-10, atol=1e-12, n_output=31)
    assert res.success, res.message
    E = np.array([model.energy(t, q, v) for t, q, v in zip(res.t, res.q, res.v)])
    T = np.array([0.5 * v @ (model.M(0.0, q) @ v) for q, v in zip(res.q, res.v)])
    assert np.max(np.abs(E - E[0])) < 1e-7 * np.max(T), np.max(np.abs(E - E[0])) / np.max(T)


def test_undeformed_against_full_inertia_on_a_slowly_rotating_body():
    """The dropped inertia terms are of order ω²/ω_k² and q_f/L: on this slowly turning body the two
    inertias give node motions within 1e-4 of the largest displacement."""
    ends = []
    for inertia in ("full", "undeformed"):
        model = _model(3, inertia=inertia)
        res = simulate(model, (0.0, 0.3), "dop853", rtol=1e-9, atol=1e-11, n_output=4)
        assert res.success
        ends.append(res.q[-1])
    q0 = _model(3).q0
    travel = np.max(np.abs(ends[1] - q0))
    assert np.max(np.abs(ends[0] - ends[1])) < 1e-4 * travel


def test_refusals_name_the_body_and_the_reason():
    with pytest.raises(NotCompilable, match="'L' has the inertia of the deformed body.*inertia='undeformed'"):
        compile_model(_model(3, inertia="full"))
    with pytest.raises(NotCompilable, match="'L': its undeformed mass matrix couples"):
        compile_model(_model(3, centred=False))
    with pytest.raises(NotCompilable, match=f"at most {MAX_COMPILED_MODES}"):
        compile_model(_model(3, n_modes=MAX_COMPILED_MODES + 1))
    with pytest.raises(NotCompilable, match="'beam' has the inertia of the deformed body"):
        compile_model(spin_up_beam(n_elements=4, n_modes=1))
    fe = _l_shaped_centred(3)
    modes = free_interface(fe.M, fe.K, fe.nodes, fe.dofs_per_node, 2).orthonormalized(drop_rigid=True)
    with pytest.raises(ModelError, match="inertia='undeformd'.*did you mean 'undeformed'"):
        ModelBuilder(3).add_flexible_body("L", fe, modes, inertia="undeformd")
    with pytest.raises(ModelError, match="cannot be combined with inertia='undeformed'"):
        ModelBuilder(3).add_flexible_body("L", fe, modes, inertia="undeformed", geometric_stiffening=True)
