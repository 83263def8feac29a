"""Runs the demo `cnem.demos.kalthoff_winkler` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.kalthoff_winkler", run_name="__main__", alter_sys=True)
