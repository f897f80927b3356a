"""conformance/attribs: attribute locations, disabled/constant attributes, vertexAttribPointer
validation and offsets. Expected values come from the WebGL 1.0 spec (§6.x) and ES 2.0/3.0 §2.7-2.8,
never from softgl's own output."""
import numpy as np
import pytest

from conformance.helpers import (GREEN, QUAD, attribute, context, error, errors, pixel,
                                 program, read, try_link)

VS2 = """attribute vec4 aPos; attribute vec4 aOther;
varying vec4 v; void main() { gl_Position = aPos; v = aOther; }"""
FS_V = "precision mediump float; varying vec4 v; void main() { gl_FragColor = v; }"


@pytest.mark.parametrize("second", ["float", "vec2", "vec3", "vec4", "mat2"])
def test_bind_attrib_location_aliasing_fails_link(version, second):
    # gl-bindAttribLocation-aliasing: two *active* attributes bound to one location must not link
    # (WebGL 1.0 §6.? "Attribute aliasing"; GLSL ES 3.00 §12.46 forbids it outright).
    gl = context(version=version)
    vs = f"""attribute vec4 aPos; attribute {second} aB;
    void main() {{ gl_Position = aPos + vec4(aB{'[0][0]' if second == 'mat2' else ('' if second == 'float' else '.x')}); }}"""
    assert try_link(gl, vs, "void main() { gl_FragColor = vec4(1.0); }",
                    {"aPos": 3, "aB": 3})[2] is False
    assert try_link(gl, vs, "void main() { gl_FragColor = vec4(1.0); }",
                    {"aPos": 3, "aB": 4})[2] is True


@pytest.mark.parametrize("mat,cols", [("mat2", 2), ("mat3", 3), ("mat4", 4)])
def test_bind_attrib_location_matrix(version, mat, cols):
    # gl-bindAttribLocation-matrix: a matN attribute takes N consecutive locations; binding
    # another attribute to any of them fails the link, right after them succeeds; a matrix that
    # would run past MAX_VERTEX_ATTRIBS fails.
    gl = context(version=version)
    vs = f"""attribute {mat} aM; attribute vec4 aPos;
    void main() {{ gl_Position = aPos + vec4(aM[0][0]); }}"""
    fs = "void main() { gl_FragColor = vec4(1.0); }"
    for k in range(cols):
        assert try_link(gl, vs, fs, {"aM": 2, "aPos": 2 + k})[2] is False, k
    assert try_link(gl, vs, fs, {"aM": 2, "aPos": 2 + cols})[2] is True
    n = gl.getParameter(gl.MAX_VERTEX_ATTRIBS)
    assert try_link(gl, vs, fs, {"aM": n - cols, "aPos": 0})[2] is True
    assert try_link(gl, vs, fs, {"aM": n - cols + 1, "aPos": 0})[2] is False


def test_disabled_attributes_read_the_current_value_default_0001(version):
    # gl-disabled-vertex-attrib: every disabled attribute reads (0, 0, 0, 1) until set.
    gl = context(version=version)
    n = gl.getParameter(gl.MAX_VERTEX_ATTRIBS)
    fs = "void main() { gl_FragColor = vec4(0.0, 1.0, 0.0, 1.0); }"
    for loc in range(1, n):
        vs = """attribute vec4 aPos; attribute vec4 aT; varying vec4 v;
        void main() { gl_Position = aPos; v = aT; }"""
        fs = """precision mediump float; varying vec4 v;
        void main() { gl_FragColor = v == vec4(0.0, 0.0, 0.0, 1.0) ? vec4(0, 1, 0, 1) : vec4(1, 0, 0, 1); }"""
        program(gl, vs, fs, {"aPos": 0, "aT": loc})
        gl.clear(gl.COLOR_BUFFER_BIT)
        attribute(gl, 0, QUAD, 2)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        assert pixel(gl, 8, 8) == GREEN, loc
    assert error(gl) == gl.NO_ERROR


def test_disabled_attribute_update_between_draws(version):
    # gl-disabled-vertex-attrib-update: a vertexAttrib4f between two draws is seen by the second;
    # disabling an array attribute falls back to the current value, enabling it again to the array.
    gl = context(version=version)
    program(gl, VS2, FS_V, {"aPos": 0, "aOther": 1})
    attribute(gl, 0, QUAD, 2)
    gl.vertexAttrib4f(1, 1, 0, 0, 1)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 3, 3) == (255, 0, 0, 255)
    gl.vertexAttrib4f(1, 0, 0, 1, 1)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 3, 3) == (0, 0, 255, 255)
    attribute(gl, 1, np.tile(np.float32([0, 1, 0, 1]), 6), 4)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 3, 3) == GREEN
    gl.disableVertexAttribArray(1)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 3, 3) == (0, 0, 255, 255)       # the current value survived the array
    assert error(gl) == gl.NO_ERROR


