"""conformance/state (gl-geterror, gl-enum-tests, gl-object-get-calls), misc (is-object,
null-object-behaviour, invalid-passed-params, webgl-specific, functions-returning-strings,
views-with-offsets, boolean-argument-conversion) and limits (gl-min-attribs, gl-min-uniforms)."""
import numpy as np
import pytest

from conformance.helpers import (GREEN, QUAD, array_buffer, attribute, context, error, errors,
                                 pixel, program, read)


def test_get_error_first_error_or_all_of_them(version):
    # gl-geterror: after INVALID_VALUE, INVALID_ENUM, INVALID_OPERATION in that order, either only
    # the first is reported or all are, the first among them; then NO_ERROR.
    gl = context(version=version)
    gl.viewport(-1, -1, -1, -1)                      # INVALID_VALUE
    gl.enable(0x0BC0)                                # GL_ALPHA_TEST: INVALID_ENUM
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferSubData(gl.ARRAY_BUFFER, 4, np.zeros(4, np.uint8))   # INVALID_VALUE again
    gl.useProgram(gl.createProgram())                # INVALID_OPERATION
    errs = errors(gl)
    assert errs[0] == gl.INVALID_VALUE
    assert errs in ([gl.INVALID_VALUE], [gl.INVALID_VALUE, gl.INVALID_ENUM, gl.INVALID_OPERATION])


@pytest.mark.parametrize("call", [
    "blendEquation(1)", "blendEquationSeparate(gl.FUNC_ADD, 1)", "blendFunc(0x1234, gl.ONE)",
    "blendFuncSeparate(gl.ONE, gl.ONE, 0x1234, gl.ONE)", "bufferData(1, 4, gl.STATIC_DRAW)",
    "cullFace(1)", "depthFunc(1)", "disable(1)", "enable(1)", "frontFace(1)", "hint(1, gl.NICEST)",
    "hint(gl.GENERATE_MIPMAP_HINT, 1)", "stencilFunc(1, 0, 0)", "stencilOp(1, gl.KEEP, gl.KEEP)",
    "stencilFuncSeparate(1, gl.ALWAYS, 0, 0)", "stencilMaskSeparate(1, 0)", "drawArrays(0x7, 0, 3)",
    "getParameter(1)", "getBufferParameter(gl.ARRAY_BUFFER, 1)", "getVertexAttrib(0, 1)",
    "isEnabled(1)", "getShaderPrecisionFormat(1, gl.HIGH_FLOAT)",
    "getShaderPrecisionFormat(gl.VERTEX_SHADER, 1)", "pixelStorei(1, 1)", "createShader(1)",
    "readPixels(0, 0, 1, 1, gl.RGBA, 1)"])
def test_invalid_enums(version, call):
    # gl-enum-tests: every enum argument rejects values outside its set with INVALID_ENUM.
    gl = context(version=version)
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
    gl.bufferData(gl.ARRAY_BUFFER, 16, gl.STATIC_DRAW)
    eval("gl." + call, {"gl": gl})
    assert errors(gl) == [gl.INVALID_ENUM]


