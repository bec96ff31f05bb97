"""Streamed and batched output of the strip patterns (SD-2, ESC) carries their strips
(cltess/stream.py, io/npz.py NpzWriter): batches joined equal the whole, a streamed .npz equals the
single pass array for array (strips included), PLY and OBJ write the strips expanded (the
triangles), and a failed stream leaves no file."""
from pathlib import Path

import numpy as np
import pytest
import trimesh

from cltess.formats import load_scene
from cltess.io.npz import NPZ_ARRAYS, load_npz
from cltess.strips import STRIP_RESTART, expand_strips
from cltess.stream import tessellate_to_file

SCENES = Path(__file__).resolve().parent.parent / "scenes"


@pytest.fixture(scope="module")
def strip_scenes(tmp_path_factory):
    """(name, scene, options, budget bytes that cut it into several batches)."""
    ico = tmp_path_factory.mktemp("mesh") / "ico.ply"
    trimesh.creation.icosphere(3).export(ico)
    return [("esc teacup", load_scene(SCENES / "teacup.bez"), dict(eps=0.01, pattern="esc"), 150_000),
            ("sd2 icosphere", load_scene(ico), dict(eps=1e-3, pattern="sd2"), 1_500_000),
            ("transition teapot", load_scene(SCENES / "teapot.bez"), dict(eps=0.01), 300_000)]


def joined(batches) -> np.ndarray:
    """The batches' strips joined as the whole has them: a restart between non-empty ones."""
    parts = [b.strips for b in batches if len(b.strips)]
    return np.concatenate([np.append(p, np.uint32(STRIP_RESTART)) for p in parts])[:-1] if parts else np.zeros(0, np.uint32)


def test_batches_carry_strips_that_join_to_the_whole(tessellator, strip_scenes):
    for name, scene, options, budget in strip_scenes[:2]:
        whole = tessellator.tessellate(scene, **options)
        _, batches = tessellator.tessellate_in_batches(scene, budget // 3, **options)
        batches = list(batches)
        assert len(batches) > 2 and all(b.strips is not None for b in batches), name
        assert np.array_equal(joined(batches), whole.strips), name
        assert np.array_equal(np.concatenate([b.triangles for b in batches]), whole.triangles), name


def test_a_streamed_npz_equals_the_single_pass(tessellator, strip_scenes, tmp_path):
    """Several batches into an .npz: every array equal to the single pass's, the strips included
    (and absent for a pattern without them); on_batch sees each batch's strips."""
    for name, scene, options, budget in strip_scenes:
        seen = []
        streamed = tessellate_to_file(tessellator, scene, tmp_path / "a.npz", max_memory_bytes=budget,
                                      on_batch=lambda b: seen.append(b.strips is not None and len(b.strips) > 0),
                                      **options)
        single = tessellate_to_file(tessellator, scene, tmp_path / "b.npz", **options)
        assert streamed.batches > 2 and single.batches == 1, name
        a, b = load_npz(tmp_path / "a.npz"), load_npz(tmp_path / "b.npz")
        for array in (*NPZ_ARRAYS, "strips", "real_factors"):
            left, right = getattr(a, array), getattr(b, array)
            assert (left is None) == (right is None), (name, array)
            if left is not None:
                assert left.dtype == right.dtype and np.array_equal(left, right), (name, array)
        has_strips = name != "transition teapot"
        assert (a.strips is not None) == has_strips and any(seen) == has_strips, name
        if name.startswith("esc"):  # the strips expand to the triangle list, in its order
            assert np.array_equal(expand_strips(a.strips, drop_degenerate=True), a.triangles)
        if name.startswith("sd2"):
            assert np.array_equal(expand_strips(a.strips), a.triangles) and a.real_factors is not None
        assert a.stats["patches"] == scene.num_patches


@pytest.mark.parametrize("suffix", [".ply", ".obj"])
def test_streamed_ply_and_obj_of_a_strip_pattern_equal_the_single_pass(tessellator, strip_scenes, tmp_path, suffix):
    """PLY and OBJ keep triangles: the strips expanded, byte for byte the single pass's file."""
    name, scene, options, budget = strip_scenes[0]
    streamed = tessellate_to_file(tessellator, scene, tmp_path / f"a{suffix}", max_memory_bytes=budget, **options)
    single = tessellate_to_file(tessellator, scene, tmp_path / f"b{suffix}", **options)
    assert streamed.batches > 2 and single.batches == 1
    assert (tmp_path / f"a{suffix}").read_bytes() == (tmp_path / f"b{suffix}").read_bytes()


def test_a_failed_npz_stream_leaves_nothing(tessellator, strip_scenes, tmp_path):
    name, scene, options, budget = strip_scenes[0]
    calls = []

    def fail_on_the_third(batch):
        calls.append(1)
        if len(calls) == 3:
            raise RuntimeError("stopped")

    with pytest.raises(RuntimeError, match="stopped"):
        tessellate_to_file(tessellator, scene, tmp_path / "out.npz", max_memory_bytes=budget,
                           on_batch=fail_on_the_third, **options)
    assert not any(tmp_path.iterdir())
