r"""The linear algebra of the constrained equations, written once for every integrator and analysis.

Saddle-point (KKT) systems
--------------------------
Index-1 accelerations with optional Baumgarte stabilisation (Baumgarte 1972, Eq. 10; Nikravesh
1988, Eq. 13.22):

.. math::

    \begin{bmatrix} M & \Phi_q^T \\ \Phi_q & 0 \end{bmatrix}
    \begin{bmatrix} \dot v \\ \lambda \end{bmatrix} =
    \begin{bmatrix} Q \\ \gamma - 2\alpha(\Phi_q v - \nu) - \beta^2 \Phi \end{bmatrix}

:func:`solve_kkt` factorises the KKT matrix with SuperLU; :class:`SaddleSolver` keeps ``M⁻¹``
of a constant mass matrix and solves by the Schur complement ``Φ_q M⁻¹ Φ_qᵀ`` (Cholesky), the
route of the integrators' right-hand sides.

Minimum-norm rules (redundant constraints kept in the model)
------------------------------------------------------------
When rows of ``Φ_q`` are dependent the accelerations stay unique but the multipliers do not.
The one rule used everywhere: ``λ`` is the **minimum-norm** solution of ``Φ_qᵀ λ = Q − M v̇``
(:func:`minimum_norm_multipliers`, SVD least squares with the relative rank cutoff
:data:`RANK_RCOND`), i.e. the multiplier set orthogonal to ``null(Φ_qᵀ)``; with the default
cutoff of LAPACK (machine epsilon) an exact null direction with singular value ~1e-15·σ_max
would be counted as rank and λ would carry a component in ``null(Φ_qᵀ)``.  Corrections of
positions and velocities are the minimum-``W``-norm solutions of ``Φ_q Δ = r``
(:func:`minimum_norm_correction`, ``W = M`` or ``I``).

Projection onto the constraint manifold (Eich 1993; Eich-Soellner & Führer 1998, Ch. 5)
---------------------------------------------------------------------------------------
:func:`project_positions`: simplified Gauss–Newton iterations for the M-weighted minimum-norm
correction along velocity-space increments,

.. math::  \begin{bmatrix} M & Φ_q^T \\ Φ_q & 0 \end{bmatrix}
           \begin{bmatrix} Δ \\ μ \end{bmatrix} = \begin{bmatrix} 0 \\ -Φ(q^{(k)}) \end{bmatrix},
           \qquad q^{(k+1)} = q^{(k)} ⊕ Δ,

with ``Φ_q`` and its factorisation frozen at the unprojected point, until ``‖Φ‖∞ ≤ tol``.
:func:`project_velocities`: the velocity correction of least ``W``-norm onto ``Φ_q v = ν``,
``[[W, Φ_qᵀ], [Φ_q, 0]] [Δv; μ] = [0; ν − Φ_q v]``.  Assembly, the index-1 and half-explicit
integrators and generalized-α use these two functions; the compiled path
(:func:`core.compiled.dynamics.project`) implements the same iteration in numba and is tested
against them.

References
----------
J. Baumgarte, "Stabilization of constraints and integrals of motion in dynamical systems",
Comput. Methods Appl. Mech. Eng. 1 (1972) 1–16.
E. Eich, "Convergence results for a coordinate projection method applied to mechanical systems
with algebraic constraints", SIAM J. Numer. Anal. 30(5) (1993) 1467–1482.
E. Eich-Soellner, C. Führer, *Numerical Methods in Multibody Dynamics*, Teubner, 1998, Ch. 5.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988.
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from .errors import NumericalFailure
from .system import ConstrainedSystem

Array = NDArray[np.float64]

__all__ = [
    "RANK_RCOND",
    "SingularKKTError",
    "kkt_matrix",
    "solve_kkt",
    "minimum_norm_multipliers",
    "minimum_norm_correction",
    "SaddleSolver",
    "constraint_terms",
    "accelerations",
    "project_positions",
    "project_velocities",
    "project",
    "keeps_redundant_rows",
]

#: Relative singular-value cutoff of every minimum-norm solve (see the module docstring).
RANK_RCOND = 1e-12
#: Systems up to this many velocity coordinates use dense Schur complements.
_DENSE_MAX = 400
#: Saddle-point matrices up to this order are factored dense where M has no inverse (a point
#: mass's zero rotational inertia): building the sparse matrix costs more than the dense LU there.
_DENSE_KKT_MAX = 120


def _dense(A) -> Array:
    return A.toarray() if sp.issparse(A) else np.asarray(A, float)


def kkt_matrix(M, J) -> sp.csc_matrix:
    """Sparse ``[[M, Jᵀ], [J, 0]]``."""
    M = sp.csr_matrix(M)
    J = sp.csr_matrix(J)
    return sp.bmat([[M, J.T], [J, None]], format="csc")


class SingularKKTError(NumericalFailure, np.linalg.LinAlgError):
    """The KKT matrix is singular beyond what redundancy of Φ_q explains (e.g. M singular)."""


def keeps_redundant_rows(system) -> bool:
    """True when the system keeps dependent constraint rows (multipliers are then minimum-norm)."""
    return bool(len(getattr(system, "redundant_rows", ())) and getattr(system, "_active_rows", None) is None)


def minimum_norm_multipliers(J, rhs: Array) -> tuple[Array, float]:
    """Minimum-norm ``λ`` of ``Jᵀλ ≈ rhs`` (SVD least squares, cutoff :data:`RANK_RCOND`) and the
    residual 2-norm ``‖Jᵀλ − rhs‖``."""
    Jd = _dense(J)
    rhs = np.asarray(rhs, float)
    if Jd.shape[0] == 0:
        return np.zeros(0), float(np.linalg.norm(rhs))
    if not (np.all(np.isfinite(Jd)) and np.all(np.isfinite(rhs))):
        raise SingularKKTError("non-finite constraint Jacobian or forces in the multiplier solve")
    lam = sla.lstsq(Jd.T, rhs, cond=RANK_RCOND, lapack_driver="gelsd")[0]
    return lam, float(np.linalg.norm(Jd.T @ lam - rhs))


def minimum_norm_correction(J, r: Array, W=None) -> Array:
    """``argmin ½ xᵀWx`` subject to ``J x = r`` (least squares in ``J x ≈ r`` if inconsistent).

    ``W = None`` is the identity.  Sparse KKT factorisation first; the dense minimum-norm least
    squares solution (``gelsd``, cutoff :data:`RANK_RCOND`) when ``J`` is rank deficient and the
    linearised system inconsistent.
    """
    n_c, n_v = J.shape
    if n_c == 0:
        return np.zeros(n_v)
    r = np.asarray(r, float)
    # [[W, Jᵀ], [J, 0]] from COO triplets (sp.bmat costs ~5 ms per call; this is called per step
    # by the velocity projection of generalized-α)
    Wc = sp.identity(n_v, format="coo") if W is None else (W.tocoo() if sp.issparse(W) else sp.coo_matrix(W))
    Jc = J.tocoo() if sp.issparse(J) else sp.coo_matrix(np.asarray(J, float))
    K = sp.csc_matrix((np.concatenate([Wc.data, Jc.data, Jc.data]),
                       (np.concatenate([Wc.row, Jc.col, Jc.row + n_v]), np.concatenate([Wc.col, Jc.row + n_v, Jc.col]))),
                      shape=(n_v + n_c, n_v + n_c))
    rhs = np.concatenate([np.zeros(n_v), r])
    try:
        with np.errstate(all="raise"), warnings.catch_warnings():
            warnings.simplefilter("error", spla.MatrixRankWarning)
            sol = spla.splu(K).solve(rhs)
        if np.all(np.isfinite(sol)) and np.linalg.norm(K @ sol - rhs) <= 1e-10 * (1.0 + np.linalg.norm(rhs)):
            return sol[:n_v]
    except (RuntimeError, FloatingPointError, ValueError, spla.MatrixRankWarning):
        pass
    Jd = _dense(J)
    if not (np.all(np.isfinite(Jd)) and np.all(np.isfinite(r))):
        raise SingularKKTError("non-finite constraint Jacobian or residual in a minimum-norm correction")
    if W is None:
        return sla.lstsq(Jd, r, cond=RANK_RCOND, lapack_driver="gelsd")[0]
    try:
        L = np.linalg.cholesky(_dense(W))
    except np.linalg.LinAlgError:
        return sla.lstsq(Jd, r, cond=RANK_RCOND, lapack_driver="gelsd")[0]
    # x = L⁻ᵀ y, min ‖y‖ s.t. (J L⁻ᵀ) y = r
    B = sla.solve_triangular(L, Jd.T, lower=True).T
    y = sla.lstsq(B, r, cond=RANK_RCOND, lapack_driver="gelsd")[0]
    return sla.solve_triangular(L.T, y, lower=False)


def solve_kkt(M, J, top: Array, bottom: Array, minimum_norm: bool = False) -> tuple[Array, Array]:
    """Solve ``[[M, Jᵀ], [J, 0]] [x; λ] = [top; bottom]``.

    Parameters
    ----------
    M : (n_v, n_v) dense or sparse
    J : (n_c, n_v) dense or sparse
    top : ndarray, shape (n_v,)
    bottom : ndarray, shape (n_c,)
    minimum_norm : bool
        Redundant rows kept: ``x`` from the dense least-squares solution of the KKT system and
        ``λ`` by :func:`minimum_norm_multipliers` of ``Jᵀλ = top − M x``.

    Returns
    -------
    x : ndarray, shape (n_v,)
    lam : ndarray, shape (n_c,)

    Raises
    ------
    SingularKKTError
        The system is singular and inconsistent, or has non-finite entries.
    """
    n_v = len(top)
    n_c = len(bottom)
    rhs = np.concatenate([top, bottom])
    if n_c == 0:
        return np.linalg.solve(_dense(M), top), np.zeros(0)
    if not minimum_norm:
        K = kkt_matrix(M, J)
        try:
            with np.errstate(all="raise"):
                sol = spla.splu(K).solve(rhs)
            if np.all(np.isfinite(sol)):
                res = K @ sol - rhs
                if np.linalg.norm(res) <= 1e-8 * (1.0 + np.linalg.norm(rhs)):
                    return sol[:n_v], sol[n_v:]
        except (RuntimeError, FloatingPointError, ValueError):
            pass
    Md, Jd = _dense(M), _dense(J)
    Kd = np.block([[Md, Jd.T], [Jd, np.zeros((n_c, n_c))]])
    if not (np.all(np.isfinite(Kd)) and np.all(np.isfinite(rhs))):
        raise SingularKKTError("KKT system has non-finite entries (the state or the forces diverged)")
    sol = sla.lstsq(Kd, rhs, cond=RANK_RCOND, lapack_driver="gelsd")[0]
    x = sol[:n_v]
    if minimum_norm:
        # redundant equations kept: γ is consistent only up to the drift of the state off the
        # constraint manifold; the least-squares acceleration and the minimum-norm λ are the
        # defined answer
        if not np.all(np.isfinite(x)):
            raise SingularKKTError("minimum-norm KKT solution is not finite")
        lam, _ = minimum_norm_multipliers(Jd, top - Md @ x)
        return x, lam
    res = Kd @ sol - rhs
    if not np.all(np.isfinite(sol)) or np.linalg.norm(res) > 1e-6 * (1.0 + np.linalg.norm(rhs)):
        raise SingularKKTError(
            f"KKT system singular and inconsistent (residual {np.linalg.norm(res):.3e}); "
            "check for massless bodies without constraints or a singular configuration"
        )
    return x, sol[n_v:]


class SaddleSolver:
    """Reusable solver for ``[[M, Gᵀ], [J, 0]]`` systems of one constrained system.

    Parameters
    ----------
    system : ConstrainedSystem
    counters : dict
        The integrator's counters; ``n_factor`` is incremented per factorisation.
    """

    def __init__(self, system, counters: dict):
        self.system = system
        self.counters = counters
        self.minimum_norm = keeps_redundant_rows(system)
        self._Minv = None
        self._M = None
        self._minv_diag = None  # diagonal M: 1/diag(M)
        self._Minv_dense = None
        self.dense = system.n_v <= _DENSE_MAX
        if system.mass_is_constant:
            M = system.M(0.0, system.q0)
            self._M = M
            if not self.minimum_norm and system.n_v:
                try:
                    Md = M.toarray() if sp.issparse(M) else np.asarray(M, float)
                    off = Md - np.diag(np.diag(Md))
                    if not np.any(off) and np.all(np.diag(Md) > 0):
                        self._minv_diag = 1.0 / np.diag(Md)
                        self._Minv = sp.diags(self._minv_diag, format="csr")
                    else:
                        Minv = spla.inv(sp.csc_matrix(Md)) if sp.issparse(M) else np.linalg.inv(Md)
                        dense = Minv.toarray() if sp.issparse(Minv) else np.asarray(Minv)
                        if np.all(np.isfinite(dense)) and np.allclose(Md @ dense, np.eye(system.n_v), atol=1e-9):
                            self._Minv = sp.csr_matrix(dense)
                            self._Minv_dense = dense if self.dense else None
                except (RuntimeError, np.linalg.LinAlgError, ValueError):
                    self._Minv = None

    def mass(self, t, q):
        """``M(t, q)`` (cached when constant)."""
        return self._M if self._M is not None else self.system.M(t, q)

    def factor(self, t, q, J, G=None):
        """Factorisation object with ``solve(f, g) -> (x, μ)`` for ``[[M, Gᵀ], [J, 0]]``."""
        self.counters["n_factor"] += 1
        return _Factor(self, t, q, J, J if G is None else G, G is None)

    def solve(self, t, q, J, f, g, G=None):
        """One-off solve of ``[[M, Gᵀ], [J, 0]] [x; μ] = [f; g]``."""
        return self.factor(t, q, J, G).solve(f, g)


class _Factor:
    def __init__(self, owner: SaddleSolver, t, q, J, G, symmetric: bool):
        self.owner = owner
        self.n_c = J.shape[0]
        self.M = owner.mass(t, q)
        self.J, self.G = J, G
        self._J_orig = J
        self.mode = None
        Minv = owner._Minv
        if self.n_c == 0:
            self.mode = "free"
            return
        if Minv is not None:
            try:
                if owner.dense:
                    Jd = J.toarray() if sp.issparse(J) else np.asarray(J, float)
                    Gd = Jd if G is J else (G.toarray() if sp.issparse(G) else np.asarray(G, float))
                    self.J = Jd
                    if owner._minv_diag is not None:
                        self.MGt = owner._minv_diag[:, None] * Gd.T
                    else:
                        self.MGt = owner._Minv_dense @ Gd.T
                    Sd = Jd @ self.MGt
                    if symmetric:
                        if not np.all(np.isfinite(Sd)):
                            raise np.linalg.LinAlgError("non-finite Schur complement")
                        self.fac = sla.cho_factor(Sd, check_finite=False)
                        self.mode = "chol"
                    else:
                        lu = sla.lu_factor(Sd, check_finite=True)
                        d = np.abs(np.diag(lu[0]))
                        if d.min() <= 1e-13 * max(d.max(), 1e-300):
                            raise np.linalg.LinAlgError("singular Schur complement")
                        self.fac = lu
                        self.mode = "lu"
                else:
                    self.MGt = Minv @ sp.csr_matrix(G).T
                    self.fac = spla.splu(sp.csc_matrix(J @ self.MGt))
                    self.mode = "splu"
            except (np.linalg.LinAlgError, RuntimeError, ValueError):
                self.mode = None
                self.J = J
        if self.mode is None and not owner.minimum_norm and J.shape[1] + self.n_c <= _DENSE_KKT_MAX:
            Md = self.M.toarray() if sp.issparse(self.M) else np.asarray(self.M, float)
            Jd = J.toarray() if sp.issparse(J) else np.asarray(J, float)
            Gd = Jd if G is J else (G.toarray() if sp.issparse(G) else np.asarray(G, float))
            K = np.block([[Md, Gd.T], [Jd, np.zeros((self.n_c, self.n_c))]])
            if np.all(np.isfinite(K)):
                with warnings.catch_warnings():  # an exactly singular K is judged by its pivots below
                    warnings.simplefilter("ignore", sla.LinAlgWarning)
                    lu = sla.lu_factor(K, check_finite=False)
                d = np.abs(np.diag(lu[0]))
                if d.min() > 1e-13 * max(d.max(), 1e-300):  # else singular: the sparse and minimum-norm routes
                    self.fac, self.K, self.mode = lu, K, "kkt-dense"
        if self.mode is None and not owner.minimum_norm:
            try:
                K = kkt_matrix(self.M, J) if G is J else sp.bmat(
                    [[sp.csr_matrix(self.M), sp.csr_matrix(G).T], [sp.csr_matrix(J), None]], format="csc")
                with np.errstate(all="raise"):
                    self.fac = spla.splu(sp.csc_matrix(K))
                self.K = K
                self.mode = "kkt"
            except (RuntimeError, FloatingPointError, ValueError):
                self.mode = None
        if self.mode is None:
            self.mode = "lstsq"

    def solve(self, f, g):
        n_v = len(f)
        mode = self.mode
        if mode == "free":
            if self.owner._minv_diag is not None:  # constant diagonal M: cached inverse
                return self.owner._minv_diag * f, np.zeros(0)
            Md = self.M.toarray() if sp.issparse(self.M) else np.asarray(self.M)
            return np.linalg.solve(Md, f), np.zeros(0)
        Minv = self.owner._Minv
        if mode in ("chol", "lu", "splu"):
            x0 = self.owner._minv_diag * f if self.owner._minv_diag is not None else Minv @ f
            r = self.J @ x0 - g
            if mode == "chol":
                mu = sla.cho_solve(self.fac, r, check_finite=False)
            elif mode == "lu":
                mu = sla.lu_solve(self.fac, r, check_finite=False)
            else:
                mu = self.fac.solve(r)
            return x0 - self.MGt @ mu, mu
        if mode in ("kkt", "kkt-dense"):
            rhs = np.concatenate([f, g])
            sol = self.fac.solve(rhs) if mode == "kkt" else sla.lu_solve(self.fac, rhs, check_finite=False)
            res = self.K @ sol - rhs
            if np.all(np.isfinite(sol)) and np.linalg.norm(res) <= 1e-8 * (1.0 + np.linalg.norm(rhs)):
                return sol[:n_v], sol[n_v:]
        if self.G is self.J:
            return solve_kkt(self.M, self.J, f, g, minimum_norm=True)
        # non-symmetric saddle point with rank-deficient blocks: dense least squares
        Md = self.M.toarray() if sp.issparse(self.M) else np.asarray(self.M, float)
        Jd = self.J.toarray() if sp.issparse(self.J) else np.asarray(self.J, float)
        Gd = self.G.toarray() if sp.issparse(self.G) else np.asarray(self.G, float)
        K = np.block([[Md, Gd.T], [Jd, np.zeros((self.n_c, self.n_c))]])
        sol, *_ = sla.lstsq(K, np.concatenate([f, g]), cond=RANK_RCOND, lapack_driver="gelsd")
        return sol[:n_v], sol[n_v:]


def constraint_terms(system: ConstrainedSystem, t: float, q: Array, v: Array):
    """``(Φ, Φ_q, ν, γ)``; uses the system's one-pass evaluator when it has one."""
    f = getattr(system, "constraint_terms", None)
    if f is not None:
        return f(t, q, v)
    return system.Phi(t, q), system.Phi_q(t, q), system.nu(t, q), system.gamma(t, q, v)


