"""A fixed calibration workload, timed beside every benchmark, so that figures from different
hosts can be compared.

A wall time belongs to its processor and to whatever else the machine was doing: the railway
vehicle's real-time factor was 0.78 on one host of this workplace and 1.92 on another with the
same code.  Each benchmark therefore also times this workload, in the same process and just
before its own cases, and reports every time of its own as a multiple of it (``/ calibration``).
Two hosts that disagree on a wall time but agree on the multiple ran the same code equally well;
a multiple that changes between versions on one host is a change of the code.

The workload is the unchanged plain numpy + scipy baseline of the 8-link rigid chain
(:func:`_numpy_baseline.solve_chain`: dense KKT solve in every right-hand side, scipy's DOP853 at
rtol = atol = 1e-8 over 1 s, 1.6e3 right-hand sides): a mix of Python call overhead and small
dense linear algebra like the hot paths of mbsuite's numpy code.  It depends on numpy and scipy
only, never on mbsuite, so a change in mbsuite cannot move it; the numpy and scipy versions are
in the header (:func:`_host.host_line`).  Best of ``repeats`` runs after one warm-up.
"""

from __future__ import annotations

import time

import _numpy_baseline as npb

WORKLOAD = ("plain numpy + scipy 8-link rigid chain (dense KKT, scipy DOP853, rtol 1e-8, 1 s; "
            "benchmarks/_numpy_baseline.py)")

__all__ = ["WORKLOAD", "calibrate", "calibration_line"]


def calibrate(repeats: int = 5) -> float:
    """Best wall time [s] of the calibration workload on this host, now."""
    npb.solve_chain(8, 1e-8)  # warm-up: imports, caches
    best = float("inf")
    for _ in range(max(1, repeats)):
        t0 = time.perf_counter()
        npb.solve_chain(8, 1e-8)
        best = min(best, time.perf_counter() - t0)
    return best


def calibration_line(seconds: float) -> str:
    """The header line that states the calibration and how to read the ``/ calibration`` columns."""
    return (f"Calibration: the {WORKLOAD} took {seconds:.4f} s (best of 5) in this run; a column "
            f"'/ calibration' gives a time as a multiple of it, comparable between hosts")
