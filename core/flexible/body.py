r"""Flexible bodies in a floating frame of reference with modal reduction.

A flexible body is a reference frame with the core's absolute coordinates (``r`` and ``θ`` in the
plane; ``r`` and Euler parameters in space) plus ``m`` modal coordinates ``q_f``.  A material point
of the reduced finite-element component, undeformed at ``x̄`` in the frame, is at

.. math::

    r_P = r + A\,(\bar x + \Phi_P\, q_f)

(Shabana 2013, *Dynamics of Multibody Systems*, 4th ed., eq. 5.10; Ambrósio's review, eqs. 29–31),
``Φ_P`` the rows of the reduction basis :math:`T` at that point.  The frame is the component's
coordinate frame: its origin and axes are those of the FE model's node coordinates, so the mode set
fixes the reference conditions (cantilever modes, zero at a clamp node: the frame is attached to the
clamp; free–free modes with the rigid-body modes removed: approximately the mean axes).  A basis that
still holds a rigid-body motion is refused at build.

Kinetic energy and inertia invariants
-------------------------------------
The nodal velocities of the component, expressed in the frame, are the rigid field of the frame
velocity ``(V̄, ω̄)`` (``V̄ = Aᵀṙ``) carried by the deformed nodes plus the elastic rates:

.. math::

    w = G_0 \begin{bmatrix}\bar V\\ \bar\omega\end{bmatrix}
        + \sum_k q_k\, G_k\, \bar\omega + T\,\dot q_f
      = W c,\qquad
    c = (\bar V,\ \bar\omega,\ q_1\bar\omega,\ \dots,\ q_m\bar\omega,\ \dot q_f),

with :math:`G_0` the rigid-body modes about the frame origin (unit translations; unit rotations
:math:`e_j \times \bar x_i` with nodal rotations :math:`e_j`) and :math:`G_k` the rotation of mode
``k`` (translations :math:`e_j \times \phi_{k,i}`, rotations :math:`e_j \times \psi_{k,i}`; in the
plane :math:`e_z \times \phi`).  With the FE mass matrix :math:`M_{FE}`,

.. math::

    T = \tfrac12\, w^\mathsf{T} M_{FE}\, w = \tfrac12\, c^\mathsf{T} \mathcal M c,\qquad
    \mathcal M = W^\mathsf{T} M_{FE} W,

so every inertia invariant of Shabana's layout (mass, first moments :math:`\int\rho\bar x`, :math:`\bar S
= \int\rho\Phi`, the rotation–deformation coupling :math:`\int\rho\tilde{\bar u}\Phi`, the inertia
tensor quadratic in :math:`q_f`, :math:`M_{ff}`; Shabana 2013, eqs. 5.47–5.60; notes of the
invariants :math:`I_1 \dots I_9`) is a block of the one constant matrix :math:`\mathcal M`, computed once from
the FE mass matrix (the route SID generators take from a consistent mass matrix; Wallrapp 1994).
With :math:`c = D(q_f)\,\hat\nu`, :math:`\hat\nu = (\bar V, \bar\omega, \dot q_f)`, the mass matrix is
:math:`\hat M = D^\mathsf{T} \mathcal M D`.  A body whose modes are frozen is the rigid body of the same
mass, centre of mass and inertia (a test).

Equations of motion
-------------------
Kirchhoff's equations for the frame in body axes and Lagrange's for the modal coordinates
(Boltzmann–Hamel; Meirovitch 1970, *Methods of Analytical Dynamics*, sec. 4.8), with momenta
:math:`p = \partial T/\partial\hat\nu = D^\mathsf{T}\mathcal M c`:

.. math::

    \dot p_V + \bar\omega\times p_V &= \bar F\\
    \dot p_\omega + \bar\omega\times p_\omega + \bar V\times p_V &= \bar N\\
    \dot p_f - \partial T/\partial q_f &= Q_f - K_{ff} q_f - D_{ff}\dot q_f - K_G(\bar\omega)\, q_f

with :math:`\dot p = \hat M\dot{\hat\nu} + \dot D^\mathsf{T}\mathcal M c + D^\mathsf{T}\mathcal M \dot D\hat\nu`,
:math:`\partial T/\partial q_k = \bar\omega\cdot(\mathcal M c)_{k}` and :math:`\dot{\bar V} = A^\mathsf{T}\ddot r -
\bar\omega\times\bar V`.  In the model's velocity coordinates :math:`(\dot r, \bar\omega, \dot q_f)`
(global translation, body-axes rotation) the mass block is :math:`T_A^\mathsf{T}\hat M T_A`,
:math:`T_A = \mathrm{diag}(A^\mathsf{T}, I, I)`, and the forces are premultiplied by :math:`T_A^\mathsf{T}`; all
quadratic-velocity terms together form the quadratic velocity vector (Shabana 2013, eq. 5.117).
The kinetic energy ½vᵀM(q)v is exact for this T, so the equations conserve energy.

Gravity follows from the potential :math:`V_g = -g^\mathsf{T}(m r + A\,s(q_f))`, :math:`s = \int\rho\bar x +
\bar S q_f`, and the strain energy is :math:`\tfrac12 q_f^\mathsf{T} K_{ff} q_f`.  Modal damping:
:math:`D_{ff} = M_{ff} X\,\mathrm{diag}(2\zeta_k\omega_k) X^\mathsf{T} M_{ff}` with :math:`X` the normal modes of
:math:`(K_{ff}, M_{ff})`.

Inertia of the undeformed body (option)
---------------------------------------
With ``inertia="undeformed"`` the kinetic energy is that of the undeformed body,
:math:`T_0 = \tfrac12\hat\nu^\mathsf{T}\hat M_0\hat\nu`, :math:`\hat M_0 = D(0)^\mathsf{T}\mathcal M D(0)` constant in
the body-axes velocities: the same Kirchhoff equations with :math:`\dot D = 0` and
:math:`\partial T/\partial q_f = 0`.  The deformation then enters the inertia only through the
constraints of the node frames: the terms of :math:`\mathcal M` linear and quadratic in :math:`q_f`
(the change of the inertia tensor with the deformation, the Coriolis coupling :math:`2\bar\omega\times
\Phi\dot q_f`, the centrifugal softening :math:`-\bar\omega^2`-terms on the modes) are dropped, which
is the linearisation of the inertia about the undeformed state (Shabana 2013, sec. 5.8; the
"order 0" of the inertia invariants in the SID of Wallrapp 1994).  It is accurate where the
frame's rotation rates are small against the modal frequencies and the deformation small against
the body (a railway car body: rates of 0.01–0.1 rad/s against 50–100 rad/s), and it is wrong for
fast-spinning bodies (the spin-up beam).  With mean-axis modes (free–free,
``orthonormalized(drop_rigid=True)``) and the frame origin at the centre of mass, :math:`\hat M_0` is
block diagonal — a rigid body plus one oscillator per mode — which the compiled integrators
invert once, as a rigid body (:mod:`core.flexible.compiled`; the full inertia, and a coupled
:math:`\hat M_0`, they take as a mass group whose matrix is rebuilt at every evaluation).  Gravity
keeps its full potential.

Geometric stiffening
--------------------
Optional.  The stress of a unit centrifugal load, :math:`f_{ij} = -M_{FE}\,(B_{ij}\bar x)` with
:math:`\bar\omega\times(\bar\omega\times\bar x) = \sum_{i\le j}\omega_i\omega_j B_{ij}\bar x`, is found
statically with the component held where its modes are held (the zero rows of :math:`T`), or with
inertia relief when it is free; its geometric stiffness :math:`K_{G,ij} = T^\mathsf{T} K_G(u_{ij}) T` is
scaled at run time with the current :math:`\omega_i\omega_j` (Wallrapp & Schwertassek 1991, Int. J.
Numer. Meth. Eng. 32:1833–1850, the centrifugal part).  Only the centrifugal load cases are
included (not the frame's translational or angular acceleration), which is the effect that keeps a
spinning beam's bending stiffness above its centrifugal softening (Kane, Ryan & Banerjee 1987).
With it the model is not conservative in :meth:`energy`.

References
----------
A. A. Shabana, *Dynamics of Multibody Systems*, 4th ed., Cambridge University Press, 2013, ch. 5.
O. Wallrapp, Mech. Struct. Mach. 22(3):283–304, 1994 (standard input data).
O. Wallrapp, R. Schwertassek, Int. J. Numer. Meth. Eng. 32:1833–1850, 1991.
T. R. Kane, R. R. Ryan, A. K. Banerjee, J. Guidance 10(2):139–151, 1987.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from .. import frames
from ..errors import ModelError
from ..joints import UserConstraint
from .fe_model import FEModel
from .reduction import RIGID_TOL, ModalComponent, rigid_body_modes

Array = NDArray[np.float64]

__all__ = ["FlexibleBodyData", "FlexibleNodes", "flexible_body_data"]


def _cross(a: Array, b: Array) -> Array:
    """a × b; planar vectors give the scalar z component as a length-1 array."""
    if a.shape[-1] == 2:
        return np.atleast_1d(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])
    return np.cross(a, b)


def _w_cross(w: Array, v: Array) -> Array:
    """ω × v with ω (n_rot,) and v (..., d): planar ``ω e_z × v``."""
    if v.shape[-1] == 2:
        out = np.empty_like(v, dtype=float)
        out[..., 0] = -w[0] * v[..., 1]
        out[..., 1] = w[0] * v[..., 0]
        return out
    return np.cross(w, v)


@dataclass(frozen=True)
class FlexibleBodyData:
    """Everything a flexible body needs at run time, computed once (see the module docstring).

    Attributes
    ----------
    name : str
    dim, n_rot, n_modes : int
    gram : (n_c, n_c) ndarray
        :math:`\\mathcal M = W^T M_{FE} W`, ``n_c = dim + n_rot + n_modes (n_rot + 1)``.
    mass : float
        [kg]
    first_moment : (dim,) ndarray
        :math:`\\int\\rho\\bar x\\,dV` [kg m].
    S : (dim, n_modes) ndarray
        :math:`\\int\\rho\\Phi\\,dV` [kg m per unit modal coordinate].
    K, D : (n_modes, n_modes) ndarray
        Modal stiffness and damping.
    KG : (n_products, n_modes, n_modes) ndarray or None
        Geometric stiffness per unit :math:`\\omega_i\\omega_j` (planar: one product ω²; spatial:
        ω_x², ω_xω_y, ω_xω_z, ω_y², ω_yω_z, ω_z²), or None without centrifugal stiffening.
    nodes : (N, dim) ndarray
        Node positions in the frame [m].
    dofs_per_node : int
    T : (n_dofs, n_modes) ndarray
        The reduction basis (node deformations and stresses are recovered from it).
    frequencies : (n_modes,) ndarray
        [Hz] of the body held in its frame (the modes of (K, M_ff)).
    labels : tuple of str
        What each modal coordinate is.
    source : str
    beam : tuple or None
        ``(mesh, section, theory)`` of a beam component (section forces), else None.
    inertia : str
        ``"full"`` (the exact kinetic energy of the deformed body) or ``"undeformed"`` (that of the
        undeformed body; module docstring).
    stress_modes : (N, n_components, n_modes) ndarray or None
        Nodal stresses [Pa per unit modal coordinate] of each mode, for plane and solid components
        (:class:`core.flexible.continuum.ContinuumStresses`), else None.
    stress_components : tuple of str
        The names of the stress components (``σ_xx`` …), empty without stress modes.
    """

    name: str
    dim: int
    n_rot: int
    n_modes: int
    gram: Array
    mass: float
    first_moment: Array
    S: Array
    K: Array
    D: Array
    KG: Array | None
    nodes: Array
    dofs_per_node: int
    T: Array
    frequencies: Array
    labels: tuple
    source: str
    beam: tuple | None = None
    inertia: str = "full"
    stress_modes: Array | None = None
    stress_components: tuple = ()

    # --- node kinematics ------------------------------------------------------------------
    def translation_rows(self, node: int) -> Array:
        """Basis rows of a node's translations, (dim, n_modes)."""
        return self.T[node * self.dofs_per_node + np.arange(self.dim)]

    def rotation_rows(self, node: int) -> Array:
        """Basis rows of a node's rotations, (n_rot, n_modes); zero for a component whose nodes have
        no rotational degrees of freedom (plane-stress and solid elements)."""
        p, d = self.dofs_per_node, self.dim
        if (d, p) in ((2, 3), (3, 6)):
            return self.T[node * p + d + np.arange(self.n_rot)]
        return np.zeros((self.n_rot, self.n_modes))

    def node_displacements(self, qf: Array) -> Array:
        """Elastic displacements (and rotations) of every node in the frame, (N, dofs_per_node)."""
        return (self.T @ np.asarray(qf, float)).reshape(-1, self.dofs_per_node)

    def section_forces(self, qf: Array) -> Array:
        """Section forces at both ends of every beam element for the modal coordinates ``qf``
        (:func:`core.flexible.beam.section_forces`: (n_el, 2, 3) in the plane, (n_el, 2, 6) in
        space, N, V, M [N, N m]); :class:`ModelError` for a component that is not made of beams."""
        from .beam import section_forces

        return self._beam_result(section_forces, "section forces", qf)

    def fibre_stresses(self, qf: Array) -> Array:
        """Largest and smallest normal stress over the section at both ends of every beam element
        for the modal coordinates ``qf`` (:func:`core.flexible.beam.fibre_stresses`: (n_el, 2, 2),
        σ_max and σ_min [Pa]); needs a beam component whose section has an outline."""
        from .beam import fibre_stresses

        return self._beam_result(fibre_stresses, "fibre stresses", qf)

    def nodal_stresses(self, qf: Array) -> Array:
        """Stresses at the nodes [Pa] for the modal coordinates ``qf``, shape (N, n_components), the
        components named by :attr:`stress_components`: the modal stresses summed,
        σ = Σ_k σ_k q_k (plane and solid components; beams have :meth:`fibre_stresses`)."""
        if self.stress_modes is None:
            other = "use fibre_stresses or section_forces" if self.beam is not None else "imported matrices carry none"
            raise ModelError(f"flexible body {self.name!r}: nodal stresses need a plane or solid component; "
                             f"{self.source or 'this component'} is not one ({other})")
        return self.stress_modes @ np.asarray(qf, float)

    def von_mises_stresses(self, qf: Array) -> Array:
        """Von Mises equivalent stress [Pa] at every node for the modal coordinates ``qf``, shape (N,)
        (:func:`core.flexible.continuum.von_mises` of :meth:`nodal_stresses`)."""
        from .continuum import von_mises

        return von_mises(self.nodal_stresses(qf))

    def _beam_result(self, fn, what: str, qf: Array) -> Array:
        """``fn(mesh, section, u, theory)`` of a beam component at the modal coordinates ``qf``."""
        if self.beam is None:
            raise ModelError(f"flexible body {self.name!r}: {what} need a beam component; "
                             f"{self.source or 'this component'} is not one (use node_displacements)")
        mesh, section, theory = self.beam
        return fn(mesh, section, self.T @ np.asarray(qf, float), theory)

    # --- dynamics ---------------------------------------------------------------------------
    @cached_property
    def _D_template(self) -> tuple[Array, Array, Array]:
        """:math:`D(0)` and the positions of the entries that hold the modal coordinates."""
        d, r, m = self.dim, self.n_rot, self.n_modes
        a = d + r
        D = np.zeros((a + m * r + m, a + m))
        D[:a, :a] = np.eye(a)
        D[a + m * r:, a:] = np.eye(m)
        return D, a + np.arange(m * r), d + np.tile(np.arange(r), m)

    def _D(self, qf: Array) -> Array:
        D0, rows, cols = self._D_template
        D = D0.copy()
        D[rows, cols] = np.repeat(qf, self.n_rot)
        return D

    def mass_block(self, A: Array, qf: Array) -> Array:
        """The mass block of :meth:`mass_and_forces` alone (what the mass matrix needs, without the
        forces)."""
        if self.inertia == "undeformed":
            Mb = self.undeformed_mass().copy()
        else:
            D = self._D(qf)
            Mb = D.T @ (self.gram @ D)
        d = self.dim
        Mb[:d, :] = A @ Mb[:d, :]
        Mb[:, :d] = Mb[:, :d] @ A.T
        return 0.5 * (Mb + Mb.T)

    def mass_and_forces(self, A: Array, rdot: Array, w: Array, qf: Array, qfd: Array, g: Array):
        """Mass block and generalized forces in the model's velocity coordinates
        ``(ṙ, ω̄, q̇_f)``: ``(M_b (n, n), Q_b (n,))``, ``n = dim + n_rot + n_modes``.

        ``Q_b`` holds the quadratic-velocity, elastic, damping, geometric-stiffening and gravity
        forces (module docstring)."""
        d, r, m = self.dim, self.n_rot, self.n_modes
        a = d + r
        V = A.T @ rdot
        if self.inertia == "undeformed":
            return self._undeformed_mass_and_forces(A, V, w, qf, qfd, g)
        c = np.concatenate([V, w, (qf[:, None] * w[None, :]).ravel(), qfd])
        D = self._D(qf)
        G = self.gram
        y = G @ c
        MD = G @ D
        Mh = D.T @ MD
        p = D.T @ y
        yb = y[a:a + m * r].reshape(m, r)
        h = np.zeros(a + m)
        h[d:a] = qfd @ yb  # Ḋᵀ M c
        h += MD[a:a + m * r].T @ (qfd[:, None] * w[None, :]).ravel()  # Dᵀ M Ḋ ν̂: Ḋ ν̂ fills the q_f ω rows
        h -= Mh[:, :d] @ _w_cross(w, V)  # M̂ (−ω̄ × V̄) from V̄̇ = Aᵀr̈ − ω̄ × V̄
        h[:d] += _w_cross(w, p[:d])
        if d == 3:
            h[d:a] += np.cross(w, p[d:a])
        h[d:a] += _cross(V, p[:d])
        h[a:] -= yb @ w
        gb = A.T @ g
        F = np.empty(a + m)
        F[:d] = self.mass * gb
        F[d:a] = _cross(self.first_moment + self.S @ qf, gb)
        F[a:] = self.S.T @ gb - self.K @ qf - self.D @ qfd
        if self.KG is not None:
            F[a:] -= np.tensordot(_omega_products(w), self.KG, 1) @ qf
        rhs = F - h
        Mb = Mh
        Mb[:d, :] = A @ Mb[:d, :]
        Mb[:, :d] = Mb[:, :d] @ A.T
        rhs[:d] = A @ rhs[:d]
        return 0.5 * (Mb + Mb.T), rhs  # symmetric to the last bit (the products round differently)

    def undeformed_mass(self) -> Array:
        """:math:`\\hat M_0 = D(0)^T \\mathcal M D(0)` in the body-axes velocities ``(V̄, ω̄, q̇_f)``
        (a copy of the cached matrix)."""
        return self._undeformed_mass.copy()

    @cached_property
    def _undeformed_mass(self) -> Array:
        D0 = self._D_template[0]
        return D0.T @ self.gram @ D0

    def _undeformed_mass_and_forces(self, A, V, w, qf, qfd, g):
        """:meth:`mass_and_forces` with the kinetic energy of the undeformed body (``inertia="undeformed"``):
        Kirchhoff's equations with the constant :math:`\\hat M_0` (module docstring)."""
        d, r = self.dim, self.n_rot
        a = d + r
        Mh = self._undeformed_mass
        p = Mh @ np.concatenate([V, w, qfd])
        h = -Mh[:, :d] @ _w_cross(w, V)
        h[:d] += _w_cross(w, p[:d])
        if d == 3:
            h[d:a] += np.cross(w, p[d:a])
        h[d:a] += _cross(V, p[:d])
        gb = A.T @ g
        F = np.empty(a + self.n_modes)
        F[:d] = self.mass * gb
        F[d:a] = _cross(self.first_moment + self.S @ qf, gb)
        F[a:] = self.S.T @ gb - self.K @ qf - self.D @ qfd
        rhs = F - h
        Mb = Mh.copy()
        Mb[:d, :] = A @ Mb[:d, :]
        Mb[:, :d] = Mb[:, :d] @ A.T
        rhs[:d] = A @ rhs[:d]
        return 0.5 * (Mb + Mb.T), rhs  # symmetric to the last bit (the products round differently)

    def potential(self, r: Array, A: Array, qf: Array, g: Array) -> float:
        """Gravitational plus strain energy [J]: ``−gᵀ(m r + A s(q_f)) + ½ q_fᵀ K q_f``."""
        s = self.first_moment + self.S @ qf
        return float(-g @ (self.mass * r + A @ s)) + self.strain_energy(qf)

    def strain_energy(self, qf: Array) -> float:
        """½ q_fᵀ K q_f [J]."""
        return float(0.5 * qf @ (self.K @ qf))

    @property
    def conservative(self) -> bool:
        return self.KG is None and not np.any(self.D)