def accelerations(system: ConstrainedSystem, t: float, q: Array, v: Array,
                  alpha: float = 0.0, beta: float = 0.0) -> tuple[Array, Array]:
    """Accelerations and multipliers of the index-1 equations (optionally Baumgarte-stabilised).

    Parameters
    ----------
    alpha, beta : float
        Baumgarte parameters [1/s]; γ is replaced by ``γ − 2α(Φ_q v − ν) − β²Φ``.

    Returns
    -------
    a : ndarray, shape (n_v,)
    lam : ndarray, shape (n_c,)
    """
    M = system.M(t, q)
    Q = system.Q(t, q, v)
    phi, J, nu, gam = constraint_terms(system, t, q, v)
    rhs = gam
    if alpha or beta:
        rhs = gam - 2.0 * alpha * (J @ v - nu) - beta * beta * phi
    return solve_kkt(M, J, Q, rhs, minimum_norm=keeps_redundant_rows(system))


def project_velocities(system: ConstrainedSystem, t: float, q: Array, v: Array, weighting: str = "mass",
                       solver: SaddleSolver | None = None, J=None) -> Array:
    """``v + Δv`` with ``Δv`` of least ``W``-norm such that ``Φ_q (v + Δv) = ν`` (see the module docstring).

    Parameters
    ----------
    weighting : {'mass', 'identity'}
        ``W = M`` (kinetic-energy norm, the M-orthogonal projection) or ``W = I``.
    solver : SaddleSolver, optional
        An integrator's solver with ``M⁻¹`` cached (mass weighting only); counts a factorisation.
    J : matrix, optional
        ``Φ_q(t, q)`` when the caller has it already.
    """
    if weighting not in ("mass", "identity"):
        raise ValueError(f"velocity weighting must be 'mass' or 'identity', got {weighting!r}")
    v = np.asarray(v, float)
    if system.n_c == 0:
        return v.copy()
    J = system.Phi_q(t, q) if J is None else J
    res = np.asarray(system.nu(t, q), float) - np.asarray(J @ v).ravel()
    if solver is not None and weighting == "mass":
        dv, _ = solver.solve(t, q, J, np.zeros(system.n_v), res)
        return v + dv
    W = None if weighting == "identity" else system.M(t, q)
    return v + minimum_norm_correction(J, res, W)


