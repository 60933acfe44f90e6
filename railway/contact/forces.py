"""Wheel-rail contact forces of all contacts of a contact search in one call.

For every contact candidate of a :class:`railway.contact.search.ContactResult` with positive
penetration delta, the forces on the wheel are::

    A = (k_wheel_rolling + k_rail_rolling)/2,  B = (k_wheel_lateral + k_rail_lateral)/2
    Hertz (Johnson 1985, sect. 4.2):  N_e = K_h(A, B) delta^(3/2),  semi-axes a (rolling), b
    Lankarani-Nikravesh (1990, Eq. 17):  N = N_e [1 + 3 (1 - c_e^2)/4 * delta_dot / v0],  N >= 0
    creepages (Kalker 1990, ch. 1):    xi = (v_w . t)/V,  eta = (v_w . l)/V,  phi = (omega . n)/V
    creep law (any of railway.contact.creep):  Fx, Fy, Mz in the contact frame (t, l, n)
    force on the wheel (global):       F = N n + Fx t + Fy l,   moment Mz n

with v_w = v_ws + omega x (p - r_ws) the velocity of the wheel material point at the contact
(rail fixed), delta_dot = -v_w . n, t the wheelset's forward axis projected onto the tangent
plane, l = n x t and V = ``|v_ws . t|`` the rolling speed.  Body 1 of :mod:`core.contact_laws` is the
wheel, body 2 the rail, x the rolling and y the lateral direction.

The Hertz theory and the Lankarani-Nikravesh law are defined once, in :mod:`core.contact_laws`
(Eqs. H1-H7 and N1 there).  This module adds only what is specific to rolling wheels:

* :func:`wheel_rail_curvatures` -- Eq. (H1) with wheel and rail radii by name;
* :func:`lankarani_nikravesh_force` -- the law N1 with chi = 3 (1 - c_e^2)/4 and the
  *steady-rolling engagement-velocity floor* v0: the law was derived for impacts, where
  delta_dot^- is the approach velocity at first touch, but a rolling wheel has no impact and
  delta_dot^- is undefined (~0, which would make the damping singular).  We use the engagement
  velocity when the caller knows it and never less than the floor ``approach_velocity_floor``
  (default 0.1 m/s); :class:`ContactForces` uses the floor alone.

Two implementations, tested against each other:

* the reference (``compiled=False``) calls the project's validated modules
  (:func:`core.contact_laws.hertz_from_penetration`, :func:`lankarani_nikravesh_force`,
  :func:`railway.contact.creepage.creepages`, the :mod:`railway.contact.creep` laws) on the loaded contacts;
  it accepts every creep law of :data:`railway.contact.creep.CREEP_MODELS` (and user laws);
* the compiled kernel (numba) evaluates the same equations per contact in one loop, with the
  Hertz coefficients (ellipse ratio, m, n, K(e)) and Kalker's C11, C22, C23, C33 tabulated once
  against t = ln(B/A) on a uniform grid of 4001 nodes (linear interpolation; relative error
  below 1e-4 against the exact bisection and table interpolation, see the tests).  Its normal
  law is Eq. (N1) of :mod:`core.contact_laws` written for numba (tested to agree with
  :func:`core.contact_laws.hysteresis_force`).  It implements every creep law of the package
  (Kalker linear, Polach 2000, Shen–Hedrick–Elkins, Polach 2005, FASTSIM; the exact classes with
  the default ``join="scaled"``, see :func:`_kernel_code`); subclasses and user laws run on the
  reference path (``compiled="auto"``) -- a law is never replaced by another.

Conformal contacts (the concave S1002 flange root on the gauge corner) are not Hertzian (B <= 0);
both implementations clip the curvature ratio B/A and so treat them as elongated ellipses -- a
documented approximation, not a conformal-contact model.  The two sides are clipped differently:

* B/A <= 1000 (rho_max): a patch long in the rolling direction and narrow across (a/b up to ~70)
  is physical on the flange; the Manchester benchmark's flange patches have a/b = 17-23, and the
  Hertz p_max there agrees with CONTACT within 4 % (tests/railway/test_manchester_contact.py).
* B/A >= 1/36.536 (``_RHO_CONFORMAL``): the lateral semi-axis stays at most 10 times the rolling one
  (b/a <= 10, the end of Kalker's table, Kalker 1990 Table E.3).  Where the wheel and rail are
  nearly conformal across the profile (B -> 0 at a point of the flange flank over the gauge
  corner) the point curvature would give ellipses 100 mm and more wide: 8 µm of penetration then
  carries 42 kN (a 124 mm wide ellipse on a 30 mm high flank), and a few µm of gap between two
  nearby stationary points of that flat valley changed a wheel's load by tens of kN, which made
  the vehicle's forces depend on which point the search held.  The real patch is bounded by the
  higher-order terms of the gap that a point curvature does not see; the clip bounds it instead.

References
----------
Johnson, K. L. (1985). Contact Mechanics, ch. 4.  Lankarani, H. M. and Nikravesh, P. E. (1990).
J. Mech. Design 112:369-376, Eq. 17.  Kalker, J. J. (1990). Three-dimensional elastic bodies in
rolling contact, Table E.3.  Polach, O. (2000). VSD 33 Suppl.:728-739.
"""

