"""Texture copies and texel words (docs/architecture.md, "Fast paths").

A fragment shader whose colour is one implicit-LOD 2D lookup at a varying, copied as it is to its
one output, is served by asking the sampler directly (GlslFragmentShader::run_texture_copy: the
executor's own query) instead of running the executor; where that lookup is NEAREST of 8-bit
unorm storage and the write is plain (blending off, all channels, one sample), the texels' RGBA8
words go to the pixels without the float round trip (TextureUnitSampler::sample_words).

References: the same draws with the paths switched off (softgl.testing tuning texture_copies /
texel_words: the executor runs the shader, the colour kernels convert the floats), at every SIMD
level this CPU has and 1 and 2 threads; and, for the byte claim, the texture's own bytes (a 1:1
NEAREST copy of a texture holding every byte value in every channel must give those bytes back:
unorm(k, 8) = k / 255 and the float-to-unorm conversion of ES 3.0 §2.1.6.1 round trip exactly).
Shaders that look alike but do more (a swizzle, arithmetic, a bias, two outputs, discard) must not
take the path, and still match the executor."""
import numpy as np
import pytest

import softgl
from softgl import _core

T = _core.testing
LEVELS = ["scalar", "sse2", "avx2", "avx512"][:T.simd_level() + 1]

VS = """#version 300 es
in vec4 pos;
in vec2 uv;
out vec2 vUV;
void main() { vUV = uv; gl_Position = pos; }
"""
FS_COPY = """#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
out vec4 fragColor;
void main() { fragColor = texture(uTex, vUV); }
"""
VS1 = """attribute vec4 pos;
attribute vec2 uv;
varying vec2 vUV;
void main() { vUV = uv; gl_Position = pos; }
"""
FS1_COPY = """precision mediump float;
uniform sampler2D uTex;
varying vec2 vUV;
void main() { gl_FragColor = texture2D(uTex, vUV); }
"""

W, H = 61, 47   # odd sizes: partial quads and tiles at the right and top edges


def es3(body, decl="out vec4 fragColor;"):
    return f"""#version 300 es
precision mediump float;
uniform sampler2D uTex;
in vec2 vUV;
{decl}
void main() {{ {body} }}
"""


# Shaders that are not a texture copy (each changes what a copy would give).
NOT_COPIES = {
    "swizzle": es3("fragColor = texture(uTex, vUV).bgra;"),
    "scaled": es3("fragColor = texture(uTex, vUV) * 0.5;"),
    "moved_coordinate": es3("fragColor = texture(uTex, vUV + vec2(0.1, 0.0));"),
    "bias": es3("fragColor = texture(uTex, vUV, 1.5);"),
    "opaque": es3("fragColor = vec4(texture(uTex, vUV).rgb, 1.0);"),
    "discard": es3("vec4 c = texture(uTex, vUV); if (c.r > 0.5) discard; fragColor = c;"),
    "two_outputs": es3("fragColor = texture(uTex, vUV); extra = texture(uTex, vUV);",
                       "layout(location = 0) out vec4 fragColor;\nlayout(location = 1) out vec4 extra;"),
}
# ... and ones that are: the lookup may read the varying's words in any order, from any varying.
COPIES = {
    "swapped_coordinates": es3("fragColor = texture(uTex, vUV.yx);"),
    "second_varying": es3("fragColor = texture(uTex, vOther.zx);", "in vec4 vOther;\nout vec4 fragColor;"),
}
VS_OTHER = """#version 300 es
in vec4 pos;
in vec2 uv;
out vec2 vUV;
out vec4 vOther;
void main() { vUV = uv; vOther = vec4(uv.y * 0.5, 3.0, uv.x * 1.5 - 0.25, 1.0); gl_Position = pos; }
"""

# Two triangles over most of the canvas, one at a slant (partial coverage, edges through quads),
# with a perspective w so that the coordinates are not affine; uv runs past [0, 1] (wrapping).
POSITIONS = np.array([
    [-0.9, -0.95, 0.0, 1.0], [0.95, -0.8, 0.0, 1.0], [-0.85, 0.9, 0.0, 1.0],
    [0.3 * 2.0, -0.7 * 2.0, 0.0, 2.0], [0.9 * 0.7, 0.95 * 0.7, 0.0, 0.7], [-0.6 * 1.4, 0.85 * 1.4, 0.0, 1.4],
], np.float32)
UVS = np.array([[-0.3, -0.2], [1.7, -0.1], [-0.2, 1.4], [1.1, -0.6], [1.9, 1.8], [-0.4, 1.2]], np.float32)


