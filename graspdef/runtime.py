"""Process set-up that a program asks for explicitly: nothing here runs at import.

:func:`configure` prepares the process for graspdef's solvers and is called by the command line
at start (``graspdef.cli.main``) and by the benchmark and gallery scripts; a library user may call
it first thing, before any solve (it only helps speed, never changes a result):

* **OpenMP wait policy.**  Two OpenMP runtimes share the cores: numba's kernels (GNU OpenMP) and
  MKL PARDISO (Intel OpenMP).  By default each one's idle threads spin after a parallel region
  and take the cores from the other (the 10k-vertex sphere path: 32.2 -> 25.5 s with passive
  waiting).  ``OMP_WAIT_POLICY=PASSIVE`` is set unless the user has set it; it has to be set
  before either runtime starts, i.e. before the first solve.
* **MKL's runtime library.**  pypardiso looks for ``libmkl_rt`` on every solver it creates (a
  recursive search of ``sys.prefix``, about 1 s) unless ``PYPARDISO_MKL_RT`` names it;
  :func:`locate_mkl_rt` names it once when it sits in the environment's ``lib`` folder (pip's
  mkl wheel).

* **numba's threading layer.**  numba tries TBB first; the TBB that pymeshlab and open3d bring
  is too old for it (a warning), so numba runs on OpenMP anyway.  ``NUMBA_THREADING_LAYER=omp``
  states that choice (the same layer in every process, whatever was imported first, and no warning).

* **OpenBLAS's threads.**  numpy's and SciPy's OpenBLAS start one thread per core; graspdef's
  dense work is small (vector dots and norms of the solvers, 2 x 2 to 100 x 100 least squares,
  the supports' QR), where the threads cost more than they give and, on a busy machine, spin
  against PARDISO and numba for the cores (a 30k-vector dot took 15 ms instead of 50 us).
  ``OPENBLAS_NUM_THREADS=1`` is set unless the user has set it (PARDISO's MKL threads and numba's
  are separate and keep both cores).  Measured 2026-11-26, 2 cores, alternating runs, medians of
  3: the linear 10k pinched cylinder's assembly 0.94 -> 0.57 s, the 2,562-vertex ball's nonlinear
  path 4.7 -> 4.2 s, the tennis-ball pad grasp 14.6 -> 13.6 s, every result the same; the 100k
  pinched cylinder's KKT solve failed its residual check with 2 threads and passed with 1 (an
  edge not yet understood, docs/speed.md).  Like the
  others it must be set before numpy is first imported (the command line calls configure before
  any numerical import; ``blas_threads_fixed`` in the returned dict says whether it was in time).

* **MKL's threading layer.**  MKL's single runtime library (``libmkl_rt``, what pypardiso loads)
  chooses its OpenMP runtime when it starts; PARDISO's numbers then depend, at round-off level, on
  whether GNU OpenMP (numba's) was already loaded: the free-edge pull-out's linear solve came out
  with different last bits in a process whose kernels ran ahead of time (graspdef.compiled: no
  numba, no GNU OpenMP) and in one that had run numba's parallel kernels first, and with
  ``MKL_THREADING_LAYER=GNU`` the two are equal to the bit.  ``MKL_THREADING_LAYER=GNU`` is set
  unless the user has set it: one OpenMP runtime (GNU's, numba's) in every process, and the same
  PARDISO numbers whichever build of the kernels ran.  Speed unchanged (2026-11-27: the 1,681-vertex
  plate 0.76-0.94 s whole process against 0.86-0.99 s, the 10k pinched cylinder's assembly + solve
  1.21 / 1.27 s against 1.38 / 1.21 s, alternating; its refactorisation after numba's parallel
  assembly 0.583 / 0.569 / 0.612 s against 0.590 / 0.554 / 0.610 s, medians of 8 in 3 processes
  each).  Like the others it must be set before MKL
  loads (the first PARDISO solve).

* **MuJoCo's OpenGL.**  ``import mujoco`` loads its classic renderer and an OpenGL context
  module (GLFW) unless ``MUJOCO_GL`` says rendering is disabled; graspdef uses MuJoCo for physics
  only and never renders with it.  ``MUJOCO_GL=disable`` is set unless the user has set it:
  ``import mujoco`` 0.22 -> 0.13 s (``python -X importtime``, 2026-11-27), once per grasp process.

* **glibc's heap kept.**  glibc serves an allocation above its mmap threshold (128 KiB, growing
  to at most 32 MiB as such blocks are freed) with fresh pages of its own and gives them back on
  free; the next array of that size is faulted in page by page again.  On this machine (a
  Firecracker VM) first touches are slow and uneven: 27 MB of a 10k ball's tangent took 3 ms to
  touch in a quiet process and 35-65 ms inside a path, and the row sums that write the tangent's
  sum took 40 ms on fresh memory against 6.6 ms on memory already touched.  Unless
  the user has set ``MALLOC_MMAP_THRESHOLD_`` or ``MALLOC_TRIM_THRESHOLD_``, :func:`keep_heap` sets
  the mmap threshold to 32 MiB (glibc's largest) and the trim threshold to 2 GiB, in this process
  (``mallopt``) and for its children (the environment): arrays up to 32 MiB come from the heap
  and freed ones are reused, already touched (the process keeps up to 2 GiB of freed heap instead
  of returning it).  Measured 2026-12-07, 5 alternating runs of the 10k ball's
  path each: median 7.78 -> 7.45 s (whole process 8.68 -> 8.36 s), 166k -> 115k page faults, every
  result the same.  It only changes where memory comes from, never a number.

All only fill in environment variables the user has not set.
"""
from __future__ import annotations