def _omega_products(w: Array) -> Array:
    if w.shape[0] == 1:
        return np.array([w[0] * w[0]])
    x, y, z = w
    return np.array([x * x, x * y, x * z, y * y, y * z, z * z])


def _products_B(dim: int) -> list[Array]:
    """``B_ij`` of ``ω × (ω × x) = Σ ω_i ω_j B_ij x`` in the order of :func:`_omega_products`."""
    if dim == 2:
        return [-np.eye(2)]
    out = []
    for i in range(3):
        for j in range(i, 3):
            ei, ej = np.eye(3)[i], np.eye(3)[j]
            if i == j:
                out.append(np.outer(ei, ei) - np.eye(3))
            else:
                out.append(np.outer(ei, ej) + np.outer(ej, ei))
    return out


def _translations(nodes: Array, p: int) -> tuple[Array, Array]:
    """Indices of the translational and rotational dofs, (N, d) and (N, r) (the latter may be (N, 0))."""
    N, d = nodes.shape
    t = np.arange(N)[:, None] * p + np.arange(d)[None, :]
    r = 1 if d == 2 else 3
    if (d, p) in ((2, 3), (3, 6)):
        rot = np.arange(N)[:, None] * p + d + np.arange(r)[None, :]
    else:
        rot = np.zeros((N, 0), np.int64)
    return t, rot


