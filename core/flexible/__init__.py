"""Flexible bodies: the finite-element models and their modal reduction (issue 23).

A flexible body in a multibody model is described, as in Shabana's floating frame of reference and
in the standard input data that Simpack and Adams read, by a reduced linear elastic component: a
few mode shapes of a finite-element model, their modal mass and stiffness, and the shapes at the
nodes where joints and forces attach.  This package makes those components:

* :mod:`core.flexible.beam` -- beam finite elements (Euler–Bernoulli and Timoshenko, planar and
  spatial), consistent mass and stiffness, assembled sparse;
* :mod:`core.flexible.fe_model` -- a component's nodes, mass and stiffness, from the beam elements
  or read from another FE code (Matrix Market matrices, CSV nodes, the model's units converted);
* :mod:`core.flexible.continuum` -- plane-stress and solid components assembled by scikit-fem, and
  their nodal stresses;
* :mod:`core.flexible.reduction` -- normal modes with scipy's sparse eigensolver, Craig–Bampton
  reduction (fixed-interface modes plus the static constraint modes of the interface nodes) and
  free-interface modes with static correction (residual attachment modes with inertia relief),
  into a :class:`~core.flexible.reduction.ModalComponent`.

The floating-frame body kind itself is :mod:`core.flexible.body` (and, for mean-axis bodies with
the undeformed inertia, :mod:`core.flexible.compiled`); :mod:`core.flexible.models` holds the
canonical models (spin-up beam, elastic slider crank, SAR antenna) with their independent
references.  Not here: HDF5 import (Matrix Market only).
"""

from .beam import BeamMesh, BeamSection, beam_matrices, straight_beam
from .continuum import ContinuumStresses, plane_stress_model, solid_model, von_mises
from .fe_model import FEModel
from .reduction import ModalComponent, craig_bampton, free_interface, normal_modes, rigid_body_modes

__all__ = ["BeamMesh", "BeamSection", "ContinuumStresses", "FEModel", "ModalComponent", "beam_matrices",
           "craig_bampton", "free_interface", "normal_modes", "plane_stress_model", "rigid_body_modes", "solid_model",
           "straight_beam", "von_mises"]
