"""The demo pages print what the code prints: every page's text comes from
``docs/demos/regenerate.py`` (its command on the page and in the text), and the pages whose
demos are short are compared number by number (times left out) with the run of their
command that the test session makes once (``demo_runs.py``; ``test_demos.py`` checks the
numbers of the same runs)."""

from __future__ import annotations

import pathlib
import re
import runpy

import pytest

import demo_runs

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAGES = runpy.run_path(str(ROOT / "docs" / "demos" / "regenerate.py"))


def test_every_printed_output_has_its_command():
    """Each text a page includes is one of the script's pages, starts with the command
    that produced it, and the page names that command."""
    texts = sorted(p.stem for p in (ROOT / "docs" / "demos" / "output").glob("*.txt"))
    assert texts == sorted(PAGES["PAGES"])
    for name in texts:
        command = PAGES["command"](name)
        text = (ROOT / "docs" / "demos" / "output" / f"{name}.txt").read_text()
        assert text.splitlines()[0] == f"$ {command}", name
        page = (ROOT / "docs" / "demos" / f"{name}.md").read_text()
        assert f"`{command}`" in page, name
        assert f"docs/demos/output/{name}.txt" in page, name
        for png in PAGES["pictures"](name):
            assert (ROOT / "docs" / "images" / "demos" / png).stat().st_size > 1000, png


def test_the_index_names_the_pages_without_a_run():
    """docs/demos/index.md says which pages show no run of their own: exactly those that
    `regenerate.py` does not make."""
    index = (ROOT / "docs" / "demos" / "index.md").read_text()
    promise = next(p for p in index.split("\n\n") if "show the pictures and the numbers" in p)
    pages = {p.stem for p in (ROOT / "docs" / "demos").glob("*.md")} - {"index"}
    assert set(re.findall(r"\[(\w+)\]\(\w+\.md\)", promise)) == pages - set(PAGES["PAGES"])


BASE = """$ cnem demo x
    cloud  nodes       h    e/sqrt2  time s |     FEM e  time s
  regular    147  0.0667  1.021e-04   68.24 | 1.768e-04    0.06
sum of cell areas 3.99999999999978 vs plate area 4 (relative error 5.5e-14), in 4.79 s
(50 s wall, one numba thread)
"""


@pytest.mark.parametrize("fresh", [
    BASE.replace("68.24", "202.1").replace("0.06\n", "1.25\n").replace("4.79", "0.93")
        .replace("(50 s", "(9 s"),                                 # other times
    BASE.replace("3.99999999999978", "3.99999999999991").replace("5.5e-14", "2.1e-15"),
    BASE.replace("1.021e-04", "1.022e-04"),                        # one unit of the last digit
])
def test_compare_ignores_times_round_off_and_rounding(fresh):
    assert PAGES["compare"](BASE, fresh) == []


@pytest.mark.parametrize("fresh", [
    BASE.replace("147", "148"),                                    # a node count
    BASE.replace("1.021e-04", "1.023e-04"),                        # two units of the last digit
    BASE.replace("0.0667", "0.0700"),
    BASE.replace("5.5e-14", "5.5e-06"),                            # round-off no more
    BASE.replace("plate area 4 ", "plate area 4 or 5 "),           # one number more
])
def test_compare_finds_a_changed_number(fresh):
    assert PAGES["compare"](BASE, fresh)


@pytest.mark.slow
@pytest.mark.parametrize("name", PAGES["CHEAP"])
def test_page_prints_what_the_demo_prints(name):
    """The run of the page's command prints the page's numbers and writes its pictures
    (`regenerate.py NAME` rewrites the page when this fails after a deliberate change)."""
    pytest.importorskip("pyvista")
    run = demo_runs.run_command(PAGES["PAGES"][name])
    text = PAGES["page_text"](name, run.stdout, run.outdir, 0.0)
    page = (ROOT / "docs" / "demos" / "output" / f"{name}.txt").read_text()
    assert PAGES["compare"](page, text) == [], (
        f"docs/demos/output/{name}.txt is stale; if the change is meant, run "
        f"python docs/demos/regenerate.py {name}")
    for png in PAGES["pictures"](name):
        assert (run.outdir / png).stat().st_size > 1000, png
