"""Benchmark sets: every ``benchmarks/*.toml`` with a ``[reference]`` table is solved and the
quantity it names is compared with the published or analytic value.

``quantity`` forms: ``[-]probe.NAME.COMP`` with COMP one of x, y, z, radial (along the position
vector from the origin), radial_xy (along the position's projection on the xy-plane, for
cylinders), norm; or ``max_displacement``.  Values are in the file's units.
"""
from __future__ import annotations

import fnmatch
import time
from pathlib import Path
from typing import Callable

import numpy as np

from .errors import ProblemError
from .problem.config import load_problem
from .solve.linear import solve_linear
from .solve.output import result_record


def quantity(rec: dict, expr: str) -> float:
    """Evaluate a reference quantity expression on a result record."""
    sign = -1.0 if expr.startswith("-") else 1.0
    body = expr.lstrip("-").strip()
    if body == "max_displacement":
        return sign * rec["max_displacement"]
    parts = body.split(".")
    if len(parts) != 3 or parts[0] != "probe" or parts[1] not in rec["probes"]:
        raise ProblemError(f"reference quantity {expr!r}: expected probe.NAME.COMP with a defined probe")
    p = rec["probes"][parts[1]]
    u, x = np.array(p["displacement"]), np.array(p["position"])
    comp = parts[2]
    if comp in ("x", "y", "z"):
        return sign * float(u["xyz".index(comp)])
    if comp == "radial":
        return sign * float(u @ x / np.linalg.norm(x))
    if comp == "radial_xy":
        return sign * float(u[:2] @ x[:2] / np.linalg.norm(x[:2]))
    if comp == "norm":
        return sign * float(np.linalg.norm(u))
    raise ProblemError(f"reference quantity {expr!r}: unknown component {comp!r}")


def run_benchmark(path: Path) -> dict:
    """Solve one benchmark file; return its comparison record."""
    t0 = time.perf_counter()
    spec = load_problem(path)
    sol = solve_linear(spec.problem, backend=spec.backend)
    seconds = time.perf_counter() - t0
    rec = result_record(spec, sol)
    ref = spec.reference
    value = quantity(rec, ref["quantity"])
    reference = float(ref["value"])
    tol = ref.get("tolerance")
    rel = (value - reference) / abs(reference)
    return {
        "name": spec.name, "reference": reference, "value": value, "rel_error": rel,
        "tolerance": tol, "passed": bool(tol is None or abs(rel) <= tol),
        "n_control": rec["n_control"], "seconds": seconds, "source": ref.get("source", ""),
        "units": rec["units"]["length"],
    }


def run_linear_benchmarks(folder: Path, pattern: str = "*",
                          progress: Callable[[str], None] = lambda m: None) -> list[dict]:
    files = sorted(folder.glob("*.toml"))
    if not files:
        raise ProblemError(f"no benchmark files (*.toml) in {folder}")
    records = []
    for f in files:
        if not fnmatch.fnmatch(f.stem, pattern):
            continue
        progress(f"benchmark {f.stem} ...")
        r = run_benchmark(f)
        progress(f"  {r['name']}: {r['value']:.6g} vs {r['reference']:.6g} ({100 * r['rel_error']:+.2f} %), "
                 f"{r['n_control']} control vertices, {r['seconds']:.1f} s")
        records.append(r)
    return records


def format_table(records: list[dict]) -> str:
    lines = ["| benchmark | reference | graspdef | error | tolerance | control vertices | time [s] |",
             "|---|---|---|---|---|---|---|"]
    for r in records:
        tol = "report only" if r["tolerance"] is None else f"{100 * r['tolerance']:.1f} %"
        mark = "" if r["passed"] else " (outside)"
        lines.append(f"| {r['name']} | {r['reference']:.6g} | {r['value']:.6g} | {100 * r['rel_error']:+.2f} %{mark} "
                     f"| {tol} | {r['n_control']} | {r['seconds']:.1f} |")
    return "\n".join(lines)
