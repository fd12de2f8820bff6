"""The code trees a benchmark script compares: the working tree (NEW) and, given a git ref, that
ref's code checked out into a temporary worktree (OLD), removed afterwards.  Used by the scripts
with ``--ref`` (bench_speed.py, bench_nonlinear_speed.py, bench_grasp_speed.py).

The kernels' ahead-of-time module (``graspdef/_aot*``, built by ``make setup``, not in git) is
copied into OLD as well, so that both trees run the same compiled kernels: the module carries the
SHA-256 of the kernel sources it was built from and is ignored where they differ
(graspdef.compiled).  Where they differ, OLD's own module is built from OLD's sources (``python -m
graspdef.compiled`` in OLD, ~8 s), as ``make setup`` would on a checkout of OLD: until 2026-11-28
such an OLD tree ran numba's JIT build for every kernel, which its start-up (~0.3 s per process)
made slower than it is -- the pad grasp against a7ac2f9, whose kernels differ, by 0.3 s.

Each tree's processes run with the environment that tree's own ``runtime.configure()`` makes
(:func:`tree_env`), from the environment the script started with: since 2026-12-07 configure also
sets glibc's heap thresholds (``MALLOC_*``, graspdef.runtime.keep_heap), which a child inherits,
and an OLD tree from before then must not get them from NEW's configure."""
from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

#: the environment before the script's own ``runtime.configure()`` (scripts import this module first)
BASE_ENV = dict(os.environ)
_ENVS: dict = {}


@contextlib.contextmanager
def code_trees(root: Path, ref: str | None, prefix: str = "bench_"):
    """{"NEW": root} or, with ``ref``, {"OLD": <worktree of ref>, "NEW": root} (OLD first)."""
    if not ref:
        yield {"NEW": root}
        return
    commit = subprocess.run(["git", "-C", str(root), "rev-parse", ref], capture_output=True, text=True,
                            check=True).stdout.strip()
    tmp = Path(tempfile.mkdtemp(prefix=prefix))
    subprocess.run(["git", "-C", str(root), "worktree", "add", "--detach", str(tmp / "old"), commit],
                   capture_output=True, check=True)
    for aot in (root / "graspdef").glob("_aot*"):
        shutil.copy2(aot, tmp / "old" / "graspdef" / aot.name)
    _own_aot(tmp / "old")
    try:
        yield {"OLD": tmp / "old", "NEW": root}
    finally:
        subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(tmp / "old")], capture_output=True)


def _own_aot(tree: Path) -> None:
    """Build ``tree``'s own ahead-of-time kernel module when the copied one is not for its kernel
    sources (a tree from before the module existed has nothing to build)."""
    if not (tree / "graspdef" / "compiled.py").exists():
        return
    env = {**os.environ, "PYTHONPATH": str(tree)}
    status = subprocess.run([sys.executable, "-c", "from graspdef import compiled; print(compiled.aot_status())"],
                            cwd=tree, env=env, capture_output=True, text=True).stdout.strip()
    if status.startswith("ahead-of-time kernels in use"):
        return
    print(f"building OLD's own ahead-of-time kernels ({status.splitlines()[-1] if status else 'no module'})",
          file=sys.stderr, flush=True)
    subprocess.run([sys.executable, "-m", "graspdef.compiled"], cwd=tree, env=env, capture_output=True, check=True)


def tree_env(tree: Path) -> dict:
    """The environment of a process of ``tree``'s code: :data:`BASE_ENV` as ``tree``'s own
    ``runtime.configure()`` fills it in (a tree without graspdef.runtime: as it is), with
    ``PYTHONPATH`` = ``tree``; made once per tree."""
    tree = Path(tree)
    if tree not in _ENVS:
        import json

        env = {**BASE_ENV, "PYTHONPATH": str(tree)}
        if (tree / "graspdef" / "runtime.py").exists():
            out = subprocess.run([sys.executable, "-c", "import json, os\nfrom graspdef import runtime\n"
                                  "runtime.configure()\nprint(json.dumps(dict(os.environ)))"],
                                 cwd=tree, env=env, capture_output=True, text=True, check=True).stdout
            env = json.loads(out.strip().splitlines()[-1])
        _ENVS[tree] = env
    return dict(_ENVS[tree])
