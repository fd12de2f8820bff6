"""The viser page of a ranking folder (``graspdef rank --out DIR``; docs/ranking-folder.md).

Left: the limit surface coloured by the compliance map (log scale, mm/N; grey where no pinch
fits), with the best candidates as line segments from the first to the second contact, coloured
by rank (green best, red worst; at most ``top`` drawn, the GUI says how many of how many).
The contacts are dots on the surface too (the segments run through the object: the surface can be
drawn translucent or hidden).  Right: the deformed shape (rest + magnification x displacement) of
one of the candidates stored in shapes.npz, picked in a dropdown by rank, coloured by |u| (mm), with
two arrows for the fingers (ending where the nearest vertex moved), and that row's figures.

Everything shown comes from :func:`graspdef.runs.ranking.read_ranking` as written: ranks, flags
and figures are the table's, never recomputed here.  viser is imported when a viewer starts.
"""
from __future__ import annotations

import threading
from os import PathLike

import numpy as np

from ..runs.ranking import Ranking, read_ranking
from . import layers
from .server import ServerPage, ViewerError, open_server

#: how many candidates are drawn as segments by default (the best ones)
DEFAULT_TOP = 200
#: how the limit surface is drawn: coloured by the compliance map, translucent grey (the segments
#: inside the object show), or not at all
SURFACE_MODES = ("compliance map", "translucent", "hidden")
#: gap between the compliance map and the deformed shape [display units; the object is ~1]
GAP = 0.45
MM = 1e3


def _candidate_label(rank: int, candidate: int) -> str:
    return f"rank {rank} · candidate {candidate}"


def _force_text(rec: dict) -> str:
    """The ranking's force: one force, or the range (each candidate at its least holding force)."""
    fr = rec.get("force_range_N")
    if fr:
        return f"{fr[0]:g}-{fr[1]:g} N (each candidate at its least holding force)"
    return f"{rec.get('force_N', float('nan')):g} N"


def row_markdown(row: dict) -> str:
    """A table row's figures as markdown, in display units (mm, mJ, N/mm, %, deg)."""
    def f(v, scale=1.0, digits=4):
        return "–" if v is None or not np.isfinite(v) else f"{v * scale:.{digits}g}"

    yes = {1: "yes", 0: "no"}
    lines = [f"**rank {row['rank']}** (rigid baseline: rank {row['rigid_rank']}) · candidate {row['candidate']}",
             "", "| | |", "|---|---|",
             f"| opening (width) | {f(row['width_m'], MM)} mm |",
             f"| force per finger | {f(row.get('force_N'))} N |",
             f"| indentation per finger | {f(row['indentation_per_finger_m'], MM)} mm |",
             f"| closing | {f(row['closing_m'], MM)} mm |",
             f"| work | {f(row['work_J'], MM)} mJ |",
             f"| grasp stiffness | {f(row['grasp_stiffness_N_per_m'], 1e-3)} N/mm |",
             f"| max displacement | {f(row['max_displacement_m'], MM)} mm |",
             f"| peak strain | {f(row['peak_strain'], 100)} % |",
             f"| peak von Mises | {f(row['peak_von_mises_Pa'], 1e-6)} MPa |",
             f"| strain limit ratio | {f(row['strain_limit_ratio'])} |",
             f"| contact area per finger | {f(row['contact_area_m2'], 1e6)} mm² |",
             f"| friction margin, rigid | {f(row['friction_margin_deg'])} ° |",
             f"| friction margin, deformed | {f(row['deformed_friction_margin_deg'])} ° |",
             f"| weight torque ratio | {f(row['weight_torque_ratio'])} |",
             f"| weight slip ratio | {f(row['weight_slip_ratio'])} |",
             f"| held | {yes.get(row['held'], row['held'])} |",
             f"| on the Pareto front | {yes.get(row['pareto'], row['pareto'])} |"]
    return "\n".join(lines)


