"""The silent traps of issue 19: natural Python mistakes must not draw nothing (or the wrong
thing) without a word, and the helpers must do what the lessons they teach do."""
import struct
import warnings
import zlib

import numpy as np
import pytest

import softgl
from softgl import display, experiments, io, programs
from softgl import transforms as T

VS = """attribute vec2 aPosition;
uniform mat4 uModel;
void main() { gl_Position = uModel * vec4(aPosition, 0.0, 1.0); gl_PointSize = 1.0; }"""
FS = "precision mediump float; void main() { gl_FragColor = vec4(1.0, 0.0, 0.0, 1.0); }"


def triangle_program(gl):
    prog = programs.Program(gl, VS, FS)
    gl.useProgram(prog.handle)
    loc = prog.attributes["aPosition"]
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    return prog


def red_pixels(gl):
    img = gl.readPixels(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight, gl.RGBA, gl.UNSIGNED_BYTE)
    return img[..., 0] > 0


# -- 1. float64 arrays meeting 32-bit float data ---------------------------------------------

def recorded(action):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")    # Python's default: once per call site
        action()
    return [w for w in caught if issubclass(w.category, softgl.Float64Warning)]


def test_float64_buffer_data_warns_once_per_call_site_and_keeps_webgl_bytes():
    gl = softgl.Context(16, 16, antialias=False)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    data = np.array([-.6, -.6, .6, -.6, 0, .6])        # NumPy's default dtype: float64

    def upload_three_times():
        for _ in range(3):
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
    caught = recorded(upload_three_times)
    assert len(caught) == 1
    assert "bufferData" in str(caught[0].message) and "np.float32" in str(caught[0].message)
    assert caught[0].filename == __file__            # points at the user's line
    # WebGL's byte semantics stay: the buffer holds the 8-byte doubles.
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 48
    assert len(recorded(lambda: gl.bufferSubData(gl.ARRAY_BUFFER, 0, data[:2]))) == 1
    assert recorded(lambda: gl.bufferData(gl.ARRAY_BUFFER, data.astype(np.float32), gl.STATIC_DRAW)) == []
    # What the warning says to write draws the triangle.
    triangle_program(gl)
    gl.uniformMatrix4fv(gl.getUniformLocation(gl.getParameter(gl.CURRENT_PROGRAM), "uModel"),
                        False, T.identity())
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert red_pixels(gl).sum() > 20


@pytest.mark.filterwarnings("ignore::softgl.errors.GLWarning")   # the GL error WebGL gives too
def test_float64_texture_data_warns_and_strict_raises():
    gl = softgl.Context(4, 4, antialias=False)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    pixels = np.full((2, 2, 4), 0.5)
    with pytest.warns(softgl.Float64Warning, match="texImage2D.*np.float32"):
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 2, 2, 0, gl.RGBA, gl.FLOAT, pixels)
    gl.getError()
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 2, 2, 0, gl.RGBA, gl.FLOAT, pixels.astype(np.float32))
    with pytest.warns(softgl.Float64Warning, match="texSubImage2D"):
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 2, 2, gl.RGBA, gl.FLOAT, pixels)
    with pytest.warns(softgl.Float64Warning, match="np.uint8 for UNSIGNED_BYTE"):
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 2, 2, 0, gl.RGBA, gl.UNSIGNED_BYTE, pixels)
    strict = softgl.Context(4, 4, strict=True)
    strict.bindBuffer(strict.ARRAY_BUFFER, strict.createBuffer())
    with pytest.raises(TypeError, match="np.float32"):
        strict.bufferData(strict.ARRAY_BUFFER, np.zeros(3), strict.STATIC_DRAW)


def test_float64_uniforms_are_converted_without_a_warning():
    gl = softgl.Context(4, 4, antialias=False)
    prog = programs.constant_color(gl)
    gl.useProgram(prog.handle)
    loc = prog.uniforms["uMaterialDiffuse"][0]
    assert recorded(lambda: gl.uniform4fv(loc, np.array([0.1, 0.2, 0.3, 0.4]))) == []
    np.testing.assert_allclose(gl.getUniform(prog.handle, loc), [0.1, 0.2, 0.3, 0.4], rtol=1e-7)


# -- 2. 2-D matrices are math layout, flat sequences column-major -----------------------------

def draw_with_model(set_model):
    gl = softgl.Context(32, 32, antialias=False)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-.5, -.5, .5, -.5, 0, .5], np.float32), gl.STATIC_DRAW)
    prog = triangle_program(gl)
    set_model(gl, prog.uniforms["uModel"][0])
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    return red_pixels(gl)


def test_uniform_matrix_takes_2d_arrays_in_math_layout():
    M = T.translate(0.4, 0, 0)
    as_matrix = draw_with_model(lambda gl, loc: gl.uniformMatrix4fv(loc, False, M))
    flat = draw_with_model(lambda gl, loc: gl.uniformMatrix4fv(loc, False, M.T.ravel()))
    listed = draw_with_model(lambda gl, loc: gl.uniformMatrix4fv(loc, False, M.T.ravel().tolist()))
    still = draw_with_model(lambda gl, loc: gl.uniformMatrix4fv(loc, False, T.identity()))
    np.testing.assert_array_equal(as_matrix, flat)
    np.testing.assert_array_equal(as_matrix, listed)
    # The translation moved the picture right by 0.4 NDC = 6.4 pixels, without skewing it.
    cols = np.nonzero(as_matrix.any(axis=0))[0]
    still_cols = np.nonzero(still.any(axis=0))[0]
    assert cols.min() - still_cols.min() in (6, 7) and as_matrix.sum() == still.sum()


