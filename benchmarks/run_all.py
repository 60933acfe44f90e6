"""Run the speed benchmarks one after the other (``make bench``).

Each script prints its own table; see ``benchmarks/README.md`` for what is measured.  The peer
comparison runs in its ``--quick`` form here (N = 8 only); the full comparison is
``python benchmarks/peer_chain.py`` (20–40 min).
"""

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
RUNS = [
    ["railway_contact_speed.py"],
    ["railway_creep_speed.py"],
    ["main_job_speedups.py"],
    ["peer_chain.py", "--quick"],
]


def main() -> int:
    failed = []
    for args in RUNS:
        print(f"\n=== {' '.join(args)} ===", flush=True)
        rc = subprocess.call([sys.executable, str(HERE / args[0]), *args[1:]])
        if rc != 0:
            failed.append(args[0])
    if failed:
        print(f"benchmarks that failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