def _rotation_field(nodes: Array, p: int, U: Array, Psi: Array | None, j: int) -> Array:
    """Nodal vector of the field ``e_j × u`` (translations U (N, d), rotations Psi (N, r) or None)."""
    N, d = nodes.shape
    out = np.zeros(N * p)
    t, rot = _translations(nodes, p)
    if d == 2:
        out[t[:, 0]] = -U[:, 1]
        out[t[:, 1]] = U[:, 0]
    else:
        e = np.eye(3)[j]
        out[t.ravel()] = np.cross(e, U).ravel()
        if rot.shape[1] and Psi is not None:
            out[rot.ravel()] = np.cross(e, Psi).ravel()
    return out


#: the kinds of geometric stiffening (module docstring); True means "centrifugal"
STIFFENING = ("centrifugal",)
#: Kinetic energies of a flexible body (module docstring)
INERTIA = ("full", "undeformed")


def _stiffening(name, value) -> bool:
    """Whether ``geometric_stiffening`` asks for the centrifugal geometric stiffness."""
    if value is None or value is False:
        return False
    if value is True or value == "centrifugal":
        return True
    from ..inputs import closest

    hint = closest(value, STIFFENING) if isinstance(value, str) else None
    raise ModelError(f"flexible body {name!r}: geometric_stiffening={value!r}; give False, True or 'centrifugal'"
                     + (f" (did you mean {hint!r}?)" if hint else ""))


