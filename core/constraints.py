r"""Vectorised constraint primitives from which every joint and driver is assembled.

Each primitive kind holds the arrays of all its elements (body indices ``i``, ``j`` and body-fixed
vectors) and evaluates them in one numpy call.  Body ``j`` may be the ground pseudo-body.
For each element the kind returns its residual rows, the Jacobian blocks with respect to the
velocity coordinates of body ``i`` and ``j`` (shape (rows, 2, n_v_body)), ``ν`` and ``γ``.

Primitives (Haug 1989, Sec. 9.2; Nikravesh 1988, Sec. 7.2), with ``P`` on ``i``, ``Q`` on ``j``,
``d = r_Q − r_P``, body-fixed directions ``a_i = A_i ā_i``, ``a_j = A_j ā_j``:

=================  ======================================  ===============================================
kind               Φ                                        γ
=================  ======================================  ===============================================
point coincidence  ``r_P − r_Q`` (d rows)                   ``−(a^q_P − a^q_Q)``
dot-1              ``a_iᵀ a_j − c``                         ``−(a_jᵀ a^q(ā_i) + a_iᵀ a^q(ā_j) + 2 ȧ_iᵀ ȧ_j)``
dot-2              ``a_iᵀ d − c``                           ``−(dᵀ a^q(ā_i) + 2 ȧ_iᵀ ḋ + a_iᵀ(a^q_Q − a^q_P))``
distance           ``(dᵀd − L²)/(2L)``                      ``−(ḋᵀḋ + dᵀ(a^q_Q − a^q_P))/L``
planar angle       ``θ_j − θ_i − c``                        ``0``
=================  ======================================  ===============================================

Drivers subtract a prescribed function of time f(t): ``Φ = g(q) − f(t)``, ``ν = ḟ``, ``γ = γ_g + f̈``.
The spatial revolute angle driver uses ``Φ = cos f (g_iᵀ f_j) − sin f (f_iᵀ f_j) = sin(θ − f)``
with the marker axes f, g of the revolute joint (θ the relative rotation about the joint axis).

References
----------
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989, Sec. 9.2.
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988, Sec. 7.2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .bodies import BodyStates
from .drivers import TimeFunction

Array = NDArray[np.float64]
IArray = NDArray[np.int64]


@dataclass
class KindEval:
    """Evaluation of one primitive kind: phi (n, r), jac (n, r, 2, n_v), nu (n, r), gamma (n, r)."""

    phi: Array | None = None
    jac: Array | None = None
    nu: Array | None = None
    gamma: Array | None = None


class PrimitiveKind:
    """Base of the vectorised constraint primitives.

    Attributes
    ----------
    rows : int
        Equations per element.
    bi, bj : ndarray of int, shape (n,)
        Body indices (ground = n_bodies).
    labels : list of str
        One label per element (``joint-name/primitive``) for error messages and row names.
    """

    rows: int = 1
    name: str = "primitive"
    time_dependent: bool = False

    def __init__(self, bi: IArray, bj: IArray, labels: list[str]):
        self.bi = np.asarray(bi, dtype=np.int64)
        self.bj = np.asarray(bj, dtype=np.int64)
        self.labels = list(labels)

    @property
    def n(self) -> int:
        return len(self.bi)

    def evaluate(self, bs: BodyStates, t: float, what: str) -> KindEval:  # pragma: no cover
        """Evaluate; ``what`` contains any of 'p' (phi), 'j' (jac), 'n' (nu), 'g' (gamma)."""
        raise NotImplementedError

    # helpers ---------------------------------------------------------------------------
    def _jac(self, bs: BodyStates) -> Array:
        return np.zeros((self.n, self.rows, 2, bs.space.n_v))

    def _time(self, t: float) -> tuple[Array, Array, Array]:
        return np.zeros(self.n), np.zeros(self.n), np.zeros(self.n)


def _rowvec_times(a: Array, C: Array) -> Array:
    """aᵀ C for stacks: a (n, d), C (n, d, k) -> (n, k)."""
    return np.einsum("ni,nik->nk", a, C)


class PointCoincidence(PrimitiveKind):
    """``r_i + A_i s̄_i − r_j − A_j s̄_j = 0`` (spherical / planar revolute)."""

    name = "point"

    def __init__(self, bi, si, bj, sj, labels, dim):
        super().__init__(bi, bj, labels)
        self.si = np.asarray(si, dtype=float).reshape(-1, dim)
        self.sj = np.asarray(sj, dtype=float).reshape(-1, dim)
        self.rows = dim

    def evaluate(self, bs, t, what):
        out = KindEval()
        d = bs.space.dim
        if "p" in what:
            out.phi = bs.point(self.bi, self.si) - bs.point(self.bj, self.sj)
        if "j" in what:
            J = self._jac(bs)
            eye = np.eye(d)
            J[:, :, 0, :d] = eye
            J[:, :, 0, d:] = bs.C(self.bi, self.si)
            J[:, :, 1, :d] = -eye
            J[:, :, 1, d:] = -bs.C(self.bj, self.sj)
            out.jac = J
        if "n" in what:
            out.nu = np.zeros((self.n, d))
        if "g" in what:
            out.gamma = -(bs.aq(self.bi, self.si) - bs.aq(self.bj, self.sj))
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_point_coincidence`)."""
        from .compiled.elements import compile_point_coincidence

        return compile_point_coincidence(self, layout)


