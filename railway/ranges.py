"""Plausible ranges of the railway inputs and the named warnings of the input checks.

The ranges are data (``data/railway/plausible_ranges.csv``, read once per process by
:func:`ranges`); :mod:`core.inputs` documents the columns and how a value outside its range is
refused with the likely unit slip named.  The vehicle file (:mod:`railway.vehicles.vehicle_file`), the
track (:mod:`railway.track`), the profile readers and :func:`railway.vehicles.vehicle.build_vehicle` check
their inputs against this one table.
"""

from __future__ import annotations

import functools

__all__ = ["ranges", "RailwayInputWarning", "IrregularityStepWarning", "SuspensionGeometryWarning"]


@functools.cache
def ranges():
    """The railway :class:`core.inputs.RangeTable` (read on first use, then cached)."""
    from core.inputs import RangeTable
    from core.paths import data_path

    return RangeTable.from_csv(data_path("railway", "plausible_ranges.csv"))


class RailwayInputWarning(UserWarning):
    """Base of the named warnings of the railway input checks: the input is usable but
    physically doubtful; the message names what and why."""


class IrregularityStepWarning(RailwayInputWarning):
    """An irregularity table that does not start or end at zero: the centreline steps by the
    end value where the table ends (irregularities are zero outside it)."""


class SuspensionGeometryWarning(RailwayInputWarning):
    """Heights of a vehicle in an unusual order (e.g. the secondary suspension above the car
    body's centre of gravity, as in a pendular coach)."""
