"""Per-patch measured deviation and triangle counts of bench/occ_compare.py's 20 random rational
patches, hull and integral bounds: where the integral bound's triangles go (bench/RESULTS.md,
"Issue 9: the integral-form bound in the engine").  Output: bench/results/bound_integral_per_patch.md.

    python bench/bound_integral_per_patch.py [--device NAME]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from occ_compare import diagonal, measured_deviation, random_rational_patches  # noqa: E402

RUNS = ((3e-2, "hull"), (1e-2, "integral"), (1e-2, "hull"), (3e-3, "integral"))


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", help="OpenCL device (as for cltess --device)")
    args = parser.parse_args(argv)

    from cltess.pipeline import Tessellator
    from cltess.scene import Scene

    patches = random_rational_patches()
    size = diagonal(patches)
    tessellator = Tessellator(device=args.device)
    scene = Scene(patches, np.zeros(len(patches), np.int32), name="random")
    for rel, bound in RUNS:
        tess = tessellator.tessellate(scene, eps=rel * size, max_factor=4096, bound=bound)
        tris = tess.triangles.astype(np.int64)
        owner = tess.patch_ids[tris[:, 0]]
        devs = np.array([measured_deviation(patches, tess.positions, tess.uv, owner[owner == p], tris[owner == p])
                         for p in range(len(patches))])
        print(f"{rel:g} {bound} {len(tris)} max dev/diag {devs.max() / size:.2e}")
        print("  dev/diag per patch:", " ".join(f"{d:.1e}" for d in devs / size))
        print("  triangles per patch:", " ".join(str(c) for c in np.bincount(owner, minlength=len(patches))), flush=True)


if __name__ == "__main__":
    main()
