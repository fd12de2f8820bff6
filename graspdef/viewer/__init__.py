"""The browser viewer (issue 7): ``graspdef view RUN_DIR [RUN_DIR ...]`` (or a ranking folder:
:mod:`.ranking`) serves a viser page on
127.0.0.1.  viser is imported only in :mod:`graspdef.viewer.server`, and only when a viewer
starts; run folders are read with :func:`graspdef.runs.read_run`; the drawing helpers (:mod:`.layers`) need numpy,
scipy and trimesh only."""
from __future__ import annotations



def view(run_dirs, host: str = "127.0.0.1", port: int = 8080, block: bool = True, **kwargs):
    """Serve run folders in the browser; see :func:`graspdef.viewer.server.view`."""
    from .server import view as _view

    return _view(run_dirs, host, port, block, **kwargs)


__all__ = ["view"]
