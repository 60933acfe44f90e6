"""The machine a benchmark ran on, for the header of its results.

Wall times and real-time factors belong to a processor: the railway vehicle's real-time factor
was 0.78 on one host of this workplace and 1.92 on another, with the same code and step counts
within 0.1 % (README, Railway vehicles, Speed).  A timed result names its host with
:func:`host_line`.
"""

from __future__ import annotations

import os
import platform
from pathlib import Path


def cpu_model() -> str:
    """Processor name with family/model/stepping from ``/proc/cpuinfo`` (Linux), else
    ``platform.processor()``; "unknown" when neither says."""
    info = {}
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            key = key.strip()
            if key in ("model name", "cpu family", "model", "stepping") and key not in info:
                info[key] = value.strip()
            if not line.strip() and info:
                break
    except OSError:
        pass
    if "model name" in info:
        extra = ", ".join(f"{k} {info[k]}" for k in ("cpu family", "model", "stepping") if k in info)
        return f"{info['model name']} ({extra})" if extra else info["model name"]
    return platform.processor() or "unknown"


def host_line() -> str:
    """One line: processor, logical cores, Python and the numerical libraries' versions."""
    import numpy as np

    parts = [f"{cpu_model()}, {os.cpu_count()} logical cores", f"Python {platform.python_version()}",
             f"numpy {np.__version__}"]
    try:
        import numba

        parts.append(f"numba {numba.__version__}")
    except ImportError:  # pragma: no cover - numba is optional
        parts.append("no numba")
    return "; ".join(parts)
