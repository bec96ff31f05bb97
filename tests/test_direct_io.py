"""cltess/io/direct.py: a file written as regions at fixed offsets in aligned blocks (direct I/O
where the file system takes it), and atomic_write's release of a large replaced file."""
import errno
import os
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from cltess.io import direct, writing
from cltess.io.direct import BLOCK, BlockFile
from cltess.io.ply import PlyWriter
from cltess.io.writing import VertexBlock, atomic_write
from cltess.tessellation import Tessellation

#: "disk": this folder's file system (direct I/O where it takes it); "refused": a file system
#: that takes the O_DIRECT flag but refuses the writes (EINVAL): the page cache instead.
FOLDERS = ["disk", "refused"]


def refuse_direct_writes(monkeypatch) -> list:
    """os.pwrite raises EINVAL while the descriptor has O_DIRECT; returns the refusals."""
    import fcntl

    real_pwrite, refused = os.pwrite, []

    def pwrite(fd, data, offset):
        if fcntl.fcntl(fd, fcntl.F_GETFL) & getattr(os, "O_DIRECT", 0):
            refused.append(offset)
            raise OSError(errno.EINVAL, "Invalid argument")
        return real_pwrite(fd, data, offset)

    monkeypatch.setattr(direct.os, "pwrite", pwrite)
    return refused


def write_regions(path: Path, data: bytes, cuts: list, pieces: np.random.Generator) -> bool:
    """Write ``data`` as regions [cuts[k], cuts[k+1]), each in random pieces, the regions'
    pieces interleaved at random; returns whether direct I/O was on."""
    with atomic_write(path, "wb") as handle:
        output = BlockFile(handle.fileno(), len(data))
        regions = [output.region(a, b - a) for a, b in zip(cuts[:-1], cuts[1:])]
        positions = list(cuts[:-1])
        try:
            while any(p < r.end for p, r in zip(positions, regions)):
                k = pieces.choice([i for i, r in enumerate(regions) if positions[i] < r.end])
                size = int(min(pieces.integers(1, 3 * BLOCK), regions[k].end - positions[k]))
                if pieces.random() < 0.5 or size > regions[k].capacity:
                    regions[k].write(data[positions[k]:positions[k] + size])
                else:
                    regions[k].reserve(size)[...] = np.frombuffer(data, np.uint8, size, positions[k])
                    regions[k].commit(size)
                positions[k] += size
            output.finish()
        finally:
            output.close()
        return output.direct


@pytest.mark.parametrize("kind", FOLDERS)
@pytest.mark.parametrize("seed", range(6))
def test_regions_in_any_order_give_the_bytes(tmp_path, monkeypatch, kind, seed):
    monkeypatch.setattr(direct, "STAGING_BYTES", 2 * BLOCK)  # many flushes, both buffers in turn
    refused = refuse_direct_writes(monkeypatch) if kind == "refused" else None
    rng = np.random.default_rng(seed)
    size = int(rng.integers(1, 40 * BLOCK))
    data = rng.integers(0, 256, size, dtype=np.uint8).tobytes()
    cuts = sorted({0, size, *map(int, rng.integers(0, size, int(rng.integers(0, 5))))})
    path = tmp_path / "out.bin"
    used_direct = write_regions(path, data, cuts, rng)
    assert path.read_bytes() == data
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.bin"]
    if refused is not None:
        assert not used_direct and len(refused) <= 1  # turned off at the first refusal


def test_direct_io_is_used_on_a_disk_and_can_be_turned_off(tmp_path, monkeypatch):
    data = bytes(range(256)) * 100
    on = write_regions(tmp_path / "on.bin", data, [0, 1000, len(data)], np.random.default_rng(0))
    monkeypatch.setenv("CLTESS_DIRECT_IO", "off")
    off = write_regions(tmp_path / "off.bin", data, [0, 1000, len(data)], np.random.default_rng(0))
    assert not off
    assert (tmp_path / "on.bin").read_bytes() == (tmp_path / "off.bin").read_bytes() == data
    if not on:
        pytest.skip(f"{tmp_path}: this file system refuses O_DIRECT (checked: the page-cache path)")


