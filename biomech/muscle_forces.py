r"""Muscle forces over a gait trial: the redundancy of the joint moments solved per frame.

Given the generalized forces τ(t) of inverse dynamics (:mod:`biomech.inverse_dynamics`), the
muscles share them: per frame

.. math::

    \sum_j r_{ij}(q)\,\big(a_j A_j(q, \dot q) + P_j(q, \dot q)\big) + r^{opt}_i u_i = \tau_i ,
    \qquad 0 \le a_j \le 1 ,

with the moment arms r_ij = −∂L_j/∂q_i of the musculotendon paths (:class:`biomech.skeleton.Skeleton`,
via, conditional and moving points), the active force per unit activation
A_j = F0_j f_L f_V cos α_j and the passive force P_j = F0_j f_PE cos α_j of the Hill-type muscle
with a rigid tendon (Thelen 2003; :class:`biomech.muscles.ThelenMuscleSet`), whose fibre length
and velocity follow from L_j and L̇_j = −Σ_i r_ij q̇_i, and reserve actuators u_i of optimal
force r^opt_i (OpenSim's reserve file).  The activations minimise the chosen criterion
(:class:`biomech.static_optimization.StaticOptimization`, one cvxpy problem with parameters,
solved by Clarabel): the paper's Σ (F_j / PCSA_j)³ or OpenSim's Σ a_j².

Choices, where OpenSim differs
------------------------------
* Muscle curves: Thelen 2003 for every muscle (gait10dof18musc's muscles are Millard 2012
  equilibrium muscles in OpenSim; the four parameters F0, l_opt, l_TS, α0 are the same, the
  curves are not).
* Passive force enters the equations by default (OpenSim's static optimization leaves it out;
  ``passive=False`` does the same).  With a rigid tendon the passive force of a stretched muscle
  can exceed what the antagonists can balance (gait2392's knee extensors in swing): those frames
  are reported infeasible with their residual, not hidden.
* The pelvis residual actuators FX, FY, FZ (point actuators on the pelvis) and MX, MY, MZ
  (torques) of a reserve file are taken as actuators on the pelvis coordinates tx, ty, tz, list,
  rotation and tilt with the same optimal forces: the same space of generalized forces in the
  planar model; their cost differs from OpenSim's by the rotation of the actuators' directions
  with the pelvis (a few degrees in walking) and, in 3-D, by the difference between body axes and
  the pelvis's Euler-angle coordinates.
* Activation bounds [0, 1] (OpenSim's Millard muscles keep a minimum activation of 0.01).

References
----------
Crowninshield, R. D. and Brand, R. A. (1981). A physiologically based criterion of muscle force
prediction in locomotion. J. Biomech. 14:793–801.  Anderson, F. C. and Pandy, M. G. (2001).
Static and dynamic optimization solutions for gait are practically equivalent. J. Biomech.
34:153–161.  Silva & Ambrósio (2003), Mech. Based Des. Struct. Mach. 31:381–411.
"""

from __future__ import annotations

import time

import numpy as np
import pandas as pd

from core.errors import InputError

from .checks import check_window, checked_options, name_hint

__all__ = ["muscle_inputs", "muscle_redundancy", "reserve_optimal_forces", "PELVIS_RESIDUALS"]

#: OpenSim's pelvis residual actuators and the coordinate each one is taken on (the force
#: components on the pelvis translations, the torques on the pelvis rotation about the same axis:
#: tilt about z, list about x, rotation about y in OpenSim's gait models)
PELVIS_RESIDUALS = {"FX": "pelvis_tx", "FY": "pelvis_ty", "FZ": "pelvis_tz",
                    "MX": "pelvis_list", "MY": "pelvis_rotation", "MZ": "pelvis_tilt"}


