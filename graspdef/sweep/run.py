"""Running a sweep on dask.distributed: locally (an embedded LocalCluster) or on a cluster.

Layout of a sweep folder::

    OUT/spec.toml           the spec as run (the last run's, when a sweep is extended)
    OUT/provenance.json     versions, command line, the spec text
    OUT/cases/<case id>/    one run folder per finished case (result.json, deformed.ply, ...)
                            + case.json (the case, its status, its key results) + provenance.json
    OUT/results.csv         one row per case of the spec (units in the header)
    OUT/summary.md          counts, times, the table in short, the failures with their errors
    OUT/sweep.json          the same summary, machine-readable
    OUT/runs.jsonl          one line per invocation (cases run and reused, wall time)

Resume semantics (see docs/sweep.md):

* a case is *final* when ``cases/<id>/case.json`` exists; the worker writes the case's folder
  (run files + case.json) in a temporary folder and renames it into place in one step
  (:func:`graspdef.runs.folder.atomic_folder`), so a case is either complete on disk or absent;
* a killed worker loses only the case it was running (dask reschedules it on another worker;
  its temporary folder is removed at the end of the sweep);
* a case that raises is submitted once more; a second failure is recorded as
  ``status = "failed"`` with the error and traceback (written by the client);
* running the sweep again skips every final case (``retry_failed=True`` reruns failed ones).

Numbers do not depend on where a case runs: every case runs single-threaded (numba set to one
thread inside the task; dask's nanny starts workers with MKL/OpenBLAS/OMP at one thread), which
is also what parallel cases on a small machine want.
"""
from __future__ import annotations

import csv
import datetime
import io
import json
import logging
import os
import shutil
import socket
import statistics
import time
import traceback
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Callable

from ..errors import GraspdefError
from ..runs.folder import atomic_folder
from ..runs.provenance import write_provenance
from ..units import PRESSURE_UNITS, format_quantity
from .spec import Case, SweepSpec

log = logging.getLogger(__name__)

CASES = "cases"
RUNNING = ".running"
#: results.csv columns (units in the names)
COLUMNS = ["case_id", "status", "scene", "force_N", "material", "analysis", "E_MPa", "gas_p0_kPa", "contact",
           "control_faces", "control_vertices", "max_displacement_mm", "indentation_mm", "completed", "load_factor",
           "normal_force_left_N", "normal_force_right_N", "net_force_residual_N", "seconds", "attempts", "error",
           "run_folder"]


class SweepError(GraspdefError):
    """A sweep cannot start (scheduler unreachable, workers cannot see the folder, ...)."""


def _now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def read_case_record(folder: Path) -> dict | None:
    """The case.json of a case folder, or None when the case has no final record."""
    try:
        return json.loads((folder / "case.json").read_text())
    except (OSError, ValueError):
        return None


# ----------------------------------------------------------------------------------- worker side

def probe_worker(cases_dir: str) -> dict:
    """Run on a worker before the sweep: can it see the sweep folder, which graspdef is it."""
    from importlib import metadata

    return {"host": socket.gethostname(), "pid": os.getpid(), "sees_folder": Path(cases_dir).is_dir(),
            "graspdef": metadata.version("graspdef")}


