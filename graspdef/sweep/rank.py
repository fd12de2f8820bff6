"""``graspdef rank ... --workers N | --scheduler tcp://HOST:PORT``: the linear screen's candidates
spread over a Dask cluster in chunks.  Each chunk is one task, :func:`graspdef.ranking.run.screen_chunk`
(its own factorisation, then the chunk's back-substitutions); the client gathers the figures in
candidate order and ranks them as the local screen does (the results are the same to rounding).
"""
from __future__ import annotations

import logging

import numpy as np

from ..ranking.run import rank_object, screen_chunk
from ..ranking.screen import PairFigures
from .run import SweepError, _connect


def rank_on_dask(scene, force: float | None, candidates: int = 2000, out=None, *, scheduler: str | None = None,
                 workers: int = 2, chunks: int | None = None, connect_timeout: float = 5.0, **kwargs) -> dict:
    """:func:`graspdef.ranking.rank_object` with the screen run as ``chunks`` Dask tasks (default:
    two per worker) on an embedded LocalCluster of ``workers`` processes or at ``scheduler``."""
    scene_path = str(scene)
    pad_size = kwargs.get("pad_size", 0.024)
    say = kwargs.get("progress") or (lambda stage, info=None: None)
    quiet = {n: lg.level for n, lg in logging.root.manager.loggerDict.items()
             if n.split(".")[0] == "distributed" and isinstance(lg, logging.Logger)}
    for n in quiet:
        logging.getLogger(n).setLevel(logging.ERROR)
    client, cluster = _connect(scheduler, workers, connect_timeout)
    try:
        n_workers = max(len(client.scheduler_info().get("workers", {})), 1)
        n_chunks = int(chunks) if chunks is not None else 2 * n_workers
        if n_chunks < 1:
            raise SweepError(f"--chunks must be >= 1, got {chunks}")

        def screen_with(first: np.ndarray, second: np.ndarray, forces: np.ndarray) -> PairFigures:
            parts = np.array_split(np.arange(len(first)), min(n_chunks, len(first)))
            futures = [client.submit(screen_chunk, scene_path, forces[p], first[p], second[p], pad_size, pure=False)
                       for p in parts]
            results = []
            for k, f in enumerate(futures):
                results.append(f.result())
                say("candidate", {"done": int(sum(len(p) for p in parts[: k + 1])), "of": len(first)})
            return PairFigures.concat(results)

        dask = {"scheduler": scheduler or f"LocalCluster({workers} processes x 1 thread)", "workers": n_workers,
                "chunks": n_chunks}
        return rank_object(scene, force, candidates, out, screen_with=screen_with, extra={"dask": dask}, **kwargs)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
        for n, level in quiet.items():
            logging.getLogger(n).setLevel(level)