def test_uniform_matrix_non_square_and_arrays_of_matrices():
    gl = softgl.Context(4, 4, version=2)
    fs = """#version 300 es
    precision mediump float; uniform mat2x3 uA; uniform mat4 uB[2]; out vec4 o;
    void main() { o = vec4(uA[1], 1.0) + uB[1][3]; }"""
    vs = "#version 300 es\nvoid main() { gl_Position = vec4(0.0); }"
    prog = programs.Program(gl, vs, fs)
    gl.useProgram(prog.handle)
    A = np.arange(6, dtype=np.float32).reshape(3, 2)       # 3 rows, 2 columns: mat2x3
    gl.uniformMatrix2x3fv(gl.getUniformLocation(prog.handle, "uA"), False, A)
    np.testing.assert_array_equal(gl.getUniform(prog.handle, gl.getUniformLocation(prog.handle, "uA")),
                                  A.T.ravel())
    B = np.stack([T.identity(), T.translate(1, 2, 3)])
    gl.uniformMatrix4fv(gl.getUniformLocation(prog.handle, "uB"), False, B)
    np.testing.assert_array_equal(gl.getUniform(prog.handle, gl.getUniformLocation(prog.handle, "uB[1]")),
                                  T.column_major(B[1]))


# -- 3. showing a canvas never clears it ------------------------------------------------------

def test_showing_a_canvas_does_not_clear_it_presenting_does():
    gl = softgl.Context(2, 2, antialias=False)          # preserveDrawingBuffer: false
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    first = gl._repr_png_()
    assert gl._repr_png_() == first                       # shown twice: the same picture
    assert display.canvas_image(gl)[0, 0].tolist() == [255, 0, 0]
    assert gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0].tolist() == [255, 0, 0, 255]
    display.present(gl)                                  # the end of a browser frame
    assert gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE)[0, 0].tolist() == [0, 0, 0, 0]


# -- 4. io.save writes the numbers it is given ------------------------------------------------