def run_case(case_rec: dict, cases_dir: str, attempt: int = 1) -> dict:
    """Worker side: run one case and commit its folder atomically; return its case record.

    A case whose folder already holds a ``done`` record is not run again (a resubmitted task
    whose first run was committed just before its worker died)."""
    import numba

    case = Case.from_record(case_rec)
    folder = Path(cases_dir) / case.id
    old = read_case_record(folder)
    if old is not None and old.get("status") == "done":
        return old
    marker = Path(cases_dir) / RUNNING / f"{case.id}.json"
    marker.parent.mkdir(exist_ok=True)
    marker.write_text(json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "started_utc": _now(),
                                  "attempt": attempt}) + "\n")
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        from ..objects import OBJECT_FILE
        from ..pipeline.grasp import run_grasp

        t0 = time.perf_counter()
        kwargs = {"gas": {"auto": None, "on": True, "off": False}[case.gas], "control_faces": case.control_faces,
                  "steps": case.steps, "E": case.E_Pa}
        with atomic_folder(folder) as tmp:
            run = run_grasp(case.scene, case.force_N, case.contact, case.analysis, tmp, **kwargs)
            rec = {"case": case.record(), "status": "done", "attempts": attempt, "error": None,
                   "seconds": time.perf_counter() - t0, "finished_utc": _now(),
                   "worker": {"host": socket.gethostname(), "pid": os.getpid()},
                   "results": _key_results(run.result)}
            (tmp / "case.json").write_text(json.dumps(rec, indent=2) + "\n")
            write_provenance(tmp, {"case": case.record(), "run_grasp": {
                "scene": case.scene, "force": case.force_N, "contact": case.contact, "analysis": case.analysis,
                **kwargs}, "object_toml": (Path(run.result["scene"]).parent / OBJECT_FILE).read_text()},
                thread_env={k: os.environ.get(k) for k in ("MKL_NUM_THREADS", "OMP_NUM_THREADS",
                                                            "OPENBLAS_NUM_THREADS")} | {"numba": 1})
        return rec
    finally:
        numba.set_num_threads(threads)
        marker.unlink(missing_ok=True)


def _key_results(r: dict) -> dict:
    fb = r.get("feedback", {})
    fingers = r.get("fingers", {})
    conv = r.get("convergence", {})
    net = r.get("residual", {}).get("net_force_N", [0.0, 0.0, 0.0])
    return {
        "max_displacement_m": r["derived"]["max_displacement"]["value"],       # the run record's, same definition
        "indentation_m": fb.get("indentation_per_finger_m", fb.get("indentation_m")),
        "completed": conv.get("completed"),
        "load_factor": conv.get("load_factor", 1.0 if conv.get("completed") else None),
        "control_vertices": r.get("shell", {}).get("control_vertices"),
        "control_faces": r.get("shell", {}).get("control_faces"),
        "E_Pa": r.get("material", {}).get("E_Pa"),
        "gas_p0_Pa": r.get("gas_p0_Pa"),
        "normal_force_N": {s: f.get("normal_force_N") for s, f in fingers.items()},
        "net_force_residual_N": float(sum(v * v for v in net) ** 0.5),
    }


# ----------------------------------------------------------------------------------- client side

@dataclass
class SweepOutcome:
    """What :func:`run_sweep` did."""

    out: Path
    n_cases: int
    n_done: int
    n_failed: int
    n_skipped: int          # final before this run (not recomputed)
    n_run: int              # run by this call
    seconds: float
    rows: list

    @property
    def table(self) -> Path:
        return self.out / "results.csv"


def _worker_env() -> dict:
    """Environment of the local workers: where MKL's runtime library is.  pypardiso otherwise
    searches sys.prefix for it on every solver it creates (2-4 s per case on this machine)."""
    try:
        import pypardiso

        return {"PYPARDISO_MKL_RT": str(pypardiso.ps.libmkl._name)}
    except Exception:       # noqa: BLE001 - no pypardiso (SuperLU fallback) or another layout
        return {}


def _connect(scheduler: str | None, workers: int, timeout: float):
    """(client, cluster or None); every failure is a SweepError before any work."""
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise SweepError("graspdef sweep needs dask.distributed: pip install 'graspdef[sweep]'") from exc
    if scheduler is None:
        if workers < 1:
            raise SweepError(f"--workers must be >= 1, got {workers}")
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address="127.0.0.1:0", scheduler_port=0, silence_logs=logging.ERROR,
                               env=_worker_env())
        return Client(cluster), cluster
    if "://" not in scheduler or not scheduler.split("://", 1)[1]:
        raise SweepError(f"--scheduler must look like tcp://HOST:PORT, got {scheduler!r}")
    try:
        client = Client(scheduler, timeout=f"{timeout}s")
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"cannot reach the dask scheduler at {scheduler} within {timeout:g} s ({exc}); start one "
                         f"with `dask scheduler` and workers with `dask worker {scheduler}`") from exc
    try:
        client.wait_for_workers(1, timeout=timeout)
    except (OSError, TimeoutError) as exc:
        client.close()
        raise SweepError(f"the dask scheduler at {scheduler} has no workers (waited {timeout:g} s); start some with "
                         f"`dask worker {scheduler} --nworkers N --nthreads 1`") from exc
    return client, None


