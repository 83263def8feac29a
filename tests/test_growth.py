"""Crack growth (`cnem.fracture.grow`): criteria, symmetry and invariance of paths,
events, Paris-law life. Small clouds: physics, not timings."""

import dataclasses
import warnings

import numpy as np
import pytest

import cnem
from cnem.errors import GeometryError, GrowthError, GrowthWarning
from cnem.fracture import grow, kink, nodal_williams
from cnem.fracture.criteria import hoop_angle

E, NU = 1.0, 0.3


# ------------------------------------------------------------------ criteria
@pytest.mark.parametrize("KI, KII", [(1.0, 0.0), (1.0, 0.3), (1.0, -0.7), (0.2, 1.0), (0.0, 1.0)])
def test_max_hoop_is_the_closed_form_and_a_maximum_of_the_hoop_stress(KI, KII):
    theta, K_eq, at_bound = kink("max_hoop", KI, KII)
    expect = 0.0 if KII == 0 else 2 * np.arctan((KI - np.sqrt(KI ** 2 + 8 * KII ** 2)) / (4 * KII))
    assert theta == pytest.approx(expect, abs=1e-14) and not at_bound
    # sigma_thetatheta sqrt(2 pi r) along the ray: largest at theta, equal to K_eq there
    t = np.linspace(-np.pi + 1e-3, np.pi - 1e-3, 20001)
    c = np.cos(t / 2)
    hoop = c * (KI * c * c - 1.5 * KII * np.sin(t))
    assert t[np.argmax(hoop)] == pytest.approx(theta, abs=1e-3)
    assert K_eq == pytest.approx(hoop.max(), rel=1e-6)


@pytest.mark.parametrize("criterion", ["max_hoop", "max_energy_release", "min_sed"])
def test_criteria_mode_one_is_straight_and_mode_two_sign_flips_the_kink(criterion):
    kap = 3 - 4 * NU
    theta, K_eq, _ = kink(criterion, 1.0, 0.0, kappa=kap)
    assert abs(theta) < 1e-6 and K_eq == pytest.approx(1.0, rel=1e-9)
    plus, minus = kink(criterion, 1.0, 0.4, kappa=kap)[0], kink(criterion, 1.0, -0.4, kappa=kap)[0]
    assert plus < 0 and minus == pytest.approx(-plus, abs=1e-8)


def test_pure_mode_two_angles_of_the_numerical_criteria():
    kap = 3 - 4 * NU
    # Sih: S'(theta) = 0 for pure mode II gives cos(theta) = (kappa - 1) / 6
    assert kink("min_sed", 0.0, 1.0, kappa=kap)[0] == pytest.approx(-np.arccos((kap - 1) / 6), abs=1e-7)
    # Hussain, Pu & Underwood: maximum G of pure mode II at about -75.2 degrees
    assert np.degrees(kink("max_energy_release", 0.0, 1.0)[0]) == pytest.approx(-75.2, abs=0.1)


def test_bad_criterion_and_arguments_raise_growth_errors():
    with pytest.raises(GrowthError, match="criterion"):
        kink("max_stress", 1.0, 0.0)
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.4, 0.5]]])
    for kwargs in (dict(increment=-1.0, steps=1), dict(increment=0.1, steps=1.5),
                   dict(increment=0.1, steps=1, criterion="x"), dict(increment=0.1, steps=1, paris=(1.0,))):
        with pytest.raises(GrowthError):
            grow(dom, 0.2, lambda m: None, progress=False, **kwargs)


# ------------------------------------------------------- imposed Williams fields
def williams_setup(KI, KII):
    """The exact near-tip field of the model's (current) tip on the outer boundary."""
    def setup(model):
        prob = cnem.Elasticity(model, (E, NU), plane="strain")
        exact = nodal_williams(model, model.domain.tips[0], KI, KII, E, NU, "strain")
        outer = np.unique(model.segments[model.segment_kind == 0])
        prob.add_dirichlet(outer, None, lambda p: exact[outer])
        return prob
    return setup


