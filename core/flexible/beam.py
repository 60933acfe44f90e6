r"""Beam finite elements, planar and spatial, Euler–Bernoulli and Timoshenko.

Two-node elements of length :math:`L` with consistent mass.  Local axes: :math:`x` along the
element from node i to node j; in space :math:`y` in the plane of :math:`x` and the section's
orientation vector, :math:`z = x \times y`.

Degrees of freedom per node
---------------------------
* planar (3): :math:`u_x, u_y, \theta_z` (global);
* spatial (6): :math:`u_x, u_y, u_z, \theta_x, \theta_y, \theta_z` (global).

Equations (local axes)
----------------------
Axial, bar with linear shape functions:

.. math::

    K_a = \frac{EA}{L}\begin{bmatrix}1&-1\\-1&1\end{bmatrix},\qquad
    M_a = \frac{\rho A L}{6}\begin{bmatrix}2&1\\1&2\end{bmatrix};

torsion alike with :math:`GJ` and :math:`\rho I_p` (:math:`J` the torsion constant, :math:`I_p`
the polar second moment).  Bending in the :math:`x`–:math:`y` plane on
:math:`(v_i, \theta_{z,i}, v_j, \theta_{z,j})` with :math:`\Phi = 12 EI_z/(\kappa G A L^2)`
(:math:`\Phi = 0`: Euler–Bernoulli):

.. math::

    K_b = \frac{EI_z}{(1+\Phi)L^3}\begin{bmatrix}
      12 & 6L & -12 & 6L\\ 6L & (4+\Phi)L^2 & -6L & (2-\Phi)L^2\\
      -12 & -6L & 12 & -6L\\ 6L & (2-\Phi)L^2 & -6L & (4+\Phi)L^2\end{bmatrix}

(Przemieniecki 1968, *Theory of Matrix Structural Analysis*, eq. 5.116), and the consistent mass
of the Timoshenko element, translational and rotary parts (Friedman & Kosmatka 1993, Computers &
Structures 47(3):473–481, eqs. 17–18):

.. math::

    M_{\rho A} = \frac{\rho A L}{210(1+\Phi)^2}\begin{bmatrix}
      70\Phi^2+147\Phi+78 & (35\Phi^2+77\Phi+44)\frac L4 & 35\Phi^2+63\Phi+27 & -(35\Phi^2+63\Phi+26)\frac L4\\
      & (7\Phi^2+14\Phi+8)\frac{L^2}4 & (35\Phi^2+63\Phi+26)\frac L4 & -(7\Phi^2+14\Phi+6)\frac{L^2}4\\
      & & 70\Phi^2+147\Phi+78 & -(35\Phi^2+77\Phi+44)\frac L4\\
      \text{sym.} & & & (7\Phi^2+14\Phi+8)\frac{L^2}4\end{bmatrix},

.. math::

    M_{\rho I} = \frac{\rho I_z}{30(1+\Phi)^2 L}\begin{bmatrix}
      36 & (3-15\Phi)L & -36 & (3-15\Phi)L\\
      & (4+5\Phi+10\Phi^2)L^2 & -(3-15\Phi)L & (-1-5\Phi+5\Phi^2)L^2\\
      & & 36 & -(3-15\Phi)L\\
      \text{sym.} & & & (4+5\Phi+10\Phi^2)L^2\end{bmatrix}.

At :math:`\Phi = 0` :math:`M_{\rho A}` is the classical :math:`\rho A L/420\,[156, 22L, 54, -13L; \dots]`.
The Euler–Bernoulli element has no rotary inertia (the closed forms it is checked against have
none); the Timoshenko element has shear deformation and rotary inertia.  Bending in the
:math:`x`–:math:`z` plane uses the same matrices on :math:`(w_i, -\theta_{y,i}, w_j, -\theta_{y,j})`
with :math:`I_y` (a positive :math:`\theta_y` lowers :math:`w` along :math:`x`).

Global matrices: :math:`K = T^\mathsf{T} K_\ell T` with :math:`T` the rotation of every node's
translations and rotations into the local axes; assembled into scipy sparse matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ..inputs import parse_quantity

__all__ = ["BeamGeometricStiffness", "BeamMesh", "BeamSection", "beam_matrices", "geometric_stiffness",
           "section_forces", "fibre_stresses", "straight_beam", "SECTION_FORCES", "THEORIES"]

THEORIES = ("euler-bernoulli", "timoshenko")


@dataclass(frozen=True)
class BeamSection:
    """Material and cross-section of a beam, SI units (a number, or a string with its unit such as
    ``"210 GPa"``).

    Parameters
    ----------
    E : Young's modulus [Pa]
    rho : density [kg/m^3]
    A : area [m^2]
    Iz : second moment about the local z axis [m^4] (bending in the x–y plane; the planar one)
    Iy : second moment about the local y axis [m^4] (bending in the x–z plane); default ``Iz``
    G : shear modulus [Pa]; default from ``nu``: E / (2 (1 + nu))
    nu : Poisson's ratio [-], default 0.3 (used only when G is not given)
    J : torsion constant [m^4]; default ``Iy + Iz`` (a circular section)
    Ip : polar second moment for the rotary inertia of torsion [m^4]; default ``Iy + Iz``
    shear_factor : Timoshenko's shear coefficient kappa [-]; default 5/6 (a rectangle)
    outline : the section's shape for fibre stresses, ``("rectangle", width, height)`` or
        ``("circle", diameter)`` [m]; set by :meth:`rectangle` and :meth:`circle`, None for a section
        given by its properties only (:func:`fibre_stresses` then refuses)
    accept : quantities whose plausible range (``data/core/flexible_plausible_ranges.csv``) is not
        enforced, e.g. ``("E",)`` for a deliberately soft material; otherwise a value outside is
        refused with the likely unit slip named
    """

    E: float
    rho: float
    A: float
    Iz: float
    Iy: float | None = None
    G: float | None = None
    nu: float = 0.3
    J: float | None = None
    Ip: float | None = None
    shear_factor: float = 5.0 / 6.0
    accept: tuple = ()
    outline: tuple | None = None

    def __post_init__(self):
        from .ranges import checked

        accept = (self.accept,) if isinstance(self.accept, str) else tuple(self.accept)
        object.__setattr__(self, "accept", accept)
        ranged = {"E": "E", "G": "G", "rho": "rho", "A": "A", "Iz": "I", "Iy": "I", "J": "I", "Ip": "I"}
        for name, quantity in ranged.items():
            value = getattr(self, name)
            if value is not None:
                a = accept + ((quantity,) if name in accept else ())
                object.__setattr__(self, name, checked(quantity, value, f"beam section {name}", a))
        nu = parse_quantity(self.nu, "1", where="beam section nu")
        if not -1.0 < nu < 0.5:
            raise InputError(f"beam section nu = {nu!r}: Poisson's ratio must lie in (-1, 0.5)")
        kappa = parse_quantity(self.shear_factor, "1", where="beam section shear_factor")
        if not 0.0 < kappa <= 1.5:
            raise InputError(f"beam section shear_factor = {kappa!r}: Timoshenko's coefficient lies in (0, 1.5] "
                             "(5/6 for a rectangle, about 0.89 for a circle)")
        object.__setattr__(self, "nu", nu)
        object.__setattr__(self, "shear_factor", kappa)
        if self.Iy is None:
            object.__setattr__(self, "Iy", self.Iz)
        if self.G is None:
            object.__setattr__(self, "G", self.E / (2.0 * (1.0 + self.nu)))
        for name in ("J", "Ip"):
            if getattr(self, name) is None:
                object.__setattr__(self, name, self.Iy + self.Iz)
        if self.outline is not None:
            o = tuple(self.outline)
            sizes = {"rectangle": 2, "circle": 1}
            if not (o and o[0] in sizes and len(o) == 1 + sizes[o[0]]
                    and all(isinstance(x, (int, float)) and np.isfinite(x) and x > 0 for x in o[1:])):
                raise InputError(f"beam section outline = {self.outline!r}: give ('rectangle', width, height) or "
                                 "('circle', diameter) in m, positive")
            object.__setattr__(self, "outline", (o[0],) + tuple(float(x) for x in o[1:]))

    @classmethod
    def rectangle(cls, E, rho, width, height, **kw) -> BeamSection:
        """A solid rectangle ``width`` (local y) by ``height`` (local z): A = b h, Iz = h b³/12,
        Iy = b h³/12, torsion constant J = β b h³ with Roark's series for the larger side b ≥ h,
        κ = 5/6."""
        from .ranges import checked

        b, h = (checked("thickness", x, f"rectangle {n}", kw.get("accept", ()))
                for x, n in ((width, "width"), (height, "height")))
        long, short = max(b, h), min(b, h)
        # Young & Budynas, Roark's Formulas for Stress and Strain, 7th ed., table 10.7 case 4
        J = long * short**3 * (1.0 / 3.0 - 0.21 * short / long * (1.0 - short**4 / (12.0 * long**4)))
        return cls(E=E, rho=rho, A=b * h, Iz=h * b**3 / 12.0, Iy=b * h**3 / 12.0, J=kw.pop("J", J),
                   outline=("rectangle", float(b), float(h)), **kw)

    @classmethod
    def circle(cls, E, rho, diameter, **kw) -> BeamSection:
        """A solid circle: A = π d²/4, Iy = Iz = π d⁴/64, J = Ip = π d⁴/32, κ = 6 (1 + ν)/(7 + 6 ν)
        (Cowper 1966)."""
        from .ranges import checked

        d = checked("thickness", diameter, "circle diameter", kw.get("accept", ()))
        nu = parse_quantity(kw.get("nu", 0.3), "1", where="beam section nu")
        kw.setdefault("shear_factor", 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu))
        return cls(E=E, rho=rho, A=np.pi * d**2 / 4.0, Iz=np.pi * d**4 / 64.0, outline=("circle", float(d)), **kw)


@dataclass(frozen=True)
class BeamMesh:
    """Nodes (N, 2) or (N, 3) [m] and two-node elements (n_el, 2) of node indices; in space an
    ``orientation`` vector that, with each element's axis, spans its local x–y plane."""

    nodes: np.ndarray
    elements: np.ndarray
    orientation: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self):
        nodes = np.asarray(self.nodes, float)
        if nodes.ndim != 2 or nodes.shape[1] not in (2, 3) or nodes.shape[0] < 2:
            raise InputError(f"beam mesh: nodes must be an (N, 2) or (N, 3) array with N >= 2, got shape "
                             f"{nodes.shape}")
        if not np.all(np.isfinite(nodes)):
            raise InputError(f"beam mesh: node {int(np.argmax(~np.isfinite(nodes).all(axis=1)))} is not finite")
        el = np.asarray(self.elements)
        if el.ndim != 2 or el.shape[1] != 2 or el.shape[0] < 1 or not np.issubdtype(el.dtype, np.integer):
            raise InputError(f"beam mesh: elements must be an (n_el, 2) integer array, got shape {el.shape}")
        bad = np.flatnonzero((el < 0).any(axis=1) | (el >= nodes.shape[0]).any(axis=1))
        if bad.size:
            raise InputError(f"beam mesh: element {int(bad[0])} {el[bad[0]].tolist()} names a node outside "
                             f"0..{nodes.shape[0] - 1}")
        lengths = np.linalg.norm(nodes[el[:, 1]] - nodes[el[:, 0]], axis=1)
        short = np.flatnonzero(~(lengths > 0.0))
        if short.size:
            raise InputError(f"beam mesh: element {int(short[0])} joins node {int(el[short[0], 0])} to itself "
                             "(zero length)")
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "elements", el.astype(np.int64))

    @property
    def dim(self) -> int:
        return self.nodes.shape[1]

    @property
    def dofs_per_node(self) -> int:
        """3 in the plane (u_x, u_y, θ_z), 6 in space (u, θ)."""
        return 3 if self.dim == 2 else 6

    @property
    def n_dofs(self) -> int:
        return self.nodes.shape[0] * self.dofs_per_node

    def dofs(self, node: int, which=None) -> np.ndarray:
        """Global indices of a node's degrees of freedom (all, or ``which``: indices into the
        node's list, e.g. ``[0, 1]`` for its translations in the plane)."""
        n = self.dofs_per_node
        k = np.arange(n) if which is None else np.asarray(which, np.int64)
        return int(node) * n + k


