"""WebGL 1's shader extensions (OES_standard_derivatives, EXT_frag_depth, EXT_shader_texture_lod)
and EXT_texture_filter_anisotropic's state, through the WebGL API.

Enum values are the extension specifications' (WebGL extension registry IDL); pixel values are
hand computations. The directive rule: a GLSL ES 1.00 `#extension` directive takes effect only
for an extension the context enabled with getExtension (each extension's WebGL specification);
without it the directive warns and what the extension adds is a compile error.
"""
import numpy as np
import pytest

import softgl

QUAD = np.array([-1, -1, 1, -1, -1, 1, -1, 1, 1, -1, 1, 1], np.float32)
VS = """attribute vec2 pos; varying vec2 f;
void main() { f = pos * 0.5 + 0.5; gl_Position = vec4(pos, 0.0, 1.0); }"""

DERIVATIVES_FS = """#extension GL_OES_standard_derivatives : enable
precision highp float; varying vec2 f;
void main() { float v = 4.0 * f.x + 6.0 * f.y; gl_FragColor = vec4(dFdx(v), dFdy(v), fwidth(v), 1.0); }"""
FRAG_DEPTH_FS = """#extension GL_EXT_frag_depth : enable
precision highp float; varying vec2 f;
void main() { gl_FragDepthEXT = f.x; gl_FragColor = vec4(1.0, 0.0, 0.0, 1.0); }"""
LOD_FS = """#extension GL_EXT_shader_texture_lod : enable
precision highp float; varying vec2 f; uniform sampler2D s; uniform float lod;
void main() { gl_FragColor = texture2DLodEXT(s, f, lod); }"""


def compile_status(gl, source, kind=None):
    s = gl.createShader(gl.FRAGMENT_SHADER if kind is None else kind)
    gl.shaderSource(s, source)
    gl.compileShader(s)
    return gl.getShaderParameter(s, gl.COMPILE_STATUS), gl.getShaderInfoLog(s)


def draw(gl, fs, setup=None):
    prog = softgl.program(gl, VS, fs)
    gl.useProgram(prog)
    buf = gl.createBuffer()
    gl.bindBuffer(gl.ARRAY_BUFFER, buf)
    gl.bufferData(gl.ARRAY_BUFFER, QUAD, gl.STATIC_DRAW)
    loc = gl.getAttribLocation(prog, "pos")
    gl.enableVertexAttribArray(loc)
    gl.vertexAttribPointer(loc, 2, gl.FLOAT, False, 0, 0)
    if setup:
        setup(prog)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    return prog


def test_offered_in_webgl1_and_not_in_webgl2():
    names1 = softgl.Context(2, 2, version=1).getSupportedExtensions()
    names2 = softgl.Context(2, 2, version=2).getSupportedExtensions()
    for name in ("OES_standard_derivatives", "EXT_frag_depth", "EXT_shader_texture_lod"):
        assert name in names1 and name not in names2   # core in WebGL 2
    assert "EXT_texture_filter_anisotropic" in names1 and "EXT_texture_filter_anisotropic" in names2


def test_enum_values_from_the_specifications():
    gl = softgl.Context(2, 2, version=1)
    assert gl.getExtension("OES_standard_derivatives").FRAGMENT_SHADER_DERIVATIVE_HINT_OES == 0x8B8B
    aniso = gl.getExtension("EXT_texture_filter_anisotropic")
    assert (aniso.TEXTURE_MAX_ANISOTROPY_EXT, aniso.MAX_TEXTURE_MAX_ANISOTROPY_EXT) == (0x84FE, 0x84FF)
    assert gl.getExtension("ext_frag_depth") is gl.getExtension("EXT_frag_depth")   # case-insensitive, one object
    assert gl.getExtension("EXT_shader_texture_lod") is not None


@pytest.mark.parametrize("source, needs", [
    (DERIVATIVES_FS, "OES_standard_derivatives"),
    (FRAG_DEPTH_FS, "EXT_frag_depth"),
    (LOD_FS, "EXT_shader_texture_lod"),
])
def test_directive_needs_get_extension(source, needs):
    gl = softgl.Context(2, 2, version=1)
    ok, log = compile_status(gl, source)
    assert not ok
    assert "extension is not supported" in log            # the directive only warns ...
    assert "ERROR" in log                                  # ... what it would add is an error
    assert gl.getExtension(needs) is not None
    ok, log = compile_status(gl, source)
    assert ok, log
    assert gl.getError() == gl.NO_ERROR


