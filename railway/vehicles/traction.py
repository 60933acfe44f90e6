r"""Speed control along the track: the pull of a locomotive on a trailer car, as a force element.

A trailer car in a train runs at the speed the train imposes.  :class:`TrackSpeedControl` applies
a longitudinal force at the centre of mass of one body (the car body), along the track tangent
t(s) at the body's arc length s (foot of the perpendicular from the body's centre on the track
centreline), from a proportional speed controller:

.. math::

    F = k_v \,\bigl(V(t) - \dot r \cdot t(s)\bigr)\, t(s),

with V(t) the prescribed speed (a number or any :mod:`core.drivers` function of time, e.g. a
ramp for a speed run-down) and k_v [N s/m] the gain.  The steady speed error is F_res / k_v for a
running resistance F_res; the time constant of the speed is m_train / k_v.  The controller is
the simplest that keeps a coasting vehicle at its speed: it adds no state (a PI controller would
need an integral state, which core's second-order coordinates do not carry).  The force on the
body is reported (``outputs``: ``F [N]``) as the traction the train must supply.

Jacobians: ∂F/∂ṙ = −k_v t tᵀ exactly; the dependence of t on the position (through s and the
curvature, dt/ds = κ n) is included as ∂t/∂r ≈ κ n tᵀ / (1 − κ n·(r − g)) (exact for a plane
curve without cant change).

Search state: the arc length s of the body is found by Newton's method from its value at the
last accepted step (core's search-state rule, :mod:`core.forces.protocol`); the result is the
foot of the perpendicular to 1e-10 m whatever the start, so the force is a function of
(t, q, v).  An open track is not extrapolated: a body whose foot of the perpendicular lies beyond
its ends raises :class:`core.errors.DataRangeError` naming the end (the compiled kernel reports
the element as failed), which ends a run as failed with what was computed kept.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from core.compiled.protocol import ELEMENT_FAILED, OK, accept_kernel, force_kernel
from core.compiled.timefunctions import evaluate as tf_evaluate
from core.drivers import as_time_function
from core.errors import DataRangeError, ModelError, NumericalFailure
from core.forces.protocol import ForceElement, ForceEval, ForceJacobian, ForceKind, nonnegative

from .wheel_rail_compiled import _project

__all__ = ["TrackSpeedControl"]


@dataclass(frozen=True, eq=False)
class TrackSpeedControl(ForceElement):
    """Proportional speed control of ``body`` along ``track`` (module docstring).

    Parameters
    ----------
    name : str
    body : str
    track : railway.track.Track (or any core.curves.FramedCurve)
    speed : float, callable or core.drivers.TimeFunction
        Prescribed speed V(t) [m/s].
    gain : float
        k_v [N s/m], > 0.
    """

    name: str
    body: str
    track: Any
    speed: Any
    gain: float

    @classmethod
    def compile(cls, elements, ctx):
        return TrackSpeedControlKind(elements, ctx)


class TrackSpeedControlKind(ForceKind):
    """All :class:`TrackSpeedControl` elements of a model."""

    stateful = True

    def __init__(self, elements, ctx):
        if ctx.space.dim != 3:
            raise ModelError(f"track speed control {elements[0].name!r}: needs a spatial model")
        self.names = [e.name for e in elements]
        self.body_names = [e.body for e in elements]
        self.b = np.array([ctx.index(e.body, e.name) for e in elements], np.int64)
        self.tracks = [e.track for e in elements]
        self.V = [as_time_function(e.speed, f"speed of {e.name!r}") for e in elements]
        self.k = np.array([nonnegative(e.gain, "gain", e.name) for e in elements])
        if np.any(self.k <= 0):
            raise ModelError(f"track speed control {self.names[int(np.argmin(self.k))]!r}: gain must be > 0")
        self._s = None
        self._s = self._arc(ctx.bs0, None)

    def _arc(self, bs, guess):
        s = np.empty(len(self.names))
        for i, tr in enumerate(self.tracks):
            r = bs.r[self.b[i]][None, :]
            g = None if guess is None else guess[i:i + 1]
            if g is None:
                nodes = tr.frame_table.nodes
                pos = tr.evaluate_raw(nodes)[0]
                g = nodes[[int(np.argmin(np.linalg.norm(pos - r, axis=1)))]]
            try:
                s[i] = tr.project(r, g)[0]
            except NumericalFailure as exc:
                raise NumericalFailure(f"track speed control {self.names[i]!r}: {exc}") from None
            L = float(tr.length)
            if not getattr(tr, "closed", False) and not (0.0 <= s[i] <= L):
                end = ("off the start of the track at s = 0 m" if s[i] < 0.0
                       else f"past the end of the track at s = {L:g} m")
                raise DataRangeError(f"track speed control {self.names[i]!r}: body {self.body_names[i]!r} ran {end} "
                                     f"(s = {s[i]:.6g} m): the track is open and is not extrapolated; make it "
                                     "longer or the run shorter")
        return s

    def _terms(self, bs, t):
        s = self._arc(bs, self._s)
        out = []
        for i, tr in enumerate(self.tracks):
            pos, d1, d2 = (a[0] for a in tr.evaluate_raw(np.array([s[i]]))[:3])
            b = self.b[i]
            tang = d1 / np.linalg.norm(d1)
            V = self.V[i](t)[0]
            err = V - bs.rdot[b] @ tang
            out.append((b, tang, d2, pos, err))
        return out

    def evaluate(self, bs, t):
        Qb = np.zeros((len(self.names), 6))
        for i, (b, tang, _, _, err) in enumerate(self._terms(bs, t)):
            Qb[i, :3] = self.k[i] * err * tang
        return ForceEval(self.b.copy(), Qb)

    def jacobian(self, bs, t):
        Kq = np.zeros((len(self.names), 6, 6))
        Kv = np.zeros((len(self.names), 6, 6))
        for i, (b, tang, d2, pos, err) in enumerate(self._terms(bs, t)):
            k = self.k[i]
            Kv[i, :3, :3] = -k * np.outer(tang, tang)
            # dt/dr = (dt/ds)(ds/dr), dt/ds = r'' (unit-speed curve), ds/dr = t^T / (1 - r''.(r - g))
            denom = 1.0 - d2 @ (bs.r[b] - pos)
            dtdr = np.outer(d2, tang) / denom
            Kq[i, :3, :3] = k * (err * dtdr - np.outer(tang, bs.rdot[b] @ dtdr))
        return ForceJacobian(self.b.copy(), self.b.copy(), Kq, Kv)

    def outputs(self, bs, t):
        F = np.array([self.k[i] * err for i, (_, _, _, _, err) in enumerate(self._terms(bs, t))])
        return {"F [N]": F, "speed error [m/s]": F / self.k}

    def reset_state(self, bs, t):
        self._s = self._arc(bs, None)

    def accept_step(self, bs, t):
        self._s = self._arc(bs, self._s)

    def compiled(self, layout):
        """Compiled kernels (the same projection and force; search state = s of each element)."""
        from core.compiled.protocol import CompiledForces
        from core.compiled.timefunctions import encode_rows
        from core.errors import NotCompilable

        tables = {id(tr.pp_frame) for tr in self.tracks}
        if len(tables) != 1:
            raise NotCompilable(f"track speed control {self.names[0]!r}: several tracks in one model "
                                "are not supported on the compiled path")
        f = self.tracks[0].pp_frame
        progs = encode_rows(self.V, [f"speed of {n!r}" for n in self.names])
        n_in, n_br, (p0, p1, p2) = f._inner.size, f.breaks.size, f._stack.shape
        head = np.array([n_in, n_br, p0, p1, p2, self.tracks[0].length,
                         1.0 if getattr(self.tracks[0], "closed", False) else 0.0], float)
        table = np.concatenate([head, f._inner, f.breaks, f._stack.ravel()])
        fd = np.hstack([self.k[:, None], np.tile(table, (len(self.names), 1)), progs])
        ix = np.column_stack([self.b, np.full(len(self.names), 1 + table.size)]).astype(np.int64)

        def initial_state():
            return np.asarray(self._s, float)[:, None].copy()

        return CompiledForces(forces=_speed_control_forces, fd=np.ascontiguousarray(fd), ix=ix,
                              names=list(self.names), accept=_speed_control_accept,
                              state=np.asarray(self._s, float)[:, None].copy(), what="track speed control",
                              initial_state=initial_state, groups=[[int(b)] for b in self.b])


@numba.njit(cache=True)
def _table(fd, e):
    """The track frame table stored in row e of fd (see TrackSpeedControlKind.compiled)."""
    n_in, n_br = int(fd[e, 1]), int(fd[e, 2])
    p0, p1, p2 = int(fd[e, 3]), int(fd[e, 4]), int(fd[e, 5])
    o = 8
    inner = fd[e, o:o + n_in]
    o += n_in
    breaks = fd[e, o:o + n_br]
    o += n_br
    stack = fd[e, o:o + p0 * p1 * p2].reshape((p0, p1, p2))
    return inner, breaks, stack, fd[e, 6], fd[e, 7]


@force_kernel
def _speed_control_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    """F = k (V(t) - v . t) t at the body's centre (module docstring)."""
    o = np.empty(45)
    for e in range(ix.shape[0]):
        b = ix[e, 0]
        inner, breaks, stack, length, closed = _table(fd, e)
        s = _project(inner, breaks, stack, r[b], state[e, 0], length, closed, o)
        if not np.isfinite(s):
            err[1] = e
            return ELEMENT_FAILED
        tn = np.sqrt(o[15] ** 2 + o[16] ** 2 + o[17] ** 2)
        t0, t1, t2 = o[15] / tn, o[16] / tn, o[17] / tn
        st, V, _, _ = tf_evaluate(fd[e, ix[e, 1]:], t)
        if st != OK:
            err[1] = e
            return st
        F = fd[e, 0] * (V - (rd[b, 0] * t0 + rd[b, 1] * t1 + rd[b, 2] * t2))
        i0 = b * lay[3]
        Q[i0] += F * t0
        Q[i0 + 1] += F * t1
        Q[i0 + 2] += F * t2
    return OK


@accept_kernel
def _speed_control_accept(t, q, v, r, A, rd, w, lay, fd, ix, state, err):
    """The arc length of each controlled body at the accepted step."""
    o = np.empty(45)
    for e in range(ix.shape[0]):
        inner, breaks, stack, length, closed = _table(fd, e)
        s = _project(inner, breaks, stack, r[ix[e, 0]], state[e, 0], length, closed, o)
        if not np.isfinite(s):
            err[1] = e
            return ELEMENT_FAILED
        state[e, 0] = s
    return OK
