"""A self-contained HTML page: inline CSS, pictures as base64 ``data:`` URIs, no scripts and no
external URL (the page opens offline, can be mailed as one file, and leaks nothing)."""
from __future__ import annotations

import base64
import html as _html
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path

CSS = """
body{font-family:-apple-system,"Segoe UI",Helvetica,Arial,sans-serif;margin:24px auto;max-width:1180px;
     color:#222;line-height:1.4;padding:0 16px}
h1{font-size:1.5em;margin-bottom:0.2em} h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ddd}
.sub{color:#666;margin-top:0}
table{border-collapse:collapse;margin:8px 0;font-size:0.92em}
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right} th{background:#f2f4f7}
td.l,th.l{text-align:left}
img{max-width:100%;height:auto;display:block;margin:6px 0}
.grid{display:flex;flex-wrap:wrap;gap:12px} .grid figure{margin:0;flex:1 1 420px}
figcaption{font-size:0.85em;color:#555}
.flag{background:#fff3cd;border:1px solid #e0b000;padding:6px 10px;margin:8px 0}
.err{background:#fde8e8;border:1px solid #d33;padding:6px 10px;margin:8px 0}
.note{color:#555;font-size:0.9em}
code{background:#f4f4f4;padding:0 3px}
"""


def esc(text) -> str:
    return _html.escape(str(text), quote=True)


def img(png: bytes, alt: str, caption: str | None = None, cls: str = "") -> str:
    """A ``<figure>`` with the PNG inlined as a data URI."""
    data = base64.b64encode(png).decode("ascii")
    cap = f"<figcaption>{esc(caption)}</figcaption>" if caption else ""
    return (f'<figure class="{esc(cls)}"><img alt="{esc(alt)}" src="data:image/png;base64,{data}">{cap}</figure>')


def fmt(v, digits: int = 4) -> str:
    """A number for a table cell (``None``/NaN: an en dash)."""
    if v is None:
        return "&ndash;"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int,)) and not isinstance(v, bool):
        return f"{v:,}"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return esc(v)
    if x != x:
        return "&ndash;"
    return f"{x:.{digits}g}"


def table(header: Sequence[str], rows: Sequence[Sequence], *, cls: str = "", left: int = 1, raw: bool = False,
          table_id: str | None = None) -> str:
    """An HTML table; the first ``left`` columns left-aligned; cells formatted with :func:`fmt`
    (strings escaped unless ``raw``)."""
    def cell(v, j, tag):
        c = ' class="l"' if j < left else ""
        if isinstance(v, str):
            return f"<{tag}{c}>{v if raw else esc(v)}</{tag}>"
        return f"<{tag}{c}>{fmt(v)}</{tag}>"

    tid = f' id="{esc(table_id)}"' if table_id else ""
    out = [f'<table class="{esc(cls)}"{tid}><thead><tr>' + "".join(cell(h, j, "th") for j, h in enumerate(header))
           + "</tr></thead><tbody>"]
    for r in rows:
        out.append("<tr>" + "".join(cell(v, j, "td") for j, v in enumerate(r)) + "</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def page(title: str, body: Sequence[str], subtitle: str = "") -> str:
    """The whole document."""
    sub = f'<p class="sub">{esc(subtitle)}</p>' if subtitle else ""
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{esc(title)}</title>"
            f"<style>{CSS}</style></head><body><h1>{esc(title)}</h1>{sub}\n" + "\n".join(body) + "\n</body></html>\n")


def write_page(out_path: Path, text: str) -> Path:
    """Write ``text`` to ``out_path`` atomically: a temporary file beside it, renamed into place
    (a failed write leaves the previous file as it was); the file gets the umask's permissions."""
    out_path = Path(out_path)
    fd, tmp = tempfile.mkstemp(prefix=".report-", suffix=".html.tmp", dir=out_path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, out_path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return out_path


def material_text(mat: dict) -> str:
    """A run record's material as one line: model, E [MPa], nu, and the thickness [mm] if given."""
    bits = [str(mat.get("model", ""))]
    if "E_Pa" in mat:
        bits.append(f"E = {mat['E_Pa'] / 1e6:.4g} MPa")
    if "nu" in mat:
        bits.append(f"nu = {mat['nu']:g}")
    if "thickness_m" in mat:
        bits.append(f"t = {mat['thickness_m'] * 1e3:.4g} mm")
    return ", ".join(b for b in bits if b)
