"""The ``mbsuite`` command line, the scene registry and scene output."""

from __future__ import annotations

import importlib.metadata
import importlib.util
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import core
from core import cli, scenes
from core.errors import InputError, NameTakenError
from core.registry import Registry
from core.results import write_table
from core.scenes import PluginLoadWarning, Scene, SceneError, SceneResult, run_scene

REPO = Path(__file__).resolve().parents[2]


def _table_scene(ctx):
    from matplotlib.figure import Figure

    n = 5 if ctx.fast else 50
    t = np.linspace(0.0, 1.0, n)
    fig = Figure()
    fig.add_subplot().plot(t, t**2)
    total = sum(ctx.progress(range(n), desc="inner"))
    return SceneResult(
        tables={"parabola": pd.DataFrame({"t [s]": t, "x [m]": t**2})},
        figures={"parabola": fig},
        notes=f"fast={ctx.fast}, sum={total}",
    )


def _broken_scene(ctx):
    raise RuntimeError("deliberate failure in scene body")


OK_SCENE = Scene("ok-scene", "A parabola", "x = t^2 sampled on [0, 1].", _table_scene)
BAD_SCENE = Scene("bad_scene", "Always fails", "Raises on purpose.", _broken_scene)


@pytest.fixture
def registry(monkeypatch):
    """An isolated scene registry holding OK_SCENE and BAD_SCENE, and no plug-ins."""
    reg = Registry("scene", scenes._check_scene)
    monkeypatch.setattr(scenes, "_REGISTRY", reg)
    monkeypatch.setattr(scenes, "_DEMO_MODULE", "core._no_such_demo_module")
    monkeypatch.setattr(scenes, "_scene_entry_points", lambda: [])
    scenes.register_scene(OK_SCENE)
    scenes.register_scene(BAD_SCENE)
    return reg


def test_version(capsys):
    assert cli.main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"mbsuite {core.__version__}"


def test_version_matches_installed_metadata():
    try:
        installed = importlib.metadata.version("mbsuite")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("mbsuite is not installed (running from a bare checkout)")
    assert installed == core.__version__


def test_help_in_subprocess():
    out = subprocess.run(
        [sys.executable, "-m", "core.cli", "--help"], capture_output=True, text=True, cwd=REPO, check=False
    )
    assert out.returncode == 0, out.stderr
    assert "list" in out.stdout and "run" in out.stdout


def test_console_script_installed():
    script = Path(sys.executable).parent / "mbsuite"
    if not script.exists():
        pytest.skip("console script not installed in this environment")
    out = subprocess.run([str(script), "--version"], capture_output=True, text=True, check=False)
    assert out.returncode == 0 and out.stdout.startswith("mbsuite ")


def test_no_command_is_usage_error(capsys):
    assert cli.main([]) == 2
    assert "usage" in capsys.readouterr().err


def test_list(registry, capsys):
    assert cli.main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split(None, 1) == ["ok-scene", "A parabola"]
    assert lines[1].split(None, 1) == ["bad_scene", "Always fails"]


def test_run_usage_errors(registry, capsys, tmp_path):
    assert cli.main(["run", "-o", str(tmp_path)]) == 2
    assert cli.main(["run", "ok-scene", "--all", "-o", str(tmp_path)]) == 2
    assert cli.main(["run", "missing", "-o", str(tmp_path)]) == 2
    assert "unknown scene(s): missing (available: ok-scene, bad_scene)" in capsys.readouterr().err


def test_run_one_scene_writes_tables_figures_readme(registry, tmp_path, capsys):
    assert cli.main(["run", "ok-scene", "-o", str(tmp_path), "--fast"]) == 0
    folder = tmp_path / "ok-scene"
    assert sorted(p.name for p in folder.iterdir()) == ["README.md", "parabola.csv", "parabola.csv-metadata.json",
                                                        "parabola.md", "parabola.png", "run.json"]
    df = pd.read_csv(folder / "parabola.csv")
    assert len(df) == 5  # fast mode reached the scene
    readme = (folder / "README.md").read_text()
    assert "# A parabola" in readme and "parabola.csv" in readme and "parabola.png" in readme
    assert "fast=True, sum=10" in readme
    assert "ok-scene" in (tmp_path / "README.md").read_text()


