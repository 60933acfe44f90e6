"""Roller-coaster domain of mbsuite.

Track centre-line curves and their moving frames, the path-following joint with the
arc length as an extra coordinate, trains and rider loads. Builds on :mod:`core`
only; never imports ``railway`` or ``biomech``.
"""
