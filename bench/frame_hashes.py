"""Hashes of Session frames, to compare two trees' frames bit for bit (issue 15: a change to the
frame loop must leave every frame as it was).

    python bench/frame_hashes.py [--as-gpu] [--device NAME] SCENE ...
    PYTHONPATH=OTHER_TREE python bench/frame_hashes.py [--as-gpu] SCENE ...   # then diff the two

Per scene (``cltess.bench.suite`` names): a ``cltess.Session`` at 0.5 px on 6 cameras of
``bench/frame_loop.py``'s circle: the 6 frames waited, 6 overlapped (``wait=False``, the last one
hashed), one with an override (0.25 px: more output, the buffers grow), and 3 more; one SHA-256
over every host field of each hashed frame (``HOST_FIELDS``) and its stats (but
``output_fit``, which says how the frame was made).  ``--as-gpu``: the frames a GPU makes
(work "point", stage 3 fused or tiled) on this device.
"""
import argparse
import hashlib
import sys
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import numpy as np  # noqa: E402

import cltess  # noqa: E402
import frame_loop as fl  # noqa: E402
from cltess.backends.opencl import Tessellator  # noqa: E402
from cltess.tessellation import HOST_FIELDS  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="+")
    parser.add_argument("--device")
    parser.add_argument("--as-gpu", action="store_true")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    tessellator = Tessellator(args.device, work="point" if args.as_gpu else None)
    if args.as_gpu:
        tessellator.fused_offsets, tessellator.tiled_offsets, tessellator._cpu = True, True, False
    print(f"cltess from {cltess.__file__}")
    for key in args.scenes:
        scene = fl.suite_scene(key)
        session = cltess.Session(scene, tessellator=tessellator, pixels=fl.PIXELS)
        path = list(fl.orbit(scene.camera, 6))
        digest = hashlib.sha256()

        def add(frame):
            frame.fetch()
            for name in HOST_FIELDS:
                array = getattr(frame, name)
                if array is not None:
                    digest.update(np.ascontiguousarray(array).tobytes())
            digest.update(repr(sorted((k, v) for k, v in frame.stats.items() if k != "output_fit")).encode())

        for camera in path:
            add(session.tessellate(camera=camera))
        overlapped = [session.tessellate(camera=camera, wait=False) for camera in path]
        add(overlapped[-1])
        add(session.tessellate(camera=path[1], pixels=0.25))
        for camera in path[:3]:
            add(session.tessellate(camera=camera))
        print(key, digest.hexdigest()[:16])
    return 0


if __name__ == "__main__":
    sys.exit(main())
