"""Tolerances and tuning constants used across cnem, kept in one place.

Tolerances are *relative*: multiply by the domain diameter (lengths) or its
square (areas) before comparing. Modules read these as ``config.NAME`` when they
run, so a user may change one for a session (``cnem.config.DIRECT_NNZ = 10**6``);
where a numba kernel needs a compile-time constant the comment says so
(``cnem.shape._kernels.MAX_CAVITY`` stays in its kernel module: numba compiles it
into the kernels as a constant).

>>> from cnem import config
>>> config.SNAP_TOL < config.CLEARANCE < 1
True
"""

__all__ = ["SNAP_TOL", "OVERLAP_TOL", "MERGE_TOL", "GRID_TOL", "SHAPE_TOL", "ROUNDOFF_ULPS",
           "HORIZON_RTOL", "CONDITION_RTOL",
           "BOUNDARY_FINER", "SHALLOW_END", "CLEARANCE", "MIN_SPACING", "MAX_NODES", "FILL_SPACINGS",
           "SPACING_NEIGHBOURS", "SPACING_COUNT_TOL", "SPACING_BISECTIONS", "FANOUT",
           "BRUTE_LIMIT", "CELLS_PER_HORIZON", "COLUMNS_PER_HORIZON", "MESH_NODES_STOP",
           "MESH_NODES_TRIES", "MESH_NODES_RTOL", "DIRECT_NNZ", "NEWTON_FORCING",
           "NEWTON_INNER_FLOOR", "MIN_GAUSS", "CPD_CHUNK", "CPD_DEGENERATE", "LIVE_MOMENT_CUTOFF",
           "MAX_INTERACTIONS",
           "FD_STEP", "HYPERDUAL_CHUNK", "CELLS_PER_PASS", "ROW_SLOTS", "TRIANGLE_TREE_AFTER",
           "DT_LIMIT", "COORDINATE_LIMIT", "DIRECT_MEMORY", "DIRECT_FILL",
           "CG_MAXITER", "SIF_DISCS", "SIF_REACH", "SIF_INNER", "SIF_STRAIGHTNESS",
           "SIF_BEND_SPACINGS", "SIF_SPREAD", "SIF_SPACINGS", "PARALLEL_MIN", "PLOT_MAX_PIXELS",
           "CHORD_TOLERANCE", "ARC_MIN_PIECES", "SMOOTH_ANGLE"]

# ---------------------------------------------------------------- geometry tolerances
#: Coordinates (and their extent) must stay below this in magnitude: squared distances
#: and in-circle determinants of larger ones overflow float64 (max 1.8e308).
#: `cnem.errors.check_points` refuses them; rescale the model (other units).
COORDINATE_LIMIT = 1e150

#: Points closer than ``SNAP_TOL * diameter`` to a boundary, interface or crack
#: are snapped onto it; vertices closer than this are the same vertex.
SNAP_TOL = 1e-9

#: Arcs, circles and curves read from files (DXF) become chords that stay within this
#: distance of the curve, relative to the drawing's diagonal; `cnem.geometry.dxf_reader`.
CHORD_TOLERANCE = 1e-3

#: ... and a full turn of an arc has at least this many chords (small holes stay round).
ARC_MIN_PIECES = 16

#: Two boundary faces of a 3-D region meeting at an edge whose dihedral angle, measured
#: inside the region, differs from 180 degrees by less than this (degrees) belong to one
#: smooth patch (a faceted sphere, cylinder or fillet). A patch hides points from the
#: nodes (cuts visibility in the 3-D cells) only when one of its edges is a sharp
#: re-entrant edge, whose angle in the region exceeds ``180 + SMOOTH_ANGLE`` (a notch,
#: a slot, a cubic cavity); `cnem.geometry.smooth_patches`.
SMOOTH_ANGLE = 30.0

#: Relative area below which an overlap of two regions is considered round-off.
OVERLAP_TOL = 1e-12

