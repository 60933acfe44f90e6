r"""Roller-coaster scenes for ``mbsuite run`` (entry point ``mbsuite.scenes: coaster``).

Each scene's body is an example script under ``examples/coaster/`` (:func:`core.scenes.example_scene`):

* ``coaster-analytic`` — bodies on analytic tracks against closed forms
  (``examples/coaster/analytic.py``, the cases in :mod:`coaster.analytic_scene`).
* ``coaster-circuit`` — the three-car train of Pombo & Ambrósio (:mod:`coaster.train`) over the
  shared 4.9 km circuit (``examples/coaster/circuit.py``): chain lift on the ``Lift`` section, free
  running, a booster on the ``Launch`` section, brakes over the crest of the ``Brake`` section's
  hill to its end; speed, wheel forces and rider load factors along the track, peaks and time
  above the limits per section, the energy drift of the free-running section, a run with rolling
  resistance and drag, and the bank designed from the speed. Run settings:
  :data:`coaster.train.CIRCUIT_SETTINGS`, output every 0.25 s (0.5 s with ``--fast``).
* ``coaster-from-control-points`` — a user's own short track from a handful of control points,
  the train run over it and the rider's loads against the limits table
  (``examples/coaster/from_control_points.py``).
"""

from __future__ import annotations

from core.scenes import example_scene

from .analytic_scene import coaster_analytic_scene
from .train import CIRCUIT_SETTINGS

__all__ = ["coaster_scenes", "circuit_scene", "from_control_points_scene", "CIRCUIT_SETTINGS"]


def circuit_scene():
    """The ``coaster-circuit`` scene: the example script ``examples/coaster/circuit.py``."""
    return example_scene("coaster-circuit", "coaster/circuit.py",
                         "Three-car train over the 4.9 km circuit: speed, wheel forces, rider loads against limits",
                         "The train of Pombo & Ambrosio (3 cars, 2 bars, 6 wheelsets on path-following joints, 1 DOF) "
                         "over the shared circuit: chain lift, free running, booster, brakes; energy drift without "
                         "dissipation; a run with rolling resistance and drag and its outcome.")


def from_control_points_scene():
    """The ``coaster-from-control-points`` scene: ``examples/coaster/from_control_points.py``."""
    return example_scene("coaster-from-control-points", "coaster/from_control_points.py",
                         "A coaster from control points: a train over a user's track, rider loads against the limits",
                         "A short open track from 18 control points written in the script (quintic spline, "
                         "rotation-minimising frame banked for the energy speed), the three-car train released on its "
                         "crest, the rider's peak load factors and time above the acceleration limits over the ride.")


def coaster_scenes():
    """The coaster scenes (entry point ``mbsuite.scenes: coaster``)."""
    return [coaster_analytic_scene(), circuit_scene(), from_control_points_scene()]
