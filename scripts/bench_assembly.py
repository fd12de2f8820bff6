"""Speed of one Newton iteration's assembly of the nonlinear shell energy at ~10k control vertices.

Full sphere (R = 32.5 mm, t = 2.5 mm, neo-Hookean mu = 1/3 MPa, ``sphere(0.0325, 5)``: 10,242
control vertices), deformed state x = 1.01 X.  Medians of ``--repeats`` (>= 5) runs each, after one
warm-up call (numba compilation / cache load):

* ``ShellEnergy.hessian`` (energy, gradient and sparse Hessian),
* ``ShellEnergy.gradient`` (energy and gradient),
* ``ShellEnergy.energy``,
* the KKT factorisation and solve of the Hessian with the six rigid modes fixed (``KKTSystem``).

Also recorded: the median CPU time of the process (all threads) and the load average, since
wall times on a shared machine depend on the other load.

Target: 20 load steps of a squeezed sphere in <= 30 s, i.e. roughly <= 0.5 s per Hessian and
<= 0.5 s per gradient + energy.  Writes ``bench_assembly.json`` to ``--out``.

    python scripts/bench_assembly.py [--level 5] [--repeats 7] [--out out]
"""
from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np


def _median_time(fun, repeats: int) -> tuple[float, list[float], float]:
    """Median wall time, all wall times, median CPU time of the process (all threads; less
    sensitive than wall time to other load on a shared machine)."""
    ts, cs = [], []
    for _ in range(repeats):
        c = time.process_time()
        t = time.perf_counter()
        fun()
        ts.append(time.perf_counter() - t)
        cs.append(time.process_time() - c)
    return statistics.median(ts), ts, statistics.median(cs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--level", type=int, default=5, help="icosphere subdivision level (5: 10,242 vertices)")
    ap.add_argument("--repeats", type=int, default=7, help="timed runs per quantity (>= 5)")
    ap.add_argument("--no-kkt", action="store_true", help="skip the KKT factor/solve timing")
    ap.add_argument("--out", default="out")
    a = ap.parse_args()
    if a.repeats < 5:
        ap.error("--repeats must be >= 5")

    import numba

    from graspdef.geometry import sphere
    from graspdef.shell.energy import ShellEnergy
    from graspdef.shell.hyperelastic import NeoHookean
    from graspdef.shell.model import Shell

    m = sphere(0.0325, a.level)
    t = time.perf_counter()
    sh = Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), 0.0025)
    t_shell = time.perf_counter() - t
    E = ShellEnergy(sh)
    x = sh.rest_positions * 1.01
    t = time.perf_counter()
    e, g, H = E.hessian(x)                    # warm-up: numba compile/cache load, block pattern
    t_first = time.perf_counter() - t
    E.gradient(x)
    E.energy(x)
    res = {"n_control": int(sh.n_control), "n_faces": int(len(sh.faces)), "repeats": a.repeats,
           "numba_threads": int(numba.get_num_threads()), "python": sys.version.split()[0],
           "machine": platform.machine(), "shell_setup_s": t_shell, "first_hessian_s": t_first,
           "energy_value": float(e), "grad_norm": float(np.linalg.norm(g)), "hessian_nnz": int(H.nnz)}
    med = {}
    runs = {}
    cpu = {}
    for name, fun in (("hessian", lambda: E.hessian(x)), ("gradient", lambda: E.gradient(x)),
                      ("energy", lambda: E.energy(x))):
        med[name], runs[name], cpu[name] = _median_time(fun, a.repeats)
        print(f"{name:9s} median {med[name]:.3f} s (cpu {cpu[name]:.3f} s)  runs "
              f"{' '.join(f'{v:.3f}' for v in runs[name])}", flush=True)
    if not a.no_kkt:
        from graspdef.problem.problem import Problem
        from graspdef.problem.supports import RigidModes
        from graspdef.solve.sparse import KKTSystem

        C, _ = Problem(sh, [], [RigidModes()]).constraints()
        kk = KKTSystem(C)
        kk.factor(H)                                          # first factor: symbolic analysis
        kk.solve(g)
        tf, ts = [], []
        for _ in range(a.repeats):
            t = time.perf_counter()
            kk.factor(H)
            t1 = time.perf_counter()
            kk.solve(g)
            tf.append(t1 - t)
            ts.append(time.perf_counter() - t1)
        med["kkt_factor"], med["kkt_solve"] = statistics.median(tf), statistics.median(ts)
        runs["kkt_factor"], runs["kkt_solve"] = tf, ts
        res["kkt_backend"] = getattr(kk, "backend", None)
        res["kkt_n_negative"] = getattr(kk, "n_negative", None)
        print(f"kkt factor median {med['kkt_factor']:.3f} s  solve median {med['kkt_solve']:.3f} s "
              f"(backend {res['kkt_backend']}, n_negative {res['kkt_n_negative']})", flush=True)
    res["median_s"] = med
    res["cpu_median_s"] = cpu
    res["load_average"] = list(__import__("os").getloadavg())
    res["runs_s"] = runs
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "bench_assembly.json").write_text(json.dumps(res, indent=2))
    print(f"wrote {out / 'bench_assembly.json'}")


if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    main()
