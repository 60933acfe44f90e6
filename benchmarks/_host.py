"""The machine a benchmark ran on, for the header of its results.

Wall times and real-time factors belong to a processor: the railway vehicle's real-time factor
was 0.78 on one host of this workplace and 1.92 on another, with the same code and step counts
within 0.1 % (docs, Railway vehicles, Speed).  A timed result names its host with
:func:`host_line`; both functions are :mod:`core.provenance`'s, which also records every scene run.
"""

from core.provenance import cpu_model, host_line

__all__ = ["cpu_model", "host_line"]
