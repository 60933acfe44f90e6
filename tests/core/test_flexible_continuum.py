"""Plane-stress and solid components (core.flexible.continuum, assembled by scikit-fem) against
the beam theory of the same bar and the closed forms of its axial and torsion modes."""

from __future__ import annotations

import numpy as np
import pytest
import skfem

from core.errors import InputError
from core.flexible import (BeamSection, FEModel, free_interface, normal_modes, plane_stress_model, solid_model,
                           straight_beam)

E, NU, RHO = 210e9, 0.3, 7850.0
L, H, T = 1.0, 0.1, 0.02


def _clamped(fe):
    root = np.flatnonzero(np.isclose(fe.nodes[:, 0], 0.0))
    return np.concatenate([fe.dofs(k) for k in root])


def test_a_plane_stress_cantilever_is_the_timoshenko_beam_of_its_section():
    fe = plane_stress_model(skfem.MeshTri.init_tensor(np.linspace(0, L, 41), np.linspace(0, H, 5)),
                            E="210 GPa", nu=NU, rho=RHO, thickness=T)
    f = normal_modes(fe.M, fe.K, 4, fixed_dofs=_clamped(fe))[0]
    beam = FEModel.from_beam(straight_beam(L, 200), BeamSection(E=E, rho=RHO, A=H * T, Iz=T * H**3 / 12, nu=NU),
                             "timoshenko")
    fb = normal_modes(beam.M, beam.K, 4, fixed_dofs=beam.dofs(0))[0]
    # bending: 83.02 / 498.1 Hz against 82.89 / 496.8 Hz (the clamped face also holds the Poisson
    # contraction, and the mesh has 4 quadratic triangles through the height)
    np.testing.assert_allclose(f[:2], fb[:2], rtol=5e-3)
    assert np.all(f[:2] > fb[:2])
    # the first axial mode against (1/4L) sqrt(E/rho) = 1293.05 Hz (mode 3 or 4: it lies beside the third bending mode)
    axial = np.sqrt(E / RHO) / (4 * L)
    assert np.min(np.abs(f[2:] / axial - 1.0)) < 3e-3


def test_a_solid_square_cantilever_bends_alike_both_ways_and_twists():
    fe = solid_model(skfem.MeshTet.init_tensor(np.linspace(0, L, 21), np.linspace(0, H, 3), np.linspace(0, H, 3)),
                     E=E, nu=NU, rho="7850 kg/m^3")
    f = normal_modes(fe.M, fe.K, 5, fixed_dofs=_clamped(fe))[0]
    sq = BeamSection.rectangle(E=E, rho=RHO, width=H, height=H, nu=NU)
    beam = FEModel.from_beam(straight_beam(L, 100, dim=3), sq, "timoshenko")
    fb = normal_modes(beam.M, beam.K, 5, fixed_dofs=beam.dofs(0))[0]
    assert abs(f[1] / f[0] - 1.0) < 1e-3  # the square's two bending directions (the mesh is not symmetric)
    np.testing.assert_allclose(f[:4], fb[:4], rtol=1.5e-2)
    # torsion: Saint-Venant's sqrt(G J / rho Ip) / (4 L) with Roark's J = 0.1406 a^4; the clamped face
    # also holds the warping, which stiffens it (here by 2 %)
    G = E / (2 * (1 + NU))
    torsion = np.sqrt(G * 0.1406 * H**4 / (RHO * H**4 / 6)) / (4 * L)
    assert 0.0 < f[4] / torsion - 1.0 < 0.03


def test_a_free_solid_reduces_with_its_six_rigid_body_modes():
    fe = solid_model(skfem.MeshTet.init_tensor(np.linspace(0, L, 11), np.linspace(0, H, 2), np.linspace(0, H, 2)),
                     E=E, nu=NU, rho=RHO)
    comp = free_interface(fe.M, fe.K, fe.nodes, 3, 4)
    assert comp.n_rigid == 6
    f = comp.frequencies()
    assert np.all(f[:6] < 1e-4 * f[6]) and f[6] > 400.0


def test_careless_continuum_inputs_are_named():
    tri = skfem.MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 0.1, 2))
    tet = skfem.MeshTet.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 0.1, 2), np.linspace(0, 0.1, 2))
    with pytest.raises(InputError, match="needs a 2-D mesh"):
        plane_stress_model(tet, E=E, nu=NU, rho=RHO, thickness=T)
    with pytest.raises(InputError, match="needs a 3-D mesh"):
        solid_model(tri, E=E, nu=NU, rho=RHO)
    with pytest.raises(InputError, match="Poisson"):
        solid_model(tet, E=E, nu=0.5, rho=RHO)
    with pytest.raises(InputError, match="thickness"):
        plane_stress_model(tri, E=E, nu=NU, rho=RHO, thickness=0.0)
    with pytest.raises(InputError, match="did you mean 20 mm"):
        plane_stress_model(tri, E=E, nu=NU, rho=RHO, thickness=20)
    # 210 read as Pa is refused; which prefix was meant (MPa? GPa?) the range cannot tell
    with pytest.raises(InputError, match="Young's modulus 210 Pa is outside the plausible range"):
        solid_model(tet, E=210, nu=NU, rho=RHO)
    with pytest.raises(InputError, match="MeshTri"):
        plane_stress_model(object(), E=E, nu=NU, rho=RHO, thickness=T)
    with pytest.raises(InputError, match="order"):
        plane_stress_model(tri, E=E, nu=NU, rho=RHO, thickness=T, order=3)


