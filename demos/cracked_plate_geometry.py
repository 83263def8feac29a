"""Runs the demo `cnem.demos.cracked_plate_geometry` (``--help`` for its options)."""

import runpy

runpy.run_module("cnem.demos.cracked_plate_geometry", run_name="__main__", alter_sys=True)
