"""graspdef's compiled kernels: one Python source, two builds.

A kernel is a plain Python function of arrays decorated with :func:`kernel` in one of the
:data:`KERNEL_MODULES`.  A call runs

* the **ahead-of-time build** -- a C extension ``graspdef/_aot*.so`` that ``make setup`` compiles
  from the same sources with numba's ``pycc`` (``python -m graspdef.compiled``), serial -- when it
  exists, was built from the kernel sources as they are now (their SHA-256 is kept beside it, in
  ``_aot.json``) on this processor (it is compiled for the build machine's instruction set), holds the kernel for these argument types, and the call is small: a kernel that
  is parallel in the JIT build goes there only while its work (``args[work].shape[0]``) is at most
  :data:`SERIAL_MAX` -- or at most :data:`LOADING_MAX` while its JIT overload is still being loaded
  by the loader thread (:class:`_Loader`, :func:`prepare`);
* otherwise the **JIT build**: numba's ``njit`` (``cache=True``, parallel where declared), which
  compiles (or loads from numba's on-disk cache) every kernel of the module on the first such call.

Why (issue 17, docs/speed.md, "Start-up"): numba costs every process 0.17 s to import and 0.3-0.4 s on its
first call even when its on-disk cache is warm (it installs its typing and lowering registries);
the plate of 1,681 control vertices took 1.2-1.6 s as a whole process, of which ~0.5 s was that.
The ahead-of-time module loads like any extension (a few ms) and needs no numba at run time.
Large problems keep the parallel JIT build (2 cores: the shell's Hessian assembly about 1.8x
faster), and numba's fixed cost is paid beside their first calls, in a thread of its own.

The ahead-of-time exports release the GIL while they run (as ``njit(nogil=True)`` would: pycc's
wrappers are built with numba's ``release_gil`` flag), so a term whose work is in such kernels can
be evaluated in a thread beside the other terms' Python code (graspdef.solve.equilibrium,
:meth:`Kernel.ahead_of_time`); the pad grasp's shell Hessian, 10 ms of a 28 ms tangent, then
overlaps the contact terms'.

Both builds compute the same numbers: the kernels' parallel loops write disjoint outputs (no
reductions across iterations) and nothing is compiled with fastmath, so serial and parallel,
ahead-of-time and JIT agree to the bit (``tests/test_compiled.py`` and ``graspdef bench kernels``
check it on real solves' arguments; a whole solve agrees to the bit too once MKL's threading layer
is fixed, graspdef.runtime).  A missing, stale or foreign (another processor's) ahead-of-time
module only costs speed: the JIT build is used, never old code.

:func:`kernel`'s registry is filled at import by the kernel modules' decorators (static, like
numba's own dispatchers); nothing is compiled or loaded before the first call.
"""
from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import importlib
import json
import logging
import sys
import threading
from pathlib import Path

import numpy as np

log = logging.getLogger(__name__)

#: the modules that define kernels (every one is hashed into the ahead-of-time module's stamp)
KERNEL_MODULES = ("graspdef.shell._kernels", "graspdef.shell.volume", "graspdef.solve._kernels",
                  "graspdef.contact._kernels")

#: a kernel that is parallel in the JIT build runs serially ahead of time only up to this much work
#: (``args[work].shape[0]`` per the kernel's ``per_face``: faces or points, or rows of the stiffness
#: at 1.5 per face): the 40 x 40 plate's 3,200 faces (5,043 rows) go there, the 2,562-vertex ball's
#: 5,120 faces (a nonlinear path of ~50 Hessians; 7,686 rows) keep both cores
SERIAL_MAX = 4096

#: while a parallel kernel's JIT overload is being loaded (:class:`_Loader`), a call with at most
#: this much work (as :data:`SERIAL_MAX`) runs the serial ahead-of-time export instead of waiting
#: for it; a larger one waits.  A serial run must not cost more than the load it saves (~0.5 s):
#: the 10k ball's shell Hessian (20,480 faces) takes 158 ms serially and 81 ms on both cores
LOADING_MAX = 8 * SERIAL_MAX