# --- nodal stresses (ContinuumStresses, FlexibleBodyData.nodal_stresses) ------------------------------

def test_pure_bending_stresses_are_exact_on_quadratic_elements():
    """The plane-stress pure-bending field u_x = −κxy, u_y = κ(x² + νy²)/2 (exact elasticity) lies in
    the quadratic elements' space, so its stresses σ_xx = −Eκy, σ_yy = τ_xy = 0 are recovered to
    round-off at every node, on triangles and quadrilaterals."""
    from core.flexible.continuum import von_mises

    kappa = 1e-3
    for mesh in (skfem.MeshTri.init_tensor(np.linspace(0, L, 11), np.linspace(-H / 2, H / 2, 3)),
                 skfem.MeshQuad.init_tensor(np.linspace(0, L, 11), np.linspace(-H / 2, H / 2, 3))):
        fe = plane_stress_model(mesh, E=E, nu=NU, rho=RHO, thickness=T)
        x, y = fe.nodes[:, 0], fe.nodes[:, 1]
        u = np.column_stack([-kappa * x * y, kappa * (x**2 + NU * y**2) / 2]).ravel()
        sigma = fe.stress_recovery(u)[:, :, 0]
        scale = E * kappa * H / 2
        np.testing.assert_allclose(sigma[:, 0], -E * kappa * y, atol=1e-9 * scale)
        np.testing.assert_allclose(sigma[:, 1:], 0.0, atol=1e-9 * scale)
        np.testing.assert_allclose(von_mises(sigma), E * kappa * np.abs(y), atol=1e-8 * scale)
    assert fe.stress_recovery.components == ("σ_xx", "σ_yy", "τ_xy")


def test_uniaxial_tension_of_a_solid_is_recovered_exactly():
    """u = ε(x, −νy, −νz): σ_xx = Eε and nothing else, at every node of a tetrahedral mesh."""
    from core.flexible.continuum import von_mises

    eps = 2e-4
    fe = solid_model(skfem.MeshTet.init_tensor(np.linspace(0, L, 6), np.linspace(0, H, 2), np.linspace(0, H, 2)),
                     E=E, nu=NU, rho=RHO)
    u = (eps * fe.nodes * np.array([1.0, -NU, -NU])).ravel()
    sigma = fe.stress_recovery(u)[:, :, 0]
    expected = np.zeros_like(sigma)
    expected[:, 0] = E * eps
    np.testing.assert_allclose(sigma, expected, atol=1e-9 * E * eps)
    np.testing.assert_allclose(von_mises(sigma), E * eps, rtol=1e-9)


def test_flexible_body_stresses_under_a_tip_load_are_the_beam_bending_stress():
    """A plane-stress cantilever (1 m × 0.1 m) as a flexible body held at its root, Craig–Bampton with
    the loaded tip as interface, which holds the exact static response to a tip load P.  Mid-span,
    the extreme fibres carry σ_xx = ∓P(L − x)(H/2)/I (beam theory, also the elasticity solution of
    the end-loaded cantilever away from its ends: Timoshenko & Goodier, Theory of Elasticity,
    §21).  Measured: 7e-12 relative with quadratic quadrilaterals, four through the height (the
    disturbance of the clamp has decayed at mid-span); asserted to 1e-6."""
    from core.flexible import craig_bampton
    from core.flexible.body import flexible_body_data

    fe = plane_stress_model(skfem.MeshQuad.init_tensor(np.linspace(0, L, 41), np.linspace(-H / 2, H / 2, 5)),
                            E=E, nu=NU, rho=RHO, thickness=T)
    tip = np.flatnonzero(np.isclose(fe.nodes[:, 0], L))
    tip_y = np.concatenate([fe.dofs(k, [1]) for k in tip])
    modes = craig_bampton(fe.M, fe.K, tip_y, 2, fixed_dofs=_clamped(fe)).orthonormalized()
    data = flexible_body_data("plate", fe, modes, dim=2)
    P = 1000.0
    f = np.zeros(fe.n_dofs)
    f[tip_y] = P / tip.size  # the load spread over the tip nodes (σ_xx at mid-span does not see how)
    qf = np.linalg.solve(data.K, data.T.T @ f)
    sigma = data.nodal_stresses(qf)
    I = T * H**3 / 12
    for y, sign in ((H / 2, -1.0), (-H / 2, 1.0)):
        k = np.flatnonzero(np.isclose(fe.nodes[:, 0], L / 2) & np.isclose(fe.nodes[:, 1], y))[0]
        expected = sign * P * (L / 2) * (H / 2) / I
        assert sigma[k, 0] == pytest.approx(expected, rel=1e-6)
    assert data.von_mises_stresses(qf).shape == (fe.nodes.shape[0],)
    assert data.stress_components == ("σ_xx", "σ_yy", "τ_xy")


def test_nodal_stresses_are_refused_by_name_without_a_continuum():
    from core.errors import ModelError
    from core.flexible.body import flexible_body_data
    from core.flexible.reduction import normal_mode_component

    beam = FEModel.from_beam(straight_beam(L, 8), BeamSection(E=E, rho=RHO, A=H * T, Iz=T * H**3 / 12))
    data = flexible_body_data("rod", beam, normal_mode_component(beam.M, beam.K, 2, fixed_dofs=beam.dofs(0)), dim=2)
    with pytest.raises(ModelError, match="'rod'.*fibre_stresses"):
        data.nodal_stresses(np.zeros(2))
