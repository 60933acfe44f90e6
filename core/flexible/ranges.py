"""Plausible ranges of the inputs of flexible components, and their check.

The ranges are data (``data/core/flexible_plausible_ranges.csv``, read once per process);
:class:`core.inputs.RangeTable` documents the columns and how a value outside its range is refused
with the likely unit slip named ("E = 210000 Pa ... did you mean 210000 MPa?").  A deliberate
outlier passes when its quantity is named in ``accept``.
"""

from __future__ import annotations

import functools

__all__ = ["ranges", "checked"]


@functools.cache
def ranges():
    """The :class:`core.inputs.RangeTable` of flexible components (read on first use, then cached)."""
    from ..inputs import RangeTable
    from ..paths import data_path

    return RangeTable.from_csv(data_path("core", "flexible_plausible_ranges.csv"))


def checked(quantity: str, value, where: str, accept=()) -> float:
    """``value`` (a number in the range's unit, or a string with its unit) in SI, checked against
    the range of ``quantity``; the message names ``where``."""
    return float(ranges().check(quantity, value, where=where, accept=accept))
