"""The ``mbsuite`` command-line tool.

Commands::

    mbsuite list                              scenes with their titles
    mbsuite run NAME [NAME ...] [-o OUT] [--fast|--full] [--workers N | --dask ADDRESS]
    mbsuite run --all [-o OUT] [--fast|--full]  every scene, into OUT/<scene name>/; OUT/README.md
                                              indexes every scene folder in OUT
    mbsuite bench [PROBLEM ...] [--methods M ...] [--repeats N] [--quick|--full] [-j N] [-o OUT]
    mbsuite bench --list                      work-precision problems and methods (core.benchmarks)
    mbsuite --version

Domain packages add sub-commands through entry points in group
``"mbsuite.commands"``: each loads to ``register(subparsers)``, which adds one
sub-parser and sets ``func=<callable(args) -> int>`` with ``set_defaults``. A plug-in
that fails to load is reported on stderr and skipped; the rest of the tool works.

Exit codes: 0 success, 1 one or more scenes (or a plug-in command) failed, or a computation
failed numerically; 2 bad input (usage error); 3 an internal error (a bug in mbsuite).

Errors are one line on stderr, never a traceback:

* bad input -- an unknown option or name (the closest valid one suggested), a value outside its
  plausible range (the likely unit slip named), a missing or unreadable file, an output folder
  that is a file, contradictory options -- ``mbsuite: error: <what, where>``, exit 2
  (:class:`core.errors.MbsuiteError`, argparse's usage errors, ``OSError`` on a named file, and a
  plain ``ValueError`` raised by a library check);
* a numerical failure (:data:`core.errors.RUN_FAILURES`) -- ``mbsuite: error: numerical
  failure: ...``, exit 1;
* anything else is a bug in mbsuite -- ``mbsuite: internal error (a bug ...): <type>: <message>``
  and a hint to run again with ``--debug``, exit 3.

``--debug`` (alias ``--traceback``) lets every exception propagate with its traceback.  Python
warnings raised while a command runs are printed as one line each,
``mbsuite: warning: <message> [<WarningClass>]``.
"""

from __future__ import annotations

import argparse
import difflib
import fnmatch
import importlib.metadata
import sys
import time
import warnings
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from .errors import RUN_FAILURES, InputError, MbsuiteError
from .paths import output_folder
from .scenes import Scene, SceneError, all_scenes, run_scene, tqdm_progress, write_index

__all__ = ["COMMAND_ENTRY_POINT_GROUP", "Parser", "UsageError", "build_parser", "check_option", "main"]

COMMAND_ENTRY_POINT_GROUP = "mbsuite.commands"
EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_BUG = 0, 1, 2, 3


class UsageError(InputError):
    """A command line argparse cannot read (unknown option or choice, a value of the wrong type)."""


def _did_you_mean(value, choices) -> str:
    m = difflib.get_close_matches(str(value), [str(c) for c in choices], n=1, cutoff=0.5)
    return f"; did you mean {m[0]!r}?" if m else ""


