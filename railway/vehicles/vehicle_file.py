r"""The vehicle file: its declared schema, units, plausible ranges and consistency rules.

A vehicle file (TOML, ``data/railway/vehicles/*.toml``) is read by
:meth:`railway.vehicles.vehicle.VehicleDefinition.from_toml`, which calls :func:`read_vehicle_file`.
Every table is a pydantic model (:class:`core.inputs.InputModel`: unknown keys refused with the
closest valid key suggested, ``[secondary] yaw_stifness: unknown key; did you mean
'yaw_stiffness'?``); every physical value is a quantity with a documented plausible range
(``data/railway/plausible_ranges.csv``, :func:`railway.ranges.ranges`).

Units
-----
A bare number is in SI (kg, m, N/m, N s/m, N m/rad, kg m²); a string carries its unit and is
converted by pint: ``mass = "32 t"``, ``stiffness = ["31.4 MN/m", "3.88 MN/m", "1.22 MN/m"]``,
``car_body_cg_height = "1800 mm"``.  A value outside its plausible range is refused with the
likely slip named (``car body mass 32 kg is outside the plausible range 1 t ... 200 t: did you
mean 32 t?``); a deliberate outlier is accepted by naming its quantity in the file's
``[checks] accept = ["car_body_mass"]`` or in ``accept=`` of the reading function.

Tables
------
``[vehicle]`` name, source (optional); ``[profiles]`` wheel ("S1002" or a profile file in mm,
relative to the vehicle file), rail ("UIC60" or a file), inclination ("1:40", "1/40", 0.025,
"vertical"), gauge, nominal_wheel_radius, flange_back_spacing; ``[geometry]``
bogie_centre_semi_distance, bogie_semi_wheelbase, primary_lateral_semi_spacing,
secondary_lateral_semi_spacing, car_body_cg_height, bogie_cg_height, secondary_height (heights
above the rail top); ``[car_body]``, ``[bogie]``, ``[wheelset]`` mass, inertia (about x, y, z: a
list of 3, or one number for all three); optional ``[car_body.flexible]`` (a flexible car body,
:mod:`railway.vehicles.car_body`): length, vertical_bending_frequency, optional torsion_frequency
and lateral_bending_frequency (free–free, in Hz; a string in rad/s is refused), damping_ratio
(default 0.02, or "2 %"), elements (default 24) -- or, instead of the beam, an FE model exported by
another code: mass_matrix, stiffness_matrix (Matrix Market), nodes (CSV), dofs_per_node (3 or 6,
default 6), length_unit, mass_unit, force_unit (defaults m, kg, N), modes (1 to 6, default 4),
centre_node and bogie_nodes (rows of the node file from 0), damping_ratio
(:func:`railway.vehicles.car_body.imported_car_body`); ``[primary]`` stiffness, damping (x, y, z per axlebox);
``[secondary]`` stiffness, damping (x, y, z per side), yaw_stiffness (per side, default 0);
optional ``[anti_roll_bar]`` stiffness (per bogie); optional ``[lateral_bump_stop]``
displacement, force (first row the clearance at 0 N); optional ``[[yaw_damper]]`` damping,
series_stiffness, node_mass, x, y, z (all required); optional ``[checks]`` accept.  A damping
coefficient, the yaw stiffness and the anti-roll bar may be 0 (no such element).

Consistency rules
-----------------
What the values imply together is checked after each value passed its range (an error names
both keys; a rule's name in ``accept`` waives it):

* ``wheelset_spacing``: bogie_semi_wheelbase > nominal_wheel_radius (the wheels of one bogie do
  not overlap) and bogie_centre_semi_distance - bogie_semi_wheelbase > nominal_wheel_radius (the
  inner wheelsets of the two bogies neither overlap nor cross);
* ``flange_back_clearance``: 30 mm <= gauge - flange_back_spacing <= 200 mm (the flange backs lie
  inside the rails with room for the flanges: 75 mm on standard gauge);
* ``cg_height_order``: bogie_cg_height < car_body_cg_height, and the wheelset centre
  (nominal_wheel_radius) below the car body's centre of gravity;
* the axle load (total mass / 4) and the static deflections of the primary and secondary springs
  under the weight, (m_c/2 + m_b) g / (4 k_1z) and m_c g / (4 k_2z), within their ranges
  (``axle_load``, ``primary_static_deflection``, ``secondary_static_deflection``): a stiffness
  in kN/m read as N/m deflects by metres;
* a secondary suspension above the car body's centre of gravity (a pendular coach) is allowed
  with a :class:`railway.ranges.SuspensionGeometryWarning`.
"""

