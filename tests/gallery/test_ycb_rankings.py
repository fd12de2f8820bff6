"""Gallery: rankings of hollow YCB objects (scripts/gallery/ycb_hollow_rankings.py), fast mode,
the soup can only.  No ranking is published; the assertions are invariants: the best candidate
holds, the work of the best is the least among the held ones, and the can's map is stiffer at its
rims than at mid-height.  Slow: it builds the object folder from the scan (remeshing, CoACD) and
ranks it."""
import json

import numpy as np
import pytest


@pytest.mark.slow
def test_soup_can_ranking(run_fast, tmp_path):
    rec = run_fast("ycb_hollow_rankings", "--only", "soup_can")
    row = rec["rows"][0]
    assert row["object"] == "soup_can" and row["held"] > 0
    from graspdef.runs.ranking import read_ranking

    r = read_ranking(tmp_path / "soup_can_rank")
    t = r.table
    assert t["held"][0] == 1 and t["work_J"][0] == t["work_J"][t["held"] == 1].min()
    z = r.vertices[:, 2]
    mid, h = 0.5 * (z.min() + z.max()), np.ptp(z)
    side = np.hypot(r.vertices[:, 0] - r.vertices[:, 0].mean(), r.vertices[:, 1] - r.vertices[:, 1].mean())
    wall = side > 0.9 * side.max()
    c = r.compliance
    assert np.nanmedian(c[wall & (np.abs(z - mid) < 0.1 * h)]) > np.nanmedian(c[wall & (np.abs(z - mid) > 0.4 * h)])
    json.dumps(rec)
