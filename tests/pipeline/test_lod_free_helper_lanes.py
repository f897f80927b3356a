"""No helper lanes for implicit-LOD lookups whose LOD cannot change the result (Tuning
lod_free_helper_lanes; FragmentShader::reads_quad_neighbours_in_draw): with no mipmaps and one
filter for magnification and minification (ES 3.0 §3.8.11) the executor never takes a lookup's
derivatives, so the shader may run on single covered pixels. The references: the same draws with
the switch off (whole quads, helper lanes shaded) and shaded per primitive chunk
(fragment_batches=False); every one must give the same colour and depth bytes, at every SIMD level
and thread count, with fewer lanes shaded when the path is taken."""
import numpy as np
import pytest

import softgl
from softgl.testing import tuned

W, H = 96, 80   # two tiles across, partial quads at the edges
SIMD = ["scalar", "sse2", "avx2", "avx512"][:softgl._core.testing.simd_level() + 1]

VS = """#version 300 es
in vec4 aPos;
in vec4 aAttr;
out vec4 vAttr;
void main() { vAttr = aAttr; gl_Position = aPos; }
"""
HEAD = "#version 300 es\nprecision highp float;\nin vec4 vAttr;\nout vec4 o;\n"
SHADERS = {
    "tex2d": HEAD + "uniform sampler2D s; void main() { o = texture(s, vAttr.xy * 1.7 - 0.3) * 0.8 + vAttr.zwxy * 0.2; }",
    "bias": HEAD + "uniform sampler2D s; void main() { o = texture(s, vAttr.xy, 2.5) + vec4(0.0, 0.0, 0.0, vAttr.w); }",
    "two_lookups": HEAD + """uniform sampler2D s; uniform sampler2D t;
        void main() { o = 0.5 * texture(s, vAttr.xy) + 0.5 * texture(t, vAttr.yx * 3.0); }""",
    "cube": HEAD + "uniform samplerCube s; void main() { o = texture(s, vAttr.xyz * 2.0 - 1.0); }",
    "shadow": HEAD + """uniform highp sampler2DShadow s;
        void main() { float lit = texture(s, vec3(vAttr.xy, vAttr.z)); o = vec4(lit, vAttr.w * lit, 0.5, 1.0); }""",
    # Derivatives of its own: whole quads whatever the texture.
    "derivatives": HEAD + "uniform sampler2D s; void main() { o = texture(s, vAttr.xy) + 8.0 * abs(dFdx(vAttr)); }",
}


def geometry(n=400, pixels=7.0, seed=5):
    """n small overlapping triangles with perspective (w from 1 to 3), both facings, and a vec4 of
    attributes in [0, 1] (texture coordinates, cube directions, shadow references)."""
    r = np.random.default_rng(seed)
    centre = r.uniform(-1, 1, (n, 1, 2))
    xy = (centre + r.uniform(-1, 1, (n, 3, 2)) * (pixels / W)).reshape(-1, 2)
    z = np.repeat(r.uniform(-0.9, 0.9, (n, 1)), 3, axis=1).reshape(-1, 1) + r.uniform(-0.05, 0.05, (n * 3, 1))
    w = r.uniform(1, 3, (n * 3, 1))
    pos = np.concatenate([xy * w, z * w, w], axis=1).astype(np.float32)
    return pos, r.uniform(0, 1, (n * 3, 4)).astype(np.float32)


def colour_texture(gl, unit, size, seed, min_filter, mag_filter, mipmap=False):
    gl.activeTexture(gl.TEXTURE0 + unit)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    img = np.random.default_rng(seed).integers(0, 256, (size, size, 4), dtype=np.uint8)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, size, size, 0, gl.RGBA, gl.UNSIGNED_BYTE, img)
    if mipmap:
        gl.generateMipmap(gl.TEXTURE_2D)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, min_filter)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, mag_filter)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.REPEAT)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.MIRRORED_REPEAT)


