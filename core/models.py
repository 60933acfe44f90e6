r"""Canonical models shared by the tests, the documentation and the demo scenes.

Every function returns a built :class:`core.model.Model` with consistent initial positions and
velocities (computed in closed form, no assembly iteration), SI units throughout.  Angles of
pendulum links are *absolute* and measured from the +x axis unless a docstring says otherwise;
gravity acts along −y in planar models and in the spatial variants of planar mechanisms (whose
motion then stays in the x–y plane and must equal the planar one).

=====================================  ====================================================
function                               what it is / source
=====================================  ====================================================
:func:`simple_pendulum`                point mass on a massless link (IFToMM A01) or a
                                       uniform rod (compound pendulum)
:func:`double_pendulum`                two uniform rods
:func:`slider_crank`                   Simeon's slider crank, rigid (test-set parameters)
:func:`four_bar`                       Grashof crank–rocker
:func:`n_link_chain`                   the N-link whip chain of ``core_benchmarks.md`` §1
                                       (planar, spatial, or with point springs for joints)
:func:`body_on_helix`                  a bead on a helix: a :class:`~core.joints.UserConstraint`
                                       with the helix parameter as an extra coordinate
:func:`bouncing_ball`                  a sphere on the ground plane (PlaneContact)
=====================================  ====================================================

Their reference solutions (the chain's minimal-coordinate motion, the equivalent pendulum of
IFToMM A02, ...) are in :mod:`core.benchmarks.references`.

References
----------
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software: problem standardization and performance measurement", Multibody Syst. Dyn. 16 (2006)
179–190; IFToMM library of computational benchmark problems (problems A01–A05).
B. Simeon, "Modelling a flexible slider crank mechanism by a mixed system of DAEs and PDEs",
Math. Modelling of Systems 2 (1996) 1–18; B. Simeon, *Computational Flexible Multibody
Dynamics*, Springer, 2013, Sec. 5.4; F. Mazzia, C. Magherini, *Test Set for IVP Solvers* 2.4
(2008), problem "slider crank" (parameters M1, M2, M3, L1, L2, J1, J2, Ω).
J. E. Shigley, J. J. Uicker, *Theory of Machines and Mechanisms*, McGraw-Hill, 1980, Sec. 1.x
(Grashof's law).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from . import frames
from .compiled.protocol import OK, WANT_GAMMA, WANT_NU, WANT_PHI, CompiledConstraints, body_slot, constraint_kernel
from .drivers import ramp
from .joints import UserConstraint
from .model import Model, ModelBuilder

Array = NDArray[np.float64]
G_EARTH = 9.81

__all__ = [
    "simple_pendulum",
    "double_pendulum",
    "slider_crank",
    "crank_geometry",
    "four_bar",
    "n_link_chain",
    "chain_tip",
    "body_on_helix",
    "bouncing_ball",
    "HelixConstraint",
    "helix_analytic",
    "SLIDER_CRANK_PARAMETERS",
]


# --------------------------------------------------------------------------------------------
# serial chains of links hanging from a pivot at the origin (pendulums, whip chain)
# --------------------------------------------------------------------------------------------


def _check_positive(label: str, value: float) -> float:
    value = float(value)
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{label} must be a positive finite number, got {value}")
    return value


def _serial_chain(name: str, lengths, masses, com, inertia, phi, omega, spatial: bool, gravity: float,
                  axial_inertia=None, springs: tuple[float, float] | None = None) -> Model:
    r"""Links k = 1..n, link k from joint point P_{k−1} to P_k = P_{k−1} + l_k (cos φ_k, sin φ_k).

    ``com[k]`` is the distance of the centre of mass from P_{k−1} along the link, ``inertia[k]``
    the moment about the centre of mass normal to the plane; P_0 = origin is the ground pivot.
    Velocities from the absolute angular rates ``omega``:
    ``ṙ_k = Σ_{j<k} l_j ω_j e⊥_j + com_k ω_k e⊥_k``.  ``springs = (k, c)`` replaces every revolute
    joint by a zero-length point spring of stiffness k [N/m] and damping c [N s/m] (the ground pivot
    included).
    """
    n = len(lengths)
    b = ModelBuilder(3 if spatial else 2, name, gravity=(0.0, -gravity, 0.0) if spatial else (0.0, -gravity))
    P = np.zeros(2)
    vP = np.zeros(2)
    prev = "ground"
    for k in range(n):
        e = np.array([np.cos(phi[k]), np.sin(phi[k])])
        eperp = np.array([-e[1], e[0]])
        r = P + com[k] * e
        vr = vP + com[k] * omega[k] * eperp
        lname = f"link{k + 1}"
        if spatial:
            Jax = inertia[k] if axial_inertia is None else axial_inertia[k]
            b.add_body(lname, masses[k], np.diag([Jax, inertia[k], inertia[k]]), (*r, 0.0),
                       orientation=frames.axis_angle_to_euler([0.0, 0.0, 1.0], phi[k]),
                       velocity=(*vr, 0.0), angular_velocity=(0.0, 0.0, omega[k]))
        else:
            b.add_body(lname, masses[k], inertia[k], r, orientation=phi[k], velocity=vr, angular_velocity=omega[k])
        at = (*P, 0.0) if spatial else tuple(P)
        jname = f"joint{k + 1}"
        if springs is None:
            b.add_revolute(jname, prev, lname, at, axis=(0.0, 0.0, 1.0) if spatial else None)
        else:
            from .forces import PointSpring

            b.add_force(PointSpring(jname, prev, lname, at, at, springs[0], springs[1]))
        P = P + lengths[k] * e
        vP = vP + lengths[k] * omega[k] * eperp
        prev = lname
    return b.build()


def simple_pendulum(length: float = 1.0, mass: float = 1.0, angle0: float = np.pi / 2, rate0: float = 0.0,
                    planar: bool = True, bob: str = "point", gravity: float = G_EARTH) -> Model:
    r"""Simple pendulum pivoted at the origin: a point mass on a massless link, or a uniform rod.

    Geometry: pivot at the origin, the link at ``angle0`` [rad] from the downward vertical
    (counter-clockwise positive; the default π/2 is horizontal along +x, as IFToMM A01),
    gravity ``gravity`` [m/s²] along −y.

    ``bob="point"`` (IFToMM A01: 1 kg on a massless 1 m link): one body of mass ``mass`` with
    its centre of mass at the tip and *zero* moment of inertia, joined to the ground by a
    revolute joint at the pivot, a distance ``length`` from the centre of mass.  ``M = diag(m, m, 0)``
    is singular but the KKT matrix is not: the body's rotation is tied to its translation by the
    two revolute rows (the only admissible motion, rotation about the pivot, has kinetic energy
    ``½ m l² θ̇²`` > 0).  Small-angle period ``2π √(l/g)``; multiplier (rod tension) ``m(g cos θ + l θ̇²)``.

    ``bob="rod"``: a uniform slender rod of mass ``mass`` and length ``length``, centre of mass
    at ``l/2``, ``J = m l²/12`` (compound pendulum, small-angle period ``2π √(2l/(3g))``).

    ``planar=False`` builds the same pendulum with a spatial (Euler-parameter) body and a
    revolute joint about global z; the motion stays in the x–y plane.  For the rod the axial
    moment is set equal to the transverse one: the revolute joint locks that rotation, so the
    value does not enter the motion, and it keeps ``M`` invertible.

    Parameters
    ----------
    length : float
        Link length l [m].
    mass : float
        m [kg].
    angle0 : float
        Initial angle from the downward vertical [rad].
    rate0 : float
        Initial angular velocity [rad/s] (counter-clockwise).
    planar : bool
    bob : {'point', 'rod'}
    gravity : float
        g [m/s²].

    Returns
    -------
    Model
        Body ``link1``, joint ``joint1``.

    References
    ----------
    IFToMM benchmark A01 (González et al. 2006).
    """
    length = _check_positive("simple_pendulum: length", length)
    mass = _check_positive("simple_pendulum: mass", mass)
    if bob == "point":
        com, J, Jax = length, 0.0, 0.0
    elif bob == "rod":
        com, J = length / 2.0, mass * length**2 / 12.0
        Jax = J
    else:
        raise ValueError(f"simple_pendulum: bob must be 'point' or 'rod', got {bob!r}")
    phi = float(angle0) - np.pi / 2.0
    return _serial_chain(f"simple_pendulum_{bob}", [length], [mass], [com], [J], [phi], [float(rate0)],
                         not planar, gravity, axial_inertia=[Jax])


def double_pendulum(lengths=(1.0, 1.0), masses=(1.0, 1.0), angles0=(np.pi / 2, np.pi / 2), rates0=(0.0, 0.0),
                    planar: bool = True, gravity: float = G_EARTH) -> Model:
    r"""Double pendulum of two uniform slender rods pinned at the origin and to each other.

    Rod k has length ``lengths[k]`` [m], mass ``masses[k]`` [kg], centre of mass at mid-length
    and ``J_k = m_k l_k²/12`` about it.  ``angles0`` are the absolute angles from the downward
    vertical [rad] (counter-clockwise), default both horizontal along +x; ``rates0`` the absolute
    angular velocities [rad/s].  Gravity along −y.  ``planar=False``: spatial bodies, revolute
    joints about z (axial moment = transverse moment, locked by the joints).

    Returns
    -------
    Model
        Bodies ``link1``, ``link2``; joints ``joint1`` (ground pivot), ``joint2``.
    """
    lengths = [_check_positive(f"double_pendulum: lengths[{k}]", x) for k, x in enumerate(lengths)]
    masses = [_check_positive(f"double_pendulum: masses[{k}]", x) for k, x in enumerate(masses)]
    if len(lengths) != 2 or len(masses) != 2 or len(angles0) != 2 or len(rates0) != 2:
        raise ValueError("double_pendulum: lengths, masses, angles0 and rates0 need two entries each")
    J = [m * l**2 / 12.0 for m, l in zip(masses, lengths)]
    phi = [float(a) - np.pi / 2.0 for a in angles0]
    return _serial_chain("double_pendulum", lengths, masses, [l / 2.0 for l in lengths], J, phi,
                         [float(w) for w in rates0], not planar, gravity)


# --------------------------------------------------------------------------------------------
# N-link whip chain (core_benchmarks.md §1)
# --------------------------------------------------------------------------------------------


def n_link_chain(n: int, planar: bool | None = None, spatial: bool | None = None, stiff_k: float | None = None,
                 stiff_c: float = 0.0, total_length: float = 1.0, total_mass: float = 1.0,
                 gravity: float = G_EARTH) -> Model:
    r"""The N-link whip chain: N identical uniform slender links hanging from a pivot at the origin.

    Definition (``/work/shared/notes/core_benchmarks.md`` §1): total length 1 m and mass 1 kg,
    so each link has ``L = 1/N`` m, ``m = 1/N`` kg and ``J = m L²/12`` about its centre; link 1
    is pinned to the ground at the origin, revolute joints join consecutive links; at ``t = 0``
    all links lie along +x at rest; gravity 9.81 m/s² along −y; ``t_end = 1 s``.  The free tip is
    the far end of link N (:func:`chain_tip`).

    Variants
    --------
    planar (default)
        Planar bodies (x, y, θ): ``3N`` coordinates, ``2N`` constraints.
    spatial
        Euler-parameter bodies with revolute joints about global z and gravity −y: ``7N``
        coordinates, ``5N`` constraints; the motion must equal the planar one.  The axial moment
        of inertia (about the link axis) is set to ``m L²/12``: the joints lock that rotation,
        so it does not enter the motion, and ``M`` stays invertible.
    stiff (``stiff_k`` given)
        Every revolute joint, the ground pivot included, is replaced by a zero-length point
        spring ``F = −k d − c ḋ`` (:class:`core.forces.PointSpring`) between the same two points:
        an unconstrained, stiff ODE (k = 1e4, 1e6, 1e8 N/m in the benchmark).

    Parameters
    ----------
    n : int
        Number of links N ≥ 1.
    planar, spatial : bool, optional
        Choose the variant; give one of them (``planar=False`` ≡ ``spatial=True``).
    stiff_k : float, optional
        Joint spring stiffness k [N/m]; None for ideal revolute joints.
    stiff_c : float
        Joint spring damping c [N s/m] (stiff variant only).
    total_length, total_mass, gravity : float
        [m], [kg], [m/s²].

    Returns
    -------
    Model
        Bodies ``link1..linkN``; joints (or springs) ``joint1..jointN``.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n_link_chain: n must be an integer ≥ 1, got {n!r}")
    if planar is not None and spatial is not None and bool(planar) == bool(spatial):
        raise ValueError(f"n_link_chain: planar={planar} and spatial={spatial} contradict each other")
    is_spatial = bool(spatial) if spatial is not None else (planar is not None and not planar)
    Ltot = _check_positive("n_link_chain: total_length", total_length)
    mtot = _check_positive("n_link_chain: total_mass", total_mass)
    L, m = Ltot / n, mtot / n
    J = m * L * L / 12.0
    springs = None
    if stiff_k is not None:
        springs = (_check_positive("n_link_chain: stiff_k", stiff_k), float(stiff_c))
        if not (np.isfinite(springs[1]) and springs[1] >= 0):
            raise ValueError(f"n_link_chain: stiff_c must be ≥ 0, got {stiff_c}")
    name = f"chain{n}_{'spatial' if is_spatial else 'planar'}" + ("" if stiff_k is None else f"_k{stiff_k:g}")
    return _serial_chain(name, [L] * n, [m] * n, [L / 2] * n, [J] * n, [0.0] * n, [0.0] * n,
                         is_spatial, gravity, springs=springs)


