"""The memory a solve of a shell needs, estimated from its control-vertex count, against what
the machine has: a mesh too large is refused with the estimate before anything is built."""
from __future__ import annotations

from ..errors import ProblemError

#: peak memory of a nonlinear solve per control vertex [bytes] and its fixed part, fitted to peak
#: resident sizes measured on spheres of 642 to 40,962 control vertices (scripts/memory_estimate.py)
BYTES_PER_VERTEX = 60_000.0
BYTES_FIXED = 400e6
#: the same with the factor on disk (backend "pardiso-ooc"): the linear 100k pinched cylinder peaked
#: at 2.94 GiB out of core against 4.84 GiB in core (scripts/bench_speed.py --backend pardiso-ooc),
#: 27 kB per vertex above the fixed part; rounded up for the nonlinear path's states
BYTES_PER_VERTEX_OUT_OF_CORE = 30_000.0
#: a linear solve (one Hessian, one factor) per control vertex above BYTES_FIXED, by the precision of
#: its factor: the 100,800-vertex pinched cylinder peaked at 2.65 GiB with the mixed-precision factor
#: (24 kB per vertex above the fixed part) and at 4.21 GiB with the double one (41 kB), one process
#: each (VmHWM, 2026-11-27, docs/speed.md, "Mixed precision"); rounded up.  "auto" is mixed from 20,000
#: unknowns on and double below, where either estimate is under 0.7 GB
BYTES_PER_VERTEX_LINEAR = {"mixed": 30_000.0, "auto": 30_000.0, "double": 45_000.0}


def memory_estimate(n_vertices: int, out_of_core: bool = False, linear: str | None = None) -> float:
    """Peak memory [bytes] of a solve of a shell with ``n_vertices`` control vertices: a nonlinear
    path's (assembly, the sparse factorisation, the path's states), or with ``linear`` (the factor's
    precision: "auto", "mixed" or "double") a linear solve's; ``out_of_core``: the factor on disk."""
    if out_of_core:
        per = BYTES_PER_VERTEX_OUT_OF_CORE
    elif linear is not None:
        per = BYTES_PER_VERTEX_LINEAR[linear]
    else:
        per = BYTES_PER_VERTEX
    return BYTES_FIXED + per * float(n_vertices)


def available_memory() -> float | None:
    """Memory the machine can give this process now [bytes] (None: unknown)."""
    try:
        import psutil
    except ImportError:
        return None
    return float(psutil.virtual_memory().available)


def check_memory(n_vertices: int, what: str, available: float | None = None, out_of_core: bool = False,
                 linear: str | None = None) -> float:
    """Refuse a shell whose estimated solve memory exceeds what the machine has; returns the
    estimate.  ``out_of_core``: the solve keeps its factor on disk (backend "pardiso-ooc");
    ``linear``: a linear solve with a factor of that precision (:func:`memory_estimate`)."""
    need = memory_estimate(n_vertices, out_of_core, linear)
    have = available_memory() if available is None else available
    if have is not None and need > have:
        hint = "use fewer faces"
        if linear == "double" and not out_of_core and memory_estimate(n_vertices, False, "mixed") <= have:
            hint += (f", or [solver] precision = \"mixed\" (a single-precision factor refined in double: about "
                     f"{memory_estimate(n_vertices, False, 'mixed') / 2**30:.1f} GiB)")
        elif not out_of_core and memory_estimate(n_vertices, True) <= have:
            hint += (f", or the solver backend pardiso-ooc (the factor on disk: about "
                     f"{memory_estimate(n_vertices, True) / 2**30:.1f} GiB)")
        raise ProblemError(f"{what}: {n_vertices:,} control vertices need about {need / 2**30:.1f} GiB to solve"
                           f"{' out of core' if out_of_core else ''}; this machine has {have / 2**30:.1f} GiB free: {hint}")
    return need
