"""Assessment quantities (railway.assessment): Nadal limit, Hertz pressure, wear number, Y/Q.

Oracles: the trigonometric identity of Nadal's formula and the statics of a flange contact on
the point of climbing (built independently with the contact frame of railway.contact.creepage); a
quadrature of the Hertz pressure distribution; CONTACT's own frictional power for the
Manchester cases (eve70a/CONTACT rev. 2447, data/railway/manchester_contact_a22_contact_rev2447.csv).
"""

import numpy as np
import pytest
from scipy import integrate

from core.errors import InputError
from railway.assessment import (
    assessment_limits,
    derailment_quotient,
    lowpass,
    max_pressure,
    nadal_limit,
    sliding_mean,
    wear_number,
    wheel_force_statistics,
    wheel_forces_track,
)
from railway.contact.creepage import contact_frame
from railway.contact.manchester_contact import load_contact_reference


# ------------------------------------------------------------------------------------------
# Nadal
# ------------------------------------------------------------------------------------------

def test_nadal_is_tan_of_angle_minus_friction_angle():
    g = np.radians(np.linspace(30.0, 80.0, 11))[:, None]
    mu = np.array([0.0, 0.1, 0.25, 0.3, 0.5])[None, :]
    # tan(g - atan mu) = (tan g - mu)/(1 + mu tan g): an identity, evaluated independently
    np.testing.assert_allclose(nadal_limit(g, mu), np.tan(g - np.arctan(mu)), rtol=1e-13)
    # frictionless flange: the limit is the flange slope itself
    np.testing.assert_allclose(nadal_limit(g[:, 0], 0.0), np.tan(g[:, 0]), rtol=1e-14)
    # steep flange: the limit tends to 1/mu
    assert nadal_limit(np.pi / 2 - 1e-9, 0.25) == pytest.approx(4.0, rel=1e-7)


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("gamma_deg, mu", [(70.0, 0.3), (60.0, 0.25), (66.4, 0.1)])
def test_flange_at_the_point_of_climbing_has_the_nadal_quotient(side, gamma_deg, mu):
    """Statics of Nadal's criterion: on a leading flange with large angle of attack the wheel
    material slides down the flange, so the friction force mu N on the wheel acts up the flange
    slope; then Y/Q of the wheel equals (tan g - mu)/(1 + mu tan g).  The contact is built
    from geometry (normal leaning towards the track centre, the frame of railway.contact.creepage) and
    turned into Y, Q by wheel_forces_track."""
    g = np.radians(gamma_deg)
    N = 25e3
    n = np.array([0.0, -side * np.sin(g), np.cos(g)])  # rail normal into the wheel
    t, l, _ = contact_frame(n[None], np.array([[1.0, 0.0, 0.0]]))
    up_slope = np.array([0.0, side * np.cos(g), np.sin(g)])  # towards the field side and up
    Fy = mu * N * float(np.dot(l[0], up_slope))  # +-mu N along l, pointing up the slope
    Y, Q, F = wheel_forces_track([[N]], [[0.0]], [[Fy]], n[None, None, :], np.array([[1.0, 0.0, 0.0]]),
                                 [side])
    np.testing.assert_allclose(F[0, 0], N * n + mu * N * up_slope, rtol=1e-12, atol=1e-9)
    assert Y[0] > 0  # the flange pushes its rail outwards
    assert derailment_quotient(Y, Q)[0] == pytest.approx(nadal_limit(g, mu), rel=1e-12)


def test_nadal_rejects_bad_input():
    with pytest.raises(InputError, match="70"):
        nadal_limit(70.0, 0.3)  # degrees given where radians are expected
    with pytest.raises(InputError, match="mu = -0.1"):
        nadal_limit(1.2, -0.1)
    with pytest.raises(InputError, match="not finite"):
        nadal_limit(np.nan, 0.3)


