"""Pictures (cnem.plot): a non-empty, non-uniform PNG in the region colours."""

import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

import cnem.plot  # noqa: E402
from cases import model  # noqa: E402


def _rgb(path):
    """(height, width, 3) int64 pixels of a PNG (read with VTK, which pyvista brings)."""
    image = pv.read(path)
    nx, ny, _ = image.dimensions
    pixels = np.asarray(image.point_data.active_scalars)
    return pixels.reshape(ny, nx, -1)[::-1, :, :3].astype(np.int64)


def _has_color(img, rgb, tol=2):
    return np.count_nonzero(np.abs(img - np.asarray(rgb, np.int64)).max(axis=-1) <= tol)


def test_bimaterial_picture_shows_both_regions(tmp_path):
    _, _, m = model("annulus_sector_regular")
    path = tmp_path / "annulus.png"
    pl = cnem.plot.model(m, path, window_size=(400, 400))
    pl.close()
    assert path.stat().st_size > 1000
    img = _rgb(path)
    assert img.shape == (400, 400, 3)
    assert img.reshape(-1, 3).var(axis=0).sum() > 0
    for r in (0, 1):
        assert _has_color(img, cnem.plot.region_color([r])[0]) > 0.02 * 400 * 400, r
    assert not _has_color(img, (255, 0, 0), tol=30)      # no crack here


def test_cracked_picture_shows_red_crack(tmp_path):
    _, _, m = model("graded_inclined_crack")
    path = tmp_path / "crack.png"
    cnem.plot.model(m, path, window_size=(400, 400)).close()
    img = _rgb(path)
    assert _has_color(img, cnem.plot.region_color([0])[0]) > 0.2 * 400 * 400
    assert _has_color(img, (255, 0, 0), tol=30) > 50
    path2 = tmp_path / "nocrack.png"
    cnem.plot.model(m, path2, window_size=(400, 400), show_cracks=False).close()
    assert not _has_color(_rgb(path2), (255, 0, 0), tol=30)


def test_cells_polydata_matches_cells():
    _, _, m = model("annulus_full_irregular")
    poly = cnem.plot.cells_polydata(m)
    assert poly.n_cells == len(m.cells)
    np.testing.assert_array_equal(poly.cell_data["region"], m.cells.region)
    np.testing.assert_array_equal(poly.cell_data["node"], m.cells.node)
    # every polygon has the cell's vertices, in order (parse the VTK face stream)
    faces, pts = np.asarray(poly.faces), np.asarray(poly.points)
    k = 0
    for i in range(len(m.cells)):
        size = faces[k]
        np.testing.assert_array_equal(pts[faces[k + 1:k + 1 + size], :2], m.cells.polygon(i))
        k += 1 + size
    assert k == len(faces)
    assert np.all(pts[:, 2] == 0)


def test_bad_bounds(tmp_path):
    _, _, m = model("graded_inclined_crack")
    with pytest.raises(cnem.plot.PlotError, match="bounds"):
        cnem.plot.model(m, bounds=(1.0, 0.0, 0.0, 1.0))   # xmin > xmax


def test_field_per_cell_keeps_its_jump_at_the_interface(tmp_path):
    """A field with one value per cell is drawn on the cells (default): a field that
    jumps from 0 to 1 at a material interface shows only the colour map's two ends in
    the body, while averaged to the nodes (cellwise=False) the triangles across the
    interface blend them (the colour bar holds the blend in both pictures)."""
    _, _, m = model("annulus_sector_regular")
    prob = cnem.Elasticity(m, [(1.0, 0.3), (2.0, 0.3)], plane="strain")
    prob.add_dirichlet(lambda p: np.ones(len(p), dtype=bool), None, lambda p: 1e-3 * p)
    sol = prob.solve(progress=False)
    jump = np.asarray(sol.cells.region, dtype=float)
    assert set(np.unique(jump)) == {0.0, 1.0}
    middle = (33, 145, 140)                          # viridis at 0.5
    counts = {}
    for cellwise in (True, False):
        path = tmp_path / f"jump_{cellwise}.png"
        cnem.plot.solution(sol, path, field=jump, window_size=(400, 400), title="region",
                           cellwise=cellwise).close()
        counts[cellwise] = _has_color(_rgb(path), middle, tol=25)
    assert counts[False] > 3 * counts[True] + 100, counts