from __future__ import annotations

import numpy as np

from core.contact_laws import (
    HYSTERESIS_LAWS,
    effective_modulus,
    ellipse_ratio,
    hertz_from_penetration,
    hysteresis_force,
    relative_curvatures,
)
from core.errors import InputError

from .creep import CreepForces, CreepModel, KalkerLinear, Polach2000, get_creep_model, kalker_coefficients

__all__ = ["ContactForces", "FORCE_KEYS", "REDUCTIONS", "lankarani_nikravesh_force", "wheel_rail_curvatures"]

#: terms of the contact forces that :class:`ContactForces` can switch off (its "Reduced models")
REDUCTIONS = ("spin_creepage", "roll_rate_creepage", "contact_angle", "gravitational_stiffness")
#: keys of the dictionary returned by :meth:`ContactForces.__call__`, arrays (n_wheels, 2)
FORCE_KEYS = ("N", "Fx", "Fy", "Mz", "xi", "eta", "phi", "a", "b", "delta_dot")
_RHO_MAX = 1e3
#: smallest relative lateral curvature B as a fraction of A: B >= A / _RHO_CONFORMAL keeps the lateral
#: semi-axis at most 10 times the rolling one (b/a <= 10, the end of Kalker's table; module docstring)
_RHO_CONFORMAL = 36.536


def _kernel_code(law: CreepModel | None):
    """(code, parameters) of ``law`` in the compiled kernel, or None.

    Codes: -1 normal forces only (``law`` None), 0 Kalker linear, 1 Polach 2000, 2
    Shen–Hedrick–Elkins, 3 Polach 2005 (parameters k_A, k_S, A, B, speed), 4 FASTSIM
    (parameters n_x, n_y).  Only the exact classes with the tables the kernel is built from
    (``join="scaled"``) qualify; subclasses, user laws and other joins run on the reference path.
    """
    from .creep import Fastsim, Polach2005, ShenHedrickElkins

    if law is None:
        return -1, np.zeros(5)
    if getattr(law, "join", None) != "scaled":
        return None
    t = type(law)
    if t is KalkerLinear:
        return 0, np.zeros(5)
    if t is Polach2000:
        return 1, np.zeros(5)
    if t is ShenHedrickElkins:
        return 2, np.zeros(5)
    if t is Polach2005:
        return 3, np.array([law.k_A, law.k_S, law.A, law.B, law.speed], float)
    if t is Fastsim:
        return 4, np.array([law.n_x, law.n_y, 0.0, 0.0, 0.0], float)
    return None


def wheel_rail_curvatures(R_wheel_rolling, R_wheel_lateral, R_rail_lateral, R_rail_rolling=np.inf):
    """Relative curvatures A (rolling) and B (lateral) of a wheel on a rail [1/m].

    Eq. (H1) of :mod:`core.contact_laws` with body 1 = wheel, body 2 = rail, x = rolling::

        A = (1/R_wheel_rolling + 1/R_rail_rolling)/2,  B = (1/R_wheel_lateral + 1/R_rail_lateral)/2

    Parameters
    ----------
    R_wheel_rolling : float or (n,) array_like
        Wheel rolling radius [m] (> 0).
    R_wheel_lateral : float or (n,) array_like
        Wheel profile radius in the lateral plane [m]; negative where the profile is concave
        (flange root), ``inf`` for a conical tread.
    R_rail_lateral : float or (n,) array_like
        Rail head profile radius [m].
    R_rail_rolling : float or (n,) array_like, optional
        Rail radius along the track (``inf`` for straight rail, finite for a roller rig).

    Returns
    -------
    A, B : (n,) ndarray
        Relative curvatures [1/m].

    Raises
    ------
    core.errors.InputError
        A zero radius or a non-Hertzian combination, naming the contact index and the radii
        (R1 = wheel, R2 = rail).
    """
    try:
        return relative_curvatures(R_wheel_rolling, R_wheel_lateral, R_rail_rolling, R_rail_lateral)
    except InputError as exc:
        raise InputError(f"wheel on rail (R1 = wheel, R2 = rail; x rolling, y lateral): {exc}") from None


