"""Time above acceleration limits from the run's dense solution, not from its output grid
(issue 21: "statistics from dense data").

Analytic case: the three-car train driven by a chain at constant speed v round a vertical circle
of radius R (``VerticalLoop`` without offset).  Every body then turns rigidly about the circle's
axis at ω = v/R, so at the rider point P (car body axes, A(t) = R_y(−ωt) A_0, P(t) − c =
R_y(−ωt)(P_0 − c))::

    a_P = −ω² (P − c),
    n(t) = Aᵀ (a_P − g_vec)/g = −ω² A_0ᵀ (P_0 − c)/g + A_0ᵀ (sin ωt, 0, cos ωt)

and n_z(t) = a_0 + r cos(ωt − δ): the crossings of a level c are ωt = δ ± arccos((c − a_0)/r) (mod
2π), in closed form from the assembled initial state (A_0, P_0: geometry, no integration).
"""

from __future__ import annotations

import math
import warnings
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from coaster.frames import RotationMinimisingFrame
from coaster.rider import rider_loads, time_above_limits
from coaster.track import VerticalLoop
from coaster.train import ChainLift, Train, run_train, time_above_limits_dense
from core import frames
from core.signals import GridResolutionWarning

R, V, RTOL = 20.0, 10.0, 1e-8
L0, L1 = 15.0, 115.0


@pytest.fixture(scope="module")
def loop_runs():
    fr = RotationMinimisingFrame(VerticalLoop(R), max_step=1.0)
    tr = Train(fr)
    runs = {hz: run_train(tr, L0, V, L1, chain=ChainLift(L0, L1, V), rtol=RTOL, atol=RTOL, output_step=1.0 / hz,
                          chunk=1.0 / hz) for hz in (20, 100)}
    for r in runs.values():
        assert r.status == "finished", r.message
    return tr, runs


def _closed_form(tr, run):
    """(a_0, r, δ, ω) of n_z(t) = a_0 + r cos(ωt − δ) for the rider of car 1."""
    m = run.models[0]
    qb = run.q[0][m.q_slice("car1")]
    A0 = frames.euler_to_matrix(qb[3:7])
    P0 = qb[:3] + A0 @ np.asarray(tr.p.rider_point, float)
    c = np.array([0.0, 0.0, R])
    w = V / R
    g = float(np.linalg.norm(m.gravity))
    a0 = -w**2 * (A0.T @ (P0 - c))[2] / g
    return a0, math.hypot(A0[0, 2], A0[2, 2]), math.atan2(A0[0, 2], A0[2, 2]), w


def _interval_below(cf, level, t_end):
    """[start, end] where n_z < level (one interval, around the minimum of n_z)."""
    a0, r, dl, w = cf
    phi = math.acos((level - a0) / r)            # cos(ωt − δ) = (c − a_0)/r
    tm = (dl + math.pi) / w                       # minimum: ωt − δ = π
    half = (math.pi - phi) / w
    assert 0 < tm - half and tm + half < t_end
    return tm - half, tm + half


def _limits(*levels):
    n = len(levels)
    return pd.DataFrame({"axis": ["z"] * n, "level [g]": list(levels), "max duration [s]": [1.0] * n,
                         "basis": ["test"] * n})


def test_closed_form_describes_the_samples(loop_runs):
    """The closed form is the motion: n_z at the 100 Hz outputs of the chain phase within 1e3 rtol
    (measured 1e-9 g; the run's last output, after the release, is free running)."""
    from coaster.rider import _Rider

    tr, runs = loop_runs
    run = runs[100]
    cf = _closed_form(tr, run)
    rider = _Rider(run.models[0], "car1", tr.p.rider_point, None)
    nz = np.array([rider.loads_given(q, v, a)[0][2] for q, v, a in zip(run.q, run.v, run.vdot)])
    a0, r, dl, w = cf
    chain = run.phase == 0
    assert chain.sum() >= len(run.t) - 2
    assert np.max(np.abs(nz - (a0 + r * np.cos(w * run.t - dl)))[chain]) < 1e3 * RTOL


def test_time_above_a_level_equals_the_closed_form_at_20_and_100_hz(loop_runs):
    """n_z < −0.3 g over the top of the loop: the located interval equals the closed form and
    does not change between 20 Hz and 100 Hz outputs (to 1e3 rtol s; measured 8e-9 s from the closed
    form, 5e-11 s between the two)."""
    tr, runs = loop_runs
    level = -0.3
    out = {}
    for hz, run in runs.items():
        tab = time_above_limits_dense(run, _limits(level), car="car1")
        out[hz] = tab.iloc[0]
    a, b = _interval_below(_closed_form(tr, runs[100]), level, runs[100].t[-1])
    for hz in (20, 100):
        assert out[hz]["exceedances [-]"] == 1
        assert abs(out[hz]["time above [s]"] - (b - a)) < 1e3 * RTOL, (hz, out[hz]["time above [s]"], b - a)
        assert abs(out[hz]["longest starts at [s]"] - a) < 1e3 * RTOL
    assert abs(out[20]["time above [s]"] - out[100]["time above [s]"]) < 1e3 * RTOL


def test_a_short_exceedance_between_two_outputs_is_found(loop_runs):
    """A level 1.25e-5 g inside the minimum of n_z: an exceedance of about 20 ms that lies between two
    20 Hz outputs.  The grid-based table misses it and warns; the dense one finds it, with the
    closed-form duration (to 1e4 rtol s, measured 5e-7 s: the duration goes as the square root of
    the depth, d(duration)/d(level) = 800 s/g here),
    flags it as between outputs and warns that the grid does not show it."""
    tr, runs = loop_runs
    run = runs[20]
    cf = _closed_form(tr, run)
    a0, r, dl, w = cf
    level = a0 - r + 1.25e-5
    a, b = _interval_below(cf, level, run.t[-1])
    assert 0.01 < b - a < 0.05
    assert not np.any((run.t >= a) & (run.t <= b))                 # no output inside: the grid cannot see it
    with pytest.warns(GridResolutionWarning, match="between two outputs"):
        dense = time_above_limits_dense(run, _limits(level), car="car1").iloc[0]
    assert dense["exceedances [-]"] == 1 and dense["between outputs [-]"] == 1
    assert abs(dense["time above [s]"] - (b - a)) < 1e4 * RTOL, (dense["time above [s]"], b - a)
    assert abs(dense["peak [g]"] - (a0 - r)) < 1e3 * RTOL
    loads = pd.concat([rider_loads(m, SimpleNamespace(t=run.t[run.phase == k], q=run.q[run.phase == k],
                                                       v=run.v[run.phase == k]), "car1", tr.p.rider_point)
                       for k, m in enumerate(run.models) if np.any(run.phase == k)], ignore_index=True)
    with pytest.warns(GridResolutionWarning, match="may hide"):
        grid = time_above_limits(loads, _limits(level)).iloc[0]
    assert grid["exceedances [-]"] == 0


def test_no_false_alarm_far_from_the_extreme(loop_runs):
    """A level the load factor never reaches: no exceedance, no warning."""
    tr, runs = loop_runs
    a0, r, _, _ = _closed_form(tr, runs[20])
    with warnings.catch_warnings():
        warnings.simplefilter("error", GridResolutionWarning)
        tab = time_above_limits_dense(runs[20], _limits(a0 - r - 0.01), car="car1")
    assert tab["exceedances [-]"].iloc[0] == 0 and tab["time above [s]"].iloc[0] == 0.0