def chain_tip(model: Model, q: Array) -> Array:
    r"""Position [m] of the free tip of the last link of a chain built by :func:`n_link_chain`.

    ``r_tip = r_N + A_N (L/2, 0[, 0])`` with ``L`` recovered from the initial configuration.

    Parameters
    ----------
    model : Model
    q : ndarray, shape (n_q,) or (n_t, n_q)

    Returns
    -------
    ndarray, shape (2,) or (n_t, 2)
        (x, y) of the tip.
    """
    q = np.asarray(q, float)
    single = q.ndim == 1
    Qm = np.atleast_2d(q)
    sp_ = model.space
    nb = model.n_bodies
    half = float(model.q0[(nb - 1) * sp_.n_q])  # initial x of the last centre = (N − ½) L
    half = half / (2 * nb - 1)  # L/2
    blk = Qm[:, (nb - 1) * sp_.n_q: nb * sp_.n_q]
    if sp_.dim == 2:
        th = blk[:, 2]
        tip = blk[:, :2] + half * np.stack([np.cos(th), np.sin(th)], 1)
    else:
        A = frames.euler_to_matrix(blk[:, 3:7])
        tip = blk[:, :2] + half * A[:, :2, 0]
    return tip[0] if single else tip


# --------------------------------------------------------------------------------------------
# slider crank and four-bar
# --------------------------------------------------------------------------------------------

