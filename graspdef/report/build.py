"""The report of one or more run folders: one self-contained HTML page.

Per run folder (read with :func:`graspdef.runs.read_run`, the reader every consumer uses):

* the run's summary from ``result.json`` (units stated), its derived quantities with their labels;
* the deformed surface coloured by the stored displacement field (``deformed.ply``'s ux, uy, uz:
  the field whose maximum is ``derived.max_displacement``, so table, caption and colour bar
  agree with each other and with the viewer);
* with a score (``score.json`` + ``scan_errors.ply`` of ``graspdef score`` in the run folder or a
  sub-folder, or made here from ``scan=``): the surface coloured by the signed scan error of the
  nearest scan point (grey where the scanner saw nothing), the prediction-vs-undeformed error
  table, the score's flags;
* for a load path (``path.csv``): load-deflection of the probes and Newton iterations per point.

And over all runs, when any has a force (grasp runs) or a table file is given: a table in the
layout of Tian & Jia 2010, Table I -- force, measured maximum displacement, nonlinear error,
linear error -- with the paper's measured values and errors beside ours.
"""
from __future__ import annotations

import csv
import datetime
import json
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from ..errors import GraspdefError
from ..runs.ranking import is_ranking
from ..runs.read import RunData, read_run
from . import html as H
from .plots import bar_chart, line_chart, load_deflection, newton_iterations
from .render import render_surface

MM = 1e3

#: Tian & Jia 2010, Table I (tennis ball, first four rows): force per finger [N], measured maximum
#: displacement [mm], average shape error of their nonlinear and linear results [mm]
PAPER_TABLE_I = (
    {"force_N": 10.63, "measured_max_mm": 2.56, "nonlinear_error_mm": 0.31, "linear_error_mm": 0.30},
    {"force_N": 16.50, "measured_max_mm": 6.05, "nonlinear_error_mm": 0.62, "linear_error_mm": 0.85},
    {"force_N": 20.37, "measured_max_mm": 9.12, "nonlinear_error_mm": 0.81, "linear_error_mm": 2.0},
    {"force_N": 21.48, "measured_max_mm": 10.27, "nonlinear_error_mm": 0.65, "linear_error_mm": 2.37},
)
FORCE_MATCH_N = 0.05


class ReportError(GraspdefError):
    """A report cannot be written (bad arguments, table file, scan)."""


@dataclass
class RunReport:
    """A run folder with what the report derives from it."""

    run: RunData
    force_N: float | None = None
    measured_mm: float | None = None
    score: dict | None = None                  # score.json
    score_dir: Path | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def grasp(self) -> bool:
        return "force_N" in self.run.record

    @property
    def obj(self) -> str | None:
        """The grasped object's name (grasp runs), else None."""
        o = self.run.record.get("object")
        return None if o is None else str(o)

    def stopped_at(self) -> float | None:
        """The load factor where an incomplete nonlinear path stopped, else None."""
        rec = self.run.record
        conv = rec.get("convergence") or {}
        if self.run.analysis == "nonlinear" and conv.get("completed") is False:
            return float(conv.get("load_factor", float("nan")))
        return None

    @property
    def length_label(self) -> str:
        return "consistent units" if self.run.length_unit == "consistent" else "mm"

    @property
    def to_display(self) -> float:
        """Display length per metre of the run's SI data (mm, or the consistent unit)."""
        return 1.0 / self.run.display_scale

    def max_displacement(self) -> float | None:
        """``derived.max_displacement`` in display units (mm)."""
        md = self.run.max_displacement()
        return None if md is None else float(md) * self.to_display

    def displacement_field(self) -> tuple[np.ndarray, str]:
        """|u| per vertex in display units (the stored field), and what it is."""
        return np.linalg.norm(self.run.displacements, axis=1) * self.to_display, self.run.displacement_label


def paper_row(force_N: float | None, obj: str | None = None) -> dict | None:
    """The paper's Table I row of this force (within 0.05 N), or None; only for the tennis ball
    (``obj``: the grasp run's object; None = unknown, e.g. a solve run listed in a table file)."""
    if force_N is None or (obj is not None and "tennis" not in str(obj).lower()):
        return None
    for row in PAPER_TABLE_I:
        if abs(row["force_N"] - force_N) <= FORCE_MATCH_N:
            return row
    return None