def decode_png(data: bytes) -> np.ndarray:
    """An independent reader: an 8-bit RGBA, non-interlaced PNG with filter 0 ... 4 rows."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        n, = struct.unpack(">I", data[pos:pos + 4])
        tag, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        if tag == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, color_type, _, _, interlace = header
    assert (depth, color_type, interlace) == (8, 6, 0)
    raw = zlib.decompress(idat)
    stride, rows, prev = 4 * w, [], np.zeros(4 * w, np.int64)
    for y in range(h):
        f, line = raw[y * (stride + 1)], np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int64)
        out = np.zeros(stride, np.int64)
        for i in range(stride):
            a = out[i - 4] if i >= 4 else 0
            b, c = prev[i], (prev[i - 4] if i >= 4 else 0)
            if f == 0:
                pred = 0
            elif f == 1:
                pred = a
            elif f == 2:
                pred = b
            elif f == 3:
                pred = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            out[i] = (line[i] + pred) & 255
        rows.append(out)
        prev = out
    return np.array(rows, np.uint8).reshape(h, w, 4)


def test_save_writes_straight_alpha_exactly(tmp_path):
    pixel = np.array([[[128, 0, 0, 128], [10, 200, 30, 1]]], np.uint8)
    path = io.save(pixel, tmp_path / "p.png")
    assert decode_png(path.read_bytes()).tolist() == pixel.tolist()
    assert io.load_image(path).tolist() == pixel.tolist()     # not re-multiplied


@pytest.mark.parametrize("premultiplied", [False, True])
def test_a_canvas_saves_as_it_displays(tmp_path, premultiplied):
    gl = softgl.Context(1, 1, antialias=False, premultipliedAlpha=premultiplied)
    gl.clearColor(128 / 255, 0, 0, 128 / 255)
    gl.clear(gl.COLOR_BUFFER_BIT)
    stored = decode_png(io.save(gl, tmp_path / "c.png").read_bytes())
    if not premultiplied:
        assert stored.tolist() == [[[128, 0, 0, 128]]]         # the drawing buffer's bytes
    # A viewer composites the straight-alpha file over its page as Jupyter shows the canvas.
    viewed = display.composite(stored, premultiplied=False).astype(int)
    assert np.abs(viewed - display.canvas_image(gl)).max() <= (0 if not premultiplied else 1)


# -- 5. gl.canvas.width/height resize the drawing buffer --------------------------------------

def test_setting_the_canvas_size_resizes_the_drawing_buffer():
    gl = softgl.Context(20, 10, antialias=False)
    gl.clearColor(1, 0, 0, 1)
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert gl.canvas is gl.canvas and (gl.canvas.width, gl.canvas.height) == (20, 10)
    gl.canvas.width = 30
    assert (gl.drawingBufferWidth, gl.drawingBufferHeight) == (30, 10)
    img = gl.readPixels(0, 0, 30, 10, gl.RGBA, gl.UNSIGNED_BYTE)
    assert img.shape == (10, 30, 4) and not img.any()          # a new buffer, cleared
    assert gl.getParameter(gl.VIEWPORT).tolist() == [0, 0, 20, 10]   # the viewport is kept
    gl.canvas.height = 40
    assert (gl.canvas.width, gl.canvas.height) == (30, 40) and gl.drawingBufferHeight == 40
    gl.clear(gl.COLOR_BUFFER_BIT)
    assert (gl.readPixels(0, 0, 30, 40, gl.RGBA, gl.UNSIGNED_BYTE)[..., 0] == 255).all()
    with pytest.raises(ValueError, match="canvas size"):
        gl.canvas.width = -1
    assert gl.drawingBufferWidth == 30


# -- 7. line widths follow what Chromium reports ------------------------------------------------

def _chromium_line_width_range():
    import json
    from pathlib import Path
    ref = json.loads((Path(__file__).parents[1] / "webgl" / "reference" / "initial_parameters.json").read_text())
    return {v: ref[f"v{v}"]["params"]["ALIASED_LINE_WIDTH_RANGE"]["v"] for v in (1, 2)}


def _line_pixels(gl, width):
    prog = triangle_program(gl)
    prog.set(uModel=np.eye(4))
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-0.8, -0.3, 0.8, 0.4], np.float32), gl.STATIC_DRAW)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.lineWidth(width)
    gl.drawArrays(gl.LINES, 0, 2)
    return red_pixels(gl)


@pytest.mark.parametrize("version", [1, 2])
def test_aliased_line_width_range_and_drawing_follow_chromium(version):
    gl = softgl.Context(64, 64, version=version, antialias=False, preserveDrawingBuffer=True)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    assert list(gl.getParameter(gl.ALIASED_LINE_WIDTH_RANGE)) == _chromium_line_width_range()[version] == [1, 1]
    thin = _line_pixels(gl, 1)
    wide = _line_pixels(gl, 6)
    assert gl.getParameter(gl.LINE_WIDTH) == 6                    # kept as set (WebGL)
    # x-major from x = 6.4 to 57.6: the 51 pixel centres in between, one per column (hand count)
    assert thin.sum() == 51 and np.array_equal(wide, thin)        # drawn 1 px wide, as Chromium does


def test_smooth_lines_keep_their_own_wide_range():
    gl = softgl.Context(64, 64, antialias=False, preserveDrawingBuffer=True)
    ext = gl.getExtension("SOFTGL_smooth")
    assert list(gl.getParameter(ext.SMOOTH_LINE_WIDTH_RANGE)) == [1, 256]
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.enable(ext.LINE_SMOOTH)
    thin, wide = _line_pixels(gl, 1), _line_pixels(gl, 6)
    assert wide.sum() > 2.5 * thin.sum()    # a 6-px band touches ~3x the pixels of a 1-px one


# -- 8. image comparisons write files only where asked -----------------------------------------

def test_assert_images_close_writes_nothing_unless_asked(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    a = np.zeros((2, 2, 4), np.uint8)
    with pytest.raises(AssertionError, match="no images written"):
        softgl.testing.assert_images_close(a, a + 9)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(AssertionError, match="images written to"):
        softgl.testing.assert_images_close(a, a + 9, out_dir=tmp_path / "here", name="x")
    assert (tmp_path / "here" / "x" / "diff.png").exists()


# -- the helpers follow the lessons ------------------------------------------------------------

def test_spot_direction_is_not_normalised_as_in_the_lesson():
    def render(direction):
        gl = softgl.Context(24, 24, antialias=False)
        prog = programs.lights(gl, 1).set(
            uLightPositions=[(0, 0, 1)], uLightDirections=[direction],
            uLightColors=[(1, 1, 1, 1)], uLightCutoffs=[0.2], uMaterialDiffuse=(1, 1, 1, 1))
        from layer_util import draw_triangles, fullscreen
        draw_triangles(gl, prog, fullscreen(), normals=np.tile((0, 0, 1), (6, 1)))
        return gl.readPixels(0, 0, 24, 24, gl.RGBA, gl.UNSIGNED_BYTE)
    # The lesson bends the normal by D as given: its length matters.
    assert not np.array_equal(render((0.3, 0, -0.5)), render((0.6, 0, -1.0)))


def test_points_lesson_column_4_keeps_the_canvas_opaque():
    label, depth, blend, kind, alpha_write, _ = experiments.POINTS_COLUMNS[3]
    assert (depth, blend, kind, alpha_write) == (True, True, "separate", True)
    gl = experiments.points_lesson(854, 480, show=False)
    img = gl.readPixels(0, 0, 854, 480, gl.RGBA, gl.UNSIGNED_BYTE)
    # A translucent red point of column 4 (bottom row, alpha 0.25) over the black canvas.
    assert img[100 + 20, 360 - 20].tolist() == [64, 0, 0, 255]
