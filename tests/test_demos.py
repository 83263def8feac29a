"""Every demo runs at a small size and returns the numbers it promises."""

import importlib.util
import pathlib

import numpy as np
import pytest
import shapely

import cnem
import cnem.io
from cnem.geometry import rectangle

DEMOS = pathlib.Path(__file__).resolve().parents[1] / "demos"


def _load(name):
    spec = importlib.util.spec_from_file_location(name, DEMOS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _has_pyvista():
    return importlib.util.find_spec("pyvista") is not None


@pytest.mark.parametrize("gamma", [30.0, 0.0])
def test_cracked_plate_geometry(tmp_path, gamma):
    demo = _load("cracked_plate_geometry")
    h, h_min, growth = 0.2, 0.04, 0.3
    plot = _has_pyvista() and gamma == 30.0
    res = demo.main(h=h, h_min=h_min, gamma_deg=gamma, growth=growth, outdir=tmp_path,
                    plot=plot, window_size=(300, 300))

    # the plate 2W = 2 is partitioned by the cells
    assert res["exact_area"] == 4.0
    assert abs(res["cell_area"] - 4.0) <= 1e-12 * 4.0
    assert res["area_error"] <= 1e-12
    assert res["n_cells"] == res["n_nodes"]          # one region: one cell per node

    # independently: the crack 2a = 0.2 through the origin at angle gamma
    g = np.deg2rad(gamma)
    tip = 0.1 * np.array([np.cos(g), np.sin(g)])
    np.testing.assert_allclose(np.sort(res["tips"], axis=0), np.sort([-tip, tip], axis=0),
                               atol=1e-15)
    dom = rectangle(2.0, 2.0, origin=(-1.0, -1.0), cracks=[[-tip, tip]])
    cloud = cnem.nodes.graded(dom, h, near=dom.tips, h_min=h_min, growth=growth)
    crack = shapely.LineString([-tip, tip])
    on_crack = shapely.distance(shapely.points(cloud.points), crack) <= 1e-12
    at_tip = np.linalg.norm(cloud.points[:, None] - np.array([-tip, tip])[None], axis=2) <= 1e-12
    assert res["n_points"] == len(cloud.points)
    assert res["n_crack_points"] == on_crack.sum() >= 3
    assert at_tip.sum() == 2 and on_crack[at_tip.any(axis=1)].all()
    assert res["n_split"] == on_crack.sum() - 2
    assert res["n_nodes"] == len(cloud.points) + on_crack.sum() - 2

    files = res["files"]
    assert pathlib.Path(files["vtu"]).stat().st_size > 0
    back = cnem.io.read(files["vtu"])
    assert len(back) == res["n_cells"]
    if plot:
        for key in ("cells", "tip"):
            assert pathlib.Path(files[key]).stat().st_size > 1000
            assert pathlib.Path(files[key]).parent == tmp_path


def test_bimaterial_cylinder_small(tmp_path):
    """The main demo at its smallest size writes its files and beats FEM P1."""
    demo = _load("bimaterial_cylinder")
    out = demo.main(((7, 21), (9, 35)), irregular=(False,), outdir=tmp_path,
                    plot=_has_pyvista())
    for f in out["files"]:
        assert pathlib.Path(f).stat().st_size > 0, f
    for row in out["rows"]:
        assert row["error"] < row["fem_error"], row
    read = cnem.io.read(tmp_path / "cylinder.vtu")
    assert read is not None


@pytest.mark.parametrize("irregular", [False, True])
def test_bimaterial_cylinder_matches_table_one(irregular):
    """Every cloud of the paper: the error (in the paper's ½-energy convention) is at
    or below Table I, and the fitted rate is at least 0.95 (paper Figure 13)."""
    demo = _load("bimaterial_cylinder")
    rows = demo.run(demo.GRIDS, irregular=(irregular,), fem=False)
    for row in rows:
        assert row["error"] / np.sqrt(2.0) <= row["paper"], row
    nodes = [r["nodes"] for r in rows]
    assert demo.rate(nodes, [r["error"] for r in rows]) >= 0.95
    # and against the exact solution directly: u_r at the nodes of the finest cloud
    sol = rows[-1]["solution"]
    x = sol.model.nodes
    r = np.hypot(x[:, 0], x[:, 1])
    exact = demo.exact_solution().radial_displacement(r)
    ur = (sol.u * x).sum(axis=1) / r
    assert np.abs(ur - exact).max() < 5e-3 * np.abs(exact).max()


def test_inclined_crack(tmp_path):
    """K_I, K_II of the inclined crack within 0.02 sigma sqrt(pi a) at both tips."""
    demo = _load("inclined_crack")
    out = demo.main((0.0, 45.0), outdir=tmp_path, plot=_has_pyvista())
    assert out["max_error"] < 0.02, out["rows"]
    assert out["max_enriched_error"] < 0.01, out["rows"]
    for row in out["rows"]:
        assert row["nodes"] <= 2000
    ahead = out["ahead"]
    assert np.median(np.abs(ahead["sigma_22"] / ahead["exact"] - 1)) < 0.05
    for f in out["files"]:
        assert pathlib.Path(f).stat().st_size > 0


def test_mode1_crack_small(tmp_path):
    """Plain C-NEM converges at about the singular rate 0.5, like FEM P1, on the
    paper's mode-I crack with exact tractions; enriched C-NEM at rate >= 0.9."""
    demo = _load("mode1_crack")
    out = demo.main((1 / 8, 1 / 16, 1 / 32), outdir=tmp_path, plot=_has_pyvista())
    assert 0.4 < out["rates"]["cnem"] < 0.65, out["rates"]
    assert 0.35 < out["rates"]["fem"] < 0.65, out["rates"]
    assert out["rates"]["enriched"] >= 0.9, out["rates"]
    finest = [r for r in out["rows"] if r["method"] == "cnem"][-1]
    assert abs(finest["KI"] - 1.0) < 0.05


def test_pd_vs_cnem_crack_small(tmp_path):
    """On the same nodes, C-NEM and state-based PD open the crack like Griffith's
    ellipse (within the finite-plate excess) and agree with each other."""
    demo = _load("pd_vs_cnem_crack")
    out = demo.main((1 / 16, 1 / 32), outdir=tmp_path, plot=True)
    for row in out["rows"]:
        assert row["cnem_error"] < 0.15 and row["pd_error"] < 0.15, row
    assert out["rows"][1]["u_difference"] < out["rows"][0]["u_difference"]
    assert abs(out["rows"][1]["K_cnem"] / np.sqrt(np.pi * 0.25) - 1.0) < 0.08


def test_pd_crack_branching_quick(tmp_path):
    """Dynamic fracture of the pre-notched glass plate (quick size): the crack runs right
    from the notch tip, slower than Rayleigh waves, only along its path, and branches;
    the branch measurement recovers a drawn Y-shaped crack."""
    demo = _load("pd_crack_branching")

    # the measurement alone: a stem to x = 60 mm, then two straight arms at +-20 degrees
    h, horizon = 0.25e-3, 1e-3
    points, shape = demo.plate(h)
    X, Y = (points[:, k].reshape(shape) for k in (0, 1))
    stem = (X > 0.05) & (X <= 0.06) & (np.abs(Y) < h)
    arms = (X > 0.06) & (X < 0.08) & (np.abs(np.abs(Y) - np.tan(np.radians(20.0)) * (X - 0.06)) < h)
    drawn = demo.branching(stem | arms, h, horizon)
    assert abs(drawn["x"] - 0.06) < h and abs(drawn["y"]) < h
    assert abs(drawn["half_angle"] - 20.0) < 0.5
    assert demo.branching(stem, h, horizon) is None

    out = demo.main(**demo.QUICK, outdir=tmp_path, plot=True, progress=False)
    mat, nu = demo.MATERIALS["soda-lime"], 1.0 / 3.0
    # Rayleigh speed, Viktorov's approximation with the plane-stress ratio nu / (1 + nu)
    nu_ps = nu / (1.0 + nu)
    c_s = np.sqrt(mat["E"] / (2.0 * (1.0 + nu)) / mat["density"])
    c_r = c_s * (0.862 + 1.14 * nu_ps) / (1.0 + nu_ps)
    assert abs(out["rayleigh"] / c_r - 1.0) < 0.01

    tip, notch = out["tip"], 0.05
    assert (np.diff(tip) >= 0).all()
    assert tip[0] == notch and tip[-1] - notch > 0.015            # the crack ran to the right
    assert 0.0 < out["t_init"] < 15e-6
    assert 0.0 < out["speed"] < c_r and out["speed"] <= out["max_speed"] < c_r

    damage, x, y = out["damage"], out["points"][:, 0], out["points"][:, 1]
    assert damage.min() >= 0.0 and damage.max() <= 1.0 and damage.max() > 0.35
    # no damage behind the notch tip (left corners, notch flanks) nor at the loaded edges
    near_path = (x > notch - 2 * 2e-3) & (np.abs(y) < 0.015)
    assert (damage[~near_path] == 0).all()

    # the crack branches ahead of the notch, the branches diverging
    assert notch < out["branch_x"] < 0.085
    assert out["t_init"] < out["branch_time"] < 30e-6
    assert 10.0 < out["half_angle"] < 45.0

    # energy: balanced while no bond is broken; bond breaking dissipates at least about
    # the Griffith energy G0 of the crack path
    assert out["energy_error"] < 0.02
    assert 0.9 < out["dissipated"] / out["griffith"] < 3.0
    for f in out["files"]:
        assert pathlib.Path(f).stat().st_size > 1000


def test_growth_sent_small(tmp_path):
    demo = _load("growth_sent")
    res = demo.main(0.05, increment=0.1, outdir=tmp_path, plot=False, progress=False)
    assert [r["a"] for r in res["rows"]] == pytest.approx([0.2, 0.3, 0.4, 0.5, 0.6])
    assert res["max_kink_deg"] < 0.1                  # the symmetric cloud keeps the path straight
    assert res["max_error"] < 0.05                    # K_I against the handbook (coarse cloud)


def test_growth_kink_small(tmp_path):
    demo = _load("growth_kink")
    res = demo.main((30.0,), cloud=(0.8, 0.005, 0.3), outdir=tmp_path, plot=False, progress=False)
    assert res["rows"][0]["exact_deg"] == pytest.approx(-43.22, abs=0.01)
    assert res["max_error_deg"] < 1.0


def test_growth_two_holes_small(tmp_path):
    demo = _load("growth_two_holes")
    res = demo.main(0.5, steps=2, outdir=tmp_path, plot=False, progress=False)
    tips = res["tips"]
    assert np.hypot(*(tips[1:] - tips[:-1]).transpose(2, 0, 1)) == pytest.approx(1.0, rel=1e-9)
    assert np.all(np.diff(tips[:, 0, 0]) > 0) and np.all(np.diff(tips[:, 1, 0]) < 0)
    # the plate is point-symmetric about its centre: so are the two paths (to the cloud's asymmetry)
    assert np.abs(tips[:, 0] + tips[:, 1] - [20.0, 10.0]).max() < 0.15
