"""Speed of the normal and tangential contact laws, vectorised over many contacts.

Run as ``python benchmarks/railway_creep_speed.py``.  Prints, for each law, the wall time of one
call over n contacts and the time per contact; for Hertz and FASTSIM also the ratio to a Python
loop calling the same law one contact at a time (measured side by side in this run).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from railway.contact.creep import CREEP_MODELS, get_creep_model  # noqa: E402
from core.contact_laws import hertz_from_load  # noqa: E402


def _best(fn, repeat=5):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(n: int = 10_000, n_loop: int = 200, seed: int = 0) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    xi, eta = rng.normal(size=(2, n)) * 3e-3
    phi = rng.normal(size=n) * 0.5
    N = rng.uniform(2e4, 1.2e5, n)
    A = rng.uniform(0.5, 5.0, n)
    B = rng.uniform(0.5, 50.0, n)
    E, nu, mu = 2.1e11, 0.28, 0.3
    G = E / (2 * (1 + nu))
    h = hertz_from_load(N, A, B, E, nu, E, nu)
    a, b = h.a, h.b
    rows = []
    t_vec = _best(lambda: hertz_from_load(N, A, B, E, nu, E, nu))
    t_loop = _best(lambda: [hertz_from_load(N[i], A[i], B[i], E, nu, E, nu) for i in range(n_loop)], 2)
    rows.append(("hertz_from_load", n, t_vec, t_vec / n * 1e6, t_loop / n_loop / (t_vec / n)))
    for name in sorted(CREEP_MODELS):
        m = get_creep_model(name)
        t_vec = _best(lambda: m(xi, eta, phi, N, a, b, G, nu, mu), 3 if name == "fastsim" else 5)
        ratio = np.nan
        if name == "fastsim":
            t_loop = _best(lambda: [m(xi[i], eta[i], phi[i], N[i], a[i], b[i], G, nu, mu)
                                    for i in range(n_loop)], 2)
            ratio = t_loop / n_loop / (t_vec / n)
        rows.append((name, n, t_vec, t_vec / n * 1e6, ratio))
    df = pd.DataFrame(rows, columns=["law", "n contacts", "wall [s]", "per contact [us]",
                                     "loop/vectorised [-]"])
    from _calibration import calibrate, header_lines, with_calibration

    cal = calibrate()
    df = with_calibration(df, cal, ["wall [s]"])
    print("\n".join(header_lines(cal)))
    print(df.to_markdown(index=False, floatfmt=".4g"))
    return df


if __name__ == "__main__":
    main()