def flexible_body_data(name: str, fe: FEModel, modes: ModalComponent, damping_ratio=0.0,
                       geometric_stiffening=False, dim: int | None = None, inertia: str = "full") -> FlexibleBodyData:
    """Check a component and compute its run-time data (module docstring).

    Raises
    ------
    ModelError
        Naming the body: a component of another dimension or layout, a basis of another order than
        the FE model, a basis that holds rigid-body motions, a reduced mass that is not positive
        definite, a damping ratio out of range, geometric stiffening asked of a component without
        a geometric stiffness.
    """
    if inertia not in INERTIA:
        from ..inputs import closest

        hint = closest(inertia, INERTIA) if isinstance(inertia, str) else None
        raise ModelError(f"flexible body {name!r}: inertia={inertia!r}; give one of {', '.join(map(repr, INERTIA))}"
                         + (f" (did you mean {hint!r}?)" if hint else ""))
    if not isinstance(fe, FEModel):
        raise ModelError(f"flexible body {name!r}: give an FEModel (core.flexible.FEModel), got {type(fe).__name__}")
    if not isinstance(modes, ModalComponent):
        raise ModelError(f"flexible body {name!r}: give the reduced component as a ModalComponent "
                         f"(normal_mode_component, craig_bampton or free_interface), got {type(modes).__name__}")
    nodes = np.asarray(fe.nodes, float)
    N, d = nodes.shape
    if dim is not None and d != dim:
        raise ModelError(f"flexible body {name!r}: the FE model's nodes are {d}-D, the model is {dim}-D")
    p = fe.dofs_per_node
    if (d, p) not in ((2, 2), (2, 3), (3, 3), (3, 6)):
        raise ModelError(f"flexible body {name!r}: {p} degrees of freedom per node in {d}-D; a floating frame "
                         "needs 2 or 3 (planar: translations, with θ_z) or 3 or 6 (spatial: translations, with rotations)")
    T = np.asarray(modes.T, float)
    if T.shape[0] != fe.n_dofs:
        raise ModelError(f"flexible body {name!r}: the mode basis has {T.shape[0]} rows, the FE model "
                         f"{fe.n_dofs} degrees of freedom (reduce this FE model)")
    m = T.shape[1]
    if m == 0:
        raise ModelError(f"flexible body {name!r}: the mode basis is empty; use a rigid body")
    Mfe = sp.csr_matrix(fe.M)
    Kr = T.T @ (sp.csr_matrix(fe.K) @ T)
    Mr = T.T @ (Mfe @ T)
    Kr, Mr = 0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T)
    try:
        np.linalg.cholesky(Mr)
    except np.linalg.LinAlgError:
        raise ModelError(f"flexible body {name!r}: the reduced mass matrix is not positive definite (dependent or "
                         "massless mode shapes)") from None
    lam, X = sla.eigh(Kr, Mr)
    n_rigid = int(np.sum(lam < RIGID_TOL * max(float(lam.max()), 1e-300)))
    if n_rigid:
        raise ModelError(f"flexible body {name!r}: its mode basis holds {n_rigid} rigid-body mode(s) (zero frequency); "
                         "the floating frame carries the rigid motion itself: use modes.orthonormalized(drop_rigid=True), "
                         "or modes of the component held at the node the frame is attached to")
    r = 1 if d == 2 else 3
    # --- W = [G0, G_1 .. G_m, T] -------------------------------------------------------------
    R = np.zeros((N * p, d + r))
    t_idx, rot_idx = _translations(nodes, p)
    for k in range(d):
        R[t_idx[:, k], k] = 1.0
    for j in range(r):
        R[:, d + j] = _rotation_field(nodes, p, nodes, None, j)
        if rot_idx.shape[1]:
            R[rot_idx[:, j], d + j] = 1.0
    cols = [R]
    for k in range(m):
        U = T[t_idx, k]
        Psi = T[rot_idx, k] if rot_idx.shape[1] else None
        cols.append(np.column_stack([_rotation_field(nodes, p, U, Psi, j) for j in range(r)]))
    cols.append(T)
    W = np.hstack(cols)
    gram = W.T @ (Mfe @ W)
    gram = 0.5 * (gram + gram.T)
    x0 = np.zeros(N * p)
    x0[t_idx.ravel()] = nodes.ravel()
    Pt = R[:, :d]
    MPt = Mfe @ Pt
    mass = float(np.trace(Pt.T @ MPt) / d)
    first = MPt.T @ x0
    S = MPt.T @ T
    # --- modal damping ---------------------------------------------------------------------------
    zeta = np.broadcast_to(np.asarray(_damping(name, damping_ratio, m), float), (m,))
    omega = np.sqrt(np.clip(lam, 0.0, None))
    Dm = Mr @ X @ np.diag(2.0 * zeta * omega) @ X.T @ Mr
    # --- geometric stiffening -------------------------------------------------------------------------
    KG = None
    centrifugal = _stiffening(name, geometric_stiffening)
    if centrifugal and inertia == "undeformed":
        raise ModelError(f"flexible body {name!r}: geometric stiffening is for fast-spinning bodies, whose inertia "
                         "changes with the deformation; it cannot be combined with inertia='undeformed'")
    if centrifugal and fe.geometric_stiffness is None:
        raise ModelError(f"flexible body {name!r}: geometric stiffening needs the component's geometric stiffness; "
                         f"{fe.source or 'this FE model'} has none (beam components have it; imported matrices do not)")
    if centrifugal:
        KG = np.array([_unit_geometric_stiffness(name, fe, Mfe, T, B, nodes, p, t_idx) for B in _products_B(d)])
    stress_modes, components = None, ()
    if fe.stress_recovery is not None:
        stress_modes = np.asarray(fe.stress_recovery(T), float)
        components = tuple(fe.stress_recovery.components)
    return FlexibleBodyData(name, d, r, m, gram, mass, first, S, Kr, 0.5 * (Dm + Dm.T), KG, nodes, p, T,
                            omega / (2.0 * np.pi), tuple(modes.labels), fe.source, fe.beam, inertia,
                            stress_modes, components)


