"""The thesis's Figures 10-13 (hemisphere, R0/t0 = 10, Mooney-Rivlin gamma = 0.1).

Thin wrapper over the gallery script scripts/gallery/thesis_fig10_13_hemisphere.py (which holds
the code): writes thesis_fig10_13_hemisphere.png (the four figures) and .json (curves, limit
loads beside the thesis's) to --out.

    .venv/bin/python scripts/thesis_figures.py [--out out/thesis] [--ring-angle 30] [--fast]
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "gallery"))
from thesis_fig10_13_hemisphere import main  # noqa: E402

if __name__ == "__main__":
    from graspdef import runtime

    runtime.configure()        # OpenMP wait policy before any solve (graspdef.runtime)
    argv = sys.argv[1:]
    main(argv if any(x.startswith("--out") for x in argv) else ["--out", "out/thesis"] + argv)