def test_builtins_without_directive_are_errors_even_when_enabled():
    gl = softgl.Context(2, 2, version=1)
    for name in ("OES_standard_derivatives", "EXT_frag_depth", "EXT_shader_texture_lod"):
        gl.getExtension(name)
    for body in ("gl_FragColor = vec4(dFdx(f.x));", "gl_FragDepthEXT = 0.5;",
                 "gl_FragColor = texture2DLodEXT(s, f, 0.0);", "gl_FragColor = vec4(fwidth(f), 0.0, 1.0);"):
        ok, log = compile_status(gl, "precision highp float; varying vec2 f; uniform sampler2D s; void main() { "
                                 + body + " }")
        assert not ok and "ERROR" in log, body


def test_webgl2_es100_shaders_may_name_them():
    gl = softgl.Context(2, 2, version=2)
    for source in (DERIVATIVES_FS, FRAG_DEPTH_FS, LOD_FS):
        assert compile_status(gl, source)[0]


def test_derivative_hint():
    gl = softgl.Context(2, 2, version=1)
    with pytest.warns(softgl.GLWarning):
        gl.hint(0x8B8B, gl.NICEST)
    assert gl.getError() == gl.INVALID_ENUM
    with pytest.warns(softgl.GLWarning):
        assert gl.getParameter(0x8B8B) is None
    assert gl.getError() == gl.INVALID_ENUM
    ext = gl.getExtension("OES_standard_derivatives")
    assert gl.getParameter(ext.FRAGMENT_SHADER_DERIVATIVE_HINT_OES) == gl.DONT_CARE
    gl.hint(ext.FRAGMENT_SHADER_DERIVATIVE_HINT_OES, gl.NICEST)
    assert gl.getParameter(ext.FRAGMENT_SHADER_DERIVATIVE_HINT_OES) == gl.NICEST
    assert gl.getError() == gl.NO_ERROR


def test_derivatives_render():
    gl = softgl.Context(16, 16, version=1, antialias=False)
    gl.getExtension("OES_standard_derivatives")
    draw(gl, DERIVATIVES_FS)
    px = gl.readPixels(0, 0, 16, 16, gl.RGBA, gl.UNSIGNED_BYTE)
    # v = 4 x/16 + 6 y/16 in pixels: dFdx = 0.25, dFdy = 0.375, fwidth = 0.625 -> 63.75, 95.625, 159.375
    assert (px.reshape(-1, 4) == [64, 96, 159, 255]).all()


def test_frag_depth_renders():
    gl = softgl.Context(16, 4, version=1, antialias=False)
    gl.getExtension("EXT_frag_depth")
    gl.enable(gl.DEPTH_TEST)
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
    draw(gl, FRAG_DEPTH_FS)    # depth = (x + 0.5) / 16 at pixel x, whatever the quad's z (0.5)
    # A green quad at window depth 0.5 passes LESS where the stored depth is above 0.5: x >= 8.
    draw(gl, "precision highp float; void main() { gl_FragColor = vec4(0.0, 1.0, 0.0, 1.0); }")
    px = gl.readPixels(0, 0, 16, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    expected = np.where((np.arange(16) + 0.5) / 16 > 0.5, 1, 0)
    assert (px[:, :, 1] == 255 * expected).all() and (px[:, :, 0] == 255 * (1 - expected)).all()


def mip_levels(gl, colors, target=None):
    """A texture whose level k (size 2^(n-1-k)) is colors[k] everywhere."""
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    n = len(colors)
    for k, c in enumerate(colors):
        size = 1 << (n - 1 - k)
        gl.texImage2D(gl.TEXTURE_2D, k, gl.RGBA, size, size, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                      np.tile(np.array(c, np.uint8), (size, size, 1)))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST)
    return tex


COLORS = [(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 255), (255, 255, 0, 255)]


@pytest.mark.parametrize("lod, level", [(0.0, 0), (1.0, 1), (1.6, 2), (2.2, 2), (9.0, 3)])
def test_texture2d_lod_ext(lod, level):
    gl = softgl.Context(8, 8, version=1, antialias=False)
    gl.getExtension("EXT_shader_texture_lod")
    mip_levels(gl, COLORS)
    # ES 2.0 §3.7.7 (NEAREST_MIPMAP_NEAREST): level ceil(lod + 1/2) - 1 for lod > 1/2, else 0;
    # lod 0 magnifies (mag filter LINEAR over a one-colour level).
    draw(gl, LOD_FS, lambda p: gl.uniform1f(gl.getUniformLocation(p, "lod"), lod))
    px = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE)
    assert (px.reshape(-1, 4) == COLORS[level]).all()


