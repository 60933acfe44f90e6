r"""Railway vehicles from a data file: car body, bogie frames and wheelsets on the core.

A :class:`VehicleDefinition` is read from a TOML file (``data/railway/vehicles/*.toml``; the
format is the Manchester coach's file, documented key by key there and in
:meth:`VehicleDefinition.from_toml`), so that a user adds a vehicle without code.
:func:`build_vehicle` turns it into a core model on a track:

* bodies (spatial, absolute coordinates): car body, two bogie frames, four wheelsets
  (x forward, y left, z up in the reference configuration; the wheelset's y axis is its axle);
* primary suspension per axlebox: a :class:`core.forces.Bushing` from the bogie frame to the
  wheelset at axle height, ±``primary_lateral_semi_spacing`` from the centre, with translational
  stiffness and damping in bogie-frame axes and no rotational terms — its wheelset point lies on
  the axle, so the spin does not load it;
* secondary suspension per side: a Bushing from the car body to the bogie frame at
  ``secondary_height``, translational stiffness and damping plus the yaw (bending) stiffness
  about z;
* anti-roll bar per bogie: a Bushing with rotational stiffness about x only;
* lateral bump stop per bogie: :class:`core.forces.BumpStop` along y, car body to bogie frame,
  with the clearance and force table of the file;
* optional yaw dampers (``[[yaw_damper]]``): :class:`core.forces.SeriesSpringDamper`
  between car body and bogie frame;
* wheel–rail contact of all four wheelsets: one :class:`railway.wheel_rail.WheelRailContact`;
* optionally a :class:`railway.traction.TrackSpeedControl` pulling the car body at the
  prescribed speed (the train a trailer car runs in).

Static preload
--------------
The suspension springs of a core model are unloaded in the configuration the model is built in.
:func:`build_vehicle` therefore places the bodies at their *unloaded* heights — the design
heights raised by the static deflection of the springs below them, from the weight each spring
carries,

.. math::

    \Delta z_1 = \frac{(m_c/2 + m_b)\,g}{4\,k_{1z}}, \qquad
    \Delta z_2 = \frac{m_c\, g}{4\,k_{2z}},

(bogie frames raised by Δz₁, the car body by Δz₁ + Δz₂) — and :meth:`Vehicle.preload` finds the
static equilibrium under gravity on its rails (:func:`core.analysis.static_equilibrium`, contact
with normal forces only, the vehicle at rest), which brings the bodies to the design heights
with the springs carrying the weight.  Its table reports the wheel loads against the share of the
weight, m_total g / 8 per wheel for the symmetric vehicle, and the suspension deflections.  The
dynamic runs start from this equilibrium with every body moving at the speed V along the track
and the wheelsets spinning at V / r0.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from core import frames
from core.errors import DataFileError, InputError

from .profiles import RailProfile, WheelProfile
from .track import RailMounting

__all__ = ["VehicleDefinition", "Vehicle", "build_vehicle", "GRAVITY"]

GRAVITY = 9.81


def _vec(d, key, n, where):
    try:
        v = np.asarray(d[key], dtype=float)
    except KeyError:
        raise DataFileError(f"{where}: missing key {key!r}") from None
    except (TypeError, ValueError):
        raise DataFileError(f"{where}: {key} = {d[key]!r} is not a number or list of numbers") from None
    if v.ndim == 0:
        v = np.full(n, float(v))
    if v.shape != (n,) or not np.all(np.isfinite(v)) or np.any(v < 0):
        raise DataFileError(f"{where}: {key} must be {n} finite numbers >= 0, got {d[key]!r}")
    return v


def _num(d, key, where, positive=True, default=None):
    if key not in d:
        if default is not None:
            return float(default)
        raise DataFileError(f"{where}: missing key {key!r}")
    try:
        v = float(d[key])
    except (TypeError, ValueError):
        raise DataFileError(f"{where}: {key} = {d[key]!r} is not a number") from None
    if not np.isfinite(v) or (v <= 0 if positive else v < 0):
        raise DataFileError(f"{where}: {key} = {v!r} must be {'> 0' if positive else '>= 0'}")
    return v


@dataclass(frozen=True)
class VehicleDefinition:
    """A two-bogie vehicle (car body, two bogie frames, four wheelsets); SI units.

    Build one with :meth:`from_toml`; see ``data/railway/vehicles/manchester_coach.toml``.
    """

    name: str
    source: str
    wheel: Any
    rail: Any
    inclination: Any
    gauge: float
    r0: float
    flange_back_spacing: float
    geometry: dict
    car_body: dict
    bogie: dict
    wheelset: dict
    primary: dict
    secondary: dict
    anti_roll_bar: float = 0.0
    bump_stop: dict | None = None
    yaw_dampers: list = field(default_factory=list)
    path: str = ""

    @classmethod
    def from_toml(cls, path) -> VehicleDefinition:
        """Read a vehicle file (TOML); every error names the file and the key.

        Tables and keys: ``[vehicle]`` name, source; ``[profiles]`` wheel ("S1002" or a profile
        file), rail ("UIC60" or a file), inclination, gauge [m], nominal_wheel_radius [m],
        flange_back_spacing [m]; ``[geometry]`` bogie_centre_semi_distance,
        bogie_semi_wheelbase, primary_lateral_semi_spacing, secondary_lateral_semi_spacing,
        car_body_cg_height, bogie_cg_height, secondary_height [m, heights above the rail top];
        ``[car_body]``, ``[bogie]``, ``[wheelset]`` mass [kg], inertia [kg m², about x, y, z];
        ``[primary]`` stiffness, damping (x, y, z per axlebox); ``[secondary]`` stiffness,
        damping (x, y, z per side), yaw_stiffness [N m/rad per side]; optional
        ``[anti_roll_bar]`` stiffness [N m/rad per bogie]; optional ``[lateral_bump_stop]``
        displacement [m], force [N] (first row: the clearance, 0 N); optional
        ``[[yaw_damper]]`` damping [N s/m], series_stiffness [N/m], node_mass [kg],
        x [m: the car-body end of the longitudinal damper is x ahead of the bogie centre, the
        bogie end at the bogie centre], y [m, each side], z [m above the rail top].
        """
        path = Path(path)
        try:
            with path.open("rb") as fh:
                d = tomllib.load(fh)
        except FileNotFoundError:
            raise DataFileError(f"vehicle file {path} does not exist") from None
        except tomllib.TOMLDecodeError as exc:
            raise DataFileError(f"vehicle file {path}: not valid TOML ({exc})") from None
        known = {"vehicle", "profiles", "geometry", "car_body", "bogie", "wheelset", "primary", "secondary",
                 "anti_roll_bar", "lateral_bump_stop", "yaw_damper"}
        extra = set(d) - known
        if extra:
            raise DataFileError(f"vehicle file {path}: unknown table(s) {sorted(extra)}; known: {sorted(known)}")
        for t in ("profiles", "geometry", "car_body", "bogie", "wheelset", "primary", "secondary"):
            if t not in d:
                raise DataFileError(f"vehicle file {path}: missing table [{t}]")
        w = f"{path} [profiles]"
        pr = d["profiles"]
        r0 = _num(pr, "nominal_wheel_radius", w)
        wheel_spec = str(pr.get("wheel", "S1002"))
        if wheel_spec.upper() == "S1002":
            wheel = WheelProfile.s1002(r0=r0)
        else:
            wheel = WheelProfile.from_file(path.parent / wheel_spec, r0=r0)
        rail_spec = str(pr.get("rail", "UIC60"))
        rail = RailProfile.uic60() if rail_spec.upper() == "UIC60" else RailProfile.from_file(path.parent / rail_spec)
        geo_keys = ("bogie_centre_semi_distance", "bogie_semi_wheelbase", "primary_lateral_semi_spacing",
                    "secondary_lateral_semi_spacing", "car_body_cg_height", "bogie_cg_height", "secondary_height")
        geometry = {k: _num(d["geometry"], k, f"{path} [geometry]") for k in geo_keys}

        def body(t):
            where = f"{path} [{t}]"
            return {"mass": _num(d[t], "mass", where), "inertia": _vec(d[t], "inertia", 3, where)}

        def susp(t):
            where = f"{path} [{t}]"
            return {"stiffness": _vec(d[t], "stiffness", 3, where), "damping": _vec(d[t], "damping", 3, where)}

        secondary = susp("secondary")
        secondary["yaw_stiffness"] = _num(d["secondary"], "yaw_stiffness", f"{path} [secondary]",
                                          positive=False, default=0.0)
        arb = _num(d.get("anti_roll_bar", {}), "stiffness", f"{path} [anti_roll_bar]", positive=False,
                   default=0.0) if "anti_roll_bar" in d else 0.0
        bump = None
        if "lateral_bump_stop" in d:
            where = f"{path} [lateral_bump_stop]"
            bs = d["lateral_bump_stop"]
            disp = np.asarray(bs.get("displacement", []), float)
            force = np.asarray(bs.get("force", []), float)
            if disp.size < 2 or disp.shape != force.shape:
                raise DataFileError(f"{where}: displacement and force must be lists of equal length >= 2")
            bump = {"displacement": disp, "force": force}
        yds = []
        for i, yd in enumerate(d.get("yaw_damper", [])):
            where = f"{path} [[yaw_damper]] {i + 1}"
            yds.append({k: _num(yd, k, where, positive=(k not in ("x", "y", "z"))) if k not in ("x", "y")
                        else float(yd[k]) for k in ("damping", "series_stiffness", "node_mass", "x", "y", "z")})
        meta = d.get("vehicle", {})
        return cls(name=str(meta.get("name", path.stem)), source=str(meta.get("source", "")), wheel=wheel,
                   rail=rail, inclination=pr.get("inclination", "1:40"), gauge=_num(pr, "gauge", w),
                   r0=r0, flange_back_spacing=_num(pr, "flange_back_spacing", w), geometry=geometry,
                   car_body=body("car_body"), bogie=body("bogie"), wheelset=body("wheelset"),
                   primary=susp("primary"), secondary=secondary, anti_roll_bar=arb, bump_stop=bump,
                   yaw_dampers=yds, path=str(path))

    @classmethod
    def manchester(cls) -> VehicleDefinition:
        """The Manchester benchmark coach shipped in ``data/railway/vehicles``."""
        from core.paths import data_path

        return cls.from_toml(data_path("railway", "vehicles", "manchester_coach.toml"))

    @property
    def total_mass(self) -> float:
        return self.car_body["mass"] + 2 * self.bogie["mass"] + 4 * self.wheelset["mass"]

    def static_deflections(self, g=GRAVITY):
        """(Δz₁ primary, Δz₂ secondary) [m] under the weight (module docstring)."""
        dz1 = (0.5 * self.car_body["mass"] + self.bogie["mass"]) * g / (4.0 * self.primary["stiffness"][2])
        dz2 = self.car_body["mass"] * g / (4.0 * self.secondary["stiffness"][2])
        return dz1, dz2

    def rails(self):
        return RailMounting(self.rail, gauge=self.gauge, inclination=self.inclination)


@dataclass
class Vehicle:
    """A vehicle built on a track: the core model and the names of its parts."""

    definition: VehicleDefinition
    model: Any
    track: Any
    car_body: str
    bogies: list
    wheelsets: list
    contact: str
    s0: float
    speed: float
    creep_law: Any
    q_static: np.ndarray | None = None
    preload_table: pd.DataFrame | None = None
    _contact_options: dict | None = None

    @property
    def contact_kind(self):
        from .wheel_rail import WheelRailKind

        return next(k for k in self.model.force_kinds if isinstance(k, WheelRailKind))

    @property
    def wheel_names(self) -> list[str]:
        return [f"{ws} {side}" for ws in self.wheelsets for side in ("left", "right")]

    def preload(self, tol: float = 1e-9):
        """Static equilibrium under gravity on the rails (module docstring).

        Solved on a copy of the model with normal contact forces only (no creep: the vehicle is
        at rest) and without speed control; the equilibrium positions are kept in
        :attr:`q_static` for the dynamic runs (:meth:`initial_state`).

        Returns
        -------
        DataFrame
            One row per wheel: ``Q [N]`` (wheel load), ``share [N]`` (m_total g / 8),
            ``relative difference [-]``; and per suspension element its static deflection
            (``attrs["deflections"]``, a DataFrame: element, dx, dy, dz [m], Fz [N]).
        """
        from core.analysis import static_equilibrium

        static = build_vehicle(self.definition, self.track, self.s0, 0.0, creep_law=None,
                               lateral=0.0, unloaded=True, name=f"{self.model.name} (static)",
                               contact_options=self._contact_options, parking=True)
        m = static.model
        eq = static_equilibrium(m, q_guess=static._hertz_guess(), method="newton", tol=tol)
        zero = np.zeros(m.n_v)
        bs = m.body_states(eq.q, zero)
        kind = static.contact_kind
        kind.reset_state(bs, 0.0)
        out = kind.contact_outputs(bs, 0.0)
        share = self.definition.total_mass * GRAVITY / 8.0
        Qw = out["wheels"]["Q [N]"]
        table = pd.DataFrame({"wheel": static.wheel_names, "Q [N]": Qw, "share m g / 8 [N]": share,
                              "relative difference [-]": Qw / share - 1.0})
        rows = []
        for k in m.force_kinds:
            if type(k).__name__ != "BushingKind":
                continue
            o = k.outputs(bs, 0.0)
            for i, nm in enumerate(k.names):
                rows.append({"element": nm, "dx [m]": o["dx [m]"][i], "dy [m]": o["dy [m]"][i],
                             "dz [m]": o["dz [m]"][i], "Fx [N]": o["Fx [N]"][i], "Fy [N]": o["Fy [N]"][i],
                             "Fz [N]": o["Fz [N]"][i], "My [N m]": o["My [N m]"][i]})
        table.attrs["deflections"] = pd.DataFrame(rows)
        table.attrs["equilibrium"] = eq
        self.q_static = eq.q
        self.preload_table = table
        return table

    def _hertz_guess(self):
        """q0 with every body lowered by the Hertz approach of its wheels under the static wheel
        load: at the rigid contact (zero penetration) the contact has no stiffness, from which
        Newton's method cannot start."""
        from core.contact_laws import hertz_from_load

        m = self.model
        q = m.q0.copy()
        kind = self.contact_kind
        bs = m.body_states(q, np.zeros(m.n_v))
        kind.reset_state(bs, 0.0)
        st = kind.sets[0]
        r, A, v, w = st.states(bs)
        res = st.contacts(r, A, v, w)[0]
        c = np.argmin(np.where(res.valid, res.gap, np.inf), axis=1)  # the loaded candidate per wheel
        i = np.arange(res.gap.shape[0])
        Ac = 0.5 * (res.k_wheel_rolling + res.k_rail_rolling)[i, c]
        Bc = 0.5 * (res.k_wheel_lateral + res.k_rail_lateral)[i, c]
        share = self.definition.total_mass * GRAVITY / 8.0
        E, nu = st.e.E, st.e.nu
        h = hertz_from_load(share / np.cos(res.contact_angle[i, c]), Ac, np.clip(Bc, Ac / 1e3, Ac * 1e3),
                            E, nu, E, nu)
        drop = float(np.mean(h.delta + res.gap[i, c]))
        for name in [self.car_body] + self.bogies + self.wheelsets:
            q[m.q_slice(name).start + 2] -= drop
        return q

    def initial_state(self, lateral=0.0, yaw=0.0, wheelset_lateral=None):
        """(q0, v0): the static equilibrium (:meth:`preload`, computed if needed) moving at the
        vehicle's speed along the track, wheelsets spinning at V / r0; optional lateral offsets
        (m) of all bodies and of the wheelsets, and a yaw angle (rad) of the wheelsets."""
        if self.q_static is None:
            self.preload()
        m = self.model
        q = self.q_static.copy()
        v = np.zeros(m.n_v)
        wl = np.zeros(4) if wheelset_lateral is None else np.asarray(wheelset_lateral, float)
        for name in [self.car_body] + self.bogies + self.wheelsets:
            qs, vs = m.q_slice(name), m.v_slice(name)
            r = q[qs][:3]
            s = self.track.project(r[None, :], np.array([self.s0]))
            fr = self.track.evaluate(s)
            t, n = fr.R[0][:, 0], fr.R[0][:, 1]
            dy = lateral + (wl[self.wheelsets.index(name)] if name in self.wheelsets else 0.0)
            q[qs.start:qs.start + 3] = r + dy * n
            v[vs.start:vs.start + 3] = self.speed * t
            if name in self.wheelsets:
                A = frames.euler_to_matrix(q[qs][3:])
                if yaw:
                    Rz = frames.euler_to_matrix(frames.rotation_vector_to_euler(yaw * fr.R[0][:, 2]))
                    A = Rz @ A
                    q[qs.start + 3:qs.stop] = frames.matrix_to_euler(A)
                # body-frame angular velocity: spin V / r0 about the axle (body y)
                v[vs.start + 3:vs.stop] = np.array([0.0, self.speed / self.definition.r0, 0.0])
        return q, v