def _check_workers(client, cases_dir: Path, timeout: float) -> int:
    try:
        info = client.run(probe_worker, str(cases_dir))
    except Exception as exc:        # noqa: BLE001 - anything the workers raise (no graspdef, ...)
        raise SweepError(f"the dask workers cannot run graspdef ({type(exc).__name__}: {exc}); install graspdef "
                         "(with the sim extra) on every worker") from exc
    blind = [f"{w} ({i['host']})" for w, i in info.items() if not i["sees_folder"]]
    if blind:
        raise SweepError(f"workers {', '.join(blind)} cannot see the sweep folder {cases_dir}: put it on a "
                         "filesystem shared by the client and every worker (an absolute path)")
    return len(info)


def _clean_orphans(cases_dir: Path) -> int:
    """Remove the temporary folders and running markers that killed workers left behind."""
    n = 0
    for p in cases_dir.iterdir():
        if p.name.startswith(".") and p.name != RUNNING and p.is_dir():
            shutil.rmtree(p, ignore_errors=True)
            n += 1
    run = cases_dir / RUNNING
    if run.is_dir():
        for p in run.iterdir():
            p.unlink(missing_ok=True)
    return n


def _error_text(exc: BaseException) -> str:
    msg = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {msg[0] if msg else ''}".strip()


def _write_failed(cases_dir: Path, case: Case, attempts: int, exc: BaseException, tb: str) -> dict:
    rec = {"case": case.record(), "status": "failed", "attempts": attempts, "error": _error_text(exc),
           "traceback": tb, "seconds": None, "finished_utc": _now(), "worker": None, "results": None}
    with atomic_folder(cases_dir / case.id) as tmp:
        (tmp / "case.json").write_text(json.dumps(rec, indent=2) + "\n")
    return rec


def run_sweep(spec: SweepSpec, out: str | PathLike, *, scheduler: str | None = None, workers: int = 2,
              retry_failed: bool = False, parquet: bool = False, connect_timeout: float = 5.0,
              progress: Callable[[str], None] | None = None) -> SweepOutcome:
    """Run every case of ``spec`` not yet final in ``out``; gather results.csv and summary.md.

    Parameters
    ----------
    spec : SweepSpec
        From :func:`graspdef.sweep.load_spec`.
    out : path
        The sweep folder (created; an existing one is resumed).
    scheduler : str, optional
        ``tcp://HOST:PORT`` of a running dask scheduler; default: an embedded LocalCluster of
        ``workers`` single-threaded worker processes.
    retry_failed : bool
        Rerun cases recorded as failed (default: failed cases are final, like finished ones).
    parquet : bool
        Also write results.parquet (needs pyarrow).
    progress : callable, optional
        Called with one line of text per event (start, each case finished or failed, the end).

    Raises
    ------
    SweepError
        Before any case runs: dask missing, scheduler unreachable or without workers, workers
        that cannot see ``out`` or import graspdef, pyarrow missing for ``parquet``.
    """
    say = progress or (lambda _m: None)
    t0 = time.perf_counter()
    out = Path(out).resolve()
    if parquet:
        try:
            import pyarrow  # noqa: F401
        except ImportError as exc:
            raise SweepError("results.parquet needs pyarrow (pip install pyarrow); results.csv is written "
                             "without it") from exc
    if out.exists() and not out.is_dir():
        raise SweepError(f"{out} exists and is not a folder")
    try:
        import distributed  # noqa: F401  (creates its loggers)
    except ImportError as exc:
        raise SweepError("graspdef sweep needs dask.distributed: pip install 'graspdef[sweep]'") from exc
    # our progress lines say what happens; dask's INFO lines (cluster start, worker restarts) would drown them
    quiet = {n: lg.level for n, lg in logging.root.manager.loggerDict.items()
             if n.split(".")[0] == "distributed" and isinstance(lg, logging.Logger)}
    for n in quiet:
        logging.getLogger(n).setLevel(logging.ERROR)
    try:
        return _run_sweep(spec, out, scheduler, workers, retry_failed, parquet, connect_timeout, say, t0)
    finally:
        for n, level in quiet.items():
            logging.getLogger(n).setLevel(level)