AOT_NAME = "_aot"                              # graspdef/_aot*.so and graspdef/_aot.json
_HERE = Path(__file__).resolve().parent

#: builtins' range until the JIT build replaces a kernel module's ``prange`` by numba's
prange = range

_REGISTRY: dict[str, list["Kernel"]] = {}      # module name -> its kernels, in definition order
_aot_state: dict = {}                          # "module": the loaded ahead-of-time module or None
_recorder: dict | None = None                  # inside recording(): export name -> (kernel, export, args)
_JIT_LOCK = threading.RLock()                  # making a module's JIT build (from any thread)


class Kernel:
    """A compiled kernel (see the module's docstring).  ``signatures``: numba signature strings
    of the ahead-of-time exports (none: JIT only, e.g. a helper that only kernels call)."""

    def __init__(self, fn, parallel: bool, signatures: tuple[str, ...], work: int, per_face: float = 1.0):
        self.py_func = fn
        self.parallel = parallel
        self.signatures = signatures
        self.work = work
        self.per_face = per_face
        self.__name__, self.__qualname__, self.__doc__ = fn.__name__, fn.__qualname__, fn.__doc__
        self.__module__ = fn.__module__
        self._jit = None                 # numba dispatcher, once the JIT build is made
        self._aot: list | None = None    # the ahead-of-time exports (empty: none usable)
        self._ready: set = set()         # argument-type keys whose JIT overload is loaded (_Loader)
        _REGISTRY.setdefault(fn.__module__, []).append(self)

    def __repr__(self):
        return f"<kernel {self.__module__}.{self.__name__}>"

    def export_name(self, i: int) -> str:
        return f"{self.__module__.rsplit('.', 2)[-2]}_{self.__module__.rsplit('.', 1)[-1].lstrip('_')}__{self.__name__}__{i}"

    def __call__(self, *args):
        if self._aot is None:
            self._aot = _aot_exports(self)
        if _recorder is not None:
            _record(self, args)
        if self._aot:
            work = args[self.work].shape[0]
            if self.serial(work) or (work <= self.per_face * LOADING_MAX and not self._jit_ready(args)):
                for f, spec in self._aot:        # (the second case: the JIT build loads beside it)
                    if _matches(args, spec):
                        return f(*args)
        return self.jit(*args)

    def _jit_ready(self, args) -> bool:
        """Whether the JIT build's overload for these argument types is loaded; if not, asks the
        loader thread for it (:class:`_Loader`) and returns False -- the call then runs ahead of
        time, serially, while numba is imported and the overload loaded on the other core.  Types
        the loader cannot name (tuples, None, ...) are loaded by the call itself (True)."""
        key = _type_key(args)
        if key is None or key in self._ready:
            return True
        _LOADER.request(self, key)
        return False

    def serial(self, work: int) -> bool:
        """Whether a call with this much work (``args[work].shape[0]``) runs serially ahead of time
        (when the module is there): a serial kernel always, a parallel one up to ``per_face``
        :data:`SERIAL_MAX`."""
        return not self.parallel or work <= self.per_face * SERIAL_MAX

    def ahead_of_time(self, work: int) -> bool:
        """Whether a call with this much work (``args[work].shape[0]``) runs the ahead-of-time
        build -- serial, with the GIL released -- when its arguments have an exported signature's
        types."""
        if self._aot is None:
            self._aot = _aot_exports(self)
        return bool(self._aot) and self.serial(work)

    @property
    def jit(self):
        """The JIT build (numba dispatcher); compiles the whole module's kernels on first use."""
        if self._jit is None:
            with _JIT_LOCK:
                if self._jit is None:
                    _jit_module(self.__module__)
        return self._jit


def _type_key(args) -> tuple | None:
    """A hashable key of the numba types of a call's arguments, made without numba (as
    ``numba.typeof`` types them: an array by dtype, dimensions, layout -- C, F or A --, writeable
    and aligned flags; a scalar by its numpy dtype, a Python int as int64 and a float as float64);
    None where an argument is of another kind."""
    key = []
    for a in args:
        if isinstance(a, np.ndarray):
            fl = a.flags
            key.append((a.dtype, a.ndim, "C" if fl.c_contiguous else ("F" if fl.f_contiguous else "A"),
                        bool(fl.writeable), bool(fl.aligned)))
        elif isinstance(a, (bool, int, float, np.bool_, np.integer, np.floating)):
            key.append(np.dtype(type(a)))
        else:
            return None
    return tuple(key)


