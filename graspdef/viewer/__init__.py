"""The browser viewer (issue 7): ``graspdef view RUN_DIR [RUN_DIR ...]`` serves a viser page on
127.0.0.1.  viser is imported only in :mod:`graspdef.viewer.server`, and only when a viewer
starts; reading run folders (:mod:`.runs`) and the drawing helpers (:mod:`.layers`) need numpy,
scipy and trimesh only."""
from __future__ import annotations

from ..solve.pathfile import read_path_u as read_path_u
from ..solve.pathfile import write_path_u as write_path_u
from ..solve.pathfile import write_solution_path as write_solution_path
from .runs import RunData as RunData
from .runs import RunFolderError as RunFolderError
from .runs import read_run as read_run


def view(run_dirs, host: str = "127.0.0.1", port: int = 8080, block: bool = True, **kwargs):
    """Serve run folders in the browser; see :func:`graspdef.viewer.server.view`."""
    from .server import view as _view

    return _view(run_dirs, host, port, block, **kwargs)


__all__ = ["view", "read_run", "RunData", "RunFolderError", "read_path_u", "write_path_u",
           "write_solution_path"]
