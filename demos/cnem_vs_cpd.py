"""Runs the demo `cnem.demos.cnem_vs_cpd` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.cnem_vs_cpd", run_name="__main__", alter_sys=True)
