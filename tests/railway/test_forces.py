"""Wheel-rail contact forces of a contact search (railway.contact.forces).

Oracles: the compiled kernel against the reference path built from the validated modules
(core.contact_laws, railway.contact.creepage, railway.contact.creep); the kernel's normal law against
core.contact_laws; every creep law through ContactForces against the law called directly;
Hertz's closed form N = K_h delta^1.5 at zero penetration rate; the force-opposes-creepage sign;
force balance of the global force vector.
"""

import numpy as np
import pytest

from core.contact_laws import HYSTERESIS_LAWS, hertz_from_penetration, hysteresis_force, relative_curvatures
from core.errors import InputError, UnknownNameError
from railway.contact.search.kernels import HAVE_NUMBA
from railway.contact.search import ContactSearch, wheelset_pose
from railway.contact.creep import CREEP_MODELS, CreepModel, get_creep_model, register_creep_model
from railway.contact.forces import (
    FORCE_KEYS,
    ContactForces,
    _compiled_normal_law,
    lankarani_nikravesh_force,
    wheel_rail_curvatures,
)
from railway.track import Curve, Straight, Track, Transition

V = 30.0
R0 = 0.46


@pytest.fixture(scope="module")
def contacts():
    track = Track([Straight(30.0), Transition(20.0), Curve(30.0, 300.0, 0.05)])
    cs = ContactSearch(track, n_wheelsets=3)
    s = np.array([10.0, 35.0, 60.0])
    # tread contacts under load, one wheelset on its flange, yaw and roll
    lat = np.array([0.002, -0.003, 0.0068])
    yaw = np.array([0.003, -0.004, 0.006])
    r, A = wheelset_pose(track, s, lat, R0 - 3e-4, np.array([0.0, 4e-4, 0.0]), yaw)
    res = cs.search(r, A, s, warm=False)
    rng = np.random.default_rng(3)
    v = A[:, :, 0] * V + rng.normal(scale=0.05, size=(3, 3))
    w = A[:, :, 1] * (V / R0) * (1 + rng.normal(scale=2e-3, size=(3, 1))) + rng.normal(scale=0.02, size=(3, 3))
    return res, r, A, v, w


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
@pytest.mark.parametrize("model", ["kalker_linear", "polach2000"])
def test_compiled_equals_reference(contacts, model):
    res, r, A, v, w = contacts
    f1 = ContactForces(creep_model=model, compiled=True)(res, r, A, v, w)
    f2 = ContactForces(creep_model=model, compiled=False)(res, r, A, v, w)
    # five loaded contacts, one of them on the S1002 flange root (contact angle ~25 deg)
    assert np.count_nonzero(f2["N"]) >= 5
    assert np.max(res.contact_angle[f2["N"] > 0]) > np.radians(20)
    # the kernel tabulates the Hertz and Kalker coefficients on 4001 nodes of ln(B/A)
    # (linear interpolation, relative error ~ (h^2/8) max|f''/f| ~ 1e-5); creepages are exact
    for k in list(FORCE_KEYS) + ["force", "moment"]:
        scale = np.max(np.abs(f2[k])) + 1e-300
        np.testing.assert_allclose(f1[k], f2[k], atol=1e-4 * scale, rtol=0, err_msg=k)
    for k in ("xi", "eta", "phi", "delta_dot"):
        np.testing.assert_allclose(f1[k], f2[k], rtol=1e-12, atol=1e-15, err_msg=k)


def test_static_normal_force_is_hertz(contacts):
    res, r, A, v, w = contacts
    # pure rolling translation along the rails with no penetration rate at the contacts:
    # v_ws . n = 0 for the rolling direction; the kinematic rolling spin makes the point velocity
    # of a wheel rolling without slip zero, so N = K_h delta^1.5 exactly
    fc = ContactForces()
    v0 = np.zeros_like(v)
    w0 = np.zeros_like(w)
    v0[:, 0] = 1.0  # creepages need V > 0; the resulting creep forces are irrelevant here
    f = fc(res, r, A, v0, w0)
    on = res.valid & (res.penetration > 0)
    A_ = 0.5 * (res.k_wheel_rolling + res.k_rail_rolling)[on]
    B_ = np.clip(0.5 * (res.k_wheel_lateral + res.k_rail_lateral)[on], A_ / 1e3, A_ * 1e3)
    h = hertz_from_penetration(res.penetration[on], A_, B_, 2.1e11, 0.28, 2.1e11, 0.28)
    # v0 has a component along n (the normal leans by the contact angle): remove its damping
    dd = f["delta_dot"][on]
    damp = 1.0 + 0.75 * (1.0 - 0.9**2) * dd / 0.1
    np.testing.assert_allclose(f["N"][on], np.maximum(h.normal_force * damp, 0.0), rtol=2e-4)
    assert np.all(f["N"][~on] == 0.0)