def _numba_types(key: tuple) -> tuple:
    """The numba argument types of a :func:`_type_key` (in the loader thread: imports numba)."""
    import numba
    from numba.core import types

    return tuple(types.Array(numba.from_dtype(k[0]), k[1], k[2], readonly=not k[3], aligned=k[4])
                 if isinstance(k, tuple) else numba.from_dtype(k) for k in key)


def _key_of(sig) -> tuple:
    """The :func:`_type_key` of a numba signature's argument types."""
    from numba.core import types

    return tuple((np.dtype(str(t.dtype)), t.ndim, t.layout, t.mutable, t.aligned)
                 if isinstance(t, types.Array) else np.dtype(str(t)) for t in sig.args)


class _Loader:
    """Loads JIT overloads in a thread of its own while the calls that need them run ahead of time
    (:meth:`Kernel._jit_ready`, :func:`prepare`).

    A large problem's first kernel calls used to wait for numba: its import and the loading of each
    kernel's overload from the on-disk cache (0.8 s of the 10k ball's path, on one thread: the
    import and the gas volume's overload 0.49 s, the others at their first calls 0.36 s; profiled).  The two builds give the same numbers to the bit (the module docstring), so a call may
    take either: until its overload is loaded a call of at most :data:`LOADING_MAX` work runs the
    serial ahead-of-time export (which releases the GIL) and numba works on the other core -- beside
    the first evaluations and PARDISO's analysis of the first tangent, which runs on one thread.
    Started at the path's start (:func:`prepare`, all of a shell's kernels at once) it cost the 10k
    ball's whole process 0.15 s less than started at the shell's creation, where the loader's Python
    shared the GIL with the set-up's (5 alternating runs each, 2026-12-07).  The thread ends when
    nothing is asked and is started again when something is.  A load that fails marks its key loaded: the
    next call then compiles it itself and raises numba's own error, if any."""

    def __init__(self):
        self._lock = threading.Lock()
        self._queue: list = []
        self._asked: set = set()
        self._thread: threading.Thread | None = None

    def request(self, k: Kernel, key: tuple | None = None, signature: str | None = None) -> None:
        """Load ``k``'s overload for a :func:`_type_key` or for a signature string."""
        with self._lock:
            if (id(k), key, signature) in self._asked:
                return
            self._asked.add((id(k), key, signature))
            self._queue.append((k, key, signature))
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="graspdef-jit-loader", daemon=True)
                self._thread.start()

    def _run(self) -> None:
        while True:
            with self._lock:
                if not self._queue:
                    self._thread = None
                    return
                k, key, signature = self._queue.pop(0)
            try:
                if signature is not None:
                    sig = _signature(signature)
                    k.jit.compile(sig.args)
                    key = _key_of(sig)
                else:
                    k.jit.compile(_numba_types(key))
            except Exception as e:              # the call's own compilation reports it
                log.debug("loading %s's JIT build for %s failed: %s", k.__name__, key or signature, e)
            if key is not None:
                k._ready.add(key)

    def join(self) -> None:
        """Wait until everything asked so far is loaded."""
        while True:
            t = self._thread
            if t is None:
                return
            t.join()


def prepare(n_faces: int) -> None:
    """Start loading the JIT build of every parallel kernel that a shell of ``n_faces`` faces runs
    there (work above :data:`SERIAL_MAX`), for its ahead-of-time signatures' types, in the loader
    thread (:class:`_Loader`), all at once: numba's import and the cached overloads then load while
    the first evaluations run ahead of time and PARDISO analyses the first tangent on one thread
    (graspdef.solve.equilibrium.Equilibrium calls it).  Nothing to do for a small shell, or without
    the ahead-of-time module (the calls then wait for the JIT build anyway)."""
    if _aot_module() is None:
        return
    for k in kernels():
        if k.parallel and k.signatures and not k.serial(int(k.per_face * n_faces)):
            for text in k.signatures:
                _LOADER.request(k, signature=text)


