"""Ride comfort (railway.comfort): frequency weightings, weighted acceleration, EN 12299 N_MV, Sperling.

Oracles, each independent of the module's code:

* published weighting factors: ISO 2631-1:1997 Tables 3/4 (W_k, W_d, W_c) as transcribed in three
  public code files that agree, and ISO 8041 reference values at 100 rad/s (W_b, W_c, W_d) quoted
  by a vendor page -- data/railway/iso2631_weighting_factors.csv, whose header names the sources;
* the BS 6841 form of W_b (K = 0.4, step normalised to 1 at DC) and the band-limiting filters,
  typed again here in complex arithmetic;
* a sine's r.m.s. A/sqrt(2) |W(j 2 pi f)| and its steady-state phase (analogue filter theory);
* Sperling's formulas (S1)-(S3) typed again here from the project notes, section 6.

Tolerances are stated at each test with the error they allow for.
"""

import numpy as np
import pandas as pd
import pytest
from scipy import signal

from core.errors import InputError
from core.paths import data_path
from railway.comfort import (
    EN12299_SCALE,
    SPERLING_COMFORT_SCALE,
    SPERLING_QUALITY_SCALE,
    WEIGHTING_NAMES,
    en12299_scale,
    frequency_weighting,
    mean_comfort,
    sperling,
    sperling_correction,
    sperling_harmonic,
    sperling_scale,
    sperling_scales,
    sperling_weighting,
    weighted_acceleration,
    weighting_gain,
    weighting_response,
)

TWO_PI = 2.0 * np.pi


# ------------------------------------------------------------------------------------------
# independent evaluations used as oracles
# ------------------------------------------------------------------------------------------

def band_limit(f, q):
    """H_h H_l of ISO 2631-1 Annex A at f (Hz): 0.4 Hz high-pass, 100 Hz low-pass, both of quality q."""
    s = 1j * TWO_PI * np.asarray(f, dtype=float)
    w1, w2 = TWO_PI * 0.4, TWO_PI * 100.0
    return (s ** 2 / (s ** 2 + s * w1 / q + w1 ** 2)) * (w2 ** 2 / (s ** 2 + s * w2 / q + w2 ** 2))


def iso_weighting(name, f, q):
    """|W| of the ISO 2631-1 Annex A product with band-limiting quality q (test's own copy)."""
    s = 1j * TWO_PI * np.asarray(f, dtype=float)
    f3, f4, q4, step = {"Wk": (12.5, 12.5, 0.63, (2.37, 0.91, 3.35, 0.91)),
                        "Wd": (2.0, 2.0, 0.63, None), "Wc": (8.0, 8.0, 0.63, None)}[name]
    w3, w4 = TWO_PI * f3, TWO_PI * f4
    h = band_limit(f, q) * (1 + s / w3) / (1 + s / (q4 * w4) + (s / w4) ** 2)
    if step:
        w5, q5, w6, q6 = TWO_PI * step[0], step[1], TWO_PI * step[2], step[3]
        h = h * (s ** 2 + s * w5 / q5 + w5 ** 2) / (s ** 2 + s * w6 / q6 + w6 ** 2)
    return np.abs(h)


def load_table():
    path = data_path("railway", "iso2631_weighting_factors.csv")
    df = pd.read_csv(path, comment="#", dtype={"factor_x1000": str})
    printed = df["factor_x1000"]
    df["value"] = printed.astype(float) / 1000.0
    decimals = printed.map(lambda t: len(t.split(".")[1]) if "." in t else 0)
    df["unit"] = 10.0 ** (-decimals.astype(float)) / 1000.0     # one unit of the last printed digit
    return df


#: table entries that are not within half a unit of the Annex A formula (measured, documented in the
#: CSV header and railway.comfort): (weighting, nominal f) -> (min, max) deviation in last-digit units
KNOWN_DEVIATIONS = {
    ("Wd", 10.0): (-10.6, -10.0),   # table 212, formula 201.7 (neighbours' geometric mean 201.8): misprint
    ("Wk", 1.25): (0.5, 0.6),       # table 484, formula 484.55: the table rounded the other way
    ("Wk", 16.0): (0.5, 0.75),      # table 768, formula 768.70
}


