"""Acceptance in a real browser: headless Debian chromium (selenium + chromedriver) loads the
page, the screenshot shows the rendered 3-D scene (pixel content, not a blank canvas), and
moving the load-path slider in the browser changes the mesh (server side and a second screenshot).

Needs the Debian packages chromium and chromium-driver and the selenium package; a missing
browser is a set-up error (graspdef.testing.headless_chromium), not a skip.  Chromium's flags: ../shared/MEASURED.md (viser)."""
from __future__ import annotations

import io
import threading
import time

import numpy as np
import pytest

from graspdef.testing import headless_chromium
from graspdef.viewer.layers import VIRIDIS
from graspdef.viewer.server import Viewer


@pytest.fixture
def browser(tmp_path):
    """Debian's headless chromium (a missing browser is a set-up error, not a skip)."""
    driver = headless_chromium(tmp_path / "profile", window="1200,800")
    yield driver
    driver.quit()


def _canvas_pixels(driver) -> np.ndarray:
    from PIL import Image
    from selenium.webdriver.common.by import By

    canvas = max(driver.find_elements(By.TAG_NAME, "canvas"), key=lambda c: c.size["width"] * c.size["height"])
    return np.asarray(Image.open(io.BytesIO(canvas.screenshot_as_png)).convert("RGB")).astype(int)


def _mesh_pixels(img: np.ndarray) -> np.ndarray:
    """Mask of pixels in the colour map's hue range (saturated, not the white/grey background)."""
    sat = img.max(axis=2) - img.min(axis=2)
    near = np.min(np.linalg.norm(img[..., None, :] - VIRIDIS[None, None, :, :], axis=-1), axis=-1)
    return (sat > 40) & (near < 90)


def _wait(pred, timeout: float, what: str) -> None:
    t0 = time.time()
    while not pred():
        if time.time() - t0 > timeout:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.1)


def test_page_renders_and_slider_moves_mesh(browser, cantilever_run, tmp_path):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    before = {t for t in threading.enumerate()}
    with Viewer([cantilever_run], port=0, live=False) as v:
        rv = v.views[0]
        browser.get(v.url)
        _wait(lambda: len(v.server.get_clients()) >= 1, 60, "the page to connect")
        _wait(lambda: browser.find_elements(By.CSS_SELECTOR, "[role=slider]"), 60, "the GUI")
        time.sleep(3.0)                                        # let WebGL draw a few frames
        img1 = _canvas_pixels(browser)
        browser.save_screenshot(str(tmp_path / "viewer_1.png"))
        h, w, _ = img1.shape
        assert h > 200 and w > 400
        colours = len(np.unique(img1.reshape(-1, 3), axis=0))
        mesh1 = _mesh_pixels(img1)
        assert colours > 50, f"blank canvas? only {colours} colours"
        assert mesh1.sum() > 0.002 * h * w, f"no coloured surface on the canvas ({mesh1.sum()} pixels)"

        # the first slider is run 1's load-path step: move it to 0 from the browser
        slider = browser.find_elements(By.CSS_SELECTOR, "[role=slider]")[0]
        assert slider.get_attribute("aria-valuenow") == str(rv.n_path - 1)
        shown = rv.displayed.copy()
        slider.click()
        slider.send_keys(Keys.HOME)
        rest = rv.to_display(rv.run.rest_vertices)
        _wait(lambda: rv.step == 0 and np.abs(rv.displayed - rest).max() < 1e-6, 30,
              "the server to receive the slider move and show path point 0 (the rest shape)")
        assert slider.get_attribute("aria-valuenow") == "0"
        assert np.abs(rv.displayed - shown).max() > 0.05
        time.sleep(3.0)
        img2 = _canvas_pixels(browser)
        browser.save_screenshot(str(tmp_path / "viewer_2.png"))
        mesh2 = _mesh_pixels(img2)
        changed = (np.abs(img2 - img1).sum(axis=2) > 30) & (mesh1 | mesh2)
        assert changed.sum() > 0.001 * h * w, "the second screenshot shows the same mesh"
        assert mesh2.sum() > 0.001 * h * w                     # the rest shape is still drawn
    deadline = time.time() + 10
    while ({t for t in threading.enumerate()} - before) and time.time() < deadline:
        time.sleep(0.05)
    assert not ({t for t in threading.enumerate()} - before)