#: Simeon's slider crank, rigid version (test set "slider crank", Simeon 1996): masses [kg]
#: of crank, connecting rod and slider, lengths [m], moments of inertia [kg m²] as published
#: (about the crank pivot and about the rod's crank-side joint, see :func:`slider_crank`),
#: crank speed Ω [rad/s].
SLIDER_CRANK_PARAMETERS = dict(m1=0.36, m2=0.151104, m3=0.075552, l1=0.15, l2=0.30, J1=0.002727,
                               J2=0.0045339259, omega=150.0)


def slider_crank(crank_angle0: float = 0.0, crank_speed: float = 150.0, driven: bool = True,
                 gravity: float = 0.0, **parameters: float) -> Model:
    r"""Rigid slider crank with the parameters of Simeon's test problem.

    Geometry: crank (body ``crank``, length ``l1``) pinned to the ground at the origin, at
    absolute angle φ1; connecting rod (``rod``, length ``l2``) pinned to the crank tip A at
    angle φ2 with ``sin φ2 = −l1 sin φ1 / l2``; slider (``slider``) pinned to the rod end B
    and moving along the x axis (translational joint).  Crank–rod–slider are collinear along +x
    at φ1 = 0 (Simeon's initial configuration).

    Parameters (:data:`SLIDER_CRANK_PARAMETERS`, the test set / Simeon 1996): ``m1 = 0.36``,
    ``m2 = 0.151104``, ``m3 = 0.075552`` kg; ``l1 = 0.15``, ``l2 = 0.30`` m;
    ``J1 = 0.002727``, ``J2 = 0.0045339259`` kg m²; ``Ω = 150`` rad/s; no gravity.  The
    published J1, J2 are the moments about the crank pivot and about the rod's joint with the
    crank (they equal rectangular bars 0.15 × 0.03 m and 0.30 × 0.008 m, ``m(l² + h²)/12 +
    m l²/4``); the bodies here carry the centroidal values ``J − m (l/2)²`` at mid-length
    (0.000702 and 0.0011340859 kg m²).  The slider is a point mass (its rotation is locked by
    the translational joint; J = 0).

    ``driven=True`` (the test problem) prescribes the crank angle ``φ1 = φ1(0) + Ω t`` by a
    revolute angle driver (``crank drive``); ``driven=False`` leaves the crank free with initial
    rate Ω.

    Parameters
    ----------
    crank_angle0 : float
        φ1(0) [rad].
    crank_speed : float
        Ω [rad/s].
    driven : bool
    gravity : float
        g [m/s²] along −y (0 in the test problem).
    **parameters : float
        Overrides of m1, m2, m3, l1, l2, J1, J2.

    References
    ----------
    B. Simeon, Math. Modelling of Systems 2 (1996) 1–18; B. Simeon, *Computational Flexible
    Multibody Dynamics*, Springer, 2013; Mazzia & Magherini, Test Set for IVP Solvers 2.4 (2008).
    """
    unknown = set(parameters) - (set(SLIDER_CRANK_PARAMETERS) - {"omega"})
    if unknown:
        raise ValueError(f"slider_crank: unknown parameter(s) {sorted(unknown)}")
    p = dict(SLIDER_CRANK_PARAMETERS, **{k: float(v) for k, v in parameters.items()})
    l1, l2 = p["l1"], p["l2"]
    if not l2 > l1 > 0:
        raise ValueError(f"slider_crank: need l2 > l1 > 0 for a full crank rotation, got l1={l1}, l2={l2}")
    J1c = p["J1"] - p["m1"] * (l1 / 2) ** 2
    J2c = p["J2"] - p["m2"] * (l2 / 2) ** 2
    if J1c < 0 or J2c < 0:
        raise ValueError("slider_crank: J1, J2 (about the joint ends) are smaller than m (l/2)²")
    p1, w1 = float(crank_angle0), float(crank_speed)
    p2 = np.arcsin(-l1 * np.sin(p1) / l2)
    w2 = -l1 * np.cos(p1) * w1 / (l2 * np.cos(p2))
    e1, n1 = np.array([np.cos(p1), np.sin(p1)]), np.array([-np.sin(p1), np.cos(p1)])
    e2, n2 = np.array([np.cos(p2), np.sin(p2)]), np.array([-np.sin(p2), np.cos(p2)])
    A, vA = l1 * e1, l1 * w1 * n1
    Bp, vB = A + l2 * e2, vA + l2 * w2 * n2
    b = ModelBuilder(2, "slider_crank", gravity=(0.0, -gravity))
    b.add_body("crank", p["m1"], J1c, l1 / 2 * e1, orientation=p1, velocity=l1 / 2 * w1 * n1, angular_velocity=w1)
    b.add_body("rod", p["m2"], J2c, A + l2 / 2 * e2, orientation=p2, velocity=vA + l2 / 2 * w2 * n2,
               angular_velocity=w2)
    b.add_body("slider", p["m3"], 0.0, Bp, velocity=(vB[0], 0.0))
    b.add_revolute("crank pivot", "ground", "crank", (0.0, 0.0))
    b.add_revolute("crank pin", "crank", "rod", A)
    b.add_revolute("wrist pin", "rod", "slider", Bp)
    b.add_translational("slider guide", "ground", "slider", Bp, (1.0, 0.0))
    if driven:
        b.add_angle_driver("crank drive", "crank pivot", ramp(w1))
    return b.build()


def crank_geometry(model: Model) -> tuple[float, float]:
    r"""Crank radius and connecting-rod length of a slider crank, read from its joint locations.

    With the crank pivot O at the origin, the crank pin A and the wrist pin B (the revolute
    joints of :func:`slider_crank`, at their positions in the model's initial configuration)::

        r = |A − O|,     l = |B − A|

    which enter the closed-form slider position ``x(θ) = r cos θ + √(l² − r² sin² θ)``.

    Parameters
    ----------
    model : Model
        A slider crank built by :func:`slider_crank` (crank pivot at the origin).

    Returns
    -------
    r : float
        Crank radius [m] (``l1``).
    l : float
        Connecting-rod length [m] (``l2``).

    References
    ----------
    B. Simeon, Math. Modelling of Systems 2 (1996) 1–18 (the geometry, ``l1 = 0.15``,
    ``l2 = 0.30`` m); the position equation is the loop closure of the crank, rod and slider.
    """
    pins = {j.name: np.asarray(j.at, float) for j in model.joints if type(j).__name__ == "Revolute"}
    # crank pivot at the origin; the crank pin is the nearer of the other two revolutes
    others = [p for p in pins.values() if np.linalg.norm(p) > 1e-12]
    a = min(others, key=lambda p: np.linalg.norm(p))
    b = max(others, key=lambda p: np.linalg.norm(p))
    return float(np.linalg.norm(a)), float(np.linalg.norm(b - a))


