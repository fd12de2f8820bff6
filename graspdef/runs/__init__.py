"""The run folder: one versioned record (:mod:`.record`), its derived quantities with their
definitions (:mod:`.derived`), the one writer (:mod:`.write`), the one reader (:mod:`.read`),
the atomic folder helper and provenance.  The format is documented in docs/run-folder.md.

It sits just above geometry: it knows files and arrays, not solvers, so every writer (solve,
grasp pipeline, score, sweep, bench) and every consumer (report, viewer, sweep tables, gallery
scripts) can use it.  Names load on first use (PEP 562)."""
from __future__ import annotations

_NAMES = {
    "RunRecord": "record", "RunFolderError": "record", "SCHEMA_VERSION": "record", "SI_UNITS": "record",
    "CONSISTENT_UNITS": "record",
    "write_run": "write", "read_run": "read", "RunData": "read", "find_score": "read",
    "atomic_folder": "folder", "write_provenance": "provenance", "read_provenance": "provenance",
    "rigid_fit_residual": "derived",
}
__all__ = sorted(_NAMES)


def __getattr__(name: str):
    if name in _NAMES:
        import importlib

        return getattr(importlib.import_module(f".{_NAMES[name]}", __name__), name)
    raise AttributeError(f"module 'graspdef.runs' has no attribute {name!r}")