class Dot1(PrimitiveKind):
    """``a_iᵀ a_j − c = 0`` (two body-fixed directions at a fixed angle)."""

    name = "dot1"

    def __init__(self, bi, ai, bj, aj, c, labels, dim):
        super().__init__(bi, bj, labels)
        self.ai = np.asarray(ai, dtype=float).reshape(-1, dim)
        self.aj = np.asarray(aj, dtype=float).reshape(-1, dim)
        self.c = np.asarray(c, dtype=float).reshape(-1)

    def evaluate(self, bs, t, what):
        out = KindEval()
        ai = bs.vector(self.bi, self.ai)
        aj = bs.vector(self.bj, self.aj)
        if "p" in what:
            out.phi = (np.sum(ai * aj, axis=1) - self.c)[:, None]
        if "j" in what:
            J = self._jac(bs)
            d = bs.space.dim
            J[:, 0, 0, d:] = _rowvec_times(aj, bs.C(self.bi, self.ai))
            J[:, 0, 1, d:] = _rowvec_times(ai, bs.C(self.bj, self.aj))
            out.jac = J
        if "n" in what:
            out.nu = np.zeros((self.n, 1))
        if "g" in what:
            aid = bs.vector_velocity(self.bi, self.ai)
            ajd = bs.vector_velocity(self.bj, self.aj)
            g = np.sum(aj * bs.aq(self.bi, self.ai), 1) + np.sum(ai * bs.aq(self.bj, self.aj), 1)
            g += 2.0 * np.sum(aid * ajd, 1)
            out.gamma = -g[:, None]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_dot1`)."""
        from .compiled.elements import compile_dot1

        return compile_dot1(self, layout)


class Dot2(PrimitiveKind):
    """``a_iᵀ (r_Q − r_P) − c = 0`` (a point of j stays in a plane of i)."""

    name = "dot2"

    def __init__(self, bi, ai, si, bj, sj, c, labels, dim):
        super().__init__(bi, bj, labels)
        self.ai = np.asarray(ai, dtype=float).reshape(-1, dim)
        self.si = np.asarray(si, dtype=float).reshape(-1, dim)
        self.sj = np.asarray(sj, dtype=float).reshape(-1, dim)
        self.c = np.asarray(c, dtype=float).reshape(-1)

    def evaluate(self, bs, t, what):
        out = KindEval()
        ai = bs.vector(self.bi, self.ai)
        dvec = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        if "p" in what:
            out.phi = (np.sum(ai * dvec, 1) - self.c)[:, None]
        if "j" in what:
            J = self._jac(bs)
            d = bs.space.dim
            J[:, 0, 0, :d] = -ai
            J[:, 0, 0, d:] = _rowvec_times(dvec, bs.C(self.bi, self.ai)) - _rowvec_times(ai, bs.C(self.bi, self.si))
            J[:, 0, 1, :d] = ai
            J[:, 0, 1, d:] = _rowvec_times(ai, bs.C(self.bj, self.sj))
            out.jac = J
        if "n" in what:
            out.nu = np.zeros((self.n, 1))
        if "g" in what:
            aid = bs.vector_velocity(self.bi, self.ai)
            dd = bs.point_velocity(self.bj, self.sj) - bs.point_velocity(self.bi, self.si)
            g = np.sum(dvec * bs.aq(self.bi, self.ai), 1) + 2.0 * np.sum(aid * dd, 1)
            g += np.sum(ai * (bs.aq(self.bj, self.sj) - bs.aq(self.bi, self.si)), 1)
            out.gamma = -g[:, None]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_dot2`)."""
        from .compiled.elements import compile_dot2

        return compile_dot2(self, layout)


class Distance(PrimitiveKind):
    """``(dᵀd − L²)/(2L) = 0`` with ``d = r_Q − r_P`` (massless rigid link of length L)."""

    name = "distance"

    def __init__(self, bi, si, bj, sj, length, labels, dim):
        super().__init__(bi, bj, labels)
        self.si = np.asarray(si, dtype=float).reshape(-1, dim)
        self.sj = np.asarray(sj, dtype=float).reshape(-1, dim)
        self.L = np.asarray(length, dtype=float).reshape(-1)

    def evaluate(self, bs, t, what):
        out = KindEval()
        dvec = bs.point(self.bj, self.sj) - bs.point(self.bi, self.si)
        L = self.L
        if "p" in what:
            out.phi = ((np.sum(dvec * dvec, 1) - L * L) / (2.0 * L))[:, None]
        if "j" in what:
            J = self._jac(bs)
            d = bs.space.dim
            u = dvec / L[:, None]
            J[:, 0, 0, :d] = -u
            J[:, 0, 0, d:] = -_rowvec_times(u, bs.C(self.bi, self.si))
            J[:, 0, 1, :d] = u
            J[:, 0, 1, d:] = _rowvec_times(u, bs.C(self.bj, self.sj))
            out.jac = J
        if "n" in what:
            out.nu = np.zeros((self.n, 1))
        if "g" in what:
            dd = bs.point_velocity(self.bj, self.sj) - bs.point_velocity(self.bi, self.si)
            g = np.sum(dd * dd, 1) + np.sum(dvec * (bs.aq(self.bj, self.sj) - bs.aq(self.bi, self.si)), 1)
            out.gamma = -(g / L)[:, None]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_distance`)."""
        from .compiled.elements import compile_distance

        return compile_distance(self, layout)


