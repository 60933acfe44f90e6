r"""The flexible car body: a free–free equivalent beam on the core's flexible bodies.

A vehicle file's ``[car_body.flexible]`` table (:mod:`railway.vehicles.vehicle_file`) makes the car
body a :mod:`core.flexible` body: a floating frame at the centre of mass with the car body's mass
and inertia, plus the free–free modes it names — first vertical bending, and optionally first
torsion and first lateral bending — with their frequencies as the file gives them (from the
car body maker's FE model or a modal test).  This is the car-body model of ride-comfort studies
that represent the body by its lowest flexible modes (Carlbom, *Carbody and Passengers in Rail
Vehicle Dynamics*, KTH 2000; Zhou, Goodall, Ren, Zhang, "Influences of car body vertical
flexibility on ride quality of passenger railway vehicles", Proc. IMechE F 223 (2009) 461–471:
a uniform free–free Euler–Bernoulli beam).

The equivalent beam
-------------------
A straight beam of the file's ``length`` along the body x axis, centred on the centre of mass,
with uniform mass per length and uniform distributed rotary inertias chosen so that its rigid
body is exactly the file's (:math:`m`, :math:`I_{xx}, I_{yy}, I_{zz}` about the centre of mass):

.. math::

    \rho A = \frac mL,\qquad \rho I_p = \frac{I_{xx}}L,\qquad
    \rho I_y = \frac{I_{yy} - mL^2/12}L,\qquad \rho I_z = \frac{I_{zz} - mL^2/12}L

(a consistent mass matrix reproduces the rigid-body kinetic energy exactly, so the FE body's
inertia is the file's to round-off; a pitch or yaw inertia below the uniform beam's
:math:`mL^2/12` cannot be matched and is refused, naming the longest length that fits).  Bending
is the Rayleigh beam — Euler–Bernoulli bending with rotary inertia — realised as Timoshenko
elements (:mod:`core.flexible.beam`) with a shear stiffness so large that
:math:`\Phi = 12EI/(\kappa GA\ell^2) < 10^{-6}`.  The bending stiffnesses :math:`EI_y` (vertical),
:math:`EI_z` (lateral) and the torsional stiffness :math:`GJ` are set so that the FE beam's lowest
mode of each family has the file's frequency: within a family :math:`\omega^2` is proportional
to the stiffness (the mass is fixed), so one scaling of the closed-form first guess
(:math:`EI = \rho A\,(2\pi f L^2/4.73004^2)^2`, :math:`GJ = \rho I_p (2 L f)^2`; free–free
beam and bar) makes it exact; the result is checked to 1e-10.  A family the file does not name
gets the closed-form stiffness of ten times the largest given frequency and is not kept as a
mode; the axial bar likewise.

Modes, frame and attachments
----------------------------
The modes are the beam's free–free modes, orthonormalised with the rigid-body modes removed
(mean axes; :meth:`core.flexible.ModalComponent.orthonormalized`), so the body is built with
``inertia="undeformed"``: a rigid body plus one oscillator per mode, coupled through the node
frames (:mod:`core.flexible.body`), which the compiled integrators run.  The mesh has nodes at
the car-body centre and at both bogie centres; the secondary suspension, anti-roll bars, bump
stops and yaw dampers attach to the node frames over the bogie centres at their file offsets
(a rigid lever from the beam axis), and the ride-comfort floor points are read at the three
nodes (:func:`railway.comfort`).

An imported FE model
--------------------
The table may instead name the car body maker's FE model (:func:`imported_car_body`): mass and
stiffness in Matrix Market files, nodes in a CSV, read by :meth:`core.flexible.FEModel.read` with
their units.  Its nodes are moved so that the centre of mass (from the mass matrix) is the origin;
its lowest free–free elastic modes are kept (mean axes, so the same undeformed-inertia body and the
compiled integrators apply), and the node frames go on the three nodes the table names.  Its mass
and inertias must agree with the file's ``[car_body]`` (1 % and 5 %): the two describe one body,
and a disagreement is a unit slip or a wrong file far more often than a modelling choice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from core.errors import InputError

__all__ = ["CarBodyBeam", "FAMILIES", "ImportedCarBody", "car_body_beam", "imported_car_body"]

#: Mode families of the beam, in the order the file names them, with the node dof indices that
#: carry their kinetic energy (u_x, u_y, u_z, θ_x, θ_y, θ_z)
FAMILIES = {"vertical bending": (2, 4), "torsion": (3,), "lateral bending": (1, 5), "axial": (0,)}
_FREE_FREE_BENDING = 4.730040744862704  # β₁L of a free–free beam, cos βL cosh βL = 1
_SHEAR_RIGID = 1e-6


@dataclass(frozen=True)
class CarBodyBeam:
    """The equivalent beam of a flexible car body.

    Attributes
    ----------
    fe : core.flexible.FEModel
    modes : core.flexible.ModalComponent
        The kept free–free modes (mass-normalised), labelled by family.
    stations : dict of float to int
        Node index of each station x [m] (car-body centre 0, bogie centres ±L_b).
    frequencies : dict of str to float
        Frequency [Hz] of each kept mode, by family.
    stiffness : dict of str to float
        EI_y, EI_z [N m²] and GJ [N m²/rad] of the beam.
    """

    fe: object
    modes: object
    stations: dict
    frequencies: dict
    stiffness: dict


def _mesh_nodes(length, stations, n_elements):
    """x of the nodes: every station a node, elements of about length / n_elements."""
    cuts = np.unique(np.concatenate([[-length / 2, length / 2], stations]))
    xs = [cuts[:1]]
    for a, b in zip(cuts[:-1], cuts[1:]):
        k = max(1, int(round((b - a) / length * n_elements)))
        xs.append(np.linspace(a, b, k + 1)[1:])
    return np.concatenate(xs)


def _sections(m, J, L, EIy, EIz, GJ, EA, GA):
    """The mass section (ρ = 1: A = ρA, I = ρI) and the stiffness section (E = 1: A = EA, I = EI,
    G = GA / EA, J = GJ / G)."""
    from core.flexible import BeamSection

    acc = ("E", "G", "rho", "A", "I")
    rot_y = (J[1] - m * L**2 / 12.0) / L
    rot_z = (J[2] - m * L**2 / 12.0) / L
    mass = BeamSection(E=1.0, rho=1.0, A=m / L, Iz=max(rot_z, 0.0), Iy=max(rot_y, 0.0), G=1e12, J=1.0,
                       Ip=J[0] / L, accept=acc)
    G = GA / EA
    stiff = BeamSection(E=1.0, rho=1.0, A=EA, Iz=EIz, Iy=EIy, G=G, J=GJ / G, Ip=1.0, accept=acc, shear_factor=1.0)
    return mass, stiff


def car_body_beam(mass, inertia, length, stations, vertical_bending, torsion=None, lateral_bending=None,
                  n_elements=24, where="car body") -> CarBodyBeam:
    """The equivalent beam of a flexible car body (module docstring).

    Parameters
    ----------
    mass : float
        [kg]
    inertia : (3,) array_like
        Roll, pitch, yaw inertia about the centre of mass [kg m²].
    length : float
        Length of the body [m]; the beam spans ±length/2 about the centre of mass.
    stations : array_like
        x [m] that must be nodes (bogie centres, floor measuring points).
    vertical_bending, torsion, lateral_bending : float or None
        Free–free frequencies [Hz] of the first mode of each family (None: not kept).
    n_elements : int
        About this many elements over the length.
    where : str
        Names the input in messages.

    Raises
    ------
    core.errors.InputError
        A pitch or yaw inertia below that of the uniform beam, a station outside the body, no
        frequency given.
    """
    from scipy.sparse import csr_matrix

    from core.flexible import BeamMesh, FEModel, free_interface
    from core.flexible.beam import beam_matrices
    from core.flexible.reduction import ModalComponent

    m, J, L = float(mass), np.asarray(inertia, float), float(length)
    st = np.asarray(stations, float)
    if np.any(np.abs(st) > L / 2):
        raise InputError(f"{where}: length {L:g} m does not reach the station at x = {st[np.argmax(np.abs(st))]:g} m "
                         f"(the bogie centres lie within the car body: length > {2 * np.max(np.abs(st)):g} m)")
    for k, axis in ((1, "pitch"), (2, "yaw")):
        if J[k] < m * L**2 / 12.0 * (1 - 1e-12):
            raise InputError(f"{where}: the {axis} inertia {J[k]:.4g} kg m² is below that of a uniform beam of the "
                             f"car body's mass over length {L:g} m (m L²/12 = {m * L**2 / 12:.4g} kg m²): the mass "
                             f"cannot be spread over that length; give a length of at most "
                             f"{np.sqrt(12 * J[k] / m):.4g} m or check the inertia")
    wanted = {"vertical bending": vertical_bending, "torsion": torsion, "lateral bending": lateral_bending}
    given = {k: float(v) for k, v in wanted.items() if v is not None}
    if "vertical bending" not in given:
        raise InputError(f"{where}: a flexible car body needs its first vertical bending frequency")
    f_high = 10.0 * max(given.values())
    target = {k: given.get(k, f_high) for k in wanted}
    rhoA, rhoIp = m / L, J[0] / L
    EI0 = lambda f: rhoA * (2 * np.pi * f * L**2 / _FREE_FREE_BENDING**2) ** 2  # noqa: E731
    stiffness = {"EI_y": EI0(target["vertical bending"]), "EI_z": EI0(target["lateral bending"]),
                 "GJ": rhoIp * (2.0 * L * target["torsion"]) ** 2}
    EA = rhoA * (2.0 * L * f_high) ** 2  # the axial bar's first free–free mode at f_high
    x = _mesh_nodes(L, st, n_elements)
    nodes = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    n_el = len(x) - 1
    mesh = BeamMesh(nodes, np.column_stack([np.arange(n_el), np.arange(1, n_el + 1)]), orientation=(0.0, 1.0, 0.0))
    ell = float(np.min(np.diff(x)))
    key = {"vertical bending": "EI_y", "lateral bending": "EI_z", "torsion": "GJ"}
    for _ in range(3):
        # shear stiffness GA so large that Φ = 12 EI / (κ G A ℓ²) < _SHEAR_RIGID on the shortest element
        GA = max(stiffness["EI_y"], stiffness["EI_z"]) * 12.0 / (_SHEAR_RIGID * ell**2)
        mass_sec, stiff_sec = _sections(m, J, L, stiffness["EI_y"], stiffness["EI_z"], stiffness["GJ"], EA, GA)
        M, _ = beam_matrices(mesh, mass_sec, "timoshenko")
        _, K = beam_matrices(mesh, stiff_sec, "timoshenko")
        M, K = csr_matrix(M), csr_matrix(K)
        comp = free_interface(M, K, nodes, 6, 8).orthonormalized(drop_rigid=True)
        T = comp.T
        f = np.sqrt(np.clip(np.diag(comp.K), 0.0, None)) / (2 * np.pi)
        MT = M @ T
        energy = np.zeros((4, T.shape[1]))
        for i, (fam, dofs) in enumerate(FAMILIES.items()):
            idx = np.concatenate([np.arange(d, T.shape[0], 6) for d in dofs])
            energy[i] = np.einsum("ij,ij->j", T[idx], MT[idx])
        family = [list(FAMILIES)[i] for i in np.argmax(energy, axis=0)]
        first = {}
        for j in np.argsort(f):
            first.setdefault(family[j], j)
        missing = [k for k in given if k not in first]
        if missing:  # pragma: no cover - eight modes always hold the three families below 10 f_max
            raise InputError(f"{where}: no {missing[0]} mode among the beam's lowest eight")
        err = {k: f[first[k]] / target[k] - 1.0 for k in given}
        if max(abs(e) for e in err.values()) < 1e-10:
            break
        for k, e in err.items():
            stiffness[key[k]] /= (1.0 + e) ** 2
    else:  # pragma: no cover - the scaling is exact up to the shear term
        raise InputError(f"{where}: the equivalent beam's frequencies did not match the file's ({err})")
    keep = [first[k] for k in wanted if k in given]
    Tk = T[:, keep]
    modes = ModalComponent(Tk, np.eye(len(keep)), np.diag((2 * np.pi * f[keep]) ** 2),
                           tuple(f"first {k}" for k in wanted if k in given), np.zeros(0), np.zeros(0, np.int64),
                           "free-free modes of the equivalent beam, orthonormalised")
    fe = FEModel(nodes, 6, M, K, f"equivalent beam of the {where}, {n_el} Rayleigh elements", None,
                 (mesh, stiff_sec, "timoshenko"))
    stations_idx = {float(s): int(np.argmin(np.abs(x - s))) for s in st}
    return CarBodyBeam(fe, modes, stations_idx, {k: float(f[first[k]]) for k in given}, dict(stiffness))


@dataclass(frozen=True)
class ImportedCarBody:
    """A flexible car body from an FE model exported by another code (:func:`imported_car_body`).

    Attributes
    ----------
    fe : core.flexible.FEModel
        The component, its nodes moved so that the origin is its centre of mass.
    modes : core.flexible.ModalComponent
        The lowest free–free elastic modes (mass-normalised, mean axes).
    stations : dict of str to int
        Node index of the car-body centre and of the nodes over bogie 1 and bogie 2.
    frequencies : dict of str to float
        Frequency [Hz] of each kept mode (``"mode 1"`` …).
    mass : float
        [kg] of the FE model.
    inertia : (3,) ndarray
        Roll, pitch, yaw inertia about its centre of mass [kg m²].
    centre_of_mass : (3,) ndarray
        Where the centre of mass lay in the file's coordinates [m].
    """

    fe: object
    modes: object
    stations: dict
    frequencies: dict
    mass: float
    inertia: np.ndarray
    centre_of_mass: np.ndarray


#: how far the mass and the inertias of an imported car body may lie from the vehicle file's
#: [car_body] values before the two are refused as contradicting each other
MASS_TOLERANCE, INERTIA_TOLERANCE = 0.01, 0.05
#: how far [m] along the body a node named as over a bogie centre (or the centre) may lie from it
STATION_TOLERANCE = 0.25
#: the most modes of an imported car body: the compiled integrators take up to six
MAX_IMPORTED_MODES = 6
#: plausible first elastic frequency [Hz] of a car body; far outside it the units were likely wrong
FIRST_MODE_RANGE = (1.0, 60.0)


def _rigid_properties(nodes, p, M):
    """Mass, centre of mass and inertia tensor about it of a component with ``p`` dofs per node."""
    N = nodes.shape[0]
    Pt = np.zeros((N * p, 3))
    for k in range(3):
        Pt[k::p, k] = 1.0
    MPt = M @ Pt
    mass = float(np.trace(Pt.T @ MPt) / 3.0)
    x0 = np.zeros(N * p)
    for k in range(3):
        x0[k::p] = nodes[:, k]
    com = (MPt.T @ x0) / mass
    d = nodes - com
    Rot = np.zeros((N * p, 3))
    for k in range(3):
        u = np.cross(np.eye(3)[k], d)  # small rotation about axis k through the centre of mass
        for j in range(3):
            Rot[j::p, k] = u[:, j]
        if p == 6:
            Rot[3 + k::6, k] = 1.0
    J = Rot.T @ (M @ Rot)
    return mass, com, 0.5 * (J + J.T)


def imported_car_body(mass_matrix, stiffness_matrix, nodes, centre_node: int, bogie_nodes, mass, inertia,
                      bogie_centre_semi_distance, n_modes: int = 4, dofs_per_node: int = 6, length_unit="m",
                      mass_unit="kg", force_unit="N", where="car body") -> ImportedCarBody:
    """A flexible car body from an exported FE model: mass and stiffness in Matrix Market files and
    node coordinates in a CSV (:meth:`core.flexible.FEModel.read`, units converted).

    The FE model's axes are the car body's: x forward (towards bogie 1), y to the left, z up; its
    origin may be anywhere (the nodes are moved so that the centre of mass is the origin, the body
    frame of the vehicle).  It must be free (six rigid-body modes).  Its lowest ``n_modes`` elastic
    free–free modes are kept (mean axes, so the compiled integrators take the body), and node
    frames are put on ``centre_node`` and on ``bogie_nodes`` (over bogie 1, over bogie 2): node
    numbers are rows of the node file counting from 0.

    Checked, each refused with the files and values named: the FE model's mass and inertias
    against the vehicle file's ``[car_body]`` (within :data:`MASS_TOLERANCE` and
    :data:`INERTIA_TOLERANCE`: one of the two is wrong, often a unit); the stations' nodes within
    :data:`STATION_TOLERANCE` of x = 0 and x = ±L_b from the centre of mass; the first elastic
    frequency within :data:`FIRST_MODE_RANGE`; at most :data:`MAX_IMPORTED_MODES` modes.
    """
    from core.flexible import FEModel, free_interface

    if not (isinstance(n_modes, (int, np.integer)) and 1 <= n_modes <= MAX_IMPORTED_MODES):
        raise InputError(f"{where}: modes = {n_modes!r}; keep 1 to {MAX_IMPORTED_MODES} elastic modes (the compiled "
                         "integrators take up to six; the lowest few carry the ride-comfort response)")
    if dofs_per_node not in (3, 6):
        raise InputError(f"{where}: dofs_per_node = {dofs_per_node!r}; a spatial car body has 3 (translations) "
                         "or 6 (with rotations) degrees of freedom per node")
    fe = FEModel.read(mass_matrix, stiffness_matrix, nodes, dofs_per_node, length_unit, mass_unit, force_unit)
    X = fe.nodes
    if X.shape[1] != 3:
        raise InputError(f"{where}: node file {nodes} gives {X.shape[1]} coordinates per node; a car body needs "
                         "x, y, z")
    N, p = X.shape[0], fe.dofs_per_node
    picks = [centre_node, *list(bogie_nodes)]
    if len(picks) != 3:
        raise InputError(f"{where}: bogie_nodes must name two nodes (over bogie 1 and over bogie 2), got "
                         f"{list(bogie_nodes)!r}")
    for k in picks:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < N:
            raise InputError(f"{where}: node {k!r} is not a row of node file {nodes} (0 to {N - 1}, counting "
                             "from 0)")
    m_fe, com, Jt = _rigid_properties(X, p, fe.M)
    m, J = float(mass), np.asarray(inertia, float)
    if abs(m_fe / m - 1.0) > MASS_TOLERANCE:
        decades = np.log10(m_fe / m)
        hint = (f" (a mass_unit slip? they differ by a factor of 10^{round(decades)})"
                if round(decades) != 0 and abs(decades - round(decades)) < 0.01 else "")
        raise InputError(f"{where}: the FE model ({mass_matrix}) has a mass of {m_fe:.6g} kg, the vehicle file's "
                         f"[car_body] mass is {m:.6g} kg{hint}; they must agree within {MASS_TOLERANCE:.0%}")
    for k, axis in enumerate(("roll", "pitch", "yaw")):
        if abs(Jt[k, k] / J[k] - 1.0) > INERTIA_TOLERANCE:
            raise InputError(f"{where}: the FE model's {axis} inertia about its centre of mass is "
                             f"{Jt[k, k]:.6g} kg m², the vehicle file's [car_body] inertia {J[k]:.6g} kg m²; they "
                             f"must agree within {INERTIA_TOLERANCE:.0%} (are the FE model's axes x forward, y left, "
                             "z up?)")
    Xc = X - com
    L_b = float(bogie_centre_semi_distance)
    for label, k, x in (("centre_node", centre_node, 0.0), ("bogie_nodes[0] (over bogie 1)", bogie_nodes[0], L_b),
                        ("bogie_nodes[1] (over bogie 2)", bogie_nodes[1], -L_b)):
        if abs(Xc[k, 0] - x) > STATION_TOLERANCE:
            raise InputError(f"{where}: {label} = {k} lies at x = {Xc[k, 0]:.4g} m from the centre of mass, not within "
                             f"{STATION_TOLERANCE:g} m of {x:g} m (bogie 1 is ahead, +x; node numbers count from 0)")
    comp = free_interface(fe.M, fe.K, Xc, p, n_modes)
    if comp.n_rigid != 6:
        raise InputError(f"{where}: the FE model ({stiffness_matrix}) has {comp.n_rigid} rigid-body modes; a free "
                         "car body has six (export it without supports)")
    modes = comp.orthonormalized(drop_rigid=True)
    f = modes.frequencies()
    lo, hi = FIRST_MODE_RANGE
    if not lo <= f[0] <= hi:
        raise InputError(f"{where}: the FE model's first elastic mode is at {f[0]:.4g} Hz, outside {lo:g} to {hi:g} Hz "
                         f"of car bodies; check length_unit, mass_unit and force_unit ({length_unit}, {mass_unit}, "
                         f"{force_unit})")
    fe_c = FEModel(Xc, p, fe.M, fe.K, fe.source)
    stations = {"centre": int(centre_node), "over bogie 1": int(bogie_nodes[0]), "over bogie 2": int(bogie_nodes[1])}
    return ImportedCarBody(fe_c, modes, stations, {f"mode {k + 1}": float(v) for k, v in enumerate(f)}, m_fe,
                           np.diag(Jt).copy(), com)