# ------------------------------------------------------------------------------------------
# names, shapes, the zpk form
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("spelling", ["Wb", "W_b", "wb", "W b", "WB", " w-b "])
def test_weighting_names_are_normalised(spelling):
    f = np.array([0.5, 4.0, 20.0])
    np.testing.assert_allclose(weighting_gain(spelling, f), weighting_gain("Wb", f), rtol=1e-15)


@pytest.mark.parametrize("bad", ["Wz", "Wbb", "", 3, None])
def test_unknown_weighting_lists_the_valid_names(bad):
    with pytest.raises(InputError) as e:
        weighting_gain(bad, 1.0)
    msg = str(e.value)
    assert repr(bad) in msg and "Wb, Wc, Wd, Wk" in msg


def test_weighting_gain_is_vectorised_and_refuses_bad_frequencies():
    f = np.array([[0.5, 1.0, 2.0], [4.0, 8.0, 16.0]])
    g = weighting_gain("Wd", f)
    assert g.shape == (2, 3)
    np.testing.assert_allclose(g.ravel(), [weighting_gain("Wd", x) for x in f.ravel()], rtol=1e-14)
    with pytest.raises(InputError, match=r"f\[1\] = -2.0 Hz"):
        weighting_gain("Wd", [1.0, -2.0])
    with pytest.raises(InputError, match="nan"):
        weighting_gain("Wk", np.nan)


@pytest.mark.parametrize("name", WEIGHTING_NAMES)
def test_zpk_and_polynomial_forms_equal_the_factor_form(name):
    """scipy's evaluation of the zeros/poles/gain and of the expanded polynomials against the
    factor-by-factor product; rtol 1e-9 for the polynomial roots and 1e-7 for the expanded
    polynomials (coefficients spanning 13 decades lose digits in the sums)."""
    w = frequency_weighting(name)
    f = np.logspace(-1.5, 2.7, 300)
    ref = weighting_response(name, f)
    _, h_zpk = signal.freqs_zpk(w.zeros, w.poles, w.gain, worN=TWO_PI * f)
    np.testing.assert_allclose(h_zpk, ref, rtol=1e-9)
    b, a = w.ba
    _, h_ba = signal.freqs(b, a, worN=TWO_PI * f)
    np.testing.assert_allclose(h_ba, ref, rtol=1e-7)
    assert w.slowest_decay_rate == pytest.approx(TWO_PI * 0.4 / (2.0 / np.sqrt(2.0)), rel=1e-12)


# ------------------------------------------------------------------------------------------
# validation against published factors
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name, n_bands", [("Wk", 37), ("Wd", 37), ("Wc", 30)])
def test_weightings_match_iso2631_tables_to_their_rounding(name, n_bands):
    """ISO 2631-1 Table 3 (W_k, W_d) and Table 4 (W_c) at the nominal band frequencies.  The table
    prints 3 significant figures (in units of 1/1000); a value rounded from the formula is within
    half a unit of its last printed digit, so that is the tolerance -- except the three
    entries of KNOWN_DEVIATIONS, whose measured deviation is asserted instead (so a corrected
    transcription or a change of the filter shows here).  Measured largest |deviation| elsewhere:
    0.48 units (W_k), 0.46 (W_d), 0.47 (W_c)."""
    df = load_table()
    rows = df[(df["weighting"] == name) & df["table"].str.startswith("ISO 2631-1")]
    assert len(rows) == n_bands
    f = rows["f_nominal_Hz"].to_numpy()
    dev = (weighting_gain(name, f) - rows["value"].to_numpy()) / rows["unit"].to_numpy()
    ordinary = np.ones(len(f), dtype=bool)
    for (wname, fk), (lo, hi) in KNOWN_DEVIATIONS.items():
        if wname == name:
            (i,) = np.flatnonzero(np.isclose(f, fk))
            ordinary[i] = False
            assert lo <= dev[i] <= hi, (fk, dev[i])
    assert np.max(np.abs(dev[ordinary])) <= 0.5, dict(zip(f[ordinary], dev[ordinary].round(2)))


