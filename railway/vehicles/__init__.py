"""Vehicle dynamics on the track: the other half of :mod:`railway` (issue 22).

* :mod:`railway.vehicles.vehicle` -- vehicles (car body, bogies, wheelsets, suspensions) on a
  track, static preload, equilibrium and initial state; :mod:`railway.vehicles.vehicle_file` --
  the checked TOML vehicle file;
* :mod:`railway.vehicles.wheel_rail` -- the wheel-rail contact as a force element of the core
  (all wheels of a model in one call), with :func:`~railway.vehicles.wheel_rail.contact_history`;
  :mod:`railway.vehicles.wheel_rail_compiled` -- its compiled kernels for core's compiled
  integrators (registered with the element when this package is imported);
  :mod:`railway.vehicles.wheel_rail_rules` -- the patch, seed and derailment rules both share;
* :mod:`railway.vehicles.traction` -- speed control along the track;
* :mod:`railway.vehicles.curving_start` -- the quasi-static curving state: a vehicle's start in a
  curve or a transition at its speed;
* :mod:`railway.vehicles.hunting` -- Klingel's wavelength and the critical speed of a suspended
  wheelset (closed forms and the linear wheelset);
* :mod:`railway.vehicles.wheelset_models` -- free and suspended single-wheelset models.

Builds on :mod:`core`, :mod:`railway.contact`, :mod:`railway.track`, :mod:`railway.assessment`
and :mod:`railway.ranges`.
"""

from . import wheel_rail_compiled  # noqa: F401  (registers WheelRailKind's compiled kernels)
from .curving_start import CurvingStart, quasi_static_curving
from .hunting import (
    TERMS,
    LinearWheelset,
    klingel_wavelength,
    suspended_wheelset_coefficients,
    suspended_wheelset_critical_speed,
    suspended_wheelset_matrices,
)
from .traction import TrackSpeedControl
from .vehicle import GRAVITY, Vehicle, VehicleDefinition, build_vehicle
from .vehicle_file import BUILTIN_RAILS, BUILTIN_WHEELS, RULES, VehicleFile, read_vehicle_file, vehicle_kwargs
from .wheel_rail import WheelRailContact, WheelRailKind, contact_history
from .wheelset_models import (
    TEXTBOOK,
    WHEELSET,
    eigen_critical_speed,
    free_wheelset,
    hunting_mode,
    linear_wheelset,
    suspended_wheelset,
)

__all__ = [
    "CurvingStart", "quasi_static_curving",
    "TERMS", "LinearWheelset", "klingel_wavelength", "suspended_wheelset_coefficients",
    "suspended_wheelset_critical_speed", "suspended_wheelset_matrices",
    "TrackSpeedControl",
    "GRAVITY", "Vehicle", "VehicleDefinition", "build_vehicle",
    "BUILTIN_RAILS", "BUILTIN_WHEELS", "RULES", "VehicleFile", "read_vehicle_file", "vehicle_kwargs",
    "WheelRailContact", "WheelRailKind", "contact_history",
    "TEXTBOOK", "WHEELSET", "eigen_critical_speed", "free_wheelset", "hunting_mode", "linear_wheelset",
    "suspended_wheelset",
]
