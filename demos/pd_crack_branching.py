"""Runs the demo `cnem.demos.pd_crack_branching` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.pd_crack_branching", run_name="__main__", alter_sys=True)