class PlanarAngle(PrimitiveKind):
    """``θ_j − θ_i − c = 0`` (planar relative rotation locked)."""

    name = "angle"

    def __init__(self, bi, bj, c, labels):
        super().__init__(bi, bj, labels)
        self.c = np.asarray(c, dtype=float).reshape(-1)

    def evaluate(self, bs, t, what):
        out = KindEval()
        if "p" in what:
            th = np.arctan2(bs.A[:, 1, 0], bs.A[:, 0, 0])
            # unwrap relative to c using the rotation matrices (angle of A_iᵀ A_j)
            rel = np.arctan2(np.sin(th[self.bj] - th[self.bi] - self.c), np.cos(th[self.bj] - th[self.bi] - self.c))
            out.phi = rel[:, None]
        if "j" in what:
            J = self._jac(bs)
            J[:, 0, 0, 2] = -1.0
            J[:, 0, 1, 2] = 1.0
            out.jac = J
        if "n" in what:
            out.nu = np.zeros((self.n, 1))
        if "g" in what:
            out.gamma = np.zeros((self.n, 1))
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_planar_angle`)."""
        from .compiled.elements import compile_planar_angle

        return compile_planar_angle(self, layout)


# --------------------------------------------------------------------------------------------
# Drivers (rheonomic constraints)
# --------------------------------------------------------------------------------------------


class _Driven(PrimitiveKind):
    time_dependent = True

    def __init__(self, bi, bj, functions: list[TimeFunction], labels):
        super().__init__(bi, bj, labels)
        self.functions = list(functions)

    def _time(self, t):
        vals = np.array([fn(t) for fn in self.functions], dtype=float).reshape(self.n, 3)
        return vals[:, 0], vals[:, 1], vals[:, 2]


class PointPositionDriver(_Driven):
    """``uᵀ (r_P − r_O) − f(t) = 0``: a point of body i moves along global direction u as f(t).

    ``r_O`` is a fixed global origin; ``u`` a fixed global unit vector (ground-fixed).
    """

    name = "point-driver"

    def __init__(self, bi, si, u, origin, functions, labels, dim):
        n = len(bi)
        super().__init__(bi, np.full(n, -1), functions, labels)
        self.si = np.asarray(si, dtype=float).reshape(-1, dim)
        self.u = np.asarray(u, dtype=float).reshape(-1, dim)
        self.o = np.asarray(origin, dtype=float).reshape(-1, dim)

    def evaluate(self, bs, t, what):
        out = KindEval()
        f, fd, fdd = self._time(t)
        if "p" in what:
            out.phi = (np.sum(self.u * (bs.point(self.bi, self.si) - self.o), 1) - f)[:, None]
        if "j" in what:
            J = self._jac(bs)
            d = bs.space.dim
            J[:, 0, 0, :d] = self.u
            J[:, 0, 0, d:] = _rowvec_times(self.u, bs.C(self.bi, self.si))
            out.jac = J
        if "n" in what:
            out.nu = fd[:, None]
        if "g" in what:
            out.gamma = (fdd - np.sum(self.u * bs.aq(self.bi, self.si), 1))[:, None]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_point_position_driver`)."""
        from .compiled.elements import compile_point_position_driver

        return compile_point_position_driver(self, layout)


class PlanarAngleDriver(_Driven):
    """``θ_j − θ_i − c − f(t) = 0`` (planar revolute angle driver)."""

    name = "angle-driver"

    def __init__(self, bi, bj, c, functions, labels):
        super().__init__(bi, bj, functions, labels)
        self.c = np.asarray(c, dtype=float).reshape(-1)

    def evaluate(self, bs, t, what):
        out = KindEval()
        f, fd, fdd = self._time(t)
        if "p" in what:
            th = np.arctan2(bs.A[:, 1, 0], bs.A[:, 0, 0])
            e = th[self.bj] - th[self.bi] - self.c - f
            out.phi = np.arctan2(np.sin(e), np.cos(e))[:, None]
        if "j" in what:
            J = self._jac(bs)
            J[:, 0, 0, 2] = -1.0
            J[:, 0, 1, 2] = 1.0
            out.jac = J
        if "n" in what:
            out.nu = fd[:, None]
        if "g" in what:
            out.gamma = fdd[:, None]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_planar_angle_driver`)."""
        from .compiled.elements import compile_planar_angle_driver

        return compile_planar_angle_driver(self, layout)


