"""Pictures (cltess/render.py, ``cltess render``, ``--preview``): checked by their pixels."""
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from cltess.cli import main
from cltess.render import BACK, Rasteriser, View, write_png

SCENES = Path(__file__).resolve().parent.parent / "scenes"


def read_png(path) -> np.ndarray:
    """(H, W, 3) uint8 of an 8-bit RGB PNG with filter 0 rows (what write_png writes)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, chunks = 8, {}
    while at < len(data):
        (length,) = struct.unpack(">I", data[at:at + 4])
        kind, body = data[at + 4:at + 8], data[at + 8:at + 8 + length]
        assert struct.unpack(">I", data[at + 8 + length:at + 12 + length])[0] == zlib.crc32(kind + body)
        chunks[kind] = chunks.get(kind, b"") + body
        at += 12 + length
    width, height, depth, colour = struct.unpack(">IIBB", chunks[b"IHDR"][:10])
    assert (depth, colour) == (8, 2)
    rows = np.frombuffer(zlib.decompress(chunks[b"IDAT"]), np.uint8).reshape(height, 1 + 3 * width)
    assert (rows[:, 0] == 0).all()
    return rows[:, 1:].reshape(height, width, 3)


def straight_view(width=64, height=48) -> View:
    """Camera at the origin looking down -z, 90 degrees vertical field of view."""
    return View(np.eye(4), 90.0, width, height)


def covered(image) -> np.ndarray:
    return (image != 255).any(axis=2)


def test_a_triangle_covers_its_projected_area_and_faces_the_right_way():
    # at depth 1 with a 90-degree view, y in [-1, 1] spans the image height
    positions = np.array([[-1, -1, -1], [1, -1, -1], [-1, 1, -1]], float)
    drawing = Rasteriser(straight_view())
    drawing.add(positions, [[0, 1, 2]])  # counter-clockwise seen from the camera: front
    image = drawing.image()
    width_world = 2 * 64 / 48  # the image spans x in [-4/3, 4/3]
    expected = 2.0 / (width_world * 2)  # triangle area 2 over the image's area
    assert abs(covered(image).mean() - expected) < 0.02
    front = image[covered(image)].astype(float).mean(axis=0)
    assert front[2] > front[0]  # grey-blue
    drawing = Rasteriser(straight_view())
    drawing.add(positions, [[0, 2, 1]])  # clockwise: its back faces the camera
    back = drawing.image()[covered(image)].astype(float).mean(axis=0)
    assert back[0] > 2 * back[2] and np.argmax(back) == np.argmax(BACK)


def test_the_nearer_triangle_wins_in_either_order():
    near = np.array([[-1, -1, -1], [1, -1, -1], [-1, 1, -1]], float)
    far = near * 2  # the same on screen, twice as far
    for order in ((near, far), (far, near)):
        drawing = Rasteriser(straight_view())
        for positions, colour in zip(order, ([[1, 0, 0]], [[0, 1, 0]]) if order[0] is near else
                                     ([[0, 1, 0]], [[1, 0, 0]])):
            drawing.add(positions, [[0, 1, 2]], np.array(colour, float))
        image = drawing.image()
        inside = image[20:30, 10:20].reshape(-1, 3).astype(int)
        assert (inside[:, 0] > inside[:, 1]).all()  # red, the near one


def test_behind_the_camera_is_not_drawn():
    drawing = Rasteriser(straight_view())
    drawing.add(np.array([[-1, -1, 1], [1, -1, 1], [-1, 1, 1]], float), [[0, 1, 2]])
    assert not covered(drawing.image()).any()


def test_png_round_trip(tmp_path):
    image = np.random.default_rng(1).integers(0, 256, (7, 5, 3), dtype=np.uint8)
    write_png(tmp_path / "x.png", image)
    assert np.array_equal(read_png(tmp_path / "x.png"), image)


# --------------------------------------------------------------------------- command line


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def red_fraction(image) -> float:
    pixels = image[covered(image)].astype(int)
    return float(((pixels[:, 0] > pixels[:, 2] + 60)).mean())


def test_render_sphere(capsys, tmp_path):
    code, out, err = run(capsys, "render", SCENES / "sphere.bpt", "--eps", "0.5%", "--size", "200x150",
                         "-o", tmp_path / "s.png")
    assert code == 0, err
    image = read_png(tmp_path / "s.png")
    assert image.shape == (150, 200, 3)
    # a unit sphere framed by its bounding box's diagonal: a disc of about 15-40% of the image
    assert 0.15 < covered(image).mean() < 0.4
    assert red_fraction(image) == 0  # outward: no back face in sight
    shades = image[covered(image)].astype(int).sum(axis=1)
    assert shades.std() > 20  # shaded, not a flat silhouette
    assert "(200x150)" in out


def test_render_shows_an_inside_out_cup_in_red(capsys, tmp_path):
    for option, name in (("--orient", "good"), ("--no-orient", "raw")):
        code, _, err = run(capsys, "render", SCENES / "teacup.bez", "--eps", "0.5%", "--size", "160",
                           option, "-q", "-o", tmp_path / f"{name}.png")
        assert code == 0, err
    good, raw = read_png(tmp_path / "good.png"), read_png(tmp_path / "raw.png")
    assert good.shape == (120, 160, 3)
    assert red_fraction(raw) > 0.5 > 0.2 > red_fraction(good)


def test_render_coloured_by_factor(capsys, tmp_path):
    code, _, err = run(capsys, "render", SCENES / "teapot.bez", "--eps", "0.2%", "--color", "factor",
                       "--size", "160", "-q", "-o", tmp_path / "f.png")
    assert code == 0, err
    pixels = read_png(tmp_path / "f.png")
    distinct = np.unique(pixels[covered(pixels)] // 32, axis=0)
    assert len(distinct) > 5  # several factor colours


def test_preview_on_tessellate(capsys, tmp_path):
    code, out, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.5%", "-o", tmp_path / "s.ply",
                         "--preview", tmp_path / "s.png")
    assert code == 0, err
    image = read_png(tmp_path / "s.png")
    assert image.shape == (600, 800, 3) and 0.15 < covered(image).mean() < 0.4
    assert str(tmp_path / "s.png") in out


@pytest.mark.parametrize("arguments, fragment", [
    (["--size", "0"], "--size"), (["--size", "8x8"], "--size"), (["--size", "wide"], "--size"),
    (["--size", "1x2x3"], "--size"), (["--color", "rainbow"], "--color"), (["-o", "out.jpg"], ".png"),
])
def test_render_bad_options_exit_2(capsys, tmp_path, arguments, fragment):
    arguments = [str(tmp_path / a) if a.startswith("out.") else a for a in arguments]
    if "-o" not in arguments:
        arguments += ["-o", str(tmp_path / "out.png")]
    code, _, err = run(capsys, "render", SCENES / "sphere.bpt", "--eps", "0.01", *arguments)
    assert code == 2 and fragment in err and "Traceback" not in err
    assert not any(tmp_path.iterdir())


def test_bad_preview_exits_2(capsys, tmp_path):
    code, _, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", "-o", tmp_path / "s.ply",
                       "--preview", tmp_path / "s.jpg")
    assert code == 2 and ".png" in err
    code, _, err = run(capsys, "tessellate", SCENES / "sphere.bpt", "--eps", "0.01", "-o", tmp_path / "s.ply",
                       "--preview", tmp_path / "missing" / "s.png")
    assert code == 2 and "does not exist" in err
    assert not any(tmp_path.iterdir())


def test_big_guy_stored_inside_out_renders_right_side_out(capsys, tmp_path):
    """bigguy.bez faces inwards as stored, in 1541 pieces that share no exact edge: each piece
    is turned by its own signed volume."""
    for option, name in (("--orient", "good"), ("--no-orient", "raw")):
        code, _, err = run(capsys, "render", SCENES / "bigguy.bez", "--eps", "0.5%", "--size", "160", option,
                           "-q", "-o", tmp_path / f"{name}.png")
        assert code == 0, err
    assert red_fraction(read_png(tmp_path / "raw.png")) > 0.9
    assert red_fraction(read_png(tmp_path / "good.png")) < 0.1


def test_vertex_normals_shade_smoothly_and_flat_without_them():
    positions = np.array([[-1, -1, -1], [1, -1, -1], [-1, 1, -1]], float)
    flat = Rasteriser(straight_view())
    flat.add(positions, [[0, 1, 2]])
    smooth = Rasteriser(straight_view())
    smooth.add(positions, [[0, 1, 2]], normals=np.array([[0, 0, 1], [0.8, 0, 0.6], [0, 0.8, 0.6]]))
    flat_image, smooth_image = flat.image(), smooth.image()
    mask = np.pad(covered(flat_image), 1)
    inside = mask[1:-1, 1:-1] & mask[:-2, 1:-1] & mask[2:, 1:-1] & mask[1:-1, :-2] & mask[1:-1, 2:]  # not the rim
    assert flat_image[inside].astype(float).std(axis=0).max() < 1
    assert smooth_image[inside].astype(float).std(axis=0).max() > 5