# ------------------------------------------------------------------------------------------------
# reading
# ------------------------------------------------------------------------------------------------
def _read_score(d: Path) -> dict:
    try:
        rec = json.loads((d / "score.json").read_text())
    except (OSError, ValueError) as exc:
        raise ReportError(f"score folder {d}: cannot read score.json: {exc}") from None
    if not isinstance(rec, dict) or "prediction" not in rec or "baseline" not in rec:
        raise ReportError(f"score folder {d}: score.json is not a 'graspdef score' record")
    return rec


def load_run(run_dir: str | PathLike, score_dir: str | PathLike | None = None) -> RunReport:
    """Read a run folder (and its score, if any) for the report."""
    run = read_run(run_dir, score_dir)
    rr = RunReport(run, force_N=run.record.get("force_N"))
    row = paper_row(rr.force_N, rr.obj)
    rr.measured_mm = row["measured_max_mm"] if row else None
    if run.scan is not None:
        rr.score_dir = run.scan.source
        rr.score = _read_score(run.scan.source)
    rr.notes = list(n for n in run.notes if not n.startswith("no problem.toml"))
    return rr


def score_run(run_dir: Path, scan: str, *, out: Path | None = None, surface_offset_mm: float | None = None,
              scan_units: str | None = None) -> Path:
    """Score ``RUN_DIR/deformed.ply`` against ``scan`` (a file or a manifest id) with
    :func:`graspdef.registration.score_cli`; written to ``out`` (default ``RUN_DIR/score``).
    The surface offset defaults to half the shell thickness of the run (the scan sees the outer
    surface, the run holds the mid-surface): the same default as ``graspdef score RUN_DIR``."""
    from ..registration import score_cli

    run = read_run(run_dir)
    if run.length_unit == "consistent":
        raise ReportError(f"run folder {run_dir} is in consistent units: it cannot be compared with a scan "
                          "(give the problem file physical units)")
    if surface_offset_mm is None:
        surface_offset_mm = run.outer_offset * MM
    out = Path(out) if out is not None else Path(run_dir) / "score"
    score_cli(Path(run_dir) / "deformed.ply", scan, out, scan_units=scan_units, surface_offset_mm=surface_offset_mm)
    return out


def read_table_file(path: str | PathLike) -> list[tuple[Path, float | None, float | None]]:
    """``--table runs.csv``: a header line and one run folder per row.

    Columns: ``run`` (a run folder, relative to the CSV's folder or absolute; required),
    ``force_N`` (default: the run's result.json), ``measured_mm`` (the measured maximum
    displacement; default: the paper's value at that force).  Returns (folder, force, measured)."""
    p = Path(path)
    try:
        with p.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
    except OSError as exc:
        raise ReportError(f"table file {p}: {exc}") from None
    if not rows or "run" not in rows[0]:
        raise ReportError(f"table file {p}: needs a header line with a 'run' column (and optionally force_N, "
                          "measured_mm) and at least one row")
    out = []
    for i, r in enumerate(rows, start=2):
        d = Path(r["run"].strip())
        d = d if d.is_absolute() else p.parent / d
        vals = []
        for key in ("force_N", "measured_mm"):
            s = (r.get(key) or "").strip()
            try:
                vals.append(float(s) if s else None)
            except ValueError:
                raise ReportError(f"table file {p}, line {i}: {key} = {s!r} is not a number") from None
        out.append((d, vals[0], vals[1]))
    return out


