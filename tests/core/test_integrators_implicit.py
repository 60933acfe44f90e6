"""Implicit integrators: index-3 generalized-α / HHT and Radau IIA on the GGL formulation.

References used for the expected values:
* compound pendulum (uniform rod, pivot at one end): ω0² = 3g/(2l) (equivalent length 2l/3),
  exact period T = 4 K(sin(θ0/2)) / ω0 (complete elliptic integral of the first kind);
* N-link chains: minimal-coordinate equations in the absolute link angles (see
  /work/shared/notes/core_benchmarks.md), integrated with DOP853 at rtol = atol = 1e-12.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from core.forces import ForceElement, ForceEval, ForceKind
from core.integrators import METHODS, simulate
from core.model import ModelBuilder

G = 9.81


# --------------------------------------------------------------------------------------------
# models and independent references
# --------------------------------------------------------------------------------------------
def chain_model(N: int, total_length=1.0, total_mass=1.0):
    """Planar N-link chain, horizontal along +x at rest, pinned at the origin."""
    L, m = total_length / N, total_mass / N
    J = m * L * L / 12
    b = ModelBuilder(2, f"chain{N}")
    prev = "ground"
    for k in range(N):
        b.add_body(f"l{k}", m, J, ((k + 0.5) * L, 0.0))
        b.add_revolute(f"j{k}", prev, f"l{k}", (k * L, 0.0))
        prev = f"l{k}"
    return b.build()


def chain_reference(N: int, t_end: float, total_length=1.0, total_mass=1.0, rtol=1e-12):
    """DOP853 solution of the minimal-coordinate chain equations (absolute angles θ_k)."""
    L, m = total_length / N, total_mass / N
    J = m * L * L / 12
    i = np.arange(N)[:, None]
    k = np.arange(N)[None, :]
    a = np.where(k < i, L, np.where(k == i, L / 2, 0.0))  # a[i, k]
    B = m * a.T @ a + J * np.eye(N)
    s = m * a.sum(0)

    def f(t, y):
        th, w = y[:N], y[N:]
        d = th[:, None] - th[None, :]
        rhs = -(B * np.sin(d)) @ (w**2) - G * np.cos(th) * s
        return np.concatenate([w, np.linalg.solve(B * np.cos(d), rhs)])

    return solve_ivp(f, (0.0, t_end), np.zeros(2 * N), method="DOP853", rtol=rtol, atol=rtol, dense_output=True)


def tip_from_q(q, N, total_length=1.0):
    """Free tip of the last link from the Cartesian coordinates, shape (..., 2)."""
    L = total_length / N
    x, y, th = q[..., 3 * (N - 1)], q[..., 3 * (N - 1) + 1], q[..., 3 * (N - 1) + 2]
    return np.stack([x + 0.5 * L * np.cos(th), y + 0.5 * L * np.sin(th)], -1)


def tip_from_angles(th, N, total_length=1.0):
    L = total_length / N
    return np.stack([L * np.cos(th).sum(0), L * np.sin(th).sum(0)], -1)


# --------------------------------------------------------------------------------------------
# a zero-free-length point spring (bushing) between coincident points: F = k (r_Q − r_P)
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PointSpring(ForceElement):
    """Linear translational bushing ``F_P = k (r_Q − r_P)``, ``F_Q = −F_P`` (zero free length).

    :class:`core.forces.SpringDamper` needs a direction ``d/|d|`` and refuses coincident points,
    so the penalty joint of the stiff chain is this isotropic spring.
    """

    name: str
    body_i: str
    body_j: str
    point: Any
    stiffness: float

    @classmethod
    def compile(cls, elements, ctx):
        return _PointSpringKind(elements, ctx)


class _PointSpringKind(ForceKind):
    conservative = True

    def __init__(self, elements, ctx):
        self.names = [e.name for e in elements]
        self.bi = np.array([ctx.index(e.body_i, e.name) for e in elements])
        self.bj = np.array([ctx.index(e.body_j, e.name) for e in elements])
        self.si = np.array([ctx.local_point(b, e.point) for b, e in zip(self.bi, elements)])
        self.sj = np.array([ctx.local_point(b, e.point) for b, e in zip(self.bj, elements)])
        self.k = np.array([e.stiffness for e in elements])

    def evaluate(self, bs, t):
        F = self.k[:, None] * (bs.point(self.bj, self.sj) - bs.point(self.bi, self.si))
        Ci, Cj = bs.C(self.bi, self.si), bs.C(self.bj, self.sj)
        Qi = np.concatenate([F, np.einsum("ndk,nd->nk", Ci, F)], 1)
        Qj = -np.concatenate([F, np.einsum("ndk,nd->nk", Cj, F)], 1)
        return ForceEval(np.concatenate([self.bi, self.bj]), np.concatenate([Qi, Qj]))

    def potential(self, bs):
        d = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        return float(0.5 * np.sum(self.k * np.sum(d * d, 1)))


def spring_chain_model(N: int, k: float):
    L, m = 1.0 / N, 1.0 / N
    b = ModelBuilder(2, f"spring-chain{N}")
    b.add_body("l0", m, m * L * L / 12, (0.5 * L, 0.0))
    b.add_revolute("j0", "ground", "l0", (0.0, 0.0))
    for i in range(1, N):
        b.add_body(f"l{i}", m, m * L * L / 12, ((i + 0.5) * L, 0.0))
        b.add_force(PointSpring(f"s{i}", f"l{i - 1}", f"l{i}", (i * L, 0.0), k))
    return b.build()


# --------------------------------------------------------------------------------------------
# tests
# --------------------------------------------------------------------------------------------
def test_registered():
    for name in ("generalized-alpha", "hht", "radau-ggl"):
        assert name in METHODS
    assert METHODS["radau-ggl"].provides_multipliers and METHODS["generalized-alpha"].provides_multipliers


def _compound_pendulum(theta0, l=1.0, m=1.0):
    b = ModelBuilder(2, "compound-pendulum")
    phi = theta0 - np.pi / 2  # body x axis along the rod, pointing away from the pivot
    b.add_body("rod", m, m * l * l / 12, (0.5 * l * np.cos(phi), 0.5 * l * np.sin(phi)), orientation=phi)
    b.add_revolute("pivot", "ground", "rod", (0.0, 0.0))
    return b.build()


def _period(t, ang):
    """Mean period from the downward zero crossings of the swing angle (linear interpolation)."""
    s = np.flatnonzero((ang[:-1] > 0) & (ang[1:] <= 0))
    tc = t[s] - ang[s] * (t[s + 1] - t[s]) / (ang[s + 1] - ang[s])
    return float(np.mean(np.diff(tc)))


@pytest.mark.parametrize("method,kw,tol_fn", [
    # second-order method: relative period error ~ (ω0 h)²; 10× margin. rtol states the accuracy
    # the step gives (the fixed-step error estimate checks it); Newton solves to min(rtol, 1e-8)
    ("generalized-alpha", dict(h=1e-3, rtol=1e-4, atol=1e-6), lambda w0: 10 * (w0 * 1e-3) ** 2),
    ("hht", dict(h=1e-3, rtol=1e-4, atol=1e-6), lambda w0: 10 * (w0 * 1e-3) ** 2),
    # error-controlled: relative period error well below 100 rtol
    ("radau-ggl", dict(rtol=1e-8, atol=1e-10), lambda w0: 1e-6),
])
def test_compound_pendulum_period(method, kw, tol_fn):
    l, theta0 = 1.0, 0.2
    w0 = np.sqrt(3 * G / (2 * l))
    T_exact = 4 * ellipk(np.sin(theta0 / 2) ** 2) / w0
    model = _compound_pendulum(theta0, l)
    t_end = 2.2 * T_exact
    t_eval = np.linspace(0, t_end, 4001)
    r = simulate(model, (0, t_end), method, t_eval=t_eval, compute_multipliers=False, **kw)
    assert r.status == "finished", r.message
    ang = r.q[:, 2] + np.pi / 2
    # dense-output sampling error of the crossing is O(dt²); the crossing times are at the fine grid
    T = _period(r.t, ang)
    assert abs(T - T_exact) / T_exact < tol_fn(w0) + (t_eval[1] ** 2) * w0**2, (T, T_exact)


def test_generalized_alpha_second_order():
    N, t_end = 2, 0.5
    model = chain_model(N)
    ref = chain_reference(N, t_end)
    tip_ref = tip_from_angles(ref.y[:N, -1], N)
    hs = np.array([4e-3, 2e-3, 1e-3, 5e-4])
    errs = []
    for h in hs:
        # rtol: the accuracy of the coarsest step; the Newton iteration solves to 1e-11 so that its
        # error stays below the discretisation error of the finest
        r = simulate(model, (0, t_end), "generalized-alpha", h=h, rtol=1e-3, atol=1e-5, newton_tol=1e-11,
                     n_output=2, compute_multipliers=False)
        assert r.status == "finished", r.message
        errs.append(np.linalg.norm(tip_from_q(r.q[-1], N) - tip_ref))
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - 2.0) < 0.3, (slope, errs)


def test_radau_ggl_meets_tolerance_and_holds_both_constraint_levels():
    N, t_end, rtol = 2, 10.0, 1e-6
    model = chain_model(N)
    ref = chain_reference(N, t_end)
    t_eval = np.linspace(0, t_end, 101)
    r = simulate(model, (0, t_end), "radau-ggl", rtol=rtol, atol=1e-2 * rtol, t_eval=t_eval)
    assert r.status == "finished", r.message
    err = np.linalg.norm(tip_from_q(r.q, N) - tip_from_angles(ref.sol(t_eval)[:N], N), axis=1)
    # the double pendulum released horizontally is chaotic: any error (also the reference's) grows
    # exponentially after a few swings, so the accuracy is checked over the first 2 s
    # (global error ≤ 10·rtol·t for a tolerance-proportional method); the constraints over 10 s
    early = t_eval <= 2.0
    assert np.all(err[early] < 10 * rtol * np.maximum(t_eval[early], 0.1)), err[early].max()
    # GGL holds Φ = 0 and Φ_q v = ν (dense-output samples, order-3 interpolant between steps)
    assert r.position_violation.max() < 10 * rtol
    assert r.velocity_violation.max() < 100 * rtol
    assert np.all(np.isfinite(r.lam[1:]))


def test_radau_ggl_multipliers_match_index1():
    model = chain_model(2)
    r = simulate(model, (0, 0.3), "radau-ggl", rtol=1e-8, atol=1e-10, t_eval=[0.0, 0.3])
    from core.dynamics import accelerations

    _, lam = accelerations(model, 0.3, r.q[-1], r.v[-1])
    assert np.allclose(r.lam[-1], lam, rtol=1e-4, atol=1e-6 * np.abs(lam).max())


def test_stiff_point_spring_chain_matches_revolute_chain():
    N, k, h, t_end = 4, 1e6, 1e-3, 0.5
    stiff = spring_chain_model(N, k)
    rigid = chain_model(N)
    t_eval = np.linspace(0, t_end, 51)
    # rtol: the accuracy h = 1e-3 gives on this chain (Newton solves to 1e-8 regardless)
    acc = dict(rtol=1e-2, atol=1e-4, newton_tol=1e-8)
    rs = simulate(stiff, (0, t_end), "generalized-alpha", h=h, t_eval=t_eval, compute_multipliers=False, **acc)
    assert rs.status == "finished", rs.message
    rr = simulate(rigid, (0, t_end), "generalized-alpha", h=h, t_eval=t_eval, **acc)
    assert rr.status == "finished", rr.message
    # penalty joints stretch by |λ|/k each: the tip deviation is O(N max|λ| / k)
    lam_max = np.nanmax(np.abs(rr.lam))
    dev = np.linalg.norm(tip_from_q(rs.q, N) - tip_from_q(rr.q, N), axis=1).max()
    assert dev < 10 * N * lam_max / k + 1e-6, (dev, lam_max)


@pytest.mark.parametrize("method", ["generalized-alpha", "hht"])
def test_velocity_projection_holds_velocity_constraints(method):
    model = chain_model(3)
    acc = dict(rtol=1e-2, atol=1e-4, newton_tol=1e-8)  # the accuracy of h = 2e-3 on this chain
    r0 = simulate(model, (0, 0.5), method, h=2e-3, n_output=11, compute_multipliers=False,
                  velocity_projection=False, **acc)
    r1 = simulate(model, (0, 0.5), method, h=2e-3, n_output=11, compute_multipliers=False, **acc)
    assert r0.status == r1.status == "finished"
    assert r1.velocity_violation[-1] < 1e-9
    assert r0.velocity_violation.max() > r1.velocity_violation[-1]


def test_whip_chain_fails_or_is_right():
    """N = 32 whip at h = 1e-2, fixed step: never 'finished' (without warning) with a wrong answer."""
    N = 32
    model = chain_model(N)
    r = simulate(model, (0, 1.0), "generalized-alpha", h=1e-2, adaptive=False, n_output=2,
                 compute_multipliers=False, rtol=1e-2, atol=1e-4)
    if r.status == "finished with warnings":
        assert "estimated global error" in r.message or "energy drift" in r.message
    elif r.status == "finished":
        ref = chain_reference(N, 1.0, rtol=1e-11)
        err = np.linalg.norm(tip_from_q(r.q[-1], N) - tip_from_angles(ref.y[:N, -1], N))
        assert err < 1e-2, err
    else:
        assert r.status == "failed"
        assert "t = " in r.message and "residual" in r.message or "Newton" in r.message


def test_adaptive_generalized_alpha_recovers():
    N = 8
    model = chain_model(N)
    r = simulate(model, (0, 1.0), "generalized-alpha", h=1e-2, adaptive=True, rtol=1e-4, atol=1e-6,
                 n_output=2, compute_multipliers=False)
    # ρ∞ = 0.9 damps the whip's fast modes: the energy check flags the dissipation (1.2 % of the
    # peak kinetic energy), the tip is still right
    assert r.status == "finished with warnings" and "energy drift" in r.message, r.message
    ref = chain_reference(N, 1.0, rtol=1e-11)
    err = np.linalg.norm(tip_from_q(r.q[-1], N) - tip_from_angles(ref.y[:N, -1], N))
    assert err < 1e-2, err


# --------------------------------------------------------------------------------------------
# published DAE test problems (Mazzia & Magherini test set; Hairer & Wanner II, Sec. VII.7)
# --------------------------------------------------------------------------------------------
def _rel_err(x, ref):
    return np.linalg.norm(x - ref) / np.linalg.norm(ref)


def test_radau_ggl_andrews_configuration_dependent_mass():
    """Andrews' squeezer has M = M(q): the collocation must use M at the stages.

    With M frozen at the step start the method is first order in M's variation (error ~5e-3
    at rtol 1e-6); done right the global error follows the tolerance.
    """
    from core.benchmarks.testset import AndrewsSqueezer

    P = AndrewsSqueezer()
    ref = P.reference
    rtol = 1e-6
    r = simulate(P, (0.0, ref["t"]), "radau-ggl", rtol=rtol, atol=1e-2 * rtol, n_output=2)
    assert r.status == "finished", r.message
    assert _rel_err(r.q[-1], ref["q"]) < rtol
    assert _rel_err(r.v[-1], ref["v"]) < 10 * rtol
    assert r.counters["n_rejected"] < 0.2 * r.counters["n_steps"], r.counters


@pytest.mark.slow
def test_radau_ggl_andrews_tight_tolerance():
    """rtol = 1e-10: used to stop with 'step size too small' (Newton stuck at the rounding level).

    The published reference (PSIDE, 1e-14) agrees with an index-1 DOP853 solution at
    rtol = 3e-14 to 8e-11 relative; 1e-8 leaves room for that and the method's own error.
    """
    from core.benchmarks.testset import AndrewsSqueezer

    P = AndrewsSqueezer()
    ref = P.reference
    r = simulate(P, (0.0, ref["t"]), "radau-ggl", rtol=1e-10, atol=1e-12, n_output=2)
    assert r.status == "finished", r.message
    assert _rel_err(r.q[-1], ref["q"]) < 1e-8
    assert _rel_err(r.v[-1], ref["v"]) < 1e-7
    assert _rel_err(r.lam[-1], ref["lam"]) < 1e-5  # index-2 components: order 3
    assert r.counters["n_rejected"] < 0.05 * r.counters["n_steps"], r.counters


@pytest.mark.parametrize("rtol", [1e-6, pytest.param(1e-9, marks=pytest.mark.slow)])
def test_radau_ggl_car_axis_reference(rtol):
    """Index-3 car axis with the moving road point (ν = ν(t, q)), published reference at t = 3."""
    from core.benchmarks.testset import CarAxis

    P = CarAxis()
    ref = P.reference
    r = simulate(P, (0.0, ref["t"]), "radau-ggl", rtol=rtol, atol=1e-2 * rtol, n_output=2)
    assert r.status == "finished", r.message
    assert _rel_err(r.q[-1], ref["q"]) < 10 * rtol
    assert _rel_err(r.v[-1], ref["v"]) < 100 * rtol
    assert r.counters["n_rejected"] < 0.2 * r.counters["n_steps"], r.counters
