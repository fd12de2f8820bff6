"""The README's Python example runs and prints the number it states."""
import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_example_runs_and_matches_its_comment():
    text = README.read_text()
    code = text.split("```python\n")[1].split("```")[0]
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    stated = re.search(r"# ([0-9.]+) mm\n", code).group(1)
    assert f"{stated} mm" in out
