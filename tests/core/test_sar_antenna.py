"""The SAR antenna unfolding (scene ``sar-antenna``; core.flexible.models.sar_antenna): the cycloidal
law, the independent exact-mode reference, one panel against it, and the free-floating satellite's
momentum.

Tolerances:

* the cycloidal law's derivatives against central differences of step h: O(h²) truncation;
* the reference's quasi-static tip deflection against the cantilever closed form: the dynamic part
  is (Ω/ω₁)² ≈ 1e-5 of it for a 60 s move, the six-mode truncation of a static deflection less;
* one flexible panel against the exact modes, 0–2.5 s of a 2 s move: the reduced panel's first two
  frequencies are 0.035 % and 0.42 % off the closed form, and the reference drops the centrifugal
  terms, (θ̇/ω₁)² ≤ 2e-3; 0.5 % of the peak covers them (measured 0.13 %);
* the momenta of the free-floating model: zero in the exact motion, so they measure the integration
  error (rtol 1e-6) against the momentum the bodies carry.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.drivers import cycloidal
from core.errors import InputError
from core.flexible.models import (SAR_ANTENNA, driven_cantilever, momenta, panel_tip_deflection, sar_antenna)
from core.integrators import simulate
from core.model import ModelBuilder

P = SAR_ANTENNA
L, MU, EI = P["panel_length"], P["mass_per_length"], P["EI"]


def test_cycloidal_law_values_derivatives_and_peaks():
    h, T, t0 = -np.pi / 2, 4.0, 1.0
    f = cycloidal(h, T, start=t0)
    assert f(0.5) == (0.0, 0.0, 0.0) and f(t0 + T + 1.0) == (h, 0.0, 0.0)
    assert f(t0 + T / 2)[0] == pytest.approx(h / 2, rel=1e-15)
    assert f(t0 + T / 2)[1] == pytest.approx(2 * h / T, rel=1e-15)  # peak velocity
    assert f(t0 + T / 4)[2] == pytest.approx(2 * np.pi * h / T**2, rel=1e-15)  # peak acceleration
    eps = 1e-4
    for t in np.linspace(t0 + 0.1, t0 + T - 0.1, 9):
        fd1 = (f(t + eps)[0] - f(t - eps)[0]) / (2 * eps)
        fd2 = (f(t + eps)[1] - f(t - eps)[1]) / (2 * eps)
        assert fd1 == pytest.approx(f(t)[1], abs=1e-8)
        assert fd2 == pytest.approx(f(t)[2], abs=1e-8)


@pytest.mark.parametrize("kw, match", [(dict(change=1.0, duration=0.0), "duration"),
                                       (dict(change=1.0, duration="10 kg"), "duration"),
                                       (dict(change=1.0, duration="ten"), "duration"),
                                       (dict(change=np.nan, duration=1.0), "change"),
                                       (dict(change="90 kg", duration=1.0), "change"),
                                       (dict(change=[1.0, 2.0], duration=1.0), "change must be one number")])
def test_cycloidal_law_refuses_bad_input(kw, match):
    with pytest.raises(InputError, match=match):
        cycloidal(**kw)


def test_cycloidal_law_reads_units():
    f = cycloidal("90 deg", "2 min", start="500 ms")
    assert f(1e6)[0] == pytest.approx(np.pi / 2, rel=1e-15)
    assert f(0.5 + 60.0)[1] == pytest.approx(2 * (np.pi / 2) / 120.0, rel=1e-15)
    assert cycloidal("20 cm", 1.0)(2.0)[0] == pytest.approx(0.2, rel=1e-15)


def test_reference_quasi_static_tip_deflection_is_the_cantilever_closed_form():
    """A slow move: the tip deflection at the peak acceleration θ̈ is the static one under the
    inertial load −μxθ̈, 11 q₀L⁴/(120 EI) with q₀ = −μLθ̈ (the triangular load on a cantilever).
    The jerk's step at the start leaves a free vibration of (2π/T)/ω₁ = 3e-3 of the static
    deflection; 5 % damping has removed it (e^{-ζω₁t} = 1e-11) by the time of the peak."""
    T = 60.0
    t = np.linspace(0.0, T, 4801)
    law = cycloidal(1.0, T)
    _, tip = driven_cantilever(law, t, L, MU, EI, 0.05, n_modes=6)
    k = np.searchsorted(t, T / 4)
    static = -11.0 * MU * law(t[k])[2] * L**5 / (120.0 * EI)
    assert tip[k] == pytest.approx(static, rel=1e-4)


def test_cantilever_roots_are_the_published_eigenvalues():
    """β_k L of the clamped–free beam (Blevins 1979, table 8-1, as in test_flexible_beam.py)."""
    from core.flexible.models import cantilever_roots

    np.testing.assert_allclose(cantilever_roots(4), [1.875104068712, 4.694091132974, 7.854757438238, 10.995540734875],
                               rtol=1e-11)


def test_reference_refuses_uneven_times():
    with pytest.raises(ValueError, match="evenly spaced"):
        driven_cantilever(cycloidal(1.0, 1.0), np.array([0.0, 0.1, 0.3]), L, MU, EI)


def test_rigid_panel_actuator_moment_is_inertia_times_acceleration():
    T = 2.0
    model = sar_antenna(flexible=False, n_panels=1, bus="fixed", deployment_time=T)
    t = np.linspace(0.0, 1.5 * T, 61)
    res = simulate(model, (0.0, 1.5 * T), "radau-projection", rtol=1e-8, atol=1e-10, t_eval=t)
    law = cycloidal(-np.pi / 2, T)
    expected = MU * L**3 / 3.0 * np.array([law(x)[2] for x in t])
    moment = res.reactions_table("actuator1")["Mz [N m]"].to_numpy()
    np.testing.assert_allclose(moment, expected, atol=1e-9 * np.abs(expected).max())


def test_flexible_panel_matches_the_exact_cantilever_modes():
    T, end = 2.0, 2.5
    t = np.linspace(0.0, end, 126)
    model = sar_antenna(flexible=True, n_panels=1, bus="fixed", deployment_time=T)
    res = simulate(model, (0.0, end), "radau-projection", rtol=1e-6, atol=1e-8, t_eval=t)
    assert res.status == "finished"
    ref_moment, ref_tip = driven_cantilever(cycloidal(-np.pi / 2, T), t, L, MU, EI, P["damping_ratio"], n_modes=6)
    moment = res.reactions_table("actuator1")["Mz [N m]"].to_numpy()
    tip = panel_tip_deflection(model, res.q, "panel1")
    assert np.abs(moment - ref_moment).max() < 5e-3 * np.abs(ref_moment).max()
    assert np.abs(tip - ref_tip).max() < 5e-3 * np.abs(ref_tip).max()
    # and the elastic effect itself is far above that tolerance: the rigid panel misses it by 8 %
    rigid = MU * L**3 / 3.0 * np.array([cycloidal(-np.pi / 2, T)(x)[2] for x in t])
    assert np.abs(rigid - ref_moment).max() > 0.05 * np.abs(ref_moment).max()


@pytest.mark.parametrize("flexible", [False, True])
def test_free_floating_satellite_keeps_zero_momentum(flexible):
    """No external force or moment: the linear and angular momentum stay zero while the actuators
    turn the panels (and the bus turns the other way)."""
    T, end = 3.0, 1.0
    model = sar_antenna(flexible=flexible, deployment_time=T)
    res = simulate(model, (0.0, end), "radau-projection", rtol=1e-6, atol=1e-8, t_eval=np.linspace(0.0, end, 21))
    H = momenta(model, res.q, res.v)
    bus = model.q_slice("bus")
    bus_spin = P["bus_inertia"] * np.abs(res.v[:, bus][:, 2]).max()  # the bus's own angular momentum
    panel_push = P["panel_length"] * P["mass_per_length"] * np.abs(res.v[:, :3 * model.n_bodies]).max()
    assert bus_spin > 1.0  # the bus does turn
    assert np.abs(H[:, 2]).max() < 1e-5 * bus_spin
    assert np.abs(H[:, :2]).max() < 1e-5 * panel_push


def test_momenta_of_a_free_rigid_body_are_the_closed_form():
    b = ModelBuilder(2, "free body", gravity=(0.0, 0.0))
    m, J = 3.0, 0.7
    b.add_body("body", m, J, (0.4, -1.2), 0.3, velocity=(0.5, 2.0), angular_velocity=1.5)
    model = b.build()
    out = momenta(model, model.q0, model.v0)[0]
    assert out == pytest.approx([m * 0.5, m * 2.0, m * (0.4 * 2.0 - (-1.2) * 0.5) + J * 1.5], rel=1e-14)


@pytest.mark.parametrize("kw, match", [(dict(n_panels=0), "n_panels"), (dict(bus="floating"), "bus"),
                                       (dict(n_panels=2.5), "n_panels")])
def test_sar_antenna_refuses_bad_input(kw, match):
    with pytest.raises(InputError, match=match):
        sar_antenna(**kw)


def test_stowed_panels_unfold_into_a_straight_antenna():
    """After the deployment every panel points along +x from the bus face, end to end."""
    model = sar_antenna(flexible=False, deployment_time=1.0)
    res = simulate(model, (0.0, 1.0), "radau-projection", rtol=1e-8, atol=1e-10, n_output=2)
    q = res.q[-1]
    bus_angle = q[model.q_slice("bus")][2]
    for k in range(P["n_panels"]):
        assert q[model.q_slice(f"panel{k + 1}")][2] - bus_angle == pytest.approx(0.0, abs=1e-7)
    tip = model.point_position(q, f"panel{P['n_panels']}", (L / 2, 0.0))
    root = model.point_position(q, "bus", (P["bus_face"], P["hinge_low"]))
    assert np.linalg.norm(tip - root) == pytest.approx(P["n_panels"] * L, rel=1e-9)


@pytest.mark.slow
def test_scene_runs_in_fast_mode(tmp_path):
    """The scene's fast mode (the docs gallery's): its tables, and the single-panel check within the
    tolerance of test_flexible_panel_matches_the_exact_cantilever_modes."""
    from core.scenes import all_scenes, run_scene

    scene = all_scenes()["sar-antenna"]
    result = run_scene(scene, tmp_path / "out", mode="fast")
    for name in ("data", "panel_modes", "single_panel_check", "deployment", "flexibility_matters"):
        assert name in result.tables, name
    check = result.tables["single_panel_check"].iloc[0]
    assert check["max |moment − exact| / peak [%]"] < 0.5
    assert check["max |tip − exact| / peak [%]"] < 0.5
    deployment = result.tables["deployment"]
    assert (deployment["peak excess [%]"] > 10.0).all()  # the 3 s deployment: flexibility matters
