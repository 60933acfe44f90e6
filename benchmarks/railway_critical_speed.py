"""Nonlinear critical speed: the fixed-cost two-rate run-down against the bisection (issue 22).

The coach's nonlinear critical speed with Polach 2000 (the README's/docs' headline creep law) by
both methods of :func:`railway.vehicles.critical_speed.nonlinear_critical_speed` in one run: the
run-down at 2 m/s² shared, then (a) a second run-down at 0.5 m/s² and the extrapolation of the
threshold speed to zero rate, (b) the bisection of 3 s constant-speed runs to 0.1 m/s.  Reports the
two speeds, their difference against the ±0.2 m/s to which the bisected speed is quoted (its
spread across processors), and the wall time of each method as a ratio.

Run: ``.venv/bin/python benchmarks/railway_critical_speed.py [--law LAW]`` (about 10 minutes on
one core of the AMD EPYC host).  Writes ``benchmarks/results/railway_critical_speed.{csv,md}``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv=None) -> int:
    from _host import host_line

    from core.results import write_table
    from railway.vehicles.critical_speed import nonlinear_critical_speed

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--law", default="polach2000")
    args = p.parse_args(argv)
    from _calibration import WORKLOAD, calibrate, with_calibration

    cal = calibrate()
    out = nonlinear_critical_speed(dict(law=args.law, two_rate=True, bisect=True))
    row = out["row"]
    two_rate_cost = row["run-down wall time [s]"] + row["slow run-downs wall time [s]"]
    bisection_cost = row["run-down wall time [s]"] + row["bisection wall time [s]"]
    table = pd.DataFrame([{
        "creep law": args.law,
        "run-down estimate [m/s]": row["run-down estimate [m/s]"],
        "run-down estimate at 1 m/s2 [m/s]": row["run-down estimate at 1 m/s2 [m/s]"],
        "run-down estimate at 0.5 m/s2 [m/s]": row["run-down estimate at 0.5 m/s2 [m/s]"],
        "two-rate [m/s]": row["two-rate critical speed [m/s]"],
        "bisected [m/s]": row["bisected critical speed [m/s]"],
        "bracket [m/s]": row["bracket [m/s]"],
        "two-rate minus bisected [m/s]": row["two-rate minus bisected [m/s]"],
        "within ±0.2 m/s": abs(row["two-rate minus bisected [m/s]"]) <= 0.2,
        "two-rate wall time [s]": two_rate_cost,
        "bisection wall time [s]": bisection_cost,
        "cost ratio two-rate / bisection": two_rate_cost / bisection_cost,
        "constant-speed runs": row["constant-speed runs"],
        "host": host_line(),
        "calibration [s]": cal,
        "calibration workload": WORKLOAD,
    }])
    table = with_calibration(table, cal, ["two-rate wall time [s]", "bisection wall time [s]"])
    folder = Path(__file__).resolve().parent / "results"
    write_table(table, folder, "railway_critical_speed")
    print(host_line())
    print(table.T.to_string())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