def test_object_get_calls(version):
    # gl-object-get-calls (buffers, shaders, programs, attributes; textures and framebuffers
    # pending): every parameter returns the documented type and value.
    gl = context(version=version)
    buf = array_buffer(gl, np.zeros(7, np.float32))
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 28
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_USAGE) == gl.STATIC_DRAW
    p = program(gl, locations={"aPos": 0})
    assert gl.getProgramParameter(p, gl.DELETE_STATUS) is False
    assert gl.getProgramParameter(p, gl.LINK_STATUS) is True
    assert gl.getProgramParameter(p, gl.VALIDATE_STATUS) in (False, True)
    assert gl.getProgramParameter(p, gl.ATTACHED_SHADERS) == 2
    assert gl.getProgramParameter(p, gl.ACTIVE_ATTRIBUTES) == 1
    assert gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS) == 0
    gl.validateProgram(p)
    assert gl.getProgramParameter(p, gl.VALIDATE_STATUS) is True
    gl.enableVertexAttribArray(0)
    gl.vertexAttribPointer(0, 3, gl.SHORT, True, 8, 4)
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_BUFFER_BINDING) == buf
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_ENABLED) is True
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_SIZE) == 3
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_STRIDE) == 8
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_TYPE) == gl.SHORT
    assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_NORMALIZED) is True
    assert gl.getVertexAttribOffset(0, gl.VERTEX_ATTRIB_ARRAY_POINTER) == 4
    gl.getVertexAttribOffset(0, gl.VERTEX_ATTRIB_ARRAY_SIZE)
    assert error(gl) == gl.INVALID_ENUM
    if version == 2:
        assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_INTEGER) is False
        assert gl.getVertexAttrib(0, gl.VERTEX_ATTRIB_ARRAY_DIVISOR) == 0
    assert error(gl) == gl.NO_ERROR


def test_is_object_and_null_objects(version):
    # is-object, null-object-behaviour: is* is false for None, for never-bound buffers (WebGL:
    # isBuffer needs a bind) and for deleted objects; calls given None behave as GL's 0.
    gl = context(version=version)
    b = gl.createBuffer()
    assert gl.isBuffer(None) is False and gl.isBuffer(b) is False
    gl.bindBuffer(gl.ARRAY_BUFFER, b)
    assert gl.isBuffer(b) is True
    gl.deleteBuffer(b)
    assert gl.isBuffer(b) is False
    p, s = gl.createProgram(), gl.createShader(gl.VERTEX_SHADER)
    assert gl.isProgram(p) and gl.isShader(s)
    assert not gl.isProgram(None) and not gl.isShader(None)
    gl.useProgram(None)
    gl.bindBuffer(gl.ARRAY_BUFFER, None)
    gl.deleteBuffer(None)
    gl.deleteProgram(None)
    gl.deleteShader(None)
    assert error(gl) == gl.NO_ERROR
    for call in (lambda: gl.attachShader(None, s), lambda: gl.compileShader(None),
                 lambda: gl.linkProgram(None), lambda: gl.getProgramParameter(None, gl.LINK_STATUS),
                 lambda: gl.getAttribLocation(None, "a"), lambda: gl.getUniformLocation(None, "a")):
        try:
            call()
        except TypeError:
            continue                                   # WebGL IDL: non-nullable -> TypeError
        assert error(gl) in (gl.INVALID_VALUE,)


def test_objects_from_another_context_are_rejected():
    # incorrect-context-object-behaviour (conformance/context): objects belong to their context.
    a, b = context(version=2), context(version=2)
    buf = b.createBuffer()
    a.bindBuffer(a.ARRAY_BUFFER, buf)
    assert error(a) == a.INVALID_OPERATION
    assert a.isBuffer(buf) is False


def test_invalid_passed_params(version):
    # invalid-passed-params: negative sizes, depthRange near > far (WebGL 1.0 §6.12), bad stencil
    # references are clamped not rejected, shaderSource characters outside ESSL's set.
    gl = context(version=version)
    gl.depthRange(0.8, 0.2)
    assert error(gl) == gl.INVALID_OPERATION
    gl.depthRange(0.2, 0.8)
    gl.viewport(0, 0, -1, 1)
    assert error(gl) == gl.INVALID_VALUE
    gl.scissor(0, 0, 1, -1)
    assert error(gl) == gl.INVALID_VALUE
    gl.lineWidth(0)
    assert error(gl) == gl.INVALID_VALUE
    gl.readPixels(0, 0, -1, 1, gl.RGBA, gl.UNSIGNED_BYTE)
    assert error(gl) == gl.INVALID_VALUE
    gl.drawArrays(gl.TRIANGLES, -1, 1)
    assert error(gl) == gl.INVALID_VALUE
    gl.drawArrays(gl.TRIANGLES, 0, -1)
    assert error(gl) == gl.INVALID_VALUE
    s = gl.createShader(gl.FRAGMENT_SHADER)
    gl.shaderSource(s, "void main() { gl_FragColor = vec4(1.0); } // comment: \u00e9 \u2603")
    assert error(gl) == gl.NO_ERROR                    # non-ASCII allowed in comments
    gl.compileShader(s)
    assert gl.getShaderParameter(s, gl.COMPILE_STATUS) is True
    gl.shaderSource(s, "void main() { gl_FragColor = vec4(1.0); float \u00e9 = 1.0; }")
    err = error(gl)
    gl.compileShader(s)
    assert err == gl.INVALID_VALUE or gl.getShaderParameter(s, gl.COMPILE_STATUS) is False


