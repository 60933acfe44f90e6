"""Statistics from the dense record of a run, not from its output grid (core.signals,
``simulate(..., record_steps=True)``).

Oracles: a synthetic signal with a known short dip between two output times (the interval and
its boundaries known exactly), and the outputs of a run with and without the record (equal to
the last bit: recording does not change the step sequence).
"""

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from core import simulate
from core.errors import InputError
from core.models import simple_pendulum
from core.signals import (GridResolutionWarning, dense_level_intervals, grid_resolution, hidden_extremes,
                          level_intervals, level_summary, peak)


def _lift_signal(t, a=0.1234, b=0.1264):
    """Q(t) = 50 kN except a lift (Q = 0) on [a, b] (3 ms) with linear ramps of 1 ms on each side."""
    Q = np.full_like(t, 50e3)
    ramp_in = (t > a - 1e-3) & (t < a)
    ramp_out = (t > b) & (t < b + 1e-3)
    Q[ramp_in] = 50e3 * (a - t[ramp_in]) / 1e-3
    Q[ramp_out] = 50e3 * (t[ramp_out] - b) / 1e-3
    Q[(t >= a) & (t <= b)] = 0.0
    return Q


def test_a_short_lift_between_two_output_times_is_found_from_the_dense_record():
    grid = np.linspace(0.0, 0.5, 11)  # 20 Hz outputs: 0.10 and 0.15 s around the lift
    rng = np.random.default_rng(3)
    steps = np.unique(np.concatenate([grid, np.cumsum(rng.uniform(0.2e-3, 0.6e-3, 2000))]))
    steps = steps[steps <= 0.5]
    # the grid sees no lift at all
    assert np.all(_lift_signal(grid) > 0)
    iv = level_intervals(steps, _lift_signal(steps), 0.0, "below")
    assert len(iv) == 1
    h = np.max(np.diff(steps))
    # Q is flat at the level inside: the boundaries are located to one step (resolution)
    assert iv["resolution [s]"].iloc[0] <= h
    assert iv["start [s]"].iloc[0] == pytest.approx(0.1234, abs=h)
    assert iv["end [s]"].iloc[0] == pytest.approx(0.1264, abs=h)
    assert not grid_resolution(iv, grid)[0]
    # event location: a refine callable finding the exact boundary in its bracket
    exact = {True: 0.1234, False: 0.1264}
    iv2 = level_intervals(steps, _lift_signal(steps), 0.0, "below",
                          refine=lambda ta, tb: exact[ta < 0.125])
    assert (iv2["start [s]"].iloc[0], iv2["end [s]"].iloc[0]) == (0.1234, 0.1264)
    assert iv2["duration [s]"].iloc[0] == pytest.approx(3e-3, rel=1e-12)
    # the summary names what the grid misses, with a named warning
    with pytest.warns(GridResolutionWarning, match="wheel 'x' lift.*1 of 1 intervals"):
        s = level_summary(steps, _lift_signal(steps), 0.0, "below", t_grid=grid, name="wheel 'x' lift")
    assert s["missed by the output grid"] == 1 and s["count"] == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        level_summary(steps, _lift_signal(steps), 0.0, "below", t_grid=grid, warn=False)


def test_interval_boundaries_by_linear_interpolation_and_open_ends():
    t = np.linspace(0.0, 1.0, 101)
    x = np.sin(2 * np.pi * t)  # above 0.5 on [1/12, 5/12]; below -0.5 on [7/12, 11/12]
    iv = level_intervals(t, x, 0.5, "above")
    assert len(iv) == 1
    # linear interpolation of a smooth signal: O(h²) (h = 0.01, curvature 4π² sin)
    assert iv["start [s]"].iloc[0] == pytest.approx(1 / 12, abs=1e-4)
    assert iv["end [s]"].iloc[0] == pytest.approx(5 / 12, abs=1e-4)
    # a set holding at the start and at the end of the record
    iv = level_intervals(t, np.cos(2 * np.pi * t), 0.0, "above")
    assert list(iv["open start"]) == [True, False] and list(iv["open end"]) == [False, True]
    assert iv["duration [s]"].sum() == pytest.approx(0.5, abs=1e-4)
    assert len(level_intervals(t, x, 2.0, "above")) == 0
    assert peak(t, x, "max") == (pytest.approx(1.0), pytest.approx(0.25))
    assert peak(t, -np.abs(x) - 1, "absmax")[0] == pytest.approx(-2.0)
    with pytest.raises(InputError, match="side must be"):
        level_intervals(t, x, 0.0, "over")
    with pytest.raises(InputError, match="t must increase strictly"):
        level_intervals(t[::-1], x, 0.0)


@pytest.mark.parametrize("method", ["dop853", "jit-dop853"])
def test_recording_the_steps_changes_no_output(method):
    """The record is the run's own steps: the outputs equal those of a run without it bit for bit,
    also for a method that lands on the output times (one step per call then)."""
    m = simple_pendulum(angle0=0.5)
    kw = dict(rtol=1e-8, atol=1e-10, n_output=21)
    a = simulate(m, (0.0, 1.0), method, **kw)
    b = simulate(m, (0.0, 1.0), method, record_steps=True, **kw)
    assert a.steps is None and b.steps is not None
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.v, b.v)
    assert a.counters == b.counters
    st = b.steps
    assert st.t[0] == 0.0 and st.t[-1] == pytest.approx(1.0) and len(st.t) == b.counters["n_steps"] + 1
    assert st.q.shape == (len(st.t), m.n_q) and not st.q.flags.writeable
    if method == "jit-dop853":  # lands on every output time
        assert np.all(np.isin(b.t, st.t))
    # without the record the output grid fixes what a summary sees; with it the steps do
    assert isinstance(level_intervals(st.t, st.q[:, 0], 0.0, "above"), pd.DataFrame)


def test_dense_intervals_find_an_exceedance_between_samples_and_locate_crossings():
    """x = sin t sampled every 0.5 s, with its slope cos t and a dense evaluator: the level 0.9999
    is exceeded for 2 acos(0.9999) = 28 ms around π/2, between the samples 1.5 and 2.0 s; the level
    0.5 over [π/6, 5π/6] and [13π/6, 17π/6].  Crossings to xtol = 1e-12 s."""
    t = np.arange(0.0, 9.51, 0.5)
    for level, want in ((0.9999, [(math.pi / 2 - math.acos(0.9999), math.pi / 2 + math.acos(0.9999)),
                                  (5 * math.pi / 2 - math.acos(0.9999), 5 * math.pi / 2 + math.acos(0.9999))]),
                        (0.5, [(math.pi / 6, 5 * math.pi / 6), (13 * math.pi / 6, 17 * math.pi / 6)])):
        assert (level == 0.5) or not np.any(np.sin(t) >= level)   # the samples never reach 0.9999
        iv = dense_level_intervals(t, np.sin(t), np.cos(t), level, "above",
                                   lambda u: (math.sin(u), math.cos(u)), xtol=1e-12)
        got = list(zip(iv["start [s]"], iv["end [s]"]))
        assert len(got) == len(want), got
        for (a, b), (wa, wb) in zip(got, want):
            assert abs(a - wa) < 1e-9 and abs(b - wb) < 1e-9
        assert list(iv["between samples"]) == [level > 0.9] * 2
    # below: a dip of -cos t under -0.9999 around t = 2π, and the grid-only screen
    assert list(hidden_extremes(t, -np.cos(t), np.sin(t), -0.9999, "below")) == [12]
    assert list(hidden_extremes(t, np.sin(t), np.cos(t), 1.5, "above")) == []
