r"""Gait inverse dynamics on the Cartesian core: joint moments from measured kinematics and
ground reaction forces.

The pipeline, as OpenSim's inverse-dynamics tool runs it and with the same choices unless
stated:

1. read the model (:func:`biomech.osim.read_osim`), the coordinates (``.mot``,
   :func:`biomech.storage.read_storage`, degrees converted) and the external loads (``.xml`` +
   ``.mot``, :func:`biomech.storage.read_external_loads`);
2. low-pass filter the coordinates (zero-lag Butterworth at 6 Hz, 3rd order per pass run
   forward and backward, as OpenSim's inverse-dynamics tool does) and differentiate them
   through a quintic spline (:func:`biomech.kinematics.process_coordinates`);
3. resample the force-plate data onto the kinematics' times (natural cubic spline,
   :func:`biomech.storage.resample_external_loads`; an error names the file when they do not
   cover the kinematics);
4. build the Cartesian model with every coordinate driven (:mod:`biomech.sagittal`) and run
   core's kinematic analysis (positions, velocities, accelerations of every body from Φ = 0,
   Φ_q v = ν, Φ_q a = γ) and core's inverse dynamics (Φ_qᵀ λ = Q − M a);
5. map the multipliers to the coordinates' generalized forces τ = −(∂h/∂q)ᵀ λ, named as
   OpenSim names them (``hip_flexion_r_moment``, ``pelvis_tx_force``); the pelvis's three are
   the residual forces and moment of an unbalanced trial.

The time window defaults to the common range of kinematics and force data.

References
----------
Silva & Ambrósio (2003), Mech. Based Des. Struct. Mach. 31:381–411 (driving constraints and
their multipliers); Delp et al. (2007), IEEE Trans. Biomed. Eng. 54:1940–1950 (OpenSim);
Winter (2009), Biomechanics and Motor Control of Human Movement, 4th ed., ch. 5 (inverse
dynamics of gait, moments normalised by body mass).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from core.errors import DataRangeError, InputError, ModelError

from .checks import check_value, check_window, checked_options, ranges, warn_sampling
from .kinematics import check_cutoff

__all__ = ["GaitTrial", "load_trial", "inverse_dynamics", "gait_events", "right_gait_cycle"]


@dataclass
class GaitTrial:
    """A model with its processed trial, ready for inverse dynamics."""

    osim: object
    kinematics: object
    loads: object
    window: tuple[float, float]
    settings: dict = field(default_factory=dict)

    @property
    def body_mass(self) -> float:
        return float(sum(b.mass for b in self.osim.bodies))


@checked_options
def load_trial(model_file, motion_file, external_loads_file, window=None, cutoff=6.0, order=3, *, accept=()):
    """Read and process a trial (steps 1–3 of the module docstring).

    Parameters
    ----------
    model_file, motion_file, external_loads_file : path-like
        ``model_file`` may also be a :class:`biomech.osim.OsimModel` built in memory (e.g. by
        :func:`biomech.anthropometry.anthropometric_sagittal_model`).
    window : (float, float), optional
        Time range [s]; default the common range of the motion and the force data.
    cutoff : float or None
        Low-pass cut-off of the coordinates [Hz] (None: no filter).
    order : int
        Butterworth order per pass: 3 (default) is OpenSim's 3rd-order IIR run forward and
        backward (6th order, zero lag); 2 gives the common 4th-order zero-lag filter.
    accept : sequence of str
        Plausible-range quantities not to enforce (``data/biomech/plausible_ranges.csv``), passed on
        to the readers.

    Raises
    ------
    core.inputs.ImplausibleValueError
        A value outside its plausible range (file, column or argument named, with the likely
        slip): segment masses, muscle parameters, translations, centre of pressure, ground
        reactions, the cut-off, the sampling rates (a time column in ms), the model's mass against
        the ground reactions (peak vertical reaction 0.7-6 body weights: a mass in pounds or grams).
    core.errors.DataRangeError
        A window outside the data's time range (per cent of the gait cycle or ms named as such).
    core.errors.ModelError
        An external force applied to (or expressed in) a body the model lacks (closest named).

    Warns
    -----
    biomech.checks.SamplingRateWarning
        Force data sampled more coarsely than the kinematics.
    """
    from .kinematics import process_coordinates
    from .osim import OsimModel, read_osim
    from .storage import check_motion_against_model, read_external_loads, read_storage, resample_external_loads

    accept = tuple([accept] if isinstance(accept, str) else accept)
    if order not in (1, 2, 3, 4, 5, 6, 7, 8, 9, 10) or isinstance(order, bool):
        raise InputError(f"load_trial(order={order!r}): the Butterworth order per pass must be an integer 1..10")
    if cutoff is not None:
        cutoff = check_cutoff(cutoff, where="load_trial(cutoff=...)", accept=accept)
    osim = model_file if isinstance(model_file, OsimModel) else read_osim(model_file, accept=accept)
    where_model = str(model_file) if not isinstance(model_file, OsimModel) else f"model {osim.name!r}"
    check_value("body_mass", osim.total_mass, where=f"{where_model}: total mass of the bodies", accept=accept)
    motion = read_storage(motion_file, model=osim, accept=accept)
    check_motion_against_model(motion, osim, source=str(motion_file))
    loads = read_external_loads(external_loads_file, accept=accept)
    _check_loads_against_model(loads, osim)
    tm = motion["time"].to_numpy(float)
    fs_k = _rate(tm)
    fs_f = _rate(loads.time)
    for quantity, fs, src in (("coordinate_sample_rate", fs_k, motion_file), ("force_sample_rate", fs_f, loads.source)):
        lowest = ranges()[quantity].low
        hint = ("the time column looks like milliseconds or frame numbers; times must be in seconds"
                if fs < lowest else "")
        check_value(quantity, fs, where=f"{src}: time column", accept=accept, hint=hint)
    if fs_f < fs_k * (1 - 1e-6):
        warn_sampling(f"{loads.source} is sampled at {fs_f:.6g} Hz, more coarsely than the kinematics {motion_file} "
                      f"({fs_k:.6g} Hz): the ground reactions are interpolated between their samples and impacts "
                      f"are smoothed (force plates are normally sampled 5-20 times faster)")
    _check_body_weight(loads, osim, where_model, accept)
    lo, hi = max(tm[0], loads.time[0]), min(tm[-1], loads.time[-1])
    if hi <= lo:
        raise DataRangeError(f"{motion_file} ({tm[0]:g}-{tm[-1]:g} s) and {loads.source} "
                             f"({loads.time[0]:g}-{loads.time[-1]:g} s) do not overlap")
    if window is not None:
        lo, hi = check_window(window, lo, hi, where=f"load_trial: {motion_file} ({tm[0]:g}-{tm[-1]:g} s) and "
                                                    f"{loads.source} ({loads.time[0]:g}-{loads.time[-1]:g} s) together")
    kin = process_coordinates(motion, cutoff=cutoff, order=order, accept=accept)  # filtered over the whole record
    keep = (tm >= lo - 1e-9) & (tm <= hi + 1e-9)

    class _K:  # the processed kinematics restricted to the window
        pass

    k = _K()
    k.q, k.qdot, k.qddot = (d[keep].reset_index(drop=True) for d in (kin.q, kin.qdot, kin.qddot))
    k.settings = kin.settings
    times = k.q["time"].to_numpy(float)
    loads_r = resample_external_loads(loads, times)
    return GaitTrial(osim, k, loads_r, (float(times[0]), float(times[-1])),
                     dict(cutoff_hz=cutoff, order_per_pass=order,
                          model=(osim.path or osim.name) if osim is model_file else str(model_file),
                          motion=str(motion_file), external_loads=str(external_loads_file)))


def _rate(t: np.ndarray) -> float:
    dt = np.diff(np.asarray(t, float))
    return 1.0 / float(np.median(dt)) if dt.size else float("nan")


def _check_loads_against_model(loads, osim) -> None:
    """Every external force acts on, and is expressed in, a body of the model (or ground)."""
    from .checks import name_hint

    names = [b.name for b in osim.bodies] + [osim.ground]
    for f in loads.spec.forces:
        for what, body in (("applied_to_body", f.applied_to_body), ("force_expressed_in_body", f.force_expressed_in_body),
                           ("point_expressed_in_body", f.point_expressed_in_body)):
            if body not in names:
                raise ModelError(f"{loads.spec.path}: external force {f.name!r}: {what} {body!r} is not a body of model "
                                 f"{osim.name!r}{name_hint(body, names)}")


def _check_body_weight(loads, osim, where_model: str, accept) -> None:
    """The peak vertical ground reaction, in body weights of the model's mass, must be plausible."""
    from core.inputs import ImplausibleValueError

    if "grf_body_weights" in accept:
        return
    g = np.asarray(osim.gravity, float)
    gn = float(np.linalg.norm(g))
    acting = [f for f in loads.forces if f.spec.applies_force]
    if gn == 0 or not acting or osim.total_mass <= 0:
        return
    up = -g / gn
    fv = np.sum([np.asarray(f.force, float) @ up for f in acting], axis=0)
    peak = float(np.max(fv))
    if not peak > 0:
        return
    mass = float(osim.total_mass)
    bw = peak / (mass * gn)
    r = ranges()["grf_body_weights"]
    if r.contains(bw):
        return
    if bw < r.low:
        cause = (f"the model's mass is too large for these forces: a mass in pounds ({mass:.4g} lb = "
                 f"{mass * 0.45359237:.4g} kg)?" if r.contains(bw / 0.45359237) else
                 "the forces are too small for the model's mass (forces scaled, or the mass in another unit?)")
    else:
        cause = "the forces are too large for the model's mass (segment masses missing, forces in another unit, or a " \
                "wrong model?)"
    raise ImplausibleValueError(
        f"{loads.source}: the peak vertical ground reaction {peak:.4g} N is {bw:.3g} body weights of {where_model}'s "
        f"{mass:.4g} kg, outside the plausible range {r.describe()}: {cause} (to use it deliberately, "
        f"accept='grf_body_weights')", "grf_body_weights", bw, cause)