def texture_data(rng, w, h, channels):
    return rng.integers(0, 256, (h, w, channels)).astype(np.uint8)


FORMATS = {
    # name: (internal format, format, type, channels)
    "rgba8": ("RGBA8", "RGBA", "UNSIGNED_BYTE", 4),
    "luminance_alpha": ("LUMINANCE_ALPHA", "LUMINANCE_ALPHA", "UNSIGNED_BYTE", 2),
    "rg8": ("RG8", "RG", "UNSIGNED_BYTE", 2),
    "rgba32f": ("RGBA32F", "RGBA", "FLOAT", 4),
}


def render(fs, *, vs=VS, fmt="rgba8", min_filter="NEAREST", mag_filter="NEAREST", wrap="REPEAT", size=(16, 8),
           blend=None, mask=(True, True, True, True), simd=None, threads=1, copies=True, words=True,
           seed=1, fbo=None, samples=None):
    """Draws POSITIONS/UVS with the texture; returns (RGBA bytes of the canvas, stats, plan)."""
    kwargs = dict(antialias=False, threads=threads)
    gl = softgl.Context(W, H, **kwargs)
    fields = dict(texture_copies=copies, texel_words=words)
    if simd:
        fields["simd"] = simd
    T.set_tuning(gl, **fields)
    prog = softgl.program(gl, vs, fs)
    gl.useProgram(prog)
    for name, data in (("pos", POSITIONS), ("uv", UVS)):
        loc = gl.getAttribLocation(prog, name)
        buf = gl.createBuffer()
        gl.bindBuffer(gl.ARRAY_BUFFER, buf)
        gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
        gl.enableVertexAttribArray(loc)
        gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
    rng = np.random.default_rng(seed)
    internal, form, typ, channels = FORMATS[fmt]
    tex = gl.createTexture()
    gl.activeTexture(gl.TEXTURE0 + 2)   # not unit 0: the sampler uniform's value is read
    gl.bindTexture(gl.TEXTURE_2D, tex)
    w, h = size
    data = texture_data(rng, w, h, channels)
    if typ == "FLOAT":
        data = (data.astype(np.float32) / 200.0 - 0.1).astype(np.float32)   # some outside [0, 1]
    gl.texImage2D(gl.TEXTURE_2D, 0, getattr(gl, internal), w, h, 0, getattr(gl, form), getattr(gl, typ), data)
    if "MIPMAP" in min_filter:
        gl.generateMipmap(gl.TEXTURE_2D)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, getattr(gl, min_filter))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, getattr(gl, mag_filter))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, getattr(gl, wrap))
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, getattr(gl, wrap))
    gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 2)
    gl.clearColor(0.2, 0.4, 0.6, 0.8)
    gl.clear(gl.COLOR_BUFFER_BIT)
    if blend:
        gl.enable(gl.BLEND)
        gl.blendFunc(*(getattr(gl, f) for f in blend))
    gl.colorMask(*mask)
    gl.stats(reset=True)
    gl.drawArrays(gl.TRIANGLES, 0, 6)
    stats = gl.stats()
    plan = gl.last_draw_plan()
    gl.colorMask(True, True, True, True)
    return gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE), stats, plan


def reference(fs, **kw):
    kw = dict(kw, copies=False, words=False)
    return render(fs, **kw)[0]


def assert_bytes_equal(got, want, what):
    bad = np.argwhere((got != want).any(axis=-1))
    assert bad.size == 0, f"{what}: {len(bad)} pixels differ, first at {bad[0]}: {got[tuple(bad[0])]} vs {want[tuple(bad[0])]}"


def test_every_byte_value_round_trips():
    """A 1:1 NEAREST copy of a 256x4 texture holding every byte value in every channel (in four
    different orders) gives the texture's bytes: the words path by construction, the float path
    (executor, colour kernels) because k / 255 converts back to k for all 256 k."""
    gl_w, gl_h = 256, 4
    k = np.arange(256, dtype=np.uint8)
    tex = np.stack([np.stack([np.roll(k, 37 * r), k[::-1], np.roll(k, 101 + r), np.roll(k[::-1], 7 * r)], -1)
                    for r in range(gl_h)])
    fs = FS_COPY
    results = {}
    for copies, words in ((True, True), (True, False), (False, False)):
        gl = softgl.Context(gl_w, gl_h, antialias=False)
        T.set_tuning(gl, texture_copies=copies, texel_words=words)
        prog = softgl.program(gl, VS, fs)
        gl.useProgram(prog)
        quad = np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [-1, 1, 0, 1], [-1, 1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1]], np.float32)
        uv = (quad[:, :2] + 1) / 2
        for name, data in (("pos", quad), ("uv", uv.astype(np.float32))):
            loc = gl.getAttribLocation(prog, name)
            gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
        gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
        gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, gl_w, gl_h, 0, gl.RGBA, gl.UNSIGNED_BYTE, tex)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
        gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
        gl.drawArrays(gl.TRIANGLES, 0, 6)
        st = gl.stats()
        assert st["draws_texture_copy"] == int(copies)
        assert st["draws_texel_words"] == int(words)
        results[(copies, words)] = gl.readPixels(0, 0, gl_w, gl_h, gl.RGBA, gl.UNSIGNED_BYTE)
    for key, got in results.items():
        assert_bytes_equal(got, tex, f"texture_copies, texel_words = {key}")