def four_bar(ground: float = 0.4, crank: float = 0.1, coupler: float = 0.35, rocker: float = 0.3,
             mass_per_length: float = 1.0, crank_angle0: float = np.pi / 2, crank_rate0: float = 2 * np.pi,
             crank_speed: float | None = None, gravity: float = G_EARTH) -> Model:
    r"""Planar four-bar linkage of uniform slender links (default: a Grashof crank–rocker).

    Geometry: ground pivots O2 = (0, 0) and O4 = (``ground``, 0); crank O2–A at absolute angle
    θ2, coupler A–B, rocker O4–B; B is the intersection of the circles ``|B − A|`` = coupler and
    ``|B − O4|`` = rocker on the left of A→O4 (the "open" assembly, B above the line A–O4).  Each
    link is a uniform slender rod of mass ``mass_per_length · length`` and ``J = m l²/12``.
    Grashof's condition ``s + l ≤ p + q`` with the crank the shortest link makes it a
    crank–rocker (defaults 0.1 + 0.4 ≤ 0.35 + 0.3): the crank turns fully and Φ_q never loses rank.

    ``crank_speed`` given: the crank angle is driven, ``θ2 = θ2(0) + Ω t`` (``crank drive``).
    Otherwise the linkage moves freely under gravity from crank rate ``crank_rate0``.

    Parameters
    ----------
    ground, crank, coupler, rocker : float
        Link lengths [m].
    mass_per_length : float
        [kg/m].
    crank_angle0 : float
        θ2(0) [rad] from +x.
    crank_rate0 : float
        θ̇2(0) [rad/s] (ignored if ``crank_speed`` is given).
    crank_speed : float, optional
        Constant driven crank speed Ω [rad/s].
    gravity : float
        [m/s²] along −y.

    Returns
    -------
    Model
        Bodies ``crank``, ``coupler``, ``rocker``; joints ``O2``, ``A``, ``B``, ``O4``.

    Raises
    ------
    ValueError
        If the linkage cannot be assembled at ``crank_angle0``.
    """
    r1, r2, r3, r4 = (_check_positive(f"four_bar: {n}", v) for n, v in
                      (("ground", ground), ("crank", crank), ("coupler", coupler), ("rocker", rocker)))
    rho = _check_positive("four_bar: mass_per_length", mass_per_length)
    th2 = float(crank_angle0)
    w2 = float(crank_rate0 if crank_speed is None else crank_speed)
    O4 = np.array([r1, 0.0])
    A = r2 * np.array([np.cos(th2), np.sin(th2)])
    dvec = O4 - A
    dist = np.linalg.norm(dvec)
    if not (abs(r3 - r4) < dist < r3 + r4):
        raise ValueError(f"four_bar: cannot assemble at crank angle {th2} rad (|A−O4| = {dist:.4g} m)")
    # circle intersection, B on the left of A→O4
    a_ = (r3**2 - r4**2 + dist**2) / (2 * dist)
    h = np.sqrt(r3**2 - a_**2)
    u = dvec / dist
    B = A + a_ * u + h * np.array([-u[1], u[0]])
    th3 = np.arctan2(*(B - A)[::-1])
    th4 = np.arctan2(*(B - O4)[::-1])
    # velocities: r3 θ̇3 e⊥3 − r4 θ̇4 e⊥4 = −r2 θ̇2 e⊥2
    perp = lambda t: np.array([-np.sin(t), np.cos(t)])  # noqa: E731
    w3, w4 = np.linalg.solve(np.column_stack([r3 * perp(th3), -r4 * perp(th4)]), -r2 * w2 * perp(th2))
    vA = r2 * w2 * perp(th2)
    b = ModelBuilder(2, "four_bar", gravity=(0.0, -gravity))
    for name, L, th, w, P0, v0 in (("crank", r2, th2, w2, np.zeros(2), np.zeros(2)),
                                   ("coupler", r3, th3, w3, A, vA),
                                   ("rocker", r4, th4, w4, O4, np.zeros(2))):
        m = rho * L
        e = np.array([np.cos(th), np.sin(th)])
        b.add_body(name, m, m * L * L / 12, P0 + L / 2 * e, orientation=th, velocity=v0 + L / 2 * w * perp(th),
                   angular_velocity=w)
    b.add_revolute("O2", "ground", "crank", (0.0, 0.0))
    b.add_revolute("A", "crank", "coupler", A)
    b.add_revolute("B", "coupler", "rocker", B)
    b.add_revolute("O4", "rocker", "ground", O4)
    if crank_speed is not None:
        b.add_angle_driver("crank drive", "O2", ramp(w2))
    return b.build()


# --------------------------------------------------------------------------------------------
# bead on a helix (user constraint + extra coordinate)
# --------------------------------------------------------------------------------------------


class HelixConstraint(UserConstraint):
    r"""Body origin on the helix ``r(s) = (R cos s, R sin s, c s)``, s an extra coordinate.

    ``Φ = r_body − r(s)`` (3 rows); Jacobian with respect to ``(v_body (6), ṡ)``:
    ``[I₃, 0₃, −r'(s)]`` with ``r' = (−R sin s, R cos s, c)``; ``ν = 0``;
    ``γ = r''(s) ṡ²`` with ``r'' = (−R cos s, −R sin s, 0)`` (from ``Φ̈ = r̈ − r' s̈ − r'' ṡ²``).

    Parameters
    ----------
    name : str
    body : str
        A spatial body whose origin (centre of mass) is held on the helix.
    coordinate : str
        Name of the extra coordinate s [rad] (``ModelBuilder.add_coordinate``).
    radius : float
        R [m].
    rise : float
        c = pitch / 2π [m/rad].
    """

    rows = 3

    def __init__(self, name: str, body: str, coordinate: str, radius: float, rise: float):
        self.name = name
        self.bodies = (body,)
        self.coordinates = (coordinate,)
        self.body_i, self.body_j = body, "ground"
        self.at = None
        self.R, self.c = float(radius), float(rise)

    def bind(self, q_index, v_index, space):
        if space.dim != 3:
            raise ValueError(f"constraint {self.name!r}: the helix constraint needs a spatial model")
        super().bind(q_index, v_index, space)

    def _curve(self, s):
        return (np.array([self.R * np.cos(s), self.R * np.sin(s), self.c * s]),
                np.array([-self.R * np.sin(s), self.R * np.cos(s), self.c]),
                np.array([-self.R * np.cos(s), -self.R * np.sin(s), 0.0]))

    def phi(self, t, q):
        qi = q[self.q_index]
        r, _, _ = self._curve(qi[7])
        return qi[:3] - r

    def jacobian(self, t, q):
        s = q[self.q_index[7]]
        _, dr, _ = self._curve(s)
        J = np.zeros((3, 7))
        J[:, :3] = np.eye(3)
        J[:, 6] = -dr
        return J

    def gamma(self, t, q, v):
        s = q[self.q_index[7]]
        sd = v[self.v_index[6]]
        _, _, ddr = self._curve(s)
        return ddr * sd * sd

    def compiled(self, layout):
        """Compiled form: :func:`helix_kernel` (the body block and the massless coordinate s)."""
        b = int(self.q_index[0]) // layout.n_q_body
        slots = np.array([[body_slot(b, layout.n_bodies), layout.extra_slot(self.coordinates[0], self.name), -1]] * 3,
                         np.int64)
        ix = np.array([[b, layout.extra_q_index(self.coordinates[0], self.name),
                        layout.extra_v_index(self.coordinates[0], self.name)]], np.int64)
        return CompiledConstraints(kernel=helix_kernel, fd=np.array([[self.R, self.c]]), ix=ix, rows=3, slots=slots,
                                   names=[self.name], what="helix constraint")