def test_rounded_band_limit_quality_misses_the_tables():
    """Why Q_1 = Q_2 = 1/sqrt(2) and not the 0.71 printed in the notes: with 0.71 (test's own
    evaluation) a dozen bands of each weighting miss the table by more than half a unit, up to
    3.9 units; with 1/sqrt(2) the same evaluation matches the module."""
    df = load_table()
    for name in ("Wk", "Wd", "Wc"):
        rows = df[(df["weighting"] == name) & df["table"].str.startswith("ISO 2631-1")]
        f = rows["f_nominal_Hz"].to_numpy()
        np.testing.assert_allclose(iso_weighting(name, f, 1 / np.sqrt(2)), weighting_gain(name, f),
                                   rtol=1e-13)
        dev071 = (iso_weighting(name, f, 0.71) - rows["value"].to_numpy()) / rows["unit"].to_numpy()
        off = np.abs(dev071) > 0.5
        off[np.isclose(f, 10.0) & (name == "Wd")] = False      # the misprint misses with either Q
        assert off.sum() >= 12, (name, off.sum())


def test_iso8041_reference_values_at_100_rad_per_s():
    """W_b, W_c, W_d at 100 rad/s against the ISO 8041 values (4 significant figures, quoted by a
    vendor page): within half a unit of the 4th figure, 5e-5.  Measured: 0.81256, 0.51445, 0.12608."""
    df = load_table()
    rows = df[df["table"].str.startswith("ISO 8041")]
    assert set(rows["weighting"]) == {"Wb", "Wc", "Wd"}
    for _, r in rows.iterrows():
        got = float(weighting_gain(r["weighting"], 100.0 / TWO_PI))
        assert abs(got - r["value"]) <= 0.5 * r["unit"] + 1e-12, (r["weighting"], got, r["value"])


def test_wb_equals_the_bs6841_form():
    """The notes' trap: BS 6841 writes the step normalised to 1 at DC and K = 0.4; ISO 2631-4 writes
    it tending to 1 at high frequency and K = 1.024.  The BS 6841 form (parameters as in the public
    bs6841freqweight.m of cseats/Footfall_app_data), typed here, times the band limits must equal
    the module's W_b to rounding (rtol 1e-12)."""
    assert 0.4 * (4.0 / 2.5) ** 2 == pytest.approx(1.024, rel=1e-15)
    f = np.logspace(-1, 2.6, 400)
    s = 1j * TWO_PI * f
    w3 = w4 = TWO_PI * 16.0
    w5, w6 = TWO_PI * 2.5, TWO_PI * 4.0
    transition = (1 + s / w3) / (1 + s / (0.55 * w4) + (s / w4) ** 2)
    step_dc1 = (1 + s / (0.90 * w5) + (s / w5) ** 2) / (1 + s / (0.95 * w6) + (s / w6) ** 2)
    bs6841 = 0.4 * transition * step_dc1 * band_limit(f, 1 / np.sqrt(2))
    np.testing.assert_allclose(weighting_response("Wb", f), bs6841, rtol=1e-12)


# ------------------------------------------------------------------------------------------
# weighted acceleration
# ------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", WEIGHTING_NAMES)
def test_weighted_sine_is_the_analogue_steady_state(name):
    """Periodic mode, a sine with a whole number of periods in the record (20 s at 200 Hz; every f
    below is a multiple of 0.05 Hz): the output is exactly A |W| sin(2 pi f t + arg W), so its
    r.m.s. is A/sqrt(2) |W(j 2 pi f)|.  The only error is FFT rounding, ~eps log2(N) ~ 1e-14
    relative; tolerance 1e-11 relative (r.m.s.) and 1e-11 A (samples)."""
    fs, T, A = 200.0, 20.0, 0.7
    t = np.arange(int(T * fs)) / fs
    for f in (0.5, 1.0, 2.5, 4.0, 8.0, 16.0, 31.5, 63.0):
        aw = weighted_acceleration(A * np.sin(TWO_PI * f * t), fs, name)
        W = complex(weighting_response(name, f))
        assert np.sqrt(np.mean(aw ** 2)) == pytest.approx(A / np.sqrt(2) * abs(W), rel=1e-11)
        np.testing.assert_allclose(aw, A * abs(W) * np.sin(TWO_PI * f * t + np.angle(W)),
                                   atol=1e-11 * A, rtol=0)


