r"""Modal reduction of a linear finite-element component.

For :math:`M \ddot u + K u = f` of order :math:`n`, a reduction :math:`u = T q` with few columns
gives :math:`M_r = T^\mathsf{T} M T`, :math:`K_r = T^\mathsf{T} K T`.

Normal modes
------------
:math:`K \phi = \omega^2 M \phi` on the free degrees of freedom (the fixed ones removed), the
lowest ``n_modes`` pairs by scipy's ``eigsh`` in shift-invert mode about a small negative shift
(so that a free component's rigid-body modes, :math:`\omega = 0`, are found and the shifted
matrix :math:`K + |\sigma| M` stays positive definite); dense ``eigh`` for small orders.  Shapes
are mass-normalised, :math:`\phi^\mathsf{T} M \phi = I`.

Craig–Bampton
-------------
Craig & Bampton (1968), AIAA J. 6(7):1313–1319.  With the interface (boundary) degrees of
freedom :math:`b` and the interior :math:`i`:

.. math::

    \begin{bmatrix} u_b \\ u_i \end{bmatrix} =
    \begin{bmatrix} I & 0 \\ \Psi_{ib} & \Phi_i \end{bmatrix}
    \begin{bmatrix} u_b \\ \eta \end{bmatrix},\qquad
    \Psi_{ib} = -K_{ii}^{-1} K_{ib},

:math:`\Psi` the static constraint modes (unit displacement of one interface degree of freedom,
the others held, the interior in static equilibrium) and :math:`\Phi_i` the lowest fixed-interface
normal modes (:math:`K_{ii}\phi = \omega^2 M_{ii}\phi`).  A component whose interface is not
grounded keeps its rigid-body motion in :math:`\Psi`: the reduced :math:`K_r` is then singular,
and :meth:`ModalComponent.orthonormalized` reports (and can remove) those modes, as a floating
frame of reference needs.

Free-interface modes with static correction
-------------------------------------------
For a free (floating) component, the lowest elastic normal modes :math:`\Phi_k` plus one residual
attachment mode per attachment degree of freedom (MacNeal 1971; Rubin 1975; Craig & Kurdila 2006,
sec. 14.6).  The rigid-body modes :math:`\Phi_r` are made from the node coordinates (unit
translations and small rotations about the origin, rotational degrees of freedom included) and
mass-normalised; :math:`K\Phi_r = 0`.  The elastic flexibility with inertia relief is

.. math::

    G_e = P\,(K + M\Phi_r\Phi_r^\mathsf{T}M)^{-1} P^\mathsf{T},\qquad
    P = I - \Phi_r\Phi_r^\mathsf{T} M,

which is :math:`\sum_e \phi_e\phi_e^\mathsf{T}/\omega_e^2` over all elastic modes (expand the
shifted matrix in the M-orthonormal modes); the residual attachment modes are the columns
:math:`G_e - \Phi_k\Lambda_k^{-1}\Phi_k^\mathsf{T}` at the attachment degrees of freedom.  The
basis :math:`[\Phi_r, \Phi_k, G_{res}]` reproduces the kept frequencies and the full model's
static deflection, with inertia relief, under loads at the attachment degrees of freedom.

References: Craig, R. R. and Bampton, M. C. C. (1968); Craig & Kurdila (2006), *Fundamentals of
Structural Dynamics*, 2nd ed., ch. 14; MacNeal, R. H. (1971), Computers & Structures 1:581–601;
Rubin, S. (1975), AIAA J. 13(8):995–1006.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import InputError, ModelError

__all__ = ["ModalComponent", "craig_bampton", "free_interface", "normal_modes", "rigid_body_modes", "DENSE_EIG_MAX"]

#: orders up to which the eigenproblems are solved dense (scipy.linalg.eigh)
DENSE_EIG_MAX = 300
#: a mode whose squared circular frequency is below this fraction of the largest reduced one
#: counts as a rigid-body mode
RIGID_TOL = 1e-9


def _check_pair(M, K):
    M = sp.csr_matrix(M)
    K = sp.csr_matrix(K)
    if M.shape != K.shape or M.shape[0] != M.shape[1]:
        raise InputError(f"mass {M.shape} and stiffness {K.shape} must be square and of one order")
    for name, A in (("mass", M), ("stiffness", K)):
        if not np.all(np.isfinite(A.data)):
            C = A.tocoo()
            k = int(np.argmax(~np.isfinite(C.data)))
            raise InputError(f"the {name} matrix has a non-finite entry {C.data[k]!r} at "
                             f"({int(C.row[k])}, {int(C.col[k])})")
        asym = abs(A - A.T).max() if A.nnz else 0.0
        if asym > 1e-9 * max(abs(A).max(), 1e-300):
            raise InputError(f"the {name} matrix is not symmetric (largest |A - Aᵀ| = {asym:.3g})")
    return M, K


def _dof_list(dofs, n, what) -> np.ndarray:
    d = np.unique(np.asarray(list(dofs) if not isinstance(dofs, np.ndarray) else dofs, dtype=np.int64).ravel())
    bad = d[(d < 0) | (d >= n)]
    if bad.size:
        raise InputError(f"{what}: degree of freedom {int(bad[0])} is outside 0..{n - 1}")
    return d


def _lowest_modes(K, M, n_modes: int, what: str):
    """The lowest ``n_modes`` eigenpairs of (K, M): (ω² ascending, mass-normalised shapes)."""
    n = K.shape[0]
    if n_modes > n:
        raise InputError(f"{what}: {n_modes} modes asked of a problem of order {n}")
    if n <= DENSE_EIG_MAX or n_modes >= n - 1:
        lam, X = sla.eigh(K.toarray(), M.toarray(), subset_by_index=(0, n_modes - 1))
    else:
        shift = -1e-6 * float(K.diagonal().mean() / M.diagonal().mean())
        try:
            lam, X = spla.eigsh(K.tocsc(), k=n_modes, M=M.tocsc(), sigma=shift, which="LM")
        except (spla.ArpackNoConvergence, spla.ArpackError, RuntimeError) as exc:
            from ..errors import NumericalFailure

            raise NumericalFailure(f"{what}: the sparse eigensolver found no {n_modes} modes of the order-{n} "
                                   f"problem ({exc})") from None
        order = np.argsort(lam)
        lam, X = lam[order], X[:, order]
        X = X / np.sqrt(np.einsum("ij,ij->j", X, M @ X))[None, :]
    return lam, X


def normal_modes(M, K, n_modes: int, fixed_dofs=()):
    """The lowest ``n_modes`` normal modes with the degrees of freedom ``fixed_dofs`` held.

    Returns
    -------
    frequencies : (n_modes,) ndarray
        Natural frequencies [Hz] (0 for rigid-body modes; round-off below is clipped).
    shapes : (n, n_modes) ndarray
        Mass-normalised mode shapes, zero at the fixed degrees of freedom.
    """
    M, K = _check_pair(M, K)
    n = M.shape[0]
    if not (isinstance(n_modes, (int, np.integer)) and n_modes >= 1):
        raise InputError(f"n_modes = {n_modes!r} must be a positive integer")
    fixed = _dof_list(fixed_dofs, n, "normal_modes fixed_dofs")
    free = np.setdiff1d(np.arange(n), fixed)
    lam, X = _lowest_modes(K[free][:, free], M[free][:, free], int(n_modes), "normal_modes")
    shapes = np.zeros((n, X.shape[1]))
    shapes[free] = X
    return np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi), shapes


def normal_mode_component(M, K, n_modes: int, fixed_dofs=()) -> ModalComponent:
    """The lowest ``n_modes`` normal modes with ``fixed_dofs`` held, as a :class:`ModalComponent`
    (mass-normalised; zero rows at the fixed degrees of freedom).  With the nodes of a clamp held,
    these are the cantilever modes of a floating frame attached to that clamp."""
    M, K = _check_pair(M, K)
    f, X = normal_modes(M, K, n_modes, fixed_dofs)
    Mr, Kr = X.T @ (M @ X), X.T @ (K @ X)
    return ModalComponent(X, 0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T), tuple(f"mode {k + 1}" for k in range(X.shape[1])),
                          f, np.zeros(0, np.int64), "normal modes" + (", supported" if len(fixed_dofs) else ""))


@dataclass(frozen=True)
class ModalComponent:
    """A reduced linear elastic component, :math:`u = T q`.

    Attributes
    ----------
    T : (n, m) ndarray
        Reduction basis on the full degrees of freedom (zero rows at fixed ones).
    M, K : (m, m) ndarray
        Reduced mass and stiffness.
    labels : tuple of str
        What each reduced coordinate is (``"interface dof 12"``, ``"fixed-interface mode 3"``,
        ``"mode 2"``).
    fixed_interface_frequencies : ndarray
        [Hz] of the fixed-interface modes kept (Craig–Bampton).
    interface_dofs : ndarray
    method : str
    """

    T: np.ndarray
    M: np.ndarray
    K: np.ndarray
    labels: tuple
    fixed_interface_frequencies: np.ndarray
    interface_dofs: np.ndarray
    method: str

    def frequencies(self) -> np.ndarray:
        """Natural frequencies [Hz] of the reduced component as it stands (its interface free),
        ascending; rigid-body modes give 0."""
        lam = sla.eigh(self.K, self.M, eigvals_only=True)
        return np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi)

    def orthonormalized(self, drop_rigid: bool = False) -> ModalComponent:
        """The same subspace in its own normal modes: :math:`M_r = I`, :math:`K_r =
        \\operatorname{diag}(\\omega^2)` (the orthonormalised Craig–Bampton basis of flexible-body
        input files).  ``drop_rigid`` removes the rigid-body modes (:data:`RIGID_TOL`), which a
        floating frame of reference carries itself; their number is in ``labels``."""
        lam, X = sla.eigh(self.K, self.M)
        rigid = lam < RIGID_TOL * max(float(lam.max()), 1e-300)
        if drop_rigid:
            keep = ~rigid
            if not keep.any():
                raise ModelError("orthonormalized(drop_rigid=True): every mode of the component is rigid")
            lam, X, rigid = lam[keep], X[:, keep], rigid[keep]
        labels = tuple(("rigid-body mode" if r else "mode") + f" {k + 1}" for k, r in enumerate(rigid))
        return ModalComponent(self.T @ X, np.eye(X.shape[1]), np.diag(np.where(rigid, 0.0, lam)), labels,
                              self.fixed_interface_frequencies, self.interface_dofs,
                              self.method + ", orthonormalised")

    @property
    def n_rigid(self) -> int:
        """Rigid-body modes of the reduced component (ω² below :data:`RIGID_TOL` of the largest)."""
        lam = sla.eigh(self.K, self.M, eigvals_only=True)
        return int(np.sum(lam < RIGID_TOL * max(float(lam.max()), 1e-300)))


def craig_bampton(M, K, interface_dofs, n_modes: int, fixed_dofs=()) -> ModalComponent:
    """Craig–Bampton reduction (module docstring): the interface degrees of freedom kept, plus the
    lowest ``n_modes`` fixed-interface modes; ``fixed_dofs`` are held (a support)."""
    M, K = _check_pair(M, K)
    n = M.shape[0]
    if not (isinstance(n_modes, (int, np.integer)) and n_modes >= 0):
        raise InputError(f"n_modes = {n_modes!r} must be a non-negative integer")
    fixed = _dof_list(fixed_dofs, n, "craig_bampton fixed_dofs")
    b = _dof_list(interface_dofs, n, "craig_bampton interface_dofs")
    clash = np.intersect1d(b, fixed)
    if clash.size:
        raise InputError(f"craig_bampton: degree of freedom {int(clash[0])} is both an interface and a fixed one")
    if b.size == 0:
        raise InputError("craig_bampton: give at least one interface degree of freedom (or use normal_modes)")
    i = np.setdiff1d(np.arange(n), np.concatenate([b, fixed]))
    Kii, Kib = K[i][:, i].tocsc(), K[i][:, b]
    try:
        lu = spla.splu(Kii)
    except RuntimeError:
        raise ModelError("craig_bampton: the interior is not held by the interface (K_ii is singular): "
                         "the interface must fix every rigid-body motion of the interior") from None
    Psi = -lu.solve(Kib.toarray())
    if n_modes:
        lam, Phi = _lowest_modes(Kii, M[i][:, i], int(n_modes), "craig_bampton")
    else:
        lam, Phi = np.zeros(0), np.zeros((i.size, 0))
    T = np.zeros((n, b.size + Phi.shape[1]))
    T[b, np.arange(b.size)] = 1.0
    T[np.ix_(i, np.arange(b.size))] = Psi
    T[np.ix_(i, b.size + np.arange(Phi.shape[1]))] = Phi
    Mr, Kr = T.T @ (M @ T), T.T @ (K @ T)
    Mr, Kr = 0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T)
    try:
        np.linalg.cholesky(Mr)
    except np.linalg.LinAlgError:
        raise ModelError("craig_bampton: the reduced mass matrix is not positive definite (a massless interface "
                         "degree of freedom? give the element a rotary inertia or drop that degree of freedom)") from None
    labels = tuple([f"interface dof {int(d)}" for d in b] + [f"fixed-interface mode {k + 1}" for k in range(Phi.shape[1])])
    return ModalComponent(T, Mr, Kr, labels, np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * np.pi), b, "Craig-Bampton")


def rigid_body_modes(nodes, dofs_per_node: int, M) -> np.ndarray:
    """Rigid-body modes of a free component (module docstring), mass-normalised, (n, 3) in the
    plane or (n, 6) in space.  ``dofs_per_node``: 2 or 3 (planar translations, with θ_z), 3 or 6
    (spatial translations, with rotations)."""
    nodes = np.asarray(nodes, float)
    N, dim = nodes.shape
    if (dim, dofs_per_node) not in ((2, 2), (2, 3), (3, 3), (3, 6)):
        raise InputError(f"rigid_body_modes: {dofs_per_node} degrees of freedom per node in {dim}-D; give 2 or 3 "
                         "in the plane, 3 or 6 in space")
    n = N * dofs_per_node
    if M.shape[0] != n:
        raise InputError(f"rigid_body_modes: the mass matrix has order {M.shape[0]}, the {N} nodes "
                         f"{n} degrees of freedom")
    c = nodes.mean(axis=0)
    d = nodes - c  # rotations about the centroid keep the basis well conditioned
    if dim == 2:
        R = np.zeros((n, 3))
        R[0::dofs_per_node, 0] = 1.0
        R[1::dofs_per_node, 1] = 1.0
        R[0::dofs_per_node, 2] = -d[:, 1]
        R[1::dofs_per_node, 2] = d[:, 0]
        if dofs_per_node == 3:
            R[2::3, 2] = 1.0
    else:
        R = np.zeros((n, 6))
        for k in range(3):
            R[k::dofs_per_node, k] = 1.0
            e = np.eye(3)[k]
            u = np.cross(e, d)  # small rotation about axis k: u = e x d
            for j in range(3):
                R[j::dofs_per_node, 3 + k] = u[:, j]
            if dofs_per_node == 6:
                R[3 + k::6, 3 + k] = 1.0
    G = R.T @ (M @ R)
    L = np.linalg.cholesky(0.5 * (G + G.T))
    return np.linalg.solve(L, R.T).T  # R L^-T: mass-normalised


def free_interface(M, K, nodes, dofs_per_node: int, n_modes: int, attachment_dofs=()) -> ModalComponent:
    """Free-interface reduction of a free component: its rigid-body modes, the lowest ``n_modes``
    elastic modes and one residual attachment mode per degree of freedom of ``attachment_dofs``
    (the static correction; module docstring)."""
    M, K = _check_pair(M, K)
    n = M.shape[0]
    if not (isinstance(n_modes, (int, np.integer)) and n_modes >= 0):
        raise InputError(f"n_modes = {n_modes!r} must be a non-negative integer")
    a = _dof_list(attachment_dofs, n, "free_interface attachment_dofs")
    R = rigid_body_modes(nodes, dofs_per_node, M)
    n_r = R.shape[1]
    resid = np.abs(K @ R).max() / max(abs(K).max(), 1e-300)
    if resid > 1e-8:
        raise ModelError(f"free_interface: the component is not free (|K Φ_r| / |K| = {resid:.2g}: its stiffness "
                         "resists a rigid-body motion); reduce a supported component with craig_bampton")
    lam, X = _lowest_modes(K, M, n_r + int(n_modes) + 1 if n_r + int(n_modes) < n else n_r + int(n_modes),
                           "free_interface")
    # against the stiffest element's scale (max diag K / diag M bounds the spectrum from about its
    # top): a relative test on the few modes computed fails when all of them are rigid
    scale = float(np.max(K.diagonal() / np.where(M.diagonal() > 0, M.diagonal(), np.inf)))
    zero = lam < RIGID_TOL * max(scale, 1e-300)
    if zero.sum() > n_r:
        raise ModelError(f"free_interface: the component has {int(zero.sum())} modes without stiffness, its node "
                         f"coordinates give {n_r} rigid-body motions: it is a mechanism or in disconnected parts")
    lam, X = lam[n_r:n_r + int(n_modes)], X[:, n_r:n_r + int(n_modes)]  # the elastic ones
    X = X - R @ (R.T @ (M @ X))  # exactly M-orthogonal to the rigid modes
    MR = M @ R
    shifted = (K + sp.csr_matrix(MR @ MR.T)).tocsc() if n <= DENSE_EIG_MAX else None
    cols = []
    if a.size:
        E = np.zeros((n, a.size))
        E[a, np.arange(a.size)] = 1.0
        PE = E - MR @ (R.T @ E)  # P^T E: the loads balanced by the rigid-body inertia (inertia relief)
        if shifted is not None:
            Y = np.linalg.solve(shifted.toarray(), PE)
        else:
            Y = spla.splu((K + sp.csr_matrix(MR @ MR.T)).tocsc()).solve(PE)
        Ge = Y - R @ (MR.T @ Y)  # P (K + M R R^T M)^-1 P^T E
        Gres = Ge - X @ ((X.T @ PE) / lam[:, None])
        cols = [Gres]
    T = np.hstack([R, X] + cols)
    Mr, Kr = T.T @ (M @ T), T.T @ (K @ T)
    Mr, Kr = 0.5 * (Mr + Mr.T), 0.5 * (Kr + Kr.T)
    labels = tuple([f"rigid-body mode {k + 1}" for k in range(n_r)] + [f"mode {k + 1}" for k in range(X.shape[1])]
                   + [f"residual attachment dof {int(d)}" for d in a])
    return ModalComponent(T, Mr, Kr, labels, np.zeros(0), a, "free interface + static correction")
