r"""Packing a frozen model into the flat arrays of the compiled path (model set-up, done once).

:func:`compile_model` asks every constraint and force kind of a :class:`core.model.Model` for its
compiled form (``kind.compiled(layout)``, :mod:`core.compiled.protocol`), and fixes what the
numba code needs: the block structure of the velocity vector, the inverse mass blocks, the rows of
``Φ_q`` and the blocks each touches, the sparsity pattern of the Schur complement and its
bandwidth-reducing order, and the tuples of kernel function pointers.

Blocks and the saddle-point solve
---------------------------------
The velocity vector is split into *blocks*: bodies (``n_v_body`` coordinates) and extra
coordinates (width 1).  Blocks with a positive definite mass block ``M_b`` are eliminated through
``M_b⁻¹``; the others — massless extra coordinates (a path parameter, fixed by constraints) and
bodies with a singular mass block (a slider or a point mass without rotational inertia, whose
rotation the joints fix) — form the *border* X with their (singular) mass matrix ``M_XX``.
The regular rows R are an independent set of the rows touching blocks with ``M_b > 0`` (all of them
without a border), so that ``S = G_{RB} M_B^{-1} G_{RB}^T`` is positive definite; the other rows E
(rows on border coordinates only, and the remainder) join the border.  With a border the set must
stay independent as the model moves, not only at the start: on a turning flexible body the hub
pin's rows and the tip node frame's rows, restricted to the body, are independent at most angles
and dependent at 0 and π/2, and a set chosen at the start then makes ``S`` singular half a turn
later.  So rows are taken greedily at the initial configuration in an order that keeps the set
independent: rows touching no border coordinate first (independent at every configuration, as the
model's rows are), then the other rows touching the border; the rows of kinds that fix massless
bodies (``CompiledConstraints.border``: a flexible body's node frames) go to E at once.

*Mass groups* (:class:`core.compiled.protocol.CompiledMass`: a flexible body with the deformed
body's inertia) are blocks with mass whose joint mass matrix depends on the configuration: their
kernel writes it at every evaluation, :func:`core.compiled.dynamics.mass_update` inverts it by its
Cholesky factor, and ``M_B⁻¹`` applies it to the group's coordinates together; every row touching a
group holds a slot on each of its blocks (added here, their Jacobian entries zero) so that
``X = M_B⁻¹G_RBᵀ`` and the Schur pattern are complete.  With ``x = (x_B, x_X)``,
``μ = (μ_R, μ_E)`` and ``z = (x_X, μ_E)`` the system ``[[M, Gᵀ], [G, 0]] [x; μ] = [f; g]``
is solved by block elimination of ``x_B`` and ``μ_R`` (Benzi, Golub & Liesen 2005, Sec. 5):

.. math::

    H = G_{RB} M_B^{-1} G_{EB}^T,\quad S_{EE} = G_{EB} M_B^{-1} G_{EB}^T,\quad
    C = [\,-G_{RX}\;\;H\,],\quad
    T = C^T S^{-1} C + \begin{bmatrix} M_{XX} & G_{EX}^T \\ G_{EX} & -S_{EE} \end{bmatrix},

    r_R = G_{RB} M_B^{-1} f_B - g_R,\qquad r_E = G_{EB} M_B^{-1} f_B - g_E,\qquad
    T z = C^T S^{-1} r_R + \begin{bmatrix} f_X \\ -r_E \end{bmatrix},

    μ_R = S^{-1}(r_R - C z),\qquad x_B = M_B^{-1}(f_B - G_{RB}^T μ_R - G_{EB}^T μ_E).

``S`` is factorised by the envelope Cholesky algorithm in reverse Cuthill–McKee order (George &
Liu 1981, Ch. 4); ``T`` (size ``n_X + n_E``, symmetric indefinite) by LU with partial pivoting.
Without border coordinates ``C``, ``T`` are empty and this is the plain Schur-complement solve.

References
----------
M. Benzi, G. H. Golub, J. Liesen, "Numerical solution of saddle point problems", Acta Numerica
14 (2005) 1–137.
A. George, J. W. H. Liu, *Computer Solution of Large Sparse Positive Definite Systems*, 1981.
"""

from __future__ import annotations

import weakref

import numba
import numpy as np
import scipy.sparse as sp
from numba.core import types
from numba.experimental import structref
from scipy.sparse.csgraph import reverse_cuthill_mckee

from ..errors import NotCompilable
from .protocol import (
    ACCEPT_SIGNATURE,
    FRC_TAB_WIDTH,
    FT_FD0,
    FT_FD1,
    FT_FW,
    FT_IW,
    FT_IX0,
    FT_IX1,
    FT_N,
    FT_ST0,
    FT_ST1,
    FT_STN,
    FT_STW,
    CONSTRAINT_SIGNATURE,
    FORCE_JACOBIAN_SIGNATURE,
    FORCE_SIGNATURE,
    MASS_SIGNATURE,
    MAX_SLOTS,
    OK,
    CompiledConstraints,
    CompiledForces,
    CompiledMass,
    accept_kernel,
    constraint_kernel,
    force_jacobian_kernel,
    force_kernel,
    mass_kernel,
    resolve_kernel,
)

__all__ = ["Layout", "CompiledModel", "CompiledData", "compile_model", "KIND_CAPACITY", "numpy_refusal"]

#: Kernel tuples are padded with no-ops to this length (a tuple's length is part of its numba
#: type), so the compiled code is compiled once for every model; a model with more kinds of one
#: family is refused by name.
KIND_CAPACITY = 16