_LOADER = _Loader()


def kernel(*, parallel: bool = False, aot: tuple[str, ...] | list[str] = (), work: int = 0,
           per_face: float = 1.0):
    """Decorator of a kernel: ``parallel`` -- its ``prange`` loops run on all cores in the JIT
    build; ``aot`` -- numba signature strings to export ahead of time; ``work`` -- the argument
    whose ``shape[0]`` measures a parallel kernel's work (:data:`SERIAL_MAX`); ``per_face`` -- how
    many of its units a face of the shell makes (faces, points: 1; rows of a shell's stiffness, three
    per control vertex and about two faces per vertex: 1.5), so that one problem's kernels go to the
    same build."""
    def wrap(fn):
        return Kernel(fn, parallel, tuple(aot), work, per_face)
    return wrap


def kernels() -> list[Kernel]:
    """Every kernel of :data:`KERNEL_MODULES` (importing them)."""
    for name in KERNEL_MODULES:
        importlib.import_module(name)
    return [k for name in KERNEL_MODULES for k in _REGISTRY.get(name, [])]


def _jit_module(name: str) -> None:
    """The JIT build of every kernel of module ``name``: numba dispatchers of copies of the kernels'
    functions whose globals are the module's with every :class:`Kernel` (of this module or imported
    from another kernel module) replaced by its dispatcher and ``prange`` by numba's -- kernels
    calling kernels compile against dispatchers, while the module itself keeps its Kernel objects
    (an import of a kernel always gets the object that chooses between the builds)."""
    import types

    import numba

    mod = sys.modules[name]
    ns = dict(vars(mod))
    for key, val in list(ns.items()):
        if isinstance(val, Kernel) and val.__module__ != name:
            ns[key] = val.jit
    if ns.get("prange") is range:
        ns["prange"] = numba.prange
    mine = [k for k in _REGISTRY.get(name, []) if k._jit is None]
    for k in mine:
        f = k.py_func
        copy = types.FunctionType(f.__code__, ns, f.__name__, f.__defaults__, f.__closure__)
        copy.__qualname__, copy.__doc__, copy.__kwdefaults__ = f.__qualname__, f.__doc__, f.__kwdefaults__
        k._jit = numba.njit(cache=True, parallel=k.parallel)(copy)
    for k in _REGISTRY.get(name, []):
        ns[k.__name__] = k._jit


def cpu_name() -> str:
    """This machine's processor model (the ahead-of-time module is compiled for the CPU it is built
    on, like the JIT build, and is not used on another one)."""
    import platform

    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return f"{platform.machine()} {platform.processor()}".strip()


def source_stamp() -> str:
    """SHA-256 of the kernel modules' source files and of this file: the ahead-of-time module is
    used only if it was built from exactly these."""
    h = hashlib.sha256()
    for name in KERNEL_MODULES:
        spec = importlib.util.find_spec(name)
        h.update(name.encode() + b"\0" + Path(spec.origin).read_bytes() + b"\0")
    h.update(Path(__file__).read_bytes())
    return h.hexdigest()


def _matches(args, spec) -> bool:
    """Whether ``args`` have the types of an ahead-of-time export's signature (``spec``: its
    :func:`_checks`).  pycc's wrappers do not check: an int32 array passed for an int64 one is read
    as int64 (a crash or wrong numbers), so nothing goes there unchecked."""
    if len(args) != len(spec):
        return False
    for a, (kind, dtype, ndim, contiguous) in zip(args, spec):
        if kind == "a":
            if not isinstance(a, np.ndarray) or a.dtype != dtype or a.ndim != ndim \
                    or (contiguous and not a.flags.c_contiguous):
                return False
        elif isinstance(a, (bool, np.bool_)):
            if kind != "b":
                return False
        elif kind == "i":
            if not isinstance(a, (int, np.integer)):
                return False
        elif kind == "f":
            if not isinstance(a, (float, int, np.floating, np.integer)):
                return False
        else:
            return False
    return True


