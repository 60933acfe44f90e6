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

__all__ = ["muscle_inputs", "muscle_redundancy", "reserve_optimal_forces", "PELVIS_RESIDUALS", "group_force",
           "cycle_peak", "frame_status", "reserve_summary", "status_summary"]

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


# ---------------------------------------------------------------------------------------------
# summaries of the per-frame solutions
# ---------------------------------------------------------------------------------------------
def _residual_column(solution: pd.DataFrame) -> str:
    return [c for c in solution.columns if c.startswith("max |R F")][0]


def group_force(solution: pd.DataFrame, members) -> np.ndarray:
    """The force of a muscle group per frame, F_group = Σ_j F_j over its ``members`` [N].

    Parameters
    ----------
    solution : pandas.DataFrame
        :func:`muscle_redundancy` (columns ``F_<muscle> [N]``).
    members : sequence of str
        Muscle names.

    Returns
    -------
    (n_frames,) ndarray
    """
    return sum(solution[f"F_{m} [N]"] for m in members).to_numpy()


def cycle_peak(y, pct, other_half: bool = False) -> dict:
    """The largest value of ``y`` over the gait cycle and where it lies [% of the cycle].

    With ``other_half`` also the largest value in the other half of the cycle (pct < 50 when the
    peak lies at pct >= 50, else pct >= 50): the second peak of a group active twice per cycle.

    Parameters
    ----------
    y : (n,) array_like
        The quantity per frame (a group force, N).
    pct : (n,) array_like
        The frames' position in the gait cycle [%].
    other_half : bool

    Returns
    -------
    dict
        ``peak force [N]``, ``at [% gait cycle]`` and, with ``other_half``, ``other-half peak [N]``,
        ``at, other half [% gait cycle]``.
    """
    y, pct = np.asarray(y, float), np.asarray(pct, float)
    i = int(np.argmax(y))
    row = {"peak force [N]": float(y[i]), "at [% gait cycle]": float(pct[i])}
    if other_half:
        half = pct < 50.0 if pct[i] >= 50.0 else pct >= 50.0
        j = int(np.argmax(np.where(half, y, -np.inf)))
        row.update({"other-half peak [N]": float(y[j]), "at, other half [% gait cycle]": float(pct[j])})
    return row


def frame_status(solutions: dict, pct) -> pd.DataFrame:
    """Per criterion and frame: the solver's status, the largest equation residual
    max_i ``|Σ_j r_ij F_j + r_i^opt u_i − τ_i|`` and the solve time.

    Parameters
    ----------
    solutions : dict
        Criterion name -> :func:`muscle_redundancy` table.
    pct : (n_frames,) array_like
        The frames' position in the gait cycle [%].

    Returns
    -------
    pandas.DataFrame
        ``criterion``, ``time [s]``, ``gait cycle [%]``, ``status``, ``max |R F + r - tau|``,
        ``solve time [ms]``.
    """
    rows = []
    for crit, d in solutions.items():
        res = _residual_column(d)
        for i in range(len(d)):
            rows.append({"criterion": crit, "time [s]": float(d["time [s]"].iloc[i]),
                         "gait cycle [%]": float(pct[i]), "status": d["status"].iloc[i],
                         "max |R F + r - tau|": float(d.iloc[i][res]),
                         "solve time [ms]": float(d["solve time [s]"].iloc[i] * 1e3)})
    return pd.DataFrame(rows)


def reserve_summary(solutions: dict) -> pd.DataFrame:
    """Per criterion and reserve actuator: its largest magnitude and RMS over the frames.

    Parameters
    ----------
    solutions : dict
        Criterion name -> :func:`muscle_redundancy` table (columns ``reserve_<coordinate> [unit]``).

    Returns
    -------
    pandas.DataFrame
        ``criterion``, ``reserve``, ``unit``, ``max |.|``, ``rms``.
    """
    rows = []
    for crit, d in solutions.items():
        for c in [c for c in d.columns if c.startswith("reserve_")]:
            rows.append({"criterion": crit, "reserve": c, "unit": c[c.index("[") + 1:-1],
                         "max |.|": float(d[c].abs().max()), "rms": float(np.sqrt(np.mean(d[c] ** 2)))})
    return pd.DataFrame(rows)


def status_summary(runs: dict) -> pd.DataFrame:
    """Per run (criterion, passive force or not): frames per solver status, the largest equation
    residual and the solve time per frame.

    Parameters
    ----------
    runs : dict
        (criterion, passive) -> :func:`muscle_redundancy` table.

    Returns
    -------
    pandas.DataFrame
        ``criterion``, ``passive force``, ``frames``, ``frames <status>`` (one column per status,
        0 where a run has none), ``largest residual [unit]``, ``per frame [ms]``.
    """
    rows = []
    for (crit, passive), d in runs.items():
        counts = d["status"].value_counts().to_dict()
        res = _residual_column(d)
        rows.append({"criterion": crit, "passive force": "included" if passive else "left out (as OpenSim)",
                     "frames": len(d), **{f"frames {k}": v for k, v in counts.items()},
                     f"largest residual {res[res.index('['):]}": float(d[res].max()),
                     "per frame [ms]": 1e3 * d.attrs["wall_time_solve"] / len(d)})
    st = pd.DataFrame(rows)
    fc = [c for c in st.columns if c.startswith("frames ")]
    st[fc] = st[fc].fillna(0).astype(int)
    return st
