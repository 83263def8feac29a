"""``docs/architecture.md``'s file table ("Find the file") lists every library module of the
package, and no file that is gone.

A module is listed when a cell of the table's file column names it in backticks, by its
path from the repository (```cnem/spatial/family.py```) or by its file name after such a
path of the same folder in the same cell (```cnem/spatial/family.py`, kernels
`_family_kernels.py```). Package files (``__init__.py``, ``__main__.py``) and the demos
(``cnem/demos/``, one row for the folder) are not modules of the table.
"""

from __future__ import annotations

import pathlib
import re

import cnem

ROOT = pathlib.Path(cnem.__file__).resolve().parents[1]
ARCHITECTURE = ROOT / "docs" / "architecture.md"


def library_modules() -> set[str]:
    """Every module file of the package the table must list, as ``cnem/.../name.py``."""
    package = ROOT / "cnem"
    return {path.relative_to(ROOT).as_posix() for path in package.rglob("*.py")
            if path.name not in ("__init__.py", "__main__.py")
            and "demos" not in path.relative_to(package).parts}


def listed_files(text: str) -> set[str]:
    """The ``.py`` files the file column of the "Find the file" table names (see the
    module docstring for how a bare file name is read)."""
    table = text.split("## Find the file", 1)[1].split("\n## ", 1)[0]
    listed = set()
    for line in table.splitlines():
        cells = line.split("|")
        if len(cells) < 4 or set(cells[2].strip()) <= {"-", " "}:
            continue
        folder = None
        for name in re.findall(r"`([^`]+\.py)`", cells[2]):
            if name.startswith("cnem/"):
                folder = name.rpartition("/")[0]
                listed.add(name)
            elif folder is not None:
                listed.add(f"{folder}/{name}")
    return listed


def test_the_reading_of_the_table():
    text = ("## Find the file\n\n| concept | file |\n| --- | --- |\n"
            "| a | `cnem/x/a.py`, kernels `_a.py` |\n| b | `b.py` |\n| c | `cnem/c.py` |\n"
            "\n## Next\n| d | `cnem/d.py` |\n")
    assert listed_files(text) == {"cnem/x/a.py", "cnem/x/_a.py", "cnem/c.py"}


def test_every_library_module_is_in_the_file_table():
    missing = sorted(library_modules() - listed_files(ARCHITECTURE.read_text()))
    assert not missing, (
        f"docs/architecture.md's file table (\"Find the file\") misses {len(missing)} "
        f"module(s): {', '.join(missing)}; add a row for each (or name it in the row of its "
        f"concept)")


def test_every_file_of_the_table_exists():
    gone = sorted(name for name in listed_files(ARCHITECTURE.read_text())
                  if not (ROOT / name).is_file())
    assert not gone, (
        f"docs/architecture.md's file table names {len(gone)} file(s) that are not in the "
        f"package: {', '.join(gone)}; point their rows at the modules' new places")
