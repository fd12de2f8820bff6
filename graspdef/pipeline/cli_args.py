"""Arguments of ``graspdef grasp`` (kept free of heavy imports: the parser is built at start-up)."""
from __future__ import annotations

import argparse


def add_grasp_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("scene", help="scene.xml, its folder, or a name under scenes/ (e.g. tennis_ball)")
    ap.add_argument("--force", type=float, required=True, help="squeezing force per finger [N]")
    ap.add_argument("--contact", choices=["point", "geometric"], default="point",
                    help="point loads (the paper's model) or geometric: the fingertips as rigid, force-controlled, "
                         "penetration-free obstacles (contact area grows with the load)")
    ap.add_argument("--analysis", choices=["linear", "nonlinear"], default="nonlinear")
    ap.add_argument("--gas", choices=["auto", "on", "off"], default="auto",
                    help="enclosed air: auto = object.toml's [gas] (nonlinear only), on (object.toml's [gas] p0; "
                         "an error if it has none), off")
    ap.add_argument("--E-MPa", dest="E_MPa", type=float,
                    help="override the Young's modulus of object.toml's material law [MPa]")
    ap.add_argument("--out", required=True, help="run folder to write (replaced if it exists)")
