"""Coaster circuit speed and work-precision (issue 12's benchmarks).

1. Real-time factor of the full circuit: the three-car train (11 bodies, 72 coordinates, 71
   constraints) free running one lap of the 4945 m circuit without dissipation (from L = 10 m at
   8 m/s, 231 s simulated), compiled DOP853 with coordinate projection (the path-following joint
   on core's compiled path, coaster._kernels), at several tolerances: simulated time / integration
   wall time (outputs every 0.5 s, the roll-back checks every 40 s included; measured after a
   warm-up run that compiles the numba kernels, whose wall time is reported on its own) and the energy drift
   max|E − E0| relative to the peak kinetic energy.  Target: >= 10x real time with drift < 1e-4.
2. Error against run time on a lap segment (20 s of the Outbound descent from L1 = 700 m, up to
   46 m/s): error of the lead arc length at the end against a reference (jit-dop853-projection,
   rtol 1e-12), for the compiled explicit (jit-rk45, jit-dop853) and implicit (jit-radau)
   integrator and numpy's dop853 (scipy), over a tolerance grid (the numpy implicit methods
   need minutes here and are left out).

Run:  .venv/bin/python benchmarks/coaster_circuit.py [--quick]
Writes benchmarks/results/coaster_circuit.md, coaster_*.csv and coaster_work_precision.png.  One
process, one core; the machine was shared with other jobs when the committed numbers were taken
(see the file's header).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import pandas as pd

RESULTS = Path(__file__).resolve().parent / "results"


def real_time(tols=(1e-6, 1e-8, 1e-10)):
    from coaster.train import Train, circuit_frame, run_train

    fr, _, cl = circuit_frame()
    tr = Train(fr)
    w0 = time.perf_counter()
    run_train(tr, 10.0, 8.0, 30.0, rtol=1e-6, atol=1e-6)  # compile (or load numba's cache of) the kernels
    warmup = time.perf_counter() - w0
    Me = tr.p.total_mass + tr.p.n_wheelsets * tr.p.wheel_spin_mass
    rows = []
    for tol in tols:
        t0 = time.perf_counter()
        run = run_train(tr, 10.0, 8.0, 10.0 + cl.length, rtol=tol, atol=tol, output_step=0.5, chunk=40.0)
        total = time.perf_counter() - t0
        E = run.energy()
        drift = float(np.max(np.abs(E - E[0])) / (0.5 * Me * run.Ldot[:, 0].max() ** 2))
        rows.append({"method": run.meta["method"], "rtol = atol": tol, "status": run.status,
                     "simulated [s]": float(run.t[-1]), "integration wall [s]": run.wall_time,
                     "real-time factor": run.real_time_factor, "wall incl. outputs [s]": total,
                     "energy drift / T_peak": drift, "warm-up run incl. compilation [s]": warmup})
        print(rows[-1], flush=True)
    return pd.DataFrame(rows)


def work_precision(quick=False):
    from coaster.train import Train, circuit_frame
    from core.integrators import simulate

    fr, _, cl = circuit_frame()
    tr = Train(fr)
    m = tr.model(700.0, 12.0)
    T = 20.0
    iq, _ = tr.lead_index(m)
    ref = simulate(m, (0.0, T), "jit-dop853-projection", rtol=1e-12, atol=1e-12, t_eval=[0.0, T],
                   compute_multipliers=False)
    assert ref.status == "finished", ref.message
    L_ref = ref.q[-1, iq]
    grids = {"jit-dop853-projection": [1e-4, 1e-6, 1e-8, 1e-10], "jit-rk45-projection": [1e-4, 1e-6, 1e-8],
             "jit-radau-projection": [1e-4, 1e-6, 1e-8], "dop853-projection": [1e-4, 1e-6]}
    if quick:
        grids = {k: v[:2] for k, v in grids.items()}
    rows = []
    for method, tols in grids.items():
        for tol in tols:
            kw = dict(rtol=tol, atol=tol)
            simulate(m, (0.0, 0.05), method, t_eval=[0.0, 0.05], compute_multipliers=False, **kw)  # compile
            t0 = time.perf_counter()
            try:
                res = simulate(m, (0.0, T), method, t_eval=[0.0, T], compute_multipliers=False, **kw)
                wall = time.perf_counter() - t0
                err = abs(res.q[-1, iq] - L_ref) if res.status != "failed" else np.nan
                status, steps = res.status, res.counters.get("n_steps", 0)
            except Exception as exc:  # noqa: BLE001 - record, do not hide
                wall, err, status, steps = time.perf_counter() - t0, np.nan, f"error: {exc}", 0
            rows.append({"method": method, "rtol = atol": tol, "status": status, "wall [s]": wall,
                         "error of L1 at 20 s [m]": err, "steps": steps})
            print(rows[-1], flush=True)
    return pd.DataFrame(rows)


def _plot(wp, path):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 5))
    ax = fig.subplots()
    for method, g in wp.groupby("method", sort=False):
        g = g[np.isfinite(g["error of L1 at 20 s [m]"])]
        ax.loglog(g["wall [s]"], g["error of L1 at 20 s [m]"].clip(lower=1e-13), "o-", label=method)
    ax.set_xlabel("wall time [s] (20 s simulated)")
    ax.set_ylabel("error of the lead arc length after 20 s [m]")
    ax.set_title("Three-car train on the circuit's Outbound descent: error vs run time")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=120, bbox_inches="tight")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    from core.results import markdown_table

    from _calibration import calibrate, header_lines, with_calibration

    RESULTS.mkdir(exist_ok=True)
    cal = calibrate()
    rt = real_time((1e-6, 1e-8) if args.quick else (1e-6, 1e-8, 1e-10))
    wp = work_precision(args.quick)
    rt = with_calibration(rt, cal, ["integration wall [s]"])
    wp = with_calibration(wp, cal, ["wall [s]"])
    rt.to_csv(RESULTS / "coaster_real_time.csv", index=False)
    wp.to_csv(RESULTS / "coaster_work_precision.csv", index=False)
    _plot(wp, RESULTS / "coaster_work_precision.png")
    text = ["# Coaster circuit: real-time factor and work-precision", "",
            f"Python {sys.version.split()[0]}, {time.strftime('%Y-%m-%d')}; one process; see the module docstring "
            "of benchmarks/coaster_circuit.py for what is measured.", "", *header_lines(cal), "",
            "## Full circuit, one lap without dissipation", "", markdown_table(rt), "",
            "## Error against run time, 20 s of the Outbound descent", "", markdown_table(wp), "",
            "![work-precision](coaster_work_precision.png)", ""]
    (RESULTS / "coaster_circuit.md").write_text("\n".join(text), encoding="utf-8")


if __name__ == "__main__":
    main()