def straight_beam(length, n_elements: int, dim: int = 2, start=None, direction=None,
                  orientation=(0.0, 0.0, 1.0)) -> BeamMesh:
    """A straight beam of ``n_elements`` equal elements from ``start`` (default the origin) along
    ``direction`` (default x)."""
    from .ranges import checked

    L = checked("length", length, "beam length")
    if not (isinstance(n_elements, (int, np.integer)) and n_elements >= 1):
        raise InputError(f"n_elements = {n_elements!r} must be a positive integer")
    if dim not in (2, 3):
        raise InputError(f"dim = {dim!r}: 2 (planar) or 3 (spatial)")
    start = np.zeros(dim) if start is None else np.asarray(start, float).reshape(dim)
    d = np.eye(dim)[0] if direction is None else np.asarray(direction, float).reshape(dim)
    if not np.linalg.norm(d) > 0:
        raise InputError("straight_beam: direction must be a non-zero vector")
    d = d / np.linalg.norm(d)
    s = np.linspace(0.0, L, n_elements + 1)
    nodes = start[None, :] + s[:, None] * d[None, :]
    elements = np.column_stack([np.arange(n_elements), np.arange(1, n_elements + 1)])
    return BeamMesh(nodes, elements, orientation)


def _bending(L, EI, rhoA, rhoI, phi, rotary: bool):
    """(K, M) 4x4 of the bending element on (v_i, θ_i, v_j, θ_j) (module docstring)."""
    c = EI / ((1.0 + phi) * L**3)
    K = c * np.array([[12.0, 6 * L, -12.0, 6 * L],
                      [6 * L, (4 + phi) * L**2, -6 * L, (2 - phi) * L**2],
                      [-12.0, -6 * L, 12.0, -6 * L],
                      [6 * L, (2 - phi) * L**2, -6 * L, (4 + phi) * L**2]])
    p = phi
    a1, a2, a3, a4 = 70 * p**2 + 147 * p + 78, (35 * p**2 + 77 * p + 44) * L / 4, 35 * p**2 + 63 * p + 27, \
        (35 * p**2 + 63 * p + 26) * L / 4
    a5, a6 = (7 * p**2 + 14 * p + 8) * L**2 / 4, (7 * p**2 + 14 * p + 6) * L**2 / 4
    M = rhoA * L / (210.0 * (1 + p) ** 2) * np.array([[a1, a2, a3, -a4],
                                                      [a2, a5, a4, -a6],
                                                      [a3, a4, a1, -a2],
                                                      [-a4, -a6, -a2, a5]])
    if rotary:
        b1, b2, b3 = 36.0, (3 - 15 * p) * L, (4 + 5 * p + 10 * p**2) * L**2
        b4 = (-1 - 5 * p + 5 * p**2) * L**2
        M = M + rhoI / (30.0 * (1 + p) ** 2 * L) * np.array([[b1, b2, -b1, b2],
                                                              [b2, b3, -b2, b4],
                                                              [-b1, -b2, b1, -b2],
                                                              [b2, b4, -b2, b3]])
    return K, M


