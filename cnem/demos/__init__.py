"""The demos: narrative scripts that reproduce the papers' examples (front layer).

Each module states its problem and the expected result in its docstring, has
``main(**sizes, outdir=..., plot=...) -> dict`` (the numbers it prints) and
``cli(argv)`` (its command line), and runs as ``python -m cnem.demos.<name>``,
``cnem demo <name>`` (see `cnem.cli`) or, from a source tree,
``python demos/<name>.py``. They use only the library's public functions.
"""

#: The demo modules (``cnem.demos.<name>``; `cnem.cli` gives them command-line names).
MODULES = ("bimaterial_cylinder", "cpd_examples", "cracked_plate_geometry", "growth_dcb",
           "growth_kink", "growth_sent", "growth_two_holes", "inclined_crack", "mode1_crack",
           "pd_crack_branching", "pd_vs_cnem_crack")

__all__ = ["MODULES"]
