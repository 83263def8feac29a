"""Runs the demo `cnem.demos.growth_dcb` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.growth_dcb", run_name="__main__", alter_sys=True)
