r"""Tier 1: the pendulum's constraint force against its closed form along a whole trajectory.

Mathematical pendulum (point mass m on a massless link of length l, pivot at the origin, gravity
−g e_y) written with the constraint ``Φ = ½(x² + y² − l²)`` as in Simeon's DAE lecture example:

.. math::

    m\ddot x = -x\lambda, \quad m\ddot y = -m g - y\lambda, \quad
    \lambda = \frac{m(\dot x^2 + \dot y^2) - m g y}{l^2}

(differentiate Φ twice and eliminate the accelerations).  The rod tension is ``T = λ l`` and the
force the joint exerts on the bob is ``F = −λ (x, y)``.  mbsuite's model uses a revolute joint
rather than this Φ, so its multipliers are scaled differently; the *reaction force* is
convention-free and is what we compare, at every output time, against the closed form evaluated
at the simulated state.  The tolerance follows from the requested rtol: the closed form is
evaluated from the same state, so the only error is the multiplier computation itself.
"""

import numpy as np
import pytest

from core import models
from core.integrators import simulate

G = models.G_EARTH


@pytest.mark.parametrize("method,kw", [
    ("radau-ggl", dict(rtol=1e-8, atol=1e-10)),
    ("dop853-projection", dict(rtol=1e-8, atol=1e-10)),
    ("generalized-alpha", dict(h=1e-3)),
])
def test_pendulum_reaction_equals_closed_form_multiplier(method, kw):
    m, l = 1.0, 1.0
    model = models.simple_pendulum(length=l, mass=m, angle0=np.pi / 2)  # IFToMM A01: horizontal start
    res = simulate(model, (0.0, 2.0), method, n_output=201, **kw)
    assert res.success, res.message
    x, y = res.q[:, 0], res.q[:, 1]
    vx, vy = res.v[:, 0], res.v[:, 1]
    lam = (m * (vx**2 + vy**2) - m * G * y) / l**2
    F_exact = -lam[:, None] * np.column_stack([x, y])
    (F,) = res.reactions.values()
    # scale: the largest tension, 3 m g at the bottom for a release from horizontal
    scale = 3 * m * G
    tol = 1e-6 * scale if method != "generalized-alpha" else 1e-3 * scale  # index-3 λ is O(h) accurate
    np.testing.assert_allclose(F[:, :2], F_exact, atol=tol)
    # and the closed form itself at the bottom: T = 3 m g for a release from horizontal at rest
    k = int(np.argmin(y))
    assert abs(np.hypot(*F[k, :2]) - (m * vx[k] ** 2 / l + m * vy[k] ** 2 / l + m * G * (-y[k] / l))) < tol


def test_a_point_mass_saddle_point_is_factored_dense_and_agrees_with_the_sparse_route(monkeypatch):
    """A point-mass bob has no rotational inertia: M has no inverse, so the saddle-point solver
    factors [[M, Φ_qᵀ], [Φ_q, 0]] whole.  Small ones are factored dense (core.dynamics._DENSE_KKT_MAX);
    the sparse LU is the independent computation: the same solution for any right-hand side, to
    round-off."""
    import core.dynamics as dyn

    system = models.simple_pendulum(length=1.0, mass=1.0, angle0=np.pi / 3, planar=True, bob="point")
    t, q = 0.0, system.q0
    J = system.Phi_q(t, q)
    rng = np.random.default_rng(3)
    f, g = rng.normal(size=system.n_v), rng.normal(size=J.shape[0])
    dense = dyn.SaddleSolver(system, {"n_factor": 0}).factor(t, q, J)
    assert dense.mode == "kkt-dense"
    monkeypatch.setattr(dyn, "_DENSE_KKT_MAX", 0)
    sparse = dyn.SaddleSolver(system, {"n_factor": 0}).factor(t, q, J)
    assert sparse.mode == "kkt"
    (xd, md), (xs, ms) = dense.solve(f, g), sparse.solve(f, g)
    np.testing.assert_allclose(xd, xs, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(md, ms, rtol=1e-12, atol=1e-12)


def test_a_singular_saddle_point_is_passed_on_without_a_warning():
    """[[M, Jᵀ], [J, 0]] singular (a coordinate with neither mass nor constraint): the dense LU's
    pivots refuse it quietly and the least-squares route answers (warnings are errors here)."""
    from types import SimpleNamespace

    import core.dynamics as dyn

    M = np.diag([1.0, 0.0])
    J = np.array([[1.0, 0.0]])
    owner = SimpleNamespace(_Minv=None, dense=True, minimum_norm=False, _minv_diag=None, mass=lambda t, q: M)
    fac = dyn._Factor(owner, 0.0, None, J, J, True)
    assert fac.mode != "kkt-dense"
    x, mu = fac.solve(np.array([2.0, 0.0]), np.array([0.5]))
    np.testing.assert_allclose(x[0], 0.5)
    np.testing.assert_allclose(mu, [1.5])
