r"""Analyses of a constrained mechanical system: assembly, kinematics, statics, inverse dynamics,
linearisation and eigenanalysis.

Every function works on the :class:`core.system.ConstrainedSystem` protocol (``M, Q, Φ, Φ_q, ν, γ``
and the retraction ``q ⊕ Δv``), so it runs on the Cartesian :class:`core.model.Model` and on models
written in generalized coordinates alike.  Tables are pandas DataFrames with SI units in the column
names.

Equations
---------
*Assembly* (kinematic analysis at one instant): :mod:`core.assembly` (``assemble_state`` and
``assemble`` are re-exported here).

*Kinematic analysis* of a fully driven mechanism (``n_v = rank Φ_q``): at each time
``Φ(t, q) = 0``, ``Φ_q v = ν``, ``Φ_q a = γ(t, q, v)`` (Haug 1989, Eqs. 3.5.1–3.5.3).

*Static equilibrium*: ``Q(t, q, 0) − Φ_qᵀλ = 0``, ``Φ(t, q) = 0`` by Newton's method on ``(Δv, λ)``
(solved by the null-space method; λ re-eliminated by least squares at each iterate):

.. math::

    \begin{bmatrix} K_T & \Phi_q^T \\ \Phi_q & 0 \end{bmatrix}
    \begin{bmatrix} \Delta v \\ \Delta\lambda \end{bmatrix} =
    \begin{bmatrix} Q - \Phi_q^T \lambda \\ -\Phi \end{bmatrix},\qquad
    K_T = -Q_q + \frac{\partial (\Phi_q^T \lambda)}{\partial q}

globalised either by descent of the potential on the constraint manifold (conservative systems;
finds a stable equilibrium) or by backtracking on the residual norm.

*Inverse dynamics*: for a given motion ``(q, v, a)``, ``Φ_qᵀλ = Q − M a`` solved in the least-squares
sense (minimum-norm ``λ`` when rows are redundant); the residual ``‖Φ_qᵀλ − (Q − M a)‖`` is zero
exactly when the motion is dynamically consistent with the model.

*Linearisation* about ``(q₀, v₀)`` with ``λ₀, a₀`` from the index-1 equations: perturbations
``δv = N x`` in the null space of ``Φ_q`` (orthonormal basis ``N`` from the SVD) give

.. math::

    M_r \ddot x + (D_r + G_r) \dot x + K_r x = 0,\quad
    M_r = N^T M N,\quad D_r + G_r = -N^T Q_v N,\quad
    K_r = N^T\Big(-Q_q + \frac{\partial(\Phi_q^T\lambda_0)}{\partial q}
                 + \frac{\partial (M a_0)}{\partial q}\Big) N

(Géradin & Cardona 2001, Sec. 11.4; Negrut & Ortiz 2006, Eqs. 10–17).  ``D_r`` and ``G_r`` are the
symmetric and skew-symmetric parts.  The constraint ("geometric") stiffness term
``∂(Φ_qᵀλ₀)/∂q`` is evaluated by central differences of ``Φ_q(q ⊕ δ)ᵀλ₀``; it is the *only*
stiffness of a pendulum hanging in gravity.  ``N`` is frozen at ``q₀``: exact at equilibrium
(``v₀ = 0``), a first-order tangent-space approximation for steady motions.

References
----------
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn & Bacon, 1989.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
M. Géradin, A. Cardona, *Flexible Multibody Dynamics: A Finite Element Approach*, Wiley, 2001, ch. 11.
D. Negrut, J. L. Ortiz, "A practical approach for the linearization of the constrained multibody
dynamics equations", J. Comput. Nonlinear Dynam. 1 (2006) 230–239.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import scipy.linalg as sla
from numpy.typing import ArrayLike, NDArray

from .assembly import assemble, assemble_state, coordinate_scale, newton_positions, truncated_svd
from .dynamics import accelerations, minimum_norm_correction, minimum_norm_multipliers
from .errors import AssemblyError, InputError
from .system import ConstrainedSystem, as_dense

Array = NDArray[np.float64]

__all__ = [
    "AnalysisWarning",
    "assemble_state",
    "assemble",
    "kinematic_analysis",
    "StaticEquilibrium",
    "static_equilibrium",
    "inverse_dynamics",
    "inverse_dynamics_from_result",
    "inverse_dynamics_from_kinematics",
    "LinearizedSystem",
    "linearize",
    "eigen",
    "null_space_basis",
]


EQUILIBRIUM_TOL = 1e-6  # eigen(): relative unbalanced force above which the state is not an equilibrium


class AnalysisWarning(UserWarning):
    """An analysis stopped early; the partial result carries ``attrs['status'] == 'failed'``."""


# ------------------------------------------------------------------------------------------------
# linear algebra helpers
# ------------------------------------------------------------------------------------------------


def _rank(J, tol: float = 1e-9) -> int:
    Jd = as_dense(J)
    if Jd.size == 0:
        return 0
    s = np.linalg.svd(Jd, compute_uv=False)
    return int(np.sum(s > tol * max(1.0, s[0]) * max(Jd.shape)))


def null_space_basis(J, tol: float = 1e-9) -> Array:
    """Orthonormal basis ``N`` (n_v, n_v − rank) of the null space of ``J`` from its SVD.

    Rows that are linearly dependent (redundant constraints) do not reduce the dimension.
    """
    Jd = as_dense(J)
    n_v = Jd.shape[1]
    if Jd.shape[0] == 0:
        return np.eye(n_v)
    _, s, Vt = np.linalg.svd(Jd, full_matrices=True)
    rank = int(np.sum(s > tol * max(1.0, s[0] if len(s) else 0.0) * max(Jd.shape)))
    return Vt[rank:].T.copy()


def _q_jacobians(system: ConstrainedSystem, t: float, q: Array, v: Array) -> tuple[Array, Array]:
    Qq, Qv = system.Q_jacobians(t, q, v)
    return as_dense(Qq), as_dense(Qv)


def _geometric_stiffness(system: ConstrainedSystem, t: float, q: Array, lam: Array, h: float | None = None) -> Array:
    r"""``∂(Φ_q(q ⊕ δ)ᵀλ)/∂δ`` at δ = 0 by central differences, shape (n_v, n_v).

    Step ``h = 1e-6·max(1, max|q|)``: truncation error O(h²), round-off O(ε/h).
    """
    n_v = system.n_v
    G = np.zeros((n_v, n_v))
    if system.n_c == 0 or not np.any(lam):
        return G
    h = 1e-6 * coordinate_scale(q) if h is None else h
    for k in range(n_v):
        dv = np.zeros(n_v)
        dv[k] = h
        Jp = system.Phi_q(t, system.retract(q, dv))
        Jm = system.Phi_q(t, system.retract(q, -dv))
        G[:, k] = (np.asarray(Jp.T @ lam).ravel() - np.asarray(Jm.T @ lam).ravel()) / (2.0 * h)
    return G


def _mass_gradient(system: ConstrainedSystem, t: float, q: Array, a: Array, h: float | None = None) -> Array:
    """``∂(M(q ⊕ δ) a)/∂δ`` (zero when the mass matrix is constant)."""
    n_v = system.n_v
    if getattr(system, "mass_is_constant", False) or not np.any(a):
        return np.zeros((n_v, n_v))
    h = 1e-6 * coordinate_scale(q) if h is None else h
    G = np.zeros((n_v, n_v))
    for k in range(n_v):
        dv = np.zeros(n_v)
        dv[k] = h
        G[:, k] = (np.asarray(system.M(t, system.retract(q, dv)) @ a).ravel()
                   - np.asarray(system.M(t, system.retract(q, -dv)) @ a).ravel()) / (2.0 * h)
    return G


def _acceleration_name(name: str) -> str:
    """``"crank.vx [m/s]" → "d(crank.vx)/dt [m/s^2]"``; names without a unit get ``d(.)/dt``."""
    if name.endswith("]") and " [" in name:
        base, unit = name[:-1].rsplit(" [", 1)
        unit = unit[:-2] + "/s^2" if unit.endswith("/s") else unit + "/s"
        return f"d({base})/dt [{unit}]"
    return f"d({name})/dt"


def _names(system: ConstrainedSystem) -> tuple[list[str], list[str], list[str]]:
    qn = list(getattr(system, "coordinate_names", None) or [f"q[{i}]" for i in range(system.n_q)])
    vn = list(getattr(system, "velocity_names", None) or [f"v[{i}]" for i in range(system.n_v)])
    if set(qn) & set(vn):  # generalized-coordinate systems may reuse names: disambiguate
        vn = [f"d({n})/dt" if n in qn else n for n in vn]
    an = [_acceleration_name(n) for n in vn]
    return qn, vn, an


# ------------------------------------------------------------------------------------------------
# 1. assembly
# ------------------------------------------------------------------------------------------------


# ------------------------------------------------------------------------------------------------
# 2. kinematic analysis
# ------------------------------------------------------------------------------------------------


def kinematic_analysis(system: ConstrainedSystem, times: ArrayLike, q_guess: ArrayLike | None = None,
                       tol: float = 1e-10, max_iter: int = 50) -> pd.DataFrame:
    r"""Positions, velocities and accelerations of a fully driven mechanism (zero degrees of freedom).

    At each time: ``Φ(t, q) = 0`` by Gauss–Newton warm-started from the previous solution advanced
    by a second-order Taylor predictor ``q ⊕ (v Δt + ½ a Δt²)``; then ``Φ_q v = ν`` and
    ``Φ_q a = γ(t, q, v)`` (Haug 1989, Eqs. 3.5.1–3.5.3), least squares/minimum norm so redundant
    rows are accepted.

    Parameters
    ----------
    system : ConstrainedSystem
        ``n_v − rank Φ_q`` must be 0 at the first time.
    times : array_like, shape (n_t,)
        Strictly increasing output times [s].
    q_guess : array_like, shape (n_q,) or (n_t, n_q), optional
        Guess at ``times[0]``; default ``system.q0``.  A guess *per frame* (a measured motion's
        forward kinematics, say) makes the frames independent: they are then solved all at once
        (below).
    tol, max_iter :
        As :func:`assemble_state`.

    Notes
    -----
    *All frames at once.*  With a guess per frame and a system that offers
    ``constraint_terms_frames`` (:class:`core.model.Model`), every frame runs the same Newton
    iteration ``Δq = −Φ_q⁻¹Φ`` side by side (one batched LU solve of the square Φ_q per
    iteration, until ``max|Φ| ≤ tol·max(1, max|q|)`` in every frame), then ``v = Φ_q⁻¹ν`` and
    ``a = Φ_q⁻¹γ``: the same equations and tolerance as the frame-by-frame path.  When a frame
    does not converge within ``max_iter``, or Φ_q is not square or not regular in some frame
    (condition test of ``_frames_inverse``), the whole analysis runs frame by frame instead
    (:func:`assemble_state`, with backtracking and least squares).

    Returns
    -------
    DataFrame
        Columns ``"t [s]"``, the coordinate names, the velocity names and the acceleration names
        (``d(<velocity>)/dt [<unit>/s]``).  ``attrs['status']`` is ``'finished'`` or ``'failed'``;
        on failure the rows computed so far are returned, ``attrs['message']`` names the time and
        the constraint that did not converge, and an :class:`AnalysisWarning` is issued.

    Raises
    ------
    ValueError
        If the system has degrees of freedom left (the message gives their number).
    """
    times = np.asarray(times, float).ravel()
    if len(times) == 0 or np.any(np.diff(times) <= 0):
        raise InputError("kinematic_analysis: times must be a non-empty, strictly increasing array")
    qn, vn, an = _names(system)
    q = np.asarray(system.q0 if q_guess is None else q_guess, float)
    if q.ndim == 2:
        if q.shape != (len(times), system.n_q):
            raise InputError(f"kinematic_analysis: q_guess has shape {q.shape}, expected ({system.n_q},) or "
                             f"({len(times)}, {system.n_q}) (one guess per time)")
        if hasattr(system, "constraint_terms_frames"):
            out = _kinematic_frames(system, times, q, tol, max_iter)
            if out is not None:
                df = pd.DataFrame(np.column_stack([times, *out]), columns=["t [s]", *qn, *vn, *an])
                df.attrs.update(status="finished", message="", analysis="kinematic", system=system.name)
                return df
        guesses = q
        q = guesses[0]
    else:
        guesses = None
    rows: list[np.ndarray] = []
    status, message = "finished", ""
    v = a = None
    for i, t in enumerate(times):
        if guesses is not None:
            q = guesses[i]
        elif i > 0:
            dt = t - times[i - 1]
            q = system.retract(q, v * dt + 0.5 * a * dt * dt)
        try:
            q, v = assemble_state(system, q, np.zeros(system.n_v), t=t, tol=tol, max_iter=max_iter,
                                  velocity_weighting="identity")
        except AssemblyError as exc:
            status, message = "failed", f"kinematic analysis stopped at t = {t:g} s: {exc}"
            break
        J = system.Phi_q(t, q)
        if i == 0:
            dof = system.n_v - _rank(J)
            if dof != 0:
                raise InputError(
                    f"{system.name}: kinematic_analysis needs a fully driven system, but {dof} degree(s) of "
                    f"freedom remain (n_v = {system.n_v}, rank Φ_q = {system.n_v - dof}); add drivers"
                )
        a = minimum_norm_correction(J, np.asarray(system.gamma(t, q, v), float))
        rows.append(np.concatenate([[t], q, v, a]))
    df = pd.DataFrame(np.array(rows).reshape(len(rows), 1 + system.n_q + 2 * system.n_v),
                      columns=["t [s]", *qn, *vn, *an])
    df.attrs.update(status=status, message=message, analysis="kinematic", system=system.name)
    if status == "failed":
        warnings.warn(message, AnalysisWarning, stacklevel=2)
    return df


def _frames_solve(J: Array, b: Array) -> Array | None:
    """``x`` with ``J x = b`` frame by frame (J (n_f, n, n), b (n_f, n)) by one batched LU solve;
    None when J is not square or a frame's J is singular or the result is not finite."""
    if J.shape[1] != J.shape[2]:
        return None
    try:
        x = np.linalg.solve(J, b[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return None
    return x if np.all(np.isfinite(x)) else None


def _frames_inverse(J: Array) -> Array | None:
    """``J⁻¹`` of every frame (J (n_f, n, n)) when each is regular in the sense of the
    frame-by-frame least squares, else None.

    Regular means ``κ₁(J) = ‖J‖₁‖J⁻¹‖₁ ≤ 1/(n·RANK_RCOND)``: since ``κ₂ ≤ n·κ₁`` (Golub & Van
    Loan 2013, Sec. 2.3.2, the norm equivalences), every singular value is then above
    ``RANK_RCOND·σ_max``, no singular value would be truncated by the least squares
    (:func:`core.dynamics.minimum_norm_multipliers`), and its minimum-norm solution is ``J⁻¹b``.
    """
    from .dynamics import RANK_RCOND

    n = J.shape[1]
    if J.shape[2] != n or n == 0:
        return None
    try:
        Ji = np.linalg.inv(J)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(Ji)):
        return None
    kappa = np.abs(J).sum(axis=1).max(axis=1) * np.abs(Ji).sum(axis=1).max(axis=1)
    return Ji if np.all(kappa <= 1.0 / (n * RANK_RCOND)) else None


def _kinematic_frames(system, times, q, tol, max_iter):
    """Positions, velocities and accelerations of all frames at once (:func:`kinematic_analysis`,
    Notes); None to fall back to the frame-by-frame path."""
    n_f = len(times)
    q = np.array([system.normalize(qi.copy()) for qi in q]) if system.space.dim == 3 else q.copy()
    if system.n_c != system.n_v:
        return None
    scale = np.maximum(1.0, np.max(np.abs(q), axis=1))
    done = False
    for _ in range(max_iter + 1):
        phi, J, _, _ = system.constraint_terms_frames(times, q)
        if not np.all(np.isfinite(phi)):
            return None
        if np.all(np.max(np.abs(phi), axis=1) <= tol * scale):
            done = True
            break
        dv = _frames_solve(J, -phi)
        if dv is None:
            return None
        q = np.array([system.retract(q[i], dv[i]) for i in range(n_f)]) if system.space.dim == 3 else q + dv
        scale = np.maximum(1.0, np.max(np.abs(q), axis=1))
    if not done:
        return None
    _, J, nu, _ = system.constraint_terms_frames(times, q)
    Ji = _frames_inverse(J)  # None also for free degrees of freedom: the frame-by-frame path names them
    if Ji is None:
        return None
    v = np.einsum("fij,fj->fi", Ji, nu)
    ga = system.constraint_terms_frames(times, q, v)[3]
    return q, v, np.einsum("fij,fj->fi", Ji, ga)


# ------------------------------------------------------------------------------------------------
# 3. static equilibrium
# ------------------------------------------------------------------------------------------------


@dataclass
class StaticEquilibrium:
    """Result of :func:`static_equilibrium`.

    Attributes
    ----------
    q : ndarray, shape (n_q,)
    lam : ndarray, shape (n_c,)
        Multipliers (minimum-norm when rows are redundant).
    t : float
    stationarity : float
        ``max|Q(t, q, 0) − Φ_qᵀλ|`` at the solution (generalized force units).
    reduced_gradient : float
        ``max|Nᵀ Q|`` with ``N`` an orthonormal null-space basis of ``Φ_q`` (independent of λ).
    constraint_violation : float
        ``max|Φ(t, q)|``.
    iterations : int
    stable : bool
        All eigenvalues of the reduced tangent stiffness ``Nᵀ K_T N`` are positive (a minimum of the
        potential for conservative systems).
    min_stiffness : float
        Smallest eigenvalue of the symmetric part of ``Nᵀ K_T N`` (NaN with no free directions).
    reactions : dict of str to ndarray
        ``system.reactions(t, q, λ)``.
    reaction_names : dict of str to list of str
    coordinate_names, constraint_names : list of str
    """

    q: Array
    lam: Array
    t: float
    stationarity: float
    reduced_gradient: float
    constraint_violation: float
    iterations: int
    stable: bool
    min_stiffness: float
    reactions: dict[str, Array] = field(default_factory=dict)
    reaction_names: dict[str, list[str]] = field(default_factory=dict)
    coordinate_names: list[str] = field(default_factory=list)
    constraint_names: list[str] = field(default_factory=list)

    def coordinates(self) -> pd.DataFrame:
        """One-row table of the equilibrium coordinates."""
        return pd.DataFrame([self.q], columns=self.coordinate_names)

    def multipliers(self) -> pd.DataFrame:
        """One-row table of the multipliers, columns ``lambda[<constraint>]``."""
        return pd.DataFrame([self.lam], columns=[f"lambda[{n}]" for n in self.constraint_names])

    def reactions_table(self) -> pd.DataFrame:
        """Joints as rows, reaction components (with units) as columns."""
        data = {j: dict(zip(self.reaction_names.get(j, [f"R[{i}]" for i in range(len(r))]), r))
                for j, r in self.reactions.items()}
        df = pd.DataFrame.from_dict(data, orient="index")
        df.index.name = "joint"
        return df


def _energy_step(system, t, q, r1, J, lam, rank0, tol):
    """One projected, energy-descending reduced Newton step of :func:`static_equilibrium`."""
    zero = np.zeros(system.n_v)
    _, _, _, N = truncated_svd(J, max_rank=rank0)
    Qq, _ = _q_jacobians(system, t, q, zero)
    KN = N.T @ (-Qq + _geometric_stiffness(system, t, q, lam)) @ N
    g = N.T @ r1  # reduced generalized force = −(reduced gradient of the potential)
    ev, EV = np.linalg.eigh(0.5 * (KN + KN.T))
    floor = 1e-8 * max(1.0, float(np.max(np.abs(ev), initial=0.0)))
    pd_ = bool(np.all(ev > floor))
    z = np.linalg.solve(KN, g) if pd_ else EV @ ((EV.T @ g) / np.maximum(np.abs(ev), floor))
    V0 = system.energy(t, q, zero)
    n0 = float(np.linalg.norm(r1))
    alpha = 1.0
    while alpha >= 1.0 / 1024:
        try:
            q1, ok, _, _ = newton_positions(system, t, system.retract(q, alpha * (N @ z)), tol, 50)
        except (ValueError, FloatingPointError, np.linalg.LinAlgError):
            ok = False
        if ok:
            V1 = system.energy(t, q1, zero)
            if V1 <= V0 - 1e-4 * alpha * float(g @ z):
                return q1
            if pd_ and alpha == 1.0:  # near the minimum energy differences drown in round-off
                J1 = system.Phi_q(t, q1)
                Q1 = np.asarray(system.Q(t, q1, zero), float)
                lam1, _ = minimum_norm_multipliers(J1, Q1)
                if np.linalg.norm(Q1 - np.asarray(J1.T @ lam1).ravel()) < 0.5 * n0:
                    return q1
        alpha *= 0.5
    return None


def static_equilibrium(system: ConstrainedSystem, q_guess: ArrayLike | None = None, t: float = 0.0,
                       tol: float = 1e-10, max_iter: int = 100, method: str = "auto") -> StaticEquilibrium:
    r"""Static equilibrium ``Q(t, q, 0) − Φ_qᵀλ = 0``, ``Φ(t, q) = 0`` by damped Newton.

    Tangent ``K_T = −Q_q + ∂(Φ_qᵀλ)/∂q`` (``Q_q`` from ``system.Q_jacobians`` when present, the
    constraint term by central differences); the KKT step for ``Δv`` is computed by the null-space
    method with a truncated SVD of ``Φ_q`` (``Δv = Y y + N z``, ``Φ_q Y y = −Φ``,
    ``Nᵀ K_T N z = Nᵀ(r₁ − K_T Y y)``), robust to redundant rows; backtracking on
    ``‖Q − Φ_qᵀλ‖² + ‖Φ‖²``.  The multipliers are eliminated at every iterate by least squares,
    ``λ(q) = (Φ_qᵀ)⁺ Q`` (minimum norm): with redundant rows a free Newton update of λ would drift
    along the null space of ``Φ_qᵀ`` and corrupt the geometric stiffness, which depends on it off
    the constraint manifold.  Convergence stays quadratic since ``λ(q) − λ* = O(‖q − q*‖)``.
    The guess is first assembled onto ``Φ = 0``.

    Two globalisations (``method``):

    * ``'energy'`` (default for conservative systems with an :meth:`energy`): every iterate is kept
      on ``Φ = 0`` (step ``N z`` then Gauss–Newton projection) and the step must decrease the
      potential (Armijo); a reduced tangent ``Nᵀ K_T N`` that is not positive definite is replaced by
      its eigenvalue-modulus so the step is a descent direction.  Converges to a *stable* equilibrium
      (local minimum of the potential on the constraint manifold) from a rough guess.
    * ``'newton'``: the full step above with backtracking on the residual norm; converges to the
      nearest stationary point, stable or not (follower loads, non-conservative systems).  Newton finds *a* stationary point; ``result.stable`` tells whether it is a
      minimum.

    Parameters
    ----------
    system : ConstrainedSystem
    q_guess : array_like, shape (n_q,), optional
        Default ``system.q0``.
    t : float
        Time [s] at which loads and drivers are evaluated.
    tol : float
        Convergence when ``max|Q − Φ_qᵀλ| ≤ tol·max(1, max|Q|)`` and ``max|Φ| ≤ tol·max(1, max|q|)``.
    max_iter : int
    method : {'auto', 'energy', 'newton'}
        ``'auto'``: ``'energy'`` if ``system.is_conservative`` and ``system.energy`` is defined.

    Returns
    -------
    StaticEquilibrium

    Raises
    ------
    RuntimeError
        Newton did not converge (the message gives the residuals and the worst coordinate).
    """
    n_v = system.n_v
    zero = np.zeros(n_v)
    q, _ = assemble_state(system, q_guess, zero, t=t, tol=tol)
    fscale = max(1.0, float(np.max(np.abs(system.Q(t, q, zero)), initial=0.0)))
    qscale = coordinate_scale(q)

    def residual(q):
        # λ eliminated by least squares: λ(q) = (Φ_qᵀ)⁺ Q, so r1 = Q − Φ_qᵀλ is the part of Q that the
        # constraints cannot balance; the minimum-norm choice keeps λ unique with redundant rows.
        J = system.Phi_q(t, q)
        Q = np.asarray(system.Q(t, q, zero), float)
        lam, _ = minimum_norm_multipliers(J, Q)
        r1 = Q - np.asarray(J.T @ lam).ravel() if system.n_c else Q
        r2 = np.asarray(system.Phi(t, q), float)
        return r1, r2, J, lam

    if method not in ("auto", "energy", "newton"):
        raise InputError(f"static_equilibrium: method must be 'auto', 'energy' or 'newton', got {method!r}")
    if method == "auto":
        method = "energy" if (getattr(system, "is_conservative", False)
                              and system.energy(t, q, zero) is not None) else "newton"
    r1, r2, J, lam = residual(q)
    rank0 = _rank(J)  # structural rank at the assembled guess (redundant rows excluded)
    it = 0
    converged = False
    for it in range(1, max_iter + 1):
        if np.max(np.abs(r1), initial=0) <= tol * fscale and np.max(np.abs(r2), initial=0) <= tol * qscale:
            converged = True
            it -= 1
            break
        if method == "energy":
            step = _energy_step(system, t, q, r1, J, lam, rank0, tol)
            if step is None:
                break
            q = step
            r1, r2, J, lam = residual(q)
            continue
        Qq, _ = _q_jacobians(system, t, q, zero)
        KT = -Qq + _geometric_stiffness(system, t, q, lam)
        # null-space Newton step: Φ_q Δv = −Φ on the numerical range, Nᵀ(K_T Δv − r1) = 0
        U, sv, Y, N = truncated_svd(J, max_rank=rank0)
        dy = Y @ (-(U.T @ r2) / sv) if len(sv) else np.zeros(n_v)
        KN = N.T @ KT @ N
        rhs = N.T @ (r1 - KT @ dy)
        try:
            z = np.linalg.solve(KN, rhs)
        except np.linalg.LinAlgError:
            z = sla.lstsq(KN, rhs, lapack_driver="gelsd")[0]
        dv = dy + N @ z
        m0 = float(r1 @ r1 + r2 @ r2)
        alpha = 1.0
        while True:
            q1 = system.retract(q, alpha * dv)
            s1, s2, J1, lam1 = residual(q1)
            m1 = float(s1 @ s1 + s2 @ s2)
            if (np.isfinite(m1) and m1 <= (1.0 - 1e-4 * alpha) * m0) or alpha < 1e-3:
                break
            alpha *= 0.5
        if not np.isfinite(m1):
            break
        q, r1, r2, J, lam = q1, s1, s2, J1, lam1
    if not converged:
        qn = _names(system)[1]
        k = int(np.argmax(np.abs(r1))) if len(r1) else 0
        raise RuntimeError(
            f"{system.name}: static equilibrium did not converge in {it} iterations; "
            f"max|Q − Φ_qᵀλ| = {np.max(np.abs(r1), initial=0):.3e} (worst along {qn[k]!r}), "
            f"max|Φ| = {np.max(np.abs(r2), initial=0):.3e}"
        )
    lam, _ = minimum_norm_multipliers(J, np.asarray(system.Q(t, q, zero), float))  # minimum-norm set
    r1 = np.asarray(system.Q(t, q, zero), float) - np.asarray(J.T @ lam).ravel() if system.n_c else np.asarray(system.Q(t, q, zero), float)
    N = null_space_basis(J)
    Qq, _ = _q_jacobians(system, t, q, zero)
    Kr = N.T @ (-Qq + _geometric_stiffness(system, t, q, lam)) @ N
    eig = np.linalg.eigvalsh(0.5 * (Kr + Kr.T)) if Kr.size else np.zeros(0)
    return StaticEquilibrium(
        q=q, lam=lam, t=float(t),
        stationarity=float(np.max(np.abs(r1), initial=0.0)),
        reduced_gradient=float(np.max(np.abs(N.T @ np.asarray(system.Q(t, q, zero), float)), initial=0.0)),
        constraint_violation=float(np.max(np.abs(system.Phi(t, q)), initial=0.0)),
        iterations=it,
        stable=bool(np.all(eig > 0)),
        min_stiffness=float(eig.min()) if len(eig) else float("nan"),
        reactions=system.reactions(t, q, lam),
        reaction_names=system.reaction_names(),
        coordinate_names=_names(system)[0],
        constraint_names=list(getattr(system, "constraint_names", []) or [f"Phi[{i}]" for i in range(system.n_c)]),
    )


# ------------------------------------------------------------------------------------------------
# 4. inverse dynamics
# ------------------------------------------------------------------------------------------------


def _driver_rows(system: ConstrainedSystem, drivers) -> dict[str, tuple[NDArray[np.int64], str]]:
    """Driver name → (constraint rows, effort unit)."""
    groups = system.reaction_groups()
    out = {}
    if drivers is None:
        try:
            from .joints import JointAngleDriver, PointDriver
        except ImportError:  # pragma: no cover
            return out
        for j in getattr(system, "joints", ()):
            if isinstance(j, (JointAngleDriver, PointDriver)) and j.name in groups and len(groups[j.name]):
                out[j.name] = (groups[j.name], "N m" if isinstance(j, JointAngleDriver) else "N")
        return out
    names = list(getattr(system, "constraint_names", []))
    for d in drivers:
        if d in groups:
            out[d] = (np.asarray(groups[d]), "-")
        elif d in names:
            out[d] = (np.array([names.index(d)]), "-")
        else:
            raise InputError(f"{system.name}: unknown driver {d!r} (neither a reaction group nor a constraint name)")
    return out


def inverse_dynamics(system: ConstrainedSystem, t: ArrayLike, q: ArrayLike, v: ArrayLike, a: ArrayLike,
                     drivers: list[str] | None = None) -> pd.DataFrame:
    r"""Multipliers, joint reactions and driver efforts of a prescribed motion.

    At each sample ``Φ_qᵀλ = Q(t, q, v) − M(q) a`` is solved in the least-squares sense with the
    minimum-norm ``λ`` (unique when Φ_q has full row rank).  The residual
    ``‖Φ_qᵀλ − (Q − M a)‖₂`` is zero when the motion is dynamically consistent with the model
    (e.g. the motion of a fully driven mechanism, or a trajectory of the forward dynamics).

    *Driver effort* is ``−λ`` of a driving constraint ``Φ = s(q) − f(t)``: the generalized force
    the driver exerts along its driven coordinate ``s`` (torque [N m] on ``body_j`` about the joint
    axis for a revolute angle driver, force [N] along the direction for a point driver), i.e. the
    actuator torque/force that produces the motion.

    Parameters
    ----------
    system : ConstrainedSystem
    t : array_like, shape (n_t,)
        Times [s].
    q : array_like, shape (n_t, n_q)
    v, a : array_like, shape (n_t, n_v)
        Velocities and accelerations (``a = v̇``).
    drivers : list of str, optional
        Reaction groups or constraint names to report as drivers; default, for a
        :class:`core.model.Model`, its angle and point drivers.

    Returns
    -------
    DataFrame
        ``"t [s]"``, ``"lambda[<constraint>]"`` per row, ``"residual"`` (2-norm, generalized-force
        units), ``"<joint>.<component> [unit]"`` reactions per joint (``system.reactions``), and
        ``"<driver> effort [N m]"`` (or ``[N]``) per driver row.
    """
    t = np.atleast_1d(np.asarray(t, float))
    q = np.atleast_2d(np.asarray(q, float))
    v = np.atleast_2d(np.asarray(v, float))
    a = np.atleast_2d(np.asarray(a, float))
    n_t = len(t)
    for nm, arr, n in (("q", q, system.n_q), ("v", v, system.n_v), ("a", a, system.n_v)):
        if arr.shape != (n_t, n):
            raise InputError(f"inverse_dynamics: {nm} has shape {arr.shape}, expected ({n_t}, {n})")
    cnames = list(getattr(system, "constraint_names", []) or [f"Phi[{i}]" for i in range(system.n_c)])
    drv = _driver_rows(system, drivers)
    rnames = system.reaction_names()
    batched = _inverse_dynamics_frames(system, t, q, v, a) if hasattr(system, "Q_frames") else None
    if batched is not None:
        L, res, reac = batched
    else:
        L = np.zeros((n_t, system.n_c))
        res = np.zeros(n_t)
        reac = {}
        for i in range(n_t):
            M = system.M(t[i], q[i])
            rhs = np.asarray(system.Q(t[i], q[i], v[i]), float) - np.asarray(M @ a[i]).ravel()
            J = system.Phi_q(t[i], q[i])
            L[i], res[i] = minimum_norm_multipliers(J, rhs)
            for name, val in system.reactions(t[i], q[i], L[i]).items():
                reac.setdefault(name, []).append(np.asarray(val, float))
    cols: dict[str, Array] = {"t [s]": t}
    for k, n in enumerate(cnames):
        cols[f"lambda[{n}]"] = L[:, k]
    cols["residual"] = res
    for name, vals in reac.items():
        arr = np.array(vals)
        comp = rnames.get(name, [f"R[{k}]" for k in range(arr.shape[1])])
        for k, c in enumerate(comp):
            cols[f"{name}.{c}"] = arr[:, k]
    for name, (rows, unit) in drv.items():
        for k, r in enumerate(rows):
            suffix = "" if len(rows) == 1 else f"[{k}]"
            cols[f"{name}{suffix} effort [{unit}]"] = -L[:, r]
    df = pd.DataFrame(cols)
    df.attrs.update(analysis="inverse dynamics", system=system.name, max_residual=float(res.max(initial=0.0)),
                    drivers=list(drv))
    return df


def _inverse_dynamics_frames(system, t, q, v, a):
    """``(λ, residual, reactions)`` of all frames at once when Φ_q is square and regular in every
    frame (``λ = Φ_q⁻ᵀ(Q − M a)`` with the batched inverse of ``_frames_inverse``: the unique
    multipliers, equal to the minimum-norm ones); None otherwise (the frame-by-frame least squares
    then runs)."""
    if system.n_c != system.n_v or system.n_c == 0:
        return None
    J = system.constraint_terms_frames(t, q)[1]
    rhs = system.Q_frames(t, q, v) - np.einsum("fij,fj->fi", system.M_frames(t, q), a)
    if not (np.all(np.isfinite(J)) and np.all(np.isfinite(rhs))):
        return None
    Ji = _frames_inverse(J)
    if Ji is None:
        return None
    lam = np.einsum("fji,fj->fi", Ji, rhs)  # λ = Φ_q⁻ᵀ (Q − M a)
    res = np.linalg.norm(np.einsum("fji,fj->fi", J, lam) - rhs, axis=1)
    reac = system.reactions_frames(t, q, lam, J=J)
    return lam, res, reac


def inverse_dynamics_from_result(system: ConstrainedSystem, result, method: str = "differentiate",
                                 drivers: list[str] | None = None) -> pd.DataFrame:
    """Inverse dynamics along a simulated trajectory (:class:`core.results.SimulationResult`).

    Parameters
    ----------
    method : {'differentiate', 'forward'}
        ``'differentiate'``: accelerations from the derivative of a cubic spline through the sampled
        velocities (independent of the forward solve; the ``residual`` column then measures how
        consistent the trajectory is with the model, O(Δt⁴) for a smooth exact trajectory);
        ``'forward'``: accelerations from the index-1 forward dynamics at each sample.
    """
    from scipy.interpolate import CubicSpline

    t = np.asarray(result.t, float)
    q = np.asarray(result.q, float)
    v = np.asarray(result.v, float)
    if method == "differentiate":
        if len(t) < 4:
            raise InputError("inverse_dynamics_from_result: 'differentiate' needs at least 4 samples")
        a = CubicSpline(t, v, axis=0)(t, 1)
    elif method == "forward":
        a = np.array([accelerations(system, ti, qi, vi)[0] for ti, qi, vi in zip(t, q, v)])
    else:
        raise InputError(f"inverse_dynamics_from_result: method must be 'differentiate' or 'forward', got {method!r}")
    return inverse_dynamics(system, t, q, v, a, drivers=drivers)


def inverse_dynamics_from_kinematics(system: ConstrainedSystem, kinematics: pd.DataFrame,
                                     drivers: list[str] | None = None) -> pd.DataFrame:
    """Inverse dynamics of a fully driven mechanism from the table of :func:`kinematic_analysis`."""
    qn, vn, an = _names(system)
    return inverse_dynamics(system, kinematics["t [s]"].to_numpy(), kinematics[qn].to_numpy(),
                            kinematics[vn].to_numpy(), kinematics[an].to_numpy(), drivers=drivers)


# ------------------------------------------------------------------------------------------------
# 5. linearisation and eigenanalysis
# ------------------------------------------------------------------------------------------------


@dataclass
class LinearizedSystem:
    r"""Reduced linear model ``M ẍ + (D + G) ẋ + K x = 0`` with ``δv = N x`` (see module docstring).

    Attributes
    ----------
    M, D, G, K : ndarray, shape (n_dof, n_dof)
        Reduced mass, damping (symmetric), gyroscopic (skew) and stiffness (may be non-symmetric
        for circulatory loads) matrices.
    N : ndarray, shape (n_v, n_dof)
        Orthonormal null-space basis of ``Φ_q`` at the linearisation point.
    q : ndarray, shape (n_q,)
    v : ndarray, shape (n_v,)
    t : float
    lam : ndarray, shape (n_c,)
        Multipliers used in the geometric stiffness.
    K_geometric : ndarray, shape (n_dof, n_dof)
        The constraint-force part ``Nᵀ ∂(Φ_qᵀλ)/∂q N`` of ``K``.
    velocity_names : list of str
    acceleration : ndarray, shape (n_v,)
        Accelerations ``a`` of the index-1 equations at the linearisation state.
    equilibrium_residual : float
        ``‖M a‖_∞ / max(‖Q‖_∞, ‖Φ_qᵀλ‖_∞)``: the unbalanced generalized force relative to the forces
        acting; zero at an equilibrium (or a steady motion with ``a = 0``).  Above 1e-6,
        :func:`eigen` warns that the modes belong to an accelerating state.
    """

    M: Array
    D: Array
    G: Array
    K: Array
    N: Array
    q: Array
    v: Array
    t: float
    lam: Array
    K_geometric: Array
    velocity_names: list[str]
    acceleration: Array | None = None
    equilibrium_residual: float = 0.0

    @property
    def n_dof(self) -> int:
        return self.N.shape[1]

    def state_matrix(self) -> Array:
        """First-order ``A`` of ``ż = A z``, ``z = (x, ẋ)``, shape (2 n_dof, 2 n_dof)."""
        n = self.n_dof
        Minv = np.linalg.inv(self.M)
        return np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K, -Minv @ (self.D + self.G)]])


