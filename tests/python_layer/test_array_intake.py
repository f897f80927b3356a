"""Array intake (docs/reliability.md, "Array intake"; cpp/bindings/array_intake.h): every method
that reads or writes client memory takes big-endian, strided, Fortran-order and misaligned arrays
by their values (the same result as the native C-order array), writes destinations of any layout
correctly, and refuses what WebGL's IDL would refuse (object arrays, non-numbers, read-only
destinations, lists where a typed array is required) with a TypeError naming the method and the
parameter, leaving every state and pixel as it was (issues 19 and 20)."""
import array
import subprocess
import sys
import warnings

import numpy as np
import pytest

import softgl

VS = """#version 300 es
uniform vec4 u_f; uniform ivec4 u_i; uniform uvec4 u_u; uniform mat4 u_m;
in vec4 a_pos; out vec4 v;
void main() { v = u_f + vec4(u_i) + vec4(u_u); gl_Position = u_m * a_pos; }"""
FS = """#version 300 es
precision highp float; in vec4 v; out vec4 o; void main() { o = v; }"""


def layouts(native: np.ndarray) -> dict:
    """The same values as `native` (1-D, native C order) in other memory layouts."""
    n = native.size
    strided = np.zeros(2 * n, native.dtype)
    strided[::2] = native
    raw = b"\0" + native.tobytes()
    out = {
        "big_endian": native.astype(native.dtype.newbyteorder(">")),
        "strided": strided[::2],
        "fortran": np.asfortranarray(native.reshape(2, n // 2)),
        "misaligned": np.frombuffer(raw, native.dtype, offset=1),
        "big_endian_strided": np.repeat(native.astype(native.dtype.newbyteorder(">")), 2)[::2],
    }
    for name, a in out.items():
        assert np.array_equal(a.reshape(-1), native), name   # the values are the same
    return out


LAYOUTS = ["big_endian", "strided", "fortran", "misaligned", "big_endian_strided"]
VALUES = {
    "f4": np.array([0.5, -1.25, 3.0, 1e-3, 2.5, -0.0, 7.75, 100.0] * 2, np.float32),
    "u2": np.array([1, 258, 0xF00F, 0x1234, 65535, 0, 77, 0x8001] * 2, np.uint16),
    "i4": np.array([1, -2, 70000, -70000, 2**31 - 1, -2**31, 5, 0x01020304] * 2, np.int32),
}


def new_gl(**kw):
    return softgl.Context(4, 4, strict=True, antialias=False, **kw)


def bound_buffer(gl, nbytes=64):
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, nbytes, gl.STATIC_DRAW)
    return buf


def buffer_bytes(gl, nbytes=64):
    out = np.zeros(nbytes, np.uint8)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, out)
    return out


# -- sources of bytes: bufferData, bufferSubData -----------------------------------------------

@pytest.mark.parametrize("kind", VALUES)
@pytest.mark.parametrize("layout", LAYOUTS)
def test_buffer_sources_take_values(kind, layout):
    native = VALUES[kind]
    given = layouts(native)[layout]
    gl = new_gl()
    bound_buffer(gl)
    gl.bufferData(gl.ARRAY_BUFFER, given, gl.STATIC_DRAW)
    assert buffer_bytes(gl, native.nbytes).tobytes() == native.tobytes()
    gl.bufferData(gl.ARRAY_BUFFER, 2 * native.nbytes, gl.STATIC_DRAW)
    gl.bufferSubData(gl.ARRAY_BUFFER, 8, given)
    got = buffer_bytes(gl, 2 * native.nbytes)
    assert got[8:8 + native.nbytes].tobytes() == native.tobytes()
    # srcOffset/length count elements of the array, whatever its layout.
    gl.bufferData(gl.ARRAY_BUFFER, given, gl.STATIC_DRAW, 3, 4)
    assert buffer_bytes(gl, 4 * native.itemsize).tobytes() == native[3:7].tobytes()


