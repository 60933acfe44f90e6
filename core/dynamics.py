r"""Forward-dynamics kernels shared by integrators and analyses.

Index-1 (acceleration-level) equations with optional Baumgarte stabilisation
(Baumgarte 1972, Eq. 10; Nikravesh 1988, Eq. 13.22):

.. math::

    \begin{bmatrix} M & \Phi_q^T \\ \Phi_q & 0 \end{bmatrix}
    \begin{bmatrix} \dot v \\ \lambda \end{bmatrix} =
    \begin{bmatrix} Q \\ \gamma - 2\alpha(\Phi_q v - \nu) - \beta^2 \Phi \end{bmatrix}

The KKT matrix is factorised with SuperLU (:func:`scipy.sparse.linalg.splu`).  When Φ_q is
rank deficient (redundant constraints kept in the model) the factorisation fails or is
ill-conditioned and :func:`solve_kkt` falls back to the minimum-norm solution: the acceleration is
unique, and λ is the minimum-norm multiplier vector (pseudo-inverse of Φ_qᵀ on the residual).

References
----------
J. Baumgarte, "Stabilization of constraints and integrals of motion in dynamical systems",
Comput. Methods Appl. Mech. Eng. 1 (1972) 1–16.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from .system import ConstrainedSystem

Array = NDArray[np.float64]


def kkt_matrix(M, J) -> sp.csc_matrix:
    """Sparse ``[[M, Jᵀ], [J, 0]]``."""
    M = sp.csr_matrix(M)
    J = sp.csr_matrix(J)
    return sp.bmat([[M, J.T], [J, None]], format="csc")


class SingularKKTError(np.linalg.LinAlgError):
    """The KKT matrix is singular beyond what redundancy of Φ_q explains (e.g. M singular)."""


def solve_kkt(M, J, top: Array, bottom: Array, minimum_norm: bool = False) -> tuple[Array, Array]:
    """Solve ``[[M, Jᵀ], [J, 0]] [x; λ] = [top; bottom]``.

    Parameters
    ----------
    M : (n_v, n_v) dense or sparse
    J : (n_c, n_v) dense or sparse
    top : ndarray, shape (n_v,)
    bottom : ndarray, shape (n_c,)
    minimum_norm : bool
        Use the dense minimum-norm least-squares route directly (redundant constraints).

    Returns
    -------
    x : ndarray, shape (n_v,)
    lam : ndarray, shape (n_c,)
    """
    n_v = len(top)
    n_c = len(bottom)
    rhs = np.concatenate([top, bottom])
    if n_c == 0:
        Md = M.toarray() if sp.issparse(M) else np.asarray(M)
        return np.linalg.solve(Md, top), np.zeros(0)
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
    Kd = np.block([[_dense(M), _dense(J).T], [_dense(J), np.zeros((n_c, n_c))]])
    if not (np.all(np.isfinite(Kd)) and np.all(np.isfinite(rhs))):
        raise SingularKKTError("KKT system has non-finite entries (the state or the forces diverged)")
    # relative rank cutoff: with the default (machine epsilon) an exact null direction of a
    # redundant Φ_q with singular value ~1e-15·σmax is counted as rank, and λ then carries a
    # component in null(Φ_qᵀ) -- it is no longer the minimum-norm multiplier
    sol, *_ = sla.lstsq(Kd, rhs, cond=1e-12, lapack_driver="gelsd")
    res = Kd @ sol - rhs
    if minimum_norm:
        # redundant equations kept: γ is consistent only up to the drift of the state off the
        # constraint manifold; the least-squares (minimum-norm) solution is the defined answer
        if not np.all(np.isfinite(sol)):
            raise SingularKKTError("minimum-norm KKT solution is not finite")
        return sol[:n_v], sol[n_v:]
    if not np.all(np.isfinite(sol)) or np.linalg.norm(res) > 1e-6 * (1.0 + np.linalg.norm(rhs)):
        raise SingularKKTError(
            f"KKT system singular and inconsistent (residual {np.linalg.norm(res):.3e}); "
            "check for massless bodies without constraints or a singular configuration"
        )
    return sol[:n_v], sol[n_v:]


def _dense(A):
    return A.toarray() if sp.issparse(A) else np.asarray(A, float)


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
    return solve_kkt(M, J, Q, rhs, minimum_norm=bool(len(getattr(system, "redundant_rows", ())) and getattr(system, "_active_rows", None) is None))