def cube_texture(gl, filt):
    gl.activeTexture(gl.TEXTURE0)
    gl.bindTexture(gl.TEXTURE_CUBE_MAP, gl.createTexture())
    r = np.random.default_rng(11)
    for face in range(6):
        gl.texImage2D(gl.TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, gl.RGBA8, 16, 16, 0, gl.RGBA, gl.UNSIGNED_BYTE,
                      r.integers(0, 256, (16, 16, 4), dtype=np.uint8))
    for pname, value in ((gl.TEXTURE_MIN_FILTER, filt), (gl.TEXTURE_MAG_FILTER, filt),
                         (gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE), (gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE)):
        gl.texParameteri(gl.TEXTURE_CUBE_MAP, pname, value)


def shadow_texture(gl, filt):
    gl.activeTexture(gl.TEXTURE0)
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture())
    words = np.random.default_rng(12).integers(0, 2 ** 32, (32, 32), dtype=np.uint64).astype(np.uint32)
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.DEPTH_COMPONENT24, 32, 32, 0, gl.DEPTH_COMPONENT, gl.UNSIGNED_INT, words)
    for pname, value in ((gl.TEXTURE_MIN_FILTER, filt), (gl.TEXTURE_MAG_FILTER, filt),
                         (gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE), (gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE),
                         (gl.TEXTURE_COMPARE_MODE, gl.COMPARE_REF_TO_TEXTURE), (gl.TEXTURE_COMPARE_FUNC, gl.LEQUAL)):
        gl.texParameteri(gl.TEXTURE_2D, pname, value)


def textures(gl, shader, kind):
    """The textures of `kind`: 'linear' / 'nearest' (no mipmaps, one filter: the LOD selects
    nothing), 'min_differs' (LINEAR minification, NEAREST magnification) or 'mipmapped'."""
    filt = {"linear": gl.LINEAR, "nearest": gl.NEAREST}.get(kind, gl.LINEAR)
    if shader == "cube":
        return cube_texture(gl, filt)
    if shader == "shadow":
        return shadow_texture(gl, filt)
    for unit in range(2 if shader == "two_lookups" else 1):
        if kind == "mipmapped":
            colour_texture(gl, unit, 32, 20 + unit, gl.LINEAR_MIPMAP_LINEAR, gl.LINEAR, mipmap=True)
        elif kind == "min_differs":
            colour_texture(gl, unit, 32, 20 + unit, gl.LINEAR, gl.NEAREST)
        else:
            colour_texture(gl, unit, 32, 20 + unit, filt, filt)


def render(shader, kind, threads=1, **tuning):
    gl = softgl.Context(W, H, antialias=False, threads=threads, preserveDrawingBuffer=True)
    with tuned(gl, **tuning):
        prog = softgl.program(gl, VS, SHADERS[shader])
        gl.useProgram(prog)
        for name, unit in (("s", 0), ("t", 1)):
            loc = gl.getUniformLocation(prog, name)
            if loc is not None:
                gl.uniform1i(loc, unit)
        textures(gl, shader, kind)
        pos, attr = geometry()
        for name, data in (("aPos", pos), ("aAttr", attr)):
            loc = gl.getAttribLocation(prog, name)
            gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer())
            gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW)
            gl.enableVertexAttribArray(loc)
            gl.vertexAttribPointer(loc, 4, gl.FLOAT, False, 0, 0)
        gl.clearColor(0.1, 0.2, 0.3, 0.4)
        gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT)
        gl.enable(gl.DEPTH_TEST)
        gl.enable(gl.BLEND)
        gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA)
        gl.stats(reset=True)
        gl.drawArrays(gl.TRIANGLES, 0, len(pos))
        plan = gl.last_draw_plan()
        gl.drawArrays(gl.TRIANGLES, 0, len(pos) // 2)   # over the first: its depth must be the same too
        assert gl.getError() == gl.NO_ERROR
        image = np.asarray(gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE))
        depth = np.asarray(softgl._core.testing.read_depth(gl))
        # quads_blended_in_place tells which write path the quads took (batches differ).
        stats = {k: v for k, v in gl.stats().items() if not k.startswith("seconds") and k != "quads_blended_in_place"}
        return image, depth, stats, plan


