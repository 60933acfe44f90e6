"""Railway wheel-rail contact mechanics and railway vehicles on the core.

Two halves, one sub-package each, over what both use (issue 22):

* :mod:`railway.contact` -- contact mechanics of a wheel on its rail: profiles
  (:mod:`~railway.contact.profiles`), wheel and rail surfaces (:mod:`~railway.contact.surfaces`),
  the four-condition contact search (:mod:`railway.contact.search`: seed scan, Newton solve,
  robust refinement, zone bookkeeping, compiled kernels), contact-geometry tables and
  conicity (:mod:`~railway.contact.geometry`), two-point contact
  (:mod:`~railway.contact.two_point`), creep laws (:mod:`~railway.contact.creep`), creepages
  (:mod:`~railway.contact.creepage`), creep curves (:mod:`~railway.contact.creep_curve`), Hertz and
  creep forces of a search's contacts (:mod:`~railway.contact.forces`), the quasi-static wheelset
  (:mod:`~railway.contact.quasi_static`) and the Manchester contact benchmark
  (:mod:`~railway.contact.manchester_contact`); the Hertz theory and the Lankarani-Nikravesh law
  are core's (:mod:`core.contact_laws`);
* :mod:`railway.vehicles` -- vehicle dynamics: vehicles from a TOML file
  (:mod:`~railway.vehicles.vehicle`, :mod:`~railway.vehicles.vehicle_file`), the wheel-rail contact
  as a force element of the core (:mod:`~railway.vehicles.wheel_rail`, its compiled kernels
  :mod:`~railway.vehicles.wheel_rail_compiled` and the rules both share,
  :mod:`~railway.vehicles.wheel_rail_rules`), speed control (:mod:`~railway.vehicles.traction`),
  the quasi-static curving start (:mod:`~railway.vehicles.curving_start`), hunting
  (:mod:`~railway.vehicles.hunting`) and the single-wheelset models
  (:mod:`~railway.vehicles.wheelset_models`);
* shared by both halves, so beside them: :mod:`railway.track` -- track centreline (straight,
  circular curve, clothoid), cant, irregularities, moving track frame (the vehicles run on it) and
  rail mounting (inclination, gauge at 14 mm: the contact searches on it);
  :mod:`railway.assessment` -- Nadal's limit, Hertz pressure, wear number, Y/Q per contact and
  wheel (the quasi-static contact and the force element report them) and the track-test
  statistics of wheel-force histories; :mod:`railway.ranges` -- plausible ranges of every input;
* :mod:`railway.cli` -- ``mbsuite railway ...`` sub-commands;
* :mod:`railway.scenes`, :mod:`railway.vehicle_scenes` -- scenes for ``mbsuite run``;
* :mod:`railway.moved_modules` -- the module paths before issue 22 (``railway.profiles``,
  ``railway.contact_search``, ``railway.wheel_rail``, ...) still import, as the same module,
  with a DeprecationWarning naming the new place.

Import direction: ``contact`` never imports ``vehicles``; ``track`` needs only
:mod:`railway.contact.profiles` (the rail profile it mounts).  A test (tests/railway/
test_architecture.py) keeps the package's import graph free of circles.

SI units throughout (m, rad); mm only in profile files and CLI output.
"""

from .moved_modules import install as _install_moved_modules
from .moved_modules import old_module_attribute as __getattr__

_install_moved_modules()

from .contact import (
    ContactForces,
    ContactResult,
    ContactSearch,
    RailProfile,
    RailSurface,
    WheelProfile,
    WheelSurface,
    conicity_table,
    contact_geometry_table,
    contact_transitions,
    equivalent_conicity,
    flange_contact_onset,
    quasi_static_contact,
    quasi_static_summary,
    read_profile_file,
    rigid_contact,
    s1002_exact,
    uic60_exact,
    wheelset_pose,
)
from .ranges import IrregularityStepWarning, RailwayInputWarning, SuspensionGeometryWarning
from .track import (
    Curve,
    Irregularities,
    RailMounting,
    Straight,
    Track,
    TrackFrame,
    Transition,
    parse_inclination,
)
from .vehicles import Vehicle, VehicleDefinition, WheelRailContact, build_vehicle, contact_history

__all__ = [
    "ContactForces",
    "ContactResult",
    "ContactSearch",
    "Curve",
    "Irregularities",
    "IrregularityStepWarning",
    "RailMounting",
    "RailwayInputWarning",
    "RailProfile",
    "RailSurface",
    "Straight",
    "SuspensionGeometryWarning",
    "Track",
    "TrackFrame",
    "Transition",
    "Vehicle",
    "VehicleDefinition",
    "WheelProfile",
    "WheelRailContact",
    "WheelSurface",
    "build_vehicle",
    "conicity_table",
    "contact_geometry_table",
    "contact_history",
    "contact_transitions",
    "equivalent_conicity",
    "flange_contact_onset",
    "parse_inclination",
    "quasi_static_contact",
    "quasi_static_summary",
    "read_profile_file",
    "rigid_contact",
    "s1002_exact",
    "uic60_exact",
    "wheelset_pose",
]
