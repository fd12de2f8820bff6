"""The memory a solve of a shell needs, estimated from its control-vertex count, against what
the machine has: a mesh too large is refused with the estimate before anything is built."""
from __future__ import annotations

from ..errors import ProblemError

#: peak memory of a nonlinear solve per control vertex [bytes] and its fixed part, fitted to peak
#: resident sizes measured on spheres of 642 to 40,962 control vertices (scripts/memory_estimate.py)
BYTES_PER_VERTEX = 60_000.0
BYTES_FIXED = 400e6


def memory_estimate(n_vertices: int) -> float:
    """Peak memory [bytes] of a nonlinear solve of a shell with ``n_vertices`` control vertices
    (assembly, the sparse factorisation, the path's states)."""
    return BYTES_FIXED + BYTES_PER_VERTEX * float(n_vertices)


def available_memory() -> float | None:
    """Memory the machine can give this process now [bytes] (None: unknown)."""
    try:
        import psutil
    except ImportError:
        return None
    return float(psutil.virtual_memory().available)


def check_memory(n_vertices: int, what: str, available: float | None = None) -> float:
    """Refuse a shell whose estimated solve memory exceeds what the machine has; returns the estimate."""
    need = memory_estimate(n_vertices)
    have = available_memory() if available is None else available
    if have is not None and need > have:
        raise ProblemError(f"{what}: {n_vertices:,} control vertices need about {need / 2**30:.1f} GiB to solve; "
                           f"this machine has {have / 2**30:.1f} GiB free: use fewer faces")
    return need
