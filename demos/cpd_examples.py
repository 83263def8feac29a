"""Runs the demo `cnem.demos.cpd_examples` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.cpd_examples", run_name="__main__", alter_sys=True)
