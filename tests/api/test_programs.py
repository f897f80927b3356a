"""Shader and program objects, uniforms and draw validation through the WebGL API (issues 3-4).

Error codes were checked against Chromium's WebGL (see the comments); pixel values against
hand computations.
"""
import numpy as np
import pytest

import softgl

VS = """attribute vec4 p; void main() { gl_Position = p; }"""
FS = """precision mediump float;
uniform vec4 c; uniform bool b; uniform float a[3]; uniform mat2 m; uniform int i;
void main() { gl_FragColor = c + a[2] + float(b) + m[1][0] + float(i); }"""


def linked(gl, vs=VS, fs=FS):
    prog = softgl.program(gl, vs, fs)
    gl.useProgram(prog)
    return prog


def test_compile_errors_give_info_log_with_line_numbers(version):
    gl = softgl.Context(2, 2, version=version)
    s = gl.createShader(gl.FRAGMENT_SHADER)
    gl.shaderSource(s, "precision mediump float;\nvoid main() {\n  gl_FragColor = vec4(1.0) + undefined_name;\n}")
    gl.compileShader(s)
    assert gl.getShaderParameter(s, gl.COMPILE_STATUS) is False
    log = gl.getShaderInfoLog(s)
    assert log.startswith("ERROR: 0:3:") and "undefined_name" in log
    assert gl.getShaderSource(s).startswith("precision")
    assert gl.getError() == gl.NO_ERROR
    with pytest.raises(softgl.ShaderError, match="ERROR: 0:3"):
        softgl.program(gl, VS, "precision mediump float;\nvoid main() {\n  undefined_name;\n}")


def test_link_errors(version):
    gl = softgl.Context(2, 2, version=version)
    with pytest.raises(softgl.ShaderError, match="vColor"):
        softgl.program(gl, VS, "precision mediump float; varying vec3 vColor; void main() { gl_FragColor = vec4(vColor, 1.0); }")
    prog = gl.createProgram()
    gl.linkProgram(prog)
    assert gl.getProgramParameter(prog, gl.LINK_STATUS) is False
    assert gl.getProgramInfoLog(prog)


def test_object_rules_match_webgl(version, quiet):
    gl = softgl.Context(2, 2, version=version)
    vs, fs = gl.createShader(gl.VERTEX_SHADER), gl.createShader(gl.FRAGMENT_SHADER)
    for s, src in ((vs, VS), (fs, FS)):
        gl.shaderSource(s, src)
        gl.compileShader(s)
    p = gl.createProgram()
    gl.attachShader(p, vs)
    gl.attachShader(p, fs)
    gl.attachShader(p, vs)
    assert gl.getError() == gl.INVALID_OPERATION          # attached twice
    gl.attachShader(p, gl.createShader(gl.VERTEX_SHADER))
    assert gl.getError() == gl.INVALID_OPERATION          # a second vertex shader
    gl.detachShader(p, gl.createShader(gl.VERTEX_SHADER))
    assert gl.getError() == gl.INVALID_OPERATION          # not attached
    assert gl.getAttachedShaders(p) == [vs, fs]
    gl.linkProgram(p)
    assert gl.getProgramParameter(p, gl.LINK_STATUS) is True
    assert gl.getProgramParameter(p, gl.ATTACHED_SHADERS) == 2
    # A deleted shader that is still attached lives on (Chromium: isShader true, DELETE_STATUS true).
    gl.deleteShader(vs)
    assert gl.isShader(vs) and gl.getShaderParameter(vs, gl.DELETE_STATUS) is True
    gl.detachShader(p, vs)
    assert not gl.isShader(vs)
    gl.compileShader(vs)
    assert gl.getError() == gl.INVALID_VALUE              # deleted object: INVALID_VALUE
    q = gl.createProgram()
    gl.deleteProgram(q)
    gl.useProgram(q)
    assert gl.getError() == gl.INVALID_OPERATION          # but useProgram(deleted): INVALID_OPERATION
    gl.linkProgram(q)
    assert gl.getError() == gl.INVALID_VALUE
    gl.useProgram(gl.createProgram())
    assert gl.getError() == gl.INVALID_OPERATION          # not linked
    for name, index in (("gl_x", 0), ("webgl_x", 0), ("x", 99)):
        gl.bindAttribLocation(p, index, name)
        assert gl.getError() == (gl.INVALID_VALUE if index == 99 else gl.INVALID_OPERATION)
    gl.getUniformLocation(gl.createProgram(), "c")
    assert gl.getError() == gl.INVALID_OPERATION          # program not linked