def test_buffer_sources_take_bytes_like_objects():
    native = VALUES["f4"]
    gl = new_gl()
    bound_buffer(gl)
    for given in (native.tobytes(), bytearray(native.tobytes()), memoryview(native.tobytes()),
                  array.array("f", native.tolist())):
        gl.bufferData(gl.ARRAY_BUFFER, given, gl.STATIC_DRAW)
        assert buffer_bytes(gl, native.nbytes).tobytes() == native.tobytes()
    # array.array's elements are floats: srcOffset counts them.
    gl.bufferData(gl.ARRAY_BUFFER, array.array("f", native.tolist()), gl.STATIC_DRAW, 2, 2)
    assert buffer_bytes(gl, 8).tobytes() == native[2:4].tobytes()


def test_big_endian_buffer_reads_as_its_values():
    # Issue 20, finding 10: 0.5 in a '>f4' array became 8.8e-44.
    gl = new_gl()
    bound_buffer(gl)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([0.5, 1.0], ">f4"), gl.STATIC_DRAW)
    out = np.zeros(2, np.float32)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, out)
    assert out.tolist() == [0.5, 1.0]


# -- destinations: getBufferSubData, readPixels ----------------------------------------------

def destination_layouts(dtype, n):
    """Zeroed destinations of n elements in each layout, with the array to read them back as 1-D
    and a guard array that must stay untouched (the gaps of the strided one)."""
    dt = np.dtype(dtype)
    base = np.full(2 * n, 7, dt)
    return {
        "big_endian": (np.zeros(n, dt.newbyteorder(">")), None),
        "strided": (base[::2], base[1::2]),
        "fortran": (np.asfortranarray(np.zeros((2, n // 2), dt)), None),
        "misaligned": (np.frombuffer(bytearray(1 + n * dt.itemsize), dt, offset=1), None),
    }


@pytest.mark.parametrize("kind", VALUES)
@pytest.mark.parametrize("layout", ["big_endian", "strided", "fortran", "misaligned"])
def test_get_buffer_sub_data_writes_any_layout(kind, layout):
    native = VALUES[kind]
    gl = new_gl()
    bound_buffer(gl)
    gl.bufferData(gl.ARRAY_BUFFER, native, gl.STATIC_DRAW)
    dst, guard = destination_layouts(native.dtype, native.size)[layout]
    gl.getBufferSubData(gl.ARRAY_BUFFER, 0, dst)
    assert np.array_equal(dst.reshape(-1), native)
    if guard is not None:
        assert (guard == 7).all()
    # dstOffset/length: only that element range is written.
    dst, _ = destination_layouts(native.dtype, native.size)[layout]
    expected = dst.reshape(-1).astype(native.dtype)
    gl.getBufferSubData(gl.ARRAY_BUFFER, 8, dst, 2, 3)
    skip = 8 // native.itemsize
    expected[2:5] = native[skip:skip + 3]
    assert np.array_equal(dst.reshape(-1), expected)


def test_failed_get_buffer_sub_data_leaves_a_converted_destination_untouched():
    gl = softgl.Context(4, 4, antialias=False)
    bound_buffer(gl, 8)
    dst = np.arange(16, dtype=">f4")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gl.getBufferSubData(gl.ARRAY_BUFFER, 0, dst)   # 64 bytes from an 8-byte buffer
    assert gl.getError() == gl.INVALID_VALUE
    assert dst.tolist() == list(range(16))


def _scene(gl):
    gl.clearColor(0.25, 0.5, 0.75, 1.0)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.enable(gl.SCISSOR_TEST)
    gl.scissor(1, 2, 2, 1)
    gl.clearColor(1.0, 0.125, 0.0, 0.5)
    gl.clear(gl.COLOR_BUFFER_BIT)
    gl.disable(gl.SCISSOR_TEST)


@pytest.mark.parametrize("layout", ["big_endian", "strided", "fortran", "misaligned"])
@pytest.mark.parametrize("color_format, type_, dtype", [("rgba32f", "FLOAT", np.float32),
                                                        ("rgba8", "UNSIGNED_BYTE", np.uint8)])
def test_read_pixels_writes_any_layout(layout, color_format, type_, dtype):
    gl = new_gl(color_format=color_format)
    _scene(gl)
    type_ = getattr(gl, type_)
    expected = gl.readPixels(0, 0, 4, 4, gl.RGBA, type_).reshape(-1)
    assert len(set(expected.tolist())) > 2   # the scene is not uniform
    dst, guard = destination_layouts(dtype, 64)[layout]
    assert gl.readPixels(0, 0, 4, 4, gl.RGBA, type_, dst) is dst
    assert np.array_equal(dst.reshape(-1), expected)
    if guard is not None:
        assert (guard == 7).all()


# -- pixel sources: texImage2D, texSubImage2D, texImage3D, texSubImage3D ----------------------

TEXTURE_KINDS = {   # values kind -> (internalformat, format, type, read format, read type)
    "f4": ("RGBA32F", "RGBA", "FLOAT", "RGBA", "FLOAT"),
    "u2": ("RGBA4", "RGBA", "UNSIGNED_SHORT_4_4_4_4", "RGBA", "UNSIGNED_BYTE"),
    "i4": ("RGBA32I", "RGBA_INTEGER", "INT", "RGBA_INTEGER", "INT"),
}


def _texels(gl, tex, target, read_format, read_type):
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    if target == gl.TEXTURE_2D:
        gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, tex, 0)
    else:
        gl.framebufferTextureLayer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, tex, 0, 0)
    out = gl.readPixels(0, 0, 2, 2, read_format, read_type)
    gl.bindFramebuffer(gl.FRAMEBUFFER, None)
    gl.deleteFramebuffer(fb)
    return out


def _upload(gl, method, pixels, kind):
    internal, fmt, type_, read_format, read_type = (getattr(gl, n) for n in TEXTURE_KINDS[kind])
    tex = gl.createTexture()
    three_d = method.endswith("3D")
    target = gl.TEXTURE_2D_ARRAY if three_d else gl.TEXTURE_2D
    gl.bindTexture(target, tex)
    for p in (gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER):
        gl.texParameteri(target, p, gl.NEAREST)
    if method == "texImage2D":
        gl.texImage2D(target, 0, internal, 2, 2, 0, fmt, type_, pixels)
    elif method == "texSubImage2D":
        gl.texImage2D(target, 0, internal, 2, 2, 0, fmt, type_, None)
        gl.texSubImage2D(target, 0, 0, 0, 2, 2, fmt, type_, pixels)
    elif method == "texImage3D":
        gl.texImage3D(target, 0, internal, 2, 2, 1, 0, fmt, type_, pixels)
    else:
        gl.texImage3D(target, 0, internal, 2, 2, 1, 0, fmt, type_, None)
        gl.texSubImage3D(target, 0, 0, 0, 0, 2, 2, 1, fmt, type_, pixels)
    return _texels(gl, tex, target, read_format, read_type)


@pytest.mark.parametrize("method", ["texImage2D", "texSubImage2D", "texImage3D", "texSubImage3D"])
@pytest.mark.parametrize("kind", VALUES)
@pytest.mark.parametrize("layout", LAYOUTS)
def test_pixel_sources_take_values(method, kind, layout):
    gl = new_gl()
    gl.getExtension("EXT_color_buffer_float")
    native = VALUES[kind]
    expected = _upload(gl, method, native, kind)
    assert len(set(expected.reshape(-1).tolist())) > 4
    assert np.array_equal(_upload(gl, method, layouts(native)[layout], kind), expected)


def test_big_endian_float_texture_reads_as_its_values():
    gl = new_gl()
    gl.getExtension("EXT_color_buffer_float")
    values = np.array([0.5, 0.25, 2.0, 1.0] * 4, ">f4")
    assert _upload(gl, "texImage2D", values, "f4").reshape(-1).tolist() == values.tolist()


# -- sequences of numbers: uniform*v, vertexAttrib*v, clearBuffer*v, drawBuffers -------------

def _program(gl):
    prog = gl.createProgram()
    for kind, src in ((gl.VERTEX_SHADER, VS), (gl.FRAGMENT_SHADER, FS)):
        sh = gl.createShader(kind)
        gl.shaderSource(sh, src)
        gl.compileShader(sh)
        gl.attachShader(prog, sh)
    gl.linkProgram(prog)
    assert gl.getProgramParameter(prog, gl.LINK_STATUS), gl.getProgramInfoLog(prog)
    gl.useProgram(prog)
    return prog


SEQUENCE_CALLS = {   # name -> (values kind, call(gl, prog, data), read(gl, prog))
    "uniform4fv": ("f4", lambda gl, p, d: gl.uniform4fv(gl.getUniformLocation(p, "u_f"), d, 0, 4),
                   lambda gl, p: gl.getUniform(p, gl.getUniformLocation(p, "u_f"))),
    "uniform4iv": ("i4", lambda gl, p, d: gl.uniform4iv(gl.getUniformLocation(p, "u_i"), d, 0, 4),
                   lambda gl, p: gl.getUniform(p, gl.getUniformLocation(p, "u_i"))),
    "uniform4uiv": ("u2", lambda gl, p, d: gl.uniform4uiv(gl.getUniformLocation(p, "u_u"), d, 0, 4),
                    lambda gl, p: gl.getUniform(p, gl.getUniformLocation(p, "u_u"))),
    "uniformMatrix4fv": ("f4", lambda gl, p, d: gl.uniformMatrix4fv(gl.getUniformLocation(p, "u_m"), False,
                                                                  np.asarray(d).reshape(-1)),
                         lambda gl, p: gl.getUniform(p, gl.getUniformLocation(p, "u_m"))),
    "vertexAttrib4fv": ("f4", lambda gl, p, d: gl.vertexAttrib4fv(1, d),
                        lambda gl, p: gl.getVertexAttrib(1, gl.CURRENT_VERTEX_ATTRIB)),
    "vertexAttribI4iv": ("i4", lambda gl, p, d: gl.vertexAttribI4iv(1, d),
                         lambda gl, p: gl.getVertexAttrib(1, gl.CURRENT_VERTEX_ATTRIB)),
    "vertexAttribI4uiv": ("u2", lambda gl, p, d: gl.vertexAttribI4uiv(1, d),
                          lambda gl, p: gl.getVertexAttrib(1, gl.CURRENT_VERTEX_ATTRIB)),
    "clearBufferfv": ("f4", lambda gl, p, d: gl.clearBufferfv(gl.COLOR, 0, np.asarray(d).reshape(-1)[[0, 3, 0, 2]]),
                      lambda gl, p: gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)),
}


@pytest.mark.parametrize("name", SEQUENCE_CALLS)
@pytest.mark.parametrize("layout", LAYOUTS + ["list", "tuple"])
def test_sequences_take_values(name, layout):
    kind, call, read = SEQUENCE_CALLS[name]
    native = VALUES[kind]
    given = (native.tolist() if layout == "list" else tuple(native.tolist()) if layout == "tuple"
             else layouts(native)[layout])
    gl, reference = new_gl(), new_gl()
    progs = _program(gl), _program(reference)
    call(reference, progs[1], native)
    call(gl, progs[0], given)
    expected, got = read(reference, progs[1]), read(gl, progs[0])
    assert np.array_equal(got, expected)
    fresh = new_gl()
    assert not np.array_equal(got, read(fresh, _program(fresh)))   # the call did set something


def test_clear_buffer_integer_sequences_take_values():
    gl = new_gl()
    gl.getExtension("EXT_color_buffer_float")
    for internal, clear, read_type, native in (("RGBA32I", "clearBufferiv", "INT", VALUES["i4"][:4]),
                                               ("RGBA32UI", "clearBufferuiv", "UNSIGNED_INT", VALUES["u2"][:4])):
        rb = gl.createRenderbuffer()
        gl.bindRenderbuffer(gl.RENDERBUFFER, rb)
        gl.renderbufferStorage(gl.RENDERBUFFER, getattr(gl, internal), 2, 2)
        fb = gl.createFramebuffer()
        gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
        gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb)
        for given in (native.astype(native.dtype.newbyteorder(">")), np.repeat(native, 2)[::2], native.tolist()):
            getattr(gl, clear)(gl.COLOR, 0, np.zeros(4, native.dtype))
            getattr(gl, clear)(gl.COLOR, 0, given)
            px = gl.readPixels(0, 0, 2, 2, gl.RGBA_INTEGER, getattr(gl, read_type))
            assert px.reshape(-1, 4).tolist() == [native.astype(np.int64).tolist()] * 4