def inverse_dynamics(trial: GaitTrial) -> pd.DataFrame:
    """Joint moments and forces of every coordinate over the trial (steps 4–5).

    Returns
    -------
    DataFrame
        ``time [s]`` and ``<coordinate>_moment [N m]`` / ``<coordinate>_force [N]``;
        ``attrs``: ``max_residual`` (of Φ_qᵀλ = Q − M a, zero for a driven mechanism),
        ``kinematic_status``, wall times, the settings, ``joint_reactions`` (a DataFrame of the
        joint reaction forces, :meth:`biomech.sagittal.SagittalModel.joint_reactions`).
    """
    from core.analysis import inverse_dynamics as core_id
    from core.analysis import kinematic_analysis

    from .sagittal import build_sagittal_model

    t0 = time.perf_counter()
    sm = build_sagittal_model(trial.osim, trial.kinematics, trial.loads)
    m = sm.model
    times = trial.kinematics.q["time"].to_numpy(float)
    t1 = time.perf_counter()
    kin = kinematic_analysis(m, times, q_guess=sm.q_frames)  # all frames at once (core.analysis)
    if kin.attrs["status"] != "finished":
        raise InputError(f"kinematic analysis of {trial.settings.get('motion')}: {kin.attrs['message']}")
    qn = [c for c in kin.columns[1:1 + m.n_q]]
    q = kin[qn].to_numpy()
    v = kin.iloc[:, 1 + m.n_q:1 + m.n_q + m.n_v].to_numpy()
    a = kin.iloc[:, 1 + m.n_q + m.n_v:].to_numpy()
    t2 = time.perf_counter()
    res = core_id(m, times, q, v, a, drivers=[])
    lam = res[[c for c in res.columns if c.startswith("lambda[")]].to_numpy()
    out = sm.generalized_forces(times, q, lam)
    reactions = sm.joint_reactions(times, q, lam)
    t3 = time.perf_counter()
    out.attrs.update(max_residual=float(res.attrs["max_residual"]), kinematic_status=kin.attrs["status"],
                     wall_time_build=t1 - t0, wall_time_kinematics=t2 - t1, wall_time_inverse_dynamics=t3 - t2,
                     n_frames=len(times), body_mass=trial.body_mass, **trial.settings)
    out.attrs["cartesian"] = dict(q=q, v=v, a=a, lam=lam)
    out.attrs["joint_reactions"] = reactions
    return out


