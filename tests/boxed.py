"""Running a piece of code in a fresh interpreter with a time limit: a hang fails the test
instead of hanging the suite."""

from __future__ import annotations

import subprocess
import sys


def run_boxed(code: str, timeout: float = 240.0) -> str:
    """Run ``code`` in a fresh interpreter with a time limit (a hang fails the test
    instead of hanging the suite); its standard output."""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=timeout)
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()
