"""Bad input of the coaster package (issue 12): each gets a clear error naming the value, or a
stated outcome.

* control points with duplicates (consecutive or further apart) or too few points;
* a frame that cannot be built: Frenet on a straight without a fallback, and the Frenet flip at
  an inflection (S-curve), found by :meth:`coaster.frames.FrenetFrame.check`;
* a track that self-intersects within the wheel gauge: :func:`coaster.track.check_clearance`
  names the two arc lengths.
(A train too slow to crest a hill is coaster/train.py's.)
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coaster.frames import FrenetFrame, RotationMinimisingFrame
from coaster.track import (Clothoid, Helix, SplineCentreline, Straight, VerticalLoop, check_clearance,
                           circuit_centreline)
from core.errors import InputError

GAUGE = 1.5  # m: wheel gauge plus margin used as the clearance in these tests


def _circle_points(n=12, R=20.0):
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.c_[R * np.cos(a), R * np.sin(a), 0.0 * a]


# ---------------------------------------------------------------------------------------------
# control points
# ---------------------------------------------------------------------------------------------
def test_consecutive_duplicate_control_points_are_named():
    P = _circle_points()
    P = np.insert(P, 4, P[3], axis=0)
    with pytest.raises(InputError, match="control points 3 and 4 coincide"):
        SplineCentreline(P, kind="cubic", closed=True)


def test_non_consecutive_duplicate_control_points_are_named():
    P = _circle_points(12)
    Q = np.vstack([P[:8], P[2:3], P[8:]])  # point 2 repeated as point 8
    with pytest.raises(InputError, match=r"control points 2 and 8 coincide.*duplicate"):
        SplineCentreline(Q, kind="quintic", closed=True)


def test_closed_curve_may_repeat_its_first_point_at_the_end():
    P = _circle_points(12)
    c = SplineCentreline(np.vstack([P, P[:1]]), kind="cubic", closed=True)
    assert c.points.shape == (12, 3)  # the stated outcome: the repetition is dropped


@pytest.mark.parametrize("n", [0, 1, 3])
def test_too_few_control_points(n):
    with pytest.raises(InputError, match=f"at least 4 control points, got {n}"):
        SplineCentreline(_circle_points(12)[:n].reshape(-1, 3), kind="cubic")


# ---------------------------------------------------------------------------------------------
# frames that cannot be built
# ---------------------------------------------------------------------------------------------
def test_frenet_on_a_straight_without_fallback_names_the_arc_length():
    fr = FrenetFrame(Straight(40.0, name="straight"))
    with pytest.raises(InputError, match=r"below kappa_min.*at L = 12\.5 m.*fallback='vertical'"):
        fr.frame([12.5])
    with pytest.raises(InputError, match="undefined there"):
        fr.check()
    # the stated outcomes with a fallback or the rotation-minimising frame: defined, no rotation
    assert FrenetFrame(Straight(40.0), fallback="vertical").check() == 0.0
    R = RotationMinimisingFrame(Straight(40.0)).frame([0.0, 20.0, 40.0])[0]
    assert np.abs(R - R[0]).max() < 1e-14


def test_frenet_flip_at_an_inflection_is_reported():
    """S-curve (clothoid κ = −1/30 … 1/30 1/m over 60 m, inflection at L = 30 m): sampled off
    the inflection, no curvature is below kappa_min, but n flips by π between two samples."""
    s = Clothoid(60.0, -1 / 30, 1 / 30, name="S-curve")
    L = np.linspace(0.0, 60.0, 400)  # 30 m is not a sample
    with pytest.raises(InputError, match=r"flips by 3\.14 rad between L = 29\.9\d* m and L = 30\.0\d* m"):
        FrenetFrame(s).check(L)
    with pytest.raises(InputError, match="flips"):
        FrenetFrame(s, fallback="vertical").check()  # the fallback only hides the singular point
    assert FrenetFrame(Helix(10.0, 2.0, 2 * math.pi)).check() < 0.02  # smooth where it is defined


# ---------------------------------------------------------------------------------------------
# self-intersection within the gauge
# ---------------------------------------------------------------------------------------------
def test_closed_vertical_loop_self_intersects():
    loop = VerticalLoop(10.0, offset=0.0, name="loop")
    with pytest.raises(InputError, match=r"loop: the track comes within .* between L = 0 m and L = 62\.83\d* m"):
        check_clearance(loop, GAUGE)
    ok = check_clearance(VerticalLoop(10.0, offset=2.0), GAUGE)  # offset by more than the gauge
    assert ok.distance > GAUGE


def test_helix_turns_closer_than_the_gauge():
    """Helix R = 10 m, rise c per radian: turns 2πc apart vertically."""
    c = 0.15  # 0.94 m per turn
    res = check_clearance(Helix(10.0, c, 4 * math.pi), GAUGE, raise_error=False)
    assert res.distance < GAUGE and res.distance == pytest.approx(2 * math.pi * c, rel=1e-3)
    assert res.L_b - res.L_a == pytest.approx(2 * math.pi * math.hypot(10.0, c), rel=1e-2)
    with pytest.raises(InputError, match="self-intersects within the gauge"):
        check_clearance(Helix(10.0, c, 4 * math.pi), GAUGE)
    assert check_clearance(Helix(10.0, 0.5, 4 * math.pi), GAUGE).distance > GAUGE


def test_crossing_spline_names_both_arc_lengths():
    """A figure-eight in the plane crosses itself at the origin."""
    a = np.linspace(0.0, 2 * np.pi, 16, endpoint=False) + 0.1
    P = np.c_[30 * np.sin(a), 15 * np.sin(2 * a), 0.0 * a]
    c = SplineCentreline(P, kind="quintic", closed=True, name="figure eight")
    res = check_clearance(c, GAUGE, raise_error=False)
    assert res.distance < 1e-6
    g = c.derivatives([res.L_a, res.L_b])[0]
    assert np.linalg.norm(g[0]) < 0.5 and np.linalg.norm(g[0] - g[1]) < 1e-6
    with pytest.raises(InputError, match=rf"figure eight: .* L = {res.L_a:.6g} m and L = {res.L_b:.6g} m"):
        check_clearance(c, GAUGE)


def test_circuit_keeps_the_gauge_clear():
    res = check_clearance(circuit_centreline(), GAUGE)
    assert res.distance > GAUGE


def test_clearance_arguments():
    with pytest.raises(InputError, match="clearance must be positive"):
        check_clearance(Straight(10.0), 0.0)
    with pytest.raises(InputError, match="spacing must be positive"):
        check_clearance(Straight(10.0), 1.0, spacing=-1.0)