def _bar(L, k, m):
    """(K, M) 2x2 of a bar (axial or torsion): stiffness k/L, mass m L/6 [2 1; 1 2]."""
    return k / L * np.array([[1.0, -1.0], [-1.0, 1.0]]), m * L / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])


def _local_axes(mesh: BeamMesh, e: int) -> tuple[float, np.ndarray]:
    """Length and the rotation R (rows: local x, y[, z] in global components) of element e."""
    i, j = mesh.elements[e]
    d = mesh.nodes[j] - mesh.nodes[i]
    L = float(np.linalg.norm(d))
    ex = d / L
    if mesh.dim == 2:
        return L, np.array([ex, [-ex[1], ex[0]]])
    v = np.asarray(mesh.orientation, float)
    ey = v - (v @ ex) * ex
    if not np.linalg.norm(ey) > 1e-9 * max(np.linalg.norm(v), 1e-300):
        raise InputError(f"beam mesh: element {e} lies along the orientation vector {v.tolist()}; give an "
                         "orientation vector that is not parallel to the element")
    ey /= np.linalg.norm(ey)
    return L, np.array([ex, ey, np.cross(ex, ey)])


def _element_rotation(mesh: BeamMesh, e: int) -> np.ndarray:
    """The rotation of element e's nodal dofs into its local axes, (6, 6) or (12, 12)."""
    _, R = _local_axes(mesh, e)
    if mesh.dim == 2:
        T = np.zeros((6, 6))
        for n in (0, 3):
            T[n:n + 2, n:n + 2] = R
            T[n + 2, n + 2] = 1.0
        return T
    T = np.zeros((12, 12))
    for n in range(4):
        T[3 * n:3 * n + 3, 3 * n:3 * n + 3] = R
    return T