# ------------------------------------------------------------------------------------------------
# the page
# ------------------------------------------------------------------------------------------------
def _summary_rows(rr: RunReport) -> list[tuple[str, str]]:
    rec, run = rr.run.record, rr.run
    units_text = ", ".join(f"{k} {v}" for k, v in rec.units.items())
    rows = [("folder", str(run.path)), ("analysis", run.analysis), ("units of the run", units_text)]
    if "object" in rec:
        rows.append(("object (scene)", f"{rec['object']} ({Path(str(rec.get('scene', ''))).parent.name})"))
    if rr.force_N is not None:
        rows.append(("force per finger [N]", H.fmt(rr.force_N)))
    mat = rec.get("material")
    if isinstance(mat, dict):
        rows.append(("material", H.material_text(mat)))
    if rec.get("gas_p0_Pa"):
        rows.append(("enclosed air [kPa]", H.fmt(rec["gas_p0_Pa"] / 1e3)))
    rows.append(("surface vertices / faces", f"{len(run.rest_vertices):,} / {len(run.faces):,}"))
    for d in rec.derived.values():
        label, value = derived_display(d, run.display_unit)
        rows.append((label, value))
    for name, p in (rec.get("probes") or {}).items():
        if isinstance(p, dict) and "displacement" in p:
            rows.append((f"probe {name}: u [{rr.length_label}]",
                         "(" + ", ".join(H.fmt(c * rr.to_display) for c in p["displacement"]) + ")"))
    conv = rec.get("convergence") or {}
    if run.analysis == "nonlinear":
        rows.append(("path completed", H.fmt(bool(conv.get("completed", True)))))
        if conv.get("stop_reason"):
            rows.append(("stop reason", str(conv["stop_reason"])))
        if "load_factor" in conv:
            rows.append(("final load factor", H.fmt(conv["load_factor"])))
        its = conv.get("newton_iterations")
        if its:
            rows.append(("path points / Newton iterations", f"{len(its)} / {sum(its)}"))
        if "n_factorisations" in conv:
            rows.append(("factorisations", H.fmt(conv["n_factorisations"])))
    tim = rec.get("timings_s") or rec.get("timings") or {}
    if isinstance(tim, dict) and tim:
        rows.append(("timings [s]", ", ".join(f"{k} {v:.3g}" for k, v in tim.items() if isinstance(v, (int, float)))))
    return rows


#: SI unit -> (display unit, factor) for the report's tables
_DISPLAY = {"m": ("mm", 1e3), "m2": ("mm^2", 1e6), "J": ("mJ", 1e3), "N": ("N", 1.0), "Pa": ("kPa", 1e-3)}


def derived_display(d: dict, display_length: str = "mm") -> tuple[str, str]:
    """A derived quantity's table row: ``label [unit]`` and its value (a number, a per-finger
    mapping or a vector) in display units; the definition goes into the label's tooltip text."""
    unit = d.get("unit", "")
    shown, f = _DISPLAY.get(unit, (unit, 1.0)) if display_length != "consistent" else (unit, 1.0)
    v = d["value"]
    if isinstance(v, dict):
        text = ", ".join(f"{k} {H.fmt(x * f)}" for k, x in v.items())
    elif isinstance(v, (list, tuple)):
        text = "(" + ", ".join(H.fmt(x * f) for x in v) + ")"
    else:
        text = H.fmt(None if v is None else v * f)
    return f"{d.get('label', '?')} [{shown}]", text


def _scan_error_colours(rr: RunReport) -> np.ndarray:
    """Signed error [mm] of the nearest scan point per deformed vertex; NaN where no scan point is
    near (the scanner did not see that part)."""
    sc = rr.run.scan
    d, i = cKDTree(sc.points).query(rr.run.deformed_vertices, workers=-1)
    err = sc.errors_mm[i].astype(float)
    unseen = d * MM > np.abs(err) + 2.0
    err[unseen] = np.nan
    return err


def _score_section(rr: RunReport) -> list[str]:
    rec = rr.score
    out = [f"<h3>Scan comparison</h3><p class=\"note\">score folder <code>{H.esc(rr.score_dir)}</code>; "
           f"scan <code>{H.esc((rec.get('inputs') or {}).get('scan', '?'))}</code>; "
           f"{H.esc(rec.get('summary', ''))}</p>"]
    flags = rec.get("flags") or []
    if flags or rec.get("ok") is False:
        out.append(f"<div class=\"flag\"><b>flagged score</b> (ok = false): {H.esc(', '.join(flags) or 'see score.json')}"
                   " &mdash; these numbers are not to be trusted as they stand.</div>")
    keys = ("mean_mm", "rms_mm", "median_mm", "p95_mm", "max_mm", "mean_signed_mm", "hausdorff_mm", "coverage")
    pe, be = rec["prediction"].get("errors", {}), rec["baseline"].get("errors", {})
    rows = [[k.replace("_mm", " [mm]"), pe.get(k), be.get(k)] for k in keys if k in pe or k in be]
    out.append(H.table(["scan &rarr; surface", "prediction", "undeformed (baseline)"], rows, raw=True,
                       table_id="score-table"))
    return out