def test_weighted_sine_from_rest_settles_to_the_steady_state():
    """From-rest mode: the analogue filter switched on at the first sample.  The sine is given
    smooth ends (2 s cosine tapers), so the band-limited ringing of a cut-off record (module
    docstring: 1e-3 near a hard end) is absent and what remains is the start-up transient, which
    decays at least as fast as exp(-1.777 t) (the 0.4 Hz high-pass poles, the slowest): from 12 s
    on that is 5e-10 of a transient of order A.  Between 12 s and the start of the end taper the
    samples must equal the steady state A |W| sin(2 pi f t + arg W) to 1e-6 A |W| (measured: below
    2e-9 for f <= 16 Hz, 1.5e-7 at 63 Hz).  The filter is causal: the end taper does not reach back."""
    fs, T, A, taper = 200.0, 40.0, 1.3, 2.0
    t = np.arange(int(T * fs)) / fs
    env = np.ones_like(t)
    env[t < taper] = 0.5 - 0.5 * np.cos(np.pi * t[t < taper] / taper)
    env[t > T - taper] = 0.5 - 0.5 * np.cos(np.pi * (T - t[t > T - taper]) / taper)
    inner = (t >= 12.0) & (t <= T - taper)
    for name, f in (("Wb", 1.0), ("Wb", 4.0), ("Wd", 0.5), ("Wk", 16.0), ("Wb", 63.0)):
        aw = weighted_acceleration(A * env * np.sin(TWO_PI * f * t), fs, name, mode="from_rest")
        W = complex(weighting_response(name, f))
        np.testing.assert_allclose(aw[inner], A * abs(W) * np.sin(TWO_PI * f * t[inner] + np.angle(W)),
                                   atol=1e-6 * A * abs(W), rtol=0)


def test_weighted_acceleration_works_row_by_row():
    rng = np.random.default_rng(7)
    a = rng.standard_normal((3, 1000))
    both = weighted_acceleration(a, 100.0, "Wd", mode="from_rest")
    for k in range(3):
        np.testing.assert_allclose(both[k], weighted_acceleration(a[k], 100.0, "Wd", mode="from_rest"),
                                   rtol=1e-12, atol=1e-14)


def test_weighted_acceleration_refuses_bad_input():
    a = np.zeros(100)
    for fs in (0.0, -200.0, np.nan, "fast"):
        with pytest.raises(InputError, match="sampling frequency fs"):
            weighted_acceleration(a, fs, "Wb")
    b = a.copy()
    b[17] = np.nan
    with pytest.raises(InputError, match=r"a\[17\] = nan"):
        weighted_acceleration(b, 100.0, "Wb")
    with pytest.raises(InputError, match="did you mean 'periodic'"):
        weighted_acceleration(a, 100.0, "Wb", mode="perodic")
    with pytest.raises(InputError, match="at least 2 samples"):
        weighted_acceleration([1.0], 100.0, "Wb")
    with pytest.raises(InputError, match="valid names"):
        weighted_acceleration(a, 100.0, "Wq")


# ------------------------------------------------------------------------------------------
# EN 12299 mean comfort
# ------------------------------------------------------------------------------------------

def sine(f, A, T=60.0, fs=200.0):
    t = np.arange(int(round(T * fs))) / fs
    return A * np.sin(TWO_PI * f * t)


def test_mean_comfort_of_a_vertical_sine():
    """z only, 4 Hz (20 periods per 5 s block), 60 s at 200 Hz: every block r.m.s. is
    A/sqrt(2) |W_b(4 Hz)|, so N_MV = 6 A/sqrt(2) |W_b|; exact up to FFT rounding (rtol 1e-10)."""
    A, f = 0.3, 4.0
    z = sine(f, A)
    r = mean_comfort(np.zeros_like(z), np.zeros_like(z), z, 200.0)
    expected = 6.0 * A / np.sqrt(2) * float(weighting_gain("Wb", f))
    assert r["N_MV [-]"] == pytest.approx(expected, rel=1e-10)
    assert r["a_ZP95 Wb [m/s2]"] == pytest.approx(A / np.sqrt(2) * float(weighting_gain("Wb", f)), rel=1e-10)
    assert r["a_XP95 Wd [m/s2]"] == 0.0 and r["a_YP95 Wd [m/s2]"] == 0.0
    assert r["blocks used"] == 12 and r["block [s]"] == 5.0 and r["record [s]"] == 60.0
    assert r["samples not used"] == 0 and r["5 min record (60 blocks)"] is False
    assert r["directions"] == "x, y, z"
    assert r["comfort (EN 12299 scale)"] == en12299_scale(expected)
    assert list(r.attrs["block_rms"].columns) == ["t_start [s]", "a_x_rms [m/s2]", "a_y_rms [m/s2]",
                                                  "a_z_rms [m/s2]"]
    assert "N_MV" in r.to_frame().to_markdown()


