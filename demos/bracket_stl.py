"""Runs the demo `cnem.demos.bracket_stl` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.bracket_stl", run_name="__main__", alter_sys=True)
