r"""The path-following joint: a body point on a track centreline, the body locked to the track frame.

A spatial body (position r, rotation A from its Euler parameters, body-frame angular velocity
ω̄, global ω = A ω̄) carries a joint point s′ and two perpendicular unit vectors ξ′, ζ′, all in
body coordinates (s = A s′, u_ξ = A ξ′, u_ζ = A ζ′).  The track is a
:class:`core.curves.FramedCurve`: centreline g(L) in its arc length L (m), moving frame
R(L) = [t, n, b] with Darboux vector Ω (1/m), e′ = Ω × e for e ∈ {t, n, b}.  The arc length L
is an extra, massless coordinate of the model (``ModelBuilder.add_coordinate(name, L0, L̇0)``).

Constraint equations (6 rows)::

    Φ1 = r + A s′ − g(L) = 0                  (3 rows: the joint point on the centreline)
    Φ2 = n · u_ξ = 0,  Φ3 = b · u_ξ = 0,  Φ4 = n · u_ζ = 0
                                               (3 rows: u_ξ = t, u_ζ = b, orientation locked)

With ξ′ ⟂ ζ′ the rows force u_ξ = ±t and u_ζ = ±b; the sign is that of the initial pose,
which :meth:`PathFollowingJoint.initial_state` builds from the track frame (never assemble from
a poor guess: u_ξ = −t, a body mounted backwards, also satisfies Φ = 0).  Orientation offsets
go into ξ′ and ζ′; the constants stay 0 (a dot constraint at ±1 has a zero gradient).

Velocity Jacobian with respect to the model's velocities of this joint, ``v_J = (ṙ, ω̄, L̇)``
(core's spatial bodies carry the **body-frame** angular velocity ω̄, so every global row
``aᵀ`` multiplying ω becomes ``(Aᵀa)ᵀ`` multiplying ω̄)::

    Φ1:  [ I    −A s̃′              −g′(L)       ]        (−A s̃′ ω̄ = ω × s)
    Φ_k: [ 0    (ū × Aᵀe)ᵀ          (Ω × e)·u    ]        (e, u) ∈ {(n, u_ξ), (b, u_ξ), (n, u_ζ)}

where ū = ξ′ or ζ′ and (ū × Aᵀe)ᵀ ω̄ = (u × e)·ω = e·(ω × u).  The constraints do not depend
on time: ν = 0.  Acceleration right-hand side, Φ_v v̇ = γ, from the second time derivative with
u̇ = ω × u, ü = ω̇ × u + ω × (ω × u), ė = L̇ e′, ë = L̈ e′ + L̇² e″::

    γ1 = −ω × (ω × s) + L̇² g″(L)
    γ_k = −[ L̇² e″·u + 2 L̇ e′·(ω × u) + e·(ω × (ω × u)) ],   e″ = Ω′ × e + Ω × (Ω × e)

Every term matters: on a helix (Ω constant, Ω′ = 0) dropping Ω × (Ω × e), the Coriolis-like
2 L̇ e′·(ω × u) or the centripetal e·(ω × (ω × u)) changes γ at O(1).

Reactions.  Core's equations of motion are ``M v̇ + Φ_qᵀ λ = Q``, so the joint's generalized
force on the body block is ``Q^c = −Φ_bᵀ λ`` (force F in global axes, moment in body axes at
the centre of mass).  :meth:`PathFollowingJoint.reactions` transfers the moment to the joint
point, ``M_P = M_cm − s × F``, and resolves F and M_P in the track frame (along t, n, b).
The L row of ``M v̇ + Φ_qᵀ λ = Q`` reads ``Φ_Lᵀ λ = 0`` (L is massless and unloaded): the
reactions do no work along the track, and their power ``F·ṙ + M_cm·ω = −λᵀ Φ_b v_b =
λᵀ Φ_L L̇`` vanishes without friction (:meth:`PathFollowingJoint.reaction_power`).

References
----------
Pombo, J. and Ambrósio, J. (2003). General spatial curve joint for rail guided vehicles:
kinematics and dynamics. Multibody System Dynamics 9(3):237-264 (the joint's constraint
equations, Jacobian and right-hand side of the acceleration equations; equation numbers not
checked).
Pombo, J. and Ambrósio, J. (2007). Modelling tracks for roller coaster dynamics. Int. J. Vehicle
Design 45(4):470-500 (reaction forces from the multipliers; equation numbers not checked).
Nikravesh, P. E. (1988). Computer-Aided Analysis of Mechanical Systems, Ch. 6-7 (body-frame
angular velocity and the Jacobian of body-fixed vectors, ``C(s̄) = −A s̄̃``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from core import frames
from core.curves import FramedCurve
from core.errors import InputError
from core.joints import UserConstraint

__all__ = ["PathFollowingJoint", "REACTION_COLUMNS"]

Array = NDArray[np.float64]

#: Column names of :meth:`PathFollowingJoint.reactions` (track frame: along t, n, b).
REACTION_COLUMNS = ("F_t [N]", "F_n [N]", "F_b [N]", "M_t [N m]", "M_n [N m]", "M_b [N m]")

_PAIRS = ((1, 0), (2, 0), (1, 1))  # (frame column e, body vector u) of rows 4, 5, 6: (n, ξ), (b, ξ), (n, ζ)


def _unit(x, what, owner):
    a = np.asarray(x, dtype=float)
    n = float(np.linalg.norm(a)) if a.shape == (3,) else 0.0
    if a.shape != (3,) or not np.all(np.isfinite(a)) or n == 0.0:
        raise InputError(f"{owner}: {what} must be a finite non-zero 3-vector, got {np.asarray(x).tolist()}")
    return a / n


class PathFollowingJoint(UserConstraint):
    r"""A body point on a track centreline, the body orientation locked to the track frame.

    Equations, Jacobian convention and γ in the module docstring (6 rows; ν = 0).

    Parameters
    ----------
    name : str
        Joint name (the rows are ``name[0]`` ... ``name[5]`` in the model).
    body : str
        A spatial body of the model.
    curve : core.curves.FramedCurve
        The track: centreline g(L), frame [t, n, b], Darboux vector Ω and Ω′.
    coordinate : str
        Name of the model's extra coordinate holding the arc length L (m); add it massless
        with ``ModelBuilder.add_coordinate(coordinate, L0, L̇0)``.
    point : (3,) array_like
        Joint point s′ in body coordinates (m); default the body origin (centre of mass).
    xi : (3,) array_like
        Body-fixed vector ξ′ held along the tangent t (normalised); default (1, 0, 0).
    zeta : (3,) array_like
        Body-fixed vector ζ′ held along the binormal b (normalised, ⟂ ξ′); default (0, 0, 1).

    Raises
    ------
    core.errors.InputError
        A vector that is not finite, zero, or ξ′ not perpendicular to ζ′ (to 1e-9), or a curve
        that is not a FramedCurve.

    References
    ----------
    Pombo & Ambrósio 2003, MSD 9:237-264 (equation numbers not checked).
    """

    rows = 6

    def __init__(self, name: str, body: str, curve: FramedCurve, coordinate: str, point: ArrayLike = (0.0, 0.0, 0.0),
                 xi: ArrayLike = (1.0, 0.0, 0.0), zeta: ArrayLike = (0.0, 0.0, 1.0)):
        owner = f"path joint {name!r}"
        if not isinstance(curve, FramedCurve):
            raise InputError(f"{owner}: curve must be a core.curves.FramedCurve, got {type(curve).__name__}")
        self.name = str(name)
        self.body = str(body)
        self.curve = curve
        self.coordinate = str(coordinate)
        self.bodies = (self.body,)
        self.coordinates = (self.coordinate,)
        self.body_i, self.body_j = self.body, "ground"
        self.at = None
        p = np.asarray(point, dtype=float)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise InputError(f"{owner}: point must be 3 finite numbers (m, body axes), got {np.asarray(point).tolist()}")
        self.point = p
        self.xi = _unit(xi, "xi", owner)
        self.zeta = _unit(zeta, "zeta", owner)
        if abs(float(self.xi @ self.zeta)) > 1e-9:
            raise InputError(f"{owner}: xi and zeta must be perpendicular, xi·zeta = {float(self.xi @ self.zeta):.3g}")
        self._u_bar = np.stack([self.xi, self.zeta])  # (2, 3) body vectors ξ′, ζ′

    # --- binding -------------------------------------------------------------------------------
    def bind(self, q_index, v_index, space):
        if space.dim != 3:
            raise InputError(f"path joint {self.name!r}: the path-following joint needs a spatial model")
        if len(q_index) != 8 or len(v_index) != 7:
            raise InputError(f"path joint {self.name!r}: expected one body block and one coordinate, got "
                             f"{len(q_index)} position and {len(v_index)} velocity indices")
        super().bind(q_index, v_index, space)

    # --- helpers -------------------------------------------------------------------------------
    def _state(self, q):
        """(r, A, L) of the joint's body and arc length from the full q."""
        qi = q[self.q_index]
        return qi[:3], frames.euler_to_matrix(qi[3:7]), float(qi[7])

    def _track(self, L):
        g, dg, ddg, R, Om, dOm = self.curve.evaluate_raw(np.array([L]))
        return g[0], dg[0], ddg[0], R[0], Om[0], dOm[0]

    def initial_state(self, L: float, Ldot: float = 0.0):
        """Body pose and velocity that satisfy the joint exactly at arc length ``L``.

        A = [t, b, t×b] [ξ′, ζ′, ξ′×ζ′]ᵀ (so A ξ′ = t, A ζ′ = b), r = g(L) − A s′,
        ω = Ω L̇ (global), ṙ = g′ L̇ − ω × (A s′).

        Parameters
        ----------
        L : float
            Arc length (m).
        Ldot : float
            Rate L̇ (m/s).

        Returns
        -------
        position : (3,) ndarray
            r (m).
        orientation : (4,) ndarray
            Euler parameters of A.
        velocity : (3,) ndarray
            ṙ (m/s).
        angular_velocity : (3,) ndarray
            ω in global axes (rad/s), as ``ModelBuilder.add_body`` takes it.
        """
        g, dg, _, R, Om, _ = self._track(float(L))
        t, b = R[:, 0], R[:, 2]
        body = np.column_stack([self.xi, self.zeta, np.cross(self.xi, self.zeta)])
        track = np.column_stack([t, b, np.cross(t, b)])
        A = track @ body.T
        s = A @ self.point
        w = Om * Ldot
        return g - s, frames.matrix_to_euler(A), dg * Ldot - np.cross(w, s), w

    # --- constraint protocol ---------------------------------------------------------------------
    def phi(self, t, q):
        """Φ (6,): point rows (m) then the three dot products (-)."""
        r, A, L = self._state(q)
        g, _, _, R, _, _ = self._track(L)
        u = A @ self._u_bar.T  # (3, 2): u_ξ, u_ζ
        out = np.empty(6)
        out[:3] = r + A @ self.point - g
        for k, (e, j) in enumerate(_PAIRS):
            out[3 + k] = R[:, e] @ u[:, j]
        return out

    def jacobian(self, t, q):
        """Φ_v (6, 7) with respect to (ṙ, ω̄ body-frame, L̇); see the module docstring."""
        r, A, L = self._state(q)
        _, dg, _, R, Om, _ = self._track(L)
        J = np.zeros((6, 7))
        J[:3, :3] = np.eye(3)
        J[:3, 3:6] = -A @ frames.skew(self.point)
        J[:3, 6] = -dg
        for k, (e, j) in enumerate(_PAIRS):
            ev = R[:, e]
            J[3 + k, 3:6] = np.cross(self._u_bar[j], A.T @ ev)
            J[3 + k, 6] = np.cross(Om, ev) @ (A @ self._u_bar[j])
        return J

    def nu(self, t, q):
        """ν = 0 (6,): the joint does not depend on time."""
        return np.zeros(6)

    def gamma(self, t, q, v):
        """γ (6,) with Φ_v v̇ = γ; every term of e″ (module docstring)."""
        r, A, L = self._state(q)
        _, _, ddg, R, Om, dOm = self._track(L)
        vi = v[self.v_index]
        wb, Ld = vi[3:6], float(vi[6])
        w = A @ wb
        s = A @ self.point
        out = np.empty(6)
        out[:3] = -np.cross(w, np.cross(w, s)) + Ld * Ld * ddg
        u = A @ self._u_bar.T
        for k, (e, j) in enumerate(_PAIRS):
            ev, uv = R[:, e], u[:, j]
            de = np.cross(Om, ev)
            dde = np.cross(dOm, ev) + np.cross(Om, de)
            wu = np.cross(w, uv)
            out[3 + k] = -(Ld * Ld * (dde @ uv) + 2.0 * Ld * (de @ wu) + ev @ np.cross(w, wu))
        return out

    # --- reactions ---------------------------------------------------------------------------------
    def joint_multipliers(self, model, lam: ArrayLike) -> Array:
        """The joint's 6 multipliers out of a model's multiplier vector (or a time history).

        Parameters
        ----------
        model : core.model.Model
            The model the joint was added to.
        lam : (n_c,) or (n_t, n_c) array_like
            Multipliers of all constraint rows (``SimulationResult.lam``).

        Returns
        -------
        (6,) or (n_t, 6) ndarray

        Raises
        ------
        core.errors.InputError
            If rows of the joint were removed as redundant at build.
        """
        rows = model.reaction_groups()[self.name]
        if len(rows) != 6:
            raise InputError(f"path joint {self.name!r}: {6 - len(rows)} of its rows were removed as redundant; "
                             "its reactions are not defined row by row")
        return np.asarray(lam, float)[..., rows]

    def _generalized(self, q, lam6):
        """Q^c = −Φ_vᵀ λ (7,): global force, body-frame moment at the centre of mass, L force."""
        return -(self.jacobian(0.0, q).T @ np.asarray(lam6, float))

    def reactions(self, q: ArrayLike, lam6: ArrayLike) -> Array:
        r"""Joint reactions on the body at the joint point, resolved in the track frame.

        F = −λ_{1:3} (global), M_cm = A (−Φ_ω̄ᵀ λ) (global, about the centre of mass),
        M_P = M_cm − s × F (about the joint point s = A s′); returned as
        (F·t, F·n, F·b, M_P·t, M_P·n, M_P·b) (:data:`REACTION_COLUMNS`).

        Parameters
        ----------
        q : (n_q,) or (n_t, n_q) array_like
            Model positions (full vectors).
        lam6 : (6,) or (n_t, 6) array_like
            The joint's multipliers (:meth:`joint_multipliers`).

        Returns
        -------
        (6,) or (n_t, 6) ndarray
            Forces (N) along t, n, b and moments (N m) about the joint point along t, n, b.
        """
        Q = np.atleast_2d(np.asarray(q, float))
        Lm = np.atleast_2d(np.asarray(lam6, float))
        out = np.empty((len(Q), 6))
        for i, (qq, ll) in enumerate(zip(Q, Lm)):
            _, A, L = self._state(qq)
            R = self._track(L)[3]
            Qc = self._generalized(qq, ll)
            F = Qc[:3]
            Mp = A @ Qc[3:6] - np.cross(A @ self.point, F)
            out[i, :3] = R.T @ F
            out[i, 3:] = R.T @ Mp
        return out[0] if np.ndim(q) == 1 else out

    def reaction_power(self, q: ArrayLike, v: ArrayLike, lam6: ArrayLike) -> Array:
        r"""Power of the joint reactions on the body, P = F·ṙ + M_cm·ω = −λᵀ Φ_b v_b (W).

        Without friction P = λᵀ Φ_L L̇ = 0, because the L row of the equations of motion is
        Φ_Lᵀ λ = 0 (L massless and unloaded).

        Parameters
        ----------
        q, v : (n_q,), (n_v,) or histories (n_t, n_q), (n_t, n_v)
        lam6 : (6,) or (n_t, 6)

        Returns
        -------
        float or (n_t,) ndarray
        """
        Q = np.atleast_2d(np.asarray(q, float))
        V = np.atleast_2d(np.asarray(v, float))
        Lm = np.atleast_2d(np.asarray(lam6, float))
        P = np.array([self._generalized(qq, ll)[:6] @ vv[self.v_index[:6]] for qq, vv, ll in zip(Q, V, Lm)])
        return float(P[0]) if np.ndim(q) == 1 else P

    def compiled(self, layout):
        """Compiled form for core's fast integrators (:func:`coaster._kernels.path_joint_kernel`).

        Needs a tabulated track (:class:`core.curves.TabulatedFramedCurve`, e.g. the table of a
        :class:`coaster.frames.RotationMinimisingFrame`); otherwise
        :class:`core.errors.NotCompilable` names the joint.
        """
        from ._kernels import compile_path_joint

        return compile_path_joint(self, layout)

    def reaction_table(self, model, result):
        """Reactions of a :class:`core.results.SimulationResult` as a DataFrame in the track frame.

        Columns ``t [s]``, ``L [m]``, :data:`REACTION_COLUMNS` and ``P [W]`` (power of the
        reactions), one row per output time.
        """
        import pandas as pd

        lam6 = self.joint_multipliers(model, result.lam)
        data = self.reactions(result.q, lam6)
        df = pd.DataFrame(data, columns=list(REACTION_COLUMNS))
        df.insert(0, "L [m]", result.q[:, self.q_index[7]])
        df.insert(0, "t [s]", result.t)
        df["P [W]"] = self.reaction_power(result.q, result.v, lam6)
        df.attrs["joint"] = self.name
        df.attrs["frame"] = "track frame (t along, n normal, b binormal); moments about the joint point"
        return df
