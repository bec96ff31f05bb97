"""Make the README's pictures of the bundled scenes (docs/pictures/*.png) with `cltess render`.

    python docs/make_pictures.py [--device NAME]

Each picture is one `cltess render` command, printed before it runs, so any of them can be
repeated by hand.  The images are small (480 x 360) so that they can live in the repository.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "pictures"

#: (file name, arguments after `cltess render`)
PICTURES = [
    ("teapot.png", ["scenes/teapot.bez", "--eps", "0.1%"]),
    ("tea_table.png", ["scenes/tea_table.json", "--pixels", "1"]),
    ("tea_table_factors.png", ["scenes/tea_table.json", "--pixels", "1", "--color", "factor"]),
    ("tea_table_as_read.png", ["scenes/tea_table.json", "--pixels", "1", "--no-orient"]),
    ("cylinder.png", ["scenes/cylinder.stl", "--eps", "0.1%"]),
]


def main(argv=None) -> int:
    from cltess.cli import main as cltess

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--device", help="OpenCL device, as for cltess")
    args = parser.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    for name, arguments in PICTURES:
        command = ["render", *arguments, "--size", "480x360", "-q", "-o", str((OUT / name).relative_to(ROOT))]
        if args.device:
            command += ["--device", args.device]
        print("cltess " + " ".join(command))
        code = cltess(command)
        if code:
            return code
    return 0


if __name__ == "__main__":
    import os

    os.chdir(ROOT)
    sys.exit(main())
