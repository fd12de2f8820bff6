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


def memory_estimate(n_vertices: int, out_of_core: bool = False) -> float:
    """Peak memory [bytes] of a nonlinear solve of a shell with ``n_vertices`` control vertices
    (assembly, the sparse factorisation, the path's states); ``out_of_core``: the factor on disk."""
    per = BYTES_PER_VERTEX_OUT_OF_CORE if out_of_core else BYTES_PER_VERTEX
    return BYTES_FIXED + per * float(n_vertices)


def available_memory() -> float | None:
    """Memory the machine can give this process now [bytes] (None: unknown)."""
    try:
        import psutil
    except ImportError:
        return None
    return float(psutil.virtual_memory().available)


def check_memory(n_vertices: int, what: str, available: float | None = None, out_of_core: bool = False) -> float:
    """Refuse a shell whose estimated solve memory exceeds what the machine has; returns the
    estimate.  ``out_of_core``: the solve keeps its factor on disk (backend "pardiso-ooc")."""
    need = memory_estimate(n_vertices, out_of_core)
    have = available_memory() if available is None else available
    if have is not None and need > have:
        hint = "use fewer faces"
        if not out_of_core and memory_estimate(n_vertices, True) <= have:
            hint += (f", or the solver backend pardiso-ooc (the factor on disk: about "
                     f"{memory_estimate(n_vertices, True) / 2**30:.1f} GiB)")
        raise ProblemError(f"{what}: {n_vertices:,} control vertices need about {need / 2**30:.1f} GiB to solve"
                           f"{' out of core' if out_of_core else ''}; this machine has {have / 2**30:.1f} GiB free: {hint}")
    return need
