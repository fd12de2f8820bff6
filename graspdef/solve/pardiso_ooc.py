"""PARDISO out of core in a worker process of its own (backend "pardiso-ooc").

MKL's out-of-core mode corrupts the memory of the process it runs in, at random: after every cause
that was found had been avoided (a folder given with a trailing separator, a second handle in a
process, MKL's threaded layer; graspdef.solve.sparse.ooc_path and this module's worker), 4 of 2,941
out-of-core processes still failed -- a wrong factor caught by the solve's check, or one of
Python's own objects overwritten (``module 'ctypes' has no attribute 'np'``; on 2026-12-07 in CI,
``'PyPardisoSolver' object has no attribute 'perm'``) -- whatever the load, not reproducible, and
valgrind's memcheck shows no invalid write (docs/speed.md, "Out of core").  graspdef cannot mend
MKL; it keeps that mode out of the process whose answers it reports.

Each out-of-core handle lives in a worker process started for it (``python -m
graspdef.solve.pardiso_ooc``), with one handle for its life, on MKL's sequential layer -- the two
rules that were, until 2026-12-07, rules of the calling process (``require_one_ooc_handle``,
``require_sequential_mkl``): MKL 2026.2's out-of-core mode keeps state across handles, and processes
that made a second handle after freeing the first corrupted memory (3 of 417 with two to ten handles,
0 of 1,036 with one); the threaded layer gave a wrong out-of-core factor about once in 60 runs of
tests/solve/test_kkt_out_of_core.py on a busy machine, the sequential one in none of 295 then.  So a
process may now hold in-core and out-of-core solvers side by side, several out-of-core ones, a second
analysis (a fresh worker) and PARDISO's fallback settings out of core (a fresh worker each).  The
calling process (:class:`graspdef.solve.sparse.KKTSystem` through :class:`OOCPardiso`) sends the
KKT upper triangle when it changes and the right-hand sides, and receives the solutions, which it
checks in its own memory (KKTSystem.solve's residual and backward-error tests, as every solve).  A
worker that ends or raises is replaced by a fresh one, which repeats the analysis and the
factorisation of the current matrix before the call it failed in: at most :data:`WORKER_ATTEMPTS`
workers per call, then a SolverError.  A factor that comes out wrong without a failure is caught by
the solve's check, and KKTSystem.retry_robust refactors in a fresh worker.  The worker ends when
the system is closed, or by itself when the calling process has gone.
"""
from __future__ import annotations

import contextlib
import logging
import os
import socket
import subprocess
import sys
import traceback
from multiprocessing.connection import Connection

import numpy as np

from ..errors import SolverError
from ..runtime import set_environment
from .pardiso import MKL_THREADING_SEQUENTIAL, call, new_solver

log = logging.getLogger(__name__)

#: the worker's command (its connection's file descriptor and the matrix type follow)
WORKER = [sys.executable, "-m", "graspdef.solve.pardiso_ooc"]

#: worker processes tried for one call: the first, and a fresh one if it ends or raises
WORKER_ATTEMPTS = 2

#: seconds a closing worker is given to end before it is killed
WORKER_EXIT_S = 10.0


class _WorkerLost(Exception):
    """The worker ended or raised (its memory is suspect): replace it."""