def _run_section(rr: RunReport, views, index: int) -> list[str]:
    run = rr.run
    out = [f"<h2 id=\"run-{index}\">{H.esc(run.label)}</h2>"]
    for n in rr.notes:
        out.append(f"<div class=\"flag\">{H.esc(n)}</div>")
    out.append(H.table(["run", "value"], _summary_rows(rr), left=2, table_id=f"summary-{index}"))
    mag, what = rr.displacement_field()
    top = float(np.nanmax(mag))          # = derived.max_displacement: the colour bar spans 0 .. this
    figs = [H.img(render_surface(run.deformed_vertices, run.faces, mag, views=views, vmin=0.0, vmax=top,
                                 label=f"{what} [{rr.length_label}]",
                                 title=f"{run.name}: deformed surface, {what}"),
                  alt=f"deformed surface of {run.name} coloured by displacement",
                  caption=f"Deformed surface (true scale) coloured by {what} in {rr.length_label}; "
                          f"largest {top:.4g} {rr.length_label} (max. displacement: "
                          f"{(run.record.derived.get('max_displacement') or {}).get('definition', '')}).")]
    if rr.score is not None:
        err = _scan_error_colours(rr)
        lim = float(np.nanpercentile(np.abs(err), 99)) if np.isfinite(err).any() else 1.0
        figs.append(H.img(render_surface(run.deformed_vertices, run.faces, err, views=views, cmap="coolwarm",
                                         vmin=-lim, vmax=lim, label="signed scan error [mm]",
                                         title=f"{run.name}: scan error (nearest scan point)"),
                          alt=f"deformed surface of {run.name} coloured by scan error",
                          caption="Signed error of the nearest scan point (positive: scan outside the surface); "
                                  "grey: no scan point near (holes, unseen parts). Colour range: 99th percentile."))
    out.append("".join(figs))
    if rr.score is not None:
        out += _score_section(rr)
    pt = run.path_table
    if pt is not None and len(pt.load_factors) > 1:
        if rr.force_N is not None:
            load, load_label = pt.load_factors * rr.force_N, "force per finger [N]"
        else:
            load, load_label = pt.load_factors, "load factor"
        probes = {k: v * rr.to_display for k, v in pt.probes.items()}
        plots = []
        fingers = run.record.get("fingers") or {}
        if {"left", "right"} <= set(probes) and all("load_point_m" in (fingers.get(k) or {}) for k in ("left", "right")):
            e = np.subtract(fingers["right"]["load_point_m"], fingers["left"]["load_point_m"])
            e /= np.linalg.norm(e)
            ind = 0.5 * (probes["left"] - probes["right"]) @ e
            ref = run.record.get("displacement_reference")
            if pt.load_factors[0] == 0 and abs(ind[0]) > 1e-3 * max(np.max(np.abs(ind)), 1e-30):
                where = (f"result.json measures displacements from the {ref}" if ref else
                         "the displacements in result.json are measured from the rest shape")
                out.append(f"<div class=\"flag\">At load factor 0 the indentation per finger is already "
                           f"{ind[0]:.3g} {rr.length_label} (this plot is from the rest shape): the path's start "
                           f"state is not the rest shape (e.g. the enclosed air inflates the shell before any "
                           f"finger force); {where}.</div>")
            plots.append(H.img(line_chart(load, {"indentation per finger": ind}, xlabel=load_label,
                                          ylabel=f"indentation per finger [{rr.length_label}]", title="load-deflection"),
                               alt="load-deflection",
                               caption="Load-deflection: half the approach of the two load points along the grasp "
                                       "axis (rigid motion cancels), at every converged path point."))
        elif probes:
            plots.append(H.img(load_deflection(load, probes, load_label=load_label,
                                               length_label=f"probe displacement [{rr.length_label}]"),
                               alt="load-deflection", caption="Load-deflection: |u| of each probe along the path."))
        its = pt.columns.get("newton_iterations")
        if its is not None:
            sel = np.isfinite(its) & (its > 0)
            if sel.any():
                plots.append(H.img(newton_iterations(load[sel], its[sel], load_label=load_label),
                                   alt="Newton iterations", caption="Convergence: Newton iterations of each "
                                                                   "converged path point."))
        out.append("<h3>Load path</h3><div class=\"grid\">" + "".join(plots) + "</div>")
    return out


