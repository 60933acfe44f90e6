"""Tests of the work-precision harness (core.benchmarks).

Fast: tiny grids on the N = 2 chain; the pendulum reference is checked against an independent
DOP853 integration of the pendulum ODE.  Timing columns are never asserted.
"""

from __future__ import annotations

import dataclasses
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from core import benchmarks as wp
from core.benchmarks import references as refs
from core.benchmarks.references import n_link_chain_reference
from core.errors import NameTakenError, UnknownNameError
from core.integrators import simulate
from core.models import chain_tip, n_link_chain
from core.results import FINISHED_STATUSES

CHAIN = "chain2-planar"


@pytest.fixture(scope="module")
def small_table():
    return wp.run_work_precision(CHAIN, methods=["dop853-projection", "generalized-alpha"],
                                 settings={"rtol": [1e-3, 1e-6, 1e-9], "h": [1e-2]}, repeats=2)


def test_table_columns_rows_and_units(small_table):
    df = small_table
    assert list(df.columns) == wp.COLUMNS
    assert len(df) == 4  # 3 tolerances + 1 step, one row each
    assert set(df["setting kind"]) == {"rtol", "h [s]"}
    # every run reaches the end; the fixed-step row carries the error warning of its estimate
    # (its rtol is the tight Newton tolerance, which h = 1e-2 does not meet)
    assert df["status"].isin(FINISHED_STATUSES).all()
    fixed_status = df.loc[df["setting kind"] == "h [s]", "status"].iloc[0]
    assert fixed_status == "finished with warnings"
    assert (df["wall time [s]"] > 0).all()
    assert df["n repeats"].between(1, 2).all()
    assert (df["n_steps"] > 0).all()
    # fixed-step rows carry the tight Newton tolerance, adaptive rows atol = rtol * atol_scale
    fixed = df[df["setting kind"] == "h [s]"].iloc[0]
    assert fixed["rtol"] == fixed["atol"] == wp.PROBLEMS[CHAIN].newton_tol
    adaptive = df[df["setting kind"] == "rtol"]
    assert np.allclose(adaptive["atol"], adaptive["rtol"] * wp.PROBLEMS[CHAIN].atol_scale)
    # the conservative chain records an energy drift
    assert np.isfinite(df["energy drift [-]"]).all()
    assert df.attrs["problem"] == CHAIN and "DOP853" in df.attrs["reference"]


def test_error_decreases_as_tolerance_tightens(small_table):
    ad = small_table[small_table["method"] == "dop853-projection"].sort_values("setting value", ascending=False)
    err = ad["error"].to_numpy()
    assert np.all(np.diff(err) < 0), err
    # the error follows the requested accuracy: within a factor 1e3 of rtol (error per unit length 1 m)
    assert np.all(err <= 1e3 * ad["setting value"].to_numpy()), err


def test_error_is_the_tip_distance_to_the_minimal_coordinate_reference(small_table):
    from core.integrators import simulate

    prob = wp.PROBLEMS[CHAIN]
    tip_ref, _ = n_link_chain_reference(2)
    np.testing.assert_array_equal(prob.reference(), tip_ref)
    np.testing.assert_array_equal(wp.PROBLEMS["chain2-spatial"].reference(), tip_ref)
    system = n_link_chain(2)
    res = simulate(system, (0.0, 1.0), "dop853-projection", n_output=2, rtol=1e-6, atol=1e-6,
                   compute_multipliers=False)
    expected = np.linalg.norm(chain_tip(system, res.q[-1]) - tip_ref)
    assert prob.error(res) == pytest.approx(expected, rel=1e-12)
    row = small_table[(small_table["method"] == "dop853-projection") & (small_table["setting value"] == 1e-6)]
    assert row["error"].iloc[0] == pytest.approx(expected, rel=1e-12)


def test_failed_runs_are_rows_with_status_failed_and_nan_error():
    base = wp.PROBLEMS[CHAIN]
    failing = dataclasses.replace(base, name="chain2-failing", method_options={
        "generalized-alpha": {"max_newton": 1},  # Newton cannot converge in one iteration: run fails
        "rk45-projection": {"no_such_option": 1},  # the integrator refuses to start
    })
    df = wp.run_work_precision(failing, methods=["generalized-alpha", "rk45-projection", "dop853-projection"],
                               settings={"rtol": [1e-4], "h": [1e-2]}, repeats=1)
    assert len(df) == 3
    by = df.set_index("method")
    for m in ("generalized-alpha", "rk45-projection"):
        assert by.loc[m, "status"] == "failed"
        assert math.isnan(by.loc[m, "error"])
        assert by.loc[m, "message"]
    assert "no_such_option" in by.loc["rk45-projection", "message"]
    assert "failed at t" in by.loc["generalized-alpha", "message"]
    assert by.loc["dop853-projection", "status"] == "finished"
    assert np.isfinite(by.loc["dop853-projection", "error"])
    # the figure marks the failed points and the writer keeps them
    fig = wp.work_precision_figure(df)
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert "generalized-alpha (failed)" in labels and "rk45-projection (failed)" in labels