#: Fields of :class:`CompiledData`: the model's arrays ...
MODEL_FIELDS = (
    "lay",        # int64 (7,): see core.compiled.protocol.LAYOUT_FIELDS
    "blk_v0",     # int64 (n_blk,): first velocity index of each block (bodies, ground, extras)
    "blk_w",      # int64 (n_blk,): width (n_v_body, 0 for the ground, 1 for extras)
    "blk_x",      # int64 (n_blk,): first index among the border coordinates, −1 for blocks with mass > 0
    "minv",       # float (n_blk, 6, 6): inverse mass blocks (zero for the ground and massless)
    "Qg",         # float (n_v,): gravity
    "Jt",         # float (n_b + 1, 3, 3): inertia tensors (spatial gyroscopic moments)
    "r_blk",      # int64 (m_all, MAX_SLOTS): block of each slot of each model row, −1 unused
    "act",        # int64 (m,): active model rows (redundant rows removed)
    "reg",        # int64 (m_R,): regular rows (touch a block with mass), in factorisation order
    "ext",        # int64 (m_E,): rows touching only massless coordinates
    "pat",        # int64 (n_p, 7): Schur pattern (a, slot_a, b, slot_b, i, j, width): S[i, j] += G[a,sa]·X[b,sb]
    "env_first",  # int64 (m_R,): first column of each envelope row
    "rs_cnt",     # int64 (m_all,): number of slots of a row on blocks with mass
    "rs",         # int64 (m_all, MAX_SLOTS, 4): those slots: (slot, block, first velocity index, width)
    "mass_blocks",  # int64: blocks with mass (bodies, extras with mass)
    "n_x",        # int: border coordinates (blocks with a singular or zero mass matrix)
    "xm",         # float (n_x, n_x): their mass matrix M_XX (block diagonal, singular)
    "hpat",       # int64 (n_h, 7): (a, slot_a, e_row, slot_e, k, e, width): H[k, e] += G[a,sa]·X[e_row,se]
    "epat",       # int64 (n_ee, 7): (e1_row, s1, e2_row, s2, e1, e2, width): S_EE[e1, e2] += G·X
    "n_grp",      # int: mass groups (configuration-dependent mass matrices, protocol "Mass groups")
    "blk_g",      # int64 (n_blk,): group of each block, −1 for blocks with a constant inverse mass
    "blk_go",     # int64 (n_blk,): first position of the block in its group's coordinates
    "grp_v",      # int64 (n_g, w_max): velocity indices of each group
    "grp_w",      # int64 (n_g,): number of coordinates of each group
    "rg_cnt",     # int64 (m_all,): groups a row touches
    "rg",         # int64 (m_all, MAX_SLOTS): those groups
    "pad_slots",  # int64 (n_pad, 2): (row, slot) added for groups: their Jacobian entries are zero
)
#: ... and the kinds' kernels (tuples of function pointers padded to KIND_CAPACITY with no-ops)
#: with their data stored flat: kind ``k`` reads ``fd[fo[k]:fo[k+1]].reshape(n[k], fw[k])`` and
#: ``ix[io[k]:io[k+1]].reshape(n[k], iw[k])``; its search state is
#: ``states[st_off[k]:st_off[k+1]].reshape(st_n[k], st_w[k])``.  ``frc_tab`` holds the same
#: offsets and shapes of the force kinds as one int64 table (n_frc, FRC_TAB_WIDTH), columns
#: ``FT_*``: the right-hand side reads one array for them instead of eight (each read of a
#: structure's array is counted up and down atomically by numba, ~10 ns a pair).
KERNEL_FIELDS = (
    "n_con", "con", "con_fd", "con_fo", "con_n", "con_fw", "con_ix", "con_io", "con_iw", "con_row0",
    "n_frc", "frc", "frc_fd", "frc_fo", "frc_n", "frc_fw", "frc_ix", "frc_io", "frc_iw", "frc_tab",
    "frc_jac", "frc_has_jac", "frc_acc", "frc_stateful", "st_off", "st_n", "st_w",
    "frc_ncol", "frc_col", "frc_reach",  # column grouping of the difference Jacobian (fd_colouring)
    "mass_k", "mass_fd", "mass_ix",  # the mass kernel of the groups (a 1-tuple; a no-op without groups) and its data
)


@structref.register
class CompiledDataType(types.StructRef):
    """numba type of :class:`CompiledData`."""

    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(typ)) for name, typ in fields)


class CompiledData(structref.StructRefProxy):
    """Everything the compiled functions read about one model, in one object (a numba structref).

    One object instead of tuples: passing it into compiled code costs ~2 µs, where a tuple of
    ~40 arrays and function pointers costs ~0.2 ms of numba's argument typing per call.  Fields
    :data:`MODEL_FIELDS` and :data:`KERNEL_FIELDS`; created by :func:`compile_model`.
    """

    def __new__(cls, *values):
        obj = _new_compiled_data(*values)
        obj._fields = dict(zip(MODEL_FIELDS + KERNEL_FIELDS, values))
        return obj

    def __getattr__(self, name):
        try:
            return self.__dict__["_fields"][name]
        except KeyError:
            raise AttributeError(f"CompiledData has no field {name!r}") from None


structref.define_proxy(CompiledData, CompiledDataType, list(MODEL_FIELDS + KERNEL_FIELDS))


@numba.njit(cache=True)
def _new_compiled_data(*values):
    """The structref built in compiled code by a function numba caches on disk:
    ``StructRefProxy.__new__`` compiles an uncached constructor in every process (~1.5 s for this
    type's ~60 fields, paid before a model's first compiled run)."""
    return CompiledData(*values)


class Layout:
    """What a kind's ``compiled(layout)`` may ask for: sizes and the indices of extra coordinates.

    Attributes
    ----------
    n_bodies, dim, n_q_body, n_v_body, n_q, n_v : int
    extra_names, body_names : list of str
    gravity : ndarray (dim,)
    """

    def __init__(self, model):
        sp_ = model.space
        self.model_name = model.name
        self.n_bodies = model.n_bodies
        self.dim = sp_.dim
        self.n_q_body, self.n_v_body = sp_.n_q, sp_.n_v
        self.n_q, self.n_v = model.n_q, model.n_v
        self.extra_names = list(model.extra_names)
        self.body_names = list(model.body_names)
        self.gravity = np.asarray(model.gravity, float).copy()

    def model_body_index(self, name: str) -> int:
        """Index of a body of the model (the ground: ``n_bodies``)."""
        if name == "ground":
            return self.n_bodies
        return self.body_names.index(name)

    def extra_index(self, name: str, element: str) -> int:
        """Index ``k`` of an extra coordinate (q index ``n_b n_q_body + k``, v index ``n_b n_v_body + k``)."""
        try:
            return self.extra_names.index(name)
        except ValueError:
            raise NotCompilable(f"{element}: unknown extra coordinate {name!r}") from None

    def extra_q_index(self, name: str, element: str) -> int:
        return self.n_bodies * self.n_q_body + self.extra_index(name, element)

    def extra_v_index(self, name: str, element: str) -> int:
        return self.n_bodies * self.n_v_body + self.extra_index(name, element)

    def extra_slot(self, name: str, element: str) -> int:
        """Jacobian slot block of an extra coordinate (:func:`core.compiled.protocol.extra_slot`)."""
        return self.n_bodies + 1 + self.extra_index(name, element)


