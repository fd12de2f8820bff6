"""The report of a ranking folder (``graspdef rank --out DIR``; docs/ranking-folder.md): one HTML page
in the report's style (self-contained: pictures inlined) and its figures as PNG files beside it.

Sections: the summary (object, force, friction, material, thickness, control vertices, candidates,
speed, criterion), the top ten, the compliance map with the top ten as segments, the Pareto front
of work and deformed friction margin, the rigid baseline's rank against the ranking's, and the
nonlinear re-check when the record has one.  Read with :func:`graspdef.runs.ranking.read_ranking`;
ranks, flags and correlations are the folder's, as written, never recomputed here.
"""
from __future__ import annotations

import datetime
from os import PathLike
from pathlib import Path

import numpy as np

from ..runs.folder import atomic_folder
from ..runs.ranking import Ranking, read_ranking
from . import html as H
from .build import ReportError
from .plots import pareto_plot, rank_scatter
from .render import render_surface

MM = 1e3
TOP = 10
#: the figures, in page order: file name -> what it shows
FIGURES = {"compliance_top10.png": "compliance map with the top-10 candidates",
           "pareto.png": "Pareto front: work vs deformed friction margin",
           "rigid_vs_deformable.png": "rigid-baseline rank vs rank"}
#: green (best) to red: the viewer's rank colours (graspdef.viewer.layers.RANKS; a sibling room, so a copy), RGB 0..1
_RANK_COLOURS = np.array([[0, 160, 60], [150, 205, 40], [250, 210, 0], [245, 120, 20], [215, 25, 30]], float) / 255


def rank_colours(n: int) -> np.ndarray:
    """RGB colours (n, 3) in 0..1 of ranks 1..n, green (best) to red."""
    if n <= 1:
        return _RANK_COLOURS[:max(n, 0)]
    t = np.linspace(0.0, 1.0, n) * (len(_RANK_COLOURS) - 1)
    i = np.minimum(np.floor(t).astype(int), len(_RANK_COLOURS) - 2)
    w = (t - i)[:, None]
    return _RANK_COLOURS[i] * (1 - w) + _RANK_COLOURS[i + 1] * w


def _num(v, scale: float = 1.0):
    try:
        return float(v) * scale
    except (TypeError, ValueError):
        return None


def summary_rows(r: Ranking) -> list[tuple[str, str]]:
    """The summary table: the record's figures in display units."""
    rec = r.record
    rows = [("folder", str(r.folder)), ("object", str(rec.get("object", "?"))),
            ("force per finger [N]", H.fmt(rec.get("force_N")) if not rec.get("force_range_N") else
             f"{H.fmt(rec['force_range_N'][0])} to {H.fmt(rec['force_range_N'][1])}: each candidate at its least "
             "holding force (column force_N)"), ("friction coefficient", H.fmt(rec.get("friction")))]
    if "mass_kg" in rec:
        rows.append(("mass [kg]", H.fmt(rec["mass_kg"])))
    mat = rec.get("material")
    if isinstance(mat, dict):
        rows.append(("material", H.material_text(mat)))
    elif mat is not None:
        rows.append(("material", str(mat)))
    rows += [("wall thickness [mm]", H.fmt(_num(rec.get("thickness_m"), MM))),
             ("control vertices", H.fmt(rec.get("control_vertices"))),
             ("candidates", H.fmt(rec.get("n_candidates", r.n))),
             ("held candidates (column held)", H.fmt(int(np.sum(r.table["held"] == 1)))),
             ("candidates per minute", H.fmt(rec.get("candidates_per_minute"))),
             ("criterion", str(rec.get("ranking", "?")))]
    tim = rec.get("timings_s")
    if isinstance(tim, dict) and tim:
        rows.append(("timings [s]", ", ".join(f"{k} {v:.3g}" for k, v in tim.items() if isinstance(v, (int, float)))))
    if rec.get("fixture"):
        rows.append(("note", str(rec["fixture"])))
    return rows


#: the top-10 table: (header, column, factor to display units)
TOP_COLUMNS = [("rank", "rank", 1), ("candidate", "candidate", 1), ("opening [mm]", "width_m", MM),
               ("indentation per finger [mm]", "indentation_per_finger_m", MM), ("work [mJ]", "work_J", MM),
               ("grasp stiffness [N/mm]", "grasp_stiffness_N_per_m", 1e-3), ("peak strain [%]", "peak_strain", 100),
               ("deformed friction margin [deg]", "deformed_friction_margin_deg", 1),
               ("rigid friction margin [deg]", "friction_margin_deg", 1),
               ("weight torque ratio", "weight_torque_ratio", 1), ("rigid rank", "rigid_rank", 1),
               ("held", "held", 1), ("Pareto", "pareto", 1)]


