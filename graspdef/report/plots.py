"""Report plots as PNG bytes (matplotlib Agg, object-oriented API only): load-deflection and
Newton iterations along a load path, grouped bar charts, force-displacement lines; for ranking folders
the Pareto front of work and friction margin and one rank against another."""
from __future__ import annotations

import io
from collections.abc import Mapping, Sequence

import numpy as np

#: one colour per series, the same in every plot of a report
COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f")


def _figure(width: float = 5.2, height: float = 3.2):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=110)
    FigureCanvasAgg(fig)
    return fig


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", facecolor="white", bbox_inches="tight")
    return buf.getvalue()


def line_chart(x: Sequence[float] | np.ndarray, series: Mapping[str, Sequence[float]], *, xlabel: str, ylabel: str,
               title: str = "", markers: bool = True, points: Mapping[str, tuple] | None = None) -> bytes:
    """Lines y(x), one per series (NaN gaps allowed); ``points``: extra labelled point sets
    ``{label: (xs, ys)}`` drawn as markers only (measurements)."""
    fig = _figure()
    ax = fig.add_subplot(1, 1, 1)
    x = np.asarray(x, dtype=float)
    for k, (name, y) in enumerate(series.items()):
        ax.plot(x, np.asarray(y, dtype=float), marker="o" if markers else None, ms=3.5, lw=1.6,
                color=COLOURS[k % len(COLOURS)], label=name)
    for k, (name, (px, py)) in enumerate((points or {}).items()):
        ax.plot(px, py, ls="none", marker="s", ms=6, mfc="none", mew=1.6,
                color=COLOURS[(len(series) + k) % len(COLOURS)], label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=10)
    if len(series) + len(points or {}) > 1:
        ax.legend(fontsize=8)
    return _png(fig)


def bar_chart(categories: Sequence[str], series: Mapping[str, Sequence[float]], *, ylabel: str, title: str = "",
              annotate: bool = True) -> bytes:
    """Grouped bars: one group per category, one bar per series (NaN: no bar)."""
    fig = _figure(max(4.0, 1.1 + 0.45 * len(categories) * max(1, len(series))), 3.2)
    ax = fig.add_subplot(1, 1, 1)
    n = max(1, len(series))
    w = 0.8 / n
    xs = np.arange(len(categories))
    for k, (name, vals) in enumerate(series.items()):
        v = np.asarray(vals, dtype=float)
        bars = ax.bar(xs + (k - (n - 1) / 2) * w, np.nan_to_num(v, nan=0.0), w, label=name,
                      color=COLOURS[k % len(COLOURS)])
        if annotate:
            for b, val in zip(bars, v):
                if np.isfinite(val):
                    ax.annotate(f"{val:.3g}", (b.get_x() + b.get_width() / 2, b.get_height()),
                                ha="center", va="bottom", fontsize=6.5, xytext=(0, 1), textcoords="offset points")
    ax.set_xticks(xs)
    ax.set_xticklabels(categories, fontsize=8)
    ax.set_ylabel(ylabel)
    ax.grid(axis="y", alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9)
    if len(series) > 1:
        ax.legend(fontsize=8)
    return _png(fig)


def load_deflection(load: np.ndarray, probes: Mapping[str, np.ndarray], *, load_label: str, length_label: str,
                    title: str = "load-deflection") -> bytes:
    """Probe displacement magnitudes against the load along a path.

    Parameters
    ----------
    load : ndarray (k,)
        Load factor, or the force it stands for.
    probes : mapping name -> ndarray (k, 3)
        Probe displacements in the plotted length unit.
    """
    series = {f"|u| {name}": np.linalg.norm(np.asarray(u, float), axis=1) for name, u in probes.items()}
    return line_chart(load, series, xlabel=load_label, ylabel=length_label, title=title)


def newton_iterations(load: np.ndarray, iterations: np.ndarray, *, load_label: str,
                      title: str = "convergence: Newton iterations per path point") -> bytes:
    """Newton iterations of each converged path point against its load (the start state excluded)."""
    fig = _figure(5.2, 2.8)
    ax = fig.add_subplot(1, 1, 1)
    x = np.asarray(load, float)
    y = np.asarray(iterations, float)
    ax.bar(np.arange(len(x)), y, color=COLOURS[0])
    ax.set_xticks(np.arange(len(x)))
    ax.set_xticklabels([f"{v:.3g}" for v in x], fontsize=7, rotation=45 if len(x) > 8 else 0)
    ax.set_xlabel(load_label)
    ax.set_ylabel("Newton iterations")
    ax.grid(axis="y", alpha=0.3)
    ax.set_title(title, fontsize=10)
    return _png(fig)


def pareto_plot(work_mJ: np.ndarray, margin_deg: np.ndarray, held: np.ndarray, pareto: np.ndarray, *,
                title: str = "work vs deformed friction margin") -> tuple[bytes, np.ndarray]:
    """Every candidate as a grey point, the held ones coloured, the rows flagged ``pareto`` joined
    (in order of work) as the front.  Returns the PNG and the front's points (x, y) as drawn."""
    x, y = np.asarray(work_mJ, float), np.asarray(margin_deg, float)
    held, front = np.asarray(held) == 1, np.asarray(pareto) == 1
    fig = _figure(5.2, 3.6)
    ax = fig.add_subplot(1, 1, 1)
    ax.scatter(x[~held], y[~held], s=9, c="#b0b0b0", label=f"not held ({int((~held).sum())})", zorder=1)
    ax.scatter(x[held], y[held], s=12, c=COLOURS[0], label=f"held ({int(held.sum())})", zorder=2)
    order = np.argsort(x[front], kind="stable")
    (line,) = ax.plot(x[front][order], y[front][order], "-o", color=COLOURS[1], ms=5, mfc="none", mew=1.4, lw=1.4,
                      label=f"Pareto front ({int(front.sum())})", zorder=3)
    ax.axhline(0.0, color="#555555", lw=0.7, ls=":")
    ax.set_xlabel("work [mJ]")
    ax.set_ylabel("deformed friction margin [deg]")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=8)
    return _png(fig), np.asarray(line.get_xydata(), float)


def rank_scatter(rank: np.ndarray, other_rank: np.ndarray, held: np.ndarray | None = None, *, xlabel: str,
                 ylabel: str, title: str = "") -> bytes:
    """One rank against another (one point per candidate, the diagonal dashed; held ones coloured)."""
    x, y = np.asarray(rank, float), np.asarray(other_rank, float)
    fig = _figure(4.4, 4.0)
    ax = fig.add_subplot(1, 1, 1)
    h = np.ones(len(x), bool) if held is None else np.asarray(held) == 1
    ax.scatter(x[~h], y[~h], s=8, c="#b0b0b0", label="not held")
    ax.scatter(x[h], y[h], s=10, c=COLOURS[0], label="held" if held is not None else None)
    top = float(max(x.max(initial=1.0), y.max(initial=1.0)))
    ax.plot([1, top], [1, top], ls="--", color="#555555", lw=0.8)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=10)
    if held is not None:
        ax.legend(fontsize=8)
    return _png(fig)