#: Relative length below which two Voronoi vertices are merged into one.
MERGE_TOL = 1e-13

#: Relative grid (times the extent of the nodes) on which the exact cell
#: clipping is snap-rounded, so that neighbouring cells share their vertices.
GRID_TOL = 1e-13

#: Relative distance (times the domain diameter) under which a query point is
#: taken to be at a node or on a constraint edge in the shape functions.
SHAPE_TOL = 1e-12

#: A crack end that meets the boundary at a shallow angle lies within the snapping
#: tolerance of it along ``tol / sin(angle)``: accepted up to this many tolerances
#: (angles down to about 1 degree); `cnem.geometry.domain`.
SHALLOW_END = 100.0

#: A cell that the cloud cannot resolve is blamed on the boundary when the
#: boundary segments at its node are shorter than this fraction of the distance
#: to the nearest interior node (a fine outline around a coarse cloud); `cnem.geometry.cells`.
BOUNDARY_FINER = 0.25

#: Far from the origin the coordinates themselves are known only to their
#: round-off (``Frame.resolution``: ``eps`` times their magnitude): the shape
#: functions' node and edge tolerances are at least this many times it.
ROUNDOFF_ULPS = 16

#: A peridynamic bond whose length is within this fraction of the horizon above it is in
#: the family (its partial volume is then about 1/2): a horizon of a whole number of
#: lattice spacings, the usual choice, then takes the bonds at the horizon whatever the
#: round-off of their lengths, and the bonds do not jump as the horizon moves by
#: round-off; `cnem.pd.Body`.
HORIZON_RTOL = 1e-9

#: Two Dirichlet (or PD velocity) conditions on one dof agree when their values differ by
#: at most this fraction of the largest prescribed value (round-off of the same formula
#: evaluated twice); a larger difference is a conflict, refused by
#: `cnem.solvers.conditions.merged_conditions`.
CONDITION_RTOL = 1e-12

# ---------------------------------------------------------------- node generation
#: Interior nodes closer than this fraction of the local spacing to a boundary,
#: interface or crack are dropped (the boundary nodes stand there); `cnem.nodes`.
CLEARANCE = 0.5

#: Smallest node spacing `cnem.nodes` accepts, relative to the domain diameter
#: (ten snapping tolerances `SNAP_TOL`).
MIN_SPACING = 1e-8

#: Most nodes `cnem.nodes` generates (estimated before generating; above it
#: `cnem.errors.LimitError`).
MAX_NODES = 20_000_000

#: `cnem.nodes.from_points` fills a gap along a boundary, interface or crack edge
#: that spans more than this many local node spacings.
FILL_SPACINGS = 2.0

#: ... the local spacing at a user's point being its mean distance to this many
#: nearest others.
SPACING_NEIGHBOURS = 4

#: Node spacing laws are sampled along each boundary, interface and crack edge
#: until bisecting a sample interval changes its expected node count by less
#: than this ...
SPACING_COUNT_TOL = 0.01

#: ... or after this many bisections (then `cnem.errors.LimitError`).
SPACING_BISECTIONS = 200

# ---------------------------------------------------------------- numba kernels
#: Work items (points, cells, rows, queries) from which a kernel with parallel loops
#: runs its ``parallel=True`` copy; below, its serial copy (`cnem._parallel.parallel_kernel`).
#: Small models then never compile the parallel copies (several times the compile cost)
#: nor wait for a parallel region.
PARALLEL_MIN = 100_000

# ---------------------------------------------------------------- spatial search
#: Children per R-tree node (and boxes per leaf); a tree keeps the value it was
#: built with, so changing it affects trees built afterwards; `cnem.spatial.RTree`.
FANOUT = 16

#: Largest cloud `cnem.spatial.family_search(method="brute")` accepts (it tests
#: all n^2 pairs).
BRUTE_LIMIT = 20_000

