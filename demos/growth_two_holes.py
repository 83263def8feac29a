"""Runs the demo `cnem.demos.growth_two_holes` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.growth_two_holes", run_name="__main__", alter_sys=True)
