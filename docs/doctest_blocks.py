"""A griffe extension for the API reference (mkdocs.yml loads it into mkdocstrings): a doctest
that stands in a docstring's text, outside an ``Examples`` section, becomes a ``pycon`` code
block. Markdown reads ``>>>`` as three nested quotes and runs the lines together; griffe's
numpy parser turns doctests into code only inside ``Examples``.
"""

from __future__ import annotations

import re
from typing import Any

from griffe import Extension

#: The underlined header of a numpydoc ``Examples`` section (griffe formats what follows).
EXAMPLES = re.compile(r"^\s*Examples\s*\n\s*-{3,}\s*$", re.MULTILINE)


def fence_doctests(text: str) -> str:
    """``text`` with every run of doctest lines (a ``>>>`` line and the lines after it up to a
    blank line, at its indentation) before any ``Examples`` section put in a ``pycon``
    fence; the rest unchanged.

    >>> fence_doctests("Sum.\\n\\n>>> 1 + 1\\n2\\n")
    'Sum.\\n\\n```pycon\\n>>> 1 + 1\\n2\\n```\\n'
    """
    header = EXAMPLES.search(text)
    head, tail = (text[:header.start()], text[header.start():]) if header else (text, "")
    lines, out, k = head.split("\n"), [], 0
    while k < len(lines):
        line = lines[k]
        if not line.lstrip().startswith(">>>"):
            out.append(line)
            k += 1
            continue
        indent = line[:len(line) - len(line.lstrip())]
        block = []
        while k < len(lines) and lines[k].strip():
            block.append(lines[k])
            k += 1
        out += [f"{indent}```pycon", *block, f"{indent}```"]
    return "\n".join(out) + tail


class DoctestBlocks(Extension):
    """Fence the doctests of every docstring as it is loaded (`fence_doctests`)."""

    def on_instance(self, *, obj: Any, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = fence_doctests(obj.docstring.value)