#: the section forces of :func:`section_forces`, planar and spatial
SECTION_FORCES = {2: ("N [N]", "V [N]", "M [N m]"),
                  3: ("N [N]", "Vy [N]", "Vz [N]", "T [N m]", "My [N m]", "Mz [N m]")}


def section_forces(mesh: BeamMesh, section: BeamSection, u, theory: str = "euler-bernoulli") -> np.ndarray:
    r"""Section forces at both ends of every element for the nodal displacements ``u``.

    The element's end loads in its local axes, :math:`f = T K_e u_e` (the loads the nodes apply to
    the element), give the section forces at the two ends as the load that the part of the beam
    towards node j transmits to the part towards node i: :math:`-f_i` at end i, :math:`+f_j` at end
    j.  So tension and a moment that turns the far part positively about the local axis are
    positive; a cantilever along x with a tip load P along y has :math:`M_z = P(L - x)`.  They are
    exact for the element's own shape functions: static loads at nodes give the exact section forces
    of an Euler–Bernoulli beam; distributed inertia loads converge with the mesh.

    Returns
    -------
    (n_el, 2, 3) or (n_el, 2, 6) ndarray
        Per element and end (i, j): ``SECTION_FORCES[dim]`` (N, V, M in the plane; N, V_y, V_z, T,
        M_y, M_z in space) [N, N m].
    """
    u = np.asarray(u, float).reshape(mesh.n_dofs)
    n = mesh.dofs_per_node
    out = np.empty((mesh.elements.shape[0], 2, n))
    for e in range(mesh.elements.shape[0]):
        Ke, _ = element_matrices(mesh, section, e, theory)
        i, j = mesh.elements[e]
        ue = np.concatenate([u[i * n:(i + 1) * n], u[j * n:(j + 1) * n]])
        f = _element_rotation(mesh, e) @ (Ke @ ue)
        out[e, 0], out[e, 1] = -f[:n], f[n:]
    return out


