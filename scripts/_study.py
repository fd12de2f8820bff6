"""What the study scripts share: writing a result (JSON) and its figure (PNG) side by side."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Callable


def write_results(out: Path, stem: str, res: dict, plot: Callable[[dict, Path], None]) -> None:
    """``out/stem.json`` (the result, indented) and ``out/stem.png`` (``plot(res, path)``); prints
    where they went and the run's ``total_seconds``."""
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.json").write_text(json.dumps(res, indent=2) + "\n")
    plot(res, out / f"{stem}.png")
    print(f"\nwrote {out / f'{stem}.json'} and {out / f'{stem}.png'} ({res['total_seconds']:.0f} s)")
