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
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ..inputs import parse_quantity
from .fe_model import FEModel

__all__ = ["plane_stress_model", "solid_model"]

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
    return FEModel(np.ascontiguousarray(locs[::dim]), dim, sp.csr_matrix(M), sp.csr_matrix(K), source)


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