def fibre_stresses(mesh: BeamMesh, section: BeamSection, u, theory: str = "euler-bernoulli") -> np.ndarray:
    r"""Largest and smallest normal stress over the section at both ends of every element (Navier).

    From the section forces (:func:`section_forces`) and the section's outline: the normal stress
    of axial force and bending, :math:`\sigma = N/A - M_z y/I_z + M_y z/I_y`, at its extreme fibres,

    * rectangle b × h (local y × z): :math:`\sigma_{max,min} = N/A \pm (|M_z|\,b/(2I_z) +
      |M_y|\,h/(2I_y))`, reached at a corner; in the plane :math:`N/A \pm |M|\,b/(2I_z)`;
    * circle of diameter d: :math:`N/A \pm \sqrt{M_y^2 + M_z^2}\,d/(2I)` (the bending axis turns
      with the moment vector);

    (Young & Budynas, *Roark's Formulas for Stress and Strain*, 7th ed., sec. 8.1).  Shear stresses
    of V and T are not included.

    Returns
    -------
    (n_el, 2, 2) ndarray
        Per element and end (i, j): (σ_max, σ_min) [Pa].

    Raises
    ------
    InputError
        A section without an outline (made from its properties only).
    """
    if section.outline is None:
        raise InputError("fibre stresses need the section's outline: make the section with BeamSection.rectangle "
                         "or BeamSection.circle (or give outline=('rectangle', width, height) / ('circle', d))")
    sf = section_forces(mesh, section, u, theory)
    N = sf[..., 0]
    kind = section.outline[0]
    if mesh.dim == 2:
        c = section.outline[1] / 2.0  # the width along local y (bending in the x–y plane)
        bend = np.abs(sf[..., 2]) * c / section.Iz
    elif kind == "rectangle":
        b, h = section.outline[1], section.outline[2]
        bend = np.abs(sf[..., 5]) * b / (2.0 * section.Iz) + np.abs(sf[..., 4]) * h / (2.0 * section.Iy)
    else:
        bend = np.hypot(sf[..., 4], sf[..., 5]) * section.outline[1] / (2.0 * section.Iz)
    axial = N / section.A
    return np.stack([axial + bend, axial - bend], axis=-1)


