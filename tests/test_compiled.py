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