def table_rows(runs: list[RunReport]) -> list[dict]:
    """Table I rows: one per force, the nonlinear and linear runs of that force side by side."""
    by_force: dict[float, dict] = {}
    for rr in runs:
        if rr.force_N is None:
            continue
        key = round(float(rr.force_N), 2)
        row = by_force.setdefault(key, {"force_N": float(rr.force_N), "measured_mm": rr.measured_mm,
                                        "paper": paper_row(rr.force_N, rr.obj)})
        if row["measured_mm"] is None:
            row["measured_mm"] = rr.measured_mm
        kind = "linear" if rr.run.analysis == "linear" else "nonlinear"
        if kind in row:
            row.setdefault("extra", []).append(rr)
            continue
        md = rr.max_displacement()
        ent = {"run": rr, "max_mm": md, "scan_mean_mm": None, "flagged": False, "stopped_at": rr.stopped_at()}
        if rr.score is not None:
            ent["scan_mean_mm"] = rr.score["prediction"]["errors"].get("mean_mm")
            ent["flagged"] = not rr.score.get("ok", True)
        if ent["scan_mean_mm"] is not None:
            ent["error_mm"], ent["error_kind"] = ent["scan_mean_mm"], "shape"
        elif md is not None and row["measured_mm"] is not None and ent["stopped_at"] is None:
            ent["error_mm"], ent["error_kind"] = abs(md - row["measured_mm"]), "max"
        else:
            ent["error_mm"], ent["error_kind"] = None, None
        row[kind] = ent
    return [by_force[k] for k in sorted(by_force)]


def _table_section(rows: list[dict]) -> list[str]:
    def err(ent):
        if not ent or ent.get("error_mm") is None:
            return "&ndash;"
        tag = "shape" if ent["error_kind"] == "shape" else "&Delta;max"
        flag = " &#9888;" if ent.get("flagged") else ""
        return f"{ent['error_mm']:.3g} <small>({tag})</small>{flag}"

    def mx(ent):
        if not ent or ent.get("max_mm") is None:
            return "&ndash;"
        if ent.get("stopped_at") is not None:      # not the prediction at this force
            return f"{ent['max_mm']:.3g} <small>(path stopped at load factor {ent['stopped_at']:.3g})</small>"
        return f"{ent['max_mm']:.3g}"

    body = []
    for r in rows:
        p = r["paper"] or {}
        nl, li = r.get("nonlinear"), r.get("linear")
        body.append([f"{r['force_N']:.2f}", H.fmt(r["measured_mm"]), mx(nl), err(nl), mx(li), err(li),
                     H.fmt(p.get("nonlinear_error_mm")), H.fmt(p.get("linear_error_mm"))])
    head = ["force per finger [N]", "measured max. displacement [mm]", "nonlinear: max. displacement [mm]",
            "nonlinear error [mm]", "linear: max. displacement [mm]", "linear error [mm]",
            "paper: nonlinear error [mm]", "paper: linear error [mm]"]
    out = ["<h2 id=\"table-i\">Comparison in the layout of Tian &amp; Jia 2010, Table I</h2>",
           H.table(head, body, raw=True, table_id="table-i-table"),
           "<p class=\"note\">Measured values: Tian &amp; Jia 2010, Table I (tennis ball), unless a table file gave "
           "others. Errors: <b>shape</b> = mean scan-to-surface distance after registration (the paper's "
           "&ldquo;average shape error&rdquo;), when the run has a score; otherwise <b>&Delta;max</b> = |predicted "
           "&minus; measured| maximum displacement (not the paper's measure). &#9888;: the score is flagged. "
           "Predicted maximum displacement: result.json (grasp runs: rigid motion removed); a path that stopped "
           "before the full force is marked and gets no error.</p>"]
    forces = [f"{r['force_N']:.2f} N" for r in rows]
    series = {"measured": [r["measured_mm"] if r["measured_mm"] is not None else np.nan for r in rows]}
    for kind in ("nonlinear", "linear"):
        vals = [r[kind]["max_mm"] if r.get(kind) and r[kind]["max_mm"] is not None else np.nan for r in rows]
        if np.isfinite(vals).any():
            series[kind] = vals
    if len(series) > 1 or np.isfinite(series["measured"]).any():
        out.append("<div class=\"grid\">" + H.img(bar_chart(forces, series, ylabel="max. displacement [mm]",
                                                            title="measured vs predicted maximum displacement"),
                                                  alt="maximum displacement per force") + "</div>")
    return out