def test_uniforms_set_and_get(version, quiet):
    gl = softgl.Context(2, 2, version=version)
    p = linked(gl)
    c, b, a, a2, m, i = (gl.getUniformLocation(p, n) for n in ("c", "b", "a", "a[2]", "m", "i"))
    assert None not in (c, b, a, a2, m, i)
    assert gl.getUniformLocation(p, "a[3]") is None and gl.getUniformLocation(p, "nope") is None
    gl.uniform4f(c, 1, 2, 3, 4)
    assert gl.getUniform(p, c).tolist() == [1, 2, 3, 4]
    gl.uniform1i(b, 2)
    assert gl.getUniform(p, b) is True                    # bools take ints and floats
    gl.uniform1f(b, 0.0)
    assert gl.getUniform(p, b) is False
    gl.uniform1fv(a, [1, 2, 3, 4, 5])                     # extra elements are ignored
    assert gl.getError() == gl.NO_ERROR and gl.getUniform(p, a2) == 3
    gl.uniform1fv(a2, np.array([7, 8], np.float32))
    assert gl.getUniform(p, a2) == 7
    gl.uniformMatrix2fv(m, False, [1, 2, 3, 4])          # column-major
    assert gl.getUniform(p, m).tolist() == [1, 2, 3, 4]
    gl.uniform1i(i, -7)
    assert gl.getUniform(p, i) == -7
    errors = [
        (lambda: gl.uniform1f(c, 1), gl.INVALID_OPERATION),          # wrong size
        (lambda: gl.uniform4fv(c, [1, 2, 3]), gl.INVALID_VALUE),     # not a multiple of 4
        (lambda: gl.uniform4fv(c, [0] * 8), gl.INVALID_OPERATION),   # two values, not an array
        (lambda: gl.uniform1i(c, 1), gl.INVALID_OPERATION),          # int for a float
        (lambda: gl.uniformMatrix2fv(m, True, [1, 2, 3, 4]),
         gl.INVALID_VALUE if version == 1 else gl.NO_ERROR),        # transpose: WebGL 2 only
    ]
    for call, error in errors:
        call()
        assert gl.getError() == error
    if version == 2:
        assert gl.getUniform(p, m).tolist() == [1, 3, 2, 4]          # transposed
    gl.uniform4f(None, 1, 2, 3, 4)                                   # null location: no-op
    assert gl.getError() == gl.NO_ERROR
    gl.useProgram(None)
    gl.uniform4f(c, 1, 2, 3, 4)
    assert gl.getError() == gl.INVALID_OPERATION                     # no program in use
    gl.useProgram(p)
    gl.linkProgram(p)
    gl.uniform4f(c, 1, 2, 3, 4)
    assert gl.getError() == gl.INVALID_OPERATION                     # stale location


def test_active_info_and_precision(version):
    gl = softgl.Context(2, 2, version=version)
    p = linked(gl)
    assert gl.getProgramParameter(p, gl.ACTIVE_ATTRIBUTES) == 1
    info = gl.getActiveAttrib(p, 0)
    assert (info.name, info.size, info.type) == ("p", 1, gl.FLOAT_VEC4)
    n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS)
    names = {gl.getActiveUniform(p, k).name: gl.getActiveUniform(p, k) for k in range(n)}
    assert set(names) == {"c", "b", "a[0]", "m", "i"}
    assert names["a[0]"].size == 3 and names["a[0]"].type == gl.FLOAT
    fmt = gl.getShaderPrecisionFormat(gl.FRAGMENT_SHADER, gl.MEDIUM_FLOAT)
    assert (fmt.rangeMin, fmt.rangeMax, fmt.precision) == (127, 127, 23)   # all floats are fp32
    assert gl.getAttribLocation(p, "p") == 0 and gl.getAttribLocation(p, "q") == -1


