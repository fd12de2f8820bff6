"""Derived quantities of a run, computed once by the writer and stored in ``result.json`` under
``derived`` with their definitions, so that every consumer (CLI line, report table, caption and
colour bar, viewer, sweep table, gallery scripts) shows the same number under the same label.

Each entry is a dict ``{"value": ..., "unit": ..., "label": ..., "definition": ..., ...}``; the
value is SI (or in the run's consistent units).  The displacement field that defines
``max_displacement`` is stored per vertex in ``deformed.ply`` (``ux, uy, uz``), so a colour map
of it tops out at exactly this value.
"""
from __future__ import annotations

import numpy as np


def rigid_fit_residual(x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """``u`` (n, 3) minus its least-squares infinitesimal rigid motion (translation + rotation
    about the centroid of ``x``): the deformation part of a free body's displacement."""
    r = x - x.mean(axis=0)
    A = np.zeros((3 * len(x), 6))
    A[:, :3] = np.tile(np.eye(3), (len(x), 1))
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1.0
        A[:, 3 + k] = np.cross(e, r).ravel()
    coef = np.linalg.lstsq(A, u.ravel(), rcond=None)[0]
    return u - (A @ coef).reshape(-1, 3)


def entry(value, unit: str, label: str, definition: str, **extra) -> dict:
    """One derived quantity (JSON-ready)."""
    if isinstance(value, np.ndarray):
        value = value.tolist()
    elif isinstance(value, (np.floating, np.integer)):
        value = value.item()
    return {"value": value, "unit": unit, "label": label, "definition": definition, **extra}


def max_displacement(rest: np.ndarray, u: np.ndarray, unit: str, *, rigid_motion_removed: bool,
                     reference: str) -> dict:
    """The largest |u| over the limit-surface vertices of the mid-surface, where it is, and how
    ``u`` was measured (``u``: the stored per-vertex field)."""
    mag = np.linalg.norm(u, axis=1)
    i = int(np.argmax(mag))
    how = "best-fit rigid motion removed" if rigid_motion_removed else "as solved (supports hold the body)"
    return entry(float(mag[i]), unit, "max. displacement",
                 f"largest |u| over the limit-surface vertices of the mid-surface; u from the {reference}, {how}",
                 surface="mid", rigid_motion_removed=bool(rigid_motion_removed), reference=reference,
                 vertex=i, at=rest[i].tolist())


def displacement_field_label(derived: dict) -> str:
    """Colour-bar label of the stored displacement field (matches ``max_displacement``)."""
    md = derived.get("max_displacement") or {}
    return "|u| (rigid motion removed)" if md.get("rigid_motion_removed") else "|u|"


def plausibility_warnings(analysis: str, max_displacement: float, thickness: float | None, size: float,
                          unit: str = "m") -> list[str]:
    """Loud warnings a result carries in its record (and the CLI prints): a linear result whose
    displacement exceeds the thickness (linear theory assumes small rotations: use the nonlinear
    analysis) or the object itself."""
    out = []
    to = 1e3 if unit == "m" else 1.0
    u = "mm" if unit == "m" else unit
    if size > 0 and max_displacement > size:
        out.append(f"the max. displacement {max_displacement * to:.4g} {u} exceeds the object's size "
                   f"{size * to:.4g} {u}: the result is not physical (check the thickness, modulus and loads)")
    if analysis == "linear" and thickness and max_displacement > thickness:
        out.append(f"linear result with a max. displacement of {max_displacement * to:.4g} {u}, more than the "
                   f"thickness {thickness * to:.4g} {u}: linear theory does not hold there; use the nonlinear "
                   "analysis")
    return out
