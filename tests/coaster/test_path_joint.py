"""Tests of :mod:`coaster.path_joint` (the path-following joint, Pombo & Ambrósio 2003).

Tier 2 (properties): Φ_q against central differences of Φ through the model's retraction
(body-frame rotation increments), γ against central differences of Φ_q v along q(τ) =
retract(q, τ v), on an analytic helix (Frenet frame, Ω constant) and on a canted clothoid
(non-Frenet frame, Ω′ ≠ 0), with the joint point offset from the body origin.
Tier 1 (closed forms, notes/coaster.md): a rigid car on a helix under gravity,
L̈ = −m g sin α / (m + J_zz/h²); reactions F·n = m κ L̇², F·b = m g R/h, F·t = m (L̈ + g c/h),
the moment J ω̇ + ω × J ω; zero power of the reactions; a bead in a vertical loop.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import fresnel

from coaster.path_joint import REACTION_COLUMNS, PathFollowingJoint
from core.curves import FramedCurve
from core.errors import InputError
from core.model import ModelBuilder
from core.simulation import simulate

G = 9.81


# ---------------------------------------------------------------------------------------------
# analytic framed curves
# ---------------------------------------------------------------------------------------------
class HelixCurve(FramedCurve):
    """g(L) = (R cos(L/h), R sin(L/h), c L/h), h = √(R² + c²), Frenet frame, Ω = ẑ/h, Ω′ = 0."""

    def __init__(self, radius, rise, length=100.0):
        self.R, self.c = float(radius), float(rise)
        self.h = np.hypot(self.R, self.c)
        self.length = float(length)

    def evaluate_raw(self, s):
        R, c, h = self.R, self.c, self.h
        a = s / h
        ca, sa, z = np.cos(a), np.sin(a), np.zeros_like(s)
        g = np.column_stack([R * ca, R * sa, c * a])
        t = np.column_stack([-R / h * sa, R / h * ca, np.full_like(s, c / h)])
        n = np.column_stack([-ca, -sa, z])
        b = np.column_stack([c / h * sa, -c / h * ca, np.full_like(s, R / h)])
        ddg = (R / h**2) * n
        Om = np.tile([0.0, 0.0, 1.0 / h], (len(s), 1))
        return g, t, ddg, np.stack([t, n, b], axis=2), Om, np.zeros_like(Om)


class CantedClothoid(FramedCurve):
    """Horizontal clothoid, heading ψ = L²/(2A²), rolled by the cant φ(L) = φ1 L + φ2 L² about t.

    g = A√π (C(L/(A√π)), S(L/(A√π)), 0); R = R_z(ψ) R_x(φ); Ω = ψ′ ẑ + φ′ t;
    Ω′ = ψ″ ẑ + φ″ t + φ′ ψ′ ẑ × t (notes/coaster.md, Frames).
    """

    def __init__(self, A=20.0, phi1=0.02, phi2=0.004, length=60.0):
        self.A, self.p1, self.p2, self.length = float(A), float(phi1), float(phi2), float(length)

    def evaluate_raw(self, s):
        A = self.A
        k = A * np.sqrt(np.pi)
        S, C = fresnel(s / k)
        psi, dpsi, ddpsi = s**2 / (2 * A**2), s / A**2, np.full_like(s, 1.0 / A**2)
        phi, dphi, ddphi = self.p1 * s + self.p2 * s**2, self.p1 + 2 * self.p2 * s, np.full_like(s, 2 * self.p2)
        z = np.zeros_like(s)
        cp, sp_, cf, sf = np.cos(psi), np.sin(psi), np.cos(phi), np.sin(phi)
        g = np.column_stack([k * C, k * S, z])
        t = np.column_stack([cp, sp_, z])
        lat = np.column_stack([-sp_, cp, z])
        ez = np.tile([0.0, 0.0, 1.0], (len(s), 1))
        n = cf[:, None] * lat + sf[:, None] * ez
        b = -sf[:, None] * lat + cf[:, None] * ez
        ddg = dpsi[:, None] * lat
        Om = dpsi[:, None] * ez + dphi[:, None] * t
        dOm = ddpsi[:, None] * ez + ddphi[:, None] * t + (dphi * dpsi)[:, None] * lat
        return g, t, ddg, np.stack([t, n, b], axis=2), Om, dOm


def _model(curve, L0=3.0, Ld0=2.0, point=(0.3, -0.2, -0.5), xi=(1, 0, 0), zeta=(0, 0, 1), mass=10.0,
           inertia=(2.0, 3.0, 4.0), gravity=G):
    joint = PathFollowingJoint("path", "car", curve, "L", point=point, xi=xi, zeta=zeta)
    r, p, v, w = joint.initial_state(L0, Ld0)
    b = ModelBuilder(3, "car_on_track", gravity=(0.0, 0.0, -gravity))
    b.add_body("car", mass, inertia, r, orientation=p, velocity=v, angular_velocity=w)
    b.add_coordinate("L", L0, Ld0, 0.0)
    b.add_joint(joint)
    return b.build(), joint


CURVES = {"helix": lambda: HelixCurve(2.0, 0.5), "clothoid": lambda: CantedClothoid()}
# body vectors: the default (x along t, z along b) and an oblique mounting
MOUNTS = {"default": ((1, 0, 0), (0, 0, 1)),
          "oblique": ((1.0, 1.0, 0.0), (-1.0, 1.0, 2.0))}


def _perturbed(model, seed):
    """A state off the constraint manifold (the formulas hold for any q, v)."""
    rng = np.random.default_rng(seed)
    q = model.retract(model.q0, 0.1 * rng.standard_normal(model.n_v))
    v = model.v0 + rng.standard_normal(model.n_v)
    return q, v


# ---------------------------------------------------------------------------------------------
# tier 2: Φ_q and γ against finite differences
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("curve", CURVES)
@pytest.mark.parametrize("mount", MOUNTS)
def test_initial_state_satisfies_the_joint(curve, mount):
    model, joint = _model(CURVES[curve](), xi=MOUNTS[mount][0], zeta=MOUNTS[mount][1])
    assert np.abs(model.Phi(0.0, model.q0)).max() < 1e-13
    assert np.abs(model.Phi_q(0.0, model.q0) @ model.v0).max() < 1e-13
    assert model.degrees_of_freedom == 1


@pytest.mark.parametrize("curve", CURVES)
@pytest.mark.parametrize("mount", MOUNTS)
def test_jacobian_against_finite_differences(curve, mount):
    """Φ_q e_j = (Φ(retract(q, ε e_j)) − Φ(retract(q, −ε e_j)))/(2ε) + O(ε²); ε = 1e-6 gives
    about 1e-10 truncation and round-off; tolerance 1e-7 (measured max 2.3e-10)."""
    model, _ = _model(CURVES[curve](), xi=MOUNTS[mount][0], zeta=MOUNTS[mount][1])
    for seed in range(3):
        q, _ = _perturbed(model, seed)
        J = model.Phi_q(0.0, q).toarray()
        eps = 1e-6
        fd = np.column_stack([(model.Phi(0.0, model.retract(q, eps * e)) - model.Phi(0.0, model.retract(q, -eps * e)))
                              / (2 * eps) for e in np.eye(model.n_v)])
        assert np.abs(J - fd).max() < 1e-7, np.abs(J - fd).max()


@pytest.mark.parametrize("curve", CURVES)
@pytest.mark.parametrize("mount", MOUNTS)
def test_gamma_against_finite_differences(curve, mount):
    """γ = −d/dτ [Φ_q(q(τ)) v] at τ = 0 along q(τ) = retract(q, τ v) with v fixed (body-frame
    ω̄ constant: A(τ) = A exp(τ ω̄~), the motion the model's q̇ = Z(q) v describes).
    Central differences, ε = 1e-6; tolerance 1e-6 (measured max 6.9e-10); dropping Ω × (Ω × e), Ω′ × e
    (clothoid), the Coriolis or the centripetal term gives errors from 7e-4 to 3."""
    model, _ = _model(CURVES[curve](), xi=MOUNTS[mount][0], zeta=MOUNTS[mount][1])
    for seed in range(3):
        q, v = _perturbed(model, seed)
        eps = 1e-6
        fd = (model.Phi_q(0.0, model.retract(q, eps * v)) @ v - model.Phi_q(0.0, model.retract(q, -eps * v)) @ v) / (2 * eps)
        gam = model.gamma(0.0, q, v)
        assert np.abs(gam + fd).max() < 1e-6 * max(1.0, np.abs(fd).max()), np.abs(gam + fd).max()
        assert np.all(model.nu(0.0, q) == 0.0)


def test_gamma_needs_every_frame_term():
    """On the helix each term of γ_k is O(1): removing any one of them would fail the test above."""
    model, joint = _model(HelixCurve(2.0, 0.5))
    q, v = _perturbed(model, 7)
    r, A, L = joint._state(q)
    _, _, _, R, Om, _ = joint._track(L)
    vi = v[joint.v_index]
    w, Ld = A @ vi[3:6], vi[6]
    u, e = A @ joint.xi, R[:, 1]
    terms = [Ld**2 * np.cross(Om, np.cross(Om, e)) @ u, 2 * Ld * np.cross(Om, e) @ np.cross(w, u),
             e @ np.cross(w, np.cross(w, u))]
    assert min(abs(x) for x in terms) > 1e-2


def test_bad_input_is_named():
    c = HelixCurve(2.0, 0.5)
    with pytest.raises(InputError, match="perpendicular"):
        PathFollowingJoint("p", "car", c, "L", xi=(1, 0, 0), zeta=(1, 0, 1))
    with pytest.raises(InputError, match="zeta"):
        PathFollowingJoint("p", "car", c, "L", zeta=(0, 0, 0))
    with pytest.raises(InputError, match="FramedCurve"):
        PathFollowingJoint("p", "car", object(), "L")
    b = ModelBuilder(2, "planar")
    b.add_body("car", 1.0, 1.0, (0.0, 0.0))
    b.add_coordinate("L", 0.0)
    b.add_joint(PathFollowingJoint("p", "car", c, "L"))
    with pytest.raises(InputError, match="spatial"):
        b.build()


# ---------------------------------------------------------------------------------------------
# tier 1: rigid car on a helix under gravity
# ---------------------------------------------------------------------------------------------
def test_rigid_car_on_helix_closed_form_and_reactions():
    """L̈ = −m g sin α/(m + J_zz/h²), J_zz = J_t sin²α + J_b cos²α (notes/coaster.md), joint at the
    centre of mass; reactions in the track frame F·n = m κ L̇², F·b = m g R/h, F·t = m(L̈ + g c/h),
    moment J ω̇ + ω × J ω with ω = ẑ L̇/h; the power of the reactions is zero.

    Tolerances from rtol = atol = 1e-9: L within 100 rtol (1 + |L|) (measured 1.0e-10 m),
    forces and moments within 1e-6 m g (measured at most 3.5e-10), power within 1e-7 m g |v|
    (measured 3.9e-8 W against 2.9e-5 W)."""
    Rh, c, m, Jt, Jn, Jb = 2.0, 0.5, 10.0, 2.0, 3.0, 4.0
    curve = HelixCurve(Rh, c)
    h = curve.h
    sa, ca = c / h, Rh / h
    acc = -m * G * sa / (m + (Jt * sa**2 + Jb * ca**2) / h**2)
    L0, Ld0 = 1.0, 3.0
    model, joint = _model(curve, L0=L0, Ld0=Ld0, point=(0, 0, 0), mass=m, inertia=(Jt, Jn, Jb))
    rtol = 1e-9
    res = simulate(model, (0.0, 2.0), "dop853-projection", rtol=rtol, atol=rtol, n_output=21)
    assert res.status == "finished", res.message
    L, Ld = res.q[:, joint.q_index[7]], res.v[:, joint.v_index[6]]
    L_exact = L0 + Ld0 * res.t + 0.5 * acc * res.t**2
    assert np.abs(L - L_exact).max() < 100 * rtol * (1 + np.abs(L_exact).max())
    assert np.abs(Ld - (Ld0 + acc * res.t)).max() < 100 * rtol * (1 + abs(Ld0))
    # reactions in the track frame
    tab = joint.reaction_table(model, res)
    assert list(tab.columns[2:8]) == list(REACTION_COLUMNS)
    F = tab[list(REACTION_COLUMNS[:3])].to_numpy()
    Mo = tab[list(REACTION_COLUMNS[3:])].to_numpy()
    kappa = Rh / h**2
    ftol = 1e-6 * m * G
    assert np.abs(F[:, 0] - m * (acc + G * sa)).max() < ftol
    assert np.abs(F[:, 1] - m * kappa * Ld**2).max() < ftol
    assert np.abs(F[:, 2] - m * G * ca).max() < ftol
    M_exact = np.column_stack([acc / h * Jt * sa * np.ones_like(Ld), (Ld / h) ** 2 * sa * ca * (Jt - Jb),
                               acc / h * Jb * ca * np.ones_like(Ld)])
    assert np.abs(Mo - M_exact).max() < ftol
    # zero power of the reactions (the L row: Φ_Lᵀ λ = 0)
    speed = np.linalg.norm(res.v[:, :3], axis=1).max()
    assert np.abs(tab["P [W]"]).max() < 1e-7 * m * G * speed
    # energy conserved
    assert np.abs(res.energy - res.energy[0]).max() < 100 * rtol * m * G * (1 + speed**2 / G)


@pytest.mark.parametrize("curve", CURVES)
def test_offset_car_energy_and_zero_power(curve):
    """Joint point offset from the centre of mass, oblique mounting: energy conserved and the
    reactions do no work (rtol 1e-8; energy within 100 rtol scale, power within 1e-6 m g |v|)."""
    m = 10.0
    model, joint = _model(CURVES[curve](), L0=2.0, Ld0=3.0, xi=MOUNTS["oblique"][0], zeta=MOUNTS["oblique"][1],
                          mass=m)
    rtol = 1e-8
    res = simulate(model, (0.0, 1.0), "dop853-projection", rtol=rtol, atol=rtol, n_output=11)
    assert res.status == "finished", res.message
    speed = np.linalg.norm(res.v[:, :3], axis=1).max()
    assert np.abs(res.energy - res.energy[0]).max() < 100 * rtol * m * G * (1 + speed**2 / G)
    P = joint.reaction_power(res.q, res.v, joint.joint_multipliers(model, res.lam))
    assert np.abs(P).max() < 1e-6 * m * G * speed
    assert res.position_violation.max() < 10 * rtol


# ---------------------------------------------------------------------------------------------
# tier 1: bead in a vertical loop
# ---------------------------------------------------------------------------------------------
class VerticalLoop(FramedCurve):
    """Circle of radius R in the x-z plane entered at the bottom along +x (Frenet frame:
    n towards the centre, b = −ŷ, Ω = −ŷ/R, Ω′ = 0)."""

    def __init__(self, radius):
        self.R = float(radius)
        self.length = 2 * np.pi * self.R

    def evaluate_raw(self, s):
        R = self.R
        a = s / R
        ca, sa, z = np.cos(a), np.sin(a), np.zeros_like(s)
        g = np.column_stack([R * sa, z, R * (1 - ca)])
        t = np.column_stack([ca, z, sa])
        n = np.column_stack([-sa, z, ca])
        b = np.tile([0.0, -1.0, 0.0], (len(s), 1))
        return g, t, n / R, np.stack([t, n, b], axis=2), b / R, np.zeros_like(b)


def test_bead_in_vertical_loop():
    """Bead (J = 1e-6 kg m², m = 1 kg) entering a loop of radius R = 5 m at v_b = 20 m/s.
    With g_e = g m/(m + J_b/R²): time to the top t = (2R/v_b) F(π/2, k), k² = 4 g_e R/v_b²
    (notes/coaster.md), and N = F·n = m(v²/R + g cos φ), so N_bottom − N_top = 2 m g + 4 m g_e
    (→ 6 m g for J → 0).  rtol = 1e-10: L(t_top) within 1e3 rtol R (measured 3e-11 m) and
    the normal forces within 1e-6 m g (measured 1.4e-10 N); N_b − N_t − 6 m g = 1.6e-6 N, the
    inertia of the bead."""
    from scipy.special import ellipkinc

    R, vb, m, J = 5.0, 20.0, 1.0, 1e-6
    ge = G * m / (m + J / R**2)
    t_top = 2 * R / vb * ellipkinc(np.pi / 2, 4 * ge * R / vb**2)
    model, joint = _model(VerticalLoop(R), L0=0.0, Ld0=vb, point=(0, 0, 0), mass=m, inertia=(J, J, J))
    rtol = 1e-10
    res = simulate(model, (0.0, t_top), "dop853-projection", rtol=rtol, atol=rtol, t_eval=[0.0, t_top])
    assert res.status == "finished", res.message
    assert abs(res.q[-1, joint.q_index[7]] - np.pi * R) < 1e3 * rtol * R
    N = joint.reaction_table(model, res)["F_n [N]"].to_numpy()
    vt2 = vb**2 - 4 * ge * R
    assert abs(N[0] - m * (vb**2 / R + G)) < 1e-6 * m * G
    assert abs(N[-1] - m * (vt2 / R - G)) < 1e-6 * m * G
    assert abs((N[0] - N[-1]) - (2 * m * G + 4 * m * ge)) < 1e-6 * m * G
    assert abs((N[0] - N[-1]) - 6 * m * G) < 1e-5 * m * G  # the bead limit, J/(m R²) = 4e-8