def test_enum_sequences_take_arrays_and_lists():
    gl = new_gl()
    fb = gl.createFramebuffer()
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb)
    for given in ([gl.COLOR_ATTACHMENT0], np.array([gl.COLOR_ATTACHMENT0], ">u4"), (gl.NONE,)):
        gl.drawBuffers(given)
        assert gl.getParameter(gl.DRAW_BUFFER0) == int(np.asarray(given)[0])
    gl.invalidateFramebuffer(gl.FRAMEBUFFER, np.array([gl.COLOR_ATTACHMENT0], ">i4"))


# -- refusals: a TypeError naming method and parameter, nothing changed -----------------------

class World:
    """A context with a buffer, a texture, a program, an attribute value and pixels, and a
    snapshot of all of them (to show a refused call changed nothing)."""

    def __init__(self):
        gl = self.gl = new_gl()
        gl.getExtension("EXT_color_buffer_float")
        self.buffer = bound_buffer(gl, 64)
        gl.bufferData(gl.ARRAY_BUFFER, np.arange(16, dtype=np.float32), gl.STATIC_DRAW)
        self.texture = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D, self.texture)
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, 2, 2, 0, gl.RGBA, gl.FLOAT, VALUES["f4"])
        self.tex3d = gl.createTexture()
        gl.bindTexture(gl.TEXTURE_2D_ARRAY, self.tex3d)
        gl.texImage3D(gl.TEXTURE_2D_ARRAY, 0, gl.RGBA32F, 2, 2, 1, 0, gl.RGBA, gl.FLOAT, VALUES["f4"])
        self.prog = _program(gl)
        self.loc = gl.getUniformLocation(self.prog, "u_f")
        self.matrix = gl.getUniformLocation(self.prog, "u_m")
        gl.uniform4fv(self.loc, [1, 2, 3, 4])
        gl.vertexAttrib4fv(1, [5, 6, 7, 8])
        _scene(gl)

    def snapshot(self):
        gl = self.gl
        return [buffer_bytes(gl), _texels(gl, self.texture, gl.TEXTURE_2D, gl.RGBA, gl.FLOAT),
                _texels(gl, self.tex3d, gl.TEXTURE_2D_ARRAY, gl.RGBA, gl.FLOAT),
                gl.getUniform(self.prog, self.loc), gl.getUniform(self.prog, self.matrix),
                gl.getVertexAttrib(1, gl.CURRENT_VERTEX_ATTRIB),
                gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE),
                gl.getParameter(gl.DRAW_BUFFER0)]


