"""Scans: the manifest of real and generated scans, loading them in metres, scan -> control mesh
and shell mid-surface, and a structured-light scanner model for synthetic scans."""

from graspdef.scans.manifest import (
    Manifest,
    ScanEntry,
    load_manifest,
    load_scan,
    ply_units,
    read_surface,
    scan_entry,
    shared_scans_dir,
)
from graspdef.scans.remesh import ControlMeshReport, control_mesh, mid_surface, vertex_normals
from graspdef.scans.scanner import (
    NEXTENGINE_SIGMA,
    Scanner,
    SyntheticScan,
    generate_scan,
    load_generated_scan,
    scan_surface,
    write_scan,
)

__all__ = ["ControlMeshReport", "Manifest", "NEXTENGINE_SIGMA", "ScanEntry", "Scanner",
           "SyntheticScan", "control_mesh", "generate_scan", "load_generated_scan",
           "load_manifest", "load_scan",
           "mid_surface", "ply_units", "read_surface", "scan_entry", "scan_surface",
           "shared_scans_dir", "vertex_normals", "write_scan"]
