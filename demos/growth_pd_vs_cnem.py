"""Runs the demo `cnem.demos.growth_pd_vs_cnem` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.growth_pd_vs_cnem", run_name="__main__", alter_sys=True)