class OOCPardiso:
    """The calling process's side of one out-of-core PARDISO handle, which lives in a worker
    process: ``set_iparm`` / ``get_iparm`` and ``free_memory`` as pypardiso's PyPardisoSolver
    (``free_memory`` ends the worker), and :meth:`call` for one PARDISO phase.

    ``iparm`` is the worker's iparm as of its last answer; ``restarts`` counts the workers replaced
    after a failure; ``layer`` and ``threads`` are the worker's MKL threading layer and thread count."""

    def __init__(self, mtype: int):
        self.mtype = mtype
        self.iparm = np.zeros(64, np.int32)
        self.restarts = 0
        self.layer = self.threads = None
        self.pid: int | None = None
        self._settings: dict[int, int] = {}
        self._proc: subprocess.Popen | None = None
        self._conn: Connection | None = None
        self._held = None                   # the upper triangle the worker holds
        self._done: set[int] = set()        # phases done on the worker's handle (11, 22)
        self._start()

    def set_iparm(self, i: int, value: int) -> None:
        self._settings[int(i)] = int(value)
        self.iparm[i - 1] = value

    def get_iparm(self, i: int) -> int:
        return int(self.iparm[i - 1])

    def _start(self) -> None:
        import graspdef

        ours, theirs = socket.socketpair()
        root = os.path.dirname(os.path.dirname(os.path.abspath(graspdef.__file__)))
        env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH")) if p),
               "MKL_THREADING_LAYER": "SEQUENTIAL"}
        try:
            self._proc = subprocess.Popen([*WORKER, str(theirs.fileno()), str(self.mtype)], pass_fds=(theirs.fileno(),),
                                          env=env, stdin=subprocess.DEVNULL, stdout=2, close_fds=True)
        finally:
            theirs.close()
        self._conn = Connection(ours.detach())
        self._held, self._done = None, set()
        try:
            hello = self._conn.recv()
        except (EOFError, OSError):
            status = self._end(kill=True)
            raise SolverError(f"PARDISO out of core: its worker process ended with status {status} before it was ready "
                              f"({' '.join(WORKER)})") from None
        self.pid, self.layer, self.threads = self._proc.pid, hello["layer"], hello["threads"]
        if self.layer != MKL_THREADING_SEQUENTIAL:
            self._end(kill=True)
            raise SolverError(f"PARDISO out of core: its worker process's MKL runs on threading layer {self.layer}, "
                              "not the sequential one")

    def _end(self, kill: bool = False) -> int | None:
        """End the worker (asked to, or killed) and return its exit status."""
        proc, conn = self._proc, self._conn
        self._proc = self._conn = None
        self._held, self._done = None, set()
        if proc is None:
            return None
        if conn is not None:
            if not kill:
                try:
                    conn.send({"op": "exit"})
                except OSError:
                    pass
            conn.close()
        if kill:
            proc.kill()
        try:
            return proc.wait(WORKER_EXIT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            return proc.wait()

    def free_memory(self, everything: bool = True) -> None:
        """End the worker: its handle, memory and process go (a new handle is a new worker)."""
        self._end()

    def close(self) -> None:
        self._end()

    def call(self, phase: int, U, b: np.ndarray, env: dict[str, str]) -> np.ndarray:
        """One PARDISO phase (11 analysis, 22 factorisation, 33 solution) on the upper triangle ``U``
        (a CSR matrix, zero-based 32-bit indices) with right-hand sides ``b`` (Fortran order, U's
        dtype) and MKL's out-of-core settings ``env``; returns x.  A fresh worker first repeats
        the phases its handle has not done on ``U`` (after a failure: the analysis, then the
        factorisation).  Raises pypardiso's PyPardisoError for PARDISO's own error codes, and
        SolverError when :data:`WORKER_ATTEMPTS` workers failed."""
        failures: list[str] = []
        while True:
            step = phase
            try:
                if self._proc is None:
                    self._start()
                for step in [p for p in (11, 22) if p < phase and p not in self._done] + [phase]:
                    x = self._request(step, U, b if step == phase else np.zeros((U.shape[0], 1), U.dtype, order="F"), env)
                    if step == 11:
                        self._done = {11}               # a new analysis: no factor yet
                    elif step == 22:
                        self._done = {11, 22}
                return x
            except _WorkerLost as exc:
                failures.append(str(exc))
                self._end(kill=True)
                self.restarts += 1
                last = len(failures) >= WORKER_ATTEMPTS
                log.warning("PARDISO out of core: the worker process failed in phase %d (%s); %s", step, exc,
                            "giving up" if last else "a fresh one repeats the analysis and factorisation")
                if last:
                    raise SolverError(f"PARDISO out of core: {len(failures)} worker processes failed in turn "
                                      f"(last: {failures[-1]}); solve in core (backend 'pardiso') or run again") from None

    def _request(self, phase: int, U, b: np.ndarray, env: dict[str, str]) -> np.ndarray:
        from pypardiso.pardiso_wrapper import PyPardisoError

        conn = self._conn
        send_matrix = self._held is not U
        b = np.asfortranarray(b)
        head = {"op": "call", "phase": phase, "env": env, "iparm": self._settings,
                "matrix": (U.dtype.str, U.indptr.size, U.indices.size) if send_matrix else None,
                "b": (b.shape, b.dtype.str)}
        try:
            conn.send(head)
            if send_matrix:
                for a in (U.data, U.indptr, U.indices):
                    conn.send_bytes(np.ascontiguousarray(a))
            conn.send_bytes(b.ravel(order="F"))
            reply = conn.recv()
            if reply["status"] == "ok":
                x = np.empty(b.size, b.dtype)
                conn.recv_bytes_into(x)
        except (EOFError, OSError) as exc:
            try:
                status = self._proc.wait(WORKER_EXIT_S)
            except subprocess.TimeoutExpired:
                raise _WorkerLost(f"its connection failed: {type(exc).__name__}") from None
            raise _WorkerLost(f"it ended with status {status}") from None
        if send_matrix:
            self._held = U
        if reply.get("iparm") is not None:
            self.iparm[:] = reply["iparm"]
        if reply["status"] == "pardiso":
            raise PyPardisoError(reply["code"])
        if reply["status"] != "ok":
            raise _WorkerLost(f"it raised {reply['text']}")
        return x.reshape(b.shape, order="F")


def _serve(fd: int, mtype: int) -> None:
    """The worker: one PARDISO handle on MKL's sequential layer, answering the calling process's
    requests until it asks to exit or goes away."""
    import signal

    from pypardiso.pardiso_wrapper import PyPardisoError

    # Ctrl-C reaches the whole process group: the calling process answers it, and the worker ends
    # when that process closes its connection (or goes)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    conn = Connection(fd)
    solver = new_solver(mtype)
    lib = solver.libmkl
    layer = int(lib.MKL_Set_Threading_Layer(MKL_THREADING_SEQUENTIAL))
    conn.send({"layer": layer, "threads": int(lib.MKL_Get_Max_Threads())})
    U = None
    while True:
        try:
            head = conn.recv()
        except (EOFError, OSError):
            return                                  # the calling process has gone
        if head["op"] == "exit":
            with contextlib.suppress(Exception):    # the process ends either way
                solver.free_memory(everything=True)
            return
        try:
            if head["matrix"] is not None:
                dtype, n1, nnz = head["matrix"]
                data, indptr, indices = np.empty(nnz, dtype), np.empty(n1, np.int32), np.empty(nnz, np.int32)
                for a in (data, indptr, indices):
                    conn.recv_bytes_into(a)
                U = (data, indptr, indices)
            shape, dtype = head["b"]
            b = np.empty(int(np.prod(shape)), dtype)
            conn.recv_bytes_into(b)
            b = b.reshape(shape, order="F")
            set_environment(head["env"])
            for k, v in head["iparm"].items():
                solver.iparm[k - 1] = v
            try:
                x = call(solver, head["phase"], *U, b)
            except PyPardisoError as exc:
                conn.send({"status": "pardiso", "code": int(exc.value), "iparm": solver.iparm.tolist()})
                continue
            conn.send({"status": "ok", "iparm": solver.iparm.tolist()})
            conn.send_bytes(np.asfortranarray(x).ravel(order="F"))
        except (EOFError, OSError):
            return
        except Exception:                           # its memory is suspect: the calling process replaces it
            conn.send({"status": "error", "text": traceback.format_exc(limit=3).strip().splitlines()[-1]})
            return


if __name__ == "__main__":
    _serve(int(sys.argv[1]), int(sys.argv[2]))
    os._exit(0)                 # no teardown of a process that ran MKL's out-of-core mode
