"""The README's gallery table lists exactly the gallery scripts, and each row's published number
appears in the script's source (the script prints it beside its own)."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _rows():
    text = (ROOT / "README.md").read_text()
    sec = text.split("## Gallery (")[1].split("\n## ")[0]
    return [line.split("|")[1:-1] for line in sec.splitlines()
            if line.startswith("| ") and line.split("|")[1].strip().endswith(".py")]


def test_readme_gallery_table_lists_every_gallery_script():
    listed = sorted(r[0].strip() for r in _rows())
    scripts = sorted(p.name for p in (ROOT / "scripts" / "gallery").glob("*.py") if not p.name.startswith("_"))
    assert listed == scripts


def test_readme_gallery_published_numbers_are_the_scripts_references():
    for row in _rows():
        script = (ROOT / "scripts" / "gallery" / row[0].strip()).read_text()
        published = re.findall(r"\d+\.\d+", row[-1])
        assert published, row
        for num in published:
            assert num in script or num.rstrip("0") in script, f"{row[0].strip()}: {num} not in the script"
