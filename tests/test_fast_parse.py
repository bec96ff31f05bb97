""".bpt / .bez read by NumPy at once (io/text.py _Numbers, bpt._fast_bpt, bez._fast_bez): bitwise
what the line-by-line parsers give, and never a file they would refuse (issue 15)."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.io import bez, bpt
from cltess.io.text import _Lines
from cltess.scene import SceneError


def slow_bpt(text: str):
    return bpt._parse_bpt(_Lines("f.bpt", text))


def slow_bez(text: str):
    return bez._parse_bez(_Lines("f.bez", text))


def random_patches(rng, count, rational):
    patches = rng.normal(size=(count, 4, 4, 4)) * 10 ** rng.uniform(-3, 3)
    patches[..., 3] = rng.uniform(0.2, 3.0, size=(count, 4, 4)) if rational else 1.0
    patches[..., :3] *= patches[..., 3:]
    return patches


@pytest.mark.parametrize("rational", [False, True])
def test_fast_equals_slow_on_written_files(tmp_path, rng, rational):
    patches = random_patches(rng, 50, rational)
    for module, slow in ((bpt, slow_bpt), (bez, slow_bez)):
        path = tmp_path / f"p{module.EXTENSION}"
        module.write(path, patches)
        fast = (bpt._fast_bpt if module is bpt else bez._fast_bez)(path.read_bytes())
        assert fast is not None
        assert fast.tobytes() == slow(path.read_text()).tobytes()
        assert module.read(path).patches.tobytes() == fast.astype(module.read(path).patches.dtype).tobytes()


def one_patch_bpt(coordinate: str, separator: str = " ", line_end: str = "\n") -> str:
    points = [f"{i} {j} 0" for j in range(4) for i in range(4)]
    points[5] = f"1{separator}{coordinate}{separator}0"
    return line_end.join(["1", "3 3", *points]) + line_end


@pytest.mark.parametrize("token", ["1-2", "1e5.2", "1.2.3", "--1", "1e", "+", ".", "1e400", "e5", "1e5e5",
                                   "0x10", "1_0", "nan", "\u0663", "+-1"])
def test_tokens_the_slow_parser_refuses_are_refused(token):
    text = one_patch_bpt(token)
    assert bpt._fast_bpt(text.encode()) is None
    with pytest.raises(SceneError, match="line 8"):
        slow_bpt(text)


@pytest.mark.parametrize("separator, line_end", [(" ", "\r\n"), ("\t", "\n"), ("  ", "\r"), (" ", "\n\n \n")])
def test_spacing_and_line_ends(separator, line_end):
    text = one_patch_bpt("-1.5e-3", separator, line_end)
    fast = bpt._fast_bpt(text.encode())
    assert fast is not None and fast.tobytes() == slow_bpt(text).tobytes()


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet="0123456789eE.+- \t", min_size=1, max_size=12))
def test_a_file_the_fast_path_takes_parses_the_same_line_by_line(token):
    text = one_patch_bpt(token)
    fast = bpt._fast_bpt(text.encode())
    if fast is None:
        return
    assert fast.tobytes() == slow_bpt(text).tobytes()


@settings(max_examples=200, deadline=None)
@given(st.text(alphabet="0123456789eE.+-, \t", min_size=1, max_size=10), st.integers(0, 1))
def test_bez_fast_path_takes_only_what_the_slow_parser_takes(token, where):
    indices = ",".join(map(str, range(1, 17)))
    vertices = [f"{i},{j},0" for j in range(4) for i in range(4)]
    if where:
        indices = indices.replace("5", token, 1)
    else:
        vertices[3] = f"1,{token},2"
    text = "\n".join(["1", indices, "16", *vertices]) + "\n"
    fast = bez._fast_bez(text.encode())
    if fast is None:
        return
    assert fast.tobytes() == slow_bez(text).tobytes()


def test_the_scene_cache_gives_the_parsed_patches_back(tmp_path, rng, monkeypatch):
    from cltess.io import scene_cache

    cache = tmp_path / "cache"
    monkeypatch.setenv("CLTESS_SCENE_CACHE", str(cache))
    monkeypatch.setattr(scene_cache, "MIN_BYTES", 0)
    path = tmp_path / "p.bpt"
    bpt.write(path, random_patches(rng, 20, True))
    first = bpt.read(path).patches
    (entry,) = cache.iterdir()
    assert bpt.read(path).patches.tobytes() == first.tobytes()  # from the cache
    entry.write_bytes(b"not an npy file")  # a broken entry: parsed again, and stored again
    assert bpt.read(path).patches.tobytes() == first.tobytes()
    assert np.load(entry).tobytes() == np.asarray(first, np.float64).tobytes()
    bpt.write(path, random_patches(rng, 20, False))  # another file: another entry
    assert bpt.read(path).patches.tobytes() != first.tobytes() and len(list(cache.iterdir())) == 2
    path.write_text(path.read_text().replace("3 3", "2 3", 1))  # an error is reported, never cached
    for _ in range(2):
        with pytest.raises(SceneError, match="line 2"):
            bpt.read(path)
    assert len(list(cache.iterdir())) == 2
    monkeypatch.setenv("CLTESS_SCENE_CACHE", "off")
    assert scene_cache.cache_folder() is None


def test_a_cache_miss_hashes_the_file_once_unless_it_changed(tmp_path, rng, monkeypatch):
    """The key hashed from the file's mapping is reused for the entry a miss stores, unless the
    file changed in between (then the bytes read are hashed): either way the entry is the one a
    later read looks up."""
    from cltess.io import scene_cache

    monkeypatch.setenv("CLTESS_SCENE_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(scene_cache, "MIN_BYTES", 0)
    hashed = []
    key = scene_cache._key
    monkeypatch.setattr(scene_cache, "_key", lambda data: hashed.append(len(data)) or key(data))
    path = tmp_path / "p.bpt"
    bpt.write(path, random_patches(rng, 20, False))
    first = bpt.read(path).patches
    assert len(hashed) == 1 and len(list((tmp_path / "cache").iterdir())) == 1
    assert bpt.read(path).patches.tobytes() == first.tobytes() and len(hashed) == 2  # a hit
    bpt.write(path, random_patches(rng, 20, False))
    monkeypatch.setattr(scene_cache, "_version", lambda path: "changed since it was hashed")
    second = bpt.read(path).patches
    assert len(hashed) == 4 and len(list((tmp_path / "cache").iterdir())) == 2
    monkeypatch.undo()
    monkeypatch.setenv("CLTESS_SCENE_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(scene_cache, "MIN_BYTES", 0)
    assert bpt.read(path).patches.tobytes() == second.tobytes() and len(list((tmp_path / "cache").iterdir())) == 2