# ------------------------------------------------------------------------------------------
# Hertz pressure
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("N, a, b", [(100e3, 6e-3, 4e-3), (15.44e3, 8.15e-3, 0.353e-3), (1.0, 1e-4, 1e-4)])
def test_max_pressure_integrates_to_the_normal_force(N, a, b):
    p0 = float(max_pressure(N, a, b))
    # integral of the semi-ellipsoidal Hertz pressure over the ellipse (numerical quadrature)
    val, err = integrate.dblquad(lambda y, x: p0 * np.sqrt(max(0.0, 1 - (x / a) ** 2 - (y / b) ** 2)),
                                 -a, a, lambda x: -b * np.sqrt(1 - (x / a) ** 2),
                                 lambda x: b * np.sqrt(1 - (x / a) ** 2), epsabs=0, epsrel=1e-9)
    assert val == pytest.approx(N, rel=1e-7)


def test_max_pressure_unloaded_zero_and_errors():
    p = max_pressure([[0.0, 1e4]], [[0.0, 5e-3]], [[0.0, 2e-3]])
    assert p.shape == (1, 2) and p[0, 0] == 0.0 and p[0, 1] > 0
    with pytest.raises(InputError, match="negative"):
        max_pressure(-1.0, 1e-3, 1e-3)
    with pytest.raises(InputError, match="semi-axes"):
        max_pressure(1e4, 0.0, 1e-3)


# ------------------------------------------------------------------------------------------
# wear number
# ------------------------------------------------------------------------------------------

def test_wear_number_is_the_creep_work_when_forces_oppose_creepage():
    rng = np.random.default_rng(3)
    xi, eta = rng.normal(0, 0.01, 50), rng.normal(0, 0.01, 50)
    Fx, Fy = -rng.uniform(0, 5e3, 50) * np.sign(xi), -rng.uniform(0, 5e3, 50) * np.sign(eta)
    np.testing.assert_allclose(wear_number(Fx, Fy, xi, eta), -(Fx * xi + Fy * eta), rtol=1e-14)
    with pytest.raises(InputError, match="both Mz and phi"):
        wear_number(Fx, Fy, xi, eta, Mz=Fx)


def test_wear_number_with_spin_equals_contact_frictional_power():
    """CONTACT's frictional power per metre (|FRIC.POWER| / VELOC) against the creep work of its
    own forces and creepages.  In full sliding at large creepage (flange cases, y >= 6.5 mm)
    the two are the same quantity up to the elastic part of the local slip: measured 0.34 %
    (left) and 0.09 % (right); tolerance 0.5 %.  At the smallest full-slip creepages (y = 1 mm)
    the elastic slip matters more: 3.5 %, tolerance 4 %.  Cases with an adhesion area are left
    out (the frictional power is then well below the creep work)."""
    r = load_contact_reference()
    T = wear_number(r["FX [N]"], r["FS [N]"], r["CKSI [-]"], r["CETA [-]"],
                    Mz=r["MN [N mm]"] * 1e-3, phi=r["CPHI [1/mm]"] * 1e3)
    D = np.abs(r["FRIC.POWER [W]"]) / (r["VELOC [mm/s]"] * 1e-3)
    full = (r["NADH [-]"] == 0).to_numpy()
    flange = full & (r["y_ws [mm]"] >= 6.5).to_numpy()
    assert flange.sum() == 16 and full.sum() == 38
    np.testing.assert_allclose(T[flange], D[flange], rtol=5e-3)
    np.testing.assert_allclose(T[full], D[full], rtol=4e-2)
    # without spin the flange-wheel work misses |Mz phi| (0.7 % at y = 6.5 mm, right wheel)
    T0 = wear_number(r["FX [N]"], r["FS [N]"], r["CKSI [-]"], r["CETA [-]"])
    assert np.all(T0 <= T + 1e-12)


# ------------------------------------------------------------------------------------------
# Y/Q
# ------------------------------------------------------------------------------------------

def test_derailment_quotient_nan_for_lifted_wheel():
    yq = derailment_quotient([8e3, 8e3, 1e3], [10e3, 0.0, -5.0])
    assert yq[0] == pytest.approx(0.8)
    assert np.isnan(yq[1]) and np.isnan(yq[2])
    with pytest.raises(InputError, match="not finite"):
        derailment_quotient(np.nan, 1.0)


