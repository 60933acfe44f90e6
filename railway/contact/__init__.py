"""Contact mechanics of a wheel on its rail: one half of :mod:`railway` (issue 22).

* :mod:`railway.contact.profiles` -- S1002 wheel (analytic definition), UIC60 rail (arcs) and
  measured profiles, as smooth curves with first and second derivatives;
* :mod:`railway.contact.surfaces` -- wheel surface of revolution and swept rail surface;
* :mod:`railway.contact.search` -- vectorised four-condition contact search (Pombo, Ambrosio &
  Silva 2007) with tread and flange candidates, global re-seeding and warm starts: the seed
  scan, the Newton solve, the robust refinement and the zone bookkeeping one module each, and
  their compiled kernels;
* :mod:`railway.contact.geometry` -- rigid contact-geometry table and equivalent conicity
  (EN 15302), flange lead with yaw;
* :mod:`railway.contact.two_point` -- two-point contact: conical profile, rigid onset,
  brute-force check;
* :mod:`railway.contact.creep` -- creep laws, interchangeable behind one signature (Kalker
  linear, Shen-Hedrick-Elkins, Polach 2000/2005, FASTSIM) and their registry;
* :mod:`railway.contact.creepage` -- contact frame and rigid creepages of a contact;
* :mod:`railway.contact.creep_curve` -- creep force curves of any creep law;
* :mod:`railway.contact.forces` -- Hertz + Lankarani-Nikravesh normal and creep forces of all
  contacts of a search in one (compiled) call, with the wheel-rail helpers (curvatures by wheel
  and rail radii, the steady-rolling engagement-velocity floor);
* :mod:`railway.contact.quasi_static` -- wheelset position under vertical wheel loads (elastic
  Hertz), and rolling with the creep forces in the balance;
* :mod:`railway.contact.manchester_contact` -- the Manchester contact benchmark against CONTACT.

Builds on :mod:`core`, :mod:`railway.track` (rail mounting), :mod:`railway.assessment` and
:mod:`railway.ranges`; never imports :mod:`railway.vehicles` (tests/railway/test_architecture.py).
"""

from .creep import (
    CREEP_MODELS,
    CreepForces,
    CreepModel,
    Fastsim,
    KalkerLinear,
    Polach2000,
    Polach2005,
    ShenHedrickElkins,
    creep_forces,
    get_creep_model,
    kalker_coefficients,
    kalker_table,
    kalker_table_path,
    polach2005_parameter_sets,
    register_creep_model,
)
from .creep_curve import SEMI_AXIS_RANGE, plot_creep_curve, semi_axes_from_curvatures
from .creepage import contact_frame, creepages
from .forces import FORCE_KEYS, REDUCTIONS, ContactForces, lankarani_nikravesh_force, wheel_rail_curvatures
from .geometry import (
    conicity_table,
    contact_geometry_table,
    contact_transitions,
    equivalent_conicity,
    flange_contact_onset,
    rigid_contact,
)
from .manchester_contact import (MANCHESTER_A22, compare_with_contact, contact_reference_per_wheel,
                                 load_contact_reference, manchester_cases, rail_profile_check,
                                 run_manchester_a22)
from .profiles import (
    DATA_DIR,
    MIN_FLANGE_HEIGHT,
    R0_RANGE,
    ProfileCurve,
    RailProfile,
    WheelProfile,
    data_resolution,
    rail_crown_problem,
    read_profile_file,
    s1002_exact,
    uic60_exact,
)
from .quasi_static import (
    quasi_static_contact,
    quasi_static_rolling,
    quasi_static_summary,
    quasi_static_wheel_table,
)
from .search import FLANGE, TREAD, ContactResult, ContactSearch, wheelset_pose
from .surfaces import RailSurface, WheelSurface
from .two_point import conical_wheel, conical_wheel_points, gap_scan, local_minima, two_point_contact

# the function creep_curve.creep_curve is not re-exported: it would hide the module
# railway.contact.creep_curve behind the package attribute of the same name
__all__ = [
    "CREEP_MODELS", "CreepForces", "CreepModel", "Fastsim", "KalkerLinear", "Polach2000", "Polach2005",
    "ShenHedrickElkins", "creep_forces", "get_creep_model", "kalker_coefficients", "kalker_table",
    "kalker_table_path", "polach2005_parameter_sets", "register_creep_model",
    "SEMI_AXIS_RANGE", "plot_creep_curve", "semi_axes_from_curvatures",
    "contact_frame", "creepages",
    "FORCE_KEYS", "REDUCTIONS", "ContactForces", "lankarani_nikravesh_force", "wheel_rail_curvatures",
    "conicity_table", "contact_geometry_table", "contact_transitions", "equivalent_conicity",
    "flange_contact_onset", "rigid_contact",
    "MANCHESTER_A22", "compare_with_contact", "contact_reference_per_wheel", "load_contact_reference",
    "manchester_cases", "rail_profile_check", "run_manchester_a22",
    "DATA_DIR", "MIN_FLANGE_HEIGHT", "R0_RANGE", "ProfileCurve", "RailProfile", "WheelProfile",
    "data_resolution", "rail_crown_problem", "read_profile_file", "s1002_exact", "uic60_exact",
    "quasi_static_contact", "quasi_static_rolling", "quasi_static_summary", "quasi_static_wheel_table",
    "FLANGE", "TREAD", "ContactResult", "ContactSearch", "wheelset_pose",
    "RailSurface", "WheelSurface",
    "conical_wheel", "conical_wheel_points", "gap_scan", "local_minima", "two_point_contact",
]
