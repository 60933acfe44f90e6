"""Per-frame cost of static optimisation (:mod:`biomech.static_optimization`), and whether going below cvxpy pays.

Run as ``python benchmarks/biomech_static_optimization.py [--frames 200]``.  For 18 muscles on 6
coordinates and 92 muscles on 23 coordinates (the sizes of gait10dof18musc and gait2392), random
physiologically scaled frames (moment arms 0.01-0.06 m, F0 300-3000 N, moments <= 100 N m, one
reserve of optimal force 1 N m per coordinate), it prints for each criterion and epigraph form:

* the first frame's time (it includes the one-off DPP compilation) and the median and 90th
  percentile of the later frames, wall time with cvxpy and Clarabel's own time;
* the statuses and how many frames needed a retry;
* the lower-level route: ``problem.get_problem_data(CLARABEL)`` (cached parameter -> data map)
  plus a direct ``clarabel.DefaultSolver`` call, against ``problem.solve``, measured side by side.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from biomech.muscles import ThelenMuscleSet  # noqa: E402
from biomech.static_optimization import StaticOptimization  # noqa: E402


def synthetic_trial(rng, n_coords, n_muscles, n_frames):
    mus = ThelenMuscleSet([f"m{j}" for j in range(n_muscles)], rng.uniform(300, 3000, n_muscles),
                          rng.uniform(0.04, 0.15, n_muscles), rng.uniform(0.05, 0.35, n_muscles),
                          rng.uniform(0.0, 0.4, n_muscles))
    pattern = np.zeros((n_coords, n_muscles))
    for j in range(n_muscles):
        span = rng.choice(n_coords, size=rng.integers(1, 4), replace=False)
        pattern[span, j] = rng.choice([-1.0, 1.0], span.size) * rng.uniform(0.01, 0.06, span.size)
    lt = rng.uniform(0.7, 1.3, (n_frames, n_muscles))
    h = mus.parallelogram_height
    l_mt = mus.tendon_slack_length + np.sqrt((lt * mus.optimal_fiber_length) ** 2 - h**2)
    v_mt = rng.uniform(-0.3, 0.3, (n_frames, n_muscles)) * 10 * mus.optimal_fiber_length
    f = mus.rigid_tendon_forces(l_mt, v_mt)
    R = pattern[None] * (1 + 0.3 * rng.uniform(-1, 1, (n_frames,) + pattern.shape))
    a = rng.uniform(0, 0.6, (n_frames, n_muscles))
    a *= np.minimum(1.0, 100.0 / np.abs(np.einsum("kij,kj->ki", R, f.active_force_per_activation * a)).max(1))[:, None]
    tau = np.einsum("kij,kj->ki", R, f.active_force_per_activation * a + f.passive_force)
    return mus, [f"q{i}" for i in range(n_coords)], R, f.active_force_per_activation, f.passive_force, tau


def direct_route(so, R, A, P, tau, n):
    """Median per-frame time of get_problem_data + clarabel.DefaultSolver, and of problem.solve."""
    import clarabel
    import cvxpy as cp
    import scipy.sparse as sp

    def set_params(k):
        so._B.value = R[k] * A[k]
        so._b.value = tau[k] - R[k] @ P[k]
        if so._c is not None:
            so._c.value = A[k] / so.stress_force_scale
            so._d.value = P[k] / so.stress_force_scale

    warnings.filterwarnings("ignore", message="Solution may be inaccurate")  # statuses are counted above
    set_params(0)
    so.problem.solve(solver=cp.CLARABEL)
    t_solve, t_direct = [], []
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    for k in range(1, n):
        set_params(k)
        t0 = time.perf_counter()
        so.problem.solve(solver=cp.CLARABEL)
        t_solve.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        data, chain, inverse = so.problem.get_problem_data(cp.CLARABEL)
        dims = data["dims"]
        cones = ([clarabel.ZeroConeT(dims.zero)] if dims.zero else []) + \
                ([clarabel.NonnegativeConeT(dims.nonneg)] if dims.nonneg else []) + \
                [clarabel.SecondOrderConeT(q) for q in dims.soc] + [clarabel.PowerConeT(a) for a in dims.p3d]
        nx = data["c"].size
        P_ = sp.triu(data["P"]).tocsc() if "P" in data else sp.csc_matrix((nx, nx))
        clarabel.DefaultSolver(P_, data["c"], data["A"], data["b"], cones, settings).solve()
        t_direct.append(time.perf_counter() - t0)
    return np.median(t_solve), np.median(t_direct)


def main(n_frames: int = 200, seed: int = 0) -> pd.DataFrame:
    rows = []
    for n_coords, n_muscles in ((6, 18), (23, 92)):
        mus, coords, R, A, P, tau = synthetic_trial(np.random.default_rng(seed), n_coords, n_muscles, n_frames)
        for criterion, epigraph in (("activation", "power_cone"), ("stress", "power_cone"), ("stress", "soc")):
            so = StaticOptimization.from_muscles(mus, coords, criterion=criterion, epigraph=epigraph,
                                                 reserve_optimal_force=1.0)
            df = so.solve_trial(np.arange(n_frames) / 60.0, R, A, P, tau)
            wall, clar = df["solve time [s]"].to_numpy(), df["solver time [s]"].to_numpy()
            solve, direct = direct_route(
                StaticOptimization.from_muscles(mus, coords, criterion=criterion, epigraph=epigraph,
                                                reserve_optimal_force=1.0), R, A, P, tau, min(n_frames, 100))
            rows.append({
                "muscles": n_muscles, "criterion": criterion, "epigraph": epigraph if criterion == "stress" else "QP",
                "first frame [ms]": 1e3 * wall[0],
                "median [ms]": 1e3 * np.median(wall[1:]), "p90 [ms]": 1e3 * np.percentile(wall[1:], 90),
                "Clarabel median [ms]": 1e3 * np.median(clar[1:]),
                "statuses": ", ".join(f"{k} {v}" for k, v in df["status"].value_counts().items()),
                "retried": int((df["message"] != "").sum()),
                "max residual [N m]": df["max |R F + r - tau| [N m]"].max(),
                "solve() [ms]": 1e3 * solve, "get_problem_data + clarabel [ms]": 1e3 * direct,
            })
    return pd.DataFrame(rows)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    from _calibration import calibrate, header_lines, with_calibration

    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    cal = calibrate()
    print("\n".join(header_lines(cal)))
    print(with_calibration(main(args.frames, args.seed), cal, ["median [ms]"]).to_markdown(index=False, floatfmt=".3g"))
