"""The code trees a benchmark script compares: the working tree (NEW) and, given a git ref, that
ref's code checked out into a temporary worktree (OLD), removed afterwards.  Used by the scripts
with ``--ref`` (bench_speed.py, bench_nonlinear_speed.py, bench_grasp_speed.py).

The kernels' ahead-of-time module (``graspdef/_aot*``, built by ``make setup``, not in git) is
copied into OLD as well, so that both trees run the same compiled kernels: the module carries the
SHA-256 of the kernel sources it was built from and is ignored where they differ (graspdef.compiled),
so an OLD tree with other kernels runs numba's JIT build as it would on its own."""
from __future__ import annotations

import contextlib
import shutil
import subprocess
import tempfile
from pathlib import Path


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
    try:
        yield {"OLD": tmp / "old", "NEW": root}
    finally:
        subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(tmp / "old")], capture_output=True)
