"""Wheel-rail contact forces of a contact search (railway.forces).

Oracles: the compiled kernel against the reference path built from the validated modules
(railway.hertz, railway.creepage, railway.creep); Hertz's closed form N = K_h delta^1.5 at zero
penetration rate; the force-opposes-creepage sign; force balance of the global force vector.
"""

import numpy as np
import pytest

from railway._kernels import HAVE_NUMBA
from railway.contact_search import ContactSearch, wheelset_pose
from railway.forces import FORCE_KEYS, ContactForces
from railway.hertz import hertz_from_penetration
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
