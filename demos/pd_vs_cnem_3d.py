"""Runs the demo `cnem.demos.pd_vs_cnem_3d` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.pd_vs_cnem_3d", run_name="__main__", alter_sys=True)
