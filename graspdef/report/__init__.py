"""HTML reports of run folders (issue 6): headless surface pictures (:mod:`.render`), plots
(:mod:`.plots`), the self-contained page (:mod:`.html`) and ``graspdef report`` (:mod:`.cli`).
matplotlib (Agg) only; open3d only through :mod:`graspdef.registration`."""
from __future__ import annotations

from .render import VIEWS as VIEWS
from .render import render_surface as render_surface

__all__ = ["VIEWS", "render_surface"]
