r"""Applied loads: forces and torques given as functions of time (action only, no reaction body).

Each component is a number, a callable ``f(t)``, a ``(times, values)`` table (C² cubic spline)
or a :class:`core.drivers.TimeFunction`.  Forces and torques in global axes or body axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..drivers import as_time_function
from ..errors import ModelError
from .coordinates import point_jacobian
from .protocol import ForceElement, ForceEval, ForceJacobian, ForceKind

Array = NDArray[np.float64]

__all__ = ["AppliedForce", "AppliedForceKind", "AppliedTorque", "AppliedTorqueKind"]


def _time_components(values, n: int, element: str, what: str):
    """Split ``n`` components into constants (array) and time functions (list of (k, TimeFunction))."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__") or len(values) != n:
        raise ModelError(f"{element!r}: {what} must be a sequence of {n} components (each a number, a callable "
                         f"f(t), a (times, values) table or a TimeFunction), got {values!r}")
    comps = list(values)
    const = np.zeros(n)
    funcs = []
    for k, c in enumerate(comps):
        if isinstance(c, (int, float, np.floating, np.integer)):
            if not np.isfinite(c):
                raise ModelError(f"{element!r}: {what} component {k} is not finite ({c})")
            const[k] = float(c)
        else:
            funcs.append((k, as_time_function(c, f"{what} component {k} of {element!r}")))
    return const, funcs


def _eval_components(const: Array, funcs: list, t: float) -> Array:
    out = const.copy()
    for k, fn in funcs:
        out[k] = fn(t)[0]
    return out


def _eval_components_frames(const: Array, funcs: list, t: Array) -> Array:
    """The components at many times, shape (n_f, n): each time function evaluated on the array."""
    out = np.repeat(const[None, :], len(t), axis=0)
    for k, fn in funcs:
        out[:, k] = fn.values(t)
    return out



# --------------------------------------------------------------------------------------------
# applied loads
# --------------------------------------------------------------------------------------------


def _check_frame(frame: str, element: str) -> None:
    if frame not in ("global", "body"):
        raise ModelError(f"{element!r}: frame must be 'global' or 'body', got {frame!r}")


@dataclass(frozen=True)
class AppliedForce(ForceElement):
    r"""Force of time applied at a body point (action only; no reaction body).

    .. math::

        F(t) = F_g(t) \;(\text{frame='global'}) \quad\text{or}\quad F(t) = A \bar F(t)
        \;(\text{frame='body'}),\qquad Q = J_P^T F = [F;\ C(\bar s)^T F]

    (Nikravesh 1988, Eq. 6.178).  Each of the d components is a number, a callable f(t), a
    ``(times, values)`` table (cubic spline) or a :class:`core.drivers.TimeFunction`.
    Exact Jacobian: global force ``∂Q/∂θ = ∂(C(s̄)ᵀF)/∂θ``; body-fixed force
    ``∂F/∂θ = C(F̄)`` with a constant moment ``C(s̄)ᵀ A F̄``.

    Parameters
    ----------
    body : str
    point : array_like, shape (d,)
        Global point of application at build [m].
    force : sequence of d components
        [N].
    frame : {'global', 'body'}
    """

    name: str
    body: str
    point: Any
    force: Any
    frame: str = "global"

    @classmethod
    def compile(cls, elements, ctx):
        return AppliedForceKind(elements, ctx)