MATRIX_ATTRIB_BUG = ("softgl reads every column of a matrix attribute from the first location's "
                     "vec4 (mat2 column 1 = components z, w of location L) instead of column c "
                     "from location L + c (ES 2.0 §2.7 / GLSL ES 1.00 §4.3.3)")


def test_matrix_attribute_minimal_repro():
    gl = context(version=2)
    vs = """attribute vec4 aPos; attribute mat2 aM; varying vec4 v;
    void main() { gl_Position = aPos; v = vec4(aM[1][0], aM[1][1], aM[0][1], 1.0); }"""
    program(gl, vs, FS_V, {"aPos": 0, "aM": 3})
    gl.vertexAttrib4f(3, 0.2, 0.3, 0.0, 0.0)       # column 0
    gl.vertexAttrib4f(4, 0.6, 0.4, 0.0, 0.0)       # column 1
    attribute(gl, 0, QUAD, 2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 5, 5) == (153, 102, 77, 255)  # softgl: (0, 0, 77, 255)


@pytest.mark.parametrize("mat,cols", [("mat2", 2), ("mat3", 3), ("mat4", 4)])
def test_matrix_attributes_take_columns_from_consecutive_locations(version, mat, cols):
    # gl-matrix-attributes: getAttribLocation gives the first column's location, column c reads
    # location + c; the active attribute reports the matrix type with size 1.
    gl = context(version=version)
    vs = f"""attribute vec4 aPos; attribute {mat} aM; varying vec4 v;
    void main() {{ gl_Position = aPos; v = vec4(0.0);
      for (int c = 0; c < {cols}; ++c) v[c] = aM[c][c]; v.a = 1.0; }}"""
    prog = program(gl, vs, FS_V, {"aPos": 0, "aM": 3})
    assert gl.getAttribLocation(prog, "aM") == 3
    names = {gl.getActiveAttrib(prog, i).name: gl.getActiveAttrib(prog, i)
             for i in range(gl.getProgramParameter(prog, gl.ACTIVE_ATTRIBUTES))}
    assert names["aM"].size == 1 and names["aM"].type == getattr(gl, f"FLOAT_{mat.upper()}")
    vals = [0.2, 0.4, 0.6, 0.8]
    for c in range(cols):
        col = [0.0] * 4
        col[c] = vals[c]
        gl.vertexAttrib4fv(3 + c, col)
    attribute(gl, 0, QUAD, 2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    got = pixel(gl, 5, 5)
    want = [round(vals[c] * 255) if c < cols else 0 for c in range(3)] + [255]
    assert got == tuple(want)


def test_vertex_attrib_setters_and_current_value(version):
    # gl-vertex-attrib: vertexAttrib{1,2,3,4}f[v] fill missing components with 0, 0, 1;
    # getVertexAttrib(CURRENT_VERTEX_ATTRIB) returns a Float32Array; index >= MAX is INVALID_VALUE.
    gl = context(version=version)
    n = gl.getParameter(gl.MAX_VERTEX_ATTRIBS)
    for i in (0, n - 1):
        gl.vertexAttrib1f(i, 5)
        assert list(gl.getVertexAttrib(i, gl.CURRENT_VERTEX_ATTRIB)) == [5, 0, 0, 1]
        gl.vertexAttrib2f(i, 6, 7)
        assert list(gl.getVertexAttrib(i, gl.CURRENT_VERTEX_ATTRIB)) == [6, 7, 0, 1]
        gl.vertexAttrib3f(i, -1, -2, -3)
        assert list(gl.getVertexAttrib(i, gl.CURRENT_VERTEX_ATTRIB)) == [-1, -2, -3, 1]
        gl.vertexAttrib4f(i, 1, 2, 3, 4)
        assert list(gl.getVertexAttrib(i, gl.CURRENT_VERTEX_ATTRIB)) == [1, 2, 3, 4]
        gl.vertexAttrib1fv(i, [9])
        assert list(gl.getVertexAttrib(i, gl.CURRENT_VERTEX_ATTRIB)) == [9, 0, 0, 1]
        gl.vertexAttrib2fv(i, np.float32([1, 2]))
        gl.vertexAttrib3fv(i, [1, 2, 3])
        gl.vertexAttrib4fv(i, [4, 3, 2, 1])
        v = gl.getVertexAttrib(i, gl.CURRENT_VERTEX_ATTRIB)
        assert v.dtype == np.float32 and list(v) == [4, 3, 2, 1]
    assert error(gl) == gl.NO_ERROR
    for call, args in ((gl.vertexAttrib1f, (n, 1)), (gl.vertexAttrib4fv, (n, [1, 2, 3, 4])),
                       (gl.getVertexAttrib, (n, gl.CURRENT_VERTEX_ATTRIB)),
                       (gl.enableVertexAttribArray, (n,)), (gl.disableVertexAttribArray, (n,))):
        call(*args)
        assert error(gl) == gl.INVALID_VALUE, call
    # too short arrays: INVALID_VALUE (WebGL 1.0 §5.14.10)
    gl.vertexAttrib4fv(0, [1, 2, 3])
    assert error(gl) == gl.INVALID_VALUE
    gl.vertexAttrib2fv(0, [1])
    assert error(gl) == gl.INVALID_VALUE


def test_vertex_attrib_integer_current_values_webgl2():
    # gl-vertex-attrib (WebGL 2 part): vertexAttribI4i/ui store integers; the query returns
    # Int32Array / Uint32Array.
    gl = context(version=2)
    gl.vertexAttribI4i(2, -1, 2, -3, 4)
    v = gl.getVertexAttrib(2, gl.CURRENT_VERTEX_ATTRIB)
    assert v.dtype == np.int32 and list(v) == [-1, 2, -3, 4]
    gl.vertexAttribI4ui(2, 1, 2, 3, 0xFFFFFFFF)
    v = gl.getVertexAttrib(2, gl.CURRENT_VERTEX_ATTRIB)
    assert v.dtype == np.uint32 and list(v) == [1, 2, 3, 0xFFFFFFFF]
    assert error(gl) == gl.NO_ERROR


def test_vertex_attrib_render_every_location(version):
    # gl-vertex-attrib-render: a constant attribute at every location reaches the shader.
    gl = context(version=version)
    n = gl.getParameter(gl.MAX_VERTEX_ATTRIBS)
    for loc in range(1, n):
        program(gl, VS2, FS_V, {"aPos": 0, "aOther": loc})
        gl.vertexAttrib4f(loc, loc / 255, 0.5, 1 - loc / 255, 1)
        attribute(gl, 0, QUAD, 2)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        assert pixel(gl, 2, 2) == (loc, 128, 255 - loc, 255), loc


def test_attribute_zero_may_be_disabled(version):
    # gl-vertex-attrib-zero-issues: WebGL must draw when location 0 is a disabled (constant)
    # attribute, even for large counts, and with location 0 not used at all.
    gl = context(version=version)
    program(gl, VS2, FS_V, {"aOther": 0, "aPos": 1})
    gl.vertexAttrib4f(0, 0, 1, 0, 1)
    attribute(gl, 1, QUAD, 2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 8, 8) == GREEN
    n = 70000
    big = np.resize(QUAD, n * 2).astype(np.float32)
    attribute(gl, 1, big, 2)
    gl.vertexAttrib4f(0, 0, 0, 1, 1)
    gl.drawArrays(gl.TRIANGLES, 0, n - n % 3)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == (0, 0, 255, 255)


def test_unconsumed_attribute_zero_out_of_bounds_is_not_checked(version):
    # gl-vertex-attrib-zero-unconsumed-out-of-bounds: an enabled array at a location the program
    # does not use is not range-checked.
    gl = context(version=version)
    program(gl, locations={"aPos": 1})
    attribute(gl, 0, np.zeros(2, np.float32), 2)       # one vertex only, but unused
    attribute(gl, 1, QUAD, 2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8) == GREEN


TYPES = [("BYTE", 1), ("UNSIGNED_BYTE", 1), ("SHORT", 2), ("UNSIGNED_SHORT", 2), ("FLOAT", 4)]


def test_vertex_attrib_pointer_validation(version):
    # gl-vertexattribpointer: no ARRAY_BUFFER bound with offset != 0 -> INVALID_OPERATION;
    # INT/UNSIGNED_INT only in WebGL 2, FIXED never; offset and stride must be multiples of the
    # component size (INVALID_OPERATION); stride <= 255 (INVALID_VALUE).
    gl = context(version=version)
    gl.vertexAttribPointer(0, 3, gl.FLOAT, False, 0, 12)
    assert error(gl) == gl.INVALID_OPERATION
    gl.vertexAttribPointer(0, 3, gl.FLOAT, False, 0, 0)     # null buffer at offset 0 is legal
    assert error(gl) == gl.NO_ERROR
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, np.zeros(0, np.float32), gl.STATIC_DRAW)
    for t in (gl.INT, gl.UNSIGNED_INT):
        gl.vertexAttribPointer(0, 1, t, False, 0, 0)
        assert error(gl) == (gl.INVALID_ENUM if version == 1 else gl.NO_ERROR)
    gl.vertexAttribPointer(0, 1, 0x140C, False, 0, 0)        # GL_FIXED
    assert error(gl) == gl.INVALID_ENUM
    for name, nbytes in TYPES:
        t = getattr(gl, name)
        for size in range(1, 5):
            choices = sorted({0, 1, nbytes - 1, nbytes, nbytes + 1, 2 * nbytes})
            for offset in choices:
                for stride in choices:
                    gl.vertexAttribPointer(0, size, t, False, stride, offset)
                    bad = offset % nbytes or stride % nbytes
                    assert error(gl) == (gl.INVALID_OPERATION if bad else gl.NO_ERROR), \
                        (name, size, offset, stride)
                if offset == 0:
                    limit = 255 // nbytes * nbytes
                    gl.vertexAttribPointer(0, size, t, False, limit, 0)
                    assert error(gl) == gl.NO_ERROR
                    gl.vertexAttribPointer(0, size, t, False, limit + nbytes, 0)
                    assert error(gl) == gl.INVALID_VALUE
    for size in (0, 5):
        gl.vertexAttribPointer(0, size, gl.FLOAT, False, 0, 0)
        assert error(gl) == gl.INVALID_VALUE
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, -4, 0)
    assert error(gl) == gl.INVALID_VALUE
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, -4)
    assert error(gl) == gl.INVALID_VALUE


