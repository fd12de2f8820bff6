"""The two builds of graspdef's compiled kernels (graspdef.compiled): the ahead-of-time serial
module must compute what the JIT build computes, to the bit, and must never be given arguments
of other types (its pycc wrappers do not check them: an int32 array read as int64 crashes).

The ahead-of-time module is built by ``make setup`` (``python -m graspdef.compiled``); a checkout
where it is missing or stale fails ``test_the_ahead_of_time_kernels_are_built_and_current``."""
from __future__ import annotations

import copy
import json

import numpy as np
import pytest

from graspdef import compiled
from graspdef.compiled import Kernel

ROOT = compiled._HERE.parent


@pytest.fixture
def fresh_state(monkeypatch):
    """The module's process-level caches emptied for the test and restored after it."""
    monkeypatch.setattr(compiled, "_aot_state", {})
    for ks in compiled._REGISTRY.values():
        for k in ks:
            monkeypatch.setattr(k, "_aot", None)


def test_the_ahead_of_time_kernels_are_built_and_current():
    """``make setup`` builds the module from the kernel sources as they are (its stamp is their
    SHA-256); every kernel with ``aot`` signatures is in it."""
    assert compiled._aot_module() is not None, compiled.aot_status()
    stamp = json.loads((compiled._HERE / f"{compiled.AOT_NAME}.json").read_text())
    want = {k.export_name(i) for k in compiled.kernels() for i in range(len(k.signatures))}
    assert want and set(stamp["exports"]) == want


def _record(monkeypatch) -> dict:
    """Wrap Kernel.__call__: the first arguments of every ahead-of-time export that a call would
    use, copied before the call (the kernels write into some of them)."""
    seen: dict = {}
    call = Kernel.__call__

    def recording(self, *args):
        if self._aot is None:
            self._aot = compiled._aot_exports(self)
        for i in range(len(self.signatures)):
            name = self.export_name(i)
            spec = compiled._aot_state.get("exports", {}).get(name)
            if name not in seen and spec is not None and compiled._matches(args, spec):
                seen[name] = (self, getattr(compiled._aot_module(), name), copy.deepcopy(args))
                break
        return call(self, *args)
    monkeypatch.setattr(Kernel, "__call__", recording)
    return seen


def _same(a, b) -> bool:
    if isinstance(a, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
    return (a == b) or (a != a and b != b)


def _cases():
    """Real solves that call every exported kernel: the linear plate (patterns, strains, the shell's
    assembly, the KKT matrix), a neo-Hookean ball holding gas (densities, enclosed volume) and two
    pads squeezing a sphere with friction (box distances, the contact samples' gather/scatter and Hessian)."""
    from graspdef.contact.barrier import FingerContact, RoundedBox
    from graspdef.contact.friction import FingerFriction
    from graspdef.geometry import icosphere
    from graspdef.problem.config import load_problem
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.potentials import EnclosedGas
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import RigidModes
    from graspdef.shell.hyperelastic import NeoHookean
    from graspdef.shell.materials import LinearElastic
    from graspdef.shell.model import Shell
    from graspdef.solve.linear import solve_linear
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

    solve_linear(load_problem(ROOT / "benchmarks" / "plate_ss_uniform.toml").problem)
    R, t = 0.0325, 0.0025
    m = icosphere(radius=R, subdivisions=2)
    pr = Problem(Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), t), [EnclosedGas(8e4)], [RigidModes()])
    top, bot = pr.locate((0, 0, R)), pr.locate((0, 0, -R))
    pr.loads += [PointLoad(top.face, top.bary, (0, 0, -2.0)), PointLoad(bot.face, bot.bary, (0, 0, 2.0))]
    assert solve_nonlinear(pr, PathOptions(steps=2)).completed
    shell = Shell(m.vertices, m.faces, LinearElastic(1e6, 0.45), 0.002)

    def pad(side):
        c = np.array([side * (R + 0.001 + 0.002), 0.0, 0.0])
        return RoundedBox(tuple(c), tuple(map(tuple, np.eye(3))), (0.002, 0.008, 0.008), 0.002)
    fingers = [FingerContact(pad(s), (-s, 0.0, 0.0), 0.5, offset=0.001, name=n) for s, n in ((1.0, "r"), (-1.0, "l"))]
    friction = [FingerFriction(f, 0.5) for f in fingers]
    assert solve_nonlinear(Problem(shell, fingers + friction, [RigidModes()]), PathOptions(steps=2)).completed


