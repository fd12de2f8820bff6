"""``graspdef grasp SCENE --force F [--contact point|geometric] [--friction MU] [--analysis ...] --out DIR``."""
from __future__ import annotations

import argparse

from ._common import progress, warn

DESCRIPTION = ("Close the scene's gripper to the force per finger, settle, map the contacts onto the object's shell "
               "and solve; writes a run folder.")


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("scene", help="scene.xml, its folder, or a name under scenes/ (e.g. tennis_ball)")
    ap.add_argument("--force", required=True, help="squeezing force per finger, e.g. 21.48 or 21.48N (a plain number "
                    "is in N)")
    ap.add_argument("--contact", choices=["point", "geometric"], default="point",
                    help="point loads (the paper's model) or geometric: the fingertips as rigid, force-controlled, "
                         "penetration-free obstacles (contact area grows with the load)")
    ap.add_argument("--analysis", choices=["linear", "nonlinear"], default="nonlinear")
    ap.add_argument("--fingertips", choices=["pin", "pad"],
                    help="the scene folder's gripper variant: pin (scene.xml) or pad (scene_pad.xml, rubber pads); "
                         "default: the scene given")
    ap.add_argument("--pad-size", help="this run's pad edge, e.g. 30mm (pad fingertips; the scene's: 24 mm)")
    ap.add_argument("--tip-material", choices=["rubber", "steel"],
                    help="this run's fingertip material: its friction and contact stiffness "
                         "(the scene's: steel pins, rubber pads)")
    ap.add_argument("--friction", type=float, metavar="MU",
                    help="Coulomb friction coefficient of fingertips and object, one value for both sides: MuJoCo's "
                         "contacts and, with --contact geometric, the fingertips' friction on the shell (0: "
                         "frictionless on both sides: a free object then slips out of MuJoCo's grasp); default: the scene's (MuJoCo's mix of the finger's and the "
                         "object's geom friction, the larger)")
    ap.add_argument("--gas", choices=["auto", "on", "off"], default="auto",
                    help="enclosed air: auto = object.toml's [gas] (nonlinear only), on (object.toml's [gas] p0; "
                         "an error if it has none), off")
    ap.add_argument("--model", choices=["full", "patch"], default="full",
                    help="full: the whole object's shell (default); patch: the paper's model (Tian & Jia 2010, "
                         "Sec. IX-A): per finger contact a square patch of the surface, border clamped, point load, "
                         "nu = 0.5, no air")
    ap.add_argument("--patch-size", default="45mm",
                    help="the patch model's square side, e.g. 45mm (the paper's; default)")
    ap.add_argument("--E-MPa", dest="E_MPa", type=float,
                    help="override the Young's modulus of object.toml's material law [MPa]")
    ap.add_argument("--out", required=True, help="run folder to write (replaced if it exists)")


class _Progress:
    """The chain's progress on stderr: its stages, and during the load path one line per converged
    point (load fraction, Newton iterations, elapsed time), rewritten in place on a terminal."""

    STAGES = {"shell": "building the shell from the object's data", "mujoco": "closing the gripper in MuJoCo",
              "solve": "solving the shell"}

    def __init__(self, args: argparse.Namespace):
        import sys
        import time

        self.args, self.t0, self.tty = args, time.perf_counter(), sys.stderr.isatty()
        self._open = False

    def __call__(self, stage: str, info: dict | None = None) -> None:
        import sys
        import time

        if getattr(self.args, "quiet", False):
            return
        t = time.perf_counter() - self.t0
        if stage != "point":
            self._end()
            progress(self.args, f"{self.STAGES.get(stage, stage)} (t = {t:.1f} s)")
            return
        bar = "#" * int(20 * min(max(info["load_factor"], 0.0), 1.0))
        line = (f"[graspdef]   [{bar:<20}] load {100 * info['load_factor']:5.1f} %, {info['iterations']} Newton "
                f"iterations, {t:.1f} s")
        if self.tty:
            print("\r" + line, end="", file=sys.stderr, flush=True)
            self._open = True
        else:
            print(line, file=sys.stderr, flush=True)

    def _end(self) -> None:
        import sys

        if self._open:
            print(file=sys.stderr, flush=True)
            self._open = False


def run(a: argparse.Namespace) -> int:
    """Run the chain for parsed arguments; prints two lines (the result, the run folder)."""
    from ..pipeline.grasp import run_grasp
    from ..runs.folder import check_output_folder

    check_output_folder(a.out)                    # before MuJoCo and the solve, not after

    gas = {"auto": None, "on": True, "off": False}[a.gas]
    from ..units import quantity

    force = quantity(a.force, "force", implied="N", what="--force")
    E = None if getattr(a, "E_MPa", None) is None else quantity(a.E_MPa, "pressure", implied="MPa", what="--E-MPa")
    bar = _Progress(a)
    scene = a.scene
    if getattr(a, "fingertips", None):
        from ..objects import scene_xml

        scene = scene_xml(a.scene, a.fingertips)
    tips = None
    if getattr(a, "pad_size", None) is not None or getattr(a, "tip_material", None) is not None:
        from ..sim.gripper import FingertipChange

        tips = FingertipChange(None if a.pad_size is None else quantity(a.pad_size, "length", what="--pad-size"),
                               a.tip_material)
    model = getattr(a, "model", "full")
    patch_size = 0.045
    if model == "patch":
        patch_size = quantity(getattr(a, "patch_size", "45mm"), "length", what="--patch-size")
    run = run_grasp(scene, force, a.contact, a.analysis, a.out, gas=gas, E=E, progress=bar, fingertips=tips,
                    friction=getattr(a, "friction", None), model=model, patch_size=patch_size)
    bar._end()                                           # close an open progress line before the summary
    r = run.result
    d = r["derived"]
    ind = d.get("indentation_per_finger", d.get("indentation"))
    conv = r["convergence"]
    stop = "" if conv["completed"] else f" (path stopped at load factor {conv.get('load_factor', 0):.3g})"
    model = "point loads" if r["contact"] == "point" else "geometric contact"
    if r.get("model") == "patch":
        model = f"patch model ({r['patch_size_m'] * 1e3:g} mm, border clamped, nu = 0.5, no air)"
    area = f", {d['contact_area']['label']} {d['contact_area']['value'] * 1e6:.1f} mm^2" if "contact_area" in d else ""
    print(f"{r['object']}: {r['analysis']} shell, {model}, {r['force_N']:g} N per finger: {ind['label']} "
          f"{ind['value'] * 1e3:.2f} mm, "
          f"{d['max_displacement']['label']} {d['max_displacement']['value'] * 1e3:.2f} mm{area}{stop}; "
          f"{r['timings_s']['total']:.1f} s")
    print(f"run folder: {run.out}")
    for w in r.get("warnings", []):
        warn(w)
    if not conv["completed"]:
        # the summary's figures are those of the last equilibrium: say how much of the force that is, and why
        lf = float(conv.get("load_factor", 0.0))
        warn(f"the results are at load factor {lf:.3g} of the {r['force_N']:g} N per finger asked "
             f"({lf * r['force_N']:.3g} N): {conv.get('stop_reason') or 'the path stopped (no reason recorded)'}")
    progress(a, f"look at it: graspdef report {run.out}, or graspdef view {run.out}")
    return 0