@constraint_kernel
def helix_kernel(t, q, v, r, A, rd, w, lay, fd, ix, row0, flags, phi, G, nu, gam, err):
    """Compiled :class:`HelixConstraint`: ``Φ = r_b − (R cos s, R sin s, c s)``,
    ``Φ_q = [I₃ 0 | −r′(s)]`` (body slot, coordinate slot), ``ν = 0``, ``γ = r″(s) ṡ²``
    (fd: R, c; ix: body, q index and v index of s)."""
    R, c = fd[0, 0], fd[0, 1]
    b, qs, vs = ix[0, 0], ix[0, 1], ix[0, 2]
    s, sd = q[qs], v[vs]
    cs, sn = np.cos(s), np.sin(s)
    if flags & WANT_PHI:
        phi[row0] = r[b, 0] - R * cs
        phi[row0 + 1] = r[b, 1] - R * sn
        phi[row0 + 2] = r[b, 2] - c * s
    for i in range(3):
        for j in range(6):
            G[row0 + i, 0, j] = 1.0 if j == i else 0.0
    G[row0, 1, 0] = R * sn
    G[row0 + 1, 1, 0] = -R * cs
    G[row0 + 2, 1, 0] = -c
    if flags & WANT_NU:
        for i in range(3):
            nu[row0 + i] = 0.0
    if flags & WANT_GAMMA:
        gam[row0] = -R * cs * sd * sd
        gam[row0 + 1] = -R * sn * sd * sd
        gam[row0 + 2] = 0.0
    return OK


def body_on_helix(radius: float = 0.5, pitch: float = 0.2, mass: float = 1.0, bead_radius: float = 0.01,
                  s0: float = 0.0, sdot0: float = 2.0, gravity: float = G_EARTH) -> Model:
    r"""A bead sliding without friction on a helix about the vertical z axis, under gravity −z.

    The helix ``r(s) = (R cos s, R sin s, c s)``, ``c = pitch/2π``, is imposed by a
    :class:`HelixConstraint` on a spatial body (a small solid sphere, ``J = (2/5) m r_b²``)
    with the helix parameter s [rad] as an extra, massless coordinate (``add_coordinate``).
    Exact motion (arc-length form of Newton's law along the curve)::

        (R² + c²) s̈ = −g c   ⇒   s(t) = s0 + ṡ0 t − ½ g c t² / (R² + c²)

    (:func:`helix_analytic`); the energy ``½ m |ṙ|² + m g z`` is conserved; the bead does not spin.

    Parameters
    ----------
    radius : float
        R [m].
    pitch : float
        Rise per turn [m] (c = pitch / 2π).
    mass : float
        [kg].
    bead_radius : float
        r_b [m] of the sphere (sets its inertia; no effect on the path motion).
    s0, sdot0 : float
        Initial parameter [rad] and rate [rad/s].
    gravity : float
        [m/s²] along −z.

    Returns
    -------
    Model
        Body ``bead``, coordinate ``s``, constraint ``helix``.
    """
    R = _check_positive("body_on_helix: radius", radius)
    pitch = float(pitch)
    m = _check_positive("body_on_helix: mass", mass)
    rb = _check_positive("body_on_helix: bead_radius", bead_radius)
    c = pitch / (2 * np.pi)
    hc = HelixConstraint("helix", "bead", "s", R, c)
    r, dr, _ = hc._curve(float(s0))
    b = ModelBuilder(3, "body_on_helix", gravity=(0.0, 0.0, -gravity))
    b.add_body("bead", m, 0.4 * m * rb * rb * np.ones(3), r, velocity=dr * sdot0)
    b.add_coordinate("s", float(s0), float(sdot0), 0.0)
    b.add_joint(hc)
    return b.build()


def helix_analytic(t, radius: float = 0.5, pitch: float = 0.2, s0: float = 0.0, sdot0: float = 2.0,
                   gravity: float = G_EARTH):
    r"""Exact ``s(t)`` [rad] and ``ṡ(t)`` [rad/s] of :func:`body_on_helix` (see there)."""
    c = pitch / (2 * np.pi)
    acc = -gravity * c / (radius**2 + c**2)
    t = np.asarray(t, float)
    return s0 + sdot0 * t + 0.5 * acc * t * t, sdot0 + acc * t


# --------------------------------------------------------------------------------------------
# bouncing ball
# --------------------------------------------------------------------------------------------


def bouncing_ball(radius: float = 0.1, mass: float = 1.0, height0: float = 1.0, restitution: float = 0.9,
                  stiffness: float = 1e7, exponent: float = 1.5, model: str = "lankarani-nikravesh",
                  spatial: bool = False, gravity: float = G_EARTH) -> Model:
    r"""A solid sphere dropped from rest onto the ground plane y = 0 (compliant PlaneContact).

    The sphere (radius ``radius`` [m], mass ``mass`` [kg], ``J = (2/5) m r²``) starts at rest with
    its lowest point ``height0`` [m] above the plane y = 0; gravity along −y.  The contact is
    :class:`core.forces.PlaneContact` with the Hertz-type law ``F = K δ^p [1 + χ(e) δ̇/δ̇⁻]``
    (default p = 3/2, K = ``stiffness`` [N/m^p]) and the approach velocity ``δ̇⁻ = √(2 g h0)`` of
    the first impact.  An exact restitution law gives the rebound apex ``e² h0``; the
    hysteresis-damping models reproduce e only approximately: Lankarani & Nikravesh's
    χ = 3(1 − e²)/4 is derived for small dissipation (e → 1) and its error in the rebound
    height grows like (1 − e)² (Flores et al. 2011, Fig. 6); e = 1 is exactly elastic.
    The default K = 1e7 N/m^1.5 (a hard rubber ball) makes an impact last a few milliseconds.

    Parameters
    ----------
    radius, mass, height0 : float
        [m], [kg], [m].
    restitution : float
        e in (0, 1].
    stiffness : float
        K [N/m^p].
    exponent : float
        p (3/2 for Hertz).
    model : {'lankarani-nikravesh', 'flores', 'hunt-crossley'}
        Hysteresis damping law (see :class:`core.forces.PlaneContact`).
    spatial : bool
        Spatial (Euler-parameter) body instead of a planar one.
    gravity : float
        [m/s²].

    Returns
    -------
    Model
        Body ``ball``, force element ``ground contact``.

    References
    ----------
    H. M. Lankarani, P. E. Nikravesh, J. Mech. Des. 112 (1990) 369–376.
    P. Flores et al., Multibody Syst. Dyn. 25 (2011) 357–375.
    """
    from .forces import PlaneContact

    r = _check_positive("bouncing_ball: radius", radius)
    m = _check_positive("bouncing_ball: mass", mass)
    h0 = _check_positive("bouncing_ball: height0", height0)
    g = _check_positive("bouncing_ball: gravity", gravity)
    e = float(restitution)
    if not 0.0 < e <= 1.0:
        raise ValueError(f"bouncing_ball: restitution must be in (0, 1], got {restitution}")
    J = 0.4 * m * r * r
    b = ModelBuilder(3 if spatial else 2, "bouncing_ball", gravity=(0.0, -g, 0.0) if spatial else (0.0, -g))
    centre = (0.0, h0 + r, 0.0) if spatial else (0.0, h0 + r)
    b.add_body("ball", m, J * np.ones(3) if spatial else J, centre)
    origin = (0.0, 0.0, 0.0) if spatial else (0.0, 0.0)
    normal = (0.0, 1.0, 0.0) if spatial else (0.0, 1.0)
    b.add_force(PlaneContact("ground contact", "ball", centre, r, origin, normal, restitution=e,
                             impact_velocity=np.sqrt(2 * g * h0), stiffness=stiffness, exponent=exponent,
                             model=model))
    return b.build()