from __future__ import annotations

import tomllib
import warnings
from pathlib import Path
from typing import Annotated, Optional, Union

import numpy as np
from pydantic import BeforeValidator, ValidationInfo

from core.errors import DataFileError, InputError
from core.inputs import ImplausibleValueError, InputModel, closest, parse_quantity, validate

from ..ranges import SuspensionGeometryWarning, ranges

__all__ = ["read_vehicle_file", "vehicle_kwargs", "VehicleFile", "RULES", "BUILTIN_WHEELS", "BUILTIN_RAILS"]

#: gravitational acceleration (m/s²) of the vehicles: static deflections, wheel loads, the models'
#: gravity (one definition; :mod:`railway.vehicles.vehicle` and the curving start import it)
GRAVITY = 9.81

#: Names of the consistency rules (accepted in ``accept`` like quantity names).
RULES = ("wheelset_spacing", "flange_back_clearance", "cg_height_order")

#: Built-in profiles by the names a file may use (case-insensitive).
BUILTIN_WHEELS = ("S1002",)
BUILTIN_RAILS = ("UIC60", "60E1")


def _accept(info) -> set:
    return set((info.context or {}).get("accept", ())) if info is not None else set()


def _number(value, unit, label):
    """SI value of one entry (number or string with unit), for the sign check."""
    return float(parse_quantity(value, unit, where=label))


def _checked(qname: str, value, accept: set, *, zero_ok: bool = False, label: str | None = None):
    """One value of quantity ``qname``: parsed, sign-checked, range-checked."""
    R = ranges()
    r = R[qname]
    label = label or r.label
    v = _number(value, r.unit, label)
    if zero_ok and v == 0.0:
        return 0.0
    if r.low >= 0 and v < 0:
        raise ValueError(f"{label} = {value!r} must be {'>= 0' if zero_ok else '> 0'}")
    return float(R.check(qname, value, accept=accept))


def Q(qname: str, *, zero_ok: bool = False):
    """A scalar quantity field (SI float): units, sign, plausible range; 0 allowed if ``zero_ok``."""
    def _v(value, info: ValidationInfo):
        return _checked(qname, value, _accept(info), zero_ok=zero_ok)

    return Annotated[float, BeforeValidator(_v)]


def V(qnames, *, zero_ok: bool = False, what: str = "x, y, z"):
    """A 3-vector field (x, y, z), each component checked against its own quantity (a list of 3
    names) or all against one; a single number stands for all three."""
    names = [qnames] * 3 if isinstance(qnames, str) else list(qnames)

    def _v(value, info: ValidationInfo):
        if isinstance(value, (int, float, str)) and not isinstance(value, bool):
            value = [value] * 3
        if not isinstance(value, (list, tuple)) or len(value) != 3:
            raise ValueError(f"must be 3 values ({what}) or one for all three, got {value!r}")
        acc = _accept(info)
        out = []
        for i, (q, x) in enumerate(zip(names, value)):
            out.append(_checked(q, x, acc, zero_ok=zero_ok, label=f"{ranges()[q].label} [{i}] ({what.split(', ')[i]})"))
        return tuple(out)

    return Annotated[tuple[float, float, float], BeforeValidator(_v)]


