"""Memory bound (cltess/stream.py): a scene whose output is several times the cap streams to a
file identical to the single-pass output, and peak memory stays within the cap plus a stated
overhead (issue 5)."""
import subprocess
import sys
from pathlib import Path

import pyopencl as cl
import pytest

from cltess.io import load_scene
from cltess.limits import OutputTooLarge
from cltess.stream import COPIES_IN_FLIGHT, STREAM_BATCH_BYTES, parse_size, tessellate_to_file

SCENES = Path(__file__).resolve().parent.parent / "scenes"
MiB = 2**20
# Peak RSS above a tiny run of the same command (imports, OpenCL runtime, programs): the cap,
# plus this much for the plan, allocator slack and the writer's buffers (measured: 31 MiB).
STATED_OVERHEAD = 40 * MiB

PEAK_RSS = r"""
import re, sys
from pathlib import Path
import cltess.stream
from cltess.cli import main
if "--single-pass" in sys.argv:  # the whole output in one batch, as the budget allows
    sys.argv.remove("--single-pass")
    cltess.stream.STREAM_BATCH_BYTES = 0
code = main(["tessellate"] + sys.argv[1:] + ["-q", "--no-weld"])  # per-patch output streams
# VmHWM, not ru_maxrss: Linux carries ru_maxrss over execve from the parent process.
print(int(re.search(r"VmHWM:\s+(\d+) kB", Path("/proc/self/status").read_text()).group(1)) * 1024)
sys.exit(code)
"""


