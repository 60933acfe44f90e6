"""Tangential wheel-rail contact: creep force laws behind one interface.

Every model is called with the same signature::

    model(xi, eta, phi, normal_force, a, b, G, nu, mu) -> CreepForces(Fx, Fy, Mz)

xi, eta [-] and phi [1/m] are the creepages of :mod:`railway.contact.creepage`; ``a`` is the contact-ellipse
semi-axis along the rolling direction and ``b`` the lateral one [m]; G the combined shear modulus
[Pa]; nu the combined Poisson ratio; mu the friction coefficient.  Model parameters (Polach's
k_A, k_S, the FASTSIM grid ...) go to the constructor.  Fx, Fy [N] and Mz [N m] act on the wheel
in the contact frame (t, l, n) and oppose the creepage (the convention of the project notes)::

    Kalker linear:  Fx = -G c^2 C11 xi
                    Fy = -G c^2 C22 eta - G c^3 C23 phi
                    Mz =  G c^3 C23 eta - G c^4 C33 phi,       c = sqrt(a b)

Models are registered by name in :data:`CREEP_MODELS`, a :class:`core.registry.Registry`
(``get_creep_model("polach2000")``), so that a scene switches law by a string; a user class
deriving from :class:`CreepModel` can be registered with :func:`register_creep_model`.  An
unknown name raises :class:`core.errors.UnknownNameError` listing the registered laws; a name
taken by another class raises :class:`core.errors.NameTakenError`.  Bad input raises
:class:`core.errors.InputError` (a ``ValueError``) naming the value.

Kalker coefficients
-------------------
Table E.3 of Kalker (1990) for g = a/b (a/b <= 1) and g = b/a (a/b > 1), nu = 0, 1/4, 1/2.
Interpolation: quadratic Lagrange in nu on 1/C at each tabulated g, then linear in g between rows::

    1/C(nu) = 8(nu - 1/4)(nu - 1/2)/C(0) - 16 nu (nu - 1/2)/C(1/4) + 8 nu (nu - 1/4)/C(1/2)

For g < 0.1 the asymptotic expressions of Kalker are used (a << b, g = a/b)::

    C11 = pi^2/(4(1-nu)),  C22 = pi^2/4,  C23 = pi sqrt(g)/(3(1-nu)) [1 + nu(ln(16/g) - 5)]

and (a >> b, g = b/a, Lam = ln(16/g^2))::

    C11 = 2 pi/((Lam - 2 nu) g) [1 + (3 - ln 4)/(Lam - 2 nu)]
    C22 = (2 pi/g) [1 + (1 - nu)(3 - ln 4)/((1 - nu) Lam + 2 nu)] / ((1 - nu) Lam + 2 nu)
    C23 = 2 pi / (3 g^(3/2) ((1 - nu) Lam - 2 + 4 nu))

C33 has no asymptote in the notes: it is clamped at its g = 0.1 value.  The raw asymptotes differ
from the g = 0.1 table row by up to 6.1 % (C23, a << b, nu = 0.5; see the tests); with
``join="scaled"`` (default) each asymptote is multiplied by the constant ratio table/asymptote at
g = 0.1 so that the coefficients are continuous there (a jump in C would put a jump in the forces
of a simulation whose contact ellipse passes g = 0.1); ``join="raw"`` uses them unscaled.

References
----------
.. [1] J. J. Kalker, *On the rolling contact of two elastic bodies in the presence of dry
   friction*, PhD thesis, TH Delft, 1967.
.. [2] J. J. Kalker, *Three-dimensional elastic bodies in rolling contact*, Kluwer, 1990,
   Table E.3 (creepage and spin coefficients).
.. [3] J. J. Kalker, "A fast algorithm for the simplified theory of rolling contact",
   Vehicle System Dynamics 11 (1982) 1-13 (FASTSIM).
.. [4] O. Polach, "A fast wheel-rail forces calculation computer code", Vehicle System Dynamics
   33 Suppl. (2000) 728-739.
.. [5] O. Polach, "Creep forces in simulations of traction vehicles running on adhesion limit",
   Wear 258 (2005) 992-1000.
.. [6] Z. Y. Shen, J. K. Hedrick and J. A. Elkins, "A comparison of alternative creep force models
   for rail vehicle dynamic analysis", Vehicle System Dynamics 12 Suppl. (1983) 79-83.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pandas as pd

from core.errors import DataFileError, InputError, UnknownNameError
from core.registry import Registry

__all__ = [
    "CreepForces",
    "CreepModel",
    "KalkerLinear",
    "ShenHedrickElkins",
    "Polach2000",
    "Polach2005",
    "Fastsim",
    "CREEP_MODELS",
    "register_creep_model",
    "get_creep_model",
    "creep_forces",
    "kalker_coefficients",
    "kalker_table",
    "kalker_table_path",
    "polach2005_parameter_sets",
]

_KALKER_FILE = ("railway", "kalker_coefficients.csv")


def kalker_table_path() -> Path:
    """Path of ``kalker_coefficients.csv`` in the checkout's ``data/railway/`` folder.

    Raises
    ------
    FileNotFoundError
        If the file is missing from the project's data folder (its path is named).
    """
    from core.paths import data_path

    return data_path(*_KALKER_FILE)


@functools.lru_cache(maxsize=1)
def kalker_table() -> dict:
    """Kalker Table E.3 as arrays: ``{branch: {"g": (10,), "C11": (10, 3), ...}}``.

    ``branch`` is ``"a/b<=1"`` (g = a/b) or ``"a/b>1"`` (g = b/a); the second axis is
    nu = 0, 0.25, 0.5.
    """
    path = kalker_table_path()
    df = pd.read_csv(path, comment=None)
    need = {"branch", "g", "nu", "C11", "C22", "C23", "C33"}
    if not need <= set(df.columns):
        raise DataFileError(f"{path}: missing columns {sorted(need - set(df.columns))}")
    out = {}
    for branch in ("a/b<=1", "a/b>1"):
        sub = df[df["branch"] == branch]
        gs = np.sort(sub["g"].unique())
        nus = np.sort(sub["nu"].unique())
        if not np.allclose(nus, [0.0, 0.25, 0.5]):
            raise DataFileError(f"{path}: branch {branch} needs nu = 0, 0.25, 0.5; got {nus.tolist()}")
        entry = {"g": gs}
        for col in ("C11", "C22", "C23", "C33"):
            piv = sub.pivot(index="g", columns="nu", values=col).loc[gs, nus]
            entry[col] = piv.to_numpy(dtype=float)
        out[branch] = entry
    return out


def _lagrange_inverse(Ctab: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """Quadratic Lagrange in nu on 1/C. Ctab (10, 3), nu (n,) -> (n, 10)."""
    nu = nu[:, None]
    inv = (8.0 * (nu - 0.25) * (nu - 0.5) / Ctab[None, :, 0]
           - 16.0 * nu * (nu - 0.5) / Ctab[None, :, 1]
           + 8.0 * nu * (nu - 0.25) / Ctab[None, :, 2])
    return 1.0 / inv


def _asymptote_small_a(g, nu):
    """Kalker asymptotes for a << b (g = a/b -> 0): C11, C22, C23."""
    C11 = np.pi**2 / (4.0 * (1.0 - nu))
    C22 = np.full_like(g, np.pi**2 / 4.0)
    C23 = np.pi * np.sqrt(g) / (3.0 * (1.0 - nu)) * (1.0 + nu * (np.log(16.0 / g) - 5.0))
    return C11 * np.ones_like(g), C22, C23


def _asymptote_small_b(g, nu):
    """Kalker asymptotes for a >> b (g = b/a -> 0): C11, C22, C23."""
    Lam = np.log(16.0 / g**2)
    q = 3.0 - np.log(4.0)
    C11 = 2.0 * np.pi / ((Lam - 2.0 * nu) * g) * (1.0 + q / (Lam - 2.0 * nu))
    den = (1.0 - nu) * Lam + 2.0 * nu
    C22 = (2.0 * np.pi / g) * (1.0 + (1.0 - nu) * q / den) / den
    C23 = 2.0 * np.pi / (3.0 * g**1.5 * ((1.0 - nu) * Lam - 2.0 + 4.0 * nu))
    return C11, C22, C23


def kalker_coefficients(a_over_b, nu, join: str = "scaled"):
    """Kalker creepage/spin coefficients C11, C22, C23, C33 for ellipse ratio a/b and Poisson nu.

    Parameters
    ----------
    a_over_b : float or (n,) array_like
        Semi-axis ratio a/b (a along the rolling direction), > 0.
    nu : float or (n,) array_like
        Combined Poisson ratio in [0, 0.5].
    join : {"scaled", "raw"}
        How the g < 0.1 asymptotes meet the table (see the module docstring).

    Returns
    -------
    C11, C22, C23, C33 : (n,) ndarray
        Dimensionless coefficients.

    References
    ----------
    Kalker (1990), Table E.3 and its asymptotic expressions for g -> 0.
    """
    r = np.atleast_1d(np.asarray(a_over_b, dtype=float))
    nu = np.atleast_1d(np.asarray(nu, dtype=float))
    r, nu = np.broadcast_arrays(r, nu)
    r = r.astype(float).copy()
    nu = nu.astype(float).copy()
    if np.any(~(r > 0)) or np.any(~np.isfinite(r)):
        i = int(np.flatnonzero(~(r > 0) | ~np.isfinite(r))[0])
        raise InputError(f"a_over_b must be finite and > 0, got {float(r[i])!r} at index {i}")
    _check_nu(nu)
    if join not in ("scaled", "raw"):
        raise InputError(f"join must be 'scaled' or 'raw', got {join!r}")
    tab = kalker_table()
    out = np.empty((4, r.size))
    for branch, mask, g_of, asym in (("a/b<=1", r <= 1.0, lambda x: x, _asymptote_small_a),
                                     ("a/b>1", r > 1.0, lambda x: 1.0 / x, _asymptote_small_b)):
        if not np.any(mask):
            continue
        g = g_of(r[mask])
        nn = nu[mask]
        t = tab[branch]
        gn = t["g"]
        gc = np.clip(g, gn[0], gn[-1])
        j = np.clip(np.searchsorted(gn, gc, side="right") - 1, 0, gn.size - 2)
        w = (gc - gn[j]) / (gn[j + 1] - gn[j])
        rows = np.arange(g.size)
        small = g < gn[0]
        for k, col in enumerate(("C11", "C22", "C23", "C33")):
            Cnu = _lagrange_inverse(t[col], nn)  # (m, 10)
            C = (1.0 - w) * Cnu[rows, j] + w * Cnu[rows, j + 1]
            if k < 3 and np.any(small):
                Ca = asym(g[small], nn[small])[k]
                if join == "scaled":
                    Ca = Ca * Cnu[small, 0] / asym(np.full(int(small.sum()), gn[0]), nn[small])[k]
                C[small] = Ca
            out[k, mask] = C
    return out[0], out[1], out[2], out[3]


# --------------------------------------------------------------------------------------------
# interface
# --------------------------------------------------------------------------------------------


class CreepForces(NamedTuple):
    """Tangential contact forces on the wheel in the contact frame.

    Attributes
    ----------
    Fx : (n,) ndarray
        Longitudinal force [N].
    Fy : (n,) ndarray
        Lateral force [N].
    Mz : (n,) ndarray
        Spin moment about the contact normal [N m].
    """

    Fx: np.ndarray
    Fy: np.ndarray
    Mz: np.ndarray


def _check_nu(nu):
    bad = ~((nu >= 0.0) & (nu <= 0.5))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"Poisson ratio nu must lie in [0, 0.5], got {float(nu[i])!r} at index {i}")


def _validate(xi, eta, phi, normal_force, a, b, G, nu, mu):
    names = ("xi", "eta", "phi", "normal_force", "a", "b", "G", "nu", "mu")
    arrs = [np.atleast_1d(np.asarray(v, dtype=float)) for v in (xi, eta, phi, normal_force, a, b, G, nu, mu)]
    try:
        arrs = [np.array(x, dtype=float) for x in np.broadcast_arrays(*arrs)]
    except ValueError as exc:
        shapes = {n: np.shape(x) for n, x in zip(names, arrs)}
        raise InputError(f"creep model inputs do not broadcast: {shapes}") from exc
    for name, x in zip(names, arrs):
        if x.ndim != 1:
            raise InputError(f"{name} must be a scalar or 1-D array, got shape {x.shape}")
        bad = ~np.isfinite(x)
        if np.any(bad):
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"{name} must be finite, got {float(x[i])!r} at index {i}")
    xi, eta, phi, N, a, b, G, nu, mu = arrs
    for name, x in (("normal_force", N), ("a", a), ("b", b)):
        if np.any(x < 0):
            i = int(np.flatnonzero(x < 0)[0])
            raise InputError(f"{name} must be >= 0, got {float(x[i])!r} at index {i}")
    loaded = N > 0
    flat = loaded & ((a <= 0) | (b <= 0))
    if np.any(flat):
        i = int(np.flatnonzero(flat)[0])
        raise InputError(f"loaded contact {i} (N={float(N[i])!r} N) needs semi-axes a, b > 0; "
                         f"got a={float(a[i])!r}, b={float(b[i])!r} m")
    if np.any(G <= 0):
        i = int(np.flatnonzero(G <= 0)[0])
        raise InputError(f"shear modulus G must be > 0, got {float(G[i])!r} Pa at index {i}")
    _check_nu(nu)
    if np.any(mu <= 0):
        i = int(np.flatnonzero(mu <= 0)[0])
        raise InputError(f"friction coefficient mu must be > 0, got {float(mu[i])!r} at index {i}")
    return xi, eta, phi, N, a, b, G, nu, mu


class CreepModel:
    """Base class of the creep force laws (one call signature for all).

    Subclasses implement :meth:`_forces` on validated, broadcast 1-D arrays of *loaded* contacts
    (N > 0, a > 0, b > 0); unloaded contacts get zero forces here.
    """

    name: str = "base"

    def __call__(self, xi, eta, phi, normal_force, a, b, G, nu, mu) -> CreepForces:
        """Creep forces on the wheel.

        Parameters
        ----------
        xi, eta : float or (n,) array_like
            Longitudinal and lateral creepage [-].
        phi : float or (n,) array_like
            Spin creepage [1/m].
        normal_force : float or (n,) array_like
            Normal load N >= 0 [N].
        a, b : float or (n,) array_like
            Semi-axes along the rolling direction and lateral [m].
        G : float or (n,) array_like
            Combined shear modulus [Pa].
        nu : float or (n,) array_like
            Combined Poisson ratio in [0, 0.5].
        mu : float or (n,) array_like
            Friction coefficient (> 0); for Polach 2005 the static value mu0.

        Returns
        -------
        CreepForces
            Fx, Fy [N] and Mz [N m], each (n,).

        Raises
        ------
        core.errors.InputError
            NaN/inf input, negative load or semi-axis, G <= 0, nu outside [0, 0.5], mu <= 0
            (a ``ValueError``; names the value and its index).
        """
        xi, eta, phi, N, a, b, G, nu, mu = _validate(xi, eta, phi, normal_force, a, b, G, nu, mu)
        Fx = np.zeros_like(xi)
        Fy = np.zeros_like(xi)
        Mz = np.zeros_like(xi)
        on = N > 0
        if np.any(on):
            fx, fy, mz = self._forces(xi[on], eta[on], phi[on], N[on], a[on], b[on], G[on], nu[on], mu[on])
            Fx[on], Fy[on], Mz[on] = fx, fy, mz
        return CreepForces(Fx, Fy, Mz)

    def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):  # pragma: no cover - abstract
        raise NotImplementedError

    def __repr__(self) -> str:
        params = ", ".join(f"{k}={v!r}" for k, v in vars(self).items())
        return f"{type(self).__name__}({params})"


def _check_creep_model(obj) -> None:
    if not (isinstance(obj, type) and issubclass(obj, CreepModel)):
        raise TypeError(f"the creep-model registry takes CreepModel subclasses, got {obj!r}")


#: Name -> creep law class (a :class:`core.registry.Registry`: one rule for a taken name, and an
#: unknown name raises :class:`core.errors.UnknownNameError` listing the registered laws).
CREEP_MODELS: Registry[type[CreepModel]] = Registry("creep model", _check_creep_model)


def register_creep_model(name: str, cls: type[CreepModel] | None = None, *, replace: bool = False):
    """Register a creep model class under ``name`` (usable as a decorator).

    The class's ``name`` attribute is set to ``name``.  Registering the same class again is a
    no-op; remove a law with ``CREEP_MODELS.unregister(name)``.

    Parameters
    ----------
    name : str
        Registry name (lower case with underscores, as looked up by :func:`get_creep_model`).
    cls : CreepModel subclass, optional
        Without it, a decorator is returned.
    replace : bool
        Replace a different class registered under ``name``.

    Raises
    ------
    core.errors.NameTakenError
        If ``name`` is taken by another class (and ``replace`` is False); names both.
    TypeError
        If ``cls`` is not a CreepModel subclass.
    """
    def deco(c):
        CREEP_MODELS.register(name, c, replace=replace)
        c.name = name
        return c

    return deco if cls is None else deco(cls)


def get_creep_model(model, **params) -> CreepModel:
    """A creep model instance from a registered name, a CreepModel class or an instance.

    Parameters
    ----------
    model : str, CreepModel subclass or CreepModel
        A name of :data:`CREEP_MODELS` (``"kalker_linear"``, ``"polach2000"``, ``"polach2005"``,
        ``"shen_hedrick_elkins"``, ``"fastsim"``, user laws) or an alias (``"kalker"``,
        ``"polach"``, ``"SHE"``, ...); case, surrounding blanks and ``-``/``_`` do not matter.
    **params
        Constructor parameters of the model (not allowed with an instance).

    Raises
    ------
    core.errors.UnknownNameError
        An unknown name; the message lists the registered laws.
    core.errors.InputError
        Parameters given with an instance, or ``model`` of another type.
    """
    if isinstance(model, CreepModel):
        if params:
            raise InputError(f"parameters {sorted(params)} given with a model instance {model!r}")
        return model
    if isinstance(model, type) and issubclass(model, CreepModel):
        return model(**params)
    if isinstance(model, str):
        key = model.strip().lower().replace("-", "_")
        key = _ALIASES.get(key, key)
        try:
            cls = CREEP_MODELS[key]
        except UnknownNameError as exc:  # the registry's message lists the registered laws
            given = f" (given as {model!r})" if key != model else ""
            aliases = ", ".join(f"{a} -> {k}" for a, k in _ALIASES.items())
            raise UnknownNameError(f"{exc}{given}; aliases: {aliases}") from None
        return cls(**params)
    raise InputError(f"creep model must be a name, a CreepModel class or instance, got {model!r}")


def creep_forces(model, xi, eta, phi, normal_force, a, b, G, nu, mu, **params) -> CreepForces:
    """Convenience: ``get_creep_model(model, **params)(xi, eta, phi, normal_force, a, b, G, nu, mu)``."""
    return get_creep_model(model, **params)(xi, eta, phi, normal_force, a, b, G, nu, mu)


def _kalker_linear(xi, eta, phi, a, b, G, nu, join):
    C11, C22, C23, C33 = kalker_coefficients(a / b, nu, join=join)
    c2 = a * b
    c = np.sqrt(c2)
    Fx = -G * c2 * C11 * xi
    Fy = -G * c2 * C22 * eta - G * c2 * c * C23 * phi
    Mz = G * c2 * c * C23 * eta - G * c2 * c2 * C33 * phi
    return Fx, Fy, Mz, (C11, C22, C23, C33)


def _she_factor(Fx_lin, Fy_lin, mu, N):
    """Shen-Hedrick-Elkins saturation factor F_R'/F_R of the linear resultant, in (0, 1].

    beta = F_R/(mu N); factor = 1 - beta/3 + beta^2/27 for beta < 3, else 1/beta.
    """
    beta = np.hypot(Fx_lin, Fy_lin) / (mu * N)
    with np.errstate(divide="ignore"):
        return np.where(beta < 3.0, 1.0 - beta / 3.0 + beta**2 / 27.0, 1.0 / beta)


@register_creep_model("kalker_linear")
class KalkerLinear(CreepModel):
    """Kalker's linear theory (no saturation; valid at small creepage only).

    Fx = -G c^2 C11 xi;  Fy = -G c^2 C22 eta - G c^3 C23 phi;  Mz = G c^3 C23 eta - G c^4 C33 phi.

    Parameters
    ----------
    join : {"scaled", "raw"}
        Junction of the g < 0.1 asymptotes (see :func:`kalker_coefficients`).

    References
    ----------
    Kalker (1967); Kalker (1990), Table E.3.
    """

    def __init__(self, join: str = "scaled"):
        self.join = join

    def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
        Fx, Fy, Mz, _ = _kalker_linear(xi, eta, phi, a, b, G, nu, self.join)
        return Fx, Fy, Mz


@register_creep_model("shen_hedrick_elkins")
class ShenHedrickElkins(CreepModel):
    """Shen-Hedrick-Elkins (1983) heuristic saturation of the Kalker linear forces.

    F_R = sqrt(Fx_lin^2 + Fy_lin^2), beta = F_R/(mu N);
    F_R' = mu N (beta - beta^2/3 + beta^3/27) for beta < 3, else mu N;
    (Fx, Fy) = (Fx_lin, Fy_lin) F_R'/F_R.

    Mz choice: the spin moment is scaled by the same factor F_R'/F_R (the usual choice in
    multibody codes; Shen et al. give no rule for it).  The factor is 1 - beta/3 + beta^2/27
    (beta < 3) or 1/beta, bounded in (0, 1] and equal to 1 where F_R = 0.
    Known limitation: under pure spin the lateral force saturates to mu N, whereas the exact
    theory gives a much smaller force.

    Parameters
    ----------
    join : {"scaled", "raw"}
        Junction of the Kalker asymptotes.

    References
    ----------
    Shen, Hedrick & Elkins (1983), VSD 12 Suppl.: 79-83.
    """

    def __init__(self, join: str = "scaled"):
        self.join = join

    def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
        Fx, Fy, Mz, _ = _kalker_linear(xi, eta, phi, a, b, G, nu, self.join)
        fac = _she_factor(Fx, Fy, mu, N)
        return Fx * fac, Fy * fac, Mz * fac


def _polach(xi, eta, phi, N, a, b, G, mu, C11, C22, C23, kA=1.0, kS=1.0):
    """Polach's method: returns Fx, the lateral force without spin and the spin part F_yS."""
    sx, sy, psi = xi, eta, phi
    s = np.hypot(sx, sy)
    sy_spin = sy + psi * a
    syC = np.where(np.abs(sy_spin) > np.abs(sy), sy_spin, sy)
    sC = np.hypot(sx, syC)
    with np.errstate(invalid="ignore", divide="ignore"):
        cjj = np.where(s > 0, np.sqrt((C11 * sx / s) ** 2 + (C22 * sy / s) ** 2), C22)
        eps = np.pi * G * a * b * cjj * sC / (4.0 * N * mu)
        F = 2.0 * N * mu / np.pi * (kA * eps / (1.0 + (kA * eps) ** 2) + np.arctan(kS * eps))
        Fx = np.where(sC > 0, -F * sx / sC, 0.0)
        Fy = np.where(sC > 0, -F * sy / sC, 0.0)
        # spin part of the lateral force (sign: tends to -G c^3 C23 psi at small creepage)
        KS = 1.0 + 6.3 * (1.0 - np.exp(-a / b))
        epsM = 8.0 / 3.0 * G * b * np.sqrt(a * b) / (N * mu) * C23 * np.abs(syC) / KS
        d = (epsM**2 - 1.0) / (epsM**2 + 1.0)
        KM = (np.abs(epsM) * (d**3 / 3.0 - d**2 / 2.0 + 1.0 / 6.0)
              - np.sqrt(np.clip(1.0 - d**2, 0.0, None) ** 3) / 3.0)
        FyS = np.where(sC > 0, 9.0 / 16.0 * a * mu * N * KM * KS * psi / sC, 0.0)
    return Fx, Fy, FyS