@pytest.mark.parametrize("simd", LEVELS)
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("fmt, filters", [
    (fmt, filters) for fmt in FORMATS
    for filters in [("NEAREST", "NEAREST"), ("LINEAR", "LINEAR"), ("LINEAR_MIPMAP_LINEAR", "LINEAR"),
                    ("NEAREST_MIPMAP_NEAREST", "NEAREST"), ("LINEAR", "NEAREST")]
    # RGBA32F is neither filterable nor mipmapped without extensions: NEAREST only.
    if fmt != "rgba32f" or filters == ("NEAREST", "NEAREST")])
def test_same_bytes_as_the_executor(simd, threads, fmt, filters):
    kw = dict(fmt=fmt, min_filter=filters[0], mag_filter=filters[1], simd=simd, threads=threads)
    want = reference(FS_COPY, **kw)
    got, stats, plan = render(FS_COPY, **kw)
    assert stats["draws_texture_copy"] == 1 and plan["texture_copy"]
    # NEAREST, or one LINEAR level (Tuning::linear_words, tests/textures/test_linear_words.py).
    byte_words = filters in (("NEAREST", "NEAREST"), ("LINEAR", "LINEAR")) and fmt != "rgba32f"
    assert stats["draws_texel_words"] == int(byte_words), plan
    assert_bytes_equal(got, want, f"{fmt} {filters} at {simd}, {threads} thread(s)")
    # Texture copies without texel words: the sampler's floats through the colour kernels.
    got_floats, stats, _ = render(FS_COPY, **kw, words=False)
    assert stats["draws_texel_words"] == 0
    assert_bytes_equal(got_floats, want, f"{fmt} {filters} at {simd}, {threads} thread(s), floats")


@pytest.mark.parametrize("wrap", ["REPEAT", "CLAMP_TO_EDGE", "MIRRORED_REPEAT"])
@pytest.mark.parametrize("size", [(16, 8), (13, 7)])   # powers of two, and not
@pytest.mark.parametrize("simd", LEVELS)
def test_wraps_and_sizes(wrap, size, simd):
    kw = dict(wrap=wrap, size=size, simd=simd)
    got, stats, _ = render(FS_COPY, **kw)
    assert stats["draws_texel_words"] == 1
    assert_bytes_equal(got, reference(FS_COPY, **kw), f"{wrap} {size} at {simd}")


@pytest.mark.parametrize("simd", LEVELS)
@pytest.mark.parametrize("state", ["alpha_over", "additive", "mask_rgb", "mask_alpha"])
def test_blending_and_masks_take_the_colour_kernels(simd, state):
    """The words path only where the write keeps the bytes: blending and colour masks read the
    destination, so the texture copy's floats go through the colour kernels."""
    kw = dict(simd=simd)
    if state == "alpha_over":
        kw["blend"] = ("SRC_ALPHA", "ONE_MINUS_SRC_ALPHA")
    elif state == "additive":
        kw["blend"] = ("ONE", "ONE")
    elif state == "mask_rgb":
        kw["mask"] = (True, True, True, False)
    else:
        kw["mask"] = (False, False, False, True)
    got, stats, plan = render(FS_COPY, **kw)
    assert stats["draws_texture_copy"] == 1 and stats["draws_texel_words"] == 0
    assert not plan["texel_words"]
    assert_bytes_equal(got, reference(FS_COPY, **kw), f"{state} at {simd}")


def test_es1_shader_and_plain_blend_func():
    """texture2D in ES 1.00 is the same program; blending ONE, ZERO is a plain write."""
    kw = dict(vs=VS1, blend=("ONE", "ZERO"))
    got, stats, plan = render(FS1_COPY, **kw)
    assert stats["draws_texture_copy"] == 1 and stats["draws_texel_words"] == 1
    assert_bytes_equal(got, reference(FS1_COPY, **kw), "ES 1.00")


