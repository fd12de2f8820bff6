"""Shared plumbing of the gallery scripts (scripts/gallery/*.py): the command line, the output
folder, the printed table of key numbers beside the published ones, JSON/CSV writers and small
PNGs.  Every gallery script has ``main(argv) -> dict`` (the JSON record it writes) and runs alone:

    python scripts/gallery/<name>.py [--out out/gallery/<name>] [--fast]
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:          # run from a checkout without installing graspdef
    sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")


def parse(name: str, doc: str, argv: list[str] | None, extra=None) -> argparse.Namespace:
    """``--out DIR`` (default out/gallery/<name>) and ``--fast``; ``extra(ap)`` adds options."""
    ap = argparse.ArgumentParser(prog=f"{name}.py", description=doc,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=f"out/gallery/{name}", help="output folder (created)")
    ap.add_argument("--fast", action="store_true", help="coarse, quick setting (what the tests run)")
    if extra is not None:
        extra(ap)
    a = ap.parse_args(argv)
    a.out = Path(a.out)
    a.out.mkdir(parents=True, exist_ok=True)
    return a


class Timer:
    def __init__(self):
        self.t0 = time.perf_counter()

    def __call__(self) -> float:
        return time.perf_counter() - self.t0


def table(rows: list[dict], columns: list[str]) -> str:
    """A Markdown table of ``rows`` (dicts) in ``columns`` order; floats with 4 significant digits."""
    def cell(v):
        if isinstance(v, float):
            return f"{v:.6g}"
        return "–" if v is None else str(v)
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(r.get(c)) for c in columns) + " |" for r in rows]
    return "\n".join(lines)


def _plain(o):
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def write_json(path: Path, record: dict) -> None:
    path.write_text(json.dumps(record, indent=2, default=_plain) + "\n")


def write_csv(path: Path, rows: list[dict]) -> None:
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def finish(out: Path, name: str, record: dict, fig=None, rows_csv: list[dict] | None = None,
           dpi: int = 100) -> dict:
    """Write ``<name>.json`` (+ ``<name>.csv``, ``<name>.png``) into ``out``; return the record."""
    import matplotlib.pyplot as plt
    if fig is not None:
        fig.savefig(out / f"{name}.png", dpi=dpi)
        plt.close(fig)
    if rows_csv:
        write_csv(out / f"{name}.csv", rows_csv)
    write_json(out / f"{name}.json", record)
    print(f"wrote {out / name}.json" + (", .png" if fig is not None else "") + (", .csv" if rows_csv else ""))
    return record


def surface(ax, vertices, faces, scalars=None, title: str = "", **kw) -> None:
    """A deformed surface drawn by graspdef.report.render.render_surface (headless, shaded,
    coloured by ``scalars``) and shown in the matplotlib axis ``ax`` (so one PNG can hold
    several surfaces beside the 2-D plots)."""
    import io

    import matplotlib.image as mpimg

    from graspdef.report.render import render_surface
    png = render_surface(vertices, faces, scalars, **kw)
    ax.imshow(mpimg.imread(io.BytesIO(png), format="png"))
    ax.set_axis_off()
    if title:
        ax.set_title(title, fontsize=9)


# ---- convergence studies (paper Figs. 8 and 11, scripts/convergence.py) -------------------------

def order(rows: list[dict]) -> float:
    """Least-squares slope of log|error| against log h, h = n_control^(-1/2)."""
    n = np.array([r["n_control"] for r in rows], float)
    e = np.array([abs(r["rel_error"]) for r in rows])
    return float(np.polyfit(np.log(n ** -0.5), np.log(e), 1)[0])


def run_study(name: str, fn, reference: float, sizes, progress=print) -> list[dict]:
    """``fn(size) -> (n_control, value)`` at every size; rows with the error against ``reference``."""
    rows = []
    for s in sizes:
        t0 = time.perf_counter()
        n, value = fn(s)
        dt = time.perf_counter() - t0
        rows.append({"study": name, "resolution": s, "n_control": n, "value": value,
                     "reference": reference, "rel_error": (value - reference) / reference, "seconds": dt})
        progress(f"{name:18s} n_control={n:7d}  value={value:.6g}  "
                 f"error={100 * (value - reference) / reference:+.4f} %  {dt:.1f} s")
    return rows


def convergence_axes(ax, name: str, rows: list[dict], **kw) -> None:
    ax.loglog([r["n_control"] for r in rows], [abs(r["rel_error"]) for r in rows], "o-",
              label=name.replace("_", " "), **kw)
    ax.set_xlabel("control vertices")
    ax.set_ylabel("|relative error|")
    ax.grid(True, which="both", alpha=0.3)


# ---- grasp run folders (paper Figs. 13-15) ------------------------------------------------------

def run_surfaces(run_dir: Path) -> dict:
    """The undeformed and deformed limit surfaces of a run folder (metres) and the magnitude of
    the stored displacement field per vertex (the field of derived.max_displacement), read with
    graspdef's one run reader."""
    from graspdef.runs.read import read_run
    r = read_run(run_dir)
    return {"undeformed": r.rest_vertices, "deformed": r.deformed_vertices, "faces": r.faces,
            "u_mag": np.linalg.norm(r.displacements, axis=1), "record": r.record}