def transformed_cloud(cloud, domain, matrix, offset=(0.0, 0.0)):
    """The same nodes mapped by ``x -> matrix x + offset`` (``matrix`` 2 x 2) as a cloud of
    the mapped domain (spacing scaled with the map)."""
    def place(x):
        return np.asarray(x) @ matrix.T + offset
    regions = [place(np.asarray(p.exterior.coords)[:-1]) for p in domain.regions]
    dom = cnem.Domain(regions, cracks=[place(c) for c in domain.cracks])
    mapped = cnem.nodes.from_points(dom, place(cloud.points))
    scale = np.sqrt(abs(np.linalg.det(matrix)))
    return dom, dataclasses.replace(mapped, spacing=cloud.spacing * scale)


@pytest.fixture(scope="module")
def williams_runs():
    """One mixed-mode run, the same rotated by 0.7 rad and mirrored about x = 0 (a mirror
    flips the sign of K_II in the crack's frame)."""
    dom = cnem.geometry.rectangle(1.0, 1.0, origin=(-0.5, -0.5), cracks=[[[-0.5, 0.0], [0.0, 0.0]]])
    cloud = cnem.nodes.irregular(dom, 0.06, seed=3)
    c, s = np.cos(0.7), np.sin(0.7)
    out = {"base": (np.eye(2), grow(dom, cloud, williams_setup(1.0, 0.4), increment=0.05, steps=2,
                                    progress=False))}
    for name, m in (("rotated", np.array([[c, -s], [s, c]])), ("mirrored", np.diag([-1.0, 1.0]))):
        d, cl = transformed_cloud(cloud, dom, m)
        setup = williams_setup(1.0, 0.4 * np.linalg.det(m))
        out[name] = (m, grow(d, cl, setup, increment=0.05, steps=2, progress=False))
    return out


@pytest.mark.slow
def test_kink_under_imposed_williams_field_matches_the_closed_form(williams_runs):
    hist = williams_runs["base"][1]
    K = hist.steps[0].K[0]
    assert K == pytest.approx([1.0, 0.4], abs=0.02)          # docs/fracture.md: 2 % at h = 0.1
    assert hist.steps[0].angle[0] == pytest.approx(hoop_angle(1.0, 0.4), abs=np.radians(0.5))
    # the tip moved by the increment in that direction
    step = hist.steps[1].tips[0] - hist.steps[0].tips[0]
    assert np.hypot(*step) == pytest.approx(0.05, rel=1e-12)
    assert np.arctan2(step[1], step[0]) == pytest.approx(hist.steps[0].angle[0], abs=1e-12)


@pytest.mark.parametrize("name", ["rotated", "mirrored"])
def test_transformed_problem_gives_the_transformed_path(williams_runs, name):
    base = williams_runs["base"][1].paths()[:, 0]
    m, hist = williams_runs[name]
    assert np.abs(hist.paths()[:, 0] - base @ m.T).max() < 1e-3 * 0.05
    sign = np.sign(np.linalg.det(m))
    assert hist.array("angle")[:-1, 0] == pytest.approx(sign * williams_runs["base"][1].array("angle")[:-1, 0],
                                                         abs=1e-4)


@pytest.mark.parametrize("offset, scale", [((1e6, -3e6), 1.0), ((5e6, 4e6), 100.0),
                                           ((0.0, 0.0), 1e-3)])
def test_moved_and_scaled_problem_gives_the_moved_and_scaled_path(williams_runs, offset, scale):
    """Far from the origin (UTM-like coordinates) and in other units, the path is the
    base path moved and scaled, to a small multiple of the coordinates' round-off; the
    kink angles are the base's."""
    dom = cnem.geometry.rectangle(1.0, 1.0, origin=(-0.5, -0.5), cracks=[[[-0.5, 0.0], [0.0, 0.0]]])
    cloud = cnem.nodes.irregular(dom, 0.06, seed=3)
    m = scale * np.eye(2)
    d, cl = transformed_cloud(cloud, dom, m, offset)
    hist = grow(d, cl, williams_setup(1.0, 0.4), increment=0.05 * scale, steps=2, progress=False)
    base = williams_runs["base"][1]
    moved = base.paths()[:, 0] / 0.05
    assert np.abs((hist.paths()[:, 0] - offset) / (0.05 * scale) - moved).max() < 1e-6
    assert hist.array("angle")[:-1, 0] == pytest.approx(base.array("angle")[:-1, 0], abs=1e-8)


