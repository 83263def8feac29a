"""Runs the demo `cnem.demos.growth_kink` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.growth_kink", run_name="__main__", alter_sys=True)