class SpatialAngleDriver(_Driven):
    """Relative rotation θ about a revolute axis prescribed: ``cos f (g_iᵀ f_j) − sin f (f_iᵀ f_j) = 0``.

    With ``f_j = cos θ f_i + sin θ g_i`` this equals ``sin(θ − f)``.  Derivatives:
    ``ν = ḟ (sin f g_iᵀf_j + cos f f_iᵀf_j)`` and γ adds the time terms of the product rule.
    """

    name = "angle-driver"

    def __init__(self, bi, fi, gi, bj, fj, c, functions, labels):
        super().__init__(bi, bj, functions, labels)
        self.fi = np.asarray(fi, float).reshape(-1, 3)
        self.gi = np.asarray(gi, float).reshape(-1, 3)
        self.fj = np.asarray(fj, float).reshape(-1, 3)
        self.c = np.asarray(c, float).reshape(-1)

    def evaluate(self, bs, t, what):
        out = KindEval()
        f, fd, fdd = self._time(t)
        f = f + self.c
        cf, sf = np.cos(f), np.sin(f)
        Fi = bs.vector(self.bi, self.fi)
        Gi = bs.vector(self.bi, self.gi)
        Fj = bs.vector(self.bj, self.fj)
        a = np.sum(Gi * Fj, 1)  # g_iᵀ f_j
        b = np.sum(Fi * Fj, 1)  # f_iᵀ f_j
        if "p" in what:
            out.phi = (cf * a - sf * b)[:, None]
        need_j = "j" in what or "g" in what
        if need_j:
            Cfi, Cgi, Cfj = bs.C(self.bi, self.fi), bs.C(self.bi, self.gi), bs.C(self.bj, self.fj)
            Ja_i, Ja_j = _rowvec_times(Fj, Cgi), _rowvec_times(Gi, Cfj)
            Jb_i, Jb_j = _rowvec_times(Fj, Cfi), _rowvec_times(Fi, Cfj)
        if "j" in what:
            J = self._jac(bs)
            J[:, 0, 0, 3:] = cf[:, None] * Ja_i - sf[:, None] * Jb_i
            J[:, 0, 1, 3:] = cf[:, None] * Ja_j - sf[:, None] * Jb_j
            out.jac = J
        if "n" in what:
            out.nu = (fd * (sf * a + cf * b))[:, None]
        if "g" in what:
            wi, wj = bs.w[self.bi], bs.w[self.bj]
            Fid, Gid, Fjd = (
                bs.vector_velocity(self.bi, self.fi),
                bs.vector_velocity(self.bi, self.gi),
                bs.vector_velocity(self.bj, self.fj),
            )
            # quadratic (velocity-product) parts of ä and b̈
            ga = np.sum(Fj * bs.aq(self.bi, self.gi), 1) + np.sum(Gi * bs.aq(self.bj, self.fj), 1) + 2 * np.sum(Gid * Fjd, 1)
            gb = np.sum(Fj * bs.aq(self.bi, self.fi), 1) + np.sum(Fi * bs.aq(self.bj, self.fj), 1) + 2 * np.sum(Fid * Fjd, 1)
            adot = np.sum(Ja_i * wi, 1) + np.sum(Ja_j * wj, 1)
            bdot = np.sum(Jb_i * wi, 1) + np.sum(Jb_j * wj, 1)
            # Φ = cf a − sf b;  Φ̈ = cf ä − sf b̈ − 2 ḟ (sf ȧ + cf ḃ) − f̈ (sf a + cf b) − ḟ² (cf a − sf b)
            rest = cf * ga - sf * gb - 2 * fd * (sf * adot + cf * bdot) - fdd * (sf * a + cf * b) - fd**2 * (cf * a - sf * b)
            out.gamma = -rest[:, None]
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_spatial_angle_driver`)."""
        from .compiled.elements import compile_spatial_angle_driver

        return compile_spatial_angle_driver(self, layout)
