"""Rules the two paths of the wheel–rail force element share: patches, seeds, derailment message.

The numpy element (:mod:`railway.vehicles.wheel_rail`) and its compiled kernels
(:mod:`railway.vehicles.wheel_rail_compiled`) apply the same rules; both import them from here,
so neither imports the other (issue 22).  The reasons for each value are in the docstring of
:mod:`railway.vehicles.wheel_rail` ("Two patches per zone", "The patch set of a wheel", "Nearby
minima").
"""

from __future__ import annotations

__all__ = ["ACCEPT_RANKS", "BLEND_GAP", "DUPLICATE", "NEIGHBOUR_OFFSETS", "SEPARATION", "climb_message"]

#: two penetrating minima of the gap in one zone at least this far apart on the wheel profile (m)
#: are two contact patches that share the load (wheel_rail's docstring, "Two patches per zone")
SEPARATION = 3e-3
#: gap difference (m) over which two overlapping patches hand the load over (wheel_rail's docstring)
BLEND_GAP = 1e-5
#: two patches of a wheel closer than this (m) on the wheel profile are one stationary point found
#: from both zones (wheel_rail's docstring, "The patch set of a wheel")
DUPLICATE = 1e-4
#: offsets (m) on the wheel profile of the extra seeds beside every penetrating contact after an
#: accepted step (wheel_rail's docstring, "Nearby minima")
NEIGHBOUR_OFFSETS = (-1.5e-3, -0.5e-3, 0.5e-3, 1.5e-3)
#: stationary points of the cross-section scan refined after an accepted step, per candidate: the
#: four lowest sign changes (two minima of the S1002 tread may have the maximum between them as
#: the second lowest)
ACCEPT_RANKS = 4


def climb_message(wheel_label, element, climb, profile, criterion, last):
    """The failure message of a flange-climb derailment (both paths)."""
    return (f"derailment of wheel {wheel_label!r} ({element}): flange climb -- its contact is "
            f"{climb * 1e3:.2f} mm (radius increase) above the top of the flank, the point of maximum "
            f"flange angle at y = {profile.y_flank_top * 1e3:.2f} mm (criterion {criterion * 1e3:g} mm); {last}")