def top_rows(r: Ranking, n: int = TOP) -> list[list]:
    t = r.table
    out = []
    for i in range(min(n, r.n)):
        row = []
        for _, col, f in TOP_COLUMNS:
            v = t[col][i]
            if col in ("held", "pareto"):
                row.append("yes" if int(v) == 1 else "no")
            elif col in ("rank", "candidate", "rigid_rank"):
                row.append(int(v))
            else:
                row.append(float(v) * f)
        out.append(row)
    return out


def _recheck_column(name: str) -> tuple[str, float]:
    """A recheck key's header with its display unit, and the factor from SI."""
    for suffix, unit, f in (("_N_per_m", "N/mm", 1e-3), ("_m2", "mm^2", 1e6), ("_m", "mm", MM), ("_J", "mJ", MM),
                            ("_Pa", "MPa", 1e-6), ("_deg", "deg", 1.0), ("_N", "N", 1.0), ("_s", "s", 1.0)):
        if name.endswith(suffix):
            return f"{name[: -len(suffix)].replace('_', ' ')} [{unit}]", f
    return name.replace("_", " "), 1.0


def recheck_section(rec: dict) -> list[str]:
    """The nonlinear re-evaluation of the best candidates (record's ``recheck``), if any."""
    rc = rec.get("recheck")
    if not rc:
        return []
    if not isinstance(rc, list) or not all(isinstance(x, dict) for x in rc):
        raise ReportError("ranking.json: 'recheck' is not a list of rows (objects)")
    keys: list[str] = []
    for x in rc:
        keys += [k for k in x if k not in keys]
    heads = [_recheck_column(k) for k in keys]
    body = []
    for x in rc:
        row = []
        for k, (_, f) in zip(keys, heads):
            v = x.get(k)
            if isinstance(v, bool) or v is None or isinstance(v, str):
                row.append(v if v is not None else None)
            elif isinstance(v, int) and f == 1.0:
                row.append(v)
            else:
                row.append(_num(v, f))
        body.append(row)
    rho = rec.get("recheck_spearman")
    cap = (f"Spearman rank correlation of the linear and nonlinear re-evaluation (ranking.json "
           f"<code>recheck_spearman</code>): <b>{H.fmt(rho, 3)}</b>." if rho is not None else
           "The record holds no <code>recheck_spearman</code>.")
    return ["<h2 id=\"recheck\">Nonlinear re-check of the best candidates</h2>",
            H.table([h for h, _ in heads], body, table_id="recheck-table", left=0),
            f"<p class=\"note\">{cap}</p>"]


def figures(r: Ranking, views=("iso", "front", "top")) -> tuple[dict[str, bytes], np.ndarray]:
    """The report's pictures (file name -> PNG) and the Pareto plot's front as drawn (k, 2)."""
    t = r.table
    first, second = r.contacts()
    n = min(TOP, r.n)
    seg = np.stack([first[:n], second[:n]], axis=1)
    comp = r.compliance * MM
    png = {"compliance_top10.png": render_surface(
        r.vertices, r.faces, comp, views=views, log=True, label="compliance [mm/N], log scale",
        title=f"{r.record.get('object', r.folder.name)}: compliance map, top {n} candidates",
        segments=seg, segment_colours=rank_colours(n), segment_labels=[str(int(k)) for k in t["rank"][:n]])}
    png["pareto.png"], front = pareto_plot(t["work_J"] * MM, t["deformed_friction_margin_deg"], t["held"], t["pareto"])
    png["rigid_vs_deformable.png"] = rank_scatter(t["rank"], t["rigid_rank"], t["held"],
                                                  xlabel="rank (deformable screen)", ylabel="rank of the rigid baseline",
                                                  title="rigid baseline vs deformable ranking")
    return png, front


def _write_figures(folder: Path, png: dict[str, bytes]) -> None:
    if folder.exists() and (not folder.is_dir() or any(p.suffix != ".png" for p in folder.iterdir())):
        raise ReportError(f"{folder} exists and holds other files than a report's figures; give another --out")
    with atomic_folder(folder) as tmp:
        for name, data in png.items():
            (tmp / name).write_bytes(data)