OBJECTS = np.array([0.5, None, 1.0, 2.0] * 4, object)
NUMBER_OBJECTS = np.array([0.5, 1.0, 2.0, 3.0] * 4, object)   # numbers, but an object array
WRONG = {
    "object": OBJECTS,
    "object_of_numbers": NUMBER_OBJECTS,
    "complex": np.ones(16, np.complex64),
    "str": np.array(["1.0"] * 16),
    "datetime": np.zeros(16, "datetime64[s]"),
    "list_of_none": [None] * 16,
}
NOT_BYTES = {**WRONG, "bool": np.ones(16, bool), "list": [0.5] * 16, "float": 0.5, "longdouble": np.ones(16, np.longdouble)}
NOT_SEQUENCE = {**WRONG, "str_value": "1234", "float": 0.5, "none": None, "ragged": [[1, 2], [3]]}

CALLS = [   # (method, parameter, wrong inputs, call(world, value))
    ("bufferData", "data", NOT_BYTES, lambda w, v: w.gl.bufferData(w.gl.ARRAY_BUFFER, v, w.gl.STATIC_DRAW)),
    ("bufferSubData", "srcData", {**NOT_BYTES, "int": 4}, lambda w, v: w.gl.bufferSubData(w.gl.ARRAY_BUFFER, 0, v)),
    ("texImage2D", "pixels", {**NOT_BYTES, "bytes": b"\0" * 64},
     lambda w, v: w.gl.texImage2D(w.gl.TEXTURE_2D, 0, w.gl.RGBA32F, 2, 2, 0, w.gl.RGBA, w.gl.FLOAT, v)),
    ("texSubImage2D", "pixels", {**NOT_BYTES, "bytes": b"\0" * 64},
     lambda w, v: w.gl.texSubImage2D(w.gl.TEXTURE_2D, 0, 0, 0, 2, 2, w.gl.RGBA, w.gl.FLOAT, v)),
    ("texImage3D", "srcData", NOT_BYTES,
     lambda w, v: w.gl.texImage3D(w.gl.TEXTURE_2D_ARRAY, 0, w.gl.RGBA32F, 2, 2, 1, 0, w.gl.RGBA, w.gl.FLOAT, v)),
    ("texSubImage3D", "srcData", NOT_BYTES,
     lambda w, v: w.gl.texSubImage3D(w.gl.TEXTURE_2D_ARRAY, 0, 0, 0, 0, 2, 2, 1, w.gl.RGBA, w.gl.FLOAT, v)),
    ("texImage2D", "source", {**WRONG, "list": [[0.5] * 4] * 4, "1-D": np.ones(4, np.float32)},
     lambda w, v: w.gl.texImage2D(w.gl.TEXTURE_2D, 0, w.gl.RGBA, w.gl.RGBA, w.gl.UNSIGNED_BYTE, v)),
    ("readPixels", "pixels", NOT_BYTES,
     lambda w, v: w.gl.readPixels(0, 0, 4, 4, w.gl.RGBA, w.gl.UNSIGNED_BYTE, v)),
    ("getBufferSubData", "dstBuffer", {**NOT_BYTES, "bytearray": bytearray(64)},
     lambda w, v: w.gl.getBufferSubData(w.gl.ARRAY_BUFFER, 0, v)),
    ("uniform4fv", "data", NOT_SEQUENCE, lambda w, v: w.gl.uniform4fv(w.loc, v)),
    ("uniformMatrix4fv", "data", NOT_SEQUENCE, lambda w, v: w.gl.uniformMatrix4fv(w.matrix, False, v)),
    ("vertexAttrib4fv", "values", NOT_SEQUENCE, lambda w, v: w.gl.vertexAttrib4fv(1, v)),
    ("vertexAttribI4iv", "values", NOT_SEQUENCE, lambda w, v: w.gl.vertexAttribI4iv(1, v)),
    ("clearBufferfv", "values", NOT_SEQUENCE, lambda w, v: w.gl.clearBufferfv(w.gl.COLOR, 0, v)),
    ("drawBuffers", "buffers", NOT_SEQUENCE, lambda w, v: w.gl.drawBuffers(v)),
]
REFUSALS = [(m, p, name, v, f) for m, p, wrong, f in CALLS for name, v in wrong.items()]