def check(shader, kind, taken, threads=1, simd=None):
    extra = {"simd": simd} if simd else {}
    ref, ref_depth, ref_stats, _ = render(shader, kind, threads, fragment_batches=False, **extra)
    quads, quad_depth, quad_stats, quad_plan = render(shader, kind, threads, lod_free_helper_lanes=False, **extra)
    pixels, depth, stats, plan = render(shader, kind, threads, **extra)
    assert quad_plan["no_helper_lanes_why_not"] == "quad_neighbours", quad_plan["text"]
    assert ref.any() and len(np.unique(ref.reshape(-1, 4), axis=0)) > 50
    assert quads.tobytes() == ref.tobytes(), (shader, kind)
    assert pixels.tobytes() == ref.tobytes(), (shader, kind, threads, simd)
    assert np.array_equal(depth, ref_depth) and np.array_equal(quad_depth, ref_depth)
    shaded = [s.pop("fragments_shaded") for s in (ref_stats, quad_stats, stats)]
    for s in (ref_stats, quad_stats, stats):
        s.pop("texture_queries_fast")   # per shader run: batches differ
    assert ref_stats == quad_stats == stats
    assert plan["no_helper_lanes"] is taken, plan["text"]
    if taken:
        assert shaded[2] < shaded[1] == shaded[0]   # only the covered pixels
    else:
        assert plan["no_helper_lanes_why_not"] == "quad_neighbours" and shaded[2] == shaded[1]


@pytest.mark.parametrize("shader,kind", [("tex2d", "linear"), ("tex2d", "nearest"), ("bias", "linear"),
                                         ("two_lookups", "linear"), ("cube", "linear"), ("cube", "nearest"),
                                         ("shadow", "linear"), ("shadow", "nearest")])
def test_lod_free_lookups_shade_single_pixels_with_the_same_bytes(shader, kind):
    check(shader, kind, taken=True)


@pytest.mark.parametrize("shader,kind", [("tex2d", "mipmapped"), ("tex2d", "min_differs"), ("bias", "mipmapped"),
                                         ("two_lookups", "mipmapped"), ("derivatives", "linear")])
def test_lookups_whose_lod_matters_keep_whole_quads(shader, kind):
    check(shader, kind, taken=False)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("simd", SIMD)
@pytest.mark.parametrize("shader", ["tex2d", "cube", "shadow"])
def test_every_simd_level_and_thread_count(shader, simd, threads):
    check(shader, "linear", taken=True, threads=threads, simd=simd)


def test_one_lod_dependent_texture_of_a_dimension_keeps_quads():
    # Two 2D samplers, only one read with an implicit LOD: the other unit's mipmaps still count
    # (the rule is per sampler dimension over the draw's units), so whole quads stay.
    fs = HEAD + """uniform sampler2D s; uniform sampler2D t;
        void main() { o = texture(s, vAttr.xy) + textureLod(t, vAttr.yx, 1.0); }"""
    gl = softgl.Context(16, 16, antialias=False)
    prog = softgl.program(gl, VS, fs)
    gl.useProgram(prog)
    gl.uniform1i(gl.getUniformLocation(prog, "s"), 0)
    gl.uniform1i(gl.getUniformLocation(prog, "t"), 1)
    colour_texture(gl, 0, 8, 1, gl.LINEAR, gl.LINEAR)
    colour_texture(gl, 1, 8, 2, gl.LINEAR_MIPMAP_LINEAR, gl.LINEAR, mipmap=True)
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.last_draw_plan()["no_helper_lanes_why_not"] == "quad_neighbours"
    gl.activeTexture(gl.TEXTURE1)
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR)   # now neither selects a level
    gl.drawArrays(gl.TRIANGLES, 0, 3)
    assert gl.last_draw_plan()["no_helper_lanes"]