def test_webgl_specific_rules(version):
    # webgl-specific: constant color + constant alpha blend factors together are
    # INVALID_OPERATION (WebGL 1.0 §6.13); stencil front/back masks and refs must match at draw
    # time (§6.11); drawingBuffer size is the canvas size.
    gl = context(10, 12, version=version, stencil=True)
    assert (gl.drawingBufferWidth, gl.drawingBufferHeight) == (10, 12)
    gl.blendFunc(gl.CONSTANT_COLOR, gl.CONSTANT_ALPHA)
    assert error(gl) == gl.INVALID_OPERATION
    gl.blendFunc(gl.ONE_MINUS_CONSTANT_ALPHA, gl.ONE_MINUS_CONSTANT_COLOR)
    assert error(gl) == gl.INVALID_OPERATION
    gl.blendFuncSeparate(gl.CONSTANT_COLOR, gl.CONSTANT_ALPHA, gl.ONE, gl.ONE)
    assert error(gl) == gl.INVALID_OPERATION
    gl.blendFuncSeparate(gl.ONE, gl.ONE, gl.CONSTANT_COLOR, gl.CONSTANT_ALPHA)
    assert error(gl) == gl.NO_ERROR                    # alpha factors may mix (only RGB checked)
    program(gl, locations={"aPos": 0})
    attribute(gl, 0, QUAD, 2)
    gl.stencilMaskSeparate(gl.BACK, 0x0F)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.INVALID_OPERATION
    gl.stencilMaskSeparate(gl.BACK, 0xFFFFFFFF)
    gl.stencilFuncSeparate(gl.FRONT, gl.ALWAYS, 3, 0xFF)
    gl.stencilFuncSeparate(gl.BACK, gl.ALWAYS, 3 + 256, 0xFF)   # clamped to 255 != 3
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.INVALID_OPERATION
    gl.stencilFuncSeparate(gl.BACK, gl.ALWAYS, 3, 0xFF)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.NO_ERROR


def test_functions_returning_strings(version):
    # functions-returning-strings: info logs and sources are str (never None) for valid objects.
    gl = context(version=version)
    s = gl.createShader(gl.VERTEX_SHADER)
    p = gl.createProgram()
    for v in (gl.getShaderInfoLog(s), gl.getShaderSource(s), gl.getProgramInfoLog(p),
              gl.getParameter(gl.VERSION), gl.getParameter(gl.VENDOR),
              gl.getParameter(gl.RENDERER), gl.getParameter(gl.SHADING_LANGUAGE_VERSION)):
        assert isinstance(v, str)
    assert gl.getParameter(gl.VERSION).startswith("WebGL %d.0" % version)
    assert gl.getParameter(gl.SHADING_LANGUAGE_VERSION).startswith(
        "WebGL GLSL ES %s" % ("1.0" if version == 1 else "3.00"))


