r"""The simulation driver: run an integrator over a time span and record what a report needs.

:func:`simulate` steps any integrator of :mod:`core.integrators` (a registered name or an
:class:`core.integrators.Integrator` subclass) through the time span, samples the state at the
output times from each step's dense output (or lands on them, for methods that step to outputs),
and records at every output time

* the position and velocity constraint violations ``max|Φ|`` and ``max|Φ_q v − ν|`` (plus
  coordinate invariants such as ``|p|² − 1`` of Euler parameters),
* the total energy, for systems that define it,
* the multipliers (the method's own when it provides consistent ones, else the index-1 KKT
  solution at the output state) and the joint reactions computed from them,

and the run metadata (method, tolerances, counters, solve and total wall time).  A run that
fails (NaN, divergence, an unmet tolerance, a singular matrix) returns with ``status ==
"failed"``, the message saying where and why, everything computed up to that point and, as its
last row, the last good state at the time where the run stopped.  Exceptions that are not
numerical failures (:data:`core.errors.RUN_FAILURES`) propagate.

The integrator protocol itself (step objects, status, counters, dense output, registry) is
:mod:`core.integrators.base`; this module only drives it.
"""

from __future__ import annotations

import time as _time

import numpy as np

from .errors import RUN_FAILURES, InputError
from .integrators.base import (
    FINISHED_STATUSES,
    STATUS_FAILED,
    STATUS_FINISHED,
    STATUS_RUNNING,
    Integrator,
    get_method,
)
from .results import AcceptedSteps, SimulationResult, run_metadata
from .system import ConstrainedSystem

__all__ = ["ENERGY_WARN_FACTOR", "VIOLATION_WARN_FACTOR", "result_checks", "simulate"]

#: A conservative run warns when ``max|E − E0| > ENERGY_WARN_FACTOR · (rtol · (E_scale + qQ_scale) +
#: atol · p_scale)`` (see :func:`result_checks`).  On the pendulum study of the tests (every adaptive
#: method, rtol 1e-2 … 1e-8) the drift relative to m g l was 0.3–7.5 times the angle error in rad, so a
#: factor 3 flags every run whose error exceeds 10 × rtol.
ENERGY_WARN_FACTOR = 3.0
#: Any run warns when a position constraint is violated by more than
#: ``VIOLATION_WARN_FACTOR · (atol + rtol · max(1, max|q|))`` at an output time.
VIOLATION_WARN_FACTOR = 10.0


def _force_per_coordinate(system, q, force):
    """``g = Z⁺ᵀ Q``: the generalized force conjugate to each coordinate (``Q`` where ``q̇ = v``)."""
    if system.n_q == system.n_v:
        return force
    Z = system.Z(q)
    Z = Z.toarray() if hasattr(Z, "toarray") else np.asarray(Z, float)
    return np.linalg.pinv(Z).T @ force


