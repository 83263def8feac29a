"""Runs the demo `cnem.demos.mode1_crack` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.mode1_crack", run_name="__main__", alter_sys=True)