@register_creep_model("polach2000")
class Polach2000(CreepModel):
    """Polach (2000) creep forces with spin, constant friction.

    s = ``|(xi, eta)|``; s_yC = eta + phi a if ``|eta + phi a|`` > ``|eta|`` else eta; s_C = ``|(xi, s_yC)|``;
    c_jj = sqrt((C11 xi/s)^2 + (C22 eta/s)^2);  eps = pi G a b c_jj s_C / (4 N mu);
    F = (2 N mu/pi) [eps/(1 + eps^2) + arctan eps];  Fx = -F xi/s_C,  Fy = -F eta/s_C + F_yS;
    K_S = 1 + 6.3 (1 - exp(-a/b));  eps_M = (8/3) G b sqrt(ab) C23 ``|s_yC|`` / (N mu K_S);
    delta = (eps_M^2 - 1)/(eps_M^2 + 1);
    K_M = ``|eps_M|`` (delta^3/3 - delta^2/2 + 1/6) - sqrt((1 - delta^2)^3)/3   (<= 0);
    F_yS = +(9/16) a mu N K_M K_S phi / s_C.

    Sign: Polach prints F_yS with a leading minus under his own convention; in the
    force-opposes-creepage convention used here K_M <= 0 and the plus sign makes F_yS tend to
    -G c^3 C23 phi at small creepage (tested).  With xi = 0 the model tends exactly to Kalker's
    linear law; with combined xi and eta the initial slope uses Polach's combined coefficient c_jj
    (a property of the method).  Polach gives no spin moment.  Our choice: Mz is the Kalker linear
    Mz times the Shen-Hedrick-Elkins factor of the linear resultant (bounded in (0, 1], tends to 1
    at small creepage).  Scaling by ``|F_Polach|``/``|F_lin|`` instead is unbounded where the linear
    lateral force crosses zero (eta = -C23 c phi/C22) while Polach's does not.

    Parameters
    ----------
    join : {"scaled", "raw"}
        Junction of the Kalker asymptotes.

    References
    ----------
    Polach (2000), VSD 33 Suppl.: 728-739.
    """

    def __init__(self, join: str = "scaled"):
        self.join = join

    def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
        Fxl, Fyl, Mzl, (C11, C22, C23, _) = _kalker_linear(xi, eta, phi, a, b, G, nu, self.join)
        Fx, Fy, FyS = _polach(xi, eta, phi, N, a, b, G, mu, C11, C22, C23)
        return Fx, Fy + FyS, Mzl * _she_factor(Fxl, Fyl, mu, N)