def linearize(system: ConstrainedSystem, q: ArrayLike | None = None, v: ArrayLike | None = None, t: float = 0.0,
              lam: ArrayLike | None = None) -> LinearizedSystem:
    r"""Linearise the constrained equations about ``(t, q, v)`` in the null space of ``Φ_q``.

    See the module docstring for the equations (Géradin & Cardona 2001, Sec. 11.4; Negrut & Ortiz
    2006).  ``λ`` and ``a`` come from the index-1 equations at the state unless ``lam`` is given (at
    a static equilibrium ``a = 0`` and ``λ`` is the static multiplier vector).

    Parameters
    ----------
    q : array_like, shape (n_q,), optional
        Default ``system.q0``; must satisfy Φ = 0 (use :func:`static_equilibrium` first).
    v : array_like, shape (n_v,), optional
        Default zeros.
    t : float
    lam : array_like, shape (n_c,), optional

    Returns
    -------
    LinearizedSystem
    """
    q = np.asarray(system.q0 if q is None else q, float)
    v = np.zeros(system.n_v) if v is None else np.asarray(v, float)
    if system.n_c:
        phi = np.asarray(system.Phi(t, q))
        if np.max(np.abs(phi)) > 1e-6 * coordinate_scale(q):
            k = int(np.argmax(np.abs(phi)))
            names = list(getattr(system, "constraint_names", []) or [f"Phi[{i}]" for i in range(system.n_c)])
            raise InputError(f"{system.name}: linearize needs an assembled state; constraint {names[k]!r} is violated by {phi[k]:.3e}")
    a, lam_kkt = accelerations(system, t, q, v)
    lam = lam_kkt if lam is None else np.asarray(lam, float)
    M = as_dense(system.M(t, q))
    Qq, Qv = _q_jacobians(system, t, q, v)
    Kg = _geometric_stiffness(system, t, q, lam)
    Km = _mass_gradient(system, t, q, a)
    N = null_space_basis(system.Phi_q(t, q))
    Mr = N.T @ M @ N
    C = -N.T @ Qv @ N
    Kr = N.T @ (-Qq + Kg + Km) @ N
    Q = np.asarray(system.Q(t, q, v), float)
    react = as_dense(system.Phi_q(t, q)).T @ lam_kkt if system.n_c else np.zeros(system.n_v)
    force_scale = max(float(np.max(np.abs(Q), initial=0.0)), float(np.max(np.abs(react), initial=0.0)))
    unbalanced = float(np.max(np.abs(M @ a), initial=0.0))
    residual = unbalanced / force_scale if force_scale > 0 else (0.0 if unbalanced == 0 else np.inf)
    return LinearizedSystem(
        M=0.5 * (Mr + Mr.T), D=0.5 * (C + C.T), G=0.5 * (C - C.T), K=Kr, N=N, q=q, v=v, t=float(t),
        lam=lam, K_geometric=N.T @ Kg @ N, velocity_names=_names(system)[1], acceleration=a,
        equilibrium_residual=residual,
    )