def _read_only(a):
    a = np.array(a, copy=True)
    a.flags.writeable = False
    return a


REFUSALS += [("readPixels", "pixels", "read_only", _read_only(np.zeros(64, np.uint8)),
              lambda w, v: w.gl.readPixels(0, 0, 4, 4, w.gl.RGBA, w.gl.UNSIGNED_BYTE, v)),
             ("getBufferSubData", "dstBuffer", "read_only", _read_only(np.zeros(16, np.float32)),
              lambda w, v: w.gl.getBufferSubData(w.gl.ARRAY_BUFFER, 0, v)),
             ("getBufferSubData", "dstBuffer", "read_only_big_endian", _read_only(np.zeros(16, ">f4")),
              lambda w, v: w.gl.getBufferSubData(w.gl.ARRAY_BUFFER, 0, v))]


@pytest.mark.parametrize("method, param, name, value, call", REFUSALS,
                         ids=[f"{m}-{n}" for m, _, n, _, _ in REFUSALS])
def test_refusals_name_method_and_parameter_and_change_nothing(method, param, name, value, call):
    world = World()
    before = world.snapshot()
    kept = value.copy() if isinstance(value, np.ndarray) else None
    with pytest.raises(TypeError) as info:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", softgl.Float64Warning)
            call(world, value)
    message = str(info.value)
    assert message.startswith(f"{method}: {param} must be "), message
    assert "got " in message
    assert world.gl.getError() == world.gl.NO_ERROR
    for a, b in zip(world.snapshot(), before):
        assert np.array_equal(np.asarray(a), np.asarray(b))
    if kept is not None and value.dtype != object:
        assert np.array_equal(value, kept)


