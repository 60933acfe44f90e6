"""Beam finite elements and modal reduction (core.flexible), against the closed forms of beam
vibration: Euler–Bernoulli cantilever and free–free frequencies, the simply supported Timoshenko
beam, the torsion of a shaft, and Craig–Bampton as a Rayleigh–Ritz reduction of the full model."""

from __future__ import annotations

import numpy as np
import pytest

from core.errors import InputError, ModelError
from core.flexible import BeamMesh, BeamSection, beam_matrices, craig_bampton, normal_modes, straight_beam

STEEL = dict(E=210e9, rho=7850.0, nu=0.3)
L = 1.0
#: beta_n L of Euler–Bernoulli beams (roots of cos bL cosh bL = -1 and = +1; Blevins 1979, table 8-1)
CANTILEVER = np.array([1.875104068712, 4.694091132974, 7.854757438238, 10.995540734875])
FREE_FREE = np.array([4.730040744862, 7.853204624096, 10.995607838002])


def _eb_frequency(betaL, s, I):
    return betaL**2 / (2 * np.pi * L**2) * np.sqrt(s.E * I / (s.rho * s.A))


def _transverse(mesh, shapes, M, axis=1):
    """Modes whose kinetic energy is mostly in the transverse translation ``axis`` (planar: 1)."""
    n = mesh.dofs_per_node
    out = []
    for k in range(shapes.shape[1]):
        phi = shapes[:, k]
        part = np.zeros_like(phi)
        part[axis::n] = phi[axis::n]
        out.append(part @ (M @ part) > 0.5)
    return np.array(out)


def _eig_rtol(M, K, fixed, f_lowest):
    """Round-off bound on a computed frequency of (K, M) with ``fixed`` held: a backward-stable
    eigensolver perturbs ω² by about eps λ_max, so f by eps λ_max / (2 λ) relatively; 100 × that
    (the dense solver's constants) for the lowest frequency, the worst."""
    import scipy.linalg as sla

    free = np.setdiff1d(np.arange(M.shape[0]), fixed)
    lam_max = sla.eigh(K.toarray()[np.ix_(free, free)], M.toarray()[np.ix_(free, free)], eigvals_only=True,
                       subset_by_index=(free.size - 1, free.size - 1))[0]
    return 100.0 * np.finfo(float).eps * lam_max / (2.0 * (2.0 * np.pi * f_lowest) ** 2)


@pytest.fixture(scope="module")
def section():
    return BeamSection.rectangle(width=0.02, height=0.02, **STEEL)


def test_cantilever_frequencies_converge_to_euler_bernoulli_at_the_fourth_power(section):
    errors = {}
    for n_el in (10, 20, 40):
        mesh = straight_beam(L, n_el)
        M, K = beam_matrices(mesh, section)
        f, shapes = normal_modes(M, K, 8, fixed_dofs=mesh.dofs(0))
        f_b = f[_transverse(mesh, shapes, M)][:4]
        errors[n_el] = f_b / _eb_frequency(CANTILEVER, section, section.Iz) - 1.0
    assert np.all(np.abs(errors[40][:3]) < 2e-6)
    assert np.all(errors[10] > 0)  # consistent mass, conforming elements: from above (Rayleigh–Ritz)
    rate = np.log2(errors[10][:3] / errors[20][:3])
    assert np.all(rate > 3.8), rate  # Hermite cubics: O(h^4) in the frequency


def test_free_free_beam_has_three_rigid_modes_then_the_closed_form(section):
    mesh = straight_beam(L, 40)
    M, K = beam_matrices(mesh, section)
    f, shapes = normal_modes(M, K, 8)
    f_ref = _eb_frequency(FREE_FREE, section, section.Iz)
    assert np.all(f[:3] < 1e-3 * f_ref[0])
    flexible = f[3:][_transverse(mesh, shapes[:, 3:], M)][:3]
    np.testing.assert_allclose(flexible, f_ref, rtol=1e-5)


