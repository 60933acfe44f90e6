r"""Railway vehicles from a data file: car body, bogie frames and wheelsets on the core.

A :class:`VehicleDefinition` is read from a TOML file (``data/railway/vehicles/*.toml``; the
format is the Manchester coach's file, documented key by key there and in
:meth:`VehicleDefinition.from_toml`; its schema, units, plausible ranges and consistency rules
are :mod:`railway.vehicles.vehicle_file`), so that a user adds a vehicle without code.
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
* wheel–rail contact of all four wheelsets: one :class:`railway.vehicles.wheel_rail.WheelRailContact`;
* optionally a :class:`railway.vehicles.traction.TrackSpeedControl` pulling the car body at the
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

Start in a curve or a transition
--------------------------------
Where the track under the vehicle is not straight (:attr:`Vehicle.on_straight_track`), the start
of a run (:meth:`Vehicle.initial_state`, :meth:`Vehicle.preload`) is the quasi-static curving
state at s0 and the speed V (:meth:`Vehicle.equilibrium`,
:func:`railway.vehicles.curving_start.quasi_static_curving`): the equilibrium of the model's own forces
with the accelerations of steady motion along the track (centripetal V²κ, the yaw and cant
rates of the track frame), the creep forces of its creep law, the wheelsets rolling.  The
suspension's unloaded geometry is always the straight design geometry: in a curve
:func:`build_vehicle` builds the vehicle on the tangent at s0 and places it on the track, so
that the springs are deflected by the curve (railway.vehicles.curving_start, "Reference geometry").  On
straight track nothing changes: the start is the static preload above.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from core import frames
from core.errors import InputError
from core.inputs import checked_options

from ..track import RailMounting
from .vehicle_file import GRAVITY

__all__ = ["VehicleDefinition", "Vehicle", "build_vehicle", "GRAVITY"]


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
    #: quantities whose plausible range was waived when the definition was read (e.g. "gauge")
    accept: tuple = ()

    @classmethod
    def from_toml(cls, path, accept=()) -> VehicleDefinition:
        """Read a vehicle file (TOML); every error names the file, the table and the key.

        The schema, units, plausible ranges and consistency rules are those of
        :mod:`railway.vehicles.vehicle_file`; ``accept`` names quantities or rules whose check is waived
        (as the file's ``[checks] accept = [...]``).

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
        from .vehicle_file import read_vehicle_file

        return cls(**read_vehicle_file(path, accept=accept))

    @classmethod
    def from_dict(cls, data: dict, *, source: str = "VehicleDefinition.from_dict()", base_dir=None,
                  accept=()) -> VehicleDefinition:
        """A vehicle from the tables of a vehicle file given as nested dicts (the same schema,
        units, ranges and rules as :meth:`from_toml`; :mod:`railway.vehicles.vehicle_file`)."""
        from .vehicle_file import vehicle_kwargs

        return cls(**vehicle_kwargs(data, source=source, base_dir=base_dir, accept=accept))

    @classmethod
    def manchester(cls) -> VehicleDefinition:
        """The Manchester benchmark coach shipped in ``data/railway/vehicles``."""
        from core.paths import data_path

        return cls.from_toml(data_path("railway", "vehicles", "manchester_coach.toml"))

    def with_flexible_car_body(self, **table) -> VehicleDefinition:
        """This vehicle with its car body flexible: ``table`` is a ``[car_body.flexible]`` table
        (length, vertical_bending_frequency, torsion_frequency, lateral_bending_frequency,
        damping_ratio, elements; :mod:`railway.vehicles.vehicle_file`), checked like the file's;
        the car body's mass and inertia stay (:mod:`railway.vehicles.car_body`)."""
        from dataclasses import replace

        from .vehicle_file import flexible_car_body

        car_body = dict(self.car_body)
        car_body["flexible"] = flexible_car_body(table, self.car_body["mass"], self.car_body["inertia"],
                                                 self.geometry["bogie_centre_semi_distance"],
                                                 f"vehicle {self.name!r} with_flexible_car_body()", InputError,
                                                 self.accept)
        return replace(self, car_body=car_body)

    @property
    def total_mass(self) -> float:
        return self.car_body["mass"] + 2 * self.bogie["mass"] + 4 * self.wheelset["mass"]

    def static_deflections(self, g=GRAVITY):
        """(Δz₁ primary, Δz₂ secondary) [m] under the weight (module docstring).

        Raises
        ------
        core.errors.InputError
            A vertical stiffness that is not positive and finite (names the suspension and value).
        """
        for part in ("primary", "secondary"):
            k_z = float(getattr(self, part)["stiffness"][2])
            if not (np.isfinite(k_z) and k_z > 0.0):
                raise InputError(f"vehicle {self.name!r}: {part} suspension vertical stiffness k_z = {k_z!r} N/m "
                                 f"([{part}] stiffness, z) must be positive: the static deflection m g / (4 k_z) "
                                 "that places the bodies above their springs is undefined")
        dz1 = (0.5 * self.car_body["mass"] + self.bogie["mass"]) * g / (4.0 * self.primary["stiffness"][2])
        dz2 = self.car_body["mass"] * g / (4.0 * self.secondary["stiffness"][2])
        return dz1, dz2

    def rails(self):
        return RailMounting(self.rail, gauge=self.gauge, inclination=self.inclination, accept=self.accept)


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
    start: Any = None
    #: a flexible car body's node frames by station ("centre", "over bogie 1", "over bogie 2");
    #: empty for a rigid car body
    car_body_frames: dict = field(default_factory=dict)
    #: a flexible car body's component: the equivalent beam (railway.vehicles.car_body.CarBodyBeam)
    #: or the imported FE model (railway.vehicles.car_body.ImportedCarBody); None for a rigid one
    car_body_component: Any = None

    @property
    def car_body_beam(self):
        """The flexible car body's equivalent beam (:class:`railway.vehicles.car_body.CarBodyBeam`),
        else None (a rigid car body, or one imported from an FE model: :attr:`car_body_component`)."""
        from .car_body import CarBodyBeam

        return self.car_body_component if isinstance(self.car_body_component, CarBodyBeam) else None

    @property
    def _moving_bodies(self) -> list[str]:
        """The bodies a start state moves and lowers: car body (and its node frames), bogies, wheelsets."""
        return [self.car_body] + list(self.car_body_frames.values()) + self.bogies + self.wheelsets

    @property
    def on_straight_track(self) -> bool:
        """True when the design line under all wheelsets is straight (no curvature, no cant
        change): the vehicle then starts from the static preload (:meth:`initial_state`)."""
        g = self.definition.geometry
        ext = g["bogie_centre_semi_distance"] + g["bogie_semi_wheelbase"]
        return _straight_track(self.track, self.s0 - ext, self.s0 + ext)

    def equilibrium(self, tol: float = 1e-9, t0: float = 0.0) -> pd.DataFrame:
        """The quasi-static curving state at s0 and the vehicle's speed: the start of a run
        anywhere on the track (:func:`railway.vehicles.curving_start.quasi_static_curving`).

        Every body moves with the track frame at the speed V, the wheelsets roll, and the
        forces of the model — suspension, wheel–rail contact with its creep law, speed control,
        gravity, gyroscopic terms — balance the accelerations of that motion (centripetal
        V²κ, the yaw and cant rates of a transition).  The state is kept in :attr:`start`
        (a :class:`railway.vehicles.curving_start.CurvingStart`) for :meth:`initial_state`.

        Returns
        -------
        DataFrame
            One row per wheel: ``Q [N]``, ``Y [N]``, ``Y/Q [-]``, ``flange contact``,
            ``flange force [N]``, ``Fx [N]``, ``Fy [N]`` (creep forces), ``contact angle [rad]``,
            ``lateral displacement [m]``, ``angle of attack [rad]``, ``sum Y [N]`` of the
            wheelset; ``attrs["bodies"]`` (pose of every body relative to the track frame),
            ``attrs["balance"]`` (lateral force balance of the whole vehicle) and
            ``attrs["start"]`` (the CurvingStart).

        Raises
        ------
        core.errors.InputError
            A start that is impossible (no creep law, speed not > 0, overturning, a lifted
            wheel, no steady state), naming s0, the speed and the reason.
        """
        from .curving_start import quasi_static_curving

        st = quasi_static_curving(self, t0=t0, tol=tol)
        self.start = st
        table = st.wheels.copy()
        table.attrs["bodies"] = st.bodies
        table.attrs["balance"] = st.balance
        table.attrs["start"] = st
        return table

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
        :attr:`q_static` for the dynamic runs (:meth:`initial_state`).  In a curve or a
        transition at a speed > 0 the vehicle is not at rest: the preload is then the
        quasi-static curving state (:meth:`equilibrium`), reported in the same table
        (``attrs["equilibrium"]`` is its :class:`railway.vehicles.curving_start.CurvingStart`).

        Returns
        -------
        DataFrame
            One row per wheel: ``Q [N]`` (wheel load), ``share [N]`` (m_total g / 8),
            ``relative difference [-]``; and per suspension element its static deflection
            (``attrs["deflections"]``, a DataFrame: element, dx, dy, dz [m], Fz [N]).

        Raises
        ------
        core.errors.InputError
            At rest (speed 0) in a curve or transition when the static equilibrium without
            creep forces does not exist (a canted track: nothing holds the vehicle on the
            cant); in a curve at speed, as :meth:`equilibrium`.
        """
        from core.analysis import static_equilibrium

        if not self.on_straight_track and self.speed > 0:
            return self._preload_in_curve(tol)
        static = build_vehicle(self.definition, self.track, self.s0, 0.0, creep_law=None,
                               lateral=0.0, unloaded=True, name=f"{self.model.name} (static)",
                               contact_options=self._contact_options, parking=True)
        m = static.model
        try:
            eq = static_equilibrium(m, q_guess=static._hertz_guess(), method="newton", tol=tol)
        except RuntimeError as exc:
            if self.on_straight_track:
                raise
            raise InputError(f"preload of {self.model.name!r} at s0 = {self.s0:g} m, speed = {self.speed:g} m/s: "
                             f"a vehicle at rest in a curve or transition is held by static friction, which the "
                             f"model's contact (normal forces only at rest) does not have, and the static "
                             f"equilibrium did not converge ({exc}); give the vehicle a speed > 0 (its start is "
                             f"then the quasi-static curving state, Vehicle.equilibrium) or start on straight "
                             f"track") from None
        zero = np.zeros(m.n_v)
        bs = m.body_states(eq.q, zero)
        kind = static.contact_kind
        kind.reset_state(bs, 0.0)
        out = kind.contact_outputs(bs, 0.0)
        return self._preload_report(m, bs, static.wheel_names, out["wheels"]["Q [N]"], eq.q, eq)

    def _preload_in_curve(self, tol):
        """:meth:`preload` in a curve or transition: the quasi-static curving state at the
        vehicle's speed (:meth:`equilibrium`, reused when already solved to ``tol``), reported
        like the static preload."""
        if self.start is None or not self.start.residual <= tol:
            self.equilibrium(tol=tol)
        st = self.start
        m = self.model
        bs = m.body_states(st.q, st.v)
        return self._preload_report(m, bs, self.wheel_names, st.wheels["Q [N]"].to_numpy(), st.q, st)

    def _preload_report(self, m, bs, wheel_names, Qw, q, equilibrium):
        """The preload table (wheel loads against m_total g / 8; ``attrs["deflections"]``: every
        Bushing's deflections and forces) of the state ``bs`` of model ``m``; keeps ``q`` as the
        start of the dynamic runs."""
        share = self.definition.total_mass * GRAVITY / 8.0
        Qw = np.asarray(Qw, dtype=float)
        table = pd.DataFrame({"wheel": wheel_names, "Q [N]": Qw, "share m g / 8 [N]": share,
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
        table.attrs["equilibrium"] = equilibrium
        self.q_static = q
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
        for name in self._moving_bodies:
            q[m.q_slice(name).start + 2] -= drop
        return q

    def initial_state(self, lateral=0.0, yaw=0.0, wheelset_lateral=None):
        """(q0, v0): the start of a run at s0 and the vehicle's speed, wherever s0 lies.

        On straight track: the static equilibrium (:meth:`preload`, computed if needed) moving
        at the vehicle's speed along the track, wheelsets spinning at V / r0.  In a curve or a
        transition (:attr:`on_straight_track` False) and at a speed > 0: the quasi-static curving
        state (:meth:`equilibrium`, computed if needed) — lateral shifts, yaw and roll of the
        bodies, suspension deflections and creep forces of steady curving, every body moving
        with the track frame (its yaw rate V κ and, in a transition, the cant rate), the
        wheelsets rolling.  Optional lateral offsets (m) of all bodies and of the wheelsets, and
        a yaw angle (rad) of the wheelsets, are added to either (positions only)."""
        if not self.on_straight_track and self.speed > 0:
            if self.start is None:
                self.equilibrium()
            return self._offset(self.start.q.copy(), self.start.v.copy(), lateral, yaw, wheelset_lateral)
        if self.q_static is None:
            self.preload()
        m = self.model
        q = self.q_static.copy()
        v = np.zeros(m.n_v)
        wl = np.zeros(4) if wheelset_lateral is None else np.asarray(wheelset_lateral, float)
        for name in self._moving_bodies:
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

    def _offset(self, q, v, lateral, yaw, wheelset_lateral):
        """Lateral offsets along the track's lateral axis and a wheelset yaw about its up axis,
        at each body's nearest track point (positions only; :meth:`initial_state`)."""
        wl = np.zeros(4) if wheelset_lateral is None else np.asarray(wheelset_lateral, float)
        if not lateral and not yaw and not np.any(wl):
            return q, v
        m = self.model
        for name in self._moving_bodies:
            qs = m.q_slice(name)
            r = q[qs][:3]
            s = self.track.project(r[None, :], np.array([self.s0]))
            R = self.track.evaluate(s).R[0]
            dy = lateral + (wl[self.wheelsets.index(name)] if name in self.wheelsets else 0.0)
            q[qs.start:qs.start + 3] = r + dy * R[:, 1]
            if name in self.wheelsets and yaw:
                A = frames.euler_to_matrix(q[qs][3:])
                Rz = frames.euler_to_matrix(frames.rotation_vector_to_euler(yaw * R[:, 2]))
                q[qs.start + 3:qs.stop] = frames.matrix_to_euler(Rz @ A)
        return q, v


def _placement(track, s, y, z):
    """Global position and rotation of a body at arc length s, lateral y, height z (track frame)."""
    fr = track.evaluate(np.atleast_1d(float(s)))
    R = fr.R[0]
    return fr.position[0] + R @ np.array([0.0, y, z]), R


def _straight_track(track, s_lo, s_hi):
    """True when the design line is straight over [s_lo, s_hi] (zero Darboux vector: no
    curvature, no cant change; irregularities do not count)."""
    s = np.linspace(s_lo, s_hi, max(3, int(np.ceil((s_hi - s_lo) / 0.5)) + 1))
    return bool(np.all(np.abs(track.evaluate(s).omega) <= 1e-12))


def _place_on_track(model, on_track, speed):
    """The model (built in the straight reference geometry) with its initial state on the
    track: each body at its own arc length, moving at ``speed`` along the tangent there, the
    wheelsets spinning at the build's rate about their axle."""
    q, v = model.q0.copy(), model.v0.copy()
    for nm, ((pos, R), omega_axle) in on_track.items():
        qs, vs = model.q_slice(nm), model.v_slice(nm)
        q[qs] = np.concatenate([pos, frames.matrix_to_euler(R)])
        v[vs] = np.concatenate([speed * R[:, 0], [0.0, omega_axle, 0.0]])
    return model.with_state(q, v)


#: keyword arguments of WheelRailContact that build_vehicle sets itself
_SET_BY_BUILD = ("name", "wheelsets", "track", "wheel", "rails", "flange_back_spacing", "creep_law",
                 "creep_params", "mu")


def _check_definition_values(D, where):
    """The values a model cannot be built from, in a definition made or changed in code (a file
    is checked fully when read, :mod:`railway.vehicles.vehicle_file`): masses, inertias, the geometry and
    the wheel radius must be positive, stiffnesses and damping non-negative, everything finite."""
    items = [(f"{b}['mass']", getattr(D, b)["mass"], True) for b in ("car_body", "bogie", "wheelset")]
    items += [(f"{b}['inertia'][{i}]", x, True) for b in ("car_body", "bogie", "wheelset")
              for i, x in enumerate(np.ravel(getattr(D, b)["inertia"]))]
    for s in ("primary", "secondary"):
        for key in ("stiffness", "damping"):
            vals = np.ravel(getattr(D, s)[key])
            if vals.size != 3:
                raise InputError(f"{where}: definition.{s}[{key!r}] must have 3 values (x, y, z), got {vals.size}")
            # (a vertical stiffness that is not positive is named by VehicleDefinition.static_deflections)
            items += [(f"{s}[{key!r}][{i}]", x, False) for i, x in enumerate(vals)
                      if not (key == "stiffness" and i == 2)]
    items += [("r0", D.r0, True), ("gauge", D.gauge, True), ("anti_roll_bar", D.anti_roll_bar, False),
              ("secondary['yaw_stiffness']", D.secondary.get("yaw_stiffness", 0.0), False)]
    items += [(f"geometry[{k!r}]", v, True) for k, v in D.geometry.items()]
    for name, x, positive in items:
        x = float(x)
        if not np.isfinite(x) or x < 0 or (positive and x == 0):
            raise InputError(f"{where}: definition.{name} = {x!r} must be {'> 0' if positive else '>= 0'} and "
                             f"finite")


def _check_build_arguments(D, track, s0, speed, creep_law, creep_params, mu, lateral, wheelset_lateral,
                           speed_control, control_gain, contact_options, accept):
    """The arguments of :func:`build_vehicle`, checked once (units parsed, ranges, names):
    (s0, speed, mu, lateral, wheelset_lateral, speed_control, control_gain) in SI."""
    import dataclasses

    from core.errors import UnknownNameError
    from core.inputs import check_keywords, closest, parse_quantity

    from ..ranges import ranges
    from .wheel_rail import WheelRailContact

    R = ranges()
    where = "build_vehicle"
    if isinstance(accept, str):
        accept = [accept]
    accept = list(accept)
    for a in accept:
        if a not in R:
            raise InputError(f"{where}(accept=...): {a!r} is not a quantity of {R.source}"
                             f"{closest(a, [r.quantity for r in R])}")
    if not isinstance(D, VehicleDefinition):
        hint = " (read the file with VehicleDefinition.from_toml(path))" if isinstance(D, (str, bytes)) or \
            hasattr(D, "__fspath__") else ""
        raise InputError(f"{where}: definition must be a VehicleDefinition, got {type(D).__name__}{hint}")
    if not (hasattr(track, "length") and hasattr(track, "evaluate")):
        raise InputError(f"{where}: track must be a railway.track.Track (or a core.curves.FramedCurve), "
                         f"got {type(track).__name__}")
    _check_definition_values(D, where)
    for arg, val in (("s0", s0), ("speed", speed), ("mu", mu), ("lateral", lateral)):
        if np.ndim(val) != 0 or val is None:
            raise InputError(f"{where}({arg}=...): one number (or a string with a unit), got {val!r}")
    s0 = float(parse_quantity(s0, "m", where=f"{where}(s0=...)"))
    speed = float(R.check("speed", speed, where=f"{where}(speed=...)", accept=accept))
    mu = float(R.check("friction_coefficient", mu, where=f"{where}(mu=...)", accept=accept))
    lateral = float(R.check("vehicle_lateral_offset", lateral, where=f"{where}(lateral=...)", accept=accept))
    if wheelset_lateral is not None:
        if np.ndim(wheelset_lateral) != 1 or len(wheelset_lateral) != 4:
            raise InputError(f"{where}(wheelset_lateral=...): must be 4 values (leading wheelset first), "
                             f"got {wheelset_lateral!r}")
        wheelset_lateral = np.asarray(R.check("vehicle_lateral_offset", list(wheelset_lateral),
                                              where=f"{where}(wheelset_lateral=...)", accept=accept), float)
    if isinstance(speed_control, (str, int, float)) and not isinstance(speed_control, bool):
        speed_control = float(R.check("speed", speed_control, where=f"{where}(speed_control=...)", accept=accept))
    elif isinstance(speed_control, bool) or not (speed_control is None or callable(speed_control)):
        raise InputError(f"{where}(speed_control=...): a speed (m/s, or a string with a unit), a function "
                         f"V(t) or a TimeFunction, got {speed_control!r}")
    if control_gain is not None:
        control_gain = float(parse_quantity(control_gain, "N*s/m", where=f"{where}(control_gain=...)"))
        if control_gain <= 0:
            raise InputError(f"{where}(control_gain=...): {control_gain:g} N s/m must be > 0")
    if isinstance(creep_law, str):
        from ..contact.creep import _ALIASES, CREEP_MODELS

        key = creep_law.strip().lower().replace("-", "_")
        if _ALIASES.get(key, key) not in CREEP_MODELS:
            names = list(CREEP_MODELS) + list(_ALIASES)
            raise UnknownNameError(f"{where}(creep_law=...): unknown creep law {creep_law!r}{closest(key, names)} "
                                   f"(registered: {', '.join(CREEP_MODELS)})")
    if creep_params is not None and not isinstance(creep_params, dict):
        raise InputError(f"{where}(creep_params=...): a dict of the creep law's parameters, got {creep_params!r}")
    if creep_params:
        import inspect

        from ..contact.creep import _ALIASES, CREEP_MODELS, CreepModel

        if isinstance(creep_law, CreepModel):
            raise InputError(f"{where}(creep_params=...): parameters {sorted(creep_params)} given with a creep law "
                             f"instance {creep_law!r}; give them to its constructor")
        if isinstance(creep_law, str):
            key = creep_law.strip().lower().replace("-", "_")
            cls = CREEP_MODELS[_ALIASES.get(key, key)]
        else:
            cls = creep_law
        if isinstance(cls, type):
            sig = inspect.signature(cls.__init__).parameters
            if not any(p.kind is p.VAR_KEYWORD for p in sig.values()):
                check_keywords(creep_params, [n for n in sig if n != "self"],
                               where=f"{where}(creep_params=...) of {cls.__name__}")
    if contact_options is not None:
        if not isinstance(contact_options, dict):
            raise InputError(f"{where}(contact_options=...): a dict of WheelRailContact options, "
                             f"got {contact_options!r}")
        allowed = [f.name for f in dataclasses.fields(WheelRailContact) if f.name not in _SET_BY_BUILD]
        check_keywords(contact_options, allowed, where=f"{where}(contact_options=...)")
    return s0, speed, mu, lateral, wheelset_lateral, speed_control, control_gain


@checked_options
def build_vehicle(definition: VehicleDefinition, track, s0: float, speed: float = 0.0, *,
                  creep_law="kalker_linear", creep_params=None, mu=0.3, lateral=0.0,
                  wheelset_lateral=None, speed_control=None, control_gain=None, unloaded=True,
                  contact_options=None, name="vehicle", parking=False, accept=()) -> Vehicle:
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
    accept : sequence of str
        Quantities of ``data/railway/plausible_ranges.csv`` whose plausible range is not enforced
        (a deliberate outlier, e.g. ``accept=["speed"]``).

    The suspension is unloaded in the straight design geometry of the vehicle: where the track
    under it is not straight the model is built on the tangent at ``s0`` and its initial state
    placed on the track (each body at its own arc length); start runs there from
    :meth:`Vehicle.initial_state` (the quasi-static curving state).

    The arguments are checked first (:func:`_check_build_arguments`): ``s0``, ``speed``,
    ``lateral`` and ``speed_control`` may be given with a unit (``speed="72 km/h"``, a bare
    number is SI); a speed, friction coefficient or lateral offset outside its plausible range,
    an unknown creep law or contact option, and a vehicle that does not fit on an open track
    are refused with one line naming the argument.
    """
    from core.model import ModelBuilder

    from .traction import TrackSpeedControl
    from .wheel_rail import WheelRailContact

    s0, speed, mu, lateral, wheelset_lateral, speed_control, control_gain = _check_build_arguments(
        definition, track, s0, speed, creep_law, creep_params, mu, lateral, wheelset_lateral, speed_control,
        control_gain, contact_options, accept)
    D = definition
    g = D.geometry
    b = ModelBuilder(3, name, gravity=(0.0, 0.0, -GRAVITY))
    dz1, dz2 = D.static_deflections() if unloaded else (0.0, 0.0)
    r0 = D.r0
    L_b, a_w = g["bogie_centre_semi_distance"], g["bogie_semi_wheelbase"]
    wl = np.zeros(4) if wheelset_lateral is None else np.asarray(wheelset_lateral, float)
    if wl.shape != (4,):
        raise InputError(f"build_vehicle: wheelset_lateral must have 4 values, got {wheelset_lateral!r}")
    s_b = [s0 + L_b, s0 - L_b]
    s_w = [s_b[0] + a_w, s_b[0] - a_w, s_b[1] + a_w, s_b[1] - a_w]
    if not getattr(track, "closed", False) and (min(s_w) < 0 or max(s_w) > track.length):
        ext = L_b + a_w
        end = "before the start" if min(s_w) < 0 else "beyond the end"
        at = min(s_w) if min(s_w) < 0 else max(s_w)
        which = "rear" if min(s_w) < 0 else "leading"
        lo, hi = ext, track.length - ext
        fit = (f"place the car body at {lo:g} m <= s0 <= {hi:g} m" if lo <= hi else
               f"the track ({track.length:g} m) is shorter than the vehicle's wheelbase ({2 * ext:g} m)")
        raise InputError(f"build_vehicle: the {which} wheelset at s = {at:g} m lies {end} of the track "
                         f"[0, {track.length:g}] m (car body at s0 = {s0:g} m): {fit}")

    # the suspension is unloaded in the vehicle's design geometry, its bodies in a straight line:
    # on a curve or transition the model is built on the tangent at s0 and then placed on the
    # track (railway.vehicles.curving_start, "Reference geometry"); on straight track the two coincide
    straight = _straight_track(track, min(s_w), max(s_w))
    on_track = {}

    def place(s, y, z):
        if straight:
            return _placement(track, s, y, z)
        pos, R = _placement(track, s0, 0.0, 0.0)
        return pos + R @ np.array([s - s0, y, z]), R

    def add(nm, body, s, y, z, omega_axle=0.0):
        on_track[nm] = (_placement(track, s, y, z), omega_axle)
        pos, R = place(s, y, z)
        t = R[:, 0]
        b.add_body(nm, mass=body["mass"], inertia=body["inertia"], position=pos,
                   orientation=frames.matrix_to_euler(R), velocity=speed * t,
                   angular_velocity=omega_axle * R[:, 1])
        return pos, R

    cb = "car body"
    flex = D.car_body.get("flexible")
    if flex is None:
        add(cb, D.car_body, s0, lateral, g["car_body_cg_height"] + dz1 + dz2)
        frames_cb, beam = {}, None
    else:
        frames_cb, beam = _add_flexible_car_body(b, D, cb, straight, place, s0, lateral,
                                                 g["car_body_cg_height"] + dz1 + dz2, speed)

    def cb_at(k):
        """The car-body end of the suspension of bogie k: the body, or the node frame over the
        bogie centre of a flexible car body."""
        return frames_cb.get(f"over bogie {k + 1}", cb)
    bogies = ["bogie 1", "bogie 2"]
    for k, nm in enumerate(bogies):
        add(nm, D.bogie, s_b[k], lateral, g["bogie_cg_height"] + dz1)
    wheelsets = [f"wheelset {k + 1}" for k in range(4)]
    for k, nm in enumerate(wheelsets):
        add(nm, D.wheelset, s_w[k], lateral + wl[k], r0, omega_axle=speed / r0)
    bs0 = {n: place(s, lateral, 0.0) for n, s in
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
            b.add_bushing(f"secondary {k + 1} {side}", cb_at(k), bg, at=P, point_j=Q,
                          translational_stiffness=D.secondary["stiffness"],
                          rotational_stiffness=(0.0, 0.0, D.secondary["yaw_stiffness"]),
                          translational_damping=D.secondary["damping"], rotational_damping=0.0, axes=R)
        P = point(cb, s0, s_b[k] - s0, 0.0, hs + dz1 + dz2)
        Q = point(bg, s_b[k], 0.0, 0.0, hs + dz1)
        if D.anti_roll_bar > 0:
            b.add_bushing(f"anti-roll bar {k + 1}", cb_at(k), bg, at=P, point_j=Q, translational_stiffness=0.0,
                          rotational_stiffness=(D.anti_roll_bar, 0.0, 0.0), axes=R)
        if D.bump_stop is not None:
            b.add_bump_stop(f"lateral bump stop {k + 1}", cb_at(k), bg, at=P, axis=R[:, 1],
                            table=np.column_stack([D.bump_stop["displacement"], D.bump_stop["force"]]), point_j=Q)
        for j, yd in enumerate(D.yaw_dampers):
            for side, sgn in (("left", 1.0), ("right", -1.0)):
                # longitudinal damper: car body end x ahead of the bogie centre, bogie end at it
                P = point(cb, s0, s_b[k] - s0 + yd["x"], sgn * yd["y"], yd["z"] + dz1 + dz2)
                Q = point(bg, s_b[k], 0.0, sgn * yd["y"], yd["z"] + dz1)
                b.add_series_spring_damper(f"yaw damper {k + 1}.{j + 1} {side}", cb_at(k), bg, P, Q,
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
    if not straight:
        model = _place_on_track(model, on_track, speed)
    return Vehicle(definition=D, model=model, track=track, car_body=cb, bogies=bogies, wheelsets=wheelsets,
                   contact=contact, s0=float(s0), speed=float(speed), creep_law=creep_law,
                   _contact_options=contact_options, car_body_frames=frames_cb, car_body_component=beam)


def _add_flexible_car_body(b, D, cb, straight, place, s0, lateral, z, speed):
    """The car body of ``[car_body.flexible]`` (:mod:`railway.vehicles.car_body`): a flexible body
    with the undeformed inertia at the centre of mass, and node frames at the car-body centre and
    over both bogie centres; returns their names by station and the component (the equivalent beam
    or the imported FE model)."""
    from .car_body import car_body_beam

    if not straight:
        raise InputError(f"build_vehicle: vehicle {D.name!r} has a flexible car body, which starts on straight "
                         f"track only (the quasi-static curving start of a flexible body is not built yet); "
                         f"place it where the track under it is straight (s0 = {s0:g} m is not)")
    fx = D.car_body["flexible"]
    L_b = D.geometry["bogie_centre_semi_distance"]
    where = f"{D.name!r} car body"
    if fx.get("mass_matrix") is not None:  # an FE model exported by another code
        from .car_body import imported_car_body

        body = imported_car_body(fx["mass_matrix"], fx["stiffness_matrix"], fx["nodes"], fx["centre_node"],
                                 fx["bogie_nodes"], D.car_body["mass"], D.car_body["inertia"], L_b, fx["modes"],
                                 fx["dofs_per_node"], fx["length_unit"], fx["mass_unit"], fx["force_unit"], where=where)
        nodes = body.stations
    else:
        body = car_body_beam(D.car_body["mass"], D.car_body["inertia"], fx["length"], [0.0, L_b, -L_b],
                             fx["vertical_bending_frequency"], fx.get("torsion_frequency"),
                             fx.get("lateral_bending_frequency"), fx.get("elements", 24), where=where)
        nodes = {label: body.stations[float(x)]
                 for label, x in (("centre", 0.0), ("over bogie 1", L_b), ("over bogie 2", -L_b))}
    pos, R = place(s0, lateral, z)
    b.add_flexible_body(cb, body.fe, body.modes, position=pos, orientation=frames.matrix_to_euler(R),
                        velocity=speed * R[:, 0], damping_ratio=fx["damping_ratio"], inertia="undeformed")
    names = {label: b.add_node_frame(cb, node, name=f"{cb} {label}") for label, node in nodes.items()}
    return names, body
