"""Before/after check of the compiled hot paths: two checkouts, timed alternately on one machine.

Run:  .venv/bin/python benchmarks/regression_ab.py --old /path/to/old/checkout [--new .] [--rounds 4]

(an old checkout: ``git worktree add /tmp/old <commit>``).  Each round runs the cases once in a
fresh process for the old checkout, then once for the new one, so that a drift of the machine's
speed during the run (load, frequency) falls on both sides alike, and the order alternates between
rounds so that neither side always runs second; each side keeps its own numba
cache (``NUMBA_CACHE_DIR``), so the first round also compiles and every time is the best of
several runs after a warm-up in its process.  Cases, each in the form the speed figures use:

* the 8-link rigid chain with ``jit-dop853`` and ``jit-radau`` at rtol = atol = 1e-8 (0–1 s);
* the 8-link penalty chain (k = 1e6 N/m) with ``jit-radau`` at 1.33e-4, the tolerance of the
  Exudyn comparison;
* the railway contact search of ``railway_contact_speed.py`` (8 wheels, warm trajectory, re-seed
  every 20 calls), per call;
* the coaster train over 60 m of the circuit at 1e-8.

Prints, per case, the best time of each side over the rounds, their spread, and new / old.  The
spread (largest over smallest of a side's per-round times) is the noise: a ratio inside it is no
change.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent

CASES = r'''
import sys, time, json, os
root = sys.argv[1]
sys.path.insert(0, root); sys.path.insert(0, os.path.join(root, "benchmarks"))
os.chdir(root)
from core.integrators import simulate
from core.models import n_link_chain
out = {}
def best(f, n):
    """Best time of n runs after a warm-up; a run that did not finish is an error, not a time."""
    def checked():
        res = f()
        if res.status != "finished":
            raise RuntimeError(f"a timed run ended with status {res.status!r}: {getattr(res, 'message', '')}")
    checked()
    b = 1e9
    for _ in range(n):
        t0 = time.perf_counter(); checked(); b = min(b, time.perf_counter() - t0)
    return b
m8, s8 = n_link_chain(8), n_link_chain(8, stiff_k=1e6)
kw = dict(t_eval=[0.0, 1.0], compute_multipliers=False)
out["chain N=8, jit-dop853, 1e-8 [s]"] = best(lambda: simulate(m8, (0, 1), "jit-dop853", rtol=1e-8, atol=1e-8, **kw), 5)
out["chain N=8, jit-radau, 1e-8 [s]"] = best(lambda: simulate(m8, (0, 1), "jit-radau", rtol=1e-8, atol=1e-8, **kw), 5)
out["stiff chain N=8, jit-radau, 1.33e-4 [s]"] = best(
    lambda: simulate(s8, (0, 1), "jit-radau", rtol=1.33e-4, atol=1.33e-4, **kw), 5)
from railway_contact_speed import _vehicle_track, trajectory_poses, bench_trajectory
track = _vehicle_track()
poses = trajectory_poses(track, 801)
out["contact search, warm trajectory, per call [s]"] = min(bench_trajectory(track, poses, 20, True)[0] for _ in range(3))
from coaster.train import Train, circuit_frame, run_train
fr, _, cl = circuit_frame()
tr = Train(fr)
out["coaster, 60 m, 1e-8 [s]"] = best(lambda: run_train(tr, 10.0, 8.0, 60.0, rtol=1e-8, atol=1e-8), 3)
print("RESULT" + json.dumps(out))
'''


def _round(root: Path, cache: Path) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as f:
        f.write(CASES)
        script = f.name
    try:
        out = subprocess.run([sys.executable, script, str(root)], env=env, capture_output=True, text=True)
    finally:
        os.unlink(script)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT"):
            return json.loads(line[6:])
    raise RuntimeError(f"the cases failed in {root}:\n{out.stderr[-2000:]}")


def main(argv=None) -> int:
    import pandas as pd

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--old", required=True, help="checkout of the old version")
    p.add_argument("--new", default=str(HERE.parent), help="checkout of the new version (default: this one)")
    p.add_argument("--rounds", type=int, default=4)
    args = p.parse_args(argv)
    if args.rounds < 1:
        p.error(f"--rounds must be >= 1, got {args.rounds}")
    for opt in ("old", "new"):
        if not (Path(getattr(args, opt)) / "core").is_dir():
            p.error(f"--{opt} {getattr(args, opt)!r} is not a checkout of mbsuite (no core/ folder in it)")
    sides = {"old": Path(args.old).resolve(), "new": Path(args.new).resolve()}
    caches = {k: Path(tempfile.mkdtemp(prefix=f"mbsuite-ab-{k}-")) for k in sides}
    runs = {k: [] for k in sides}
    for r in range(args.rounds):
        for k in (("old", "new") if r % 2 == 0 else ("new", "old")):  # neither side always second
            runs[k].append(_round(sides[k], caches[k]))
            print(f"round {r + 1} {k}: " + ", ".join(f"{c} {v:.4g}" for c, v in runs[k][-1].items()), flush=True)
    rows = []
    for case in runs["old"][0]:
        o = [x[case] for x in runs["old"]]
        n = [x[case] for x in runs["new"]]
        rows.append({"case": case, "old best": min(o), "new best": min(n), "new / old": min(n) / min(o),
                     "old spread": max(o) / min(o), "new spread": max(n) / min(n)})
    from _host import host_line

    print(f"\nHost: {host_line()}; old {sides['old']}, new {sides['new']}; {args.rounds} alternated rounds")
    print(pd.DataFrame(rows).to_markdown(index=False, floatfmt=".4g"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