def L(qname: str, *, min_len: int = 2):
    """A list of values of one quantity (a table column)."""
    def _v(value, info: ValidationInfo):
        if not isinstance(value, (list, tuple)) or len(value) < min_len:
            raise ValueError(f"must be a list of at least {min_len} values, got {value!r}")
        acc = _accept(info)
        return tuple(_checked(qname, x, acc, zero_ok=True, label=f"{ranges()[qname].label} [{i}]")
                     for i, x in enumerate(value))

    return Annotated[tuple[float, ...], BeforeValidator(_v)]


def _wheel_radius(value, info):
    """The nominal rolling radius, with the diameter slips named (920 for 920 mm, 0.92 m)."""
    R = ranges()
    r = R["nominal_wheel_radius"]
    acc = _accept(info)
    v = _number(value, r.unit, r.label)
    if "nominal_wheel_radius" not in acc and not r.contains(v) and v > 0:
        guesses = [f"{words}; the radius is {v * factor:g} m" for factor, words in
                   ((1e-3, "a radius in mm"), (0.5e-3, "a wheel diameter in mm"), (0.5, "a wheel diameter"))
                   if r.contains(v * factor)]
        if guesses:
            raise ImplausibleValueError(
                f"{r.label} {value!r} m is outside the plausible range {r.describe()}: it looks like "
                f"{', or '.join(guesses)} (to use it deliberately, accept='nominal_wheel_radius')",
                "nominal_wheel_radius", v, guesses[0])
    return _checked("nominal_wheel_radius", value, acc)


def _inclination(value, info):
    from ..track import parse_inclination

    parse_inclination(value)  # raises InputError naming the value
    return value


# ---------------------------------------------------------------------------------------------
# tables
# ---------------------------------------------------------------------------------------------
class VehicleTable(InputModel):
    name: Optional[str] = None
    source: str = ""


class Profiles(InputModel):
    wheel: str = "S1002"
    rail: str = "UIC60"
    inclination: Annotated[Union[str, float], BeforeValidator(_inclination)] = "1:40"
    gauge: Q("gauge")
    nominal_wheel_radius: Annotated[float, BeforeValidator(_wheel_radius)]
    flange_back_spacing: Q("flange_back_spacing")


class Geometry(InputModel):
    bogie_centre_semi_distance: Q("bogie_centre_semi_distance")
    bogie_semi_wheelbase: Q("bogie_semi_wheelbase")
    primary_lateral_semi_spacing: Q("primary_lateral_semi_spacing")
    secondary_lateral_semi_spacing: Q("secondary_lateral_semi_spacing")
    car_body_cg_height: Q("car_body_cg_height")
    bogie_cg_height: Q("bogie_cg_height")
    secondary_height: Q("secondary_height")


_ROT = "roll, pitch, yaw"


def F(qname: str):
    """A frequency field [Hz]: as :func:`Q`, refusing angular-frequency units (pint reads '60 rad/s'
    as 60 Hz: it drops the 2π)."""
    def _v(value, info: ValidationInfo):
        if isinstance(value, str) and "rad" in value:
            raise ValueError(f"{value!r}: give the frequency in Hz (cycles per second); an angular frequency "
                             "in rad/s would be read without its 2π")
        return _checked(qname, value, _accept(info))

    return Annotated[float, BeforeValidator(_v)]


def _elements(value):
    if isinstance(value, bool) or not isinstance(value, int) or not 4 <= value <= 400:
        raise ValueError(f"must be a whole number of beam elements from 4 to 400, got {value!r}")
    return value


def _node(value):
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"must be a node number (a row of the node file, counting from 0), got {value!r}")
    return value


def _unit_name(value):
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"must be a unit name such as 'm', 'mm', 'kg', 't', 'N', got {value!r}")
    return value


#: keys of ``[car_body.flexible]`` for the equivalent beam and for an imported FE model
BEAM_KEYS = ("length", "vertical_bending_frequency", "torsion_frequency", "lateral_bending_frequency", "elements")
IMPORT_KEYS = ("mass_matrix", "stiffness_matrix", "nodes", "dofs_per_node", "length_unit", "mass_unit", "force_unit",
               "modes", "centre_node", "bogie_nodes")