# --------------------------------------------------------------------------------------------
# Andrews' squeezing mechanism as a Cartesian planar model (IFToMM A03 / test set "andrews")
# --------------------------------------------------------------------------------------------


def _andrews_points(q_angles, p):
    r"""Joint points, spring point D and body frames of Andrews' mechanism from the seven angles.

    Returns ``(points, frames)``: ``points`` maps a point name to its global position [m];
    ``frames`` is a list of ``(body name, orientation [rad], centre of mass [m])`` for bodies 1..7.
    """
    b, th, g, ph, de, om, ep = (float(x) for x in q_angles)
    e_ = lambda a: np.array([np.cos(a), np.sin(a)])  # noqa: E731
    rot = lambda a, v: np.array([np.cos(a) * v[0] - np.sin(a) * v[1], np.sin(a) * v[0] + np.cos(a) * v[1]])  # noqa: E731
    O = np.zeros(2)
    A = np.array([p["xa"], p["ya"]])
    B = np.array([p["xb"], p["yb"]])
    C = np.array([p["xc"], p["yc"]])
    F = p["rr"] * e_(b)
    E = F - p["d"] * e_(b + th)
    G = A + p["zt"] * e_(de)
    H = A + rot(ep, (0.0, -p["u"]))
    D = B + rot(g, (p["sd"], -p["sc"]))
    ee, zz = p["e"] - p["ea"], p["zf"] - p["fa"]
    frames_ = [
        ("body1", b, p["ra"] * e_(b)),
        ("body2", b + th, F - p["da"] * e_(b + th)),
        ("body3", g, B + rot(g, (p["sa"], p["sb"]))),
        ("body4", ph + de, G + rot(ph + de, (0.0, -ee))),
        ("body5", de, A + rot(de, (p["ta"], p["tb"]))),
        ("body6", om + ep, H + zz * e_(om + ep)),
        ("body7", ep, A + rot(ep, (p["ua"], p["ub"]))),
    ]
    return dict(O=O, A=A, B=B, C=C, D=D, E=E, F=F, G=G, H=H), frames_


def andrews_cartesian(**overrides: float) -> Model:
    r"""Andrews' squeezing mechanism as a planar Cartesian model of seven rigid bodies.

    The same mechanism as :class:`core.benchmarks.testset.AndrewsSqueezer` (which is written in
    the seven angles), built with :class:`~core.model.ModelBuilder` in absolute coordinates
    ``(x, y, θ)`` per body: 21 coordinates, ten revolute joints (20 equations), 1 degree of
    freedom.  Its solution must reach the same angles (:func:`andrews_angles_from_cartesian`).

    Geometry (Hairer & Wanner II, Sec. VII.7, Fig. 7.1 and Eqs. (7.11)–(7.14); test set
    ``andrews.f``), read off the angle-form constraints and mass matrix of
    :class:`~core.benchmarks.testset.AndrewsSqueezer`; ``e(α) = (cos α, sin α)``,
    ``R(α)`` the rotation by α; fixed points O = (0, 0), A = (xa, ya), B = (xb, yb),
    C = (xc, yc):

    ====== ========== ===================================================================
    body   angle θ    joints, centre of mass
    ====== ========== ===================================================================
    1      β          crank: pivot O; F = rr e(β); c.o.m. at ra e(β)
    2      β + Θ      coupler: F; E = F − d e(β+Θ); c.o.m. at F − da e(β+Θ)
    3      γ          pivot B; E = B + R(γ)(0, −ss); spring point D = B + R(γ)(sd, −sc);
                      c.o.m. at B + R(γ)(sa, sb)
    4      Φ + δ      G; E = G + R(Φ+δ)(0, −e); c.o.m. at G + R(Φ+δ)(0, −(e − ea))
    5      δ          pivot A; G = A + zt e(δ); c.o.m. at A + R(δ)(ta, tb)
    6      Ω + ε      H; E = H + zf e(Ω+ε); c.o.m. at H + (zf − fa) e(Ω+ε)
    7      ε          pivot A; H = A + R(ε)(0, −u); c.o.m. at A + R(ε)(ua, ub)
    ====== ========== ===================================================================

    Joints (revolute): ``O`` (ground–1), ``F`` (1–2), ``B`` (ground–3), ``E23``, ``E24``,
    ``E26`` (body 2 to bodies 3, 4, 6 at the common point E), ``A5`` (ground–5), ``G``
    (5–4), ``A7`` (ground–7), ``H`` (7–6).  Force elements: the spring ``spring c0`` between
    D on body 3 and C on the ground, stiffness c0 = 4530 N/m, free length l0 = 0.07785 m
    (:class:`core.forces.SpringDamper`); the drive torque ``drive mom`` = 0.033 N m on body 1
    (:class:`core.forces.AppliedTorque`).  No gravity.

    Assumption (stated, and without effect on the motion): the published data give for the
    bodies pivoted at a fixed point (1, 3, 5, 7) only the *distance* of the centre of mass from
    the pivot (``ra``, ``√(sa² + sb²)``, ``√(ta² + tb²)``, ``√(ua² + ub²)``, which is all the
    angle-form mass matrix contains); the direction chosen above changes no equation of motion
    (no gravity acts, and a body turning about a fixed pivot has kinetic energy
    ``½ (I + m s²) θ̇²`` whatever the direction of s).  For bodies 2, 4 and 6 the centre of mass
    lies on the line of the two joints, as the cross terms ``M21``, ``M54``, ``M76`` require.

    Initial state: positions from the published consistent angles
    (:attr:`AndrewsSqueezer.Q0_PUBLISHED`), all velocities zero.

    Parameters
    ----------
    **overrides : float
        Replace entries of :data:`core.benchmarks.testset.ANDREWS_PARAMETERS` (SI units).

    Returns
    -------
    Model
        Bodies ``body1..body7``.

    References
    ----------
    - E. Hairer, G. Wanner, *Solving ODEs II*, 2nd ed., Springer, 1996, Sec. VII.7, pp. 530–536.
    - F. Mazzia, C. Magherini, *Test Set for IVP Solvers* 2.4, Univ. of Bari, 2008, "andrews".
    - W. Schiehlen (ed.), *Multibody Systems Handbook*, Springer, 1990 (Manning & Giles,
      Andrews & Richard: "seven body mechanism"); IFToMM benchmark A03.
    """
    from .benchmarks.testset import ANDREWS_PARAMETERS, AndrewsSqueezer
    from .forces import AppliedTorque, SpringDamper

    unknown = set(overrides) - set(ANDREWS_PARAMETERS)
    if unknown:
        raise ValueError(f"andrews_cartesian: unknown parameter(s) {sorted(unknown)}")
    p = dict(ANDREWS_PARAMETERS, **{k: float(v) for k, v in overrides.items()})
    pts, frames_ = _andrews_points(AndrewsSqueezer.Q0_PUBLISHED, p)
    b = ModelBuilder(2, "andrews_cartesian", gravity=(0.0, 0.0))
    for k, (name, ang, com) in enumerate(frames_):
        b.add_body(name, p[f"m{k + 1}"], p[f"i{k + 1}"], com, orientation=ang)
    for jname, bi, bj, at in (("O", "ground", "body1", "O"), ("F", "body1", "body2", "F"),
                              ("B", "ground", "body3", "B"), ("E23", "body2", "body3", "E"),
                              ("E24", "body2", "body4", "E"), ("E26", "body2", "body6", "E"),
                              ("A5", "ground", "body5", "A"), ("G", "body5", "body4", "G"),
                              ("A7", "ground", "body7", "A"), ("H", "body7", "body6", "H")):
        b.add_revolute(jname, bi, bj, pts[at])
    b.add_force(SpringDamper("spring c0", "body3", "ground", pts["D"], pts["C"], p["c0"], 0.0, p["l0"]))
    b.add_force(AppliedTorque("drive mom", "body1", p["mom"]))
    return b.build()