def test_forces_oppose_creepage_and_resolve_globally(contacts):
    res, r, A, v, w = contacts
    f = ContactForces(creep_model="kalker_linear")(res, r, A, v, w)
    on = f["N"] > 0
    assert np.all(f["Fx"][on] * f["xi"][on] <= 0.0)
    # global force = N n + Fx t + Fy l: its component along n is N
    n_comp = np.einsum("wck,wck->wc", f["force"], np.nan_to_num(res.normal))
    np.testing.assert_allclose(n_comp[on], f["N"][on], rtol=1e-9)
    tang = np.linalg.norm(f["force"] - n_comp[..., None] * np.nan_to_num(res.normal), axis=-1)
    np.testing.assert_allclose(tang[on], np.hypot(f["Fx"], f["Fy"])[on], rtol=1e-9)


def test_bad_input_names_the_value(contacts):
    res, r, A, v, w = contacts
    bad = w.copy()
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"omega_ws\[1, 2\] = nan"):
        ContactForces()(res, r, A, v, bad)
    with pytest.raises(ValueError, match="mu = -0.1"):
        ContactForces(mu=-0.1)
    with pytest.raises(ValueError, match="rolling speed"):
        ContactForces()(res, r, A, np.zeros_like(v), w)


# ----------------------------------------------------------------------------- normal law

def test_lankarani_nikravesh_limits():
    K = 1e10
    d = np.array([-1e-5, 1e-5, 1e-5, 1e-5])
    dd = np.array([1.0, 0.0, 0.05, -50.0])
    F = lankarani_nikravesh_force(d, dd, K, restitution=0.8)
    hertz = K * 1e-5**1.5
    assert F[0] == 0.0
    assert F[1] == pytest.approx(hertz, rel=1e-14)  # steady rolling, no rate: pure Hertz
    # floor 0.1 m/s used when no engagement velocity is given (documented steady-rolling choice)
    assert F[2] == pytest.approx(hertz * (1 + 0.75 * 0.36 * 0.05 / 0.1), rel=1e-14)
    assert F[3] == 0.0  # fast separation: clipped, never adhesive
    F2 = lankarani_nikravesh_force(1e-5, 0.05, K, 0.8, approach_velocity=2.0)
    assert F2[0] == pytest.approx(hertz * (1 + 0.75 * 0.36 * 0.05 / 2.0), rel=1e-14)
    F3 = lankarani_nikravesh_force(1e-5, 0.05, K, 1.0)
    assert F3[0] == pytest.approx(hertz, rel=1e-14)
    with pytest.raises(ValueError, match="restitution must lie in \\[0, 1\\], got 1.5"):
        lankarani_nikravesh_force(1e-5, 0.0, K, 1.5)
    with pytest.raises(InputError, match="approach_velocity_floor must be > 0, got 0.0"):
        lankarani_nikravesh_force(1e-5, 0.0, K, 0.8, approach_velocity_floor=0.0)
    with pytest.raises(InputError, match="stiffness must be >= 0, got -1.0"):
        lankarani_nikravesh_force(1e-5, 0.0, -1.0, 0.8)
    # it is the law of core.contact_laws with v0 = max(|engagement velocity|, floor)
    ref = HYSTERESIS_LAWS["lankarani-nikravesh"].force(d, dd, K, 0.8, approach_velocity=0.1)
    np.testing.assert_array_equal(F, ref.force)
    F4 = lankarani_nikravesh_force(d, dd, K, 0.8, approach_velocity=[0.01, -3.0, 0.5, 0.2])
    ref4 = HYSTERESIS_LAWS["lankarani-nikravesh"].force(d, dd, K, 0.8, approach_velocity=[0.1, 3.0, 0.5, 0.2])
    np.testing.assert_array_equal(F4, ref4.force)


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
def test_kernel_normal_law_equals_core_contact_laws():
    # the numba kernel writes Eq. (N1) of core.contact_laws out for one contact; both must agree
    # on contact, no contact and the clip (fast separation), for every hysteresis factor
    law = _compiled_normal_law()
    rng = np.random.default_rng(4)
    n = 500
    d = np.concatenate([[-1e-5, 0.0], rng.uniform(-2e-5, 2e-4, n)])
    dd = np.concatenate([[0.1, 0.1], rng.uniform(-3.0, 3.0, n)])
    Kh = np.concatenate([[1e10, 1e10], rng.uniform(1e9, 5e11, n)])
    v0 = np.concatenate([[0.1, 0.1], rng.uniform(0.05, 2.0, n)])
    chi = np.concatenate([[0.3, 0.3], HYSTERESIS_LAWS["lankarani-nikravesh"].factor(rng.uniform(0.0, 1.0, n))])
    F_kernel = np.array([law(*args) for args in zip(Kh, d, dd, chi, v0)])
    F_core = hysteresis_force(d, dd, Kh, chi, v0, 1.5).force
    assert np.count_nonzero(F_core == 0) > 50 and np.count_nonzero(F_core > 0) > 50
    np.testing.assert_allclose(F_kernel, F_core, rtol=4e-16, atol=0)