def test_wheel_forces_track_sums_contacts_and_matches_the_contact_frame():
    rng = np.random.default_rng(7)
    nw, nc = 4, 2
    g = rng.uniform(-0.1, 1.2, (nw, nc))
    side = np.array([1.0, -1.0, 1.0, -1.0])
    n = np.stack([np.zeros((nw, nc)), -side[:, None] * np.sin(g), np.cos(g)], axis=2)
    fwd = np.array([[np.cos(0.01), np.sin(0.01), 0.0]] * nw)
    N, Fx, Fy = rng.uniform(0, 2e4, (nw, nc)), rng.normal(0, 2e3, (nw, nc)), rng.normal(0, 2e3, (nw, nc))
    N[0, 1] = Fx[0, 1] = Fy[0, 1] = 0.0
    n[0, 1] = np.nan  # an invalid candidate: ignored
    Y, Q, F = wheel_forces_track(N, Fx, Fy, n, fwd, side)
    Fref = np.zeros((nw, 3))
    for w in range(nw):
        for c in range(nc):
            if N[w, c] == 0:
                continue
            t, l, nn = contact_frame(n[w, c][None], fwd[w][None])
            Fref[w] += N[w, c] * nn[0] + Fx[w, c] * t[0] + Fy[w, c] * l[0]
    np.testing.assert_allclose(Q, Fref[:, 2], rtol=1e-12)
    np.testing.assert_allclose(Y, -side * Fref[:, 1], rtol=1e-12)
    with pytest.raises(InputError, match="side"):
        wheel_forces_track(N, Fx, Fy, n, fwd, [1, 0, 1, -1])


def test_limits_are_data_with_their_source_flag():
    lim = assessment_limits()
    row = lim[lim["quantity"] == "Y/Q"].iloc[0]
    assert row["limit [-]"] == 0.8
    assert "UIC" in row["source"] and "second-hand" in row["status"]
    assert not lim["source"].str.contains("EN 14363").any()  # not found: not held


# ------------------------------------------------------------------------------------------
# Track-test processing: low-pass, sliding mean, percentiles (A6, A7)
# ------------------------------------------------------------------------------------------

def test_lowpass_gain_is_the_squared_butterworth_gain():
    """A6: zero-phase digital Butterworth of order 4 at 20 Hz, sampled at 1 kHz: a harmonic of
    frequency f keeps 1/(1 + (tan(pi f/fs)/tan(pi 20/fs))^8) (1/2 at the cut-off, 3e-9 at the
    200 Hz wheelset bounce); measured on the middle of a 4 s record."""
    fs = 1000.0
    t = np.arange(0.0, 4.0, 1.0 / fs)
    mid = (t > 1.0) & (t < 3.0)
    for f, A in ((5.0, 1.0), (200.0, 1.0), (20.0, 1.0)):
        x = A * np.sin(2 * np.pi * f * t)
        y = lowpass(x, fs)
        gain = np.sqrt(2.0 * np.mean(y[mid] ** 2))
        expected = 1.0 / (1.0 + (np.tan(np.pi * f / fs) / np.tan(np.pi * 20.0 / fs)) ** 8)
        assert gain == pytest.approx(expected, rel=2e-3, abs=1e-10)
        if f < 20.0:  # no phase shift: the filtered peak where the signal's is
            assert np.max(np.abs(y[mid] - expected * x[mid])) < 2e-3


def test_sliding_mean_scales_a_harmonic_by_the_window_sinc():
    """A7: a harmonic of wavelength L averaged over w = 2 m keeps sin(pi w/L)/(pi w/L) of its
    amplitude, at every window centre (the integral of a piecewise-linear signal, exact up to the
    sampling of the harmonic)."""
    s = np.linspace(0.0, 100.0, 20001)
    for L in (3.0, 10.0, 37.0):
        x = np.cos(2 * np.pi * s / L)
        c, m = sliding_mean(s, x)
        k = np.pi * 2.0 / L
        assert np.allclose(m, np.sin(k) / k * np.cos(2 * np.pi * c / L), atol=1e-6)
        assert c[0] == pytest.approx(1.0) and np.all(np.diff(c) == pytest.approx(0.5))


