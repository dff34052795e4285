"""A tiny HTML writer for the report's own markdown subset.

Handled: ``#``-headings, paragraphs, ``- `` bullet lists, pipe tables (header, separator,
rows), images ``![alt](src)`` on their own line, fenced code blocks, and inline code and
``**bold**``. Everything else is escaped text. No third-party markdown library is needed.
"""

import html
import re

STYLE = ("body{font-family:sans-serif;max-width:72em;margin:1em auto;padding:0 1em}"
         "table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #bbb;"
         "padding:2px 6px;text-align:right}th{background:#eee}img{max-width:100%}"
         "code{background:#f4f4f4}")
IMAGE = re.compile(r"^!\[(?P<alt>[^\]]*)\]\((?P<src>[^)]+)\)$")


def inline(text):
    """Escape ``text`` and render ``code`` spans and ``**bold**``."""
    out = html.escape(text, quote=False)
    out = re.sub(r"`([^`]+)`", r"<code>\1</code>", out)
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", out)


def _cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _table(lines):
    head = "".join(f"<th>{inline(c)}</th>" for c in _cells(lines[0]))
    rows = ["<tr>" + "".join(f"<td>{inline(c)}</td>" for c in _cells(line)) + "</tr>"
            for line in lines[2:]]
    return f"<table><tr>{head}</tr>" + "".join(rows) + "</table>"


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


def _render(kind, lines):
    if kind == "heading":
        level = min(len(lines[0]) - len(lines[0].lstrip("#")), 6)
        return f"<h{level}>{inline(lines[0].lstrip('#').strip())}</h{level}>"
    if kind == "table":
        return _table(lines)
    if kind == "list":
        return "<ul>" + "".join(f"<li>{inline(x[2:])}</li>" for x in lines) + "</ul>"
    if kind == "image":
        m = IMAGE.match(lines[0].strip())
        return (f'<p><img src="{html.escape(m["src"])}" alt="{html.escape(m["alt"])}">'
                "</p>")
    if kind == "code":
        return "<pre>" + html.escape("\n".join(lines)) + "</pre>"
    if kind == "text":
        return "<p>" + inline(" ".join(x.strip() for x in lines)) + "</p>"
    return ""


def markdown_to_html(text, title="report"):
    """A complete HTML page from the markdown subset in ``text``."""
    body = "\n".join(filter(None, (_render(k, b) for k, b in _blocks(text.splitlines()))))
    return (f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{html.escape(title)}"
            f"</title><style>{STYLE}</style></head><body>\n{body}\n</body></html>\n")