@pytest.mark.parametrize("name", list(NOT_COPIES))
@pytest.mark.parametrize("filters", [("NEAREST", "NEAREST"), ("LINEAR_MIPMAP_LINEAR", "LINEAR")])
def test_other_shaders_do_not_take_it(name, filters):
    """Eligibility: each of these differs from a plain copy; taking the path would give the copy's
    bytes (the test against the executor fails), and the plan must say why not."""
    fs = NOT_COPIES[name]
    kw = dict(min_filter=filters[0], mag_filter=filters[1])
    got, stats, plan = render(fs, **kw)
    assert stats["draws_texture_copy"] == 0 and stats["draws_texel_words"] == 0
    assert not plan["texture_copy"]
    assert_bytes_equal(got, reference(fs, **kw), name)
    # And they do differ from the copy, so a wrong eligibility could not pass unnoticed.
    # (A bias changes nothing without mipmaps.)
    if name != "two_outputs" and not (name == "bias" and "MIPMAP" not in filters[0]):
        copy = render(FS_COPY, **kw)[0]
        assert (copy != got).any(), name


@pytest.mark.parametrize("name", list(COPIES))
@pytest.mark.parametrize("simd", LEVELS)
def test_lookups_at_other_words_take_it(name, simd):
    fs = COPIES[name]
    for filters in (("NEAREST", "NEAREST"), ("LINEAR_MIPMAP_LINEAR", "LINEAR")):
        kw = dict(vs=VS_OTHER, min_filter=filters[0], mag_filter=filters[1], simd=simd)
        got, stats, _ = render(fs, **kw)
        assert stats["draws_texture_copy"] == 1
        assert stats["draws_texel_words"] == int(filters[0] == "NEAREST")
        assert_bytes_equal(got, reference(fs, **kw), f"{name} {filters} at {simd}")
        assert (got != render(FS_COPY, **dict(kw, vs=VS_OTHER))[0]).any(), name


def test_switches_and_plan():
    """The tuning switches turn the paths off; the plan names the reason."""
    _, stats, plan = render(FS_COPY, copies=False, words=True)
    assert stats["draws_texture_copy"] == 0 and stats["draws_texel_words"] == 0
    assert not plan["texture_copy"] and not plan["texel_words"]
    _, stats, plan = render(FS_COPY, fmt="rgba32f")
    assert stats["draws_texture_copy"] == 1 and stats["draws_texel_words"] == 0
    _, stats, plan = render(FS_COPY, min_filter="LINEAR", mag_filter="NEAREST")
    assert stats["draws_texel_words"] == 0


def test_framebuffer_object_and_multisampled_canvas():
    """An RGBA8 texture attachment takes the colour kernels (words too); a multisampled canvas
    does not take the words (several samples), and both give the executor's bytes."""
    for samples in (False, True):
        results = []
        for copies in (True, False):
            gl = softgl.Context(W, H, antialias=samples)
            T.set_tuning(gl, texture_copies=copies, texel_words=copies)
            prog = softgl.program(gl, VS, FS_COPY)
            gl.useProgram(prog)
            for name, data in (("pos", POSITIONS), ("uv", UVS)):
                loc = gl.getAttribLocation(prog, name)
                gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
                gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
                gl.enableVertexAttribArray(loc)
                gl.vertexAttribPointer(loc, data.shape[1], gl.FLOAT, False, 0, 0)
            tex = gl.createTexture()
            gl.bindTexture(gl.TEXTURE_2D, tex)
            data = texture_data(np.random.default_rng(3), 16, 8, 4)
            gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 16, 8, 0, gl.RGBA, gl.UNSIGNED_BYTE, data)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST)
            gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST)
            gl.uniform1i(gl.getUniformLocation(prog, "uTex"), 0)
            target = None
            if not samples:
                target = gl.createTexture()
                gl.bindTexture(gl.TEXTURE_2D, target)
                gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA8, W, H)
                gl.bindFramebuffer(gl.FRAMEBUFFER, gl.createFramebuffer())
                gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0)
                gl.bindTexture(gl.TEXTURE_2D, tex)
            gl.drawArrays(gl.TRIANGLES, 0, 6)
            st = gl.stats()
            assert st["draws_texture_copy"] == int(copies)
            assert st["draws_texel_words"] == int(copies and not samples)
            results.append(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE))
        assert_bytes_equal(results[0], results[1], "multisampled canvas" if samples else "framebuffer object")