def test_mean_comfort_combines_three_axes_and_lateral_vertical_only():
    """x 1 Hz and y 2 Hz with W_d, z 8 Hz with W_b (all whole periods per block): N_MV is 6 times
    the root sum of squares of the three r.m.s. values (rtol 1e-10); with ax=None the x term is
    left out and the result says so."""
    x, y, z = sine(1.0, 0.2), sine(2.0, 0.25), sine(8.0, 0.4)
    ax_ = 0.2 / np.sqrt(2) * float(weighting_gain("Wd", 1.0))
    ay_ = 0.25 / np.sqrt(2) * float(weighting_gain("Wd", 2.0))
    az_ = 0.4 / np.sqrt(2) * float(weighting_gain("Wb", 8.0))
    r = mean_comfort(x, y, z, 200.0)
    assert r["N_MV [-]"] == pytest.approx(6.0 * np.sqrt(ax_ ** 2 + ay_ ** 2 + az_ ** 2), rel=1e-10)
    r2 = mean_comfort(None, y, z, 200.0)
    assert r2["N_MV [-]"] == pytest.approx(6.0 * np.sqrt(ay_ ** 2 + az_ ** 2), rel=1e-10)
    assert np.isnan(r2["a_XP95 Wd [m/s2]"]) and "y, z only" in r2["directions"]
    assert list(r2.attrs["block_rms"].columns) == ["t_start [s]", "a_y_rms [m/s2]", "a_z_rms [m/s2]"]
    # ax of zeros gives the same N_MV as leaving it out
    r3 = mean_comfort(np.zeros_like(y), y, z, 200.0)
    assert r3["N_MV [-]"] == pytest.approx(r2["N_MV [-]"], rel=1e-14)


def test_five_minute_record_is_sixty_blocks_and_p95_is_over_them():
    """A 5 min random record (plus 1.3 s left over): 60 blocks, the flag set, the left-over
    samples reported; each block r.m.s. equals the one computed here from the weighted signal,
    and each P95 is numpy's 95th percentile of them (both to rounding)."""
    fs = 100.0
    rng = np.random.default_rng(12299)
    x, y, z = rng.standard_normal((3, int(301.3 * fs))) * np.array([[0.1], [0.2], [0.3]])
    r = mean_comfort(x, y, z, fs)
    assert r["blocks used"] == 60 and r["5 min record (60 blocks)"] is True
    assert r["samples not used"] == 130
    blocks = r.attrs["block_rms"]
    zw = weighted_acceleration(z, fs, "Wb")
    own = np.sqrt(np.mean(zw[:60 * 500].reshape(60, 500) ** 2, axis=1))
    np.testing.assert_allclose(blocks["a_z_rms [m/s2]"], own, rtol=1e-13)
    for col, key in (("a_x_rms [m/s2]", "a_XP95 Wd [m/s2]"), ("a_y_rms [m/s2]", "a_YP95 Wd [m/s2]"),
                     ("a_z_rms [m/s2]", "a_ZP95 Wb [m/s2]")):
        assert r[key] == pytest.approx(np.percentile(blocks[col], 95), rel=1e-14)
    np.testing.assert_allclose(blocks["t_start [s]"], np.arange(60) * 5.0)


def test_record_shorter_than_one_block_is_refused():
    z = sine(4.0, 0.3, T=4.9)
    with pytest.raises(InputError, match=r"980 samples \(4.9 s\) is shorter than one block of 5 s"):
        mean_comfort(None, z, z, 200.0)


