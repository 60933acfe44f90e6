"""Flexible bodies in a floating frame of reference (core.flexible.body, issue 23).

Tier 1/2: the mass matrix against the rigid body and against the kinetic energy summed node by node
over the FE model; the node-frame constraint's Jacobian and γ against finite differences; energy
and momentum of a free tumbling body; the eigenfrequencies of a free body against the
Euler–Bernoulli closed form.  Tier 4: the spin-up beam of Kane, Ryan & Banerjee (1987) against an
independent geometrically exact rigid-link model, and its divergence without geometric stiffening.
"""

from __future__ import annotations

import numpy as np
import pytest

from core import frames
from core.analysis import eigen
from core.errors import ModelError
from core.flexible import BeamMesh, BeamSection, FEModel, free_interface, straight_beam
from core.flexible.models import hub_frame_deflection, spin_up_angle, spin_up_beam, spin_up_chain
from core.flexible.reduction import normal_mode_component
from core.model import ModelBuilder
from core.simulation import simulate

SECTION = BeamSection(E=7e10, rho=3000.0, A=4e-4, Iz=2e-7, Iy=3e-7, J=4e-7, Ip=5e-7)


def _l_shaped(dim):
    """Two perpendicular beams (an L), so that every inertia coupling is non-zero."""
    if dim == 2:
        nodes = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [1.0, 0.4], [1.0, 0.8]])
    else:
        nodes = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.4, 0.1], [1.0, 0.8, 0.2]])
    mesh = BeamMesh(nodes, np.array([[0, 1], [1, 2], [2, 3], [3, 4]]), orientation=(0.3, 0.2, 1.0))
    return FEModel.from_beam(mesh, SECTION)


def _free_body_model(dim, seed=0, gravity=None, nodes=(), n_modes=4):
    fe = _l_shaped(dim)
    modes = free_interface(fe.M, fe.K, fe.nodes, fe.dofs_per_node, n_modes).orthonormalized(drop_rigid=True)
    rng = np.random.default_rng(seed)
    b = ModelBuilder(dim, "free flexible body", gravity=np.zeros(dim) if gravity is None else gravity)
    if dim == 2:
        pose = dict(position=(0.3, -0.2), orientation=0.4, velocity=(0.5, -0.3), angular_velocity=2.0)
    else:
        pose = dict(position=(0.3, -0.2, 0.1), orientation=frames.axis_angle_to_euler(np.array([1.0, 2.0, 0.5]) / 2.29, 0.7),
                    velocity=(0.5, -0.3, 0.2), angular_velocity=(1.0, -2.0, 1.5))
    m = modes.T.shape[1]
    b.add_flexible_body("body", fe, modes, modal_coordinates=1e-3 * rng.standard_normal(m),
                        modal_velocities=0.05 * rng.standard_normal(m), **pose)
    for k in nodes:
        b.add_node_frame("body", k)
    return b.build(), fe, modes


def _block(model, q):
    f = model.flexible[0]
    return model.M(0.0, q).toarray()[np.ix_(f.vi, f.vi)], f


