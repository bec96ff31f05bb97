"""pyopencl keeps built programs in an on-disk cache keyed by the source, the options and the
headers the source includes, which it finds by matching each line against its ``C_INCLUDE_RE``
(``#include "file"`` alone on its line).  An include it does not see (a comment after it, say)
leaves that header out of the key: after an upgrade that changes only that header, the old
binary is loaded and the kernels silently run the old code (the ESC pole rule did not reach
stage 1 that way, 2026-11-23).  So every include in kernels/ is one pyopencl sees."""
import re

from pyopencl.cache import C_INCLUDE_RE

from cltess.backends.opencl.programs import kernel_dir

ANY_INCLUDE = re.compile(rb"^\s*#\s*include\b.*$", re.MULTILINE)


def test_every_include_line_is_one_the_binary_cache_follows():
    folder = kernel_dir()
    sources = sorted(folder.rglob("*.h")) + sorted(folder.rglob("*.cl"))
    assert len(sources) > 30
    unseen = []
    for path in sources:
        text = path.read_bytes()
        for line in ANY_INCLUDE.finditer(text):
            seen = C_INCLUDE_RE.search(line.group(0))
            if seen is None:
                unseen.append(f"{path.relative_to(folder)}: {line.group(0).decode().strip()}")
            else:  # and it is found on the include path (kernels/), where the cache looks
                assert (folder / seen.group(1).decode()).is_file(), f"{path.name}: {seen.group(1)} not in kernels/"
    assert not unseen, "includes pyopencl's cache does not see (put comments on their own line):\n" + "\n".join(unseen)