# ----------------------------------------------------------------- SENT in tension
def tension_setup(W, H):
    def setup(model):
        tol = 1e-9 * W
        prob = cnem.Elasticity(model, (E, NU), plane="strain")
        prob.add_traction(lambda x, n: np.abs(np.abs(x[:, 1] - 0.5 * H) - 0.5 * H) < tol,
                          lambda x, n: n * [0.0, 1.0])
        prob.add_dirichlet(lambda p: np.hypot(p[:, 0] - W, p[:, 1]) < tol, None)
        prob.add_dirichlet(lambda p: np.hypot(p[:, 0] - W, p[:, 1] - H) < tol, 0)
        return prob
    return setup


@pytest.fixture(scope="module")
def sent_run():
    dom = cnem.geometry.rectangle(1.0, 2.0, cracks=[[[0.0, 1.0], [0.3, 1.0]]])
    top = lambda sol: float(sol.displacement(np.array([[0.5, 2.0]]))[0, 1])   # noqa: E731
    return grow(dom, cnem.nodes.regular(dom, 0.05), tension_setup(1.0, 2.0), increment=0.05,
                steps=2, K_Ic=2.0, measure=top, progress=False)


def test_symmetric_problem_grows_on_its_symmetry_line(sent_run):
    hist = sent_run
    tips = hist.paths()[:, 0]
    assert np.abs(tips[:, 1] - 1.0).max() < 1e-9
    assert tips[:, 0] == pytest.approx([0.3, 0.35, 0.4], abs=1e-12)
    K = hist.array("K")[:, 0]
    assert np.abs(K[:, 1]).max() < 1e-6 * K[:, 0].min()
    assert np.all(np.diff(K[:, 0]) > 0)                              # K_I grows with a
    assert hist.array("load_factor")[:, 0] == pytest.approx(2.0 / hist.array("K_eq")[:, 0])
    # a longer crack: a more compliant strip
    assert np.all(np.diff(hist.array("measure")) > 0)


def test_history_writes_one_frame_per_state_and_its_pictures(sent_run, tmp_path):
    import cnem.io
    files = sent_run.write(tmp_path / "frames")
    assert [f.name for f in files] == ["step_000.vtu", "step_001.vtu", "step_002.vtu"]
    for f, state in zip(files, sent_run.steps + [sent_run.final]):
        mesh = cnem.io.read(f)
        assert np.array_equal(mesh.nodes, state.solution.model.nodes)
        assert mesh.area.sum() == pytest.approx(2.0, rel=1e-12)
    pvd = (tmp_path / "frames" / "steps.pvd").read_text()          # the series, over the step
    assert pvd.count("<DataSet ") == 3 and 'timestep="2.0"' in pvd and "step_002.vtu" in pvd
    for kind in ("paths", "sif", "load"):
        sent_run.plot(tmp_path / f"{kind}.png", kind=kind)
        assert (tmp_path / f"{kind}.png").stat().st_size > 10_000
    with pytest.raises(GrowthError, match="kind"):
        sent_run.plot(kind="map")


