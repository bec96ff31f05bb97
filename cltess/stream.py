"""Tessellate a scene straight into a file, in batches that fit a memory budget.

Stages 1-3 run once for the whole scene (``Tessellator.plan``): the scan tells the output size
before anything big is allocated.  The patches are then cut into consecutive batches whose
output fits the budget; each batch runs stages 4-5 (``Tessellator.emit``) and is appended to a
streaming PLY or OBJ writer.  The file is the same, byte for byte, as a single pass would
write, and it appears only when complete (``io.writing.atomic_write``).  An .npz is streamed
too (``io.npz.NpzWriter``: its arrays spooled to temporary files, then zipped): the same
arrays as the single pass, a strip pattern's strips (SD-2, ESC) included; PLY and OBJ write
the triangles, which are the strips expanded.

Memory: batches are sized to a third of the budget, and a per-patch .ply's to at most
``STREAM_BATCH_BYTES`` (8 MB: for speed, measured).  Two batches' output buffers are alive at
once (``_overlapped``: the device computes batch k+1 while the host writes batch k), and on a
GPU their two page-locked host copies; on a CPU device the buffers are mapped, so the host
arrays are the device buffers themselves.  The PLY writer builds its records in four 4 MB
staging buffers (``io.direct``), the OBJ writer in chunks.  Between them at most 2 of the 3
thirds of the budget, plus the staging.

on_batch gets each batch as it is written: its arrays are views of buffers that batch k+2
reuses, so copy what must outlive the call.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pyopencl as cl

from .backends.opencl.tessellator import combine_verified
from .limits import OutputTooLarge
from .io.export import check_extension, export
from .io.npz import NpzWriter
from .io.obj import ObjWriter
from .io.ply import PlyWriter

COPIES_IN_FLIGHT = 3  # device buffers, host copy, writer records
STREAMING_WRITERS = {".ply": PlyWriter, ".obj": ObjWriter, ".npz": NpzWriter}
#: Output bytes per batch when a large .ply is streamed, whatever the budget allows (not .obj:
#: its faces before the last vertices go to a spool, and its text formatting is the cost):
#: two sets of batch buffers are reused throughout, so the process touches 2 x 8 MB of fresh
#: output memory instead of the whole output (556 MB first touched took 0.5-1.4 s on the 2-vCPU
#: VM, touched again 0.03-0.07 s), a batch is still in the CPU's cache when the host reads it,
#: and the device computes batch k+1 while batch k is written.  The 30k-patch PLY, median wall
#: of 5 (load 11): 8 MB 2.65 s, 4 MB 2.91, 32 MB 3.35, one pass 4.6 (CPU the same within
#: 0.1 s, one pass 0.2-0.3 s more).  bench/RESULTS.md, "Issue 15: the 30k-patch PLY (session 4)".
STREAM_BATCH_BYTES = 8 << 20


@dataclass
class StreamResult:
    """What a streamed run did: the scene's stats, summed stage times, the batches it took."""

    stats: dict
    stage_ms: dict
    batches: int
    budget_bytes: int
    path: Path
    batch_ranges: list = field(default_factory=list)


