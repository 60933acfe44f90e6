"""Tests of :mod:`coaster.rider`: load factors, jerk, limits as data, time above each level.

Tier 1 (closed forms): n = (0, 0, 1) at rest on level track and (0, sin θ, cos θ) on a level
track banked by θ; a rider offset from the centre of a bead on a horizontal circle feels
n_y = ω² (R − d)/g (the ω × (ω × ρ) term); on a horizontal clothoid at constant speed
jerk_y = v³/(a g) (notes/coaster.md, closed forms).  Durations above a level on synthetic,
piecewise-linear signals, where linear interpolation of the crossings is exact.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from coaster.frames import RotationMinimisingFrame
from coaster.path_joint import PathFollowingJoint
from coaster.rider import (JERK_COLUMNS, LOAD_COLUMNS, exceedances, load_factor, read_acceleration_limits,
                           rider_loads, time_above_limits)
from coaster.track import CircularArc, Clothoid, Straight
from core.errors import DataFileError, InputError, ModelError
from core.model import ModelBuilder
from core.simulation import simulate

G = 9.81
RTOL = 1e-10
K = 1e3  # tolerance factor on rtol: the global error of dop853 stays within 10-100 rtol (see analytic_scene)


def _model(curve, L0=0.0, Ld0=0.0, mass=1.0, inertia=(0.0, 0.0, 0.0)):
    joint = PathFollowingJoint("path", "car", curve, "L")
    r, p, v, w = joint.initial_state(L0, Ld0)
    b = ModelBuilder(3, "rider_test", gravity=(0.0, 0.0, -G))
    b.add_body("car", mass, inertia, r, orientation=p, velocity=v, angular_velocity=w)
    b.add_coordinate("L", L0, Ld0)
    b.add_joint(joint)
    return b.build()


def _run(model, T, n=21):
    res = simulate(model, (0.0, T), "dop853-projection", rtol=RTOL, atol=RTOL, n_output=n)
    assert res.status == "finished", res.message
    return res


@pytest.mark.parametrize("point", [(0.0, 0.0, 0.0), (0.4, -0.3, 0.9)])
def test_at_rest_on_level_track_load_factor_is_0_0_1(point):
    model = _model(RotationMinimisingFrame(Straight(50.0)), L0=10.0, mass=300.0, inertia=(50.0, 80.0, 90.0))
    res = _run(model, 1.0, 5)
    df = rider_loads(model, res, "car", point, coordinate="L")
    assert list(df.columns) == ["t [s]", "L [m]", *LOAD_COLUMNS, *JERK_COLUMNS, "v_P [m/s]"]
    n = df[list(LOAD_COLUMNS)].to_numpy()
    assert np.abs(n - [0.0, 0.0, 1.0]).max() < 1e-12
    assert np.abs(df[list(JERK_COLUMNS)].to_numpy()).max() < 1e-9
    assert np.allclose(df["L [m]"], 10.0) and np.abs(df["v_P [m/s]"]).max() < 1e-12
    assert df.attrs["g_m_s2"] == pytest.approx(G)


def test_at_rest_on_banked_level_track():
    """The rolled frame b = −sin θ u + cos θ v, n = cos θ u + sin θ v: gravity's reaction ẑ has
    car components (0, sin θ, cos θ)."""
    th = 0.3
    model = _model(RotationMinimisingFrame(Straight(50.0), bank=th), L0=5.0)
    n = load_factor(model, 0.0, model.q0, model.v0, "car")
    assert np.abs(n - [0.0, math.sin(th), math.cos(th)]).max() < 1e-12


def test_car_axes_argument_permutes_components():
    th = 0.3
    model = _model(RotationMinimisingFrame(Straight(50.0), bank=th), L0=5.0)
    C = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # car x = body y, y = body z, z = body x
    n = load_factor(model, 0.0, model.q0, model.v0, "car", axes=C)
    assert np.abs(n - [math.sin(th), math.cos(th), 0.0]).max() < 1e-12


def test_rider_offset_on_horizontal_circle_feels_its_own_radius():
    """Bead at 15 m/s on a horizontal circle R = 20 m (turning left), rider at ρ′ = (0.5, d, h):
    a_P = a + ω × (ω × ρ) with ω = v/R ẑ, so n_y = ω² (R − d)/g; the forward offset f adds the
    centripetal part −ω² f along x, n_x = −ω² f/g; n_z = 1 (h is along ω)."""
    R, v, d, h, f = 20.0, 15.0, 0.7, 1.1, 0.5
    model = _model(RotationMinimisingFrame(CircularArc(R, 2 * math.pi), max_step=0.25, tol=1e-12), 0.0, v)
    res = _run(model, 1.0)
    df = rider_loads(model, res, "car", (f, d, h))
    w = v / R
    n = df[list(LOAD_COLUMNS)].to_numpy()
    exact = [-w**2 * f / G, w**2 * (R - d) / G, 1.0]
    q = v**2 / (G * R)
    assert np.abs(n - exact).max() < K * RTOL * (1 + q)
    assert np.abs(df[list(JERK_COLUMNS)].to_numpy()).max() < K * RTOL * (1 + q)
    # the speed of the rider point: ω × (R − d, f) in the plane
    assert np.abs(df["v_P [m/s]"] - w * math.hypot(R - d, f)).max() < K * RTOL * (1 + v)


def test_clothoid_jerk_closed_form():
    """Horizontal clothoid κ = L/a, bead at constant speed v: n_y = v² κ/g grows linearly in time
    with jerk_y = v³/(a g); the jerk comes from the model's accelerations (derivative along the
    flow), not from differencing the sampled n_y."""
    v, length, k1 = 12.0, 50.0, 1.0 / 25.0
    seg = Clothoid(length, 0.0, k1)
    model = _model(RotationMinimisingFrame(seg, max_step=0.25, tol=1e-12), 0.0, v)
    res = _run(model, 3.0, 31)
    df = rider_loads(model, res, "car", coordinate="L")
    L = df["L [m]"].to_numpy()
    q = v**2 * k1 / G
    assert np.abs(df["n_y [g]"] - v**2 * L / (seg.a * G)).max() < K * RTOL * (1 + q)
    jerk = v**3 / (seg.a * G)
    scale = 1 + q * v / length
    assert np.abs(df["jerk_y [g/s]"] - jerk).max() < K * RTOL * scale
    assert np.abs(df[["jerk_x [g/s]", "jerk_z [g/s]"]].to_numpy()).max() < K * RTOL * scale
    # the jerk step does not matter (no truncation visible from 1e-5 s to 1e-3 s)
    df2 = rider_loads(model, res, "car", jerk_step=1e-3)
    assert np.abs(df2["jerk_y [g/s]"] - df["jerk_y [g/s]"]).max() < K * RTOL * scale


def test_rider_loads_bad_input():
    model = _model(RotationMinimisingFrame(Straight(50.0)), L0=5.0)
    res = _run(model, 0.1, 2)
    with pytest.raises(ModelError, match="no body 'train'"):
        rider_loads(model, res, "train")
    with pytest.raises(InputError, match="rider_point"):
        rider_loads(model, res, "car", (0.0, np.nan, 0.0))
    with pytest.raises(InputError, match="axes"):
        rider_loads(model, res, "car", axes=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InputError, match="jerk_step"):
        rider_loads(model, res, "car", jerk_step=0.0)
    with pytest.raises(InputError, match="no coordinate 's'"):
        rider_loads(model, res, "car", coordinate="s")
    b = ModelBuilder(2, "planar")
    b.add_body("car", 1.0, 1.0, (0.0, 0.0))
    with pytest.raises(InputError, match="spatial"):
        load_factor(b.build(), 0.0, np.zeros(3), np.zeros(3), "car")


# ---------------------------------------------------------------------------------------------
# durations above levels
# ---------------------------------------------------------------------------------------------
def _triangle(t, centre, peak, half_width, base=1.0):
    return base + (peak - base) * np.clip(1.0 - np.abs(t - centre) / half_width, 0.0, None)


def test_exceedance_durations_of_a_piecewise_linear_signal():
    """Two triangular pulses 1 → 7 g (half width 1 s) and, on top of the 1 g base, a second of 5.5 g (to 6.5 g, half width 2 s) sampled at
    0.05 s: the time above 6 g is 2 (1 − 5/6) = 1/3 s and 2 · 2 (1 − 5/5.5) = 4/11 s, exactly."""
    t = np.arange(0.0, 12.0 + 1e-9, 0.05)
    n = _triangle(t, 3.0, 7.0, 1.0) + _triangle(t, 8.0, 5.5, 2.0, base=0.0)
    ex = exceedances(t, n, 6.0)
    assert len(ex) == 2
    assert ex["duration [s]"].to_numpy() == pytest.approx([1 / 3, 4 / 11], abs=1e-12)
    assert ex["start [s]"].to_numpy() == pytest.approx([3 - 1 / 6, 8 - 2 / 11], abs=1e-12)
    assert ex["peak [g]"].to_numpy() == pytest.approx([7.0, 6.5])
    assert not ex["open"].any()
    # a negative level counts values below it; an interval open at the end of the record is cut there
    m = 1.0 - 3.0 * np.clip((t - 10.0) / 2.0, 0.0, None)  # 1 g, then down to −2 g at t = 12 s
    neg = exceedances(t, m, -1.5)
    assert len(neg) == 1 and bool(neg["open"].iloc[0])
    assert neg["duration [s]"].iloc[0] == pytest.approx(12.0 - (10.0 + 2.0 * 2.5 / 3.0), abs=1e-12)
    assert neg["peak [g]"].iloc[0] == pytest.approx(-2.0)
    assert len(exceedances(t, n, 8.0)) == 0
    with pytest.raises(InputError, match="non-zero"):
        exceedances(t, n, 0.0)
    with pytest.raises(InputError, match=r"strictly increasing; t\[3\]"):
        exceedances([0.0, 1.0, 2.0, 2.0], [0.0] * 4, 1.0)


def test_time_above_limits_per_axis_and_section_with_verdicts():
    """Verdict 'exceeds' only when the longest contiguous exceedance is longer than allowed (or
    any exceedance of a peak limit); a section is summed over its occurrences."""
    t = np.arange(0.0, 12.0 + 1e-9, 0.05)
    nz = _triangle(t, 3.0, 7.0, 1.0) + _triangle(t, 8.0, 5.5, 2.0, base=0.0)
    ny = 2.5 * np.sin(np.pi * t / 6.0)  # above 2 g for t in (6/π asin 0.8, 6 − that)
    loads = pd.DataFrame({"t [s]": t, "n_x [g]": 0 * t, "n_y [g]": ny, "n_z [g]": nz})
    section = np.where(t < 5.0, "drop", "helix")
    limits = pd.DataFrame({"axis": ["z", "z", "y", "y"], "level [g]": [6.0, 6.4, 2.0, -2.0],
                           "max duration [s]": [0.35, 0.0, np.nan, 3.0], "basis": ["test"] * 4})
    tab = time_above_limits(loads, limits, sections=section)
    assert list(tab["section"].unique()) == ["drop", "helix"]
    row = tab[(tab.section == "drop") & (tab["level [g]"] == 6.0)].iloc[0]
    assert row["exceedances [-]"] == 1 and row["time above [s]"] == pytest.approx(1 / 3, abs=1e-12)
    assert row["verdict"] == "within" and row["peak [g]"] == pytest.approx(7.0)
    row = tab[(tab.section == "helix") & (tab["level [g]"] == 6.0)].iloc[0]
    assert row["longest [s]"] == pytest.approx(4 / 11, abs=1e-12) and row["verdict"] == "exceeds"
    row = tab[(tab.section == "drop") & (tab["level [g]"] == 6.4)].iloc[0]
    assert row["verdict"] == "exceeds"  # a peak limit: any exceedance
    y = tab[(tab["level [g]"] == 2.0)]
    t1 = 6 / np.pi * np.arcsin(0.8)
    assert y["time above [s]"].sum() == pytest.approx(6.0 - 2 * t1, abs=2e-3)  # sine: interpolation error
    assert set(y["verdict"]) == {"no duration given"}
    row = tab[(tab.section == "helix") & (tab["level [g]"] == -2.0)].iloc[0]
    assert row["exceedances [-]"] == 1 and row["verdict"] == "within"
    assert row["longest [s]"] == pytest.approx(6.0 - 2 * t1, abs=2e-3) and row["peak [g]"] == pytest.approx(-2.5)
    # one section for the whole record gives the same totals
    whole = time_above_limits(loads, limits)
    for lev in (6.0, 2.0, -2.0):
        assert whole[whole["level [g]"] == lev]["time above [s]"].iloc[0] == pytest.approx(
            tab[tab["level [g]"] == lev]["time above [s]"].sum(), abs=1e-12)
    with pytest.raises(InputError, match="section labels"):
        time_above_limits(loads, limits, sections=["a"])


def test_shipped_limits_are_data_with_a_second_hand_source():
    lim = read_acceleration_limits()
    assert set(lim["axis"]) <= {"x", "y", "z"}
    assert "SECOND-HAND" in lim.attrs["source"] and "ASTM F2291" in lim.attrs["source"]
    row = lim[(lim.axis == "z") & (lim["level [g]"] > 0)].iloc[0]
    assert row["level [g]"] == 6.0 and row["max duration [s]"] == 1.0
    assert (lim["level [g]"] != 0).all()


def test_limit_file_errors_name_the_row(tmp_path):
    p = tmp_path / "lim.csv"
    p.write_text("# source: test\naxis,level [g],max duration [s],basis\nz,6,1,a\nw,2,1,b\n")
    with pytest.raises(DataFileError, match="data row 1: axis 'w'"):
        read_acceleration_limits(p)
    p.write_text("axis,level [g],max duration [s],basis\nz,0,1,a\n")
    with pytest.raises(DataFileError, match="data row 0: level"):
        read_acceleration_limits(p)
    p.write_text("axis,level,basis\nz,1,a\n")
    with pytest.raises(DataFileError, match="columns"):
        read_acceleration_limits(p)
    with pytest.raises(DataFileError, match="not found"):
        read_acceleration_limits(tmp_path / "missing.csv")
