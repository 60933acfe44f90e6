"""Biomechanics scenes for ``mbsuite run`` (entry point ``mbsuite.scenes: biomech``).

Each scene's body is an example script under ``examples/biomech/`` (:func:`core.scenes.example_scene`),
the script a user adapts for their own OpenSim trial (the model and trial files in one block at the
top of its Model cell):

* ``gait-inverse-dynamics`` — joint moments of hip, knee and ankle over the right gait cycle of
  OpenSim's subject01 walking trial on the gait10dof18musc model, from core's inverse dynamics of
  the Cartesian model driven by the measured joint angles (:mod:`biomech.inverse_dynamics`), side
  by side with OpenSim 4.6's inverse-dynamics tool when it is installed
  (``examples/biomech/gait_inverse_dynamics.py``).
* ``gait-muscle-forces`` — static optimisation of the muscles of gait10dof18musc and gait2392 per
  frame, two criteria (:mod:`biomech.muscle_forces`; ``examples/biomech/gait_muscle_forces.py``).

Each scene builds only what it needs: the inverse-dynamics scene reads no muscle and builds no
optimiser.
"""

from __future__ import annotations

from .inverse_dynamics import right_gait_cycle

__all__ = ["biomech_scenes", "right_gait_cycle"]


def biomech_scenes():
    """The biomechanics scenes (entry point ``mbsuite.scenes: biomech``)."""
    from core.scenes import example_scene

    return [
        example_scene("gait-inverse-dynamics", "biomech/gait_inverse_dynamics.py",
                      "Gait inverse dynamics: hip, knee and ankle moments over the gait cycle (gait10dof18musc)",
                      "Joint moments from measured joint angles as driving constraints on the Cartesian core "
                      "(Silva & Ambrosio 2003), subject01 walking trial, side by side with OpenSim's ID tool."),
        example_scene("gait-muscle-forces", "biomech/gait_muscle_forces.py",
                      "Gait muscle forces: hamstrings and triceps surae over the gait cycle, two criteria",
                      "Static optimisation of the 18 muscles of gait10dof18musc per frame (cvxpy + Clarabel): the "
                      "paper's sum of cubed muscle stresses and OpenSim's sum of squared activations, reserves, "
                      "per-frame status; side by side with OpenSim's static optimization."),
    ]