def element_matrices(mesh: BeamMesh, section: BeamSection, e: int, theory: str = "euler-bernoulli"):
    """Global-axes (K, M) of element e: (6, 6) in the plane, (12, 12) in space."""
    L, R = _local_axes(mesh, e)
    s = section
    timo = theory == "timoshenko"
    if mesh.dim == 2:
        phi = 12 * s.E * s.Iz / (s.shear_factor * s.G * s.A * L**2) if timo else 0.0
        Kl, Ml = np.zeros((6, 6)), np.zeros((6, 6))
        Ka, Ma = _bar(L, s.E * s.A, s.rho * s.A)
        ax = [0, 3]
        Kl[np.ix_(ax, ax)] += Ka
        Ml[np.ix_(ax, ax)] += Ma
        Kb, Mb = _bending(L, s.E * s.Iz, s.rho * s.A, s.rho * s.Iz, phi, timo)
        bd = [1, 2, 4, 5]
        Kl[np.ix_(bd, bd)] += Kb
        Ml[np.ix_(bd, bd)] += Mb
        T = np.zeros((6, 6))
        for n in (0, 3):
            T[n:n + 2, n:n + 2] = R
            T[n + 2, n + 2] = 1.0
        return T.T @ Kl @ T, T.T @ Ml @ T
    Kl, Ml = np.zeros((12, 12)), np.zeros((12, 12))
    for k_, m_, dofs in ((s.E * s.A, s.rho * s.A, [0, 6]), (s.G * s.J, s.rho * s.Ip, [3, 9])):
        Kx, Mx = _bar(L, k_, m_)
        Kl[np.ix_(dofs, dofs)] += Kx
        Ml[np.ix_(dofs, dofs)] += Mx
    # x-y plane: (v, θz); x-z plane: (w, -θy)
    for I, dofs, sign in ((s.Iz, [1, 5, 7, 11], np.array([1.0, 1.0, 1.0, 1.0])),
                          (s.Iy, [2, 4, 8, 10], np.array([1.0, -1.0, 1.0, -1.0]))):
        phi = 12 * s.E * I / (s.shear_factor * s.G * s.A * L**2) if timo else 0.0
        Kb, Mb = _bending(L, s.E * I, s.rho * s.A, s.rho * I, phi, timo)
        S = np.diag(sign)
        Kl[np.ix_(dofs, dofs)] += S @ Kb @ S
        Ml[np.ix_(dofs, dofs)] += S @ Mb @ S
    T = np.zeros((12, 12))
    for n in range(4):
        T[3 * n:3 * n + 3, 3 * n:3 * n + 3] = R
    return T.T @ Kl @ T, T.T @ Ml @ T


def beam_matrices(mesh: BeamMesh, section: BeamSection, theory: str = "euler-bernoulli"):
    """Assembled mass and stiffness of the mesh, ``(M, K)`` as scipy CSR matrices of order
    ``mesh.n_dofs`` (free: no support; see :mod:`core.flexible.reduction` for fixed nodes)."""
    if theory not in THEORIES:
        from ..inputs import closest

        raise InputError(f"beam theory {theory!r}: give one of {', '.join(THEORIES)}"
                         + (f" (did you mean {closest(theory, THEORIES)!r}?)" if isinstance(theory, str) else ""))
    if not isinstance(section, BeamSection):
        raise InputError(f"beam_matrices: section must be a BeamSection, got {type(section).__name__}")
    n = mesh.dofs_per_node
    rows, cols, kv, mv = [], [], [], []
    for e in range(mesh.elements.shape[0]):
        Ke, Me = element_matrices(mesh, section, e, theory)
        i, j = mesh.elements[e]
        idx = np.concatenate([np.arange(n) + i * n, np.arange(n) + j * n])
        r, c = np.meshgrid(idx, idx, indexing="ij")
        rows.append(r.ravel())
        cols.append(c.ravel())
        kv.append(Ke.ravel())
        mv.append(Me.ravel())
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    shape = (mesh.n_dofs, mesh.n_dofs)
    K = sp.csr_matrix((np.concatenate(kv), (rows, cols)), shape=shape)
    M = sp.csr_matrix((np.concatenate(mv), (rows, cols)), shape=shape)
    return M, K