def test_history_writes_its_k_table_as_csv_and_json(sent_run, tmp_path):
    """``sif.csv`` and ``sif.json`` read back with the standard library hold, per state
    and tip, the history's own arrays (NaN as ``nan`` in the CSV, ``null`` in the JSON)."""
    import csv
    import json
    sent_run.write(tmp_path)
    with open(tmp_path / "sif.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    data = json.loads((tmp_path / "sif.json").read_text())
    assert data["criterion"] == sent_run.criterion
    assert len(rows) == len(data["records"]) == 3                 # 3 states, 1 tip
    for name, column in (("tips", ["x", "y"]), ("K", ["K_I", "K_II"]), ("K_eq", ["K_eq"]),
                         ("crack_length", ["crack_length"]), ("load_factor", ["load_factor"]),
                         ("increment", ["increment"])):
        expected = sent_run.array(name)[:, 0].reshape(3, -1)
        from_csv = np.array([[float(r[c]) for c in column] for r in rows])
        from_json = np.array([[r[c] for c in column] for r in data["records"]], dtype=float)
        np.testing.assert_array_equal(from_csv, expected, err_msg=name)
        np.testing.assert_array_equal(from_json, expected, err_msg=name)
    np.testing.assert_array_equal([float(r["angle_deg"]) for r in rows],
                                  np.degrees(sent_run.array("angle")[:, 0]))
    assert [int(r["step"]) for r in rows] == [0, 1, 2] and {r["tip"] for r in rows} == {"0"}
    assert all(np.isnan(float(r["cycles"])) for r in rows)            # no Paris law
    assert all(r["cycles"] is None for r in data["records"])
    assert list(rows[0]) == list(sent_run.COLUMNS)
    table = sent_run.table().splitlines()                           # the same rows as text
    assert len(table) == 1 + 3 + len(sent_run.events)
    assert [float(line.split()[5]) for line in table[1:4]] == \
        pytest.approx(sent_run.array("K")[:, 0, 0], rel=1e-3)


def test_tip_into_the_far_edge_splits_the_body_with_the_pieces_named():
    dom = cnem.geometry.rectangle(1.0, 2.0, cracks=[[[0.0, 1.0], [0.88, 1.0]]])
    with pytest.raises(GeometryError, match="2 pieces") as info, \
            pytest.warns(GrowthWarning, match="left_domain"):
        grow(dom, cnem.nodes.regular(dom, 0.05), tension_setup(1.0, 2.0), increment=0.2, steps=2,
             progress=False)
    hist = info.value.history
    assert [e.kind for e in hist.events] == ["left_domain", "boundary"]
    assert hist.cracks[0][-1] == pytest.approx([1.0, 1.0])


# ---------------------------------------------------------------------- events
def uniaxial_setup(sigma, **options):
    """Unit square, traction sigma along y on top and bottom, rigid motions held
    (``options``: more arguments of the problem)."""
    def setup(model):
        tol = 1e-9
        prob = cnem.Elasticity(model, (E, NU), plane="strain", **options)
        prob.add_traction(lambda x, n: np.abs(np.abs(x[:, 1] - 0.5) - 0.5) < tol,
                          lambda x, n: sigma * n * [0.0, 1.0])
        prob.add_dirichlet(lambda p: np.hypot(*p.T) < tol, None)
        prob.add_dirichlet(lambda p: np.hypot(p[:, 0] - 1.0, p[:, 1]) < tol, 1)
        return prob
    return setup


def test_tip_reaching_the_boundary_stops_and_the_crack_becomes_an_edge_crack():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.55, 0.5], [0.85, 0.5]]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        hist = grow(dom, cnem.nodes.regular(dom, 0.05), uniaxial_setup(1.0), increment=0.1, steps=3,
                    progress=False)
    kinds = [(e.kind, e.step) for e in hist.events]
    right = int(np.argmax(hist.steps[0].tips[:, 0]))
    assert ("left_domain", 1) in kinds and ("boundary", 1) in kinds
    assert any(issubclass(w.category, GrowthWarning) and "left_domain" in str(w.message) for w in caught)
    assert not hist.final.active[right] and hist.final.active[1 - right]
    assert len(hist.domain.tips) == 1 and hist.steps[2].increment[right] == 0
    assert np.isnan(hist.final.K[right]).all()


def test_tip_meeting_the_tip_of_another_crack_joins_it():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.25, 0.5], [0.42, 0.5]], [[0.58, 0.5], [0.75, 0.5]]])
    hist = grow(dom, cnem.nodes.regular(dom, 0.05), uniaxial_setup(1.0), increment=0.08, steps=1,
                progress=False)
    assert "joined" in [e.kind for e in hist.events]
    assert len(hist.cracks) == 1 and len(hist.domain.tips) == 2
    assert hist.final.active.sum() == 2


def test_compression_closes_the_crack_and_nothing_grows():
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.3, 0.5], [0.7, 0.5]]])
    with pytest.warns(GrowthWarning, match="closed"):
        hist = grow(dom, cnem.nodes.regular(dom, 0.1), uniaxial_setup(-1.0), increment=0.1, steps=2,
                    progress=False)
    assert len(hist.steps) == 0 and {e.kind for e in hist.events} == {"closed"}
    assert np.all(hist.final.K[:, 0] < 0)


