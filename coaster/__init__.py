"""Roller-coaster domain of mbsuite.

Track centre-line curves and their moving frames (:mod:`coaster.track`, :mod:`coaster.frames`),
the path-following joint with the arc length as an extra coordinate (:mod:`coaster.path_joint`,
compiled kernel in :mod:`coaster._kernels`), the three-car train with chain lift, track forces,
roll-back detection and wheel forces (:mod:`coaster.train`), rider loads (:mod:`coaster.rider`),
figures of a run (:mod:`coaster.plots`) and the scenes (:mod:`coaster.scenes`, bodies in
``examples/coaster/``).  Builds on :mod:`core` only; never imports ``railway``
or ``biomech``.
"""
