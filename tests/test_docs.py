"""The documentation: the site builds with warnings as errors (formulas as MathML, no CDN), the
tutorials' scripts run and their reactions balance their loads, and the README's links resolve."""

from __future__ import annotations

import csv
import importlib.util
import os
import pathlib
import re
import runpy
import subprocess
import sys

import meshio
import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None
                    or importlib.util.find_spec("mkdocstrings") is None,
                    reason='the docs extra is not installed (pip install -e ".[docs]")')
def test_site_builds_strict(tmp_path):
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir",
                           str(tmp_path / "site")], cwd=ROOT, capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert done.returncode == 0, done.stderr[-3000:]
    for page in ("index.html", "tutorial/index.html", "api/geometry/index.html",
                 "demos/bimaterial_cylinder/index.html", "api-contract/index.html"):
        assert (tmp_path / "site" / page).stat().st_size > 1000, page
    site = tmp_path / "site"
    api = sorted((site / "api").glob("*/index.html"))
    assert api
    for page in api:              # a bare doctest in a docstring is code, not nested quotes
        assert "<blockquote>" not in page.read_text(), page
    fracture = (site / "fracture" / "index.html").read_text()
    assert 'class="arithmatex"' in fracture
    # formulas are MathML from the build, with no script or CDN to draw them
    assert '<math xmlns="http://www.w3.org/1998/Math/MathML" display="block">' in fracture
    assert "<mi>&#x003C3;</mi>" in fracture                     # sigma
    assert "\\frac" not in fracture and "\\sigma" not in fracture
    for page in site.rglob("*.html"):
        text = page.read_text()
        assert not re.search(r"<script[^>]+(mathjax|katex)", text, re.I), page
        assert not re.search(r"https?://[^\"']*(mathjax|katex|unpkg|jsdelivr|cdnjs)", text,
                             re.I), page
    # long code lines wrap, printed output and tables scroll (docs/stylesheets/extra.css)
    assert 'href="../stylesheets/extra.css"' in fracture
    assert '<div class="language-text highlight">' in (site / "tutorial" / "index.html").read_text()


@pytest.mark.skipif(importlib.util.find_spec("latex2mathml") is None,
                    reason='the docs extra is not installed (pip install -e ".[docs]")')
def test_formulas_become_mathml():
    """docs/mathml_hook.py turns arithmatex's inline and display TeX into MathML (its
    HTML escapes read back), leaves other HTML alone and names the page of a formula it
    cannot read."""
    render = runpy.run_path(str(ROOT / "docs" / "mathml_hook.py"))["render_formulas"]
    page = ('<p>If <span class="arithmatex">\\(a &lt; b_i\\)</span> then</p>\n'
            '<div class="arithmatex">\\[\n\\frac{1}{2}\n\\]</div><p>$5 and \\(x\\)</p>')
    out = render(page, "x.md")
    assert out.count("<math") == 2 and "\\frac" not in out and "&lt; b_i" not in out
    assert '<span class="arithmatex"><math xmlns="http://www.w3.org/1998/Math/MathML" ' \
           'display="inline">' in out
    bare = out.replace("<mrow>", "").replace("</mrow>", "")
    assert 'display="block"><mfrac><mn>1</mn><mn>2</mn></mfrac></math></div>' in bare
    assert "<mi>a</mi><mo>&#x0003C;</mo><msub><mi>b</mi><mi>i</mi></msub>" in bare
    assert out.endswith("<p>$5 and \\(x\\)</p>")       # not marked by arithmatex: kept
    for broken in ("x^", "\\sigma + \\unknowncommand"):   # unreadable; unknown to latex2mathml
        with pytest.raises(ValueError, match="x.md"):
            render(f'<span class="arithmatex">\\({broken}\\)</span>', "x.md")


@pytest.mark.skipif(importlib.util.find_spec("griffe") is None,
                    reason='the docs extra is not installed (pip install -e ".[docs]")')
def test_bare_doctests_become_code_blocks():
    """docs/doctest_blocks.py fences a doctest in a docstring's text (at its indentation, up
    to the blank line), leaves an ``Examples`` section to griffe and other text alone."""
    fence = runpy.run_path(str(ROOT / "docs" / "doctest_blocks.py"))["fence_doctests"]
    assert fence("Text.\n\n>>> x = 1\n>>> x\n1\n\nMore.") == (
        "Text.\n\n```pycon\n>>> x = 1\n>>> x\n1\n```\n\nMore.")
    assert fence("a : int\n    >>> f(\n    ... 2)\n") == (
        "a : int\n    ```pycon\n    >>> f(\n    ... 2)\n    ```\n")
    examples = "Examples\n--------\n>>> 1 + 1\n2"
    assert fence("Sum.\n\n" + examples) == "Sum.\n\n" + examples
    assert fence("No doctest; a > b.") == "No doctest; a > b."