def test_messages_say_what_to_write():
    gl = new_gl()
    bound_buffer(gl)
    with pytest.raises(TypeError) as info:
        gl.bufferData(gl.ARRAY_BUFFER, [0.0, 1.0], gl.STATIC_DRAW)
    assert str(info.value) == ("bufferData: data must be a size in bytes (int), None or an ArrayBuffer-like "
                               "(a NumPy array of numbers, or bytes); got list - use np.asarray(data, np.float32)")
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    with pytest.raises(TypeError, match=r"texSubImage2D: pixels must be .*; got list - use "
                                        r"np.asarray\(pixels, np.uint16\)"):
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 1, 1, gl.RGB, gl.UNSIGNED_SHORT_5_6_5, [1])
    with pytest.raises(TypeError, match=r"readPixels: pixels must be a writeable NumPy array.*; got a read-only "
                                        r"NumPy array of dtype uint8 - pass a writeable copy"):
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, _read_only(np.zeros(4, np.uint8)))
    with pytest.raises(TypeError, match=r"bufferData: data .*; got a NumPy array of dtype bool - WebGL has no "
                                        r"boolean arrays: use data.astype\(np.uint8\)"):
        gl.bufferData(gl.ARRAY_BUFFER, np.ones(4, bool), gl.STATIC_DRAW)