def convergence_figure(name: str, rows: list[dict], reference: float, ref_label: str, column: str,
                       ylabel: str, title: str, ratio: bool = False):
    """The two panels of a convergence figure: the value (or value/reference) against the control
    vertices with the reference and the paper's range (<= 2,500 control points), and |error| on log
    axes.  Prints the rows; returns (figure, key record of the finest mesh)."""
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.6))
    n = [r["n_control"] for r in rows]
    ax1.semilogx(n, [r[column] for r in rows], "o-", label="graspdef")
    ax1.axhline(1.0 if ratio else reference, color="C3", ls="--", lw=0.8, label=ref_label)
    ax1.axvspan(min(n), 2500, color="0.9", label="paper's range (≤ 2,500)")
    ax1.set_xlabel("control vertices")
    ax1.set_ylabel(ylabel)
    ax1.set_title(title, fontsize=9)
    ax1.legend(fontsize=7)
    ax1.grid(alpha=0.3)
    convergence_axes(ax2, name, rows)
    e = [abs(r["rel_error"]) for r in rows[:3]]
    p = order(rows[:3]) if len(e) == 3 and e[0] > e[1] > e[2] else None   # an order only where the error falls
    ax2.set_title("|error|" + (f"; order {p:.2f} in h on the three coarsest" if p else ""), fontsize=9)
    fig.tight_layout()
    last = rows[-1]
    key = {"study": name, "n_control": last["n_control"], "graspdef": last["value"], "reference": reference,
           "error_%": 100 * last["rel_error"], "order_three_coarsest": p}
    print(table([dict(r, error_pct=100 * r["rel_error"]) for r in rows],
                ["n_control", "value", column, "error_pct", "seconds"]))
    return fig, key


def surfaces_figure(run_dir: Path, views, titles, suptitle: str):
    """One PNG with the deformed surface of a grasp run folder from each of ``views``, coloured by
    |u| [mm] (rigid motion removed)."""
    import matplotlib.pyplot as plt
    s = run_surfaces(run_dir)
    fig, axs = plt.subplots(1, len(views), figsize=(5 * len(views), 4.6))
    for ax, view, title in zip(np.atleast_1d(axs), views, titles):
        surface(ax, 1e3 * s["deformed"], s["faces"], 1e3 * s["u_mag"], views=(view,), label="|u| [mm]", title=title)
    fig.suptitle(suptitle, fontsize=9)
    fig.tight_layout()
    return fig


def convergence_main(name: str, doc: str, argv, study: str, fn, reference: float, sizes, fast_sizes,
                     figure: dict, published: str, source: str, ratio: bool = False) -> dict:
    """The whole of a convergence script (paper Figs. 8 and 11): parse, run the study, draw,
    print the key row beside the published value, write the files.  ``figure``: keyword
    arguments of :func:`convergence_figure` (ref_label, column, ylabel, title)."""
    a = parse(name, doc, argv)
    clock = Timer()
    rows = run_study(study, fn, reference, fast_sizes if a.fast else sizes)
    for r in rows:
        r["normalised"] = r["value"] / reference
    fig, key = convergence_figure(study, rows, reference, ratio=ratio, **figure)
    key.update(normalised=rows[-1]["normalised"], published=published)
    print(table([key], ["study", "n_control", "graspdef", "reference", "error_%", "order_three_coarsest", "published"]))
    rec = {"figure": figure["title"].split(":")[0], "fast": a.fast, "rows": rows, "key": key,
           "reference_source": source, "seconds": clock()}
    return finish(a.out, name, rec, fig, rows)
