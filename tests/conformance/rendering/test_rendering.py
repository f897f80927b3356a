"""conformance/rendering: drawElements/drawArrays equivalence, LINE_LOOP / TRIANGLE_FAN through
indices, more than 65536 vertices/indices/points, the 0xFFFF index (WebGL 1: a vertex;
WebGL 2: primitive restart, WebGL 2.0 §5.18), point sizes from varyings, many draw calls,
scissor changes between draws. Expected images are derived from the geometry by hand or from an
equivalent drawArrays call (their tests compare the same way)."""
import numpy as np
import pytest

from conformance.helpers import (GREEN, QUAD, array_buffer, attribute, context, error, errors,
                                 pixel, program, read)

INDEX_TYPES = {"UNSIGNED_BYTE": np.uint8, "UNSIGNED_SHORT": np.uint16, "UNSIGNED_INT": np.uint32}


def _uint_ok(gl, version):
    return version == 2 or gl.getExtension("OES_element_index_uint") is not None


@pytest.mark.parametrize("itype", list(INDEX_TYPES))
@pytest.mark.parametrize("mode", ["POINTS", "LINES", "LINE_STRIP", "LINE_LOOP", "TRIANGLES",
                                  "TRIANGLE_STRIP", "TRIANGLE_FAN"])
def test_draw_elements_equals_draw_arrays_of_the_gathered_vertices(version, itype, mode):
    # gl-drawelements, line-loop-tri-fan: drawElements(mode, idx) draws exactly what drawArrays
    # draws on the vertices gathered by idx, for every mode and index type.
    rng = np.random.default_rng(hash((mode, itype)) % 2**32)
    verts = rng.uniform(-0.9, 0.9, (10, 2)).astype(np.float32)
    idx = np.array([3, 7, 1, 0, 9, 4, 2, 8, 5, 6, 3], INDEX_TYPES[itype])
    images = []
    for indexed in (True, False):
        gl = context(24, 24, version=version)
        if itype == "UNSIGNED_INT":
            assert _uint_ok(gl, version)
        program(gl)
        if indexed:
            attribute(gl, 0, verts, 2)
            array_buffer(gl, idx, gl.ELEMENT_ARRAY_BUFFER)
            gl.drawElements(getattr(gl, mode), len(idx), getattr(gl, itype), 0)
        else:
            attribute(gl, 0, verts[idx.astype(int)], 2)
            gl.drawArrays(getattr(gl, mode), 0, len(idx))
        assert error(gl) == gl.NO_ERROR
        images.append(read(gl))
    assert images[0].any()
    np.testing.assert_array_equal(images[0], images[1])


def test_unsigned_int_indices_need_the_extension_in_webgl1():
    # extensions/oes-element-index-uint (negative part)
    gl = context(version=1)
    program(gl)
    attribute(gl, 0, QUAD, 2)
    array_buffer(gl, np.arange(6, dtype=np.uint32), gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_INT, 0)
    assert error(gl) == gl.INVALID_ENUM
    gl.getExtension("OES_element_index_uint")
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_INT, 0)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == GREEN
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_INT, 2)                # offset % 4 != 0
    assert error(gl) == gl.INVALID_OPERATION


def test_line_loop_closes_and_fan_pivots_on_the_first_vertex(version):
    # line-loop-tri-fan: LINE_LOOP == LINE_STRIP + the first vertex again; TRIANGLE_FAN ==
    # TRIANGLES (0, i, i+1).
    verts = np.float32([[-0.8, -0.8], [0.8, -0.7], [0.7, 0.8], [-0.6, 0.6], [-0.9, 0.0]])
    n = len(verts)

    def render(mode, v):
        gl = context(32, 32, version=version)
        program(gl)
        attribute(gl, 0, v, 2)
        gl.drawArrays(getattr(gl, mode), 0, len(v))
        return read(gl)

    np.testing.assert_array_equal(render("LINE_LOOP", verts),
                                  render("LINE_STRIP", np.vstack([verts, verts[:1]])))
    tris = np.vstack([[verts[0], verts[i], verts[i + 1]] for i in range(1, n - 1)])
    np.testing.assert_array_equal(render("TRIANGLE_FAN", verts), render("TRIANGLES", tris))