def _timoshenko_ss(n, s, I):
    """Lower root of (ρA ω² − κGA k²)(ρI ω² − EI k² − κGA) = (κGA k)², k = nπ/L: the simply
    supported Timoshenko beam (w = W sin kx, ψ = Ψ cos kx in the two equations of motion)."""
    k = n * np.pi / L
    kGA = s.shear_factor * s.G * s.A
    a = s.rho * s.A * s.rho * I
    b = -(s.rho * s.A * (s.E * I * k**2 + kGA) + s.rho * I * kGA * k**2)
    c = kGA * s.E * I * k**4
    w2 = (-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)
    return np.sqrt(w2) / (2 * np.pi)


def test_a_thick_simply_supported_timoshenko_beam_against_its_closed_form():
    thick = BeamSection.rectangle(width=0.2, height=0.2, **STEEL)  # L/h = 5: shear matters
    ref = np.array([_timoshenko_ss(n, thick, thick.Iz) for n in (1, 2, 3)])
    errors = []
    for n_el in (60, 120):
        mesh = straight_beam(L, n_el)
        M, K = beam_matrices(mesh, thick, theory="timoshenko")
        fixed = np.concatenate([mesh.dofs(0, [0, 1]), mesh.dofs(n_el, [1])])
        f, shapes = normal_modes(M, K, 6, fixed_dofs=fixed)
        errors.append(f[_transverse(mesh, shapes, M)][:3] / ref - 1.0)
    # converges to the closed form from above at the second power of the element length
    assert np.all(errors[1] > 0) and np.all(errors[1] < 1.5e-4)
    assert np.all(errors[0] / errors[1] > 3.8)
    # and Euler–Bernoulli overestimates it: (nπ)² sqrt(EI/ρA)/L² is 7 % to 40 % higher here
    eb = np.array([(n * np.pi) ** 2 / (2 * np.pi * L**2) * np.sqrt(thick.E * thick.Iz / (thick.rho * thick.A))
                   for n in (1, 2, 3)])
    assert np.all(eb / ref - 1.0 > 0.06)


def test_a_slender_timoshenko_beam_is_an_euler_bernoulli_beam(section):
    mesh = straight_beam(L, 40)
    f = {}
    for theory in ("euler-bernoulli", "timoshenko"):
        M, K = beam_matrices(mesh, section, theory=theory)
        f[theory] = normal_modes(M, K, 3, fixed_dofs=mesh.dofs(0))[0]
    # L/h = 50: shear and rotary inertia lower the frequencies, by more the higher the mode
    # (about (n h/L)²: 3e-4, 2e-3, 5e-3 here)
    rel = f["timoshenko"] / f["euler-bernoulli"] - 1.0
    assert np.all(rel < 0) and rel[0] > -1e-3 and np.all(np.diff(rel) < 0)


def test_a_spatial_cantilever_in_any_direction_bends_about_both_axes_and_twists():
    s = BeamSection.rectangle(width=0.03, height=0.02, **STEEL)  # Iz != Iy
    d = np.array([1.0, 2.0, 2.0]) / 3.0
    mesh = straight_beam(L, 40, dim=3, direction=d, orientation=(0.0, 0.0, 1.0))
    M, K = beam_matrices(mesh, s)
    f, _ = normal_modes(M, K, 7, fixed_dofs=mesh.dofs(0))
    bending = np.concatenate([_eb_frequency(CANTILEVER[:3], s, s.Iz), _eb_frequency(CANTILEVER[:3], s, s.Iy)])
    torsion = np.array([(2 * k - 1) / (4 * L) * np.sqrt(s.G * s.J / (s.rho * s.Ip)) for k in (1,)])
    expected = np.sort(np.concatenate([bending, torsion]))
    expected = expected[expected < f[-1] * 1.0001]
    np.testing.assert_allclose(f[:expected.size], expected, rtol=2e-4)
    # the same beam along x gives the same frequencies (the rotation into local axes is exact)
    mesh_x = straight_beam(L, 40, dim=3)
    Mx, Kx = beam_matrices(mesh_x, s)
    # to the round-off of the eigensolver: relative error of ω² about eps λ_max / λ
    np.testing.assert_allclose(normal_modes(Mx, Kx, 7, fixed_dofs=mesh_x.dofs(0))[0], f,
                               rtol=_eig_rtol(Mx, Kx, mesh_x.dofs(0), f[0]))


