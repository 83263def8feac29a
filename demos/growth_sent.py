"""Runs the demo `cnem.demos.growth_sent` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.growth_sent", run_name="__main__", alter_sys=True)
