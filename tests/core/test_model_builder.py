"""ModelBuilder validation: every error names the element at fault; redundancy; pickling."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest

from core import drivers, frames
from core.errors import ModelError, RedundantConstraintError
from core.model import ModelBuilder


def _pendulum(dim=2, **body):
    b = ModelBuilder(dim, "pend")
    pos = (1.0, 0.0) if dim == 2 else (1.0, 0.0, 0.0)
    inertia = 0.1 if dim == 2 else [0.1, 0.1, 0.1]
    b.add_body("bob", 1.0, inertia, pos, **body)
    return b


# --------------------------------------------------------------------------------------------
# names
# --------------------------------------------------------------------------------------------


def test_unknown_body_in_joint_names_joint_and_body():
    b = _pendulum()
    b.add_revolute("pivot", "ground", "nobody", (0.0, 0.0))
    with pytest.raises(ModelError, match=r"'pivot'.*'nobody'"):
        b.build()


def test_unknown_body_in_force_names_force_element():
    b = _pendulum()
    b.add_point_spring("spr", "bob", "ghost", (1.0, 0.0), stiffness=1.0)
    with pytest.raises(ModelError, match=r"'spr'.*'ghost'"):
        b.build()


@pytest.mark.parametrize("second", ["body", "joint", "force", "coordinate"])
def test_duplicate_name(second):
    b = _pendulum()
    with pytest.raises(ModelError, match=r"duplicate name 'bob'"):
        if second == "body":
            b.add_body("bob", 1.0, 0.1, (0.0, 0.0))
        elif second == "joint":
            b.add_revolute("bob", "ground", "bob", (0.0, 0.0))
        elif second == "force":
            b.add_applied_torque("bob", "bob", 1.0)
        else:
            b.add_coordinate("bob", 0.0)


def test_ground_name_reserved():
    b = ModelBuilder(2)
    with pytest.raises(ModelError, match="reserved"):
        b.add_body("ground", 1.0, 0.1, (0.0, 0.0))


def test_joint_connecting_body_to_itself():
    b = _pendulum()
    with pytest.raises(ModelError, match=r"joint 'self' connects body 'bob' to itself"):
        b.add_revolute("self", "bob", "bob", (0.0, 0.0))


def test_force_connecting_body_to_itself():
    b = _pendulum()
    b.add_rotational_spring_damper("tors", "bob", "bob", 1.0)
    with pytest.raises(ValueError, match=r"'tors' connects body 'bob' to itself"):
        b.build()


# --------------------------------------------------------------------------------------------
# initial state
# --------------------------------------------------------------------------------------------


def test_inconsistent_initial_positions_name_constraint():
    b = _pendulum()
    b.add_distance("rod", "ground", "bob", (0.0, 0.0), (1.0, 0.0), length=1.2)
    with pytest.raises(ModelError, match=r"inconsistent initial positions; constraint 'rod/distance'"):
        b.build()
    # assembly repairs it: the bob is moved onto the circle of radius 1.2
    m = b.build(assemble=True)
    np.testing.assert_allclose(np.hypot(*m.q0[:2]), 1.2, rtol=1e-9)


def test_inconsistent_initial_velocities_name_constraint():
    b = _pendulum(velocity=(0.5, 0.0))  # radial velocity violates the pivot
    b.add_revolute("pivot", "ground", "bob", (0.0, 0.0))
    with pytest.raises(ModelError, match=r"inconsistent initial velocities; constraint 'pivot/point\[0\]'"):
        b.build()


def test_universal_axes_not_perpendicular():
    b = _pendulum(3)
    b.add_universal("cardan", "ground", "bob", (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0))
    with pytest.raises(ValueError, match=r"joint 'cardan'.*perpendicular"):
        b.build()


def test_spatial_revolute_needs_axis():
    b = _pendulum(3)
    b.add_revolute("hinge", "ground", "bob", (0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"joint 'hinge'.*axis"):
        b.build()


def test_angle_driver_needs_revolute():
    b = _pendulum()
    b.add_distance("rod", "ground", "bob", (0.0, 0.0), (1.0, 0.0))
    with pytest.raises(ModelError, match=r"driver 'drv'.*'rod' is not a revolute"):
        b.add_angle_driver("drv", "rod", drivers.ramp(1.0))


# --------------------------------------------------------------------------------------------
# bodies
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dim", [2, 3])
def test_negative_mass(dim):
    b = ModelBuilder(dim)
    with pytest.raises(ModelError, match=r"body 'heavy'.*mass"):
        b.add_body("heavy", -1.0, 0.1 if dim == 2 else [0.1] * 3, np.zeros(dim))


@pytest.mark.parametrize("inertia", [
    [[1.0, 0.2, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],  # not symmetric
    [1.0, -0.1, 1.0],  # negative principal moment
    [[1.0, 0.0], [0.0, 1.0]],  # wrong shape
])
def test_bad_spatial_inertia(inertia):
    b = ModelBuilder(3)
    with pytest.raises(ModelError, match=r"body 'wheel'.*inertia"):
        b.add_body("wheel", 1.0, inertia, np.zeros(3))


def test_bad_planar_inertia():
    b = ModelBuilder(2)
    with pytest.raises(ModelError, match=r"body 'disc'.*inertia"):
        b.add_body("disc", 1.0, -0.5, np.zeros(2))


@pytest.mark.parametrize("p", [[2.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [np.nan, 0, 0, 1]])
def test_bad_euler_parameters(p):
    b = ModelBuilder(3)
    with pytest.raises(ModelError, match=r"body 'link'.*Euler parameters"):
        b.add_body("link", 1.0, [0.1] * 3, np.zeros(3), orientation=p)


@pytest.mark.parametrize("dim", [2, 3])
def test_non_finite_initial_velocity(dim):
    b = ModelBuilder(dim)
    with pytest.raises(ModelError, match=r"body 'link'.*velocity"):
        b.add_body("link", 1.0, 0.1 if dim == 2 else [0.1] * 3, np.zeros(dim), velocity=[np.nan] * dim)
    with pytest.raises(ModelError, match=r"body 'link'.*angular velocity"):
        b.add_body("link", 1.0, 0.1 if dim == 2 else [0.1] * 3, np.zeros(dim),
                   angular_velocity=np.inf if dim == 2 else [0.0, np.inf, 0.0])


def test_bad_position_shape():
    b = ModelBuilder(3)
    with pytest.raises(ModelError, match=r"body 'link'.*position"):
        b.add_body("link", 1.0, [0.1] * 3, (0.0, 0.0))


# --------------------------------------------------------------------------------------------
# force-element validation names the element
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("add, pattern", [
    (lambda b: b.add_point_spring("ps", "ground", "bob", (1.0, 0.0), stiffness=-1.0), r"'ps'.*stiffness"),
    (lambda b: b.add_spring_damper("sd", "ground", "bob", (0.0, 0.0), (1.0, 0.0), 1.0, damping=-2.0), r"'sd'.*damping"),
    (lambda b: b.add_bushing("bu", "ground", "bob", (1.0, 0.0), [1.0, 2.0, 3.0], 1.0), r"'bu'.*translational stiffness"),
    (lambda b: b.add_bushing("bu", "ground", "bob", (1.0, 0.0), 1.0, 1.0, axes=[[1, 0], [0, 2]]), r"'bu'.*axes"),
    (lambda b: b.add_applied_force("af", "bob", (1.0, 0.0), [1.0]), r"'af'.*force must be a sequence of 2"),
    (lambda b: b.add_applied_force("af", "bob", (1.0, 0.0), [1.0, 0.0], frame="marker"), r"'af'.*frame"),
    (lambda b: b.add_applied_force("af", "ground", (1.0, 0.0), [1.0, 0.0]), r"'af'.*ground"),
    (lambda b: b.add_plane_contact("pc", "bob", (1.0, 0.0), 0.1, (0.0, -1.0), (0.0, 1.0), restitution=0.5,
                                   stiffness=1e5), r"'pc'.*impact_velocity"),
    (lambda b: b.add_plane_contact("pc", "bob", (1.0, 0.0), 0.1, (0.0, -1.0), (0.0, 1.0)), r"'pc'.*stiffness"),
    (lambda b: b.add_plane_contact("pc", "bob", (1.0, 0.0), 0.1, (0.0, -1.0), (0.0, 0.0), stiffness=1.0), r"'pc'.*normal"),
    (lambda b: b.add_plane_contact("pc", "bob", (1.0, 0.0), 0.1, (0.0, -1.0), (0.0, 1.0), stiffness=1.0,
                                   restitution=1.5), r"'pc'.*restitution"),
])
def test_force_element_errors_name_element(add, pattern):
    b = _pendulum()
    add(b)
    with pytest.raises(ValueError, match=pattern):
        b.build()


def test_spatial_rotational_spring_needs_axis():
    b = _pendulum(3)
    b.add_rotational_spring_damper("tors", "ground", "bob", 1.0)
    with pytest.raises(ValueError, match=r"'tors'.*axis"):
        b.build()


# --------------------------------------------------------------------------------------------
# redundant constraints: planar four-bar modelled with spatial revolutes about z
# --------------------------------------------------------------------------------------------


def _spatial_four_bar():
    A, B, C, D = (np.array(p, float) for p in ([0, 0, 0], [0.3, 0.8, 0], [1.6, 1.1, 0], [1.8, 0, 0]))
    b = ModelBuilder(3, "four-bar")
    for name, (p, q) in {"crank": (A, B), "coupler": (B, C), "rocker": (C, D)}.items():
        b.add_body(name, 1.0, [0.01, 0.1, 0.1], 0.5 * (p + q))
    z = (0.0, 0.0, 1.0)
    b.add_revolute("A", "ground", "crank", A, z)
    b.add_revolute("B", "crank", "coupler", B, z)
    b.add_revolute("C", "coupler", "rocker", C, z)
    b.add_revolute("D", "rocker", "ground", D, z)
    return b


def test_redundant_four_bar_raises_with_dependent_rows():
    b = _spatial_four_bar()
    with pytest.raises(RedundantConstraintError) as err:
        b.build()
    dep = err.value.dependent
    # 4 × 5 = 20 rows on 3 × 6 = 18 velocities with mobility 1: rank 17, 3 rows dependent
    assert len(dep) == 3
    assert len(set(dep)) == 3
    # the in-plane rows (x, y of the pins) are independent; the dependency is out of plane
    assert all(name.endswith(("/point[2]", "/f.h", "/g.h")) for name in dep), dep
    assert all(name in str(err.value) for name in dep)
    # removing them leaves a full-rank Jacobian with the same null space (mobility 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = b.build(redundant="keep")
    assert full.n_c == 20 and full.n_v == 18
    J = full.Phi_q(0.0, full.q0).toarray()
    keep = [k for k, n in enumerate(full.constraint_names) if n not in dep]
    Jr = J[keep]
    assert np.linalg.matrix_rank(Jr) == Jr.shape[0] == 17
    assert np.linalg.matrix_rank(J) == 17
    assert full.n_v - np.linalg.matrix_rank(Jr) == full.n_v - np.linalg.matrix_rank(J) == 1


def test_redundant_remove_and_keep_build():
    b = _spatial_four_bar()
    with pytest.warns(UserWarning, match="removed"):
        m = b.build(redundant="remove")
    assert m.n_c == 17
    assert m.degrees_of_freedom == 1
    J = m.Phi_q(0.0, m.q0).toarray()
    assert np.linalg.matrix_rank(J) == 17
    assert len(m.Phi(0.0, m.q0)) == len(m.constraint_names) == 17
    with pytest.warns(UserWarning, match="kept"):
        k = b.build(redundant="keep")
    assert k.n_c == 20
    assert k.degrees_of_freedom == 1
    assert len(k.redundant_constraints) == 3


def test_redundant_mode_validated():
    with pytest.raises(ModelError, match="redundant"):
        _spatial_four_bar().build(redundant="ignore")


def test_planar_four_bar_not_redundant():
    b = ModelBuilder(2, "planar-four-bar")
    A, B, C, D = (np.array(p, float) for p in ([0, 0], [0.3, 0.8], [1.6, 1.1], [1.8, 0]))
    for name, (p, q) in {"crank": (A, B), "coupler": (B, C), "rocker": (C, D)}.items():
        b.add_body(name, 1.0, 0.1, 0.5 * (p + q))
    for name, bi, bj, p in (("A", "ground", "crank", A), ("B", "crank", "coupler", B), ("C", "coupler", "rocker", C),
                            ("D", "rocker", "ground", D)):
        b.add_revolute(name, bi, bj, p)
    m = b.build()
    assert m.n_c == 8 and m.degrees_of_freedom == 1 and m.redundant_constraints == []


# --------------------------------------------------------------------------------------------
# pickling
# --------------------------------------------------------------------------------------------


def test_pickle_round_trip_same_Phi_and_Q():
    """Drivers and actuators of every time-function form (ramp, harmonic, table, constant) pickle."""
    rng = np.random.default_rng(0)
    b = ModelBuilder(3, "pickled")
    b.add_body("a", 1.0, [0.1, 0.2, 0.3], (0.5, 0.0, 0.0), orientation=frames.axis_angle_to_euler([1, 2, 3], 0.3))
    b.add_body("c", 2.0, [0.2, 0.2, 0.1], (1.5, 0.2, 0.0), orientation=frames.axis_angle_to_euler([0, 1, 1], 0.7))
    b.add_revolute("j1", "ground", "a", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    b.add_spherical("j2", "a", "c", (1.0, 0.0, 0.0))
    b.add_angle_driver("drive", "j1", drivers.ramp(1.0))
    b.add_spring_damper("sd", "a", "c", (0.3, 0.1, 0.0), (1.7, 0.1, 0.2), 100.0, 2.0)
    b.add_point_spring("ps", "ground", "c", (1.5, 0.2, 0.0), stiffness=1e3, damping=1.0)
    ts = np.linspace(0.0, 2.0, 9)
    b.add_rotational_spring_damper("rs", "a", "c", 5.0, 0.1, actuator=(ts, np.sin(ts)), axis=(1.0, 0.0, 0.0))
    b.add_spring_damper("sd2", "ground", "c", (0.0, 1.0, 0.0), (1.5, 0.2, 0.0), 10.0, actuator=3.0)
    b.add_point_driver("push", "c", (1.5, 0.2, 0.0), (0.0, 0.0, 1.0), drivers.harmonic(0.01, 3.0))
    b.add_bushing("bu", "a", "c", (1.0, 0.0, 0.0), 100.0, 10.0, 1.0, 0.1)
    b.add_applied_force("af", "c", (1.5, 0.2, 0.0), [1.0, 0.0, drivers.ramp(2.0)])
    b.add_applied_torque("at", "a", [0.0, 0.0, 1.0], frame="body")
    b.add_plane_contact("pc", "c", (1.5, 0.2, 0.0), 0.1, (0.0, 0.0, -0.05), (0.0, 0.0, 1.0),
                        restitution=0.8, impact_velocity=1.0, stiffness=1e6)
    m = b.build(assemble=True)
    m2 = pickle.loads(pickle.dumps(m))
    q = m.retract(m.q0, 0.05 * rng.standard_normal(m.n_v))
    v = rng.standard_normal(m.n_v)
    for t in (0.0, 0.4):
        np.testing.assert_array_equal(m2.Phi(t, q), m.Phi(t, q))
        np.testing.assert_array_equal(m2.Q(t, q, v), m.Q(t, q, v))
        np.testing.assert_array_equal(m2.gamma(t, q, v), m.gamma(t, q, v))
    assert m2.constraint_names == m.constraint_names
    assert m2.energy(0.0, q, v) == m.energy(0.0, q, v)


def test_built_model_is_frozen():
    """build() returns an immutable model: attributes and initial-state arrays cannot be changed;
    with_state() returns a frozen copy and leaves the original untouched."""
    import numpy as np

    from core import models

    m = models.simple_pendulum()
    with pytest.raises(AttributeError, match="frozen"):
        m.gravity = np.zeros(2)
    with pytest.raises(ValueError):
        m.q0[0] = 1.0
    q0 = m.q0.copy()
    m2 = m.with_state(q0 + 0.0, m.v0 + 1.0)
    assert m2._frozen and m._frozen
    assert np.array_equal(m.q0, q0) and not np.array_equal(m2.v0, m.v0)


def test_body_fixed_points_and_frames():
    """Body-fixed points and frames: the tip of the pendulum rod is at l(sin θ, −cos θ)."""
    import numpy as np

    from core import models

    m = models.simple_pendulum(length=1.0, angle0=0.3, bob="rod")
    (body,) = m.body_names
    A = m.body_frame(m.q0, body)
    assert np.allclose(A.T @ A, np.eye(2))
    # the rod's centre of mass is at mid-length; its far end is l/2 further along the rod
    com = m.q0[:2]
    axis = com / np.linalg.norm(com)
    tip_local = A.T @ (axis * 0.5)
    tip = m.point_position(m.q0, body, tip_local)
    assert np.allclose(tip, [np.sin(0.3), -np.cos(0.3)], atol=1e-12)
    hist = m.point_position(np.stack([m.q0, m.q0]), body, tip_local)
    assert hist.shape == (2, 2)


def test_kinematic_matrix_Z_maps_velocities_to_coordinate_rates():
    """q̇ = Z(q) v: the sparse Z of a spatial model equals the vectorised qdot, and ω̄ = 2 L ṗ."""
    import numpy as np

    from core import frames, models

    m = models.n_link_chain(3, spatial=True)
    rng = np.random.default_rng(7)
    q = m.retract(m.q0, 0.1 * rng.standard_normal(m.n_v))
    v = rng.standard_normal(m.n_v)
    qd = m.Z(q) @ v
    np.testing.assert_allclose(qd, m.qdot(q, v), atol=1e-15)
    p, pdot = q[3:7], qd[3:7]
    np.testing.assert_allclose(2.0 * frames.euler_rate_matrix(p) @ pdot, v[3:6], atol=1e-12)