def test_wheel_rail_curvatures_is_core_with_wheel_and_rail_names():
    A, B = wheel_rail_curvatures([0.46, 0.47], [np.inf, -0.5], [0.3, 0.013], [np.inf, 2.0])
    A2, B2 = relative_curvatures([0.46, 0.47], [np.inf, -0.5], [np.inf, 2.0], [0.3, 0.013])
    np.testing.assert_array_equal(A, A2)
    np.testing.assert_array_equal(B, B2)
    with pytest.raises(InputError, match="R1 = wheel, R2 = rail.*non-Hertzian contact at index 1"):
        wheel_rail_curvatures([0.46, 0.46], [-0.014, -0.012], [0.013, 0.013])


# ----------------------------------------------------------------------------- creep laws

POLACH2005 = dict(k_A=0.6, k_S=0.2, A=0.38, B=0.7, speed=V)


@pytest.mark.parametrize("compiled", ["auto", False])
@pytest.mark.parametrize("model", sorted(CREEP_MODELS))
def test_every_creep_law_through_contact_forces(contacts, model, compiled):
    """ContactForces gives the forces of the creep law called directly with its own creepages,
    semi-axes and normal force; exactly on the numpy path, to the kernel's table accuracy on the
    compiled one (Kalker coefficients tabulated against ln(B/A), ~1e-5 relative)."""
    res, r, A, v, w = contacts
    params = POLACH2005 if model == "polach2005" else None
    fc = ContactForces(creep_model=model, compiled=compiled, creep_params=params)
    assert fc.creep_model == model
    # every law of the package (join="scaled") has a compiled form
    assert fc.compiled == (compiled == "auto" and HAVE_NUMBA)
    f = fc(res, r, A, v, w)
    on = f["N"] > 0
    assert np.count_nonzero(on) >= 5
    law = get_creep_model(model, **(params or {}))
    direct = law(f["xi"][on], f["eta"][on], f["phi"][on], f["N"][on], f["a"][on], f["b"][on],
                 fc.G, fc.nu, fc.mu)
    for k in ("Fx", "Fy", "Mz"):
        got = f[k][on]
        want = getattr(direct, k)
        if fc.compiled:
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-4 * np.max(np.abs(want)), err_msg=k)
        else:
            np.testing.assert_allclose(got, want, rtol=1e-13, atol=0, err_msg=k)
    assert np.all(np.abs(f["Fx"][on]) > 0)


def test_polach2005_is_not_replaced_by_another_law(contacts):
    res, r, A, v, w = contacts
    f5 = ContactForces(creep_model="polach2005", creep_params=POLACH2005)(res, r, A, v, w)
    f0 = ContactForces(creep_model="polach2000", compiled=False)(res, r, A, v, w)
    on = f0["N"] > 0
    assert np.max(np.abs(f5["Fx"][on] - f0["Fx"][on])) > 1e-2 * np.max(np.abs(f0["Fx"][on]))
    with pytest.raises(InputError, match="compiled=True, but the numba kernel implements only"):
        ContactForces(creep_model=get_creep_model("polach2005", join="raw", **POLACH2005), compiled=True)
    assert not ContactForces(creep_model=get_creep_model("polach2000", join="raw")).compiled
    with pytest.raises(UnknownNameError, match="unknown creep model 'nope'; registered: kalker_linear"):
        ContactForces(creep_model="nope")


def test_user_creep_law_through_contact_forces(contacts):
    res, r, A, v, w = contacts

    class Coulomb(CreepModel):
        def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
            s = np.hypot(xi, eta)
            return -mu * N * xi / s, -mu * N * eta / s, np.zeros_like(xi)

    register_creep_model("test_coulomb_forces", Coulomb)
    try:
        f = ContactForces(creep_model="test_coulomb_forces")(res, r, A, v, w)
    finally:
        CREEP_MODELS.unregister("test_coulomb_forces")
    on = f["N"] > 0
    np.testing.assert_allclose(np.hypot(f["Fx"], f["Fy"])[on], 0.3 * f["N"][on], rtol=1e-12)
