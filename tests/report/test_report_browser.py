"""Acceptance in a real browser: headless Debian chromium (selenium + chromedriver) opens the
report file offline; every picture decodes (naturalWidth > 0), the tables are there, and the
screenshot has content (many colours, colour-map hues, not a blank page).  Chromium's flags:
../shared/MEASURED.md, as in tests/viewer/test_browser.py."""
from __future__ import annotations

import io

import numpy as np
import pytest

from graspdef.testing import headless_chromium

@pytest.fixture
def browser(tmp_path):
    """Debian's headless chromium (a missing browser is a set-up error, not a skip)."""
    driver = headless_chromium(tmp_path / "profile", window="1280,2400")
    yield driver
    driver.quit()


def test_report_opens_offline_with_pictures_and_tables(browser, scored_report):
    from PIL import Image
    from selenium.webdriver.common.by import By

    browser.get((scored_report / "report.html").resolve().as_uri())
    assert browser.title.startswith("graspdef report")
    imgs = browser.find_elements(By.TAG_NAME, "img")
    assert len(imgs) == 2
    sizes = browser.execute_script("return Array.from(document.images).map(i => [i.complete, i.naturalWidth, "
                                   "i.naturalHeight])")
    assert all(c and w > 200 and h > 100 for c, w, h in sizes), sizes
    assert browser.find_element(By.ID, "summary-0").is_displayed()
    score_rows = browser.find_elements(By.CSS_SELECTOR, "#score-table tbody tr")
    assert len(score_rows) >= 5 and "rms" in browser.find_element(By.ID, "score-table").text
    # no request left the machine: the page holds everything
    assert browser.execute_script("return performance.getEntriesByType('resource')"
                                  ".filter(r => !r.name.startsWith('data:')).length") == 0
    shot = np.asarray(Image.open(io.BytesIO(browser.get_screenshot_as_png())).convert("RGB")).astype(int)
    assert shot.std() > 20
    colours = {tuple(c) for c in shot.reshape(-1, 3)[::5]}
    assert len(colours) > 300
    sat = shot.max(axis=2) - shot.min(axis=2)
    assert np.mean(sat > 60) > 0.02                 # the colour-mapped surfaces are on screen
    first = imgs[0].screenshot_as_png
    pic = np.asarray(Image.open(io.BytesIO(first)).convert("RGB")).astype(int)
    assert pic.std() > 20 and np.mean((pic.max(axis=2) - pic.min(axis=2)) > 60) > 0.1
