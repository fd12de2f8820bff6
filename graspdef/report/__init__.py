"""HTML reports of run folders (issue 6): headless surface pictures (:mod:`.render`), plots
(:mod:`.plots`), the self-contained page (:mod:`.html`) and the report itself (:mod:`.build`; of a
ranking folder: :mod:`.ranking`;
``graspdef report`` is :mod:`graspdef.cli.report`).  matplotlib (Agg, object-oriented API) only; open3d only
through :mod:`graspdef.registration`, and only when a scan is scored."""
from __future__ import annotations

from .build import PAPER_TABLE_I as PAPER_TABLE_I
from .build import ReportError as ReportError
from .build import build_report as build_report
from .ranking import build_ranking_report as build_ranking_report
from .render import VIEWS as VIEWS
from .render import render_surface as render_surface

__all__ = ["PAPER_TABLE_I", "ReportError", "VIEWS", "build_ranking_report", "build_report", "render_surface"]