def test_texture_size_error_names_unpack_alignment():
    gl = new_gl()
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    # RGB rows of width 5 are 15 bytes; with UNPACK_ALIGNMENT 4 they start 16 bytes apart.
    with pytest.raises(softgl.GLError, match=r"holds 45 bytes, 47 are needed: UNPACK_ALIGNMENT is 4, so each "
                                             r"row of 15 bytes starts 16 bytes after the previous one"):
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 5, 3, 0, gl.RGB, gl.UNSIGNED_BYTE, np.zeros(45, np.uint8))
    with pytest.raises(softgl.GLError) as info:   # short even without padding: no mention of it
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 5, 3, 0, gl.RGB, gl.UNSIGNED_BYTE, np.zeros(44, np.uint8))
    assert "UNPACK_ALIGNMENT" not in str(info.value)
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB, 5, 3, 0, gl.RGB, gl.UNSIGNED_BYTE, np.zeros(45, np.uint8))


def test_object_array_destination_does_not_crash():
    # Issue 20, finding 2: getBufferSubData wrote raw bytes over an object array's pointers
    # (SIGSEGV when the array was used), bufferData stored object addresses. In a child process,
    # so that a crash fails this test instead of ending the run.
    code = """
import numpy as np, softgl
gl = softgl.Context(4, 4)
gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
gl.bufferData(gl.ARRAY_BUFFER, np.arange(8, dtype=np.float32), gl.STATIC_DRAW)
refused = 0
for call in (lambda: gl.getBufferSubData(gl.ARRAY_BUFFER, 0, np.empty(2, object)),
             lambda: gl.bufferData(gl.ARRAY_BUFFER, np.array([object(), object()]), gl.STATIC_DRAW)):
    try:
        call()
    except TypeError:
        refused += 1
a = np.empty(2, object)
print(refused, repr(a), gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE))
"""
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[0] == "2"
    assert run.stdout.strip().endswith("32")   # the buffer kept its 8 floats


