"""Extension points that domain packages build on (:mod:`core.forces.protocol`, :mod:`core.errors`).

* A force element may act on an extra coordinate (a path parameter): checked against the closed
  form of a damped oscillator in that coordinate, on the numpy and the compiled path, and its
  Jacobian entries against finite differences.
* A force kind may keep a search state, updated through ``accept_step`` on accepted steps only:
  every integrator family calls the hook exactly once per accepted step, with the accepted state,
  and never changes the state inside a step, so evaluations at the same ``(t, q, v)`` inside a step
  (stages, Newton iterates, rejected attempts, dense output) give the same force.
* Integrators turn numerical failures into ``status == "failed"`` and let programming errors in a
  user's element propagate with their traceback.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from core.compiled import CompiledForces, force_jacobian_kernel, force_kernel
from core.compiled import protocol as P
from core.errors import MbsuiteError, ModelError
from core.forces import ForceElement, ForceEval, ForceJacobian, ForceKind
from core.integrators import simulate
from core.model import ModelBuilder

# --------------------------------------------------------------------------------------------
# a force on an extra coordinate
# --------------------------------------------------------------------------------------------


@force_kernel
def _coordinate_spring_kernel(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    for e in range(ix.shape[0]):
        qs, vs = ix[e, 0], ix[e, 1]
        Q[vs] += -fd[e, 0] * q[qs] - fd[e, 1] * v[vs]
    return P.OK


@force_jacobian_kernel
def _coordinate_spring_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    for e in range(ix.shape[0]):
        vs = ix[e, 1]
        K[vs, vs] -= fd[e, 0]
        D[vs, vs] -= fd[e, 1]
    return P.OK


@dataclass(frozen=True)
class CoordinateSpring(ForceElement):
    """``Q_s = −k s − c ṡ`` on an extra coordinate ``s`` (a force kind written outside core)."""

    name: str
    coordinate: str
    k: float
    c: float

    @classmethod
    def compile(cls, elements, ctx):
        return CoordinateSpringKind(elements, ctx)


class CoordinateSpringKind(ForceKind):
    def __init__(self, elements, ctx):
        self.names = [e.name for e in elements]
        self.idx = np.array([ctx.coordinate_index(e.coordinate, e.name) for e in elements], np.int64)
        self.vidx = np.array([ctx.velocity_index(e.coordinate, e.name) for e in elements], np.int64)
        self.kc = np.array([[e.k, e.c] for e in elements], float)
        self.n_q_bodies = ctx.n_bodies * ctx.space.n_q

    def evaluate(self, bs, t):
        Qx = -self.kc[:, 0] * bs.x[self.idx] - self.kc[:, 1] * bs.xdot[self.idx]
        return ForceEval(np.zeros(0, np.int64), np.zeros((0, 3)), self.idx, Qx)

    def jacobian(self, bs, t):
        e = np.zeros((0, 3, 3))
        return ForceJacobian(np.zeros(0, np.int64), np.zeros(0, np.int64), e, e,
                             entries=(self.vidx, self.vidx, -self.kc[:, 0], -self.kc[:, 1]))

    def compiled(self, layout):
        ix = np.column_stack([self.n_q_bodies + self.idx, self.vidx]).astype(np.int64)
        return CompiledForces(forces=_coordinate_spring_kernel, fd=self.kc, ix=ix, names=self.names,
                              jacobian=_coordinate_spring_jacobian, what="coordinate spring")


def _oscillator():
    b = ModelBuilder(2, "coordinate-oscillator")
    b.add_body("cart", 1.0, 0.1, (0.0, 0.0))  # a free body beside the coordinate
    b.add_coordinate("s", value=0.2, rate=0.0, mass=2.0)
    b.add_force(CoordinateSpring("spring", "s", k=50.0, c=1.0))
    return b.build()


@pytest.mark.parametrize("method", ["dop853", "radau-ggl", "jit-dop853"])
def test_force_on_an_extra_coordinate_follows_the_damped_oscillator(method):
    """m s̈ + c ṡ + k s = 0, s(0) = 0.2, ṡ(0) = 0: ``s = e^{−ζω t}(s0 cos ω_d t + s0 ζω/ω_d sin ω_d t)``."""
    model = _oscillator()
    m, k, c, s0 = 2.0, 50.0, 1.0, 0.2
    t = np.linspace(0.0, 2.0, 11)
    res = simulate(model, (0.0, 2.0), method, t_eval=t, rtol=1e-10, atol=1e-12)
    assert res.status == "finished", res.message
    wn = np.sqrt(k / m)
    zeta = c / (2 * np.sqrt(k * m))
    wd = wn * np.sqrt(1 - zeta**2)
    s_exact = np.exp(-zeta * wn * t) * (s0 * np.cos(wd * t) + s0 * zeta * wn / wd * np.sin(wd * t))
    assert np.max(np.abs(res.q[:, -1] - s_exact)) < 1e-7
    assert np.allclose(res.q[:, 1], -0.5 * 9.81 * t**2, atol=1e-7)  # the cart falls freely


def test_extra_coordinate_force_jacobian_against_finite_differences():
    model = _oscillator()
    q = model.q0.copy()
    q[-1] = 0.13
    v = np.zeros(model.n_v)
    v[-1] = -0.4
    Qq, Qv = model.Q_jacobians(0.0, q, v)
    h = 1e-6
    for j in range(model.n_v):
        dv = np.zeros(model.n_v)
        dv[j] = h
        fd_q = (model.Q(0.0, model.retract(q, dv), v) - model.Q(0.0, model.retract(q, -dv), v)) / (2 * h)
        fd_v = (model.Q(0.0, q, v + dv) - model.Q(0.0, q, v - dv)) / (2 * h)
        assert np.allclose(Qq.toarray()[:, j], fd_q, atol=1e-8)
        assert np.allclose(Qv.toarray()[:, j], fd_v, atol=1e-8)


def test_unknown_coordinate_is_named():
    b = ModelBuilder(2, "bad")
    b.add_body("cart", 1.0, 0.1, (0.0, 0.0))
    b.add_force(CoordinateSpring("spring", "path", 1.0, 0.0))
    with pytest.raises(ModelError, match="element 'spring' refers to unknown coordinate 'path'"):
        b.build()


# --------------------------------------------------------------------------------------------
# a force kind with a search state
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SeededSpring(ForceElement):
    """``F_x = −k x*`` with ``x*`` the root of ``g(x) = x + x³/3 − x_b`` (unique; ``x_b`` the body's
    x coordinate), found by Newton iterations started from a search state: the last accepted root.
    The force is a function of ``q`` alone; the state only seeds the search."""

    name: str
    body: str
    k: float

    @classmethod
    def compile(cls, elements, ctx):
        return SeededSpringKind(elements, ctx)


class SeededSpringKind(ForceKind):
    stateful = True

    def __init__(self, elements, ctx):
        self.names = [e.name for e in elements]
        self.b = ctx.index(elements[0].body, elements[0].name)
        self.k = elements[0].k
        self.seed = 0.0
        self.evaluations: list[tuple[float, float, float, float]] = []  # (t, x_b, seed, F)
        self.accepted: list[tuple[float, np.ndarray]] = []

    def _root(self, xb):
        x = self.seed
        for _ in range(60):
            x -= (x + x**3 / 3 - xb) / (1 + x * x)
        return x

    def evaluate(self, bs, t):
        xb = float(bs.r[self.b, 0])
        F = -self.k * self._root(xb)
        self.evaluations.append((float(t), xb, self.seed, F))
        Qb = np.zeros((1, bs.space.n_v))
        Qb[0, 0] = F
        return ForceEval(np.array([self.b]), Qb)

    def reset_state(self, bs, t):
        self.seed = 0.0
        self.evaluations.clear()
        self.accepted.clear()

    def accept_step(self, bs, t):
        xb = float(bs.r[self.b, 0])
        self.accepted.append((float(t), np.array([bs.r[self.b, 0], bs.r[self.b, 1]])))
        self.seed = self._root(xb)


@pytest.mark.parametrize("method,kw", [
    ("rk45", dict(rtol=1e-6, atol=1e-8)),
    ("radau", dict(rtol=1e-6, atol=1e-8)),
    ("radau-ggl", dict(rtol=1e-6, atol=1e-8)),
    ("generalized-alpha", dict(h=2e-3, rtol=1e-2, atol=1e-4)),  # the accuracy of h = 2e-3 here
    ("hem4", dict(h=2e-3)),
])
def test_search_state_hook_runs_on_accepted_steps_only(method, kw):
    b = ModelBuilder(2, "seeded")
    b.add_body("m", 1.0, 0.1, (1.5, 0.0), velocity=(0.0, 0.0))
    b.add_force(SeededSpring("spring", "m", 400.0))
    model = b.build()
    kind = model.force_kinds[0]
    res = simulate(model, (0.0, 0.5), method, n_output=26, **kw)
    assert res.status == "finished", res.message
    # one accept per accepted step, in time order, ending at t_end
    times = [t for t, _ in kind.accepted]
    assert len(times) == res.counters["n_steps"]
    assert np.all(np.diff(times) > 0) and times[-1] == pytest.approx(0.5)
    # the seed seen by every evaluation is the root of the last accepted state before it: it never
    # changes inside a step (stages, Newton iterates, rejected attempts)
    seeds = {round(s, 15) for _, _, s, _ in kind.evaluations}
    assert len(seeds) <= len(kind.accepted) + 1
    # the force is a function of (t, q, v): re-evaluated with another seed, every recorded value is
    # reproduced (the root is unique)
    for t, xb, _, F in kind.evaluations[:: max(1, len(kind.evaluations) // 50)]:
        kind.seed = 10.0
        assert -kind.k * kind._root(xb) == pytest.approx(F, rel=1e-12, abs=1e-12)


def test_model_reports_stateful_kinds():
    b = ModelBuilder(2, "seeded")
    b.add_body("m", 1.0, 0.1, (1.5, 0.0))
    b.add_force(SeededSpring("spring", "m", 400.0))
    assert b.build().stateful
    assert not _oscillator().stateful


# --------------------------------------------------------------------------------------------
# numerical failures end a run; programming errors propagate
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Faulty(ForceElement):
    """A force element that misbehaves after ``t_bad``: ``mode`` 'nan' (a numerical failure) or
    'bug' (raises the exception class ``exc``)."""

    name: str
    body: str
    t_bad: float
    mode: str
    exc: type = TypeError

    @classmethod
    def compile(cls, elements, ctx):
        return FaultyKind(elements, ctx)


class FaultyKind(ForceKind):
    def __init__(self, elements, ctx):
        e = elements[0]
        self.names = [e.name]
        self.b, self.t_bad, self.mode, self.exc = ctx.index(e.body, e.name), e.t_bad, e.mode, e.exc

    def evaluate(self, bs, t):
        Qb = np.zeros((1, bs.space.n_v))
        if t > self.t_bad:
            if self.mode == "nan":
                Qb[0, 0] = np.nan
            else:
                raise self.exc("a bug in a user element")
        return ForceEval(np.array([self.b]), Qb)


def _faulty_model(mode, exc=TypeError):
    b = ModelBuilder(2, "faulty")
    b.add_body("m", 1.0, 0.1, (1.0, 0.0))
    b.add_revolute("pin", "ground", "m", (0.0, 0.0))
    b.add_force(Faulty("faulty", "m", 0.05, mode, exc))
    return b.build()


METHODS_ALL = [("rk45", {}), ("rk45-projection", {}), ("radau", {}), ("radau-ggl", {}),
               ("generalized-alpha", dict(h=1e-3)), ("hem4", dict(h=1e-3))]


@pytest.mark.parametrize("method,kw", METHODS_ALL)
def test_non_finite_force_ends_the_run_as_failed(method, kw):
    res = simulate(_faulty_model("nan"), (0.0, 0.2), method, n_output=5, **kw)
    assert res.status == "failed"
    assert "t = " in res.message and res.t[-1] <= 0.06
    assert np.all(np.isfinite(res.q))  # what was computed is kept


@pytest.mark.parametrize("exc", [TypeError, IndexError, ValueError, KeyError, RuntimeError])
@pytest.mark.parametrize("method,kw", METHODS_ALL)
def test_programming_error_in_an_element_propagates(method, kw, exc):
    with pytest.raises(exc, match="a bug in a user element"):
        simulate(_faulty_model("bug", exc), (0.0, 0.2), method, n_output=5, **kw)


def test_every_bad_input_error_of_building_a_model_is_an_mbsuite_error():
    """``except MbsuiteError`` catches the errors of building a model (a sample of kinds)."""
    cases = []
    b = ModelBuilder(2, "m")
    cases.append(lambda: b.add_body("a", -1.0, 0.1, (0, 0)))
    cases.append(lambda: ModelBuilder(4))
    b2 = ModelBuilder(2, "m2")
    b2.add_body("a", 1.0, 0.1, (0, 0))
    b2.add_spring_damper("s", "a", "ghost", (0, 0), (1, 0), 1.0)
    cases.append(b2.build)
    b3 = ModelBuilder(2, "m3")
    b3.add_body("a", 1.0, 0.1, (0, 0))
    b3.add_point_spring("p", "ground", "a", (0, 0), stiffness=-5.0)
    cases.append(b3.build)
    b4 = ModelBuilder(2, "m4")
    b4.add_body("a", 1.0, 0.1, (0, 0))
    b4.add_plane_contact("c", "a", (0, 0), 0.1, (0, -1), (0, 1), restitution=2.0, stiffness=1.0)
    cases.append(b4.build)
    b5 = ModelBuilder(2, "m5")
    b5.add_body("a", 1.0, 0.1, (0, 0))
    b5.add_applied_force("f", "a", (0, 0), [1.0])
    cases.append(b5.build)
    for case in cases:
        with pytest.raises(MbsuiteError):
            case()