import glob
import os
import sys


def locate_mkl_rt() -> str | None:
    """Set ``PYPARDISO_MKL_RT`` (if unset) to ``sys.prefix/lib/libmkl_rt.so*`` when that exists;
    returns the value in effect (None if none)."""
    if "PYPARDISO_MKL_RT" not in os.environ:
        found = sorted(glob.glob(os.path.join(sys.prefix, "lib", "libmkl_rt.so*")), key=len)
        if found:
            os.environ["PYPARDISO_MKL_RT"] = found[0]
    return os.environ.get("PYPARDISO_MKL_RT")


#: glibc's mallopt parameters (malloc.h) and the values :func:`keep_heap` gives them
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
HEAP_MMAP_THRESHOLD = 32 * 2**20          # glibc's largest (HEAP_MAX_SIZE / 2 on 64-bit systems)
HEAP_TRIM_THRESHOLD = 2**31 - 1           # mallopt takes an int


def keep_heap() -> dict | None:
    """Arrays up to 32 MiB from glibc's heap, and freed heap kept for reuse (the module docstring):
    ``MALLOC_MMAP_THRESHOLD_`` and ``MALLOC_TRIM_THRESHOLD_`` are set unless the user has set them
    (glibc reads them when a process starts: child processes inherit the policy) and applied to
    this process with ``mallopt``; returns the two values in effect, or None where the C library is
    not glibc or a value is not an integer mallopt takes."""
    import ctypes
    import platform

    if platform.libc_ver()[0] != "glibc":
        return None
    os.environ.setdefault("MALLOC_MMAP_THRESHOLD_", str(HEAP_MMAP_THRESHOLD))
    os.environ.setdefault("MALLOC_TRIM_THRESHOLD_", str(HEAP_TRIM_THRESHOLD))
    try:
        values = {name: int(os.environ[name]) for name in ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")}
        mallopt = ctypes.CDLL(None).mallopt
    except (ValueError, OSError, AttributeError):
        return None
    if not all(0 <= v <= 2**31 - 1 for v in values.values()):
        return None
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    ok = mallopt(_M_MMAP_THRESHOLD, values["MALLOC_MMAP_THRESHOLD_"]) and mallopt(_M_TRIM_THRESHOLD, values["MALLOC_TRIM_THRESHOLD_"])
    return values if ok else None


def configure() -> dict:
    """Set the OpenMP wait policy, numba's and MKL's threading layers, OpenBLAS's thread count and
    MuJoCo's OpenGL (unless set), locate MKL's runtime and keep glibc's heap (:func:`keep_heap`);
    returns what is in effect."""
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    os.environ.setdefault("NUMBA_THREADING_LAYER", "omp")
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    os.environ.setdefault("MUJOCO_GL", "disable")
    os.environ.setdefault("MKL_THREADING_LAYER", "GNU")
    return {"MKL_THREADING_LAYER": os.environ["MKL_THREADING_LAYER"], "OMP_WAIT_POLICY": os.environ["OMP_WAIT_POLICY"], "NUMBA_THREADING_LAYER": os.environ["NUMBA_THREADING_LAYER"],
            "OPENBLAS_NUM_THREADS": os.environ["OPENBLAS_NUM_THREADS"], "blas_threads_fixed": "numpy" not in sys.modules,
            "MUJOCO_GL": os.environ["MUJOCO_GL"], "PYPARDISO_MKL_RT": locate_mkl_rt(), "heap": keep_heap()}


def set_environment(values: dict[str, str]) -> None:
    """Set environment variables for the rest of the process: for a process of one library's own
    whose settings that library reads from the environment at call time -- the out-of-core PARDISO
    worker, where MKL reads its factor files' folder and memory at every call
    (graspdef.solve.pardiso_ooc)."""
    os.environ.update(values)