#: Cells per horizon along each axis of the family search's cell list
#: (one horizon per point).
CELLS_PER_HORIZON = 2

#: Columns per horizon along the binned axes of the family search (one horizon for
#: all points), by the points' dimension (a single number serves both). Narrow columns
#: cost more windows per point, wide ones more candidates tested. Measured on 1M points
#: with a horizon of 3 spacings, 2 threads: in 3-D 1.5 (lattice 0.43 s, random 1.23 s,
#: best of 6 runs) against 3 (0.46-0.57 s, 1.38-1.53 s) and 2 (0.51 s, 1.07 s); in 2-D,
#: where the columns are strips, 3 (lattice 0.18 s, random 0.35 s, medians of 5)
#: against 2 (0.23 s, 0.43 s).
COLUMNS_PER_HORIZON = {2: 3.0, 3: 1.5}

#: `cnem.fem.mesh_domain` with a node target stops once the node count is within this
#: relative distance of the target ...
MESH_NODES_STOP = 0.02

#: ... or after this many meshes (a secant on log count against log max_area) ...
MESH_NODES_TRIES = 6

#: ... and warns when the best is further than this from the target (the coarsest
#: mesh is taken when it is this close).
MESH_NODES_RTOL = 0.05

# ---------------------------------------------------------------- linear solves
#: Above this many matrix non-zeros `cnem.solvers.linsolve.solve_spd` uses
#: pyamg-preconditioned CG: about 200k unknowns of linear triangles (12 non-zeros
#: per row), about 40k unknowns of an SCNI stiffness (~65 per row), whose sparse
#: factors fill in much faster (at 200k unknowns: 74 s direct against 7 s for
#: smoothed aggregation + CG, 36 iterations).
DIRECT_NNZ = 2_500_000

#: CG iterations `cnem.solvers.linsolve.solve_spd` allows before it calls a solve stalled.
CG_MAXITER = 2000

#: Memory a sparse direct factor may take when `solve_spd` falls back to it after a
#: stalled iterative solve: a fraction (at most 1) of the memory available when it is
#: asked, or bytes (above 1).
DIRECT_MEMORY = 0.5

#: ``(fill, unknowns, exponent)``: SuperLU's factor (COLAMD) holds about
#: ``fill (N / unknowns)^exponent`` times the matrix's non-zeros (measured on
#: branch-enriched SCNI stiffnesses: 7.3 at 6.3k unknowns, 14.9 at 40k; the rule is
#: 10 % above both).
DIRECT_FILL = (16.5, 40_000, 0.4)

#: Largest relative tolerance of the inner linear solve of a Newton step in
#: `cnem.pd.Problem.solve_static` (inexact Newton: ``min(NEWTON_FORCING, |R| / ref)``).
NEWTON_FORCING = 1e-3

#: Smallest relative tolerance asked of that inner linear solve (and of the one
#: solve of a linear problem).
NEWTON_INNER_FLOOR = 1e-12

# ---------------------------------------------------------------- fracture
#: Fewest Gauss points per cell-edge piece in the smoothing of the enrichment
#: functions (they vary like sqrt(r) about the tip, not like a rational
#: function); `cnem.fracture.enrichment`.
MIN_GAUSS = 4

# ---------------------------------------------------------------- peridynamics
#: Explicit PD dynamics refuses a time step above this many times Silling & Askari's
#: bound (`stable_time_step(safety=1)`, guaranteed stable) and warns between the two:
#: the critical step measured on uniform lattices (``2 / omega_max``, the largest
#: eigenvalue of ``M^-1 K``) is 1.7 (PMB) to 2.0 (state-based) times the bound.
DT_LIMIT = 2.0

#: CPD interactions evaluated together (bounds the temporaries: ~0.3 KB per 2-D pair).
CPD_CHUNK = 1 << 18

