"""A file written as regions at known offsets, in whole aligned blocks, by direct I/O where the
file system takes it (``O_DIRECT``: the bytes go from our buffer to the disk, not through the
page cache).

Why: a large output written through the page cache needs as many fresh pages of memory as the
file is long, and on a virtual machine whose freed memory the host takes back (virtio-balloon
free page reporting, as on the VM of bench/RESULTS.md "Issue 15: the 30k-patch PLY") each of
them is faulted in by the host: 556 MB took 2.1-2.4 s through the page cache there, 0.34-0.44 s
by direct I/O (and its fsync 0.24 s against 0.002 s).  Measured, not assumed: see
bench/RESULTS.md.

How: every region (a PLY's header, its vertex records, its face records) is a sequential stream
that starts at a known file offset.  Its bytes are built in place in a page-aligned staging
buffer (``Region.reserve`` / ``commit``: the records are made right there, no extra copy) and
written in whole blocks at block-aligned offsets.  A block shared by two regions (a region's
first and last block) is set aside and written when the file is finished, once both regions
have put their bytes into it; the file is then cut to its exact length (``ftruncate``).  Where
``O_DIRECT`` cannot be set or a direct write is refused (``EINVAL``: tmpfs, some network file
systems), the same writes go through the page cache: same bytes, same offsets.

The caller keeps what makes the file safe (``io.writing.atomic_write``: temporary file, fsync,
rename; nothing left behind on failure).
"""
from __future__ import annotations

import errno
import mmap
import os

import numpy as np

#: Offsets and lengths of direct writes are multiples of this (4 KiB covers 512-byte and 4K
#: sector disks; buffers are page-aligned mmaps).
BLOCK = 4096
#: Bytes staged per region before a write (plus one block for the carried partial block); a
#: region has two such buffers (one built while the other is written), a PLY two regions of
#: size: 16 MB in all, within the stated overhead of a streamed run (tests/test_stream.py).
STAGING_BYTES = 4 << 20


def _set_direct(fd: int) -> bool:
    """Turn on O_DIRECT for ``fd`` if this platform and file system allow it."""
    direct = getattr(os, "O_DIRECT", 0)
    if not direct or os.environ.get("CLTESS_DIRECT_IO", "").lower() in ("0", "off", "no"):
        return False
    import fcntl

    try:
        flags = fcntl.fcntl(fd, fcntl.F_GETFL)
        fcntl.fcntl(fd, fcntl.F_SETFL, flags | direct)
    except OSError:
        return False
    return bool(fcntl.fcntl(fd, fcntl.F_GETFL) & direct)


def _aligned(nbytes: int) -> tuple[mmap.mmap, np.ndarray]:
    """A page-aligned buffer (an anonymous mapping) and its uint8 view."""
    memory = mmap.mmap(-1, nbytes)
    return memory, np.frombuffer(memory, np.uint8)


class BlockFile:
    """The file behind ``fd`` (opened for writing, empty), ``size`` bytes long when finished,
    written region by region (``region``).  ``finish`` writes the shared blocks and sets the
    length; the caller then fsyncs and renames as before."""

    def __init__(self, fd: int, size: int):
        self.fd = fd
        self.size = int(size)
        self.direct = _set_direct(fd)
        self._edges: dict = {}  # block index -> (bytes of the block, how many of them are set)
        self._regions: list = []
        self._writer = None  # one thread that runs the regions' writes in order (``submit``)

    def submit(self, data: np.ndarray, offset: int):
        """``pwrite(data, offset)`` on the writer thread: the caller goes on building records
        (and the device computing) while the disk takes this.  Returns its Future."""
        if self._writer is None:
            from concurrent.futures import ThreadPoolExecutor

            self._writer = ThreadPoolExecutor(1, thread_name_prefix="cltess-write")
        return self._writer.submit(self.pwrite, data, offset)

    def region(self, offset: int, length: int) -> "Region":
        """A stream of exactly ``length`` bytes starting at file offset ``offset``."""
        if offset < 0 or offset + length > self.size:
            raise ValueError(f"region [{offset}, {offset + length}) outside a file of {self.size} bytes")
        region = Region(self, offset, length)
        self._regions.append(region)
        return region

    def pwrite(self, data: np.ndarray, offset: int) -> None:
        """Write ``data`` (whole blocks from an aligned buffer) at ``offset``: directly, or
        through the page cache once a direct write has been refused."""
        view = memoryview(data)
        while len(view):
            try:
                written = os.pwrite(self.fd, view, offset)
            except OSError as error:
                if not (self.direct and error.errno == errno.EINVAL):
                    raise
                self._stop_direct()
                continue
            if written <= 0:
                raise OSError(errno.EIO, "short write")
            view, offset = view[written:], offset + written

    def _stop_direct(self) -> None:
        import fcntl

        fcntl.fcntl(self.fd, fcntl.F_SETFL, fcntl.fcntl(self.fd, fcntl.F_GETFL) & ~os.O_DIRECT)
        self.direct = False

    def _edge(self, offset: int, data: np.ndarray) -> None:
        """Bytes of one partly owned block (``offset`` inside it): kept until ``finish``."""
        index, start = divmod(offset, BLOCK)
        block, count = self._edges.get(index, (None, 0))
        if block is None:
            block = np.zeros(BLOCK, np.uint8)
        block[start:start + len(data)] = data
        self._edges[index] = (block, count + len(data))

    def finish(self) -> None:
        """Write the shared blocks (each must be whole by now, except the file's last), then
        cut the file to its size."""
        for region in self._regions:
            if not region.closed:
                raise ValueError(f"region at {region.start} has {region.end - region.position} bytes unwritten")
        if self._edges:
            memory, staging = _aligned(BLOCK)
            for index, (block, count) in sorted(self._edges.items()):
                expected = min(BLOCK, self.size - index * BLOCK)
                if count != expected:
                    raise ValueError(f"block {index} has {count} of its {expected} bytes")
                staging[:] = block
                self.pwrite(staging, index * BLOCK)
        os.ftruncate(self.fd, self.size)

    def close(self) -> None:
        """Wait for the writes under way (their errors are raised by ``finish``, or dropped
        after a failure) and release the staging buffers."""
        if self._writer is not None:
            self._writer.shutdown(wait=True)
            self._writer = None
        for region in self._regions:
            region.release()