def lankarani_nikravesh_force(penetration, penetration_rate, stiffness, restitution,
                              approach_velocity=None, approach_velocity_floor=0.1):
    """Lankarani-Nikravesh normal force of a rolling wheel, with the engagement-velocity floor [N].

    Eq. (N1) of :mod:`core.contact_laws` with p = 3/2 and chi = 3 (1 - c_e^2)/4
    (``HYSTERESIS_LAWS["lankarani-nikravesh"]``)::

        F_N = max(0, K_h delta^(3/2) [1 + 3 (1 - c_e^2)/4 * delta_dot / v0])  for delta > 0, else 0
        v0  = max(|approach_velocity|, approach_velocity_floor)

    Choice for steady rolling (documented trap, see the module docstring): with
    ``approach_velocity=None`` the floor alone is used, so the law acts as a Hertz spring with the
    linear-in-rate damper c(delta) = 3 (1 - c_e^2) K_h delta^(3/2) / (4 v0).  The force is clipped
    at zero because the law would otherwise pull the bodies together in fast separation
    (delta_dot < -4 v0/(3(1 - c_e^2))).

    Parameters
    ----------
    penetration : float or (n,) array_like
        delta [m].
    penetration_rate : float or (n,) array_like
        d delta/dt [m/s] (> 0 approaching).
    stiffness : float or (n,) array_like
        K_h [N/m^1.5] (from :func:`core.contact_laws.hertz_from_load`), >= 0.
    restitution : float or (n,) array_like
        Coefficient of restitution c_e in [0, 1].
    approach_velocity : float, (n,) array_like or None
        Velocity at engagement [m/s] (e.g. stored by a contact element when a flange contact is
        first detected); None in steady rolling.
    approach_velocity_floor : float
        Lower bound of v0 [m/s] (> 0).

    Returns
    -------
    (n,) ndarray
        Normal force [N].

    Raises
    ------
    core.errors.InputError
        NaN input, c_e outside [0, 1], K_h < 0 or a floor <= 0 (names the value).

    References
    ----------
    Lankarani & Nikravesh (1990), J. Mech. Design 112: 369-376, Eq. 17.
    """
    if not approach_velocity_floor > 0:
        raise InputError(f"approach_velocity_floor must be > 0, got {approach_velocity_floor!r}")
    chi = HYSTERESIS_LAWS["lankarani-nikravesh"].factor(restitution)
    v0 = np.full(1, float(approach_velocity_floor))
    if approach_velocity is not None:
        va = np.asarray(approach_velocity, dtype=float)
        if np.any(np.isnan(va)):
            raise InputError(f"approach_velocity contains NaN: {va.tolist()!r}")
        v0 = np.maximum(np.abs(np.atleast_1d(va)), v0)
    return hysteresis_force(np.atleast_1d(penetration), np.atleast_1d(penetration_rate),
                            np.atleast_1d(stiffness), chi, v0, 1.5).force


try:  # optional dependency; module-level kernels so that numba's disk cache finds them
    import numba as _numba

    import core.compiled  # noqa: F401  (keys the disk cache on all compiled sources: core.compiled.cache)
except ImportError:  # pragma: no cover - numba missing
    _numba = None