def _damping(name, value, m):
    from ..inputs import parse_quantity

    z = parse_quantity(value, "1", where=f"flexible body {name!r} damping_ratio")
    z = np.atleast_1d(np.asarray(z, float))
    if z.size not in (1, m):
        raise ModelError(f"flexible body {name!r}: damping_ratio has {z.size} values for {m} modes (give one, or one per mode)")
    bad = np.flatnonzero(~((z >= 0.0) & (z < 0.5)))
    if bad.size:
        v = float(z[bad[0]])
        hint = f" (a ratio: {v:g} % is {v / 100:g}; write '{v:g} %' for percent)" if v >= 0.5 else ""
        raise ModelError(f"flexible body {name!r}: damping ratio {v:g} is outside 0 <= zeta < 0.5{hint}")
    return z if z.size == m else z[0]


def _unit_geometric_stiffness(name, fe, Mfe, T, B, nodes, p, t_idx):
    """``Tᵀ K_G(u) T`` for the static response u to the unit centrifugal load of ``B``."""
    n = fe.n_dofs
    xB = np.zeros(n)
    xB[t_idx.ravel()] = (nodes @ B.T).ravel()
    f = -(Mfe @ xB)
    held = np.flatnonzero(~np.any(T != 0.0, axis=1))
    K = sp.csr_matrix(fe.K)
    if held.size:
        free = np.setdiff1d(np.arange(n), held)
        try:  # splu raises on an exactly singular matrix (spsolve would warn and return NaN)
            uf = spla.splu(K[free][:, free].tocsc()).solve(f[free])
        except RuntimeError:
            uf = np.full(free.size, np.nan)
        u = np.zeros(n)
        u[free] = uf
        if not np.all(np.isfinite(u)):
            raise ModelError(f"flexible body {name!r}: the component held where its modes are zero is not supported "
                             "against every rigid motion; the centrifugal stress for geometric stiffening is undefined")
    else:  # free component: inertia relief
        Rm = rigid_body_modes(nodes, p, Mfe)
        MR = Mfe @ Rm
        fb = f - MR @ (Rm.T @ f)
        try:
            u = spla.splu((K + sp.csr_matrix(MR @ MR.T)).tocsc()).solve(fb)
        except RuntimeError:
            raise ModelError(f"flexible body {name!r}: the free component's stiffness with inertia relief is singular "
                             "(a mechanism or disconnected parts); the centrifugal stress for geometric stiffening "
                             "is undefined") from None
        u = u - Rm @ (MR.T @ u)
    KG = fe.geometric_stiffness(u)
    out = T.T @ (sp.csr_matrix(KG) @ T)
    return 0.5 * (out + out.T)