def test_a_region_refuses_more_or_fewer_bytes(tmp_path):
    with open(tmp_path / "x.bin", "wb") as handle:
        output = BlockFile(handle.fileno(), 100)
        first, second = output.region(0, 10), output.region(10, 90)
        with pytest.raises(ValueError, match="too many"):
            first.write(b"x" * 11)
        first.write(b"x" * 10)
        second.write(b"y" * 50)
        with pytest.raises(ValueError, match="unwritten"):
            output.finish()
        with pytest.raises(ValueError, match="outside"):
            output.region(90, 20)
        output.close()


def tessellation(count: int, seed: int = 0) -> Tessellation:
    rng = np.random.default_rng(seed)
    return Tessellation(rng.random((count, 3), np.float32), rng.random((count, 3), np.float32),
                        rng.random((count, 2), np.float32), rng.integers(0, 9, count).astype(np.int32),
                        np.zeros(count, np.int32), rng.integers(0, count, (2 * count, 3)).astype(np.uint32),
                        np.zeros((1, 4), np.int32))


def test_a_failed_write_on_the_writer_thread_is_raised_and_leaves_nothing(tmp_path, monkeypatch):
    """A disk error in a background write (ENOSPC) reaches the caller; the temporary file is
    removed and the earlier file is kept."""
    tess = tessellation(300_000)
    target = tmp_path / "mesh.ply"
    target.write_bytes(b"earlier")
    real_pwrite, calls = os.pwrite, []

    def full_disk(fd, data, offset):
        calls.append(offset)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_pwrite(fd, data, offset)

    monkeypatch.setattr(direct.os, "pwrite", full_disk)
    with pytest.raises(OSError, match="No space left") as error:
        with PlyWriter(target, tess.num_vertices, tess.num_triangles) as writer:
            writer.write_vertices(tess)
            writer.write_faces(tess.triangles)
    assert str(target) in str(error.value)  # named: the output, not its temporary file
    assert target.read_bytes() == b"earlier"
    assert [p.name for p in tmp_path.iterdir()] == ["mesh.ply"]


def test_ply_blocks_in_any_order_equal_the_one_shot_bytes(tmp_path, monkeypatch):
    """Vertex and face blocks interleaved (a batch's faces before the next batch's vertices),
    small staging buffers: the same file as one block each."""
    monkeypatch.setattr(direct, "STAGING_BYTES", 3 * BLOCK)
    tess = tessellation(5_000, seed=3)
    whole, pieces = tmp_path / "whole.ply", tmp_path / "pieces.ply"
    with PlyWriter(whole, tess.num_vertices, tess.num_triangles) as writer:
        writer.write_vertices(tess)
        writer.write_faces(tess.triangles)
    with PlyWriter(pieces, tess.num_vertices, tess.num_triangles) as writer:
        for k, start in enumerate(range(0, tess.num_vertices, 777)):
            stop = min(start + 777, tess.num_vertices)
            writer.write_vertices(VertexBlock(tess.positions[start:stop], tess.normals[start:stop],
                                              tess.uv[start:stop], tess.patch_ids[start:stop],
                                              tess.object_ids[start:stop]))
            writer.write_faces(tess.triangles[2 * start:2 * stop])
    assert pieces.read_bytes() == whole.read_bytes()


def test_a_large_replaced_file_is_freed_by_a_helper(tmp_path, monkeypatch):
    """atomic_write onto a large file: the new content is there at once, the helper that holds
    the old file ends by itself, nothing else is left in the folder."""
    monkeypatch.setattr(writing, "RELEASE_ELSEWHERE_BYTES", 1000)
    target = tmp_path / "big.bin"
    target.write_bytes(b"old" * 1000)
    link = tmp_path / "link.bin"
    link.symlink_to(target)
    with atomic_write(target, "wb") as handle:
        handle.write(b"new" * 10)
    assert target.read_bytes() == b"new" * 10
    helpers = list(writing._HELPERS)
    assert helpers and all(isinstance(h, subprocess.Popen) for h in helpers)
    deadline = time.monotonic() + 10
    while any(h.poll() is None for h in helpers) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert all(h.returncode == 0 for h in helpers)
    with atomic_write(link, "wb") as handle:  # a link is replaced, not followed (as before)
        handle.write(b"x")
    assert link.read_bytes() == b"x" and not link.is_symlink() and target.read_bytes() == b"new" * 10
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.bin", "link.bin"]
