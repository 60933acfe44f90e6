"""A linear finite-element component: node coordinates, mass and stiffness, and where they came from.

The reductions of :mod:`core.flexible.reduction` work on its ``M`` and ``K``; a component comes
from the beam elements of :mod:`core.flexible.beam` (:meth:`FEModel.from_beam`) or from another FE
code (:meth:`FEModel.read`): mass and stiffness exported in Matrix Market format (``.mtx``, the
NIST exchange format that Abaqus' ``*MATRIX GENERATE``, Ansys' HBMAT via a converter, Code_Aster and
most FE codes can write, read with ``scipy.io.mmread``) and the node coordinates as CSV, one node
per line.  The degrees of freedom are numbered node by node, ``dofs_per_node`` per node in the
order (u_x, u_y[, u_z][, rotations]).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..errors import InputError

__all__ = ["FEModel"]

#: a component larger than this (m) is taken for one whose coordinates are in another unit
MAX_EXTENT = 500.0


@dataclass(frozen=True)
class FEModel:
    """Nodes (N, dim) [m], ``dofs_per_node``, mass and stiffness (scipy CSR) of order
    ``N * dofs_per_node``, and ``source`` (what it was made from).

    ``geometric_stiffness``, where the element type provides one, is a callable ``u -> K_G(u)``:
    the stress stiffness in the stress state of the displacement ``u`` (beams:
    :class:`~core.flexible.beam.BeamGeometricStiffness`); flexible bodies use it for geometric
    stiffening.  Imported matrices have none.  ``beam`` is ``(mesh, section, theory)`` for a beam
    component (section forces are recovered from it), else None.  ``stress_recovery``, for plane and
    solid components, is a callable ``U -> σ`` giving the nodal stresses of displacement columns
    (:class:`~core.flexible.continuum.ContinuumStresses`), else None."""

    nodes: np.ndarray
    dofs_per_node: int
    M: sp.csr_matrix
    K: sp.csr_matrix
    source: str = ""
    geometric_stiffness: object = None
    beam: tuple | None = None
    stress_recovery: object = None

    def __post_init__(self):
        n = self.nodes.shape[0] * self.dofs_per_node
        for name in ("M", "K"):
            A = getattr(self, name)
            if A.shape != (n, n):
                raise InputError(f"{self.source or 'FE model'}: {name} has order {A.shape}, the "
                                 f"{self.nodes.shape[0]} nodes with {self.dofs_per_node} degrees of freedom each "
                                 f"need {n}")

    @property
    def n_dofs(self) -> int:
        return self.M.shape[0]

    def dofs(self, node: int, which=None) -> np.ndarray:
        """Global indices of a node's degrees of freedom (all, or ``which`` of them)."""
        k = np.arange(self.dofs_per_node) if which is None else np.asarray(which, np.int64)
        return int(node) * self.dofs_per_node + k

    @classmethod
    def from_beam(cls, mesh, section, theory: str = "euler-bernoulli") -> FEModel:
        """The beam elements' assembled matrices (:func:`core.flexible.beam.beam_matrices`)."""
        from .beam import BeamGeometricStiffness, beam_matrices

        M, K = beam_matrices(mesh, section, theory)
        return cls(mesh.nodes, mesh.dofs_per_node, M, K, f"{theory} beam, {mesh.elements.shape[0]} elements",
                   BeamGeometricStiffness(mesh, section), (mesh, section, theory))

    @classmethod
    def read(cls, mass, stiffness, nodes, dofs_per_node: int, length_unit: str = "m",
             mass_unit: str = "kg", force_unit: str = "N") -> FEModel:
        """Read an exported component (module docstring).

        Parameters
        ----------
        mass, stiffness : path
            Matrix Market files (``.mtx``, coordinate or array, symmetric or general).
        nodes : path
            CSV of the node coordinates, one node per line (x, y[, z]); a header line is skipped.
        dofs_per_node : int
        length_unit, mass_unit, force_unit : str
            The units the FE model was written in (pint names: ``"mm"``, ``"t"``, ``"N"``); the
            matrices and coordinates are converted to SI.  A model in mm, t, N (a common FE
            system) is read with ``length_unit="mm", mass_unit="t"``.

        Raises
        ------
        InputError
            Naming the file at fault: missing, not Matrix Market, not square, of another order
            than the nodes, not symmetric, non-finite, a mass matrix that is not positive
            definite, or coordinates that look like another length unit.
        """
        from scipy.io import mmread

        from ..inputs import parse_quantity

        if not (isinstance(dofs_per_node, (int, np.integer)) and 1 <= dofs_per_node <= 6):
            raise InputError(f"dofs_per_node = {dofs_per_node!r}: give 1 to 6")
        to_m = parse_quantity(f"1 {length_unit}", "m", where="length_unit")
        to_kg = parse_quantity(f"1 {mass_unit}", "kg", where="mass_unit")
        to_N = parse_quantity(f"1 {force_unit}", "N", where="force_unit")
        mats = {}
        for name, path in (("mass", mass), ("stiffness", stiffness)):
            path = Path(path)
            if not path.is_file():
                raise InputError(f"{name} matrix file {path} does not exist")
            try:
                A = mmread(str(path))
            except Exception as exc:  # scipy raises ValueError or its own errors on bad files
                raise InputError(f"{name} matrix file {path} is not a Matrix Market file ({exc})") from None
            A = sp.csr_matrix(A, dtype=float)
            if A.shape[0] != A.shape[1]:
                raise InputError(f"{name} matrix file {path}: {A.shape[0]} x {A.shape[1]} is not square")
            if not np.all(np.isfinite(A.data)):
                raise InputError(f"{name} matrix file {path} has non-finite entries")
            asym = abs(A - A.T).max() if A.nnz else 0.0
            if asym > 1e-9 * max(abs(A).max(), 1e-300):
                raise InputError(f"{name} matrix file {path} is not symmetric (largest |A - Aᵀ| = {asym:.3g}); "
                                 "export the full symmetric matrix")
            mats[name] = (A, path)
        path = Path(nodes)
        if not path.is_file():
            raise InputError(f"node file {path} does not exist")
        text = path.read_text(encoding="utf-8").splitlines()
        rows = []
        for k, line in enumerate(text, start=1):
            if not line.strip():
                continue
            try:
                rows.append([float(x) for x in line.replace(";", ",").split(",") if x.strip()])
            except ValueError:
                if not rows:  # a header line
                    continue
                raise InputError(f"node file {path}, line {k}: {line.strip()!r} is not a row of numbers") from None
        widths = {len(r) for r in rows}
        if not rows or len(widths) != 1 or widths.pop() not in (2, 3):
            raise InputError(f"node file {path}: give 2 or 3 coordinates on every line")
        X = np.array(rows) * to_m
        extent = float(np.max(X.max(axis=0) - X.min(axis=0)))
        if extent > MAX_EXTENT:
            raise InputError(f"node file {path}: the component is {extent:g} m long; were the coordinates in "
                             "millimetres? pass length_unit='mm'")
        M = mats["mass"][0] * (to_kg)  # kg: mass_unit
        K = mats["stiffness"][0] * (to_N / to_m)  # N/m: force_unit / length_unit
        if dofs_per_node > X.shape[1]:  # rotational degrees of freedom: inertias and moments in length²
            rot = np.zeros(X.shape[0] * dofs_per_node, bool)
            for j in range(X.shape[1], dofs_per_node):
                rot[j::dofs_per_node] = True
            sM = np.where(rot, to_m, 1.0)
            M = sp.diags(sM) @ M @ sp.diags(sM)
            K = sp.diags(sM) @ K @ sp.diags(sM)
        model = cls(X, int(dofs_per_node), sp.csr_matrix(M), sp.csr_matrix(K), f"{mats['mass'][1].name} + "
                    f"{mats['stiffness'][1].name} + {path.name}")
        if model.n_dofs <= 3000:
            try:
                np.linalg.cholesky(model.M.toarray())
            except np.linalg.LinAlgError:
                raise InputError(f"mass matrix file {mats['mass'][1]} is not positive definite (a degree of "
                                 "freedom without mass? drop it, or give the element its rotary inertia)") from None
        return model
