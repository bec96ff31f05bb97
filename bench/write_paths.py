"""What writing a large output costs on this machine, path by path (issue 15, session 4).

    python bench/write_paths.py [--mb 556] [--repeat 3] [--spacing 4] [--folder DIR]

Each measurement runs in a fresh child process (Python start not timed), ``--spacing`` seconds
after the last one, so that it does not reuse memory the last one freed:

* ``touch``: first write of ``--mb`` MB of fresh anonymous memory, then a second write of the
  same memory (what a process pays for memory it has not touched yet);
* ``page cache``: the bytes written to a temporary file beside the target through the page
  cache in 4 MB writes, fsync'd and renamed onto the last one (``atomic_write``'s steps);
* ``direct``: the same with O_DIRECT (aligned 4 MB writes: ``cltess.io.direct``);
* ``direct, old freed by helper``: as ``direct``, the replaced file's last reference handed to
  a helper process (``cltess.io.writing._release_elsewhere``): the rename's cost without the
  freeing of the old file's blocks.

Prints seconds per step (median and min of ``--repeat``) and the load average.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHILD = r"""
import json, mmap, os, sys, time
from pathlib import Path
import numpy as np
mode, target, mb = sys.argv[1], sys.argv[2], int(sys.argv[3])
size = mb << 20
chunk = 4 << 20
out = {}
if mode == "touch":
    pages = np.frombuffer(mmap.mmap(-1, size), np.uint8)[::4096]  # one byte of every page
    started = time.perf_counter()
    pages[...] = 1
    out["first touch"] = time.perf_counter() - started
    started = time.perf_counter()
    pages[...] = 2
    out["second touch"] = time.perf_counter() - started
else:
    sys.path.insert(0, sys.argv[4])
    from cltess.io.writing import _hold_large, _release_elsewhere
    buffer = mmap.mmap(-1, chunk)
    buffer.write(b"\1" * chunk)
    temporary = target + ".tmp"
    started = time.perf_counter()
    fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    if mode != "page cache":
        import fcntl
        fcntl.fcntl(fd, fcntl.F_SETFL, fcntl.fcntl(fd, fcntl.F_GETFL) | os.O_DIRECT)
    for offset in range(0, size, chunk):
        os.pwrite(fd, buffer, offset)
    out["write"] = time.perf_counter() - started
    started = time.perf_counter()
    os.fsync(fd)
    os.close(fd)
    out["fsync"] = time.perf_counter() - started
    started = time.perf_counter()
    old = _hold_large(Path(target)) if mode == "direct, old freed by helper" else None
    os.replace(temporary, target)
    if old is not None:
        _release_elsewhere(old)
    out["rename onto the last file"] = time.perf_counter() - started
print(json.dumps(out))
"""

MODES = ("touch", "page cache", "direct", "direct, old freed by helper")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mb", type=int, default=556)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--spacing", type=float, default=4.0)
    parser.add_argument("--folder", default=".")
    args = parser.parse_args()
    tree = str(Path(__file__).resolve().parent.parent)
    results: dict = {}
    loads = []
    with tempfile.TemporaryDirectory(dir=args.folder) as folder:
        for _ in range(args.repeat):
            for mode in MODES:
                time.sleep(args.spacing)
                loads.append(os.getloadavg()[0])
                target = os.path.join(folder, mode.replace(" ", "_").replace(",", "") + ".bin")
                done = subprocess.run([sys.executable, "-c", CHILD, mode, target, str(args.mb), tree],
                                      capture_output=True, text=True)
                if done.returncode:
                    sys.exit(done.stderr)
                for step, seconds in json.loads(done.stdout).items():
                    results.setdefault((mode, step), []).append(seconds)
    print(f"{args.mb} MB, {args.repeat} runs each, {args.spacing:g} s apart; seconds, median [min]; "
          f"load average {min(loads):.1f}-{max(loads):.1f}")
    for (mode, step), values in results.items():
        print(f"  {mode:30} {step:26}: {statistics.median(values):.3f} [{min(values):.3f}]")
    return 0


if __name__ == "__main__":
    sys.exit(main())
