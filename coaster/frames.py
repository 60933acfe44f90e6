"""Moving frames on a track centreline: Frenet and rotation-minimising with a bank angle.

Every frame here is a :class:`core.curves.FramedCurve` (r, r', r'', R = [t, n, b], the
Darboux vector omega and omega' at any arc length L, fast ``evaluate_raw``) and also offers
:meth:`frame` (R, omega, omega' computed from the centreline's exact derivatives).  Columns: t
tangent, n lateral/normal, b binormal/up.  The two providers are interchangeable for a path
joint:

================================== ================== =================================
frame                              omega              omega'
================================== ================== =================================
Frenet (:class:`FrenetFrame`)      tau t + kappa b    tau' t + kappa' b
RMF + bank theta                   theta' t + t x g'' theta'' t + theta' g'' + t x g'''
(:class:`RotationMinimisingFrame`)
================================== ================== =================================

with kappa = ``|g''|``, n = g''/kappa, kappa' = g''.g'''/kappa, tau = t.(g'' x g''')/kappa^2 and
tau' = t.(g'' x g'''')/kappa^2 - 2 tau kappa'/kappa (notes/coaster.md "Frames").  For the table of
the RMF, omega'' = theta''' t + 2 theta'' g'' + theta' g''' + g'' x g''' + t x g''''.

:func:`frame_quality` tabulates orthonormality, tangent error, continuity, curvature and torsion.

References
----------
Bishop, R. L. (1975). There is more than one way to frame a curve. Amer. Math. Monthly
82(3):246-251 (rotation-minimising frame, e' = (t x t') x e).
Wang, W., Juettler, B., Zheng, D. and Liu, Y. (2008). Computation of rotation minimizing frames.
ACM TOG 27(1), art. 2 (double reflection; used here only as the definition being integrated).
Iserles, A., Munthe-Kaas, H. Z., Norsett, S. P. and Zanna, A. (2000). Lie-group methods. Acta
Numerica 9:215-365, eq. (4.20) (fourth-order Magnus method with two Gauss points).
Pombo, J. and Ambrosio, J. (2003). Multibody Syst. Dyn. 9:237-264 (Frenet frame of a track,
cant relative to the osculating plane); (2007) Int. J. Vehicle Design 45(4):470-500.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import scipy.interpolate as si

from core.curves import CurveFrame, FramedCurve, TabulatedFramedCurve
from core.errors import InputError, NumericalFailure

from .track import Centreline

__all__ = [
    "Bank",
    "FrenetFrame",
    "RotationMinimisingFrame",
    "frame_quality",
    "frame_quality_summary",
]

_EZ = np.array([0.0, 0.0, 1.0])


def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def _col(a):
    return np.asarray(a)[:, None]


# ---------------------------------------------------------------------------------------------
# bank angle
# ---------------------------------------------------------------------------------------------
class Bank:
    """A bank (cant) angle theta(L) (rad) with its first three derivatives.

    Calling it returns a (4, N) array theta, theta', theta'', theta''' (rad, rad/m, ...).

    Parameters
    ----------
    func : callable
        ``func(L) -> (4, N) array``; use the constructors below for the usual cases.
    """

    def __init__(self, func, name="bank"):
        self._func = func
        self.name = name

    def __call__(self, L):
        return np.asarray(self._func(np.asarray(L, dtype=float)), dtype=float)

    @classmethod
    def constant(cls, theta=0.0, accept=()):
        """theta(L) = theta (rad; or a string with its unit, ``"30 deg"``).

        A number outside the plausible bank angle (``|theta|`` <= pi, data/coaster/plausible_ranges.csv)
        is refused as a likely slip of degrees (:class:`core.inputs.ImplausibleValueError`);
        ``accept=["bank_angle"]`` takes it deliberately.
        """
        from .inputs import check

        th = float(check("bank_angle", theta, where="Bank.constant(theta)", accept=accept))
        return cls(lambda L: np.vstack([np.full(L.shape, th)] + [np.zeros(L.shape)] * 3),
                   name=f"constant {th!r} rad")

    @classmethod
    def from_samples(cls, L, theta, closed=False, length=None, accept=()):
        """Quintic (C4) interpolating spline of theta through samples (L_i, theta_i).

        Parameters
        ----------
        L, theta : (m,) array_like
            Strictly increasing arc lengths (m) and angles (rad), m >= 6.
        closed : bool
            Periodic with period ``length`` (m); the samples must not repeat L_0 + length.
        length : float
            Period of a closed bank (the circuit length).
        accept : sequence of str
            ``["bank_angle"]`` accepts angles beyond +-pi (an unwrapped roll through several
            inversions).

        Raises
        ------
        InputError
            Fewer than 6 samples (a quintic spline needs 6), samples of different lengths,
            non-finite or non-increasing samples (named by index), a closed bank without its
            length or with a sample at or beyond L_0 + length.
        core.inputs.ImplausibleValueError
            An angle beyond +-pi rad: the likely slip of degrees is named.
        """
        from .inputs import check

        L = np.asarray(L, dtype=float)
        th = theta
        if np.ndim(L) != 1 or np.ndim(th) != 1 or len(L) != len(th):
            raise InputError(f"bank samples: L and theta must be 1-D of equal length, got {np.shape(L)} and "
                             f"{np.shape(th)}")
        if len(L) < 6:
            raise InputError(f"bank samples: a quintic bank spline needs at least 6 samples (L_i, theta_i), "
                             f"got {len(L)}; add samples or use Bank.constant")
        if any(isinstance(x, str) for x in th):
            th = check("bank_angle", list(th), where="bank samples theta", accept=("bank_angle",))
        th = np.asarray(th, dtype=float)
        for nm, a in (("L", L), ("theta", th)):
            bad = ~np.isfinite(a)
            if np.any(bad):
                i = int(np.argmax(bad))
                raise InputError(f"bank samples: {nm}[{i}] = {float(a[i])!r} is not finite")
        if np.any(np.diff(L) <= 0):
            i = int(np.argmax(np.diff(L) <= 0)) + 1
            raise InputError(f"bank samples: L must increase strictly; L[{i}] = {float(L[i])!r}")
        check("bank_angle", th, where="bank samples theta", accept=accept)
        if closed:
            if length is None:
                raise InputError("bank samples: a closed bank needs its period 'length'")
            if not float(length) > L[-1] - L[0]:
                raise InputError(f"bank samples: a closed bank of period length = {float(length)!r} m needs its "
                                 f"samples within [L_0, L_0 + length), got L from {float(L[0])!r} to "
                                 f"{float(L[-1])!r} m (do not repeat the first sample at L_0 + length)")
            Lx = np.concatenate([L, [L[0] + float(length)]])
            tx = np.concatenate([th, th[:1]])
            b = si.make_interp_spline(Lx, tx, k=5, bc_type="periodic")
            L0, P = L[0], float(length)
        else:
            b = si.make_interp_spline(L, th, k=5)
            L0, P = None, None
        ders = [b.derivative(k) for k in range(1, 4)]

        def f(x):
            if P is not None:
                x = L0 + np.mod(x - L0, P)
            return np.vstack([b(x)] + [d(x) for d in ders])

        return cls(f, name="quintic spline bank")


# ---------------------------------------------------------------------------------------------
# Frenet
# ---------------------------------------------------------------------------------------------
class FrenetFrame(FramedCurve):
    """Frenet frame [t, n, b] of a centreline, evaluated exactly from g' ... g''''.

        t = g',  n = g''/kappa,  b = t x n,  omega = tau t + kappa b,  omega' = tau' t + kappa' b
        kappa' = g''.g'''/kappa,  tau = t.(g'' x g''')/kappa^2,
        tau' = t.(g'' x g'''')/kappa^2 - 2 tau kappa'/kappa

    The frame is undefined where kappa = 0 (straights, inflections).  Where kappa <
    ``kappa_min`` it raises, unless ``fallback="vertical"``: then n = e_z x t/``|e_z x t|``, b =
    t x n, omega = omega' = 0 (exact on a straight; on an inflection of a curved track this
    only hides the singularity).  **Inflection flip:** on a planar S-curve n = g''/kappa points
    to the centre of curvature, which changes side at the inflection: n and b flip by 180 deg
    over an arbitrarily short distance and tau ~ 1/kappa^2 spikes nearby; a body locked to
    this frame would be turned over.  :func:`frame_quality` shows the flip as a rotation step
    near pi between neighbouring samples.  Use :class:`RotationMinimisingFrame` for tracks.

    Parameters
    ----------
    centreline : coaster.track.Centreline
    kappa_min : float
        Curvature (1/m) below which the frame counts as undefined.
    fallback : {None, "vertical"}

    References
    ----------
    Pombo & Ambrosio (2003), Multibody Syst. Dyn. 9:237-264 (Frenet frame of a track).
    """

    def __init__(self, centreline: Centreline, kappa_min=1e-6, fallback=None, name=None):
        if fallback not in (None, "vertical"):
            raise InputError(f"FrenetFrame: fallback must be None or 'vertical', got {fallback!r}")
        self.centreline = centreline
        self.kappa_min = float(kappa_min)
        self.fallback = fallback
        self.length = centreline.length
        self.closed = centreline.closed
        self.name = name or f"Frenet frame of {centreline.name}"

    def frame(self, L, side="right"):
        """R (N, 3, 3), omega (N, 3), omega' (N, 3) at arc lengths L (m).

        Raises
        ------
        InputError
            kappa < kappa_min at some L (named) and no fallback.
        """
        d = self.centreline.derivatives(L, side)
        return self._from_derivatives(np.atleast_1d(np.asarray(L, dtype=float)).reshape(-1), d)[3:]

    def _from_derivatives(self, L, d):
        g, g1, g2, g3, g4 = d
        k = np.linalg.norm(g2, axis=1)
        small = k < self.kappa_min
        if np.any(small) and self.fallback is None:
            i = int(np.argmax(small))
            raise InputError(f"{self.name}: curvature {float(k[i])!r} 1/m below kappa_min = "
                             f"{self.kappa_min!r} at L = {float(L[i])!r} m (index {i}): the Frenet frame "
                             f"is undefined there (straight or inflection); use fallback='vertical' or "
                             f"a RotationMinimisingFrame")
        ks = np.where(small, 1.0, k)
        t = g1
        n = g2 / ks[:, None]
        b = np.cross(t, n)
        k1 = _dot(g2, g3) / ks
        tau = _dot(t, np.cross(g2, g3)) / ks**2
        tau1 = _dot(t, np.cross(g2, g4)) / ks**2 - 2.0 * tau * k1 / ks
        om = _col(tau) * t + _col(k) * b
        dom = _col(tau1) * t + _col(k1) * b
        if np.any(small):
            nv = np.cross(_EZ, t[small])
            nn = np.linalg.norm(nv, axis=1)
            if np.any(nn < 1e-9):
                raise InputError(f"{self.name}: vertical fallback undefined on vertical track at "
                                 f"L = {float(L[small][int(np.argmin(nn))])!r} m")
            n[small] = nv / nn[:, None]
            b[small] = np.cross(t[small], n[small])
            om[small] = 0.0
            dom[small] = 0.0
        R = np.stack([t, n, b], axis=2)
        return g, g1, g2, R, om, dom

    def evaluate_raw(self, s):
        """(r, r', r'', R, omega, omega') exactly from the centreline (see the class)."""
        return self._from_derivatives(s, self.centreline.derivatives(s))

    def check(self, L=None, n=2001):
        """Check that the frame is defined and continuous along the track; raise where it is not.

        Pointwise evaluation only raises where kappa < kappa_min at a requested L; near an
        inflection the curvature is small but non-zero at the samples and n = g''/kappa turns
        by about pi between two of them (the centre of curvature changes side).  This scan
        evaluates the frame at ``L`` (default ``n`` points over the track plus the breaks) and
        reports the first place where it is undefined (no fallback) or where the normals of two
        neighbouring samples point apart (n_i . n_{i+1} < 0: a flip, which a body locked to the
        frame would follow by turning over).

        Parameters
        ----------
        L : array_like, optional
            Arc lengths (m), increasing.
        n : int
            Number of equally spaced samples when ``L`` is not given.

        Returns
        -------
        float
            The largest rotation angle (rad) between neighbouring samples' frames.

        Raises
        ------
        InputError
            kappa < kappa_min at some L without a fallback (named), or a flip of the frame
            between L_i and L_{i+1} (both named, with the angle).
        """
        c = self.centreline
        if L is None:
            L = np.unique(np.concatenate([np.linspace(0.0, c.length, int(n)), np.asarray(c.breaks, float)]))
        L = np.atleast_1d(np.asarray(L, dtype=float)).reshape(-1)
        R = self.frame(L)[0]  # raises where undefined without a fallback
        if L.size < 2:
            return 0.0
        nn = R[:, :, 1]
        dots = _dot(nn[:-1], nn[1:])
        ang = _rotation_steps(R)
        flip = dots < 0.0
        if np.any(flip):
            i = int(np.argmax(flip))
            raise InputError(f"{self.name}: the Frenet frame flips by {float(ang[i]):.3g} rad between L = "
                             f"{float(L[i])!r} m and L = {float(L[i + 1])!r} m (normal n_i . n_(i+1) = "
                             f"{float(dots[i]):.3g}): an inflection, where the curvature changes side; use a "
                             f"RotationMinimisingFrame")
        return float(np.max(ang))


# ---------------------------------------------------------------------------------------------
# rotation-minimising frame with bank
# ---------------------------------------------------------------------------------------------
class RotationMinimisingFrame(FramedCurve):
    """Rotation-minimising frame rolled by a bank angle, stored as a quintic Hermite table.

    **RMF.**  The rotation-minimising frame F0 = [t, u, v] turns with omega_0 = t x g'' (no
    twist about t; Bishop 1975), dF0/dL = [omega_0]x F0.  It is integrated over the table
    nodes with the fourth-order Magnus method (Iserles et al. 2000, eq. 4.20), which keeps F0
    exactly orthonormal: on a step [L, L + h] with w_i = omega_0(L + c_i h),
    c_{1,2} = 1/2 -+ sqrt(3)/6::

        sigma = h/2 (w_1 + w_2) + sqrt(3) h^2/12 (w_2 x w_1),   F0(L + h) = exp([sigma]x) F0(L)

    The number of Magnus substeps per table interval is doubled until two successive results
    differ by less than ``tol`` (max entry of F0 over all nodes); that difference is kept in
    ``rmf_error``.

    **Bank.**  The frame R = [t, n, b] is F0 turned by theta(L) about t:
    n = cos theta u + sin theta v, b = -sin theta u + cos theta v, so::

        omega = theta' t + t x g'',   omega' = theta'' t + theta' g'' + t x g''',
        omega'' = theta''' t + 2 theta'' g'' + theta' g''' + g'' x g''' + t x g''''

    With ``bank_reference="frame"`` theta is the given bank (relative to the RMF, which starts
    with u = the horizontal lateral e_z x t/``|e_z x t|`` unless ``initial_normal`` is given).  With
    ``bank_reference="vertical"`` the given angle phi is measured from the vertical frame
    (lateral n_v = e_z x t/``|e_z x t|``, singular on vertical track) and theta = phi + beta with
    beta the angle from u to n_v about t, beta' = t_z (t x g'')_z/(1 - t_z^2) (= sin(grade)
    times the heading rate), beta'' and beta''' by the quotient rule.

    **Closing.**  On a closed circuit F0 comes back turned by the holonomy Delta about t
    (Delta = atan2(u_end.v_0, u_end.u_0)); with a frame-relative bank the correction
    theta_c(L) = -Delta L/length (theta_c' = -Delta/length) is added so that R closes.  A
    vertical-relative bank closes by itself.

    **Table.**  Nodes at the centreline breaks, subdivided to at most ``max_step``; exact
    one-sided values at both ends of every interval (:class:`core.curves.TabulatedFramedCurve`),
    interpolation error about (h ``|omega|``)^6/46080.

    Parameters
    ----------
    centreline : coaster.track.Centreline
    bank : Bank or float, optional
        theta(L) or phi(L) (rad); default 0.
    bank_reference : {"frame", "vertical"}
    max_step : float
        Largest table interval (m).
    tol : float
        Tolerance on the integrated RMF (max entry error).
    initial_normal : (3,) array_like, optional
        u at L = 0 (projected normal to t).

    Attributes
    ----------
    table : TabulatedFramedCurve
    nodes : (n+1,) ndarray
    holonomy : float
        Delta (rad) of a closed circuit, else NaN.
    rmf_error : float
    n_substeps : int

    Raises
    ------
    InputError
        Bad options, a vertical tangent with ``bank_reference="vertical"`` (names L).
    NumericalFailure
        The RMF did not reach ``tol`` with 256 substeps per interval.
    """

    def __init__(self, centreline: Centreline, bank=None, bank_reference="frame", max_step=2.0,
                 tol=1e-10, initial_normal=None, name=None):
        if bank_reference not in ("frame", "vertical"):
            raise InputError(f"RotationMinimisingFrame: bank_reference must be 'frame' or 'vertical', "
                             f"got {bank_reference!r}")
        if bank is None or np.isscalar(bank):
            bank = Bank.constant(0.0 if bank is None else bank)
        self.centreline = centreline
        self.bank = bank
        self.bank_reference = bank_reference
        self.length = centreline.length
        self.closed = centreline.closed
        self.name = name or f"RMF of {centreline.name}"
        self.tol = float(tol)
        max_step = float(max_step)
        if not max_step > 0:
            raise InputError(f"{self.name}: max_step must be positive, got {max_step!r}")
        br = np.asarray(centreline.breaks, dtype=float)
        nodes = [br[:1]]
        for a, b in zip(br[:-1], br[1:]):
            m = max(1, int(math.ceil((b - a) / max_step)))
            nodes.append(np.linspace(a, b, m + 1)[1:])
        self.nodes = np.concatenate(nodes)
        self._integrate(initial_normal)
        self._build_table()

    # --- RMF -----------------------------------------------------------------------------
    def _omega0(self, L):
        d = self.centreline.derivatives(L)
        return np.cross(d[1], d[2])

    def _march(self, F0, m):
        x = self.nodes
        h = np.diff(x) / m
        sub = (x[:-1, None] + h[:, None] * np.arange(m)[None, :]).reshape(-1)
        hh = np.repeat(h, m)
        c1, c2 = 0.5 - math.sqrt(3) / 6, 0.5 + math.sqrt(3) / 6
        w1 = self._omega0(sub + c1 * hh)
        w2 = self._omega0(sub + c2 * hh)
        sig = 0.5 * hh[:, None] * (w1 + w2) + (math.sqrt(3) / 12) * hh[:, None] ** 2 * np.cross(w2, w1)
        # Rodrigues: exp([s]x) = I + sin a/a [s]x + (1 - cos a)/a^2 [s]x^2
        a = np.linalg.norm(sig, axis=1)
        small = a < 1e-8
        asafe = np.where(small, 1.0, a)
        A = np.where(small, 1.0 - a**2 / 6, np.sin(asafe) / asafe)
        B = np.where(small, 0.5 - a**2 / 24, (1 - np.cos(asafe)) / asafe**2)
        K = np.zeros((sig.shape[0], 3, 3))
        K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -sig[:, 2], sig[:, 1], -sig[:, 0]
        K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = sig[:, 2], -sig[:, 1], sig[:, 0]
        E = np.eye(3) + A[:, None, None] * K + B[:, None, None] * (K @ K)
        out = np.empty((x.size, 3, 3))
        out[0] = F = F0
        for i in range(x.size - 1):
            for j in range(m):
                F = E[i * m + j] @ F
            out[i + 1] = F
        return out

    def _integrate(self, initial_normal):
        d0 = self.centreline.derivatives([self.nodes[0]])
        t0 = d0[1, 0]
        u0 = np.cross(_EZ, t0) if initial_normal is None else np.asarray(initial_normal, dtype=float)
        u0 = u0 - (u0 @ t0) * t0
        if np.linalg.norm(u0) < 1e-9:
            if initial_normal is not None:
                raise InputError(f"{self.name}: initial_normal is parallel to the start tangent")
            u0 = np.cross([1.0, 0.0, 0.0], t0)  # vertical start: any lateral
        u0 /= np.linalg.norm(u0)
        F0 = np.column_stack([t0, u0, np.cross(t0, u0)])
        m = 1
        prev = self._march(F0, m)
        while True:
            m *= 2
            cur = self._march(F0, m)
            err = float(np.max(np.abs(cur - prev)))
            if err <= self.tol:
                break
            if m >= 256:
                raise NumericalFailure(f"{self.name}: rotation-minimising frame did not reach tol = "
                                       f"{self.tol!r} with {m} Magnus substeps per interval (change {err!r})")
            prev = cur
        self.rmf_error = err
        self.n_substeps = m
        self._F0 = cur
        if self.closed:
            Fe, Fs = cur[-1], cur[0]
            self.holonomy = math.atan2(Fe[:, 1] @ Fs[:, 2], Fe[:, 1] @ Fs[:, 1])
        else:
            self.holonomy = float("nan")

    # --- bank -----------------------------------------------------------------------------
    def _theta(self, L, d, F0=None):
        """theta, theta', theta'', theta''' at L (4, N) given the centreline derivatives d."""
        th = self.bank(L).copy()
        if self.closed and self.bank_reference == "frame":
            th[0] -= self.holonomy * L / self.length
            th[1] -= self.holonomy / self.length
        if self.bank_reference == "vertical":
            _, g1, g2, g3, g4 = d
            a, a1, a2 = g1[:, 2], g2[:, 2], g3[:, 2]
            D = 1.0 - a**2
            if np.any(D < 1e-10):
                i = int(np.argmin(D))
                raise InputError(f"{self.name}: bank relative to the vertical is undefined on vertical "
                                 f"track at L = {float(L[i])!r} m")
            D1, D2 = -2 * a * a1, -2 * (a1**2 + a * a2)
            w = np.cross(g1, g2)[:, 2]
            w1 = np.cross(g1, g3)[:, 2]
            w2 = (np.cross(g2, g3) + np.cross(g1, g4))[:, 2]
            num, num1, num2 = a * w, a1 * w + a * w1, a2 * w + 2 * a1 * w1 + a * w2
            f = num / D
            f1 = (num1 - f * D1) / D
            f2 = (num2 - 2 * f1 * D1 - f * D2) / D
            th[1] += f
            th[2] += f1
            th[3] += f2
            if F0 is not None:  # beta from the integrated RMF
                nv = np.cross(_EZ, g1)
                nv /= np.linalg.norm(nv, axis=1)[:, None]
                beta = np.unwrap(np.arctan2(_dot(nv, F0[:, :, 2]), _dot(nv, F0[:, :, 1])))
                th[0] += beta
        return th

    def _frames_at(self, L, side, F0, theta0):
        d = self.centreline.derivatives(L, side)
        th = self._theta(L, d)
        th[0] = theta0
        g, g1, g2, g3, g4 = d
        c, s = np.cos(th[0])[:, None], np.sin(th[0])[:, None]
        u, v = F0[:, :, 1], F0[:, :, 2]
        R = np.stack([g1, c * u + s * v, -s * u + c * v], axis=2)
        om = _col(th[1]) * g1 + np.cross(g1, g2)
        dom = _col(th[2]) * g1 + _col(th[1]) * g2 + np.cross(g1, g3)
        ddom = (_col(th[3]) * g1 + 2 * _col(th[2]) * g2 + _col(th[1]) * g3 + np.cross(g2, g3)
                + np.cross(g1, g4))
        return CurveFrame(g, g1, g2, R, om, dom, ddomega=ddom)

    def _build_table(self):
        x, F0 = self.nodes, self._F0
        d = self.centreline.derivatives(x)
        theta = self._theta(x, d, F0)[0]
        start = self._frames_at(x[:-1], "right", F0[:-1], theta[:-1])
        end = self._frames_at(x[1:], "left", F0[1:], theta[1:])
        if self.closed:
            gapR = float(np.max(np.abs(end.R[-1] - start.R[0])))
            if gapR > max(1e3 * self.tol, 1e-8):
                raise NumericalFailure(f"{self.name}: the banked frame does not close (|R(end) - R(0)| = "
                                       f"{gapR!r}); is the bank periodic?")
            self.closure_gap = gapR
            end.R[-1] = start.R[0]
            end.position[-1] = start.position[0]
        else:
            self.closure_gap = float("nan")
        self._theta_nodes = theta
        self.table = TabulatedFramedCurve(x, start, end, closed=self.closed, name=self.name)

    # --- FramedCurve ------------------------------------------------------------------------
    def evaluate_raw(self, s):
        """(r, r', r'', R, omega, omega') from the quintic Hermite table (fast path)."""
        return self.table.evaluate_raw(s)

    def frame(self, L, side="right"):
        """R (table, re-orthonormalised), omega and omega' (exact) at arc lengths L (m)."""
        L = np.atleast_1d(np.asarray(L, dtype=float)).reshape(-1)
        R = self.table.evaluate(L).R
        U, _, Vt = np.linalg.svd(R)
        R = U @ Vt
        d = self.centreline.derivatives(L, side)
        th = self._theta(L, d)
        _, g1, g2, g3, _ = d
        om = _col(th[1]) * g1 + np.cross(g1, g2)
        dom = _col(th[2]) * g1 + _col(th[1]) * g2 + np.cross(g1, g3)
        return R, om, dom

    def bank_angle(self, L):
        """Total roll theta(L) relative to the RMF (rad), linear between the table nodes."""
        return np.interp(L, self.nodes, self._theta_nodes)