def _geometric_bending(L):
    """Consistent geometric stiffness of a bending element per unit axial force, on
    (v_i, θ_i, v_j, θ_j) (Przemieniecki 1968, eq. 15.33; cubic Hermite shape functions)."""
    return 1.0 / (30.0 * L) * np.array([[36.0, 3 * L, -36.0, 3 * L],
                                        [3 * L, 4 * L**2, -3 * L, -L**2],
                                        [-36.0, -3 * L, 36.0, -3 * L],
                                        [3 * L, -L**2, -3 * L, 4 * L**2]])


def _unit_geometric(mesh: BeamMesh, e: int):
    """(element dof indices, global-axes geometric stiffness of element e per unit axial force)."""
    L, R = _local_axes(mesh, e)
    i, j = mesh.elements[e]
    n = mesh.dofs_per_node
    Gb = _geometric_bending(L)
    if mesh.dim == 2:
        Kl = np.zeros((6, 6))
        bd = [1, 2, 4, 5]
        Kl[np.ix_(bd, bd)] = Gb
        T = np.zeros((6, 6))
        for k in (0, 3):
            T[k:k + 2, k:k + 2] = R
            T[k + 2, k + 2] = 1.0
    else:
        Kl = np.zeros((12, 12))
        Kl[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])] = Gb
        S = np.diag([1.0, -1.0, 1.0, -1.0])
        Kl[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])] = S @ Gb @ S
        T = np.zeros((12, 12))
        for k in range(4):
            T[3 * k:3 * k + 3, 3 * k:3 * k + 3] = R
    idx = np.concatenate([np.arange(n) + i * n, np.arange(n) + j * n])
    return idx, T.T @ Kl @ T


def _assemble(mesh: BeamMesh, parts) -> sp.csr_matrix:
    rows, cols, vals = [], [], []
    for idx, Ke in parts:
        r, c = np.meshgrid(idx, idx, indexing="ij")
        rows.append(r.ravel())
        cols.append(c.ravel())
        vals.append(Ke.ravel())
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(mesh.n_dofs, mesh.n_dofs))


def geometric_stiffness(mesh: BeamMesh, section: BeamSection, u) -> sp.csr_matrix:
    r"""Geometric (stress) stiffness of the mesh in the axial-force state of the displacement ``u``.

    Each element's axial force :math:`N_e = EA\,(u_j - u_i)\cdot e_x / L` multiplies its consistent
    geometric stiffness :math:`N_e/(30L)\,[36, 3L, -36, 3L; \dots]` in both bending planes
    (Przemieniecki 1968, eq. 15.33), so that :math:`(K + K_G(u))` is the tangent stiffness of a beam
    pre-stressed by :math:`u`.  Tension (:math:`N > 0`) stiffens.  The torsional term
    :math:`N I_p / (A L)` is left out (second order for slender beams).

    Parameters
    ----------
    u : (n_dofs,) array
        Nodal displacements [m, rad] in the mesh's global axes.
    """
    u = np.asarray(u, float).reshape(mesh.n_dofs)
    n, d = mesh.dofs_per_node, mesh.dim
    parts = []
    for e in range(mesh.elements.shape[0]):
        L, R = _local_axes(mesh, e)
        i, j = mesh.elements[e]
        N = section.E * section.A * float(R[0] @ (u[j * n:j * n + d] - u[i * n:i * n + d])) / L
        idx, G = _unit_geometric(mesh, e)
        parts.append((idx, N * G))
    return _assemble(mesh, parts)


@dataclass(frozen=True)
class BeamGeometricStiffness:
    """``K_G(u)`` of a beam mesh (:func:`geometric_stiffness`) as a picklable callable, the form in
    which an :class:`~core.flexible.fe_model.FEModel` offers its stress stiffening."""

    mesh: BeamMesh
    section: BeamSection

    def __call__(self, u) -> sp.csr_matrix:
        return geometric_stiffness(self.mesh, self.section, u)
