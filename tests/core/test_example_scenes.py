"""Scenes whose body is an example script (core.scenes.example_scene / scene_run): ``mbsuite run``
executes the file a user reads, and the file run by hand writes the same output folder."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pandas as pd
import pytest

from core.paths import repo_root
from core.scenes import SceneError, example_scene, run_scene

SCRIPT = textwrap.dedent('''
    """
    A parabola
    ==========
    """
    import pandas as pd
    from core.scenes import scene_run

    scene = scene_run("{name}")
    n = 3 if scene.fast else 7
    scene.table("parabola", pd.DataFrame({{"x": range(n), "y": [i * i for i in range(n)]}}))
    scene.note(f"mode {{scene.mode}}, n = {{n}}")
    {done}
''')


def _script(tmp_path, name="parabola-script", done="scene.done()", call_name=None):
    path = tmp_path / f"{name}.py"
    path.write_text(SCRIPT.format(name=call_name or name, done=done))
    return path


@pytest.mark.parametrize("mode, rows", [("fast", 3), ("default", 7), ("full", 7)])
def test_the_runner_executes_the_script_in_its_mode(tmp_path, mode, rows):
    scene = example_scene("parabola-script", _script(tmp_path), "A parabola", "")
    result = run_scene(scene, tmp_path / "out", mode=mode)
    assert len(result.tables["parabola"]) == rows
    folder = tmp_path / "out" / "parabola-script"
    assert json.loads((folder / "run.json").read_text())["mode"] == mode
    assert f"mode {mode}, n = {rows}" in (folder / "README.md").read_text()


def test_a_script_that_never_hands_over_its_results_fails_the_scene(tmp_path):
    scene = example_scene("parabola-script", _script(tmp_path, done="pass"), "A parabola", "")
    with pytest.raises(SceneError, match="without calling done"):
        run_scene(scene, tmp_path / "out")


def test_a_script_asking_for_another_scene_name_fails_the_scene(tmp_path):
    scene = example_scene("parabola-script", _script(tmp_path, call_name="other"), "A parabola", "")
    with pytest.raises(SceneError, match="names differ"):
        run_scene(scene, tmp_path / "out")


def test_a_missing_script_names_the_path(tmp_path):
    scene = example_scene("parabola-script", "core/no_such_example.py", "A parabola", "")
    with pytest.raises(SceneError, match="no_such_example.py"):
        run_scene(scene, tmp_path / "out")


def _run_by_hand(path, cwd, **env):
    environment = {**os.environ, "MPLBACKEND": "Agg", "MBSUITE_WORKERS": "1", **env}
    environment["PYTHONPATH"] = os.pathsep.join([str(repo_root()), environment.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, str(path)], cwd=cwd, env=environment, capture_output=True, text=True,
                          timeout=600)


def test_run_by_hand_the_script_writes_the_same_folder(tmp_path):
    """From another working directory, at MBSUITE_MODE, into MBSUITE_OUT: the folder of
    ``mbsuite run`` with the same tables and a run record."""
    path = _script(tmp_path)
    work = tmp_path / "elsewhere"
    work.mkdir()
    proc = _run_by_hand(path, work, MBSUITE_MODE="fast")
    assert proc.returncode == 0, proc.stderr
    folder = work / "out" / "parabola-script"
    assert pd.read_csv(folder / "parabola.csv")["y"].tolist() == [0, 1, 4]
    assert json.loads((folder / "run.json").read_text())["mode"] == "fast"
    proc = _run_by_hand(path, work, MBSUITE_MODE="quick")
    assert proc.returncode != 0 and "MBSUITE_MODE='quick'" in proc.stderr


def test_the_pendulum_example_runs_by_hand_from_any_directory(tmp_path):
    proc = _run_by_hand(repo_root() / "examples" / "core" / "pendulum.py", tmp_path, MBSUITE_MODE="fast",
                        MBSUITE_OUT=str(tmp_path / "results"))
    assert proc.returncode == 0, proc.stderr
    summary = pd.read_csv(tmp_path / "results" / "pendulum" / "summary.csv")
    assert (summary["status"] != "failed").all()
    # the closed forms of the example's docstring, at the accuracy of its integrator settings
    assert summary["period error [s]"].abs().max() < 1e-5
    assert summary["tension error [N]"].abs().max() < 1e-3


def test_simulate_stops_where_stop_when_says(tmp_path):
    """``simulate(stop_when=...)`` ends the run at the first output time where the condition
    holds: status finished, the outputs up to there, and the message naming the time."""
    from core import models
    from core.integrators import simulate

    model = models.simple_pendulum(length=1.0, mass=1.0, angle0=0.1)
    seen = []

    def past_first_crossing(t, q, v):  # the bob's x changes sign: a quarter period
        seen.append(q[0])
        return len(seen) > 1 and seen[-2] > 0 >= seen[-1]

    full = simulate(model, (0.0, 2.0), "radau-ggl", rtol=1e-8, atol=1e-10, n_output=201)
    res = simulate(model, (0.0, 2.0), "radau-ggl", rtol=1e-8, atol=1e-10, n_output=201, stop_when=past_first_crossing)
    assert res.status == "finished" and res.message.startswith("stopped by stop_when at t = ")
    k = len(res.t)
    assert 40 < k < 70  # a quarter of the small-amplitude period 2.006 s is 0.50 s: output 51
    np.testing.assert_allclose(res.q, full.q[:k], rtol=0, atol=1e-12)
    assert res.q[-2, 0] > 0 >= res.q[-1, 0]


def test_figures_are_queued_for_the_gallery_only_when_asked(tmp_path, monkeypatch):
    """Run by hand, a script's figures go to the documentation's scraper queue only with
    MBSUITE_SHOW_FIGURES set (so repeated runs in a session keep no figures alive), never under
    the runner."""
    import runpy

    from matplotlib.figure import Figure

    from core.scenes import figures_to_show

    script = tmp_path / "fig.py"
    script.write_text("from matplotlib.figure import Figure\nfrom core.scenes import scene_run\n"
                      "scene = scene_run('fig-script')\nscene.figure('f', Figure())\nscene.done()\n")
    monkeypatch.setenv("MBSUITE_OUT", str(tmp_path / "out"))
    monkeypatch.setenv("MBSUITE_WORKERS", "1")
    figures_to_show()
    monkeypatch.delenv("MBSUITE_SHOW_FIGURES", raising=False)
    runpy.run_path(str(script), run_name="__main__")
    assert figures_to_show() == []
    monkeypatch.setenv("MBSUITE_SHOW_FIGURES", "1")
    runpy.run_path(str(script), run_name="__main__")
    queued = figures_to_show()
    assert len(queued) == 1 and isinstance(queued[0], Figure) and figures_to_show() == []
    run_scene(example_scene("fig-script", script, "figure", ""), tmp_path / "runner")
    assert figures_to_show() == []


def test_a_bad_worker_count_for_a_script_is_named(tmp_path):
    proc = _run_by_hand(_script(tmp_path), tmp_path, MBSUITE_MODE="fast", MBSUITE_WORKERS="two")
    # the script runs no sweep: the count is read when the run record is written
    assert proc.returncode != 0 and "MBSUITE_WORKERS='two'" in proc.stderr
