r"""Filtering and differentiation of coordinates (biomech.kinematics).

Test signal: q(t) = c + Σ_k A_k sin(ω_k t + φ_k), components at 1 and 2 Hz, sampled at 60 Hz for
2.5 s (the gait10dof IK trial's rate and length), f_c = 6 Hz.

Tolerances, derived:

* The zero-lag filter multiplies each sinusoid by the exact gain G(f) = [1 + (tan(πf/f_s) /
  tan(πf_c/f_s))^{2N}]^{-1} without phase shift, so the filtered signal and its derivatives are
  Σ G_k A_k ω_k^r sin(ω_k t + φ_k + rπ/2).
* The quintic interpolating spline then differentiates the filtered samples; its error in the r-th
  derivative is bounded by K h^{6-r} max|q^{(6)}| with max|q^{(6)}| ≤ Σ A_k ω_k^6, taking K = 1
  (the constants of quintic-spline interpolation are well below 1 for r ≤ 2).
* Away from the ends (0.5 s margins, beyond the range where the odd-reflection padding still shows,
  see the module docstring) the result must agree with the gain-corrected derivatives within that
  spline bound, and with the unfiltered analytic derivatives within Σ (1 - G_k) A_k ω_k^r plus it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from core.errors import InputError
from biomech.kinematics import butterworth_gain, lowpass_filter, odd_reflection_pad, process_coordinates
from biomech.storage import read_storage
from core.paths import data_path

FS = 60.0
T = np.arange(151) / FS
H = 1.0 / FS
AMPS, FREQS, PHASES, OFFSET = (0.3, 0.1), (1.0, 2.0), (0.2, 1.0), 0.1
INTERIOR = (T >= 0.5) & (T <= T[-1] - 0.5)


def analytic(t, r, *, cutoff=None, order=2):
    """r-th derivative of the test signal, each component times G(f) if a cut-off is given."""
    out = np.full_like(t, OFFSET if r == 0 else 0.0)
    for a, f, ph in zip(AMPS, FREQS, PHASES):
        w = 2 * np.pi * f
        g = 1.0 if cutoff is None else float(butterworth_gain(f, cutoff, FS, order))
        out += g * a * w**r * np.sin(w * t + ph + r * np.pi / 2)
    return out


def spline_bound(r):
    return H ** (6 - r) * sum(a * (2 * np.pi * f) ** 6 for a, f in zip(AMPS, FREQS))


def motion(extra=None):
    q = analytic(T, 0) + (0.0 if extra is None else extra)
    df = pd.DataFrame({"time": T, "q": q})
    df.attrs["units"] = {"time": "s", "q": "rad"}
    return df


@pytest.mark.parametrize("order", [2, 3])
def test_sum_of_sines_below_the_cutoff_comes_back_with_its_derivatives(order):
    k = process_coordinates(motion(), cutoff=6.0, order=order)
    for r, frame in enumerate((k.q, k.qdot, k.qddot)):
        got = frame["q"].to_numpy()[INTERIOR]
        filtered = analytic(T, r, cutoff=6.0, order=order)[INTERIOR]
        assert np.max(np.abs(got - filtered)) <= spline_bound(r), r
        attenuation = sum((1 - float(butterworth_gain(f, 6.0, FS, order))) * a * (2 * np.pi * f) ** r
                          for a, f in zip(AMPS, FREQS))
        assert np.max(np.abs(got - analytic(T, r)[INTERIOR])) <= attenuation + spline_bound(r), r
    assert k.qdot.attrs["units"]["q"] == "rad/s" and k.qddot.attrs["units"]["q"] == "rad/s^2"
    assert k.settings["effective_order"] == 2 * order and k.settings["pad"] == 75


def test_a_frequency_far_above_the_cutoff_is_attenuated():
    """25 Hz noise of amplitude 0.05 rad: G(25 Hz) = 5.7e-5 for N = 2, so at most 2.9e-6 rad remains
    in q; in q̈ the raw noise amplitude ω²A = 1234 rad/s² drops by more than four orders."""
    a, f = 0.05, 25.0
    noise = a * np.sin(2 * np.pi * f * T + 0.3)
    g = float(butterworth_gain(f, 6.0, FS, 2))
    k = process_coordinates(motion(noise), cutoff=6.0)
    residual_q = k.q["q"].to_numpy()[INTERIOR] - analytic(T, 0, cutoff=6.0)[INTERIOR]
    assert np.max(np.abs(residual_q)) <= g * a + spline_bound(0)
    residual_qdd = k.qddot["q"].to_numpy()[INTERIOR] - analytic(T, 2, cutoff=6.0)[INTERIOR]
    assert np.max(np.abs(residual_qdd)) < 1e-4 * a * (2 * np.pi * f) ** 2
    # lowpass_filter alone: same gain
    y = lowpass_filter(noise, FS, 6.0)
    assert np.max(np.abs(y[INTERIOR])) <= g * a * 1.01


def test_filter_passes_constants_and_lines_and_padding_is_an_odd_reflection():
    x = np.array([1.0, 2.0, 4.0, 7.0])
    np.testing.assert_array_equal(odd_reflection_pad(x, 2), [-2.0, 0.0, 1.0, 2.0, 4.0, 7.0, 10.0, 12.0])
    ramp = 0.3 + 0.8 * T
    np.testing.assert_allclose(lowpass_filter(ramp, FS, 6.0), ramp, rtol=0, atol=1e-9)
    np.testing.assert_allclose(lowpass_filter(np.full(50, 2.0), FS, 6.0), 2.0, rtol=0, atol=1e-12)


def test_without_filter_the_spline_interpolates_the_samples():
    m = motion()
    k = process_coordinates(m, cutoff=None)
    np.testing.assert_allclose(k.q["q"], m["q"], rtol=0, atol=1e-12)
    assert k.settings["pad"] == 0 and k.settings["order_per_pass"] is None


def test_bad_inputs_are_refused():
    m = motion()
    with pytest.raises(InputError, match=r"cut-off 30\.0 Hz must lie between 0 and the Nyquist frequency 30 Hz"):
        process_coordinates(m, cutoff=30.0)
    uneven = m.copy()
    uneven.loc[40, "time"] += 0.004
    with pytest.raises(InputError, match=r"uniformly spaced samples"):
        process_coordinates(uneven)
    with pytest.raises(InputError, match="spline_degree must be 3 or 5"):
        process_coordinates(m, spline_degree=4)
    bad = m.copy()
    bad.loc[7, "q"] = np.nan
    with pytest.raises(InputError, match=r"column 'q' is nan at t = 0\.1166"):
        process_coordinates(bad)


def test_the_gait10dof_trial():
    ik = read_storage(data_path("biomech", "opensim", "gait10dof18musc_subject01_walk", "subject01_walk_IK.mot"))
    k = process_coordinates(ik)
    assert list(k.qddot.columns) == list(ik.columns) and len(k.q) == len(ik)
    assert all(np.all(np.isfinite(f.to_numpy())) for f in (k.q, k.qdot, k.qddot))
    assert k.qdot.attrs["units"]["pelvis_tx"] == "m/s" and k.qddot.attrs["units"]["knee_angle_r"] == "rad/s^2"
    # a 6 Hz filter changes a walking motion little: every angle within 2 degrees of the IK values
    # (the largest change, 1.8 degrees, is at the ankle around toe-off)
    angles = [c for c in ik.columns[1:] if not c.endswith(("_tx", "_ty"))]
    assert np.max(np.abs(k.q[angles].to_numpy() - ik[angles].to_numpy())) < np.deg2rad(2.0)
    # q̇ is the derivative of q: central differences of the filtered q agree to O(h²·max|q⃛|)
    q = k.q["knee_angle_r"].to_numpy()
    qd = k.qdot["knee_angle_r"].to_numpy()
    jerk = np.max(np.abs(np.diff(k.qddot["knee_angle_r"].to_numpy()))) / H
    fd = (q[2:] - q[:-2]) / (2 * H)
    assert np.max(np.abs(fd - qd[1:-1])) <= H**2 / 6 * jerk * 1.5