def test_every_docs_page_is_in_the_navigation():
    nav = (ROOT / "mkdocs.yml").read_text()
    pages = {p.relative_to(ROOT / "docs").as_posix() for p in (ROOT / "docs").rglob("*.md")}
    assert pages == set(re.findall(r"([\w/.-]+\.md)", nav))


def test_readme_links_resolve():
    readme = (ROOT / "README.md").read_text()
    links = re.findall(r"\]\((?!https?://)([^)#]+)", readme)
    assert links
    for link in links:
        assert (ROOT / link).exists(), link


@pytest.mark.slow
def test_first_model_tutorial_balances_its_load(tmp_path, monkeypatch, capsys):
    """The tutorial's script: the clamped edge's reactions balance the end load (10 N/mm down)
    to the solver's tolerance, it prints what the tutorial shows, and it writes its file and
    picture."""
    monkeypatch.chdir(tmp_path)
    pyvista = importlib.util.find_spec("pyvista") is not None
    script = ROOT / "docs" / "examples" / "first_model.py"
    if not pyvista:
        pytest.skip("the plot extra is not installed")
    names = runpy.run_path(str(script), run_name="__main__")
    pages = runpy.run_path(str(ROOT / "docs" / "demos" / "regenerate.py"))
    printed = (ROOT / "docs" / "examples" / "first_model.out").read_text()
    assert pages["compare"](printed, capsys.readouterr().out) == [], "first_model.out is stale"
    np.testing.assert_allclose(names["reaction"], [0.0, 10.0], atol=1e-6 * 10.0)
    assert names["dom"].area == pytest.approx(3.0 - names["hole"].area, rel=1e-12)
    for f in ("l_plate.vtu", "l_plate_von_mises.png"):
        assert (tmp_path / "results" / "first_model" / f).stat().st_size > 1000


@pytest.mark.slow
def test_cad_tutorial_reports_balanced_forces(tmp_path, monkeypatch, capsys):
    """docs/examples/cad_to_report.py: the DXF lug's named boundaries drive the conditions,
    the pin's load is the 2000 N asked for and the clamp's reaction balances it, the CSV
    holds those forces, the VTU reads back with a 3-component displacement and named
    tensors, the bending stress is beam theory's within 3 %, and it prints what the page
    shows."""
    monkeypatch.chdir(tmp_path)
    names = runpy.run_path(str(ROOT / "docs" / "examples" / "cad_to_report.py"),
                           run_name="__main__")
    pages = runpy.run_path(str(ROOT / "docs" / "demos" / "regenerate.py"))
    printed = (ROOT / "docs" / "examples" / "cad_to_report.out").read_text()
    assert pages["compare"](printed, capsys.readouterr().out) == [], "cad_to_report.out is stale"
    assert names["dom"].boundaries == ("clamp", "edge", "pin")
    exact_area = 60.0 * 40.0 + np.pi * 20.0**2 / 2 - np.pi * 8.0**2
    assert names["dom"].area == pytest.approx(exact_area, rel=1e-3)      # chords of the arcs
    np.testing.assert_allclose(names["load"], [0.0, -2000.0], atol=1e-9 * 2000.0)
    np.testing.assert_allclose(names["reaction"], [0.0, 2000.0], atol=1e-6 * 2000.0)
    np.testing.assert_allclose(names["sxx"], [names["beam"], -names["beam"]], rtol=0.03)
    with open(tmp_path / "results" / "cad_to_report" / "forces.csv") as f:
        rows = {(r["boundary"], r["kind"]): (float(r["force_x_N"]), float(r["force_y_N"]))
                for r in csv.DictReader(f)}
    np.testing.assert_allclose(rows[("pin", "load")], [0.0, -2000.0], atol=1e-3)
    np.testing.assert_allclose(rows[("clamp", "reaction")], [0.0, 2000.0], atol=1e-3)
    np.testing.assert_allclose(rows[("total", "sum")], [0.0, 0.0], atol=1e-3)
    mesh = meshio.read(tmp_path / "results" / "cad_to_report" / "bracket.vtu")
    assert mesh.point_data["displacement"].shape[1] == 3
    assert all(block.shape[1] == 9 for block in mesh.cell_data["stress"])