#: CPD pairs (triplets) whose reference area (volume) is below this fraction of
#: the product of their bond lengths are degenerate (collinear / coplanar): their
#: stretch is undefined and their reference measure, the energy's weight,
#: vanishes; they are left out.
CPD_DEGENERATE = 1e-8

#: A point of the state-based solid whose bonds broke takes its dilatation from the
#: moment tensor of its live bonds (`cnem.pd.moments.live_inverse`), restricted to the
#: directions in which that tensor keeps at least this fraction of the largest eigenvalue
#: of the reference one: a direction almost emptied of bonds carries no dilatation
#: (instead of a stiffness growing as 1 / eigenvalue).
LIVE_MOMENT_CUTOFF = 0.1

#: Most CPD pairs or triplets a body may hold (about 64 bytes each are stored);
#: above it `cnem.errors.LimitError`.
MAX_INTERACTIONS = 50_000_000

#: Relative step of the CPD finite differences (``derivatives="fd"``).
FD_STEP = 1e-4

# ---------------------------------------------------------------- hyper-dual numbers
#: Real numbers per part handed to the function in one call of
#: `cnem.hyperdual.derivatives` (bounds its temporaries).
HYPERDUAL_CHUNK = 2 ** 21

# ---------------------------------------------------------------- shape functions and SCNI
# (speed and memory only: results do not depend on them)

#: Cells whose boundary quadrature is built and evaluated in one pass of the SCNI
#: smoothed gradients (`cnem.assembly.passes`): bounds the memory of the points
#: and their shape functions, and keeps a pass in cache.
CELLS_PER_PASS = 10_000

#: Room per point for the shape-function rows written chunk by chunk
#: (`cnem.shape.natural`; doubled when a chunk overflows: points have about 5-6
#: natural neighbours on average).
ROW_SLOTS = 8

#: Points the walks of the point location cannot reach, as a fraction of the
#: triangles, above which they are located with an R-tree of the triangles
#: (`Model.triangle_tree`, built once) rather than of the circumcircles.
TRIANGLE_TREE_AFTER = 0.01

# ---------------------------------------------------------------- stress intensity factors
#: Nested integration discs of `cnem.fracture.sif` by default (3 to 6 make sense).
SIF_DISCS = 4

#: The largest default disc, as a fraction of the distance from the tip to the first
#: obstacle (a boundary, a hole, an interface, another crack or tip, a kink behind the
#: tip; `cnem.fracture.discs.clearance`): the disc stays clear of it.
SIF_REACH = 0.9

#: The smallest default disc as a fraction of the largest (smaller discs are less
#: accurate on every cloud measured: docs/fracture.md).
SIF_INNER = 0.5

#: The crack inside a disc of radius R may leave the straight line through the tip
#: by at most this times R (a kink or a curved path behind the tip limits the disc).
SIF_STRAIGHTNESS = 0.01

#: ... but a kink or bend limits the default discs to no fewer than this many local
#: node spacings (a kink one increment behind a growing tip would leave a disc of a
#: spacing or less, whose K is off by tens of %; six spacings was the old default).
SIF_BEND_SPACINGS = 6.0

#: Relative spread of K over the discs above which `cnem.fracture.sif` warns.
SIF_SPREAD = 0.01

#: Fewer local node spacings than this in the largest disc that fits: `sif` warns
#: (the discs cannot resolve the near-tip field; refine the nodes at the tip).
SIF_SPACINGS = 3.0

# ---------------------------------------------------------------- pictures
#: The largest side of a picture in pixels that `cnem.plot` accepts (larger windows make
#: VTK allocate more than any machine has and abort the interpreter).
PLOT_MAX_PIXELS = 16384

# ---------------------------------------------------------------- files
#: A solution's displacement at a cell vertex, written for ParaView, is interpolated at
#: the point this fraction of the way from the vertex to the cell's node: inside the
#: cell, so that a vertex on a crack face or the boundary takes the cell's side.
VERTEX_NUDGE = 1e-6
