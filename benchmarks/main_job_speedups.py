"""The two hot-path speed-ups of issue 22, each as a ratio measured in one run.

1. Dense saddle-point factorisation (``core.dynamics._DENSE_KKT_MAX``): where M has no inverse,
   [[M, Φ_qᵀ], [Φ_q, 0]] is factored by a dense LU up to order 120 instead of being assembled as a
   sparse matrix at every solve.  Measured on Andrews' squeezer (radau-projection and
   dop853-projection, rtol 1e-7) and the 100-s pendulum's point mass (HEM4, h = 1e-2 s, 10 s),
   alternating the two routes (``_DENSE_KKT_MAX`` = 120 and 0) ``--rounds`` times; the median
   of each.
2. Batched evaluation at the accepted steps (``railway.vehicles.wheel_rail.ROW_BATCH``):
   ``contact_history(at="steps")`` of one recorded curving run (Polach 2000, 20 m/s, the first
   ``--span`` seconds), with the rows evaluated 256 at a time and one at a time (``ROW_BATCH`` =
   1, the cost of the row-by-row evaluation), alternating; the tables are compared.

Run: ``.venv/bin/python benchmarks/main_job_speedups.py`` (43 s on one core of the AMD EPYC host).
``ROW_BATCH = 1`` keeps the one call for the peak samples of a step, so its ratio understates the
gain over the evaluation before issue 22's batching (20.0 → 3.7 s on a full 20 m/s curving case).  Writes ``benchmarks/results/main_job_speedups.{csv,md}``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def _saddle_cases(rounds: int):
    import core.dynamics as dyn
    from core.benchmarks.problems import PROBLEMS
    from core.integrators import simulate

    cases = [("andrews", "radau-projection", dict(rtol=1e-7, atol=1e-7), None),
             ("andrews", "dop853-projection", dict(rtol=1e-7, atol=1e-7), None),
             ("pendulum-100s", "hem4", dict(h=1e-2), 10.0)]
    rows = []
    for name, method, opts, t_end in cases:
        p = PROBLEMS[name]
        system = p.build_system()
        span = (0.0, t_end if t_end is not None else p.t_end)
        times = {120: [], 0: []}
        finals = {}
        for _ in range(rounds):
            for limit in (120, 0):
                dyn._DENSE_KKT_MAX = limit
                wall, res = _timed(lambda: simulate(system, span, method, n_output=11, **opts))
                assert res.status != "failed", res.message
                times[limit].append(wall)
                finals[limit] = res.q[-1]
        dyn._DENSE_KKT_MAX = 120
        dense, sparse = statistics.median(times[120]), statistics.median(times[0])
        rows.append({"case": f"{name}, {method}", "new [s]": dense, "before [s]": sparse,
                     "speed-up before / new": sparse / dense,
                     "max |q_new - q_before|": float(np.max(np.abs(finals[120] - finals[0])))})
    return rows


def _history_case(rounds: int, span: float):
    import railway.vehicles.wheel_rail as wr
    from railway.vehicles.curving import run_curving

    res, veh = run_curving("polach2000", 20.0, T=span, record_steps=True)
    assert res.status == "finished", res.message
    times = {256: [], 1: []}
    tables = {}
    for _ in range(rounds):
        for batch in (256, 1):
            wr.ROW_BATCH = batch
            wall, H = _timed(lambda: wr.contact_history(veh.model, res, at="steps"))
            times[batch].append(wall)
            tables[batch] = H
    wr.ROW_BATCH = 256
    num = [c for c in tables[256].columns if tables[256][c].dtype.kind == "f"]
    a, b = tables[256][num].to_numpy(), tables[1][num].to_numpy()
    scale = np.maximum(np.abs(a), np.abs(b))
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.where(scale > 0, np.abs(a - b) / scale, 0.0)
    new, before = statistics.median(times[256]), statistics.median(times[1])
    return {"case": f"contact_history(at='steps'), curving Polach 2000 20 m/s, {span:g} s, "
                    f"{res.steps.t.size} accepted steps", "new [s]": new, "before [s]": before,
            "speed-up before / new": before / new,
            "max relative difference of the table": float(np.nanmax(rel))}


def main(argv=None) -> int:
    from _host import host_line

    from core.results import write_table

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=3)
    p.add_argument("--span", type=float, default=4.0, help="simulated seconds of the curving run")
    args = p.parse_args(argv)
    from _calibration import WORKLOAD, calibrate, with_calibration

    cal = calibrate()
    rows = _saddle_cases(args.rounds) + [_history_case(args.rounds, args.span)]
    table = with_calibration(pd.DataFrame(rows), cal, ["new [s]", "before [s]"])
    table["host"] = host_line()
    table["calibration [s]"] = cal
    table["calibration workload"] = WORKLOAD
    write_table(table, Path(__file__).resolve().parent / "results", "main_job_speedups")
    print(host_line())
    print(table.drop(columns="host").to_string())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