if _numba is not None:
    @_numba.njit(cache=True)
    def normal_law(Kh, d, dd, chi, v0):
        """Eq. (N1) of :mod:`core.contact_laws` with p = 3/2, for numba (one contact).

        F = max(0, K_h d^(3/2) (1 + chi dd / v0)) for d > 0, else 0; the one definition is
        :func:`core.contact_laws.hysteresis_force` (tested to agree).
        """
        if not (d > 0.0):
            return 0.0
        F = Kh * d**1.5 * (1.0 + chi * dd / v0)
        return F if F > 0.0 else 0.0

    @_numba.njit(cache=True)
    def she_factor(Fxl, Fyl, mu, N):
        """Shen–Hedrick–Elkins factor F_R'/F_R of the linear resultant (railway.contact.creep._she_factor)."""
        beta = np.sqrt(Fxl * Fxl + Fyl * Fyl) / (mu * N)
        return 1.0 - beta / 3.0 + beta * beta / 27.0 if beta < 3.0 else 1.0 / beta

    @_numba.njit(cache=True)
    def polach(xi, eta, phi, N, a, b, G, mu, C11, C22, C23, kA, kS):
        """Polach's method (railway.contact.creep._polach): Fx and Fy including the spin part."""
        s = np.sqrt(xi * xi + eta * eta)
        sys_ = eta + phi * a
        syC = sys_ if abs(sys_) > abs(eta) else eta
        sC = np.sqrt(xi * xi + syC * syC)
        if not (sC > 0.0):
            return 0.0, 0.0
        if s > 0.0:
            cjj = np.sqrt((C11 * xi / s) ** 2 + (C22 * eta / s) ** 2)
        else:
            cjj = C22
        eps = np.pi * G * a * b * cjj * sC / (4.0 * N * mu)
        F = 2.0 * N * mu / np.pi * (kA * eps / (1.0 + (kA * eps) ** 2) + np.arctan(kS * eps))
        Fx = -F * xi / sC
        Fy = -F * eta / sC
        KS = 1.0 + 6.3 * (1.0 - np.exp(-a / b))
        epsM = 8.0 / 3.0 * G * b * np.sqrt(a * b) / (N * mu) * C23 * abs(syC) / KS
        dl = (epsM * epsM - 1.0) / (epsM * epsM + 1.0)
        q = 1.0 - dl * dl
        if q < 0.0:
            q = 0.0
        KM = abs(epsM) * (dl**3 / 3.0 - dl * dl / 2.0 + 1.0 / 6.0) - np.sqrt(q**3) / 3.0
        Fy += 9.0 / 16.0 * a * mu * N * KM * KS * phi / sC
        return Fx, Fy

    @_numba.njit(cache=True)
    def fastsim(xi, eta, phi, N, a, b, G, mu, C11, C22, C23, nx, ny):
        """FASTSIM strip marching (railway.contact.creep.Fastsim), one contact."""
        L1 = 8.0 * a / (3.0 * G * C11)
        L2 = 8.0 * a / (3.0 * G * C22)
        L3 = np.pi * a * np.sqrt(a / b) / (4.0 * G * C23)
        dy = 2.0 * b / ny
        pmax_c = 2.0 * N / (np.pi * a * b)
        Fx = 0.0
        Fy = 0.0
        Mz = 0.0
        for j in range(ny):
            yb = (j + 0.5) / ny * 2.0 - 1.0
            y = b * yb
            aj = a * np.sqrt(1.0 - yb * yb)
            dx = 2.0 * aj / nx
            ax = xi / L1 - phi / L3 * y
            ay = eta / L2
            sp = phi / L3
            px = 0.0
            py = 0.0
            for i in range(nx):
                x_c = aj - (i + 0.5) * dx
                x_b = aj - i * dx
                h = 0.5 * dx if i == 0 else dx
                x_mid = x_b - 0.25 * dx if i == 0 else x_b
                px -= ax * h
                py -= (ay + sp * x_mid) * h
                bnd = 1.0 - (x_c / a) ** 2 - yb * yb
                bound = mu * pmax_c * (bnd if bnd > 0.0 else 0.0)
                mag = np.sqrt(px * px + py * py)
                if mag > bound:
                    fac = bound / mag
                    px *= fac
                    py *= fac
                w = dx * dy
                Fx += px * w
                Fy += py * w
                Mz += (x_c * py - y * px) * w
        return Fx, Fy, Mz

    @_numba.njit(cache=True)
    def creep_law(model, cp, xi, eta, phi, N, a, b, G, mu, C11, C22, C23, C33):
        """Forces (Fx, Fy, Mz) on the wheel of the creep law ``model`` (see _kernel_code)."""
        c2 = a * b
        cc = np.sqrt(c2)
        Fxl = -G * c2 * C11 * xi
        Fyl = -G * c2 * C22 * eta - G * c2 * cc * C23 * phi
        Mzl = G * c2 * cc * C23 * eta - G * c2 * c2 * C33 * phi
        if model == 0:
            return Fxl, Fyl, Mzl
        if model == 2:
            fac = she_factor(Fxl, Fyl, mu, N)
            return Fxl * fac, Fyl * fac, Mzl * fac
        if model == 4:
            return fastsim(xi, eta, phi, N, a, b, G, mu, C11, C22, C23, int(cp[0]), int(cp[1]))
        kA, kS, muw = 1.0, 1.0, mu
        if model == 3:
            kA, kS = cp[0], cp[1]
            w = cp[4] * np.sqrt(xi * xi + eta * eta)
            muw = mu * ((1.0 - cp[2]) * np.exp(-cp[3] * w) + cp[2])
        Fx, Fy = polach(xi, eta, phi, N, a, b, G, muw, C11, C22, C23, kA, kS)
        return Fx, Fy, Mzl * she_factor(Fxl, Fyl, muw, N)

    @_numba.njit(cache=True)
    def kernel(pen, valid, kwr, kwl, krr, krl, P, Nrm, ws_of, rws, vws, wws, fwd,
               t0, dt, tab, ksum, G, mu, chi, v0, model, cp, out, Fg, Mg):
        """All contacts in one loop: Hertz (Eqs. H1-H6 of :mod:`core.contact_laws`, coefficients
        from ``tab``), the normal law N1 (:func:`normal_law`), creepages and the creep law
        ``model`` with parameters ``cp`` (:func:`_kernel_code`; -1: normal forces only).  See the
        module docstring; the definitions are those modules, this is their compiled copy.
        Returns the smallest rolling speed of a loaded contact (inf without one; creep laws need
        it above 1e-3 m/s, the caller checks)."""
        nt = tab.shape[1]
        vmin = np.inf
        c = np.empty(tab.shape[0])
        for i in range(pen.shape[0]):
            for k in range(out.shape[1]):
                out[i, k] = 0.0
            for k in range(3):
                Fg[i, k] = 0.0
                Mg[i, k] = 0.0
            d = pen[i]
            if not valid[i] or not (d > 0.0):
                continue
            A = 0.5 * (kwr[i] + krr[i])
            B = 0.5 * (kwl[i] + krl[i])
            lo = A / _RHO_CONFORMAL
            if B < lo:
                B = lo
            if B > A * _RHO_MAX:
                B = A * _RHO_MAX
            x = (np.log(B / A) - t0) / dt
            j = int(x)
            if j > nt - 2:
                j = nt - 2
            if j < 0:
                j = 0
            w = x - j
            for k in range(tab.shape[0]):
                c[k] = (1.0 - w) * tab[k, j] + w * tab[k, j + 1]
            mH, nH, Kel, C11, C22, C23, C33 = c[0], c[1], c[2], c[3], c[4], c[5], c[6]
            S = A + B
            Kh = (2.0 * mH / (3.0 * ksum * Kel)) ** 1.5 * np.sqrt(3.0 * np.pi * ksum / (4.0 * S))
            Ne = Kh * d**1.5
            base = np.cbrt(3.0 * np.pi * Ne * ksum / (4.0 * S))
            if A <= B:
                a = mH * base
                b = nH * base
            else:
                a = nH * base
                b = mH * base
            # kinematics
            iw = ws_of[i]
            n0, n1, n2 = Nrm[i, 0], Nrm[i, 1], Nrm[i, 2]
            rx = P[i, 0] - rws[iw, 0]
            ry = P[i, 1] - rws[iw, 1]
            rz = P[i, 2] - rws[iw, 2]
            wx, wy, wz = wws[iw, 0], wws[iw, 1], wws[iw, 2]
            vx = vws[iw, 0] + wy * rz - wz * ry
            vy = vws[iw, 1] + wz * rx - wx * rz
            vz = vws[iw, 2] + wx * ry - wy * rx
            f0, f1, f2 = fwd[iw, 0], fwd[iw, 1], fwd[iw, 2]
            fn = f0 * n0 + f1 * n1 + f2 * n2
            tx, ty, tz = f0 - fn * n0, f1 - fn * n1, f2 - fn * n2
            tn = np.sqrt(tx * tx + ty * ty + tz * tz)
            tx /= tn
            ty /= tn
            tz /= tn
            lx = n1 * tz - n2 * ty
            ly = n2 * tx - n0 * tz
            lz = n0 * ty - n1 * tx
            dd = -(vx * n0 + vy * n1 + vz * n2)
            N = normal_law(Kh, d, dd, chi, v0)
            Fx, Fy, Mz, xi, eta, phi = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
            if model >= 0:
                V = abs(vws[iw, 0] * tx + vws[iw, 1] * ty + vws[iw, 2] * tz)
                if V < vmin:
                    vmin = V
                if V < 1e-3:
                    continue
                xi = (vx * tx + vy * ty + vz * tz) / V
                eta = (vx * lx + vy * ly + vz * lz) / V
                phi = (wx * n0 + wy * n1 + wz * n2) / V
                if N > 0.0:
                    Fx, Fy, Mz = creep_law(model, cp, xi, eta, phi, N, a, b, G, mu, C11, C22, C23, C33)
            out[i, 0] = N
            out[i, 1] = Fx
            out[i, 2] = Fy
            out[i, 3] = Mz
            out[i, 4] = xi
            out[i, 5] = eta
            out[i, 6] = phi
            out[i, 7] = a
            out[i, 8] = b
            out[i, 9] = dd
            Fg[i, 0] = N * n0 + Fx * tx + Fy * lx
            Fg[i, 1] = N * n1 + Fx * ty + Fy * ly
            Fg[i, 2] = N * n2 + Fx * tz + Fy * lz
            Mg[i, 0] = Mz * n0
            Mg[i, 1] = Mz * n1
            Mg[i, 2] = Mz * n2
        return vmin

