"""Biomechanics domain of mbsuite.

Segment models, gait inverse dynamics driven by measured joint angles, muscle
models and static optimisation (cvxpy, imported only inside this package). Builds on
:mod:`core` only; never imports ``railway`` or ``coaster``.
"""