@register_creep_model("polach2005")
class Polach2005(CreepModel):
    """Polach (2005): reduction factors k_A, k_S and slip-velocity dependent friction.

    F = (2 N mu/pi) [k_A eps/(1 + (k_A eps)^2) + arctan(k_S eps)],  0 < k_S <= k_A <= 1;
    mu = mu0 [(1 - A) exp(-B w) + A],  w = V sqrt(xi^2 + eta^2)  [m/s],  A = mu_inf/mu0.

    All else as :class:`Polach2000` (eps, the spin term and the Mz factor evaluated with mu(w); the
    spin term is not reduced by k_A, k_S).  Small creepage: Fx -> (k_A + k_S)/2 * (-G c^2 C11 xi).
    Large creepage: ``|F|`` -> mu(w) N.  The ``mu`` argument of the call is mu0.

    Defaults k_A = k_S = 1, A = 1, B = 0 reduce the law to :class:`Polach2000`.  The dry and wet
    sets of Polach (2005), Table 2, as quoted second-hand (not checked against the paper), are
    data: :meth:`from_parameter_set` ("dry", "wet"), :func:`polach2005_parameter_sets`.  The notes
    quote mu0 = 0.36, A = 0.38, B = 0.7 s/m for a locomotive (Spiryagin, Polach & Cole 2013).

    Parameters
    ----------
    k_A, k_S : float
        Reduction factors in the adhesion and slip areas, 0 < k_S <= k_A <= 1.
    A : float
        mu_inf/mu0 in (0, 1].
    B : float
        Exponential friction decrease rate [s/m], >= 0.
    speed : float
        Rolling speed V [m/s] used for the slip velocity w.
    join : {"scaled", "raw"}

    References
    ----------
    Polach (2005), Wear 258: 992-1000.
    """

    def __init__(self, k_A: float = 1.0, k_S: float = 1.0, A: float = 1.0, B: float = 0.0,
                 speed: float = 20.0, join: str = "scaled"):
        vals = {}
        for key, val in (("k_A", k_A), ("k_S", k_S), ("A", A), ("B", B), ("speed", speed)):
            if isinstance(val, bool) or not isinstance(val, (int, float, np.integer, np.floating)):
                raise InputError(f"Polach 2005 parameter {key} = {val!r} is not a number")
            vals[key] = float(val)
        k_A, k_S, A, B, speed = (vals[k] for k in ("k_A", "k_S", "A", "B", "speed"))
        if not (0.0 < k_S <= k_A <= 1.0):
            raise InputError(f"Polach 2005 needs 0 < k_S <= k_A <= 1 (reduction factors of Kalker's slope), "
                             f"got k_A={k_A}, k_S={k_S}")
        if not (0.0 < A <= 1.0):
            raise InputError(f"Polach 2005 friction ratio A must lie in (0, 1], got {A} (A = mu_inf / mu_0: "
                             "friction falls with the slip velocity)")
        if not (0.0 <= B < np.inf):
            raise InputError(f"Polach 2005 friction decay B must be >= 0 s/m and finite, got {B}")
        if not (0.0 < speed < np.inf):
            raise InputError(f"Polach 2005 speed must be > 0 m/s and finite, got {speed}")
        self.k_A, self.k_S, self.A, self.B, self.speed, self.join = k_A, k_S, A, B, speed, join

    @classmethod
    def from_parameter_set(cls, name: str, speed: float = 20.0, join: str = "scaled") -> "Polach2005":
        """The law with a published parameter set (k_A, k_S, A, B) by name.

        The sets are data (``data/railway/polach2005_parameters.csv``, see
        :func:`polach2005_parameter_sets`): "dry" (k_A = 1.0, k_S = 0.4, A = 0.4, B = 0.6 s/m)
        and "wet" (k_A = 0.3, k_S = 0.1, A = 0.4, B = 0.2 s/m), quoted second-hand as Polach
        (2005), Wear 258, Table 2, and *not checked against the paper*.  The friction
        coefficient mu0 is the caller's (the ``mu`` of the call); the file's inferred mu0 is
        not used.

        Parameters
        ----------
        name : {"dry", "wet"}
            Parameter set (case-insensitive).
        speed : float
            Rolling speed V (m/s) for the slip velocity w = V ``|(xi, eta)|``.
        join : {"scaled", "raw"}

        Returns
        -------
        Polach2005

        Raises
        ------
        core.errors.UnknownNameError
            An unknown set (lists the sets of the file).
        core.errors.InputError
            A speed <= 0.
        """
        sets = polach2005_parameter_sets()
        key = str(name).strip().lower()
        if key not in set(sets["set"]):
            raise UnknownNameError(f"Polach 2005 parameter set {name!r} is unknown; the sets of "
                                   f"{_POLACH2005_FILE[-1]} are {sorted(sets['set'])}")
        row = sets[sets["set"] == key].iloc[0]
        return cls(k_A=float(row["k_A [-]"]), k_S=float(row["k_S [-]"]), A=float(row["A [-]"]),
                   B=float(row["B [s/m]"]), speed=speed, join=join)

    def friction(self, mu0, xi, eta):
        """mu(w) = mu0 [(1 - A) exp(-B w) + A], w = V ``|(xi, eta)|`` (arrays broadcast)."""
        w = self.speed * np.hypot(xi, eta)
        return mu0 * ((1.0 - self.A) * np.exp(-self.B * w) + self.A)

    def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
        Fxl, Fyl, Mzl, (C11, C22, C23, _) = _kalker_linear(xi, eta, phi, a, b, G, nu, self.join)
        muw = self.friction(mu, xi, eta)
        Fx, Fy, FyS = _polach(xi, eta, phi, N, a, b, G, muw, C11, C22, C23, kA=self.k_A, kS=self.k_S)
        return Fx, Fy + FyS, Mzl * _she_factor(Fxl, Fyl, muw, N)


