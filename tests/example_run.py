"""Run an example script as a user does: ``python examples/<domain>/<name>.py`` from a temporary
working directory, in fast mode, one worker, output into ``<tmp>/out``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run_example(script: str, scene: str, tmp_path: Path, timeout: float = 600) -> Path:
    """Run ``examples/<script>`` with cwd ``tmp_path`` (MBSUITE_MODE=fast, MBSUITE_OUT=tmp_path/out,
    MBSUITE_WORKERS=1), check it succeeded and that its ``run.json`` says scene ``scene``, mode fast,
    status ok; return the scene's output folder."""
    env = os.environ | {"MBSUITE_MODE": "fast", "MBSUITE_OUT": str(tmp_path / "out"), "MBSUITE_WORKERS": "1",
                        "MPLBACKEND": "Agg"}
    done = subprocess.run([sys.executable, str(EXAMPLES / script)], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=timeout)
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "out" / scene
    run = json.loads((folder / "run.json").read_text(encoding="utf-8"))
    assert run["mode"] == "fast" and run["scene"] == scene and run["status"] == "ok", run
    return folder


def tables_written(folder: Path, stems) -> list[str]:
    """The stems of ``stems`` whose ``.csv`` or ``.md`` is missing from ``folder``."""
    return [s for s in stems if not ((folder / f"{s}.csv").is_file() and (folder / f"{s}.md").is_file())]