def test_craig_bampton_is_a_rayleigh_ritz_reduction_of_the_free_beam(section):
    mesh = straight_beam(L, 40)
    M, K = beam_matrices(mesh, section)
    full = normal_modes(M, K, 9)[0][3:]
    root = mesh.dofs(0)
    cantilever = normal_modes(M, K, 4, fixed_dofs=root)[0]
    errors = []
    for m in (4, 8, 16):
        comp = craig_bampton(M, K, root, m)
        # the same eigenproblem, to the solver's round-off
        np.testing.assert_allclose(comp.fixed_interface_frequencies[:4], cantilever,
                                   rtol=_eig_rtol(M, K, root, cantilever[0]))
        assert comp.n_rigid == 3  # the root is free: the constraint modes carry the rigid motion
        f = comp.frequencies()[3:9]
        assert np.all(f >= full[:f.size] * (1 - 1e-10))  # from above
        errors.append(f[:3] / full[:3] - 1.0)
    assert np.all(np.diff(np.array(errors), axis=0) <= 1e-12)  # more modes, never worse
    # 16 cantilever modes give the first three free-free frequencies to 2e-6, 1.2e-5, 3.9e-5
    assert np.all(errors[-1] < 1e-4) and np.all(errors[-1] < 0.1 * errors[0])


def test_orthonormalized_components_are_mass_normal_and_drop_their_rigid_modes(section):
    mesh = straight_beam(L, 20)
    M, K = beam_matrices(mesh, section)
    comp = craig_bampton(M, K, np.concatenate([mesh.dofs(0), mesh.dofs(20)]), 6).orthonormalized(drop_rigid=True)
    assert comp.T.shape[1] == 3 + 3 + 6 - 3 and "rigid" not in " ".join(comp.labels)
    np.testing.assert_allclose(comp.T.T @ (M @ comp.T), np.eye(comp.T.shape[1]), atol=1e-10)
    np.testing.assert_allclose(comp.T.T @ (K @ comp.T), comp.K, rtol=1e-9, atol=1e-6 * comp.K.max())


def test_careless_inputs_are_named():
    assert BeamSection(E="210 GPa", rho="7.85 g/cm^3", A="4 cm^2", Iz=1e-8).E == pytest.approx(2.1e11)
    with pytest.raises(InputError, match="beam section E: Young's modulus -1 Pa is outside"):
        BeamSection(E=-1.0, rho=7850.0, A=1e-4, Iz=1e-8)
    # unit slips: E written in MPa (refused; the prefix meant is ambiguous over the range of
    # materials), the area in mm² (named), the density in t/mm³ (refused)
    with pytest.raises(InputError, match="Young's modulus 210000 Pa is outside the plausible range"):
        BeamSection(E=210000, rho=7850.0, A=1e-4, Iz=1e-8)
    with pytest.raises(InputError, match="did you mean 400 mm²"):
        BeamSection(E=2.1e11, rho=7850.0, A=400, Iz=1e-8)
    with pytest.raises(InputError, match="beam section rho: density 7.85e-09 kg/m.3 is outside the plausible range"):
        BeamSection(E=2.1e11, rho=7.85e-9, A=1e-4, Iz=1e-8)  # steel in t/mm³ (the mm-t-s system)
    with pytest.raises(InputError, match="beam length"):
        straight_beam(5000.0, 10)  # 5 m written in mm
    # a deliberate outlier is accepted by name
    assert BeamSection(E=5e5, rho=1000.0, A=1e-4, Iz=1e-8, accept="E").E == 5e5
    with pytest.raises(InputError, match="shear_factor"):
        BeamSection(E=2e11, rho=7850.0, A=1e-4, Iz=1e-8, shear_factor=0.0)
    with pytest.raises(InputError, match="Poisson"):
        BeamSection(E=2e11, rho=7850.0, A=1e-4, Iz=1e-8, nu=0.7)
    with pytest.raises(InputError, match="element 1 joins node 1 to itself"):
        BeamMesh(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0, 1], [1, 1]]))
    with pytest.raises(InputError, match="names a node outside"):
        BeamMesh(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([[0, 2]]))
    s = BeamSection(E=2e11, rho=7850.0, A=1e-4, Iz=1e-8)
    mesh = straight_beam(1.0, 4)
    with pytest.raises(InputError, match="did you mean 'timoshenko'"):
        beam_matrices(mesh, s, theory="timoshenk")
    M, K = beam_matrices(mesh, s)
    with pytest.raises(InputError, match="both an interface and a fixed"):
        craig_bampton(M, K, mesh.dofs(0), 2, fixed_dofs=mesh.dofs(0))
    with pytest.raises(InputError, match="outside"):
        normal_modes(M, K, 2, fixed_dofs=[99])
    with pytest.raises(InputError, match="parallel to the element"):
        beam_matrices(straight_beam(1.0, 2, dim=3, direction=(0, 0, 1)), s)


