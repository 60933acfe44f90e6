"""Parameter sweeps: any executor must reproduce the serial reference exactly."""

from __future__ import annotations

import concurrent.futures

import numpy as np
import pytest

from core.sweep import executor_workers, run_sweep


def damped_walk(case: dict) -> dict:
    """A small seeded computation: a damped random walk and its statistics.

    Module-level so that worker processes can unpickle it.
    """
    rng = np.random.default_rng(case["seed"])
    steps = rng.standard_normal(500)
    x = np.zeros(501)
    for k, s in enumerate(steps):  # sequential recurrence (deliberately order-dependent)
        x[k + 1] = case["damping"] * x[k] + s
    return {"seed": case["seed"], "damping": case["damping"], "final": x[-1], "rms": float(np.sqrt(np.mean(x**2)))}


def fail_on_three(case: int) -> int:
    if case == 3:
        raise ValueError("case three is bad")
    return case * case


CASES = [{"seed": seed, "damping": d} for seed in range(4) for d in (0.5, 0.9, 0.99)]


def test_process_pool_equals_serial_exactly():
    serial = run_sweep(damped_walk, CASES)
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        parallel = run_sweep(damped_walk, CASES, executor=pool, progress=True)
    assert parallel == serial  # exact equality, in case order
    assert [r["seed"] for r in serial] == [c["seed"] for c in CASES]


def test_thread_pool_and_progress_serial():
    serial = run_sweep(fail_on_three, [0, 1, 2], progress=True)
    with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
        assert run_sweep(fail_on_three, [0, 1, 2], executor=pool) == serial == [0, 1, 4]


@pytest.mark.parametrize("use_pool", [False, True])
def test_failure_names_case(use_pool):
    cases = [1, 2, 3, 4]
    if use_pool:
        with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
            with pytest.raises(ValueError, match="case three") as info:
                run_sweep(fail_on_three, cases, executor=pool)
    else:
        with pytest.raises(ValueError, match="case three") as info:
            run_sweep(fail_on_three, cases)
    assert "run_sweep: case 2 (3) failed" in info.value.__notes__


def test_rejects_non_executor():
    with pytest.raises(TypeError, match="Executor"):
        run_sweep(fail_on_three, [1], executor=object())


def test_executor_workers():
    assert executor_workers(None) == 1
    with concurrent.futures.ThreadPoolExecutor(max_workers=3) as pool:
        assert executor_workers(pool) == 3
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        assert executor_workers(pool) == 2

    class Elsewhere(concurrent.futures.Executor):  # a cluster's executor: size not known
        pass

    assert executor_workers(Elsewhere()) is None


def test_simulate_case_runs_anywhere_and_names_what_a_case_lacks():
    import functools

    from core import models
    from core.errors import InputError, UnknownOptionError
    from core.sweep import simulate_case

    make = functools.partial(models.n_link_chain, 2)
    case = dict(system=make, t_span=(0.0, 0.05), method="dop853-projection", n_output=3, rtol=1e-8, atol=1e-10)
    serial = run_sweep(simulate_case, [case])[0]
    with concurrent.futures.ProcessPoolExecutor(max_workers=1) as ex:
        pooled = run_sweep(simulate_case, [case], executor=ex)[0]
    assert serial.status == pooled.status == "finished"
    np.testing.assert_array_equal(serial.q, pooled.q)  # the same run, built in the worker
    with pytest.raises(InputError, match="lacks t_span"):
        simulate_case(dict(system=make, t_spn=(0.0, 0.05), method="dop853"))
    with pytest.raises(InputError, match="system must be a factory"):
        simulate_case(dict(system=make(), t_span=(0.0, 0.05), method="dop853"))
    with pytest.raises(UnknownOptionError, match="rtl"):
        simulate_case(dict(system=make, t_span=(0.0, 0.05), method="dop853", rtl=1e-6))