def project_positions(system: ConstrainedSystem, t: float, q: Array, tol: float, max_iter: int = 10,
                      solver: SaddleSolver | None = None) -> tuple[Array, int]:
    """Positions projected onto ``Φ(t, q) = 0`` by simplified Gauss–Newton (module docstring).

    Returns
    -------
    q : ndarray, shape (n_q,)
        Normalised (``system.normalize``).
    n_iter : int
        Iterations used; ``-1`` when ``‖Φ‖∞ ≤ tol`` was not reached in ``max_iter`` iterations
        (or the iteration diverged).
    """
    q = system.normalize(q)
    if system.n_c == 0:
        return q, 0
    phi = system.Phi(t, q)
    n_iter = 0
    if np.max(np.abs(phi)) > tol:
        solver = SaddleSolver(system, {"n_factor": 0}) if solver is None else solver
        fac = solver.factor(t, q, system.Phi_q(t, q))
        zero = np.zeros(system.n_v)
        prev = np.inf
        while True:
            dq, _ = fac.solve(zero, -phi)
            q = system.retract(q, dq)
            n_iter += 1
            phi = system.Phi(t, q)
            err = np.max(np.abs(phi))
            if err <= tol:
                break
            if n_iter >= max_iter or not np.isfinite(err) or err > 2.0 * prev:
                return q, -1
            prev = err
        q = system.normalize(q)
    return q, n_iter


def project(system: ConstrainedSystem, t: float, q: Array, v: Array, tol: float, max_iter: int = 10,
            solver: SaddleSolver | None = None) -> tuple[Array, Array, int]:
    """Coordinate projection of a state: :func:`project_positions`, then :func:`project_velocities`
    (M-weighted) at the projected positions.  Returns ``(q, v, n_iter)``, ``n_iter = -1`` when the
    positions did not converge (``v`` is then returned unchanged)."""
    q, n_iter = project_positions(system, t, q, tol, max_iter, solver)
    if n_iter < 0:
        return q, v, -1
    return q, project_velocities(system, t, q, v, "mass", solver), n_iter
