"""weld.edge_counts before (two np.unique and an np.isin) and after (one sort), on a grid mesh with
1% of its faces turned over: the same counts, and the time of each (session 12).

    python bench/results/lead12-2core/edge_counts_ab.py
"""
import time

import numpy as np

from cltess.weld import edge_counts


def before(triangles):
    faces = np.asarray(triangles, np.int64).reshape(-1, 3)
    start, end = faces.reshape(-1), np.roll(faces, -1, axis=1).reshape(-1)
    top = int(faces.max()) + 1
    undirected = np.minimum(start, end) * top + np.maximum(start, end)
    keys, uses = np.unique(undirected, return_counts=True)
    directed, directed_uses = np.unique(start * top + end, return_counts=True)
    double = directed[directed_uses == 2]
    pair = np.isin(np.minimum(double // top, double % top) * top + np.maximum(double // top, double % top),
                   keys[uses == 2])
    return {"boundary_edges": int((uses == 1).sum()), "nonmanifold_edges": int((uses > 2).sum()),
            "misoriented_edges": int(pair.sum())}


rng = np.random.default_rng(3)
for size in (90_000, 1_000_000):
    m = int(np.sqrt(size / 2))
    i = np.arange(m * m).reshape(m, m)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    turned = rng.random(len(triangles)) < 0.01
    triangles[turned] = triangles[turned][:, ::-1]
    for name, function in (("before", before), ("after", edge_counts)):
        started = time.perf_counter()
        counts = function(triangles)
        print(f"{name:6s} {len(triangles):>9,} triangles {1e3 * (time.perf_counter() - started):8.1f} ms {counts}")
