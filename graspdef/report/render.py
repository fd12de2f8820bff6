"""Headless surface pictures (matplotlib Agg, no display, no OpenGL): a triangle mesh coloured
by a scalar, shaded, seen from a few directions, with one colour bar, as PNG bytes.

How: orthographic projection of every view direction; faces drawn back to front (painter's
order by the depth of their centroids) as one ``PolyCollection`` per view; Lambert shading
``ambient + diffuse * |n . l|`` (two-sided, so open surfaces show their inside); on closed
surfaces the faces turned away from the viewer are dropped first (they are hidden anyway),
which halves the work.  20,000 faces x 3 views take about a second.

Only matplotlib's object-oriented API is used (``Figure`` + ``FigureCanvasAgg``): no pyplot, no
global state, safe in threads and in tests.
"""
from __future__ import annotations

import io
from collections.abc import Sequence

import numpy as np

#: named view directions: (elevation, azimuth) in degrees, matplotlib's convention
#: (azimuth about +z from +x, elevation above the xy plane)
VIEWS = {"front": (10.0, -90.0), "back": (10.0, 90.0), "side": (10.0, 0.0), "top": (90.0, -90.0),
         "bottom": (-90.0, -90.0), "iso": (30.0, -60.0), "iso_back": (30.0, 120.0)}
DEFAULT_VIEWS = ("iso", "front", "top")


