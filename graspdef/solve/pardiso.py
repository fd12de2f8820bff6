"""MKL PARDISO's handle and its one call, for the KKT solves (graspdef.solve.sparse, in core) and the
out-of-core worker process (graspdef.solve.pardiso_ooc): nothing else of graspdef is imported here,
so that the worker starts with numpy, ctypes and MKL alone."""
from __future__ import annotations

import ctypes

import numpy as np

from ..runtime import locate_mkl_rt

#: MKL_Set_Threading_Layer's code of the sequential layer
MKL_THREADING_SEQUENTIAL = 1


def new_solver(mtype: int):
    """A PyPardisoSolver.  pypardiso looks for MKL's runtime library on every solver it creates
    (a recursive search of sys.prefix, ~1 s, and 2-4 s on a loaded machine) unless the environment
    variable PYPARDISO_MKL_RT names it.  :func:`graspdef.runtime.locate_mkl_rt` names it (once,
    only if unset and only where pip's mkl wheel puts it), here as well as in
    :func:`graspdef.runtime.configure`, so that a library user who never calls ``configure``
    does not pay the search per solver (measured on a loaded machine: the import 3.1 -> 1.1 s,
    each further solver 1.7 s -> 0)."""
    locate_mkl_rt()
    import pypardiso

    return pypardiso.PyPardisoSolver(mtype=mtype)


def call(solver, phase: int, data: np.ndarray, indptr: np.ndarray, indices: np.ndarray,
         b: np.ndarray) -> np.ndarray:
    """One call of MKL's ``pardiso`` with ``solver``'s handle, matrix type and iparm on the upper
    triangle (``data``, ``indptr``, ``indices``: zero-based 32-bit indices, iparm 35 = 1; float32
    values when iparm 28 = 1) with right-hand sides ``b`` (Fortran order, the values' dtype);
    returns x.  pypardiso's own call copies the index arrays to one-based ones at every call (at
    100k: 2 x 68 MB) and accepts float64 only; this one passes them as they are.  Raises
    pypardiso's PyPardisoError (``value``: PARDISO's error code)."""
    from pypardiso.pardiso_wrapper import PyPardisoError

    s = solver
    x = np.zeros_like(b)
    err = ctypes.c_int32(0)
    i32p, f64p = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
    s._mkl_pardiso(s.pt.ctypes.data_as(ctypes.POINTER(s._pt_type[0])),
                   ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(1)),      # maxfct, mnum
                   ctypes.byref(ctypes.c_int32(s.mtype)), ctypes.byref(ctypes.c_int32(phase)),
                   ctypes.byref(ctypes.c_int32(indptr.size - 1)),
                   data.ctypes.data_as(f64p), indptr.ctypes.data_as(i32p), indices.ctypes.data_as(i32p),
                   s.perm.ctypes.data_as(i32p), ctypes.byref(ctypes.c_int32(1 if b.ndim == 1 else b.shape[1])),
                   s.iparm.ctypes.data_as(i32p), ctypes.byref(ctypes.c_int32(int(s.msglvl))),
                   b.ctypes.data_as(f64p), x.ctypes.data_as(f64p), ctypes.byref(err))
    if err.value != 0:
        raise PyPardisoError(err.value)
    return x
