"""What every writer shares: atomic writes (into a temporary file beside the target, fsync'd,
renamed onto it; on any failure, Ctrl-C included, the temporary is removed and an existing
target is left untouched), the vertex block the streaming writers take, the checks of vertex
and face arrays, and the streaming writer base (totals up front, then any number of blocks)."""
from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from pathlib import Path
from typing import IO, Iterator, NamedTuple

import numpy as np

from ..tessellation import VERTEX_RECORD

#: A run of vertices for the streaming writers: the fields of the vertex record (positions (k, 3),
#: normals (k, 3), uv (k, 2): float32; patch_ids (k,), object_ids (k,): int32).
VertexBlock = NamedTuple("VertexBlock", [(name, np.ndarray) for name, _, _ in VERTEX_RECORD])


def _current_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "wb", **open_kwargs) -> Iterator[IO]:
    """Open a temporary file next to ``path``; on success fsync it and rename it onto ``path``.

    If the body raises anything (KeyboardInterrupt included) the temporary file is removed,
    the exception propagates, and whatever was at ``path`` before is unchanged.
    ``mode`` is ``"wb"`` or ``"w"`` (``open_kwargs`` such as ``encoding`` go to ``open``).
    """
    if "w" not in mode:
        raise ValueError(f"atomic_write needs a write mode, got {mode!r}")
    target = Path(path)
    try:
        fd, temp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as error:
        raise _naming(error, target) from error
    handle = None
    try:
        if hasattr(os, "fchmod"):  # mkstemp makes it 0600; give it what a plain open() would
            os.fchmod(fd, 0o666 & ~_current_umask())
        handle = open(fd, mode, **open_kwargs)
        with handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        old = _hold_large(target)
        os.replace(temp_name, target)
        if old is not None:
            _release_elsewhere(old)
    except BaseException as error:
        if handle is None:
            os.close(fd)  # open() never took the descriptor over
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temp_name)
        if isinstance(error, OSError) and error.filename in (None, temp_name):
            raise _naming(error, target) from error
        raise


#: A replaced file at least this large has its blocks freed by a helper process (``_release_elsewhere``).
RELEASE_ELSEWHERE_BYTES = 64 << 20


def _hold_large(target: Path) -> int | None:
    """A descriptor holding the file that ``target`` names now (not following a link), if it is
    a regular file of at least RELEASE_ELSEWHERE_BYTES; else None."""
    if not hasattr(os, "O_PATH"):
        return None
    try:
        fd = os.open(target, os.O_PATH | os.O_NOFOLLOW)
    except OSError:
        return None
    try:
        info = os.fstat(fd)
        if stat.S_ISREG(info.st_mode) and info.st_size >= RELEASE_ELSEWHERE_BYTES and info.st_nlink == 1:
            return fd
    except OSError:
        pass
    os.close(fd)
    return None


_HELPERS: list = []  # the helpers of _release_elsewhere not yet seen to end


def _release_elsewhere(fd: int) -> None:
    """Close ``fd``, the last reference to a file just replaced, so that freeing its blocks
    happens in a helper process, not here: freeing a 556 MB file took 0.14-0.25 s on the VM of
    bench/RESULTS.md ("Issue 15: the 30k-patch PLY"; ext4 mounted with ``discard``), after the
    output was complete.  The helper (``cat`` reading a pipe) holds a copy of ``fd``; ours is
    closed first, then the pipe, so the helper's exit is the last close.  Where no helper can be
    started, the plain close."""
    import subprocess

    try:
        reading, writing = os.pipe()
    except OSError:
        os.close(fd)
        return
    _HELPERS[:] = [helper for helper in _HELPERS if helper.poll() is None]  # reaped when done
    try:
        _HELPERS.append(subprocess.Popen(["cat"], stdin=reading, stdout=subprocess.DEVNULL,
                                         stderr=subprocess.DEVNULL, pass_fds=(fd,), start_new_session=True))
    except (OSError, ValueError, subprocess.SubprocessError):
        pass
    finally:
        os.close(reading)
        os.close(fd)  # the helper's copy keeps the file
        os.close(writing)  # the helper sees the end of its input and exits


def _naming(error: OSError, target: Path) -> OSError:
    """The same error (class, errno) naming the output file rather than the temporary one or
    none (a full disk, a read-only file system)."""
    return type(error)(error.errno, f"cannot write: {error.strerror or error}", os.fspath(target))


