"""Same-run comparison: every model array of cnem.discretize, old tree vs new, bit for bit.

    python benchmarks/discretize_compare.py OLD_ROOT NEW_ROOT [--big]

runs each tree in its own child (PYTHONPATH=root) on the same clouds (square, cracked
plates, holes, annulus, L-shape, two materials, 1e6 offset, 1e-6 and 1e6 scales, lattices,
graded, thin strips, user clouds; ``--big`` adds 300k and 1M nodes), saves the arrays
(nodes, node_of_point, triangles, regions, segments and kinds, the cells' node, region,
offsets, vertices and areas, or the error raised) and compares them with np.array_equal
and their dtypes. Exit status 1 if any differs."""
import os, subprocess, sys, tempfile
import numpy as np

def clouds(big):
    import cnem
    g, nodes = cnem.geometry, cnem.nodes
    rect = g.rectangle
    crack = [[[0.0, 0.5], [0.5, 0.5]]]
    out = {
        "square": lambda: nodes.irregular(rect(1.0, 1.0), 0.01, seed=0),
        "cracked": lambda: nodes.irregular(rect(1.0, 1.0, cracks=crack), 0.01, seed=0),
        "cracked_center": lambda: nodes.irregular(rect(1.0, 1.0, cracks=[[[0.3, 0.4], [0.7, 0.6]]]), 0.02, seed=3),
        "hole": lambda: nodes.irregular(g.plate_with_hole(1.0, 1.0, 0.2), 0.02, seed=1),
        "annulus": lambda: nodes.irregular(g.annulus([0.5, 1.0]), 0.03, seed=2),
        "lshape_crack": lambda: nodes.irregular(g.l_shape(1.0, 0.5, cracks=[[[0.5, 0.5], [0.25, 0.25]]]), 0.02, seed=4),
        "bimaterial": lambda: nodes.irregular(g.Domain([[[0, 0], [0.5, 0], [0.5, 1], [0, 1]], [[0.5, 0], [1, 0], [1, 1], [0.5, 1]]]), 0.02, seed=5),
        "bimaterial_crack": lambda: nodes.irregular(g.Domain([[[0, 0], [0.5, 0], [0.5, 1], [0, 1]], [[0.5, 0], [1, 0], [1, 1], [0.5, 1]]], cracks=[[[0.2, 0.5], [0.5, 0.5]]]), 0.02, seed=6),
        "far_1e6": lambda: nodes.irregular(rect(1.0, 1.0, origin=(1e6, 1e6), cracks=[[[1e6, 1e6 + 0.5], [1e6 + 0.5, 1e6 + 0.5]]]), 0.02, seed=7),
        "tiny_1e-6": lambda: nodes.irregular(rect(1e-6, 1e-6, cracks=[[[0.0, 0.5e-6], [0.5e-6, 0.5e-6]]]), 0.02e-6, seed=8),
        "huge_1e6": lambda: nodes.irregular(rect(1e6, 1e6, cracks=[[[0.0, 0.5e6], [0.5e6, 0.5e6]]]), 0.02e6, seed=9),
        "regular": lambda: nodes.regular(rect(1.0, 1.0, cracks=crack), 0.02),
        "regular_hole": lambda: nodes.regular(g.plate_with_hole(1.0, 1.0, 0.25), 0.025),
        "graded": lambda: nodes.graded(rect(1.0, 1.0, cracks=crack), 0.02, near=[[0.5, 0.5]], h_min=0.001),
        "user_random": lambda: nodes.from_points(rect(1.0, 1.0, cracks=crack), np.random.default_rng(1).random((3000, 2)) * 0.98 + 0.01),
        "user_lattice": lambda: nodes.from_points(rect(1.0, 1.0), np.stack(np.meshgrid(np.linspace(0.05, 0.95, 19), np.linspace(0.05, 0.95, 19)), -1).reshape(-1, 2)),
        "strip_rows": lambda: nodes.irregular(rect(1.0, 0.02), 0.004, seed=3),
        "user_strip": lambda: nodes.from_points(rect(1.0, 0.01), np.column_stack([np.linspace(0.01, 0.99, 200), np.full(200, 0.005)])),
    }
    if big:
        out["square_300k"] = lambda: nodes.irregular(rect(1.0, 1.0), 1 / np.sqrt(3e5), seed=0)
        out["cracked_1M"] = lambda: nodes.irregular(rect(1.0, 1.0, cracks=crack), 1e-3, seed=0)
    return out

FIELDS = ("nodes", "node_of_point", "triangles", "triangle_region", "segments", "segment_kind")

def child(outdir, big):
    import cnem
    print(cnem.__file__, flush=True)
    for name, make in clouds(big).items():
        try:
            m = cnem.discretize(make(), progress=False)
        except Exception as e:           # an error is a result too
            np.savez(os.path.join(outdir, name), error=np.array(f"{type(e).__name__}: {e}"))
            continue
        arrs = {f: getattr(m, f) for f in FIELDS}
        c = m.cells
        arrs.update(cell_node=c.node, cell_region=c.region, offsets=c.offsets, vertices=c.vertices,
                    area=c.area)
        np.savez(os.path.join(outdir, name), **arrs)

def main():
    old, new = sys.argv[1], sys.argv[2]
    big = "--big" in sys.argv
    with tempfile.TemporaryDirectory() as tmp:
        dirs = {}
        for tag, root in (("old", old), ("new", new)):
            d = os.path.join(tmp, tag); os.mkdir(d); dirs[tag] = d
            env = dict(os.environ, PYTHONPATH=root)
            subprocess.run([sys.executable, __file__, "--child", d] + (["--big"] if big else []),
                           env=env, check=True)
        bad = 0
        for f in sorted(os.listdir(dirs["old"])):
            a, b = np.load(os.path.join(dirs["old"], f)), np.load(os.path.join(dirs["new"], f))
            diff = [k for k in a.files if k not in b.files or a[k].dtype != b[k].dtype
                    or not np.array_equal(a[k], b[k])] + [k for k in b.files if k not in a.files]
            size = "error: " + str(a["error"]) if "error" in a.files else f"{len(a['nodes'])} nodes, {len(a['area'])} cells"
            print(f"{f[:-4]:>18}: {'EQUAL' if not diff else 'DIFFER ' + str(diff)} ({size})")
            bad += bool(diff)
        print("all equal" if not bad else f"{bad} clouds differ")
        sys.exit(1 if bad else 0)

if __name__ == "__main__":
    if sys.argv[1] == "--child":
        child(sys.argv[2], "--big" in sys.argv)
    else:
        main()