def test_mean_comfort_refuses_bad_input():
    z = sine(4.0, 0.3, T=10.0)
    for fs in (0.0, -1.0):
        with pytest.raises(InputError, match=f"fs = {fs!r} Hz"):
            mean_comfort(z, z, z, fs)
    bad = z.copy()
    bad[7] = np.nan
    with pytest.raises(InputError, match=r"ay\[7\] = nan"):
        mean_comfort(z, bad, z, 200.0)
    with pytest.raises(InputError, match="different lengths"):
        mean_comfort(z, z[:-1], z, 200.0)
    with pytest.raises(InputError, match="block = 0.0 s"):
        mean_comfort(z, z, z, 200.0, block=0.0)
    with pytest.raises(InputError, match="az is None"):
        mean_comfort(z, z, None, 200.0)
    with pytest.raises(InputError, match="one-dimensional"):
        mean_comfort(None, np.vstack([z, z]), np.vstack([z, z]), 200.0)


def test_en12299_scale_boundaries():
    n = [0.0, 0.999, 1.0, 1.999, 2.0, 3.999, 4.0, 4.999, 5.0, 7.0]
    expected = ["very comfortable"] * 2 + ["comfortable"] * 2 + ["medium"] * 2 + \
               ["uncomfortable"] * 2 + ["very uncomfortable"] * 2
    assert list(en12299_scale(n)) == expected
    assert en12299_scale(1.5) == "comfortable"
    assert [b for b, _ in EN12299_SCALE][:4] == [1.0, 2.0, 4.0, 5.0]
    with pytest.raises(InputError):
        en12299_scale(-1.0)


# ------------------------------------------------------------------------------------------
# Sperling
# ------------------------------------------------------------------------------------------

def F_notes(f, direction):
    """(S2) typed from the notes; break frequencies to the upper piece."""
    f = np.asarray(f, dtype=float)
    if direction == "vertical":
        return np.where(f < 5.9, 0.325 * f ** 2, np.where(f < 20, 400 / f ** 2, 1.0))
    return np.where(f < 5.4, 0.8 * f ** 2, np.where(f < 26, 650 / f ** 2, 1.0))


def B_notes(f, direction):
    """(S3) typed from the notes."""
    f = np.asarray(f, dtype=float)
    bv = 0.588 * np.sqrt((1.911 * f ** 2 + (0.25 * f ** 2) ** 2)
                         / ((1 - 0.277 * f ** 2) ** 2 + (1.563 * f - 0.0368 * f ** 3) ** 2))
    return bv if direction == "vertical" else 1.25 * bv


def expected_ratio(f, a_peak, direction, c):
    """(S4)/(S1) for a sine of peak a_peak (m/s^2): (c B^2 a^2/2)^(1/6.67) / (0.896 (a^3 F/f)^0.1)."""
    a = 100.0 * a_peak
    return (c * B_notes(f, direction) ** 2 * a ** 2 / 2) ** (1 / 6.67) / (
        0.896 * (a ** 3 * F_notes(f, direction) / f) ** 0.1)


def test_sperling_harmonic_formula():
    """(S1) at hand-evaluated points, a given in m/s^2 and converted to cm/s^2 inside."""
    assert sperling_harmonic(0.1, 1.0, "vertical") == pytest.approx(0.896 * (10.0 ** 3 * 0.325) ** 0.1,
                                                                    rel=1e-14)
    assert sperling_harmonic(0.5, 10.0, "lateral") == pytest.approx(
        0.896 * (50.0 ** 3 * 6.5 / 10.0) ** 0.1, rel=1e-14)
    assert sperling_harmonic(0.2, 30.0, "horizontal") == pytest.approx(
        0.896 * (20.0 ** 3 / 30.0) ** 0.1, rel=1e-14)
    w = sperling_harmonic([[0.1], [0.2]], [1.0, 2.0, 8.0], "vertical")
    assert w.shape == (2, 3)