_POLACH2005_FILE = ("railway", "polach2005_parameters.csv")


def polach2005_parameter_sets() -> pd.DataFrame:
    """Published Polach (2005) parameter sets, read from ``data/railway/polach2005_parameters.csv``.

    Returns
    -------
    DataFrame
        One row per set (``set`` = "dry", "wet"), columns ``k_A [-]``, ``k_S [-]``, ``A [-]``,
        ``B [s/m]``, ``mu0 (inferred) [-]``, ``source`` and ``status``.  Every row is flagged
        "second-hand, not checked against the paper" (Polach 2005, Wear 258, Table 2, quoted by
        a third party); mu0 is an inference from a third-party interpolation, not a quoted value
        (see the file's header).

    Raises
    ------
    core.errors.DataFileError
        Missing columns, or values outside 0 < k_S <= k_A <= 1, 0 < A <= 1, B >= 0 (names the
        file and the row).
    """
    from core.paths import data_path

    path = data_path(*_POLACH2005_FILE)
    df = pd.read_csv(path, comment="#")
    need = {"set", "k_A [-]", "k_S [-]", "A [-]", "B [s/m]", "source", "status"}
    if not need <= set(df.columns):
        raise DataFileError(f"{path}: missing columns {sorted(need - set(df.columns))}")
    df["set"] = df["set"].str.strip().str.lower()
    for _, r in df.iterrows():
        if not (0.0 < r["k_S [-]"] <= r["k_A [-]"] <= 1.0 and 0.0 < r["A [-]"] <= 1.0 and r["B [s/m]"] >= 0.0):
            raise DataFileError(f"{path}: set {r['set']!r} has parameters out of range "
                                f"(k_A={r['k_A [-]']}, k_S={r['k_S [-]']}, A={r['A [-]']}, B={r['B [s/m]']})")
    return df


