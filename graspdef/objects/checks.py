"""Checks of an object before any heavy work: the thin-shell range of its thickness (the memory
a solve needs is checked by graspdef.shell.memory)."""
from __future__ import annotations

import numpy as np

from ..errors import ProblemError

#: thickness / object size that a Kirchhoff-Love thin shell covers: above 0.2 the object is a thick
#: solid (transverse shear and thickness change matter); below 1e-4 it is a membrane whose bending
#: stiffness -- t^3 -- is lost in round-off (0.004 mm on a 65 mm ball gave a 16 m "indentation")
THIN_SHELL_RANGE = (1e-4, 0.2)
def check_thin_shell(thickness: float, points: np.ndarray, where) -> None:
    """Refuse a thickness outside the thin-shell range relative to the object's size (the largest
    extent of its surface), before any solve."""
    size = float(np.ptp(points, axis=0).max())
    ratio = thickness / size
    lo, hi = THIN_SHELL_RANGE
    if not lo <= ratio <= hi:
        raise ProblemError(f"{where}: thickness {thickness * 1e3:.4g} mm is {ratio:.3g} of the object's size "
                           f"({size * 1e3:.4g} mm); a thin shell needs {lo:g} to {hi:g} of it "
                           f"({lo * size * 1e3:.3g} to {hi * size * 1e3:.3g} mm here): check the units")
