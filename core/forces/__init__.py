r"""Force elements: declared per element, evaluated per kind in one vectorised call.

=====================  ========================================================================
module                 contents
=====================  ========================================================================
``protocol``           :class:`ForceElement`, :class:`ForceKind`, :class:`ForceEval`,
                       :class:`ForceJacobian`; the search-state hook of stateful kinds
``coordinates``        point Jacobians and element coordinates with exact Jacobians
``springs``            :class:`SpringDamper`, :class:`PointSpring`,
                       :class:`RotationalSpringDamper`, :class:`Bushing`, :class:`BumpStop`,
                       :class:`SeriesSpringDamper`
``loads``              :class:`AppliedForce`, :class:`AppliedTorque`
``contact``            :class:`PlaneContact` (laws from :mod:`core.contact_laws`)
=====================  ========================================================================

Gravity and the gyroscopic moments are built into :class:`core.model.Model`.  Domain packages
add force kinds the same way (the railway wheel–rail contact is one): a frozen dataclass
deriving from :class:`ForceElement` whose ``compile(elements, ctx)`` returns a
:class:`ForceKind`, added with ``ModelBuilder.add_force``.
"""

from .contact import PlaneContact, PlaneContactKind, hertz_sphere_plane_stiffness
from .loads import AppliedForce, AppliedForceKind, AppliedTorque, AppliedTorqueKind
from .protocol import ForceElement, ForceEval, ForceJacobian, ForceKind
from .springs import (
    BumpStop,
    BumpStopKind,
    Bushing,
    BushingKind,
    PointSpring,
    PointSpringKind,
    RotationalSpringDamper,
    RotationalSpringDamperKind,
    SeriesSpringDamper,
    SeriesSpringDamperKind,
    SpringDamper,
    SpringDamperKind,
)

__all__ = [
    "ForceElement",
    "ForceKind",
    "ForceEval",
    "ForceJacobian",
    "SpringDamper",
    "SpringDamperKind",
    "PointSpring",
    "PointSpringKind",
    "RotationalSpringDamper",
    "RotationalSpringDamperKind",
    "Bushing",
    "BushingKind",
    "BumpStop",
    "BumpStopKind",
    "SeriesSpringDamper",
    "SeriesSpringDamperKind",
    "AppliedForce",
    "AppliedForceKind",
    "AppliedTorque",
    "AppliedTorqueKind",
    "PlaneContact",
    "PlaneContactKind",
    "hertz_sphere_plane_stiffness",
]