def test_buffer_offsets_too_big_name_the_parameter():
    # Was pybind11's "Unable to cast Python instance of type <class 'int'> to C++ type '?'".
    gl = new_gl()
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    with pytest.raises(OverflowError, match=r"texSubImage2D: pixels as a buffer offset must fit a GLintptr"):
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, 2**70)
    with pytest.raises(OverflowError, match=r"readPixels: pixels as a buffer offset must fit a GLintptr"):
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, 2**70)
    assert gl.getError() == gl.NO_ERROR


@pytest.mark.parametrize("setter, uniform, values", [
    ("uniform4iv", "u_i", [2**32 + 5, -1, True, -2**31 - 1]),
    ("uniform4uiv", "u_u", [-1, 2**33 + 2, False, 7]),
    ("uniform4fv", "u_f", [1, 2.5, True, 2**40]),
])
def test_lists_of_python_numbers_convert_as_numpy_does(setter, uniform, values):
    # Lists of Python ints and floats take a path of their own (no NumPy conversion): the same
    # values as the NumPy array of them (integers wrap modulo 2^32, as WebIDL's ToInt32/ToUint32).
    gl = new_gl()
    prog = _program(gl)
    loc = gl.getUniformLocation(prog, uniform)
    getattr(gl, setter)(loc, values)
    from_list = gl.getUniform(prog, loc)
    getattr(gl, setter)(loc, np.array([0, 0, 0, 0]))
    getattr(gl, setter)(loc, np.array(values, np.int64 if setter != "uniform4fv" else np.float64))
    assert np.array_equal(from_list, gl.getUniform(prog, loc))
    expected = {"uniform4iv": [5, -1, 1, 2**31 - 1], "uniform4uiv": [2**32 - 1, 2, 0, 7],
                "uniform4fv": [1.0, 2.5, 1.0, 2.0**40]}[setter]
    assert from_list.tolist() == expected


def test_matrices_and_fog_take_the_intake():
    gl = new_gl()
    prog = _program(gl)
    loc = gl.getUniformLocation(prog, "u_m")
    m = np.arange(16, dtype=np.float32).reshape(4, 4)
    gl.uniformMatrix4fv(loc, False, m.astype(">f4"))          # a 2-D matrix: math layout, any byte order
    assert np.array_equal(gl.getUniform(prog, loc), m.T.reshape(-1))
    before = gl.getUniform(prog, loc)
    with pytest.raises(TypeError, match=r"^uniformMatrix4fv: data must be a sequence of numbers"):
        gl.uniformMatrix4fv(loc, False, m.astype(object))
    assert np.array_equal(gl.getUniform(prog, loc), before) and gl.getError() == gl.NO_ERROR
    fog = gl.getExtension("SOFTGL_fog")
    fog.fogfv(fog.FOG_COLOR, np.array([0.25, 0.5, 0.75, 1.0], ">f4")[::-1][::-1])
    assert np.array_equal(gl.getParameter(fog.FOG_COLOR), [0.25, 0.5, 0.75, 1.0])
    with pytest.raises(TypeError, match=r"^fogfv: params must be a sequence of numbers"):
        fog.fogfv(fog.FOG_COLOR, [0.5, None, 0.5, 1.0])
    assert np.array_equal(gl.getParameter(fog.FOG_COLOR), [0.25, 0.5, 0.75, 1.0])