def andrews_angles_from_cartesian(model: Model, q: Array) -> Array:
    r"""The seven angles ``(β, Θ, γ, Φ, δ, Ω, ε)`` [rad] of :func:`andrews_cartesian` states.

    ``β = θ1``, ``Θ = θ2 − θ1``, ``γ = θ3``, ``Φ = θ4 − θ5``, ``δ = θ5``, ``Ω = θ6 − θ7``,
    ``ε = θ7`` with ``θ_k`` the (unwrapped) body angles.  The same linear map applies to
    velocities and accelerations (pass ``v`` or ``a`` in place of ``q``).

    Parameters
    ----------
    model : Model
        Built by :func:`andrews_cartesian`.
    q : ndarray, shape (21,) or (n_t, 21)

    Returns
    -------
    ndarray, shape (7,) or (n_t, 7)
    """
    q = np.asarray(q, float)
    if q.shape[-1] != model.n_v or model.n_bodies != 7:
        raise ValueError(f"andrews_angles_from_cartesian: expected a 7-body planar state of length 21, got {q.shape}")
    th = q[..., 2::3]
    return np.stack([th[..., 0], th[..., 1] - th[..., 0], th[..., 2], th[..., 3] - th[..., 4], th[..., 4],
                     th[..., 5] - th[..., 6], th[..., 6]], axis=-1)


# --------------------------------------------------------------------------------------------
# IFToMM A02: N four-bar mechanism
# --------------------------------------------------------------------------------------------


def _a02_rate(phi: float, speed: float, L: float) -> float:
    """Bar rate φ̇ [rad/s] giving ẋ(B_0) = −L φ̇ sin φ = speed (or ẏ(B_0) = speed when sin φ = 0)."""
    if abs(np.sin(phi)) > 1e-12:
        return -speed / (L * np.sin(phi))
    return speed / (L * np.cos(phi))


def iftomm_a02_four_bar_chain(n_windows: int = 40, link_length: float = 1.0, link_mass: float = 1.0,
                              speed: float = 1.0, angle0: float = np.pi / 2, gravity: float = G_EARTH,
                              redundant: str = "keep") -> Model:
    r"""IFToMM benchmark A02: the N four-bar mechanism (a row of N parallelogram "windows").

    Geometry (IFToMM library, González et al. 2006; as implemented in the open OpenSim port of
    the library, RehabEngGroup/MBSbenchmarksInOpenSim, ``src/A02-NFourBarMechanism``): ground
    pivots ``O_i = (i L, 0)``, i = 0..N; ``N + 1`` *bars* ``bar0..barN``, bar i from ``O_i`` to
    ``B_i = O_i + L e(φ)``; ``N`` *couplers* ``coupler1..couplerN``, coupler i from
    ``B_{i−1}`` to ``B_i``: ``2N + 1`` uniform slender links of length L = 1 m, mass 1 kg,
    ``J = m L²/12``; gravity 9.81 m/s² along −y.  Revolute joints ``O_i`` (ground–bar i),
    ``B_0`` (bar0–coupler1), ``B_i/L`` (coupler i–bar i) and ``B_i/R`` (bar i–coupler i+1),
    ``B_N`` (couplerN–barN).  Initial configuration: bars vertical (φ = π/2), couplers horizontal
    at y = L; initial velocity ``ẋ(B_0) = 1 m/s``, i.e. every bar turns at ``φ̇ = −ẋ(B_0)/L``
    (clockwise) and every coupler translates at (1, 0) m/s.  Simulated for 20 s.

    Motion: the parallelograms keep all bars parallel, so the exact motion is that of one
    equivalent pendulum in the bar angle φ (:func:`core.benchmarks.references.iftomm_a02_reference`)::

        [ (N+1) m L²/3 + N m L² ] φ̈ = −g L cos φ [ (N+1) m/2 + N m ]

    Starting upright with non-zero speed the bars circulate, passing through the horizontal
    positions φ = 0, π where all links are collinear on the ground line: there ``Φ_q`` loses
    N ranks and the mechanism has N + 1 degrees of freedom instead of 1 (the singular
    configurations of the benchmark).

    Redundancy: at the upright start (and at every non-horizontal configuration) the 2(3N+1)
    revolute equations are independent: Grübler count ``3(2N+1) − 2(3N+1) = 1`` equals the
    mobility, so ``build`` reports *no* redundant equations there (``redundant`` only matters
    when ``angle0`` is a singular angle, 0 or π; the default ``'keep'`` then keeps the
    dependent rows and the integrators use minimum-norm multipliers).

    Parameters
    ----------
    n_windows : int
        N ≥ 1 (40 in the benchmark).
    link_length, link_mass : float
        L [m], m [kg].
    speed : float
        ẋ(B_0) at t = 0 [m/s] (``φ̇(0) = −speed/(L sin φ0)``); when ``angle0`` is horizontal
        (sin φ0 = 0, where ẋ(B_0) must vanish) it is ẏ(B_0) instead.
    angle0 : float
        Initial bar angle φ from +x [rad] (π/2: upright, the benchmark).
    gravity : float
        [m/s²] along −y.
    redundant : {'raise', 'remove', 'keep'}
        Passed to :meth:`ModelBuilder.build`.

    Returns
    -------
    Model
        Bodies ``bar0..barN``, ``coupler1..couplerN``.

    References
    ----------
    M. González, D. Dopico, U. Lugrís, J. Cuadrado, Multibody Syst. Dyn. 16 (2006) 179–190;
    IFToMM Library of Computational Benchmark Problems, problem A02 "N four-bar mechanism";
    E. Bayo, R. Ledesma (1996) / Bayo & Avello (1994) (the two-window original).
    """
    if isinstance(n_windows, bool) or not isinstance(n_windows, (int, np.integer)) or n_windows < 1:
        raise ValueError(f"iftomm_a02_four_bar_chain: n_windows must be an integer ≥ 1, got {n_windows!r}")
    L = _check_positive("iftomm_a02_four_bar_chain: link_length", link_length)
    m = _check_positive("iftomm_a02_four_bar_chain: link_mass", link_mass)
    phi = float(angle0)
    w = _a02_rate(phi, float(speed), L)
    e = np.array([np.cos(phi), np.sin(phi)])
    eperp = np.array([-e[1], e[0]])
    J = m * L * L / 12.0
    b = ModelBuilder(2, f"iftomm_a02_{n_windows}", gravity=(0.0, -gravity))
    vB = L * w * eperp
    for i in range(n_windows + 1):
        O = np.array([i * L, 0.0])
        b.add_body(f"bar{i}", m, J, O + 0.5 * L * e, orientation=phi, velocity=0.5 * vB, angular_velocity=w)
    for i in range(1, n_windows + 1):
        Bl = np.array([(i - 1) * L, 0.0]) + L * e
        b.add_body(f"coupler{i}", m, J, Bl + np.array([0.5 * L, 0.0]), orientation=0.0, velocity=vB)
    for i in range(n_windows + 1):
        b.add_revolute(f"O{i}", "ground", f"bar{i}", (i * L, 0.0))
    for i in range(n_windows + 1):
        Bi = np.array([i * L, 0.0]) + L * e
        if i > 0:
            b.add_revolute(f"B{i}/L", f"coupler{i}", f"bar{i}", Bi)
        if i < n_windows:
            b.add_revolute(f"B{i}/R", f"bar{i}", f"coupler{i + 1}", Bi)
    return b.build(redundant=redundant)