_IMPORT_REQUIRED = ("mass_matrix", "stiffness_matrix", "nodes", "centre_node", "bogie_nodes")


class FlexibleCarBody(InputModel):
    """``[car_body.flexible]``: the car body as a free–free equivalent beam, or an FE model exported
    by another code (:mod:`railway.vehicles.car_body`); one or the other."""

    length: Optional[Q("car_body_length")] = None
    vertical_bending_frequency: Optional[F("car_body_bending_frequency")] = None
    torsion_frequency: Optional[F("car_body_torsion_frequency")] = None
    lateral_bending_frequency: Optional[F("car_body_lateral_bending_frequency")] = None
    damping_ratio: Q("car_body_damping_ratio", zero_ok=True) = 0.02
    elements: Annotated[int, BeforeValidator(_elements)] = 24
    mass_matrix: Optional[str] = None
    stiffness_matrix: Optional[str] = None
    nodes: Optional[str] = None
    dofs_per_node: int = 6
    length_unit: Annotated[str, BeforeValidator(_unit_name)] = "m"
    mass_unit: Annotated[str, BeforeValidator(_unit_name)] = "kg"
    force_unit: Annotated[str, BeforeValidator(_unit_name)] = "N"
    modes: int = 4
    centre_node: Optional[Annotated[int, BeforeValidator(_node)]] = None
    bogie_nodes: Optional[list[Annotated[int, BeforeValidator(_node)]]] = None


class CarBody(InputModel):
    mass: Q("car_body_mass")
    inertia: V(["car_body_roll_inertia", "car_body_pitch_inertia", "car_body_yaw_inertia"], what=_ROT)
    flexible: Optional[FlexibleCarBody] = None


class Bogie(InputModel):
    mass: Q("bogie_mass")
    inertia: V(["bogie_roll_inertia", "bogie_pitch_inertia", "bogie_yaw_inertia"], what=_ROT)


class Wheelset(InputModel):
    mass: Q("wheelset_mass")
    inertia: V(["wheelset_roll_inertia", "wheelset_spin_inertia", "wheelset_yaw_inertia"], what="roll, spin, yaw")


class Primary(InputModel):
    stiffness: V(["primary_stiffness_x", "primary_stiffness_y", "primary_stiffness_z"])
    damping: V("primary_damping", zero_ok=True)


class Secondary(InputModel):
    stiffness: V(["secondary_stiffness_x", "secondary_stiffness_y", "secondary_stiffness_z"])
    damping: V("secondary_damping", zero_ok=True)
    yaw_stiffness: Q("secondary_yaw_stiffness", zero_ok=True) = 0.0


class AntiRollBar(InputModel):
    stiffness: Q("anti_roll_bar_stiffness", zero_ok=True)


class BumpStop(InputModel):
    displacement: L("bump_stop_displacement")
    force: L("bump_stop_force")


class YawDamper(InputModel):
    damping: Q("yaw_damper_damping")
    series_stiffness: Q("yaw_damper_series_stiffness")
    node_mass: Q("yaw_damper_node_mass")
    x: Q("yaw_damper_x")
    y: Q("yaw_damper_y")
    z: Q("yaw_damper_z")


class Checks(InputModel):
    accept: Union[list[str], str] = []


class VehicleFile(InputModel):
    """The whole vehicle file (module docstring)."""

    vehicle: VehicleTable = VehicleTable()
    profiles: Profiles
    geometry: Geometry
    car_body: CarBody
    bogie: Bogie
    wheelset: Wheelset
    primary: Primary
    secondary: Secondary
    anti_roll_bar: Optional[AntiRollBar] = None
    lateral_bump_stop: Optional[BumpStop] = None
    yaw_damper: list[YawDamper] = []
    checks: Checks = Checks()


_REQUIRED = ("profiles", "geometry", "car_body", "bogie", "wheelset", "primary", "secondary")


