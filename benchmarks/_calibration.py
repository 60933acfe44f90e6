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

__all__ = ["WORKLOAD", "calibrate", "calibration_line", "header_lines", "with_calibration"]

_UNITS = {"[s]": 1.0, "[ms]": 1e-3, "[us]": 1e-6, "[µs]": 1e-6}


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


def header_lines(seconds: float) -> list[str]:
    """The processor line and the calibration line, for a results file or a printed table."""
    from _host import host_line

    return [f"Host: {host_line()}.", f"{calibration_line(seconds)}."]


def with_calibration(table, seconds: float, columns=None):
    """``table`` with a column ``<column> / calibration [-]`` after each time column (a unit of
    ``[s]``, ``[ms]`` or ``[us]`` in its name, or the given ``columns``): the time divided by the
    calibration workload's time measured in the same run."""
    out = table.copy()
    names = [c for c in out.columns if any(str(c).endswith(u) for u in _UNITS)] if columns is None else list(columns)
    for c in names:
        unit = next((u for u in _UNITS if str(c).endswith(u)), "[s]")
        base = str(c)[: -len(unit)].rstrip() if str(c).endswith(unit) else str(c)
        pos = list(out.columns).index(c) + 1
        out.insert(pos, f"{base} / calibration [-]", out[c].astype(float) * _UNITS[unit] / seconds)
    return out