@checked_options
def muscle_inputs(trial, moments, window=None):
    """Per frame: moment arms, active and passive force per muscle, and τ.

    ``window`` (start, end) [s] must lie inside the trial's time range (a window in per cent of
    the gait cycle or in ms is refused as such, :class:`core.errors.DataRangeError`).

    Returns a dict with ``time`` (n,), ``R`` (n, n_coords, n_muscles), ``A``, ``P`` (n, n_muscles),
    ``tau`` (n, n_coords), ``coordinates``, ``coordinate_units`` (``"N m"`` for a rotational,
    ``"N"`` for a translational coordinate), ``muscles``, ``muscle_set``, ``lengths`` (n, m),
    ``speeds`` (n, m) and the wall time of the geometry.
    """
    from .muscles import ThelenMuscleSet
    from .skeleton import Skeleton

    osim = trial.osim
    K = trial.kinematics
    t = K.q["time"].to_numpy(float)
    if window is not None:
        window = check_window(window, float(t[0]), float(t[-1]),
                              where=f"muscle_inputs: trial {trial.settings.get('motion', '')}".rstrip())
    keep = np.ones(len(t), bool) if window is None else (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    if not keep.any():
        raise InputError(f"window {window} holds no frame of the trial ({t[0]:g}-{t[-1]:g} s)")
    t0 = time.perf_counter()
    sk = Skeleton(osim)
    names = list(sk.coordinate_names)
    q = np.column_stack([K.q[c].to_numpy(float)[keep] for c in names])
    qd = np.column_stack([K.qdot[c].to_numpy(float)[keep] for c in names])
    geom = sk.muscle_geometry(q)
    L = geom.length  # (n, m)
    r = geom.moment_arm  # (n, m, nq)
    Ld = -np.einsum("nmq,nq->nm", r, qd)
    mus = ThelenMuscleSet.from_muscles(osim.muscles)
    rt = mus.rigid_tendon_forces(L, Ld)
    t1 = time.perf_counter()
    ctype = {c.name: c.motion_type for c in osim.coordinates}
    missing = [c for c in names if (f"{c}_moment [N m]" if ctype[c] == "rotational" else f"{c}_force [N]")
               not in moments.columns]
    if "time [s]" not in moments.columns or missing:
        raise InputError(f"muscle_inputs: moments lack {'time [s]' if 'time [s]' not in moments.columns else missing}: "
                         f"pass the table of biomech.inverse_dynamics.inverse_dynamics(trial)")
    mt = moments["time [s]"].to_numpy(float)
    tau = []
    for c in names:
        col = f"{c}_moment [N m]" if ctype[c] == "rotational" else f"{c}_force [N]"
        y = moments[col].to_numpy(float)
        if len(mt) != len(t) or not np.allclose(mt, t):
            y = np.interp(t, mt, y)
        tau.append(y[keep])
    return dict(time=t[keep], R=np.transpose(r, (0, 2, 1)), A=np.asarray(rt.active_force_per_activation), P=np.asarray(rt.passive_force),
                tau=np.column_stack(tau), coordinates=names, muscles=list(sk.muscle_names), muscle_set=mus,
                coordinate_units=["N m" if ctype[c] == "rotational" else "N" for c in names],
                lengths=L, speeds=Ld, wall_time_geometry=t1 - t0, clamped=np.asarray(rt.kinematics.clamped))


def reserve_optimal_forces(force_set, coordinates):
    """Optimal force of the reserve on each coordinate (0: none), from an OpenSim force set.

    Parameters
    ----------
    force_set : biomech.osim.ForceSet
        From :func:`biomech.osim.read_force_set` (reserve and pelvis residual actuators).
    coordinates : sequence of str
        The coordinates in the order of the optimisation (``muscle_inputs(...)["coordinates"]``).

    Returns
    -------
    ndarray, shape (n_coordinates,)
        [N m] on a rotational, [N] on a translational coordinate.
    """
    out = np.zeros(len(coordinates))
    for act in force_set.actuators:
        c = getattr(act, "coordinate", None) or PELVIS_RESIDUALS.get(act.name)
        if c is None:
            continue
        if c not in coordinates:
            raise InputError(f"{force_set.path}: actuator {act.name!r} acts on {c!r}, which the model lacks"
                             f"{name_hint(c, coordinates)}")
        out[coordinates.index(c)] = float(act.optimal_force)
    return out


def muscle_redundancy(inputs, reserves, criterion="stress", exponent=None, passive=True, **options) -> pd.DataFrame:
    """Static optimisation over the frames of :func:`muscle_inputs`.

    ``criterion``: ``"stress"`` (Σ (F/PCSA)^p, p = 3 by default: the paper's) or
    ``"activation"`` (Σ a^p, p = 2: OpenSim's).  ``reserves``: optimal force per coordinate.
    ``passive=False`` leaves the passive fibre force out of the equations, as OpenSim's static
    optimization does.  Other ``options`` are keyword arguments of :class:`StaticOptimization`
    (a misspelt one is refused naming the closest); the reserve columns carry the unit of their
    coordinate (``reserve_pelvis_tx [N]``, ``reserve_hip_flexion_r [N m]``).
    Returns the per-frame table of :meth:`StaticOptimization.solve_trial` with the wall times in
    ``attrs``.
    """
    import inspect

    from core.inputs import check_keywords

    from .static_optimization import StaticOptimization

    accepted = [n for n in inspect.signature(StaticOptimization.__init__).parameters
                if n not in ("self", "muscle_names", "coordinate_names", "max_isometric_force", "criterion",
                             "exponent", "reserve_optimal_force")]
    check_keywords(options, ["criterion", "exponent", "passive"] + accepted, where="muscle_redundancy()")
    if "coordinate_units" not in options and "coordinate_units" in inputs:
        options["coordinate_units"] = inputs["coordinate_units"]
    mus = inputs["muscle_set"]
    t0 = time.perf_counter()
    so = StaticOptimization(inputs["muscles"], inputs["coordinates"], mus.max_isometric_force, criterion=criterion,
                            exponent=exponent, reserve_optimal_force=reserves, **options)
    t1 = time.perf_counter()
    P = inputs["P"] if passive else np.zeros_like(inputs["P"])
    df = so.solve_trial(inputs["time"], inputs["R"], inputs["A"], P, inputs["tau"])
    t2 = time.perf_counter()
    df.attrs.update(passive=bool(passive), wall_time_build=t1 - t0, wall_time_solve=t2 - t1, wall_time_geometry=inputs["wall_time_geometry"])
    return df