@checked_options
def gait_events(loads, body, threshold=20.0):
    """Heel strikes and toe-offs of the foot ``body`` from its vertical ground reaction force.

    Heel strike: the vertical force rises through ``threshold`` [N]; toe-off: it falls through
    it (linear interpolation between samples; a common force-plate rule, Zeni et al. 2008 use
    kinematics instead).  Returns (heel_strikes, toe_offs) [s].
    """
    for f in loads.forces:
        if f.spec.applied_to_body == body:
            Fy = np.asarray(f.force, float)[:, 1]
            t = np.asarray(f.time, float)
            on = Fy > threshold
            up = np.nonzero(~on[:-1] & on[1:])[0]
            dn = np.nonzero(on[:-1] & ~on[1:])[0]

            def cross(i):
                return t[i] + (threshold - Fy[i]) * (t[i + 1] - t[i]) / (Fy[i + 1] - Fy[i])

            return np.array([cross(i) for i in up]), np.array([cross(i) for i in dn])
    from .checks import name_hint

    bodies = [f.spec.applied_to_body for f in loads.forces]
    raise InputError(f"no external force acts on {body!r} (they act on {bodies}){name_hint(str(body), bodies)}")


def right_gait_cycle(trial):
    """The right gait cycle of a trial: two successive right heel strikes (start, end) [s].

    Heel strikes from :func:`gait_events` on ``calcn_r``: its vertical ground reaction force
    rises through 20 N.

    Parameters
    ----------
    trial : GaitTrial

    Returns
    -------
    (float, float)

    Raises
    ------
    InputError
        Fewer than two right heel strikes in the trial.
    """
    hs, _ = gait_events(trial.loads, "calcn_r")
    if len(hs) < 2:
        raise InputError(f"{trial.settings.get('external_loads', 'the trial')}: fewer than two right heel strikes "
                         f"(calcn_r's vertical ground reaction rises through 20 N only {len(hs)} times)")
    return float(hs[0]), float(hs[1])
