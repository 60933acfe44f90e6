"""The ``mbsuite`` command-line tool.

Commands::

    mbsuite list                              scenes with their titles
    mbsuite run NAME [NAME ...] [-o OUT] [--fast] [--workers N | --dask ADDRESS]
    mbsuite run --all [-o OUT] [--fast]       every scene, into OUT/<scene name>/
    mbsuite bench [PROBLEM ...] [--methods M ...] [--repeats N] [--quick|--full] [-j N] [-o OUT]
    mbsuite bench --list                      work-precision problems and methods (core.benchmarks)
    mbsuite --version

Domain packages add sub-commands through entry points in group
``"mbsuite.commands"``: each loads to ``register(subparsers)``, which adds one
sub-parser and sets ``func=<callable(args) -> int>`` with ``set_defaults``. A plug-in
that fails to load is reported on stderr and skipped; the rest of the tool works.

Exit codes: 0 success, 1 one or more scenes (or a plug-in command) failed, 2 usage error.
"""

from __future__ import annotations

import argparse
import fnmatch
import importlib.metadata
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from . import __version__
from .errors import InputError, MbsuiteError
from .paths import output_folder
from .scenes import Scene, SceneError, all_scenes, run_scene, tqdm_progress

__all__ = ["COMMAND_ENTRY_POINT_GROUP", "build_parser", "main"]

COMMAND_ENTRY_POINT_GROUP = "mbsuite.commands"
EXIT_OK, EXIT_FAILURE, EXIT_USAGE = 0, 1, 2


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


def _write_index(out_dir: Path, outcomes: dict[str, tuple[Scene, str]]) -> None:
    lines = ["# mbsuite output", "", "| scene | title | status |", "|---|---|---|"]
    for name, (scene, status) in outcomes.items():
        lines.append(f"| [{name}]({name}/README.md) | {scene.title} | {status} |")
    (out_dir / "README.md").write_text("\n".join(lines) + "\n", encoding="utf-8")


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
            parser.error(f"unknown scene(s): {', '.join(unknown)} (available: {known})")
        selected = [scenes[n] for n in dict.fromkeys(args.names)]
    if not selected:
        print("No scenes are registered; nothing to run.")
        return EXIT_OK

    from tqdm import tqdm

    out_dir = output_folder(args.out)
    with _sweep_executor(args) as executor:
        return _run_selected(selected, out_dir, args, executor, tqdm)


def _sweep_executor(args: argparse.Namespace):
    """The executor of the scenes' sweeps: serial (None), a local process pool (``--workers N``)
    or a dask.distributed cluster (``--dask ADDRESS``, extra ``mbsuite[parallel]``)."""
    import contextlib
    import concurrent.futures

    if args.workers is not None and args.dask is not None:
        raise InputError("give --workers or --dask, not both")
    if args.workers is not None:
        if args.workers < 1:
            raise InputError(f"--workers {args.workers}: give a number of processes >= 1")
        return concurrent.futures.ProcessPoolExecutor(max_workers=args.workers)
    if args.dask is not None:
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
    outcomes: dict[str, tuple[Scene, str]] = {}
    failed: list[str] = []
    bar = tqdm(selected, desc="scenes", unit="scene", disable=None)
    for scene in bar:
        bar.set_postfix_str(scene.name)
        start = time.perf_counter()
        try:
            result = run_scene(scene, out_dir, fast=args.fast, progress=tqdm_progress, executor=executor)
        except SceneError as exc:
            failed.append(scene.name)
            outcomes[scene.name] = (scene, "failed")
            tqdm.write(f"FAILED {scene.name}: {exc}", file=sys.stderr)
            continue
        outcomes[scene.name] = (scene, "ok")
        tqdm.write(
            f"ok     {scene.name} -> {out_dir / scene.name} "
            f"({len(result.tables)} tables, {len(result.figures)} figures, {time.perf_counter() - start:.1f} s)"
        )
    bar.close()
    _write_index(out_dir, outcomes)
    if failed:
        print(f"mbsuite: {len(failed)} of {len(selected)} scene(s) failed: {', '.join(failed)}", file=sys.stderr)
        return EXIT_FAILURE
    print(f"mbsuite: {len(selected)} scene(s) written to {out_dir}")
    return EXIT_OK


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
                args._parser.error(f"unknown problem {n!r}; see `mbsuite bench --list`")
            expanded += matches
    expanded = list(dict.fromkeys(expanded))
    methods = None
    if args.methods:
        methods = [m for item in args.methods for m in item.split(",") if m]
        registry = available_methods()
        unknown = [m for m in methods if m not in registry]
        if unknown:
            args._parser.error(f"unknown method(s) {unknown}; registered: {', '.join(registry)}")
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
    parser = argparse.ArgumentParser(
        prog="mbsuite",
        description="Cartesian multibody dynamics suite: run scenes and domain tools.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--traceback", action="store_true",
                        help="on an error, show the Python traceback instead of the one-line message (debugging)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p_list = sub.add_parser("list", help="list the available scenes")
    p_list.set_defaults(func=_cmd_list)

    p_run = sub.add_parser("run", help="run scenes and write their tables and figures")
    p_run.add_argument("names", nargs="*", metavar="NAME", help="scene name(s), see `mbsuite list`")
    p_run.add_argument("--all", action="store_true", help="run every available scene")
    p_run.add_argument("-o", "--out", default="out", help="output folder (default: %(default)s)")
    p_run.add_argument("--fast", action="store_true", help="reduced resolution (smoke test)")
    p_run.add_argument("--workers", type=int, default=None, metavar="N",
                       help="run the scenes' parameter sweeps on N local processes (default: serial)")
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


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``mbsuite`` command line and return the exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` if None.
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help/--version (0) and usage errors (2)
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    try:
        code = func(args)
    except SystemExit as exc:  # parser.error() inside a command
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    except (MbsuiteError, ValueError, TypeError, OSError) as exc:
        # bad input (a value, a name, a file or folder): the message names it; one line, no traceback
        # (--traceback shows it for debugging)
        if getattr(args, "traceback", False):
            raise
        text = " ".join(str(exc).split()) or type(exc).__name__
        if isinstance(exc, OSError) and not isinstance(exc, MbsuiteError):
            text = f"{exc.strerror or type(exc).__name__}: {exc.filename}" if exc.filename else text
        print(f"mbsuite: error: {text}", file=sys.stderr)
        return EXIT_USAGE
    return EXIT_OK if code is None else int(code)


if __name__ == "__main__":
    sys.exit(main())