@pytest.mark.parametrize("name,nbytes", TYPES)
@pytest.mark.parametrize("normalized", [False, True])
def test_vertex_attrib_pointer_offsets(version, name, nbytes, normalized):
    # gl-vertexattribpointer-offsets: the same triangle stored at several byte offsets in a
    # buffer of each type draws the same pixels; normalized integers map by ES 3.0 §2.8 (c/(2^b-1)
    # for unsigned, max(c/(2^(b-1)-1), -1) for signed).
    gl = context(32, 32, version=version)
    vs = """attribute vec4 aPos; uniform float uScale;
    void main() { gl_Position = vec4(aPos.xy * uScale, 0.0, 1.0); }"""
    prog = program(gl, vs, "void main() { gl_FragColor = vec4(0.0, 1.0, 0.0, 1.0); }",
                   {"aPos": 0})
    dtype = {"BYTE": np.int8, "UNSIGNED_BYTE": np.uint8, "SHORT": np.int16,
             "UNSIGNED_SHORT": np.uint16, "FLOAT": np.float32}[name]
    if name.startswith("UNSIGNED"):
        tri = np.array([0, 0, 1, 0, 0, 1], np.float64)        # first quadrant
    else:
        tri = np.array([-1, -1, 1, -1, -1, 1], np.float64)
    if normalized and name != "FLOAT":
        maxv = np.iinfo(dtype).max
        data = (tri * maxv).astype(dtype)
        scale = 1.0
    else:
        data = (tri * 100).astype(dtype)
        scale = 0.01
    gl.uniform1f(gl.getUniformLocation(prog, "uScale"), scale)
    for offset in (0, 8, 16, 24, 32):
        raw = np.zeros(offset + data.nbytes, np.uint8)
        raw[offset:] = data.view(np.uint8)
        gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
        gl.bufferData(gl.ARRAY_BUFFER, raw, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(0)
        gl.vertexAttribPointer(0, 2, getattr(gl, name), normalized, 0, offset)
        gl.clearColor(0, 0, 0, 0)
        gl.clear(gl.COLOR_BUFFER_BIT)
        gl.drawArrays(gl.TRIANGLES, 0, 3)
        img = read(gl)
        if name.startswith("UNSIGNED"):
            assert tuple(img[18, 18]) == GREEN and tuple(img[30, 30]) == (0, 0, 0, 0)
            assert tuple(img[10, 10]) == (0, 0, 0, 0)
        else:
            assert tuple(img[4, 4]) == GREEN and tuple(img[28, 28]) == (0, 0, 0, 0)
        assert error(gl) == gl.NO_ERROR, offset


def test_shared_buffer_interleaved_layouts(version):
    # gl-vertexattribpointer-shared-layouts: two attributes interleaved in one buffer with a
    # common stride, then the same buffer re-described with another layout.
    gl = context(version=version)
    program(gl, VS2, FS_V, {"aPos": 0, "aOther": 1})
    inter = np.zeros((6, 6), np.float32)
    inter[:, :2] = QUAD.reshape(6, 2)
    inter[:, 2:] = [0, 0, 1, 1]
    buf = attribute(gl, 0, inter, 2, stride=24, offset=0)
    gl.enableVertexAttribArray(1)
    gl.vertexAttribPointer(1, 4, gl.FLOAT, False, 24, 8)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 8, 8) == (0, 0, 255, 255)
    # non-interleaved: all positions, then all colors, in the same buffer
    planar = np.concatenate([QUAD, np.tile(np.float32([1, 0, 0, 1]), 6)])
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, planar, gl.STATIC_DRAW)
    gl.vertexAttribPointer(0, 2, gl.FLOAT, False, 0, 0)
    gl.vertexAttribPointer(1, 4, gl.FLOAT, False, 0, QUAD.nbytes)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 8, 8) == (255, 0, 0, 255)
    assert errors(gl) == []
