"""The ``mbsuite`` command-line tool.

Commands::

    mbsuite list                              scenes with their titles
    mbsuite run NAME [NAME ...] [-o OUT] [--fast]
    mbsuite run --all [-o OUT] [--fast]       every scene, into OUT/<scene name>/
    mbsuite bench [PROBLEM ...] [--methods M ...] [--repeats N] [--quick|--full] [-j N] [-o OUT]
    mbsuite bench --list                      work-precision problems and methods (core.workprecision)
    mbsuite --version

Domain packages add sub-commands through entry points in group
``"mbsuite.commands"``: each loads to ``register(subparsers)``, which adds one
sub-parser and sets ``func=<callable(args) -> int>`` with ``set_defaults``. A plug-in
that fails to load is reported on stderr and skipped; the rest of the tool works.

Exit codes: 0 success, 1 one or more scenes (or a plug-in command) failed, 2 usage error.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from . import __version__
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

    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    outcomes: dict[str, tuple[Scene, str]] = {}
    failed: list[str] = []
    bar = tqdm(selected, desc="scenes", unit="scene", disable=None)
    for scene in bar:
        bar.set_postfix_str(scene.name)
        start = time.perf_counter()
        try:
            result = run_scene(scene, out_dir, fast=args.fast, progress=tqdm_progress)
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


def build_parser() -> argparse.ArgumentParser:
    """Build the argument parser, including sub-commands from plug-ins."""
    parser = argparse.ArgumentParser(
        prog="mbsuite",
        description="Cartesian multibody dynamics suite: run scenes and domain tools.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p_list = sub.add_parser("list", help="list the available scenes")
    p_list.set_defaults(func=_cmd_list)

    p_run = sub.add_parser("run", help="run scenes and write their tables and figures")
    p_run.add_argument("names", nargs="*", metavar="NAME", help="scene name(s), see `mbsuite list`")
    p_run.add_argument("--all", action="store_true", help="run every available scene")
    p_run.add_argument("-o", "--out", default="out", help="output folder (default: %(default)s)")
    p_run.add_argument("--fast", action="store_true", help="reduced resolution (smoke test)")
    p_run.set_defaults(func=_cmd_run, _parser=p_run)

    from .workprecision import register_bench_command

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
    except (ValueError, TypeError, FileNotFoundError) as exc:
        # bad input (a value, a file): the message names it; no traceback for the user
        print(f"mbsuite: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    return EXIT_OK if code is None else int(code)


if __name__ == "__main__":
    sys.exit(main())
