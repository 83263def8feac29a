"""Rerun the demos at the settings their documentation pages state, and rewrite what the pages
show: the printed text (``docs/demos/output/<page>.txt``) and the pictures the page shows
(``docs/images/demos/*.png``).

    python docs/demos/regenerate.py                      # every page (about 8 minutes)
    python docs/demos/regenerate.py inclined_crack ...   # some pages (names: PAGES)

Each demo runs in a fresh process (``python -m cnem ...``) with ``NUMBA_NUM_THREADS=1`` and its
files in a temporary folder; the text keeps the demo's standard output (not the progress bars)
with that folder written as the demo's default one, and ends with the wall time.
``tests/test_demo_pages.py`` compares the pages of `CHEAP` with the runs of their commands
that the test session makes once (``tests/demo_runs.py``), number by number (`compare`).
"""

from __future__ import annotations

import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
OUTPUT = ROOT / "docs" / "demos" / "output"
IMAGES = ROOT / "docs" / "images" / "demos"

#: Page name (``docs/demos/<name>.md``) -> the command line after ``cnem`` that its text shows.
PAGES = {
    "bimaterial_cylinder": ("demo", "bimaterial-cylinder"),
    "cracked_plate_geometry": ("demo", "cracked-plate-geometry"),
    "inclined_crack": ("demo", "inclined-crack"),
    "mode1_crack": ("demo", "mode1-crack", "--n", "8", "16", "32"),
    "pd_vs_cnem_crack": ("pd", "pd-vs-cnem-crack", "--n", "16", "32"),
    "pd_crack_branching": ("pd", "pd-crack-branching", "--quick"),
    "cpd_examples": ("pd", "cpd-examples", "--quick"),
    "kalthoff_winkler": ("pd", "kalthoff-winkler", "--quick"),
    "growth_sent": ("demo", "growth-sent"),
    "growth_kink": ("demo", "growth-kink", "--angles", "30", "60"),
    "growth_two_holes": ("demo", "growth-two-holes", "--grips", "both", "--h", "0.5", "--steps", "8"),
}
#: The pages whose runs are short enough for the test suite (8-30 s each with a warm numba
#: cache on the shared 2-core machine; growth_sent, 20361 nodes, took 310 s there).
CHEAP = tuple(name for name in PAGES if name != "growth_sent")

#: Numbers smaller than this are round-off (a relative area error of 1e-14, a K_II of 1e-14):
#: a fresh run must print one as small, not the same digits.
ROUND_OFF = 1e-9
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
#: Times: a number of seconds ("4.79 s", "1.5s", "3.76 s per increment"), a column headed
#: "time", "time s" or "wall (s)", or the last line.
SECONDS = re.compile(r"[-+]?\d+(?:\.\d+)?\s?s\b")
TIME_HEADER = re.compile(r"\btime(?: s)?\b|\bwall \(s\)")


def command(name: str) -> str:
    """The command line of page ``name`` as a user types it."""
    return "cnem " + " ".join(PAGES[name])


def run(name: str) -> tuple[str, pathlib.Path]:
    """Run page ``name``'s demo; return its text (as the page shows it) and its folder
    (a temporary one; the caller removes it)."""
    out = pathlib.Path(tempfile.mkdtemp(prefix=f"cnem_{name}_"))
    env = dict(os.environ, NUMBA_NUM_THREADS="1", PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "cnem", *PAGES[name], "--out", str(out)],
                          cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{command(name)} failed ({done.returncode}):\n{done.stderr[-3000:]}")
    return page_text(name, done.stdout, out, wall), out


def page_text(name: str, stdout: str, out: pathlib.Path, wall: float) -> str:
    """The text page ``name`` shows for a run that printed ``stdout`` with its files in
    ``out`` (written as the demo's default folder) in ``wall`` seconds."""
    default = f"results/{name}"
    lines = [line.rstrip() for line in stdout.replace(str(out), default).splitlines()]
    text = "\n".join([f"$ {command(name)}", *lines, f"({wall:.0f} s wall, one numba thread)"])
    return text + "\n"


def pictures(name: str) -> list[str]:
    """The PNG files page ``name`` shows (``../images/demos/<file>.png``)."""
    page = (ROOT / "docs" / "demos" / f"{name}.md").read_text()
    return re.findall(r"\.\./images/demos/([\w.-]+\.png)", page)


def _numbers(text: str) -> list[tuple[int, str]]:
    """The numbers of ``text`` that are not times, with their line numbers; the command
    line (``$ ...``) and the wall-time line are left out."""
    found, columns = [], []
    for k, line in enumerate(text.splitlines()):
        if line.startswith("$ ") or line.endswith("one numba thread)") or not line.strip():
            columns = [] if not line.strip() else columns
            continue
        if TIME_HEADER.search(line) and not any(NUMBER.fullmatch(t) for t in line.split()):
            columns = [m.end() for m in TIME_HEADER.finditer(line)]     # right-aligned
            continue
        masked = SECONDS.sub(lambda m: " " * len(m.group()), line)
        for m in NUMBER.finditer(masked):
            if m.end() not in columns:
                found.append((k, m.group()))
    return found


def _close(page: str, fresh: str) -> bool:
    """Whether two printed numbers agree: integers exactly; decimals to one unit of the
    page's last digit (a rounding either way) or to 1e-12 relative (round-off in full
    precision); both below `ROUND_OFF` in size."""
    a, b = float(page), float(fresh)
    if abs(a) < ROUND_OFF and abs(b) < ROUND_OFF:
        return True
    if NUMBER.fullmatch(page) and not re.search(r"[.eE]", page):
        return a == b
    mantissa, _, exponent = page.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    unit = 10.0 ** (-decimals + (int(exponent) if exponent else 0))
    return abs(a - b) <= max(unit * (1 + 1e-9), 1e-12 * abs(a))   # 1e-9: binary round-off


def compare(page: str, fresh: str) -> list[str]:
    """The differences between a page's text and a fresh run's (empty: the same numbers),
    times left out."""
    a, b = _numbers(page), _numbers(fresh)
    if len(a) != len(b):
        return [f"{len(a)} numbers on the page, {len(b)} in the fresh run"]
    return [f"page line {i + 1}: {x} vs fresh {y}" for (i, x), (_, y) in zip(a, b)
            if not _close(x, y)]


def regenerate(name: str) -> None:
    """Rewrite page ``name``'s text and pictures from a fresh run."""
    text, out = run(name)
    try:
        (OUTPUT / f"{name}.txt").write_text(text)
        for png in pictures(name):
            shutil.copyfile(out / png, IMAGES / png)
        print(f"{name}: {command(name)} -> {OUTPUT / f'{name}.txt'} and {len(pictures(name))} "
              f"pictures")
    finally:
        shutil.rmtree(out, ignore_errors=True)


if __name__ == "__main__":
    for page in sys.argv[1:] or list(PAGES):
        regenerate(page)