@register_creep_model("fastsim")
class Fastsim(CreepModel):
    """FASTSIM, Kalker's simplified theory, vectorised over contacts and strips.

    Flexibilities L1 = 8a/(3 G C11), L2 = 8a/(3 G C22), L3 = pi a sqrt(a/b)/(4 G C23); parabolic
    traction bound g(x, y) = mu p_z, p_z = 2N/(pi a b) (1 - x^2/a^2 - y^2/b^2).  Each strip
    y_j (midpoints of ``n_y`` strips across [-b, b]) runs from the leading edge x = a_j =
    a sqrt(1 - y_j^2/b^2) to -a_j in ``n_x`` elements; the traction on the wheel is marched from
    p = 0 at the leading edge::

        p_x <- p_x - (xi/L1 - phi y/L3) dx,   p_y <- p_y - (eta/L2 + phi x/L3) dx,
        if |p| > mu p_z:  p <- mu p_z p/|p|                   (slip)

    with the traction sampled at element centres (the rigid-slip term at the element boundary, so
    that the linear limit is integrated exactly in x).  F = sum p dx dy, Mz = sum (x p_y - y p_x) dx dy.
    At small creepage Fx, Fy tend to Kalker's linear values (exactly, up to the strip quadrature);
    the moment of the simplified theory does not reproduce C23 eta and C33 phi exactly, so Mz
    differs from the linear theory (a known property of the simplified theory).

    Parameters
    ----------
    n_x, n_y : int
        Elements per strip and number of strips.
    join : {"scaled", "raw"}

    References
    ----------
    Kalker (1982), VSD 11: 1-13.
    """

    def __init__(self, n_x: int = 40, n_y: int = 40, join: str = "scaled"):
        if int(n_x) < 2 or int(n_y) < 2:
            raise InputError(f"FASTSIM grid needs n_x, n_y >= 2, got n_x={n_x!r}, n_y={n_y!r}")
        self.n_x, self.n_y, self.join = int(n_x), int(n_y), join

    def _forces(self, xi, eta, phi, N, a, b, G, nu, mu):
        C11, C22, C23, _ = kalker_coefficients(a / b, nu, join=self.join)
        L1 = 8.0 * a / (3.0 * G * C11)
        L2 = 8.0 * a / (3.0 * G * C22)
        L3 = np.pi * a * np.sqrt(a / b) / (4.0 * G * C23)
        ny, nx = self.n_y, self.n_x
        yb = (np.arange(ny) + 0.5) / ny * 2.0 - 1.0          # y/b at strip midpoints
        col = lambda v: v[:, None]                           # (n,) -> (n, 1)
        y = col(b) * yb[None, :]                             # (n, ny)
        dy = 2.0 * col(b) / ny
        aj = col(a) * np.sqrt(1.0 - yb**2)[None, :]          # strip half length (n, ny)
        dx = 2.0 * aj / nx
        pmax_c = 2.0 * col(N) / (np.pi * col(a) * col(b))    # peak pressure (n, 1)
        ax = col(xi / L1) - col(phi / L3) * y                 # x rigid slip rate / L (n, ny)
        ay = col(eta / L2)
        sp = col(phi / L3)
        px = np.zeros_like(y)
        py = np.zeros_like(y)
        Fx = np.zeros(a.shape)
        Fy = np.zeros(a.shape)
        Mz = np.zeros(a.shape)
        for i in range(nx):
            x_c = aj - (i + 0.5) * dx                         # element centre
            x_b = aj - i * dx                                 # boundary passed since last centre
            h = 0.5 * dx if i == 0 else dx
            x_mid = x_b - 0.25 * dx if i == 0 else x_b
            px = px - ax * h
            py = py - (ay + sp * x_mid) * h
            bound = mu[:, None] * pmax_c * np.clip(1.0 - (x_c / col(a)) ** 2 - yb[None, :] ** 2, 0.0, None)
            mag = np.hypot(px, py)
            with np.errstate(invalid="ignore", divide="ignore"):
                fac = np.where(mag > bound, bound / mag, 1.0)
            px = px * fac
            py = py * fac
            w = dx * dy
            Fx += np.sum(px * w, axis=1)
            Fy += np.sum(py * w, axis=1)
            Mz += np.sum((x_c * py - y * px) * w, axis=1)
        return Fx, Fy, Mz


