"""The run record: ``result.json`` of a run folder, one versioned type for every kind of run.

Layout (schema 2; see docs/run-folder.md)::

    {"schema": "graspdef.run", "schema_version": 2,
     "kind": "solve" | "grasp" | "synthetic", "name": ..., "analysis": "linear" | "nonlinear",
     "units": {"length": "m", "force": "N", "energy": "J", "pressure": "Pa"}   (or "consistent"),
     "derived": {name: {"value", "unit", "label", "definition", ...}},
     "files": {role: file name},
     ... the kind's own fields (all SI, names carry their unit: force_N, thickness_m, ...)}

Values are SI inside and in the file; a problem in consistent units (textbook benchmarks without
physical units) states ``"consistent"`` instead.  Folders of schema 1 (written before graspdef
0.2) are refused with one line saying how to regenerate them; a newer schema with one line too.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import GraspdefError

SCHEMA = "graspdef.run"
SCHEMA_VERSION = 2
KINDS = ("solve", "grasp", "synthetic")
SI_UNITS = {"length": "m", "force": "N", "energy": "J", "pressure": "Pa"}
CONSISTENT_UNITS = {"length": "consistent", "force": "consistent", "energy": "consistent", "pressure": "consistent"}
_HEAD = ("schema", "schema_version", "kind", "name", "analysis", "units", "derived", "files")


class RunFolderError(GraspdefError):
    """A run folder is missing, incomplete, unreadable or of another schema."""


@dataclass(frozen=True)
class RunRecord:
    """``result.json``: what every consumer of a run reads (treat the mappings as read-only).

    ``data`` holds the kind's own fields; ``record[key]`` / ``record.get(key)`` read them (and the
    head fields), so the record reads like the JSON document it is."""

    kind: str
    name: str
    analysis: str
    units: Mapping[str, str]
    derived: Mapping[str, dict] = field(default_factory=dict)
    files: Mapping[str, str] = field(default_factory=dict)
    data: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"run kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.analysis not in ("linear", "nonlinear"):
            raise ValueError(f"analysis must be 'linear' or 'nonlinear', got {self.analysis!r}")
        clash = set(_HEAD) & set(self.data)
        if clash:
            raise ValueError(f"run record data may not use the head keys {sorted(clash)}")

    # ---- the JSON document ---------------------------------------------------------------------
    def to_json(self) -> dict:
        return {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "kind": self.kind, "name": self.name,
                "analysis": self.analysis, "units": dict(self.units), "derived": dict(self.derived),
                "files": dict(self.files), **self.data}

    @classmethod
    def from_json(cls, doc, where: str) -> "RunRecord":
        """Check and read a parsed ``result.json``; every problem is one :class:`RunFolderError`."""
        if not isinstance(doc, dict):
            raise RunFolderError(f"{where}: result.json must hold a JSON object")
        if doc.get("schema") != SCHEMA:
            if "units" in doc and ("max_displacement" in doc or "max_displacement_m" in doc):
                raise RunFolderError(f"{where} was written by an older graspdef (run-folder schema 1); regenerate it "
                                     "with the command in its provenance.json (graspdef solve/grasp ... --out DIR)")
            raise RunFolderError(f"{where}: result.json is not a graspdef run record (no schema '{SCHEMA}')")
        v = doc.get("schema_version")
        if not isinstance(v, int) or v < 1:
            raise RunFolderError(f"{where}: result.json: schema_version must be a positive integer, got {v!r}")
        if v > SCHEMA_VERSION:
            raise RunFolderError(f"{where} has run-folder schema {v}, newer than this graspdef reads "
                                 f"({SCHEMA_VERSION}): update graspdef")
        if v < SCHEMA_VERSION:
            raise RunFolderError(f"{where} has run-folder schema {v}; regenerate it with the command in its "
                                 "provenance.json")
        try:
            units = doc["units"]
            if not isinstance(units, dict) or not isinstance(units.get("length"), str):
                raise RunFolderError(f"{where}: result.json: 'units' must state at least the length unit")
            derived = doc.get("derived", {})
            if not isinstance(derived, dict) or not all(isinstance(d, dict) and "value" in d for d in derived.values()):
                raise RunFolderError(f"{where}: result.json: 'derived' must map names to {{value, unit, ...}}")
            files = doc.get("files", {})
            if not isinstance(files, dict):
                raise RunFolderError(f"{where}: result.json: 'files' must be an object")
            return cls(str(doc["kind"]), str(doc["name"]), str(doc["analysis"]), units, derived, files,
                       {k: v for k, v in doc.items() if k not in _HEAD})
        except KeyError as exc:
            raise RunFolderError(f"{where}: result.json lacks {exc}") from None
        except ValueError as exc:
            raise RunFolderError(f"{where}: result.json: {exc}") from None

    # ---- reading ---------------------------------------------------------------------------------
    def __getitem__(self, key: str):
        if key in _HEAD[2:]:
            return getattr(self, key)
        return self.data[key]

    def __contains__(self, key: str) -> bool:
        return key in _HEAD[2:] or key in self.data

    def get(self, key: str, default=None):
        try:
            return self[key]
        except KeyError:
            return default

    def value(self, name: str, default=None):
        """The value of the derived quantity ``name`` (SI or consistent), or ``default``."""
        d = self.derived.get(name)
        return default if d is None else d["value"]

    @property
    def consistent(self) -> bool:
        return self.units.get("length") == "consistent"