def _run_sweep(spec, out, scheduler, workers, retry_failed, parquet, connect_timeout, say, t0) -> SweepOutcome:
    cases_dir = out / CASES
    todo, skipped = [], 0
    for c in spec.cases:
        rec = read_case_record(cases_dir / c.id)
        if rec is None or (retry_failed and rec.get("status") == "failed"):
            todo.append(c)
        else:
            skipped += 1
    prov = {"spec_file": "spec.toml", "spec_path": spec.path, "text": spec.text, "retry_failed": retry_failed,
            "scheduler": scheduler or f"LocalCluster({workers} processes x 1 thread)"}
    n_run = 0
    if not todo:                        # nothing to compute: no cluster
        cases_dir.mkdir(parents=True, exist_ok=True)
        (out / "spec.toml").write_text(spec.text)
        write_provenance(out, prov)
        say(f"sweep {spec.name}: all {len(spec.cases)} cases already final; folder {out}")
    else:
        say(f"connecting to the dask scheduler at {scheduler}" if scheduler else
            f"starting a local cluster: {workers} worker process{'es' if workers != 1 else ''}, 1 thread each")
        client, cluster = _connect(scheduler, workers, connect_timeout)
        try:
            cases_dir.mkdir(parents=True, exist_ok=True)
            n_workers = _check_workers(client, cases_dir, connect_timeout)
            (out / "spec.toml").write_text(spec.text)
            write_provenance(out, prov)
            _clean_orphans(cases_dir)
            say(f"sweep {spec.name}: {len(spec.cases)} cases, {skipped} already final, {len(todo)} to run on "
                f"{n_workers} worker{'s' if n_workers != 1 else ''} ({scheduler or 'this machine'}); folder {out}")
            n_run = _execute(client, todo, cases_dir, say)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    _clean_orphans(out / CASES)
    rows = gather(spec, out, parquet=parquet)
    seconds = time.perf_counter() - t0
    n_done = sum(r["status"] == "done" for r in rows)
    n_failed = sum(r["status"] == "failed" for r in rows)
    write_summary(spec, out, rows, seconds, n_run, skipped)
    say(f"sweep {spec.name}: {n_done} done, {n_failed} failed of {len(rows)} cases in {seconds:.1f} s; "
        f"wrote {out}/results.csv, summary.md")
    return SweepOutcome(out, len(spec.cases), n_done, n_failed, skipped, n_run, seconds, rows)