_ALIASES = {
    "kalker": "kalker_linear",
    "linear": "kalker_linear",
    "she": "shen_hedrick_elkins",
    "shen": "shen_hedrick_elkins",
    "polach": "polach2000",
    "polach_2000": "polach2000",
    "polach_2005": "polach2005",
}


#: the creep laws the vehicle runs compare, by name
VEHICLE_CREEP_LAWS = ("kalker_linear", "shen_hedrick_elkins", "polach2000", "polach2005", "fastsim")


def creep_law_for_runs(name: str, speed: float):
    """``(creep_law, creep_params)`` of :func:`railway.vehicles.vehicle.build_vehicle` for a law
    of :data:`VEHICLE_CREEP_LAWS` as the vehicle runs use it: Polach 2005 with the published
    "dry" parameter set (second-hand, see data/railway/polach2005_parameters.csv) at the run's
    ``speed`` [m/s]; FASTSIM on a 10 x 10 grid (called for every contact at every right-hand side);
    the others by name with their defaults."""
    from core.inputs import check_choice

    check_choice(name, VEHICLE_CREEP_LAWS, where="creep law")
    if name == "polach2005":
        return Polach2005.from_parameter_set("dry", speed=speed), None
    if name == "fastsim":
        return Fastsim(10, 10), None
    return name, None
