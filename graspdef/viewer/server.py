"""The viser page: one or several run folders side by side (viser is imported only here).

Per run: the deformed limit surface coloured by |u| (legend in the run's units), the undeformed
shape, a deformation scale factor, fingers, contact points and force arrows (contacts.json),
a scan coloured by its signed error (score.json), a slider along the load path with the
load-displacement chart, and live force / modulus sliders (:mod:`.live`).

Threads: viser's server thread, its callback pool, and one worker of ours (live set-up, path
re-solves and re-solves); :meth:`Viewer.stop` ends all of them and frees the port.
"""
from __future__ import annotations

import contextlib
import io
import logging
import socket
import threading
import time
from os import PathLike
from pathlib import Path

import numpy as np

from ..errors import GraspdefError
from . import layers
from ..runs.read import RunData, read_run

log = logging.getLogger(__name__)


class ViewerError(GraspdefError):
    """The viewer cannot start (port in use, bad host, viser missing)."""


def _import_viser():
    try:
        import viser
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ViewerError(f"the viewer needs viser: pip install 'graspdef[viewer]' ({exc})") from None
    return viser


def check_port(host: str, port: int) -> None:
    """Raise ViewerError if ``host:port`` cannot be bound (in use, or not a local address)."""
    if port == 0:
        return
    if not (0 < port < 65536):
        raise ViewerError(f"port must be 0..65535, got {port}")
    s = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)     # as asyncio does on POSIX
        s.bind((host, port))
    except OSError as exc:
        if exc.errno in (98, 48):                                    # EADDRINUSE (Linux, macOS)
            raise ViewerError(f"port {port} on {host} is in use (another viewer?): choose another with --port") from None
        raise ViewerError(f"cannot listen on {host}:{port}: {exc.strerror or exc}") from None
    finally:
        s.close()


def open_server(host: str, port: int):
    """(a quiet viser server on ``host``:``port``, its port); a port in use is refused (viser
    would move on to the next free one), a port of 0 takes any free one."""
    viser = _import_viser()
    check_port(host, port)
    with contextlib.redirect_stdout(io.StringIO()):
        server = viser.ViserServer(host=host, port=port, verbose=False)
    got = server.get_port()
    if port != 0 and got != port:
        close_server(server)
        raise ViewerError(f"port {port} on {host} is in use (another viewer?): choose another with --port")
    return server, got


def close_server(server) -> None:
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()


def page_url(host: str, port: int) -> str:
    return f"http://{f'[{host}]' if ':' in host else host}:{port}"


class ServerPage:
    """The life cycle both viewer pages share (runs, ranking): the URL, ``with``, ``stop()`` (safe
    twice; a page stops its own workers first in :meth:`_before_close`) and ``wait()``.  A page
    sets ``host``, ``port``, ``server`` (:func:`open_server`), ``_lock``, ``_stop`` and
    ``_stopped`` in its constructor."""

    @property
    def url(self) -> str:
        return page_url(self.host, self.port)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def _stop_server(self) -> None:
        close_server(self.server)

    def _before_close(self) -> None:
        """What the page stops before its server (workers, live solvers)."""

    def stop(self) -> None:
        """Stop the page's workers and the server; free the port.  Safe to call twice."""
        with self._lock:                                 # let a redraw in progress finish
            if self._stopped:
                return
            self._stopped = True
        self._stop.set()
        self._before_close()
        self._stop_server()

    def wait(self) -> None:
        """Block until interrupted (Ctrl-C) or stopped."""
        try:
            while not self._stop.wait(0.5):
                pass
        except KeyboardInterrupt:
            pass