@pytest.mark.parametrize("grad, level", [(0.5 / 8, 0), (2.0 / 8, 1), (4.0 / 8, 2), (16.0 / 8, 3)])
def test_texture2d_grad_ext(grad, level):
    gl = softgl.Context(8, 8, version=1, antialias=False)
    gl.getExtension("EXT_shader_texture_lod")
    mip_levels(gl, COLORS)
    # rho = |grad| * 8 texels (level 0 is 8 x 8): lambda = log2(rho) = -1, 1, 2, 4.
    fs = """#extension GL_EXT_shader_texture_lod : enable
    precision highp float; varying vec2 f; uniform sampler2D s; uniform float g;
    void main() { gl_FragColor = texture2DGradEXT(s, f, vec2(g, 0.0), vec2(0.0, g)); }"""
    draw(gl, fs, lambda p: gl.uniform1f(gl.getUniformLocation(p, "g"), grad))
    px = gl.readPixels(0, 0, 8, 8, gl.RGBA, gl.UNSIGNED_BYTE)
    assert (px.reshape(-1, 4) == COLORS[level]).all()


def test_texture_cube_lod_ext():
    gl = softgl.Context(4, 4, version=1, antialias=False)
    gl.getExtension("EXT_shader_texture_lod")
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, tex)
    for k, c in enumerate(COLORS[:3]):
        size = 4 >> k
        for face in range(6):
            gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, k, gl.RGBA, size, size, 0, gl.RGBA,
                          gl.UNSIGNED_BYTE, np.tile(np.array(c, np.uint8), (size, size, 1)))
    gl.texParameteri(gl.TEXTURE_CUBE_MAP, gl.TEXTURE_MIN_FILTER, gl.NEAREST_MIPMAP_NEAREST)
    fs = """#extension GL_EXT_shader_texture_lod : enable
    precision highp float; varying vec2 f; uniform samplerCube s;
    void main() { gl_FragColor = textureCubeLodEXT(s, vec3(1.0, f - 0.5), 2.0); }"""
    draw(gl, fs)
    px = gl.readPixels(0, 0, 4, 4, gl.RGBA, gl.UNSIGNED_BYTE)
    assert (px.reshape(-1, 4) == COLORS[2]).all()


@pytest.mark.parametrize("version", [1, 2])
def test_anisotropy_parameter(version):
    gl = softgl.Context(2, 2, version=version)
    tex = gl.createTexture()
    gl.bindTexture(gl.TEXTURE_2D, tex)
    with pytest.warns(softgl.GLWarning):   # before getExtension: not a parameter
        gl.texParameterf(gl.TEXTURE_2D, 0x84FE, 4.0)
    assert gl.getError() == gl.INVALID_ENUM
    with pytest.warns(softgl.GLWarning):
        gl.getParameter(0x84FF)
    assert gl.getError() == gl.INVALID_ENUM
    ext = gl.getExtension("EXT_texture_filter_anisotropic")
    assert gl.getParameter(ext.MAX_TEXTURE_MAX_ANISOTROPY_EXT) == 16.0
    assert gl.getTexParameter(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT) == 1.0   # the initial value
    gl.texParameterf(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT, 4.5)
    assert gl.getTexParameter(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT) == 4.5
    gl.texParameteri(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT, 64)   # kept; clamped when sampling
    assert gl.getTexParameter(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT) == 64.0
    with pytest.warns(softgl.GLWarning, match="at least 1.0"):
        gl.texParameterf(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT, 0.5)
    assert gl.getError() == gl.INVALID_VALUE
    assert gl.getTexParameter(gl.TEXTURE_2D, ext.TEXTURE_MAX_ANISOTROPY_EXT) == 64.0   # unchanged
    assert gl.getError() == gl.NO_ERROR
    if version == 2:
        s = gl.createSampler()
        assert gl.getSamplerParameter(s, ext.TEXTURE_MAX_ANISOTROPY_EXT) == 1.0
        gl.samplerParameterf(s, ext.TEXTURE_MAX_ANISOTROPY_EXT, 8.0)
        assert gl.getSamplerParameter(s, ext.TEXTURE_MAX_ANISOTROPY_EXT) == 8.0
        with pytest.warns(softgl.GLWarning):
            gl.samplerParameterf(s, ext.TEXTURE_MAX_ANISOTROPY_EXT, 0.0)
        assert gl.getError() == gl.INVALID_VALUE