class Parser(argparse.ArgumentParser):
    """argparse with errors raised as :class:`UsageError` (reported by :func:`main` in one line)
    and the closest valid choice suggested for a misspelt one (a sub-command name too).
    Sub-parsers (also those of plug-ins) are of this class.

    A negative number in exponent notation (``--min -1e-3``) is a value, not an option (argparse
    itself knows only ``-1`` and ``-0.5``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        import re

        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|nan)$")

    def error(self, message):  # noqa: D102 (argparse API)
        sub = self.prog.split(" ", 1)[1] if " " in self.prog else ""  # "railway creep-curve"
        raise UsageError(f"{sub + ': ' if sub else ''}{message} (see `{self.prog} --help`)")

    def _check_value(self, action, value):
        if action.choices is not None and value not in action.choices:
            choices = list(action.choices)
            raise argparse.ArgumentError(
                action, f"invalid choice: {value!r}{_did_you_mean(value, choices)} (choose from "
                        + ", ".join(map(str, choices)) + ")")


def check_option(ranges, quantity: str, value, option: str, unit: str | None = None, accept=()):
    """Check a command-line option against its plausible range; return it in SI.

    Parameters
    ----------
    ranges : core.inputs.RangeTable
        The domain's plausible ranges.
    quantity : str
        The range's key (e.g. ``"wheel_normal_load"``).
    value : float or str
        The option's value as given (in ``unit``).
    option : str
        The option's name for the message (``"--load-kN"``).
    unit : str, optional
        The option's unit (pint syntax) when it is not the range's own (``"kN"``, ``"mm"``).
    accept : iterable of str
        Quantities whose range is not enforced (``--accept``).

    Raises
    ------
    core.inputs.ImplausibleValueError
        One line in the option's unit: ``--load-kN 100000: the wheel-rail normal load must lie in
        0.5 ... 500 kN: did you mean 100000 N, i.e. --load-kN 100? (to use it deliberately:
        --accept wheel_normal_load)``.
    core.inputs.UnitError, core.errors.InputError
        Not a finite number.
    """
    from . import inputs
    from .inputs import ImplausibleValueError, _fmt, _pretty, _SLIP_UNITS, unit_registry

    tiny = getattr(inputs, "SLIP_MIN_FRACTION", 0.0)

    r = ranges[quantity]
    shown = _fmt(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)
    try:
        return ranges.check(quantity, value, where=f"{option} {shown}", unit=unit, accept=accept)
    except ImplausibleValueError as exc:
        u = unit or r.unit
        ureg = unit_registry()
        to_u = float(ureg.Quantity(1.0, r.unit).to(u).magnitude)
        lo, hi = r.low * to_u, r.high * to_u
        bounds = (f"{_fmt(lo)} ... {_fmt(hi)}" if lo > -float("inf") and hi < float("inf")
                  else f">= {_fmt(lo)}" if hi == float("inf") else f"<= {_fmt(hi)}")
        bounds += f" {_pretty(u)}" if u != "1" else ""
        msg = f"{option} {shown}: the {r.label} must lie in {bounds}"
        slip = ""
        if isinstance(value, (int, float)) and value != 0:
            for cand in (r.unit,) + _SLIP_UNITS.get(r.unit, ()):
                if cand == u:
                    continue
                si = value * float(ureg.Quantity(1.0, cand).to(r.unit).magnitude)
                # as core.inputs: in a range around zero, a tiny corrected value is no slip
                if r.low <= 0 <= r.high and abs(si) < tiny * max(abs(r.low), abs(r.high)):
                    continue
                if r.contains(si):
                    slip = (f": did you mean {shown} {_pretty(cand)}, i.e. {option} "
                            f"{_fmt(si * to_u)}?")
                    break
        msg += slip or (f" ({r.rationale})" if r.rationale else "")
        msg += f" (to use it deliberately: --accept {quantity})"
        raise ImplausibleValueError(msg, quantity=quantity, value=exc.value, suggestion=slip) from None


def _warn(message: str) -> None:
    print(f"mbsuite: warning: {message}", file=sys.stderr)


def _command_entry_points() -> list[importlib.metadata.EntryPoint]:
    return list(importlib.metadata.entry_points(group=COMMAND_ENTRY_POINT_GROUP))


def _cmd_list(args: argparse.Namespace) -> int:
    scenes = all_scenes(on_error=lambda plugin, exc: _warn(f"scene plug-in {plugin} skipped: {exc!r}"))
    if not scenes:
        print("No scenes are registered.")
        return EXIT_OK
    width = max(len(name) for name in scenes)
    for name, scene in scenes.items():
        print(f"{name:<{width}}  {scene.title}")
    return EXIT_OK


def _cmd_run(args: argparse.Namespace) -> int:
    parser: argparse.ArgumentParser = args._parser
    if args.all and args.names:
        parser.error("give scene names or --all, not both")
    if not args.all and not args.names:
        parser.error("give at least one scene name, or --all")
    scenes = all_scenes(on_error=lambda plugin, exc: _warn(f"scene plug-in {plugin} skipped: {exc!r}"))
    if args.all:
        selected = list(scenes.values())
    else:
        unknown = [n for n in args.names if n not in scenes]
        if unknown:
            known = ", ".join(scenes) or "none registered"
            hint = "".join(_did_you_mean(n, scenes) for n in unknown)
            parser.error(f"unknown scene(s): {', '.join(unknown)}{hint} (available: {known})")
        selected = [scenes[n] for n in dict.fromkeys(args.names)]
    if not selected:
        print("No scenes are registered; nothing to run.")
        return EXIT_OK

    from tqdm import tqdm

    out_dir = output_folder(args.out)
    with _sweep_executor(args) as executor:
        return _run_selected(selected, out_dir, args, executor, tqdm)


def _sweep_executor(args: argparse.Namespace):
    """The executor of the scenes' sweeps: a local process pool on every core (default; ``--workers
    N`` for N processes, ``--workers 1`` serial in this process) or a dask.distributed cluster
    (``--dask ADDRESS``, extra ``mbsuite[parallel]``). The pool starts its processes only when a
    sweep submits work."""
    import contextlib
    import concurrent.futures

    if args.workers is not None and args.dask is not None:
        raise InputError("give --workers or --dask, not both")
    if args.workers is None and args.dask is None:
        import os

        args.workers = os.cpu_count() or 1
    if args.workers is not None:
        if args.workers < 1:
            raise InputError(f"--workers {args.workers}: give a number of processes >= 1")
        import os

        cpus = os.cpu_count() or 1
        if args.workers > 4 * cpus:
            raise InputError(f"--workers {args.workers}: this machine has {cpus} processor(s); more than "
                             f"{4 * cpus} processes only slow the sweep down (use --dask for a cluster)")
        if args.workers == 1:
            return contextlib.nullcontext(None)
        return concurrent.futures.ProcessPoolExecutor(max_workers=args.workers)
    if args.dask is not None:
        if ":" not in args.dask:
            raise InputError(f"--dask {args.dask!r}: give the scheduler's address with its port, e.g. "
                             "tcp://host:8786 or host:8786")
        try:
            from dask.distributed import Client
        except ImportError:
            raise InputError("--dask needs dask.distributed: pip install 'mbsuite[parallel]'") from None

        @contextlib.contextmanager
        def _client():
            try:
                client = Client(args.dask, timeout=30)
            except OSError as exc:
                raise InputError(f"--dask {args.dask}: cannot connect to the scheduler ({exc})") from None
            with client:
                yield client.get_executor()

        return _client()
    return contextlib.nullcontext(None)


def _run_selected(selected, out_dir, args, executor, tqdm) -> int:
    import concurrent.futures

    if isinstance(executor, concurrent.futures.ProcessPoolExecutor) and len(selected) > 1:
        return _run_side_by_side(selected, out_dir, args, executor, tqdm)
    failed: list[str] = []
    begin = time.perf_counter()
    bar = tqdm(selected, desc="scenes", unit="scene", disable=None)
    for scene in bar:
        bar.set_postfix_str(scene.name)
        start = time.perf_counter()
        try:
            result = run_scene(scene, out_dir, mode=args.mode, progress=tqdm_progress, executor=executor,
                               workers=args.workers or 1)
        except SceneError as exc:
            failed.append(scene.name)
            tqdm.write(f"FAILED {scene.name}: {exc}", file=sys.stderr)
            continue
        tqdm.write(
            f"ok     {scene.name} -> {out_dir / scene.name} "
            f"({len(result.tables)} tables, {len(result.figures)} figures, {time.perf_counter() - start:.1f} s)"
        )
    bar.close()
    return _finish_run(selected, failed, out_dir, begin, f"mode {args.mode}")


def _finish_run(selected, failed, out_dir, begin, how) -> int:
    """The index of ``out_dir`` and the command's last line and exit status."""
    write_index(out_dir)
    if failed:
        print(f"mbsuite: {len(failed)} of {len(selected)} scene(s) failed: {', '.join(failed)}", file=sys.stderr)
        return EXIT_FAILURE
    print(f"mbsuite: {len(selected)} scene(s) written to {out_dir} in {time.perf_counter() - begin:.0f} s "
          f"({how}); index: {out_dir / 'README.md'}")
    return EXIT_OK


