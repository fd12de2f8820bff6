"""The two builds of graspdef's compiled kernels (graspdef.compiled): the ahead-of-time serial
module must compute what the JIT build computes, to the bit, and must never be given arguments
of other types (its pycc wrappers do not check them: an int32 array read as int64 crashes).

The ahead-of-time module is built by ``make setup`` (``python -m graspdef.compiled``); a checkout
where it is missing or stale fails ``test_the_ahead_of_time_kernels_are_built_and_current``."""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from graspdef import compiled

ROOT = compiled._HERE.parent


@pytest.fixture
def fresh_state(monkeypatch):
    """The module's process-level caches emptied for the test and restored after it.  Every kernel
    module is imported first: a kernel registered only during the test (its module imported by it)
    kept the ``_aot`` the test's fake module gave it (none usable) after the test, and a later
    ``bench kernels`` in the same process found no call of it (kkt_upper_values "missing": it
    failed 1 run in 2 under ``pytest -n 2`` without ``--dist loadfile`` with a cold numba cache)."""
    compiled.kernels()
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


def test_every_ahead_of_time_kernel_gives_the_jit_builds_numbers_to_the_bit():
    """``graspdef bench kernels`` (graspdef.bench.check_kernels): on the arguments that small real
    solves give them (a linear plate, a neo-Hookean ball with gas, pads and pins with friction),
    each export's result and everything it writes into its arguments equal the JIT build's exactly
    (serial against parallel, pycc against JIT: no reductions across a parallel loop, no fastmath);
    every export is reached."""
    from graspdef.bench import check_kernels

    out = check_kernels()
    assert out["status"].startswith("ahead-of-time kernels in use"), out["status"]
    assert out["missing"] == [], "exports no solve reached: " + ", ".join(out["missing"])
    assert len(out["records"]) == len({k.export_name(i) for k in compiled.kernels() for i in range(len(k.signatures))})
    assert [r["export"] for r in out["records"] if not r["equal"]] == []


def test_compare_finds_a_difference():
    """The comparison can fail: an export recorded with the arguments of one call but compared with
    a JIT build that computes something else (here: another kernel of the same arguments' types)."""
    from graspdef.solve._kernels import kkt_upper_values

    src, kd, cd = np.array([1, 0, -1], np.int64), np.array([5.0, 6.0]), np.array([7.0])
    with compiled.recording() as rec:
        kkt_upper_values(src, kd, cd, 2.0)
    (name, (k, f, args)), = rec.items()
    assert compiled.compare(rec)[0]["equal"]
    other = SimpleNamespace(jit=lambda s, a, b, c: np.ones(len(s)), __module__="x", __name__="ones")
    rec[name] = (other, f, args)
    assert not compiled.compare(rec)[0]["equal"]


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


def test_a_module_built_for_another_processor_is_not_used(monkeypatch, fresh_state):
    """The module is compiled for the build machine's instruction set: on another processor model
    (a shared disk) it is not loaded, and the status says so."""
    monkeypatch.setattr(compiled, "cpu_name", lambda: "some other processor")
    assert compiled._aot_module() is None
    assert "another processor" in compiled.aot_status()


