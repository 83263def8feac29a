"""The demos: narrative scripts that reproduce the papers' examples (front layer).

Each module states its problem and the expected result in its docstring, has
``main(**sizes, outdir=..., plot=...) -> dict`` (the numbers it prints) and
``cli(argv, prog)`` (its command line), and runs as ``python -m cnem.demos.<name>``,
``cnem demo <name>`` (see `cnem.cli`) or, from a source tree,
``python demos/<name>.py``. They use only the library's public functions.

Writing a demo (the rules every demo follows; ``tests/test_cli.py`` checks them
for every entry of `cnem.cli.DEMOS` and `cnem.cli.PD_DEMOS`):

1. ``cnem/demos/<module>.py`` with ``main(..., outdir: str = "results/<module>",
   plot: bool = True) -> dict``, a launcher ``demos/<module>.py``, a row in
   ``tests/test_demos.py``'s ``CASES``, its name in `MODULES` below, an entry in
   `cnem.cli.DEMOS` (or `cnem.cli.PD_DEMOS`).
2. Its command line starts from the shared parser, which shows every default,
   holds the output rule (``--out``, default ``results/<module>/``, and
   ``--no-plot``) and states the run time at the defaults on 2 cores (the module's
   ``RUN_TIME``, measured)::

       RUN_TIME = "about 10 s"

       def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
           parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)  # cnem.cli
           parser.add_argument("--h", type=float, default=0.1, help="node spacing")
           args = parser.parse_args(argv)
           return main(args.h, outdir=args.out, plot=not args.no_plot)

   Give every option a ``help``: the default is appended to it.
3. Long stages show progress (tqdm on stderr, off when it is not a terminal or
   with ``progress=False``); numba compiling is announced by the parser.
4. A number that cannot be computed (NaN, an empty fit, too coarse a cloud) is
   not printed as ``nan``: print ``-`` and one line saying why and how to get it.
"""

#: The demo modules (``cnem.demos.<name>``; `cnem.cli` gives them command-line names).
MODULES = ("bimaterial_cylinder", "bracket_stl", "cnem_vs_cpd", "cpd_examples", "cracked_plate_geometry", "growth_dcb",
           "growth_kink", "growth_pd_vs_cnem", "growth_sent", "growth_two_holes", "inclined_crack",
           "kalthoff_winkler", "mode1_crack", "pd_crack_branching", "pd_vs_cnem_3d",
           "pd_vs_cnem_crack")

__all__ = ["MODULES"]