# ---------------------------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------------------------
def _accept_list(d, source, accept, error):
    """The accepted outliers: the file's [checks] accept plus the caller's, names checked."""
    given = [accept] if isinstance(accept, str) else list(accept or ())
    chk = d.get("checks", {}) if isinstance(d, dict) else {}
    file_acc = chk.get("accept", []) if isinstance(chk, dict) else []
    if isinstance(file_acc, str):
        file_acc = [file_acc]
    if not isinstance(file_acc, list):
        raise error(f"{source} [checks] accept: must be a list of quantity names, got {file_acc!r}")
    known = [r.quantity for r in ranges()] + list(RULES)
    for where, names in ((f"{source} [checks] accept", file_acc), ("accept", given)):
        for n in names:
            if n not in known:
                raise error(f"{where}: {n!r} is not a quantity or rule name{closest(n, known)}")
    return sorted(set(given) | set(file_acc))


def _profile(spec, kind, base: Path | None, r0, source, error):
    from ..contact.profiles import RailProfile, WheelProfile

    builtin = BUILTIN_WHEELS if kind == "wheel" else BUILTIN_RAILS
    if spec.strip().upper() in builtin:
        if kind == "wheel":
            return WheelProfile.s1002(r0=r0)
        return RailProfile.uic60()
    p = Path(spec)
    if base is not None and not p.is_absolute():
        p = base / p
    if not p.is_file():
        hint = closest(spec.strip().upper(), builtin)
        raise error(f"{source} [profiles] {kind}: {spec!r} is neither a built-in {kind} profile "
                    f"({', '.join(builtin)}) nor a profile file ({p} does not exist){hint}")
    if kind == "wheel":
        return WheelProfile.from_file(p, r0=r0)
    return RailProfile.from_file(p)


def _consistency(vf: VehicleFile, source: str, accept: set, error):
    """The consistency rules of the module docstring."""
    pr, g = vf.profiles, vf.geometry
    r0 = pr.nominal_wheel_radius
    a_w, L_b = g.bogie_semi_wheelbase, g.bogie_centre_semi_distance
    if "wheelset_spacing" not in accept:
        if a_w >= L_b:
            raise error(
                f"{source} [geometry]: bogie_semi_wheelbase {a_w:g} m >= bogie_centre_semi_distance {L_b:g} m: "
                f"the wheelsets of the two bogies cross (a metre/millimetre slip, or the full wheelbase "
                f"or bogie distance given for the half?)")
        if L_b - a_w <= r0:
            raise error(
                f"{source} [geometry]: the inner wheelsets of the two bogies are {2 * (L_b - a_w):g} m apart "
                f"(2 (bogie_centre_semi_distance - bogie_semi_wheelbase)), less than a wheel diameter "
                f"{2 * r0:g} m: their wheels overlap (to use it deliberately, accept='wheelset_spacing')")
        if a_w <= r0:
            raise error(
                f"{source} [geometry]: bogie_semi_wheelbase {a_w:g} m <= nominal_wheel_radius {r0:g} m: the "
                f"wheels of one bogie overlap (is it the half of the wheelbase?) (to use it deliberately, "
                f"accept='wheelset_spacing')")
    if "flange_back_clearance" not in accept:
        gap = pr.gauge - pr.flange_back_spacing
        if gap <= 0:
            raise error(
                f"{source} [profiles]: flange_back_spacing {pr.flange_back_spacing:g} m >= gauge {pr.gauge:g} m: "
                f"the flange backs must lie inside the rails (1.360 m on the 1.435 m standard gauge)")
        if not 0.03 <= gap <= 0.2:
            raise error(
                f"{source} [profiles]: gauge - flange_back_spacing = {gap * 1e3:.4g} mm is outside 30 ... 200 mm "
                f"(75 mm on standard gauge: two flanges and their play) (to use it deliberately, "
                f"accept='flange_back_clearance')")
    if "cg_height_order" not in accept:
        if g.bogie_cg_height >= g.car_body_cg_height:
            raise error(
                f"{source} [geometry]: bogie_cg_height {g.bogie_cg_height:g} m >= car_body_cg_height "
                f"{g.car_body_cg_height:g} m: the car body rides on the bogies, its centre of gravity is "
                f"higher (to use it deliberately, accept='cg_height_order')")
        if r0 >= g.car_body_cg_height:
            raise error(
                f"{source} [geometry]: car_body_cg_height {g.car_body_cg_height:g} m is not above the wheelset "
                f"centre (nominal_wheel_radius {r0:g} m) (to use it deliberately, accept='cg_height_order')")
    if g.secondary_height > g.car_body_cg_height:
        warnings.warn(
            f"{source} [geometry]: secondary_height {g.secondary_height:g} m is above car_body_cg_height "
            f"{g.car_body_cg_height:g} m (a pendular suspension): check the heights",
            SuspensionGeometryWarning, stacklevel=4)
    # what the masses and stiffnesses imply
    R = ranges()
    mc, mb, mw = vf.car_body.mass, vf.bogie.mass, vf.wheelset.mass
    derived = [
        ("axle_load", (mc + 2 * mb + 4 * mw) / 4.0,
         "total mass / 4 from the [car_body], [bogie] and [wheelset] masses"),
        ("primary_static_deflection", (0.5 * mc + mb) * GRAVITY / (4.0 * vf.primary.stiffness[2]),
         "(m_car/2 + m_bogie) g / (4 [primary] stiffness z)"),
        ("secondary_static_deflection", mc * GRAVITY / (4.0 * vf.secondary.stiffness[2]),
         "m_car g / (4 [secondary] stiffness z)"),
    ]
    for q, v, how in derived:
        r = R[q]
        if q in accept or r.contains(v):
            continue
        if q == "axle_load":
            hint = "are the masses in kg?"
        elif v > r.high:
            hint = "are the stiffnesses in N/m (not kN/m)?"
        else:
            hint = "are the masses in kg (not t) and the stiffnesses in N/m?"
        msg = (f"{source}: the {r.label} implied by the file, {how} = {_fmt(v, r.unit)}, is outside the "
               f"plausible range {r.describe()}: {hint} (to use it deliberately, accept={q!r})")
        raise ImplausibleValueError(msg, q, v, "")


