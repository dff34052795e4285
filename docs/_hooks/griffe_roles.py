"""A griffe extension for the API reference: the docstrings' reStructuredText bits read as
Markdown.

The docstrings are numpy style and read as plain text in a terminal; Markdown has no roles
and no directives, so

- a cross-reference role (``:func:`name```, ``:class:`~.registry.Model```) becomes the code
  span of the name (a leading ``~`` keeps the last dotted part, as in Sphinx);
- a ``.. math::`` directive (its first line and the lines indented below it) becomes a
  ``$$ ... $$`` block, which pymdownx.arithmatex hands to MathJax.
"""

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|mod|meth|attr|data|obj|exc|const):`(~?)([^`]+)`")
MATH = re.compile(r"^(\s*)\.\. math::\s?(.*)$")


def plain_reference(match):
    """The role's target as a Markdown code span (its last dotted part after ``~``)."""
    shorten, target = match.groups()
    target = "".join(target.split())  # a target broken over two lines of the docstring
    shown = target.lstrip(".").rsplit(".", 1)[-1] if shorten else target
    return f"`{shown}`"


def indent_of(line):
    return len(line) - len(line.lstrip())


def math_blocks(text):
    """``text`` with each ``.. math::`` directive written as a ``$$`` block at its indent."""
    lines = text.split("\n")
    out = []
    i = 0
    while i < len(lines):
        match = MATH.match(lines[i])
        if not match:
            out.append(lines[i])
            i += 1
            continue
        margin, first = match.groups()
        body = [first.strip()] if first.strip() else []
        i += 1
        while i < len(lines) and (not lines[i].strip() and not body
                                  or lines[i].strip() and indent_of(lines[i]) > len(margin)):
            if lines[i].strip():
                body.append(lines[i].strip())
            i += 1
        out.extend(["", f"{margin}$$", *(margin + line for line in body), f"{margin}$$", ""])
    return "\n".join(out)


def as_markdown(docstring):
    return math_blocks(ROLE.sub(plain_reference, docstring))


class RestructuredTextAsMarkdown(griffe.Extension):
    """Rewrites each object's docstring as it is loaded."""

    def on_instance(self, *, obj, **kwargs):
        if obj.docstring is not None:
            obj.docstring.value = as_markdown(obj.docstring.value)
