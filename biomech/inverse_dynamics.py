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

from core.errors import DataRangeError, InputError

__all__ = ["GaitTrial", "load_trial", "inverse_dynamics", "gait_events"]


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


def load_trial(model_file, motion_file, external_loads_file, window=None, cutoff=6.0, order=3):
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
    """
    from .kinematics import process_coordinates
    from .osim import OsimModel, read_osim
    from .storage import check_motion_against_model, read_external_loads, read_storage, resample_external_loads

    osim = model_file if isinstance(model_file, OsimModel) else read_osim(model_file)
    motion = read_storage(motion_file, model=osim)
    check_motion_against_model(motion, osim, source=str(motion_file))
    loads = read_external_loads(external_loads_file)
    tm = motion["time"].to_numpy(float)
    lo, hi = max(tm[0], loads.time[0]), min(tm[-1], loads.time[-1])
    if window is not None:
        lo_w, hi_w = map(float, window)
        if lo_w < lo - 1e-9 or hi_w > hi + 1e-9:
            raise DataRangeError(f"window [{lo_w:g}, {hi_w:g}] s is outside the range covered by both "
                                 f"{motion_file} ({tm[0]:g}-{tm[-1]:g} s) and {loads.source} "
                                 f"({loads.time[0]:g}-{loads.time[-1]:g} s)")
        lo, hi = lo_w, hi_w
    if hi <= lo:
        raise DataRangeError(f"{motion_file} ({tm[0]:g}-{tm[-1]:g} s) and {loads.source} "
                             f"({loads.time[0]:g}-{loads.time[-1]:g} s) do not overlap")
    kin = process_coordinates(motion, cutoff=cutoff, order=order)  # filtered over the whole record
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
    kin = kinematic_analysis(m, times, q_guess=m.q0)
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
    raise InputError(f"no external force acts on {body!r}")