def test_every_output_says_how_it_was_run(registry, tmp_path, capsys):
    """run.json, the scene README's last section, the table's CSVW metadata and the line under the
    Markdown table all name the mode, wall time, processor, versions, date and git revision; the
    index lists every scene folder in OUT, also those of earlier commands."""
    import json

    from core.provenance import cpu_model, package_versions

    assert cli.main(["run", "ok-scene", "-o", str(tmp_path), "--fast"]) == 0
    folder = tmp_path / "ok-scene"
    run = json.loads((folder / "run.json").read_text())
    assert run["mode"] == "fast" and run["status"] == "ok" and run["scene"] == "ok-scene"
    assert run["processor"] == cpu_model() and run["versions"]["numpy"] == package_versions()["numpy"]
    assert run["wall_time_s"] > 0 and run["started"].endswith("+00:00") and run["git_revision"]
    readme = (folder / "README.md").read_text()
    section = readme[readme.index("## How this scene was run"):]
    for text in ("| mode | fast |", "| wall time |", cpu_model(), f"numpy {package_versions()['numpy']}",
                 "| git revision |", "| started (UTC) |"):
        assert text in section, text
    meta = json.loads((folder / "parabola.csv-metadata.json").read_text())
    assert meta["url"] == "parabola.csv" and meta["mbsuite:run"] == run
    md = (folder / "parabola.md").read_text()
    assert "mode fast" in md.splitlines()[-1] and run["git_revision"] in md.splitlines()[-1]
    # a second command into the same folder: the index keeps the first scene, with its mode
    assert cli.main(["run", "bad_scene", "-o", str(tmp_path)]) == 1
    index = (tmp_path / "README.md").read_text()
    assert "| [ok-scene](ok-scene/README.md) | A parabola | ok | fast |" in index
    assert "| [bad_scene](bad_scene/error.txt) | Always fails | failed (see bad_scene/error.txt) | default |" in index
    failed = json.loads((tmp_path / "bad_scene" / "run.json").read_text())
    assert failed["status"] == "failed" and "deliberate failure" in failed["message"]
    (tmp_path / "by-hand").mkdir()
    (tmp_path / "by-hand" / "README.md").write_text("# not a scene run\n")
    assert cli.main(["run", "ok-scene", "-o", str(tmp_path), "--full"]) == 0
    index = (tmp_path / "README.md").read_text()
    assert "| [by-hand](by-hand/README.md) |  | unknown (no run.json) |" in index
    assert "| ok | full |" in index
    capsys.readouterr()
    assert cli.main(["run", "ok-scene", "-o", str(tmp_path), "--full", "--fast"]) == 2


def _sweep_scene(ctx):
    from core.sweep import run_sweep

    squares = run_sweep(abs, [-1, -2, -3], executor=ctx.executor)
    kind = type(ctx.executor).__name__
    return SceneResult(tables={"sweep": pd.DataFrame({"x": squares, "executor": kind})})


def test_run_passes_the_sweep_executor_to_the_scenes(registry, tmp_path, capsys):
    scenes.register_scene(Scene("sweep-scene", "A sweep", "", _sweep_scene))
    assert cli.main(["run", "sweep-scene", "-o", str(tmp_path / "serial"), "--workers", "1"]) == 0
    assert cli.main(["run", "sweep-scene", "-o", str(tmp_path / "pool")]) == 0  # default: a process per core
    serial = pd.read_csv(tmp_path / "serial" / "sweep-scene" / "sweep.csv")
    pool = pd.read_csv(tmp_path / "pool" / "sweep-scene" / "sweep.csv")
    assert serial["x"].tolist() == pool["x"].tolist() == [1, 2, 3]
    assert serial["executor"].iloc[0] == "NoneType"
    assert pool["executor"].iloc[0] == "ProcessPoolExecutor"
    capsys.readouterr()
    assert cli.main(["run", "sweep-scene", "-o", str(tmp_path), "--workers", "0"]) == 2
    assert "--workers 0" in capsys.readouterr().err
    assert cli.main(["run", "sweep-scene", "-o", str(tmp_path), "--workers", "2", "--dask", "x"]) == 2