class AppliedForceKind(ForceKind):
    """All :class:`AppliedForce` elements of a model."""

    conservative = False

    def __init__(self, elements: list[AppliedForce], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        b, s, const, funcs, body_frame = [], [], [], [], []
        for e in elements:
            k = ctx.index(e.body, e.name)
            if k == len(ctx.bs0.r) - 1:
                raise ModelError(f"applied force {e.name!r}: cannot act on the ground")
            _check_frame(e.frame, e.name)
            p = np.asarray(e.point, float)
            if p.shape != (d,) or not np.all(np.isfinite(p)):
                raise ModelError(f"applied force {e.name!r}: point must be {d} finite numbers")
            c, f = _time_components(e.force, d, e.name, "force")
            b.append(k)
            s.append(ctx.local_point(k, p))
            const.append(c)
            funcs.append(f)
            body_frame.append(e.frame == "body")
        self.b = np.array(b, np.int64)
        self.s = np.array(s)
        self.const = np.array(const)
        self.funcs = funcs
        self.body_frame = np.array(body_frame)

    def _F(self, bs, t):
        Fc = np.array([_eval_components(c, f, t) for c, f in zip(self.const, self.funcs)])
        Fg = Fc.copy()
        if np.any(self.body_frame):
            bf = self.body_frame
            Fg[bf] = bs.vector(self.b[bf], Fc[bf])
        return Fc, Fg

    def evaluate(self, bs, t):
        _, F = self._F(bs, t)
        return ForceEval(self.b, np.einsum("ndk,nd->nk", point_jacobian(bs, self.b, self.s), F))

    def evaluate_frames(self, bsf, t):
        """:meth:`evaluate` at the frames of ``bsf`` (:meth:`core.bodies.BodyStates.from_frames`),
        times ``t`` (n_f,): ``Qb`` (n_f, n, n_v) = J_Pᵀ F per frame."""
        nf, n, d = len(t), len(self.b), bsf.space.dim
        Fc = np.stack([_eval_components_frames(c, f, t) for c, f in zip(self.const, self.funcs)], axis=1)
        A = bsf.A[:, self.b]  # (n_f, n, d, d)
        F = np.where(self.body_frame[None, :, None], np.einsum("fnij,fnj->fni", A, Fc), Fc)
        C = bsf.space.C(A.reshape(-1, d, d), np.broadcast_to(self.s, (nf, n, d)).reshape(-1, d))
        Qb = np.concatenate([F, np.einsum("mdk,md->mk", C, F.reshape(-1, d)).reshape(nf, n, -1)], axis=2)
        return ForceEval(self.b, Qb)

    def jacobian(self, bs, t):
        Fc, Fg = self._F(bs, t)
        d, nv = bs.space.dim, bs.space.n_v
        n = len(self.b)
        Kq = np.zeros((n, nv, nv))
        g = ~self.body_frame
        if np.any(g):
            Kq[g, d:, d:] = bs.space.Cdot_T_force(bs.A[self.b[g]], self.s[g], Fg[g])
        if np.any(self.body_frame):
            bf = self.body_frame
            Kq[bf, :d, d:] = bs.C(self.b[bf], Fc[bf])
        return ForceJacobian(self.b, self.b, Kq, np.zeros((n, nv, nv)))

    def outputs(self, bs, t):
        _, F = self._F(bs, t)
        return {f"F{a} [N]": F[:, k] for k, a in enumerate("xyz"[: bs.space.dim])}

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_applied_forces`)."""
        from ..compiled.elements import compile_applied_forces

        return compile_applied_forces(self, layout)


@dataclass(frozen=True)
class AppliedTorque(ForceElement):
    r"""Torque of time applied to a body (action only).

    Planar: a scalar torque ``T(t)``, ``Q_θ = T``.  Spatial: a torque vector ``T_g(t)`` in
    global axes (frame='global') giving the body-frame moment ``Q_ω = Aᵀ T_g`` with the exact
    Jacobian ``∂(AᵀT_g)/∂θ = (AᵀT_g)~``, or ``T̄(t)`` in body axes (frame='body'),
    ``Q_ω = T̄`` (Nikravesh 1988, Sec. 6.6).  Components as for :class:`AppliedForce`.

    Parameters
    ----------
    body : str
    torque : number/function (planar) or sequence of 3 components (spatial)
        [N m].
    frame : {'global', 'body'}
    """

    name: str
    body: str
    torque: Any
    frame: str = "global"

    @classmethod
    def compile(cls, elements, ctx):
        return AppliedTorqueKind(elements, ctx)


class AppliedTorqueKind(ForceKind):
    """All :class:`AppliedTorque` elements of a model."""

    conservative = False

    def __init__(self, elements: list[AppliedTorque], ctx):
        nr = ctx.space.n_v - ctx.space.dim
        self.names = [e.name for e in elements]
        b, const, funcs, body_frame = [], [], [], []
        for e in elements:
            k = ctx.index(e.body, e.name)
            if k == len(ctx.bs0.r) - 1:
                raise ModelError(f"applied torque {e.name!r}: cannot act on the ground")
            _check_frame(e.frame, e.name)
            tq = e.torque
            if nr == 1 and not (isinstance(tq, (list, np.ndarray)) and np.ndim(tq) == 1 and len(tq) == 1):
                tq = [tq]
            c, f = _time_components(tq, nr, e.name, "torque")
            b.append(k)
            const.append(c)
            funcs.append(f)
            body_frame.append(e.frame == "body")
        self.b = np.array(b, np.int64)
        self.const = np.array(const)
        self.funcs = funcs
        self.body_frame = np.array(body_frame)

    def _torques(self, bs, t):
        Tc = np.array([_eval_components(c, f, t) for c, f in zip(self.const, self.funcs)])
        Tb = Tc.copy()
        if bs.space.dim == 3:
            g = ~self.body_frame
            Tb[g] = np.einsum("nji,nj->ni", bs.A[self.b[g]], Tc[g])
        return Tc, Tb

    def evaluate(self, bs, t):
        d, nv = bs.space.dim, bs.space.n_v
        _, Tb = self._torques(bs, t)
        Q = np.zeros((len(self.b), nv))
        Q[:, d:] = Tb
        return ForceEval(self.b, Q)

    def evaluate_frames(self, bsf, t):
        """:meth:`evaluate` at the frames of ``bsf``, times ``t`` (n_f,): ``Qb`` (n_f, n, n_v)."""
        d, nv = bsf.space.dim, bsf.space.n_v
        Tc = np.stack([_eval_components_frames(c, f, t) for c, f in zip(self.const, self.funcs)], axis=1)
        Tb = Tc
        if d == 3:
            Tb = np.where(self.body_frame[None, :, None], Tc, np.einsum("fnji,fnj->fni", bsf.A[:, self.b], Tc))
        Q = np.zeros((len(t), len(self.b), nv))
        Q[:, :, d:] = Tb
        return ForceEval(self.b, Q)

    def jacobian(self, bs, t):
        from ..frames import skew

        d, nv = bs.space.dim, bs.space.n_v
        n = len(self.b)
        Kq = np.zeros((n, nv, nv))
        if d == 3:
            _, Tb = self._torques(bs, t)
            g = ~self.body_frame
            Kq[g, 3:, 3:] = skew(Tb[g])
        return ForceJacobian(self.b, self.b, Kq, np.zeros((n, nv, nv)))

    def outputs(self, bs, t):
        Tc, _ = self._torques(bs, t)
        if bs.space.dim == 2:
            return {"Mz [N m]": Tc[:, 0]}
        return {f"M{a} [N m]": Tc[:, k] for k, a in enumerate("xyz")}

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_applied_torques`)."""
        from ..compiled.elements import compile_applied_torques

        return compile_applied_torques(self, layout)