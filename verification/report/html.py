"""A tiny HTML writer for the report's own markdown subset: one self-contained page.

Handled: ``#``-headings (with GitHub-style ``id`` anchors, :func:`slug`), paragraphs, ``- ``
bullet lists, pipe tables (header, separator, rows), images ``![alt](src)`` on their own line,
fenced code blocks, and inline code, ``**bold**`` and links ``[text](#anchor)``. Everything
else is escaped text. No third-party markdown library is needed.

The page is self-contained: every image is embedded as a base64 ``data:`` URI (read from
``base_dir``), so the HTML file can be mailed or moved alone. Numeric table cells do not wrap
(``white-space: nowrap``); wide tables scroll sideways. The output is well-formed XML (void
elements closed) so that it parses with any HTML or XML parser.
"""

import base64
import html
import re
from pathlib import Path

STYLE = ("body{font-family:sans-serif;max-width:80em;margin:1em auto;padding:0 1em;"
         "line-height:1.4}"
         "table{border-collapse:collapse;font-size:90%;margin:0.5em 0}"
         "td,th{border:1px solid #bbb;padding:2px 6px;vertical-align:top}"
         "th{background:#eee;text-align:center}td{text-align:left}"
         "td.num{text-align:right;white-space:nowrap}"
         ".scroll{overflow-x:auto}figure{margin:1em 0}img{max-width:100%;height:auto}"
         "code{background:#f4f4f4}nav p{font-size:95%}")
IMAGE = re.compile(r"^!\[(?P<alt>[^\]]*)\]\((?P<src>[^)]+)\)$")
LINK = re.compile(r"\[([^\]]+)\]\((#[^)\s]+|https?://[^)\s]+)\)")
# a cell that is a number (with sign, unit or percent), n/a, none, or "-"
NUMERIC = re.compile(r"^(n/a|none|-|[+-]?(\d|\.\d)[\d.,eE+\- /%]*( (m/s|mm|MPa|m|ms|s))?)$")
MIME = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg", ".svg": "image/svg+xml"}


def slug(text):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    return re.sub(r"[^\w\- ]", "", text.strip().lower()).replace(" ", "-")


def inline(text):
    """Escape ``text`` and render ``code`` spans, ``**bold**`` and links."""
    out = html.escape(text, quote=False)
    out = re.sub(r"`([^`]+)`", r"<code>\1</code>", out)
    out = re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", out)
    return LINK.sub(lambda m: f'<a href="{html.escape(m[2])}">{m[1]}</a>', out)


def _cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _cell(text):
    kind = ' class="num"' if NUMERIC.match(text) else ""
    return f"<td{kind}>{inline(text)}</td>"


def _table(lines):
    head = "".join(f"<th>{inline(c)}</th>" for c in _cells(lines[0]))
    rows = ["<tr>" + "".join(_cell(c) for c in _cells(line)) + "</tr>" for line in lines[2:]]
    return f'<div class="scroll"><table><tr>{head}</tr>' + "".join(rows) + "</table></div>"


def _blocks(lines):
    """Group lines into (kind, lines) blocks."""
    blocks, i = [], 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("```"):
            j = next((k for k in range(i + 1, len(lines)) if lines[k].startswith("```")),
                     len(lines))
            blocks.append(("code", lines[i + 1:j]))
            i = j + 1
            continue
        kind = ("blank" if not line.strip() else "heading" if line.startswith("#")
                else "table" if line.startswith("|") else "list" if line.startswith("- ")
                else "image" if IMAGE.match(line.strip()) else "text")
        if blocks and blocks[-1][0] == kind and kind in ("table", "list", "text"):
            blocks[-1][1].append(line)
        else:
            blocks.append((kind, [line]))
        i += 1
    return blocks


def data_uri(path):
    """The file at ``path`` as a base64 ``data:`` URI, or None if it cannot be read."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError:
        return None
    mime = MIME.get(path.suffix.lower(), "application/octet-stream")
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def _image(match, base_dir):
    alt, src = match["alt"], match["src"]
    uri = data_uri(Path(base_dir) / src)
    if uri is None:
        return f"<p><i>[figure {html.escape(src)} not available]</i></p>"
    return f'<figure><img src="{uri}" alt="{html.escape(alt)}"/></figure>'


def _render(kind, lines, base_dir, ids):
    if kind == "heading":
        level = min(len(lines[0]) - len(lines[0].lstrip("#")), 6)
        text = lines[0].lstrip("#").strip()
        anchor = slug(text)
        ids[anchor] = ids.get(anchor, -1) + 1  # repeated headings: -1, -2, ... as GitHub
        if ids[anchor]:
            anchor = f"{anchor}-{ids[anchor]}"
        return f'<h{level} id="{html.escape(anchor)}">{inline(text)}</h{level}>'
    if kind == "table":
        return _table(lines)
    if kind == "list":
        return "<ul>" + "".join(f"<li>{inline(x[2:])}</li>" for x in lines) + "</ul>"
    if kind == "image":
        return _image(IMAGE.match(lines[0].strip()), base_dir)
    if kind == "code":
        return "<pre>" + html.escape("\n".join(lines)) + "</pre>"
    if kind == "text":
        return "<p>" + inline(" ".join(x.strip() for x in lines)) + "</p>"
    return ""


def markdown_to_html(text, title="report", base_dir="."):
    """A complete, self-contained HTML page from the markdown subset in ``text``; images are
    read from ``base_dir`` and embedded."""
    ids = {}
    body = "\n".join(filter(None, (_render(k, b, base_dir, ids)
                                   for k, b in _blocks(text.splitlines()))))
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"/>'
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head><body>\n{body}\n"
            "</body></html>\n")
