"""What the viewer draws, as plain arrays and HTML (no viser here): colour maps and their
legends, display coordinates, force arrows and the load-displacement chart.

float32 appears only in this package (STYLE.md section 2); everything here is numpy.
"""
from __future__ import annotations

import html

import numpy as np

#: viridis at 9 stops (matplotlib's table, sampled), RGB 0..255
VIRIDIS = np.array([[68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
                    [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37]], float)
#: blue - white - red for signed errors
DIVERGING = np.array([[59, 76, 192], [141, 176, 254], [221, 221, 221], [244, 154, 123], [180, 4, 38]], float)


def colormap(values: np.ndarray, vmin: float, vmax: float, table: np.ndarray = VIRIDIS) -> np.ndarray:
    """RGB colours (n, 3) uint8 of ``values`` (n,) on [vmin, vmax] (clipped; a zero range maps to the
    lowest colour)."""
    v = np.asarray(values, float)
    span = vmax - vmin
    t = np.zeros_like(v) if not span > 0 else np.clip((v - vmin) / span, 0.0, 1.0)
    t = np.nan_to_num(t, nan=0.0)
    x = t * (len(table) - 1)
    i = np.minimum(np.floor(x).astype(int), len(table) - 2)
    w = (x - i)[:, None]
    return np.rint(table[i] * (1 - w) + table[i + 1] * w).astype(np.uint8)


def nice_ticks(vmin: float, vmax: float, n: int = 5) -> list[float]:
    """About ``n`` round tick values covering [vmin, vmax]."""
    if not vmax > vmin:
        return [vmin]
    raw = (vmax - vmin) / max(n - 1, 1)
    mag = 10 ** np.floor(np.log10(raw))
    step = min((s * mag for s in (1, 2, 2.5, 5, 10) if s * mag >= raw), default=raw)
    lo = np.ceil(vmin / step - 1e-9) * step
    return [float(t) + 0.0 for t in np.arange(lo, vmax + 1e-9 * step, step)]


def legend_html(title: str, unit: str, vmin: float, vmax: float, table: np.ndarray = VIRIDIS) -> str:
    """A horizontal colour bar with ticks, its title and unit, as HTML for a GUI panel."""
    stops = ", ".join(f"rgb({int(r)},{int(g)},{int(b)}) {100 * k / (len(table) - 1):.0f}%"
                      for k, (r, g, b) in enumerate(table))
    ticks = nice_ticks(vmin, vmax)
    span = vmax - vmin if vmax > vmin else 1.0
    marks = "".join(
        f'<span style="position:absolute;left:{100 * (t - vmin) / span:.1f}%;transform:translateX(-50%);'
        f'font-size:10px">{t:.3g}</span>' for t in ticks)
    return (f'<div style="padding:4px 12px 16px 12px;font-family:sans-serif">'
            f'<div style="font-size:12px;margin-bottom:2px">{html.escape(title)} [{html.escape(unit)}]</div>'
            f'<div style="height:12px;border-radius:2px;background:linear-gradient(to right, {stops})"></div>'
            f'<div style="position:relative;height:12px">{marks}</div></div>')


def display_frame(vertices: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre (3,) and length [m] that map a scene of this size to about one display unit."""
    lo, hi = vertices.min(0), vertices.max(0)
    size = float(np.max(hi - lo))
    return 0.5 * (lo + hi), size if size > 0 else 1.0


def force_arrows(points: np.ndarray, forces: np.ndarray, length: float) -> np.ndarray:
    """Arrow segments (c, 2, 3) ending at the contact points, the largest force drawn ``length``
    long (length proportional to force); the force acts on the object at the arrow head."""
    points = np.asarray(points, float).reshape(-1, 3)
    forces = np.asarray(forces, float).reshape(-1, 3)
    fmax = float(np.linalg.norm(forces, axis=1).max()) if len(forces) else 0.0
    vec = forces * (length / fmax if fmax > 0 else 0.0)
    return np.stack([points - vec, points], axis=1)


def chart_svg(x: np.ndarray, y: np.ndarray, current: int | None, xlabel: str, ylabel: str,
              width: int = 260, height: int = 150, extra: tuple[float, float] | None = None) -> str:
    """A small load-displacement chart (polyline, the current point in red, an optional extra
    point -- a live state -- in orange) as inline SVG."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    px = np.append(x, extra[0]) if extra else x
    py = np.append(y, extra[1]) if extra else y
    ml, mb, mt, mr = 44, 30, 8, 8
    x0, x1 = float(np.nanmin(px)), float(np.nanmax(px))
    y0, y1 = float(np.nanmin(py)), float(np.nanmax(py))
    x1 = x1 if x1 > x0 else x0 + 1.0
    y1 = y1 if y1 > y0 else y0 + 1.0

    def sx(v):
        return ml + (v - x0) / (x1 - x0) * (width - ml - mr)

    def sy(v):
        return height - mb - (v - y0) / (y1 - y0) * (height - mb - mt)

    pts = " ".join(f"{sx(a):.1f},{sy(b):.1f}" for a, b in zip(x, y))
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'style="font-family:sans-serif;font-size:9px">',
           f'<rect x="{ml}" y="{mt}" width="{width - ml - mr}" height="{height - mb - mt}" fill="none" stroke="#999"/>',
           f'<polyline points="{pts}" fill="none" stroke="#2c71b8" stroke-width="1.5"/>']
    out += [f'<circle cx="{sx(a):.1f}" cy="{sy(b):.1f}" r="1.8" fill="#2c71b8"/>' for a, b in zip(x, y)]
    if current is not None and 0 <= current < len(x):
        out.append(f'<circle cx="{sx(x[current]):.1f}" cy="{sy(y[current]):.1f}" r="4.5" fill="#d62728"/>')
    if extra:
        out.append(f'<circle cx="{sx(extra[0]):.1f}" cy="{sy(extra[1]):.1f}" r="4" fill="#ff9900" stroke="#000"/>')
    out += [f'<text x="{ml}" y="{height - mb + 11}">{x0:.3g}</text>',
            f'<text x="{width - mr}" y="{height - mb + 11}" text-anchor="end">{x1:.3g}</text>',
            f'<text x="{ml - 3}" y="{height - mb}" text-anchor="end">{y0:.3g}</text>',
            f'<text x="{ml - 3}" y="{mt + 8}" text-anchor="end">{y1:.3g}</text>',
            f'<text x="{(ml + width - mr) / 2}" y="{height - 4}" text-anchor="middle">{html.escape(xlabel)}</text>',
            f'<text x="10" y="{(mt + height - mb) / 2}" text-anchor="middle" '
            f'transform="rotate(-90 10 {(mt + height - mb) / 2})">{html.escape(ylabel)}</text>', "</svg>"]
    return "".join(out)


# ---- ranking folders (graspdef rank) ---------------------------------------------------------------
#: colour of vertices without a value (NaN: e.g. no pinch fits there), RGB 0..255
NAN_GREY = (150, 150, 150)
#: best -> worst rank: green - yellow - red
RANKS = np.array([[0, 160, 60], [150, 205, 40], [250, 210, 0], [245, 120, 20], [215, 25, 30]], float)


def log_colormap(values: np.ndarray, vmin: float, vmax: float, table: np.ndarray = VIRIDIS,
                 nan: tuple[int, int, int] = NAN_GREY) -> np.ndarray:
    """RGB colours (n, 3) uint8 of positive ``values`` on a log scale [vmin, vmax] (clipped); NaN
    and non-positive values get ``nan`` (grey)."""
    v = np.asarray(values, float)
    bad = ~(np.isfinite(v) & (v > 0))
    logs = np.log10(np.where(bad, 1.0, v))
    out = colormap(logs, float(np.log10(vmin)), float(np.log10(vmax)), table)
    out[bad] = nan
    return out


def log_ticks(vmin: float, vmax: float) -> list[float]:
    """Tick values 1, 2, 5 x 10^k inside [vmin, vmax] (positive); the two ends as well when fewer
    than three such values fall inside."""
    if not (vmin > 0 and vmax > vmin):
        return [float(vmin)]
    ticks = [m * 10.0 ** e for e in range(int(np.floor(np.log10(vmin))), int(np.ceil(np.log10(vmax))) + 1)
             for m in (1, 2, 5) if vmin * (1 - 1e-9) <= m * 10.0 ** e <= vmax * (1 + 1e-9)]
    if len(ticks) < 3:
        ticks = sorted(set([float(vmin), *ticks, float(vmax)]))
    return [float(t) for t in ticks]


def log_legend_html(title: str, unit: str, vmin: float, vmax: float, table: np.ndarray = VIRIDIS,
                    nan_label: str | None = None) -> str:
    """A horizontal colour bar on a log scale with ticks, its title and unit, and (``nan_label``)
    a grey swatch for vertices without a value, as HTML for a GUI panel."""
    stops = ", ".join(f"rgb({int(r)},{int(g)},{int(b)}) {100 * k / (len(table) - 1):.0f}%"
                      for k, (r, g, b) in enumerate(table))
    lo, hi = np.log10(vmin), np.log10(vmax)
    span = hi - lo if hi > lo else 1.0
    marks = "".join(
        f'<span style="position:absolute;left:{100 * (np.log10(t) - lo) / span:.1f}%;transform:translateX(-50%);'
        f'font-size:10px">{t:.3g}</span>' for t in log_ticks(vmin, vmax))
    grey = ""
    if nan_label:
        r, g, b = NAN_GREY
        grey = (f'<div style="font-size:11px;margin-top:6px"><span style="display:inline-block;width:12px;'
                f'height:10px;background:rgb({r},{g},{b});margin-right:4px"></span>{html.escape(nan_label)}</div>')
    return (f'<div style="padding:4px 12px 8px 12px;font-family:sans-serif">'
            f'<div style="font-size:12px;margin-bottom:2px">{html.escape(title)} [{html.escape(unit)}], log scale</div>'
            f'<div style="height:12px;border-radius:2px;background:linear-gradient(to right, {stops})"></div>'
            f'<div style="position:relative;height:12px">{marks}</div>{grey}</div>')


def rank_colours(n: int) -> np.ndarray:
    """Colours (n, 3) uint8 of ranks 1..n: the best green, the worst red."""
    if n <= 0:
        return np.zeros((0, 3), np.uint8)
    return colormap(np.arange(n, dtype=float), 0.0, float(max(n - 1, 1)), RANKS)


def segments(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Line segments (n, 2, 3) from ``first`` (n, 3) to ``second`` (n, 3)."""
    return np.stack([np.asarray(first, float), np.asarray(second, float)], axis=1)