def test_bench_kernels_without_the_module_is_one_line(monkeypatch, fresh_state, capsys):
    """``graspdef bench kernels`` where the module is stale: exit status 2 and one line that says
    why and how to build it."""
    from graspdef.cli import main

    monkeypatch.setattr(compiled, "source_stamp", lambda: "0" * 64)
    assert main(["-q", "bench", "kernels"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "stale" in err[0] and "python -m graspdef.compiled" in err[0], err


def test_bench_kernels_writes_its_folder_and_refuses_options_it_ignores(tmp_path, capsys):
    """``--out DIR``: kernels.json (every export equal) and provenance.json; ``--only`` and ``--dir``
    (which select benchmark files) are one-line errors, exit 2, nothing written."""
    from graspdef.cli import main

    assert main(["-q", "bench", "kernels", "--out", str(tmp_path / "k")]) == 0
    rec = json.loads((tmp_path / "k" / "kernels.json").read_text())
    assert rec["records"] and all(r["equal"] for r in rec["records"]) and rec["missing"] == []
    assert (tmp_path / "k" / "provenance.json").is_file()
    for extra in (["--only", "plate*"], ["--dir", str(tmp_path)]):
        capsys.readouterr()
        assert main(["-q", "bench", "kernels", "--out", str(tmp_path / "x"), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and extra[0] in err[0], err
        assert not (tmp_path / "x").exists()


@pytest.fixture
def fresh_loader(monkeypatch):
    """A loader of its own and no overload marked loaded, for the test (restored after it)."""
    compiled.kernels()
    monkeypatch.setattr(compiled, "_LOADER", compiled._Loader())
    for ks in compiled._REGISTRY.values():
        for k in ks:
            monkeypatch.setattr(k, "_ready", set())
    return compiled._LOADER


def _ball_shell(subdivisions=2):
    from graspdef.geometry import icosphere
    from graspdef.shell.hyperelastic import NeoHookean
    from graspdef.shell.model import Shell

    m = icosphere(radius=0.0325, subdivisions=subdivisions)
    return Shell(m.vertices, m.faces, NeoHookean(1e6 / 3), 0.0025)


def test_a_large_call_runs_ahead_of_time_until_its_jit_build_is_loaded(monkeypatch, fresh_loader):
    """compiled._Loader: a call above SERIAL_MAX whose JIT overload is not loaded runs the serial
    ahead-of-time export and asks the loader thread for it; once loaded, the same call runs the JIT
    build -- the overload the loader made (no other is compiled for the call) -- with the same
    numbers to the bit.  The loader's thread ends when nothing is asked."""
    from graspdef.shell._kernels import block_positions

    shell = _ball_shell()
    pat = shell.block_pattern
    st = np.ascontiguousarray(shell.basis.groups[0].stencils, np.int64)
    args = (st, pat.indptr, pat.cols)
    monkeypatch.setattr(compiled, "SERIAL_MAX", 1)            # every call of this shell "large"
    export, spec = block_positions._aot[0] if block_positions._aot else compiled._aot_exports(block_positions)[0]
    calls = []
    monkeypatch.setattr(block_positions, "_aot", [(lambda *a: calls.append(1) or export(*a), spec)])
    first = block_positions(*args)
    assert calls == [1]                                       # ran ahead of time, and asked
    fresh_loader.join()
    assert fresh_loader._thread is None
    key = compiled._type_key(args)
    assert key in block_positions._ready
    n = len(block_positions.jit.overloads)
    again = block_positions(*args)
    assert calls == [1] and len(block_positions.jit.overloads) == n    # the JIT build, already loaded
    assert np.array_equal(first, again)


def test_a_large_shells_solve_loads_its_kernels_jit_build_at_its_start(monkeypatch, fresh_loader):
    """compiled.prepare (called by Equilibrium): for a shell above SERIAL_MAX every parallel
    kernel's overload for its ahead-of-time signatures is loaded in the loader thread, and the
    solve's own calls (the shell's Hessian, the enclosed volume, the tangent's sum) have exactly
    those types: they run the JIT build without compiling anything more.  A small shell asks for
    nothing."""
    from graspdef.problem.potentials import EnclosedGas
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import RigidModes
    from graspdef.solve.equilibrium import Equilibrium

    small = _ball_shell(1)
    Equilibrium(Problem(small, [EnclosedGas(8e4)], [RigidModes()]))
    assert not fresh_loader._asked
    monkeypatch.setattr(compiled, "SERIAL_MAX", 16)
    shell = _ball_shell(2)                                    # 320 faces
    assert not fresh_loader._asked                            # asked when its solve starts
    eq = Equilibrium(Problem(shell, [EnclosedGas(8e4)], [RigidModes()]))
    asked = {k.__name__ for k in compiled.kernels() if any(a[0] == id(k) for a in fresh_loader._asked)}
    assert {"assemble_elements", "point_strains", "density_points", "_volume_terms", "row_sums",
            "csr_products"} <= asked
    fresh_loader.join()
    par = [k for k in compiled.kernels() if k.parallel and k.signatures]
    before = {k.__name__: len(k.jit.overloads) for k in par}
    aot_calls = []
    for k in par:
        monkeypatch.setattr(k, "_aot", [(lambda *a, f=f, k=k: aot_calls.append((k.__name__, compiled._type_key(a), sorted(k._ready, key=str))) or f(*a), s) for f, s in compiled._aot_exports(k)])
    st = eq.evaluate(np.zeros(eq.n), 0.0, 2)
    assert st.hessian is not None and np.isfinite(st.energy)
    assert aot_calls == [], "\n".join(map(repr, aot_calls))
    assert {k.__name__: len(k.jit.overloads) for k in par} == before
    assert small.n_control < shell.n_control


def test_the_loaders_builds_give_a_path_to_the_bit(monkeypatch, fresh_loader):
    """A nonlinear path whose first calls ran ahead of time while the JIT build loaded equals, to
    the bit, the same path with every large call on the JIT build from the start (the module
    docstring: the two builds compute the same numbers)."""
    from graspdef.problem.loads import PointLoad
    from graspdef.problem.potentials import EnclosedGas
    from graspdef.problem.problem import Problem
    from graspdef.problem.supports import RigidModes
    from graspdef.solve.nonlinear import PathOptions, solve_nonlinear

    monkeypatch.setattr(compiled, "SERIAL_MAX", 16)

    def path():
        shell = _ball_shell(2)
        pr = Problem(shell, [EnclosedGas(8e4)], [RigidModes()])
        top, bot = pr.locate((0, 0, 0.0325)), pr.locate((0, 0, -0.0325))
        pr.loads += [PointLoad(top.face, top.bary, (0, 0, -2.0)), PointLoad(bot.face, bot.bary, (0, 0, 2.0))]
        sol = solve_nonlinear(pr, PathOptions(steps=2))
        assert sol.completed
        return sol.u, [p.load_factor for p in sol.path]

    first = path()                      # the loader works beside it (what it loads depends on timing)
    fresh_loader.join()
    second = path()                     # everything loaded: every large call on the JIT build
    assert np.array_equal(first[0], second[0]) and first[1] == second[1]


def test_a_call_above_loading_max_waits_for_its_jit_build(monkeypatch, fresh_loader):
    """A call with more work than LOADING_MAX is not run serially while its overload loads (a
    long serial run would cost more than the load): it runs the JIT build, loading it itself."""
    from graspdef.shell._kernels import block_positions

    shell = _ball_shell()
    pat = shell.block_pattern
    args = (np.ascontiguousarray(shell.basis.groups[0].stencils, np.int64), pat.indptr, pat.cols)
    monkeypatch.setattr(compiled, "SERIAL_MAX", 1)
    monkeypatch.setattr(compiled, "LOADING_MAX", 1)
    export, spec = compiled._aot_exports(block_positions)[0]
    calls = []
    monkeypatch.setattr(block_positions, "_aot", [(lambda *a: calls.append(1) or export(*a), spec)])
    out = block_positions(*args)
    assert calls == [] and not fresh_loader._asked
    assert np.array_equal(out, export(*args))