# --------------------------------------------------------------------------------------------
# mass matrix
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dim", [2, 3])
def test_frozen_modes_give_the_rigid_body(dim):
    """At q_f = 0 the reference block is the rigid body's: mass ρAL, first moment and inertia about
    the frame origin of the two beams (Euler–Bernoulli elements carry no rotary inertia in bending,
    the torsion bar carries ρI_p)."""
    model, fe, modes = _free_body_model(dim)
    q = model.q0.copy()
    f = model.flexible[0]
    q[f.qi[model.space.n_q:]] = 0.0
    M, _ = _block(model, q)
    nodes = fe.nodes
    segs = [(nodes[i], nodes[i + 1]) for i in range(4)]
    rhoA = SECTION.rho * SECTION.A
    mass = sum(rhoA * np.linalg.norm(b - a) for a, b in segs)
    first = sum(rhoA * np.linalg.norm(b - a) * (a + b) / 2 for a, b in segs)
    A = model.body_frame(q, "body")
    d = dim
    tol = 1e-13 * np.max(np.abs(M))  # round-off of the Gram products
    np.testing.assert_allclose(M[:d, :d], mass * np.eye(d), atol=tol)
    if dim == 2:
        J = sum(rhoA * np.linalg.norm(b - a) * (a @ a + a @ b + b @ b) / 3 for a, b in segs)
        np.testing.assert_allclose(M[:2, 2], A @ (frames.ROT90 @ first), atol=tol)
        np.testing.assert_allclose(M[2, 2], J, atol=tol)
    else:
        # ∫ρA (|x|² I − x xᵀ) ds along each segment (exact for linear x(s)), plus ρ I_p about its axis
        J = np.zeros((3, 3))
        for a, b in segs:
            L = np.linalg.norm(b - a)
            xx = (np.outer(a, a) + np.outer(b, b)) / 3 + (np.outer(a, b) + np.outer(b, a)) / 6
            J += rhoA * L * (np.trace(xx) * np.eye(3) - xx)
            e = (b - a) / L
            J += SECTION.rho * SECTION.Ip * L * np.outer(e, e)
        np.testing.assert_allclose(M[:3, 3:6], -A @ frames.skew(first), atol=tol)
        np.testing.assert_allclose(M[3:6, 3:6], J, atol=tol)
    np.testing.assert_allclose(M[d + f.data.n_rot:, d + f.data.n_rot:], modes.M, atol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_kinetic_energy_equals_the_fe_models_summed_node_by_node(dim):
    """½ vᵀ M(q) v of the body equals ½ wᵀ M_FE w with the nodal velocities written out node by node
    in the frame: V̄ + ω̄ × (x̄ + u) + u̇ for translations, ω̄ + ψ̇ + ω̄ × ψ for rotations."""
    model, fe, modes = _free_body_model(dim, seed=3)
    rng = np.random.default_rng(7)
    q = model.retract(model.q0, 0.3 * rng.standard_normal(model.n_v))
    v = rng.standard_normal(model.n_v)
    M, f = _block(model, q)
    vb, qb = v[f.vi], q[f.qi]
    nq, nv = model.space.n_q, model.space.n_v
    A = model.body_frame(q, "body")
    qf, qfd = qb[nq:], vb[nv:]
    V, w = A.T @ vb[:dim], vb[dim:nv]
    u, ud = modes.T @ qf, modes.T @ qfd
    p = fe.dofs_per_node
    wn = np.zeros(fe.n_dofs)
    for i, x in enumerate(fe.nodes):
        t, r = slice(i * p, i * p + dim), slice(i * p + dim, (i + 1) * p)
        if dim == 2:
            s = x + u[t]
            wn[t] = V + w[0] * np.array([-s[1], s[0]]) + ud[t]
            wn[r] = w[0] + ud[r]
        else:
            wn[t] = V + np.cross(w, x + u[t]) + ud[t]
            wn[r] = w + ud[r] + np.cross(w, u[r])
    T_fe = 0.5 * wn @ (fe.M @ wn)
    np.testing.assert_allclose(0.5 * vb @ M @ vb, T_fe, rtol=1e-12)


# --------------------------------------------------------------------------------------------
# node frames
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dim", [2, 3])
def test_node_frame_constraint_derivatives(dim):
    model, _, _ = _free_body_model(dim, seed=1, nodes=(0, 2, 4))
    assert model.constraint_names[0].startswith("body.nodes")
    rng = np.random.default_rng(11)
    t, eps = 0.3, 1e-6
    q = model.retract(model.q0, 0.05 * rng.standard_normal(model.n_v))
    v, a = rng.standard_normal(model.n_v), rng.standard_normal(model.n_v)
    J = model.Phi_q(t, q).toarray()
    fd = np.array([(model.Phi(t, model.retract(q, eps * e)) - model.Phi(t, model.retract(q, -eps * e))) / (2 * eps)
                   for e in np.eye(model.n_v)]).T
    np.testing.assert_allclose(J, fd, atol=1e-8)

    def phidot(s):
        qq = model.retract(q, s * v + 0.5 * s * s * a)
        return model.Phi_q(t, qq).toarray() @ (v + s * a)

    h = 1e-5
    np.testing.assert_allclose(model.gamma(t, q, v), J @ a - (phidot(h) - phidot(-h)) / (2 * h), atol=2e-6)


@pytest.mark.parametrize("dim", [2, 3])
def test_node_frame_starts_on_the_deformed_node(dim):
    """Built with initial modal coordinates, the node frames satisfy their constraint (build checks
    it) and sit at r + A(x̄ + Φ q_f)."""
    model, fe, modes = _free_body_model(dim, seed=2, nodes=(4,))
    f = model.flexible[0]
    qf = model.q0[f.qi[model.space.n_q:]]
    A = model.body_frame(model.q0, "body")
    r = model.q0[model.q_slice("body")][:dim]
    expected = r + A @ (fe.nodes[4] + (modes.T @ qf)[4 * fe.dofs_per_node:4 * fe.dofs_per_node + dim])
    np.testing.assert_allclose(model.point_position(model.q0, "body.node4", np.zeros(dim)), expected, atol=1e-14)
    assert np.max(np.abs(model.Phi(0.0, model.q0))) < 1e-12
    assert np.max(np.abs(model.velocity_violation(0.0, model.q0, model.v0))) < 1e-12


# --------------------------------------------------------------------------------------------
# dynamics
# --------------------------------------------------------------------------------------------


def _momenta(model, q, v):
    f = model.flexible[0]
    M, _ = _block(model, q)
    pb = M @ v[f.vi]
    d = model.space.dim
    A = model.body_frame(q, "body")
    r = q[model.q_slice("body")][:d]
    L = pb[:d]
    if d == 2:
        H = r[0] * L[1] - r[1] * L[0] + pb[2]
        return L, np.atleast_1d(H)
    return L, np.cross(r, L) + A @ pb[3:6]


@pytest.mark.parametrize("dim", [2, 3])
def test_free_tumbling_body_conserves_energy_and_momentum(dim):
    """No external force: energy (kinetic + strain), linear and angular momentum stay constant to
    the integration tolerance (rtol 1e-10 of DOP853) over 0.5 s (many periods of the lowest mode)."""
    model, _, _ = _free_body_model(dim, seed=4)
    assert model.is_conservative
    res = simulate(model, (0.0, 0.05), "dop853", rtol=1e-10, atol=1e-12, n_output=11)
    assert res.status == "finished", res.message
    E0 = model.energy(0.0, res.q[0], res.v[0])
    L0, H0 = _momenta(model, res.q[0], res.v[0])
    for q, v in zip(res.q, res.v):
        assert abs(model.energy(0.0, q, v) - E0) <= 1e-8 * abs(E0)
        L, H = _momenta(model, q, v)
        np.testing.assert_allclose(L, L0, atol=1e-8 * np.linalg.norm(L0))
        np.testing.assert_allclose(H, H0, atol=1e-8 * np.linalg.norm(H0))


def test_gravity_and_strain_energy_balance_with_node_frames():
    """A cantilever hanging in gravity from a revolute at its root node frame swings; total energy
    (kinetic, gravity, strain) is conserved by the constrained motion (index-2 GGL Radau)."""
    fe = FEModel.from_beam(straight_beam(1.0, 8, dim=2), SECTION)
    modes = normal_mode_component(fe.M, fe.K, 2, fixed_dofs=fe.dofs(0))
    b = ModelBuilder(2, "flexible pendulum")
    b.add_flexible_body("rod", fe, modes, orientation=-0.3)
    b.add_node_frame("rod", 0)
    b.add_revolute("pivot", "ground", "rod.node0", at=(0.0, 0.0))
    model = b.build()
    res = simulate(model, (0.0, 0.1), "radau-ggl", rtol=1e-6, atol=1e-6, n_output=5)
    assert res.status == "finished", res.message
    E = np.array([model.energy(0.0, q, v) for q, v in zip(res.q, res.v)])
    assert np.max(np.abs(E - E[0])) < 1e-8 * np.max(np.abs(E))
    f = model.flexible[0]
    assert np.max(np.abs(res.q[-1][f.qi[3:]])) > 0  # it deflects


def test_force_jacobians_include_the_flexible_body():
    model, _, _ = _free_body_model(3, seed=5, gravity=(0.0, 0.0, -9.81))
    rng = np.random.default_rng(2)
    q = model.retract(model.q0, 0.1 * rng.standard_normal(model.n_v))
    v = rng.standard_normal(model.n_v)
    Qq, Qv = model.Q_jacobians(0.0, q, v)
    eps = 1e-6
    fq = np.array([(model.Q(0, model.retract(q, eps * e), v) - model.Q(0, model.retract(q, -eps * e), v)) / (2 * eps)
                   for e in np.eye(model.n_v)]).T
    fv = np.array([(model.Q(0, q, v + eps * e) - model.Q(0, q, v - eps * e)) / (2 * eps) for e in np.eye(model.n_v)]).T
    scale = np.max(np.abs(fq)) + np.max(np.abs(fv))
    np.testing.assert_allclose(Qq.toarray(), fq, atol=1e-5 * scale)
    np.testing.assert_allclose(Qv.toarray(), fv, atol=1e-5 * scale)


def test_eigen_of_a_free_flexible_body_returns_its_modal_frequencies():
    """A free straight beam with free–free modes: the constrained eigen analysis gives the rigid-body
    zeros and the Euler–Bernoulli free–free frequencies (βL = 4.73004, 7.85320; Blevins 1979)
    within the FE discretisation error (40 elements: below 1e-5)."""
    L = 2.0
    fe = FEModel.from_beam(straight_beam(L, 40, dim=2), SECTION)
    modes = free_interface(fe.M, fe.K, fe.nodes, 3, 2).orthonormalized(drop_rigid=True)
    b = ModelBuilder(2, "free beam", gravity=(0.0, 0.0))
    b.add_flexible_body("beam", fe, modes)
    table, _ = eigen(b.build())
    f = table["natural frequency [Hz]"].to_numpy()
    assert np.sum(f < 1e-6) == 6  # three rigid-body motions, a double root s = 0 each
    c = np.sqrt(SECTION.E * SECTION.Iz / (SECTION.rho * SECTION.A * L**4)) / (2 * np.pi)
    np.testing.assert_allclose(f[f >= 1e-6], np.array([4.73004074486, 7.85320462410]) ** 2 * c, rtol=1e-5)


@pytest.mark.parametrize("dim", [2, 3])
def test_section_forces_of_a_cantilever_under_a_tip_load(dim):
    """A skew cantilever with a tip load: the section forces are the statics of the beam exactly
    (N, V constant, M = P (L − x)), from the static FE solution and from a flexible body's modal
    coordinates alike (all modes kept: the same displacement)."""
    from core.flexible.beam import section_forces

    L = 2.0
    d = np.array([1.0, 1.0]) if dim == 2 else np.array([1.0, 1.0, 0.5])
    d /= np.linalg.norm(d)
    mesh = straight_beam(L, 8, dim=dim, direction=d)
    fe = FEModel.from_beam(mesh, SECTION)
    free = np.setdiff1d(np.arange(fe.n_dofs), fe.dofs(0))
    perp = np.array([-d[1], d[0]]) if dim == 2 else np.cross(d, [0.0, 0.0, 1.0]) / np.linalg.norm(np.cross(d, [0.0, 0.0, 1.0]))
    f = np.zeros(fe.n_dofs)
    f[fe.dofs(8)[:dim]] = 10.0 * perp + 3.0 * d
    u = np.zeros(fe.n_dofs)
    import scipy.sparse.linalg as spla

    u[free] = spla.spsolve(fe.K[free][:, free].tocsc(), f[free])
    sf = section_forces(mesh, SECTION, u)
    x = np.linspace(0.0, L, 9)
    M = np.abs(sf[:, :, -1] if dim == 2 else np.hypot(sf[:, :, 4], sf[:, :, 5]))
    np.testing.assert_allclose(M[:, 0], 10.0 * (L - x[:-1]), atol=1e-9)
    np.testing.assert_allclose(M[:, 1], 10.0 * (L - x[1:]), atol=1e-9)
    np.testing.assert_allclose(sf[:, :, 0], 3.0, atol=1e-9)  # tension
    modes = normal_mode_component(fe.M, fe.K, fe.n_dofs - len(fe.dofs(0)), fixed_dofs=fe.dofs(0))
    b = ModelBuilder(dim, "cantilever")
    b.add_flexible_body("beam", fe, modes, modal_coordinates=modes.T.T @ (fe.M @ u))
    data = b.build().flexible[0].data
    np.testing.assert_allclose(data.section_forces(modes.T.T @ (fe.M @ u)), sf, atol=1e-6)


@pytest.mark.parametrize("dim,shape", [(2, "rectangle"), (3, "rectangle"), (3, "circle")])
def test_fibre_stresses_of_a_cantilever_under_a_tip_load(dim, shape):
    """Navier at the extreme fibres: a cantilever of length L with a tip load P across it and an
    axial pull F has σ = F/A ± P (L − x) c / I (c the extreme fibre distance in the bending plane);
    for the rectangle in space a load with components along both section axes puts the extreme at
    a corner, F/A ± (P_y (L − x) b/(2 I_z) + P_z (L − x) h/(2 I_y)).  Statics: exact (1e-6 relative)."""
    import scipy.sparse.linalg as spla

    from core.flexible.beam import fibre_stresses

    L, n = 2.0, 8
    sec = (BeamSection.rectangle(E=7e10, rho=2700.0, width=0.04, height=0.02) if shape == "rectangle"
           else BeamSection.circle(E=7e10, rho=2700.0, diameter=0.03))
    mesh = straight_beam(L, n, dim=dim, orientation=(0.0, 1.0, 0.0))  # local y = global y, local z = global z
    fe = FEModel.from_beam(mesh, sec)
    free = np.setdiff1d(np.arange(fe.n_dofs), fe.dofs(0))
    F, Py, Pz = 300.0, 40.0, (25.0 if dim == 3 else 0.0)
    f = np.zeros(fe.n_dofs)
    f[fe.dofs(n)[:dim]] = [F, Py] + ([Pz] if dim == 3 else [])
    u = np.zeros(fe.n_dofs)
    u[free] = spla.spsolve(fe.K[free][:, free].tocsc(), f[free])
    sig = fibre_stresses(mesh, sec, u)
    x = np.linspace(0.0, L, n + 1)[:-1]  # end i of every element
    if shape == "circle":
        bend = np.hypot(Py, Pz) * (L - x) * sec.outline[1] / (2 * sec.Iz)
    else:
        b, h = sec.outline[1], sec.outline[2]
        bend = Py * (L - x) * b / (2 * sec.Iz) + Pz * (L - x) * h / (2 * sec.Iy)
    np.testing.assert_allclose(sig[:, 0, 0], F / sec.A + bend, rtol=1e-6)
    np.testing.assert_allclose(sig[:, 0, 1], F / sec.A - bend, rtol=1e-6)
    modes = normal_mode_component(fe.M, fe.K, fe.n_dofs - len(fe.dofs(0)), fixed_dofs=fe.dofs(0))
    b_ = ModelBuilder(dim, "cantilever")
    b_.add_flexible_body("beam", fe, modes)
    data = b_.build().flexible[0].data
    np.testing.assert_allclose(data.fibre_stresses(modes.T.T @ (fe.M @ u)), sig, rtol=1e-6, atol=1e-3)


def test_fibre_stresses_need_an_outline():
    from core.errors import InputError
    from core.flexible.beam import fibre_stresses

    mesh = straight_beam(1.0, 2)
    fe = FEModel.from_beam(mesh, SECTION)
    with pytest.raises(InputError, match="fibre stresses need the section's outline"):
        fibre_stresses(mesh, SECTION, np.zeros(fe.n_dofs))
    with pytest.raises(InputError, match="outline = \\('square', 0.1\\)"):
        BeamSection(E=7e10, rho=2700.0, A=1e-4, Iz=1e-8, outline=("square", 0.1))


# --------------------------------------------------------------------------------------------
# spin-up beam (Kane, Ryan & Banerjee 1987)
# --------------------------------------------------------------------------------------------


def _spin_up_deflection(model, res, tip_body, tip_point):
    tip = np.array([model.point_position(q, tip_body, tip_point) for q in res.q])
    theta = np.array([spin_up_angle()(t)[0] for t in res.t])
    return hub_frame_deflection(tip, theta, 10.0)


def test_spin_up_beam_against_a_geometrically_exact_rigid_link_model():
    """Kane, Ryan & Banerjee (1987), ω_s = 6 rad/s, T_s = 15 s, the lag phase 0–10 s. The floating
    frame with cantilever modes and centrifugal geometric stiffening against the Hencky chain of
    10 and 20 rigid links, Richardson-extrapolated (its error is O(N⁻²)).

    * tip deflection, 3 modes: within 0.25 % of the peak (measured 0.11 %; the chain's 20-link error
      is 0.3 %);
    * root bending moment (the section force at the clamp against the chain's root spring torque,
      which carries the whole moment at x = 0): it converges more slowly with the modes than the
      deflection, 4.3 % of the peak with 3 modes and 1.3 % with 6; asserted: below 2 % with 6 and
      smaller than with 3.
    """
    from core.flexible.models import KANE_SPIN_UP

    t_eval = np.linspace(0.0, 10.0, 11)
    moments = {}
    for n_modes in (3, 6):
        ffr = spin_up_beam(n_elements=20, n_modes=n_modes)
        res = simulate(ffr, (0.0, 10.0), "radau-projection", rtol=1e-7, atol=1e-9, t_eval=t_eval)
        assert res.status == "finished", res.message
        f = ffr.flexible[0]
        moments[n_modes] = np.array([f.data.section_forces(q[f.qi[3:]])[0, 0, 2] for q in res.q])
        if n_modes == 3:
            v, u = _spin_up_deflection(ffr, res, "beam.tip", np.zeros(2))
    chains, roots = [], []
    EI = KANE_SPIN_UP["E"] * KANE_SPIN_UP["I"]
    for n in (10, 20):
        m = spin_up_chain(n)
        r = simulate(m, (0.0, 10.0), "radau-projection", rtol=1e-7, atol=1e-9, t_eval=t_eval)
        assert r.status == "finished", r.message
        chains.append(_spin_up_deflection(m, r, f"link{n}", (5.0 / n, 0.0))[0])
        hub, l1 = m.q_slice("hub"), m.q_slice("link1")
        roots.append(np.array([2 * EI / (10.0 / n) * (q[l1][2] - q[hub][2]) for q in r.q]))
    ref = chains[1] + (chains[1] - chains[0]) / 3.0
    peak = np.max(np.abs(ref))
    assert 0.5 < peak < 0.6  # the lag of about half a metre at t ≈ 7 s
    assert np.max(np.abs(v - ref)) < 2.5e-3 * peak
    assert np.max(np.abs(u)) < 1e-5  # linear modes without axial ones: no foreshortening
    root_ref = roots[1] + (roots[1] - roots[0]) / 3.0
    m_peak = np.max(np.abs(root_ref))
    assert 300.0 < m_peak < 340.0  # N m
    err3, err6 = (np.max(np.abs(moments[k] - root_ref)) / m_peak for k in (3, 6))
    assert err6 < 0.02 and err6 < err3


def test_spin_up_beam_diverges_without_geometric_stiffening():
    """Without stiffening the first bending mode (3.80 rad/s) softens by −ω² and goes unstable once
    ω exceeds it (t ≈ 10 s of the spin-up): the deflection grows without bound, while the stiffened
    body stays below 0.6 m."""
    t_eval = np.linspace(0.0, 12.0, 13)
    model = spin_up_beam(n_elements=10, n_modes=2, geometric_stiffening=False)
    res = simulate(model, (0.0, 12.0), "radau-projection", rtol=1e-6, atol=1e-8, t_eval=t_eval)
    v, _ = _spin_up_deflection(model, res, "beam.tip", np.zeros(2))
    assert np.max(np.abs(v)) > 100.0 or res.status == "failed"


def test_spin_up_spatial_body_gives_the_planar_answer():
    """The same beam as a spatial body (in- and out-of-plane modes, Euler parameters) spinning about
    z gives the planar in-plane deflection to the integration tolerance."""
    t_eval = np.linspace(0.0, 6.0, 7)
    planar = spin_up_beam(n_elements=10, n_modes=2)
    spatial = spin_up_beam(n_elements=10, n_modes=4, dimension=3)
    rp = simulate(planar, (0.0, 6.0), "radau-projection", rtol=1e-8, atol=1e-10, t_eval=t_eval)
    rs = simulate(spatial, (0.0, 6.0), "radau-projection", rtol=1e-8, atol=1e-10, t_eval=t_eval)
    vp, _ = _spin_up_deflection(planar, rp, "beam.tip", np.zeros(2))
    tip = np.array([spatial.point_position(q, "beam.tip", np.zeros(3)) for q in rs.q])
    theta = np.array([spin_up_angle()(t)[0] for t in rs.t])
    vs, _ = hub_frame_deflection(tip[:, :2], theta, 10.0)
    np.testing.assert_allclose(vs, vp, atol=1e-6)
    assert np.max(np.abs(tip[:, 2])) < 1e-12


# --------------------------------------------------------------------------------------------
# bad input
# --------------------------------------------------------------------------------------------


def test_bad_flexible_inputs_are_refused_by_name():
    fe = FEModel.from_beam(straight_beam(1.0, 6, dim=2), SECTION)
    free = free_interface(fe.M, fe.K, fe.nodes, 3, 2)
    b = ModelBuilder(2, "bad")
    with pytest.raises(ModelError, match="'arm'.*3 rigid-body mode"):
        b.add_flexible_body("arm", fe, free)
    modes = free.orthonormalized(drop_rigid=True)
    with pytest.raises(ModelError, match=r"'arm'.*damping ratio 2 .*0\.02"):
        b.add_flexible_body("arm", fe, modes, damping_ratio=2)
    b.add_flexible_body("arm", fe, modes, damping_ratio="2 %")
    with pytest.raises(ModelError, match="nodes 0..6"):
        b.add_node_frame("arm", 7)
    b.add_body("block", 1.0, 0.1, (0.0, 0.0))
    with pytest.raises(ModelError, match="'block' is a rigid body"):
        b.add_node_frame("block", 0)
    with pytest.raises(ModelError, match="'arm'.*3 values for 2 modes"):
        ModelBuilder(2).add_flexible_body("arm", fe, modes, damping_ratio=[0.01, 0.02, 0.03])
    with pytest.raises(ModelError, match="3-D"):
        ModelBuilder(3).add_flexible_body("arm", fe, modes)
    imported = FEModel(fe.nodes, 3, fe.M, fe.K, "imported")
    with pytest.raises(ModelError, match="geometric stiffening.*imported"):
        ModelBuilder(2).add_flexible_body("arm", imported, modes, geometric_stiffening=True)
    bi = ModelBuilder(2)
    bi.add_flexible_body("arm", imported, modes)
    with pytest.raises(ModelError, match="'arm': section forces need a beam component; imported"):
        bi.build().flexible[0].data.section_forces(np.zeros(2))
    with pytest.raises(ModelError, match="geometric_stiffening='centrifgual'.*did you mean 'centrifugal'"):
        ModelBuilder(2).add_flexible_body("arm", fe, modes, geometric_stiffening="centrifgual")
    with pytest.raises(ModelError, match="2 finite numbers"):
        ModelBuilder(2).add_flexible_body("arm", fe, modes, modal_coordinates=[0.0])


def test_compiled_integrators_take_the_inertia_of_the_deformed_body_as_a_mass_group():
    """The spin-up beam needs the deformed body's inertia (its centrifugal terms); the compiled path
    takes it as a mass group whose M(q_f) is rebuilt at every evaluation (the kernels' agreement
    with the numpy model: tests/core/test_flexible_compiled.py)."""
    from core.compiled.layout import compile_model

    model = spin_up_beam(n_elements=4, n_modes=1)
    cm = compile_model(model)
    assert cm.n_grp == 1 and cm.mass_record.names == ["beam"]
    vi = model.flexible[0].vi
    assert cm.fields["grp_v"][0, :cm.fields["grp_w"][0]].tolist() == vi.tolist()