def default_budget(device: cl.Device) -> int:
    """Bytes of output a run may hold at once: half the device's memory, and no single
    buffer above the device's largest allocation."""
    return int(min(device.global_mem_size // 2, COPIES_IN_FLIGHT * device.max_mem_alloc_size))


def tessellate_to_file(tessellator, scene, path, max_memory_bytes: int | None = None,
                       weld: bool = False, uv: str = "drop", on_plan=None, on_batch=None, progress=None,
                       verify: bool = False, batch_bytes: int | None = None, **options) -> StreamResult:
    """Tessellate ``scene`` into ``path`` (.ply, .obj, .stl, .glb or .npz) within ``max_memory_bytes``.

    options: eps / pixels / max_factor / forward_differencing, as for ``Tessellator.tessellate``.
    weld: write one welded mesh (``cltess.weld``; ``uv`` "drop" or "seam"): it is built in
    memory, so it must fit the budget in one batch, as must .stl and .glb output; .ply, .obj
    and .npz without weld are streamed batch by batch (.npz: every array, strips included).  on_plan(plan): called after stages 1-3,
    before anything big is allocated or written (to check or refuse the output size).
    on_batch(tess): called with each batch's Tessellation (per-patch vertices, before welding),
    e.g. to draw a preview.
    progress(stage, done, total): called as batches are written.
    verify: measure the error of every batch on the device (``Tessellator.verify``); the stats
    (and a .npz file's stats_json) carry "verify_ratio" and where it occurs.
    batch_bytes: output per batch of a streamed .ply at most (None: STREAM_BATCH_BYTES;
    0: as much as the budget allows, one pass if the output fits); the file is the same.
    """
    path = Path(path)
    extension = check_extension(path)
    budget = max_memory_bytes or default_budget(tessellator.device)
    forward_differencing = options.pop("forward_differencing", True)
    plan = tessellator.plan(scene, **options)
    if on_plan is not None:
        on_plan(plan)
    try:
        ranges = plan.batch_ranges(max(budget // COPIES_IN_FLIGHT, 1))
    except OutputTooLarge as error:
        raise OutputTooLarge(f"{error} (a batch may take a third of the memory cap, {budget} bytes)") from None
    batch_bytes = STREAM_BATCH_BYTES if batch_bytes is None else batch_bytes
    if not weld and extension == ".ply" and 0 < batch_bytes < budget // COPIES_IN_FLIGHT:
        try:  # smaller batches than the budget allows: for speed (unless a patch alone is larger)
            ranges = plan.batch_ranges(batch_bytes)
        except OutputTooLarge:
            pass
    if weld or extension not in STREAMING_WRITERS or (extension == ".npz" and len(ranges) == 1):
        if len(ranges) > 1:
            why = "a welded mesh is built in memory" if weld else f"{extension} cannot be streamed"
            fix = "give --no-weld to stream per-patch .ply, .obj or .npz" if weld else "write .ply, .obj or .npz"
            raise OutputTooLarge(f"{path}: the output ({plan.output_bytes} bytes) needs {len(ranges)} batches "
                                 f"under a budget of {budget} bytes, and {why}; {fix}, or raise the memory cap")
        tess = tessellator.emit(plan, 0, plan.num_patches, forward_differencing)
        if verify:
            tess.stats.update(tessellator.verify(scene, plan, tess))
        if progress is not None:
            progress("tessellated", 1, 1)
        if on_batch is not None:
            on_batch(tess)
        result = tess.welded(uv=uv) if weld else tess
        if progress is not None and weld:
            progress("welded", 1, 1)
        export(result, path)
        return StreamResult(result.stats, tess.stage_ms, 1, budget, path, ranges)

    stage_ms: dict = {}
    done, verified = [], []
    with STREAMING_WRITERS[extension](path, plan.num_vertices, plan.num_indices // 3) as writer:
        for batch in _overlapped(tessellator, plan, ranges, forward_differencing):
            if isinstance(writer, NpzWriter):  # every array, strips included
                writer.write_batch(batch)
            else:  # PLY, OBJ: the triangles (a strip pattern's strips expanded)
                writer.write_vertices(batch)
                writer.write_faces(batch.triangles)
            if on_batch is not None:
                on_batch(batch)
            done.append((batch.stats["first_patch"], batch.stats["last_patch"]))
            if progress is not None:
                progress("batches", batch.stats["last_patch"], plan.num_patches)
            if verify:
                verified.append(tessellator.verify(scene, plan, batch))
            for stage, ms in batch.stage_ms.items():
                stage_ms[stage] = ms if stage == "total_wall" else stage_ms.get(stage, 0.0) + ms
            del batch
        stats = dict(plan.stats, **combine_verified(verified))
        if isinstance(writer, NpzWriter):
            writer.set_meta(stats, stage_ms)
    return StreamResult(stats, stage_ms, len(done), budget, path, done)


def _overlapped(tessellator, plan, ranges, forward_differencing: bool):
    """The batches' Tessellations in order, batch k+1's stages 4-5 enqueued before batch k is
    handed out, so the device computes it while the host writes batch k.  Two sets of output
    buffers take turns (``OutputBuffers``: reused, so allocated and first touched once; on a
    GPU read back through page-locked memory).  A batch the device has no memory for is
    split in two (``_emit_fitting``)."""
    from .backends.opencl.output import OutputBuffers

    if not hasattr(tessellator, "emit_async"):  # another backend: one batch after the other
        for first, last in ranges:
            yield from _emit_fitting(tessellator, plan, first, last, forward_differencing)
        return
    buffers = [OutputBuffers(tessellator, pinned=len(ranges) > 1) for _ in range(min(2, len(ranges)))]

    def start(k, first, last):
        try:
            job = tessellator.emit_async(plan, first, last, forward_differencing, out=buffers[k % 2])
            job.start_read_back()  # before the next batch's stages (in-order queue)
            return job
        except (cl.MemoryError, cl.RuntimeError) as error:
            if not _out_of_memory(error):
                raise
            return None

    def finish(first, last, job):
        if job is not None:
            try:
                batch = job.result()
            except (cl.MemoryError, cl.RuntimeError) as error:
                if not _out_of_memory(error):
                    raise
            else:
                yield batch
                return
        yield from _emit_fitting(tessellator, plan, first, last, forward_differencing)  # in halves if need be

    pending = None
    for k, (first, last) in enumerate(ranges):
        upcoming = (first, last, start(k, first, last))
        if pending is not None:
            yield from finish(*pending)
        pending = upcoming
    if pending is not None:
        yield from finish(*pending)


def _emit_fitting(tessellator, plan, first: int, last: int, forward_differencing: bool):
    """Emit patches first..last-1; if the device runs out of memory, retry in two halves."""
    try:
        yield tessellator.emit(plan, first, last, forward_differencing)
    except (cl.MemoryError, cl.RuntimeError) as error:
        if not _out_of_memory(error) or last - first == 1:
            raise
        middle = (first + last) // 2
        yield from _emit_fitting(tessellator, plan, first, middle, forward_differencing)
        yield from _emit_fitting(tessellator, plan, middle, last, forward_differencing)


def _out_of_memory(error: Exception) -> bool:
    text = str(error).upper()
    return isinstance(error, cl.MemoryError) or "MEM_OBJECT_ALLOCATION_FAILURE" in text \
        or "OUT_OF_RESOURCES" in text or "OUT_OF_HOST_MEMORY" in text


def parse_size(text: str) -> int:
    """'512M', '16MB', '2G', '1000000' -> bytes (binary units)."""
    units = {"K": 2**10, "M": 2**20, "G": 2**30}
    value = text.strip().upper().removesuffix("B").removesuffix("I")
    scale = units.get(value[-1:], 1)
    number = float(value[:-1] if value[-1:] in units else value)
    if not (number > 0 and number * scale < 2**63):
        raise ValueError(f"memory size must be positive, got {text!r}")
    return int(number * scale)


__all__ = ["StreamResult", "default_budget", "tessellate_to_file", "parse_size"]