def test_serial_equals_process_pool_for_deterministic_columns():
    kw = dict(methods=["rk45-projection", "hht"], settings={"rtol": [1e-3, 1e-5], "h": [1e-2]}, repeats=1)
    serial = wp.run_work_precision(CHAIN, **kw)
    with ProcessPoolExecutor(max_workers=2) as ex:
        parallel = wp.run_work_precision(CHAIN, executor=ex, **kw)
    cols = wp.DETERMINISTIC_COLUMNS
    pd.testing.assert_frame_equal(serial[cols], parallel[cols], check_exact=True)


def test_problem_set_on_a_given_executor_equals_serial():
    """run_problem_set on the caller's executor (the work-precision scene passes its sweep executor):
    the deterministic columns equal the serial run's; the executor stays open; jobs and executor
    together are refused."""
    kw = dict(methods=["rk45-projection", "hht"], repeats=1)
    serial = wp.run_problem_set([CHAIN], "quick", **kw)
    with ProcessPoolExecutor(max_workers=2) as ex:
        parallel = wp.run_problem_set([CHAIN], "quick", executor=ex, **kw)
        assert ex.submit(abs, -1).result() == 1  # not shut down
        with pytest.raises(ValueError, match="not both"):
            wp.run_problem_set([CHAIN], "quick", jobs=2, executor=ex, **kw)
    cols = wp.DETERMINISTIC_COLUMNS
    pd.testing.assert_frame_equal(serial[cols], parallel[cols], check_exact=True)


def test_work_precision_notes_name_grid_workers_and_measures():
    notes = wp.work_precision_notes([CHAIN, "andrews"], "quick", 2)
    assert notes.startswith("Grid `quick`; 2 worker process(es)")
    assert f"| {CHAIN} | {wp.PROBLEMS[CHAIN].error_measure} |" in notes and "| andrews |" in notes
    assert "the workers of a distributed executor" in wp.work_precision_notes([CHAIN], "quick", None)


def test_pendulum_exact_solution_matches_an_independent_integration():
    g, l, th0 = 9.81, 1.0, np.pi / 2
    t = np.array([0.0, 0.3, 1.7, 25.0, 100.0])
    sol = solve_ivp(lambda _, y: [y[1], -g / l * np.sin(y[0])], (0, 100.0), [th0, 0.0], method="DOP853",
                    rtol=1e-13, atol=1e-13, t_eval=t)
    exact = wp.pendulum_angle_exact(t, th0, l, g)
    assert exact[0] == pytest.approx(th0, abs=1e-15)
    # DOP853 at 1e-13 accumulates ~1e-11 rad of phase error per period over 42 periods
    np.testing.assert_allclose(exact, sol.y[0], atol=1e-8)
    assert wp.PROBLEMS["pendulum-100s"].reference() == pytest.approx(exact[-1], abs=1e-15)


def test_stiff_chain_reference_differs_from_rigid_by_order_mg_over_k():
    # k = 1e4 N/m: static sag scale m g / k = 9.81e-4 m for the 1 kg chain
    stiff = wp.PROBLEMS["chain2-stiff-k1e4"].reference()
    rigid = wp.PROBLEMS[CHAIN].reference()
    d = np.linalg.norm(stiff - rigid)
    assert 1e-2 * 9.81e-4 < d < 1e2 * 9.81e-4


def test_registry_grids_and_unknown_names():
    for name, p in wp.PROBLEMS.items():
        assert set(wp.GRID_NAMES) <= set(p.grids), name
    for s in ("quick", "standard"):
        assert set(wp.PROBLEM_SETS[s]) <= set(wp.PROBLEMS)
    with pytest.raises(UnknownNameError, match="unknown work-precision problem 'no-such-problem'; registered: chain2"):
        wp.run_work_precision("no-such-problem")
    with pytest.raises(ValueError, match="unknown integrator"):
        wp.run_work_precision(CHAIN, methods=["no-such-method"])
    with pytest.raises(NameTakenError, match="work-precision problem name 'chain2-planar' is taken"):
        wp.register_problem(dataclasses.replace(wp.PROBLEMS[CHAIN]))
    assert [s.name for s in wp.work_precision_scenes()] == ["work-precision"]


def test_write_and_summary(small_table, tmp_path):
    written = wp.write_work_precision(small_table, tmp_path)
    for suffix in ("csv", "md", "png"):
        assert (tmp_path / f"wp_{CHAIN}.{suffix}").is_file()
    assert (tmp_path / "wp_summary.csv").is_file()
    back = pd.read_csv(written[CHAIN]["csv"])
    # the written table is the harness table with its units in the column names (report_table)
    assert list(back.columns) == wp.REPORT_COLUMNS and len(back) == len(small_table)
    np.testing.assert_array_equal(back["error"], small_table["error"])
    np.testing.assert_array_equal(back["n_steps [-]"], small_table["n_steps"])
    assert set(back["error unit"]) == {"m"} and set(back["setting unit"]) == {"-", "s"}
    summ = wp.fastest_to_tolerance(small_table, targets=(1e-2, 1e-30))
    assert summ.loc[0, "error"] <= 1e-2
    assert summ.loc[1, "method"] == "none"


