r"""Plain numpy + scipy baseline for the N-link whip chain: what a careful user writes without a library.

Rigid chain (index-1, dense KKT)
--------------------------------
Absolute planar coordinates of every link, ``q = (x_k, y_k, θ_k)_{k=1..N}``, ``v = q̇``;
mass matrix ``M = diag(m, m, J)`` per link (L = 1/N m, m = 1/N kg, J = m L²/12).
Joint k joins point ``s⁺ = (+L/2, 0)`` of link k−1 (the origin for k = 1) to point
``s⁻ = (−L/2, 0)`` of link k:

.. math::

    Φ_k = r_{k−1} + A_{k−1} s^+ − r_k − A_k s^− = 0, \qquad
    \frac{∂(A s)}{∂θ} = B s = A \begin{bmatrix} −s_y \\ s_x \end{bmatrix},

so ``Φ_q`` has blocks ``[I, B_{k−1}s⁺]`` and ``[−I, −B_k s⁻]``, and the acceleration right-hand
side is ``γ_k = A_{k−1}s⁺ θ̇_{k−1}² − A_k s⁻ θ̇_k²`` (Haug 1989, Sec. 6.1).  Every right-hand side
assembles the dense ``(5N)×(5N)`` KKT matrix

.. math::

    \begin{bmatrix} M & Φ_q^T \\ Φ_q & 0 \end{bmatrix}
    \begin{bmatrix} \dot v \\ λ \end{bmatrix} = \begin{bmatrix} Q \\ γ \end{bmatrix},
    \qquad Q = (0, −m g, 0)_k

and solves it with ``numpy.linalg.solve`` (LAPACK ``gesv``); the state ``(q, v)`` is integrated by
``scipy.integrate.solve_ivp(method="DOP853")`` with ``rtol = atol``: no stabilisation, no
projection (the constraints drift, which the tip error includes).  This is the "naive numpy +
scipy DOP853, index 1" column of ``core_benchmarks.md`` §1.

Stiff chain (penalty joints)
----------------------------
The same links with each joint replaced by a zero-length spring ``F = −k Φ_k`` acting on link k
and ``+k Φ_k`` on link k−1 (generalised forces ``−k Φ_qᵀ Φ``): ``M v̇ = Q − k Φ_qᵀ Φ``, an
unconstrained stiff ODE with diagonal M.  Its analytic Jacobian (for the implicit solvers) is

.. math::

    ∂\dot v/∂q = −M^{-1} k (Φ_q^T Φ_q + \sum_k Φ_k · ∂^2Φ_k/∂q^2), \qquad ∂\dot v/∂v = 0,

the second-derivative term being ``−A s`` on the diagonal θθ entries (``∂²(A s)/∂θ² = −A s``).
Used for the stiff reference (DOP853 / Radau at tight tolerance) and as the stiff baseline.

References
----------
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, Allyn & Bacon, 1989,
Ch. 6.  E. Hairer, G. Wanner, *Solving ODEs II*, 2nd ed., Springer 1996, Sec. VII.1 (index-1
formulation), Sec. IV.8 (Radau IIA).  SciPy ``solve_ivp`` (DOP853: Hairer, Nørsett, Wanner, *Solving
ODEs I*, Sec. II.10).
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp

G_EARTH = 9.81


class PlanarChain:
    """Cartesian planar N-link chain (rigid joints: index-1 KKT RHS; penalty joints: stiff ODE).

    Parameters
    ----------
    n : int
        Number of links N ≥ 1.
    stiff_k : float, optional
        Joint spring stiffness k [N/m]; None for ideal revolute joints.
    """

    def __init__(self, n: int, stiff_k: float | None = None, total_length: float = 1.0,
                 total_mass: float = 1.0, gravity: float = G_EARTH):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"PlanarChain: n must be an integer ≥ 1, got {n!r}")
        if stiff_k is not None and not stiff_k > 0:
            raise ValueError(f"PlanarChain: stiff_k must be > 0, got {stiff_k}")
        self.n = n
        self.k = stiff_k
        self.L = total_length / n
        self.m = total_mass / n
        self.J = self.m * self.L**2 / 12.0
        self.Mdiag = np.tile([self.m, self.m, self.J], n)
        self.Minv = 1.0 / self.Mdiag
        self.Q = np.tile([0.0, -self.m * gravity, 0.0], n)
        self.q0 = np.zeros(3 * n)
        self.q0[0::3] = (np.arange(n) + 0.5) * self.L
        self.v0 = np.zeros(3 * n)
        self.nfev = 0
        idx = np.arange(n)
        self._rows = 2 * idx  # x-row of joint k
        self._body = 3 * idx  # first coordinate of link k
        self._K = np.zeros((5 * n, 5 * n))
        self._K[:3 * n, :3 * n] = np.diag(self.Mdiag)
        # constant entries of Φ_q: +I for the previous link (k ≥ 1), −I for link k
        self._Jq = np.zeros((2 * n, 3 * n))
        for k in range(n):
            self._Jq[2 * k, 3 * k] = self._Jq[2 * k + 1, 3 * k + 1] = -1.0
            if k:
                self._Jq[2 * k, 3 * (k - 1)] = self._Jq[2 * k + 1, 3 * (k - 1) + 1] = 1.0

    # ---- kinematics (vectorised over joints) ------------------------------------------------
    def _points(self, q):
        th = q[2::3]
        c, s = np.cos(th), np.sin(th)
        h = 0.5 * self.L
        return th, c, s, h

    def Phi(self, q):
        """Joint position violations, shape (2N,)."""
        n = self.n
        _, c, s, h = self._points(q)
        r = q.reshape(n, 3)[:, :2]
        minus = r - h * np.stack([c, s], 1)  # joint point at the start of link k
        plus = r + h * np.stack([c, s], 1)  # end of link k
        prev = np.vstack([np.zeros((1, 2)), plus[:-1]])
        return (prev - minus).ravel()

    def Phi_q(self, q):
        """Dense constraint Jacobian, shape (2N, 3N)."""
        n = self.n
        _, c, s, h = self._points(q)
        Jq = self._Jq.copy()
        ks = np.arange(n)
        # −B_k s⁻ = −(h sinθ, −h cosθ) for link k (s⁻ = (−h, 0): B s⁻ = (h sinθ, −h cosθ))
        Jq[2 * ks, 3 * ks + 2] = -h * s
        Jq[2 * ks + 1, 3 * ks + 2] = h * c
        # B_{k−1} s⁺ = (−h sinθ, h cosθ) of the previous link
        kp = ks[1:]
        Jq[2 * kp, 3 * (kp - 1) + 2] = -h * s[:-1]
        Jq[2 * kp + 1, 3 * (kp - 1) + 2] = h * c[:-1]
        return Jq

    def gamma(self, q, v):
        """Acceleration right-hand side γ = A_{k−1}s⁺θ̇²_{k−1} − A_k s⁻θ̇²_k, shape (2N,)."""
        _, c, s, h = self._points(q)
        w2 = v[2::3] ** 2
        own = h * np.stack([c, s], 1) * w2[:, None]  # −A_k s⁻ θ̇² = +h e θ̇²
        prev = np.vstack([np.zeros((1, 2)), own[:-1]])  # A_{k−1}s⁺θ̇² = +h e θ̇²
        return (prev + own).ravel()

    def tip(self, q):
        """Free tip of link N [m], shape (2,)."""
        x, y, th = q[-3:]
        return np.array([x + 0.5 * self.L * np.cos(th), y + 0.5 * self.L * np.sin(th)])

    # ---- right-hand sides --------------------------------------------------------------------
    def rhs_kkt(self, t, y):
        """Index-1 RHS: dense KKT solve per call (``numpy.linalg.solve``)."""
        self.nfev += 1
        n3 = 3 * self.n
        q, v = y[:n3], y[n3:]
        Jq = self.Phi_q(q)
        K = self._K
        K[n3:, :n3] = Jq
        K[:n3, n3:] = Jq.T
        sol = np.linalg.solve(K, np.concatenate([self.Q, self.gamma(q, v)]))
        return np.concatenate([v, sol[:n3]])

    def rhs_penalty(self, t, y):
        """Penalty-joint RHS ``v̇ = M⁻¹(Q − k Φ_qᵀ Φ)``."""
        self.nfev += 1
        n3 = 3 * self.n
        q, v = y[:n3], y[n3:]
        f = self.Q - self.k * (self.Phi_q(q).T @ self.Phi(q))
        return np.concatenate([v, self.Minv * f])

    def jac_penalty(self, t, y):
        """Analytic Jacobian of :meth:`rhs_penalty`, sparse CSC (6N × 6N)."""
        n, n3 = self.n, 3 * self.n
        q = y[:n3]
        Jq = self.Phi_q(q)
        Phi = self.Phi(q)
        H = Jq.T @ Jq
        # Σ_k Φ_k · ∂²Φ_k/∂θ²: link k enters joint k with −A s⁻ (∂²/∂θ² → +A s⁻ = −h e) and joint
        # k+1 with A s⁺ (∂²/∂θ² → −A s⁺ = −h e)
        _, c, s, h = self._points(q)
        e = np.stack([c, s], 1)
        P = Phi.reshape(n, 2)
        d2 = -(h * e * P).sum(1)  # joint k, link k: ∂²(−A s⁻)/∂θ² = −h e, dotted with Φ_k
        nxt = np.zeros(n)
        nxt[:-1] = -(h * e[:-1] * P[1:]).sum(1)  # joint k+1, link k: ∂²(A s⁺)/∂θ² = −h e
        H[np.arange(n) * 3 + 2, np.arange(n) * 3 + 2] += d2 + nxt
        dvdq = -(self.k * self.Minv)[:, None] * H
        top = sp.hstack([sp.csr_matrix((n3, n3)), sp.identity(n3, format="csr")])
        bot = sp.hstack([sp.csr_matrix(dvdq), sp.csr_matrix((n3, n3))])
        return sp.vstack([top, bot]).tocsc()


def solve_chain(n: int, rtol: float, atol: float | None = None, method: str = "DOP853",
                stiff_k: float | None = None, t_end: float = 1.0, analytic_jac: bool = True):
    """One timed baseline solve.

    Returns
    -------
    tip : ndarray, shape (2,)
    wall_s : float
        Wall time of ``solve_ivp`` alone [s].
    info : dict
        ``status``, ``nfev``, ``message``, ``cpu_s`` (process CPU time of the solve [s]).
    """
    ch = PlanarChain(n, stiff_k)
    y0 = np.concatenate([ch.q0, ch.v0])
    atol = rtol if atol is None else atol
    if stiff_k is None:
        fun, kw = ch.rhs_kkt, {}
    else:
        fun = ch.rhs_penalty
        kw = {"jac": ch.jac_penalty} if (analytic_jac and method in ("Radau", "BDF")) else {}
    t0, c0 = time.perf_counter(), time.process_time()
    sol = solve_ivp(fun, (0.0, t_end), y0, method=method, rtol=rtol, atol=atol, t_eval=[t_end], **kw)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    q = sol.y[: 3 * n, -1] if sol.y.size else np.full(3 * n, np.nan)
    return ch.tip(q), wall, dict(status=int(sol.status), nfev=int(ch.nfev), message=str(sol.message), cpu_s=cpu)
