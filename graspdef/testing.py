"""Verification helpers shared by graspdef's tests and usable by anyone extending it (numpy; the
browser helper imports selenium when called)."""
from __future__ import annotations

import numpy as np

#: An FD error below this fraction of the derivative's magnitude is indistinguishable from the
#: round-off of the difference quotient (eps / h ~ 1e-13 for h ~ 1e-3) plus the O(h^4) term;
#: above it the O(h^2) truncation error of a central difference dominates and must drop by a
#: factor 4 when h halves.
FD_FLOOR = 1e-7


def assert_fd_rate(exact, fd_h, fd_h2, scale=None, floor=FD_FLOOR, what="derivative"):
    """Central differences at steps h and h/2 against an analytic derivative.

    Every entry either agrees to ``floor * scale`` at h/2, or its error drops by a factor in
    (3, 5) when h is halved (O(h^2) truncation of a central difference: factor 4).  A wrong
    derivative leaves an h-independent error (factor ~1) and fails.  Returns the largest
    relative error at h/2 and the number of entries that went through the ratio test."""
    exact = np.asarray(exact, float)
    e1 = np.abs(np.asarray(fd_h) - exact)
    e2 = np.abs(np.asarray(fd_h2) - exact)
    if scale is None:
        scale = max(np.abs(exact).max(), 1e-300)
    small = e2 <= floor * scale
    ratio = e1[~small] / e2[~small]
    bad = (ratio < 3.0) | (ratio > 5.0)
    assert not bad.any(), (
        f"{what}: {bad.sum()} of {ratio.size} entries above the round-off floor do not converge "
        f"at O(h^2): ratios {np.sort(ratio[bad])[:8]}, errors {np.sort(e2[~small][bad])[-4:]} "
        f"(scale {scale:.3e})")
    return e2.max() / scale, int(ratio.size)


#: Debian chromium's flags for headless screenshots (../shared/MEASURED.md, viser)
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--no-first-run"]


def headless_chromium(profile_dir, window: str = "1200,800"):
    """A selenium driver of Debian's headless chromium (profile in ``profile_dir``), for the
    browser acceptance tests and the screenshot scripts.  A missing browser is a set-up error
    (AssertionError naming the packages), not a skip: ``make test`` installs them."""
    import shutil

    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    chromedriver = shutil.which("chromedriver")
    assert chromium and chromedriver, ("Debian's chromium and chromium-driver are missing: run 'make test' as root "
                                       "(it apt-installs them) or 'apt-get install chromium chromium-driver'")
    opts = Options()
    opts.binary_location = chromium
    for f in CHROMIUM_FLAGS + [f"--window-size={window}", f"--user-data-dir={profile_dir}"]:
        opts.add_argument(f)
    driver = webdriver.Chrome(options=opts, service=Service(chromedriver))
    driver.set_page_load_timeout(60)
    return driver


# ---- small problem files the tests share (one text each, not a copy per test module) -------------
POINT_LOAD = 'kind = "point"\nat = [0.0, 0.0, 0.0]\nforce = [0.0, 0.0, -1.0]'


def plate_problem(name: str = "small_plate", n: int = 4, load: str = POINT_LOAD, probe: bool = True) -> str:
    """Problem-file text: a 100 mm square plate (mm, N; E = 1000 N/mm^2, nu = 0.3, t = 1 mm),
    simply supported, ``n`` x ``n`` cells, one load table (default: 1 N down at the centre) and a
    probe "centre"."""
    text = (f'\nname = "{name}"\n[units]\nlength = "mm"\nforce = "N"\n[geometry]\ntype = "rectangle"\n'
            f"lx = 100.0\nly = 100.0\nnx = {n}\nny = {n}\n[material]\nE = 1000.0\nnu = 0.3\n[shell]\n"
            'thickness = 1.0\n[regions]\nedges = "abs(abs(x) - 50) < 1e-6 or abs(abs(y) - 50) < 1e-6"\n'
            '[[supports]]\nkind = "simply_supported"\nregion = "edges"\n'
            f"[[loads]]\n{load}\n")
    return text + ('[[probes]]\nname = "centre"\nat = [0.0, 0.0, 0.0]\n' if probe else "")


def cantilever_problem(name: str = "cantilever_small", nx: int = 10, force: float = 1.0, steps: int = 4,
                       units: str = "consistent", length: float = 10.0, width: float = 1.0, E: float = 1.2e6,
                       thickness: float = 0.1) -> str:
    """Problem-file text: a Saint Venant-Kirchhoff cantilever strip (nu = 0) clamped at x = 0,
    an edge load ``force`` (total, +z) at the tip, probe "tip", a load-controlled nonlinear path of
    ``steps`` steps; ``units`` "consistent" or "mm" (then forces in N)."""
    force_unit = "consistent" if units == "consistent" else "N"
    return (f'\nname = "{name}"\n[units]\nlength = "{units}"\nforce = "{force_unit}"\n[geometry]\n'
            f'type = "rectangle"\nlx = {length!r}\nly = {width!r}\nnx = {nx}\nny = 2\n'
            f"center = [{length / 2!r}, {width / 2!r}]\n"
            f'[material]\nmodel = "saint_venant_kirchhoff"\nE = {E!r}\nnu = 0.0\n[shell]\nthickness = {thickness!r}\n'
            f'[regions]\nroot = "abs(x) < 1e-9"\ntip = "abs(x - {length!r}) < 1e-9"\n'
            '[[supports]]\nkind = "clamped"\nregion = "root"\n'
            f'[[loads]]\nkind = "edge_load"\nregion = "tip"\nforce = [0.0, 0.0, {force!r}]\n'
            f'[[probes]]\nname = "tip"\nat = [{length!r}, {width / 2!r}, 0.0]\n'
            f'[solver]\ntype = "nonlinear"\nmethod = "load"\nsteps = {steps}\n')