def test_views_with_offsets(version):
    # views-with-offsets: array views that start inside a larger buffer upload only the view.
    gl = context(version=version)
    big = np.arange(16, dtype=np.float32)
    view = big[4:10]
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, view, gl.STATIC_DRAW)
    assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 24
    if version == 2:
        out = np.zeros(6, np.float32)
        gl.getBufferSubData(gl.ARRAY_BUFFER, 0, out)
        np.testing.assert_array_equal(out, view)
        gl.bufferSubData(gl.ARRAY_BUFFER, 4, big, 12, 2)       # srcOffset/length in elements
        gl.getBufferSubData(gl.ARRAY_BUFFER, 0, out)
        np.testing.assert_array_equal(out, [4, 12, 13, 7, 8, 9])
        gl.bufferData(gl.ARRAY_BUFFER, big, gl.STATIC_DRAW, 2, 3)
        assert gl.getBufferParameter(gl.ARRAY_BUFFER, gl.BUFFER_SIZE) == 12
        gl.bufferData(gl.ARRAY_BUFFER, big, gl.STATIC_DRAW, 17)
        assert error(gl) == gl.INVALID_VALUE


def test_boolean_argument_conversion(version):
    # boolean-argument-conversion: GLboolean arguments accept truthy values (Python: bool, int)
    gl = context(version=version)
    gl.colorMask(1, 0, True, False)
    assert gl.getParameter(gl.COLOR_WRITEMASK) == [True, False, True, False]
    gl.depthMask(0)
    assert gl.getParameter(gl.DEPTH_WRITEMASK) is False
    gl.sampleCoverage(0.5, 1)
    assert gl.getParameter(gl.SAMPLE_COVERAGE_INVERT) is True


def test_min_attribs(version):
    # gl-min-attribs: MAX_VERTEX_ATTRIBS >= 8 and a program using 8 attributes draws.
    gl = context(version=version)
    n = gl.getParameter(gl.MAX_VERTEX_ATTRIBS)
    assert n >= 8
    decl = "".join(f"attribute vec4 a{i};" for i in range(8))
    total = " + ".join(f"a{i}" for i in range(1, 8))
    vs = f"{decl} varying vec4 v; void main() {{ gl_Position = a0; v = {total}; }}"
    program(gl, vs, "precision mediump float; varying vec4 v; void main() { gl_FragColor = v; }",
            {f"a{i}": i for i in range(8)})
    attribute(gl, 0, QUAD, 2)
    for i in range(1, 8):
        attribute(gl, i, np.tile(np.float32([i / 255, 0, 0, 0]), 6), 4)
    gl.vertexAttrib4f(0, 0, 0, 0, 1)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert error(gl) == gl.NO_ERROR and pixel(gl, 8, 8)[0] == sum(range(1, 8))


def test_min_uniforms(version):
    # gl-min-uniforms: at least 128 vertex and 16 fragment uniform vectors, all usable.
    gl = context(version=version)
    nv = gl.getParameter(gl.MAX_VERTEX_UNIFORM_VECTORS)
    nf = gl.getParameter(gl.MAX_FRAGMENT_UNIFORM_VECTORS)
    assert nv >= 128 and nf >= 16 and gl.getParameter(gl.MAX_VARYING_VECTORS) >= 8
    vs = """attribute vec4 aPos; uniform vec4 uv[128]; varying vec4 v;
    void main() { gl_Position = aPos; vec4 s = vec4(0.0);
      for (int i = 0; i < 128; ++i) s += uv[i]; v = s; }"""
    fs = """precision mediump float; uniform vec4 uf[16]; varying vec4 v;
    void main() { vec4 s = v; for (int i = 0; i < 16; ++i) s += uf[i]; gl_FragColor = s; }"""
    p = program(gl, vs, fs, {"aPos": 0})
    gl.uniform4fv(gl.getUniformLocation(p, "uv"), np.tile(np.float32([1 / 255, 0, 0, 0]), 128))
    gl.uniform4fv(gl.getUniformLocation(p, "uf"), np.tile(np.float32([0, 2 / 255, 0, 1 / 16]), 16))
    attribute(gl, 0, QUAD, 2)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    assert pixel(gl, 8, 8) == (128, 32, 0, 255)