def _fmt(v, unit):
    if unit == "kg":
        return f"{v / 1000:.4g} t"
    if unit == "m" and abs(v) < 1:
        return f"{v * 1000:.4g} mm"
    return f"{v:.4g} {unit}"


def vehicle_kwargs(data: dict, *, source: str = "vehicle definition", base_dir=None, accept=()) -> dict:
    """Validate a vehicle definition given as nested dicts (a parsed TOML file) and return the
    keyword arguments of :class:`railway.vehicles.vehicle.VehicleDefinition` (SI units).

    Parameters
    ----------
    data : dict
        The file's tables (module docstring).
    source : str
        The file or function the data came from (every message starts with it).
    base_dir : path, optional
        Folder that profile file names are relative to.
    accept : sequence of str
        Quantities (rows of ``data/railway/plausible_ranges.csv``) and rules (:data:`RULES`)
        whose check is waived, in addition to the file's ``[checks] accept``.

    Raises
    ------
    DataFileError
        (``source`` a file) unknown or missing table or key, malformed value, broken rule.
    core.inputs.ImplausibleValueError
        A value outside its plausible range (the likely slip named).
    core.inputs.UnitError
        A unit of the wrong dimension or an unknown one.
    """
    error = DataFileError if str(source).endswith(".toml") else InputError
    if not isinstance(data, dict):
        raise error(f"{source}: expected tables of keys, got {type(data).__name__}")
    known = list(VehicleFile.model_fields)
    extra = [k for k in data if k not in known]
    if extra:
        hint = closest(extra[0], known)
        raise error(f"{source}: unknown table(s) {sorted(extra)}{hint}; known: {sorted(known)}")
    for t in _REQUIRED:
        if t not in data:
            raise error(f"{source}: missing table [{t}]")
    for t, val in data.items():
        if t == "yaw_damper":
            if not isinstance(val, list):
                raise error(f"{source}: yaw_damper must be an array of tables [[yaw_damper]], got {val!r}")
        elif not isinstance(val, dict):
            raise error(f"{source}: {t} must be a table [{t}], got {val!r}")
    acc = _accept_list(data, source, accept, error)
    vf = validate(VehicleFile, data, source=str(source), context={"accept": acc}, error=error)
    _consistency(vf, str(source), set(acc), error)
    pr = vf.profiles
    base = None if base_dir is None else Path(base_dir)
    wheel = _profile(pr.wheel, "wheel", base, pr.nominal_wheel_radius, source, error)
    rail = _profile(pr.rail, "rail", base, pr.nominal_wheel_radius, source, error)
    g = vf.geometry.model_dump()

    def body(b):
        return {"mass": b.mass, "inertia": np.array(b.inertia, dtype=float)}

    car_body = body(vf.car_body)
    if vf.car_body.flexible is not None:
        car_body["flexible"] = _flexible_rules(vf.car_body.flexible, vf.car_body.mass, vf.car_body.inertia,
                                               g["bogie_centre_semi_distance"], source, error, base)

    def susp(s):
        return {"stiffness": np.array(s.stiffness, dtype=float), "damping": np.array(s.damping, dtype=float)}

    secondary = susp(vf.secondary)
    secondary["yaw_stiffness"] = vf.secondary.yaw_stiffness
    bump = None
    if vf.lateral_bump_stop is not None:
        bs = vf.lateral_bump_stop
        w = f"{source} [lateral_bump_stop]"
        d, f = np.array(bs.displacement), np.array(bs.force)
        if d.shape != f.shape:
            raise error(f"{w}: displacement and force must be lists of equal length, got {d.size} and {f.size}")
        if np.any(np.diff(d) <= 0):
            i = int(np.argmax(np.diff(d) <= 0)) + 1
            raise error(f"{w}: displacement must increase strictly; displacement[{i}] = {d[i]:g} m after {d[i - 1]:g} m")
        if f[0] != 0.0:
            raise error(f"{w}: the first row is the clearance, at force 0 N; got force[0] = {f[0]:g} N")
        if np.any(np.diff(f) < 0):
            i = int(np.argmax(np.diff(f) < 0)) + 1
            raise error(f"{w}: force must not decrease with the displacement; force[{i}] = {f[i]:g} N after {f[i - 1]:g} N")
        bump = {"displacement": d, "force": f}
    yds = [{k: getattr(y, k) for k in ("damping", "series_stiffness", "node_mass", "x", "y", "z")}
           for y in vf.yaw_damper]
    name = vf.vehicle.name if vf.vehicle.name is not None else Path(str(source)).stem
    return dict(name=name, source=vf.vehicle.source, wheel=wheel, rail=rail, inclination=pr.inclination,
                gauge=pr.gauge, r0=pr.nominal_wheel_radius, flange_back_spacing=pr.flange_back_spacing,
                geometry=g, car_body=car_body, bogie=body(vf.bogie), wheelset=body(vf.wheelset),
                primary=susp(vf.primary), secondary=secondary,
                anti_roll_bar=vf.anti_roll_bar.stiffness if vf.anti_roll_bar is not None else 0.0,
                bump_stop=bump, yaw_dampers=yds, accept=tuple(acc))