def _run_side_by_side(selected, out_dir, args, pool, tqdm) -> int:
    """Several scenes on a local pool: the sweep scenes here, the others whole in the pool's free
    processes (:mod:`core.scene_scheduler`)."""
    import threading

    from .scene_scheduler import run_scenes

    begin = time.perf_counter()
    bar = tqdm(total=len(selected), desc="scenes", unit="scene", disable=None)
    lock = threading.Lock()

    def report(o) -> None:
        with lock:
            if o.ok:
                tqdm.write(f"ok     {o.name} -> {out_dir / o.name} ({o.tables} tables, {o.figures} figures, "
                           f"{o.wall_time_s:.1f} s{', in a pool process' if o.where == 'pool' else ''})")
            else:
                tqdm.write(f"FAILED {o.name}: {o.message}", file=sys.stderr)
            bar.update(1)

    outcomes = run_scenes(selected, out_dir, pool, args.workers, mode=args.mode, progress=tqdm_progress,
                          report=report)
    bar.close()
    return _finish_run(selected, [o.name for o in outcomes if not o.ok], out_dir, begin,
                       f"mode {args.mode}; {args.workers} processes, scenes side by side")


def _cmd_bench(args: argparse.Namespace) -> int:
    from .benchmarks import (
        PROBLEMS,
        available_methods,
        fastest_to_tolerance,
        problem_sets,
        run_problem_set,
        write_work_precision,
    )

    if args.list:
        sets = problem_sets()
        width = max(len(n) for n in PROBLEMS)
        for name, p in PROBLEMS.items():
            tags = ",".join(s for s in ("quick", "standard") if name in sets[s]) or "-"
            print(f"{name:<{width}}  [{tags}]  {p.title}")
        print("\nsets: " + "; ".join(f"{k}: {len(v)} problems" for k, v in sets.items()))
        print("methods: " + ", ".join(available_methods()))
        return 0
    grid = "quick" if args.quick else ("full" if args.full else "standard")
    names = list(args.problems) or problem_sets()[grid]
    expanded: list[str] = []
    sets = problem_sets()
    for n in names:
        if n in sets:
            expanded += sets[n]
        elif n in PROBLEMS:
            expanded.append(n)
        else:
            matches = [p for p in PROBLEMS if fnmatch.fnmatchcase(p, n)]
            if not matches:
                args._parser.error(f"unknown problem {n!r}{_did_you_mean(n, list(PROBLEMS) + list(sets))}; "
                                   "see `mbsuite bench --list`")
            expanded += matches
    expanded = list(dict.fromkeys(expanded))
    methods = None
    if args.methods:
        methods = [m for item in args.methods for m in item.split(",") if m]
        registry = available_methods()
        unknown = [m for m in methods if m not in registry]
        if unknown:
            hint = "".join(_did_you_mean(m, registry) for m in unknown)
            args._parser.error(f"unknown method(s) {unknown}{hint}; registered: {', '.join(registry)}")
    import os

    cpus = os.cpu_count() or 1
    if args.jobs > 4 * cpus:
        raise InputError(f"-j {args.jobs}: this machine has {cpus} processor(s); more than {4 * cpus} worker "
                         "processes only slow the runs down (and distort the timings)")
    output_folder(args.out)  # a file in the way is refused before the runs, not after them
    start = time.perf_counter()
    df = run_problem_set(expanded, grid, methods=methods, repeats=args.repeats, jobs=args.jobs, progress=True,
                           report=lambda s: print(s, file=sys.stderr))
    written = write_work_precision(df, args.out)
    summary = fastest_to_tolerance(df)
    from .results import markdown_table

    print(markdown_table(summary, floatfmt=".3g"))
    print(f"mbsuite bench: {len(df)} runs of {len(expanded)} problem(s) in {time.perf_counter() - start:.1f} s "
          f"-> {args.out} ({len(written) - 1} tables + figures, summary)")
    return 0


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1 (``--repeats 0`` would time nothing and report a median of nothing)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {value}")
    return value