def build_ranking_report(folder: str | PathLike, out: str | PathLike | None = None, *, title: str | None = None,
                         views=("iso", "front", "top"), progress=None) -> Path:
    """Write the report of the ranking folder ``folder`` to ``out`` (default ``folder/report.html``)
    and its figures to ``<out stem>_figures/`` beside it; return the HTML's path.  A missing or
    damaged folder raises :class:`~graspdef.runs.ranking.RankingFolderError` (nothing written)."""
    say = progress or (lambda m: None)
    r = read_ranking(folder)
    say(f"read {folder} (ranking, {r.n} candidates)")
    out_path = Path(out) if out is not None else Path(folder) / "report.html"
    if out_path.is_dir():
        raise ReportError(f"--out {out_path} is a folder; give a file name such as {out_path / 'report.html'}")
    if not out_path.parent.is_dir():
        raise ReportError(f"cannot write {out_path}: folder {out_path.parent} does not exist")
    fig_dir = out_path.parent / f"{out_path.stem}_figures"
    rec = r.record
    say("rendering the compliance map and the plots")
    png, _ = figures(r, views)
    n = min(TOP, r.n)
    obj = rec.get("object", r.folder.name)
    title = title or (f"graspdef ranking: {obj} at {H.fmt(rec.get('force_N'))} N per finger" if not rec.get("force_range_N")
                      else f"graspdef ranking: {obj} at {H.fmt(rec['force_range_N'][0])} to "
                           f"{H.fmt(rec['force_range_N'][1])} N per finger")
    body = ["<p class=\"note\">Contents: <a href=\"#summary\">summary</a>, <a href=\"#top\">top ten</a>, "
            "<a href=\"#compliance\">compliance map</a>, <a href=\"#pareto\">Pareto front</a>, "
            "<a href=\"#rigid\">rigid baseline</a>" + (", <a href=\"#recheck\">nonlinear re-check</a>"
                                                        if rec.get("recheck") else "") + ". Figures also as files in "
            f"<code>{H.esc(fig_dir.name)}/</code>.</p>"]
    if rec.get("fixture"):
        body.append(f"<div class=\"flag\">{H.esc(rec['fixture'])}</div>")
    body += ["<h2 id=\"summary\">Summary</h2>",
             H.table(["ranking", "value"], summary_rows(r), left=2, table_id="summary-table")]
    body += [f"<h2 id=\"top\">Top {n}</h2>",
             H.table([h for h, _, _ in TOP_COLUMNS], top_rows(r), left=0, table_id="top-table"),
             "<p class=\"note\">From ranking.csv as written (rank order; held and Pareto are its flags). "
             "Opening: the distance between the contacts; indentation per finger: half the linear closing; "
             "work: F &times; closing / 2.</p>"]
    body += ["<h2 id=\"compliance\">Compliance map and the top ten</h2>",
             H.img(png["compliance_top10.png"], alt="compliance map with the top-10 candidates",
                   caption=f"Limit surface coloured by the compliance of a pinch through each vertex "
                           f"(compliance.ply, mm/N, log scale; grey: no pinch fits). Segments: the top {n} "
                           f"candidates from the first to the second contact, labelled by rank, green (1) to red "
                           f"({n}); drawn on top of the surface, so a segment shows through the object.")]
    t = r.table
    body += ["<h2 id=\"pareto\">Pareto front</h2>",
             H.img(png["pareto.png"], alt="Pareto front of work and deformed friction margin",
                   caption=f"Every candidate (grey), the held ones coloured ({int(np.sum(t['held'] == 1))}), and the "
                           f"{int(np.sum(t['pareto'] == 1))} rows flagged pareto = 1 in ranking.csv joined as the "
                           "front (least work, largest deformed friction margin).")]
    rho = (rec.get("rank_correlation") or {}).get("rigid_vs_deformable_spearman")
    rho_text = (f"Spearman rank correlation rigid vs deformable (ranking.json): ρ = {H.fmt(rho, 3)}."
                if rho is not None else "ranking.json records no rigid-vs-deformable rank correlation.")
    body += ["<h2 id=\"rigid\">Rigid baseline against the ranking</h2>",
             H.img(png["rigid_vs_deformable.png"], alt="rigid-baseline rank against rank",
                   caption=f"Each candidate's rank of the rigid-object baseline (friction margin, then weight torque "
                           f"ratio) against its rank here; the diagonal: the same order. {rho_text}")]
    body += recheck_section(rec)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    text = H.page(title, body, subtitle=f"written {stamp} by graspdef report from the ranking folder {r.folder}")
    _write_figures(fig_dir, png)
    return H.write_page(out_path, text)


__all__ = ["FIGURES", "build_ranking_report", "figures", "rank_colours", "recheck_section", "summary_rows",
           "top_rows"]
