"""The ``coaster-analytic`` scene: every closed form within its tolerance derived from the
integrator's rtol (K · rtol · scale, :mod:`coaster.analytic_scene`), the zero multiplier on the
ballistic parabola, the frames compared where Frenet breaks, and the report files (units in
column names, titles naming the scene and the integrator: tests/core/test_report_files.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coaster.analytic_scene import (G, K_TOL, METHOD, RTOL, Parabola, coaster_analytic_scene)
from core.scenes import run_scene
from tests.core.test_report_files import figure_problems, folder_problems


def _quiet(iterable, **kwargs):
    return iterable


@pytest.fixture(scope="module")
def scene_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("scenes")
    result = run_scene(coaster_analytic_scene(), out, fast=True, progress=_quiet)
    return result, out / "coaster-analytic"


def _rows(comp, case, quantity=None):
    sel = comp[comp["case"] == case]
    return sel if quantity is None else sel[sel["quantity"] == quantity].iloc[0]


def test_every_closed_form_within_its_integrator_tolerance(scene_run):
    comp = scene_run[0].tables["comparison"]
    cases = {"helix", "vertical loop", "banked circle", "banked circle (perfect bank)", "clothoid",
             "ballistic parabola", "S-curve"}
    assert set(comp["case"]) == cases
    assert (comp["tolerance"] > 0).all()
    np.testing.assert_allclose(comp["error/tolerance"], comp["|error|"] / comp["tolerance"])
    bad = comp[~comp["pass"]]
    assert bad.empty, bad[["case", "quantity", "|error|", "tolerance"]].to_string()
    assert (comp["|error|"] <= K_TOL * RTOL * 1e3).all()  # no scale hides an O(1) error


def test_loop_bottom_minus_top_is_six_mg_and_reaches_the_top_on_time(scene_run):
    comp = scene_run[0].tables["comparison"]
    row = _rows(comp, "vertical loop", "N_bottom - N_top")
    assert row["closed form"] == pytest.approx(6 * G) and row["pass"]
    row = _rows(comp, "vertical loop", "L at t_top")
    assert row["closed form"] == pytest.approx(10 * math.pi) and row["pass"]


def test_ballistic_parabola_has_zero_multipliers_and_weightless_rider(scene_run):
    comp = scene_run[0].tables["comparison"]
    for q in ("max |multiplier| (force rows)", "max |multiplier| (orientation rows)", "|n|"):
        row = _rows(comp, "ballistic parabola", q)
        assert row["closed form"] == 0.0 and row["simulated"] <= row["tolerance"], q
    assert _rows(comp, "ballistic parabola", "max |multiplier| (force rows)")["tolerance"] == pytest.approx(
        K_TOL * RTOL * 1.0 * G)


def test_perfect_bank_has_no_lateral_load_at_the_track(scene_run):
    comp = scene_run[0].tables["comparison"]
    row = _rows(comp, "banked circle (perfect bank)", "n_y at the track")
    assert abs(row["closed form"]) < 1e-14 and row["pass"]
    # one metre above the track the rider turns on a smaller radius: a small inward (negative) n_y
    row = _rows(comp, "banked circle (perfect bank)", "n_y at the rider (1 m up)")
    assert row["closed form"] < 0 and row["pass"]


def test_runs_are_honest(scene_run):
    runs = scene_run[0].tables["runs"]
    assert (runs["status"] == "finished").all()
    assert (runs["method"] == METHOD).all() and (runs["rtol [-]"] == RTOL).all()
    assert (runs["max position violation [m]"] < 100 * RTOL * 100).all()


def test_frames_where_frenet_breaks(scene_run):
    ft = scene_run[0].tables["frames_where_frenet_breaks"].set_index(["track", "frame"])
    straight = [k for k in ft.index.levels[0] if k.startswith("straight")][0]
    s_curve = [k for k in ft.index.levels[0] if k.startswith("S-curve")][0]
    assert ft.loc[(straight, "Frenet"), "outcome"].startswith("InputError: curvature 0.0")
    assert ft.loc[(s_curve, "Frenet, vertical fallback"), "outcome"].startswith("InputError: the Frenet frame flips")
    assert ft.loc[(s_curve, "Frenet, vertical fallback"), "max rotation step [rad]"] == pytest.approx(math.pi)
    rmf = ft.loc[(s_curve, "rotation-minimising")]
    assert rmf["outcome"] == "defined and continuous"
    assert rmf["max rotation step [rad]"] == pytest.approx(rmf["expected step [rad]"], rel=1e-3)


def test_report_files_follow_the_conventions(scene_run):
    result, folder = scene_run
    for stem in ("comparison", "runs", "frames_where_frenet_breaks", "loop_rider_loads", "loop_time_above_limits"):
        assert (folder / f"{stem}.csv").is_file() and (folder / f"{stem}.md").is_file()
    assert (folder / "README.md").is_file()
    problems = folder_problems(folder)
    for stem, fig in result.figures.items():
        assert (folder / f"{stem}.png").is_file()
        problems += [f"{stem}: {p}" for p in figure_problems(fig, names=("coaster-analytic",))]
    problems += figure_problems(result.figures["closed_forms"], names=(METHOD, "rtol 1e-10"))
    assert problems == []


def test_parabola_segment_is_the_free_flight():
    """g(L(x)) = (x, 0, x tan γ − g x²/(2 v₀² cos²γ)); unit tangent; at the apex the curvature is
    κ = g/(v₀ cos γ)² (horizontal speed v₀ cos γ, centripetal acceleration g)."""
    v0, gam = 20.0, math.radians(40.0)
    seg = Parabola(v0, gam)
    x = np.linspace(0.0, 2 * seg.p * math.tan(gam), 7)
    d = seg.derivatives(seg.L_of_x(x))
    assert np.abs(d[0][:, 2] - (x * math.tan(gam) - G * x**2 / (2 * v0**2 * math.cos(gam) ** 2))).max() < 1e-10
    assert np.abs(np.linalg.norm(d[1], axis=1) - 1).max() < 1e-14
    apex = seg.derivatives([0.5 * seg.length])
    assert np.linalg.norm(apex[2, 0]) == pytest.approx(G / (v0 * math.cos(gam)) ** 2, rel=1e-12)
    # g''' and g'''' against central differences of the lower derivatives
    L, h = np.array([3.0, 11.0]), 1e-4
    dp, dm = seg.derivatives(L + h), seg.derivatives(L - h)
    assert np.abs((dp[2] - dm[2]) / (2 * h) - seg.derivatives(L)[3]).max() < 1e-7
    assert np.abs((dp[3] - dm[3]) / (2 * h) - seg.derivatives(L)[4]).max() < 1e-7