# --- no-op kernels padding the tuples and standing in for a missing Jacobian or search state --------


@constraint_kernel
def _no_constraints(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    return OK


@force_kernel
def _no_forces(t, q, v, r, A, rd, w, lay, fd, ix, state, Q, err):
    return OK


@force_jacobian_kernel
def _no_jacobian(t, q, v, r, A, rd, w, lay, fd, ix, state, K, D, err):
    return OK


@accept_kernel
def _no_accept(t, q, v, r, A, rd, w, lay, fd, ix, state, err):
    return OK


@mass_kernel
def _no_mass(t, q, v, r, A, rd, w, lay, fd, ix, Mg, err):
    return OK


class CompiledModel:
    """A model packed for the compiled path (cached per model; see :func:`compile_model`).

    Attributes
    ----------
    data : CompiledData
        What the compiled functions read (one numba structref).
    constraint_kinds, force_kinds : list
        The compiled records of the kinds (for names in messages).
    n_x, n_e, n_reg, m : int
        Border coordinates (massless or of bodies with a singular mass block), rows on border
        coordinates only, regular rows, active rows.
    n_q, n_v, m_all : int
    stateful : bool
        Some force kind keeps a search state (copied per run by :meth:`initial_states`).
    """

    def __init__(self, model, fields: dict, constraint_kinds, force_kinds, states: np.ndarray,
                 mass_record: CompiledMass | None = None):
        self.name = model.name
        self.fields = fields
        self.data = CompiledData(*(fields[f] for f in MODEL_FIELDS + KERNEL_FIELDS))
        self.constraint_kinds = constraint_kinds
        self.force_kinds = force_kinds
        self.mass_record = mass_record
        self.n_grp = int(fields["n_grp"])
        self.group_width = int(fields["grp_v"].shape[1])
        self._states = states
        self.n_x = int(fields["n_x"])
        self.n_e = len(fields["ext"])
        self.n_reg = len(fields["reg"])
        self.m = len(fields["act"])
        self.m_all = fields["r_blk"].shape[0]
        self.n_b = int(fields["lay"][0])
        self.n_q, self.n_v = int(fields["lay"][4]), int(fields["lay"][5])
        self.stateful = bool(np.any(fields["frc_stateful"]))
        self._st_off, self._st_n, self._st_w = fields["st_off"], fields["st_n"], fields["st_w"]
        #: set-up results of integrators kept with the model (e.g. the Radau unknowns' ordering)
        self.setup_cache: dict = {}

    def initial_states(self) -> np.ndarray:
        """A fresh copy of the force kinds' search states (one per integrator run), stored flat
        (see :data:`KERNEL_FIELDS`); kinds with an ``initial_state`` callback supply the state of
        the run's initial conditions (call after the system's ``begin_run``)."""
        out = self._states.copy()
        for k, rec in enumerate(self.force_kinds):
            cb = getattr(rec, "initial_state", None)
            if cb is None:
                continue
            blk = np.asarray(cb(), dtype=float)
            a, b = int(self._st_off[k]), int(self._st_off[k + 1])
            if blk.size != b - a:
                raise RuntimeError(f"{rec.what} {rec.names[0]!r}: initial_state() returned {blk.size} values, "
                                   f"the state holds {b - a}")
            out[a:b] = blk.ravel()
        return out

    def state_blocks(self, states: np.ndarray) -> dict[tuple[str, ...], np.ndarray]:
        """The search state of every stateful force kind in the flat ``states`` (one row, or rows
        of a run's steps), by the kind's element names: copies of shape ``(..., n_elements,
        width)``, the layout of the kind's own ``state`` (its accept kernel's view)."""
        states = np.asarray(states)
        out = {}
        for k, rec in enumerate(self.force_kinds):
            a, b = int(self._st_off[k]), int(self._st_off[k + 1])
            if b > a:
                shape = states.shape[:-1] + (int(self._st_n[k]), int(self._st_w[k]))
                out[tuple(rec.names)] = np.array(states[..., a:b]).reshape(shape)
        return out

    def failure_description(self, kind: int, states: np.ndarray) -> str:
        """The kind's own description of a failure its kernels reported ('' if none)."""
        if not (0 <= kind < len(self.force_kinds)):
            return ""
        rec = self.force_kinds[kind]
        cb = getattr(rec, "describe_failure", None)
        if cb is None:
            return ""
        a, b = int(self._st_off[kind]), int(self._st_off[kind + 1])
        return str(cb(np.asarray(states[a:b]).reshape(int(self._st_n[kind]), int(self._st_w[kind]))))

    def element_name(self, family: str, kind: int, element: int) -> str:
        """Name of the element a kernel reported in ``err`` (family 'force', 'constraint' or 'mass';
        for a mass group ``kind`` is the group)."""
        if family == "mass":
            rec = self.mass_record
            if rec is not None and 0 <= kind < len(rec.names):
                return f"{rec.what} {rec.names[kind]!r}"
            return "a mass group"
        recs = self.force_kinds if family == "force" else self.constraint_kinds
        if 0 <= kind < len(recs):
            rec = recs[kind]
            name = rec.names[element] if 0 <= element < len(rec.names) else "?"
            return f"{rec.what} {name!r}"
        return "an element"


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def compile_model(model) -> CompiledModel:
    """Pack a frozen :class:`core.model.Model` for the compiled path (cached per model).

    Raises
    ------
    NotCompilable
        For a system that is not a Cartesian model, an element kind without a compiled form (the
        message names the element), a body with a singular mass block, redundant rows kept in the
        model, or more than :data:`KIND_CAPACITY` kinds of one family.
    """
    from ..model import Model

    if isinstance(model, Model):
        try:
            return _CACHE[model]
        except (KeyError, TypeError):
            pass
    cm = _compile(model)
    # the arrays stay writable at the numpy level (numba types a read-only array differently from
    # the kernels' signatures); nothing writes to them after this point
    try:
        _CACHE[model] = cm
    except TypeError:  # pragma: no cover - a model class without weak references
        pass
    return cm


def _compile(model) -> CompiledModel:
    from ..model import Model

    if not isinstance(model, Model):
        raise NotCompilable(f"compiled integrators need a core.model.Model, got {type(model).__name__} "
                            f"{getattr(model, 'name', '')!r}; use the numpy integrators for hand-written systems")
    if len(getattr(model, "redundant_rows", ())) and model._active_rows is None:
        raise NotCompilable(f"model {model.name!r} keeps redundant constraint rows "
                            f"({', '.join(model.redundant_constraints[:3])}...); build it with redundant='remove' "
                            "for the compiled integrators (their Schur complement must be positive definite)")
    layout = Layout(model)
    sp_ = model.space
    nb, dim, nvb = model.n_bodies, sp_.dim, sp_.n_v
    ne = len(model.extra_names)
    # --- flexible bodies (core.flexible.compiled): a rigid block plus modal oscillators, or a mass
    # group whose mass matrix follows the deformation (its kernels recompute it at every evaluation) --
    flex_blocks, flex_extra_mass, flex_rows, group_rows = {}, {}, [], []
    for f in getattr(model, "flexible", ()):
        from ..flexible.compiled import compiled_flexible_body

        names = [model.extra_names[int(i) - nb * sp_.n_v] for i in f.vi[nvb:]]
        try:
            fb = compiled_flexible_body(f.data, layout, nvb, names)
        except NotCompilable as exc:
            raise NotCompilable(f"model {model.name!r}: {exc}") from None
        if fb["form"] == "group":
            fb["v_index"] = np.asarray(f.vi, np.int64)
            group_rows.append(fb)
            continue
        flex_blocks[f.body] = fb
        for c, mu in zip(names, fb["modal_mass"]):
            flex_extra_mass[model.extra_names.index(c)] = float(mu)
        flex_rows.append(fb)
    mass_rec = None
    if group_rows:
        from ..flexible.compiled import inertia_records

        mass_rec, inertia_forces = inertia_records(group_rows)
    n_blk = nb + 1 + ne
    blk_g, blk_go, groups, group_blocks = _mass_groups(model, mass_rec, nb, nvb, ne)
    # --- constraint kinds (model row order: primitive kinds, then user constraints) ------------------
    ckinds: list[CompiledConstraints] = []
    row = 0
    for kind in list(model.kinds) + list(model.user_constraints):
        rec = _compiled_form(kind, layout, model)
        if not isinstance(rec, CompiledConstraints):
            raise NotCompilable(f"model {model.name!r}: constraint {_label(kind)!r} returned {type(rec).__name__} "
                                "from compiled(), expected core.compiled.CompiledConstraints")
        sl = np.asarray(rec.slots)
        if sl.ndim != 2 or sl.shape[0] != rec.rows or not 1 <= sl.shape[1] <= MAX_SLOTS:
            raise NotCompilable(f"model {model.name!r}: constraint {_label(kind)!r}: slots have shape "
                                f"{sl.shape}, expected ({rec.rows}, w) with 1 <= w <= {MAX_SLOTS}")
        if sl.shape[1] < MAX_SLOTS:  # a kind that uses fewer slots (e.g. written when MAX_SLOTS was 3)
            rec.slots = np.hstack([sl, np.full((rec.rows, MAX_SLOTS - sl.shape[1]), -1, sl.dtype)])
        rec._row0 = row  # noqa: SLF001 - bookkeeping of the packer
        row += rec.rows
        ckinds.append(rec)
    m_all = row
    if m_all != len(model._jac_indptr) - 1:
        raise NotCompilable(f"model {model.name!r}: the compiled constraint kinds write {m_all} rows, "
                            f"the model has {len(model._jac_indptr) - 1}")
    r_blk = np.full((m_all, MAX_SLOTS), -1, np.int64)
    for rec in ckinds:
        r_blk[rec._row0:rec._row0 + rec.rows] = rec.slots
    rg_cnt, rg, pad_slots = _group_slots(model, ckinds, r_blk, blk_g, group_blocks, mass_rec)
    # --- blocks and masses ---------------------------------------------------------------------------
    blk_v0 = np.zeros(n_blk, np.int64)
    blk_w = np.zeros(n_blk, np.int64)
    blk_x = np.full(n_blk, -1, np.int64)
    minv = np.zeros((n_blk, 6, 6))
    Mcsr = model._M
    border_mass = []  # mass blocks of the border coordinates (singular or zero)
    nx = 0
    for k, bd in enumerate(model.bodies):
        blk_v0[k], blk_w[k] = k * nvb, nvb
        if blk_g[k] >= 0:  # a mass group's block: inverted with its group at every evaluation
            continue
        blk = Mcsr[k * nvb:(k + 1) * nvb, k * nvb:(k + 1) * nvb].toarray()
        if k in flex_blocks:
            blk = flex_blocks[k]["mass_block"]
        if not np.all(np.isfinite(blk)):
            raise NotCompilable(f"model {model.name!r}: body {bd.name!r} has a non-finite mass matrix")
        if np.all(np.linalg.eigvalsh(0.5 * (blk + blk.T)) > 1e-14 * max(1.0, float(np.max(np.abs(blk))))):
            minv[k, :nvb, :nvb] = np.linalg.inv(blk)
        else:  # a singular mass block (zero inertia): its coordinates join the border
            blk_x[k] = nx
            nx += nvb
            border_mass.append(blk)
    blk_v0[nb] = -1  # the ground
    for k in range(ne):
        b = nb + 1 + k
        blk_v0[b], blk_w[b] = nb * nvb + k, 1
        if blk_g[b] >= 0:
            continue
        mass = flex_extra_mass.get(k, float(Mcsr[nb * nvb + k, nb * nvb + k]))
        if mass > 0:
            minv[b, 0, 0] = 1.0 / mass
        else:
            blk_x[b] = nx
            nx += 1
            border_mass.append(np.array([[mass]]))
    xm = np.zeros((max(nx, 1), max(nx, 1)))
    o = 0
    for blk in border_mass:
        w_ = blk.shape[0]
        xm[o:o + w_, o:o + w_] = blk
        o += w_
    # --- active, regular and E rows; Schur pattern and RCM order -------------------------------------
    act = np.arange(m_all) if model._active_rows is None else np.asarray(model._active_rows, np.int64)
    massive = (blk_w > 0) & (blk_x < 0)
    reg_rows, ext_rows = [], []
    for a in act:
        blocks = [int(b) for b in r_blk[a] if b >= 0]
        if any(massive[b] for b in blocks):
            reg_rows.append(int(a))
        elif blocks:
            ext_rows.append(int(a))
        else:
            raise NotCompilable(f"model {model.name!r}: constraint row {int(a)} touches no coordinate")
    if nx and reg_rows:
        reg_rows, ext_rows = _independent_rows(model, ckinds, reg_rows, ext_rows, r_blk, blk_x, blk_v0, blk_w,
                                               massive)
    touching: dict[int, list[tuple[int, int]]] = {}
    for ka, a in enumerate(reg_rows):
        for slot in range(MAX_SLOTS):
            b = int(r_blk[a, slot])
            if b >= 0 and massive[b]:
                touching.setdefault(b, []).append((ka, slot))
    pairs = [(ka, sa, kb, sb) for lst in touching.values() for (ka, sa) in lst for (kb, sb) in lst]
    m_r = len(reg_rows)
    if m_r:
        pr = np.array([p[0] for p in pairs] + list(range(m_r)), np.int64)
        pc = np.array([p[2] for p in pairs] + list(range(m_r)), np.int64)
        pattern = sp.csr_matrix((np.ones(len(pr)), (pr, pc)), shape=(m_r, m_r))
        order = np.asarray(reverse_cuthill_mckee(pattern, symmetric_mode=True), np.int64)
    else:
        order = np.zeros(0, np.int64)
    pos = np.empty(m_r, np.int64)
    pos[order] = np.arange(m_r)
    keep = [(ka, sa, kb, sb) for (ka, sa, kb, sb) in pairs if pos[ka] >= pos[kb]]
    reg_arr = np.asarray(reg_rows, np.int64)
    pat = np.array([(reg_arr[ka], sa, reg_arr[kb], sb, pos[ka], pos[kb], blk_w[r_blk[reg_arr[ka], sa]])
                    for (ka, sa, kb, sb) in keep], np.int64).reshape(-1, 7)
    env_first = np.arange(m_r, dtype=np.int64)
    for i, j in zip(pat[:, 4], pat[:, 5]):
        env_first[i] = min(env_first[i], j)
    reg_sorted = reg_arr[order] if m_r else reg_arr  # regular rows in factorisation order
    ext_arr = np.asarray(ext_rows, np.int64)
    # couplings through blocks with mass of E rows with regular rows (H) and among themselves (S_EE)
    e_touch: dict[int, list[tuple[int, int]]] = {}
    for e, a in enumerate(ext_arr):
        for slot in range(MAX_SLOTS):
            b = int(r_blk[a, slot])
            if b >= 0 and massive[b]:
                e_touch.setdefault(b, []).append((e, slot))
    hpat = np.array([(reg_arr[ka], sa, int(ext_arr[e]), se, pos[ka], e, blk_w[b])
                     for b, lst in e_touch.items() for (e, se) in lst for (ka, sa) in touching.get(b, [])],
                    np.int64).reshape(-1, 7)
    epat = np.array([(int(ext_arr[e1]), s1, int(ext_arr[e2]), s2, e1, e2, blk_w[b])
                     for b, lst in e_touch.items() for (e1, s1) in lst for (e2, s2) in lst], np.int64).reshape(-1, 7)
    # compact tables of the blocks with mass, per row and overall (no branches on the hot path)
    rs_cnt = np.zeros(m_all, np.int64)
    rs = np.zeros((m_all, MAX_SLOTS, 4), np.int64)  # (slot, block, first velocity index, width)
    for a in range(m_all):
        for slot in range(MAX_SLOTS):
            b = int(r_blk[a, slot])
            if b >= 0 and massive[b]:
                rs[a, rs_cnt[a]] = (slot, b, blk_v0[b], blk_w[b])
                rs_cnt[a] += 1
    mass_blocks = np.flatnonzero(massive & (blk_g < 0)).astype(np.int64)  # blocks with a constant inverse
    wg = max([len(g) for g in groups], default=1)
    grp_v = np.zeros((max(len(groups), 1), wg), np.int64)
    grp_w = np.zeros(max(len(groups), 1), np.int64)
    for g, vi in enumerate(groups):
        grp_v[g, :len(vi)] = vi
        grp_w[g] = len(vi)
    # --- forces ----------------------------------------------------------------------------------------
    fkinds: list[CompiledForces] = []
    for fk in model.force_kinds:
        rec = _compiled_form(fk, layout, model)
        if not isinstance(rec, CompiledForces):
            raise NotCompilable(f"model {model.name!r}: force element {fk.names[0]!r} returned {type(rec).__name__} "
                                "from compiled(), expected core.compiled.CompiledForces")
        fkinds.append(rec)
    if flex_rows:
        from ..flexible.compiled import modal_force_record

        fkinds.append(modal_force_record(flex_rows, [f.data.name for f in model.flexible
                                                      if f.body in flex_blocks]))
    if mass_rec is not None:
        fkinds.append(inertia_forces)
    if len(ckinds) > KIND_CAPACITY or len(fkinds) > KIND_CAPACITY:
        raise NotCompilable(f"model {model.name!r} has {len(ckinds)} constraint and {len(fkinds)} force kinds; "
                            f"the compiled path takes at most {KIND_CAPACITY} of each")
    Qg = np.asarray(model._Qg, float).copy()
    Jt = np.zeros((nb + 1, 3, 3))
    if dim == 3 and nb:
        Jt[:nb] = model._J
    for k, fb in flex_blocks.items():  # the flexible bodies' rigid part: inertia and weight
        if dim == 3:
            Jt[k] = fb["inertia"]
        Qg[k * nvb:k * nvb + dim] += fb["weight"] * np.asarray(model.gravity, float)
    lay = np.array([nb, dim, sp_.n_q, nvb, model.n_q, model.n_v, ne], np.int64)
    fields = dict(lay=lay, blk_v0=blk_v0, blk_w=blk_w, blk_x=blk_x, minv=minv, Qg=Qg, Jt=Jt, r_blk=r_blk,
                  act=np.asarray(act, np.int64), reg=np.ascontiguousarray(reg_sorted), ext=ext_arr,
                  pat=np.ascontiguousarray(pat), env_first=env_first, rs_cnt=rs_cnt, rs=rs, mass_blocks=mass_blocks,
                  n_x=np.int64(nx), xm=xm, hpat=np.ascontiguousarray(hpat), epat=np.ascontiguousarray(epat),
                  n_grp=np.int64(len(groups)), blk_g=blk_g, blk_go=blk_go, grp_v=grp_v, grp_w=grp_w, rg_cnt=rg_cnt,
                  rg=rg, pad_slots=pad_slots)
    kernel_fields, states = _kernel_tuples(ckinds, fkinds, mass_rec)
    fields.update(kernel_fields)
    fields.update(zip(("frc_ncol", "frc_col", "frc_reach"), fd_colouring(fkinds, nb)))
    return CompiledModel(model, fields, ckinds, fkinds, states, mass_rec)


def _independent_rows(model, ckinds, reg_rows, ext_rows, r_blk, blk_x, blk_v0, blk_w, massive):
    """With border coordinates, more rows may touch the blocks with mass than those blocks have
    freedoms: keep an independent set as the regular rows and move the rest to E (module docstring).

    The set must stay independent as the model moves, not only at the initial configuration (a row
    pair on a turning body is independent at most angles and dependent at some), so rows are taken
    greedily in an order that makes that likely: rows touching no border coordinate first
    (independent at every configuration: the model's rows are), then rows touching border
    coordinates; rows of kinds that prefer the border (``CompiledConstraints.border``: a flexible
    body's node frames, which fix massless node bodies) go to E at once.  A row joins R when it
    adds to the rank of the rows taken, restricted to the blocks with mass, at the initial
    configuration (Gram–Schmidt, relative tolerance 1e-9).  Returns ``(reg_rows, ext_rows)``.
    """
    J = model._Phi_q_all(0.0, model.q0).toarray()
    cols = np.concatenate([np.arange(blk_v0[b], blk_v0[b] + blk_w[b]) for b in np.flatnonzero(massive)])
    prefer_e = np.zeros(r_blk.shape[0], bool)
    for rec in ckinds:
        if getattr(rec, "border", False):
            prefer_e[rec._row0:rec._row0 + rec.rows] = True
    on_border = [any(blk_x[b] >= 0 for b in r_blk[a] if b >= 0) for a in range(r_blk.shape[0])]
    order = sorted((a for a in reg_rows if not prefer_e[a]), key=lambda a: (on_border[a], a))
    basis: list[np.ndarray] = []
    keep_rows, moved = [], [a for a in reg_rows if prefer_e[a]]
    for a in order:
        r = J[a, cols].copy()
        nrm = float(np.linalg.norm(r))
        for _ in range(2):  # Gram–Schmidt, repeated once for orthogonality in floating point
            for e in basis:
                r -= (e @ r) * e
        res = float(np.linalg.norm(r))
        if nrm > 0.0 and res > 1e-9 * nrm:
            basis.append(r / res)
            keep_rows.append(a)
        else:
            moved.append(a)
    return sorted(keep_rows), sorted(ext_rows + moved)


def _mass_groups(model, mass_rec, nb: int, nvb: int, ne: int):
    """The blocks of each mass group, from its velocity indices (whole blocks, checked):
    ``(blk_g, blk_go, groups, group_blocks)`` — each block's group (−1: none) and first position in
    it, each group's velocity indices and block list."""
    n_blk = nb + 1 + ne
    blk_g = np.full(n_blk, -1, np.int64)
    blk_go = np.zeros(n_blk, np.int64)
    groups = [] if mass_rec is None else [np.asarray(g, np.int64) for g in mass_rec.groups]
    group_blocks: list[list[int]] = []
    for g, vi in enumerate(groups):
        blocks, o = [], 0
        while o < len(vi):
            j = int(vi[o])
            b, w_ = (j // nvb, nvb) if j < nb * nvb else (nb + 1 + j - nb * nvb, 1)
            start = j if b > nb else b * nvb
            if j != start or not np.array_equal(vi[o:o + w_], np.arange(start, start + w_)) or blk_g[b] >= 0:
                raise NotCompilable(f"model {model.name!r}: {mass_rec.what} {mass_rec.names[g]!r}: its velocity "
                                    "indices are not whole blocks, or overlap another group")
            blk_g[b], blk_go[b] = g, o
            blocks.append(b)
            o += w_
        group_blocks.append(blocks)
    return blk_g, blk_go, groups, group_blocks


def _group_slots(model, ckinds, r_blk: np.ndarray, blk_g: np.ndarray, group_blocks, mass_rec):
    """Give every row touching a block of a mass group a slot on every block of the group (protocol,
    "Mass groups"), filled into ``r_blk`` from the last free slot down (:func:`core.compiled.dynamics.
    constraints` zeroes their entries).  Returns ``(rg_cnt, rg, pad_slots)``: the groups of each row
    and the (row, slot) pairs added; :class:`NotCompilable` naming the element when a row runs out
    of slots."""
    m_all = r_blk.shape[0]
    pad = []
    rg_cnt = np.zeros(m_all, np.int64)
    rg = np.full((m_all, MAX_SLOTS), -1, np.int64)
    if not group_blocks:
        return rg_cnt, rg, np.zeros((0, 2), np.int64)
    for rec in ckinds:
        for i in range(rec.rows):
            a = rec._row0 + i
            for g in sorted({int(blk_g[b]) for b in r_blk[a] if b >= 0 and blk_g[b] >= 0}):
                rg[a, rg_cnt[a]] = g
                rg_cnt[a] += 1
                for b in group_blocks[g]:
                    if b in r_blk[a]:
                        continue
                    free = np.flatnonzero(r_blk[a] < 0)
                    if free.size == 0:
                        element = rec.names[i * len(rec.names) // rec.rows]  # rows are in element order
                        raise NotCompilable(
                            f"model {model.name!r}: {rec.what} {element!r} touches {mass_rec.what} "
                            f"{mass_rec.names[g]!r}, whose mass matrix couples its frame with its "
                            f"{len(group_blocks[g]) - 1} modal coordinates: a row then touches more than "
                            f"{MAX_SLOTS} blocks; keep fewer modes or use the numpy integrators")
                    r_blk[a, free[-1]] = b
                    pad.append((a, int(free[-1])))
    return rg_cnt, rg, np.array(pad, np.int64).reshape(-1, 2)


def _label(kind) -> str:
    labels = getattr(kind, "labels", None)
    if labels:
        return labels[0]
    return getattr(kind, "name", type(kind).__name__)


def _compiled_form(kind, layout, model):
    fn = getattr(kind, "compiled", None)
    if fn is None:
        names = getattr(kind, "names", None) or getattr(kind, "labels", None) or [getattr(kind, "name", "?")]
        raise NotCompilable(f"model {model.name!r}: element {names[0]!r} ({type(kind).__name__}) has no compiled kernel")
    try:
        return fn(layout)
    except NotCompilable as exc:
        raise NotCompilable(f"model {model.name!r}: {exc}") from None


def _i2(a) -> np.ndarray:
    a = np.asarray(a, np.int64)
    return np.ascontiguousarray(a.reshape(a.shape[0], -1) if a.ndim else a.reshape(1, 1))


def _f2(a) -> np.ndarray:
    a = np.asarray(a, float)
    return np.ascontiguousarray(a.reshape(a.shape[0], -1) if a.ndim else a.reshape(1, 1))


def _stack(blocks: list[np.ndarray], dtype) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Blocks stored flat, one after the other: (flat, offsets, rows, widths); block k is
    ``flat[off[k]:off[k+1]].reshape(rows[k], widths[k])`` (C-contiguous)."""
    off = np.zeros(len(blocks) + 1, np.int64)
    for k, b in enumerate(blocks):
        off[k + 1] = off[k] + b.size
    flat = np.zeros(max(int(off[-1]), 1), dtype)
    for k, b in enumerate(blocks):
        flat[off[k]:off[k + 1]] = np.ascontiguousarray(b, dtype).ravel()
    rows = np.array([b.shape[0] for b in blocks] + [0], np.int64)
    widths = np.array([b.shape[1] for b in blocks] + [0], np.int64)
    return flat, off, rows, widths


def fd_colouring(fkinds, nb: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Column grouping of each force kind's difference Jacobian from its body groups
    (:attr:`~core.compiled.protocol.CompiledForces.groups`).

    The rows a perturbation of body ``b`` reaches are the bodies of every group holding ``b``;
    two bodies whose reaches do not meet can be perturbed in one evaluation (Curtis, Powell & Reid
    1974), assigned greedily in body order.  Returns ``ncol`` (KIND_CAPACITY,): the number of
    colours, −1 for a kind without groups (every column on its own); ``col`` (KIND_CAPACITY, nb):
    the colour of each body's columns, −1 for a body the kind does not read; ``reach``
    (KIND_CAPACITY, nb, nb): 1 where a perturbation of body ``b`` (second index) reaches the forces
    on body ``r`` (third).
    """
    n = max(nb, 1)
    ncol = np.full(KIND_CAPACITY, -1, np.int64)
    col = np.full((KIND_CAPACITY, n), -1, np.int64)
    reach = np.zeros((KIND_CAPACITY, n, n), np.int64)
    for k, rec in enumerate(fkinds):
        if rec.groups is None:
            continue
        hits = [set() for _ in range(nb)]
        for g in rec.groups:
            if np.ndim(g) != 1:
                raise ValueError(f"{rec.what} {rec.names[0]!r}: each body group must be a sequence of body "
                                 f"indices, got {g!r} (groups=[[0, 1], [2]], not [0, 1, 2])")
            bodies = [int(b) for b in np.asarray(g, np.int64)]
            bad = [b for b in bodies if not 0 <= b <= nb]
            if bad:
                raise ValueError(f"{rec.what} {rec.names[0]!r}: body group {list(bodies)} names bodies {bad} "
                                 f"outside 0..{nb} (the layout's bodies and the ground)")
            bodies = [b for b in bodies if b < nb]
            for b in bodies:
                hits[b].update(bodies)
        used: list[set] = []
        for b in range(nb):
            if not hits[b]:
                continue
            c = next((i for i, u in enumerate(used) if not u & hits[b]), len(used))
            if c == len(used):
                used.append(set())
            used[c] |= hits[b]
            col[k, b] = c
            reach[k, b, sorted(hits[b])] = 1
        ncol[k] = len(used)
    return ncol, col, reach


def _kernel_tuples(ckinds, fkinds, mass_rec: CompiledMass | None = None) -> tuple[dict, np.ndarray]:
    cap = KIND_CAPACITY

    def res(k, role, sig, owner):
        return resolve_kernel(k, role, sig, owner)

    def pad(items, noop):
        return tuple(items) + (noop.dispatcher,) * (cap - len(items))

    con = pad([res(r.kernel, "constraint", CONSTRAINT_SIGNATURE, f"{r.what} {r.names[0]!r}") for r in ckinds],
              _no_constraints)
    con_fd, con_fo, con_n, con_fw = _stack([_f2(r.fd) for r in ckinds], float)
    con_ix, con_io, _, con_iw = _stack([_i2(r.ix) for r in ckinds], np.int64)
    con_row0 = np.array([r._row0 for r in ckinds] + [0], np.int64)
    frc = pad([res(r.forces, "force", FORCE_SIGNATURE, f"{r.what} {r.names[0]!r}") for r in fkinds], _no_forces)
    frc_fd, frc_fo, frc_n, frc_fw = _stack([_f2(r.fd) for r in fkinds], float)
    frc_ix, frc_io, _, frc_iw = _stack([_i2(r.ix) for r in fkinds], np.int64)
    frc_jac = pad([_no_jacobian.dispatcher if r.jacobian is None else
                   res(r.jacobian, "force Jacobian", FORCE_JACOBIAN_SIGNATURE, f"{r.what} {r.names[0]!r}")
                   for r in fkinds], _no_jacobian)
    frc_has_jac = np.array([r.jacobian is not None for r in fkinds] + [False], np.int64)
    frc_acc = pad([_no_accept.dispatcher if r.accept is None else
                   res(r.accept, "accept", ACCEPT_SIGNATURE, f"{r.what} {r.names[0]!r}") for r in fkinds], _no_accept)
    frc_stateful = np.array([r.accept is not None for r in fkinds] + [False], np.int64)
    states, st_off, st_n, st_w = _stack([_f2(r.state) if r.state.size else np.zeros((0, 0)) for r in fkinds], float)
    nk = len(fkinds)
    frc_tab = np.zeros((max(nk, 1), FRC_TAB_WIDTH), np.int64)
    for col, vals in ((FT_FD0, frc_fo[:nk]), (FT_FD1, frc_fo[1:nk + 1]), (FT_N, frc_n[:nk]), (FT_FW, frc_fw[:nk]),
                      (FT_IX0, frc_io[:nk]), (FT_IX1, frc_io[1:nk + 1]), (FT_IW, frc_iw[:nk]),
                      (FT_ST0, st_off[:nk]), (FT_ST1, st_off[1:nk + 1]), (FT_STN, st_n[:nk]), (FT_STW, st_w[:nk])):
        frc_tab[:nk, col] = vals
    fields = dict(n_con=len(ckinds), con=con, con_fd=con_fd, con_fo=con_fo, con_n=con_n, con_fw=con_fw,
                  con_ix=con_ix, con_io=con_io, con_iw=con_iw, con_row0=con_row0,
                  n_frc=len(fkinds), frc=frc, frc_fd=frc_fd, frc_fo=frc_fo, frc_n=frc_n, frc_fw=frc_fw,
                  frc_ix=frc_ix, frc_io=frc_io, frc_iw=frc_iw, frc_tab=frc_tab, frc_jac=frc_jac, frc_has_jac=frc_has_jac,
                  frc_acc=frc_acc, frc_stateful=frc_stateful, st_off=st_off, st_n=st_n, st_w=st_w)
    if mass_rec is None:
        fields.update(mass_k=(_no_mass.dispatcher,), mass_fd=np.zeros((1, 1)), mass_ix=np.zeros((1, 1), np.int64))
    else:
        fields.update(mass_k=(res(mass_rec.kernel, "mass", MASS_SIGNATURE, f"{mass_rec.what} {mass_rec.names[0]!r}"),),
                      mass_fd=_f2(mass_rec.fd), mass_ix=_i2(mass_rec.ix))
    return fields, states


def numpy_refusal(system, t, q, v) -> str:
    """The message of the refusal the numpy path raises at ``(t, q, v)`` ('' if it evaluates).

    A force kernel that refuses a state without recording why (``ELEMENT_FAILED``, e.g. a
    rolling speed below a creep law's limit) leaves only a status code; the compiled
    integrators then evaluate the numpy elements at the failing state (stateful kinds' search
    state reset there by ``system.begin_run``) and pass on the element's own message, so both
    paths end with the same words.  A failure path: one numpy evaluation per failed run.
    """
    from ..errors import RUN_FAILURES, MbsuiteError

    try:
        system.begin_run(float(t), np.asarray(q, float), np.asarray(v, float))
        system.Q(float(t), np.asarray(q, float), np.asarray(v, float))
    except (MbsuiteError, ValueError, *RUN_FAILURES) as exc:  # the refusal's own words
        return str(exc)
    return ""


def status_message(cm, system, err, states, code, state=None) -> str:
    """The failure of a kernel status code in the words of the element that reported it.

    The kind's ``describe_failure`` of its state rows; failing that, for ``ELEMENT_FAILED``,
    the refusal of the numpy element at ``state = (t, y)`` or at the first of several candidate
    states ``(ts, ys)`` that draws one (:func:`numpy_refusal`); failing both, the generic status
    text after the element's name.  ``err`` is the workspace's error record (element index, row,
    family 1 = force, 2 = constraint); shared by the compiled explicit and implicit integrators.
    """
    from . import protocol as _p

    why = _p.STATUS_MESSAGES.get(code, f"kernel status {code}")
    if code == _p.MASS_NOT_PD and err[2] == 3:
        return f"{cm.element_name('mass', int(err[0]), 0)}: {why}"
    if code in (_p.SINGULAR, _p.NONFINITE, _p.PROJECTION) or err[2] not in (1, 2):
        return why
    family = "force" if err[2] == 1 else "constraint"
    element = cm.element_name(family, int(err[0]), int(err[1]))
    why = f"{element}: {why}"
    if err[2] != 1:
        return why
    more = cm.failure_description(int(err[0]), states)
    if not more and code == _p.ELEMENT_FAILED and state is not None:
        # the kernel kept no words: the numpy element's own refusal at that state
        nq = system.n_q
        for t_s, y_s in ([state] if np.ndim(state[0]) == 0 else zip(*state)):
            more = numpy_refusal(system, t_s, y_s[:nq], y_s[nq:])
            if more:
                break
        if more and element in more:
            return more
    return f"{element}: {more}" if more else why