def test_every_ahead_of_time_kernel_gives_the_jit_builds_numbers_to_the_bit(monkeypatch, fresh_state):
    """On the inputs of real solves (``_cases``), each export's result and everything it writes
    into its arguments equal the JIT build's exactly (serial against parallel, pycc against JIT:
    no reductions across a parallel loop, no fastmath).  Every export must be called by a case."""
    if compiled._aot_module() is None:
        pytest.fail(compiled.aot_status())
    monkeypatch.setattr(compiled, "SERIAL_MAX", 10**9)
    seen = _record(monkeypatch)
    _cases()
    assert set(seen) == set(compiled._aot_state["exports"]), "exports no case calls: " + \
        ", ".join(sorted(set(compiled._aot_state["exports"]) - set(seen)))
    for name, (k, aot, args) in sorted(seen.items()):
        a1, a2 = copy.deepcopy(args), copy.deepcopy(args)
        r1, r2 = aot(*a1), k.jit(*a2)
        assert _same(r1, r2), name
        assert all(_same(x, y) for x, y in zip(a1, a2)), f"{name}: its outputs written into arguments differ"


def test_arguments_of_other_types_go_to_the_jit_build(fresh_state):
    """An int32 stencil array (the export wants int64) or a strided view is not passed to the
    ahead-of-time wrapper (it would read the memory as int64: a crash); the JIT build answers, with
    the same numbers as for the int64 array."""
    from graspdef.shell._kernels import block_positions

    stencils = np.array([[0, 1, 2], [2, 1, 0]], np.int64)
    indptr, cols = np.array([0, 3, 6, 9], np.int64), np.array([0, 1, 2] * 3, np.int64)
    want = block_positions(stencils, indptr, cols)
    assert list(want[:3]) == [0, 1, 2]          # rows 0..2 hold columns 0, 1, 2 at positions 3r + c
    assert np.array_equal(block_positions(stencils.astype(np.int32), indptr, cols), want)
    wide = np.zeros((2, 6), np.int64)
    wide[:, ::2] = stencils
    assert np.array_equal(block_positions(wide[:, ::2], indptr, cols), want)
    spec = compiled._aot_state["exports"][block_positions.export_name(0)]
    assert compiled._matches((stencils, indptr, cols), spec)
    assert not compiled._matches((stencils.astype(np.int32), indptr, cols), spec)
    assert not compiled._matches((wide[:, ::2], indptr, cols), spec)
    assert not compiled._matches((stencils, indptr), spec)


def test_a_stale_module_is_not_used(monkeypatch, fresh_state):
    """Kernel sources changed since the build (another stamp): the JIT build is used, and says why."""
    monkeypatch.setattr(compiled, "source_stamp", lambda: "0" * 64)
    assert compiled._aot_module() is None
    assert "stale" in compiled.aot_status() and "python -m graspdef.compiled" in compiled.aot_status()
    from graspdef.solve._kernels import kkt_upper_values

    out = kkt_upper_values(np.array([1, 0, -1, -3], np.int64), np.array([5.0, 6.0]), np.array([7.0, 8.0]), 2.0)
    assert list(out) == [6.0, 5.0, 14.0, 0.0]


def test_a_run_folder_records_which_builds_ran(tmp_path):
    """provenance.json names the ahead-of-time module in use and the modules the JIT compiled."""
    from graspdef.runs.provenance import write_provenance, read_provenance
    from graspdef.solve._kernels import kkt_upper_values

    kkt_upper_values(np.array([0], np.int64), np.array([1.0]), np.array([2.0]), 1.0)
    k = read_provenance(write_provenance(tmp_path).parent)["kernels"]
    assert k["ahead_of_time"] == compiled.aot_status() and k["ahead_of_time"].startswith("ahead-of-time kernels in use")
    assert set(k["jit"]) <= set(compiled.KERNEL_MODULES)