def test_kink_sharper_than_max_kink_is_reported():
    dom = cnem.geometry.rectangle(1.0, 1.0, origin=(-0.5, -0.5), cracks=[[[-0.5, 0.0], [0.0, 0.0]]])
    with pytest.warns(GrowthWarning, match="max_kink"):
        hist = grow(dom, cnem.nodes.regular(dom, 0.1), williams_setup(1.0, 1.0), increment=0.05,
                    steps=1, max_kink=np.radians(30), progress=False)
    assert hist.steps[0].events[0].kind == "sharp_kink"


# ------------------------------------------------------------------- Paris law
@pytest.mark.slow
def test_paris_cycles_follow_the_integral_of_the_handbook_sif():
    """K_I(a) of the SENT handbook formula imposed through the Williams field about
    the current tip: cycles against N = int da / (C K(a)^m)."""
    def K_of(a):
        r = a
        return np.sqrt(np.pi * a) * (1.12 - 0.231 * r + 10.55 * r ** 2 - 21.72 * r ** 3 + 30.39 * r ** 4)

    def setup(model):
        a = model.domain.tips[0][0]
        return williams_setup(K_of(a), 0.0)(model)

    C, m = 1e-3, 2.0
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.5], [0.3, 0.5]]])
    hist = grow(dom, cnem.nodes.regular(dom, 0.05), setup, increment=0.025, steps=8,
                paris=(C, m), progress=False)
    a = np.linspace(0.3, 0.5, 2001)
    f = 1.0 / (C * K_of(a) ** m)
    exact = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(a)))
    assert hist.cycles[-1] == pytest.approx(exact, rel=0.01)
    assert np.all(np.diff(hist.cycles) > 0)


# ------------------------------------------------------------ local update
def grown_pair(dom, setup, steps, h=0.07):
    """The same run by the local update and by full rebuilds, on the user's cloud only
    (rings follow the tips in tests/test_growth_rings.py: there the two runs may number
    the ring nodes differently where the tips differ by round-off)."""
    cloud = cnem.nodes.irregular(dom, h, seed=1)
    return [grow(dom, cloud, setup, increment=0.06, steps=steps, progress=False, local=local,
                 refine=None) for local in (True, False)]


def assert_same_runs(local, full):
    assert len(local.steps) == len(full.steps)
    for a, b in zip(local.cracks, full.cracks):
        assert a.shape == b.shape
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-10)      # unit square
    for name in ("K", "angle", "K_eq"):
        a, b = local.array(name), full.array(name)
        assert np.array_equal(np.isnan(a), np.isnan(b))
        ok = ~np.isnan(a)
        np.testing.assert_allclose(a[ok], b[ok], rtol=1e-10, atol=1e-10 * np.abs(b[ok]).max())
    u, v = local.solution.u, full.solution.u
    assert u.shape == v.shape and np.abs(u - v).max() <= 1e-10 * np.abs(v).max()


@pytest.mark.slow
@pytest.mark.parametrize("crack", [[[0.35, 0.42], [0.65, 0.58]],      # internal, two tips
                                   [[0.0, 0.45], [0.3, 0.55]]],       # edge crack
                         ids=["internal", "edge"])
def test_local_update_grows_the_same_path_as_full_rebuilds(crack, caplog):
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[crack])
    with caplog.at_level("INFO", logger="cnem.fracture.growth"):
        local, full = grown_pair(dom, uniaxial_setup(1.0), steps=2)
    assert not [r for r in caplog.records if "refuses" in r.getMessage()]   # updated locally
    assert np.abs(local.array("angle")[0]).min() > 1e-2              # mixed mode: the paths kink
    assert_same_runs(local, full)


@pytest.mark.slow
def test_enriched_problem_falls_back_to_full_rebuilds_and_says_so(caplog):
    dom = cnem.geometry.rectangle(1.0, 1.0, cracks=[[[0.0, 0.45], [0.3, 0.55]]])
    with caplog.at_level("INFO", logger="cnem.fracture.growth"):
        local, full = grown_pair(dom, uniaxial_setup(1.0, enrich=dict(radius=0.12)), steps=2)
    said = [r for r in caplog.records if "refuses the local update" in r.getMessage()]
    assert len(said) == 1 and "enrich" in said[0].getMessage()
    assert_same_runs(local, full)