class _RunView:
    """Scene nodes, GUI and state of one run."""

    def __init__(self, viewer: "Viewer", index: int, run: RunData, centre: np.ndarray, lref: float, offset: np.ndarray):
        self.v, self.i, self.run = viewer, index, run
        self.centre, self.lref, self.offset = centre, lref, offset
        self.root = f"/run{index}"
        self.disp = run.displacements.copy()           # (n, 3) [m] shown now
        self.source = "final state"
        self.step: int | None = None
        self.live = None
        self.live_error: str | None = None
        n_path = len(run.path_table.load_factors) if run.path_table is not None else 0
        self.n_path = n_path
        if n_path:
            self.step = n_path - 1
        mags = [np.linalg.norm(self.disp, axis=1).max()]
        if run.path_u is not None:
            mags += [np.linalg.norm(run.path_displacements(k), axis=1).max() for k in range(n_path)]
        self.vmax = float(max(mags))                   # colour range [m], grows with live states
        self.displayed: np.ndarray | None = None       # (n, 3) float32 display coordinates sent last
        self.status = ""

    # ---- coordinates -------------------------------------------------------------------------
    def to_display(self, x: np.ndarray) -> np.ndarray:
        return ((np.asarray(x, float) - self.centre) / self.lref + self.offset).astype(np.float32)

    # ---- building ------------------------------------------------------------------------------
    def build(self) -> None:
        v, run, gui, scene = self.v, self.run, self.v.server.gui, self.v.server.scene
        lo = self.to_display(run.rest_vertices).min(0)
        hi = self.to_display(run.rest_vertices).max(0)
        self.label = scene.add_label(f"{self.root}/title", run.label, anchor="top-center",
                                     position=(float(0.5 * (lo[0] + hi[0])), float(lo[1] - 0.15), float(lo[2])))
        self.folder = gui.add_folder(f"{self.i + 1}: {run.name}")
        with self.folder:
            self.legend = gui.add_html("")
            self.info = gui.add_markdown("")
            if self.n_path:
                self.step_slider = gui.add_slider("load path step", 0, self.n_path - 1, 1, self.n_path - 1)
                self.step_slider.on_update(lambda _: self.v._on_step(self))
                self.chart = gui.add_html("")
            self.force_slider = self.modulus_slider = None
            self.live_folder = gui.add_folder("live re-solve", expand_by_default=True)
            with self.live_folder:
                self.live_status = gui.add_markdown("*preparing the live model…*" if v.live else "*live re-solves off*")
            if run.scan is not None:
                sc = run.scan
                self.scan_check = gui.add_checkbox("scan overlay", True)
                self.scan_check.on_update(lambda _: self._scan_visibility())
                lim = float(np.max(np.abs(sc.errors_mm))) if len(sc.errors_mm) else 1.0
                self.scan_legend = gui.add_html(layers.legend_html("scan error (signed)", "mm", -lim, lim,
                                                                   layers.DIVERGING))
                rows = [f"| | prediction | undeformed |", "|---|---|---|"]
                for k in ("mean_mm", "rms_mm", "max_mm"):
                    a, b = sc.stats_mm.get(k), sc.baseline_stats_mm.get(k)
                    rows.append(f"| {k[:-3]} [mm] | {_fmt(a)} | {_fmt(b)} |")
                self.scan_info = gui.add_markdown("\n".join(rows) + (f"\n\n{sc.summary}" if sc.summary else ""))
        if run.scan is not None:
            sc = run.scan
            lim = float(np.max(np.abs(sc.errors_mm))) if len(sc.errors_mm) else 1.0
            cols = layers.colormap(sc.errors_mm, -lim, lim, layers.DIVERGING)
            self.scan_cloud = scene.add_point_cloud(f"{self.root}/scan", self.to_display(sc.points), cols,
                                                    point_size=0.008, point_shape="circle")
        if run.contacts is not None:
            self._build_contacts()
        self.redraw()
        self._update_info()

    def _build_contacts(self) -> None:
        scene, c = self.v.server.scene, self.run.contacts
        for k, f in enumerate(c.fingers):
            size = f["size"] / self.lref if f["size"] is not None else np.full(3, 0.06)
            scene.add_box(f"{self.root}/fingers/{k}_{f['name']}", color=(150, 150, 160), dimensions=tuple(size),
                          wxyz=tuple(f["wxyz"]), position=tuple(self.to_display(f["position"])), opacity=0.8)
        if len(c.points):
            p = self.to_display(c.points)
            scene.add_point_cloud(f"{self.root}/contact_points", p, (230, 30, 30), point_size=0.02,
                                  point_shape="circle")
            seg = layers.force_arrows(p, c.forces, 0.3)
            scene.add_arrows(f"{self.root}/forces", seg.astype(np.float32), (230, 60, 30), shaft_radius=0.006,
                             head_radius=0.016, head_length=0.04)
            for k, (tail, f) in enumerate(zip(seg[:, 0], c.forces)):
                scene.add_label(f"{self.root}/force_labels/{k}", f"{np.linalg.norm(f):.3g} N", position=tuple(tail))

    def _scan_visibility(self) -> None:
        self.scan_cloud.visible = bool(self.scan_check.value)

    # ---- drawing ---------------------------------------------------------------------------------
    def redraw(self) -> None:
        import trimesh

        with self.v._lock:
            if not self.v._stopped:
                self._redraw()

    def _redraw(self) -> None:
        import trimesh

        v, run = self.v, self.run
        scale = float(v.scale_input.value)
        mode = v.show_dropdown.value
        mags = np.linalg.norm(self.disp, axis=1)
        self.vmax = max(self.vmax, float(mags.max()))
        verts = self.to_display(run.rest_vertices + scale * self.disp)
        cols = layers.colormap(mags, 0.0, self.vmax)
        mesh = trimesh.Trimesh(verts, run.faces, vertex_colors=np.c_[cols, np.full(len(cols), 255, np.uint8)],
                               process=False)
        with v._lock:
            self.mesh_handle = v.server.scene.add_mesh_trimesh(f"{self.root}/deformed", mesh,
                                                               visible=mode in ("deformed", "both"))
            self.mesh_handle.on_click(lambda ev: self.pick(ev.ray_origin, ev.ray_direction))
            if not hasattr(self, "rest_handle"):
                self.rest_handle = v.server.scene.add_mesh_simple(
                    f"{self.root}/undeformed", self.to_display(run.rest_vertices), run.faces, color=(170, 170, 170),
                    opacity=0.35 if mode == "both" else None, side="double", visible=mode != "deformed")
            else:
                self.rest_handle.visible = mode != "deformed"
                self.rest_handle.opacity = 0.35 if mode == "both" else None
            self.displayed = verts
        ls = run.display_scale
        self.legend.content = layers.legend_html(run.displacement_label, run.display_unit, 0.0, self.vmax / ls)

    def pick(self, origin, direction) -> str:
        """The numbers at the surface point under a click (a ray in display coordinates): the
        nearest shown vertex's displacement and, with a scan, the nearest scan point's error."""
        o, dvec = np.asarray(origin, float), np.asarray(direction, float)
        dvec = dvec / np.linalg.norm(dvec)
        x = self.displayed.astype(float) - o
        t = x @ dvec
        dist = np.linalg.norm(x - t[:, None] * dvec, axis=1)
        near = dist < max(2.0 * float(dist.min()), 0.02)
        i = int(np.flatnonzero(near)[np.argmin(t[near])])             # the front-most close vertex
        ls, lu = self.run.display_scale, self.run.display_unit
        u = self.disp[i] / ls
        text = (f"**picked vertex {i}**: |u| = {np.linalg.norm(u):.4g} {lu}, "
                f"u = ({u[0]:.3g}, {u[1]:.3g}, {u[2]:.3g}) {lu}")
        if self.run.scan is not None and len(self.run.scan.points):
            sc = self.run.scan
            xs = self.run.rest_vertices[i] + float(self.v.scale_input.value) * self.disp[i]
            j = int(np.argmin(np.linalg.norm(sc.points - xs, axis=1)))
            text += f"; nearest scan point {j}: error {sc.errors_mm[j]:+.3f} mm"
        self.picked = text
        self._update_info()
        return text

    def _update_info(self, extra: str = "") -> None:
        run = self.run
        ls = run.display_scale
        lines = [f"**{run.analysis}** run `{run.path.name}` · units: {run.display_unit}, {run.force_unit}",
                 f"showing: {self.source} · max |u| = {np.linalg.norm(self.disp, axis=1).max() / ls:.4g} "
                 f"{run.display_unit}"]
        md = run.record.derived.get("max_displacement")
        if md is not None:                     # the run's own number, with its definition (as in the report)
            lines.append(f"{md['label']} of the run: {md['value'] / ls:.4g} {run.display_unit} ({md['definition']})")
        lines += [f"*{n}*" for n in run.notes]
        lines.append(getattr(self, "picked", None) or "*click the surface for the numbers at a point*")
        if extra:
            lines.append(extra)
        self.status = "\n\n".join(lines)
        self.info.content = self.status
        if self.n_path:
            self._update_chart()

    def _update_chart(self, live_point: tuple[float, float] | None = None) -> None:
        t = self.run.path_table
        if not t.probes:
            self.chart.content = "<i>no probe in path.csv: no load-displacement chart</i>"
            return
        name, p = next(iter(t.probes.items()))
        comp = int(np.argmax(np.ptp(p, axis=0)))
        x = p[:, comp] / self.run.display_scale
        self.chart.content = layers.chart_svg(x, t.load_factors, self.step if self.source.startswith("path") or
                                              self.source == "final state" else None,
                                              f"{name} u{'xyz'[comp]} [{self.run.display_unit}]", "load factor",
                                              extra=live_point)


