"""A mkdocs hook that renders the site's formulas as MathML when the site is built, so that
they show with no network and no JavaScript (browsers draw MathML natively).

``pymdownx.arithmatex`` (``generic: true`` in mkdocs.yml) marks each formula of the Markdown
(``$...$`` inline, ``$$...$$`` display) as ``<span class="arithmatex">\\(...\\)</span>`` or
``<div class="arithmatex">\\[...\\]</div>``; `render_formulas` replaces each one's TeX by
the MathML of ``latex2mathml`` inside the same element. A formula that latex2mathml cannot
read stops the build with its page and its TeX.
"""

from __future__ import annotations

import html
import re

from latex2mathml.converter import convert

INLINE = re.compile(r'<span class="arithmatex">\\\((.*?)\\\)</span>', re.DOTALL)
DISPLAY = re.compile(r'<div class="arithmatex">\\\[(.*?)\\\]</div>', re.DOTALL)


def _mathml(tex: str, display: str, where: str) -> str:
    """The MathML of one formula (its TeX HTML-escaped, as arithmatex writes it)."""
    source = html.unescape(tex).strip()
    try:
        mathml = convert(source, display=display)
    except Exception as exc:   # latex2mathml raises exceptions of many kinds
        problem = f"{type(exc).__name__} {exc}".strip()
    else:
        unknown = re.findall(r"\\[A-Za-z]+", mathml)    # commands it passed through as text
        if not unknown:
            return mathml
        problem = f"unknown command(s) {', '.join(unknown)}"
    raise ValueError(f"{where}: latex2mathml cannot render the formula {source!r} "
                     f"({problem}); rewrite it with the TeX commands latex2mathml knows")


def render_formulas(page_html: str, where: str = "a page") -> str:
    """``page_html`` with every arithmatex formula rendered as MathML.

    Parameters
    ----------
    page_html : str
        A page's HTML as Markdown renders it.
    where : str
        The page's name, for the error message.

    Returns
    -------
    str
        The same HTML, each ``\\(...\\)`` / ``\\[...\\]`` inside an ``arithmatex`` element
        replaced by a ``<math>`` element (``display="inline"`` / ``"block"``).
    """
    page_html = DISPLAY.sub(lambda m: '<div class="arithmatex">'
                            f'{_mathml(m.group(1), "block", where)}</div>', page_html)
    return INLINE.sub(lambda m: '<span class="arithmatex">'
                      f'{_mathml(m.group(1), "inline", where)}</span>', page_html)


def on_page_content(html_text: str, page, config, files) -> str:
    """mkdocs' hook: render the formulas of every page (guide, demos and API pages)."""
    return render_formulas(html_text, page.file.src_uri)
