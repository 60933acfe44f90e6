r"""Continuous (penalty) contact of a body sphere or point with a ground plane.

The contact laws (Hertz stiffness, hysteresis damping) are those of :mod:`core.contact_laws`;
``hertz_sphere_plane_stiffness`` is re-exported from there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..contact_laws import HYSTERESIS_LAWS, hertz_sphere_plane_stiffness, hysteresis_force
from ..errors import InputError, ModelError
from .coordinates import ElementCoordinate, coordinate_forces, coordinate_jacobian, dot2_coordinate, pair_velocity, point_jacobian
from .protocol import ForceElement, ForceEval, ForceKind, nonnegative

Array = NDArray[np.float64]

__all__ = ["PlaneContact", "PlaneContactKind", "hertz_sphere_plane_stiffness"]


# --------------------------------------------------------------------------------------------
# sphere (or point) on a ground plane: continuous contact
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlaneContact(ForceElement):
    r"""Continuous (penalty) contact of a body sphere (or point) with a ground plane.

    Sphere centre C on the body (global position at build ``center``), radius R (0: a point);
    plane through ``plane_point`` with outward unit normal ``n``.  Penetration and its rate:

    .. math::

        δ = R - n^T (r_C - p_0), \qquad \dot δ = -n^T \dot r_C,

    normal force along ``n`` through the centre (for δ > 0, clamped at 0 so the plane never pulls):

    .. math::

        F_n = \max\bigl(0,\ K δ^{p}\,[1 + χ(e)\, \dot δ / \dot δ^{-}]\bigr),

    the law of :mod:`core.contact_laws` (Eq. N1 there, with its exact derivatives N2, N3).  The
    hysteresis factor χ(e) is the entry ``model`` of :data:`core.contact_laws.HYSTERESIS_LAWS`:
    χ = 3(1 − e²)/4 (Lankarani & Nikravesh 1990, Eq. 17; ``model='lankarani-nikravesh'``),
    χ = 8(1 − e)/(5e) (Flores et al. 2011, Eq. 24; ``'flores'``) or χ = 3(1 − e)/2 (Hunt &
    Crossley 1975; ``'hunt-crossley'``), or a law registered there by the user.  K is the user
    ``stiffness`` with ``exponent`` p, or the Hertz sphere-on-plane value
    :func:`core.contact_laws.hertz_sphere_plane_stiffness` (Johnson 1985, Eq. 4.23)
    ``K = (4/3) E* √R``, ``1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`` with p = 3/2 from
    ``materials=((E1, nu1), (E2, nu2))`` (0 ≤ ν ≤ 1/2).

    **Approach velocity.**  Force kinds are stateless functions of (t, q, v) called inside
    integrators (including rejected steps and Newton iterations), so the approach velocity
    δ̇⁻ at the start of each impact is *not* tracked per impact: it is the user parameter
    ``impact_velocity`` (e.g. √(2 g h) for a drop from height h).  The dissipated energy of an
    impact whose actual approach speed differs from it scales like the ratio of the two; choose
    e and ``impact_velocity`` together.

    Optional regularised Coulomb friction at the contact point ``r_C − R n``:
    ``F_t = −μ F_n v_t / √(|v_t|² + v_ε²)``, ``v_t`` the tangential slip velocity.

    The element is conservative (potential ``K δ^{p+1}/(p+1)``) only when e = 1 and μ = 0.
    The Jacobian is exact without friction (F_n non-smooth only at δ = 0, and where the clamp
    acts); with friction ``jacobian`` returns None and the model differentiates numerically.

    References
    ----------
    H. M. Lankarani, P. E. Nikravesh, "A contact force model with hysteresis damping for impact
    analysis of multibody systems", J. Mech. Des. 112 (1990) 369–376.
    P. Flores, M. Machado, M. T. Silva, J. M. Martins, "On the continuous contact force models for
    soft materials in multibody dynamics", Multibody Syst. Dyn. 25 (2011) 357–375.
    K. H. Hunt, F. R. E. Crossley, "Coefficient of restitution interpreted as damping in
    vibroimpact", J. Appl. Mech. 42 (1975) 440–445.
    K. L. Johnson, *Contact Mechanics*, Cambridge University Press, 1985.
    """

    name: str
    body: str
    center: Any
    radius: float
    plane_point: Any
    plane_normal: Any
    restitution: float = 1.0
    impact_velocity: float | None = None
    stiffness: float | None = None
    exponent: float = 1.5
    materials: Any = None
    friction: float = 0.0
    friction_velocity: float = 1e-3
    model: str = "lankarani-nikravesh"

    @classmethod
    def compile(cls, elements, ctx):
        return PlaneContactKind(elements, ctx)


class PlaneContactKind(ForceKind):
    """All :class:`PlaneContact` elements of a model."""

    def __init__(self, elements: list[PlaneContact], ctx):
        d = ctx.space.dim
        self.names = [e.name for e in elements]
        nb = len(ctx.bs0.r) - 1
        b, s, p0, n, R, K, p, chi, v0, mu, veps = [], [], [], [], [], [], [], [], [], [], []
        for e in elements:
            k = ctx.index(e.body, e.name)
            if k == nb:
                raise ModelError(f"plane contact {e.name!r}: the sphere must be on a body, not the ground")
            c = np.asarray(e.center, float)
            pp = np.asarray(e.plane_point, float)
            nn = np.asarray(e.plane_normal, float)
            for what, a in (("center", c), ("plane_point", pp), ("plane_normal", nn)):
                if a.shape != (d,) or not np.all(np.isfinite(a)):
                    raise ModelError(f"plane contact {e.name!r}: {what} must be {d} finite numbers, got {np.asarray(a).tolist()}")
            if np.linalg.norm(nn) == 0:
                raise ModelError(f"plane contact {e.name!r}: plane_normal is zero")
            rad = nonnegative(e.radius, "radius", e.name)
            try:
                law = HYSTERESIS_LAWS[e.model]
                chi_e = float(law.factor(e.restitution))
            except InputError as exc:
                raise ModelError(f"plane contact {e.name!r}: model {e.model!r}: {exc}") from None
            rest = float(e.restitution)
            if e.stiffness is not None and e.materials is not None:
                raise ModelError(f"plane contact {e.name!r}: give either stiffness or materials, not both")
            if e.stiffness is not None:
                kk = nonnegative(e.stiffness, "stiffness", e.name)
                ex = float(e.exponent)
                if not (np.isfinite(ex) and ex >= 1.0):
                    raise ModelError(f"plane contact {e.name!r}: exponent must be ≥ 1, got {e.exponent}")
            elif e.materials is not None:
                try:
                    (E1, nu1), (E2, nu2) = e.materials
                    E1, nu1, E2, nu2 = map(float, (E1, nu1, E2, nu2))
                except (TypeError, ValueError):
                    raise ModelError(f"plane contact {e.name!r}: materials must be ((E1, nu1), (E2, nu2))") from None
                if rad == 0:
                    raise ModelError(f"plane contact {e.name!r}: Hertz stiffness needs radius > 0 (give stiffness for a point)")
                try:
                    kk, ex = hertz_sphere_plane_stiffness(rad, E1, nu1, E2, nu2), 1.5
                except InputError as exc:
                    raise ModelError(f"plane contact {e.name!r}: materials {e.materials}: {exc}") from None
            else:
                raise ModelError(f"plane contact {e.name!r}: give stiffness (with exponent) or materials")
            if rest < 1.0:
                if e.impact_velocity is None or not (np.isfinite(e.impact_velocity) and e.impact_velocity > 0):
                    raise ModelError(f"plane contact {e.name!r}: restitution < 1 needs impact_velocity > 0 "
                                     f"(the expected approach speed δ̇⁻ [m/s]), got {e.impact_velocity}")
            b.append(k)
            s.append(ctx.local_point(k, c))
            p0.append(pp)
            n.append(nn / np.linalg.norm(nn))
            R.append(rad)
            K.append(kk)
            p.append(ex)
            chi.append(chi_e if rest < 1.0 else 0.0)
            v0.append(float(e.impact_velocity) if rest < 1.0 else 1.0)
            mu.append(nonnegative(e.friction, "friction coefficient", e.name))
            ve = float(e.friction_velocity)
            if not (np.isfinite(ve) and ve > 0):
                raise ModelError(f"plane contact {e.name!r}: friction_velocity must be > 0, got {e.friction_velocity}")
            veps.append(ve)
        self.b = np.array(b, np.int64)
        self.ground = np.full(len(b), nb, np.int64)
        self.s = np.array(s)
        self.p0, self.n = np.array(p0), np.array(n)
        self.R, self.K, self.p = np.array(R), np.array(K), np.array(p)
        self.chi, self.v0 = np.array(chi), np.array(v0)
        self.mu, self.veps = np.array(mu), np.array(veps)
        self.conservative = not (np.any(self.chi > 0) or np.any(self.mu > 0))

    def _coord(self, bs) -> ElementCoordinate:
        # s = nᵀ(r_C − p_0): dot-2 with i = ground (u = n, P = p_0) and j = the body (Q = C)
        return dot2_coordinate(bs, self.ground, self.n, self.p0, self.b, self.s)

    def _normal(self, bs, c):
        w = pair_velocity(bs, self.ground, self.b)
        sd = np.einsum("nr,nr->n", c.G[:, 0], w)
        delta = self.R - c.x[:, 0]
        # parameters were checked at build: the law (N1)-(N3) of core.contact_laws, unchecked
        Fn, dF_ddelta, dF_dddelta = hysteresis_force(delta, -sd, self.K, self.chi, self.v0, self.p, validate=False)
        return delta, Fn, dF_ddelta, dF_dddelta, w

    def _friction(self, bs, Fn):
        """Friction force (global, on the body) and body-local contact points."""
        scp = self.s - self.R[:, None] * np.einsum("nji,nj->ni", bs.A[self.b], self.n)
        vcp = bs.point_velocity(self.b, scp)
        vt = vcp - np.sum(vcp * self.n, 1)[:, None] * self.n
        Ft = -(self.mu * Fn / np.sqrt(np.sum(vt * vt, 1) + self.veps**2))[:, None] * vt
        return Ft, scp

    def evaluate(self, bs, t):
        c = self._coord(bs)
        _, Fn, _, _, _ = self._normal(bs, c)
        ev = coordinate_forces(self.ground, self.b, c, -Fn[:, None], bs.space.n_v)
        if np.any(self.mu > 0):
            Ft, scp = self._friction(bs, Fn)
            Qt = np.einsum("ndk,nd->nk", point_jacobian(bs, self.b, scp), Ft)
            ev = ForceEval(np.concatenate([ev.bodies, self.b]), np.concatenate([ev.Qb, Qt]))
        return ev

    def jacobian(self, bs, t):
        if np.any(self.mu > 0):
            return None
        c = self._coord(bs)
        _, Fn, dF_dd, dF_ddd, w = self._normal(bs, c)
        # f = −F_n as a generalized force against s; δ = R − s, δ̇ = −ṡ
        return coordinate_jacobian(self.ground, self.b, c, -Fn[:, None], dF_dd[:, None], dF_ddd[:, None], w, bs.space.n_v)

    def potential(self, bs):
        c = self._coord(bs)
        delta = np.maximum(self.R - c.x[:, 0], 0.0)
        return float(np.sum(self.K * delta ** (self.p + 1.0) / (self.p + 1.0)))

    def outputs(self, bs, t):
        c = self._coord(bs)
        delta, Fn, _, _, _ = self._normal(bs, c)
        out = {"penetration [m]": delta, "normal force [N]": Fn}
        if np.any(self.mu > 0):
            Ft, _ = self._friction(bs, Fn)
            out["friction force [N]"] = np.linalg.norm(Ft, axis=1)
        return out

    def compiled(self, layout):
        """Compiled form (:func:`core.compiled.elements.compile_plane_contacts`)."""
        from ..compiled.elements import compile_plane_contacts

        return compile_plane_contacts(self, layout)