def _placement(track, s, y, z):
    """Global position and rotation of a body at arc length s, lateral y, height z (track frame)."""
    fr = track.evaluate(np.atleast_1d(float(s)))
    R = fr.R[0]
    return fr.position[0] + R @ np.array([0.0, y, z]), R


def build_vehicle(definition: VehicleDefinition, track, s0: float, speed: float = 0.0, *,
                  creep_law="kalker_linear", creep_params=None, mu=0.3, lateral=0.0,
                  wheelset_lateral=None, speed_control=None, control_gain=None, unloaded=True,
                  contact_options=None, name="vehicle", parking=False) -> Vehicle:
    """A core model of the vehicle on ``track`` with its car body at arc length ``s0``.

    Parameters
    ----------
    definition : VehicleDefinition
    track : railway.track.Track
    s0 : float
        Arc length of the car body centre (m); the leading bogie is ahead (larger s).
    speed : float
        Initial speed V (m/s) of every body along the track; wheelsets spin at V / r0.
    creep_law, creep_params, mu :
        Creep law of the wheel–rail contact (None: normal forces only).
    lateral : float
        Lateral offset of every body from the track centre (m).
    wheelset_lateral : sequence of 4 floats, optional
        Extra lateral offsets of the wheelsets (m), leading first.
    speed_control : float, callable or TimeFunction, optional
        Prescribed speed V(t) of the car body along the track (a :class:`TrackSpeedControl`);
        None: the vehicle coasts.
    control_gain : float, optional
        k_v [N s/m]; default m_total / 0.5 s (a speed time constant of 0.5 s).
    unloaded : bool
        Place the bodies at their unloaded heights (for :meth:`preload`); False places them at
        the design heights (springs unloaded there).
    contact_options : dict, optional
        Further :class:`WheelRailContact` parameters (restitution, reseed_every, ...).
    name : str
    parking : bool
        Add springs to the ground that fix the neutral directions of a vehicle at rest (its
        travel and the wheelset spins) for the static preload.
    """
    from core.model import ModelBuilder

    from .traction import TrackSpeedControl
    from .wheel_rail import WheelRailContact

    D = definition
    g = D.geometry
    if not np.isfinite(s0):
        raise InputError(f"build_vehicle: s0 = {s0!r} m is not finite")
    b = ModelBuilder(3, name, gravity=(0.0, 0.0, -GRAVITY))
    dz1, dz2 = D.static_deflections() if unloaded else (0.0, 0.0)
    r0 = D.r0
    L_b, a_w = g["bogie_centre_semi_distance"], g["bogie_semi_wheelbase"]
    wl = np.zeros(4) if wheelset_lateral is None else np.asarray(wheelset_lateral, float)
    if wl.shape != (4,):
        raise InputError(f"build_vehicle: wheelset_lateral must have 4 values, got {wheelset_lateral!r}")
    s_b = [s0 + L_b, s0 - L_b]
    s_w = [s_b[0] + a_w, s_b[0] - a_w, s_b[1] + a_w, s_b[1] - a_w]
    if min(s_w) < 0 or max(s_w) > track.length:
        raise InputError(f"build_vehicle: the vehicle at s0 = {s0:g} m reaches from {min(s_w):g} to "
                         f"{max(s_w):g} m, outside the track [0, {track.length:g}] m")

    def add(nm, body, s, y, z, omega_axle=0.0):
        pos, R = _placement(track, s, y, z)
        t = R[:, 0]
        b.add_body(nm, mass=body["mass"], inertia=body["inertia"], position=pos,
                   orientation=frames.matrix_to_euler(R), velocity=speed * t,
                   angular_velocity=omega_axle * R[:, 1])
        return pos, R

    cb = "car body"
    add(cb, D.car_body, s0, lateral, g["car_body_cg_height"] + dz1 + dz2)
    bogies = ["bogie 1", "bogie 2"]
    for k, nm in enumerate(bogies):
        add(nm, D.bogie, s_b[k], lateral, g["bogie_cg_height"] + dz1)
    wheelsets = [f"wheelset {k + 1}" for k in range(4)]
    for k, nm in enumerate(wheelsets):
        add(nm, D.wheelset, s_w[k], lateral + wl[k], r0, omega_axle=speed / r0)
    bs0 = {n: _placement(track, s, lateral, 0.0) for n, s in
           zip([cb] + bogies + wheelsets, [s0] + s_b + s_w)}

    def point(body, s, x, y, z):
        """Global point at (x along the track from the body's arc length, y, z) in the body's
        reference frame at build (z above the rail top, in the build heights)."""
        pos, R = bs0[body]
        return pos + R @ np.array([x, y, z])

    yp = g["primary_lateral_semi_spacing"]
    ys = g["secondary_lateral_semi_spacing"]
    hs = g["secondary_height"]
    for k, ws in enumerate(wheelsets):
        bg = bogies[k // 2]
        R = bs0[ws][1]
        for side, y in (("left", yp), ("right", -yp)):
            P = point(bg, s_b[k // 2], (s_w[k] - s_b[k // 2]), y, r0 + dz1)
            Q = point(ws, s_w[k], 0.0, y, r0)
            b.add_bushing(f"primary {k + 1} {side}", bg, ws, at=P, point_j=Q,
                          translational_stiffness=D.primary["stiffness"], rotational_stiffness=0.0,
                          translational_damping=D.primary["damping"], rotational_damping=0.0, axes=R)
    for k, bg in enumerate(bogies):
        R = bs0[bg][1]
        for side, y in (("left", ys), ("right", -ys)):
            P = point(cb, s0, s_b[k] - s0, y, hs + dz1 + dz2)
            Q = point(bg, s_b[k], 0.0, y, hs + dz1)
            b.add_bushing(f"secondary {k + 1} {side}", cb, bg, at=P, point_j=Q,
                          translational_stiffness=D.secondary["stiffness"],
                          rotational_stiffness=(0.0, 0.0, D.secondary["yaw_stiffness"]),
                          translational_damping=D.secondary["damping"], rotational_damping=0.0, axes=R)
        P = point(cb, s0, s_b[k] - s0, 0.0, hs + dz1 + dz2)
        Q = point(bg, s_b[k], 0.0, 0.0, hs + dz1)
        if D.anti_roll_bar > 0:
            b.add_bushing(f"anti-roll bar {k + 1}", cb, bg, at=P, point_j=Q, translational_stiffness=0.0,
                          rotational_stiffness=(D.anti_roll_bar, 0.0, 0.0), axes=R)
        if D.bump_stop is not None:
            b.add_bump_stop(f"lateral bump stop {k + 1}", cb, bg, at=P, axis=R[:, 1],
                            table=np.column_stack([D.bump_stop["displacement"], D.bump_stop["force"]]), point_j=Q)
        for j, yd in enumerate(D.yaw_dampers):
            for side, sgn in (("left", 1.0), ("right", -1.0)):
                # longitudinal damper: car body end x ahead of the bogie centre, bogie end at it
                P = point(cb, s0, s_b[k] - s0 + yd["x"], sgn * yd["y"], yd["z"] + dz1 + dz2)
                Q = point(bg, s_b[k], 0.0, sgn * yd["y"], yd["z"] + dz1)
                b.add_series_spring_damper(f"yaw damper {k + 1}.{j + 1} {side}", cb, bg, P, Q,
                                           stiffness=yd["series_stiffness"], damping=yd["damping"],
                                           node_mass=yd["node_mass"])
    if parking:
        # the static preload has no creep: the vehicle's travel along the track and the wheelset
        # spins are free (neutral) directions; these springs to the ground fix them without
        # carrying load (no force acts along them; the preload table reports their forces)
        b.add_bushing("parking: car body travel", "ground", cb, at=bs0[cb][0] + np.array([0, 0, 1.0]),
                      translational_stiffness=(1e6, 0.0, 0.0), rotational_stiffness=0.0,
                      axes=bs0[cb][1])
        for ws in wheelsets:
            b.add_bushing(f"parking: {ws} spin", "ground", ws, at=bs0[ws][0] + np.array([0, 0, r0]),
                          translational_stiffness=0.0, rotational_stiffness=(0.0, 1e5, 0.0),
                          axes=bs0[ws][1])
    opts = dict(contact_options or {})
    contact = "wheel-rail"
    b.add_force(WheelRailContact(contact, wheelsets, track, wheel=D.wheel, rails=D.rails(),
                                 flange_back_spacing=D.flange_back_spacing, creep_law=creep_law,
                                 creep_params=creep_params, mu=mu, **opts))
    if speed_control is not None:
        gain = D.total_mass / 0.5 if control_gain is None else float(control_gain)
        b.add_force(TrackSpeedControl("speed control", cb, track, speed_control, gain))
    model = b.build()
    return Vehicle(definition=D, model=model, track=track, car_body=cb, bogies=bogies, wheelsets=wheelsets,
                   contact=contact, s0=float(s0), speed=float(speed), creep_law=creep_law,
                   _contact_options=contact_options)