def test_cli_bench(tmp_path, capsys):
    from core.cli import main

    assert main(["bench", "--list"]) == 0
    out = capsys.readouterr().out
    assert CHAIN in out and "andrews" in out and "pendulum-100s" in out
    code = main(["bench", CHAIN, "--methods", "rk45-projection", "--repeats", "1", "--quick", "-o", str(tmp_path)])
    assert code == 0
    df = pd.read_csv(tmp_path / f"wp_{CHAIN}.csv")
    assert set(df["method"]) == {"rk45-projection"} and df["status"].isin(FINISHED_STATUSES).all()
    assert main(["bench", "no-such-problem", "-o", str(tmp_path)]) == 2


def test_independent_stiff_chain_rhs_agrees_with_the_model():
    n, k = 3, 1e6
    system = n_link_chain(n, stiff_k=k)
    rng = np.random.default_rng(1)
    q = system.q0 + 0.01 * rng.standard_normal(system.n_q)
    v = rng.standard_normal(system.n_v)
    M = system.M(0.0, q)
    M = M.toarray() if hasattr(M, "toarray") else np.asarray(M)
    a = np.linalg.solve(M, system.Q(0.0, q, v))
    y = np.concatenate([q[0::3], q[1::3], q[2::3], v[0::3], v[1::3], v[2::3]])
    f = wp.stiff_chain_rhs(n, k)(0.0, y)
    np.testing.assert_allclose(f[3 * n:], np.concatenate([a[0::3], a[1::3], a[2::3]]), rtol=1e-10,
                               atol=1e-8 * np.abs(a).max())
    np.testing.assert_array_equal(f[:3 * n], y[3 * n:])


def test_methods_that_cannot_integrate_a_system_are_left_out_of_its_table():
    """Compiled integrators need a core Model: on the hand-written car axis they are not rows at all;
    on the chain they run, to the accuracy of their scipy counterparts (same tableau and controller;
    their steps also land on the problem's output times, so the step sequences differ)."""
    kw = dict(methods=["rk45", "jit-rk45"], settings={"rtol": [1e-4]}, repeats=1)
    car = wp.run_work_precision("car-axis", **kw)
    assert set(car["method"]) == {"rk45"}
    chain = wp.run_work_precision(CHAIN, **kw).set_index("method")
    assert set(chain.index) == {"rk45", "jit-rk45"}
    assert chain["status"].isin(FINISHED_STATUSES).all()
    e_jit, e_ref = chain.loc["jit-rk45", "error"], chain.loc["rk45", "error"]
    assert 0.1 * e_ref <= e_jit <= 10 * e_ref


@pytest.mark.slow
def test_a04_reference_agrees_with_the_numpy_path_and_conserves_energy():
    """The A04 reference (compiled DOP853 + projection, 1e-12) against scipy DOP853 + projection on the
    numpy right-hand side at 1e-11: two implementations of the equations agree to 1e-8 m at t = 10 s."""
    ref = refs.iftomm_a04_reference()
    system = refs.iftomm_a04_system()
    res = simulate(system, (0.0, refs.A04_T_END), "dop853-projection", n_output=11, rtol=1e-11, atol=1e-11,
                   compute_multipliers=False)
    assert res.status == "finished"
    assert np.linalg.norm(refs.iftomm_a04_p2(system, res.q[-1]) - ref) < 1e-8
    assert np.max(np.abs(res.energy - res.energy[0])) < 1e-8 * 5 * 9.81


def test_a_case_stops_repeating_at_the_time_budget():
    # a budget below any solve's time: one solve per case; a budget far above: all the repeats
    kw = dict(methods=["dop853-projection"], settings={"rtol": [1e-6]}, repeats=3)
    one = wp.run_work_precision(CHAIN, max_repeat_time=1e-9, **kw)
    three = wp.run_work_precision(CHAIN, max_repeat_time=1e3, **kw)
    assert (one["n repeats"] == 1).all() and (three["n repeats"] == 3).all()
    # the default budget is the module's, and a solve of this size (milliseconds) repeats under it
    assert wp.MAX_REPEAT_TIME == 0.5
    assert (wp.run_work_precision(CHAIN, **kw)["n repeats"] == 3).all()


def test_a_non_positive_repeat_budget_is_refused():
    with pytest.raises(ValueError, match="max_repeat_time must be > 0 s, got -1"):
        wp.run_work_precision(CHAIN, methods=["dop853-projection"], settings={"rtol": [1e-3]}, max_repeat_time=-1)
    with pytest.raises(ValueError, match="max_repeat_time must be > 0 s, got 0"):
        wp.run_problem_set([CHAIN], "quick", methods=["dop853-projection"], max_repeat_time=0)