class RankingViewer(ServerPage):
    """A running viser page for one ranking folder; ``stop()`` (or leaving the ``with`` block)
    shuts it down.  ``show_candidate(candidate)`` does what the dropdown does."""

    def __init__(self, folder: str | PathLike, host: str = "127.0.0.1", port: int = 8080, *,
                 top: int = DEFAULT_TOP):
        self.ranking: Ranking = read_ranking(folder)
        if top < 1:
            raise ViewerError(f"--top must be at least 1, got {top}")
        self.top = int(top)
        self.host = host
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._stopped = False
        self.server, self.port = open_server(host, port)
        try:
            self._build()
        except BaseException:
            self._stop_server()
            raise

    # ---- life cycle ------------------------------------------------------------------------------

    @property
    def runs(self) -> list:
        """What the page shows (one ranking), for the command line's progress line."""
        return [self.ranking]

    # ---- coordinates -------------------------------------------------------------------------------
    def to_display(self, x: np.ndarray, offset: np.ndarray | None = None) -> np.ndarray:
        """Display coordinates (float32) of points [m]: centred, about one unit across, shifted by
        ``offset`` (the deformed shape's panel sits right of the compliance map)."""
        off = np.zeros(3) if offset is None else offset
        return ((np.asarray(x, float) - self.centre) / self.lref + off).astype(np.float32)

    # ---- building ----------------------------------------------------------------------------------
    def _build(self) -> None:
        r, server = self.ranking, self.server
        gui, scene = server.gui, server.scene
        self.centre, self.lref = layers.display_frame(r.vertices)
        lo = (r.vertices - self.centre).min(0) / self.lref
        hi = (r.vertices - self.centre).max(0) / self.lref
        self.offset = np.array([hi[0] - lo[0] + GAP, 0.0, 0.0])          # the deformed shape's panel
        server.gui.configure_theme(control_width="large")
        scene.set_up_direction("+z")

        # the compliance map
        comp_mm = r.compliance * MM                                    # [mm/N]
        finite = comp_mm[np.isfinite(comp_mm) & (comp_mm > 0)]
        self.compliance_range = ((float(finite.min()), float(finite.max())) if finite.size else (1.0, 10.0))
        if not self.compliance_range[1] > self.compliance_range[0]:
            c = self.compliance_range[0]
            self.compliance_range = (c / 1.5, c * 1.5)
        self.surface_colours = layers.log_colormap(comp_mm, *self.compliance_range)
        self.surface_vertices = self.to_display(r.vertices)
        self.surface_handle = self._mesh("/ranking/compliance", self.surface_vertices, self.surface_colours)

        # the candidates: the best `top` as segments, coloured by rank (the table's order)
        first, second = r.contacts()
        self.n_drawn = min(self.top, r.n)
        seg = layers.segments(self.to_display(first[: self.n_drawn]), self.to_display(second[: self.n_drawn]))
        self.segment_colours = layers.rank_colours(self.n_drawn)
        self.segments_handle = scene.add_line_segments(
            "/ranking/candidates", seg.astype(np.float32), np.repeat(self.segment_colours[:, None, :], 2, axis=1),
            thickness=0.004)
        self.drawn_ranks = r.table["rank"][: self.n_drawn].copy()
        # the contacts as dots: on the surface, so seen through the opaque map (the segments run inside)
        dots = np.concatenate([seg[:, 0], seg[:, 1]]).astype(np.float32)
        self.contacts_handle = scene.add_point_cloud("/ranking/contacts", dots,
                                                     np.concatenate([self.segment_colours] * 2),
                                                     point_size=0.018, point_shape="circle")
        self.translucent_handle = scene.add_mesh_simple("/ranking/translucent", self.surface_vertices, r.faces,
                                                        color=(170, 170, 170), opacity=0.3, side="double",
                                                        visible=False)

        lo_d, hi_d = self.surface_vertices.min(0), self.surface_vertices.max(0)
        scene.add_label("/ranking/title_map", "compliance map, candidates", anchor="top-center",
                        position=(float(0.5 * (lo_d[0] + hi_d[0])), float(lo_d[1] - 0.15), float(lo_d[2])))
        gui.add_markdown(self._header_markdown())
        gui.add_html(layers.log_legend_html("compliance (pinch through a vertex)", "mm/N", *self.compliance_range,
                                            nan_label="grey: no pinch fits (NaN)"))
        drawn_text = (f"all {r.n} candidates" if self.n_drawn == r.n else
                      f"the best {self.n_drawn} of {r.n} candidates")
        self.segments_note = gui.add_markdown(
            f"Segments: {drawn_text}, first → second contact (dots: the contacts), coloured by rank "
            f"(green: rank 1 … red: rank {int(self.drawn_ranks[-1]) if self.n_drawn else 0}). The segments run "
            "through the object: surface 'translucent' shows them.")
        gui.add_html(layers.legend_html("rank", "1 = best", 1.0, float(max(self.n_drawn, 1)), layers.RANKS))
        self.segments_check = gui.add_checkbox("show candidates", True)
        self.segments_check.on_update(lambda _: self._segments_visibility())
        self.surface_dropdown = gui.add_dropdown("surface", SURFACE_MODES, initial_value=SURFACE_MODES[0],
                                                 hint="the segments run through the object: 'translucent' shows them")
        self.surface_dropdown.on_update(lambda _: self._surface_mode())

        # the stored shapes, by rank
        rank_of = {int(c): int(k) for c, k in zip(r.table["candidate"], r.table["rank"])}
        stored = sorted((rank_of[int(c)], int(c)) for c in r.shape_candidates)
        self.stored = stored                                            # (rank, candidate), best first
        self._option_of = {cand: _candidate_label(rk, cand) for rk, cand in stored}
        self._candidate_of = {v: k for k, v in self._option_of.items()}
        self._row_of = {int(c): i for i, c in enumerate(r.table["candidate"])}
        with gui.add_folder("deformed shape of a stored candidate"):
            if stored:
                self.pick_dropdown = gui.add_dropdown(f"candidate ({len(stored)} stored)",
                                                      tuple(self._option_of[c] for _, c in stored),
                                                      initial_value=self._option_of[stored[0][1]])
                self.magnification = gui.add_slider("displacement magnification", 0.0, 50.0, 0.5, 1.0)
                self.displacement_legend = gui.add_html("")
                self.row_panel = gui.add_markdown("")
            else:
                self.pick_dropdown = self.magnification = None
                self.row_panel = gui.add_markdown("*shapes.npz holds no candidate: no deformed shape to show*")
        self.candidate: int | None = None
        self.displayed: np.ndarray | None = None                      # deformed shape's display coordinates
        if stored:
            self.pick_dropdown.on_update(lambda _: self._on_pick())
            self.magnification.on_update(lambda _: self._redraw_shape())
            self.show_candidate(stored[0][1])

        width = self.offset[0] + (hi[0] - lo[0])
        d = 0.55 + 0.45 * width
        cx = (width + lo[0]) / 2 + 0.3 * d
        server.initial_camera.look_at = (cx, 0.0, 0.0)
        server.initial_camera.position = (cx + 0.35 * d, -1.2 * d, 0.85 * d)
        server.initial_camera.up = (0.0, 0.0, 1.0)

    def _mesh(self, name: str, verts: np.ndarray, colours: np.ndarray):
        import trimesh

        mesh = trimesh.Trimesh(verts, self.ranking.faces,
                               vertex_colors=np.c_[colours, np.full(len(colours), 255, np.uint8)], process=False)
        return self.server.scene.add_mesh_trimesh(name, mesh)

    def _header_markdown(self) -> str:
        r = self.ranking
        rec = r.record
        mat = rec.get("material") or {}
        bits = [f"**graspdef ranking** `{r.folder.name}`",
                f"object **{rec.get('object', '?')}**, {_force_text(rec)} per finger, "
                f"friction {rec.get('friction', float('nan')):g}, {r.n} candidates"]
        if isinstance(mat, dict) and "E_Pa" in mat:
            bits.append(f"{mat.get('model', '')} E = {mat['E_Pa'] / 1e6:.4g} MPa, ν = {mat.get('nu', '?')}, "
                        f"t = {rec.get('thickness_m', float('nan')) * MM:.3g} mm")
        if rec.get("ranking"):
            bits.append(f"criterion: {rec['ranking']}")
        return "\n\n".join(bits)

    def _segments_visibility(self) -> None:
        self.segments_handle.visible = self.contacts_handle.visible = bool(self.segments_check.value)

    def _surface_mode(self) -> None:
        mode = self.surface_dropdown.value
        self.surface_handle.visible = mode == "compliance map"
        self.translucent_handle.visible = mode == "translucent"

    # ---- picking a stored candidate ----------------------------------------------------------------
    def _on_pick(self) -> None:
        cand = self._candidate_of.get(self.pick_dropdown.value)
        if cand is not None and cand != self.candidate:
            self.show_candidate(cand)

    def show_candidate(self, candidate: int) -> str:
        """Show the deformed shape of a stored ``candidate`` (its number, as in ranking.csv) and its
        row's figures; what picking it in the dropdown does.  Returns the panel's text."""
        candidate = int(candidate)
        if candidate not in self._option_of:
            raise ViewerError(f"candidate {candidate} has no stored shape (shapes.npz holds "
                              f"{', '.join(str(c) for _, c in self.stored) or 'none'})")
        with self._lock:
            if self._stopped:
                return ""
            self.candidate = candidate
            if self.pick_dropdown.value != self._option_of[candidate]:
                self.pick_dropdown.value = self._option_of[candidate]   # its callback sees no change
            self.row = self.ranking.row(self._row_of[candidate])
            self.row_panel.content = row_markdown(self.row)
            self._redraw_shape()
        return self.row_panel.content

    def set_magnification(self, factor: float) -> None:
        """What moving the magnification slider does (its callback redraws the shape)."""
        self.magnification.value = float(factor)

    def _redraw_shape(self) -> None:
        with self._lock:
            if self._stopped or self.candidate is None:
                return
            r = self.ranking
            u = r.displacement_of(self.candidate)                     # (n, 3) [m]
            mag = float(self.magnification.value)
            mags = np.linalg.norm(u, axis=1) * MM                     # [mm], true scale
            vmax = float(mags.max()) if mags.size and mags.max() > 0 else 1.0
            verts = self.to_display(r.vertices + mag * u, self.offset)
            self.shape_handle = self._mesh("/ranking/deformed", verts, layers.colormap(mags, 0.0, vmax))
            i = self._row_of[self.candidate]
            first, second = r.contacts()
            ends = np.stack([first[i], second[i]])                    # [m]
            near = np.argmin(np.linalg.norm(r.vertices[None] - ends[:, None], axis=2), axis=1)
            tips = self.to_display(ends + mag * u[near], self.offset)  # moved like the nearest vertex
            inward = np.array([second[i] - first[i], first[i] - second[i]])
            self.picked_handle = self.server.scene.add_arrows(
                "/ranking/picked", layers.force_arrows(tips, inward, 0.25).astype(np.float32), (40, 40, 40),
                shaft_radius=0.006, head_radius=0.016, head_length=0.04)
            lo = verts.min(0)
            self.server.scene.add_label(
                "/ranking/title_shape", f"rank {self.row['rank']}: deformed × {mag:g}", anchor="top-center",
                position=(float(0.5 * (lo[0] + verts.max(0)[0])), float(lo[1] - 0.15), float(lo[2])))
            self.displayed = verts
            self.displacement_legend.content = layers.legend_html(
                f"|u| of rank {self.row['rank']} (colours true scale; shape × {mag:g})", "mm", 0.0, vmax)


def view_ranking(folder, host: str = "127.0.0.1", port: int = 8080, block: bool = True, *,
                 top: int = DEFAULT_TOP) -> RankingViewer:
    """Serve a ranking folder on ``host:port`` (127.0.0.1 by default); ``block``: until Ctrl-C."""
    v = RankingViewer(folder, host, port, top=top)
    if block:
        try:
            v.wait()
        finally:
            v.stop()
    return v


__all__ = ["DEFAULT_TOP", "SURFACE_MODES", "RankingViewer", "row_markdown", "view_ranking"]
