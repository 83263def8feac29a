"""Runs the demo `cnem.demos.bimaterial_cylinder` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.bimaterial_cylinder", run_name="__main__", alter_sys=True)