@pytest.mark.parametrize("span", [3e-6, 1.0, 2.0, 4.99, 5.0, 7.3, 1e4 / 3])
def test_scale_bar_length_is_round_and_about_a_fifth(span):
    """The scale bar: 1, 2 or 5 times a power of ten, between a twelfth and a fifth of the
    width shown, at any size of model."""
    length = cnem.plot.nice_length(span)
    mantissa = length / 10.0 ** np.floor(np.log10(length) + 1e-12)
    assert min(abs(mantissa - m) for m in (1.0, 2.0, 5.0)) < 1e-9, length
    assert span / 12.5 < length <= span / 5 * (1 + 1e-12)


def test_every_field_has_a_symbol():
    assert set(cnem.plot.FIELD_LABELS) == set(cnem.plot.SOLUTION_FIELDS)


def test_field_symbols_are_mathtext_that_vtk_draws():
    """The colour-bar symbols are matplotlib mathtext (``$\\sigma_{xx}$``, as the matplotlib
    pictures write them) that parses, and VTK has its matplotlib math-text renderer, so the
    pyvista pictures show symbols, not ``$`` and underscores."""
    from matplotlib.mathtext import MathTextParser
    from vtkmodules.vtkRenderingFreeType import vtkMathTextUtilities

    parser = MathTextParser("path")
    for label in cnem.plot.FIELD_LABELS.values():
        assert label.startswith("$") and label.endswith("$") and label.count("$") == 2, label
        parser.parse(label)                       # raises on TeX that mathtext cannot draw
    cnem.plot.fields._pyvista().Plotter(off_screen=True).close()
    assert vtkMathTextUtilities.GetInstance() is not None


@pytest.mark.parametrize("size", [(-5, -5), (100000, 100000), (0, 0), (1200.5, 900), 800,
                                  (True, 10), (10, 10, 10)])
def test_a_window_vtk_cannot_make_is_refused(size, tmp_path):
    """Negative or huge windows made VTK abort the interpreter and (0, 0) divided by zero:
    they are refused before VTK sees them, with what to give instead."""
    with pytest.raises(cnem.PlotInputError, match="window_size"):
        cnem.plot.model(model("annulus_sector_regular")[2], tmp_path / "m.png", window_size=size)


def test_a_non_finite_scale_is_refused(tmp_path):
    mdl = model("annulus_sector_regular")[2]
    prob = cnem.Elasticity(mdl, (1.0, 0.3))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1.0, 0.0])
    sol = prob.solve(progress=False)
    with pytest.raises(cnem.PlotInputError, match="scale"):
        cnem.plot.solution(sol, tmp_path / "s.png", scale=float("nan"))


@pytest.mark.parametrize("scale", [float("nan"), float("inf"), [1.0, 2.0]])
@pytest.mark.parametrize("run", ["static", "dynamic"])
def test_a_non_finite_scale_is_refused_for_peridynamic_results(run, scale, tmp_path):
    """A PD result's picture (points moved by scale * u) refuses a scale that is not one
    finite number, by name, as the C-NEM one does."""
    h = 0.25
    lattice = np.array([(x, y) for x in np.arange(5) * h for y in np.arange(5) * h])
    prob = cnem.pd.Problem(cnem.pd.Body(lattice, h * h, 3.04 * h), cnem.pd.BondBased(1.0))
    prob.add_dirichlet(lambda p: p[:, 0] < 1e-9, None)
    prob.add_body_force([1.0, 0.0])
    sol = prob.solve_static() if run == "static" else \
        prob.run_dynamic(1e-3, 2, velocity=np.ones((len(lattice), 2)), progress=False)
    with pytest.raises(cnem.PlotInputError, match="scale: expected a finite number"):
        sol.plot(tmp_path / "s.png", scale=scale)


def test_a_model_that_is_none_and_a_path_that_is_no_picture_are_named(tmp_path):
    with pytest.raises(cnem.InputError, match="expects a Model, received NoneType"):
        cnem.plot.model(None, tmp_path / "m.png")
    with pytest.raises(cnem.PlotInputError, match="picture file ending in one of"):
        cnem.plot.model(model("annulus_sector_regular")[2], tmp_path / "m.bogus")