def result_checks(system: ConstrainedSystem, t, Q, V, energy, position_violation, rtol: float,
                  atol: float) -> list[str]:
    r"""Checks of a finished run against physics that need no reference; one message per failed check.

    * **Energy** (``system.is_conservative``): the total energy of the exact motion is constant, so

      .. math::

          \max_t |E - E_0| > F \,\big(\mathrm{rtol}\,(E_\mathrm{scale} + qQ_\mathrm{scale})
          + \mathrm{atol}\, p_\mathrm{scale}\big), \qquad F = \texttt{ENERGY\_WARN\_FACTOR},

      is an error the tolerances did not allow, with ``E_scale = max_t ½ vᵀM v`` (the peak kinetic
      energy: independent of the potential's datum; ``|E0|`` for a run at rest),
      ``p_scale = max_t (‖M v‖₁ + ‖Q‖₁)``, the change of ``E`` per unit absolute error of every
      coordinate (``∂E/∂v = M v``, ``∂E/∂q = −Q`` for conservative forces), and
      ``qQ_scale = max_t Σ_j |g_j| |q_j|`` with ``g = Z⁺ᵀ Q`` the generalized force per coordinate
      (``g = Q`` where ``q̇ = v``): the change of ``E`` when every coordinate is off by the
      relative error ``rtol · |q_j|`` the error control allows.  Without that term a run far from
      the coordinates' origin (a pendulum of small amplitude 1 m below its pivot: ``E_scale`` is
      small, the error allowed in ``y`` is ``rtol · 1 m``) was warned about while it met its
      tolerance (bdf, 0.01 rad, rtol 1e-11: drift 1.3e-10 J = m g · 1.3 · rtol · 1 m, "12.8 ×").
    * **Constraints**: the exact motion has ``Φ = 0``; an output with
      ``‖Φ‖∞ > VIOLATION_WARN_FACTOR · (atol + rtol · max(1, max|q|))`` (rows in m or rad, plus
      the unit-norm invariant of Euler parameters) drifted off the constraint manifold.
    """
    out: list[str] = []
    n_t = len(t)
    if energy is not None and getattr(system, "is_conservative", False) and n_t >= 2 and np.all(np.isfinite(energy)):
        momenta = [np.asarray(system.M(t[i], Q[i]) @ V[i], float) for i in range(n_t)]
        kinetic = np.array([0.5 * float(V[i] @ momenta[i]) for i in range(n_t)])
        forces = [np.asarray(system.Q(t[i], Q[i], V[i]), float) for i in range(n_t)]
        p_scale = max(float(np.sum(np.abs(momenta[i]))) + float(np.sum(np.abs(forces[i]))) for i in range(n_t))
        scale = float(np.max(kinetic)) if np.max(kinetic) > 0 else abs(float(energy[0]))
        drift = np.abs(energy - energy[0])
        k = int(np.argmax(drift))
        # qQ_scale >= 0 only widens the allowance: its pseudo-inverses per output are needed only
        # when the drift exceeds the allowance without it
        allowed = rtol * scale + atol * p_scale
        if drift[k] > ENERGY_WARN_FACTOR * allowed or allowed <= 0:
            qQ_scale = max(float(np.sum(np.abs(_force_per_coordinate(system, Q[i], forces[i]) * Q[i])))
                           for i in range(n_t))
            allowed = rtol * (scale + qQ_scale) + atol * p_scale
        if allowed > 0 and drift[k] > ENERGY_WARN_FACTOR * allowed:
            out.append(f"energy drift |E − E0| = {drift[k]:.3g} J at t = {t[k]:.6g} s is {drift[k] / allowed:.3g} × "
                       f"what the tolerances allow, rtol × ({scale:.3g} J (peak kinetic energy) + {qQ_scale:.3g} J "
                       f"(Σ|Q_j q_j|)) + atol × {p_scale:.3g} (|M v| + |Q|), for this conservative system (limit "
                       f"{ENERGY_WARN_FACTOR:g} ×); tighten the tolerance or the step")
    if n_t and len(position_violation):
        q_scale = max(1.0, float(np.max(np.abs(Q)))) if Q.size else 1.0
        limit = VIOLATION_WARN_FACTOR * (atol + rtol * q_scale)
        k = int(np.argmax(position_violation))
        if position_violation[k] > limit:
            out.append(f"position constraints violated by {position_violation[k]:.3g} at t = {t[k]:.6g} s (limit "
                       f"{limit:.3g} = {VIOLATION_WARN_FACTOR:g} × (atol + rtol · {q_scale:.3g})); use a stabilised "
                       "formulation (-projection, -baumgarte) or a tighter tolerance")
    return out


