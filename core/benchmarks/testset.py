r"""Published multibody DAE test problems written directly in generalized coordinates.

Both problems come from the *Test Set for IVP Solvers* (Mazzia & Magherini, University of Bari)
and Hairer & Wanner, *Solving Ordinary Differential Equations II*, Sec. VII.7.  They implement
:class:`core.system.ConstrainedSystem` with ``Z = I`` (``n_q = n_v``), so every integrator of
:mod:`core.integrators` runs on them exactly as on a Cartesian :class:`core.model.Model`.

Sign convention of the multipliers (that of :mod:`core.system`)::

    M(q) v̇ + Φ_q(t, q)ᵀ λ = Q(t, q, v),   Φ(t, q) = 0.

The Andrews problem is published in this very form (``M q̈ = f − Gᵀλ``), so its published
multipliers compare directly.  The car axis is published as ``K v̇ = f + Gᵀλ``; its published
multipliers are therefore ``−λ`` in our convention (:attr:`CarAxis.reference` stores them
already converted).

References
----------
F. Mazzia, C. Magherini, *Test Set for Initial Value Problem Solvers*, release 2.4,
Department of Mathematics, University of Bari, 2008 (problems "andrews" and "caraxis";
Fortran sources ``andrews.f`` and ``caraxis.f``; reference solutions computed with PSIDE /
RADAU5 at tolerances 1e-14).
E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer, 1996,
Sec. VII.7, Eqs. (7.11)–(7.14) (Andrews' squeezing mechanism).
W. Schiehlen (ed.), *Multibody Systems Handbook*, Springer, 1990 (Andrews' mechanism,
the "seven body mechanism" of Manning & Giles).
G. Andrews, M. Richard, "Seven body mechanism", in Schiehlen (1990).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..system import ConstrainedSystem

Array = NDArray[np.float64]

__all__ = ["AndrewsSqueezer", "CarAxis", "SimeonCrank", "ANDREWS_PARAMETERS", "SIMEON_CRANK_PARAMETERS"]


#: Parameters of Andrews' squeezing mechanism, SI units (Hairer & Wanner 1996, Table 7.1;
#: test set ``andrews.f``): masses [kg], moments of inertia [kg m²], lengths [m], spring
#: stiffness c0 [N/m], drive torque mom [N m].
ANDREWS_PARAMETERS: dict[str, float] = dict(
    m1=0.04325, m2=0.00365, m3=0.02373, m4=0.00706, m5=0.07050, m6=0.00706, m7=0.05498,
    xa=-0.06934, ya=-0.00227, xb=-0.03635, yb=0.03273, xc=0.014, yc=0.072, c0=4530.0,
    i1=2.194e-6, i2=4.410e-7, i3=5.255e-6, i4=5.667e-7, i5=1.169e-5, i6=5.667e-7, i7=1.912e-5,
    d=28e-3, da=115e-4, e=2e-2, ea=1421e-5, rr=7e-3, ra=92e-5, l0=7785e-5,
    ss=35e-3, sa=1874e-5, sb=1043e-5, sc=18e-3, sd=2e-2, ta=2308e-5, tb=916e-5,
    u=4e-2, ua=1228e-5, ub=449e-5, zf=2e-2, zt=4e-2, fa=1421e-5, mom=33e-3,
)


class AndrewsSqueezer(ConstrainedSystem):
    r"""Andrews' squeezing mechanism in the seven absolute/relative angles (index-3 DAE).

    Coordinates ``q = (β, Θ, γ, Φ, δ, Ω, ε)`` [rad]: β crank angle (driven by the constant
    torque ``mom``), Θ relative angle of the coupler 2 to the crank, γ angle of body 3
    (carrying the spring attachment D), Φ, δ and Ω, ε the angles of the two two-link
    branches closing the loop at the fixed point A.

    Equations (Hairer & Wanner 1996, Sec. VII.7)::

        M(q) q̈ = f(q, q̇) − G(q)ᵀ λ,     0 = g(q),     G = ∂g/∂q

    with the symmetric 7×7 mass matrix (non-zero entries)::

        M11 = m1 ra² + m2 (rr² − 2 da rr cos Θ + da²) + I1 + I2
        M21 = m2 (da² − da rr cos Θ) + I2,         M22 = m2 da² + I2
        M33 = m3 (sa² + sb²) + I3
        M44 = m4 (e − ea)² + I4,                   M54 = m4 ((e − ea)² + zt (e − ea) sin Φ) + I4
        M55 = m4 (zt² + 2 zt (e − ea) sin Φ + (e − ea)²) + m5 (ta² + tb²) + I4 + I5
        M66 = m6 (zf − fa)² + I6,                  M76 = m6 ((zf − fa)² − u (zf − fa) sin Ω) + I6
        M77 = m6 ((zf − fa)² − 2 u (zf − fa) sin Ω + u²) + m7 (ua² + ub²) + I6 + I7

    the forces (Coriolis/centrifugal terms, drive torque, spring between D on body 3 and the
    fixed point C)::

        f1 = mom − m2 da rr Θ̇ (Θ̇ + 2β̇) sin Θ,     f2 = m2 da rr β̇² sin Θ
        f3 = Fx (sc cos γ − sd sin γ) + Fy (sd cos γ + sc sin γ)
        f4 = m4 zt (e − ea) δ̇² cos Φ,                f5 = −m4 zt (e − ea) Φ̇ (Φ̇ + 2δ̇) cos Φ
        f6 = −m6 u (zf − fa) ε̇² cos Ω,               f7 = m6 u (zf − fa) Ω̇ (Ω̇ + 2ε̇) cos Ω
        x_D = sd cos γ + sc sin γ + xb,   y_D = sd sin γ − sc cos γ + yb
        L = |r_D − r_C|,   (Fx, Fy) = −c0 (L − l0)/L · (x_D − xc, y_D − yc)

    and the six loop-closure constraints::

        g1 = rr cos β − d cos(β+Θ) − ss sin γ − xb
        g2 = rr sin β − d sin(β+Θ) + ss cos γ − yb
        g3 = rr cos β − d cos(β+Θ) − e sin(Φ+δ) − zt cos δ − xa
        g4 = rr sin β − d sin(β+Θ) + e cos(Φ+δ) − zt sin δ − ya
        g5 = rr cos β − d cos(β+Θ) − zf cos(Ω+ε) − u sin ε − xa
        g6 = rr sin β − d sin(β+Θ) − zf sin(Ω+ε) + u cos ε − ya

    The constraints are scleronomic: ``ν = 0`` and ``γ = −g_qq(q̇, q̇)``.  The drive torque is
    constant, so ``T + ½ c0 (L − l0)² − mom·β`` is conserved (:meth:`energy`); there is no
    gravity in the published problem.

    Initial state (test set): the consistent angles listed in :attr:`q0`, all velocities 0;
    the published consistent accelerations ``q̈(0) = (14222.44…, −10666.83…, 0, …, 0)`` and
    multipliers ``λ(0) = (98.5668…, −6.1226…, 0, 0, 0, 0)`` are in :attr:`initial_reference`.

    Reference solution at ``t = 0.03 s`` (:attr:`reference`): computed by the test-set authors
    with PSIDE at rtol = atol = 1e−14 on a Cray C90 (test set ``andrews.f``, subroutine
    ``andsoln``).

    Parameters
    ----------
    **overrides : float
        Replace any entry of :data:`ANDREWS_PARAMETERS` (SI units).

    References
    ----------
    - E. Hairer, G. Wanner, *Solving ODEs II*, Springer, 1996, Sec. VII.7, pp. 530–536.
    - F. Mazzia, C. Magherini, *Test Set for IVP Solvers*, release 2.4, Univ. of Bari, 2008,
      problem "Andrews' squeezing mechanism".
    - W. Schiehlen (ed.), *Multibody Systems Handbook*, Springer, 1990.
    """

    name = "andrews_squeezer"
    n_q = n_v = 7
    n_c = 6
    mass_is_constant = False
    is_conservative = True
    coordinate_names = ["beta [rad]", "Theta [rad]", "gamma [rad]", "Phi [rad]", "delta [rad]",
                        "Omega [rad]", "epsilon [rad]"]
    velocity_names = ["beta_dot [rad/s]", "Theta_dot [rad/s]", "gamma_dot [rad/s]", "Phi_dot [rad/s]",
                      "delta_dot [rad/s]", "Omega_dot [rad/s]", "epsilon_dot [rad/s]"]
    constraint_names = ["B loop x", "B loop y", "A loop (Phi, delta) x", "A loop (Phi, delta) y",
                        "A loop (Omega, epsilon) x", "A loop (Omega, epsilon) y"]

    #: Published consistent initial angles [rad] (test set, ``andrews.f``, subroutine ``init``).
    Q0_PUBLISHED = np.array([
        -0.0617138900142764496358948458001,
        0.0,
        0.455279819163070380255912382449,
        0.222668390165885884674473185609,
        0.487364979543842550225598953530,
        -0.222668390165885884674473185609,
        1.23054744454982119249735015568,
    ])

    #: Published state at t = 0 beyond q0: accelerations [rad/s²] and multipliers.
    initial_reference = dict(
        t=0.0,
        a=np.array([14222.4439199541138705911625887, -10666.8329399655854029433719415, 0, 0, 0, 0, 0]),
        lam=np.array([98.5668703962410896057654982170, -6.12268834425566265503114393122, 0, 0, 0, 0]),
        source="Mazzia & Magherini, Test Set for IVP Solvers 2.4 (2008), andrews.f, subroutine init",
    )

    #: Published reference solution at t = 0.03 s (q [rad], v [rad/s], λ in our sign convention).
    reference = dict(
        t=0.03,
        q=np.array([0.1581077119629904e2, -0.1575637105984298e2, 0.4082224013073101e-1,
                    -0.5347301163226948, 0.5244099658805304, 0.5347301163226948,
                    0.1048080741042263e1]),
        v=np.array([0.1139920302151208e4, -0.1424379294994111e4, 0.1103291221937134e2,
                    0.1929337464421385e2, 0.5735699284790808, -0.1929337464421385e2,
                    0.3231791658026955]),
        a=np.array([-0.2463176316945196e5, 0.5185037701610329e5, 0.3241025686413781e6,
                    0.5667493645176213e6, 0.1674362929479361e5, -0.5667493645176222e6,
                    0.9826520791458422e4]),
        lam=np.array([0.1991753333731910e3, -0.2975531228015052e2, 0.2306654119098399e2,
                      0.3145271365475927e2, 0.2264249232082739e2, 0.1161740700019673e2]),
        source=("Mazzia & Magherini, Test Set for IVP Solvers 2.4 (2008), andrews.f, subroutine "
                "andsoln: PSIDE, rtol = atol = 1e-14, Cray C90 double precision"),
    )

    def __init__(self, **overrides: float):
        unknown = set(overrides) - set(ANDREWS_PARAMETERS)
        if unknown:
            raise ValueError(f"AndrewsSqueezer: unknown parameter(s) {sorted(unknown)}")
        self.p = dict(ANDREWS_PARAMETERS, **{k: float(v) for k, v in overrides.items()})
        self.q0 = self.Q0_PUBLISHED.copy()
        self.v0 = np.zeros(7)

    # --- dynamics ------------------------------------------------------------------------------
    def M(self, t: float, q: Array) -> Array:
        p = self.p
        sph, som = np.sin(q[3]), np.sin(q[5])
        cth = np.cos(q[1])
        m2, da, rr = p["m2"], p["da"], p["rr"]
        ee, zt = p["e"] - p["ea"], p["zt"]
        zz, u = p["zf"] - p["fa"], p["u"]
        M = np.zeros((7, 7))
        M[0, 0] = p["m1"] * p["ra"] ** 2 + m2 * (rr**2 - 2 * da * rr * cth + da**2) + p["i1"] + p["i2"]
        M[1, 0] = M[0, 1] = m2 * (da**2 - da * rr * cth) + p["i2"]
        M[1, 1] = m2 * da**2 + p["i2"]
        M[2, 2] = p["m3"] * (p["sa"] ** 2 + p["sb"] ** 2) + p["i3"]
        M[3, 3] = p["m4"] * ee**2 + p["i4"]
        M[4, 3] = M[3, 4] = p["m4"] * (ee**2 + zt * ee * sph) + p["i4"]
        M[4, 4] = (p["m4"] * (zt**2 + 2 * zt * ee * sph + ee**2) + p["m5"] * (p["ta"] ** 2 + p["tb"] ** 2)
                   + p["i4"] + p["i5"])
        M[5, 5] = p["m6"] * zz**2 + p["i6"]
        M[6, 5] = M[5, 6] = p["m6"] * (zz**2 - u * zz * som) + p["i6"]
        M[6, 6] = (p["m6"] * (zz**2 - 2 * u * zz * som + u**2) + p["m7"] * (p["ua"] ** 2 + p["ub"] ** 2)
                   + p["i6"] + p["i7"])
        return M

    def _spring(self, q: Array):
        """Spring attachment D, its γ-derivative, length L and force F on D [N] (global)."""
        p = self.p
        sg, cg = np.sin(q[2]), np.cos(q[2])
        rD = np.array([p["sd"] * cg + p["sc"] * sg + p["xb"], p["sd"] * sg - p["sc"] * cg + p["yb"]])
        drD = np.array([p["sc"] * cg - p["sd"] * sg, p["sd"] * cg + p["sc"] * sg])
        d = rD - np.array([p["xc"], p["yc"]])
        L = float(np.hypot(*d))
        F = -p["c0"] * (L - p["l0"]) / L * d
        return rD, drD, L, F

    def Q(self, t: float, q: Array, v: Array) -> Array:
        p = self.p
        bep, thp, php, dep, omp, epp = v[0], v[1], v[3], v[4], v[5], v[6]
        c1 = p["m2"] * p["da"] * p["rr"]
        c4 = p["m4"] * p["zt"] * (p["e"] - p["ea"])
        c6 = p["m6"] * p["u"] * (p["zf"] - p["fa"])
        sth, cph, com = np.sin(q[1]), np.cos(q[3]), np.cos(q[5])
        _, drD, _, F = self._spring(q)
        return np.array([
            p["mom"] - c1 * thp * (thp + 2 * bep) * sth,
            c1 * bep**2 * sth,
            F @ drD,
            c4 * dep**2 * cph,
            -c4 * php * (php + 2 * dep) * cph,
            -c6 * epp**2 * com,
            c6 * omp * (omp + 2 * epp) * com,
        ])

    # --- constraints ---------------------------------------------------------------------------
    def Phi(self, t: float, q: Array) -> Array:
        p = self.p
        b, th, g, ph, de, om, ep = q
        cx = p["rr"] * np.cos(b) - p["d"] * np.cos(b + th)
        cy = p["rr"] * np.sin(b) - p["d"] * np.sin(b + th)
        return np.array([
            cx - p["ss"] * np.sin(g) - p["xb"],
            cy + p["ss"] * np.cos(g) - p["yb"],
            cx - p["e"] * np.sin(ph + de) - p["zt"] * np.cos(de) - p["xa"],
            cy + p["e"] * np.cos(ph + de) - p["zt"] * np.sin(de) - p["ya"],
            cx - p["zf"] * np.cos(om + ep) - p["u"] * np.sin(ep) - p["xa"],
            cy - p["zf"] * np.sin(om + ep) + p["u"] * np.cos(ep) - p["ya"],
        ])

    def Phi_q(self, t: float, q: Array) -> Array:
        p = self.p
        b, th, g, ph, de, om, ep = q
        rr, d, ss, e, zt, zf, u = p["rr"], p["d"], p["ss"], p["e"], p["zt"], p["zf"], p["u"]
        sbt, cbt = np.sin(b + th), np.cos(b + th)
        G = np.zeros((6, 7))
        G[0::2, 0] = -rr * np.sin(b) + d * sbt
        G[1::2, 0] = rr * np.cos(b) - d * cbt
        G[0::2, 1] = d * sbt
        G[1::2, 1] = -d * cbt
        G[0, 2] = -ss * np.cos(g)
        G[1, 2] = -ss * np.sin(g)
        spd, cpd = np.sin(ph + de), np.cos(ph + de)
        G[2, 3] = -e * cpd
        G[2, 4] = -e * cpd + zt * np.sin(de)
        G[3, 3] = -e * spd
        G[3, 4] = -e * spd - zt * np.cos(de)
        soe, coe = np.sin(om + ep), np.cos(om + ep)
        G[4, 5] = zf * soe
        G[4, 6] = zf * soe - u * np.cos(ep)
        G[5, 5] = -zf * coe
        G[5, 6] = -zf * coe - u * np.sin(ep)
        return G

    def nu(self, t: float, q: Array) -> Array:
        return np.zeros(6)

    def gamma(self, t: float, q: Array, v: Array) -> Array:
        r"""``γ = −g_qq(q̇, q̇)`` (the constraints do not depend on time)."""
        p = self.p
        b, th, g, ph, de, om, ep = q
        bp, thp, gp, php, dep, omp, epp = v
        rr, d, ss, e, zt, zf, u = p["rr"], p["d"], p["ss"], p["e"], p["zt"], p["zf"], p["u"]
        w1, w12 = bp**2, (bp + thp) ** 2
        ax = -rr * np.cos(b) * w1 + d * np.cos(b + th) * w12
        ay = -rr * np.sin(b) * w1 + d * np.sin(b + th) * w12
        w45, w5 = (php + dep) ** 2, dep**2
        w67, w7 = (omp + epp) ** 2, epp**2
        gqq = np.array([
            ax + ss * np.sin(g) * gp**2,
            ay - ss * np.cos(g) * gp**2,
            ax + e * np.sin(ph + de) * w45 + zt * np.cos(de) * w5,
            ay - e * np.cos(ph + de) * w45 + zt * np.sin(de) * w5,
            ax + zf * np.cos(om + ep) * w67 + u * np.sin(ep) * w7,
            ay + zf * np.sin(om + ep) * w67 - u * np.cos(ep) * w7,
        ])
        return -gqq

    # --- diagnostics -----------------------------------------------------------------------------
    def energy(self, t: float, q: Array, v: Array) -> float:
        """``½ q̇ᵀ M q̇ + ½ c0 (L − l0)² − mom·β`` [J] (conserved by the exact motion)."""
        _, _, L, _ = self._spring(q)
        return float(0.5 * v @ self.M(t, q) @ v + 0.5 * self.p["c0"] * (L - self.p["l0"]) ** 2 - self.p["mom"] * q[0])

    def reaction_groups(self) -> dict[str, NDArray[np.int64]]:
        return {"joint B": np.array([0, 1]), "joint A (Phi, delta)": np.array([2, 3]),
                "joint A (Omega, epsilon)": np.array([4, 5])}


class CarAxis(ConstrainedSystem):
    r"""The car-axis problem: index-3, stiff, with a time-dependent constraint (bumpy road).

    Two points ``(x_l, y_l)`` and ``(x_r, y_r)`` [m] of a car axis of length L, each carried by
    a spring of stiffness 1 and free length L0 (the left to the origin, the right to the
    wheel contact point ``(x_b, y_b)``); the wheel rolls over a bump ``y_b = r sin(ωt)``,
    ``x_b = √(L² − y_b²)``.  With ``k = M ε²/2``, ``L_l = |(x_l, y_l)|``,
    ``L_r = |(x_r − x_b, y_r − y_b)|`` (test set, problem "caraxis")::

        k u̇_l = (L0 − L_l) x_l/L_l            + λ1 x_b + 2λ2 (x_l − x_r)
        k v̇_l = (L0 − L_l) y_l/L_l            + λ1 y_b + 2λ2 (y_l − y_r) − k g
        k u̇_r = (L0 − L_r)(x_r − x_b)/L_r                − 2λ2 (x_l − x_r)
        k v̇_r = (L0 − L_r)(y_r − y_b)/L_r                − 2λ2 (y_l − y_r) − k g
        0 = x_b x_l + y_b y_l
        0 = (x_l − x_r)² + (y_l − y_r)² − L²

    In the form of :mod:`core.system`: ``M = k I₄``, ``Q`` the spring and gravity forces,
    ``Φ`` the two constraints above, ``Φ_q = [[x_b, y_b, 0, 0], 2 [Δx, Δy, −Δx, −Δy]]``
    (``Δ = left − right``), so ``λ_ours = −λ_published``.  Time terms:
    ``ν = −(ẋ_b x_l + ẏ_b y_l, 0)`` and
    ``γ = (−2(ẋ_b u_l + ẏ_b v_l) − (ẍ_b x_l + ÿ_b y_l), −2(Δu² + Δv²))`` with
    ``ẏ_b = rω cos ωt``, ``ÿ_b = −rω² sin ωt``, ``ẋ_b = −y_b ẏ_b/x_b``,
    ``ẍ_b = −(ẋ_b² + ẏ_b² + y_b ÿ_b)/x_b``.

    Parameters (test set): ε = 1e−2, M = 10, L = 1, L0 = 0.5, r = 0.1, ω = 10, g = 1,
    t ∈ [0, 3]; initial state ``(x_l, y_l, x_r, y_r) = (0, L0, L, L0)``,
    ``(u_l, v_l, u_r, v_r) = (−L0/L, 0, −L0/L, 0)`` (consistent: ``r ω = 1``).  The problem is
    dimensionless in the test set; the units are nominal.

    Reference solution at ``t = 3`` (:attr:`reference`): test set ``caraxis.f``, subroutine
    ``soln`` (computed by the test-set authors with RADAU at tight tolerances).

    References
    ----------
    F. Mazzia, C. Magherini, *Test Set for IVP Solvers*, release 2.4, Univ. of Bari, 2008,
    problem "Car axis".
    E. Hairer, G. Wanner, *Solving ODEs II*, Springer, 1996 (car-axis problem, after
    Rentrop, Roche & Steinebach 1989).
    G. Rentrop, M. Roche, G. Steinebach, "The application of Rosenbrock–Wanner type methods
    with stepsize control in differential-algebraic equations", Numer. Math. 55 (1989) 545–563.
    """

    name = "car_axis"
    n_q = n_v = 4
    n_c = 2
    mass_is_constant = True
    is_conservative = False
    coordinate_names = ["xl [m]", "yl [m]", "xr [m]", "yr [m]"]
    velocity_names = ["ul [m/s]", "vl [m/s]", "ur [m/s]", "vr [m/s]"]
    constraint_names = ["wheel contact (x_b x_l + y_b y_l)", "axis length"]

    #: Published reference solution at t = 3 (test set caraxis.f, subroutine soln);
    #: multipliers converted to our sign convention (λ_ours = −λ_published).
    reference = dict(
        t=3.0,
        q=np.array([0.4934557842755629e-1, 0.4969894602303324, 0.1041742524885400e1, 0.3739110272652214]),
        v=np.array([-0.7705836840321485e-1, 0.7446866596327776e-2, 0.1755681574942899e-1, 0.7703410437794031]),
        lam=-np.array([-0.4736886750784630e-2, -0.1104680411345730e-2]),
        source="Mazzia & Magherini, Test Set for IVP Solvers 2.4 (2008), caraxis.f, subroutine soln",
    )

    def __init__(self, eps: float = 1e-2, mass: float = 10.0, length: float = 1.0, free_length: float = 0.5,
                 bump_amplitude: float = 0.1, bump_omega: float = 10.0, g: float = 1.0):
        for label, val in (("eps", eps), ("mass", mass), ("length", length), ("free_length", free_length),
                           ("bump_omega", bump_omega)):
            if not (np.isfinite(val) and val > 0):
                raise ValueError(f"CarAxis: {label} must be > 0, got {val}")
        if not abs(bump_amplitude) < length:
            raise ValueError(f"CarAxis: bump_amplitude must be smaller than length, got {bump_amplitude}")
        self.eps, self.mass, self.L, self.L0 = float(eps), float(mass), float(length), float(free_length)
        self.r, self.omega, self.g = float(bump_amplitude), float(bump_omega), float(g)
        self.k = self.mass * self.eps**2 / 2.0
        self.q0 = np.array([0.0, self.L0, self.L, self.L0])
        self.v0 = np.array([-self.L0 / self.L, 0.0, -self.L0 / self.L, 0.0])

    def wheel(self, t: float) -> tuple[Array, Array, Array]:
        """Wheel contact point ``(x_b, y_b)`` and its first and second time derivatives."""
        r, w, L = self.r, self.omega, self.L
        yb, ybd, ybdd = r * np.sin(w * t), r * w * np.cos(w * t), -r * w * w * np.sin(w * t)
        xb = np.sqrt(L * L - yb * yb)
        xbd = -yb * ybd / xb
        xbdd = -(xbd**2 + ybd**2 + yb * ybdd) / xb
        return np.array([xb, yb]), np.array([xbd, ybd]), np.array([xbdd, ybdd])

    def M(self, t: float, q: Array) -> Array:
        return self.k * np.eye(4)

    def Q(self, t: float, q: Array, v: Array) -> Array:
        (xb, yb), _, _ = self.wheel(t)
        xl, yl, xr, yr = q
        Ll = np.hypot(xl, yl)
        Lr = np.hypot(xr - xb, yr - yb)
        return np.array([
            (self.L0 - Ll) * xl / Ll,
            (self.L0 - Ll) * yl / Ll - self.k * self.g,
            (self.L0 - Lr) * (xr - xb) / Lr,
            (self.L0 - Lr) * (yr - yb) / Lr - self.k * self.g,
        ])

    def Phi(self, t: float, q: Array) -> Array:
        (xb, yb), _, _ = self.wheel(t)
        xl, yl, xr, yr = q
        return np.array([xb * xl + yb * yl, (xl - xr) ** 2 + (yl - yr) ** 2 - self.L**2])

    def Phi_q(self, t: float, q: Array) -> Array:
        (xb, yb), _, _ = self.wheel(t)
        dx, dy = q[0] - q[2], q[1] - q[3]
        return np.array([[xb, yb, 0.0, 0.0], [2 * dx, 2 * dy, -2 * dx, -2 * dy]])

    def nu(self, t: float, q: Array) -> Array:
        _, (xbd, ybd), _ = self.wheel(t)
        return np.array([-(xbd * q[0] + ybd * q[1]), 0.0])

    def gamma(self, t: float, q: Array, v: Array) -> Array:
        _, (xbd, ybd), (xbdd, ybdd) = self.wheel(t)
        du, dv = v[0] - v[2], v[1] - v[3]
        return np.array([
            -2.0 * (xbd * v[0] + ybd * v[1]) - (xbdd * q[0] + ybdd * q[1]),
            -2.0 * (du * du + dv * dv),
        ])

    def Q_q(self, t: float, q: Array, v: Array) -> Array:
        """Exact spring stiffness blocks ``−[(1 − L0/L) I + (L0/L) n nᵀ]`` per spring."""
        (xb, yb), _, _ = self.wheel(t)
        K = np.zeros((4, 4))
        for sl, d in ((slice(0, 2), q[0:2]), (slice(2, 4), q[2:4] - np.array([xb, yb]))):
            Ld = np.hypot(*d)
            n = d / Ld
            K[sl, sl] = -((1.0 - self.L0 / Ld) * np.eye(2) + (self.L0 / Ld) * np.outer(n, n))
        return K

    def Q_v(self, t: float, q: Array, v: Array) -> Array:
        return np.zeros((4, 4))

    def energy(self, t: float, q: Array, v: Array) -> float:
        """Kinetic + spring + gravity energy [J] (not conserved: the road moves)."""
        (xb, yb), _, _ = self.wheel(t)
        Ll = np.hypot(q[0], q[1])
        Lr = np.hypot(q[2] - xb, q[3] - yb)
        return float(0.5 * self.k * v @ v + 0.5 * ((Ll - self.L0) ** 2 + (Lr - self.L0) ** 2)
                     + self.k * self.g * (q[1] + q[3]))

    def reaction_groups(self) -> dict[str, NDArray[np.int64]]:
        return {"wheel contact": np.array([0]), "axis length": np.array([1])}



#: Parameters of Simeon's slider crank with an elastic rod (test set ``crank.f``, ``RESMBS``):
#: masses [kg], lengths [m], inertias [kg m²], E [Pa], rod section BB × HH [m], ρ [kg/m³], Ω [rad/s].
#: PI is the code's truncated π, which enters the stiffness and coupling terms.
SIMEON_CRANK_PARAMETERS: dict[str, float] = dict(
    M1=0.36, M2=0.151104, M3=0.075552, L1=0.15, L2=0.30, J1=0.002727, J2=0.0045339259,
    EE=0.20e12, BB=0.008, HH=0.008, RHO=7870.0, GRAV=0.0, OMEGA=150.0, PI=3.1415927,
)


class SimeonCrank(ConstrainedSystem):
    r"""Slider crank with an elastic connecting rod, as published (Simeon 1996; test set "crank").

    Coordinates ``p = (φ₁, φ₂, x₃, q₁, q₂, q₃, q₄)``: crank angle, rod angle, slider position and
    the rod's deformation in a frame attached at the crank pin with its x axis through the rod's
    other end; lateral ``v(ξ) = q₁ sin πξ + q₂ sin 2πξ``, axial ``u(ξ) = q₃ 4ξ(1−ξ) + q₄ ξ(2ξ−1)``
    (ξ = s/L₂).  The midpoint deflection in that frame is ``q₁``.  Mass matrix, forces (with
    the quadratic-velocity terms) and constraints exactly as in the test set's ``RESMBS`` (Simeon,
    18.2.98; test set release 2.4), with its options: ``stiffness="linear"`` (the reference) or
    ``"nonlinear"`` (its geometric stiffness term), ``damping`` off or on (its "0.5 %" matrix).

    Constraints (index 3; the test set integrates the index-2 form)::

        Φ = [L₁ sin φ₁ + (L₂ + q₄) sin φ₂,
             x₃ − L₁ cos φ₁ − (L₂ + q₄) cos φ₂,
             φ₁ − Ω t]

    **The axial mass block.** The published code sets it to ``ρBHL₂ [[8, 1], [1, 2]]``, fifteen
    times the consistent mass of its quadratic shape functions (∫N₃² = 8/15, ∫N₃N₄ = 1/15,
    ∫N₄² = 2/15); the published initial values and reference solution are consistent only with the
    block as coded, so ``axial_mass="published"`` (default) reproduces the test set and
    ``axial_mass="consistent"`` divides it by 15.

    Initial values: ``initial="smooth"`` (the test set's set 1, "close to smooth motion", with the
    refined digits that reproduce its reference) or ``"rigid"`` (set 2: rod straight and
    undeformed, rigid-mechanism velocities).  Reference at t = 0.1 s (:attr:`reference`): the test
    set's ``cranksoln`` (MEBDFI, rtol = atol = 1e-14; set 1, linear stiffness, no damping).

    References
    ----------
    B. Simeon, "Modelling a flexible slider crank mechanism by a mixed system of DAEs and PDEs",
    Math. Modelling of Systems 2 (1996) 1–18; F. Mazzia, C. Magherini, Test Set for IVP Solvers,
    release 2.4, 2008, problem "crank" (``crank.f``: ``RESMBS``, ``init``, ``init2``,
    ``cranksoln``), as distributed with the R package deTestSet (``src/Ex_crank.f``).
    """

    name = "simeon_crank"
    n_q = n_v = 7
    n_c = 3
    mass_is_constant = False
    is_conservative = False
    coordinate_names = ["phi1 [rad]", "phi2 [rad]", "x3 [m]", "q1 [m]", "q2 [m]", "q3 [m]", "q4 [m]"]
    velocity_names = ["phi1_dot [rad/s]", "phi2_dot [rad/s]", "x3_dot [m/s]", "q1_dot [m/s]", "q2_dot [m/s]",
                      "q3_dot [m/s]", "q4_dot [m/s]"]
    constraint_names = ["rod end on the slider axis (y)", "rod end at the slider (x)", "crank drive"]

    #: set 1 with the refined digits (they reproduce ``cranksoln``; the 9-digit values of ``init``
    #: move q₁(0.1) by about 2e-8 relative)
    SMOOTH = dict(
        q=np.array([0.0, 0.0, 4.500169330000000e-01, 0.0, 0.0, 1.033398630000000e-05, 1.693279690000000e-05]),
        v=np.array([1.500000000000000e+02, -7.499576703969453e+01, -2.689386719979040e-06, 4.448961125815990e-01,
                    4.634339319238670e-03, -1.785910760000550e-06, -2.689386719979040e-06]),
    )
    #: set 2 (``init2``): on the rigid motion, rod undeformed
    RIGID = dict(q=np.array([0.0, 0.0, 0.45, 0.0, 0.0, 0.0, 0.0]),
                 v=np.array([150.0, -75.0, 0.0, 0.0, 0.0, 0.0, 0.0]))

    #: published solution at t = 0.1 s (set 1, linear stiffness, no damping, axial mass as published)
    reference = dict(
        t=0.1,
        q=np.array([0.1500000000000104e+02, -0.3311734988256260e+00, 0.1697373328427860e+00,
                    0.1893192899613509e-03, 0.2375751249879174e-04, -0.5323896770569702e-05,
                    -0.8363313279112129e-05]),
        v=np.array([0.1500000000000000e+03, 0.6025346755138369e+02, -0.8753116326670527e+01,
                    -0.3005541400289738e-01, -0.5500431812571696e-02, 0.4974111734266989e-03,
                    0.1105560003626645e-02]),
        lam=np.array([-0.6232935833287916e+02, -0.1637920993367306e+03, 0.2529857947066878e+02]),
        source=("Mazzia & Magherini, Test Set for IVP Solvers, crank.f, subroutine cranksoln (MEBDFI, "
                "rtol = atol = 1e-14), as in deTestSet src/Ex_crank.f"),
    )

    def __init__(self, initial: str = "smooth", stiffness: str = "linear", damping: bool = False,
                 axial_mass: str = "published", **overrides: float):
        if initial not in ("smooth", "rigid"):
            raise ValueError(f"SimeonCrank: initial must be 'smooth' (set 1) or 'rigid' (set 2), got {initial!r}")
        if stiffness not in ("linear", "nonlinear"):
            raise ValueError(f"SimeonCrank: stiffness must be 'linear' or 'nonlinear', got {stiffness!r}")
        if axial_mass not in ("published", "consistent"):
            raise ValueError(f"SimeonCrank: axial_mass must be 'published' or 'consistent', got {axial_mass!r}")
        unknown = set(overrides) - set(SIMEON_CRANK_PARAMETERS)
        if unknown:
            raise ValueError(f"SimeonCrank: unknown parameter(s) {sorted(unknown)}")
        self.p = p = dict(SIMEON_CRANK_PARAMETERS, **{k: float(v) for k, v in overrides.items()})
        self.nonlinear, self.damping = stiffness == "nonlinear", bool(damping)
        start = self.SMOOTH if initial == "smooth" else self.RIGID
        self.q0, self.v0 = start["q"].copy(), start["v"].copy()
        PI, L2 = p["PI"], p["L2"]
        # the published x₃ is rounded to 9 digits (2e-10 m off the loop closure, which an index-2/3
        # integrator must satisfy exactly): take it from the closure
        self.q0[2] = p["L1"] * np.cos(self.q0[0]) + (L2 + self.q0[6]) * np.cos(self.q0[1])
        facm, fack, facb = p["RHO"] * p["BB"] * p["HH"] * L2, p["EE"] * p["BB"] * p["HH"] / L2, p["BB"] * p["HH"] * L2
        MQ = np.zeros((4, 4))
        MQ[0, 0] = MQ[1, 1] = 0.5 * facm
        MQ[2:, 2:] = facm * np.array([[8.0, 1.0], [1.0, 2.0]]) / (1.0 if axial_mass == "published" else 15.0)
        KQ = np.zeros((4, 4))
        KQ[0, 0] = fack * PI**4 / 24.0 * (p["HH"] / L2) ** 2
        KQ[1, 1] = fack * PI**4 * 2.0 / 3.0 * (p["HH"] / L2) ** 2
        KQ[2:, 2:] = fack * np.array([[16.0, -8.0], [-8.0, 7.0]]) / 3.0
        BQ = np.zeros((4, 4))
        BQ[0, 2], BQ[0, 3], BQ[1, 3] = -facb * 16.0 / PI**3, facb * (8.0 / PI**3 - 1.0 / PI), facb * 0.5 / PI
        BQ[2, 0], BQ[3, 0], BQ[3, 1] = -BQ[0, 2], -BQ[0, 3], -BQ[1, 3]
        self.c1 = np.array([0.0, 0.0, facb * 2.0 / 3.0, facb / 6.0])
        self.c2 = np.array([facb * 2.0 / PI, 0.0, 0.0, 0.0])
        self.c12 = np.array([0.0, 0.0, L2 * facb / 3.0, L2 * facb / 6.0])
        self.c21 = np.array([L2 * facb / PI, -L2 * facb * 0.5 / PI, 0.0, 0.0])
        DQ = np.zeros((4, 4))
        if self.damping:  # as coded (DQ(3,4) carries one digit fewer than DQ(4,3))
            DQ[0, 0], DQ[1, 1] = 5.0, 25.0
            DQ[2, 2], DQ[2, 3] = 0.5 * 2.308375455264791e2, -0.5 * 2.62688487992052e2
            DQ[3, 2], DQ[3, 3] = -0.5 * 2.626884879920526e2, 0.5 * 4.217421837156818e2
        self.MQ, self.KQ, self.BQ, self.DQ = MQ, KQ, BQ, DQ

    def M(self, t: float, q: Array) -> Array:
        p = self.p
        L1, L2, M2, RHO = p["L1"], p["L2"], p["M2"], p["RHO"]
        Q = q[3:]
        c12p, s12p = np.cos(q[0] - q[1]), np.sin(q[0] - q[1])
        A = np.zeros((7, 7))
        A[0, 0] = p["J1"] + M2 * L1 * L1
        A[0, 1] = 0.5 * L1 * L2 * M2 * c12p + RHO * L1 * (s12p * self.c2 @ Q + c12p * self.c1 @ Q)
        A[1, 1] = p["J2"] + Q @ self.MQ @ Q + 2.0 * RHO * self.c12 @ Q
        A[2, 2] = p["M3"]
        A[0, 3:] = RHO * L1 * (-s12p * self.c1 + c12p * self.c2)
        A[1, 3:] = RHO * self.c21 + RHO * (Q @ self.BQ)
        A[3:, 3:] = self.MQ
        return np.triu(A) + np.triu(A, 1).T

    def Q(self, t: float, q: Array, v: Array) -> Array:
        p = self.p
        L1, L2, M2, RHO, G = p["L1"], p["L2"], p["M2"], p["RHO"], p["GRAV"]
        Q, QD = q[3:], v[3:]
        c1p, c2p, s12p, c12p = np.cos(q[0]), np.cos(q[1]), np.sin(q[0] - q[1]), np.cos(q[0] - q[1])
        s2p = np.sin(q[1])
        c1, c2, c12 = self.c1, self.c2, self.c12
        MQQ, BQQD = self.MQ @ Q, self.BQ @ QD
        F = np.zeros(7)
        F[0] = -0.5 * L1 * G * (p["M1"] + 2.0 * M2) * c1p - 0.5 * L1 * L2 * M2 * v[1] ** 2 * s12p
        F[1] = -0.5 * L2 * G * M2 * c2p + 0.5 * L1 * L2 * M2 * v[0] ** 2 * s12p
        F[0] += (RHO * L1 * v[1] ** 2 * (-s12p * c1 @ Q + c12p * c2 @ Q)
                 - 2.0 * RHO * L1 * v[1] * (c12p * c1 @ QD + s12p * c2 @ QD))
        F[1] += (RHO * L1 * v[0] ** 2 * (s12p * c1 @ Q - c12p * c2 @ Q) - 2.0 * RHO * v[1] * c12 @ QD
                 - 2.0 * v[1] * QD @ MQQ - RHO * QD @ BQQD - RHO * G * (c2p * c1 @ Q - s2p * c2 @ Q))
        F[3:] = (v[1] ** 2 * MQQ + RHO * (v[1] ** 2 * c12 + L1 * v[0] ** 2 * (c12p * c1 + s12p * c2)
                                          + 2.0 * v[1] * BQQD)
                 - RHO * G * (s2p * c1 + c2p * c2) - self.KQ @ Q - self.DQ.T @ QD)
        if self.nonlinear:
            fk = 0.5 * p["EE"] * p["BB"] * p["HH"] / L2**2 * p["PI"] ** 2
            fb = 80.0 / (p["PI"] ** 2 * 9.0)
            F[3] -= fk * (Q[0] * Q[3] - fb * Q[1] * (-4 * Q[2] + 2 * Q[3]))
            F[4] -= fk * (4 * Q[1] * Q[3] - fb * Q[0] * (-4 * Q[2] + 2 * Q[3]))
            F[5] -= fk * 4.0 * fb * Q[0] * Q[1]
            F[6] -= fk * (0.5 * Q[0] ** 2 + 2 * Q[1] ** 2 - 2 * fb * Q[0] * Q[1])
        return F

    def Phi(self, t: float, q: Array) -> Array:
        p = self.p
        L1, L2 = p["L1"], p["L2"]
        return np.array([L1 * np.sin(q[0]) + (L2 + q[6]) * np.sin(q[1]),
                         q[2] - L1 * np.cos(q[0]) - (L2 + q[6]) * np.cos(q[1]),
                         q[0] - p["OMEGA"] * t])

    def Phi_q(self, t: float, q: Array) -> Array:
        L1, L2 = self.p["L1"], self.p["L2"]
        G = np.zeros((3, 7))
        G[0, 0], G[0, 1], G[0, 6] = L1 * np.cos(q[0]), (L2 + q[6]) * np.cos(q[1]), np.sin(q[1])
        G[1, 0], G[1, 1], G[1, 2], G[1, 6] = L1 * np.sin(q[0]), (L2 + q[6]) * np.sin(q[1]), 1.0, -np.cos(q[1])
        G[2, 0] = 1.0
        return G

    def nu(self, t: float, q: Array) -> Array:
        return np.array([0.0, 0.0, self.p["OMEGA"]])

    def gamma(self, t: float, q: Array, v: Array) -> Array:
        L1, L2 = self.p["L1"], self.p["L2"]
        s1, c1, s2, c2 = np.sin(q[0]), np.cos(q[0]), np.sin(q[1]), np.cos(q[1])
        return np.array([
            L1 * s1 * v[0] ** 2 + (L2 + q[6]) * s2 * v[1] ** 2 - 2.0 * v[1] * c2 * v[6],
            -L1 * c1 * v[0] ** 2 - (L2 + q[6]) * c2 * v[1] ** 2 - 2.0 * v[1] * s2 * v[6],
            0.0,
        ])

    def reaction_groups(self) -> dict[str, NDArray[np.int64]]:
        return {"wrist pin": np.array([0, 1]), "crank drive": np.array([2])}
