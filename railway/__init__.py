"""Railway wheel-rail contact mechanics and railway vehicles on the core.

Geometry half of the railway domain (the Hertz theory and the Lankarani-Nikravesh law are
core's, :mod:`core.contact_laws`; the creep laws live in :mod:`railway.creep`):

* :mod:`railway.profiles` -- S1002 wheel (analytic definition), UIC60 rail (arcs) and measured
  profiles, as smooth curves with first and second derivatives;
* :mod:`railway.track` -- track centreline (straight, circular curve, clothoid), cant,
  irregularities, moving track frame, rail mounting (inclination, gauge at 14 mm);
* :mod:`railway.surfaces` -- wheel surface of revolution and swept rail surface;
* :mod:`railway.contact_search` -- vectorised four-condition contact search (Pombo, Ambrosio &
  Silva 2007) with tread and flange candidates, global re-seeding and warm starts;
* :mod:`railway.contact_geometry` -- rigid contact-geometry table and equivalent conicity
  (EN 15302), flange lead with yaw;
* :mod:`railway.forces` -- Hertz + Lankarani-Nikravesh normal and creep forces of all contacts
  of a search in one (compiled) call, with the wheel-rail helpers (curvatures by wheel and rail
  radii, the steady-rolling engagement-velocity floor);
* :mod:`railway.two_point` -- two-point contact: conical profile, rigid onset, brute-force check;
* :mod:`railway.quasi_static` -- wheelset position under vertical wheel loads (elastic Hertz),
  and rolling with the creep forces in the balance (Manchester contact benchmark);
* :mod:`railway.assessment` -- Nadal's limit, Hertz pressure, wear number, Y/Q;
* :mod:`railway.wheel_rail` -- the wheel-rail contact as a force element of the core (all wheels
  of a model in one call; :mod:`railway.wheel_rail_compiled` its compiled kernels);
* :mod:`railway.vehicle` -- vehicles from a TOML file (car body, bogies, wheelsets, suspensions),
  static preload; :mod:`railway.traction` -- speed control along the track;
* :mod:`railway.curving_start` -- the quasi-static curving state: a vehicle's start in a curve or
  a transition at its speed (``Vehicle.equilibrium``, ``Vehicle.initial_state``);
* :mod:`railway.hunting` -- Klingel's wavelength and the critical speed of a suspended wheelset;
* :mod:`railway.wheelset_models` -- free and suspended single-wheelset models;
* :mod:`railway.scenes`, :mod:`railway.vehicle_scenes` -- scenes for ``mbsuite run``.

SI units throughout (m, rad); mm only in profile files and CLI output.
"""

from .contact_geometry import (
    conicity_table,
    contact_geometry_table,
    contact_transitions,
    equivalent_conicity,
    flange_contact_onset,
    rigid_contact,
)
from .contact_search import ContactResult, ContactSearch, wheelset_pose
from .forces import ContactForces
from .profiles import RailProfile, WheelProfile, read_profile_file, s1002_exact, uic60_exact
from .quasi_static import quasi_static_contact, quasi_static_summary
from .ranges import IrregularityStepWarning, RailwayInputWarning, SuspensionGeometryWarning
from .vehicle import Vehicle, VehicleDefinition, build_vehicle
from .wheel_rail import WheelRailContact, contact_history
from .surfaces import RailSurface, WheelSurface
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