def _flexible_rules(fx: FlexibleCarBody, m, J, L_b, source, error, base=None) -> dict:
    """The ``[car_body.flexible]`` table's consistency: the equivalent beam's keys or an imported FE
    model's, not both.  A beam reaches over the bogie centres, and its pitch and yaw inertias are at
    least the uniform beam's; an imported model is read and checked against ``[car_body]``
    (:func:`railway.vehicles.car_body.imported_car_body`), its file names resolved against
    ``base`` (the vehicle file's folder)."""
    given = fx.model_fields_set
    beam = [k for k in BEAM_KEYS if k in given]
    imported = [k for k in IMPORT_KEYS if k in given]
    w = f"{source} [car_body.flexible]"
    if beam and imported:
        raise error(f"{w}: give either the equivalent beam ({', '.join(BEAM_KEYS[:2])}, ...) or an imported FE model "
                    f"({', '.join(_IMPORT_REQUIRED)}, ...), not both; found {beam[0]!r} and {imported[0]!r}")
    if imported:
        missing = [k for k in _IMPORT_REQUIRED if k not in given]
        if missing:
            raise error(f"{w}: an imported FE model needs {', '.join(_IMPORT_REQUIRED)}; missing {', '.join(missing)}")
        from .car_body import imported_car_body

        out = fx.model_dump()
        for k in ("mass_matrix", "stiffness_matrix", "nodes"):
            path = Path(out[k])
            out[k] = str(path if path.is_absolute() or base is None else Path(base) / path)
        try:
            imported_car_body(out["mass_matrix"], out["stiffness_matrix"], out["nodes"], out["centre_node"],
                              out["bogie_nodes"], m, J, L_b, out["modes"], out["dofs_per_node"], out["length_unit"],
                              out["mass_unit"], out["force_unit"], where=w)
        except InputError as exc:
            raise error(str(exc) if str(exc).startswith(w) else f"{w}: {exc}") from None
        for k in BEAM_KEYS:
            out.pop(k)
        return out
    for k in BEAM_KEYS[:2]:
        if k not in given:
            raise error(f"{w}: the equivalent beam needs length and vertical_bending_frequency (or give an imported "
                        f"FE model: {', '.join(_IMPORT_REQUIRED)}); missing {k}")
    if fx.length <= 2 * L_b:
        raise error(f"{source} [car_body.flexible] length = {fx.length:g} m does not reach over the bogie centres "
                    f"(2 bogie_centre_semi_distance = {2 * L_b:g} m): the car body is longer than its bogie distance")
    for k, axis in ((1, "pitch"), (2, "yaw")):
        if J[k] < m * fx.length**2 / 12.0 * (1 - 1e-12):
            raise error(f"{source} [car_body] inertia: the {axis} inertia {J[k]:.4g} kg m^2 is below that of a "
                        f"uniform beam of the car body's mass over [car_body.flexible] length {fx.length:g} m "
                        f"(m L^2/12 = {m * fx.length**2 / 12:.4g} kg m^2): the flexible car body's mass cannot "
                        f"be spread over that length; give a length of at most {np.sqrt(12 * J[k] / m):.4g} m")
    out = fx.model_dump()
    for k in IMPORT_KEYS:
        out.pop(k)
    return out


