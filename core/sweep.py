"""Parameter sweeps over any :class:`concurrent.futures.Executor`.

A sweep maps a pure function over a list of cases, ``results[i] = fn(cases[i])``.
Where the calls run is the caller's choice, and the result does not depend on it:

* ``executor=None`` -- a plain serial loop in this process. This is the reference
  result; tests compare every parallel route against it.
* one machine -- ``concurrent.futures.ProcessPoolExecutor(max_workers=n)`` from the
  standard library; nothing to install, no server.
* beyond one machine -- ``dask.distributed`` (extra ``mbsuite[parallel]``).
  ``Client(...).get_executor()`` returns an object that *is* a
  ``concurrent.futures.Executor``, so it is passed here unchanged::

      from dask.distributed import Client, LocalCluster
      with Client(LocalCluster(n_workers=4)) as client:      # or Client("tcp://host:8786"),
          rows = run_sweep(fn, cases, executor=client.get_executor())  # SSHCluster, dask-jobqueue

Rules for ``fn`` so that every route gives the same answer:

* a module-level (picklable) function of the case alone; randomness only through
  ``np.random.default_rng(seed)`` with the seed inside the case;
* return small values (a row dict, a small DataFrame) rather than writing to a shared
  file; a case that needs large output writes its own shard;
* set ``OMP_NUM_THREADS=1`` / ``OPENBLAS_NUM_THREADS=1`` for worker processes so BLAS
  threads do not oversubscribe the cores.
"""

from __future__ import annotations

import concurrent.futures
from collections.abc import Callable, Iterable
from typing import TypeVar

__all__ = ["executor_workers", "run_sweep", "simulate_case"]

C = TypeVar("C")
R = TypeVar("R")


def run_sweep(
    fn: Callable[[C], R],
    cases: Iterable[C],
    executor: concurrent.futures.Executor | None = None,
    progress: bool = False,
) -> list[R]:
    """Evaluate ``fn`` for every case and return the results in case order.

    Parameters
    ----------
    fn : callable
        ``fn(case) -> result``; must be picklable (module-level) when an executor
        runs it in other processes.
    cases : iterable
        The cases; materialised into a list first.
    executor : concurrent.futures.Executor, optional
        None runs serially in this process (the reference). Otherwise every case is
        submitted with ``executor.submit(fn, case)``; the executor is not shut down.
    progress : bool, optional
        Show a tqdm bar (over cases, or over completed futures); silent when stderr is
        not a terminal.

    Returns
    -------
    list
        ``[fn(case) for case in cases]``, in case order whatever the completion order.

    Raises
    ------
    Exception
        The first failing case's exception (in case order), with a note naming the case
        index; the remaining not-yet-started cases are cancelled.
    """
    cases = list(cases)
    if executor is None:
        iterator: Iterable[tuple[int, C]] = enumerate(cases)
        if progress:
            from tqdm import tqdm

            iterator = tqdm(iterator, total=len(cases), desc="sweep", unit="case", disable=None)
        results: list[R] = []
        for i, case in iterator:
            try:
                results.append(fn(case))
            except Exception as exc:
                exc.add_note(f"run_sweep: case {i} ({case!r}) failed")
                raise
        return results

    if not isinstance(executor, concurrent.futures.Executor):
        raise TypeError(f"executor must be a concurrent.futures.Executor or None, got {type(executor).__name__}")
    futures = [executor.submit(fn, case) for case in cases]
    try:
        if progress:
            from tqdm import tqdm

            for _ in tqdm(
                concurrent.futures.as_completed(futures), total=len(futures), desc="sweep", unit="case", disable=None
            ):
                pass
        results = []
        for i, future in enumerate(futures):
            try:
                results.append(future.result())
            except Exception as exc:
                exc.add_note(f"run_sweep: case {i} ({cases[i]!r}) failed")
                raise
    except BaseException:
        for future in futures:
            future.cancel()
        raise
    return results


def executor_workers(executor: concurrent.futures.Executor | None) -> int | None:
    """The number of workers behind ``executor``, as a sweep's report states it.

    Parameters
    ----------
    executor : concurrent.futures.Executor or None
        None (a serial sweep in this process), a standard-library process or thread pool, or
        any other executor (a ``dask.distributed`` client's).

    Returns
    -------
    int or None
        1 for None; the pool's ``max_workers`` for a :class:`concurrent.futures.ProcessPoolExecutor`
        or :class:`~concurrent.futures.ThreadPoolExecutor`; None when the executor does not say
        (a cluster may grow and shrink while it runs).
    """
    if executor is None:
        return 1
    if isinstance(getattr(executor, "max_workers", None), int):  # core.scene_scheduler.SlotExecutor
        return int(executor.max_workers)
    if isinstance(executor, (concurrent.futures.ProcessPoolExecutor, concurrent.futures.ThreadPoolExecutor)):
        return int(executor._max_workers)  # the standard library keeps it only here
    return None


def simulate_case(case: dict):
    """One run of a sweep of simulations, for :func:`run_sweep`: ``case = dict(system=factory,
    t_span=(t0, t1), method=..., **simulate_options)``.

    ``factory()`` builds the system in the process that runs the case (a module-level function,
    a class or a :func:`functools.partial` of one, so that the case pickles; a built model need
    not); the rest goes to :func:`core.integrators.simulate` unchanged.  Returns its
    :class:`core.results.SimulationResult`, which pickles back.

    Examples
    --------
    >>> import functools
    >>> from core import models
    >>> cases = [dict(system=functools.partial(models.n_link_chain, 2), t_span=(0.0, 0.1), method=m,
    ...               n_output=3) for m in ("radau-ggl", "dop853-projection")]
    >>> [r.status for r in run_sweep(simulate_case, cases)]
    ['finished', 'finished']
    """
    from .errors import InputError
    from .integrators import simulate

    if not isinstance(case, dict):
        raise InputError(f"simulate_case: a case is a dict(system=..., t_span=..., method=...), got {case!r}")
    missing = [k for k in ("system", "t_span", "method") if k not in case]
    if missing:
        raise InputError(f"simulate_case: the case {sorted(case)} lacks {', '.join(missing)} "
                         "(system: a picklable factory; t_span: (t0, t1); method: an integrator name)")
    if not callable(case["system"]):
        raise InputError(f"simulate_case: system must be a factory that builds the system (a module-level function, "
                         f"class or functools.partial), got {case['system']!r}")
    opts = dict(case)
    system = opts.pop("system")()
    return simulate(system, opts.pop("t_span"), opts.pop("method"), **opts)