def test_run_all_continues_after_failure_and_exits_nonzero(registry, tmp_path, capsys):
    assert cli.main(["run", "--all", "-o", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "1 of 2 scene(s) failed: bad_scene" in err
    error_txt = (tmp_path / "bad_scene" / "error.txt").read_text()
    assert "RuntimeError: deliberate failure in scene body" in error_txt and "Traceback" in error_txt
    assert (tmp_path / "ok-scene" / "parabola.png").exists()
    index = (tmp_path / "README.md").read_text()
    assert "| failed (see bad_scene/error.txt) |" in index and "| ok |" in index


def test_run_scene_raises_scene_error_and_clears_stale_error(tmp_path):
    with pytest.raises(SceneError, match="bad_scene") as info:
        run_scene(BAD_SCENE, tmp_path)
    assert isinstance(info.value.__cause__, RuntimeError)
    assert (tmp_path / "bad_scene" / "error.txt").exists()
    (tmp_path / "ok-scene").mkdir()
    (tmp_path / "ok-scene" / "error.txt").write_text("stale")
    result = run_scene(OK_SCENE, tmp_path)
    assert isinstance(result, SceneResult)
    assert not (tmp_path / "ok-scene" / "error.txt").exists()


def test_scene_returning_wrong_type_fails(tmp_path):
    scene = Scene("wrong", "Wrong", "", lambda ctx: {"tables": {}})
    with pytest.raises(SceneError, match="expected SceneResult"):
        run_scene(scene, tmp_path)


def test_scene_validation_and_duplicates(registry):
    with pytest.raises(ValueError, match="lower-case"):
        Scene("Bad Name", "t", "d", _table_scene)
    with pytest.raises(ValueError, match="callable"):
        Scene("x", "t", "d", run=42)
    scenes.register_scene(OK_SCENE)  # same object again: fine
    with pytest.raises(NameTakenError, match="scene name 'ok-scene' is taken"):
        scenes.register_scene(Scene("ok-scene", "other", "", _table_scene))


def _fake_entry_point(monkeypatch, module_name, attr, value, group):
    module = types.ModuleType(module_name)
    setattr(module, attr, value)
    monkeypatch.setitem(sys.modules, module_name, module)
    return importlib.metadata.EntryPoint(name=module_name, value=f"{module_name}:{attr}", group=group)


def test_scene_plugins_from_entry_points(registry, monkeypatch):
    extra = Scene("plugin-scene", "From a plug-in", "", _table_scene)
    good = _fake_entry_point(monkeypatch, "fake_scene_plugin", "scenes", lambda: [extra], "mbsuite.scenes")
    broken = importlib.metadata.EntryPoint(
        name="broken", value="no_such_module_for_mbsuite:scenes", group="mbsuite.scenes"
    )
    monkeypatch.setattr(scenes, "_scene_entry_points", lambda: [broken, good])
    with pytest.warns(PluginLoadWarning, match="broken"):
        found = scenes.all_scenes()
    assert list(found) == ["ok-scene", "bad_scene", "plugin-scene"]

    clash = _fake_entry_point(
        monkeypatch, "clash_plugin", "scenes", lambda: [Scene("ok-scene", "dup", "", _table_scene)], "mbsuite.scenes"
    )
    monkeypatch.setattr(scenes, "_scene_entry_points", lambda: [clash])
    with pytest.raises(ValueError, match="'ok-scene' is provided by both core and plug-in clash_plugin"):
        scenes.all_scenes()


def test_command_plugins(monkeypatch, capsys):
    def register(subparsers):
        p = subparsers.add_parser("hello", help="say hello")
        p.add_argument("--name", default="world")
        p.set_defaults(func=lambda args: print(f"hello {args.name}") or 0)

    good = _fake_entry_point(monkeypatch, "fake_cmd_plugin", "register", register, "mbsuite.commands")
    broken = importlib.metadata.EntryPoint(
        name="broken", value="no_such_module_for_mbsuite.cli:register", group="mbsuite.commands"
    )
    monkeypatch.setattr(cli, "_command_entry_points", lambda: [broken, good])
    assert cli.main(["hello", "--name", "rail"]) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == "hello rail"
    assert "plug-in command 'broken'" in captured.err and "ModuleNotFoundError" in captured.err
    assert cli.main(["--help"]) == 0
    assert "hello" in capsys.readouterr().out


def test_registered_command_plugins_load():
    """Entry points declared in pyproject.toml must load once their module exists."""
    for ep in cli._command_entry_points():
        module = ep.value.split(":")[0]
        if importlib.util.find_spec(module.split(".")[0]) is None or importlib.util.find_spec(module) is None:
            continue  # the plug-in's package is still being written
        assert callable(ep.load()), ep


def test_bad_input_in_a_command_is_reported_without_traceback(capsys):
    """A ValueError raised by a command (bad value or file) becomes one line naming it, exit 2."""
    import argparse

    from core import cli

    def boom(args):
        raise ValueError("rail inclination -0.025 (given as '-1:40') is negative")

    parser = cli.build_parser()
    original = parser.parse_args

    def parse(argv=None):
        return argparse.Namespace(func=boom)

    parser.parse_args = parse
    orig_build = cli.build_parser
    cli.build_parser = lambda: parser
    try:
        code = cli.main([])
    finally:
        cli.build_parser = orig_build
        parser.parse_args = original
    err = capsys.readouterr().err
    assert code == 2
    assert "mbsuite: error: rail inclination -0.025" in err and "Traceback" not in err


def test_failed_scene_removes_the_stale_files_of_an_earlier_run(tmp_path):
    """A scene that fails must not leave an earlier run's tables and figures passing for its own: the
    files it did not rewrite are removed and listed in error.txt."""
    run_scene(OK_SCENE, tmp_path)
    folder = tmp_path / "ok-scene"
    earlier = sorted(p.name for p in folder.iterdir())
    assert "parabola.csv" in earlier and "parabola.png" in earlier
    failing = Scene("ok-scene", "Fails this time", "", _broken_scene)
    with pytest.raises(SceneError):
        run_scene(failing, tmp_path)
    assert sorted(p.name for p in folder.iterdir()) == ["error.txt", "run.json"]  # run.json: this run's record
    text = (folder / "error.txt").read_text()
    assert "removed 6 file(s) of an earlier run" in text and "parabola.csv" in text


def test_output_path_that_is_a_file_is_a_one_line_error(registry, tmp_path, capsys):
    blocker = tmp_path / "afile"
    blocker.write_text("not a folder")
    for out in (blocker, blocker / "sub"):
        assert cli.main(["run", "ok-scene", "-o", str(out)]) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "afile" in err and "is a file" in err, err
    with pytest.raises(InputError, match="it is a file"):
        write_table(pd.DataFrame({"x [m]": [1.0]}), blocker, "t")
    with pytest.raises(InputError, match="it is a file"):  # --traceback: the exception itself, for debugging
        cli.main(["--traceback", "run", "ok-scene", "-o", str(blocker)])


def test_bench_repeats_and_jobs_must_be_positive(capsys):
    for args in (["bench", "--repeats", "0"], ["bench", "-j", "-1"], ["bench", "--repeats", "two"]):
        assert cli.main(args) == 2
        assert "expected an integer >= 1" in capsys.readouterr().err


def test_library_errors_are_one_line(capsys, tmp_path):
    """A bad creep-law name is a usage error (argparse's usage, then one line naming it), no traceback."""
    code = cli.main(["railway", "creep-curve", "--model", "no-such-law", "-o", str(tmp_path)])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "Traceback" not in err and "no-such-law" in err.splitlines()[-1]


def test_atomic_write_keeps_the_old_file_when_writing_fails(tmp_path):
    from core.paths import write_atomically

    target = tmp_path / "table.csv"
    target.write_text("old, complete\n")

    def failing(p):
        p.write_text("half of a new fi")
        raise OSError("disk full")

    with pytest.raises(OSError, match="disk full"):
        write_atomically(target, failing)
    assert target.read_text() == "old, complete\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv"]


# ---------------------------------------------------------------------------------------------
# issue 21: no traceback on bad input, from any registered sub-command
# ---------------------------------------------------------------------------------------------
def _leaf_commands(parser, path=()):
    """(path, sub-parser) of every runnable sub-command (plug-ins included)."""
    import argparse

    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield path, parser
        return
    for name, sub in subs[0].choices.items():
        yield from _leaf_commands(sub, path + (name,))


def _sweep_cases():
    import argparse

    cases = []
    for path, sub in _leaf_commands(cli.build_parser()):
        cases.append((list(path) + ["--no-such-option"], "unknown option"))
        for action in sub._actions:
            if not action.option_strings or action.nargs == 0 or isinstance(action, argparse._HelpAction):
                continue
            opt = max(action.option_strings, key=len)
            if action.choices is not None:
                first = str(list(action.choices)[0])
                cases.append((list(path) + [opt, first[:-1] + "x"], "misspelt choice"))
            elif action.type is not None:  # numbers and checked names
                for bad in ("nan", "-1e30", "abc"):
                    cases.append((list(path) + [opt, bad], f"bad value {bad}"))
    return cases


_SWEEP = _sweep_cases()


@pytest.mark.parametrize("argv,what", _SWEEP, ids=[" ".join(a) for a, _ in _SWEEP])
def test_every_subcommand_refuses_bad_options_without_traceback(argv, what, capsys, tmp_path, monkeypatch):
    """Every registered sub-command (plug-ins included), every typed option: a bad value is one line
    ``mbsuite: error: ...`` naming the option, exit 2, never a traceback."""
    monkeypatch.chdir(tmp_path)  # nothing is written into the checkout
    code = cli.main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert code == 2, (argv, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("mbsuite: error: "), err
    opt = argv[-2] if what != "unknown option" else argv[-1]
    assert opt in lines[0] or opt.lstrip("-") in lines[0], lines[0]


def test_sweep_covers_every_command():
    leaves = {path for path, _ in _leaf_commands(cli.build_parser())}
    assert {("list",), ("run",), ("bench",), ("railway", "contact-table"), ("railway", "creep-curve")} <= leaves
    assert len(_SWEEP) >= 60


def _run_with_command(func, argv=()):
    """main() with a parser whose only command runs ``func``."""
    parser = cli.Parser(prog="mbsuite")
    parser.add_argument("--debug", "--traceback", dest="traceback", action="store_true")
    sub = parser.add_subparsers(dest="command")
    sub.add_parser("boom").set_defaults(func=func)
    orig = cli.build_parser
    cli.build_parser = lambda: parser
    try:
        return cli.main([*argv, "boom"])
    finally:
        cli.build_parser = orig


def test_an_internal_error_is_one_line_naming_a_bug(capsys):
    """A bug (not bad input) is reported as such: one line, exit 3, the traceback only with --debug."""
    def boom(args):
        return {}["no such key"]

    assert _run_with_command(boom) == 3
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert err.startswith("mbsuite: internal error (a bug in mbsuite, please report it): KeyError: 'no such key' "
                          "(in test_cli.py:")
    assert err.strip().endswith("run again with --debug for the traceback")
    with pytest.raises(KeyError):
        _run_with_command(boom, ["--debug"])


def test_bad_input_with_debug_shows_the_exception(capsys):
    def bad(args):
        raise InputError("--gauge-mm 1.435: deliberately bad")

    assert _run_with_command(bad) == 2
    assert capsys.readouterr().err == "mbsuite: error: --gauge-mm 1.435: deliberately bad\n"
    with pytest.raises(InputError, match="deliberately bad"):
        _run_with_command(bad, ["--debug"])


def test_a_numerical_failure_is_exit_1(capsys):
    from core.errors import NumericalFailure

    def fails(args):
        raise NumericalFailure("Newton did not converge at t = 0.25 s")

    assert _run_with_command(fails) == 1
    assert capsys.readouterr().err == ("mbsuite: error: numerical failure: Newton did not converge at t = 0.25 s "
                                       "[NumericalFailure]\n")


def test_a_warning_is_one_line_with_its_class(capsys):
    import warnings

    class DemoWarning(UserWarning):
        pass

    def warns(args):
        warnings.warn(DemoWarning("the step is\ncoarse"))
        return 0

    assert _run_with_command(warns) == 0
    assert capsys.readouterr().err == "mbsuite: warning: the step is coarse [DemoWarning]\n"


def test_misspelt_names_suggest_the_closest(registry, capsys):
    assert cli.main(["rn"]) == 2
    assert "invalid choice: 'rn'; did you mean 'run'?" in capsys.readouterr().err
    assert cli.main(["run", "ok-scen"]) == 2
    assert "unknown scene(s): ok-scen; did you mean 'ok-scene'?" in capsys.readouterr().err


def test_too_many_workers_is_refused(registry, capsys, tmp_path):
    import os

    n = 4 * (os.cpu_count() or 1) + 1
    assert cli.main(["run", "ok-scene", "-o", str(tmp_path), "--workers", str(n)]) == 2
    assert f"--workers {n}: this machine has" in capsys.readouterr().err


def test_bench_and_run_options_are_checked_before_running(registry, capsys, tmp_path):
    import os

    blocker = tmp_path / "afile"
    blocker.write_text("x")
    for argv, expected in (
        (["bench", "andrews", "-o", str(blocker)], "output folder '" + str(blocker) + "' cannot be created: it is a file"),
        (["bench", "andrews", "-j", str(4 * (os.cpu_count() or 1) + 1)], "worker processes only slow the runs down"),
        (["run", "ok-scene", "-o", str(tmp_path / "o"), "--dask", "localhost"],
         "--dask 'localhost': give the scheduler's address with its port, e.g. tcp://host:8786"),
    ):
        assert cli.main(argv) == 2
        err = capsys.readouterr().err
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1 and expected in err, err