class FlexibleNodes(UserConstraint):
    r"""Node frames attached to a flexible body: one massless body per attachment node, held at the
    node's deformed position and orientation.

    For node frame ``N`` on node ``i`` (frame axes those of the body frame when undeformed):

    .. math::

        \Phi_{pos} = r_N - r - A(\bar x_i + \Phi_i q_f),\qquad
        \Phi_{rot} = \begin{cases}\theta_N - \theta - \psi_i q_f & \text{planar}\\
        \operatorname{ax}(C) - \Psi_i q_f,\ C = A^\mathsf{T} A_N & \text{spatial}\end{cases}

    with :math:`\operatorname{ax}(C) = \tfrac12(C_{32}-C_{23}, C_{13}-C_{31}, C_{21}-C_{12})` (the sine
    vector of the relative rotation, equal to the small rotation :math:`\Psi_i q_f` to first order).
    Jacobians, with body-axes angular velocities: :math:`\partial\,\operatorname{ax}(C)/\partial\theta =
    -\tfrac12(\operatorname{tr}C\,I - C)`, :math:`\partial\,\operatorname{ax}(C)/\partial\theta_N =
    \tfrac12(\operatorname{tr}C\,I - C^\mathsf{T})`; :math:`\gamma_{pos} = A(\bar\omega\times(\bar\omega\times
    \bar s) + 2\bar\omega\times\Phi_i\dot q_f)`, :math:`\bar s = \bar x_i + \Phi_i q_f`;
    :math:`\gamma_{rot} = -\operatorname{ax}(\tilde\omega^2 C - 2\tilde\omega C\tilde\omega_N + C\tilde\omega_N^2)`
    (spatial; 0 in the plane).  Every joint, force element and driver then attaches to the node frame
    unchanged.
    """

    def __init__(self, data: FlexibleBodyData, modal_names: list[str]):
        self.data = data
        self.name = f"{data.name}.nodes"
        self.body = data.name
        self.node_bodies: list[str] = []
        self.nodes: list[int] = []
        self.coordinates = tuple(modal_names)
        self.rows = 0

    def add(self, node_body: str, node: int) -> None:
        self.node_bodies.append(node_body)
        self.nodes.append(int(node))
        d = self.data.dim
        self.rows = len(self.nodes) * (d + self.data.n_rot)
        self.bodies = tuple([self.body] + self.node_bodies)
        self._X = self.data.nodes[self.nodes]
        self._Pt = np.array([self.data.translation_rows(i) for i in self.nodes])
        self._Pr = np.array([self.data.rotation_rows(i) for i in self.nodes])

    def compiled(self, layout):
        """Compiled form (:func:`core.flexible.compiled.compile_flexible_nodes`)."""
        from .compiled import compile_flexible_nodes

        return compile_flexible_nodes(self, layout)

    # --- helpers -----------------------------------------------------------------------------
    def _split(self, q):
        sp_ = self.space
        k = len(self.nodes)
        qq = q[self.q_index]
        ref = qq[:sp_.n_q]
        nod = qq[sp_.n_q:sp_.n_q * (k + 1)].reshape(k, sp_.n_q)
        return ref, nod, qq[sp_.n_q * (k + 1):]

    def _vsplit(self, v):
        sp_ = self.space
        k = len(self.nodes)
        vv = v[self.v_index]
        return vv[:sp_.n_v], vv[sp_.n_v:sp_.n_v * (k + 1)].reshape(k, sp_.n_v), vv[sp_.n_v * (k + 1):]

    def _frames(self, ref, nod):
        """The frame's rotation matrix and the nodes' (these only in space: the planar rows use the
        node angles directly)."""
        sp_ = self.space
        A = sp_.rotation(ref[None])[0]
        return A, (sp_.rotation(nod) if self.data.dim == 3 else None)

    def phi(self, t, q):
        d = self.data.dim
        ref, nod, qf = self._split(q)
        A, AN = self._frames(ref, nod)
        s = self._X + self._Pt @ qf
        pos = nod[:, :d] - ref[:d] - s @ A.T
        if d == 2:
            rot = (nod[:, 2] - ref[2] - self._Pr[:, 0, :] @ qf)[:, None]
        else:
            C = np.einsum("ji,njk->nik", A, AN)
            rot = _ax(C) - self._Pr @ qf
        return np.hstack([pos, rot]).ravel()

    def jacobian(self, t, q):
        d, r, m = self.data.dim, self.data.n_rot, self.data.n_modes
        nvb = self.space.n_v
        k = len(self.nodes)
        ref, nod, qf = self._split(q)
        A, AN = self._frames(ref, nod)
        s = self._X + self._Pt @ qf
        J = np.zeros((k, d + r, nvb * (k + 1) + m))
        idx = np.arange(k)
        for a in range(d):
            J[idx, a, nvb * (idx + 1) + a] = 1.0
            J[:, a, a] = -1.0
        J[:, :d, nvb * (k + 1):] = -np.einsum("ij,njm->nim", A, self._Pt)
        J[:, d:, nvb * (k + 1):] = -self._Pr
        if d == 2:
            J[:, :d, 2] = -(s @ (A @ frames.ROT90).T)
            J[idx, 2, nvb * (idx + 1) + 2] = 1.0
            J[:, 2, 2] = -1.0
        else:
            J[:, :3, 3:6] = np.einsum("ij,njk->nik", A, frames.skew(s))
            C = np.einsum("ji,njk->nik", A, AN)
            tr = np.trace(C, axis1=1, axis2=2)[:, None, None] * np.eye(3)
            J[:, 3:, 3:6] = -0.5 * (tr - C)
            cols = nvb * (idx + 1)[:, None, None] + 3 + np.arange(3)[None, None, :]  # each node's ω̄ columns
            J[idx[:, None, None], 3 + np.arange(3)[None, :, None], cols] = 0.5 * (tr - np.swapaxes(C, 1, 2))
        return J.reshape(self.rows, -1)

    def gamma(self, t, q, v):
        d = self.data.dim
        ref, nod, qf = self._split(q)
        vr, vn, qfd = self._vsplit(v)
        A, AN = self._frames(ref, nod)
        s = self._X + self._Pt @ qf
        sd = self._Pt @ qfd
        w = vr[d:]
        acc = _w_cross(w, _w_cross(w, s)) + 2.0 * _w_cross(w, sd)
        pos = acc @ A.T
        if d == 2:
            rot = np.zeros((len(self.nodes), 1))
        else:
            C = np.einsum("ji,njk->nik", A, AN)
            W = frames.skew(w)
            WN = frames.skew(vn[:, 3:])
            H = W @ W @ C - 2.0 * np.einsum("ij,njk,nkl->nil", W, C, WN) + np.einsum("nij,njk,nkl->nil", C, WN, WN)
            rot = -_ax(H)
        return np.hstack([pos, rot]).ravel()


def _ax(C: Array) -> Array:
    """Axial vector of the skew part of (n, 3, 3) matrices."""
    return 0.5 * np.stack([C[:, 2, 1] - C[:, 1, 2], C[:, 0, 2] - C[:, 2, 0], C[:, 1, 0] - C[:, 0, 1]], -1)
