"""Bad and careless inputs to the core (issue 9): each gets an exact outcome.

Every case asserts one of: an error of a :class:`core.errors.MbsuiteError` type whose message names
the element, value or file at fault; or a run that finishes with the right answer; never a
"finished" run with a wrong one.
"""

from __future__ import annotations

import numpy as np
import pytest

from core import models
from core.errors import InputError, MbsuiteError, ModelError
from core.integrators import simulate
from core.model import ModelBuilder


def _rod_pendulum_builder():
    b = ModelBuilder(2, "rod pendulum")
    b.add_body("rod", mass=1.0, inertia=1 / 12, position=(0.5, 0.0))
    b.add_revolute("pivot", "ground", "rod", at=(0.0, 0.0))
    return b


def test_a_model_builder_instead_of_a_model_says_build_first():
    with pytest.raises(InputError, match=r"got a ModelBuilder: call build\(\) on the ModelBuilder first"):
        simulate(_rod_pendulum_builder(), (0.0, 1.0), "rk45")


@pytest.mark.parametrize("method", ["rk45-projection", "generalized-alpha", "jit-dop853"])
def test_q0_of_the_wrong_length_names_the_sizes(method):
    model = _rod_pendulum_builder().build()
    with pytest.raises(InputError, match=r"q0 has shape \(2,\), model 'rod pendulum' has 3 coordinates: rod.x \[m\], rod.y"):
        simulate(model, (0.0, 1.0), method, q0=[0.5, 0.0], h=1e-3)
    with pytest.raises(InputError, match=r"v0 has shape \(4,\), model 'rod pendulum' has 3 velocity coordinates"):
        simulate(model, (0.0, 1.0), method, v0=np.zeros(4), h=1e-3)
    with pytest.raises(InputError, match=r"q0\[1\] is nan"):
        simulate(model, (0.0, 1.0), method, q0=[0.5, np.nan, 0.0], h=1e-3)


@pytest.mark.parametrize("n_output", [0, -3, 2.5, True])
def test_n_output_must_be_a_positive_integer(n_output):
    model = _rod_pendulum_builder().build()
    with pytest.raises(InputError, match=r"n_output must be an integer >= 1.*got " + repr(n_output).replace(".", r"\.")):
        simulate(model, (0.0, 1.0), "rk45", n_output=n_output)


def test_one_output_time_is_the_end_state():
    model = _rod_pendulum_builder().build()
    res = simulate(model, (0.0, 0.1), "rk45-projection", n_output=1, rtol=1e-9, atol=1e-9)
    assert res.status == "finished" and res.t.tolist() == [0.1]


def test_initial_positions_off_the_constraints_are_refused_or_assembled():
    """q0 0.1 m off the pivot: the check of build() names the violated row; assemble=True moves the
    rod back onto its pivot (minimum-norm correction) and the run keeps the constraint."""
    model = _rod_pendulum_builder().build()
    q_off = model.q0 + np.array([0.1, 0.0, 0.0])
    with pytest.raises(ModelError, match=r"inconsistent initial positions; constraint 'pivot/point\[0\]' is violated "
                                         r"by -1\.000e-01 .*simulate\(\.\.\., assemble=True\)"):
        simulate(model, (0.0, 0.5), "rk45-projection", q0=q_off)
    res = simulate(model, (0.0, 0.5), "rk45-projection", q0=q_off, assemble=True, rtol=1e-9, atol=1e-9)
    assert res.status == "finished"
    assert np.max(res.position_violation) < 10 * 1e-9  # held to the requested tolerance (dense output between steps)
    # the assembled rod still hangs from the pivot at its half length
    np.testing.assert_allclose(np.hypot(res.q[0, 0], res.q[0, 1]), 0.5, atol=1e-10)


def test_inconsistent_initial_velocity_is_refused():
    model = _rod_pendulum_builder().build()
    with pytest.raises(ModelError, match=r"inconsistent initial velocities; constraint 'pivot/point\[0\]'"):
        simulate(model, (0.0, 0.5), "rk45", v0=np.array([1.0, 0.0, 0.0]))


def test_spatial_inertia_violating_the_triangle_inequality_names_the_body():
    b = ModelBuilder(3, "box")
    with pytest.raises(ModelError, match=r"body 'box': principal moments of inertia 0\.1, 0\.2, 0\.5 .*triangle inequality"):
        b.add_body("box", mass=1.0, inertia=(0.1, 0.2, 0.5), position=(0, 0, 0))
    # limiting cases that are rigid bodies: a flat plate (J3 = J1 + J2), a slender rod, a point mass
    b.add_body("plate", mass=1.0, inertia=(0.1, 0.2, 0.3), position=(0, 0, 0))
    b.add_body("rod", mass=1.0, inertia=(0.0, 0.5, 0.5), position=(1, 0, 0))
    b.add_body("point", mass=1.0, inertia=(0.0, 0.0, 0.0), position=(2, 0, 0))


def test_every_input_error_is_an_mbsuite_error():
    model = _rod_pendulum_builder().build()
    for call in (lambda: simulate(_rod_pendulum_builder(), (0, 1), "rk45"),
                 lambda: simulate(model, (0, 1), "rk45", q0=[1.0]),
                 lambda: simulate(model, (0, 1), "rk45", n_output=0),
                 lambda: simulate(model, (0, 1), "rk45", q0=model.q0 + 0.1)):
        with pytest.raises(MbsuiteError):
            call()


def test_energy_drift_of_a_run_from_zero_energy_is_absolute():
    """A pendulum released at the pivot's height has E0 = 0: the summary's relative drift is not
    defined (NaN), the absolute drift is small against the energy scale of the swing."""
    model = models.simple_pendulum(bob="rod")
    res = simulate(model, (0.0, 1.0), "rk45-projection", rtol=1e-9, atol=1e-9)
    assert res.energy[0] == pytest.approx(0.0, abs=1e-12)
    row = res.summary().iloc[0]
    assert np.isnan(row["max |relative energy drift| [-]"])
    assert row["max |energy drift| [J]"] < 1e-6 * row["energy scale [J]"] or row["max |energy drift| [J]"] < 1e-7


def test_eigen_away_from_equilibrium_says_so():
    """A rod pendulum held horizontal is not an equilibrium: eigen() warns and reports the relative
    unbalanced force (0.75 for the free rod: the angular acceleration 3g/2L against the gravity m g); hanging, it is
    silent and the residual is round-off."""
    import warnings

    from core.analysis import AnalysisWarning, eigen

    horizontal = models.simple_pendulum(bob="rod", angle0=np.pi / 2)
    with pytest.warns(AnalysisWarning, match=r"not an equilibrium .*largest acceleration .* in 'link1"):
        table, _ = eigen(horizontal)
    assert table.attrs["equilibrium_residual"] == pytest.approx(0.75, rel=1e-9)
    hanging = models.simple_pendulum(bob="rod", angle0=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        table, _ = eigen(hanging)
    assert table.attrs["equilibrium_residual"] < 1e-12
    # the compound pendulum's frequency: sqrt(m g l/2 / (m l²/3)) for a 1 m rod
    assert table["natural frequency [Hz]"].iloc[0] == pytest.approx(np.sqrt(1.5 * 9.81) / (2 * np.pi), rel=1e-9)
