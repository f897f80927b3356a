"""Canvas compositing like a browser, PNG display, and image files through OpenImageIO."""
import numpy as np
import pytest

import softgl
from softgl import display, io


def composite_f64(rgba, premultiplied, page=(255, 255, 255)):
    c = rgba[..., :3] / 255.0
    a = rgba[..., 3:4] / 255.0
    p = np.array(page) / 255.0
    shown = (c if premultiplied else c * a) + (1 - a) * p
    return np.clip(np.floor(shown * 255 + 0.5), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("premultiplied", [True, False])
def test_canvas_composites_over_white_page(premultiplied):
    gl = softgl.Context(2, 1, antialias=False, premultipliedAlpha=premultiplied,
                        preserveDrawingBuffer=True)
    gl.clearColor(0.2, 0.1, 0.0, 0.4)
    gl.clear(gl.COLOR_BUFFER_BIT)
    shown = display.canvas_image(gl)
    raw = np.array([[[51, 26, 0, 102]] * 2], np.float64)
    assert np.array_equal(shown, composite_f64(raw, premultiplied))
    # Hand computation for the premultiplied case: 51 + (1 - 0.4) * 255 = 204.
    if premultiplied:
        assert shown[0, 0].tolist() == [204, 179, 153]


def test_opaque_canvas_ignores_page():
    gl = softgl.Context(1, 1, alpha=False, antialias=False)
    gl.clearColor(0.5, 0.25, 1, 0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert display.canvas_image(gl, background=(0, 0, 0)).tolist() == [[[128, 64, 255]]]


def test_presenting_clears_unless_preserved():
    for preserve in (False, True):
        gl = softgl.Context(1, 1, antialias=False, preserveDrawingBuffer=preserve)
        gl.clearColor(1, 0, 0, 1)
        gl.clear(gl.COLOR_BUFFER_BIT)
        png = gl._repr_png_()                 # showing the canvas never clears it
        assert png.startswith(b"\x89PNG")
        assert gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0].tolist() == [255, 0, 0, 255]
        display.present(gl)                   # the end of a browser frame does
        after = gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0].tolist()
        assert after == ([255, 0, 0, 255] if preserve else [0, 0, 0, 0])


def test_png_roundtrip_through_openimageio(tmp_path):
    gl = softgl.Context(5, 3, antialias=False, preserveDrawingBuffer=True)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(0, 2, 5, 1)   # top row in GL coordinates -> first row of the image file
    gl.clearColor(0, 0, 1, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    path = io.save(gl, tmp_path / "canvas.png")
    image = io.load_image(path)
    assert image.shape == (3, 5, 4) and image.dtype == np.uint8
    assert image[0].tolist() == [[0, 0, 255, 255]] * 5 and not image[1:].any()
    # The in-memory PNG encoder used for Jupyter gives the same pixels.
    (tmp_path / "repr.png").write_bytes(display.encode_png(image))
    assert np.array_equal(io.load_image(tmp_path / "repr.png"), image)


@pytest.mark.parametrize("suffix", [".exr", ".tif"])
def test_float_images_roundtrip(tmp_path, suffix):
    image = np.random.default_rng(1).random((4, 6, 4)).astype(np.float32)
    path = io.save(image, tmp_path / f"f{suffix}")
    back = io.load_image(path)
    assert back.dtype == np.float32
    np.testing.assert_array_equal(back, image)


def test_save_rejects_bad_shapes(tmp_path):
    with pytest.raises(ValueError):
        io.save(np.zeros((2, 2, 7), np.uint8), tmp_path / "x.png")