def flexible_car_body(table: dict, mass, inertia, bogie_centre_semi_distance, source, error=InputError,
                      accept=()) -> dict:
    """A ``[car_body.flexible]`` table checked as in a vehicle file (schema, units, ranges, rules),
    as a dict of SI values (:meth:`railway.vehicles.vehicle.VehicleDefinition.with_flexible_car_body`)."""
    if not isinstance(table, dict):
        raise error(f"{source}: the flexible car body must be a table of keys, got {table!r}")
    fx = validate(FlexibleCarBody, table, source=f"{source} [car_body.flexible]", context={"accept": list(accept)},
                  error=error)
    return _flexible_rules(fx, float(mass), np.asarray(inertia, float), float(bogie_centre_semi_distance), source,
                           error)


def read_vehicle_file(path, accept=()) -> dict:
    """Read and check a vehicle file (module docstring); returns the keyword arguments of
    :class:`railway.vehicles.vehicle.VehicleDefinition` (with ``path``).  Every error names the file, the
    table and the key; see :func:`vehicle_kwargs`."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            d = tomllib.load(fh)
    except FileNotFoundError:
        raise DataFileError(f"vehicle file {path} does not exist") from None
    except IsADirectoryError:
        raise DataFileError(f"vehicle file {path} is a folder, not a file") from None
    except tomllib.TOMLDecodeError as exc:
        raise DataFileError(f"vehicle file {path}: not valid TOML ({exc})") from None
    kw = vehicle_kwargs(d, source=str(path), base_dir=path.parent, accept=accept)
    kw["path"] = str(path)
    return kw
