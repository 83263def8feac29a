"""Runs the demo `cnem.demos.inclined_crack` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.inclined_crack", run_name="__main__", alter_sys=True)