def _view_frame(elev: float, azim: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen right, screen up and towards-the-viewer unit vectors for (elev, azim) [deg]."""
    e, a = np.radians(elev), np.radians(azim)
    toward = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    if abs(np.sin(e)) < 0.999:
        up_hint = np.array([0.0, 0.0, 1.0])
    else:                                   # looking along z: screen up is away from the azimuth
        up_hint = -np.sign(np.sin(e)) * np.array([np.cos(a), np.sin(a), 0.0])
    right = np.cross(up_hint, toward)
    right /= np.linalg.norm(right)
    up = np.cross(toward, right)
    return right, up, toward


def _closed(faces: np.ndarray) -> bool:
    """Every edge shared by exactly two faces."""
    e = np.sort(faces[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return bool(len(counts)) and bool(np.all(counts == 2))


def _resolve_views(views) -> list[tuple[str, float, float]]:
    out = []
    for v in views:
        if isinstance(v, str):
            if v not in VIEWS:
                raise ValueError(f"unknown view {v!r} (named views: {', '.join(VIEWS)}; or (elev, azim) in degrees)")
            out.append((v, *VIEWS[v]))
        else:
            elev, azim = (float(x) for x in v)
            out.append((f"elev {elev:g}°, azim {azim:g}°", elev, azim))
    if not out:
        raise ValueError("no views to render")
    return out


def _log_ticks(vmin: float, vmax: float) -> list[float]:
    """1, 2, 5 x 10^k inside [vmin, vmax] (positive); with the two ends when fewer than three fall inside."""
    ticks = [m * 10.0 ** e for e in range(int(np.floor(np.log10(vmin))), int(np.ceil(np.log10(vmax))) + 1)
             for m in (1, 2, 5) if vmin * (1 - 1e-9) <= m * 10.0 ** e <= vmax * (1 + 1e-9)]
    return ticks if len(ticks) >= 3 else sorted(set([float(vmin), *ticks, float(vmax)]))


def face_values(scalars: np.ndarray, n_vertices: int, faces: np.ndarray) -> np.ndarray:
    """Per-face values (m,) from per-vertex (n,) scalars (the mean of the corners) or per-face ones."""
    s = np.asarray(scalars, dtype=np.float64).ravel()
    if len(s) == n_vertices:
        return s[faces].mean(axis=1)
    if len(s) == len(faces):
        return s
    raise ValueError(f"scalars must have one value per vertex ({n_vertices}) or per face ({len(faces)}), "
                     f"got {len(s)}")


def render_surface(vertices: np.ndarray, faces: np.ndarray, scalars: np.ndarray | None = None, *,
                   views: Sequence = DEFAULT_VIEWS, cmap: str = "viridis", label: str = "",
                   title: str = "", vmin: float | None = None, vmax: float | None = None,
                   symmetric: bool = False, panel_size: float = 3.2, dpi: int = 110,
                   colour: str = "#b8c4d6", light: Sequence[float] = (0.35, -0.5, 0.8),
                   cull: bool | None = None, edges: bool = False, view_titles: bool = True,
                   log: bool = False, segments: np.ndarray | None = None, segment_colours=None,
                   segment_labels: Sequence[str] | None = None) -> bytes:
    """Render a triangle mesh from one or more view directions into one PNG.

    Parameters
    ----------
    vertices : ndarray, shape (n, 3)
        Vertex positions (any consistent length unit; the picture is scale-free).
    faces : ndarray, shape (m, 3)
        Triangles (vertex indices).
    scalars : ndarray, shape (n,) or (m,), optional
        Values to colour by, per vertex (averaged over each face's corners) or per face; NaN is
        drawn grey.  Without them the surface is drawn in ``colour``.
    views : sequence
        View names (:data:`VIEWS`: front, back, side, top, bottom, iso, iso_back) or
        (elevation, azimuth) pairs in degrees; one panel each, side by side.
    cmap : str
        matplotlib colour map name (``viridis`` for magnitudes, ``coolwarm``/``RdBu_r`` for signed
        errors).
    label : str
        Colour-bar label, with the unit (e.g. ``"|u| [mm]"``).
    title : str
        Figure title.
    vmin, vmax : float, optional
        Colour range (default: the finite range of the scalars).
    symmetric : bool
        Colour range symmetric about zero (signed errors).
    panel_size : float
        Size of each panel [inch]; ``dpi`` the resolution.
    light : (3,) floats
        Light direction in screen coordinates (right, up, towards the viewer).
    cull : bool, optional
        Drop faces turned away from the viewer; default: only if the mesh is closed.
    edges : bool
        Draw the triangle edges (thin dark lines; for coarse meshes).
    log : bool
        Colour on a log scale (positive scalars; others are drawn grey like NaN).
    segments : ndarray, shape (k, 2, 3), optional
        Line segments in the vertices' coordinates, drawn **on top** of the surface in every view
        (not hidden by it: a segment between two surface points shows through the object), with
        dots at both ends; ``segment_colours`` (k colours, default black) and ``segment_labels``
        (k strings, written at the first end).

    Returns
    -------
    bytes
        The PNG file.
    """
    from matplotlib import colormaps
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import PolyCollection
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LogNorm, Normalize, to_rgba
    from matplotlib.figure import Figure
    from matplotlib.cm import ScalarMappable

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if v.ndim != 2 or v.shape[1] != 3 or len(v) == 0:
        raise ValueError(f"vertices must be an (n, 3) array with n > 0, got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0:
        raise ValueError(f"faces must be an (m, 3) array with m > 0, got shape {f.shape}")
    if f.min() < 0 or f.max() >= len(v):
        raise ValueError("faces refer to vertices that do not exist")
    if not np.all(np.isfinite(v)):
        raise ValueError("vertices hold NaN or infinite coordinates")
    view_list = _resolve_views(views)
    fv = None if scalars is None else face_values(scalars, len(v), f)
    norm = None
    cm = colormaps[cmap]
    if fv is not None and log:
        fv = np.where(fv > 0, fv, np.nan)
    if fv is not None:
        finite = fv[np.isfinite(fv)]
        lo = float(finite.min()) if vmin is None and finite.size else (vmin if vmin is not None else 0.0)
        hi = float(finite.max()) if vmax is None and finite.size else (vmax if vmax is not None else 1.0)
        if symmetric:
            m = max(abs(lo), abs(hi))
            lo, hi = -m, m
        if not hi > lo:
            hi = lo + (abs(lo) * 1e-6 or 1e-12)
        norm = LogNorm(lo, hi) if log else Normalize(lo, hi)
        base = cm(norm(np.nan_to_num(fv, nan=lo)))
        base[~np.isfinite(fv)] = to_rgba("#999999")
    else:
        base = np.tile(to_rgba(colour), (len(f), 1))
    if cull is None:
        cull = _closed(f)

    tri = v[f]                                                    # (m, 3, 3)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nn = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.divide(normal, nn, out=np.zeros_like(normal), where=nn > 0)
    centre = 0.5 * (v.min(0) + v.max(0))
    radius = float(np.max(np.linalg.norm(v - centre, axis=1))) or 1.0
    lvec = np.asarray(light, dtype=np.float64)
    lvec = lvec / np.linalg.norm(lvec)

    n_views = len(view_list)
    cbar_w = 0.9 if fv is not None else 0.0
    fig = Figure(figsize=(panel_size * n_views + cbar_w, panel_size + (0.35 if title else 0.0)), dpi=dpi)
    FigureCanvasAgg(fig)
    top = 1.0 - (0.35 / (panel_size + 0.35) if title else 0.0)
    width = panel_size * n_views + cbar_w
    for k, (name, elev, azim) in enumerate(view_list):
        right, up, toward = _view_frame(elev, azim)
        ax = fig.add_axes([k * panel_size / width, 0.0, panel_size / width, top])
        ax.set_xlim(-1.02, 1.02)
        ax.set_ylim(-1.02, 1.02)
        ax.set_aspect("equal")
        ax.axis("off")
        facing = normal @ toward
        keep = np.nonzero(facing > -1e-9)[0] if cull else np.arange(len(f))
        rel = (tri[keep] - centre) / radius
        xy = np.stack([rel @ right, rel @ up], axis=-1)           # (k, 3, 2)
        depth = (rel @ toward).mean(axis=1)
        order = np.argsort(depth, kind="stable")                   # far first
        screen_n = np.stack([normal[keep] @ right, normal[keep] @ up, facing[keep]], axis=1)
        shade = 0.35 + 0.65 * np.abs(screen_n @ lvec)
        rgba = base[keep].copy()
        rgba[:, :3] *= shade[:, None]
        rgba = rgba[order]
        pc = PolyCollection(xy[order], facecolors=rgba, edgecolors=rgba if not edges else "#00000055",
                            linewidths=0.25 if not edges else 0.3, antialiaseds=False)
        ax.add_collection(pc)
        if segments is not None and len(segments):
            rs = (np.asarray(segments, dtype=np.float64).reshape(-1, 2, 3) - centre) / radius
            sxy = np.stack([rs @ right, rs @ up], axis=-1)         # (k, 2, 2)
            sc = "#000000" if segment_colours is None else segment_colours
            ax.add_collection(LineCollection(sxy, colors=sc, linewidths=1.4, zorder=3))
            ends = sxy.reshape(-1, 2)
            ec = sc if isinstance(sc, str) else np.repeat(np.asarray(sc), 2, axis=0)
            ax.scatter(ends[:, 0], ends[:, 1], s=7, c=ec, edgecolors="#000000", linewidths=0.3, zorder=4)
            for lab, (x0, y0) in zip(segment_labels or (), sxy[:, 0]):
                ax.annotate(str(lab), (x0, y0), fontsize=6, xytext=(2, 2), textcoords="offset points", zorder=5)
        if view_titles and n_views > 1:
            ax.set_title(name, fontsize=8, pad=1)
    if fv is not None:
        cax = fig.add_axes([(panel_size * n_views + 0.12) / width, 0.12, 0.16 / width, top * 0.76])
        sm = ScalarMappable(norm=norm, cmap=cm)
        cb = fig.colorbar(sm, cax=cax)
        cb.ax.tick_params(labelsize=7)
        if log:                                  # 1-2-5 ticks as plain numbers (short ranges included)
            from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

            cb.ax.yaxis.set_major_locator(FixedLocator(_log_ticks(norm.vmin, norm.vmax)))
            cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:.3g}"))
            cb.ax.yaxis.set_minor_locator(NullLocator())
        if label:
            cb.set_label(label, fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10, y=0.995, va="top")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, facecolor="white")
    return buf.getvalue()