def test_free_interface_modes_keep_the_frequencies_and_the_static_correction_the_flexibility(section):
    """Free beam: rigid-body modes, 4 elastic modes and residual attachment modes at both ends.
    The kept frequencies are exact; the basis holds the full model's static deflection with inertia
    relief under an end load, checked against the spectral sum Σ φ φᵀ/ω² over every elastic mode
    of the full model (an independent computation)."""
    from core.flexible import free_interface

    n_el = 30
    mesh = straight_beam(L, n_el)
    M, K = beam_matrices(mesh, section)
    ends = np.concatenate([mesh.dofs(0), mesh.dofs(n_el)])
    comp = free_interface(M, K, mesh.nodes, 3, 4, attachment_dofs=ends)
    assert comp.n_rigid == 3 and comp.T.shape[1] == 3 + 4 + 6
    full = normal_modes(M, K, 7)[0]
    np.testing.assert_allclose(comp.frequencies()[3:7], full[3:7], rtol=1e-8)
    import scipy.linalg as sla

    lam, Phi = sla.eigh(K.toarray(), M.toarray())  # every M-orthonormal mode of the full model
    elastic = lam > 1e-9 * lam.max()
    Ge = (Phi[:, elastic] / lam[elastic]) @ Phi[:, elastic].T
    f = np.zeros(mesh.n_dofs)
    f[mesh.dofs(n_el, [1])] = 1.0  # a transverse unit force at the free end
    u = Ge @ f
    coef, *_ = np.linalg.lstsq(comp.T, u, rcond=None)
    assert np.linalg.norm(comp.T @ coef - u) < 1e-8 * np.linalg.norm(u)
    # without the static correction the four modes miss a part of it
    coef4, *_ = np.linalg.lstsq(comp.T[:, :7], u, rcond=None)
    assert np.linalg.norm(comp.T[:, :7] @ coef4 - u) > 1e-3 * np.linalg.norm(u)


def test_free_interface_refuses_a_supported_component(section):
    from core.flexible import free_interface

    mesh = straight_beam(L, 10)
    M, K = beam_matrices(mesh, section)
    import scipy.sparse as sp

    K = K + 1e9 * sp.diags(np.r_[np.ones(3), np.zeros(mesh.n_dofs - 3)])  # a spring support at the root
    with pytest.raises(ModelError, match="not free"):
        free_interface(M, K.tocsr(), mesh.nodes, 3, 2)