def _checks(spec: list) -> tuple:
    """An export's argument spec from ``_aot.json`` as :func:`_matches` reads it: per argument
    (kind, numpy dtype, dimensions, C-contiguous required)."""
    return tuple((s[0], np.dtype(s[1]), s[2], s[3] == "C") if s[0] == "a" else (s[0], None, 0, False)
                 for s in spec)


def _arg_spec(t) -> list:
    """An argument's numba type as ``_matches`` checks it: ["a", dtype, ndim, layout] for an
    array, ["i"], ["f"] or ["b"] for an integer, float or boolean scalar."""
    from numba.core import types

    if isinstance(t, types.Array):
        return ["a", str(t.dtype), t.ndim, t.layout]
    for cls, kind in ((types.Boolean, "b"), (types.Integer, "i"), (types.Float, "f")):
        if isinstance(t, cls):
            return [kind]
    raise TypeError(f"an ahead-of-time kernel argument must be an array or a scalar, not {t}")


def _aot_exports(k: Kernel) -> list:
    """The ahead-of-time exports of kernel ``k`` as (function, argument spec) pairs."""
    mod = _aot_module()
    if mod is None:
        return []
    specs = _aot_state["exports"]
    return [(getattr(mod, n), specs[n]) for n in (k.export_name(i) for i in range(len(k.signatures)))
            if n in specs and hasattr(mod, n)]


def _aot_module():
    """The ahead-of-time module if it is there and current, else None (once per process)."""
    if "module" not in _aot_state:
        _aot_state["module"] = None
        stamp_file = _HERE / f"{AOT_NAME}.json"
        try:
            stamp = json.loads(stamp_file.read_text())
        except (OSError, ValueError):
            _aot_state["why"] = f"not built ({stamp_file.name} missing)"
        else:
            if stamp.get("source_sha256") != source_stamp():
                _aot_state["why"] = "stale (built from other kernel sources)"
            elif stamp.get("cpu") != cpu_name():
                _aot_state["why"] = f"built for another processor ({stamp.get('cpu')})"
            else:
                try:
                    _aot_state["module"] = importlib.import_module(f"graspdef.{AOT_NAME}")
                    _aot_state["exports"] = {n: _checks(v) for n, v in stamp["exports"].items()}
                except ImportError as e:
                    _aot_state["why"] = f"not loadable ({e})"
        if _aot_state["module"] is None:
            log.debug("ahead-of-time kernels %s: the JIT build is used", _aot_state["why"])
    return _aot_state["module"]


def aot_available() -> bool:
    """Whether the ahead-of-time module is there, current and loadable."""
    return _aot_module() is not None


def aot_status() -> str:
    """One line: whether the ahead-of-time kernels are in use, and why not if not."""
    mod = _aot_module()
    if mod is not None:
        return f"ahead-of-time kernels in use: {Path(mod.__file__).name}"
    return f"ahead-of-time kernels {_aot_state['why']}: numba's JIT build only (build them: python -m graspdef.compiled)"


def _signature(text: str):
    """A numba signature from its string (numba's type names: f8[:, ::1], i8, UniTuple(...), ...).
    Read-only arrays match a signature's writable array type (the compiled code is the same;
    ``_matches`` checks dtype, dimensions and layout, which are what the memory layout needs)."""
    from numba.core import types

    return eval(text, {"__builtins__": {}}, dict(vars(types)))


def _copy(a):
    """A copy of a kernel argument that keeps an array's read-only flag (numba types read-only
    arrays separately: the JIT build must see what the caller passed)."""
    if isinstance(a, np.ndarray):
        c = a.copy()
        c.flags.writeable = a.flags.writeable
        return c
    return a


def _record(k: Kernel, args) -> None:
    for f, spec in k._aot or ():
        if _matches(args, spec):
            _recorder.setdefault(f.__name__, (k, f, tuple(_copy(a) for a in args)))
            return


@contextlib.contextmanager
def recording():
    """Within the block, the first arguments every ahead-of-time export would be (or is) given
    are recorded (copied before the call); yields the dict export name -> (kernel, export, args)
    that :func:`compare` checks."""
    global _recorder
    outer, _recorder = _recorder, {}
    try:
        yield _recorder
    finally:
        _recorder = outer