def test_sperling_correction_pieces_and_their_jumps():
    """(S2) as typed from the notes; the quoted pieces do not join (documented in the module):
    F_v jumps by 1.6 % at 5.9 Hz, F_h by -4.4 % at 5.4 Hz and by +4 % at 26 Hz."""
    f = np.array([0.5, 1, 3, 5.4, 5.8999, 5.9, 10, 19.99, 20, 25.99, 26, 40])
    for d in ("vertical", "lateral"):
        np.testing.assert_allclose(sperling_correction(f, d), F_notes(f, d), rtol=1e-15)
    eps = 1e-9
    jump_v = sperling_correction(5.9, "vertical") / sperling_correction(5.9 - eps, "vertical")
    jump_h = sperling_correction(5.4, "lateral") / sperling_correction(5.4 - eps, "lateral")
    jump_h26 = sperling_correction(26.0, "lateral") / sperling_correction(26.0 - eps, "lateral")
    assert jump_v == pytest.approx(400 / (0.325 * 5.9 ** 4), rel=1e-8) and 1.015 < jump_v < 1.017
    assert jump_h == pytest.approx(650 / (0.8 * 5.4 ** 4), rel=1e-8) and 0.955 < jump_h < 0.956
    assert jump_h26 == pytest.approx(676 / 650, rel=1e-8)
    with pytest.raises(InputError, match="below 0.5 Hz"):
        sperling_correction(0.3, "vertical")


def test_sperling_weighting_is_the_notes_formula():
    f = np.logspace(-1, 2, 50)
    for d in ("vertical", "lateral"):
        np.testing.assert_allclose(sperling_weighting(f, d), B_notes(f, d), rtol=1e-14)


SINE_FREQUENCIES = (0.5, 0.8, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 5.9, 8.0, 10.0, 15.0, 20.0)


@pytest.mark.parametrize("direction", ["vertical", "lateral"])
@pytest.mark.parametrize("normalisation, c", [("peak", 2.0), ("mean-square", 1.0)])
def test_spectral_form_of_a_sine_is_its_analytic_value(direction, normalisation, c):
    """A sine of peak 1 m/s^2 on a periodogram bin (20 s at 200 Hz, df = 0.05 Hz): the one-sided
    periodogram holds exactly a^2/2 in that bin, so (S4) = (c B(f)^2 a^2/2)^(1/6.67) up to FFT
    rounding (rtol 1e-10), i.e. the spectral/harmonic ratio is exactly expected_ratio."""
    fs, T, a = 200.0, 20.0, 1.0
    t = np.arange(int(T * fs)) / fs
    for f in SINE_FREQUENCIES:
        wz = sperling(a * np.sin(TWO_PI * f * t), fs, direction, normalisation=normalisation)
        assert wz == pytest.approx((c * B_notes(f, direction) ** 2 * (100 * a) ** 2 / 2) ** (1 / 6.67),
                                   rel=1e-10)
        ratio = wz / float(sperling_harmonic(a, f, direction))
        assert ratio == pytest.approx(expected_ratio(f, a, direction, c), rel=1e-10)


def test_spectral_and_harmonic_forms_agree_where_b_fits_f():
    """How far (S4) (c = 2) and (S1) may differ follows from how well B(f)^2 reproduces
    2 * 0.896^(20/3) (F(f)/f)^(2/3) -- expected_ratio, computed from the formulas and checked
    against the module above.  Measured (a = 1 m/s^2):

        vertical: 0.5 Hz 0.965 | 0.8-5 Hz 0.998..1.008 | 5.9 Hz 0.975 | 8 Hz 1.000 | 10 Hz 0.989 |
                  15 Hz 0.961 | 20 Hz 0.948
        lateral:  0.5 Hz 0.943 | 0.8-5 Hz 0.976..0.985 | 5.9 Hz 0.993 | 8 Hz 1.018 | 10 Hz 1.007 |
                  15 Hz 0.979 | 20 Hz 0.965

    So they agree to 1 % vertically at 0.8-5 Hz and 8 Hz, and to 2.5 % laterally at 0.8-15 Hz.
    They disagree by 2.5-6 % at 0.5 Hz (3.5 % vertical, 5.7 % lateral), at 5.9 Hz vertically
    (2.5 %), at 15-20 Hz vertically (3.9-5.2 %) and at 20 Hz laterally (3.5 %): asserted below as
    documented disagreements, not as agreement.  With c = 1 (the literal mean-square PSD) every
    ratio is 2^(-1/6.67) = 0.901 times these."""
    a = 1.0
    for f in (0.8, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 8.0):
        assert abs(expected_ratio(f, a, "vertical", 2.0) - 1) <= 0.01, f
    for f in (0.8, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 5.9, 8.0, 10.0, 15.0):
        assert abs(expected_ratio(f, a, "lateral", 2.0) - 1) <= 0.025, f
    # the documented disagreements
    assert expected_ratio(0.5, a, "vertical", 2.0) < 0.97 and expected_ratio(0.5, a, "lateral", 2.0) < 0.95
    assert expected_ratio(5.9, a, "vertical", 2.0) < 0.98
    assert expected_ratio(15.0, a, "vertical", 2.0) < 0.965 and expected_ratio(20.0, a, "vertical", 2.0) < 0.95
    assert expected_ratio(20.0, a, "lateral", 2.0) < 0.97
    f = np.array(SINE_FREQUENCIES)
    np.testing.assert_allclose(expected_ratio(f, a, "vertical", 1.0) / expected_ratio(f, a, "vertical", 2.0),
                               2 ** (-1 / 6.67), rtol=1e-13)