def peak_rss(*args) -> int:
    done = subprocess.run([sys.executable, "-c", PEAK_RSS, *map(str, args)], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    return int(done.stdout.split()[-1])


def test_streaming_under_a_16mb_cap_matches_single_pass_and_bounds_memory(tessellator, tmp_path):
    cap = 16 * MiB
    scene = SCENES / "teapots.json"
    options = ["--eps", "0.0005", "--max-factor", "128"]
    # PoCL compiles kernel variants for new launch sizes at enqueue, in-process, and caches them
    # on disk: one unmeasured run first, so that no measured run pays for a compilation.
    peak_rss(scene, *options, "--max-memory", "16M", "-o", tmp_path / "warm-up.ply")
    baseline = peak_rss(SCENES / "teapot.bez", "--eps", "0.1", "-o", tmp_path / "tiny.ply")
    streamed = peak_rss(scene, *options, "--max-memory", "16M", "-o", tmp_path / "streamed.ply")
    single = peak_rss(scene, *options, "--single-pass", "-o", tmp_path / "single.ply")
    default = peak_rss(scene, *options, "-o", tmp_path / "default.ply")  # batches of STREAM_BATCH_BYTES
    size = (tmp_path / "streamed.ply").stat().st_size
    print(f"output {size / MiB:.0f} MiB; peak RSS above a tiny run: streamed "
          f"{(streamed - baseline) / MiB:.1f} MiB under a 16 MiB cap, single pass {(single - baseline) / MiB:.1f} MiB, "
          f"default {(default - baseline) / MiB:.1f} MiB")
    assert size >= 8 * cap
    assert (tmp_path / "streamed.ply").read_bytes() == (tmp_path / "single.ply").read_bytes()
    assert (tmp_path / "default.ply").read_bytes() == (tmp_path / "single.ply").read_bytes()
    assert streamed - baseline <= cap + STATED_OVERHEAD
    if tessellator.device.type & cl.device_type.CPU:  # the cap is what made the difference
        # (On an NVIDIA H200 the single pass peaked only 60 MiB above the tiny run for 131 MiB of
        # output, at the session's start as after it: a GPU's host memory is not this premise.)
        assert single - baseline > 2 * (cap + STATED_OVERHEAD)
    assert default - baseline <= COPIES_IN_FLIGHT * STREAM_BATCH_BYTES + STATED_OVERHEAD


@pytest.mark.parametrize("suffix", [".ply", ".obj"])
def test_streamed_files_equal_single_pass_files(tessellator, tmp_path, suffix):
    """PLY and OBJ: byte-identical to a single pass (faces are spooled until every vertex is
    written, and OBJ writes v, vt, vn per vertex)."""
    scene = load_scene(SCENES / "teapot.bez")
    streamed = tessellate_to_file(tessellator, scene, tmp_path / f"a{suffix}", max_memory_bytes=900_000, eps=0.002)
    single = tessellate_to_file(tessellator, scene, tmp_path / f"b{suffix}", eps=0.002, batch_bytes=0)
    assert streamed.batches > 3 and single.batches == 1
    assert streamed.stats == single.stats
    assert (tmp_path / f"a{suffix}").read_bytes() == (tmp_path / f"b{suffix}").read_bytes()


def test_each_batch_runs_its_stages_once(tessellator, tmp_path, monkeypatch):
    """A streamed batch launches stages 4-5 once, its read-back enqueued right behind them.
    (Sessions 8-10 ran every batch of a stream twice: the check for a frame launched on the
    buffers' capacity took a batch's range for a plan's whole output, never fitting.)"""
    from cltess.backends.opencl import output

    scene = load_scene(SCENES / "teapot.bez")
    launches, early = [], []
    real_emit_async, real_start = tessellator.emit_async, output.OutputBuffers.start_read_back

    def emit_async(plan, first, last, forward_differencing=True, out=None):
        launches.append((first, last))
        return real_emit_async(plan, first, last, forward_differencing, out)

    def start_read_back(self, *sizes):
        early.append(sizes)
        return real_start(self, *sizes)

    monkeypatch.setattr(tessellator, "emit_async", emit_async)
    monkeypatch.setattr(output.OutputBuffers, "start_read_back", start_read_back)
    result = tessellate_to_file(tessellator, scene, tmp_path / "a.ply", max_memory_bytes=900_000, eps=0.002)
    assert result.batches > 3
    assert launches == result.batch_ranges  # once each, in order
    if tessellator.device.type & cl.device_type.CPU:  # a map per batch, no sizes needed
        assert early == [()] * result.batches
    else:  # each batch's copies (into page-locked memory: several batches, OutputBuffers(pinned=True))
        assert len(early) == result.batches and sum(sizes[0] for sizes in early) == result.stats["vertices"]


@pytest.mark.parametrize("suffix", [".stl", ".glb"])
def test_formats_that_do_not_stream_are_refused_before_writing(tessellator, tmp_path, suffix):
    scene = load_scene(SCENES / "teapot.bez")
    with pytest.raises(OutputTooLarge, match="cannot be streamed"):
        tessellate_to_file(tessellator, scene, tmp_path / f"out{suffix}", max_memory_bytes=900_000, eps=0.002)
    assert not any(tmp_path.iterdir())


def test_out_of_memory_on_the_device_retries_smaller_batches(tessellator, tmp_path, monkeypatch):
    """A batch that fails with an allocation error is split in halves, never hangs or dies."""
    import pyopencl as cl

    scene = load_scene(SCENES / "teapot.bez")
    real_emit = tessellator.emit
    failed = []

    def emit(plan, first, last, forward_differencing=True):
        if last - first > 4:
            failed.append((first, last))
            raise cl.MemoryError("clEnqueueNDRangeKernel", cl.status_code.MEM_OBJECT_ALLOCATION_FAILURE,
                                 "simulated")
        return real_emit(plan, first, last, forward_differencing)

    real_emit_async = tessellator.emit_async

    def emit_async(plan, first, last, forward_differencing=True, out=None):
        if last - first > 4:
            failed.append((first, last))
            raise cl.MemoryError("clCreateBuffer", cl.status_code.MEM_OBJECT_ALLOCATION_FAILURE, "simulated")
        return real_emit_async(plan, first, last, forward_differencing, out)

    monkeypatch.setattr(tessellator, "emit", emit)
    monkeypatch.setattr(tessellator, "emit_async", emit_async)
    result = tessellate_to_file(tessellator, scene, tmp_path / "a.ply", eps=0.01)
    monkeypatch.undo()
    tessellate_to_file(tessellator, scene, tmp_path / "b.ply", eps=0.01)
    assert failed and result.batches >= 8
    assert (tmp_path / "a.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()


@pytest.mark.parametrize("text, size", [("16M", 16 * MiB), ("512MB", 512 * MiB), ("2G", 2 * 2**30),
                                        ("1000", 1000), ("1.5K", 1536), ("4MiB", 4 * MiB)])
def test_parse_size(text, size):
    assert parse_size(text) == size


@pytest.mark.parametrize("text", ["0", "-1M", "lots", "M"])
def test_parse_size_refuses_nonsense(text):
    with pytest.raises((ValueError, IndexError)):
        parse_size(text)
