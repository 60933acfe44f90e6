r"""Kinematic assembly: consistent positions and velocities near a guess.

Equations (Haug 1989, Sec. 3.5; Nikravesh 1988, Sec. 3.4)
----------------------------------------------------------
Positions: Gauss–Newton with minimum-norm increments in velocity space, applied with the
retraction,

.. math::

    \Delta v_k = -\Phi_q(t, q_k)^{+}\, \Phi(t, q_k), \qquad q_{k+1} = q_k \oplus \alpha_k \Delta v_k,

(``⁺`` the truncated Moore–Penrose pseudo-inverse, so redundant rows are harmless; ``α_k``
halves until ``‖Φ‖₂`` decreases).  Velocities: the correction of least kinetic-energy norm

.. math::

    \min_{\Delta v} \tfrac12 \Delta v^T M \Delta v \quad\text{s.t.}\quad \Phi_q (v_0 + \Delta v) = \nu

(:func:`core.dynamics.project_velocities`).  ``ModelBuilder.build(assemble=True)`` and the
analyses of :mod:`core.analysis` use this module; it imports neither of them.

References
----------
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn & Bacon, 1989.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .dynamics import project_velocities
from .errors import AssemblyError, InputError, ModelError
from .system import ConstrainedSystem, as_dense

Array = NDArray[np.float64]

__all__ = ["assemble_state", "assemble", "check_initial_state", "newton_positions", "truncated_svd",
           "coordinate_scale"]


def coordinate_scale(q: Array) -> float:
    """``max(1, max|q|)``: the scale of absolute tolerances on positions."""
    return max(1.0, float(np.max(np.abs(q)))) if len(q) else 1.0


def check_initial_state(system: ConstrainedSystem, t: float, q: Array, v: Array, tol: float = 1e-9,
                        owner: str = "", remedy: str = "") -> None:
    """Raise :class:`core.errors.ModelError` when ``(q, v)`` violates the constraints at time ``t``.

    Positions: ``|Φ_i(t, q)| ≤ tol·max(1, max|q|)`` for every row; velocities:
    ``|(Φ_q v − ν)_i| ≤ tol·max(1, max|v|)``.  The message names the worst row by its constraint
    name, its residual, the number of rows over the tolerance, ``owner`` (who supplied the state)
    and ``remedy`` (what to do about it).  Non-finite constraint values are reported too.
    """
    if system.n_c == 0:
        return
    who = f"{owner}: " if owner else ""
    names = list(getattr(system, "constraint_names", [])) or [f"row {i}" for i in range(system.n_c)]
    phi = np.asarray(system.Phi(t, q), float)
    if not np.all(np.isfinite(phi)):
        k = int(np.flatnonzero(~np.isfinite(phi))[0])
        raise ModelError(f"{who}constraint {names[k]!r} is not finite at the initial configuration")
    bad = np.flatnonzero(np.abs(phi) > tol * coordinate_scale(q))
    if len(bad):
        worst = bad[np.argmax(np.abs(phi[bad]))]
        raise ModelError(f"{who}inconsistent initial positions; constraint {names[worst]!r} is violated by "
                         f"{phi[worst]:.3e} ({len(bad)} rows over tolerance {tol:g}). {remedy}".rstrip())
    vv = np.asarray(system.velocity_violation(t, q, v), float)
    bad = np.flatnonzero(~(np.abs(vv) <= tol * coordinate_scale(v)))
    if len(bad):
        worst = bad[np.argmax(np.nan_to_num(np.abs(vv[bad]), nan=np.inf))]
        raise ModelError(f"{who}inconsistent initial velocities; constraint {names[worst]!r} has velocity "
                         f"residual {vv[worst]:.3e} ({len(bad)} rows over tolerance {tol:g}). {remedy}".rstrip())


def truncated_svd(J, rank_tol: float = 1e-6, max_rank: int | None = None):
    """``(U_r, s_r, V_r, N)`` of dense ``J`` keeping singular values ``> rank_tol·s_max`` (and at most
    ``max_rank``); ``N`` spans the remaining right singular directions (the numerical null space).

    Newton iterations use the truncated pseudo-inverse: near a configuration where rows are
    redundant, the "redundant" singular value is only O(‖Φ‖) and keeping it makes Newton converge
    linearly towards the singular root (ratio ½); truncating it restores quadratic convergence.
    """
    Jd = as_dense(J)
    n_v = Jd.shape[1]
    if Jd.shape[0] == 0:
        return np.zeros((0, 0)), np.zeros(0), np.zeros((n_v, 0)), np.eye(n_v)
    U, s, Vt = np.linalg.svd(Jd, full_matrices=True)
    r = int(np.sum(s > rank_tol * s[0])) if len(s) and s[0] > 0 else 0
    if max_rank is not None:
        r = min(r, max_rank)
    return U[:, :r], s[:r], Vt[:r].T, Vt[r:].T


def newton_positions(system, t, q, tol, max_iter):
    """Gauss–Newton on ``Φ(t, q) = 0`` (module docstring); returns ``(q, converged, iterations, Φ)``."""
    q = system.normalize(np.asarray(q, float).copy())
    scale = coordinate_scale(q)
    phi = np.asarray(system.Phi(t, q), float)
    if not np.all(np.isfinite(phi)):
        return q, False, 0, phi
    it = 0
    for it in range(1, max_iter + 1):
        if np.max(np.abs(phi), initial=0.0) <= tol * scale:
            return q, True, it - 1, phi
        U, sv, V, _ = truncated_svd(system.Phi_q(t, q))
        dv = -V @ ((U.T @ phi) / sv)
        f0 = float(phi @ phi)
        alpha = 1.0
        while True:
            q_new = system.retract(q, alpha * dv)
            phi_new = np.asarray(system.Phi(t, q_new), float)
            f1 = float(phi_new @ phi_new) if np.all(np.isfinite(phi_new)) else np.inf
            if f1 <= (1.0 - 1e-4 * alpha) * f0 or alpha < 1.0 / 64:
                break
            alpha *= 0.5
        if not np.isfinite(f1):
            return q, False, it, phi
        if alpha < 1.0 / 64 and f1 >= f0:  # stalled at a stationary point of ‖Φ‖²
            return q_new, False, it, phi_new
        q, phi = q_new, phi_new
    return q, bool(np.max(np.abs(phi), initial=0.0) <= tol * scale), it, phi


def assemble_state(system: ConstrainedSystem, q_guess: ArrayLike | None = None, v_guess: ArrayLike | None = None,
                   t: float = 0.0, tol: float = 1e-10, max_iter: int = 50,
                   velocity_weighting: str = "mass") -> tuple[Array, Array]:
    r"""Consistent positions and velocities near a guess (kinematic assembly).

    Positions: Gauss–Newton ``Δv = −Φ_q⁺ Φ`` (minimum-norm increments in velocity space, applied with
    ``system.retract``; backtracking on ``‖Φ‖₂``).  Velocities: the correction of least norm
    ``½ΔvᵀWΔv`` with ``Φ_q(v + Δv) = ν``, ``W = M`` (kinetic-energy norm, default) or ``W = I``.
    Redundant rows are handled by the pseudo-inverse.

    Parameters
    ----------
    system : ConstrainedSystem
    q_guess : array_like, shape (n_q,), optional
        Rough configuration; default ``system.q0``.
    v_guess : array_like, shape (n_v,), optional
        Default ``system.v0``.
    t : float
        Time [s] (driving constraints).
    tol : float
        Convergence when ``max|Φ| ≤ tol·max(1, max|q|)`` [m or rad].
    max_iter : int
    velocity_weighting : {'mass', 'identity'}

    Returns
    -------
    q : ndarray, shape (n_q,)
    v : ndarray, shape (n_v,)

    Raises
    ------
    core.errors.AssemblyError
        Newton did not converge; the message names the worst violated constraint.
    """
    if velocity_weighting not in ("mass", "identity"):
        raise InputError(f"velocity_weighting must be 'mass' or 'identity', got {velocity_weighting!r}")
    q0 = np.asarray(system.q0 if q_guess is None else q_guess, float)
    v0 = np.asarray(system.v0 if v_guess is None else v_guess, float)
    if q0.shape != (system.n_q,):
        raise InputError(f"{system.name}: q_guess has shape {q0.shape}, expected ({system.n_q},)")
    if v0.shape != (system.n_v,):
        raise InputError(f"{system.name}: v_guess has shape {v0.shape}, expected ({system.n_v},)")
    if system.n_c == 0:
        return system.normalize(q0.copy()), v0.copy()
    q, ok, it, phi = newton_positions(system, t, q0, tol, max_iter)
    if not ok:
        names = list(getattr(system, "constraint_names", []) or [f"Phi[{i}]" for i in range(system.n_c)])
        if np.all(np.isfinite(phi)):
            k = int(np.argmax(np.abs(phi)))
            what = f"constraint {names[k]!r} is still violated by {phi[k]:.3e}"
        else:
            k = int(np.flatnonzero(~np.isfinite(phi))[0])
            what = f"constraint {names[k]!r} is not finite"
        raise AssemblyError(
            f"{system.name}: assembly at t = {t:g} s did not converge after {it} Newton iterations; {what} "
            f"(tolerance {tol:g}). Improve the initial guess or check the joint definitions."
        )
    v = project_velocities(system, t, q, v0, velocity_weighting)
    return q, v


def assemble(model, q_guess: ArrayLike | None = None, v_guess: ArrayLike | None = None, t: float = 0.0,
             tol: float = 1e-10, max_iter: int = 50, velocity_weighting: str = "mass"):
    """Return ``model.with_state(q, v)`` with ``(q, v)`` from :func:`assemble_state`.

    Used by ``ModelBuilder.build(assemble=True)``.  For systems without ``with_state`` call
    :func:`assemble_state`, which returns the arrays.
    """
    if not hasattr(model, "with_state"):
        raise InputError(f"{type(model).__name__} has no with_state(); use assemble_state(system, ...) -> (q, v)")
    q, v = assemble_state(model, q_guess, v_guess, t=t, tol=tol, max_iter=max_iter, velocity_weighting=velocity_weighting)
    return model.with_state(q, v)
