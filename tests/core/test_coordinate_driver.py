"""core.joints.CoordinateDriver: an extra coordinate prescribed as a function of time.

Closed form: a coordinate of mass m driven by x(t) = c0 + c1 t + c2 t² needs the generalized
force m ẍ = 2 m c2, so the driver's multiplier is λ = −2 m c2 (M v̇ + Φ_qᵀ λ = Q = 0);
ν = ḟ = c1 + 2 c2 t, γ = f̈.  numpy and compiled paths agree to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest

from core.compiled import compile_model, make_workspace
from core.compiled import dynamics as D
from core.compiled import protocol as P
from core.drivers import motion, polynomial
from core.errors import NotCompilable
from core.joints import CoordinateDriver
from core.model import ModelBuilder
from core.simulation import simulate

C = (0.5, 1.0, 1.5)
MASS = 2.0


def _model(fn=None):
    b = ModelBuilder(3, "driven_coordinate")
    b.add_coordinate("x", C[0], C[1], MASS)
    b.add_joint(CoordinateDriver("drive", "x", polynomial(C) if fn is None else fn))
    return b.build()


def test_rows_and_flags():
    m = _model()
    t, q = 0.7, np.array([3.0])
    assert m.time_dependent and not m.is_conservative
    assert m.Phi(t, q)[0] == pytest.approx(3.0 - (C[0] + C[1] * t + C[2] * t * t), abs=1e-15)
    assert m.Phi_q(t, q).toarray().tolist() == [[1.0]]
    assert m.nu(t, q)[0] == pytest.approx(C[1] + 2 * C[2] * t, abs=1e-15)
    assert m.gamma(t, q, np.zeros(1))[0] == pytest.approx(2 * C[2], abs=1e-15)
    assert m.degrees_of_freedom == 0


@pytest.mark.parametrize("method", ["dop853-projection", "jit-dop853-projection"])
def test_driven_coordinate_follows_the_motion_and_the_multiplier_is_the_force(method):
    m = _model()
    res = simulate(m, (0.0, 2.0), method, rtol=1e-10, atol=1e-10, n_output=5)
    assert res.status == "finished", res.message
    t = res.t
    assert np.max(np.abs(res.q[:, 0] - (C[0] + C[1] * t + C[2] * t**2))) < 1e-9
    assert np.max(np.abs(res.v[:, 0] - (C[1] + 2 * C[2] * t))) < 1e-9
    assert np.max(np.abs(res.lam[:, 0] + 2 * MASS * C[2])) < 1e-9


def test_compiled_kernel_equals_numpy():
    m = _model()
    cm = compile_model(m)
    ws = make_workspace(cm)
    q, v, t = np.array([1.3]), np.array([0.2]), 0.41
    D.body_states(cm.fields["lay"], q, v, ws)
    assert D.constraints(cm.data, ws, t, q, v, P.WANT_ALL) == P.OK
    assert ws.phi[0] == pytest.approx(m.Phi(t, q)[0], abs=1e-15)
    assert ws.nu[0] == pytest.approx(m.nu(t, q)[0], abs=1e-15)
    assert ws.gam[0] == pytest.approx(m.gamma(t, q, v)[0], abs=1e-15)


def test_python_callable_is_refused_by_name_on_the_compiled_path():
    m = _model(motion(lambda t: C[0] + C[1] * t + C[2] * t * t))
    with pytest.raises(NotCompilable, match="drive"):
        compile_model(m)