def test_sperling_of_two_harmonics_adds_powers():
    """(S4) is a power sum: two harmonics on bins give (c sum B_i^2 a_i^2/2)^(1/6.67) (rtol 1e-10)."""
    fs, T = 200.0, 20.0
    t = np.arange(int(T * fs)) / fs
    a1, f1, a2, f2 = 0.3, 1.0, 0.5, 6.0
    x = a1 * np.sin(TWO_PI * f1 * t) + a2 * np.cos(TWO_PI * f2 * t)
    expected = (2.0 * (B_notes(f1, "lateral") ** 2 * (100 * a1) ** 2
                       + B_notes(f2, "lateral") ** 2 * (100 * a2) ** 2) / 2) ** (1 / 6.67)
    assert sperling(x, fs, "lateral") == pytest.approx(expected, rel=1e-10)
    both = sperling(np.vstack([x, 2 * x]), fs, "lateral")
    assert both.shape == (2,) and both[0] == pytest.approx(expected, rel=1e-10)


def test_sperling_refuses_bad_input():
    fs = 200.0
    x = np.sin(TWO_PI * np.arange(4000) / fs)
    with pytest.raises(InputError, match=r"direction 'vertcal'.*did you mean 'vertical'"):
        sperling(x, fs, "vertcal")
    with pytest.raises(InputError, match="direction"):
        sperling_harmonic(1.0, 1.0, "longitudinal")
    with pytest.raises(InputError, match="Nyquist"):
        sperling(x, 40.0, "vertical")
    with pytest.raises(InputError, match="cannot resolve"):
        sperling(x[:300], fs, "vertical")
    with pytest.raises(InputError, match="normalisation 'rms'"):
        sperling(x, fs, "vertical", normalisation="rms")
    with pytest.raises(InputError, match="fs = 0.0 Hz"):
        sperling(x, 0.0, "vertical")
    y = x.copy()
    y[3] = np.inf
    with pytest.raises(InputError, match=r"a\[3\] = inf"):
        sperling(y, fs, "lateral")
    with pytest.raises(InputError, match="band"):
        sperling(x, fs, "vertical", band=(5.0, 1.0))


def test_sperling_scales_as_data_and_lookup():
    assert [v for v, _ in SPERLING_COMFORT_SCALE] == [1.0, 2.0, 2.5, 3.0, 3.25, 3.5, 4.0]
    assert [v for v, _ in SPERLING_QUALITY_SCALE] == [1.0, 2.0, 3.0, 4.0, 4.5, 5.0]
    assert sperling_scale(2.0) == "2 (clearly noticeable)"
    assert sperling_scale(2.2) == ("between 2 (clearly noticeable) and 2.5 (more pronounced but not "
                                   "unpleasant)")
    assert sperling_scale(0.4).startswith("below 1")
    assert sperling_scale(4.2).startswith("above 4")
    assert sperling_scale(2.5, "quality") == "between 2 (good) and 3 (satisfactory)"
    assert sperling_scale(5.5, "quality") == "above 5 (dangerous)"
    out = sperling_scale([1.0, 3.3])
    assert out.shape == (2,) and out[1].startswith("between 3.25 (very irregular)")
    with pytest.raises(InputError, match="did you mean 'quality'"):
        sperling_scale(2.0, "qualty")
    table = sperling_scales()
    assert len(table) == 13 and list(table.columns) == ["scale", "W_z [-]", "reading"]