def _fmt(v) -> str:
    return "–" if v is None else f"{v:.3g}"


class Viewer(ServerPage):
    """A running viser page for one or more run folders; use :func:`view`.

    ``stop()`` (or leaving the ``with`` block) shuts the server and the worker down."""

    def __init__(self, run_dirs, host: str = "127.0.0.1", port: int = 8080, *, score_dirs=None,
                 live: bool = True, backend: str = "auto"):
        if isinstance(run_dirs, (str, PathLike)):
            run_dirs = [run_dirs]
        run_dirs = list(run_dirs)
        if not run_dirs:
            raise ViewerError("no run folder given")
        score_dirs = list(score_dirs) if score_dirs is not None else [None] * len(run_dirs)
        score_dirs += [None] * (len(run_dirs) - len(score_dirs))
        self.runs = [read_run(d, s) for d, s in zip(run_dirs, score_dirs)]
        self.host = host
        self.live = live
        self.backend = backend
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._wake = threading.Condition()
        self._pending: dict[int, tuple[float, float]] = {}
        self._worker: threading.Thread | None = None
        self._stopped = False
        self._syncing = False
        self.server, self.port = open_server(host, port)
        try:
            self._build()
        except BaseException:
            self._stop_server()
            raise
        if live:
            self._worker = threading.Thread(target=self._work, name="graspdef-viewer-worker", daemon=True)
            self._worker.start()

    # ---- life cycle (ServerPage) -------------------------------------------------------------------
    def _before_close(self) -> None:
        """Stop the live re-solve worker and free the live solvers."""
        with self._wake:
            self._wake.notify_all()
        if self._worker is not None:
            self._worker.join(timeout=60)
        for rv in self.views:
            if rv.live is not None:
                rv.live.close()

    # ---- scene -------------------------------------------------------------------------------------
    def _build(self) -> None:
        server = self.server
        server.gui.configure_theme(control_width="large")
        server.scene.set_up_direction("+z")
        server.gui.add_markdown("**graspdef viewer** — " + ", ".join(r.label for r in self.runs))
        self.show_dropdown = server.gui.add_dropdown("show", ("deformed", "undeformed", "both"), initial_value="deformed")
        self.scale_input = server.gui.add_number("deformation scale", 1.0, min=0.0, max=1e6, step=0.1)
        self.views: list[_RunView] = []
        x0 = 0.0
        for i, run in enumerate(self.runs):
            centre, size = layers.display_frame(np.vstack([run.rest_vertices, run.deformed_vertices]))
            lo = (run.rest_vertices - centre).min(0) / size
            hi = (run.rest_vertices - centre).max(0) / size
            offset = np.array([x0 - lo[0], 0.0, 0.0])
            x0 = offset[0] + hi[0] + 0.4
            self.views.append(_RunView(self, i, run, centre, size, offset))
        for rv in self.views:
            rv.build()
        self.show_dropdown.on_update(lambda _: self._redraw_all())
        self.scale_input.on_update(lambda _: self._redraw_all())
        width = x0 - 0.4
        d = 0.55 + 0.45 * width
        cx = width / 2 + 0.3 * d                         # the scene left of the GUI panel
        server.initial_camera.look_at = (cx, 0.0, 0.0)
        server.initial_camera.position = (cx + 0.35 * d, -1.2 * d, 0.85 * d)
        server.initial_camera.up = (0.0, 0.0, 1.0)

    def _redraw_all(self) -> None:
        for rv in self.views:
            rv.redraw()

    # ---- load path --------------------------------------------------------------------------------
    def _on_step(self, rv: _RunView) -> None:
        with self._lock:
            self._show_step(rv)

    def _show_step(self, rv: _RunView) -> None:
        k = int(rv.step_slider.value)
        d = rv.run.path_displacements(k) if rv.run.path_u is not None else None
        lf = rv.run.path_table.load_factors[k]
        if d is None:
            rv._update_info(f"path point {k} (load factor {lf:.4g}): the surface along the path is not "
                            "available yet (path_u.npz absent; re-solving)" if self.live else
                            "path_u.npz absent: only the final state")
            rv.step = k
            return
        rv.disp = d
        shown = float(rv.run.path_u[1][k])
        rv.source = f"path point {k}, load factor {shown:.4g}"
        rv.redraw()
        rv.step = k                                      # set last: the state is complete
        rv._update_info()

    def show_path_point(self, run: int, k: int) -> None:
        """Show path point ``k`` of run ``run`` (what moving its slider does)."""
        rv = self.views[run]
        rv.step_slider.value = int(k)
        self._on_step(rv)

    # ---- live -----------------------------------------------------------------------------------------
    def _add_live_gui(self, rv: _RunView, m) -> None:
        gui = self.server.gui
        with rv.live_folder:
            fu = rv.run.force_unit
            fs = {"N": 1.0, "kN": 1e3, "mN": 1e-3}.get(fu, 1.0)
            if m.force0:
                f0 = m.force0 / fs * (m.lam_end if m.nonlinear else 1.0)
                rv.force_ref = f0
                rv.force_slider = gui.add_slider(f"finger force [{fu}]", 0.0, float(3 * f0), float(f0 / 100), float(f0))
            else:
                rv.force_ref = 1.0
                rv.force_slider = gui.add_slider("load × run's load", 0.0, 3.0, 0.01, 1.0)
            name, e0 = m.modulus_name, m.modulus0
            if name == "E":
                lu = rv.run.display_unit
                if lu == "consistent" or fu == "consistent":
                    unit, es = "consistent", 1.0
                else:
                    unit, es = f"{fu}/{lu}²", fs / rv.run.display_scale ** 2
                rv.modulus_ref = e0 / es
                rv.modulus_slider = gui.add_slider(f"Young's modulus E [{unit}]", float(0.2 * rv.modulus_ref),
                                                   float(5 * rv.modulus_ref), float(rv.modulus_ref / 100),
                                                   float(rv.modulus_ref), disabled=not m.modulus_ok)
            else:
                rv.modulus_ref = 1.0
                rv.modulus_slider = gui.add_slider("moduli × run's", 0.2, 5.0, 0.01, 1.0, disabled=not m.modulus_ok)
        rv.force_slider.on_update(lambda _: self._queue(rv))
        rv.modulus_slider.on_update(lambda _: self._queue(rv))

    def _queue(self, rv: _RunView) -> None:
        if self._syncing:
            return
        with self._wake:
            self._pending[rv.i] = (float(rv.force_slider.value) / rv.force_ref,
                                   float(rv.modulus_slider.value) / rv.modulus_ref)
            self._wake.notify_all()

    def set_live(self, run: int, force_scale: float = 1.0, modulus_scale: float = 1.0, timeout: float = 60.0):
        """Request a live state (scales of the run's loads and moduli) and wait for its result
        (a :class:`~graspdef.viewer.live.LiveResult`, or None on time-out)."""
        rv = self.views[run]
        t0 = time.perf_counter()
        while rv.live is None and rv.live_error is None and time.perf_counter() - t0 < timeout:
            time.sleep(0.05)
        if rv.live is None:
            return None
        rv.last_result = None
        self._syncing = True
        try:                                             # show the request on the sliders too
            rv.force_slider.value = float(np.clip(force_scale * rv.force_ref, rv.force_slider.min, rv.force_slider.max))
            rv.modulus_slider.value = float(np.clip(modulus_scale * rv.modulus_ref, rv.modulus_slider.min,
                                                    rv.modulus_slider.max))
        finally:
            self._syncing = False
        with self._wake:
            self._pending[run] = (force_scale, modulus_scale)
            self._wake.notify_all()
        while getattr(rv, "last_result", None) is None and time.perf_counter() - t0 < timeout:
            time.sleep(0.02)
        return rv.last_result

    def wait_ready(self, timeout: float = 120.0) -> bool:
        """Wait until every run's live model (and re-solved path) is ready or failed."""
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < timeout:
            if all(rv.live is not None or rv.live_error is not None for rv in self.views) and \
                    all(getattr(rv, "path_ready", True) for rv in self.views):
                return True
            time.sleep(0.05)
        return False

    def _work(self) -> None:
        from .live import Aborted, LiveModel

        for rv in self.views:
            rv.path_ready = rv.run.analysis != "nonlinear" or rv.run.path_u is not None
        for rv in self.views:
            if self._stop.is_set():
                return
            try:
                m = LiveModel(rv.run, self.backend)
            except Exception as exc:                   # noqa: BLE001 - reported in the panel
                rv.live_error = f"live re-solves off: {exc}"
                rv.live_status.content = f"*{rv.live_error}*"
                rv.path_ready = True
                continue
            if m.nonlinear:
                try:
                    self._prepare_path(rv, m)
                except Aborted:
                    m.close()
                    return
                except Exception as exc:               # noqa: BLE001
                    rv.live_error = f"live re-solves off: the load path could not be re-solved ({exc})"
                    rv.live_status.content = f"*{rv.live_error}*"
                    rv.path_ready = True
                    m.close()
                    continue
            self._add_live_gui(rv, m)
            rv.live = m                                  # last: the sliders exist now
            rv.live_status.content = (f"ready (set-up {m.seconds_setup:.2f} s). " +
                                      ("Linear: the sliders scale the kept solution exactly." if not m.nonlinear else
                                       "Nonlinear: Newton steps from the current state; only converged states are "
                                       "shown.") + ("" if m.modulus_ok else " Modulus slider off (prescribed "
                                                    "displacements or enclosed gas)."))
        while not self._stop.is_set():
            with self._wake:
                while not self._pending and not self._stop.is_set():
                    self._wake.wait(0.5)
                if self._stop.is_set():
                    return
                i, (fs, ms) = next(iter(self._pending.items()))
                del self._pending[i]
            rv = self.views[i]
            try:
                res = rv.live.request(fs, ms)
            except Exception as exc:                    # noqa: BLE001
                from .live import LiveResult
                res = LiveResult(False, None, fs, ms, None, 0.0, f"re-solve failed: {exc}")
            if res.converged:
                with self._lock:
                    rv.disp = res.displacements
                    rv.source = f"live: load × {fs:.3g}, modulus × {ms:.3g}"
                    rv.redraw()
                    rv._update_info()
                    if rv.n_path and rv.live.nonlinear and rv.run.path_table.probes:
                        name = next(iter(rv.run.path_table.probes))
                        p = rv.run.path_table.probes[name]
                        comp = int(np.argmax(np.ptp(p, axis=0)))
                        pt = self.views[i].live.problem.probes.get(name)
                        if pt is not None:
                            st, w = rv.live.problem.evaluator.values(pt.face, np.asarray(pt.bary))
                            up = w @ rv.live.u.reshape(-1, 3)[st]
                            rv._update_chart((float(up[comp] / rv.run.display_scale), float(res.load_factor)))
                rv.live_status.content = f"**converged** in {res.seconds:.2f} s — {res.message}"
            else:
                rv.live_status.content = f"**not converged** ({res.seconds:.2f} s): {res.message}"
            rv.last_result = res

    def _prepare_path(self, rv: _RunView, m) -> None:
        run = rv.run
        if run.path_u is None:
            rv.live_status.content = "*re-solving the load path (path_u.npz absent)…*"
            want = run.path_table.load_factors
            sol = m.solve_path(self._stop.is_set, want)
            lf = sol.load_factors()
            near = np.array([int(np.argmin(np.abs(lf - w))) for w in want])
            exact = np.allclose(lf[near], want, rtol=1e-6, atol=1e-12)
            run.path_u = (np.stack([sol.path[j].u for j in near]), lf[near], m.L)
            if not exact:
                run.notes.append("the re-solved load path does not land on every point of path.csv: each "
                                 "slider step shows the nearest re-solved point (its load factor is shown)")
            rv.path_exact = exact
            rv.vmax = max([rv.vmax] + [float(np.linalg.norm(m.L @ sol.path[j].u, axis=1).max()) for j in near])
            m.start_from(sol.u, sol.load_factor)
        else:
            u, lf, _ = run.path_u
            m.start_from(u[-1], lf[-1])
        rv.path_ready = True
        if rv.step is not None and run.path_u is not None:
            self._on_step(rv)


def view(run_dirs, host: str = "127.0.0.1", port: int = 8080, block: bool = True, *, score_dirs=None,
         live: bool = True, backend: str = "auto") -> Viewer:
    """Serve a viser page for one or more run folders on ``host:port`` (127.0.0.1 by default).

    Parameters
    ----------
    run_dirs : path or list of paths
        Run folders written by ``graspdef solve`` (shown side by side).
    host, port : where to listen (port 0: any free port; see ``Viewer.port``).
    block : wait until Ctrl-C, then stop (the returned viewer is stopped); False returns at once
        with the page running (call ``.stop()`` or use it as a context manager).
    score_dirs : optional ``graspdef score`` folders, one per run (None: looked up in the run).
    live : prepare live re-solves (force and modulus sliders) in the background.

    Raises
    ------
    RunFolderError  for a missing, incomplete or inconsistent run folder (nothing started);
    ViewerError     for a port in use or a host that cannot be bound.
    """
    v = Viewer(run_dirs, host, port, score_dirs=score_dirs, live=live, backend=backend)
    if block:
        try:
            v.wait()
        finally:
            v.stop()
    return v