def _same(a, b) -> bool:
    """Equal to the bit (NaN equal to NaN): results of kernels (arrays, scalars, tuples, None)."""
    if isinstance(a, tuple):
        return isinstance(b, tuple) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return (isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape
                and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    return a == b or (a != a and b != b)


def compare(recorded: dict) -> list[dict]:
    """Each recorded export run on its arguments and the JIT build on the same (fresh copies, so
    that what a kernel writes into its arguments is compared too; the JIT build compiles, or loads
    from numba's on-disk cache, the overload of those argument types).  One record per export:
    name, kernel, ``equal`` (results and written arguments equal to the bit), the two builds'
    seconds."""
    import time

    out = []
    for name, (k, f, args) in sorted(recorded.items()):
        a1, a2 = [_copy(a) for a in args], [_copy(a) for a in args]
        k.jit(*[_copy(a) for a in args])                # compile / load before timing
        t0 = time.perf_counter()
        r1 = f(*a1)
        t1 = time.perf_counter()
        r2 = k.jit(*a2)
        t2 = time.perf_counter()
        out.append({"export": name, "kernel": f"{k.__module__}.{k.__name__}",
                    "equal": _same(r1, r2) and all(_same(x, y) for x, y in zip(a1, a2)),
                    "aot_s": t1 - t0, "jit_s": t2 - t1})
    return out


def builds_used() -> dict:
    """Which builds this process's kernels have used so far (for a run's provenance): the
    ahead-of-time module's status line and the kernel modules numba's JIT has compiled."""
    return {"ahead_of_time": aot_status(),
            "jit": sorted(n for n, ks in _REGISTRY.items() if any(k._jit is not None for k in ks))}


@contextlib.contextmanager
def _gil_released_exports():
    """pycc compiles its exports with numba's compiler flags made in ``numba.pycc.compiler``; with
    ``release_gil`` set there, each export's Python wrapper releases the GIL around the kernel, as
    numba's ``nogil=True`` does for the JIT (the kernels touch no Python object).  The flag class
    is swapped for the build only."""
    from numba.core.compiler import Flags
    from numba.pycc import compiler as pycc_compiler

    class GilReleased(Flags):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            self.release_gil = True

    saved, pycc_compiler.Flags = pycc_compiler.Flags, GilReleased
    try:
        yield
    finally:
        pycc_compiler.Flags = saved


def build(out_dir: Path = _HERE, verbose: bool = False) -> Path:
    """Compile every kernel's ``aot`` signatures into ``out_dir/_aot*.so`` (numba's pycc; needs a C
    compiler) and write the source stamp ``_aot.json`` beside it; returns the module's path."""
    import warnings

    kernels()
    for name in KERNEL_MODULES:
        _jit_module(name)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # pycc's deprecation notice
        from numba.pycc import CC

        cc = CC(AOT_NAME)
        cc.output_dir = str(out_dir)
        cc.verbose = verbose
        cc.target_cpu = "host"       # built where it runs (make setup): the machine's own instruction set, as the JIT
        exports = {}
        for name in KERNEL_MODULES:
            for k in _REGISTRY.get(name, []):
                for i, text in enumerate(k.signatures):
                    sig = _signature(text)
                    cc.export(k.export_name(i), sig)(k.jit.py_func)    # globals: the dispatchers
                    exports[k.export_name(i)] = [_arg_spec(t) for t in sig.args]
        stamp_file = Path(out_dir) / f"{AOT_NAME}.json"
        stamp_file.unlink(missing_ok=True)
        with _gil_released_exports():
            cc.compile()
    so = next(Path(out_dir).glob(f"{AOT_NAME}.*.so"))
    stamp_file.write_text(json.dumps({"source_sha256": source_stamp(), "cpu": cpu_name(), "exports": exports}) + "\n")
    return so


if __name__ == "__main__":
    import time

    from graspdef import compiled     # the kernel modules register with this module, not __main__

    t0 = time.perf_counter()
    path = compiled.build(verbose="-v" in sys.argv)
    print(f"built {path} in {time.perf_counter() - t0:.1f} s")