def _kernels():
    """(kernel, normal_law) compiled on first use, or None without numba."""
    return None if _numba is None else (kernel, normal_law)


def _kernel():
    k = _kernels()
    return None if k is None else k[0]


def _compiled_normal_law():
    """The kernel's normal law ``normal_law(Kh, d, dd, chi, v0)`` (numba), or None (for tests)."""
    k = _kernels()
    return None if k is None else k[1]


class ContactForces:
    """Normal and creep forces of all contacts of a vehicle's contact search in one call.

    The equations are in the module docstring.  Wheel and rail share the material (E, nu).

    Parameters
    ----------
    E : float
        Young's modulus of wheel and rail (Pa), default 210 GPa.
    nu : float
        Poisson ratio, default 0.28; G = E / (2 (1 + nu)).
    mu : float
        Friction coefficient (> 0); for Polach 2005 the static value mu0.
    creep_model : str, CreepModel subclass or CreepModel
        Any creep law of :data:`railway.contact.creep.CREEP_MODELS` by name or alias (``"kalker_linear"``,
        ``"shen_hedrick_elkins"``, ``"polach2000"``, ``"polach2005"``, ``"fastsim"``, or one
        registered by the user), a :class:`railway.contact.creep.CreepModel` class or an instance;
        ``None`` for normal forces only (creepages and creep forces zero: static analyses of a
        vehicle standing on its rails, where no rolling speed defines the creepages).
    restitution : float
        Coefficient of restitution c_e of the Lankarani-Nikravesh damping, in [0, 1].
    approach_velocity_floor : float
        Damping reference velocity v0 (m/s), see :func:`lankarani_nikravesh_force`.
    compiled : {"auto", True, False}
        ``"auto"``: the numba kernel when numba is installed *and* the kernel implements the creep
        law (every law of the package with ``join="scaled"``, and normal forces only), else the
        numpy reference path -- user laws and other joins run there, never replaced by a compiled
        one.  ``True``: the kernel or an error;
        ``False``: the reference path.  :attr:`compiled` tells which path is used.
    creep_params : dict, optional
        Constructor parameters of the creep law given by name or class (e.g. Polach 2005's
        ``k_A, k_S, A, B, speed``).  Note that Polach 2005 evaluates its slip velocity with its
        own ``speed`` parameter, not with the rolling speed of the wheelsets.
    spin_creepage, roll_rate_creepage, contact_angle, gravitational_stiffness : bool
        Terms of the contact forces, all on by default (the full model); switching one off gives
        the reduced models below, for like-for-like comparisons with the linear wheelset models
        (:class:`railway.vehicles.hunting.LinearWheelset`).  Any of them off runs on the numpy reference
        path.

    Notes
    -----
    Reduced models (each switch removes one mechanism the classical two-degree-of-freedom
    wheelset neglects; Wickens 2003, ch. 2):

    * ``spin_creepage=False``: the spin creepage φ passed to the creep law is zero, and the spin
      moment M_z is dropped (Kalker's f23 and f33 terms, static and dynamic).
    * ``roll_rate_creepage=False``: the creepages use the wheelset's angular velocity without its
      component about the forward axis f, ω − (ω·f) f, so the roll rate does not move the contact
      point (the term ρ h ẏ / V of the lateral creepage, :class:`railway.vehicles.hunting.LinearWheelset`).
    * ``contact_angle=False``: creepages and creep forces in the wheelset's own frame, t = f,
      l = a (the axle), spin about u = f × a, instead of the contact plane (t, l, n) of the
      module docstring; needs ``A_ws`` to be the unspun frame [f, a, u].
    * ``gravitational_stiffness=False``: only the normal force's component along the track's up
      axis b_T acts, N (n·b_T) b_T: its lateral and longitudinal components (the gravitational
      stiffness, and the path by which the wheels' load transfer couples roll and lateral
      motion) are dropped; the wheel loads, and so the Hertz ellipses, are those of the full
      model.  Needs ``up_ws`` in :meth:`__call__`.

    Attributes
    ----------
    creep_law : CreepModel
        The creep law instance used on both paths.
    creep_model : str
        Its registry name.
    compiled : bool
        True when the numba kernel is used.
    reduced : list of str
        The terms of :data:`REDUCTIONS` switched off (empty for the full model).

    Raises
    ------
    core.errors.InputError
        A parameter out of range (named), or ``compiled=True`` with a creep law the kernel does
        not implement.
    core.errors.UnknownNameError
        An unknown creep-law name (lists the registered laws).
    ImportError
        ``compiled=True`` without numba.

    References
    ----------
    See the module docstring.
    """

    def __init__(self, E=2.1e11, nu=0.28, mu=0.3, creep_model="polach2000", restitution=0.9,
                 approach_velocity_floor=0.1, compiled="auto", creep_params=None, spin_creepage=True,
                 roll_rate_creepage=True, contact_angle=True, gravitational_stiffness=True):
        for name, val, ok in (("E", E, E > 0), ("nu", nu, 0.0 <= nu <= 0.5), ("mu", mu, mu > 0),
                              ("restitution", restitution, 0.0 <= restitution <= 1.0),
                              ("approach_velocity_floor", approach_velocity_floor,
                               approach_velocity_floor > 0)):
            if not (np.isfinite(val) and ok):
                raise InputError(f"ContactForces: {name} = {val!r} is out of range")
        if compiled not in ("auto", True, False):
            raise InputError(f"compiled must be 'auto', True or False, got {compiled!r}")
        if creep_model is None:  # normal forces only (static analyses: no rolling, no creep)
            if creep_params:
                raise InputError("ContactForces: creep_params given without a creep law")
            self.creep_law, self.creep_model = None, None
        else:
            self.creep_law = get_creep_model(creep_model, **(creep_params or {}))
            self.creep_model = self.creep_law.name
        self.spin_creepage, self.roll_rate_creepage = bool(spin_creepage), bool(roll_rate_creepage)
        self.contact_angle, self.gravitational_stiffness = bool(contact_angle), bool(gravitational_stiffness)
        self.reduced = [k for k in REDUCTIONS if not getattr(self, k)]
        code = None if self.reduced else _kernel_code(self.creep_law)
        if compiled is True and self.reduced:
            raise InputError(f"ContactForces: compiled=True, but the terms {self.reduced} are switched off, "
                             "which only the numpy reference path does; use compiled='auto' or False")
        if compiled is True and code is None:
            raise InputError(f"ContactForces: compiled=True, but the numba kernel implements only the "
                             f"creep laws of railway.contact.creep with join='scaled', not {self.creep_law!r}; "
                             "use compiled='auto' or False (numpy reference path)")
        self.E, self.nu, self.mu = float(E), float(nu), float(mu)
        self.G = self.E / (2.0 * (1.0 + self.nu))
        self.restitution = float(restitution)
        self._chi = float(HYSTERESIS_LAWS["lankarani-nikravesh"].factor(self.restitution))
        self.v0 = float(approach_velocity_floor)
        self._ksum = 1.0 / (np.pi * float(np.ravel(effective_modulus(E, nu, E, nu))[0]))
        self._kernel = _kernel() if (compiled and code is not None) else None
        self._model_code, self._model_params = (None, None) if code is None else code
        self._ws_of = None
        if compiled is True and self._kernel is None:
            raise ImportError("compiled=True needs numba")
        self.compiled = self._kernel is not None
        if self._kernel is not None:
            self._build_table()

    def _build_table(self, n=4001):
        """Hertz m, n, K(e) and Kalker C11..C33 against t = ln(B/A) (uniform grid)."""
        from scipy import special

        t = np.linspace(-np.log(_RHO_MAX), np.log(_RHO_MAX), n)
        g = ellipse_ratio(np.exp(np.abs(t)))
        K = special.ellipk(1.0 - g * g)
        E = special.ellipe(1.0 - g * g)
        mH = (2.0 * E / (np.pi * g * g)) ** (1.0 / 3.0)
        a_over_b = np.where(t >= 0.0, 1.0 / g, g)  # A <= B: the major axis is along x
        C = kalker_coefficients(a_over_b, self.nu)
        self._t0, self._dt = float(t[0]), float(t[1] - t[0])
        self._tab = np.ascontiguousarray(np.vstack([mH, mH * g, K, *C]))

    def __call__(self, res, r_ws, A_ws, v_ws, omega_ws, up_ws=None):
        """Forces on the wheels for the contacts ``res`` of wheelsets moving with (v_ws, omega_ws).

        Parameters
        ----------
        res : ContactResult
            From :meth:`railway.contact.search.ContactSearch.search` (n_wheels = 2 n_ws).
        r_ws : (n_ws, 3) array_like
            Wheelset centres (m), the reference points of ``v_ws``.
        A_ws : (n_ws, 3, 3) array_like
            Wheelset orientations (column 0: forward axis, giving the rolling direction).
        v_ws, omega_ws : (n_ws, 3) array_like
            Wheelset centre velocity (m/s) and angular velocity including the spin (rad/s), global.
        up_ws : (n_ws, 3) array_like, optional
            The track's up axis at every wheelset; needed only with ``gravitational_stiffness=False``.

        Returns
        -------
        dict
            ``N, Fx, Fy, Mz, xi, eta, phi, a, b, delta_dot`` (:data:`FORCE_KEYS`) as
            (n_wheels, 2) arrays (N [N], Fx, Fy [N] and Mz [N m] in the contact frame, creepages
            [-] and [1/m], semi-axes [m], penetration rate [m/s]), plus ``force`` and
            ``moment`` (n_wheels, 2, 3): the force and spin moment on the wheel, global.
            Candidates without penetration have zeros.

        Raises
        ------
        core.errors.InputError
            Non-finite velocities, or a rolling speed below 1e-3 m/s at a loaded contact
            (creepages undefined).
        """
        nw = res.gap.shape[0]
        n_ws = nw // 2
        r_ws = np.asarray(r_ws, dtype=float).reshape(n_ws, 3)
        v_ws = np.asarray(v_ws, dtype=float).reshape(n_ws, 3)
        omega_ws = np.asarray(omega_ws, dtype=float).reshape(n_ws, 3)
        A_ws = np.asarray(A_ws, dtype=float).reshape(n_ws, 3, 3)
        for name, arr in (("v_ws", v_ws), ("omega_ws", omega_ws)):
            if not np.all(np.isfinite(arr)):
                idx = np.argwhere(~np.isfinite(arr))[0]
                raise InputError(f"ContactForces: {name}{idx.tolist()} = {float(arr[tuple(idx)])!r} is not finite")
        fwd = np.ascontiguousarray(A_ws[:, :, 0])
        if self._kernel is not None:
            return self._compiled(res, r_ws, fwd, v_ws, omega_ws)
        if not self.gravitational_stiffness and up_ws is None:
            raise InputError("ContactForces: gravitational_stiffness=False needs the track's up axis (up_ws)")
        return self._reference(res, r_ws, fwd, v_ws, omega_ws, A_ws=A_ws,
                               up_ws=None if up_ws is None else np.asarray(up_ws, float).reshape(n_ws, 3))

    def _compiled(self, res, r_ws, fwd, v_ws, omega_ws):
        shp = res.gap.shape
        M = res.gap.size
        if self._ws_of is None or self._ws_of.size != M:
            self._ws_of = np.arange(M) // 4
        out = np.empty((M, 10))
        Fg = np.empty((M, 3))
        Mg = np.empty((M, 3))
        vmin = self._kernel(res.penetration.reshape(M), res.valid.reshape(M),
                            res.k_wheel_rolling.reshape(M), res.k_wheel_lateral.reshape(M),
                            res.k_rail_rolling.reshape(M), res.k_rail_lateral.reshape(M),
                            res.point_wheel.reshape(M, 3), res.normal.reshape(M, 3), self._ws_of,
                            r_ws, v_ws, omega_ws, fwd, self._t0, self._dt, self._tab, self._ksum,
                            self.G, self.mu, self._chi, self.v0,
                            self._model_code, self._model_params, out, Fg, Mg)
        if vmin < 1e-3:
            raise InputError(f"ContactForces: rolling speed {vmin!r} m/s at a loaded contact is "
                             "below 1e-3 m/s: creepages undefined")
        out = out.reshape(shp + (10,))
        d = {k: out[..., i] for i, k in enumerate(FORCE_KEYS)}
        d["force"] = Fg.reshape(shp + (3,))
        d["moment"] = Mg.reshape(shp + (3,))
        return d

    def _reference(self, res, r_ws, fwd, v_ws, omega_ws, A_ws=None, up_ws=None):
        """The same forces from the project's reference modules (vectorised numpy), with the
        terms switched off that the class docstring's "Reduced models" lists."""
        from .creepage import creepages

        M = res.gap.size
        shp = res.gap.shape
        d = {k: np.zeros(M) for k in FORCE_KEYS}
        d["force"] = np.zeros((M, 3))
        d["moment"] = np.zeros((M, 3))
        with np.errstate(invalid="ignore"):
            pen = res.penetration.reshape(M)
        on = np.flatnonzero(res.valid.reshape(M) & (pen > 0))
        if on.size:
            iw = on // 4
            A = 0.5 * (res.k_wheel_rolling.reshape(M)[on] + res.k_rail_rolling.reshape(M)[on])
            B = 0.5 * (res.k_wheel_lateral.reshape(M)[on] + res.k_rail_lateral.reshape(M)[on])
            B = np.clip(B, A / _RHO_CONFORMAL, A * _RHO_MAX)
            h = hertz_from_penetration(pen[on], A, B, self.E, self.nu, self.E, self.nu)
            P = res.point_wheel.reshape(M, 3)[on]
            n = res.normal.reshape(M, 3)[on]
            vw = v_ws[iw] + np.cross(omega_ws[iw], P - r_ws[iw])
            dd = -np.einsum("ij,ij->i", vw, n)
            N = lankarani_nikravesh_force(pen[on], dd, h.stiffness, self.restitution,
                                          approach_velocity_floor=self.v0)
            if self.creep_law is None:
                zero = np.zeros(on.size)
                xi = eta = phi = zero
                f = CreepForces(zero, zero, zero)
            # the creep frame: the contact plane, or the wheelset's own (forward, axle, up) frame
            nc = n if self.contact_angle else np.asarray(A_ws, float)[iw, :, 2]
            if self.creep_law is not None:
                w_c = omega_ws[iw]
                if not self.roll_rate_creepage:  # the roll rate (about the forward axis) left out
                    w_c = w_c - np.einsum("ij,ij->i", w_c, fwd[iw])[:, None] * fwd[iw]
                xi, eta, phi = creepages(P, nc, fwd[iw], r_ws[iw], v_ws[iw], w_c)
                if not self.spin_creepage:
                    phi = np.zeros(on.size)
                f = self.creep_law(xi, eta, phi, N, h.a, h.b, self.G, self.nu, self.mu)
                if not self.spin_creepage:  # no spin moment either (Kalker's f23, f33 terms)
                    f = CreepForces(f.Fx, f.Fy, np.zeros(on.size))
            t = fwd[iw] - np.einsum("ij,ij->i", fwd[iw], nc)[:, None] * nc
            t /= np.linalg.norm(t, axis=1)[:, None]
            l = np.cross(nc, t)
            for k, v in zip(FORCE_KEYS, (N, f.Fx, f.Fy, f.Mz, xi, eta, phi, h.a, h.b, dd)):
                d[k][on] = v
            if self.gravitational_stiffness:
                Fn = N[:, None] * n
            else:  # only the normal force's component along the track's up axis
                up = up_ws[iw]
                Fn = (N * np.einsum("ij,ij->i", n, up))[:, None] * up
            d["force"][on] = Fn + f.Fx[:, None] * t + f.Fy[:, None] * l
            d["moment"][on] = f.Mz[:, None] * nc
        out = {k: d[k].reshape(shp) for k in FORCE_KEYS}
        out["force"] = d["force"].reshape(shp + (3,))
        out["moment"] = d["moment"].reshape(shp + (3,))
        return out
