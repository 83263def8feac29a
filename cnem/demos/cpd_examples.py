"""Continuum-kinematics-inspired peridynamics (CPD): the examples of §6 of Javili et al.

The problems
------------
CPD (`cnem.pd.CPD`) adds to the bonds of bond-based PD (one-neighbour
interactions, constant C1) the areas spanned by pairs of bonds (two-neighbour,
C2) and, in 3-D, the volumes spanned by triplets of bonds (three-neighbour, C3),
each with the Seth-Hill energy ``1/2 C |reference measure| S_n(stretch)^2``
(eq. 41-42). `cnem.pd.Problem.solve` finds the equilibrium by
Newton-Raphson with the exact tangent (hyper-dual derivatives). All bodies are
regular lattices of spacing D with horizon delta = m D; every example prints a
convergence table like the paper's Tables 4-8 (residual norm per Newton
iteration, one column per load step) and writes a picture of the deformed body.

1. ``tension2d`` (§6.1, Figure 5, Tables 4-5): a unit square stretched to twice
   its length (n = 1), with C2 = 0 and with C2 >> C1: the area of the lattice.
2. ``cube`` (§6.1, Figure 6, Tables 6-8): a unit cube stretched to twice its
   height with one- (C1), one- and two- (C2 >> C1) and one- and three-neighbour
   (C3 >> C1) interactions: lateral contraction and volume.
3. ``cantilever`` (§6.2, Figure 7, 2-D row): a beam of aspect ratio 25 (n = 2),
   clamped at one end, bent by a downward load on its free end, for several C1.
4. ``torsion`` (§6.3, Figures 8-9): a block of slenderness 2 (n = 0), bottom
   clamped, top face turned by 180 degrees about the block's axis.
5. ``lshape`` (§6.4, Figure 10): an L-shaped plate (C2 = 0, n = 1) pulled up by
   a small displacement, at one grid for several horizons: the von Mises
   stress near the re-entrant corner.

"C >> C1" is set through the small-strain continuum limit of the CPD sums
(`cnem.pd.cpd_moduli`): the interaction adds ``ratio`` times the shear modulus of
the bonds to the Lame constant lambda (ratio 100 here, `cnem.demos.cpd.common.RATIO`). The paper's
constants, read the same way, are ratio 15 (cantilever, C2 = 1e4, 2-D) and 0.5
(torsion, C3 = 1e8); those ratios are kept on the grids used here.

Sizes: the paper's grids (D = 0.01 in 2-D, D = 0.02-0.05 in 3-D, delta = 3D)
hold up to 10^8 pairs or triplets of bonds; on a 2-core machine the default
runs use coarser lattices and smaller 3-D horizons (printed with each example;
about 2 minutes for all five): tension D = 0.02 (paper 0.01); cube 7^3 points,
delta = 2D (paper 21^3, 3D); cantilever D = 0.04 (paper 0.02); torsion
7 x 7 x 13 points, delta = 1.5D (paper D = 0.02, 3D; with delta = 2D on 5 x 5 x 9
points some triplets of the coarse, 22-degrees-per-layer twist turn inside out
before 180 degrees); L-shape D = 1/40 (paper 0.005). ``--quick`` runs tiny
versions (the tests).

Expected result
---------------
* Quadratic convergence of Newton in every load step: the residual roughly
  squares from one iteration to the next until round-off.
* Tension: with C2 >> C1 the lattice keeps its area (ratio close to 1, lateral
  stretch close to 1/2); with C2 = 0 it grows by about 40 %.
* Cube: one-neighbour contracts least; three-neighbour keeps the volume
  (lateral stretch close to 1/sqrt 2); two-neighbour contracts most.
* Cantilever: the tip moves down (the load's sense), by about half the length,
  and less for larger C1; the large rotation pulls the end back towards the clamp.
* Torsion: the cross-sections turn in the sense of the top face, more with
  height; Newton stays quadratic up to 180 degrees.
* L-shape: the peak stress at the corner falls as the horizon grows (a more
  nonlocal response smooths the concentration).
* Pictures ``cpd_<example>.png`` (and ``cpd_lshape_profiles.png``) in ``outdir``.

The code: ``cnem/demos/cpd/common.py`` (solve, tables, pictures),
``cnem/demos/cpd/stretch.py`` (examples 1-2), ``cnem/demos/cpd/structures.py`` (3-5).
Run ``python demos/cpd_examples.py --help`` or ``cnem pd cpd-examples --help``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from cnem.cli import demo_parser
from cnem.demos.cpd import stretch, structures
from cnem.errors import OptionError

if TYPE_CHECKING:
    from typing import Sequence

__all__ = ["main", "cli", "EXAMPLES", "QUICK"]

#: Example name -> function (each returns its numbers and writes ``cpd_<name>.png``).
RUN = {"tension2d": stretch.tension2d, "cube": stretch.cube,
       "cantilever": structures.cantilever, "torsion": structures.torsion,
       "lshape": structures.lshape}
EXAMPLES = tuple(RUN)

#: Tiny versions for the tests (``--quick``).
QUICK = {
    "tension2d": dict(spacing=0.1, steps=4),
    "cube": dict(n=5, m=1.5, steps=4),
    "cantilever": dict(spacing=0.05, C1s=(1.0, 2.0), aspect=10, steps=4, load=2.0),
    "torsion": dict(n=3, m=1.5, angle=90.0, steps=3),
    "lshape": dict(spacing=1 / 12, ratios=(2.0, 4.0)),
}


#: How long the demo runs at its defaults (its --help says it; see cnem.cli.demo_parser).
RUN_TIME = "about 4 min"


def main(examples: tuple = EXAMPLES, *, quick: bool = False, outdir: str = "results/cpd_examples",
         plot: bool = True) -> dict:
    """Run the examples (names from `EXAMPLES`), print their tables, write their pictures.

    Returns
    -------
    dict
        example name -> the numbers its function returns.
    """
    unknown = [e for e in examples if e not in EXAMPLES]
    if unknown:
        raise OptionError(f"examples: expected names from {EXAMPLES}, received {unknown}")
    return {e: RUN[e](**(QUICK[e] if quick else {}), outdir=outdir, plot=plot) for e in examples}


def cli(argv: Sequence[str] | None = None, prog: str | None = None) -> None:
    """Command line: ``python demos/cpd_examples.py --help`` or ``cnem pd cpd-examples``."""
    parser = demo_parser(__file__, __doc__, prog, run_time=RUN_TIME)
    parser.add_argument("--example", choices=EXAMPLES + ("all",), default="all",
                        help="the example to run (all: the five)")
    parser.add_argument("--quick", action="store_true", help="tiny versions (seconds)")
    args = parser.parse_args(argv)
    examples = EXAMPLES if args.example == "all" else (args.example,)
    return main(examples, quick=args.quick, outdir=args.out, plot=not args.no_plot)


if __name__ == "__main__":
    cli()
