r"""Checked inputs of the coaster domain: plausible ranges and the named warnings.

The ranges are data (``data/coaster/plausible_ranges.csv``: quantity, label, SI unit, bounds and
the rationale of each) read once per process by :func:`ranges`; the public constructors and
functions of :mod:`coaster.track`, :mod:`coaster.frames` and :mod:`coaster.train` check what a
user gives them against it at the boundary (:meth:`core.inputs.RangeTable.check`), accept a
number in SI units or a string with its unit (``"900 kg"``, ``"1800 mm"``, ``"30 deg"``,
``"80 km/h"``, ``"2.5 %"``), and refuse an implausible value with the likely unit slip named::

    TrainParameters(car_mass=0.9): car mass (with riders) 0.9 kg is outside the plausible range
    100 kg ... 6 t: did you mean 0.9 t? (to use it deliberately, accept='car_mass')

A deliberate outlier is accepted by naming its quantity in the ``accept`` argument.

Consistency rules (what the inputs imply together) are checked where the inputs meet; a
contradiction that still leaves a meaningful run gives a finished run with a named warning
(:class:`OutwardBankWarning`), the others an :class:`core.errors.InputError`.
"""

from __future__ import annotations

import functools

from core.inputs import RangeTable
from core.paths import data_path

__all__ = ["ranges", "check", "OutwardBankWarning", "CoasterInputWarning"]


@functools.cache
def ranges() -> RangeTable:
    """The coaster range table (``data/coaster/plausible_ranges.csv``), read once per process."""
    return RangeTable.from_csv(data_path("coaster", "plausible_ranges.csv"))


def check(quantity: str, value, where: str = "", accept=(), unit: str | None = None):
    """``ranges().check(quantity, value, where=..., accept=..., unit=...)``: SI value(s)."""
    if isinstance(accept, str):
        accept = (accept,)
    return ranges().check(quantity, value, where=where, accept=accept or (), unit=unit)


class CoasterInputWarning(UserWarning):
    """Base of the coaster domain's warnings about inputs that still give a meaningful run."""


class OutwardBankWarning(CoasterInputWarning):
    """The track's bank tilts the riders out of its turns (the bank's sign disagrees with the
    sign of the lateral curvature over most of the lateral demand v² κ): the lateral loads are
    larger than on flat track.  :func:`coaster.track.check_bank` measures it,
    :func:`coaster.track.design_bank` offers a bank from the speed."""
