r"""Reference solutions of the work-precision problems, each independent of the code under test.

=========================================  ===================================================
function                                   reference of
=========================================  ===================================================
:func:`n_link_chain_reference`             the N-link whip chain (minimal coordinates, DOP853)
:func:`stiff_chain_rhs`                    the point-spring ("stiff") chain: an independent
                                           right-hand side of the penalty ODE
:func:`stiff_chain_tip_reference`          its tip at ``t_end`` (scipy DOP853, 1e−12)
:func:`pendulum_angle_exact`               the large-amplitude pendulum (closed form, IFToMM A01)
:func:`iftomm_a02_reference`               IFToMM A02, the N four-bar mechanism (equivalent
                                           pendulum in the bar angle, DOP853)
:func:`iftomm_a04_reference`               IFToMM A04, Bricard's mechanism (converged run of the
                                           same model, point P2 at t = 10 s)
=========================================  ===================================================

The models these references belong to are built in :mod:`core.models`; the published solutions
of Andrews' squeezer and the car axis are class attributes of :mod:`core.benchmarks.testset`.

References
----------
``core_benchmarks.md`` §1 (the N-link chain and its minimal-coordinate equations).
P. F. Byrd, M. D. Friedman, *Handbook of Elliptic Integrals for Engineers and Scientists*,
2nd ed., Springer, 1971, formula 121.00 (large-amplitude pendulum); D. F. Lawden, *Elliptic
Functions and Applications*, Springer, 1989, Sec. 5.2.
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody Syst. Dyn. 16 (2006)
179–190; IFToMM Library of Computational Benchmark Problems, problems A01, A02 and A04.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable

import numpy as np

G_EARTH = 9.81

__all__ = [
    "A04_REFERENCE_TOL",
    "A04_T_END",
    "G_EARTH",
    "iftomm_a02_reference",
    "iftomm_a04_p2",
    "iftomm_a04_reference",
    "iftomm_a04_system",
    "n_link_chain_reference",
    "pendulum_angle_exact",
    "stiff_chain_rhs",
    "stiff_chain_tip_reference",
]


# --------------------------------------------------------------------------------------------
# the N-link whip chain: rigid and with point springs for joints
# --------------------------------------------------------------------------------------------


def n_link_chain_reference(n: int, t_end: float = 1.0, t_eval=None, rtol: float = 1e-13, atol: float = 1e-13,
                           total_length: float = 1.0, total_mass: float = 1.0, gravity: float = G_EARTH):
    r"""Reference motion of the N-link chain in minimal coordinates (absolute link angles θ_k).

    Equations (``core_benchmarks.md`` §1; Lagrange's equations of the chain)::

        Σ_l B_kl cos(θ_k − θ_l) θ̈_l + Σ_l B_kl sin(θ_k − θ_l) θ̇_l² = −g cos θ_k Σ_i m a_ik
        a_ik = L (k < i), L/2 (k = i), 0 (k > i),     B_kl = Σ_i m a_ik a_il + J δ_kl

    integrated with scipy's DOP853 at ``rtol = atol = 1e−13``, from θ = 0, θ̇ = 0.  The tip is
    ``Σ_k L (cos θ_k, sin θ_k)``.

    Parameters
    ----------
    n : int
    t_end : float
        [s]
    t_eval : array_like, optional
        Output times [s] (default: 101 equally spaced).

    Returns
    -------
    tip : ndarray, shape (2,)
        Tip position (x, y) [m] at ``t_end``.
    history : pandas.DataFrame
        Columns ``t [s]``, ``theta_k [rad]``, ``omega_k [rad/s]`` (k = 1..N), ``tip x [m]``,
        ``tip y [m]``.

    Raises
    ------
    RuntimeError
        If DOP853 does not reach ``t_end``.
    """
    import pandas as pd
    from scipy.integrate import solve_ivp

    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n_link_chain_reference: n must be an integer ≥ 1, got {n!r}")
    L, m = total_length / n, total_mass / n
    J = m * L * L / 12.0
    idx = np.arange(n)
    a = np.where(idx[None, :] < idx[:, None], L, 0.0) + np.where(idx[None, :] == idx[:, None], L / 2, 0.0)  # a[i, k]
    B = m * a.T @ a + J * np.eye(n)
    grav = gravity * m * a.sum(0)  # g Σ_i m a_ik

    def rhs(t, y):
        th, om = y[:n], y[n:]
        D = th[:, None] - th[None, :]
        Mth = B * np.cos(D)
        f = -(B * np.sin(D)) @ (om * om) - grav * np.cos(th)
        return np.concatenate([om, np.linalg.solve(Mth, f)])

    t_eval = np.linspace(0.0, t_end, 101) if t_eval is None else np.asarray(t_eval, float)
    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(2 * n), method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval,
                    dense_output=True)
    if sol.status != 0:
        raise RuntimeError(f"n_link_chain_reference(n={n}): DOP853 failed: {sol.message}")
    yend = sol.sol(t_end)
    tip_end = L * np.array([np.cos(yend[:n]).sum(), np.sin(yend[:n]).sum()])
    th = sol.y[:n].T
    cols = {"t [s]": sol.t}
    for k in range(n):
        cols[f"theta_{k + 1} [rad]"] = th[:, k]
    for k in range(n):
        cols[f"omega_{k + 1} [rad/s]"] = sol.y[n + k]
    cols["tip x [m]"] = L * np.cos(th).sum(1)
    cols["tip y [m]"] = L * np.sin(th).sum(1)
    return tip_end, pd.DataFrame(cols)


def stiff_chain_rhs(n: int, stiff_k: float, total_length: float = 1.0, total_mass: float = 1.0,
                    gravity: float = G_EARTH) -> Callable[[float, np.ndarray], np.ndarray]:
    r"""Right-hand side of the planar point-spring chain, written independently of :mod:`core.model`.

    State ``y = (x_1..x_N, y_1..y_N, θ_1..θ_N, ẋ.., ẏ.., θ̇..)`` of N uniform links (``L = 1/N``,
    ``m = 1/N``, ``J = m L²/12``).  Joint j joins the tail ``p_j = r_j − (L/2) e_j`` of link j to
    the head ``h_{j−1} = r_{j−1} + (L/2) e_{j−1}`` of link j − 1 (the origin for j = 1) by a
    zero-length spring: ``d_j = p_j − h_{j−1}``, force ``−k d_j`` on link j at ``p_j`` and
    ``+k d_j`` on link j − 1 at ``h_{j−1}``; gravity ``−m g`` along y::

        m r̈_j = −k d_j + k d_{j+1} − m g ŷ
        J θ̈_j = (−(L/2) e_j) × (−k d_j) + ((L/2) e_j) × (k d_{j+1})

    (``d_{N+1} = 0``; × is the planar cross product).  Used by the stiff-chain reference so that
    it shares no code with the model under test.
    """
    L, m = total_length / n, total_mass / n
    J = m * L * L / 12.0
    k = float(stiff_k)

    def rhs(t, y):
        x, yy, th = y[:n], y[n:2 * n], y[2 * n:3 * n]
        c, s = np.cos(th), np.sin(th)
        px, py = x - 0.5 * L * c, yy - 0.5 * L * s  # tails
        hx, hy = x + 0.5 * L * c, yy + 0.5 * L * s  # heads
        dx = px - np.concatenate(([0.0], hx[:-1]))
        dy = py - np.concatenate(([0.0], hy[:-1]))
        fx_t, fy_t = -k * dx, -k * dy  # force on link j at its tail
        fx_h = np.concatenate((-fx_t[1:], [0.0]))  # force on link j at its head (reaction of joint j+1)
        fy_h = np.concatenate((-fy_t[1:], [0.0]))
        ax = (fx_t + fx_h) / m
        ay = (fy_t + fy_h) / m - gravity
        # torques: arm × F with arms −(L/2) e (tail) and +(L/2) e (head)
        tq = 0.5 * L * (-(c * fy_t - s * fx_t) + (c * fy_h - s * fx_h))
        return np.concatenate((y[3 * n:], ax, ay, tq / J))

    return rhs


def stiff_chain_tip_reference(n: int, stiff_k: float, t_end: float = 1.0, rtol: float = 1e-12) -> np.ndarray:
    r"""Tip [m] at ``t_end`` of the stiff (point-spring) chain by scipy DOP853, ``rtol = atol = 1e−12``.

    The stiff chain is an unconstrained ODE; it is integrated from the initial state of
    :func:`core.models.n_link_chain` (links along +x at rest, springs unstretched) with the
    independent right-hand side :func:`stiff_chain_rhs`.  The springs are undamped, so the
    reference resolves the high-frequency spring oscillations (amplitude O(m g / k)); the
    rigid-chain reference differs from it by O(m g / k) and is not used.
    """
    from scipy.integrate import solve_ivp

    L = 1.0 / n
    y0 = np.zeros(6 * n)
    y0[:n] = (np.arange(n) + 0.5) * L
    sol = solve_ivp(stiff_chain_rhs(n, stiff_k), (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=rtol)
    if sol.status != 0:
        raise RuntimeError(f"stiff chain reference (n={n}, k={stiff_k:g}) failed: {sol.message}")
    th = sol.y[2 * n:3 * n, -1]
    return np.array([sol.y[n - 1, -1] + 0.5 * L * np.cos(th[-1]), sol.y[2 * n - 1, -1] + 0.5 * L * np.sin(th[-1])])


# --------------------------------------------------------------------------------------------
# pendulum (IFToMM A01 geometry)
# --------------------------------------------------------------------------------------------


def pendulum_angle_exact(t, angle0: float = np.pi / 2, length: float = 1.0, gravity: float = G_EARTH):
    r"""Exact angle [rad] from the downward vertical of a pendulum released from rest at ``angle0``.

    .. math::

        \theta(t) = 2 \arcsin\!\big(k\, \mathrm{sn}(K(k) - \omega t,\ k)\big), \qquad
        k = \sin(\theta_0/2),\quad \omega = \sqrt{g/l},

    with ``K`` the complete elliptic integral of the first kind (scipy's parameter
    ``m = k²``).  At ``t = 0``, ``sn(K) = 1`` gives ``θ = θ0``; the period is ``4K/ω``.  The
    argument is reduced modulo the period ``4K`` of ``sn`` before :func:`scipy.special.ellipj`
    is called, so the accuracy does not degrade over long times.

    Parameters
    ----------
    t : float or array_like
        Time [s].
    angle0 : float
        Release angle θ0 [rad], ``0 < θ0 < π``.
    length, gravity : float
        l [m], g [m/s²].

    References
    ----------
    Byrd & Friedman (1971), formula 121.00; Lawden (1989), Sec. 5.2.
    """
    from scipy.special import ellipj, ellipk

    if not 0.0 < angle0 < np.pi:
        raise ValueError(f"pendulum_angle_exact: angle0 must be in (0, π), got {angle0}")
    k = np.sin(angle0 / 2.0)
    m = k * k
    K = ellipk(m)
    omega = np.sqrt(gravity / length)
    u = np.mod(K - omega * np.asarray(t, float), 4.0 * K)
    sn, _, _, _ = ellipj(u, m)
    return 2.0 * np.arcsin(k * sn)


# --------------------------------------------------------------------------------------------
# IFToMM A02: N four-bar mechanism
# --------------------------------------------------------------------------------------------


def iftomm_a02_reference(t_eval, n_windows: int = 40, link_length: float = 1.0, speed: float = 1.0,
                         angle0: float = np.pi / 2, gravity: float = G_EARTH, rtol: float = 1e-12,
                         atol: float = 1e-12):
    r"""Minimal-coordinate reference of :func:`core.models.iftomm_a02_four_bar_chain`: bar angle φ(t).

    Equal masses m cancel: ``[(N+1)/3 + N] L φ̈ = −g cos φ [(N+1)/2 + N]`` (see the model
    docstring), integrated with DOP853.  ``x(B_0) = L cos φ``, ``y(B_0) = L sin φ``.

    Returns
    -------
    phi, phidot : ndarray, shape (n_t,)
        [rad], [rad/s] at ``t_eval`` [s].
    """
    from scipy.integrate import solve_ivp

    from ..models import _a02_rate

    t_eval = np.asarray(t_eval, float)
    N, L = int(n_windows), float(link_length)
    c = gravity * ((N + 1) / 2 + N) / (L * ((N + 1) / 3 + N))
    w0 = _a02_rate(float(angle0), float(speed), L)
    sol = solve_ivp(lambda t, y: [y[1], -c * np.cos(y[0])], (0.0, float(t_eval[-1])), [float(angle0), w0],
                    method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval)
    if sol.status != 0:
        raise RuntimeError(f"iftomm_a02_reference: DOP853 failed: {sol.message}")
    return sol.y[0], sol.y[1]


# --------------------------------------------------------------------------------------------
# IFToMM A04: Bricard mechanism
# --------------------------------------------------------------------------------------------


#: End time [s] of IFToMM A04 and tolerance of its reference run.
A04_T_END = 10.0
A04_REFERENCE_TOL = 1e-12


def iftomm_a04_system():
    """Bricard's mechanism (:func:`core.models.iftomm_a04_bricard`) with its one dependent equation
    removed (named by ``build``): the system of the ``iftomm-a04`` problem and of its reference."""
    from ..models import iftomm_a04_bricard

    with warnings.catch_warnings():  # the redundancy warning is the expected, documented one
        warnings.simplefilter("ignore", UserWarning)
        return iftomm_a04_bricard(redundant="remove")


def iftomm_a04_p2(system, q) -> np.ndarray:
    """Global position [m] of P2 = (1, −1, 0) m at t = 0, the joint J3 end of rod2."""
    k = system.body_index("rod2")
    q0 = system.q0
    r0 = q0[7 * k:7 * k + 3]
    s = system.body_frame(q0, "rod2").T @ (np.array([1.0, -1.0, 0.0]) - r0)
    return system.point_position(q, "rod2", s)


def iftomm_a04_reference() -> np.ndarray:
    """P2 at t = 10 s by the compiled DOP853 with coordinate projection at rtol = atol = 1e-12.

    A converged solution of the same Cartesian model, as the IFToMM library's references are; it is
    cross-checked in ``tests/core/test_workprecision.py`` (slow) against scipy's DOP853 with
    projection driving the numpy right-hand side, and against energy conservation.
    """
    from ..integrators import simulate

    system = iftomm_a04_system()
    res = simulate(system, (0.0, A04_T_END), "jit-dop853-projection", t_eval=[A04_T_END], rtol=A04_REFERENCE_TOL,
                   atol=A04_REFERENCE_TOL, compute_multipliers=False)
    if not res.success:  # pragma: no cover - the reference run is deterministic
        raise RuntimeError(f"A04 reference run failed: {res.message}")
    return iftomm_a04_p2(system, res.q[-1])