def test_more_than_65536_vertices_with_draw_arrays(version):
    # more-than-65536-points / more-than-65536-indices (drawArrays part): the only visible
    # primitive is after vertex 65536.
    gl = context(version=version)
    program(gl)
    n = 65536 + 6
    verts = np.full((n, 2), 2.0, np.float32)                         # off screen
    verts[-6:] = QUAD.reshape(6, 2)
    attribute(gl, 0, verts, 2)
    gl.drawArrays(gl.TRIANGLES, 0, n)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == GREEN


def test_more_than_65536_points(version):
    # more-than-65536-points: 65540 points, one per pixel of a 256x256 canvas plus 4 repeats.
    gl = context(256, 256, version=version)
    program(gl)
    ys, xs = np.mgrid[0:256, 0:256]
    centres = np.stack([(xs.ravel() + 0.5) / 128 - 1, (ys.ravel() + 0.5) / 128 - 1], 1)
    verts = np.vstack([centres, centres[:4]]).astype(np.float32)
    attribute(gl, 0, verts, 2)
    gl.drawArrays(gl.POINTS, 0, len(verts))
    img = read(gl)
    assert error(gl) == gl.NO_ERROR and (img == GREEN).all()


def test_more_than_65536_indices(version):
    # more-than-65536-indices: UNSIGNED_INT indices that reach vertex 70000, and an index count
    # above 65536 with UNSIGNED_SHORT.
    gl = context(version=version)
    gl.getExtension("OES_element_index_uint")
    program(gl)
    verts = np.full((70006, 2), 3.0, np.float32)
    verts[70000:] = QUAD.reshape(6, 2)
    attribute(gl, 0, verts, 2)
    array_buffer(gl, np.arange(70000, 70006, dtype=np.uint32), gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, 6, gl.UNSIGNED_INT, 0)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == GREEN
    gl.clear(gl.COLOR_BUFFER_BIT)
    idx = np.zeros(65538 + 6, np.uint16)                               # degenerate ...
    idx[-6:] = [0, 1, 2, 3, 4, 5]                                      # ... then the quad
    attribute(gl, 0, QUAD, 2)
    array_buffer(gl, idx, gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, len(idx), gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == GREEN


RESTART_BUG = ("softgl treats the maximum index (0xFF / 0xFFFF / 0xFFFFFFFF) as an ordinary vertex "
               "in WebGL 2; WebGL 2.0 §5.18 makes PRIMITIVE_RESTART_FIXED_INDEX always enabled "
               "(ES 3.0 §2.8.1): the index must end the primitive and is not range-checked")


@pytest.mark.parametrize("version", [1, pytest.param(2)],
                         ids=["webgl1", "webgl2"])
def test_index_0xffff(version):
    # negative-one-index: in WebGL 1 index 0xFFFF is an ordinary vertex (triangle drawn); WebGL 2
    # always has primitive restart on for the maximum index (WebGL 2.0 §5.18), so the triangle
    # is cut and nothing is drawn.
    gl = context(50, 50, version=version)
    program(gl)
    verts = np.zeros((65536, 3), np.float32)
    verts[0], verts[1], verts[65535] = [0, 0.5, 0], [-0.5, -0.5, 0], [0.5, -0.5, 0]
    attribute(gl, 0, verts, 3)
    array_buffer(gl, np.uint16([0, 1, 0xFFFF]), gl.ELEMENT_ARRAY_BUFFER)
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_SHORT, 0)
    assert error(gl) == gl.NO_ERROR
    img = read(gl)
    assert not img[0].any() and not img[49].any()
    if version == 1:
        assert (img[15, 20:30] == GREEN).all()
    else:
        assert not img.any()


