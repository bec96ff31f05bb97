"""pyopencl's ``GenericScanKernel``, imported without Pygments.

pyopencl.scan renders its kernels with Mako; ``mako.exceptions`` (imported by Mako's code
generator) imports Pygments when it can, only to colour the HTML error pages of
``mako.exceptions.html_error_template``, which cltess never shows: about 0.1 s of CPU on every
start of the CLI here, a quarter of pyopencl.scan's import (``python -X importtime -m cltess``).
Mako falls back to plain escaping when that import raises ImportError
(``mako.exceptions._install_highlighting``); a ``None`` in ``sys.modules`` makes it raise.
Only the first import of Mako is affected: Pygments itself imports as usual afterwards.
"""
from __future__ import annotations

import contextlib
import sys


@contextlib.contextmanager
def pygments_hidden():
    """Within: ``import pygments`` raises ImportError, unless Pygments was imported already."""
    if "pygments" in sys.modules:
        yield
        return
    sys.modules["pygments"] = None
    try:
        yield
    finally:
        if "pygments" in sys.modules and sys.modules["pygments"] is None:
            del sys.modules["pygments"]


with pygments_hidden():
    from pyopencl.scan import GenericScanKernel

__all__ = ["GenericScanKernel", "pygments_hidden"]