def test_sliding_mean_of_a_constant_and_a_ramp_on_an_uneven_grid():
    s = np.sort(np.random.default_rng(3).uniform(0.0, 30.0, 400))
    c, m = sliding_mean(s, 3.0 + 0.0 * s)
    assert np.allclose(m, 3.0, rtol=1e-12)
    c, m = sliding_mean(s, 2.0 * s)  # the mean of a ramp over a centred window is its centre value
    assert np.allclose(m, 2.0 * c, rtol=1e-12)


def test_sliding_mean_and_lowpass_name_bad_input():
    with pytest.raises(InputError, match="must increase"):
        sliding_mean(np.array([0.0, 1.0, 1.0, 3.0]), np.zeros(4))
    with pytest.raises(InputError, match="shorter than the window"):
        sliding_mean(np.array([0.0, 1.0]), np.zeros(2))
    with pytest.raises(InputError, match="Nyquist"):
        lowpass(np.zeros(100), fs=30.0)
    with pytest.raises(InputError, match="not finite"):
        lowpass(np.array([0.0, np.nan] * 50), fs=1000.0)


def test_wheel_force_statistics_of_a_bouncing_wheel():
    """A wheel load of 54.5 kN with a 2 Hz swing of 5 kN and a 200 Hz bounce of 20 kN, at 1 kHz:
    the 20 Hz low-pass keeps the swing (gain 1 - 1e-8) and removes the bounce, so the 99.85 %
    percentile of Q is 54.5 + 5 sin(pi (0.9985 - 1/2)) kN (the quantile of a sinusoid); the
    unfiltered maximum is about 54.5 + 25 kN; Y = 0.1 Q gives (Y/Q) 2 m = 0.1."""
    import pandas as pd

    fs, V = 1000.0, 20.0
    t = np.arange(0.0, 10.0, 1.0 / fs)
    Q = 54.5e3 + 5e3 * np.sin(2 * np.pi * 2.0 * t) + 20e3 * np.sin(2 * np.pi * 200.0 * t + 0.3)
    Y = 0.1 * (54.5e3 + 5e3 * np.sin(2 * np.pi * 2.0 * t))
    H = pd.DataFrame({"t [s]": t, "wheel": "ws1 left", "wheelset": "ws1", "s [m]": V * t,
                      "Q [N]": Q, "Y [N]": Y, "sum Y [N]": Y})
    W = wheel_force_statistics(H)
    assert len(W) == 1
    r = W.iloc[0]
    # the filter's end transients lie outside the percentile's 0.15 %: 15 ms at each end
    assert r["Q high [N]"] == pytest.approx(54.5e3 + 5e3 * np.sin(np.pi * 0.4985), rel=1e-4)
    assert r["Q low [N]"] == pytest.approx(54.5e3 - 5e3 * np.sin(np.pi * 0.4985), rel=1e-4)
    assert r["Q max, unfiltered [N]"] == pytest.approx(54.5e3 + 25e3, rel=2e-3)
    assert r["(Y/Q) 2 m high [-]"] == pytest.approx(0.1, rel=1e-3)
    # sum Y: 2 m window at 20 m/s is 0.1 s; the 2 Hz swing (L = 10 m) keeps sinc(pi/5) of its amplitude
    k = np.pi * 2.0 / 10.0
    q = np.sin(np.pi * 0.4985)
    assert r["(sum Y) 2 m high [N]"] == pytest.approx(0.1 * (54.5e3 + 5e3 * np.sin(k) / k * q), rel=2e-3)


def test_wheel_force_statistics_name_the_wheel_and_time_of_a_bad_sample():
    import pandas as pd

    t = np.arange(0.0, 1.0, 1e-3)
    H = pd.DataFrame({"t [s]": t, "wheel": "ws2 right", "wheelset": "ws2", "s [m]": 20.0 * t,
                      "Q [N]": 5e4 + 0.0 * t, "Y [N]": 0.0 * t, "sum Y [N]": 0.0 * t})
    H.loc[500, "Q [N]"] = np.nan
    with pytest.raises(InputError, match=r"wheel 'ws2 right': Q \[N\] = nan at t = 0\.5"):
        wheel_force_statistics(H)
    short = H.iloc[:50].copy()  # 50 ms at 20 m/s: 1 m of track, shorter than the 2 m window
    short["Q [N]"] = 5e4
    with pytest.raises(InputError, match="shorter than the window"):
        wheel_force_statistics(short)