def test_primitive_restart_in_strips_webgl2():
    # es3fPrimitiveRestartTests (WebGL 2 subset): the maximum index of each type ends a strip and
    # starts a new one; the restart index itself is never range-checked as a vertex.
    for itype, dtype, restart in (("UNSIGNED_BYTE", np.uint8, 0xFF),
                                  ("UNSIGNED_SHORT", np.uint16, 0xFFFF),
                                  ("UNSIGNED_INT", np.uint32, 0xFFFFFFFF)):
        gl = context(32, 32, version=2)
        program(gl)
        # two separate quads as strips: left half and right half, with a gap between
        v = np.float32([[-1, -1], [-0.2, -1], [-1, 1], [-0.2, 1],
                        [0.2, -1], [1, -1], [0.2, 1], [1, 1]])
        attribute(gl, 0, v, 2)
        array_buffer(gl, np.array([0, 1, 2, 3, restart, 4, 5, 6, 7], dtype),
                     gl.ELEMENT_ARRAY_BUFFER)
        gl.drawElements(gl.TRIANGLE_STRIP, 9, getattr(gl, itype), 0)
        assert error(gl) == gl.NO_ERROR, itype
        img = read(gl)
        assert (img[16, 2] == GREEN).all() and (img[16, 29] == GREEN).all(), itype
        assert not img[16, 15:17].any(), itype                           # no bridging triangle


def test_point_size_from_varying_attribute(version):
    # point-size-varyings: gl_PointSize taken per vertex from an attribute; a point of size s
    # centred on a pixel centre covers s x s pixels (odd s).
    gl = context(40, 10, version=version)
    vs = """attribute vec2 aPos; attribute float aSize;
    void main() { gl_Position = vec4(aPos, 0.0, 1.0); gl_PointSize = aSize; }"""
    program(gl, vs, "void main() { gl_FragColor = vec4(0.0, 1.0, 0.0, 1.0); }",
            {"aPos": 0, "aSize": 1})
    centres_px = [(4.5, 4.5), (14.5, 4.5), (24.5, 4.5), (34.5, 4.5)]
    sizes = [1, 3, 5, 7]
    pos = np.float32([[x / 20 - 1, y / 5 - 1] for x, y in centres_px])
    attribute(gl, 0, pos, 2)
    attribute(gl, 1, np.float32(sizes), 1)
    gl.drawArrays(gl.POINTS, 0, 4)
    lit = read(gl)[..., 1] == 255
    expected = np.zeros((10, 40), bool)
    for (x, y), s in zip(centres_px, sizes):
        h = s // 2
        expected[int(y) - h:int(y) + h + 1, int(x) - h:int(x) + h + 1] = True
    np.testing.assert_array_equal(lit, expected)


def test_aliased_point_size_range_includes_one(version):
    # point-size: ALIASED_POINT_SIZE_RANGE[0] <= 1 <= [1]; a size-1 point lights one pixel.
    gl = context(version=version)
    lo, hi = gl.getParameter(gl.ALIASED_POINT_SIZE_RANGE)
    assert lo <= 1 <= hi
    program(gl)
    attribute(gl, 0, np.float32([0.5 / 8 * 1 + 0.0625 * 0, 0.0625]), 2)   # centre of pixel (8, 8)
    gl.drawArrays(gl.POINTS, 0, 1)
    assert (read(gl)[..., 1] == 255).sum() == 1 and pixel(gl, 8, 8) == GREEN


def test_many_draw_calls(version):
    # many-draw-calls: thousands of small draws, each adding 1/255 to one pixel row's colour.
    gl = context(8, 8, version=version)
    program(gl, fs="precision mediump float; uniform vec4 uC; void main() { gl_FragColor = uC; }")
    attribute(gl, 0, QUAD, 2)
    gl.enable(gl.BLEND)
    gl.blendFunc(gl.ONE, gl.ONE)
    loc = gl.getUniformLocation(gl.getParameter(gl.CURRENT_PROGRAM), "uC")
    gl.uniform4f(loc, 1 / 255, 0, 0, 0)
    for _ in range(200):
        gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.NO_ERROR and (read(gl)[..., 0] == 200).all()


def test_scissor_rect_changes_between_draws(version):
    # scissor-rect-repeated-rendering: each draw uses the scissor box current at its call.
    gl = context(16, 16, version=version)
    prog = program(gl, fs="precision mediump float; uniform vec4 uC; void main() { gl_FragColor = uC; }")
    loc = gl.getUniformLocation(prog, "uC")
    attribute(gl, 0, QUAD, 2)
    gl.enable(gl.SCISSOR_TEST)
    for i in range(4):
        gl.scissor(i * 4, 0, 4, 16)
        gl.uniform4f(loc, (i + 1) * 50 / 255, 0, 0, 1)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
    img = read(gl)
    for i in range(4):
        assert (img[:, i * 4:(i + 1) * 4, 0] == (i + 1) * 50).all()