class Region:
    """Bytes start..end-1 of a BlockFile, appended in order: ``reserve(n)`` gives n writable
    bytes in the staging buffer, ``commit(n)`` appends them; or ``write(data)``.  Two staging
    buffers take turns: one is built while the writer thread writes the other."""

    def __init__(self, output: BlockFile, start: int, length: int):
        self.output = output
        self.start, self.end = start, start + length
        self.position = start  # file offset of the next byte
        self.closed = False
        self._buffers = [None, None]  # (mapping, uint8 view), made when first needed
        self._pending = [None, None]  # the Future of each buffer's write under way
        self._current = 0
        self._staging = self._buffer(0)
        self._base = start - start % BLOCK  # file offset of staging[0]
        self._fill = start - self._base  # staging[:_fill] is in use (its head below start: a hole)
        if length == 0:
            self.close()

    @property
    def capacity(self) -> int:
        """The most bytes one ``reserve`` can give."""
        return STAGING_BYTES

    def _buffer(self, index: int) -> np.ndarray:
        if self._buffers[index] is None:  # small regions (a header) need only a block or two
            self._buffers[index] = _aligned(min(STAGING_BYTES, self.end - self.start + BLOCK) + BLOCK)
        return self._buffers[index][1]

    def reserve(self, nbytes: int) -> np.ndarray:
        if nbytes > STAGING_BYTES:
            raise ValueError(f"cannot reserve {nbytes} bytes at once (at most {STAGING_BYTES})")
        if self._fill + nbytes > len(self._staging):
            self._flush()
        return self._staging[self._fill:self._fill + nbytes]

    def commit(self, nbytes: int) -> None:
        if self.position + nbytes > self.end:
            raise ValueError(f"region [{self.start}, {self.end}): {self.position + nbytes - self.end} bytes too many")
        self._fill += nbytes
        self.position += nbytes
        if self.position == self.end:
            self.close()

    def write(self, data) -> None:
        data = np.frombuffer(data, np.uint8) if not isinstance(data, np.ndarray) else data.reshape(-1).view(np.uint8)
        for first in range(0, len(data), STAGING_BYTES):
            piece = data[first:first + STAGING_BYTES]
            self.reserve(len(piece))[...] = piece
            self.commit(len(piece))

    def _flush(self) -> None:
        """Hand the whole blocks staged so far to the writer thread (a block with a hole, the
        region's first when it does not start on a block, goes to the shared blocks) and go on
        in the other buffer, the partial last block moved to its front."""
        whole = self._fill - self._fill % BLOCK
        if not whole:
            return
        low = 0
        if self._base < self.start:  # the region's first block: its head belongs to another
            self.output._edge(self.start, self._staging[self.start - self._base:BLOCK])
            low = BLOCK
        if whole > low:
            self._pending[self._current] = self.output.submit(self._staging[low:whole], self._base + low)
        other = 1 - self._current
        self._wait(other)
        rest = self._fill - whole
        following = self._buffer(other)
        following[:rest] = self._staging[whole:self._fill]
        self._current, self._staging = other, following
        self._base += whole
        self._fill = rest

    def _wait(self, index: int) -> None:
        pending, self._pending[index] = self._pending[index], None
        if pending is not None:
            pending.result()  # a failed write raises here

    def close(self) -> None:
        """All bytes given: write the whole blocks, hand the partial last block over, wait for
        the writes."""
        if self.closed:
            return
        if self.position != self.end:
            raise ValueError(f"region [{self.start}, {self.end}) closed at {self.position}")
        self._flush()
        if self._fill:
            low = max(self.start - self._base, 0)
            self.output._edge(self._base + low, self._staging[low:self._fill])
        self._fill = 0
        self._wait(0)
        self._wait(1)
        self.closed = True
        self.release()

    def release(self) -> None:
        """Drop the staging buffers (unmapped once no view of them is left)."""
        self._staging = None
        self._buffers = [None, None]