def simulate(system: ConstrainedSystem, t_span, method: str | type[Integrator] = "rk45-projection", *,
             t_eval=None, n_output: int = 201, q0=None, v0=None, rtol: float = 1e-6, atol: float = 1e-8,
             h: float | None = None, max_step: float = np.inf, progress: bool | None = False,
             compute_multipliers: bool = True, assemble: bool = False, record_steps: bool = False,
             stop_when=None, **options):
    """Integrate ``system`` over ``t_span`` and return a :class:`core.results.SimulationResult`.

    Output is sampled at ``t_eval`` (default ``n_output`` equally spaced times) from each step's
    dense output.  Multipliers at output times come from the method when it provides consistent
    ones, else from the index-1 KKT solve at the output state.  Position and velocity constraint
    violations (max-abs over rows, plus coordinate invariants such as ``|p|−1``) and, for
    conservative systems, the energy are recorded at every output time.

    A run that fails (NaN, divergence, unmet tolerance, exception) returns with
    ``status == "failed"``, the message saying where, all output computed up to that point and, as
    its last row, the last good state at the time where the run stopped.

    Initial states given as ``q0``/``v0`` get the consistency check of ``build()``: a violated
    constraint raises :class:`core.errors.ModelError` naming it; with ``assemble=True`` they are
    first made consistent by :func:`core.assembly.assemble_state` (Gauss–Newton on the positions,
    mass-weighted projection of the velocities).  ``n_output`` must be at least 1 (with one
    output time, the end state only).

    ``record_steps=True`` also keeps the state at every accepted step in ``result.steps``
    (:class:`core.results.AcceptedSteps`): the dense record from which peaks, threshold
    crossings and durations are taken so that they do not depend on the output grid
    (:mod:`core.signals`).  The step sequence is the one the run takes anyway: methods that land
    on the output times (``steps_to_output``) still land on them, one step per call.

    ``stop_when(t, q, v) -> bool`` is called at every output time; the run ends there when it
    returns True, with status ``finished``, the outputs up to that time and the message "stopped
    by stop_when at t = ...": a run that has shown what it was run for (a decayed oscillation, a
    vehicle at rest) need not integrate to ``t_end``.  The callable may keep a history of its own.
    """
    cls = get_method(method)
    t0, t_end = map(float, t_span)
    if t_eval is None:
        if isinstance(n_output, bool) or not isinstance(n_output, (int, np.integer)) or n_output < 1:
            raise InputError(f"simulate: n_output must be an integer >= 1 (the number of equally spaced output "
                             f"times, t0 and t_end included), got {n_output!r}")
        t_eval = np.linspace(t0, t_end, n_output) if n_output > 1 else np.array([t_end])
    t_eval = np.asarray(t_eval, float)
    if np.any(np.diff(t_eval) <= 0) or t_eval[0] < t0 - 1e-14 or t_eval[-1] > t_end + 1e-12:
        raise InputError(f"t_eval must be strictly increasing within t_span {t_span}")
    if assemble and (q0 is not None or v0 is not None) and isinstance(system, ConstrainedSystem):
        from .assembly import assemble_state

        q0, v0 = assemble_state(system, q0, v0, t=t0)
    integ = cls(system, (t0, t_end), q0, v0, rtol=rtol, atol=atol, h=h, max_step=max_step, **options)
    ts, qs, vs, lams = [], [], [], []
    rec_t, rec_q, rec_v = ([float(integ.t)], [integ.q.copy()], [integ.v.copy()]) if record_steps else ([], [], [])
    # compiled integrators: the force kinds' search states after every accepted step, too
    record_states = record_steps and getattr(integ, "_states", None) is not None and integ._states.size > 0
    rec_states = [integ._states.copy()] if record_states else []
    k = 0
    wall0 = _time.perf_counter()
    solve_time = 0.0
    bar = None
    if progress is not False:
        from tqdm.auto import tqdm

        bar = tqdm(total=t_end - t0, disable=None if progress is None else not progress, unit="s", desc=system.name)
    # output at t0
    while k < len(t_eval) and t_eval[k] <= t0 + 1e-15:
        ts.append(t0)
        qs.append(integ.q.copy())
        vs.append(integ.v.copy())
        lams.append(None)
        k += 1
    while integ.status == STATUS_RUNNING:
        s0 = _time.perf_counter()
        if integ.steps_to_output:
            if record_steps:
                integ.advance(t_eval[k] if k < len(t_eval) else t_end, max_steps=1)
            else:
                integ.advance(t_eval[k] if k < len(t_eval) else t_end)
        else:
            integ.step()
        solve_time += _time.perf_counter() - s0
        if record_steps and integ.t > rec_t[-1]:
            rec_t.append(float(integ.t))
            rec_q.append(integ.q.copy())
            rec_v.append(integ.v.copy())
            if record_states:
                rec_states.append(integ._states.copy())
        if integ.status == STATUS_FAILED:
            break
        if bar is not None:
            bar.update(integ.t - integ.t_old)
        if k < len(t_eval) and t_eval[k] <= integ.t + 1e-12 * max(1.0, abs(integ.t)):
            try:
                dense = integ.dense_output()
            except RUN_FAILURES as exc:
                integ.status = STATUS_FAILED
                integ.message = (f"{integ.name} failed at t = {integ.t:.6g} s: dense output could not be "
                                 f"built ({type(exc).__name__}: {exc})")
                break
            while k < len(t_eval) and t_eval[k] <= integ.t + 1e-12 * max(1.0, abs(integ.t)):
                tk = t_eval[k]
                if abs(tk - integ.t) <= 1e-12 * max(1.0, abs(integ.t)):
                    q, v = integ.q.copy(), integ.v.copy()
                    lam = None if integ.lam is None else np.array(integ.lam)
                else:
                    try:
                        q, v = dense(tk)
                    except RUN_FAILURES as exc:
                        integ.status = STATUS_FAILED
                        integ.message = (f"{integ.name} failed at t = {tk:.6g} s: dense output could not be "
                                         f"evaluated ({type(exc).__name__}: {exc})")
                        break
                    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                        integ.status = STATUS_FAILED
                        integ.message = f"{integ.name} failed at t = {tk:.6g} s: dense output is not finite"
                        break
                    lam = None
                ts.append(tk)
                qs.append(q)
                vs.append(v)
                lams.append(lam)
                k += 1
                if stop_when is not None and stop_when(tk, q, v):
                    integ.status = STATUS_FINISHED
                    integ.message = f"stopped by stop_when at t = {tk:.6g} s"
                    break
            if integ.status != STATUS_RUNNING:
                break
    if bar is not None:
        bar.close()
    if integ.status == STATUS_FAILED and (not ts or integ.t > ts[-1]):
        # keep what was computed: the last good state, where the run stopped (not a requested time)
        ts.append(float(integ.t))
        qs.append(integ.q.copy())
        vs.append(integ.v.copy())
        lams.append(None)
    wall = _time.perf_counter() - wall0
    ts = np.array(ts)
    n_t = len(ts)
    Q = np.array(qs).reshape(n_t, system.n_q)
    V = np.array(vs).reshape(n_t, system.n_v)
    pos_viol = np.zeros(n_t)
    vel_viol = np.zeros(n_t)
    inv_viol = np.zeros(n_t)
    energy = np.full(n_t, np.nan) if system.energy(t0, system.q0, system.v0) is not None else None
    L = np.full((n_t, system.n_c), np.nan) if compute_multipliers else None
    reactions: dict[str, list] = {}
    for i in range(n_t):
        t, q, v = ts[i], Q[i], V[i]
        if system.n_c:
            pos_viol[i] = np.max(np.abs(system.Phi(t, q)))
            vel_viol[i] = np.max(np.abs(system.velocity_violation(t, q, v)))
        inv_viol[i] = system.invariant_violation(q)
        if energy is not None:
            energy[i] = system.energy(t, q, v)
        if compute_multipliers and system.n_c:
            lam = lams[i]
            if lam is None or not (integ.provides_multipliers and len(lam) == system.n_c):
                try:
                    lam = integ.multipliers(t, q, v)
                except RUN_FAILURES:
                    lam = np.full(system.n_c, np.nan)
            L[i] = lam
            for name, val in system.reactions(t, q, lam).items():
                reactions.setdefault(name, []).append(val)
    reactions_arr = {n: np.array(v) for n, v in reactions.items() if len(v) == n_t}
    if integ.status in FINISHED_STATUSES:
        for text in result_checks(system, ts, Q, V, energy, np.maximum(pos_viol, inv_viol), rtol, atol):
            integ.add_warning(text)
    meta = run_metadata(
        method=cls.name,
        system=system.name,
        rtol=rtol,
        atol=atol,
        h=h,
        wall_time_s=solve_time,
        total_time_s=wall,
        t_end_reached=float(integ.t),
        max_invariant_violation=float(inv_viol.max()) if n_t else 0.0,
    )
    return SimulationResult(
        t=ts,
        q=Q,
        v=V,
        lam=L,
        status=integ.status,
        message=integ.message or "",
        warnings=tuple(integ.warnings),
        counters=dict(integ.counters),
        meta=meta,
        coordinate_names=list(system.coordinate_names),
        velocity_names=list(system.velocity_names),
        constraint_names=list(system.constraint_names),
        position_violation=np.maximum(pos_viol, inv_viol),
        velocity_violation=vel_viol,
        energy=energy,
        reactions=reactions_arr,
        reaction_names={n: system.reaction_names().get(n, []) for n in reactions_arr},
        steps=AcceptedSteps(np.array(rec_t), np.array(rec_q).reshape(len(rec_t), system.n_q),
                            np.array(rec_v).reshape(len(rec_t), system.n_v)) if record_steps else None,
        step_search_states=_search_state_blocks(integ, rec_states),
    )


def _search_state_blocks(integ, rec_states: list) -> dict | None:
    """The recorded flat search states split by force kind: (n_steps + 1, n_elements, width) each."""
    if not rec_states:
        return None
    return integ._cm.state_blocks(np.array(rec_states)) or None