def _execute(client, todo: list[Case], cases_dir: Path, say, heartbeat: float = 30.0) -> int:
    """Submit the cases, report each as it ends, resubmit a failed case once, record the second
    failure; a line every ``heartbeat`` seconds while nothing ends."""
    from distributed import wait

    if not todo:
        return 0
    by_key = {}

    def submit(case: Case, attempt: int):
        fut = client.submit(run_case, case.record(), str(cases_dir), attempt, pure=False,
                            key=f"graspdef-case-{case.id}-{attempt}")
        by_key[fut.key] = (case, attempt)
        return fut

    pending = {submit(c, 1) for c in todo}
    n, k, t0 = len(todo), 0, time.perf_counter()
    while pending:
        try:
            finished, pending = wait(pending, timeout=heartbeat, return_when="FIRST_COMPLETED")
        except TimeoutError:
            running = len(list((cases_dir / RUNNING).glob("*.json"))) if (cases_dir / RUNNING).is_dir() else 0
            say(f"{k}/{n} cases done, {running} running, {time.perf_counter() - t0:.0f} s")
            continue
        pending = set(pending)
        for fut in finished:
            case, attempt = by_key.pop(fut.key)
            if fut.status == "finished":
                rec = fut.result()
                k += 1
                say(f"case {k}/{n} done ({case.label()}) {rec['seconds']:.1f} s")
                continue
            try:
                exc = fut.exception()
                tb = "".join(traceback.format_tb(fut.traceback())) if fut.traceback() is not None else ""
            except Exception as err:        # noqa: BLE001 - cancelled (e.g. the scheduler restarted)
                exc, tb = err, ""
            if attempt == 1:
                say(f"case ({case.label()}) failed: {_error_text(exc)}; retrying once")
                pending.add(submit(case, 2))
                continue
            k += 1
            _write_failed(cases_dir, case, attempt, exc, tb)
            say(f"case {k}/{n} FAILED ({case.label()}): {_error_text(exc)}")
    return n


# ------------------------------------------------------------------------------------- gathering

def _row(case: Case, rec: dict | None, out: Path) -> dict:
    row = {c: "" for c in COLUMNS}
    row.update({"case_id": case.id, "scene": case.scene_name, "force_N": case.force_N, "material": case.material,
                "analysis": case.analysis, "contact": case.contact, "control_faces": case.control_faces,
                "E_MPa": "" if case.E_Pa is None else case.E_Pa / PRESSURE_UNITS["MPa"]})
    if rec is None:
        row["status"] = "missing"
        return row
    row.update({"status": rec["status"], "attempts": rec.get("attempts", ""), "error": rec.get("error") or ""})
    if rec["status"] != "done":
        return row
    r = rec["results"]
    nf = r.get("normal_force_N") or {}
    row.update({
        "E_MPa": r["E_Pa"] / 1e6 if r.get("E_Pa") is not None else row["E_MPa"],
        "gas_p0_kPa": r["gas_p0_Pa"] / 1e3 if r.get("gas_p0_Pa") is not None else "",
        "control_faces": r.get("control_faces", case.control_faces),
        "control_vertices": r.get("control_vertices", ""),
        "max_displacement_mm": r["max_displacement_m"] * 1e3,
        "indentation_mm": "" if r.get("indentation_m") is None else r["indentation_m"] * 1e3,
        "completed": r.get("completed"), "load_factor": "" if r.get("load_factor") is None else r["load_factor"],
        "normal_force_left_N": nf.get("left", ""), "normal_force_right_N": nf.get("right", ""),
        "net_force_residual_N": r.get("net_force_residual_N", ""), "seconds": rec.get("seconds", ""),
        "run_folder": f"{CASES}/{case.id}"})
    return row


def gather(spec: SweepSpec, out: str | PathLike, parquet: bool = False) -> list[dict]:
    """Read every case record of ``spec`` in ``out``; write results.csv (and .parquet)."""
    out = Path(out)
    rows = [_row(c, read_case_record(out / CASES / c.id), out) for c in spec.cases]
    buf = io.StringIO()
    w = csv.DictWriter(buf, COLUMNS, lineterminator="\n")
    w.writeheader()
    w.writerows({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()} for r in rows)
    tmp = out / ".results.csv.tmp"
    tmp.write_text(buf.getvalue())
    os.replace(tmp, out / "results.csv")
    if parquet:
        import pyarrow as pa
        import pyarrow.parquet as pq

        cols = {c: [r[c] if r[c] != "" else None for r in rows] for c in COLUMNS}
        pq.write_table(pa.table(cols), out / "results.parquet")
    return rows