def eigen(system: ConstrainedSystem | LinearizedSystem, q: ArrayLike | None = None, v: ArrayLike | None = None,
          t: float = 0.0, lam: ArrayLike | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    r"""Eigenvalues and modes of the linearised constrained system.

    Solves the generalized problem ``s B z = A z`` with ``A = [[0, I], [−K, −(D+G)]]``,
    ``B = diag(I, M)`` (so a singular ``M_r`` is tolerated).  One eigenvalue of each complex-conjugate
    pair is kept (``Im s ≥ 0``); rows are sorted by undamped natural frequency.

    Returns
    -------
    table : DataFrame
        ``"real [1/s]"``, ``"imag [rad/s]"``, ``"frequency [Hz]"`` (damped, ``|Im s|/2π``),
        ``"natural frequency [Hz]"`` (``|s|/2π``), ``"damping ratio [-]"`` (``−Re s/|s|``).
    modes : DataFrame (complex)
        One column per row of ``table`` (``"mode 0"``, ...), indexed by the velocity names: the mode
        shape ``N φ`` mapped back to velocity space, scaled to unit largest component.
    """
    lin = system if isinstance(system, LinearizedSystem) else linearize(system, q, v, t, lam)
    if lin.equilibrium_residual > EQUILIBRIUM_TOL and lin.acceleration is not None:
        k = int(np.argmax(np.abs(lin.acceleration)))
        warnings.warn(
            f"eigen: the state is not an equilibrium (unbalanced generalized force {lin.equilibrium_residual:.3g} "
            f"of the forces acting; largest acceleration {lin.acceleration[k]:.3g} in {lin.velocity_names[k]!r}); "
            "the modes describe the linearisation about an accelerating state. Find the equilibrium first "
            "(static_equilibrium).", AnalysisWarning, stacklevel=2)
    n = lin.n_dof
    if n == 0:
        empty = pd.DataFrame(columns=["real [1/s]", "imag [rad/s]", "frequency [Hz]", "natural frequency [Hz]", "damping ratio [-]"])
        return empty, pd.DataFrame(index=lin.velocity_names)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-lin.K, -(lin.D + lin.G)]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), lin.M]])
    s, Zr = sla.eig(A, B)
    finite = np.isfinite(s)
    s, Zr = s[finite], Zr[:, finite]
    scale = max(1.0, float(np.max(np.abs(s), initial=0.0)))
    keep = s.imag >= -1e-9 * scale
    s, Zr = s[keep], Zr[:, keep]
    wn = np.abs(s)
    order = np.lexsort((s.real, wn))
    s, Zr, wn = s[order], Zr[:, order], wn[order]
    zeta = np.where(wn > 0, -s.real / np.where(wn > 0, wn, 1.0), np.nan)
    table = pd.DataFrame({
        "real [1/s]": s.real,
        "imag [rad/s]": np.abs(s.imag),
        "frequency [Hz]": np.abs(s.imag) / (2 * np.pi),
        "natural frequency [Hz]": wn / (2 * np.pi),
        "damping ratio [-]": zeta,
    })
    modes = lin.N @ Zr[:n]
    for k in range(modes.shape[1]):
        j = int(np.argmax(np.abs(modes[:, k])))
        if abs(modes[j, k]) > 0:
            modes[:, k] /= modes[j, k]
    mdf = pd.DataFrame(modes, index=lin.velocity_names, columns=[f"mode {k}" for k in range(modes.shape[1])])
    table.attrs.update(analysis="eigen", n_dof=n, equilibrium_residual=lin.equilibrium_residual)
    return table, mdf