def test_draw_validation(version, quiet):
    gl = softgl.Context(4, 4, version=version, antialias=False)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() == gl.INVALID_OPERATION          # no program
    p = linked(gl)
    loc = gl.getAttribLocation(p, "p")
    gl.drawArrays(0x1234, 0, 3)
    assert gl.getError() == gl.INVALID_ENUM
    gl.drawArrays(gl.TRIANGLES, -1, 3)
    assert gl.getError() == gl.INVALID_VALUE
    gl.drawArrays(gl.TRIANGLES, 0, 3)                    # attribute disabled: constant value
    assert gl.getError() == gl.NO_ERROR
    gl.enableVertexAttribArray(loc)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() == gl.INVALID_OPERATION          # enabled without a buffer
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.zeros(8, np.float32), gl.STATIC_DRAW)
    gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.getError() == gl.INVALID_OPERATION          # reads past the buffer (2 vertices)
    gl.drawArrays(gl.TRIANGLES, 0, 2)
    assert gl.getError() == gl.NO_ERROR
    gl.drawElements(gl.TRIANGLES, 3, gl.UNSIGNED_BYTE, 0)
    assert gl.getError() == gl.INVALID_OPERATION          # no element buffer
    eb = gl.createBuffer()
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, eb)
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, np.array([0, 1, 5], np.uint16), gl.STATIC_DRAW)
    for count, typ, offset, error in [(3, gl.UNSIGNED_SHORT, 0, gl.INVALID_OPERATION),   # index 5
                                      (2, gl.UNSIGNED_SHORT, 1, gl.INVALID_OPERATION),   # misaligned
                                      (3, gl.UNSIGNED_SHORT, 2, gl.INVALID_OPERATION),   # past the end
                                      (2, gl.UNSIGNED_SHORT, 0, gl.NO_ERROR),
                                      (2, gl.FLOAT, 0, gl.INVALID_ENUM)]:
        gl.drawElements(gl.TRIANGLES, count, typ, offset)
        assert gl.getError() == error, (count, typ, offset)
    gl.drawElements(gl.TRIANGLES, 2, gl.UNSIGNED_INT, 0)
    assert gl.getError() == (gl.INVALID_ENUM if version == 1 else gl.INVALID_OPERATION)


def test_stencil_front_back_must_agree_when_there_is_a_stencil_buffer(quiet):
    for stencil, error in ((False, "NO_ERROR"), (True, "INVALID_OPERATION")):
        gl = softgl.Context(2, 2, stencil=stencil)
        linked(gl)
        gl.stencilFuncSeparate(gl.BACK, gl.ALWAYS, 1, 0xFF)
        gl.drawArrays(gl.TRIANGLES, 0, 3)
        assert gl.getError() == getattr(gl, error)


VS_COLOR = """attribute vec2 aPos; attribute vec3 aColor; varying vec3 vColor;
void main() { vColor = aColor; gl_Position = vec4(aPos, 0.0, 1.0); }"""
FS_COLOR = """precision mediump float; varying vec3 vColor; uniform float uAlpha;
void main() { gl_FragColor = vec4(vColor, uAlpha); }"""


def test_a_glsl_triangle_interpolates_colors():
    gl = softgl.Context(8, 8, antialias=False)
    p = linked(gl, VS_COLOR, FS_COLOR)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, np.array([-1, -1, 1, 0, 0, 1, -1, 0, 1, 0, -1, 1, 0, 0, 1], np.float32),
                  gl.STATIC_DRAW)
    for name, size, offset in (("aPos", 2, 0), ("aColor", 3, 8)):
        loc = gl.getAttribLocation(p, name)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, size, gl.FLOAT, False, 20, offset)
    gl.uniform1f(gl.getUniformLocation(p, "uAlpha"), 1.0)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    img = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE).astype(int)
    # Pixel (0, 0): centre (0.5, 0.5) -> NDC (-0.875, -0.875): weights 0.875, 0.0625, 0.0625.
    assert img[0, 0].tolist() == [223, 16, 16, 255]
    # Pixel (2, 3): centre (2.5, 3.5) -> NDC (-0.375, -0.125): weights 0.25, 0.3125, 0.4375.
    assert img[3, 2].tolist() == [64, 80, 112, 255]
    assert (img[..., 3] > 0).sum() == 28                  # the lower-left half, ties excluded
    assert gl.stats()["draws"] == 1


def test_constant_attribute_and_points_without_attributes():
    gl = softgl.Context(8, 8, antialias=False)
    linked(gl, "void main() { gl_PointSize = 4.0; gl_Position = vec4(0.0, 0.0, 0.0, 1.0); }",
           "precision mediump float; void main() { gl_FragColor = vec4(gl_PointCoord, 0.0, 1.0); }")
    gl.drawArrays(gl.POINTS, 0, 1)
    img = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE).astype(int)
    covered = img[..., 3] > 0
    assert covered.sum() == 16 and covered[2:6, 2:6].all()
    # gl_PointCoord at the lower-left covered pixel's centre: s = 0.125, t = 0.875 (t points down).
    assert img[2, 2, :2].tolist() == [32, 223]
