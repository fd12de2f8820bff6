"""The gallery scripts (scripts/gallery) are imported by name; each test runs one in --fast mode
into a temporary folder and checks the files it writes and its main number."""
import importlib
import json
import sys
from pathlib import Path

import pytest

GALLERY = Path(__file__).resolve().parents[2] / "scripts" / "gallery"
if str(GALLERY) not in sys.path:
    sys.path.insert(0, str(GALLERY))


@pytest.fixture
def run_fast(tmp_path):
    """run_fast(name) -> the JSON record the script wrote (and checks that it wrote its PNG)."""
    def run(name: str, *extra: str) -> dict:
        mod = importlib.import_module(name)
        mod.main(["--fast", "--out", str(tmp_path), *extra])
        png, js = tmp_path / f"{name}.png", tmp_path / f"{name}.json"
        assert png.is_file() and png.stat().st_size > 10_000, png
        assert js.is_file()
        on_disk = json.loads(js.read_text())
        assert on_disk["fast"] is True and on_disk["key"]
        return on_disk
    return run