# --------------------------------------------------------------------------------------------
# IFToMM A04: Bricard mechanism
# --------------------------------------------------------------------------------------------

#: Joint points and global axes of the Bricard mechanism at t = 0 (A04), L = 1 m.
BRICARD_JOINTS = (
    ("J1", "ground", "rod1", (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    ("J2", "rod1", "rod2", (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("J3", "rod2", "rod3", (1.0, -1.0, 0.0), (1.0, 0.0, 0.0)),
    ("J4", "rod3", "rod4", (1.0, -1.0, 1.0), (0.0, 1.0, 0.0)),
    ("J5", "rod4", "rod5", (0.0, -1.0, 1.0), (0.0, 0.0, 1.0)),
    ("J6", "rod5", "ground", (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)),
)


def iftomm_a04_bricard(link_length: float = 1.0, link_mass: float = 1.0, cross_section: float = 0.1,
                       gravity: float = G_EARTH, redundant: str = "keep") -> Model:
    r"""IFToMM benchmark A04: Bricard's over-constrained 6R mechanism (5 rods + ground).

    Geometry at t = 0 (L = 1 m; the IFToMM description as implemented in the open OpenSim port
    of the library, RehabEngGroup/MBSbenchmarksInOpenSim ``src/A04-BricardsMechanism``, whose
    fifth rod is split into two welded halves): the closed chain of six unit edges
    O → P1 → P2 → P3 → P4 → P5 → O with

    ====== ================ ================ =====================
    rod    from             to               joint at "from", axis
    ====== ================ ================ =====================
    rod1   O  = (0, 0, 0)   P1 = (1, 0, 0)   J1, y (to ground)
    rod2   P1               P2 = (1, −1, 0)  J2, z
    rod3   P2               P3 = (1, −1, 1)  J3, x
    rod4   P3               P4 = (0, −1, 1)  J4, y
    rod5   P4               P5 = (0, 0, 1)   J5, z
    ====== ================ ================ =====================

    and J6 at P5 = (0, 0, 1), axis x, joining rod5 to the ground (the ground "link" is the
    edge P5–O).  Every joint axis is perpendicular to both links it joins and to the
    neighbouring axes: the trihedral Bricard linkage.  Gravity 9.81 m/s² along −y; the
    mechanism starts at rest (no initial speed is set in the OpenSim port) and moves under
    gravity for 10 s; energy is conserved.

    Rods: uniform, mass 1 kg, square cross-section of side ``cross_section`` = 0.1 m (as the
    OpenSim port; ``J_axial = m a²/6``, ``J_transverse = m (L² + a²)/12``), centre of mass at
    mid-length.

    Redundancy: 5 spatial bodies (30 velocity coordinates) and 6 revolute joints (30 equations)
    give a Grübler count of 0, yet the linkage moves with one degree of freedom: ``Φ_q`` has
    rank 29 and one equation is dependent at every configuration of the motion.  ``build``
    detects it by pivoted QR (the dependent row is named in ``model.redundant_constraints``);
    ``redundant='keep'`` keeps all 30 rows (minimum-norm multipliers), ``'remove'`` deletes
    the named row (unique multipliers of the remaining 29).

    Parameters
    ----------
    link_length, link_mass, cross_section : float
        L [m], m [kg], a [m].
    gravity : float
        [m/s²] along −y.
    redundant : {'raise', 'remove', 'keep'}

    Returns
    -------
    Model
        Bodies ``rod1..rod5``; joints ``J1..J6``.

    References
    ----------
    R. Bricard, "Mémoire sur la théorie de l'octaèdre articulé", J. Math. Pures Appl. 3 (1897)
    113–148.  M. González, D. Dopico, U. Lugrís, J. Cuadrado, Multibody Syst. Dyn. 16 (2006)
    179–190; IFToMM Library of Computational Benchmark Problems, problem A04.
    """
    L = _check_positive("iftomm_a04_bricard: link_length", link_length)
    m = _check_positive("iftomm_a04_bricard: link_mass", link_mass)
    a = _check_positive("iftomm_a04_bricard: cross_section", cross_section)
    Jax, Jtr = m * a * a / 6.0, m * (L * L + a * a) / 12.0
    pts = [L * np.asarray(j[3]) for j in BRICARD_JOINTS] + [np.zeros(3)]
    b = ModelBuilder(3, "iftomm_a04_bricard", gravity=(0.0, -gravity, 0.0))
    for k in range(5):
        P, Q = pts[k], pts[k + 1]
        d = (Q - P) / L
        # body x axis along the rod: rotation taking e_x to d
        ex = np.array([1.0, 0.0, 0.0])
        ax = np.cross(ex, d)
        s, c = np.linalg.norm(ax), float(ex @ d)
        if s < 1e-12:
            ori = np.array([1.0, 0.0, 0.0, 0.0]) if c > 0 else frames.axis_angle_to_euler([0.0, 0.0, 1.0], np.pi)
        else:
            ori = frames.axis_angle_to_euler(ax / s, np.arctan2(s, c))
        b.add_body(f"rod{k + 1}", m, np.array([Jax, Jtr, Jtr]), 0.5 * (P + Q), orientation=ori)
    for name, bi, bj, at, axis in BRICARD_JOINTS:
        b.add_revolute(name, bi, bj, L * np.asarray(at), axis=axis)
    return b.build(redundant=redundant)


__all__ += ["andrews_cartesian", "andrews_angles_from_cartesian", "iftomm_a02_four_bar_chain",
            "iftomm_a04_bricard", "BRICARD_JOINTS"]
