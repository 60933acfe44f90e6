"""Railway vehicles in motion: closed forms, equilibrium and the sweep (railway.vehicle_scenes).

Oracles: Klingel's kinematic wavelength, the Routh-Hurwitz critical speed of the suspended
wheelset (railway.hunting, itself tested against its own eigenvalues), the lateral force balance
of a vehicle in a steady curve, and the serial sweep as reference for the parallel one.
"""

import concurrent.futures

import numpy as np
import pytest

from core.integrators import simulate
from railway.contact_geometry import contact_geometry_table
from railway.hunting import klingel_wavelength
from railway.two_point import conical_wheel
from railway.vehicle_scenes import (
    CURVE,
    irregular_case,
    linear_critical_speed,
    run_curving,
)
from railway.wheel_rail import contact_history
from railway.wheelset_models import free_wheelset


def test_klingel_wavelength_of_a_free_conical_wheelset():
    """A free wheelset with 1:40 cones at 5 m/s runs on Klingel's sinusoid: the wavelength from
    the zero crossings within 1 % of 2 pi sqrt(r0 l / lambda) (the issue's tolerance; measured
    -0.49 % with the nominal cone, +0.77 % with the equivalent conicity of the profile pair)."""
    cone = conical_wheel()
    V, y0, T = 5.0, 0.002, 6.0
    m = free_wheelset(V, y0, wheel=cone, track_length=V * T + 60.0)
    res = simulate(m, (0.0, T), "jit-dop853", rtol=1e-7, atol=1e-9, n_output=int(T * 200) + 1)
    assert res.status == "finished"
    C = res.coordinates()
    x, y = C["wheelset.x [m]"].to_numpy(), C["wheelset.y [m]"].to_numpy()
    i = np.nonzero(np.sign(y[:-1]) != np.sign(y[1:]))[0]
    xc = x[i] - y[i] * (x[i + 1] - x[i]) / (y[i + 1] - y[i])
    assert len(xc) >= 2
    L_sim = 2.0 * np.mean(np.diff(xc))
    tab = contact_geometry_table(np.linspace(-0.002, 0.002, 41), wheel=cone)
    lam_e = np.polyfit(tab["y [m]"], tab["delta_r [m]"], 1)[0] / 2.0
    l = 0.5 * (1.360 + 0.140)  # taping lines (the cone's contact sits within 3 mm of them)
    for lam in (1.0 / 40.0, lam_e):
        assert L_sim == pytest.approx(klingel_wavelength(0.46, l, lam), rel=1e-2)
    # the amplitude stays put at this speed (kinematic motion, no growth beyond 1 %)
    assert np.max(np.abs(y)) < 1.01 * y0


def test_suspended_wheelset_critical_speed_eigenvalues_against_closed_form():
    """Core's linearisation (non-rotating wheelset formulation) against the closed form with the
    equivalent conicity, roll and gyroscopic term: within 1 % (measured +0.92 %)."""
    lin = linear_critical_speed()
    assert lin["V_core"] == pytest.approx(lin["V_cf"], rel=1e-2)
    assert lin["w_core"] == pytest.approx(lin["w_cf"], rel=1e-2)
    # the hunting eigenvalue changes sign there: stable 1 % below, unstable 1 % above
    assert lin["real"](0.99 * lin["V_core"]) < 0 < lin["real"](1.01 * lin["V_core"])


def test_lateral_equilibrium_in_the_full_curve():
    """Sum of the rail forces along the track's lateral axis = m (a_c - g) . n within 2 % (the
    issue's tolerance) when the whole coach is in the curve, 20 m/s, Polach 2000."""
    V = 20.0
    c = CURVE
    s_cb = c["lead"] + c["transition"] + 45.0  # car body 45 m into the curve: all wheelsets in it
    res, veh = run_curving("polach2000", V, T=(s_cb - 35.0) / V, n_output_per_s=20)
    assert res.success
    H = contact_history(veh.model, res)
    last = H[H["t [s]"] >= res.t[-1] - 0.5]  # the last half second
    assert (last["s [m]"] > c["lead"] + c["transition"] + 10.0).all()
    sumY = last.groupby("t [s]")["sum Y [N]"].sum() / 2.0
    fr = veh.track.evaluate(np.array([s_cb]))
    n = fr.R[0][:, 1]
    t_h = fr.R[0][:, 0]
    c_dir = np.array([-t_h[1], t_h[0], 0.0]) / np.hypot(t_h[0], t_h[1])
    Vm = float(last["speed [m/s]"].mean())
    need = veh.definition.total_mass * (Vm**2 / c["radius"] * c_dir - np.array([0.0, 0.0, -9.81])) @ n
    assert float(-sumY.mean()) == pytest.approx(need, rel=2e-2)


def test_sweep_parallel_equals_serial():
    from core.sweep import run_sweep

    cases = [dict(speed=V, length=50.0, law="kalker_linear", seed=3) for V in (25.0, 35.0)]
    serial = run_sweep(irregular_case, cases)
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as ex:
        parallel = run_sweep(irregular_case, cases, executor=ex)
    for (a, sa), (b, sb) in zip(serial, parallel):
        assert a == b
        for x, y in zip(sa, sb):
            np.testing.assert_array_equal(x, y)