def test_a_component_exported_in_mm_and_t_reads_back_to_the_same_frequencies(tmp_path, section):
    """Matrix Market export of the beam's matrices in the FE unit system mm, t, N (translations in
    mm, rotations in rad), read with FEModel.read: the SI model's frequencies to round-off."""
    import scipy.io
    import scipy.sparse as sp

    from core.flexible import FEModel

    mesh = straight_beam(L, 12)
    model = FEModel.from_beam(mesh, section)
    # exported K in N/mm (translations), N (coupling), N mm (rotations); M in t, t mm, t mm²:
    # K_SI = (1/1e-3) S K_mm S with S = 1 on translations, 1e-3 on rotations -- inverted here
    S_inv = sp.diags(np.tile([1.0, 1.0, 1e3], mesh.nodes.shape[0]))
    K_mm = S_inv @ (model.K * 1e-3) @ S_inv
    M_mm = S_inv @ (model.M * 1e-3) @ S_inv
    scipy.io.mmwrite(str(tmp_path / "mass.mtx"), sp.coo_matrix(M_mm))
    scipy.io.mmwrite(str(tmp_path / "stiff.mtx"), sp.coo_matrix(K_mm))
    (tmp_path / "nodes.csv").write_text("x [mm], y [mm]\n" + "\n".join(f"{x * 1e3},{y * 1e3}" for x, y in mesh.nodes))
    back = FEModel.read(tmp_path / "mass.mtx", tmp_path / "stiff.mtx", tmp_path / "nodes.csv", 3,
                        length_unit="mm", mass_unit="t")
    np.testing.assert_allclose(back.nodes, mesh.nodes, atol=1e-12)
    f_si = normal_modes(model.M, model.K, 4, fixed_dofs=mesh.dofs(0))[0]
    f_back = normal_modes(back.M, back.K, 4, fixed_dofs=back.dofs(0))[0]
    np.testing.assert_allclose(f_back, f_si, rtol=1e-9)
    # a hurried user: the same files read as metres and kilograms
    with pytest.raises(InputError, match="were the coordinates in millimetres"):
        FEModel.read(tmp_path / "mass.mtx", tmp_path / "stiff.mtx", tmp_path / "nodes.csv", 3)
    with pytest.raises(InputError, match="need 26"):
        FEModel.read(tmp_path / "mass.mtx", tmp_path / "stiff.mtx", tmp_path / "nodes.csv", 2, length_unit="mm")
    with pytest.raises(InputError, match="nodes.csv.*does not exist|does not exist"):
        FEModel.read(tmp_path / "mass.mtx", tmp_path / "stiff.mtx", tmp_path / "no_nodes.csv", 3)
    (tmp_path / "bad.mtx").write_text("not a matrix\n")
    with pytest.raises(InputError, match="bad.mtx is not a Matrix Market file"):
        FEModel.read(tmp_path / "bad.mtx", tmp_path / "stiff.mtx", tmp_path / "nodes.csv", 3, length_unit="mm")
    scipy.io.mmwrite(str(tmp_path / "upper.mtx"), sp.triu(sp.coo_matrix(K_mm), k=1) + sp.diags(K_mm.diagonal()))
    with pytest.raises(InputError, match="upper.mtx is not symmetric"):
        FEModel.read(tmp_path / "mass.mtx", tmp_path / "upper.mtx", tmp_path / "nodes.csv", 3, length_unit="mm")


def test_a_component_in_two_parts_is_refused_by_the_free_interface_reduction(section):
    """Two beams side by side and unconnected have 6 rigid-body motions, the node coordinates of one
    body give 3: a mechanism, whose static correction would divide by zero."""
    from core.flexible import free_interface

    nodes = np.array([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 1.0], [1.0, 1.0]])
    mesh = BeamMesh(nodes, np.array([[0, 1], [1, 2], [3, 4], [4, 5]]))
    M, K = beam_matrices(mesh, section)
    with pytest.raises(ModelError, match="6 modes without stiffness.*3 rigid-body motions"):
        free_interface(M, K, mesh.nodes, 3, 2, attachment_dofs=mesh.dofs(0))
