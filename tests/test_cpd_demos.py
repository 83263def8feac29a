"""The CPD examples of `demos/cpd_examples.py` (Javili et al. §6) at their quick sizes:
Newton converges quadratically in every load step, and each example shows its physics."""

import importlib.util
import pathlib

import numpy as np
import pytest

from cnem import cli

DEMO = pathlib.Path(__file__).resolve().parents[1] / "demos" / "cpd_examples.py"
HAS_PYVISTA = importlib.util.find_spec("pyvista") is not None


@pytest.fixture(scope="module")
def demo():
    spec = importlib.util.spec_from_file_location("cpd_examples", DEMO)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def common(demo):
    """``demos/cpd/common.py`` (importable once the demo has been loaded)."""
    return importlib.import_module("cpd.common")


@pytest.fixture(scope="module")
def results(demo, tmp_path_factory):
    return demo.main(quick=True, outdir=tmp_path_factory.mktemp("cpd"), plot=HAS_PYVISTA)


def histories(result):
    """Every Newton history of one example's result."""
    runs = result.get("cases") or result.get("runs") or result.get("results")
    return [h for r in runs.values() for h in r["history"]] if runs else result["history"]


def quadratic_pairs(history, *, asymptotic=1e-3, floor=1e-12):
    """``(r_k, r_{k+1})`` of the last iterations of one load step, residuals scaled by the
    step's first (the solver's own reference): ``r_k`` in the asymptotic range, and
    ``r_{k+1}`` above the round-off floor (``floor`` times the step's largest residual)."""
    h = np.asarray(history)
    return [(a / h[0], b / h[0]) for a, b in zip(h[:-1], h[1:])
            if a < asymptotic * h[0] and b > floor * h.max()]


@pytest.mark.parametrize("example", ["tension2d", "cube", "cantilever", "torsion", "lshape"])
def test_newton_converges_quadratically(results, example):
    """r_{k+1} <= 1000 r_k^2 near the solution (residuals relative to the step's first):
    an inexact tangent (relative error q) gives r_{k+1} ~ q r_k and fails it once
    r_k < q / 1000, which the last iterations reach for any q above ~1e-7."""
    steps = histories(results[example])
    assert steps
    checked = 0
    for history in steps:
        assert history[-1] <= 1e-8 * max(history), history            # converged
        for a, b in quadratic_pairs(history):
            assert b <= 1000.0 * a * a, (example, history)
            checked += 1
    assert checked >= 1, steps


def test_tension_large_c2_preserves_area(results):
    cases = results["tension2d"]["cases"]
    free, area = cases["C2=0"], cases["C2>>C1"]
    assert free["area_ratio"] > 1.1                       # bonds alone: the area grows
    assert abs(area["area_ratio"] - 1) < abs(free["area_ratio"] - 1) / 5
    assert abs(area["central_area_ratio"] - 1) < abs(free["central_area_ratio"] - 1) / 5
    # stretched twice as long at constant area: half as wide
    assert abs(area["lateral_stretch"] - 0.5) < 0.05
    assert area["lateral_stretch"] < free["lateral_stretch"] < 1


def test_cube_one_neighbour_contracts_least_three_keeps_volume(results):
    cases = results["cube"]["cases"]
    assert cases["one"]["lateral_stretch"] > max(cases["two"]["lateral_stretch"],
                                                  cases["three"]["lateral_stretch"])
    assert abs(cases["three"]["volume_ratio"] - 1) < abs(cases["one"]["volume_ratio"] - 1) / 5
    assert abs(cases["three"]["lateral_stretch"] - 1 / np.sqrt(2)) < 0.05


def test_cantilever_bends_with_the_load_and_stiffens_with_c1(results):
    runs = results["cantilever"]["runs"]
    C1s = sorted(runs)
    tips = np.array([runs[c]["tip"] for c in C1s])
    assert (tips[:, 1] < 0).all()                          # the load points down
    assert (np.diff(np.abs(tips[:, 1])) < 0).all()         # stiffer, less deflection
    assert (tips[:, 0] < 0).all()                          # a bent beam's end moves back


def test_torsion_turns_every_section_in_the_load_sense(results, demo):
    res = results["torsion"]
    angle = demo.QUICK["torsion"]["angle"]
    rotation = res["rotation"]
    assert abs(rotation[0]) < 1e-9 and abs(rotation[-1] - angle) < 1e-6
    assert (np.diff(rotation) > 0).all()                   # more with height, same sense
    middle = np.interp(0.5 * res["z"][-1], res["z"], rotation)
    assert 0.25 * angle < middle < 0.75 * angle


def test_lshape_larger_horizon_lowers_the_corner_peak(results):
    per = results["lshape"]["results"]
    horizons = sorted(per)
    corner = [per[m]["corner"] for m in horizons]
    assert (np.diff(corner) < 0).all()
    smallest = per[horizons[0]]                            # the most local: peak at the corner
    assert smallest["corner"] == max(smallest["row"].max(), smallest["column"].max())


@pytest.mark.skipif(not HAS_PYVISTA, reason="pyvista not installed")
def test_every_example_writes_its_picture(results):
    for name, res in results.items():
        assert res["files"], name
        for f in res["files"]:
            assert pathlib.Path(f).stat().st_size > 1000, f


@pytest.mark.parametrize("dim", [2, 3])
def test_lattice_measure_of_an_affine_map(common, dim):
    rng = np.random.default_rng(dim)
    counts = (4, 3, 5)[:dim]
    x = common.lattice(counts, 0.5)
    F = np.eye(dim) + 0.3 * rng.standard_normal((dim, dim))
    cells = common.lattice_measure(x @ F.T + 1.0, counts)
    assert cells.shape == tuple(c - 1 for c in counts)
    np.testing.assert_allclose(cells, np.linalg.det(F) * 0.5 ** dim, rtol=1e-12)


def test_bad_options_are_named(demo):
    with pytest.raises(ValueError, match="expected names from .*received \\['bending'\\]"):
        demo.main(("bending",))
    with pytest.raises(SystemExit) as done:
        cli.main(["pd", "cpd", "--example", "bending"])
    assert done.value.code == 2


def test_cnem_pd_cpd_runs_the_demo(tmp_path, capsys):
    cli.main(["pd", "cpd", "--example", "lshape", "--quick", "--no-plot", "--out",
              str(tmp_path)])
    assert "delta/D" in capsys.readouterr().out