def write_summary(spec: SweepSpec, out: Path, rows: list[dict], seconds: float, n_run: int, n_skipped: int) -> None:
    """summary.md and sweep.json: counts, times, the results in short, the failures."""
    done = [r for r in rows if r["status"] == "done"]
    failed = [r for r in rows if r["status"] == "failed"]
    times = [float(r["seconds"]) for r in done if r["seconds"] != ""]
    stats = {"median": statistics.median(times), "min": min(times), "max": max(times),
             "sum": sum(times)} if times else {}
    record = {"name": spec.name, "description": spec.description, "n_cases": len(rows), "n_done": len(done),
              "n_failed": len(failed), "n_missing": len(rows) - len(done) - len(failed), "n_run": n_run,
              "n_skipped": n_skipped, "wall_seconds": seconds, "case_seconds": stats,
              "axes": {"scenes": list(spec.scenes), "forces_N": list(spec.forces_N), "materials": spec.materials,
                       "contacts": list(spec.contacts),
                       "control_faces": list(spec.control_faces) if spec.control_faces else "object.toml"},
              "finished_utc": _now()}
    (out / "sweep.json").write_text(json.dumps(record, indent=2) + "\n")
    with open(out / "runs.jsonl", "a") as fh:      # one line per invocation: the history of a resumed sweep
        fh.write(json.dumps({k: record[k] for k in ("finished_utc", "n_run", "n_skipped", "n_done", "n_failed",
                                                    "wall_seconds")}) + "\n")
    L = [f"# Sweep {spec.name}", ""]
    if spec.description:
        L += [spec.description, ""]
    L += [f"{len(rows)} cases: **{len(done)} done**, **{len(failed)} failed**"
          + (f", {record['n_missing']} missing" if record["n_missing"] else "")
          + f"; this run computed {n_run} and reused {n_skipped}; wall time {seconds:.1f} s.", ""]
    if stats:
        L += [f"Time per case (in its worker): median {stats['median']:.1f} s, min {stats['min']:.1f} s, "
              f"max {stats['max']:.1f} s, total {stats['sum']:.1f} s.", ""]
    L += ["Materials: " + "; ".join(f"`{n}` = {m['analysis']}"
                                    + (f", E = {format_quantity(m['E_Pa'], 'MPa', 'pressure')}" if m["E_Pa"] is not None
                                       else ", the object's E")
                                    + (f", gas {m['gas']}" if m["analysis"] == "nonlinear" else "")
                                    for n, m in spec.materials.items()), ""]
    L += ["| scene | force [N] | material | contact | control faces | status | max. displacement [mm] | "
          "indentation [mm] | path completed | time [s] |", "|---|---|---|---|---|---|---|---|---|---|"]

    def f(v, fmt):
        return "" if v == "" or v is None else format(float(v), fmt)

    def completed(r):
        if r["completed"] in ("", None):
            return ""
        if r["completed"] or r["load_factor"] in ("", None):
            return "yes" if r["completed"] else "no"
        return f"path stopped at {float(r['load_factor']) * r['force_N']:.3g} N"

    for r in rows:
        L.append(f"| {r['scene']} | {r['force_N']:g} | {r['material']} | {r['contact']} | {r['control_faces']} | "
                 f"{r['status']} | {f(r['max_displacement_mm'], '.3f')} | {f(r['indentation_mm'], '.3f')} | "
                 f"{completed(r)} | {f(r['seconds'], '.1f')} |")
    if failed:
        L += ["", "## Failed cases", ""]
        L += [f"* `{r['case_id']}` (after {r['attempts']} attempts): {r['error']}" for r in failed]
    L += ["", "Full table: `results.csv` (one row per case, units in the column names); each case's run folder: "
          "`cases/<case_id>/` (`graspdef view cases/<case_id>` shows it, `graspdef report cases/<id> cases/<id> ...` "
          "writes an HTML report of several)."]
    (out / "summary.md").write_text("\n".join(L) + "\n")
