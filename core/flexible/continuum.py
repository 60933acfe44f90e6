r"""Plane-stress and solid components, assembled by scikit-fem.

Linear elasticity, isotropic, small strains (Hughes 1987, *The Finite Element Method*, ch. 2):

.. math::

    K:\ \int_\Omega \sigma(u) : \varepsilon(v)\,t\,d\Omega,\qquad
    \sigma = 2\mu\,\varepsilon + \lambda\,\operatorname{tr}\varepsilon\, I,\qquad
    M:\ \int_\Omega \rho\, u\cdot v\,t\,d\Omega,

with the Lamé parameters :math:`\mu = E/(2(1+\nu))`, :math:`\lambda = E\nu/((1+\nu)(1-2\nu))` in a
solid (:math:`t = 1`) and, in plane stress, :math:`\lambda^* = 2\lambda\mu/(\lambda + 2\mu)` with the
thickness :math:`t` (the through-thickness stress eliminated).  The forms are scikit-fem's
(``skfem.models.elasticity.linear_elasticity``, a ``BilinearForm`` for the mass); the elements are
its Lagrange elements, quadratic by default (linear triangles and tetrahedra lock in bending).

Why scikit-fem: a maintained, pure-Python assembler of exactly these forms (Gustafsson &
McBain 2020, JOSS 5(52):2369), on scipy's sparse matrices; writing and testing element
integration here would add nothing.

The degrees of freedom of the result are numbered node by node, (u_x, u_y[, u_z]) at every node
of the element (vertices, and mid-edge points for quadratic elements): scikit-fem's numbering,
checked here to interleave the components at each location.

Stresses at the nodes (:class:`ContinuumStresses`): the stress of a displacement field is
discontinuous between elements; it is evaluated at the quadrature points, σ = 2με + λ tr ε I
(λ* in plane stress), and smoothed by the L2 projection onto the component's own continuous
Lagrange basis, σ_h = M_s⁻¹ ∫ σ w dΩ (Zienkiewicz & Taylor, *The Finite Element Method*, vol. 1,
the global projection of stresses; exact wherever σ lies in that basis, as in uniform tension or
pure bending on quadratic elements).  A flexible body applies it to each mode once
(:attr:`core.flexible.body.FlexibleBodyData.stress_modes`, the modal stresses of Adams' and
Simpack's flexible-body files), so a stress at run time is a sum over the modes.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ..inputs import parse_quantity
from .fe_model import FEModel

__all__ = ["ContinuumStresses", "plane_stress_model", "solid_model", "von_mises"]

_ELEMENTS = {
    ("tri", 1): "ElementTriP1", ("tri", 2): "ElementTriP2",
    ("quad", 1): "ElementQuad1", ("quad", 2): "ElementQuad2",
    ("tet", 1): "ElementTetP1", ("tet", 2): "ElementTetP2",
    ("hex", 1): "ElementHex1", ("hex", 2): "ElementHex2",
}


def _skfem():
    try:
        import skfem
    except ImportError:  # pragma: no cover - a declared dependency
        raise InputError("plane and solid components need scikit-fem (pip install scikit-fem)") from None
    return skfem


def _shape(mesh) -> str:
    skfem = _skfem()
    for cls, name in ((skfem.MeshTri, "tri"), (skfem.MeshQuad, "quad"), (skfem.MeshTet, "tet"), (skfem.MeshHex, "hex")):
        if isinstance(mesh, cls):
            return name
    raise InputError(f"the mesh must be a scikit-fem MeshTri, MeshQuad, MeshTet or MeshHex, got {type(mesh).__name__}")


def _material(E, nu, rho, accept=()):
    from .ranges import checked

    E = checked("E", E, "Young's modulus E", accept)
    rho = checked("rho", rho, "density rho", accept)
    nu = parse_quantity(nu, "1", where="Poisson's ratio nu")
    if not -1.0 < nu < 0.5:
        raise InputError(f"Poisson's ratio nu = {nu!r} must lie in (-1, 0.5)")
    mu = E / (2.0 * (1.0 + nu))
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    return E, nu, rho, lam, mu


class ContinuumStresses:
    """Nodal stresses of a plane-stress or solid component (module docstring); picklable.

    Calling it with displacement columns ``U`` (n_dofs, k) returns the stresses at the FE model's
    nodes, shape (n_nodes, n_components, k) [Pa]: (σ_xx, σ_yy, τ_xy) in plane stress, (σ_xx, σ_yy,
    σ_zz, τ_xy, τ_yz, τ_xz) in a solid; :attr:`components` names them.
    """

    def __init__(self, mesh, order: int, lam: float, mu: float):
        self.mesh, self.order, self.lam, self.mu = mesh, int(order), float(lam), float(mu)
        self.dim = mesh.p.shape[0]
        self.components = (("σ_xx", "σ_yy", "τ_xy") if self.dim == 2 else
                           ("σ_xx", "σ_yy", "σ_zz", "τ_xy", "τ_yz", "τ_xz"))

    def __call__(self, U) -> np.ndarray:
        skfem = _skfem()
        from skfem.helpers import sym_grad

        U = np.asarray(U, float)
        U = U[:, None] if U.ndim == 1 else U
        element = getattr(skfem, _ELEMENTS[(_shape(self.mesh), self.order)])()
        basis_u = skfem.Basis(self.mesh, skfem.ElementVector(element))
        basis_s = basis_u.with_element(element)
        if U.shape[0] != basis_u.N:
            raise InputError(f"stress recovery: {U.shape[0]} displacement rows, the component has {basis_u.N}")
        d = self.dim
        pairs = [(0, 0), (1, 1), (0, 1)] if d == 2 else [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
        out = np.empty((basis_s.N, len(pairs), U.shape[1]))
        for k in range(U.shape[1]):
            eps = np.asarray(sym_grad(basis_u.interpolate(U[:, k])))  # (d, d, n_elements, n_points)
            tr = sum(eps[i, i] for i in range(d))
            for c, (i, j) in enumerate(pairs):
                sigma = 2.0 * self.mu * eps[i, j] + (self.lam * tr if i == j else 0.0)
                out[:, c, k] = basis_s.project(sigma)
        return out


def von_mises(stresses) -> np.ndarray:
    """Von Mises equivalent stress [Pa] of stresses (..., 3) in plane stress (σ_xx, σ_yy, τ_xy) or
    (..., 6) in a solid (σ_xx, σ_yy, σ_zz, τ_xy, τ_yz, τ_xz):
    √(½[(σ_x − σ_y)² + (σ_y − σ_z)² + (σ_z − σ_x)²] + 3(τ_xy² + τ_yz² + τ_xz²)),
    σ_z = τ_yz = τ_xz = 0 in plane stress."""
    s = np.asarray(stresses, float)
    if s.shape[-1] == 3:
        sx, sy, txy = s[..., 0], s[..., 1], s[..., 2]
        return np.sqrt(sx * sx - sx * sy + sy * sy + 3.0 * txy * txy)
    if s.shape[-1] == 6:
        sx, sy, sz, txy, tyz, txz = (s[..., i] for i in range(6))
        return np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2) + 3.0 * (txy**2 + tyz**2 + txz**2))
    raise InputError(f"von_mises: the last axis must hold 3 (plane stress) or 6 (solid) components, "
                     f"got {s.shape[-1]}")


def _assemble(mesh, order, lam, mu, rho, scale, source) -> FEModel:
    skfem = _skfem()
    from skfem.helpers import dot
    from skfem.models.elasticity import linear_elasticity

    if order not in (1, 2):
        raise InputError(f"element order {order!r}: 1 (linear) or 2 (quadratic)")
    kind = _shape(mesh)
    element = skfem.ElementVector(getattr(skfem, _ELEMENTS[(kind, order)])())
    basis = skfem.Basis(mesh, element)
    K = skfem.asm(linear_elasticity(lam, mu), basis) * scale

    @skfem.BilinearForm
    def mass(u, v, w):
        return rho * dot(u, v)

    M = skfem.asm(mass, basis) * scale
    dim = mesh.p.shape[0]
    locs = basis.doflocs.T  # (n_dofs, dim)
    n = locs.shape[0]
    if n % dim or not np.allclose(locs.reshape(-1, dim, dim) - locs[::dim][:, None, :], 0.0):
        raise InputError("scikit-fem numbered the components of a node apart; this scikit-fem version is not "
                         "supported")  # pragma: no cover
    return FEModel(np.ascontiguousarray(locs[::dim]), dim, sp.csr_matrix(M), sp.csr_matrix(K), source,
                   stress_recovery=ContinuumStresses(mesh, order, lam, mu))


def plane_stress_model(mesh, E, nu, rho, thickness, order: int = 2, accept=()) -> FEModel:
    """A plane-stress component of ``thickness`` [m] on a scikit-fem triangle or quadrilateral
    mesh [m] (module docstring): (u_x, u_y) per node.  E, rho and the thickness are checked
    against their plausible ranges (:mod:`core.flexible.ranges`; ``accept`` names deliberate
    outliers)."""
    from .ranges import checked

    E, nu, rho, lam, mu = _material(E, nu, rho, accept)
    t = checked("thickness", thickness, "thickness", accept)
    _shape(mesh)
    if mesh.p.shape[0] != 2:
        raise InputError(f"plane_stress_model needs a 2-D mesh, got {mesh.p.shape[0]}-D")
    lam_star = 2.0 * lam * mu / (lam + 2.0 * mu)
    return _assemble(mesh, order, lam_star, mu, rho, t,
                     f"plane stress, {type(mesh).__name__} with {mesh.t.shape[1]} elements, order {order}")


def solid_model(mesh, E, nu, rho, order: int = 2, accept=()) -> FEModel:
    """A solid component on a scikit-fem tetrahedron or hexahedron mesh [m] (module docstring):
    (u_x, u_y, u_z) per node; E and rho checked as in :func:`plane_stress_model`."""
    E, nu, rho, lam, mu = _material(E, nu, rho, accept)
    _shape(mesh)
    if mesh.p.shape[0] != 3:
        raise InputError(f"solid_model needs a 3-D mesh, got {mesh.p.shape[0]}-D")
    return _assemble(mesh, order, lam, mu, rho, 1.0,
                     f"solid, {type(mesh).__name__} with {mesh.t.shape[1]} elements, order {order}")