def register_bench_command(subparsers) -> None:
    """Add ``mbsuite bench`` (the work-precision harness of :mod:`core.benchmarks`) to an argparse
    sub-parser collection; the package is imported only when the command runs."""
    p = subparsers.add_parser(
        "bench", help="work-precision benchmark: error vs run time of every integrator",
        description=("Run benchmark problems with every integrator over tolerance / step-size grids and write "
                     "<out>/wp_<problem>.csv/.md/.png and wp_summary.csv/.md. PROBLEM may be a problem name, a "
                     "glob (chain*), or a set name (quick, standard, full); default: the standard set "
                     "(--quick: the quick set)."))
    p.add_argument("problems", nargs="*", metavar="PROBLEM", help="problem names, globs or sets (see --list)")
    p.add_argument("--list", action="store_true", help="list problems, sets and registered methods")
    p.add_argument("--methods", nargs="+", metavar="METHOD", help="integrator names (default: the grid's)")
    p.add_argument("--repeats", type=positive_int, default=3, help="solves per case; wall time = median (default 3)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="CI-sized grids (about a minute for the quick set)")
    g.add_argument("--full", action="store_true", help="full grids: every method, rtol 1e-3..1e-10 (long)")
    p.add_argument("-j", "--jobs", type=positive_int, default=1, help="worker processes (default 1: serial)")
    p.add_argument("-o", "--out", default="out/bench", help="output folder (default: %(default)s)")
    p.set_defaults(func=_cmd_bench, _parser=p)


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser, including sub-commands from plug-ins."""
    parser = Parser(
        prog="mbsuite",
        description="Cartesian multibody dynamics suite: run scenes and domain tools.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--debug", "--traceback", dest="traceback", action="store_true",
                        help="on an error, show the Python traceback instead of the one-line message (debugging)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p_list = sub.add_parser("list", help="list the available scenes")
    p_list.set_defaults(func=_cmd_list)

    p_run = sub.add_parser("run", help="run scenes and write their tables and figures")
    p_run.add_argument("names", nargs="*", metavar="NAME", help="scene name(s), see `mbsuite list`")
    p_run.add_argument("--all", action="store_true", help="run every available scene")
    p_run.add_argument("-o", "--out", default="out", help="output folder (default: %(default)s)")
    modes = p_run.add_mutually_exclusive_group()
    modes.add_argument("--fast", dest="mode", action="store_const", const="fast", default="default",
                       help="reduced resolution (smoke test)")
    modes.add_argument("--full", dest="mode", action="store_const", const="full",
                       help="also the exhaustive computations (each scene's README says what this adds)")
    p_run.add_argument("--workers", type=int, default=None, metavar="N",
                       help="run the scenes' parameter sweeps on N local processes (default: one per core; "
                            "1 = serially in this process)")
    p_run.add_argument("--dask", default=None, metavar="ADDRESS",
                       help="run the scenes' parameter sweeps on a dask.distributed scheduler "
                            "(e.g. tcp://host:8786; extra mbsuite[parallel])")
    p_run.set_defaults(func=_cmd_run, _parser=p_run)

    register_bench_command(sub)

    for ep in _command_entry_points():
        try:
            register = ep.load()
            register(sub)
        except Exception as exc:  # a broken plug-in must not break the tool
            _warn(f"plug-in command {ep.name!r} ({ep.value}) is unavailable: {type(exc).__name__}: {exc}")
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None):
    text = " ".join(str(message).split())
    print(f"mbsuite: warning: {text} [{category.__name__}]", file=sys.stderr)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``mbsuite`` command line and return the exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` if None.

    Returns
    -------
    int
        0 success; 1 a scene or a computation failed; 2 bad input (one line on stderr,
        ``mbsuite: error: ...``); 3 an internal error (a bug: one line, the traceback with
        ``--debug``).  See the module docstring.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = any(a in ("--debug", "--traceback") for a in argv)
    with warnings.catch_warnings():
        # a warning while a command runs is one line on stderr, whatever the caller's filters
        # (pytest's "error" included); --debug keeps the caller's filters
        if not debug:
            warnings.simplefilter("default")
            warnings.showwarning = _show_warning
        try:
            return _main(argv)
        except SystemExit as exc:  # --help/--version (0), parser.exit() and argparse's own exits
            return exc.code if isinstance(exc.code, int) else EXIT_USAGE
        except BrokenPipeError:  # output piped into `head`: stop quietly
            import os

            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return EXIT_FAILURE
        except KeyboardInterrupt:
            if debug:
                raise
            print("mbsuite: interrupted", file=sys.stderr)
            return 130
        except RUN_FAILURES as exc:  # a computation that failed numerically (LinAlgError is a ValueError)
            if debug:
                raise
            print(f"mbsuite: error: numerical failure: {_one_line(exc)} [{type(exc).__name__}]", file=sys.stderr)
            return EXIT_FAILURE
        except (MbsuiteError, ValueError) as exc:
            # bad input: the message names the option, value or file; one line, exit 2.  A plain
            # ValueError is taken for a library check not yet turned into an InputError.
            if debug:
                raise
            print(f"mbsuite: error: {_one_line(exc)}", file=sys.stderr)
            return EXIT_USAGE
        except OSError as exc:  # a file or folder that cannot be read or written: name it
            if debug:
                raise
            text = _one_line(exc)
            if exc.filename:
                text = f"{exc.strerror or type(exc).__name__}: {exc.filename}"
            print(f"mbsuite: error: {text}", file=sys.stderr)
            return EXIT_USAGE
        except Exception as exc:  # a bug in mbsuite (or in a plug-in): say so, traceback with --debug
            if debug:
                raise
            where = ""
            tb = exc.__traceback__
            while tb is not None and tb.tb_next is not None:
                tb = tb.tb_next
            if tb is not None:
                where = f" (in {Path(tb.tb_frame.f_code.co_filename).name}:{tb.tb_lineno})"
            print(f"mbsuite: internal error (a bug in mbsuite, please report it): {type(exc).__name__}: "
                  f"{_one_line(exc)}{where}; run again with --debug for the traceback", file=sys.stderr)
            return EXIT_BUG


def _main(argv: list[str]) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    code = func(args)
    return EXIT_OK if code is None else int(code)


if __name__ == "__main__":
    sys.exit(main())