def _as_array(values, dtype, shape_tail: tuple, name: str) -> np.ndarray:
    array = np.asarray(values)
    if array.ndim != 1 + len(shape_tail) or array.shape[1:] != shape_tail:
        raise ValueError(f"{name} must have shape (n, {', '.join(map(str, shape_tail))})"
                         if shape_tail else f"{name} must have shape (n,)")
    return np.ascontiguousarray(array, dtype=dtype)


def _vertex_arrays(block) -> VertexBlock:
    """The five vertex arrays of ``block`` (any object with those attributes), checked."""
    arrays = VertexBlock(*(_as_array(getattr(block, name), dtype, shape, name) for name, dtype, shape in VERTEX_RECORD))
    lengths = {len(a) for a in arrays}
    if len(lengths) != 1:
        raise ValueError(f"vertex arrays differ in length: {[len(a) for a in arrays]}")
    return arrays


def _face_array(triangles, num_vertices: int) -> np.ndarray:
    """(k, 3) uint32 triangles, checked against the declared vertex total."""
    triangles = np.asarray(triangles)
    if triangles.ndim != 2 or triangles.shape[1] != 3:
        raise ValueError(f"triangles must have shape (n, 3), got {triangles.shape}")
    if len(triangles):  # unsigned indices (the device's): no pass for the minimum
        low = 0 if triangles.dtype.kind == "u" else int(triangles.min())
        high = int(triangles.max())
        if low < 0 or high >= num_vertices:
            raise ValueError(f"triangle indices span [{low}, {high}], outside [0, {num_vertices})")
    return np.ascontiguousarray(triangles, dtype=np.uint32)


class _StreamingWriter:
    """Shared bookkeeping: declared totals, counts written so far, the atomic target file."""

    def __init__(self, path: str | os.PathLike, num_vertices: int, num_faces: int):
        if num_vertices < 0 or num_faces < 0:
            raise ValueError("vertex and face totals must be non-negative")
        self.path = Path(path)
        self.num_vertices = int(num_vertices)
        self.num_faces = int(num_faces)
        self.vertices_written = 0
        self.faces_written = 0
        self._atomic = atomic_write(self.path, "wb")
        self._file: IO | None = None
        self._face_spool: IO | None = None

    def __enter__(self):
        self._file = self._atomic.__enter__()
        try:
            self._write_header()
        except BaseException as error:
            self._abort(error)
            raise
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            try:
                self._finish()
            except BaseException as error:
                self._abort(error)
                raise
            self._atomic.__exit__(None, None, None)
        else:
            self._abort(exc)
        return False

    def _abort(self, error: BaseException) -> None:
        """Remove the temporary files; the caller re-raises ``error``."""
        self._close_spool()
        self._atomic.__exit__(type(error), error, error.__traceback__)

    def _put_faces(self, data: bytes) -> None:
        """Face records go after every vertex: straight into the file once all vertices are
        written, else to an anonymous spool appended at the end.  So the file does not depend
        on how the mesh was cut into blocks."""
        if self.vertices_written == self.num_vertices and self._face_spool is None:
            self._file.write(data)
            return
        if self._face_spool is None:
            self._face_spool = tempfile.TemporaryFile(dir=self.path.parent)
        self._face_spool.write(data)

    def _close_spool(self) -> None:
        if self._face_spool is not None:
            self._face_spool.close()
            self._face_spool = None

    def _take_vertices(self, block) -> VertexBlock:
        arrays = _vertex_arrays(block)
        if self.vertices_written + len(arrays.positions) > self.num_vertices:
            raise ValueError(f"more vertices than the {self.num_vertices} declared")
        self.vertices_written += len(arrays.positions)
        return arrays

    def _take_faces(self, triangles) -> np.ndarray:
        faces = _face_array(triangles, self.num_vertices)
        if self.faces_written + len(faces) > self.num_faces:
            raise ValueError(f"more faces than the {self.num_faces} declared")
        self.faces_written += len(faces)
        return faces

    def _check_totals(self) -> None:
        if (self.vertices_written, self.faces_written) != (self.num_vertices, self.num_faces):
            raise ValueError(
                f"{self.path}: wrote {self.vertices_written} vertices and {self.faces_written} faces, "
                f"declared {self.num_vertices} and {self.num_faces}"
            )

    def _write_header(self) -> None:
        raise NotImplementedError

    def _finish(self) -> None:
        self._check_totals()
        if self._face_spool is not None:
            self._face_spool.seek(0)
            shutil.copyfileobj(self._face_spool, self._file, 1 << 24)
            self._close_spool()