# ---------------------------------------------------------------------------------------------
# quality table
# ---------------------------------------------------------------------------------------------
def _rotation_steps(R):
    """Angle (rad) of the rotation R_{i-1}^T R_i between neighbouring frames (n - 1,):
    cos angle = (trace - 1) / 2."""
    rel = np.einsum("nki,nkj->nij", R[:-1], R[1:])
    return np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0))


def frame_quality(curve: FramedCurve, centreline: Centreline, L=None, n=1001):
    """Quality of a framed curve along the track, one row per sample.

    Columns (SI units in the names):

    * ``L_m`` arc length;
    * ``orthonormality`` max ``|R^T R - I|``;
    * ``tangent_error`` ``|t - dg/dL|`` with dg/dL exact from the centreline;
    * ``position_error_m`` ``|r - g|``;
    * ``R_jump`` max ``|R_i - R_{i-1}|`` (entrywise) between neighbouring samples (NaN on row 0);
    * ``rotation_step_rad`` the angle of R_{i-1}^T R_i, and ``expected_step_rad`` =
      ``|omega|`` Delta L at the midpoint: a step far above the expected one is a discontinuity
      (e.g. a Frenet flip, ``rotation_step_rad`` near pi);
    * ``curvature_1_m`` kappa = ``|g''|`` and ``torsion_1_m`` tau = t.(g'' x g''')/kappa^2 (NaN where
      kappa = 0);
    * ``twist_1_m`` omega . t.

    Parameters
    ----------
    curve : FramedCurve
    centreline : Centreline
    L : array_like, optional
        Arc lengths (m); default ``n`` points over [0, length].

    Returns
    -------
    pandas.DataFrame
    """
    L = np.linspace(0.0, centreline.length, n) if L is None else np.asarray(L, dtype=float)
    f = curve.evaluate(L)
    d = centreline.derivatives(L)
    R = f.R
    orth = np.max(np.abs(np.einsum("nki,nkj->nij", R, R) - np.eye(3)), axis=(1, 2))
    terr = np.linalg.norm(R[:, :, 0] - d[1], axis=1)
    perr = np.linalg.norm(f.position - d[0], axis=1)
    jump = np.full(L.size, np.nan)
    step = np.full(L.size, np.nan)
    expected = np.full(L.size, np.nan)
    if L.size > 1:
        jump[1:] = np.max(np.abs(np.diff(R, axis=0)), axis=(1, 2))
        step[1:] = _rotation_steps(R)
        om_mid = curve.evaluate(0.5 * (L[1:] + L[:-1])).omega
        expected[1:] = np.linalg.norm(om_mid, axis=1) * np.diff(L)
    k = np.linalg.norm(d[2], axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(k > 0, _dot(d[1], np.cross(d[2], d[3])) / k**2, np.nan)
    return pd.DataFrame({
        "L_m": L,
        "orthonormality": orth,
        "tangent_error": terr,
        "position_error_m": perr,
        "R_jump": jump,
        "rotation_step_rad": step,
        "expected_step_rad": expected,
        "curvature_1_m": k,
        "torsion_1_m": tau,
        "twist_1_m": _dot(f.omega, R[:, :, 0]),
    })


def frame_quality_summary(curve: FramedCurve, centreline: Centreline, step: float = 1.0):
    """:func:`frame_quality` every ``step`` m along the track, with units in the column names, and
    its summary.

    The rotation step between neighbouring samples against ``|ω|`` ΔL flags a jump (a ratio of order
    π/(``|ω|`` ΔL) ≫ 1); the closure max ``|R(length) − R(0)|`` tells whether the frame of a closed track
    returns to itself.

    Parameters
    ----------
    curve : FramedCurve
    centreline : Centreline
    step : float
        Sample spacing (m).

    Returns
    -------
    samples : pandas.DataFrame
        ``L [m]``, ``max |R^T R - I| [-]``, ``|t - g'| [-]``, ``|r - g| [m]``,
        ``max |R_i - R_i-1| [-]``, ``rotation step [rad]``, ``|omega| dL [rad]``,
        ``curvature [1/m]``, ``torsion [1/m]``, ``twist omega.t [1/m]``.
    summary : pandas.DataFrame
        One row: samples, step, the largest of each error, the largest rotation step and its
        ratio to ``|ω|`` ΔL, the frame closure, the largest curvature and ``|torsion|``.
    """
    q = frame_quality(curve, centreline, L=np.arange(0.0, centreline.length, step))
    q = q.rename(columns={"L_m": "L [m]", "orthonormality": "max |R^T R - I| [-]", "tangent_error": "|t - g'| [-]",
                          "position_error_m": "|r - g| [m]", "R_jump": "max |R_i - R_i-1| [-]",
                          "rotation_step_rad": "rotation step [rad]", "expected_step_rad": "|omega| dL [rad]",
                          "curvature_1_m": "curvature [1/m]", "torsion_1_m": "torsion [1/m]",
                          "twist_1_m": "twist omega.t [1/m]"})
    ratio = (q["rotation step [rad]"] / q["|omega| dL [rad]"]).replace([np.inf, -np.inf], np.nan)
    end = curve.evaluate(np.array([0.0, centreline.length]))
    closure = float(np.max(np.abs(end.R[0] - end.R[1])))
    summary = pd.DataFrame([{
        "samples [-]": len(q), "step [m]": step,
        "max |R^T R - I| [-]": q["max |R^T R - I| [-]"].max(), "max |t - g'| [-]": q["|t - g'| [-]"].max(),
        "max |r - g| [m]": q["|r - g| [m]"].max(),
        "max rotation step [rad]": q["rotation step [rad]"].max(),
        "max rotation step / (|omega| dL) [-]": ratio.max(),
        "frame closure max |R(length) - R(0)| [-]": closure,
        "max curvature [1/m]": q["curvature [1/m]"].max(),
        "max |torsion| [1/m]": q["torsion [1/m]"].abs().max()}])
    return q, summary