def build_report(run_dirs, out: str | PathLike | None = None, *, scan: str | None = None,
                 table: str | PathLike | None = None, title: str | None = None, views=("iso", "front", "top"),
                 surface_offset_mm: float | None = None, scan_units: str | None = None, progress=None,
                 flagged: list | None = None) -> Path:
    """Write the report of ``run_dirs`` (and of the runs of a ``table`` file) to ``out``
    (default ``RUN_DIR/report.html`` of the first run), atomically; return its path.  A ranking
    folder (``graspdef rank --out``) is reported on its own by
    :func:`graspdef.report.ranking.build_ranking_report`.

    ``scan``: a scan file or manifest id to score every run against first (``RUN_DIR/score``).
    Raises a GraspdefError subclass (``RunFolderError``, ``ReportError``, ``RegistrationError``)
    for a missing or incomplete folder, a bad table file or a scan that cannot be registered;
    nothing is written then.  ``flagged``: a list that receives ``(run folder, flags)`` of every
    flagged score (the page shows them too)."""
    say = progress or (lambda m: None)
    if isinstance(run_dirs, (str, PathLike)):
        run_dirs = [run_dirs]
    rankings = [d for d in (run_dirs or []) if is_ranking(d)]
    if rankings:                                  # a ranking folder (graspdef rank): its own page
        if len(run_dirs) > 1 or table is not None or scan is not None:
            raise ReportError(f"{rankings[0]} is a ranking folder: report it on its own (graspdef report RANK_DIR "
                              "[--out FILE] [--title T]; no other folders, --table or --scan)")
        from .ranking import build_ranking_report

        return build_ranking_report(rankings[0], out, title=title, views=views, progress=progress)
    entries: list[tuple[Path, float | None, float | None]] = [(Path(d), None, None) for d in (run_dirs or [])]
    if table is not None:
        entries += read_table_file(table)
    if not entries:
        raise ReportError("no run folders: give RUN_DIR ... or --table FILE")
    runs = []
    for d, force, measured in entries:
        score_dir = None
        if scan is not None:
            say(f"scoring {d}/deformed.ply against {scan}")
            score_dir = score_run(d, scan, surface_offset_mm=surface_offset_mm, scan_units=scan_units)
        rr = load_run(d, score_dir)
        if force is not None:
            rr.force_N = force
            row = paper_row(force, rr.obj)
            rr.measured_mm = row["measured_max_mm"] if row else None
        if measured is not None:
            rr.measured_mm = measured
        runs.append(rr)
        if rr.score is not None and (rr.score.get("flags") or rr.score.get("ok") is False):
            if flagged is not None:
                flagged.append((rr.run.path, list(rr.score.get("flags") or [])))
        say(f"read {d} ({rr.run.analysis}{', scored' if rr.score else ''})")
    out_path = Path(out) if out is not None else entries[0][0] / "report.html"
    if out_path.is_dir():
        raise ReportError(f"--out {out_path} is a folder; give a file name such as {out_path / 'report.html'}")
    if not out_path.parent.is_dir():
        raise ReportError(f"cannot write {out_path}: folder {out_path.parent} does not exist")
    title = title or ("graspdef report: " + ", ".join(rr.run.name for rr in runs[:4])
                      + (f" and {len(runs) - 4} more" if len(runs) > 4 else ""))
    body = ["<p class=\"note\">Contents: " + ", ".join(
        f"<a href=\"#run-{i}\">{H.esc(rr.run.label)}</a>" for i, rr in enumerate(runs))
        + "</p>"]
    rows = table_rows(runs)
    # measured vs predicted only where a measurement exists (the paper's for the tennis ball, or a
    # table file's); runs of an object nobody measured get no comparison table
    if any(r["measured_mm"] is not None for r in rows):
        body[0] = body[0].replace("</p>", ", <a href=\"#table-i\">Table I</a></p>")
        body += _table_section(rows)
    for i, rr in enumerate(runs):
        say(f"rendering {rr.run.name}")
        body += _run_section(rr, views, i)
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    text = H.page(title, body, subtitle=f"written {stamp} by graspdef report from "
                                        + ", ".join(str(rr.run.path) for rr in runs))
    return H.write_page(out_path, text)


__all__ = ["PAPER_TABLE_I", "ReportError", "RunReport", "build_report", "load_run", "read_table_file",
           "score_run", "table_rows"]
